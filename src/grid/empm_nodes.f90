!> Nodal (grid) fields, rebuilt from the particles every step, and the Dirichlet constraints.
module empm_nodes
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise_error, empm_alloc_error
  use empm_strings, only: str
  use empm_grid, only: empm_grid_t
  use empm_extension, only: empm_extension_t
  use empm_friction, only: empm_friction_t
  implicit none
  private
  public :: empm_nodes_t

  ! The constraints in the whole grid's numbering, kept from set-up when a parallel run's nodal
  ! storage first becomes a window ([[nodes_window]]): a boundary's worth of entries, from
  ! which every later window takes its own.
  type :: node_catalogue_t
    logical :: made = .false.
    integer, allocatable :: fix(:)         ! fixed dofs, positions d + ndim (G − 1), increasing
    real(wp), allocatable :: vfix(:)       ! their prescribed velocities [m/s]
    integer, allocatable :: set_ptr(:)     ! reaction sets: first dof of each in set_dof
    integer, allocatable :: set_dof(:)     ! their dofs, as in fix
    integer, allocatable :: ghost(:)       ! mirror ghosts (whole-grid ids)
    integer, allocatable :: image(:)       ! their images
    real(wp), allocatable :: msign(:,:)    ! their component signs (ndim, pairs)
    type(empm_friction_t) :: fric          ! frictional wall nodes (whole-grid ids)
  end type node_catalogue_t

  !> Nodal fields (structure of arrays, node index last).
  type :: empm_nodes_t
    integer :: ndim = 0                     !! spatial dimension
    integer :: nnode = 0                    !! number of nodes
    real(wp) :: mass_tol = 0.0_wp           !! nodes lighter than this are treated as empty [kg]
    real(wp), allocatable :: mass(:)        !! lumped mass m_I (nnode) [kg]
    real(wp), allocatable :: mom(:,:)       !! momentum p_I (ndim, nnode) [kg m/s]
    real(wp), allocatable :: vel(:,:)       !! velocity v_I (ndim, nnode) [m/s]
    real(wp), allocatable :: force(:,:)     !! total force f_I (ndim, nnode) [N]
    real(wp), allocatable :: acc(:,:)       !! acceleration a_I = f_I/m_I (ndim, nnode) [m/s²]
    real(wp), allocatable :: work(:,:)      !! scratch nodal vector (ndim, nnode)
    real(wp), allocatable :: vol(:)         !! filled volume Σ N_Ip V_p (nnode) [m^ndim], for
                                            !! the extension of nearly-empty nodes
    type(empm_extension_t) :: ext           !! nearly-empty nodes of the current basis
    type(empm_friction_t) :: fric           !! frictional walls (`&boundary friction_angle`)
    ! Mirror planes (`&boundary mirror`): ghost node ghost(k) takes msign(d, k) times the value
    ! of its image image(k) across the plane; its mass and numerators are gathered into the
    ! image (docs/free-surfaces.md, "Mirror planes").
    integer :: nmirror = 0                          !! ghost/image pairs
    integer, allocatable :: ghost(:)                !! ghost nodes (nmirror)
    integer, allocatable :: image(:)                !! their images (nmirror)
    real(wp), allocatable :: msign(:,:)             !! −1 (odd) or +1 (even) per component
                                                    !! (ndim, nmirror)
    logical, allocatable :: mirrored(:)             !! node is a ghost's image (nnode)
    integer :: nplane = 0                           !! mirror planes
    integer, allocatable :: plane_side(:)           !! ±axis of each plane's ghost side
    real(wp), allocatable :: plane_at(:)            !! its coordinate [m]
    ! The constraints are private: `fixed_dofs` must follow `fixed`, so they change only
    ! through fix_box/fix_dof, and are read through is_fixed/fixed_velocity/nfixed.
    logical, allocatable, private :: fixed(:,:)     !! Dirichlet mask per dof (ndim, nnode)
    real(wp), allocatable, private :: vfix(:,:)     !! prescribed velocity (ndim, nnode) [m/s]
    integer, allocatable, private :: fixed_dofs(:)  !! the fixed dofs as positions
                                                    !! d + ndim (I − 1), increasing
    ! Named node sets whose reaction is recorded (`&boundary name`): set s owns the dofs
    ! set_dof(set_ptr(s):set_ptr(s+1)−1), those its box fixed when it was declared.
    integer :: nset = 0                             !! number of reaction sets
    character(len=64), allocatable :: set_name(:)   !! their names (nset)
    integer, allocatable :: set_ptr(:)              !! first dof of each set in set_dof (nset+1)
    integer, allocatable :: set_dof(:)              !! dofs of the sets, as in fixed_dofs
    logical, allocatable :: set_fix(:,:)            !! components each set prescribes (ndim, nset)
    real(wp), allocatable :: set_vel(:,:)           !! their prescribed velocity (ndim, nset) [m/s]
    real(wp), allocatable :: reaction(:,:)          !! reaction force of each set from the last
                                                    !! assembly (ndim, nset) [N], see
                                                    !! [[nodes_compute_reactions]]
    type(node_catalogue_t), private :: cat          !! set-up's constraints in whole-grid
                                                    !! numbering (windows only)
    logical, private :: sparse = .false.            !! a parallel run's set-up: the fixed dofs
                                                    !! kept in the catalogue only, no array
                                                    !! of the whole grid's nodes
  contains
    procedure :: alloc => nodes_alloc
    procedure :: reset => nodes_reset
    procedure :: fix_box => nodes_fix_box
    procedure :: fix_dof => nodes_fix_dof
    procedure :: is_fixed => nodes_is_fixed
    procedure :: fixed_velocity => nodes_fixed_velocity
    procedure :: nfixed => nodes_nfixed
    procedure :: constrain_velocity => nodes_constrain_velocity
    procedure :: constrain_force => nodes_constrain_force
    procedure :: compute_reactions => nodes_compute_reactions
    procedure :: friction_box => nodes_friction_box
    procedure :: apply_friction => nodes_apply_friction
    procedure :: restore_friction => nodes_restore_friction
    procedure :: local_damping => nodes_local_damping
    procedure :: find_degenerate => nodes_find_degenerate
    procedure :: mirror_box => nodes_mirror_box
    procedure :: mirror_gather_mass => nodes_mirror_gather_mass
    procedure :: mirror_gather_even => nodes_mirror_gather_even
    procedure :: mirror_correct => nodes_mirror_correct
    procedure :: mirror_scatter => nodes_mirror_scatter
    procedure :: window => nodes_window
    procedure, private :: list_fixed => nodes_list_fixed
  end type empm_nodes_t

contains

  !> Move the nodal storage from grid `old` to its window `new` (a parallel process's
  !> block-local storage, docs/parallel.md): the fields keep their values on the nodes both
  !> hold and are zero on the others; the fixed dofs, mirror pairs (both nodes in the window),
  !> frictional wall nodes and reaction sets are set-up's, on the window's nodes. The first
  !> call must start from the whole grid: it keeps set-up's constraints in the whole grid's
  !> numbering. The nearly-empty nodes are found again at the next basis evaluation.
  subroutine nodes_window(self, old, new)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields (on `old`)
    type(empm_grid_t), intent(in) :: old       !! the grid the storage is on
    type(empm_grid_t), intent(in) :: new       !! a window of the same whole grid
    type(empm_grid_t) :: whole
    integer, allocatable :: from(:), dofs(:), gh(:), im(:), keep(:)
    integer :: n, nd, I, k, s, j, L
    if (.not. self%cat%made) call make_catalogue(self, old)
    whole = new%whole()
    n = new%nnode; nd = self%ndim
    allocate(from(n))
    do I = 1, n
      from(I) = old%node_id(new%node_ijk(I))
    end do
    call move1(self%mass); call move1(self%vol)
    call move2(self%mom); call move2(self%vel); call move2(self%force); call move2(self%acc)
    call move2(self%work)
    self%nnode = n
    deallocate(self%fixed, self%vfix, self%mirrored)
    self%sparse = .false.
    allocate(self%fixed(nd, n), self%vfix(nd, n), self%mirrored(n))
    self%fixed = .false.; self%vfix = 0.0_wp; self%mirrored = .false.
    do k = 1, size(self%cat%fix)
      j = local_dof(self%cat%fix(k))
      if (j == 0) cycle
      self%fixed(mod(j - 1, nd) + 1, (j - 1) / nd + 1) = .true.
      self%vfix(mod(j - 1, nd) + 1, (j - 1) / nd + 1) = self%cat%vfix(k)
    end do
    call self%list_fixed()
    ! Reaction sets: their dofs in the window, in the same order.
    allocate(dofs(size(self%cat%set_dof)))
    j = 0
    do s = 1, self%nset
      do k = self%cat%set_ptr(s), self%cat%set_ptr(s + 1) - 1
        L = local_dof(self%cat%set_dof(k))
        if (L == 0) cycle
        j = j + 1; dofs(j) = L
      end do
      self%set_ptr(s + 1) = j + 1
    end do
    self%set_dof = dofs(1:j)
    ! Mirror pairs with both nodes in the window (a pair cut by the window's edge lies beyond
    ! the nodes the process's particles read: its margin, [[empm_halo]]).
    allocate(gh(size(self%cat%ghost)), im(size(self%cat%ghost)), keep(size(self%cat%ghost)))
    j = 0
    do k = 1, size(self%cat%ghost)
      gh(k) = new%node_id(whole%node_ijk(self%cat%ghost(k)))
      im(k) = new%node_id(whole%node_ijk(self%cat%image(k)))
      if (gh(k) == 0 .or. im(k) == 0) cycle
      j = j + 1; keep(j) = k
    end do
    self%ghost = gh(keep(1:j)); self%image = im(keep(1:j))
    self%msign = self%cat%msign(:, keep(1:j))
    self%nmirror = j
    self%mirrored(self%image) = .true.
    ! Frictional wall nodes in the window.
    call self%fric%init(nd)
    do k = 1, self%cat%fric%n
      L = new%node_id(whole%node_ijk(self%cat%fric%node(k)))
      if (L == 0) cycle
      call self%fric%add([L], self%cat%fric%axis(k), self%cat%fric%sgn(k), self%cat%fric%mu(k), &
                         self%cat%fric%set(k))
    end do
    call self%ext%init(n)
  contains
    ! The window's dof position of a whole-grid dof position (0 outside the window).
    integer function local_dof(gj)
      integer, intent(in) :: gj
      integer :: id
      id = new%node_id(whole%node_ijk((gj - 1) / nd + 1))
      local_dof = 0
      if (id > 0) local_dof = mod(gj - 1, nd) + 1 + nd * (id - 1)
    end function local_dof

    ! A field on the new window: the old values where both hold the node (none when the
    ! fields were never allocated: set-up's storage, [[nodes_alloc]]), else 0.
    subroutine move1(a)
      real(wp), allocatable, intent(inout) :: a(:)
      real(wp), allocatable :: b(:)
      integer :: q
      logical :: had
      had = size(a) == old%nnode
      allocate(b(n))
      do q = 1, n
        b(q) = 0.0_wp
        if (had .and. from(q) > 0) b(q) = a(from(q))
      end do
      call move_alloc(b, a)
    end subroutine move1

    subroutine move2(a)
      real(wp), allocatable, intent(inout) :: a(:,:)
      real(wp), allocatable :: b(:,:)
      integer :: q
      logical :: had
      had = size(a, 2) == old%nnode
      allocate(b(nd, n))
      do q = 1, n
        b(:, q) = 0.0_wp
        if (had .and. from(q) > 0) b(:, q) = a(:, from(q))
      end do
      call move_alloc(b, a)
    end subroutine move2
  end subroutine nodes_window

  ! Keep set-up's constraints in the whole grid's numbering (the storage is on `whole`).
  subroutine make_catalogue(self, whole)
    type(empm_nodes_t), intent(inout) :: self
    type(empm_grid_t), intent(in) :: whole
    if (any(whole%off /= 0) .or. any(whole%ln /= whole%nn)) &
      error stop 'empm_nodes: the first window must be taken from the whole grid'
    if (.not. self%sparse) then
      self%cat%fix = self%fixed_dofs
      self%cat%vfix = pack(self%vfix, self%fixed)
    end if
    self%cat%set_ptr = self%set_ptr; self%cat%set_dof = self%set_dof
    self%cat%ghost = self%ghost(1:self%nmirror); self%cat%image = self%image(1:self%nmirror)
    self%cat%msign = self%msign(:, 1:self%nmirror)
    self%cat%fric = self%fric
    self%cat%made = .true.
  end subroutine make_catalogue

  !> Allocate nodal storage for `grid`; no dof fixed. An allocation failure is reported in
  !> `err` when present (with the memory asked for), otherwise it stops the program. With
  !> `fields = .false.` (a parallel run's set-up, which never holds the whole grid's fields)
  !> nothing node-sized is stored: the fields are empty and the constraints, which can be
  !> set, are lists of the fixed dofs (a boundary's worth) until a window is taken
  !> ([[nodes_window]]).
  subroutine nodes_alloc(self, grid, err, fields)
    class(empm_nodes_t), intent(inout) :: self     !! nodal fields
    type(empm_grid_t), intent(in) :: grid          !! background grid
    type(empm_error_t), intent(inout), optional :: err !! set on an allocation failure
    logical, intent(in), optional :: fields        !! allocate the fields (default .true.)
    integer :: d, n, nf, nc, stat
    character(len=256) :: msg
    d = grid%ndim; n = grid%nnode
    nf = n
    if (present(fields)) then
      if (.not. fields) nf = 0
    end if
    self%sparse = nf == 0 .and. n > 0
    nc = nf ! node-sized constraint arrays
    self%ndim = d; self%nnode = n
    if (allocated(self%mass)) deallocate(self%mass, self%mom, self%vel, self%force, self%acc, &
      self%work, self%fixed, self%vfix, self%vol)
    allocate(self%mass(nf), self%mom(d, nf), self%vel(d, nf), self%force(d, nf), &
      self%acc(d, nf), self%work(d, nf), self%fixed(d, nc), self%vfix(d, nc), self%vol(nf), &
      stat=stat, errmsg=msg)
    if (stat /= 0) then
      self%nnode = 0
      call empm_raise_error(empm_alloc_error('nodal fields ('//str(n)//' nodes)', &
        int(nf, int64) * 8_int64 * (2 + 5 * d) + int(nc, int64) * 12_int64 * d, msg), err)
      return
    end if
    self%fixed = .false.; self%vfix = 0.0_wp
    self%cat%made = .false.
    if (allocated(self%cat%fix)) deallocate(self%cat%fix, self%cat%vfix)
    allocate(self%cat%fix(0), self%cat%vfix(0))
    call self%list_fixed()
    self%nset = 0
    if (allocated(self%set_name)) deallocate(self%set_name, self%set_ptr, self%set_dof, &
      self%set_fix, self%set_vel, self%reaction)
    allocate(self%set_name(0), self%set_ptr(1), self%set_dof(0), self%set_fix(d, 0), &
      self%set_vel(d, 0), self%reaction(d, 0))
    self%set_ptr(1) = 1
    call zero(self%mass, nf); call zero(self%mom, d * nf); call zero(self%vel, d * nf)
    call zero(self%force, d * nf); call zero(self%acc, d * nf); call zero(self%work, d * nf)
    call zero(self%vol, nf)
    call self%ext%init(nf)
    call self%fric%init(d)
    self%nmirror = 0; self%nplane = 0
    if (allocated(self%ghost)) deallocate(self%ghost, self%image, self%msign, self%plane_side, &
                                          self%plane_at)
    allocate(self%ghost(0), self%image(0), self%msign(d, 0), self%plane_side(0), self%plane_at(0))
    if (allocated(self%mirrored)) deallocate(self%mirrored)
    allocate(self%mirrored(nc))
    self%mirrored = .false.
  end subroutine nodes_alloc

  !> A mirror plane: the nodes in the box [lo, hi], which must be flat along axis |side| (the
  !> plane, on a grid line), get components `comp` fixed at zero; every node on the ghost side
  !> of the plane (sign of `side`) whose foot lies in the box becomes the ghost of its mirror
  !> image, with value −v (the `comp` components: odd about the plane) or +v (the others: even).
  !> Gathering the ghosts' masses and numerators into their images is what the mirror
  !> particles of the symmetric problem would give them. `info`: 0 ok, 1 box not flat along
  !> the axis or not on a grid line, 2 no plane node, 3 a ghost node fixed or already a ghost,
  !> 4 no ghost node (the grid ends at the plane).
  subroutine nodes_mirror_box(self, grid, lo, hi, side, comp, nsel, info)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: lo(3), hi(3)       !! box of the plane's nodes [m]
    integer, intent(in) :: side                !! ±axis: the ghost side (e.g. -1: x below)
    logical, intent(in) :: comp(3)             !! odd (fixed on the plane) components
    integer, intent(out) :: nsel               !! plane nodes selected
    integer, intent(out) :: info               !! status (above)
    real(wp) :: tol, zero3(3)
    integer :: a, id, k, ijk(3), g(3), m(3), ip, nd, d, ng, q
    integer, allocatable :: gh(:), im(:), sel(:)
    real(wp), allocatable :: sg(:,:)
    info = 0; nd = grid%ndim; a = abs(side); zero3 = 0.0_wp
    tol = 1.0e-9_wp * grid%hmin()
    ip = nint((lo(a) - grid%origin(a)) * grid%inv_h(a))
    if (abs(hi(a) - lo(a)) > tol .or. abs(grid%origin(a) + ip * grid%h(a) - lo(a)) > tol) then
      info = 1; return
    end if
    call self%fix_box(grid, lo, hi, comp, zero3, nsel)
    if (nsel == 0) then
      info = 2; return
    end if
    allocate(gh(0), im(0), sg(nd, 0))
    ng = 0
    call box_nodes(grid, lo, hi, tol, sel)
    do q = 1, size(sel)
      id = sel(q)
      ijk = grid%node_ijk(id)
      do k = 1, grid%nn(a)
        g = ijk; g(a) = ijk(a) + sign(k, side)
        m = ijk; m(a) = ijk(a) - sign(k, side)
        if (g(a) < 0 .or. g(a) > grid%nn(a) - 1 .or. m(a) < 0 .or. m(a) > grid%nn(a) - 1) exit
        if (any([(self%is_fixed(d, grid%node_id(g)), d = 1, nd)]) .or. &
            any(gh == grid%node_id(g)) .or. any(self%ghost == grid%node_id(g))) then
          info = 3; return
        end if
        gh = [gh, grid%node_id(g)]; im = [im, grid%node_id(m)]
        sg = reshape([sg, [(merge(-1.0_wp, 1.0_wp, comp(d)), d = 1, nd)]], [nd, size(gh)])
        ng = ng + 1
      end do
    end do
    if (ng == 0) then
      info = 4; return
    end if
    self%ghost = [self%ghost, gh]; self%image = [self%image, im]
    self%msign = reshape([self%msign, sg], [nd, size(self%ghost)])
    self%nmirror = size(self%ghost)
    if (.not. self%sparse) self%mirrored(im) = .true. ! a window marks its own
    self%plane_side = [self%plane_side, side]; self%plane_at = [self%plane_at, lo(a)]
    self%nplane = size(self%plane_side)
  end subroutine nodes_mirror_box

  !> m_image += m_ghost, m_ghost = 0 (the ghosts are not unknowns).
  subroutine nodes_mirror_gather_mass(self)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    call gather_even(self%nmirror, self%ghost, self%image, self%mass)
  end subroutine nodes_mirror_gather_mass

  !> A nodal scalar even about the mirror planes (a mass-like sum, e.g. of the volumetric
  !> rate): a_image += a_ghost, a_ghost = 0.
  subroutine nodes_mirror_gather_even(self, a)
    class(empm_nodes_t), intent(in) :: self     !! nodal fields
    real(wp), intent(inout) :: a(:)             !! nodal scalars (nnode)
    call gather_even(self%nmirror, self%ghost, self%image, a)
  end subroutine nodes_mirror_gather_even

  pure subroutine gather_even(n, ghost, image, a)
    integer, intent(in) :: n, ghost(:), image(:)
    real(wp), intent(inout) :: a(:)
    integer :: k
    do k = 1, n
      a(image(k)) = a(image(k)) + a(ghost(k))
      a(ghost(k)) = 0.0_wp
    end do
  end subroutine gather_even

  !> After out = q/m̂: the images get their ghosts' numerators with the component signs,
  !> out_J += s q_I/m̂_J (free dofs only), and the ghosts their mirrored values.
  subroutine nodes_mirror_correct(self, q, out)
    class(empm_nodes_t), intent(in) :: self     !! nodal fields (gathered masses)
    real(wp), intent(in) :: q(:,:)              !! numerators (ndim, nnode)
    real(wp), intent(inout) :: out(:,:)         !! q/m̂ (ndim, nnode)
    integer :: k, d, J
    do k = 1, self%nmirror
      J = self%image(k)
      if (.not. self%mass(J) > self%mass_tol) cycle
      do d = 1, self%ndim
        if (.not. self%fixed(d, J)) out(d, J) = out(d, J) + self%msign(d, k) * q(d, self%ghost(k)) &
                                                / self%mass(J)
      end do
    end do
    call self%mirror_scatter(out)
  end subroutine nodes_mirror_correct

  !> v_ghost = s v_image (with `even`, v_ghost = v_image in every row).
  subroutine nodes_mirror_scatter(self, v, even)
    class(empm_nodes_t), intent(in) :: self     !! nodal fields
    real(wp), intent(inout) :: v(:,:)           !! nodal vectors (ndim or 1, nnode)
    logical, intent(in), optional :: even       !! an even field (default: the plane's signs)
    integer :: k
    logical :: ev
    ev = .false.
    if (present(even)) ev = even
    do k = 1, self%nmirror
      if (ev) then
        v(:, self%ghost(k)) = v(:, self%image(k))
      else
        v(:, self%ghost(k)) = self%msign(:, k) * v(:, self%image(k))
      end if
    end do
  end subroutine nodes_mirror_scatter

  !> The nearly-empty nodes of a new basis ([[empm_extension]]), from the nodal masses and the
  !> filled volumes `vol` just accumulated; a node with a fixed dof, or a mirror image (its
  !> ghosts take their values from it and hand it their numerators), is never one.
  subroutine nodes_find_degenerate(self, grid)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    type(empm_grid_t), intent(in) :: grid      !! background grid
    call self%ext%find(grid, self%mass, self%vol, self%mass_tol, self%fixed, self%mirrored)
  end subroutine nodes_find_degenerate

  !> Zero the fields P2G accumulates into, mass and momentum (step 9 of the paper's
  !> algorithm); constraints are kept. The other nodal fields are outputs, written at every node
  !> by the pass that computes them (force is zeroed where it is assembled); a scheme that
  !> accumulates into one of them zeroes it itself.
  subroutine nodes_reset(self)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    ! Each field as one contiguous block (assigning through the polymorphic `self` compiles
    ! to one library call per node column).
    call zero(self%mass, size(self%mass)); call zero(self%mom, size(self%mom))
  end subroutine nodes_reset

  !> a = 0 over n contiguous entries.
  subroutine zero(a, n)
    integer, intent(in) :: n       !! number of entries
    real(wp), intent(out) :: a(n)  !! array
    integer :: i
    !$omp parallel do default(none) shared(a, n) private(i) schedule(static) if(n >= 65536)
    do i = 1, n
      a(i) = 0.0_wp
    end do
    !$omp end parallel do
  end subroutine zero

  !> Constrain components `comp` of every node inside the closed box [lo, hi] (a node set by
  !> geometry) to the velocity `value`, or with `gradient` G to the affine field
  !> value + G x_I (x_I the node's position: a kinematic driver, steady in space). Returns the
  !> number of nodes selected. Allocates the nodal storage on first use. With `name`, the dofs
  !> fixed here also form a reaction set of that name, whose reaction force
  !> [[nodes_compute_reactions]] records (uniform `value` only).
  subroutine nodes_fix_box(self, grid, lo, hi, comp, value, nsel, name, gradient)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: lo(3)              !! lower corner of the selection box [m]
    real(wp), intent(in) :: hi(3)              !! upper corner of the selection box [m]
    logical, intent(in) :: comp(3)             !! which velocity components to prescribe
    real(wp), intent(in) :: value(3)           !! prescribed velocity components [m/s]
    integer, intent(out) :: nsel               !! number of nodes selected
    character(len=*), intent(in), optional :: name !! name of the reaction set to record
    real(wp), intent(in), optional :: gradient(3, 3) !! velocity gradient G of the prescribed
                                                     !! field value + G x [1/s]
    real(wp) :: tol, x(3), v(3)
    integer :: q, id, d, nd, nc, j
    integer, allocatable :: ids(:), dofs(:)
    real(wp), allocatable :: vals(:)
    if (.not. allocated(self%mass) .or. self%nnode /= grid%nnode) call self%alloc(grid)
    ! A node counts as inside when within a small fraction of a cell of the box.
    tol = 1.0e-9_wp * grid%hmin()
    nd = grid%ndim
    call box_nodes(grid, lo, hi, tol, ids)
    nsel = size(ids); nc = count(comp(1:nd))
    allocate(dofs(nsel * nc), vals(nsel * nc))
    j = 0
    do q = 1, nsel
      id = ids(q)
      v = value
      if (present(gradient)) then
        x = grid%node_coord(id)
        v = value + matmul(gradient, x)
      end if
      do d = 1, nd
        if (comp(d)) then
          j = j + 1; dofs(j) = d + nd * (id - 1); vals(j) = v(d)
          if (.not. self%sparse) then
            self%fixed(d, id) = .true.
            self%vfix(d, id) = v(d)
          end if
        end if
      end do
    end do
    if (self%sparse) call merge_fixed(self%cat, dofs, vals)
    call self%list_fixed()
    if (present(name)) call add_set(self, name, dofs, comp(1:nd), value(1:nd))
  end subroutine nodes_fix_box

  !> A frictional wall at rest: every node in the box [lo, hi], which must be flat along axis
  !> |side| (lo = hi there), gets that component fixed at zero and Coulomb friction of
  !> coefficient `mu` on the others ([[empm_friction]]); the body lies on the `side` of the
  !> wall (+axis: above it). With `name`, the wall is a reaction set whose reaction includes
  !> the friction. info: 0 done, 1 the box is not flat along the axis, 2 it selects no node,
  !> 3 a node is already on another frictional wall.
  subroutine nodes_friction_box(self, grid, lo, hi, side, mu, nsel, info, name)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: lo(3)              !! lower corner of the selection box [m]
    real(wp), intent(in) :: hi(3)              !! upper corner of the selection box [m]
    integer, intent(in) :: side                !! ±axis: the normal from the wall into the body
    real(wp), intent(in) :: mu                 !! friction coefficient tan δ (≥ 0)
    integer, intent(out) :: nsel               !! number of nodes selected
    integer, intent(out) :: info               !! 0 or the failure above
    character(len=*), intent(in), optional :: name !! name of the reaction set to record
    real(wp) :: tol
    logical :: comp(3)
    integer :: id, a, set
    integer, allocatable :: ids(:)
    a = abs(side); nsel = 0; info = 0
    if (.not. allocated(self%mass) .or. self%nnode /= grid%nnode) call self%alloc(grid)
    tol = 1.0e-9_wp * grid%hmin()
    if (hi(a) - lo(a) > tol) then
      info = 1; return
    end if
    call box_nodes(grid, lo, hi, tol, ids)
    if (size(ids) == 0) info = 2
    do id = 1, size(ids)
      if (self%fric%has(ids(id))) info = 3
    end do
    if (info /= 0) return
    comp = .false.; comp(a) = .true.
    set = 0
    if (present(name)) then
      call self%fix_box(grid, lo, hi, comp, [0.0_wp, 0.0_wp, 0.0_wp], nsel, name)
      set = self%nset
    else
      call self%fix_box(grid, lo, hi, comp, [0.0_wp, 0.0_wp, 0.0_wp], nsel)
    end if
    call self%fric%add(ids, a, sign(1.0_wp, real(side, wp)), mu, set)
  end subroutine nodes_friction_box

  !> The frictional walls' forces added to the total nodal force `f` (before the fixed dofs
  !> are zeroed: the normal load is read from it), with the nodal velocities `v` of the step
  !> and the time `h` over which f/m is added to them; the reaction sets include them.
  pure subroutine nodes_apply_friction(self, v, h, f, mask)
    class(empm_nodes_t), intent(inout) :: self     !! nodal fields
    real(wp), intent(in), contiguous :: v(:,:)     !! nodal velocities (ndim, nnode) [m/s]
    real(wp), intent(in) :: h                      !! time over which f/m is added to v [s]
    real(wp), intent(inout), contiguous :: f(:,:)  !! total nodal force (ndim, nnode) [N]
    logical, intent(in), optional :: mask(:)       !! nodes whose friction the reactions count
                                                   !! (nnode); all when absent
    call self%fric%apply(self%mass, self%fixed, v, h, f, self%reaction, mask)
  end subroutine nodes_apply_friction

  !> Put back the walls' tangential forces after a pass that changed every dof (damping).
  pure subroutine nodes_restore_friction(self, f)
    class(empm_nodes_t), intent(in) :: self        !! nodal fields
    real(wp), intent(inout), contiguous :: f(:,:)  !! total nodal force (ndim, nnode) [N]
    call self%fric%restore(self%fixed, f)
  end subroutine nodes_restore_friction

  !> Whether node `id` lies in the closed box [lo, hi], within `tol` (the node sets by geometry).
  pure logical function in_box(grid, id, lo, hi, tol)
    type(empm_grid_t), intent(in) :: grid !! background grid
    integer, intent(in) :: id             !! node
    real(wp), intent(in) :: lo(3), hi(3)  !! the box [m]
    real(wp), intent(in) :: tol           !! tolerance [m]
    real(wp) :: xi(3)
    xi = grid%node_coord(id)
    in_box = all(xi(1:grid%ndim) >= lo(1:grid%ndim) - tol .and. &
                 xi(1:grid%ndim) <= hi(1:grid%ndim) + tol)
  end function in_box

  ! The nodes in the closed box [lo, hi] within `tol`, in increasing order: those of the
  ! box's index range (a node wider on each side, against rounding), each checked by in_box.
  subroutine box_nodes(grid, lo, hi, tol, ids)
    type(empm_grid_t), intent(in) :: grid
    real(wp), intent(in) :: lo(3), hi(3), tol
    integer, allocatable, intent(out) :: ids(:)
    integer, allocatable :: found(:)
    integer :: a(3), b(3), d, i, j, k, n, id
    real(wp) :: top(3)
    top = grid%upper()
    a = 0; b = 0
    do d = 1, grid%ndim
      a(d) = first_index((lo(d) - tol - grid%origin(d)) * grid%inv_h(d)) - 1
      b(d) = first_index((hi(d) + tol - grid%origin(d)) * grid%inv_h(d)) + 1
      ! Coordinates too large for the cell size (their rounding a fair part of a cell, which
      ! the range's one node of margin may not cover): every node of the line is a candidate,
      ! as in a scan of every node.
      if (spacing(max(abs(grid%origin(d)), abs(top(d)))) > 0.1_wp * grid%h(d)) then
        a(d) = 0; b(d) = grid%nn(d) - 1
      end if
      a(d) = max(a(d), 0); b(d) = min(b(d), grid%nn(d) - 1)
    end do
    n = 0
    if (all(a <= b)) n = product(b - a + 1)
    allocate(found(n))
    n = 0
    do k = a(3), b(3)
      do j = a(2), b(2)
        do i = a(1), b(1)
          id = grid%node_id([i, j, k])
          if (id == 0) cycle
          if (.not. in_box(grid, id, lo, hi, tol)) cycle
          n = n + 1; found(n) = id
        end do
      end do
    end do
    allocate(ids(n))
    ids = found(1:n)
  contains
    ! floor(r), clamped to the grid's index range (a box far outside, or infinite, too).
    integer function first_index(r)
      real(wp), intent(in) :: r
      first_index = int(floor(min(max(r, -2.0_wp), real(grid%nn(d) + 1, wp))))
    end function first_index
  end subroutine box_nodes

  ! Add the dofs `dofs` (increasing) with velocities `vals` to the catalogue's sorted list;
  ! a dof already there takes the new value (as a later box overwrites an earlier one).
  subroutine merge_fixed(cat, dofs, vals)
    type(node_catalogue_t), intent(inout) :: cat
    integer, intent(in) :: dofs(:)
    real(wp), intent(in) :: vals(:)
    integer, allocatable :: f(:)
    real(wp), allocatable :: v(:)
    integer :: i, j, n
    allocate(f(size(cat%fix) + size(dofs)), v(size(cat%fix) + size(dofs)))
    i = 1; j = 1; n = 0
    do while (i <= size(cat%fix) .or. j <= size(dofs))
      n = n + 1
      if (j > size(dofs)) then
        f(n) = cat%fix(i); v(n) = cat%vfix(i); i = i + 1
      else if (i > size(cat%fix)) then
        f(n) = dofs(j); v(n) = vals(j); j = j + 1
      else if (cat%fix(i) < dofs(j)) then
        f(n) = cat%fix(i); v(n) = cat%vfix(i); i = i + 1
      else
        if (cat%fix(i) == dofs(j)) i = i + 1
        f(n) = dofs(j); v(n) = vals(j); j = j + 1
      end if
    end do
    cat%fix = f(1:n); cat%vfix = v(1:n)
  end subroutine merge_fixed

  ! Position of `dof` in the increasing list `list` (0: absent), by bisection.
  pure integer function listed(list, dof) result(k)
    integer, intent(in) :: list(:), dof
    integer :: lo, hi, mid
    k = 0; lo = 1; hi = size(list)
    do while (lo <= hi)
      mid = (lo + hi) / 2
      if (list(mid) == dof) then
        k = mid; return
      else if (list(mid) < dof) then
        lo = mid + 1
      else
        hi = mid - 1
      end if
    end do
  end function listed

  !> Append the reaction set `name` (set-up only).
  subroutine add_set(self, name, dofs, comp, value)
    type(empm_nodes_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: dofs(:)
    logical, intent(in) :: comp(:)
    real(wp), intent(in) :: value(:)
    character(len=64), allocatable :: names(:)
    logical, allocatable :: fx(:,:)
    real(wp), allocatable :: r(:,:)
    integer :: n
    n = self%nset + 1; self%nset = n
    names = [character(len=64) :: self%set_name, name]; call move_alloc(names, self%set_name)
    self%set_ptr = [self%set_ptr, self%set_ptr(n) + size(dofs)]
    self%set_dof = [self%set_dof, dofs]
    allocate(fx(self%ndim, n)); fx(:, 1:n - 1) = self%set_fix; fx(:, n) = comp
    call move_alloc(fx, self%set_fix)
    allocate(r(self%ndim, n)); r(:, 1:n - 1) = self%set_vel; r(:, n) = merge(value, 0.0_wp, comp)
    call move_alloc(r, self%set_vel)
    deallocate(self%reaction); allocate(self%reaction(self%ndim, n)); self%reaction = 0.0_wp
  end subroutine add_set

  !> Reaction force of every reaction set from the total nodal force `f` (internal + external,
  !> before the fixed dofs are zeroed): R_s = Σ over the set's dofs of (m_I a_prescribed − f_I)
  !> = −Σ f_I, the prescribed velocities being constant in time. R is the force the support
  !> exerts on the body (a base carrying a body's weight W pushes up: R = +W along the up axis).
  !> A dof in several sets counts in each.
  pure subroutine nodes_compute_reactions(self, f, mask)
    class(empm_nodes_t), intent(inout) :: self     !! nodal fields (reaction is set)
    real(wp), intent(in), contiguous :: f(:,:)     !! total nodal force (ndim, nnode) [N]
    logical, intent(in), optional :: mask(:)       !! the nodes to count (nnode), e.g. those a
                                                   !! process owns; all when absent
    if (present(mask)) then
      call set_sums(self%nset, self%ndim, self%set_ptr, self%set_dof, f, self%reaction, mask)
    else
      call set_sums(self%nset, self%ndim, self%set_ptr, self%set_dof, f, self%reaction)
    end if
  end subroutine nodes_compute_reactions

  pure subroutine set_sums(nset, nd, ptr, dofs, f, r, mask)
    integer, intent(in) :: nset, nd
    integer, intent(in) :: ptr(nset + 1), dofs(*)
    real(wp), intent(in) :: f(*)
    real(wp), intent(out) :: r(nd, nset)
    logical, intent(in), optional :: mask(:)
    integer :: s, k, j
    r = 0.0_wp
    do s = 1, nset
      do k = ptr(s), ptr(s + 1) - 1
        j = dofs(k)
        if (present(mask)) then
          if (.not. mask((j - 1) / nd + 1)) cycle
        end if
        r(mod(j - 1, nd) + 1, s) = r(mod(j - 1, nd) + 1, s) - f(j)
      end do
    end do
  end subroutine set_sums

  !> Local non-viscous (Cundall) damping of the nodal force: f_Id −= α |f_Id| sgn(v_Id) on
  !> every dof (sgn 0 = 0: a node at rest is not damped); the fixed dofs are zeroed later anyway.
  pure subroutine nodes_local_damping(self, alpha, v, f)
    class(empm_nodes_t), intent(in) :: self        !! nodal fields
    real(wp), intent(in) :: alpha                  !! damping coefficient α in [0, 1)
    real(wp), intent(in), contiguous :: v(:,:)     !! nodal velocities (ndim, nnode) [m/s]
    real(wp), intent(inout), contiguous :: f(:,:)  !! nodal force (ndim, nnode) [N]
    integer :: i, d
    do i = 1, self%nnode
      do d = 1, self%ndim
        if (v(d, i) > 0.0_wp) then
          f(d, i) = f(d, i) - alpha * abs(f(d, i))
        else if (v(d, i) < 0.0_wp) then
          f(d, i) = f(d, i) + alpha * abs(f(d, i))
        end if
      end do
    end do
  end subroutine nodes_local_damping

  !> Rebuild `fixed_dofs` from `fixed`, so that the constraint passes of every step visit the
  !> fixed dofs only (none, usually, or a boundary's worth) instead of every node.
  subroutine nodes_list_fixed(self)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields
    integer :: k
    if (allocated(self%fixed_dofs)) deallocate(self%fixed_dofs)
    if (self%sparse) then
      self%fixed_dofs = self%cat%fix; return
    end if
    if (.not. allocated(self%fixed)) then
      allocate(self%fixed_dofs(0)); return
    end if
    allocate(self%fixed_dofs(count(self%fixed)))
    self%fixed_dofs = pack([(k, k = 1, size(self%fixed))], reshape(self%fixed, [size(self%fixed)]))
  end subroutine nodes_list_fixed

  !> Prescribe velocity `value` on component `d` of node `id` (set-up; after fixing many dofs
  !> one by one, a box is faster: [[nodes_fix_box]]).
  subroutine nodes_fix_dof(self, d, id, value)
    class(empm_nodes_t), intent(inout) :: self !! nodal fields (allocated)
    integer, intent(in) :: d                   !! component, 1..ndim
    integer, intent(in) :: id                  !! node, 1..nnode
    real(wp), intent(in) :: value              !! prescribed velocity [m/s]
    if (self%sparse) then
      call merge_fixed(self%cat, [d + self%ndim * (id - 1)], [value])
    else
      self%fixed(d, id) = .true.
      self%vfix(d, id) = value
    end if
    call self%list_fixed()
  end subroutine nodes_fix_dof

  !> Whether component `d` of node `id` is prescribed.
  pure logical function nodes_is_fixed(self, d, id)
    class(empm_nodes_t), intent(in) :: self !! nodal fields
    integer, intent(in) :: d                !! component
    integer, intent(in) :: id               !! node
    if (self%sparse) then
      nodes_is_fixed = listed(self%cat%fix, d + self%ndim * (id - 1)) > 0
    else
      nodes_is_fixed = self%fixed(d, id)
    end if
  end function nodes_is_fixed

  !> Prescribed velocity of component `d` of node `id` (0 when free) [m/s].
  pure real(wp) function nodes_fixed_velocity(self, d, id)
    class(empm_nodes_t), intent(in) :: self !! nodal fields
    integer, intent(in) :: d                !! component
    integer, intent(in) :: id               !! node
    integer :: k
    if (self%sparse) then
      k = listed(self%cat%fix, d + self%ndim * (id - 1))
      nodes_fixed_velocity = 0.0_wp
      if (k > 0) nodes_fixed_velocity = self%cat%vfix(k)
    else
      nodes_fixed_velocity = merge(self%vfix(d, id), 0.0_wp, self%fixed(d, id))
    end if
  end function nodes_fixed_velocity

  !> Number of prescribed dofs.
  pure integer function nodes_nfixed(self)
    class(empm_nodes_t), intent(in) :: self !! nodal fields
    nodes_nfixed = 0
    if (allocated(self%fixed_dofs)) nodes_nfixed = size(self%fixed_dofs)
  end function nodes_nfixed

  !> Impose the Dirichlet conditions on nodal velocities (and the matching momenta): the
  !> prescribed dofs only (`fixed_dofs`), not every node.
  subroutine nodes_constrain_velocity(self, v, mom)
    class(empm_nodes_t), intent(in) :: self           !! nodal constraints and masses
    real(wp), intent(inout), contiguous :: v(:,:)     !! nodal velocities (ndim, nnode)
    real(wp), intent(inout), contiguous :: mom(:,:)   !! nodal momenta (ndim, nnode)
    call constrain_dofs(size(self%fixed_dofs), self%fixed_dofs, self%ndim, self%mass, &
                        self%vfix, v, mom)
    ! Ghosts and nearly-empty nodes take their values from the constrained ones.
    if (self%nmirror > 0) call self%mirror_scatter(v)
    if (self%ext%n > 0) call self%ext%scatter(v)
  end subroutine nodes_constrain_velocity

  !> v = vfix and mom = m vfix on the listed dofs (positions in the (ndim, nnode) arrays).
  pure subroutine constrain_dofs(n, dofs, nd, mass, vfix, v, mom)
    integer, intent(in) :: n             !! number of fixed dofs
    integer, intent(in) :: dofs(n)       !! fixed dofs (positions in the (nd, nnode) arrays)
    integer, intent(in) :: nd            !! spatial dimension
    real(wp), intent(in) :: mass(*)      !! nodal masses
    real(wp), intent(in) :: vfix(*)      !! prescribed velocities (nd, nnode)
    real(wp), intent(inout) :: v(*)      !! nodal velocities (nd, nnode)
    real(wp), intent(inout) :: mom(*)    !! nodal momenta (nd, nnode)
    integer :: k, j
    do k = 1, n
      j = dofs(k)
      v(j) = vfix(j)
      mom(j) = mass((j - 1) / nd + 1) * vfix(j)
    end do
  end subroutine constrain_dofs

  !> Zero nodal forces on the prescribed dofs (zero acceleration there).
  subroutine nodes_constrain_force(self, f)
    class(empm_nodes_t), intent(in) :: self           !! nodal constraints
    real(wp), intent(inout), contiguous :: f(:,:)     !! nodal forces (ndim, nnode)
    call zero_dofs(size(self%fixed_dofs), self%fixed_dofs, f)
  end subroutine nodes_constrain_force

  !> f = 0 on the listed dofs.
  pure subroutine zero_dofs(n, dofs, f)
    integer, intent(in) :: n             !! number of fixed dofs
    integer, intent(in) :: dofs(n)       !! fixed dofs (positions in the nodal array)
    real(wp), intent(inout) :: f(*)      !! nodal forces (ndim, nnode)
    integer :: k
    do k = 1, n
      f(dofs(k)) = 0.0_wp
    end do
  end subroutine zero_dofs
end module empm_nodes
