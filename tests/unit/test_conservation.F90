! Conservation by the particle-grid transfers: mass and momentum are conserved exactly by
! P2G/G2P (no constraints, no body force), and a rigid translation stays rigid through full
! steps of every forward-Euler scheme, for every shape family and dimension.
module test_conservation
  use funit
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_particle_gen, only: empm_fill, GEOM_BOX, GEOM_DISK, PLACE_GAUSS
  use empm_shape_factory, only: empm_shape_create
  use empm_material_factory, only: empm_material_create
  use empm_integrator, only: empm_integrator_t
  use empm_integrator_factory, only: empm_integrator_create
  use empm_transfer, only: p2g_mass, p2g_weighted, g2p_value, nodal_divide_by_mass
  implicit none

  character(len=8), parameter :: FAMILIES(4) = [character(len=8) :: 'linear', 'ugimp', &
                                                'bspline2', 'bspline3']
  character(len=4), parameter :: SCHEMES(3) = [character(len=4) :: 'usf', 'usl', 'musl']

contains

  ! A body of particles well inside a padded grid, with pseudo-random velocities.
  subroutine make_model(ndim, family, model)
    integer, intent(in) :: ndim
    character(len=*), intent(in) :: family
    type(empm_model_t), intent(out) :: model
    integer :: info, nadd, p, d
    real(wp) :: lo(3), hi(3), seed
    call model%grid%init(ndim, [0.0_wp, 0.0_wp, 0.0_wp], [0.5_wp, 0.5_wp, 0.5_wp], [8, 8, 8], info)
    call model%pts%alloc(ndim, 16)
    allocate(model%mats(1))
    call empm_material_create('linear_elastic', 1.0e3_wp, 0.25_wp, 2.0_wp, model%mats(1)%model, info)
    lo = 1.3_wp; hi = 2.7_wp
    call empm_fill(model%pts, model%grid, GEOM_BOX, lo, hi, lo, 0.0_wp, 2, PLACE_GAUSS, 2.0_wp, 1, nadd, info)
    call empm_shape_create(family, ndim, model%shape, info)
    call model%finalize_setup()
    seed = 0.123_wp
    do p = 1, model%pts%np
      do d = 1, ndim
        seed = mod(seed * 997.0_wp + 0.31_wp, 1.0_wp)
        model%pts%v(d, p) = seed - 0.5_wp
      end do
    end do
  end subroutine make_model

  !@test
  subroutine test_p2g_conserves_mass_and_momentum()
    type(empm_model_t) :: model
    integer :: ndim, f, ibad, info
    real(wp) :: pm(3), gm(3)
    do ndim = 1, 3
      do f = 1, size(FAMILIES)
        call make_model(ndim, trim(FAMILIES(f)), model)
        call model%shape%eval_batch(model%grid, model%pts, model%basis, ibad, info)
#line 55 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(0, info, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 55) )
  if (anyExceptions()) return
#line 56 "/work/main/tests/unit/test_conservation.pf"
        call model%nodes%reset()
        call p2g_mass(model%basis, model%pts%m, model%nodes%mass)
        call p2g_weighted(model%basis, model%pts%m, model%pts%v, 0.0_wp, model%pts%v, model%nodes%mom)
#line 59 "/work/main/tests/unit/test_conservation.pf"
  call assertRelativelyEqual(sum(model%pts%m(1:model%pts%np)), sum(model%nodes%mass), tolerance=1.0e-13_wp, &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 59) )
  if (anyExceptions()) return
#line 60 "/work/main/tests/unit/test_conservation.pf"
        pm = 0.0_wp; gm = 0.0_wp
        pm(1:ndim) = matmul(model%pts%v(:, 1:model%pts%np), model%pts%m(1:model%pts%np))
        gm(1:ndim) = sum(model%nodes%mom, dim=2)
#line 63 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(pm, gm, tolerance=1.0e-13_wp * sum(model%pts%m(1:model%pts%np)), &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 63) )
  if (anyExceptions()) return
#line 64 "/work/main/tests/unit/test_conservation.pf"
      end do
    end do
  end subroutine test_p2g_conserves_mass_and_momentum

  !@test
  subroutine test_uniform_velocity_round_trip()
    ! P2G then G2P of a uniform velocity returns it exactly (partition of unity).
    type(empm_model_t) :: model
    integer :: ndim, f, ibad, info, np
    real(wp), allocatable :: vp(:,:)
    do ndim = 1, 3
      do f = 1, size(FAMILIES)
        call make_model(ndim, trim(FAMILIES(f)), model)
        np = model%pts%np
        model%pts%v(:, 1:np) = 0.7_wp
        call model%shape%eval_batch(model%grid, model%pts, model%basis, ibad, info)
        call model%nodes%reset()
        call p2g_mass(model%basis, model%pts%m, model%nodes%mass)
        call p2g_weighted(model%basis, model%pts%m, model%pts%v, 0.0_wp, model%pts%v, model%nodes%mom)
        call nodal_divide_by_mass(model%nodes, model%nodes%mom, model%nodes%vel)
        allocate(vp(ndim, np))
        call g2p_value(model%basis, model%nodes%vel, vp)
#line 86 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(0.7_wp, vp, tolerance=1.0e-14_wp, message=trim(FAMILIES(f)), &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 86) )
  if (anyExceptions()) return
#line 87 "/work/main/tests/unit/test_conservation.pf"
        deallocate(vp)
      end do
    end do
  end subroutine test_uniform_velocity_round_trip

  !@test
  subroutine test_rigid_translation_stays_rigid()
    ! Unstressed body, uniform velocity, no constraints or loads: after 10 steps of every
    ! scheme, positions moved by v t exactly, velocities and stresses unchanged.
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_step_status_t) :: stat
    integer :: ndim, f, s, k, info, np
    real(wp), allocatable :: x0(:,:)
    real(wp), parameter :: dt = 1.0e-3_wp, vel = 0.3_wp
    do ndim = 1, 3
      do f = 1, size(FAMILIES)
        do s = 1, size(SCHEMES)
          call make_model(ndim, trim(FAMILIES(f)), model)
          np = model%pts%np
          model%pts%v(:, 1:np) = vel
          x0 = model%pts%x(:, 1:np)
          call empm_integrator_create(trim(SCHEMES(s)), integ, info)
          call integ%prepare(model)
          do k = 1, 10
            call integ%step(model, dt, stat)
#line 113 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(STEP_OK, stat%code, &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 113) )
  if (anyExceptions()) return
#line 114 "/work/main/tests/unit/test_conservation.pf"
          end do
#line 115 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(x0 + 10 * dt * vel, model%pts%x(:, 1:np), tolerance=1.0e-13_wp, &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 115) )
  if (anyExceptions()) return
#line 116 "/work/main/tests/unit/test_conservation.pf"
#line 116 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(vel, model%pts%v(:, 1:np), tolerance=1.0e-13_wp, &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 116) )
  if (anyExceptions()) return
#line 117 "/work/main/tests/unit/test_conservation.pf"
#line 117 "/work/main/tests/unit/test_conservation.pf"
  call assertEqual(0.0_wp, model%pts%stress(:, 1:np), tolerance=1.0e-9_wp, &
 & location=SourceLocation( &
 & 'test_conservation.pf', &
 & 117) )
  if (anyExceptions()) return
#line 118 "/work/main/tests/unit/test_conservation.pf"
          deallocate(integ)
        end do
      end do
    end do
  end subroutine test_rigid_translation_stays_rigid
end module test_conservation

module Wraptest_conservation
   use FUnit
   use test_conservation
   implicit none
   private

contains


end module Wraptest_conservation

function test_conservation_suite() result(suite)
   use FUnit
   use test_conservation
   use Wraptest_conservation
   implicit none
   type (TestSuite) :: suite

   class (Test), allocatable :: t

   suite = TestSuite('test_conservation_suite')

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_p2g_conserves_mass_and_momentum', &
      test_p2g_conserves_mass_and_momentum))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_uniform_velocity_round_trip', &
      test_uniform_velocity_round_trip))
   call suite%addTest(t)

   if(allocated(t)) deallocate(t)
   allocate(t, source=TestMethod('test_rigid_translation_stays_rigid', &
      test_rigid_translation_stays_rigid))
   call suite%addTest(t)


end function test_conservation_suite

