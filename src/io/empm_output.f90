!> Writes a run to HDF5 (layout in docs/output.md) and an XDMF file beside it for ParaView.
!>
!> The file is written under a temporary name (`OUT.partial`) and renamed when complete, so an
!> interrupted run never leaves a file that looks complete. A run stopped by a guard is still
!> written, with the last good state and the root attribute `complete = 0`.
!>
!> The materials' state variables are written by name (`state/<name>`, one value per particle),
!> NaN for the particles whose material does not declare that name.
module empm_output
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use hdf5, only: h5open_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F
  use empm_kinds, only: wp
  use empm_h5, only: hid_t, h5_group, h5_close_group, h5_write, h5_attr
  use empm_error, only: empm_error_t, empm_raise, EMPM_ERR_IO
  use empm_files, only: empm_rename, empm_remove
  use empm_version_info, only: empm_version
  use empm_model, only: empm_model_t
  use empm_material, only: STATE_NAME_LEN
  use empm_history, only: empm_history_t
  use empm_particles, only: empm_particles_t
  implicit none
  private
  public :: empm_write_results, empm_output_meta_t

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
  subroutine empm_write_results(path, model, hist, meta, complete, status, err)
    character(len=*), intent(in) :: path               !! output HDF5 file
    type(empm_model_t), intent(in) :: model            !! state to store as /final
    type(empm_history_t), intent(in) :: hist           !! histories and snapshots
    type(empm_output_meta_t), intent(in) :: meta       !! root attributes
    logical, intent(in) :: complete                    !! whether the run reached t_end
    character(len=*), intent(in) :: status             !! '' or the message that stopped it
    type(empm_error_t), intent(out), optional :: err   !! error, if present
    integer(hid_t) :: fid, g, gs, gp
    integer :: ierr, e, k, info, n
    character(len=:), allocatable :: tmp
    character(len=16) :: sname
    character(len=STATE_NAME_LEN), allocatable :: snames(:)
    integer, allocatable :: scol(:,:)
    tmp = path//'.partial'
    ierr = 0
    call state_columns(model, snames, scol)
    call h5open_f(e)
    call h5fcreate_f(tmp, H5F_ACC_TRUNC_F, fid, e)
    if (e /= 0) then
      call empm_raise(EMPM_ERR_IO, path//': cannot create HDF5 file '//tmp, err); return
    end if
    call h5_attr(fid, 'empm_version', empm_version(), ierr)
    call h5_attr(fid, 'complete', merge(1, 0, complete), ierr)
    call h5_attr(fid, 'status', merge('completed', 'stopped  ', complete)//' '//status, ierr)
    call h5_attr(fid, 'case_file', meta%case_file, ierr)
    call h5_attr(fid, 'case_text', meta%case_text, ierr)
    call h5_attr(fid, 'shape', meta%shape, ierr)
    call h5_attr(fid, 'integrator', meta%integrator, ierr)
    call h5_attr(fid, 'cfl', meta%cfl, ierr)
    call h5_attr(fid, 't_end', meta%t_end, ierr)
    call h5_attr(fid, 'ndim', model%grid%ndim, ierr)
    call h5_attr(fid, 'time', model%t, ierr)
    call h5_attr(fid, 'steps', model%step, ierr)

    call h5_group(fid, 'grid', g, ierr)
    call h5_attr(g, 'origin', model%grid%origin(1:model%grid%ndim), ierr)
    call h5_attr(g, 'h', model%grid%h(1:model%grid%ndim), ierr)
    call h5_attr(g, 'cells', model%grid%ncell(1), ierr)
    call h5_write(g, 'cells_per_direction', model%grid%ncell(1:model%grid%ndim), ierr)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'final', g, ierr)
    call h5_attr(g, 'time', model%t, ierr)
    call h5_attr(g, 'step', model%step, ierr)
    call write_state(g, model%pts, ierr)
    call write_state_vars(g, model%pts%state, model%pts%mat, snames, scol, ierr)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'snapshots', gs, ierr)
    do k = 1, hist%nsnap
      write(sname, '(i6.6)') k - 1
      call h5_group(gs, trim(sname), g, ierr)
      call h5_attr(g, 'time', hist%snap(k)%t, ierr)
      call h5_attr(g, 'step', hist%snap(k)%step, ierr)
      call h5_write(g, 'x', hist%snap(k)%x, ierr)
      call h5_write(g, 'xyz', pad3(hist%snap(k)%x), ierr)
      call h5_write(g, 'v', hist%snap(k)%v, ierr)
      call h5_write(g, 'stress', hist%snap(k)%stress, ierr)
      call h5_write(g, 'strain', hist%snap(k)%strain, ierr)
      call h5_write(g, 'mass', hist%snap(k)%m, ierr)
      call h5_write(g, 'volume', hist%snap(k)%vol, ierr)
      call h5_write(g, 'density', hist%snap(k)%rho, ierr)
      ! Particles keep their material for the whole run: the current indices apply.
      n = min(size(hist%snap(k)%m), model%pts%np)
      if (allocated(hist%snap(k)%state)) call write_state_vars(g, hist%snap(k)%state(:, 1:n), &
        model%pts%mat(1:n), snames, scol, ierr)
      call h5_close_group(g, ierr)
    end do
    call h5_close_group(gs, ierr)

    call h5_group(fid, 'history', g, ierr)
    call h5_write(g, 'time', hist%t(1:hist%nt), ierr)
    call h5_write(g, 'kinetic_energy', hist%kinetic(1:hist%nt), ierr)
    call h5_write(g, 'strain_energy', hist%strain(1:hist%nt), ierr)
    call h5_write(g, 'gravity_potential', hist%gravity(1:hist%nt), ierr)
    call h5_close_group(g, ierr)

    call h5_group(fid, 'probes', gs, ierr)
    do k = 1, hist%nprobe
      call h5_group(gs, trim(hist%probe_name(k)), gp, ierr)
      call h5_attr(gp, 'particle', hist%probe_particle(k), ierr)
      call h5_write(gp, 'time', hist%t(1:hist%nt), ierr)
      call h5_write(gp, 'x', hist%px(:, k, 1:hist%nt), ierr)
      call h5_write(gp, 'v', hist%pv(:, k, 1:hist%nt), ierr)
      call h5_write(gp, 'stress', hist%ps(:, k, 1:hist%nt), ierr)
      call h5_close_group(gp, ierr)
    end do
    call h5_close_group(gs, ierr)

    call h5fclose_f(fid, e)
    if (e /= 0) ierr = e
    if (ierr /= 0) then
      info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': writing the HDF5 output failed', err); return
    end if
    call write_xdmf(path, model, hist, snames, ierr)
    if (ierr /= 0) then
      info = empm_remove(tmp)
      call empm_raise(EMPM_ERR_IO, path//': cannot write the XDMF file', err); return
    end if
    if (empm_rename(tmp, path) /= 0) then
      call empm_raise(EMPM_ERR_IO, path//': cannot rename '//tmp//' to '//path, err)
    end if
  end subroutine empm_write_results

  subroutine write_state(g, pts, ierr)
    integer(hid_t), intent(in) :: g
    type(empm_particles_t), intent(in) :: pts
    integer, intent(inout) :: ierr
    integer :: n
    n = pts%np
    call h5_write(g, 'x', pts%x(:, 1:n), ierr)
    call h5_write(g, 'xyz', pad3(pts%x(:, 1:n)), ierr)
    call h5_write(g, 'x0', pts%x0(:, 1:n), ierr)
    call h5_write(g, 'v', pts%v(:, 1:n), ierr)
    call h5_write(g, 'a', pts%a(:, 1:n), ierr)
    call h5_write(g, 'stress', pts%stress(:, 1:n), ierr)
    call h5_write(g, 'strain', pts%strain(:, 1:n), ierr)
    call h5_write(g, 'mass', pts%m(1:n), ierr)
    call h5_write(g, 'volume', pts%vol(1:n), ierr)
    call h5_write(g, 'density', pts%rho(1:n), ierr)
    call h5_write(g, 'material', pts%mat(1:n), ierr)
  end subroutine write_state

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
  subroutine write_state_vars(g, state, mat, names, col, ierr)
    integer(hid_t), intent(in) :: g
    real(wp), intent(in) :: state(:,:)
    integer, intent(in) :: mat(:)
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: col(:,:)
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
      call h5_write(gs, trim(names(k)), buf, ierr)
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

  !> XDMF 2 temporal collection of the snapshots and the final state (particles as vertices),
  !> with one scalar attribute per state variable.
  subroutine write_xdmf(path, model, hist, snames, ierr)
    character(len=*), intent(in) :: path
    type(empm_model_t), intent(in) :: model
    type(empm_history_t), intent(in) :: hist
    character(len=*), intent(in) :: snames(:)
    integer, intent(inout) :: ierr
    integer :: u, k, ios, s
    character(len=:), allocatable :: xmf, h5name
    character(len=16) :: sname
    s = index(path, '/', back=.true.)
    h5name = path(s + 1:)
    k = index(path, '.h5', back=.true.)
    if (k > 0) then
      xmf = path(1:k - 1)//'.xmf'
    else
      xmf = path//'.xmf'
    end if
    open(newunit=u, file=xmf, status='replace', action='write', iostat=ios)
    if (ios /= 0) then
      ierr = 1; return
    end if
    write(u, '(a)') '<?xml version="1.0" ?>'
    write(u, '(a)') '<Xdmf Version="2.0">'
    write(u, '(a)') ' <Domain>'
    write(u, '(a)') '  <Grid Name="particles" GridType="Collection" CollectionType="Temporal">'
    do k = 1, hist%nsnap
      write(sname, '(i6.6)') k - 1
      call grid_entry(hist%snap(k)%t, size(hist%snap(k)%m), '/snapshots/'//trim(sname))
    end do
    if (hist%nsnap == 0) call grid_entry(model%t, model%pts%np, '/final')
    write(u, '(a)') '  </Grid>'
    write(u, '(a)') ' </Domain>'
    write(u, '(a)') '</Xdmf>'
    close(u)
  contains
    subroutine grid_entry(t, np, grp)
      real(wp), intent(in) :: t
      integer, intent(in) :: np
      character(len=*), intent(in) :: grp
      character(len=32) :: cnp, ct
      integer :: j
      write(cnp, '(i0)') np
      write(ct, '(es24.16)') t
      write(u, '(a)') '   <Grid Name="t" GridType="Uniform">'
      write(u, '(a)') '    <Time Value="'//trim(adjustl(ct))//'"/>'
      write(u, '(a)') '    <Topology TopologyType="Polyvertex" NumberOfElements="'// &
        trim(cnp)//'"/>'
      write(u, '(a)') '    <Geometry GeometryType="XYZ">'
      call item(grp//'/xyz', trim(cnp)//' 3')
      write(u, '(a)') '    </Geometry>'
      call attribute('velocity', 'Vector', grp//'/v', trim(cnp)//' '//dimstr(model%grid%ndim))
      call attribute('stress', 'Tensor6', grp//'/stress', trim(cnp)//' 6')
      call attribute('density', 'Scalar', grp//'/density', trim(cnp))
      do j = 1, size(snames)
        call attribute(trim(snames(j)), 'Scalar', grp//'/state/'//trim(snames(j)), trim(cnp))
      end do
      write(u, '(a)') '   </Grid>'
    end subroutine grid_entry
    subroutine attribute(name, kind, ds, dims)
      character(len=*), intent(in) :: name, kind, ds, dims
      write(u, '(a)') '    <Attribute Name="'//name//'" AttributeType="'//kind// &
        '" Center="Node">'
      call item(ds, dims)
      write(u, '(a)') '    </Attribute>'
    end subroutine attribute
    subroutine item(ds, dims)
      character(len=*), intent(in) :: ds, dims
      write(u, '(a)') '     <DataItem Dimensions="'//dims//'" NumberType="Float" '// &
        'Precision="8" Format="HDF">'//h5name//':'//ds//'</DataItem>'
    end subroutine item
    pure function dimstr(d) result(c)
      integer, intent(in) :: d
      character(len=1) :: c
      c = achar(iachar('0') + d)
    end function dimstr
  end subroutine write_xdmf
end module empm_output
