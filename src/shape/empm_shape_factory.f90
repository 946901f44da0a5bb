!> Create a shape-function family from its name: the one place that lists every family.
module empm_shape_factory
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use empm_shape, only: empm_shape_t
  use empm_shape_linear, only: empm_shape_linear_t
  use empm_shape_ugimp, only: empm_shape_ugimp_t
  use empm_shape_bspline, only: empm_shape_bspline_t
  use empm_shape_lme, only: empm_shape_lme_t
  use empm_kinds, only: wp
  use empm_strings, only: lower
  implicit none
  private
  public :: empm_shape_create, empm_shape_names
  public :: SHAPE_CREATE_OK, SHAPE_CREATE_UNKNOWN, SHAPE_CREATE_BAD_NDIM, SHAPE_CREATE_BAD_PARAM

  integer, parameter :: SHAPE_CREATE_OK = 0        !! family created
  integer, parameter :: SHAPE_CREATE_UNKNOWN = 1   !! no family of that name
  integer, parameter :: SHAPE_CREATE_BAD_NDIM = 2  !! dimension not in 1..3
  integer, parameter :: SHAPE_CREATE_BAD_PARAM = 3 !! LME: γ ≤ 0 or tol0 outside (0, 1)

contains

  !> Allocate the family called `name` (case and surrounding blanks ignored) for dimension
  !> `ndim`. On failure `shape` is left unallocated and `info` is nonzero.
  !>
  !> 'lme' takes γ and tol0 from `gamma` (default 3) and `tol0` (default 1e-6); a name
  !> 'lme_g<γ>' (as returned by `name()`, e.g. 'lme_g0.8') sets γ from the name instead.
  subroutine empm_shape_create(name, ndim, shape, info, gamma, tol0)
    character(len=*), intent(in) :: name                         !! family, see [[empm_shape_names]]
    integer, intent(in) :: ndim                                  !! spatial dimension, 1..3
    class(empm_shape_t), allocatable, intent(out) :: shape       !! the new family
    integer, intent(out) :: info                                 !! one of `SHAPE_CREATE_*`
    real(wp), intent(in), optional :: gamma                      !! LME γ = β h² > 0
    real(wp), intent(in), optional :: tol0                       !! LME truncation, 0 < tol0 < 1
    character(len=:), allocatable :: key
    real(wp) :: g, t
    integer :: ios
    if (ndim < 1 .or. ndim > 3) then
      info = SHAPE_CREATE_BAD_NDIM; return
    end if
    info = SHAPE_CREATE_OK
    key = lower(trim(adjustl(name)))
    g = 3.0_wp; t = 1.0e-6_wp
    if (present(gamma)) g = gamma
    if (present(tol0)) t = tol0
    if (len(key) > 5) then
      if (key(1:5) == 'lme_g') then
        read(key(6:), *, iostat=ios) g
        if (ios /= 0) then
          info = SHAPE_CREATE_UNKNOWN; return
        end if
        key = 'lme'
      end if
    end if
    select case (key)
    case ('linear')
      allocate(empm_shape_linear_t :: shape)
    case ('ugimp')
      allocate(empm_shape_ugimp_t :: shape)
    case ('bspline2')
      allocate(shape, source=empm_shape_bspline_t(order=2))
    case ('bspline3')
      allocate(shape, source=empm_shape_bspline_t(order=3))
    case ('lme')
      if (.not. (ieee_is_finite(g) .and. ieee_is_finite(t))) then
        info = SHAPE_CREATE_BAD_PARAM; return
      end if
      if (.not. (g > 0.0_wp .and. t > 0.0_wp .and. t < 1.0_wp)) then
        info = SHAPE_CREATE_BAD_PARAM; return
      end if
      allocate(shape, source=empm_shape_lme_t(gamma=g, tol0=t))
    case default
      info = SHAPE_CREATE_UNKNOWN; return
    end select
    shape%ndim = ndim
  end subroutine empm_shape_create

  !> Supported family names, comma-separated, for error messages.
  pure function empm_shape_names() result(s)
    character(len=:), allocatable :: s !! e.g. "linear, ugimp, bspline2, bspline3, lme"
    s = 'linear, ugimp, bspline2, bspline3, lme'
  end function empm_shape_names
end module empm_shape_factory
