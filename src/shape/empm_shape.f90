!> Shape-function extension point: the abstract type every family extends, and the per-particle
!> basis storage it fills.
!>
!> A family implements two deferred procedures: `eval_point` (one point, for tests and for
!> embedding codes) and `eval_batch` (all particles, called once per step so that polymorphic
!> dispatch happens once per batch, not per particle). Adding a family means adding one file
!> that extends [[empm_shape_t]] and one line in [[empm_shape_factory]].
module empm_shape
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  implicit none
  private
  public :: empm_shape_t, empm_basis_t
  public :: SHAPE_OK, SHAPE_OUTSIDE_GRID, SHAPE_SUPPORT_CLIPPED, SHAPE_NOT_CONVERGED, &
            SHAPE_OUTSIDE_HULL, SHAPE_SINGULAR, SHAPE_TOO_MANY_NODES, shape_status_text

  integer, parameter :: SHAPE_OK = 0              !! evaluation succeeded
  integer, parameter :: SHAPE_OUTSIDE_GRID = 1    !! the point lies outside the grid box
  integer, parameter :: SHAPE_SUPPORT_CLIPPED = 2 !! the support needs nodes beyond the grid
  integer, parameter :: SHAPE_NOT_CONVERGED = 3   !! iterative basis did not converge
  integer, parameter :: SHAPE_OUTSIDE_HULL = 4    !! point outside the convex hull of its nodes
  integer, parameter :: SHAPE_SINGULAR = 5        !! singular or ill-conditioned system
  integer, parameter :: SHAPE_TOO_MANY_NODES = 6  !! support larger than the storage provided

  !> Shape-function values and gradients for every particle (contiguous per particle).
  type :: empm_basis_t
    integer :: ndim = 0                     !! spatial dimension
    integer :: maxn = 0                     !! capacity: nodes per particle
    integer :: np = 0                       !! number of particles
    integer, allocatable :: nn(:)           !! nodes in the support of each particle (np)
    integer, allocatable :: node(:,:)       !! node indices (maxn, np)
    real(wp), allocatable :: N(:,:)         !! values N_Ip (maxn, np)
    real(wp), allocatable :: dN(:,:,:)      !! gradients ∇N_Ip (ndim, maxn, np)
  contains
    procedure :: alloc => basis_alloc
  end type empm_basis_t

  !> Abstract shape-function family.
  type, abstract :: empm_shape_t
    integer :: ndim = 0 !! spatial dimension the instance was set up for
  contains
    procedure(max_nodes_iface), deferred :: max_nodes
    procedure(eval_point_iface), deferred :: eval_point
    procedure(eval_batch_iface), deferred :: eval_batch
    procedure(name_iface), deferred :: name
    procedure :: eval_batch_iters => shape_eval_batch_iters
  end type empm_shape_t

  abstract interface
    !> Upper bound on the number of nodes supporting one point.
    pure integer function max_nodes_iface(self, grid)
      import :: empm_shape_t, empm_grid_t
      class(empm_shape_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid   !! background grid
    end function max_nodes_iface

    !> Values and gradients at one point.
    subroutine eval_point_iface(self, grid, x, lp, lam, nn, node, N, dN, info)
      import :: empm_shape_t, empm_grid_t, wp
      class(empm_shape_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid   !! background grid
      real(wp), intent(in) :: x(:)            !! point (ndim)
      real(wp), intent(in) :: lp(:)           !! particle half-lengths (ndim); used by GIMP
      real(wp), intent(inout) :: lam(:)       !! iterative state (LME λ): warm start in, result out
      integer, intent(out) :: nn              !! number of supporting nodes
      integer, intent(out) :: node(:)         !! supporting node indices (>= max_nodes entries)
      real(wp), intent(out) :: N(:)           !! values
      real(wp), intent(out) :: dN(:,:)        !! gradients (ndim, :)
      integer, intent(out) :: info            !! SHAPE_OK or a SHAPE_* failure code
    end subroutine eval_point_iface

    !> Values and gradients at every particle; on failure `ibad` is the first bad particle.
    subroutine eval_batch_iface(self, grid, pts, basis, ibad, info)
      import :: empm_shape_t, empm_grid_t, empm_particles_t, empm_basis_t
      class(empm_shape_t), intent(in) :: self      !! shape family
      type(empm_grid_t), intent(in) :: grid        !! background grid
      type(empm_particles_t), intent(inout) :: pts !! particles (λ may be updated)
      type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
      integer, intent(out) :: ibad                 !! first failing particle, 0 if none
      integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    end subroutine eval_batch_iface

    !> Short identifier, e.g. "linear", "ugimp", "bspline3", "lme_g3".
    function name_iface(self) result(s)
      import :: empm_shape_t
      class(empm_shape_t), intent(in) :: self   !! shape family
      character(len=:), allocatable :: s        !! identifier
    end function name_iface
  end interface

contains

  !> `eval_batch` that also returns the iterations spent (summed over the particles); the
  !> default is for direct (non-iterative) families: no iterations. Iterative families (LME)
  !> override it.
  subroutine shape_eval_batch_iters(self, grid, pts, basis, ibad, info, iters)
    class(empm_shape_t), intent(in) :: self      !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer, intent(out) :: iters                !! iterations summed over the particles
    call self%eval_batch(grid, pts, basis, ibad, info)
    iters = 0
  end subroutine shape_eval_batch_iters

  !> Allocate basis storage for `np` particles with up to `maxn` nodes each.
  subroutine basis_alloc(self, ndim, maxn, np)
    class(empm_basis_t), intent(inout) :: self !! basis storage
    integer, intent(in) :: ndim                !! spatial dimension
    integer, intent(in) :: maxn                !! nodes per particle (capacity)
    integer, intent(in) :: np                  !! number of particles
    if (allocated(self%nn)) deallocate(self%nn, self%node, self%N, self%dN)
    self%ndim = ndim; self%maxn = maxn; self%np = np
    allocate(self%nn(np), self%node(maxn, np), self%N(maxn, np), self%dN(ndim, maxn, np))
    self%nn = 0; self%node = 1; self%N = 0.0_wp; self%dN = 0.0_wp
  end subroutine basis_alloc

  !> Human-readable text for a SHAPE_* status code.
  pure function shape_status_text(info) result(s)
    integer, intent(in) :: info             !! status code
    character(len=:), allocatable :: s      !! description
    select case (info)
    case (SHAPE_OK);              s = 'ok'
    case (SHAPE_OUTSIDE_GRID);    s = 'point outside the grid'
    case (SHAPE_SUPPORT_CLIPPED); s = 'support needs nodes beyond the grid (add padding cells)'
    case (SHAPE_NOT_CONVERGED);   s = 'basis iteration did not converge'
    case (SHAPE_OUTSIDE_HULL);    s = 'point outside the convex hull of its support nodes'
    case (SHAPE_SINGULAR);        s = 'singular or ill-conditioned system'
    case (SHAPE_TOO_MANY_NODES);  s = 'support larger than the storage provided'
    case default;                 s = 'unknown shape-function status'
    end select
  end function shape_status_text
end module empm_shape
