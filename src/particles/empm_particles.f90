!> Material points stored as a structure of arrays.
!>
!> Every per-particle quantity is a contiguous array whose last index is the particle.
!> Tensors use Voigt order (xx, yy, zz, yz, xz, xy) with tensor (not engineering) shear strains.
!> The materials' state variables are `state(nstate, np)`: nstate rows for every particle (the
!> largest count over the materials; the model sets it), whatever each row means to the
!> particle's material.
module empm_particles
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_alloc_error, empm_raise_error
  use empm_strings, only: str
  use empm_screen, only: empm_screen_finite, empm_screen_finite2
  implicit none
  private
  public :: empm_particles_t

  !> Particle state (structure of arrays).
  type :: empm_particles_t
    integer :: ndim = 0                     !! spatial dimension
    integer :: np = 0                       !! number of particles in use
    real(wp), allocatable :: x(:,:)         !! current position (ndim, np) [m]
    real(wp), allocatable :: x0(:,:)        !! reference (initial) position (ndim, np) [m]
    real(wp), allocatable :: v(:,:)         !! velocity (ndim, np) [m/s]
    real(wp), allocatable :: a(:,:)         !! acceleration (ndim, np) [m/s²]
    real(wp), allocatable :: dx(:,:)        !! position correction still to apply (ndim, np)
                                            !! [m]: the trapezoidal term of the last
                                            !! `pc_newmark` drift, added by the next one
                                            !! (docs/integrators.md); zero for other schemes
    real(wp), allocatable :: m(:)           !! mass (np) [kg]
    real(wp), allocatable :: vol(:)         !! current volume (np) [m³]
    real(wp), allocatable :: vol0(:)        !! initial volume (np) [m³]
    real(wp), allocatable :: rho(:)         !! current density (np) [kg/m³]
    real(wp), allocatable :: stress(:,:)    !! Cauchy stress, Voigt (6, np) [Pa]
    real(wp), allocatable :: strain(:,:)    !! accumulated small strain, Voigt (6, np)
    real(wp), allocatable :: F(:,:,:)       !! deformation gradient (3, 3, np): finite-strain
                                            !! models (small-strain ones leave it = I)
    real(wp), allocatable :: lp(:,:)        !! half-length of the particle domain (ndim, np) [m]
    real(wp), allocatable :: lam(:,:)       !! shape-function state (LME Lagrange multiplier) (ndim, np)
    real(wp), allocatable :: lam_old(:,:)   !! its value one evaluation earlier (LME extrapolation;
                                            !! huge = no history yet)
    real(wp), allocatable :: lam_prev(:,:)  !! `lam` before the last evaluation (ndim, np): with
    real(wp), allocatable :: lam_old_prev(:,:) !! this, what that evaluation started from
                                            !! ([[particles_rewind_shape_state]])
    integer, allocatable :: mat(:)          !! material index (np)
    integer :: nstate = 0                   !! state variables per particle (rows of `state`)
    real(wp), allocatable :: state(:,:)     !! materials' state variables (nstate, np)
  contains
    procedure :: alloc => particles_alloc
    procedure :: set_nstate => particles_set_nstate
    procedure :: append => particles_append
    procedure :: copy_state_from => particles_copy_state
    procedure :: rewind_shape_state => particles_rewind_shape_state
    procedure :: material_fields_fine => particles_material_fields_fine
  end type empm_particles_t

contains

  !> .true. when particles q0..q1 have a finite stress, strain and state and a finite, positive
  !> density and volume: the screen of what a stress update writes, for the run-time guards
  !> (sums of the values, [[empm_screen_finite]]: .false. may also be a false alarm, which the
  !> guards' detailed search then clears).
  pure logical function particles_material_fields_fine(self, q0, q1) result(fine)
    class(empm_particles_t), intent(in) :: self !! particles
    integer, intent(in) :: q0                   !! first particle
    integer, intent(in) :: q1                   !! last particle (< q0: none)
    integer :: n, p
    real(wp) :: low
    fine = .true.
    n = q1 - q0 + 1
    if (n < 1) return
    fine = empm_screen_finite2(6 * n, self%stress(1, q0), self%strain(1, q0))
    if (fine) fine = empm_screen_finite2(n, self%rho(q0), self%vol(q0))
    if (fine .and. self%nstate > 0) fine = empm_screen_finite(self%nstate * n, self%state(1, q0))
    if (.not. fine) return
    ! Only on finite values: a comparison with a NaN would trap in a debug build.
    low = huge(1.0_wp)
    do p = q0, q1
      low = min(low, self%rho(p), self%vol(p))
    end do
    fine = low > 0.0_wp
  end function particles_material_fields_fine

  !> Allocate storage for `capacity` particles and set `np = 0`. On an allocation failure the
  !> set is left empty and unallocated, and the error says how much memory was asked for: in
  !> `err` when present (the program never stops then), otherwise on stderr before stopping.
  subroutine particles_alloc(self, ndim, capacity, nstate, err)
    class(empm_particles_t), intent(inout) :: self          !! particle set
    integer, intent(in) :: ndim                             !! spatial dimension
    integer, intent(in) :: capacity                         !! number of particles to reserve
    integer, intent(in), optional :: nstate                 !! state variables per particle
                                                            !! (default 0)
    type(empm_error_t), intent(inout), optional :: err      !! allocation failure, if present
    integer :: n, ns, st
    integer(int64) :: bytes
    character(len=256) :: msg
    n = max(capacity, 0)
    ns = 0
    if (present(nstate)) ns = max(nstate, 0)
    self%ndim = ndim
    self%np = 0
    self%nstate = ns
    call release(self)
    st = 0; msg = ''
    allocate(self%x(ndim, n), self%x0(ndim, n), self%v(ndim, n), self%a(ndim, n), self%dx(ndim, n), &
      self%m(n), self%vol(n), self%vol0(n), self%rho(n), self%stress(6, n), self%strain(6, n), &
      self%F(3, 3, n), self%lp(ndim, n), self%lam(ndim, n), &
      self%lam_old(ndim, n), self%lam_prev(ndim, n), self%lam_old_prev(ndim, n), self%mat(n), &
      self%state(ns, n), stat=st, errmsg=msg)
    if (st /= 0) then
      call release(self)
      ! 10 vectors, 4 scalars, 2 Voigt tensors, F and the state in reals; the material index.
      bytes = int(n, int64) * (8_int64 * (10 * ndim + 4 + 12 + 9 + int(ns, int64)) + 4_int64)
      call empm_raise_error(empm_alloc_error('particle storage ('//str(n)//' particles)', &
        bytes, trim(msg)), err)
      return
    end if
    self%dx = 0.0_wp ! particles filled in place (not appended) have no pending correction
  end subroutine particles_alloc

  !> Give every particle `nstate` state variables, all zero (set-up; the model calls it with
  !> the largest count over its materials, then lets each material set its particles' values).
  !> Allocation failures are reported as in [[particles_alloc]].
  subroutine particles_set_nstate(self, nstate, err)
    class(empm_particles_t), intent(inout) :: self          !! particle set (allocated)
    integer, intent(in) :: nstate                           !! state variables per particle
    type(empm_error_t), intent(inout), optional :: err      !! allocation failure, if present
    integer :: n, st
    character(len=256) :: msg
    n = 0
    if (allocated(self%m)) n = size(self%m)
    self%nstate = max(nstate, 0)
    if (allocated(self%state)) deallocate(self%state)
    st = 0; msg = ''
    allocate(self%state(self%nstate, n), stat=st, errmsg=msg)
    if (st /= 0) then
      call empm_raise_error(empm_alloc_error('particle state variables ('//str(self%nstate)// &
        ' x '//str(n)//')', 8_int64 * self%nstate * n, trim(msg)), err)
      return
    end if
    self%state = 0.0_wp
  end subroutine particles_set_nstate

  !> Deallocate whatever is allocated (a failed allocate may leave some arrays allocated).
  subroutine release(self)
    class(empm_particles_t), intent(inout) :: self
    if (allocated(self%x)) deallocate(self%x)
    if (allocated(self%x0)) deallocate(self%x0)
    if (allocated(self%v)) deallocate(self%v)
    if (allocated(self%a)) deallocate(self%a)
    if (allocated(self%dx)) deallocate(self%dx)
    if (allocated(self%m)) deallocate(self%m)
    if (allocated(self%vol)) deallocate(self%vol)
    if (allocated(self%vol0)) deallocate(self%vol0)
    if (allocated(self%rho)) deallocate(self%rho)
    if (allocated(self%stress)) deallocate(self%stress)
    if (allocated(self%strain)) deallocate(self%strain)
    if (allocated(self%F)) deallocate(self%F)
    if (allocated(self%lp)) deallocate(self%lp)
    if (allocated(self%lam)) deallocate(self%lam)
    if (allocated(self%lam_old)) deallocate(self%lam_old)
    if (allocated(self%lam_prev)) deallocate(self%lam_prev)
    if (allocated(self%lam_old_prev)) deallocate(self%lam_old_prev)
    if (allocated(self%mat)) deallocate(self%mat)
    if (allocated(self%state)) deallocate(self%state)
  end subroutine release

  !> Append one particle at rest, unstressed, with identity deformation gradient and zero
  !> state variables. Grows the storage geometrically when full (set-up only, never in the time
  !> loop). On an allocation failure nothing is appended and the error is reported as in
  !> [[particles_alloc]].
  subroutine particles_append(self, x, vol, rho, lp, mat, err)
    class(empm_particles_t), intent(inout) :: self     !! particle set
    real(wp), intent(in) :: x(:)                       !! position (ndim)
    real(wp), intent(in) :: vol                        !! volume [m³]
    real(wp), intent(in) :: rho                        !! density [kg/m³]
    real(wp), intent(in) :: lp(:)                      !! half-lengths of the particle domain (ndim)
    integer, intent(in) :: mat                         !! material index
    type(empm_error_t), intent(inout), optional :: err !! allocation failure, if present
    type(empm_particles_t) :: tmp
    type(empm_error_t) :: e
    integer :: n, d
    if (.not. allocated(self%x)) then
      call self%alloc(size(x), 64, err=e)
      if (e%code /= 0) then
        call empm_raise_error(e, err); return
      end if
    end if
    if (self%np == size(self%m)) then
      call tmp%alloc(self%ndim, 2 * size(self%m), self%nstate, e)
      if (e%code /= 0) then
        call empm_raise_error(e, err); return
      end if
      call tmp%copy_state_from(self)
      call move_alloc_all(tmp, self)
    end if
    n = self%np + 1
    self%np = n
    d = self%ndim
    self%x(:, n) = x(1:d); self%x0(:, n) = x(1:d)
    self%v(:, n) = 0.0_wp; self%a(:, n) = 0.0_wp; self%dx(:, n) = 0.0_wp
    self%vol(n) = vol; self%vol0(n) = vol; self%rho(n) = rho; self%m(n) = rho * vol
    self%stress(:, n) = 0.0_wp; self%strain(:, n) = 0.0_wp
    self%F(:, :, n) = 0.0_wp; self%F(1, 1, n) = 1.0_wp; self%F(2, 2, n) = 1.0_wp
    self%F(3, 3, n) = 1.0_wp
    ! lam_old = huge: no history yet (see the LME warm-start extrapolation).
    self%lp(:, n) = lp(1:d); self%lam(:, n) = 0.0_wp; self%lam_old(:, n) = huge(1.0_wp)
    self%lam_prev(:, n) = 0.0_wp; self%lam_old_prev(:, n) = huge(1.0_wp)
    self%mat(n) = mat
    self%state(:, n) = 0.0_wp
  end subroutine particles_append

  !> Copy the first `src%np` particles of `src` into `self` (which must be large enough), state
  !> variables included. The destination takes the source's number of state variables: its
  !> state array is reallocated when that differs, so a copy allocated with [[particles_alloc]]
  !> alone (no `nstate`) works; the next copies then allocate nothing.
  subroutine particles_copy_state(self, src)
    class(empm_particles_t), intent(inout) :: self !! destination (allocated, capacity >= src%np)
    class(empm_particles_t), intent(in) :: src     !! source
    integer :: n
    n = src%np
    self%np = n
    if (size(self%state, 1) /= src%nstate) call self%set_nstate(src%nstate)
    if (src%nstate > 0) self%state(:, 1:n) = src%state(:, 1:n)
    self%x(:, 1:n) = src%x(:, 1:n); self%x0(:, 1:n) = src%x0(:, 1:n)
    self%v(:, 1:n) = src%v(:, 1:n); self%a(:, 1:n) = src%a(:, 1:n)
    self%dx(:, 1:n) = src%dx(:, 1:n)
    self%m(1:n) = src%m(1:n); self%vol(1:n) = src%vol(1:n); self%vol0(1:n) = src%vol0(1:n)
    self%rho(1:n) = src%rho(1:n)
    self%stress(:, 1:n) = src%stress(:, 1:n); self%strain(:, 1:n) = src%strain(:, 1:n)
    self%F(:, :, 1:n) = src%F(:, :, 1:n)
    self%lp(:, 1:n) = src%lp(:, 1:n); self%lam(:, 1:n) = src%lam(:, 1:n)
    self%lam_old(:, 1:n) = src%lam_old(:, 1:n)
    self%lam_prev(:, 1:n) = src%lam_prev(:, 1:n)
    self%lam_old_prev(:, 1:n) = src%lam_old_prev(:, 1:n)
    self%mat(1:n) = src%mat(1:n)
  end subroutine particles_copy_state

  !> Put the shape state (the LME multipliers) back to what the last basis evaluation started
  !> from, so that evaluating again at the same positions repeats it bit for bit.
  subroutine particles_rewind_shape_state(self)
    class(empm_particles_t), intent(inout) :: self !! particles
    integer :: n
    n = self%np
    self%lam(:, 1:n) = self%lam_prev(:, 1:n)
    self%lam_old(:, 1:n) = self%lam_old_prev(:, 1:n)
  end subroutine particles_rewind_shape_state

  subroutine move_alloc_all(from, to)
    type(empm_particles_t), intent(inout) :: from
    class(empm_particles_t), intent(inout) :: to
    to%np = from%np
    call move_alloc(from%x, to%x); call move_alloc(from%x0, to%x0)
    call move_alloc(from%v, to%v); call move_alloc(from%a, to%a)
    call move_alloc(from%dx, to%dx)
    call move_alloc(from%m, to%m); call move_alloc(from%vol, to%vol)
    call move_alloc(from%vol0, to%vol0); call move_alloc(from%rho, to%rho)
    call move_alloc(from%stress, to%stress); call move_alloc(from%strain, to%strain)
    call move_alloc(from%F, to%F)
    call move_alloc(from%lp, to%lp); call move_alloc(from%lam, to%lam)
    call move_alloc(from%lam_old, to%lam_old)
    call move_alloc(from%lam_prev, to%lam_prev)
    call move_alloc(from%lam_old_prev, to%lam_old_prev)
    call move_alloc(from%mat, to%mat)
    to%nstate = from%nstate
    call move_alloc(from%state, to%state)
  end subroutine move_alloc_all
end module empm_particles
