!> Integrator extension point: the abstract explicit time integrator, and the step building
!> blocks shared by all schemes (basis evaluation, nodal forces, stress update).
!>
!> A scheme implements `step`, which advances the model by Δt. Adding a scheme means adding
!> one file that extends [[empm_integrator_t]] and one line in [[empm_registry]].
module empm_integrator
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_tensor, only: adjugate3
  use empm_error, only: empm_error_t, empm_raise, empm_raise_error, empm_alloc_error, &
                        EMPM_ERR_INPUT
  use empm_family, only: empm_family_t
  use empm_namelist, only: empm_group_t
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_SHAPE_FAILED, &
                        STEP_MATERIAL_FAILED
  use empm_transfer, only: p2g_mass, p2g_mass_momentum, p2g_weighted, p2g_internal_force, &
                           p2g_body_force, &
                           nodal_divide_by_mass, g2p_value, &
                           velocity_gradient, gradient_g2p_block, g2p_block, axpy_flat, &
                           empm_p2g_work_t
  use empm_timer, only: empm_phase_timer_t, PHASE_SHAPE, PHASE_P2G, PHASE_GRID, PHASE_STRESS, &
                        PHASE_G2P
  use empm_material, only: empm_material_ctx_t
  use empm_shape, only: BASIS_LISTS
  use empm_parallel, only: empm_max_threads, empm_chunks, empm_chunk_bounds, &
                           EMPM_OMP_MIN_PARTICLES
  implicit none
  private
  public :: empm_integrator_t, eval_basis, map_velocity, update_stress, initial_acceleration
  public :: drift_prepare, drift_begin, drift_end, WALL_SCHEMES

  !> Particles per material call in [[update_stress]]: their L, F, strain and stress fit in
  !> the L1 cache together.
  integer, parameter :: STRESS_BLOCK = 32
  !> Particles per screen of the updated fields and per stored-energy call in [[update_stress]]
  !> (the run-time guards' and the energy history's share of the stress pass): a multiple of
  !> STRESS_BLOCK, small enough for the group's stress, strain and state to stay in cache.
  integer, parameter :: SCREEN_GROUP = 256
  !> The schemes whose `walls` is true (messages).
  character(len=*), parameter :: WALL_SCHEMES = 'usf, usl, musl, pc_published and pc_newmark'

  !> Abstract explicit integrator. Work arrays are allocated once in `prepare`. A scheme names
  !> itself (`family`, the registry name, also returned by `name`), may declare parameters
  !> (`params`) and reads them from the `&integrator` group (`configure`).
  type, abstract, extends(empm_family_t) :: empm_integrator_t
    real(wp), allocatable :: bwork(:,:)  !! body-force scratch (ndim, np)
    real(wp) :: damping = 0.0_wp         !! local non-viscous damping coefficient α in [0, 1)
                                         !! ([[assemble_forces]]); 0: none
    real(wp), allocatable :: tforce(:,:) !! nodal traction forces of the last assembly
                                         !! (ndim, nnode); allocated with tractions only
    logical :: vol_smooth = .false.      !! replace each particle's volumetric strain rate by
                                         !! its nodal average ([[update_stress]])
    real(wp), allocatable :: vs_mass(:)  !! smoothing scratch: nodal mass (nnode)
    real(wp), allocatable :: vs_q(:)     !! smoothing scratch: Σ_p N_Ip m_p tr L_p (nnode)
    real(wp), allocatable :: vs_node(:,:) !! smoothing scratch: nodal average in every row
                                         !! (ndim, nnode)
    real(wp), allocatable :: vs_tr(:)    !! smoothing scratch: tr L_p (np)
    real(wp), allocatable :: vs_w(:)     !! smoothing scratch: m_p tr L_p (np)
    real(wp), allocatable :: vs_bar(:,:) !! smoothing scratch: interpolated average in every
                                         !! row (ndim, np)
    type(empm_p2g_work_t) :: p2g         !! per-thread P2G buffers (sized in `prepare`)
    type(empm_phase_timer_t) :: timer    !! wall time per phase of the step, Newton iterations
    logical :: basis_ready = .false.     !! model%basis and the nodal masses are at the
                                         !! particles' current positions (evaluated at the end
                                         !! of the last step, [[drift_end]]): the next step's
                                         !! [[map_velocity]] reuses them
    logical :: carry = .false.           !! the scheme carries the basis of x^{n+1} into the
                                         !! next step (set by the scheme's `start`)
    logical :: reeval = .false.          !! the particles were put back (restart, replay): the
                                         !! next evaluation repeats the one that made the
                                         !! carried basis, from the multipliers it started from
    real(wp), allocatable :: l0(:,:,:)   !! schemes with a trapezoidal drift: the gradient of
                                         !! the drift over the basis of x^n per particle
                                         !! (ndim, ndim, np; [[drift_begin]], [[drift_end]])
  contains
    procedure(step_iface), deferred :: step
    procedure :: name => integrator_name
    procedure :: configure => integrator_configure
    procedure :: prepare => integrator_prepare
    procedure :: start => integrator_start
    procedure :: assemble_forces
    procedure :: resync => integrator_resync
    procedure :: walls => integrator_walls
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
  end interface

contains

  !> Scheme identifier written to results, e.g. "usl": the registry name.
  function integrator_name(self) result(s)
    class(empm_integrator_t), intent(in) :: self !! integrator
    character(len=:), allocatable :: s           !! identifier
    s = self%family()
  end function integrator_name

  !> Read the scheme's parameters from the `&integrator` group; the default is for schemes
  !> without parameters. A scheme with parameters reads each with `group%get(param, value,
  !> err)`, which validates it against the declaration.
  subroutine integrator_configure(self, group, err)
    class(empm_integrator_t), intent(inout) :: self !! integrator
    type(empm_group_t), intent(inout) :: group      !! the `&integrator` group
    type(empm_error_t), intent(inout) :: err        !! set on invalid parameters
    associate (unused_ => self, unused_group_ => group, unused_err_ => err); end associate
  end subroutine integrator_configure

  !> Whether the scheme supports frictional walls (it passes [[assemble_forces]] the time over
  !> which the force changes the nodal velocities); the default is no.
  pure logical function integrator_walls(self)
    class(empm_integrator_t), intent(in) :: self !! integrator
    associate (unused_ => self); end associate
    integrator_walls = .false.
  end function integrator_walls

  !> Allocate work arrays for `model` and initialise the scheme's state (`start`). Call once,
  !> after the model's set-up, before stepping ([[empm_solve]] does).
  !> An allocation failure is reported in `err` when present (with the memory asked for),
  !> otherwise it stops the program.
  subroutine integrator_prepare(self, model, err)
    class(empm_integrator_t), intent(inout) :: self     !! integrator
    type(empm_model_t), intent(inout) :: model          !! simulation state
    type(empm_error_t), intent(inout), optional :: err  !! set on an allocation failure
    integer :: stat
    character(len=256) :: msg
    if (model%nodes%fric%n > 0 .and. .not. self%walls()) then
      call empm_raise(EMPM_ERR_INPUT, 'scheme '''//self%family()//''' does not support '// &
        'frictional walls ('//WALL_SCHEMES//' do)', err)
      return
    end if
    ! A case read to be shared among processes gets its nodal fields with its first window
    ! of the grid, and its basis with its share; one that was not shared gets them here.
    if (size(model%nodes%mass) /= model%nodes%nnode) call model%nodes%window(model%grid, model%grid)
    if (.not. allocated(model%basis%nn) .and. .not. allocated(model%basis%cell)) then
      call model%set_runs(err)
      if (present(err)) then
        if (err%code /= 0) return
      end if
    end if
    if (allocated(self%bwork)) deallocate(self%bwork)
    allocate(self%bwork(model%grid%ndim, model%pts%np), stat=stat, errmsg=msg)
    if (stat /= 0) then
      call empm_raise_error(empm_alloc_error('integrator work arrays', &
        8_int64 * model%grid%ndim * model%pts%np, msg), err)
      return
    end if
    self%bwork = 0.0_wp
    call prepare_tractions(model, stat, msg)
    if (stat == 0 .and. model%loads%ntraction() > 0) then
      if (allocated(self%tforce)) deallocate(self%tforce)
      allocate(self%tforce(model%grid%ndim, model%grid%nnode), stat=stat, errmsg=msg)
    end if
    if (stat /= 0) then
      call empm_raise_error(empm_alloc_error('traction work arrays', 0_int64, msg), err)
      return
    end if
    if (self%vol_smooth) then
      if (allocated(self%vs_mass)) deallocate(self%vs_mass, self%vs_q, self%vs_node, &
                                              self%vs_tr, self%vs_w, self%vs_bar)
      allocate(self%vs_mass(model%grid%nnode), self%vs_q(model%grid%nnode), &
               self%vs_node(model%grid%ndim, model%grid%nnode), self%vs_tr(model%pts%np), &
               self%vs_w(model%pts%np), self%vs_bar(model%grid%ndim, model%pts%np), &
               stat=stat, errmsg=msg)
      if (stat /= 0) then
        call empm_raise_error(empm_alloc_error('volumetric smoothing work arrays', &
          8_int64 * (model%grid%ndim + 2) * (model%grid%nnode + model%pts%np), msg), err)
        return
      end if
    end if
    ! Threads are fixed here: P2G sums depend on the chunking, so it must not change mid-run.
    call self%p2g%init(model%grid%ndim, model%grid%nnode, model%pts%np, empm_max_threads())
    call self%timer%reset()
    call self%start(model)
    if (model%track) call monitor_initial(self, model)
  end subroutine integrator_prepare

  !> Size each traction's scratch (support nodes of one face centre) for the model's shape
  !> family, and its shape-function state.
  subroutine prepare_tractions(model, stat, msg)
    type(empm_model_t), intent(inout) :: model
    integer, intent(out) :: stat
    character(len=*), intent(inout) :: msg
    integer :: k, maxn, nd, n
    stat = 0
    if (model%loads%ntraction() == 0) return
    nd = model%grid%ndim; maxn = model%shape%max_nodes(model%grid)
    do k = 1, size(model%loads%tractions)
      associate (tr => model%loads%tractions(k))
        n = size(tr%part)
        if (allocated(tr%node)) deallocate(tr%node, tr%N, tr%dN)
        if (allocated(tr%lam)) deallocate(tr%lam)
        allocate(tr%node(maxn), tr%N(maxn), tr%dN(nd, maxn), tr%lam(nd, n), stat=stat, &
                 errmsg=msg)
        if (stat /= 0) return
        tr%lam = 0.0_wp
      end associate
    end do
  end subroutine prepare_tractions

  !> With `model%track`, the residual and reactions of the initial state (recorded by the
  !> first history sample): shape functions, nodal masses and one force assembly. Nothing the
  !> step uses is changed (every step recomputes these).
  subroutine monitor_initial(self, model)
    class(empm_integrator_t), intent(inout) :: self
    type(empm_model_t), intent(inout) :: model
    type(empm_step_status_t) :: stat
    call eval_basis(model, stat, ws=self%p2g)
    if (stat%code /= 0) return
    call model%nodes%reset()
    call p2g_mass(model%basis, model%pts%m, model%nodes%mass)
    call model%halo%sum(model%comm, model%nodes%mass)
    call extend_masses(self, model)
    model%nodes%vel = 0.0_wp ! no damping in this assembly
    call self%assemble_forces(model, model%t)
  end subroutine monitor_initial

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
    call eval_basis(model, stat, ws=self%p2g)
    if (stat%code /= 0) return
    call model%nodes%reset()
    call p2g_mass(model%basis, model%pts%m, model%nodes%mass)
    call model%halo%sum(model%comm, model%nodes%mass)
    call extend_masses(self, model)
    call self%assemble_forces(model, model%t)
    call nodal_divide_by_mass(model%nodes, model%nodes%force, model%nodes%acc)
    call g2p_value(model%basis, model%nodes%acc, model%pts%a)
    self%basis_ready = self%carry
  end subroutine initial_acceleration

  !> Evaluate shape functions at the current particle positions (one batched call). With
  !> `timer`, Newton iterations of LME bases are counted in it.
  subroutine eval_basis(model, stat, timer, ws, again)
    type(empm_model_t), intent(inout) :: model               !! simulation state
    type(empm_step_status_t), intent(inout) :: stat          !! set on failure
    type(empm_phase_timer_t), intent(inout), optional :: timer !! iteration counters
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace: its
                                                             !! node ranges follow the new basis
    logical, intent(in), optional :: again                   !! repeat the last evaluation:
                                                             !! the shape state is first put
                                                             !! back to what it started from
    integer :: ibad, info, iters
    if (present(again)) then
      if (again) call model%pts%rewind_shape_state()
    end if
    ! The nodes the particles reach, and the window of the grid stored for them, come first:
    ! the basis is numbered on that window.
    if (model%comm%parallel()) then
      call model%share_region()
      if (present(ws)) call ws%fit(model%grid%nnode)
    end if
    if (present(timer)) then
      call model%shape%eval_batch_iters(model%grid, model%pts, model%basis, ibad, info, iters)
      timer%newton_iters = timer%newton_iters + iters
      timer%basis_evals = timer%basis_evals + model%pts%np
    else
      call model%shape%eval_batch(model%grid, model%pts, model%basis, ibad, info)
    end if
    if (info /= 0) then
      stat%code = STEP_SHAPE_FAILED; stat%detail = info; stat%particle = model%pts%id(ibad)
      stat%rank = model%comm%rank; stat%local = ibad
    else if (present(ws)) then
      call ws%set_ranges(model%basis)
    end if
    call agree_status(model, stat)
  end subroutine eval_basis

  !> Every process takes the failure the serial run would report (that of the particle with
  !> the smallest id), or none: the processes leave a step together, before its next
  !> collective operation.
  subroutine agree_status(model, stat)
    type(empm_model_t), intent(in) :: model          !! simulation state (communicator)
    type(empm_step_status_t), intent(inout) :: stat  !! this process's outcome in, the run's out
    integer :: first, lowest, v(5)
    if (.not. model%comm%parallel()) return
    lowest = model%comm%min_int(merge(stat%particle, huge(1), stat%code /= 0))
    first = model%comm%min_int(merge(model%comm%rank, model%comm%nranks, &
                                     stat%code /= 0 .and. stat%particle == lowest))
    if (first == model%comm%nranks) return
    v = [stat%code, stat%detail, stat%particle, stat%rank, stat%local]
    call model%comm%bcast_ints(v, first)
    stat%code = v(1); stat%detail = v(2); stat%particle = v(3); stat%rank = v(4)
    stat%local = v(5)
  end subroutine agree_status

  !> After the nodal masses were accumulated on a new basis: mirror ghosts' masses go to their
  !> images; with the extension of nearly-empty nodes on ([[empm_extension]]), find them (their
  !> filled volumes in one more P2G) and gather the masses, m̂ = Eᵀm. Without mirrors and
  !> degenerate nodes nothing changes. (A carried basis keeps its masses: [[map_velocity]].)
  subroutine extend_masses(self, model, again, mapped)
    class(empm_integrator_t), intent(inout) :: self   !! integrator (P2G workspace)
    type(empm_model_t), intent(inout) :: model        !! simulation state
    logical, intent(in), optional :: again            !! the basis repeats the last evaluation
                                                      !! (a carried basis made again): its
                                                      !! fill is that of the volumes it used
    logical, intent(in), optional :: mapped           !! the caller's P2G already summed the
                                                      !! fill volumes into `nodes%vol`
                                                      !! ([[fill_volumes_ready]])
    logical :: done
    done = .false.
    if (present(mapped)) done = mapped
    associate (nodes => model%nodes)
      if (nodes%nmirror > 0) call nodes%mirror_gather_mass()
      if (nodes%ext%theta <= 0.0_wp) return
      if (.not. done) then
        call fill_volumes_ready(model, again)
        call p2g_mass(model%basis, model%pts%vol_fill, nodes%vol, self%p2g)
      end if
      call model%halo%sum(model%comm, nodes%vol)
      call nodes%find_degenerate(model%grid)
      if (nodes%ext%n > 0) call nodes%ext%gather_mass(nodes%mass)
    end associate
  end subroutine extend_masses

  !> Before the P2G of the fill volumes (with the nearly-empty-node rule on): the particles'
  !> fill volumes `pts%vol_fill` and `nodes%vol` zeroed. The fill of a carried basis comes from
  !> the volumes before the step's stress update; a restart or a re-cut that evaluates it again
  !> (`again`) must see the same ones, so they are kept then.
  subroutine fill_volumes_ready(model, again)
    type(empm_model_t), intent(inout) :: model        !! simulation state
    logical, intent(in), optional :: again            !! the basis repeats the last evaluation
    logical :: repeat
    integer :: np
    repeat = .false.
    if (present(again)) repeat = again
    np = model%pts%np
    if (.not. repeat) model%pts%vol_fill(1:np) = model%pts%vol(1:np)
    model%nodes%vol = 0.0_wp
  end subroutine fill_volumes_ready

  !> The particle state was replaced from outside the step (a restart or a guard's replay put
  !> back a saved state): a basis carried from the last step is stale. A scheme that carries
  !> its basis re-evaluates it at the next step from the shape state saved with the particles
  !> (bitwise the evaluation that made it); the others evaluate as usual.
  subroutine integrator_resync(self, model)
    class(empm_integrator_t), intent(inout) :: self !! integrator
    type(empm_model_t), intent(inout) :: model      !! simulation state (unused)
    associate (unused_model => model); end associate
    self%reeval = self%carry
    self%basis_ready = .false.
  end subroutine integrator_resync

  !> The opening of every scheme's step, timed as its shape, P2G and grid phases: shape
  !> functions at the particles; mass and mass-weighted velocity v_p + c w_p on the grid in one
  !> pass (without `c` and `w`: the momentum); nodal velocity = that / mass with the Dirichlet
  !> values imposed (nodes%vel, and nodes%mom to match). With a carried basis (`basis_ready`)
  !> its nodal masses are kept and only the momentum is mapped. On a shape failure `stat` says
  !> which particle and nothing else is done.
  subroutine map_velocity(self, model, stat, c, w)
    class(empm_integrator_t), intent(inout) :: self   !! integrator (timer, P2G workspace)
    type(empm_model_t), intent(inout) :: model        !! simulation state
    type(empm_step_status_t), intent(inout) :: stat   !! set on failure
    real(wp), intent(in), optional :: c               !! scale of `w`
    real(wp), intent(in), contiguous, optional :: w(:,:) !! second particle vectors (ndim, np)
    logical :: again, fill
    real(wp) :: cw
    associate (nodes => model%nodes, pts => model%pts, basis => model%basis, tm => self%timer)
      call tm%mark()
      if (self%basis_ready) then
        ! The carried basis came with its nodal masses (extended and gathered): only the
        ! momentum is new.
        self%basis_ready = .false.
        nodes%mom = 0.0_wp
        if (present(c) .and. present(w)) then
          call p2g_weighted(basis, pts%m, pts%v, c, w, nodes%mom, self%p2g)
        else
          call p2g_weighted(basis, pts%m, pts%v, 0.0_wp, pts%v, nodes%mom, self%p2g)
        end if
        call model%halo%sum(model%comm, nodes%mom)
      else
        again = self%reeval
        call eval_basis(model, stat, tm, self%p2g, again)
        self%reeval = .false.
        call tm%lap(PHASE_SHAPE)
        if (stat%code /= 0) return
        call nodes%reset()
        ! With the nearly-empty-node rule the fill volumes are summed in the same pass.
        fill = nodes%ext%theta > 0.0_wp
        if (fill) call fill_volumes_ready(model, again)
        if (present(c) .and. present(w)) then
          cw = c
        else
          cw = 0.0_wp
        end if
        if (fill .and. present(w)) then
          call p2g_mass_momentum(basis, pts%m, pts%v, cw, w, nodes%mass, nodes%mom, self%p2g, &
                                 pts%vol_fill, nodes%vol)
        else if (fill) then
          call p2g_mass_momentum(basis, pts%m, pts%v, cw, pts%v, nodes%mass, nodes%mom, &
                                 self%p2g, pts%vol_fill, nodes%vol)
        else if (present(w)) then
          call p2g_mass_momentum(basis, pts%m, pts%v, cw, w, nodes%mass, nodes%mom, self%p2g)
        else
          call p2g_mass_momentum(basis, pts%m, pts%v, cw, pts%v, nodes%mass, nodes%mom, &
                                 self%p2g)
        end if
        call model%halo%sum(model%comm, nodes%mass)
        call model%halo%sum(model%comm, nodes%mom)
        call extend_masses(self, model, again, mapped=fill)
      end if
      call tm%lap(PHASE_P2G)
      call nodal_divide_by_mass(nodes, nodes%mom, nodes%vel)
      call nodes%constrain_velocity(nodes%vel, nodes%mom)
      call tm%lap(PHASE_GRID)
    end associate
  end subroutine map_velocity

  !> Total nodal force at time `t` (paper eqs. 16–17): reset, internal force from the current
  !> stresses, gravity, the body-force callback and the surface tractions; then, when used, the
  !> reactions of the named node sets (from the force before the fixed dofs are zeroed), the
  !> fixed dofs zeroed, the residual ‖f_free‖₂/‖f_ext‖₂ (`model%track`; f_ext = m_I g + the
  !> nodal traction forces, the body-force callback left out) and the local damping
  !> f −= α |f| sgn(v) with the nodal velocities `nodes%vel` of the step. Without tractions,
  !> reaction sets, tracking and damping the work is that of eqs. 16–17 alone. The friction of
  !> frictional walls ([[empm_friction]]) is added before the fixed dofs are zeroed, from the
  !> nodal velocities `nodes%vel` and `kick`, the time over which the caller adds f/m to them
  !> (walls need it: [[integrator_prepare]] refuses them for a scheme that does not pass it);
  !> the damping leaves the walls' tangential forces as the friction set them.
  subroutine assemble_forces(self, model, t, kick)
    class(empm_integrator_t), intent(inout) :: self !! integrator (body-force scratch)
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in) :: t                       !! time at which loads are evaluated [s]
    real(wp), intent(in), optional :: kick          !! time over which f/m is added to v_I [s]
    real(wp) :: g(3), fext2, funb
    integer :: np, d, i
    logical :: use_b
    np = model%pts%np; d = model%grid%ndim
    model%nodes%force = 0.0_wp
    call p2g_internal_force(model%basis, model%pts%vol, model%pts%stress, model%nodes%force, &
                            self%p2g)
    g = model%loads%gravity_at(t)
    use_b = allocated(model%loads%body_force)
    if (use_b) call model%loads%body_force%eval(t, model%pts%x0(:, 1:np), &
                                                model%pts%x(:, 1:np), self%bwork(:, 1:np))
    call p2g_body_force(model%basis, model%pts%m, g(1:d), self%bwork, use_b, model%nodes%force, &
                        self%p2g)
    call model%halo%sum(model%comm, model%nodes%force)
    if (model%loads%ntraction() > 0) then
      ! The tractions' nodal forces apart (for the residual's ‖f_ext‖), then added.
      if (size(self%tforce, 2) /= model%nodes%nnode) then ! a new window (parallel runs)
        deallocate(self%tforce); allocate(self%tforce(d, model%nodes%nnode))
      end if
      self%tforce = 0.0_wp
      call p2g_tractions(model, t, self%tforce)
      call model%halo%sum(model%comm, self%tforce)
      model%nodes%force = model%nodes%force + self%tforce
    end if
    if (model%halo%active) then
      ! Each node's share of a reaction counted once, by the process that owns it, then summed.
      if (model%nodes%nset > 0) &
        call model%nodes%compute_reactions(model%nodes%force, model%halo%owned)
      if (model%nodes%fric%n > 0 .and. present(kick)) &
        call model%nodes%apply_friction(model%nodes%vel, kick, model%nodes%force, &
                                        model%halo%owned)
      if (model%nodes%nset > 0) call model%comm%sum(model%nodes%reaction)
    else
      if (model%nodes%nset > 0) call model%nodes%compute_reactions(model%nodes%force)
      if (model%nodes%fric%n > 0 .and. present(kick)) &
        call model%nodes%apply_friction(model%nodes%vel, kick, model%nodes%force)
    end if
    call model%nodes%constrain_force(model%nodes%force)
    if (model%track) then
      if (model%halo%active) then
        ! Each node counted once, by the process that owns it.
        associate (own => model%halo%owned)
          if (model%loads%ntraction() > 0) then
            fext2 = ext_norm2(model%nodes%mass, g(1:d), self%tforce, own)
          else
            fext2 = sum(model%nodes%mass**2, mask=own) * sum(g(1:d)**2)
          end if
          funb = 0.0_wp
          do i = 1, model%nodes%nnode
            if (own(i)) funb = funb + sum(model%nodes%force(:, i)**2)
          end do
        end associate
        fext2 = model%comm%sum_real(fext2)
        funb = sqrt(model%comm%sum_real(funb))
      else
        if (model%loads%ntraction() > 0) then
          fext2 = ext_norm2(model%nodes%mass, g(1:d), self%tforce)
        else
          fext2 = sum(model%nodes%mass**2) * sum(g(1:d)**2)
        end if
        funb = sqrt(sum(model%nodes%force**2))
      end if
      if (fext2 > 0.0_wp) then
        model%residual = funb / sqrt(fext2)
      else
        model%residual = -1.0_wp
      end if
    end if
    if (self%damping > 0.0_wp) then
      call model%nodes%local_damping(self%damping, model%nodes%vel, model%nodes%force)
      if (model%nodes%fric%n > 0) call model%nodes%restore_friction(model%nodes%force)
    end if
  end subroutine assemble_forces

  !> Σ_I |m_I g + t_I|², the squared norm of the nodal external force (gravity and tractions).
  pure real(wp) function ext_norm2(mass, g, tf, mask) result(s)
    real(wp), intent(in) :: mass(:)     !! nodal masses
    real(wp), intent(in) :: g(:)        !! gravity (ndim)
    real(wp), intent(in) :: tf(:,:)     !! nodal traction forces (ndim, nnode)
    logical, intent(in), optional :: mask(:) !! the nodes to count (nnode); all when absent
    integer :: i
    s = 0.0_wp
    do i = 1, size(mass)
      if (present(mask)) then
        if (.not. mask(i)) cycle
      end if
      s = s + sum((mass(i) * g + tf(:, i))**2)
    end do
  end function ext_norm2

  !> Add the nodal forces of every traction at time `t` to `f`: per loaded particle the force
  !> s(t) t A_p, spread with the shape functions on its face, x_p + offset_p side e_axis
  !> (where the load acts); should those fail (a face centre outside the grid or beyond the
  !> family's support), with the particle's own shape functions. Serial: the loaded particles
  !> are few (a boundary layer).
  subroutine p2g_tractions(model, t, f)
    type(empm_model_t), intent(inout) :: model        !! simulation state
    real(wp), intent(in) :: t                         !! time [s]
    real(wp), intent(inout), contiguous :: f(:,:)     !! nodal forces (ndim, nnode)
    real(wp) :: s, xf(3), fp(3)
    integer :: k, j, p, nd, nn, info, i
    nd = model%grid%ndim
    do k = 1, size(model%loads%tractions)
      associate (tr => model%loads%tractions(k), b => model%basis)
        s = tr%factor(t)
        if (s == 0.0_wp) cycle
        do j = 1, size(tr%part)
          p = tr%part(j)
          if (p == 0) cycle ! another process holds it
          fp(1:nd) = (s * tr%area(j)) * tr%traction(1:nd)
          xf(1:nd) = model%pts%x(:, p)
          xf(tr%axis) = xf(tr%axis) + tr%side * tr%offset(j)
          call model%shape%eval_point(model%grid, xf(1:nd), model%pts%lp(:, p), tr%lam(:, j), &
                                      nn, tr%node, tr%N, tr%dN, info)
          if (info == 0) then
            do i = 1, nn
              f(:, tr%node(i)) = f(:, tr%node(i)) + tr%N(i) * fp(1:nd)
            end do
          else if (b%layout /= BASIS_LISTS) then
            ! A compact layout: the particle's nodes and values as the transfers have them.
            call b%get(p, nn, tr%node, tr%N, tr%dN)
            do i = 1, nn
              f(:, tr%node(i)) = f(:, tr%node(i)) + tr%N(i) * fp(1:nd)
            end do
          else
            do i = 1, b%nn(p)
              f(:, b%node(i, p)) = f(:, b%node(i, p)) + b%N(i, p) * fp(1:nd)
            end do
          end if
        end do
      end associate
    end do
  end subroutine p2g_tractions

  !> Strain and stress update of every particle from the nodal velocities `vel`: per block of
  !> STRESS_BLOCK particles, L_p = Σ v_I ⊗ ∇N_Ip into a small buffer, then one material call on
  !> the block, then V_p = m_p/ρ_p. L stays in the cache instead of making a round trip through
  !> memory. Blocks never straddle a run of particles sharing a material; with OpenMP each
  !> thread takes a contiguous slice of every run (particles are independent, so the result does
  !> not depend on the thread count). The material gets the block's whole state columns
  !> `pts%state(:, q0:q1)` (contiguous, so passed without a copy; zero rows when no material
  !> has state variables) and uses its own first rows. On failure `stat` names the first
  !> failing particle.
  !>
  !> With `integ` given and its `vol_smooth` set, the volumetric strain rate tr L_p of every
  !> particle is replaced by its mass-weighted nodal average ([[smooth_volumetric]]) before the
  !> material call: L_p += (ē_p − tr L_p)/ndim · I on the in-plane (2D) or full (3D) diagonal,
  !> the deviatoric part of L_p unchanged. Without it the update is unchanged, bit for bit.
  !>
  !> With `cx`, the particles also move by x_p += cx Σ N_Ip v_I in the gradient's pass (USL's
  !> position update; the same bits as [[g2p_add_scaled]] before the call, one read of the
  !> basis and the nodes fewer). A failing step leaves some particles moved and others not; the
  !> time loop restores its last good state then.
  subroutine update_stress(model, vel, dt, stat, integ, lprev, cx)
    type(empm_model_t), intent(inout) :: model      !! simulation state
    real(wp), intent(in), contiguous :: vel(:,:)    !! nodal velocities defining L (ndim, nnode)
    real(wp), intent(in) :: dt                      !! time step [s]
    type(empm_step_status_t), intent(inout) :: stat !! set on failure
    class(empm_integrator_t), intent(inout), optional :: integ !! the scheme (smoothing option
                                                    !! and its scratch)
    real(wp), intent(in), contiguous, optional :: lprev(:,:,:) !! with it (a trapezoidal drift,
                                                    !! [[drift_end]]), the particles' L at the
                                                    !! start of the step (ndim, ndim, np): the
                                                    !! material gets the trapezoidal gradient
                                                    !! of [[trapezoid_gradient]], and the drift's
                                                    !! correction `pts%dx` is formed
    real(wp), intent(in), optional :: cx            !! with it, x_p += cx Σ N_Ip v_I [s]
    real(wp) :: none1(0), none2(0, 0), none3(0, 0, 0), c
    logical :: sm, tz
    sm = .false.
    if (present(integ)) sm = integ%vol_smooth
    tz = present(lprev)
    c = 0.0_wp
    if (present(cx)) c = cx
    if (sm .and. tz) then
      call smooth_volumetric(integ, model, vel, lprev, dt)
      call stress_blocks(model, vel, dt, stat, .true., integ%vs_tr, integ%vs_bar, .true., lprev, c)
    else if (sm) then
      call smooth_volumetric(integ, model, vel, none3, dt)
      call stress_blocks(model, vel, dt, stat, .true., integ%vs_tr, integ%vs_bar, .false., none3, c)
    else if (tz) then
      call stress_blocks(model, vel, dt, stat, .false., none1, none2, .true., lprev, c)
    else
      call stress_blocks(model, vel, dt, stat, .false., none1, none2, .false., none3, c)
    end if
  end subroutine update_stress

  !> For a scheme with a trapezoidal drift (its `start`): the basis of x^{n+1} is carried
  !> into the next step, and the drift's gradient has its array.
  subroutine drift_prepare(self, model)
    class(empm_integrator_t), intent(inout) :: self !! integrator
    type(empm_model_t), intent(in) :: model         !! simulation state
    self%carry = .true.
    if (allocated(self%l0)) deallocate(self%l0)
    allocate(self%l0(model%grid%ndim, model%grid%ndim, model%pts%np))
  end subroutine drift_prepare

  !> The first half of a trapezoidal drift over the bases of x^n and x^{n+1}
  !> (docs/integrators.md, "Why the drift is trapezoidal"): keep L⁰ = Σ v_I ⊗ ∇N_Ip, add the
  !> correction left by the last step to x, keep the resulting start positions in `pts%dx`
  !> ([[drift_end]] forms the next correction from them) and move the particles by
  !> Δt G2P(v)_p. `v` is the grid velocity field whose interpolation moves the particles. With
  !> `cx` and `cv`, the particle updates x += cx a and (after the move) v += cv a of the scheme
  !> are made in the same pass (skipped when 0; [[axpy_flat]] on the block). One pass,
  !> block by block: each block's particle data is read once, its basis and nodes once.
  subroutine drift_begin(self, model, v, dt, cx, cv)
    class(empm_integrator_t), intent(inout) :: self  !! integrator (l0)
    type(empm_model_t), intent(inout) :: model       !! simulation state
    real(wp), intent(in), contiguous :: v(:,:)       !! v_I (ndim, nnode)
    real(wp), intent(in) :: dt                       !! time step [s]
    real(wp), intent(in), optional :: cx             !! x += cx a before the drift (default 0)
    real(wp), intent(in), optional :: cv             !! v += cv a (default 0)
    real(wp) :: Lb(3, 3, STRESS_BLOCK), ax, av
    integer :: np, nc, c, a, b, q0, q1, d
    np = model%pts%np; d = model%grid%ndim
    ax = 0.0_wp; av = 0.0_wp
    if (present(cx)) ax = cx
    if (present(cv)) av = cv
    nc = empm_chunks(np)
    !$omp parallel do default(none) schedule(static, 1) &
    !$omp& shared(model, self, v, dt, np, nc, d, ax, av) private(a, b, q0, q1, Lb) if(nc > 1)
    do c = 0, nc - 1
      call empm_chunk_bounds(np, nc, c, a, b)
      do q0 = a, b, STRESS_BLOCK
        q1 = min(b, q0 + STRESS_BLOCK - 1)
        if (ax /= 0.0_wp) call axpy_flat(d * (q1 - q0 + 1), ax, model%pts%a(:, q0:q1), &
                                          model%pts%x(:, q0:q1))
        call shift_keep(q0, q1, model%pts%x, model%pts%dx)
        call gradient_g2p_block(model%basis, v, q0, q1, Lb, dt, model%pts%x)
        call keep_gradients(d, q0, q1, Lb, self%l0)
        if (av /= 0.0_wp) call axpy_flat(d * (q1 - q0 + 1), av, model%pts%a(:, q0:q1), &
                                          model%pts%v(:, q0:q1))
      end do
    end do
    !$omp end parallel do
  end subroutine drift_begin

  !> x += dx, then dx = x, for particles q0..q1 (the start positions of a trapezoidal drift).
  pure subroutine shift_keep(q0, q1, x, dx)
    integer, intent(in) :: q0                        !! first particle
    integer, intent(in) :: q1                        !! last particle
    real(wp), intent(inout), contiguous :: x(:,:)    !! positions (ndim, >= q1)
    real(wp), intent(inout), contiguous :: dx(:,:)   !! corrections in, start positions out
    integer :: p, k
    ! Element loops: an array assignment of ndim entries compiles to a library copy.
    do p = q0, q1
      do k = 1, size(x, 1)
        x(k, p) = x(k, p) + dx(k, p)
        dx(k, p) = x(k, p)
      end do
    end do
  end subroutine shift_keep

  !> dx = ½(dx − x) for particles q0..q1: with dx the start positions, −½ the displacement.
  pure subroutine half_back(q0, q1, x, dx)
    integer, intent(in) :: q0                        !! first particle
    integer, intent(in) :: q1                        !! last particle
    real(wp), intent(in), contiguous :: x(:,:)       !! positions (ndim, >= q1)
    real(wp), intent(inout), contiguous :: dx(:,:)   !! start positions in, −½ displacement out
    integer :: p, k
    do p = q0, q1
      do k = 1, size(x, 1)
        dx(k, p) = 0.5_wp * (dx(k, p) - x(k, p))
      end do
    end do
  end subroutine half_back

  !> l0(:, :, q0:q1) = the ndim × ndim part of a block of gradients.
  pure subroutine keep_gradients(d, q0, q1, Lb, l0)
    integer, intent(in) :: d                          !! dimension
    integer, intent(in) :: q0                         !! first particle of the block
    integer, intent(in) :: q1                         !! last particle
    real(wp), intent(in) :: Lb(:,:,:)                 !! block gradients (3, 3, >= q1-q0+1)
    real(wp), intent(inout), contiguous :: l0(:,:,:)  !! kept gradients (d, d, >= q1)
    integer :: p
    select case (d)
    case (1)
      l0(1, 1, q0:q1) = Lb(1, 1, 1:q1 - q0 + 1)
    case (2)
      do p = q0, q1
        l0(1, 1, p) = Lb(1, 1, p - q0 + 1); l0(2, 1, p) = Lb(2, 1, p - q0 + 1)
        l0(1, 2, p) = Lb(1, 2, p - q0 + 1); l0(2, 2, p) = Lb(2, 2, p - q0 + 1)
      end do
    case default
      l0(:, :, q0:q1) = Lb(:, :, 1:q1 - q0 + 1)
    end select
  end subroutine keep_gradients

  !> The second half of the trapezoidal drift, after the particles moved: the basis at x^{n+1}
  !> (the step's one evaluation, carried into the next step), the particle velocities `pts%v`
  !> mapped on it (u_I in `nodes%vel`), the stress with the trapezoidal gradient of L⁰ and
  !> L¹ = Σ u_I ⊗ ∇N_Ip(x^{n+1}) ([[trapezoid_gradient]]), and the correction
  !> dx_p = ½Δt (G2P(u)_p − G2P(v)_p) for the next drift. `pts%v` must be the particle values
  !> that `v` of [[drift_begin]] was mapped from. On failure `stat` says why.
  subroutine drift_end(self, model, dt, stat)
    class(empm_integrator_t), intent(inout) :: self  !! integrator (l0, timer)
    type(empm_model_t), intent(inout) :: model       !! simulation state
    real(wp), intent(in) :: dt                       !! time step [s]
    type(empm_step_status_t), intent(inout) :: stat  !! set on failure
    self%basis_ready = .false.
    call map_velocity(self, model, stat)
    if (stat%code /= 0) return
    self%basis_ready = .true.
    ! The stress blocks also form dx = ½Δt (G2P(u)_p − G2P(v)_p), the second term from the
    ! displacement, ½(x_start − x).
    call update_stress(model, model%nodes%vel, dt, stat, self, self%l0)
    call self%timer%lap(PHASE_STRESS)
  end subroutine drift_end

  !> L := ½(L⁰ + L) + ½Δt L L⁰ for a block of particles: with L⁰ the gradient of the drift's
  !> velocity field on the basis of x^n and L that of the same particle velocities on the basis
  !> of x^{n+1}, I + Δt L is ½[I + (I + Δt L)(I + Δt L⁰)], the deformation gradient of the
  !> trapezoidal (Heun) drift (docs/integrators.md, "Temporal order at large motion").
  pure subroutine trapezoid_gradient(dt, l0, L)
    real(wp), intent(in) :: dt                      !! time step [s]
    real(wp), intent(in), contiguous :: l0(:,:,:)   !! gradients at the start of the step
                                                    !! (d, d, n)
    real(wp), intent(inout), contiguous :: L(:,:,:) !! gradients at the end (3, 3, >= n; the
                                                    !! d × d part is used); the combination
    real(wp) :: a11, a21, a12, a22, b11, b21, b12, b22, g(3, 3), h
    integer :: p, i, j
    h = 0.5_wp * dt
    ! One branch per dimension: constant bounds, no temporaries.
    select case (size(l0, 1))
    case (1)
      do p = 1, size(l0, 3)
        L(1, 1, p) = 0.5_wp * (l0(1, 1, p) + L(1, 1, p)) + h * L(1, 1, p) * l0(1, 1, p)
      end do
    case (2)
      do p = 1, size(l0, 3)
        a11 = l0(1, 1, p); a21 = l0(2, 1, p); a12 = l0(1, 2, p); a22 = l0(2, 2, p)
        b11 = L(1, 1, p); b21 = L(2, 1, p); b12 = L(1, 2, p); b22 = L(2, 2, p)
        L(1, 1, p) = 0.5_wp * (a11 + b11) + h * (b11 * a11 + b12 * a21)
        L(2, 1, p) = 0.5_wp * (a21 + b21) + h * (b21 * a11 + b22 * a21)
        L(1, 2, p) = 0.5_wp * (a12 + b12) + h * (b11 * a12 + b12 * a22)
        L(2, 2, p) = 0.5_wp * (a22 + b22) + h * (b21 * a12 + b22 * a22)
      end do
    case (3)
      ! Written out: the inline matmul with its temporaries took 250 instructions a particle.
      ! The products are summed in matmul's order (k = 1, 2, 3).
      do p = 1, size(l0, 3)
        do j = 1, 3
          do i = 1, 3
            g(i, j) = 0.5_wp * (l0(i, j, p) + L(i, j, p)) &
                      + h * (L(i, 1, p) * l0(1, j, p) + L(i, 2, p) * l0(2, j, p) &
                             + L(i, 3, p) * l0(3, j, p))
          end do
        end do
        L(:, :, p) = g
      end do
    end select
  end subroutine trapezoid_gradient

  !> L := L (I + ½Δt L)⁻¹ for particle `p`: the midpoint gradient G/Δt of the trapezoidal
  !> drift's increment ΔF = I + ΔtL, G = (ΔF − I)(½(I + ΔF))⁻¹, that a rate-form model takes
  !> (`ctx%midpoint`, [[empm_plasticity]]): Δt sym G is the step's strain to second order and
  !> is zero under a rigid rotation, whose Cayley transform of Δt skw G is that rotation.
  !> `ok` is false, and L zero, when I + ½ΔtL is singular or reverses orientation (ΔF inverts
  !> the particle).
  pure subroutine midpoint_gradient(dt, d, L, ok)
    real(wp), intent(in) :: dt             !! time step [s]
    integer, intent(in) :: d               !! dimension (the d × d part of L is used)
    real(wp), intent(inout) :: L(3, 3)     !! trapezoidal gradient in, midpoint gradient out
    logical, intent(out) :: ok             !! the increment is invertible
    real(wp) :: h, M(3, 3), C(3, 3), det
    integer :: i, j
    h = 0.5_wp * dt
    select case (d)
    case (1)
      det = 1.0_wp + h * L(1, 1)
      ok = det > 0.0_wp
      if (ok) then
        L(1, 1) = L(1, 1) / det
      else
        L(1, 1) = 0.0_wp
      end if
    case (2)
      M(1, 1) = 1.0_wp + h * L(1, 1); M(1, 2) = h * L(1, 2)
      M(2, 1) = h * L(2, 1); M(2, 2) = 1.0_wp + h * L(2, 2)
      det = M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1)
      ok = det > 0.0_wp
      if (.not. ok) then
        L(1:2, 1:2) = 0.0_wp; return
      end if
      ! L M⁻¹ with M⁻¹ = adj(M)/det.
      C(1, 1) = L(1, 1) * M(2, 2) - L(1, 2) * M(2, 1)
      C(1, 2) = L(1, 2) * M(1, 1) - L(1, 1) * M(1, 2)
      C(2, 1) = L(2, 1) * M(2, 2) - L(2, 2) * M(2, 1)
      C(2, 2) = L(2, 2) * M(1, 1) - L(2, 1) * M(1, 2)
      L(1:2, 1:2) = C(1:2, 1:2) / det
    case default
      do j = 1, 3
        do i = 1, 3
          M(i, j) = h * L(i, j)
        end do
        M(j, j) = M(j, j) + 1.0_wp
      end do
      C = adjugate3(M)
      det = M(1, 1) * C(1, 1) + M(1, 2) * C(2, 1) + M(1, 3) * C(3, 1)
      ok = det > 0.0_wp
      if (.not. ok) then
        L = 0.0_wp; return
      end if
      do j = 1, 3
        do i = 1, 3
          M(i, j) = (L(i, 1) * C(1, j) + L(i, 2) * C(2, j) + L(i, 3) * C(3, j)) / det
        end do
      end do
      L = M
    end select
  end subroutine midpoint_gradient

  !> Nodal averaging of the volumetric strain rate (a B-bar/F-bar-like projection for MPM):
  !> ē_I = Σ_p N_Ip m_p tr L_p / Σ_p N_Ip m_p on every node with mass, then
  !> ē_p = Σ_I N_Ip ē_I. One volumetric constraint per node instead of one per particle, which
  !> removes the volumetric locking of isochoric (plastic, φ = ψ = 0) flow with several particles
  !> per cell; a uniform tr L is reproduced (partition of unity), up to round-off. Results:
  !> `integ%vs_tr` (tr L_p) and `integ%vs_bar` (ē_p in every row).
  subroutine smooth_volumetric(integ, model, vel, lprev, dt)
    class(empm_integrator_t), intent(inout) :: integ !! the scheme (scratch, P2G workspace)
    type(empm_model_t), intent(inout) :: model       !! simulation state
    real(wp), intent(in), contiguous :: vel(:,:)     !! nodal velocities (ndim, nnode)
    real(wp), intent(in), contiguous :: lprev(:,:,:) !! empty, or the gradients at the start of
                                                     !! the step ([[trapezoid_gradient]])
    real(wp), intent(in) :: dt                       !! time step [s]
    real(wp) :: Lb(3, 3, STRESS_BLOCK)
    integer :: np, d, nc, c, a, b, q0, q1, p, k, I
    logical :: tz, rf(size(model%mats)), ok
    np = model%pts%np; d = model%grid%ndim
    nc = empm_chunks(np)
    tz = size(lprev) > 0
    ! The trace the stress update will see: of the midpoint gradient for a rate-form model.
    do k = 1, size(rf)
      rf(k) = tz .and. model%mats(k)%model%rate_form()
    end do
    !$omp parallel do default(none) schedule(static, 1) &
    !$omp& shared(model, vel, integ, np, nc, d, lprev, dt, tz, rf) &
    !$omp& private(a, b, q0, q1, p, k, Lb, ok) if(nc > 1)
    do c = 0, nc - 1
      call empm_chunk_bounds(np, nc, c, a, b)
      Lb = 0.0_wp
      do q0 = a, b, STRESS_BLOCK
        q1 = min(b, q0 + STRESS_BLOCK - 1)
        call velocity_gradient(model%basis, vel, q0, q1, Lb)
        if (tz) call trapezoid_gradient(dt, lprev(:, :, q0:q1), Lb)
        do p = q0, q1
          if (rf(model%pts%mat(p))) call midpoint_gradient(dt, d, Lb(:, :, p - q0 + 1), ok)
        end do
        do p = q0, q1
          integ%vs_tr(p) = 0.0_wp
          do k = 1, d
            integ%vs_tr(p) = integ%vs_tr(p) + Lb(k, k, p - q0 + 1)
          end do
          integ%vs_w(p) = model%pts%m(p) * integ%vs_tr(p)
        end do
      end do
    end do
    !$omp end parallel do
    if (size(integ%vs_mass) /= model%nodes%nnode) then ! a new window (parallel runs)
      deallocate(integ%vs_mass, integ%vs_q, integ%vs_node)
      allocate(integ%vs_mass(model%nodes%nnode), integ%vs_q(model%nodes%nnode), &
               integ%vs_node(d, model%nodes%nnode))
    end if
    integ%vs_mass = 0.0_wp; integ%vs_q = 0.0_wp
    call p2g_mass(model%basis, model%pts%m(1:np), integ%vs_mass, integ%p2g)
    call p2g_mass(model%basis, integ%vs_w(1:np), integ%vs_q, integ%p2g)
    call model%halo%sum(model%comm, integ%vs_mass)
    call model%halo%sum(model%comm, integ%vs_q)
    ! Mirror planes: the volumetric rate is even about the plane, so a ghost's share adds to its
    ! image and the ghost takes the image's value.
    call model%nodes%mirror_gather_even(integ%vs_mass)
    call model%nodes%mirror_gather_even(integ%vs_q)
    do I = 1, size(integ%vs_mass)
      if (integ%vs_mass(I) > model%nodes%mass_tol) then
        integ%vs_node(:, I) = integ%vs_q(I) / integ%vs_mass(I)
      else
        integ%vs_node(:, I) = 0.0_wp
      end if
    end do
    call model%nodes%mirror_scatter(integ%vs_node, even=.true.)
    call g2p_value(model%basis, integ%vs_node, integ%vs_bar)
  end subroutine smooth_volumetric

  !> The block loop of [[update_stress]]; with `tz`, L_p is first combined with `lprev`
  !> ([[trapezoid_gradient]]) and the block's drift correction `pts%dx` formed
  !> ([[drift_end]]); with `sm`, its volumetric part is then replaced by
  !> ē_p = `bar(1, p)` (`tr(p)` = tr L_p) before the material call; with `cx` ≠ 0 the block's
  !> particles move by cx Σ N v_I first.
  subroutine stress_blocks(model, vel, dt, stat, sm, tr, bar, tz, lprev, cx)
    type(empm_model_t), intent(inout) :: model
    real(wp), intent(in), contiguous :: vel(:,:)
    real(wp), intent(in) :: dt
    type(empm_step_status_t), intent(inout) :: stat
    logical, intent(in) :: sm, tz
    real(wp), intent(in) :: tr(:), bar(:,:)
    real(wp), intent(in), contiguous :: lprev(:,:,:)
    real(wp), intent(in) :: cx
    real(wp) :: Lb(3, 3, STRESS_BLOCK), dv, cm
    integer :: r, i0, i1, info, im, n, nc, c, a, b, q0, q1, bad, p, k, g0
    logical :: fine, we, ok, mp
    type(empm_material_ctx_t) :: ctx
    ctx%t = model%t; ctx%step = model%step + 1; ctx%ndim = model%grid%ndim
    ctx%h = minval(model%grid%h(1:model%grid%ndim))
    ! Each group of updated particles is screened for the run-time guards, gives its largest
    ! wave speed and, when the time loop asks for it, its stored energy densities, in cache.
    fine = .true.; cm = 0.0_wp
    we = model%want_energy
    if (we) we = allocated(model%diag_psi)
    if (we) we = size(model%diag_psi) >= model%pts%np
    model%diag_step = -1
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      im = model%pts%mat(i0)
      n = i1 - i0 + 1
      nc = empm_chunks(n)
      ! The trapezoidal drift gives a rate-form model its midpoint gradient.
      mp = tz .and. model%mats(im)%model%rate_form()
      ctx%midpoint = mp
      ! The first failing particle of the run, whichever block it is in.
      bad = huge(1)
      !$omp parallel do default(none) schedule(static, 1) &
      !$omp& shared(model, vel, dt, i0, im, n, nc, sm, tr, bar, tz, lprev, we, cx, mp) &
      !$omp& private(a, b, q0, q1, p, k, dv, Lb, info, ok, g0) firstprivate(ctx) &
      !$omp& reduction(min: bad) reduction(.and.: fine) reduction(max: cm) if(nc > 1)
      do c = 0, nc - 1
        call empm_chunk_bounds(n, nc, c, a, b)
        a = a + i0 - 1; b = b + i0 - 1
        Lb = 0.0_wp ! the blocks write only the ndim×ndim part
        g0 = a
        do q0 = a, b, STRESS_BLOCK
          q1 = min(b, q0 + STRESS_BLOCK - 1)
          if (tz) then
            ! The trapezoidal drift: its gradient, and its position correction from the same
            ! pass over the block's basis, dx = ½(dx − x) + ½Δt G2P(u) ([[drift_end]]); a move
            ! by `cx` first, as the call after [[g2p_add_scaled]] would see it.
            if (cx /= 0.0_wp) call g2p_block(model%basis, cx, vel, q0, q1, model%pts%x)
            call half_back(q0, q1, model%pts%x, model%pts%dx)
            call gradient_g2p_block(model%basis, vel, q0, q1, Lb, 0.5_wp * dt, model%pts%dx)
            call trapezoid_gradient(dt, lprev(:, :, q0:q1), Lb)
            if (mp) then
              do p = q0, q1
                call midpoint_gradient(dt, ctx%ndim, Lb(:, :, p - q0 + 1), ok)
                if (.not. ok) bad = min(bad, p)
              end do
            end if
          else if (cx /= 0.0_wp) then
            call gradient_g2p_block(model%basis, vel, q0, q1, Lb, cx, model%pts%x)
          else
            call velocity_gradient(model%basis, vel, q0, q1, Lb)
          end if
          if (sm) then
            do p = q0, q1
              dv = (bar(1, p) - tr(p)) / ctx%ndim
              do k = 1, ctx%ndim
                Lb(k, k, p - q0 + 1) = Lb(k, k, p - q0 + 1) + dv
              end do
            end do
          end if
          ctx%first = q0; ctx%nid = q1 - q0 + 1
          ctx%id(1:ctx%nid) = model%pts%id(q0:q1)
          call model%mats(im)%model%update(dt, Lb(:, :, 1:q1 - q0 + 1), model%pts%F(:, :, q0:q1), &
            model%pts%strain(:, q0:q1), model%pts%stress(:, q0:q1), model%pts%state(:, q0:q1), &
            model%pts%rho(q0:q1), ctx, info)
          if (info /= 0) bad = min(bad, q0 + info - 1)
          do p = q0, q1
            model%pts%vol(p) = model%pts%m(p) / model%pts%rho(p)
          end do
          ! Every SCREEN_GROUP particles (still in cache), one screen and one energy call:
          ! per 32-particle block their calls cost more than their arithmetic.
          if (q1 - g0 + 1 >= SCREEN_GROUP .or. q1 == b) then
            ok = model%pts%material_fields_fine(g0, q1)
            fine = fine .and. ok
            ! The next step's CFL limit (only on fine values: a NaN would trap in a debug build).
            if (ok) cm = max(cm, model%mats(im)%model%max_wave_speed(model%pts%rho(g0:q1), &
              model%pts%stress(:, g0:q1), model%pts%state(:, g0:q1)))
            if (we .and. ok) call model%mats(im)%model%energy_density(model%pts%F(:, :, g0:q1), &
              model%pts%strain(:, g0:q1), model%pts%stress(:, g0:q1), &
              model%pts%state(:, g0:q1), model%diag_psi(g0:q1))
            g0 = q1 + 1
          end if
        end do
      end do
      !$omp end parallel do
      if (bad /= huge(1)) then
        stat%code = STEP_MATERIAL_FAILED; stat%detail = im; stat%particle = model%pts%id(bad)
        stat%rank = model%comm%rank; stat%local = bad
        exit
      end if
    end do
    call agree_status(model, stat)
    if (stat%code /= 0) return
    model%diag_step = ctx%step; model%diag_fine = fine; model%diag_cmax = cm
  end subroutine stress_blocks

end module empm_integrator
