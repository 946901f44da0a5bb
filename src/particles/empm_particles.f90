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
  public :: empm_particles_t, PARTICLE_FIELDS

  !> Number of arrays a particle set stores per particle ([[particles_take_field]]); the id
  !> is field 1.
  integer, parameter :: PARTICLE_FIELDS = 21

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
    real(wp), allocatable :: vol_fill(:)    !! the volumes the last basis evaluation filled
                                            !! the nodes with (np) [m³]: a scheme that carries
                                            !! its basis into the next step finds its
                                            !! nearly-empty nodes from them, and so must an
                                            !! evaluation that repeats it (a restart)
    integer, allocatable :: mat(:)          !! material index (np)
    integer, allocatable :: id(:)           !! the particle's number in generation order (np):
                                            !! its place in the output whichever process
                                            !! holds it (docs/parallel.md)
    integer :: nstate = 0                   !! state variables per particle (rows of `state`)
    real(wp), allocatable :: state(:,:)     !! materials' state variables (nstate, np)
  contains
    procedure :: alloc => particles_alloc
    procedure :: set_nstate => particles_set_nstate
    procedure :: append => particles_append
    procedure :: copy_state_from => particles_copy_state
    procedure :: rewind_shape_state => particles_rewind_shape_state
    procedure :: material_fields_fine => particles_material_fields_fine
    procedure :: row_size => particles_row_size
    procedure :: id_row => particles_id_row
    procedure :: pack_rows => particles_pack_rows
    procedure :: set_from_rows => particles_set_from_rows
    procedure :: keep => particles_keep
    procedure :: take_field => particles_take_field
    procedure :: put_field => particles_put_field
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
      self%id(n), self%vol_fill(n), self%state(ns, n), stat=st, errmsg=msg)
    if (st /= 0) then
      call release(self)
      ! 10 vectors, 4 scalars, 2 Voigt tensors, F and the state in reals; the material index.
      bytes = int(n, int64) * (8_int64 * (10 * ndim + 5 + 12 + 9 + int(ns, int64)) + 8_int64)
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
    if (allocated(self%id)) deallocate(self%id)
    if (allocated(self%vol_fill)) deallocate(self%vol_fill)
    if (allocated(self%state)) deallocate(self%state)
  end subroutine release

  !> Append one particle at rest, unstressed, with identity deformation gradient and zero
  !> state variables. Grows the storage geometrically when full (set-up only, never in the time
  !> loop). On an allocation failure nothing is appended and the error is reported as in
  !> [[particles_alloc]].
  subroutine particles_append(self, x, vol, rho, lp, mat, err, id)
    class(empm_particles_t), intent(inout) :: self     !! particle set
    real(wp), intent(in) :: x(:)                       !! position (ndim)
    real(wp), intent(in) :: vol                        !! volume [m³]
    real(wp), intent(in) :: rho                        !! density [kg/m³]
    real(wp), intent(in) :: lp(:)                      !! half-lengths of the particle domain (ndim)
    integer, intent(in) :: mat                         !! material index
    type(empm_error_t), intent(inout), optional :: err !! allocation failure, if present
    integer, intent(in), optional :: id                !! its number in generation order
                                                       !! (default: its index in the set)
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
    self%vol_fill(n) = vol
    self%stress(:, n) = 0.0_wp; self%strain(:, n) = 0.0_wp
    self%F(:, :, n) = 0.0_wp; self%F(1, 1, n) = 1.0_wp; self%F(2, 2, n) = 1.0_wp
    self%F(3, 3, n) = 1.0_wp
    ! lam_old = huge: no history yet (see the LME warm-start extrapolation).
    self%lp(:, n) = lp(1:d); self%lam(:, n) = 0.0_wp; self%lam_old(:, n) = huge(1.0_wp)
    self%lam_prev(:, n) = 0.0_wp; self%lam_old_prev(:, n) = huge(1.0_wp)
    self%mat(n) = mat
    self%id(n) = n
    if (present(id)) self%id(n) = id
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
    self%id(1:n) = src%id(1:n)
    self%vol_fill(1:n) = src%vol_fill(1:n)
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

  !> Number of reals that hold one particle in a row ([[particles_pack_rows]]).
  pure integer function particles_row_size(self) result(m)
    class(empm_particles_t), intent(in) :: self !! particles
    m = 10 * self%ndim + 4 + 12 + 9 + 3 + self%nstate
  end function particles_row_size

  !> The row of [[particles_pack_rows]] that holds a particle's id.
  pure integer function particles_id_row(self) result(r)
    class(empm_particles_t), intent(in) :: self !! particles
    r = 10 * self%ndim + 27
  end function particles_id_row

  !> rows(:, k) = every field of particle idx(k), as reals (the material index and the id are
  !> exact in a real): what moves a particle between processes or gathers them for output.
  pure subroutine particles_pack_rows(self, idx, rows)
    class(empm_particles_t), intent(in) :: self    !! particles
    integer, intent(in) :: idx(:)                  !! particles to pack
    real(wp), intent(out) :: rows(:,:)             !! (row_size, >= size(idx))
    integer :: k, p, d, o
    d = self%ndim
    do k = 1, size(idx)
      p = idx(k)
      rows(1:d, k) = self%x(:, p); rows(d + 1:2 * d, k) = self%x0(:, p)
      rows(2 * d + 1:3 * d, k) = self%v(:, p); rows(3 * d + 1:4 * d, k) = self%a(:, p)
      rows(4 * d + 1:5 * d, k) = self%dx(:, p); rows(5 * d + 1:6 * d, k) = self%lp(:, p)
      rows(6 * d + 1:7 * d, k) = self%lam(:, p); rows(7 * d + 1:8 * d, k) = self%lam_old(:, p)
      rows(8 * d + 1:9 * d, k) = self%lam_prev(:, p)
      rows(9 * d + 1:10 * d, k) = self%lam_old_prev(:, p)
      o = 10 * d
      rows(o + 1, k) = self%m(p); rows(o + 2, k) = self%vol(p)
      rows(o + 3, k) = self%vol0(p); rows(o + 4, k) = self%rho(p)
      rows(o + 5:o + 10, k) = self%stress(:, p); rows(o + 11:o + 16, k) = self%strain(:, p)
      rows(o + 17:o + 25, k) = reshape(self%F(:, :, p), [9])
      rows(o + 26, k) = real(self%mat(p), wp); rows(o + 27, k) = real(self%id(p), wp)
      rows(o + 28, k) = self%vol_fill(p)
      rows(o + 29:o + 28 + self%nstate, k) = self%state(:, p)
    end do
  end subroutine particles_pack_rows

  !> Make the set the n particles of `rows` ([[particles_pack_rows]]), in that order; storage
  !> for exactly n. Allocation failures as in [[particles_alloc]].
  subroutine particles_set_from_rows(self, ndim, nstate, rows, n, err, order)
    class(empm_particles_t), intent(inout) :: self     !! particles (replaced)
    integer, intent(in) :: ndim                        !! spatial dimension
    integer, intent(in) :: nstate                      !! state variables per particle
    real(wp), intent(in) :: rows(:,:)                  !! packed particles (row_size, >= n)
    integer, intent(in) :: n                           !! number of particles
    type(empm_error_t), intent(inout), optional :: err !! allocation failure, if present
    integer, intent(in), optional :: order(:)          !! particle k from column order(k)
                                                       !! (default k): no sorted copy
    type(empm_error_t) :: e
    integer :: k, d, o, c
    call self%alloc(ndim, n, nstate, e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    d = ndim; o = 10 * d
    do k = 1, n
      c = k
      if (present(order)) c = order(k)
      self%x(:, k) = rows(1:d, c); self%x0(:, k) = rows(d + 1:2 * d, c)
      self%v(:, k) = rows(2 * d + 1:3 * d, c); self%a(:, k) = rows(3 * d + 1:4 * d, c)
      self%dx(:, k) = rows(4 * d + 1:5 * d, c); self%lp(:, k) = rows(5 * d + 1:6 * d, c)
      self%lam(:, k) = rows(6 * d + 1:7 * d, c); self%lam_old(:, k) = rows(7 * d + 1:8 * d, c)
      self%lam_prev(:, k) = rows(8 * d + 1:9 * d, c)
      self%lam_old_prev(:, k) = rows(9 * d + 1:10 * d, c)
      self%m(k) = rows(o + 1, c); self%vol(k) = rows(o + 2, c)
      self%vol0(k) = rows(o + 3, c); self%rho(k) = rows(o + 4, c)
      self%stress(:, k) = rows(o + 5:o + 10, c); self%strain(:, k) = rows(o + 11:o + 16, c)
      self%F(:, :, k) = reshape(rows(o + 17:o + 25, c), [3, 3])
      self%mat(k) = nint(rows(o + 26, c)); self%id(k) = nint(rows(o + 27, c))
      self%vol_fill(k) = rows(o + 28, c)
      self%state(:, k) = rows(o + 29:o + 28 + nstate, c)
    end do
    self%np = n
  end subroutine particles_set_from_rows

  !> Field f (1..PARTICLE_FIELDS; 1 is the id) of particles 1..np as columns, one per
  !> particle (integers as reals), and the field's storage released: a set moved field by
  !> field to other processes holds a few copies of one field at a time, not the whole set
  !> twice ([[particles_put_field]]).
  subroutine particles_take_field(self, f, cols)
    class(empm_particles_t), intent(inout) :: self     !! particles (field f released)
    integer, intent(in) :: f                           !! field, 1..PARTICLE_FIELDS
    real(wp), allocatable, intent(out) :: cols(:,:)    !! its values (width, np)
    integer :: n
    n = self%np
    select case (f)
    case (1); cols = reshape(real(self%id(1:n), wp), [1, n]); deallocate(self%id)
    case (2); call take2(self%x)
    case (3); call take2(self%x0)
    case (4); call take2(self%v)
    case (5); call take2(self%a)
    case (6); call take2(self%dx)
    case (7); call take1(self%m)
    case (8); call take1(self%vol)
    case (9); call take1(self%vol0)
    case (10); call take1(self%rho)
    case (11); call take2(self%stress)
    case (12); call take2(self%strain)
    case (13); cols = reshape(self%F(:, :, 1:n), [9, n]); deallocate(self%F)
    case (14); call take2(self%lp)
    case (15); call take2(self%lam)
    case (16); call take2(self%lam_old)
    case (17); call take2(self%lam_prev)
    case (18); call take2(self%lam_old_prev)
    case (19); call take1(self%vol_fill)
    case (20); cols = reshape(real(self%mat(1:n), wp), [1, n]); deallocate(self%mat)
    case (21); call take2(self%state)
    end select
  contains
    subroutine take1(a)
      real(wp), allocatable, intent(inout) :: a(:)
      cols = reshape(a(1:n), [1, n]); deallocate(a)
    end subroutine take1
    subroutine take2(a)
      real(wp), allocatable, intent(inout) :: a(:,:)
      cols = a(:, 1:n); deallocate(a)
    end subroutine take2
  end subroutine particles_take_field

  !> Field f of a set of n particles from columns (those of [[particles_take_field]], in the
  !> new set's order: particle k from column order(k)). The caller sets `np` = n once every
  !> field is put (each field is taken with the old `np`). Out of memory: `ok` false and the
  !> field left unallocated.
  subroutine particles_put_field(self, f, cols, order, ok)
    class(empm_particles_t), intent(inout) :: self     !! particles (field f replaced)
    integer, intent(in) :: f                           !! field, 1..PARTICLE_FIELDS
    real(wp), intent(in) :: cols(:,:)                  !! values (width, >= maxval(order))
    integer, intent(in) :: order(:)                    !! column of each particle
    logical, intent(out) :: ok                         !! the field's storage was allocated
    integer :: n, st
    n = size(order); st = 0
    select case (f)
    case (1)
      allocate(self%id(n), stat=st)
      if (st == 0) self%id = nint(cols(1, order))
    case (2); call put2(self%x)
    case (3); call put2(self%x0)
    case (4); call put2(self%v)
    case (5); call put2(self%a)
    case (6); call put2(self%dx)
    case (7); call put1(self%m)
    case (8); call put1(self%vol)
    case (9); call put1(self%vol0)
    case (10); call put1(self%rho)
    case (11); call put2(self%stress)
    case (12); call put2(self%strain)
    case (13)
      allocate(self%F(3, 3, n), stat=st)
      if (st == 0) self%F = reshape(cols(:, order), [3, 3, n])
    case (14); call put2(self%lp)
    case (15); call put2(self%lam)
    case (16); call put2(self%lam_old)
    case (17); call put2(self%lam_prev)
    case (18); call put2(self%lam_old_prev)
    case (19); call put1(self%vol_fill)
    case (20)
      allocate(self%mat(n), stat=st)
      if (st == 0) self%mat = nint(cols(1, order))
    case (21); call put2(self%state)
    end select
    ok = st == 0
  contains
    subroutine put1(a)
      real(wp), allocatable, intent(inout) :: a(:)
      allocate(a(n), stat=st)
      if (st == 0) a = cols(1, order)
    end subroutine put1
    subroutine put2(a)
      real(wp), allocatable, intent(inout) :: a(:,:)
      allocate(a(size(cols, 1), n), stat=st)
      if (st == 0) a = cols(:, order)
    end subroutine put2
  end subroutine particles_put_field

  !> Keep particles idx(1), idx(2), ... (increasing), in that order, as particles 1, 2, ...;
  !> the others are dropped (the storage keeps its size).
  subroutine particles_keep(self, idx)
    class(empm_particles_t), intent(inout) :: self !! particles
    integer, intent(in) :: idx(:)                  !! particles to keep, increasing
    integer :: k, p
    do k = 1, size(idx)
      p = idx(k)
      if (p == k) cycle
      self%x(:, k) = self%x(:, p); self%x0(:, k) = self%x0(:, p)
      self%v(:, k) = self%v(:, p); self%a(:, k) = self%a(:, p); self%dx(:, k) = self%dx(:, p)
      self%m(k) = self%m(p); self%vol(k) = self%vol(p); self%vol0(k) = self%vol0(p)
      self%rho(k) = self%rho(p)
      self%stress(:, k) = self%stress(:, p); self%strain(:, k) = self%strain(:, p)
      self%F(:, :, k) = self%F(:, :, p)
      self%lp(:, k) = self%lp(:, p); self%lam(:, k) = self%lam(:, p)
      self%lam_old(:, k) = self%lam_old(:, p); self%lam_prev(:, k) = self%lam_prev(:, p)
      self%lam_old_prev(:, k) = self%lam_old_prev(:, p)
      self%mat(k) = self%mat(p); self%id(k) = self%id(p); self%vol_fill(k) = self%vol_fill(p)
      if (self%nstate > 0) self%state(:, k) = self%state(:, p)
    end do
    self%np = size(idx)
  end subroutine particles_keep

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
    call move_alloc(from%id, to%id)
    call move_alloc(from%vol_fill, to%vol_fill)
    to%nstate = from%nstate
    call move_alloc(from%state, to%state)
  end subroutine move_alloc_all
end module empm_particles
