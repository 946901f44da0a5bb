! First end-to-end check: the 1D vibrating bar (docs/algorithms §3) with linear shape
! functions and MUSL against the exact first-mode solution, through the public API.
module test_vibrating_bar
  use funit
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t
  use empm_particle_gen, only: empm_fill, GEOM_BOX, PLACE_GAUSS
  use empm_shape_factory, only: empm_shape_create
  use empm_material_factory, only: empm_material_create
  use empm_integrator, only: empm_integrator_t
  use empm_integrator_factory, only: empm_integrator_create
  use empm_solver, only: empm_solve, empm_run_config_t
  use empm_history, only: empm_history_t
  use empm_error, only: empm_error_t
  use empm_exact_bar, only: empm_vibrating_bar_t
  implicit none

contains

  ! Run the bar with `ncell` cells over its length to t = periods*T (T = 4L/c) at CFL 0.5 and
  ! return the volume-weighted RMS velocity error relative to v0.
  subroutine run_bar(ncell, scheme, v0, periods, rel_err)
    integer, intent(in) :: ncell
    character(len=*), intent(in) :: scheme
    real(wp), intent(in) :: v0, periods
    real(wp), intent(out) :: rel_err
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_run_config_t) :: cfg
    type(empm_history_t) :: hist
    type(empm_error_t) :: err
    type(empm_vibrating_bar_t) :: bar
    real(wp) :: h, zero3(3), vex
    integer :: info, nadd, nsel, p, np
    character(len=8) :: names(0)
    integer :: parts(0)
    bar%v0 = v0
    h = bar%L / ncell
    zero3 = 0.0_wp
    call model%grid%init(1, [0.0_wp], [h], [ncell + 2], info)
    call model%pts%alloc(1, 2 * ncell)
    allocate(model%mats(1))
    call empm_material_create('linear_elastic', bar%E, 0.0_wp, bar%rho, model%mats(1)%model, info)
    call empm_fill(model%pts, model%grid, GEOM_BOX, zero3, [bar%L, 0.0_wp, 0.0_wp], zero3, &
                   0.0_wp, 2, PLACE_GAUSS, bar%rho, 1, nadd, info)
    np = model%pts%np
    model%pts%v(1, 1:np) = bar%velocity(model%pts%x(1, 1:np), 0.0_wp)
    call model%nodes%fix_box(model%grid, zero3, zero3, [.true., .false., .false.], zero3, nsel)
    call empm_shape_create('linear', 1, model%shape, info)
    call model%finalize_setup()
    call empm_integrator_create(scheme, integ, info)
    cfg%t_end = periods * 4.0_wp * bar%L / sqrt(bar%E / bar%rho)
    cfg%cfl = 0.5_wp
    cfg%progress = .false.
    call hist%init(1, names, parts, 16, 0)
    call empm_solve(model, integ, cfg, hist, err)
#line 57 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertEqual(0, err%code, message='the run must complete', &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 57) )
  if (anyExceptions()) return
#line 58 "/work/main/tests/unit/test_vibrating_bar.pf"
    rel_err = 0.0_wp
    do p = 1, np
      vex = bar%velocity(model%pts%x0(1, p), cfg%t_end)
      rel_err = rel_err + model%pts%vol0(p) * (model%pts%v(1, p) - vex)**2
    end do
    rel_err = sqrt(rel_err / sum(model%pts%vol0(1:np))) / v0
  end subroutine run_bar

  !@test
  subroutine test_musl_linear_at_velocity_extremum()
    ! At t = T the velocity is extremal, so phase errors enter only quadratically and the error
    ! measures the spatial discretisation: linear elements with exact (Gauss) quadrature give
    ! O(h^2). Measured: 3.5e-5, 4.8e-6, 1.1e-6 (h = 1, 1/2, 1/4).
    real(wp) :: e(3), order
    call run_bar(25, 'musl', 1.0e-3_wp, 1.0_wp, e(1))
    call run_bar(50, 'musl', 1.0e-3_wp, 1.0_wp, e(2))
    call run_bar(100, 'musl', 1.0e-3_wp, 1.0_wp, e(3))
    print '(a,3es12.4)', 'vibrating bar MUSL/linear, t = T: relative RMS velocity error', e
#line 76 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertLessThan(e(1), 5.0e-5_wp, &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 76) )
  if (anyExceptions()) return
#line 77 "/work/main/tests/unit/test_vibrating_bar.pf"
    order = log(e(2) / e(3)) / log(2.0_wp)
    print '(a,f8.3)', '  observed order', order
#line 79 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertGreaterThan(order, 1.8_wp, &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 79) )
  if (anyExceptions()) return
#line 80 "/work/main/tests/unit/test_vibrating_bar.pf"
  end subroutine test_musl_linear_at_velocity_extremum

  !@test
  subroutine test_musl_linear_phase_error_is_first_order()
    ! At t = 5T/4 the exact velocity is zero and the error is the phase error. Forward-Euler MPM
    ! advances velocities that lag half a step behind positions (symplectic Euler), a phase
    ! error omega*dt/2 = beta*h*cfl/2; times the RMS of sin(beta x) over the bar (1/sqrt 2):
    ! e = beta*h*cfl/(2 sqrt 2) at leading order, first order in h at fixed CFL. The measured
    ! error must approach that estimate from above (within 25 % on the finest two grids) with an
    ! observed order near 1. Measured: 1.36e-2, 6.17e-3, 2.92e-3.
    type(empm_vibrating_bar_t) :: bar
    real(wp) :: e(3), est(3), order
    integer :: k
    integer, parameter :: ncell(3) = [25, 50, 100]
    do k = 1, 3
      call run_bar(ncell(k), 'musl', 1.0e-3_wp, 1.25_wp, e(k))
      est(k) = bar%beta() * (bar%L / ncell(k)) * 0.5_wp / (2.0_wp * sqrt(2.0_wp))
    end do
    print '(a,3es12.4)', 'vibrating bar MUSL/linear, t = 5T/4: relative RMS velocity error', e
    print '(a,3es12.4)', '  leading-order estimate beta*h*cfl/(2 sqrt 2)              ', est
    order = log(e(2) / e(3)) / log(2.0_wp)
    print '(a,f8.3)', '  observed order', order
#line 102 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertGreaterThan(e(2), est(2), &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 102) )
  if (anyExceptions()) return
#line 103 "/work/main/tests/unit/test_vibrating_bar.pf"
#line 103 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertLessThan(e(2), 1.25_wp * est(2), &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 103) )
  if (anyExceptions()) return
#line 104 "/work/main/tests/unit/test_vibrating_bar.pf"
#line 104 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertLessThan(e(3), 1.25_wp * est(3), &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 104) )
  if (anyExceptions()) return
#line 105 "/work/main/tests/unit/test_vibrating_bar.pf"
#line 105 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertGreaterThan(order, 0.9_wp, &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 105) )
  if (anyExceptions()) return
#line 106 "/work/main/tests/unit/test_vibrating_bar.pf"
#line 106 "/work/main/tests/unit/test_vibrating_bar.pf"
  call assertLessThan(order, 1.2_wp, &
 & location=SourceLocation( &
 & 'test_vibrating_bar.pf', &
 & 106) )
  if (anyExceptions()) return
#line 107 "/work/main/tests/unit/test_vibrating_bar.pf"
  end subroutine test_musl_linear_phase_error_is_first_order
end module test_vibrating_bar

module Wraptest_vibrating_bar
   use FUnit
   use test_vibrating_bar
   implicit none
   private

contains


end module Wraptest_vibrating_bar

function test_vibrating_bar_suite() result(suite)
   use FUnit
   use test_vibrating_bar
   use Wraptest_vibrating_bar
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_vibrating_bar_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_musl_linear_at_velocity_extremum', &
      test_musl_linear_at_velocity_extremum))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_musl_linear_phase_error_is_first_order', &
      test_musl_linear_phase_error_is_first_order))
   call suite%addTest(t)


end function test_vibrating_bar_suite

