!> Manufactured-solution extension point: a body force that also knows its exact fields.
!>
!> A concrete solution implements `fields` (displacement, velocity, deformation gradient, Cauchy
!> stress and body force at one reference point); the body-force binding `eval`, shared here,
!> evaluates the body force at every particle's reference position.
module empm_mms
  use empm_kinds, only: wp
  use empm_loads, only: empm_body_force_t
  implicit none
  private
  public :: empm_mms_t

  !> A manufactured solution; its dimension is the model's (the rows of the positions).
  type, abstract, extends(empm_body_force_t) :: empm_mms_t
  contains
    procedure(fields_iface), deferred :: fields
    procedure :: eval => mms_eval
  end type empm_mms_t

  abstract interface
    !> Exact fields at reference position X and time t.
    pure subroutine fields_iface(self, X, t, u, v, F, s, b)
      import :: empm_mms_t, wp
      class(empm_mms_t), intent(in) :: self !! solution
      real(wp), intent(in) :: X(:)          !! reference position (ndim) [m]
      real(wp), intent(in) :: t             !! time [s]
      real(wp), intent(out) :: u(:)         !! displacement (ndim) [m]
      real(wp), intent(out) :: v(:)         !! velocity (ndim) [m/s]
      real(wp), intent(out) :: F(3,3)       !! deformation gradient
      real(wp), intent(out) :: s(6)         !! Cauchy stress, Voigt [Pa]
      real(wp), intent(out) :: b(:)         !! body force per unit mass (ndim) [m/s²]
    end subroutine fields_iface
  end interface

contains

  !> [[empm_body_force_t]] binding: the body force at the particles' reference positions (the
  !> manufactured fields are Lagrangian).
  pure subroutine mms_eval(self, t, x0, x, b)
    class(empm_mms_t), intent(in) :: self !! solution
    real(wp), intent(in) :: t             !! time [s]
    real(wp), intent(in) :: x0(:,:)       !! reference positions (ndim, n) [m]
    real(wp), intent(in) :: x(:,:)        !! current positions (ndim, n), unused
    real(wp), intent(out) :: b(:,:)       !! body force per unit mass (ndim, n)
    real(wp) :: u(3), v(3), F(3,3), s(6)
    integer :: p, d
    d = size(x0, 1)
    b = 0.0_wp
    do p = 1, size(x0, 2)
      call self%fields(x0(1:d, p), t, u(1:d), v(1:d), F, s, b(1:d, p))
    end do
    associate (unused => x)
    end associate
  end subroutine mms_eval
end module empm_mms
