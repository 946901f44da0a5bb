!> Process-level helpers through C interoperability: whether stderr is a terminal (so progress
!> lines are shown to people and kept out of logs and pipes) and a quiet exit with a status.
module empm_terminal
  use, intrinsic :: iso_c_binding, only: c_int
  implicit none
  private
  public :: stderr_is_terminal, empm_exit

  interface
    function c_isatty(fd) bind(C, name='isatty') result(r)
      import :: c_int
      integer(c_int), value :: fd
      integer(c_int) :: r
    end function c_isatty
    subroutine c_exit(status) bind(C, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
  end interface

contains

  !> True when file descriptor 2 (stderr) is a terminal.
  logical function stderr_is_terminal()
    stderr_is_terminal = c_isatty(2_c_int) == 1_c_int
  end function stderr_is_terminal

  !> Terminate the process with exit `status`, without the compiler's "STOP n" banner.
  subroutine empm_exit(status)
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
    integer, intent(in) :: status !! process exit status
    flush(output_unit); flush(error_unit)
    call c_exit(int(status, c_int))
  end subroutine empm_exit
end module empm_terminal
