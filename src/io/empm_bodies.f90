!> Bodies from files: material points read from a CSV or HDF5 point list, or generated at the
!> quadrature points of a Gmsh mesh ([[empm_gmsh]]). The format follows the extension: `.csv`,
!> `.h5`/`.hdf5`, `.msh`. docs/input.md describes the file layouts.
!>
!> A malformed file is an input error (EMPM_ERR_INPUT) whose message names the file and the
!> line (for CSV also the column; for HDF5 the dataset and the point).
module empm_bodies
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, EMPM_ERR_INPUT, EMPM_OK
  use empm_files, only: empm_read_text
  use empm_strings, only: str, lower
  use empm_gmsh, only: empm_gmsh_points, empm_text_to_real
  use empm_h5, only: hid_t, h5_open_read, h5_close_file, h5_exists, h5_dims, h5_read
  use hdf5, only: hsize_t
  implicit none
  private
  public :: empm_body_points_t, empm_read_body, empm_body_path

  !> The points of one body, before they become particles.
  type :: empm_body_points_t
    integer :: n = 0                          !! points
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

  !> CSV column names: position, volume, velocity, stress (Voigt order).
  character(len=6), parameter :: COLS(13) = [character(len=6) :: 'x', 'y', 'z', 'volume', &
    'vx', 'vy', 'vz', 'sxx', 'syy', 'szz', 'syz', 'sxz', 'sxy']

contains

  !> `file` relative to the folder of `case_file` (an absolute `file` is kept as is).
  pure function empm_body_path(case_file, file) result(path)
    character(len=*), intent(in) :: case_file  !! the case file's path
    character(len=*), intent(in) :: file       !! as written in the case file
    character(len=:), allocatable :: path      !! path to open
    integer :: s
    path = trim(adjustl(file))
    if (len(path) == 0) return
    if (path(1:1) == '/') return
    s = index(case_file, '/', back=.true.)
    if (s > 0) path = case_file(1:s)//path
  end function empm_body_path

  !> Read the body in `path` (format from the extension) for an `ndim`-dimensional case.
  !> `order` is the quadrature order per direction for a mesh (the case's `ppc`).
  subroutine empm_read_body(path, ndim, order, body, err)
    character(len=*), intent(in) :: path               !! .csv, .h5/.hdf5 or .msh file
    integer, intent(in) :: ndim                        !! spatial dimension (1..3)
    integer, intent(in) :: order                       !! mesh quadrature order (1..4)
    type(empm_body_points_t), intent(out) :: body      !! the points
    type(empm_error_t), intent(inout) :: err           !! set on a malformed file
    select case (extension(path))
    case ('csv')
      call read_csv(path, ndim, body, err)
    case ('h5', 'hdf5')
      call read_hdf5(path, ndim, body, err)
    case ('msh')
      call empm_gmsh_points(path, ndim, order, body%x, body%vol, err)
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
  subroutine read_csv(path, ndim, body, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: ndim
    type(empm_body_points_t), intent(inout) :: body
    type(empm_error_t), intent(inout) :: err
    type(empm_error_t) :: e
    character(len=:), allocatable :: text, ln
    character(len=256), allocatable :: fld(:)
    integer, allocatable :: col(:)        ! column -> index into COLS
    real(wp), allocatable :: val(:,:)     ! (13, capacity)
    real(wp) :: r
    integer :: b, i, lnum, nf, ncol, k, c, n, hline
    logical :: header_done, big, ok
    call empm_read_text(path, text, e)
    if (e%code /= EMPM_OK) then
      call err%set(EMPM_ERR_INPUT, 'cannot read the point list: '//e%message, file=path); return
    end if
    header_done = .false.; n = 0; lnum = 0; b = 1; ncol = 0; hline = 0
    allocate(val(13, 256))
    do while (b <= len(text))
      i = index(text(b:), new_line('a'))
      if (i == 0) i = len(text) - b + 2
      ln = text(b:b + i - 2)
      b = b + i
      lnum = lnum + 1
      if (len(ln) > 0) then
        if (ln(len(ln):len(ln)) == achar(13)) ln = ln(1:len(ln) - 1)
      end if
      if (len_trim(ln) == 0) cycle
      if (index(adjustl(ln), '#') == 1) cycle
      call split_commas(ln, fld, nf)
      if (.not. header_done) then
        hline = lnum
        call header(fld(1:nf))
        if (err%code /= EMPM_OK) return
        header_done = .true.; ncol = nf
        cycle
      end if
      if (nf /= ncol) then
        call err%set(EMPM_ERR_INPUT, 'expected '//str(ncol)//' comma-separated values (as '// &
          'the header at line '//str(hline)//'), got '//str(nf), file=path, line=lnum); return
      end if
      if (n == size(val, 2)) val = reshape(val, [13, 2 * n], pad=[0.0_wp])
      n = n + 1
      val(:, n) = 0.0_wp
      do k = 1, nf
        c = col(k)
        ok = empm_text_to_real(fld(k), r, big)
        if (big) r = huge(r)  ! reported as beyond the magnitude bound below
        if (.not. (ok .or. big)) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): expected a number, got '''//trim(fld(k))//'''', file=path, line=lnum); return
        end if
        if (abs(r) > merge(SMAX, merge(XMAX**ndim, XMAX, c == 4), c >= 8)) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): '//trim(fld(k))//' is beyond the accepted magnitude ('// &
            trim(merge('1e15 m or m/s; volume 1e15^ndim', '1e30 Pa                        ', &
            c < 8))//')', file=path, line=lnum); return
        end if
        if (c == 4 .and. r <= 0.0_wp) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' (''volume''): expected a '// &
            'volume > 0, got '//trim(fld(k)), file=path, line=lnum); return
        end if
        if (beyond(c, ndim) .and. r /= 0.0_wp) then
          call err%set(EMPM_ERR_INPUT, 'column '//str(k)//' ('''//trim(COLS(c))// &
            '''): must be 0 in a '//str(ndim)//'-D case, got '//trim(fld(k)), file=path, &
            line=lnum); return
        end if
        val(c, n) = r
      end do
    end do
    if (.not. header_done) then
      call err%set(EMPM_ERR_INPUT, 'empty point list: expected a header line naming the '// &
        'columns (x, y, z, volume, ...)', file=path); return
    end if
    if (n == 0) then
      call err%set(EMPM_ERR_INPUT, 'no point after the header', file=path, line=hline); return
    end if
    body%n = n
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
  subroutine read_hdf5(path, ndim, body, err)
    character(len=*), intent(in) :: path
    integer, intent(in) :: ndim
    type(empm_body_points_t), intent(inout) :: body
    type(empm_error_t), intent(inout) :: err
    integer(hid_t) :: fid
    integer :: ierr, n, q
    integer(hsize_t), allocatable :: dims(:)
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
    allocate(body%x(ndim, n), body%vol(n), body%v(ndim, n), body%stress(6, n))
    body%n = n; body%v = 0.0_wp; body%stress = 0.0_wp
    call dataset_dims('x', 2, ndim, n)
    if (err%code /= EMPM_OK) go to 9
    ierr = 0
    call h5_read(fid, 'volume', body%vol, ierr)
    call h5_read(fid, 'x', body%x, ierr)
    body%has_velocity = h5_exists(fid, 'v')
    if (body%has_velocity) then
      call dataset_dims('v', 2, ndim, n)
      if (err%code /= EMPM_OK) go to 9
      call h5_read(fid, 'v', body%v, ierr)
    end if
    body%has_stress = h5_exists(fid, 'stress')
    if (body%has_stress) then
      call dataset_dims('stress', 2, 6, n)
      if (err%code /= EMPM_OK) go to 9
      call h5_read(fid, 'stress', body%stress, ierr)
    end if
    if (ierr /= 0) then
      call err%set(EMPM_ERR_INPUT, 'cannot read the datasets', file=path); go to 9
    end if
    do q = 1, n
      if (.not. all(ieee_is_finite(body%x(:, q))) .or. .not. ieee_is_finite(body%vol(q)) .or. &
          .not. all(ieee_is_finite(body%v(:, q))) .or. &
          .not. all(ieee_is_finite(body%stress(:, q)))) then
        call err%set(EMPM_ERR_INPUT, 'point '//str(q)//': a value is not finite', file=path)
        go to 9
      end if
      if (any(abs(body%x(:, q)) > XMAX) .or. any(abs(body%v(:, q)) > XMAX) .or. &
          body%vol(q) > XMAX**ndim .or. any(abs(body%stress(:, q)) > SMAX)) then
        call err%set(EMPM_ERR_INPUT, 'point '//str(q)//': a value is beyond the accepted '// &
          'magnitude (1e15 m or m/s, volume 1e15^ndim, 1e30 Pa)', file=path); go to 9
      end if
      if (body%vol(q) <= 0.0_wp) then
        call err%set(EMPM_ERR_INPUT, 'dataset /volume, point '//str(q)//': expected a '// &
          'volume > 0, got '//str(body%vol(q)), file=path); go to 9
      end if
    end do
    if (n == 0) call err%set(EMPM_ERR_INPUT, 'dataset /volume holds no point', file=path)
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
