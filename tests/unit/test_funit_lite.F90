! Every assertion form of the supported .pf subset (docs/testing.md), all passing.
! Runs under real pFUnit 4.x and under funit-lite alike; funit-lite's failure reports are
! checked separately by tests/funit_lite/selftest/failing_example.pf.
module test_funit_lite
  use funit
  use, intrinsic :: iso_fortran_env, only: real64, int64
  implicit none

  integer :: n_before = 0               ! calls of set_up so far
  integer :: n_after = 0                ! calls of tear_down so far
  real(real64) :: fixture(3) = -1.0_real64

contains

  !@before
  subroutine set_up()
    n_before = n_before + 1
    fixture = [1.0_real64, 2.0_real64, 3.0_real64]
  end subroutine set_up

  !@after
  subroutine tear_down()
    n_after = n_after + 1
    fixture = -1.0_real64
  end subroutine tear_down

  !@test
  subroutine test_before_after()
    ! set_up ran before this test and tear_down after every earlier one, whatever the order
#line 30 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(n_after + 1, n_before, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 30) )
  if (anyExceptions()) return
#line 31 "/work/main/tests/unit/test_funit_lite.pf"
#line 31 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual([1.0_real64, 2.0_real64, 3.0_real64], fixture, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 31) )
  if (anyExceptions()) return
#line 32 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_before_after

  !@test
  subroutine test_equal_integer()
    integer :: iv(3), zeros(4)
    integer(int64) :: n8

    iv = [1, 2, 3]
    zeros = 0
    n8 = 3_int64
#line 42 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(2, 1 + 1, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 42) )
  if (anyExceptions()) return
#line 43 "/work/main/tests/unit/test_funit_lite.pf"
#line 43 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(2, size(iv) - 1, message='nodes', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 43) )
  if (anyExceptions()) return
#line 44 "/work/main/tests/unit/test_funit_lite.pf"
#line 44 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(3, size(iv), 'positional message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 44) )
  if (anyExceptions()) return
#line 45 "/work/main/tests/unit/test_funit_lite.pf"
#line 45 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(expected=3, actual=size(iv), &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 45) )
  if (anyExceptions()) return
#line 46 "/work/main/tests/unit/test_funit_lite.pf"
#line 46 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual([1, 2, 3], iv, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 46) )
  if (anyExceptions()) return
#line 47 "/work/main/tests/unit/test_funit_lite.pf"
#line 47 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(0, zeros, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 47) )
  if (anyExceptions()) return
#line 48 "/work/main/tests/unit/test_funit_lite.pf"
#line 48 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(3_int64, n8, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 48) )
  if (anyExceptions()) return
#line 49 "/work/main/tests/unit/test_funit_lite.pf"
#line 49 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(3, n8, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 49) )
  if (anyExceptions()) return
#line 50 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_equal_integer

  !@test
  subroutine test_equal_string()
#line 54 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual('abc', 'abc', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 54) )
  if (anyExceptions()) return
#line 55 "/work/main/tests/unit/test_funit_lite.pf"
#line 55 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual('abc', 'abc   ', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 55) )
  if (anyExceptions()) return
#line 56 "/work/main/tests/unit/test_funit_lite.pf"
#line 56 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual('abc', '  abc', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 56) )
  if (anyExceptions()) return
#line 57 "/work/main/tests/unit/test_funit_lite.pf"
#line 57 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(expected='x', found='x', message='keywords', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 57) )
  if (anyExceptions()) return
#line 58 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_equal_string

  !@test
  subroutine test_equal_real_scalar()
    real(real64) :: x

    x = 1.0_real64 + 1.0e-14_real64
#line 65 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(0.5_real64, 0.25_real64 + 0.25_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 65) )
  if (anyExceptions()) return
#line 66 "/work/main/tests/unit/test_funit_lite.pf"
#line 66 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(1.0_real64, x, tolerance=1.0e-12_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 66) )
  if (anyExceptions()) return
#line 67 "/work/main/tests/unit/test_funit_lite.pf"
#line 67 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(1.0_real64, x, 1.0e-12_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 67) )
  if (anyExceptions()) return
#line 68 "/work/main/tests/unit/test_funit_lite.pf"
#line 68 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(1.0_real64, x, 1.0e-12_real64, 'positional message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 68) )
  if (anyExceptions()) return
#line 69 "/work/main/tests/unit/test_funit_lite.pf"
#line 69 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(1.0_real64, x, tolerance=1.0e-12_real64, message='keyword message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 69) )
  if (anyExceptions()) return
#line 70 "/work/main/tests/unit/test_funit_lite.pf"
#line 70 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(expected=1.0_real64, actual=x, tolerance=1.0e-12_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 70) )
  if (anyExceptions()) return
#line 71 "/work/main/tests/unit/test_funit_lite.pf"
#line 71 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(huge(x), huge(x), &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 71) )
  if (anyExceptions()) return
#line 72 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_equal_real_scalar

  !@test
  subroutine test_equal_real_arrays()
    real(real64) :: v(3), m(2, 3)

    v = [1.0_real64, 2.0_real64, 3.0_real64]
    m = reshape([1.0_real64, 2.0_real64, 3.0_real64, 4.0_real64, 5.0_real64, 6.0_real64], &
                [2, 3])
#line 81 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual([1.0_real64, 2.0_real64, 3.0_real64], v, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 81) )
  if (anyExceptions()) return
#line 82 "/work/main/tests/unit/test_funit_lite.pf"
#line 82 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual([1.0_real64, 2.0_real64, 3.0_real64] + 1.0e-14_real64, v, 1.0e-12_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 82) )
  if (anyExceptions()) return
#line 83 "/work/main/tests/unit/test_funit_lite.pf"
#line 83 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(m, m, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 83) )
  if (anyExceptions()) return
#line 84 "/work/main/tests/unit/test_funit_lite.pf"
#line 84 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(m + 1.0e-14_real64, m, tolerance=1.0e-12_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 84) )
  if (anyExceptions()) return
#line 85 "/work/main/tests/unit/test_funit_lite.pf"
#line 85 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(2.0_real64, v, tolerance=1.0_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 85) )
  if (anyExceptions()) return
#line 86 "/work/main/tests/unit/test_funit_lite.pf"
#line 86 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(3.5_real64, m, 2.5_real64, message='scalar expected, rank-2 actual', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 86) )
  if (anyExceptions()) return
#line 87 "/work/main/tests/unit/test_funit_lite.pf"
#line 87 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(0.0_real64, v - v, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 87) )
  if (anyExceptions()) return
#line 88 "/work/main/tests/unit/test_funit_lite.pf"
#line 88 "/work/main/tests/unit/test_funit_lite.pf"
  call assertEqual(0.0_real64, m - m, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 88) )
  if (anyExceptions()) return
#line 89 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_equal_real_arrays

  !@test
  subroutine test_relatively_equal()
    real(real64) :: v(3)

    v = [1.0e6_real64, 2.0e6_real64, 3.0e6_real64]
#line 96 "/work/main/tests/unit/test_funit_lite.pf"
  call assertRelativelyEqual(1.0e6_real64, 1.0e6_real64 + 0.5_real64, 1.0e-6_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 96) )
  if (anyExceptions()) return
#line 97 "/work/main/tests/unit/test_funit_lite.pf"
#line 97 "/work/main/tests/unit/test_funit_lite.pf"
  call assertRelativelyEqual(-2.0_real64, -2.0_real64 * (1.0_real64 + 1.0e-9_real64), 1.0e-8_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 97) )
  if (anyExceptions()) return
#line 98 "/work/main/tests/unit/test_funit_lite.pf"
#line 98 "/work/main/tests/unit/test_funit_lite.pf"
  call assertRelativelyEqual([1.0e6_real64, 2.0e6_real64, 3.0e6_real64] + 1.0_real64, v, 1.0e-6_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 98) )
  if (anyExceptions()) return
#line 99 "/work/main/tests/unit/test_funit_lite.pf"
#line 99 "/work/main/tests/unit/test_funit_lite.pf"
  call assertRelativelyEqual(2.0e6_real64, v, 0.5_real64, message='scalar expected', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 99) )
  if (anyExceptions()) return
#line 100 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_relatively_equal

  !@test
  subroutine test_true_false()
    logical :: flags(3)

    flags = .true.
#line 107 "/work/main/tests/unit/test_funit_lite.pf"
  call assertTrue(1 < 2, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 107) )
  if (anyExceptions()) return
#line 108 "/work/main/tests/unit/test_funit_lite.pf"
#line 108 "/work/main/tests/unit/test_funit_lite.pf"
  call assertTrue(flags, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 108) )
  if (anyExceptions()) return
#line 109 "/work/main/tests/unit/test_funit_lite.pf"
#line 109 "/work/main/tests/unit/test_funit_lite.pf"
  call assertTrue(size(flags) == 3, message='size', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 109) )
  if (anyExceptions()) return
#line 110 "/work/main/tests/unit/test_funit_lite.pf"
#line 110 "/work/main/tests/unit/test_funit_lite.pf"
  call assertFalse(1 > 2, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 110) )
  if (anyExceptions()) return
#line 111 "/work/main/tests/unit/test_funit_lite.pf"
#line 111 "/work/main/tests/unit/test_funit_lite.pf"
  call assertFalse(.not. flags, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 111) )
  if (anyExceptions()) return
#line 112 "/work/main/tests/unit/test_funit_lite.pf"
#line 112 "/work/main/tests/unit/test_funit_lite.pf"
  call assertFalse(size(flags) == 4, 'positional message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 112) )
  if (anyExceptions()) return
#line 113 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_true_false

  !@test
  subroutine test_ordering_real()
#line 117 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThan(1.0_real64, 2.0_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 117) )
  if (anyExceptions()) return
#line 118 "/work/main/tests/unit/test_funit_lite.pf"
#line 118 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThanOrEqual(2.0_real64, 2.0_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 118) )
  if (anyExceptions()) return
#line 119 "/work/main/tests/unit/test_funit_lite.pf"
#line 119 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThanOrEqual(1.0_real64, 2.0_real64, 'positional message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 119) )
  if (anyExceptions()) return
#line 120 "/work/main/tests/unit/test_funit_lite.pf"
#line 120 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThan(3.0_real64, 2.0_real64, message='keyword message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 120) )
  if (anyExceptions()) return
#line 121 "/work/main/tests/unit/test_funit_lite.pf"
#line 121 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThanOrEqual(2.0_real64, 2.0_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 121) )
  if (anyExceptions()) return
#line 122 "/work/main/tests/unit/test_funit_lite.pf"
#line 122 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThanOrEqual(-huge(1.0_real64), -huge(1.0_real64), &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 122) )
  if (anyExceptions()) return
#line 123 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_ordering_real

  !@test
  subroutine test_ordering_integer()
    integer(int64) :: big

    big = huge(big)
#line 130 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThan(1, 2, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 130) )
  if (anyExceptions()) return
#line 131 "/work/main/tests/unit/test_funit_lite.pf"
#line 131 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThanOrEqual(2, 2, message='keyword message', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 131) )
  if (anyExceptions()) return
#line 132 "/work/main/tests/unit/test_funit_lite.pf"
#line 132 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThan(3, 2, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 132) )
  if (anyExceptions()) return
#line 133 "/work/main/tests/unit/test_funit_lite.pf"
#line 133 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThanOrEqual(2, 2, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 133) )
  if (anyExceptions()) return
#line 134 "/work/main/tests/unit/test_funit_lite.pf"
#line 134 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThan(1_int64, big, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 134) )
  if (anyExceptions()) return
#line 135 "/work/main/tests/unit/test_funit_lite.pf"
#line 135 "/work/main/tests/unit/test_funit_lite.pf"
  call assertLessThanOrEqual(big, big, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 135) )
  if (anyExceptions()) return
#line 136 "/work/main/tests/unit/test_funit_lite.pf"
#line 136 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThan(big, 0_int64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 136) )
  if (anyExceptions()) return
#line 137 "/work/main/tests/unit/test_funit_lite.pf"
#line 137 "/work/main/tests/unit/test_funit_lite.pf"
  call assertGreaterThanOrEqual(big, big, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 137) )
  if (anyExceptions()) return
#line 138 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_ordering_integer

  !@test
  subroutine test_is_finite()
    real(real64) :: x

    x = huge(x)
#line 145 "/work/main/tests/unit/test_funit_lite.pf"
  call assertIsFinite(x, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 145) )
  if (anyExceptions()) return
#line 146 "/work/main/tests/unit/test_funit_lite.pf"
#line 146 "/work/main/tests/unit/test_funit_lite.pf"
  call assertIsFinite(-tiny(x), message='smallest normal', &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 146) )
  if (anyExceptions()) return
#line 147 "/work/main/tests/unit/test_funit_lite.pf"
#line 147 "/work/main/tests/unit/test_funit_lite.pf"
  call assertIsFinite(0.0_real64, &
 & location=SourceLocation( &
 & 'test_funit_lite.pf', &
 & 147) )
  if (anyExceptions()) return
#line 148 "/work/main/tests/unit/test_funit_lite.pf"
  end subroutine test_is_finite

end module test_funit_lite

module Wraptest_funit_lite
   use FUnit
   use test_funit_lite
   implicit none
   private

contains


end module Wraptest_funit_lite

function test_funit_lite_suite() result(suite)
   use FUnit
   use test_funit_lite
   use Wraptest_funit_lite
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_funit_lite_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_before_after', &
      test_before_after, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_equal_integer', &
      test_equal_integer, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_equal_string', &
      test_equal_string, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_equal_real_scalar', &
      test_equal_real_scalar, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_equal_real_arrays', &
      test_equal_real_arrays, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_relatively_equal', &
      test_relatively_equal, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_true_false', &
      test_true_false, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ordering_real', &
      test_ordering_real, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_ordering_integer', &
      test_ordering_integer, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_is_finite', &
      test_is_finite, setUp=set_up, tearDown=tear_down))
   call suite%addTest(t)


end function test_funit_lite_suite

