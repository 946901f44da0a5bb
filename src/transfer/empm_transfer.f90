!> Particle-grid transfer kernels shared by every integrator: P2G of mass, momentum-like
!> quantities and forces; G2P interpolation of values and gradients; nodal constraints.
!>
!> No kernel allocates. With OpenMP, G2P kernels split the particles among the threads
!> (each particle is independent, so results do not depend on the thread count). P2G is made
!> race-free by a workspace ([[empm_p2g_work_t]], allocated once) in one of two modes, chosen
!> after every basis evaluation from the node range each block of particles touches:
!> - **two phases** (no buffers): the particles are cut into 2·nt contiguous sub-chunks; when
!>   sub-chunks k and k + 2 never share a node (particles stored roughly in space order, as
!>   the generators make them), the odd sub-chunks accumulate straight into the target in
!>   parallel, then, after a barrier, the even ones;
!> - **buffers** otherwise: the particles are cut into nt chunks, chunk 1 accumulates straight
!>   into the target, chunk c > 1 into buffer c, and the buffers are added to the target node
!>   by node, in chunk order, over the node range each chunk touched.
!> Either way the sums are fixed for a given thread count and particle order (reproducible run
!> to run) and equal to the serial sums to round-off; with one thread, or without a workspace,
!> they are the serial sums bit for bit. One driver, [[p2g_drive]], runs this skeleton for
!> every P2G kernel; what it accumulates is selected once per particle range ([[p2g_range]]).
!>
!> Every kernel dispatches on the basis layout and dimension once per particle chunk: the
!> compact bilinear and trilinear layouts (`BASIS_Q4`, `BASIS_Q8`) go to [[empm_transfer_q4]]
!> and [[empm_transfer_q8]], the compact 3^ndim
!> stencils of quadratic B-splines and uGIMP to [[empm_transfer_s9]] (`BASIS_B9`, `BASIS_G9`:
!> 2D) and [[empm_transfer_s27]] (`BASIS_B27`, `BASIS_G27`: 3D); node lists in 2D and 3D to
!> the specialised loops of [[empm_transfer_2d]] and [[empm_transfer_3d]] for the kernels of
!> the time step (momentum, mass + momentum, internal force, G2P, velocity gradient);
!> everything else (1D, the mass alone, body forces) to the generic loops here. All paths do
!> the same arithmetic in the same order (same bits). Nodal and particle arrays must be
!> contiguous.
module empm_transfer
  use empm_kinds, only: wp
  use empm_shape, only: empm_basis_t, BASIS_LISTS, BASIS_Q4, BASIS_Q8, BASIS_B9, BASIS_B27, &
                        BASIS_G9, BASIS_G27
  use empm_nodes, only: empm_nodes_t
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES, empm_chunks, empm_chunk_bounds
  use empm_transfer_2d, only: weighted_2d, mass_momentum_2d, internal_force_2d, &
                              velocity_gradient_2d, g2p_2d, gradient_g2p_2d
  use empm_transfer_3d, only: weighted_3d, mass_momentum_3d, internal_force_3d, &
                              velocity_gradient_3d, g2p_3d, gradient_g2p_3d
  use empm_transfer_q4, only: mass_q4, weighted_q4, mass_momentum_q4, body_force_q4, &
                              internal_force_q4, velocity_gradient_q4, g2p_q4, gradient_g2p_q4
  use empm_transfer_q8, only: mass_q8, weighted_q8, mass_momentum_q8, body_force_q8, &
                              internal_force_q8, velocity_gradient_q8, g2p_q8, gradient_g2p_q8
  use empm_transfer_s9, only: mass_s9, weighted_s9, mass_momentum_s9, body_force_s9, &
                              internal_force_s9, velocity_gradient_s9, g2p_s9, gradient_g2p_s9
  use empm_transfer_s27, only: mass_s27, weighted_s27, mass_momentum_s27, body_force_s27, &
                               internal_force_s27, velocity_gradient_s27, g2p_s27, &
                               gradient_g2p_s27
  implicit none
  private
  public :: empm_p2g_work_t
  public :: p2g_mass, p2g_weighted, p2g_mass_momentum, p2g_internal_force, p2g_body_force
  public :: g2p_value, g2p_add_scaled, g2p_block, velocity_gradient, gradient_g2p_block
  public :: axpy_flat
  public :: nodal_divide_by_mass

  !> Particles per block of a G2P with a kick ([[g2p_value]]): the interpolated vectors are
  !> still in L1 when the kick reads them (256 × 3 × 8 B = 6 KiB).
  integer, parameter :: KICK_BLOCK = 256

  !> Workspace of a race-free threaded P2G: the mode, the node ranges and the per-thread
  !> nodal accumulators (kept zero between calls).
  type :: empm_p2g_work_t
    integer :: nt = 1                       !! particle chunks (threads); 1 = serial
    logical :: two_phase = .false.          !! the current basis allows the two-phase mode
    real(wp), allocatable :: buf(:,:,:)     !! vector accumulators of chunks 2..nt (ndim, nnode, nt-1)
    real(wp), allocatable :: mbuf(:,:)      !! scalar (mass) accumulators of chunks 2..nt (nnode, nt-1)
    real(wp), allocatable :: vbuf(:,:)      !! second scalar (fill volume) accumulators (nnode, nt-1)
    integer, allocatable :: lo(:)           !! first node touched by each chunk (nt); set by
                                            !! set_ranges after every basis evaluation
    integer, allocatable :: hi(:)           !! last node touched by each chunk (nt)
    integer, allocatable :: slo(:)          !! first node touched by each sub-chunk (2 nt)
    integer, allocatable :: shi(:)          !! last node touched by each sub-chunk (2 nt)
  contains
    procedure :: init => p2g_work_init
    procedure :: set_ranges => p2g_work_set_ranges
    procedure :: fit => p2g_work_fit
  end type empm_p2g_work_t

  ! What a P2G pass accumulates: the selector of [[p2g_drive]] and [[p2g_range]].
  integer, parameter :: OP_MASS = 1           ! m_I ([[p2g_mass]])
  integer, parameter :: OP_WEIGHTED = 2       ! q_I ([[p2g_weighted]])
  integer, parameter :: OP_MASS_MOMENTUM = 3  ! m_I and q_I in one pass ([[p2g_mass_momentum]])
  integer, parameter :: OP_INTERNAL_FORCE = 4 ! internal force ([[p2g_internal_force]])
  integer, parameter :: OP_BODY_FORCE = 5     ! body force ([[p2g_body_force]])
  integer, parameter :: OP_MASS_MOMENTUM_FILL = 6 ! m_I, q_I and the fill volumes V_I in one pass

contains

  !> Size the workspace for `nthreads` threads (serial when there are too few particles for
  !> threads to pay off). Call at set-up, never in the time loop.
  subroutine p2g_work_init(self, ndim, nnode, np, nthreads)
    class(empm_p2g_work_t), intent(inout) :: self !! workspace
    integer, intent(in) :: ndim                   !! spatial dimension
    integer, intent(in) :: nnode                  !! number of grid nodes
    integer, intent(in) :: np                     !! number of particles
    integer, intent(in) :: nthreads               !! threads to use
    self%nt = max(1, nthreads)
    if (np < EMPM_OMP_MIN_PARTICLES) self%nt = 1
    if (allocated(self%buf)) deallocate(self%buf, self%mbuf, self%vbuf, self%lo, self%hi, &
                                        self%slo, self%shi)
    allocate(self%buf(ndim, nnode, self%nt - 1), self%mbuf(nnode, self%nt - 1), &
             self%vbuf(nnode, self%nt - 1), self%lo(self%nt), self%hi(self%nt), &
             self%slo(2 * self%nt), self%shi(2 * self%nt))
    self%buf = 0.0_wp; self%mbuf = 0.0_wp; self%vbuf = 0.0_wp
    self%lo = 1; self%hi = 0; self%slo = 1; self%shi = 0
    self%two_phase = .false.
  end subroutine p2g_work_init

  !> Resize the per-thread accumulators for `nnode` nodes when the stored grid changed size (a
  !> parallel process's new window); nothing otherwise.
  subroutine p2g_work_fit(self, nnode)
    class(empm_p2g_work_t), intent(inout) :: self !! workspace
    integer, intent(in) :: nnode                  !! nodes of the stored grid
    integer :: nd
    if (self%nt <= 1 .or. .not. allocated(self%buf)) return
    if (size(self%buf, 2) == nnode) return
    nd = size(self%buf, 1)
    deallocate(self%buf, self%mbuf, self%vbuf)
    allocate(self%buf(nd, nnode, self%nt - 1), self%mbuf(nnode, self%nt - 1), &
             self%vbuf(nnode, self%nt - 1))
    self%buf = 0.0_wp; self%mbuf = 0.0_wp; self%vbuf = 0.0_wp
  end subroutine p2g_work_fit

  !> Record the node range touched by each particle sub-chunk and chunk for the current basis
  !> and choose the mode (two phases when sub-chunks k and k + 2 share no node). The basis
  !> changes once per step, so this runs once per step (after the shape functions) instead of
  !> in every P2G call; the ranges are computed in parallel.
  subroutine p2g_work_set_ranges(self, basis)
    class(empm_p2g_work_t), intent(inout) :: self !! workspace
    type(empm_basis_t), intent(in) :: basis       !! shape functions at the particles
    integer :: c, p0, p1, p, k, lo, hi, last(0:1), span
    if (self%nt <= 1) return
    ! A compact layout's nodes run from `cell` to `cell + span` (the last node of its stencil).
    span = 0
    if (basis%layout == BASIS_Q4) span = basis%stride + 1
    if (basis%layout == BASIS_Q8) span = basis%stride2 + basis%stride + 1
    if (is_s9(basis)) span = 2 * basis%stride + 2
    if (is_s27(basis)) span = 2 * basis%stride2 + 2 * basis%stride + 2
    ! Sub-chunk by sub-chunk, each one's particles shared by all threads (a loop over the
    ! sub-chunks would leave threads idle when there are few of them).
    do c = 1, 2 * self%nt
      call empm_chunk_bounds(basis%np, 2 * self%nt, c - 1, p0, p1)
      lo = huge(1); hi = 0
      if (basis%layout /= BASIS_LISTS) then
        !$omp parallel do num_threads(self%nt) schedule(static) default(none) &
        !$omp   shared(basis, p0, p1, span) reduction(min: lo) reduction(max: hi)
        do p = p0, p1
          lo = min(lo, basis%cell(p)); hi = max(hi, basis%cell(p) + span)
        end do
        !$omp end parallel do
      else
        !$omp parallel do num_threads(self%nt) schedule(static) default(none) &
        !$omp   shared(basis, p0, p1) private(k) reduction(min: lo) reduction(max: hi)
        do p = p0, p1
          do k = 1, basis%nn(p)
            lo = min(lo, basis%node(k, p)); hi = max(hi, basis%node(k, p))
          end do
        end do
        !$omp end parallel do
      end if
      if (hi == 0) lo = huge(1) ! empty: shares no node with anything
      self%slo(c) = lo; self%shi(c) = hi
    end do
    ! Chunk c is sub-chunks 2c − 1 and 2c (the same particle bounds).
    do c = 1, self%nt
      self%lo(c) = min(self%slo(2 * c - 1), self%slo(2 * c))
      self%hi(c) = max(self%shi(2 * c - 1), self%shi(2 * c))
      if (self%hi(c) == 0) self%lo(c) = 1
    end do
    ! Two phases when, within each phase (odd, even sub-chunks), every non-empty sub-chunk
    ! starts above the last node of the previous non-empty one: the ranges then increase, so no
    ! two of them overlap (an empty sub-chunk must not hide an overlap across it).
    self%two_phase = .true.
    last = 0
    do c = 1, 2 * self%nt
      if (self%shi(c) == 0) cycle
      if (self%slo(c) <= last(mod(c, 2))) self%two_phase = .false.
      last(mod(c, 2)) = self%shi(c)
    end do
  end subroutine p2g_work_set_ranges

  !> Task `it` (1..nt) of phase `ph` of a threaded P2G over `np` particles: its particles
  !> p0..p1 and where they accumulate (`dst` = 0: the target; c > 0: buffer c).
  pure subroutine p2g_task(ws, np, ph, it, p0, p1, dst)
    type(empm_p2g_work_t), intent(in) :: ws !! threaded-P2G workspace
    integer, intent(in) :: np               !! number of particles
    integer, intent(in) :: ph               !! phase, 1..p2g_phases(ws)
    integer, intent(in) :: it               !! task, 1..nt
    integer, intent(out) :: p0              !! first particle
    integer, intent(out) :: p1              !! last particle
    integer, intent(out) :: dst             !! 0: the target; c > 0: buffer c
    if (ws%two_phase) then
      call empm_chunk_bounds(np, 2 * ws%nt, 2 * (it - 1) + ph - 1, p0, p1)
      dst = 0
    else
      call empm_chunk_bounds(np, ws%nt, it - 1, p0, p1)
      dst = it - 1
    end if
  end subroutine p2g_task

  !> Phases of a threaded P2G in the current mode.
  pure integer function p2g_phases(ws)
    type(empm_p2g_work_t), intent(in) :: ws !! threaded-P2G workspace
    p2g_phases = merge(2, 1, ws%two_phase)
  end function p2g_phases

  !> True when a P2G call runs on per-thread chunks (a workspace with more than one chunk).
  pure logical function threaded(ws)
    type(empm_p2g_work_t), intent(in), optional :: ws !! threaded-P2G workspace
    threaded = .false.
    if (present(ws)) threaded = ws%nt > 1
  end function threaded

  !> Add the chunk buffers to `q` (in chunk order) and zero them again.
  subroutine reduce_vec(ws, q)
    type(empm_p2g_work_t), intent(inout) :: ws !! threaded-P2G workspace (buffers zeroed)
    real(wp), intent(inout) :: q(:,:)          !! nodal vectors (ndim, nnode), accumulated
    integer :: I, c, ilo, ihi
    if (ws%two_phase) return ! nothing in the buffers
    ilo = minval(ws%lo(2:ws%nt)); ihi = maxval(ws%hi(2:ws%nt))
    !$omp do schedule(static)
    do I = ilo, ihi
      do c = 2, ws%nt
        if (I < ws%lo(c) .or. I > ws%hi(c)) cycle
        q(:, I) = q(:, I) + ws%buf(:, I, c - 1)
        ws%buf(:, I, c - 1) = 0.0_wp
      end do
    end do
    !$omp end do
  end subroutine reduce_vec

  !> As [[reduce_vec]] for a scalar nodal field, from the scalar buffers `sbuf` (`ws%mbuf` or
  !> `ws%vbuf`).
  subroutine reduce_scalar(ws, sbuf, q)
    type(empm_p2g_work_t), intent(in) :: ws    !! threaded-P2G workspace (modes, ranges)
    real(wp), intent(inout) :: sbuf(:,:)       !! its scalar buffers (zeroed)
    real(wp), intent(inout) :: q(:)            !! nodal scalars (accumulated)
    integer :: I, c, ilo, ihi
    if (ws%two_phase) return ! nothing in the buffers
    ilo = minval(ws%lo(2:ws%nt)); ihi = maxval(ws%hi(2:ws%nt))
    !$omp do schedule(static)
    do I = ilo, ihi
      do c = 2, ws%nt
        if (I < ws%lo(c) .or. I > ws%hi(c)) cycle
        q(I) = q(I) + sbuf(I, c - 1)
        sbuf(I, c - 1) = 0.0_wp
      end do
    end do
    !$omp end do
  end subroutine reduce_scalar

  !> Lumped mass m_I = Σ_p N_Ip m_p (accumulated into `mass`).
  subroutine p2g_mass(basis, m, mass, ws)
    type(empm_basis_t), intent(in) :: basis                  !! shape functions at the particles
    real(wp), intent(in) :: m(:)                             !! particle masses
    real(wp), intent(inout), contiguous :: mass(:)           !! nodal masses (accumulated)
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace
    real(wp) :: none1(0), none2(0, 0), nv(0)
    call p2g_drive(OP_MASS, basis, ws, m, none2, 0.0_wp, none2, none1, none2, none1, none2, &
                   .false., mass, none2, nv)
  end subroutine p2g_mass

  !> Mass-weighted transfer q_I += Σ_p N_Ip m_p (u_p + c·w_p), e.g. momentum (c = 0) or the
  !> predictor's v_p + (1−γ)Δt a_p.
  subroutine p2g_weighted(basis, m, u, c, w, q, ws)
    type(empm_basis_t), intent(in) :: basis                  !! shape functions at the particles
    real(wp), intent(in) :: m(:)                             !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)               !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                                !! scale of the second vector (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)               !! second particle vectors (ndim, np)
    real(wp), intent(inout), contiguous :: q(:,:)            !! nodal vectors (ndim, nnode), accumulated
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace
    real(wp) :: none1(0), none2(0, 0), nv(0)
    call p2g_drive(OP_WEIGHTED, basis, ws, m, u, c, w, none1, none2, none1, none2, .false., &
                   none1, q, nv)
  end subroutine p2g_weighted

  !> Lumped mass and a mass-weighted vector in one pass over the particles:
  !> m_I += Σ_p N_Ip m_p and q_I += Σ_p N_Ip m_p (u_p + c·w_p). The same sums as
  !> [[p2g_mass]] followed by [[p2g_weighted]], bit for bit, reading the basis once. With
  !> `vfill` and `vnode`, also the nodal fill volumes vnode_I += Σ_p N_Ip vfill_p in the same
  !> pass (the sums of a separate [[p2g_mass]] of `vfill`, bit for bit).
  subroutine p2g_mass_momentum(basis, m, u, c, w, mass, q, ws, vfill, vnode)
    type(empm_basis_t), intent(in) :: basis                  !! shape functions at the particles
    real(wp), intent(in) :: m(:)                             !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)               !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                                !! scale of the second vector (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)               !! second particle vectors (ndim, np)
    real(wp), intent(inout), contiguous :: mass(:)           !! nodal masses (accumulated)
    real(wp), intent(inout), contiguous :: q(:,:)            !! nodal vectors (ndim, nnode), accumulated
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace
    real(wp), intent(in), optional :: vfill(:)               !! particle volumes of the fill test
    real(wp), intent(inout), contiguous, optional :: vnode(:) !! nodal fill volumes (accumulated)
    real(wp) :: none1(0), none2(0, 0), nv(0)
    if (present(vfill) .and. present(vnode)) then
      call p2g_drive(OP_MASS_MOMENTUM_FILL, basis, ws, m, u, c, w, vfill, none2, none1, none2, &
                     .false., mass, q, vnode)
    else
      call p2g_drive(OP_MASS_MOMENTUM, basis, ws, m, u, c, w, none1, none2, none1, none2, &
                     .false., mass, q, nv)
    end if
  end subroutine p2g_mass_momentum

  !> Internal force f_I −= Σ_p V_p σ_p ∇N_Ip (paper eq. 16), σ in Voigt order.
  subroutine p2g_internal_force(basis, vol, stress, f, ws)
    type(empm_basis_t), intent(in) :: basis                  !! shape functions at the particles
    real(wp), intent(in) :: vol(:)                           !! particle volumes
    real(wp), intent(in), contiguous :: stress(:,:)          !! Cauchy stress (6, np)
    real(wp), intent(inout), contiguous :: f(:,:)            !! nodal forces (ndim, nnode), accumulated
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace
    real(wp) :: none1(0), none2(0, 0), nv(0)
    call p2g_drive(OP_INTERNAL_FORCE, basis, ws, none1, none2, 0.0_wp, none2, vol, stress, none1, &
                   none2, .false., none1, f, nv)
  end subroutine p2g_internal_force

  !> External body force f_I += Σ_p N_Ip m_p (g + b_p) (paper eq. 17 without tractions).
  subroutine p2g_body_force(basis, m, g, b, use_b, f, ws)
    type(empm_basis_t), intent(in) :: basis                  !! shape functions at the particles
    real(wp), intent(in) :: m(:)                             !! particle masses
    real(wp), intent(in) :: g(:)                             !! uniform acceleration (gravity) (ndim)
    real(wp), intent(in) :: b(:,:)                           !! per-particle body force per unit mass (ndim, np)
    logical, intent(in) :: use_b                             !! whether `b` holds data
    real(wp), intent(inout), contiguous :: f(:,:)            !! nodal forces (ndim, nnode), accumulated
    type(empm_p2g_work_t), intent(inout), optional :: ws     !! threaded-P2G workspace
    real(wp) :: none1(0), none2(0, 0), nv(0)
    ! Nothing to add: skip the pass (adding zeros leaves f unchanged bit for bit).
    if (.not. use_b .and. all(g == 0.0_wp)) return
    call p2g_drive(OP_BODY_FORCE, basis, ws, m, none2, 0.0_wp, none2, none1, none2, g, b, use_b, &
                   none1, f, nv)
  end subroutine p2g_body_force

  !> The P2G skeleton of every `p2g_*` above: accumulate the sums `op` selects into `mass`
  !> and/or `q`. Serial over all particles without a threaded workspace; otherwise each task
  !> of each phase (module comment) sends its particle range to the target (dst = 0) or to its
  !> chunk's buffers, and the buffers are reduced into the targets `op` writes. The arguments
  !> `op` does not read are zero-size arrays (not absent optional ones: gfortran forms the
  !> descriptor of an absent array argument from a null pointer, which UBSan rightly reports).
  subroutine p2g_drive(op, basis, ws, m, u, c, w, vol, stress, g, b, use_b, mass, q, vn)
    integer, intent(in) :: op                                       !! OP_* selector
    type(empm_basis_t), intent(in) :: basis                         !! shape functions at the particles
    type(empm_p2g_work_t), intent(inout), optional :: ws            !! threaded-P2G workspace
    real(wp), intent(in) :: m(:)                          !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)            !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                             !! scale of `w` (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)            !! second particle vectors (ndim, np)
    real(wp), intent(in) :: vol(:)                        !! particle volumes (OP_MASS_MOMENTUM_FILL:
                                                          !! of the fill test)
    real(wp), intent(in), contiguous :: stress(:,:)       !! Cauchy stress (6, np)
    real(wp), intent(in) :: g(:)                          !! uniform acceleration (ndim)
    real(wp), intent(in) :: b(:,:)                        !! body force per unit mass (ndim, np)
    logical, intent(in) :: use_b                          !! whether `b` holds data
    real(wp), intent(inout), contiguous :: mass(:)        !! nodal scalars (accumulated)
    real(wp), intent(inout), contiguous :: q(:,:)         !! nodal vectors (ndim, nnode), accumulated
    real(wp), intent(inout), contiguous :: vn(:)          !! nodal fill volumes (accumulated;
                                                          !! OP_MASS_MOMENTUM_FILL only)
    integer :: it, p0, p1, ph, dst
    if (.not. threaded(ws)) then
      call p2g_range(op, basis, 1, basis%np, m, u, c, w, vol, stress, g, b, use_b, mass, q, vn)
      return
    end if
    !$omp parallel num_threads(ws%nt) default(none) private(ph, it, p0, p1, dst) &
    !$omp   shared(op, basis, ws, m, u, c, w, vol, stress, g, b, use_b, mass, q, vn)
    do ph = 1, p2g_phases(ws)
      !$omp do schedule(static, 1)
      do it = 1, ws%nt
        call p2g_task(ws, basis%np, ph, it, p0, p1, dst)
        if (dst == 0) then
          call p2g_range(op, basis, p0, p1, m, u, c, w, vol, stress, g, b, use_b, mass, q, vn)
        else
          call p2g_range(op, basis, p0, p1, m, u, c, w, vol, stress, g, b, use_b, &
                         ws%mbuf(:, dst), ws%buf(:, :, dst), ws%vbuf(:, dst))
        end if
      end do
      !$omp end do
    end do
    if (op == OP_MASS .or. op == OP_MASS_MOMENTUM .or. op == OP_MASS_MOMENTUM_FILL) &
      call reduce_scalar(ws, ws%mbuf, mass)
    if (op == OP_MASS_MOMENTUM_FILL) call reduce_scalar(ws, ws%vbuf, vn)
    if (op /= OP_MASS) call reduce_vec(ws, q)
    !$omp end parallel
  end subroutine p2g_drive

  !> Particles p0..p1 of the P2G pass `op` into `mass` and/or `q`: the one dispatch on the
  !> pass, once per particle range (never per particle).
  pure subroutine p2g_range(op, basis, p0, p1, m, u, c, w, vol, stress, g, b, use_b, mass, q, vn)
    integer, intent(in) :: op                                       !! OP_* selector
    type(empm_basis_t), intent(in) :: basis                         !! shape functions at the particles
    integer, intent(in) :: p0                                       !! first particle
    integer, intent(in) :: p1                                       !! last particle
    real(wp), intent(in) :: m(:)                          !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)            !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                             !! scale of `w` (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)            !! second particle vectors (ndim, np)
    real(wp), intent(in) :: vol(:)                        !! particle volumes
    real(wp), intent(in), contiguous :: stress(:,:)       !! Cauchy stress (6, np)
    real(wp), intent(in) :: g(:)                          !! uniform acceleration (ndim)
    real(wp), intent(in) :: b(:,:)                        !! body force per unit mass (ndim, np)
    logical, intent(in) :: use_b                          !! whether `b` holds data
    real(wp), intent(inout), contiguous :: mass(:)        !! nodal scalars (accumulated)
    real(wp), intent(inout), contiguous :: q(:,:)         !! nodal vectors (ndim, nnode), accumulated
    real(wp), intent(inout), contiguous :: vn(:)          !! nodal fill volumes (accumulated)
    select case (op)
    case (OP_MASS)
      call mass_range(basis, m, p0, p1, mass)
    case (OP_WEIGHTED)
      call weighted_range(basis, m, u, c, w, p0, p1, q)
    case (OP_MASS_MOMENTUM)
      call mass_momentum_range(basis, m, u, c, w, p0, p1, mass, q, .false., vol, vn)
    case (OP_MASS_MOMENTUM_FILL)
      call mass_momentum_range(basis, m, u, c, w, p0, p1, mass, q, .true., vol, vn)
    case (OP_INTERNAL_FORCE)
      call internal_range(basis, vol, stress, p0, p1, q)
    case (OP_BODY_FORCE)
      call body_range(basis, m, g, b, use_b, p0, p1, q)
    end select
  end subroutine p2g_range

  !> m_I += Σ_p N_Ip m_p over particles p0..p1.
  pure subroutine mass_range(basis, m, p0, p1, mass)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in) :: m(:)                     !! particle masses
    integer, intent(in) :: p0                        !! first particle
    integer, intent(in) :: p1                        !! last particle
    real(wp), intent(inout) :: mass(:)               !! nodal masses (accumulated)
    integer :: p, k
    if (basis%layout == BASIS_Q4) then
      call mass_q4(basis%stride, p0, p1, basis%cell, basis%t, m, mass); return
    end if
    if (basis%layout == BASIS_Q8) then
      call mass_q8(basis%stride, basis%stride2, p0, p1, basis%cell, basis%t, m, mass); return
    end if
    if (is_s9(basis)) then
      call mass_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                   basis%layout == BASIS_G9, basis%wg, m, mass); return
    end if
    if (is_s27(basis)) then
      call mass_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                    basis%layout == BASIS_G27, basis%wg, m, mass); return
    end if
    do p = p0, p1
      do k = 1, basis%nn(p)
        mass(basis%node(k, p)) = mass(basis%node(k, p)) + basis%N(k, p) * m(p)
      end do
    end do
  end subroutine mass_range

  !> q_I += Σ_p N_Ip m_p (u_p + c·w_p) over particles p0..p1.
  pure subroutine weighted_range(basis, m, u, c, w, p0, p1, q)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in) :: m(:)                     !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)       !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                        !! scale of `w` (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)       !! second particle vectors (ndim, np)
    integer, intent(in) :: p0                        !! first particle
    integer, intent(in) :: p1                        !! last particle
    real(wp), intent(inout), contiguous :: q(:,:)    !! nodal vectors (ndim, nnode), accumulated
    real(wp) :: mu(3)
    integer :: p, k, I, d
    if (basis%layout == BASIS_Q4) then
      call weighted_q4(basis%stride, p0, p1, basis%cell, basis%t, m, u, c, w, q); return
    end if
    if (basis%layout == BASIS_Q8) then
      call weighted_q8(basis%stride, basis%stride2, p0, p1, basis%cell, basis%t, m, u, c, w, q); return
    end if
    if (is_s9(basis)) then
      call weighted_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                       basis%layout == BASIS_G9, basis%wg, m, u, c, w, q)
      return
    end if
    if (is_s27(basis)) then
      call weighted_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                        basis%layout == BASIS_G27, basis%wg, m, u, c, w, q)
      return
    end if
    if (basis%ndim == 2) then
      call weighted_2d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, m, u, c, w, q); return
    end if
    if (basis%ndim == 3) then
      call weighted_3d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, m, u, c, w, q); return
    end if
    d = size(u, 1)
    do p = p0, p1
      if (c == 0.0_wp) then
        mu(1:d) = m(p) * u(:, p)
      else
        mu(1:d) = m(p) * (u(:, p) + c * w(:, p))
      end if
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        q(:, I) = q(:, I) + basis%N(k, p) * mu(1:d)
      end do
    end do
  end subroutine weighted_range

  !> [[mass_range]] and [[weighted_range]] in one pass over particles p0..p1 (the same bits);
  !> with `fill` also the [[mass_range]] of `vol` into `vn`.
  pure subroutine mass_momentum_range(basis, m, u, c, w, p0, p1, mass, q, fill, vol, vn)
    type(empm_basis_t), intent(in) :: basis              !! shape functions at the particles
    real(wp), intent(in) :: m(:)                         !! particle masses
    real(wp), intent(in), contiguous :: u(:,:)           !! particle vectors (ndim, np)
    real(wp), intent(in) :: c                            !! scale of `w` (0 to ignore it)
    real(wp), intent(in), contiguous :: w(:,:)           !! second particle vectors (ndim, np)
    integer, intent(in) :: p0                            !! first particle
    integer, intent(in) :: p1                            !! last particle
    real(wp), intent(inout), contiguous :: mass(:)       !! nodal masses (accumulated)
    real(wp), intent(inout), contiguous :: q(:,:)        !! nodal vectors (ndim, nnode), accumulated
    logical, intent(in) :: fill                          !! also the fill volumes
    real(wp), intent(in) :: vol(:)                       !! particle fill volumes (with `fill`)
    real(wp), intent(inout), contiguous :: vn(:)         !! nodal fill volumes (with `fill`)
    if (basis%layout == BASIS_Q4) then
      call mass_momentum_q4(basis%stride, p0, p1, basis%cell, basis%t, m, u, c, w, mass, q, &
                            fill, vol, vn)
    else if (basis%layout == BASIS_Q8) then
      call mass_momentum_q8(basis%stride, basis%stride2, p0, p1, basis%cell, basis%t, m, u, c, w, mass, &
                            q, fill, vol, vn)
    else if (is_s9(basis)) then
      call mass_momentum_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                            basis%layout == BASIS_G9, basis%wg, m, u, c, w, &
                            mass, q, fill, vol, vn)
    else if (is_s27(basis)) then
      call mass_momentum_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                             basis%layout == BASIS_G27, basis%wg, m, u, c, w, mass, q, fill, vol, vn)
    else if (basis%ndim == 2) then
      call mass_momentum_2d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, m, u, c, w, &
                            mass, q, fill, vol, vn)
    else if (basis%ndim == 3) then
      call mass_momentum_3d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, m, u, c, w, &
                            mass, q, fill, vol, vn)
    else
      call mass_range(basis, m, p0, p1, mass)
      call weighted_range(basis, m, u, c, w, p0, p1, q)
      if (fill) call mass_range(basis, vol, p0, p1, vn)
    end if
  end subroutine mass_momentum_range

  !> f_I −= Σ_p V_p σ_p ∇N_Ip over particles p0..p1.
  pure subroutine internal_range(basis, vol, stress, p0, p1, f)
    type(empm_basis_t), intent(in) :: basis              !! shape functions at the particles
    real(wp), intent(in) :: vol(:)                       !! particle volumes
    real(wp), intent(in), contiguous :: stress(:,:)      !! Cauchy stress (6, np)
    integer, intent(in) :: p0                            !! first particle
    integer, intent(in) :: p1                            !! last particle
    real(wp), intent(inout), contiguous :: f(:,:)        !! nodal forces (ndim, nnode), accumulated
    real(wp) :: s(3, 3), t
    integer :: p, k, I, d, a, b
    d = basis%ndim
    if (basis%layout == BASIS_Q4) then
      call internal_force_q4(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, vol, &
                             stress, f)
      return
    end if
    if (basis%layout == BASIS_Q8) then
      call internal_force_q8(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                             vol, stress, f)
      return
    end if
    if (is_s9(basis)) then
      call internal_force_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                             basis%layout == BASIS_G9, basis%wg, vol, &
                             stress, f)
      return
    end if
    if (is_s27(basis)) then
      call internal_force_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                              basis%layout == BASIS_G27, basis%wg, vol, stress, f)
      return
    end if
    if (d == 2) then
      call internal_force_2d(basis%maxn, p0, p1, basis%nn, basis%node, basis%dN, vol, stress, f)
      return
    end if
    if (d == 3) then
      call internal_force_3d(basis%maxn, p0, p1, basis%nn, basis%node, basis%dN, vol, stress, f)
      return
    end if
    do p = p0, p1
      s(1, 1) = stress(1, p); s(2, 2) = stress(2, p); s(3, 3) = stress(3, p)
      s(2, 3) = stress(4, p); s(3, 2) = stress(4, p)
      s(1, 3) = stress(5, p); s(3, 1) = stress(5, p)
      s(1, 2) = stress(6, p); s(2, 1) = stress(6, p)
      s = vol(p) * s
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        ! (σV ∇N)_a summed over b in order, as matmul did, without its run-time-sized temporary.
        do a = 1, d
          t = 0.0_wp
          do b = 1, d
            t = t + s(a, b) * basis%dN(b, k, p)
          end do
          f(a, I) = f(a, I) - t
        end do
      end do
    end do
  end subroutine internal_range

  !> f_I += Σ_p N_Ip m_p (g + b_p) over particles p0..p1.
  pure subroutine body_range(basis, m, g, b, use_b, p0, p1, f)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in) :: m(:)                     !! particle masses
    real(wp), intent(in) :: g(:)                     !! uniform acceleration (ndim)
    real(wp), intent(in) :: b(:,:)                   !! body force per unit mass (ndim, np)
    logical, intent(in) :: use_b                     !! whether `b` holds data
    integer, intent(in) :: p0                        !! first particle
    integer, intent(in) :: p1                        !! last particle
    real(wp), intent(inout) :: f(:,:)                !! nodal forces (ndim, nnode), accumulated
    real(wp) :: fp(3)
    integer :: p, k, I, d
    if (basis%layout == BASIS_Q4) then
      call body_force_q4(basis%stride, p0, p1, basis%cell, basis%t, m, g, b, use_b, f); return
    end if
    if (basis%layout == BASIS_Q8) then
      call body_force_q8(basis%stride, basis%stride2, p0, p1, basis%cell, basis%t, m, g, b, use_b, f)
      return
    end if
    if (is_s9(basis)) then
      call body_force_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                         basis%layout == BASIS_G9, basis%wg, m, g, b, use_b, &
                         f)
      return
    end if
    if (is_s27(basis)) then
      call body_force_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                          basis%layout == BASIS_G27, basis%wg, m, g, b, use_b, f)
      return
    end if
    d = size(g)
    do p = p0, p1
      fp(1:d) = g
      if (use_b) fp(1:d) = fp(1:d) + b(:, p)
      fp(1:d) = m(p) * fp(1:d)
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        f(:, I) = f(:, I) + basis%N(k, p) * fp(1:d)
      end do
    end do
  end subroutine body_range

  !> Whether `basis` has a compact 3 × 3 stencil layout (2D quadratic B-splines or uGIMP).
  pure logical function is_s9(basis)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    is_s9 = basis%layout == BASIS_B9 .or. basis%layout == BASIS_G9
  end function is_s9

  !> Whether `basis` has a compact 3 × 3 × 3 stencil layout (3D quadratic B-splines or uGIMP).
  pure logical function is_s27(basis)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    is_s27 = basis%layout == BASIS_B27 .or. basis%layout == BASIS_G27
  end function is_s27

  !> u_p = Σ_I N_Ip q_I (overwrite). With `c` and `v`, also v_p += c u_p in the same pass, block
  !> by block while u is in cache, as a separate y += c a over the particles would (a scheme's
  !> kick; skipped when c = 0).
  subroutine g2p_value(basis, q, u, c, v)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in), contiguous :: q(:,:)       !! nodal vectors (ndim, nnode)
    real(wp), intent(out), contiguous :: u(:,:)      !! particle vectors (ndim, np)
    real(wp), intent(in), optional :: c              !! scale of the kick
    real(wp), intent(inout), contiguous, optional :: v(:,:) !! kicked particle vectors (ndim, np)
    integer :: ic, nc, p0, p1, q0, q1, d
    real(wp) :: ck
    logical :: kick
    ck = 0.0_wp
    if (present(c)) ck = c
    kick = present(v) .and. ck /= 0.0_wp
    d = basis%ndim
    nc = empm_chunks(basis%np)
    !$omp parallel do num_threads(nc) schedule(static, 1) default(none) &
    !$omp   shared(basis, q, u, v, nc, ck, kick, d) private(p0, p1, q0, q1) if(nc > 1)
    do ic = 0, nc - 1
      call empm_chunk_bounds(basis%np, nc, ic, p0, p1)
      if (.not. kick) then
        call g2p_range(basis, q, p0, p1, .false., 0.0_wp, u)
        cycle
      end if
      do q0 = p0, p1, KICK_BLOCK
        q1 = min(p1, q0 + KICK_BLOCK - 1)
        call g2p_range(basis, q, q0, q1, .false., 0.0_wp, u)
        call axpy_flat(d * (q1 - q0 + 1), ck, u(:, q0:q1), v(:, q0:q1))
      end do
    end do
    !$omp end parallel do
  end subroutine g2p_value

  !> y += c a over n consecutive reals: the vectors of a range of particles, passed as contiguous
  !> sections (sequence association), so that the loop is flat and vectorises (over (ndim, np)
  !> arrays the inner loop over ndim took 18 instructions per entry).
  pure subroutine axpy_flat(n, c, a, y)
    integer, intent(in) :: n                 !! number of entries
    real(wp), intent(in) :: c                !! scale
    real(wp), intent(in) :: a(n)             !! vectors, flattened
    real(wp), intent(inout) :: y(n)          !! vectors, flattened
    integer :: i
    do i = 1, n
      y(i) = y(i) + c * a(i)
    end do
  end subroutine axpy_flat

  !> u(:, p) += c Σ_I N_Ip q_I for the particles p0..p1 only, without threads: the G2P of one
  !> block inside a caller's own threaded loop (e.g. a block that also forms the gradients),
  !> with the same arithmetic as [[g2p_add_scaled]].
  pure subroutine g2p_block(basis, c, q, p0, p1, u)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in) :: c                        !! scale
    real(wp), intent(in), contiguous :: q(:,:)       !! nodal vectors (ndim, nnode)
    integer, intent(in) :: p0                        !! first particle
    integer, intent(in) :: p1                        !! last particle
    real(wp), intent(inout), contiguous :: u(:,:)    !! particle vectors (ndim, >= p1)
    call g2p_range(basis, q, p0, p1, .true., c, u)
  end subroutine g2p_block

  !> The G2P of particles p0..p1, by layout and dimension: u_p += c Σ_I N_Ip q_I with `add`
  !> ([[g2p_block]]), u_p = Σ_I N_Ip q_I without it ([[g2p_value]]).
  pure subroutine g2p_range(basis, q, p0, p1, add, c, u)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in), contiguous :: q(:,:)       !! nodal vectors (ndim, nnode)
    integer, intent(in) :: p0                        !! first particle
    integer, intent(in) :: p1                        !! last particle (p1 < p0: nothing to do)
    logical, intent(in) :: add                       !! accumulate c Σ N q instead of overwriting
    real(wp), intent(in) :: c                        !! scale (with `add`)
    real(wp), intent(inout), contiguous :: u(:,:)    !! particle vectors (ndim, >= p1)
    real(wp) :: s(3)
    integer :: p, k, d
    d = basis%ndim
    if (p1 < p0) return
    if (basis%layout == BASIS_Q4) then
      call g2p_q4(basis%stride, p0, p1, basis%cell, basis%t, q, add, c, u)
    else if (basis%layout == BASIS_Q8) then
      call g2p_q8(basis%stride, basis%stride2, p0, p1, basis%cell, basis%t, q, add, c, u)
    else if (is_s9(basis)) then
      call g2p_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                  basis%layout == BASIS_G9, basis%wg, q, add, c, u)
    else if (is_s27(basis)) then
      call g2p_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                   basis%layout == BASIS_G27, basis%wg, q, add, c, u)
    else if (d == 2) then
      call g2p_2d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, q, add, c, u)
    else if (d == 3) then
      call g2p_3d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, q, add, c, u)
    else
      do p = p0, p1
        s(1:d) = 0.0_wp
        do k = 1, basis%nn(p)
          s(1:d) = s(1:d) + basis%N(k, p) * q(:, basis%node(k, p))
        end do
        if (add) then
          u(:, p) = u(:, p) + c * s(1:d)
        else
          u(:, p) = s(1:d)
        end if
      end do
    end if
  end subroutine g2p_range

  !> Add a scaled interpolated nodal vector: u_p += c Σ_I N_Ip q_I.
  subroutine g2p_add_scaled(basis, c, q, u)
    type(empm_basis_t), intent(in) :: basis          !! shape functions at the particles
    real(wp), intent(in) :: c                        !! scale (e.g. Δt)
    real(wp), intent(in), contiguous :: q(:,:)       !! nodal vectors (ndim, nnode)
    real(wp), intent(inout), contiguous :: u(:,:)    !! particle vectors (ndim, np)
    integer :: ic, nc, p0, p1
    nc = empm_chunks(basis%np)
    !$omp parallel do num_threads(nc) schedule(static, 1) default(none) &
    !$omp   shared(basis, c, q, u, nc) private(p0, p1) if(nc > 1)
    do ic = 0, nc - 1
      call empm_chunk_bounds(basis%np, nc, ic, p0, p1)
      call g2p_block(basis, c, q, p0, p1, u)
    end do
    !$omp end parallel do
  end subroutine g2p_add_scaled


  !> Velocity gradients L_p = Σ_I v_I ⊗ ∇N_Ip of particles p0..p1, into L(:, :, 1:p1-p0+1).
  !> Serial, for one block of particles inside a particle-parallel loop (the stress update
  !> calls it block by block, so L never leaves the cache). Only the ndim×ndim block of each
  !> L is written: zero `L` once before the first call.
  pure subroutine velocity_gradient(basis, v, p0, p1, L)
    type(empm_basis_t), intent(in) :: basis         !! shape functions at the particles
    real(wp), intent(in), contiguous :: v(:,:)      !! nodal velocities (ndim, nnode)
    integer, intent(in) :: p0                       !! first particle
    integer, intent(in) :: p1                       !! last particle (p1 < p0: nothing to do)
    real(wp), intent(inout), contiguous :: L(:,:,:) !! velocity gradients (3, 3, >= p1-p0+1)
    real(wp) :: g(3, 3)
    integer :: p, k, I, a, b, d
    d = basis%ndim
    if (p1 < p0) return
    if (basis%layout == BASIS_Q4) then
      call velocity_gradient_q4(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, v, L)
      return
    end if
    if (basis%layout == BASIS_Q8) then
      call velocity_gradient_q8(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                                v, L)
      return
    end if
    if (is_s9(basis)) then
      call velocity_gradient_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                                basis%layout == BASIS_G9, basis%wg, v, L)
      return
    end if
    if (is_s27(basis)) then
      call velocity_gradient_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, &
                                 basis%layout == BASIS_G27, basis%wg, v, L)
      return
    end if
    if (d == 2) then
      ! Element sequence association: the kernel sees particles p0..p1 as 1..p1-p0+1.
      call velocity_gradient_2d(basis%maxn, 1, p1 - p0 + 1, basis%nn(p0), basis%node(1, p0), &
                                basis%dN(1, 1, p0), v, L)
      return
    end if
    if (d == 3) then
      call velocity_gradient_3d(basis%maxn, 1, p1 - p0 + 1, basis%nn(p0), basis%node(1, p0), &
                                basis%dN(1, 1, p0), v, L)
      return
    end if
    do p = p0, p1
      ! Accumulate in registers, store once.
      g = 0.0_wp
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        do b = 1, d
          do a = 1, d
            g(a, b) = g(a, b) + v(a, I) * basis%dN(b, k, p)
          end do
        end do
      end do
      L(1:d, 1:d, p - p0 + 1) = g(1:d, 1:d)
    end do
  end subroutine velocity_gradient

  !> [[velocity_gradient]] and [[g2p_block]] of one nodal field in one pass over particles
  !> p0..p1: L_p = Σ_I v_I ⊗ ∇N_Ip into L(:, :, 1:p1-p0+1) and u_p += c Σ_I N_Ip v_I. The
  !> results are those of the two calls bit for bit (each sum keeps its order); the basis and
  !> the nodal values are read once instead of twice. Serial, for one block inside a
  !> particle-parallel loop; zero `L` once before the first call (only the ndim×ndim block is
  !> written).
  pure subroutine gradient_g2p_block(basis, v, p0, p1, L, c, u)
    type(empm_basis_t), intent(in) :: basis         !! shape functions at the particles
    real(wp), intent(in), contiguous :: v(:,:)      !! nodal velocities (ndim, nnode)
    integer, intent(in) :: p0                       !! first particle
    integer, intent(in) :: p1                       !! last particle (p1 < p0: nothing to do)
    real(wp), intent(inout), contiguous :: L(:,:,:) !! velocity gradients (3, 3, >= p1-p0+1)
    real(wp), intent(in) :: c                       !! scale of the interpolated velocity
    real(wp), intent(inout), contiguous :: u(:,:)   !! particle vectors (ndim, >= p1)
    if (p1 < p0) return
    if (basis%layout == BASIS_Q4) then
      call gradient_g2p_q4(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, v, L, c, u)
    else if (basis%layout == BASIS_Q8) then
      call gradient_g2p_q8(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, basis%t, v, L, &
                           c, u)
    else if (is_s9(basis)) then
      call gradient_g2p_s9(basis%stride, basis%inv_h, p0, p1, basis%cell, basis%t, &
                           basis%layout == BASIS_G9, basis%wg, v, L, c, u)
    else if (is_s27(basis)) then
      call gradient_g2p_s27(basis%stride, basis%stride2, basis%inv_h, p0, p1, basis%cell, &
                            basis%t, basis%layout == BASIS_G27, basis%wg, v, L, c, u)
    else if (basis%ndim == 2) then
      call gradient_g2p_2d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, basis%dN, v, L, &
                           c, u)
    else if (basis%ndim == 3) then
      call gradient_g2p_3d(basis%maxn, p0, p1, basis%nn, basis%node, basis%N, basis%dN, v, L, &
                           c, u)
    else
      call velocity_gradient(basis, v, p0, p1, L)
      call g2p_block(basis, c, v, p0, p1, u)
    end if
  end subroutine gradient_g2p_block

  !> out_I = q_I / m_I on nodes with mass above the empty-node threshold, 0 elsewhere; with
  !> nearly-empty nodes ([[empm_extension]]) their numerators are gathered into their stencils
  !> and they get the extrapolated values (`nodes%mass` then holds the gathered masses).
  subroutine nodal_divide_by_mass(nodes, q, out)
    type(empm_nodes_t), intent(in) :: nodes           !! nodal fields (mass, mass_tol)
    real(wp), intent(in), contiguous :: q(:,:)        !! nodal vectors (ndim, nnode)
    real(wp), intent(out), contiguous :: out(:,:)     !! q/m (ndim, nnode)
    integer :: I, d
    if (nodes%ndim == 2) then
      call divide_2d(nodes%nnode, nodes%mass, nodes%mass_tol, q, out)
      if (nodes%nmirror > 0) call nodes%mirror_correct(q, out)
      if (nodes%ext%n > 0) call nodes%ext%correct(nodes%mass, q, out)
      return
    end if
    !$omp parallel do schedule(static) default(none) shared(nodes, q, out) private(d) &
    !$omp   if(nodes%nnode >= EMPM_OMP_MIN_PARTICLES)
    do I = 1, nodes%nnode
      if (nodes%mass(I) > nodes%mass_tol) then
        do d = 1, nodes%ndim
          out(d, I) = q(d, I) / nodes%mass(I)
        end do
      else
        do d = 1, nodes%ndim
          out(d, I) = 0.0_wp
        end do
      end if
    end do
    !$omp end parallel do
    if (nodes%nmirror > 0) call nodes%mirror_correct(q, out)
    if (nodes%ext%n > 0) call nodes%ext%correct(nodes%mass, q, out)
  end subroutine nodal_divide_by_mass

  !> [[nodal_divide_by_mass]] in 2D (pairs in registers; the same divisions).
  subroutine divide_2d(n, mass, tol, q, out)
    integer, intent(in) :: n             !! number of nodes
    real(wp), intent(in) :: mass(n)      !! nodal masses
    real(wp), intent(in) :: tol          !! empty-node mass threshold
    real(wp), intent(in) :: q(2, n)      !! nodal vectors
    real(wp), intent(out) :: out(2, n)   !! q/m
    integer :: I
    !$omp parallel do schedule(static) default(none) shared(n, mass, tol, q, out) &
    !$omp   if(n >= EMPM_OMP_MIN_PARTICLES)
    do I = 1, n
      if (mass(I) > tol) then
        out(:, I) = q(:, I) / mass(I)
      else
        out(:, I) = 0.0_wp
      end if
    end do
    !$omp end parallel do
  end subroutine divide_2d
end module empm_transfer
