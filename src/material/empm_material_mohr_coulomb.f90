!> Mohr–Coulomb elastoplasticity with non-associated flow, a tension cut-off and optional linear
!> softening of the cohesion and the friction angle (docs/materials.md, section mohr_coulomb).
!>
!> Principal stresses σ1 ≥ σ2 ≥ σ3, tension positive. Yield and plastic potential of the
!> ordered sextant:
!>
!>   f = (σ1 − σ3) + (σ1 + σ3) sin φ − 2c cos φ,   g = (σ1 − σ3) + (σ1 + σ3) sin ψ,
!>
!> and the tension cut-off σ1 ≤ σt (associated flow). Each step: Δε = Δt sym(L), Jaumann
!> rotation of the stress ([[jaumann_rotate]]) with Δε turned by half of it
!> ([[corotated_increment]]), elastic trial σ* = σ + D:Δε, its principal values and directions ([[principal_decompose]]; closed
!> form in 2D), the return in principal space, and σ composed back with the trial's
!> directions (isotropy: the return is coaxial with σ*).
!>
!> The return: every plane is linear in σ, so for a set A of active planes the return
!> σ = σ* − Σ_{j∈A} Δλ_j D m_j (m_j the flow direction of plane j) solves the |A| linear
!> consistency equations in closed form. The sets are tried in a fixed order — the main plane,
!> the compression edge σ1 = σ2 (triaxial compression meridian), the extension edge σ2 = σ3,
!> the cut-off plane, the cut-off lines and points, the apex — and the first whose
!> multipliers are all ≥ 0 and whose stress is ordered and admissible is taken. For linear
!> planes the return regions (the set's stress plus the cone of its D m_j) tile the space
!> outside the yield surface also with non-associated flow, so exactly this one set passes
!> (a trial on a region boundary may pass two; both give the same stress). With softening the
!> strength parameters depend on the accumulated plastic shear strain, and the consistency
!> equations of the set are solved by a local Newton iteration on the Δλ_j.
!>
!> Split independence: with perfect plasticity a return along a fixed flow direction onto a
!> fixed plane is a projection P with P(P(x) + y) = P(x + y), so the result of a strain increment
!> does not depend on how it is split as long as the principal directions do not rotate and the
!> trials stay in one return region. Otherwise (rotating principal axes, region changes,
!> softening) the return is first-order accurate in the increment; `substep_tolerance` > 0
!> switches on error-controlled substepping (one return over a substep against two over its
!> halves).
module empm_material_mohr_coulomb
  use empm_kinds, only: wp, pi
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t, STATE_NAME_LEN
  use empm_material_linear_elastic, only: empm_elastic_params, empm_elastic_read, empm_lame
  use empm_plasticity, only: jaumann_rotate, corotated_increment, principal_decompose, &
    principal_compose, volume_ratio
  implicit none
  private
  public :: empm_mohr_coulomb_t
  public :: MC_ELASTIC, MC_PLANE, MC_EDGE_COMPRESSION, MC_EDGE_EXTENSION, MC_TENSION, &
            MC_TENSION_LINE, MC_TENSION_EDGE, MC_TENSION_POINT, MC_TENSION_APEX, MC_APEX, &
            MC_NO_REGION, MC_NO_CONVERGENCE

  ! Return regions (what `return_map` reports).
  integer, parameter :: MC_ELASTIC = 0           !! no plastic flow
  integer, parameter :: MC_PLANE = 1             !! main plane
  integer, parameter :: MC_EDGE_COMPRESSION = 2  !! edge σ1 = σ2 (triaxial compression)
  integer, parameter :: MC_EDGE_EXTENSION = 3    !! edge σ2 = σ3 (triaxial extension)
  integer, parameter :: MC_TENSION = 4           !! cut-off plane σ1 = σt
  integer, parameter :: MC_TENSION_LINE = 5      !! main plane ∩ cut-off
  integer, parameter :: MC_TENSION_EDGE = 6      !! σ1 = σ2 = σt
  integer, parameter :: MC_TENSION_POINT = 7     !! corner points of the cut-off with MC edges
  integer, parameter :: MC_TENSION_APEX = 8      !! σ1 = σ2 = σ3 = σt
  integer, parameter :: MC_APEX = 9              !! apex of the MC cone
  integer, parameter :: MC_NO_REGION = -1        !! no set passed (should not happen)
  integer, parameter :: MC_NO_CONVERGENCE = -2   !! softening Newton iteration failed

  ! Planes of the ordered sextant: MC planes by (major, minor) index, then the cut-offs.
  ! 1 F13 (main), 2 F23, 3 F12, 4 T1, 5 T2, 6 T3, 7 F31, 8 F32, 9 F21 (the last three only
  ! meet the sextant at the apex).
  integer, parameter :: NPLANE = 9
  integer, parameter :: MAJ(NPLANE) = [1, 2, 1, 1, 2, 3, 3, 3, 2]
  integer, parameter :: MIN_(NPLANE) = [3, 3, 2, 0, 0, 0, 1, 2, 1]
  ! Candidate sets, in the order tried, and their regions.
  integer, parameter :: NCAND = 12
  integer, parameter :: CAND(3, NCAND) = reshape([ &
    1, 0, 0,   1, 2, 0,   1, 3, 0,   4, 0, 0,   1, 4, 0,   4, 5, 0, &
    1, 3, 4,   1, 2, 4,   1, 2, 5,   1, 4, 5,   2, 4, 5,   4, 5, 6], [3, NCAND])
  integer, parameter :: CAND_N(NCAND) = [1, 2, 2, 1, 2, 2, 3, 3, 3, 3, 3, 3]
  integer, parameter :: CAND_REGION(NCAND) = [MC_PLANE, MC_EDGE_COMPRESSION, &
    MC_EDGE_EXTENSION, MC_TENSION, MC_TENSION_LINE, MC_TENSION_EDGE, MC_TENSION_POINT, &
    MC_TENSION_POINT, MC_TENSION_POINT, MC_TENSION_POINT, MC_TENSION_POINT, MC_TENSION_APEX]

  integer, parameter :: NEWTON_MAX = 50            !! softening Newton iterations
  integer, parameter :: SUBSTEP_LEVELS = 16        !! substeps down to 2^-16 of the step
  real(wp), parameter :: REL_TOL = 1.0e-12_wp      !! acceptance / convergence, relative
  real(wp), parameter :: DEG = pi / 180.0_wp

  !> Mohr–Coulomb material (see the module notes).
  type, extends(empm_material_t) :: empm_mohr_coulomb_t
    real(wp) :: E = 0.0_wp            !! Young's modulus [Pa]
    real(wp) :: nu = 0.0_wp           !! Poisson's ratio [-]
    real(wp) :: K = 0.0_wp            !! bulk modulus [Pa]
    real(wp) :: G = 0.0_wp            !! shear modulus [Pa]
    real(wp) :: lam = 0.0_wp          !! first Lamé parameter [Pa]
    real(wp) :: c0 = 0.0_wp           !! peak cohesion [Pa]
    real(wp) :: phi0 = 0.0_wp         !! peak friction angle [rad]
    real(wp) :: psi = 0.0_wp          !! dilatancy angle [rad]
    real(wp) :: c_res = 0.0_wp        !! residual cohesion [Pa]
    real(wp) :: phi_res = 0.0_wp      !! residual friction angle [rad]
    real(wp) :: eps_soft = 0.0_wp     !! softening strain (0: no softening)
    logical :: cutoff = .false.       !! a tension cut-off exists
    logical :: cutoff_apex = .false.  !! the cut-off is the apex value c cot φ (follows softening)
    real(wp) :: st_user = 0.0_wp      !! tension cut-off given [Pa]
    real(wp) :: substep_tol = 0.0_wp  !! substepping tolerance (0: one return per step)
    real(wp) :: sphi = 0.0_wp         !! sin φ0 (cached)
    real(wp) :: cphi = 1.0_wp         !! cos φ0 (cached)
    real(wp) :: spsi = 0.0_wp         !! sin ψ (cached)
    real(wp) :: m(3, NPLANE) = 0.0_wp !! flow directions of the planes (principal)
    real(wp) :: r(3, NPLANE) = 0.0_wp !! D m of the planes
    ! Constants of the fixed-strength return (no softening), see [[mc_prepare]].
    logical :: fixed = .false.        !! strength fixed: the closed-form return applies
    real(wp) :: k0 = 0.0_wp           !! 2c cos φ [Pa]
    real(wp) :: st0 = 0.0_wp          !! cut-off value (huge without one) [Pa]
    real(wp) :: ap = 0.0_wp           !! 1 + sin φ (major coefficient of the MC planes)
    real(wp) :: am = 0.0_wp           !! 1 − sin φ (minor coefficient)
    real(wp) :: inv_plane = 0.0_wp    !! 1/(a·D m) of the main plane [1/Pa]
    real(wp) :: inv_comp(2,2) = 0.0_wp  !! inverse of [a_i·D m_j] of the compression edge
    real(wp) :: inv_ext(2,2) = 0.0_wp   !! inverse of [a_i·D m_j] of the extension edge
    real(wp) :: kap_plane = 0.0_wp    !! sqrt(2/3)|dev m| of the main plane
    real(wp) :: dev_m(3, 3) = 0.0_wp  !! sqrt(2/3) dev m of the three MC planes
  contains
    procedure :: configure => mc_configure
    procedure :: family => mc_family
    procedure :: summary => mc_summary
    procedure :: params => mc_params
    procedure :: state_names => mc_state_names
    procedure :: update => mc_update
    procedure :: wave_speed => mc_wave_speed
    procedure :: energy_density => mc_energy_density
    procedure :: failure_text => mc_failure_text
    procedure :: strength => mc_strength
    procedure :: yield_value => mc_yield_value
    procedure :: return_map => mc_return_map
    procedure :: integrate => mc_integrate
  end type empm_mohr_coulomb_t

contains

  ! ---- description and set-up ------------------------------------------------------------

  !> Registry name "mohr_coulomb".
  pure function mc_family(self) result(s)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    character(len=:), allocatable :: s             !! "mohr_coulomb"
    associate (unused_ => self); end associate
    s = 'mohr_coulomb'
  end function mc_family

  !> One-line description.
  pure function mc_summary(self) result(s)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    character(len=:), allocatable :: s             !! summary
    associate (unused_ => self); end associate
    s = 'Mohr-Coulomb plasticity, non-associated flow, tension cut-off, optional linear softening'
  end function mc_summary

  !> Parameters: the elastic ones ([[empm_elastic_params]]) and the strength, flow, cut-off,
  !> softening and substepping keys.
  pure function mc_params(self) result(p)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:)        !! declarations
    associate (unused_ => self); end associate
    p = [empm_elastic_params(), &
      empm_param('cohesion', PARAM_REAL, 'Pa', 'cohesion c (peak value with softening)', &
        lo=0.0_wp, hi=1.0e30_wp), &
      empm_param('friction_angle', PARAM_REAL, 'deg', 'friction angle phi (peak value with ' &
        //'softening)', lo=0.0_wp, hi=90.0_wp, hi_open=.true.), &
      empm_param('dilatancy_angle', PARAM_REAL, 'deg', 'dilatancy angle psi of the plastic ' &
        //'potential, at most the friction angle (and the residual one); psi = phi is ' &
        //'associated flow', default='0', lo=0.0_wp, hi=90.0_wp, hi_open=.true.), &
      empm_param('tension_cutoff', PARAM_REAL, 'Pa', 'tensile strength: sigma_1 <= ' &
        //'tension_cutoff (associated flow); at most the apex value c cot(phi). Absent: ' &
        //'the apex value, following softening; none when a friction angle is 0', &
        lo=0.0_wp, hi=1.0e30_wp, optional=.true.), &
      empm_param('residual_cohesion', PARAM_REAL, 'Pa', 'cohesion reached at softening_strain ' &
        //'(at most cohesion); absent: no cohesion softening', lo=0.0_wp, hi=1.0e30_wp, &
        optional=.true.), &
      empm_param('residual_friction_angle', PARAM_REAL, 'deg', 'friction angle reached at ' &
        //'softening_strain (at most friction_angle); absent: no friction softening', &
        lo=0.0_wp, hi=90.0_wp, hi_open=.true., optional=.true.), &
      empm_param('softening_strain', PARAM_REAL, '-', 'accumulated plastic shear strain ' &
        //'eps_p_shear at which c and phi reach their residual values (linear from 0); ' &
        //'absent: no softening', lo=0.0_wp, lo_open=.true., hi=1.0e3_wp, optional=.true.), &
      empm_param('substep_tolerance', PARAM_REAL, '-', 'relative local error of the stress ' &
        //'return per substep (one return against two over the halves); 0: one return per ' &
        //'step, exact for fixed principal axes within one return region', default='0', &
        lo=0.0_wp, hi=1.0e-2_wp)]
  end function mc_params

  !> State variables: the accumulated plastic shear strain Σ sqrt(2/3 Δe_p:Δe_p) (Δe_p the
  !> deviator of the plastic strain increment) and the accumulated plastic volume strain
  !> Σ tr Δε_p (positive: dilation).
  pure subroutine mc_state_names(self, names)
    class(empm_mohr_coulomb_t), intent(in) :: self                        !! material
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:)   !! the names
    associate (unused_ => self); end associate
    names = [character(len=STATE_NAME_LEN) :: 'eps_p_shear', 'eps_p_vol']
  end subroutine mc_state_names

  !> Read and check the keys (see [[mc_params]]); every inconsistency names its key.
  subroutine mc_configure(self, group, err)
    class(empm_mohr_coulomb_t), intent(inout) :: self !! material
    type(empm_group_t), intent(inout) :: group        !! the `&material` group
    type(empm_error_t), intent(inout) :: err          !! set on a missing or invalid value
    type(empm_param_t), allocatable :: p(:)
    real(wp) :: E, nu, rho0, c, phi, psi, st, cres, phires, esoft, tol, apex
    integer :: j
    logical :: soft
    allocate(p, source=mc_params(self))
    call empm_elastic_read(group, E, nu, rho0, err)
    if (err%code /= 0) return
    c = 0.0_wp; phi = 0.0_wp; psi = 0.0_wp; tol = 0.0_wp
    call group%get(p(4), c, err)
    call group%get(p(5), phi, err)
    call group%get(p(6), psi, err)
    st = -1.0_wp; cres = c; phires = phi; esoft = 0.0_wp
    call group%get(p(7), st, err)
    call group%get(p(8), cres, err)
    call group%get(p(9), phires, err)
    call group%get(p(10), esoft, err)
    call group%get(p(11), tol, err)
    if (err%code /= 0) return
    soft = group%has('softening_strain')
    if (soft .and. .not. (group%has('residual_cohesion') .or. &
                          group%has('residual_friction_angle'))) then
      call group%fail(err, 'softening_strain', 'softening needs residual_cohesion or ' &
        //'residual_friction_angle'); return
    end if
    if (.not. soft .and. (group%has('residual_cohesion') .or. &
                          group%has('residual_friction_angle'))) then
      if (group%has('residual_cohesion')) then
        call group%fail(err, 'residual_cohesion', 'a residual value needs softening_strain')
      else
        call group%fail(err, 'residual_friction_angle', 'a residual value needs softening_strain')
      end if
      return
    end if
    if (cres > c) then
      call group%fail(err, 'residual_cohesion', 'must not exceed cohesion'); return
    end if
    if (phires > phi) then
      call group%fail(err, 'residual_friction_angle', 'must not exceed friction_angle'); return
    end if
    if (psi > min(phi, phires)) then
      call group%fail(err, 'dilatancy_angle', 'must not exceed the friction angle (psi <= ' &
        //'phi, and <= residual_friction_angle with softening)'); return
    end if
    if (st >= 0.0_wp .and. phi > 0.0_wp) then
      apex = c * cos(phi * DEG) / sin(phi * DEG)
      if (st > apex * (1.0_wp + 1.0e-12_wp)) then
        call group%fail(err, 'tension_cutoff', 'must not exceed the apex value c cot(phi) '// &
          '(beyond it the cut-off never acts)'); return
      end if
    end if

    self%E = E; self%nu = nu; self%rho0 = rho0
    call empm_lame(E, nu, self%lam, self%G)
    self%K = self%lam + 2.0_wp * self%G / 3.0_wp
    self%c0 = c; self%phi0 = phi * DEG; self%psi = psi * DEG
    self%c_res = cres; self%phi_res = phires * DEG
    self%eps_soft = merge(esoft, 0.0_wp, soft)
    self%substep_tol = tol
    self%sphi = sin(self%phi0); self%cphi = cos(self%phi0); self%spsi = sin(self%psi)
    if (st >= 0.0_wp) then
      self%cutoff = .true.; self%cutoff_apex = .false.; self%st_user = st
    else
      ! The apex value exists only while the friction angle stays positive.
      self%cutoff = min(phi, phires) > 0.0_wp
      self%cutoff_apex = self%cutoff; self%st_user = 0.0_wp
    end if
    do j = 1, NPLANE
      self%m(:, j) = 0.0_wp
      if (MIN_(j) > 0) then
        self%m(MAJ(j), j) = 1.0_wp + self%spsi
        self%m(MIN_(j), j) = -(1.0_wp - self%spsi)
      else
        self%m(MAJ(j), j) = 1.0_wp
      end if
      self%r(:, j) = self%lam * sum(self%m(:, j)) + 2.0_wp * self%G * self%m(:, j)
    end do
    call mc_prepare(self)
  end subroutine mc_configure

  !> Constants of the closed-form return at fixed strength (no softening): with fixed planes
  !> the products a_i·D m_j of the main plane and of the two edges are constants, so their
  !> multipliers are a product with a precomputed inverse (no elimination per particle).
  pure subroutine mc_prepare(self)
    class(empm_mohr_coulomb_t), intent(inout) :: self !! material, configured
    real(wp) :: A(2,2), det, dm(3)
    integer :: j
    self%fixed = self%eps_soft <= 0.0_wp
    self%k0 = 2.0_wp * self%c0 * self%cphi
    self%st0 = huge(1.0_wp)
    if (self%cutoff) then
      if (self%cutoff_apex) then
        self%st0 = self%c0 * self%cphi / self%sphi
      else
        self%st0 = self%st_user
      end if
    end if
    self%ap = 1.0_wp + self%sphi; self%am = 1.0_wp - self%sphi
    do j = 1, 3
      dm = self%m(:, j) - sum(self%m(:, j)) / 3.0_wp
      self%dev_m(:, j) = sqrt(2.0_wp / 3.0_wp) * dm
    end do
    self%kap_plane = sqrt(sum(self%dev_m(:, 1)**2))
    ! Planes 1 (F13) and 2 (F23) meet on σ1 = σ2, planes 1 and 3 (F12) on σ2 = σ3.
    self%inv_plane = 1.0_wp / dot_product(grad(1), self%r(:, 1))
    A = reshape([dot_product(grad(1), self%r(:, 1)), dot_product(grad(2), self%r(:, 1)), &
                 dot_product(grad(1), self%r(:, 2)), dot_product(grad(2), self%r(:, 2))], [2, 2])
    det = A(1,1) * A(2,2) - A(1,2) * A(2,1)
    if (.not. abs(det) > 0.0_wp) then
      self%fixed = .false.; return
    end if
    self%inv_comp = reshape([A(2,2), -A(2,1), -A(1,2), A(1,1)], [2, 2]) / det
    A = reshape([dot_product(grad(1), self%r(:, 1)), dot_product(grad(3), self%r(:, 1)), &
                 dot_product(grad(1), self%r(:, 3)), dot_product(grad(3), self%r(:, 3))], [2, 2])
    det = A(1,1) * A(2,2) - A(1,2) * A(2,1)
    if (.not. abs(det) > 0.0_wp) then
      self%fixed = .false.; return
    end if
    self%inv_ext = reshape([A(2,2), -A(2,1), -A(1,2), A(1,1)], [2, 2]) / det
  contains
    ! Gradient of MC plane j at the peak strength.
    pure function grad(j) result(a)
      integer, intent(in) :: j
      real(wp) :: a(3)
      a = 0.0_wp
      a(MAJ(j)) = 1.0_wp + self%sphi; a(MIN_(j)) = -(1.0_wp - self%sphi)
    end function grad
  end subroutine mc_prepare

  ! ---- strength and the principal-space return ---------------------------------------------

  !> Strength at the accumulated plastic shear strain `kappa`: sin φ, cos φ, 2c cos φ, σt
  !> and their derivatives with respect to kappa (zero without softening or beyond it).
  pure subroutine mc_strength(self, kappa, s, cs, k, st, ds, dk, dst)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: kappa                  !! eps_p_shear
    real(wp), intent(out) :: s      !! sin φ
    real(wp), intent(out) :: cs     !! cos φ
    real(wp), intent(out) :: k      !! 2c cos φ [Pa]
    real(wp), intent(out) :: st     !! tension cut-off (huge without one) [Pa]
    real(wp), intent(out) :: ds     !! d sin φ / dκ
    real(wp), intent(out) :: dk     !! d(2c cos φ)/dκ [Pa]
    real(wp), intent(out) :: dst    !! dσt/dκ [Pa]
    real(wp) :: c, phi, dc, dphi, t
    if (self%eps_soft > 0.0_wp) then
      if (kappa < self%eps_soft) then
        t = kappa / self%eps_soft
        dc = (self%c_res - self%c0) / self%eps_soft
        dphi = (self%phi_res - self%phi0) / self%eps_soft
        c = self%c0 + (self%c_res - self%c0) * t
        phi = self%phi0 + (self%phi_res - self%phi0) * t
      else
        c = self%c_res; phi = self%phi_res; dc = 0.0_wp; dphi = 0.0_wp
      end if
      s = sin(phi); cs = cos(phi)
    else
      c = self%c0; s = self%sphi; cs = self%cphi; dc = 0.0_wp; dphi = 0.0_wp
    end if
    k = 2.0_wp * c * cs
    ds = cs * dphi
    dk = 2.0_wp * (dc * cs - c * s * dphi)
    st = huge(1.0_wp); dst = 0.0_wp
    if (self%cutoff) then
      if (self%cutoff_apex) then
        ! s > 0 here: the apex cut-off exists only when every friction angle is positive.
        st = c * cs / s
        dst = (dc * cs - c * s * dphi) / s - c * cs * ds / s**2
      else
        st = self%st_user; dst = 0.0_wp
        ! With softening the apex may move below a given cut-off: the cut-off then never acts.
      end if
    end if
  end subroutine mc_strength

  !> Yield function of the ordered principal stress `sig` at `kappa`: the largest of the main
  !> MC plane and the cut-off, (σ1 − σ3) + (σ1 + σ3) sin φ − 2c cos φ and σ1 − σt.
  pure real(wp) function mc_yield_value(self, sig, kappa) result(f)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: sig(3)                 !! principal stresses, decreasing [Pa]
    real(wp), intent(in) :: kappa                  !! eps_p_shear
    real(wp) :: s, cs, k, st, ds, dk, dst
    call mc_strength(self, kappa, s, cs, k, st, ds, dk, dst)
    f = (sig(1) - sig(3)) + (sig(1) + sig(3)) * s - k
    if (self%cutoff) f = max(f, sig(1) - st)
  end function mc_yield_value

  !> Return of an ordered trial `str` (σ1 ≥ σ2 ≥ σ3) in principal space: the stress `sig`,
  !> the increments of eps_p_shear and eps_p_vol and the region. `info` = 0, or 1 when no
  !> region passed or the softening iteration did not converge (region MC_NO_REGION or
  !> MC_NO_CONVERGENCE; `sig` is then the trial). At fixed strength the closed-form return
  !> ([[fixed_return]]) decides first; `general` = .true. forces the candidate-set search
  !> (the reference the unit test compares it with).
  pure subroutine mc_return_map(self, str, kappa, sig, dkappa, devol, region, info, general)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: str(3)                 !! trial principal stresses [Pa]
    real(wp), intent(in) :: kappa                  !! eps_p_shear at the start
    real(wp), intent(out) :: sig(3)                !! returned principal stresses [Pa]
    real(wp), intent(out) :: dkappa                !! increment of eps_p_shear
    real(wp), intent(out) :: devol                 !! increment of eps_p_vol
    integer, intent(out) :: region                 !! MC_* region
    integer, intent(out) :: info                   !! 0 ok, 1 failed
    logical, intent(in), optional :: general       !! skip the closed-form return
    real(wp) :: scale, lam(3), s, cs, k, st, ds, dk, dst, ep(3)
    integer :: ic, i, j, l, nap, ap(9), set(3)
    logical :: ok, conv, done
    sig = str; dkappa = 0.0_wp; devol = 0.0_wp; info = 0
    region = MC_ELASTIC
    done = .false.
    if (present(general)) done = general
    if (self%fixed .and. .not. done) then
      call fixed_return(self, str, sig, dkappa, devol, region, done)
      if (done) return
    end if
    if (mc_yield_value(self, str, kappa) <= 0.0_wp) return
    call mc_strength(self, kappa, s, cs, k, st, ds, dk, dst)
    scale = max(maxval(abs(str)) + self%c0, 1.0e-200_wp)
    do ic = 1, NCAND
      if (.not. self%cutoff .and. any(CAND(1:CAND_N(ic), ic) >= 4)) cycle
      ! With the cut-off at the apex (and fixed strength) every set after the two edges
      ! returns to the apex point: the cut-off planes meet the MC cone only there. Its
      ! region is then what the main plane and the edges leave (the regions tile the space),
      ! so the apex is taken at once; the plastic strain is D⁻¹(σ* − σ).
      if (ic == 4 .and. self%cutoff_apex .and. self%eps_soft <= 0.0_wp) then
        sig = st
        ep = (str - sig) / (2.0_wp * self%G)
        ep = ep - self%lam / (2.0_wp * self%G) * sum(str - sig) / (3.0_wp * self%K)
        devol = sum(ep)
        dkappa = sqrt(2.0_wp / 3.0_wp * sum((ep - devol / 3.0_wp)**2))
        region = MC_APEX; return
      end if
      call try_set(CAND(:, ic), CAND_N(ic), lam, sig, dkappa, devol, ok, conv)
      if (.not. conv) then
        region = MC_NO_CONVERGENCE; info = 1; sig = str; return
      end if
      if (ok) then
        region = CAND_REGION(ic); return
      end if
    end do
    ! The apex: every plane through it; a trial in its region is in the cone of some three
    ! of their D m (Carathéodory), so the triples are tried.
    nap = 6
    ap(1:6) = [1, 2, 3, 7, 8, 9]
    if (self%cutoff) then
      ap(7:9) = [4, 5, 6]; nap = 9
    end if
    do i = 1, nap - 2
      do j = i + 1, nap - 1
        do l = j + 1, nap
          set = [ap(i), ap(j), ap(l)]
          call try_set(set, 3, lam, sig, dkappa, devol, ok, conv)
          if (.not. conv) then
            region = MC_NO_CONVERGENCE; info = 1; sig = str; return
          end if
          if (ok) then
            region = MC_APEX; return
          end if
        end do
      end do
    end do
    region = MC_NO_REGION; info = 1; sig = str; dkappa = 0.0_wp; devol = 0.0_wp

  contains

    ! Solve the consistency equations of the planes set(1:n); ok when the multipliers are
    ! non-negative and the stress is ordered and admissible; conv false when the softening
    ! iteration failed.
    pure subroutine try_set(set, n, lam, sig, dkappa, devol, ok, conv)
      integer, intent(in) :: set(3), n
      real(wp), intent(out) :: lam(3), sig(3), dkappa, devol
      logical, intent(out) :: ok, conv
      real(wp) :: A(3,3), R(3), a_i(3), da_i(3), ep(3), dev(3), dkdl(3), kap, x(3), sm
      real(wp) :: s1, cs1, k1, st1, ds1, dk1, dst1, fm, dlim
      integer :: it, ii, jj
      logical :: good
      ok = .false.; conv = .true.
      sig = str; dkappa = 0.0_wp; devol = 0.0_wp
      ! Frozen strength: the linear solve (exact without softening).
      do ii = 1, n
        call plane(set(ii), s, k, st, 0.0_wp, a_i, da_i, R(ii))
        R(ii) = dot_product(a_i, str) - R(ii)
        do jj = 1, n
          A(ii, jj) = dot_product(a_i, self%r(:, set(jj)))
        end do
      end do
      call solve_small(n, A, R, lam, good)
      if (.not. good) return
      if (self%eps_soft > 0.0_wp .and. kappa < self%eps_soft) then
        conv = .false.
        do it = 1, NEWTON_MAX
          call state_of(n, set, lam, sig, ep, dev, dkappa)
          kap = kappa + dkappa
          call mc_strength(self, kap, s1, cs1, k1, st1, ds1, dk1, dst1)
          ! d(dkappa)/dλ_j; at dkappa = 0 the one-sided value.
          do jj = 1, n
            sm = sum(self%m(:, set(jj))) / 3.0_wp
            if (dkappa > 0.0_wp) then
              dkdl(jj) = 2.0_wp / 3.0_wp * dot_product(dev, self%m(:, set(jj)) - sm) / dkappa
            else
              dkdl(jj) = sqrt(2.0_wp / 3.0_wp * sum((self%m(:, set(jj)) - sm)**2))
            end if
          end do
          fm = 0.0_wp
          do ii = 1, n
            call plane(set(ii), s1, k1, st1, ds1, a_i, da_i, dlim)
            R(ii) = dot_product(a_i, sig) - dlim
            fm = max(fm, abs(R(ii)))
            do jj = 1, n
              A(ii, jj) = dot_product(a_i, self%r(:, set(jj))) &
                - (dot_product(da_i, sig) - dk_of(set(ii), dk1, dst1)) * dkdl(jj)
            end do
          end do
          if (fm <= REL_TOL * scale) then
            conv = .true.; exit
          end if
          call solve_small(n, A, R, x, good)
          if (.not. good) return
          lam(1:n) = lam(1:n) + x(1:n)
        end do
        if (.not. conv) return
      end if
      call state_of(n, set, lam, sig, ep, dev, dkappa)
      devol = sum(ep)
      if (any(lam(1:n) < -REL_TOL * scale / self%G)) return
      if (sig(1) - sig(2) < -REL_TOL * scale .or. sig(2) - sig(3) < -REL_TOL * scale) return
      if (mc_yield_value(self, sig, kappa + dkappa) > REL_TOL * scale) return
      ok = .true.
    end subroutine try_set

    ! Gradient a, its κ-derivative, and the strength constant of plane j; for the Newton
    ! matrix the constant's κ-derivative comes from dk_of.
    pure subroutine plane(j, s, k, st, ds, a, da, kj)
      integer, intent(in) :: j
      real(wp), intent(in) :: s, k, st, ds
      real(wp), intent(out) :: a(3), da(3), kj
      a = 0.0_wp; da = 0.0_wp
      if (MIN_(j) > 0) then
        a(MAJ(j)) = 1.0_wp + s; a(MIN_(j)) = -(1.0_wp - s)
        da(MAJ(j)) = ds; da(MIN_(j)) = ds
        kj = k
      else
        a(MAJ(j)) = 1.0_wp
        kj = st
      end if
    end subroutine plane

    pure real(wp) function dk_of(j, dk, dst)
      integer, intent(in) :: j
      real(wp), intent(in) :: dk, dst
      dk_of = merge(dk, dst, MIN_(j) > 0)
    end function dk_of

    ! Stress, plastic strain (principal), its deviator and sqrt(2/3 dev:dev) for multipliers.
    pure subroutine state_of(n, set, lam, sig, ep, dev, dkap)
      integer, intent(in) :: n, set(3)
      real(wp), intent(in) :: lam(3)
      real(wp), intent(out) :: sig(3), ep(3), dev(3), dkap
      integer :: jj
      sig = str; ep = 0.0_wp
      do jj = 1, n
        sig = sig - lam(jj) * self%r(:, set(jj))
        ep = ep + lam(jj) * self%m(:, set(jj))
      end do
      dev = ep - sum(ep) / 3.0_wp
      dkap = sqrt(2.0_wp / 3.0_wp * sum(dev**2))
    end subroutine state_of
  end subroutine mc_return_map

  !> The return at fixed strength, decided from the trial directly: the main plane when its
  !> closed-form stress σ* − Δλ D m (Δλ = f*/(a·D m)) keeps the order σ1 ≥ σ2 ≥ σ3 and the
  !> cut-off; else the compression edge, else the extension edge (2×2 multipliers from the
  !> precomputed inverses), accepted under the same tests as in [[mc_return_map]]; else,
  !> with the cut-off at the apex, the apex. `done` false leaves the trial to the candidate-set
  !> search: a given cut-off below the apex that the trial exceeds, or a trial beyond both
  !> edges without the apex cut-off (rare; the search then repeats these three sets).
  pure subroutine fixed_return(self, str, sig, dkappa, devol, region, done)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material (fixed strength)
    real(wp), intent(in) :: str(3)                 !! trial principal stresses, ordered [Pa]
    real(wp), intent(out) :: sig(3)                !! returned principal stresses [Pa]
    real(wp), intent(out) :: dkappa                !! increment of eps_p_shear
    real(wp), intent(out) :: devol                 !! increment of eps_p_vol
    integer, intent(out) :: region                 !! MC_* region
    logical, intent(out) :: done                   !! false: not decided here
    real(wp) :: f1, f2, f3, ft, tol, ltol, l1, l2, ep(3)
    sig = str; dkappa = 0.0_wp; devol = 0.0_wp; region = MC_ELASTIC; done = .true.
    f1 = self%ap * str(1) - self%am * str(3) - self%k0
    ft = str(1) - self%st0
    if (f1 <= 0.0_wp .and. ft <= 0.0_wp) return
    if (ft > 0.0_wp .and. .not. self%cutoff_apex) then
      done = .false.; return
    end if
    tol = REL_TOL * max(max(abs(str(1)), abs(str(3))) + self%c0, 1.0e-200_wp)
    ltol = -tol / self%G
    ! Main plane.
    l1 = f1 * self%inv_plane
    sig = str - l1 * self%r(:, 1)
    if (l1 >= ltol .and. admissible(sig)) then
      dkappa = l1 * self%kap_plane
      devol = l1 * (self%m(1, 1) + self%m(3, 1))
      region = MC_PLANE; return
    end if
    ! Compression edge σ1 = σ2 (planes F13, F23).
    f2 = self%ap * str(2) - self%am * str(3) - self%k0
    l1 = self%inv_comp(1,1) * f1 + self%inv_comp(1,2) * f2
    l2 = self%inv_comp(2,1) * f1 + self%inv_comp(2,2) * f2
    sig = str - l1 * self%r(:, 1) - l2 * self%r(:, 2)
    if (l1 >= ltol .and. l2 >= ltol .and. admissible(sig)) then
      call plastic(l1, l2, 2, dkappa, devol)
      region = MC_EDGE_COMPRESSION; return
    end if
    ! Extension edge σ2 = σ3 (planes F13, F12).
    f3 = self%ap * str(1) - self%am * str(2) - self%k0
    l1 = self%inv_ext(1,1) * f1 + self%inv_ext(1,2) * f3
    l2 = self%inv_ext(2,1) * f1 + self%inv_ext(2,2) * f3
    sig = str - l1 * self%r(:, 1) - l2 * self%r(:, 3)
    if (l1 >= ltol .and. l2 >= ltol .and. admissible(sig)) then
      call plastic(l1, l2, 3, dkappa, devol)
      region = MC_EDGE_EXTENSION; return
    end if
    if (.not. self%cutoff_apex) then
      sig = str; done = .false.; return
    end if
    ! The apex (see mc_return_map): the plastic strain is D⁻¹(σ* − σ).
    sig = self%st0
    ep = (str - sig) / (2.0_wp * self%G)
    ep = ep - self%lam / (2.0_wp * self%G) * sum(str - sig) / (3.0_wp * self%K)
    devol = sum(ep)
    dkappa = sqrt(2.0_wp / 3.0_wp * sum((ep - devol / 3.0_wp)**2))
    region = MC_APEX

  contains

    ! Ordered and inside the main plane and the cut-off, to the acceptance tolerance.
    pure logical function admissible(x)
      real(wp), intent(in) :: x(3)
      admissible = x(1) - x(2) >= -tol .and. x(2) - x(3) >= -tol .and. &
        self%ap * x(1) - self%am * x(3) - self%k0 <= tol .and. x(1) - self%st0 <= tol
    end function admissible

    ! Plastic strain increments of the main plane and plane j with multipliers a, b.
    pure subroutine plastic(a, b, j, dkap, dvol)
      real(wp), intent(in) :: a, b
      integer, intent(in) :: j
      real(wp), intent(out) :: dkap, dvol
      dkap = sqrt(sum((a * self%dev_m(:, 1) + b * self%dev_m(:, j))**2))
      dvol = a * sum(self%m(:, 1)) + b * sum(self%m(:, j))
    end subroutine plastic
  end subroutine fixed_return

  !> Gaussian elimination with partial pivoting for n ≤ 3; ok false when singular.
  pure subroutine solve_small(n, A, b, x, ok)
    integer, intent(in) :: n
    real(wp), intent(in) :: A(3,3), b(3)
    real(wp), intent(out) :: x(3)
    logical, intent(out) :: ok
    real(wp) :: M(3,3), y(3), amax, t
    integer :: i, j, p
    x = 0.0_wp; ok = .false.
    M = A; y = b
    amax = maxval(abs(M(1:n, 1:n)))
    if (.not. amax > 0.0_wp) return
    do i = 1, n
      p = i - 1 + maxloc(abs(M(i:n, i)), 1)
      if (abs(M(p, i)) <= 1.0e-12_wp * amax) return
      if (p /= i) then
        do j = 1, n
          t = M(i, j); M(i, j) = M(p, j); M(p, j) = t
        end do
        t = y(i); y(i) = y(p); y(p) = t
      end if
      do j = i + 1, n
        t = M(j, i) / M(i, i)
        M(j, i:n) = M(j, i:n) - t * M(i, i:n)
        y(j) = y(j) - t * y(i)
      end do
    end do
    do i = n, 1, -1
      x(i) = (y(i) - dot_product(M(i, i+1:n), x(i+1:n))) / M(i, i)
    end do
    ok = .true.
  end subroutine solve_small

  ! ---- one stress point ----------------------------------------------------------------------

  !> One return over the strain increment `de` from the (rotated) stress `s`. With yz = xz = 0
  !> (1D, plane strain) zz is principal and the in-plane pair is c ± r, r = |((xx − yy)/2, xy)|:
  !> an elastic trial needs no directions at all, and the returned in-plane pair c' ± r' goes
  !> back by scaling the trial's in-plane deviator by r'/r (coaxiality), without forming Q.
  pure subroutine one_return(self, s, de, kappa, evol, region, info)
    class(empm_mohr_coulomb_t), intent(in) :: self
    real(wp), intent(inout) :: s(6), kappa, evol
    real(wp), intent(in) :: de(6)
    integer, intent(out) :: region, info
    real(wp) :: tr, p(3), Q(3,3), pn(3), dk, dv, c, d, r, pa, pb, pz, t
    integer :: iz
    tr = de(1) + de(2) + de(3)
    s(1:3) = s(1:3) + self%lam * tr + 2.0_wp * self%G * de(1:3)
    s(4:6) = s(4:6) + 2.0_wp * self%G * de(4:6)
    region = MC_ELASTIC; info = 0
    if (s(4) == 0.0_wp .and. s(5) == 0.0_wp) then
      c = 0.5_wp * (s(1) + s(2))
      d = 0.5_wp * (s(1) - s(2))
      ! hypot only where the squares could overflow (it is a slow library call).
      if (max(abs(d), abs(s(6))) < 1.0e150_wp) then
        r = sqrt(d * d + s(6) * s(6))
      else
        r = hypot(d, s(6))
      end if
      ! The order of principal_decompose: zz after any equal in-plane value.
      if (s(3) > c + r) then
        iz = 1; p = [s(3), c + r, c - r]
      else if (s(3) > c - r) then
        iz = 2; p = [c + r, s(3), c - r]
      else
        iz = 3; p = [c + r, c - r, s(3)]
      end if
      if (.not. plastic_trial(p)) return
      call mc_return_map(self, p, kappa, pn, dk, dv, region, info)
      if (info /= 0) return
      select case (iz)
      case (1)
        pz = pn(1); pa = pn(2); pb = pn(3)
      case (2)
        pa = pn(1); pz = pn(2); pb = pn(3)
      case default
        pa = pn(1); pb = pn(2); pz = pn(3)
      end select
      if (r > 0.0_wp) then
        t = 0.5_wp * (pa - pb) / r
        s(1) = 0.5_wp * (pa + pb) + t * d
        s(2) = 0.5_wp * (pa + pb) - t * d
        s(6) = t * s(6)
      else
        s(1) = pa; s(2) = pb; s(6) = 0.0_wp
      end if
      s(3) = pz
    else
      call principal_decompose(s, p, Q)
      if (.not. plastic_trial(p)) return
      call mc_return_map(self, p, kappa, pn, dk, dv, region, info)
      if (info /= 0) return
      s = principal_compose(pn, Q)
    end if
    kappa = kappa + dk
    evol = evol + dv

  contains

    ! The trial violates the yield condition (fixed strength: the precomputed planes).
    pure logical function plastic_trial(x)
      real(wp), intent(in) :: x(3)
      if (self%fixed) then
        plastic_trial = self%ap * x(1) - self%am * x(3) - self%k0 > 0.0_wp &
          .or. x(1) - self%st0 > 0.0_wp
      else
        plastic_trial = mc_yield_value(self, x, kappa) > 0.0_wp
      end if
    end function plastic_trial
  end subroutine one_return

  !> Stress update of one point over the strain increment `de` from the (already rotated)
  !> stress `s`: a single return, or with `substep_tolerance` > 0 substeps 2^-l of the step
  !> (l ≤ 10) each accepted when one return over it and two over its halves agree to the
  !> tolerance (relative to |σ| + c); at the finest level the substep is accepted as it is.
  !> `info` = 1 when a return failed (`region` tells why).
  pure subroutine mc_integrate(self, s, de, kappa, evol, region, info)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(inout) :: s(6)                !! stress, Voigt [Pa]
    real(wp), intent(in) :: de(6)                  !! strain increment, tensor shears
    real(wp), intent(inout) :: kappa               !! eps_p_shear
    real(wp), intent(inout) :: evol                !! eps_p_vol
    integer, intent(out) :: region                 !! last return's MC_* region
    integer, intent(out) :: info                   !! 0 ok, 1 failed
    real(wp) :: sa(6), ka, va, sb(6), kb, vb, h, dp(6), p(3), Q(3,3), lo, hi, mid, se(6), a
    integer :: lev, pos, span, rb, it
    sa = s; ka = kappa; va = evol
    call one_return(self, sa, de, ka, va, region, info)
    if (info /= 0) return
    if (self%substep_tol <= 0.0_wp .or. region == MC_ELASTIC) then
      s = sa; kappa = ka; evol = va; return
    end if
    ! The elastic part first (bisection for the fraction a at which the straight elastic path
    ! meets the surface): one full and two half returns agree exactly when the first half is
    ! elastic, so the error estimate would be blind to it.
    dp(1:3) = self%lam * (de(1) + de(2) + de(3)) + 2.0_wp * self%G * de(1:3)
    dp(4:6) = 2.0_wp * self%G * de(4:6)
    call principal_decompose(s, p, Q)
    a = 0.0_wp
    if (mc_yield_value(self, p, kappa) < 0.0_wp) then
      lo = 0.0_wp; hi = 1.0_wp
      do it = 1, 52
        mid = 0.5_wp * (lo + hi)
        se = s + mid * dp
        call principal_decompose(se, p, Q)
        if (mc_yield_value(self, p, kappa) < 0.0_wp) then
          lo = mid
        else
          hi = mid
        end if
      end do
      a = lo
      s = s + a * dp
    end if
    ! pos and span count in units of 2^-SUBSTEP_LEVELS of the plastic part (1 − a) de.
    lev = 0; pos = 0
    do while (pos < 2**SUBSTEP_LEVELS)
      span = 2**(SUBSTEP_LEVELS - lev)
      h = (1.0_wp - a) * real(span, wp) / 2**SUBSTEP_LEVELS
      if (lev > 0 .or. pos > 0 .or. a > 0.0_wp) then
        sa = s; ka = kappa; va = evol
        call one_return(self, sa, h * de, ka, va, region, info)
        if (info /= 0) return
      end if
      if (region == MC_ELASTIC) then
        s = sa; kappa = ka; evol = va; pos = pos + span; cycle
      end if
      sb = s; kb = kappa; vb = evol
      call one_return(self, sb, 0.5_wp * h * de, kb, vb, rb, info)
      if (info /= 0) return
      call one_return(self, sb, 0.5_wp * h * de, kb, vb, rb, info)
      if (info /= 0) return
      if (lev == SUBSTEP_LEVELS .or. maxval(abs(sb - sa)) <= self%substep_tol * &
          (maxval(abs(sb)) + self%c0)) then
        ! Local extrapolation: backward Euler is first order, so 2 sb − sa is second order
        ! (the estimate above bounds the error of sb, the extrapolated value is better).
        s = 2.0_wp * sb - sa; kappa = 2.0_wp * kb - ka; evol = 2.0_wp * vb - va
        pos = pos + span; region = rb
        ! Grow again after a success when the position allows the larger substep.
        if (lev > 0) then
          if (mod(pos, 2 * span) == 0) lev = lev - 1
        end if
      else
        lev = lev + 1
      end if
    end do
    ! The extrapolated stress is off the yield surface by a higher-order amount: return it
    ! (a zero increment: the trial is the stress itself), so that it is admissible to
    ! round-off as every one-return result is.
    sa = s; ka = kappa; va = evol
    call one_return(self, sa, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], ka, va, rb, info)
    if (info /= 0) return
    if (rb /= MC_ELASTIC) then
      s = sa; kappa = ka; evol = va; region = rb
    end if
  end subroutine mc_integrate

  ! ---- the material interface -----------------------------------------------------------------

  !> Update of `n` particles (see the module notes). `info = k > 0`: 1 + tr Δε <= 0 at particle
  !> k, or its return failed (the first such particle); −1: array extents disagree with n.
  pure subroutine mc_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: dt                     !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)          !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)       !! deformation gradient, left unchanged
    real(wp), intent(inout), contiguous :: strain(:,:)    !! small strain, Voigt (6,n)
    real(wp), intent(inout), contiguous :: stress(:,:)    !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)     !! eps_p_shear, eps_p_vol (rows 1, 2)
    real(wp), intent(inout), contiguous :: rho(:)         !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx   !! the kinematics' form (`midpoint`)
    integer, intent(out) :: info                   !! 0 ok; k > 0 particle k failed; −1 shapes
    real(wp) :: de(6), tr, jv
    integer :: p, n, region, ip
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n .or. size(state, 1) < 2 .or. size(state, 2) /= n) then
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
      call mc_integrate(self, stress(:,p), de, state(1,p), state(2,p), region, ip)
      if (ip /= 0 .and. info == 0) info = p
      rho(p) = rho(p) / jv
    end do
  end subroutine mc_update

  !> P-wave speed sqrt((K + 4G/3)/ρ) [m/s] (the elastic one: plastic flow only softens).
  pure real(wp) function mc_wave_speed(self, rho)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho                    !! current density [kg/m³]
    mc_wave_speed = sqrt((self%K + 4.0_wp * self%G / 3.0_wp) / rho)
  end function mc_wave_speed

  !> Elastic energy density from the stress, (tr σ)²/(18K) + s:s/(4G) [J/m³].
  pure subroutine mc_energy_density(self, F, strain, stress, state, psi)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)               !! deformation gradient, unused
    real(wp), intent(in) :: strain(:,:)            !! small strain, unused
    real(wp), intent(in) :: stress(:,:)            !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)             !! state variables, unused
    real(wp), intent(out) :: psi(:)                !! energy density (n) [J/m³]
    real(wp) :: tr, d(3)
    integer :: p
    associate (unused_ => F, unused2_ => strain, unused3_ => state); end associate
    do p = 1, min(size(psi), size(stress, 2))
      tr = stress(1,p) + stress(2,p) + stress(3,p)
      d = stress(1:3,p) - tr / 3.0_wp
      psi(p) = tr**2 / (18.0_wp * self%K) + (sum(d**2) + 2.0_wp * sum(stress(4:6,p)**2)) &
               / (4.0_wp * self%G)
    end do
  end subroutine mc_energy_density

  !> Why a particle failed.
  function mc_failure_text(self) result(s)
    class(empm_mohr_coulomb_t), intent(in) :: self !! material
    character(len=:), allocatable :: s             !! reason
    associate (unused_ => self); end associate
    s = 'its volume ratio became <= 0, or its Mohr-Coulomb return failed: the softening ' &
      //'consistency equation did not converge in 50 Newton iterations (softening too steep ' &
      //'for the elastic stiffness: reduce the step or lengthen softening_strain)'
  end function mc_failure_text
end module empm_material_mohr_coulomb
