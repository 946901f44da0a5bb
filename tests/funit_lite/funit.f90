!> funit-lite: a minimal stand-in for pFUnit's `funit` module.
!>
!> Used only when pFUnit 4.x is not installed. It provides the subset of pFUnit's assertion
!> API documented in docs/testing.md, with pFUnit's argument names and positional order, so
!> that the same .pf files build under both. `funitproc_lite.py` turns each `@assertX(args)`
!> into `call assertX(args, location=SourceLocation('file.pf', line))` followed by
!> `if (anyExceptions()) return`, exactly as pFUnit's preprocessor does.
!>
!> The only global state is the runner's list of failures of the test being run; the
!> generated code resets it before each test through [[funit_lite_run_test]].
module funit
  use, intrinsic :: iso_fortran_env, only: real64, int64, output_unit
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
  implicit none
  private

  ! pFUnit-compatible API
  public :: SourceLocation, anyExceptions
  public :: assertEqual, assertTrue, assertFalse
  public :: assertLessThan, assertLessThanOrEqual
  public :: assertGreaterThan, assertGreaterThanOrEqual
  public :: assertRelativelyEqual, assertIsFinite
  ! runner API, used by the code funitproc_lite.py generates
  public :: funit_lite_test_proc, funit_lite_run_test
  public :: funit_lite_reset, funit_lite_num_failures, funit_lite_failure
  ! Names that pFUnit's `funit` module also exports: reserved here, so that a .pf module that
  ! defines one of them (e.g. a helper called `run`) fails under funit-lite as under pFUnit.
  public :: initialize, run, finalize, stub

  integer, parameter :: MAXLEN_FILE_NAME = 255   !! as pFUnit's SourceLocation
  integer, parameter :: MAXLEN_MESSAGE = 2048    !! longer failure messages are truncated
  integer, parameter :: LEN_REAL = 32            !! es24.16 or es25.16e3
  integer, parameter :: LEN_INT = 24

  !> Where an assertion sits in its .pf file (same components as pFUnit's type, so the
  !> structure constructor `SourceLocation('file.pf', 12)` works under both).
  type :: SourceLocation
    character(len=MAXLEN_FILE_NAME) :: fileName = '<unknown file>' !! .pf file name
    integer :: lineNumber = -1                                      !! line of the @assert
  end type SourceLocation

  !> Never instantiated: an optional dummy of this type forces the arguments after it to be
  !> given by keyword, as pFUnit's KeywordEnforcer does for some assertions.
  type, abstract :: KeywordEnforcer
  end type KeywordEnforcer

  !> One failed assertion of the current test.
  type :: failure_t
    character(len=MAXLEN_FILE_NAME) :: file = ''  !! .pf file, blank when unknown
    integer :: line = -1                          !! .pf line, -1 when unknown
    character(len=MAXLEN_MESSAGE) :: text = ''    !! one-line description
  end type failure_t

  type(failure_t), allocatable :: failures(:)     !! failures of the current test
  integer :: n_failures = 0                       !! entries of `failures` in use

  abstract interface
    !> A test, @before or @after procedure.
    subroutine funit_lite_test_proc()
    end subroutine funit_lite_test_proc
  end interface

  !> assertEqual(expected, actual [, tolerance] [, message] [, location]) for numbers;
  !> assertEqual(expected, found [, message] [, location]) for strings.
  interface assertEqual
    module procedure assert_equal_i_0_0, assert_equal_i_1_1, assert_equal_i_0_1
    module procedure assert_equal_i8_0_0, assert_equal_i8_1_1, assert_equal_i_i8_0_0
    module procedure assert_equal_string
    module procedure assert_equal_r_0_0, assert_equal_r_0_0_tol
    module procedure assert_equal_r_1_1, assert_equal_r_1_1_tol
    module procedure assert_equal_r_2_2, assert_equal_r_2_2_tol
    module procedure assert_equal_r_0_1, assert_equal_r_0_1_tol
    module procedure assert_equal_r_0_2, assert_equal_r_0_2_tol
  end interface assertEqual

  !> assertRelativelyEqual(expected, actual, tolerance [, message] [, location]):
  !> |actual - expected| <= tolerance*|expected|.
  interface assertRelativelyEqual
    module procedure assert_rel_equal_0_0, assert_rel_equal_1_1, assert_rel_equal_0_1
  end interface assertRelativelyEqual

  !> assertTrue(condition [, message] [, location]); rank 1 means all(condition).
  interface assertTrue
    module procedure assert_true_0, assert_true_1
  end interface assertTrue

  !> assertFalse(condition [, message] [, location]); rank 1 means .not. any(condition).
  interface assertFalse
    module procedure assert_false_0, assert_false_1
  end interface assertFalse

  !> assertLessThan(lhs, rhs, ...): passes when lhs < rhs.
  interface assertLessThan
    module procedure assert_lt_r, assert_lt_i, assert_lt_i8
  end interface assertLessThan

  !> assertLessThanOrEqual(lhs, rhs, ...): passes when lhs <= rhs.
  interface assertLessThanOrEqual
    module procedure assert_le_r, assert_le_i, assert_le_i8
  end interface assertLessThanOrEqual

  !> assertGreaterThan(lhs, rhs, ...): passes when lhs > rhs.
  interface assertGreaterThan
    module procedure assert_gt_r, assert_gt_i, assert_gt_i8
  end interface assertGreaterThan

  !> assertGreaterThanOrEqual(lhs, rhs, ...): passes when lhs >= rhs.
  interface assertGreaterThanOrEqual
    module procedure assert_ge_r, assert_ge_i, assert_ge_i8
  end interface assertGreaterThanOrEqual

  !> assertIsFinite(x [, message] [, location]): x is neither infinite nor NaN.
  interface assertIsFinite
    module procedure assert_is_finite_r
  end interface assertIsFinite

  ! Comparison codes for the ordering assertions.
  integer, parameter :: OP_LT = 1, OP_LE = 2, OP_GT = 3, OP_GE = 4

contains

  ! ======================================================================= runner ====

  !> True when the current test has recorded a failure (pFUnit's anyExceptions()).
  logical function anyExceptions()
    anyExceptions = n_failures > 0
  end function anyExceptions

  !> Forget the failures recorded so far (called before each test).
  subroutine funit_lite_reset()
    n_failures = 0
  end subroutine funit_lite_reset

  !> Number of failures recorded since the last reset.
  integer function funit_lite_num_failures()
    funit_lite_num_failures = n_failures
  end function funit_lite_num_failures

  !> Failure `i` (1 <= i <= funit_lite_num_failures()) as `file:line: test: message`.
  function funit_lite_failure(i, file, test_name) result(line)
    integer, intent(in) :: i                  !! failure index
    character(len=*), intent(in) :: file      !! .pf file, used when the location is unknown
    character(len=*), intent(in) :: test_name !! name of the test
    character(len=:), allocatable :: line

    if (len_trim(failures(i)%file) > 0) then
      line = trim(failures(i)%file)
    else
      line = trim(file)
    end if
    if (failures(i)%line >= 0) line = line // ':' // int_str(failures(i)%line)
    line = line // ': ' // trim(test_name) // ': ' // trim(failures(i)%text)
  end function funit_lite_failure

  !> Run one test: @before, the test (unless @before failed), @after; print one line per
  !> failure and count the test as passed or failed.
  subroutine funit_lite_run_test(file, test_name, test, n_passed, n_failed, before, after)
    character(len=*), intent(in) :: file                     !! .pf file name
    character(len=*), intent(in) :: test_name                !! test procedure name
    procedure(funit_lite_test_proc) :: test                  !! the test
    integer, intent(inout) :: n_passed                       !! tests passed so far
    integer, intent(inout) :: n_failed                       !! tests failed so far
    procedure(funit_lite_test_proc), optional :: before      !! @before procedure
    procedure(funit_lite_test_proc), optional :: after       !! @after procedure
    integer :: i

    call funit_lite_reset()
    if (present(before)) call before()
    if (.not. anyExceptions()) call test()
    if (present(after)) call after()
    if (n_failures == 0) then
      n_passed = n_passed + 1
    else
      n_failed = n_failed + 1
      do i = 1, n_failures
        write(output_unit, '(a)') funit_lite_failure(i, file, test_name)
      end do
    end if
    flush(output_unit)
    call funit_lite_reset()
  end subroutine funit_lite_run_test

  !> Record a failure of the current test.
  subroutine record_failure(text, message, location)
    character(len=*), intent(in) :: text                    !! what failed
    character(len=*), optional, intent(in) :: message       !! user message, prepended
    type(SourceLocation), optional, intent(in) :: location  !! where
    type(failure_t), allocatable :: grown(:)

    if (.not. allocated(failures)) allocate(failures(8))
    if (n_failures == size(failures)) then
      allocate(grown(2*size(failures)))
      grown(1:n_failures) = failures(1:n_failures)
      call move_alloc(grown, failures)
    end if
    n_failures = n_failures + 1
    failures(n_failures) = failure_t()
    if (present(message)) then
      if (len_trim(message) > 0) then
        failures(n_failures)%text = trim(message) // ': ' // text
      else
        failures(n_failures)%text = text
      end if
    else
      failures(n_failures)%text = text
    end if
    if (present(location)) then
      failures(n_failures)%file = location%fileName
      failures(n_failures)%line = location%lineNumber
    end if
  end subroutine record_failure

  ! ================================================================== formatting ====

  !> A real64 in es24.16 (es25.16e3 for exponents beyond two digits), without blanks;
  !> NaN and Infinity as the compiler writes them.
  function real_str(x) result(s)
    real(real64), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=LEN_REAL) :: buf

    buf = ''
    if (ieee_is_finite(x)) then
      if (x /= 0.0_real64 .and. (abs(x) >= 1.0e99_real64 .or. abs(x) < 1.0e-99_real64)) then
        write(buf, '(es25.16e3)') x
      else
        write(buf, '(es24.16)') x
      end if
    else
      write(buf, '(es24.16)') x
    end if
    s = trim(adjustl(buf))
  end function real_str

  !> A default integer in i0.
  function int_str(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=LEN_INT) :: buf

    write(buf, '(i0)') i
    s = trim(buf)
  end function int_str

  !> An int64 in i0.
  function int8_str(i) result(s)
    integer(int64), intent(in) :: i
    character(len=:), allocatable :: s
    character(len=LEN_INT) :: buf

    write(buf, '(i0)') i
    s = trim(buf)
  end function int8_str

  !> A logical as .true. / .false.
  function logical_str(l) result(s)
    logical, intent(in) :: l
    character(len=:), allocatable :: s

    if (l) then
      s = '.true.'
    else
      s = '.false.'
    end if
  end function logical_str

  !> A shape or index vector as "(3, 4)".
  function vector_str(v) result(s)
    integer, intent(in) :: v(:)
    character(len=:), allocatable :: s
    integer :: k

    s = '('
    do k = 1, size(v)
      if (k > 1) s = s // ', '
      s = s // int_str(v(k))
    end do
    s = s // ')'
  end function vector_str

  !> Multi-index (1-based, column-major) of element `lin` of an array of shape `shp`.
  function index_str(lin, shp) result(s)
    integer, intent(in) :: lin     !! linear (array element order) index, 1-based
    integer, intent(in) :: shp(:)  !! array shape
    character(len=:), allocatable :: s
    integer :: idx(size(shp)), rest, k

    rest = lin - 1
    do k = 1, size(shp)
      idx(k) = mod(rest, max(shp(k), 1)) + 1
      rest = rest / max(shp(k), 1)
    end do
    s = vector_str(idx)
  end function index_str

  !> Prefix "at index (i, j) of shape (m, n): " for array assertions, "" for scalars.
  function where_str(lin, shp) result(s)
    integer, intent(in) :: lin
    integer, intent(in) :: shp(:)
    character(len=:), allocatable :: s

    if (size(shp) == 0) then
      s = ''
    else
      s = 'at index ' // index_str(lin, shp) // ' of shape ' // vector_str(shp) // ': '
    end if
  end function where_str

  !> True (after recording a failure) when the shapes of expected and actual differ.
  !> A scalar expected (empty shape) conforms with any actual, as in pFUnit.
  logical function shapes_differ(shape_e, shape_a, message, location)
    integer, intent(in) :: shape_e(:), shape_a(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    shapes_differ = .false.
    if (size(shape_e) == 0) return
    if (size(shape_e) == size(shape_a)) then
      if (all(shape_e == shape_a)) return
    end if
    shapes_differ = .true.
    call record_failure('shapes differ: expected shape ' // vector_str(shape_e) // &
                        ' but found shape ' // vector_str(shape_a), message, location)
  end function shapes_differ

  ! ========================================================== real comparisons ====

  !> |a - e| without overflow (huge() when it would overflow); both must be finite.
  real(real64) function abs_diff(e, a)
    real(real64), intent(in) :: e, a

    if (((a < 0.0_real64) .neqv. (e < 0.0_real64)) .and. abs(a) > huge(a) - abs(e)) then
      abs_diff = huge(a)
    else
      abs_diff = abs(a - e)
    end if
  end function abs_diff

  !> Absolute comparison of one element; `d` is |a - e| when both are finite.
  logical function reals_match(e, a, tol, d, finite)
    real(real64), intent(in) :: e, a, tol
    real(real64), intent(out) :: d
    logical, intent(out) :: finite

    d = 0.0_real64
    finite = ieee_is_finite(e) .and. ieee_is_finite(a)
    reals_match = .false.
    if (ieee_is_nan(e) .or. ieee_is_nan(a)) return
    if (e == a) then              ! exact, and the only way two infinities can match
      reals_match = .true.
      return
    end if
    if (.not. finite) return
    d = abs_diff(e, a)
    reals_match = d <= tol
  end function reals_match

  !> Absolute comparison of flattened arrays; `shp` is the shape of actual (empty: scalar).
  subroutine check_reals(e, a, tol, shp, message, location)
    real(real64), intent(in) :: e(:), a(:)  !! expected and actual, same size
    real(real64), intent(in) :: tol         !! absolute tolerance
    integer, intent(in) :: shp(:)           !! shape of actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    real(real64) :: d, d_first, d_max
    logical :: finite, finite_first
    integer :: i, first, n_bad, n_bad_finite
    character(len=:), allocatable :: text

    n_bad = 0
    n_bad_finite = 0
    first = 0
    d_first = 0.0_real64
    d_max = 0.0_real64
    finite_first = .true.
    do i = 1, size(a)
      if (reals_match(e(i), a(i), tol, d, finite)) cycle
      n_bad = n_bad + 1
      if (first == 0) then
        first = i
        d_first = d
        finite_first = finite
      end if
      if (finite) then
        n_bad_finite = n_bad_finite + 1
        d_max = max(d_max, d)
      end if
    end do
    if (n_bad == 0) return

    text = where_str(first, shp) // 'expected ' // real_str(e(first)) // ' but found ' // &
           real_str(a(first))
    if (finite_first) then
      text = text // '; difference ' // real_str(d_first) // ' > tolerance ' // real_str(tol)
    end if
    if (size(shp) > 0) then
      if (n_bad_finite == n_bad) then
        text = text // '; max difference ' // real_str(d_max)
      else if (n_bad_finite > 0) then
        text = text // '; max difference over finite elements ' // real_str(d_max)
      end if
      text = text // ' (' // int_str(n_bad) // ' of ' // int_str(size(a)) // &
             ' elements differ)'
    end if
    call record_failure(text, message, location)
  end subroutine check_reals

  !> Relative comparison of flattened arrays: |a - e| <= tol*|e|, and e /= 0 (as pFUnit).
  subroutine check_reals_rel(e, a, tol, shp, message, location)
    real(real64), intent(in) :: e(:), a(:)  !! expected and actual, same size
    real(real64), intent(in) :: tol         !! relative tolerance
    integer, intent(in) :: shp(:)           !! shape of actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: i, first, n_bad
    real(real64) :: rel_first
    logical :: ok, finite_first
    character(len=:), allocatable :: text

    do i = 1, size(e)
      if (e(i) == 0.0_real64) then
        call record_failure(where_str(i, shp) // 'expected ' // real_str(e(i)) // &
                            ': a relative comparison needs a nonzero expected value', &
                            message, location)
        return
      end if
    end do

    n_bad = 0
    first = 0
    rel_first = 0.0_real64
    finite_first = .true.
    do i = 1, size(a)
      if (ieee_is_finite(e(i)) .and. ieee_is_finite(a(i))) then
        ok = abs_diff(e(i), a(i)) <= tol*abs(e(i))
      else
        ok = .false.
      end if
      if (ok) cycle
      n_bad = n_bad + 1
      if (first == 0) then
        first = i
        finite_first = ieee_is_finite(e(i)) .and. ieee_is_finite(a(i))
        if (finite_first) rel_first = abs_diff(e(i), a(i)) / abs(e(i))
      end if
    end do
    if (n_bad == 0) return

    text = where_str(first, shp) // 'expected ' // real_str(e(first)) // ' but found ' // &
           real_str(a(first))
    if (finite_first) then
      text = text // '; relative difference ' // real_str(rel_first) // ' > tolerance ' // &
             real_str(tol)
    end if
    if (size(shp) > 0) then
      text = text // ' (' // int_str(n_bad) // ' of ' // int_str(size(a)) // &
             ' elements differ)'
    end if
    call record_failure(text, message, location)
  end subroutine check_reals_rel

  ! ======================================================= assertEqual: integer ====

  !> Element comparison of flattened integer arrays; `shp` is the shape of actual.
  subroutine check_ints(e, a, shp, message, location)
    integer(int64), intent(in) :: e(:), a(:)
    integer, intent(in) :: shp(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: i, first, n_bad
    character(len=:), allocatable :: text

    n_bad = 0
    first = 0
    do i = 1, size(a)
      if (e(i) == a(i)) cycle
      n_bad = n_bad + 1
      if (first == 0) first = i
    end do
    if (n_bad == 0) return
    text = where_str(first, shp) // 'expected ' // int8_str(e(first)) // ' but found ' // &
           int8_str(a(first))
    if (size(shp) > 0) then
      text = text // ' (' // int_str(n_bad) // ' of ' // int_str(size(a)) // &
             ' elements differ)'
    end if
    call record_failure(text, message, location)
  end subroutine check_ints

  subroutine assert_equal_i_0_0(expected, actual, message, location)
    integer, intent(in) :: expected, actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: no_shape(0)

    call check_ints([int(expected, int64)], [int(actual, int64)], no_shape, message, location)
  end subroutine assert_equal_i_0_0

  subroutine assert_equal_i_1_1(expected, actual, message, location)
    integer, intent(in) :: expected(:), actual(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (shapes_differ(shape(expected), shape(actual), message, location)) return
    call check_ints(int(expected, int64), int(actual, int64), shape(actual), message, location)
  end subroutine assert_equal_i_1_1

  subroutine assert_equal_i_0_1(expected, actual, message, location)
    integer, intent(in) :: expected, actual(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer(int64) :: e(size(actual))

    e = int(expected, int64)
    call check_ints(e, int(actual, int64), shape(actual), message, location)
  end subroutine assert_equal_i_0_1

  subroutine assert_equal_i8_0_0(expected, actual, message, location)
    integer(int64), intent(in) :: expected, actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: no_shape(0)

    call check_ints([expected], [actual], no_shape, message, location)
  end subroutine assert_equal_i8_0_0

  subroutine assert_equal_i8_1_1(expected, actual, message, location)
    integer(int64), intent(in) :: expected(:), actual(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (shapes_differ(shape(expected), shape(actual), message, location)) return
    call check_ints(expected, actual, shape(actual), message, location)
  end subroutine assert_equal_i8_1_1

  subroutine assert_equal_i_i8_0_0(expected, actual, message, location)
    integer, intent(in) :: expected
    integer(int64), intent(in) :: actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: no_shape(0)

    call check_ints([int(expected, int64)], [actual], no_shape, message, location)
  end subroutine assert_equal_i_i8_0_0

  ! ======================================================== assertEqual: string ====

  !> Strings compare equal when they agree after removing leading and trailing blanks
  !> (pFUnit's default whitespace option, TRIM_ALL).
  subroutine assert_equal_string(expected, found, message, location)
    character(len=*), intent(in) :: expected, found
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (trim(adjustl(expected)) == trim(adjustl(found))) then
      if (len_trim(adjustl(expected)) == len_trim(adjustl(found))) return
    end if
    call record_failure('expected "' // trim(adjustl(expected)) // '" but found "' // &
                        trim(adjustl(found)) // '"', message, location)
  end subroutine assert_equal_string

  ! ========================================================== assertEqual: real ====

  subroutine assert_equal_r_0_0(expected, actual, message, location)
    real(real64), intent(in) :: expected, actual
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call assert_equal_r_0_0_tol(expected, actual, 0.0_real64, message, location)
  end subroutine assert_equal_r_0_0

  subroutine assert_equal_r_0_0_tol(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected, actual, tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: no_shape(0)

    call check_reals([expected], [actual], tolerance, no_shape, message, location)
  end subroutine assert_equal_r_0_0_tol

  subroutine assert_equal_r_1_1(expected, actual, message, location)
    real(real64), intent(in) :: expected(:), actual(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call assert_equal_r_1_1_tol(expected, actual, 0.0_real64, message, location)
  end subroutine assert_equal_r_1_1

  subroutine assert_equal_r_1_1_tol(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected(:), actual(:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (shapes_differ(shape(expected), shape(actual), message, location)) return
    call check_reals(expected, actual, tolerance, shape(actual), message, location)
  end subroutine assert_equal_r_1_1_tol

  subroutine assert_equal_r_2_2(expected, actual, message, location)
    real(real64), intent(in) :: expected(:,:), actual(:,:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call assert_equal_r_2_2_tol(expected, actual, 0.0_real64, message, location)
  end subroutine assert_equal_r_2_2

  subroutine assert_equal_r_2_2_tol(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected(:,:), actual(:,:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (shapes_differ(shape(expected), shape(actual), message, location)) return
    call check_reals(reshape(expected, [size(expected)]), reshape(actual, [size(actual)]), &
                     tolerance, shape(actual), message, location)
  end subroutine assert_equal_r_2_2_tol

  subroutine assert_equal_r_0_1(expected, actual, message, location)
    real(real64), intent(in) :: expected, actual(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call assert_equal_r_0_1_tol(expected, actual, 0.0_real64, message, location)
  end subroutine assert_equal_r_0_1

  subroutine assert_equal_r_0_1_tol(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected, actual(:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    real(real64) :: e(size(actual))

    e = expected
    call check_reals(e, actual, tolerance, shape(actual), message, location)
  end subroutine assert_equal_r_0_1_tol

  subroutine assert_equal_r_0_2(expected, actual, message, location)
    real(real64), intent(in) :: expected, actual(:,:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call assert_equal_r_0_2_tol(expected, actual, 0.0_real64, message, location)
  end subroutine assert_equal_r_0_2

  subroutine assert_equal_r_0_2_tol(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected, actual(:,:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    real(real64) :: e(size(actual))

    e = expected
    call check_reals(e, reshape(actual, [size(actual)]), tolerance, shape(actual), &
                     message, location)
  end subroutine assert_equal_r_0_2_tol

  ! ================================================================ relative ====

  subroutine assert_rel_equal_0_0(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected, actual, tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: no_shape(0)

    call check_reals_rel([expected], [actual], tolerance, no_shape, message, location)
  end subroutine assert_rel_equal_0_0

  subroutine assert_rel_equal_1_1(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected(:), actual(:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (shapes_differ(shape(expected), shape(actual), message, location)) return
    call check_reals_rel(expected, actual, tolerance, shape(actual), message, location)
  end subroutine assert_rel_equal_1_1

  subroutine assert_rel_equal_0_1(expected, actual, tolerance, message, location)
    real(real64), intent(in) :: expected, actual(:), tolerance
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    real(real64) :: e(size(actual))

    e = expected
    call check_reals_rel(e, actual, tolerance, shape(actual), message, location)
  end subroutine assert_rel_equal_0_1

  ! ========================================================= assertTrue/False ====

  subroutine assert_true_0(condition, message, location)
    logical, intent(in) :: condition
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (.not. condition) call record_failure('expected .true. but found .false.', &
                                             message, location)
  end subroutine assert_true_0

  subroutine assert_true_1(condition, message, location)
    logical, intent(in) :: condition(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_logicals(condition, .true., message, location)
  end subroutine assert_true_1

  subroutine assert_false_0(condition, message, location)
    logical, intent(in) :: condition
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (condition) call record_failure('expected .false. but found .true.', message, location)
  end subroutine assert_false_0

  subroutine assert_false_1(condition, message, location)
    logical, intent(in) :: condition(:)
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_logicals(condition, .false., message, location)
  end subroutine assert_false_1

  !> Every element of `condition` must equal `expected`.
  subroutine check_logicals(condition, expected, message, location)
    logical, intent(in) :: condition(:)
    logical, intent(in) :: expected
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    integer :: i, first, n_bad

    n_bad = 0
    first = 0
    do i = 1, size(condition)
      if (condition(i) .eqv. expected) cycle
      n_bad = n_bad + 1
      if (first == 0) first = i
    end do
    if (n_bad == 0) return
    call record_failure(where_str(first, shape(condition)) // 'expected ' // &
                        logical_str(expected) // ' but found ' // logical_str(.not. expected) // &
                        ' (' // int_str(n_bad) // ' of ' // int_str(size(condition)) // &
                        ' elements differ)', message, location)
  end subroutine check_logicals

  ! ================================================================ ordering ====

  !> Record a failure of lhs <op> rhs.
  subroutine fail_order(op, lhs, rhs, message, location)
    integer, intent(in) :: op
    character(len=*), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    character(len=2) :: sym

    select case (op)
    case (OP_LT)
      sym = '< '
    case (OP_LE)
      sym = '<='
    case (OP_GT)
      sym = '> '
    case default
      sym = '>='
    end select
    call record_failure('expected lhs ' // trim(sym) // ' rhs but found lhs = ' // lhs // &
                        ', rhs = ' // rhs, message, location)
  end subroutine fail_order

  !> lhs <op> rhs for reals; NaN never satisfies an ordering (checked without trapping).
  subroutine check_order_r(op, lhs, rhs, message, location)
    integer, intent(in) :: op
    real(real64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    logical :: ok

    if (ieee_is_nan(lhs) .or. ieee_is_nan(rhs)) then
      ok = .false.
    else
      select case (op)
      case (OP_LT)
        ok = lhs < rhs
      case (OP_LE)
        ok = lhs <= rhs
      case (OP_GT)
        ok = lhs > rhs
      case default
        ok = lhs >= rhs
      end select
    end if
    if (.not. ok) call fail_order(op, real_str(lhs), real_str(rhs), message, location)
  end subroutine check_order_r

  !> lhs <op> rhs for integers.
  subroutine check_order_i(op, lhs, rhs, message, location)
    integer, intent(in) :: op
    integer(int64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location
    logical :: ok

    select case (op)
    case (OP_LT)
      ok = lhs < rhs
    case (OP_LE)
      ok = lhs <= rhs
    case (OP_GT)
      ok = lhs > rhs
    case default
      ok = lhs >= rhs
    end select
    if (.not. ok) call fail_order(op, int8_str(lhs), int8_str(rhs), message, location)
  end subroutine check_order_i

  ! Real: (lhs, rhs, message, location), as pFUnit's no-tolerance overloads.
  subroutine assert_lt_r(lhs, rhs, message, location)
    real(real64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_order_r(OP_LT, lhs, rhs, message, location)
  end subroutine assert_lt_r

  subroutine assert_le_r(lhs, rhs, message, location)
    real(real64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_order_r(OP_LE, lhs, rhs, message, location)
  end subroutine assert_le_r

  subroutine assert_gt_r(lhs, rhs, message, location)
    real(real64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_order_r(OP_GT, lhs, rhs, message, location)
  end subroutine assert_gt_r

  subroutine assert_ge_r(lhs, rhs, message, location)
    real(real64), intent(in) :: lhs, rhs
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    call check_order_r(OP_GE, lhs, rhs, message, location)
  end subroutine assert_ge_r

  ! Integer: (lhs, rhs, unused, message, location), as pFUnit: message and location must
  ! be given by keyword.
  subroutine assert_lt_i(lhs, rhs, unused, message, location)
    integer, intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_LT, int(lhs, int64), int(rhs, int64), message, location)
  end subroutine assert_lt_i

  subroutine assert_le_i(lhs, rhs, unused, message, location)
    integer, intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_LE, int(lhs, int64), int(rhs, int64), message, location)
  end subroutine assert_le_i

  subroutine assert_gt_i(lhs, rhs, unused, message, location)
    integer, intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_GT, int(lhs, int64), int(rhs, int64), message, location)
  end subroutine assert_gt_i

  subroutine assert_ge_i(lhs, rhs, unused, message, location)
    integer, intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_GE, int(lhs, int64), int(rhs, int64), message, location)
  end subroutine assert_ge_i

  subroutine assert_lt_i8(lhs, rhs, unused, message, location)
    integer(int64), intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_LT, lhs, rhs, message, location)
  end subroutine assert_lt_i8

  subroutine assert_le_i8(lhs, rhs, unused, message, location)
    integer(int64), intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_LE, lhs, rhs, message, location)
  end subroutine assert_le_i8

  subroutine assert_gt_i8(lhs, rhs, unused, message, location)
    integer(int64), intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_GT, lhs, rhs, message, location)
  end subroutine assert_gt_i8

  subroutine assert_ge_i8(lhs, rhs, unused, message, location)
    integer(int64), intent(in) :: lhs, rhs
    class(KeywordEnforcer), optional, intent(in) :: unused
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (present(unused)) continue
    call check_order_i(OP_GE, lhs, rhs, message, location)
  end subroutine assert_ge_i8

  ! ================================================================= isFinite ====

  subroutine assert_is_finite_r(x, message, location)
    real(real64), intent(in) :: x
    character(len=*), optional, intent(in) :: message
    type(SourceLocation), optional, intent(in) :: location

    if (.not. ieee_is_finite(x)) call record_failure('expected a finite value but found ' // &
                                                     real_str(x), message, location)
  end subroutine assert_is_finite_r


  !> Reserved pFUnit name (see the public list); not part of the funit-lite subset.
  subroutine initialize()
    error stop 'funit-lite: initialize is a pFUnit name, not part of the supported subset'
  end subroutine initialize

  !> Reserved pFUnit name (see the public list); not part of the funit-lite subset.
  subroutine run()
    error stop 'funit-lite: run is a pFUnit name, not part of the supported subset'
  end subroutine run

  !> Reserved pFUnit name (see the public list); not part of the funit-lite subset.
  subroutine finalize()
    error stop 'funit-lite: finalize is a pFUnit name, not part of the supported subset'
  end subroutine finalize

  !> Reserved pFUnit name (see the public list); not part of the funit-lite subset.
  subroutine stub()
    error stop 'funit-lite: stub is a pFUnit name, not part of the supported subset'
  end subroutine stub
end module funit
