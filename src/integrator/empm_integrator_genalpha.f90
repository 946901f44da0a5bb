!> Explicit generalized-α MPM (Tran & Sołowski 2019, after Hulbert & Chung's explicit
!> generalized-α; paper eqs. 25–27), parameterised by the spectral radius at infinity ρ_b:
!> α_m = (2ρ_b − 1)/(1 + ρ_b), β = (5 − 3ρ_b)/((1 + ρ_b)²(2 − ρ_b)), γ = 3/2 − α_m.
!>
!> One step:
!> 1. m_I, v_I = Σ N m_p v_p / m_I, a_I = Σ N m_p a_p / m_I (Dirichlet: v prescribed, a = 0)
!> 2. f_I from the current stresses at t; a⁺_I = (f_I/m_I − α_m a_I)/(1 − α_m) (0 on fixed dofs)
!> 3. Δu_I = Δt v_I + Δt² ((½ − β) a_I + β a⁺_I)
!> 4. x_p += Σ N Δu_I;  v_p += Δt Σ N ((1−γ) a_I + γ a⁺_I);  a_p = Σ N a⁺_I
!> 5. L_p = Σ (Δu_I/Δt) ⊗ ∇N: the strain increment matches the displacement of step 4.
!>
!> `gen_alpha` (the same α_m, β, γ), second order under large motion
!> (docs/integrators.md): the α_m recursion runs on the particles,
!> a_p⁺ = (Σ N f_I/m_I − α_m a_p)/(1 − α_m); the Newmark displacement is formed on the particles
!> and projected, Δu_I = Δt P2G(v + Δt((½ − β) a + β a⁺))_I (as pc_newmark projects v*), with
!> the trapezoidal drift over the bases of x^n and x^{n+1} and its deformation gradient;
!> v_p += Δt((1 − γ) a_p + γ a_p⁺), a_p = a_p⁺.
module empm_integrator_genalpha
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL
  use empm_namelist, only: empm_group_t
  use empm_integrator, only: empm_integrator_t, map_velocity, update_stress, initial_acceleration, &
                             drift_prepare, drift_begin, drift_end
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_transfer, only: p2g_weighted, g2p_add_scaled, g2p_value, &
                           nodal_divide_by_mass
  use empm_timer, only: PHASE_P2G, PHASE_GRID, PHASE_G2P, PHASE_STRESS
  implicit none
  private
  public :: empm_genalpha_t, genalpha_parameters, GA_PUBLISHED, GA_PARTICLE

  integer, parameter :: GA_PUBLISHED = 1 !! Tran & Sołowski's scheme (nodal α_m recursion)
  integer, parameter :: GA_PARTICLE = 2  !! α_m recursion and Newmark displacement on the
                                         !! particles, trapezoidal drift

  !> Explicit generalized-α.
  type, extends(empm_integrator_t) :: empm_genalpha_t
    real(wp) :: rho_b = 0.8_wp  !! spectral radius at infinite frequency, in [0, 1]
    integer :: variant = GA_PUBLISHED !! GA_PUBLISHED or GA_PARTICLE
    real(wp), allocatable :: dv(:,:) !! gen_alpha: the new particle accelerations of a step
                                     !! (ndim, np)
  contains
    procedure :: step => ga_step
    procedure :: family => ga_family
    procedure :: summary => ga_summary
    procedure :: params => ga_params
    procedure :: configure => ga_configure
    procedure :: start => ga_start
  end type empm_genalpha_t

contains

  !> Parameters α_m, β, γ from ρ_b (in real arithmetic throughout).
  pure subroutine genalpha_parameters(rho_b, alpha_m, beta, gamma)
    real(wp), intent(in) :: rho_b     !! spectral radius at infinity, [0, 1]
    real(wp), intent(out) :: alpha_m  !! α_m
    real(wp), intent(out) :: beta     !! Newmark β
    real(wp), intent(out) :: gamma    !! Newmark γ
    alpha_m = (2.0_wp * rho_b - 1.0_wp) / (1.0_wp + rho_b)
    beta = (5.0_wp - 3.0_wp * rho_b) / ((1.0_wp + rho_b)**2 * (2.0_wp - rho_b))
    gamma = 1.5_wp - alpha_m
  end subroutine genalpha_parameters

  !> Registry name: "gen_alpha_grid" or "gen_alpha".
  pure function ga_family(self) result(s)
    class(empm_genalpha_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s        !! name
    if (self%variant == GA_PARTICLE) then
      s = 'gen_alpha'
    else
      s = 'gen_alpha_grid'
    end if
  end function ga_family

  !> One-line description.
  pure function ga_summary(self) result(s)
    class(empm_genalpha_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s        !! summary
    if (self%variant == GA_PARTICLE) then
      s = 'explicit generalized-alpha with the recursion and displacement on the particles '// &
          'and a trapezoidal drift'
    else
      s = 'explicit generalized-alpha (Tran & Solowski 2019)'
    end if
  end function ga_summary

  !> Parameters: the spectral radius at infinite frequency ρ_b.
  pure function ga_params(self) result(p)
    class(empm_genalpha_t), intent(in) :: self !! integrator
    type(empm_param_t), allocatable :: p(:)    !! declarations
    associate (unused_ => self); end associate
    p = [empm_param('rho_b', PARAM_REAL, '-', 'spectral radius at infinite frequency '// &
      '(1: no numerical damping)', default='0.8', lo=0.0_wp, hi=1.0_wp)]
  end function ga_params

  !> Read ρ_b from the `&integrator` group.
  subroutine ga_configure(self, group, err)
    class(empm_genalpha_t), intent(inout) :: self !! integrator
    type(empm_group_t), intent(inout) :: group    !! the `&integrator` group
    type(empm_error_t), intent(inout) :: err      !! set on an invalid value
    type(empm_param_t), allocatable :: p(:)
    allocate(p, source=self%params())
    call group%get(p(1), self%rho_b, err)
  end subroutine ga_configure

  !> Initial particle accelerations.
  subroutine ga_start(self, model)
    class(empm_genalpha_t), intent(inout) :: self !! integrator
    type(empm_model_t), intent(inout) :: model    !! simulation state
    if (self%variant == GA_PARTICLE) then
      call drift_prepare(self, model)
      if (allocated(self%dv)) deallocate(self%dv)
      allocate(self%dv(model%grid%ndim, model%pts%np))
    end if
    call initial_acceleration(self, model)
  end subroutine ga_start

  !> One generalized-α step.
  subroutine ga_step(self, model, dt, stat)
    class(empm_genalpha_t), intent(inout) :: self   !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: dt                      !! time step [s]
    type(empm_step_status_t), intent(out) :: stat   !! outcome
    real(wp) :: am, be, ga
    call genalpha_parameters(self%rho_b, am, be, ga)
    if (self%variant == GA_PARTICLE) then
      call particle_step(self, model, dt, am, be, ga, stat)
      return
    end if
    associate (nodes => model%nodes, pts => model%pts, basis => model%basis, tm => self%timer)
      call map_velocity(self, model, stat)
      if (stat%code /= STEP_OK) return
      ! a_I^k in nodes%work (mass-weighted map of particle accelerations, accumulated in acc).
      nodes%acc = 0.0_wp
      call p2g_weighted(basis, pts%m, pts%a, 0.0_wp, pts%a, nodes%acc, self%p2g)
      call model%halo%sum(model%comm, nodes%acc)
      call tm%lap(PHASE_P2G)
      call nodal_divide_by_mass(nodes, nodes%acc, nodes%work)
      call nodes%constrain_force(nodes%work)
      call tm%lap(PHASE_GRID)
      ! a_I^{k+1} in nodes%acc.
      call self%assemble_forces(model, model%t)
      call tm%lap(PHASE_P2G)
      call nodal_divide_by_mass(nodes, nodes%force, nodes%acc)
      nodes%acc = (nodes%acc - am * nodes%work) / (1.0_wp - am)
      call nodes%constrain_force(nodes%acc)
      call tm%lap(PHASE_GRID)
      ! Particle velocity from both accelerations; then Δu_I (reusing nodes%force).
      call g2p_add_scaled(basis, dt * (1.0_wp - ga), nodes%work, pts%v)
      call g2p_add_scaled(basis, dt * ga, nodes%acc, pts%v)
      nodes%force = dt * nodes%vel + dt * dt * ((0.5_wp - be) * nodes%work + be * nodes%acc)
      call g2p_add_scaled(basis, 1.0_wp, nodes%force, pts%x)
      call g2p_value(basis, nodes%acc, pts%a)
      call tm%lap(PHASE_G2P)
      ! Strain with the nodal displacement actually applied: L = Σ (Δu_I/Δt) ⊗ ∇N.
      nodes%force = nodes%force / dt
      call update_stress(model, nodes%force, dt, stat, self)
      call tm%lap(PHASE_STRESS)
    end associate
  end subroutine ga_step

  !> One `gen_alpha` step (module header). The basis and masses are carried from the last
  !> step; the velocities v_I are mapped only where they are used (the local damping) or with
  !> a new basis (the first step, a restart). The displacement rate
  !> w_p = v_p + Δt((½ − β) a_p + β a_p⁺) is mapped on the same basis, momentum only.
  subroutine particle_step(self, model, dt, am, be, ga, stat)
    class(empm_genalpha_t), intent(inout) :: self   !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: dt                      !! time step [s]
    real(wp), intent(in) :: am                      !! α_m
    real(wp), intent(in) :: be                      !! β
    real(wp), intent(in) :: ga                      !! γ
    type(empm_step_status_t), intent(out) :: stat   !! outcome
    integer :: np
    associate (nodes => model%nodes, pts => model%pts, basis => model%basis, tm => self%timer)
      np = pts%np
      if (self%damping > 0.0_wp .or. .not. self%basis_ready) then
        call map_velocity(self, model, stat)
        if (stat%code /= STEP_OK) return
        self%basis_ready = .true. ! the masses stay valid: the next mapping adds only momentum
      end if
      call self%assemble_forces(model, model%t)
      call tm%lap(PHASE_P2G)
      call nodal_divide_by_mass(nodes, nodes%force, nodes%acc)
      call nodes%constrain_force(nodes%acc)
      call tm%lap(PHASE_GRID)
      ! a_p⁺ in dv; then v_p holds w_p while the drift maps it.
      call g2p_value(basis, nodes%acc, self%dv)
      self%dv(:, 1:np) = (self%dv(:, 1:np) - am * pts%a(:, 1:np)) / (1.0_wp - am)
      pts%v(:, 1:np) = pts%v(:, 1:np) + dt * ((0.5_wp - be) * pts%a(:, 1:np) + &
                                              be * self%dv(:, 1:np))
      call tm%lap(PHASE_G2P)
      call map_velocity(self, model, stat)
      if (stat%code /= STEP_OK) return
      call drift_begin(self, model, nodes%vel, dt)
      call tm%lap(PHASE_G2P)
      call drift_end(self, model, dt, stat)
      if (stat%code /= STEP_OK) return
      ! v_p = w_p + Δt((½ − γ + β) a_p + (γ − β) a_p⁺) = v_p^n + Δt((1 − γ) a_p + γ a_p⁺).
      pts%v(:, 1:np) = pts%v(:, 1:np) + dt * ((0.5_wp - ga + be) * pts%a(:, 1:np) + &
                                              (ga - be) * self%dv(:, 1:np))
      pts%a(:, 1:np) = self%dv(:, 1:np)
      call tm%lap(PHASE_G2P)
    end associate
  end subroutine particle_step
end module empm_integrator_genalpha
