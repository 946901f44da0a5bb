!> Cheap screens for non-finite values, for run-time guards that must cost next to nothing.
!>
!> A sum is finite when every term is: an Inf or a NaN among the terms makes it an Inf or a NaN.
!> The converse fails only when finite terms overflow (|sum| > 1.8e308), which raises a false
!> alarm, never a miss; so a screen that passes settles the matter and only one that fails
!> needs the detailed search for the first offender. Additions into independent partial sums
!> vectorise (a packed add takes two values) and carry no branch; screening values a pass has
!> just written (still in cache) costs well under a nanosecond per particle. A quiet NaN raises
!> no floating-point exception; +Inf meeting −Inf (invalid) and an overflowing sum (overflow)
!> do, which a debug build traps: there the operation that made the Inf has trapped first,
!> unless it came from outside (an API call), and the trap then stops the run instead of the
!> guard (tests/unit/test_screen.pf runs the screens with those traps off).
module empm_screen
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_screen_finite, empm_screen_finite2, empm_screen_finite3

contains

  !> .true. when `x(1:n)` are all finite (n = 0: .true.); .false. when one is an Inf or a NaN,
  !> and also, falsely, when finite values sum past the largest double. Explicit shape, so that
  !> a contiguous section of a rank-2 array (`a(1, q0)`, `n = size(a, 1) * (q1 − q0 + 1)`) is
  !> screened as one sequence.
  pure logical function empm_screen_finite(n, x) result(ok)
    integer, intent(in) :: n          !! number of values
    real(wp), intent(in) :: x(n)      !! values
    real(wp) :: s(4)
    integer :: i, i4
    s = 0.0_wp
    i4 = n - mod(n, 4)
    ! Four partial sums: one reduction chain would neither vectorise nor pipeline.
    do i = 1, i4, 4
      s(1) = s(1) + x(i); s(2) = s(2) + x(i + 1)
      s(3) = s(3) + x(i + 2); s(4) = s(4) + x(i + 3)
    end do
    do i = i4 + 1, n
      s(1) = s(1) + x(i)
    end do
    ok = ieee_is_finite((s(1) + s(2)) + (s(3) + s(4)))
  end function empm_screen_finite

  !> [[empm_screen_finite]] of two sequences at once: the screen of the sums x(i) + y(i).
  pure logical function empm_screen_finite2(n, x, y) result(ok)
    integer, intent(in) :: n          !! number of values in each
    real(wp), intent(in) :: x(n)      !! first values
    real(wp), intent(in) :: y(n)      !! second values
    real(wp) :: s(4)
    integer :: i, i4
    s = 0.0_wp
    i4 = n - mod(n, 4)
    do i = 1, i4, 4
      s(1) = s(1) + (x(i) + y(i)); s(2) = s(2) + (x(i + 1) + y(i + 1))
      s(3) = s(3) + (x(i + 2) + y(i + 2)); s(4) = s(4) + (x(i + 3) + y(i + 3))
    end do
    do i = i4 + 1, n
      s(1) = s(1) + (x(i) + y(i))
    end do
    ok = ieee_is_finite((s(1) + s(2)) + (s(3) + s(4)))
  end function empm_screen_finite2

  !> [[empm_screen_finite]] of three sequences at once: the screen of x(i) + y(i) + z(i).
  pure logical function empm_screen_finite3(n, x, y, z) result(ok)
    integer, intent(in) :: n          !! number of values in each
    real(wp), intent(in) :: x(n)      !! first values
    real(wp), intent(in) :: y(n)      !! second values
    real(wp), intent(in) :: z(n)      !! third values
    real(wp) :: s(4)
    integer :: i, i4
    s = 0.0_wp
    i4 = n - mod(n, 4)
    do i = 1, i4, 4
      s(1) = s(1) + ((x(i) + y(i)) + z(i)); s(2) = s(2) + ((x(i + 1) + y(i + 1)) + z(i + 1))
      s(3) = s(3) + ((x(i + 2) + y(i + 2)) + z(i + 2))
      s(4) = s(4) + ((x(i + 3) + y(i + 3)) + z(i + 3))
    end do
    do i = i4 + 1, n
      s(1) = s(1) + ((x(i) + y(i)) + z(i))
    end do
    ok = ieee_is_finite((s(1) + s(2)) + (s(3) + s(4)))
  end function empm_screen_finite3
end module empm_screen
