!> Memory bandwidth of this machine, for the roofline of docs/performance.md: the STREAM
!> "triad" a = b + s c over three arrays far larger than the caches, on 1 and on the maximum
!> number of threads, best of 10 repetitions. Prints one JSON object per thread count:
!>   {"threads":T,"bytes":B,"best_seconds":S,"gb_per_s":G}
!> (B counts 3 arrays × 8 bytes per element: read b, read c, write a; write-allocate traffic is
!> not counted, as in STREAM.) Usage: bandwidth [n]   (n elements per array, default 2**25)
program bandwidth
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use empm_kinds, only: wp
  use empm_parallel, only: empm_max_threads, empm_set_threads
  implicit none
  real(wp), allocatable :: a(:), b(:), c(:)
  integer(int64) :: n, i, t0, t1, rate
  integer :: rep, nt, tmax, stat
  character(len=32) :: arg
  real(wp) :: best, s
  n = 2_int64**25
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read(arg, *, iostat=stat) n
    if (stat /= 0 .or. n < 1) error stop 'bandwidth: argument 1 must be a positive integer'
  end if
  allocate(a(n), b(n), c(n))
  tmax = empm_max_threads()
  do nt = 1, tmax, max(1, tmax - 1)
    call empm_set_threads(nt)
    ! First touch by the threads that will use the data (page placement).
    !$omp parallel do schedule(static)
    do i = 1, n
      a(i) = 0.0_wp; b(i) = 1.0_wp; c(i) = 2.0_wp
    end do
    !$omp end parallel do
    best = huge(1.0_wp)
    s = 3.0_wp
    do rep = 1, 10
      call system_clock(t0, rate)
      !$omp parallel do schedule(static)
      do i = 1, n
        a(i) = b(i) + s * c(i)
      end do
      !$omp end parallel do
      call system_clock(t1)
      best = min(best, real(t1 - t0, wp) / real(rate, wp))
      s = s + a(1 + mod(rep, int(n)))  ! a data dependence, so no repetition is optimised away
    end do
    write(output_unit, '(a,i0,a,i0,a,es12.5,a,f8.2,a)') '{"threads":', nt, ',"bytes":', &
      24_int64 * n, ',"best_seconds":', best, ',"gb_per_s":', 24.0_wp * real(n, wp) / best / 1e9_wp, '}'
  end do
end program bandwidth
