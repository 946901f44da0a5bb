!> The one error type of the library: a code, a message and where the problem is.
!>
!> Pure kernels return an integer status that their owner turns into an [[empm_error_t]];
!> set-up, factory and driver routines take an optional `type(empm_error_t)` out-argument. When
!> the caller passes none, [[empm_raise]] prints the message on stderr and stops with the code
!> as exit status; with `err` present no library routine ends the host process.
!>
!> The location fields say where: the case file, group, key and line for input errors, the
!> step, particle and node for run-time ones (0 or unallocated when not applicable). The
!> message already names them; the fields are for programs that react to them.
module empm_error
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  implicit none
  private
  public :: empm_error_t, empm_raise, empm_raise_error, empm_clear, empm_alloc_error
  public :: EMPM_OK, EMPM_ERR_USAGE, EMPM_ERR_INPUT, EMPM_ERR_RUNTIME, EMPM_ERR_IO
  public :: EMPM_ERR_INTERRUPTED

  integer, parameter :: EMPM_OK = 0          !! success
  integer, parameter :: EMPM_ERR_USAGE = 1   !! bad command line or API misuse
  integer, parameter :: EMPM_ERR_INPUT = 2   !! invalid case file or input value
  integer, parameter :: EMPM_ERR_RUNTIME = 3 !! run-time guard tripped (NaN, particle left grid, dt)
  integer, parameter :: EMPM_ERR_IO = 4      !! file system or HDF5 failure (or out of memory)
  integer, parameter :: EMPM_ERR_INTERRUPTED = 6 !! the run was asked to stop (a signal): a
                                                 !! checkpoint and the results so far written

  !> An error status with a human-readable message and its location.
  type :: empm_error_t
    integer :: code = EMPM_OK                  !! one of the `EMPM_*` codes; 0 means no error
    character(len=:), allocatable :: message   !! what went wrong, where, and what was expected
    character(len=:), allocatable :: file      !! case file, if any
    character(len=:), allocatable :: group     !! namelist group, if any (without '&')
    character(len=:), allocatable :: key       !! key of that group, if any
    integer :: line = 0                        !! line in `file`, 0 if unknown
    integer :: step = 0                        !! time step, 0 if none
    integer :: particle = 0                    !! particle index, 0 if none
    integer :: node = 0                        !! node index, 0 if none
  contains
    procedure :: ok => error_ok
    procedure :: set => error_set
  end type empm_error_t

contains

  !> True when no error is recorded.
  elemental logical function error_ok(self)
    class(empm_error_t), intent(in) :: self !! error object
    error_ok = self%code == EMPM_OK
  end function error_ok

  !> Record an error: the message is prefixed with its location,
  !> `file:line: group &g: key 'k': text` (the parts given), or `step n: text`.
  pure subroutine error_set(self, code, text, file, group, key, line, step, particle, node)
    class(empm_error_t), intent(inout) :: self      !! error object
    integer, intent(in) :: code                     !! `EMPM_ERR_*` code
    character(len=*), intent(in) :: text            !! what is wrong and what was expected
    character(len=*), intent(in), optional :: file  !! case file
    character(len=*), intent(in), optional :: group !! namelist group (without '&')
    character(len=*), intent(in), optional :: key   !! key
    integer, intent(in), optional :: line           !! line in the file
    integer, intent(in), optional :: step           !! time step
    integer, intent(in), optional :: particle       !! particle index
    integer, intent(in), optional :: node           !! node index
    character(len=:), allocatable :: where
    character(len=24) :: buf
    self%code = code
    where = ''
    if (present(file)) then
      self%file = file
      where = file
      if (present(line)) then
        if (line > 0) then
          write(buf, '(i0)') line
          where = where//':'//trim(buf)
        end if
      end if
      where = where//': '
    end if
    if (present(line)) self%line = line
    if (present(group)) then
      self%group = group
      if (len(group) > 0) where = where//'group &'//group//': '
    end if
    if (present(key)) then
      self%key = key
      if (len(key) > 0) where = where//'key '''//key//''': '
    end if
    if (present(step)) then
      self%step = step
      if (.not. present(file)) then
        write(buf, '(i0)') step
        where = where//'step '//trim(buf)//': '
      end if
    end if
    if (present(particle)) self%particle = particle
    if (present(node)) self%node = node
    self%message = where//text
  end subroutine error_set

  !> Reset an error object to "no error".
  subroutine empm_clear(err)
    type(empm_error_t), intent(inout) :: err !! error object to reset
    err = empm_error_t()
  end subroutine empm_clear

  !> Record an error in `err` if present, otherwise print it and stop with exit status `code`.
  subroutine empm_raise(code, message, err)
    integer, intent(in) :: code                         !! error code (`EMPM_ERR_*`)
    character(len=*), intent(in) :: message             !! full message
    type(empm_error_t), intent(out), optional :: err    !! receives the error when present
    type(empm_error_t) :: e
    call e%set(code, message)
    call empm_raise_error(e, err)
  end subroutine empm_raise

  !> Hand the error `e` to the caller's `err` if present (location fields included), otherwise
  !> print it and stop with exit status `e%code`. Does nothing when `e` holds no error.
  subroutine empm_raise_error(e, err)
    type(empm_error_t), intent(in) :: e                 !! the error
    type(empm_error_t), intent(out), optional :: err    !! receives it when present
    if (present(err)) then
      err = e
      return
    end if
    if (e%code == EMPM_OK) return
    write(error_unit, '(a)') 'empm: error: '//e%message
    select case (e%code)
    case (EMPM_ERR_USAGE)
      error stop 1
    case (EMPM_ERR_INPUT)
      error stop 2
    case (EMPM_ERR_RUNTIME)
      error stop 3
    case default
      error stop 4
    end select
  end subroutine empm_raise_error

  !> An allocation failure as an error (code EMPM_ERR_IO): what was being allocated, how much
  !> memory was asked for, and the run-time library's message.
  pure function empm_alloc_error(what, bytes, errmsg) result(e)
    character(len=*), intent(in) :: what     !! e.g. 'particle storage (1000000 particles)'
    integer(int64), intent(in) :: bytes      !! bytes requested
    character(len=*), intent(in) :: errmsg   !! `errmsg=` of the failed allocate
    type(empm_error_t) :: e                  !! the error
    character(len=32) :: buf
    write(buf, '(f0.1)') real(bytes, kind(1.0d0)) / 1048576.0d0
    if (buf(1:1) == '.') buf = '0'//buf(1:31)
    call e%set(EMPM_ERR_IO, 'out of memory: allocating '//what//' needs '//trim(buf)// &
      ' MiB ('//trim(errmsg)//')')
  end function empm_alloc_error
end module empm_error
