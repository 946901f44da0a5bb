!> The performance benchmark behind `empm bench` (docs/performance.md): an elastic block
!> vibrating freely, stepped with a chosen shape family and integrator, timed after a warm-up,
!> with phase timers, Newton iterations and resident memory per particle.
!>
!> The block fills `cells`^dim cells of size 1/cells (unit box), with `ppc` particles per cell
!> at Gauss positions (`ppc` a perfect square in 2D, cube in 3D). The grid gets the padding
!> cells the family asks for on every side (`shape%padding_cells()`: uGIMP and B-splines 1), so
!> the particle count never depends on the family. The shape and the scheme are named as in a
!> case file (`lme_g3`, `pc_newmark`) and created through the registry: nothing here knows a
!> family. The initial velocity is a smooth standing-wave field of
!> small amplitude (nothing is fixed, unless the block starts confined: then it stands between
!> smooth rigid walls, so that it stays confined); Δt is half the CFL limit.
!> The timed loop calls the integrator's `step` only: no guards, no last-good copy, no output.
!>
!> The material is any registered model (`--material`, default linear_elastic) with the bench's
!> elastic constants (the keys `E`, `nu`, `density` a model declares), the model's bench
!> defaults (soil models: a strength that the block's vibration exceeds, so that the bench
!> times plastic updates; [[bench_material_keys]]) and the user's `--material-keys`, which
!> replace defaults of the same name. For a model with state variables the fraction of
!> particle updates that changed a state variable (a plastic update, for the plasticity
!> models) is reported; it is counted between the timed steps, outside the timing.
module empm_bench
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp, pi
  use empm_error, only: empm_error_t, empm_raise, EMPM_ERR_USAGE, EMPM_ERR_RUNTIME
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK, STEP_MATERIAL_FAILED
  use empm_particle_gen, only: empm_fill, GEOM_BOX, PLACE_GAUSS
  use empm_namelist, only: empm_kv
  use empm_registry, only: empm_create_shape, empm_create_material, empm_create_integrator, &
                           empm_registry_t, empm_default_registry
  use empm_params, only: empm_param_t
  use empm_integrator, only: empm_integrator_t
  use empm_solver, only: empm_stable_dt
  use empm_timer, only: PHASE_COUNT, PHASE_NAMES
  use empm_parallel, only: empm_set_threads, empm_max_threads
  use empm_strings, only: str, lower
  use empm_files, only: empm_proc_kib, empm_peak_memory
  use empm_case, only: empm_case_t
  use empm_input, only: empm_read_case
  implicit none
  private
  public :: empm_bench_config_t, empm_bench_result_t, empm_bench_run, empm_bench_json

  real(wp), parameter :: BENCH_E = 1.0e7_wp     !! Young's modulus [Pa]
  real(wp), parameter :: BENCH_NU = 0.3_wp      !! Poisson's ratio
  real(wp), parameter :: BENCH_RHO = 1000.0_wp  !! density [kg/m³]
  real(wp), parameter :: BENCH_V0 = 0.1_wp      !! velocity amplitude [m/s] (~1e-3 of c)

  !> What to run.
  type :: empm_bench_config_t
    integer :: dim = 2                              !! spatial dimension, 2 or 3
    character(len=32) :: shape = 'linear'           !! shape identifier, e.g. linear, lme_g3
    integer :: cells = 64                           !! cells per direction of the block
    integer :: ppc = 4                              !! particles per cell (a perfect power)
    integer :: steps = 50                           !! timed steps
    integer :: warmup = 3                           !! untimed steps first
    integer :: threads = 1                          !! OpenMP threads
    character(len=32) :: integrator = 'pc_newmark'  !! scheme name, as in a case file
    character(len=32) :: material = 'linear_elastic' !! material model, a registry name
    character(len=512) :: material_keys = ''         !! 'key = value, ...' replacing defaults
    real(wp) :: confinement = -1.0_wp                !! initial isotropic compression p0 [Pa]
                                                     !! (< 0: the model's bench default)
    real(wp) :: min_fill = -1.0_wp                   !! `&grid min_fill` (< 0: the default)
    character(len=16) :: motion = 'vibrate'          !! 'vibrate': the standing wave, the
                                                     !! particles barely move; 'rotate': the
                                                     !! block spins about its centre (axis z),
                                                     !! its corners crossing a cell every ~20
                                                     !! steps, on a grid a quarter larger
                                                     !! on every side
    character(len=1024) :: case_file = ''            !! time this case file's model instead of
                                                     !! the block ('': the block); the other
                                                     !! fields but steps, warmup and threads
                                                     !! are then unused
  end type empm_bench_config_t

  !> What was measured (the JSON of `empm bench`, plus a checksum for tests).
  type :: empm_bench_result_t
    integer :: dim = 0                                  !! spatial dimension
    character(len=:), allocatable :: shape              !! family identifier, e.g. lme_g3
    character(len=:), allocatable :: integrator         !! scheme identifier
    character(len=:), allocatable :: material           !! material model
    character(len=:), allocatable :: material_keys      !! the keys it was created with
    real(wp) :: confinement = 0.0_wp                    !! initial isotropic compression [Pa]
    character(len=:), allocatable :: motion             !! 'vibrate', 'rotate' or 'case'
    real(wp) :: plastic_fraction = 0.0_wp               !! particle updates that changed a
                                                        !! state variable / all (timed steps)
    integer :: particles = 0                            !! particles
    integer :: nodes = 0                                !! grid nodes
    integer :: steps = 0                                !! timed steps
    integer :: threads = 1                              !! threads actually available
    real(wp) :: seconds = 0.0_wp                        !! wall time of the timed steps [s]
    real(wp) :: particle_steps_per_second = 0.0_wp      !! particles × steps / seconds
    real(wp) :: newton_iterations_mean = 0.0_wp         !! per particle-step (LME; else 0)
    real(wp) :: travel_cells = 0.0_wp                   !! mean net displacement of a particle
                                                        !! over the timed steps, in cells
                                                        !! (sampled)
    real(wp) :: bytes_per_particle = 0.0_wp             !! (peak RSS − baseline) / particles
    real(wp) :: phase_seconds(PHASE_COUNT) = 0.0_wp     !! shape, p2g, grid, g2p, stress [s]
    real(wp) :: checksum = 0.0_wp                       !! Σ|x| + Σ|v|/v0 + Σ|σ|/E at the end
  end type empm_bench_result_t

contains

  !> Build the block (or read `cfg%case_file`), warm up, time `cfg%steps` steps. `err%code` is
  !> EMPM_ERR_USAGE for a bad configuration (a case file's own input error code for a bad case)
  !> and EMPM_ERR_RUNTIME when a step fails.
  subroutine empm_bench_run(cfg, res, err)
    type(empm_bench_config_t), intent(in) :: cfg     !! configuration
    type(empm_bench_result_t), intent(out) :: res    !! measurements
    type(empm_error_t), intent(out), optional :: err !! error, if present
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_error_t) :: e
    real(wp) :: zero3(3), hi(3), origin(3), h(3), dt, s, p0, lo3(3), hi3(3)
    logical :: fixk(3)
    integer :: nfix
    integer :: nper, pad, nd, info, nadd, p, d, k, ncell(3)
    integer(int64) :: rss0
    character(len=:), allocatable :: mkeys

    if (len_trim(cfg%case_file) > 0) then
      call bench_case(cfg, res, err); return
    end if
    nd = cfg%dim
    if (nd < 2 .or. nd > 3) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --dim must be 2 or 3', err); return
    end if
    nper = nint(real(cfg%ppc, wp)**(1.0_wp / nd))
    if (nper < 1 .or. nper > 4 .or. nper**nd /= cfg%ppc) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --ppc '//str(cfg%ppc)//' is not n**'// &
        str(nd)//' with n in 1..4 (particles per cell, e.g. 4 or 9 in 2D, 8 or 27 in 3D)', err)
      return
    end if
    if (cfg%cells < 2 .or. cfg%steps < 1 .or. cfg%warmup < 0 .or. cfg%threads < 1) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: need --cells >= 2, --steps >= 1, --threads >= 1', &
                      err); return
    end if
    call empm_set_threads(cfg%threads)
    rss0 = empm_peak_memory()

    ! The family first (on a provisional grid: only the dimension matters), for its padding.
    h = 1.0_wp / cfg%cells
    call model%grid%init(nd, [(0.0_wp, k = 1, nd)], h(1:nd), [(cfg%cells, k = 1, nd)], info)
    call empm_create_shape(trim(cfg%shape), model%grid, model%shape, e)
    if (e%code /= 0) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --shape: '//e%message, err); return
    end if
    if (cfg%motion /= 'vibrate' .and. cfg%motion /= 'rotate') then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --motion must be vibrate or rotate, not '// &
        trim(cfg%motion), err); return
    end if
    pad = model%shape%padding_cells()
    ! A rotating block sweeps the disk of radius √2/2 about (½, ½): a quarter more grid on
    ! every side holds it while it turns through 45°.
    if (cfg%motion == 'rotate') pad = pad + (cfg%cells + 3) / 4
    origin = -pad * h
    ncell = cfg%cells + 2 * pad
    call model%grid%init(nd, origin(1:nd), h(1:nd), ncell(1:nd), info)
    if (info /= 0) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: invalid grid', err); return
    end if
    call empm_create_integrator(trim(cfg%integrator), integ, e)
    if (e%code /= 0) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --integrator: '//e%message, err); return
    end if
    allocate(model%mats(1))
    call bench_material_keys(trim(cfg%material), trim(cfg%material_keys), mkeys, e)
    if (e%code == 0) call empm_create_material(trim(cfg%material), mkeys, model%mats(1)%model, e)
    if (e%code /= 0) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: --material '//trim(cfg%material)//': '// &
                      e%message, err); return
    end if
    ! Exact capacity: no geometric growth (it would double the footprint being measured).
    call model%pts%alloc(nd, cfg%ppc * cfg%cells**nd)
    zero3 = 0.0_wp; hi = 0.0_wp; hi(1:nd) = 1.0_wp
    call empm_fill(model%pts, model%grid, GEOM_BOX, zero3, hi, zero3, 0.0_wp, nper, &
                   PLACE_GAUSS, BENCH_RHO, 1, nadd, info)
    if (info /= 0) then
      call empm_raise(EMPM_ERR_USAGE, 'bench: particle generation failed', err); return
    end if
    ! Initial stress σ = −p0 I (camclay needs a confinement: its stiffness is proportional to p').
    p0 = cfg%confinement
    if (p0 < 0.0_wp) p0 = bench_confinement(trim(cfg%material))
    do p = 1, model%pts%np
      model%pts%stress(1:3, p) = -p0
    end do
    ! Rotation about the block's axis (x, y) = (½, ½): v = ω ẑ × (x − c), corner speed
    ! 0.1 c_P (the material's wave speed, 116 m/s for the bench's elastic block): a corner
    ! crosses a cell every ~20 steps at Δt = ½ h/c_P.
    if (cfg%motion == 'rotate') then
      s = 0.1_wp * model%mats(1)%model%wave_speed(BENCH_RHO) / sqrt(0.5_wp)
      do p = 1, model%pts%np
        model%pts%v(:, p) = 0.0_wp
        model%pts%v(1, p) = -s * (model%pts%x(2, p) - 0.5_wp)
        model%pts%v(2, p) = s * (model%pts%x(1, p) - 0.5_wp)
      end do
    end if
    ! Standing wave: component d varies as sin(π(d+k)x_k)-like products, zero on the faces.
    if (cfg%motion == 'vibrate') then
      do p = 1, model%pts%np
        do d = 1, nd
          s = BENCH_V0
          do k = 1, nd
            s = s * sin(pi * model%pts%x(k, p) * merge(2.0_wp, 1.0_wp, k == d))
          end do
          model%pts%v(d, p) = s
        end do
      end do
    end if
    ! A confined block must stay confined: a free block under −p0 I is not in equilibrium and
    ! would expand (a Cam-Clay block by far more than the grid). The walls x_k = 0 and 1 are
    ! smooth and rigid (normal velocity 0; the standing wave's normal component vanishes there).
    if (p0 > 0.0_wp) then
      do k = 1, nd
        lo3 = -1.0e30_wp; hi3 = 1.0e30_wp; hi3(k) = 0.0_wp
        fixk = .false.; fixk(k) = .true.
        call model%nodes%fix_box(model%grid, lo3, hi3, fixk, zero3, nfix)
        lo3 = -1.0e30_wp; hi3 = 1.0e30_wp; lo3(k) = 1.0_wp
        call model%nodes%fix_box(model%grid, lo3, hi3, fixk, zero3, nfix)
      end do
    end if
    call model%finalize_setup()
    if (cfg%min_fill >= 0.0_wp) model%nodes%ext%theta = cfg%min_fill
    call integ%prepare(model)
    dt = 0.5_wp * empm_stable_dt(model)
    call time_steps(model, integ, dt, cfg, rss0, res, err)
    if (allocated(res%shape)) then
      res%motion = trim(cfg%motion)
      res%material = trim(cfg%material)
      res%material_keys = mkeys
      res%confinement = p0
    end if
  end subroutine empm_bench_run

  !> Warm up, then time `cfg%steps` steps of `integ` on `model` (prepared) with the fixed time
  !> step `dt`, each step alone (the state comparison for the plastic fraction stays outside the
  !> timing), and fill `res`: `res%shape` stays unallocated when a step failed (`err` set).
  subroutine time_steps(model, integ, dt, cfg, rss0, res, err)
    type(empm_model_t), intent(inout) :: model           !! set-up model
    class(empm_integrator_t), intent(inout) :: integ     !! prepared integrator
    real(wp), intent(in) :: dt                           !! time step [s]
    type(empm_bench_config_t), intent(in) :: cfg         !! steps and warm-up steps
    integer(int64), intent(in) :: rss0                   !! peak RSS before the set-up [B]
    type(empm_bench_result_t), intent(inout) :: res      !! measurements
    type(empm_error_t), intent(inout), optional :: err   !! a failed step
    type(empm_step_status_t) :: stat
    integer(int64) :: rss1, c0, c1, rate, ticks, nchanged
    real(wp), allocatable :: state0(:,:), x0(:,:)
    integer :: k, stride

    do k = 1, cfg%warmup
      call advance()
      if (stat%code /= STEP_OK) return
    end do
    call integ%timer%reset()
    ticks = 0; nchanged = 0
    if (model%pts%nstate > 0) allocate(state0(model%pts%nstate, model%pts%np))
    ! The net displacement, on every (np/1024)-th particle (1024 to 2047 of them; all below
    ! 1024): a copy of every position would add to the peak memory `bytes_per_particle` reports.
    stride = max(1, model%pts%np / 1024)
    x0 = model%pts%x(:, 1:model%pts%np:stride)
    do k = 1, cfg%steps
      if (allocated(state0)) state0 = model%pts%state(:, 1:model%pts%np)
      call system_clock(c0, rate)
      call advance()
      call system_clock(c1)
      ticks = ticks + (c1 - c0)
      if (stat%code /= STEP_OK) return
      if (allocated(state0)) nchanged = nchanged + &
        count(any(state0 /= model%pts%state(:, 1:model%pts%np), dim=1))
    end do
    rss1 = empm_peak_memory()

    res%dim = model%grid%ndim
    res%shape = model%shape%name()
    res%integrator = integ%name()
    res%particles = model%pts%np
    res%nodes = model%grid%nnode
    res%steps = cfg%steps
    res%threads = empm_max_threads()
    res%plastic_fraction = real(nchanged, wp) / (real(model%pts%np, wp) * cfg%steps)
    res%seconds = real(ticks, wp) / real(rate, wp)
    res%particle_steps_per_second = real(res%particles, wp) * cfg%steps / max(res%seconds, 1.0e-9_wp)
    if (integ%timer%basis_evals > 0) res%newton_iterations_mean = &
      real(integ%timer%newton_iters, wp) / real(integ%timer%basis_evals, wp)
    if (rss0 > 0 .and. rss1 > 0) res%bytes_per_particle = real(rss1 - rss0, wp) / res%particles
    res%phase_seconds = integ%timer%seconds
    if (size(x0, 2) > 0) res%travel_cells = sum(sqrt(sum((model%pts%x(:, 1:model%pts%np:stride) &
      - x0)**2, dim=1))) / (size(x0, 2) * model%grid%hmin())
    associate (np => model%pts%np)
      res%checksum = sum(abs(model%pts%x(:, 1:np))) + sum(abs(model%pts%v(:, 1:np))) / BENCH_V0 &
                     + sum(abs(model%pts%stress(:, 1:np))) / BENCH_E
    end associate

  contains

    subroutine advance()
      call integ%step(model, dt, stat)
      if (stat%code /= STEP_OK) then
        if (stat%code == STEP_MATERIAL_FAILED .and. stat%detail >= 1 .and. &
            stat%detail <= size(model%mats)) then
          call empm_raise(EMPM_ERR_RUNTIME, 'bench: step '//str(model%step + 1)// &
            ' failed at particle '//str(stat%particle)//': '// &
            model%mats(stat%detail)%model%failure_text(), err)
        else
          call empm_raise(EMPM_ERR_RUNTIME, 'bench: step '//str(model%step + 1)// &
            ' failed at particle '//str(stat%particle)//' (status '//str(stat%detail)//')', err)
        end if
        return
      end if
      model%t = model%t + dt
      model%step = model%step + 1
    end subroutine advance
  end subroutine time_steps

  !> `empm bench --case FILE`: the case's model, integrator and time step (its `dt`, or `cfl`
  !> times the stable step at the start), timed as the block is: the integrator's steps alone,
  !> without the guards, the history, the snapshots and the output of `empm run FILE`.
  subroutine bench_case(cfg, res, err)
    type(empm_bench_config_t), intent(in) :: cfg     !! configuration (case_file set)
    type(empm_bench_result_t), intent(out) :: res    !! measurements
    type(empm_error_t), intent(out), optional :: err !! error, if present
    type(empm_case_t) :: cs
    type(empm_error_t) :: e
    integer(int64) :: rss0
    real(wp) :: dt
    call empm_set_threads(cfg%threads)
    rss0 = empm_peak_memory()
    call empm_read_case(trim(cfg%case_file), cs, e)
    if (e%code == 0) call cs%integ%prepare(cs%model, e)
    if (e%code /= 0) then
      call empm_raise(e%code, 'bench: --case: '//e%message, err); return
    end if
    dt = cs%run%dt
    if (dt <= 0.0_wp) dt = cs%run%cfl * empm_stable_dt(cs%model)
    call time_steps(cs%model, cs%integ, dt, cfg, rss0, res, err)
    if (.not. allocated(res%shape)) return
    res%material = cs%model%mats(1)%model%family()
    res%motion = 'case'
    res%material_keys = ''
    res%confinement = 0.0_wp
  end subroutine bench_case

  !> The bench's default initial isotropic compression p0 of `name` [Pa]: camclay 1e4 Pa (its
  !> elastic stiffness K = v p'/κ vanishes with p'; with OCR = 1 the block starts on the yield
  !> surface, so its vibration loads it plastically), 0 for the other models. The block's faces are free:
  !> they unload, and the corner particle fails after ~8 steps (a camclay weakness reported).
  pure real(wp) function bench_confinement(name)
    character(len=*), intent(in) :: name !! registry name
    bench_confinement = merge(1.0e4_wp, 0.0_wp, name == 'camclay')
  end function bench_confinement

  !> The keys of the bench material: the bench's `E`, `nu`, `density` where the model declares
  !> them, the model's bench defaults, then `user` ('key = value, ...'), whose keys replace
  !> defaults of the same name. Bench defaults: mohr_coulomb and drucker_prager c = 500 Pa,
  !> φ = 30°, ψ = 5° (the block's stresses reach ~1e4 Pa from zero, so most of it yields; the
  !> cut-off is the apex value, ~870 Pa, and the block has no confinement: shear, cut-off and
  !> apex returns all occur); camclay λ = 0.2, κ = 0.04, M = 1.2, e0 = 1, OCR = 1 (ν = the bench's 0.3; with
  !> the initial compression of [[bench_confinement]]).
  subroutine bench_material_keys(name, user, keys, err)
    character(len=*), intent(in) :: name                !! registry name
    character(len=*), intent(in) :: user                !! user keys ('' for none)
    character(len=:), allocatable, intent(out) :: keys  !! the keys to create it with
    type(empm_error_t), intent(inout) :: err            !! set for an unknown model
    type(empm_registry_t) :: reg
    type(empm_param_t), allocatable :: p(:)
    character(len=:), allocatable :: dflt
    integer :: k, im
    reg = empm_default_registry()
    im = 0
    do k = 1, size(reg%materials)
      if (reg%materials(k)%proto%family() == name) im = k
    end do
    keys = user
    if (im == 0) return  ! creating it reports the unknown model with the valid names
    allocate(p, source=reg%materials(im)%proto%params())
    dflt = ''
    do k = 1, size(p)
      select case (p(k)%name)
      case ('E');       call add(empm_kv('E', BENCH_E))
      case ('nu');      call add(empm_kv('nu', BENCH_NU))
      case ('density'); call add(empm_kv('density', BENCH_RHO))
      end select
    end do
    select case (name)
    case ('mohr_coulomb', 'drucker_prager')
      call add('cohesion = 500'); call add('friction_angle = 30'); call add('dilatancy_angle = 5')
    case ('camclay')
      call add('lambda = 0.2'); call add('kappa = 0.04'); call add('M = 1.2'); call add('e0 = 1')
      if (.not. (has_key(user, 'pc0'))) call add('ocr = 1')
    end select
    associate (unused_ => err); end associate
  contains
    ! Add 'key = value' unless the user's keys name the key.
    subroutine add(kv)
      character(len=*), intent(in) :: kv
      character(len=:), allocatable :: key, item
      item = trim(kv)
      if (item(len(item):) == ',') item = item(1:len(item) - 1)  ! empm_kv's separator
      key = trim(adjustl(item(1:index(item, '=') - 1)))
      if (has_key(user, key)) return
      if (len_trim(keys) > 0) then
        keys = item//', '//keys
      else
        keys = item
      end if
    end subroutine add
  end subroutine bench_material_keys

  ! Whether 'k1 = v1, k2 = v2, ...' names `key` (case-insensitive).
  pure logical function has_key(list, key)
    character(len=*), intent(in) :: list, key
    integer :: i, j, eq
    character(len=:), allocatable :: item
    has_key = .false.
    i = 1
    do while (i <= len(list))
      j = index(list(i:), ',')
      if (j == 0) then
        item = list(i:)
        i = len(list) + 1
      else
        item = list(i:i + j - 2)
        i = i + j
      end if
      eq = index(item, '=')
      if (eq == 0) cycle
      if (lower(trim(adjustl(item(1:eq - 1)))) == lower(key)) has_key = .true.
    end do
  end function has_key

  !> One-line JSON object with the keys of docs/performance.md.
  function empm_bench_json(res) result(s)
    type(empm_bench_result_t), intent(in) :: res !! measurements
    character(len=:), allocatable :: s           !! {"dim":2,"shape":"lme_g3",...}
    character(len=:), allocatable :: motion
    integer :: k
    motion = 'vibrate'
    if (allocated(res%motion)) motion = res%motion
    s = '{"dim":'//str(res%dim)//',"shape":"'//res%shape//'","integrator":"'// &
      res%integrator//'","material":"'//res%material//'","material_keys":"'// &
      res%material_keys//'","motion":"'//motion//'","plastic_fraction":'// &
      num(res%plastic_fraction)// &
      ',"confinement":'//num(res%confinement)//',"particles":'//str(res%particles)//',"nodes":'//str(res%nodes)// &
      ',"steps":'//str(res%steps)//',"threads":'//str(res%threads)//',"seconds":'// &
      num(res%seconds)//',"particle_steps_per_second":'//num(res%particle_steps_per_second)// &
      ',"newton_iterations_mean":'//num(res%newton_iterations_mean)//',"travel_cells":'// &
      num(res%travel_cells)//',"bytes_per_particle":'// &
      num(res%bytes_per_particle)//',"phase_seconds":{'
    do k = 1, PHASE_COUNT
      if (k > 1) s = s//','
      s = s//'"'//trim(PHASE_NAMES(k))//'":'//num(res%phase_seconds(k))
    end do
    s = s//'}}'
  end function empm_bench_json

  pure function num(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=32) :: buf
    write(buf, '(es15.8e2)') x
    s = trim(adjustl(buf))
  end function num
end module empm_bench
