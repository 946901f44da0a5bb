!> Local maximum-entropy (LME) shape functions (Arroyo & Ortiz 2006; docs/algorithms.md §1).
!>
!> For a point x and candidate nodes a, with ξ_a = (x − x_a)/h and γ = β h² (dimensionless):
!>
!>   f_a(λ) = −γ_a |ξ_a|² + λ·ξ_a,   p_a = exp(f_a − log Z),   log Z = log Σ_b exp(f_b),
!>   r(λ) = Σ p_a ξ_a,   J(λ) = Σ p_a ξ_a⊗ξ_a − r⊗r   (gradient and Hessian of log Z).
!>
!> λ* minimises the convex log Z. All of this is done in units of h (λ here is λ_phys·h), so
!> every tolerance is dimensionless; `lam` values passed in and out are physical (1/length).
!> log Z is evaluated with the shift by max_b f_b, so exp never overflows.
!>
!> **h and the support.** h is the largest grid spacing (all benchmark grids are uniform). A node
!> is a candidate when γ_a |ξ_a|² ≤ −ln tol0, i.e. it lies within its radius
!> R_a = h·sqrt(−ln tol0/γ_a); with uniform γ, R = h·sqrt(−ln tol0/γ). Candidates are found
!> through the grid (cell binning): the index box of the lattice nodes within R_max of x,
!> filtered by distance. [[empm_shape_t:max_nodes]] counts the lattice nodes within R_max of any
!> point of one cell: a safe bound for every point.
!>
!> **Newton.** From the warm start λ (the particle's previous value), Newton steps
!> Δ = −J⁻¹ r (closed-form inverse, d ≤ 3, of J scaled to unit norm, with a conditioning
!> check), the step length capped at `LME_STEP_MAX`, and Armijo backtracking on log Z while
!> |r| > `LME_TOL_GUARD`, full steps after (backtracking all the way stalls on round-off).
!> Converged when |r| < `LME_TOL_CONV`, i.e. ‖r_phys‖/h < 1e-10. The moments r and J are
!> accumulated about ξ of the heaviest node, so that J has no cancellation when one node carries
!> nearly all the weight (large γ far from λ*, where J is tiny but well conditioned).
!>
!> **Final linearised step.** With Δ = −J⁻¹r at convergence, p̃_a = p_a (1 + (ξ_a − r)·Δ) is p
!> at λ + Δ to first order (error O(|Δ|²) < 1e-18), costs no exponential, and makes Σp̃ = 1 and
!> Σ p̃ ξ = 0 (linear reproduction) hold to round-off instead of to the tolerance 1e-10. It is
!> skipped when some factor 1 + (ξ_a − r)·Δ could fall below 1/2 (points within ~1e-9 h of the
!> hull boundary), where reproduction then holds to 1e-10 h. The returned p are the p̃, and
!> r, J below are their moments (r ≈ 1e-16).
!>
!> **2D batch path.** `eval_batch` in 2D with uniform γ uses [[lme_point_2d]]: the same
!> algorithm in three passes over the support, stopping Newton early when a bound proves the
!> residual after the final step below the tolerance, with values made exactly consistent by a
!> 2×2 solve (docs/shape-functions.md, "The 2D batch path"); anything unusual falls back to the
!> general path above.
!>
!> **Gradient.** With uniform γ: ∇p_a = −p_a J⁻¹ (ξ_a − r)/h, which equals −p_a J⁻¹ l_a at the
!> exact λ* (r = 0); keeping −r makes Σ∇p_a = 0 and Σ x_a⊗∇p_a = I hold to round-off. With
!> node-wise γ_a (β_a = γ_a/h²), f_a = −γ_a|ξ_a|² + λ·ξ_a; differentiate r(x, λ*(x)) = 0
!> (∂ξ_a/∂x = I/h): ∂r/∂x|_λ = (I − 2B)/h with B = Σ_b p_b γ_b ξ_b⊗ξ_b, so
!> ∂λ*/∂x = −J⁻¹(I − 2B)/h, and ∇p_a = p_a(∇f_a − Σ_b p_b ∇f_b) with
!> ∇f_a = (−2γ_a ξ_a + λ)/h + (∂λ*/∂x)ᵀ ξ_a gives
!>
!>   ∇p_a = p_a [ −J⁻¹ξ_a + 2 (B J⁻¹ ξ_a − γ_a ξ_a + m) ] / h,   m = Σ_b p_b γ_b ξ_b.
!>
!> The extra terms 2(B J⁻¹ξ_a − γ_a ξ_a + m) vanish for uniform γ (B = γJ, m = γr = 0). The
!> code uses ξ_a − r in place of ξ_a in the J⁻¹ terms, as above; Σ∇p_a = 0 then holds to
!> round-off, and Σ x_a⊗∇p_a = I to O(|r|γ), i.e. to round-off as well with the p̃ above.
!>
!> **Failures** (never NaN; on failure nn = 0 and `lam` is left unchanged):
!> - `SHAPE_OUTSIDE_GRID`: x is outside the closed grid box;
!> - `SHAPE_OUTSIDE_HULL`: x is not inside the convex hull of its candidates. Detected directly
!>   (fewer than d+1 candidates, x outside their bounding box, or candidates in a hyperplane:
!>   e.g. large γ in 3D, where only coplanar nodes lie within R) or during Newton: log Z fell
!>   below −max_a γ_a|ξ_a|², a lower bound of log Z(λ*) (log Z* = H(p*) − Σ p*γ_a|ξ_a|²), or
!>   |λ| exceeded `LME_LAM_MAX` (λ diverges), or, when J turns singular or the iteration cap is
!>   hit, λ·ξ_a < 0 for all a (−λ separates x from the nodes) or, for at most
!>   `HULL_TEST_MAXN` candidates, no simplex of d+1 candidates contains x (Carathéodory);
!> - `SHAPE_SUPPORT_CLIPPED`: OUTSIDE_HULL when some lattice node within R_max lies beyond the
!>   grid. On a box grid with uniform γ this does not happen (a node beyond a face has a mirror
!>   image inside the grid that is closer to x); it can with node-wise γ;
!> - `SHAPE_SINGULAR`: J singular or ill-conditioned (Frobenius condition > `LME_COND_MAX`, or
!>   ‖J‖ < `LME_J_MIN` at convergence) at a point not shown to be outside the hull, e.g. large
!>   γ (≳ 30 in 2D) at a point on a grid line, where the weights off the line fall below 1e-13;
!> - `SHAPE_NOT_CONVERGED`: `max_iter` Newton steps without convergence, or no Armijo step;
!> - `SHAPE_TOO_MANY_NODES`: the storage is smaller than the support, or invalid parameters
!>   (γ ≤ 0, tol0 outside (0, 1), max_iter < 1, node-wise γ of the wrong size).
!>
!> **Grid boundary.** Nodes beyond the grid do not exist: they are simply not candidates. LME
!> only needs x inside the hull of the existing candidates, which holds for every point of the
!> grid box whenever R covers its cell's corners (γ ≤ 4 with tol0 = 1e-6 in every dimension).
!> Near the boundary Newton needs more iterations (≈ ln(1/ε) at distance εh: 14–23 at ε = 0)
!> and cond(J) grows like 0.7/ε; points exactly on the boundary converge to the face's LME (p of
!> the nodes off the face ~ 1e-10). No padding is needed for LME; particles must stay inside the
!> grid (else OUTSIDE_GRID).
!>
!> **Remedy** (`remedy = LME_REMEDY_ENLARGE`): a point that fails with OUTSIDE_HULL,
!> SUPPORT_CLIPPED, SINGULAR or NOT_CONVERGED is re-evaluated from λ = 0 with every γ (uniform
!> and node-wise) halved, then quartered (R grows by √2, then 2); the first success is kept.
!> This cures supports that are too small (large γ). That particle's basis is then the LME of a
!> smaller γ: still a partition of unity with linear reproduction, so mass and momentum are
!> conserved. `max_nodes` accounts for the largest support. With `LME_REMEDY_NONE` (default) the
!> failure is returned and the solver stops, naming the particle, its position and the reason.
module empm_shape_lme
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES
  use empm_shape, only: empm_shape_t, empm_basis_t, SHAPE_OK, SHAPE_OUTSIDE_GRID, &
                        SHAPE_SUPPORT_CLIPPED, SHAPE_NOT_CONVERGED, SHAPE_OUTSIDE_HULL, &
                        SHAPE_SINGULAR, SHAPE_TOO_MANY_NODES
  use empm_shape_linear, only: shape_batch_fits, shape_keep_first_failure
  implicit none
  private
  public :: empm_shape_lme_t, lme_kernel, lme_support_radius, lme_format_gamma
  public :: LME_REMEDY_NONE, LME_REMEDY_ENLARGE, LME_REMEDY_TRIES, LME_REMEDY_FACTOR
  public :: LME_TOL_CONV, LME_TOL_GUARD, LME_COND_MAX, LME_J_MIN, LME_STEP_MAX, LME_LAM_MAX
  public :: LME_MAXIT_DEFAULT

  integer, parameter :: LME_REMEDY_NONE = 0     !! return the failure (the solver stops)
  integer, parameter :: LME_REMEDY_ENLARGE = 1  !! retry with smaller γ (larger support)
  integer, parameter :: LME_REMEDY_TRIES = 2    !! retries of the 'enlarge' remedy
  real(wp), parameter :: LME_REMEDY_FACTOR = 0.5_wp !! γ multiplier per retry
  real(wp), parameter :: LME_TOL_CONV = 1.0e-10_wp  !! convergence: ‖r‖/h below this
  real(wp), parameter :: LME_TOL_GUARD = 1.0e-4_wp  !! Armijo backtracking while ‖r‖/h above this
  real(wp), parameter :: LME_COND_MAX = 1.0e12_wp   !! largest accepted Frobenius condition of J
  real(wp), parameter :: LME_J_MIN = 1.0e-14_wp     !! smallest accepted ‖J‖_F (units of h²)
  real(wp), parameter :: LME_STEP_MAX = 10.0_wp     !! largest Newton step |Δλ|·h
  real(wp), parameter :: LME_LAM_MAX = 1.0e3_wp     !! |λ|·h beyond this: λ diverges
  integer, parameter :: LME_MAXIT_DEFAULT = 100     !! default Newton iteration cap
  !> Armijo sufficient-decrease constant and smallest step fraction.
  real(wp), parameter :: ARMIJO_C = 1.0e-4_wp, ARMIJO_TMIN = 1.0e-12_wp
  !> Range of a sum of squares in which sqrt(sum) is accurate (no under- or overflow).
  real(wp), parameter :: SUMSQ_LO = 1.0e-280_wp, SUMSQ_HI = 1.0e280_wp
  !> Most candidates for the direct hull test on failure (C(40, 4) = 91390 simplices in 3D).
  integer, parameter :: HULL_TEST_MAXN = 40
  !> Largest Frobenius condition of the candidates' covariance before they count as flat.
  real(wp), parameter :: FLAT_COND_MAX = 1.0e10_wp
  !> Most candidates whose exponents [[moments]] keeps between its two passes (2D fast path).
  integer, parameter :: MOM_BUF = 128
  !> Iteration count returned by [[lme_point_2d]] when the general path must take over.
  integer, parameter :: LME_FALLBACK = -1

  !> Local max-ent shape functions with uniform or node-wise γ.
  type, extends(empm_shape_t) :: empm_shape_lme_t
    real(wp) :: gamma = 3.0_wp                 !! γ = β h² (uniform value)
    real(wp) :: tol0 = 1.0e-6_wp               !! truncation tolerance of the weights, 0 < tol0 < 1
    integer :: max_iter = LME_MAXIT_DEFAULT    !! Newton iteration cap
    integer :: remedy = LME_REMEDY_NONE        !! LME_REMEDY_NONE or LME_REMEDY_ENLARGE
    !> Node-wise γ (grid%nnode), replacing `gamma` when allocated; set it with
    !> `set_gamma_nodes` or `set_gamma_box`, which also keep `gamma_min` up to date.
    real(wp), allocatable :: gamma_node(:)
    real(wp) :: gamma_min = 0.0_wp             !! min of gamma_node (set with gamma_node)
  contains
    procedure :: max_nodes => lme_max_nodes
    procedure :: eval_point => lme_eval_point
    procedure :: eval_batch => lme_eval_batch
    procedure :: name => lme_name
    procedure :: eval_point_iters => lme_eval_point_iters
    procedure :: eval_batch_iters => lme_eval_batch_iters
    procedure :: set_gamma_nodes => lme_set_gamma_nodes
    procedure :: set_gamma_box => lme_set_gamma_box
    procedure :: support_radius => lme_radius
  end type empm_shape_lme_t

contains

  ! ---- type-bound procedures ------------------------------------------------------------------

  !> Upper bound on supporting nodes: the lattice nodes within R_max of some point of one cell
  !> (R_max from the smallest γ, including the remedy's); 0 for invalid parameters.
  pure integer function lme_max_nodes(self, grid)
    class(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid       !! background grid
    real(wp) :: rr, c, dd, dist2
    integer :: kk(3), i, j, k, d, ijk(3)
    lme_max_nodes = 0
    if (.not. params_ok(self, grid)) return
    rr = lme_radius(self, grid)
    if (self%remedy == LME_REMEDY_ENLARGE) rr = rr / sqrt(LME_REMEDY_FACTOR**LME_REMEDY_TRIES)
    kk = 0
    do d = 1, grid%ndim
      kk(d) = ceiling(rr * grid%inv_h(d)) + 1
    end do
    if (grid%ndim == 2) then
      lme_max_nodes = max_depth_2d(grid%h(1), grid%h(2), rr, kk)
      return
    end if
    ! Distance from lattice node ijk to the cell [0, h1]×[0, h2]×[0, h3], times (1 + 1e-12).
    do k = -kk(3), kk(3) + min(1, kk(3))
      do j = -kk(2), kk(2) + min(1, kk(2))
        do i = -kk(1), kk(1) + min(1, kk(1))
          ijk = [i, j, k]
          dist2 = 0.0_wp
          do d = 1, grid%ndim
            c = ijk(d) * grid%h(d)
            dd = max(0.0_wp, -c, c - grid%h(d))
            dist2 = dist2 + dd * dd
          end do
          if (dist2 <= rr * rr * (1.0_wp + 1.0e-12_wp)) lme_max_nodes = lme_max_nodes + 1
        end do
      end do
    end do
  end function lme_max_nodes

  !> Exact largest number of lattice nodes (spacing h1, h2) within the closed disk of radius rr
  !> around any point: the deepest point of an arrangement of closed disks can be taken at a
  !> vertex (an intersection of two circles), so every pairwise intersection of the circles
  !> around the nodes near one cell is tried (lattice periodicity covers every other cell).
  !> Counting is inflated by 1e-9 rr so that vertices, which lie on circles, count. Tighter than
  !> the union over the cell (e.g. 24 -> 21 nodes at gamma = 3), which sizes the basis storage.
  pure integer function max_depth_2d(h1, h2, rr, kk) result(depth)
    real(wp), intent(in) :: h1, h2   !! cell sizes
    real(wp), intent(in) :: rr       !! support radius
    integer, intent(in) :: kk(3)     !! index half-widths of the node neighbourhood
    real(wp) :: xs(4 * (2 * kk(1) + 2) * (2 * kk(2) + 2)), ys(size(xs))
    real(wp) :: dx, dy, d2, a, hh, mx, my, px, py, r2
    integer :: i, j, n, q, m, s
    ! Nodes within 2 rr of the cell (those that can lie within rr of a point of the cell).
    n = 0
    do j = -kk(2) - 1, kk(2) + 2
      do i = -kk(1) - 1, kk(1) + 2
        dx = max(0.0_wp, -i * h1, i * h1 - h1); dy = max(0.0_wp, -j * h2, j * h2 - h2)
        if (dx * dx + dy * dy <= 4.0_wp * rr * rr * (1.0_wp + 1.0e-9_wp) .and. n < size(xs)) then
          n = n + 1; xs(n) = i * h1; ys(n) = j * h2
        end if
      end do
    end do
    r2 = (rr * (1.0_wp + 1.0e-9_wp))**2
    depth = 1
    do q = 1, n
      do m = q + 1, n
        dx = xs(m) - xs(q); dy = ys(m) - ys(q); d2 = dx * dx + dy * dy
        if (d2 > 4.0_wp * rr * rr .or. d2 == 0.0_wp) cycle
        ! The two intersection points: midpoint ± hh along the perpendicular.
        a = 0.5_wp; hh = sqrt(max(0.0_wp, rr * rr / d2 - 0.25_wp))
        mx = xs(q) + a * dx; my = ys(q) + a * dy
        do s = -1, 1, 2
          px = mx - s * hh * dy; py = my + s * hh * dx
          if (px < 0.0_wp .or. px > h1 .or. py < 0.0_wp .or. py > h2) cycle
          depth = max(depth, count((xs(1:n) - px)**2 + (ys(1:n) - py)**2 <= r2))
        end do
      end do
    end do
  end function max_depth_2d

  !> Family identifier: "lme_g" and γ in its shortest decimal form, e.g. "lme_g3", "lme_g0.8".
  function lme_name(self) result(s)
    class(empm_shape_lme_t), intent(in) :: self !! shape family
    character(len=:), allocatable :: s          !! identifier
    s = 'lme_g'//lme_format_gamma(self%gamma)
  end function lme_name

  !> Support radius R_max = h·sqrt(−ln tol0 / γ_min) [length], h the largest grid spacing
  !> (without the remedy's enlargement); 0 for invalid parameters.
  pure real(wp) function lme_radius(self, grid) result(rr)
    class(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid       !! background grid
    rr = 0.0_wp
    if (.not. params_ok(self, grid)) return
    rr = lme_support_radius(gamma_lowest(self), self%tol0, lme_h(grid))
  end function lme_radius

  !> Values and gradients at one point; `lam` is the warm start λ (1/length), updated on success.
  subroutine lme_eval_point(self, grid, x, lp, lam, nn, node, N, dN, info)
    class(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid       !! background grid
    real(wp), intent(in) :: x(:)                !! point (ndim)
    real(wp), intent(in) :: lp(:)               !! particle half-lengths (unused)
    real(wp), intent(inout) :: lam(:)           !! λ (ndim): warm start in, converged λ out
    integer, intent(out) :: nn                  !! number of supporting nodes
    integer, intent(out) :: node(:)             !! supporting node indices
    real(wp), intent(out) :: N(:)               !! values
    real(wp), intent(out) :: dN(:,:)            !! gradients (ndim, :)
    integer, intent(out) :: info                !! SHAPE_OK or a SHAPE_* failure code
    integer :: iters
    associate (unused_lp_ => lp); end associate
    call lme_point_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
  end subroutine lme_eval_point

  !> As `eval_point`, also returning the number of Newton iterations (of the last attempt).
  subroutine lme_eval_point_iters(self, grid, x, lam, nn, node, N, dN, info, iters)
    class(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid       !! background grid
    real(wp), intent(in) :: x(:)                !! point (ndim)
    real(wp), intent(inout) :: lam(:)           !! λ (ndim): warm start in, converged λ out
    integer, intent(out) :: nn                  !! number of supporting nodes
    integer, intent(out) :: node(:)             !! supporting node indices
    real(wp), intent(out) :: N(:)               !! values
    real(wp), intent(out) :: dN(:,:)            !! gradients (ndim, :)
    integer, intent(out) :: info                !! SHAPE_OK or a SHAPE_* failure code
    integer, intent(out) :: iters               !! Newton iterations taken
    call lme_point_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
  end subroutine lme_eval_point_iters

  !> Values and gradients at particles 1..pts%np, warm-started by extrapolation from `pts%lam`
  !> and `pts%lam_old` (the last two converged multipliers) and updating both;
  !> stops at the first failing particle.
  subroutine lme_eval_batch(self, grid, pts, basis, ibad, info)
    class(empm_shape_lme_t), intent(in) :: self  !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer :: iters
    call lme_batch(self, grid, pts, basis, ibad, info, iters)
  end subroutine lme_eval_batch

  !> As `eval_batch`, also returning the total number of Newton iterations.
  subroutine lme_eval_batch_iters(self, grid, pts, basis, ibad, info, iters)
    class(empm_shape_lme_t), intent(in) :: self  !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer, intent(out) :: iters                !! Newton iterations summed over the particles
    call lme_batch(self, grid, pts, basis, ibad, info, iters)
  end subroutine lme_eval_batch_iters

  !> Set node-wise γ from an array of grid%nnode positive values; info = 1 (nothing changed)
  !> for a wrong size or a value that is not positive and finite.
  subroutine lme_set_gamma_nodes(self, grid, gamma_node, info)
    class(empm_shape_lme_t), intent(inout) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    real(wp), intent(in) :: gamma_node(:)          !! γ per node (grid%nnode)
    integer, intent(out) :: info                   !! 0 ok, 1 invalid
    info = 1
    if (size(gamma_node) /= grid%nnode .or. grid%nnode < 1) return
    if (.not. all(gamma_node > 0.0_wp .and. gamma_node <= huge(1.0_wp))) return
    self%gamma_node = gamma_node
    self%gamma_min = minval(gamma_node)
    info = 0
  end subroutine lme_set_gamma_nodes

  !> Node-wise γ: `gamma_inside` for the nodes in the closed box [lo, hi] (within 1e-9 h),
  !> `self%gamma` elsewhere. info = 1 (nothing changed) if a value is not positive.
  subroutine lme_set_gamma_box(self, grid, lo, hi, gamma_inside, info)
    class(empm_shape_lme_t), intent(inout) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid          !! background grid
    real(wp), intent(in) :: lo(:)                  !! lower corner of the box (ndim) [length]
    real(wp), intent(in) :: hi(:)                  !! upper corner of the box (ndim) [length]
    real(wp), intent(in) :: gamma_inside           !! γ of the nodes inside the box
    integer, intent(out) :: info                   !! 0 ok, 1 invalid
    real(wp), allocatable :: g(:)
    real(wp) :: xi(3), tol
    integer :: id, nd
    nd = grid%ndim
    tol = 1.0e-9_wp * grid%hmin()
    allocate(g(grid%nnode))
    g = self%gamma
    do id = 1, grid%nnode
      xi = grid%node_coord(id)
      if (all(xi(1:nd) >= lo(1:nd) - tol .and. xi(1:nd) <= hi(1:nd) + tol)) g(id) = gamma_inside
    end do
    call lme_set_gamma_nodes(self, grid, g, info)
  end subroutine lme_set_gamma_box

  ! ---- evaluation -------------------------------------------------------------------------------

  !> Batch loop without polymorphic calls: one [[lme_point_remedy]] per particle.
  subroutine lme_batch(self, grid, pts, basis, ibad, info, iters)
    type(empm_shape_lme_t), intent(in) :: self   !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer, intent(out) :: iters                !! total Newton iterations
    integer :: p, it, pinfo, nd
    real(wp) :: lam(3), hs, cut, rmax
    logical :: fast
    iters = 0
    call shape_batch_fits(pts%np, basis, ibad, info)
    if (info /= SHAPE_OK) return
    nd = grid%ndim
    ! The lean 2D path needs uniform γ and valid parameters (a support larger than the storage
    ! falls back, and the general path reports it).
    fast = nd == 2 .and. .not. allocated(self%gamma_node) .and. params_ok(self, grid)
    hs = lme_h(grid)
    cut = -log(self%tol0)
    rmax = sqrt(cut / self%gamma) * hs
    ! Particles are independent: threads share them; the first failure (lowest index) is kept.
    ibad = huge(1)
    !$omp parallel do schedule(static) private(pinfo, it, lam) reduction(+: iters) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
    do p = 1, pts%np
      ! Warm start extrapolated from the last two converged multipliers: in a smooth motion
      ! λ* changes smoothly, so 2λ_n − λ_(n−1) is off by O(Δx²) and one Newton step usually
      ! reaches the tolerance (the plain warm start λ_n needs two). lam_old = huge marks a
      ! particle without a converged history yet (set at generation): plain warm start.
      if (pts%lam_old(1, p) == huge(1.0_wp)) then
        lam(1:nd) = pts%lam(:, p)
      else
        lam(1:nd) = 2.0_wp * pts%lam(:, p) - pts%lam_old(:, p)
      end if
      it = LME_FALLBACK
      if (fast) call lme_point_2d(grid, pts%x(:, p), self%gamma, cut, hs, rmax, &
        self%max_iter, lam, basis%maxn, basis%nn(p), basis%node(:, p), basis%N(:, p), &
        basis%dN(:, :, p), it)
      if (it == LME_FALLBACK) then
        ! Anything unusual: the guarded general path, from the same warm start.
        call lme_point_remedy(self, grid, pts%x(:, p), lam(1:nd), basis%nn(p), &
                              basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), it, pinfo)
      else
        pinfo = SHAPE_OK
      end if
      if (pinfo == SHAPE_OK) then
        if (pts%lam_old(1, p) == huge(1.0_wp)) then
          pts%lam_old(:, p) = lam(1:nd)
        else
          pts%lam_old(:, p) = pts%lam(:, p)
        end if
        pts%lam(:, p) = lam(1:nd)
      end if
      iters = iters + it
      if (pinfo /= SHAPE_OK) call shape_keep_first_failure(p, pinfo, ibad, info)
    end do
    !$omp end parallel do
    if (ibad == huge(1)) ibad = 0
  end subroutine lme_batch

  !> One point, with the 'enlarge' remedy when enabled.
  pure subroutine lme_point_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: x(:)               !! point (ndim)
    real(wp), intent(inout) :: lam(:)          !! λ: warm start in, converged λ out
    integer, intent(out) :: nn                 !! number of supporting nodes (0 on failure)
    integer, intent(out) :: node(:)            !! supporting node indices
    real(wp), intent(out) :: N(:)              !! values
    real(wp), intent(out) :: dN(:,:)           !! gradients (ndim, :)
    integer, intent(out) :: iters              !! Newton iterations of the last attempt
    integer, intent(out) :: info               !! SHAPE_OK or a SHAPE_* failure code
    integer :: k
    call lme_point(self, grid, x, lam, 1.0_wp, nn, node, N, dN, iters, info)
    if (self%remedy /= LME_REMEDY_ENLARGE) return
    do k = 1, LME_REMEDY_TRIES
      select case (info)
      case (SHAPE_OUTSIDE_HULL, SHAPE_SUPPORT_CLIPPED, SHAPE_SINGULAR, SHAPE_NOT_CONVERGED)
        lam(1:grid%ndim) = 0.0_wp
        call lme_point(self, grid, x, lam, LME_REMEDY_FACTOR**k, nn, node, N, dN, iters, info)
      case default
        return
      end select
    end do
  end subroutine lme_point_remedy

  !> One point with every γ multiplied by `scale`: candidates through the grid, then the kernel.
  pure subroutine lme_point(self, grid, x, lam, scale, nn, node, N, dN, iters, info)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: x(:)               !! point (ndim)
    real(wp), intent(inout) :: lam(:)          !! λ: warm start in, converged λ out
    real(wp), intent(in) :: scale              !! multiplier of every γ (1, or the remedy's)
    integer, intent(out) :: nn                 !! number of supporting nodes (0 on failure)
    integer, intent(out) :: node(:)            !! supporting node indices
    real(wp), intent(out) :: N(:)              !! values
    real(wp), intent(out) :: dN(:,:)           !! gradients (ndim, :)
    integer, intent(out) :: iters              !! Newton iterations
    integer, intent(out) :: info               !! SHAPE_OK or a SHAPE_* failure code
    real(wp) :: hs, cut, rmax, s, rd, xi(3), q, ga
    integer :: nd, d, lo(3), hi(3), i, j, k, id, id0, cap
    logical :: varying
    nn = 0
    iters = 0
    nd = grid%ndim
    if (.not. params_ok(self, grid)) then
      info = SHAPE_TOO_MANY_NODES; return
    end if
    if (.not. grid%inside(x)) then
      info = SHAPE_OUTSIDE_GRID; return
    end if
    if (size(dN, 1) < nd .or. size(lam) < nd) then
      info = SHAPE_TOO_MANY_NODES; return
    end if
    cap = min(size(node), size(N), size(dN, 2))
    varying = allocated(self%gamma_node)
    hs = lme_h(grid)
    cut = -log(self%tol0)
    ! Index box of the lattice nodes within R_max of x, clipped to the grid.
    rmax = sqrt(cut / (scale * gamma_lowest(self))) * hs
    lo = 0; hi = 0
    do d = 1, nd
      s = (x(d) - grid%origin(d)) * grid%inv_h(d)
      rd = rmax * grid%inv_h(d)
      lo(d) = max(0, ceiling(s - rd))
      hi(d) = min(grid%ncell(d), floor(s + rd))
    end do
    ! Node ids by integer arithmetic (the box is clipped to the grid); ξ along j and k once per
    ! row. ξ and q are the same expressions as before, so the candidate set is unchanged.
    xi = 0.0_wp
    ga = scale * self%gamma
    do k = lo(3), hi(3)
      if (nd >= 3) xi(3) = (x(3) - (grid%origin(3) + k * grid%h(3))) / hs
      do j = lo(2), hi(2)
        if (nd >= 2) xi(2) = (x(2) - (grid%origin(2) + j * grid%h(2))) / hs
        id0 = 1 + grid%nn(1) * (j + grid%nn(2) * k)
        do i = lo(1), hi(1)
          id = id0 + i
          xi(1) = (x(1) - (grid%origin(1) + i * grid%h(1))) / hs
          if (varying) ga = scale * self%gamma_node(id)
          q = ga * (xi(1)**2 + xi(2)**2 + xi(3)**2)
          if (q > cut) cycle
          nn = nn + 1
          if (nn > cap) then
            nn = 0
            info = SHAPE_TOO_MANY_NODES; return
          end if
          node(nn) = id
          if (nd == 2) then
            ! 2D: explicit copy (the generic slice of run-time length costs ~30 instructions).
            dN(1, nn) = xi(1)
            dN(2, nn) = xi(2)
          else
            dN(1:nd, nn) = xi(1:nd)
          end if
        end do
      end do
    end do
    if (varying) then
      call lme_kernel(nd, nn, scale, self%tol0, hs, self%max_iter, lam, N, dN, iters, info, &
                      self%gamma_node, node)
    else
      call lme_kernel(nd, nn, scale * self%gamma, self%tol0, hs, self%max_iter, lam, N, dN, &
                      iters, info)
    end if
    if (info == SHAPE_OUTSIDE_HULL) then
      if (clipped(grid, x, rmax)) info = SHAPE_SUPPORT_CLIPPED
    end if
    if (info /= SHAPE_OK) nn = 0
  end subroutine lme_point

  !> The common case, lean: 2D, uniform γ, a warm start near λ*. The same basis as
  !> [[lme_point]] (to the Newton tolerance), with the work fused into three passes over the
  !> support: one finds the candidates (all active, since the box is filtered by
  !> γ|ξ|² ≤ −ln tol0) and their exponents, one evaluates the weights and their moments up to
  !> third order (about the heaviest node), one writes values and gradients. Newton stops as
  !> soon as a bound proves the residual after the final linearised step below the tolerance;
  !> the moments of the final values follow from the third moments without another pass over
  !> the nodes (docs/shape-functions.md, "The 2D batch path"). Only full Newton steps are
  !> taken here: whenever the general path could do something else (point outside the grid,
  !> ‖r‖ above the Armijo threshold, ill-conditioned J, a step or λ beyond its cap, the
  !> iteration cap, too few candidates or x outside their bounding box), `iters` returns
  !> `LME_FALLBACK` and the caller starts [[lme_point]] over.
  pure subroutine lme_point_2d(grid, x, gamma, cut, h, rmax, maxit, lam, cap, nn, node, N, dN, &
                               iters)
    type(empm_grid_t), intent(in) :: grid     !! background grid (2D)
    real(wp), intent(in) :: x(2)              !! point
    real(wp), intent(in) :: gamma             !! γ
    real(wp), intent(in) :: cut               !! −ln tol0
    real(wp), intent(in) :: h                 !! nodal spacing of γ [length]
    real(wp), intent(in) :: rmax              !! support radius [length]
    integer, intent(in) :: maxit              !! Newton iteration cap
    real(wp), intent(inout) :: lam(2)         !! λ [1/length]: warm start in, λ* out
    integer, intent(in) :: cap                !! storage per point
    integer, intent(out) :: nn                !! number of supporting nodes
    integer, intent(out) :: node(cap)         !! node indices
    real(wp), intent(out) :: N(cap)           !! values
    real(wp), intent(out) :: dN(2, cap)       !! gradients
    integer, intent(out) :: iters             !! Newton iterations, or LME_FALLBACK
    real(wp) :: s1, s2, rd1, rd2, xi1, xi2, q, f, fmax, qmax, x2max, xlo1, xhi1, xlo2, xhi2
    real(wp) :: l1, l2, c1, c2, sw, m1(2), m2(3), m3(4), logz, r(2), jm(3), ji(3), scl, rn
    real(wp) :: d1, d2, dn2, b1, b2, mm(4), det, q1, q2, t1(2), t2(3), st, rt1, rt2, p, v1, v2
    integer :: lo1, hi1, lo2, hi2, i, j, id0, a, amax, it
    nn = 0
    it = 0
    ! LME_FALLBACK until the very end: every early return hands over to the general path.
    iters = LME_FALLBACK
    if (.not. grid%inside(x)) return
    l1 = lam(1) * h; l2 = lam(2) * h
    if (.not. (abs(l1) <= LME_LAM_MAX .and. abs(l2) <= LME_LAM_MAX)) return
    ! Candidates: the index box of the lattice nodes within R of x, filtered by distance, with
    ! ξ and γ|ξ|² the expressions of lme_point; their exponents f = −γ|ξ|² + λ·ξ at once.
    s1 = (x(1) - grid%origin(1)) * grid%inv_h(1); rd1 = rmax * grid%inv_h(1)
    s2 = (x(2) - grid%origin(2)) * grid%inv_h(2); rd2 = rmax * grid%inv_h(2)
    lo1 = max(0, ceiling(s1 - rd1)); hi1 = min(grid%ncell(1), floor(s1 + rd1))
    lo2 = max(0, ceiling(s2 - rd2)); hi2 = min(grid%ncell(2), floor(s2 + rd2))
    fmax = -huge(1.0_wp); amax = 0; qmax = 0.0_wp
    xlo1 = huge(1.0_wp); xhi1 = -huge(1.0_wp); xlo2 = huge(1.0_wp); xhi2 = -huge(1.0_wp)
    do j = lo2, hi2
      xi2 = (x(2) - (grid%origin(2) + j * grid%h(2))) / h
      id0 = 1 + grid%nn(1) * j
      do i = lo1, hi1
        xi1 = (x(1) - (grid%origin(1) + i * grid%h(1))) / h
        q = gamma * (xi1**2 + xi2**2)
        if (q > cut) cycle
        if (nn == cap) return
        nn = nn + 1
        node(nn) = id0 + i
        dN(1, nn) = xi1; dN(2, nn) = xi2
        f = -q + (l1 * xi1 + l2 * xi2)
        N(nn) = f
        if (f > fmax) then
          fmax = f; amax = nn
        end if
        qmax = max(qmax, q)
        xlo1 = min(xlo1, xi1); xhi1 = max(xhi1, xi1)
        xlo2 = min(xlo2, xi2); xhi2 = max(xhi2, xi2)
      end do
    end do
    ! Direct hull tests of the general path: d + 1 nodes, x in their bounding box (flat sets
    ! show up below as a singular J).
    if (nn < 3) return
    if (.not. (xhi1 >= 0.0_wp .and. xlo1 <= 0.0_wp .and. xhi2 >= 0.0_wp .and. &
               xlo2 <= 0.0_wp)) return
    x2max = qmax / gamma
    c1 = dN(1, amax); c2 = dN(2, amax)
    call weights_2d(nn, fmax, c1, c2, dN, N, sw, m1, m2, m3, logz, r, jm)
    do
      ! Newton step Δ = −J⁻¹r, full steps only (‖r‖ small).
      rn = sqrt(r(1)**2 + r(2)**2)
      if (logz < -qmax - 1.0e-9_wp * (1.0_wp + qmax)) return
      if (rn > LME_TOL_GUARD) return
      call inverse_2d(jm, ji, scl)
      if (scl < LME_J_MIN) return
      d1 = -(ji(1) * r(1) + ji(2) * r(2)) / scl
      d2 = -(ji(2) * r(1) + ji(3) * r(2)) / scl
      dn2 = d1**2 + d2**2
      ! Done when r(λ+Δ), bounded by ½ (ξmax + ‖r‖)³ |Δ|², is within the tolerance.
      if (rn < LME_TOL_CONV .or. &
          0.5_wp * (sqrt(x2max) + rn)**3 * dn2 < LME_TOL_CONV) exit
      if (it >= maxit .or. dn2 > LME_STEP_MAX**2) return
      l1 = l1 + d1; l2 = l2 + d2
      it = it + 1
      if (.not. (abs(l1) <= LME_LAM_MAX .and. abs(l2) <= LME_LAM_MAX)) return
      fmax = -huge(1.0_wp); amax = 0
      do a = 1, nn
        f = -(gamma * (dN(1, a)**2 + dN(2, a)**2)) + (l1 * dN(1, a) + l2 * dN(2, a))
        N(a) = f
        if (f > fmax) then
          fmax = f; amax = a
        end if
      end do
      c1 = dN(1, amax); c2 = dN(2, amax)
      call weights_2d(nn, fmax, c1, c2, dN, N, sw, m1, m2, m3, logz, r, jm)
    end do
    ! Final values p̂_a ∝ w_a (1 + q·u_a), u = ξ − c, the linearised step with q chosen so that
    ! Σ p̂ ξ = 0 holds exactly (not only to first order): Σ w (1 + q·u) ξ = 0, i.e.
    ! (S1 + S0 c) + M q = 0 with M = S2 + c⊗S1. q = Δ + O(|Δ|²), so p̂ = p* + O(|Δ|²), within
    ! the bound above; reproduction holds to round-off whatever the early stop left in r.
    ! The moments of p̂ follow from S0..S3: ŝ = S0 + q·S1, Σ w Q u = S1 + S2 q,
    ! Σ w Q u⊗u = S2 + S3[q], so no pass over the nodes is needed before the last one.
    b1 = m1(1) + sw * c1; b2 = m1(2) + sw * c2
    mm(1) = m2(1) + c1 * m1(1); mm(2) = m2(2) + c1 * m1(2)
    mm(3) = m2(2) + c2 * m1(1); mm(4) = m2(3) + c2 * m1(2)
    det = mm(1) * mm(4) - mm(2) * mm(3)
    if (.not. (abs(det) > LME_J_MIN * sw * sw)) return
    q1 = -(mm(4) * b1 - mm(2) * b2) / det
    q2 = -(mm(1) * b2 - mm(3) * b1) / det
    ! The general path's guard on the linearisation: every factor 1 + q·u above 1/2.
    if (sqrt(q1**2 + q2**2) * (sqrt(x2max) + sqrt(c1**2 + c2**2)) > 0.5_wp) return
    st = sw + (m1(1) * q1 + m1(2) * q2)
    t1(1) = m1(1) + (m2(1) * q1 + m2(2) * q2)
    t1(2) = m1(2) + (m2(2) * q1 + m2(3) * q2)
    t2(1) = m2(1) + (m3(1) * q1 + m3(2) * q2)
    t2(2) = m2(2) + (m3(2) * q1 + m3(3) * q2)
    t2(3) = m2(3) + (m3(3) * q1 + m3(4) * q2)
    rt1 = t1(1) / st; rt2 = t1(2) / st
    jm(1) = t2(1) / st - rt1 * rt1
    jm(2) = t2(2) / st - rt1 * rt2
    jm(3) = t2(3) / st - rt2 * rt2
    call inverse_2d(jm, ji, scl)
    if (scl < LME_J_MIN) return
    ji = ji / scl
    ! r̂ − c = (rt1, rt2); ∇p̂_a = −p̂_a Ĵ⁻¹ (ξ_a − r̂)/h.
    do a = 1, nn
      v1 = dN(1, a) - c1; v2 = dN(2, a) - c2
      p = N(a) * (1.0_wp + (q1 * v1 + q2 * v2)) / st
      N(a) = p
      v1 = v1 - rt1; v2 = v2 - rt2
      dN(1, a) = -p * (ji(1) * v1 + ji(2) * v2) / h
      dN(2, a) = -p * (ji(2) * v1 + ji(3) * v2) / h
    end do
    lam(1) = (l1 + d1) / h; lam(2) = (l2 + d2) / h
    iters = it

  end subroutine lme_point_2d

  !> 2D weights w_a = exp(f_a − fm) (f in `w` on entry), their moments about c up to third
  !> order (S0 = Σw, S1 = Σ w u, S2 = Σ w u⊗u as (11, 12, 22), S3 as (111, 112, 122, 222),
  !> u = ξ − c), and log Z, r and J (11, 12, 22) of the normalised weights.
  pure subroutine weights_2d(nn, fm, c1, c2, xi, w, sw, m1, m2, m3, logz, r, jm)
    integer, intent(in) :: nn            !! number of nodes
    real(wp), intent(in) :: fm           !! max f
    real(wp), intent(in) :: c1           !! centre of the moments, x
    real(wp), intent(in) :: c2           !! centre of the moments, y
    real(wp), intent(in) :: xi(2, *)     !! ξ_a
    real(wp), intent(inout) :: w(*)      !! in: f_a; out: w_a
    real(wp), intent(out) :: sw          !! S0
    real(wp), intent(out) :: m1(2)       !! S1
    real(wp), intent(out) :: m2(3)       !! S2
    real(wp), intent(out) :: m3(4)       !! S3
    real(wp), intent(out) :: logz        !! log Z
    real(wp), intent(out) :: r(2)        !! r = Σ p ξ
    real(wp), intent(out) :: jm(3)       !! J
    real(wp) :: e, u1, u2, eu1, eu2
    integer :: b
    sw = 0.0_wp; m1 = 0.0_wp; m2 = 0.0_wp; m3 = 0.0_wp
    do b = 1, nn
      e = exp(w(b) - fm)
      w(b) = e
      u1 = xi(1, b) - c1; u2 = xi(2, b) - c2
      eu1 = e * u1; eu2 = e * u2
      sw = sw + e
      m1(1) = m1(1) + eu1; m1(2) = m1(2) + eu2
      m2(1) = m2(1) + eu1 * u1; m2(2) = m2(2) + eu1 * u2; m2(3) = m2(3) + eu2 * u2
      m3(1) = m3(1) + (eu1 * u1) * u1; m3(2) = m3(2) + (eu1 * u1) * u2
      m3(3) = m3(3) + (eu1 * u2) * u2; m3(4) = m3(4) + (eu2 * u2) * u2
    end do
    logz = fm + log(sw)
    r(1) = c1 + m1(1) / sw; r(2) = c2 + m1(2) / sw
    jm(1) = m2(1) / sw - (m1(1) / sw)**2
    jm(2) = m2(2) / sw - (m1(1) / sw) * (m1(2) / sw)
    jm(3) = m2(3) / sw - (m1(2) / sw)**2
  end subroutine weights_2d

  !> (J/‖J‖_F)⁻¹ of a symmetric 2×2 J = (j11, j12, j22) by its adjugate, and ‖J‖_F; `nrm` = 0
  !> when J is not positive definite to within the Frobenius condition LME_COND_MAX.
  pure subroutine inverse_2d(jj, jinv, nrm)
    real(wp), intent(in) :: jj(3)        !! J
    real(wp), intent(out) :: jinv(3)     !! (J/‖J‖)⁻¹
    real(wp), intent(out) :: nrm         !! ‖J‖_F, or 0 on failure
    real(wp) :: b11, b12, b22, det, nadj
    nrm = sqrt(jj(1)**2 + 2.0_wp * jj(2)**2 + jj(3)**2)
    jinv = 0.0_wp
    if (.not. (nrm > sqrt(SUMSQ_LO) .and. nrm < sqrt(SUMSQ_HI))) then
      nrm = 0.0_wp; return
    end if
    b11 = jj(1) / nrm; b12 = jj(2) / nrm; b22 = jj(3) / nrm
    det = b11 * b22 - b12 * b12
    nadj = sqrt(b11**2 + 2.0_wp * b12**2 + b22**2)
    if (.not. (det > 0.0_wp .and. det * LME_COND_MAX > nadj)) then
      nrm = 0.0_wp; return
    end if
    jinv(1) = b22 / det; jinv(2) = -b12 / det; jinv(3) = b11 / det
  end subroutine inverse_2d

  !> True when a lattice node within `rmax` of x lies beyond the grid.
  pure logical function clipped(grid, x, rmax)
    type(empm_grid_t), intent(in) :: grid !! background grid
    real(wp), intent(in) :: x(:)          !! point (inside the grid)
    real(wp), intent(in) :: rmax          !! support radius [length]
    integer :: lo(3), hi(3), i, j, k, d, ijk(3)
    real(wp) :: s, rd, dist2
    clipped = .false.
    lo = 0; hi = 0
    do d = 1, grid%ndim
      s = (x(d) - grid%origin(d)) * grid%inv_h(d)
      rd = rmax * grid%inv_h(d)
      lo(d) = ceiling(s - rd)
      hi(d) = floor(s + rd)
    end do
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          ijk = [i, j, k]
          if (grid%node_id(ijk) /= 0) cycle
          dist2 = 0.0_wp
          do d = 1, grid%ndim
            dist2 = dist2 + (x(d) - (grid%origin(d) + ijk(d) * grid%h(d)))**2
          end do
          if (dist2 <= rmax * rmax) then
            clipped = .true.; return
          end if
        end do
      end do
    end do
  end function clipped

  ! ---- the kernel (shared with the procedural entry point empm_lme_basis) --------------------

  !> LME values and gradients at a point from its candidate nodes.
  !>
  !> On entry `dN(1:nd, a)` holds ξ_a = (x − x_a)/h for the `nc` candidates; on exit `N(a)` and
  !> `dN(:, a)` hold p_a and ∇p_a. Candidates with γ_a|ξ_a|² > −ln tol0 (beyond their support
  !> radius) get p_a = 0 and ∇p_a = 0. γ_a = `gamma` · gnode(node(a)) when `gnode` and `node`
  !> are present, else `gamma`. On failure N = 0, dN = 0 and `lam` is unchanged.
  pure subroutine lme_kernel(nd, nc, gamma, tol0, h, maxit, lam, N, dN, iters, info, gnode, node)
    integer, intent(in) :: nd                    !! spatial dimension, 1..3
    integer, intent(in) :: nc                    !! number of candidates
    real(wp), intent(in) :: gamma                !! γ (uniform), or the factor of gnode
    real(wp), intent(in) :: tol0                 !! truncation tolerance, 0 < tol0 < 1
    real(wp), intent(in) :: h                    !! nodal spacing of γ = β h² [length]
    integer, intent(in) :: maxit                 !! Newton iteration cap
    real(wp), intent(inout) :: lam(:)            !! λ (nd) [1/length]: warm start in, λ* out
    real(wp), intent(inout) :: N(:)              !! out: values p_a (nc)
    real(wp), intent(inout) :: dN(:,:)           !! in: ξ_a; out: gradients ∇p_a (nd, nc)
    integer, intent(out) :: iters                !! Newton iterations taken
    integer, intent(out) :: info                 !! SHAPE_OK or a SHAPE_* failure code
    real(wp), intent(in), optional :: gnode(:)   !! γ per grid node
    integer, intent(in), optional :: node(:)     !! grid node of each candidate
    real(wp) :: cut, q, qmax, lh(3), lt(3), r(3), rt(3), jm(3, 3), jt(3, 3), jinv(3, 3)
    real(wp) :: del(3), y(3), bm(3, 3), mv(3), logz, logzt, rn, t, slope, dnorm, zlow, p, ga
    real(wp) :: cmean(3), cov(3, 3), cinv(3, 3), v(3), s, ximax, x2, x2max, scl, cen(3), cent(3)
    real(wp) :: xlo(3), xhi(3)
    integer :: a, i, nact
    logical :: varying, ok, qvalid, fast2d

    iters = 0
    info = SHAPE_OK
    lh = 0.0_wp
    ok = .true.
    qvalid = .true.
    nact = 0
    varying = present(gnode) .and. present(node)
    fast2d = nd == 2 .and. .not. varying
    cut = -log(tol0)
    main: block
      ! Mark the active candidates (γ_a|ξ_a|² ≤ −ln tol0) with N(a) = 0, inactive ones with
      ! N(a) = −1. From here until the final values, N(a) ≥ 0 marks an active candidate and holds
      ! its weight exp(f_a − max f) at the last λ evaluated (`moments` recomputes γ_a|ξ_a|²,
      ! cheaper than storing it), so the final values need no exponential.
      nact = 0; qmax = 0.0_wp; x2max = 0.0_wp
      cmean = 0.0_wp
      xlo = huge(1.0_wp); xhi = -huge(1.0_wp)
      if (fast2d) then
        ! The hot case with scalars: the same expressions as the general loop (same results).
        do a = 1, nc
          x2 = dN(1, a)**2 + dN(2, a)**2
          q = gamma * x2
          if (q <= cut) then
            N(a) = 0.0_wp
            nact = nact + 1
            qmax = max(qmax, q)
            x2max = max(x2max, x2)
            cmean(1) = cmean(1) + dN(1, a)
            cmean(2) = cmean(2) + dN(2, a)
            xlo(1) = min(xlo(1), dN(1, a))
            xhi(1) = max(xhi(1), dN(1, a))
            xlo(2) = min(xlo(2), dN(2, a))
            xhi(2) = max(xhi(2), dN(2, a))
          else
            N(a) = -1.0_wp
          end if
        end do
      else
        do a = 1, nc
          x2 = sum(dN(1:nd, a)**2)
          q = gam(a) * x2
          if (q <= cut) then
            N(a) = 0.0_wp
            nact = nact + 1
            qmax = max(qmax, q)
            x2max = max(x2max, x2)
            cmean(1:nd) = cmean(1:nd) + dN(1:nd, a)
            do i = 1, nd
              xlo(i) = min(xlo(i), dN(i, a))
              xhi(i) = max(xhi(i), dN(i, a))
            end do
          else
            N(a) = -1.0_wp
          end if
        end do
      end if
      ximax = sqrt(x2max)
      ! Direct hull tests: d+1 nodes, x in their bounding box, not all in one hyperplane.
      if (nact < nd + 1) then
        info = SHAPE_OUTSIDE_HULL; exit main
      end if
      do i = 1, nd
        if (.not. (xhi(i) >= 0.0_wp .and. xlo(i) <= 0.0_wp)) then
          info = SHAPE_OUTSIDE_HULL; exit main
        end if
      end do
      cmean = cmean / nact
      cov = 0.0_wp
      if (nd == 2) then
        ! As the general loop; cov(1, 2) = cov(2, 1) exactly there too (y1 y2 = y2 y1).
        do a = 1, nc
          if (N(a) < 0.0_wp) cycle
          y(1) = dN(1, a) - cmean(1)
          y(2) = dN(2, a) - cmean(2)
          cov(1, 1) = cov(1, 1) + y(1) * y(1)
          cov(2, 1) = cov(2, 1) + y(2) * y(1)
          cov(2, 2) = cov(2, 2) + y(2) * y(2)
        end do
        cov(1, 2) = cov(2, 1)
      else
        do a = 1, nc
          if (N(a) < 0.0_wp) cycle
          y(1:nd) = dN(1:nd, a) - cmean(1:nd)
          do i = 1, nd
            cov(1:nd, i) = cov(1:nd, i) + y(1:nd) * y(i)
          end do
        end do
      end if
      cov = cov / nact
      call sym_inverse(nd, cov, cinv, scl, FLAT_COND_MAX, ok)
      if (.not. ok) then
        info = SHAPE_OUTSIDE_HULL; exit main
      end if

      ! Guarded Newton on log Z, in units of h.
      lh = 0.0_wp
      lh(1:nd) = lam(1:nd) * h
      if (.not. all(abs(lh(1:nd)) <= LME_LAM_MAX)) lh = 0.0_wp
      call moments(nd, nc, gamma, N, dN, lh, logz, r, jm, cen, gnode, node)
      ! log Z(λ*) = H(p*) − Σ p*γ_a|ξ_a|² ≥ −qmax: a smaller log Z proves there is no minimiser.
      zlow = -qmax - 1.0e-9_wp * (1.0_wp + qmax)
      do
        rn = norm_small(nd, r)
        if (rn < LME_TOL_CONV) exit
        if (logz < zlow) then
          info = SHAPE_OUTSIDE_HULL; exit main
        end if
        if (iters >= maxit) then
          info = SHAPE_NOT_CONVERGED; exit main
        end if
        call sym_inverse(nd, jm, jinv, scl, LME_COND_MAX, ok)
        if (.not. ok) then
          ! J singular before convergence: the weights concentrate on a face of the hull, as
          ! when x is outside it (or very close to its boundary).
          info = SHAPE_SINGULAR; exit main
        end if
        ! Δ = −J⁻¹r = −(J/‖J‖)⁻¹r/‖J‖, capped at LME_STEP_MAX (J may be tiny far from λ*,
        ! when one node carries nearly all the weight).
        del = matvec(nd, jinv, r)
        dnorm = norm_small(nd, del)
        if (dnorm > LME_STEP_MAX * scl) then
          del = -del * (LME_STEP_MAX / dnorm)
        else
          del = -del / scl
        end if
        t = 1.0_wp
        ! The first trial is the full step, and its moments are kept: the guard costs extra
        ! evaluations only when it actually backtracks.
        if (rn > LME_TOL_GUARD) then
          slope = dot_product(r(1:nd), del(1:nd))
          do
            lt = lh + t * del
            call moments(nd, nc, gamma, N, dN, lt, logzt, rt, jt, cent, gnode, node)
            if (logzt <= logz + ARMIJO_C * t * slope) exit
            t = 0.5_wp * t
            if (t < ARMIJO_TMIN) then
              info = SHAPE_NOT_CONVERGED; exit main
            end if
          end do
        else
          lt = lh + del
          call moments(nd, nc, gamma, N, dN, lt, logzt, rt, jt, cent, gnode, node)
        end if
        lh = lt; logz = logzt; r = rt; jm = jt; cen = cent
        iters = iters + 1
        if (.not. all(abs(lh(1:nd)) <= LME_LAM_MAX)) then
          info = SHAPE_OUTSIDE_HULL; exit main
        end if
      end do
      ! Final step, linearised: p̃_a = p_a (1 + (ξ_a − r)·Δ) with Δ = −J⁻¹r is p at λ + Δ to
      ! first order (error O(|Δ|²) < 1e-18), costs no exponential, and makes Σp̃ = 1 and
      ! Σp̃ ξ = 0 hold to round-off instead of to the convergence tolerance. It is skipped
      ! (Δ = 0) when a factor 1 + (ξ_a − r)·Δ could fall below 1/2, i.e. for points within
      ! ~1e-9 h of the hull boundary, where consistency then holds to the tolerance 1e-10.
      call sym_inverse(nd, jm, jinv, scl, LME_COND_MAX, ok)
      if (.not. (ok .and. scl >= LME_J_MIN)) then
        info = SHAPE_SINGULAR; exit main
      end if
      jinv = jinv / scl
      del = -matvec(nd, jinv, r)
      if (norm_small(nd, del) * (ximax + norm_small(nd, r)) > 0.5_wp) del = 0.0_wp

      ! Values p̃ and their moments; for node-wise γ also B = Σ p γ ξ⊗ξ and m = Σ p γ ξ.
      ! N(a) holds exp(f_a − max f) at λ, i.e. p_a up to the factor Z that the division by
      ! s = Σp̃ below removes; from here N holds p̃ (0 for inactive candidates).
      qvalid = .false.
      s = 0.0_wp; rt = 0.0_wp; jt = 0.0_wp; bm = 0.0_wp; mv = 0.0_wp
      if (fast2d) then
        ! The hot case with scalars: the same expressions as the general loop (same results;
        ! jt(1, 2) and jt(2, 1) may differ in the last bit, as there).
        do a = 1, nc
          if (N(a) < 0.0_wp) then
            N(a) = 0.0_wp
            cycle
          end if
          p = N(a) * (1.0_wp + ((dN(1, a) - r(1)) * del(1) + (dN(2, a) - r(2)) * del(2)))
          N(a) = p
          s = s + p
          v(1) = dN(1, a) - cen(1)
          v(2) = dN(2, a) - cen(2)
          rt(1) = rt(1) + p * v(1)
          rt(2) = rt(2) + p * v(2)
          jt(1, 1) = jt(1, 1) + (p * v(1)) * v(1)
          jt(2, 1) = jt(2, 1) + (p * v(1)) * v(2)
          jt(1, 2) = jt(1, 2) + (p * v(2)) * v(1)
          jt(2, 2) = jt(2, 2) + (p * v(2)) * v(2)
        end do
      else
        do a = 1, nc
          if (N(a) < 0.0_wp) then
            N(a) = 0.0_wp
            cycle
          end if
          v(1:nd) = dN(1:nd, a) - r(1:nd)
          p = N(a) * (1.0_wp + dot_product(v(1:nd), del(1:nd)))
          N(a) = p
          s = s + p
          v(1:nd) = dN(1:nd, a) - cen(1:nd)
          rt(1:nd) = rt(1:nd) + p * v(1:nd)
          do i = 1, nd
            jt(1:nd, i) = jt(1:nd, i) + (p * v(i)) * v(1:nd)
          end do
          if (varying) then
            ga = p * gam(a)
            mv(1:nd) = mv(1:nd) + ga * dN(1:nd, a)
            do i = 1, nd
              bm(1:nd, i) = bm(1:nd, i) + ga * dN(1:nd, a) * dN(i, a)
            end do
          end if
        end do
      end if
      lh = lh + del
      rt = rt / s
      r = cen + rt
      do i = 1, nd
        jm(1:nd, i) = jt(1:nd, i) / s - rt(1:nd) * rt(i)
      end do
      bm = bm / s; mv = mv / s
      call sym_inverse(nd, jm, jinv, scl, LME_COND_MAX, ok)
      if (.not. (ok .and. scl >= LME_J_MIN)) then
        info = SHAPE_SINGULAR; exit main
      end if
      jinv = jinv / scl
      ! Gradients (see the module documentation), with the normalised p̃.
      v = 0.0_wp
      if (fast2d) then
        ! The hot case with scalars, as the general loop below.
        do a = 1, nc
          if (N(a) == 0.0_wp) then
            dN(1, a) = 0.0_wp
            dN(2, a) = 0.0_wp
            cycle
          end if
          N(a) = N(a) / s
          v(1) = dN(1, a) - r(1)
          v(2) = dN(2, a) - r(2)
          y(1) = jinv(1, 1) * v(1) + jinv(1, 2) * v(2)
          y(2) = jinv(2, 1) * v(1) + jinv(2, 2) * v(2)
          dN(1, a) = -N(a) * y(1) / h
          dN(2, a) = -N(a) * y(2) / h
        end do
      else
        do a = 1, nc
          if (N(a) == 0.0_wp) then
            dN(1:nd, a) = 0.0_wp
            cycle
          end if
          N(a) = N(a) / s
          v(1:nd) = dN(1:nd, a) - r(1:nd)
          y = matvec(nd, jinv, v)
          if (varying) then
            v = matvec(nd, bm, y)
            dN(1:nd, a) = N(a) * (-y(1:nd) + 2.0_wp * (v(1:nd) - gam(a) * dN(1:nd, a) + &
                          mv(1:nd))) / h
          else
            dN(1:nd, a) = -N(a) * y(1:nd) / h
          end if
        end do
      end if
      lam(1:nd) = lh(1:nd) / h
    end block main
    ! On a singular J or no convergence, test whether x is outside the hull: λ·ξ_a < 0 for every
    ! candidate proves it (−λ separates x from them); otherwise, for small supports, a direct
    ! test (Carathéodory: x is in the hull iff it is in a simplex of d+1 candidates).
    if ((info == SHAPE_SINGULAR .or. info == SHAPE_NOT_CONVERGED) .and. qvalid) then
      if (separates(nd, nc, N, dN, lh)) then
        info = SHAPE_OUTSIDE_HULL
      else if (nact <= HULL_TEST_MAXN) then
        if (.not. in_simplex_hull(nd, nc, N, dN)) info = SHAPE_OUTSIDE_HULL
      end if
    end if
    if (info /= SHAPE_OK) then
      N(1:nc) = 0.0_wp
      dN(1:nd, 1:nc) = 0.0_wp
    end if

  contains

    !> γ of candidate a.
    pure real(wp) function gam(a)
      integer, intent(in) :: a !! candidate
      if (varying) then
        gam = gamma * gnode(node(a))
      else
        gam = gamma
      end if
    end function gam
  end subroutine lme_kernel

  !> True when λ·ξ_a < 0 for every active candidate (then −λ separates x from their hull).
  pure logical function separates(nd, nc, q, xi, lh)
    integer, intent(in) :: nd        !! spatial dimension
    integer, intent(in) :: nc        !! number of candidates
    real(wp), intent(in) :: q(:)     !! ≥ 0 (active), < 0 (inactive)
    real(wp), intent(in) :: xi(:,:)  !! ξ_a (nd, nc)
    real(wp), intent(in) :: lh(3)    !! λ·h
    integer :: a
    separates = .false.
    if (all(lh(1:nd) == 0.0_wp)) return
    do a = 1, nc
      if (q(a) < 0.0_wp) cycle
      if (dot_product(lh(1:nd), xi(1:nd, a)) >= 0.0_wp) return
    end do
    separates = .true.
  end function separates

  !> True when x (ξ = 0) lies in a closed simplex of d+1 active candidates, i.e. in their
  !> convex hull (Carathéodory), to within 1e-12 in barycentric coordinates. Failure path only.
  pure logical function in_simplex_hull(nd, nc, q, xi)
    integer, intent(in) :: nd        !! spatial dimension
    integer, intent(in) :: nc        !! number of candidates
    real(wp), intent(in) :: q(:)     !! ≥ 0 (active), < 0 (inactive)
    real(wp), intent(in) :: xi(:,:)  !! ξ_a (nd, nc)
    integer :: i, j, k, l
    in_simplex_hull = .true.
    select case (nd)
    case (1)
      in_simplex_hull = any(xi(1, 1:nc) >= 0.0_wp .and. q(1:nc) >= 0.0_wp) .and. &
                        any(xi(1, 1:nc) <= 0.0_wp .and. q(1:nc) >= 0.0_wp)
      return
    case (2)
      do i = 1, nc
        if (q(i) < 0.0_wp) cycle
        do j = i + 1, nc
          if (q(j) < 0.0_wp) cycle
          do k = j + 1, nc
            if (q(k) < 0.0_wp) cycle
            if (in_simplex(nd, xi(:, i), xi(:, j), xi(:, k), xi(:, k))) return
          end do
        end do
      end do
    case default
      do i = 1, nc
        if (q(i) < 0.0_wp) cycle
        do j = i + 1, nc
          if (q(j) < 0.0_wp) cycle
          do k = j + 1, nc
            if (q(k) < 0.0_wp) cycle
            do l = k + 1, nc
              if (q(l) < 0.0_wp) cycle
              if (in_simplex(nd, xi(:, i), xi(:, j), xi(:, k), xi(:, l))) return
            end do
          end do
        end do
      end do
    end select
    in_simplex_hull = .false.
  end function in_simplex_hull

  !> True when the origin lies in the closed simplex with vertices v0..v_nd (2D: v0, v1, v2;
  !> `v3` unused), to within 1e-12 in barycentric coordinates; false for a degenerate simplex.
  pure logical function in_simplex(nd, v0, v1, v2, v3)
    integer, intent(in) :: nd        !! spatial dimension, 2 or 3
    real(wp), intent(in) :: v0(:)    !! vertex
    real(wp), intent(in) :: v1(:)    !! vertex
    real(wp), intent(in) :: v2(:)    !! vertex
    real(wp), intent(in) :: v3(:)    !! vertex (3D only)
    real(wp) :: m(3, 3), minv(3, 3), b(3), mu(3), scl
    logical :: ok
    real(wp), parameter :: TOL = 1.0e-12_wp
    m = 0.0_wp; b = 0.0_wp
    m(1:nd, 1) = v1(1:nd) - v0(1:nd)
    m(1:nd, 2) = v2(1:nd) - v0(1:nd)
    if (nd == 3) m(1:nd, 3) = v3(1:nd) - v0(1:nd)
    b(1:nd) = -v0(1:nd)
    ! Solve M μ = −v0 through MᵀM (symmetric, for sym_inverse); degenerate simplices fail.
    call sym_inverse(nd, matmul_tn(nd, m), minv, scl, 1.0e14_wp, ok)
    in_simplex = .false.
    if (.not. ok) return
    mu = matvec(nd, minv, matvec_t(nd, m, b)) / scl
    in_simplex = all(mu(1:nd) >= -TOL) .and. sum(mu(1:nd)) <= 1.0_wp + TOL
  end function in_simplex

  !> MᵀM for the leading nd×nd block.
  pure function matmul_tn(nd, m) result(c)
    integer, intent(in) :: nd        !! dimension
    real(wp), intent(in) :: m(3, 3)  !! matrix
    real(wp) :: c(3, 3)              !! MᵀM (zero beyond nd)
    integer :: i, j
    c = 0.0_wp
    do j = 1, nd
      do i = 1, nd
        c(i, j) = sum(m(1:nd, i) * m(1:nd, j))
      end do
    end do
  end function matmul_tn

  !> Mᵀv for the leading nd×nd block.
  pure function matvec_t(nd, m, v) result(y)
    integer, intent(in) :: nd        !! dimension
    real(wp), intent(in) :: m(3, 3)  !! matrix
    real(wp), intent(in) :: v(3)     !! vector
    real(wp) :: y(3)                 !! product (zero beyond nd)
    integer :: i
    y = 0.0_wp
    do i = 1, nd
      y(i) = sum(m(1:nd, i) * v(1:nd))
    end do
  end function matvec_t

  !> log Z, r and J at λ (units of h) for the active candidates (w(a) ≥ 0), with the exponent
  !> f_a = −γ_a|ξ_a|² + λ·ξ_a shifted by its maximum; on return w(a) = exp(f_a − max f) for
  !> the active candidates (reused for the final values). The moments are taken about c = ξ of
  !> the heaviest node, so that J = Σ p (ξ − c)⊗(ξ − c) − (r − c)⊗(r − c) has no cancellation
  !> when that node carries nearly all the weight (large γ, far from λ*).
  pure subroutine moments(nd, nc, gamma, w, xi, lh, logz, r, jm, c, gnode, node)
    integer, intent(in) :: nd                  !! spatial dimension
    integer, intent(in) :: nc                  !! number of candidates
    real(wp), intent(in) :: gamma              !! γ (uniform), or the factor of gnode
    real(wp), intent(inout) :: w(:)            !! in: ≥ 0 active, < 0 inactive; out: weights
    real(wp), intent(in) :: xi(:,:)            !! ξ_a (nd, nc)
    real(wp), intent(in) :: lh(3)              !! λ·h
    real(wp), intent(out) :: logz              !! log Z
    real(wp), intent(out) :: r(3)              !! r = Σ p ξ
    real(wp), intent(out) :: jm(3, 3)          !! J = Σ p ξ⊗ξ − r⊗r
    real(wp), intent(out) :: c(3)              !! centre of the moments (ξ of the heaviest node)
    real(wp), intent(in), optional :: gnode(:) !! γ per grid node
    integer, intent(in), optional :: node(:)   !! grid node of each candidate
    real(wp) :: fmax, f, e, s, sr(3), sj(3, 3), u(3), fa(MOM_BUF)
    integer :: a, i, amax
    logical :: varying
    varying = present(gnode) .and. present(node)
    fmax = -huge(1.0_wp)
    amax = 0
    s = 0.0_wp; sr = 0.0_wp; sj = 0.0_wp; u = 0.0_wp
    c = 0.0_wp
    if (nd == 2 .and. .not. varying .and. nc <= MOM_BUF) then
      ! The hot case, with scalars: the general loop's expressions, without its short
      ! assumed-shape loops (same results, except sj(1, 2), summed here as Σ(e u1)u2 and
      ! there as Σ(e u2)u1: they may differ in the last bit); the exponents are kept for the
      ! second pass rather than recomputed.
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        f = -(gamma * (xi(1, a) * xi(1, a) + xi(2, a) * xi(2, a))) + &
            (lh(1) * xi(1, a) + lh(2) * xi(2, a))
        fa(a) = f
        if (f > fmax) then
          fmax = f
          amax = a
        end if
      end do
      if (amax > 0) c(1:2) = xi(1:2, amax)
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        e = exp(fa(a) - fmax)
        w(a) = e
        s = s + e
        u(1) = xi(1, a) - c(1)
        u(2) = xi(2, a) - c(2)
        sr(1) = sr(1) + e * u(1)
        sr(2) = sr(2) + e * u(2)
        sj(1, 1) = sj(1, 1) + (e * u(1)) * u(1)
        sj(2, 1) = sj(2, 1) + (e * u(1)) * u(2)
        sj(2, 2) = sj(2, 2) + (e * u(2)) * u(2)
      end do
      sj(1, 2) = sj(2, 1)
    else
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        f = fexp(a)
        if (f > fmax) then
          fmax = f
          amax = a
        end if
      end do
      if (amax > 0) c(1:nd) = xi(1:nd, amax)
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        e = exp(fexp(a) - fmax)
        w(a) = e
        s = s + e
        u(1:nd) = xi(1:nd, a) - c(1:nd)
        sr(1:nd) = sr(1:nd) + e * u(1:nd)
        do i = 1, nd
          sj(1:nd, i) = sj(1:nd, i) + (e * u(i)) * u(1:nd)
        end do
      end do
    end if
    logz = fmax + log(s)
    sr = sr / s
    r = c + sr
    jm = 0.0_wp
    do i = 1, nd
      jm(1:nd, i) = sj(1:nd, i) / s - sr(1:nd) * sr(i)
    end do

  contains

    !> Exponent f_a (γ_a|ξ_a|² recomputed: a few flops, cheaper than storing it).
    pure real(wp) function fexp(a)
      integer, intent(in) :: a !! candidate
      real(wp) :: g
      g = gamma
      if (varying) g = gamma * gnode(node(a))
      fexp = -(g * sum(xi(1:nd, a)**2)) + dot_product(lh(1:nd), xi(1:nd, a))
    end function fexp
  end subroutine moments

  !> Inverse of a symmetric d×d matrix (d ≤ 3) scaled to unit Frobenius norm, by its adjugate:
  !> `ainv` = (a/na)⁻¹ with na = ‖a‖_F, so a⁻¹ = ainv/na (the scaling keeps a tiny but well-
  !> conditioned matrix usable without overflow). `ok` is false when na = 0 or the matrix is
  !> not positive definite to within the Frobenius condition `cond_max`.
  pure subroutine sym_inverse(nd, a, ainv, na, cond_max, ok)
    integer, intent(in) :: nd           !! dimension, 1..3
    real(wp), intent(in) :: a(3, 3)     !! matrix (leading nd×nd block used)
    real(wp), intent(out) :: ainv(3, 3) !! (a/na)⁻¹ (leading block; zero elsewhere)
    real(wp), intent(out) :: na         !! ‖a‖_F
    real(wp), intent(in) :: cond_max    !! largest accepted ‖a‖_F ‖adj a‖_F / det a
    logical, intent(out) :: ok          !! inverse computed
    real(wp) :: b(3, 3), adj(3, 3), det, nadj
    ainv = 0.0_wp
    ok = .false.
    na = frob(nd, a)
    if (.not. (na > 0.0_wp .and. na <= huge(na))) return
    ! Only the leading block is formed: b and adj beyond it are never read.
    if (nd == 2) then
      ! 2D with scalars (the hot case): the same expressions as the general code below.
      b(1, 1) = a(1, 1) / na; b(1, 2) = a(1, 2) / na; b(2, 2) = a(2, 2) / na
      adj(1, 1) = b(2, 2); adj(2, 2) = b(1, 1)
      adj(1, 2) = -b(1, 2); adj(2, 1) = -b(1, 2)
      det = b(1, 1) * b(2, 2) - b(1, 2) * b(1, 2)
      nadj = frob(2, adj)
      ok = det > 0.0_wp .and. det * cond_max > nadj
      if (ok) then
        ainv(1, 1) = adj(1, 1) / det; ainv(2, 1) = adj(2, 1) / det
        ainv(1, 2) = adj(1, 2) / det; ainv(2, 2) = adj(2, 2) / det
      end if
      return
    end if
    b(1:nd, 1:nd) = a(1:nd, 1:nd) / na
    select case (nd)
    case (1)
      adj(1, 1) = 1.0_wp
      det = b(1, 1)
    case (2)
      adj(1, 1) = b(2, 2); adj(2, 2) = b(1, 1)
      adj(1, 2) = -b(1, 2); adj(2, 1) = -b(1, 2)
      det = b(1, 1) * b(2, 2) - b(1, 2) * b(1, 2)
    case default
      adj(1, 1) = b(2, 2) * b(3, 3) - b(2, 3) * b(2, 3)
      adj(2, 2) = b(1, 1) * b(3, 3) - b(1, 3) * b(1, 3)
      adj(3, 3) = b(1, 1) * b(2, 2) - b(1, 2) * b(1, 2)
      adj(1, 2) = b(1, 3) * b(2, 3) - b(1, 2) * b(3, 3)
      adj(1, 3) = b(1, 2) * b(2, 3) - b(1, 3) * b(2, 2)
      adj(2, 3) = b(1, 2) * b(1, 3) - b(1, 1) * b(2, 3)
      adj(2, 1) = adj(1, 2); adj(3, 1) = adj(1, 3); adj(3, 2) = adj(2, 3)
      det = b(1, 1) * adj(1, 1) + b(1, 2) * adj(2, 1) + b(1, 3) * adj(3, 1)
    end select
    nadj = frob(nd, adj)
    ok = det > 0.0_wp .and. det * cond_max > nadj
    if (ok) ainv(1:nd, 1:nd) = adj(1:nd, 1:nd) / det
  end subroutine sym_inverse

  !> ‖a‖_F of the leading nd×nd block: sqrt of the plain sum of squares, falling back to the
  !> scaled (slower) norm2 when that sum may have under- or overflowed.
  pure real(wp) function frob(nd, a)
    integer, intent(in) :: nd        !! dimension, 1..3
    real(wp), intent(in) :: a(3, 3)  !! matrix
    real(wp) :: ss
    integer :: i, j
    if (nd == 2) then
      ! Same order as the loops (0 + a11² = a11² exactly).
      ss = a(1, 1)**2 + a(2, 1)**2 + a(1, 2)**2 + a(2, 2)**2
    else
      ss = 0.0_wp
      do j = 1, nd
        do i = 1, nd
          ss = ss + a(i, j)**2
        end do
      end do
    end if
    if (ss > SUMSQ_LO .and. ss < SUMSQ_HI) then
      frob = sqrt(ss)
    else
      frob = norm2(a(1:nd, 1:nd))
    end if
  end function frob

  !> |v| of the leading nd entries, as [[frob]].
  pure real(wp) function norm_small(nd, v)
    integer, intent(in) :: nd        !! dimension, 1..3
    real(wp), intent(in) :: v(3)     !! vector
    real(wp) :: ss
    integer :: i
    if (nd == 2) then
      ss = v(1)**2 + v(2)**2
    else
      ss = 0.0_wp
      do i = 1, nd
        ss = ss + v(i)**2
      end do
    end if
    if (ss > SUMSQ_LO .and. ss < SUMSQ_HI) then
      norm_small = sqrt(ss)
    else
      norm_small = norm2(v(1:nd))
    end if
  end function norm_small

  ! ---- helpers ------------------------------------------------------------------------------

  !> y = A v for the leading nd×nd block (explicit loops: no temporaries).
  pure function matvec(nd, a, v) result(y)
    integer, intent(in) :: nd        !! dimension, 1..3
    real(wp), intent(in) :: a(3, 3)  !! matrix
    real(wp), intent(in) :: v(3)     !! vector
    real(wp) :: y(3)                 !! product (zero beyond nd)
    integer :: i, j
    if (nd == 2) then
      ! The loops' sums in the same order (up to the sign of a zero result).
      y(1) = a(1, 1) * v(1) + a(1, 2) * v(2)
      y(2) = a(2, 1) * v(1) + a(2, 2) * v(2)
      y(3) = 0.0_wp
      return
    end if
    y = 0.0_wp
    do j = 1, nd
      do i = 1, nd
        y(i) = y(i) + a(i, j) * v(j)
      end do
    end do
  end function matvec

  !> Support radius h·sqrt(−ln tol0/γ) [length] (γ > 0, 0 < tol0 < 1).
  pure real(wp) function lme_support_radius(gamma, tol0, h) result(rr)
    real(wp), intent(in) :: gamma !! γ = β h²
    real(wp), intent(in) :: tol0  !! truncation tolerance
    real(wp), intent(in) :: h     !! nodal spacing [length]
    rr = h * sqrt(-log(tol0) / gamma)
  end function lme_support_radius

  !> γ in its shortest decimal form that reads back exactly: 3 → "3", 0.8 → "0.8".
  pure function lme_format_gamma(g) result(s)
    real(wp), intent(in) :: g           !! value
    character(len=:), allocatable :: s  !! text
    character(len=40) :: buf
    character(len=8) :: fmt
    real(wp) :: back
    integer :: d, ios
    do d = 0, 17
      write(fmt, '("(f0.",i0,")")') d
      write(buf, fmt, iostat=ios) g
      if (ios /= 0) exit
      read(buf, *, iostat=ios) back
      if (ios == 0 .and. back == g) then
        s = trim(adjustl(buf))
        if (s(len(s):len(s)) == '.') s = s(1:len(s) - 1)
        if (s(1:1) == '.') s = '0'//s
        return
      end if
    end do
    write(buf, '(es24.16e3)') g
    s = trim(adjustl(buf))
  end function lme_format_gamma

  !> Spacing h of γ = β h²: the largest grid spacing.
  pure real(wp) function lme_h(grid)
    type(empm_grid_t), intent(in) :: grid !! background grid
    lme_h = maxval(grid%h(1:grid%ndim))
  end function lme_h

  !> Smallest γ in use (node-wise when set).
  pure real(wp) function gamma_lowest(self)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    if (allocated(self%gamma_node)) then
      gamma_lowest = self%gamma_min
    else
      gamma_lowest = self%gamma
    end if
  end function gamma_lowest

  !> Parameters usable on `grid`.
  pure logical function params_ok(self, grid)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    params_ok = grid%ndim >= 1 .and. grid%ndim <= 3 .and. self%gamma > 0.0_wp .and. &
                self%tol0 > 0.0_wp .and. self%tol0 < 1.0_wp .and. self%max_iter >= 1
    if (params_ok .and. allocated(self%gamma_node)) &
      params_ok = size(self%gamma_node) == grid%nnode .and. self%gamma_min > 0.0_wp
  end function params_ok
end module empm_shape_lme
