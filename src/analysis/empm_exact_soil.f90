!> Closed-form results of element tests on soil models, for the stress-point verification
!> (docs/benchmarks.md, "Stress-point tests"). Soil conventions: compression positive,
!> p' = −tr σ/3, q = sqrt(3 J2); friction and dilatancy angles in radians.
!>
!> - Mohr–Coulomb triaxial compression and extension at constant cell pressure σr:
!>   σ1 = Nφ σ3 + 2c √Nφ, Nφ = (1 + sin φ)/(1 − sin φ).
!> - Drucker–Prager cone √J2 = α p' + k (its matches to Mohr–Coulomb) on the same paths.
!> - Plane-strain steady flow of a Drucker–Prager cone with potential √J2 − β p': the
!>   equivalent in-plane friction and dilatancy, sin φ_ps = α √(1 − β²/3)/(1 − αβ/3),
!>   sin ψ_ps = β/√(1 − β²/3), c_ps cos φ_ps = k √(1 − β²/3)/(1 − αβ/3).
!> - Simple shear of a cohesionless Mohr–Coulomb material in plane strain at the limit: the
!>   ratio τ/σ'n on the planes of zero extension, sin φ cos ψ/(1 − sin φ sin ψ) (Davis 1968).
!> - Modified Cam-Clay (yield q² = M² p'(p'c − p')): drained triaxial end point on the critical
!>   state line from the path q = 3(p' − p'0); undrained (isochoric) path
!>   p' = p'0 [(p'c0/p'0) M²/(M² + η²)]^Λ, Λ = (λ − κ)/λ, and its end point η = M.
!> - A stress rotated rigidly about z.
module empm_exact_soil
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_mc_nphi, empm_mc_triax_compression, empm_mc_triax_extension
  public :: empm_dp_match, empm_dp_triax_compression, empm_dp_triax_extension
  public :: empm_dp_plane_strain, empm_simple_shear_ratio
  public :: empm_mcc_drained_end, empm_mcc_undrained_p, empm_mcc_undrained_end
  public :: empm_mcc_yield, empm_mc_yield, empm_dp_yield, empm_soil_pq
  public :: empm_rotate_z

contains

  !> Nφ = (1 + sin φ)/(1 − sin φ).
  pure real(wp) function empm_mc_nphi(phi) result(n)
    real(wp), intent(in) :: phi !! friction angle [rad], in [0, π/2)
    n = (1.0_wp + sin(phi)) / (1.0_wp - sin(phi))
  end function empm_mc_nphi

  !> Peak deviator q = σa − σr of Mohr–Coulomb in triaxial compression (axial loading) at
  !> constant cell pressure `sr` (compression positive).
  pure real(wp) function empm_mc_triax_compression(sr, c, phi) result(q)
    real(wp), intent(in) :: sr  !! cell pressure [Pa], > 0 in compression
    real(wp), intent(in) :: c   !! cohesion [Pa]
    real(wp), intent(in) :: phi !! friction angle [rad]
    real(wp) :: n
    n = empm_mc_nphi(phi)
    q = (n - 1.0_wp) * sr + 2.0_wp * c * sqrt(n)
  end function empm_mc_triax_compression

  !> Peak deviator q = σr − σa (a magnitude) of Mohr–Coulomb in triaxial extension (axial
  !> unloading) at constant cell pressure `sr`: σr = Nφ σa + 2c√Nφ.
  pure real(wp) function empm_mc_triax_extension(sr, c, phi) result(q)
    real(wp), intent(in) :: sr  !! cell pressure [Pa]
    real(wp), intent(in) :: c   !! cohesion [Pa]
    real(wp), intent(in) :: phi !! friction angle [rad]
    real(wp) :: n
    n = empm_mc_nphi(phi)
    q = sr - (sr - 2.0_wp * c * sqrt(n)) / n
  end function empm_mc_triax_extension

  !> Drucker–Prager cone √J2 = α p' + k matched to Mohr–Coulomb (c, φ): `match` =
  !> 'compression' (outer cone, through the compression meridian), 'extension' (through the
  !> extension meridian) or 'plane_strain' (associated plane-strain limit loads agree).
  !> The same formula with ψ for φ gives the potential's β.
  pure subroutine empm_dp_match(match, c, phi, alpha, k)
    character(len=*), intent(in) :: match !! 'compression' | 'extension' | 'plane_strain'
    real(wp), intent(in) :: c             !! cohesion [Pa]
    real(wp), intent(in) :: phi           !! friction angle [rad]
    real(wp), intent(out) :: alpha        !! friction coefficient of √J2 = α p' + k
    real(wp), intent(out) :: k            !! cohesion term [Pa]
    real(wp) :: d, t
    select case (match)
    case ('compression')
      d = sqrt(3.0_wp) * (3.0_wp - sin(phi))
      alpha = 6.0_wp * sin(phi) / d; k = 6.0_wp * c * cos(phi) / d
    case ('extension')
      d = sqrt(3.0_wp) * (3.0_wp + sin(phi))
      alpha = 6.0_wp * sin(phi) / d; k = 6.0_wp * c * cos(phi) / d
    case default ! plane_strain
      t = tan(phi)
      d = sqrt(9.0_wp + 12.0_wp * t**2)
      alpha = 3.0_wp * t / d; k = 3.0_wp * c / d
    end select
  end subroutine empm_dp_match

  !> Peak q of the cone √J2 = α p' + k in triaxial compression at constant cell pressure:
  !> p' = σr + q/3, q = √3 √J2 → q = √3(α σr + k)/(1 − α/√3).
  pure real(wp) function empm_dp_triax_compression(sr, alpha, k) result(q)
    real(wp), intent(in) :: sr    !! cell pressure [Pa]
    real(wp), intent(in) :: alpha !! friction coefficient
    real(wp), intent(in) :: k     !! cohesion term [Pa]
    q = sqrt(3.0_wp) * (alpha * sr + k) / (1.0_wp - alpha / sqrt(3.0_wp))
  end function empm_dp_triax_compression

  !> Peak q (magnitude) of the cone in triaxial extension at constant cell pressure:
  !> p' = σr − q/3 → q = √3(α σr + k)/(1 + α/√3).
  pure real(wp) function empm_dp_triax_extension(sr, alpha, k) result(q)
    real(wp), intent(in) :: sr    !! cell pressure [Pa]
    real(wp), intent(in) :: alpha !! friction coefficient
    real(wp), intent(in) :: k     !! cohesion term [Pa]
    q = sqrt(3.0_wp) * (alpha * sr + k) / (1.0_wp + alpha / sqrt(3.0_wp))
  end function empm_dp_triax_extension

  !> Steady plane-strain plastic flow of the cone √J2 = α p' + k with potential √J2 − β p'
  !> (ε̇zz = 0, stationary stress so no elastic rate): s_zz = 2β√J2/3, the in-plane Mohr circle
  !> has radius t = √J2 √(1 − β²/3) and centre s = p' − β√J2/3, which gives the equivalent
  !> in-plane Mohr–Coulomb friction, dilatancy and cohesion (module notes).
  pure subroutine empm_dp_plane_strain(alpha, beta, k, sin_phi, sin_psi, c_cos_phi)
    real(wp), intent(in) :: alpha      !! friction coefficient
    real(wp), intent(in) :: beta       !! dilatancy coefficient of the potential, |β| < √3
    real(wp), intent(in) :: k          !! cohesion term [Pa]
    real(wp), intent(out) :: sin_phi   !! sin φ_ps
    real(wp), intent(out) :: sin_psi   !! sin ψ_ps
    real(wp), intent(out) :: c_cos_phi !! c_ps cos φ_ps [Pa]
    real(wp) :: r
    r = sqrt(1.0_wp - beta**2 / 3.0_wp)
    sin_phi = alpha * r / (1.0_wp - alpha * beta / 3.0_wp)
    sin_psi = beta / r
    c_cos_phi = k * r / (1.0_wp - alpha * beta / 3.0_wp)
  end subroutine empm_dp_plane_strain

  !> Limit stress ratio τ/σ'n of plane-strain simple shear (cohesionless, steady flow): on the
  !> planes containing the zero-extension direction, at θ from σ1 with
  !> tan²θ = (1 − sin ψ)/(1 + sin ψ), σn = s − t sin ψ and τ = t cos ψ with t = s sin φ.
  pure real(wp) function empm_simple_shear_ratio(sin_phi, sin_psi) result(r)
    real(wp), intent(in) :: sin_phi !! sine of the (in-plane) friction angle
    real(wp), intent(in) :: sin_psi !! sine of the (in-plane) dilatancy angle
    r = sin_phi * sqrt(max(0.0_wp, 1.0_wp - sin_psi**2)) / (1.0_wp - sin_phi * sin_psi)
  end function empm_simple_shear_ratio

  !> p' = −tr σ/3 and q = √(3 J2) of a Cauchy stress (Voigt, tension positive).
  pure subroutine empm_soil_pq(s, p, q)
    real(wp), intent(in) :: s(6)  !! stress [Pa]
    real(wp), intent(out) :: p    !! mean effective pressure [Pa]
    real(wp), intent(out) :: q    !! deviator [Pa]
    real(wp) :: m
    m = (s(1) + s(2) + s(3)) / 3.0_wp
    p = -m
    q = sqrt(1.5_wp * ((s(1) - m)**2 + (s(2) - m)**2 + (s(3) - m)**2) &
             + 3.0_wp * (s(4)**2 + s(5)**2 + s(6)**2))
  end subroutine empm_soil_pq

  !> MCC yield function q² − M² p'(p'c − p') (≤ 0 admissible).
  pure real(wp) function empm_mcc_yield(p, q, M, pc) result(f)
    real(wp), intent(in) :: p   !! p' [Pa]
    real(wp), intent(in) :: q   !! q [Pa]
    real(wp), intent(in) :: M   !! critical-state stress ratio
    real(wp), intent(in) :: pc  !! preconsolidation pressure (ellipse tip) [Pa]
    f = q**2 - M**2 * p * (pc - p)
  end function empm_mcc_yield

  !> Mohr–Coulomb yield function (σ1 − σ3) − (σ1 + σ3) sin φ − 2c cos φ with compression-positive
  !> principal stresses σ1 ≥ σ3 (≤ 0 admissible), from principal Cauchy stresses `sig` (tension
  !> positive, any order).
  pure real(wp) function empm_mc_yield(sig, c, phi) result(f)
    real(wp), intent(in) :: sig(3) !! principal Cauchy stresses [Pa]
    real(wp), intent(in) :: c      !! cohesion [Pa]
    real(wp), intent(in) :: phi    !! friction angle [rad]
    real(wp) :: s1, s3
    s1 = -minval(sig); s3 = -maxval(sig)
    f = (s1 - s3) - (s1 + s3) * sin(phi) - 2.0_wp * c * cos(phi)
  end function empm_mc_yield

  !> Drucker–Prager yield function √J2 − α p' − k (≤ 0 admissible).
  pure real(wp) function empm_dp_yield(s, alpha, k) result(f)
    real(wp), intent(in) :: s(6)  !! Cauchy stress, Voigt [Pa]
    real(wp), intent(in) :: alpha !! friction coefficient
    real(wp), intent(in) :: k     !! cohesion term [Pa]
    real(wp) :: p, q
    call empm_soil_pq(s, p, q)
    f = q / sqrt(3.0_wp) - alpha * p - k
  end function empm_dp_yield

  !> MCC drained triaxial compression from isotropic p'0 at constant cell pressure: the path
  !> q = 3(p' − p'0) meets the critical state line q = M p' at p' = 3p'0/(3 − M) (M < 3).
  pure subroutine empm_mcc_drained_end(p0, M, p, q)
    real(wp), intent(in) :: p0  !! initial isotropic p' [Pa]
    real(wp), intent(in) :: M   !! critical-state stress ratio, < 3
    real(wp), intent(out) :: p  !! p' at critical state [Pa]
    real(wp), intent(out) :: q  !! q at critical state [Pa]
    p = 3.0_wp * p0 / (3.0_wp - M)
    q = M * p
  end subroutine empm_mcc_drained_end

  !> MCC undrained (isochoric) path on the yield surface from isotropic p'0 with
  !> preconsolidation p'c0 ≥ p'0, elastic law dεv^e = κ dp'/(v p'), hardening
  !> dp'c/p'c = v dεv^p/(λ − κ), v constant: p'(η) = p'0 [(p'c0/p'0) M²/(M² + η²)]^Λ,
  !> Λ = (λ − κ)/λ (normally consolidated: p'c0 = p'0). Valid once the path has reached the
  !> yield surface (before it, p' = p'0 for a shear modulus independent of q).
  pure real(wp) function empm_mcc_undrained_p(eta, p0, pc0, M, Lambda) result(p)
    real(wp), intent(in) :: eta    !! stress ratio q/p'
    real(wp), intent(in) :: p0     !! initial p' [Pa]
    real(wp), intent(in) :: pc0    !! initial preconsolidation pressure [Pa]
    real(wp), intent(in) :: M      !! critical-state stress ratio
    real(wp), intent(in) :: Lambda !! plastic volumetric ratio (λ − κ)/λ
    p = p0 * ((pc0 / p0) * M**2 / (M**2 + eta**2))**Lambda
  end function empm_mcc_undrained_p

  !> End point (η = M) of the undrained path: p' = p'0 (p'c0/(2p'0))^Λ, q = M p'.
  pure subroutine empm_mcc_undrained_end(p0, pc0, M, Lambda, p, q)
    real(wp), intent(in) :: p0     !! initial p' [Pa]
    real(wp), intent(in) :: pc0    !! initial preconsolidation pressure [Pa]
    real(wp), intent(in) :: M      !! critical-state stress ratio
    real(wp), intent(in) :: Lambda !! (λ − κ)/λ
    real(wp), intent(out) :: p     !! p' at critical state [Pa]
    real(wp), intent(out) :: q     !! q at critical state [Pa]
    p = empm_mcc_undrained_p(M, p0, pc0, M, Lambda)
    q = M * p
  end subroutine empm_mcc_undrained_end

  !> The stress `s0` rotated rigidly by `theta` about z: R s0 Rᵀ, R = [[c, −s, 0], [s, c, 0],
  !> [0, 0, 1]] (a body spinning with ω = θ̇ about z carries its stress so).
  pure function empm_rotate_z(s0, theta) result(s)
    real(wp), intent(in) :: s0(6)  !! stress, Voigt
    real(wp), intent(in) :: theta  !! angle [rad]
    real(wp) :: s(6)               !! rotated stress
    real(wp) :: c, sn
    c = cos(theta); sn = sin(theta)
    s(1) = c**2 * s0(1) + sn**2 * s0(2) - 2.0_wp * c * sn * s0(6)
    s(2) = sn**2 * s0(1) + c**2 * s0(2) + 2.0_wp * c * sn * s0(6)
    s(3) = s0(3)
    s(6) = c * sn * (s0(1) - s0(2)) + (c**2 - sn**2) * s0(6)
    s(4) = sn * s0(5) + c * s0(4)
    s(5) = c * s0(5) - sn * s0(4)
  end function empm_rotate_z
end module empm_exact_soil
