!> Explicit predictor-corrector (the paper, section 4), with two particle updates:
!> `pc_published` (eqs. 33–35 as printed, eq. 33's typo fixed) and `pc_newmark` (the update
!> consistent with explicit Newmark, β = 0). See docs/integrators.md.
!>
!> One step, γ = γ_N (Newmark γ):
!> 1. m_I = Σ N_Ip m_p
!> 2. predictor v*_I = Σ N_Ip m_p (v_p + (1−γ)Δt a_p) / m_I;  3. Dirichlet values on v*_I
!> 4. L_p = Σ v*_I ⊗ ∇N_Ip, Δε = Δt sym L;  5. density and stress update
!> 6. pc_published: f_I at t+Δt from the new stresses (basis of x^n), zero on fixed dofs;
!>    a_I = f_I/m_I; corrector v_I = v*_I + γ Δt a_I;
!>    a_p = Σ N a_I, v_p += Δt a_p, x_p += Δt Σ N v_I + ½Δt² Σ N a_I
!> 7. pc_newmark (steps 4–5 move after the drift), drift: L⁰_p = Σ v*_I ⊗ ∇N_Ip kept;
!>    x_p += dx_p + Δt Σ N v*_I + (γ − ½)Δt² a_p, v_p += (1−γ)Δt a_p; then the basis at x^{n+1}
!>    (kept for the next step), the same particle velocities mapped on it (u_I); the stress
!>    with the trapezoidal gradient of L⁰ and L_p = Σ u_I ⊗ ∇N_Ip; dx_p = ½Δt Σ N (u_I − v*_I)
!>    for the next drift; f_I at t+Δt, a_I = f_I/m_I; kick: a_p = Σ N a_I, v_p += γΔt a_p
module empm_integrator_pc
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL
  use empm_namelist, only: empm_group_t
  use empm_integrator, only: empm_integrator_t, map_velocity, update_stress, initial_acceleration, &
                             drift_prepare, drift_begin, drift_end
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_transfer, only: g2p_add_scaled, g2p_value, nodal_divide_by_mass
  use empm_timer, only: PHASE_P2G, PHASE_GRID, PHASE_G2P, PHASE_STRESS
  implicit none
  private
  public :: empm_pc_t, PC_PUBLISHED, PC_NEWMARK

  integer, parameter :: PC_PUBLISHED = 1 !! particle update of eqs. (33)–(35)
  integer, parameter :: PC_NEWMARK = 2   !! Newmark-consistent particle update

  !> Explicit predictor-corrector.
  type, extends(empm_integrator_t) :: empm_pc_t
    integer :: variant = PC_NEWMARK  !! PC_PUBLISHED or PC_NEWMARK
    real(wp) :: gamma = 0.5_wp       !! Newmark γ_N, in [0, 1]
  contains
    procedure :: step => pc_step
    procedure :: family => pc_family
    procedure :: summary => pc_summary
    procedure :: params => pc_params
    procedure :: configure => pc_configure
    procedure :: start => pc_start
    procedure :: walls => pc_walls
  end type empm_pc_t

contains

  !> Registry name: "pc_published" or "pc_newmark".
  pure function pc_family(self) result(s)
    class(empm_pc_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s  !! name
    if (self%variant == PC_PUBLISHED) then
      s = 'pc_published'
    else
      s = 'pc_newmark'
    end if
  end function pc_family

  !> One-line description.
  pure function pc_summary(self) result(s)
    class(empm_pc_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s  !! summary
    if (self%variant == PC_PUBLISHED) then
      s = 'explicit predictor-corrector, particle update of eqs. (33)-(35) as published'
    else
      s = 'explicit predictor-corrector with the Newmark-consistent particle update'
    end if
  end function pc_summary

  !> Parameters: the Newmark γ_N.
  pure function pc_params(self) result(p)
    class(empm_pc_t), intent(in) :: self     !! integrator
    type(empm_param_t), allocatable :: p(:)  !! declarations
    associate (unused_ => self); end associate
    p = [empm_param('newmark_gamma', PARAM_REAL, '-', 'Newmark gamma_N of the predictor '// &
      'and corrector (0.5: second order)', default='0.5', lo=0.0_wp, hi=1.0_wp)]
  end function pc_params

  !> Read γ_N from the `&integrator` group.
  subroutine pc_configure(self, group, err)
    class(empm_pc_t), intent(inout) :: self    !! integrator
    type(empm_group_t), intent(inout) :: group !! the `&integrator` group
    type(empm_error_t), intent(inout) :: err   !! set on an invalid value
    type(empm_param_t), allocatable :: p(:)
    allocate(p, source=self%params())
    call group%get(p(1), self%gamma, err)
  end subroutine pc_configure

  !> Initial particle accelerations (the predictor uses a_p).
  subroutine pc_start(self, model)
    class(empm_pc_t), intent(inout) :: self     !! integrator
    type(empm_model_t), intent(inout) :: model  !! simulation state
    if (self%variant == PC_NEWMARK) call drift_prepare(self, model)
    call initial_acceleration(self, model)
  end subroutine pc_start

  !> Frictional walls are supported. The force of t + Δt acts on the velocity twice: γΔt in
  !> this step's corrector (kick), (1 − γ)Δt in the next step's predictor; the friction is sized
  !> over the whole Δt, so that a sticking node's predicted velocity v*_I, the one that moves
  !> and strains the particles, is zero (sized over γΔt, the next predictor would reverse it).
  pure logical function pc_walls(self)
    class(empm_pc_t), intent(in) :: self !! integrator
    associate (unused_ => self); end associate
    pc_walls = .true.
  end function pc_walls

  !> One predictor-corrector step.
  subroutine pc_step(self, model, dt, stat)
    class(empm_pc_t), intent(inout) :: self         !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: dt                      !! time step [s]
    type(empm_step_status_t), intent(out) :: stat   !! outcome
    real(wp) :: g
    g = self%gamma
    associate (nodes => model%nodes, pts => model%pts, basis => model%basis, tm => self%timer)
      ! Predictor v*_I, formed from particle data (eq. 31) to avoid dividing accelerations.
      call map_velocity(self, model, stat, (1.0_wp - g) * dt, pts%a)
      if (stat%code /= STEP_OK) return
      if (self%variant == PC_PUBLISHED) then
        ! Strain increment and stress with the predicted velocity.
        call update_stress(model, nodes%vel, dt, stat, self)
        call tm%lap(PHASE_STRESS)
        if (stat%code /= STEP_OK) return
        ! Balance of forces at t + Δt with the basis of x^n, as published; nodes%acc = f/m
        ! (zero on fixed dofs).
        call self%assemble_forces(model, model%t + dt, dt)
        call tm%lap(PHASE_P2G)
        call nodal_divide_by_mass(nodes, nodes%force, nodes%acc)
        call tm%lap(PHASE_GRID)
        ! Corrector v_I = v* + γΔt a_I into the scratch array; eqs. (33)–(35).
        nodes%work = nodes%vel + g * dt * nodes%acc
        call g2p_add_scaled(basis, dt, nodes%work, pts%x)
        call g2p_add_scaled(basis, 0.5_wp * dt * dt, nodes%acc, pts%x)
        call g2p_value(basis, nodes%acc, pts%a)
        pts%v(:, 1:pts%np) = pts%v(:, 1:pts%np) + dt * pts%a(:, 1:pts%np)
      else
        ! Newmark β = 0: drift with the predictor v* (the particles' v + (1−γ)Δt a mapped on
        ! the basis of x^n), trapezoidal over the bases of x^n and x^{n+1} (the projection
        ! particles → grid → particles moves with the particles; docs/integrators.md), then
        ! the stress with the drift's deformation gradient.
        ! One pass: x += (γ − ½)Δt² a_p, the drift's first half, v += (1 − γ)Δt a_p.
        call drift_begin(self, model, nodes%vel, dt, (g - 0.5_wp) * dt * dt, (1.0_wp - g) * dt)
        call tm%lap(PHASE_G2P)
        call drift_end(self, model, dt, stat)
        if (stat%code /= STEP_OK) return
        ! Kick: a^{n+1} = f(σ^{n+1}, t + Δt)/m on the grid the particles now see.
        call self%assemble_forces(model, model%t + dt, dt)
        call tm%lap(PHASE_P2G)
        call nodal_divide_by_mass(nodes, nodes%force, nodes%acc)
        call tm%lap(PHASE_GRID)
        call g2p_value(basis, nodes%acc, pts%a, g * dt, pts%v) ! and v += γΔt a_p
      end if
      call tm%lap(PHASE_G2P)
    end associate
  end subroutine pc_step
end module empm_integrator_pc
