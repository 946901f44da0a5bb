!> Thread control in one place, so that the rest of the library builds with and without
!> OpenMP: the OpenMP runtime is only referenced through conditional-compilation sentinels.
module empm_parallel
  use, intrinsic :: iso_fortran_env, only: int64
  !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
  implicit none
  private
  public :: empm_max_threads, empm_set_threads, EMPM_OMP_MIN_PARTICLES
  public :: empm_chunks, empm_chunk_bounds

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
