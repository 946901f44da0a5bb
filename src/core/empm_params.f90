!> Parameter declarations: how a family (shape function, material, integrator) or an input group
!> describes each of its keys (name, type, unit, default, bounds, one-line meaning).
!>
!> The declarations serve three readers: the case-file reader validates values against them
!> ([[empm_namelist]]), `empm keys` prints them as the tables of docs/input.md
!> ([[empm_params_markdown]]), and a test checks that docs/input.md holds those tables.
module empm_params
  use empm_kinds, only: wp
  use empm_strings, only: str_short
  implicit none
  private
  public :: empm_param_t, empm_param, empm_params_markdown, empm_param_names
  public :: PARAM_REAL, PARAM_INT, PARAM_STR, PARAM_LOGICAL

  integer, parameter :: PARAM_REAL = 1    !! real number(s)
  integer, parameter :: PARAM_INT = 2     !! integer(s)
  integer, parameter :: PARAM_STR = 3     !! string(s)
  integer, parameter :: PARAM_LOGICAL = 4 !! logical(s)

  !> One key of a group.
  type :: empm_param_t
    character(len=:), allocatable :: name     !! key, lower case
    integer :: kind = PARAM_REAL              !! PARAM_REAL, PARAM_INT, PARAM_STR or PARAM_LOGICAL
    integer :: count = 1                      !! values: 1 scalar, n > 1 up to n values
    character(len=:), allocatable :: unit     !! SI unit, '-' when dimensionless
    character(len=:), allocatable :: default  !! default as written in a case file; '' = required
                                              !! (or optional without default: see `optional`)
    logical :: optional = .false.             !! may be absent without a default ("unset")
    real(wp) :: lo = -huge(1.0_wp)            !! lower bound (numbers)
    real(wp) :: hi = huge(1.0_wp)             !! upper bound (numbers)
    logical :: lo_open = .false.              !! the lower bound is excluded
    logical :: hi_open = .false.              !! the upper bound is excluded
    character(len=:), allocatable :: choices  !! strings: allowed values, blank-separated ('' = any)
    character(len=:), allocatable :: meaning  !! one line
    character(len=:), allocatable :: tag      !! short tag in identifiers ('g' in 'lme_g3'), or ''
  end type empm_param_t

contains

  !> Declare a key. Numbers take bounds `lo`/`hi` (open with `lo_open`/`hi_open`); strings take
  !> `choices`. A key without `default` is required unless `optional` is true.
  pure function empm_param(name, kind, unit, meaning, default, lo, hi, lo_open, hi_open, &
                           choices, count, optional, tag) result(p)
    character(len=*), intent(in) :: name               !! key
    integer, intent(in) :: kind                        !! PARAM_* type
    character(len=*), intent(in) :: unit               !! SI unit or '-'
    character(len=*), intent(in) :: meaning            !! one-line meaning
    character(len=*), intent(in), optional :: default  !! default value as case-file text
    real(wp), intent(in), optional :: lo               !! lower bound
    real(wp), intent(in), optional :: hi               !! upper bound
    logical, intent(in), optional :: lo_open           !! exclude the lower bound
    logical, intent(in), optional :: hi_open           !! exclude the upper bound
    character(len=*), intent(in), optional :: choices  !! allowed strings, blank-separated
    integer, intent(in), optional :: count             !! maximum number of values (default 1)
    logical, intent(in), optional :: optional          !! may be absent without a default
    character(len=*), intent(in), optional :: tag      !! identifier tag
    type(empm_param_t) :: p                            !! the declaration
    p%name = name; p%kind = kind; p%unit = unit; p%meaning = meaning
    p%default = ''; p%choices = ''; p%tag = ''
    if (present(default)) p%default = default
    if (present(lo)) p%lo = lo
    if (present(hi)) p%hi = hi
    if (present(lo_open)) p%lo_open = lo_open
    if (present(hi_open)) p%hi_open = hi_open
    if (present(choices)) p%choices = choices
    if (present(count)) p%count = count
    if (present(optional)) p%optional = optional
    if (present(tag)) p%tag = tag
  end function empm_param

  !> The keys of `params`, comma-separated (for "valid keys" messages).
  pure function empm_param_names(params) result(s)
    type(empm_param_t), intent(in) :: params(:) !! declarations
    character(len=:), allocatable :: s          !! e.g. "family, gamma, tol0"
    integer :: i
    s = ''
    do i = 1, size(params)
      if (i > 1) s = s//', '
      s = s//params(i)%name
    end do
  end function empm_param_names

  !> A Markdown table of `params`: key, type, unit, default, range, meaning.
  function empm_params_markdown(params) result(s)
    type(empm_param_t), intent(in) :: params(:) !! declarations
    character(len=:), allocatable :: s          !! the table, one row per key, newline-terminated
    character(len=*), parameter :: NL = new_line('a')
    integer :: i
    s = '| key | type | unit | default | range | meaning |'//NL//'|---|---|---|---|---|---|'//NL
    do i = 1, size(params)
      associate (p => params(i))
        s = s//'| `'//p%name//'` | '//type_text(p)//' | '//p%unit//' | '//default_text(p)// &
          ' | '//range_text(p)//' | '//p%meaning//' |'//NL
      end associate
    end do
  end function empm_params_markdown

  pure function type_text(p) result(s)
    type(empm_param_t), intent(in) :: p
    character(len=:), allocatable :: s
    character(len=16) :: buf
    select case (p%kind)
    case (PARAM_REAL); s = 'real'
    case (PARAM_INT); s = 'integer'
    case (PARAM_STR); s = 'string'
    case default; s = 'logical'
    end select
    if (p%count > 1) then
      write(buf, '(i0)') p%count
      s = s//'('//trim(buf)//')'
    end if
  end function type_text

  pure function default_text(p) result(s)
    type(empm_param_t), intent(in) :: p
    character(len=:), allocatable :: s
    if (len(p%default) > 0) then
      s = '`'//p%default//'`'
    else if (p%optional) then
      s = 'unset'
    else
      s = 'required'
    end if
  end function default_text

  function range_text(p) result(s)
    type(empm_param_t), intent(in) :: p
    character(len=:), allocatable :: s
    integer :: i, j
    s = ''
    select case (p%kind)
    case (PARAM_REAL, PARAM_INT)
      if (p%lo > -huge(1.0_wp) .and. p%hi < huge(1.0_wp)) then
        s = merge('(', '[', p%lo_open)//num(p)//', '//num(p, .true.)//merge(')', ']', p%hi_open)
      else if (p%lo > -huge(1.0_wp)) then
        s = trim(merge('> ', '>=', p%lo_open))//' '//num(p)
      else if (p%hi < huge(1.0_wp)) then
        s = trim(merge('< ', '<=', p%hi_open))//' '//num(p, .true.)
      else
        s = 'any'
      end if
    case (PARAM_STR)
      if (len(p%choices) == 0) then
        s = 'any'
      else
        ! 'a b c' -> `'a'`, `'b'`, `'c'`
        i = 1
        do while (i <= len(p%choices))
          j = index(p%choices(i:), ' ')
          if (j == 0) then
            j = len(p%choices) + 1
          else
            j = i + j - 1
          end if
          if (j > i) s = s//merge(', ', '  ', len(s) > 0)//'`'''//p%choices(i:j - 1)//'''`'
          i = j + 1
        end do
        s = adjustl(s)
        s = trim(s)
      end if
    case default
      s = '`.true.`, `.false.`'
    end select
  end function range_text

  function num(p, upper) result(s)
    type(empm_param_t), intent(in) :: p
    logical, intent(in), optional :: upper
    character(len=:), allocatable :: s
    real(wp) :: x
    x = p%lo
    if (present(upper)) then
      if (upper) x = p%hi
    end if
    s = str_short(x)
  end function num
end module empm_params
