!> Whether a standard stream is a terminal (POSIX isatty through C interoperability), so that
!> progress lines are shown to people and kept out of logs and pipes.
module empm_terminal
  use, intrinsic :: iso_c_binding, only: c_int
  implicit none
  private
  public :: stderr_is_terminal

  interface
    function c_isatty(fd) bind(C, name='isatty') result(r)
      import :: c_int
      integer(c_int), value :: fd
      integer(c_int) :: r
    end function c_isatty
  end interface

contains

  !> True when file descriptor 2 (stderr) is a terminal.
  logical function stderr_is_terminal()
    stderr_is_terminal = c_isatty(2_c_int) == 1_c_int
  end function stderr_is_terminal
end module empm_terminal
