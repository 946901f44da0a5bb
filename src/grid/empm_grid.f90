!> Regular Cartesian background grid in 1, 2 or 3 dimensions.
!>
!> Nodes are numbered lexicographically, x fastest: node (i,j,k), 0-based per direction,
!> has index `1 + i + n1*(j + n2*k)` with `n1, n2` the node counts along x and y.
module empm_grid
  use empm_kinds, only: wp, int64 => i8
  implicit none
  private
  public :: empm_grid_t

  !> Background grid: origin, spacing and cell counts.
  type :: empm_grid_t
    integer :: ndim = 0                !! spatial dimension (1, 2 or 3)
    real(wp) :: origin(3) = 0.0_wp     !! coordinates of node (0,0,0)
    real(wp) :: h(3) = 1.0_wp          !! cell size per direction
    real(wp) :: inv_h(3) = 1.0_wp      !! 1/h per direction
    integer :: ncell(3) = 1            !! cells per direction (1 along unused directions)
    integer :: nn(3) = 1               !! nodes per direction (1 along unused directions)
    integer :: nnode = 0               !! total number of nodes
  contains
    procedure :: init => grid_init
    procedure :: node_coord => grid_node_coord
    procedure :: node_id => grid_node_id
    procedure :: node_ijk => grid_node_ijk
    procedure :: inside => grid_inside
    procedure :: hmin => grid_hmin
    procedure :: upper => grid_upper
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
  end subroutine grid_init

  !> Coordinates of node `id` (first `ndim` entries meaningful, others 0).
  pure function grid_node_coord(self, id) result(x)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: id              !! node index, 1..nnode
    real(wp) :: x(3)                       !! node coordinates
    integer :: ijk(3)
    ijk = self%node_ijk(id)
    x = self%origin + real(ijk, wp) * self%h
    x(self%ndim + 1:) = 0.0_wp
  end function grid_node_coord

  !> Node index from 0-based (i,j,k); 0 if outside the grid.
  pure integer function grid_node_id(self, ijk) result(id)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: ijk(3)          !! 0-based indices (unused directions: 0)
    if (any(ijk < 0) .or. any(ijk >= self%nn)) then
      id = 0
    else
      id = 1 + ijk(1) + self%nn(1) * (ijk(2) + self%nn(2) * ijk(3))
    end if
  end function grid_node_id

  !> 0-based (i,j,k) of node `id`.
  pure function grid_node_ijk(self, id) result(ijk)
    class(empm_grid_t), intent(in) :: self !! grid
    integer, intent(in) :: id              !! node index, 1..nnode
    integer :: ijk(3)                      !! 0-based indices
    integer :: r
    r = id - 1
    ijk(1) = mod(r, self%nn(1)); r = r / self%nn(1)
    ijk(2) = mod(r, self%nn(2)); ijk(3) = r / self%nn(2)
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
end module empm_grid
