!> A modern Fortran host for empm (docs/embedding.md): the 1D bar of the C and Fortran 77
!> hosts, assembled from empm's derived types and run by empm_solve. Build:
!>   gfortran modern_host.f90 $(pkg-config --cflags --libs empm)
program modern_host
  use empm, only: empm_model_t, empm_integrator_t, empm_run_config_t, empm_history_t, &
                  empm_error_t, empm_wp, empm_pi, empm_create_material, empm_create_shape, &
                  empm_create_integrator, empm_solve, empm_kv, empm_version
  implicit none
  integer, parameter :: wp = empm_wp, np = 50
  real(wp), parameter :: L = 25.0_wp, E = 100.0_wp, rho = 1.0_wp, v0 = 1.0e-3_wp
  type(empm_model_t) :: model
  class(empm_integrator_t), allocatable :: integ
  type(empm_run_config_t) :: run
  type(empm_history_t) :: hist
  type(empm_error_t) :: err
  character(len=8) :: no_names(0)
  integer :: no_particles(0), p, info, nsel
  real(wp) :: x, beta, exact

  call model%grid%init(1, [0.0_wp], [1.0_wp], [27], info)
  if (info /= 0) error stop 'grid'
  call model%pts%alloc(1, np)
  allocate(model%mats(1))
  call empm_create_material('linear_elastic', empm_kv('E', E)//empm_kv('nu', 0.0_wp)// &
                            empm_kv('density', rho), model%mats(1)%model, err)
  if (err%code /= 0) error stop 'material'
  beta = empm_pi / (2 * L)
  do p = 1, np
    x = (p - 0.5_wp) * L / np
    call model%pts%append([x], L / np, rho, [0.5_wp * L / np], 1, err)
    model%pts%v(1, p) = v0 * sin(beta * x)
  end do
  call model%nodes%fix_box(model%grid, [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 0.0_wp], &
                           [.true., .false., .false.], [0.0_wp, 0.0_wp, 0.0_wp], nsel)
  call empm_create_shape('linear', model%grid, model%shape, err)
  if (err%code == 0) call empm_create_integrator('musl', integ, err)
  if (err%code == 0) call model%finalize_setup(err)
  if (err%code /= 0) error stop 'set-up'

  run%t_end = 2.5_wp; run%cfl = 0.5_wp; run%progress = .false.
  allocate(run%snapshot_times(0))
  call hist%init(1, no_names, no_particles, 128, 0, err)
  call empm_solve(model, integ, run, hist, err)
  if (err%code /= 0) then
    print '(a)', err%message; error stop 'run'
  end if
  exact = E * v0 / sqrt(E / rho) * cos(beta * model%pts%x(1, 1))
  print '(a, es11.4, a, es11.4)', 'empm '//empm_version()//': sigma_xx = ', &
    model%pts%stress(1, 1), ', exact ', exact
  if (abs(model%pts%stress(1, 1) - exact) > 0.01_wp * exact) error stop 'stress'
  print '(a)', 'modern host ok'
end program modern_host
