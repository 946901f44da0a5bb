!> Small formatting helpers for messages.
module empm_strings
  use empm_kinds, only: wp
  implicit none
  private
  public :: str, lower, join, str_short

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

  !> Real to the short text a person would write: "0.5", "1", "1e-06", "2.5e+09" (at most 15
  !> significant digits; for bounds and defaults in messages, not for values to read back).
  pure function str_short(x) result(s)
    real(wp), intent(in) :: x !! value
    character(len=:), allocatable :: s !! text
    character(len=40) :: buf
    integer :: e, k
    if (x /= x .or. abs(x) > huge(x)) then
      s = str_real(x); return
    end if
    if (x == 0.0_wp) then
      s = '0'
    else if (abs(x) >= 1.0e-3_wp .and. abs(x) < 1.0e9_wp) then
      write(buf, '(f0.12)') x
      s = trim(buf)
      ! f0.d leaves out the zero before the point
      if (s(1:1) == '.') s = '0'//s
      if (s(1:2) == '-.') s = '-0'//s(2:)
      s = trim_zeros(s)
    else
      write(buf, '(es22.14e3)') x
      buf = adjustl(buf)
      e = index(buf, 'E')
      s = trim_zeros(buf(1:e - 1))
      read(buf(e + 1:), *) k
      s = s//'e'//merge('+', '-', k >= 0)//str_pad2(abs(k))
    end if
  contains
    pure function trim_zeros(t) result(r)
      character(len=*), intent(in) :: t
      character(len=:), allocatable :: r
      integer :: n
      r = t
      if (index(r, '.') == 0) return
      n = len(r)
      do while (n > 1)
        if (r(n:n) /= '0') exit
        n = n - 1
      end do
      if (r(n:n) == '.') n = n - 1
      r = r(1:n)
    end function trim_zeros
    pure function str_pad2(i) result(r)
      integer, intent(in) :: i
      character(len=:), allocatable :: r
      character(len=12) :: b
      write(b, '(i2.2)') i
      r = trim(adjustl(b))
    end function str_pad2
  end function str_short

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
