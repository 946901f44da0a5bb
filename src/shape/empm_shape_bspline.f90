!> Uniform quadratic and cubic B-spline shape functions centred at the grid nodes.
!>
!> In 1D, with r = |x − x_I|/h:
!>
!> - quadratic (`order = 2`, support radius 1.5h, 3 nodes): 3/4 − r² for r < 1/2,
!>   (3/2 − r)²/2 for 1/2 ≤ r < 3/2;
!> - cubic (`order = 3`, support radius 2h, 4 nodes): 2/3 − r² + r³/2 for r < 1,
!>   (2 − r)³/6 for 1 ≤ r < 2;
!>
!> and 0 beyond; in 2D and 3D the tensor product. Only nodes with a nonzero value are returned,
!> so a generic point has (order+1)^ndim nodes (fewer when it sits on a breakpoint).
!>
!> Near the grid boundary the uniform B-spline needs nodes outside the grid: evaluation then
!> returns `SHAPE_SUPPORT_CLIPPED`: for points closer than h/2 (quadratic) or h (cubic) to a
!> grid face. The user must pad the grid by enough cells that material stays at least that far
!> from every face (one padding cell suffices for both). An `order` other than 2 or 3 gives
!> `max_nodes = 0` and `SHAPE_TOO_MANY_NODES` (no storage can hold an undefined support).
!>
!> **Clamped** variants (`bspline2_clamped`, `bspline3_clamped`): in each direction the knot
!> vector is the uniform one in the interior and repeated p + 1 times at the grid's first and
!> last node (quadratic, in cell units: 0,0,0, 3/2, 5/2, …, n − 3/2, n,n,n; cubic: 0,0,0,0, 2, 3,
!> …, n − 2, n,n,n,n), one function per node. The functions of nodes at least p + 1 cells from a
!> face are the uniform ones; the face node's function is 1 on the face (interpolatory there,
!> so a fixed face node imposes v = 0 exactly, with no nodes outside the body's boundary); the
!> basis is a partition of unity and reproduces linear fields on the whole grid box, with no
!> padding. Points within 2p cells of a face are evaluated by the Cox–de Boor recursion,
!> the others by the uniform formulas.
!>
!> **Compact layout.** The uniform quadratic family fills `BASIS_B9` on a 2D grid and
!> `BASIS_B27` on a 3D one (per particle the first node of its 3^ndim stencil and ndim local
!> coordinates; [[empm_basis_t]]), whose transfers recompute the values ([[empm_transfer_s9]],
!> [[empm_transfer_s27]]). A particle whose stencil is not
!> inside the grid (it is then within h/2 of a face: the node lists drop a node beyond the face
!> whose value is zero or, within SHAPE_CLIP_TOL, nearly so, or fail with
!> SHAPE_SUPPORT_CLIPPED) cannot be held by it: the batch then turns the storage into node
!> lists, once, and evaluates them, which keeps every result and failure of the node lists.
module empm_shape_bspline
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES
  use empm_shape, only: empm_shape_t, empm_basis_t, SHAPE_OK, SHAPE_OUTSIDE_GRID, &
                        SHAPE_SUPPORT_CLIPPED, SHAPE_TOO_MANY_NODES, BASIS_LISTS, BASIS_B9, &
                        BASIS_B27
  use empm_shape_linear, only: SHAPE_TP_MAXM, SHAPE_CLIP_TOL, shape_tp_init, shape_tp_assemble, &
                               shape_batch_fits, shape_keep_first_failure, shape_tp_store, &
                               shape_stencil_batch
  implicit none
  private
  public :: empm_shape_bspline_t, shape_bspline_kernel

  !> B-spline shape functions of degree `order` (2 or 3), uniform or clamped at the grid faces.
  type, extends(empm_shape_t) :: empm_shape_bspline_t
    integer :: order = 3          !! polynomial degree: 2 (quadratic) or 3 (cubic)
    logical :: clamped = .false.  !! knots repeated at the grid faces (no padding needed)
  contains
    procedure :: max_nodes => bspline_max_nodes
    procedure :: eval_point => bspline_eval_point
    procedure :: eval_batch => bspline_eval_batch
    procedure :: name => bspline_name
    procedure :: family => bspline_family
    procedure :: summary => bspline_summary
    procedure :: padding_cells => bspline_padding_cells
    procedure :: layout => bspline_layout
  end type empm_shape_bspline_t

contains

  !> Upper bound on supporting nodes: (order+1)^ndim, or 0 for an unsupported order.
  pure integer function bspline_max_nodes(self, grid)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid           !! background grid
    if (self%order == 2 .or. self%order == 3) then
      bspline_max_nodes = (self%order + 1)**grid%ndim
    else
      bspline_max_nodes = 0
    end if
  end function bspline_max_nodes

  !> Registry name of the family: "bspline2" or "bspline3" (each order is its own family;
  !> "bspline?" for an unsupported order).
  pure function bspline_family(self) result(s)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s              !! name
    select case (self%order)
    case (2); s = 'bspline2'
    case (3); s = 'bspline3'
    case default; s = 'bspline?'
    end select
    if (self%clamped) s = s//'_clamped'
  end function bspline_family

  !> One-line description of the family.
  pure function bspline_summary(self) result(s)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s              !! summary
    select case (self%order)
    case (2); s = 'uniform quadratic B-splines: support radius 1.5h, 3 nodes per direction; '// &
                  'one padding cell'
    case (3); s = 'uniform cubic B-splines: support radius 2h, 4 nodes per direction; '// &
                  'one padding cell'
    case default; s = 'uniform B-splines of an unsupported order'
    end select
    if (self%clamped) then
      select case (self%order)
      case (2); s = 'quadratic B-splines clamped at the grid faces (knots repeated there): '// &
                    'interpolatory on the faces, no padding'
      case (3); s = 'cubic B-splines clamped at the grid faces (knots repeated there): '// &
                    'interpolatory on the faces, no padding'
      end select
    end if
  end function bspline_summary

  !> Padding cells: 1 (the uniform spline needs nodes beyond the grid within h/2 (quadratic) or
  !> h (cubic) of a face: SHAPE_SUPPORT_CLIPPED).
  pure integer function bspline_padding_cells(self) result(n)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    n = merge(0, 1, self%clamped)
  end function bspline_padding_cells

  !> Basis layout: for the uniform quadratic family BASIS_B9 on a 2D grid and BASIS_B27 on a
  !> 3D one (the first node of the 3^ndim stencil and ndim local coordinates per particle),
  !> node lists otherwise.
  pure integer function bspline_layout(self, grid)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid           !! background grid
    bspline_layout = BASIS_LISTS
    if (self%order /= 2 .or. self%clamped) return
    if (grid%ndim == 2) bspline_layout = BASIS_B9
    if (grid%ndim == 3) bspline_layout = BASIS_B27
  end function bspline_layout

  !> Family identifier: "bspline2" or "bspline3" ("bspline?" for an unsupported order).
  function bspline_name(self) result(s)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s              !! identifier
    select case (self%order)
    case (2); s = 'bspline2'
    case (3); s = 'bspline3'
    case default; s = 'bspline?'
    end select
    if (self%clamped) s = s//'_clamped'
  end function bspline_name

  !> Values and gradients at one point (`lp` and `lam` are not used by this family).
  subroutine bspline_eval_point(self, grid, x, lp, lam, nn, node, N, dN, info)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid           !! background grid
    real(wp), intent(in) :: x(:)                    !! point (ndim)
    real(wp), intent(in) :: lp(:)                   !! particle half-lengths (unused)
    real(wp), intent(inout) :: lam(:)               !! iterative state (unused, unchanged)
    integer, intent(out) :: nn                      !! number of supporting nodes
    integer, intent(out) :: node(:)                 !! supporting node indices
    real(wp), intent(out) :: N(:)                   !! values
    real(wp), intent(out) :: dN(:,:)                !! gradients (ndim, :)
    integer, intent(out) :: info                    !! SHAPE_OK or a SHAPE_* failure code
    associate (unused_lp_ => lp, unused_lam_ => lam); end associate
    call shape_bspline_kernel(self%order, grid, x, nn, node, N, dN, info, self%clamped)
  end subroutine bspline_eval_point

  !> Values and gradients at particles 1..pts%np; stops at the first failing particle.
  subroutine bspline_eval_batch(self, grid, pts, basis, ibad, info)
    class(empm_shape_bspline_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid           !! background grid
    type(empm_particles_t), intent(inout) :: pts    !! particles (unchanged)
    type(empm_basis_t), intent(inout) :: basis      !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                    !! first failing particle, 0 if none
    integer, intent(out) :: info                    !! SHAPE_OK or the failing particle's code
    integer :: p, pinfo
    call shape_batch_fits(pts%np, basis, ibad, info, compact=self%layout(grid))
    if (info /= SHAPE_OK) return
    if (basis%layout /= BASIS_LISTS) then
      ! BASIS_B9 or BASIS_B27 (shape_batch_fits admits no other). Done, unless a stencil
      ! reaches beyond the grid: then node lists, evaluated below.
      if (shape_stencil_batch(grid, pts, .false., 0.0_wp, basis, ibad, info)) return
    end if
    if (.not. self%clamped .and. grid%ndim >= 2 .and. &
        basis%maxn >= (self%order + 1)**grid%ndim .and. size(basis%dN, 1) >= grid%ndim) then
      call uniform_batch(self%order, grid, pts, basis, ibad, info)
      return
    end if
    ! Particles are independent: threads share them; the first failure (lowest index) is kept.
    ibad = huge(1)
    !$omp parallel do default(none) schedule(static) shared(self, grid, pts, basis, ibad, info) &
    !$omp   private(pinfo) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
    do p = 1, pts%np
      call shape_bspline_kernel(self%order, grid, pts%x(:, p), basis%nn(p), basis%node(:, p), &
                                basis%N(:, p), basis%dN(:, :, p), pinfo, self%clamped)
      if (pinfo /= SHAPE_OK) call shape_keep_first_failure(p, pinfo, ibad, info)
    end do
    !$omp end parallel do
    if (ibad == huge(1)) ibad = 0
  end subroutine bspline_eval_batch

  !> The uniform B-splines (quadratic, cubic) in 2D and 3D for particles 1..pts%np, the hot
  !> case written out: the arithmetic of [[shape_bspline_kernel]] (bspline_1d and
  !> shape_tp_assemble: the same values, bitwise, and the same node lists, a node with a zero
  !> value dropped), without its per-particle calls, work arrays and per-node index checks
  !> (they were ~40 % of a 2D bspline2 step). `tests/unit/test_bspline_fast.pf` compares them.
  subroutine uniform_batch(order, grid, pts, basis, ibad, info)
    integer, intent(in) :: order                    !! 2 or 3
    type(empm_grid_t), intent(in) :: grid           !! background grid (2D or 3D)
    type(empm_particles_t), intent(in) :: pts       !! particles
    type(empm_basis_t), intent(inout) :: basis      !! node lists (maxn >= (order + 1)^ndim)
    integer, intent(out) :: ibad                    !! first failing particle, 0 if none
    integer, intent(out) :: info                    !! SHAPE_OK or the failing particle's code
    real(wp) :: w(4, 3), g(4, 3)
    integer :: p, pinfo, m(3), base(3), nd, d
    nd = grid%ndim
    ibad = huge(1); info = SHAPE_OK
    !$omp parallel do default(none) schedule(static) &
    !$omp   shared(order, grid, pts, basis, ibad, info, nd) private(pinfo, m, base, w, g, d) &
    !$omp   if(pts%np >= EMPM_OMP_MIN_PARTICLES)
    do p = 1, pts%np
      if (.not. grid%inside(pts%x(:, p))) then
        basis%nn(p) = 0
        call shape_keep_first_failure(p, SHAPE_OUTSIDE_GRID, ibad, info); cycle
      end if
      ! Beyond ndim: one node at index 0 with factor 1 (shape_tp_init).
      m(3) = 1; base(3) = 0; w(1, 3) = 1.0_wp; g(1, 3) = 0.0_wp
      pinfo = SHAPE_OK
      do d = 1, nd
        call bspline_1d(order, grid, d, pts%x(d, p), m(d), base(d), w(:, d), g(:, d), pinfo)
        if (pinfo /= SHAPE_OK) exit
      end do
      if (pinfo /= SHAPE_OK) then
        basis%nn(p) = 0
        call shape_keep_first_failure(p, pinfo, ibad, info); cycle
      end if
      call shape_tp_store(grid, m, base, w, g, basis, p, pinfo)
      if (pinfo /= SHAPE_OK) call shape_keep_first_failure(p, pinfo, ibad, info)
    end do
    !$omp end parallel do
    if (ibad == huge(1)) ibad = 0
  end subroutine uniform_batch

  !> B-spline shape functions of degree `order` at one point; only nodes with a nonzero value
  !> are returned, in increasing index order.
  pure subroutine shape_bspline_kernel(order, grid, x, nn, node, N, dN, info, clamped)
    integer, intent(in) :: order          !! degree: 2 or 3
    type(empm_grid_t), intent(in) :: grid !! background grid
    real(wp), intent(in) :: x(:)          !! point (ndim)
    integer, intent(out) :: nn            !! number of supporting nodes (0 on failure)
    integer, intent(out) :: node(:)       !! supporting node indices (capacity >= (order+1)^ndim)
    real(wp), intent(out) :: N(:)         !! values
    real(wp), intent(out) :: dN(:,:)      !! gradients (ndim, :)
    integer, intent(out) :: info          !! SHAPE_OK or a SHAPE_* failure code (see module)
    logical, intent(in), optional :: clamped !! knots repeated at the grid faces (default no)
    integer :: m(3), base(3), d
    real(wp) :: sd
    logical :: clamp
    real(wp) :: w(SHAPE_TP_MAXM, 3), g(SHAPE_TP_MAXM, 3)
    nn = 0
    if (order /= 2 .and. order /= 3) then
      info = SHAPE_TOO_MANY_NODES; return
    end if
    if (grid%ndim < 1) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    if (.not. grid%inside(x)) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    clamp = .false.
    if (present(clamped)) clamp = clamped
    call shape_tp_init(m, base, w, g)
    do d = 1, grid%ndim
      if (clamp) then
        if (grid%ncell(d) < 2 * order) then
          info = SHAPE_SUPPORT_CLIPPED; return  ! too few cells for the clamped knots
        end if
        sd = (x(d) - grid%origin(d)) * grid%inv_h(d)
        if (sd < real(2 * order, wp) .or. sd > real(grid%ncell(d) - 2 * order, wp)) then
          call clamped_1d(order, grid, d, x(d), m(d), base(d), w(:, d), g(:, d))
          cycle
        end if
      end if
      call bspline_1d(order, grid, d, x(d), m(d), base(d), w(:, d), g(:, d), info)
      if (info /= SHAPE_OK) return
    end do
    call shape_tp_assemble(grid, m, base, w, g, nn, node, N, dN, info)
  end subroutine shape_bspline_kernel

  !> 1D B-spline factors along direction `d`: the nodes with a nonzero value.
  pure subroutine bspline_1d(order, grid, d, xd, m, base, w, g, info)
    integer, intent(in) :: order          !! degree: 2 or 3
    type(empm_grid_t), intent(in) :: grid !! background grid
    integer, intent(in) :: d              !! direction
    real(wp), intent(in) :: xd            !! coordinate of the point (inside the grid)
    integer, intent(out) :: m             !! number of nodes
    integer, intent(out) :: base          !! 0-based index of the first node
    real(wp), intent(out) :: w(:)         !! values
    real(wp), intent(out) :: g(:)         !! derivatives with respect to x_d
    integer, intent(out) :: info          !! SHAPE_OK or SHAPE_SUPPORT_CLIPPED
    real(wp) :: s, u, r, radius, ih
    integer :: i, i1
    m = 0
    base = 0
    ih = grid%inv_h(d)
    s = (xd - grid%origin(d)) * ih
    radius = 0.5_wp * real(order + 1, wp)
    ! Candidates i1 .. i1+order are the only nodes within `radius` of s; any that are dropped
    ! (zero value or tolerated outside node) sit at the ends, so the kept ones are contiguous.
    i1 = floor(s - 0.5_wp * real(order - 1, wp))
    do i = i1, i1 + order
      u = s - i
      r = abs(u)
      if (r >= radius) cycle
      if (i < 0 .or. i > grid%ncell(d)) then
        if (r < radius - SHAPE_CLIP_TOL) then
          info = SHAPE_SUPPORT_CLIPPED; return
        end if
        cycle
      end if
      if (m == 0) base = i
      m = m + 1
      if (order == 2) then
        if (r < 0.5_wp) then
          w(m) = 0.75_wp - r * r
          g(m) = -2.0_wp * u * ih
        else
          w(m) = 0.5_wp * (1.5_wp - r)**2
          g(m) = -sign(1.0_wp, u) * (1.5_wp - r) * ih
        end if
      else
        if (r < 1.0_wp) then
          w(m) = 2.0_wp / 3.0_wp - r * r + 0.5_wp * r**3
          g(m) = u * (1.5_wp * r - 2.0_wp) * ih
        else
          w(m) = (2.0_wp - r)**3 / 6.0_wp
          g(m) = -sign(1.0_wp, u) * 0.5_wp * (2.0_wp - r)**2 * ih
        end if
      end if
    end do
    info = SHAPE_OK
  end subroutine bspline_1d

  !> 1D factors of the clamped B-splines along direction `d` by the Cox–de Boor recursion
  !> (values and first derivatives of the p + 1 functions of the knot span holding the point),
  !> with the functions at the ends of the list whose value and slope are both zero dropped.
  pure subroutine clamped_1d(p, grid, d, xd, m, base, w, g)
    integer, intent(in) :: p              !! degree: 2 or 3
    type(empm_grid_t), intent(in) :: grid !! background grid
    integer, intent(in) :: d              !! direction
    real(wp), intent(in) :: xd            !! coordinate of the point (inside the grid)
    integer, intent(out) :: m             !! number of nodes
    integer, intent(out) :: base          !! 0-based index of the first node
    real(wp), intent(out) :: w(:)         !! values
    real(wp), intent(out) :: g(:)         !! derivatives with respect to x_d
    real(wp) :: s, left(3), right(3), Nd(0:3, 0:3), saved, tmp, a(0:3), ih
    integer :: n, k, j, r, first, last
    n = grid%ncell(d)
    ih = grid%inv_h(d)
    s = min(max((xd - grid%origin(d)) * ih, 0.0_wp), real(n, wp))
    ! The span k: knot(k) <= s < knot(k+1), the last non-empty span for s = n.
    k = p
    do while (k < n .and. knot(k + 1) <= s)
      k = k + 1
    end do
    ! Values of degrees 0..p (The NURBS Book, A2.2), the table kept for the derivative.
    Nd = 0.0_wp
    Nd(0, 0) = 1.0_wp
    do j = 1, p
      left(j) = s - knot(k + 1 - j)
      right(j) = knot(k + j) - s
      saved = 0.0_wp
      do r = 0, j - 1
        ! Lower triangle: knot differences; upper: the basis values.
        Nd(j, r) = right(r + 1) + left(j - r)
        tmp = Nd(r, j - 1) / Nd(j, r)
        Nd(r, j) = saved + right(r + 1) * tmp
        saved = left(j - r) * tmp
      end do
      Nd(j, j) = saved
    end do
    ! First derivatives: p (N_{i,p-1}/(t_{i+p} − t_i) − N_{i+1,p-1}/(t_{i+p+1} − t_{i+1})).
    do r = 0, p
      a(r) = 0.0_wp
      if (r >= 1) a(r) = a(r) + Nd(r - 1, p - 1) / Nd(p, r - 1)
      if (r <= p - 1) a(r) = a(r) - Nd(r, p - 1) / Nd(p, r)
      a(r) = real(p, wp) * a(r)
    end do
    ! Drop only functions whose value and slope both vanish (on a face a neighbour's value is
    ! 0 but its slope is not: the gradients must still sum to zero).
    first = 0; last = p
    do while (first < last .and. Nd(first, p) == 0.0_wp .and. a(first) == 0.0_wp)
      first = first + 1
    end do
    do while (last > first .and. Nd(last, p) == 0.0_wp .and. a(last) == 0.0_wp)
      last = last - 1
    end do
    m = last - first + 1
    base = k - p + first
    do r = first, last
      w(r - first + 1) = Nd(r, p)
      g(r - first + 1) = a(r) * ih
    end do
  contains
    ! Knot i of the clamped vector in cell units: p + 1 zeros, the uniform interior knots (cell
    ! midpoints for p = 2, nodes for p = 3), p + 1 values n.
    pure real(wp) function knot(i)
      integer, intent(in) :: i
      if (i <= p) then
        knot = 0.0_wp
      else if (i >= n + 1) then
        knot = real(n, wp)
      else
        knot = real(i, wp) - 0.5_wp * real(p + 1, wp)
      end if
    end function knot
  end subroutine clamped_1d
end module empm_shape_bspline
