!> In-memory record of a run: energy histories, probe histories and state snapshots.
!> Filled by the solver, written to HDF5 by the output layer, or read directly by an
!> embedding code.
module empm_history
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise_error, empm_alloc_error
  use empm_particles, only: empm_particles_t
  use empm_model, only: empm_model_t
  implicit none
  private
  public :: empm_history_t, empm_snapshot_t

  !> Particle state at one time.
  type :: empm_snapshot_t
    real(wp) :: t = 0.0_wp               !! time [s]
    integer :: step = 0                  !! step number
    real(wp), allocatable :: x(:,:)      !! positions (ndim, np)
    real(wp), allocatable :: v(:,:)      !! velocities (ndim, np)
    real(wp), allocatable :: stress(:,:) !! stresses (6, np)
    real(wp), allocatable :: strain(:,:) !! strains (6, np)
    real(wp), allocatable :: m(:)        !! masses (np)
    real(wp), allocatable :: vol(:)      !! volumes (np)
    real(wp), allocatable :: rho(:)      !! densities (np)
    integer, allocatable :: id(:)        !! the particles' ids (np): the columns' order
    real(wp), allocatable :: state(:,:)  !! materials' state variables (nstate, np), as
                                         !! `pts%state`
    !> The file the snapshot was written to as it was taken ([[history_add_staged]]), its
    !> arrays then unallocated; unallocated when the arrays hold it.
    character(len=:), allocatable :: file
    !> The group of `file` holding it: '' (the file's root) or a results file's
    !> `/snapshots/NNNNNN` (a restart's earlier snapshots)
    character(len=:), allocatable :: frame
  contains
    procedure :: take => snapshot_take
  end type empm_snapshot_t

  !> Histories of a run.
  type :: empm_history_t
    integer :: nt = 0                        !! number of recorded history samples
    integer :: nprobe = 0                    !! number of probes
    character(len=64), allocatable :: probe_name(:)  !! probe names (nprobe)
    integer, allocatable :: probe_particle(:)        !! particle followed by each probe
    integer, allocatable :: probe_local(:)           !! its index on this process (0: held by
                                                     !! another; [[history_locate_probes]])
    real(wp), allocatable :: t(:)            !! sample times (nt) [s]
    real(wp), allocatable :: kinetic(:)      !! kinetic energy (nt) [J]
    real(wp), allocatable :: strain(:)       !! stored elastic energy (nt) [J]
    real(wp), allocatable :: gravity(:)      !! gravitational potential −Σ m g·x (nt) [J]
    real(wp), allocatable :: px(:,:,:)       !! probe positions (ndim, nprobe, nt)
    real(wp), allocatable :: pv(:,:,:)       !! probe velocities (ndim, nprobe, nt)
    real(wp), allocatable :: ps(:,:,:)       !! probe stresses (6, nprobe, nt)
    integer :: nsnap = 0                     !! snapshots taken
    type(empm_snapshot_t), allocatable :: snap(:) !! snapshots (nsnap used)
    ! Recorded when the model tracks its residual (`model%track`), sized at the first sample.
    logical :: tracked = .false.             !! the arrays below are in use
    real(wp), allocatable :: residual(:)     !! ‖f_unbalanced‖/‖f_ext‖ of the last force
                                             !! assembly (nt); −1 when no external load acts
    integer :: nset = 0                      !! reaction sets (named &boundary groups)
    character(len=64), allocatable :: set_name(:) !! their names (nset)
    real(wp), allocatable :: reaction(:,:,:) !! reaction force of each set (ndim, nset, nt) [N]
    real(wp), allocatable :: set_disp(:,:,:) !! prescribed displacement of each set, velocity × t
                                             !! on its fixed components (ndim, nset, nt) [m]
  contains
    procedure :: init => history_init
    procedure :: add_sample => history_add_sample
    procedure :: add_snapshot => history_add_snapshot
    procedure :: add_staged => history_add_staged
    procedure :: locate_probes => history_locate_probes
  end type empm_history_t

contains

  !> Prepare an empty record for `nprobe` probes following the given particles, with room for
  !> `capacity` samples and `nsnap_max` snapshots. An allocation failure is reported in `err`
  !> when present (with the memory asked for), otherwise it stops the program.
  subroutine history_init(self, ndim, names, particles, capacity, nsnap_max, err)
    class(empm_history_t), intent(inout) :: self    !! record
    integer, intent(in) :: ndim                     !! spatial dimension
    character(len=*), intent(in) :: names(:)        !! probe names
    integer, intent(in) :: particles(:)             !! particle index of each probe
    integer, intent(in) :: capacity                 !! initial number of samples reserved
    integer, intent(in) :: nsnap_max                !! number of snapshots reserved
    type(empm_error_t), intent(inout), optional :: err !! set on an allocation failure
    integer :: n, c, stat
    character(len=256) :: msg
    n = size(particles); c = max(capacity, 16)
    self%nt = 0; self%nprobe = n; self%nsnap = 0
    if (allocated(self%t)) deallocate(self%t, self%kinetic, self%strain, self%gravity, &
      self%px, self%pv, self%ps, self%probe_name, self%probe_particle, self%probe_local)
    if (allocated(self%snap)) deallocate(self%snap)
    if (allocated(self%residual)) deallocate(self%residual)
    if (allocated(self%set_name)) deallocate(self%set_name, self%reaction, self%set_disp)
    self%tracked = .false.; self%nset = 0
    allocate(self%probe_name(n), self%probe_particle(n), self%probe_local(n))
    self%probe_name = names; self%probe_particle = particles; self%probe_local = particles
    allocate(self%t(c), self%kinetic(c), self%strain(c), self%gravity(c), &
      self%px(ndim, n, c), self%pv(ndim, n, c), self%ps(6, n, c), self%snap(max(nsnap_max, 1)), &
      stat=stat, errmsg=msg)
    if (stat /= 0) call empm_raise_error(empm_alloc_error('history buffers', &
      8_int64 * c * (4 + n * (2 * ndim + 6)), msg), err)
  end subroutine history_init

  !> Append one sample. Storage grows geometrically when full (rare, amortised). With `model`
  !> tracking its residual, the residual and the reactions of its node sets are recorded too
  !> (their arrays sized at the first such sample).
  subroutine history_add_sample(self, t, ekin, estrain, egrav, pts, model)
    class(empm_history_t), intent(inout) :: self !! record
    real(wp), intent(in) :: t                    !! time [s]
    real(wp), intent(in) :: ekin                 !! kinetic energy [J]
    real(wp), intent(in) :: estrain              !! stored energy [J]
    real(wp), intent(in) :: egrav                !! gravitational potential [J]
    type(empm_particles_t), intent(in) :: pts    !! particles (probe values)
    type(empm_model_t), intent(in), optional :: model !! model (residual, reactions)
    integer :: k, p, nd, q
    if (present(model)) then
      ! Tracking starts with the first sample (a model tracked only later is not recorded).
      if (model%track .and. .not. self%tracked .and. self%nt == 0) then
        self%tracked = .true.; self%nset = model%nodes%nset; nd = model%grid%ndim
        allocate(self%residual(size(self%t)), self%set_name(self%nset), &
          self%reaction(nd, self%nset, size(self%t)), self%set_disp(nd, self%nset, size(self%t)))
        self%set_name = model%nodes%set_name(1:self%nset)
      end if
    end if
    if (self%nt == size(self%t)) call grow(self)
    k = self%nt + 1; self%nt = k
    self%t(k) = t; self%kinetic(k) = ekin; self%strain(k) = estrain; self%gravity(k) = egrav
    do p = 1, self%nprobe
      q = self%probe_local(p)
      if (q > 0) then
        self%px(:, p, k) = pts%x(:, q)
        self%pv(:, p, k) = pts%v(:, q)
        self%ps(:, p, k) = pts%stress(:, q)
      else
        self%px(:, p, k) = 0.0_wp; self%pv(:, p, k) = 0.0_wp; self%ps(:, p, k) = 0.0_wp
      end if
    end do
    if (present(model) .and. self%nprobe > 0) then
      ! One process holds each probe's particle; the others add zeros.
      call model%comm%sum(self%px(:, :, k))
      call model%comm%sum(self%pv(:, :, k))
      call model%comm%sum(self%ps(:, :, k))
    end if
    if (self%tracked .and. present(model)) then
      self%residual(k) = model%residual
      do p = 1, self%nset
        self%reaction(:, p, k) = model%nodes%reaction(:, p)
        self%set_disp(:, p, k) = model%nodes%set_vel(:, p) * t
      end do
    end if
  end subroutine history_add_sample

  !> Find each probe's particle among those this process holds (by id, after the particles
  !> were shared among processes); 0 where another process holds it.
  subroutine history_locate_probes(self, pts)
    class(empm_history_t), intent(inout) :: self !! record
    type(empm_particles_t), intent(in) :: pts    !! this process's particles
    integer :: p, q
    self%probe_local = 0
    do q = 1, pts%np
      do p = 1, self%nprobe
        if (pts%id(q) == self%probe_particle(p)) self%probe_local(p) = q
      end do
    end do
  end subroutine history_locate_probes

  subroutine grow(self)
    type(empm_history_t), intent(inout) :: self
    real(wp), allocatable :: r1(:), r3(:,:,:)
    integer :: n, c
    n = self%nt; c = 2 * size(self%t)
    allocate(r1(c)); r1(1:n) = self%t(1:n); call move_alloc(r1, self%t)
    allocate(r1(c)); r1(1:n) = self%kinetic(1:n); call move_alloc(r1, self%kinetic)
    allocate(r1(c)); r1(1:n) = self%strain(1:n); call move_alloc(r1, self%strain)
    allocate(r1(c)); r1(1:n) = self%gravity(1:n); call move_alloc(r1, self%gravity)
    allocate(r3(size(self%px, 1), self%nprobe, c)); r3(:, :, 1:n) = self%px(:, :, 1:n)
    call move_alloc(r3, self%px)
    allocate(r3(size(self%pv, 1), self%nprobe, c)); r3(:, :, 1:n) = self%pv(:, :, 1:n)
    call move_alloc(r3, self%pv)
    allocate(r3(6, self%nprobe, c)); r3(:, :, 1:n) = self%ps(:, :, 1:n)
    call move_alloc(r3, self%ps)
    if (self%tracked) then
      allocate(r1(c)); r1(1:n) = self%residual(1:n); call move_alloc(r1, self%residual)
      allocate(r3(size(self%reaction, 1), self%nset, c))
      r3(:, :, 1:n) = self%reaction(:, :, 1:n); call move_alloc(r3, self%reaction)
      allocate(r3(size(self%set_disp, 1), self%nset, c))
      r3(:, :, 1:n) = self%set_disp(:, :, 1:n); call move_alloc(r3, self%set_disp)
    end if
  end subroutine grow

  !> Store a snapshot of the particle state, state variables included (ignored beyond the
  !> reserved count).
  subroutine history_add_snapshot(self, t, step, pts)
    class(empm_history_t), intent(inout) :: self !! record
    real(wp), intent(in) :: t                    !! time [s]
    integer, intent(in) :: step                  !! step number
    type(empm_particles_t), intent(in) :: pts    !! particles
    if (self%nsnap >= size(self%snap)) return
    self%nsnap = self%nsnap + 1
    call self%snap(self%nsnap)%take(t, step, pts)
  end subroutine history_add_snapshot

  !> The particles' state as a snapshot (a copy of their arrays, in their order, with ids).
  subroutine snapshot_take(self, t, step, pts)
    class(empm_snapshot_t), intent(inout) :: self !! snapshot (replaced)
    real(wp), intent(in) :: t                     !! time [s]
    integer, intent(in) :: step                   !! step number
    type(empm_particles_t), intent(in) :: pts     !! particles
    integer :: n
    n = pts%np
    self%t = t; self%step = step
    self%x = pts%x(:, 1:n); self%v = pts%v(:, 1:n)
    self%stress = pts%stress(:, 1:n); self%strain = pts%strain(:, 1:n)
    self%m = pts%m(1:n); self%vol = pts%vol(1:n); self%rho = pts%rho(1:n)
    self%state = pts%state(:, 1:n)
    self%id = pts%id(1:n)
    if (allocated(self%file)) deallocate(self%file)
    if (allocated(self%frame)) deallocate(self%frame)
  end subroutine snapshot_take

  !> Record a snapshot that was written to `file` as it was taken (its particle arrays are
  !> not held: empm_run_case streams them; docs/output.md, "Memory"); ignored beyond the
  !> reserved count.
  subroutine history_add_staged(self, t, step, file)
    class(empm_history_t), intent(inout) :: self !! record
    real(wp), intent(in) :: t                    !! time [s]
    integer, intent(in) :: step                  !! step number
    character(len=*), intent(in) :: file         !! the snapshot's file (at its root)
    integer :: k
    if (self%nsnap >= size(self%snap)) return
    k = self%nsnap + 1; self%nsnap = k
    self%snap(k)%t = t; self%snap(k)%step = step
    self%snap(k)%file = file; self%snap(k)%frame = ''
  end subroutine history_add_staged
end module empm_history
