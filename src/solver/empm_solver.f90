!> The explicit time loop: CFL time step, stepping, run-time guards, histories, progress.
module empm_solver
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_INT
  use empm_error, only: empm_error_t, empm_raise, empm_raise_error, empm_alloc_error, &
                        EMPM_ERR_RUNTIME, EMPM_ERR_USAGE
  use empm_strings, only: str, join
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK, STEP_SHAPE_FAILED
  use empm_integrator, only: empm_integrator_t
  use empm_particles, only: empm_particles_t
  use empm_history, only: empm_history_t
  use empm_shape, only: shape_status_text, SHAPE_OUTSIDE_GRID
  use empm_terminal, only: stderr_is_terminal
  implicit none
  private
  public :: empm_run_params
  public :: empm_run_config_t, empm_solve, empm_stable_dt, empm_energies, empm_check_guards

  !> How to run: end time, time step control, output sampling.
  type :: empm_run_config_t
    real(wp) :: t_end = 0.0_wp                 !! end time [s]
    real(wp) :: cfl = 0.5_wp                   !! Courant number, Δt = cfl·h/c_max
    real(wp) :: dt = 0.0_wp                    !! fixed time step [s]; 0 = use cfl
    integer :: max_steps = huge(1)             !! safety cap on the number of steps
    integer :: history_every = 1               !! record energies and probes every n steps
    real(wp), allocatable :: snapshot_times(:) !! times at which to store snapshots [s]
    logical :: progress = .true.               !! progress line on stderr (terminals only)
  end type empm_run_config_t

contains

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
  !> particles (wave speeds are non-increasing in density, so each material run is evaluated
  !> once, at its smallest density).
  function empm_stable_dt(model) result(dt)
    type(empm_model_t), intent(in) :: model !! simulation state
    real(wp) :: dt                          !! critical time step [s]
    real(wp) :: cmax, c
    integer :: r, i0, i1
    cmax = 0.0_wp
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      c = model%mats(model%pts%mat(i0))%model%wave_speed(minval(model%pts%rho(i0:i1)))
      cmax = max(cmax, c)
    end do
    dt = model%grid%hmin() / cmax
  end function empm_stable_dt

  !> Kinetic energy, stored (elastic) energy and gravitational potential of the particles.
  subroutine empm_energies(model, psi, ekin, estrain, egrav)
    type(empm_model_t), intent(in) :: model !! simulation state
    real(wp), intent(inout) :: psi(:)       !! scratch, size >= np
    real(wp), intent(out) :: ekin           !! Σ ½ m |v|² [J]
    real(wp), intent(out) :: estrain        !! Σ V ψ [J]
    real(wp), intent(out) :: egrav          !! −Σ m g(t)·x [J]
    real(wp) :: g(3)
    integer :: r, i0, i1, np, d
    np = model%pts%np; d = model%grid%ndim
    ekin = 0.5_wp * sum(model%pts%m(1:np) * sum(model%pts%v(:, 1:np)**2, dim=1))
    estrain = 0.0_wp
    do r = 1, size(model%run_first)
      i0 = model%run_first(r); i1 = model%run_last(r)
      call model%mats(model%pts%mat(i0))%model%energy_density(model%pts%F(:, :, i0:i1), &
        model%pts%strain(:, i0:i1), model%pts%stress(:, i0:i1), model%pts%state(:, i0:i1), &
        psi(i0:i1))
      estrain = estrain + sum(model%pts%vol(i0:i1) * psi(i0:i1))
    end do
    g = model%loads%gravity_at(model%t)
    egrav = -sum(model%pts%m(1:np) * matmul(g(1:d), model%pts%x(:, 1:np)))
  end subroutine empm_energies

  !> Run `model` with `integ` until `cfg%t_end`. Records energies, probes and snapshots in
  !> `hist`. On a tripped guard the model is restored to the last good state and the error
  !> (code EMPM_ERR_RUNTIME) names the step, the particle or node and the quantity.
  subroutine empm_solve(model, integ, cfg, hist, err)
    type(empm_model_t), intent(inout) :: model                !! simulation (set up)
    class(empm_integrator_t), intent(inout) :: integ          !! time integrator
    type(empm_run_config_t), intent(in) :: cfg                !! run controls
    type(empm_history_t), intent(inout) :: hist               !! record (initialised by caller)
    type(empm_error_t), intent(out), optional :: err          !! error, if present
    type(empm_particles_t) :: good
    type(empm_step_status_t) :: stat
    real(wp), allocatable :: psi(:)
    real(wp) :: dt, dt_stable, ekin, estr, egrav, t_good, t_next_snap
    integer :: isnap, nsnap, step_good
    integer(int64) :: clock0, clock_last, clock, rate
    logical :: show
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
    call integ%prepare(model, e)
    if (e%code == 0) call good%alloc(model%grid%ndim, model%pts%np, model%pts%nstate, e)
    if (e%code == 0) then
      allocate(psi(model%pts%np), stat=astat, errmsg=amsg)
      if (astat /= 0) e = empm_alloc_error('energy scratch', 8_int64 * model%pts%np, amsg)
    end if
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    nsnap = 0
    if (allocated(cfg%snapshot_times)) nsnap = size(cfg%snapshot_times)
    isnap = 1
    call empm_energies(model, psi, ekin, estr, egrav)
    call hist%add_sample(model%t, ekin, estr, egrav, model%pts)
    call skip_past_snapshots()
    show = .false.
    if (cfg%progress) show = stderr_is_terminal()
    call system_clock(clock0, rate); clock_last = clock0

    do while (model%t < cfg%t_end * (1.0_wp - 1.0e-12_wp))
      if (model%step >= cfg%max_steps) then
        call fail('the step cap max_steps = '//str(cfg%max_steps)//' was reached at t = '// &
                  str(model%t)//' s before t_end'); return
      end if
      dt_stable = empm_stable_dt(model)
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

      call good%copy_state_from(model%pts)
      t_good = model%t; step_good = model%step
      call integ%step(model, dt, stat)
      model%step = model%step + 1
      if (stat%code /= STEP_OK) then
        msg = describe_status(stat)
        call restore(); call fail(msg, stat%particle); return
      end if
      model%t = model%t + dt
      msg = empm_check_guards(model)
      if (len(msg) > 0) then
        call restore(); call fail(msg); return
      end if

      if (mod(model%step, cfg%history_every) == 0 .or. model%t >= cfg%t_end) then
        call empm_energies(model, psi, ekin, estr, egrav)
        call hist%add_sample(model%t, ekin, estr, egrav, model%pts)
      end if
      call skip_past_snapshots()
      if (show) call progress()
    end do
    if (show) write(error_unit, '(a)') ''

  contains

    subroutine skip_past_snapshots()
      do while (isnap <= nsnap)
        if (cfg%snapshot_times(isnap) > model%t * (1.0_wp + 1.0e-12_wp) + tiny(1.0_wp)) exit
        call hist%add_snapshot(model%t, model%step, model%pts)
        isnap = isnap + 1
      end do
    end subroutine skip_past_snapshots

    subroutine restore()
      call model%pts%copy_state_from(good)
      model%t = t_good; model%step = step_good
    end subroutine restore

    ! The run-time error: the text already names the step (and the particle or node); the
    ! fields carry them for programs.
    subroutine fail(text, particle)
      character(len=*), intent(in) :: text
      integer, intent(in), optional :: particle
      type(empm_error_t) :: ef
      if (show) write(error_unit, '(a)') ''
      ef%code = EMPM_ERR_RUNTIME; ef%message = text; ef%step = model%step + 1
      if (present(particle)) ef%particle = particle
      call empm_raise_error(ef, err)
    end subroutine fail

    subroutine progress()
      real(wp) :: elapsed, sps, eta
      character(len=160) :: line
      call system_clock(clock)
      if (real(clock - clock_last, wp) < 0.5_wp * real(rate, wp) .and. model%t < cfg%t_end) return
      clock_last = clock
      elapsed = real(clock - clock0, wp) / real(rate, wp)
      sps = real(model%step, wp) / max(elapsed, 1.0e-9_wp)
      eta = elapsed * (cfg%t_end - model%t) / max(model%t, tiny(1.0_wp))
      write(line, '(a,es10.3,a,es10.3,a,i0,a,f10.1,a,f8.1,a)') 't = ', model%t, ' / ', &
        cfg%t_end, ' s  step ', model%step, '  ', sps, ' steps/s  ETA ', eta, ' s'
      write(error_unit, '(a)', advance='no') achar(13)//trim(line)
      flush(error_unit)
    end subroutine progress

    function describe_status(s) result(text)
      type(empm_step_status_t), intent(in) :: s
      character(len=:), allocatable :: text
      integer :: p
      p = max(1, min(s%particle, model%pts%np))
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

  !> Check particle and nodal fields after a step (state variables included: they must stay
  !> finite); returns '' when all is well, otherwise a message naming the step, the particle or
  !> node and the quantity.
  function empm_check_guards(model) result(msg)
    type(empm_model_t), intent(in) :: model !! simulation state
    character(len=:), allocatable :: msg    !! '' or the first problem found
    integer :: p, I
    msg = ''
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
          msg = 'step '//str(model%step)//': '//msg//' at particle '//str(p)
          return
        end if
        if (.not. model%grid%inside(pts%x(:, p))) then
          msg = 'step '//str(model%step)//': particle '//str(p)//' left the grid: x = '// &
            vec(pts%x(:, p))
          return
        end if
      end do
    end associate
    do I = 1, model%nodes%nnode
      if (.not. all(ieee_is_finite(model%nodes%vel(:, I)))) then
        msg = 'step '//str(model%step)//': non-finite nodal velocity at node '//str(I)
        return
      end if
      if (.not. all(ieee_is_finite(model%nodes%acc(:, I)))) then
        msg = 'step '//str(model%step)//': non-finite nodal acceleration at node '//str(I)
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

  pure function vec(x) result(s)
    real(wp), intent(in) :: x(:)
    character(len=:), allocatable :: s
    s = '('//join(x, ', ')//')'
  end function vec
end module empm_solver
