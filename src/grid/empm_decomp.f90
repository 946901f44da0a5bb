!> Splitting the grid's cells among processes: recursive coordinate bisection (RCB) of the cell
!> box by particle counts, along cell planes, into one box of cells per process
!> (docs/parallel.md). Pure kernels; the model layer applies them.
module empm_decomp
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  implicit none
  private
  public :: empm_rcb, empm_cell_of, empm_box_owner

contains

  !> Cut the cells 1..ncell(k) (per direction) into `nparts` boxes, each holding about the
  !> same number of particles: the box of a group of parts is cut across its longest side at
  !> the cell plane that splits its count in the ratio of the two halves' part numbers, and
  !> each side is cut again (recursive coordinate bisection). Box q is lo(:, q) .. hi(:, q)
  !> (cell indices, inclusive); a box that could not be cut further leaves its later parts
  !> empty (hi < lo in direction 1). `counts` holds the particles per cell, direction 1
  !> fastest.
  pure subroutine empm_rcb(ndim, ncell, counts, nparts, lo, hi)
    integer, intent(in) :: ndim                  !! spatial dimension
    integer, intent(in) :: ncell(:)              !! cells per direction (ndim)
    integer, intent(in) :: counts(:)             !! particles per cell (product of ncell)
    integer, intent(in) :: nparts                !! number of boxes (processes)
    integer, intent(out) :: lo(3, nparts)        !! first cell of each box
    integer, intent(out) :: hi(3, nparts)        !! last cell of each box
    integer :: box_lo(3), box_hi(3), n3(3)
    n3 = 1
    n3(1:ndim) = ncell(1:ndim)
    box_lo = 1; box_hi = n3
    lo = 1; hi = 0
    call split(ndim, n3, counts, box_lo, box_hi, 1, nparts, lo, hi)
  end subroutine empm_rcb

  ! Cut the box blo..bhi for parts q0 .. q0 + n − 1 (empm_rcb).
  pure recursive subroutine split(ndim, n3, counts, blo, bhi, q0, n, lo, hi)
    integer, intent(in) :: ndim, n3(3), counts(:), blo(3), bhi(3), q0, n
    integer, intent(inout) :: lo(:,:), hi(:,:)
    integer :: ax, k, c, n1, cut, best
    integer(int64) :: total, acc, target, prof(maxval(n3))
    integer :: alo(3), ahi(3), i, j, l
    if (n == 1) then
      lo(:, q0) = blo; hi(:, q0) = bhi
      return
    end if
    ! The longest side that can be cut (in cells).
    ax = 0; best = 1
    do k = 1, ndim
      if (bhi(k) - blo(k) + 1 > best) then
        best = bhi(k) - blo(k) + 1; ax = k
      end if
    end do
    if (ax == 0) then ! one cell: the first part takes it, the others stay empty
      lo(:, q0) = blo; hi(:, q0) = bhi
      return
    end if
    ! Particles per cell plane across the box along ax.
    prof = 0
    do l = blo(3), bhi(3)
      do j = blo(2), bhi(2)
        do i = blo(1), bhi(1)
          c = i + n3(1) * ((j - 1) + n3(2) * (l - 1))
          select case (ax)
          case (1); prof(i) = prof(i) + counts(c)
          case (2); prof(j) = prof(j) + counts(c)
          case default; prof(l) = prof(l) + counts(c)
          end select
        end do
      end do
    end do
    n1 = n / 2
    total = sum(prof(blo(ax):bhi(ax)))
    ! The plane after which the count is closest to total n1/n (each side keeps a cell).
    target = (total * n1) / n
    acc = 0; cut = bhi(ax) - 1
    do c = blo(ax), bhi(ax) - 1
      if (acc + prof(c) >= target) then
        cut = c
        if (c > blo(ax) .and. target - acc < acc + prof(c) - target) cut = c - 1
        exit
      end if
      acc = acc + prof(c)
    end do
    if (total == 0) cut = blo(ax) + (bhi(ax) - blo(ax)) * n1 / n
    alo = blo; ahi = bhi; ahi(ax) = cut
    call split(ndim, n3, counts, alo, ahi, q0, n1, lo, hi)
    alo = blo; ahi = bhi; alo(ax) = cut + 1
    call split(ndim, n3, counts, alo, ahi, q0 + n1, n - n1, lo, hi)
  end subroutine split

  !> The cell holding x (indices from 1, clamped to the grid: a particle on the upper face
  !> belongs to the last cell).
  pure function empm_cell_of(grid, x) result(ijk)
    type(empm_grid_t), intent(in) :: grid !! grid
    real(wp), intent(in) :: x(:)          !! position (ndim)
    integer :: ijk(3)                     !! cell indices (1 beyond ndim)
    integer :: k
    ijk = 1
    do k = 1, grid%ndim
      ijk(k) = min(grid%ncell(k), max(1, floor((x(k) - grid%origin(k)) / grid%h(k)) + 1))
    end do
  end function empm_cell_of

  !> The box (process) holding cell ijk, from [[empm_rcb]]'s boxes; 0 if none.
  pure integer function empm_box_owner(lo, hi, ijk) result(q)
    integer, intent(in) :: lo(:,:)  !! first cells (3, nparts)
    integer, intent(in) :: hi(:,:)  !! last cells (3, nparts)
    integer, intent(in) :: ijk(3)   !! cell
    do q = 1, size(lo, 2)
      if (all(ijk >= lo(:, q)) .and. all(ijk <= hi(:, q))) return
    end do
    q = 0
  end function empm_box_owner
end module empm_decomp
