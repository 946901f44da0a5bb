!> The verification suite driver behind `empm verify`: expands every study of the manifest into
!> runs, filters them by id pattern, runs them with progress and ETA, evaluates metrics and
!> convergence orders against the exact solutions, and writes raw HDF5 results plus
!> `summary.json`. Exit semantics: the number of failed checks is returned.
module empm_verify_suite
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, int64
  use empm_kinds, only: wp
  use empm_strings, only: str, join
  use empm_error, only: empm_error_t, EMPM_OK, EMPM_ERR_IO
  use empm_files, only: empm_rename
  use empm_json, only: empm_json_t
  use empm_version_info, only: empm_version
  use empm_case, only: empm_case_t, empm_overrides_t
  use empm_input, only: empm_read_case
  use empm_history, only: empm_history_t
  use empm_solver, only: empm_solve
  use empm_comm, only: empm_comm_t
  use empm_partition, only: empm_partition_particles, empm_gather_particles
  use empm_output, only: empm_write_results, empm_output_meta_t
  use empm_verify_spec, only: empm_verify_spec_t, empm_read_verify_spec
  use empm_verify_bench, only: empm_bench_t, bench_known
  use empm_verify_metrics, only: observed_orders, fitted_order, weighted_l2
  use empm_verify_stress_point, only: empm_sp_study
  implicit none
  private
  public :: empm_verify_run, empm_glob_match

  !> One run of the suite.
  type :: run_t
    character(len=:), allocatable :: id        !! result id (benchmark/scheme/shape[/level])
    character(len=:), allocatable :: group     !! convergence group id ('' for matrix runs)
    integer :: spec = 0                        !! index of its study
    integer :: ishape = 0, ischeme = 0, ilevel = 0
    integer :: ippc = 0                        !! particles-per-cell variant (0: the file's)
  end type run_t

contains

  !> Simple glob: `*` matches any run of characters (including '/').
  pure recursive logical function empm_glob_match(pattern, s) result(m)
    character(len=*), intent(in) :: pattern !! pattern with '*' wildcards
    character(len=*), intent(in) :: s       !! candidate
    integer :: i
    if (len(pattern) == 0) then
      m = len(s) == 0; return
    end if
    if (pattern(1:1) == '*') then
      do i = 0, len(s)
        if (empm_glob_match(pattern(2:), s(i + 1:))) then
          m = .true.; return
        end if
      end do
      m = .false.
    else
      m = len(s) > 0
      if (m) m = pattern(1:1) == s(1:1)
      if (m) m = empm_glob_match(pattern(2:), s(2:))
    end if
  end function empm_glob_match

  !> Run the suite. `manifest` lists case files (one per line, relative to its folder; `#`
  !> starts a comment). Only runs whose id matches one of `patterns` run (all if none).
  !> `quick` runs only the first `quick_levels` levels of convergence studies and skips
  !> studies marked `quick = .false.`. Results go to `outdir`/raw (HDF5) and `outdir`/summary.json.
  subroutine empm_verify_run(manifest, outdir, patterns, quick, nfail, err, comm)
    character(len=*), intent(in) :: manifest          !! path of verification/cases.txt
    character(len=*), intent(in) :: outdir            !! output folder (created by the caller)
    character(len=*), intent(in) :: patterns(:)       !! id patterns
    logical, intent(in) :: quick                      !! quick subset
    integer, intent(out) :: nfail                     !! failed checks (cases + convergence)
    type(empm_error_t), intent(out) :: err            !! set on set-up or I/O problems
    type(empm_comm_t), intent(in), optional :: comm   !! the processes running each case
                                                      !! together (mpirun; docs/parallel.md):
                                                      !! the root judges, prints and writes
    type(empm_verify_spec_t), allocatable :: specs(:)
    type(run_t), allocatable :: runs(:)
    real(wp), allocatable :: values(:,:), hval(:)
    logical, allocatable :: done(:)
    real(wp), allocatable :: ref_u(:,:)
    character(len=:), allocatable :: emsg, dir
    type(empm_json_t) :: js, jc
    integer :: i, nrun, nsel
    integer(int64) :: c0, c1, rate
    real(wp) :: elapsed
    logical :: root

    nfail = 0
    dir = manifest(1:index(manifest, '/', back=.true.))
    call read_manifest(manifest, dir, specs, emsg)
    if (len(emsg) > 0) then
      err%code = 2; err%message = emsg; return
    end if
    call expand(specs, quick, runs)
    nrun = size(runs)
    ! Ids name results and raw files: a duplicate would overwrite another study's evidence.
    do i = 2, nrun
      do nsel = 1, i - 1
        if (runs(nsel)%id == runs(i)%id) then
          err%code = 2
          err%message = 'verification run id '''//runs(i)%id//''' occurs in both '// &
            specs(runs(nsel)%spec)%file//' and '//specs(runs(i)%spec)%file// &
            ': give one study a label (key ''label'' of &verify)'
          return
        end if
      end do
    end do
    allocate(done(nrun)); done = .false.
    do i = 1, nrun
      done(i) = selected(runs(i))
    end do
    nsel = count(done)
    if (nsel == 0) then
      err%code = 1; err%message = 'no verification run matches the given pattern(s)'; return
    end if
    allocate(values(16, nrun), hval(nrun)); values = huge(1.0_wp); hval = 0.0_wp

    call js%begin_object()
    call js%key('empm_version'); call js%str_value(empm_version())
    call js%key('generated'); call js%str_value(iso_time())
    call js%key('quick'); call js%bool_value(quick)
    call js%key('cases'); call js%begin_array()
    call jc%begin_array()

    root = .true.
    if (present(comm)) root = comm%is_root()
    call system_clock(c0, rate)
    nsel = 0
    do i = 1, nrun
      if (.not. done(i)) cycle
      nsel = nsel + 1
      call system_clock(c1)
      elapsed = real(c1 - c0, wp) / rate
      if (root) then
        write(output_unit, '(a,i0,a,i0,a,a)', advance='no') '[', nsel, '/', count(done), &
          '] ', runs(i)%id
        if (nsel > 1) write(output_unit, '(a,f7.1,a)', advance='no') '  (ETA ', &
          elapsed / (nsel - 1) * (count(done) - nsel + 1), ' s)'
        write(output_unit, '(a)') ''
        flush(output_unit)
      end if
      call one_run(specs(runs(i)%spec), runs(i), values(:, i), hval(i))
    end do
    ! The other processes helped run the cases; the root holds the results.
    if (.not. root) then
      nfail = 0; return
    end if
    call js%end_array()
    call convergence_groups()
    call jc%end_array()
    call js%key('convergence'); js%text = js%text//jc%text; js%need_comma = .true.
    call js%end_object()
    call write_text(outdir//'/summary.json', js%text, err)
    if (err%code /= EMPM_OK) return
    call system_clock(c1)
    write(output_unit, '(a,i0,a,f8.1,a,i0,a)') 'empm verify: ', count(done), ' runs in ', &
      real(c1 - c0, wp) / rate, ' s, ', nfail, ' failed check(s); summary: '//outdir// &
      '/summary.json'

  contains

    logical function selected(r)
      type(run_t), intent(in) :: r
      integer :: k
      selected = size(patterns) == 0
      do k = 1, size(patterns)
        if (empm_glob_match(trim(patterns(k)), r%id)) selected = .true.
        if (len(r%group) > 0) then
          if (empm_glob_match(trim(patterns(k)), r%group)) selected = .true.
        end if
      end do
    end function selected

    ! Read, prepare, run and write one configuration; exact fields are stored beside it.
    subroutine execute(spec, ov, out, cs, hist, bench, ran, msg)
      type(empm_verify_spec_t), intent(in) :: spec
      type(empm_overrides_t), intent(in) :: ov
      character(len=*), intent(in) :: out
      type(empm_case_t), intent(inout) :: cs
      type(empm_history_t), intent(inout) :: hist
      type(empm_bench_t), intent(inout) :: bench
      logical, intent(out) :: ran
      character(len=:), allocatable, intent(out) :: msg
      type(empm_error_t) :: e, ew
      type(empm_output_meta_t) :: meta
      integer :: ierr
      ran = .false.; msg = ''
      call empm_read_case(spec%file, cs, e, ov, extra_groups='verify')
      if (e%code /= EMPM_OK) then
        msg = e%message; return
      end if
      call bench%prepare(spec%benchmark, cs, msg)
      if (len(msg) > 0) return
      call hist%init(cs%model%grid%ndim, cs%probe_name, cs%probe_particle, 1024, &
                     size(cs%run%snapshot_times))
      if (present(comm)) then
        ! The case's particles shared among the processes (after the benchmark set them up).
        cs%model%comm = comm
        call empm_partition_particles(cs%model, e)
        if (e%code /= EMPM_OK) then
          msg = e%message; return
        end if
        call hist%locate_probes(cs%model%pts)
      end if
      cs%run%progress = .false.
      call empm_solve(cs%model, cs%integ, cs%run, hist, e)
      ran = e%code == EMPM_OK
      if (.not. ran) msg = e%message
      meta%case_file = spec%file; meta%case_text = cs%text
      meta%shape = cs%shape_name; meta%integrator = cs%scheme_name
      meta%cfl = cs%run%cfl; meta%t_end = cs%run%t_end
      call empm_gather_particles(cs%model, hist, ew)
      if (.not. root .or. ew%code /= EMPM_OK) then
        if (ew%code /= EMPM_OK) then
          ran = .false.; msg = ew%message
        end if
        return
      end if
      call empm_write_results(out, cs%model, hist, meta, ran, msg, ew)
      if (ew%code == EMPM_OK) then
        call bench%write_exact(out, cs, hist, ierr)
      else
        ran = .false.; msg = ew%message
      end if
    end subroutine execute

    subroutine one_run(spec, r, val, hlevel)
      type(empm_verify_spec_t), intent(in) :: spec
      type(run_t), intent(in) :: r
      real(wp), intent(inout) :: val(:)
      real(wp), intent(out) :: hlevel
      type(empm_case_t) :: cs, cref
      type(empm_history_t) :: hist, href
      type(empm_overrides_t) :: ov
      type(empm_bench_t) :: bench, bref
      character(len=:), allocatable :: out, msg
      logical :: passed, ran, expected, ok
      integer :: m, np
      if (spec%study == 'stress_point') then
        ! A material point driven through an element-test path (no grid, no scheme): the
        ! root's alone.
        if (.not. root) return
        out = outdir//'/raw/'//flat(r%id)//'.h5'
        call empm_sp_study(spec%file, max(1, spec%levels(r%ilevel)), out, &
                           spec%metrics(1:spec%nmetric), val(1:spec%nmetric), hlevel, msg)
        ran = len(msg) == 0
        passed = ran
        do m = 1, spec%nmetric
          if (spec%thresholds(m) >= 0.0_wp) then
            if (.not. (val(m) <= spec%thresholds(m))) passed = .false.
          end if
        end do
        ok = judged(spec, r%id, ran, passed, val, expected)
      else
      ov%shape = trim(spec%shapes(r%ishape)); ov%scheme = trim(spec%schemes(r%ischeme))
      if (r%ippc > 0) ov%ppc = spec%ppcs(r%ippc)
      if (spec%study == 'space') ov%refine = spec%levels(r%ilevel)
      if (spec%study == 'time' .and. r%ilevel == 1 .and. spec%against == 'reference') then
        ! Temporal errors are measured against a run with the same spatial discretisation and
        ! a time step 8 times smaller than the smallest of the study.
        ov%cfl = minval(spec%cfls(1:spec%nlevel)) / 8.0_wp
        call execute(spec, ov, outdir//'/raw/'//flat(r%group)//'_reference.h5', cref, href, &
                     bref, ran, msg)
        if (root) then
          if (.not. ran) write(error_unit, '(a)') '  reference run failed: '//msg
          np = cref%model%pts%np
          if (trim(spec%metrics(1)) == 'velocity_l2') then
            ref_u = cref%model%pts%v(:, 1:np)
          else
            ref_u = cref%model%pts%x(:, 1:np) - cref%model%pts%x0(:, 1:np)
          end if
        end if
      end if
      if (spec%study == 'time') ov%cfl = spec%cfls(r%ilevel)
      out = outdir//'/raw/'//flat(r%id)//'.h5'
      call execute(spec, ov, out, cs, hist, bench, ran, msg)
      if (.not. root) return
      hlevel = cs%model%grid%hmin()
      if (spec%study == 'time') hlevel = spec%cfls(r%ilevel)
      if (spec%study == 'time' .and. ran .and. spec%against == 'reference') then
        np = cs%model%pts%np
        if (allocated(ref_u) .and. trim(spec%metrics(1)) == 'velocity_l2') then
          val(1) = weighted_l2(cs%model%pts%vol0(1:np), cs%model%pts%v(:, 1:np), ref_u) / &
                   bench%vscale
        else if (allocated(ref_u)) then
          val(1) = weighted_l2(cs%model%pts%vol0(1:np), cs%model%pts%x(:, 1:np) - &
                               cs%model%pts%x0(:, 1:np), ref_u) / bench%uscale
        else
          ran = .false.
        end if
        if (.not. ran) nfail = nfail + 1
        return
      end if
      passed = ran
      do m = 1, spec%nmetric
        if (ran) then
          call bench%metric(trim(spec%metrics(m)), cs, hist, val(m), msg)
          if (len(msg) > 0) passed = .false.
          if (spec%study == 'matrix' .and. spec%thresholds(m) >= 0.0_wp) then
            if (.not. (val(m) <= spec%thresholds(m))) passed = .false.
          end if
        end if
      end do
      if (spec%study /= 'matrix') then
        if (.not. ran) nfail = nfail + 1
        if (.not. ran) write(error_unit, '(a)') '  run failed: '//msg
        return
      end if
      ok = judged(spec, r%id, ran, passed, val, expected)
      end if
      if (.not. ok) nfail = nfail + 1
      call js%begin_object()
      call js%key('id'); call js%str_value(r%id)
      call js%key('expected_failure'); call js%bool_value(expected)
      call js%key('metrics'); call js%begin_object()
      do m = 1, spec%nmetric
        call js%key(trim(spec%metrics(m))); call js%real_value(val(m))
      end do
      call js%end_object()
      call js%key('thresholds'); call js%begin_object()
      do m = 1, spec%nmetric
        call js%key(trim(spec%metrics(m)))
        if (spec%thresholds(m) >= 0.0_wp) then
          call js%real_value(spec%thresholds(m))
        else
          call js%null_value()
        end if
      end do
      call js%end_object()
      call js%key('passed'); call js%bool_value(ok)
      call js%key('within_thresholds'); call js%bool_value(passed)
      call js%key('completed'); call js%bool_value(ran)
      if (len(msg) > 0) then
        call js%key('message'); call js%str_value(msg)
      end if
      call js%key('output'); call js%str_value(out)
      call js%end_object()
      ! One label per case; each asserted metric says whether it is within its bound.
      if (expected) then
        write(output_unit, '(a)', advance='no') '    '//trim(merge( &
          'pass (known failure, signature shown)       ', &
          'FAIL (known failure, signature not shown)   ', ok))
      else
        write(output_unit, '(a)', advance='no') '    '//merge('pass', 'FAIL', ok)
      end if
      do m = 1, spec%nmetric
        write(output_unit, '(a)', advance='no') '  '//trim(spec%metrics(m))//' = '//str(val(m))
        if (spec%thresholds(m) >= 0.0_wp) write(output_unit, '(a)', advance='no') &
          trim(merge(' (<=', ' (> ', val(m) <= spec%thresholds(m)))//' '// &
          str(spec%thresholds(m))//')'
      end do
      write(output_unit, '(a)') ''
      if (len(msg) > 0) write(output_unit, '(a)') '    '//msg
    end subroutine one_run

    ! The verdict of a run with asserted metrics `val`: within its thresholds (`passed`), or,
    ! for a run expected to fail (a documented known failure, e.g. a claim of the paper), by
    ! showing the stated signature: the abort itself, or a completed run with an asserted
    ! metric at least `expect_excess` times its threshold. A known failure that stops showing
    ! its signature fails the check, so that a fix is noticed.
    logical function judged(spec, id, ran, passed, val, expected) result(ok)
      type(empm_verify_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: id
      logical, intent(in) :: ran, passed
      real(wp), intent(in) :: val(:)
      logical, intent(out) :: expected
      logical :: signature
      integer :: k
      expected = .false.
      do k = 1, size(spec%expect_fail)
        if (len_trim(spec%expect_fail(k)) > 0) then
          if (empm_glob_match(trim(spec%expect_fail(k)), id)) expected = .true.
        end if
      end do
      signature = .false.
      if (expected .and. spec%expect_abort) then
        signature = .not. ran
      else if (expected .and. ran) then
        do k = 1, spec%nmetric
          if (spec%thresholds(k) >= 0.0_wp) then
            if (val(k) >= spec%expect_excess * spec%thresholds(k)) signature = .true.
          end if
        end do
      end if
      ok = merge(signature, passed, expected)
    end function judged

    subroutine convergence_groups()
      integer :: a, b, n, k
      real(wp), allocatable :: hs(:), es(:), p(:)
      real(wp) :: order
      logical :: ok, expected, within
      character(len=:), allocatable :: bound
      a = 1
      do while (a <= nrun)
        if (len(runs(a)%group) == 0 .or. .not. done(a)) then
          a = a + 1; cycle
        end if
        b = a
        do while (b < nrun)
          if (runs(b + 1)%group /= runs(a)%group) exit
          b = b + 1
        end do
        n = count(done(a:b))
        hs = pack(hval(a:b), done(a:b)); es = pack(values(1, a:b), done(a:b))
        ok = n >= 2 .and. all(es > 0.0_wp .and. es < huge(1.0_wp)) .and. all(hs > 0.0_wp)
        order = 0.0_wp
        if (ok) then
          p = observed_orders(hs, es)
          order = p(size(p))
          ok = order >= specs(runs(a)%spec)%min_order .and. order <= specs(runs(a)%spec)%max_order
          ! The error level too: with max_error, the finest level's error must be below it
          ! (in the full study; the quick subset stops at a coarser level).
          if (.not. quick) ok = ok .and. es(size(es)) <= specs(runs(a)%spec)%max_error
        end if
        ! A documented known failure passes the check when its runs completed and its order
        ! misses the bounds.
        expected = .false.
        do k = 1, size(specs(runs(a)%spec)%expect_fail)
          if (len_trim(specs(runs(a)%spec)%expect_fail(k)) > 0) then
            if (empm_glob_match(trim(specs(runs(a)%spec)%expect_fail(k)), runs(a)%group)) &
              expected = .true.
          end if
        end do
        within = ok
        ! A known failure passes its check only when every level completed and the order is
        ! below the stated bound: a run that aborts, or converges again, fails it.
        if (expected) ok = n >= 2 .and. all(done(a:b)) .and. &
          all(es > 0.0_wp .and. es < huge(1.0_wp)) .and. &
          order < specs(runs(a)%spec)%expect_order_below
        if (.not. ok) nfail = nfail + 1
        call jc%begin_object()
        call jc%key('id'); call jc%str_value(runs(a)%group)
        call jc%key('expected_failure'); call jc%bool_value(expected)
        call jc%key('within_bounds'); call jc%bool_value(within)
        select case (specs(runs(a)%spec)%study)
        case ('space')
          call jc%key('parameter'); call jc%str_value('h')
        case ('stress_point')
          call jc%key('parameter'); call jc%str_value('dt')
        case default
          call jc%key('parameter'); call jc%str_value('cfl')
        end select
        if (specs(runs(a)%spec)%study == 'time' .and. &
            specs(runs(a)%spec)%against == 'reference') then
          call jc%key('metric'); call jc%str_value('temporal_'//trim(specs(runs(a)%spec)%metrics(1)))
        else
          call jc%key('metric'); call jc%str_value(trim(specs(runs(a)%spec)%metrics(1)))
        end if
        call jc%key('values'); call jc%real_array(hs)
        call jc%key('errors'); call jc%real_array(es)
        call jc%key('observed_order'); call jc%real_value(order)
        if (ok .or. (n >= 2 .and. all(es > 0.0_wp .and. es < huge(1.0_wp)))) then
          call jc%key('fitted_order'); call jc%real_value(fitted_order(hs, es))
        end if
        if (specs(runs(a)%spec)%max_error < huge(1.0_wp)) then
          call jc%key('max_error'); call jc%real_value(specs(runs(a)%spec)%max_error)
        end if
        if (specs(runs(a)%spec)%min_order > -huge(1.0_wp)) then
          call jc%key('min_order'); call jc%real_value(specs(runs(a)%spec)%min_order)
        end if
        if (expected) then
          call jc%key('expect_order_below')
          call jc%real_value(specs(runs(a)%spec)%expect_order_below)
        end if
        if (specs(runs(a)%spec)%max_order < huge(1.0_wp)) then
          call jc%key('max_order'); call jc%real_value(specs(runs(a)%spec)%max_order)
        end if
        call jc%key('passed'); call jc%bool_value(ok)
        call jc%key('outputs'); call jc%begin_array()
        do k = a, b
          if (done(k)) call jc%str_value(outdir//'/raw/'//flat(runs(k)%id)//'.h5')
        end do
        call jc%end_array()
        call jc%end_object()
        bound = ''
        if (specs(runs(a)%spec)%min_order > -huge(1.0_wp)) &
          bound = '>= '//str(specs(runs(a)%spec)%min_order)
        if (len(bound) > 0 .and. specs(runs(a)%spec)%max_order < huge(1.0_wp)) bound = bound//', '
        if (specs(runs(a)%spec)%max_order < huge(1.0_wp)) &
          bound = bound//'<= '//str(specs(runs(a)%spec)%max_order)
        if (specs(runs(a)%spec)%max_error < huge(1.0_wp) .and. .not. quick) &
          bound = bound//'; finest error <= '//str(specs(runs(a)%spec)%max_error)
        if (expected) bound = 'known failure: < '//str(specs(runs(a)%spec)%expect_order_below)
        write(output_unit, '(a)') trim(merge('pass ', 'FAIL ', ok))//' '//runs(a)%group// &
          ': errors '//join(es, ' ')//' observed order '//str(order)//' ('//trim(bound)//')'
        a = b + 1
      end do
    end subroutine convergence_groups
  end subroutine empm_verify_run


  !> Run id with '/' made file-name safe.
  pure function flat(id) result(s)
    character(len=*), intent(in) :: id
    character(len=len(id)) :: s
    integer :: i
    s = id
    do i = 1, len(s)
      if (s(i:i) == '/') s(i:i) = '_'
    end do
  end function flat

  subroutine read_manifest(manifest, dir, specs, emsg)
    character(len=*), intent(in) :: manifest, dir
    type(empm_verify_spec_t), allocatable, intent(out) :: specs(:)
    character(len=:), allocatable, intent(out) :: emsg
    type(empm_verify_spec_t), allocatable :: tmp(:)
    type(empm_verify_spec_t) :: sp
    character(len=512) :: line
    integer :: u, ios, n
    emsg = ''
    allocate(specs(0))
    open(newunit=u, file=manifest, status='old', action='read', iostat=ios)
    if (ios /= 0) then
      emsg = manifest//': cannot open the verification manifest'; return
    end if
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      line = adjustl(line)
      if (len_trim(line) == 0 .or. line(1:1) == '#') cycle
      call empm_read_verify_spec(dir//trim(line), sp, emsg)
      if (len(emsg) > 0) exit
      if (sp%study == 'stress_point') then
        if (sp%benchmark /= 'stress_point' .and. sp%benchmark /= 'objectivity') then
          emsg = dir//trim(line)//': group &verify: study = ''stress_point'' takes benchmark '// &
            '''stress_point'' or ''objectivity'''
          exit
        end if
      else if (.not. bench_known(sp%benchmark)) then
        emsg = dir//trim(line)//': group &verify: unknown benchmark '''//trim(sp%benchmark)//''''
        exit
      end if
      n = size(specs)
      allocate(tmp(n + 1)); tmp(1:n) = specs; tmp(n + 1) = sp
      call move_alloc(tmp, specs)
    end do
    close(u)
  end subroutine read_manifest

  subroutine expand(specs, quick, runs)
    type(empm_verify_spec_t), intent(in) :: specs(:)
    logical, intent(in) :: quick
    type(run_t), allocatable, intent(out) :: runs(:)
    type(run_t), allocatable :: tmp(:)
    integer :: s, i, j, l, nl, n, k
    type(run_t) :: r
    character(len=:), allocatable :: lab
    allocate(runs(0))
    do s = 1, size(specs)
      if (quick .and. .not. specs(s)%quick) cycle
      nl = max(1, specs(s)%nlevel)
      if (quick .and. specs(s)%study /= 'matrix' .and. specs(s)%nlevel >= 2) &
        nl = specs(s)%quick_levels
      if (specs(s)%study == 'stress_point') then
        ! One run per level (increment multiplier); a convergence group when there are levels.
        do l = 1, nl
          r%spec = s; r%ishape = 0; r%ischeme = 0; r%ilevel = l; r%ippc = 0
          r%group = ''
          r%id = trim(specs(s)%benchmark)//'/'//trim(specs(s)%label)
          if (specs(s)%nlevel >= 2) then
            r%group = r%id; r%id = r%id//'/'//str(l)
          end if
          n = size(runs)
          allocate(tmp(n + 1)); tmp(1:n) = runs; tmp(n + 1) = r
          call move_alloc(tmp, runs)
        end do
        cycle
      end if
      do k = 0, specs(s)%nppc
        if (k == 0 .and. specs(s)%nppc > 0) cycle
        ! The label, with the particles-per-cell variant as a suffix.
        lab = trim(specs(s)%label)
        if (k > 0) then
          if (len(lab) > 0) lab = lab//'_'
          lab = lab//'ppc'//str(specs(s)%ppcs(k))
        end if
        do j = 1, specs(s)%nscheme
          do i = 1, specs(s)%nshape
            do l = 1, nl
              r%spec = s; r%ishape = i; r%ischeme = j; r%ilevel = l; r%ippc = k
              if (specs(s)%study == 'matrix') then
                r%group = ''
                r%id = trim(specs(s)%benchmark)//'/'//trim(specs(s)%schemes(j))//'/'// &
                  trim(specs(s)%shapes(i))
                if (len(lab) > 0) r%id = r%id//'-'//lab
              else
                r%group = trim(specs(s)%benchmark)//'/'//trim(specs(s)%study)
                if (len(lab) > 0) r%group = r%group//'_'//lab
                r%group = r%group//'/'// &
                  trim(specs(s)%schemes(j))//'/'//trim(specs(s)%shapes(i))
                r%id = r%group//'/'//str(l)
              end if
              n = size(runs)
              allocate(tmp(n + 1)); tmp(1:n) = runs; tmp(n + 1) = r
              call move_alloc(tmp, runs)
            end do
          end do
        end do
      end do
    end do
  end subroutine expand

  !> Write `text` to `path` (written under a temporary name and renamed, so that a failed
  !> write never leaves a truncated summary); an I/O failure is an error with the system's
  !> message.
  subroutine write_text(path, text, err)
    character(len=*), intent(in) :: path, text
    type(empm_error_t), intent(inout) :: err
    integer :: u, ios, ios2
    character(len=512) :: msg
    open(newunit=u, file=path//'.partial', status='replace', action='write', iostat=ios, &
         iomsg=msg)
    if (ios == 0) then
      write(u, '(a)', iostat=ios, iomsg=msg) text
      close(u, iostat=ios2)
      if (ios == 0 .and. ios2 /= 0) then
        ios = ios2; msg = 'closing the file failed'
      end if
    end if
    if (ios == 0) then
      if (empm_rename(path//'.partial', path) /= 0) then
        ios = 1; msg = 'cannot rename '//path//'.partial'
      end if
    end if
    if (ios /= 0) then
      err%code = EMPM_ERR_IO
      err%message = path//': cannot write the summary: '//trim(msg)
    end if
  end subroutine write_text

  !> Current local time as ISO 8601 (e.g. 2026-11-21T05:19:14+00:00).
  function iso_time() result(s)
    character(len=:), allocatable :: s
    character(len=8) :: d
    character(len=10) :: t
    character(len=5) :: z
    call date_and_time(d, t, z)
    s = d(1:4)//'-'//d(5:6)//'-'//d(7:8)//'T'//t(1:2)//':'//t(3:4)//':'//t(5:6)//z(1:3)//':'//z(4:5)
  end function iso_time
end module empm_verify_suite
