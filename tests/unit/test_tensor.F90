! Unit tests for empm_tensor: 3×3 helpers and Voigt conversions.
! Tolerances: entries built from small integers or halves are exact in binary floating point
! and are compared with tolerance 0; other results are a few rounded operations on O(1)
! numbers, so 1e-14 (≈ 45 ulp of 1) is round-off level with a safety margin.
module test_tensor
  use funit
  use empm_kinds, only: wp
  use empm_tensor, only: identity3, trace3, det3, sym3, voigt_to_mat, mat_to_voigt, voigt_ddot
  implicit none

  real(wp), parameter :: RTOL = 1.0e-14_wp !! round-off tolerance for O(1) results

contains

  ! Rotation by `angle` about the unit vector along `axis` (Rodrigues' formula).
  pure function rotation(axis, angle) result(R)
    real(wp), intent(in) :: axis(3), angle
    real(wp) :: R(3,3), n(3), K(3,3)
    n = axis / sqrt(sum(axis**2))
    K = reshape([0.0_wp, n(3), -n(2), -n(3), 0.0_wp, n(1), n(2), -n(1), 0.0_wp], [3, 3])
    R = identity3() + sin(angle) * K + (1.0_wp - cos(angle)) * matmul(K, K)
  end function rotation

  !@test
  subroutine test_identity_and_trace()
    real(wp) :: A(3,3)
    integer :: i, j
    A = identity3()
    do j = 1, 3
      do i = 1, 3
#line 31 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(merge(1.0_wp, 0.0_wp, i == j), A(i,j), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 31) )
  if (anyExceptions()) return
#line 32 "/work/main/tests/unit/test_tensor.pf"
      end do
    end do
#line 34 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(3.0_wp, trace3(A), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 34) )
  if (anyExceptions()) return
#line 35 "/work/main/tests/unit/test_tensor.pf"
    A = reshape([1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp, 7.0_wp, 8.0_wp, 9.0_wp], [3, 3])
#line 36 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(15.0_wp, trace3(A), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 36) )
  if (anyExceptions()) return
#line 37 "/work/main/tests/unit/test_tensor.pf"
  end subroutine test_identity_and_trace

  !@test
  subroutine test_det3_closed_forms()
    real(wp) :: A(3,3), P(3,3)
    ! Integer matrices: every product and sum is exact, so the determinant is exact.
    A = reshape([2.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 3.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 4.0_wp], [3, 3])
#line 44 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(18.0_wp, det3(A), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 44) )
  if (anyExceptions()) return
#line 45 "/work/main/tests/unit/test_tensor.pf"
    ! Non-symmetric: columns (1,4,7), (2,5,8), (3,6,10) → det = −3.
    A = reshape([1.0_wp, 4.0_wp, 7.0_wp, 2.0_wp, 5.0_wp, 8.0_wp, 3.0_wp, 6.0_wp, 10.0_wp], [3, 3])
#line 47 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(-3.0_wp, det3(A), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 47) )
  if (anyExceptions()) return
#line 48 "/work/main/tests/unit/test_tensor.pf"
    ! Singular (two equal rows) and an odd permutation.
    A = reshape([1.0_wp, 1.0_wp, 7.0_wp, 2.0_wp, 2.0_wp, 8.0_wp, 3.0_wp, 3.0_wp, 10.0_wp], [3, 3])
#line 50 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(0.0_wp, det3(A), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 50) )
  if (anyExceptions()) return
#line 51 "/work/main/tests/unit/test_tensor.pf"
    P = reshape([0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [3, 3])
#line 52 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(-1.0_wp, det3(P), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 52) )
  if (anyExceptions()) return
#line 53 "/work/main/tests/unit/test_tensor.pf"
  end subroutine test_det3_closed_forms

  !@test
  subroutine test_det3_rotation_and_product()
    real(wp) :: R(3,3), A(3,3), B(3,3)
    R = rotation([1.0_wp, 2.0_wp, 3.0_wp], 0.7_wp)
#line 59 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(1.0_wp, det3(R), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 59) )
  if (anyExceptions()) return
#line 60 "/work/main/tests/unit/test_tensor.pf"
    A = reshape([1.1_wp, 0.2_wp, -0.3_wp, 0.4_wp, 0.9_wp, 0.1_wp, 0.05_wp, -0.2_wp, 1.3_wp], [3, 3])
    B = reshape([0.8_wp, -0.1_wp, 0.2_wp, 0.3_wp, 1.2_wp, 0.0_wp, -0.4_wp, 0.6_wp, 0.7_wp], [3, 3])
#line 62 "/work/main/tests/unit/test_tensor.pf"
  call assertRelativelyEqual(det3(A) * det3(B), det3(matmul(A, B)), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 62) )
  if (anyExceptions()) return
#line 63 "/work/main/tests/unit/test_tensor.pf"
  end subroutine test_det3_rotation_and_product

  !@test
  subroutine test_voigt_layout_and_round_trip()
    real(wp) :: s(6), A(3,3), t(6)
    integer :: k
    s = [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp]
    A = voigt_to_mat(s)
    ! Voigt order xx, yy, zz, yz, xz, xy; tensor shears (no factor 2).
#line 72 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(1.0_wp, A(1,1), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 72) )
  if (anyExceptions()) return
#line 73 "/work/main/tests/unit/test_tensor.pf"
#line 73 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(2.0_wp, A(2,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 73) )
  if (anyExceptions()) return
#line 74 "/work/main/tests/unit/test_tensor.pf"
#line 74 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(3.0_wp, A(3,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 74) )
  if (anyExceptions()) return
#line 75 "/work/main/tests/unit/test_tensor.pf"
#line 75 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(4.0_wp, A(2,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 75) )
  if (anyExceptions()) return
#line 76 "/work/main/tests/unit/test_tensor.pf"
#line 76 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(4.0_wp, A(3,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 76) )
  if (anyExceptions()) return
#line 77 "/work/main/tests/unit/test_tensor.pf"
#line 77 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(5.0_wp, A(1,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 77) )
  if (anyExceptions()) return
#line 78 "/work/main/tests/unit/test_tensor.pf"
#line 78 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(5.0_wp, A(3,1), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 78) )
  if (anyExceptions()) return
#line 79 "/work/main/tests/unit/test_tensor.pf"
#line 79 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(6.0_wp, A(1,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 79) )
  if (anyExceptions()) return
#line 80 "/work/main/tests/unit/test_tensor.pf"
#line 80 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(6.0_wp, A(2,1), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 80) )
  if (anyExceptions()) return
#line 81 "/work/main/tests/unit/test_tensor.pf"
    t = mat_to_voigt(A)
    do k = 1, 6
#line 83 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(s(k), t(k), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 83) )
  if (anyExceptions()) return
#line 84 "/work/main/tests/unit/test_tensor.pf"
    end do
  end subroutine test_voigt_layout_and_round_trip

  !@test
  subroutine test_mat_to_voigt_takes_symmetric_part()
    real(wp) :: A(3,3), s(6), S3(3,3)
    integer :: i, j
    A = reshape([1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp, 7.0_wp, 8.0_wp, 9.0_wp], [3, 3])
    s = mat_to_voigt(A)
#line 93 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(1.0_wp, s(1), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 93) )
  if (anyExceptions()) return
#line 94 "/work/main/tests/unit/test_tensor.pf"
#line 94 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(5.0_wp, s(2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 94) )
  if (anyExceptions()) return
#line 95 "/work/main/tests/unit/test_tensor.pf"
#line 95 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(9.0_wp, s(3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 95) )
  if (anyExceptions()) return
#line 96 "/work/main/tests/unit/test_tensor.pf"
    ! Shears: (A23 + A32)/2 = (8 + 6)/2, (A13 + A31)/2 = (7 + 3)/2, (A12 + A21)/2 = (4 + 2)/2.
#line 97 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(7.0_wp, s(4), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 97) )
  if (anyExceptions()) return
#line 98 "/work/main/tests/unit/test_tensor.pf"
#line 98 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(5.0_wp, s(5), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 98) )
  if (anyExceptions()) return
#line 99 "/work/main/tests/unit/test_tensor.pf"
#line 99 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(3.0_wp, s(6), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 99) )
  if (anyExceptions()) return
#line 100 "/work/main/tests/unit/test_tensor.pf"
    S3 = sym3(A)
    do j = 1, 3
      do i = 1, 3
#line 103 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(0.5_wp * (A(i,j) + A(j,i)), S3(i,j), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 103) )
  if (anyExceptions()) return
#line 104 "/work/main/tests/unit/test_tensor.pf"
#line 104 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(S3(j,i), S3(i,j), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 104) )
  if (anyExceptions()) return
#line 105 "/work/main/tests/unit/test_tensor.pf"
      end do
    end do
  end subroutine test_mat_to_voigt_takes_symmetric_part

  !@test
  subroutine test_voigt_ddot_counts_shears_twice()
    real(wp) :: a(6), b(6)
    a = [1.0_wp, -2.0_wp, 0.5_wp, 0.25_wp, -1.5_wp, 3.0_wp]
    b = [0.3_wp, 1.7_wp, -0.9_wp, 2.2_wp, 0.6_wp, -0.4_wp]
#line 114 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(sum(voigt_to_mat(a) * voigt_to_mat(b)), voigt_ddot(a, b), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 114) )
  if (anyExceptions()) return
#line 115 "/work/main/tests/unit/test_tensor.pf"
    ! Pure shear: only the xy pair contributes, twice.
    a = [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 3.0_wp]
#line 117 "/work/main/tests/unit/test_tensor.pf"
  call assertEqual(18.0_wp, voigt_ddot(a, a), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_tensor.pf', &
 & 117) )
  if (anyExceptions()) return
#line 118 "/work/main/tests/unit/test_tensor.pf"
  end subroutine test_voigt_ddot_counts_shears_twice
end module test_tensor

module Wraptest_tensor
   use FUnit
   use test_tensor
   implicit none
   private

contains


end module Wraptest_tensor

function test_tensor_suite() result(suite)
   use FUnit
   use test_tensor
   use Wraptest_tensor
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_tensor_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_identity_and_trace', &
      test_identity_and_trace))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_det3_closed_forms', &
      test_det3_closed_forms))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_det3_rotation_and_product', &
      test_det3_rotation_and_product))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_voigt_layout_and_round_trip', &
      test_voigt_layout_and_round_trip))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_mat_to_voigt_takes_symmetric_part', &
      test_mat_to_voigt_takes_symmetric_part))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_voigt_ddot_counts_shears_twice', &
      test_voigt_ddot_counts_shears_twice))
   call suite%addTest(t)


end function test_tensor_suite

