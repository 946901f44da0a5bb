!> Total, kinetic and strain energy histories of every time integrator (docs/integrators.md,
!> "Energy") on
!> - the vibrating bar (L = 25, E = 100, ρ = 1, fixed-free, first mode, v0 = 1e-3; h = 1,
!>   2 Gauss particles per cell, linear shape functions, CFL 0.5, 4 periods T = 4L/c);
!> - the colliding disks (Sulsky et al. 1994; unit square, 20 × 20 cells, 2 × 2 Gauss particles
!>   per cell, disks r = 0.2 at (0.2, 0.2) and (0.8, 0.8) moving at ±(0.1, 0.1) toward each
!>   other, E = 1000, ν = 0.3, ρ = 1000, linear shape functions, t_end = 4) at CFL 0.1 (as
!>   verification/colliding_disks.nml) and CFL 0.5.
!>
!> Usage: `energy_histories [outdir]` (default `reports/integrators`); writes
!> `outdir/energy.h5`: groups `vibrating_bar`, `colliding_disks_cfl0.1`, `colliding_disks_cfl0.5`,
!> each with one group per scheme holding t, kinetic, strain, total and the attributes
!> completed (1/0), message, cfl, steps, cpu_seconds. A run stopped by a solver guard keeps its
!> history up to the last good step. Prints a summary table. Plot:
!> `reports/integrators/plot_energy.py`.
program energy_histories
  use, intrinsic :: iso_fortran_env, only: int64
  use hdf5, only: h5open_f, h5close_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F
  use empm_kinds, only: wp
  use empm_h5, only: hid_t, h5_group, h5_close_group, h5_write, h5_attr
  use empm_files, only: empm_mkdir_p
  use empm_model, only: empm_model_t
  use empm_particle_gen, only: empm_fill, GEOM_BOX, GEOM_DISK, PLACE_GAUSS
  use empm_integrator, only: empm_integrator_t
  use empm_registry, only: empm_create_shape, empm_create_material, empm_create_integrator
  use empm_namelist, only: empm_kv
  use empm_solver, only: empm_solve, empm_run_config_t
  use empm_history, only: empm_history_t
  use empm_error, only: empm_error_t
  use empm_exact_bar, only: empm_vibrating_bar_t
  implicit none
  integer, parameter :: NS = 9
  integer, parameter :: CASE_BAR = 1, CASE_DISKS = 2
  character(len=16), parameter :: SCHEME(NS) = [character(len=16) :: 'usf', 'usl', 'musl', &
    'pc_published', 'pc_newmark', 'gen_alpha_grid', 'gen_alpha_grid', 'gen_alpha_grid', 'gen_alpha_grid']
  real(wp), parameter :: RHO_B(NS) = [0.8_wp, 0.8_wp, 0.8_wp, 0.8_wp, 0.8_wp, 0.0_wp, 0.5_wp, &
                                      0.8_wp, 1.0_wp]
  character(len=16), parameter :: LABEL(NS) = [character(len=16) :: 'usf', 'usl', 'musl', &
    'pc_published', 'pc_newmark', 'gen_alpha_grid_rb0.0', 'gen_alpha_grid_rb0.5', 'gen_alpha_grid_rb0.8', &
    'gen_alpha_grid_rb1.0']
  character(len=:), allocatable :: outdir
  character(len=512) :: buf
  integer(hid_t) :: fid
  integer :: ierr, e1, e2
  real(wp) :: total_cpu

  outdir = 'reports/integrators'
  if (command_argument_count() >= 1) then
    call get_command_argument(1, buf)
    outdir = trim(buf)
  end if
  if (empm_mkdir_p(outdir) /= 0) error stop 'energy_histories: cannot create the output folder'

  ierr = 0
  call h5open_f(ierr)
  call h5fcreate_f(outdir//'/energy.h5', H5F_ACC_TRUNC_F, fid, ierr)
  if (ierr /= 0) error stop 'energy_histories: cannot create energy.h5'
  call h5_attr(fid, 'description', 'Energy histories of the empm integrators '// &
    '(benchmarks/energy_histories.f90, docs/integrators.md)', ierr)
  total_cpu = 0.0_wp
  write(*, '(a)') 'case                     scheme            done  steps   E_end/E0-1   '// &
    'min E/E0-1   max E/E0-1   cpu [s]'
  call study('vibrating_bar', CASE_BAR, 0.5_wp)
  call study('colliding_disks_cfl0.1', CASE_DISKS, 0.1_wp)
  call study('colliding_disks_cfl0.5', CASE_DISKS, 0.5_wp)
  ! ierr has collected every write's status: the closes get their own, so none is lost.
  call h5fclose_f(fid, e1)
  call h5close_f(e2)
  if (ierr /= 0 .or. e1 /= 0 .or. e2 /= 0) error stop 'energy_histories: HDF5 error'
  write(*, '(a,f8.2,a)') 'total run time', total_cpu, ' s'
  write(*, '(a)') 'wrote '//outdir//'/energy.h5'

contains

  !> Run every scheme on one case and store the histories under group `name`.
  subroutine study(name, which, cfl)
    character(len=*), intent(in) :: name   !! group name
    integer, intent(in) :: which           !! CASE_BAR or CASE_DISKS
    real(wp), intent(in) :: cfl            !! Courant number
    integer(hid_t) :: gc
    integer :: i
    call h5_group(fid, name, gc, ierr)
    call h5_attr(gc, 'cfl', cfl, ierr)
    do i = 1, NS
      call run_one(name, which, cfl, i, gc)
    end do
    call h5_close_group(gc, ierr)
  end subroutine study

  !> One run (a fresh model) of scheme `i`; its histories go to group LABEL(i) under `gc`.
  subroutine run_one(name, which, cfl, i, gc)
    character(len=*), intent(in) :: name   !! case name (for the table)
    integer, intent(in) :: which           !! CASE_BAR or CASE_DISKS
    real(wp), intent(in) :: cfl            !! Courant number
    integer, intent(in) :: i               !! scheme index
    integer(hid_t), intent(in) :: gc       !! case group
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_run_config_t) :: cfg
    type(empm_history_t) :: hist
    type(empm_error_t) :: err
    integer(hid_t) :: g
    integer(int64) :: c0, c1, rate
    real(wp), allocatable :: tot(:)
    real(wp) :: cpu
    integer :: n
    character(len=8) :: names(0)
    integer :: parts(0)
    if (which == CASE_BAR) then
      call build_bar(model, cfg, cfl)
    else
      call build_disks(model, cfg, cfl)
    end if
    ! ρ_b is gen_alpha_grid's parameter; the other schemes declare none (an undeclared key is an
    ! error), so it is passed to gen_alpha_grid only.
    if (trim(SCHEME(i)) == 'gen_alpha_grid') then
      call empm_create_integrator(trim(SCHEME(i)), integ, err, empm_kv('rho_b', RHO_B(i)))
    else
      call empm_create_integrator(trim(SCHEME(i)), integ, err)
    end if
    call check_created(err, 'integrator '//trim(SCHEME(i)))
    cfg%progress = .false.
    call hist%init(model%grid%ndim, names, parts, 4096, 0)
    call system_clock(c0, rate)
    call empm_solve(model, integ, cfg, hist, err)
    call system_clock(c1)
    cpu = real(c1 - c0, wp) / real(rate, wp)
    total_cpu = total_cpu + cpu
    n = hist%nt
    tot = hist%kinetic(1:n) + hist%strain(1:n)
    call h5_group(gc, trim(LABEL(i)), g, ierr)
    call h5_write(g, 't', hist%t(1:n), ierr)
    call h5_write(g, 'kinetic', hist%kinetic(1:n), ierr)
    call h5_write(g, 'strain', hist%strain(1:n), ierr)
    call h5_write(g, 'total', tot, ierr)
    call h5_attr(g, 'scheme', trim(SCHEME(i)), ierr)
    call h5_attr(g, 'rho_b', RHO_B(i), ierr)
    call h5_attr(g, 'cfl', cfl, ierr)
    call h5_attr(g, 'steps', model%step, ierr)
    call h5_attr(g, 'completed', merge(1, 0, err%code == 0), ierr)
    if (err%code == 0) then
      call h5_attr(g, 'message', '', ierr)
    else
      call h5_attr(g, 'message', err%message, ierr)
    end if
    call h5_attr(g, 'cpu_seconds', cpu, ierr)
    call h5_close_group(g, ierr)
    write(*, '(a24,1x,a16,l3,i8,3es13.3,f9.3)') name, LABEL(i), err%code == 0, model%step, &
      tot(n) / tot(1) - 1.0_wp, minval(tot) / tot(1) - 1.0_wp, maxval(tot) / tot(1) - 1.0_wp, cpu
    if (err%code /= 0) write(*, '(27x,a)') 'stopped: '//err%message
  end subroutine run_one

  !> Vibrating bar, first mode (docs/benchmarks.md), as in tests/unit/test_energy.pf.
  subroutine build_bar(model, cfg, cfl)
    type(empm_model_t), intent(inout) :: model  !! model to set up
    type(empm_run_config_t), intent(out) :: cfg !! run controls
    real(wp), intent(in) :: cfl                 !! Courant number
    type(empm_vibrating_bar_t) :: bar
    type(empm_error_t) :: err
    real(wp) :: zero3(3), h
    integer :: info, nadd, nsel, np
    integer, parameter :: ncell = 25
    bar%v0 = 1.0e-3_wp
    zero3 = 0.0_wp
    h = bar%L / ncell
    call model%grid%init(1, [0.0_wp], [h], [ncell + 2], info)
    call model%pts%alloc(1, 2 * ncell)
    allocate(model%mats(1))
    call empm_create_material('linear_elastic', empm_kv('E', bar%E)//empm_kv('nu', 0.0_wp)// &
                              empm_kv('density', bar%rho), model%mats(1)%model, err)
    call check_created(err, 'bar material')
    call empm_fill(model%pts, model%grid, GEOM_BOX, zero3, [bar%L, 0.0_wp, 0.0_wp], zero3, &
                   0.0_wp, 2, PLACE_GAUSS, bar%rho, 1, nadd, info)
    np = model%pts%np
    model%pts%v(1, 1:np) = bar%velocity(model%pts%x(1, 1:np), 0.0_wp)
    call model%nodes%fix_box(model%grid, zero3, zero3, [.true., .false., .false.], zero3, nsel)
    call empm_create_shape('linear', model%grid, model%shape, err)
    call check_created(err, 'bar shape')
    call model%finalize_setup()
    cfg%t_end = 4.0_wp * 4.0_wp * bar%L / sqrt(bar%E / bar%rho)
    cfg%dt = cfl * h / sqrt(bar%E / bar%rho)
  end subroutine build_bar

  !> Colliding disks (docs/benchmarks.md, verification/colliding_disks.nml).
  subroutine build_disks(model, cfg, cfl)
    type(empm_model_t), intent(inout) :: model  !! model to set up
    type(empm_run_config_t), intent(out) :: cfg !! run controls
    real(wp), intent(in) :: cfl                 !! Courant number
    type(empm_error_t) :: err
    real(wp) :: zero3(3)
    integer :: info, n1, n2, np
    zero3 = 0.0_wp
    call model%grid%init(2, [0.0_wp, 0.0_wp], [0.05_wp, 0.05_wp], [20, 20], info)
    allocate(model%mats(1))
    call empm_create_material('linear_elastic', empm_kv('E', 1000.0_wp)// &
                              empm_kv('nu', 0.3_wp)//empm_kv('density', 1000.0_wp), &
                              model%mats(1)%model, err)
    call check_created(err, 'disks material')
    call model%pts%alloc(2, 512)
    call empm_fill(model%pts, model%grid, GEOM_DISK, zero3, zero3, [0.2_wp, 0.2_wp, 0.0_wp], &
                   0.2_wp, 2, PLACE_GAUSS, 1000.0_wp, 1, n1, info)
    call empm_fill(model%pts, model%grid, GEOM_DISK, zero3, zero3, [0.8_wp, 0.8_wp, 0.0_wp], &
                   0.2_wp, 2, PLACE_GAUSS, 1000.0_wp, 1, n2, info)
    np = model%pts%np
    model%pts%v(:, 1:n1) = 0.1_wp
    model%pts%v(:, n1 + 1:np) = -0.1_wp
    call empm_create_shape('linear', model%grid, model%shape, err)
    call check_created(err, 'disks shape')
    call model%finalize_setup()
    cfg%t_end = 4.0_wp
    cfg%cfl = cfl
  end subroutine build_disks

  !> Stop when the registry could not create a family (the study cannot run).
  subroutine check_created(err, what)
    type(empm_error_t), intent(in) :: err !! status of the creation
    character(len=*), intent(in) :: what  !! what was created, for the message
    if (err%code /= 0) then
      write(*, '(a)') 'energy_histories: '//what//': '//err%message
      error stop 1
    end if
  end subroutine check_created
end program energy_histories
