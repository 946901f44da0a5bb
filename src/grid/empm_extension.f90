!> Extension of nearly-empty nodes (docs/free-surfaces.md).
!>
!> A node whose support holds only a sliver of the body (a free surface just past it) gets a
!> lumped mass and an internal force that are both tiny and dominated by one or two particles
!> at the edge of its support: a_I = f_I/m_I is then an inconsistent, O(1) boundary value that
!> the particles near the surface pick up, and spatial convergence is lost (the vibrating bar
!> with LME, a free end past a grid line). The rule, the same for every shape family: a node
!> is *degenerate* when the body fills less than `theta` of its support,
!>
!>     φ_I = Σ_p N_Ip V_p / h^d < θ,
!>
!> and it has no fixed dof (nor is a mirror plane's image node). Its value is extrapolated linearly from the nearest free, well-filled
!> node J (Euclidean distance in grid steps, then the largest φ, equal to 1e-12 relative
!> counting as a tie that node order breaks) and J's free neighbour one step
!> further into the body along each direction of the offset,
!> v_I = (1 + Σ|o_d|) v_J − Σ |o_d| v_{J − sgn(o_d) e_d}, o = I − J (grid steps): linear fields
!> stay exact, as in the extended B-splines of Höllig. The lumped system is the one of that
!> extended basis: masses and the numerators of every nodal division are gathered with the
!> transposed coefficients (m̂ = Eᵀm), the divisions are done on the other nodes, and the
!> degenerate nodes then get their extrapolated values (v = E v̂). The switch is sharp (a
!> partial share kept by nodes filled just under θ brings the failure back: measured on the
!> free end ¼ of a cell past a grid line). A stencil that would take more than half of a
!> neighbour's mass falls back to the constant extension v_I = v_J; a node with no usable node
!> within `REACH` steps (a small fragment) stays an ordinary node.
module empm_extension
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  implicit none
  private
  public :: empm_extension_t, EXT_MAXST, EXT_THETA_DEFAULT

  integer, parameter :: EXT_MAXST = 4 !! stencil entries per degenerate node (1 + ndim)
  integer, parameter :: REACH = 3     !! grid steps searched for a well-filled node
  real(wp), parameter :: TIE = 1.0e-12_wp !! fills closer than this (relative) are equal
  real(wp), parameter :: EXT_THETA_DEFAULT = 0.1_wp !! default fill fraction (`&grid min_fill`)

  !> The degenerate nodes of the current basis and their extrapolation stencils.
  type :: empm_extension_t
    real(wp) :: theta = EXT_THETA_DEFAULT !! fill fraction below which a node is degenerate
                                          !! (0: no extension)
    integer :: n = 0                      !! degenerate nodes of the current basis
    integer, allocatable :: node(:)       !! their indices (n)
    integer, allocatable :: ns(:)         !! stencil sizes (n)
    integer, allocatable :: sn(:,:)       !! stencil nodes (EXT_MAXST, n)
    real(wp), allocatable :: sc(:,:)      !! stencil coefficients (EXT_MAXST, n), sum 1
    logical, allocatable :: deg(:)        !! degenerate flag per node (nnode)
    real(wp), allocatable :: mh(:)        !! scratch: gathered masses (nnode)
  contains
    procedure :: init => ext_init
    procedure :: find => ext_find
    procedure :: gather_mass => ext_gather_mass
    procedure :: correct => ext_correct
    procedure :: scatter => ext_scatter
  end type empm_extension_t

contains

  !> Size the per-node flags for `nnode` nodes (set-up only); no degenerate node.
  subroutine ext_init(self, nnode)
    class(empm_extension_t), intent(inout) :: self !! extension
    integer, intent(in) :: nnode                   !! number of grid nodes
    if (allocated(self%deg)) deallocate(self%deg, self%mh)
    allocate(self%deg(nnode), self%mh(nnode))
    self%deg = .false.; self%mh = 0.0_wp
    self%n = 0
    if (.not. allocated(self%node)) allocate(self%node(0), self%ns(0), self%sn(EXT_MAXST, 0), &
      self%sc(EXT_MAXST, 0))
  end subroutine ext_init

  !> Find the degenerate nodes and their stencils from the nodal masses and filled volumes of
  !> a new basis. `fixed(d, I)`: dof d of node I is prescribed. The lists grow only when a basis
  !> has more degenerate nodes than any before (no allocation in a steady run).
  subroutine ext_find(self, grid, mass, vol, mass_tol, fixed, keep)
    class(empm_extension_t), intent(inout) :: self !! extension
    type(empm_grid_t), intent(in) :: grid          !! background grid
    real(wp), intent(in) :: mass(:)                !! lumped nodal masses (nnode) [kg]
    real(wp), intent(in) :: vol(:)                 !! filled volumes Σ N_Ip V_p (nnode) [m^d]
    real(wp), intent(in) :: mass_tol               !! lighter nodes are empty [kg]
    logical, intent(in) :: fixed(:,:)              !! Dirichlet mask (ndim, nnode)
    logical, intent(in) :: keep(:)                 !! nodes never degenerate (mirror images,
                                                   !! whose ghosts take their values) (nnode)
    real(wp) :: vcut, best
    integer :: I, J, K, c, nd, r, ijk(3), q(3), o(3), lo(3), hi(3), a, b, e, cnt, dist, dbest
    nd = grid%ndim
    self%n = 0
    if (self%theta <= 0.0_wp) return
    vcut = self%theta * product(grid%h(1:nd))
    cnt = 0
    do I = 1, grid%nnode
      self%deg(I) = mass(I) > mass_tol .and. vol(I) < vcut .and. .not. any(fixed(:, I)) &
                    .and. .not. keep(I)
      if (self%deg(I)) cnt = cnt + 1
    end do
    if (cnt == 0) return
    if (size(self%node) < cnt) then
      deallocate(self%node, self%ns, self%sn, self%sc)
      allocate(self%node(cnt), self%ns(cnt), self%sn(EXT_MAXST, cnt), self%sc(EXT_MAXST, cnt))
    end if
    do I = 1, grid%nnode
      if (.not. self%deg(I)) cycle
      ijk = grid%node_ijk(I)
      ! Anchor: the nearest usable node (Euclidean distance in grid steps, within the square
      ! of half-width r), the best-filled one among equally near ones: a node above a flat
      ! surface extends along the normal.
      J = 0; best = -1.0_wp; dbest = huge(1)
      do r = 1, REACH
        lo = 0; hi = 0
        lo(1:nd) = max(ijk(1:nd) - r, 0); hi(1:nd) = min(ijk(1:nd) + r, grid%nn(1:nd) - 1)
        do c = lo(3), hi(3)
          do b = lo(2), hi(2)
            do a = lo(1), hi(1)
              q = [a, b, c]
              if (maxval(abs(q - ijk)) /= r) cycle
              K = grid%node_id(q)
              if (.not. usable(K)) cycle
              dist = sum((q - ijk)**2)
              ! "Better filled" beyond round-off only: equally filled nodes (a symmetric
              ! body) must not be told apart by the last bits of their sums, which depend on
              ! the summation order (threads, processes); the first in node order wins.
              if (dist < dbest .or. (dist == dbest .and. vol(K) > best + TIE * abs(best))) then
                J = K; best = vol(K); dbest = dist
              end if
            end do
          end do
        end do
        if (J > 0) exit
      end do
      if (J == 0) then
        self%deg(I) = .false.; cycle   ! a fragment: no well-filled node near it
      end if
      self%n = self%n + 1
      e = self%n
      self%node(e) = I
      self%ns(e) = 1; self%sn(1, e) = J; self%sc(1, e) = 1.0_wp
      o = ijk - grid%node_ijk(J)
      q = grid%node_ijk(J)
      do a = 1, nd
        if (o(a) == 0) cycle
        ! One step further into the body along direction a.
        lo = q; lo(a) = q(a) - sign(1, o(a))
        if (lo(a) < 0 .or. lo(a) > grid%nn(a) - 1) cycle
        K = grid%node_id(lo)
        if (.not. usable(K)) cycle
        self%ns(e) = self%ns(e) + 1
        self%sn(self%ns(e), e) = K; self%sc(self%ns(e), e) = -real(abs(o(a)), wp)
        self%sc(1, e) = self%sc(1, e) + abs(o(a))
      end do
    end do
    ! A neighbour must keep at least half its own mass after the gather (m̂ > 0 with margin).
    do e = 1, self%n
      do a = 1, self%ns(e)
        self%mh(self%sn(a, e)) = mass(self%sn(a, e))
      end do
    end do
    do e = 1, self%n
      do a = 1, self%ns(e)
        K = self%sn(a, e)
        self%mh(K) = self%mh(K) + self%sc(a, e) * mass(self%node(e))
      end do
    end do
    do e = 1, self%n
      do a = 2, self%ns(e)
        K = self%sn(a, e)
        if (self%mh(K) < 0.5_wp * mass(K)) then
          self%ns(e) = 1; self%sc(1, e) = 1.0_wp; exit
        end if
      end do
    end do
  contains
    ! Stencil nodes are free: a degenerate node next to a prescribed boundary (a footing, a
    ! wall) must not be tied to the boundary's motion. Node 0: not stored (beyond a parallel
    ! process's window, where its particles read nothing).
    logical function usable(node)
      integer, intent(in) :: node
      usable = .false.
      if (node == 0) return
      usable = mass(node) > mass_tol .and. .not. self%deg(node) .and. .not. any(fixed(:, node))
    end function usable
  end subroutine ext_find

  !> m̂ = Eᵀm: each degenerate node's mass goes to its stencil, and its own becomes zero (it is
  !> no longer an unknown; divisions skip it).
  subroutine ext_gather_mass(self, mass)
    class(empm_extension_t), intent(in) :: self !! extension
    real(wp), intent(inout) :: mass(:)          !! lumped nodal masses (nnode) [kg]
    integer :: e, k, I
    do e = 1, self%n
      I = self%node(e)
      do k = 1, self%ns(e)
        mass(self%sn(k, e)) = mass(self%sn(k, e)) + self%sc(k, e) * mass(I)
      end do
      mass(I) = 0.0_wp
    end do
  end subroutine ext_gather_mass

  !> After out = q/m̂ on the other nodes: add the gathered numerators of the degenerate nodes,
  !> out_J += c q_I/m̂_J (stencil nodes are free), then give the degenerate nodes their
  !> extrapolated values.
  subroutine ext_correct(self, mass, q, out)
    class(empm_extension_t), intent(in) :: self !! extension
    real(wp), intent(in) :: mass(:)             !! gathered masses m̂ (nnode) [kg]
    real(wp), intent(in) :: q(:,:)              !! numerators (ndim, nnode)
    real(wp), intent(inout) :: out(:,:)         !! q/m̂ (ndim, nnode)
    integer :: e, k, J
    do e = 1, self%n
      do k = 1, self%ns(e)
        J = self%sn(k, e)
        out(:, J) = out(:, J) + self%sc(k, e) * q(:, self%node(e)) / mass(J)
      end do
    end do
    call self%scatter(out)
  end subroutine ext_correct

  !> v_I = Σ_k c_k v_{J_k} at the degenerate nodes.
  subroutine ext_scatter(self, v)
    class(empm_extension_t), intent(in) :: self !! extension
    real(wp), intent(inout) :: v(:,:)           !! nodal vectors (ndim, nnode)
    integer :: e, k, I
    do e = 1, self%n
      I = self%node(e)
      v(:, I) = 0.0_wp
      do k = 1, self%ns(e)
        v(:, I) = v(:, I) + self%sc(k, e) * v(:, self%sn(k, e))
      end do
    end do
  end subroutine ext_scatter
end module empm_extension
