!> Linear (tent) shape functions on the regular grid: 2-node bar (1D), Q4 (2D), H8 (3D).
!>
!> Also home of the tensor-product machinery shared by every grid-aligned family (linear,
!> uGIMP, B-splines): each family computes 1D values and derivatives per direction, and
!> [[shape_tp_assemble]] multiplies them out into node indices, values and gradients.
!>
!> The spatial dimension is taken from the grid (`grid%ndim`); `self%ndim` is set by the
!> factory and is expected to agree with it.
module empm_shape_linear
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES, empm_chunks, empm_chunk_bounds
  use empm_shape, only: empm_shape_t, empm_basis_t, SHAPE_OK, SHAPE_OUTSIDE_GRID, &
                        SHAPE_SUPPORT_CLIPPED, SHAPE_TOO_MANY_NODES, SHAPE_BAD_LAYOUT, SHAPE_NO_MEMORY, &
                        BASIS_LISTS, BASIS_Q4, BASIS_Q8, BASIS_G9, BASIS_G27, basis_q4_weights, &
                        basis_q8_weights, basis_stencil_factors
  implicit none
  private
  public :: empm_shape_linear_t, shape_linear_kernel
  public :: SHAPE_TP_MAXM, SHAPE_CLIP_TOL, shape_tp_init, shape_tp_assemble, shape_batch_fits, &
            shape_stencil_batch
  public :: shape_keep_first_failure, shape_tp_store

  !> Most nodes per direction of any tensor-product family (cubic B-spline).
  integer, parameter :: SHAPE_TP_MAXM = 4
  !> Tolerance, in grid units, on the support edge when a node beyond the grid is involved:
  !> a node whose distance to the point is within this of the support radius carries a weight
  !> of order tol² (round-off of a particle domain that exactly touches the grid boundary), so
  !> it is dropped instead of reporting SHAPE_SUPPORT_CLIPPED.
  real(wp), parameter :: SHAPE_CLIP_TOL = 1.0e-10_wp

  !> Linear tensor-product shape functions: 2^ndim nodes, those of the cell holding the point.
  type, extends(empm_shape_t) :: empm_shape_linear_t
  contains
    procedure :: max_nodes => linear_max_nodes
    procedure :: eval_point => linear_eval_point
    procedure :: eval_batch => linear_eval_batch
    procedure :: name => linear_name
    procedure :: family => linear_family
    procedure :: summary => linear_summary
    procedure :: layout => linear_layout
  end type empm_shape_linear_t

contains

  !> Upper bound on supporting nodes: 2^ndim.
  pure integer function linear_max_nodes(self, grid)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    associate (unused_ => self); end associate
    linear_max_nodes = 2**grid%ndim
  end function linear_max_nodes

  !> Basis layout: BASIS_Q4 on a 2D grid, BASIS_Q8 on a 3D one (the cell and the local
  !> coordinates per particle), node lists in 1D.
  pure integer function linear_layout(self, grid)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    associate (unused_ => self); end associate
    linear_layout = BASIS_LISTS
    if (grid%ndim == 2) linear_layout = BASIS_Q4
    if (grid%ndim == 3) linear_layout = BASIS_Q8
  end function linear_layout

  !> Registry name of the family.
  pure function linear_family(self) result(s)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s             !! name
    associate (unused_ => self); end associate
    s = 'linear'
  end function linear_family

  !> One-line description of the family.
  pure function linear_summary(self) result(s)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s             !! summary
    associate (unused_ => self); end associate
    s = 'linear finite elements on the grid cells: bar (1D), Q4 (2D), H8 (3D); no padding '// &
        'needed'
  end function linear_summary

  !> Family identifier: "linear".
  function linear_name(self) result(s)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s             !! identifier
    associate (unused_ => self); end associate
    s = 'linear'
  end function linear_name

  !> Values and gradients at one point (`lp` and `lam` are not used by this family).
  subroutine linear_eval_point(self, grid, x, lp, lam, nn, node, N, dN, info)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    real(wp), intent(in) :: x(:)                   !! point (ndim)
    real(wp), intent(in) :: lp(:)                  !! particle half-lengths (unused)
    real(wp), intent(inout) :: lam(:)              !! iterative state (unused, unchanged)
    integer, intent(out) :: nn                     !! number of supporting nodes (2^ndim)
    integer, intent(out) :: node(:)                !! supporting node indices
    real(wp), intent(out) :: N(:)                  !! values
    real(wp), intent(out) :: dN(:,:)               !! gradients (ndim, :)
    integer, intent(out) :: info                   !! SHAPE_OK or a SHAPE_* failure code
    associate (unused_ => self, unused_lp_ => lp, unused_lam_ => lam); end associate
    call shape_linear_kernel(grid, x, nn, node, N, dN, info)
  end subroutine linear_eval_point

  !> Values and gradients at particles 1..pts%np; stops at the first failing particle.
  subroutine linear_eval_batch(self, grid, pts, basis, ibad, info)
    class(empm_shape_linear_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    type(empm_particles_t), intent(inout) :: pts   !! particles (unchanged)
    type(empm_basis_t), intent(inout) :: basis     !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                   !! first failing particle, 0 if none
    integer, intent(out) :: info                   !! SHAPE_OK or the failing particle's code
    integer :: p, pinfo, nc, c, p0, p1, b
    logical :: q4, q8, lists3
    call shape_batch_fits(pts%np, basis, ibad, info, compact=self%layout(grid))
    if (info /= SHAPE_OK) return
    q4 = basis%layout == BASIS_Q4
    q8 = basis%layout == BASIS_Q8
    lists3 = grid%ndim == 3 .and. basis%ndim == 3 .and. basis%maxn >= 8
    if (q4 .or. q8 .or. lists3 .or. (grid%ndim == 2 .and. basis%ndim == 2 .and. basis%maxn >= 4)) then
      ! 2D and 3D: one bilinear or trilinear kernel call per chunk of particles.
      if (q4 .or. q8) then
        basis%stride = grid%ln(1); basis%inv_h(1:grid%ndim) = grid%inv_h(1:grid%ndim)
        if (q8) basis%stride2 = grid%ln(1) * grid%ln(2)
      end if
      nc = empm_chunks(pts%np)
      ibad = huge(1)
      !$omp parallel do default(none) num_threads(nc) schedule(static, 1) &
      !$omp   shared(nc, q4, q8, lists3, grid, pts, basis) private(p0, p1, b) &
      !$omp   reduction(min: ibad) if(nc > 1)
      do c = 0, nc - 1
        call empm_chunk_bounds(pts%np, nc, c, p0, p1)
        if (q4) then
          call q4_range(grid, p0, p1, pts%x, basis%cell, basis%t, b)
        else if (q8) then
          call q8_range(grid, p0, p1, pts%x, basis%cell, basis%t, b)
        else if (lists3) then
          call linear_range_3d(grid, p0, p1, pts%x, basis%maxn, basis%nn, basis%node, &
                               basis%N, basis%dN, b)
        else
          call linear_range_2d(grid, p0, p1, pts%x, basis%maxn, basis%nn, basis%node, &
                               basis%N, basis%dN, b)
        end if
        ibad = min(ibad, b)
      end do
      !$omp end parallel do
      if (ibad == huge(1)) then
        ibad = 0
      else
        info = SHAPE_OUTSIDE_GRID
      end if
      return
    end if
    ! Particles are independent: threads share them; the first failure (lowest index) is kept.
    ibad = huge(1)
    !$omp parallel do default(none) schedule(static) shared(grid, pts, basis, ibad, info) &
    !$omp   private(pinfo) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
    do p = 1, pts%np
      call shape_linear_kernel(grid, pts%x(:, p), basis%nn(p), basis%node(:, p), &
                               basis%N(:, p), basis%dN(:, :, p), pinfo)
      if (pinfo /= SHAPE_OK) call shape_keep_first_failure(p, pinfo, ibad, info)
    end do
    !$omp end parallel do
    if (ibad == huge(1)) ibad = 0
  end subroutine linear_eval_batch

  !> Linear shape functions at one point: the 2^ndim nodes of the cell holding `x`.
  !>
  !> A point on a cell face belongs to the cell above it, except on the upper grid boundary
  !> where the last cell is used, so every point of the closed grid box is accepted.
  !> Nodes are returned in increasing index order; one of them may carry a zero value.
  pure subroutine shape_linear_kernel(grid, x, nn, node, N, dN, info)
    type(empm_grid_t), intent(in) :: grid !! background grid
    real(wp), intent(in) :: x(:)          !! point (ndim)
    integer, intent(out) :: nn            !! number of supporting nodes (0 on failure)
    integer, intent(out) :: node(:)       !! supporting node indices (capacity >= 2^ndim)
    real(wp), intent(out) :: N(:)         !! values (capacity >= 2^ndim)
    real(wp), intent(out) :: dN(:,:)      !! gradients (ndim, capacity >= 2^ndim)
    integer, intent(out) :: info          !! SHAPE_OK, SHAPE_OUTSIDE_GRID, SHAPE_TOO_MANY_NODES
    integer :: m(3), base(3), d, i0, nn1(1), ibad
    real(wp) :: w(SHAPE_TP_MAXM, 3), g(SHAPE_TP_MAXM, 3), s, t
    nn = 0
    if (grid%ndim < 1) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    if (.not. grid%inside(x)) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    if (grid%ndim == 2 .and. size(node) >= 4 .and. size(N) >= 4 .and. size(dN, 1) >= 2 .and. &
        size(dN, 2) >= 4) then
      ! The batch kernel for this one point (x is inside: it cannot fail).
      call linear_range_2d(grid, 1, 1, x(1:2), 4, nn1, node(1:4), N(1:4), dN(1:2, 1:4), ibad)
      nn = nn1(1); info = SHAPE_OK; return
    end if
    call shape_tp_init(m, base, w, g)
    do d = 1, grid%ndim
      s = (x(d) - grid%origin(d)) * grid%inv_h(d)
      ! Clamp: the upper boundary belongs to the last cell, and round-off in s must not
      ! produce t slightly outside [0, 1] (a negative value).
      i0 = min(max(floor(s), 0), grid%ncell(d) - 1)
      t = min(max(s - i0, 0.0_wp), 1.0_wp)
      m(d) = 2
      base(d) = i0
      w(1, d) = 1.0_wp - t
      w(2, d) = t
      g(1, d) = -grid%inv_h(d)
      g(2, d) = grid%inv_h(d)
    end do
    call shape_tp_assemble(grid, m, base, w, g, nn, node, N, dN, info)
  end subroutine shape_linear_kernel

  !> Bilinear (Q4) values and gradients at particles p0..p1 into node lists, without the
  !> generic tensor-product assembly (the same values and node order, x fastest; located by
  !> [[q4_range]], values by [[basis_q4_weights]], as for the compact layout). A particle
  !> outside the closed grid box gets nn = 0; `ibad` is the first one, huge(1) if none.
  pure subroutine linear_range_2d(grid, p0, p1, x, mx, nn, node, N, dN, ibad)
    type(empm_grid_t), intent(in) :: grid    !! background grid (2D)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    real(wp), intent(in) :: x(2, *)          !! particle positions
    integer, intent(in) :: mx                !! basis capacity (>= 4)
    integer, intent(inout) :: nn(*)          !! nodes per particle
    integer, intent(inout) :: node(mx, *)    !! node indices
    real(wp), intent(inout) :: N(mx, *)      !! values
    real(wp), intent(inout) :: dN(2, mx, *)  !! gradients
    integer, intent(out) :: ibad             !! first particle outside the grid, huge(1) if none
    real(wp) :: t(2, 1)
    integer :: p, id(1), n1, b
    n1 = grid%ln(1)
    ibad = huge(1)
    do p = p0, p1
      ! Located as for the compact layout (one particle: x(1, p) starts its coordinate pair).
      call q4_range(grid, 1, 1, x(1, p), id, t, b)
      if (b /= huge(1)) then
        nn(p) = 0
        ibad = min(ibad, p)
        cycle
      end if
      nn(p) = 4
      node(1, p) = id(1); node(2, p) = id(1) + 1
      node(3, p) = id(1) + n1; node(4, p) = id(1) + n1 + 1
      call basis_q4_weights(t(1, 1), t(2, 1), grid%inv_h(1), grid%inv_h(2), N(1:4, p), &
                            dN(1:2, 1:4, p))
    end do
  end subroutine linear_range_2d

  !> Trilinear values and gradients at particles p0..p1 into node lists: the bits of
  !> [[shape_linear_kernel]] (its cell, clamps and the products of [[shape_tp_assemble]], in
  !> its node order, x fastest) without the per-point work arrays and run-time dimension;
  !> located by [[q8_range]], values by [[basis_q8_weights]], as for the compact layout (one
  !> text for both layouts, as [[linear_range_2d]] has in 2D). A particle outside the closed
  !> grid box gets nn = 0; `ibad` is the first one, huge(1) if none.
  pure subroutine linear_range_3d(grid, p0, p1, x, mx, nn, node, N, dN, ibad)
    type(empm_grid_t), intent(in) :: grid    !! background grid (3D)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    real(wp), intent(in) :: x(3, *)          !! particle positions
    integer, intent(in) :: mx                !! basis capacity (>= 8)
    integer, intent(inout) :: nn(*)          !! nodes per particle
    integer, intent(inout) :: node(mx, *)    !! node indices
    real(wp), intent(inout) :: N(mx, *)      !! values
    real(wp), intent(inout) :: dN(3, mx, *)  !! gradients
    integer, intent(out) :: ibad             !! first particle outside the grid, huge(1) if none
    real(wp) :: t(3, 1)
    integer :: p, id(1), n1, n12, b, a1, a2, a3
    n1 = grid%ln(1); n12 = grid%ln(1) * grid%ln(2)
    ibad = huge(1)
    do p = p0, p1
      ! Located as for the compact layout (one particle: x(1, p) starts its coordinates).
      call q8_range(grid, 1, 1, x(1, p), id, t, b)
      if (b /= huge(1)) then
        nn(p) = 0
        ibad = min(ibad, p)
        cycle
      end if
      nn(p) = 8
      do a3 = 0, 1
        do a2 = 0, 1
          do a1 = 0, 1
            node(1 + a1 + 2 * a2 + 4 * a3, p) = id(1) + a1 + n1 * a2 + n12 * a3
          end do
        end do
      end do
      call basis_q8_weights(t(:, 1), grid%inv_h(1:3), N(1:8, p), dN(1:3, 1:8, p))
    end do
  end subroutine linear_range_3d

  !> The compact bilinear basis (BASIS_Q4) at particles p0..p1: the lowest node of the cell
  !> and the local coordinates (also how [[linear_range_2d]] locates a particle, so both
  !> layouts hold the same bits). A particle outside the closed grid box (the test of
  !> grid%inside, which a NaN coordinate fails too) is left as it was; `ibad` is the first
  !> one, huge(1) if none.
  pure subroutine q4_range(grid, p0, p1, x, cell, t, ibad)
    type(empm_grid_t), intent(in) :: grid    !! background grid (2D)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    real(wp), intent(in) :: x(2, *)          !! particle positions
    integer, intent(inout) :: cell(*)        !! lowest node of each particle's cell
    real(wp), intent(inout) :: t(2, *)       !! local coordinates
    integer, intent(out) :: ibad             !! first particle outside the grid, huge(1) if none
    real(wp) :: o1, o2, e1, e2, h1, h2, s1, s2
    integer :: p, i0, j0, n1, c1, c2, id0
    o1 = grid%origin(1); o2 = grid%origin(2)
    e1 = grid%origin(1) + grid%ncell(1) * grid%h(1)
    e2 = grid%origin(2) + grid%ncell(2) * grid%h(2)
    h1 = grid%inv_h(1); h2 = grid%inv_h(2)
    n1 = grid%ln(1); id0 = grid%id0; c1 = grid%ncell(1) - 1; c2 = grid%ncell(2) - 1
    ibad = huge(1)
    do p = p0, p1
      if (.not. (x(1, p) >= o1 .and. x(1, p) <= e1 .and. x(2, p) >= o2 .and. &
                 x(2, p) <= e2)) then
        ibad = min(ibad, p)
        cycle
      end if
      ! Inside the box, s ≥ 0: floor is int, and s − i0 ≥ 0 needs no clamp from below; the
      ! upper face belongs to the last cell.
      s1 = (x(1, p) - o1) * h1
      s2 = (x(2, p) - o2) * h2
      i0 = min(int(s1), c1)
      j0 = min(int(s2), c2)
      cell(p) = id0 + i0 + n1 * j0
      t(1, p) = min(s1 - i0, 1.0_wp)
      t(2, p) = min(s2 - j0, 1.0_wp)
    end do
  end subroutine q4_range

  !> The compact trilinear basis (BASIS_Q8) at particles p0..p1: the lowest node of the cell
  !> and the local coordinates, located as [[linear_range_3d]] locates a particle (inside the
  !> box s ≥ 0, so its clamps from below change nothing: the same bits). A particle outside
  !> the closed grid box (which a NaN coordinate fails too) is left as it was; `ibad` is the
  !> first one, huge(1) if none.
  pure subroutine q8_range(grid, p0, p1, x, cell, t, ibad)
    type(empm_grid_t), intent(in) :: grid    !! background grid (3D)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    real(wp), intent(in) :: x(3, *)          !! particle positions
    integer, intent(inout) :: cell(*)        !! lowest node of each particle's cell
    real(wp), intent(inout) :: t(3, *)       !! local coordinates
    integer, intent(out) :: ibad             !! first particle outside the grid, huge(1) if none
    real(wp) :: o(3), e(3), h(3), s
    integer :: p, d, i0, n(3), cmax(3)
    o = grid%origin(1:3); h = grid%inv_h(1:3)
    e = grid%origin(1:3) + grid%ncell(1:3) * grid%h(1:3)
    n = [1, grid%ln(1), grid%ln(1) * grid%ln(2)]; cmax = grid%ncell(1:3) - 1
    ibad = huge(1)
    do p = p0, p1
      if (.not. (x(1, p) >= o(1) .and. x(1, p) <= e(1) .and. x(2, p) >= o(2) .and. &
                 x(2, p) <= e(2) .and. x(3, p) >= o(3) .and. x(3, p) <= e(3))) then
        ibad = min(ibad, p)
        cycle
      end if
      cell(p) = grid%id0
      do d = 1, 3
        s = (x(d, p) - o(d)) * h(d)
        i0 = min(int(s), cmax(d))
        cell(p) = cell(p) + n(d) * i0
        t(d, p) = min(s - i0, 1.0_wp)
      end do
    end do
  end subroutine q8_range

  !> Reset tensor-product factors to the neutral values used along directions beyond ndim:
  !> one node at index 0 with value 1 and derivative 0.
  pure subroutine shape_tp_init(m, base, w, g)
    integer, intent(out) :: m(3)      !! nodes per direction
    integer, intent(out) :: base(3)   !! 0-based index of the first node per direction
    real(wp), intent(out) :: w(:,:)   !! 1D values (SHAPE_TP_MAXM, 3)
    real(wp), intent(out) :: g(:,:)   !! 1D derivatives d/dx_d (SHAPE_TP_MAXM, 3)
    m = 1
    base = 0
    w = 0.0_wp
    w(1, :) = 1.0_wp
    g = 0.0_wp
  end subroutine shape_tp_init

  !> Tensor product of 1D factors: node (base + k - 1) per direction gets value
  !> Π_d w(k_d, d) and gradient component d given by replacing w(k_d, d) with g(k_d, d).
  !> Nodes come out x fastest, i.e. in increasing node index.
  pure subroutine shape_tp_assemble(grid, m, base, w, g, nn, node, N, dN, info)
    type(empm_grid_t), intent(in) :: grid !! background grid
    integer, intent(in) :: m(3)           !! nodes per direction (1 beyond ndim)
    integer, intent(in) :: base(3)        !! 0-based index of the first node per direction
    real(wp), intent(in) :: w(:,:)        !! 1D values (SHAPE_TP_MAXM, 3)
    real(wp), intent(in) :: g(:,:)        !! 1D derivatives with respect to x_d
    integer, intent(out) :: nn            !! number of nodes, product(m) (0 on failure)
    integer, intent(out) :: node(:)       !! node indices
    real(wp), intent(out) :: N(:)         !! values
    real(wp), intent(out) :: dN(:,:)      !! gradients (ndim, :)
    integer, intent(out) :: info          !! SHAPE_OK, SHAPE_TOO_MANY_NODES, SHAPE_SUPPORT_CLIPPED
    integer :: nd, k1, k2, k3, a, d, row, n1, n12
    real(wp) :: w23, w13, w12
    nd = grid%ndim
    nn = 0
    a = m(1) * m(2) * m(3)
    if (a > size(node) .or. a > size(N) .or. a > size(dN, 2) .or. size(dN, 1) < nd) then
      info = SHAPE_TOO_MANY_NODES; return
    end if
    ! Families only hand over nodes inside the grid; guard against a logic error once per
    ! direction (a node_id call per node cost as much as the products).
    do d = 1, 3
      if (base(d) < 0 .or. base(d) + m(d) - 1 >= grid%nn(d)) then
        info = SHAPE_SUPPORT_CLIPPED; return
      end if
    end do
    n1 = grid%ln(1); n12 = grid%ln(1) * grid%ln(2)
    a = 0
    do k3 = 1, m(3)
      do k2 = 1, m(2)
        w23 = w(k2, 2) * w(k3, 3)
        ! grid%node_id of (base(1), base(2) + k2 − 1, base(3) + k3 − 1), the row's first node
        row = grid%id0 + base(1) + n1 * (base(2) + k2 - 1) + n12 * (base(3) + k3 - 1)
        do k1 = 1, m(1)
          a = a + 1
          node(a) = row + k1 - 1
          N(a) = w(k1, 1) * w23
          dN(1, a) = g(k1, 1) * w23
          if (nd >= 2) then
            w13 = w(k1, 1) * w(k3, 3)
            dN(2, a) = g(k2, 2) * w13
          end if
          if (nd >= 3) then
            w12 = w(k1, 1) * w(k2, 2)
            dN(3, a) = g(k3, 3) * w12
          end if
        end do
      end do
    end do
    nn = a
    info = SHAPE_OK
  end subroutine shape_tp_assemble

  !> [[shape_tp_assemble]] for a batch in 2D or 3D: the tensor product of the 1D factors
  !> straight into particle p's node list (the same products, bitwise; `w(1, 3) = 1` and
  !> `g(1, 3) = 0` with `m(3) = 1`, `base(3) = 0` in 2D). The families' batch loops call it
  !> instead of the per-point kernel: no array sections, work arrays or per-node index
  !> checks. `info` = SHAPE_TOO_MANY_NODES when the node list has no room (nothing written).
  pure subroutine shape_tp_store(grid, m, base, w, g, basis, p, info)
    type(empm_grid_t), intent(in) :: grid       !! background grid (2D or 3D)
    integer, intent(in) :: m(3)                 !! nodes per direction (1 beyond ndim)
    integer, intent(in) :: base(3)              !! 0-based index of the first node per direction
    real(wp), intent(in) :: w(:,:)              !! 1D values (>= max m, 3)
    real(wp), intent(in) :: g(:,:)              !! 1D derivatives with respect to x_d
    type(empm_basis_t), intent(inout) :: basis  !! node lists
    integer, intent(in) :: p                    !! particle
    integer, intent(out) :: info                !! SHAPE_OK or SHAPE_TOO_MANY_NODES
    integer :: a, k1, k2, k3, row, n1, n12
    real(wp) :: w23, w13
    if (m(1) * m(2) * m(3) > basis%maxn) then
      basis%nn(p) = 0
      info = SHAPE_TOO_MANY_NODES; return
    end if
    n1 = grid%ln(1); n12 = grid%ln(1) * grid%ln(2)
    a = 0
    if (grid%ndim == 2) then
      ! w(k3, 3) = 1: w23 = w(k2, 2) and w13 = w(k1, 1) exactly.
      do k2 = 1, m(2)
        row = grid%id0 + base(1) + n1 * (base(2) + k2 - 1)
        do k1 = 1, m(1)
          a = a + 1
          basis%node(a, p) = row + k1 - 1
          basis%N(a, p) = w(k1, 1) * w(k2, 2)
          basis%dN(1, a, p) = g(k1, 1) * w(k2, 2)
          basis%dN(2, a, p) = g(k2, 2) * w(k1, 1)
        end do
      end do
    else
      do k3 = 1, m(3)
        do k2 = 1, m(2)
          w23 = w(k2, 2) * w(k3, 3)
          row = grid%id0 + base(1) + n1 * (base(2) + k2 - 1) + n12 * (base(3) + k3 - 1)
          do k1 = 1, m(1)
            a = a + 1
            basis%node(a, p) = row + k1 - 1
            basis%N(a, p) = w(k1, 1) * w23
            basis%dN(1, a, p) = g(k1, 1) * w23
            w13 = w(k1, 1) * w(k3, 3)
            basis%dN(2, a, p) = g(k2, 2) * w13
            basis%dN(3, a, p) = g(k3, 3) * (w(k1, 1) * w(k2, 2))
          end do
        end do
      end do
    end if
    basis%nn(p) = a
    info = SHAPE_OK
  end subroutine shape_tp_store

  !> Check that `basis` has storage for `np` particles before a batch (the per-particle
  !> capacity and dimension are checked by [[shape_tp_assemble]]) in a layout the caller
  !> fills: node lists always, a compact layout (BASIS_Q4, BASIS_B9, ...) only when it is
  !> `compact`. On failure `ibad` is the first particle without storage and
  !> `info = SHAPE_TOO_MANY_NODES`, or `ibad = 1` and `info = SHAPE_BAD_LAYOUT`.
  pure subroutine shape_batch_fits(np, basis, ibad, info, compact)
    integer, intent(in) :: np                  !! number of particles to evaluate
    type(empm_basis_t), intent(in) :: basis    !! basis storage
    integer, intent(out) :: ibad               !! 0, or the first particle that does not fit
    integer, intent(out) :: info               !! SHAPE_OK, SHAPE_TOO_MANY_NODES, SHAPE_BAD_LAYOUT
    integer, intent(in), optional :: compact   !! the compact layout the caller can fill
                                               !! (default: none)
    ibad = 0
    info = SHAPE_OK
    if (np <= 0) return
    if (basis%layout /= BASIS_LISTS) then
      if (.not. present(compact)) then
        ibad = 1; info = SHAPE_BAD_LAYOUT; return
      end if
      if (basis%layout /= compact) then
        ibad = 1; info = SHAPE_BAD_LAYOUT; return
      end if
      if (.not. allocated(basis%cell)) then
        ibad = 1
      else if (basis%layout == BASIS_G9 .or. basis%layout == BASIS_G27) then
        if (size(basis%cell) < np .or. size(basis%wg, 4) < np) &
          ibad = min(size(basis%cell), size(basis%wg, 4)) + 1
      else if (size(basis%cell) < np .or. size(basis%t, 2) < np) then
        ibad = min(size(basis%cell), size(basis%t, 2)) + 1
      end if
    else if (.not. allocated(basis%nn)) then
      ibad = 1
    else if (size(basis%nn) < np .or. size(basis%node, 2) < np .or. size(basis%N, 2) < np &
             .or. size(basis%dN, 3) < np) then
      ibad = min(size(basis%nn), size(basis%node, 2), size(basis%N, 2), size(basis%dN, 3)) + 1
    end if
    if (ibad /= 0) info = SHAPE_TOO_MANY_NODES
  end subroutine shape_batch_fits

  !> A compact stencil basis at particles 1..pts%np (BASIS_B9, BASIS_B27 for the quadratic
  !> B-splines; BASIS_G9, BASIS_G27 for uGIMP, `gimp`), each particle located as the family's
  !> 1D routine locates it, with s the position in cells:
  !> - B-splines (`bspline_1d`): first node i₁ = ⌊s − ½⌋, t = s − i₁;
  !> - uGIMP (`ugimp_1d`): nearest node c = nint(s), first node c − 1, t = s − c, and the
  !>   half-length el = lp/h (at most `el_max`, then min(el, ½), as `ugimp_1d` takes it); the
  !>   1D factors are computed here and stored.
  !> t is exact either way. When some particle inside the grid cannot be held (a stencil node
  !> beyond the grid; uGIMP: el not in (0, el_max]), the storage is turned into node lists
  !> (once for the run: one allocation) and the result is false, nothing reported: the caller
  !> evaluates the lists, which give that particle's own result or failure. Otherwise true,
  !> `ibad` the first particle outside the closed grid box (the test of grid%inside, which a NaN
  !> fails too) or 0; or `ibad` = 1 and SHAPE_NO_MEMORY when the lists could not be allocated
  !> (the storage is then empty).
  logical function shape_stencil_batch(grid, pts, gimp, el_max, basis, ibad, info) result(held)
    type(empm_grid_t), intent(in) :: grid           !! background grid (2D or 3D)
    type(empm_particles_t), intent(in) :: pts       !! particles
    logical, intent(in) :: gimp                     !! uGIMP (else quadratic B-splines)
    real(wp), intent(in) :: el_max                  !! uGIMP: largest half-length in cells
    type(empm_basis_t), intent(inout) :: basis      !! compact stencil storage
    integer, intent(out) :: ibad                    !! first particle outside the grid, or 0
    integer, intent(out) :: info                    !! SHAPE_OK, SHAPE_OUTSIDE_GRID or
                                                    !! SHAPE_NO_MEMORY
    real(wp) :: o(3), e(3), ih(3), s, t(3), el, wg(3, 2, 3)
    integer :: nc, c, p0, p1, p, d, nd, i, id, id0, lim(3), str(3), iout, k0, k1
    logical :: inside, fits
    type(empm_error_t) :: err
    nd = grid%ndim
    o = 0.0_wp; e = 0.0_wp; ih = 1.0_wp; lim = 0; str = 0; t = 0.0_wp; el = 0.0_wp; wg = 0.0_wp
    do d = 1, nd
      o(d) = grid%origin(d); e(d) = grid%origin(d) + grid%ncell(d) * grid%h(d)
      ih(d) = grid%inv_h(d); lim(d) = grid%ncell(d) - 2
    end do
    str(1) = 1; str(2) = grid%ln(1); str(3) = grid%ln(1) * grid%ln(2); id0 = grid%id0
    basis%stride = str(2); basis%stride2 = str(3); basis%inv_h(1:nd) = ih(1:nd)
    nc = empm_chunks(pts%np)
    ibad = huge(1); iout = huge(1)
    !$omp parallel do default(none) num_threads(nc) schedule(static, 1) &
    !$omp   shared(nc, nd, pts, basis, gimp, el_max, o, e, ih, lim, str, id0) &
    !$omp   private(p0, p1, p, d, s, i, id, t, el, wg, k0, k1, inside, fits) &
    !$omp   reduction(min: ibad, iout) &
    !$omp   if(nc > 1)
    do c = 0, nc - 1
      call empm_chunk_bounds(pts%np, nc, c, p0, p1)
      do p = p0, p1
        inside = .true.
        do d = 1, nd
          if (.not. (pts%x(d, p) >= o(d) .and. pts%x(d, p) <= e(d))) inside = .false.
        end do
        if (.not. inside) then
          ibad = min(ibad, p); cycle
        end if
        fits = .true.; id = id0
        if (gimp) then
          do d = 1, nd
            s = (pts%x(d, p) - o(d)) * ih(d)
            el = pts%lp(d, p) * ih(d)
            if (.not. (el > 0.0_wp .and. el <= el_max)) fits = .false.
            el = min(el, 0.5_wp)
            i = nint(s) - 1
            t(d) = s - (i + 1)
            call basis_stencil_factors(BASIS_G9, t(d), el, ih(d), wg(:, 1, d), wg(:, 2, d), k0, k1)
            if (i < 0 .or. i > lim(d)) fits = .false.
            id = id + str(d) * i
          end do
          if (fits) basis%wg(:, :, 1:nd, p) = wg(:, :, 1:nd)
        else
          do d = 1, nd
            s = (pts%x(d, p) - o(d)) * ih(d)
            i = floor(s - 0.5_wp)
            t(d) = s - i
            if (i < 0 .or. i > lim(d)) fits = .false.
            id = id + str(d) * i
          end do
          if (fits) basis%t(1:nd, p) = t(1:nd)
        end if
        if (.not. fits) then
          iout = min(iout, p); cycle
        end if
        basis%cell(p) = id
      end do
    end do
    !$omp end parallel do
    held = iout == huge(1)
    info = SHAPE_OK
    if (.not. held) then
      call basis%alloc(nd, basis%maxn, basis%np, BASIS_LISTS, err)
      if (err%code /= 0) then
        held = .true.; ibad = 1; info = SHAPE_NO_MEMORY
      end if
      return
    end if
    if (ibad == huge(1)) then
      ibad = 0
    else
      info = SHAPE_OUTSIDE_GRID
    end if
  end function shape_stencil_batch

  !> In a particle-parallel batch loop, after particle `p` failed with `pinfo`: keep the lowest
  !> failing particle and its code, as a serial loop would report. `ibad` starts at huge(1).
  subroutine shape_keep_first_failure(p, pinfo, ibad, info)
    integer, intent(in) :: p         !! the failing particle
    integer, intent(in) :: pinfo     !! its SHAPE_* code
    integer, intent(inout) :: ibad   !! lowest failing particle so far (shared by the threads)
    integer, intent(inout) :: info   !! its code (shared by the threads)
    !$omp critical (empm_shape_failure)
    if (p < ibad) then
      ibad = p; info = pinfo
    end if
    !$omp end critical (empm_shape_failure)
  end subroutine shape_keep_first_failure
end module empm_shape_linear
