!> The `empm` command: run case files, print help and version.
program empm_main
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use empm, only: empm_version, empm_run_case, empm_error_t
  use empm_terminal, only: empm_exit
  use empm_error, only: EMPM_ERR_INTERRUPTED
  use empm_parallel, only: empm_set_threads
  use empm_comm, only: empm_comm_t, empm_comm_world
  use empm_solver, only: empm_run_stats_t, empm_run_summary
  use empm_files, only: empm_mkdir_p
  use empm_posix, only: empm_ignore_sigxfsz, empm_catch_stop_signals, empm_stop_signal
  use empm_verify_suite, only: empm_verify_run
  use empm_input, only: empm_input_markdown
  use empm_bench, only: empm_bench_config_t, empm_bench_result_t, empm_bench_run, empm_bench_json
  implicit none
  integer :: nargs, i, ios, nfail, npat, nthreads, envlen, envstat
  logical :: auto
  character(len=:), allocatable :: cmd, case_file, out_file, written, manifest, outdir, restart
  character(len=256), allocatable :: patterns(:)
  character(len=64) :: numtext
  logical :: quick
  type(empm_error_t) :: err
  type(empm_bench_config_t) :: bcfg
  type(empm_bench_result_t) :: bres
  type(empm_run_stats_t) :: stats
  type(empm_comm_t) :: comm

  nargs = command_argument_count()
  if (nargs == 0) then
    call usage(error_unit); call empm_exit(1)
  end if
  cmd = arg(1)
  select case (cmd)
  case ('-h', '--help', 'help')
    call usage(output_unit)
  case ('-V', '--version', 'version')
    write(output_unit, '(a)') 'empm '//empm_version()
  case ('run')
    case_file = ''; out_file = ''; nthreads = 0; restart = ''
    i = 2
    do while (i <= nargs)
      select case (arg(i))
      case ('-h', '--help')
        call usage_run(output_unit); call empm_exit(0)
      case ('-o', '--output')
        if (i == nargs) call die('option '//arg(i)//' needs a file name')
        out_file = arg(i + 1); i = i + 2
      case ('-t', '--threads')
        if (i == nargs) call die('option '//arg(i)//' needs a value')
        nthreads = int_arg(i); i = i + 2
        if (nthreads < 1) call die('option --threads needs a positive integer')
      case ('-r', '--restart')
        if (i == nargs) call die('option '//arg(i)//' needs a checkpoint file')
        restart = arg(i + 1); i = i + 2
      case default
        if (index(arg(i), '-') == 1) call die('unknown option '//arg(i))
        if (len(case_file) > 0) call die('only one case file per run (got '//case_file// &
                                         ' and '//arg(i)//')')
        case_file = arg(i); i = i + 1
      end select
    end do
    if (len(case_file) == 0) call die('empm run needs a case file: empm run CASE.nml')
    if (nthreads > 0) call empm_set_threads(nthreads)
    ! Neither --threads nor OMP_NUM_THREADS: the threads follow the machine's idle cores.
    call get_environment_variable('OMP_NUM_THREADS', length=envlen, status=envstat)
    auto = nthreads == 0 .and. (envstat /= 0 .or. envlen == 0)
    ! Beyond the file-size limit (ulimit -f) a write fails and is reported (status 4).
    call empm_ignore_sigxfsz()
    ! Ctrl-C or a batch system's SIGTERM: a checkpoint and the results so far, then exit.
    call empm_catch_stop_signals()
    ! Under mpirun the processes run the case together (a build with EMPM_USE_MPI; otherwise
    ! each would run it alone): only the root prints, every process exits with the status.
    comm = empm_comm_world()
    ! A verification case file also runs: its &verify group is the suite's, not the run's.
    call empm_run_case(case_file, out_file, written=written, err=err, extra_groups='verify', &
                       stats=stats, restart=restart, auto_threads=auto, comm=comm)
    ! The summary also for a run stopped by a guard (whenever the time loop ran).
    if (stats%ran .and. comm%is_root()) &
      write(output_unit, '(a)', iostat=ios) 'empm: '//empm_run_summary(stats)
    if (err%code == EMPM_ERR_INTERRUPTED) then
      ! As shells report a process ended by a signal: 128 + its number.
      if (comm%is_root()) write(error_unit, '(a)') 'empm: '//err%message
      call comm%finish()
      call empm_exit(128 + empm_stop_signal())
    else if (err%code /= 0) then
      if (comm%is_root()) write(error_unit, '(a)') 'empm: error: '//err%message
      call comm%finish()
      call empm_exit(err%code)
    end if
    if (comm%is_root()) write(output_unit, '(a)', iostat=ios) 'empm: wrote '//written
    call comm%finish()
  case ('verify')
    manifest = 'verification/cases.txt'; outdir = 'reports'; quick = .false.
    allocate(patterns(nargs)); npat = 0
    i = 2
    do while (i <= nargs)
      select case (arg(i))
      case ('-h', '--help')
        call usage_verify(output_unit); call empm_exit(0)
      case ('--quick')
        quick = .true.; i = i + 1
      case ('--out', '-o')
        if (i == nargs) call die('option '//arg(i)//' needs a folder')
        outdir = arg(i + 1); i = i + 2
      case ('--manifest')
        if (i == nargs) call die('option '//arg(i)//' needs a file')
        manifest = arg(i + 1); i = i + 2
      case default
        if (index(arg(i), '-') == 1) call die('unknown option '//arg(i))
        npat = npat + 1; patterns(npat) = arg(i); i = i + 1
      end select
    end do
    if (empm_mkdir_p(outdir//'/raw') /= 0) then
      write(error_unit, '(a)') 'empm: error: cannot create '//outdir//'/raw'
      call empm_exit(4)
    end if
    ! Under mpirun every case runs on all the processes (a build with EMPM_USE_MPI).
    comm = empm_comm_world()
    call empm_verify_run(manifest, outdir, patterns(1:npat), quick, nfail, err, comm)
    nfail = comm%max_int(nfail)
    if (err%code /= 0) then
      if (comm%is_root()) write(error_unit, '(a)') 'empm: error: '//err%message
      call comm%finish()
      call empm_exit(err%code)
    end if
    call comm%finish()
    if (nfail > 0) call empm_exit(5)
  case ('bench')
    i = 2
    do while (i <= nargs)
      if (arg(i) == '-h' .or. arg(i) == '--help') then
        call usage_bench(output_unit); call empm_exit(0)
      end if
      if (i == nargs) call die('option '//arg(i)//' needs a value')
      select case (arg(i))
      case ('--dim');        bcfg%dim = int_arg(i)
      case ('--shape');      bcfg%shape = arg(i + 1)
      case ('--cells');      bcfg%cells = int_arg(i)
      case ('--ppc');        bcfg%ppc = int_arg(i)
      case ('--steps');      bcfg%steps = int_arg(i)
      case ('--warmup');     bcfg%warmup = int_arg(i)
      case ('--threads');    bcfg%threads = int_arg(i)
      case ('--integrator'); bcfg%integrator = arg(i + 1)
      case ('--material');   bcfg%material = arg(i + 1)
      case ('--material-keys'); bcfg%material_keys = arg(i + 1)
      case ('--case');       bcfg%case_file = arg(i + 1)
      case ('--motion');     bcfg%motion = arg(i + 1)
      case ('--confinement')
        numtext = arg(i + 1)
        read(numtext, *, iostat=ios) bcfg%confinement
        if (ios /= 0 .or. bcfg%confinement < 0) &
          call die('--confinement needs a pressure >= 0 [Pa]')
      case ('--min-fill')
        numtext = arg(i + 1)
        read(numtext, *, iostat=ios) bcfg%min_fill
        if (ios /= 0 .or. bcfg%min_fill < 0 .or. bcfg%min_fill > 0.5) &
          call die('--min-fill needs a fill fraction in [0, 0.5] (&grid min_fill)')
      case default;          call die('unknown option '//arg(i))
      end select
      i = i + 2
    end do
    call empm_bench_run(bcfg, bres, err)
    if (err%code /= 0) then
      write(error_unit, '(a)') 'empm: error: '//err%message
      call empm_exit(err%code)
    end if
    write(output_unit, '(a)') empm_bench_json(bres)
  case ('keys')
    if (nargs == 2) then
      if (arg(2) == '-h' .or. arg(2) == '--help') then
        call usage_keys(output_unit); call empm_exit(0)
      end if
    end if
    if (nargs > 1) call die('empm keys takes no argument')
    write(output_unit, '(a)', advance='no') empm_input_markdown()
  case default
    call die('unknown command '''//cmd//'''')
  end select

contains

  function arg(k) result(s)
    integer, intent(in) :: k
    character(len=:), allocatable :: s
    integer :: n
    call get_command_argument(k, length=n)
    allocate(character(len=n) :: s)
    call get_command_argument(k, s)
  end function arg

  ! Value of option k (argument k + 1) as an integer; a usage error otherwise.
  integer function int_arg(k) result(v)
    integer, intent(in) :: k
    integer :: ios
    character(len=:), allocatable :: text
    text = arg(k + 1)
    read(text, *, iostat=ios) v
    if (ios /= 0) call die('option '//arg(k)//' needs an integer, got '''//arg(k + 1)//'''')
  end function int_arg

  subroutine die(msg)
    character(len=*), intent(in) :: msg
    write(error_unit, '(a)') 'empm: '//msg//' (see empm --help)'
    call empm_exit(1)
  end subroutine die

  subroutine usage_run(u)
    integer, intent(in) :: u
    write(u, '(a)') 'usage: empm run CASE.nml [-o OUT.h5] [--threads N] [--restart CKPT.h5]'
    write(u, '(a)') ''
    write(u, '(a)') 'Runs the case file CASE.nml (keys: empm keys, docs/input.md) and writes OUT.h5'
    write(u, '(a)') 'and OUT.xmf for ParaView (docs/output.md, docs/paraview.md). The first'
    write(u, '(a)') 'snapshot is the state at t = 0.'
    write(u, '(a)') ''
    write(u, '(a)') '  -o, --output OUT.h5  output file (default: the &output file, else CASE.h5)'
    write(u, '(a)') '  -t, --threads N      OpenMP threads (default: OMP_NUM_THREADS, else the cores'
    write(u, '(a)') '                       other processes leave idle at the start, at most all)'
    write(u, '(a)') '  -r, --restart CKPT.h5  continue from a checkpoint of this case file (written'
    write(u, '(a)') '                       with &output checkpoint_every / checkpoint_seconds, or'
    write(u, '(a)') '                       on SIGINT/SIGTERM): the results equal an uninterrupted'
    write(u, '(a)') '                       run''s, bitwise with the same number of threads'
    write(u, '(a)') '  -h, --help           this text'
    write(u, '(a)') ''
    write(u, '(a)') 'Progress goes to stderr: one updated line on a terminal, a plain line every'
    write(u, '(a)') '10 % of t_end or 10 s otherwise. At the end one summary line (steps, dt range,'
    write(u, '(a)') 'wall time, total energy at the start and end and its relative drift) and'
    write(u, '(a)') '"wrote OUT.h5" go to stdout.'
    write(u, '(a)') ''
    write(u, '(a)') 'exit status: 0 success, 1 usage error, 2 invalid case file,'
    write(u, '(a)') '             3 run stopped by a guard (results marked incomplete), 4 I/O error'
    write(u, '(a)') '             (also when another run is writing OUT.h5: its lock OUT.h5.lock),'
    write(u, '(a)') '             130 / 143 stopped by SIGINT / SIGTERM (a checkpoint OUT.ckpt.h5 and'
    write(u, '(a)') '             the results so far, marked incomplete, written first)'
  end subroutine usage_run

  subroutine usage_verify(u)
    integer, intent(in) :: u
    write(u, '(a)') 'usage: empm verify [PATTERN...] [--quick] [--out DIR] [--manifest FILE]'
    write(u, '(a)') ''
    write(u, '(a)') 'Runs the verification studies listed in verification/cases.txt (or FILE), only'
    write(u, '(a)') 'the runs whose id or group matches a PATTERN (* wildcard, e.g. ''dyka/*''),'
    write(u, '(a)') 'writes DIR/raw/*.h5 and DIR/summary.json (default DIR: reports) and exits'
    write(u, '(a)') 'with status 5 when a check fails (docs/verification.md).'
    write(u, '(a)') ''
    write(u, '(a)') '  --quick          coarse levels only'
    write(u, '(a)') '  -o, --out DIR    output folder (default: reports)'
    write(u, '(a)') '  --manifest FILE  list of studies (default: verification/cases.txt)'
    write(u, '(a)') '  -h, --help       this text'
  end subroutine usage_verify

  subroutine usage_bench(u)
    integer, intent(in) :: u
    write(u, '(a)') 'usage: empm bench [--dim 2|3] [--shape S] [--cells N] [--ppc P] [--steps K]'
    write(u, '(a)') '                  [--threads T] [--integrator I] [--warmup W]'
    write(u, '(a)') '                  [--material M] [--material-keys ''k = v, ...'']'
    write(u, '(a)') '                  [--confinement P0] [--min-fill F] [--motion vibrate|rotate]'
    write(u, '(a)') '       empm bench --case FILE [--steps K] [--warmup W] [--threads T]'
    write(u, '(a)') ''
    write(u, '(a)') 'Times a freely vibrating block (N^dim cells, P particles per cell) and'
    write(u, '(a)') 'prints one JSON object (docs/performance.md). S is a shape identifier as in a'
    write(u, '(a)') 'case file: linear, ugimp, bspline2, bspline3, lme, lme_g<gamma>; I an'
    write(u, '(a)') 'integrator (usf, usl, musl, pc_published, pc_newmark, gen_alpha_grid,'
    write(u, '(a)') 'gen_alpha); K timed'
    write(u, '(a)') 'steps after W warm-up steps on T threads. M is a material model (empm keys;'
    write(u, '(a)') 'default linear_elastic) with E = 1e7 Pa, nu = 0.3, density = 1000 kg/m3 and'
    write(u, '(a)') 'bench defaults that make soil models yield (mohr_coulomb, drucker_prager:'
    write(u, '(a)') 'cohesion = 500, friction_angle = 30, dilatancy_angle = 5; camclay: lambda ='
    write(u, '(a)') '0.2, kappa = 0.04, M = 1.2, e0 = 1, ocr = 1); --material-keys replaces keys of'
    write(u, '(a)') 'the same name and adds others. The block starts under an isotropic pressure'
    write(u, '(a)') 'P0 [Pa] (default: 1e4 for camclay, 0 otherwise), between smooth rigid walls'
    write(u, '(a)') 'when P0 > 0 (so that it stays confined). A umat library path is'
    write(u, '(a)') 'relative to the working folder. F is the fill below which nodes are extended'
    write(u, '(a)') '(&grid min_fill; default 0.1, 0: off). "plastic_fraction" in the output is the'
    write(u, '(a)') 'share of particle updates that changed a state variable.'
    write(u, '(a)') 'With --motion rotate the block spins about its centre instead (corner speed'
    write(u, '(a)') '0.1 of the P-wave speed: a corner crosses a cell every ~20 steps), on a grid'
    write(u, '(a)') 'a quarter larger on every side: particles move through cells, as in a run.'
    write(u, '(a)') ''
    write(u, '(a)') 'With --case, the model, integrator and time step of a case file are timed'
    write(u, '(a)') 'instead of the block (its dt, or cfl times the stable step at the start):'
    write(u, '(a)') 'the integrator''s steps alone, without the guards, histories, snapshots and'
    write(u, '(a)') 'output of `empm run FILE`, whose time-loop wall time it can be compared with.'
  end subroutine usage_bench

  subroutine usage_keys(u)
    integer, intent(in) :: u
    write(u, '(a)') 'usage: empm keys'
    write(u, '(a)') ''
    write(u, '(a)') 'Prints, as Markdown, every key of the case files with the parameters each'
    write(u, '(a)') 'shape family, material model and integrator declares (docs/input.md).'
  end subroutine usage_keys

  subroutine usage(u)
    integer, intent(in) :: u
    write(u, '(a)') 'usage: empm run CASE.nml [-o OUT.h5] [--threads N]'
    write(u, '(a)') '       empm verify [PATTERN...] [--quick] [--out DIR] [--manifest FILE]'
    write(u, '(a)') '       empm keys'
    write(u, '(a)') '       empm bench [--dim 2|3] [--shape S] [--cells N] [--ppc P] [--steps K]'
    write(u, '(a)') '                  [--threads T] [--integrator I] [--warmup W]'
    write(u, '(a)') '                  [--material M] [--material-keys ''k = v, ...'']'
    write(u, '(a)') '       empm --help | --version'
    write(u, '(a)') '       empm COMMAND --help'
    write(u, '(a)') ''
    write(u, '(a)') 'Runs an explicit MPM simulation described by a namelist case file'
    write(u, '(a)') '(keys: docs/input.md) and writes HDF5 results plus an XDMF file for'
    write(u, '(a)') 'ParaView (layout: docs/output.md).'
    write(u, '(a)') ''
    write(u, '(a)') 'empm verify runs the verification studies listed in verification/cases.txt'
    write(u, '(a)') '(or --manifest), only the runs whose id matches a PATTERN (* wildcard, e.g.'
    write(u, '(a)') '''dyka/*''), writes DIR/raw/*.h5 and DIR/summary.json (default DIR: reports)'
    write(u, '(a)') 'and exits with status 5 when a check fails. --quick: coarse levels only.'
    write(u, '(a)') ''
    write(u, '(a)') 'empm bench times a freely vibrating elastic block (N^dim cells, P particles per'
    write(u, '(a)') 'cell) and prints one JSON object (docs/performance.md). S is a shape identifier'
    write(u, '(a)') 'as in a case file: linear, ugimp, bspline2, bspline3, lme, lme_g<gamma>.'
    write(u, '(a)') ''
    write(u, '(a)') 'empm keys prints every key of the case files, with the parameters each shape'
    write(u, '(a)') 'family, material model and integrator declares (the tables of docs/input.md).'
    write(u, '(a)') ''
    write(u, '(a)') 'exit status: 0 success, 1 usage error, 2 invalid case file,'
    write(u, '(a)') '             3 run stopped by a guard (results marked incomplete), 4 I/O error,'
    write(u, '(a)') '             5 a verification check failed'
  end subroutine usage
end program empm_main
