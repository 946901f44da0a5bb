!> Exact small-strain solutions of the self-weight column (docs/algorithms §3, Andersen block).
!>
!> Uniaxial strain, height H, density ρ, modulus E (the constrained modulus λ + 2μ; = E for
!> ν = 0), wave speed c = sqrt(E/ρ); y from the fixed base (u(0) = 0) up to the top y = H, which
!> carries the traction p0 (tension positive; 0 for the Andersen block); gravity g acts in −y.
!> Displacement u is positive upward, stress σ = E ∂u/∂y is tension positive. The loads are
!> scaled by a load factor φ(t): a step (φ = 1 for t >= 0) or the paper's ramp, eq. (46),
!> φ = ½(1 − cos Ωt) for t <= T/2 and 1 afterwards, Ω = 2π/T. Before t = 0 everything is zero.
!>
!> **Static solution** (E u'' = ρg, u(0) = 0, E u'(H) = p0), α = ρg/E:
!>   u_s(y) = α y²/2 + (p0/E − αH) y = −(ρg/E)(Hy − y²/2) + p0 y/E,
!>   σ_s(y) = −ρg(H − y) + p0; top settlement −u_s(H) = ρgH²/(2E) − p0H/E.
!>
!> **Modes** of the fixed–free column: sin(k_n y), k_n = (2n−1)π/(2H), ω_n = c k_n; the first
!> period is 2π/ω_1 = 4H/c. Expand u = Σ q_n(t) sin(k_n y). The static solution has the modal
!> coefficients (with s_n ≡ sin(k_n H) = (−1)^(n+1), ∫₀ᴴ y sin(ky) dy = s_n/k² and
!> ∫₀ᴴ y² sin(ky) dy = 2H s_n/k² − 2/k³)
!>   c_n = (2/H)∫₀ᴴ u_s sin(k_n y) dy = −2α/(H k_n³) + 2 s_n p0/(E H k_n²),
!> and each mode obeys q̈_n + ω_n² q_n = ω_n² c_n φ(t), q_n(0) = q̇_n(0) = 0 (start at rest).
!> Write q_n = φ c_n + d_n, so that u = φ(t) u_s(y) + Σ d_n(t) sin(k_n y): the static part is
!> summed in closed form and only the dynamic remainder d_n is a series.
!>
!> **Step** (φ = 1): d_n = −c_n cos(ω_n t), i.e. u = u_s + Σ a_n cos(ω_n t) sin(k_n y) with
!> a_n = −c_n = 2ρg/(E H k_n³) − 2 s_n p0/(E H k_n²) (u(y,0) = 0 by construction).
!>
!> **Ramp**, closed form of the Duhamel integral. For t <= T/2 (particular solution of the
!> constant and of the cos Ωt forcing, plus the free vibration that starts the mode at rest):
!>   q_n/c_n = ½(1 − cos ωt) − ½ R (cos Ωt − cos ωt),  R = ω²/(ω² − Ω²),
!>   d_n = −½ c_n Ω² D(t),  D(t) = (cos Ωt − cos ωt)/(ω² − Ω²),
!> evaluated without cancellation (and through resonance ω = Ω) as
!>   D = t sin(σt) sinc(δt)/(2σ),  D' = sin(ωt)/(2σ) + Ω t cos(σt) sinc(δt)/(2σ),
!> σ = (ω+Ω)/2, δ = (ω−Ω)/2. For t > T/2 (φ = 1, φ' = 0, both continuous at T/2) the mode
!> vibrates freely about c_n: d_n = d_n(T/2) cos ωτ + ḋ_n(T/2)/ω sin ωτ, τ = t − T/2, with
!> amplitude |c_n| Ω²/|ω² − Ω²| · |cos(ωT/4)|.
!>
!> **Truncation.** The series is cut after `nterms` modes. For the step load |d_n| = |c_n| and
!>   Σ_{n>N} |c_n| <= 4αH²/(π³(2N−1)²) + 4|p0|H/(π²E(2N−1))
!> (from Σ_{n>N} (2n−1)^(−m) <= ∫_N^∞ (2x−1)^(−m) dx), a bound on the displacement error
!> ([[empm_column_t(type):truncation_bound]]); for the ramp |d_n| <= |c_n| Ω²/|ω_n² − Ω²|, so the
!> same bound holds when ω_{N+1}² >= 2Ω² (always for any useful N). The velocity and stress
!> series converge one order slower (terms ~ k_n^(−2) for p0 = 0).
module empm_exact_column
  use empm_kinds, only: wp, pi
  implicit none
  private
  public :: empm_column_t, empm_andersen_column, COLUMN_STEP, COLUMN_RAMP

  integer, parameter :: COLUMN_STEP = 0 !! loads applied suddenly at t = 0
  integer, parameter :: COLUMN_RAMP = 1 !! loads ramped by the paper's eq. (46) over t_ramp

  !> Self-weight column, small strain (defaults: the Andersen block's data, step load).
  type :: empm_column_t
    real(wp) :: H = 10.0_wp         !! height [m]
    real(wp) :: rho = 6000.0_wp     !! density [kg/m³]
    real(wp) :: E = 5.0e6_wp        !! constrained (uniaxial-strain) modulus [Pa]
    real(wp) :: g = 9.81_wp         !! gravity magnitude, acting in −y [m/s²]
    real(wp) :: p0 = 0.0_wp         !! top traction, tension positive [Pa]
    integer :: load = COLUMN_STEP   !! COLUMN_STEP or COLUMN_RAMP
    real(wp) :: t_ramp = 20.0_wp    !! ramp period T of eq. (46) (COLUMN_RAMP) [s]
    integer :: nterms = 200         !! number of modes summed
  contains
    procedure :: wave_speed => col_wave_speed
    procedure :: period => col_period
    procedure :: settlement => col_settlement
    procedure :: static_displacement => col_static_displacement
    procedure :: static_stress => col_static_stress
    procedure :: wavenumber => col_wavenumber
    procedure :: omega => col_omega
    procedure :: static_coefficient => col_static_coefficient
    procedure :: load_factor => col_load_factor
    procedure :: load_rate => col_load_rate
    procedure :: modal_amplitude => col_modal_amplitude
    procedure :: modal_velocity => col_modal_velocity
    procedure :: displacement => col_displacement
    procedure :: velocity => col_velocity
    procedure :: stress => col_stress
    procedure :: truncation_bound => col_truncation_bound
  end type empm_column_t

contains

  !> The Andersen block of the paper's section 6.2 as a column: H = 10 m, ρ = 6000 kg/m³,
  !> E = 5 MPa (ν = 0), g = 9.81 m/s², gravity ramped by eq. (46) over T = 20 s.
  pure function empm_andersen_column() result(col)
    type(empm_column_t) :: col !! the column
    col%load = COLUMN_RAMP
    col%t_ramp = 20.0_wp
  end function empm_andersen_column

  !> Wave speed c = sqrt(E/ρ) [m/s].
  elemental real(wp) function col_wave_speed(self)
    class(empm_column_t), intent(in) :: self !! column
    col_wave_speed = sqrt(self%E / self%rho)
  end function col_wave_speed

  !> First-mode period 4H/c [s].
  elemental real(wp) function col_period(self)
    class(empm_column_t), intent(in) :: self !! column
    col_period = 4.0_wp * self%H / self%wave_speed()
  end function col_period

  !> Static top settlement −u_s(H) = ρgH²/(2E) − p0 H/E [m] (positive downward).
  elemental real(wp) function col_settlement(self)
    class(empm_column_t), intent(in) :: self !! column
    col_settlement = -self%static_displacement(self%H)
  end function col_settlement

  !> Static displacement u_s(y) = −(ρg/E)(Hy − y²/2) + p0 y/E [m] (upward positive).
  elemental real(wp) function col_static_displacement(self, y)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: y                !! height above the base, in [0, H] [m]
    col_static_displacement = -(self%rho * self%g / self%E) * (self%H * y - 0.5_wp * y**2) &
                              + self%p0 * y / self%E
  end function col_static_displacement

  !> Static stress σ_s(y) = −ρg(H − y) + p0 [Pa] (tension positive).
  elemental real(wp) function col_static_stress(self, y)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: y                !! height above the base, in [0, H] [m]
    col_static_stress = -self%rho * self%g * (self%H - y) + self%p0
  end function col_static_stress

  !> Wavenumber k_n = (2n−1)π/(2H) of mode n [1/m].
  elemental real(wp) function col_wavenumber(self, n)
    class(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                 !! mode number, >= 1
    col_wavenumber = real(2 * n - 1, wp) * pi / (2.0_wp * self%H)
  end function col_wavenumber

  !> Angular frequency ω_n = c k_n of mode n [rad/s].
  elemental real(wp) function col_omega(self, n)
    class(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                 !! mode number, >= 1
    col_omega = self%wave_speed() * self%wavenumber(n)
  end function col_omega

  !> Modal coefficient c_n = (2/H)∫u_s sin(k_n y)dy = −2ρg/(E H k_n³) + 2(−1)^(n+1) p0/(E H k_n²)
  !> of the static solution [m].
  elemental real(wp) function col_static_coefficient(self, n)
    class(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                 !! mode number, >= 1
    real(wp) :: k, sn
    k = self%wavenumber(n)
    sn = 1.0_wp
    if (mod(n, 2) == 0) sn = -1.0_wp
    col_static_coefficient = -2.0_wp * self%rho * self%g / (self%E * self%H * k**3) &
                             + 2.0_wp * sn * self%p0 / (self%E * self%H * k**2)
  end function col_static_coefficient

  !> Load factor φ(t): 0 before t = 0; step: 1; ramp: ½(1 − cos(2πt/T)) up to T/2, then 1.
  elemental real(wp) function col_load_factor(self, t)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: t                !! time [s]
    if (t < 0.0_wp) then
      col_load_factor = 0.0_wp
    else if (self%load == COLUMN_RAMP .and. t <= 0.5_wp * self%t_ramp) then
      col_load_factor = 0.5_wp * (1.0_wp - cos(2.0_wp * pi * t / self%t_ramp))
    else
      col_load_factor = 1.0_wp
    end if
  end function col_load_factor

  !> Rate dφ/dt [1/s]: ½Ω sin(Ωt) during the ramp, 0 otherwise (the step's impulse excluded).
  elemental real(wp) function col_load_rate(self, t)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: om
    col_load_rate = 0.0_wp
    if (self%load == COLUMN_RAMP .and. t > 0.0_wp .and. t <= 0.5_wp * self%t_ramp) then
      om = 2.0_wp * pi / self%t_ramp
      col_load_rate = 0.5_wp * om * sin(om * t)
    end if
  end function col_load_rate

  !> Modal coordinate q_n(t) = φ(t) c_n + d_n(t) of mode n [m] (u = Σ q_n sin(k_n y)).
  elemental real(wp) function col_modal_amplitude(self, n, t)
    class(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                 !! mode number, >= 1
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: d, dd
    call dynamic_part(self, n, t, d, dd)
    col_modal_amplitude = self%load_factor(t) * self%static_coefficient(n) + d
  end function col_modal_amplitude

  !> Modal velocity q̇_n(t) of mode n [m/s].
  elemental real(wp) function col_modal_velocity(self, n, t)
    class(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                 !! mode number, >= 1
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: d, dd
    call dynamic_part(self, n, t, d, dd)
    col_modal_velocity = self%load_rate(t) * self%static_coefficient(n) + dd
  end function col_modal_velocity

  !> Displacement u(y,t) = φ u_s(y) + Σ_{n<=nterms} d_n(t) sin(k_n y) [m] (upward positive).
  elemental real(wp) function col_displacement(self, y, t) result(u)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: y                !! height above the base, in [0, H] [m]
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: d, dd
    integer :: n
    u = self%load_factor(t) * self%static_displacement(y)
    do n = 1, self%nterms
      call dynamic_part(self, n, t, d, dd)
      u = u + d * sin(self%wavenumber(n) * y)
    end do
  end function col_displacement

  !> Velocity ∂u/∂t(y,t) = φ' u_s(y) + Σ ḋ_n(t) sin(k_n y) [m/s].
  elemental real(wp) function col_velocity(self, y, t) result(v)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: y                !! height above the base, in [0, H] [m]
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: d, dd
    integer :: n
    v = self%load_rate(t) * self%static_displacement(y)
    do n = 1, self%nterms
      call dynamic_part(self, n, t, d, dd)
      v = v + dd * sin(self%wavenumber(n) * y)
    end do
  end function col_velocity

  !> Stress σ(y,t) = E ∂u/∂y = φ σ_s(y) + E Σ d_n(t) k_n cos(k_n y) [Pa] (tension positive).
  elemental real(wp) function col_stress(self, y, t) result(s)
    class(empm_column_t), intent(in) :: self !! column
    real(wp), intent(in) :: y                !! height above the base, in [0, H] [m]
    real(wp), intent(in) :: t                !! time [s]
    real(wp) :: d, dd, k
    integer :: n
    s = self%load_factor(t) * self%static_stress(y)
    do n = 1, self%nterms
      call dynamic_part(self, n, t, d, dd)
      k = self%wavenumber(n)
      s = s + self%E * d * k * cos(k * y)
    end do
  end function col_stress

  !> Bound on the displacement truncation error, Σ_{n>N}|c_n| <= 4αH²/(π³(2N−1)²)
  !> + 4|p0|H/(π²E(2N−1)), α = ρg/E, N = nterms [m] (see the module notes for the ramp).
  elemental real(wp) function col_truncation_bound(self)
    class(empm_column_t), intent(in) :: self !! column
    real(wp) :: m
    m = real(2 * max(self%nterms, 1) - 1, wp)
    col_truncation_bound = 4.0_wp * self%rho * self%g * self%H**2 / (pi**3 * self%E * m**2) &
                           + 4.0_wp * abs(self%p0) * self%H / (pi**2 * self%E * m)
  end function col_truncation_bound

  ! ---- private helpers ------------------------------------------------------------------------

  !> Dynamic remainder d_n(t) = q_n − φ c_n of mode n and its rate (module notes).
  elemental subroutine dynamic_part(self, n, t, d, dd)
    type(empm_column_t), intent(in) :: self !! column
    integer, intent(in) :: n                !! mode number
    real(wp), intent(in) :: t               !! time [s]
    real(wp), intent(out) :: d              !! d_n(t) [m]
    real(wp), intent(out) :: dd             !! ḋ_n(t) [m/s]
    real(wp) :: w, om, cn, th, dh, ddh, tau
    d = 0.0_wp
    dd = 0.0_wp
    if (t < 0.0_wp) return
    w = self%omega(n)
    cn = self%static_coefficient(n)
    if (self%load == COLUMN_RAMP) then
      om = 2.0_wp * pi / self%t_ramp
      th = 0.5_wp * self%t_ramp
      if (t <= th) then
        call ramp_part(w, om, cn, t, d, dd)
      else
        ! Free vibration about the static state from the state reached at T/2.
        call ramp_part(w, om, cn, th, dh, ddh)
        tau = t - th
        d = dh * cos(w * tau) + (ddh / w) * sin(w * tau)
        dd = -dh * w * sin(w * tau) + ddh * cos(w * tau)
      end if
    else
      d = -cn * cos(w * t)
      dd = cn * w * sin(w * t)
    end if
  end subroutine dynamic_part

  !> d = −½ c Ω² D(t) and its rate during the ramp, D = (cos Ωt − cos ωt)/(ω² − Ω²) written as
  !> products with sinc so that it stays accurate near and at resonance (module notes).
  elemental subroutine ramp_part(w, om, cn, t, d, dd)
    real(wp), intent(in) :: w   !! modal frequency ω [rad/s]
    real(wp), intent(in) :: om  !! ramp frequency Ω = 2π/T [rad/s]
    real(wp), intent(in) :: cn  !! static modal coefficient c_n [m]
    real(wp), intent(in) :: t   !! time in [0, T/2] [s]
    real(wp), intent(out) :: d  !! d_n(t) [m]
    real(wp), intent(out) :: dd !! ḋ_n(t) [m/s]
    real(wp) :: sg, dl, sc, dfun, dprime
    sg = 0.5_wp * (w + om)
    dl = 0.5_wp * (w - om)
    sc = sinc(dl * t)
    dfun = t * sin(sg * t) * sc / (2.0_wp * sg)
    dprime = sin(w * t) / (2.0_wp * sg) + om * t * cos(sg * t) * sc / (2.0_wp * sg)
    d = -0.5_wp * cn * om**2 * dfun
    dd = -0.5_wp * cn * om**2 * dprime
  end subroutine ramp_part

  !> sin(x)/x, 1 at x = 0 (series below 1e-4, where its error is below 1e-17).
  elemental real(wp) function sinc(x)
    real(wp), intent(in) :: x !! argument
    if (abs(x) < 1.0e-4_wp) then
      sinc = 1.0_wp - x**2 / 6.0_wp
    else
      sinc = sin(x) / x
    end if
  end function sinc
end module empm_exact_column
