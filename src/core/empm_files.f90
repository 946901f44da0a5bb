!> File-system helpers through C interoperability (POSIX rename, remove, mkdir), used to
!> publish output files atomically and to create output folders.
module empm_files
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_size_t, c_ptr, &
    c_associated
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_error, only: empm_error_t, EMPM_ERR_IO
  implicit none
  private
  public :: empm_rename, empm_remove, empm_mkdir_p, empm_read_text, empm_physical_memory, &
            empm_proc_kib, empm_peak_memory, empm_rmdir, empm_absolute, empm_path_beside

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
    function c_rmdir(path) bind(C, name='rmdir') result(r)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int) :: r
    end function c_rmdir
    function c_getcwd(buf, size) bind(C, name='getcwd') result(p)
      import :: c_char, c_size_t, c_ptr
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_size_t), value :: size
      type(c_ptr) :: p
    end function c_getcwd
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

  !> `file` as named beside `ref`: relative to the folder of `ref` (a body file beside its
  !> case file, a snapshot beside its checkpoint); an absolute `file` is kept as is.
  pure function empm_path_beside(ref, file) result(path)
    character(len=*), intent(in) :: ref        !! the file `file` is named beside
    character(len=*), intent(in) :: file       !! as written there
    character(len=:), allocatable :: path      !! path to open
    integer :: s
    path = trim(adjustl(file))
    if (len(path) == 0) return
    if (path(1:1) == '/') return
    s = index(ref, '/', back=.true.)
    if (s > 0) path = ref(1:s)//path
  end function empm_path_beside

  !> Remove the folder `path` if it is empty (never a file); returns 0 on success.
  integer function empm_rmdir(path) result(info)
    character(len=*), intent(in) :: path !! folder to remove
    info = int(c_rmdir(path//c_null_char))
  end function empm_rmdir

  !> `path` made absolute against the working folder (unchanged when it starts with '/', or
  !> when the working folder cannot be read).
  function empm_absolute(path) result(abs_path)
    character(len=*), intent(in) :: path         !! a path
    character(len=:), allocatable :: abs_path    !! the same place, absolute
    character(kind=c_char) :: buf(4096)
    integer :: n
    abs_path = path
    if (len(path) > 0) then
      if (path(1:1) == '/') return
    end if
    if (.not. c_associated(c_getcwd(buf, int(size(buf), c_size_t)))) return
    n = 0
    do while (n < size(buf))
      if (buf(n + 1) == c_null_char) exit
      n = n + 1
    end do
    abs_path = transfer(buf(1:n), repeat(' ', n))//'/'//path
  end function empm_absolute

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

  !> The whole contents of the text file `path` (any line length). On failure `err` holds the
  !> run-time library's message (code EMPM_ERR_IO) and `text` is empty.
  subroutine empm_read_text(path, text, err)
    character(len=*), intent(in) :: path               !! file to read
    character(len=:), allocatable, intent(out) :: text !! its contents
    type(empm_error_t), intent(inout) :: err           !! set on failure
    integer :: u, ios, n
    character(len=512) :: msg
    text = ''
    open(newunit=u, file=path, status='old', action='read', access='stream', &
         form='unformatted', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call err%set(EMPM_ERR_IO, trim(msg)); return
    end if
    inquire(unit=u, size=n)
    if (n > 0) then
      deallocate(text)
      allocate(character(len=n) :: text)
      read(u, iostat=ios, iomsg=msg) text
      if (ios /= 0) then
        text = ''
        call err%set(EMPM_ERR_IO, trim(msg))
      end if
    end if
    close(u)
  end subroutine empm_read_text

  !> Physical memory of the machine [bytes] (MemTotal of /proc/meminfo), or -1 when unknown
  !> (not Linux): the limit a case's memory estimate is checked against.
  function empm_physical_memory() result(bytes)
    integer(int64) :: bytes !! physical memory [bytes], or -1
    bytes = empm_proc_kib('/proc/meminfo', 'MemTotal:')
    if (bytes > 0) bytes = 1024_int64 * bytes
  end function empm_physical_memory

  !> Peak resident memory of this process so far (VmHWM of /proc/self/status) [bytes]; −1
  !> when unavailable (not Linux).
  function empm_peak_memory() result(bytes)
    integer(int64) :: bytes !! peak resident memory [bytes], or −1
    bytes = empm_proc_kib('/proc/self/status', 'VmHWM:')
    if (bytes > 0) bytes = 1024_int64 * bytes
  end function empm_peak_memory

  !> The number after `key` on its line of a /proc file in kB (e.g. 'VmHWM:' of
  !> /proc/self/status), or -1 when the file or the key is missing.
  function empm_proc_kib(file, key) result(kib)
    character(len=*), intent(in) :: file !! e.g. '/proc/meminfo'
    character(len=*), intent(in) :: key  !! e.g. 'MemTotal:'
    integer(int64) :: kib                !! value [kB], or -1
    character(len=256) :: line
    integer :: u, ios
    kib = -1
    open(newunit=u, file=file, action='read', status='old', iostat=ios)
    if (ios /= 0) return
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, key) == 1) then
        read(line(len(key) + 1:), *, iostat=ios) kib
        if (ios /= 0) kib = -1
        exit
      end if
    end do
    close(u)
  end function empm_proc_kib
end module empm_files
