!> High-level driver: read a case file, run it, write the results. Used by the `empm run`
!> command and callable from embedding codes.
module empm_driver
  use empm_error, only: empm_error_t, empm_raise_error, EMPM_OK
  use empm_case, only: empm_case_t
  use empm_input, only: empm_read_case
  use empm_history, only: empm_history_t
  use empm_solver, only: empm_solve, empm_run_stats_t
  use empm_output, only: empm_write_results, empm_output_meta_t, empm_output_claim, &
    empm_output_release
  implicit none
  private
  public :: empm_run_case

contains

  !> Run the case in `path`, writing HDF5 to `output` (default: the case's &output file).
  !> Exit-status semantics when `err` is absent: 2 invalid input, 3 run-time guard, 4 I/O.
  !> A run stopped by a guard still writes its last good state, marked incomplete.
  !> The output is checked and locked before the run: a folder, device or other non-regular
  !> file at the output path is refused (status 2), and so is an output another live run is
  !> writing (status 4, the lock `OUT.lock`).
  !> The state at the start is stored as the first snapshot (t = 0, `/snapshots/000000`) even
  !> when the case's `snapshot_times` do not include it, unless `initial_snapshot` is false.
  subroutine empm_run_case(path, output, progress, written, err, extra_groups, stats, &
                           initial_snapshot)
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
    type(empm_case_t) :: cs
    type(empm_history_t) :: hist
    type(empm_error_t) :: e, ew
    type(empm_output_meta_t) :: meta
    logical :: add0

    call empm_read_case(path, cs, e, extra_groups=extra_groups)
    if (e%code /= EMPM_OK) then
      call empm_raise_error(e, err); return
    end if
    if (present(output)) then
      if (len_trim(output) > 0) cs%output_file = trim(output)
    end if
    if (present(progress)) cs%run%progress = progress
    call empm_output_claim(cs%output_file, e)
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
    call empm_solve(cs%model, cs%integ, cs%run, hist, e, stats)

    meta%case_file = path; meta%case_text = cs%text
    meta%shape = cs%shape_name; meta%integrator = cs%scheme_name
    meta%cfl = cs%run%cfl; meta%t_end = cs%run%t_end
    if (e%code == EMPM_OK) then
      call empm_write_results(cs%output_file, cs%model, hist, meta, .true., '', ew)
    else
      call empm_write_results(cs%output_file, cs%model, hist, meta, .false., e%message, ew)
    end if
    call empm_output_release(cs%output_file)
    if (present(written)) written = cs%output_file
    if (e%code /= EMPM_OK) then
      ! The guard's error, with its location fields; the message says where the state went.
      if (ew%code == EMPM_OK) then
        e%message = e%message//' (last good state written to '//cs%output_file// &
          ', marked incomplete)'
      else
        e%message = e%message//' (and writing the last good state failed: '//ew%message//')'
      end if
      call empm_raise_error(e, err)
    else if (ew%code /= EMPM_OK) then
      call empm_raise_error(ew, err)
    end if
  end subroutine empm_run_case
end module empm_driver
