!> Kernels shared by the rate-form (hypoelastic and elastoplastic) material models: the strain
!> increment, the volume ratio and the Jaumann rotation of a step, the isotropic elastic
!> increment, stress invariants, and the spectral decomposition of a symmetric stress.
!>
!> The step's kinematics come in two forms ([[empm_material_ctx_t]]'s `midpoint`): with the
!> Euler form the increment of F is I + ΔtL; with the midpoint form (the trapezoidal drift of
!> `pc_newmark` and `gen_alpha`) L is the gradient on the step's midpoint configuration,
!> G = ΔtL = (ΔF − I)(½(I + ΔF))⁻¹, so ΔF = (I − ½G)⁻¹(I + ½G) (Hughes and Winget 1980): a
!> rigid rotation has sym G = 0 exactly and the Cayley rotation of skw G is that rotation.
!> In either form a model rotates its stress with the step's spin and adds the increment of
!> [[corotated_increment]] (Δε turned by half the rotation): the Jaumann rate is then
!> integrated to second order whatever the motion, the order the scheme's kinematics allow.
!>
!> Conventions (those of empm): Voigt order (xx, yy, zz, yz, xz, xy) with tensor shears;
!> tension positive. Soil models that think in compression-positive effective pressure convert
!> at their boundary (p' = −tr σ/3), not here. All procedures are pure.
module empm_plasticity
  use empm_kinds, only: wp
  use empm_tensor, only: adjugate3
  implicit none
  private
  public :: strain_increment, jaumann_rotate, jaumann_rotate_block, elastic_increment, &
            mean_deviator, volume_ratio, midpoint_increment, corotated_increment
  public :: principal_decompose, principal_compose

contains

  !> Strain increment Δε = Δt·sym(L), Voigt with tensor shears.
  pure function strain_increment(dt, L) result(de)
    real(wp), intent(in) :: dt      !! time step [s]
    real(wp), intent(in) :: L(3,3)  !! velocity gradient [1/s]
    real(wp) :: de(6)               !! strain increment
    de(1) = dt * L(1,1)
    de(2) = dt * L(2,2)
    de(3) = dt * L(3,3)
    de(4) = 0.5_wp * dt * (L(2,3) + L(3,2))
    de(5) = 0.5_wp * dt * (L(1,3) + L(3,1))
    de(6) = 0.5_wp * dt * (L(1,2) + L(2,1))
  end function strain_increment

  !> Volume ratio J = V¹/V⁰ of a step: 1 + Δt tr L (Euler form, summed as
  !> [[strain_increment]]'s diagonal) or det(I + ½ΔtL)/det(I − ½ΔtL) = det ΔF (midpoint form,
  !> see the module notes; second order where 1 + Δt tr L is first). J ≤ 0 flags a step that
  !> inverts the particle (−1 when a midpoint determinant is not positive).
  pure real(wp) function volume_ratio(dt, L, midpoint) result(j)
    real(wp), intent(in) :: dt       !! time step [s]
    real(wp), intent(in) :: L(3,3)   !! velocity gradient [1/s]
    logical, intent(in) :: midpoint  !! L is the midpoint gradient
    real(wp) :: a, b
    if (.not. midpoint) then
      j = 1.0_wp + (dt * L(1,1) + dt * L(2,2) + dt * L(3,3))
      return
    end if
    a = det_shift(0.5_wp * dt, L)
    b = det_shift(-0.5_wp * dt, L)
    j = -1.0_wp
    if (a > 0.0_wp .and. b > 0.0_wp) j = a / b
  end function volume_ratio

  !> Increment of the deformation gradient of a midpoint-form step,
  !> ΔF = (I − ½ΔtL)⁻¹(I + ½ΔtL) (module notes); the identity when I − ½ΔtL is singular
  !> ([[volume_ratio]] rejects such a step).
  pure function midpoint_increment(dt, L) result(dF)
    real(wp), intent(in) :: dt       !! time step [s]
    real(wp), intent(in) :: L(3,3)   !! midpoint velocity gradient [1/s]
    real(wp) :: dF(3,3)              !! F¹ = ΔF F⁰
    real(wp) :: M(3,3), C(3,3), P(3,3), d
    integer :: i
    M = -0.5_wp * dt * L; P = 0.5_wp * dt * L
    do i = 1, 3
      M(i,i) = M(i,i) + 1.0_wp; P(i,i) = P(i,i) + 1.0_wp
    end do
    C = adjugate3(M) ! det(M) M⁻¹
    d = M(1,1) * C(1,1) + M(1,2) * C(2,1) + M(1,3) * C(3,1)
    if (.not. (abs(d) > 0.0_wp)) then
      dF = 0.0_wp
      do i = 1, 3
        dF(i,i) = 1.0_wp
      end do
      return
    end if
    dF = matmul(C, P) / d
  end function midpoint_increment

  ! det(I + c L).
  pure real(wp) function det_shift(c, L) result(d)
    real(wp), intent(in) :: c, L(3,3)
    real(wp) :: a11, a22, a33
    a11 = 1.0_wp + c * L(1,1); a22 = 1.0_wp + c * L(2,2); a33 = 1.0_wp + c * L(3,3)
    d = a11 * (a22 * a33 - c * L(2,3) * c * L(3,2)) &
        - c * L(1,2) * (c * L(2,1) * a33 - c * L(2,3) * c * L(3,1)) &
        + c * L(1,3) * (c * L(2,1) * c * L(3,2) - a22 * c * L(3,1))
  end function det_shift

  !> Jaumann rotation of a step: σ ← Q σ Qᵀ with Q the Cayley transform of the step's spin,
  !> Q = (I − ½ΔtW)⁻¹(I + ½ΔtW), W = skew(L) (Hughes and Winget 1980). Q is exactly orthogonal,
  !> so the rotation keeps the stress invariants to round-off: the explicit form
  !> σ + Δt(Wσ − σW) grows |σ| by (1 + 4ω²Δt²)^½ per step and pumped energy into spinning
  !> bodies (colliding disks, +675 % with gen_alpha_grid). Applied to the stress at the start of
  !> the step, before the constitutive increment; the rotation is second-order accurate in Δt.
  pure subroutine jaumann_rotate(dt, L, s)
    real(wp), intent(in) :: dt       !! time step [s]
    real(wp), intent(in) :: L(3,3)   !! velocity gradient [1/s]
    real(wp), intent(inout) :: s(6)  !! Cauchy stress, Voigt [Pa]
    real(wp) :: a(3)
    ! Axial vector of A = ½ΔtW: A x = a × x.
    a(1) = 0.25_wp * dt * (L(3,2) - L(2,3))
    a(2) = 0.25_wp * dt * (L(1,3) - L(3,1))
    a(3) = 0.25_wp * dt * (L(2,1) - L(1,2))
    if (a(1) == 0.0_wp .and. a(2) == 0.0_wp) then
      call rotate_about_z(a(3), s)
    else
      call rotate_general(a, s)
    end if
  end subroutine jaumann_rotate

  !> [[jaumann_rotate]] for a general spin, a the axial vector of ½ΔtW.
  pure subroutine rotate_general(a, s)
    real(wp), intent(in) :: a(3)     !! axial vector of ½ΔtW
    real(wp), intent(inout) :: s(6)  !! Cauchy stress, Voigt [Pa]
    real(wp) :: c, Q(3,3), S3(3,3), T(3,3), M(3,3)
    integer :: i, j
    ! Q = I + 2/(1 + a·a) (A + A²), with A² = a aᵀ − (a·a) I.
    c = 2.0_wp / (1.0_wp + a(1)**2 + a(2)**2 + a(3)**2)
    do j = 1, 3
      do i = 1, 3
        Q(i,j) = c * a(i) * a(j)
      end do
    end do
    Q(1,1) = Q(1,1) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(2,2) = Q(2,2) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(3,3) = Q(3,3) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(1,2) = Q(1,2) - c * a(3); Q(2,1) = Q(2,1) + c * a(3)
    Q(1,3) = Q(1,3) + c * a(2); Q(3,1) = Q(3,1) - c * a(2)
    Q(2,3) = Q(2,3) - c * a(1); Q(3,2) = Q(3,2) + c * a(1)
    S3(1,1) = s(1); S3(2,2) = s(2); S3(3,3) = s(3)
    S3(2,3) = s(4); S3(3,2) = s(4)
    S3(1,3) = s(5); S3(3,1) = s(5)
    S3(1,2) = s(6); S3(2,1) = s(6)
    ! T = Q S3 Qᵀ written out (M = S3 Qᵀ, then Q M), each sum in matmul's order: the inline
    ! matmuls with their temporaries took twice the instructions.
    do j = 1, 3
      do i = 1, 3
        M(i,j) = S3(i,1) * Q(j,1) + S3(i,2) * Q(j,2) + S3(i,3) * Q(j,3)
      end do
    end do
    do j = 1, 3
      do i = 1, 3
        T(i,j) = Q(i,1) * M(1,j) + Q(i,2) * M(2,j) + Q(i,3) * M(3,j)
      end do
    end do
    s(1) = T(1,1); s(2) = T(2,2); s(3) = T(3,3)
    s(4) = 0.5_wp * (T(2,3) + T(3,2))
    s(5) = 0.5_wp * (T(1,3) + T(3,1))
    s(6) = 0.5_wp * (T(1,2) + T(2,1))
  end subroutine rotate_general

  !> [[jaumann_rotate]] for a spin about z alone (every 2D step), a3 = ¼Δt(L21 − L12): Q is
  !> the in-plane rotation cos = 1 − c a3², sin = c a3, c = 2/(1 + a3²) (the general Q,
  !> written out: a quarter of the 3×3 products).
  pure subroutine rotate_about_z(a3, s)
    real(wp), intent(in) :: a3       !! axial vector's z component of ½ΔtW
    real(wp), intent(inout) :: s(6)  !! Cauchy stress, Voigt [Pa]
    real(wp) :: c, ct, st, t11, t22, t12, t13
    if (a3 == 0.0_wp) return
    c = 2.0_wp / (1.0_wp + a3**2)
    ct = 1.0_wp - c * a3**2; st = c * a3
    t11 = ct * ct * s(1) - 2.0_wp * ct * st * s(6) + st * st * s(2)
    t22 = st * st * s(1) + 2.0_wp * ct * st * s(6) + ct * ct * s(2)
    t12 = ct * st * (s(1) - s(2)) + (ct * ct - st * st) * s(6)
    t13 = ct * s(5) - st * s(4)
    s(4) = st * s(5) + ct * s(4)
    s(1) = t11; s(2) = t22; s(5) = t13; s(6) = t12
  end subroutine rotate_about_z

  !> [[jaumann_rotate]] of the stresses s(:, p) of particles 1..n with the velocity gradients
  !> L(:, :, p), skipping those whose step would invert them, [[volume_ratio]] ≤ 0 (the models
  !> update no stress there). For a model that rotates before its increment: one call per
  !> block instead of one per particle (the rotation, split into its two cases, is inlined
  !> into this loop).
  pure subroutine jaumann_rotate_block(dt, n, L, s, midpoint)
    real(wp), intent(in) :: dt           !! time step [s]
    integer, intent(in) :: n             !! number of particles
    real(wp), intent(in) :: L(3, 3, n)   !! velocity gradients [1/s]
    real(wp), intent(inout) :: s(6, n)   !! Cauchy stresses, Voigt [Pa]
    logical, intent(in) :: midpoint      !! the L are midpoint gradients (module notes)
    integer :: p
    do p = 1, n
      if (volume_ratio(dt, L(:,:,p), midpoint) <= 0.0_wp) cycle
      call jaumann_rotate(dt, L(:,:,p), s(:,p))
    end do
  end subroutine jaumann_rotate_block

  !> The step's strain increment turned by half the step's rotation, Q½ Δε Q½ᵀ with
  !> Δε = Δt sym L ([[strain_increment]]) and Q½ the Cayley rotation of ½Δt skw L (that of
  !> [[jaumann_rotate]] over Δt/2). A rate-form model that rotates its stress by Q and adds
  !> the increment of this one integrates the Jaumann rate to second order under any motion:
  !> the exact step, Qσ⁰Qᵀ + ∫ Q(τ) C:D Q(τ)ᵀ dτ, is the midpoint rule's Q½ (C:Δε) Q½ᵀ to
  !> O(Δt³) for an isotropic C, while Δε unturned loses ½Δt²[W, C:D] each step (first order
  !> wherever strain and spin meet: simple shear). Without spin it is Δε, bitwise.
  pure function corotated_increment(dt, L) result(de)
    real(wp), intent(in) :: dt       !! time step [s]
    real(wp), intent(in) :: L(3,3)   !! velocity gradient [1/s]
    real(wp) :: de(6)                !! strain increment, Voigt with tensor shears
    de = strain_increment(dt, L)
    call jaumann_rotate(0.5_wp * dt, L, de)
  end function corotated_increment

  !> Isotropic elastic stress increment K tr(Δε) I + 2G dev(Δε).
  pure function elastic_increment(K, G, de) result(ds)
    real(wp), intent(in) :: K      !! bulk modulus [Pa]
    real(wp), intent(in) :: G      !! shear modulus [Pa]
    real(wp), intent(in) :: de(6)  !! strain increment, tensor shears
    real(wp) :: ds(6)              !! stress increment [Pa]
    real(wp) :: tr
    tr = de(1) + de(2) + de(3)
    ds(1:3) = (K - 2.0_wp * G / 3.0_wp) * tr + 2.0_wp * G * de(1:3)
    ds(4:6) = 2.0_wp * G * de(4:6)
  end function elastic_increment

  !> Mean stress m = tr σ/3 (tension positive), the deviator s = σ − m I and
  !> q = sqrt(3/2 s:s) (the von Mises equivalent stress).
  pure subroutine mean_deviator(sig, m, dev, q)
    real(wp), intent(in) :: sig(6)   !! stress, Voigt
    real(wp), intent(out) :: m       !! mean stress tr σ/3
    real(wp), intent(out) :: dev(6)  !! deviator, Voigt
    real(wp), intent(out) :: q       !! sqrt(3 J2)
    m = (sig(1) + sig(2) + sig(3)) / 3.0_wp
    dev(1:3) = sig(1:3) - m
    dev(4:6) = sig(4:6)
    q = sqrt(1.5_wp * (dev(1)**2 + dev(2)**2 + dev(3)**2) &
             + 3.0_wp * (dev(4)**2 + dev(5)**2 + dev(6)**2))
  end subroutine mean_deviator

  !> Principal values σ1 ≥ σ2 ≥ σ3 and unit principal directions (columns of Q) of a
  !> symmetric stress: σ = Σ σ_i q_i q_iᵀ. With yz = xz = 0 (1D and plane strain) zz is a
  !> principal direction and the in-plane pair is found in closed form; otherwise cyclic Jacobi
  !> rotations, converged to round-off.
  pure subroutine principal_decompose(s, sig, Q)
    real(wp), intent(in) :: s(6)      !! symmetric tensor, Voigt
    real(wp), intent(out) :: sig(3)   !! principal values, decreasing
    real(wp), intent(out) :: Q(3,3)   !! principal directions, column i for sig(i)
    real(wp) :: A(3,3), c, r, d, ct, st, v(3)
    integer :: i, j
    if (s(4) == 0.0_wp .and. s(5) == 0.0_wp) then
      ! In-plane pair: c ± r with r = |(d, xy)|, d = (xx − yy)/2; the major direction at the
      ! angle θ with cos 2θ = d/r, sin 2θ = xy/r, from the half-angle formulas (no trigonometric
      ! calls: this runs for every particle of a 2D plasticity model). The branch on the sign
      ! of d keeps the square root away from cancellation.
      c = 0.5_wp * (s(1) + s(2))
      d = 0.5_wp * (s(1) - s(2))
      r = hypot(d, s(6))
      if (r == 0.0_wp) then
        ct = 1.0_wp; st = 0.0_wp
      else if (d >= 0.0_wp) then
        ct = sqrt(0.5_wp * (1.0_wp + d / r))
        st = s(6) / (2.0_wp * r * ct)
      else
        st = sign(sqrt(0.5_wp * (1.0_wp - d / r)), s(6))
        ct = s(6) / (2.0_wp * r * st)
      end if
      sig = [c + r, c - r, s(3)]
      Q = 0.0_wp
      Q(1,1) = ct; Q(2,1) = st
      Q(1,2) = -st; Q(2,2) = ct
      Q(3,3) = 1.0_wp
    else
      A(1,1) = s(1); A(2,2) = s(2); A(3,3) = s(3)
      A(2,3) = s(4); A(3,2) = s(4)
      A(1,3) = s(5); A(3,1) = s(5)
      A(1,2) = s(6); A(2,1) = s(6)
      call jacobi3(A, Q)
      sig = [A(1,1), A(2,2), A(3,3)]
    end if
    ! Insertion sort of three, carrying the directions.
    do i = 2, 3
      c = sig(i); v = Q(:, i)
      j = i - 1
      do while (j >= 1)
        if (sig(j) >= c) exit
        sig(j + 1) = sig(j); Q(:, j + 1) = Q(:, j)
        j = j - 1
      end do
      sig(j + 1) = c; Q(:, j + 1) = v
    end do
  end subroutine principal_decompose

  !> σ = Σ σ_i q_i q_iᵀ in Voigt form (the inverse of [[principal_decompose]]).
  pure function principal_compose(sig, Q) result(s)
    real(wp), intent(in) :: sig(3)  !! principal values
    real(wp), intent(in) :: Q(3,3)  !! principal directions (columns)
    real(wp) :: s(6)                !! tensor, Voigt
    integer :: i
    s = 0.0_wp
    do i = 1, 3
      s(1) = s(1) + sig(i) * Q(1,i) * Q(1,i)
      s(2) = s(2) + sig(i) * Q(2,i) * Q(2,i)
      s(3) = s(3) + sig(i) * Q(3,i) * Q(3,i)
      s(4) = s(4) + sig(i) * Q(2,i) * Q(3,i)
      s(5) = s(5) + sig(i) * Q(1,i) * Q(3,i)
      s(6) = s(6) + sig(i) * Q(1,i) * Q(2,i)
    end do
  end function principal_compose

  !> Cyclic Jacobi diagonalisation of a symmetric 3×3 matrix: on return A is diagonal (to
  !> round-off) and V holds the eigenvectors as columns.
  pure subroutine jacobi3(A, V)
    real(wp), intent(inout) :: A(3,3) !! symmetric matrix, diagonalised in place
    real(wp), intent(out) :: V(3,3)   !! eigenvectors (columns)
    real(wp) :: off, scale, theta, t, c, s, tau, apq, app, aqq, g, h
    integer :: sweep, p, q, k, i
    integer, parameter :: pp(3) = [1, 1, 2], qq(3) = [2, 3, 3]
    V = 0.0_wp
    V(1,1) = 1.0_wp; V(2,2) = 1.0_wp; V(3,3) = 1.0_wp
    scale = abs(A(1,1)) + abs(A(2,2)) + abs(A(3,3)) + abs(A(1,2)) + abs(A(1,3)) + abs(A(2,3))
    if (scale == 0.0_wp) return
    do sweep = 1, 50
      off = abs(A(1,2)) + abs(A(1,3)) + abs(A(2,3))
      if (off <= epsilon(1.0_wp) * 1.0e-3_wp * scale) exit
      do k = 1, 3
        p = pp(k); q = qq(k)
        apq = A(p,q)
        if (apq == 0.0_wp) cycle
        app = A(p,p); aqq = A(q,q)
        ! t = tan of the rotation angle, the smaller root. For |θ| > 1e150 (θ² would overflow,
        ! and for a denormal apq already the division) t = 1/(2θ) = apq/(aqq − app).
        if (abs(apq) < 0.5e-150_wp * abs(aqq - app)) then
          t = apq / (aqq - app)
        else
          theta = (aqq - app) / (2.0_wp * apq)
          t = sign(1.0_wp, theta) / (abs(theta) + sqrt(theta**2 + 1.0_wp))
        end if
        c = 1.0_wp / sqrt(t**2 + 1.0_wp)
        s = t * c
        tau = s / (1.0_wp + c)
        A(p,p) = app - t * apq
        A(q,q) = aqq + t * apq
        A(p,q) = 0.0_wp; A(q,p) = 0.0_wp
        ! The remaining index r ≠ p, q.
        associate (r => 6 - p - q)
          g = A(r,p); h = A(r,q)
          A(r,p) = g - s * (h + g * tau); A(p,r) = A(r,p)
          A(r,q) = h + s * (g - h * tau); A(q,r) = A(r,q)
        end associate
        do i = 1, 3
          g = V(i,p); h = V(i,q)
          V(i,p) = g - s * (h + g * tau)
          V(i,q) = h + s * (g - h * tau)
        end do
      end do
    end do
  end subroutine jacobi3
end module empm_plasticity
