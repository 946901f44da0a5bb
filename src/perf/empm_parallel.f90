!> Thread control in one place, so that the rest of the library builds with and without
!> OpenMP: the OpenMP runtime is only referenced through conditional-compilation sentinels.
module empm_parallel
  !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
  implicit none
  private
  public :: empm_max_threads, empm_set_threads, EMPM_OMP_MIN_PARTICLES

  !> Particle loops shorter than this run on one thread: below it, forking costs more than
  !> it saves (and the small verification cases stay serial).
  integer, parameter :: EMPM_OMP_MIN_PARTICLES = 4096

contains

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
end module empm_parallel
