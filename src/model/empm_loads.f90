!> External loads: gravity (constant or with the paper's sinusoidal ramp, eq. 46), surface
!> tractions on groups of boundary particles, and an optional user body force (used by
!> manufactured solutions); and the geostatic initial stress of a body under gravity.
!>
!> The body force is an object extending [[empm_body_force_t]], so that it can carry its own
!> parameters (no global state); it is evaluated once per step for all particles.
!>
!> A traction ([[empm_traction_t]]) acts on the outer face of each of its particles: the face
!> normal to axis `axis` on side `side` of the particle's domain (half-lengths `lp`). Its force
!> is the traction vector × the face's reference area, the product of the domain's side lengths
!> 2 lp along the other axes (per unit thickness in 2D, 1 in 1D), so that the areas of a layer
!> of particles sum to the area of the body's face. The integrator maps the force to the nodes
!> with the shape functions evaluated where the load acts, on the face: the particle's
!> position moved along the outward normal by its distance to the loaded plane at set-up
!> (`offset`; the face moves with the particle), rather than at the particle.
module empm_loads
  use empm_kinds, only: wp, pi
  use empm_comm, only: empm_comm_t
  implicit none
  private
  public :: empm_loads_t, empm_body_force_t, empm_traction_t, RAMP_NONE, RAMP_SINE, RAMP_LINEAR
  public :: empm_ramp_factor, empm_geostatic_stress

  integer, parameter :: RAMP_NONE = 0   !! constant in time
  integer, parameter :: RAMP_SINE = 1   !! paper eq. (46): sinusoidal rise to t_ramp/2, then constant
  integer, parameter :: RAMP_LINEAR = 2 !! linear rise from 0 at t = 0 to 1 at t_ramp, then constant

  !> A user body force per unit mass, b(X, x, t).
  type, abstract :: empm_body_force_t
  contains
    procedure(body_force_iface), deferred :: eval
  end type empm_body_force_t

  abstract interface
    !> Body force per unit mass at `n` particles (added to gravity).
    subroutine body_force_iface(self, t, x0, x, b)
      import :: empm_body_force_t, wp
      class(empm_body_force_t), intent(in) :: self !! body-force object
      real(wp), intent(in) :: t          !! time [s]
      real(wp), intent(in) :: x0(:,:)    !! reference positions (ndim, n) [m]
      real(wp), intent(in) :: x(:,:)     !! current positions (ndim, n) [m]
      real(wp), intent(out) :: b(:,:)    !! body force per unit mass (ndim, n) [m/s²]
    end subroutine body_force_iface
  end interface

  !> A surface traction on the outer faces of a set of particles (a dead load: its total force
  !> does not follow the deformation). The scratch arrays are sized by the integrator's
  !> `prepare`, so that no step allocates.
  type :: empm_traction_t
    character(len=64) :: name = ''          !! label (messages)
    integer :: axis = 1                     !! axis of the face normal, 1..ndim
    integer :: side = 1                     !! +1: the face on the + side of the particle, −1: −
    real(wp) :: traction(3) = 0.0_wp        !! traction vector at full load [Pa]
    integer :: ramp = RAMP_NONE             !! RAMP_NONE, RAMP_LINEAR or RAMP_SINE
    real(wp) :: t_ramp = 0.0_wp             !! ramp time [s]
    integer, allocatable :: part(:)         !! loaded particles (this process's index; on
                                            !! several processes 0 for another's particle)
    integer, allocatable :: pid(:)          !! their ids (several processes: set when they
                                            !! are first shared out, then kept)
    real(wp), allocatable :: area(:)        !! reference face area of each [m^(ndim−1)]
    real(wp), allocatable :: offset(:)      !! distance from each particle to the loaded face
                                            !! along the outward normal [m] (fixed at set-up)
    real(wp), allocatable :: lam(:,:)       !! shape-function state at each face centre (ndim, n)
    integer, allocatable :: node(:)         !! scratch: support nodes of one face centre
    real(wp), allocatable :: N(:)           !! scratch: shape-function values
    real(wp), allocatable :: dN(:,:)        !! scratch: gradients (ndim, maxn)
  contains
    procedure :: factor => traction_factor
  end type empm_traction_t

  !> Load definition of a model.
  type :: empm_loads_t
    real(wp) :: gravity(3) = 0.0_wp                 !! final gravity vector [m/s²]
    integer :: ramp = RAMP_NONE                     !! RAMP_NONE or RAMP_SINE
    real(wp) :: t_ramp = 0.0_wp                     !! ramp period T of eq. (46) [s]
    class(empm_body_force_t), allocatable :: body_force !! optional user body force
    type(empm_traction_t), allocatable :: tractions(:) !! surface tractions (none: unallocated
                                                       !! or size 0)
  contains
    procedure :: gravity_at => loads_gravity_at
    procedure :: ntraction => loads_ntraction
  end type empm_loads_t

contains

  !> Gravity vector at time `t`: constant, or eq. (46)
  !> g(t) = ½ g (sin(2πt/T − π/2) + 1) for t ≤ T/2 and g afterwards.
  pure function loads_gravity_at(self, t) result(g)
    class(empm_loads_t), intent(in) :: self !! loads
    real(wp), intent(in) :: t               !! time [s]
    real(wp) :: g(3)                        !! gravity [m/s²]
    g = self%gravity
    if (self%ramp == RAMP_SINE) then
      if (t <= 0.5_wp * self%t_ramp) &
        g = 0.5_wp * self%gravity * (sin(2.0_wp * pi * t / self%t_ramp - 0.5_wp * pi) + 1.0_wp)
    end if
  end function loads_gravity_at

  !> Number of tractions.
  pure integer function loads_ntraction(self) result(n)
    class(empm_loads_t), intent(in) :: self !! loads
    n = 0
    if (allocated(self%tractions)) n = size(self%tractions)
  end function loads_ntraction

  !> Fraction of the final value reached at time `t`: 1 (RAMP_NONE); t/T up to T, then 1
  !> (RAMP_LINEAR); ½ (sin(2πt/T − π/2) + 1) up to T/2, then 1 (RAMP_SINE, eq. 46).
  pure function empm_ramp_factor(ramp, t_ramp, t) result(s)
    integer, intent(in) :: ramp     !! RAMP_* kind
    real(wp), intent(in) :: t_ramp  !! ramp time T [s] (> 0 unless RAMP_NONE)
    real(wp), intent(in) :: t       !! time [s]
    real(wp) :: s                   !! factor in [0, 1]
    s = 1.0_wp
    select case (ramp)
    case (RAMP_LINEAR)
      if (t < t_ramp) s = max(t, 0.0_wp) / t_ramp
    case (RAMP_SINE)
      if (t <= 0.5_wp * t_ramp) s = 0.5_wp * (sin(2.0_wp * pi * t / t_ramp - 0.5_wp * pi) + 1.0_wp)
    end select
  end function empm_ramp_factor

  !> Ramp factor of a traction at time `t`.
  pure real(wp) function traction_factor(self, t) result(s)
    class(empm_traction_t), intent(in) :: self !! traction
    real(wp), intent(in) :: t                  !! time [s]
    s = empm_ramp_factor(self%ramp, self%t_ramp, t)
  end function traction_factor

  !> Geostatic stress of one body under gravity `g` (along a grid axis): at each particle
  !> σ_v = −ρ_p |g| (z_top − z_p) on the vertical axis and σ_h = K₀ σ_v on the other normal
  !> components (the out-of-plane σ_zz in 2D too), shears zero (tension positive). z is the
  !> elevation (the coordinate along −g); z_top is the top of the particle's grid column (the
  !> cells sharing its horizontal cell indices): the highest z_q + lp_q of the body's particles
  !> q in that column, i.e. the upper face of the column's highest particle; or, with
  !> `surface`, that elevation for every column (a flat top known exactly, e.g. a box's). `info`
  !> = 1 when g is zero or not along one axis, 2 when the body spans more than 1e8 columns.
  !> With `comm`, the body's particles are those of every process (each passes its own): the
  !> columns and their tops are agreed (collective), as if one process held them all.
  subroutine empm_geostatic_stress(nd, origin, h, x, lp, rho, g, k0, stress, info, surface, &
                                   comm)
    integer, intent(in) :: nd               !! spatial dimension
    real(wp), intent(in) :: origin(:)       !! grid origin (>= nd) [m]
    real(wp), intent(in) :: h(:)            !! grid spacing (>= nd) [m]
    real(wp), intent(in) :: x(:,:)          !! particle positions (nd, n) [m]
    real(wp), intent(in) :: lp(:,:)         !! particle half-lengths (nd, n) [m]
    real(wp), intent(in) :: rho(:)          !! particle densities (n) [kg/m³]
    real(wp), intent(in) :: g(3)            !! gravity [m/s²]
    real(wp), intent(in) :: k0              !! lateral earth pressure coefficient K₀
    real(wp), intent(out) :: stress(:,:)    !! Cauchy stress, Voigt (6, n) [Pa]
    integer, intent(out) :: info            !! 0 ok, 1 bad gravity, 2 too many columns
    real(wp), intent(in), optional :: surface !! elevation of a flat top (along −g) [m]
    type(empm_comm_t), intent(in), optional :: comm !! the processes sharing the body
    integer :: a, up, n, p, d, k, nh, hd(2), lo(2), ext(2)
    logical :: shared
    real(wp) :: gabs, z
    real(wp), allocatable :: top(:)
    info = 0; n = size(x, 2)
    stress(:, 1:n) = 0.0_wp
    if (count(g(1:nd) /= 0.0_wp) /= 1 .or. any(g(nd + 1:3) /= 0.0_wp)) then
      info = 1; return
    end if
    a = findloc(g(1:nd) /= 0.0_wp, .true., dim=1)
    gabs = abs(g(a)); up = -int(sign(1.0_wp, g(a)))
    shared = .false.
    if (present(comm)) shared = comm%parallel()
    if (n == 0 .and. .not. shared) return
    ! Horizontal axes and the index box of the body's columns.
    nh = 0; hd = 0; lo = 0; ext = 1
    do d = 1, nd
      if (d == a) cycle
      nh = nh + 1; hd(nh) = d
    end do
    do k = 1, nh
      d = hd(k)
      lo(k) = minval(floor((x(d, 1:n) - origin(d)) / h(d)))      ! huge(1) when n = 0
      ext(k) = maxval(floor((x(d, 1:n) - origin(d)) / h(d)))     ! −huge(1) when n = 0
      if (shared) then
        lo(k) = comm%min_int(lo(k)); ext(k) = comm%max_int(ext(k))
      end if
      ext(k) = ext(k) - lo(k) + 1
    end do
    if (real(ext(1), wp) * real(ext(2), wp) > 1.0e8_wp) then
      info = 2; return
    end if
    allocate(top(ext(1) * ext(2)))
    top = -huge(1.0_wp)
    if (present(surface)) then
      top = surface
    else
      do p = 1, n
        k = column(p)
        top(k) = max(top(k), up * x(a, p) + lp(a, p))
      end do
      if (shared) call comm%max_reals(top)
    end if
    do p = 1, n
      z = up * x(a, p)
      stress(1:3, p) = k0 * (-rho(p) * gabs * (top(column(p)) - z))
      stress(a, p) = -rho(p) * gabs * (top(column(p)) - z)
    end do
  contains
    pure integer function column(q)
      integer, intent(in) :: q
      integer :: j, c(2)
      c = 0
      do j = 1, nh
        c(j) = floor((x(hd(j), q) - origin(hd(j))) / h(hd(j))) - lo(j)
      end do
      column = 1 + c(1) + ext(1) * c(2)
    end function column
  end subroutine empm_geostatic_stress
end module empm_loads
