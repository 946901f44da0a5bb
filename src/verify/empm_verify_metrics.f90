!> Error measures used by the verification suite: the paper's RMS (eq. 45), volume-weighted L2
!> norms, the L2 error of a time history, a spectral noise measure (FFTW) and observed orders.
module empm_verify_metrics
  use empm_kinds, only: wp
  use empm_spectrum, only: empm_energy_share_above
  implicit none
  private
  public :: rms_error, weighted_l2, history_l2, noise_share, observed_orders, fitted_order

contains

  !> Paper eq. (45): sqrt(mean((a − b)²)) over the particles.
  pure real(wp) function rms_error(a, b) result(e)
    real(wp), intent(in) :: a(:) !! numerical values at the particles
    real(wp), intent(in) :: b(:) !! exact values at the particles
    e = sqrt(sum((a - b)**2) / max(1, size(a)))
  end function rms_error

  !> Volume-weighted L2 norm of a vector field error, sqrt(Σ V |a − b|² / Σ V).
  pure real(wp) function weighted_l2(w, a, b) result(e)
    real(wp), intent(in) :: w(:)      !! weights (particle volumes)
    real(wp), intent(in) :: a(:,:)    !! numerical (ncomp, np)
    real(wp), intent(in) :: b(:,:)    !! exact (ncomp, np)
    e = sqrt(sum(spread(w, 1, size(a, 1)) * (a - b)**2) / sum(w))
  end function weighted_l2

  !> L2 error of a sampled history over its time span, sqrt(∫(a − b)² dt / T), trapezoidal.
  pure real(wp) function history_l2(t, a, b) result(e)
    real(wp), intent(in) :: t(:) !! sample times (increasing)
    real(wp), intent(in) :: a(:) !! numerical history
    real(wp), intent(in) :: b(:) !! exact history
    real(wp) :: d2(size(t))
    integer :: n
    n = size(t)
    e = 0.0_wp
    if (n < 2) return
    d2 = (a - b)**2
    e = sqrt(0.5_wp * sum((t(2:n) - t(1:n - 1)) * (d2(2:n) + d2(1:n - 1))) / (t(n) - t(1)))
  end function history_l2

  !> Share of the error history's energy above `fcut` [Hz]. The history is resampled to
  !> uniform spacing (linear interpolation at the mean step) before the FFT.
  subroutine noise_share(t, a, b, fcut, share, info)
    real(wp), intent(in) :: t(:)     !! sample times (increasing)
    real(wp), intent(in) :: a(:)     !! numerical history
    real(wp), intent(in) :: b(:)     !! exact history
    real(wp), intent(in) :: fcut     !! cutoff frequency [Hz]
    real(wp), intent(out) :: share   !! energy fraction above fcut (0..1)
    integer, intent(out) :: info     !! 0 ok, else from the FFT
    real(wp), allocatable :: e(:), u(:)
    real(wp) :: dt, tk
    integer :: n, k, j
    n = size(t)
    share = 0.0_wp; info = 1
    if (n < 4) return
    e = a - b
    dt = (t(n) - t(1)) / (n - 1)
    allocate(u(n))
    j = 1
    do k = 1, n
      tk = t(1) + (k - 1) * dt
      do while (j < n - 1)
        if (t(j + 1) >= tk) exit
        j = j + 1
      end do
      u(k) = e(j) + (e(j + 1) - e(j)) * (tk - t(j)) / max(t(j + 1) - t(j), tiny(1.0_wp))
    end do
    call empm_energy_share_above(u, dt, fcut, share, info)
  end subroutine noise_share

  !> Observed orders log(e_k/e_{k+1}) / log(h_k/h_{k+1}) between successive levels.
  pure function observed_orders(h, e) result(p)
    real(wp), intent(in) :: h(:)   !! resolution parameter per level (decreasing)
    real(wp), intent(in) :: e(:)   !! error per level
    real(wp) :: p(max(size(h) - 1, 0)) !! order between levels k and k+1
    integer :: k
    do k = 1, size(h) - 1
      p(k) = log(e(k) / e(k + 1)) / log(h(k) / h(k + 1))
    end do
  end function observed_orders

  !> Least-squares slope of log e against log h (the fitted order over all levels).
  pure real(wp) function fitted_order(h, e) result(p)
    real(wp), intent(in) :: h(:)  !! resolution parameter per level
    real(wp), intent(in) :: e(:)  !! error per level
    real(wp) :: x(size(h)), y(size(h)), xm, ym
    x = log(h); y = log(e)
    xm = sum(x) / size(x); ym = sum(y) / size(y)
    p = sum((x - xm) * (y - ym)) / sum((x - xm)**2)
  end function fitted_order
end module empm_verify_metrics
