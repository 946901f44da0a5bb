!> Integrator extension point: the abstract explicit time integrator, and the step building
!> blocks shared by all schemes (basis evaluation, nodal forces, stress update).
!>
!> A scheme implements `step`, which advances the model by Δt. Adding a scheme means adding
!> one file that extends [[empm_integrator_t]] and one line in [[empm_integrator_factory]].
module empm_integrator
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_SHAPE_FAILED, &
                        STEP_MATERIAL_FAILED
  use empm_transfer, only: p2g_mass, p2g_internal_force, p2g_body_force, constrain_force, &
                           nodal_divide_by_mass, g2p_value
  implicit none
  private
  public :: empm_integrator_t, eval_basis, update_stress, initial_acceleration

  !> Abstract explicit integrator. Work arrays are allocated once in `prepare`.
  type, abstract :: empm_integrator_t
    real(wp), allocatable :: bwork(:,:)  !! body-force scratch (ndim, np)
  contains
    procedure(step_iface), deferred :: step
    procedure(name_iface), deferred :: name
    procedure :: prepare => integrator_prepare
    procedure :: start => integrator_start
    procedure :: assemble_forces
  end type empm_integrator_t

  abstract interface
    !> Advance `model` from t to t + dt. On failure `stat` names the particle and cause.
    subroutine step_iface(self, model, dt, stat)
      import :: empm_integrator_t, empm_model_t, empm_step_status_t, wp
      class(empm_integrator_t), intent(inout) :: self !! integrator (work arrays)
      type(empm_model_t), intent(inout) :: model      !! simulation state
      real(wp), intent(in) :: dt                      !! time step [s]
      type(empm_step_status_t), intent(out) :: stat   !! outcome
    end subroutine step_iface

    !> Scheme identifier, e.g. "usl", "musl".
    function name_iface(self) result(s)
      import :: empm_integrator_t
      class(empm_integrator_t), intent(in) :: self !! integrator
      character(len=:), allocatable :: s           !! identifier
    end function name_iface
  end interface

contains

  !> Allocate work arrays for `model` and initialise the scheme's state (`start`). Call once,
  !> after the model's set-up, before stepping ([[empm_solve]] does).
  subroutine integrator_prepare(self, model)
    class(empm_integrator_t), intent(inout) :: self !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    if (allocated(self%bwork)) deallocate(self%bwork)
    allocate(self%bwork(model%grid%ndim, model%pts%np))
    self%bwork = 0.0_wp
    call self%start(model)
  end subroutine integrator_prepare

  !> Scheme-specific initialisation hook; the default does nothing.
  subroutine integrator_start(self, model)
    class(empm_integrator_t), intent(inout) :: self !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state
    associate (unused_self => self, unused_model => model)
    end associate
  end subroutine integrator_start

  !> Particle accelerations consistent with the initial state, a_p = Σ N_Ip f_I/m_I at the
  !> current time, for schemes that carry a_p between steps (predictor-corrector,
  !> generalized-α). A shape failure is left for the first step to report.
  subroutine initial_acceleration(self, model)
    class(empm_integrator_t), intent(inout) :: self !! integrator (body-force scratch)
    type(empm_model_t), intent(inout) :: model      !! simulation state
    type(empm_step_status_t) :: stat
    call eval_basis(model, stat)
    if (stat%code /= 0) return
    call model%nodes%reset()
    call p2g_mass(model%basis, model%pts%m, model%nodes%mass)
    call self%assemble_forces(model, model%t)
    call nodal_divide_by_mass(model%nodes, model%nodes%force, model%nodes%acc)
    call g2p_value(model%basis, model%nodes%acc, model%pts%a)
  end subroutine initial_acceleration

  !> Evaluate shape functions at the current particle positions (one batched call).
  subroutine eval_basis(model, stat)
    type(empm_model_t), intent(inout) :: model    !! simulation state
    type(empm_step_status_t), intent(inout) :: stat !! set on failure
    integer :: ibad, info
    call model%shape%eval_batch(model%grid, model%pts, model%basis, ibad, info)
    if (info /= 0) then
      stat%code = STEP_SHAPE_FAILED; stat%detail = info; stat%particle = ibad
    end if
  end subroutine eval_basis

  !> Total nodal force at time `t` (paper eqs. 16–17): reset, internal force from the current
  !> stresses, gravity and the body-force callback; zeroed on fixed dofs.
  subroutine assemble_forces(self, model, t)
    class(empm_integrator_t), intent(inout) :: self !! integrator (body-force scratch)
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: t                       !! time at which loads are evaluated [s]
    real(wp) :: g(3)
    integer :: np, d
    np = model%pts%np; d = model%grid%ndim
    model%nodes%force = 0.0_wp
    call p2g_internal_force(model%basis, model%pts%vol, model%pts%stress, model%nodes%force)
    g = model%loads%gravity_at(t)
    if (allocated(model%loads%body_force)) then
      call model%loads%body_force%eval(t, model%pts%x0(:, 1:np), model%pts%x(:, 1:np), &
                                  self%bwork(:, 1:np))
      call p2g_body_force(model%basis, model%pts%m, g(1:d), self%bwork, .true., &
                          model%nodes%force)
    else
      call p2g_body_force(model%basis, model%pts%m, g(1:d), self%bwork, .false., &
                          model%nodes%force)
    end if
    call constrain_force(model%nodes, model%nodes%force)
  end subroutine assemble_forces

  !> Stress update of every particle from its velocity gradient `pts%L`, one batched call per
  !> run of particles sharing a material; volumes follow from the updated densities.
  subroutine update_stress(model, dt, stat)
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: dt                      !! time step [s]
    type(empm_step_status_t), intent(inout) :: stat !! set on failure
    integer :: r, i0, i1, info, im
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      im = model%pts%mat(i0)
      call model%mats(im)%model%update(dt, model%pts%L(:, :, i0:i1), model%pts%F(:, :, i0:i1), &
        model%pts%strain(:, i0:i1), model%pts%stress(:, i0:i1), model%pts%rho(i0:i1), info)
      if (info /= 0) then
        stat%code = STEP_MATERIAL_FAILED; stat%detail = info; stat%particle = i0 + info - 1
        return
      end if
    end do
    model%pts%vol(1:model%pts%np) = model%pts%m(1:model%pts%np) / model%pts%rho(1:model%pts%np)
  end subroutine update_stress
end module empm_integrator
