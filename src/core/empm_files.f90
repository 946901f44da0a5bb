!> File-system helpers through C interoperability (POSIX rename and remove), used to publish
!> output files atomically.
module empm_files
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  implicit none
  private
  public :: empm_rename, empm_remove

  interface
    function c_rename(old, new) bind(C, name='rename') result(r)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old(*), new(*)
      integer(c_int) :: r
    end function c_rename
    function c_remove(path) bind(C, name='remove') result(r)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int) :: r
    end function c_remove
  end interface

contains

  !> Rename `old` to `new` atomically (same file system); returns 0 on success.
  integer function empm_rename(old, new) result(info)
    character(len=*), intent(in) :: old !! existing path
    character(len=*), intent(in) :: new !! new path (replaced if it exists)
    info = int(c_rename(old//c_null_char, new//c_null_char))
  end function empm_rename

  !> Remove a file if it exists; returns 0 on success.
  integer function empm_remove(path) result(info)
    character(len=*), intent(in) :: path !! file to remove
    info = int(c_remove(path//c_null_char))
  end function empm_remove
end module empm_files
