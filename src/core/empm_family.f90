!> What every extension point has in common: a family (shape function, material model,
!> integrator) has a registry name, a one-line summary and declared parameters.
!>
!> The parameters are declared in the family's own module ([[empm_param_t]]) and read by the
!> family's own `configure` (each extension point defines its signature); the registry
!> ([[empm_registry]]) lists the families by name, and docs/input.md shows the declarations.
module empm_family
  use empm_params, only: empm_param_t
  implicit none
  private
  public :: empm_family_t

  !> A family of an extension point.
  type, abstract :: empm_family_t
  contains
    procedure(family_iface), deferred :: family
    procedure :: summary => family_summary
    procedure :: params => family_params
  end type empm_family_t

  abstract interface
    !> Registry name of the family, e.g. "lme", "linear_elastic", "pc_newmark".
    pure function family_iface(self) result(s)
      import :: empm_family_t
      class(empm_family_t), intent(in) :: self !! family
      character(len=:), allocatable :: s       !! registry name
    end function family_iface
  end interface

contains

  !> One-line description for listings and docs; the default is empty.
  pure function family_summary(self) result(s)
    class(empm_family_t), intent(in) :: self !! family
    character(len=:), allocatable :: s       !! summary
    associate (unused_ => self); end associate
    s = ''
  end function family_summary

  !> Declared parameters; the default is none.
  pure function family_params(self) result(p)
    class(empm_family_t), intent(in) :: self     !! family
    type(empm_param_t), allocatable :: p(:)      !! declarations
    associate (unused_ => self); end associate
    allocate(p(0))
  end function family_params
end module empm_family
