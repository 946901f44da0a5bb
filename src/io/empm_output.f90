!> Writes a run to HDF5 (layout in docs/output.md) and an XDMF file beside it for ParaView.
!>
!> The file is written under a temporary name unique to the writer (`OUT.<pid>-<n>.partial`,
!> created exclusively) and renamed when complete, so an interrupted run never leaves a file
!> that looks complete and two writers never share a partial file. A run stopped by a guard is
!> still written, with the last good state and the root attribute `complete = 0`. HDF5's own
!> error stack is not printed: a failed write is one message with the system's reason, and
!> every object is closed (no partial file, no crash at exit).
!>
!> [[empm_output_claim]] checks an output path before a run (it must be a regular file or
!> absent) and takes its lock (`OUT.lock`, holding the pid), so that a second run writing the
!> same file is refused at its start; [[empm_output_release]] removes the lock.
!>
!> The materials' state variables are written by name (`state/<name>`, one value per particle),
!> NaN for the particles whose material does not declare that name.
!>
!> The XDMF file (same folder, `.xmf`) is written atomically too and refers to the HDF5 file by
!> its bare name, so it opens from any working directory. Its fields come from the `xdmf`
!> subgroup of each frame, in the layouts XDMF readers agree on: vectors padded to 3 components
!> and symmetric tensors as full 3x3 tensors (9 components, row by row). Not `Tensor6`: VTK's
!> XDMF 2 reader expands Tensor6 in XDMF order (xx, xy, xz, yy, yz, zz) but its Xdmf3 readers
!> pass the 6 values through and ParaView labels them in VTK's order (XX, YY, ZZ, XY, YZ, XZ),
!> so no 6-value order reads right in both (docs/paraview.md).
module empm_output
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use, intrinsic :: iso_fortran_env, only: error_unit
  use hdf5, only: h5open_f, h5fcreate_f, h5fclose_f, H5F_ACC_EXCL_F, h5eset_auto_f, &
    h5dont_atexit_f
  use empm_kinds, only: wp
  use empm_h5, only: hid_t, h5_group, h5_close_group, h5_write, h5_attr, h5_part_t, &
    h5_open_read, h5_close_file, h5_read, h5_dims, h5_read_attr
  use hdf5, only: hsize_t
  use empm_h5_mpio, only: empm_h5_collective, h5_mpio_properties, h5_mpio_close
  use empm_error, only: empm_error_t, empm_raise, EMPM_ERR_IO, EMPM_ERR_INPUT
  use empm_files, only: empm_rename, empm_remove
  use empm_posix, only: empm_getpid, empm_process_alive, empm_path_kind, empm_errno, &
    empm_errno_text, empm_write_reason, empm_glob, PATH_MISSING, PATH_REGULAR, PATH_DIRECTORY
  use empm_version_info, only: empm_version
  use empm_strings, only: str
  use empm_model, only: empm_model_t
  use empm_comm, only: empm_comm_t
  use empm_material, only: STATE_NAME_LEN
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_particles, only: empm_particles_t
  implicit none
  private
  public :: empm_write_results, empm_output_meta_t, empm_xdmf_path
  public :: empm_output_claim, empm_output_release, empm_partial_name, empm_shared_file_t
  public :: empm_remove_stale_partials
  public :: empm_write_snapshot_file, empm_staging_path, empm_frame_header

  !> An HDF5 file written by the processes of a run: together (parallel HDF5, each process
  !> holding a block of consecutive particle ids, [[empm_h5_collective]]) or by one process.
  !> `create` opens it under a partial name (the root's, the same for all), `close` closes it
  !> and gives every process the worst outcome; then the root alone renames it.
  type :: empm_shared_file_t
    logical :: together = .false.  !! the processes write it together
    logical :: root = .true.       !! this process writes what is not per particle, renames
    integer :: first = 0           !! particles of the processes before this one
    integer :: ntotal = 0          !! particles in the file
    type(h5_part_t) :: pp          !! this process's part of a particle dataset
    type(h5_part_t) :: sh          !! its part of any other dataset (the root's array)
    integer(hid_t) :: fapl = 0     !! file access properties (MPI-IO), 0: none
    integer(hid_t) :: xfer = 0     !! data transfer properties (collective), 0: none
  contains
    procedure :: create => shared_create
    procedure :: close => shared_close
  end type empm_shared_file_t

  !> Descriptive metadata stored as root attributes.
  type :: empm_output_meta_t
    character(len=:), allocatable :: case_file   !! path of the case file ('' for API runs)
    character(len=:), allocatable :: case_text   !! full text of the case file
    character(len=:), allocatable :: shape       !! shape family identifier
    character(len=:), allocatable :: integrator  !! integrator identifier
    real(wp) :: cfl = 0.0_wp                     !! Courant number used
    real(wp) :: t_end = 0.0_wp                   !! requested end time [s]
  end type empm_output_meta_t

contains

  !> Write `model` (final state) and `hist` to `path` (+ `path` with .xmf), atomically.
  !>
  !> `together` (several processes with parallel HDF5: [[empm_h5_collective]]): called by
  !> every process, each holding a block of consecutive ids in id order, and the snapshots'
  !> rows of those ids (`empm_gather_particles(..., blocks=.true.)`); they open one file and
  !> write each its columns of every particle dataset, the root alone the rest, the XDMF file
  !> and the rename. An error is returned on the root (the callers agree on it). Otherwise one
  !> process calls it, holding every particle.
  subroutine empm_write_results(path, model, hist, meta, complete, status, err, together)
    character(len=*), intent(in) :: path               !! output HDF5 file
    type(empm_model_t), intent(in) :: model            !! state to store as /final (this
                                                       !! process's block when collective)
    type(empm_history_t), intent(in) :: hist           !! histories and snapshots (likewise)
    type(empm_output_meta_t), intent(in) :: meta       !! root attributes
    logical, intent(in) :: complete                    !! whether the run reached t_end
    character(len=*), intent(in) :: status             !! '' or the message that stopped it
    type(empm_error_t), intent(out), optional :: err   !! error, if present
    logical, intent(in), optional :: together          !! all processes write it (blocks)
    integer(hid_t) :: fid, g, gs, gp
    integer :: ierr, e, k, info, n, oserr, np
    character(len=:), allocatable :: tmp, xmf, xtmp, stat, why
    character(len=16) :: sname
    character(len=STATE_NAME_LEN), allocatable :: snames(:)
    integer, allocatable :: scol(:,:)
    type(empm_shared_file_t) :: sf
    type(empm_snapshot_t) :: held
    integer :: rk, rfail, src
    np = model%pts%np; rfail = 0
    ierr = 0
    call state_columns(model, snames, scol)
    ! A file whose close failed (its flush: disk full) stays open inside HDF5, and closing it
    ! again, as HDF5's clean-up at exit does, crashes (HDF5 1.10): no clean-up at exit (our
    ! files are all closed explicitly). Effective only before the library's first use.
    call h5dont_atexit_f(e)
    call h5open_f(e)
    ! Failures are reported once, by us, with the system's reason: not HDF5's error stacks.
    call h5eset_auto_f(0, e)
    call sf%create(path, model%comm, np, together, tmp, fid, e)
    if (e /= 0) then
      if (.not. sf%root) return
      oserr = empm_errno()
      call empm_raise(EMPM_ERR_IO, path//': cannot create HDF5 file '//tmp//': '// &
        empm_errno_text(oserr), err); return
    end if
    call h5_attr(fid, 'empm_version', empm_version(), ierr)
    call h5_attr(fid, 'complete', merge(1, 0, complete), ierr)
    ! An attribute of a file written together must be the same on every process: the root's.
    stat = 'completed'
    if (.not. complete) stat = trim('stopped: '//status)
    if (sf%together) call model%comm%bcast_text(stat, 0)
    call h5_attr(fid, 'status', stat, ierr)
    call h5_attr(fid, 'case_file', meta%case_file, ierr)
    call h5_attr(fid, 'case_text', meta%case_text, ierr)
    call h5_attr(fid, 'shape', meta%shape, ierr)
    call h5_attr(fid, 'integrator', meta%integrator, ierr)
    call h5_attr(fid, 'cfl', meta%cfl, ierr)
    call h5_attr(fid, 't_end', meta%t_end, ierr)
    call h5_attr(fid, 'ndim', model%grid%ndim, ierr)
    call h5_attr(fid, 'time', model%t, ierr)
    call h5_attr(fid, 'steps', model%step, ierr)
    call h5_attr(fid, 'mpi_ranks', model%comm%nranks, ierr)
    call h5_attr(fid, 'writers', merge(model%comm%nranks, 1, sf%together), ierr)

    call h5_group(fid, 'grid', g, ierr)
    call h5_attr(g, 'origin', model%grid%origin(1:model%grid%ndim), ierr)
    call h5_attr(g, 'h', model%grid%h(1:model%grid%ndim), ierr)
    call h5_attr(g, 'cells', model%grid%ncell(1), ierr)
    call h5_write(g, 'cells_per_direction', model%grid%ncell(1:model%grid%ndim), ierr, sf%sh)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'final', g, ierr)
    call h5_attr(g, 'time', model%t, ierr)
    call h5_attr(g, 'step', model%step, ierr)
    call write_state(g, model%pts, sf%pp, ierr)
    call write_state_vars(g, model%pts%state(:, 1:np), model%pts%mat(1:np), snames, scol, sf%pp, &
      ierr)
    call write_xdmf_fields(g, model%pts%x(:, 1:np), model%pts%x0(:, 1:np), model%pts%v(:, 1:np), &
      model%pts%stress(:, 1:np), model%pts%strain(:, 1:np), sf%pp, ierr)
    call h5_close_group(g, ierr)

    ! Polyvertex connectivity (0-based), shared by every frame: without it ParaView's XDMF
    ! reader builds no cells and its default view is empty.
    call h5_group(fid, 'xdmf', g, ierr)
    call h5_write(g, 'vertices', [(sf%first + k - 1, k = 1, np)], ierr, sf%pp)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'snapshots', gs, ierr)
    why = ''
    do k = 1, hist%nsnap
      write(sname, '(i6.6)') k - 1
      call h5_group(gs, trim(sname), g, ierr)
      call h5_attr(g, 'time', hist%snap(k)%t, ierr)
      call h5_attr(g, 'step', hist%snap(k)%step, ierr)
      if (allocated(hist%snap(k)%file)) then
        ! Written to its own file as it was taken: read back (this process's block), then
        ! written as one held in memory. A snapshot that cannot be read is written as zeros
        ! by every process (the writes stay collective), and the file then discarded.
        rk = 0
        call read_frame(hist%snap(k), sf, np, model%grid%ndim, model%pts%nstate, &
          model%pts%mat(1:np), snames, scol, held, rk, why)
        if (sf%together) then
          ! The reason of the lowest process that failed, for all.
          src = model%comm%min_int(merge(model%comm%rank, model%comm%nranks, rk /= 0))
          if (src < model%comm%nranks) then
            rk = 1
            if (.not. allocated(why)) why = ''
            call model%comm%bcast_text(why, src)
          end if
        end if
        if (rk /= 0) then
          rfail = 1; held = empty_frame(model%grid%ndim, model%pts%nstate, np)
        end if
        call write_snapshot(held)
      else
        call write_snapshot(hist%snap(k))
      end if
      call h5_close_group(g, ierr)
    end do
    call h5_close_group(gs, ierr)

    call h5_group(fid, 'history', g, ierr)
    call h5_write(g, 'time', hist%t(1:hist%nt), ierr, sf%sh)
    call h5_write(g, 'kinetic_energy', hist%kinetic(1:hist%nt), ierr, sf%sh)
    call h5_write(g, 'strain_energy', hist%strain(1:hist%nt), ierr, sf%sh)
    call h5_write(g, 'gravity_potential', hist%gravity(1:hist%nt), ierr, sf%sh)
    if (hist%tracked) then
      ! Residual and reactions (docs/output.md), recorded when the model tracks them.
      call h5_write(g, 'residual', hist%residual(1:hist%nt), ierr, sf%sh)
      if (hist%nset > 0) then
        call h5_group(g, 'reaction', gs, ierr)
        do k = 1, hist%nset
          call h5_group(gs, trim(hist%set_name(k)), gp, ierr)
          call h5_write(gp, 'force', hist%reaction(:, k, 1:hist%nt), ierr, sf%sh)
          call h5_write(gp, 'displacement', hist%set_disp(:, k, 1:hist%nt), ierr, sf%sh)
          call h5_close_group(gp, ierr)
        end do
        call h5_close_group(gs, ierr)
      end if
    end if
    call h5_close_group(g, ierr)

    call h5_group(fid, 'probes', gs, ierr)
    do k = 1, hist%nprobe
      call h5_group(gs, trim(hist%probe_name(k)), gp, ierr)
      call h5_attr(gp, 'particle', hist%probe_particle(k), ierr)
      call h5_write(gp, 'time', hist%t(1:hist%nt), ierr, sf%sh)
      call h5_write(gp, 'x', hist%px(:, k, 1:hist%nt), ierr, sf%sh)
      call h5_write(gp, 'v', hist%pv(:, k, 1:hist%nt), ierr, sf%sh)
      call h5_write(gp, 'stress', hist%ps(:, k, 1:hist%nt), ierr, sf%sh)
      call h5_close_group(gp, ierr)
    end do
    call h5_close_group(gs, ierr)

    ! Every group, dataset and attribute is closed by now (the helpers close what they open
    ! even on failure): only the file is left.
    call sf%close(model%comm, path, tmp, fid, ierr, oserr)
    if (.not. sf%root) return
    if (ierr /= 0) then
      info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': writing the HDF5 output '//tmp//' failed: '// &
        empm_write_reason(oserr), err)
      return
    end if
    if (rfail /= 0) then
      info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot copy a snapshot into it: '//why, err)
      return
    end if
    xmf = empm_xdmf_path(path)
    xtmp = empm_partial_name(xmf)
    call write_xdmf(xtmp, basename(path), model, hist, sf%ntotal, snames, ierr, oserr)
    if (ierr /= 0) then
      info = empm_remove(tmp); info = empm_remove(xtmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot write the XDMF file '//xtmp//': '// &
        empm_write_reason(oserr), err)
      return
    end if
    if (empm_rename(tmp, path) /= 0) then
      oserr = empm_errno()
      info = empm_remove(tmp); info = empm_remove(xtmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot rename '//tmp//' to '//path//': '// &
        empm_write_reason(oserr), err); return
    end if
    if (empm_rename(xtmp, xmf) /= 0) then
      oserr = empm_errno()
      info = empm_remove(xtmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot rename '//xtmp//' to '//xmf//': '// &
        empm_write_reason(oserr), err)
    end if

  contains

    ! A snapshot's frame datasets in group g. Particles keep their material for the whole run:
    ! the current indices apply.
    subroutine write_snapshot(sn)
      type(empm_snapshot_t), intent(in) :: sn
      n = min(size(sn%m), np)
      call write_frame(g, sn%x(:, 1:n), model%pts%x0(:, 1:n), sn%v(:, 1:n), sn%stress(:, 1:n), &
        sn%strain(:, 1:n), sn%m(1:n), sn%vol(1:n), sn%rho(1:n), sn%state(:, 1:n), &
        model%pts%mat(1:n), snames, scol, sf%pp, ierr)
    end subroutine write_snapshot
  end subroutine empm_write_results

  !> Create `path`'s partial file (name in `tmp`) for this process's `np` particles, with every
  !> process of `comm` when they write together (`together` and [[empm_h5_collective]]; the
  !> caller shared the particles out in blocks of ids). e ≠ 0 on every process when it failed.
  subroutine shared_create(self, path, comm, np, together, tmp, fid, e)
    class(empm_shared_file_t), intent(inout) :: self        !! the file's writers
    character(len=*), intent(in) :: path                    !! final name
    type(empm_comm_t), intent(in) :: comm                   !! the run's processes
    integer, intent(in) :: np                               !! this process's particles
    logical, intent(in), optional :: together               !! all processes write it
    character(len=:), allocatable, intent(out) :: tmp       !! partial name (the root's)
    integer(hid_t), intent(out) :: fid                      !! the open file
    integer, intent(out) :: e                               !! 0 on success
    integer :: counts(1, comm%nranks)
    logical :: created
    self%together = .false.
    if (present(together)) self%together = together .and. empm_h5_collective(comm)
    self%root = comm%is_root() .or. .not. self%together
    self%first = 0; self%ntotal = np
    if (self%together) then
      ! One name for all, the root's; each process's columns follow the lower ranks'.
      if (comm%is_root()) tmp = empm_partial_name(path)
      call comm%bcast_text(tmp, 0)
      call comm%allgather_ints([np], counts)
      self%first = sum(counts(1, 1:comm%rank)); self%ntotal = sum(counts)
    else
      tmp = empm_partial_name(path)
    end if
    fid = 0; e = 0
    if (self%together) then
      ! Collective (the file access list duplicates the communicator, the create opens the
      ! file on all): every process goes on only if all can.
      call h5_mpio_properties(comm, self%fapl, self%xfer, e)
      e = comm%max_int(abs(e))
      if (e == 0) then
        call h5fcreate_f(tmp, H5F_ACC_EXCL_F, fid, e, access_prp=self%fapl)
        created = e == 0
        e = comm%max_int(abs(e))
        ! Created on some processes only: the open file cannot be closed by them alone.
        if (e /= 0 .and. comm%any_true(created)) call abort_write(comm, path, &
          'the parallel create of '//tmp//' failed on some of the processes', tmp)
      end if
    else
      call h5fcreate_f(tmp, H5F_ACC_EXCL_F, fid, e)
    end if
    ! Particle datasets: this process's columns of ntotal. Others: the root's array.
    self%pp = h5_part_t(first=self%first, total=merge(self%ntotal, -1, self%together), &
      writes=.true., xfer=self%xfer)
    self%sh = h5_part_t(first=0, total=-1, writes=self%root, xfer=self%xfer)
    if (e /= 0) call h5_mpio_close(self%fapl, self%xfer)
  end subroutine shared_create

  !> Close the file; ierr (in: this process's write failures) and oserr (the system's reason)
  !> become the worst over the processes. Written together, a write that failed on any
  !> process cannot be undone collectively (parallel HDF5's state of the file then differs
  !> between the processes, and closing it hangs or crashes): the root reports it, removes
  !> the partial file `tmp` and the job ends with status 4 ([[abort_write]]).
  subroutine shared_close(self, comm, path, tmp, fid, ierr, oserr)
    class(empm_shared_file_t), intent(inout) :: self !! the file's writers
    type(empm_comm_t), intent(in) :: comm            !! the processes it was created with
    character(len=*), intent(in) :: path             !! final name
    character(len=*), intent(in) :: tmp              !! partial name
    integer(hid_t), intent(in) :: fid                !! the open file
    integer, intent(inout) :: ierr                   !! ≠ 0: a write failed
    integer, intent(out) :: oserr                    !! errno of the failure, 0 if none
    integer :: e
    ! errno now is the reason of a failed write (HDF5 keeps it); a failed close sets it too.
    oserr = 0
    if (ierr /= 0) oserr = empm_errno()
    if (self%together) then
      if (comm%max_int(abs(ierr)) /= 0) then
        oserr = comm%max_int(oserr)
        call abort_write(comm, path, 'writing '//tmp//' failed: '// &
          empm_write_reason(oserr), tmp)
      end if
    end if
    call h5fclose_f(fid, e)
    call h5_mpio_close(self%fapl, self%xfer)
    self%fapl = 0; self%xfer = 0
    if (e /= 0) then
      if (oserr == 0) oserr = empm_errno()
      ierr = e
    end if
    if (self%together) then
      ierr = comm%max_int(abs(ierr))
      oserr = comm%max_int(oserr)
    end if
  end subroutine shared_close

  !> A failure of a file written together that the processes cannot recover from: the root
  !> prints `why` for `path`, removes the partial file `tmp`, and the job ends with status 4
  !> (EMPM_ERR_IO) on every process. Collective.
  subroutine abort_write(comm, path, why, tmp)
    type(empm_comm_t), intent(in) :: comm !! the processes writing it
    character(len=*), intent(in) :: path  !! final name
    character(len=*), intent(in) :: why   !! what failed
    character(len=*), intent(in) :: tmp   !! partial name
    integer :: info
    if (comm%is_root()) then
      info = empm_remove(tmp)
      call empm_output_release(path) ! the results' lock, if this is the results file
      write(error_unit, '(a)') 'empm: error: '//path//': '//why//'; the processes writing '// &
        'it together (parallel HDF5) cannot close it consistently, so the run ends here ' &
        //'(status 4)'
      flush(error_unit)
    end if
    call comm%barrier()
    call comm%abort(EMPM_ERR_IO)
  end subroutine abort_write

  subroutine write_state(g, pts, pp, ierr)
    integer(hid_t), intent(in) :: g
    type(empm_particles_t), intent(in) :: pts
    type(h5_part_t), intent(in) :: pp
    integer, intent(inout) :: ierr
    integer :: n
    n = pts%np
    call h5_write(g, 'x', pts%x(:, 1:n), ierr, pp)
    call h5_write(g, 'xyz', pad3(pts%x(:, 1:n)), ierr, pp)
    call h5_write(g, 'x0', pts%x0(:, 1:n), ierr, pp)
    call h5_write(g, 'v', pts%v(:, 1:n), ierr, pp)
    call h5_write(g, 'a', pts%a(:, 1:n), ierr, pp)
    call h5_write(g, 'stress', pts%stress(:, 1:n), ierr, pp)
    call h5_write(g, 'strain', pts%strain(:, 1:n), ierr, pp)
    call h5_write(g, 'mass', pts%m(1:n), ierr, pp)
    call h5_write(g, 'volume', pts%vol(1:n), ierr, pp)
    call h5_write(g, 'density', pts%rho(1:n), ierr, pp)
    call h5_write(g, 'material', pts%mat(1:n), ierr, pp)
  end subroutine write_state

  ! The datasets of a snapshot's frame group `g` (docs/output.md, "/snapshots").
  subroutine write_frame(g, x, x0, v, stress, strain, m, vol, rho, state, mat, snames, scol, pp, &
                         ierr)
    integer(hid_t), intent(in) :: g
    real(wp), intent(in) :: x(:,:), x0(:,:), v(:,:), stress(:,:), strain(:,:), m(:), vol(:), &
      rho(:), state(:,:)
    integer, intent(in) :: mat(:)
    character(len=*), intent(in) :: snames(:)
    integer, intent(in) :: scol(:,:)
    type(h5_part_t), intent(in) :: pp
    integer, intent(inout) :: ierr
    call h5_write(g, 'x', x, ierr, pp)
    call h5_write(g, 'xyz', pad3(x), ierr, pp)
    call h5_write(g, 'v', v, ierr, pp)
    call h5_write(g, 'stress', stress, ierr, pp)
    call h5_write(g, 'strain', strain, ierr, pp)
    call h5_write(g, 'mass', m, ierr, pp)
    call h5_write(g, 'volume', vol, ierr, pp)
    call h5_write(g, 'density', rho, ierr, pp)
    call write_state_vars(g, state, mat, snames, scol, pp, ierr)
    call write_xdmf_fields(g, x, x0, v, stress, strain, pp, ierr)
  end subroutine write_frame

  ! Read this process's columns (sf%first on, np of them) of a snapshot written as it was
  ! taken: a snapshot file's raw fields (`x`, `v`, `stress`, `strain`, `mass`, `volume`,
  ! `density`, `state`: [[empm_write_snapshot_file]]), or, a restart's earlier snapshot, a
  ! results file's `/snapshots/NNNNNN` group, whose state variables are by name (`mat`, `names`
  ! and `col` map them back to the materials' rows). `why` says what failed (ierr set).
  subroutine read_frame(sn, sf, np, nd, ns, mat, names, col, got, ierr, why)
    type(empm_snapshot_t), intent(in) :: sn
    type(empm_shared_file_t), intent(in) :: sf
    integer, intent(in) :: np, nd, ns, mat(:)
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: col(:,:)
    type(empm_snapshot_t), intent(out) :: got
    integer, intent(inout) :: ierr
    character(len=:), allocatable, intent(inout) :: why
    integer(hid_t) :: src
    integer :: e, k, p, r, rs, step, ntot
    character(len=:), allocatable :: at
    real(wp), allocatable :: buf(:)
    real(wp) :: t
    at = sn%frame
    if (len(at) > 0) at = at//'/'
    got = empty_frame(nd, ns, np)
    call h5_open_read(sn%file, src, e)
    if (e == 0) then
      ! The snapshot of this run at this time: not one another run left there.
      call empm_frame_header(src, sn%frame, t, step, ntot, e)
      if (e /= 0 .or. t /= sn%t .or. step /= sn%step .or. ntot /= sf%ntotal) e = 4
      if (e /= 0) call h5_close_file(src, rs)
    end if
    if (e /= 0) then
      ierr = 1
      select case (e)
      case (1); why = sn%file//': no such file (the run wrote it as the snapshot was taken)'
      case (2, 3); why = sn%file//': not a readable HDF5 file'
      case default; why = sn%file//': not the snapshot of this run at t = '//str(sn%t)// &
        ' s (step '//itoa(sn%step)//') at "'//sn%frame//'/"'
      end select
      return
    end if
    rs = 0
    call get2('x', got%x); call get2('v', got%v)
    call get2('stress', got%stress); call get2('strain', got%strain)
    call get1('mass', got%m); call get1('volume', got%vol); call get1('density', got%rho)
    if (len(at) == 0) then
      if (ns > 0) call get2('state', got%state)
    else
      allocate(buf(np))
      do k = 1, size(names)
        call get1('state/'//trim(names(k)), buf)
        do p = 1, np
          r = 0
          if (mat(p) >= 1 .and. mat(p) <= size(col, 2)) r = col(k, mat(p))
          if (r >= 1 .and. r <= ns) got%state(r, p) = buf(p)
        end do
      end do
    end if
    call h5_close_file(src, rs)
    if (rs /= 0) then
      ierr = 1
      if (len(why) == 0) why = sn%file//': closing it failed'
    end if
  contains
    subroutine get1(name, a)
      character(len=*), intent(in) :: name
      real(wp), intent(inout) :: a(:)
      integer :: q
      q = 0
      call h5_read(src, at//name, a, q, [sf%first, 1])
      if (q /= 0) call failed(name)
    end subroutine get1
    subroutine get2(name, a)
      character(len=*), intent(in) :: name
      real(wp), intent(inout) :: a(:,:)
      integer :: q
      q = 0
      call h5_read(src, at//name, a, q, [sf%first, 1])
      if (q /= 0) call failed(name)
    end subroutine get2
    subroutine failed(name)
      character(len=*), intent(in) :: name
      ierr = 1
      if (len(why) == 0) why = sn%file//': cannot read its dataset '//at//name
    end subroutine failed
  end subroutine read_frame

  !> The `time` and `step` attributes of a snapshot (group `frame` of the open file `fid`, ''
  !> its root) and its number of particles (the extent of its `mass`); e ≠ 0 when one of them
  !> is missing or `mass` is not a list.
  subroutine empm_frame_header(fid, frame, t, step, n, e)
    use hdf5, only: h5gopen_f, h5gclose_f
    integer(hid_t), intent(in) :: fid          !! an open file
    character(len=*), intent(in) :: frame      !! the snapshot's group ('' the root)
    real(wp), intent(out) :: t                 !! its time [s]
    integer, intent(out) :: step               !! its step
    integer, intent(out) :: n                  !! its particles
    integer, intent(out) :: e                  !! 0 when all were read
    integer(hid_t) :: loc
    integer(hsize_t), allocatable :: dims(:)
    real(wp) :: tt(1)
    integer :: ie
    t = 0.0_wp; step = -1; n = -1; e = 0
    loc = fid
    if (len(frame) > 0) call h5gopen_f(fid, frame, loc, e)
    if (e /= 0) return
    call h5_read_attr(loc, 'time', tt, e)
    call h5_read_attr(loc, 'step', step, e)
    call h5_dims(loc, 'mass', dims, e)
    if (e == 0 .and. size(dims) /= 1) e = 1
    if (e == 0) n = int(dims(1))
    t = tt(1)
    if (loc /= fid) call h5gclose_f(loc, ie)
  end subroutine empm_frame_header

  ! A snapshot of np particles, zero (what is written when reading one failed: the file is
  ! then removed).
  function empty_frame(nd, ns, np) result(sn)
    integer, intent(in) :: nd, ns, np
    type(empm_snapshot_t) :: sn
    allocate(sn%x(nd, np), sn%v(nd, np), sn%stress(6, np), sn%strain(6, np), sn%m(np), &
      sn%vol(np), sn%rho(np), sn%state(ns, np))
    sn%x = 0.0_wp; sn%v = 0.0_wp; sn%stress = 0.0_wp; sn%strain = 0.0_wp
    sn%m = 0.0_wp; sn%vol = 0.0_wp; sn%rho = 0.0_wp; sn%state = 0.0_wp
  end function empty_frame

  !> Write one snapshot to its own HDF5 file `path` (atomically: a partial name, then
  !> renamed): the root attributes `format` = 'empm snapshot', `time`, `step`, `particles`,
  !> `case_text` and the raw fields `x` (ndim, np), `v`, `stress` (6, np), `strain`, `mass` (np), `volume`,
  !> `density` and `state` (the materials' rows, nstate × np; absent when nstate = 0), as h5py
  !> shows them transposed. Called by every process when `together` (each its block of
  !> consecutive ids, as [[empm_write_results]]), else by one holding every particle. The
  !> error is every process's.
  subroutine empm_write_snapshot_file(path, comm, case_text, t, step, x, v, stress, strain, m, &
                                      vol, rho, state, together, err)
    character(len=*), intent(in) :: path               !! the snapshot's file
    type(empm_comm_t), intent(in) :: comm              !! the run's processes
    character(len=*), intent(in) :: case_text         !! the case file's text (a restart checks
                                                       !! that the snapshot is its case's)
    real(wp), intent(in) :: t                          !! its time [s]
    integer, intent(in) :: step                        !! its step
    real(wp), intent(in) :: x(:,:)                     !! positions (ndim, np) [m]
    real(wp), intent(in) :: v(:,:)                     !! velocities (ndim, np) [m/s]
    real(wp), intent(in) :: stress(:,:)                !! stresses (6, np) [Pa]
    real(wp), intent(in) :: strain(:,:)                !! strains (6, np)
    real(wp), intent(in) :: m(:)                       !! masses (np) [kg]
    real(wp), intent(in) :: vol(:)                     !! volumes (np) [m³]
    real(wp), intent(in) :: rho(:)                     !! densities (np) [kg/m³]
    real(wp), intent(in) :: state(:,:)                 !! state variables (nstate, np)
    logical, intent(in) :: together                    !! all processes write it (blocks)
    type(empm_error_t), intent(out) :: err             !! error, if any
    integer(hid_t) :: fid
    integer :: ierr, e, oserr, info
    character(len=:), allocatable :: tmp
    type(empm_shared_file_t) :: sf
    call h5dont_atexit_f(e)
    call h5open_f(e)
    call h5eset_auto_f(0, e)
    call sf%create(path, comm, size(m), together, tmp, fid, e)
    if (e /= 0) then
      oserr = empm_errno()
      if (sf%together) oserr = comm%max_int(oserr)
      call empm_raise(EMPM_ERR_IO, path//': cannot create the snapshot file '//tmp//': '// &
        empm_errno_text(oserr), err); return
    end if
    ierr = 0
    call h5_attr(fid, 'format', 'empm snapshot', ierr)
    call h5_attr(fid, 'time', t, ierr)
    call h5_attr(fid, 'step', step, ierr)
    call h5_attr(fid, 'particles', sf%ntotal, ierr)
    call h5_attr(fid, 'case_text', case_text, ierr)
    call h5_write(fid, 'x', x, ierr, sf%pp)
    call h5_write(fid, 'v', v, ierr, sf%pp)
    call h5_write(fid, 'stress', stress, ierr, sf%pp)
    call h5_write(fid, 'strain', strain, ierr, sf%pp)
    call h5_write(fid, 'mass', m, ierr, sf%pp)
    call h5_write(fid, 'volume', vol, ierr, sf%pp)
    call h5_write(fid, 'density', rho, ierr, sf%pp)
    if (size(state, 1) > 0) call h5_write(fid, 'state', state, ierr, sf%pp)
    call sf%close(comm, path, tmp, fid, ierr, oserr)
    if (sf%root) then
      if (ierr /= 0) then
        info = empm_remove(tmp)
      else if (empm_rename(tmp, path) /= 0) then
        ierr = 1; oserr = empm_errno(); info = empm_remove(tmp)
      end if
    end if
    if (sf%together) then
      ierr = comm%max_int(abs(ierr)); oserr = comm%max_int(oserr)
    end if
    if (ierr /= 0) call empm_raise(EMPM_ERR_IO, path//': writing the snapshot failed: '// &
      empm_write_reason(oserr), err)
  end subroutine empm_write_snapshot_file

  !> The folder that holds a run's snapshots as they are taken, until they are copied into
  !> the results file `output` at its end: `OUT.h5` -> `OUT.h5.snapshots` (the whole name, as
  !> the output's lock: two outputs never share one).
  pure function empm_staging_path(output) result(path)
    character(len=*), intent(in) :: output     !! results file
    character(len=:), allocatable :: path      !! the folder
    path = trim(output)//'.snapshots'
  end function empm_staging_path

  !> The temporary name a file is written under before it is renamed to `path`: unique to
  !> this process and call (`path.<pid>-<n>.partial`), so that concurrent writers never share
  !> one.
  function empm_partial_name(path) result(tmp)
    character(len=*), intent(in) :: path     !! final name
    character(len=:), allocatable :: tmp     !! temporary name beside it
    integer, save :: counter = 0
    integer :: n
    !$omp atomic capture
    counter = counter + 1
    n = counter
    !$omp end atomic
    tmp = path//'.'//itoa(empm_getpid())//'-'//itoa(n)//'.partial'
  end function empm_partial_name

  !> Remove the partial files a killed writer left (`[[empm_partial_name]]`: `F.<pid>-<n>.partial`
  !> whose process no longer exists): beside each of `files`, and in each of `folders`. A live
  !> process's partial file, and any other file, is left alone. Called by the run that holds an
  !> output's lock, for the output's files and its snapshots' folder: a killed run's
  !> partial snapshot may be as large as a snapshot.
  subroutine empm_remove_stale_partials(files, folders)
    character(len=*), intent(in) :: files(:)   !! files whose partial names are looked for
    character(len=*), intent(in) :: folders(:) !! folders whose partial files are looked for
    character(len=4096), allocatable :: names(:)
    integer :: k, j, info
    do k = 1, size(files) + size(folders)
      if (k <= size(files)) then
        call empm_glob(glob_literal(trim(files(k)))//'.*.partial', names)
      else
        call empm_glob(glob_literal(trim(folders(k - size(files))))//'/*.partial', names)
      end if
      do j = 1, size(names)
        ! (A file that cannot be removed stays: it harms nothing.)
        if (stale(trim(names(j)))) info = empm_remove(trim(names(j)))
      end do
    end do
  contains
    ! `name` is NAME.<pid>-<n>.partial of a process that no longer exists.
    logical function stale(name)
      character(len=*), intent(in) :: name
      integer :: b, d, pid, ios
      stale = .false.
      b = index(name(1:len(name) - len('.partial')), '.', back=.true.)
      if (b == 0) return
      d = index(name(b + 1:), '-')
      if (d <= 1) return
      if (verify(name(b + 1:b + d - 1), '0123456789') /= 0) return
      read(name(b + 1:b + d - 1), *, iostat=ios) pid
      if (ios /= 0) return
      stale = .not. empm_process_alive(pid)
    end function stale
  end subroutine empm_remove_stale_partials

  ! `path` with the shell pattern characters escaped: matched literally by empm_glob.
  pure function glob_literal(path) result(s)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: s
    integer :: i
    s = ''
    do i = 1, len(path)
      if (index('*?[]'//achar(92), path(i:i)) > 0) s = s//achar(92) ! a backslash
      s = s//path(i:i)
    end do
  end function glob_literal

  !> Before a run: check that `path` can be an output (absent or a regular file; a folder or a
  !> device is refused, EMPM_ERR_INPUT naming it) and take its lock `path.lock` (EMPM_ERR_IO
  !> when another live process holds it; a lock left by a killed run is taken over). On
  !> success the caller owns the lock and calls [[empm_output_release]] at the end.
  subroutine empm_output_claim(path, err)
    character(len=*), intent(in) :: path         !! output HDF5 file
    type(empm_error_t), intent(out) :: err       !! error, code 0 on success
    character(len=*), parameter :: SUFFIX(3) = [character(len=5) :: '', '.h5', '.hdf5']
    character(len=:), allocatable :: lock, xmf, sibling, stem
    integer :: u, ios, pid, attempt, info, k
    xmf = empm_xdmf_path(path)
    select case (empm_path_kind(path))
    case (PATH_MISSING, PATH_REGULAR)
    case (PATH_DIRECTORY)
      call err%set(EMPM_ERR_INPUT, path//': the output exists and is a folder, not a file'); return
    case default
      call err%set(EMPM_ERR_INPUT, path//': the output exists and is not a regular file '// &
        '(a device, FIFO or socket); refusing to replace it'); return
    end select
    if (empm_path_kind(xmf) /= PATH_MISSING .and. empm_path_kind(xmf) /= PATH_REGULAR) then
      call err%set(EMPM_ERR_INPUT, path//': its XDMF file '//xmf// &
        ' exists and is not a regular file; refusing to replace it'); return
    end if
    if (empm_path_kind(empm_staging_path(path)) /= PATH_MISSING .and. &
        empm_path_kind(empm_staging_path(path)) /= PATH_DIRECTORY) then
      call err%set(EMPM_ERR_INPUT, path//': '//empm_staging_path(path)//', where its '// &
        'snapshots go as they are taken, exists and is not a folder; refusing to replace it')
      return
    end if
    ! `k`, `k.h5` and `k.hdf5` share their XDMF file (k.xmf), the first two their checkpoints
    ! (k.ckpt.h5): a live run on another of these names holds them.
    stem = trim(path)
    if (ends(stem, '.h5')) stem = stem(1:len(stem) - 3)
    if (ends(stem, '.hdf5')) stem = stem(1:len(stem) - 5)
    do k = 1, 3
      sibling = stem//trim(SUFFIX(k))
      if (sibling == trim(path)) cycle
      pid = lock_owner(sibling//'.lock')
      if (pid <= 0) cycle
      if (.not. empm_process_alive(pid)) cycle
      call err%set(EMPM_ERR_IO, path//': another run (process '//itoa(pid)//') is writing '// &
        sibling//', which shares its XDMF file or checkpoints (lock '//sibling//'.lock); '// &
        'wait for it or choose another -o'); return
    end do
    lock = path//'.lock'
    do attempt = 1, 2
      ! status 'new' creates the file exclusively (O_EXCL): one process wins.
      open(newunit=u, file=lock, status='new', action='write', iostat=ios)
      if (ios == 0) then
        write(u, '(i0)', iostat=ios) empm_getpid()
        close(u)
        return
      end if
      pid = lock_owner(lock)
      if (pid < 0 .and. empm_path_kind(lock) == PATH_MISSING) then
        ! The folder is missing or not writable: the same test as for the output itself.
        call err%set(EMPM_ERR_IO, path//': cannot create the lock file '//lock//': '// &
          empm_errno_text(empm_errno())); return
      end if
      if (pid > 0 .and. empm_process_alive(pid)) then
        call err%set(EMPM_ERR_IO, path//': another run (process '//itoa(pid)// &
          ') is writing this file (lock '//lock//'); wait for it or choose another -o'); return
      end if
      ! Left by a killed run (or being written this instant: then the retry finds it again).
      if (pid /= 0) info = empm_remove(lock)
    end do
    call err%set(EMPM_ERR_IO, path//': cannot take the lock '//lock// &
      ' (remove it if no run is writing '//path//')')
  contains
    logical function ends(str_, tail)
      character(len=*), intent(in) :: str_, tail
      ends = .false.
      if (len(str_) > len(tail)) ends = str_(len(str_) - len(tail) + 1:) == tail
    end function ends
    integer function lock_owner(f) result(p)
      character(len=*), intent(in) :: f
      integer :: v, ios2
      p = -1
      open(newunit=v, file=f, status='old', action='read', iostat=ios2)
      if (ios2 /= 0) return
      p = 0
      read(v, *, iostat=ios2) p
      if (ios2 /= 0) p = 0
      close(v)
      ! p = 0: just created by another process that has not written its pid yet.
    end function lock_owner
  end subroutine empm_output_claim

  !> Release the lock taken by [[empm_output_claim]] (remove `path.lock` if this process
  !> holds it).
  subroutine empm_output_release(path)
    character(len=*), intent(in) :: path !! output HDF5 file
    integer :: u, ios, pid, info
    open(newunit=u, file=path//'.lock', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    read(u, *, iostat=ios) pid
    close(u)
    if (ios == 0 .and. pid == empm_getpid()) info = empm_remove(path//'.lock')
  end subroutine empm_output_release

  pure function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: b
    write(b, '(i0)') i
    s = trim(b)
  end function itoa

  !> The state-variable names of all materials (each once, in material order) and, for name k
  !> and material m, the row `col(k, m)` of `pts%state` holding it (0: m does not declare it).
  subroutine state_columns(model, names, col)
    type(empm_model_t), intent(in) :: model
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:)
    integer, allocatable, intent(out) :: col(:,:)
    character(len=STATE_NAME_LEN), allocatable :: own(:)
    integer :: nmat, m, j, k
    allocate(names(0))
    nmat = 0
    if (allocated(model%mats)) nmat = size(model%mats)
    do m = 1, nmat
      if (.not. allocated(model%mats(m)%model)) cycle
      call model%mats(m)%model%state_names(own)
      do j = 1, size(own)
        if (.not. any(names == own(j))) names = [character(len=STATE_NAME_LEN) :: names, own(j)]
      end do
    end do
    allocate(col(size(names), nmat))
    col = 0
    do m = 1, nmat
      if (.not. allocated(model%mats(m)%model)) cycle
      call model%mats(m)%model%state_names(own)
      do j = 1, size(own)
        do k = 1, size(names)
          if (names(k) == own(j)) col(k, m) = j
        end do
      end do
    end do
  end subroutine state_columns

  !> Group `state` under `g`: one dataset (np) per name, NaN where the particle's material does
  !> not declare the name. Nothing when no material has state variables.
  subroutine write_state_vars(g, state, mat, names, col, pp, ierr)
    integer(hid_t), intent(in) :: g
    real(wp), intent(in) :: state(:,:)
    integer, intent(in) :: mat(:)
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: col(:,:)
    type(h5_part_t), intent(in) :: pp
    integer, intent(inout) :: ierr
    integer(hid_t) :: gs
    real(wp), allocatable :: buf(:)
    real(wp) :: nan
    integer :: k, p, r
    if (size(names) == 0) return
    nan = ieee_value(1.0_wp, ieee_quiet_nan)
    allocate(buf(size(mat)))
    call h5_group(g, 'state', gs, ierr)
    do k = 1, size(names)
      do p = 1, size(mat)
        r = 0
        if (mat(p) >= 1 .and. mat(p) <= size(col, 2)) r = col(k, mat(p))
        if (r >= 1 .and. r <= size(state, 1)) then
          buf(p) = state(r, p)
        else
          buf(p) = nan
        end if
      end do
      call h5_write(gs, trim(names(k)), buf, ierr, pp)
    end do
    call h5_close_group(gs, ierr)
  end subroutine write_state_vars

  !> Positions padded to three components (what ParaView's XDMF reader needs).
  pure function pad3(x) result(y)
    real(wp), intent(in) :: x(:,:)
    real(wp) :: y(3, size(x, 2))
    y = 0.0_wp
    y(1:size(x, 1), :) = x
  end function pad3

  !> The XDMF file written beside `path`: `path` without a final `.h5`/`.hdf5`, plus `.xmf`.
  pure function empm_xdmf_path(path) result(xmf)
    character(len=*), intent(in) :: path !! HDF5 output path
    character(len=:), allocatable :: xmf !! XDMF path, same folder
    integer :: n
    n = len_trim(path)
    if (ends_with(path(1:n), '.h5')) then
      xmf = path(1:n - 3)//'.xmf'
    else if (ends_with(path(1:n), '.hdf5')) then
      xmf = path(1:n - 5)//'.xmf'
    else
      xmf = path(1:n)//'.xmf'
    end if
  contains
    pure logical function ends_with(s, suffix)
      character(len=*), intent(in) :: s, suffix
      ends_with = .false.
      if (len(s) > len(suffix)) ends_with = s(len(s) - len(suffix) + 1:) == suffix
    end function ends_with
  end function empm_xdmf_path

  ! The file name of `path` without its folder: the XDMF refers to the HDF5 file beside it
  ! this way, which readers resolve against the XDMF's own folder.
  pure function basename(path) result(b)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: b
    b = path(index(path, '/', back=.true.) + 1:len_trim(path))
  end function basename

  ! Subgroup `xdmf` of a frame group: displacement x − x0 and velocity padded to 3 components,
  ! stress and strain as full tensors (xx, xy, xz, yx, yy, yz, zx, zy, zz).
  subroutine write_xdmf_fields(g, x, x0, v, stress, strain, pp, ierr)
    integer(hid_t), intent(in) :: g
    real(wp), intent(in) :: x(:,:), x0(:,:), v(:,:), stress(:,:), strain(:,:)
    type(h5_part_t), intent(in) :: pp
    integer, intent(inout) :: ierr
    integer, parameter :: FULL(9) = [1, 6, 5, 6, 2, 4, 5, 4, 3] ! Voigt row of each entry
    integer(hid_t) :: gx
    call h5_group(g, 'xdmf', gx, ierr)
    call h5_write(gx, 'displacement', pad3(x - x0), ierr, pp)
    call h5_write(gx, 'velocity', pad3(v), ierr, pp)
    call h5_write(gx, 'stress', stress(FULL, :), ierr, pp)
    call h5_write(gx, 'strain', strain(FULL, :), ierr, pp)
    call h5_close_group(gx, ierr)
  end subroutine write_xdmf_fields

  !> XDMF 2 temporal collection, one polyvertex grid per snapshot and the final state (unless
  !> the last snapshot is it), written to `xmf` (the caller renames it) with every write
  !> checked; `ierr` /= 0 on failure. `h5name` is the HDF5 file relative to the XDMF's folder.
  subroutine write_xdmf(xmf, h5name, model, hist, ntotal, snames, ierr, oserr)
    character(len=*), intent(in) :: xmf
    character(len=*), intent(in) :: h5name
    type(empm_model_t), intent(in) :: model
    type(empm_history_t), intent(in) :: hist
    integer, intent(in) :: ntotal ! particles in the file
    character(len=*), intent(in) :: snames(:)
    integer, intent(inout) :: ierr
    integer, intent(out) :: oserr
    character(len=*), parameter :: NL = new_line('a')
    character(len=:), allocatable :: doc
    integer :: u, k, ios
    character(len=16) :: sname
    logical :: final_frame
    doc = '<?xml version="1.0" ?>'//NL//'<Xdmf Version="2.0">'//NL//' <Domain>'//NL// &
      '  <Grid Name="particles" GridType="Collection" CollectionType="Temporal">'//NL
    do k = 1, hist%nsnap
      write(sname, '(i6.6)') k - 1
      call grid_entry(hist%snap(k)%t, ntotal, '/snapshots/'//trim(sname))
    end do
    final_frame = hist%nsnap == 0
    if (.not. final_frame) final_frame = hist%snap(hist%nsnap)%step /= model%step
    if (final_frame) call grid_entry(model%t, ntotal, '/final')
    doc = doc//'  </Grid>'//NL//' </Domain>'//NL//'</Xdmf>'
    oserr = 0
    ! status 'new': created exclusively (the name is this writer's own).
    open(newunit=u, file=xmf, status='new', action='write', iostat=ios)
    if (ios /= 0) then
      oserr = empm_errno(); ierr = 1; return
    end if
    write(u, '(a)', iostat=ios) doc
    if (ios /= 0) then
      oserr = empm_errno(); ierr = 1
    end if
    flush(u, iostat=ios)
    if (ios /= 0 .and. ierr == 0) then
      oserr = empm_errno(); ierr = 1
    end if
    close(u, iostat=ios)
    if (ios /= 0 .and. ierr == 0) then
      oserr = empm_errno(); ierr = 1
    end if
  contains
    subroutine grid_entry(t, np, grp)
      real(wp), intent(in) :: t
      integer, intent(in) :: np
      character(len=*), intent(in) :: grp
      character(len=32) :: cnp, ct
      integer :: j
      write(cnp, '(i0)') np
      write(ct, '(es24.16)') t
      doc = doc//'   <Grid Name="t" GridType="Uniform">'//NL// &
        '    <Time Value="'//trim(adjustl(ct))//'"/>'//NL// &
        '    <Topology TopologyType="Polyvertex" NumberOfElements="'//trim(cnp)// &
        '" NodesPerElement="1">'//NL
      call item('/xdmf/vertices', trim(cnp)//' 1', 'Int', '4')
      doc = doc//'    </Topology>'//NL//'    <Geometry GeometryType="XYZ">'//NL
      call item(grp//'/xyz', trim(cnp)//' 3', 'Float', '8')
      doc = doc//'    </Geometry>'//NL
      call attribute('displacement', 'Vector', grp//'/xdmf/displacement', trim(cnp)//' 3')
      call attribute('velocity', 'Vector', grp//'/xdmf/velocity', trim(cnp)//' 3')
      call attribute('stress', 'Tensor', grp//'/xdmf/stress', trim(cnp)//' 9')
      call attribute('strain', 'Tensor', grp//'/xdmf/strain', trim(cnp)//' 9')
      call attribute('density', 'Scalar', grp//'/density', trim(cnp))
      call attribute('volume', 'Scalar', grp//'/volume', trim(cnp))
      ! Particles keep their material: every frame shows the final indices.
      call attribute('material', 'Scalar', '/final/material', trim(cnp), 'Int', '4')
      do j = 1, size(snames)
        call attribute(trim(snames(j)), 'Scalar', grp//'/state/'//trim(snames(j)), trim(cnp))
      end do
      doc = doc//'   </Grid>'//NL
    end subroutine grid_entry
    subroutine attribute(name, kind, ds, dims, ntype, prec)
      character(len=*), intent(in) :: name, kind, ds, dims
      character(len=*), intent(in), optional :: ntype, prec
      doc = doc//'    <Attribute Name="'//name//'" AttributeType="'//kind// &
        '" Center="Node">'//NL
      if (present(ntype)) then
        call item(ds, dims, ntype, prec)
      else
        call item(ds, dims, 'Float', '8')
      end if
      doc = doc//'    </Attribute>'//NL
    end subroutine attribute
    subroutine item(ds, dims, ntype, prec)
      character(len=*), intent(in) :: ds, dims, ntype, prec
      ! The file name comes from the user (-o): escaped as XML text.
      doc = doc//'     <DataItem Dimensions="'//dims//'" NumberType="'//ntype//'" '// &
        'Precision="'//prec//'" Format="HDF">'//xml_text(h5name)//':'//ds//'</DataItem>'//NL
    end subroutine item
  end subroutine write_xdmf

  ! `s` with the XML special characters escaped.
  pure function xml_text(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    integer :: i
    r = ''
    do i = 1, len(s)
      select case (s(i:i))
      case ('&'); r = r//'&amp;'
      case ('<'); r = r//'&lt;'
      case ('>'); r = r//'&gt;'
      case default; r = r//s(i:i)
      end select
    end do
  end function xml_text
end module empm_output
