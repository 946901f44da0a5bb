!> A minimal JSON writer (objects, arrays, strings, numbers, booleans) for machine-readable
!> reports. Values are appended to a growing string; commas are inserted automatically.
module empm_json
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_json_t

  !> JSON document under construction.
  type :: empm_json_t
    character(len=:), allocatable :: text   !! the document so far
    logical :: need_comma = .false.          !! a value was just written at this level
  contains
    procedure :: begin_object, end_object, begin_array, end_array
    procedure :: key
    procedure :: str_value, real_value, int_value, bool_value, null_value, real_array
  end type empm_json_t

contains

  subroutine sep(self)
    class(empm_json_t), intent(inout) :: self
    if (.not. allocated(self%text)) self%text = ''
    if (self%need_comma) self%text = self%text//', '
    self%need_comma = .false.
  end subroutine sep

  !> Start an object `{`.
  subroutine begin_object(self)
    class(empm_json_t), intent(inout) :: self !! document
    call sep(self); self%text = self%text//'{'
  end subroutine begin_object

  !> Close an object `}`.
  subroutine end_object(self)
    class(empm_json_t), intent(inout) :: self !! document
    self%text = self%text//'}'; self%need_comma = .true.
  end subroutine end_object

  !> Start an array `[`.
  subroutine begin_array(self)
    class(empm_json_t), intent(inout) :: self !! document
    call sep(self); self%text = self%text//'['
  end subroutine begin_array

  !> Close an array `]`.
  subroutine end_array(self)
    class(empm_json_t), intent(inout) :: self !! document
    self%text = self%text//']'; self%need_comma = .true.
  end subroutine end_array

  !> Write an object key `"name": ` (the value follows).
  subroutine key(self, name)
    class(empm_json_t), intent(inout) :: self !! document
    character(len=*), intent(in) :: name      !! key
    call sep(self); self%text = self%text//quote(name)//': '
  end subroutine key

  !> Write a string value.
  subroutine str_value(self, s)
    class(empm_json_t), intent(inout) :: self !! document
    character(len=*), intent(in) :: s         !! value
    call sep(self); self%text = self%text//quote(s); self%need_comma = .true.
  end subroutine str_value

  !> Write a number (non-finite values become null, which JSON requires).
  subroutine real_value(self, x)
    class(empm_json_t), intent(inout) :: self !! document
    real(wp), intent(in) :: x                 !! value
    call sep(self); self%text = self%text//num(x); self%need_comma = .true.
  end subroutine real_value

  !> Write an integer.
  subroutine int_value(self, i)
    class(empm_json_t), intent(inout) :: self !! document
    integer, intent(in) :: i                  !! value
    character(len=24) :: buf
    write(buf, '(i0)') i
    call sep(self); self%text = self%text//trim(buf); self%need_comma = .true.
  end subroutine int_value

  !> Write true/false.
  subroutine bool_value(self, b)
    class(empm_json_t), intent(inout) :: self !! document
    logical, intent(in) :: b                  !! value
    call sep(self); self%text = self%text//trim(merge('true ', 'false', b)); self%need_comma = .true.
  end subroutine bool_value

  !> Write null.
  subroutine null_value(self)
    class(empm_json_t), intent(inout) :: self !! document
    call sep(self); self%text = self%text//'null'; self%need_comma = .true.
  end subroutine null_value

  !> Write an array of numbers.
  subroutine real_array(self, x)
    class(empm_json_t), intent(inout) :: self !! document
    real(wp), intent(in) :: x(:)              !! values
    integer :: i
    call self%begin_array()
    do i = 1, size(x)
      call self%real_value(x(i))
    end do
    call self%end_array()
  end subroutine real_array

  pure function num(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=32) :: buf
    if (x /= x .or. abs(x) > huge(x)) then
      s = 'null'
    else
      write(buf, '(es24.16e3)') x
      s = trim(adjustl(buf))
    end if
  end function num

  pure function quote(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    integer :: i
    q = '"'
    do i = 1, len(s)
      select case (s(i:i))
      case ('"'); q = q//'\"'
      case ('\'); q = q//'\\'
      case default
        if (iachar(s(i:i)) < 32) then
          q = q//' '
        else
          q = q//s(i:i)
        end if
      end select
    end do
    q = q//'"'
  end function quote
end module empm_json
