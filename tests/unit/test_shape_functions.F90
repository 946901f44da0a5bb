! Shape-function families (linear, uGIMP, quadratic and cubic B-splines) in 1D, 2D and 3D:
! reproducing properties at pseudo-random interior points, gradients against finite
! differences, exact support sizes, hand-computed values, failure codes, batch = point, factory.
module test_shape_functions
  use funit
  use empm_kinds, only: wp, i8
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_shape, only: empm_shape_t, empm_basis_t, SHAPE_OK, SHAPE_OUTSIDE_GRID, &
                        SHAPE_SUPPORT_CLIPPED, SHAPE_TOO_MANY_NODES
  use empm_shape_factory, only: empm_shape_create, empm_shape_names
  implicit none

  !> Random points per family and dimension.
  integer, parameter :: NPTS = 200
  !> uGIMP half-lengths lp/h per direction in the random tests (0.5 is the largest allowed).
  real(wp), parameter :: UGIMP_L(3) = [0.25_wp, 0.37_wp, 0.5_wp]
  !> Points are kept this far (in grid units) from every breakpoint of the family, so support
  !> sizes are generic and no finite-difference stencil straddles a kink.
  real(wp), parameter :: MARGIN = 1.0e-3_wp
  !> Finite-difference step in grid units (margin >> step).
  real(wp), parameter :: FD_STEP = 1.0e-6_wp
  !> FD gradient tolerance in units of 1/h. The central difference has round-off error
  !> ~ eps·max|N|/step ≈ 2e-10/h and truncation error step²·max|N'''|/6 ≤ 5e-13/h (cubic
  !> B-spline; zero for the piecewise-quadratic families), so 1e-7/h leaves a wide margin.
  real(wp), parameter :: FD_TOL = 1.0e-7_wp

  character(len=8), parameter :: FAMILIES(4) = [character(len=8) :: &
    'linear', 'ugimp', 'bspline2', 'bspline3']

  integer(i8) :: lcg_state = 1_i8

contains

  ! ---- helpers --------------------------------------------------------------------------------

  !> Restart the pseudo-random sequence (Park-Miller minimal standard LCG).
  subroutine lcg_seed(seed)
    integer, intent(in) :: seed
    lcg_state = int(seed, i8)
  end subroutine lcg_seed

  !> Next pseudo-random number in (0, 1).
  real(wp) function lcg_next() result(u)
    lcg_state = mod(16807_i8 * lcg_state, 2147483647_i8)
    u = real(lcg_state, wp) / 2147483647.0_wp
  end function lcg_next

  !> A non-dyadic, anisotropic grid with a shifted origin, for the random tests.
  subroutine make_grid(ndim, grid)
    integer, intent(in) :: ndim
    type(empm_grid_t), intent(out) :: grid
    integer :: info
    call grid%init(ndim, [-0.3_wp, 0.7_wp, 1.1_wp], [0.23_wp, 0.4_wp, 0.3_wp], [9, 7, 6], info)
  end subroutine make_grid

  !> A dyadic grid (exact node coordinates and grid coordinates), for hand-computed values.
  subroutine make_dyadic_grid(ndim, grid)
    integer, intent(in) :: ndim
    type(empm_grid_t), intent(out) :: grid
    integer :: info
    call grid%init(ndim, [-1.0_wp, 0.5_wp, 2.0_wp], [0.25_wp, 0.5_wp, 0.125_wp], [8, 8, 8], info)
  end subroutine make_dyadic_grid

  !> Create a family through the factory.
  subroutine make_shape(name, ndim, shp)
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim
    class(empm_shape_t), allocatable, intent(out) :: shp
    integer :: info
    call empm_shape_create(name, ndim, shp, info)
  end subroutine make_shape

  !> Particle half-lengths used with `name` on `grid` (uGIMP only; zero otherwise).
  subroutine half_lengths(name, grid, lp)
    character(len=*), intent(in) :: name
    type(empm_grid_t), intent(in) :: grid
    real(wp), intent(out) :: lp(:)
    integer :: d
    lp = 0.0_wp
    if (name == 'ugimp') then
      do d = 1, grid%ndim
        lp(d) = UGIMP_L(d) * grid%h(d)
      end do
    end if
  end subroutine half_lengths

  !> True when the fractional grid coordinate t is at least MARGIN (mod 1) from every
  !> breakpoint of the family along direction d.
  logical function away_from_breakpoints(name, d, t) result(ok)
    character(len=*), intent(in) :: name
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    ok = far(0.0_wp)
    select case (name)
    case ('ugimp')
      ok = ok .and. far(UGIMP_L(d)) .and. far(1.0_wp - UGIMP_L(d))
    case ('bspline2')
      ok = far(0.5_wp)
    end select
  contains
    logical function far(b)
      real(wp), intent(in) :: b
      real(wp) :: dist
      dist = abs(t - b)
      far = min(dist, 1.0_wp - dist) > MARGIN
    end function far
  end function away_from_breakpoints

  !> Random point at least 2 cells from the grid faces and away from breakpoints; also
  !> returns its grid coordinates s (units of h from the origin).
  subroutine sample_point(name, grid, x, s)
    character(len=*), intent(in) :: name
    type(empm_grid_t), intent(in) :: grid
    real(wp), intent(out) :: x(:)
    real(wp), intent(out) :: s(:)
    integer :: d
    do d = 1, grid%ndim
      do
        s(d) = 2.0_wp + (grid%ncell(d) - 4) * lcg_next()
        if (away_from_breakpoints(name, d, s(d) - floor(s(d)))) exit
      end do
      x(d) = grid%origin(d) + s(d) * grid%h(d)
    end do
  end subroutine sample_point

  !> Exact support size of a generic interior point (grid coordinates s).
  integer function expected_count(name, ndim, s) result(nexp)
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim
    real(wp), intent(in) :: s(:)
    integer :: d, m
    real(wp) :: t
    nexp = 1
    do d = 1, ndim
      select case (name)
      case ('linear'); m = 2
      case ('bspline2'); m = 3
      case ('bspline3'); m = 4
      case default
        ! uGIMP: nodes within (1 + L)h of the point: the two cell nodes, plus the node below
        ! when t < L and the node above when t > 1 - L (never both, as L <= 1/2).
        t = s(d) - floor(s(d))
        m = 2
        if (t < UGIMP_L(d)) m = m + 1
        if (t > 1.0_wp - UGIMP_L(d)) m = m + 1
      end select
      nexp = nexp * m
    end do
  end function expected_count

  !> Context string for assertion messages.
  function context(name, ndim, i) result(ctx)
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim, i
    character(len=:), allocatable :: ctx
    character(len=64) :: buf
    write(buf, '(a,1x,i0,"D point ",i0)') trim(name), ndim, i
    ctx = trim(buf)
  end function context

  !> Reproducing properties, positivity, node validity and support size at NPTS points.
  subroutine check_properties(name)
    character(len=*), intent(in) :: name
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(3), s(3), lp(3), lam(3), xa(3), rep(3), sumg(3), mom(3, 3), delta_ij
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    integer :: ndim, ip, nn, info, a, i, j, maxn
    character(len=:), allocatable :: ctx
    call lcg_seed(20240611)
    do ndim = 1, 3
      call make_grid(ndim, grid)
      call make_shape(name, ndim, shp)
      maxn = shp%max_nodes(grid)
      allocate(node(maxn), N(maxn), dN(ndim, maxn))
      call half_lengths(name, grid, lp)
      do ip = 1, NPTS
        ctx = context(name, ndim, ip)
        call sample_point(name, grid, x, s)
        lam = 0.0_wp
        call shp%eval_point(grid, x(1:ndim), lp(1:ndim), lam(1:ndim), nn, node, N, dN, info)
#line 184 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 184) )
  if (anyExceptions()) return
#line 185 "/work/main/tests/unit/test_shape_functions.pf"
#line 185 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(expected_count(name, ndim, s), nn, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 185) )
  if (anyExceptions()) return
#line 186 "/work/main/tests/unit/test_shape_functions.pf"
#line 186 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(nn <= maxn, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 186) )
  if (anyExceptions()) return
#line 187 "/work/main/tests/unit/test_shape_functions.pf"
        rep = 0.0_wp; sumg = 0.0_wp; mom = 0.0_wp
        do a = 1, nn
#line 189 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(node(a) >= 1 .and. node(a) <= grid%nnode, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 189) )
  if (anyExceptions()) return
#line 190 "/work/main/tests/unit/test_shape_functions.pf"
#line 190 "/work/main/tests/unit/test_shape_functions.pf"
  call assertGreaterThanOrEqual(N(a), 0.0_wp, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 190) )
  if (anyExceptions()) return
#line 191 "/work/main/tests/unit/test_shape_functions.pf"
          xa = grid%node_coord(node(a))
          rep = rep + N(a) * xa
          sumg(1:ndim) = sumg(1:ndim) + dN(:, a)
          do j = 1, ndim
            mom(1:ndim, j) = mom(1:ndim, j) + xa(1:ndim) * dN(j, a)
          end do
        end do
#line 198 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(1.0_wp, sum(N(1:nn)), tolerance=1.0e-13_wp, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 198) )
  if (anyExceptions()) return
#line 199 "/work/main/tests/unit/test_shape_functions.pf"
        do i = 1, ndim
#line 200 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(x(i), rep(i), tolerance=1.0e-12_wp, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 200) )
  if (anyExceptions()) return
#line 201 "/work/main/tests/unit/test_shape_functions.pf"
#line 201 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(0.0_wp, sumg(i), tolerance=1.0e-12_wp, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 201) )
  if (anyExceptions()) return
#line 202 "/work/main/tests/unit/test_shape_functions.pf"
          do j = 1, ndim
            delta_ij = merge(1.0_wp, 0.0_wp, i == j)
#line 204 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(delta_ij, mom(i, j), tolerance=1.0e-11_wp, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 204) )
  if (anyExceptions()) return
#line 205 "/work/main/tests/unit/test_shape_functions.pf"
          end do
        end do
      end do
      deallocate(node, N, dN)
    end do
  end subroutine check_properties

  !> Scatter the basis of `x` into dense per-node arrays (value, or gradient component d).
  subroutine dense_values(shp, grid, x, lp, Nd, Gd, d)
    class(empm_shape_t), intent(in) :: shp
    type(empm_grid_t), intent(in) :: grid
    real(wp), intent(in) :: x(:), lp(:)
    real(wp), intent(out) :: Nd(:), Gd(:)
    integer, intent(in) :: d
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    real(wp) :: lam(3)
    integer :: nn, info, a
    allocate(node(shp%max_nodes(grid)), N(shp%max_nodes(grid)), &
             dN(grid%ndim, shp%max_nodes(grid)))
    lam = 0.0_wp
    call shp%eval_point(grid, x, lp, lam(1:grid%ndim), nn, node, N, dN, info)
#line 227 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 227) )
  if (anyExceptions()) return
#line 228 "/work/main/tests/unit/test_shape_functions.pf"
    Nd = 0.0_wp; Gd = 0.0_wp
    do a = 1, nn
      Nd(node(a)) = N(a)
      Gd(node(a)) = dN(d, a)
    end do
  end subroutine dense_values

  !> Gradients against central differences, compared node by node (over all grid nodes, so
  !> a node missing from one support but not another would be caught).
  subroutine check_fd_gradient(name)
    character(len=*), intent(in) :: name
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(3), s(3), lp(3), xp(3), xm(3), delta, err
    real(wp), allocatable :: N0(:), G0(:), Np(:), Nm(:), scratch(:)
    integer :: ndim, ip, d
    character(len=:), allocatable :: ctx
    call lcg_seed(777)
    do ndim = 1, 3
      call make_grid(ndim, grid)
      call make_shape(name, ndim, shp)
      call half_lengths(name, grid, lp)
      allocate(N0(grid%nnode), G0(grid%nnode), Np(grid%nnode), Nm(grid%nnode), &
               scratch(grid%nnode))
      do ip = 1, NPTS
        ctx = context(name, ndim, ip)
        call sample_point(name, grid, x, s)
        do d = 1, ndim
          delta = FD_STEP * grid%h(d)
          xp = x; xp(d) = x(d) + delta
          xm = x; xm(d) = x(d) - delta
          call dense_values(shp, grid, x(1:ndim), lp(1:ndim), N0, G0, d)
          call dense_values(shp, grid, xp(1:ndim), lp(1:ndim), Np, scratch, d)
          call dense_values(shp, grid, xm(1:ndim), lp(1:ndim), Nm, scratch, d)
          err = maxval(abs((Np - Nm) / (xp(d) - xm(d)) - G0)) * grid%h(d)
#line 263 "/work/main/tests/unit/test_shape_functions.pf"
  call assertLessThanOrEqual(err, FD_TOL, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 263) )
  if (anyExceptions()) return
#line 264 "/work/main/tests/unit/test_shape_functions.pf"
        end do
      end do
      deallocate(N0, G0, Np, Nm, scratch)
    end do
  end subroutine check_fd_gradient

  !> Compare with hand-computed values on the dyadic grid: the point has grid coordinate sc
  !> in every direction; the supporting nodes are first(d) + k - 1, k = 1..size(w1), with 1D
  !> values w1(k) and derivatives g1(k)/h_d; values and gradients are their tensor products.
  subroutine check_exact(name, ndim, lpfrac, sc, first, w1, g1)
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim
    real(wp), intent(in) :: lpfrac      ! uGIMP lp/h
    real(wp), intent(in) :: sc          ! grid coordinate of the point, every direction
    integer, intent(in) :: first        ! index of the first supporting node, every direction
    real(wp), intent(in) :: w1(:), g1(:)
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(3), lp(3), lam(3), val, gr
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    integer :: nn, info, a, d, e, k(3), ijk(3)
    character(len=64) :: ctx
    write(ctx, '(a,1x,i0,"D at s = ",f6.3)') trim(name), ndim, sc
    call make_dyadic_grid(ndim, grid)
    call make_shape(name, ndim, shp)
    allocate(node(shp%max_nodes(grid)), N(shp%max_nodes(grid)), dN(ndim, shp%max_nodes(grid)))
    x = grid%origin + sc * grid%h
    lp = lpfrac * grid%h
    lam = 0.0_wp
    call shp%eval_point(grid, x(1:ndim), lp(1:ndim), lam(1:ndim), nn, node, N, dN, info)
#line 295 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 295) )
  if (anyExceptions()) return
#line 296 "/work/main/tests/unit/test_shape_functions.pf"
#line 296 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(size(w1)**ndim, nn, message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 296) )
  if (anyExceptions()) return
#line 297 "/work/main/tests/unit/test_shape_functions.pf"
    do a = 1, nn
      ijk = grid%node_ijk(node(a))
      k = 1
      k(1:ndim) = ijk(1:ndim) - first + 1
      do d = 1, ndim
#line 302 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(k(d) >= 1 .and. k(d) <= size(w1), message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 302) )
  if (anyExceptions()) return
#line 303 "/work/main/tests/unit/test_shape_functions.pf"
      end do
      val = product(w1(k(1:ndim)))
#line 305 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(val, N(a), tolerance=1.0e-14_wp, message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 305) )
  if (anyExceptions()) return
#line 306 "/work/main/tests/unit/test_shape_functions.pf"
      do d = 1, ndim
        gr = g1(k(d)) * grid%inv_h(d)
        do e = 1, ndim
          if (e /= d) gr = gr * w1(k(e))
        end do
#line 311 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(gr, dN(d, a), tolerance=1.0e-12_wp, message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 311) )
  if (anyExceptions()) return
#line 312 "/work/main/tests/unit/test_shape_functions.pf"
      end do
    end do
  end subroutine check_exact

  !> Status of one evaluation at grid coordinates s (units of h from the origin).
  integer function status_at(name, ndim, s, lpfrac) result(info)
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim
    real(wp), intent(in) :: s(3)
    real(wp), intent(in) :: lpfrac
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(3), lp(3), lam(3)
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    integer :: nn
    call make_dyadic_grid(ndim, grid)
    call make_shape(name, ndim, shp)
    allocate(node(shp%max_nodes(grid)), N(shp%max_nodes(grid)), dN(ndim, shp%max_nodes(grid)))
    x = grid%origin + s * grid%h
    lp = lpfrac * grid%h
    lam = 0.0_wp
    call shp%eval_point(grid, x(1:ndim), lp(1:ndim), lam(1:ndim), nn, node, N, dN, info)
  end function status_at

  !> Assert the status of one evaluation at grid coordinates s.
  subroutine expect_status(expected, name, ndim, s, lpfrac)
    integer, intent(in) :: expected
    character(len=*), intent(in) :: name
    integer, intent(in) :: ndim
    real(wp), intent(in) :: s(3)
    real(wp), intent(in) :: lpfrac
    character(len=96) :: ctx
    integer :: info
    write(ctx, '(a,1x,i0,"D, lp/h =",f5.2,", s =",3f7.3)') name, ndim, lpfrac, s(1:ndim)
    info = status_at(name, ndim, s, lpfrac)
#line 348 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(expected, info, message=trim(ctx), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 348) )
  if (anyExceptions()) return
#line 349 "/work/main/tests/unit/test_shape_functions.pf"
  end subroutine expect_status

  !> Grid coordinates: 4 (interior) everywhere except `v` along direction d.
  function s_with(d, v) result(s)
    integer, intent(in) :: d
    real(wp), intent(in) :: v
    real(wp) :: s(3)
    s = 4.0_wp
    s(d) = v
  end function s_with

  ! ---- reproducing properties, positivity, support size ---------------------------------------

  !@test
  subroutine test_linear_properties()
    call check_properties('linear')
  end subroutine test_linear_properties

  !@test
  subroutine test_ugimp_properties()
    call check_properties('ugimp')
  end subroutine test_ugimp_properties

  !@test
  subroutine test_bspline2_properties()
    call check_properties('bspline2')
  end subroutine test_bspline2_properties

  !@test
  subroutine test_bspline3_properties()
    call check_properties('bspline3')
  end subroutine test_bspline3_properties

  ! ---- gradients against finite differences ---------------------------------------------------

  !@test
  subroutine test_linear_gradient_fd()
    call check_fd_gradient('linear')
  end subroutine test_linear_gradient_fd

  !@test
  subroutine test_ugimp_gradient_fd()
    call check_fd_gradient('ugimp')
  end subroutine test_ugimp_gradient_fd

  !@test
  subroutine test_bspline2_gradient_fd()
    call check_fd_gradient('bspline2')
  end subroutine test_bspline2_gradient_fd

  !@test
  subroutine test_bspline3_gradient_fd()
    call check_fd_gradient('bspline3')
  end subroutine test_bspline3_gradient_fd

  ! ---- hand-computed values -------------------------------------------------------------------

  !@test
  subroutine test_linear_exact_values()
    integer :: ndim
    do ndim = 1, 3
      ! Cell centre: 1/2 per direction, so 1/2^d; slopes ∓1/h.
      call check_exact('linear', ndim, 0.0_wp, 3.5_wp, 3, [0.5_wp, 0.5_wp], [-1.0_wp, 1.0_wp])
      ! On a node: the cell above it is used (value 1 at the node, 0 at the next one).
      call check_exact('linear', ndim, 0.0_wp, 3.0_wp, 3, [1.0_wp, 0.0_wp], [-1.0_wp, 1.0_wp])
      ! Lower and upper grid boundary: the first and the last cell.
      call check_exact('linear', ndim, 0.0_wp, 0.0_wp, 0, [1.0_wp, 0.0_wp], [-1.0_wp, 1.0_wp])
      call check_exact('linear', ndim, 0.0_wp, 8.0_wp, 7, [0.0_wp, 1.0_wp], [-1.0_wp, 1.0_wp])
    end do
  end subroutine test_linear_exact_values

  !@test
  subroutine test_ugimp_exact_values()
    integer :: ndim
    do ndim = 1, 3
      ! lp = h/4 at a node: centre 1 − L/2 = 7/8, neighbours L/4 = 1/16 (3 per direction).
      call check_exact('ugimp', ndim, 0.25_wp, 4.0_wp, 3, [1.0_wp/16, 7.0_wp/8, 1.0_wp/16], &
                       [-0.5_wp, 0.0_wp, 0.5_wp])
      ! lp = h/4 at a cell centre (L ≤ t ≤ 1 − L): 2 per direction, linear values.
      call check_exact('ugimp', ndim, 0.25_wp, 4.5_wp, 4, [0.5_wp, 0.5_wp], [-1.0_wp, 1.0_wp])
      ! lp = h/4, t = 1/8 < L: (1+L−r)²/(4L) = 1/64, 1 − (u²+L²)/(2L) = 27/32, 9/64.
      call check_exact('ugimp', ndim, 0.25_wp, 4.125_wp, 3, &
                       [1.0_wp/64, 27.0_wp/32, 9.0_wp/64], [-0.25_wp, -0.5_wp, 0.75_wp])
      ! lp = h/2 (the limit) at a cell centre: 2 per direction, still linear there.
      call check_exact('ugimp', ndim, 0.5_wp, 4.5_wp, 4, [0.5_wp, 0.5_wp], [-1.0_wp, 1.0_wp])
      ! lp = h/2 at a node: 1 − L/2 = 3/4, L/4 = 1/8 (same as the quadratic B-spline).
      call check_exact('ugimp', ndim, 0.5_wp, 4.0_wp, 3, [0.125_wp, 0.75_wp, 0.125_wp], &
                       [-0.5_wp, 0.0_wp, 0.5_wp])
      ! lp = 0 is the linear hat (cell above a node).
      call check_exact('ugimp', ndim, 0.0_wp, 4.0_wp, 4, [1.0_wp, 0.0_wp], [-1.0_wp, 1.0_wp])
      call check_exact('ugimp', ndim, 0.0_wp, 4.25_wp, 4, [0.75_wp, 0.25_wp], [-1.0_wp, 1.0_wp])
    end do
  end subroutine test_ugimp_exact_values

  !@test
  subroutine test_ugimp_mixed_support_size()
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(2), lp(2), lam(2), N(9), dN(2, 9)
    integer :: node(9), nn, info
    ! lp = h/4; t = 1/8 along x (3 nodes), t = 1/2 along y (2 nodes): 6 nodes.
    call make_dyadic_grid(2, grid)
    call make_shape('ugimp', 2, shp)
    x = grid%origin(1:2) + [4.125_wp, 4.5_wp] * grid%h(1:2)
    lp = 0.25_wp * grid%h(1:2)
    lam = 0.0_wp
    call shp%eval_point(grid, x, lp, lam, nn, node, N, dN, info)
#line 456 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 456) )
  if (anyExceptions()) return
#line 457 "/work/main/tests/unit/test_shape_functions.pf"
#line 457 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(6, nn, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 457) )
  if (anyExceptions()) return
#line 458 "/work/main/tests/unit/test_shape_functions.pf"
#line 458 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(1.0_wp, sum(N(1:nn)), tolerance=1.0e-14_wp, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 458) )
  if (anyExceptions()) return
#line 459 "/work/main/tests/unit/test_shape_functions.pf"
  end subroutine test_ugimp_mixed_support_size

  !@test
  subroutine test_bspline2_exact_values()
    integer :: ndim
    do ndim = 1, 3
      ! At a node: 3/4 at the node, 1/8 at each neighbour; slopes ∓1/(2h) at the neighbours.
      call check_exact('bspline2', ndim, 0.0_wp, 4.0_wp, 3, [0.125_wp, 0.75_wp, 0.125_wp], &
                       [-0.5_wp, 0.0_wp, 0.5_wp])
      ! At a cell centre: the outer nodes sit on the support edge, 1/2 at the cell nodes.
      call check_exact('bspline2', ndim, 0.0_wp, 4.5_wp, 4, [0.5_wp, 0.5_wp], [-1.0_wp, 1.0_wp])
    end do
  end subroutine test_bspline2_exact_values

  !@test
  subroutine test_bspline3_exact_values()
    integer :: ndim
    do ndim = 1, 3
      ! At a node: 2/3 at the node, 1/6 at each neighbour; slopes ∓1/(2h).
      call check_exact('bspline3', ndim, 0.0_wp, 4.0_wp, 3, &
                       [1.0_wp/6, 2.0_wp/3, 1.0_wp/6], [-0.5_wp, 0.0_wp, 0.5_wp])
      ! At a cell centre: 1/48, 23/48, 23/48, 1/48; slopes −1/8, −5/8, 5/8, 1/8 (per h).
      call check_exact('bspline3', ndim, 0.0_wp, 4.5_wp, 3, &
                       [1.0_wp/48, 23.0_wp/48, 23.0_wp/48, 1.0_wp/48], &
                       [-0.125_wp, -0.625_wp, 0.625_wp, 0.125_wp])
    end do
  end subroutine test_bspline3_exact_values

  ! ---- failure codes --------------------------------------------------------------------------

  !@test
  subroutine test_outside_grid()
    integer :: f, ndim, d
    do f = 1, size(FAMILIES)
      do ndim = 1, 3
        do d = 1, ndim
          call expect_status(SHAPE_OUTSIDE_GRID, trim(FAMILIES(f)), ndim, s_with(d, -0.01_wp), &
                             0.25_wp)
          call expect_status(SHAPE_OUTSIDE_GRID, trim(FAMILIES(f)), ndim, s_with(d, 8.01_wp), &
                             0.25_wp)
        end do
      end do
    end do
  end subroutine test_outside_grid

  !@test
  subroutine test_bspline_support_clipped()
    integer :: ndim, d
    do ndim = 1, 3
      do d = 1, ndim
        ! Quadratic: every node within 1.5h must exist, so points closer than h/2 to a face
        ! are clipped; at exactly h/2 the outside node is at 1.5h, has value zero, and is
        ! not needed.
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline2', ndim, s_with(d, 0.4_wp), 0.0_wp)
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline2', ndim, s_with(d, 0.0_wp), 0.0_wp)
        call expect_status(SHAPE_OK, 'bspline2', ndim, s_with(d, 0.5_wp), 0.0_wp)
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline2', ndim, s_with(d, 7.6_wp), 0.0_wp)
        call expect_status(SHAPE_OK, 'bspline2', ndim, s_with(d, 7.5_wp), 0.0_wp)
        ! Cubic: nodes within 2h, so points closer than h to a face are clipped.
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline3', ndim, s_with(d, 0.9_wp), 0.0_wp)
        call expect_status(SHAPE_OK, 'bspline3', ndim, s_with(d, 1.0_wp), 0.0_wp)
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline3', ndim, s_with(d, 7.1_wp), 0.0_wp)
        call expect_status(SHAPE_OK, 'bspline3', ndim, s_with(d, 7.0_wp), 0.0_wp)
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'bspline3', ndim, s_with(d, 8.0_wp), 0.0_wp)
      end do
    end do
  end subroutine test_bspline_support_clipped

  !@test
  subroutine test_ugimp_bad_half_length()
    integer :: ndim, d
    do ndim = 1, 3
      do d = 1, ndim
        ! lp > h/2 would need 4 nodes per direction: SHAPE_TOO_MANY_NODES; lp < 0 likewise.
        call expect_status(SHAPE_TOO_MANY_NODES, 'ugimp', ndim, s_with(d, 4.3_wp), 0.51_wp)
        call expect_status(SHAPE_TOO_MANY_NODES, 'ugimp', ndim, s_with(d, 4.3_wp), -0.1_wp)
        call expect_status(SHAPE_OK, 'ugimp', ndim, s_with(d, 4.3_wp), 0.5_wp)
      end do
    end do
  end subroutine test_ugimp_bad_half_length

  !@test
  subroutine test_ugimp_support_clipped()
    integer :: ndim, d
    do ndim = 1, 3
      do d = 1, ndim
        ! lp = h/4: the particle domain [x − lp, x + lp] must stay inside the grid box;
        ! touching a face exactly is fine (the outside node has value zero).
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'ugimp', ndim, s_with(d, 0.2_wp), 0.25_wp)
        call expect_status(SHAPE_OK, 'ugimp', ndim, s_with(d, 0.25_wp), 0.25_wp)
        call expect_status(SHAPE_SUPPORT_CLIPPED, 'ugimp', ndim, s_with(d, 7.8_wp), 0.25_wp)
        call expect_status(SHAPE_OK, 'ugimp', ndim, s_with(d, 7.75_wp), 0.25_wp)
        ! lp = 0 (linear hat) works up to the faces.
        call expect_status(SHAPE_OK, 'ugimp', ndim, s_with(d, 0.0_wp), 0.0_wp)
        call expect_status(SHAPE_OK, 'ugimp', ndim, s_with(d, 8.0_wp), 0.0_wp)
      end do
    end do
  end subroutine test_ugimp_support_clipped

  !@test
  subroutine test_storage_too_small()
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    real(wp) :: x(3), lp(3), lam(3)
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    integer :: f, nn, info, maxn
    call make_dyadic_grid(3, grid)
    do f = 1, size(FAMILIES)
      call make_shape(trim(FAMILIES(f)), 3, shp)
      maxn = shp%max_nodes(grid)
      allocate(node(maxn - 1), N(maxn - 1), dN(3, maxn - 1))
      ! A generic interior point needs max_nodes nodes for every family (uGIMP: near a node).
      x = grid%origin + 4.1_wp * grid%h
      lp = 0.25_wp * grid%h
      lam = 0.0_wp
      call shp%eval_point(grid, x, lp, lam, nn, node, N, dN, info)
#line 576 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_TOO_MANY_NODES, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 576) )
  if (anyExceptions()) return
#line 577 "/work/main/tests/unit/test_shape_functions.pf"
      deallocate(node, N, dN)
    end do
  end subroutine test_storage_too_small

  ! ---- batch evaluation -----------------------------------------------------------------------

  !@test
  subroutine test_batch_matches_point()
    integer, parameter :: NP = 40
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    type(empm_particles_t) :: pts
    type(empm_basis_t) :: basis
    real(wp) :: x(3), s(3), lp(3), lam(3)
    integer, allocatable :: node(:)
    real(wp), allocatable :: N(:), dN(:,:)
    integer :: f, ndim, p, nn, info, ibad, maxn
    character(len=:), allocatable :: ctx
    call lcg_seed(4242)
    do f = 1, size(FAMILIES)
      do ndim = 1, 3
        call make_grid(ndim, grid)
        call make_shape(trim(FAMILIES(f)), ndim, shp)
        call half_lengths(trim(FAMILIES(f)), grid, lp)
        maxn = shp%max_nodes(grid)
        call pts%alloc(ndim, NP)
        pts%np = NP
        do p = 1, NP
          call sample_point(trim(FAMILIES(f)), grid, x, s)
          pts%x(:, p) = x(1:ndim)
          pts%lp(:, p) = lp(1:ndim)
          pts%lam(:, p) = 0.0_wp
        end do
        call basis%alloc(ndim, maxn, NP)
        call shp%eval_batch(grid, pts, basis, ibad, info)
#line 612 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 612) )
  if (anyExceptions()) return
#line 613 "/work/main/tests/unit/test_shape_functions.pf"
#line 613 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(0, ibad, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 613) )
  if (anyExceptions()) return
#line 614 "/work/main/tests/unit/test_shape_functions.pf"
        allocate(node(maxn), N(maxn), dN(ndim, maxn))
        do p = 1, NP
          ctx = context(trim(FAMILIES(f)), ndim, p)
          lam = 0.0_wp
          call shp%eval_point(grid, pts%x(:, p), pts%lp(:, p), lam(1:ndim), nn, node, N, dN, info)
#line 619 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OK, info, message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 619) )
  if (anyExceptions()) return
#line 620 "/work/main/tests/unit/test_shape_functions.pf"
#line 620 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(nn, basis%nn(p), message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 620) )
  if (anyExceptions()) return
#line 621 "/work/main/tests/unit/test_shape_functions.pf"
#line 621 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(all(node(1:nn) == basis%node(1:nn, p)), message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 621) )
  if (anyExceptions()) return
#line 622 "/work/main/tests/unit/test_shape_functions.pf"
#line 622 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(all(N(1:nn) == basis%N(1:nn, p)), message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 622) )
  if (anyExceptions()) return
#line 623 "/work/main/tests/unit/test_shape_functions.pf"
#line 623 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(all(dN(:, 1:nn) == basis%dN(:, 1:nn, p)), message=ctx, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 623) )
  if (anyExceptions()) return
#line 624 "/work/main/tests/unit/test_shape_functions.pf"
        end do
        deallocate(node, N, dN)
      end do
    end do
  end subroutine test_batch_matches_point

  !@test
  subroutine test_batch_reports_first_failure()
    integer, parameter :: NP = 10
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    type(empm_particles_t) :: pts
    type(empm_basis_t) :: basis
    real(wp) :: lp(3)
    integer :: f, ndim, p, info, ibad
    do f = 1, size(FAMILIES)
      do ndim = 1, 3
        call make_dyadic_grid(ndim, grid)
        call make_shape(trim(FAMILIES(f)), ndim, shp)
        lp = 0.25_wp * grid%h
        call pts%alloc(ndim, NP)
        pts%np = NP
        do p = 1, NP
          pts%x(:, p) = grid%origin(1:ndim) + (3.0_wp + 0.2_wp * p) * grid%h(1:ndim)
          pts%lp(:, p) = lp(1:ndim)
          pts%lam(:, p) = 0.0_wp
        end do
        ! Particle 7 leaves the grid, particle 9 too: the first one is reported.
        pts%x(1, 7) = grid%origin(1) - grid%h(1)
        pts%x(ndim, 9) = grid%origin(ndim) + 9.0_wp * grid%h(ndim)
        call basis%alloc(ndim, shp%max_nodes(grid), NP)
        call shp%eval_batch(grid, pts, basis, ibad, info)
#line 656 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_OUTSIDE_GRID, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 656) )
  if (anyExceptions()) return
#line 657 "/work/main/tests/unit/test_shape_functions.pf"
#line 657 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(7, ibad, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 657) )
  if (anyExceptions()) return
#line 658 "/work/main/tests/unit/test_shape_functions.pf"
        ! Storage for fewer particles than pts%np: refused before any evaluation.
        call basis%alloc(ndim, shp%max_nodes(grid), NP - 3)
        call shp%eval_batch(grid, pts, basis, ibad, info)
#line 661 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(SHAPE_TOO_MANY_NODES, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 661) )
  if (anyExceptions()) return
#line 662 "/work/main/tests/unit/test_shape_functions.pf"
#line 662 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(NP - 2, ibad, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 662) )
  if (anyExceptions()) return
#line 663 "/work/main/tests/unit/test_shape_functions.pf"
      end do
    end do
  end subroutine test_batch_reports_first_failure

  ! ---- factory --------------------------------------------------------------------------------

  !@test
  subroutine test_factory_creates_every_family()
    class(empm_shape_t), allocatable :: shp
    type(empm_grid_t) :: grid
    integer :: f, ndim, info
    integer, parameter :: per_dim(4) = [2, 3, 3, 4]
    do f = 1, size(FAMILIES)
      do ndim = 1, 3
        call make_grid(ndim, grid)
        call empm_shape_create(trim(FAMILIES(f)), ndim, shp, info)
#line 679 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(0, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 679) )
  if (anyExceptions()) return
#line 680 "/work/main/tests/unit/test_shape_functions.pf"
#line 680 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(allocated(shp), message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 680) )
  if (anyExceptions()) return
#line 681 "/work/main/tests/unit/test_shape_functions.pf"
#line 681 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(shp%name() == trim(FAMILIES(f)), message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 681) )
  if (anyExceptions()) return
#line 682 "/work/main/tests/unit/test_shape_functions.pf"
#line 682 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(ndim, shp%ndim, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 682) )
  if (anyExceptions()) return
#line 683 "/work/main/tests/unit/test_shape_functions.pf"
#line 683 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(per_dim(f)**ndim, shp%max_nodes(grid), message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 683) )
  if (anyExceptions()) return
#line 684 "/work/main/tests/unit/test_shape_functions.pf"
#line 684 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(index(empm_shape_names(), trim(FAMILIES(f))) > 0, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 684) )
  if (anyExceptions()) return
#line 685 "/work/main/tests/unit/test_shape_functions.pf"
      end do
    end do
    ! Case and surrounding blanks are ignored.
    call empm_shape_create(' BSpline2 ', 2, shp, info)
#line 689 "/work/main/tests/unit/test_shape_functions.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 689) )
  if (anyExceptions()) return
#line 690 "/work/main/tests/unit/test_shape_functions.pf"
#line 690 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(shp%name() == 'bspline2', &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 690) )
  if (anyExceptions()) return
#line 691 "/work/main/tests/unit/test_shape_functions.pf"
  end subroutine test_factory_creates_every_family

  !@test
  subroutine test_factory_rejects_bad_input()
    class(empm_shape_t), allocatable :: shp
    integer :: info
    call empm_shape_create('bspline4', 2, shp, info)
#line 698 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(info /= 0, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 698) )
  if (anyExceptions()) return
#line 699 "/work/main/tests/unit/test_shape_functions.pf"
#line 699 "/work/main/tests/unit/test_shape_functions.pf"
  call assertFalse(allocated(shp), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 699) )
  if (anyExceptions()) return
#line 700 "/work/main/tests/unit/test_shape_functions.pf"
    call empm_shape_create('linear', 4, shp, info)
#line 701 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(info /= 0, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 701) )
  if (anyExceptions()) return
#line 702 "/work/main/tests/unit/test_shape_functions.pf"
#line 702 "/work/main/tests/unit/test_shape_functions.pf"
  call assertFalse(allocated(shp), &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 702) )
  if (anyExceptions()) return
#line 703 "/work/main/tests/unit/test_shape_functions.pf"
    call empm_shape_create('linear', 0, shp, info)
#line 704 "/work/main/tests/unit/test_shape_functions.pf"
  call assertTrue(info /= 0, &
 & location=SourceLocation( &
 & 'test_shape_functions.pf', &
 & 704) )
  if (anyExceptions()) return
#line 705 "/work/main/tests/unit/test_shape_functions.pf"
  end subroutine test_factory_rejects_bad_input
end module test_shape_functions

module Wraptest_shape_functions
   use FUnit
   use test_shape_functions
   implicit none
   private

contains


end module Wraptest_shape_functions

function test_shape_functions_suite() result(suite)
   use FUnit
   use test_shape_functions
   use Wraptest_shape_functions
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_shape_functions_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_linear_properties', &
      test_linear_properties))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_properties', &
      test_ugimp_properties))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline2_properties', &
      test_bspline2_properties))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline3_properties', &
      test_bspline3_properties))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_linear_gradient_fd', &
      test_linear_gradient_fd))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_gradient_fd', &
      test_ugimp_gradient_fd))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline2_gradient_fd', &
      test_bspline2_gradient_fd))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline3_gradient_fd', &
      test_bspline3_gradient_fd))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_linear_exact_values', &
      test_linear_exact_values))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_exact_values', &
      test_ugimp_exact_values))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_mixed_support_size', &
      test_ugimp_mixed_support_size))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline2_exact_values', &
      test_bspline2_exact_values))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline3_exact_values', &
      test_bspline3_exact_values))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_outside_grid', &
      test_outside_grid))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_bspline_support_clipped', &
      test_bspline_support_clipped))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_bad_half_length', &
      test_ugimp_bad_half_length))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ugimp_support_clipped', &
      test_ugimp_support_clipped))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_storage_too_small', &
      test_storage_too_small))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_batch_matches_point', &
      test_batch_matches_point))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_batch_reports_first_failure', &
      test_batch_reports_first_failure))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_factory_creates_every_family', &
      test_factory_creates_every_family))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_factory_rejects_bad_input', &
      test_factory_rejects_bad_input))
   call suite%addTest(t)


end function test_shape_functions_suite

