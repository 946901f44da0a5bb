!> Create a shape-function family from its name: the one place that lists every family.
module empm_shape_factory
  use empm_shape, only: empm_shape_t
  use empm_shape_linear, only: empm_shape_linear_t
  use empm_shape_ugimp, only: empm_shape_ugimp_t
  use empm_shape_bspline, only: empm_shape_bspline_t
  use empm_strings, only: lower
  implicit none
  private
  public :: empm_shape_create, empm_shape_names
  public :: SHAPE_CREATE_OK, SHAPE_CREATE_UNKNOWN, SHAPE_CREATE_BAD_NDIM

  integer, parameter :: SHAPE_CREATE_OK = 0       !! family created
  integer, parameter :: SHAPE_CREATE_UNKNOWN = 1  !! no family of that name
  integer, parameter :: SHAPE_CREATE_BAD_NDIM = 2 !! dimension not in 1..3

contains

  !> Allocate the family called `name` (case and surrounding blanks ignored) for dimension
  !> `ndim`. On failure `shape` is left unallocated and `info` is nonzero.
  subroutine empm_shape_create(name, ndim, shape, info)
    character(len=*), intent(in) :: name                         !! family, see [[empm_shape_names]]
    integer, intent(in) :: ndim                                  !! spatial dimension, 1..3
    class(empm_shape_t), allocatable, intent(out) :: shape       !! the new family
    integer, intent(out) :: info                                 !! one of `SHAPE_CREATE_*`
    if (ndim < 1 .or. ndim > 3) then
      info = SHAPE_CREATE_BAD_NDIM; return
    end if
    info = SHAPE_CREATE_OK
    select case (lower(trim(adjustl(name))))
    case ('linear')
      allocate(empm_shape_linear_t :: shape)
    case ('ugimp')
      allocate(empm_shape_ugimp_t :: shape)
    case ('bspline2')
      allocate(shape, source=empm_shape_bspline_t(order=2))
    case ('bspline3')
      allocate(shape, source=empm_shape_bspline_t(order=3))
    ! ---- LME (local max-ent) goes here: case ('lme'), parameters from a later issue. ----
    case default
      info = SHAPE_CREATE_UNKNOWN; return
    end select
    shape%ndim = ndim
  end subroutine empm_shape_create

  !> Supported family names, comma-separated, for error messages.
  pure function empm_shape_names() result(s)
    character(len=:), allocatable :: s !! e.g. "linear, ugimp, bspline2, bspline3"
    s = 'linear, ugimp, bspline2, bspline3'
  end function empm_shape_names
end module empm_shape_factory
