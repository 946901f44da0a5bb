!> Spectral measures of sampled signals with FFTW (through its `fftw3.f03` interface): the
!> one-sided power spectrum and the share of a signal's energy above a cutoff frequency
!> (the verification suite's noise measure).
module empm_spectrum
  ! fftw3.f03 refers to many iso_c_binding names (c_int32_t, c_intptr_t, c_funptr, ...).
  use, intrinsic :: iso_c_binding
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_power_spectrum, empm_energy_share_above
  include 'fftw3.f03'

contains

  !> One-sided power spectrum of `x` sampled every `dt`: `power(k)` at `freq(k)`,
  !> k = 1..n/2+1, normalised so that Σ power = Σ x² (Parseval). info = 1 if n < 2,
  !> 2 if FFTW could not plan.
  subroutine empm_power_spectrum(x, dt, freq, power, info)
    real(wp), intent(in) :: x(:)                    !! samples (uniform spacing)
    real(wp), intent(in) :: dt                      !! sampling interval [s]
    real(wp), allocatable, intent(out) :: freq(:)   !! frequencies [Hz]
    real(wp), allocatable, intent(out) :: power(:)  !! power per frequency bin
    integer, intent(out) :: info                    !! 0 ok
    real(c_double), allocatable :: in(:)
    complex(c_double_complex), allocatable :: out(:)
    type(c_ptr) :: plan
    integer :: n, nh, k
    info = 0
    n = size(x)
    if (n < 2) then
      info = 1; return
    end if
    nh = n / 2 + 1
    allocate(in(n), out(nh), freq(nh), power(nh))
    plan = fftw_plan_dft_r2c_1d(int(n, c_int), in, out, FFTW_ESTIMATE)
    if (.not. c_associated(plan)) then
      info = 2; return
    end if
    in = x
    call fftw_execute_dft_r2c(plan, in, out)
    call fftw_destroy_plan(plan)
    do k = 1, nh
      freq(k) = real(k - 1, wp) / (n * dt)
      power(k) = abs(out(k))**2 / n
      ! Interior bins stand for both positive and negative frequencies.
      if (k > 1 .and. .not. (mod(n, 2) == 0 .and. k == nh)) power(k) = 2.0_wp * power(k)
    end do
  end subroutine empm_power_spectrum

  !> Share (0..1) of the energy of `x` carried by frequencies strictly above `fcut`; 0 for a
  !> zero signal. info as in [[empm_power_spectrum]].
  subroutine empm_energy_share_above(x, dt, fcut, share, info)
    real(wp), intent(in) :: x(:)     !! samples (uniform spacing)
    real(wp), intent(in) :: dt       !! sampling interval [s]
    real(wp), intent(in) :: fcut     !! cutoff frequency [Hz]
    real(wp), intent(out) :: share   !! energy fraction above fcut
    integer, intent(out) :: info     !! 0 ok
    real(wp), allocatable :: freq(:), power(:)
    real(wp) :: total
    share = 0.0_wp
    call empm_power_spectrum(x, dt, freq, power, info)
    if (info /= 0) return
    total = sum(power)
    if (total > 0.0_wp) share = sum(power, mask=freq > fcut) / total
  end subroutine empm_energy_share_above
end module empm_spectrum
