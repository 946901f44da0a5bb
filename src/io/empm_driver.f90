!> High-level driver: read a case file, run it, write the results. Used by the `empm run`
!> command and callable from embedding codes.
module empm_driver
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use empm_error, only: empm_error_t, empm_raise_error, EMPM_OK, EMPM_ERR_INTERRUPTED, &
                        EMPM_ERR_INPUT, EMPM_ERR_IO
  use empm_case, only: empm_case_t
  use empm_input, only: empm_read_case, empm_check_basis
  use empm_model, only: empm_model_t
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_solver, only: empm_solve, empm_run_stats_t, empm_run_hook_t, empm_solver_state_t
  use empm_output, only: empm_write_results, empm_output_meta_t, empm_output_claim, &
    empm_output_release, empm_write_snapshot_file, empm_staging_path, empm_xdmf_path, &
    empm_remove_stale_partials
  use empm_files, only: empm_mkdir_p, empm_remove, empm_rmdir
  use empm_checkpoint, only: empm_checkpoint_write, empm_checkpoint_read, empm_checkpoint_path
  use empm_posix, only: empm_stop_signal, empm_sleep, empm_errno, empm_errno_text
  use empm_parallel, only: empm_cpu_sample_t, empm_cpu_sample, empm_threads_for_load, &
                           empm_max_threads, empm_set_threads, EMPM_OMP_MIN_PARTICLES
  use empm_strings, only: str
  use empm_kinds, only: wp
  use empm_comm, only: empm_comm_t
  use empm_partition, only: empm_partition_particles, empm_gather_particles, &
    empm_copy_for_output, empm_gather_snapshot
  use empm_h5_mpio, only: empm_h5_collective
  implicit none
  private
  public :: empm_run_case, empm_write_shared

  ! Checkpoints next to the results file, and the stop signal the program caught (if it
  ! installed the handlers: `empm run` does, the library does not).
  type, extends(empm_run_hook_t) :: driver_hook_t
    character(len=:), allocatable :: path       ! OUT.ckpt.h5
    character(len=:), allocatable :: prev       ! OUT.ckpt.prev.h5
    character(len=:), allocatable :: case_text  ! the case file's text
    character(len=:), allocatable :: staging    ! OUT.h5.snapshots: each snapshot as taken
    character(len=:), allocatable :: results    ! OUT.h5
  contains
    procedure :: checkpoint => hook_checkpoint
    procedure :: stop_requested => hook_stop
    procedure :: snapshot => hook_snapshot
  end type driver_hook_t

contains

  subroutine hook_checkpoint(self, model, hist, state, err)
    class(driver_hook_t), intent(inout) :: self
    type(empm_model_t), intent(in) :: model
    type(empm_history_t), intent(in) :: hist
    type(empm_solver_state_t), intent(in) :: state
    type(empm_error_t), intent(out) :: err
    type(empm_model_t) :: whole
    type(empm_history_t) :: hwhole
    logical :: together
    if (.not. model%comm%parallel()) then
      call empm_checkpoint_write(self%path, self%prev, model, hist, state, self%case_text, &
        self%results, err)
      return
    end if
    ! Several processes: one checkpoint with every particle in id order (as a serial run's),
    ! from copies, so that the run goes on with its own share; any number of processes can
    ! restart from it. Written by all together, each a block of ids (parallel HDF5), or by the
    ! root holding every particle.
    together = empm_h5_collective(model%comm)
    call empm_copy_for_output(model, whole)
    hwhole = hist
    call empm_gather_particles(whole, hwhole, err, blocks=together)
    if (together) call model%comm%agree(err)
    if (err%code == EMPM_OK .and. (together .or. model%comm%is_root())) &
      call empm_checkpoint_write(self%path, self%prev, whole, hwhole, state, self%case_text, &
      self%results, err, together)
    call model%comm%agree(err)
  end subroutine hook_checkpoint

  !> Write the results of a run shared among the processes of `model%comm` (or of a serial
  !> one) to `path`, as [[empm_write_results]]: each process gets a block of consecutive ids
  !> and they write the file together (parallel HDF5), or the root gets every particle and
  !> writes it as a serial run does. Collective; every process returns the same `err`.
  !> `model` and `hist` then hold a block, or everything on the root: give copies
  !> ([[empm_copy_for_output]]) when the run goes on.
  subroutine empm_write_shared(path, model, hist, meta, complete, status, err)
    character(len=*), intent(in) :: path            !! output HDF5 file
    type(empm_model_t), intent(inout) :: model      !! final state (its particles replaced)
    type(empm_history_t), intent(inout) :: hist     !! histories and snapshots (likewise)
    type(empm_output_meta_t), intent(in) :: meta    !! root attributes
    logical, intent(in) :: complete                 !! whether the run reached t_end
    character(len=*), intent(in) :: status          !! '' or the message that stopped it
    type(empm_error_t), intent(out) :: err          !! error, the same on every process
    logical :: together
    together = empm_h5_collective(model%comm)
    call empm_gather_particles(model, hist, err, blocks=together)
    if (together) call model%comm%agree(err)
    if (err%code == EMPM_OK .and. (together .or. model%comm%is_root())) &
      call empm_write_results(path, model, hist, meta, complete, status, err, together)
    call model%comm%agree(err)
  end subroutine empm_write_shared

  ! Each snapshot goes to its own file in the staging folder as it is taken (written by the
  ! processes together, each a block of ids, or by the root), and the record keeps its name
  ! only: a run holds no snapshot in memory (docs/output.md, "Memory"). The results file
  ! copies them at the end.
  subroutine hook_snapshot(self, model, hist, err)
    class(driver_hook_t), intent(inout) :: self
    type(empm_model_t), intent(in) :: model
    type(empm_history_t), intent(inout) :: hist
    type(empm_error_t), intent(out) :: err
    type(empm_snapshot_t) :: sn
    character(len=:), allocatable :: file
    character(len=16) :: name
    logical :: together
    integer :: n
    if (hist%nsnap >= size(hist%snap)) return
    write(name, '(i6.6)') hist%nsnap
    file = self%staging//'/'//trim(name)//'.h5'
    n = model%pts%np
    if (.not. model%comm%parallel()) then
      ! Straight from the particles.
      associate (p => model%pts)
        call empm_write_snapshot_file(file, model%comm, self%case_text, model%t, model%step, &
          p%x(:, 1:n), &
          p%v(:, 1:n), p%stress(:, 1:n), p%strain(:, 1:n), p%m(1:n), p%vol(1:n), p%rho(1:n), &
          p%state(:, 1:n), .false., err)
      end associate
    else
      ! A copy of this process's particles goes to the block of their ids (or the root).
      together = empm_h5_collective(model%comm)
      call sn%take(model%t, model%step, model%pts)
      call empm_gather_snapshot(model%comm, sn, together)
      if (together .or. model%comm%is_root()) &
        call empm_write_snapshot_file(file, model%comm, self%case_text, model%t, model%step, &
        sn%x, sn%v, sn%stress, sn%strain, sn%m, sn%vol, sn%rho, sn%state, together, err)
      call model%comm%agree(err)
    end if
    if (err%code == EMPM_OK) call hist%add_staged(model%t, model%step, file)
  end subroutine hook_snapshot

  integer function hook_stop(self) result(sig)
    class(driver_hook_t), intent(inout) :: self
    associate (unused_ => self); end associate
    sig = empm_stop_signal()
  end function hook_stop

  !> Run the case in `path`, writing HDF5 to `output` (default: the case's &output file).
  !> Exit-status semantics when `err` is absent: 2 invalid input, 3 run-time guard, 4 I/O.
  !> A run stopped by a guard still writes its last good state, marked incomplete.
  !> The output is checked and locked before the run: a folder, device or other non-regular
  !> file at the output path is refused (status 2), and so is an output another live run is
  !> writing (status 4, the lock `OUT.lock`).
  !> The state at the start is stored as the first snapshot (t = 0, `/snapshots/000000`) even
  !> when the case's `snapshot_times` do not include it, unless `initial_snapshot` is false.
  !> With the case's `checkpoint_every`/`checkpoint_seconds`, checkpoints go to OUT.ckpt.h5
  !> (the previous one kept as OUT.ckpt.prev.h5); `restart` continues from one (a checkpoint
  !> of this case file written by this version, else status 2 saying why), so that the results
  !> equal the uninterrupted run's. A stop signal caught by the program (SIGINT, SIGTERM: see
  !> empm_catch_stop_signals) ends the run after the current step with a checkpoint and the
  !> results so far (marked incomplete), error code EMPM_ERR_INTERRUPTED.
  subroutine empm_run_case(path, output, progress, written, err, extra_groups, stats, &
                           initial_snapshot, restart, auto_threads, comm)
    character(len=*), intent(in) :: path                !! case file
    character(len=*), intent(in), optional :: output    !! output HDF5 path override
    logical, intent(in), optional :: progress           !! progress on stderr (default on; false
                                                        !! keeps the library quiet)
    character(len=:), allocatable, intent(out), optional :: written !! path of the HDF5 file
    type(empm_error_t), intent(out), optional :: err    !! error, if present
    character(len=*), intent(in), optional :: extra_groups !! groups of the case file that are
                                                        !! not the run's (blank-separated, e.g.
                                                        !! 'verify'): skipped, not rejected
    type(empm_run_stats_t), intent(out), optional :: stats !! steps, time steps, wall time and
                                                        !! energy balance (for a summary line)
    logical, intent(in), optional :: initial_snapshot   !! store the start as a snapshot
                                                        !! (default true)
    character(len=*), intent(in), optional :: restart   !! checkpoint to continue from ('' or
                                                        !! absent: start afresh)
    logical, intent(in), optional :: auto_threads       !! choose the OpenMP threads from the
                                                        !! machine's load (`empm run` without
                                                        !! --threads or OMP_NUM_THREADS): as
                                                        !! many as the cores other processes
                                                        !! leave idle over the set-up (at least
                                                        !! 0.2 s), at most the current number
    type(empm_comm_t), intent(in), optional :: comm     !! the processes that run the case
                                                        !! together (every one calls this with
                                                        !! the same arguments; the root writes
                                                        !! the results): docs/parallel.md.
                                                        !! Default: this process alone
    type(empm_case_t) :: cs
    type(driver_hook_t) :: hook
    type(empm_solver_state_t) :: sst
    character(len=:), allocatable :: warning
    logical :: resumed
    type(empm_history_t) :: hist
    type(empm_error_t) :: e, ew
    type(empm_output_meta_t) :: meta
    logical :: add0, shared
    type(empm_cpu_sample_t) :: load0
    integer(int64) :: clock0, clock1, rate
    character(len=:), allocatable :: own(:), folder(:)

    call system_clock(clock0, rate)
    call empm_cpu_sample(load0)
    ! Shared among processes, each stores its share of the particles (a restart reads its
    ! share from the checkpoint), then its window of the grid and its basis.
    resumed = .false.
    if (present(restart)) resumed = len_trim(restart) > 0
    shared = .false.
    if (present(comm)) shared = comm%parallel()
    ! Shared, each process stores its share of the particles only (collective).
    call empm_read_case(path, cs, e, extra_groups=extra_groups, shared=shared, comm=comm)
    ! Each process reads the case: one that cannot (a file missing on its machine) must not
    ! leave the others waiting. All take the error of the first process that has one.
    if (present(comm)) call comm%agree(e)
    if (e%code /= EMPM_OK) then
      call empm_raise_error(e, err); return
    end if
    if (present(output)) then
      if (len_trim(output) > 0) cs%output_file = trim(output)
    end if
    if (present(progress)) cs%run%progress = progress
    if (present(comm)) cs%model%comm = comm
    if (cs%model%comm%parallel()) then
      ! One thread per process unless OMP_NUM_THREADS or --threads say otherwise: the
      ! processes already share the cores.
      if (present(auto_threads)) then
        if (auto_threads) call empm_set_threads(1)
      end if
    else if (present(auto_threads)) then
      if (auto_threads) call choose_threads()
    end if
    if (shared .and. .not. resumed) then
      ! Each process takes its share of the particles, its window of the grid, and checks its
      ! share's shape functions: the set-up a serial run finishes in empm_read_case, before
      ! the output is claimed (an unfit case is the same input error, exit 2).
      call empm_partition_particles(cs%model, e, dealt=.true.)
      if (e%code == EMPM_OK) call empm_check_basis(path, cs, e)
      call cs%model%comm%agree(e)
      if (e%code /= EMPM_OK) then
        call empm_raise_error(e, err); return
      end if
    end if
    ! The root claims the output for all (one file, one lock), and makes the folder the
    ! snapshots go to as they are taken; its verdict is everyone's.
    hook%staging = empm_staging_path(cs%output_file); hook%results = cs%output_file
    if (cs%model%comm%is_root()) then
      call empm_output_claim(cs%output_file, e)
      if (e%code == EMPM_OK) then
        ! What a killed run of this output was writing (its snapshots are kept: a restart
        ! may need them).
        allocate(character(len=len(cs%output_file) + 16) :: own(4), folder(1))
        own(1) = cs%output_file; own(2) = empm_xdmf_path(cs%output_file)
        own(3) = empm_checkpoint_path(cs%output_file)
        own(4) = empm_checkpoint_path(cs%output_file, prev=.true.)
        folder(1) = hook%staging
        call empm_remove_stale_partials(own, folder)
        if (empm_mkdir_p(hook%staging) /= 0) then
          call e%set(EMPM_ERR_IO, cs%output_file//': cannot create the folder '// &
            hook%staging//' for its snapshots: '//empm_errno_text(empm_errno()))
          call release()
        end if
      end if
    end if
    call cs%model%comm%agree(e)
    if (e%code /= EMPM_OK) then
      call empm_raise_error(e, err); return
    end if
    ! A first frame at the start time, so that viewers show the undeformed state. The solver
    ! stores it before the first step: the time steps are unchanged.
    add0 = .true.
    if (present(initial_snapshot)) add0 = initial_snapshot
    if (size(cs%run%snapshot_times) > 0) add0 = add0 .and. cs%run%snapshot_times(1) > cs%model%t
    if (add0) cs%run%snapshot_times = [cs%model%t, cs%run%snapshot_times]
    call hist%init(cs%model%grid%ndim, cs%probe_name, cs%probe_particle, 1024, &
                   size(cs%run%snapshot_times))
    hook%path = empm_checkpoint_path(cs%output_file)
    hook%prev = empm_checkpoint_path(cs%output_file, prev=.true.)
    hook%case_text = cs%text
    if (resumed) then
      ! The checkpoint (written by any number of processes) holds every particle in id
      ! order: each process reads the columns of the particles dealt to it, then they move to
      ! the processes of their boxes below.
      call empm_checkpoint_read(trim(restart), cs%model, hist, sst, cs%text, warning, e, &
                                dealt=cs%deal)
      call cs%model%comm%agree(e)
      if (e%code /= EMPM_OK) then
        call release()
        call empm_raise_error(e, err); return
      end if
      if (len(warning) > 0 .and. cs%run%progress .and. cs%model%comm%is_root()) &
        write(error_unit, '(a)') 'empm: note: '//warning
    end if
    if (cs%model%comm%parallel()) then
      ! No basis is evaluated here: a restart continues from the checkpoint's shape-function
      ! state (the LME multipliers the next evaluation starts from), as a serial one does.
      if (resumed) call empm_partition_particles(cs%model, e, dealt=.true.)
      if (e%code /= EMPM_OK) then
        call release(); call empm_raise_error(e, err); return
      end if
      call hist%locate_probes(cs%model%pts)
    end if
    if (resumed) then
      call empm_solve(cs%model, cs%integ, cs%run, hist, e, stats, hook=hook, resume=sst)
    else
      call empm_solve(cs%model, cs%integ, cs%run, hist, e, stats, hook=hook)
    end if
    ! Set-up: all before the time loop (the solver's preparation, the first basis, included),
    ! the slowest process's.
    call system_clock(clock1)
    if (present(stats)) stats%setup = cs%model%comm%max_real(max(0.0_wp, &
      real(clock1 - clock0, wp) / real(max(rate, 1_int64), wp) - stats%wall))

    meta%case_file = path; meta%case_text = cs%text
    meta%shape = cs%shape_name; meta%integrator = cs%scheme_name
    meta%cfl = cs%run%cfl; meta%t_end = cs%run%t_end
    if (e%code == EMPM_OK) then
      call empm_write_shared(cs%output_file, cs%model, hist, meta, .true., '', ew)
    else
      call empm_write_shared(cs%output_file, cs%model, hist, meta, .false., e%message, ew)
    end if
    ! The snapshots are in the results now (a restart takes them from there).
    if (ew%code == EMPM_OK) call unstage()
    call release()
    if (present(written)) written = cs%output_file
    if (e%code /= EMPM_OK) then
      ! The guard's error, with its location fields; the message says where the state went.
      if (e%code == EMPM_ERR_INTERRUPTED .and. ew%code == EMPM_OK) then
        e%message = e%message//' to '//hook%path//'; results so far written to '// &
          cs%output_file//', marked incomplete; continue with --restart '//hook%path
      else if (ew%code == EMPM_OK) then
        e%message = e%message//' (last good state written to '//cs%output_file// &
          ', marked incomplete)'
      else
        e%message = e%message//' (and writing the last good state failed: '//ew%message//')'
      end if
      call empm_raise_error(e, err)
    else if (ew%code /= EMPM_OK) then
      call empm_raise_error(ew, err)
    end if

  contains

    ! The root removes the snapshot files of this run's folder: this run's (some of a
    ! restarted run's came from its results file instead), then on while they follow each
    ! other (a run writes them in order: those of an earlier, killed run beyond this one's
    ! too), and the folder when empty.
    subroutine unstage()
      integer :: k, info
      character(len=6) :: name
      if (.not. cs%model%comm%is_root()) return
      do k = 0, 999999
        write(name, '(i6.6)') k
        if (empm_remove(hook%staging//'/'//name//'.h5') /= 0 .and. k >= hist%nsnap) exit
      end do
      info = empm_rmdir(hook%staging)
    end subroutine unstage

    ! The root releases the output it claimed (and the snapshot folder, when empty).
    subroutine release()
      integer :: info
      if (.not. cs%model%comm%is_root()) return
      call empm_output_release(cs%output_file)
      if (allocated(hook%staging)) info = empm_rmdir(hook%staging)
    end subroutine release

    ! Threads for a run that can use them (EMPM_OMP_MIN_PARTICLES or more): the cores other
    ! processes left idle since the start of the set-up, measured over at least 0.2 s.
    subroutine choose_threads()
      type(empm_cpu_sample_t) :: load1
      integer :: nmax, n
      real :: other, waited
      nmax = empm_max_threads()
      if (nmax <= 1 .or. cs%model%pts%np < EMPM_OMP_MIN_PARTICLES) return
      call empm_cpu_sample(load1)
      waited = real(load1%clock - load0%clock) / real(max(1_int64, load1%rate))
      if (waited < 0.2) then
        call empm_sleep(0.2 - waited)
        call empm_cpu_sample(load1)
      end if
      call empm_threads_for_load(load0, load1, nmax, n, other)
      if (n == nmax) return
      call empm_set_threads(n)
      if (cs%run%progress) write(error_unit, '(a, f0.1, a)') 'empm: '//str(n)//' thread'// &
        trim(merge('s', ' ', n > 1))//' of '//str(nmax)//': other processes keep ', other, &
        ' cores busy (--threads N or OMP_NUM_THREADS to choose)'
    end subroutine choose_threads
  end subroutine empm_run_case
end module empm_driver
