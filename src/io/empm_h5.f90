!> Thin helpers over HDF5's Fortran API: create groups, write real/integer datasets and
!> scalar/string attributes, with one error flag threaded through.
module empm_h5
  use hdf5, only: hid_t, hsize_t, size_t, h5gcreate_f, h5gclose_f, &
    h5screate_simple_f, h5screate_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
    h5acreate_f, h5awrite_f, h5aclose_f, h5tcopy_f, h5tset_size_f, h5tclose_f, &
    H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_NATIVE_CHARACTER, H5S_SCALAR_F
  use empm_kinds, only: wp
  implicit none
  private
  public :: hid_t, h5_group, h5_close_group, h5_write, h5_attr

  !> Write a dataset (real rank 1–2, integer rank 1).
  interface h5_write
    module procedure write_r1, write_r2, write_i1
  end interface h5_write

  !> Write an attribute (real scalar or rank 1, integer scalar, string).
  interface h5_attr
    module procedure attr_r0, attr_r1, attr_i0, attr_s
  end interface h5_attr

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

  subroutine write_r1(loc, name, a, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: a(:)
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: sid, did
    integer :: e(4)
    real(wp), allocatable :: buf(:)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call h5screate_simple_f(1, dims, sid, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, sid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_DOUBLE, buf, dims, e(3))
    call h5dclose_f(did, e(4)); call h5sclose_f(sid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine write_r1

  subroutine write_r2(loc, name, a, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: a(:,:)
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(2)
    integer(hid_t) :: sid, did
    integer :: e(4)
    real(wp), allocatable :: buf(:, :)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call h5screate_simple_f(2, dims, sid, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, sid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_DOUBLE, buf, dims, e(3))
    call h5dclose_f(did, e(4)); call h5sclose_f(sid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine write_r2

  subroutine write_i1(loc, name, a, ierr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: a(:)
    integer, intent(inout) :: ierr
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: sid, did
    integer :: e(4)
    integer, allocatable :: buf(:)
    dims = shape(a, kind=hsize_t)
    buf = a  ! contiguous copy for the C library (a may be a strided section)
    call h5screate_simple_f(1, dims, sid, e(1))
    call h5dcreate_f(loc, name, H5T_NATIVE_INTEGER, sid, did, e(2))
    call h5dwrite_f(did, H5T_NATIVE_INTEGER, buf, dims, e(3))
    call h5dclose_f(did, e(4)); call h5sclose_f(sid, e(1))
    if (any(e /= 0)) ierr = 1
  end subroutine write_i1

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

end module empm_h5
