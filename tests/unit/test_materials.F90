! Unit tests for the material models and the material factory.
!
! Tolerances:
! - RTOL = 1e-14: closed forms evaluated in a different order than the model does. Each result
!   is a handful of rounded operations (≤ ~10 × 1.1e-16 relative), so 1e-14 is round-off level
!   with margin; structurally zero components are compared with tolerance 0.
! - Objectivity: entries of R σ Rᵀ are sums of ~27 products of O(1) numbers, ~30 ulp → 1e-13.
! - Finite differences (h = 1e-5, central): truncation h²/6·|ψ'''| ~ 1e-10 and round-off
!   ε|ψ|/h ~ 1e-11 for O(1) moduli and F (observed ≤ 1e-10), so 1e-8 is safe yet far below
!   the O(1) error of a wrong stress formula.
! - Small-strain limit: neo-Hookean vs linear elastic differ by O(ε) relatively; ε ≤ 1e-6
!   (observed 5e-7), tolerance 1e-5.
module test_materials
  use funit
  use empm_kinds, only: wp
  use empm_material, only: empm_material_t
  use empm_material_linear_elastic, only: empm_linear_elastic_t
  use empm_material_neohookean, only: empm_neohookean_t, empm_neohookean_cauchy, &
                                      empm_neohookean_energy
  use empm_material_factory, only: empm_material_create, empm_material_names, &
                                   material_status_text, MAT_OK, MAT_UNKNOWN_NAME, MAT_BAD_E, &
                                   MAT_BAD_NU, MAT_BAD_RHO0, MAT_NAME_LEN
  use empm_tensor, only: identity3, det3, voigt_to_mat, mat_to_voigt
  implicit none

  real(wp), parameter :: RTOL = 1.0e-14_wp  !! round-off level, see the header
  ! Steel as in the Dyka bar, with ν = 0.3 so that λ ≠ 0.
  real(wp), parameter :: E_ST = 200.0e9_wp, NU_ST = 0.3_wp, RHO_ST = 7833.0_wp
  real(wp), parameter :: LAM_ST = E_ST * NU_ST / ((1.0_wp + NU_ST) * (1.0_wp - 2.0_wp * NU_ST))
  real(wp), parameter :: MU_ST = E_ST / (2.0_wp * (1.0_wp + NU_ST))

contains

  ! ---- helpers ---------------------------------------------------------------------------------

  ! Linear-elastic material with the given constants (asserting success is the caller's job).
  function make_le(E, nu, rho0) result(mat)
    real(wp), intent(in) :: E, nu, rho0
    type(empm_linear_elastic_t) :: mat
    integer :: info
    call mat%init(E, nu, rho0, info)
  end function make_le

  function make_nh(E, nu, rho0) result(mat)
    real(wp), intent(in) :: E, nu, rho0
    type(empm_neohookean_t) :: mat
    integer :: info
    call mat%init(E, nu, rho0, info)
  end function make_nh

  ! One step of one particle through the polymorphic interface, starting from the given state.
  subroutine step1(mat, dt, L, F, strain, stress, rho, info)
    class(empm_material_t), intent(in) :: mat
    real(wp), intent(in) :: dt, L(3,3)
    real(wp), intent(inout) :: F(3,3), strain(6), stress(6), rho
    integer, intent(out) :: info
    real(wp) :: Lb(3,3,1), Fb(3,3,1), eb(6,1), sb(6,1), rb(1)
    Lb(:,:,1) = L; Fb(:,:,1) = F; eb(:,1) = strain; sb(:,1) = stress; rb(1) = rho
    call mat%update(dt, Lb, Fb, eb, sb, rb, info)
    F = Fb(:,:,1); strain = eb(:,1); stress = sb(:,1); rho = rb(1)
  end subroutine step1

  ! Fresh state: F = I, zero strain and stress.
  subroutine rest(F, strain, stress)
    real(wp), intent(out) :: F(3,3), strain(6), stress(6)
    F = identity3(); strain = 0.0_wp; stress = 0.0_wp
  end subroutine rest

  ! Rotation by `angle` about the unit vector along `axis` (Rodrigues' formula).
  pure function rotation(axis, angle) result(R)
    real(wp), intent(in) :: axis(3), angle
    real(wp) :: R(3,3), n(3), K(3,3)
    n = axis / sqrt(sum(axis**2))
    K = reshape([0.0_wp, n(3), -n(2), -n(3), 0.0_wp, n(1), n(2), -n(1), 0.0_wp], [3, 3])
    R = identity3() + sin(angle) * K + (1.0_wp - cos(angle)) * matmul(K, K)
  end function rotation

  ! A general deformation gradient with det > 0 (neither symmetric nor near I).
  pure function general_F() result(F)
    real(wp) :: F(3,3)
    F = reshape([1.2_wp, 0.1_wp, -0.2_wp, 0.3_wp, 0.9_wp, 0.15_wp, 0.05_wp, -0.25_wp, 1.1_wp], &
                [3, 3])
  end function general_F

  ! ---- linear elastic --------------------------------------------------------------------------

  !@test
  subroutine test_le_uniaxial_strain()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), eps
    integer :: info
    mat = make_le(E_ST, NU_ST, RHO_ST)
    call rest(F, e, s); rho = RHO_ST
    L = 0.0_wp; L(1,1) = 2.0e2_wp
    call step1(mat, 5.0e-7_wp, L, F, e, s, rho, info)
#line 96 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 96) )
  if (anyExceptions()) return
#line 97 "/work/main/tests/unit/test_materials.pf"
    eps = 5.0e-7_wp * 2.0e2_wp
#line 98 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(eps, e(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 98) )
  if (anyExceptions()) return
#line 99 "/work/main/tests/unit/test_materials.pf"
#line 99 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual((LAM_ST + 2.0_wp * MU_ST) * eps, s(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 99) )
  if (anyExceptions()) return
#line 100 "/work/main/tests/unit/test_materials.pf"
#line 100 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * eps, s(2), tolerance=RTOL, message='lateral yy = lambda eps', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 100) )
  if (anyExceptions()) return
#line 101 "/work/main/tests/unit/test_materials.pf"
#line 101 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * eps, s(3), tolerance=RTOL, message='lateral zz = lambda eps', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 101) )
  if (anyExceptions()) return
#line 102 "/work/main/tests/unit/test_materials.pf"
#line 102 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(4), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 102) )
  if (anyExceptions()) return
#line 103 "/work/main/tests/unit/test_materials.pf"
#line 103 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(5), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 103) )
  if (anyExceptions()) return
#line 104 "/work/main/tests/unit/test_materials.pf"
#line 104 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(6), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 104) )
  if (anyExceptions()) return
#line 105 "/work/main/tests/unit/test_materials.pf"
#line 105 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(1.0_wp + eps, F(1,1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 105) )
  if (anyExceptions()) return
#line 106 "/work/main/tests/unit/test_materials.pf"
#line 106 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(1.0_wp, F(2,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 106) )
  if (anyExceptions()) return
#line 107 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_uniaxial_strain

  !@test
  subroutine test_le_uniaxial_strain_nu0_is_E_eps()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), eps
    integer :: info
    mat = make_le(E_ST, 0.0_wp, RHO_ST)
    call rest(F, e, s); rho = RHO_ST
    L = 0.0_wp; L(1,1) = -3.0e2_wp
    call step1(mat, 1.0e-6_wp, L, F, e, s, rho, info)
#line 118 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 118) )
  if (anyExceptions()) return
#line 119 "/work/main/tests/unit/test_materials.pf"
    eps = 1.0e-6_wp * (-3.0e2_wp)
#line 120 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(E_ST * eps, s(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 120) )
  if (anyExceptions()) return
#line 121 "/work/main/tests/unit/test_materials.pf"
    ! λ = 0 exactly for ν = 0: no lateral stress at all.
#line 122 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 122) )
  if (anyExceptions()) return
#line 123 "/work/main/tests/unit/test_materials.pf"
#line 123 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 123) )
  if (anyExceptions()) return
#line 124 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_uniaxial_strain_nu0_is_E_eps

  !@test
  subroutine test_le_plane_strain()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), dt, exx, eyy, exy
    integer :: info
    mat = make_le(E_ST, NU_ST, RHO_ST)
    call rest(F, e, s); rho = RHO_ST
    dt = 1.0e-6_wp
    L = 0.0_wp
    L(1,1) = 150.0_wp; L(2,2) = -40.0_wp; L(1,2) = 70.0_wp; L(2,1) = -10.0_wp
    call step1(mat, dt, L, F, e, s, rho, info)
#line 137 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 137) )
  if (anyExceptions()) return
#line 138 "/work/main/tests/unit/test_materials.pf"
    exx = dt * 150.0_wp; eyy = dt * (-40.0_wp); exy = 0.5_wp * dt * (70.0_wp - 10.0_wp)
#line 139 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, e(3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 139) )
  if (anyExceptions()) return
#line 140 "/work/main/tests/unit/test_materials.pf"
#line 140 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(exy, e(6), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 140) )
  if (anyExceptions()) return
#line 141 "/work/main/tests/unit/test_materials.pf"
#line 141 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual((LAM_ST + 2.0_wp * MU_ST) * exx + LAM_ST * eyy, s(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 141) )
  if (anyExceptions()) return
#line 142 "/work/main/tests/unit/test_materials.pf"
#line 142 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * exx + (LAM_ST + 2.0_wp * MU_ST) * eyy, s(2), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 142) )
  if (anyExceptions()) return
#line 143 "/work/main/tests/unit/test_materials.pf"
#line 143 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * (exx + eyy), s(3), tolerance=RTOL, message='szz = lam(exx+eyy)', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 143) )
  if (anyExceptions()) return
#line 144 "/work/main/tests/unit/test_materials.pf"
#line 144 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(2.0_wp * MU_ST * exy, s(6), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 144) )
  if (anyExceptions()) return
#line 145 "/work/main/tests/unit/test_materials.pf"
#line 145 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(4), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 145) )
  if (anyExceptions()) return
#line 146 "/work/main/tests/unit/test_materials.pf"
#line 146 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(5), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 146) )
  if (anyExceptions()) return
#line 147 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_plane_strain

  !@test
  subroutine test_le_pure_shear_and_energy()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), exy, psi(1)
    integer :: info, k
    mat = make_le(E_ST, NU_ST, RHO_ST)
    call rest(F, e, s); rho = RHO_ST
    ! Simple shear rate: sym(L) is pure shear, tr = 0, so ρ is unchanged exactly.
    L = 0.0_wp; L(1,2) = 400.0_wp
    call step1(mat, 1.0e-6_wp, L, F, e, s, rho, info)
#line 159 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 159) )
  if (anyExceptions()) return
#line 160 "/work/main/tests/unit/test_materials.pf"
    exy = 0.5_wp * 1.0e-6_wp * 400.0_wp
#line 161 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(exy, e(6), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 161) )
  if (anyExceptions()) return
#line 162 "/work/main/tests/unit/test_materials.pf"
#line 162 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(2.0_wp * MU_ST * exy, s(6), tolerance=RTOL, message='sxy = 2 mu exy', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 162) )
  if (anyExceptions()) return
#line 163 "/work/main/tests/unit/test_materials.pf"
    do k = 1, 5
#line 164 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(k), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 164) )
  if (anyExceptions()) return
#line 165 "/work/main/tests/unit/test_materials.pf"
    end do
#line 166 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(RHO_ST, rho, tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 166) )
  if (anyExceptions()) return
#line 167 "/work/main/tests/unit/test_materials.pf"
    ! ½σ:ε with the shear pair counted twice: ψ = σxy εxy = 2μ εxy².
    call mat%energy_density(reshape(F, [3, 3, 1]), reshape(e, [6, 1]), reshape(s, [6, 1]), psi)
#line 169 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(2.0_wp * MU_ST * exy**2, psi(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 169) )
  if (anyExceptions()) return
#line 170 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_pure_shear_and_energy

  !@test
  subroutine test_le_volumetric_and_density_eq19()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), dt, ev, kbulk
    integer :: info, k
    mat = make_le(E_ST, NU_ST, RHO_ST)
    call rest(F, e, s); rho = 1000.0_wp
    dt = 1.0e-3_wp
    L = 0.0_wp; L(1,1) = 2.0_wp; L(2,2) = 3.0_wp; L(3,3) = 5.0_wp
    call step1(mat, dt, L, F, e, s, rho, info)
#line 182 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 182) )
  if (anyExceptions()) return
#line 183 "/work/main/tests/unit/test_materials.pf"
    ev = dt * 2.0_wp + dt * 3.0_wp + dt * 5.0_wp
    ! eq. (19) over one step: ρ ← ρ/(1 + tr Δε), tr Δε = 0.01.
#line 185 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(1000.0_wp / 1.01_wp, rho, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 185) )
  if (anyExceptions()) return
#line 186 "/work/main/tests/unit/test_materials.pf"
    ! Mean stress = K tr ε with K = λ + 2μ/3.
    kbulk = LAM_ST + 2.0_wp * MU_ST / 3.0_wp
#line 188 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(kbulk * ev, (s(1) + s(2) + s(3)) / 3.0_wp, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 188) )
  if (anyExceptions()) return
#line 189 "/work/main/tests/unit/test_materials.pf"
    ! Isotropic L: equal normal stresses 3Kε, no shear.
    call rest(F, e, s); rho = 1000.0_wp
    L = 4.0_wp * identity3()
    call step1(mat, dt, L, F, e, s, rho, info)
    do k = 1, 3
#line 194 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(3.0_wp * kbulk * 4.0e-3_wp, s(k), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 194) )
  if (anyExceptions()) return
#line 195 "/work/main/tests/unit/test_materials.pf"
#line 195 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(k + 3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 195) )
  if (anyExceptions()) return
#line 196 "/work/main/tests/unit/test_materials.pf"
    end do
#line 197 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(1000.0_wp / 1.012_wp, rho, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 197) )
  if (anyExceptions()) return
#line 198 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_volumetric_and_density_eq19

  !@test
  subroutine test_le_increments_add_up()
    ! The stress update is linear in Δε: 1000 steps of Δt/1000 give the single step's strain
    ! and stress up to accumulated round-off (≤ 1000 × 1.1e-16 ≈ 1e-13 relative, observed
    ! 4e-14; tolerance 1e-12).
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F1(3,3), e1(6), s1(6), r1, F2(3,3), e2(6), s2(6), r2, L(3,3)
    integer :: info, k
    integer, parameter :: NSUB = 1000
    mat = make_le(E_ST, NU_ST, RHO_ST)
    L = reshape([30.0_wp, -5.0_wp, 12.0_wp, 8.0_wp, -20.0_wp, 3.0_wp, -7.0_wp, 6.0_wp, 10.0_wp], &
                [3, 3])
    call rest(F1, e1, s1); r1 = RHO_ST
    call step1(mat, 1.0e-4_wp, L, F1, e1, s1, r1, info)
    call rest(F2, e2, s2); r2 = RHO_ST
    do k = 1, NSUB
      call step1(mat, 1.0e-4_wp / NSUB, L, F2, e2, s2, r2, info)
#line 217 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 217) )
  if (anyExceptions()) return
#line 218 "/work/main/tests/unit/test_materials.pf"
    end do
    do k = 1, 6
#line 220 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(e1(k), e2(k), tolerance=1.0e-12_wp, message='strain', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 220) )
  if (anyExceptions()) return
#line 221 "/work/main/tests/unit/test_materials.pf"
#line 221 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(s1(k), s2(k), tolerance=1.0e-12_wp, message='stress', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 221) )
  if (anyExceptions()) return
#line 222 "/work/main/tests/unit/test_materials.pf"
    end do
  end subroutine test_le_increments_add_up

  !@test
  subroutine test_le_energy_general_state()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), psi(1)
    integer :: info
    mat = make_le(E_ST, NU_ST, RHO_ST)
    call rest(F, e, s); rho = RHO_ST
    L = reshape([30.0_wp, -5.0_wp, 12.0_wp, 8.0_wp, -20.0_wp, 3.0_wp, -7.0_wp, 6.0_wp, 10.0_wp], &
                [3, 3])
    call step1(mat, 1.0e-5_wp, L, F, e, s, rho, info)
    call mat%energy_density(reshape(F, [3, 3, 1]), reshape(e, [6, 1]), reshape(s, [6, 1]), psi)
    ! Full tensor contraction of the 3×3 matrices.
#line 237 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(0.5_wp * sum(voigt_to_mat(s) * voigt_to_mat(e)), psi(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 237) )
  if (anyExceptions()) return
#line 238 "/work/main/tests/unit/test_materials.pf"
#line 238 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(psi(1) > 0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 238) )
  if (anyExceptions()) return
#line 239 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_energy_general_state

  !@test
  subroutine test_le_wave_speed()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: expected
    mat = make_le(E_ST, 0.0_wp, RHO_ST)
    ! Dyka bar: c = sqrt(E/ρ) ≈ 5053 m/s for ν = 0.
#line 247 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(sqrt(E_ST / RHO_ST), mat%wave_speed(RHO_ST), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 247) )
  if (anyExceptions()) return
#line 248 "/work/main/tests/unit/test_materials.pf"
    mat = make_le(E_ST, NU_ST, RHO_ST)
    expected = sqrt((LAM_ST + 2.0_wp * MU_ST) / 7000.0_wp)
#line 250 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(expected, mat%wave_speed(7000.0_wp), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 250) )
  if (anyExceptions()) return
#line 251 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_wave_speed

  !@test
  subroutine test_le_failure_reports_first_bad_particle()
    type(empm_linear_elastic_t) :: mat
    real(wp) :: L(3,3,3), F(3,3,3), e(6,3), s(6,3), rho(3)
    integer :: info, p
    mat = make_le(E_ST, NU_ST, RHO_ST)
    L = 0.0_wp
    do p = 1, 3
      F(:,:,p) = identity3()
    end do
    e = 0.0_wp; s = 0.0_wp; rho = RHO_ST
    L(1,1,1) = 0.1_wp
    L(1,1,2) = -1.0_wp  ! 1 + tr Δε = 0 with dt = 1
    L(1,1,3) = -2.0_wp  ! 1 + tr Δε < 0
    call mat%update(1.0_wp, L, F, e, s, rho, info)
#line 268 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(2, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 268) )
  if (anyExceptions()) return
#line 269 "/work/main/tests/unit/test_materials.pf"
#line 269 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(RHO_ST / 1.1_wp, rho(1), tolerance=RTOL, message='good particle updated', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 269) )
  if (anyExceptions()) return
#line 270 "/work/main/tests/unit/test_materials.pf"
#line 270 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(RHO_ST, rho(2), tolerance=0.0_wp, message='failed particle left unchanged', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 270) )
  if (anyExceptions()) return
#line 271 "/work/main/tests/unit/test_materials.pf"
#line 271 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(1,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 271) )
  if (anyExceptions()) return
#line 272 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_le_failure_reports_first_bad_particle

  ! ---- neo-Hookean ------------------------------------------------------------------------------

  !@test
  subroutine test_nh_zero_stress_at_identity()
    real(wp) :: sig(3,3)
    integer :: i, j
    sig = empm_neohookean_cauchy(MU_ST, LAM_ST, identity3())
    do j = 1, 3
      do i = 1, 3
#line 283 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(i,j), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 283) )
  if (anyExceptions()) return
#line 284 "/work/main/tests/unit/test_materials.pf"
      end do
    end do
#line 286 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, empm_neohookean_energy(MU_ST, LAM_ST, identity3()), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 286) )
  if (anyExceptions()) return
#line 287 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_zero_stress_at_identity

  !@test
  subroutine test_nh_uniaxial_stretch()
    real(wp) :: F(3,3), sig(3,3), st, lnst, expected
    integer :: k
    real(wp), parameter :: STRETCH(2) = [1.3_wp, 0.6_wp]
    do k = 1, size(STRETCH)
      st = STRETCH(k)
      lnst = log(st)
      F = identity3(); F(1,1) = st
      sig = empm_neohookean_cauchy(MU_ST, LAM_ST, F)
      ! J = s: σxx = μ(s² − 1)/s + λ ln s / s, σyy = σzz = λ ln s / s.
      expected = MU_ST * (st - 1.0_wp / st) + LAM_ST * lnst / st
#line 301 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(expected, sig(1,1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 301) )
  if (anyExceptions()) return
#line 302 "/work/main/tests/unit/test_materials.pf"
#line 302 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * lnst / st, sig(2,2), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 302) )
  if (anyExceptions()) return
#line 303 "/work/main/tests/unit/test_materials.pf"
#line 303 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST * lnst / st, sig(3,3), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 303) )
  if (anyExceptions()) return
#line 304 "/work/main/tests/unit/test_materials.pf"
#line 304 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(1,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 304) )
  if (anyExceptions()) return
#line 305 "/work/main/tests/unit/test_materials.pf"
#line 305 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(1,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 305) )
  if (anyExceptions()) return
#line 306 "/work/main/tests/unit/test_materials.pf"
#line 306 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(2,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 306) )
  if (anyExceptions()) return
#line 307 "/work/main/tests/unit/test_materials.pf"
      expected = 0.5_wp * MU_ST * (st**2 - 1.0_wp) - MU_ST * lnst + 0.5_wp * LAM_ST * lnst**2
#line 308 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(expected, empm_neohookean_energy(MU_ST, LAM_ST, F), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 308) )
  if (anyExceptions()) return
#line 309 "/work/main/tests/unit/test_materials.pf"
    end do
  end subroutine test_nh_uniaxial_stretch

  !@test
  subroutine test_nh_simple_shear()
    real(wp) :: F(3,3), sig(3,3)
    real(wp), parameter :: G = 0.3_wp
    F = identity3(); F(1,2) = G
    sig = empm_neohookean_cauchy(MU_ST, LAM_ST, F)
    ! J = 1 exactly: σ = μ(F Fᵀ − I) → σxx = μγ², σxy = μγ, all else 0.
#line 319 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(MU_ST * G**2, sig(1,1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 319) )
  if (anyExceptions()) return
#line 320 "/work/main/tests/unit/test_materials.pf"
#line 320 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(MU_ST * G, sig(1,2), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 320) )
  if (anyExceptions()) return
#line 321 "/work/main/tests/unit/test_materials.pf"
#line 321 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(MU_ST * G, sig(2,1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 321) )
  if (anyExceptions()) return
#line 322 "/work/main/tests/unit/test_materials.pf"
#line 322 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(2,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 322) )
  if (anyExceptions()) return
#line 323 "/work/main/tests/unit/test_materials.pf"
#line 323 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(3,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 323) )
  if (anyExceptions()) return
#line 324 "/work/main/tests/unit/test_materials.pf"
#line 324 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(1,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 324) )
  if (anyExceptions()) return
#line 325 "/work/main/tests/unit/test_materials.pf"
#line 325 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, sig(2,3), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 325) )
  if (anyExceptions()) return
#line 326 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_simple_shear

  !@test
  subroutine test_nh_objectivity()
    ! σ(R F) = R σ(F) Rᵀ for a rotation R (O(1) moduli so that 1e-13 is an absolute round-off).
    real(wp), parameter :: MU = 1.0_wp, LAM = 1.5_wp
    real(wp) :: F(3,3), R(3,3), lhs(3,3), rhs(3,3), psi_f, psi_rf
    integer :: i, j
    F = general_F()
    R = rotation([1.0_wp, -2.0_wp, 0.5_wp], 2.1_wp)
    lhs = empm_neohookean_cauchy(MU, LAM, matmul(R, F))
    rhs = matmul(R, matmul(empm_neohookean_cauchy(MU, LAM, F), transpose(R)))
    do j = 1, 3
      do i = 1, 3
#line 340 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(rhs(i,j), lhs(i,j), tolerance=1.0e-13_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 340) )
  if (anyExceptions()) return
#line 341 "/work/main/tests/unit/test_materials.pf"
      end do
    end do
    ! And the energy is frame-indifferent.
    psi_f = empm_neohookean_energy(MU, LAM, F)
    psi_rf = empm_neohookean_energy(MU, LAM, matmul(R, F))
#line 346 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(psi_f, psi_rf, tolerance=1.0e-13_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 346) )
  if (anyExceptions()) return
#line 347 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_objectivity

  !@test
  subroutine test_nh_stress_is_energy_derivative()
    ! σ = (1/J) (∂ψ₀/∂F) Fᵀ with ∂ψ₀/∂F from central differences (tolerance: see the header).
    real(wp), parameter :: MU = 1.0_wp, LAM = 1.5_wp, H = 1.0e-5_wp
    real(wp) :: F(3,3), Fp(3,3), Fm(3,3), P(3,3), sig_fd(3,3), sig(3,3)
    integer :: i, j
    F = general_F()
    do j = 1, 3
      do i = 1, 3
        Fp = F; Fp(i,j) = F(i,j) + H
        Fm = F; Fm(i,j) = F(i,j) - H
        P(i,j) = (empm_neohookean_energy(MU, LAM, Fp) - empm_neohookean_energy(MU, LAM, Fm)) &
                 / (2.0_wp * H)
      end do
    end do
    sig_fd = matmul(P, transpose(F)) / det3(F)
    sig = empm_neohookean_cauchy(MU, LAM, F)
    do j = 1, 3
      do i = 1, 3
#line 368 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(sig_fd(i,j), sig(i,j), tolerance=1.0e-8_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 368) )
  if (anyExceptions()) return
#line 369 "/work/main/tests/unit/test_materials.pf"
      end do
    end do
  end subroutine test_nh_stress_is_energy_derivative

  !@test
  subroutine test_nh_update_consistent_with_F()
    type(empm_neohookean_t) :: mat
    real(wp) :: F(3,3), e(6), s(6), rho, L(3,3), dt, Fx(3,3), sx(6), ex(6), psi(1), J
    integer :: info, k
    mat = make_nh(1.0e4_wp, 0.3_wp, 1.0_wp)
    call rest(F, e, s); rho = 1.0_wp
    dt = 1.0e-2_wp
    L = reshape([3.0_wp, -1.0_wp, 2.0_wp, 4.0_wp, -2.0_wp, 1.5_wp, -0.5_wp, 2.5_wp, 1.0_wp], [3, 3])
    call step1(mat, dt, L, F, e, s, rho, info)
#line 383 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 383) )
  if (anyExceptions()) return
#line 384 "/work/main/tests/unit/test_materials.pf"
    ! Second step from the deformed state exercises the product (I + ΔtL) F.
    call step1(mat, dt, L, F, e, s, rho, info)
#line 386 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 386) )
  if (anyExceptions()) return
#line 387 "/work/main/tests/unit/test_materials.pf"
    Fx = matmul(identity3() + dt * L, identity3() + dt * L)
    J = det3(Fx)
    sx = mat_to_voigt(empm_neohookean_cauchy(mat%mu, mat%lambda, Fx))
    ex = mat_to_voigt(Fx - identity3())
#line 391 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(1.0_wp / J, rho, tolerance=RTOL, message='rho = rho0/J', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 391) )
  if (anyExceptions()) return
#line 392 "/work/main/tests/unit/test_materials.pf"
    do k = 1, 6
#line 393 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(sx(k), s(k), tolerance=RTOL * 1.0e4_wp, message='stress = sigma(F)', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 393) )
  if (anyExceptions()) return
#line 394 "/work/main/tests/unit/test_materials.pf"
#line 394 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(ex(k), e(k), tolerance=RTOL, message='strain = sym(F) - I', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 394) )
  if (anyExceptions()) return
#line 395 "/work/main/tests/unit/test_materials.pf"
    end do
    call mat%energy_density(reshape(F, [3, 3, 1]), reshape(e, [6, 1]), reshape(s, [6, 1]), psi)
    sx(1) = empm_neohookean_energy(mat%mu, mat%lambda, Fx) / J
#line 398 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(sx(1), psi(1), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 398) )
  if (anyExceptions()) return
#line 399 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_update_consistent_with_F

  !@test
  subroutine test_nh_small_strain_limit_is_linear_elastic()
    ! For |ε| ~ 1e-6 both models agree up to O(ε) relatively: tolerance 1e-5 × stress scale.
    type(empm_neohookean_t) :: nh
    type(empm_linear_elastic_t) :: le
    real(wp) :: F1(3,3), e1(6), s1(6), r1, F2(3,3), e2(6), s2(6), r2, L(3,3), scale
    integer :: info, k
    nh = make_nh(E_ST, NU_ST, RHO_ST)
    le = make_le(E_ST, NU_ST, RHO_ST)
    L = reshape([3.0_wp, -1.0_wp, 2.0_wp, 4.0_wp, -2.0_wp, 1.5_wp, -0.5_wp, 2.5_wp, 1.0_wp], [3, 3])
    call rest(F1, e1, s1); r1 = RHO_ST
    call rest(F2, e2, s2); r2 = RHO_ST
    call step1(nh, 2.5e-7_wp, L, F1, e1, s1, r1, info)
    call step1(le, 2.5e-7_wp, L, F2, e2, s2, r2, info)
    scale = maxval(abs(s2))
    do k = 1, 6
#line 417 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(s2(k), s1(k), tolerance=1.0e-5_wp * scale, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 417) )
  if (anyExceptions()) return
#line 418 "/work/main/tests/unit/test_materials.pf"
    end do
  end subroutine test_nh_small_strain_limit_is_linear_elastic

  !@test
  subroutine test_nh_wave_speed()
    type(empm_neohookean_t) :: mat
    real(wp) :: expected
    mat = make_nh(1.0e4_wp, 0.3_wp, 1.0_wp)
    ! At the current density (0.8 ≠ ρ0), not the reference one.
    expected = sqrt((mat%lambda + 2.0_wp * mat%mu) / 0.8_wp)
#line 428 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(expected, mat%wave_speed(0.8_wp), tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 428) )
  if (anyExceptions()) return
#line 429 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_wave_speed

  !@test
  subroutine test_nh_inverted_F_fails()
    type(empm_neohookean_t) :: mat
    real(wp) :: L(3,3,3), F(3,3,3), e(6,3), s(6,3), rho(3)
    integer :: info, p
    mat = make_nh(1.0e4_wp, 0.3_wp, 1.0_wp)
    L = 0.0_wp
    do p = 1, 3
      F(:,:,p) = identity3()
    end do
    e = 0.0_wp; s = 0.0_wp; rho = 1.0_wp
    L(1,1,1) = 0.1_wp
    L(1,1,2) = -1.0_wp  ! J = 0 with dt = 1
    L(1,1,3) = -2.0_wp  ! J = −1
    call mat%update(1.0_wp, L, F, e, s, rho, info)
#line 446 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(2, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 446) )
  if (anyExceptions()) return
#line 447 "/work/main/tests/unit/test_materials.pf"
#line 447 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(1.1_wp, F(1,1,1), tolerance=RTOL, message='good particle updated', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 447) )
  if (anyExceptions()) return
#line 448 "/work/main/tests/unit/test_materials.pf"
#line 448 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(1.0_wp, F(1,1,2), tolerance=0.0_wp, message='failed particle left unchanged', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 448) )
  if (anyExceptions()) return
#line 449 "/work/main/tests/unit/test_materials.pf"
#line 449 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(1.0_wp, rho(2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 449) )
  if (anyExceptions()) return
#line 450 "/work/main/tests/unit/test_materials.pf"
#line 450 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(0.0_wp, s(1,2), tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 450) )
  if (anyExceptions()) return
#line 451 "/work/main/tests/unit/test_materials.pf"
    ! Only particle 3 bad: info points at it.
    L(1,1,2) = 0.0_wp
    call mat%update(1.0_wp, L, F, e, s, rho, info)
#line 454 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(3, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 454) )
  if (anyExceptions()) return
#line 455 "/work/main/tests/unit/test_materials.pf"
  end subroutine test_nh_inverted_F_fails

  ! ---- factory ----------------------------------------------------------------------------------

  !@test
  subroutine test_factory_names_and_create()
    character(len=MAT_NAME_LEN) :: names(size(empm_material_names()))
    character(len=:), allocatable :: nm
    class(empm_material_t), allocatable :: mat
    integer :: info, k
    names = empm_material_names()
#line 466 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(2, size(names), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 466) )
  if (anyExceptions()) return
#line 467 "/work/main/tests/unit/test_materials.pf"
#line 467 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(any(names == 'linear_elastic'), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 467) )
  if (anyExceptions()) return
#line 468 "/work/main/tests/unit/test_materials.pf"
#line 468 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(any(names == 'neohookean'), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 468) )
  if (anyExceptions()) return
#line 469 "/work/main/tests/unit/test_materials.pf"
    do k = 1, size(names)
      nm = trim(names(k))
      call empm_material_create(nm, E_ST, NU_ST, RHO_ST, mat, info)
#line 472 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_OK, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 472) )
  if (anyExceptions()) return
#line 473 "/work/main/tests/unit/test_materials.pf"
#line 473 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(allocated(mat), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 473) )
  if (anyExceptions()) return
#line 474 "/work/main/tests/unit/test_materials.pf"
#line 474 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(mat%name() == nm, message='name() round-trips', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 474) )
  if (anyExceptions()) return
#line 475 "/work/main/tests/unit/test_materials.pf"
#line 475 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(RHO_ST, mat%rho0, tolerance=0.0_wp, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 475) )
  if (anyExceptions()) return
#line 476 "/work/main/tests/unit/test_materials.pf"
    end do
    call empm_material_create(' Linear_Elastic ', E_ST, NU_ST, RHO_ST, mat, info)
#line 478 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_OK, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 478) )
  if (anyExceptions()) return
#line 479 "/work/main/tests/unit/test_materials.pf"
    select type (mat)
    type is (empm_linear_elastic_t)
#line 481 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(LAM_ST, mat%lambda, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 481) )
  if (anyExceptions()) return
#line 482 "/work/main/tests/unit/test_materials.pf"
#line 482 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(MU_ST, mat%mu, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 482) )
  if (anyExceptions()) return
#line 483 "/work/main/tests/unit/test_materials.pf"
    class default
#line 484 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(.false., message='wrong dynamic type for linear_elastic', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 484) )
  if (anyExceptions()) return
#line 485 "/work/main/tests/unit/test_materials.pf"
    end select
    call empm_material_create('neohookean', E_ST, NU_ST, RHO_ST, mat, info)
    select type (mat)
    type is (empm_neohookean_t)
#line 489 "/work/main/tests/unit/test_materials.pf"
  call assertRelativelyEqual(MU_ST, mat%mu, tolerance=RTOL, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 489) )
  if (anyExceptions()) return
#line 490 "/work/main/tests/unit/test_materials.pf"
    class default
#line 491 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(.false., message='wrong dynamic type for neohookean', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 491) )
  if (anyExceptions()) return
#line 492 "/work/main/tests/unit/test_materials.pf"
    end select
  end subroutine test_factory_names_and_create

  !@test
  subroutine test_factory_errors()
    class(empm_material_t), allocatable :: mat
    integer :: info, k
    character(len=*), parameter :: MODELS(2) = ['linear_elastic', 'neohookean    ']
    call empm_material_create('steel', E_ST, NU_ST, RHO_ST, mat, info)
#line 501 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_UNKNOWN_NAME, info, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 501) )
  if (anyExceptions()) return
#line 502 "/work/main/tests/unit/test_materials.pf"
#line 502 "/work/main/tests/unit/test_materials.pf"
  call assertFalse(allocated(mat), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 502) )
  if (anyExceptions()) return
#line 503 "/work/main/tests/unit/test_materials.pf"
#line 503 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(index(material_status_text(info), 'neohookean') > 0, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 503) )
  if (anyExceptions()) return
#line 504 "/work/main/tests/unit/test_materials.pf"
    do k = 1, size(MODELS)
      call empm_material_create(trim(MODELS(k)), E_ST, 0.5_wp, RHO_ST, mat, info)
#line 506 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_BAD_NU, info, message='nu = 0.5', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 506) )
  if (anyExceptions()) return
#line 507 "/work/main/tests/unit/test_materials.pf"
#line 507 "/work/main/tests/unit/test_materials.pf"
  call assertFalse(allocated(mat), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 507) )
  if (anyExceptions()) return
#line 508 "/work/main/tests/unit/test_materials.pf"
      call empm_material_create(trim(MODELS(k)), E_ST, -1.0_wp, RHO_ST, mat, info)
#line 509 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_BAD_NU, info, message='nu = -1', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 509) )
  if (anyExceptions()) return
#line 510 "/work/main/tests/unit/test_materials.pf"
      call empm_material_create(trim(MODELS(k)), 0.0_wp, NU_ST, RHO_ST, mat, info)
#line 511 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_BAD_E, info, message='E = 0', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 511) )
  if (anyExceptions()) return
#line 512 "/work/main/tests/unit/test_materials.pf"
      call empm_material_create(trim(MODELS(k)), -1.0_wp, NU_ST, RHO_ST, mat, info)
#line 513 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_BAD_E, info, message='E < 0', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 513) )
  if (anyExceptions()) return
#line 514 "/work/main/tests/unit/test_materials.pf"
      call empm_material_create(trim(MODELS(k)), E_ST, NU_ST, 0.0_wp, mat, info)
#line 515 "/work/main/tests/unit/test_materials.pf"
  call assertEqual(MAT_BAD_RHO0, info, message='rho0 = 0', &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 515) )
  if (anyExceptions()) return
#line 516 "/work/main/tests/unit/test_materials.pf"
#line 516 "/work/main/tests/unit/test_materials.pf"
  call assertFalse(allocated(mat), &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 516) )
  if (anyExceptions()) return
#line 517 "/work/main/tests/unit/test_materials.pf"
#line 517 "/work/main/tests/unit/test_materials.pf"
  call assertTrue(len(material_status_text(info)) > 0, &
 & location=SourceLocation( &
 & 'test_materials.pf', &
 & 517) )
  if (anyExceptions()) return
#line 518 "/work/main/tests/unit/test_materials.pf"
    end do
  end subroutine test_factory_errors
end module test_materials

module Wraptest_materials
   use FUnit
   use test_materials
   implicit none
   private

contains


end module Wraptest_materials

function test_materials_suite() result(suite)
   use FUnit
   use test_materials
   use Wraptest_materials
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_materials_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_uniaxial_strain', &
      test_le_uniaxial_strain))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_uniaxial_strain_nu0_is_E_eps', &
      test_le_uniaxial_strain_nu0_is_E_eps))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_plane_strain', &
      test_le_plane_strain))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_pure_shear_and_energy', &
      test_le_pure_shear_and_energy))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_volumetric_and_density_eq19', &
      test_le_volumetric_and_density_eq19))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_increments_add_up', &
      test_le_increments_add_up))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_energy_general_state', &
      test_le_energy_general_state))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_wave_speed', &
      test_le_wave_speed))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_le_failure_reports_first_bad_particle', &
      test_le_failure_reports_first_bad_particle))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_zero_stress_at_identity', &
      test_nh_zero_stress_at_identity))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_uniaxial_stretch', &
      test_nh_uniaxial_stretch))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_simple_shear', &
      test_nh_simple_shear))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_objectivity', &
      test_nh_objectivity))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_stress_is_energy_derivative', &
      test_nh_stress_is_energy_derivative))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_update_consistent_with_F', &
      test_nh_update_consistent_with_F))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_small_strain_limit_is_linear_elastic', &
      test_nh_small_strain_limit_is_linear_elastic))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_wave_speed', &
      test_nh_wave_speed))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_nh_inverted_F_fails', &
      test_nh_inverted_F_fails))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_factory_names_and_create', &
      test_factory_names_and_create))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_factory_errors', &
      test_factory_errors))
   call suite%addTest(t)


end function test_materials_suite

