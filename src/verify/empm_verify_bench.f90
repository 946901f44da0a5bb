!> Benchmarks of the verification suite: the exact or manufactured solution behind each
!> benchmark id, the initial state and body force it needs, and the metrics computed from a
!> run against it. Definitions: ../shared/docs/algorithms.md §3 and docs/verification.md.
module empm_verify_bench
  use empm_kinds, only: wp
  use empm_case, only: empm_case_t
  use empm_history, only: empm_history_t
  use empm_verify_metrics, only: rms_error, weighted_l2, history_l2, noise_share
  use empm_exact_bar, only: empm_vibrating_bar_t
  implicit none
  private
  public :: bench_prepare, bench_metric, bench_known

  character(len=*), parameter :: KNOWN = 'vibrating_bar'

contains

  !> True when `benchmark` is implemented.
  pure logical function bench_known(benchmark)
    character(len=*), intent(in) :: benchmark !! benchmark id
    bench_known = index(' '//KNOWN//' ', ' '//trim(benchmark)//' ') > 0
  end function bench_known

  !> Impose what the benchmark needs beyond the case file (initial fields from the exact
  !> solution, body forces). `emsg` is '' on success.
  subroutine bench_prepare(benchmark, cs, emsg)
    character(len=*), intent(in) :: benchmark          !! benchmark id
    type(empm_case_t), intent(inout) :: cs             !! case read from its file
    character(len=:), allocatable, intent(out) :: emsg !! '' or the problem
    integer :: p
    emsg = ''
    associate (pts => cs%model%pts)
      select case (trim(benchmark))
      case ('vibrating_bar')
        ! The case file gives the sine velocity already; check it matches the exact mode.
        block
          type(empm_vibrating_bar_t) :: bar
          do p = 1, pts%np
            if (abs(pts%v(1, p) - bar%velocity(pts%x0(1, p), 0.0_wp)) > 1.0e-12_wp * bar%v0) then
              emsg = cs%file//': the initial velocity does not match the exact vibrating-bar mode'
              return
            end if
          end do
        end block
      case default
        emsg = 'unknown benchmark '''//trim(benchmark)//'''; known: '//KNOWN
      end select
    end associate
  end subroutine bench_prepare

  !> Compute metric `name` of a finished run. `emsg` is '' on success.
  subroutine bench_metric(benchmark, name, cs, hist, value, emsg)
    character(len=*), intent(in) :: benchmark          !! benchmark id
    character(len=*), intent(in) :: name               !! metric name
    type(empm_case_t), intent(in) :: cs                !! the run (final state)
    type(empm_history_t), intent(in) :: hist           !! its histories
    real(wp), intent(out) :: value                     !! metric value
    character(len=:), allocatable, intent(out) :: emsg !! '' or the problem
    real(wp), allocatable :: vex(:,:)
    integer :: np, d
    emsg = ''; value = huge(1.0_wp)
    np = cs%model%pts%np; d = cs%model%grid%ndim
    allocate(vex(d, np))
    call exact_velocity(benchmark, cs%model%pts%x0(:, 1:np), cs%model%t, vex, emsg)
    if (len(emsg) > 0) return
    select case (trim(name))
    case ('rms_velocity')
      value = rms_error(cs%model%pts%v(1, 1:np), vex(1, :))
    case ('velocity_l2')
      value = weighted_l2(cs%model%pts%vol0(1:np), cs%model%pts%v(:, 1:np), vex)
    case ('relative_velocity_l2')
      value = weighted_l2(cs%model%pts%vol0(1:np), cs%model%pts%v(:, 1:np), vex) / &
              velocity_scale(benchmark)
    case default
      emsg = 'unknown metric '''//trim(name)//''' for benchmark '''//trim(benchmark)//''''
    end select
    if (hist%nt < 0) emsg = 'corrupt history'
  end subroutine bench_metric

  !> Velocity scale used to make errors relative (the benchmark's amplitude).
  pure real(wp) function velocity_scale(benchmark) result(s)
    character(len=*), intent(in) :: benchmark
    type(empm_vibrating_bar_t) :: bar
    select case (trim(benchmark))
    case ('vibrating_bar'); s = bar%v0
    case default; s = 1.0_wp
    end select
  end function velocity_scale

  !> Exact velocity at reference positions `x0` and time `t`.
  subroutine exact_velocity(benchmark, x0, t, v, emsg)
    character(len=*), intent(in) :: benchmark
    real(wp), intent(in) :: x0(:,:), t
    real(wp), intent(out) :: v(:,:)
    character(len=:), allocatable, intent(out) :: emsg
    emsg = ''
    select case (trim(benchmark))
    case ('vibrating_bar')
      block
        type(empm_vibrating_bar_t) :: bar
        v(1, :) = bar%velocity(x0(1, :), t)
      end block
    case default
      emsg = 'no exact velocity for benchmark '''//trim(benchmark)//''''
    end select
  end subroutine exact_velocity
end module empm_verify_bench
