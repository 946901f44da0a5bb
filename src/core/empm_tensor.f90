!> Small 3×3 tensor helpers shared by the material models and the solver.
!>
!> Symmetric tensors are stored in Voigt order (xx, yy, zz, yz, xz, xy) with *tensor* shear
!> components (ε_yz, not γ_yz = 2ε_yz), as everywhere in empm. All procedures are pure.
module empm_tensor
  use empm_kinds, only: wp
  implicit none
  private
  public :: identity3, trace3, det3, adjugate3, sym3, voigt_to_mat, mat_to_voigt, voigt_ddot, &
            advance_f

contains

  !> The 3×3 identity matrix.
  pure function identity3() result(A)
    real(wp) :: A(3,3) !! identity
    A = 0.0_wp
    A(1,1) = 1.0_wp; A(2,2) = 1.0_wp; A(3,3) = 1.0_wp
  end function identity3

  !> Trace of a 3×3 matrix.
  pure real(wp) function trace3(A)
    real(wp), intent(in) :: A(3,3) !! matrix
    trace3 = A(1,1) + A(2,2) + A(3,3)
  end function trace3

  !> Determinant of a 3×3 matrix (cofactor expansion along the first row).
  pure real(wp) function det3(A)
    real(wp), intent(in) :: A(3,3) !! matrix
    det3 = A(1,1) * (A(2,2) * A(3,3) - A(2,3) * A(3,2)) &
         - A(1,2) * (A(2,1) * A(3,3) - A(2,3) * A(3,1)) &
         + A(1,3) * (A(2,1) * A(3,2) - A(2,2) * A(3,1))
  end function det3

  !> Adjugate C = det(A) A⁻¹ of a 3×3 matrix (defined for any A); det A =
  !> A(1,1) C(1,1) + A(1,2) C(2,1) + A(1,3) C(3,1).
  pure function adjugate3(A) result(C)
    real(wp), intent(in) :: A(3,3) !! matrix
    real(wp) :: C(3,3)             !! adjugate
    C(1,1) = A(2,2) * A(3,3) - A(2,3) * A(3,2)
    C(1,2) = A(1,3) * A(3,2) - A(1,2) * A(3,3)
    C(1,3) = A(1,2) * A(2,3) - A(1,3) * A(2,2)
    C(2,1) = A(2,3) * A(3,1) - A(2,1) * A(3,3)
    C(2,2) = A(1,1) * A(3,3) - A(1,3) * A(3,1)
    C(2,3) = A(1,3) * A(2,1) - A(1,1) * A(2,3)
    C(3,1) = A(2,1) * A(3,2) - A(2,2) * A(3,1)
    C(3,2) = A(1,2) * A(3,1) - A(1,1) * A(3,2)
    C(3,3) = A(1,1) * A(2,2) - A(1,2) * A(2,1)
  end function adjugate3

  !> Symmetric part ½(A + Aᵀ) of a 3×3 matrix.
  pure function sym3(A) result(S)
    real(wp), intent(in) :: A(3,3) !! matrix
    real(wp) :: S(3,3)             !! symmetric part
    S = 0.5_wp * (A + transpose(A))
  end function sym3

  !> Symmetric 3×3 matrix from Voigt components (xx, yy, zz, yz, xz, xy), tensor shears.
  pure function voigt_to_mat(s) result(A)
    real(wp), intent(in) :: s(6) !! Voigt components
    real(wp) :: A(3,3)           !! symmetric matrix
    A(1,1) = s(1); A(2,2) = s(2); A(3,3) = s(3)
    A(2,3) = s(4); A(3,2) = s(4)
    A(1,3) = s(5); A(3,1) = s(5)
    A(1,2) = s(6); A(2,1) = s(6)
  end function voigt_to_mat

  !> Voigt components (xx, yy, zz, yz, xz, xy) of the symmetric part of a 3×3 matrix.
  !> Off-diagonal pairs are averaged, so a non-symmetric A is symmetrised, not truncated.
  pure function mat_to_voigt(A) result(s)
    real(wp), intent(in) :: A(3,3) !! matrix (need not be symmetric)
    real(wp) :: s(6)               !! Voigt components of ½(A + Aᵀ), tensor shears
    s(1) = A(1,1); s(2) = A(2,2); s(3) = A(3,3)
    s(4) = 0.5_wp * (A(2,3) + A(3,2))
    s(5) = 0.5_wp * (A(1,3) + A(3,1))
    s(6) = 0.5_wp * (A(1,2) + A(2,1))
  end function mat_to_voigt

  !> Double contraction a:b of two symmetric tensors given in Voigt form (tensor shears):
  !> each shear product counts twice, because a_ij b_ij sums both (i,j) and (j,i).
  pure real(wp) function voigt_ddot(a, b)
    real(wp), intent(in) :: a(6) !! first tensor, Voigt
    real(wp), intent(in) :: b(6) !! second tensor, Voigt
    voigt_ddot = a(1) * b(1) + a(2) * b(2) + a(3) * b(3) &
               + 2.0_wp * (a(4) * b(4) + a(5) * b(5) + a(6) * b(6))
  end function voigt_ddot

  !> Deformation gradient after a step with constant velocity gradient L (first order):
  !> (I + Δt L) F, written out so that no temporary is allocated per particle.
  pure function advance_f(dt, L, F) result(Fn)
    real(wp), intent(in) :: dt       !! time step [s]
    real(wp), intent(in) :: L(3,3)   !! velocity gradient [1/s]
    real(wp), intent(in) :: F(3,3)   !! deformation gradient at the start of the step
    real(wp) :: Fn(3,3)              !! deformation gradient at the end of the step
    integer :: i, j
    do j = 1, 3
      do i = 1, 3
        Fn(i,j) = F(i,j) + dt * (L(i,1) * F(1,j) + L(i,2) * F(2,j) + L(i,3) * F(3,j))
      end do
    end do
  end function advance_f
end module empm_tensor
