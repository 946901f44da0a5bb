!> Compressible neo-Hookean hyperelasticity, the form of the MPM manufactured-solution papers
!> (Wallstedt & Guilkey 2008; Steffen, Kirby & Berzins 2008):
!>
!>   ψ₀(F) = μ/2 (tr(FᵀF) − 3) − μ ln J + λ/2 (ln J)²     per reference volume,
!>   σ(F)  = (μ/J)(F Fᵀ − I) + (λ ln J / J) I              Cauchy stress, J = det F.
!>
!> Update: F ← (I + Δt L) F, a first-order (forward-Euler) integration of Ḟ = L F: exact for a
!> constant L with L² = 0 (e.g. simple shear), otherwise O(Δt²) per step, O(Δt) over a run.
!> The stress is then evaluated from F (total form: no objective stress rate is needed).
!> Density follows F: ρ ← ρ·J_old/J_new, i.e. ρ = ρ_p0/J for a particle that started at F = I
!> with density ρ_p0 (= ρ0/J when it started at the material's reference density ρ0).
!> The strain array receives sym(F) − I, for output only.
module empm_material_neohookean
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t
  use empm_material_linear_elastic, only: empm_elastic_check, empm_lame, empm_elastic_params, &
                                          empm_elastic_read, MAT_OK
  use empm_tensor, only: identity3, det3, mat_to_voigt, advance_f
  implicit none
  private
  public :: empm_neohookean_t, empm_neohookean_cauchy, empm_neohookean_energy

  !> Compressible neo-Hookean material.
  type, extends(empm_material_t) :: empm_neohookean_t
    real(wp) :: E = 0.0_wp      !! small-strain Young's modulus [Pa]
    real(wp) :: nu = 0.0_wp     !! small-strain Poisson's ratio [-]
    real(wp) :: lambda = 0.0_wp !! first Lamé parameter [Pa]
    real(wp) :: mu = 0.0_wp     !! shear modulus [Pa]
  contains
    procedure :: init => nh_init
    procedure :: configure => nh_configure
    procedure :: family => nh_family
    procedure :: summary => nh_summary
    procedure :: params => nh_params
    procedure :: update => nh_update
    procedure :: wave_speed => nh_wave_speed
    procedure :: energy_density => nh_energy_density
    procedure :: rate_form => nh_rate_form
  end type empm_neohookean_t

contains

  !> Cauchy stress σ = (μ/J)(F Fᵀ − I) + (λ ln J / J) I. Requires det F > 0 (not checked here:
  !> [[empm_neohookean_t(type):update]] never produces det F <= 0).
  pure function empm_neohookean_cauchy(mu, lambda, F) result(sigma)
    real(wp), intent(in) :: mu        !! shear modulus μ [Pa]
    real(wp), intent(in) :: lambda    !! Lamé λ [Pa]
    real(wp), intent(in) :: F(3,3)    !! deformation gradient, det F > 0
    real(wp) :: sigma(3,3)            !! Cauchy stress [Pa]
    real(wp) :: J, eye(3,3)
    J = det3(F)
    eye = identity3() ! a local: gfortran -O3 warns about the inlined function results
    sigma = (mu / J) * (matmul(F, transpose(F)) - eye) + (lambda * log(J) / J) * eye
  end function empm_neohookean_cauchy

  !> Stored energy ψ₀ = μ/2 (tr(FᵀF) − 3) − μ ln J + λ/2 (ln J)² per *reference* volume.
  !> Requires det F > 0.
  pure real(wp) function empm_neohookean_energy(mu, lambda, F) result(psi0)
    real(wp), intent(in) :: mu     !! shear modulus μ [Pa]
    real(wp), intent(in) :: lambda !! Lamé λ [Pa]
    real(wp), intent(in) :: F(3,3) !! deformation gradient, det F > 0
    real(wp) :: lnJ
    lnJ = log(det3(F))
    psi0 = 0.5_wp * mu * (sum(F * F) - 3.0_wp) - mu * lnJ + 0.5_wp * lambda * lnJ**2
  end function empm_neohookean_energy

  !> Set the constants after validating them; on failure `self` is left unchanged.
  pure subroutine nh_init(self, E, nu, rho0, info)
    class(empm_neohookean_t), intent(inout) :: self !! material
    real(wp), intent(in) :: E                       !! small-strain Young's modulus [Pa], > 0
    real(wp), intent(in) :: nu                      !! small-strain Poisson's ratio, in (−1, 0.5)
    real(wp), intent(in) :: rho0                    !! reference density [kg/m³], > 0
    integer, intent(out) :: info                    !! `MAT_OK` or `MAT_BAD_E|NU|RHO0`
    info = empm_elastic_check(E, nu, rho0)
    if (info /= MAT_OK) return
    self%E = E
    self%nu = nu
    self%rho0 = rho0
    call empm_lame(E, nu, self%lambda, self%mu)
  end subroutine nh_init

  !> Read `density`, `E` and `nu` (small-strain constants) from the `&material` group and set
  !> the constants.
  subroutine nh_configure(self, group, err)
    class(empm_neohookean_t), intent(inout) :: self !! material
    type(empm_group_t), intent(inout) :: group      !! the `&material` group
    type(empm_error_t), intent(inout) :: err        !! set on a missing or invalid value
    real(wp) :: E, nu, rho0
    integer :: info
    call empm_elastic_read(group, E, nu, rho0, err)
    if (err%code /= 0) return
    call self%init(E, nu, rho0, info)
    if (info /= MAT_OK) call group%fail(err, '', 'invalid elastic constants') ! checked above
  end subroutine nh_configure

  !> Registry name "neohookean".
  pure function nh_family(self) result(s)
    class(empm_neohookean_t), intent(in) :: self !! material
    character(len=:), allocatable :: s           !! "neohookean"
    associate (unused_ => self); end associate
    s = 'neohookean'
  end function nh_family

  !> One-line description.
  pure function nh_summary(self) result(s)
    class(empm_neohookean_t), intent(in) :: self !! material
    character(len=:), allocatable :: s           !! summary
    associate (unused_ => self); end associate
    s = 'compressible neo-Hookean hyperelasticity (finite strain, total form)'
  end function nh_summary

  !> Parameters: `density`, `E`, `nu`, the small-strain constants ([[empm_elastic_params]]).
  pure function nh_params(self) result(p)
    class(empm_neohookean_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:)      !! declarations
    associate (unused_ => self); end associate
    p = empm_elastic_params()
  end function nh_params

  !> Advance `n = size(rho)` particles (see the module notes).
  !> `info = k > 0`: det F <= 0 after the step at particle k (the first such), or already
  !> before it; that particle's state is left unchanged, the others are updated.
  !> `info = −1`: array extents disagree with n.
  pure subroutine nh_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_neohookean_t), intent(in) :: self !! material
    real(wp), intent(in) :: dt                   !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)           !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)        !! deformation gradient (3,3,n)
    real(wp), intent(inout), contiguous :: strain(:,:)     !! sym(F) − I on output, Voigt (6,n)
    real(wp), intent(inout), contiguous :: stress(:,:)     !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)      !! state variables, none used
    real(wp), intent(inout), contiguous :: rho(:)          !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx !! unused
    integer, intent(out) :: info                 !! 0 ok; k > 0 particle k failed; −1 shapes
    real(wp) :: eye(3,3), Fn(3,3), J0, J1
    integer :: p, n
    associate (unused_ => state, unused2_ => ctx); end associate
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n) then
      info = -1
      return
    end if
    eye = identity3()
    do p = 1, n
      J0 = det3(F(:,:,p))
      Fn = advance_f(dt, L(:,:,p), F(:,:,p))
      J1 = det3(Fn)
      ! Inverted or degenerate element: ln J is undefined, stop before producing NaN.
      if (J0 <= 0.0_wp .or. J1 <= 0.0_wp) then
        if (info == 0) info = p
        cycle
      end if
      F(:,:,p) = Fn
      stress(:,p) = mat_to_voigt(empm_neohookean_cauchy(self%mu, self%lambda, Fn))
      strain(:,p) = mat_to_voigt(Fn - eye)
      rho(p) = rho(p) * (J0 / J1)
    end do
  end subroutine nh_update

  !> F-based, not rate-form: F advances with I + ΔtL ([[empm_material_t]]'s `rate_form`).
  pure logical function nh_rate_form(self) result(r)
    class(empm_neohookean_t), intent(in) :: self !! material
    associate (unused_ => self); end associate
    r = .false.
  end function nh_rate_form

  !> Small-strain P-wave speed sqrt((λ + 2μ)/ρ) [m/s]. The tangent stiffness of this model
  !> stays close to λ + 2μ for moderate strains; for large compression the true speed is
  !> higher, so use a CFL safety margin there.
  pure real(wp) function nh_wave_speed(self, rho)
    class(empm_neohookean_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho                  !! current density [kg/m³]
    nh_wave_speed = sqrt((self%lambda + 2.0_wp * self%mu) / rho)
  end function nh_wave_speed

  !> Energy per current volume ψ₀(F)/J from F alone. A particle with det F <= 0 (never produced
  !> by the update) gets huge(), the limit of ψ as J → 0⁺.
  pure subroutine nh_energy_density(self, F, strain, stress, state, psi)
    class(empm_neohookean_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)             !! deformation gradient (3,3,n)
    real(wp), intent(in) :: strain(:,:)          !! small strain (6,n), unused
    real(wp), intent(in) :: stress(:,:)          !! Cauchy stress (6,n), unused
    real(wp), intent(in) :: state(:,:)           !! state variables, unused
    real(wp), intent(out) :: psi(:)              !! ψ₀/J (n) [J/m³]
    real(wp) :: J
    integer :: p
    associate (unused_ => state); end associate
    ! Bound by every extent so that a short argument can never be read past its end.
    do p = 1, min(size(psi), size(F, 3), size(strain, 2), size(stress, 2))
      J = det3(F(:,:,p))
      if (J > 0.0_wp) then
        psi(p) = empm_neohookean_energy(self%mu, self%lambda, F(:,:,p)) / J
      else
        psi(p) = huge(1.0_wp)
      end if
    end do
  end subroutine nh_energy_density
end module empm_material_neohookean
