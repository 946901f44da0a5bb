!> Sharing a model's particles among the processes of its communicator (docs/parallel.md):
!> each process keeps the particles of its box of cells, the boxes cut from the particle
!> counts by recursive coordinate bisection; the grid stays whole on every process.
module empm_partition
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise_error
  use empm_model, only: empm_model_t
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_decomp, only: empm_rcb, empm_cell_of, empm_box_owner
  implicit none
  private
  public :: empm_partition_particles, empm_gather_particles

contains

  !> Keep on this process the particles of its box (every process must hold the same complete
  !> set before: the case read, or a checkpoint read, on each). The particles keep their ids,
  !> which order them in the output; nodal masses and the empty-node threshold are those of
  !> the whole set. Serial: nothing changes.
  subroutine empm_partition_particles(model, err, hist)
    type(empm_model_t), intent(inout) :: model          !! model (set up)
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    type(empm_history_t), intent(inout), optional :: hist !! a record with snapshots of every
                                                        !! particle (a checkpoint's): they keep
                                                        !! this process's particles too
    type(empm_error_t) :: e
    integer, allocatable :: counts(:), mine(:), owner(:)
    integer :: lo(3, model%comm%nranks), hi(3, model%comm%nranks), ijk(3), nc(3)
    integer :: p, np, n, c
    real(wp) :: mass_tol
    if (.not. model%comm%parallel()) return
    np = model%pts%np
    nc = 1
    nc(1:model%grid%ndim) = model%grid%ncell(1:model%grid%ndim)
    allocate(counts(product(nc)), owner(np))
    counts = 0
    do p = 1, np
      ijk = empm_cell_of(model%grid, model%pts%x(:, p))
      c = ijk(1) + nc(1) * ((ijk(2) - 1) + nc(2) * (ijk(3) - 1))
      counts(c) = counts(c) + 1
    end do
    call empm_rcb(model%grid%ndim, nc(1:model%grid%ndim), counts, model%comm%nranks, lo, hi)
    n = 0
    do p = 1, np
      owner(p) = empm_box_owner(lo, hi, empm_cell_of(model%grid, model%pts%x(:, p))) - 1
      if (owner(p) == model%comm%rank) n = n + 1
    end do
    allocate(mine(n))
    n = 0
    do p = 1, np
      if (owner(p) == model%comm%rank) then
        n = n + 1; mine(n) = p
      end if
    end do
    mass_tol = model%nodes%mass_tol
    call keep_tractions(model, owner)
    call model%pts%keep(mine)
    if (present(hist)) then
      do p = 1, hist%nsnap
        call keep_snapshot(hist%snap(p), mine)
      end do
    end if
    call model%set_runs(e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    model%nodes%mass_tol = mass_tol
  end subroutine empm_partition_particles
  ! A snapshot of every particle keeps the columns `mine`.
  subroutine keep_snapshot(sn, mine)
    type(empm_snapshot_t), intent(inout) :: sn
    integer, intent(in) :: mine(:)
    sn%x = sn%x(:, mine); sn%v = sn%v(:, mine)
    sn%stress = sn%stress(:, mine); sn%strain = sn%strain(:, mine)
    sn%m = sn%m(mine); sn%vol = sn%vol(mine); sn%rho = sn%rho(mine)
    sn%state = sn%state(:, mine)
  end subroutine keep_snapshot

  ! Each traction keeps the loaded particles this process holds, renumbered as they will be.
  subroutine keep_tractions(model, owner)
    type(empm_model_t), intent(inout) :: model
    integer, intent(in) :: owner(:)
    integer, allocatable :: newidx(:), part(:)
    real(wp), allocatable :: area(:), offset(:), lam(:,:)
    integer :: k, j, n, p, q
    if (model%loads%ntraction() == 0) return
    allocate(newidx(size(owner)))
    q = 0
    do p = 1, size(owner)
      newidx(p) = 0
      if (owner(p) == model%comm%rank) then
        q = q + 1; newidx(p) = q
      end if
    end do
    do k = 1, size(model%loads%tractions)
      associate (tr => model%loads%tractions(k))
        n = count(newidx(tr%part) > 0)
        allocate(part(n), area(n), offset(n))
        if (allocated(tr%lam)) allocate(lam(size(tr%lam, 1), n))
        q = 0
        do j = 1, size(tr%part)
          if (newidx(tr%part(j)) == 0) cycle
          q = q + 1
          part(q) = newidx(tr%part(j)); area(q) = tr%area(j); offset(q) = tr%offset(j)
          if (allocated(tr%lam)) lam(:, q) = tr%lam(:, j)
        end do
        call move_alloc(part, tr%part); call move_alloc(area, tr%area)
        call move_alloc(offset, tr%offset)
        if (allocated(lam)) call move_alloc(lam, tr%lam)
      end associate
    end do
  end subroutine keep_tractions

  !> After a parallel run: the root process gets every particle, in id (generation) order,
  !> and every snapshot likewise, to write the results as a serial run would; the other
  !> processes keep theirs. Serial: nothing changes.
  subroutine empm_gather_particles(model, hist, err)
    type(empm_model_t), intent(inout) :: model          !! model (its particles replaced on the
                                                        !! root)
    type(empm_history_t), intent(inout) :: hist         !! record (its snapshots likewise)
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    real(wp), allocatable :: rows(:,:), all(:,:), sorted(:,:)
    type(empm_error_t) :: e
    integer :: m, np, k, nd, ns, oid
    integer, allocatable :: ids(:)
    if (.not. model%comm%parallel()) return
    np = model%pts%np; nd = model%grid%ndim; ns = model%pts%nstate
    ids = model%pts%id(1:np)
    do k = 1, hist%nsnap
      call gather_snapshot(hist%snap(k))
    end do
    m = model%pts%row_size()
    allocate(rows(m, np))
    call model%pts%pack_rows([(k, k = 1, np)], rows)
    call model%comm%gather_rows(rows, np, all)
    if (.not. model%comm%is_root()) return
    oid = m - ns ! the id's row (pack_rows)
    allocate(sorted(m, size(all, 2)))
    do k = 1, size(all, 2)
      sorted(:, nint(all(oid, k))) = all(:, k)
    end do
    call model%pts%set_from_rows(nd, ns, sorted, size(sorted, 2), e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    call model%set_runs(e)
    if (e%code /= 0) call empm_raise_error(e, err)

  contains

    ! One snapshot's particles (taken in this process's current order, `ids`).
    subroutine gather_snapshot(sn)
      type(empm_snapshot_t), intent(inout) :: sn
      real(wp), allocatable :: r(:,:), a(:,:), srt(:,:)
      integer :: mm, q, o
      mm = 1 + 2 * nd + 12 + 3 + ns
      allocate(r(mm, np))
      do q = 1, np
        r(1, q) = real(ids(q), wp)
        r(2:1 + nd, q) = sn%x(:, q); r(2 + nd:1 + 2 * nd, q) = sn%v(:, q)
        o = 1 + 2 * nd
        r(o + 1:o + 6, q) = sn%stress(:, q); r(o + 7:o + 12, q) = sn%strain(:, q)
        r(o + 13, q) = sn%m(q); r(o + 14, q) = sn%vol(q); r(o + 15, q) = sn%rho(q)
        r(o + 16:o + 15 + ns, q) = sn%state(:, q)
      end do
      call model%comm%gather_rows(r, np, a)
      if (.not. model%comm%is_root()) return
      allocate(srt(mm, size(a, 2)))
      do q = 1, size(a, 2)
        srt(:, nint(a(1, q))) = a(:, q)
      end do
      o = 1 + 2 * nd
      sn%x = srt(2:1 + nd, :); sn%v = srt(2 + nd:1 + 2 * nd, :)
      sn%stress = srt(o + 1:o + 6, :); sn%strain = srt(o + 7:o + 12, :)
      sn%m = srt(o + 13, :); sn%vol = srt(o + 14, :); sn%rho = srt(o + 15, :)
      sn%state = srt(o + 16:o + 15 + ns, :)
    end subroutine gather_snapshot
  end subroutine empm_gather_particles
end module empm_partition
