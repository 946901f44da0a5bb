!> File-system helpers through C interoperability (POSIX rename, remove, mkdir), used to
!> publish output files atomically and to create output folders.
module empm_files
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  implicit none
  private
  public :: empm_rename, empm_remove, empm_mkdir_p

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
    function c_mkdir(path, mode) bind(C, name='mkdir') result(r)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
      integer(c_int) :: r
    end function c_mkdir
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

  !> Create folder `path` and its missing parents (like `mkdir -p`); returns 0 when the folder
  !> exists afterwards.
  integer function empm_mkdir_p(path) result(info)
    character(len=*), intent(in) :: path !! folder to create
    integer :: i, r
    logical :: there
    do i = 2, len(path)
      if (path(i:i) == '/') r = int(c_mkdir(path(1:i - 1)//c_null_char, int(o'755', c_int)))
    end do
    r = int(c_mkdir(path//c_null_char, int(o'755', c_int)))
    inquire(file=path//'/.', exist=there)
    info = merge(0, 1, there)
  end function empm_mkdir_p
end module empm_files
