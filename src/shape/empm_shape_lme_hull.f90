!> Hull tests of the LME failure path: whether −λ separates x from the candidates, whether x
!> lies in a simplex of d+1 candidates (Carathéodory), and whether the support reaches beyond
!> the grid. A child of empm_shape_lme_newton, whose `sym_inverse` and `matvec` it uses.
submodule (empm_shape_lme:empm_shape_lme_newton) empm_shape_lme_hull
  implicit none

contains

  module procedure separates
    integer :: a
    separates = .false.
    if (all(lh(1:nd) == 0.0_wp)) return
    do a = 1, nc
      if (q(a) < 0.0_wp) cycle
      if (dot_product(lh(1:nd), xi(1:nd, a)) >= 0.0_wp) return
    end do
    separates = .true.
  end procedure separates

  module procedure in_simplex_hull
    integer :: i, j, k, l
    in_simplex_hull = .true.
    select case (nd)
    case (1)
      in_simplex_hull = any(xi(1, 1:nc) >= 0.0_wp .and. q(1:nc) >= 0.0_wp) .and. &
                        any(xi(1, 1:nc) <= 0.0_wp .and. q(1:nc) >= 0.0_wp)
      return
    case (2)
      do i = 1, nc
        if (q(i) < 0.0_wp) cycle
        do j = i + 1, nc
          if (q(j) < 0.0_wp) cycle
          do k = j + 1, nc
            if (q(k) < 0.0_wp) cycle
            if (in_simplex(nd, xi(:, i), xi(:, j), xi(:, k), xi(:, k))) return
          end do
        end do
      end do
    case default
      do i = 1, nc
        if (q(i) < 0.0_wp) cycle
        do j = i + 1, nc
          if (q(j) < 0.0_wp) cycle
          do k = j + 1, nc
            if (q(k) < 0.0_wp) cycle
            do l = k + 1, nc
              if (q(l) < 0.0_wp) cycle
              if (in_simplex(nd, xi(:, i), xi(:, j), xi(:, k), xi(:, l))) return
            end do
          end do
        end do
      end do
    end select
    in_simplex_hull = .false.
  end procedure in_simplex_hull

  module procedure clipped
    integer :: lo(3), hi(3), i, j, k, d, ijk(3)
    real(wp) :: s, rd, dist2
    clipped = .false.
    lo = 0; hi = 0
    do d = 1, grid%ndim
      s = (x(d) - grid%origin(d)) * grid%inv_h(d)
      rd = rmax * grid%inv_h(d)
      lo(d) = ceiling(s - rd)
      hi(d) = floor(s + rd)
    end do
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          ijk = [i, j, k]
          if (all(ijk >= 0 .and. ijk < grid%nn)) cycle ! a node of the grid
          dist2 = 0.0_wp
          do d = 1, grid%ndim
            dist2 = dist2 + (x(d) - (grid%origin(d) + ijk(d) * grid%h(d)))**2
          end do
          if (dist2 <= rmax * rmax) then
            clipped = .true.; return
          end if
        end do
      end do
    end do
  end procedure clipped

  !> True when the origin lies in the closed simplex with vertices v0..v_nd (2D: v0, v1, v2;
  !> `v3` unused), to within 1e-12 in barycentric coordinates; false for a degenerate simplex.
  pure logical function in_simplex(nd, v0, v1, v2, v3)
    integer, intent(in) :: nd        !! spatial dimension, 2 or 3
    real(wp), intent(in) :: v0(:)    !! vertex
    real(wp), intent(in) :: v1(:)    !! vertex
    real(wp), intent(in) :: v2(:)    !! vertex
    real(wp), intent(in) :: v3(:)    !! vertex (3D only)
    real(wp) :: m(3, 3), minv(3, 3), b(3), mu(3), scl
    logical :: ok
    real(wp), parameter :: TOL = 1.0e-12_wp
    m = 0.0_wp; b = 0.0_wp
    m(1:nd, 1) = v1(1:nd) - v0(1:nd)
    m(1:nd, 2) = v2(1:nd) - v0(1:nd)
    if (nd == 3) m(1:nd, 3) = v3(1:nd) - v0(1:nd)
    b(1:nd) = -v0(1:nd)
    ! Solve M μ = −v0 through MᵀM (symmetric, for sym_inverse); degenerate simplices fail.
    call sym_inverse(nd, matmul_tn(nd, m), minv, scl, 1.0e14_wp, ok)
    in_simplex = .false.
    if (.not. ok) return
    mu = matvec(nd, minv, matvec_t(nd, m, b)) / scl
    in_simplex = all(mu(1:nd) >= -TOL) .and. sum(mu(1:nd)) <= 1.0_wp + TOL
  end function in_simplex

  !> MᵀM for the leading nd×nd block.
  pure function matmul_tn(nd, m) result(c)
    integer, intent(in) :: nd        !! dimension
    real(wp), intent(in) :: m(3, 3)  !! matrix
    real(wp) :: c(3, 3)              !! MᵀM (zero beyond nd)
    integer :: i, j
    c = 0.0_wp
    do j = 1, nd
      do i = 1, nd
        c(i, j) = sum(m(1:nd, i) * m(1:nd, j))
      end do
    end do
  end function matmul_tn

  !> Mᵀv for the leading nd×nd block.
  pure function matvec_t(nd, m, v) result(y)
    integer, intent(in) :: nd        !! dimension
    real(wp), intent(in) :: m(3, 3)  !! matrix
    real(wp), intent(in) :: v(3)     !! vector
    real(wp) :: y(3)                 !! product (zero beyond nd)
    integer :: i
    y = 0.0_wp
    do i = 1, nd
      y(i) = sum(m(1:nd, i) * v(1:nd))
    end do
  end function matvec_t
end submodule empm_shape_lme_hull
