!> Creates integrators by name (the names accepted in case files and by the API).
module empm_integrator_factory
  use empm_kinds, only: wp
  use empm_integrator, only: empm_integrator_t
  use empm_integrator_euler, only: empm_euler_t, EULER_USF, EULER_USL, EULER_MUSL
  use empm_integrator_pc, only: empm_pc_t, PC_PUBLISHED, PC_NEWMARK
  use empm_integrator_genalpha, only: empm_genalpha_t
  implicit none
  private
  public :: empm_integrator_create, empm_integrator_names

contains

  !> Allocate the integrator called `name`. info = 1 for an unknown name, 2 for a parameter
  !> out of range (γ_N outside [0, 1], ρ_b outside [0, 1]).
  subroutine empm_integrator_create(name, integ, info, newmark_gamma, rho_b)
    character(len=*), intent(in) :: name                         !! scheme name
    class(empm_integrator_t), allocatable, intent(out) :: integ  !! new integrator
    integer, intent(out) :: info                                 !! 0 ok, 1 name, 2 parameter
    real(wp), intent(in), optional :: newmark_gamma  !! γ_N of pc_* schemes (default 0.5)
    real(wp), intent(in), optional :: rho_b          !! ρ_b of gen_alpha (default 0.8)
    real(wp) :: g, r
    info = 0
    g = 0.5_wp; r = 0.8_wp
    if (present(newmark_gamma)) g = newmark_gamma
    if (present(rho_b)) r = rho_b
    if (.not. (g >= 0.0_wp .and. g <= 1.0_wp .and. r >= 0.0_wp .and. r <= 1.0_wp)) then
      info = 2; return
    end if
    select case (trim(name))
    case ('usf');          allocate(integ, source=empm_euler_t(variant=EULER_USF))
    case ('usl');          allocate(integ, source=empm_euler_t(variant=EULER_USL))
    case ('musl');         allocate(integ, source=empm_euler_t(variant=EULER_MUSL))
    case ('pc_published'); allocate(integ, source=empm_pc_t(variant=PC_PUBLISHED, gamma=g))
    case ('pc_newmark');   allocate(integ, source=empm_pc_t(variant=PC_NEWMARK, gamma=g))
    case ('gen_alpha');    allocate(integ, source=empm_genalpha_t(rho_b=r))
    case default;          info = 1
    end select
  end subroutine empm_integrator_create

  !> Comma-separated list of the accepted names, for error messages.
  pure function empm_integrator_names() result(s)
    character(len=:), allocatable :: s !! accepted names
    s = 'usf, usl, musl, pc_published, pc_newmark, gen_alpha'
  end function empm_integrator_names
end module empm_integrator_factory
