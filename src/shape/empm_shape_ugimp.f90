!> Uniform GIMP shape functions (Bardenhagen & Kober 2004), "undeformed" variant.
!>
!> The particle's characteristic function (a box of half-lengths `lp`, the initial half-size,
!> kept constant) convolved with the linear hat. In 1D, with ξ = x − x_I, r = |ξ|:
!>
!>   S = 1 − (ξ² + lp²)/(2 h lp)      for r < lp
!>   S = 1 − r/h                      for lp ≤ r ≤ h − lp
!>   S = (h + lp − r)²/(4 h lp)       for h − lp < r < h + lp
!>
!> and 0 beyond; in 2D and 3D the tensor product. S is C¹. The formulas hold for
!> 0 ≤ lp ≤ h/2 (at most 3 nodes per direction); lp = 0 gives the linear hat.
!>
!> Status codes specific to this family:
!> - `SHAPE_TOO_MANY_NODES` when some lp_d > h_d/2 (the support would need 4 nodes per
!>   direction, more than `max_nodes`), or lp_d is negative or not a number;
!> - `SHAPE_SUPPORT_CLIPPED` when the particle domain reaches past the grid box
!>   (x_d − lp_d < origin_d or x_d + lp_d > upper_d, beyond a round-off tolerance): pad the grid.
!>
!> Only nodes with a nonzero value are returned, so a point whose fractional cell position t
!> (per direction, in [0,1)) and L = lp/h satisfy L ≤ t ≤ 1 − L has 2 nodes in that direction,
!> otherwise 3.
!>
!> **Compact layout.** On 2D and 3D grids the family fills `BASIS_G9` / `BASIS_G27` (per
!> particle the first node of its 3^ndim stencil and the 3 values and slopes per direction,
!> computed once a step; [[empm_basis_t]]), whose transfers form their products
!> ([[empm_transfer_s9]], [[empm_transfer_s27]]). A particle the layout cannot hold (a stencil node beyond the grid,
!> or lp outside (0, h/2]) turns the storage into node lists, once, with their results and
!> failures.
module empm_shape_ugimp
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES
  use empm_shape, only: empm_shape_t, empm_basis_t, SHAPE_OK, SHAPE_OUTSIDE_GRID, &
                        SHAPE_SUPPORT_CLIPPED, SHAPE_TOO_MANY_NODES, BASIS_LISTS, BASIS_G9, &
                        BASIS_G27
  use empm_shape_linear, only: SHAPE_TP_MAXM, SHAPE_CLIP_TOL, shape_tp_init, shape_tp_assemble, &
                               shape_batch_fits, shape_keep_first_failure, shape_tp_store, &
                               shape_stencil_batch
  implicit none
  private
  public :: empm_shape_ugimp_t, shape_ugimp_kernel

  !> Relative tolerance on lp ≤ h/2, so that lp computed as h/2 in another way is accepted.
  real(wp), parameter :: LP_TOL = 1.0e-12_wp

  !> Uniform GIMP shape functions (tensor product), using the particle half-lengths `lp`.
  type, extends(empm_shape_t) :: empm_shape_ugimp_t
  contains
    procedure :: max_nodes => ugimp_max_nodes
    procedure :: eval_point => ugimp_eval_point
    procedure :: eval_batch => ugimp_eval_batch
    procedure :: name => ugimp_name
    procedure :: family => ugimp_family
    procedure :: summary => ugimp_summary
    procedure :: padding_cells => ugimp_padding_cells
    procedure :: layout => ugimp_layout
  end type empm_shape_ugimp_t

contains

  !> Upper bound on supporting nodes: 3^ndim (valid for lp ≤ h/2).
  pure integer function ugimp_max_nodes(self, grid)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid         !! background grid
    associate (unused_ => self); end associate
    ugimp_max_nodes = 3**grid%ndim
  end function ugimp_max_nodes

  !> Registry name of the family.
  pure function ugimp_family(self) result(s)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s            !! name
    associate (unused_ => self); end associate
    s = 'ugimp'
  end function ugimp_family

  !> One-line description of the family.
  pure function ugimp_summary(self) result(s)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s            !! summary
    associate (unused_ => self); end associate
    s = 'uniform GIMP (Bardenhagen & Kober 2004): the linear hat convolved with the particle '// &
        'box, C¹, up to 3 nodes per direction; one padding cell'
  end function ugimp_summary

  !> Padding cells: 1 (a particle domain reaching past the grid box is SHAPE_SUPPORT_CLIPPED).
  pure integer function ugimp_padding_cells(self) result(n)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    associate (unused_ => self); end associate
    n = 1
  end function ugimp_padding_cells

  !> Family identifier: "ugimp".
  function ugimp_name(self) result(s)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s            !! identifier
    associate (unused_ => self); end associate
    s = 'ugimp'
  end function ugimp_name

  !> Values and gradients at one point with particle half-lengths `lp` (`lam` is not used).
  subroutine ugimp_eval_point(self, grid, x, lp, lam, nn, node, N, dN, info)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid         !! background grid
    real(wp), intent(in) :: x(:)                  !! point (ndim)
    real(wp), intent(in) :: lp(:)                 !! particle half-lengths (ndim), 0 ≤ lp ≤ h/2
    real(wp), intent(inout) :: lam(:)             !! iterative state (unused, unchanged)
    integer, intent(out) :: nn                    !! number of supporting nodes
    integer, intent(out) :: node(:)               !! supporting node indices
    real(wp), intent(out) :: N(:)                 !! values
    real(wp), intent(out) :: dN(:,:)              !! gradients (ndim, :)
    integer, intent(out) :: info                  !! SHAPE_OK or a SHAPE_* failure code
    associate (unused_ => self, unused_lam_ => lam); end associate
    call shape_ugimp_kernel(grid, x, lp, nn, node, N, dN, info)
  end subroutine ugimp_eval_point

  !> Values and gradients at particles 1..pts%np, with `pts%lp`; stops at the first failure.
  subroutine ugimp_eval_batch(self, grid, pts, basis, ibad, info)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid         !! background grid
    type(empm_particles_t), intent(inout) :: pts  !! particles (unchanged)
    type(empm_basis_t), intent(inout) :: basis    !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                  !! first failing particle, 0 if none
    integer, intent(out) :: info                  !! SHAPE_OK or the failing particle's code
    integer :: p, pinfo
    real(wp) :: w(3, 3), g(3, 3)
    integer :: m(3), base(3), d
    call shape_batch_fits(pts%np, basis, ibad, info, compact=self%layout(grid))
    if (info /= SHAPE_OK) return
    if (basis%layout /= BASIS_LISTS) then
      ! BASIS_G9 or BASIS_G27 (shape_batch_fits admits no other). Done, unless a particle
      ! cannot be held: then node lists, evaluated below.
      if (shape_stencil_batch(grid, pts, .true., 0.5_wp * (1.0_wp + LP_TOL), basis, ibad, info)) &
        return
    end if
    ! Particles are independent: threads share them; the first failure (lowest index) is kept.
    ibad = huge(1)
    if (grid%ndim >= 2 .and. size(basis%dN, 1) >= grid%ndim) then
      ! The kernel's steps written out (the same arithmetic, bitwise: test_bspline_fast):
      ! no per-particle call, work arrays or per-node index checks.
      !$omp parallel do default(none) schedule(static) shared(grid, pts, basis, ibad, info) &
      !$omp   private(pinfo, m, base, w, g, d) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
      do p = 1, pts%np
        if (.not. grid%inside(pts%x(:, p))) then
          basis%nn(p) = 0
          call shape_keep_first_failure(p, SHAPE_OUTSIDE_GRID, ibad, info); cycle
        end if
        m(3) = 1; base(3) = 0; w(1, 3) = 1.0_wp; g(1, 3) = 0.0_wp
        pinfo = SHAPE_OK
        do d = 1, grid%ndim
          call ugimp_1d(grid, d, pts%x(d, p), pts%lp(d, p), m(d), base(d), w(:, d), g(:, d), &
                        pinfo)
          if (pinfo /= SHAPE_OK) exit
        end do
        if (pinfo == SHAPE_OK) call shape_tp_store(grid, m, base, w, g, basis, p, pinfo)
        if (pinfo /= SHAPE_OK) then
          basis%nn(p) = 0
          call shape_keep_first_failure(p, pinfo, ibad, info)
        end if
      end do
      !$omp end parallel do
    else
      !$omp parallel do default(none) schedule(static) shared(grid, pts, basis, ibad, info) &
      !$omp   private(pinfo) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
      do p = 1, pts%np
        call shape_ugimp_kernel(grid, pts%x(:, p), pts%lp(:, p), basis%nn(p), &
                                basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), pinfo)
        if (pinfo /= SHAPE_OK) call shape_keep_first_failure(p, pinfo, ibad, info)
      end do
      !$omp end parallel do
    end if
    if (ibad == huge(1)) ibad = 0
  end subroutine ugimp_eval_batch

  !> Basis layout: BASIS_G9 on a 2D grid, BASIS_G27 on a 3D one (the first node of the 3^ndim
  !> stencil and the stored 1D factors per particle), node lists otherwise.
  pure integer function ugimp_layout(self, grid)
    class(empm_shape_ugimp_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid         !! background grid
    associate (unused_ => self); end associate
    ugimp_layout = BASIS_LISTS
    if (grid%ndim == 2) ugimp_layout = BASIS_G9
    if (grid%ndim == 3) ugimp_layout = BASIS_G27
  end function ugimp_layout

  !> uGIMP shape functions at one point; only nodes with a nonzero value are returned,
  !> in increasing index order.
  pure subroutine shape_ugimp_kernel(grid, x, lp, nn, node, N, dN, info)
    type(empm_grid_t), intent(in) :: grid !! background grid
    real(wp), intent(in) :: x(:)          !! point (ndim)
    real(wp), intent(in) :: lp(:)         !! particle half-lengths (ndim), 0 ≤ lp ≤ h/2
    integer, intent(out) :: nn            !! number of supporting nodes (0 on failure)
    integer, intent(out) :: node(:)       !! supporting node indices (capacity >= 3^ndim)
    real(wp), intent(out) :: N(:)         !! values
    real(wp), intent(out) :: dN(:,:)      !! gradients (ndim, :)
    integer, intent(out) :: info          !! SHAPE_OK or a SHAPE_* failure code (see module)
    integer :: m(3), base(3), d
    real(wp) :: w(SHAPE_TP_MAXM, 3), g(SHAPE_TP_MAXM, 3)
    nn = 0
    if (grid%ndim < 1) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    if (.not. grid%inside(x)) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    call shape_tp_init(m, base, w, g)
    do d = 1, grid%ndim
      call ugimp_1d(grid, d, x(d), lp(d), m(d), base(d), w(:, d), g(:, d), info)
      if (info /= SHAPE_OK) return
    end do
    call shape_tp_assemble(grid, m, base, w, g, nn, node, N, dN, info)
  end subroutine shape_ugimp_kernel

  !> 1D uGIMP factors along direction `d`: the nodes with a nonzero value (2 or 3).
  pure subroutine ugimp_1d(grid, d, xd, lpd, m, base, w, g, info)
    type(empm_grid_t), intent(in) :: grid !! background grid
    integer, intent(in) :: d              !! direction
    real(wp), intent(in) :: xd            !! coordinate of the point (inside the grid)
    real(wp), intent(in) :: lpd           !! particle half-length along d
    integer, intent(out) :: m             !! number of nodes
    integer, intent(out) :: base          !! 0-based index of the first node
    real(wp), intent(out) :: w(:)         !! values
    real(wp), intent(out) :: g(:)         !! derivatives with respect to x_d
    integer, intent(out) :: info          !! SHAPE_OK, SHAPE_TOO_MANY_NODES, SHAPE_SUPPORT_CLIPPED
    real(wp) :: s, el, u, r, ih
    integer :: c, i, k
    m = 0
    base = 0
    ih = grid%inv_h(d)
    ! Work in grid units: s = position, el = lp/h, u = signed distance from the node.
    el = lpd * ih
    if (.not. (el >= 0.0_wp .and. el <= 0.5_wp * (1.0_wp + LP_TOL))) then
      info = SHAPE_TOO_MANY_NODES; return
    end if
    el = min(el, 0.5_wp)
    s = (xd - grid%origin(d)) * ih
    if (el == 0.0_wp) then
      ! Degenerate case: the linear hat, whose derivative at a node needs a cell choice
      ! (the formulas below would give a lone node with nonzero slope).
      c = min(max(floor(s), 0), grid%ncell(d) - 1)
      u = min(max(s - c, 0.0_wp), 1.0_wp)
      m = 2; base = c
      w(1) = 1.0_wp - u; w(2) = u
      g(1) = -ih; g(2) = ih
      info = SHAPE_OK
      return
    end if
    ! The nearest node c has |s − c| ≤ 1/2, so every node within 1 + el ≤ 3/2 of s is one of
    ! c−1, c, c+1. Dropped candidates are always at the ends, so the kept nodes are contiguous.
    c = nint(s)
    do k = -1, 1
      i = c + k
      u = s - i
      r = abs(u)
      if (r >= 1.0_wp + el) cycle
      if (i < 0 .or. i > grid%ncell(d)) then
        if (r < 1.0_wp + el - SHAPE_CLIP_TOL) then
          info = SHAPE_SUPPORT_CLIPPED; return
        end if
        cycle
      end if
      if (m == 0) base = i
      m = m + 1
      if (r < el) then
        w(m) = 1.0_wp - (u * u + el * el) / (2.0_wp * el)
        g(m) = -u / el * ih
      else if (r <= 1.0_wp - el) then
        w(m) = 1.0_wp - r
        g(m) = -sign(1.0_wp, u) * ih
      else
        w(m) = (1.0_wp + el - r)**2 / (4.0_wp * el)
        g(m) = -sign(1.0_wp, u) * (1.0_wp + el - r) / (2.0_wp * el) * ih
      end if
    end do
    info = SHAPE_OK
  end subroutine ugimp_1d
end module empm_shape_ugimp
