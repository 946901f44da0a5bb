!> Run-time loading of shared libraries (POSIX dlopen/dlsym/dlerror/dlclose through
!> ISO_C_BINDING), for user subroutines named in a case file (the `umat` material).
!>
!> Errors are returned as the loader's own message (dlerror), which names the file and the
!> reason ("cannot open shared object file: No such file or directory", "undefined symbol: x"):
!> the caller quotes it in its input error.
module empm_dynlib
  use, intrinsic :: iso_c_binding, only: c_ptr, c_funptr, c_char, c_int, c_null_char, &
    c_null_ptr, c_null_funptr, c_associated, c_f_pointer, c_size_t
  implicit none
  private
  public :: empm_dynlib_open, empm_dynlib_symbol, empm_dynlib_close

  ! <dlfcn.h> on Linux (glibc and musl): resolve every undefined symbol at load time, so that a
  ! library with a missing dependency fails here, where the message can name it, and not at the
  ! first call; keep the library's symbols local (two user libraries may both define `umat_`).
  integer(c_int), parameter :: RTLD_NOW = 2, RTLD_LOCAL = 0

  interface
    function c_dlopen(file, mode) bind(C, name='dlopen') result(h)
      import :: c_ptr, c_char, c_int
      character(kind=c_char), intent(in) :: file(*)
      integer(c_int), value :: mode
      type(c_ptr) :: h
    end function c_dlopen
    function c_dlsym(handle, name) bind(C, name='dlsym') result(f)
      import :: c_ptr, c_funptr, c_char
      type(c_ptr), value :: handle
      character(kind=c_char), intent(in) :: name(*)
      type(c_funptr) :: f
    end function c_dlsym
    function c_dlerror() bind(C, name='dlerror') result(s)
      import :: c_ptr
      type(c_ptr) :: s
    end function c_dlerror
    function c_dlclose(handle) bind(C, name='dlclose') result(r)
      import :: c_ptr, c_int
      type(c_ptr), value :: handle
      integer(c_int) :: r
    end function c_dlclose
    function c_strlen(s) bind(C, name='strlen') result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function c_strlen
  end interface

contains

  !> Load the shared library `path` (an absolute path, or one relative to the working folder;
  !> a name without '/' is searched for as dlopen does). On failure `handle` is null and `msg`
  !> holds the loader's message.
  subroutine empm_dynlib_open(path, handle, msg)
    character(len=*), intent(in) :: path                !! library file
    type(c_ptr), intent(out) :: handle                  !! library handle (null on failure)
    character(len=:), allocatable, intent(out) :: msg   !! '' or the loader's message
    handle = c_dlopen(trim(path)//c_null_char, ior(RTLD_NOW, RTLD_LOCAL))
    msg = ''
    if (.not. c_associated(handle)) msg = last_error('cannot load '//trim(path))
  end subroutine empm_dynlib_open

  !> Address of the function `name` (its external name, e.g. 'umat_' for gfortran's
  !> `SUBROUTINE UMAT`) in a loaded library. On failure `fun` is null and `msg` holds the
  !> loader's message.
  subroutine empm_dynlib_symbol(handle, name, fun, msg)
    type(c_ptr), intent(in) :: handle                   !! from [[empm_dynlib_open]]
    character(len=*), intent(in) :: name                !! symbol name
    type(c_funptr), intent(out) :: fun                  !! its address (null on failure)
    character(len=:), allocatable, intent(out) :: msg   !! '' or the loader's message
    type(c_ptr) :: prev
    prev = c_dlerror() ! clear a stale error: a null result is told from an error by dlerror
    fun = c_dlsym(handle, trim(name)//c_null_char)
    msg = ''
    if (.not. c_associated(fun)) then
      fun = c_null_funptr
      msg = last_error('symbol '''//trim(name)//''' not found')
    end if
  end subroutine empm_dynlib_symbol

  !> Unload a library (the handle becomes null). Nothing of it may be called afterwards.
  subroutine empm_dynlib_close(handle)
    type(c_ptr), intent(inout) :: handle !! from [[empm_dynlib_open]]
    integer(c_int) :: r
    if (c_associated(handle)) r = c_dlclose(handle)
    handle = c_null_ptr
  end subroutine empm_dynlib_close

  ! The pending dlerror() message as a Fortran string, or `fallback` when there is none.
  function last_error(fallback) result(msg)
    character(len=*), intent(in) :: fallback
    character(len=:), allocatable :: msg
    type(c_ptr) :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: n, i
    s = c_dlerror()
    if (.not. c_associated(s)) then
      msg = fallback
      return
    end if
    n = int(c_strlen(s))
    call c_f_pointer(s, chars, [n])
    allocate(character(len=n) :: msg)
    do i = 1, n
      msg(i:i) = chars(i)
    end do
  end function last_error
end module empm_dynlib
