!> Material extension point: the abstract constitutive model.
!>
!> A model updates a batch of particles (a contiguous range of the particle arrays) from the
!> velocity gradient of the step. Adding a material means adding one file that extends
!> [[empm_material_t]] and one line in [[empm_material_factory]].
!>
!> Kinematics: 1D is uniaxial strain (only xx is non-zero), 2D is plane strain (zz strain zero,
!> zz stress generally not), 3D is general. Voigt order (xx, yy, zz, yz, xz, xy), tensor shears.
module empm_material
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_material_t

  !> Abstract material.
  type, abstract :: empm_material_t
    real(wp) :: rho0 = 0.0_wp           !! reference density [kg/m³]
  contains
    procedure(update_iface), deferred :: update
    procedure(wave_speed_iface), deferred :: wave_speed
    procedure(energy_iface), deferred :: energy_density
    procedure(name_iface), deferred :: name
  end type empm_material_t

  abstract interface
    !> Advance the state of `n` particles over a step `dt` with velocity gradients `L`.
    !> Updates the deformation gradient, the accumulated strain, the Cauchy stress and the
    !> density (rho is updated as the model's kinematics dictate; see each model). The arrays
    !> are contiguous (the particle arrays' sections for a run of particles are; anything else
    !> is copied in and out by the compiler).
    pure subroutine update_iface(self, dt, L, F, strain, stress, rho, info)
      import :: empm_material_t, wp
      class(empm_material_t), intent(in) :: self  !! material
      real(wp), intent(in) :: dt                  !! time step [s]
      real(wp), intent(in), contiguous :: L(:,:,:)         !! velocity gradient (3,3,n) [1/s]
      real(wp), intent(inout), contiguous :: F(:,:,:)      !! deformation gradient (3,3,n)
      real(wp), intent(inout), contiguous :: strain(:,:)   !! small strain, Voigt (6,n)
      real(wp), intent(inout), contiguous :: stress(:,:)   !! Cauchy stress, Voigt (6,n) [Pa]
      real(wp), intent(inout), contiguous :: rho(:)        !! density (n) [kg/m³]
      integer, intent(out) :: info                !! 0 ok; k > 0: particle k of the batch failed
    end subroutine update_iface

    !> Dilatational (P-) wave speed at density `rho`, used for the CFL time step [m/s].
    pure real(wp) function wave_speed_iface(self, rho)
      import :: empm_material_t, wp
      class(empm_material_t), intent(in) :: self !! material
      real(wp), intent(in) :: rho                !! current density [kg/m³]
    end function wave_speed_iface

    !> Stored energy per unit current volume for `n` particles [J/m³].
    pure subroutine energy_iface(self, F, strain, stress, psi)
      import :: empm_material_t, wp
      class(empm_material_t), intent(in) :: self !! material
      real(wp), intent(in) :: F(:,:,:)           !! deformation gradient (3,3,n)
      real(wp), intent(in) :: strain(:,:)        !! small strain (6,n)
      real(wp), intent(in) :: stress(:,:)        !! Cauchy stress (6,n)
      real(wp), intent(out) :: psi(:)            !! energy density per current volume (n)
    end subroutine energy_iface

    !> Short identifier, e.g. "linear_elastic".
    function name_iface(self) result(s)
      import :: empm_material_t
      class(empm_material_t), intent(in) :: self !! material
      character(len=:), allocatable :: s         !! identifier
    end function name_iface
  end interface
end module empm_material
