!> Large-deformation manufactured solutions for the compressible neo-Hookean law of
!> [[empm_material_neohookean]] (docs/algorithms §3): the 1D problem of Steffen, Kirby &
!> Berzins (2008) and the 2D axis-aligned displacement of Wallstedt & Guilkey (2008). Each type
!> is its own body force (it extends [[empm_mms_t]], a body force): give it to `loads%body_force`.
!>
!> Total Lagrangian momentum balance ρ0 ü = Div P + ρ0 b, with P = J σ F⁻ᵀ the first Piola
!> stress, Div the reference divergence and b evaluated at the particle's reference position X.
!> In every problem F is diagonal, F = diag(F_x, F_y, F_z) (F_y = F_z = 1 in 1D, F_z = 1 in 2D),
!> J = F_x F_y F_z, and
!> σ = (μ/J)(F Fᵀ − I) + (λ ln J/J) I gives
!>   σ_ii = [μ(F_i² − 1) + λ ln J]/J (σ_zz = λ ln J/J when F_z = 1),
!>   P_xx = J σ_xx/F_x = μ(F_x − 1/F_x) + λ ln J/F_x   (P_yy likewise, P_xy = P_yx = 0).
!> P_xx depends on X only through F_x (and on Y only through F_y, which P_xx's X-derivative does
!> not see), so with ∂(ln J)/∂F_x = 1/F_x:
!>   ∂P_xx/∂X = [μ(1 + F_x⁻²) + λ(1 − ln J) F_x⁻²] ∂F_x/∂X.
!> Both problems have u_x = A sin(kX)·θ(t) with k = 2π/L, so ∂F_x/∂X = −k² u_x and ü_x = θ''/θ u_x
!> = −ω² u_x; hence, per component (likewise for y),
!>   b_x = u_x [ (k²/ρ0)(μ(1 + F_x⁻²) + λ(1 − ln J) F_x⁻²) − ω² ].
!> Here c = sqrt(E/ρ0) is the papers' time scale (the small-strain P-wave speed only for ν = 0).
!>
!> **1D** ([[empm_mms_neohookean_1d_t]], uniaxial strain on [0, L], u = 0 at X = 0, L/2, L):
!>   u = A sin(2πX/L) cos(cπt/L),  ω = cπ/L,  F_x = 1 + A k cos(kX) cos(ωt),  J = F_x.
!> **2D** ([[empm_mms_axis_aligned_2d_t]], plane strain on [0, L]²):
!>   u_x = A sin(2πX/L) sin(cπt/L),  u_y = A sin(2πY/L) sin(cπt/L + π),  ω = cπ/L;
!> u_x = 0 on X = 0, L and u_y = 0 on Y = 0, L, and P_xy = 0 everywhere: rollers on all four
!> sides. With A = 0.05 and L = 1, F_x, F_y ∈ [1 − 0.1π, 1 + 0.1π] ≈ [0.69, 1.31].
!> **3D** ([[empm_mms_axis_aligned_3d_t]], on [0, L]³): the same along each axis with the phases
!> 0, π and π/2, u_z = A sin(2πZ/L) sin(cπt/L + π/2); J = F_x F_y F_z, the same b_i formula
!> (ln J's X-derivative is still F_x'/F_x) and σ_zz = [μ(F_z² − 1) + λ ln J]/J; rollers on all
!> six faces.
!> The derivation is checked by finite differences of P in tests/unit/test_exact_mms.pf.
module empm_mms_neohookean
  use empm_kinds, only: wp, pi
  use empm_mms, only: empm_mms_t
  use empm_material_linear_elastic, only: empm_lame
  use empm_tensor, only: identity3
  implicit none
  private
  public :: empm_mms_neohookean_1d_t, empm_mms_axis_aligned_2d_t, empm_mms_axis_aligned_3d_t

  !> 1D neo-Hookean manufactured solution of Steffen et al. (2008).
  type, extends(empm_mms_t) :: empm_mms_neohookean_1d_t
    real(wp) :: L = 1.0_wp       !! bar length [m]
    real(wp) :: E = 1.0e4_wp     !! small-strain Young's modulus [Pa]
    real(wp) :: nu = 0.3_wp      !! small-strain Poisson's ratio
    real(wp) :: rho0 = 1.0_wp    !! reference density [kg/m³]
    real(wp) :: A = 0.05_wp      !! displacement amplitude [m]
  contains
    procedure :: displacement => n1_displacement
    procedure :: velocity => n1_velocity
    procedure :: acceleration => n1_acceleration
    procedure :: def_grad => n1_def_grad
    procedure :: stress => n1_stress
    procedure :: body_force => n1_body_force
    procedure :: fields => n1_fields
  end type empm_mms_neohookean_1d_t

  !> 2D axis-aligned neo-Hookean manufactured solution of Wallstedt & Guilkey (2008).
  type, extends(empm_mms_t) :: empm_mms_axis_aligned_2d_t
    real(wp) :: L = 1.0_wp       !! side of the square [m]
    real(wp) :: E = 1.0e4_wp     !! small-strain Young's modulus [Pa]
    real(wp) :: nu = 0.3_wp      !! small-strain Poisson's ratio
    real(wp) :: rho0 = 1.0_wp    !! reference density [kg/m³]
    real(wp) :: A = 0.05_wp      !! displacement amplitude [m]
  contains
    procedure :: displacement => n2_displacement
    procedure :: velocity => n2_velocity
    procedure :: acceleration => n2_acceleration
    procedure :: def_grad => n2_def_grad
    procedure :: stress => n2_stress
    procedure :: body_force => n2_body_force
    procedure :: fields => n2_fields
  end type empm_mms_axis_aligned_2d_t

  !> 3D axis-aligned manufactured solution (module notes), neo-Hookean, on [0, L]³.
  type, extends(empm_mms_t) :: empm_mms_axis_aligned_3d_t
    real(wp) :: L = 1.0_wp       !! side of the cube [m]
    real(wp) :: E = 1.0e4_wp     !! small-strain Young's modulus [Pa]
    real(wp) :: nu = 0.3_wp      !! small-strain Poisson's ratio
    real(wp) :: rho0 = 1.0_wp    !! reference density [kg/m³]
    real(wp) :: A = 0.05_wp      !! displacement amplitude [m]
  contains
    procedure :: fields => n3_fields
  end type empm_mms_axis_aligned_3d_t

contains

  ! ---- 1D (Steffen et al.) ------------------------------------------------------------------

  !> Displacement u = A sin(kX) cos(ωt), k = 2π/L, ω = cπ/L [m].
  pure function n1_displacement(self, X, t) result(u)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: u(1)                                    !! displacement [m]
    u(1) = self%A * sin(2.0_wp * pi * X(1) / self%L) * cos(n1_omega(self) * t)
  end function n1_displacement

  !> Velocity −Aω sin(kX) sin(ωt) [m/s].
  pure function n1_velocity(self, X, t) result(v)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: v(1)                                    !! velocity [m/s]
    real(wp) :: w
    w = n1_omega(self)
    v(1) = -self%A * w * sin(2.0_wp * pi * X(1) / self%L) * sin(w * t)
  end function n1_velocity

  !> Acceleration −ω² u [m/s²].
  pure function n1_acceleration(self, X, t) result(acc)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: acc(1)                                  !! acceleration [m/s²]
    acc = -n1_omega(self)**2 * self%displacement(X, t)
  end function n1_acceleration

  !> Deformation gradient diag(1 + A k cos(kX) cos(ωt), 1, 1).
  pure function n1_def_grad(self, X, t) result(F)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: F(3,3)                                  !! deformation gradient
    real(wp) :: k
    k = 2.0_wp * pi / self%L
    F = identity3()
    F(1,1) = 1.0_wp + self%A * k * cos(k * X(1)) * cos(n1_omega(self) * t)
  end function n1_def_grad

  !> Cauchy stress, Voigt xx, yy, zz, yz, xz, xy (module notes) [Pa].
  pure function n1_stress(self, X, t) result(s)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: s(6)                                    !! stress, Voigt [Pa]
    real(wp) :: F(3,3), lam, mu
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    s = diagonal_stress(mu, lam, F(1,1), 1.0_wp)
  end function n1_stress

  !> Body force per unit mass b = u[(k²/ρ0)(μ(1 + F⁻²) + λ(1 − ln F)F⁻²) − ω²] [m/s²].
  pure function n1_body_force(self, X, t) result(b)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(1)                        !! reference position [m]
    real(wp), intent(in) :: t                           !! time [s]
    real(wp) :: b(1)                                    !! body force per unit mass [m/s²]
    real(wp) :: F(3,3), lam, mu, u(1)
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    u = self%displacement(X, t)
    b = u * body_factor(mu, lam, self%rho0, 2.0_wp * pi / self%L, n1_omega(self), F(1,1), &
                        F(1,1))
  end function n1_body_force

  !> [[empm_mms_t]] binding: every exact field at one reference point.
  pure subroutine n1_fields(self, X, t, u, v, F, s, b)
    class(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
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
  end subroutine n1_fields

  !> ω = cπ/L with c = sqrt(E/ρ0) [rad/s].
  pure real(wp) function n1_omega(self)
    type(empm_mms_neohookean_1d_t), intent(in) :: self !! solution
    n1_omega = sqrt(self%E / self%rho0) * pi / self%L
  end function n1_omega

  ! ---- 2D axis-aligned (Wallstedt & Guilkey) -------------------------------------------------

  !> Displacement (A sin(kX) sin(ωt), A sin(kY) sin(ωt + π)) [m].
  pure function n2_displacement(self, X, t) result(u)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: u(2)                                      !! displacement [m]
    real(wp) :: k, w
    k = 2.0_wp * pi / self%L
    w = n2_omega(self)
    u(1) = self%A * sin(k * X(1)) * sin(w * t)
    u(2) = self%A * sin(k * X(2)) * sin(w * t + pi)
  end function n2_displacement

  !> Velocity [m/s].
  pure function n2_velocity(self, X, t) result(v)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: v(2)                                      !! velocity [m/s]
    real(wp) :: k, w
    k = 2.0_wp * pi / self%L
    w = n2_omega(self)
    v(1) = self%A * w * sin(k * X(1)) * cos(w * t)
    v(2) = self%A * w * sin(k * X(2)) * cos(w * t + pi)
  end function n2_velocity

  !> Acceleration −ω² u [m/s²].
  pure function n2_acceleration(self, X, t) result(acc)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: acc(2)                                    !! acceleration [m/s²]
    acc = -n2_omega(self)**2 * self%displacement(X, t)
  end function n2_acceleration

  !> Deformation gradient diag(1 + A k cos(kX) sin(ωt), 1 + A k cos(kY) sin(ωt + π), 1).
  pure function n2_def_grad(self, X, t) result(F)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: F(3,3)                                    !! deformation gradient
    real(wp) :: k, w
    k = 2.0_wp * pi / self%L
    w = n2_omega(self)
    F = identity3()
    F(1,1) = 1.0_wp + self%A * k * cos(k * X(1)) * sin(w * t)
    F(2,2) = 1.0_wp + self%A * k * cos(k * X(2)) * sin(w * t + pi)
  end function n2_def_grad

  !> Cauchy stress, Voigt xx, yy, zz, yz, xz, xy (module notes) [Pa].
  pure function n2_stress(self, X, t) result(s)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: s(6)                                      !! stress, Voigt [Pa]
    real(wp) :: F(3,3), lam, mu
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    s = diagonal_stress(mu, lam, F(1,1), F(2,2))
  end function n2_stress

  !> Body force per unit mass, b_i = u_i[(k²/ρ0)(μ(1 + F_i⁻²) + λ(1 − ln J)F_i⁻²) − ω²] [m/s²].
  pure function n2_body_force(self, X, t) result(b)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(2)                          !! reference position [m]
    real(wp), intent(in) :: t                             !! time [s]
    real(wp) :: b(2)                                      !! body force per unit mass [m/s²]
    real(wp) :: F(3,3), lam, mu, u(2), k, w, J
    call empm_lame(self%E, self%nu, lam, mu)
    F = self%def_grad(X, t)
    u = self%displacement(X, t)
    k = 2.0_wp * pi / self%L
    w = n2_omega(self)
    J = F(1,1) * F(2,2)
    b(1) = u(1) * body_factor(mu, lam, self%rho0, k, w, F(1,1), J)
    b(2) = u(2) * body_factor(mu, lam, self%rho0, k, w, F(2,2), J)
  end function n2_body_force

  !> [[empm_mms_t]] binding: every exact field at one reference point.
  pure subroutine n2_fields(self, X, t, u, v, F, s, b)
    class(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
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
  end subroutine n2_fields

  !> ω = cπ/L with c = sqrt(E/ρ0) [rad/s].
  pure real(wp) function n2_omega(self)
    type(empm_mms_axis_aligned_2d_t), intent(in) :: self !! solution
    n2_omega = sqrt(self%E / self%rho0) * pi / self%L
  end function n2_omega

  ! ---- shared -------------------------------------------------------------------------------

  !> Neo-Hookean Cauchy stress for F = diag(fx, fy, 1), Voigt (module notes) [Pa].
  pure function diagonal_stress(mu, lam, fx, fy, fz) result(s)
    real(wp), intent(in) :: mu  !! shear modulus [Pa]
    real(wp), intent(in) :: lam !! Lamé λ [Pa]
    real(wp), intent(in) :: fx  !! F_xx > 0
    real(wp), intent(in) :: fy  !! F_yy > 0
    real(wp), intent(in), optional :: fz !! F_zz > 0 (default 1)
    real(wp) :: s(6)            !! stress, Voigt [Pa]
    real(wp) :: J, lnj
    J = fx * fy
    if (present(fz)) J = J * fz
    lnj = log(J)
    s = 0.0_wp
    s(1) = (mu * (fx**2 - 1.0_wp) + lam * lnj) / J
    s(2) = (mu * (fy**2 - 1.0_wp) + lam * lnj) / J
    s(3) = lam * lnj / J
    if (present(fz)) s(3) = (mu * (fz**2 - 1.0_wp) + lam * lnj) / J
  end function diagonal_stress

  ! ---- 3D axis-aligned ----------------------------------------------------------------------

  !> [[empm_mms_t]] binding: every exact field at one reference point (module notes).
  pure subroutine n3_fields(self, X, t, u, v, F, s, b)
    class(empm_mms_axis_aligned_3d_t), intent(in) :: self !! solution
    real(wp), intent(in) :: X(:)          !! reference position (3) [m]
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(out) :: u(:)         !! displacement [m]
    real(wp), intent(out) :: v(:)         !! velocity [m/s]
    real(wp), intent(out) :: F(3,3)       !! deformation gradient
    real(wp), intent(out) :: s(6)         !! Cauchy stress, Voigt [Pa]
    real(wp), intent(out) :: b(:)         !! body force per unit mass [m/s²]
    real(wp), parameter :: phase(3) = [0.0_wp, pi, 0.5_wp * pi]
    real(wp) :: k, w, lam, mu, J
    integer :: i
    call empm_lame(self%E, self%nu, lam, mu)
    k = 2.0_wp * pi / self%L
    w = sqrt(self%E / self%rho0) * pi / self%L
    F = identity3()
    do i = 1, 3
      u(i) = self%A * sin(k * X(i)) * sin(w * t + phase(i))
      v(i) = self%A * w * sin(k * X(i)) * cos(w * t + phase(i))
      F(i,i) = 1.0_wp + self%A * k * cos(k * X(i)) * sin(w * t + phase(i))
    end do
    J = F(1,1) * F(2,2) * F(3,3)
    s = diagonal_stress(mu, lam, F(1,1), F(2,2), F(3,3))
    do i = 1, 3
      b(i) = u(i) * body_factor(mu, lam, self%rho0, k, w, F(i,i), J)
    end do
  end subroutine n3_fields

  !> b_i/u_i = (k²/ρ0)(μ(1 + f⁻²) + λ(1 − ln J) f⁻²) − ω², f = F_ii (module notes) [1/s²].
  pure real(wp) function body_factor(mu, lam, rho0, k, w, f, J)
    real(wp), intent(in) :: mu   !! shear modulus [Pa]
    real(wp), intent(in) :: lam  !! Lamé λ [Pa]
    real(wp), intent(in) :: rho0 !! reference density [kg/m³]
    real(wp), intent(in) :: k    !! wavenumber 2π/L [1/m]
    real(wp), intent(in) :: w    !! angular frequency [rad/s]
    real(wp), intent(in) :: f    !! stretch F_ii > 0
    real(wp), intent(in) :: J    !! det F > 0
    body_factor = k**2 / rho0 * (mu * (1.0_wp + 1.0_wp / f**2) &
                                 + lam * (1.0_wp - log(J)) / f**2) - w**2
  end function body_factor
end module empm_mms_neohookean
