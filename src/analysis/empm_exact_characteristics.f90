!> Exact solution of the 1D elastic bar by characteristics (docs/algorithms §3, Dyka bar).
!>
!> Bar [0, L], density ρ, modulus E (uniaxial-strain modulus in 1D), wave speed c = sqrt(E/ρ),
!> impedance Z = ρc. The initial velocity V(x) and stress S(x) are piecewise constant on common
!> segments [xb(i), xb(i+1)]. Each end is fixed (v = 0) or free (σ = 0). V and S are extended to
!> the whole line by reflection about each end — fixed end: V odd, S even; free end: V even,
!> S odd — so that the extension satisfies both end conditions for all time; the reflections
!> about 0 and L compose to a shift by 2L with the factor s₀·s_L (the product of the two
!> reflection signs): periodic over 2L for equal ends, anti-periodic over 2L (periodic over 4L)
!> for a fixed and a free end. Then (d'Alembert)
!>
!>   v(x,t) = ½[V(x−ct) + V(x+ct)] + [S(x+ct) − S(x−ct)]/(2Z),
!>   σ(x,t) = ½[S(x−ct) + S(x+ct)] + (Z/2)[V(x+ct) − V(x−ct)].
!>
!> **Convention on wave fronts.** An argument x ± ct within `front_tol` (= 1e-12·L) of a jump of
!> the extended V or S (a breakpoint or an end) takes the mean of the two one-sided values. So
!> on a front v and σ are the mean of the states on either side (on a crossing of two fronts,
!> the mean of the four), and the end conditions hold exactly even on a front, because the
!> reflected jumps are averaged symmetrically. The tolerance absorbs the rounding of x ± ct
!> for |x ± ct| up to about 10³ L.
module empm_exact_characteristics
  use empm_kinds, only: wp, i8
  implicit none
  private
  public :: empm_char_bar_t, empm_dyka_bar
  public :: CHAR_FIXED, CHAR_FREE
  public :: CHAR_OK, CHAR_BAD_MATERIAL, CHAR_BAD_BREAKS, CHAR_BAD_VALUES, CHAR_BAD_END

  integer, parameter :: CHAR_FIXED = 1        !! end condition v = 0
  integer, parameter :: CHAR_FREE = 2         !! end condition σ = 0
  integer, parameter :: CHAR_OK = 0           !! set-up valid
  integer, parameter :: CHAR_BAD_MATERIAL = 1 !! L, E or ρ not positive and finite
  integer, parameter :: CHAR_BAD_BREAKS = 2   !! breakpoints not 0 = xb(1) < ... < xb(n+1) = L
  integer, parameter :: CHAR_BAD_VALUES = 3   !! segment values missing, extra or not finite
  integer, parameter :: CHAR_BAD_END = 4      !! end condition neither 'fixed' nor 'free'

  integer, parameter :: FIELD_V = 1 !! the velocity field V
  integer, parameter :: FIELD_S = 2 !! the stress field S

  !> 1D elastic bar with piecewise-constant initial data, solved by characteristics.
  !> Set it up with [[empm_char_bar_t(type):init]] or [[empm_dyka_bar]].
  type :: empm_char_bar_t
    real(wp) :: L = 0.0_wp              !! length [m]
    real(wp) :: E = 0.0_wp              !! modulus [Pa]
    real(wp) :: rho = 0.0_wp            !! density [kg/m³]
    integer :: end_bc(2) = CHAR_FIXED   !! end conditions at x = 0 and x = L (CHAR_FIXED|FREE)
    real(wp) :: front_tol = 0.0_wp      !! distance within which a point is on a jump [m]
    real(wp), allocatable :: xb(:)      !! segment breakpoints (n+1), xb(1) = 0, xb(n+1) = L [m]
    real(wp), allocatable :: vseg(:)    !! initial velocity on each segment (n) [m/s]
    real(wp), allocatable :: sseg(:)    !! initial stress on each segment (n) [Pa]
  contains
    procedure :: init => cb_init
    procedure :: wave_speed => cb_wave_speed
    procedure :: impedance => cb_impedance
    procedure :: velocity => cb_velocity
    procedure :: stress => cb_stress
    procedure :: initial_velocity => cb_initial_velocity
    procedure :: initial_stress => cb_initial_stress
  end type empm_char_bar_t

contains

  !> Set up the bar; on failure (`info /= CHAR_OK`) `self` is left unchanged.
  pure subroutine cb_init(self, L, E, rho, xb, vseg, sseg, left, right, info)
    class(empm_char_bar_t), intent(inout) :: self !! bar
    real(wp), intent(in) :: L           !! length [m], > 0
    real(wp), intent(in) :: E           !! modulus [Pa], > 0
    real(wp), intent(in) :: rho         !! density [kg/m³], > 0
    real(wp), intent(in) :: xb(:)       !! breakpoints (n+1): 0 = xb(1) < ... < xb(n+1) = L [m]
    real(wp), intent(in) :: vseg(:)     !! initial velocity on (xb(i), xb(i+1)) (n) [m/s]
    real(wp), intent(in) :: sseg(:)     !! initial stress on (xb(i), xb(i+1)) (n) [Pa]
    character(len=*), intent(in) :: left  !! end condition at x = 0: 'fixed' or 'free'
    character(len=*), intent(in) :: right !! end condition at x = L: 'fixed' or 'free'
    integer, intent(out) :: info        !! CHAR_OK or the CHAR_BAD_* code of the first problem
    integer :: n, bc(2)
    real(wp) :: tol
    info = CHAR_OK
    if (.not. (positive(L) .and. positive(E) .and. positive(rho))) then
      info = CHAR_BAD_MATERIAL
      return
    end if
    tol = 1.0e-12_wp * L
    n = size(xb) - 1
    ! Segments must be much longer than the front tolerance, or a point could be on two jumps.
    if (n < 1) then
      info = CHAR_BAD_BREAKS
    else if (abs(xb(1)) > tol .or. abs(xb(n + 1) - L) > tol) then
      info = CHAR_BAD_BREAKS
    else if (any(xb(2:n + 1) - xb(1:n) <= 4.0_wp * tol)) then
      info = CHAR_BAD_BREAKS
    else if (size(vseg) /= n .or. size(sseg) /= n) then
      info = CHAR_BAD_VALUES
    else if (.not. (all(abs(vseg) <= huge(1.0_wp)) .and. all(abs(sseg) <= huge(1.0_wp)))) then
      info = CHAR_BAD_VALUES
    end if
    if (info /= CHAR_OK) return
    bc = [end_code(left), end_code(right)]
    if (any(bc == 0)) then
      info = CHAR_BAD_END
      return
    end if
    self%L = L
    self%E = E
    self%rho = rho
    self%end_bc = bc
    self%front_tol = tol
    self%xb = xb
    self%xb(1) = 0.0_wp        ! snap the ends so that the reflections are exact
    self%xb(n + 1) = L
    self%vseg = vseg
    self%sseg = sseg
  end subroutine cb_init

  !> The Dyka bar of docs/algorithms §3: L = 0.1333 m, E = 200 GPa, ρ = 7833 kg/m³, x = 0 fixed,
  !> x = L free, no initial stress, v = +5 m/s on the last quarter [3L/4, L], 0 elsewhere.
  pure function empm_dyka_bar() result(bar)
    type(empm_char_bar_t) :: bar !! the bar, ready to evaluate
    real(wp), parameter :: L = 0.1333_wp
    integer :: info
    call bar%init(L, 200.0e9_wp, 7833.0_wp, [0.0_wp, 0.75_wp * L, L], [0.0_wp, 5.0_wp], &
                  [0.0_wp, 0.0_wp], 'fixed', 'free', info)
  end function empm_dyka_bar

  !> Wave speed c = sqrt(E/ρ) [m/s].
  elemental real(wp) function cb_wave_speed(self)
    class(empm_char_bar_t), intent(in) :: self !! bar
    cb_wave_speed = sqrt(self%E / self%rho)
  end function cb_wave_speed

  !> Impedance Z = ρc [Pa·s/m].
  elemental real(wp) function cb_impedance(self)
    class(empm_char_bar_t), intent(in) :: self !! bar
    cb_impedance = self%rho * self%wave_speed()
  end function cb_impedance

  !> Velocity v(x, t) [m/s] (mean of the two sides on a wave front).
  elemental real(wp) function cb_velocity(self, x, t) result(v)
    class(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: x                  !! position in [0, L] [m]
    real(wp), intent(in) :: t                  !! time >= 0 [s]
    real(wp) :: ct
    ct = self%wave_speed() * t
    v = 0.5_wp * (extended(self, x - ct, FIELD_V) + extended(self, x + ct, FIELD_V)) &
      + (extended(self, x + ct, FIELD_S) - extended(self, x - ct, FIELD_S)) &
        / (2.0_wp * self%impedance())
  end function cb_velocity

  !> Axial stress σ(x, t) [Pa], tension positive (mean of the two sides on a wave front).
  elemental real(wp) function cb_stress(self, x, t) result(s)
    class(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: x                  !! position in [0, L] [m]
    real(wp), intent(in) :: t                  !! time >= 0 [s]
    real(wp) :: ct
    ct = self%wave_speed() * t
    s = 0.5_wp * (extended(self, x - ct, FIELD_S) + extended(self, x + ct, FIELD_S)) &
      + 0.5_wp * self%impedance() &
        * (extended(self, x + ct, FIELD_V) - extended(self, x - ct, FIELD_V))
  end function cb_stress

  !> Initial velocity V(y) extended to the whole line by the end reflections [m/s].
  elemental real(wp) function cb_initial_velocity(self, y)
    class(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: y                  !! any point of the line [m]
    cb_initial_velocity = extended(self, y, FIELD_V)
  end function cb_initial_velocity

  !> Initial stress S(y) extended to the whole line by the end reflections [Pa].
  elemental real(wp) function cb_initial_stress(self, y)
    class(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: y                  !! any point of the line [m]
    cb_initial_stress = extended(self, y, FIELD_S)
  end function cb_initial_stress

  ! ---- private helpers ------------------------------------------------------------------------

  !> Value of the extended field at y: reduce y to [0, L] by the period 2L and the reflection
  !> about L, tracking the sign; then look up the segment (mean of both sides on a jump).
  pure real(wp) function extended(self, y, field) result(f)
    type(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: y                 !! point of the line [m]
    integer, intent(in) :: field              !! FIELD_V or FIELD_S
    real(wp) :: s0, sL, p, z, sgn
    integer(i8) :: k
    s0 = reflection_sign(self%end_bc(1), field)
    sL = reflection_sign(self%end_bc(2), field)
    p = 2.0_wp * self%L
    k = floor(y / p, kind=i8)
    z = min(max(y - real(k, wp) * p, 0.0_wp), p)
    ! f(y + 2L) = s0·sL·f(y): each whole period contributes that factor.
    sgn = 1.0_wp
    if (mod(k, 2_i8) /= 0_i8) sgn = s0 * sL
    if (z > self%L) then
      z = p - z
      sgn = sgn * sL
    end if
    f = sgn * local_value(self, z, field, s0, sL)
  end function extended

  !> Field value at z in [0, L]; on a breakpoint or an end, the mean of the two sides (the side
  !> beyond an end is the reflected value of the first or last segment).
  pure real(wp) function local_value(self, z, field, s0, sL) result(f)
    type(empm_char_bar_t), intent(in) :: self !! bar
    real(wp), intent(in) :: z                 !! point in [0, L] [m]
    integer, intent(in) :: field              !! FIELD_V or FIELD_S
    real(wp), intent(in) :: s0                !! reflection sign at x = 0
    real(wp), intent(in) :: sL                !! reflection sign at x = L
    real(wp) :: left, right
    integer :: i, n
    n = size(self%xb) - 1
    do i = 1, n + 1
      if (abs(z - self%xb(i)) <= self%front_tol) then
        if (i == 1) then
          left = s0 * seg_value(self, 1, field)
        else
          left = seg_value(self, i - 1, field)
        end if
        if (i == n + 1) then
          right = sL * seg_value(self, n, field)
        else
          right = seg_value(self, i, field)
        end if
        f = 0.5_wp * (left + right)
        return
      end if
    end do
    ! Not on a jump: the segment holding z (breakpoints are increasing).
    f = seg_value(self, n, field)
    do i = 1, n
      if (z < self%xb(i + 1)) then
        f = seg_value(self, i, field)
        return
      end if
    end do
  end function local_value

  !> Initial value of `field` on segment i.
  pure real(wp) function seg_value(self, i, field)
    type(empm_char_bar_t), intent(in) :: self !! bar
    integer, intent(in) :: i                  !! segment index
    integer, intent(in) :: field              !! FIELD_V or FIELD_S
    if (field == FIELD_V) then
      seg_value = self%vseg(i)
    else
      seg_value = self%sseg(i)
    end if
  end function seg_value

  !> Sign of the reflection of `field` about an end: a fixed end makes V odd (−1) and S even
  !> (+1), a free end makes V even (+1) and S odd (−1).
  pure real(wp) function reflection_sign(bc, field)
    integer, intent(in) :: bc    !! CHAR_FIXED or CHAR_FREE
    integer, intent(in) :: field !! FIELD_V or FIELD_S
    reflection_sign = 1.0_wp
    if ((bc == CHAR_FIXED) .eqv. (field == FIELD_V)) reflection_sign = -1.0_wp
  end function reflection_sign

  !> CHAR_FIXED for 'fixed', CHAR_FREE for 'free', 0 otherwise.
  pure integer function end_code(name)
    character(len=*), intent(in) :: name !! end condition name
    select case (trim(adjustl(name)))
    case ('fixed')
      end_code = CHAR_FIXED
    case ('free')
      end_code = CHAR_FREE
    case default
      end_code = 0
    end select
  end function end_code

  !> True for a positive finite number (false for NaN).
  pure logical function positive(a)
    real(wp), intent(in) :: a !! value
    positive = a > 0.0_wp .and. a <= huge(a)
  end function positive
end module empm_exact_characteristics
