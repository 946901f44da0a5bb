!> Bodies from files: material points read from a CSV or HDF5 point list, or generated at the
!> quadrature points of a Gmsh mesh ([[empm_gmsh]]). The format follows the extension: `.csv`,
!> `.h5`/`.hdf5`, `.msh`. docs/input.md describes the file layouts.
!>
!> A malformed file is an input error (EMPM_ERR_INPUT) whose message names the file and the
!> line (for CSV also the column; for HDF5 the dataset and the point).
!>
!> Shared among processes, each keeps every `stride`-th point only (`keep`): a CSV file is
!> read line by line and an HDF5 one in blocks of points, so that no process holds the whole
!> list. An HDF5 file's points are all checked on every process (the same error everywhere).
!> A CSV file's lines are all read and their values counted everywhere, but each process
!> converts and checks the values of its own points only: the conversion is the reading's
!> cost. Its error is then the first in the file of those it has: the caller agrees on the
!> earliest line over the processes, which is the error a single process would give. A Gmsh
!> mesh is read whole by every process (its text, nodes and elements, every element checked),
!> which stores its share of the quadrature points only.
module empm_bodies
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_ERR_INPUT, EMPM_OK
  use empm_strings, only: str, lower
  use empm_gmsh, only: empm_gmsh_points, empm_text_to_real
  use empm_h5, only: hid_t, h5_open_read, h5_close_file, h5_exists, h5_dims, h5_read
  use hdf5, only: hsize_t
  implicit none
  private
  public :: empm_body_points_t, empm_read_body

  !> The points of one body, before they become particles.
  type :: empm_body_points_t
    integer :: n = 0                          !! points kept (all, unless `keep`)
    integer :: total = 0                      !! points in the file
    real(wp), allocatable :: x(:,:)           !! positions (ndim, n) [m]
    real(wp), allocatable :: vol(:)           !! volumes (n) [m^ndim]
    logical :: has_velocity = .false.         !! the file gives velocities
    real(wp), allocatable :: v(:,:)           !! velocities (ndim, n) [m/s], 0 where not given
    logical :: has_stress = .false.           !! the file gives stresses
    real(wp), allocatable :: stress(:,:)      !! Cauchy stress, Voigt (6, n) [Pa], 0 where not given
  end type empm_body_points_t

  !> Largest magnitude of a coordinate [m] or a speed [m/s], and of a stress [Pa], accepted from
  !> a file (the case reader's bounds): mass, momentum and energy sums then cannot overflow.
  real(wp), parameter :: XMAX = 1.0e15_wp, SMAX = 1.0e30_wp

  ! A text file read a chunk at a time, line by line ([[reader_next]]).
  integer, parameter :: CHUNK = 1048576
  type :: line_reader_t
    integer :: u = -1                            ! the open unit (stream access)
    integer(int64) :: size = 0                   ! the file's bytes
    integer(int64) :: pos = 1                    ! its next byte to read
    character(len=:), allocatable :: buf         ! bytes read: buf(b:fill) not yet returned
    integer :: b = 1                             ! first byte not yet returned
    integer :: fill = 0                          ! bytes of buf in use
    integer :: seen = 1                          ! buf(b:seen - 1) holds no newline
    character(len=256) :: msg = ''               ! the system's reason of a failed read
  contains
    procedure :: next => reader_next
  end type line_reader_t

  !> CSV column names: position, volume, velocity, stress (Voigt order).
  character(len=6), parameter :: COLS(13) = [character(len=6) :: 'x', 'y', 'z', 'volume', &
    'vx', 'vy', 'vz', 'sxx', 'syy', 'szz', 'syz', 'sxz', 'sxy']

contains

  !> Read the body in `path` (format from the extension) for an `ndim`-dimensional case.
  !> `order` is the quadrature order per direction for a mesh (the case's `ppc`).
  subroutine empm_read_body(path, ndim, order, body, err, keep)
    character(len=*), intent(in) :: path               !! .csv, .h5/.hdf5 or .msh file
    integer, intent(in) :: ndim                        !! spatial dimension (1..3)
    integer, intent(in) :: order                       !! mesh quadrature order (1..4)
    type(empm_body_points_t), intent(out) :: body      !! the points
    type(empm_error_t), intent(inout) :: err           !! set on a malformed file
    integer, intent(in), optional :: keep(2)           !! (first, stride): keep points
                                                       !! first + 1, first + 1 + stride, ...
                                                       !! only (first 0-based); default all
    integer :: kp(2)
    kp = [0, 1]
    if (present(keep)) kp = keep
    select case (extension(path))
    case ('csv')
      call read_csv(path, ndim, kp, body, err)
    case ('h5', 'hdf5')
      call read_hdf5(path, ndim, kp, body, err)
    case ('msh')
      ! Every element read and checked, only the kept quadrature points stored.
      call empm_gmsh_points(path, ndim, order, body%x, body%vol, err, keep=kp, &
                            total=body%total)
      if (err%code /= EMPM_OK) return
      body%n = size(body%vol)
      allocate(body%v(ndim, body%n), body%stress(6, body%n))
      body%v = 0.0_wp; body%stress = 0.0_wp
    case default
      call err%set(EMPM_ERR_INPUT, 'unknown body file format '''//extension(path)// &
        ''': expected .csv, .h5 or .hdf5 (point lists) or .msh (Gmsh 4.1 mesh)', file=path)
    end select
  end subroutine empm_read_body

  pure function extension(path) result(ext)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: ext
    integer :: d, s
    d = index(path, '.', back=.true.); s = index(path, '/', back=.true.)
    ext = ''
    if (d > s) ext = trim(lower(path(d + 1:)))
  end function extension

  ! ---- CSV --------------------------------------------------------------------------------

  !> A header line naming the columns, then one point per line; blank lines and lines
  !> starting with '#' are skipped.
  subroutine read_csv(path, ndim, keep, body, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: ndim, keep(2)
    type(empm_body_points_t), intent(inout) :: body
    type(empm_error_t), intent(inout) :: err
    character(len=:), allocatable :: ln
    character(len=256), allocatable :: fld(:)
    character(len=512) :: msg
    integer, allocatable :: col(:)        ! column -> index into COLS
    real(wp), allocatable :: val(:,:)     ! (13, capacity): the points kept
    real(wp) :: r, row(13)
    integer :: u, ios, lnum, nf, ncol, k, c, n, total, hline, i
    integer :: fb(14), fe(14)             ! a data line's fields: ln(fb(k):fe(k))
    logical :: header_done, big, ok
    type(line_reader_t) :: rd
    ! Line by line, a chunk of the file at a time: the text is never held whole.
    open(newunit=u, file=path, status='old', action='read', form='unformatted', &
         access='stream', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call err%set(EMPM_ERR_INPUT, 'cannot read the point list: '//trim(msg), file=path); return
    end if
    rd%u = u
    inquire(unit=u, size=rd%size)
    header_done = .false.; n = 0; total = 0; lnum = 0; ncol = 0; hline = 0
    allocate(val(13, 256))
    do
      call rd%next(ln, ios)
      if (ios /= 0) exit
      lnum = lnum + 1
      if (len(ln) > 0) then
        if (ln(len(ln):len(ln)) == achar(13)) ln = ln(1:len(ln) - 1)
      end if
      if (len_trim(ln) == 0) cycle
      if (index(adjustl(ln), '#') == 1) cycle
      if (.not. header_done) then
        call split_commas(ln, fld, nf)
        hline = lnum
        call header(fld(1:nf))
        if (err%code /= EMPM_OK) then
          close(u); return
        end if
        header_done = .true.; ncol = nf
        cycle
      end if
      ! The fields, in place (at most 13 columns: a 14th field is one too many).
      nf = 1; fb(1) = 1
      do i = 1, len(ln)
        if (ln(i:i) == ',') then
          if (nf <= 13) then
            fe(nf) = i - 1; fb(nf + 1) = i + 1
          end if
          nf = nf + 1
        else if (ln(i:i) == achar(9)) then
          ln(i:i) = ' '
        end if
      end do
      if (nf <= 14) fe(nf) = len(ln)
      if (nf /= ncol) then
        call err%set(EMPM_ERR_INPUT, 'expected '//str(ncol)//' comma-separated values (as '// &
          'the header at line '//str(hline)//'), got '//str(nf), file=path, line=lnum)
        close(u); return
      end if
      total = total + 1
      ! Another process's point: it converts and checks the values.
      if (total - 1 < keep(1) .or. mod(total - 1 - keep(1), keep(2)) /= 0) cycle
      row = 0.0_wp
      do k = 1, nf
        c = col(k)
        associate (f => ln(fb(k):fe(k)))
        ok = empm_text_to_real(f, r, big)
        if (big) r = huge(r)  ! reported as beyond the magnitude bound below
        if (.not. (ok .or. big)) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): expected a number, got '''//trim(adjustl(f))//'''', file=path, line=lnum)
          close(u); return
        end if
        if (abs(r) > merge(SMAX, merge(XMAX**ndim, XMAX, c == 4), c >= 8)) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): '//trim(adjustl(f))//' is beyond the accepted magnitude ('// &
            trim(merge('1e15 m or m/s; volume 1e15^ndim', '1e30 Pa                        ', &
            c < 8))//')', file=path, line=lnum)
          close(u); return
        end if
        if (c == 4 .and. r <= 0.0_wp) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' (''volume''): expected a '// &
            'volume > 0, got '//trim(adjustl(f)), file=path, line=lnum)
          close(u); return
        end if
        if (beyond(c, ndim) .and. r /= 0.0_wp) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): must be 0 in a '//str(ndim)//'-D case, got '//trim(adjustl(f)), &
            file=path, line=lnum)
          close(u); return
        end if
        end associate
        row(c) = r
      end do
      if (n == size(val, 2)) val = reshape(val, [13, 2 * n], pad=[0.0_wp])
      n = n + 1
      val(:, n) = row
    end do
    close(u)
    if (ios > 0) then
      ! At the line it could not read: the processes agree on the earliest line.
      call err%set(EMPM_ERR_INPUT, 'cannot read the point list after line '//str(lnum)// &
        ': '//trim(rd%msg), file=path, line=lnum + 1); return
    end if
    if (.not. header_done) then
      call err%set(EMPM_ERR_INPUT, 'empty point list: expected a header line naming the '// &
        'columns (x, y, z, volume, ...)', file=path); return
    end if
    if (total == 0) then
      call err%set(EMPM_ERR_INPUT, 'no point after the header', file=path, line=hline); return
    end if
    body%n = n; body%total = total
    body%x = val(1:ndim, 1:n)
    body%vol = val(4, 1:n)
    body%v = val(5:4 + ndim, 1:n)
    body%stress = val(8:13, 1:n)
    body%has_velocity = any(col >= 5 .and. col <= 4 + ndim)
    body%has_stress = any(col >= 8)

  contains

    subroutine header(names)
      character(len=256), intent(in) :: names(:)
      integer :: j, m
      character(len=:), allocatable :: nm, need
      allocate(col(size(names)))
      do j = 1, size(names)
        nm = lower(trim(names(j)))
        ! Quoted names ("x") are accepted, as spreadsheets write them.
        if (len(nm) >= 2) then
          if ((nm(1:1) == '"' .and. nm(len(nm):len(nm)) == '"') .or. &
              (nm(1:1) == '''' .and. nm(len(nm):len(nm)) == '''')) nm = nm(2:len(nm) - 1)
        end if
        col(j) = 0
        do m = 1, size(COLS)
          if (nm == trim(COLS(m))) col(j) = m
        end do
        if (col(j) == 0) then
          call err%set(EMPM_ERR_INPUT, 'header, column '//str(j)//': unknown column '''// &
            nm//'''; expected names among: '//names_list(), file=path, line=lnum); return
        end if
        if (any(col(1:j - 1) == col(j))) then
          call err%set(EMPM_ERR_INPUT, 'header, column '//str(j)//': column '''//nm// &
            ''' given twice', file=path, line=lnum); return
        end if
      end do
      need = ''
      do m = 1, ndim
        if (.not. any(col == m)) need = need//merge(', ', '  ', len(need) > 0)//trim(COLS(m))
      end do
      if (.not. any(col == 4)) need = need//merge(', ', '  ', len(need) > 0)//'volume'
      if (len(need) > 0) call err%set(EMPM_ERR_INPUT, 'header: missing column(s) '// &
        trim(adjustl(need))//' (a '//str(ndim)//'-D body needs '// &
        join_names(COLS(1:ndim))//', volume)', file=path, line=lnum)
    end subroutine header
  end subroutine read_csv

  ! The next line of the file (any length), without its end; ios < 0 at the end of the file,
  ! > 0 when reading failed. The last line needs no newline.
  subroutine reader_next(self, ln, ios)
    class(line_reader_t), intent(inout) :: self
    character(len=:), allocatable, intent(out) :: ln
    integer, intent(out) :: ios
    character(len=:), allocatable :: grown
    integer :: i, n, tail
    ios = 0
    if (.not. allocated(self%buf)) allocate(character(len=CHUNK) :: self%buf)
    do
      ! A line's search resumes where the last one stopped: linear in its length.
      i = index(self%buf(self%seen:self%fill), new_line('a'))
      if (i > 0) then
        i = self%seen + i - 1
        ln = self%buf(self%b:i - 1); self%b = i + 1; self%seen = self%b; return
      end if
      self%seen = self%fill + 1
      if (self%pos > self%size) then
        if (self%b > self%fill) then
          ln = ''; ios = -1; return
        end if
        ln = self%buf(self%b:self%fill); self%b = self%fill + 1; self%seen = self%b; return
      end if
      ! The unread tail to the front, room doubled when a line outgrows it, then the next
      ! chunk of the file.
      tail = self%fill - self%b + 1
      n = int(min(int(CHUNK, int64), self%size - self%pos + 1))
      if (tail + n > len(self%buf)) then
        allocate(character(len=max(2 * len(self%buf), tail + n)) :: grown)
        grown(1:tail) = self%buf(self%b:self%fill)
        call move_alloc(grown, self%buf)
      else if (self%b > 1) then
        self%buf(1:tail) = self%buf(self%b:self%fill)
      end if
      self%seen = self%seen - self%b + 1; self%b = 1; self%fill = tail
      read(self%u, pos=self%pos, iostat=ios, iomsg=self%msg) self%buf(tail + 1:tail + n)
      if (ios /= 0) then
        ios = 1; return
      end if
      self%pos = self%pos + n; self%fill = tail + n
    end do
  end subroutine reader_next

  !> Columns for directions beyond ndim (z in 2D, vy in 1D, ...): accepted when 0.
  pure logical function beyond(c, ndim)
    integer, intent(in) :: c, ndim
    beyond = (c <= 3 .and. c > ndim) .or. (c >= 5 .and. c <= 7 .and. c - 4 > ndim)
  end function beyond

  pure function names_list() result(s)
    character(len=:), allocatable :: s
    s = join_names(COLS)
  end function names_list

  pure function join_names(names) result(s)
    character(len=*), intent(in) :: names(:)
    character(len=:), allocatable :: s
    integer :: j
    s = ''
    do j = 1, size(names)
      s = s//trim(names(j))
      if (j < size(names)) s = s//', '
    end do
  end function join_names

  subroutine split_commas(s, fld, nf)
    character(len=*), intent(in) :: s
    character(len=256), allocatable, intent(out) :: fld(:)
    integer, intent(out) :: nf
    integer :: i, b, k
    nf = 1
    do i = 1, len(s)
      if (s(i:i) == ',') nf = nf + 1
    end do
    allocate(fld(nf))
    b = 1; k = 0
    do i = 1, len(s) + 1
      if (i > len(s)) then
        k = k + 1; fld(k) = adjustl(s(b:))
      else if (s(i:i) == ',') then
        k = k + 1; fld(k) = adjustl(s(b:i - 1)); b = i + 1
      end if
    end do
    do k = 1, nf
      do i = 1, len(fld(k))
        if (fld(k)(i:i) == achar(9)) fld(k)(i:i) = ' '
      end do
      fld(k) = adjustl(fld(k))
    end do
  end subroutine split_commas


  ! ---- HDF5 -------------------------------------------------------------------------------

  !> Datasets /x (ndim, n), /volume (n), optional /v (ndim, n) and /stress (6, n), in
  !> Fortran order (written from C or Python: shapes (n, ndim), (n), (n, ndim), (n, 6)).
  subroutine read_hdf5(path, ndim, keep, body, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: ndim, keep(2)
    type(empm_body_points_t), intent(inout) :: body
    type(empm_error_t), intent(inout) :: err
    ! Points read at a time: every one is checked, those kept are stored.
    integer, parameter :: BLOCK = 65536
    integer(hid_t) :: fid
    integer :: ierr, n, q, q0, m, j, kept
    integer(hsize_t), allocatable :: dims(:)
    real(wp), allocatable :: x(:,:), vol(:), v(:,:), st(:,:)
    call h5_open_read(path, fid, ierr)
    if (ierr /= 0) then
      call err%set(EMPM_ERR_INPUT, trim(merge('cannot open: no such file     ', &
        'not an HDF5 file              ', ierr == 1)), file=path)
      if (ierr == 3) call err%set(EMPM_ERR_INPUT, 'cannot open the HDF5 file', file=path)
      return
    end if
    n = 0
    call dataset_dims('volume', 1, 0, n)
    if (err%code /= EMPM_OK) go to 9
    call dataset_dims('x', 2, ndim, n)
    if (err%code /= EMPM_OK) go to 9
    body%has_velocity = h5_exists(fid, 'v')
    if (body%has_velocity) call dataset_dims('v', 2, ndim, n)
    if (err%code /= EMPM_OK) go to 9
    body%has_stress = h5_exists(fid, 'stress')
    if (body%has_stress) call dataset_dims('stress', 2, 6, n)
    if (err%code /= EMPM_OK) go to 9
    if (n == 0) then
      call err%set(EMPM_ERR_INPUT, 'dataset /volume holds no point', file=path); go to 9
    end if
    body%total = n
    kept = 0
    if (n > keep(1)) kept = (n - 1 - keep(1)) / keep(2) + 1
    allocate(body%x(ndim, kept), body%vol(kept), body%v(ndim, kept), body%stress(6, kept))
    body%n = kept; body%v = 0.0_wp; body%stress = 0.0_wp
    allocate(x(ndim, min(n, BLOCK)), vol(min(n, BLOCK)), v(ndim, min(n, BLOCK)), &
      st(6, min(n, BLOCK)))
    v = 0.0_wp; st = 0.0_wp
    ierr = 0
    do q0 = 0, n - 1, BLOCK
      m = min(BLOCK, n - q0)
      call h5_read(fid, 'volume', vol(1:m), ierr, [q0, 1])
      call h5_read(fid, 'x', x(:, 1:m), ierr, [q0, 1])
      if (body%has_velocity) call h5_read(fid, 'v', v(:, 1:m), ierr, [q0, 1])
      if (body%has_stress) call h5_read(fid, 'stress', st(:, 1:m), ierr, [q0, 1])
      if (ierr /= 0) then
        call err%set(EMPM_ERR_INPUT, 'cannot read the datasets', file=path); go to 9
      end if
      do j = 1, m
        q = q0 + j
        if (.not. all(ieee_is_finite(x(:, j))) .or. .not. ieee_is_finite(vol(j)) .or. &
            .not. all(ieee_is_finite(v(:, j))) .or. .not. all(ieee_is_finite(st(:, j)))) then
          call err%set(EMPM_ERR_INPUT, 'point '//str(q)//': a value is not finite', file=path)
          go to 9
        end if
        if (any(abs(x(:, j)) > XMAX) .or. any(abs(v(:, j)) > XMAX) .or. &
            vol(j) > XMAX**ndim .or. any(abs(st(:, j)) > SMAX)) then
          call err%set(EMPM_ERR_INPUT, 'point '//str(q)//': a value is beyond the accepted '// &
            'magnitude (1e15 m or m/s, volume 1e15^ndim, 1e30 Pa)', file=path); go to 9
        end if
        if (vol(j) <= 0.0_wp) then
          call err%set(EMPM_ERR_INPUT, 'dataset /volume, point '//str(q)//': expected a '// &
            'volume > 0, got '//str(vol(j)), file=path); go to 9
        end if
        if (q - 1 < keep(1) .or. mod(q - 1 - keep(1), keep(2)) /= 0) cycle
        kept = (q - 1 - keep(1)) / keep(2) + 1
        body%x(:, kept) = x(:, j); body%vol(kept) = vol(j)
        body%v(:, kept) = v(:, j); body%stress(:, kept) = st(:, j)
      end do
    end do
9   call h5_close_file(fid, ierr)

  contains

    !> Check that dataset `name` exists and has rank `rank` with (rows, n) or (n) extents;
    !> `n` < 1 on entry takes the count from this dataset.
    subroutine dataset_dims(name, rank, rows, n)
      character(len=*), intent(in) :: name
      integer, intent(in) :: rank, rows
      integer, intent(inout) :: n
      character(len=:), allocatable :: want
      integer :: ie
      logical :: bad
      if (rank == 1) then
        want = '(n)'
      else
        want = '('//str(rows)//', n)'
      end if
      if (.not. h5_exists(fid, name)) then
        call err%set(EMPM_ERR_INPUT, 'missing dataset /'//name//' '//want, file=path); return
      end if
      ie = 0
      call h5_dims(fid, name, dims, ie)
      if (ie /= 0) then
        call err%set(EMPM_ERR_INPUT, 'cannot read dataset /'//name, file=path); return
      end if
      if (size(dims) /= rank) then
        call err%set(EMPM_ERR_INPUT, 'dataset /'//name//': expected rank '//str(rank)// &
          ' '//want//' (Fortran order), got rank '//str(size(dims)), file=path); return
      end if
      if (rank == 1 .and. n < 1) n = int(dims(1))
      ! (no short-circuit in Fortran: compare whole arrays)
      if (rank == 1) then
        bad = any(dims /= [n])
      else
        bad = any(dims /= [rows, n])
      end if
      if (bad) then
        call err%set(EMPM_ERR_INPUT, 'dataset /'//name//': expected shape '//want// &
          ' (Fortran order; (n, '//str(rows)//') from C or Python), got '//dims_text(dims), &
          file=path)
      end if
    end subroutine dataset_dims
  end subroutine read_hdf5

  pure function dims_text(d) result(s)
    integer(hsize_t), intent(in) :: d(:)
    character(len=:), allocatable :: s
    integer :: j
    s = '('
    do j = 1, size(d)
      s = s//str(int(d(j)))
      if (j < size(d)) s = s//', '
    end do
    s = s//')'
  end function dims_text
end module empm_bodies
