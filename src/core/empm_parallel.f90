!> Thread control in one place, so that the rest of the library builds with and without
!> OpenMP: the OpenMP runtime is only referenced through conditional-compilation sentinels.
module empm_parallel
  use, intrinsic :: iso_fortran_env, only: int64
  !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
  implicit none
  private
  public :: empm_max_threads, empm_set_threads, EMPM_OMP_MIN_PARTICLES
  public :: empm_chunks, empm_chunk_bounds
  public :: empm_cpu_sample_t, empm_cpu_sample, empm_threads_for_load

  !> Particle loops shorter than this run on one thread: below it, forking costs more than
  !> it saves (and the small verification cases stay serial).
  integer, parameter :: EMPM_OMP_MIN_PARTICLES = 4096


  !> What the machine's processors and this process have done so far (Linux `/proc/stat` and
  !> the process's CPU time): two samples give the cores other processes kept busy between.
  type :: empm_cpu_sample_t
    logical :: ok = .false.         !! /proc/stat was read
    integer :: ncpu = 0             !! processors (its `cpuN` lines)
    integer(int64) :: busy = 0      !! jiffies spent not idle (user, nice, system, irq, softirq,
                                    !! steal), all processors
    integer(int64) :: total = 0     !! busy + idle + iowait jiffies, all processors
    real :: self = 0.0              !! CPU time of this process, all its threads [s]
    integer(int64) :: clock = 0     !! wall clock (system_clock count)
    integer(int64) :: rate = 1      !! its counts per second
  end type empm_cpu_sample_t

contains

  !> Take a sample (`s%ok` false where `/proc/stat` cannot be read: not Linux).
  subroutine empm_cpu_sample(s)
    type(empm_cpu_sample_t), intent(out) :: s !! the sample
    character(len=512) :: line
    integer(int64) :: f(8)
    integer :: u, ios
    call cpu_time(s%self)
    call system_clock(s%clock, s%rate)
    open(newunit=u, file='/proc/stat', action='read', status='old', iostat=ios)
    if (ios /= 0) return
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (line(1:4) == 'cpu ') then
        f = 0
        read(line(5:), *, iostat=ios) f
        if (ios /= 0) exit
        ! user nice system idle iowait irq softirq steal
        s%busy = f(1) + f(2) + f(3) + f(6) + f(7) + f(8)
        s%total = s%busy + f(4) + f(5)
        s%ok = .true.
      else if (line(1:3) == 'cpu') then
        s%ncpu = s%ncpu + 1
      end if
    end do
    close(u)
    s%ok = s%ok .and. s%ncpu > 0
  end subroutine empm_cpu_sample

  !> Threads to use, at most `nmax`, when other processes kept `other` cores busy between two
  !> samples: the processors they left (`ncpu − other`, rounded), at least 1; `nmax` when the
  !> samples say nothing (not Linux, or less than 50 ms apart). More threads than free cores
  !> make an OpenMP run wait at every barrier for a thread the scheduler has parked: with one
  !> busy process on two cores, two threads were 13 times slower than one (docs/performance.md).
  pure subroutine empm_threads_for_load(s0, s1, nmax, n, other)
    type(empm_cpu_sample_t), intent(in) :: s0   !! first sample
    type(empm_cpu_sample_t), intent(in) :: s1   !! later sample
    integer, intent(in) :: nmax                 !! threads allowed
    integer, intent(out) :: n                   !! threads to use
    real, intent(out) :: other                  !! cores busy with other processes (−1: unknown)
    real :: wall, busy
    n = max(1, nmax); other = -1.0
    if (.not. (s0%ok .and. s1%ok) .or. s1%total <= s0%total .or. s1%rate <= 0) return
    wall = real(s1%clock - s0%clock) / real(s1%rate)
    if (wall < 0.05) return
    ! The machine's busy cores over the interval, less this process's own share.
    busy = real(s1%ncpu) * real(s1%busy - s0%busy) / real(s1%total - s0%total)
    other = max(0.0, busy - (s1%self - s0%self) / wall)
    n = max(1, min(nmax, s1%ncpu - nint(other)))
  end subroutine empm_threads_for_load

  !> Threads an OpenMP parallel region would use now (1 without OpenMP).
  integer function empm_max_threads() result(n)
    n = 1
    !$ n = omp_get_max_threads()
  end function empm_max_threads

  !> Set the number of threads of later parallel regions (no effect without OpenMP).
  subroutine empm_set_threads(n)
    integer, intent(in) :: n !! threads, >= 1
    associate (unused_ => n); end associate
    !$ call omp_set_num_threads(max(1, n))
  end subroutine empm_set_threads

  !> Contiguous chunks to cut a loop over `n` particles into: one per thread from
  !> EMPM_OMP_MIN_PARTICLES on, else one (serial).
  integer function empm_chunks(n) result(nc)
    integer, intent(in) :: n !! loop length
    nc = 1
    if (n >= EMPM_OMP_MIN_PARTICLES) nc = empm_max_threads()
  end function empm_chunks

  !> Items p0..p1 of chunk c (0-based) when n items are cut into nc contiguous chunks (empty,
  !> p0 > p1, when there are more chunks than items).
  pure subroutine empm_chunk_bounds(n, nc, c, p0, p1)
    integer, intent(in) :: n   !! number of items
    integer, intent(in) :: nc  !! number of chunks
    integer, intent(in) :: c   !! chunk, 0..nc-1
    integer, intent(out) :: p0 !! first item
    integer, intent(out) :: p1 !! last item
    p0 = int(int(n, int64) * c / nc) + 1
    p1 = int(int(n, int64) * (c + 1) / nc)
  end subroutine empm_chunk_bounds
end module empm_parallel
