!> Nodal sums over the processes by exchange with neighbours only (docs/parallel.md, "Grid").
!>
!> Each process's P2G writes only to the nodes its particles' supports reach: its **core**, a
!> box of nodes found from the particles' extreme positions and the family's reach
!> ([[empm_shape_t:reach_cells]]). Its **region** is the core widened by a margin: the nodes
!> whose sums it needs complete. The margin covers what the grid operations read beyond a
!> node — the extension of a nearly-empty node looks up to 4 steps away, and its choice
!> depends on nodes 4 steps further (so 8); a mirror ghost's image lies within two reaches —
!> so every node a process's particles read ends up with the serial run's value.
!>
!> Each sum sends every process's partial values on the overlap of its region with each
!> other region, and every shared node is then added **in rank order** from the partials,
!> the same expression on every process that holds it: the processes agree bitwise on every
!> node they share. Nodes outside a process's region keep its own partials (zero where its
!> particles do not reach; meaningless beyond): they are never read there. A reduction over
!> nodes counts each node once, on the lowest-ranked process whose core holds it (`owned`).
!>
!> The boxes are agreed before each basis evaluation (one small all-gather); the exchange
!> plan is rebuilt only when a box changes, on the grid the process then stores (a window of
!> the whole grid holding its region: [[empm_model_t:fit_window]]). Boxes are in the whole
!> grid's node indices; lists and masks in the stored grid's. Serial runs never use it.
module empm_halo
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_comm, only: empm_comm_t
  use empm_grid, only: empm_grid_t
  implicit none
  private
  public :: empm_halo_t

  integer, parameter :: EXT_MARGIN = 8 !! two extension reaches of 4 steps ([[empm_extension]])

  !> The processes' node boxes and the plan of the exchange of their overlaps.
  type :: empm_halo_t
    logical :: active = .false.            !! several processes: sums go through the plan
    integer :: me = 0                      !! this process's rank
    integer :: margin = EXT_MARGIN         !! region = core widened by this many nodes
    integer :: last(3, 2) = reshape([0, 0, 0, -1, -1, -1], [3, 2]) !! core of the last
                                           !! evaluation (0-based node ijk, lo and hi)
    integer, allocatable :: core(:,:,:)    !! every process's core (3, 2, nranks), 0-based
    integer, allocatable :: region(:,:,:)  !! every process's region (3, 2, nranks)
    integer :: nnbr = 0                    !! processes whose region overlaps this one's
    integer, allocatable :: nbr(:)         !! their ranks, increasing (nnbr)
    integer, allocatable :: ptr(:)         !! their node lists in `list` (nnbr + 1)
    integer, allocatable :: list(:)        !! shared node ids per neighbour, increasing
    integer :: nshared = 0                 !! distinct shared nodes
    integer, allocatable :: node(:)        !! their ids (nshared)
    integer, allocatable :: mptr(:)        !! their contributions in `src` (nshared + 1)
    integer, allocatable :: src(:)         !! entry of `list` received from a neighbour, or 0
                                           !! for this process's own value; in rank order
    logical, allocatable :: owned(:)       !! node counted here by reductions (nnode)
    real(wp), allocatable :: sbuf(:)       !! send buffer (3 size(list))
    real(wp), allocatable :: rbuf(:)       !! receive buffer (3 size(list))
    integer, allocatable :: got(:,:)       !! every process's boxes as gathered (12, nranks)
    integer(int64) :: sent = 0             !! bytes sent by `sum` so far
    logical :: replan = .false.            !! the boxes changed: [[halo_plan]] rebuilds the plan
  contains
    procedure :: update => halo_update
    procedure :: plan => halo_plan
    procedure :: set_boxes => halo_set_boxes
    procedure :: in_core => halo_in_core
    procedure :: pack => halo_pack
    procedure :: merge => halo_merge
    procedure, private :: sum_1, sum_2
    generic :: sum => sum_1, sum_2
  end type empm_halo_t

contains

  !> Agree on the boxes before a basis evaluation. `lo`, `hi`: this process's core, the nodes
  !> (whole-grid 0-based ijk) its particles now reach (lo > hi: none). The core used is the
  !> union with the last evaluation's, because a step may still map nodal values of the basis
  !> before this one. When any box changed, `replan` is set: the caller fits its storage to
  !> the new region and calls [[halo_plan]]. Collective.
  subroutine halo_update(self, comm, grid, lo, hi, reach)
    class(empm_halo_t), intent(inout) :: self !! halo
    type(empm_comm_t), intent(in) :: comm     !! the run's processes
    type(empm_grid_t), intent(in) :: grid     !! background grid
    integer, intent(in) :: lo(3)              !! core, lower corner (0-based node ijk)
    integer, intent(in) :: hi(3)              !! core, upper corner
    integer, intent(in) :: reach              !! the family's reach in cells (mirror images)
    integer :: mine(12), c(3, 2), r(3, 2)
    self%active = comm%parallel()
    if (.not. self%active) return
    self%me = comm%rank
    self%margin = EXT_MARGIN + 2 * (reach + 1)
    c(:, 1) = lo; c(:, 2) = hi
    if (all(self%last(:, 1) <= self%last(:, 2))) then
      if (all(lo <= hi)) then
        c(:, 1) = min(lo, self%last(:, 1)); c(:, 2) = max(hi, self%last(:, 2))
      else
        c = self%last
      end if
    end if
    self%last(:, 1) = lo; self%last(:, 2) = hi
    c(:, 1) = max(c(:, 1), 0); c(:, 2) = min(c(:, 2), grid%nn - 1)
    r(:, 1) = max(c(:, 1) - self%margin, 0); r(:, 2) = min(c(:, 2) + self%margin, grid%nn - 1)
    if (any(c(:, 1) > c(:, 2))) then
      c(:, 1) = 0; c(:, 2) = -1; r = c
    end if
    mine(1:6) = reshape(c, [6]); mine(7:12) = reshape(r, [6])
    if (allocated(self%got)) then
      if (size(self%got, 2) /= comm%nranks) deallocate(self%got)
    end if
    if (.not. allocated(self%got)) allocate(self%got(12, comm%nranks))
    call comm%allgather_ints(mine, self%got)
    if (allocated(self%core)) then
      if (size(self%core, 3) == comm%nranks) then
        if (all(reshape(self%core, [6, comm%nranks]) == self%got(1:6, :)) .and. &
            all(reshape(self%region, [6, comm%nranks]) == self%got(7:12, :))) return
      end if
      deallocate(self%core, self%region)
    end if
    allocate(self%core(3, 2, comm%nranks), self%region(3, 2, comm%nranks))
    self%core = reshape(self%got(1:6, :), [3, 2, comm%nranks])
    self%region = reshape(self%got(7:12, :), [3, 2, comm%nranks])
    self%replan = .true.
  end subroutine halo_update

  !> After [[halo_update]] changed the boxes (`replan`): build the exchange plan and the
  !> ownership on `grid`, the grid this process now stores (which must hold its region).
  subroutine halo_plan(self, grid)
    class(empm_halo_t), intent(inout) :: self !! halo
    type(empm_grid_t), intent(in) :: grid     !! the stored grid (whole or a window)
    if (.not. self%replan) return
    call build_plan(self, grid, size(self%core, 3))
    self%replan = .false.
  end subroutine halo_plan

  !> Take every process's core and region (whole-grid 0-based node ijk boxes, lo > hi: empty)
  !> and build the exchange plan and the ownership as process `me`: what [[halo_update]] and
  !> [[halo_plan]] do with the boxes gathered (public for tests).
  subroutine halo_set_boxes(self, grid, me, core, region)
    class(empm_halo_t), intent(inout) :: self !! halo
    type(empm_grid_t), intent(in) :: grid     !! background grid
    integer, intent(in) :: me                 !! this process's rank, 0-based
    integer, intent(in) :: core(:,:,:)        !! cores (3, 2, nranks)
    integer, intent(in) :: region(:,:,:)      !! regions (3, 2, nranks), each holding its core
    self%me = me
    self%active = .true.
    if (allocated(self%core)) deallocate(self%core, self%region)
    allocate(self%core, source=core)
    allocate(self%region, source=region)
    call build_plan(self, grid, size(core, 3))
    self%replan = .false.
  end subroutine halo_set_boxes

  ! The neighbours, their overlap lists, the rank-order merge plan and the ownership mask.
  subroutine build_plan(self, grid, nranks)
    type(empm_halo_t), intent(inout) :: self
    type(empm_grid_t), intent(in) :: grid
    integer, intent(in) :: nranks
    integer :: q, k, n, e, u, nlist, o(3, 2)
    integer, allocatable :: tag(:), fill(:)
    ! Neighbours and the sizes of their overlaps.
    if (allocated(self%nbr)) deallocate(self%nbr, self%ptr)
    allocate(self%nbr(nranks), self%ptr(nranks + 1))
    self%nnbr = 0; self%ptr(1) = 1
    do q = 0, nranks - 1
      if (q == self%me) cycle
      o = overlap(self%region(:, :, self%me + 1), self%region(:, :, q + 1))
      if (any(o(:, 1) > o(:, 2))) cycle
      self%nnbr = self%nnbr + 1
      self%nbr(self%nnbr) = q
      self%ptr(self%nnbr + 1) = self%ptr(self%nnbr) + product(o(:, 2) - o(:, 1) + 1)
    end do
    nlist = self%ptr(self%nnbr + 1) - 1
    if (allocated(self%list)) deallocate(self%list)
    allocate(self%list(nlist))
    if (allocated(self%sbuf)) then
      if (size(self%sbuf) < 3 * nlist) deallocate(self%sbuf, self%rbuf)
    end if
    if (.not. allocated(self%sbuf)) allocate(self%sbuf(3 * nlist), self%rbuf(3 * nlist))
    ! The lists, in node order (both sides of an overlap list the same nodes alike).
    allocate(tag(grid%nnode))
    tag = 0
    do k = 1, self%nnbr
      o = overlap(self%region(:, :, self%me + 1), self%region(:, :, self%nbr(k) + 1))
      e = self%ptr(k) - 1
      call box_ids(grid, o, self%list(e + 1:self%ptr(k + 1) - 1))
      do e = self%ptr(k), self%ptr(k + 1) - 1
        tag(self%list(e)) = tag(self%list(e)) + 1
      end do
    end do
    ! Distinct shared nodes in node order, each with 1 + (neighbours sharing it) entries.
    self%nshared = count(tag > 0)
    if (allocated(self%node)) deallocate(self%node, self%mptr, self%src)
    allocate(self%node(self%nshared), self%mptr(self%nshared + 1), &
             self%src(self%nshared + nlist), fill(self%nshared))
    u = 0; self%mptr(1) = 1
    do n = 1, grid%nnode
      if (tag(n) == 0) cycle
      u = u + 1
      self%node(u) = n
      self%mptr(u + 1) = self%mptr(u) + 1 + tag(n)
      tag(n) = u
    end do
    ! Contributions in rank order: the lower neighbours, this process, the higher ones.
    fill = self%mptr(1:self%nshared)
    do k = 1, self%nnbr
      if (self%nbr(k) > self%me) cycle
      call add_entries(k)
    end do
    do u = 1, self%nshared
      self%src(fill(u)) = 0; fill(u) = fill(u) + 1
    end do
    do k = 1, self%nnbr
      if (self%nbr(k) < self%me) cycle
      call add_entries(k)
    end do
    ! Ownership: this core less the cores of lower ranks.
    if (allocated(self%owned)) deallocate(self%owned)
    allocate(self%owned(grid%nnode))
    self%owned = .false.
    call mark(self%core(:, :, self%me + 1), .true.)
    do q = 0, self%me - 1
      call mark(overlap(self%core(:, :, self%me + 1), self%core(:, :, q + 1)), .false.)
    end do
  contains
    subroutine add_entries(kk)
      integer, intent(in) :: kk
      integer :: ee, uu
      do ee = self%ptr(kk), self%ptr(kk + 1) - 1
        uu = tag(self%list(ee))
        self%src(fill(uu)) = ee; fill(uu) = fill(uu) + 1
      end do
    end subroutine add_entries

    subroutine mark(b, v)
      integer, intent(in) :: b(3, 2)
      logical, intent(in) :: v
      integer, allocatable :: ids(:)
      if (any(b(:, 1) > b(:, 2))) return
      allocate(ids(product(b(:, 2) - b(:, 1) + 1)))
      call box_ids(grid, b, ids)
      self%owned(ids) = v
    end subroutine mark
  end subroutine build_plan

  ! The intersection of two boxes (empty: some lo > hi).
  pure function overlap(a, b) result(o)
    integer, intent(in) :: a(3, 2), b(3, 2)
    integer :: o(3, 2)
    o(:, 1) = max(a(:, 1), b(:, 1)); o(:, 2) = min(a(:, 2), b(:, 2))
  end function overlap

  ! The stored grid's node ids of box b (whole-grid 0-based ijk, inside the stored grid), in
  ! increasing order.
  pure subroutine box_ids(grid, b, ids)
    type(empm_grid_t), intent(in) :: grid
    integer, intent(in) :: b(3, 2)
    integer, intent(out) :: ids(:)
    integer :: i, j, k, e
    e = 0
    do k = b(3, 1), b(3, 2)
      do j = b(2, 1), b(2, 2)
        do i = b(1, 1), b(1, 2)
          e = e + 1
          ids(e) = grid%id0 + i + grid%ln(1) * (j + grid%ln(2) * k)
        end do
      end do
    end do
  end subroutine box_ids

  !> Whether node `id` is in this process's core (the nodes its particles reach): there its
  !> values are the serial run's. Always .true. when serial.
  pure logical function halo_in_core(self, grid, id) result(yes)
    class(empm_halo_t), intent(in) :: self !! halo
    type(empm_grid_t), intent(in) :: grid  !! background grid
    integer, intent(in) :: id              !! node
    integer :: ijk(3)
    yes = .true.
    if (.not. self%active) return
    ijk = grid%node_ijk(id)
    yes = all(ijk >= self%core(:, 1, self%me + 1) .and. ijk <= self%core(:, 2, self%me + 1))
  end function halo_in_core

  !> a ← Σ over the processes of a on this process's region (nodal scalars (nnode)).
  subroutine sum_1(self, comm, a)
    class(empm_halo_t), intent(inout) :: self      !! halo (buffers)
    type(empm_comm_t), intent(in) :: comm          !! the run's processes
    real(wp), intent(inout), contiguous, target :: a(:) !! partial sums in, sums out
    real(wp), pointer :: a2(:,:)
    if (.not. self%active) return
    a2(1:1, 1:size(a)) => a
    call exchange(self, comm, 1, a2)
  end subroutine sum_1

  !> a ← Σ over the processes of a on this process's region (nodal vectors (m, nnode)).
  subroutine sum_2(self, comm, a)
    class(empm_halo_t), intent(inout) :: self      !! halo (buffers)
    type(empm_comm_t), intent(in) :: comm          !! the run's processes
    real(wp), intent(inout), contiguous :: a(:,:)  !! partial sums in, sums out (m <= 3)
    if (.not. self%active) return
    call exchange(self, comm, size(a, 1), a)
  end subroutine sum_2

  ! Pack, swap, and add every shared node's partials in rank order.
  subroutine exchange(self, comm, m, a)
    type(empm_halo_t), intent(inout) :: self
    type(empm_comm_t), intent(in) :: comm
    integer, intent(in) :: m
    real(wp), intent(inout) :: a(:,:)
    call self%pack(m, a)
    call comm%swap(self%nbr(1:self%nnbr), self%ptr(1:self%nnbr + 1), m, self%sbuf, self%rbuf)
    self%sent = self%sent + 8_int64 * m * size(self%list)
    call self%merge(m, a)
  end subroutine exchange

  !> Copy this process's partial values of the shared nodes into the send buffer, neighbour
  !> by neighbour (the first half of a sum; public for tests).
  pure subroutine halo_pack(self, m, a)
    class(empm_halo_t), intent(inout) :: self  !! halo (sbuf is set)
    integer, intent(in) :: m                   !! values per node (<= 3)
    real(wp), intent(in) :: a(:,:)             !! partial nodal values (>= m, nnode)
    integer :: e
    do e = 1, size(self%list)
      self%sbuf(m * (e - 1) + 1:m * e) = a(1:m, self%list(e))
    end do
  end subroutine halo_pack

  !> With the neighbours' partials in the receive buffer: every shared node's sum, added in
  !> rank order (the second half of a sum; public for tests).
  pure subroutine halo_merge(self, m, a)
    class(empm_halo_t), intent(in) :: self     !! halo (rbuf holds the neighbours' partials)
    integer, intent(in) :: m                   !! values per node (<= 3)
    real(wp), intent(inout) :: a(:,:)          !! partial values in, sums on shared nodes out
    real(wp) :: own(3), s(3)
    integer :: u, j
    do u = 1, self%nshared
      own(1:m) = a(1:m, self%node(u))
      j = self%mptr(u)
      s(1:m) = part(self%src(j))
      do j = self%mptr(u) + 1, self%mptr(u + 1) - 1
        s(1:m) = s(1:m) + part(self%src(j))
      end do
      a(1:m, self%node(u)) = s(1:m)
    end do
  contains
    pure function part(k) result(v)
      integer, intent(in) :: k
      real(wp) :: v(m)
      if (k == 0) then
        v = own(1:m)
      else
        v = self%rbuf(m * (k - 1) + 1:m * k)
      end if
    end function part
  end subroutine halo_merge
end module empm_halo
