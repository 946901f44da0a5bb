!> LME benchmark: evaluations per second and mean Newton iterations per evaluation, from a cold
!> start (λ = 0) and warm-started in a smooth flow, for 2D γ = 0.8 and 3 and 3D γ = 3; then the
!> mean iterations per evaluation in two real runs of the solver (Dyka bar, Andersen block).
!>
!> Synthetic flow: particles fill the interior of a regular grid (16 per cell in 2D, 8 in 3D, at
!> jittered positions). Cold: every evaluation starts from λ = 0. Warm: between evaluations the
!> particles move by a smooth divergence-free displacement (a cellular flow) of at most δ per
!> evaluation, δ = 1e-2 h, 1e-3 h and 1e-4 h, and each evaluation starts from the particle's
!> previous λ, as in the solver (an explicit MPM step moves a particle by CFL·(v/c)·h, e.g.
!> 5e-4 h in the Dyka bar). The rate is for δ = 1e-3 h. Evaluation allocates nothing.
!>
!> Solver runs: the Dyka bar (1D, to T = 2e-4 s) and the Andersen block (2D, 2 s of the 20 s
!> ramp) with MUSL and LME γ = 0.8 and 3, as in tests/unit/test_lme_solver.pf; after every
!> step the next step's basis evaluation is repeated on a copy of the particles and its Newton
!> iterations counted.
!>
!> One line per configuration on stdout. Usage: `lme_bench [scale]`, scale (default 1)
!> multiplies the number of repetitions. Use a Release build.
program lme_bench
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use empm_kinds, only: wp, pi
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_shape, only: empm_basis_t, SHAPE_OK
  use empm_shape_lme, only: empm_shape_lme_t, lme_format_gamma
  use empm_model, only: empm_model_t, empm_step_status_t, STEP_OK
  use empm_particle_gen, only: empm_fill, GEOM_BOX, PLACE_GAUSS
  use empm_integrator, only: empm_integrator_t
  use empm_registry, only: empm_create_shape, empm_create_material, empm_create_integrator
  use empm_namelist, only: empm_kv
  use empm_error, only: empm_error_t
  use empm_solver, only: empm_stable_dt
  use empm_loads, only: RAMP_SINE
  implicit none
  integer :: scale, ios
  character(len=32) :: arg

  scale = 1
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read(arg, *, iostat=ios) scale
    if (ios /= 0 .or. scale < 1) scale = 1
  end if
  call synthetic(2, 0.8_wp, 48, 4, 4 * scale, 20 * scale)
  call synthetic(2, 3.0_wp, 48, 4, 4 * scale, 20 * scale)
  call synthetic(3, 3.0_wp, 16, 2, 4 * scale, 20 * scale)
  call solver_run('dyka', 0.8_wp)
  call solver_run('dyka', 3.0_wp)
  call solver_run('andersen', 0.8_wp)
  call solver_run('andersen', 3.0_wp)

contains

  !> One synthetic configuration: `ncell` cells per direction, `ppc` particles per cell and
  !> direction in the interior (a margin of R from the faces), `ncold` cold batches and
  !> `nwarm` warm batches per displacement amplitude.
  subroutine synthetic(nd, gamma, ncell, ppc, ncold, nwarm)
    integer, intent(in) :: nd, ncell, ppc, ncold, nwarm
    real(wp), intent(in) :: gamma
    real(wp), parameter :: AMPS(3) = [1.0e-2_wp, 1.0e-3_wp, 1.0e-4_wp]
    type(empm_grid_t) :: grid
    type(empm_shape_lme_t) :: shp
    type(empm_particles_t) :: pts
    type(empm_basis_t) :: basis
    real(wp) :: x(3), u(3), lo, span, t_cold, t_warm, it_cold, it_warm(3), nodes_pt
    integer :: info, k, d, ibad, iters, npc, cells(3), c(3), ia
    integer(int64) :: c0, c1, rate
    call grid%init(nd, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], &
                   [ncell, ncell, ncell], info)
    shp%gamma = gamma
    shp%ndim = nd
    lo = real(ceiling(shp%support_radius(grid)) + 1, wp)
    span = ncell - 2.0_wp * lo
    npc = nint(span) * ppc
    cells = 1
    cells(1:nd) = npc
    call pts%alloc(nd, product(cells))
    call random_seed_fixed()
    do k = 0, product(cells) - 1
      c = [mod(k, cells(1)), mod(k / cells(1), cells(2)), k / (cells(1) * cells(2))]
      call random_number(u)
      x = 0.0_wp
      do d = 1, nd
        x(d) = lo + (c(d) + 0.1_wp + 0.8_wp * u(d)) * span / npc
      end do
      call pts%append(x(1:nd), 1.0_wp, 1.0_wp, [(0.0_wp, d = 1, nd)], 1)
    end do
    call basis%alloc(nd, shp%max_nodes(grid), pts%np)

    ! Cold starts.
    it_cold = 0.0_wp
    call system_clock(c0, rate)
    do k = 1, ncold
      pts%lam(:, 1:pts%np) = 0.0_wp
      call shp%eval_batch_iters(grid, pts, basis, ibad, info, iters)
      call check(info, ibad)
      it_cold = it_cold + iters
    end do
    call system_clock(c1)
    t_cold = real(c1 - c0, wp) / real(rate, wp)
    nodes_pt = real(sum(basis%nn(1:pts%np)), wp) / pts%np

    ! Warm starts in the flow, for each amplitude (timed for the second).
    t_warm = 1.0_wp
    do ia = 1, size(AMPS)
      it_warm(ia) = 0.0_wp
      call system_clock(c0)
      do k = 1, nwarm
        call move(nd, pts, AMPS(ia))
        call shp%eval_batch_iters(grid, pts, basis, ibad, info, iters)
        call check(info, ibad)
        it_warm(ia) = it_warm(ia) + iters
      end do
      call system_clock(c1)
      if (ia == 2) t_warm = real(c1 - c0, wp) / real(rate, wp)
      it_warm(ia) = it_warm(ia) / (nwarm * real(pts%np, wp))
    end do

    write(output_unit, '(a,i0,a,a,a,i0,a,f5.1,a,es9.3,a,f4.2,a,es9.3,a,3(1x,f4.2),a)') &
      'lme_bench ', nd, 'D gamma=', lme_format_gamma(gamma), ' np=', pts%np, ' nodes/pt=', &
      nodes_pt, ': cold ', ncold * real(pts%np, wp) / t_cold, ' evals/s ', &
      it_cold / (ncold * pts%np), ' it/eval; warm ', nwarm * real(pts%np, wp) / t_warm, &
      ' evals/s, it/eval at delta = 1e-2h 1e-3h 1e-4h:', it_warm, ''
  end subroutine synthetic

  !> Cellular flow: x += δ (sin πX cos πY, −cos πX sin πY) (and the same in (y, z) in 3D),
  !> X, Y the position in units of 8 cells; |Δx| ≤ δ.
  subroutine move(nd, pts, delta)
    integer, intent(in) :: nd
    type(empm_particles_t), intent(inout) :: pts
    real(wp), intent(in) :: delta
    real(wp) :: x(3), u(3)
    integer :: p
    do p = 1, pts%np
      x = 0.0_wp
      x(1:nd) = pts%x(:, p) * pi / 8.0_wp
      u = 0.0_wp
      u(1) = sin(x(1)) * cos(x(2))
      u(2) = -cos(x(1)) * sin(x(2))
      if (nd == 3) then
        u(2) = u(2) + sin(x(2)) * cos(x(3))
        u(3) = -cos(x(2)) * sin(x(3))
      end if
      pts%x(:, p) = pts%x(:, p) + delta * u(1:nd) / sqrt(real(nd, wp))
    end do
  end subroutine move

  !> Run the Dyka bar or the Andersen block with LME γ and MUSL; count the Newton iterations
  !> of each step's basis evaluation (repeated on a copy of the particles after the step).
  subroutine solver_run(case_name, gamma)
    character(len=*), intent(in) :: case_name
    real(wp), intent(in) :: gamma
    type(empm_model_t) :: model
    class(empm_integrator_t), allocatable :: integ
    type(empm_particles_t) :: tmp
    type(empm_basis_t) :: tbasis
    type(empm_step_status_t) :: stat
    real(wp) :: t_end, cfl, dt, its
    type(empm_error_t) :: err
    integer :: info, ibad, iters, nevals
    if (case_name == 'dyka') then
      call make_dyka(model, gamma)
      t_end = 2.0e-4_wp; cfl = 0.5_wp
    else
      call make_andersen(model, gamma)
      t_end = 2.0_wp; cfl = 0.1_wp
    end if
    call model%finalize_setup()
    call empm_create_integrator('musl', integ, err)
    call check_created(err, 'integrator')
    call integ%prepare(model)
    call tmp%alloc(model%grid%ndim, model%pts%np)
    call tbasis%alloc(model%grid%ndim, model%basis%maxn, model%pts%np)
    its = 0.0_wp; nevals = 0
    do while (model%t < t_end * (1.0_wp - 1.0e-12_wp))
      dt = min(cfl * empm_stable_dt(model), t_end - model%t)
      call integ%step(model, dt, stat)
      if (stat%code /= STEP_OK) then
        write(output_unit, '(a)') 'lme_bench: '//case_name//' step failed'
        error stop 1
      end if
      model%t = model%t + dt
      model%step = model%step + 1
      call tmp%copy_state_from(model%pts)
      select type (s => model%shape)
      type is (empm_shape_lme_t)
        call s%eval_batch_iters(model%grid, tmp, tbasis, ibad, info, iters)
      end select
      call check(info, ibad)
      its = its + iters
      nevals = nevals + model%pts%np
    end do
    write(output_unit, '(a,a,a,a,a,i0,a,i0,a,f5.3,a)') 'lme_bench solver ', case_name, &
      ' gamma=', lme_format_gamma(gamma), ' np=', model%pts%np, ' steps=', model%step, &
      ': warm ', its / nevals, ' it/eval'
  end subroutine solver_run

  !> Dyka bar (docs/benchmarks.md): 40 cells, 1 particle per cell, x = 0 fixed, v0 = 5 m/s
  !> on the last quarter.
  subroutine make_dyka(model, gamma)
    type(empm_model_t), intent(out) :: model
    real(wp), intent(in) :: gamma
    real(wp), parameter :: L = 0.1333_wp
    real(wp) :: zero3(3)
    type(empm_error_t) :: err
    integer :: info, nadd, nsel, np
    zero3 = 0.0_wp
    call model%grid%init(1, [0.0_wp], [3.3325e-3_wp], [46], info)
    call model%pts%alloc(1, 40)
    allocate(model%mats(1))
    call empm_create_material('linear_elastic', empm_kv('E', 200.0e9_wp)// &
                              empm_kv('nu', 0.0_wp)//empm_kv('density', 7833.0_wp), &
                              model%mats(1)%model, err)
    call check_created(err, 'Dyka bar material')
    call empm_fill(model%pts, model%grid, GEOM_BOX, zero3, [L, 0.0_wp, 0.0_wp], zero3, &
                   0.0_wp, 1, PLACE_GAUSS, 7833.0_wp, 1, nadd, info)
    np = model%pts%np
    where (model%pts%x(1, 1:np) > 0.75_wp * L) model%pts%v(1, 1:np) = 5.0_wp
    call model%nodes%fix_box(model%grid, zero3, zero3, [.true., .false., .false.], zero3, nsel)
    call empm_create_shape('lme', model%grid, model%shape, err, empm_kv('gamma', gamma))
    call check_created(err, 'Dyka bar shape')
  end subroutine make_dyka

  !> Andersen block (docs/benchmarks.md): 10 m × 10 m, h = 2 m, 2×2 Gauss particles per
  !> cell, bottom fixed, side rollers, gravity ramped over 20 s.
  subroutine make_andersen(model, gamma)
    type(empm_model_t), intent(out) :: model
    real(wp), intent(in) :: gamma
    real(wp) :: zero3(3)
    type(empm_error_t) :: err
    integer :: info, nadd, nsel
    zero3 = 0.0_wp
    call model%grid%init(2, [0.0_wp, 0.0_wp], [2.0_wp, 2.0_wp], [5, 7], info)
    call model%pts%alloc(2, 100)
    allocate(model%mats(1))
    call empm_create_material('linear_elastic', empm_kv('E', 5.0e6_wp)// &
                              empm_kv('nu', 0.0_wp)//empm_kv('density', 6000.0_wp), &
                              model%mats(1)%model, err)
    call check_created(err, 'Andersen block material')
    call empm_fill(model%pts, model%grid, GEOM_BOX, zero3, [10.0_wp, 10.0_wp, 0.0_wp], zero3, &
                   0.0_wp, 2, PLACE_GAUSS, 6000.0_wp, 1, nadd, info)
    call model%nodes%fix_box(model%grid, zero3, [10.0_wp, 0.0_wp, 0.0_wp], &
                             [.true., .true., .false.], zero3, nsel)
    call model%nodes%fix_box(model%grid, zero3, [0.0_wp, 14.0_wp, 0.0_wp], &
                             [.true., .false., .false.], zero3, nsel)
    call model%nodes%fix_box(model%grid, [10.0_wp, 0.0_wp, 0.0_wp], [10.0_wp, 14.0_wp, 0.0_wp], &
                             [.true., .false., .false.], zero3, nsel)
    model%loads%gravity = [0.0_wp, -9.81_wp, 0.0_wp]
    model%loads%ramp = RAMP_SINE
    model%loads%t_ramp = 20.0_wp
    call empm_create_shape('lme', model%grid, model%shape, err, empm_kv('gamma', gamma))
    call check_created(err, 'Andersen block shape')
  end subroutine make_andersen

  !> Stop when the registry could not create a family (the benchmark cannot run).
  subroutine check_created(err, what)
    type(empm_error_t), intent(in) :: err !! status of the creation
    character(len=*), intent(in) :: what  !! what was created, for the message
    if (err%code /= 0) then
      write(output_unit, '(a)') 'lme_bench: '//what//': '//err%message
      error stop 1
    end if
  end subroutine check_created

  !> Stop on a failed evaluation (the benchmark is meaningless then).
  subroutine check(info, ibad)
    integer, intent(in) :: info, ibad
    if (info /= SHAPE_OK) then
      write(output_unit, '(a,i0,a,i0)') 'lme_bench: evaluation failed at particle ', ibad, &
        ' with status ', info
      error stop 1
    end if
  end subroutine check

  !> Reproducible pseudo-random positions.
  subroutine random_seed_fixed()
    integer :: n
    integer, allocatable :: seed(:)
    call random_seed(size=n)
    allocate(seed(n))
    seed = 12345
    call random_seed(put=seed)
  end subroutine random_seed_fixed
end program lme_bench
