!> Error reporting for drivers: an error object the caller may inspect, or a clean stop.
!>
!> Pure kernels return an integer status; public drivers take an optional
!> `type(empm_error_t)` out-argument. When the caller passes none, [[empm_raise]] prints the
!> message on stderr and stops with the status as exit code.
module empm_error
  use, intrinsic :: iso_fortran_env, only: error_unit
  implicit none
  private
  public :: empm_error_t, empm_raise, empm_clear
  public :: EMPM_OK, EMPM_ERR_USAGE, EMPM_ERR_INPUT, EMPM_ERR_RUNTIME, EMPM_ERR_IO

  integer, parameter :: EMPM_OK = 0          !! success
  integer, parameter :: EMPM_ERR_USAGE = 1   !! bad command line or API misuse
  integer, parameter :: EMPM_ERR_INPUT = 2   !! invalid case file or input value
  integer, parameter :: EMPM_ERR_RUNTIME = 3 !! run-time guard tripped (NaN, particle left grid, dt)
  integer, parameter :: EMPM_ERR_IO = 4      !! file system or HDF5 failure

  !> An error status with a human-readable message.
  type :: empm_error_t
    integer :: code = EMPM_OK                  !! one of the `EMPM_*` codes; 0 means no error
    character(len=:), allocatable :: message   !! what went wrong, where, and what was expected
  contains
    procedure :: ok => error_ok
  end type empm_error_t

contains

  !> True when no error is recorded.
  elemental logical function error_ok(self)
    class(empm_error_t), intent(in) :: self !! error object
    error_ok = self%code == EMPM_OK
  end function error_ok

  !> Reset an error object to "no error".
  subroutine empm_clear(err)
    type(empm_error_t), intent(inout) :: err !! error object to reset
    err%code = EMPM_OK
    if (allocated(err%message)) deallocate(err%message)
  end subroutine empm_clear

  !> Record an error in `err` if present, otherwise print it and stop with exit status `code`.
  subroutine empm_raise(code, message, err)
    integer, intent(in) :: code                         !! error code (`EMPM_ERR_*`)
    character(len=*), intent(in) :: message             !! full message
    type(empm_error_t), intent(out), optional :: err    !! receives the error when present
    if (present(err)) then
      err%code = code
      err%message = message
      return
    end if
    write(error_unit, '(a)') 'empm: error: '//message
    select case (code)
    case (EMPM_ERR_USAGE)
      error stop 1
    case (EMPM_ERR_INPUT)
      error stop 2
    case (EMPM_ERR_RUNTIME)
      error stop 3
    case default
      error stop 4
    end select
  end subroutine empm_raise
end module empm_error
