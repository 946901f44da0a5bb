!> Drucker–Prager elastoplasticity for soils: perfectly plastic linear cone with a non-associated
!> plastic potential and a tension cut-off on the mean stress, integrated with a closed-form
!> return mapping that handles the apex (see docs/materials.md, `drucker_prager`).
!>
!> With m = tr σ/3 (tension positive; m = −p'), s = dev σ and t = √J₂ = √(½ s:s):
!>
!>   yield     f   = t + η m − ξ c ≤ 0,        tension cut-off  f_T = m − T ≤ 0,
!>   potential g   = t + η_ψ m,                 flow Δεᵖ = Δλ (s/(2t) + η_ψ/3 I) (+ Δλ_T I/3).
!>
!> η, ξ (and η_ψ with ψ in place of φ) match Mohr–Coulomb in plane strain, at the outer
!> (triaxial compression) or at the inner (triaxial extension) corners, chosen by `match`.
!> The apex of the cone lies at m_A = ξc/η; the cut-off T defaults to it and may not exceed it.
!>
!> Step: Δε = Δt·sym(L) turned by half the step's rotation ([[corotated_increment]]),
!> σ ← Q σ Qᵀ ([[jaumann_rotate]]), trial σᵗʳ = σ + K tr Δε I + 2G dev Δε.
!> If f(σᵗʳ) ≤ 0 and mᵗʳ ≤ T the step is elastic (the common case, checked first). Otherwise
!> the return is found in closed form in the (m, t) plane, the deviator keeping its direction:
!> - cone:    Δλ = f(σᵗʳ)/(G + K η η_ψ), t = tᵗʳ − GΔλ, m = mᵗʳ − K η_ψ Δλ, valid when t ≥ 0
!>            and m ≤ T;
!> - tension: m = T, s = sᵗʳ (when tᵗʳ ≤ t_T = ξc − ηT, the cone's radius at m = T);
!> - corner:  m = T, t = t_T (the apex itself when T = m_A: σ = m_A I). With a non-associated
!>            potential the apex return is the corner with t_T = 0: the deviator is removed and the
!>            mean stress is set to the apex, whatever ψ.
!> Each plastic multiplier of the chosen region is non-negative exactly when the region applies,
!> so the three cover every trial state without overlap. For a linear yield line and a fixed
!> return direction the map is affine in the trial point: on strain paths whose deviatoric
!> increments are parallel to the stress deviator (every proportional path from an isotropic
!> stress, simple shear, triaxial paths) the result does not depend on how an increment is split,
!> to round-off. On non-coaxial paths the return is the backward-Euler solution, first-order
!> accurate in the increment (measured in the tests and documented).
!>
!> State variables: `eps_p_eq` accumulates Δε̄ᵖ = √(2/3 Δeᵖ:Δeᵖ) = (tᵗʳ − t)/(√3 G) and
!> `eps_p_vol` accumulates tr Δεᵖ = (mᵗʳ − m)/K. Density: ρ ← ρ/(1 + tr Δε); strain ← strain + Δε.
module empm_material_drucker_prager
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_STR
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t, STATE_NAME_LEN
  use empm_material_linear_elastic, only: empm_elastic_params, empm_elastic_read, empm_lame
  use empm_plasticity, only: jaumann_rotate, corotated_increment, volume_ratio
  implicit none
  private
  public :: empm_drucker_prager_t, empm_dp_match, empm_dp_return, empm_dp_tangent
  public :: DP_ELASTIC, DP_CONE, DP_TENSION, DP_CORNER

  integer, parameter :: DP_ELASTIC = 0 !! region of a return: trial state admissible
  integer, parameter :: DP_CONE = 1    !! return to the cone
  integer, parameter :: DP_TENSION = 2 !! return to the tension cut-off only
  integer, parameter :: DP_CORNER = 3  !! return to the cone/cut-off corner (the apex when T = m_A)

  !> Largest apex or cut-off kept: a cone with φ so small that ξc/η would overflow has,
  !> in practice, no apex.
  real(wp), parameter :: NO_APEX = 1.0e300_wp
  integer, parameter :: SUBSTEP_LEVELS = 16 !! substeps down to 2^-16 of a step

  !> Drucker–Prager material (perfect plasticity, non-associated, tension cut-off).
  type, extends(empm_material_t) :: empm_drucker_prager_t
    real(wp) :: E = 0.0_wp        !! Young's modulus [Pa]
    real(wp) :: nu = 0.0_wp       !! Poisson's ratio [-]
    real(wp) :: lambda = 0.0_wp   !! first Lamé parameter [Pa]
    real(wp) :: G = 0.0_wp        !! shear modulus [Pa]
    real(wp) :: K = 0.0_wp        !! bulk modulus [Pa]
    real(wp) :: c = 0.0_wp        !! cohesion [Pa]
    real(wp) :: phi = 0.0_wp      !! friction angle [deg]
    real(wp) :: psi = 0.0_wp      !! dilatancy angle [deg]
    character(len=16) :: match = 'plane_strain' !! Mohr–Coulomb matching
    real(wp) :: eta = 0.0_wp      !! friction coefficient η of the yield cone
    real(wp) :: xi = 1.0_wp       !! cohesion coefficient ξ of the yield cone
    real(wp) :: eta_psi = 0.0_wp  !! dilatancy coefficient η_ψ of the plastic potential
    real(wp) :: xic = 0.0_wp      !! ξc: the cone's radius t at m = 0 [Pa]
    real(wp) :: apex = NO_APEX    !! apex mean stress m_A = ξc/η [Pa] (NO_APEX if η = 0)
    real(wp) :: T = NO_APEX       !! tension cut-off on m [Pa], 0 <= T <= m_A
    real(wp) :: tT = 0.0_wp       !! cone radius at the cut-off, t_T = ξc − ηT >= 0 [Pa]
    real(wp) :: H = 0.0_wp        !! G + K η η_ψ, the cone return's modulus [Pa]
    real(wp) :: substep_tol = 0.0_wp !! substepping tolerance (0: one return per step)
  contains
    procedure :: init => dp_init
    procedure :: configure => dp_configure
    procedure :: family => dp_family
    procedure :: summary => dp_summary
    procedure :: params => dp_params
    procedure :: state_names => dp_state_names
    procedure :: update => dp_update
    procedure :: wave_speed => dp_wave_speed
    procedure :: energy_density => dp_energy_density
    procedure :: failure_text => dp_failure_text
  end type empm_drucker_prager_t

contains

  !> Cone coefficients matched to Mohr–Coulomb with angle `angle` [deg]:
  !> 'plane_strain' η = 3 tanφ/√(9 + 12 tan²φ), ξ = 3/√(9 + 12 tan²φ);
  !> 'compression' (outer cone) η = 6 sinφ/(√3(3 − sinφ)), ξ = 6 cosφ/(√3(3 − sinφ));
  !> 'extension' (inner cone) the same with 3 + sinφ. For φ = 0 every match has η = 0;
  !> ξ = 1 in plane strain (√J₂ = c, Tresca in plane strain) and 2/√3 for the other two
  !> (q = 2c, Tresca in triaxial compression or extension).
  pure subroutine empm_dp_match(match, angle, eta, xi)
    character(len=*), intent(in) :: match !! 'plane_strain' | 'compression' | 'extension'
    real(wp), intent(in) :: angle          !! friction (or dilatancy) angle [deg], in [0, 90)
    real(wp), intent(out) :: eta           !! η (η_ψ for the dilatancy angle)
    real(wp), intent(out) :: xi            !! ξ
    real(wp), parameter :: DEG = acos(-1.0_wp) / 180.0_wp
    real(wp) :: ta, sa, d
    select case (match)
    case ('compression', 'extension')
      sa = sin(angle * DEG)
      if (match == 'compression') then
        d = sqrt(3.0_wp) * (3.0_wp - sa)
      else
        d = sqrt(3.0_wp) * (3.0_wp + sa)
      end if
      eta = 6.0_wp * sa / d
      xi = 6.0_wp * cos(angle * DEG) / d
    case default ! plane_strain
      ta = tan(angle * DEG)
      d = sqrt(9.0_wp + 12.0_wp * ta**2)
      eta = 3.0_wp * ta / d
      xi = 3.0_wp / d
    end select
  end subroutine empm_dp_match

  !> Set the constants (valid values assumed, as checked by `configure`): E, ν, density,
  !> cohesion, friction and dilatancy angles [deg], match, and the cut-off (`T < 0`: the apex).
  !> `info` = 0, or 1 when T exceeds the apex (then `self` is incomplete).
  pure subroutine dp_init(self, E, nu, rho0, c, phi, psi, match, T, info)
    class(empm_drucker_prager_t), intent(inout) :: self !! material
    real(wp), intent(in) :: E                           !! Young's modulus [Pa]
    real(wp), intent(in) :: nu                          !! Poisson's ratio
    real(wp), intent(in) :: rho0                        !! reference density [kg/m³]
    real(wp), intent(in) :: c                           !! cohesion [Pa], >= 0
    real(wp), intent(in) :: phi                         !! friction angle [deg], in [0, 90)
    real(wp), intent(in) :: psi                         !! dilatancy angle [deg], in [0, φ]
    character(len=*), intent(in) :: match               !! Mohr–Coulomb matching
    real(wp), intent(in) :: T                           !! tension cut-off [Pa]; < 0: the apex
    integer, intent(out) :: info                        !! 0, or 1: T above the apex
    real(wp) :: xi_psi
    info = 0
    self%E = E; self%nu = nu; self%rho0 = rho0
    call empm_lame(E, nu, self%lambda, self%G)
    self%K = E / (3.0_wp * (1.0_wp - 2.0_wp * nu))
    self%c = c; self%phi = phi; self%psi = psi; self%match = match
    call empm_dp_match(match, phi, self%eta, self%xi)
    call empm_dp_match(match, psi, self%eta_psi, xi_psi)
    self%xic = self%xi * c
    ! η < 1 always, so η·NO_APEX cannot overflow; a cone too flat to have a finite apex has none.
    if (self%xic < self%eta * NO_APEX) then
      self%apex = self%xic / self%eta
    else
      self%apex = NO_APEX
    end if
    if (T < 0.0_wp) then
      self%T = self%apex
      ! At the apex the cone's radius is zero: set it exactly, not as a difference.
      self%tT = merge(0.0_wp, self%xic, self%apex < NO_APEX)
    else
      ! A value a few ulps above the apex (e.g. the apex as printed) is clipped to it.
      if (T > self%apex * (1.0_wp + 8.0_wp * epsilon(1.0_wp))) then
        info = 1
        return
      end if
      self%T = min(T, self%apex)
      self%tT = max(0.0_wp, self%xic - self%eta * self%T)
    end if
    self%H = self%G + self%K * self%eta * self%eta_psi
  end subroutine dp_init

  !> Read `density`, `E`, `nu`, `cohesion`, `friction_angle`, `dilatancy_angle`,
  !> `tension_cutoff` and `match`; ψ > φ and a cut-off above the apex are errors naming the key.
  subroutine dp_configure(self, group, err)
    class(empm_drucker_prager_t), intent(inout) :: self !! material
    type(empm_group_t), intent(inout) :: group          !! the `&material` group
    type(empm_error_t), intent(inout) :: err            !! set on a missing or invalid value
    type(empm_param_t), allocatable :: p(:)
    real(wp) :: E, nu, rho0, c, phi, psi, T, tol
    character(len=:), allocatable :: match
    character(len=32) :: buf
    integer :: info
    allocate(p, source=dp_own_params())
    call empm_elastic_read(group, E, nu, rho0, err)
    c = 0.0_wp; phi = 0.0_wp; psi = 0.0_wp; T = -1.0_wp; match = 'plane_strain'
    call group%get(p(1), c, err)
    call group%get(p(2), phi, err)
    call group%get(p(3), psi, err)
    call group%get(p(4), T, err)
    call group%get(p(5), match, err)
    tol = 0.0_wp
    call group%get(p(6), tol, err)
    if (err%code /= 0) return
    if (psi > phi) then
      call group%fail(err, p(3)%name, 'the dilatancy angle must not exceed friction_angle')
      return
    end if
    call self%init(E, nu, rho0, c, phi, psi, match, T, info)
    self%substep_tol = tol
    if (info /= 0) then
      write(buf, '(es12.5)') self%apex
      call group%fail(err, p(4)%name, 'the tension cut-off must not exceed the cone''s apex '// &
        'xi*c/eta = '//trim(adjustl(buf))//' Pa')
    end if
  end subroutine dp_configure

  !> The model's own keys (after `density`, `E`, `nu`).
  pure function dp_own_params() result(p)
    type(empm_param_t), allocatable :: p(:) !! declarations
    p = [ &
      empm_param('cohesion', PARAM_REAL, 'Pa', 'cohesion c (0: cohesionless, the apex at m = 0)', &
        lo=0.0_wp, hi=1.0e30_wp), &
      empm_param('friction_angle', PARAM_REAL, 'deg', 'friction angle phi (0: von Mises, '// &
        'Tresca-matched)', lo=0.0_wp, hi=90.0_wp, hi_open=.true.), &
      empm_param('dilatancy_angle', PARAM_REAL, 'deg', 'dilatancy angle psi of the plastic '// &
        'potential, at most friction_angle (= friction_angle: associated flow)', default='0', &
        lo=0.0_wp, hi=90.0_wp, hi_open=.true.), &
      empm_param('tension_cutoff', PARAM_REAL, 'Pa', 'largest mean stress tr(sigma)/3 '// &
        '(tension positive); default and upper limit: the apex xi*c/eta of the cone '// &
        '(none when friction_angle = 0)', lo=0.0_wp, hi=1.0e30_wp, optional=.true.), &
      empm_param('match', PARAM_STR, '-', 'cone matched to Mohr-Coulomb in plane strain, at '// &
        'the triaxial compression (outer) or the triaxial extension (inner) corners', &
        default="'plane_strain'", choices='plane_strain compression extension'), &
      empm_param('substep_tolerance', PARAM_REAL, '-', 'relative local error of the return '// &
        'per substep (one return against two over the halves, extrapolated); 0: one return '// &
        'per step, first order in the increment on non-coaxial paths (docs/materials.md)', &
        default='0', lo=0.0_wp, hi=1.0e-2_wp)]
  end function dp_own_params

  !> Registry name "drucker_prager".
  pure function dp_family(self) result(s)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    character(len=:), allocatable :: s               !! "drucker_prager"
    associate (unused_ => self); end associate
    s = 'drucker_prager'
  end function dp_family

  !> One-line description.
  pure function dp_summary(self) result(s)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    character(len=:), allocatable :: s               !! summary
    associate (unused_ => self); end associate
    s = 'Drucker-Prager perfect plasticity (non-associated, tension cut-off), closed-form return'
  end function dp_summary

  !> Parameters: `density`, `E`, `nu` and the model's own ([[dp_own_params]]).
  pure function dp_params(self) result(p)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:)          !! declarations
    associate (unused_ => self); end associate
    p = [empm_elastic_params(), dp_own_params()]
  end function dp_params

  !> State variables: `eps_p_eq` (accumulated √(2/3 Δeᵖ:Δeᵖ)) and `eps_p_vol` (tr εᵖ).
  pure subroutine dp_state_names(self, names)
    class(empm_drucker_prager_t), intent(in) :: self                    !! material
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:) !! names
    associate (unused_ => self); end associate
    allocate(names(2))
    names(1) = 'eps_p_eq'
    names(2) = 'eps_p_vol'
  end subroutine dp_state_names

  !> Return mapping of a trial stress (see the module notes): the admissible stress `sig`, the
  !> `region` (DP_ELASTIC, DP_CONE, DP_TENSION or DP_CORNER), and the trial's mean stress and
  !> radius `m_tr`, `t_tr` and the result's `m`, `t` (for the plastic strains).
  pure subroutine empm_dp_return(mat, sig_tr, sig, region, m_tr, t_tr, m, t)
    type(empm_drucker_prager_t), intent(in) :: mat !! material
    real(wp), intent(in) :: sig_tr(6)              !! trial stress, Voigt [Pa]
    real(wp), intent(out) :: sig(6)                !! returned stress [Pa]
    integer, intent(out) :: region                 !! DP_* region
    real(wp), intent(out) :: m_tr, t_tr, m, t      !! mean stresses and radii √J₂ [Pa]
    real(wp) :: s(6), f, dlam, scale
    m_tr = (sig_tr(1) + sig_tr(2) + sig_tr(3)) / 3.0_wp
    s(1:3) = sig_tr(1:3) - m_tr
    s(4:6) = sig_tr(4:6)
    t_tr = sqrt(0.5_wp * (s(1)**2 + s(2)**2 + s(3)**2) + s(4)**2 + s(5)**2 + s(6)**2)
    f = t_tr + mat%eta * m_tr - mat%xic
    m = m_tr; t = t_tr
    if (f <= 0.0_wp .and. m_tr <= mat%T) then
      region = DP_ELASTIC
      sig = sig_tr
      return
    end if
    region = DP_TENSION
    if (f > 0.0_wp) then
      dlam = f / mat%H
      t = t_tr - mat%G * dlam
      m = m_tr - mat%K * mat%eta_psi * dlam
      if (t >= 0.0_wp .and. m <= mat%T) then
        region = DP_CONE
      else if (t_tr > mat%tT) then
        region = DP_CORNER
      end if
    end if
    select case (region)
    case (DP_CONE)
      scale = t / t_tr ! t_tr >= G dlam > 0 here
    case (DP_CORNER)
      m = mat%T; t = mat%tT
      scale = t / t_tr ! t_tr > tT >= 0 here
    case default
      m = mat%T; t = t_tr
      scale = 1.0_wp
    end select
    sig(1:3) = scale * s(1:3) + m
    sig(4:6) = scale * s(4:6)
  end subroutine empm_dp_return

  !> Algorithmic (consistent) tangent D = ∂σ/∂Δε of the return mapping at the trial stress
  !> `sig_tr` (perfect plasticity, exact derivative of [[empm_dp_return]] within its region),
  !> Voigt 6×6 acting on tensor-shear strain components: D(i,j) = ∂σ_i/∂ε_j with ε_j the Voigt
  !> component (for a shear, both symmetric entries move). Cone, with n = sᵗʳ/|sᵗʳ|,
  !> β = GΔλ/tᵗʳ:  dσ = 2G(1−β) de + 2G(β − G/H) n (n:de) − (√2 GKη/H) n dε_v
  !>                    + [K(1 − Kηη_ψ/H) dε_v − (√2 GKη_ψ/H) n:de] I;
  !> tension: dσ = 2G de; corner: dσ = 2G (t_T/tᵗʳ)(de − n (n:de)) (zero at the apex).
  pure subroutine empm_dp_tangent(mat, sig_tr, D)
    type(empm_drucker_prager_t), intent(in) :: mat !! material
    real(wp), intent(in) :: sig_tr(6)              !! trial stress, Voigt [Pa]
    real(wp), intent(out) :: D(6,6)                !! ∂σ/∂Δε [Pa]
    real(wp) :: sig(6), m_tr, t_tr, m, t, n(6), de(6), dv, nde, beta, ds(6), dm
    real(wp), parameter :: R2 = sqrt(2.0_wp)
    integer :: region, j
    call empm_dp_return(mat, sig_tr, sig, region, m_tr, t_tr, m, t)
    n = 0.0_wp
    if (t_tr > 0.0_wp) then
      n(1:3) = (sig_tr(1:3) - m_tr) / (R2 * t_tr)
      n(4:6) = sig_tr(4:6) / (R2 * t_tr)
    end if
    beta = 0.0_wp
    if (region == DP_CONE) beta = (t_tr - t) / t_tr
    do j = 1, 6
      de = 0.0_wp
      de(j) = 1.0_wp
      dv = de(1) + de(2) + de(3)
      de(1:3) = de(1:3) - dv / 3.0_wp
      nde = n(1) * de(1) + n(2) * de(2) + n(3) * de(3) &
        + 2.0_wp * (n(4) * de(4) + n(5) * de(5) + n(6) * de(6))
      select case (region)
      case (DP_ELASTIC)
        ds = 2.0_wp * mat%G * de; dm = mat%K * dv
      case (DP_CONE)
        ds = 2.0_wp * mat%G * (1.0_wp - beta) * de &
          + 2.0_wp * mat%G * (beta - mat%G / mat%H) * nde * n &
          - (R2 * mat%G * mat%K * mat%eta / mat%H) * dv * n
        dm = mat%K * (1.0_wp - mat%K * mat%eta * mat%eta_psi / mat%H) * dv &
          - (R2 * mat%G * mat%K * mat%eta_psi / mat%H) * nde
      case (DP_TENSION)
        ds = 2.0_wp * mat%G * de; dm = 0.0_wp
      case default
        ds = 2.0_wp * mat%G * (t / t_tr) * (de - nde * n); dm = 0.0_wp
      end select
      D(:, j) = ds
      D(1:3, j) = D(1:3, j) + dm
    end do
  end subroutine empm_dp_tangent

  !> Update of `n = size(rho)` particles (see the module notes). `info = k > 0`: 1 + tr Δε <= 0
  !> at particle k (the first such), whose state is left unchanged; `info = -1`: array extents
  !> disagree with n or fewer than 2 state rows.
  pure subroutine dp_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    real(wp), intent(in) :: dt                       !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)           !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)        !! deformation gradient, unchanged
    real(wp), intent(inout), contiguous :: strain(:,:)     !! small strain, Voigt (6,n)
    real(wp), intent(inout), contiguous :: stress(:,:)     !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)      !! eps_p_eq, eps_p_vol (rows 1, 2)
    real(wp), intent(inout), contiguous :: rho(:)          !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx     !! the kinematics' form (`midpoint`)
    integer, intent(out) :: info                     !! 0 ok; k > 0 particle k failed; −1 shapes
    real(wp) :: de(6), tr, sig(6), m_tr, t_tr, m, t, jv
    integer :: p, n, region
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n .or. size(state, 2) /= n .or. size(state, 1) < 2) then
      info = -1
      return
    end if
    do p = 1, n
      de = corotated_increment(dt, L(:,:,p))
      tr = de(1) + de(2) + de(3)
      jv = volume_ratio(dt, L(:,:,p), ctx%midpoint)
      if (jv <= 0.0_wp) then
        if (info == 0) info = p
        cycle
      end if
      strain(:,p) = strain(:,p) + de
      call jaumann_rotate(dt, L(:,:,p), stress(:,p))
      if (self%substep_tol > 0.0_wp) then
        call dp_integrate(self, stress(:,p), de, state(1,p), state(2,p))
        rho(p) = rho(p) / jv
        cycle
      end if
      ! The elastic predictor in linear_elastic's operation order: with an unreachable
      ! strength the two models agree bitwise.
      sig(1:3) = stress(1:3,p) + self%lambda * tr + 2.0_wp * self%G * de(1:3)
      sig(4:6) = stress(4:6,p) + 2.0_wp * self%G * de(4:6)
      call empm_dp_return(self, sig, stress(:,p), region, m_tr, t_tr, m, t)
      if (region /= DP_ELASTIC) then
        state(1,p) = state(1,p) + (t_tr - t) / (sqrt(3.0_wp) * self%G)
        state(2,p) = state(2,p) + (m_tr - m) / self%K
      end if
      rho(p) = rho(p) / jv
    end do
  end subroutine dp_update

  !> One return over the strain increment `de` from the (rotated) stress `s`, accumulating the
  !> plastic strains; `region` is the return's DP_* region.
  pure subroutine dp_step(self, s, de, e_eq, e_vol, region)
    class(empm_drucker_prager_t), intent(in) :: self
    real(wp), intent(inout) :: s(6), e_eq, e_vol
    real(wp), intent(in) :: de(6)
    integer, intent(out) :: region
    real(wp) :: sig(6), tr, m_tr, t_tr, m, t
    tr = de(1) + de(2) + de(3)
    sig(1:3) = s(1:3) + self%lambda * tr + 2.0_wp * self%G * de(1:3)
    sig(4:6) = s(4:6) + 2.0_wp * self%G * de(4:6)
    call empm_dp_return(self, sig, s, region, m_tr, t_tr, m, t)
    if (region /= DP_ELASTIC) then
      e_eq = e_eq + (t_tr - t) / (sqrt(3.0_wp) * self%G)
      e_vol = e_vol + (m_tr - m) / self%K
    end if
  end subroutine dp_step

  !> Error-controlled integration of one point over `de` (`substep_tolerance` > 0): the
  !> elastic part of the increment first (the fraction a where the straight elastic path leaves
  !> the admissible set, by bisection: one and two returns agree exactly while the first half is
  !> elastic, so the estimate would be blind to it), then substeps 2^-l of the plastic part
  !> (l ≤ 16), each accepted when one return over it and two over its halves agree to the
  !> tolerance (relative to |σ| + ξc), with local extrapolation 2σ_two − σ_one (backward Euler
  !> is first order: the extrapolated value is second order). The result is returned to the
  !> surface once more (a zero increment) so that it is admissible to round-off. On paths where
  !> a single return is exact (coaxial) the first substep is accepted at once.
  pure subroutine dp_integrate(self, s, de, e_eq, e_vol)
    class(empm_drucker_prager_t), intent(in) :: self
    real(wp), intent(inout) :: s(6), e_eq, e_vol
    real(wp), intent(in) :: de(6)
    real(wp) :: sa(6), sb(6), a1, a2, b1, b2, dsig(6), tr, lo, hi, mid, a, h
    integer :: region, rb, lev, pos, span, it
    sa = s; a1 = e_eq; a2 = e_vol
    call dp_step(self, sa, de, a1, a2, region)
    if (region == DP_ELASTIC) then
      s = sa; e_eq = a1; e_vol = a2; return
    end if
    tr = de(1) + de(2) + de(3)
    dsig(1:3) = self%lambda * tr + 2.0_wp * self%G * de(1:3)
    dsig(4:6) = 2.0_wp * self%G * de(4:6)
    a = 0.0_wp
    if (admissible(s, 0.0_wp)) then
      lo = 0.0_wp; hi = 1.0_wp
      do it = 1, 60
        mid = 0.5_wp * (lo + hi)
        if (admissible(s + mid * dsig, 0.0_wp)) then
          lo = mid
        else
          hi = mid
        end if
      end do
      a = lo
      s = s + a * dsig
    end if
    lev = 0; pos = 0
    do while (pos < 2**SUBSTEP_LEVELS)
      span = 2**(SUBSTEP_LEVELS - lev)
      h = (1.0_wp - a) * real(span, wp) / 2**SUBSTEP_LEVELS
      sa = s; a1 = e_eq; a2 = e_vol
      call dp_step(self, sa, h * de, a1, a2, region)
      if (region == DP_ELASTIC) then
        s = sa; e_eq = a1; e_vol = a2; pos = pos + span; cycle
      end if
      sb = s; b1 = e_eq; b2 = e_vol
      call dp_step(self, sb, 0.5_wp * h * de, b1, b2, rb)
      call dp_step(self, sb, 0.5_wp * h * de, b1, b2, rb)
      if (lev == SUBSTEP_LEVELS .or. maxval(abs(sb - sa)) <= self%substep_tol * &
          (maxval(abs(sb)) + self%xic)) then
        s = 2.0_wp * sb - sa; e_eq = 2.0_wp * b1 - a1; e_vol = 2.0_wp * b2 - a2
        pos = pos + span
        if (lev > 0) then
          if (mod(pos, 2 * span) == 0) lev = lev - 1
        end if
      else
        lev = lev + 1
      end if
    end do
    call dp_step(self, s, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], e_eq, e_vol, &
      region)
  contains
    ! The stress x is inside the cone and below the cut-off, with a margin `tol` [Pa].
    pure logical function admissible(x, tol)
      real(wp), intent(in) :: x(6), tol
      real(wp) :: mm, tt
      mm = (x(1) + x(2) + x(3)) / 3.0_wp
      tt = sqrt(0.5_wp * ((x(1) - mm)**2 + (x(2) - mm)**2 + (x(3) - mm)**2) + x(4)**2 + &
        x(5)**2 + x(6)**2)
      admissible = tt + self%eta * mm - self%xic <= tol .and. mm <= self%T + tol
    end function admissible
  end subroutine dp_integrate

  !> Elastic P-wave speed sqrt((λ + 2G)/ρ) [m/s] (plastic flow only softens the response).
  pure real(wp) function dp_wave_speed(self, rho)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho                      !! current density [kg/m³]
    dp_wave_speed = sqrt((self%lambda + 2.0_wp * self%G) / rho)
  end function dp_wave_speed

  !> Elastic stored energy ½ σ:C⁻¹:σ = m²/(2K) + J₂/(2G) per current volume (the energy the
  !> elastic strain holds; the plastic work is dissipated, so ½σ:ε would be wrong).
  pure subroutine dp_energy_density(self, F, strain, stress, state, psi)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)                 !! deformation gradient, unused
    real(wp), intent(in) :: strain(:,:)              !! small strain, unused
    real(wp), intent(in) :: stress(:,:)              !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)               !! state variables, unused
    real(wp), intent(out) :: psi(:)                  !! energy density (n) [J/m³]
    real(wp) :: m, s(3), j2
    integer :: p
    associate (unused_ => F, unused2_ => strain, unused3_ => state); end associate
    do p = 1, min(size(psi), size(stress, 2))
      m = (stress(1,p) + stress(2,p) + stress(3,p)) / 3.0_wp
      s = stress(1:3,p) - m
      j2 = 0.5_wp * (s(1)**2 + s(2)**2 + s(3)**2) + stress(4,p)**2 + stress(5,p)**2 &
        + stress(6,p)**2
      psi(p) = 0.5_wp * m**2 / self%K + 0.5_wp * j2 / self%G
    end do
  end subroutine dp_energy_density

  !> Why a particle failed: only the kinematic failure (the return mapping cannot fail).
  function dp_failure_text(self) result(s)
    class(empm_drucker_prager_t), intent(in) :: self !! material
    character(len=:), allocatable :: s               !! reason
    associate (unused_ => self); end associate
    s = 'its volume ratio became <= 0 (1 + tr(strain increment) <= 0)'
  end function dp_failure_text
end module empm_material_drucker_prager
