!> Case files as data: a reader for the Fortran namelist syntax that keeps each group as a
!> table of keys and values, and typed getters that validate a value against its declaration
!> ([[empm_param_t]]).
!>
!> Why not the compiler's namelist read: it needs the keys at compile time, so every family's
!> keys would have to be known to the reader; here a family reads its own keys from the group.
!> The syntax accepted is the subset of namelist that case files use (docs/input.md): groups
!> `&name ... /` (or `&end`), `key = value, value ...`, `key(i) = value` (values from element
!> i on), repeat counts `r*value`, quoted strings ('' or "" doubles a quote), logicals
!> `.true.`/`.false.`/`t`/`f`, and `!` comments. Text outside groups is ignored. Numbers are
!> converted by list-directed read, as a namelist read converts them.
module empm_namelist
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_ERR_INPUT
  use empm_params, only: empm_param_t, empm_param_names, PARAM_REAL, PARAM_INT, PARAM_STR, &
                         PARAM_LOGICAL
  use empm_strings, only: str, lower, str_short
  implicit none
  private
  public :: empm_group_t, empm_parse_namelist, empm_group_from_text, empm_kv

  !> `key = value, ` as case-file text, reals with 17 significant digits (read back to the same
  !> bits): for programs that build a group from numbers, e.g.
  !> `empm_kv('E', E)//empm_kv('nu', nu)//empm_kv('density', rho)`.
  interface empm_kv
    module procedure kv_real, kv_int, kv_str
  end interface empm_kv

  integer, parameter :: MAXVAL = 4096  !! values per key (snapshot_times needs 1000)

  !> The value(s) given to one key.
  type :: keyval_t
    character(len=:), allocatable :: key       !! lower case
    integer :: line = 0                        !! line of the (last) assignment
    integer :: n = 0                           !! values set (highest index)
    type(text_t), allocatable :: v(:)          !! values, as written (strings unquoted)
    logical, allocatable :: quoted(:)          !! value was a quoted string
    logical :: used = .false.                  !! read by a getter
  end type keyval_t

  type :: text_t
    character(len=:), allocatable :: s
  end type text_t

  !> One namelist group of a case file.
  type :: empm_group_t
    character(len=:), allocatable :: file      !! case file (for messages)
    character(len=:), allocatable :: name      !! group name, lower case, without '&'
    integer :: line = 0                        !! line of '&name'
    integer :: nkey = 0                        !! keys given
    type(keyval_t), allocatable :: kv(:)       !! the keys (nkey used)
  contains
    procedure :: has => group_has
    procedure :: key_line => group_key_line
    procedure :: count => group_count
    procedure :: set => group_set
    procedure :: check_keys => group_check_keys
    procedure :: keep_only => group_keep_only
    procedure :: fail => group_fail
    procedure, private :: get_real, get_int, get_str, get_logical
    procedure, private :: get_reals, get_ints, get_strs, get_logicals
    generic :: get => get_real, get_int, get_str, get_logical, get_reals, get_ints, get_strs, &
                      get_logicals
  end type empm_group_t

contains

  ! ---- building text -------------------------------------------------------------------

  pure function kv_real(key, x) result(s)
    character(len=*), intent(in) :: key  !! key
    real(wp), intent(in) :: x            !! value
    character(len=:), allocatable :: s   !! 'key = 1.00000000000000000E+000, '
    character(len=32) :: buf
    write(buf, '(es25.17e3)') x
    s = key//' = '//trim(adjustl(buf))//', '
  end function kv_real

  pure function kv_int(key, i) result(s)
    character(len=*), intent(in) :: key  !! key
    integer, intent(in) :: i             !! value
    character(len=:), allocatable :: s   !! 'key = 3, '
    s = key//' = '//str(i)//', '
  end function kv_int

  pure function kv_str(key, v) result(s)
    character(len=*), intent(in) :: key  !! key
    character(len=*), intent(in) :: v    !! value (quoted in the text)
    character(len=:), allocatable :: s   !! "key = 'v', "
    s = key//' = '''//v//''', '
  end function kv_str

  ! ---- parsing ---------------------------------------------------------------------------

  !> Parse namelist `text` (the contents of `file`) into its groups, in file order.
  subroutine empm_parse_namelist(text, file, groups, err)
    character(len=*), intent(in) :: text                    !! file contents
    character(len=*), intent(in) :: file                    !! file name, for messages
    type(empm_group_t), allocatable, intent(out) :: groups(:) !! the groups
    type(empm_error_t), intent(inout) :: err                !! set on a syntax error
    type(empm_group_t), allocatable :: tmp(:)
    type(empm_group_t) :: g
    integer :: i, n, line, ng
    character(len=1) :: c
    n = len(text); i = 1; line = 1; ng = 0
    allocate(groups(0))
    do while (i <= n)
      c = text(i:i)
      if (c == new_line('a')) then
        line = line + 1; i = i + 1
      else if (c == '!') then
        call skip_comment()
      else if (c == '&' .or. c == '$') then
        call parse_group(text, file, i, line, g, err)
        if (err%code /= 0) return
        if (g%name == 'end') cycle  ! a stray '&end'
        allocate(tmp(ng + 1))
        tmp(1:ng) = groups(1:ng)
        tmp(ng + 1) = g
        call move_alloc(tmp, groups)
        ng = ng + 1
      else
        i = i + 1
      end if
    end do
  contains
    subroutine skip_comment()
      do while (i <= n)
        if (text(i:i) == new_line('a')) exit
        i = i + 1
      end do
    end subroutine skip_comment
  end subroutine empm_parse_namelist

  !> A group from the text of one namelist group, e.g. `&material E = 1e7, density = 1000 /`
  !> (for programs that build families without a case file).
  subroutine empm_group_from_text(text, g, err)
    character(len=*), intent(in) :: text             !! one group
    type(empm_group_t), intent(out) :: g             !! the group
    type(empm_error_t), intent(inout) :: err         !! set on a syntax error
    type(empm_group_t), allocatable :: gs(:)
    call empm_parse_namelist(text, '(text)', gs, err)
    if (err%code /= 0) return
    if (size(gs) /= 1) then
      call err%set(EMPM_ERR_INPUT, 'expected exactly one namelist group, got '//str(size(gs))// &
        ': '//text)
      return
    end if
    g = gs(1)
  end subroutine empm_group_from_text

  !> Parse the group starting at text(i:i) = '&'; on return `i` is past its end.
  subroutine parse_group(text, file, i, line, g, err)
    character(len=*), intent(in) :: text, file
    integer, intent(inout) :: i, line
    type(empm_group_t), intent(out) :: g
    type(empm_error_t), intent(inout) :: err
    character(len=*), parameter :: IDCHARS = 'abcdefghijklmnopqrstuvwxyz_0123456789'
    integer :: n, j, k, idx, rep, ios
    character(len=:), allocatable :: key, tok
    logical :: quoted
    n = len(text)
    j = i + 1
    do while (j <= n)
      if (index(IDCHARS, lower(text(j:j))) == 0) exit
      j = j + 1
    end do
    g%file = file; g%name = lower(text(i + 1:j - 1)); g%line = line
    allocate(g%kv(0))
    i = j
    if (len(g%name) == 0) then
      call err%set(EMPM_ERR_INPUT, 'expected a group name after ''&''', file=file, line=line)
      return
    end if
    if (g%name == 'end') return
    key = ''; idx = 0
    do
      call skip_space()
      if (i > n) then
        call err%set(EMPM_ERR_INPUT, 'group &'//g%name//' (line '//str(g%line)// &
          ') is not closed: expected ''/'' at its end', file=file, line=line)
        return
      end if
      if (text(i:i) == '/') then
        i = i + 1; return
      end if
      if (text(i:i) == '&' .or. text(i:i) == '$') then
        ! '&end' closes the group; another '&' means a missing '/'.
        if (lower(text(i + 1:min(n, i + 3))) == 'end') then
          i = i + 4; return
        end if
        call err%set(EMPM_ERR_INPUT, 'group &'//g%name//' (line '//str(g%line)// &
          ') is not closed: expected ''/'' before the next group', file=file, line=line)
        return
      end if
      if (text(i:i) == ',') then
        i = i + 1; cycle
      end if
      ! A key is an identifier followed by '=' (or '(index) ='); anything else is a value.
      if (is_key_start()) then
        j = i
        do while (j <= n)
          if (index(IDCHARS, lower(text(j:j))) == 0) exit
          j = j + 1
        end do
        key = lower(text(i:j - 1)); idx = 1
        k = j
        call skip_blanks_at(k)
        if (text(k:k) == '(') then
          j = index(text(k:), ')') + k - 1
          ios = 1
          if (j > k) read(text(k + 1:j - 1), *, iostat=ios) idx
          if (ios /= 0 .or. idx < 1 .or. idx > MAXVAL) then
            call err%set(EMPM_ERR_INPUT, 'expected an index 1..'//str(MAXVAL)//' in '''// &
              text(i:j)//'''', file=file, group=g%name, key=key, line=line)
            return
          end if
          k = j + 1
          call skip_blanks_at(k)
        end if
        i = k + 1  ! past '='
        call start_key(g, key, line)
        cycle
      end if
      if (len(key) == 0) then
        call err%set(EMPM_ERR_INPUT, 'expected ''key = value'', got '''// &
          text(i:min(n, i + 20))//'''', file=file, group=g%name, line=line)
        return
      end if
      call read_token(tok, quoted)
      if (err%code /= 0) return
      ! r*value repeats the value r times
      rep = 1
      if (.not. quoted) then
        k = index(tok, '*')
        if (k > 1) then
          read(tok(1:k - 1), *, iostat=ios) rep
          if (ios /= 0 .or. rep < 1) then
            call err%set(EMPM_ERR_INPUT, 'bad repeat count in '''//tok//'''', file=file, &
              group=g%name, key=key, line=line)
            return
          end if
          tok = tok(k + 1:)
          if (len(tok) == 0) then
            idx = idx + rep; cycle  ! r* = r null values: keep what is there
          end if
        end if
      end if
      do k = 1, rep
        if (idx > MAXVAL) then
          call err%set(EMPM_ERR_INPUT, 'more than '//str(MAXVAL)//' values', file=file, &
            group=g%name, key=key, line=line)
          return
        end if
        call add_value(g%kv(g%nkey), idx, tok, quoted)
        idx = idx + 1
      end do
    end do
  contains
    subroutine skip_space()
      do while (i <= n)
        if (text(i:i) == new_line('a')) then
          line = line + 1
        else if (text(i:i) == '!') then
          do while (i < n)
            if (text(i + 1:i + 1) == new_line('a')) exit
            i = i + 1
          end do
        else if (text(i:i) /= ' ' .and. text(i:i) /= achar(9) .and. text(i:i) /= achar(13)) then
          exit
        end if
        i = i + 1
      end do
    end subroutine skip_space

    subroutine skip_blanks_at(k)
      integer, intent(inout) :: k
      do while (k <= n)
        if (text(k:k) /= ' ' .and. text(k:k) /= achar(9)) exit
        k = k + 1
      end do
    end subroutine skip_blanks_at

    logical function is_key_start()
      integer :: k2, j2
      is_key_start = .false.
      if (index('abcdefghijklmnopqrstuvwxyz', lower(text(i:i))) == 0) return
      k2 = i
      do while (k2 <= n)
        if (index(IDCHARS, lower(text(k2:k2))) == 0) exit
        k2 = k2 + 1
      end do
      call skip_blanks_at(k2)
      if (k2 > n) return
      if (text(k2:k2) == '(') then
        j2 = index(text(k2:), ')')
        if (j2 == 0) return
        k2 = k2 + j2
        call skip_blanks_at(k2)
        if (k2 > n) return
      end if
      is_key_start = text(k2:k2) == '='
    end function is_key_start

    !> One value: a quoted string or a run of non-separator characters.
    subroutine read_token(t, q)
      character(len=:), allocatable, intent(out) :: t
      logical, intent(out) :: q
      character(len=1) :: qc
      integer :: j2
      q = .false.
      if (text(i:i) == '''' .or. text(i:i) == '"') then
        q = .true.; qc = text(i:i); t = ''; i = i + 1
        do
          if (i > n) then
            call err%set(EMPM_ERR_INPUT, 'unterminated string', file=file, group=g%name, &
              key=key, line=line)
            return
          end if
          if (text(i:i) == new_line('a')) then
            call err%set(EMPM_ERR_INPUT, 'unterminated string', file=file, group=g%name, &
              key=key, line=line)
            return
          end if
          if (text(i:i) == qc) then
            if (i < n) then
              if (text(i + 1:i + 1) == qc) then
                t = t//qc; i = i + 2; cycle
              end if
            end if
            i = i + 1; exit
          end if
          t = t//text(i:i); i = i + 1
        end do
        return
      end if
      j2 = i
      do while (j2 <= n)
        if (index(' ,/!&'//new_line('a')//achar(9)//achar(13), text(j2:j2)) > 0) exit
        j2 = j2 + 1
      end do
      t = text(i:j2 - 1)
      i = j2
    end subroutine read_token
  end subroutine parse_group

  subroutine start_key(g, key, line)
    type(empm_group_t), intent(inout) :: g
    character(len=*), intent(in) :: key
    integer, intent(in) :: line
    type(keyval_t), allocatable :: tmp(:)
    integer :: k
    ! A key given twice: the later values replace the earlier ones element by element, as in a
    ! namelist read.
    do k = 1, g%nkey
      if (g%kv(k)%key == key) then
        if (k /= g%nkey) then
          ! move it last so that values go to g%kv(g%nkey)
          tmp = [g%kv(1:k - 1), g%kv(k + 1:g%nkey), g%kv(k)]
          call move_alloc(tmp, g%kv)
        end if
        g%kv(g%nkey)%line = line
        return
      end if
    end do
    allocate(tmp(g%nkey + 1))
    tmp(1:g%nkey) = g%kv(1:g%nkey)
    tmp(g%nkey + 1)%key = key
    tmp(g%nkey + 1)%line = line
    allocate(tmp(g%nkey + 1)%v(0), tmp(g%nkey + 1)%quoted(0))
    call move_alloc(tmp, g%kv)
    g%nkey = g%nkey + 1
  end subroutine start_key

  subroutine add_value(kv, idx, tok, quoted)
    type(keyval_t), intent(inout) :: kv
    integer, intent(in) :: idx
    character(len=*), intent(in) :: tok
    logical, intent(in) :: quoted
    type(text_t), allocatable :: tv(:)
    logical, allocatable :: tq(:)
    integer :: m
    if (idx > size(kv%v)) then
      m = max(idx, 2 * size(kv%v), 4)
      allocate(tv(m), tq(m))
      tv(1:size(kv%v)) = kv%v
      tq = .false.; tq(1:size(kv%v)) = kv%quoted
      call move_alloc(tv, kv%v); call move_alloc(tq, kv%quoted)
    end if
    kv%v(idx)%s = tok
    kv%quoted(idx) = quoted
    kv%n = max(kv%n, idx)
  end subroutine add_value

  ! ---- queries ---------------------------------------------------------------------------

  integer function find(self, key) result(k)
    class(empm_group_t), intent(in) :: self
    character(len=*), intent(in) :: key
    do k = 1, self%nkey
      if (self%kv(k)%key == lower(key)) return
    end do
    k = 0
  end function find

  !> True when the group gives a value to `key`.
  logical function group_has(self, key)
    class(empm_group_t), intent(in) :: self !! group
    character(len=*), intent(in) :: key     !! key
    group_has = find(self, key) > 0
  end function group_has

  !> Line of the assignment of `key` (the group's line when it is absent).
  integer function group_key_line(self, key) result(line)
    class(empm_group_t), intent(in) :: self !! group
    character(len=*), intent(in) :: key     !! key
    integer :: k
    k = find(self, key)
    line = self%line
    if (k > 0) line = self%kv(k)%line
  end function group_key_line

  !> Number of values given to `key` (0 when absent).
  integer function group_count(self, key) result(n)
    class(empm_group_t), intent(in) :: self !! group
    character(len=*), intent(in) :: key     !! key
    integer :: k
    k = find(self, key)
    n = 0
    if (k > 0) n = self%kv(k)%n
  end function group_count

  !> Give `key` the values `values` (replacing what the file said), e.g. for overrides.
  subroutine group_set(self, key, values)
    class(empm_group_t), intent(inout) :: self   !! group
    character(len=*), intent(in) :: key          !! key
    character(len=*), intent(in) :: values(:)    !! values as case-file text (strings unquoted)
    integer :: k, i
    k = find(self, key)
    if (k == 0) then
      if (.not. allocated(self%kv)) allocate(self%kv(0))
      call start_key(self, lower(key), self%line)
      k = self%nkey
    end if
    self%kv(k)%n = 0
    do i = 1, size(values)
      call add_value(self%kv(k), i, trim(values(i)), .true.)
    end do
  end subroutine group_set

  !> Error unless every key given is one of `params` (or of `extra`, blank-separated);
  !> `context` (e.g. " for family 'linear'") is added to the message.
  subroutine group_check_keys(self, params, err, extra, context)
    class(empm_group_t), intent(in) :: self            !! group
    type(empm_param_t), intent(in) :: params(:)        !! declared keys
    type(empm_error_t), intent(inout) :: err           !! set for the first unknown key
    character(len=*), intent(in), optional :: extra    !! other valid keys, blank-separated
    character(len=*), intent(in), optional :: context  !! added after the group name
    integer :: k, i
    logical :: known
    character(len=:), allocatable :: valid
    if (err%code /= 0) return
    do k = 1, self%nkey
      known = .false.
      do i = 1, size(params)
        if (lower(params(i)%name) == self%kv(k)%key) known = .true.
      end do
      if (present(extra)) known = known .or. index(' '//lower(extra)//' ', ' '//self%kv(k)%key//' ') > 0
      if (known) cycle
      valid = empm_param_names(params)
      if (present(extra)) then
        if (len_trim(extra) > 0) valid = trim(adjustl(join_blanks(extra)))// &
          merge(', ', '  ', len(valid) > 0)//valid
      end if
      if (present(context)) then
        call err%set(EMPM_ERR_INPUT, 'unknown key '''//self%kv(k)%key//''''//context// &
          '; valid keys: '//trim(valid), file=self%file, group=self%name, line=self%kv(k)%line)
      else
        call err%set(EMPM_ERR_INPUT, 'unknown key '''//self%kv(k)%key//'''; valid keys: '// &
          trim(valid), file=self%file, group=self%name, line=self%kv(k)%line)
      end if
      return
    end do
  end subroutine group_check_keys

  !> Drop the keys that are not among `params` (a study that replaces the family drops the
  !> keys of the family it replaces).
  subroutine group_keep_only(self, params)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: params(:)  !! keys to keep
    integer :: k, i, n
    logical :: keep
    n = 0
    do k = 1, self%nkey
      keep = .false.
      do i = 1, size(params)
        if (lower(params(i)%name) == self%kv(k)%key) keep = .true.
      end do
      if (keep) then
        n = n + 1
        if (n /= k) self%kv(n) = self%kv(k)
      end if
    end do
    self%nkey = n
    self%kv = self%kv(1:n)
  end subroutine group_keep_only

  pure function join_blanks(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    integer :: i
    logical :: prev_blank
    r = ''; prev_blank = .true.
    do i = 1, len_trim(s)
      if (s(i:i) == ' ') then
        if (.not. prev_blank) r = r//','
        prev_blank = .true.
      else
        if (prev_blank .and. len(r) > 0) r = r//' '
        r = r//s(i:i); prev_blank = .false.
      end if
    end do
  end function join_blanks

  !> Record an input error about `key` of this group (file, line, group and key in the message).
  subroutine group_fail(self, err, key, text)
    class(empm_group_t), intent(in) :: self   !! group
    type(empm_error_t), intent(inout) :: err  !! receives the error
    character(len=*), intent(in) :: key       !! key ('' for the group as a whole)
    character(len=*), intent(in) :: text      !! what is wrong and what was expected
    if (len(key) > 0) then
      call err%set(EMPM_ERR_INPUT, text, file=self%file, group=self%name, key=key, &
        line=group_key_line(self, key))
    else
      call err%set(EMPM_ERR_INPUT, text, file=self%file, group=self%name, line=self%line)
    end if
  end subroutine group_fail

  ! ---- typed getters ---------------------------------------------------------------------

  !> Raw values of `p` (the file's, or the default's); `n` = 0 when absent and optional.
  subroutine raw(self, p, vals, n, err)
    class(empm_group_t), intent(inout) :: self
    type(empm_param_t), intent(in) :: p
    type(text_t), allocatable, intent(out) :: vals(:)
    integer, intent(out) :: n
    type(empm_error_t), intent(inout) :: err
    type(empm_group_t) :: dflt
    integer :: k
    n = 0
    k = find(self, p%name)
    if (k > 0) then
      self%kv(k)%used = .true.
      n = self%kv(k)%n
      if (n == 0) then
        call self%fail(err, p%name, 'no value given (a null value such as ''3*'' sets nothing)')
        return
      end if
      if (n > p%count) then
        if (p%count == 1) then
          call self%fail(err, p%name, 'expected one value, got '//str(n))
        else
          call self%fail(err, p%name, 'expected at most '//str(p%count)//' values, got '//str(n))
        end if
        return
      end if
      do k = 1, n
        if (.not. allocated(self%kv(find(self, p%name))%v(k)%s)) then
          call self%fail(err, p%name, 'value '//str(k)//' is missing (values must be '// &
            'consecutive from index 1)')
          return
        end if
      end do
      vals = self%kv(find(self, p%name))%v(1:n)
      return
    end if
    if (len(p%default) == 0) then
      if (.not. p%optional) call self%fail(err, p%name, 'required: '//p%meaning// &
        unit_suffix(p))
      allocate(vals(0))
      return
    end if
    ! Parse the default text like a value of the file.
    call empm_group_from_text('&d '//p%name//' = '//p%default//' /', dflt, err)
    if (err%code /= 0) return
    n = dflt%kv(1)%n
    vals = dflt%kv(1)%v(1:n)
  end subroutine raw

  pure function unit_suffix(p) result(s)
    type(empm_param_t), intent(in) :: p
    character(len=:), allocatable :: s
    s = ''
    if (len(p%unit) > 0 .and. p%unit /= '-') s = ' ['//p%unit//']'
  end function unit_suffix

  subroutine to_real(self, p, t, x, err)
    class(empm_group_t), intent(in) :: self
    type(empm_param_t), intent(in) :: p
    character(len=*), intent(in) :: t
    real(wp), intent(out) :: x
    type(empm_error_t), intent(inout) :: err
    integer :: ios
    x = 0.0_wp
    read(t, *, iostat=ios) x
    if (ios == 0 .and. len_trim(t) > 0) then
      if (.not. ieee_is_finite(x)) then
        call self%fail(err, p%name, 'expected a finite number, got '''//t//''''); return
      end if
    end if
    ! List-directed reading also takes 'T', or '1.0abc' up to a separator: here only a sign,
    ! digits, a point and an exponent letter form a number.
    if (ios /= 0 .or. len_trim(t) == 0 .or. verify(lower(trim(t)), '+-.0123456789ed') > 0) then
      call self%fail(err, p%name, 'expected a number, got '''//t//''''); return
    end if
    call check_bounds(self, p, x, t, err)
  end subroutine to_real

  subroutine check_bounds(self, p, x, t, err)
    class(empm_group_t), intent(in) :: self
    type(empm_param_t), intent(in) :: p
    real(wp), intent(in) :: x
    character(len=*), intent(in) :: t
    type(empm_error_t), intent(inout) :: err
    logical :: ok
    ok = .true.
    if (p%lo_open) then
      ok = ok .and. x > p%lo
    else
      ok = ok .and. x >= p%lo
    end if
    if (p%hi_open) then
      ok = ok .and. x < p%hi
    else
      ok = ok .and. x <= p%hi
    end if
    if (.not. ok) call self%fail(err, p%name, 'expected '//bounds_text(p)//', got '//trim(t))
  end subroutine check_bounds

  !> "0 < cfl <= 1", "gamma > 0", "ppc in 1..4" (closed integer ranges).
  function bounds_text(p) result(s)
    type(empm_param_t), intent(in) :: p
    character(len=:), allocatable :: s
    logical :: has_lo, has_hi
    has_lo = p%lo > -huge(1.0_wp); has_hi = p%hi < huge(1.0_wp)
    if (p%kind == PARAM_INT .and. has_lo .and. has_hi .and. .not. (p%lo_open .or. p%hi_open)) then
      s = p%name//' in '//str(nint(p%lo))//'..'//str(nint(p%hi))
    else if (has_lo .and. has_hi) then
      s = bound(p%lo)//trim(merge(' < ', ' <=', p%lo_open))//' '//p%name// &
        trim(merge(' < ', ' <=', p%hi_open))//' '//bound(p%hi)
    else if (has_lo) then
      s = p%name//trim(merge(' > ', ' >=', p%lo_open))//' '//bound(p%lo)
    else if (has_hi) then
      s = p%name//trim(merge(' < ', ' <=', p%hi_open))//' '//bound(p%hi)
    else
      s = 'a value'
    end if
    s = s//unit_suffix(p)
  contains
    function bound(x) result(b)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: b
      b = str_short(x)
    end function bound
  end function bounds_text

  subroutine get_real(self, p, x, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_REAL)
    real(wp), intent(inout) :: x                 !! the value (unchanged when absent and optional)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    real(wp) :: a(1)
    integer :: n
    ! One value: the array getter with room for one (the declaration's count is 1).
    a(1) = x
    call self%get_reals(p, a, n, err)
    if (err%code == 0 .and. n > 0) x = a(1)
  end subroutine get_real

  subroutine get_reals(self, p, x, n, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_REAL, count > 1)
    real(wp), intent(inout) :: x(:)              !! values 1..n set, the rest unchanged
    integer, intent(out) :: n                    !! number of values given (0 when absent)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    type(text_t), allocatable :: v(:)
    integer :: i
    n = 0
    if (err%code /= 0) return
    call raw(self, p, v, n, err)
    if (err%code /= 0) return
    n = min(n, size(x))
    do i = 1, n
      call to_real(self, p, v(i)%s, x(i), err)
      if (err%code /= 0) return
    end do
  end subroutine get_reals

  subroutine to_int(self, p, t, x, err)
    class(empm_group_t), intent(in) :: self
    type(empm_param_t), intent(in) :: p
    character(len=*), intent(in) :: t
    integer, intent(out) :: x
    type(empm_error_t), intent(inout) :: err
    integer :: ios
    x = 0
    read(t, *, iostat=ios) x
    if (ios /= 0 .or. len_trim(t) == 0 .or. verify(trim(t), '+-0123456789') > 0) then
      call self%fail(err, p%name, 'expected an integer, got '''//t//''''); return
    end if
    call check_bounds(self, p, real(x, wp), t, err)
  end subroutine to_int

  subroutine get_int(self, p, x, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_INT)
    integer, intent(inout) :: x                  !! the value (unchanged when absent and optional)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    integer :: a(1)
    integer :: n
    ! One value: the array getter with room for one (the declaration's count is 1).
    a(1) = x
    call self%get_ints(p, a, n, err)
    if (err%code == 0 .and. n > 0) x = a(1)
  end subroutine get_int

  subroutine get_ints(self, p, x, n, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_INT, count > 1)
    integer, intent(inout) :: x(:)               !! values 1..n set, the rest unchanged
    integer, intent(out) :: n                    !! number of values given (0 when absent)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    type(text_t), allocatable :: v(:)
    integer :: i
    n = 0
    if (err%code /= 0) return
    call raw(self, p, v, n, err)
    if (err%code /= 0) return
    n = min(n, size(x))
    do i = 1, n
      call to_int(self, p, v(i)%s, x(i), err)
      if (err%code /= 0) return
    end do
  end subroutine get_ints

  subroutine to_str(self, p, t, x, err)
    class(empm_group_t), intent(in) :: self
    type(empm_param_t), intent(in) :: p
    character(len=*), intent(in) :: t
    character(len=:), allocatable, intent(out) :: x
    type(empm_error_t), intent(inout) :: err
    x = trim(adjustl(t))
    if (len(p%choices) > 0) then
      x = lower(x)
      if (index(' '//p%choices//' ', ' '//x//' ') == 0 .or. len(x) == 0) then
        call self%fail(err, p%name, 'expected one of: '//join_blanks(p%choices)//'; got '''// &
          trim(t)//'''')
      end if
    end if
  end subroutine to_str

  subroutine get_str(self, p, x, err)
    class(empm_group_t), intent(inout) :: self        !! group
    type(empm_param_t), intent(in) :: p               !! declaration (kind PARAM_STR)
    character(len=:), allocatable, intent(inout) :: x !! the value, lower case when `choices`
                                                      !! are declared (unchanged when absent
                                                      !! and optional)
    type(empm_error_t), intent(inout) :: err          !! set when invalid or missing
    type(text_t), allocatable :: v(:)
    integer :: n
    if (err%code /= 0) return
    call raw(self, p, v, n, err)
    if (err%code /= 0 .or. n == 0) return
    call to_str(self, p, v(1)%s, x, err)
  end subroutine get_str

  subroutine get_strs(self, p, x, n, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_STR, count > 1)
    character(len=*), intent(inout) :: x(:)      !! values 1..n set, the rest unchanged
    integer, intent(out) :: n                    !! number of values given (0 when absent)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    type(text_t), allocatable :: v(:)
    character(len=:), allocatable :: s
    integer :: i
    n = 0
    if (err%code /= 0) return
    call raw(self, p, v, n, err)
    if (err%code /= 0) return
    n = min(n, size(x))
    do i = 1, n
      call to_str(self, p, v(i)%s, s, err)
      if (err%code /= 0) return
      if (len(s) > len(x)) then
        call self%fail(err, p%name, 'value '''//s//''' is longer than '//str(len(x))// &
          ' characters'); return
      end if
      x(i) = s
    end do
  end subroutine get_strs

  subroutine to_logical(self, p, t, x, err)
    class(empm_group_t), intent(in) :: self
    type(empm_param_t), intent(in) :: p
    character(len=*), intent(in) :: t
    logical, intent(out) :: x
    type(empm_error_t), intent(inout) :: err
    x = .false.
    select case (lower(trim(t)))
    case ('.true.', '.t.', 't', 'true')
      x = .true.
    case ('.false.', '.f.', 'f', 'false')
      x = .false.
    case default
      call self%fail(err, p%name, 'expected .true. or .false., got '''//t//'''')
    end select
  end subroutine to_logical

  subroutine get_logical(self, p, x, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_LOGICAL)
    logical, intent(inout) :: x                  !! the value (unchanged when absent and optional)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    logical :: a(1)
    integer :: n
    ! One value: the array getter with room for one (the declaration's count is 1).
    a(1) = x
    call self%get_logicals(p, a, n, err)
    if (err%code == 0 .and. n > 0) x = a(1)
  end subroutine get_logical

  subroutine get_logicals(self, p, x, n, err)
    class(empm_group_t), intent(inout) :: self   !! group
    type(empm_param_t), intent(in) :: p          !! declaration (kind PARAM_LOGICAL, count > 1)
    logical, intent(inout) :: x(:)               !! values 1..n set, the rest unchanged
    integer, intent(out) :: n                    !! number of values given (0 when absent)
    type(empm_error_t), intent(inout) :: err     !! set when invalid or missing
    type(text_t), allocatable :: v(:)
    integer :: i
    n = 0
    if (err%code /= 0) return
    call raw(self, p, v, n, err)
    if (err%code /= 0) return
    n = min(n, size(x))
    do i = 1, n
      call to_logical(self, p, v(i)%s, x(i), err)
      if (err%code /= 0) return
    end do
  end subroutine get_logicals
end module empm_namelist
