!> Exact solution of the vibrating continuum bar (docs/algorithms §3): fixed at x = 0, free at
!> x = L, first mode. β = π/(2L), ω = β sqrt(E/ρ), v = v0 cos(ωt) sin(βx),
!> u = (v0/ω) sin(ωt) sin(βx), σ = E ∂u/∂x = E β (v0/ω) sin(ωt) cos(βx).
module empm_exact_bar
  use empm_kinds, only: wp, pi
  implicit none
  private
  public :: empm_vibrating_bar_t

  !> Parameters of the vibrating bar.
  type :: empm_vibrating_bar_t
    real(wp) :: L = 25.0_wp     !! length [m]
    real(wp) :: E = 100.0_wp    !! Young's modulus [Pa]
    real(wp) :: rho = 1.0_wp    !! density [kg/m³]
    real(wp) :: v0 = 1.0e-3_wp  !! velocity amplitude [m/s]
  contains
    procedure :: beta => bar_beta
    procedure :: omega => bar_omega
    procedure :: velocity => bar_velocity
    procedure :: displacement => bar_displacement
    procedure :: stress => bar_stress
  end type empm_vibrating_bar_t

contains

  !> Wavenumber β = π/(2L) [1/m].
  elemental real(wp) function bar_beta(self)
    class(empm_vibrating_bar_t), intent(in) :: self !! bar
    bar_beta = pi / (2.0_wp * self%L)
  end function bar_beta

  !> Angular frequency ω = β sqrt(E/ρ) [rad/s].
  elemental real(wp) function bar_omega(self)
    class(empm_vibrating_bar_t), intent(in) :: self !! bar
    bar_omega = self%beta() * sqrt(self%E / self%rho)
  end function bar_omega

  !> Velocity at reference position `x` and time `t` [m/s].
  elemental real(wp) function bar_velocity(self, x, t)
    class(empm_vibrating_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: x !! reference position [m]
    real(wp), intent(in) :: t !! time [s]
    bar_velocity = self%v0 * cos(self%omega() * t) * sin(self%beta() * x)
  end function bar_velocity

  !> Displacement at reference position `x` and time `t` [m].
  elemental real(wp) function bar_displacement(self, x, t)
    class(empm_vibrating_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: x !! reference position [m]
    real(wp), intent(in) :: t !! time [s]
    bar_displacement = self%v0 / self%omega() * sin(self%omega() * t) * sin(self%beta() * x)
  end function bar_displacement

  !> Axial stress at reference position `x` and time `t` [Pa].
  elemental real(wp) function bar_stress(self, x, t)
    class(empm_vibrating_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: x !! reference position [m]
    real(wp), intent(in) :: t !! time [s]
    bar_stress = self%E * self%beta() * self%v0 / self%omega() * sin(self%omega() * t) * &
                 cos(self%beta() * x)
  end function bar_stress
end module empm_exact_bar
