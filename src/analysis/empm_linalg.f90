!> Dense linear algebra through LAPACK: eigenvalues of small general matrices (amplification
!> matrices of the integrators) and spectral radius.
module empm_linalg
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_eigenvalues, empm_spectral_radius

  interface
    subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: jobvl, jobvr
      integer, intent(in) :: n, lda, ldvl, ldvr, lwork
      real(wp), intent(inout) :: a(lda, *)
      real(wp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
      integer, intent(out) :: info
    end subroutine dgeev
  end interface

contains

  !> Eigenvalues `lam = wr + i wi` of the square matrix `A` (LAPACK dgeev). info from LAPACK.
  subroutine empm_eigenvalues(A, lam, info)
    real(wp), intent(in) :: A(:,:)          !! square matrix (n, n)
    complex(wp), intent(out) :: lam(:)      !! eigenvalues (n)
    integer, intent(out) :: info            !! 0 ok, < 0 bad argument, > 0 QR failed
    real(wp) :: B(size(A, 1), size(A, 1)), wr(size(A, 1)), wi(size(A, 1)), vl(1, 1), vr(1, 1)
    real(wp) :: work(max(1, 8 * size(A, 1)))
    integer :: n
    n = size(A, 1)
    B = A
    call dgeev('N', 'N', n, B, n, wr, wi, vl, 1, vr, 1, work, size(work), info)
    lam = cmplx(wr, wi, kind=wp)
  end subroutine empm_eigenvalues

  !> Spectral radius max |λ| of `A`.
  function empm_spectral_radius(A, info) result(r)
    real(wp), intent(in) :: A(:,:)   !! square matrix
    integer, intent(out) :: info     !! LAPACK status
    real(wp) :: r                    !! spectral radius
    complex(wp) :: lam(size(A, 1))
    call empm_eigenvalues(A, lam, info)
    r = maxval(abs(lam))
  end function empm_spectral_radius
end module empm_linalg
