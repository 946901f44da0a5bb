!> Sharing a model's particles among the processes of its communicator (docs/parallel.md):
!> each process keeps the particles of its box of cells, the boxes cut from the particle
!> counts by recursive coordinate bisection; the grid stays whole on every process.
module empm_partition
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise_error, empm_alloc_error
  use empm_strings, only: str
  use empm_model, only: empm_model_t
  use empm_comm, only: empm_comm_t
  use empm_particles, only: PARTICLE_FIELDS
  use empm_loads, only: empm_traction_t
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_decomp, only: empm_rcb, empm_cell_of, empm_box_owner
  implicit none
  private
  public :: empm_partition_particles, empm_share_traction_state, empm_gather_particles, empm_rebalance
  public :: empm_copy_for_output, empm_list_loaded, empm_gather_snapshot

contains

  !> Keep on this process the particles of its box (every process must hold the same complete
  !> set before: the case read, or a checkpoint read, on each). The particles keep their ids,
  !> which order them in the output; nodal masses and the empty-node threshold are those of
  !> the whole set. Serial: nothing changes.
  subroutine empm_partition_particles(model, err, hist, dealt)
    type(empm_model_t), intent(inout) :: model          !! model (set up)
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    type(empm_history_t), intent(inout), optional :: hist !! a record with snapshots of every
                                                        !! particle (a checkpoint's): they keep
                                                        !! this process's particles too
    logical, intent(in), optional :: dealt              !! each process holds a share of the
                                                        !! particles (the case read with a
                                                        !! communicator: `empm_read_case`),
                                                        !! not every one: they move to the
                                                        !! process of their box (collective)
    type(empm_error_t) :: e
    integer, allocatable :: counts(:), mine(:), owner(:)
    integer :: lo(3, model%comm%nranks), hi(3, model%comm%nranks), nc(3)
    integer :: p, n
    real(wp) :: mass_tol
    if (.not. model%comm%parallel()) then
      ! One process keeps every particle; a case read to be shared gets its basis here.
      if (.not. allocated(model%basis%nn) .and. .not. allocated(model%basis%cell)) &
        call model%set_runs(err)
      return
    end if
    call cell_counts(model, nc, counts)
    if (present(dealt)) then
      if (dealt) then
        ! Each process holds a share: the counts, and the lightest particle, are everyone's.
        call model%comm%sum_counts(counts)
        call empm_rcb(model%grid%ndim, nc(1:model%grid%ndim), counts, model%comm%nranks, lo, hi)
        mass_tol = huge(1.0_wp)
        if (model%pts%np > 0) mass_tol = model%nodes%mass_tol
        model%nodes%mass_tol = model%comm%min_real(mass_tol)
        call move_particles(model, owners(model, lo, hi), e)
        if (e%code /= 0) then
          call empm_raise_error(e, err); return
        end if
        call keep_boxes(model, lo, hi)
        model%boxes0 = model%boxes
        call model%share_region()
        return
      end if
    end if
    ! Every process holds every particle here: its own counts are the whole run's.
    call empm_rcb(model%grid%ndim, nc(1:model%grid%ndim), counts, model%comm%nranks, lo, hi)
    owner = owners(model, lo, hi)
    n = count(owner == model%comm%rank)
    allocate(mine(n))
    n = 0
    do p = 1, model%pts%np
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
    call keep_boxes(model, lo, hi)
    model%boxes0 = model%boxes
    ! The first window of the grid (the whole grid's nodal storage is given back).
    call model%share_region()
  end subroutine empm_partition_particles

  ! The particles this process holds in each cell (direction 1 fastest), and the cells per
  ! direction (1 beyond ndim).
  subroutine cell_counts(model, nc, counts)
    type(empm_model_t), intent(in) :: model
    integer, intent(out) :: nc(3)
    integer, allocatable, intent(out) :: counts(:)
    integer :: p, ijk(3), c
    nc = 1
    nc(1:model%grid%ndim) = model%grid%ncell(1:model%grid%ndim)
    allocate(counts(product(nc)))
    counts = 0
    do p = 1, model%pts%np
      ijk = empm_cell_of(model%grid, model%pts%x(:, p))
      c = ijk(1) + nc(1) * ((ijk(2) - 1) + nc(2) * (ijk(3) - 1))
      counts(c) = counts(c) + 1
    end do
  end subroutine cell_counts

  ! The process (from 0) whose box holds each particle's cell.
  function owners(model, lo, hi) result(dest)
    type(empm_model_t), intent(in) :: model
    integer, intent(in) :: lo(:,:), hi(:,:)
    integer :: dest(model%pts%np)
    integer :: p
    do p = 1, model%pts%np
      dest(p) = empm_box_owner(lo, hi, empm_cell_of(model%grid, model%pts%x(:, p))) - 1
    end do
  end function owners

  ! The boxes as (3, 2, nranks): first and last cell of each process's.
  subroutine keep_boxes(model, lo, hi)
    type(empm_model_t), intent(inout) :: model
    integer, intent(in) :: lo(:,:), hi(:,:)
    if (allocated(model%boxes)) deallocate(model%boxes)
    allocate(model%boxes(3, 2, size(lo, 2)))
    model%boxes(:, 1, :) = lo; model%boxes(:, 2, :) = hi
  end subroutine keep_boxes

  !> Cut the boxes again from where the particles are now, and move every particle to the
  !> process of its box (each process's particles then in id order). `before` and `static`
  !> report the largest process's share over the mean: in the boxes being replaced, and in the
  !> first ones (what a split never re-cut would hold). `moved` is false when no particle
  !> changed process (the new boxes are kept). Surface tractions follow their particles
  !> ([[empm_share_traction_state]], then their entries found again by id). `migrated` counts
  !> the particles that changed process (all processes together). Serial: nothing changes.
  subroutine empm_rebalance(model, before, static, moved, migrated, err)
    type(empm_model_t), intent(inout) :: model          !! model (shared among processes)
    real(wp), intent(out) :: before                     !! max/mean in the boxes replaced
    real(wp), intent(out) :: static                     !! max/mean in the first boxes
    logical, intent(out) :: moved                       !! the particles were redistributed
    integer, intent(out) :: migrated                    !! particles that changed process
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    type(empm_error_t) :: e
    integer, allocatable :: counts(:), dest(:)
    integer :: lo(3, model%comm%nranks), hi(3, model%comm%nranks), nc(3)
    integer :: nd
    before = 1.0_wp; static = 1.0_wp; moved = .false.; migrated = 0
    if (.not. model%comm%parallel() .or. .not. allocated(model%boxes)) return
    nd = model%grid%ndim
    call cell_counts(model, nc, counts)
    call model%comm%sum_counts(counts)
    before = share(model%boxes)
    static = share(model%boxes0)
    call empm_rcb(nd, nc(1:nd), counts, model%comm%nranks, lo, hi)
    call keep_boxes(model, lo, hi)
    ! Every particle to the process of its box; nothing to do when none changes process.
    dest = owners(model, lo, hi)
    migrated = model%comm%sum_int(count(dest /= model%comm%rank))
    if (migrated == 0) return
    call move_particles(model, dest, e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    moved = .true.

  contains

    ! Largest process's share of the particles over the mean, in the boxes b.
    real(wp) function share(b)
      integer, intent(in) :: b(:,:,:)
      real(wp) :: per(size(b, 3))
      integer :: q, i, j, k
      per = 0.0_wp
      do q = 1, size(b, 3)
        do k = b(3, 1, q), b(3, 2, q)
          do j = b(2, 1, q), b(2, 2, q)
            do i = b(1, 1, q), b(1, 2, q)
              per(q) = per(q) + counts(i + nc(1) * ((j - 1) + nc(2) * (k - 1)))
            end do
          end do
        end do
      end do
      share = maxval(per) / max(sum(per) / size(per), 1.0_wp)
    end function share
  end subroutine empm_rebalance

  ! Every particle to process dest(p), each process's then in id order, as the set was made
  ! (runs of one material stay together), with the storage of their basis; the empty-node
  ! threshold kept; tractions follow their particles by id. A failure (out of memory) on one
  ! process is everyone's: the callers' next steps are collective. Collective.
  subroutine move_particles(model, dest, e)
    type(empm_model_t), intent(inout) :: model
    integer, intent(in) :: dest(:)
    type(empm_error_t), intent(inout) :: e
    real(wp) :: mass_tol
    logical :: ok
    call exchange_fields(model, dest, ok)
    if (ok) then
      mass_tol = model%nodes%mass_tol
      call model%set_runs(e)
      model%nodes%mass_tol = mass_tol
    else
      e = empm_alloc_error('particle storage ('//str(model%pts%np)//' particles moved '// &
        'between processes)', 8_int64 * model%pts%row_size() * model%pts%np, '')
    end if
    call model%comm%agree(e)
    if (e%code /= 0) return
    call empm_share_traction_state(model)
    call map_tractions(model)
  end subroutine move_particles

  ! Every particle to process dest(p), field by field (the id first), each process's then in id
  ! order; each field's storage released once sent, so that a process holds a few copies of
  ! one field at a time, not its set twice. `ok` is false on a process that ran out of memory
  ! (it takes part in the remaining exchanges, which are collective).
  subroutine exchange_fields(model, dest, ok)
    type(empm_model_t), intent(inout) :: model
    integer, intent(in) :: dest(:)
    logical, intent(out) :: ok
    real(wp), allocatable :: cols(:,:), got(:,:)
    integer, allocatable :: order(:)
    integer :: f, np
    np = model%pts%np
    ok = .true.
    do f = 1, PARTICLE_FIELDS
      call model%pts%take_field(f, cols)
      call model%comm%exchange_rows(cols, np, dest, got)
      deallocate(cols)
      if (f == 1) order = id_order(nint(got(1, :)))
      if (ok) call model%pts%put_field(f, got, order, ok)
      deallocate(got)
    end do
    model%pts%np = size(order)
  end subroutine exchange_fields

  !> Every process gets the tractions' shape-function state (λ at each face centre, which
  !> only the process holding the particle updates, as `part` still says): after the
  !> particles moved, before their entries are found again, and before the root writes a
  !> checkpoint. Collective; serial: nothing.
  subroutine empm_share_traction_state(model)
    type(empm_model_t), intent(inout) :: model !! model (shared among processes)
    integer :: k, j
    if (.not. model%comm%parallel() .or. model%loads%ntraction() == 0) return
    do k = 1, size(model%loads%tractions)
      associate (tr => model%loads%tractions(k))
        if (.not. allocated(tr%lam)) cycle
        do j = 1, size(tr%part)
          if (tr%part(j) == 0) tr%lam(:, j) = 0.0_wp
        end do
        call model%comm%sum(tr%lam)
      end associate
    end do
  end subroutine empm_share_traction_state

  ! After the particles moved: each traction entry's index on this process, from its particle's
  ! id, 0 when another holds it.
  subroutine map_tractions(model)
    type(empm_model_t), intent(inout) :: model
    integer :: k
    if (model%loads%ntraction() == 0) return
    do k = 1, size(model%loads%tractions)
      call find_ids(model, model%loads%tractions(k))
    end do
  end subroutine map_tractions

  ! `part` from `pid`: this process's index of each loaded particle (its particles are in id
  ! order: a binary search), 0 when another process holds it.
  subroutine find_ids(model, tr)
    type(empm_model_t), intent(in) :: model
    type(empm_traction_t), intent(inout) :: tr
    integer :: j, lo, hi, mid
    associate (id => model%pts%id)
      do j = 1, size(tr%pid)
        tr%part(j) = 0
        lo = 1; hi = model%pts%np
        do while (lo <= hi)
          mid = (lo + hi) / 2
          if (id(mid) == tr%pid(j)) then
            tr%part(j) = mid; exit
          else if (id(mid) < tr%pid(j)) then
            lo = mid + 1
          else
            hi = mid - 1
          end if
        end do
      end do
    end associate
  end subroutine find_ids

  !> A traction selected on a particle set dealt out among the processes (each selected from
  !> its own particles, `part` their indices, with their `area` and `offset`): every process
  !> gets the whole list in id order, as one process holding every particle selects it, by id
  !> (`pid`), with its own particles' indices in `part` and 0 for the others', as after the
  !> partition. Collective.
  subroutine empm_list_loaded(model, tr)
    type(empm_model_t), intent(in) :: model     !! the model whose particles are dealt out
    type(empm_traction_t), intent(inout) :: tr  !! the traction, selected on this process
    real(wp), allocatable :: mine(:,:), all(:,:)
    integer, allocatable :: ids(:), order(:)
    integer :: j, m
    m = size(tr%part)
    allocate(mine(3, m))
    do j = 1, m
      mine(:, j) = [real(model%pts%id(tr%part(j)), wp), tr%area(j), tr%offset(j)]
    end do
    call model%comm%gather_rows(mine, m, all, to_all=.true.)
    ids = nint(all(1, :))
    order = id_order(ids)
    tr%pid = ids(order); tr%area = all(2, order); tr%offset = all(3, order)
    deallocate(tr%part)
    allocate(tr%part(size(ids)))
    call find_ids(model, tr)
  end subroutine empm_list_loaded

  ! The permutation that sorts distinct integers increasingly (merge sort: n log n, stable).
  pure function id_order(key) result(idx)
    integer, intent(in) :: key(:)
    integer :: idx(size(key))
    integer :: tmp(size(key)), width, lo, mid, hi, i, j, k, n
    n = size(key)
    idx = [(i, i = 1, n)]
    width = 1
    do while (width < n)
      lo = 1
      do while (lo <= n)
        mid = min(lo + width - 1, n); hi = min(lo + 2 * width - 1, n)
        i = lo; j = mid + 1; k = lo
        do while (i <= mid .and. j <= hi)
          if (key(idx(j)) < key(idx(i))) then
            tmp(k) = idx(j); j = j + 1
          else
            tmp(k) = idx(i); i = i + 1
          end if
          k = k + 1
        end do
        tmp(k:k + mid - i) = idx(i:mid); k = k + mid - i + 1
        tmp(k:k + hi - j) = idx(j:hi)
        lo = lo + 2 * width
      end do
      idx = tmp
      width = 2 * width
    end do
  end function id_order

  ! A snapshot of every particle keeps the columns `mine`.
  subroutine keep_snapshot(sn, mine)
    type(empm_snapshot_t), intent(inout) :: sn
    integer, intent(in) :: mine(:)
    if (allocated(sn%file)) return
    sn%x = sn%x(:, mine); sn%v = sn%v(:, mine)
    sn%stress = sn%stress(:, mine); sn%strain = sn%strain(:, mine)
    sn%m = sn%m(mine); sn%vol = sn%vol(mine); sn%rho = sn%rho(mine)
    sn%state = sn%state(:, mine); sn%id = sn%id(mine)
  end subroutine keep_snapshot

  ! Each traction keeps every loaded particle, by id; those this process holds get their index
  ! as it will be (the others 0), so that a re-cut or a restart can share them out again.
  subroutine keep_tractions(model, owner)
    type(empm_model_t), intent(inout) :: model
    integer, intent(in) :: owner(:)
    integer, allocatable :: newidx(:)
    integer :: k, j, p, q
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
        if (.not. allocated(tr%pid)) tr%pid = model%pts%id(tr%part)
        do j = 1, size(tr%part)
          tr%part(j) = newidx(tr%part(j))
        end do
      end associate
    end do
  end subroutine keep_tractions

  !> What writing the results or a checkpoint reads of a model, copied: the grid's geometry,
  !> the particles, the shape family and materials (their names and state variables), the
  !> loads (the tractions' state), the communicator, time, step and residual. Not the nodal
  !> fields, the basis or the halo, which for LME shapes outweigh the particles: a process
  !> writing while its run goes on (a checkpoint, `empm_model_write`) then holds two copies of
  !> its particles only.
  subroutine empm_copy_for_output(model, copy)
    type(empm_model_t), intent(in) :: model    !! the running model
    type(empm_model_t), intent(out) :: copy    !! its copy for output
    copy%grid = model%grid
    copy%pts = model%pts
    if (allocated(model%shape)) allocate(copy%shape, source=model%shape)
    if (allocated(model%mats)) copy%mats = model%mats
    copy%loads = model%loads
    copy%comm = model%comm
    if (allocated(model%boxes)) copy%boxes = model%boxes
    copy%t = model%t; copy%step = model%step
    copy%track = model%track; copy%residual = model%residual
  end subroutine empm_copy_for_output

  !> After a parallel run: the root process gets every particle, in id (generation) order,
  !> and every snapshot likewise, to write the results as a serial run would; the other
  !> processes keep theirs. With `blocks`, each process gets instead a contiguous block of ids
  !> (process r: ids ⌊rN/P⌋ + 1 .. ⌊(r + 1)N/P⌋ of N on P processes), in id order, and every
  !> snapshot's rows of those ids: the processes then write one file together, each its block
  !> (empm_write_results), and no process holds more than its share. Serial: nothing changes.
  !> The particles are for output only afterwards: the run cannot go on with them.
  subroutine empm_gather_particles(model, hist, err, blocks)
    type(empm_model_t), intent(inout) :: model          !! model (its particles replaced on the
                                                        !! root, or by the block)
    type(empm_history_t), intent(inout) :: hist         !! record (its snapshots likewise)
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    logical, intent(in), optional :: blocks             !! each process a block of ids
    real(wp), allocatable :: rows(:,:), all(:,:)
    integer, allocatable :: dest(:), order(:)
    type(empm_error_t) :: e
    integer :: m, np, k, nd, ns, oid, first, last, ntotal
    logical :: by_block, ok
    if (.not. model%comm%parallel()) return
    by_block = .false.
    if (present(blocks)) by_block = blocks
    np = model%pts%np; nd = model%grid%ndim; ns = model%pts%nstate
    ntotal = model%comm%sum_int(np)
    ! This process's ids: all (the root), none (another process) or its block.
    first = 1; last = ntotal
    if (by_block) then
      first = block_start(model%comm%rank) + 1; last = block_start(model%comm%rank + 1)
    else if (.not. model%comm%is_root()) then
      last = 0
    end if
    do k = 1, hist%nsnap
      call empm_gather_snapshot(model%comm, hist%snap(k), by_block)
    end do
    if (by_block) then
      ! Field by field (exchange_fields): a process holds a few copies of one field at a
      ! time, not its whole set twice.
      dest = [(owner(model%pts%id(k)), k = 1, np)]
      call exchange_fields(model, dest, ok)
      if (.not. ok) call empm_raise_error(empm_alloc_error('particle storage ('// &
        str(model%pts%np)//' particles, a block of ids for the output)', &
        8_int64 * model%pts%row_size() * model%pts%np, ''), err)
      ! A block is written and dropped: it needs no material runs nor basis storage.
      return
    end if
    m = model%pts%row_size()
    allocate(rows(m, np))
    call model%pts%pack_rows([(k, k = 1, np)], rows)
    oid = model%pts%id_row()
    ! On a process other than the root, gathering to it, the model keeps its particles.
    call model%comm%gather_rows(rows, np, all)
    if (.not. model%comm%is_root()) return
    ! At most two copies of the particles at a time: the storage goes once sent.
    call model%pts%alloc(nd, 0, ns)
    deallocate(rows)
    ! Particle k of the result is id first + k − 1.
    allocate(order(last - first + 1))
    do k = 1, size(all, 2)
      order(nint(all(oid, k)) - first + 1) = k
    end do
    call model%pts%set_from_rows(nd, ns, all, size(order), e, order=order)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    ! The root's model stays a whole one (material runs, basis storage).
    call model%set_runs(e)
    if (e%code /= 0) call empm_raise_error(e, err)

  contains

    integer function block_start(r)
      integer, intent(in) :: r
      block_start = id_block_start(r, ntotal, model%comm%nranks)
    end function block_start

    integer function owner(i)
      integer, intent(in) :: i
      owner = id_block_owner(i, ntotal, model%comm%nranks)
    end function owner
  end subroutine empm_gather_particles

  !> One snapshot's particles (its columns in the order of `sn%id`: the process's particles
  !> when it was taken) to the root in id order, the others then holding none, or with
  !> `blocks` to the process of each id's block (as [[empm_gather_particles]]). Collective; a
  !> snapshot held in a file (`sn%file`) has nothing to move.
  subroutine empm_gather_snapshot(comm, sn, blocks)
    type(empm_comm_t), intent(in) :: comm          !! the run's processes
    type(empm_snapshot_t), intent(inout) :: sn     !! the snapshot (replaced)
    logical, intent(in) :: blocks                  !! to the blocks of ids, else to the root
    real(wp), allocatable :: a(:,:)
    integer, allocatable :: ord(:), dest(:)
    integer :: q, n, ntotal, first, last
    if (allocated(sn%file)) return
    n = size(sn%id) ! the particles it held then (before a re-cut, perhaps)
    ntotal = comm%sum_int(n)
    first = 1; last = ntotal
    if (blocks) then
      first = id_block_start(comm%rank, ntotal, comm%nranks) + 1
      last = id_block_start(comm%rank + 1, ntotal, comm%nranks)
      dest = [(id_block_owner(sn%id(q), ntotal, comm%nranks), q = 1, n)]
    else if (.not. comm%is_root()) then
      last = 0
    end if
    ! Field by field, each in the same order (the exchange keeps each process's order): a
    ! process holds a few copies of one field at a time, not of the whole snapshot. The ids
    ! first: particle q of the result is id first + q − 1, arrived in column ord(q).
    call move(reshape(real(sn%id(1:n), wp), [1, n]))
    allocate(ord(max(last - first + 1, 0)))
    do q = 1, size(a, 2)
      ord(nint(a(1, q)) - first + 1) = q
    end do
    call move2(sn%x); call move2(sn%v); call move2(sn%stress); call move2(sn%strain)
    call move2(sn%state)
    call move1(sn%m); call move1(sn%vol); call move1(sn%rho)
    sn%id = [(q, q = first, last)]
  contains
    ! This process's columns of `rows` to where they go, received in `a`.
    subroutine move(rows)
      real(wp), intent(in), contiguous :: rows(:,:)
      integer :: m
      m = size(rows, 1)
      if (allocated(a)) deallocate(a)
      if (blocks) then
        call comm%exchange_rows(rows, n, dest, a)
      else
        call comm%gather_rows(rows, n, a)
        ! What another process held went to the root.
        if (.not. comm%is_root()) then
          if (allocated(a)) deallocate(a)
          allocate(a(m, 0))
        end if
      end if
    end subroutine move
    subroutine move2(f)
      real(wp), allocatable, intent(inout) :: f(:,:)
      integer :: m
      m = size(f, 1)
      if (m == 0) then ! no state variables: nothing to send
        deallocate(f); allocate(f(0, size(ord))); return
      end if
      call move(f)
      deallocate(f)
      f = a(:, ord)
      deallocate(a)
    end subroutine move2
    subroutine move1(f)
      real(wp), allocatable, intent(inout) :: f(:)
      call move(reshape(f, [1, n]))
      deallocate(f)
      f = a(1, ord)
      deallocate(a)
    end subroutine move1
  end subroutine empm_gather_snapshot

  ! The first id's position (0-based) of process r's block of ids, of ntotal on nranks
  ! processes; id_block_start(nranks) = ntotal.
  pure integer function id_block_start(r, ntotal, nranks)
    integer, intent(in) :: r, ntotal, nranks
    id_block_start = int((int(r, int64) * ntotal) / nranks)
  end function id_block_start

  ! The process whose block holds id i: the r with ⌊rN/P⌋ < i ≤ ⌊(r + 1)N/P⌋.
  pure integer function id_block_owner(i, ntotal, nranks)
    integer, intent(in) :: i, ntotal, nranks
    id_block_owner = int((int(i, int64) * nranks - 1) / ntotal)
  end function id_block_owner
end module empm_partition
