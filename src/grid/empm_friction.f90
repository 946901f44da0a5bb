!> Coulomb friction on rigid walls at rest (`&boundary friction_angle`): the nodes of a wall have
!> their normal velocity component fixed at zero, and their tangential components are free but
!> get the wall's friction, which reaches the particles through the nodal force (a FLIP update
!> carries the particle's own velocity, so a fixed tangential dof would not stop a particle
!> sliding alone along a rough base; docs/benchmarks.md, granular column collapse).
!>
!> Per wall node, with n̂ the wall's normal into the body, the normal load the wall carries
!> N = max(0, −f·n̂) (f the total nodal force before the normal dof is zeroed), and the
!> tangential velocity the node would reach with the force alone, q = v_t + h f_t/m, the
!> friction force f_μ = −min(μ N, m|q|/h) q/|q|: it stops the node when μN suffices
!> (sticking: the node's tangential velocity is then zero after the step) and otherwise
!> opposes the slip with μN. `h` is the time over which the integrator adds f/m to the nodal
!> velocity `v` (Δt; the predictor-corrector passes Δt too, see its `walls`).
!> This is the rigid-wall case of Bardenhagen et al.'s (2001) frictional contact.
module empm_friction
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_friction_t, empm_wall_problem

  !> The frictional wall nodes of a model (few: a boundary's worth).
  type :: empm_friction_t
    integer :: n = 0                      !! number of wall nodes
    integer, allocatable :: node(:)       !! their node ids (n)
    integer, allocatable :: axis(:)       !! the wall's normal axis (n)
    real(wp), allocatable :: sgn(:)       !! +1 when the body lies on the +axis side (n)
    real(wp), allocatable :: mu(:)        !! friction coefficient tan δ (n)
    integer, allocatable :: set(:)        !! reaction set the node belongs to, 0 for none (n)
    real(wp), allocatable :: kept(:,:)    !! the tangential forces last applied (ndim, n) [N]
  contains
    procedure :: init => friction_init
    procedure :: add => friction_add
    procedure :: has => friction_has
    procedure :: apply => friction_apply
    procedure :: restore => friction_restore
  end type empm_friction_t

contains

  !> No wall.
  subroutine friction_init(self, ndim)
    class(empm_friction_t), intent(inout) :: self !! walls
    integer, intent(in) :: ndim                   !! spatial dimension
    self%n = 0
    if (allocated(self%node)) deallocate(self%node, self%axis, self%sgn, self%mu, self%set, &
                                         self%kept)
    allocate(self%node(0), self%axis(0), self%sgn(0), self%mu(0), self%set(0), self%kept(ndim, 0))
  end subroutine friction_init

  !> Append the nodes `ids` of one wall (set-up only).
  subroutine friction_add(self, ids, axis, sgn, mu, set)
    class(empm_friction_t), intent(inout) :: self !! walls
    integer, intent(in) :: ids(:)                 !! node ids
    integer, intent(in) :: axis                   !! normal axis
    real(wp), intent(in) :: sgn                   !! +1: the body on the +axis side; −1: on −
    real(wp), intent(in) :: mu                    !! friction coefficient (≥ 0)
    integer, intent(in) :: set                    !! reaction set, 0 for none
    real(wp), allocatable :: k(:,:)
    integer :: m
    m = size(ids)
    self%node = [self%node, ids]; self%axis = [self%axis, spread(axis, 1, m)]
    self%sgn = [self%sgn, spread(sgn, 1, m)]; self%mu = [self%mu, spread(mu, 1, m)]
    self%set = [self%set, spread(set, 1, m)]
    self%n = self%n + m
    allocate(k(size(self%kept, 1), self%n)); k = 0.0_wp
    call move_alloc(k, self%kept)
  end subroutine friction_add

  !> What a wall's set-up status `info` of [[nodes_friction_box]] means ('' for 0).
  pure function empm_wall_problem(info, axis) result(text)
    integer, intent(in) :: info           !! 0..3
    integer, intent(in) :: axis           !! the normal's axis, 1..3
    character(len=:), allocatable :: text !! the problem
    select case (info)
    case (1); text = 'a frictional wall''s box must be flat along '//'xyz'(axis:axis)//' (lo = hi there)'
    case (2); text = 'the box [lo, hi] selects no grid node (nodes lie at origin + i*h)'
    case (3); text = 'a node of the box is on another frictional wall'
    case default; text = ''
    end select
  end function empm_wall_problem

  !> Whether node `id` is already a wall node.
  pure logical function friction_has(self, id)
    class(empm_friction_t), intent(in) :: self !! walls
    integer, intent(in) :: id                  !! node id
    friction_has = any(self%node(1:self%n) == id)
  end function friction_has

  !> Add the friction forces to `f` (module header) and their sum per reaction set to
  !> `reaction` (the force the wall exerts on the body). Tangential dofs fixed by another
  !> boundary (`fixed`) are left alone; nodes without mass carry no friction. With `mask`,
  !> only the nodes it marks add to `reaction` (a parallel run's owned nodes).
  pure subroutine friction_apply(self, mass, fixed, v, h, f, reaction, mask)
    class(empm_friction_t), intent(inout) :: self   !! walls (kept is set)
    real(wp), intent(in) :: mass(:)                 !! nodal masses (nnode) [kg]
    logical, intent(in) :: fixed(:,:)               !! Dirichlet mask (ndim, nnode)
    real(wp), intent(in) :: v(:,:)                  !! nodal velocities of the step (ndim, nnode)
    real(wp), intent(in) :: h                       !! time over which f/m is added to v [s]
    real(wp), intent(inout) :: f(:,:)               !! total nodal force (ndim, nnode) [N]
    real(wp), intent(inout) :: reaction(:,:)        !! reaction per set (ndim, nset) [N]
    logical, intent(in), optional :: mask(:)        !! nodes whose friction the reaction counts
    real(wp) :: q(3), fmu(3), qn, cap, load
    integer :: k, id, a, d, nd
    logical :: t(3)
    nd = size(f, 1)
    do k = 1, self%n
      id = self%node(k); a = self%axis(k)
      t = .false.
      do d = 1, nd
        t(d) = d /= a .and. .not. fixed(d, id)
      end do
      fmu = 0.0_wp
      if (mass(id) > 0.0_wp) then
        load = max(0.0_wp, -self%sgn(k) * f(a, id))
        q = 0.0_wp
        do d = 1, nd
          if (t(d)) q(d) = v(d, id) + h * f(d, id) / mass(id)
        end do
        qn = norm2(q(1:nd))
        if (qn > 0.0_wp) then
          cap = self%mu(k) * load
          if (h > 0.0_wp) cap = min(cap, mass(id) * qn / h)
          fmu(1:nd) = -cap * q(1:nd) / qn
        end if
      end if
      do d = 1, nd
        if (.not. t(d)) cycle
        f(d, id) = f(d, id) + fmu(d)
        self%kept(d, k) = f(d, id)
      end do
      if (self%set(k) == 0) cycle
      if (present(mask)) then
        if (.not. mask(id)) cycle
      end if
      reaction(1:nd, self%set(k)) = reaction(1:nd, self%set(k)) + fmu(1:nd)
    end do
  end subroutine friction_apply

  !> Put back the tangential wall forces last applied (after a pass such as the local damping
  !> changed every dof: the friction already balances the wall's nodes).
  pure subroutine friction_restore(self, fixed, f)
    class(empm_friction_t), intent(in) :: self      !! walls
    logical, intent(in) :: fixed(:,:)               !! Dirichlet mask (ndim, nnode)
    real(wp), intent(inout) :: f(:,:)               !! total nodal force (ndim, nnode) [N]
    integer :: k, d, id
    do k = 1, self%n
      id = self%node(k)
      do d = 1, size(f, 1)
        if (d /= self%axis(k) .and. .not. fixed(d, id)) f(d, id) = self%kept(d, k)
      end do
    end do
  end subroutine friction_restore
end module empm_friction
