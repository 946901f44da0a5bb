!> Shape-function extension point: the abstract type every family extends, and the per-particle
!> basis storage it fills.
!>
!> A family implements two deferred procedures: `eval_point` (one point, for tests and for
!> embedding codes) and `eval_batch` (all particles, called once per step so that polymorphic
!> dispatch happens once per batch, not per particle). Adding a family means adding one file
!> that extends [[empm_shape_t]] and one line in [[empm_registry]].
module empm_shape
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise_error, empm_alloc_error
  use empm_strings, only: str
  use empm_family, only: empm_family_t
  use empm_namelist, only: empm_group_t
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  implicit none
  private
  public :: empm_shape_t, empm_basis_t, BASIS_LISTS, BASIS_Q4, BASIS_B9, BASIS_B27, BASIS_G9, &
            BASIS_G27, BASIS_Q8, basis_q4_weights, basis_q8_weights, basis_stencil_factors
  public :: SHAPE_OK, SHAPE_OUTSIDE_GRID, SHAPE_SUPPORT_CLIPPED, SHAPE_NOT_CONVERGED, &
            SHAPE_OUTSIDE_HULL, SHAPE_SINGULAR, SHAPE_TOO_MANY_NODES, SHAPE_BAD_LAYOUT, &
            SHAPE_NO_MEMORY, shape_status_text

  integer, parameter :: SHAPE_OK = 0              !! evaluation succeeded
  integer, parameter :: SHAPE_OUTSIDE_GRID = 1    !! the point lies outside the grid box
  integer, parameter :: SHAPE_SUPPORT_CLIPPED = 2 !! the support needs nodes beyond the grid
  integer, parameter :: SHAPE_NOT_CONVERGED = 3   !! iterative basis did not converge
  integer, parameter :: SHAPE_OUTSIDE_HULL = 4    !! point outside the convex hull of its nodes
  integer, parameter :: SHAPE_SINGULAR = 5        !! singular or ill-conditioned system
  integer, parameter :: SHAPE_TOO_MANY_NODES = 6  !! support larger than the storage provided
  integer, parameter :: SHAPE_BAD_LAYOUT = 7      !! basis storage layout this family cannot fill
  integer, parameter :: SHAPE_NO_MEMORY = 8       !! no memory to turn a compact basis into lists

  integer, parameter :: BASIS_LISTS = 0 !! layout: node lists with values and gradients (any family)
  integer, parameter :: BASIS_Q4 = 1    !! layout: bilinear on a 2D grid, the cell and two local
                                        !! coordinates per particle (values recomputed when used)
  integer, parameter :: BASIS_B9 = 2    !! layout: uniform quadratic B-splines on a 2D grid, the
                                        !! first node of the 3 × 3 stencil and two local
                                        !! coordinates per particle (values recomputed when used)
  integer, parameter :: BASIS_B27 = 3   !! layout: BASIS_B9 on a 3D grid (3 × 3 × 3 stencil, three
                                        !! local coordinates per particle)
  integer, parameter :: BASIS_G9 = 4    !! layout: uGIMP on a 2D grid, the first node of the 3 × 3
                                        !! stencil and the stored 1D factors per particle
  integer, parameter :: BASIS_G27 = 5   !! layout: BASIS_G9 on a 3D grid
  integer, parameter :: BASIS_Q8 = 6    !! layout: trilinear on a 3D grid, the cell and three
                                        !! local coordinates per particle (values recomputed)

  !> Shape-function values and gradients for every particle, in one of seven layouts.
  !>
  !> `BASIS_LISTS` (any family): per particle the number of supporting nodes, their indices,
  !> values and gradients, contiguous per particle. Compact layouts, chosen by a family
  !> through [[empm_shape_t(type):layout]], keep per particle only a node `cell` and local
  !> coordinates `t` (uGIMP: 1D factors), and every transfer forms the values and gradients
  !> from them (20–148 B per particle, read four times a step, instead of 116–972 B):
  !> - `BASIS_Q4` (linear shapes on a 2D grid): `cell` the lowest node of the particle's cell,
  !>   t ∈ [0, 1]²; the four nodes cell, cell + 1, cell + stride, cell + stride + 1 and the
  !>   bilinear values of [[basis_q4_weights]];
  !> - `BASIS_Q8` (linear shapes on a 3D grid): the same in 3D, t ∈ [0, 1]³, the eight nodes
  !>   cell + a + stride·b + stride2·c (a, b, c = 0, 1) and the trilinear values of
  !>   [[basis_q8_weights]];
  !> - `BASIS_B9` (uniform quadratic B-splines on a 2D grid): `cell` the first node of the
  !>   3 × 3 stencil (i₁ = ⌊s − ½⌋ per direction, s the position in cells), t = s − i₁ ∈
  !>   [0.5, 1.5)²; the nodes cell + a + stride·b (a, b = 0, 1, 2) and the tensor products of
  !>   [[basis_stencil_factors]]. A stencil node of value exactly zero (t = 0.5: a particle at a
  !>   cell centre) is kept in the stencil, where its terms add ±0; node lists and
  !>   [[basis_get]] drop it;
  !> - `BASIS_B27`: the same on a 3D grid, the 3 × 3 × 3 stencil's nodes
  !>   cell + a + stride·b + stride2·c and three local coordinates;
  !> - `BASIS_G9`, `BASIS_G27` (uGIMP on a 2D, 3D grid): `cell` the node below the nearest one
  !>   per direction (c − 1, c = nint(s)) and `wg` the 1D factors of `g9_factors`
  !>   (empm_stencil_weights.inc), stored rather than recomputed (their pieces branch and
  !>   divide: recomputed nine times a step they cost more than they save); a node beyond the
  !>   support has value and slope 0, and the node lists and [[basis_get]] drop it (a kept
  !>   node's value is positive). 100 B per particle in 2D, 148 B in 3D.
  !> Either way, [[basis_get]] gives one particle's nodes, values and gradients, the same bits
  !> as the transfers use.
  type :: empm_basis_t
    integer :: layout = BASIS_LISTS         !! BASIS_LISTS or a compact layout (BASIS_Q4, BASIS_Q8,
                                            !! BASIS_B9, BASIS_B27, BASIS_G9, BASIS_G27)
    integer :: ndim = 0                     !! spatial dimension
    integer :: maxn = 0                     !! capacity: nodes per particle
    integer :: np = 0                       !! number of particles
    integer, allocatable :: nn(:)           !! lists: nodes in the support of each particle (np)
    integer, allocatable :: node(:,:)       !! lists: node indices (maxn, np)
    real(wp), allocatable :: N(:,:)         !! lists: values N_Ip (maxn, np)
    real(wp), allocatable :: dN(:,:,:)      !! lists: gradients ∇N_Ip (ndim, maxn, np)
    integer, allocatable :: cell(:)         !! compact: first node of the particle's stencil (np)
    real(wp), allocatable :: t(:,:)         !! compact: local coordinates (ndim, np)
    integer :: stride = 0                   !! compact: nodes along x (set by the family's batch)
    integer :: stride2 = 0                  !! 3D compact: nodes per x-y plane (set by the batch)
    real(wp), allocatable :: wg(:,:,:,:)    !! uGIMP stencils: the 1D values (wg(:, 1, d, p)) and
                                            !! slopes (wg(:, 2, d, p)) of the 3 stencil nodes per
                                            !! direction (3, 2, ndim, np); (3, 2, ndim, 1), unused,
                                            !! for the B-spline ones
    real(wp) :: inv_h(3) = 1.0_wp           !! compact: 1/h per direction (set by the family's batch)
  contains
    procedure :: alloc => basis_alloc
    procedure :: get => basis_get
  end type empm_basis_t

  !> Abstract shape-function family. Besides the deferred procedures, a family names itself
  !> (`family`, the registry name, and `name`, the identifier of a configured instance written
  !> to results, e.g. "lme_g0.8"), may declare parameters (`params`) and read them from the
  !> `&shape` group (`configure`), and says how many padding cells a body needs (`padding_cells`).
  type, abstract, extends(empm_family_t) :: empm_shape_t
    integer :: ndim = 0 !! spatial dimension the instance was set up for
  contains
    procedure(max_nodes_iface), deferred :: max_nodes
    procedure(eval_point_iface), deferred :: eval_point
    procedure(eval_batch_iface), deferred :: eval_batch
    procedure(name_iface), deferred :: name
    procedure :: eval_batch_iters => shape_eval_batch_iters
    procedure :: layout => shape_layout
    procedure :: configure => shape_configure
    procedure :: padding_cells => shape_padding_cells
    procedure :: reach_cells => shape_reach_cells
    procedure :: node_data => shape_node_data
  end type empm_shape_t

  abstract interface
    !> Upper bound on the number of nodes supporting one point.
    pure integer function max_nodes_iface(self, grid)
      import :: empm_shape_t, empm_grid_t
      class(empm_shape_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid   !! background grid
    end function max_nodes_iface

    !> Values and gradients at one point.
    subroutine eval_point_iface(self, grid, x, lp, lam, nn, node, N, dN, info)
      import :: empm_shape_t, empm_grid_t, wp
      class(empm_shape_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid   !! background grid
      real(wp), intent(in) :: x(:)            !! point (ndim)
      real(wp), intent(in) :: lp(:)           !! particle half-lengths (ndim); used by GIMP
      real(wp), intent(inout) :: lam(:)       !! iterative state (LME λ): warm start in, result out
      integer, intent(out) :: nn              !! number of supporting nodes
      integer, intent(out) :: node(:)         !! supporting node indices (>= max_nodes entries)
      real(wp), intent(out) :: N(:)           !! values
      real(wp), intent(out) :: dN(:,:)        !! gradients (ndim, :)
      integer, intent(out) :: info            !! SHAPE_OK or a SHAPE_* failure code
    end subroutine eval_point_iface

    !> Values and gradients at every particle; on failure `ibad` is the first bad particle.
    subroutine eval_batch_iface(self, grid, pts, basis, ibad, info)
      import :: empm_shape_t, empm_grid_t, empm_particles_t, empm_basis_t
      class(empm_shape_t), intent(in) :: self      !! shape family
      type(empm_grid_t), intent(in) :: grid        !! background grid
      type(empm_particles_t), intent(inout) :: pts !! particles (λ may be updated)
      type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
      integer, intent(out) :: ibad                 !! first failing particle, 0 if none
      integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    end subroutine eval_batch_iface

    !> Short identifier, e.g. "linear", "ugimp", "bspline3", "lme_g3".
    function name_iface(self) result(s)
      import :: empm_shape_t
      class(empm_shape_t), intent(in) :: self   !! shape family
      character(len=:), allocatable :: s        !! identifier
    end function name_iface
  end interface

contains

  !> `eval_batch` that also returns the iterations spent (summed over the particles); the
  !> default is for direct (non-iterative) families: no iterations. Iterative families (LME)
  !> override it.
  subroutine shape_eval_batch_iters(self, grid, pts, basis, ibad, info, iters)
    class(empm_shape_t), intent(in) :: self      !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer, intent(out) :: iters                !! iterations summed over the particles
    call self%eval_batch(grid, pts, basis, ibad, info)
    iters = 0
  end subroutine shape_eval_batch_iters

  !> Read the family's parameters from the `&shape` group `group` (the registry sets `ndim`
  !> first; `grid` is the model's grid). The default is for families without parameters:
  !> nothing to read. A family with parameters reads each with `group%get(param, value, err)`
  !> (which validates it against the declaration) and checks combinations itself, reporting
  !> problems with `group%fail(err, key, text)`.
  subroutine shape_configure(self, grid, group, err)
    class(empm_shape_t), intent(inout) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    type(empm_group_t), intent(inout) :: group !! the `&shape` group (possibly empty)
    type(empm_error_t), intent(inout) :: err   !! set on invalid parameters
    associate (unused_ => self, unused_grid_ => grid, unused_group_ => group, unused_err_ => err)
    end associate
  end subroutine shape_configure

  !> Cells of grid a body needs beyond its material on every side so that every particle's
  !> support fits in the grid (uGIMP and B-splines 1); the default, 0, is for families whose
  !> support never needs nodes outside the grid (linear, LME).
  pure integer function shape_padding_cells(self) result(n)
    class(empm_shape_t), intent(in) :: self !! shape family
    associate (unused_ => self); end associate
    n = 0
  end function shape_padding_cells

  !> Cells beyond a particle's own cell that its support can reach, along any direction (the
  !> nodes of cells c − n .. c + 1 + n); the default, `padding_cells`, holds for the families
  !> whose support is one cell (linear), or two with a margin of one (uGIMP, B-splines).
  pure integer function shape_reach_cells(self, grid) result(n)
    class(empm_shape_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid   !! background grid
    associate (unused_ => grid); end associate
    n = self%padding_cells()
  end function shape_reach_cells

  !> Whether the family holds data per grid node, indexed by node id (LME's node-wise γ): a
  !> parallel process then stores the whole grid, not a window of it (docs/parallel.md). The
  !> default: none.
  pure logical function shape_node_data(self)
    class(empm_shape_t), intent(in) :: self !! shape family
    associate (unused_ => self); end associate
    shape_node_data = .false.
  end function shape_node_data

  !> Basis layout the family fills fastest on `grid`; the default is BASIS_LISTS, the only
  !> layout every family fills. A family overriding it must fill that layout in `eval_batch`.
  pure integer function shape_layout(self, grid)
    class(empm_shape_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid   !! background grid
    associate (unused_ => self, unused_grid_ => grid); end associate
    shape_layout = BASIS_LISTS
  end function shape_layout

  !> Allocate basis storage for `np` particles with up to `maxn` nodes each, in `layout`
  !> (default BASIS_LISTS; BASIS_Q4 needs ndim = 2 and maxn >= 4, BASIS_Q8 ndim = 3 and
  !> maxn >= 8, BASIS_B9 and BASIS_G9 ndim = 2 and maxn >= 9, BASIS_B27 and BASIS_G27 ndim = 3
  !> and maxn >= 27, otherwise lists are used).
  !> An allocation failure is reported in `err` when present (with the memory asked for),
  !> otherwise it stops the program.
  subroutine basis_alloc(self, ndim, maxn, np, layout, err)
    class(empm_basis_t), intent(inout) :: self !! basis storage
    integer, intent(in) :: ndim                !! spatial dimension
    integer, intent(in) :: maxn                !! nodes per particle (capacity)
    integer, intent(in) :: np                  !! number of particles
    integer, intent(in), optional :: layout    !! BASIS_LISTS (default) or a compact layout
    type(empm_error_t), intent(inout), optional :: err !! set on an allocation failure
    integer :: stat
    character(len=256) :: msg
    logical :: gimp
    if (allocated(self%nn)) deallocate(self%nn, self%node, self%N, self%dN)
    if (allocated(self%cell)) deallocate(self%cell, self%t)
    if (allocated(self%wg)) deallocate(self%wg)
    self%ndim = ndim; self%maxn = maxn; self%np = np
    self%layout = BASIS_LISTS
    if (present(layout)) then
      if (layout == BASIS_Q4 .and. ndim == 2 .and. maxn >= 4) self%layout = BASIS_Q4
      if (layout == BASIS_Q8 .and. ndim == 3 .and. maxn >= 8) self%layout = BASIS_Q8
      if (layout == BASIS_B9 .and. ndim == 2 .and. maxn >= 9) self%layout = BASIS_B9
      if (layout == BASIS_B27 .and. ndim == 3 .and. maxn >= 27) self%layout = BASIS_B27
      if (layout == BASIS_G9 .and. ndim == 2 .and. maxn >= 9) self%layout = BASIS_G9
      if (layout == BASIS_G27 .and. ndim == 3 .and. maxn >= 27) self%layout = BASIS_G27
    end if
    if (self%layout /= BASIS_LISTS) then
      gimp = self%layout == BASIS_G9 .or. self%layout == BASIS_G27
      allocate(self%cell(np), self%t(ndim, merge(1, np, gimp)), &
               self%wg(3, 2, ndim, merge(np, 1, gimp)), stat=stat, errmsg=msg)
      if (stat /= 0) then
        call empm_raise_error(empm_alloc_error('shape functions ('//str(np)//' particles)', &
          (4_int64 + 8_int64 * ndim * merge(6, 1, gimp)) * np, msg), err)
        return
      end if
      self%cell = 1; self%t = 0.0_wp; self%wg = 0.0_wp
      self%stride = 0; self%stride2 = 0; self%inv_h = 1.0_wp
    else
      allocate(self%nn(np), self%node(maxn, np), self%N(maxn, np), self%dN(ndim, maxn, np), &
               stat=stat, errmsg=msg)
      if (stat /= 0) then
        call empm_raise_error(empm_alloc_error('shape functions ('//str(np)//' particles x '// &
          str(maxn)//' nodes)', int(np, int64) * (4_int64 + maxn * (12_int64 + 8_int64 * ndim)), &
          msg), err)
        return
      end if
      self%nn = 0; self%node = 1; self%N = 0.0_wp; self%dN = 0.0_wp
    end if
  end subroutine basis_alloc

  !> Nodes, values and gradients of particle `p`, whatever the layout (for tests, output and
  !> embedding codes; the transfers read the storage directly). `node`, `N` and `dN` need room
  !> for `maxn` nodes; `nn` = 0 when `p` is out of range or the storage too small.
  pure subroutine basis_get(self, p, nn, node, N, dN)
    class(empm_basis_t), intent(in) :: self !! basis storage
    integer, intent(in) :: p                !! particle, 1..np
    integer, intent(out) :: nn              !! number of supporting nodes
    integer, intent(out) :: node(:)         !! node indices
    real(wp), intent(out) :: N(:)           !! values
    real(wp), intent(out) :: dN(:,:)        !! gradients (ndim, :)
    integer :: id, a, b, c, d, nd, m, k0(3), k1(3)
    real(wp) :: w(3, 3), g(3, 3)
    nn = 0
    if (p < 1 .or. p > self%np) return
    if (self%layout == BASIS_B9 .or. self%layout == BASIS_B27 .or. self%layout == BASIS_G9 &
        .or. self%layout == BASIS_G27) then
      ! The factors per direction, and the stencil nodes the node lists keep (k0..k1).
      nd = self%ndim
      w = 1.0_wp; g = 0.0_wp; k0 = 1; k1 = 1
      do d = 1, nd
        if (self%layout == BASIS_G9 .or. self%layout == BASIS_G27) then
          w(:, d) = self%wg(:, 1, d, p); g(:, d) = self%wg(:, 2, d, p)
          k0(d) = merge(2, 1, w(1, d) == 0.0_wp); k1(d) = merge(2, 3, w(3, d) == 0.0_wp)
        else
          call basis_stencil_factors(self%layout, self%t(d, p), 0.0_wp, self%inv_h(d), &
                                     w(:, d), g(:, d), k0(d), k1(d))
        end if
      end do
      m = product(k1 - k0 + 1)
      if (size(node) < m .or. size(N) < m .or. size(dN, 1) < nd .or. size(dN, 2) < m) return
      ! The node lists' order and products (x fastest; shape_tp_store; beyond ndim w = 1, exact).
      do c = k0(3), k1(3)
        do b = k0(2), k1(2)
          do a = k0(1), k1(1)
            nn = nn + 1
            node(nn) = self%cell(p) + (a - 1) + self%stride * (b - 1) + self%stride2 * (c - 1)
            N(nn) = w(a, 1) * (w(b, 2) * w(c, 3))
            dN(1, nn) = g(a, 1) * (w(b, 2) * w(c, 3))
            dN(2, nn) = g(b, 2) * (w(a, 1) * w(c, 3))
            if (nd == 3) dN(3, nn) = g(c, 3) * (w(a, 1) * w(b, 2))
          end do
        end do
      end do
    else if (self%layout == BASIS_Q4) then
      if (size(node) < 4 .or. size(N) < 4 .or. size(dN, 1) < 2 .or. size(dN, 2) < 4) return
      id = self%cell(p)
      node(1:4) = [id, id + 1, id + self%stride, id + self%stride + 1]
      call basis_q4_weights(self%t(1, p), self%t(2, p), self%inv_h(1), self%inv_h(2), &
                            N(1:4), dN(1:2, 1:4))
      nn = 4
    else if (self%layout == BASIS_Q8) then
      if (size(node) < 8 .or. size(N) < 8 .or. size(dN, 1) < 3 .or. size(dN, 2) < 8) return
      id = self%cell(p)
      do c = 0, 1
        do b = 0, 1
          do a = 0, 1
            node(1 + a + 2 * b + 4 * c) = id + a + self%stride * b + self%stride2 * c
          end do
        end do
      end do
      call basis_q8_weights(self%t(:, p), self%inv_h, N(1:8), dN(1:3, 1:8))
      nn = 8
    else
      if (size(node) < self%nn(p) .or. size(N) < self%nn(p) .or. size(dN, 1) < self%ndim &
          .or. size(dN, 2) < self%nn(p)) return
      nn = self%nn(p)
      node(1:nn) = self%node(1:nn, p)
      N(1:nn) = self%N(1:nn, p)
      dN(1:self%ndim, 1:nn) = self%dN(:, 1:nn, p)
    end if
  end subroutine basis_get

  !> Bilinear values and gradients from the local coordinates (t1, t2) of a cell with 1/h =
  !> (h1, h2); nodes in increasing index order (x fastest). The Q4 basis for the linear
  !> family's 2D kernel and [[basis_get]]; the expressions are those of empm_q4_weights.inc,
  !> which the Q4 transfers include too (the same bits in both layouts).
  pure subroutine basis_q4_weights(t1, t2, h1, h2, N, dN)
    real(wp), intent(in) :: t1        !! local coordinate along x, in [0, 1]
    real(wp), intent(in) :: t2        !! local coordinate along y, in [0, 1]
    real(wp), intent(in) :: h1        !! 1/h along x
    real(wp), intent(in) :: h2        !! 1/h along y
    real(wp), intent(out) :: N(4)     !! values
    real(wp), intent(out) :: dN(2, 4) !! gradients
    call q4_values(t1, t2, N)
    call q4_gradients(t1, t2, h1, h2, -h1, -h2, dN)
  end subroutine basis_q4_weights

  include 'empm_q4_weights.inc'

  !> Trilinear values and gradients from the local coordinates t of a cell with 1/h = h per
  !> direction; nodes in increasing index order (x fastest). The Q8 basis for [[basis_get]];
  !> the expressions are those of empm_q8_weights.inc and empm_q8_gradients.inc, which the Q8
  !> transfers include too, and
  !> the linear family's 3D node lists form the same products (the same bits in both layouts).
  pure subroutine basis_q8_weights(t, h, N, dN)
    real(wp), intent(in) :: t(3)      !! local coordinates, in [0, 1]
    real(wp), intent(in) :: h(3)      !! 1/h per direction
    real(wp), intent(out) :: N(8)     !! values
    real(wp), intent(out) :: dN(3, 8) !! gradients
    real(wp) :: tp(3), m(3), u1, u2, u3, a00, a10, a01, a11, c00, c10, c01, c11, e00, e10, e01, e11
    call q8_values(t, N)
    tp = t; m = -h
    include 'empm_q8_gradients.inc'
  end subroutine basis_q8_weights

  include 'empm_q8_weights.inc'

  !> The 1D factors of a compact stencil layout along one direction (those of
  !> empm_stencil_weights.inc, which the stencil transfers include too), and the stencil nodes
  !> k0..k1 (of 1..3) the node lists keep: quadratic B-splines (BASIS_B9, BASIS_B27) at the
  !> local coordinate t ∈ [0.5, 1.5), dropping the third node where its value is exactly zero;
  !> uGIMP (BASIS_G9, BASIS_G27) at t ∈ [−0.5, 0.5] with half-length `el` cells, dropping the
  !> end nodes beyond the support (r ≥ 1 + el).
  pure subroutine basis_stencil_factors(layout, t, el, ih, w, g, k0, k1)
    integer, intent(in) :: layout     !! BASIS_B9, BASIS_B27, BASIS_G9 or BASIS_G27
    real(wp), intent(in) :: t         !! local coordinate
    real(wp), intent(in) :: el        !! uGIMP: half-length in cells (unused otherwise)
    real(wp), intent(in) :: ih        !! 1/h along the direction
    real(wp), intent(out) :: w(3)     !! values
    real(wp), intent(out) :: g(3)     !! derivatives with respect to x
    integer, intent(out) :: k0        !! first stencil node the node lists keep
    integer, intent(out) :: k1        !! last one
    k0 = 1; k1 = 3
    if (layout == BASIS_G9 .or. layout == BASIS_G27) then
      call g9_factors(t, el, ih, w, g)
      ! ugimp_1d drops a node at r = |t − k| ≥ 1 + el: only the end ones can be.
      if (abs(t + 1.0_wp) >= 1.0_wp + el) k0 = 2
      if (abs(t - 1.0_wp) >= 1.0_wp + el) k1 = 2
    else
      call b9_factors(t, ih, w, g)
      ! bspline_1d drops the node where r = |t − 2| reaches the support radius 1.5.
      if (2.0_wp - t >= 1.5_wp) k1 = 2
    end if
  end subroutine basis_stencil_factors

  include 'empm_stencil_weights.inc'

  !> Human-readable text for a SHAPE_* status code.
  pure function shape_status_text(info) result(s)
    integer, intent(in) :: info             !! status code
    character(len=:), allocatable :: s      !! description
    select case (info)
    case (SHAPE_OK);              s = 'ok'
    case (SHAPE_OUTSIDE_GRID);    s = 'point outside the grid'
    case (SHAPE_SUPPORT_CLIPPED); s = 'support needs nodes beyond the grid (add padding cells)'
    case (SHAPE_NOT_CONVERGED);   s = 'basis iteration did not converge'
    case (SHAPE_OUTSIDE_HULL);    s = 'point outside the convex hull of its support nodes'
    case (SHAPE_SINGULAR);        s = 'singular or ill-conditioned system'
    case (SHAPE_TOO_MANY_NODES);  s = 'support larger than the storage provided'
    case (SHAPE_BAD_LAYOUT);      s = 'basis storage layout this shape family cannot fill'
    case (SHAPE_NO_MEMORY);       s = 'not enough memory to turn the compact shape-function '// &
                                      'storage into node lists'
    case default;                 s = 'unknown shape-function status'
    end select
  end function shape_status_text
end module empm_shape
