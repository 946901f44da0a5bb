!> Restart checkpoints: everything a run needs to continue bitwise as if it had not stopped
!> (layout in docs/output.md, "Checkpoints").
!>
!> A checkpoint holds every particle array (the integrators and the LME warm start keep their
!> memory there), the time, step and residual, the surface tractions' shape-function state,
!> the time loop's progress ([[empm_solver_state_t]]), the histories so far and where the
!> snapshots so far are (their files, or the results file's groups: a restart copies them from
!> there), so that the results file written at the end of a restarted run equals the
!> uninterrupted run's. It also records the program version, the full text of the case file and the number of
!> threads. A checkpoint is written under a unique partial name and renamed: `OUT.ckpt.h5`, the
!> previous one kept as `OUT.ckpt.prev.h5` (the last two). Reading one refuses, with an input
!> error saying why, a file that is not an empm checkpoint, one written by another version, for
!> another case file (first differing line named) or for another particle set.
module empm_checkpoint
  use hdf5, only: hid_t, h5open_f, h5eset_auto_f
  use empm_kinds, only: wp
  use empm_strings, only: str
  use empm_error, only: empm_error_t, empm_raise, EMPM_ERR_IO, EMPM_ERR_INPUT
  use empm_h5, only: h5_group, h5_close_group, h5_write, h5_attr, h5_open_read, &
    h5_close_file, h5_exists, h5_dims, h5_read, h5_read_attr
  use empm_files, only: empm_rename, empm_remove, empm_absolute, empm_path_beside
  use empm_posix, only: empm_errno, empm_errno_text, empm_write_reason, empm_path_kind, &
    PATH_REGULAR
  use empm_version_info, only: empm_version
  use empm_parallel, only: empm_max_threads
  use empm_model, only: empm_model_t
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_solver, only: empm_solver_state_t
  use empm_particle_gen, only: empm_deal_t
  use empm_output, only: empm_shared_file_t, empm_frame_header
  implicit none
  private
  public :: empm_checkpoint_write, empm_checkpoint_read, empm_checkpoint_path

  character(len=*), parameter :: FORMAT_NAME = 'empm checkpoint'
  ! 2: snapshots named (their files), not held
  integer, parameter :: FORMAT_VERSION = 2

contains

  !> The checkpoint file of the results file `output`: `OUT.h5` -> `OUT.ckpt.h5` (`prev`:
  !> `OUT.ckpt.prev.h5`, the one before).
  pure function empm_checkpoint_path(output, prev) result(path)
    character(len=*), intent(in) :: output     !! results file
    logical, intent(in), optional :: prev      !! the previous checkpoint's name
    character(len=:), allocatable :: path      !! checkpoint file
    character(len=:), allocatable :: stem
    integer :: n
    n = len_trim(output)
    stem = output(1:n)
    if (n > 3) then
      if (output(n - 2:n) == '.h5') stem = output(1:n - 3)
    end if
    path = stem//'.ckpt.h5'
    if (present(prev)) then
      if (prev) path = stem//'.ckpt.prev.h5'
    end if
  end function empm_checkpoint_path

  !> Write a checkpoint of `model`, `hist` and `state` to `path`, atomically; an existing
  !> `path` becomes the previous checkpoint (`prev`), replacing the one before. `together`:
  !> called by all processes, each holding a block of consecutive ids, as
  !> [[empm_write_results]]; the error is the root's.
  subroutine empm_checkpoint_write(path, prev, model, hist, state, case_text, results, err, &
                                   together)
    character(len=*), intent(in) :: path               !! checkpoint file
    character(len=*), intent(in) :: prev               !! where the previous one goes
    type(empm_model_t), intent(in) :: model            !! the state after a completed step
    type(empm_history_t), intent(in) :: hist           !! histories and snapshots so far
    type(empm_solver_state_t), intent(in) :: state     !! the time loop's progress
    character(len=*), intent(in) :: case_text          !! full text of the case file
    character(len=*), intent(in) :: results            !! the run's results file (a restart
                                                       !! finds the snapshots there when
                                                       !! their own files are gone)
    type(empm_error_t), intent(out) :: err             !! error (EMPM_ERR_IO), if any
    logical, intent(in), optional :: together          !! all processes write it (blocks)
    integer(hid_t) :: fid, g, gs, gk
    character(len=:), allocatable :: tmp
    integer :: e, ierr, k, n, nd, oserr, info, th(1)
    type(empm_shared_file_t) :: sf
    n = model%pts%np
    call h5open_f(e)
    call h5eset_auto_f(0, e)
    call sf%create(path, model%comm, n, together, tmp, fid, e)
    if (e /= 0) then
      if (.not. sf%root) return
      call empm_raise(EMPM_ERR_IO, path//': cannot create the checkpoint '//tmp//': '// &
        empm_errno_text(empm_errno()), err); return
    end if
    ierr = 0
    nd = model%grid%ndim
    call h5_attr(fid, 'format', FORMAT_NAME, ierr)
    call h5_attr(fid, 'format_version', FORMAT_VERSION, ierr)
    call h5_attr(fid, 'empm_version', empm_version(), ierr)
    call h5_attr(fid, 'results', relative_to(folder_of(path), results), ierr)
    call h5_attr(fid, 'case_text', case_text, ierr)
    ! The root's (an attribute of a file written together is the same on every process).
    th(1) = empm_max_threads()
    if (sf%together) call model%comm%bcast_ints(th, 0)
    call h5_attr(fid, 'threads', th(1), ierr)
    call h5_attr(fid, 'particles', sf%ntotal, ierr)
    call h5_attr(fid, 'ndim', nd, ierr)
    call h5_attr(fid, 'nstate', model%pts%nstate, ierr)

    call h5_group(fid, 'model', g, ierr)
    call h5_write(g, 'scalars', [model%t, real(model%step, wp), model%residual], ierr, sf%sh)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'particles', g, ierr)
    associate (p => model%pts)
      call h5_write(g, 'x', p%x(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'x0', p%x0(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'v', p%v(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'a', p%a(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'dx', p%dx(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'm', p%m(1:n), ierr, sf%pp)
      call h5_write(g, 'vol', p%vol(1:n), ierr, sf%pp)
      call h5_write(g, 'vol0', p%vol0(1:n), ierr, sf%pp)
      call h5_write(g, 'rho', p%rho(1:n), ierr, sf%pp)
      call h5_write(g, 'stress', p%stress(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'strain', p%strain(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'F', reshape(p%F(:, :, 1:n), [9, n]), ierr, sf%pp)
      call h5_write(g, 'lp', p%lp(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'lam', p%lam(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'lam_old', p%lam_old(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'lam_prev', p%lam_prev(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'lam_old_prev', p%lam_old_prev(:, 1:n), ierr, sf%pp)
      call h5_write(g, 'vol_fill', p%vol_fill(1:n), ierr, sf%pp)
      call h5_write(g, 'mat', real(p%mat(1:n), wp), ierr, sf%pp)
      if (p%nstate > 0) call h5_write(g, 'state', p%state(:, 1:n), ierr, sf%pp)
    end associate
    call h5_close_group(g, ierr)

    call h5_group(fid, 'tractions', g, ierr)
    if (model%loads%ntraction() > 0) then
      do k = 1, size(model%loads%tractions)
        call h5_group(g, str(k), gk, ierr)
        associate (tr => model%loads%tractions(k))
          if (allocated(tr%lam)) then
            if (size(tr%lam) > 0) call h5_write(gk, 'lam', tr%lam, ierr, sf%sh)
          end if
        end associate
        call h5_close_group(gk, ierr)
      end do
    end if
    call h5_close_group(g, ierr)

    call h5_group(fid, 'solver', g, ierr)
    call h5_write(g, 'scalars', [real(state%isnap, wp), real(state%steps, wp), state%dt_min, &
      state%dt_max, state%t_start, state%energy_initial, state%work_gravity], ierr, sf%sh)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'history', g, ierr)
    call h5_write(g, 'counts', [real(hist%nt, wp), real(hist%nprobe, wp), &
      real(hist%nsnap, wp), merge(1.0_wp, 0.0_wp, hist%tracked), real(hist%nset, wp)], ierr, &
      sf%sh)
    if (hist%nt > 0) then
      call h5_write(g, 't', hist%t(1:hist%nt), ierr, sf%sh)
      call h5_write(g, 'kinetic', hist%kinetic(1:hist%nt), ierr, sf%sh)
      call h5_write(g, 'strain', hist%strain(1:hist%nt), ierr, sf%sh)
      call h5_write(g, 'gravity', hist%gravity(1:hist%nt), ierr, sf%sh)
      if (hist%nprobe > 0) then
        call h5_write(g, 'px', reshape(hist%px(:, :, 1:hist%nt), &
          [size(hist%px, 1) * hist%nprobe, hist%nt]), ierr, sf%sh)
        call h5_write(g, 'pv', reshape(hist%pv(:, :, 1:hist%nt), &
          [size(hist%pv, 1) * hist%nprobe, hist%nt]), ierr, sf%sh)
        call h5_write(g, 'ps', reshape(hist%ps(:, :, 1:hist%nt), [6 * hist%nprobe, hist%nt]), &
          ierr, sf%sh)
      end if
      if (hist%tracked) then
        call h5_write(g, 'residual', hist%residual(1:hist%nt), ierr, sf%sh)
        if (hist%nset > 0) then
          call h5_write(g, 'reaction', reshape(hist%reaction(:, :, 1:hist%nt), &
            [size(hist%reaction, 1) * hist%nset, hist%nt]), ierr, sf%sh)
          call h5_write(g, 'set_disp', reshape(hist%set_disp(:, :, 1:hist%nt), &
            [size(hist%set_disp, 1) * hist%nset, hist%nt]), ierr, sf%sh)
        end if
      end if
    end if
    ! The snapshots stay in their files (empm_run_case writes each as it is taken): their
    ! names, relative to the checkpoint's folder.
    call h5_group(g, 'snapshots', gs, ierr)
    do k = 1, hist%nsnap
      call h5_group(gs, str(k), gk, ierr)
      associate (sn => hist%snap(k))
        call h5_write(gk, 'scalars', [sn%t, real(sn%step, wp)], ierr, sf%sh)
        if (allocated(sn%file)) then
          call h5_attr(gk, 'file', relative_to(folder_of(path), sn%file), ierr)
          call h5_attr(gk, 'frame', sn%frame, ierr)
        else
          ierr = 1 ! held in memory: only a run that streams its snapshots checkpoints
        end if
      end associate
      call h5_close_group(gk, ierr)
    end do
    call h5_close_group(gs, ierr)
    call h5_close_group(g, ierr)

    call sf%close(model%comm, path, tmp, fid, ierr, oserr)
    if (.not. sf%root) return
    if (ierr /= 0) then
      info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': writing the checkpoint failed: '// &
        empm_write_reason(oserr), err); return
    end if
    ! Keep the last two: the current one becomes the previous, then the new one takes its
    ! place (a crash between the two renames leaves the previous one to restart from).
    if (empm_path_kind(path) == PATH_REGULAR) then
      if (empm_rename(path, prev) /= 0) then
        oserr = empm_errno(); info = empm_remove(tmp)
        call empm_raise(EMPM_ERR_IO, path//': cannot keep it as '//prev//': '// &
          empm_write_reason(oserr), err); return
      end if
    end if
    if (empm_rename(tmp, path) /= 0) then
      oserr = empm_errno(); info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot rename '//tmp//' to it: '// &
        empm_write_reason(oserr), err); return
    end if
  end subroutine empm_checkpoint_write

  !> Restore `model` (set up from the same case file), `hist` (initialised for it) and `state`
  !> from the checkpoint `path`. Refused (EMPM_ERR_INPUT, saying why) when `path` is missing or
  !> not an empm checkpoint, or was written by another version of empm, for another case file
  !> (`case_text` differs) or for another particle set. `warning` is '' or a note (another
  !> number of threads: the run continues, but not bitwise).
  subroutine empm_checkpoint_read(path, model, hist, state, case_text, warning, err, dealt)
    character(len=*), intent(in) :: path               !! checkpoint file
    type(empm_model_t), intent(inout) :: model         !! model to restore into
    type(empm_history_t), intent(inout) :: hist        !! histories to restore into
    type(empm_solver_state_t), intent(out) :: state    !! the time loop's progress
    character(len=*), intent(in) :: case_text          !! full text of this run's case file
    character(len=:), allocatable, intent(out) :: warning !! '' or a note for the user
    type(empm_error_t), intent(out) :: err             !! error, if any
    type(empm_deal_t), intent(in), optional :: dealt   !! the case's particles dealt out among
                                                       !! processes: each reads its share (its
                                                       !! ids, of particles and snapshots)
    integer(hid_t) :: fid, g, gs, gk
    integer :: cols(2), ntotal
    logical :: share
    character(len=:), allocatable :: s, results
    real(wp), allocatable :: r1(:), r2(:,:)
    real(wp) :: sc(7), cnt(5)
    integer :: ierr, e, n, nd, k, nt, np, ns, threads, fv
    warning = ''
    ! Failures are ours to report, once: not HDF5's error stacks (a damaged file).
    call h5open_f(e)
    call h5eset_auto_f(0, e)
    call h5_open_read(path, fid, ierr)
    select case (ierr)
    case (1)
      call refuse('no such file'); return
    case (2)
      call refuse('not an HDF5 file'); return
    case (3)
      call refuse('cannot be opened'); return
    end select
    ierr = 0
    call h5_read_attr(fid, 'format', s, ierr)
    if (ierr /= 0 .or. s /= FORMAT_NAME) then
      call refuse('not an empm checkpoint (no "format" attribute saying so)'); return
    end if
    call h5_read_attr(fid, 'format_version', fv, ierr)
    if (ierr /= 0 .or. fv /= FORMAT_VERSION) then
      call refuse('its format version is '//str(fv)//', this empm reads version '// &
        str(FORMAT_VERSION)); return
    end if
    call h5_read_attr(fid, 'empm_version', s, ierr)
    if (ierr /= 0) then
      call refuse('it has no empm_version attribute'); return
    end if
    if (s /= empm_version()) then
      call refuse('written by empm '//s//', this is empm '//empm_version()// &
        ' (a checkpoint restarts only with the version that wrote it)'); return
    end if
    call h5_read_attr(fid, 'case_text', s, ierr)
    if (ierr /= 0) then
      call refuse('it has no case_text attribute'); return
    end if
    if (s /= case_text) then
      call refuse('written for another case file: '//first_difference(s, case_text)); return
    end if
    call h5_read_attr(fid, 'results', results, ierr)
    if (ierr /= 0) then
      call refuse('it has no results attribute'); return
    end if
    np = int_attr('particles'); nd = int_attr('ndim'); ns = int_attr('nstate')
    threads = int_attr('threads')
    if (ierr /= 0) then
      call refuse('its attributes particles, ndim, nstate, threads are incomplete'); return
    end if
    ! Dealt out, this process reads the columns of its ids: rank + 1, rank + 1 + P, ...
    share = .false.; ntotal = model%pts%np; cols = [0, 1]
    if (present(dealt)) then
      share = dealt%every > 1
      if (share) then
        ntotal = dealt%n; cols = [dealt%rank, dealt%every]
      end if
    end if
    if (np /= ntotal .or. nd /= model%grid%ndim .or. ns /= model%pts%nstate) then
      call refuse('it holds '//str(np)//' particles in '//str(nd)//'D with '//str(ns)// &
        ' state variables, the case '//str(ntotal)//' in '//str(model%grid%ndim)// &
        'D with '//str(model%pts%nstate)); return
    end if
    if (threads /= empm_max_threads()) warning = 'the checkpoint was written with '// &
      str(threads)//' threads, this run uses '//str(empm_max_threads())//': it continues, '// &
      'but not bitwise as the uninterrupted run (the sums over particles follow the threads)'
    n = model%pts%np

    ! Everything below exists in a file written by empm_checkpoint_write of this version.
    call open_group(fid, 'model', g)
    allocate(r1(3)); call h5_read(g, 'scalars', r1, ierr)
    model%t = r1(1); model%step = nint(r1(2)); model%residual = r1(3)
    call h5_close_group(g, ierr)

    call open_group(fid, 'particles', g)
    associate (p => model%pts)
      call h5_read(g, 'x', p%x(:, 1:n), ierr, cols)
      call h5_read(g, 'x0', p%x0(:, 1:n), ierr, cols)
      call h5_read(g, 'v', p%v(:, 1:n), ierr, cols)
      call h5_read(g, 'a', p%a(:, 1:n), ierr, cols)
      call h5_read(g, 'dx', p%dx(:, 1:n), ierr, cols)
      call h5_read(g, 'm', p%m(1:n), ierr, cols); call h5_read(g, 'vol', p%vol(1:n), ierr, cols)
      call h5_read(g, 'vol0', p%vol0(1:n), ierr, cols)
      call h5_read(g, 'rho', p%rho(1:n), ierr, cols)
      call h5_read(g, 'stress', p%stress(:, 1:n), ierr, cols)
      call h5_read(g, 'strain', p%strain(:, 1:n), ierr, cols)
      allocate(r2(9, n)); call h5_read(g, 'F', r2, ierr, cols)
      p%F(:, :, 1:n) = reshape(r2, [3, 3, n]); deallocate(r2)
      call h5_read(g, 'lp', p%lp(:, 1:n), ierr, cols)
      call h5_read(g, 'lam', p%lam(:, 1:n), ierr, cols)
      call h5_read(g, 'lam_old', p%lam_old(:, 1:n), ierr, cols)
      call h5_read(g, 'lam_prev', p%lam_prev(:, 1:n), ierr, cols)
      call h5_read(g, 'lam_old_prev', p%lam_old_prev(:, 1:n), ierr, cols)
      ! Checkpoints before session 12 lack it: the current volumes (what they restarted with).
      if (h5_exists(g, 'vol_fill')) then
        call h5_read(g, 'vol_fill', p%vol_fill(1:n), ierr, cols)
      else
        p%vol_fill(1:n) = p%vol(1:n)
      end if
      deallocate(r1); allocate(r1(n)); call h5_read(g, 'mat', r1, ierr, cols)
      p%mat(1:n) = nint(r1)
      if (p%nstate > 0) call h5_read(g, 'state', p%state(:, 1:n), ierr, cols)
    end associate
    call h5_close_group(g, ierr)

    call open_group(fid, 'tractions', g)
    if (model%loads%ntraction() > 0) then
      do k = 1, size(model%loads%tractions)
        associate (tr => model%loads%tractions(k))
          if (allocated(tr%lam)) deallocate(tr%lam)
          allocate(tr%lam(nd, size(tr%part)))
          tr%lam = 0.0_wp
          call open_group(g, str(k), gk)
          if (size(tr%lam) > 0) call h5_read(gk, 'lam', tr%lam, ierr)
          call h5_close_group(gk, ierr)
        end associate
      end do
    end if
    call h5_close_group(g, ierr)

    call open_group(fid, 'solver', g)
    call h5_read(g, 'scalars', sc, ierr)
    state%isnap = nint(sc(1)); state%steps = nint(sc(2)); state%dt_min = sc(3)
    state%dt_max = sc(4); state%t_start = sc(5); state%energy_initial = sc(6)
    state%work_gravity = sc(7)
    call h5_close_group(g, ierr)

    call open_group(fid, 'history', g)
    call h5_read(g, 'counts', cnt, ierr)
    nt = nint(cnt(1))
    if (nint(cnt(2)) /= hist%nprobe .or. nint(cnt(3)) > size(hist%snap)) then
      call refuse('its probes or snapshots do not match the case file'); return
    end if
    call restore_history()
    if (err%code /= 0) return
    call h5_close_group(g, ierr)
    call h5_close_file(fid, ierr)
    if (ierr /= 0) then
      call empm_raise(EMPM_ERR_IO, path//': reading the checkpoint failed (a damaged file?)', &
        err)
    end if

  contains

    subroutine refuse(why)
      character(len=*), intent(in) :: why
      integer :: ie
      if (fid >= 0) call h5_close_file(fid, ie)
      call empm_raise(EMPM_ERR_INPUT, path//': cannot restart from this checkpoint: '//why, err)
    end subroutine refuse

    subroutine open_group(loc, name, gid)
      use hdf5, only: h5gopen_f
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      integer(hid_t), intent(out) :: gid
      integer :: ie
      call h5gopen_f(loc, name, gid, ie)
      if (ie /= 0) ierr = 1
    end subroutine open_group

    integer function int_attr(name) result(v)
      character(len=*), intent(in) :: name
      v = -1
      call h5_read_attr(fid, name, v, ierr)
    end function int_attr

    ! The histories as recorded up to the checkpoint, in arrays with room to grow.
    subroutine restore_history()
      character(len=:), allocatable :: rel, fr, why, why_alt
      character(len=6) :: num
      type(empm_snapshot_t) :: alt
      integer :: c, np_, d, ks
      real(wp) :: ssc(2)
      d = size(hist%px, 1); np_ = hist%nprobe
      c = max(size(hist%t), nt, 16)
      if (size(hist%t) < c) then
        deallocate(hist%t, hist%kinetic, hist%strain, hist%gravity, hist%px, hist%pv, hist%ps)
        allocate(hist%t(c), hist%kinetic(c), hist%strain(c), hist%gravity(c), &
          hist%px(d, np_, c), hist%pv(d, np_, c), hist%ps(6, np_, c))
      end if
      hist%nt = nt
      hist%tracked = nint(cnt(4)) == 1
      hist%nset = nint(cnt(5))
      if (nt > 0) then
        call h5_read(g, 't', hist%t(1:nt), ierr)
        call h5_read(g, 'kinetic', hist%kinetic(1:nt), ierr)
        call h5_read(g, 'strain', hist%strain(1:nt), ierr)
        call h5_read(g, 'gravity', hist%gravity(1:nt), ierr)
        if (np_ > 0) then
          allocate(r2(d * np_, nt))
          call h5_read(g, 'px', r2, ierr); hist%px(:, :, 1:nt) = reshape(r2, [d, np_, nt])
          call h5_read(g, 'pv', r2, ierr); hist%pv(:, :, 1:nt) = reshape(r2, [d, np_, nt])
          deallocate(r2); allocate(r2(6 * np_, nt))
          call h5_read(g, 'ps', r2, ierr); hist%ps(:, :, 1:nt) = reshape(r2, [6, np_, nt])
          deallocate(r2)
        end if
      end if
      if (allocated(hist%residual)) deallocate(hist%residual)
      if (allocated(hist%set_name)) deallocate(hist%set_name, hist%reaction, hist%set_disp)
      if (hist%tracked) then
        ! Tracking and its node sets come from the case file, as when they were recorded.
        if (hist%nset /= model%nodes%nset) then
          call refuse('its reaction sets do not match the case file'); return
        end if
        allocate(hist%residual(c), hist%set_name(hist%nset), &
          hist%reaction(nd, hist%nset, c), hist%set_disp(nd, hist%nset, c))
        hist%set_name = model%nodes%set_name(1:hist%nset)
        if (nt > 0) then
          call h5_read(g, 'residual', hist%residual(1:nt), ierr)
          if (hist%nset > 0) then
            allocate(r2(nd * hist%nset, nt))
            call h5_read(g, 'reaction', r2, ierr)
            hist%reaction(:, :, 1:nt) = reshape(r2, [nd, hist%nset, nt])
            call h5_read(g, 'set_disp', r2, ierr)
            hist%set_disp(:, :, 1:nt) = reshape(r2, [nd, hist%nset, nt])
            deallocate(r2)
          end if
        end if
      end if
      hist%nsnap = nint(cnt(3))
      why = ''
      call open_group(g, 'snapshots', gs)
      do ks = 1, hist%nsnap
        call open_group(gs, str(ks), gk)
        associate (sn => hist%snap(ks))
          call h5_read(gk, 'scalars', ssc, ierr)
          sn%t = ssc(1); sn%step = nint(ssc(2))
          call h5_read_attr(gk, 'file', rel, ierr)
          call h5_read_attr(gk, 'frame', fr, ierr)
          if (ierr /= 0) exit
          sn%frame = trim(fr) ! '' is stored as ' '
          sn%file = empm_path_beside(path, rel)
          why = snapshot_problem(sn, np, case_text)
          if (len(why) > 0) then
            ! Its own file is gone once the results of the run that took it hold it (a run
            ! that ended, or was stopped by a signal): taken from there, the results beside
            ! the snapshot's folder (OUT.h5 of OUT.h5.snapshots/), else this checkpoint's.
            alt%t = sn%t; alt%step = sn%step
            write(num, '(i6.6)') ks - 1
            alt%frame = '/snapshots/'//num
            alt%file = results_of(sn%file)
            why_alt = 'is not named'
            if (len(alt%file) > 0) why_alt = snapshot_problem(alt, np, case_text)
            if (len(why_alt) > 0 .and. alt%file /= empm_path_beside(path, results)) then
              alt%file = empm_path_beside(path, results)
              why_alt = snapshot_problem(alt, np, case_text)
            end if
            if (len(why_alt) == 0) then
              sn%file = alt%file; sn%frame = alt%frame; why = ''
            else
              why = 'neither in '//sn%file//', which '//why//', nor in the results '// &
                alt%file//', which '//why_alt
            end if
          end if
        end associate
        call h5_close_group(gk, ierr)
        if (len(why) > 0) exit
      end do
      call h5_close_group(gs, ierr)
      if (len(why) > 0) then
        call h5_close_group(g, ierr)
        call refuse('its snapshot '//str(ks - 1)//' (t = '//str(hist%snap(ks)%t)// &
          ' s) is '//why); return
      end if
    end subroutine restore_history
  end subroutine empm_checkpoint_read

  ! '' when group `sn%frame` of `sn%file` holds the snapshot `sn` (its time and step) of `np`
  ! particles, else why not (words following "which").
  function snapshot_problem(sn, np, case_text) result(why)
    type(empm_snapshot_t), intent(in) :: sn
    integer, intent(in) :: np
    character(len=*), intent(in) :: case_text
    character(len=:), allocatable :: why
    character(len=:), allocatable :: text
    integer(hid_t) :: fid
    integer :: e, step, ie, n
    real(wp) :: t
    why = ''
    call h5_open_read(sn%file, fid, e)
    select case (e)
    case (1)
      why = 'is missing'; return
    case (2, 3)
      why = 'is not a readable HDF5 file'; return
    end select
    ! Written for this case (a snapshot file, or the results file): another case's snapshot
    ! at the same time and step is not this one.
    call h5_read_attr(fid, 'case_text', text, e)
    if (e /= 0) then
      call h5_close_file(fid, ie)
      why = 'has no case_text attribute'; return
    else if (text /= case_text) then
      call h5_close_file(fid, ie)
      why = 'was written for another case file'; return
    end if
    call empm_frame_header(fid, sn%frame, t, step, n, e)
    call h5_close_file(fid, ie)
    if (e /= 0) then
      why = 'has no snapshot at "'//sn%frame//'/"'
    else if (step /= sn%step .or. t /= sn%t .or. n /= np) then
      why = 'holds another (step '//str(step)//', t = '//str(t)//' s, '//str(n)//' particles)'
    end if
  end function snapshot_problem

  ! The results file whose snapshot folder holds `file` (OUT.h5 for OUT.h5.snapshots/NNNNNN.h5),
  ! '' when `file` lies in no such folder (a results file itself).
  pure function results_of(file) result(res)
    character(len=*), intent(in) :: file
    character(len=:), allocatable :: res
    character(len=*), parameter :: TAIL = '.snapshots/'
    integer :: k
    res = ''
    k = index(file, TAIL, back=.true.)
    if (k > 1) res = file(1:k - 1)
  end function results_of

  ! The folder part of `path`, with its final '/' ('' for a bare name).
  pure function folder_of(path) result(dir)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: dir
    dir = path(1:index(path, '/', back=.true.))
  end function folder_of

  ! `file` (a path as the run names it) relative to the folder `dir` (as folder_of gives it):
  ! the rest of it when it lies there, as it is when `dir` is the working folder, else
  ! absolute (so that a restart finds it wherever it runs from).
  function relative_to(dir, file) result(rel)
    character(len=*), intent(in) :: dir, file
    character(len=:), allocatable :: rel
    rel = file
    if (len(dir) == 0) return
    if (index(file, dir) == 1) then
      rel = file(len(dir) + 1:)
    else
      rel = empm_absolute(file)
    end if
  end function relative_to

  !> 'line N: "..." here, "..." in the checkpoint' for the first line where two texts differ.
  pure function first_difference(saved, now) result(msg)
    character(len=*), intent(in) :: saved, now
    character(len=:), allocatable :: msg
    integer :: i, line, a0, b0, a1, b1
    line = 1; a0 = 1; b0 = 1
    do i = 1, min(len(saved), len(now))
      if (saved(i:i) /= now(i:i)) exit
      if (now(i:i) == new_line('a')) then
        line = line + 1; a0 = i + 1; b0 = i + 1
      end if
    end do
    a1 = index(saved(a0:), new_line('a')); b1 = index(now(b0:), new_line('a'))
    if (a1 == 0) then
      a1 = len(saved)
    else
      a1 = a0 + a1 - 2
    end if
    if (b1 == 0) then
      b1 = len(now)
    else
      b1 = b0 + b1 - 2
    end if
    msg = 'line '//str(line)//' is "'//now(b0:b1)//'" here, "'//saved(a0:a1)// &
      '" in the checkpoint'
  end function first_difference
end module empm_checkpoint
