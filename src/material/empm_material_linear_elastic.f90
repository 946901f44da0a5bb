!> Isotropic linear elasticity, hypoelastic update (paper eqs. 2–4, 18–19), objective by default.
!>
!> Each step: Δε = Δt·sym(L), ε ← ε + Δε, σ ← σ + D:Δε with the isotropic D (Lamé λ, μ),
!> ρ ← ρ/(1 + tr Δε) (eq. 19; ρ/det ΔF with the midpoint kinematics of `pc_newmark` and
!> `gen_alpha`, [[volume_ratio]]). With `rate = 'jaumann'` (the default) the stress is first
!> rotated with the spin of the step (σ ← QσQᵀ, Q the orthogonal Cayley rotation of ΔtW,
!> [[jaumann_rotate]]), so that a body in rigid rotation carries its stress with it, and Δε is
!> turned by half that rotation ([[corotated_increment]]: second order under strain with spin);
!> `rate = 'small_strain'` is the paper's update, which omits the rotation. The two agree
!> wherever W = 0 (always in 1D). 1D uniaxial strain and 2D plane strain need no special case:
!> the velocity gradient is zero in the unused directions, so the lateral stresses come out
!> as λ·tr Δε by themselves. The small-strain model does not track the deformation gradient: F
!> is left as it is (identity) — updating it cost a third of the stress phase's memory traffic and
!> nothing reads it.
!>
!> The module also holds what every isotropic elastic model shares: the parameter declarations
!> [[empm_elastic_params]] and their reader [[empm_elastic_read]], the parameter check
!> [[empm_elastic_check]], the Lamé conversion [[empm_lame]] and the `MAT_*` status codes.
module empm_material_linear_elastic
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_STR
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t
  use empm_plasticity, only: jaumann_rotate_block, volume_ratio, strain_increment, &
    corotated_increment
  implicit none
  private
  public :: empm_linear_elastic_t, empm_elastic_check, empm_lame
  public :: empm_elastic_params, empm_elastic_read, empm_rate_param, empm_rate_read
  public :: MAT_OK, MAT_BAD_E, MAT_BAD_NU, MAT_BAD_RHO0

  integer, parameter :: MAT_OK = 0       !! parameters valid / update succeeded
  integer, parameter :: MAT_BAD_E = 2    !! Young's modulus not in (0, huge)
  integer, parameter :: MAT_BAD_NU = 3   !! Poisson's ratio not in (−1, 0.5)
  integer, parameter :: MAT_BAD_RHO0 = 4 !! reference density not in (0, huge)

  !> Isotropic small-strain linear-elastic material.
  type, extends(empm_material_t) :: empm_linear_elastic_t
    real(wp) :: E = 0.0_wp      !! Young's modulus [Pa]
    real(wp) :: nu = 0.0_wp     !! Poisson's ratio [-]
    real(wp) :: lambda = 0.0_wp !! first Lamé parameter [Pa]
    real(wp) :: mu = 0.0_wp     !! shear modulus [Pa]
    logical :: jaumann = .true. !! rotate the stress with the spin (objective rate)
  contains
    procedure :: init => le_init
    procedure :: configure => le_configure
    procedure :: family => le_family
    procedure :: summary => le_summary
    procedure :: params => le_params
    procedure :: update => le_update
    procedure :: wave_speed => le_wave_speed
    procedure :: energy_density => le_energy_density
  end type empm_linear_elastic_t

contains

  !> The parameters of an isotropic elastic model: `density`, `E`, `nu`.
  pure function empm_elastic_params() result(p)
    type(empm_param_t), allocatable :: p(:) !! declarations
    p = [ &
      ! The magnitudes are bounded so that the wave speed sqrt(E/rho) and the step's products
      ! stay far from overflow (a density of 1e-308 made the CFL time step overflow).
      empm_param('density', PARAM_REAL, 'kg/m3', 'initial density', lo=1.0e-30_wp, &
        hi=1.0e30_wp), &
      empm_param('E', PARAM_REAL, 'Pa', "Young's modulus", lo=0.0_wp, lo_open=.true., &
        hi=1.0e30_wp), &
      empm_param('nu', PARAM_REAL, '-', "Poisson's ratio", default='0', lo=-1.0_wp, &
        hi=0.5_wp, lo_open=.true., hi_open=.true.)]
  end function empm_elastic_params

  !> The `rate` key of the rate-form models: 'jaumann' (objective, the default) or
  !> 'small_strain' (no rotation, the paper's update).
  pure function empm_rate_param() result(p)
    type(empm_param_t) :: p !! declaration
    p = empm_param('rate', PARAM_STR, '-', "stress rate: 'jaumann' (objective: the stress " &
      //"rotates with the spin of the velocity gradient) or 'small_strain' (the paper's update, " &
      //'without rotation)', default="'jaumann'", choices='jaumann small_strain')
  end function empm_rate_param

  !> Read the `rate` key ([[empm_rate_param]]): true for 'jaumann'.
  subroutine empm_rate_read(group, jaumann, err)
    type(empm_group_t), intent(inout) :: group !! the `&material` group
    logical, intent(out) :: jaumann            !! objective (Jaumann) rate
    type(empm_error_t), intent(inout) :: err   !! set on an invalid value
    character(len=:), allocatable :: rate
    rate = 'jaumann'
    call group%get(empm_rate_param(), rate, err)
    jaumann = rate == 'jaumann'
  end subroutine empm_rate_read

  !> Read and validate `density`, `E` and `nu` ([[empm_elastic_params]]) from a `&material`
  !> group; `err` names the key of the first missing or invalid one. The bounds are those of
  !> [[empm_elastic_check]] (the reader rejects non-finite numbers).
  subroutine empm_elastic_read(group, E, nu, rho0, err)
    type(empm_group_t), intent(inout) :: group !! the `&material` group
    real(wp), intent(out) :: E                 !! Young's modulus [Pa]
    real(wp), intent(out) :: nu                !! Poisson's ratio [-]
    real(wp), intent(out) :: rho0              !! reference density [kg/m³]
    type(empm_error_t), intent(inout) :: err   !! set on a missing or invalid value
    type(empm_param_t) :: p(3)
    integer :: info
    p = empm_elastic_params()
    E = 0.0_wp; nu = 0.0_wp; rho0 = 0.0_wp
    call group%get(p(1), rho0, err)
    call group%get(p(2), E, err)
    call group%get(p(3), nu, err)
    if (err%code /= 0) return
    ! The declarations already hold these bounds; the check keeps the two in step.
    info = empm_elastic_check(E, nu, rho0)
    select case (info)
    case (MAT_BAD_E)
      call group%fail(err, p(2)%name, "Young's modulus must be positive and finite")
    case (MAT_BAD_NU)
      call group%fail(err, p(3)%name, "Poisson's ratio must satisfy -1 < nu < 0.5")
    case (MAT_BAD_RHO0)
      call group%fail(err, p(1)%name, 'the density must be positive and finite')
    end select
  end subroutine empm_elastic_read

  !> Check isotropic elastic constants: `MAT_OK`, or the code of the first invalid one.
  !> NaN fails every test (comparisons with NaN are false), so it is rejected too.
  pure integer function empm_elastic_check(E, nu, rho0) result(info)
    real(wp), intent(in) :: E    !! Young's modulus [Pa], must be in (0, huge)
    real(wp), intent(in) :: nu   !! Poisson's ratio, must be in (−1, 0.5)
    real(wp), intent(in) :: rho0 !! reference density [kg/m³], must be in (0, huge)
    info = MAT_OK
    if (.not. (E > 0.0_wp .and. E <= huge(E))) then
      info = MAT_BAD_E
    else if (.not. (nu > -1.0_wp .and. nu < 0.5_wp)) then
      info = MAT_BAD_NU
    else if (.not. (rho0 > 0.0_wp .and. rho0 <= huge(rho0))) then
      info = MAT_BAD_RHO0
    end if
  end function empm_elastic_check

  !> Lamé parameters from Young's modulus and Poisson's ratio (valid E, ν assumed).
  pure subroutine empm_lame(E, nu, lambda, mu)
    real(wp), intent(in) :: E       !! Young's modulus [Pa]
    real(wp), intent(in) :: nu      !! Poisson's ratio, in (−1, 0.5)
    real(wp), intent(out) :: lambda !! λ = Eν/((1+ν)(1−2ν)) [Pa]
    real(wp), intent(out) :: mu     !! μ = E/(2(1+ν)) [Pa]
    lambda = E * nu / ((1.0_wp + nu) * (1.0_wp - 2.0_wp * nu))
    mu = E / (2.0_wp * (1.0_wp + nu))
  end subroutine empm_lame

  !> Set the constants after validating them; on failure `self` is left unchanged.
  pure subroutine le_init(self, E, nu, rho0, info)
    class(empm_linear_elastic_t), intent(inout) :: self !! material
    real(wp), intent(in) :: E                           !! Young's modulus [Pa], > 0
    real(wp), intent(in) :: nu                          !! Poisson's ratio, in (−1, 0.5)
    real(wp), intent(in) :: rho0                        !! reference density [kg/m³], > 0
    integer, intent(out) :: info                        !! `MAT_OK` or `MAT_BAD_E|NU|RHO0`
    info = empm_elastic_check(E, nu, rho0)
    if (info /= MAT_OK) return
    self%E = E
    self%nu = nu
    self%rho0 = rho0
    call empm_lame(E, nu, self%lambda, self%mu)
  end subroutine le_init

  !> Read `density`, `E` and `nu` from the `&material` group and set the constants.
  subroutine le_configure(self, group, err)
    class(empm_linear_elastic_t), intent(inout) :: self !! material
    type(empm_group_t), intent(inout) :: group          !! the `&material` group
    type(empm_error_t), intent(inout) :: err            !! set on a missing or invalid value
    real(wp) :: E, nu, rho0
    integer :: info
    call empm_elastic_read(group, E, nu, rho0, err)
    call empm_rate_read(group, self%jaumann, err)
    if (err%code /= 0) return
    call self%init(E, nu, rho0, info)
    if (info /= MAT_OK) call group%fail(err, '', 'invalid elastic constants') ! checked above
  end subroutine le_configure

  !> Registry name "linear_elastic".
  pure function le_family(self) result(s)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    character(len=:), allocatable :: s               !! "linear_elastic"
    associate (unused_ => self); end associate
    s = 'linear_elastic'
  end function le_family

  !> One-line description.
  pure function le_summary(self) result(s)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    character(len=:), allocatable :: s               !! summary
    associate (unused_ => self); end associate
    s = 'isotropic linear elasticity, hypoelastic: Jaumann rate, or the paper''s small-strain update'
  end function le_summary

  !> Parameters: `density`, `E`, `nu` ([[empm_elastic_params]]) and `rate`.
  pure function le_params(self) result(p)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:)          !! declarations
    associate (unused_ => self); end associate
    p = [empm_elastic_params(), empm_rate_param()]
  end function le_params

  !> Hypoelastic update of `n = size(rho)` particles (see the module notes).
  !> `info = k > 0`: 1 + tr Δε <= 0 at particle k (the first such), whose state is left
  !> unchanged (the other particles are updated); `info = -1`: array extents disagree with n.
  pure subroutine le_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    real(wp), intent(in) :: dt                       !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)           !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)        !! deformation gradient (3,3,n), left unchanged
    real(wp), intent(inout), contiguous :: strain(:,:)     !! small strain, Voigt (6,n)
    real(wp), intent(inout), contiguous :: stress(:,:)     !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)      !! state variables, none used
    real(wp), intent(inout), contiguous :: rho(:)          !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx     !! the kinematics' form (`midpoint`)
    integer, intent(out) :: info                     !! 0 ok; k > 0 particle k failed; −1 shapes
    real(wp) :: de(6), tr, jv
    integer :: p, n
    associate (unused_ => state); end associate
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n) then
      info = -1
      return
    end if
    ! The rotation of the start-of-step stresses first, for the block (a call per particle
    ! cost as much as the rotation); the particles the loop below rejects are not rotated.
    ! The Jaumann increment is then the corotated one (second order under strain with spin).
    if (self%jaumann) call jaumann_rotate_block(dt, n, L, stress, ctx%midpoint)
    do p = 1, n
      if (ctx%midpoint) then
        jv = volume_ratio(dt, L(:,:,p), .true.)
      else
        jv = 1.0_wp + (dt * L(1,1,p) + dt * L(2,2,p) + dt * L(3,3,p))
      end if
      ! eq. (19) integrated over the step; a non-positive volume ratio is unphysical.
      if (jv <= 0.0_wp) then
        if (info == 0) info = p
        cycle
      end if
      if (self%jaumann) then
        de = corotated_increment(dt, L(:,:,p))
      else
        de = strain_increment(dt, L(:,:,p))
      end if
      tr = de(1) + de(2) + de(3)
      strain(:,p) = strain(:,p) + de
      stress(1:3,p) = stress(1:3,p) + self%lambda * tr + 2.0_wp * self%mu * de(1:3)
      stress(4:6,p) = stress(4:6,p) + 2.0_wp * self%mu * de(4:6)
      rho(p) = rho(p) / jv
    end do
  end subroutine le_update

  !> P-wave speed sqrt((λ + 2μ)/ρ) [m/s].
  pure real(wp) function le_wave_speed(self, rho)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho                      !! current density [kg/m³]
    le_wave_speed = sqrt((self%lambda + 2.0_wp * self%mu) / rho)
  end function le_wave_speed

  !> Energy density ½ σ:ε per current volume (small strain: current ≈ reference volume).
  !> Exact for a stress built from zero by this model; F is not needed.
  pure subroutine le_energy_density(self, F, strain, stress, state, psi)
    class(empm_linear_elastic_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)                 !! deformation gradient (3,3,n), unused
    real(wp), intent(in) :: strain(:,:)              !! small strain, Voigt (6,n)
    real(wp), intent(in) :: stress(:,:)              !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)               !! state variables, unused
    real(wp), intent(out) :: psi(:)                  !! ½ σ:ε (n) [J/m³]
    integer :: n
    associate (unused_ => state); end associate
    ! Bound by every extent so that a short argument can never be read past its end.
    n = min(size(psi), size(strain, 2), size(stress, 2), size(F, 3))
    if (n > 0) call half_ddot(n, stress, strain, psi)
    associate (unused => self) ! the energy needs no material constant
    end associate
  end subroutine le_energy_density

  ! ψ = ½ σ:ε over explicit-shape (contiguous) arrays, so that the loop vectorises; voigt_ddot
  ! written out (a call per particle cost as much as the product). Called with sections of
  ! the particles' whole columns: no copy.
  pure subroutine half_ddot(n, stress, strain, psi)
    integer, intent(in) :: n
    real(wp), intent(in) :: stress(6, n), strain(6, n)
    real(wp), intent(inout) :: psi(n)
    integer :: p
    do p = 1, n
      psi(p) = 0.5_wp * (stress(1,p) * strain(1,p) + stress(2,p) * strain(2,p) &
        + stress(3,p) * strain(3,p) &
        + 2.0_wp * (stress(4,p) * strain(4,p) + stress(5,p) * strain(5,p) + stress(6,p) * strain(6,p)))
    end do
  end subroutine half_ddot
end module empm_material_linear_elastic
