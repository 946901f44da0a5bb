!> Regular Cartesian background grid in 1, 2 or 3 dimensions.
!>
!> Nodes are numbered lexicographically, x fastest: node (i,j,k), 0-based per direction,
!> has index `1 + i + n1*(j + n2*k)` with `n1, n2` the node counts along x and y.
!>
!> A grid may store only a **window** of its nodes: the box a process of a parallel run holds
!> (docs/parallel.md, "Block-local grids"). Its geometry (origin, spacing, cell and node
!> counts, `inside`, `node_coord`, node (i,j,k)) stays the whole grid's, so every coordinate a
!> window computes is the serial run's to the bit; only node ids are the window's: node (i,j,k)
!> has index `id0 + i + l1*(j + l2*k)` with `l1, l2` the window's node counts and `id0` placing
!> its first node at 1. `node_id` returns 0 for a node outside the window. A grid made by `init`
!> stores all its nodes.
module empm_grid
  use empm_kinds, only: wp, int64 => i8
  implicit none
  private
  public :: empm_grid_t

  !> Background grid: origin, spacing and cell counts, and the box of nodes it stores.
  type :: empm_grid_t
    integer :: ndim = 0                !! spatial dimension (1, 2 or 3)
    real(wp) :: origin(3) = 0.0_wp     !! coordinates of node (0,0,0)
    real(wp) :: h(3) = 1.0_wp          !! cell size per direction
    real(wp) :: inv_h(3) = 1.0_wp      !! 1/h per direction
    integer :: ncell(3) = 1            !! cells per direction (1 along unused directions)
    integer :: nn(3) = 1               !! nodes per direction (1 along unused directions)
    integer :: nnode = 0               !! number of nodes stored (all, or the window's)
    integer :: off(3) = 0              !! (i,j,k) of the first node stored (0 unless a window)
    integer :: ln(3) = 1               !! nodes stored per direction (nn unless a window)
    integer :: id0 = 1                 !! index of node (0,0,0) in the stored numbering:
                                       !! 1 − off1 − l1 (off2 + l2 off3)
  contains
    procedure :: init => grid_init
    procedure :: node_coord => grid_node_coord
    procedure :: node_id => grid_node_id
    procedure :: node_ijk => grid_node_ijk
    procedure :: inside => grid_inside
    procedure :: hmin => grid_hmin
    procedure :: upper => grid_upper
    procedure :: window => grid_window
    procedure :: whole => grid_whole
  end type empm_grid_t

contains

  !> Set up a grid. Unused directions (beyond `ndim`) get one node.
  pure subroutine grid_init(self, ndim, origin, h, ncell, info)
    class(empm_grid_t), intent(inout) :: self !! grid
    integer, intent(in) :: ndim               !! spatial dimension, 1..3
    real(wp), intent(in) :: origin(:)         !! origin, at least `ndim` entries
    real(wp), intent(in) :: h(:)              !! cell sizes (> 0), at least `ndim` entries
    integer, intent(in) :: ncell(:)           !! cells per direction (>= 1), at least `ndim` entries
    integer, intent(out) :: info              !! 0 ok, 1 bad dimension, 2 bad spacing, 3 bad cells,
                                              !! 4 more nodes than a default integer counts
    info = 0
    if (ndim < 1 .or. ndim > 3) then
      info = 1; return
    end if
    if (any(h(1:ndim) <= 0.0_wp)) then
      info = 2; return
    end if
    if (any(ncell(1:ndim) < 1)) then
      info = 3; return
    end if
    ! Node ids are default integers: the node count, formed in 64 bits, must fit.
    if (product(int(ncell(1:ndim), int64) + 1_int64) > int(huge(1), int64)) then
      info = 4; return
    end if
    self%ndim = ndim
    self%origin = 0.0_wp; self%h = 1.0_wp; self%ncell = 0; self%nn = 1
    self%origin(1:ndim) = origin(1:ndim)
    self%h(1:ndim) = h(1:ndim)
    self%inv_h = 1.0_wp / self%h
    self%ncell(1:ndim) = ncell(1:ndim)
    self%nn(1:ndim) = ncell(1:ndim) + 1
    self%nnode = product(self%nn)
    self%off = 0; self%ln = self%nn; self%id0 = 1
  end subroutine grid_init

  !> Coordinates of stored node `id` (first `ndim` entries meaningful, others 0).
  pure function grid_node_coord(self, id) result(x)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: id              !! node index, 1..nnode
    real(wp) :: x(3)                       !! node coordinates
    integer :: ijk(3)
    ijk = self%node_ijk(id)
    x = self%origin + real(ijk, wp) * self%h
    x(self%ndim + 1:) = 0.0_wp
  end function grid_node_coord

  !> Index of node (i,j,k) (0-based) among the stored nodes; 0 if outside the grid or not
  !> stored (outside the window).
  pure integer function grid_node_id(self, ijk) result(id)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: ijk(3)          !! 0-based indices (unused directions: 0)
    if (any(ijk < self%off) .or. any(ijk >= self%off + self%ln)) then
      id = 0
    else
      id = self%id0 + ijk(1) + self%ln(1) * (ijk(2) + self%ln(2) * ijk(3))
    end if
  end function grid_node_id

  !> 0-based (i,j,k) of stored node `id`.
  pure function grid_node_ijk(self, id) result(ijk)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: id              !! node index, 1..nnode
    integer :: ijk(3)                      !! 0-based indices
    integer :: r
    r = id - 1
    ijk(1) = mod(r, self%ln(1)); r = r / self%ln(1)
    ijk(2) = mod(r, self%ln(2)); ijk(3) = r / self%ln(2)
    ijk = ijk + self%off
  end function grid_node_ijk

  !> True when `x` lies in the closed grid box.
  pure logical function grid_inside(self, x) result(inside)
    class(empm_grid_t), intent(in) :: self !! grid
    real(wp), intent(in) :: x(:)           !! point, `ndim` entries
    integer :: d
    inside = .true.
    do d = 1, self%ndim
      if (.not. (x(d) >= self%origin(d) .and. &
                 x(d) <= self%origin(d) + self%ncell(d) * self%h(d))) inside = .false.
    end do
  end function grid_inside

  !> Smallest cell size over the used directions.
  pure real(wp) function grid_hmin(self) result(hm)
    class(empm_grid_t), intent(in) :: self !! grid
    hm = minval(self%h(1:self%ndim))
  end function grid_hmin

  !> Upper corner of the grid box.
  pure function grid_upper(self) result(x)
    class(empm_grid_t), intent(in) :: self !! grid
    real(wp) :: x(3) !! upper corner (unused directions: 0)
    x = 0.0_wp
    x(1:self%ndim) = self%origin(1:self%ndim) + self%ncell(1:self%ndim) * self%h(1:self%ndim)
  end function grid_upper

  !> The grid storing only its nodes lo..hi (0-based (i,j,k), clipped to the grid; unused
  !> directions ignored): a window.
  pure function grid_window(self, lo, hi) result(w)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: lo(3)           !! first node stored
    integer, intent(in) :: hi(3)           !! last node stored
    type(empm_grid_t) :: w                 !! the window
    integer :: nd, a(3), b(3)
    nd = self%ndim
    a = 0; b = 0
    a(1:nd) = max(lo(1:nd), 0); b(1:nd) = min(hi(1:nd), self%nn(1:nd) - 1)
    b = max(a, b)
    w = self
    w%off = a
    w%ln = b - a + 1
    w%nnode = product(w%ln)
    w%id0 = 1 - a(1) - w%ln(1) * (a(2) + w%ln(2) * a(3))
  end function grid_window

  !> The grid storing all its nodes (itself unless a window).
  pure function grid_whole(self) result(g)
    class(empm_grid_t), intent(in) :: self !! grid
    type(empm_grid_t) :: g                 !! the whole grid
    g = self
    g%off = 0; g%ln = self%nn; g%id0 = 1
    g%nnode = product(g%nn)
  end function grid_whole
end module empm_grid
