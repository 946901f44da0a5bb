!> External loads: gravity (constant or with the paper's sinusoidal ramp, eq. 46) and an
!> optional user body force (used by manufactured solutions).
!>
!> The body force is an object extending [[empm_body_force_t]], so that it can carry its own
!> parameters (no global state); it is evaluated once per step for all particles.
module empm_loads
  use empm_kinds, only: wp, pi
  implicit none
  private
  public :: empm_loads_t, empm_body_force_t, RAMP_NONE, RAMP_SINE

  integer, parameter :: RAMP_NONE = 0 !! gravity constant in time
  integer, parameter :: RAMP_SINE = 1 !! paper eq. (46): sinusoidal rise to t_ramp/2, then constant

  !> A user body force per unit mass, b(X, x, t).
  type, abstract :: empm_body_force_t
  contains
    procedure(body_force_iface), deferred :: eval
  end type empm_body_force_t

  abstract interface
    !> Body force per unit mass at `n` particles (added to gravity).
    subroutine body_force_iface(self, t, x0, x, b)
      import :: empm_body_force_t, wp
      class(empm_body_force_t), intent(in) :: self !! body-force object
      real(wp), intent(in) :: t          !! time [s]
      real(wp), intent(in) :: x0(:,:)    !! reference positions (ndim, n) [m]
      real(wp), intent(in) :: x(:,:)     !! current positions (ndim, n) [m]
      real(wp), intent(out) :: b(:,:)    !! body force per unit mass (ndim, n) [m/s²]
    end subroutine body_force_iface
  end interface

  !> Load definition of a model.
  type :: empm_loads_t
    real(wp) :: gravity(3) = 0.0_wp                 !! final gravity vector [m/s²]
    integer :: ramp = RAMP_NONE                     !! RAMP_NONE or RAMP_SINE
    real(wp) :: t_ramp = 0.0_wp                     !! ramp period T of eq. (46) [s]
    class(empm_body_force_t), allocatable :: body_force !! optional user body force
  contains
    procedure :: gravity_at => loads_gravity_at
  end type empm_loads_t

contains

  !> Gravity vector at time `t`: constant, or eq. (46)
  !> g(t) = ½ g (sin(2πt/T − π/2) + 1) for t ≤ T/2 and g afterwards.
  pure function loads_gravity_at(self, t) result(g)
    class(empm_loads_t), intent(in) :: self !! loads
    real(wp), intent(in) :: t               !! time [s]
    real(wp) :: g(3)                        !! gravity [m/s²]
    g = self%gravity
    if (self%ramp == RAMP_SINE) then
      if (t <= 0.5_wp * self%t_ramp) &
        g = 0.5_wp * self%gravity * (sin(2.0_wp * pi * t / self%t_ramp - 0.5_wp * pi) + 1.0_wp)
    end if
  end function loads_gravity_at
end module empm_loads
