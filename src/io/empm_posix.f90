!> Operating-system queries the output needs and Fortran does not offer (POSIX and Linux
!> through C interoperability): the process id and whether a process is alive (output locks),
!> the kind of an existing path (an output must be a regular file), the text of `errno` (the
!> reason of a failed write), ignoring SIGXFSZ (so that exceeding the file-size limit is a
!> failed write, reported, not a killed process), a short sleep (the thread choice of
!> `empm run` measuring the machine's load) and the files matching a pattern (glob: a killed
!> run's partial files).
module empm_posix
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_ptr, c_funptr, &
    c_intptr_t, c_f_pointer, c_associated, c_int16_t, c_funloc, c_null_funptr, c_null_ptr, &
    c_size_t
  implicit none
  private
  public :: empm_getpid, empm_process_alive, empm_path_kind, empm_errno, empm_errno_text, &
            empm_ignore_sigxfsz, empm_catch_stop_signals, empm_stop_signal, empm_write_reason, &
            empm_sleep, empm_glob
  public :: PATH_MISSING, PATH_REGULAR, PATH_DIRECTORY, PATH_OTHER

  integer, parameter :: PATH_MISSING = 0   !! nothing at the path (or it cannot be examined)
  integer, parameter :: PATH_REGULAR = 1   !! a regular file (after following symbolic links)
  integer, parameter :: PATH_DIRECTORY = 2 !! a folder
  integer, parameter :: PATH_OTHER = 3     !! a device, FIFO or socket

  interface
    function c_getpid() bind(C, name='getpid') result(pid)
      import :: c_int
      integer(c_int) :: pid
    end function c_getpid
    function c_kill(pid, sig) bind(C, name='kill') result(r)
      import :: c_int
      integer(c_int), value :: pid, sig
      integer(c_int) :: r
    end function c_kill
    function c_statx(dirfd, path, flags, mask, buf) bind(C, name='statx') result(r)
      import :: c_int, c_char, c_int16_t
      integer(c_int), value :: dirfd, flags, mask
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int16_t), intent(out) :: buf(128)
      integer(c_int) :: r
    end function c_statx
    function c_errno_location() bind(C, name='__errno_location') result(p)
      import :: c_ptr
      type(c_ptr) :: p
    end function c_errno_location
    function c_strerror(errnum) bind(C, name='strerror') result(p)
      import :: c_int, c_ptr
      integer(c_int), value :: errnum
      type(c_ptr) :: p
    end function c_strerror
    function c_usleep(usec) bind(C, name='usleep') result(r)
      import :: c_int
      integer(c_int), value :: usec
      integer(c_int) :: r
    end function c_usleep
    function c_signal(sig, handler) bind(C, name='signal') result(old)
      import :: c_int, c_funptr
      integer(c_int), value :: sig
      type(c_funptr), value :: handler
      type(c_funptr) :: old
    end function c_signal
    ! glob_t is passed as the address of a buffer larger than glibc's (72 bytes on 64-bit
    ! Linux), whose first two members are size_t gl_pathc and char **gl_pathv.
    function c_glob(pattern, flags, errfunc, pglob) bind(C, name='glob') result(r)
      import :: c_char, c_int, c_funptr, c_ptr
      character(kind=c_char), intent(in) :: pattern(*)
      integer(c_int), value :: flags
      type(c_funptr), value :: errfunc
      type(c_ptr), intent(inout) :: pglob(16)
      integer(c_int) :: r
    end function c_glob
    subroutine c_globfree(pglob) bind(C, name='globfree')
      import :: c_ptr
      type(c_ptr), intent(inout) :: pglob(16)
    end subroutine c_globfree
    function c_strlen(s) bind(C, name='strlen') result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function c_strlen
  end interface

  ! Linux constants (the same on every architecture gfortran targets there except MIPS/SPARC,
  ! which empm does not support).
  integer(c_int), parameter :: AT_FDCWD = -100, STATX_TYPE = 1, SIGXFSZ = 25
  integer(c_int), parameter :: SIGINT = 2, SIGTERM = 15

  !> The stop signal caught (0: none). Written only by the handler, read by the time loop.
  integer(c_int), volatile, save :: caught = 0
  integer, parameter :: S_IFMT = int(o'170000'), S_IFREG = int(o'100000'), &
                        S_IFDIR = int(o'040000')

contains

  !> Sleep for `seconds` (at most 1 s at a time; interrupted early by a signal).
  subroutine empm_sleep(seconds)
    real, intent(in) :: seconds !! duration [s], 0 to 1
    integer(c_int) :: r
    r = c_usleep(int(max(0.0, min(1.0, seconds)) * 1.0e6, c_int))
  end subroutine empm_sleep

  !> The paths matching the shell pattern `pattern` (`*`, `?`, `[...]`; a metacharacter of a
  !> literal part escaped with `\`), sorted; none when nothing matches or the search fails.
  subroutine empm_glob(pattern, names)
    character(len=*), intent(in) :: pattern                   !! shell pattern
    character(len=4096), allocatable, intent(out) :: names(:) !! matching paths
    type(c_ptr) :: g(16)
    type(c_ptr), pointer :: pathv(:)
    character(kind=c_char), pointer :: chars(:)
    integer(c_intptr_t) :: npath
    integer :: k, j, n
    g = c_null_ptr
    allocate(names(0))
    if (c_glob(pattern//c_null_char, 0_c_int, c_null_funptr, g) == 0) then
      npath = transfer(g(1), npath)
      if (npath > 0 .and. c_associated(g(2))) then
        call c_f_pointer(g(2), pathv, [int(npath)])
        deallocate(names)
        allocate(names(int(npath)))
        do k = 1, int(npath)
          n = int(min(c_strlen(pathv(k)), int(len(names), c_size_t)))
          call c_f_pointer(pathv(k), chars, [n])
          names(k) = ''
          do j = 1, n
            names(k)(j:j) = chars(j)
          end do
        end do
      end if
    end if
    call c_globfree(g)
  end subroutine empm_glob

  !> The id of this process.
  integer function empm_getpid() result(pid)
    pid = int(c_getpid())
  end function empm_getpid

  !> Whether process `pid` exists (on this machine).
  logical function empm_process_alive(pid) result(alive)
    integer, intent(in) :: pid !! process id
    alive = .false.
    if (pid <= 0) return
    ! Signal 0 checks existence only; it fails for another user's process too (EPERM), which
    ! /proc still shows.
    alive = c_kill(int(pid, c_int), 0_c_int) == 0
    if (.not. alive) inquire(file='/proc/'//itoa(pid)//'/.', exist=alive)
  end function empm_process_alive

  !> What is at `path`: PATH_MISSING, PATH_REGULAR, PATH_DIRECTORY or PATH_OTHER. Symbolic
  !> links are followed (a link to a regular file is a regular file).
  integer function empm_path_kind(path) result(kind)
    character(len=*), intent(in) :: path !! file or folder
    integer(c_int16_t) :: buf(128)  ! struct statx: 256 bytes, the same layout on every Linux
    integer :: mode
    buf = 0
    kind = PATH_MISSING
    if (c_statx(AT_FDCWD, path//c_null_char, 0_c_int, STATX_TYPE, buf) /= 0) return
    ! stx_mode: the 16-bit field at byte offset 28 (element 15 of 2-byte units).
    mode = iand(int(buf(15)), 65535)
    select case (iand(mode, S_IFMT))
    case (S_IFREG); kind = PATH_REGULAR
    case (S_IFDIR); kind = PATH_DIRECTORY
    case default;   kind = PATH_OTHER
    end select
  end function empm_path_kind

  !> The current value of `errno` (the reason of the last failed system call).
  integer function empm_errno() result(e)
    integer(c_int), pointer :: p
    call c_f_pointer(c_errno_location(), p)
    e = int(p)
  end function empm_errno

  !> The system's text for error number `e` (e.g. 'No space left on device').
  function empm_errno_text(e) result(text)
    integer, intent(in) :: e              !! error number (errno)
    character(len=:), allocatable :: text !! its description
    type(c_ptr) :: p
    character(kind=c_char), pointer :: s(:)
    integer :: n, k
    text = 'error '//itoa(e)
    p = c_strerror(int(e, c_int))
    if (.not. c_associated(p)) return
    call c_f_pointer(p, s, [512])
    n = 0
    do while (n < 512)
      if (s(n + 1) == c_null_char) exit
      n = n + 1
    end do
    if (n == 0) return
    deallocate(text)
    allocate(character(len=n) :: text)
    do k = 1, n
      text(k:k) = s(k)
    end do
  end function empm_errno_text

  !> Why a write failed, for a message: the system's text for `code` (an errno), or, when the
  !> system gave none (0), that the HDF5 library reported the error.
  function empm_write_reason(code) result(r)
    integer, intent(in) :: code            !! errno after the failed call, or 0
    character(len=:), allocatable :: r     !! the reason
    if (code > 0) then
      r = empm_errno_text(code)
    else
      r = 'the HDF5 library reports an error'
    end if
  end function empm_write_reason

  !> Ignore SIGXFSZ, so that a write beyond the file-size limit (`ulimit -f`) fails with EFBIG
  !> and is reported as an I/O error instead of killing the process (the Fortran run-time
  !> library's handler would print a backtrace).
  subroutine empm_ignore_sigxfsz()
    type(c_funptr) :: old
    type(c_funptr) :: ign
    ign = transfer(1_c_intptr_t, ign)  ! SIG_IGN
    old = c_signal(SIGXFSZ, ign)
  end subroutine empm_ignore_sigxfsz

  !> Catch SIGINT and SIGTERM: the handler only records the signal (async-signal-safe), and
  !> the time loop, polling [[empm_stop_signal]] once per step, writes a checkpoint and the
  !> results so far and stops. A second signal of the same kind has its default effect
  !> (the handler restores it). For programs (`empm run`), not for the library: a host
  !> program owns its signals.
  subroutine empm_catch_stop_signals()
    type(c_funptr) :: old
    old = c_signal(SIGINT, c_funloc(on_stop_signal))
    old = c_signal(SIGTERM, c_funloc(on_stop_signal))
  end subroutine empm_catch_stop_signals

  !> The stop signal caught so far (SIGINT = 2, SIGTERM = 15), 0 when none.
  integer function empm_stop_signal() result(sig)
    sig = int(caught)
  end function empm_stop_signal

  subroutine on_stop_signal(sig) bind(C)
    integer(c_int), value :: sig
    type(c_funptr) :: old
    caught = sig
    old = c_signal(sig, transfer(0_c_intptr_t, old))  ! SIG_DFL
  end subroutine on_stop_signal

  pure function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: b
    write(b, '(i0)') i
    s = trim(b)
  end function itoa
end module empm_posix
