!> Manufactured solutions for small-strain isotropic linear elasticity (docs/algorithms §3),
!> for measuring spatial and temporal rates without large-deformation effects. Each type is
!> its own body force (it extends [[empm_mms_t]], a body force): give it to `loads%body_force`.
!>
!> Small strain: ρ ü = div σ + ρ b with σ = λ tr(ε) I + 2μ ε, ε = sym ∇u, all derivatives taken
!> in the reference configuration and b evaluated at the particle's reference position X
!> (the differences to the current configuration are O(|∇u|) relative, i.e. the model error
!> of small-strain theory, kept small by a small amplitude A).
!>
!> **1D** ([[empm_mms_linear_1d_t]], uniaxial strain on [0, L], both ends fixed), k = 2π/L,
!> ω = 2π/T0, M = λ + 2μ:
!>   u = A sin(kX) sin(ωt),  σ_xx = M u_X,  σ_yy = σ_zz = λ u_X,
!>   b = ü − (M/ρ) u_XX = (M k²/ρ − ω²) u.
!> The default T0 = 2L/c (ν = 0: c = sqrt(E/ρ)) is half the frequency of the natural mode
!> with this shape (ω = πc/L against 2πc/L), so b ≠ 0 and the motion is forced.
!>
!> **2D plane strain** ([[empm_mms_linear_2d_t]], square [0, L]², all sides fixed), a = π/L,
!> s(t) = sin(ωt):
!>   u_x = A sin(aX) sin(aY) s,  u_y = A sin(2aX) sin(aY) s   (zero on the whole boundary).
!> Navier's form div σ = μ ∇²u + (λ+μ) ∇(div u), with ∇²u_x = −2a² u_x, ∇²u_y = −5a² u_y,
!> div u = A a s [cos aX sin aY + sin 2aX cos aY], gives
!>   (div σ)_x = A a² s [−(λ+3μ) sin aX sin aY + 2(λ+μ) cos 2aX cos aY],
!>   (div σ)_y = A a² s [−(λ+6μ) sin 2aX sin aY + (λ+μ) cos aX cos aY],
!>   b = −ω² u − div σ / ρ;
!> σ_xx = λ tr ε + 2μ u_x,X, σ_yy = λ tr ε + 2μ u_y,Y, σ_zz = λ tr ε, σ_xy = μ(u_x,Y + u_y,X).
!> The derivation is checked by finite differences in tests/unit/test_exact_mms.pf.
module empm_mms_linear
  use empm_kinds, only: wp, pi
  use empm_mms, only: empm_mms_t
  use empm_material_linear_elastic, only: empm_lame
  use empm_tensor, only: identity3
  implicit none
  private
  public :: empm_mms_linear_1d_t, empm_mms_linear_2d_t

  !> 1D small-strain manufactured solution u = A sin(2πX/L) sin(2πt/T0), both ends fixed.
  type, extends(empm_mms_t) :: empm_mms_linear_1d_t
    real(wp) :: L = 1.0_wp         !! bar length [m]
    real(wp) :: E = 1.0e4_wp       !! Young's modulus [Pa]
    real(wp) :: nu = 0.0_wp        !! Poisson's ratio (uniaxial strain: M = λ + 2μ)
    real(wp) :: rho = 1.0_wp       !! density [kg/m³]
    real(wp) :: A = 1.0e-4_wp      !! displacement amplitude [m]
    real(wp) :: period = 0.02_wp   !! period T0 of the motion [s]
  contains
    procedure :: modulus => l1_modulus
    procedure :: displacement => l1_displacement
    procedure :: velocity => l1_velocity
    procedure :: acceleration => l1_acceleration
    procedure :: def_grad => l1_def_grad
    procedure :: stress => l1_stress
    procedure :: body_force => l1_body_force
    procedure :: fields => l1_fields
  end type empm_mms_linear_1d_t

  !> 2D plane-strain small-strain manufactured solution on [0, L]², all sides fixed.
  type, extends(empm_mms_t) :: empm_mms_linear_2d_t
    real(wp) :: L = 1.0_wp         !! side of the square [m]
    real(wp) :: E = 1.0e4_wp       !! Young's modulus [Pa]
    real(wp) :: nu = 0.3_wp        !! Poisson's ratio
    real(wp) :: rho = 1.0_wp       !! density [kg/m³]
    real(wp) :: A = 1.0e-4_wp      !! displacement amplitude [m]
    real(wp) :: period = 0.02_wp   !! period T0 of the motion [s]
  contains
    procedure :: displacement => l2_displacement
    procedure :: velocity => l2_velocity
    procedure :: acceleration => l2_acceleration
    procedure :: def_grad => l2_def_grad
    procedure :: stress => l2_stress
    procedure :: body_force => l2_body_force
    procedure :: fields => l2_fields
  end type empm_mms_linear_2d_t

contains

  ! ---- 1D ---------------------------------------------------------------------------------

  !> Uniaxial-strain modulus M = λ + 2μ [Pa].
  pure real(wp) function l1_modulus(self)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp) :: lam, mu
    call empm_lame(self%E, self%nu, lam, mu)
    l1_modulus = lam + 2.0_wp * mu
  end function l1_modulus

  !> Displacement u(X, t) [m].
  pure function l1_displacement(self, X, t) result(u)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: u(1)                                !! displacement [m]
    u(1) = self%A * sin(2.0_wp * pi * X(1) / self%L) * sin(2.0_wp * pi * t / self%period)
  end function l1_displacement

  !> Velocity ∂u/∂t [m/s].
  pure function l1_velocity(self, X, t) result(v)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: v(1)                                !! velocity [m/s]
    real(wp) :: w
    w = 2.0_wp * pi / self%period
    v(1) = self%A * w * sin(2.0_wp * pi * X(1) / self%L) * cos(w * t)
  end function l1_velocity

  !> Acceleration ∂²u/∂t² = −ω² u [m/s²].
  pure function l1_acceleration(self, X, t) result(acc)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: acc(1)                              !! acceleration [m/s²]
    acc = -(2.0_wp * pi / self%period)**2 * self%displacement(X, t)
  end function l1_acceleration

  !> Deformation gradient F = I + ∇u (only F_xx differs from I).
  pure function l1_def_grad(self, X, t) result(F)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: F(3,3)                              !! deformation gradient
    real(wp) :: k
    k = 2.0_wp * pi / self%L
    F = identity3()
    F(1,1) = 1.0_wp + self%A * k * cos(k * X(1)) * sin(2.0_wp * pi * t / self%period)
  end function l1_def_grad

  !> Cauchy stress (small strain), Voigt xx, yy, zz, yz, xz, xy: M ε, λ ε, λ ε, 0, 0, 0 [Pa].
  pure function l1_stress(self, X, t) result(s)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: s(6)                                !! stress, Voigt [Pa]
    real(wp) :: F(3,3), lam, mu
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    s = 0.0_wp
    s(1) = (lam + 2.0_wp * mu) * (F(1,1) - 1.0_wp)
    s(2:3) = lam * (F(1,1) - 1.0_wp)
  end function l1_stress

  !> Body force per unit mass b = (M k²/ρ − ω²) u [m/s²].
  pure function l1_body_force(self, X, t) result(b)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: b(1)                                !! body force per unit mass [m/s²]
    b = (self%modulus() * (2.0_wp * pi / self%L)**2 / self%rho &
         - (2.0_wp * pi / self%period)**2) * self%displacement(X, t)
  end function l1_body_force

  !> [[empm_mms_t]] binding: every exact field at one reference point.
  pure subroutine l1_fields(self, X, t, u, v, F, s, b)
    class(empm_mms_linear_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(:)          !! reference position (1) [m]
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(out) :: u(:)         !! displacement [m]
    real(wp), intent(out) :: v(:)         !! velocity [m/s]
    real(wp), intent(out) :: F(3,3)       !! deformation gradient
    real(wp), intent(out) :: s(6)         !! Cauchy stress, Voigt [Pa]
    real(wp), intent(out) :: b(:)         !! body force per unit mass [m/s²]
    u = self%displacement(X(1:1), t); v = self%velocity(X(1:1), t)
    F = self%def_grad(X(1:1), t); s = self%stress(X(1:1), t)
    b = self%body_force(X(1:1), t)
  end subroutine l1_fields

  ! ---- 2D plane strain ------------------------------------------------------------------------

  !> Displacement (u_x, u_y) [m].
  pure function l2_displacement(self, X, t) result(u)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: u(2)                                !! displacement [m]
    u = self%A * shape2(self, X) * sin(2.0_wp * pi * t / self%period)
  end function l2_displacement

  !> Velocity [m/s].
  pure function l2_velocity(self, X, t) result(v)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: v(2)                                !! velocity [m/s]
    real(wp) :: w
    w = 2.0_wp * pi / self%period
    v = self%A * w * shape2(self, X) * cos(w * t)
  end function l2_velocity

  !> Acceleration −ω² u [m/s²].
  pure function l2_acceleration(self, X, t) result(acc)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: acc(2)                              !! acceleration [m/s²]
    acc = -(2.0_wp * pi / self%period)**2 * self%displacement(X, t)
  end function l2_acceleration

  !> Deformation gradient F = I + ∇u (in-plane block; F_zz = 1).
  pure function l2_def_grad(self, X, t) result(F)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: F(3,3)                              !! deformation gradient
    real(wp) :: a, s, cx, sx, cy, sy, c2x, s2x
    a = pi / self%L
    s = self%A * a * sin(2.0_wp * pi * t / self%period)
    cx = cos(a * X(1)); sx = sin(a * X(1)); c2x = cos(2.0_wp * a * X(1))
    s2x = sin(2.0_wp * a * X(1)); cy = cos(a * X(2)); sy = sin(a * X(2))
    F = identity3()
    F(1,1) = F(1,1) + s * cx * sy
    F(1,2) = s * sx * cy
    F(2,1) = s * 2.0_wp * c2x * sy
    F(2,2) = F(2,2) + s * s2x * cy
  end function l2_def_grad

  !> Cauchy stress (small strain, plane strain), Voigt xx, yy, zz, yz, xz, xy [Pa].
  pure function l2_stress(self, X, t) result(sv)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: sv(6)                               !! stress, Voigt [Pa]
    real(wp) :: F(3,3), lam, mu, tr
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    tr = F(1,1) + F(2,2) - 2.0_wp
    sv = 0.0_wp
    sv(1) = lam * tr + 2.0_wp * mu * (F(1,1) - 1.0_wp)
    sv(2) = lam * tr + 2.0_wp * mu * (F(2,2) - 1.0_wp)
    sv(3) = lam * tr
    sv(6) = mu * (F(1,2) + F(2,1))
  end function l2_stress

  !> Body force per unit mass b = −ω² u − div σ/ρ (closed form, module notes) [m/s²].
  pure function l2_body_force(self, X, t) result(b)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                    !! reference position [m]
    real(wp), intent(in) :: t                       !! time [s]
    real(wp) :: b(2)                                !! body force per unit mass [m/s²]
    real(wp) :: lam, mu, a, s, divs(2), ax, ay
    call empm_lame(self%E, self%nu, lam, mu)
    a = pi / self%L
    ax = a * X(1); ay = a * X(2)
    s = self%A * a**2 * sin(2.0_wp * pi * t / self%period)
    divs(1) = s * (-(lam + 3.0_wp * mu) * sin(ax) * sin(ay) &
                   + 2.0_wp * (lam + mu) * cos(2.0_wp * ax) * cos(ay))
    divs(2) = s * (-(lam + 6.0_wp * mu) * sin(2.0_wp * ax) * sin(ay) &
                   + (lam + mu) * cos(ax) * cos(ay))
    b = self%acceleration(X, t) - divs / self%rho
  end function l2_body_force

  !> [[empm_mms_t]] binding: every exact field at one reference point.
  pure subroutine l2_fields(self, X, t, u, v, F, s, b)
    class(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(:)          !! reference position (2) [m]
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(out) :: u(:)         !! displacement [m]
    real(wp), intent(out) :: v(:)         !! velocity [m/s]
    real(wp), intent(out) :: F(3,3)       !! deformation gradient
    real(wp), intent(out) :: s(6)         !! Cauchy stress, Voigt [Pa]
    real(wp), intent(out) :: b(:)         !! body force per unit mass [m/s²]
    u = self%displacement(X(1:2), t); v = self%velocity(X(1:2), t)
    F = self%def_grad(X(1:2), t); s = self%stress(X(1:2), t)
    b = self%body_force(X(1:2), t)
  end subroutine l2_fields

  !> Spatial shapes (sin aX sin aY, sin 2aX sin aY), a = π/L.
  pure function shape2(self, X) result(f)
    type(empm_mms_linear_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                   !! reference position [m]
    real(wp) :: f(2)                               !! shape values
    real(wp) :: a
    a = pi / self%L
    f(1) = sin(a * X(1)) * sin(a * X(2))
    f(2) = sin(2.0_wp * a * X(1)) * sin(a * X(2))
  end function shape2
end module empm_mms_linear
