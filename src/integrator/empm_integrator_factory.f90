!> Creates integrators by name (the names accepted in case files and by the API).
module empm_integrator_factory
  use empm_integrator, only: empm_integrator_t
  use empm_integrator_euler, only: empm_euler_t, EULER_USF, EULER_USL, EULER_MUSL
  implicit none
  private
  public :: empm_integrator_create, empm_integrator_names

contains

  !> Allocate the integrator called `name`; info = 1 for an unknown name.
  subroutine empm_integrator_create(name, integ, info)
    character(len=*), intent(in) :: name                           !! scheme name
    class(empm_integrator_t), allocatable, intent(out) :: integ    !! new integrator
    integer, intent(out) :: info                                   !! 0 ok, 1 unknown name
    info = 0
    select case (trim(name))
    case ('usf');  allocate(integ, source=empm_euler_t(variant=EULER_USF))
    case ('usl');  allocate(integ, source=empm_euler_t(variant=EULER_USL))
    case ('musl'); allocate(integ, source=empm_euler_t(variant=EULER_MUSL))
    ! Later schemes (pc_published, pc_newmark, gen_alpha) are added here.
    case default;  info = 1
    end select
  end subroutine empm_integrator_create

  !> Comma-separated list of the accepted names, for error messages.
  pure function empm_integrator_names() result(s)
    character(len=:), allocatable :: s !! accepted names
    s = 'usf, usl, musl'
  end function empm_integrator_names
end module empm_integrator_factory
