!> Forward-Euler MPM schemes: USF, USL (Sulsky et al. 1994; paper eqs. 21–22) and MUSL
!> (the momentum-based modified update of Zhang et al. 2016; paper eqs. 23–24).
!>
!> All three advance particle velocities with the nodal acceleration and positions with the
!> updated nodal velocity: v_p += Δt Σ N_Ip f_I/m_I, x_p += Δt Σ N_Ip p_I^{k+1}/m_I (eqs. 23–24
!> written with the momentum to avoid dividing accelerations by tiny masses). They differ only
!> in when and with which nodal velocity the stress is updated:
!> - USF: before the forces, with v_I^k = p_I^k/m_I;
!> - USL: after the particle update, with the updated nodal velocity v_I^{k+1};
!> - MUSL: after the particle update, with velocities re-mapped from the updated particles.
module empm_integrator_euler
  use empm_kinds, only: wp
  use empm_integrator, only: empm_integrator_t, map_velocity, update_stress
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_transfer, only: p2g_weighted, g2p_add_scaled, g2p_value, &
                           nodal_divide_by_mass
  use empm_timer, only: PHASE_P2G, PHASE_GRID, PHASE_G2P, PHASE_STRESS
  implicit none
  private
  public :: empm_euler_t, EULER_USF, EULER_USL, EULER_MUSL

  integer, parameter :: EULER_USF = 1  !! update stress first
  integer, parameter :: EULER_USL = 2  !! update stress last
  integer, parameter :: EULER_MUSL = 3 !! modified update stress last

  !> Forward-Euler family.
  type, extends(empm_integrator_t) :: empm_euler_t
    integer :: variant = EULER_MUSL !! EULER_USF, EULER_USL or EULER_MUSL
  contains
    procedure :: step => euler_step
    procedure :: family => euler_family
    procedure :: summary => euler_summary
    procedure :: walls => euler_walls
  end type empm_euler_t

contains

  !> Registry name: "usf", "usl" or "musl".
  pure function euler_family(self) result(s)
    class(empm_euler_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s      !! name
    select case (self%variant)
    case (EULER_USF); s = 'usf'
    case (EULER_USL); s = 'usl'
    case default;     s = 'musl'
    end select
  end function euler_family

  !> One-line description.
  pure function euler_summary(self) result(s)
    class(empm_euler_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s      !! summary
    select case (self%variant)
    case (EULER_USF); s = 'forward Euler, update stress first'
    case (EULER_USL); s = 'forward Euler, update stress last'
    case default;     s = 'forward Euler, modified update stress last (velocities re-mapped)'
    end select
  end function euler_summary

  !> Frictional walls are supported: the nodal force is added over Δt to v_I = p_I/m_I.
  pure logical function euler_walls(self)
    class(empm_euler_t), intent(in) :: self !! integrator
    associate (unused_ => self); end associate
    euler_walls = .true.
  end function euler_walls

  !> One forward-Euler step.
  subroutine euler_step(self, model, dt, stat)
    class(empm_euler_t), intent(inout) :: self      !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: dt                      !! time step [s]
    type(empm_step_status_t), intent(out) :: stat   !! outcome
    associate (nodes => model%nodes, pts => model%pts, basis => model%basis, tm => self%timer)
      call map_velocity(self, model, stat)
      if (stat%code /= STEP_OK) return

      if (self%variant == EULER_USF) then
        call update_stress(model, nodes%vel, dt, stat, self)
        call tm%lap(PHASE_STRESS)
        if (stat%code /= STEP_OK) return
      end if

      call self%assemble_forces(model, model%t, dt)
      call tm%lap(PHASE_P2G)
      ! p^{k+1} = p^k + Δt f, then the constraints on the new nodal velocity.
      nodes%mom = nodes%mom + dt * nodes%force
      call nodal_divide_by_mass(nodes, nodes%force, nodes%acc)
      call nodal_divide_by_mass(nodes, nodes%mom, nodes%vel)
      call nodes%constrain_velocity(nodes%vel, nodes%mom)
      call tm%lap(PHASE_GRID)

      ! a_p = Σ N a_I and v_p += Δt a_p in one pass; x_p += Δt Σ N v_I here, or for USL in
      ! the stress update's pass over the same field (the same bits either way).
      call g2p_value(basis, nodes%acc, pts%a, dt, pts%v)
      if (self%variant /= EULER_USL) call g2p_add_scaled(basis, dt, nodes%vel, pts%x)
      call tm%lap(PHASE_G2P)

      select case (self%variant)
      case (EULER_USL)
        call update_stress(model, nodes%vel, dt, stat, self, cx=dt)
        call tm%lap(PHASE_STRESS)
      case (EULER_MUSL)
        ! Re-map momentum from the updated particle velocities (Sulsky's MUSL).
        nodes%mom = 0.0_wp
        call p2g_weighted(basis, pts%m, pts%v, 0.0_wp, pts%v, nodes%mom, self%p2g)
        call model%halo%sum(model%comm, nodes%mom)
        call tm%lap(PHASE_P2G)
        call nodal_divide_by_mass(nodes, nodes%mom, nodes%vel)
        call nodes%constrain_velocity(nodes%vel, nodes%mom)
        call tm%lap(PHASE_GRID)
        call update_stress(model, nodes%vel, dt, stat, self)
        call tm%lap(PHASE_STRESS)
      end select
    end associate
  end subroutine euler_step
end module empm_integrator_euler
