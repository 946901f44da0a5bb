!> Procedural entry point to the local max-ent (LME) shape functions, for legacy Fortran, C and
!> C++ codes that do not use empm's derived types: [[empm_lme_basis]].
!>
!> The module cannot be called `empm_lme_basis` like its procedure: a module name and the
!> procedure's binding label are both global identifiers and must differ (Fortran 2008, 16.2).
!> Fortran callers use it through the umbrella: `use empm, only: empm_lme_basis`.
!>
!> C prototype (all arguments by reference; int = integer(c_int), double = real(c_double),
!> which are the default integer and real(wp) of empm; arrays column-major, xa[a*ndim + i]):
!>
!>     void empm_lme_basis(const int *ndim, const int *nnodes, const double *x,
!>                         const double *xa, const double *gamma, const double *h,
!>                         const double *tol0, double *p, double *dp, double *lambda,
!>                         int *info);
!>
!> Fortran 77 callers (`CALL EMPM_LME_BASIS(...)`, default gfortran naming, no module) link to
!> `empm_lme_basis_`, the same routine under that name in [[empm_f77]]; C callers use the
!> name above and the header empm.h (docs/embedding.md).
module empm_lme_legacy
  use, intrinsic :: iso_c_binding, only: c_int, c_double
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  use empm_shape_lme, only: lme_kernel, LME_MAXIT_DEFAULT
  implicit none
  private
  public :: empm_lme_basis, LME_INFO_BAD_ARGUMENT

  !> `info` of [[empm_lme_basis]] for invalid arguments (ndim not 1..3, nnodes < 1, γ ≤ 0,
  !> h ≤ 0, tol0 outside (0, 1)). Other nonzero codes are the SHAPE_* codes of [[empm_shape]].
  integer(c_int), parameter :: LME_INFO_BAD_ARGUMENT = -1

contains

  !> LME values and gradients at `x` from the nodes `xa` (the caller passes the candidates:
  !> nodes beyond the support radius h·sqrt(−ln tol0/γ) get p = 0 and dp = 0).
  !>
  !> `info`: 0 converged; 3 (SHAPE_NOT_CONVERGED) no convergence in 100 Newton iterations;
  !> 4 (SHAPE_OUTSIDE_HULL) x is not inside the convex hull of the nodes within the support
  !> radius; 5 (SHAPE_SINGULAR) singular or ill-conditioned Hessian J; −1 invalid arguments.
  !> On failure p = 0, dp = 0 and `lambda` is unchanged (never NaN). Allocates nothing.
  subroutine empm_lme_basis(ndim, nnodes, x, xa, gamma, h, tol0, p, dp, lambda, info) &
      bind(C, name="empm_lme_basis")
    integer(c_int), intent(in) :: ndim                  !! spatial dimension, 1..3
    integer(c_int), intent(in) :: nnodes                !! number of nodes in `xa`
    real(c_double), intent(in) :: x(ndim)               !! evaluation point
    real(c_double), intent(in) :: xa(ndim, nnodes)      !! node coordinates
    real(c_double), intent(in) :: gamma                 !! γ = β h² > 0
    real(c_double), intent(in) :: h                     !! nodal spacing > 0 of γ = β h²
    real(c_double), intent(in) :: tol0                  !! truncation tolerance, 0 < tol0 < 1
    real(c_double), intent(out) :: p(nnodes)            !! shape-function values
    real(c_double), intent(out) :: dp(ndim, nnodes)     !! gradients
    real(c_double), intent(inout) :: lambda(ndim)       !! λ [1/length]: warm start in, λ* out
    integer(c_int), intent(out) :: info                 !! 0 or a documented code (see above)
    integer :: a, iters, stat
    logical :: bad
    bad = ndim < 1 .or. ndim > 3 .or. nnodes < 1
    if (.not. bad) bad = .not. (ieee_is_finite(gamma) .and. ieee_is_finite(h) .and. &
                                ieee_is_finite(tol0))
    if (.not. bad) bad = .not. (gamma > 0.0_wp .and. h > 0.0_wp .and. tol0 > 0.0_wp .and. &
                                tol0 < 1.0_wp)
    if (bad) then
      info = LME_INFO_BAD_ARGUMENT
      if (nnodes >= 1) p = 0.0_wp
      if (nnodes >= 1 .and. ndim >= 1) dp = 0.0_wp
      return
    end if
    do a = 1, nnodes
      dp(:, a) = (x - xa(:, a)) / h
    end do
    call lme_kernel(ndim, nnodes, gamma, tol0, h, LME_MAXIT_DEFAULT, lambda, p, dp, iters, stat)
    info = int(stat, c_int)
  end subroutine empm_lme_basis
end module empm_lme_legacy
