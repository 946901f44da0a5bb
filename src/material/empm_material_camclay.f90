!> Modified Cam-Clay (Roscoe and Burland 1968) with pressure-dependent elasticity, integrated
!> with an implicit (backward-Euler) return mapping inside an error-controlled sub-stepping loop.
!>
!> Compression-positive invariants: p' = −tr σ/3, q = √(3J₂), s = dev σ (σ tension positive).
!> Specific volume v = 1 + e, tracked exactly from the volumetric strain: v ← v exp(tr Δε)
!> (so ρ v stays constant: ρ ← ρ exp(−tr Δε)). The stress is rotated with the step's spin
!> ([[jaumann_rotate]]) and Δε turned by half of it ([[corotated_increment]]), so that the
!> Jaumann rate is integrated to second order under any motion.
!>
!> - Yield: f = q²/M² + p'(p' − p'c) ≤ 0; associated flow Δεᵖ = Δγ ∂f/∂σ.
!> - Elasticity: K = v p'/κ, written in the exact "κ-line" form ln(p'/p'ₙ) = −Δvᵉ/κ (v dεᵉ_vol =
!>   −dvᵉ); G = 3K(1 − 2ν)/(2(1 + ν)) (constant ν) or a constant G.
!> - Hardening: ln(p'c/p'cₙ) = −Δvᵖ/(λ − κ), Δvᵖ = −v Δεᵖ_vol (compression positive strain).
!>   Hence on the isotropic NCL (q = 0, p' = p'c) v − ln p' has slope λ exactly, and along the
!>   elastic (unloading) line slope κ exactly, whatever the increment size.
!> - Elastic predictor: the exact integral of the hypoelastic law along the step's straight
!>   strain path: p'_tr = p'ₙ exp(−Δv/κ), s_tr = sₙ + 2 G_sec Δe with the secant
!>   G_sec = α K_sec, K_sec = Δp'/(−tr Δε) (exact for constant ν because K dε_vol = dp').
!> - Plastic corrector (backward Euler): unknowns u = Δvᵖ and Δγ; p'(u) and p'c(u) are explicit
!>   exponentials, q = q_tr(G)/(1 + 6GΔγ/M²) with G = G(p'ₙ₊₁) (radial return, isotropic
!>   elasticity), residuals u + v Δγ (2p' − p'c) = 0 and f/p'cₙ² = 0, solved with a 2×2
!>   Newton to 1e-12 relative.
!> - By default (`substep_tolerance` = 0) one such return per call, the fast path for explicit
!>   MPM steps; when its Newton iteration fails, the increment is substepped with error control
!>   at 1e-6 instead of stopping the run.
!> - Error control (`substep_tolerance` > 0): a substep that starts inside the yield surface and
!>   ends outside it first takes its elastic part exactly (the crossing fraction by regula
!>   falsi); a plastic substep is compared with two half substeps; their difference (relative to
!>   p'c) must be below the tolerance, otherwise the substep shrinks (it grows again after a
!>   success). The result kept is the local extrapolation 2·(two halves) − (one step), second
!>   order. At 1e-8 this makes the result independent of how a strain increment is split:
!>   measured ≤ 7e-10 relative (docs/materials.md gives the figures and the cost).
!>
!> State variables: `pc` (p'c, Pa), `v` (specific volume), `resolved` (1 once `pc` and `v` are
!> known: with `ocr` or `N` they follow from the stress at the first update).
module empm_material_camclay
  use, intrinsic :: iso_c_binding, only: c_double
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t, STATE_NAME_LEN
  use empm_plasticity, only: corotated_increment, jaumann_rotate, mean_deviator, volume_ratio
  implicit none
  private
  public :: empm_camclay_t, camclay_stats_t

  real(wp), parameter :: TOL_NEWTON = 1.0e-12_wp !! relative residual of the local Newton
  integer, parameter :: MAXIT = 40               !! Newton iterations per return mapping
  real(wp), parameter :: FALLBACK_TOL = 1.0e-6_wp !! error control when one return failed
  ! 1/k! for the series of phi (e^x − 1)/x.
  real(wp), parameter :: R2 = 1.0_wp / 2.0_wp, R3 = 1.0_wp / 6.0_wp, R4 = 1.0_wp / 24.0_wp, &
    R5 = 1.0_wp / 120.0_wp, R6 = 1.0_wp / 720.0_wp, R7 = 1.0_wp / 5040.0_wp, &
    R8 = 1.0_wp / 40320.0_wp, R9 = 1.0_wp / 362880.0_wp, R10 = 1.0_wp / 3628800.0_wp
  integer, parameter :: MAXSUB = 5000            !! substeps per particle update
  real(wp), parameter :: HMIN = 1.0e-9_wp        !! smallest substep (fraction of the increment)
  real(wp), parameter :: EXP_CAP = 200.0_wp      !! exponent cap (no overflow in a failing Newton)

  !> Counters of one integration (for tests and the documentation's figures).
  type :: camclay_stats_t
    integer :: substeps = 0   !! accepted substeps
    integer :: rejected = 0   !! rejected substeps (error too large or Newton failed)
    integer :: newton = 0     !! Newton iterations, all return mappings together
    integer :: mappings = 0   !! plastic return mappings solved
  end type camclay_stats_t

  ! Why an update failed (the one cause, for failure_text).
  integer, parameter :: WHY_VOLUME = 1, WHY_RESOLVE = 2, WHY_RETURN = 3

  !> The last failure of an update: its cause and the particle's state at the step's start.
  type :: camclay_failure_t
    integer :: why = 0           !! WHY_* (0: none recorded)
    real(wp) :: p = 0.0_wp       !! p' [Pa]
    real(wp) :: q = 0.0_wp       !! q [Pa]
    real(wp) :: pc = 0.0_wp      !! p'c [Pa]
    real(wp) :: de = 0.0_wp      !! tr Δε (WHY_VOLUME) or |Δε| (WHY_RETURN)
  end type camclay_failure_t

  !> Modified Cam-Clay material (see the module notes).
  type, extends(empm_material_t) :: empm_camclay_t
    real(wp) :: lam = 0.0_wp     !! λ, NCL slope in v–ln p'
    real(wp) :: kap = 0.0_wp     !! κ, unloading-line slope in v–ln p'
    real(wp) :: M = 0.0_wp       !! critical-state stress ratio
    real(wp) :: N = 0.0_wp       !! v on the NCL at p' = p_ref (0: unset, e0 given)
    real(wp) :: e0 = -1.0_wp     !! initial void ratio (< 0: unset, N given)
    real(wp) :: p_ref = 1.0e3_wp !! reference pressure of N [Pa]
    real(wp) :: pc0 = 0.0_wp     !! initial p'c [Pa] (0: unset, ocr given)
    real(wp) :: ocr = 0.0_wp     !! overconsolidation ratio (0: unset, pc0 given)
    real(wp) :: nu = 0.0_wp      !! Poisson's ratio (constant-ν elasticity)
    real(wp) :: G = 0.0_wp       !! constant shear modulus [Pa] (0: constant ν instead)
    real(wp) :: p_min = 1.0_wp   !! confinement floor [Pa]
    real(wp) :: substep_tol = 0.0_wp !! error control of the substeps (0: one return per call)
    real(wp) :: alpha = 0.0_wp   !! G/K = 3(1 − 2ν)/(2(1 + ν)) for constant ν
    type(camclay_failure_t), pointer :: failure => null() !! the last failure (a pointer, so
                                                          !! that `update` can record it)
  contains
    procedure :: configure => cc_configure
    procedure :: family => cc_family
    procedure :: summary => cc_summary
    procedure :: params => cc_params
    procedure :: update => cc_update
    procedure :: wave_speed => cc_wave_speed
    procedure :: max_wave_speed => cc_max_wave_speed
    procedure :: energy_density => cc_energy_density
    procedure :: state_names => cc_state_names
    procedure :: init_state => cc_init_state
    procedure :: failure_text => cc_failure_text
    procedure :: integrate => cc_integrate
    procedure :: resolve => cc_resolve
    procedure :: shear_modulus => cc_shear_modulus
  end type empm_camclay_t

  interface
    !> C99 expm1 (libm): e^x − 1 without cancellation near 0. Declared pure: it has no side
    !> effects for finite arguments (it may set errno on overflow, which the caller caps).
    pure function c_expm1(x) bind(C, name='expm1') result(y)
      import :: c_double
      real(c_double), value :: x
      real(c_double) :: y
    end function c_expm1
  end interface

contains

  ! ---- description and configuration -------------------------------------------------------

  !> Registry name "camclay".
  pure function cc_family(self) result(s)
    class(empm_camclay_t), intent(in) :: self !! material
    character(len=:), allocatable :: s        !! "camclay"
    associate (unused_ => self); end associate
    s = 'camclay'
  end function cc_family

  !> One-line description.
  pure function cc_summary(self) result(s)
    class(empm_camclay_t), intent(in) :: self !! material
    character(len=:), allocatable :: s        !! summary
    associate (unused_ => self); end associate
    s = 'Modified Cam-Clay: pressure-dependent elasticity, implicit error-controlled return mapping'
  end function cc_summary

  !> Parameters (exactly one of each pair M/phi_cs, N/e0, pc0/ocr, nu/G).
  pure function cc_params(self) result(p)
    class(empm_camclay_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:)   !! declarations
    associate (unused_ => self); end associate
    p = [ &
      empm_param('density', PARAM_REAL, 'kg/m3', 'initial density', lo=1.0e-30_wp, &
        hi=1.0e30_wp), &
      empm_param('lambda', PARAM_REAL, '-', 'slope of the normal compression line in v-ln p''', &
        lo=0.0_wp, lo_open=.true., hi=10.0_wp), &
      empm_param('kappa', PARAM_REAL, '-', 'slope of the unloading line in v-ln p'' '// &
        '(kappa < lambda)', lo=0.0_wp, lo_open=.true., hi=10.0_wp), &
      empm_param('M', PARAM_REAL, '-', 'critical-state stress ratio q/p'' (give M or phi_cs)', &
        lo=0.0_wp, hi=3.0_wp, lo_open=.true., hi_open=.true., optional=.true.), &
      empm_param('phi_cs', PARAM_REAL, 'deg', 'critical-state friction angle: M = '// &
        '6 sin(phi)/(3 - sin(phi)) (give M or phi_cs)', lo=0.0_wp, hi=90.0_wp, &
        lo_open=.true., hi_open=.true., optional=.true.), &
      empm_param('N', PARAM_REAL, '-', 'specific volume on the isotropic NCL at p'' = p_ref; '// &
        'the initial v follows from the initial p'' and pc (give N or e0)', lo=1.0_wp, &
        lo_open=.true., hi=1.0e3_wp, optional=.true.), &
      empm_param('e0', PARAM_REAL, '-', 'initial void ratio: v0 = 1 + e0 (give N or e0)', &
        lo=0.0_wp, lo_open=.true., hi=1.0e3_wp, optional=.true.), &
      empm_param('p_ref', PARAM_REAL, 'Pa', 'reference pressure of N', default='1000', &
        lo=0.0_wp, lo_open=.true., hi=1.0e30_wp), &
      empm_param('pc0', PARAM_REAL, 'Pa', 'initial preconsolidation pressure p''c '// &
        '(compression positive; give pc0 or ocr)', lo=0.0_wp, lo_open=.true., hi=1.0e30_wp, &
        optional=.true.), &
      empm_param('ocr', PARAM_REAL, '-', 'overconsolidation ratio: pc0 = ocr (p0 + q0^2/(M^2 '// &
        'p0)) from the initial stress, resolved at the first update (give pc0 or ocr)', &
        lo=1.0_wp, hi=1.0e30_wp, optional=.true.), &
      empm_param('nu', PARAM_REAL, '-', 'constant Poisson ratio: G = 3K(1-2nu)/(2(1+nu)) '// &
        '(give nu or G)', lo=-1.0_wp, hi=0.5_wp, lo_open=.true., hi_open=.true., &
        optional=.true.), &
      empm_param('G', PARAM_REAL, 'Pa', 'constant shear modulus (give nu or G)', lo=0.0_wp, &
        lo_open=.true., hi=1.0e30_wp, optional=.true.), &
      empm_param('p_min', PARAM_REAL, 'Pa', 'confinement floor: a particle with p'' < p_min '// &
        'starts its update at p'' = p_min (so that K = v p''/kappa > 0)', default='1', &
        lo=0.0_wp, lo_open=.true., hi=1.0e30_wp), &
      empm_param('substep_tolerance', PARAM_REAL, '-', 'error control: a plastic substep '// &
        'against two half substeps, relative to p''c (e.g. 1e-8: independent of the split '// &
        'to 1e-8); 0: one backward-Euler return per call, substepped only when its Newton '// &
        'iteration fails (docs/materials.md)', default='0', lo=0.0_wp, hi=1.0e-2_wp)]
  end function cc_params

  !> Read and validate the keys; each pair must have exactly one member given.
  subroutine cc_configure(self, group, err)
    class(empm_camclay_t), intent(inout) :: self !! material
    type(empm_group_t), intent(inout) :: group   !! the `&material` group
    type(empm_error_t), intent(inout) :: err     !! set on a missing or invalid value
    type(empm_param_t), allocatable :: p(:)
    real(wp) :: phi, x
    real(wp), parameter :: PI = acos(-1.0_wp)
    if (.not. associated(self%failure)) allocate(self%failure)
    allocate(p, source=cc_params(self))
    call group%get(p(1), self%rho0, err)
    call group%get(p(2), self%lam, err)
    call group%get(p(3), self%kap, err)
    if (err%code /= 0) return
    if (.not. self%kap < self%lam) then
      call group%fail(err, 'kappa', 'kappa must be smaller than lambda (got kappa >= lambda)')
      return
    end if
    ! M or phi_cs
    call one_of('M', 'phi_cs'); if (err%code /= 0) return
    if (group%has('M')) then
      call group%get(p(4), self%M, err)
    else
      phi = 0.0_wp
      call group%get(p(5), phi, err)
      x = sin(phi * PI / 180.0_wp)
      self%M = 6.0_wp * x / (3.0_wp - x)
    end if
    ! N or e0
    call one_of('N', 'e0'); if (err%code /= 0) return
    if (group%has('N')) then
      call group%get(p(6), self%N, err)
      self%e0 = -1.0_wp
    else
      call group%get(p(7), self%e0, err)
      self%N = 0.0_wp
    end if
    call group%get(p(8), self%p_ref, err)
    ! pc0 or ocr
    call one_of('pc0', 'ocr'); if (err%code /= 0) return
    if (group%has('pc0')) then
      call group%get(p(9), self%pc0, err)
      self%ocr = 0.0_wp
    else
      call group%get(p(10), self%ocr, err)
      self%pc0 = 0.0_wp
    end if
    ! nu or G
    call one_of('nu', 'G'); if (err%code /= 0) return
    if (group%has('nu')) then
      call group%get(p(11), self%nu, err)
      self%G = 0.0_wp
      self%alpha = 1.5_wp * (1.0_wp - 2.0_wp * self%nu) / (1.0_wp + self%nu)
    else
      call group%get(p(12), self%G, err)
      self%alpha = 0.0_wp
    end if
    call group%get(p(13), self%p_min, err)
    call group%get(p(14), self%substep_tol, err)
    if (err%code /= 0) return
    if (self%pc0 > 0.0_wp .and. .not. self%p_min < self%pc0) &
      call group%fail(err, 'p_min', 'p_min must be smaller than pc0')
  contains
    subroutine one_of(a, b)
      character(len=*), intent(in) :: a, b
      if (err%code /= 0) return
      if (group%has(a) .and. group%has(b)) then
        call group%fail(err, b, 'give exactly one of '''//a//''' and '''//b//''', not both')
      else if (.not. (group%has(a) .or. group%has(b))) then
        call group%fail(err, a, 'required: give one of '''//a//''' and '''//b//'''')
      end if
    end subroutine one_of
  end subroutine cc_configure

  !> State variables: `pc` (p'c [Pa]), `v` (specific volume), `resolved` (1: pc and v known).
  pure subroutine cc_state_names(self, names)
    class(empm_camclay_t), intent(in) :: self                            !! material
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:)  !! pc, v, resolved
    associate (unused_ => self); end associate
    allocate(names(3))
    names(1) = 'pc'; names(2) = 'v'; names(3) = 'resolved'
  end subroutine cc_state_names

  !> Initial state from the keys: pc = pc0 and v = 1 + e0 where given (0 otherwise, resolved
  !> from the stress at the first update), `resolved` = 1 when both are known.
  pure subroutine cc_init_state(self, state)
    class(empm_camclay_t), intent(in) :: self  !! material
    real(wp), intent(out) :: state(:,:)        !! state variables (3, n)
    state = 0.0_wp
    if (size(state, 1) < 3) return
    state(1,:) = self%pc0
    if (self%e0 >= 0.0_wp) state(2,:) = 1.0_wp + self%e0
    if (self%pc0 > 0.0_wp .and. self%e0 >= 0.0_wp) state(3,:) = 1.0_wp
  end subroutine cc_init_state

  !> Resolve pc (from `ocr`) and v (from `N`) at the particle's current stress: p'₀ (floored at
  !> p_min), pc = ocr (p'₀ + q₀²/(M² p'₀)) (ocr times the yield surface through the stress),
  !> v = N − λ ln(pc/p_ref) + κ ln(pc/p'₀) (the κ-line from the NCL at pc). `ok` is false when
  !> v would not be positive.
  pure subroutine cc_resolve(self, sig, st, ok)
    class(empm_camclay_t), intent(in) :: self !! material
    real(wp), intent(in) :: sig(6)            !! current stress [Pa]
    real(wp), intent(inout) :: st(3)          !! pc, v, resolved
    logical, intent(out) :: ok                !! resolution succeeded
    real(wp) :: m, dev(6), q, p0
    ok = .true.
    if (st(3) /= 0.0_wp) return
    call mean_deviator(sig, m, dev, q)
    p0 = max(-m, self%p_min)
    if (self%ocr > 0.0_wp) st(1) = self%ocr * (p0 + q**2 / (self%M**2 * p0))
    if (self%e0 < 0.0_wp) st(2) = self%N - self%lam * log(st(1) / self%p_ref) &
                                  + self%kap * log(st(1) / p0)
    ok = st(2) > 0.0_wp .and. st(1) > 0.0_wp
    if (ok) st(3) = 1.0_wp
  end subroutine cc_resolve

  ! ---- update --------------------------------------------------------------------------------

  !> Update `n = size(rho)` particles: Jaumann rotation, then [[cc_integrate]] of the strain
  !> increment. `info = k > 0`: particle k (the first) failed and is left unchanged (volume
  !> ratio ≤ 0, v not positive at resolution, or the return mapping did not converge); −1:
  !> array extents disagree. F is not tracked (left as it is).
  subroutine cc_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_camclay_t), intent(in) :: self        !! material
    real(wp), intent(in) :: dt                       !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)       !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)    !! deformation gradient, left unchanged
    real(wp), intent(inout), contiguous :: strain(:,:) !! small strain, Voigt (6,n)
    real(wp), intent(inout), contiguous :: stress(:,:) !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)  !! pc, v, resolved (rows 1..3)
    real(wp), intent(inout), contiguous :: rho(:)      !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx     !! the kinematics' form (`midpoint`)
    integer, intent(out) :: info                     !! 0 ok; k > 0 particle k failed; −1 shapes
    real(wp) :: de(6), tr, sig(6), st(3), jv
    type(camclay_stats_t) :: stats
    integer :: p, n, status
    logical :: ok
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n .or. size(state, 2) /= n .or. size(state, 1) < 3) then
      info = -1
      return
    end if
    do p = 1, n
      de = corotated_increment(dt, L(:,:,p))
      tr = de(1) + de(2) + de(3)
      ! A volume ratio exp(tr) beyond e^±1 in one step is no soil increment: refuse it.
      jv = 1.0_wp + tr
      if (ctx%midpoint) jv = volume_ratio(dt, L(:,:,p), .true.)
      if (.not. (abs(tr) < 1.0_wp .and. jv > 0.0_wp)) then
        if (info == 0) info = p
        call record(WHY_VOLUME, stress(:,p), state(1,p), tr)
        cycle
      end if
      sig = stress(:,p)
      st = state(1:3,p)
      ! Module procedures called directly: no dispatch per particle.
      call cc_resolve(self, sig, st, ok)
      if (.not. ok) then
        if (info == 0) info = p
        call record(WHY_RESOLVE, sig, st(1), 0.0_wp)
        cycle
      end if
      call jaumann_rotate(dt, L(:,:,p), sig)
      call cc_integrate(self, de, sig, st, status, stats)
      if (status /= 0) then
        if (info == 0) info = p
        call record(WHY_RETURN, stress(:,p), state(1,p), sqrt(sum(de**2)))
        cycle
      end if
      strain(:,p) = strain(:,p) + de
      stress(:,p) = sig
      state(1:3,p) = st
      ! exp(tr Δε), as the specific volume's update: det ΔF to O(Δt³) with either kinematics
      ! (with the midpoint form, log det ΔF = tr ΔtL + O(Δt³)).
      rho(p) = rho(p) * fexp(-tr)
    end do
  contains
    ! Record a failure (rare: once per failing particle), one thread at a time.
    subroutine record(why, sig0, pc, x)
      integer, intent(in) :: why
      real(wp), intent(in) :: sig0(6), pc, x
      real(wp) :: m, dev(6), q
      if (.not. associated(self%failure)) return
      call mean_deviator(sig0, m, dev, q)
      !$omp critical (empm_camclay_failure)
      self%failure = camclay_failure_t(why, -m, q, pc, x)
      !$omp end critical (empm_camclay_failure)
    end subroutine record
  end subroutine cc_update

  !> Shear modulus at p' (floored at p_min) and v: α v p'/κ (constant ν) or the constant G.
  pure real(wp) function cc_shear_modulus(self, p, v) result(G)
    class(empm_camclay_t), intent(in) :: self !! material
    real(wp), intent(in) :: p                 !! p' [Pa]
    real(wp), intent(in) :: v                 !! specific volume
    if (self%G > 0.0_wp) then
      G = self%G
    else
      G = self%alpha * v * max(p, self%p_min) / self%kap
    end if
  end function cc_shear_modulus

  !> Integrate one strain increment `de` (after the rotation) from the resolved state: the
  !> confinement floor, then substeps (elastic ones exact and taken whole; plastic ones checked
  !> against two half substeps, see the module notes). `status` 0: converged; 1: the Newton
  !> iteration failed on the smallest substep or more than `MAXSUB` substeps were needed (then
  !> `sig` and `st` are unchanged).
  pure subroutine cc_integrate(self, de, sig, st, status, stats)
    class(empm_camclay_t), intent(in) :: self  !! material
    real(wp), intent(in) :: de(6)              !! strain increment (tensor shears)
    real(wp), intent(inout) :: sig(6)          !! stress [Pa], rotated to the step's end frame
    real(wp), intent(inout) :: st(3)           !! pc, v, resolved (resolved on entry)
    integer, intent(out) :: status             !! 0 ok, 1 failed
    type(camclay_stats_t), intent(out) :: stats !! substeps, Newton iterations
    real(wp) :: s0(6), pc0, v0, s1(6), pc1, v1, sh(6), pch, vh, s2(6), pc2, v2
    real(wp) :: t, h, hs, err, m, dev(6), q, fy, a, tol
    logical :: ok, plastic, last
    integer :: nit
    status = 0
    s0 = sig; pc0 = max(st(1), self%p_min); v0 = st(2)
    ! The confinement floor: a particle with p' < p_min starts at p' = p_min.
    if (-(s0(1) + s0(2) + s0(3)) / 3.0_wp < self%p_min) then
      call mean_deviator(s0, m, dev, q)
      s0(1:3) = dev(1:3) - self%p_min
    end if
    tol = self%substep_tol
    if (tol <= 0.0_wp) then
      ! One backward-Euler return over the whole increment (the common, fast case); only when
      ! its Newton iteration fails is the increment substepped, with error control.
      s1 = s0; pc1 = pc0; v1 = v0
      call be_step(self, de, s1, pc1, v1, ok, plastic, nit)
      stats%newton = nit
      if (plastic) stats%mappings = 1
      if (ok) then
        stats%substeps = 1
        sig = s1; st(1) = pc1; st(2) = v1
        return
      end if
      stats%rejected = 1
      tol = FALLBACK_TOL
    end if
    t = 0.0_wp; h = 1.0_wp
    do
      if (stats%substeps + stats%rejected >= MAXSUB .or. h < HMIN) then
        status = 1; return
      end if
      last = h >= 1.0_wp - t
      if (last) h = 1.0_wp - t
      ! A substep that leaves the elastic domain: its elastic part first, exactly (the return
      ! mapping of a partly elastic substep is only first order, extrapolated or not).
      call mean_deviator(s0, m, dev, q)
      fy = q**2 / self%M**2 + (-m) * (-m - pc0)
      if (fy < -1.0e-10_wp * pc0**2) then
        call elastic_trial(self, h * de, s0, pc0, v0, s1, fy)
        if (fy > 0.0_wp) then
          a = crossing(self, h * de, s0, pc0, v0)
          if (a > 0.0_wp) then
            call elastic_trial(self, a * h * de, s0, pc0, v0, s1, fy)
            v0 = v0 * exp(a * h * (de(1) + de(2) + de(3)))
            s0 = s1
            t = t + a * h
            h = (1.0_wp - a) * h
            cycle
          end if
        end if
      end if
      s1 = s0; pc1 = pc0; v1 = v0
      call be_step(self, h * de, s1, pc1, v1, ok, plastic, nit)
      stats%newton = stats%newton + nit
      if (plastic) stats%mappings = stats%mappings + 1
      if (.not. ok) then
        stats%rejected = stats%rejected + 1; h = 0.25_wp * h; cycle
      end if
      if (plastic) then
        sh = s0; pch = pc0; vh = v0
        call be_step(self, 0.5_wp * h * de, sh, pch, vh, ok, plastic, nit)
        stats%newton = stats%newton + nit
        if (plastic) stats%mappings = stats%mappings + 1
        if (ok) then
          s2 = sh; pc2 = pch; v2 = vh
          call be_step(self, 0.5_wp * h * de, s2, pc2, v2, ok, plastic, nit)
          stats%newton = stats%newton + nit
          if (plastic) stats%mappings = stats%mappings + 1
        end if
        if (.not. ok) then
          stats%rejected = stats%rejected + 1; h = 0.25_wp * h; cycle
        end if
        err = max(maxval(abs(s2 - s1)), abs(pc2 - pc1)) / max(pc1, pc2)
        if (err > tol) then
          stats%rejected = stats%rejected + 1
          h = h * max(0.1_wp, 0.9_wp * sqrt(tol / err))
          cycle
        end if
        ! Local extrapolation: the two estimates are first order with errors in the ratio 2:1,
        ! so 2 y_half − y_one is second order (both lie on the yield surface; the combination is
        ! off it by O(err²) relative, far below the consistency tolerance).
        s1 = 2.0_wp * s2 - s1; pc1 = 2.0_wp * pc2 - pc1; v1 = v2
        hs = h
        ! Grow the next substep (first-order local error ~ h²).
        h = h * min(4.0_wp, 0.9_wp * sqrt(tol / max(err, 1.0e-300_wp)))
      else
        hs = h
        h = 4.0_wp * h
      end if
      stats%substeps = stats%substeps + 1
      s0 = s1; pc0 = pc1; v0 = v1
      if (last) exit
      t = t + hs
    end do
    sig = s0; st(1) = pc0; st(2) = v0
  end subroutine cc_integrate

  !> One backward-Euler substep from (s, pc, v) with the strain increment `de`: the exact elastic
  !> predictor, and when it lies outside the yield surface the return mapping (2×2 Newton on
  !> u = Δvᵖ and Δγ). `ok` false: the Newton iteration did not converge (s, pc, v unchanged).
  pure subroutine be_step(self, de, s, pc, v, ok, plastic, nit)
    class(empm_camclay_t), intent(in) :: self
    real(wp), intent(in) :: de(6)
    real(wp), intent(inout) :: s(6), pc, v
    logical, intent(out) :: ok, plastic
    integer, intent(out) :: nit
    real(wp) :: m, dev(6), pn, tr, v1, dV, x, ksec, gsec, ded(6), str(6), qtr, ptr, f
    real(wp) :: a, b, c, u, dg, p, pc1, G, dGu, qtr2, dqtr, D, qn, dq_du, dq_dg
    real(wp) :: Ra, Rb, Ra_u, Ra_g, Rb_u, Rb_g, det, du, ddg, S2, M2, lk, sq(6)
    ok = .true.; plastic = .false.; nit = 0
    M2 = self%M**2; lk = self%lam - self%kap
    ! Mean stress and deviator (q is not needed here: no square root on the elastic path).
    m = (s(1) + s(2) + s(3)) / 3.0_wp
    dev(1:3) = s(1:3) - m; dev(4:6) = s(4:6)
    pn = -m
    tr = de(1) + de(2) + de(3)
    v1 = v * fexp(tr)
    dV = v * tr * phi(tr)                 ! v1 − v without cancellation
    ded(1:3) = de(1:3) - tr / 3.0_wp
    ded(4:6) = de(4:6)
    ! Exact elastic predictor.
    x = -dV / self%kap
    ptr = pn * fexp(x)
    if (self%G > 0.0_wp) then
      gsec = self%G
    else
      ksec = pn * phi(x) * (v / self%kap) * phi(tr)
      gsec = self%alpha * ksec
    end if
    str = dev + 2.0_wp * gsec * ded
    qtr2 = 1.5_wp * (str(1)**2 + str(2)**2 + str(3)**2) + 3.0_wp * (str(4)**2 + str(5)**2 + &
      str(6)**2)
    f = qtr2 / M2 + ptr * (ptr - pc)
    if (f <= 0.0_wp) then
      s(1:3) = str(1:3) - ptr; s(4:6) = str(4:6)
      v = v1
      return
    end if
    plastic = .true.
    ! Return mapping. q_tr(G)² = a + 2bG + cG² with s_tr(G) = dev + 2G Δe.
    a = 1.5_wp * sum(dev(1:3)**2) + 3.0_wp * sum(dev(4:6)**2)
    b = 1.5_wp * sum(dev(1:3) * 2.0_wp * ded(1:3)) + 3.0_wp * sum(dev(4:6) * 2.0_wp * ded(4:6))
    c = 1.5_wp * sum((2.0_wp * ded(1:3))**2) + 3.0_wp * sum((2.0_wp * ded(4:6))**2)
    S2 = pc**2
    u = 0.0_wp; dg = 0.0_wp
    do
      p = pn * fexp(min((u - dV) / self%kap, EXP_CAP))
      pc1 = pc * fexp(min(-u / lk, EXP_CAP))
      if (self%G > 0.0_wp) then
        G = self%G; dGu = 0.0_wp
      else
        G = self%alpha * v1 * p / self%kap; dGu = G / self%kap
      end if
      qtr2 = max(a + 2.0_wp * b * G + c * G**2, 0.0_wp)
      qtr = sqrt(qtr2)
      dqtr = 0.0_wp
      if (qtr > 0.0_wp) dqtr = (b + c * G) * dGu / qtr
      D = 1.0_wp + 6.0_wp * G * dg / M2
      qn = qtr / D
      Ra = u + v1 * dg * (2.0_wp * p - pc1)
      f = qn**2 / M2 + p * (p - pc1)
      Rb = f / S2
      if (abs(Ra) <= TOL_NEWTON * self%kap .and. abs(f) <= TOL_NEWTON * min(pc, pc1)**2) exit
      if (nit >= MAXIT) then
        ok = .false.; return
      end if
      nit = nit + 1
      dq_du = dqtr / D - qtr * 6.0_wp * dg * dGu / (M2 * D**2)
      dq_dg = -qtr * 6.0_wp * G / (M2 * D**2)
      Ra_u = 1.0_wp + v1 * dg * (2.0_wp * p / self%kap + pc1 / lk)
      Ra_g = v1 * (2.0_wp * p - pc1)
      Rb_u = (2.0_wp * qn * dq_du / M2 + (2.0_wp * p - pc1) * p / self%kap + p * pc1 / lk) / S2
      Rb_g = 2.0_wp * qn * dq_dg / M2 / S2
      det = Ra_u * Rb_g - Ra_g * Rb_u
      if (.not. (abs(det) > 0.0_wp .and. abs(det) <= huge(det))) then
        ok = .false.; return
      end if
      du = -(Ra * Rb_g - Ra_g * Rb) / det
      ddg = -(Ra_u * Rb - Rb_u * Ra) / det
      if (.not. (abs(du) <= huge(du) .and. abs(ddg) <= huge(ddg))) then
        ok = .false.; return
      end if
      ! Keep each iterate sane: p' may change by at most a factor e³, Δγ stays ≥ 0.
      du = max(-3.0_wp * self%kap, min(3.0_wp * self%kap, du))
      u = u + du
      if (dg + ddg < 0.0_wp) then
        dg = 0.5_wp * dg
      else
        dg = dg + ddg
      end if
    end do
    sq = (dev + 2.0_wp * G * ded) / D
    s(1:3) = sq(1:3) - p; s(4:6) = sq(4:6)
    pc = pc1; v = v1
  end subroutine be_step

  !> The exact elastic step of `de` from (s, v): the new stress `se` and its yield value `f`
  !> for the hardening variable `pc`.
  pure subroutine elastic_trial(self, de, s, pc, v, se, f)
    class(empm_camclay_t), intent(in) :: self
    real(wp), intent(in) :: de(6), s(6), pc, v
    real(wp), intent(out) :: se(6), f
    real(wp) :: m, dev(6), q, pn, tr, dV, x, ptr, gsec
    call mean_deviator(s, m, dev, q)
    pn = -m
    tr = de(1) + de(2) + de(3)
    dV = v * tr * phi(tr)
    x = -dV / self%kap
    ptr = pn * exp(min(x, EXP_CAP))
    if (self%G > 0.0_wp) then
      gsec = self%G
    else
      gsec = self%alpha * pn * phi(x) * (v / self%kap) * phi(tr)
    end if
    se(1:3) = dev(1:3) + 2.0_wp * gsec * (de(1:3) - tr / 3.0_wp)
    se(4:6) = dev(4:6) + 2.0_wp * gsec * de(4:6)
    q = sqrt(1.5_wp * sum(se(1:3)**2) + 3.0_wp * sum(se(4:6)**2))
    f = q**2 / self%M**2 + ptr * (ptr - pc)
    se(1:3) = se(1:3) - ptr
  end subroutine elastic_trial

  !> Fraction a in (0, 1) of `de` at which the exact elastic path from a state inside the
  !> yield surface (f < 0) reaches it (f(1) > 0): Illinois regula falsi on f, to round-off.
  pure real(wp) function crossing(self, de, s, pc, v) result(a)
    class(empm_camclay_t), intent(in) :: self
    real(wp), intent(in) :: de(6), s(6), pc, v
    real(wp) :: a0, a1, f0, f1, fa, se(6), m, dev(6), q
    integer :: it, side
    call mean_deviator(s, m, dev, q)
    f0 = q**2 / self%M**2 + (-m) * (-m - pc)
    call elastic_trial(self, de, s, pc, v, se, f1)
    a0 = 0.0_wp; a1 = 1.0_wp; a = 0.0_wp; side = 0
    do it = 1, 100
      a = (a0 * f1 - a1 * f0) / (f1 - f0)
      call elastic_trial(self, a * de, s, pc, v, se, fa)
      if (abs(fa) <= 1.0e-15_wp * pc**2 .or. a1 - a0 <= 1.0e-15_wp) exit
      if (fa > 0.0_wp) then
        a1 = a; f1 = fa
        if (side == 1) f0 = 0.5_wp * f0
        side = 1
      else
        a0 = a; f0 = fa
        if (side == -1) f1 = 0.5_wp * f1
        side = -1
      end if
    end do
    ! Stay on the elastic side: a state exactly at or just inside the surface.
    if (fa > 0.0_wp) a = a0
  end function crossing

  !> φ(x) = (eˣ − 1)/x, φ(0) = 1, accurate for all x (series near 0, where eˣ − 1 cancels).
  pure elemental real(wp) function phi(x)
    real(wp), intent(in) :: x
    real(wp) :: x2, x4
    if (abs(x) < 0.05_wp) then
      ! Σ xᵏ/(k+1)!, k = 0..9 (Horner): the first omitted term is below 0.05¹⁰/11! ≈ 2.4e-21.
      ! MPM increments land here: a few multiply-adds (a 20-term series with a division per
      ! term was most of a Cam-Clay update).
      ! Estrin's scheme: the same polynomial in pairs, a dependency chain of 4 multiply-adds
      ! instead of 9 (the update is bound by latency, and this runs 4-8 times per update).
      x2 = x * x
      x4 = x2 * x2
      phi = ((1.0_wp + R2 * x) + x2 * (R3 + R4 * x)) + x4 * ((R5 + R6 * x) + x2 * (R7 + R8 * x)) &
        + (x4 * x4) * (R9 + R10 * x)
    else
      ! expm1 has no cancellation for small x (C99's, through libm).
      phi = c_expm1(min(x, EXP_CAP)) / x
    end if
  end function phi

  !> e^x: for |x| < 0.05 (the exponents of an MPM step's increment) 1 + x·phi(x), equal to exp
  !> to the last bit or two, at a fraction of a library call; else exp.
  pure elemental real(wp) function fexp(x)
    real(wp), intent(in) :: x
    if (abs(x) < 0.05_wp) then
      fexp = 1.0_wp + x * phi(x)
    else
      fexp = exp(x)
    end if
  end function fexp

  ! ---- wave speeds, energy, failure text ---------------------------------------------------

  !> P-wave speed at the initial stiffness scale: K = v_s p_s/κ with p_s = pc0 (or p_ref when
  !> `ocr` is given) and v_s = 1 + e0 (or N). The CFL step uses [[cc_max_wave_speed]].
  pure real(wp) function cc_wave_speed(self, rho)
    class(empm_camclay_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho               !! current density [kg/m³]
    real(wp) :: vs, ps, K, G
    vs = merge(1.0_wp + self%e0, self%N, self%e0 >= 0.0_wp)
    ps = merge(self%pc0, self%p_ref, self%pc0 > 0.0_wp)
    K = vs * ps / self%kap
    G = self%shear_modulus(ps, vs)
    cc_wave_speed = sqrt((K + 4.0_wp * G / 3.0_wp) / rho)
  end function cc_wave_speed

  !> Largest P-wave speed over a run: K = v max(p', p_min)/κ and G at each particle's stress
  !> (before resolution the scale of [[cc_wave_speed]]).
  pure real(wp) function cc_max_wave_speed(self, rho, stress, state) result(c)
    class(empm_camclay_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho(:)             !! densities (n) [kg/m³]
    real(wp), intent(in) :: stress(:,:)        !! Cauchy stresses (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)         !! state variables (nstate_max,n)
    real(wp) :: v, p, K, G
    integer :: i
    real(wp) :: c2
    c = 0.0_wp; c2 = 0.0_wp
    do i = 1, size(rho)
      if (size(state, 1) < 3) then
        c = max(c, self%wave_speed(rho(i))); cycle
      end if
      if (state(3,i) == 0.0_wp .or. .not. state(2,i) > 0.0_wp) then
        c = max(c, self%wave_speed(rho(i))); cycle
      end if
      v = state(2,i)
      p = max(-(stress(1,i) + stress(2,i) + stress(3,i)) / 3.0_wp, self%p_min)
      K = v * p / self%kap
      G = self%shear_modulus(p, v)
      c2 = max(c2, (K + 4.0_wp * G / 3.0_wp) / rho(i))
    end do
    c = max(c, sqrt(c2))
  end function cc_max_wave_speed

  !> Elastic energy estimate ψ = κ p'/v + q²/(6G(p')): the volumetric term is the work of the
  !> elastic law from p' = 0 at fixed v (exact for κ-line paths), the shear term the
  !> current-stiffness value. Before resolution v is taken as 1 + e0 or N.
  pure subroutine cc_energy_density(self, F, strain, stress, state, psi)
    class(empm_camclay_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)          !! deformation gradient, unused
    real(wp), intent(in) :: strain(:,:)       !! small strain, unused
    real(wp), intent(in) :: stress(:,:)       !! Cauchy stress (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)        !! pc, v, resolved
    real(wp), intent(out) :: psi(:)           !! energy density (n) [J/m³]
    real(wp) :: m, dev(6), q, v, p
    integer :: i
    associate (unused_ => F, unused2_ => strain); end associate
    do i = 1, min(size(psi), size(stress, 2))
      call mean_deviator(stress(:,i), m, dev, q)
      v = merge(1.0_wp + self%e0, self%N, self%e0 >= 0.0_wp)
      if (size(state, 1) >= 3) then
        if (state(2,i) > 0.0_wp) v = state(2,i)
      end if
      p = max(-m, 0.0_wp)
      psi(i) = self%kap * p / v + q**2 / (6.0_wp * self%shear_modulus(p, v))
    end do
  end subroutine cc_energy_density

  !> Why a particle failed.
  function cc_failure_text(self) result(s)
    class(empm_camclay_t), intent(in) :: self !! material
    character(len=:), allocatable :: s        !! reason
    character(len=160) :: b
    integer :: why
    why = 0
    if (associated(self%failure)) why = self%failure%why
    select case (why)
    case (WHY_VOLUME)
      write(b, '(a,es10.3,a)') 'its volume ratio exp(tr de) for tr de = ', self%failure%de, &
        ' left (1/e, e) in one step'
      s = 'the Modified Cam-Clay update refused the step: '//trim(b)// &
        ' (a strain increment too large for a soil step: reduce dt or cfl)'
    case (WHY_RESOLVE)
      write(b, '(a,es10.3,a,es10.3,a)') 'p'' = ', self%failure%p, ' Pa, p''c = ', &
        self%failure%pc, ' Pa'
      s = 'the Modified Cam-Clay initial state is not valid: the specific volume from N is '// &
        'not positive at '//trim(b)//' (check N, lambda, kappa, ocr and the initial stress)'
    case (WHY_RETURN)
      write(b, '(a,es10.3,a,es10.3,a,es10.3,a,es10.3)') 'p'' = ', self%failure%p, &
        ' Pa, q = ', self%failure%q, ' Pa, p''c = ', self%failure%pc, ' Pa, |de| = ', &
        self%failure%de
      s = 'the Modified Cam-Clay return mapping did not converge at '//trim(b)// &
        ' (the local Newton iteration failed on the smallest substep, or the substep cap '// &
        'was reached: the strain increment of the step is too large, reduce dt or cfl)'
    case default
      s = 'the Modified Cam-Clay update failed'
    end select
  end function cc_failure_text
end module empm_material_camclay
