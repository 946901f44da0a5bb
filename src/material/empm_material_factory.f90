!> Material factory: build a material from its name and isotropic elastic constants.
!>
!> Adding a model: one file extending [[empm_material_t]], one entry in `NAMES` and one `case`
!> in [[empm_material_create]].
!>
!> Status codes (`info`): `MAT_OK` (0) success; `MAT_UNKNOWN_NAME` (1) name not in
!> [[empm_material_names]]; `MAT_BAD_E` (2) E not in (0, huge); `MAT_BAD_NU` (3) ν not in
!> (−1, 0.5); `MAT_BAD_RHO0` (4) ρ0 not in (0, huge). [[material_status_text]] explains a code.
module empm_material_factory
  use empm_kinds, only: wp
  use empm_material, only: empm_material_t
  use empm_material_linear_elastic, only: empm_linear_elastic_t, MAT_OK, MAT_BAD_E, MAT_BAD_NU, &
                                          MAT_BAD_RHO0
  use empm_material_neohookean, only: empm_neohookean_t
  use empm_strings, only: lower
  implicit none
  private
  public :: empm_material_create, empm_material_names, material_status_text
  public :: MAT_OK, MAT_UNKNOWN_NAME, MAT_BAD_E, MAT_BAD_NU, MAT_BAD_RHO0, MAT_NAME_LEN

  integer, parameter :: MAT_UNKNOWN_NAME = 1 !! no material of that name
  integer, parameter :: MAT_NAME_LEN = 32    !! length of the names in [[empm_material_names]]

  character(len=MAT_NAME_LEN), parameter :: NAMES(2) = &
    [character(len=MAT_NAME_LEN) :: 'linear_elastic', 'neohookean']

contains

  !> Allocate and initialise the material `name` (case and surrounding blanks ignored).
  !> On failure `mat` is returned unallocated.
  subroutine empm_material_create(name, E, nu, rho0, mat, info)
    character(len=*), intent(in) :: name                    !! model name (see the names list)
    real(wp), intent(in) :: E                               !! Young's modulus [Pa], > 0
    real(wp), intent(in) :: nu                              !! Poisson's ratio, in (−1, 0.5)
    real(wp), intent(in) :: rho0                            !! reference density [kg/m³], > 0
    class(empm_material_t), allocatable, intent(out) :: mat !! the material, if info = 0
    integer, intent(out) :: info                            !! `MAT_*` status code
    select case (trim(adjustl(lower(name))))
    case ('linear_elastic')
      block
        type(empm_linear_elastic_t) :: le
        call le%init(E, nu, rho0, info)
        if (info == MAT_OK) allocate(mat, source=le)
      end block
    case ('neohookean')
      block
        type(empm_neohookean_t) :: nh
        call nh%init(E, nu, rho0, info)
        if (info == MAT_OK) allocate(mat, source=nh)
      end block
    case default
      info = MAT_UNKNOWN_NAME
    end select
  end subroutine empm_material_create

  !> Names accepted by [[empm_material_create]], blank-padded to `MAT_NAME_LEN`.
  pure function empm_material_names() result(list)
    character(len=MAT_NAME_LEN) :: list(size(NAMES)) !! known model names
    list = NAMES
  end function empm_material_names

  !> Human-readable explanation of a `MAT_*` status code.
  pure function material_status_text(info) result(s)
    integer, intent(in) :: info        !! status code
    character(len=:), allocatable :: s !! explanation
    integer :: i
    select case (info)
    case (MAT_OK)
      s = 'ok'
    case (MAT_UNKNOWN_NAME)
      s = 'unknown material name; known:'
      do i = 1, size(NAMES)
        s = s // ' ' // trim(NAMES(i))
      end do
    case (MAT_BAD_E)
      s = "Young's modulus E must be positive and finite"
    case (MAT_BAD_NU)
      s = "Poisson's ratio nu must satisfy -1 < nu < 0.5"
    case (MAT_BAD_RHO0)
      s = 'reference density rho0 must be positive and finite'
    case default
      s = 'unknown material status code'
    end select
  end function material_status_text
end module empm_material_factory
