!> Thin helpers over HDF5's Fortran API: create groups, write real/integer datasets and
!> scalar/string attributes, with one error flag threaded through; open a file read-only and
!> read real datasets (bodies from HDF5 point lists).
module empm_h5
  use hdf5, only: hid_t, hsize_t, size_t, h5gcreate_f, h5gclose_f, &
    h5screate_simple_f, h5screate_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
    h5acreate_f, h5awrite_f, h5aclose_f, h5tcopy_f, h5tset_size_f, h5tclose_f, &
    H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_NATIVE_CHARACTER, H5S_SCALAR_F, &
    h5open_f, h5fopen_f, h5fclose_f, h5fis_hdf5_f, H5F_ACC_RDONLY_F, h5lexists_f, h5dopen_f, &
    h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5dread_f, &
    h5aopen_f, h5aget_type_f, h5tget_size_f, h5aread_f, h5aexists_f, h5sselect_hyperslab_f, &
    h5sselect_none_f, H5S_SELECT_SET_F, H5P_DEFAULT_F, H5S_ALL_F
  use empm_kinds, only: wp
  implicit none
  private
  public :: hid_t, h5_group, h5_close_group, h5_write, h5_attr
  public :: h5_open_read, h5_close_file, h5_exists, h5_dims, h5_read, h5_read_attr
  public :: h5_part_t

  !> This process's part of a dataset that several processes write together into one file
  !> (parallel HDF5, the file opened by all): every process creates the dataset, with the
  !> same shape, and writes its part. A dataset of particles: `total` columns (the last
  !> extent), this process's from column `first` (0-based) on. A dataset every process holds
  !> whole (histories, probes): `total` < 0, and the processes whose `writes` is false select
  !> nothing.
  type :: h5_part_t
    integer(hsize_t) :: first = 0          !! columns of the processes before this one
    integer(hsize_t) :: total = -1         !! the dataset's columns; < 0: the array's own
    logical :: writes = .true.             !! this process writes its array
    integer(hid_t) :: xfer = 0             !! data transfer properties (0: HDF5's default)
  end type h5_part_t

  !> Write a dataset (real rank 1–2, integer rank 1); with `part`, this process's part of it
  !> ([[h5_part_t]]).
  interface h5_write
    module procedure write_r1, write_r2, write_i1
  end interface h5_write

  !> Write an attribute (real scalar or rank 1, integer scalar, string).
  interface h5_attr
    module procedure attr_r0, attr_r1, attr_i0, attr_s
  end interface h5_attr

  !> Read a real dataset of known shape (rank 1–2), converting from its stored type.
  interface h5_read
    module procedure read_r1, read_r2
  end interface h5_read

  !> Read an attribute (a string).
  interface h5_read_attr
    module procedure read_attr_s, read_attr_i, read_attr_r
  end interface h5_read_attr

contains

  !> Create group `name` under `loc`.
  subroutine h5_group(loc, name, gid, ierr)
    integer(hid_t), intent(in) :: loc       !! parent file or group
    character(len=*), intent(in) :: name    !! group name
    integer(hid_t), intent(out) :: gid      !! new group
    integer, intent(inout) :: ierr          !! set non-zero on failure (left as is on success)
    integer :: e
    call h5gcreate_f(loc, name, gid, e)
    if (e /= 0) ierr = e
  end subroutine h5_group

  !> Close a group.
  subroutine h5_close_group(gid, ierr)
    integer(hid_t), intent(in) :: gid   !! group
    integer, intent(inout) :: ierr      !! set non-zero on failure
    integer :: e
    call h5gclose_f(gid, e)
    if (e /= 0) ierr = e
  end subroutine h5_close_group

  subroutine write_r1(loc, name, a, ierr, part)
    integer(hid_t), intent(in) :: loc                 !! parent file or group
    character(len=*), intent(in) :: name              !! dataset name
    real(wp), intent(in) :: a(:)                      !! values (last extent: columns)
    integer, intent(inout) :: ierr                    !! set non-zero on failure
    type(h5_part_t), intent(in), optional :: part     !! this process's part (written together)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: fsid, msid, did, xfer
    integer :: e(5)
    real(wp), allocatable :: buf(:)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call spaces(dims, part, fsid, msid, xfer, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, fsid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_DOUBLE, buf, dims, e(3), msid, fsid, xfer)
    call h5dclose_f(did, e(4)); call close_spaces(fsid, msid, e(5))
    if (any(e /= 0)) ierr = 1
  end subroutine write_r1

  subroutine write_r2(loc, name, a, ierr, part)
    integer(hid_t), intent(in) :: loc                 !! parent file or group
    character(len=*), intent(in) :: name              !! dataset name
    real(wp), intent(in) :: a(:,:)                    !! values (last extent: columns)
    integer, intent(inout) :: ierr                    !! set non-zero on failure
    type(h5_part_t), intent(in), optional :: part     !! this process's part (written together)
    integer(hsize_t) :: dims(2)
    integer(hid_t) :: fsid, msid, did, xfer
    integer :: e(5)
    real(wp), allocatable :: buf(:, :)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call spaces(dims, part, fsid, msid, xfer, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, fsid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_DOUBLE, buf, dims, e(3), msid, fsid, xfer)
    call h5dclose_f(did, e(4)); call close_spaces(fsid, msid, e(5))
    if (any(e /= 0)) ierr = 1
  end subroutine write_r2

  subroutine write_i1(loc, name, a, ierr, part)
    integer(hid_t), intent(in) :: loc                 !! parent file or group
    character(len=*), intent(in) :: name              !! dataset name
    integer, intent(in) :: a(:)                       !! values (last extent: columns)
    integer, intent(inout) :: ierr                    !! set non-zero on failure
    type(h5_part_t), intent(in), optional :: part     !! this process's part (written together)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: fsid, msid, did, xfer
    integer :: e(5)
    integer, allocatable :: buf(:)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call spaces(dims, part, fsid, msid, xfer, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_INTEGER, fsid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_INTEGER, buf, dims, e(3), msid, fsid, xfer)
    call h5dclose_f(did, e(4)); call close_spaces(fsid, msid, e(5))
    if (any(e /= 0)) ierr = 1
  end subroutine write_i1

  ! The dataset's file space and the buffer's memory space (`dims`, the buffer's shape) with
  ! their selections. Without `part`: both the buffer's shape, all of it written. With `part`:
  ! the file space's last extent is part%total (or the buffer's when part%total < 0) and the
  ! buffer goes to the columns from part%first on, or nothing is selected when part%writes is
  ! false or the buffer is empty (the process still takes part in the collective calls).
  subroutine spaces(dims, part, fsid, msid, xfer, e)
    integer(hsize_t), intent(in) :: dims(:)
    type(h5_part_t), intent(in), optional :: part
    integer(hid_t), intent(out) :: fsid, msid, xfer
    integer, intent(out) :: e
    integer(hsize_t) :: fdims(size(dims)), start(size(dims))
    integer :: r, k(5)
    r = size(dims)
    k = 0
    xfer = H5P_DEFAULT_F
    call h5screate_simple_f(r, dims, msid, k(1))
    if (.not. present(part)) then
      call h5screate_simple_f(r, dims, fsid, k(2))
      e = maxval(abs(k)); return
    end if
    if (part%xfer /= 0) xfer = part%xfer
    fdims = dims
    if (part%total >= 0) fdims(r) = part%total
    call h5screate_simple_f(r, fdims, fsid, k(2))
    if (part%writes .and. product(dims) > 0) then
      start = 0
      if (part%total >= 0) start(r) = part%first
      call h5sselect_hyperslab_f(fsid, H5S_SELECT_SET_F, start, dims, k(3))
    else
      call h5sselect_none_f(fsid, k(3)); call h5sselect_none_f(msid, k(4))
    end if
    e = maxval(abs(k))
  end subroutine spaces

  subroutine close_spaces(fsid, msid, e)
    integer(hid_t), intent(in) :: fsid, msid
    integer, intent(out) :: e
    integer :: k(2)
    call h5sclose_f(fsid, k(1)); call h5sclose_f(msid, k(2))
    e = maxval(abs(k))
  end subroutine close_spaces

  subroutine attr_r0(loc, name, x, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: x
    integer, intent(inout) :: ierr
    call attr_r1(loc, name, [x], ierr)
  end subroutine attr_r0

  subroutine attr_r1(loc, name, x, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: x(:)
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: sid, aid
    integer :: e(4)
    dims = shape(x, kind=hsize_t)
    if (size(x) == 1) then
      call h5screate_f(H5S_SCALAR_F, sid, e(1))
    else
      call h5screate_simple_f(1, dims, sid, e(1))
    end if
    call h5acreate_f(loc, name, H5T_NATIVE_DOUBLE, sid, aid, e(2))
    call h5awrite_f(aid, H5T_NATIVE_DOUBLE, x, dims, e(3))
    call h5aclose_f(aid, e(4)); call h5sclose_f(sid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine attr_r1

  subroutine attr_i0(loc, name, i, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: i
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: sid, aid
    integer :: e(4)
    dims = 1
    call h5screate_f(H5S_SCALAR_F, sid, e(1))
    call h5acreate_f(loc, name, H5T_NATIVE_INTEGER, sid, aid, e(2))
    call h5awrite_f(aid, H5T_NATIVE_INTEGER, [i], dims, e(3))
    call h5aclose_f(aid, e(4)); call h5sclose_f(sid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine attr_i0

  subroutine attr_s(loc, name, s, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: s
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: sid, aid, tid
    integer :: e(6)
    dims = 1
    call h5tcopy_f(H5T_NATIVE_CHARACTER, tid, e(1))
    call h5tset_size_f(tid, int(max(len(s), 1), size_t), e(2))
    call h5screate_f(H5S_SCALAR_F, sid, e(3))
    call h5acreate_f(loc, name, tid, sid, aid, e(4))
    if (len(s) > 0) then
      call h5awrite_f(aid, tid, s, dims, e(5))
    else
      call h5awrite_f(aid, tid, ' ', dims, e(5))
    end if
    call h5aclose_f(aid, e(6)); call h5sclose_f(sid, e(3)); call h5tclose_f(tid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine attr_s

  ! ---- reading ------------------------------------------------------------------------------

  !> Open an existing HDF5 file read-only. `ierr` is 1 when the file does not exist, 2 when it
  !> is not an HDF5 file, 3 when it cannot be opened (checked in that order, so that the HDF5
  !> library prints no error stack for the first two).
  subroutine h5_open_read(path, fid, ierr)
    character(len=*), intent(in) :: path   !! file
    integer(hid_t), intent(out) :: fid     !! open file
    integer, intent(out) :: ierr           !! 0 on success
    logical :: there, is_h5
    integer :: e
    fid = -1; ierr = 0
    inquire(file=path, exist=there)
    if (.not. there) then
      ierr = 1; return
    end if
    call h5open_f(e)
    call h5fis_hdf5_f(path, is_h5, e)
    if (e /= 0 .or. .not. is_h5) then
      ierr = 2; return
    end if
    call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, e)
    if (e /= 0) ierr = 3
  end subroutine h5_open_read

  !> Close a file opened by [[h5_open_read]].
  subroutine h5_close_file(fid, ierr)
    integer(hid_t), intent(in) :: fid   !! file
    integer, intent(inout) :: ierr      !! set non-zero on failure
    integer :: e
    call h5fclose_f(fid, e)
    if (e /= 0) ierr = e
  end subroutine h5_close_file

  !> True when `loc` has a link called `name` (a dataset or group directly under it).
  logical function h5_exists(loc, name) result(there)
    integer(hid_t), intent(in) :: loc       !! file or group
    character(len=*), intent(in) :: name    !! link name (no '/')
    integer :: e
    call h5lexists_f(loc, name, there, e)
    if (e /= 0) there = .false.
  end function h5_exists

  !> Dimensions of dataset `name` in Fortran order (an array written from C or Python with
  !> shape (n, 3) reads as (3, n)); `ierr` non-zero when it cannot be opened.
  subroutine h5_dims(loc, name, dims, ierr)
    integer(hid_t), intent(in) :: loc                  !! file or group
    character(len=*), intent(in) :: name               !! dataset
    integer(hsize_t), allocatable, intent(out) :: dims(:) !! extent per dimension
    integer, intent(inout) :: ierr                     !! set non-zero on failure
    integer(hid_t) :: did, sid
    integer(hsize_t) :: maxdims(8)
    integer :: e, rank, bad
    allocate(dims(0))
    call h5dopen_f(loc, name, did, e)
    if (e /= 0) then
      ierr = 1; return
    end if
    bad = 0; rank = -1
    call h5dget_space_f(did, sid, e)
    if (e /= 0) bad = 1
    if (bad == 0) call h5sget_simple_extent_ndims_f(sid, rank, e)
    if (bad == 0 .and. e == 0 .and. rank >= 0 .and. rank <= 8) then
      deallocate(dims); allocate(dims(rank))
      ! hdferr is the rank on success, -1 on failure.
      if (rank > 0) call h5sget_simple_extent_dims_f(sid, dims, maxdims(1:rank), e)
      if (e < 0) bad = 1
    else
      bad = 1
    end if
    call h5sclose_f(sid, e); call h5dclose_f(did, e)
    if (bad /= 0) ierr = 1
  end subroutine h5_dims

  !> Read the rank-1 dataset `name` into `a` (sized to the dataset, see [[h5_dims]]); with
  !> `cols` = (first, stride), the entries first, first + stride, ... (0-based) only, as many
  !> as `a` holds.
  subroutine read_r1(loc, name, a, ierr, cols)
    integer(hid_t), intent(in) :: loc        !! file or group
    character(len=*), intent(in) :: name     !! dataset
    real(wp), intent(inout) :: a(:)          !! values (contiguous, the dataset's shape)
    integer, intent(inout) :: ierr           !! set non-zero on failure
    integer, intent(in), optional :: cols(2) !! first column (0-based) and stride
    integer(hsize_t) :: dims(1)
    dims = shape(a, kind=hsize_t)
    call read_any(loc, name, dims, ierr, cols, r1=a)
  end subroutine read_r1

  !> Read the rank-2 dataset `name` into `a` (sized to the dataset in Fortran order); with
  !> `cols` = (first, stride), its columns first, first + stride, ... (0-based) only.
  subroutine read_r2(loc, name, a, ierr, cols)
    integer(hid_t), intent(in) :: loc        !! file or group
    character(len=*), intent(in) :: name     !! dataset
    real(wp), intent(inout) :: a(:,:)        !! values (contiguous, the dataset's shape)
    integer, intent(inout) :: ierr           !! set non-zero on failure
    integer, intent(in), optional :: cols(2) !! first column (0-based) and stride
    integer(hsize_t) :: dims(2)
    dims = shape(a, kind=hsize_t)
    call read_any(loc, name, dims, ierr, cols, r2=a)
  end subroutine read_r2

  ! The reading of read_r1 and read_r2: the whole dataset, or the columns `cols` selects
  ! (the last extent's, a strided hyperslab of the dataset's space; `dims` the buffer's).
  subroutine read_any(loc, name, dims, ierr, cols, r1, r2)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hsize_t), intent(in) :: dims(:)
    integer, intent(inout) :: ierr
    integer, intent(in), optional :: cols(2)
    real(wp), intent(inout), optional :: r1(:), r2(:,:)
    integer(hsize_t) :: start(size(dims)), stride(size(dims))
    integer(hid_t) :: did, fsid, msid
    integer :: e(8), r
    e = 0; r = size(dims)
    call h5dopen_f(loc, name, did, e(1))
    if (e(1) /= 0) then
      ierr = 1; return
    end if
    fsid = H5S_ALL_F; msid = H5S_ALL_F
    if (present(cols)) then
      if (product(dims) == 0) then
        call h5dclose_f(did, e(8)); return
      end if
      call h5dget_space_f(did, fsid, e(2))
      start = 0; start(r) = cols(1)
      stride = 1; stride(r) = cols(2)
      call h5sselect_hyperslab_f(fsid, H5S_SELECT_SET_F, start, dims, e(3), stride=stride)
      call h5screate_simple_f(r, dims, msid, e(4))
    end if
    if (present(r1)) call h5dread_f(did, H5T_NATIVE_DOUBLE, r1, dims, e(5), msid, fsid)
    if (present(r2)) call h5dread_f(did, H5T_NATIVE_DOUBLE, r2, dims, e(5), msid, fsid)
    if (present(cols)) then
      call h5sclose_f(fsid, e(6)); call h5sclose_f(msid, e(7))
    end if
    call h5dclose_f(did, e(8))
    if (any(e /= 0)) ierr = 1
  end subroutine read_any

  !> Read the string attribute `name` of `loc` (a fixed-length string, as [[h5_attr]] writes
  !> it); `ierr` set non-zero when it is missing or not a string.
  subroutine read_attr_s(loc, name, s, ierr)
    integer(hid_t), intent(in) :: loc                !! file, group or dataset
    character(len=*), intent(in) :: name             !! attribute
    character(len=:), allocatable, intent(out) :: s  !! its value
    integer, intent(inout) :: ierr                   !! set non-zero on failure
    integer(hid_t) :: aid, tid
    integer(size_t) :: n
    integer(hsize_t) :: dims(1)
    integer :: e
    s = ''
    if (.not. open_attr(loc, name, aid, ierr)) return
    call h5aget_type_f(aid, tid, e)
    if (e == 0) call h5tget_size_f(tid, n, e)
    if (e == 0 .and. n > 0 .and. n < 100000000_size_t) then
      deallocate(s); allocate(character(len=int(n)) :: s)
      dims = 1
      call h5aread_f(aid, tid, s, dims, e)
    else
      e = 1
    end if
    if (e /= 0) ierr = 1
    call h5tclose_f(tid, e); call h5aclose_f(aid, e)
  end subroutine read_attr_s

  !> Read the scalar integer attribute `name` of `loc`; `ierr` set non-zero when it is
  !> missing or cannot be read as an integer.
  subroutine read_attr_i(loc, name, i, ierr)
    integer(hid_t), intent(in) :: loc                !! file, group or dataset
    character(len=*), intent(in) :: name             !! attribute
    integer, intent(out) :: i                        !! its value
    integer, intent(inout) :: ierr                   !! set non-zero on failure
    integer(hid_t) :: aid
    integer(hsize_t) :: dims(1)
    integer :: buf(1), e
    i = 0; dims = 1
    if (.not. open_attr(loc, name, aid, ierr)) return
    call h5aread_f(aid, H5T_NATIVE_INTEGER, buf, dims, e)
    if (e /= 0) ierr = 1
    i = buf(1)
    call h5aclose_f(aid, e)
  end subroutine read_attr_i

  !> Read the real attribute `name` of `loc` (as many values as `x` holds: 1 for a scalar);
  !> `ierr` set non-zero when it is missing or cannot be read.
  subroutine read_attr_r(loc, name, x, ierr)
    integer(hid_t), intent(in) :: loc                !! file, group or dataset
    character(len=*), intent(in) :: name             !! attribute
    real(wp), intent(out) :: x(:)                    !! its values
    integer, intent(inout) :: ierr                   !! set non-zero on failure
    integer(hid_t) :: aid
    integer(hsize_t) :: dims(1)
    integer :: e
    x = 0.0_wp; dims = size(x, kind=hsize_t)
    if (.not. open_attr(loc, name, aid, ierr)) return
    call h5aread_f(aid, H5T_NATIVE_DOUBLE, x, dims, e)
    if (e /= 0) ierr = 1
    call h5aclose_f(aid, e)
  end subroutine read_attr_r

  ! Open the attribute `name` of `loc` as `aid` (the caller closes it); false, with ierr set,
  ! when it is missing or cannot be opened (HDF5 then prints nothing: it is checked first).
  logical function open_attr(loc, name, aid, ierr) result(ok)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hid_t), intent(out) :: aid
    integer, intent(inout) :: ierr
    logical :: there
    integer :: e
    ok = .false.; aid = -1
    call h5aexists_f(loc, name, there, e)
    if (e /= 0 .or. .not. there) then
      ierr = 1; return
    end if
    call h5aopen_f(loc, name, aid, e)
    if (e /= 0) then
      ierr = 1; return
    end if
    ok = .true.
  end function open_attr

end module empm_h5
