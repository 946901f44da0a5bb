!> Homogeneous motion with a constant velocity gradient G: the exact solution of a block whose
!> every node is driven with v = G x (`&boundary velocity_gradient`), in 1D, 2D or 3D.
!>
!> Kinematics: x = F(t) X with F = exp(tG), v = G x, a = G² x, ρ = ρ₀/det F = ρ₀ e^(−t tr G).
!> Every shape family with linear completeness reproduces these fields exactly, so the error of
!> a run is the time integration's alone. Stress, for a start stress σ₀:
!> - rate form with the Jaumann rate (D = sym G, W = skw G, S = λ tr D I + 2μD constant):
!>   σ(t) = Q(t) [σ₀ + ∫₀ᵗ Q(τ)ᵀ S Q(τ) dτ] Q(t)ᵀ with Q = exp(tW), the integral by composite
!>   Gauss–Legendre quadrature (to round-off); a rigid rotation (D = 0) gives Q σ₀ Qᵀ for any
!>   rate-form model;
!> - the small-strain (non-objective) update: σ = σ₀ + tS;
!> - neo-Hookean: σ = σ(F(t)) from the stress-free reference (σ₀ = 0).
!> The body force per unit mass is the acceleration (div σ = 0).
module empm_exact_homogeneous
  use empm_kinds, only: wp
  use empm_mms, only: empm_mms_t
  use empm_tensor, only: identity3, mat_to_voigt, voigt_to_mat
  use empm_material_neohookean, only: empm_neohookean_cauchy
  implicit none
  private
  public :: empm_homogeneous_t, empm_expm, HOM_JAUMANN, HOM_SMALL_STRAIN, HOM_NEOHOOKEAN

  integer, parameter :: HOM_JAUMANN = 1      !! rate form, Jaumann rate
  integer, parameter :: HOM_SMALL_STRAIN = 2 !! rate form without rotation (the paper's update)
  integer, parameter :: HOM_NEOHOOKEAN = 3   !! compressible neo-Hookean

  !> Homogeneous motion v = G x and its stress.
  type, extends(empm_mms_t) :: empm_homogeneous_t
    real(wp) :: G(3,3) = 0.0_wp   !! velocity gradient [1/s] (zero outside ndim × ndim)
    real(wp) :: s0(6) = 0.0_wp    !! start stress, Voigt [Pa]
    real(wp) :: lambda = 0.0_wp   !! Lamé λ [Pa]
    real(wp) :: mu = 0.0_wp       !! shear modulus [Pa]
    integer :: kind = HOM_JAUMANN !! stress law (HOM_*)
  contains
    procedure :: fields => hom_fields
    procedure :: eval => hom_eval
    procedure :: stress => hom_stress
  end type empm_homogeneous_t

contains

  !> Exact fields at reference position X and time t.
  pure subroutine hom_fields(self, X, t, u, v, F, s, b)
    class(empm_homogeneous_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(:)          !! reference position (ndim) [m]
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(out) :: u(:)         !! displacement (ndim) [m]
    real(wp), intent(out) :: v(:)         !! velocity (ndim) [m/s]
    real(wp), intent(out) :: F(3,3)       !! deformation gradient
    real(wp), intent(out) :: s(6)         !! Cauchy stress, Voigt [Pa]
    real(wp), intent(out) :: b(:)         !! body force per unit mass (ndim) [m/s²]
    real(wp) :: x3(3), xv(3)
    integer :: d
    d = size(X)
    F = empm_expm(t * self%G)
    x3 = 0.0_wp; x3(1:d) = X
    x3 = matmul(F, x3)
    xv = matmul(self%G, x3)
    u = x3(1:d) - X
    v = xv(1:d)
    xv = matmul(self%G, xv)
    b = xv(1:d)
    s = self%stress(t)
  end subroutine hom_fields

  !> The body force (the acceleration G²F X) at every particle: one exponential per call.
  pure subroutine hom_eval(self, t, x0, x, b)
    class(empm_homogeneous_t), intent(in) :: self !! solution
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(in) :: x0(:,:)       !! reference positions (ndim, n) [m]
    real(wp), intent(in) :: x(:,:)        !! current positions (ndim, n), unused
    real(wp), intent(out) :: b(:,:)       !! body force per unit mass (ndim, n)
    real(wp) :: A(3,3), y(3)
    integer :: p, d
    associate (unused_ => x); end associate
    d = size(x0, 1)
    A = matmul(self%G, matmul(self%G, empm_expm(t * self%G)))
    b = 0.0_wp
    do p = 1, size(x0, 2)
      y = 0.0_wp; y(1:d) = x0(1:d, p)
      y = matmul(A, y)
      b(1:d, p) = y(1:d)
    end do
  end subroutine hom_eval

  !> The exact (uniform) Cauchy stress at time t, Voigt [Pa].
  pure function hom_stress(self, t) result(s)
    class(empm_homogeneous_t), intent(in) :: self !! solution
    real(wp), intent(in) :: t                     !! time [s]
    real(wp) :: s(6)
    ! 5-point Gauss–Legendre on NPANEL panels: the integrand is entire and its rotation stays
    ! below a few radians, so the quadrature error is far below round-off.
    integer, parameter :: NPANEL = 32
    real(wp), parameter :: xg(5) = [-0.906179845938663992797626878299_wp, &
      -0.538469310105683091036314420700_wp, 0.0_wp, 0.538469310105683091036314420700_wp, &
      0.906179845938663992797626878299_wp]
    real(wp), parameter :: wg(5) = [0.236926885056189087514264040720_wp, &
      0.478628670499366468041291514836_wp, 0.568888888888888888888888888889_wp, &
      0.478628670499366468041291514836_wp, 0.236926885056189087514264040720_wp]
    real(wp) :: D(3,3), W(3,3), Sm(3,3), Acc(3,3), Q(3,3), tau, h
    integer :: i, j
    D = 0.5_wp * (self%G + transpose(self%G)); W = 0.5_wp * (self%G - transpose(self%G))
    Sm = self%lambda * (D(1,1) + D(2,2) + D(3,3)) * identity3() + 2.0_wp * self%mu * D
    select case (self%kind)
    case (HOM_NEOHOOKEAN)
      s = mat_to_voigt(empm_neohookean_cauchy(self%mu, self%lambda, empm_expm(t * self%G)))
    case (HOM_SMALL_STRAIN)
      s = self%s0 + t * mat_to_voigt(Sm)
    case default
      Acc = 0.0_wp
      h = t / NPANEL
      do j = 1, NPANEL
        do i = 1, 5
          tau = h * (j - 1) + 0.5_wp * h * (xg(i) + 1.0_wp)
          Q = empm_expm(tau * W)
          Acc = Acc + (0.5_wp * h * wg(i)) * matmul(transpose(Q), matmul(Sm, Q))
        end do
      end do
      Q = empm_expm(t * W)
      s = mat_to_voigt(matmul(Q, matmul(voigt_to_mat(self%s0) + Acc, transpose(Q))))
    end select
  end function hom_stress

  !> The matrix exponential exp(A) of a 3 × 3 matrix: Taylor series of A/2ˢ (‖A/2ˢ‖₁ ≤ ½, 18
  !> terms: truncation below 1e-19) squared s times.
  pure function empm_expm(A) result(E)
    real(wp), intent(in) :: A(3,3) !! matrix
    real(wp) :: E(3,3)             !! exp(A)
    real(wp) :: B(3,3), P(3,3), nrm
    integer :: s, k
    nrm = maxval(sum(abs(A), dim=1))
    s = 0
    if (nrm > 0.5_wp) s = ceiling(log(nrm / 0.5_wp) / log(2.0_wp))
    B = A / 2.0_wp**s
    E = identity3(); P = identity3()
    do k = 1, 18
      P = matmul(P, B) / k
      E = E + P
    end do
    do k = 1, s
      E = matmul(E, E)
    end do
  end function empm_expm
end module empm_exact_homogeneous
