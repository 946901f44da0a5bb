!> Stability and dissipation of the time integrators, measured on the library's own code.
!>
!> The amplification matrix of a scheme is built column by column: a small linear model is set
!> to a unit state, advanced by one `step` of the real integrator, and the new state is read
!> back. Nothing here re-derives a scheme's formulas (the one closed form, [[empm_hc_matrix]],
!> is Hulbert & Chung's nodal scheme, the reference gen_alpha_grid is compared with); the closed
!> forms in docs/integrators.md are checked against these matrices by tests/unit/
!> test_stability.pf.
!>
!> Models (1D, linear shape functions, linear elasticity with ν = 0, E = ρ = h = 1, so the
!> bar wave speed is c = 1):
!> - the *oscillator*: one cell [0, h], node 0 fixed, one particle of mass ρh at `position`·h
!>   (default ½, the cell centre). In the limit Δt → 0 its particle state (σ_p, v_p) oscillates
!>   at ω = c/h (not the lumped-mass nodal ω_n = sqrt(2)c/h: the particle carries the whole mass
!>   ρh but receives only N_1p = ½ of the nodal acceleration f_1/m_1). Hence Ω = ωΔt = CFL;
!> - the *lattice*: a fixed-free bar of `ncell` cells with `ppc` particles per cell at Gauss
!>   positions; state (σ_p, v_p, a_p) of every particle.
!>
!> State vector per particle z = (σ_p/(ρc), v_p, a_p h/c). Before each probe step the particle
!> positions, densities and volumes are reset to the reference configuration, which freezes
!> the linearisation point (shape functions and volumes at t = 0). What is left nonlinear in
!> one step is the volume change V = m/ρ multiplying the new stress and, for `pc_newmark`,
!> the basis at the drifted positions and its trapezoidal gradient: the even terms cancel in
!> the symmetric difference of the steps from +εe_j and −εe_j, and the O(ε²) error of the odd
!> (cubic) ones by Richardson extrapolation over ε and ε/2.
module empm_stability
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_particles, only: empm_particles_t
  use empm_particle_gen, only: empm_fill, GEOM_BOX, PLACE_GAUSS
  use empm_error, only: empm_error_t
  use empm_namelist, only: empm_kv
  use empm_registry, only: empm_create_shape, empm_create_material, empm_create_integrator
  use empm_integrator, only: empm_integrator_t
  use empm_linalg, only: empm_eigenvalues
  use empm_solver, only: empm_energies
  implicit none
  private
  public :: empm_scheme_spec_t, empm_root_t
  public :: empm_oscillator_matrix, empm_lattice_matrix, empm_principal_root
  public :: empm_oscillator_curve, empm_critical_omega, empm_lattice_critical_cfl
  public :: empm_lattice_growth, empm_hc_matrix, empm_hc_omega_crit
  public :: STAB_RHO_TOL

  !> A spectral radius up to 1 + STAB_RHO_TOL counts as stable. The allowance covers round-off
  !> and what is left of the probe's own nonlinearity (schemes that form a^{n+1} with the basis
  !> of x^{n+1}, pc_newmark, move the particles by Δt·v = O(AMP) within the step; see
  !> [[probe_matrix]]). A real instability exceeds it at once (ρ − 1 = 0.26 at CFL 2.02).
  real(wp), parameter :: STAB_RHO_TOL = 1.0e-10_wp

  real(wp), parameter :: E_MOD = 1.0_wp  ! Young's modulus of the probe models
  real(wp), parameter :: RHO0 = 1.0_wp   ! density
  real(wp), parameter :: H = 1.0_wp      ! cell size
  real(wp), parameter :: AMP = 1.0e-6_wp ! probe amplitude (strains of order 1e-6)

  !> A scheme and its parameters, as in a case file's `&integrator` group (created through the
  !> registry, so that any registered scheme can be analysed).
  type :: empm_scheme_spec_t
    character(len=32) :: name = 'pc_newmark'  !! scheme name
    character(len=256) :: params = ''         !! its keys as text, e.g. 'rho_b = 0.5'
  end type empm_scheme_spec_t

  !> Spectral radius and principal-root measures of one amplification matrix.
  !> With the principal pair λ = A ± iB = exp(Ω̄(−ξ̄ ± i)) (Hughes 1987, §9.3):
  !> Ω̄ = atan2(B, A), ξ̄ = −ln(A² + B²)/(2Ω̄), period error T̄/T − 1 = Ω/Ω̄ − 1.
  type :: empm_root_t
    real(wp) :: rho = 0.0_wp            !! spectral radius max |λ|
    logical :: oscillatory = .false.    !! a complex pair exists (else the measures below are 0)
    real(wp) :: modulus = 0.0_wp        !! |λ| of the principal pair
    real(wp) :: omega_bar = 0.0_wp      !! Ω̄ = arg λ, numerical frequency times Δt
    real(wp) :: xi = 0.0_wp             !! numerical damping ratio ξ̄
    real(wp) :: period_error = 0.0_wp   !! relative period error (T̄ − T)/T
  end type empm_root_t

  ! A probe model with its integrator and reference particle state.
  type :: probe_t
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_particles_t) :: ref
  end type probe_t

contains

  !> Amplification matrix (3×3, state (σ, v, a) scaled as in the module notes) of one step of
  !> `spec` on the one-cell oscillator at Ω = ωΔt. info: 0 ok, 1 bad scheme or parameter,
  !> 2 a step failed.
  subroutine empm_oscillator_matrix(spec, omega, A, info, position)
    type(empm_scheme_spec_t), intent(in) :: spec !! scheme
    real(wp), intent(in) :: omega                !! Ω = ωΔt, ω = c/h
    real(wp), intent(out) :: A(3, 3)             !! amplification matrix
    integer, intent(out) :: info                 !! status
    real(wp), intent(in), optional :: position   !! particle position / h in (0, 1], default ½
    type(probe_t) :: pr
    A = 0.0_wp
    call probe_build(pr, spec, 1, 1, pos_or_half(position), info)
    if (info /= 0) return
    call probe_matrix(pr, omega * H / wave_speed(), A, info)
  end subroutine empm_oscillator_matrix

  !> Amplification matrix (3·np × 3·np, np = ncell·ppc) of the fixed-free lattice at Courant
  !> number `cfl` (Δt = cfl·h/c). info as [[empm_oscillator_matrix]], 3 bad ncell/ppc or size.
  subroutine empm_lattice_matrix(spec, cfl, ncell, ppc, A, info)
    type(empm_scheme_spec_t), intent(in) :: spec !! scheme
    real(wp), intent(in) :: cfl                  !! Courant number
    integer, intent(in) :: ncell                 !! cells
    integer, intent(in) :: ppc                   !! particles per cell, 1..4
    real(wp), intent(out) :: A(:,:)              !! amplification matrix (3·np, 3·np)
    integer, intent(out) :: info                 !! status
    type(probe_t) :: pr
    A = 0.0_wp
    if (ncell < 1 .or. ppc < 1 .or. ppc > 4) then
      info = 3; return
    end if
    if (size(A, 1) /= 3 * ncell * ppc .or. size(A, 2) /= 3 * ncell * ppc) then
      info = 3; return
    end if
    call probe_build(pr, spec, ncell, ppc, 0.5_wp, info)
    if (info /= 0) return
    call probe_matrix(pr, cfl * H / wave_speed(), A, info)
  end subroutine empm_lattice_matrix

  !> Spectral radius and principal-root measures of `A` at Ω (LAPACK dgeev). The principal
  !> root is the complex eigenvalue with positive imaginary part (a 3×3 matrix has at most one
  !> pair); without one, `oscillatory` is false. info from LAPACK.
  subroutine empm_principal_root(A, omega, root, info)
    real(wp), intent(in) :: A(:,:)          !! square amplification matrix
    real(wp), intent(in) :: omega           !! Ω = ωΔt of the exact oscillator
    type(empm_root_t), intent(out) :: root  !! measures
    integer, intent(out) :: info            !! LAPACK status
    complex(wp) :: lam(size(A, 1))
    real(wp) :: best
    integer :: k, kp
    call empm_eigenvalues(A, lam, info)
    if (info /= 0) return
    root%rho = maxval(abs(lam))
    ! The pair of largest modulus, if several (lattice matrices).
    kp = 0; best = -1.0_wp
    do k = 1, size(lam)
      if (aimag(lam(k)) > 0.0_wp .and. abs(lam(k)) > best) then
        kp = k; best = abs(lam(k))
      end if
    end do
    if (kp == 0) return
    root%oscillatory = .true.
    root%modulus = abs(lam(kp))
    root%omega_bar = atan2(aimag(lam(kp)), real(lam(kp), wp))
    root%xi = -log(root%modulus) / root%omega_bar
    root%period_error = omega / root%omega_bar - 1.0_wp
  end subroutine empm_principal_root

  !> Measures of the oscillator at each Ω of `omegas` (one model, many matrices).
  subroutine empm_oscillator_curve(spec, omegas, roots, info, position)
    type(empm_scheme_spec_t), intent(in) :: spec  !! scheme
    real(wp), intent(in) :: omegas(:)             !! Ω values (> 0)
    type(empm_root_t), intent(out) :: roots(:)    !! measures, same size as `omegas`
    integer, intent(out) :: info                  !! status (see [[empm_oscillator_matrix]])
    real(wp), intent(in), optional :: position    !! particle position / h, default ½
    type(probe_t) :: pr
    real(wp) :: A(3, 3)
    integer :: k
    call probe_build(pr, spec, 1, 1, pos_or_half(position), info)
    if (info /= 0) return
    do k = 1, min(size(omegas), size(roots))
      call probe_matrix(pr, omegas(k) * H / wave_speed(), A, info)
      if (info /= 0) return
      call empm_principal_root(A, omegas(k), roots(k), info)
      if (info /= 0) return
    end do
  end subroutine empm_oscillator_curve

  !> Critical Ω of the oscillator: the first Ω at which ρ exceeds 1 + STAB_RHO_TOL, found by a
  !> scan in steps of 0.01 up to `omega_max` (default 4) and bisection to round-off.
  !> info: 0 found, −1 no instability up to omega_max (omega_crit = omega_max), else as above.
  subroutine empm_critical_omega(spec, omega_crit, info, omega_max, position)
    type(empm_scheme_spec_t), intent(in) :: spec  !! scheme
    real(wp), intent(out) :: omega_crit           !! critical Ω
    integer, intent(out) :: info                  !! status
    real(wp), intent(in), optional :: omega_max   !! end of the scan, default 4
    real(wp), intent(in), optional :: position    !! particle position / h, default ½
    type(probe_t) :: pr
    real(wp) :: xmax
    xmax = 4.0_wp
    if (present(omega_max)) xmax = omega_max
    omega_crit = 0.0_wp
    call probe_build(pr, spec, 1, 1, pos_or_half(position), info)
    if (info /= 0) return
    call first_crossing(pr, 0.0_wp, xmax, 0.01_wp, omega_crit, info)
  end subroutine empm_critical_omega

  !> Critical Courant number of the fixed-free lattice from its amplification matrix: first
  !> CFL with ρ > 1 + tol (scan in steps of 0.01 from `cfl_min`, default 0, to `cfl_max`,
  !> default 4, then bisection). info as [[empm_critical_omega]]; the scan assumes stability
  !> below cfl_min.
  subroutine empm_lattice_critical_cfl(spec, ncell, ppc, cfl_crit, info, cfl_min, cfl_max, tol)
    type(empm_scheme_spec_t), intent(in) :: spec  !! scheme
    integer, intent(in) :: ncell                  !! cells
    integer, intent(in) :: ppc                    !! particles per cell, 1..4
    real(wp), intent(out) :: cfl_crit             !! critical Courant number
    integer, intent(out) :: info                  !! status
    real(wp), intent(in), optional :: cfl_min     !! start of the scan, default 0
    real(wp), intent(in), optional :: cfl_max     !! end of the scan, default 4
    real(wp), intent(in), optional :: tol         !! allowance on ρ − 1, default STAB_RHO_TOL
    type(probe_t) :: pr
    real(wp) :: xmin, xmax, rtol
    xmin = 0.0_wp; xmax = 4.0_wp; rtol = STAB_RHO_TOL
    if (present(cfl_min)) xmin = cfl_min
    if (present(cfl_max)) xmax = cfl_max
    if (present(tol)) rtol = tol
    cfl_crit = 0.0_wp
    if (ncell < 1 .or. ppc < 1 .or. ppc > 4) then
      info = 3; return
    end if
    call probe_build(pr, spec, ncell, ppc, 0.5_wp, info)
    if (info /= 0) return
    call first_crossing(pr, xmin, xmax, 0.01_wp, cfl_crit, info, rtol)
  end subroutine empm_lattice_critical_cfl

  !> Direct growth test: run the fixed-free lattice (real steps, particles moving, nothing
  !> reset) from small pseudo-random particle velocities (|v| ≤ 1e-6 c, zero stress) for
  !> `nsteps` steps at Courant number `cfl`, and return the largest ratio of total energy
  !> (kinetic + strain) to its initial value. The run stops early once the ratio exceeds
  !> `stop_ratio` (default 1e6), so an unstable run never overflows.
  !> info: 0 ok, 1 bad scheme, 2 a step failed (counted as growth), 3 bad arguments.
  subroutine empm_lattice_growth(spec, ncell, ppc, cfl, nsteps, growth, info, stop_ratio)
    type(empm_scheme_spec_t), intent(in) :: spec  !! scheme
    integer, intent(in) :: ncell                  !! cells
    integer, intent(in) :: ppc                    !! particles per cell, 1..4
    real(wp), intent(in) :: cfl                   !! Courant number
    integer, intent(in) :: nsteps                 !! steps to run
    real(wp), intent(out) :: growth               !! max E(t)/E(0) over the run
    integer, intent(out) :: info                  !! status
    real(wp), intent(in), optional :: stop_ratio  !! stop when E/E(0) exceeds this, default 1e6
    type(probe_t) :: pr
    type(empm_step_status_t) :: stat
    real(wp), allocatable :: psi(:)
    real(wp) :: dt, e0, ek, es, eg, smax
    integer :: p, k
    growth = 1.0_wp
    smax = 1.0e6_wp
    if (present(stop_ratio)) smax = stop_ratio
    if (ncell < 1 .or. ppc < 1 .or. ppc > 4 .or. nsteps < 1) then
      info = 3; return
    end if
    call probe_build(pr, spec, ncell, ppc, 0.5_wp, info)
    if (info /= 0) return
    associate (pts => pr%model%pts)
      do p = 1, pts%np
        pts%v(1, p) = AMP * wave_speed() * hash_unit(p)
      end do
      ! Start the a-carrying schemes from the accelerations of this state (zero stress: 0).
      call pr%integ%prepare(pr%model)
      allocate(psi(pts%np))
      call empm_energies(pr%model, psi, ek, es, eg)
      e0 = ek + es
      dt = cfl * H / wave_speed()
      do k = 1, nsteps
        call pr%integ%step(pr%model, dt, stat)
        if (stat%code /= STEP_OK) then
          info = 2; growth = smax; return
        end if
        pr%model%t = pr%model%t + dt
        call empm_energies(pr%model, psi, ek, es, eg)
        growth = max(growth, (ek + es) / e0)
        if (growth > smax) return
      end do
    end associate
  end subroutine empm_lattice_growth

  !> Closed-form amplification matrix of Hulbert & Chung's explicit generalized-α (1996) on
  !> the SDOF oscillator ü + ω²u = 0, state (ωu, v, a/ω): the reference the MPM scheme is
  !> compared with. a⁺ = (−ω²u − α_m a)/(1 − α_m), u⁺ = u + Δt v + Δt²((½ − β)a + βa⁺),
  !> v⁺ = v + Δt((1 − γ)a + γa⁺).
  pure subroutine empm_hc_matrix(rho_b, omega, A)
    real(wp), intent(in) :: rho_b     !! spectral radius at infinity, [0, 1]
    real(wp), intent(in) :: omega     !! Ω = ωΔt
    real(wp), intent(out) :: A(3, 3)  !! amplification matrix
    real(wp) :: am, be, ga, arow(3)
    am = (2.0_wp * rho_b - 1.0_wp) / (1.0_wp + rho_b)
    be = (5.0_wp - 3.0_wp * rho_b) / ((1.0_wp + rho_b)**2 * (2.0_wp - rho_b))
    ga = 1.5_wp - am
    arow = [-1.0_wp, 0.0_wp, -am] / (1.0_wp - am)
    A(3, :) = arow
    A(1, :) = [1.0_wp, omega, omega**2 * (0.5_wp - be)] + omega**2 * be * arow
    A(2, :) = [0.0_wp, 1.0_wp, omega * (1.0_wp - ga)] + omega * ga * arow
  end subroutine empm_hc_matrix

  !> Critical Ω of Hulbert & Chung's explicit generalized-α, from det(A + I) = 0 of
  !> [[empm_hc_matrix]] (a real root leaves the unit circle through −1):
  !> Ω_s² = 12(1 + ρ_b)(2 − ρ_b)/(10 − 5ρ_b + ρ_b²) (= 12(1+ρ_b)³(2−ρ_b)/(10 + 15ρ_b + ρ_b² −
  !> 3ρ_b³ + ρ_b⁴)); 2 at ρ_b = 1 (central difference), sqrt(2.4) at ρ_b = 0.
  pure real(wp) function empm_hc_omega_crit(rho_b) result(om)
    real(wp), intent(in) :: rho_b !! spectral radius at infinity, [0, 1]
    om = sqrt(12.0_wp * (1.0_wp + rho_b) * (2.0_wp - rho_b) / (10.0_wp - 5.0_wp * rho_b + rho_b**2))
  end function empm_hc_omega_crit

  ! ---- internals ----------------------------------------------------------------------------

  pure real(wp) function wave_speed()
    wave_speed = sqrt(E_MOD / RHO0)
  end function wave_speed

  pure real(wp) function pos_or_half(position)
    real(wp), intent(in), optional :: position
    pos_or_half = 0.5_wp
    if (present(position)) pos_or_half = position
  end function pos_or_half

  ! Deterministic numbers in [−1, 1] (no global random state).
  pure real(wp) function hash_unit(k)
    integer, intent(in) :: k
    real(wp) :: s
    s = sin(12.9898_wp * real(k, wp)) * 43758.5453_wp
    hash_unit = 2.0_wp * (s - real(floor(s), wp)) - 1.0_wp
  end function hash_unit

  ! Set up a probe model: the one-cell oscillator (ncell = 1, ppc = 1, particle at
  ! position·h) or the fixed-free lattice; node 0 fixed. info 1: bad scheme/parameter/position.
  subroutine probe_build(pr, spec, ncell, ppc, position, info)
    type(probe_t), intent(inout) :: pr
    type(empm_scheme_spec_t), intent(in) :: spec
    integer, intent(in) :: ncell, ppc
    real(wp), intent(in) :: position
    integer, intent(out) :: info
    real(wp) :: zero3(3)
    integer :: stat, nadd, nsel
    type(empm_error_t) :: e
    zero3 = 0.0_wp
    info = 1
    if (.not. (position > 0.0_wp .and. position <= 1.0_wp)) return
    call pr%model%grid%init(1, [0.0_wp], [H], [ncell], stat)
    if (stat /= 0) return
    allocate(pr%model%mats(1))
    call empm_create_material('linear_elastic', empm_kv('E', E_MOD)//empm_kv('nu', 0.0_wp)// &
                              empm_kv('density', RHO0), pr%model%mats(1)%model, e)
    if (e%code /= 0) return
    if (ncell == 1 .and. ppc == 1) then
      call pr%model%pts%alloc(1, 1)
      call pr%model%pts%append([position * H], H, RHO0, [0.5_wp * H], 1)
    else
      call pr%model%pts%alloc(1, ncell * ppc)
      call empm_fill(pr%model%pts, pr%model%grid, GEOM_BOX, zero3, [ncell * H, 0.0_wp, 0.0_wp], &
                     zero3, 0.0_wp, ppc, PLACE_GAUSS, RHO0, 1, nadd, stat)
      if (stat /= 0) return
    end if
    call pr%model%nodes%fix_box(pr%model%grid, zero3, zero3, [.true., .false., .false.], &
                                zero3, nsel)
    call empm_create_shape('linear', pr%model%grid, pr%model%shape, e)
    if (e%code /= 0) return
    call pr%model%finalize_setup()
    call empm_create_integrator(trim(spec%name), pr%integ, e, trim(spec%params))
    if (e%code /= 0) return
    call pr%integ%prepare(pr%model)
    call pr%ref%alloc(1, pr%model%pts%np)
    call pr%ref%copy_state_from(pr%model%pts)
    info = 0
  end subroutine probe_build

  ! Amplification matrix by symmetric differences of single steps from ±ε·e_j, ε = AMP and
  ! AMP/2, extrapolated: D(ε) = A e_j + O(ε²) (a step is a polynomial of low degree in the
  ! state once the positions are reset), so (4 D(ε/2) − D(ε))/3 = A e_j + O(ε⁴).
  subroutine probe_matrix(pr, dt, A, info)
    type(probe_t), intent(inout) :: pr
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: A(:,:)
    integer, intent(out) :: info
    real(wp) :: z(size(A, 1)), zp(size(A, 1)), zm(size(A, 1)), d(size(A, 1), 2), eps
    integer :: j, k
    A = 0.0_wp
    do j = 1, size(A, 2)
      do k = 1, 2
        eps = AMP / k
        z = 0.0_wp
        z(j) = eps
        call probe_step(pr, dt, z, zp, info)
        if (info /= 0) return
        z(j) = -eps
        call probe_step(pr, dt, z, zm, info)
        if (info /= 0) return
        d(:, k) = (zp - zm) / (2.0_wp * eps)
      end do
      A(:, j) = (4.0_wp * d(:, 2) - d(:, 1)) / 3.0_wp
    end do
  end subroutine probe_matrix

  ! One step of the real integrator from the scaled state z (reference configuration).
  subroutine probe_step(pr, dt, z, znew, info)
    type(probe_t), intent(inout) :: pr
    real(wp), intent(in) :: dt, z(:)
    real(wp), intent(out) :: znew(:)
    integer, intent(out) :: info
    type(empm_step_status_t) :: stat
    real(wp) :: c
    integer :: p
    c = wave_speed()
    associate (pts => pr%model%pts)
      call pts%copy_state_from(pr%ref)
      do p = 1, pts%np
        pts%stress(1, p) = z(3 * p - 2) * RHO0 * c
        pts%v(1, p) = z(3 * p - 1)
        pts%a(1, p) = z(3 * p) * c / H
      end do
      ! The state was replaced: a basis carried from the last probe is stale.
      call pr%integ%resync(pr%model)
      call pr%integ%step(pr%model, dt, stat)
      info = 0
      if (stat%code /= STEP_OK) info = 2
      do p = 1, pts%np
        znew(3 * p - 2) = pts%stress(1, p) / (RHO0 * c)
        znew(3 * p - 1) = pts%v(1, p)
        znew(3 * p) = pts%a(1, p) * H / c
      end do
    end associate
  end subroutine probe_step

  ! Spectral radius of the probe's amplification matrix at x = ωΔt = CFL (c = h = 1 units).
  function probe_rho(pr, x, info) result(r)
    type(probe_t), intent(inout) :: pr
    real(wp), intent(in) :: x
    integer, intent(out) :: info
    real(wp) :: r
    real(wp) :: A(3 * pr%model%pts%np, 3 * pr%model%pts%np)
    type(empm_root_t) :: root
    r = huge(1.0_wp)
    call probe_matrix(pr, x * H / wave_speed(), A, info)
    if (info /= 0) return
    call empm_principal_root(A, x, root, info)
    r = root%rho
  end function probe_rho

  ! First x in (xmin, xmax] with ρ(x) > 1 + tol: scan with step dx, then bisection.
  ! info −1 when no crossing up to xmax (xc = xmax).
  subroutine first_crossing(pr, xmin, xmax, dx, xc, info, tol)
    type(probe_t), intent(inout) :: pr
    real(wp), intent(in) :: xmin, xmax, dx
    real(wp), intent(out) :: xc
    integer, intent(out) :: info
    real(wp), intent(in), optional :: tol
    real(wp) :: lo, hi, mid, t, r
    integer :: k, n
    t = STAB_RHO_TOL
    if (present(tol)) t = tol
    xc = xmax
    n = max(1, ceiling((xmax - xmin) / dx))
    lo = xmin; hi = -1.0_wp; info = 0
    do k = 1, n
      mid = min(xmin + k * dx, xmax)
      r = probe_rho(pr, mid, info)
      if (info /= 0) return
      if (r > 1.0_wp + t) then
        hi = mid; exit
      end if
      lo = mid
    end do
    if (hi < 0.0_wp) then
      info = -1; return
    end if
    do k = 1, 200
      if (hi - lo <= 4.0_wp * epsilon(1.0_wp) * hi) exit
      mid = 0.5_wp * (lo + hi)
      r = probe_rho(pr, mid, info)
      if (info /= 0) return
      if (r > 1.0_wp + t) then
        hi = mid
      else
        lo = mid
      end if
    end do
    xc = lo
  end subroutine first_crossing
end module empm_stability
