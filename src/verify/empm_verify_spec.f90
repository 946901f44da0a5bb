!> The `&verify` group of a verification case file: which benchmark, which study (a matrix of
!> shapes × schemes with thresholds, or a convergence study in space or time), the metrics and
!> their thresholds. Keys are documented in docs/verification.md.
module empm_verify_spec
  use, intrinsic :: iso_fortran_env, only: iostat_end
  use empm_kinds, only: wp
  use empm_strings, only: str, lower
  implicit none
  private
  public :: empm_verify_spec_t, empm_read_verify_spec, MAXLIST

  integer, parameter :: MAXLIST = 16  !! capacity of each list key

  !> A verification study.
  type :: empm_verify_spec_t
    character(len=:), allocatable :: file        !! case file
    character(len=32) :: benchmark = ''          !! benchmark id (dyka, vibrating_bar, ...)
    character(len=16) :: study = 'matrix'        !! 'matrix', 'space', 'time' or 'stress_point'
    integer :: nshape = 0, nscheme = 0, nlevel = 0, nmetric = 0
    character(len=16) :: shapes(MAXLIST) = ''    !! shape identifiers
    character(len=16) :: schemes(MAXLIST) = ''   !! scheme names
    integer :: levels(MAXLIST) = 0               !! space study: refinement factors;
                                                 !! stress_point: multipliers of the increments
    real(wp) :: cfls(MAXLIST) = 0.0_wp           !! time study: Courant numbers
    integer :: nppc = 0                          !! variants in particles per cell (0: the file's)
    integer :: ppcs(MAXLIST) = 0                 !! particles per cell and direction of each
                                                 !! variant (every body), label suffix _ppcN
    character(len=32) :: metrics(MAXLIST) = ''   !! matrix study: metric names
    real(wp) :: thresholds(MAXLIST) = 0.0_wp     !! matrix study: upper bounds
    real(wp) :: min_order = 0.0_wp               !! convergence study: required order
    real(wp) :: max_order = huge(1.0_wp)         !! convergence study: order must stay below
    real(wp) :: max_error = huge(1.0_wp)         !! convergence study: bound on the error of
                                                 !! the finest level (unset: not asserted)
                                                 !! (to assert a known loss of convergence)
    character(len=64) :: expect_fail(MAXLIST) = '' !! run-id patterns expected to fail a check
    character(len=32) :: label = ''              !! variant of the study, part of its ids
    !> The signature an expected failure must show (a known failure that stops showing it, or
    !> that fails differently, fails its check): a matrix run either aborts (`expect_abort`) or
    !> completes with an asserted metric above `expect_excess` times its threshold; a
    !> convergence group completes every level with its observed order below `expect_order_below`.
    logical :: expect_abort = .false.
    real(wp) :: expect_excess = 0.0_wp
    real(wp) :: expect_order_below = -huge(1.0_wp)
    character(len=16) :: against = 'reference'   !! time study: errors against a run at an
                                                 !! 8 times smaller step ('reference') or the
                                                 !! benchmark's exact solution ('exact')
    integer :: quick_levels = 2                  !! convergence levels run in quick mode
    logical :: quick = .true.                    !! included in the quick subset
  end type empm_verify_spec_t

contains

  !> Read the `&verify` group of `path`; `emsg` is '' on success.
  subroutine empm_read_verify_spec(path, spec, emsg)
    character(len=*), intent(in) :: path                     !! case file
    type(empm_verify_spec_t), intent(out) :: spec            !! the study
    character(len=:), allocatable, intent(out) :: emsg       !! '' or the problem
    character(len=*), parameter :: K = 'benchmark, study, shapes, schemes, levels, cfls, '// &
      'metrics, thresholds, min_order, max_order, max_error, expect_fail, expect_abort, expect_excess, '// &
      'expect_order_below, label, quick_levels, quick, ppcs, against'
    character(len=32) :: benchmark, metrics(MAXLIST)
    character(len=64) :: expect_fail(MAXLIST)
    character(len=16) :: study, shapes(MAXLIST), schemes(MAXLIST), against
    character(len=32) :: label
    integer :: levels(MAXLIST), quick_levels, u, ios, ppcs(MAXLIST)
    real(wp) :: cfls(MAXLIST), thresholds(MAXLIST), min_order, max_order, expect_excess, &
                expect_order_below, max_error
    logical :: quick, expect_abort, expects
    character(len=512) :: msg
    namelist /verify/ benchmark, study, shapes, schemes, levels, cfls, metrics, thresholds, &
      min_order, max_order, max_error, expect_fail, expect_abort, expect_excess, expect_order_below, label, &
      quick_levels, quick, ppcs, against
    emsg = ''
    spec%file = path
    benchmark = ''; study = 'matrix'; shapes = ''; schemes = ''; levels = 0; cfls = 0.0_wp
    metrics = ''; thresholds = -huge(1.0_wp); min_order = -huge(1.0_wp); max_order = huge(1.0_wp)
    max_error = huge(1.0_wp)
    quick_levels = 2; quick = .true.; expect_fail = ''; label = ''; expect_abort = .false.
    expect_excess = 0.0_wp; expect_order_below = -huge(1.0_wp); ppcs = 0; against = 'reference'
    open(newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      emsg = path//': cannot open: '//trim(msg); return
    end if
    read(u, nml=verify, iostat=ios, iomsg=msg)
    close(u)
    if (ios == iostat_end) then
      emsg = path//': missing group &verify (keys: '//K//')'; return
    else if (ios /= 0) then
      emsg = path//': group &verify: '//trim(msg)//' (valid keys: '//K//')'; return
    end if
    spec%benchmark = lower(benchmark); spec%study = lower(study)
    spec%nshape = count(shapes /= ''); spec%shapes = shapes
    spec%nscheme = count(schemes /= ''); spec%schemes = schemes
    spec%quick_levels = quick_levels; spec%quick = quick; spec%min_order = min_order
    spec%max_order = max_order; spec%max_error = max_error; spec%expect_fail = expect_fail; spec%label = lower(label)
    spec%expect_abort = expect_abort; spec%expect_excess = expect_excess
    spec%expect_order_below = expect_order_below
    expects = any(len_trim(expect_fail) > 0)
    if (index(trim(label), '/') > 0 .or. index(trim(label), ' ') > 0) then
      emsg = path//': group &verify: key ''label'': one word without ''/'''; return
    end if
    if (len_trim(benchmark) == 0) then
      emsg = path//': group &verify: key ''benchmark'': required'; return
    end if
    spec%nppc = count(ppcs /= 0); spec%ppcs = ppcs
    if (any(ppcs(1:spec%nppc) < 1 .or. ppcs(1:spec%nppc) > 4) .or. &
        any(ppcs(spec%nppc + 1:) /= 0)) then
      emsg = path//': group &verify: key ''ppcs'': particles per cell and direction, 1..4 each'
      return
    end if
    if (spec%study == 'stress_point') then
      ! A stress-point study (a material point, no grid: no shapes or schemes): metrics with
      ! thresholds as in a matrix study, one run, or with `levels` (increment multipliers, at
      ! least two) also a convergence study in the increment, asserting an order.
      if (len_trim(label) == 0) then
        emsg = path//': group &verify: key ''label'': required for study = ''stress_point'' '// &
          '(the run id is benchmark/label)'; return
      end if
      spec%nmetric = count(metrics /= '')
      spec%metrics = metrics; spec%thresholds = thresholds
      if (spec%nmetric == 0) then
        emsg = path//': group &verify: key ''metrics'': at least one for study = ''stress_point'''
        return
      end if
      if (any(thresholds(1:spec%nmetric) == -huge(1.0_wp))) then
        emsg = path//': group &verify: key ''thresholds'': one per metric ('// &
          str(spec%nmetric)//' expected; -1 = reported only)'; return
      end if
      spec%nlevel = count(levels > 0); spec%levels = levels
      ! A known failure of a single run shows its signature as for a matrix run (an asserted
      ! metric at least expect_excess times its bound); a stress point cannot abort.
      if (expects .and. (spec%nlevel > 0 .or. expect_abort .or. .not. expect_excess > 1.0_wp)) then
        emsg = path//': group &verify: key ''expect_fail'': a stress_point study declares a '// &
          'known failure without levels and with ''expect_excess'' > 1'; return
      end if
      if (spec%nlevel == 1 .or. any(levels(1:spec%nlevel) <= 0)) then
        emsg = path//': group &verify: key ''levels'': none, or at least two increment '// &
          'multipliers'; return
      end if
      if (spec%nlevel >= 2) then
        if (min_order == -huge(1.0_wp) .and. max_order == huge(1.0_wp)) then
          emsg = path//': group &verify: key ''min_order'' (or ''max_order''): required with '// &
            '''levels'''; return
        end if
        if (min_order /= -huge(1.0_wp) .and. .not. (min_order > 0.0_wp)) then
          emsg = path//': group &verify: key ''min_order'': a convergence order > 0'; return
        end if
        if (quick_levels < 2 .or. quick_levels > spec%nlevel) then
          emsg = path//': group &verify: key ''quick_levels'': expected 2..'//str(spec%nlevel)
          return
        end if
      end if
      return
    end if
    if (spec%nshape == 0 .or. spec%nscheme == 0) then
      emsg = path//': group &verify: keys ''shapes'' and ''schemes'': at least one each'; return
    end if
    select case (spec%study)
    case ('matrix')
      spec%nmetric = count(metrics /= '')
      spec%metrics = metrics; spec%thresholds = thresholds
      if (spec%nmetric == 0) then
        emsg = path//': group &verify: key ''metrics'': at least one for study = ''matrix'''
        return
      end if
      ! A negative threshold marks a metric that is reported, not asserted.
      if (any(thresholds(1:spec%nmetric) == -huge(1.0_wp))) then
        emsg = path//': group &verify: key ''thresholds'': one per metric ('// &
          str(spec%nmetric)//' expected; -1 = reported only)'; return
      end if
      if (expects .and. .not. expect_abort .and. .not. expect_excess > 1.0_wp) then
        emsg = path//': group &verify: key ''expect_fail'': state the failure''s signature, '// &
          '''expect_abort = .true.'' or ''expect_excess'' > 1'; return
      end if
    case ('space')
      spec%nlevel = count(levels > 0); spec%levels = levels
      if (spec%nlevel < 2 .or. any(levels(1:spec%nlevel) <= 0)) then
        emsg = path//': group &verify: key ''levels'': at least two refinement factors'; return
      end if
      spec%nmetric = 1; spec%metrics(1) = metrics(1)
    case ('time')
      spec%nlevel = count(cfls > 0.0_wp); spec%cfls = cfls
      if (spec%nlevel < 2) then
        emsg = path//': group &verify: key ''cfls'': at least two Courant numbers'; return
      end if
      spec%nmetric = 1; spec%metrics(1) = metrics(1)
      spec%against = lower(against)
      if (spec%against /= 'reference' .and. spec%against /= 'exact') then
        emsg = path//': group &verify: key ''against'': expected ''reference'' or ''exact'', '// &
          'got '''//trim(against)//''''; return
      end if
    case default
      emsg = path//': group &verify: key ''study'': expected ''matrix'', ''space'', '// &
        '''time'' or ''stress_point'', got '''//trim(study)//''''; return
    end select
    if (spec%study /= 'matrix') then
      if (len_trim(spec%metrics(1)) == 0) then
        emsg = path//': group &verify: key ''metrics'': the error measure of the study'; return
      end if
      ! The assertion of a convergence study: an order it must reach (min_order), or, for a
      ! demonstration of lost convergence, only a bound it must stay below (max_order).
      if (min_order == -huge(1.0_wp) .and. max_order == huge(1.0_wp)) then
        emsg = path//': group &verify: key ''min_order'' (or ''max_order''): required for a '// &
          'convergence study'; return
      end if
      if (min_order /= -huge(1.0_wp) .and. .not. (min_order > 0.0_wp)) then
        emsg = path//': group &verify: key ''min_order'': a convergence order > 0 (to assert '// &
          'lost convergence, give only max_order)'; return
      end if
      if (expects .and. .not. (expect_order_below > -huge(1.0_wp))) then
        emsg = path//': group &verify: key ''expect_fail'': state the failure''s signature, '// &
          '''expect_order_below'''; return
      end if
      if (quick_levels < 2 .or. quick_levels > spec%nlevel) then
        emsg = path//': group &verify: key ''quick_levels'': expected 2..'//str(spec%nlevel); return
      end if
    end if
  end subroutine empm_read_verify_spec
end module empm_verify_spec
