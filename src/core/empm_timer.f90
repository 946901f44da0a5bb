!> Phase timers of the time step: wall time accumulated per phase (shape functions, P2G,
!> grid update, G2P, stress update) and the Newton iterations of iterative bases.
!>
!> One `system_clock` read per phase boundary (`lap`): the time since the previous mark is
!> charged to the phase that just ended. Timers never touch the numerics.
module empm_timer
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  implicit none
  private
  public :: empm_phase_timer_t, PHASE_SHAPE, PHASE_P2G, PHASE_GRID, PHASE_G2P, PHASE_STRESS, &
            PHASE_COUNT, PHASE_NAMES

  integer, parameter :: PHASE_SHAPE = 1   !! shape-function evaluation
  integer, parameter :: PHASE_P2G = 2     !! particle-to-grid transfers (mass, momentum, forces)
  integer, parameter :: PHASE_GRID = 3    !! nodal updates (division by mass, constraints)
  integer, parameter :: PHASE_G2P = 4     !! grid-to-particle transfers and particle updates
  integer, parameter :: PHASE_STRESS = 5  !! velocity gradient and constitutive update
  integer, parameter :: PHASE_COUNT = 5   !! number of phases
  !> Phase names, as in the benchmark's JSON.
  character(len=6), parameter :: PHASE_NAMES(PHASE_COUNT) = &
    [character(len=6) :: 'shape', 'p2g', 'grid', 'g2p', 'stress']

  !> Accumulated wall time per phase and iteration counts.
  type :: empm_phase_timer_t
    real(wp) :: seconds(PHASE_COUNT) = 0.0_wp  !! wall time per phase [s]
    integer(int64) :: newton_iters = 0         !! Newton iterations summed over evaluations
    integer(int64) :: basis_evals = 0          !! particle basis evaluations counted with them
    integer(int64) :: last = 0                 !! clock count at the last mark
    integer(int64) :: rate = 1                 !! clock counts per second
  contains
    procedure :: reset => timer_reset
    procedure :: mark => timer_mark
    procedure :: lap => timer_lap
  end type empm_phase_timer_t

contains

  !> Zero every accumulator.
  subroutine timer_reset(self)
    class(empm_phase_timer_t), intent(inout) :: self !! timers
    self%seconds = 0.0_wp
    self%newton_iters = 0
    self%basis_evals = 0
    call self%mark()
  end subroutine timer_reset

  !> Start timing from now (e.g. at the beginning of a step).
  subroutine timer_mark(self)
    class(empm_phase_timer_t), intent(inout) :: self !! timers
    call system_clock(self%last, self%rate)
  end subroutine timer_mark

  !> Charge the time since the last mark to `phase` and mark again.
  subroutine timer_lap(self, phase)
    class(empm_phase_timer_t), intent(inout) :: self !! timers
    integer, intent(in) :: phase                     !! PHASE_* index
    integer(int64) :: c
    call system_clock(c)
    self%seconds(phase) = self%seconds(phase) + real(c - self%last, wp) / real(self%rate, wp)
    self%last = c
  end subroutine timer_lap
end module empm_timer
