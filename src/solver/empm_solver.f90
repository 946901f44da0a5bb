!> The explicit time loop: CFL time step, stepping, run-time guards, histories, progress.
module empm_solver
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_INT
  use empm_error, only: empm_error_t, empm_raise, empm_raise_error, empm_alloc_error, &
                        EMPM_ERR_RUNTIME, EMPM_ERR_USAGE, EMPM_ERR_INTERRUPTED
  use empm_strings, only: str, join
  use empm_partition, only: empm_rebalance, empm_share_traction_state
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK, STEP_SHAPE_FAILED
  use empm_loads, only: RAMP_NONE
  use empm_integrator, only: empm_integrator_t
  use empm_particles, only: empm_particles_t
  use empm_history, only: empm_history_t
  use empm_shape, only: shape_status_text, SHAPE_OUTSIDE_GRID
  use empm_terminal, only: stderr_is_terminal
  use empm_screen, only: empm_screen_finite2, empm_screen_finite3
  use empm_files, only: empm_peak_memory
  implicit none
  private
  public :: empm_run_params
  public :: empm_run_config_t, empm_solve, empm_stable_dt, empm_energies, empm_check_guards
  public :: empm_run_stats_t, empm_run_summary
  public :: empm_run_hook_t, empm_solver_state_t

  !> Particles per block of the time loop's screen of positions, velocities and accelerations.
  integer, parameter :: SCREEN_BLOCK = 256

  !> How to run: end time, time step control, output sampling.
  type :: empm_run_config_t
    real(wp) :: t_end = 0.0_wp                 !! end time [s]
    real(wp) :: cfl = 0.5_wp                   !! Courant number, Δt = cfl·h/c_max
    real(wp) :: dt = 0.0_wp                    !! fixed time step [s]; 0 = use cfl
    integer :: max_steps = huge(1)             !! safety cap on the number of steps
    integer :: history_every = 1               !! record energies and probes every n steps
    real(wp), allocatable :: snapshot_times(:) !! times at which to store snapshots [s]
    logical :: progress = .true.               !! progress on stderr: a line updated in place
                                               !! on a terminal, plain lines (every 10 % of
                                               !! t_end or 10 s) otherwise
    integer :: checkpoint_every = 0            !! checkpoint every n steps (0: never), through
                                               !! the hook given to [[empm_solve]]
    real(wp) :: checkpoint_seconds = 0.0_wp    !! checkpoint after this much wall time [s]
                                               !! (0: never)
  end type empm_run_config_t

  !> The time loop's own progress: what a checkpoint stores besides the model and the
  !> histories, and what [[empm_solve]] continues from on a restart.
  type :: empm_solver_state_t
    integer :: isnap = 1                      !! next snapshot time to store
    integer :: steps = 0                      !! steps taken since the run's start
    real(wp) :: dt_min = huge(1.0_wp)         !! smallest time step so far [s]
    real(wp) :: dt_max = 0.0_wp               !! largest time step so far [s]
    real(wp) :: t_start = 0.0_wp              !! time at the run's start [s]
    real(wp) :: energy_initial = 0.0_wp       !! total energy at the run's start [J]
    real(wp) :: work_gravity = 0.0_wp         !! work of a time-varying gravity so far [J]
  end type empm_solver_state_t

  !> What the time loop calls out to: a checkpoint when one is due, a request to stop (e.g. a
  !> signal caught by the program), once per step, and each snapshot as it is taken.
  !> Extended by the driver, which knows where and how to write (the solver writes no files).
  type, abstract :: empm_run_hook_t
  contains
    procedure(hook_checkpoint), deferred :: checkpoint
    procedure :: stop_requested => hook_stop_requested
    procedure :: snapshot => hook_snapshot
  end type empm_run_hook_t

  abstract interface
    !> Write a checkpoint of the state after a completed step.
    subroutine hook_checkpoint(self, model, hist, state, err)
      import :: empm_run_hook_t, empm_model_t, empm_history_t, empm_solver_state_t, &
        empm_error_t
      class(empm_run_hook_t), intent(inout) :: self     !! hook
      type(empm_model_t), intent(in) :: model           !! the state (last step completed)
      type(empm_history_t), intent(in) :: hist          !! histories and snapshots so far
      type(empm_solver_state_t), intent(in) :: state    !! the loop's progress
      type(empm_error_t), intent(out) :: err            !! error (code 0 when written)
    end subroutine hook_checkpoint
  end interface

  !> What a run did, for an end-of-run summary ([[empm_run_summary]]).
  type :: empm_run_stats_t
    logical :: ran = .false.            !! the time loop was entered (false when the run was
                                        !! refused before it, e.g. t_end not after the start)
    integer :: steps = 0                !! steps taken by this call
    real(wp) :: dt_min = 0.0_wp         !! smallest time step [s] (0 when no step was taken)
    real(wp) :: dt_max = 0.0_wp         !! largest time step [s]
    real(wp) :: wall = 0.0_wp           !! wall-clock time of the time loop [s]
    real(wp) :: setup = -1.0_wp         !! wall-clock time before it [s] (the driver's: reading
                                        !! the case, sharing the particles, claiming the
                                        !! output, the first basis; the slowest process's);
                                        !! < 0: not measured (empm_solve alone)
    real(wp) :: t_start = 0.0_wp        !! time at the start [s]
    real(wp) :: t_reached = 0.0_wp      !! time reached [s]
    real(wp) :: energy_initial = 0.0_wp !! total energy (kinetic + strain + gravity) at the start [J]
    real(wp) :: energy_final = 0.0_wp   !! total energy at the end (last good state) [J]
    real(wp) :: work_gravity = 0.0_wp   !! work of a time-varying gravity, −∫ Σ m ġ·x dt [J]
    logical :: tracked = .false.        !! the model tracked its residual
    real(wp) :: residual = -1.0_wp      !! its last value (model%residual)
                                        !! (trapezoidal per step): what the total energy
                                        !! gains from a gravity ramp
    integer :: nranks = 1               !! processes that ran it
    integer :: rebalances = 0           !! times particles moved to other processes after a
                                        !! re-cut of the boxes
    real(wp) :: imbalance = 1.0_wp      !! largest process's particles over the mean, just
                                        !! before a re-cut (the worst the boxes drifted to)
    real(wp) :: imbalance_static = 1.0_wp !! the same in the first boxes (a split never re-cut)
    real(wp) :: halo_bytes = 0.0_wp     !! bytes of nodal partial sums the busiest process
                                        !! sent per step to its neighbours
    integer :: migrated = 0             !! particles that changed process at the re-cuts
    integer :: grid_nodes = 0           !! nodes of the whole grid
    integer :: stored_nodes = 0         !! most grid nodes a process stored at once (its
                                        !! window; parallel runs)
    integer :: windows = 0              !! new windows taken, all processes together
    real(wp) :: peak_memory = -1.0_wp   !! largest peak resident memory of a process so far
                                        !! (set-up and time loop) [bytes]; < 0: unknown
  end type empm_run_stats_t

contains

  !> Default: no stop is ever requested. Returns a signal number (> 0) when the run must stop
  !> after the current step, writing a checkpoint first.
  integer function hook_stop_requested(self) result(sig)
    class(empm_run_hook_t), intent(inout) :: self !! hook
    associate (unused_ => self); end associate
    sig = 0
  end function hook_stop_requested

  !> Default: the snapshot is kept in `hist` ([[empm_history_t]]'s `add_snapshot`). Called
  !> by every process at each snapshot time, after the step that reached it.
  subroutine hook_snapshot(self, model, hist, err)
    class(empm_run_hook_t), intent(inout) :: self !! hook
    type(empm_model_t), intent(in) :: model       !! the state to record
    type(empm_history_t), intent(inout) :: hist   !! record it goes into
    type(empm_error_t), intent(out) :: err        !! error (code 0 when recorded)
    associate (unused_ => self); end associate
    err%code = 0
    call hist%add_snapshot(model%t, model%step, model%pts)
  end subroutine hook_snapshot

  !> The run controls of the `&integrator` group (t_end, cfl, dt, max_steps), declared here
  !> where they are used; the case reader reads them, the scheme its own keys.
  pure function empm_run_params() result(p)
    type(empm_param_t), allocatable :: p(:) !! declarations
    p = [ &
      empm_param('t_end', PARAM_REAL, 's', 'end time', lo=0.0_wp, lo_open=.true.), &
      empm_param('cfl', PARAM_REAL, '-', 'Courant number: dt = cfl h_min / c_max', &
        default='0.5', lo=0.0_wp, hi=1.0_wp, lo_open=.true.), &
      empm_param('dt', PARAM_REAL, 's', 'fixed time step; 0 = from cfl (a fixed step above '// &
        'the stability limit stops the run, status 3)', default='0', lo=0.0_wp), &
      empm_param('max_steps', PARAM_INT, '-', 'safety cap on the number of steps (reaching '// &
        'it stops the run, status 3)', default='100000000', lo=1.0_wp)]
  end function empm_run_params

  !> Largest stable time step h_min / c_max, with c_max the largest P-wave speed over the
  !> particles (each material run asked once, `max_wave_speed`).
  function empm_stable_dt(model) result(dt)
    type(empm_model_t), intent(in) :: model !! simulation state
    real(wp) :: dt                          !! critical time step [s]
    real(wp) :: cmax, c
    integer :: r, i0, i1
    cmax = 0.0_wp
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      c = model%mats(model%pts%mat(i0))%model%max_wave_speed(model%pts%rho(i0:i1), &
        model%pts%stress(:, i0:i1), model%pts%state(:, i0:i1))
      cmax = max(cmax, c)
    end do
    cmax = model%comm%max_real(cmax)
    dt = huge(1.0_wp) ! no particle anywhere (a process may hold none)
    if (cmax > 0.0_wp) dt = model%grid%hmin() / cmax
  end function empm_stable_dt

  !> Kinetic energy, stored (elastic) energy and gravitational potential of the particles.
  subroutine empm_energies(model, psi, ekin, estrain, egrav)
    type(empm_model_t), intent(in) :: model !! simulation state
    real(wp), intent(inout) :: psi(:)       !! scratch, size >= np
    real(wp), intent(out) :: ekin           !! Σ ½ m |v|² [J]
    real(wp), intent(out) :: estrain        !! Σ V ψ [J]
    real(wp), intent(out) :: egrav          !! −Σ m g(t)·x [J]
    real(wp) :: g(3)
    integer :: r, i0, i1, np
    np = model%pts%np
    g = model%loads%gravity_at(model%t)
    ekin = 0.0_wp; egrav = 0.0_wp
    call motion_energies(model, 1, np, g, ekin, egrav)
    ekin = 0.5_wp * ekin
    estrain = 0.0_wp
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      call model%mats(model%pts%mat(i0))%model%energy_density(model%pts%F(:, :, i0:i1), &
        model%pts%strain(:, i0:i1), model%pts%stress(:, i0:i1), model%pts%state(:, i0:i1), &
        psi(i0:i1))
    end do
    estrain = stored_energy(model, psi)
    call sum_energies(model, ekin, estrain, egrav)
  end subroutine empm_energies

  ! The energies of all the processes' particles (each process summed its own).
  subroutine sum_energies(model, ekin, estr, egrav)
    type(empm_model_t), intent(in) :: model
    real(wp), intent(inout) :: ekin, estr, egrav
    real(wp) :: e(3)
    if (.not. model%comm%parallel()) return
    e = [ekin, estr, egrav]
    call model%comm%sum(e)
    ekin = e(1); estr = e(2); egrav = e(3)
  end subroutine sum_energies

  !> Run `model` with `integ` until `cfg%t_end`. Records energies, probes and snapshots in
  !> `hist`. On a tripped guard the model is restored to the last good state and the error
  !> (code EMPM_ERR_RUNTIME) names the step, the particle or node and the quantity.
  !>
  !> With `hook`, a checkpoint is asked of it every `cfg%checkpoint_every` steps and every
  !> `cfg%checkpoint_seconds` of wall time, and its stop request is polled once per step: on a
  !> request the loop writes a checkpoint and returns EMPM_ERR_INTERRUPTED (the model holds the
  !> last completed step). With `resume` (a restart), `model` and `hist` already hold a
  !> checkpoint's state: the integrator's start-up is not redone (its work arrays are set up,
  !> then the particles and the traction state are put back as they were), no first sample
  !> is taken, and the loop continues from `resume`; the run is then bitwise the uninterrupted
  !> one when the number of threads is the same (the P2G sums follow the thread chunks).
  subroutine empm_solve(model, integ, cfg, hist, err, stats, hook, resume)
    type(empm_model_t), intent(inout) :: model                !! simulation (set up)
    class(empm_integrator_t), intent(inout) :: integ          !! time integrator
    type(empm_run_config_t), intent(in) :: cfg                !! run controls
    type(empm_history_t), intent(inout) :: hist               !! record (initialised by caller)
    type(empm_error_t), intent(out), optional :: err          !! error, if present
    type(empm_run_stats_t), intent(out), optional :: stats    !! steps, time steps, wall time and
                                                              !! energies of the run (also when
                                                              !! a guard stopped it)
    class(empm_run_hook_t), intent(inout), optional :: hook   !! checkpoints and stop requests
    type(empm_solver_state_t), intent(in), optional :: resume !! continue a restored run
    type(empm_particles_t) :: good
    type(empm_solver_state_t) :: sst
    ! The last good state is kept every KEEP_EVERY steps only (a copy of every particle array
    ! each step cost as much as a linear step): a guard stop restores it and replays the
    ! steps since with their recorded time steps, which gives the state before the failing
    ! step bitwise (the step is deterministic for a given number of threads).
    integer, parameter :: KEEP_EVERY = 128
    ! On several processes the boxes are cut again at every kept state, every RECUT_EVERY
    ! steps: a collapsing body drifts out of balance within a few tens of steps.
    integer, parameter :: RECUT_EVERY = 32
    real(wp) :: dts(KEEP_EVERY), t_prev
    integer :: keep
    real(wp), allocatable :: xprev(:,:)
    integer :: nrep
    logical :: ramping
    real(wp), allocatable :: tlam(:,:,:)
    real(wp) :: residual0
    integer(int64) :: clock_ckpt
    integer :: sig, k, inode
    type(empm_step_status_t) :: stat
    real(wp), allocatable :: psi(:)
    real(wp) :: dt, dt_stable, ekin, estr, egrav, t_good, t_next_snap
    integer :: isnap, nsnap, step_good, step_first
    integer(int64) :: clock0, clock_last, clock, rate, sent0
    logical :: show, tty, sample, suspect, summed
    type(empm_run_stats_t) :: st
    real(wp) :: t_report
    character(len=:), allocatable :: msg
    type(empm_error_t) :: e
    integer :: astat
    character(len=256) :: amsg

    if (.not. allocated(model%run_first)) then
      call empm_raise(EMPM_ERR_USAGE, 'empm_solve: call model%finalize_setup() first', err); return
    end if
    if (cfg%t_end <= model%t) then
      call empm_raise(EMPM_ERR_USAGE, 'empm_solve: t_end must exceed the current time', err)
      return
    end if
    call good%alloc(model%grid%ndim, model%pts%np, model%pts%nstate, e)
    if (e%code == 0 .and. present(resume)) then
      ! The integrator's start-up changes the particles (initial accelerations, LME
      ! multipliers) and resets the traction state: keep the restored ones aside.
      call good%copy_state_from(model%pts)
      call save_tractions()
      residual0 = model%residual
    end if
    if (e%code == 0) call integ%prepare(model, e)
    if (e%code == 0) call particle_scratch(e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    nsnap = 0
    if (allocated(cfg%snapshot_times)) nsnap = size(cfg%snapshot_times)
    if (present(resume)) then
      call model%pts%copy_state_from(good)
      call integ%resync(model)
      call restore_tractions()
      model%residual = residual0
      isnap = resume%isnap
      st%steps = resume%steps; st%dt_min = resume%dt_min; st%dt_max = resume%dt_max
      st%t_start = resume%t_start; st%energy_initial = resume%energy_initial
      st%work_gravity = resume%work_gravity
    else
      isnap = 1
      call empm_energies(model, psi, ekin, estr, egrav)
      call hist%add_sample(model%t, ekin, estr, egrav, model%pts, model)
      st%t_start = model%t; st%energy_initial = ekin + estr + egrav
      st%dt_min = huge(1.0_wp)
      call skip_past_snapshots(e)
      if (e%code /= 0) then
        call empm_raise_error(e, err); return
      end if
    end if
    show = cfg%progress .and. model%comm%is_root()
    tty = .false.
    if (show) tty = stderr_is_terminal()
    ! Plain lines (logs, pipes) are written when t passes the next tenth of the run.
    t_report = model%t + 0.1_wp * (cfg%t_end - model%t)
    call system_clock(clock0, rate); clock_last = clock0; clock_ckpt = clock0
    keep = KEEP_EVERY
    if (model%comm%parallel()) keep = RECUT_EVERY
    nrep = keep ! a copy before the first step
    step_first = model%step
    st%nranks = model%comm%nranks
    sent0 = model%halo%sent
    ! The work of a time-varying gravity needs the positions before each step.
    ramping = model%loads%ramp /= RAMP_NONE
    if (ramping) allocate(xprev(model%grid%ndim, model%pts%np))

    do while (model%t < cfg%t_end * (1.0_wp - 1.0e-12_wp))
      if (model%step >= cfg%max_steps) then
        call fail('the step cap max_steps = '//str(cfg%max_steps)//' was reached at t = '// &
                  str(model%t)//' s before t_end'); return
      end if
      ! The last stress update gave c_max while its blocks were in cache (fine values only:
      ! with a failed screen the guards have stopped the run); the same maximum.
      if (model%comm%parallel()) then
        dt_stable = empm_stable_dt(model)
      else if (model%diag_step == model%step .and. model%diag_fine .and. &
               model%diag_cmax > 0.0_wp) then
        dt_stable = model%grid%hmin() / model%diag_cmax
      else
        dt_stable = empm_stable_dt(model)
      end if
      if (cfg%dt > 0.0_wp) then
        dt = cfg%dt
        if (dt > dt_stable) then
          call fail('step '//str(model%step + 1)//': time step dt = '//str(dt)// &
            ' s exceeds the stability limit h/c_max = '//str(dt_stable)//' s'); return
        end if
      else
        dt = cfg%cfl * dt_stable
      end if
      ! Land exactly on the end time and on snapshot times.
      t_next_snap = cfg%t_end
      if (isnap <= nsnap) t_next_snap = min(cfg%t_end, cfg%snapshot_times(isnap))
      if (model%t + dt > t_next_snap * (1.0_wp - 1.0e-12_wp)) dt = t_next_snap - model%t

      if (nrep == keep) then
        ! Several processes: the boxes follow the particles (before the kept state, so that a
        ! guard's replay never crosses a re-cut).
        if (model%comm%parallel() .and. model%step > step_first) then
          call rebalance(e)
          if (e%code /= 0) then
            call finish_stats(); call empm_raise_error(e, err); return
          end if
        end if
        call good%copy_state_from(model%pts)
        call save_tractions()
        t_good = model%t; step_good = model%step; nrep = 0
      end if
      t_prev = model%t
      if (ramping) xprev = model%pts%x(:, 1:model%pts%np)
      ! A sampled step: the stress update sums the stored energy while its blocks are in cache
      ! (the same test as the sampling below, on the same sums).
      model%want_energy = mod(model%step + 1, cfg%history_every) == 0 .or. &
        model%t + dt >= cfg%t_end
      call integ%step(model, dt, stat)
      nrep = nrep + 1; dts(nrep) = dt
      model%step = model%step + 1
      if (stat%code /= STEP_OK) then
        ! The process that holds the particle says why (its material knows); the others
        ! take its words.
        msg = ''
        if (model%comm%rank == stat%rank) msg = describe_status(stat)
        call model%comm%bcast_text(msg, stat%rank)
        call restore(); call fail(msg, stat%particle); return
      end if
      model%t = model%t + dt
      ! The screen reads x, v, a and the nodal fields once (and sums the energies of a sampled
      ! step from them); the detailed search (the same verdict, with the first offender named)
      ! runs only when it fails.
      sample = mod(model%step, cfg%history_every) == 0 .or. model%t >= cfg%t_end
      call screen_step(model, sample, suspect, ekin, egrav, estr, summed)
      if (model%comm%parallel()) then
        suspect = model%comm%any_true(suspect)
        summed = .not. model%comm%any_true(.not. summed)
        if (summed) call sum_energies(model, ekin, estr, egrav)
      end if
      if (suspect) then
        msg = empm_check_guards(model, k, inode)
        msg = first_problem(msg, k, inode)
        if (len(msg) > 0) then
          call restore(); call fail(msg); return
        end if
      end if
      st%steps = st%steps + 1
      st%dt_min = min(st%dt_min, dt); st%dt_max = max(st%dt_max, dt)
      call add_gravity_work()

      if (sample) then
        if (.not. summed) call empm_energies(model, psi, ekin, estr, egrav)
        call hist%add_sample(model%t, ekin, estr, egrav, model%pts, model)
      end if
      model%want_energy = .false.
      call skip_past_snapshots(e)
      if (e%code /= 0) then
        if (show .and. tty) write(error_unit, '(a)') ''
        call finish_stats(); call empm_raise_error(e, err); return
      end if
      if (show) call progress()
      if (present(hook)) then
        ! Every process stops, and checkpoints, at the same step.
        sig = model%comm%max_int(hook%stop_requested())
        if (model%comm%any_true(checkpoint_due()) .or. sig /= 0) then
          call checkpoint(e)
          if (e%code /= 0) then
            if (show .and. tty) write(error_unit, '(a)') ''
            call finish_stats(); call empm_raise_error(e, err); return
          end if
        end if
        if (sig /= 0) then
          if (show .and. tty) write(error_unit, '(a)') ''
          call finish_stats()
          call empm_raise(EMPM_ERR_INTERRUPTED, 'stopped by '//signal_name(sig)// &
            ' after step '//str(model%step)//' at t = '//str(model%t)// &
            ' s: checkpoint written', err)
          return
        end if
      end if
    end do
    if (show .and. tty) write(error_unit, '(a)') ''
    call finish_stats()

  contains

    function signal_name(k) result(name)
      integer, intent(in) :: k
      character(len=:), allocatable :: name
      select case (k)
      case (2); name = 'SIGINT'
      case (15); name = 'SIGTERM'
      case default; name = 'signal '//str(k)
      end select
    end function signal_name

    ! A checkpoint is due every checkpoint_every steps and once checkpoint_seconds of wall
    ! time have passed since the last one (one clock read per step only when that is set).
    logical function checkpoint_due() result(due)
      integer(int64) :: c
      due = .false.
      if (cfg%checkpoint_every > 0) due = mod(model%step, cfg%checkpoint_every) == 0
      if (.not. due .and. cfg%checkpoint_seconds > 0.0_wp) then
        call system_clock(c)
        due = real(c - clock_ckpt, wp) / real(rate, wp) >= cfg%checkpoint_seconds
      end if
    end function checkpoint_due

    subroutine checkpoint(ec)
      type(empm_error_t), intent(out) :: ec
      sst%isnap = isnap; sst%steps = st%steps; sst%dt_min = st%dt_min; sst%dt_max = st%dt_max
      sst%t_start = st%t_start; sst%energy_initial = st%energy_initial
      sst%work_gravity = st%work_gravity
      call empm_share_traction_state(model) ! the root writes every face centre's state
      call hook%checkpoint(model, hist, sst, ec)
      call system_clock(clock_ckpt)
    end subroutine checkpoint

    ! The surface tractions' shape-function state (LME multipliers at the face centres),
    ! which the integrator's preparation resets.
    subroutine save_tractions()
      integer :: n
      if (model%loads%ntraction() == 0) return
      n = 0
      do k = 1, size(model%loads%tractions)
        if (allocated(model%loads%tractions(k)%lam)) &
          n = max(n, size(model%loads%tractions(k)%lam, 2))
      end do
      ! Allocated once (this runs in the time loop too, at every kept state).
      if (.not. allocated(tlam)) then
        allocate(tlam(model%grid%ndim, n, size(model%loads%tractions)))
        tlam = 0.0_wp
      end if
      do k = 1, size(model%loads%tractions)
        associate (tr => model%loads%tractions(k))
          if (allocated(tr%lam)) tlam(:, 1:size(tr%lam, 2), k) = tr%lam
        end associate
      end do
    end subroutine save_tractions

    subroutine restore_tractions()
      if (.not. allocated(tlam)) return
      do k = 1, size(model%loads%tractions)
        associate (tr => model%loads%tractions(k))
          if (allocated(tr%lam)) tr%lam = tlam(:, 1:size(tr%lam, 2), k)
        end associate
      end do
    end subroutine restore_tractions

    ! Cut the processes' boxes again and move the particles; then the work arrays sized by
    ! the number of particles, as a restart makes them (the integrator's start-up changes the
    ! particles: they are put back).
    subroutine rebalance(ec)
      type(empm_error_t), intent(out) :: ec
      real(wp) :: before, static, res0
      logical :: moved
      integer :: migrated
      call empm_rebalance(model, before, static, moved, migrated, ec)
      if (ec%code /= 0) return
      st%migrated = st%migrated + migrated
      st%imbalance = max(st%imbalance, before)
      st%imbalance_static = max(st%imbalance_static, static)
      if (.not. moved) return
      st%rebalances = st%rebalances + 1
      call hist%locate_probes(model%pts)
      call good%alloc(model%grid%ndim, model%pts%np, model%pts%nstate, ec)
      if (ec%code /= 0) return
      call good%copy_state_from(model%pts)
      call save_tractions() ! the start-up resets the traction state too
      res0 = model%residual
      call integ%prepare(model, ec)
      if (ec%code /= 0) return
      call model%pts%copy_state_from(good)
      call integ%resync(model)
      call restore_tractions()
      model%residual = res0
      call particle_scratch(ec)
      model%diag_step = -1 ! the last stress update's screen was of the particles as they were
    end subroutine rebalance

    ! The time loop's scratch sized by the particles the model holds (at the start, and again
    ! after a re-cut moved particles between processes).
    subroutine particle_scratch(ec)
      type(empm_error_t), intent(inout) :: ec
      integer :: np
      np = model%pts%np
      if (allocated(psi)) deallocate(psi)
      allocate(psi(np), stat=astat, errmsg=amsg)
      if (astat /= 0) then
        ec = empm_alloc_error('energy scratch', 8_int64 * np, amsg); return
      end if
      ! The stress update's energy densities of a sampled step (model%want_energy).
      if (allocated(model%diag_psi)) deallocate(model%diag_psi)
      allocate(model%diag_psi(np), stat=astat, errmsg=amsg)
      if (astat /= 0) then
        ec = empm_alloc_error('energy densities', 8_int64 * np, amsg); return
      end if
      if (allocated(xprev)) then
        deallocate(xprev); allocate(xprev(model%grid%ndim, np))
      end if
    end subroutine particle_scratch

    ! The potential −Σ m g(t)·x changes with g(t) too: the ramp's work, so that the energy
    ! balance of the summary can subtract it. Diagnostics only (the state is not touched).
    subroutine add_gravity_work()
      real(wp) :: g0(3), g1(3)
      integer :: d, np
      g0 = model%loads%gravity_at(t_prev); g1 = model%loads%gravity_at(model%t)
      if (all(g0 == g1) .or. .not. ramping) return
      d = model%grid%ndim; np = model%pts%np
      st%work_gravity = st%work_gravity - model%comm%sum_real(sum(model%pts%m(1:np) * &
        matmul(g1(1:d) - g0(1:d), 0.5_wp * (xprev(:, 1:np) + model%pts%x(:, 1:np)))))
    end subroutine add_gravity_work

    ! The statistics of the run so far (the model holds the last good state).
    subroutine finish_stats()
      call system_clock(clock)
      st%wall = real(clock - clock0, wp) / real(rate, wp)
      if (st%steps == 0) st%dt_min = 0.0_wp
      st%t_reached = model%t; st%ran = .true.
      st%tracked = model%track; st%residual = model%residual
      call empm_energies(model, psi, ekin, estr, egrav)
      st%energy_final = ekin + estr + egrav
      st%halo_bytes = model%comm%max_real(real(model%halo%sent - sent0, wp) / max(st%steps, 1))
      st%grid_nodes = product(model%grid%nn)
      st%stored_nodes = nint(model%comm%max_real(real(model%stored_peak, wp)))
      st%windows = model%comm%sum_int(model%windows)
      st%peak_memory = model%comm%max_real(real(empm_peak_memory(), wp))
      if (present(stats)) stats = st
    end subroutine finish_stats

    ! Record the snapshots whose times the run has reached (the hook's way, else in hist).
    subroutine skip_past_snapshots(es)
      type(empm_error_t), intent(out) :: es
      do while (isnap <= nsnap)
        if (cfg%snapshot_times(isnap) > model%t * (1.0_wp + 1.0e-12_wp) + tiny(1.0_wp)) exit
        if (present(hook)) then
          call hook%snapshot(model, hist, es)
          if (es%code /= 0) return
        else
          call hist%add_snapshot(model%t, model%step, model%pts)
        end if
        isnap = isnap + 1
      end do
    end subroutine skip_past_snapshots

    ! Back to the state before the failing step: the kept state, then the steps since it
    ! replayed with their time steps (all but the last, which failed).
    subroutine restore()
      type(empm_step_status_t) :: rs
      integer :: i
      call model%pts%copy_state_from(good)
      call integ%resync(model)
      call restore_tractions()
      model%t = t_good; model%step = step_good
      do i = 1, nrep - 1
        call integ%step(model, dts(i), rs)
        if (rs%code /= STEP_OK) exit ! cannot happen for a deterministic step
        model%step = model%step + 1
        model%t = model%t + dts(i)
      end do
    end subroutine restore

    ! The run-time error: the text already names the step (and the particle or node); the
    ! fields carry them for programs.
    subroutine fail(text, particle)
      character(len=*), intent(in) :: text
      integer, intent(in), optional :: particle
      type(empm_error_t) :: ef
      if (show .and. tty) write(error_unit, '(a)') ''
      call finish_stats()
      ef%code = EMPM_ERR_RUNTIME; ef%message = text; ef%step = model%step + 1
      if (present(particle)) ef%particle = particle
      call empm_raise_error(ef, err)
    end subroutine fail

    ! On a terminal one line rewritten twice a second; elsewhere (a batch log) a plain line
    ! each tenth of the run or every 10 s, whichever comes first.
    subroutine progress()
      real(wp) :: elapsed, sps, eta, since
      character(len=160) :: line
      integer :: ios
      call system_clock(clock)
      since = real(clock - clock_last, wp) / real(rate, wp)
      if (tty) then
        if (since < 0.5_wp .and. model%t < cfg%t_end) return
      else
        if (since < 10.0_wp .and. model%t < t_report * (1.0_wp - 1.0e-12_wp)) return
        do while (t_report <= model%t * (1.0_wp + 1.0e-12_wp))
          t_report = t_report + 0.1_wp * (cfg%t_end - st%t_start)
        end do
      end if
      clock_last = clock
      elapsed = real(clock - clock0, wp) / real(rate, wp)
      sps = real(st%steps, wp) / max(elapsed, 1.0e-9_wp)
      eta = elapsed * (cfg%t_end - model%t) / max(model%t - st%t_start, tiny(1.0_wp))
      write(line, '(a,es10.3,a,es10.3,a,i0,a,f10.1,a,f8.1,a)') 't = ', model%t, ' / ', &
        cfg%t_end, ' s  step ', model%step, '  ', sps, ' steps/s  ETA ', eta, ' s'
      if (tty) then
        write(error_unit, '(a)', advance='no', iostat=ios) achar(13)//trim(line)
      else
        write(error_unit, '(a,i3,a)', iostat=ios) 'empm: ', &
          nint(100.0_wp * (model%t - st%t_start) / (cfg%t_end - st%t_start)), '%  '//trim(line)
      end if
      flush(error_unit)
    end subroutine progress

    ! The problem the serial run would report, on every process: the particle with the
    ! smallest id (`id`, huge(1) for a nodal problem); with none, the node with the smallest
    ! number (`node`: a node is checked only where it is complete, on the processes whose
    ! particles reach it, so the processes may find different ones).
    function first_problem(mine, id, node) result(text)
      character(len=*), intent(in) :: mine
      integer, intent(in) :: id, node
      character(len=:), allocatable :: text
      integer :: first, lowest, key
      text = mine
      if (.not. model%comm%parallel()) return
      key = id
      lowest = model%comm%min_int(merge(key, huge(1), len(mine) > 0))
      if (lowest == huge(1)) then
        key = node
        lowest = model%comm%min_int(merge(key, huge(1), len(mine) > 0))
      end if
      first = model%comm%min_int(merge(model%comm%rank, model%comm%nranks, &
                                       len(mine) > 0 .and. key == lowest))
      if (first == model%comm%nranks) return
      call model%comm%bcast_text(text, first)
    end function first_problem

    function describe_status(s) result(text)
      type(empm_step_status_t), intent(in) :: s
      character(len=:), allocatable :: text
      integer :: p
      p = max(1, min(s%local, model%pts%np))
      if (s%code == STEP_SHAPE_FAILED) then
        text = 'step '//str(model%step)//': shape functions failed at particle '// &
          str(s%particle)//' at x = '//vec(model%pts%x(:, p))//': '//shape_status_text(s%detail)
        if (s%detail == SHAPE_OUTSIDE_GRID) text = 'step '//str(model%step)//': particle '//str(s%particle)// &
          ' left the grid: x = '//vec(model%pts%x(:, p))
      else
        ! The material says why its update fails (the owner of the status explains it).
        text = 'step '//str(model%step)//': stress update failed at particle '// &
          str(s%particle)//' (material '''//model%mats(s%detail)%label//''', model '// &
          model%mats(s%detail)%model%name()//'): '//model%mats(s%detail)%model%failure_text()
      end if
    end function describe_status
  end subroutine empm_solve

  !> After a step: the guards' cheap test (`suspect` = .false. only when [[empm_check_guards]]
  !> would return '') and, with `sample` on a step whose stress update left its energy
  !> densities (`model%want_energy`), the kinetic, stored and gravitational energies as
  !> [[empm_energies]] sums them (`done` then; not when the screen failed first). The material
  !> fields count as screened when this step's stress update screened them
  !> (`model%diag_step`); otherwise they are read here. Positions, velocities and accelerations
  !> are read once, block by block: the screen of their sums, the extreme coordinates (against
  !> the grid box and the mirror planes, with the detailed check's expressions) and the energies
  !> from the block in cache; then the nodal velocities and accelerations.
  subroutine screen_step(model, sample, suspect, ekin, egrav, estr, done)
    type(empm_model_t), intent(in) :: model !! simulation state
    logical, intent(in) :: sample           !! sum the energies too
    logical, intent(out) :: suspect         !! the detailed check may find something
    real(wp), intent(out) :: ekin           !! Σ ½ m |v|² [J] (with `done`)
    real(wp), intent(out) :: egrav          !! −Σ m g(t)·x [J] (with `done`)
    real(wp), intent(out) :: estr           !! Σ V ψ [J] (with `done`)
    logical, intent(out) :: done            !! the three energies were summed
    real(wp) :: lo(3), hi(3), upper, side, g(3), xlo, xhi, er
    integer :: np, nd, p, k, I, nn, q0, q1, n, r
    logical :: whole
    np = model%pts%np; nd = model%grid%ndim; nn = model%nodes%nnode
    suspect = .true.; done = .false.; ekin = 0.0_wp; egrav = 0.0_wp; estr = 0.0_wp
    ! The stress update left the energy densities of this step (a sampled one) in diag_psi:
    ! the stored energy is summed in the same pass as the motion energies.
    whole = sample .and. model%want_energy .and. model%diag_step == model%step
    if (whole) whole = allocated(model%diag_psi)
    if (whole) whole = size(model%diag_psi) >= np
    r = 1; er = 0.0_wp
    if (model%diag_step == model%step) then
      if (.not. model%diag_fine) return
    else
      if (.not. model%pts%material_fields_fine(1, np)) return
    end if
    g = model%loads%gravity_at(model%t)
    lo = huge(1.0_wp); hi = -huge(1.0_wp)
    associate (x => model%pts%x)
      do q0 = 1, np, SCREEN_BLOCK
        q1 = min(np, q0 + SCREEN_BLOCK - 1); n = nd * (q1 - q0 + 1)
        if (.not. empm_screen_finite3(n, x(1, q0), model%pts%v(1, q0), model%pts%a(1, q0))) &
          return
        ! Finite now: min and max cannot meet a NaN (which would trap in a debug build). One
        ! direction at a time, into scalars: the loop over the block then vectorises.
        do k = 1, nd
          xlo = lo(k); xhi = hi(k)
          do p = q0, q1
            xlo = min(xlo, x(k, p)); xhi = max(xhi, x(k, p))
          end do
          lo(k) = xlo; hi(k) = xhi
        end do
        if (whole) call all_energies(model, q0, q1, g, ekin, egrav, r, er, estr)
      end do
    end associate
    do k = 1, nd
      upper = model%grid%origin(k) + model%grid%ncell(k) * model%grid%h(k)
      if (np > 0 .and. .not. (lo(k) >= model%grid%origin(k) .and. hi(k) <= upper)) return
    end do
    do I = 1, model%nodes%nplane
      k = abs(model%nodes%plane_side(I))
      side = sign(1.0_wp, real(model%nodes%plane_side(I), wp))
      if (np > 0 .and. side * (merge(hi(k), lo(k), side > 0.0_wp) - model%nodes%plane_at(I)) > &
          1.0e-9_wp * model%grid%h(k)) return
    end do
    if (nn > 0) then
      if (.not. empm_screen_finite2(nd * nn, model%nodes%vel, model%nodes%acc)) return
    end if
    suspect = .false.
    ekin = 0.5_wp * ekin
    done = whole
  end subroutine screen_step

  ! motion_energies and, in the same loop, the stored energy Σ V ψ of particles q0..q1 from
  ! model%diag_psi: three independent sums, so their additions overlap instead of waiting on
  ! one another in two passes, each still in its old order (stored_energy: a sum per material
  ! run `r`, partial `er`, added to `estr` when the run ends).
  subroutine all_energies(model, q0, q1, g, ekin, egrav, r, er, estr)
    type(empm_model_t), intent(in) :: model
    integer, intent(in) :: q0, q1
    real(wp), intent(in) :: g(3)
    real(wp), intent(inout) :: ekin, egrav
    integer, intent(inout) :: r
    real(wp), intent(inout) :: er, estr
    integer :: p, p0, pe
    p0 = q0
    associate (v => model%pts%v, x => model%pts%x, m => model%pts%m, vol => model%pts%vol, &
               psi => model%diag_psi)
      do while (p0 <= q1)
        pe = min(q1, model%run_last(r))
        select case (model%grid%ndim)
        case (2)
          do p = p0, pe
            ekin = ekin + m(p) * (v(1, p)**2 + v(2, p)**2)
            egrav = egrav - m(p) * (g(1) * x(1, p) + g(2) * x(2, p))
            er = er + vol(p) * psi(p)
          end do
        case (3)
          do p = p0, pe
            ekin = ekin + m(p) * ((v(1, p)**2 + v(2, p)**2) + v(3, p)**2)
            egrav = egrav - m(p) * ((g(1) * x(1, p) + g(2) * x(2, p)) + g(3) * x(3, p))
            er = er + vol(p) * psi(p)
          end do
        case default
          call motion_energies(model, p0, pe, g, ekin, egrav)
          do p = p0, pe
            er = er + vol(p) * psi(p)
          end do
        end select
        if (pe == model%run_last(r)) then
          estr = estr + er
          er = 0.0_wp; r = r + 1
        end if
        p0 = pe + 1
      end do
    end associate
  end subroutine all_energies

  ! Add Σ m |v|² and −Σ m g·x of particles q0..q1 to ekin and egrav, one particle after the
  ! other in index order (the order of every earlier version: the energy metrics of the
  ! verification summary are differences of nearly equal energies, sensitive to the last bit).
  subroutine motion_energies(model, q0, q1, g, ekin, egrav)
    type(empm_model_t), intent(in) :: model
    integer, intent(in) :: q0, q1
    real(wp), intent(in) :: g(3)
    real(wp), intent(inout) :: ekin, egrav
    real(wp) :: vv, gx
    integer :: k, p
    associate (v => model%pts%v, x => model%pts%x, m => model%pts%m)
      select case (model%grid%ndim)
      case (2)
        do p = q0, q1
          ekin = ekin + m(p) * (v(1, p)**2 + v(2, p)**2)
          egrav = egrav - m(p) * (g(1) * x(1, p) + g(2) * x(2, p))
        end do
      case (3)
        do p = q0, q1
          ekin = ekin + m(p) * ((v(1, p)**2 + v(2, p)**2) + v(3, p)**2)
          egrav = egrav - m(p) * ((g(1) * x(1, p) + g(2) * x(2, p)) + g(3) * x(3, p))
        end do
      case default
        do p = q0, q1
          vv = 0.0_wp; gx = 0.0_wp
          do k = 1, model%grid%ndim
            vv = vv + v(k, p)**2
            gx = gx + g(k) * x(k, p)
          end do
          ekin = ekin + m(p) * vv
          egrav = egrav - m(p) * gx
        end do
      end select
    end associate
  end subroutine motion_energies

  ! Σ V ψ, run by run, each run's sum added to the total (the order of every earlier version).
  function stored_energy(model, psi) result(e)
    type(empm_model_t), intent(in) :: model
    real(wp), intent(in) :: psi(:)
    real(wp) :: e, er
    integer :: r, p
    e = 0.0_wp
    do r = 1, size(model%run_first)
      er = 0.0_wp
      do p = model%run_first(r), model%run_last(r)
        er = er + model%pts%vol(p) * psi(p)
      end do
      e = e + er
    end do
  end function stored_energy

  !> Check particle and nodal fields after a step (state variables included: they must stay
  !> finite); returns '' when all is well, otherwise a message naming the step, the particle or
  !> node and the quantity.
  function empm_check_guards(model, where, node) result(msg)
    type(empm_model_t), intent(in) :: model !! simulation state
    integer, intent(out), optional :: where !! id of the particle it names; huge(1) for a node
                                            !! or no problem
    integer, intent(out), optional :: node  !! the node it names (the whole grid's number);
                                            !! huge(1) for a particle or no problem
    character(len=:), allocatable :: msg    !! '' or the first problem found
    integer :: p, I, G, ijk(3)
    msg = ''
    if (present(where)) where = huge(1)
    if (present(node)) node = huge(1)
    associate (pts => model%pts)
      do p = 1, pts%np
        if (.not. all(ieee_is_finite(pts%x(:, p)))) then
          msg = 'non-finite position'
        else if (.not. all(ieee_is_finite(pts%v(:, p)))) then
          msg = 'non-finite velocity'
        else if (.not. all(ieee_is_finite(pts%a(:, p)))) then
          msg = 'non-finite acceleration'
        else if (.not. all(ieee_is_finite(pts%stress(:, p)))) then
          msg = 'non-finite stress'
        else if (.not. all(ieee_is_finite(pts%strain(:, p)))) then
          msg = 'non-finite strain'
        else if (.not. all(ieee_is_finite(pts%state(:, p)))) then
          msg = 'non-finite state variable '//state_label(p)
        else if (.not. (ieee_is_finite(pts%rho(p)) .and. pts%rho(p) > 0.0_wp)) then
          msg = 'non-finite or non-positive density'
        else if (.not. (ieee_is_finite(pts%vol(p)) .and. pts%vol(p) > 0.0_wp)) then
          msg = 'non-finite or non-positive volume'
        end if
        if (len(msg) > 0) then
          msg = 'step '//str(model%step)//': '//msg//' at particle '//str(model%pts%id(p))
          if (present(where)) where = model%pts%id(p)
          return
        end if
        if (.not. model%grid%inside(pts%x(:, p))) then
          msg = 'step '//str(model%step)//': particle '//str(model%pts%id(p))// &
            ' left the grid: x = '//vec(pts%x(:, p))
          if (present(where)) where = model%pts%id(p)
          return
        end if
        ! The ghost side of a mirror plane stands for the body's image: no particle may enter it.
        do I = 1, model%nodes%nplane
          if (sign(1.0_wp, real(model%nodes%plane_side(I), wp)) * (pts%x(abs(model%nodes% &
              plane_side(I)), p) - model%nodes%plane_at(I)) > &
              1.0e-9_wp * model%grid%h(abs(model%nodes%plane_side(I)))) then
            msg = 'step '//str(model%step)//': particle '//str(model%pts%id(p))// &
              ' crossed the mirror plane at '//str(model%nodes%plane_at(I))//' m: x = '// &
              vec(pts%x(:, p))
            if (present(where)) where = model%pts%id(p)
            return
          end if
        end do
      end do
    end associate
    do I = 1, model%nodes%nnode
      ! A parallel run's nodes are complete only where this process's particles reach.
      if (.not. model%halo%in_core(model%grid, I)) cycle
      ! Named by the whole grid's number (a parallel process stores a window of the grid).
      ijk = model%grid%node_ijk(I)
      G = 1 + ijk(1) + model%grid%nn(1) * (ijk(2) + model%grid%nn(2) * ijk(3))
      if (.not. all(ieee_is_finite(model%nodes%vel(:, I)))) then
        msg = 'step '//str(model%step)//': non-finite nodal velocity at node '//str(G)
      else if (.not. all(ieee_is_finite(model%nodes%acc(:, I)))) then
        msg = 'step '//str(model%step)//': non-finite nodal acceleration at node '//str(G)
      end if
      if (len(msg) > 0) then
        if (present(node)) node = G
        return
      end if
    end do
  contains
    ! 'k' or, when the particle's material names its row k, 'k (name)'.
    function state_label(p) result(t)
      use empm_material, only: STATE_NAME_LEN
      integer, intent(in) :: p
      character(len=:), allocatable :: t
      character(len=STATE_NAME_LEN), allocatable :: names(:)
      integer :: k, im
      k = findloc(ieee_is_finite(model%pts%state(:, p)), .false., dim=1)
      t = str(k)
      im = model%pts%mat(p)
      if (.not. allocated(model%mats)) return
      if (im < 1 .or. im > size(model%mats)) return
      call model%mats(im)%model%state_names(names)
      if (k <= size(names)) t = t//' ('//trim(names(k))//')'
    end function state_label
  end function empm_check_guards

  !> One line for the end of a run: steps, time-step range, wall time and energy balance, e.g.
  !> `120 steps to t = 5.0E-01 s, dt 4.1E-03..4.2E-03 s, wall 0.01 s; energy 1.0E-03 -> 1.0E-03 J
  !> (drift -2.1E-06)` (`wall 0.01 s, set-up 0.02 s` when the driver measured its set-up), with `, gravity ramp work W J` before the drift when gravity varies.
  !> The drift is (E_final − E_initial − W) / max(|E_initial|, |E_final|, |W|) of the total
  !> energy (kinetic + strain + gravity potential); work done by prescribed non-zero boundary
  !> velocities is not subtracted and shows in it. A run that tracked its residual (model%track)
  !> ends with `; residual R`, its last value.
  function empm_run_summary(st) result(s)
    type(empm_run_stats_t), intent(in) :: st !! statistics of a run
    character(len=:), allocatable :: s       !! the line (no trailing newline)
    character(len=40) :: a, b, c, e0, e1, w, drift, su
    real(wp) :: scale
    write(a, '(es10.3)') st%t_reached
    write(b, '(es10.3)') st%dt_min
    write(c, '(es10.3)') st%dt_max
    write(w, '(f12.2)') st%wall
    if (st%setup >= 0.0_wp) then
      write(su, '(f12.2)') st%setup
      w = trim(adjustl(w))//' s, set-up '//trim(adjustl(su))
    end if
    scale = max(abs(st%energy_initial), abs(st%energy_final), abs(st%work_gravity))
    if (scale > 0.0_wp) then
      write(drift, '(es10.2)') (st%energy_final - st%energy_initial - st%work_gravity) / scale
    else
      drift = '0'
    end if
    write(e0, '(es12.5)') st%energy_initial
    write(e1, '(es12.5)') st%energy_final
    s = str(st%steps)//' steps to t = '//trim(adjustl(a))//' s, dt '//trim(adjustl(b))//'..'// &
      trim(adjustl(c))//' s, wall '//trim(adjustl(w))//' s; energy '//trim(adjustl(e0))// &
      ' -> '//trim(adjustl(e1))//' J'
    if (st%work_gravity /= 0.0_wp) then
      write(e0, '(es12.5)') st%work_gravity
      s = s//', gravity ramp work '//trim(adjustl(e0))//' J'
    end if
    s = s//' (drift '//trim(adjustl(drift))//')'
    if (st%tracked) then
      write(e0, '(es10.3)') st%residual
      s = s//'; residual '//trim(adjustl(e0))
    end if
    if (st%nranks > 1) then
      write(e0, '(f8.3)') st%imbalance
      write(e1, '(f8.3)') st%imbalance_static
      s = s//'; '//str(st%nranks)//' processes, '//str(st%rebalances)//' re-cuts, particles '// &
        'per process at most '//trim(adjustl(e0))//' x the mean (never re-cut: '// &
        trim(adjustl(e1))//')'
      write(e0, '(es10.3)') st%halo_bytes
      s = s//', '//str(st%migrated)//' particles migrated, halo '//trim(adjustl(e0))// &
        ' bytes per step, grid nodes stored per process at most '//str(st%stored_nodes)// &
        ' of '//str(st%grid_nodes)//' ('//str(st%windows)//' windows)'
    end if
    if (st%peak_memory > 0.0_wp) then
      write(e0, '(f12.1)') st%peak_memory / 2.0_wp**20
      s = s//'; peak memory '//trim(adjustl(e0))//' MiB'
      if (st%nranks > 1) s = s//' per process at most'
    end if
  end function empm_run_summary

  pure function vec(x) result(s)
    real(wp), intent(in) :: x(:)
    character(len=:), allocatable :: s
    s = '('//join(x, ', ')//')'
  end function vec
end module empm_solver
