! Strict case-file validation: every kind of bad input gives EMPM_ERR_INPUT with a message
! naming the file, the group, the key and what was expected.
module test_input_validation
  use funit
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_ERR_INPUT, EMPM_OK
  use empm_case, only: empm_case_t
  use empm_input, only: empm_read_case
  implicit none

  character(len=*), parameter :: GOOD_GRID = "&grid ndim = 1, h = 1.0, cells = 12 /"
  character(len=*), parameter :: GOOD_MAT = "&material name = 'm', E = 100.0, density = 1.0 /"
  character(len=*), parameter :: GOOD_PART = "&particles material = 'm', lo = 0.0, hi = 10.0 /"
  character(len=*), parameter :: GOOD_INT = "&integrator t_end = 1.0 /"

contains

  ! Write `lines` to a scratch case file, read it, return the error.
  subroutine read_text(name, lines, err)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    type(empm_error_t), intent(out) :: err
    type(empm_case_t) :: cs
    integer :: u, i
    open(newunit=u, file=name, status='replace', action='write')
    do i = 1, size(lines)
      write(u, '(a)') trim(lines(i))
    end do
    close(u)
    call empm_read_case(name, cs, err)
    open(newunit=u, file=name, status='old')
    close(u, status='delete')
  end subroutine read_text

  ! Assert that reading fails as an input error whose message contains every fragment.
  subroutine expect_error(name, lines, fragments)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    character(len=*), intent(in) :: fragments(:)
    type(empm_error_t) :: err
    integer :: i
    call read_text(name, lines, err)
#line 43 "/work/main/tests/unit/test_input_validation.pf"
  call assertEqual(EMPM_ERR_INPUT, err%code, message=name, &
 & location=SourceLocation( &
 & 'test_input_validation.pf', &
 & 43) )
  if (anyExceptions()) return
#line 44 "/work/main/tests/unit/test_input_validation.pf"
    do i = 1, size(fragments)
#line 45 "/work/main/tests/unit/test_input_validation.pf"
  call assertTrue(index(err%message, trim(fragments(i))) > 0, message='missing "'//trim(fragments(i))//'" in: '//err%message, &
 & location=SourceLocation( &
 & 'test_input_validation.pf', &
 & 45) )
  if (anyExceptions()) return
#line 46 "/work/main/tests/unit/test_input_validation.pf"
    end do
  end subroutine expect_error

  !@test
  subroutine test_valid_case_reads()
    type(empm_error_t) :: err
    character(len=80) :: lines(4)
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT]
    call read_text('iv_valid.nml', lines, err)
#line 55 "/work/main/tests/unit/test_input_validation.pf"
  call assertEqual(EMPM_OK, err%code, &
 & location=SourceLocation( &
 & 'test_input_validation.pf', &
 & 55) )
  if (anyExceptions()) return
#line 56 "/work/main/tests/unit/test_input_validation.pf"
  end subroutine test_valid_case_reads

  !@test
  subroutine test_unknown_key()
    character(len=80) :: lines(4)
    lines = [character(len=80) :: "&grid ndim = 1, h = 1.0, cells = 12, spacing = 2 /", GOOD_MAT, GOOD_PART, GOOD_INT]
    call expect_error('iv_key.nml', lines, [character(len=20) :: 'iv_key.nml', '&grid', 'spacing', 'valid keys'])
  end subroutine test_unknown_key

  !@test
  subroutine test_unknown_group()
    character(len=80) :: lines(5)
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&grd ndim = 1 /"]
    call expect_error('iv_group.nml', lines, [character(len=20) :: 'iv_group.nml', '&grd', 'expected one of'])
  end subroutine test_unknown_group

  !@test
  subroutine test_missing_required_group_and_key()
    character(len=80) :: lines(3)
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART]
    call expect_error('iv_nogroup.nml', lines, [character(len=20) :: 'iv_nogroup.nml', '&integrator'])
    lines = [character(len=80) :: "&grid ndim = 1, cells = 12 /", GOOD_MAT, GOOD_PART]
    call expect_error('iv_nokey.nml', lines, [character(len=20) :: '&grid', '''h''', 'required'])
  end subroutine test_missing_required_group_and_key

  !@test
  subroutine test_out_of_range_values()
    character(len=80) :: lines(4)
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, "&integrator t_end = 1.0, cfl = 1.5 /"]
    call expect_error('iv_cfl.nml', lines, [character(len=20) :: '&integrator', '''cfl''', '0 < cfl <= 1'])
    lines = [character(len=80) :: GOOD_GRID, "&material name = 'm', E = 1.0, nu = 0.5, density = 1.0 /", GOOD_PART, GOOD_INT]
    call expect_error('iv_nu.nml', lines, [character(len=20) :: '&material', 'nu'])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, "&particles material = 'm', lo = 0.0, hi = 10.0, ppc = 7 /", GOOD_INT]
    call expect_error('iv_ppc.nml', lines, [character(len=20) :: '&particles', '''ppc''', '1..4'])
    lines = [character(len=80) :: "&grid ndim = 4, h = 1.0, cells = 12 /", GOOD_MAT, GOOD_PART, GOOD_INT]
    call expect_error('iv_ndim.nml', lines, [character(len=20) :: '&grid', '''ndim''', '1, 2 or 3'])
  end subroutine test_out_of_range_values

  !@test
  subroutine test_malformed_value()
    character(len=80) :: lines(4)
    lines = [character(len=80) :: "&grid ndim = 1, h = abc, cells = 12 /", GOOD_MAT, GOOD_PART, GOOD_INT]
    call expect_error('iv_bad.nml', lines, [character(len=20) :: 'iv_bad.nml', '&grid'])
  end subroutine test_malformed_value

  !@test
  subroutine test_inconsistent_combinations()
    character(len=80) :: lines(5)
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, "&particles material = 'steel', lo = 0.0, hi = 10.0 /", GOOD_INT, ""]
    call expect_error('iv_mat.nml', lines, [character(len=20) :: '&particles', '''material''', 'steel'])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&shape family = 'bspline3' /"]
    call expect_error('iv_pad.nml', lines, [character(len=20) :: 'bspline3', 'particle'])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&loads ramp = 'sine' /"]
    call expect_error('iv_ramp.nml', lines, [character(len=20) :: '&loads', 'ramp_time'])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&boundary lo = 0.5, hi = 0.6, fix = .true. /"]
    call expect_error('iv_bc.nml', lines, [character(len=20) :: '&boundary', 'no grid node'])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&probe name = 'p', particle = 999 /"]
    call expect_error('iv_probe.nml', lines, [character(len=20) :: '&probe', '''particle'''])
    lines = [character(len=80) :: GOOD_GRID, GOOD_MAT, GOOD_PART, GOOD_INT, "&shape family = 'quartic' /"]
    call expect_error('iv_family.nml', lines, [character(len=20) :: '&shape', 'quartic', 'linear'])
  end subroutine test_inconsistent_combinations
end module test_input_validation

module Wraptest_input_validation
   use FUnit
   use test_input_validation
   implicit none
   private

contains


end module Wraptest_input_validation

function test_input_validation_suite() result(suite)
   use FUnit
   use test_input_validation
   use Wraptest_input_validation
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_input_validation_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_valid_case_reads', &
      test_valid_case_reads))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_unknown_key', &
      test_unknown_key))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_unknown_group', &
      test_unknown_group))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_missing_required_group_and_key', &
      test_missing_required_group_and_key))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_out_of_range_values', &
      test_out_of_range_values))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_malformed_value', &
      test_malformed_value))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_inconsistent_combinations', &
      test_inconsistent_combinations))
   call suite%addTest(t)


end function test_input_validation_suite

