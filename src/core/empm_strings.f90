!> Small formatting helpers for messages.
module empm_strings
  use empm_kinds, only: wp
  implicit none
  private
  public :: str, lower, join

  !> Format a value as a trimmed string.
  interface str
    module procedure str_int, str_real, str_logical
  end interface str

contains

  !> Integer to string.
  pure function str_int(i) result(s)
    integer, intent(in) :: i !! value
    character(len=:), allocatable :: s !! decimal text
    character(len=24) :: buf
    write(buf, '(i0)') i
    s = trim(buf)
  end function str_int

  !> Real to string in shortest-round-trip-ish general format.
  pure function str_real(x) result(s)
    real(wp), intent(in) :: x !! value
    character(len=:), allocatable :: s !! text, e.g. "1.5E-03"
    character(len=32) :: buf
    if (x /= x) then
      s = 'NaN'
    else if (abs(x) > huge(x)) then
      s = merge('+Inf', '-Inf', x > 0)
    else
      write(buf, '(es16.8e3)') x
      s = trim(adjustl(buf))
    end if
  end function str_real

  !> Logical to string.
  pure function str_logical(l) result(s)
    logical, intent(in) :: l !! value
    character(len=:), allocatable :: s !! ".true." or ".false."
    s = merge('.true. ', '.false.', l)
    s = trim(s)
  end function str_logical

  !> Lower-case copy of an ASCII string.
  pure function lower(s) result(t)
    character(len=*), intent(in) :: s !! input
    character(len=len(s)) :: t !! lower-case copy
    integer :: i, c
    t = s
    do i = 1, len(s)
      c = iachar(s(i:i))
      if (c >= iachar('A') .and. c <= iachar('Z')) t(i:i) = achar(c + 32)
    end do
  end function lower

  !> Reals formatted with [[str]] and joined by `sep`, e.g. join([1.0, 2.0], ', ').
  pure function join(x, sep) result(s)
    real(wp), intent(in) :: x(:)           !! values
    character(len=*), intent(in) :: sep    !! separator
    character(len=:), allocatable :: s     !! joined text
    integer :: i
    s = ''
    do i = 1, size(x)
      s = s//str(x(i))
      if (i < size(x)) s = s//sep
    end do
  end function join
end module empm_strings
