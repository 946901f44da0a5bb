!> Local maximum-entropy (LME) shape functions (Arroyo & Ortiz 2006; docs/shape-functions.md).
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
!> Converged when |r| < `LME_TOL_CONV`, i.e. ‖r_phys‖/h < 1e-10, or (3D with uniform γ, after
!> no guarded step) when a bound proves the residual after the final linearised step below it,
!> as in the batch's lean paths. The moments r and J are
!> accumulated about ξ of the heaviest node, so that J has no cancellation when one node carries
!> nearly all the weight (large γ far from λ*, where J is tiny but well conditioned).
!>
!> **Final linearised step.** With Δ = −J⁻¹r at convergence, p̃_a = p_a (1 + (ξ_a − r)·Δ) is p
!> at λ + Δ to first order (error O(|Δ|²): < 1e-18 after ‖r‖ < 1e-10, < 1e-10 after the
!> bound), costs no exponential, and makes Σp̃ = 1 and
!> Σ p̃ ξ = 0 (linear reproduction) hold to round-off instead of to the tolerance 1e-10. It is
!> skipped when some factor 1 + (ξ_a − r)·Δ could fall below 1/2 (points within ~1e-9 h of the
!> hull boundary), where reproduction then holds to 1e-10 h. The returned p are the p̃, and
!> r, J below are their moments (r ≈ 1e-16).
!>
!> **Warm starts.** `eval_batch` starts a particle from 2λ_n − λ_(n−1), or, when its λ changed
!> by more than `LME_START_MOVE`/h in its last step, from `start_tab` (the one-dimensional
!> problems' multipliers, built by `configure`; docs/shape-functions.md, "Warm starts of moving
!> particles").
!>
!> **Lean batch paths.** `eval_batch` in 2D and 3D with uniform γ uses `lme_point_2d` and
!> `lme_point_3d`: the same algorithm in three passes over the support (3D: a fourth for its
!> third moments), stopping Newton early when a bound proves the residual after the final step
!> below the tolerance, with values made exactly consistent by a 2×2 or 3×3 solve
!> (docs/shape-functions.md, "The lean batch paths"); anything unusual falls back to the
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
!>
!> **Files.** This module holds the type, the constants and the interfaces; the procedures are
!> in its submodules, one file each: `empm_shape_lme_setup` (parameters, `configure`, name,
!> storage bound, node-wise γ), `empm_shape_lme_batch` (`eval_point`, `eval_batch` with the
!> lean 2D and 3D paths, and the remedy), `empm_shape_lme_newton` (the general path: candidates, the
!> guarded Newton kernel, the parameter helpers) and its child `empm_shape_lme_hull` (the hull
!> tests of the failure path, which share the kernel's small linear algebra). Procedures that
!> call each other per particle are kept in one file, and the lean paths' kernels are internal
!> procedures of the batch routine: gfortran gives submodule procedures external linkage, and
!> in the position-independent library GCC then assumes they may be interposed, so it neither
!> inlines nor specialises calls to them, even from their own file.
module empm_shape_lme
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t
  use empm_namelist, only: empm_group_t
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_shape, only: empm_shape_t, empm_basis_t
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
  real(wp), parameter :: LME_ARMIJO_C = 1.0e-4_wp   !! Armijo sufficient-decrease constant
  real(wp), parameter :: LME_COND_MAX = 1.0e12_wp   !! largest accepted Frobenius condition of J
  real(wp), parameter :: LME_J_MIN = 1.0e-14_wp     !! smallest accepted ‖J‖_F (units of h²)
  real(wp), parameter :: LME_STEP_MAX = 10.0_wp     !! largest Newton step |Δλ|·h
  real(wp), parameter :: LME_LAM_MAX = 1.0e3_wp     !! |λ|·h beyond this: λ diverges
  integer, parameter :: LME_MAXIT_DEFAULT = 100     !! default Newton iteration cap
  !> Range of a sum of squares in which sqrt(sum) is accurate (no under- or overflow).
  real(wp), parameter :: SUMSQ_LO = 1.0e-280_wp, SUMSQ_HI = 1.0e280_wp
  !> Iteration count returned by `lme_point_2d` and `lme_point_3d` when the general path must
  !> take over.
  integer, parameter :: LME_FALLBACK = -1
  !> Intervals of a cell in the warm-start table (`start_tab`).
  integer, parameter :: LME_START_N = 512
  !> A particle whose λh changed by more than this in its last step starts from the table
  !> instead of the extrapolation 2λ_n − λ_(n−1) (which is then no longer the closer start).
  real(wp), parameter :: LME_START_MOVE = 1.0e-3_wp

  !> Local max-ent shape functions with uniform or node-wise γ.
  !>
  !> Parameters are declared by `params` and read from a `&shape` group by `configure`;
  !> programs may also set them directly, e.g. `empm_shape_lme_t(gamma=0.8_wp, tol0=1e-8_wp)`.
  type, extends(empm_shape_t) :: empm_shape_lme_t
    real(wp) :: gamma = 3.0_wp                 !! γ = β h² (uniform value)
    real(wp) :: tol0 = 1.0e-6_wp               !! truncation tolerance of the weights, 0 < tol0 < 1
    integer :: max_iter = LME_MAXIT_DEFAULT    !! Newton iteration cap
    integer :: remedy = LME_REMEDY_NONE        !! LME_REMEDY_NONE or LME_REMEDY_ENLARGE
    !> Node-wise γ (grid%nnode), replacing `gamma` when allocated; set it with
    !> `set_gamma_nodes` or `set_gamma_box`, which also keep `gamma_min` up to date.
    real(wp), allocatable :: gamma_node(:)
    real(wp) :: gamma_min = 0.0_wp             !! min of gamma_node (set with gamma_node)
    !> Warm starts of moving particles (uniform γ; built by `configure`, absent otherwise):
    !> column k holds λ_k h of the one-dimensional problem of direction k, whose product over
    !> the directions solves the problem on the whole box of candidates, at LME_START_N + 1
    !> evenly spaced points of a cell (docs/shape-functions.md, "Warm starts").
    real(wp), allocatable :: start_tab(:,:)
    real(wp) :: start_h(3) = 0.0_wp            !! grid spacings the table was built for
    real(wp) :: start_gamma = 0.0_wp           !! γ the table was built for
    real(wp) :: start_tol0 = 0.0_wp            !! tol0 the table was built for
  contains
    procedure :: max_nodes => lme_max_nodes
    procedure :: eval_point => lme_eval_point
    procedure :: eval_batch => lme_eval_batch
    procedure :: name => lme_name
    procedure :: family => lme_family
    procedure :: summary => lme_summary
    procedure :: params => lme_params
    procedure :: configure => lme_configure
    procedure :: eval_point_iters => lme_eval_point_iters
    procedure :: eval_batch_iters => lme_eval_batch_iters
    procedure :: set_gamma_nodes => lme_set_gamma_nodes
    procedure :: set_gamma_box => lme_set_gamma_box
    procedure :: support_radius => lme_radius
    procedure :: reach_cells => lme_reach_cells
    procedure :: node_data => lme_node_data
  end type empm_shape_lme_t

  interface
    ! ---- empm_shape_lme_setup: parameters, name, storage bound, node-wise γ -------------------

    !> Upper bound on supporting nodes: the lattice nodes within R_max of some point of one cell
    !> (R_max from the smallest γ, including the remedy's); 0 for invalid parameters.
    module pure integer function lme_max_nodes(self, grid)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid       !! background grid
    end function lme_max_nodes

    !> Registry name of the family.
    module pure function lme_family(self) result(s)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      character(len=:), allocatable :: s !! name
    end function lme_family

    !> One-line description of the family.
    module pure function lme_summary(self) result(s)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      character(len=:), allocatable :: s          !! summary
    end function lme_summary

    !> Declared parameters of the `&shape` group: gamma, tol0, remedy, gamma_inside,
    !> gamma_box_lo, gamma_box_hi.
    module pure function lme_params(self) result(p)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      type(empm_param_t), allocatable :: p(:)     !! declarations
    end function lme_params

    !> Read and validate the parameters from `group` (absent keys take their defaults), with
    !> the combinations: `gamma_inside` needs both box corners with `grid%ndim` coordinates each
    !> and `gamma_box_hi` ≥ `gamma_box_lo`; box corners need `gamma_inside`. Node-wise γ is set
    !> on `grid`. On an error `err` names the key and `self` may be partly configured.
    module subroutine lme_configure(self, grid, group, err)
      class(empm_shape_lme_t), intent(inout) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid          !! background grid
      type(empm_group_t), intent(inout) :: group     !! the `&shape` group
      type(empm_error_t), intent(inout) :: err       !! set on invalid parameters
    end subroutine lme_configure

    !> Family identifier: "lme_g" and γ in its shortest decimal form, e.g. "lme_g3", "lme_g0.8".
    module function lme_name(self) result(s)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      character(len=:), allocatable :: s          !! identifier
    end function lme_name

    !> Whether γ is set per node (`set_gamma_nodes`, `set_gamma_box`): indexed by node id.
    module pure logical function lme_node_data(self)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
    end function lme_node_data

    !> Cells beyond a particle's own that its support reaches: ⌈R_max/h⌉ with the remedy's
    !> enlargement (0 for invalid parameters).
    module pure integer function lme_reach_cells(self, grid) result(n)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid       !! background grid
    end function lme_reach_cells

    !> Support radius R_max = h·sqrt(−ln tol0 / γ_min) [length], h the largest grid spacing
    !> (without the remedy's enlargement); 0 for invalid parameters.
    module pure real(wp) function lme_radius(self, grid) result(rr)
      class(empm_shape_lme_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid       !! background grid
    end function lme_radius

    !> Set node-wise γ from an array of grid%nnode positive values; info = 1 (nothing changed)
    !> for a wrong size or a value that is not positive and finite.
    module subroutine lme_set_gamma_nodes(self, grid, gamma_node, info)
      class(empm_shape_lme_t), intent(inout) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid          !! background grid
      real(wp), intent(in) :: gamma_node(:)          !! γ per node (grid%nnode)
      integer, intent(out) :: info                   !! 0 ok, 1 invalid
    end subroutine lme_set_gamma_nodes

    !> Node-wise γ: `gamma_inside` for the nodes in the closed box [lo, hi] (within 1e-9 h),
    !> `self%gamma` elsewhere. info = 1 (nothing changed) if a value is not positive.
    module subroutine lme_set_gamma_box(self, grid, lo, hi, gamma_inside, info)
      class(empm_shape_lme_t), intent(inout) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid          !! background grid
      real(wp), intent(in) :: lo(:)                  !! lower corner of the box (ndim) [length]
      real(wp), intent(in) :: hi(:)                  !! upper corner of the box (ndim) [length]
      real(wp), intent(in) :: gamma_inside           !! γ of the nodes inside the box
      integer, intent(out) :: info                   !! 0 ok, 1 invalid
    end subroutine lme_set_gamma_box

    !> Support radius h·sqrt(−ln tol0/γ) [length] (γ > 0, 0 < tol0 < 1).
    module pure real(wp) function lme_support_radius(gamma, tol0, h) result(rr)
      real(wp), intent(in) :: gamma !! γ = β h²
      real(wp), intent(in) :: tol0  !! truncation tolerance
      real(wp), intent(in) :: h     !! nodal spacing [length]
    end function lme_support_radius

    !> γ in its shortest decimal form that reads back exactly: 3 → "3", 0.8 → "0.8".
    module pure function lme_format_gamma(g) result(s)
      real(wp), intent(in) :: g           !! value
      character(len=:), allocatable :: s  !! text
    end function lme_format_gamma

    ! ---- empm_shape_lme_batch: one point, all particles, the remedy ---------------------------

    !> Values and gradients at one point; `lam` is the warm start λ (1/length), updated on success.
    module subroutine lme_eval_point(self, grid, x, lp, lam, nn, node, N, dN, info)
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
    end subroutine lme_eval_point

    !> As `eval_point`, also returning the number of Newton iterations (of the last attempt).
    module subroutine lme_eval_point_iters(self, grid, x, lam, nn, node, N, dN, info, iters)
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
    end subroutine lme_eval_point_iters

    !> Values and gradients at particles 1..pts%np, warm-started by extrapolation from `pts%lam`
    !> and `pts%lam_old` (the last two converged multipliers) and updating both; a particle
    !> that fails from that start is retried from λ_n, then cold, before it counts as failed.
    !> Reports the first failing particle.
    module subroutine lme_eval_batch(self, grid, pts, basis, ibad, info)
      class(empm_shape_lme_t), intent(in) :: self  !! shape family
      type(empm_grid_t), intent(in) :: grid        !! background grid
      type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
      type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
      integer, intent(out) :: ibad                 !! first failing particle, 0 if none
      integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    end subroutine lme_eval_batch

    !> As `eval_batch`, also returning the total number of Newton iterations.
    module subroutine lme_eval_batch_iters(self, grid, pts, basis, ibad, info, iters)
      class(empm_shape_lme_t), intent(in) :: self  !! shape family
      type(empm_grid_t), intent(in) :: grid        !! background grid
      type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
      type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
      integer, intent(out) :: ibad                 !! first failing particle, 0 if none
      integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
      integer, intent(out) :: iters                !! Newton iterations summed over the particles
    end subroutine lme_eval_batch_iters

    !> Build `start_tab` for `grid` (uniform γ and valid parameters with 2 to 64 nodes across
    !> the support in each direction; otherwise none).
    module subroutine lme_build_start(self, grid)
      class(empm_shape_lme_t), intent(inout) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid          !! background grid
    end subroutine lme_build_start

    ! ---- empm_shape_lme_newton: the general path and the parameter helpers it inlines ---------

    !> Spacing h of γ = β h²: the largest grid spacing.
    module pure real(wp) function lme_h(grid)
      type(empm_grid_t), intent(in) :: grid !! background grid
    end function lme_h

    !> Smallest γ in use (node-wise when set).
    module pure real(wp) function gamma_lowest(self)
      type(empm_shape_lme_t), intent(in) :: self !! shape family
    end function gamma_lowest

    !> Parameters usable on `grid`.
    module pure logical function params_ok(self, grid)
      type(empm_shape_lme_t), intent(in) :: self !! shape family
      type(empm_grid_t), intent(in) :: grid      !! background grid
    end function params_ok

    !> One point with every γ multiplied by `scale`: candidates through the grid, then the kernel.
    module pure subroutine lme_point(self, grid, x, lam, scale, nn, node, N, dN, iters, info)
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
    end subroutine lme_point

    !> LME values and gradients at a point from its candidate nodes.
    !>
    !> On entry `dN(1:nd, a)` holds ξ_a = (x − x_a)/h for the `nc` candidates; on exit `N(a)` and
    !> `dN(:, a)` hold p_a and ∇p_a. Candidates with γ_a|ξ_a|² > −ln tol0 (beyond their support
    !> radius) get p_a = 0 and ∇p_a = 0. γ_a = `gamma` · gnode(node(a)) when `gnode` and `node`
    !> are present, else `gamma`. On failure N = 0, dN = 0 and `lam` is unchanged.
    module pure subroutine lme_kernel(nd, nc, gamma, tol0, h, maxit, lam, N, dN, iters, info, &
                                      gnode, node)
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
    end subroutine lme_kernel

    ! ---- empm_shape_lme_hull: hull tests of the failure path ----------------------------------

    !> True when λ·ξ_a < 0 for every active candidate (then −λ separates x from their hull).
    module pure logical function separates(nd, nc, q, xi, lh)
      integer, intent(in) :: nd        !! spatial dimension
      integer, intent(in) :: nc        !! number of candidates
      real(wp), intent(in) :: q(:)     !! ≥ 0 (active), < 0 (inactive)
      real(wp), intent(in) :: xi(:,:)  !! ξ_a (nd, nc)
      real(wp), intent(in) :: lh(3)    !! λ·h
    end function separates

    !> True when x (ξ = 0) lies in a closed simplex of d+1 active candidates, i.e. in their
    !> convex hull (Carathéodory), to within 1e-12 in barycentric coordinates. Failure path only.
    module pure logical function in_simplex_hull(nd, nc, q, xi)
      integer, intent(in) :: nd        !! spatial dimension
      integer, intent(in) :: nc        !! number of candidates
      real(wp), intent(in) :: q(:)     !! ≥ 0 (active), < 0 (inactive)
      real(wp), intent(in) :: xi(:,:)  !! ξ_a (nd, nc)
    end function in_simplex_hull

    !> True when a lattice node within `rmax` of x lies beyond the grid.
    module pure logical function clipped(grid, x, rmax)
      type(empm_grid_t), intent(in) :: grid !! background grid
      real(wp), intent(in) :: x(:)          !! point (inside the grid)
      real(wp), intent(in) :: rmax          !! support radius [length]
    end function clipped
  end interface
end module empm_shape_lme
