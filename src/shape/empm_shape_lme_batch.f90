!> LME evaluation entry points: one point (`eval_point`), every particle (`eval_batch`: the
!> particle-parallel loop with the extrapolated warm start and the lean 2D and 3D paths) and
!> the 'enlarge' remedy around the general path.
!>
!> The lean paths (`lme_point_2d` and `lme_point_3d`, with their fused weight-and-moment passes
!> `weights_2d` and `weights_3d` and small inverses) are made of internal procedures of the
!> batch routine: local to this file, so the compiler inlines them into the particle loop and
!> calls the others directly, as it did when LME was one module. (Submodule procedures have external linkage;
!> in the position-independent library that blocks inlining and specialisation.)
submodule (empm_shape_lme) empm_shape_lme_batch
  use empm_parallel, only: EMPM_OMP_MIN_PARTICLES
  use empm_shape, only: SHAPE_OK, SHAPE_SUPPORT_CLIPPED, SHAPE_NOT_CONVERGED, SHAPE_OUTSIDE_HULL, &
                        SHAPE_SINGULAR, SHAPE_OUTSIDE_GRID, SHAPE_TOO_MANY_NODES
  use empm_shape_linear, only: shape_batch_fits, shape_keep_first_failure
  implicit none

  !> Most candidates of the lean paths, whose γ|ξ_a|² they keep on the stack (8 kB, small
  !> enough for a caller's thread stacks) for the Newton steps' exponents: with γ below about
  !> 0.04 in 2D or 0.35 in 3D the general path takes the point.
  integer, parameter :: LEAN_MAX = 1024

contains

  module procedure lme_eval_point
    integer :: iters
    associate (unused_lp_ => lp); end associate
    call lme_point_retry(self, grid, x, lam, nn, node, N, dN, iters, info)
    if (info /= SHAPE_OK .and. self%remedy == LME_REMEDY_ENLARGE) &
      call lme_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
  end procedure lme_eval_point

  module procedure lme_eval_point_iters
    call lme_point_retry(self, grid, x, lam, nn, node, N, dN, iters, info)
    if (info /= SHAPE_OK .and. self%remedy == LME_REMEDY_ENLARGE) &
      call lme_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
  end procedure lme_eval_point_iters

  module procedure lme_eval_batch
    integer :: iters
    call lme_batch(self, grid, pts, basis, ibad, info, iters)
  end procedure lme_eval_batch

  module procedure lme_eval_batch_iters
    call lme_batch(self, grid, pts, basis, ibad, info, iters)
  end procedure lme_eval_batch_iters

  !> Batch loop without polymorphic calls: per particle `lme_point_2d` (2D, uniform γ) or
  !> [[lme_point]], then [[lme_remedy]] after a failure when enabled.
  subroutine lme_batch(self, grid, pts, basis, ibad, info, iters)
    type(empm_shape_lme_t), intent(in) :: self   !! shape family
    type(empm_grid_t), intent(in) :: grid        !! background grid
    type(empm_particles_t), intent(inout) :: pts !! particles (λ updated)
    type(empm_basis_t), intent(inout) :: basis   !! filled for particles 1..pts%np
    integer, intent(out) :: ibad                 !! first failing particle, 0 if none
    integer, intent(out) :: info                 !! SHAPE_OK or the failing particle's code
    integer, intent(out) :: iters                !! total Newton iterations
    integer :: p, it, pinfo, nd, k
    real(wp) :: lam(3), hs, cut, rmax
    logical :: fast, table
    iters = 0
    call shape_batch_fits(pts%np, basis, ibad, info)
    if (info /= SHAPE_OK) return
    nd = grid%ndim
    ! The lean paths need 2D or 3D, uniform γ and valid parameters (a support larger than the
    ! storage falls back, and the general path reports it).
    fast = (nd == 2 .or. nd == 3) .and. .not. allocated(self%gamma_node) .and. &
      params_ok(self, grid)
    hs = lme_h(grid)
    cut = -log(self%tol0)
    rmax = sqrt(cut / self%gamma) * hs
    ! The warm-start table applies to the grid and parameters it was built for (γ and tol0 may
    ! be set directly after `configure`).
    table = allocated(self%start_tab) .and. .not. allocated(self%gamma_node)
    if (table) table = size(self%start_tab, 2) == nd .and. self%start_gamma == self%gamma &
      .and. self%start_tol0 == self%tol0
    if (table) table = all(self%start_h(1:nd) == grid%h(1:nd))
    ! Particles are independent: threads share them; the first failure (lowest index) is kept.
    ibad = huge(1)
    !$omp parallel do default(none) schedule(static) &
    !$omp   shared(self, grid, pts, basis, fast, table, nd, hs, cut, rmax, ibad, info) &
    !$omp   private(pinfo, it, lam, k) reduction(+: iters) if(pts%np >= EMPM_OMP_MIN_PARTICLES)
    do p = 1, pts%np
      ! What this evaluation starts from, kept so that it can be repeated exactly.
      pts%lam_prev(:, p) = pts%lam(:, p); pts%lam_old_prev(:, p) = pts%lam_old(:, p)
      ! Warm start extrapolated from the last two converged multipliers: in a smooth motion
      ! λ* changes smoothly, so 2λ_n − λ_(n−1) is off by O(Δx²) and one Newton step usually
      ! reaches the tolerance (the plain warm start λ_n needs two). lam_old = huge marks a
      ! particle without a converged history yet (set at generation): plain warm start.
      ! A particle that moved (its λ changed by more than LME_START_MOVE/h in its last step)
      ! starts from the table when there is one (`start_tab`): the extrapolation is off by
      ! O(Δλ²), the table by about tol0 wherever the particle is.
      if (pts%lam_old(1, p) == huge(1.0_wp)) then
        lam(1:nd) = pts%lam(:, p)
      else
        lam(1:nd) = 2.0_wp * pts%lam(:, p) - pts%lam_old(:, p)
        if (table) then
          if (maxval(abs(pts%lam(:, p) - pts%lam_old(:, p))) * hs > LME_START_MOVE) &
            call table_start(pts%x(:, p), lam)
        end if
      end if
      it = LME_FALLBACK
      if (fast) then
        if (nd == 2) then
          call lme_point_2d(grid, pts%x(:, p), self%gamma, cut, hs, rmax, self%max_iter, lam, &
            basis%maxn, basis%nn(p), basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), it)
        else
          call lme_point_3d(grid, pts%x(:, p), self%gamma, cut, hs, rmax, self%max_iter, lam, &
            basis%maxn, basis%nn(p), basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), it)
        end if
      end if
      if (it == LME_FALLBACK) then
        ! Anything unusual: the guarded general path, from the same warm start. (The remedy is
        ! a separate call after a failure: the common call passes its arrays once.)
        call lme_point(self, grid, pts%x(:, p), lam(1:nd), 1.0_wp, basis%nn(p), &
                       basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), it, pinfo)
        ! A failed warm start is not a failed basis: near a face λ* grows like ln(1/ε), so the
        ! extrapolation can overshoot into a region where J is numerically singular while a
        ! nearer start converges. Retry from λ_n, then cold (λ = 0), before reporting.
        do k = 1, 2
          if (pinfo == SHAPE_OK .or. pinfo == SHAPE_OUTSIDE_GRID .or. &
              pinfo == SHAPE_TOO_MANY_NODES) exit
          if (k == 1) then
            if (pts%lam_old(1, p) == huge(1.0_wp)) cycle  ! the first attempt started from λ_n
            lam(1:nd) = pts%lam(:, p)
          else
            lam(1:nd) = 0.0_wp
          end if
          iters = iters + it
          call lme_point(self, grid, pts%x(:, p), lam(1:nd), 1.0_wp, basis%nn(p), &
                         basis%node(:, p), basis%N(:, p), basis%dN(:, :, p), it, pinfo)
        end do
        if (pinfo /= SHAPE_OK .and. self%remedy == LME_REMEDY_ENLARGE) &
          call lme_remedy(self, grid, pts%x(:, p), lam(1:nd), basis%nn(p), basis%node(:, p), &
                          basis%N(:, p), basis%dN(:, :, p), it, pinfo)
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

  contains

    !> λ at x from `start_tab` (linear interpolation in each direction), when the box of
    !> candidates lies inside the grid in every direction; `lam` is left as it is otherwise
    !> (near a face λ* grows without bound and the one-dimensional problem is another one).
    pure subroutine table_start(x, lam)
      real(wp), intent(in) :: x(:)         !! point (nd)
      real(wp), intent(inout) :: lam(3)    !! start [1/length]
      real(wp) :: s, t, w, rd, l(3)
      integer :: k, j
      do k = 1, nd
        s = (x(k) - grid%origin(k)) * grid%inv_h(k)
        rd = rmax * grid%inv_h(k)
        if (.not. (s - rd >= 0.0_wp .and. s + rd <= grid%ncell(k))) return
        t = (s - aint(s)) * LME_START_N
        j = min(int(t), LME_START_N - 1)
        w = t - j
        l(k) = (1.0_wp - w) * self%start_tab(j, k) + w * self%start_tab(j + 1, k)
      end do
      lam(1:nd) = l(1:nd) / hs
    end subroutine table_start

    !> The common case, lean: 2D, uniform γ, a warm start near λ*. The same basis as
    !> [[lme_point]] (to the Newton tolerance), with the work fused into three passes over the
    !> support: one finds the candidates (all active, since the box is filtered by
    !> γ|ξ|² ≤ −ln tol0) and their exponents, one evaluates the weights and their moments up to
    !> third order (about the heaviest node), one writes values and gradients. Newton stops as
    !> soon as a bound proves the residual after the final linearised step below the tolerance;
    !> the moments of the final values follow from the third moments without another pass over
    !> the nodes (docs/shape-functions.md, "The lean batch paths"). Only full Newton steps are
    !> taken here: whenever the general path could do something else (point outside the grid,
    !> ‖r‖ above the Armijo threshold, ill-conditioned J, a step or λ beyond its cap, the
    !> iteration cap, too few candidates or x outside their bounding box), `iters` returns
    !> `LME_FALLBACK` and the caller starts [[lme_point]] over.
    pure subroutine lme_point_2d(grid, x, gamma, cut, h, rmax, maxit, lam, cap, nn, node, N, &
                                 dN, iters)
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
      real(wp) :: slope, logz0, xi22
      ! Widest box of candidate columns kept (a wider one, with γ below about 0.015 on square
      ! cells and tol0 = 1e-6, or cells much narrower in x than h, falls back to the general
      ! path).
      integer, parameter :: BOX_MAX = 64
      real(wp) :: xr(BOX_MAX), xr2(BOX_MAX)
      real(wp) :: qa(LEAN_MAX) ! γ|ξ_a|² of each candidate (the value the Newton steps need)
      integer :: lo1, hi1, lo2, hi2, i, j, id0, a, amax, it
      logical :: guard, far
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
      ! ξ₁ and ξ₁² of the box's columns once, not in every row: the same values (the same
      ! expressions), without a division per node.
      if (hi1 - lo1 >= BOX_MAX) return
      do i = lo1, hi1
        xr(i - lo1 + 1) = (x(1) - (grid%origin(1) + i * grid%h(1))) / h
        xr2(i - lo1 + 1) = xr(i - lo1 + 1)**2
      end do
      do j = lo2, hi2
        xi2 = (x(2) - (grid%origin(2) + j * grid%h(2))) / h
        xi22 = xi2**2
        id0 = grid%id0 + grid%ln(1) * j
        do i = lo1, hi1
          xi1 = xr(i - lo1 + 1)
          q = gamma * (xr2(i - lo1 + 1) + xi22)
          if (q > cut) cycle
          if (nn == cap .or. nn == LEAN_MAX) return
          nn = nn + 1
          qa(nn) = q
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
      far = .false.
      c1 = dN(1, amax); c2 = dN(2, amax)
      call weights_2d(nn, fmax, c1, c2, dN, N, sw, m1, m2, m3, logz, r, jm)
      do
        ! Newton step Δ = −J⁻¹r, full steps only.
        rn = sqrt(r(1)**2 + r(2)**2)
        if (logz < -qmax - 1.0e-9_wp * (1.0_wp + qmax)) return
        call inverse_2d(jm, ji, scl)
        if (scl < LME_J_MIN) return
        d1 = -(ji(1) * r(1) + ji(2) * r(2)) / scl
        d2 = -(ji(2) * r(1) + ji(3) * r(2)) / scl
        dn2 = d1**2 + d2**2
        ! Done when r(λ+Δ), bounded by ½ (ξmax + ‖r‖)³ |Δ|², is within the tolerance; after a
        ! far start (a step under the Armijo test) only on ‖r‖ itself, as the general path,
        ! whose result (p* to O(1e-20)) a far start then reproduces to round-off.
        if (rn < LME_TOL_CONV) exit
        if (.not. far .and. 0.5_wp * (sqrt(x2max) + rn)**3 * dn2 < LME_TOL_CONV) exit
        if (it >= maxit .or. dn2 > LME_STEP_MAX**2) return
        ! Far from λ* the general path takes the full step only when it decreases log Z enough
        ! (Armijo, its first trial): the same test below on the new weights, else hand over.
        guard = rn > LME_TOL_GUARD
        if (guard) then
          slope = r(1) * d1 + r(2) * d2; logz0 = logz; far = .true.
        end if
        l1 = l1 + d1; l2 = l2 + d2
        it = it + 1
        if (.not. (abs(l1) <= LME_LAM_MAX .and. abs(l2) <= LME_LAM_MAX)) return
        fmax = -huge(1.0_wp); amax = 0
        do a = 1, nn
          f = -qa(a) + (l1 * dN(1, a) + l2 * dN(2, a))
          N(a) = f
          if (f > fmax) then
            fmax = f; amax = a
          end if
        end do
        c1 = dN(1, amax); c2 = dN(2, amax)
        call weights_2d(nn, fmax, c1, c2, dN, N, sw, m1, m2, m3, logz, r, jm)
        if (guard) then
          if (.not. (logz <= logz0 + LME_ARMIJO_C * slope)) return
        end if
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
      if (far) then
        lam(1) = l1 / h; lam(2) = l2 / h ! the general path's λ: its last iterate
      else
        lam(1) = (l1 + d1) / h; lam(2) = (l2 + d2) / h
      end if
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
      ! The exponentials in a loop of their own, as in weights_3d: the vector exp call inside
      ! the summing loop made its ten accumulators spill around every pair of nodes.
      do b = 1, nn
        w(b) = exp(w(b) - fm)
      end do
      sw = 0.0_wp; m1 = 0.0_wp; m2 = 0.0_wp; m3 = 0.0_wp
      do b = 1, nn
        e = w(b)
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

    !> The 3D twin of [[lme_point_2d]] (uniform γ, a warm start near λ*): the same passes and
    !> early stop with 3-vectors, a 3×3 linear system for the final values, and the third
    !> moments (ten entries) in a pass of their own once Newton has stopped. Every case [[lme_point_2d]] hands over (the
    !> general path's guards, a support larger than the storage, x outside the candidates'
    !> bounding box) returns `LME_FALLBACK` here as well.
    pure subroutine lme_point_3d(grid, x, gamma, cut, h, rmax, maxit, lam, cap, nn, node, N, &
                                 dN, iters)
      type(empm_grid_t), intent(in) :: grid     !! background grid (3D)
      real(wp), intent(in) :: x(3)              !! point
      real(wp), intent(in) :: gamma             !! γ
      real(wp), intent(in) :: cut               !! −ln tol0
      real(wp), intent(in) :: h                 !! nodal spacing of γ [length]
      real(wp), intent(in) :: rmax              !! support radius [length]
      integer, intent(in) :: maxit              !! Newton iteration cap
      real(wp), intent(inout) :: lam(3)         !! λ [1/length]: warm start in, λ* out
      integer, intent(in) :: cap                !! storage per point
      integer, intent(out) :: nn                !! number of supporting nodes
      integer, intent(out) :: node(cap)         !! node indices
      real(wp), intent(out) :: N(cap)           !! values
      real(wp), intent(out) :: dN(3, cap)       !! gradients
      integer, intent(out) :: iters             !! Newton iterations, or LME_FALLBACK
      integer, parameter :: BOX_MAX = 64        ! as in lme_point_2d
      real(wp) :: qa(LEAN_MAX)                  ! γ|ξ_a|² of each candidate, as in 2D
      real(wp) :: xr(BOX_MAX), xr2(BOX_MAX), s(3), rd(3), xi2, xi3, xi22, xi32, q, f, fmax
      real(wp) :: qmax, x2max, xlo(3), xhi(3), l(3), c(3), sw, m1(3), m2(6), m3(10), logz
      real(wp) :: r(3), jm(6), ji(6), scl, rn, d(3), dn2, slope, logz0, b(3), mm(3, 3)
      real(wp) :: adj(3, 3), det, qv(3), st, t1(3), t2(6), rt(3), v(3), p, rem, wd, lim
      integer :: lo(3), hi(3), i, j, k, id0, a, amax, it, i0, i1
      logical :: guard, far
      nn = 0
      it = 0
      iters = LME_FALLBACK ! until the very end, as in lme_point_2d
      if (.not. grid%inside(x)) return
      l = lam * h
      if (.not. all(abs(l) <= LME_LAM_MAX)) return
      do k = 1, 3
        s(k) = (x(k) - grid%origin(k)) * grid%inv_h(k); rd(k) = rmax * grid%inv_h(k)
        lo(k) = max(0, ceiling(s(k) - rd(k))); hi(k) = min(grid%ncell(k), floor(s(k) + rd(k)))
      end do
      if (hi(1) - lo(1) >= BOX_MAX) return
      do i = lo(1), hi(1)
        xr(i - lo(1) + 1) = (x(1) - (grid%origin(1) + i * grid%h(1))) / h
        xr2(i - lo(1) + 1) = xr(i - lo(1) + 1)**2
      end do
      fmax = -huge(1.0_wp); amax = 0; qmax = 0.0_wp
      xlo = huge(1.0_wp); xhi = -huge(1.0_wp)
      lim = cut / gamma
      ! Candidates with the expressions of lme_point, its rows trimmed the same way (the test
      ! on q decides), so the same nodes in the same order; their exponents at once.
      do k = lo(3), hi(3)
        xi3 = (x(3) - (grid%origin(3) + k * grid%h(3))) / h
        xi32 = xi3**2
        do j = lo(2), hi(2)
          xi2 = (x(2) - (grid%origin(2) + j * grid%h(2))) / h
          xi22 = xi2**2
          rem = lim - (xi22 + xi32)
          if (rem < -1.0e-9_wp * lim) cycle
          wd = sqrt(max(rem, 0.0_wp) + 1.0e-12_wp * lim) * h * grid%inv_h(1) + 1.0e-6_wp
          i0 = max(lo(1), ceiling(s(1) - wd)); i1 = min(hi(1), floor(s(1) + wd))
          id0 = grid%id0 + grid%ln(1) * (j + grid%ln(2) * k)
          do i = i0, i1
            q = gamma * ((xr2(i - lo(1) + 1) + xi22) + xi32)
            if (q > cut) cycle
            if (nn == cap .or. nn == LEAN_MAX) return
            nn = nn + 1
            qa(nn) = q
            node(nn) = id0 + i
            dN(1, nn) = xr(i - lo(1) + 1); dN(2, nn) = xi2; dN(3, nn) = xi3
            f = -q + ((l(1) * dN(1, nn) + l(2) * xi2) + l(3) * xi3)
            N(nn) = f
            if (f > fmax) then
              fmax = f; amax = nn
            end if
            qmax = max(qmax, q)
            xlo(1) = min(xlo(1), dN(1, nn)); xhi(1) = max(xhi(1), dN(1, nn))
            xlo(2) = min(xlo(2), xi2); xhi(2) = max(xhi(2), xi2)
            xlo(3) = min(xlo(3), xi3); xhi(3) = max(xhi(3), xi3)
          end do
        end do
      end do
      if (nn < 4) return
      if (.not. all(xhi >= 0.0_wp .and. xlo <= 0.0_wp)) return
      x2max = qmax / gamma
      far = .false.
      c = dN(:, amax)
      call weights_3d(nn, fmax, c, dN, N, sw, m1, m2, logz, r, jm)
      do
        rn = sqrt(r(1)**2 + r(2)**2 + r(3)**2)
        if (logz < -qmax - 1.0e-9_wp * (1.0_wp + qmax)) return
        call inverse_3d(jm, ji, scl)
        if (scl < LME_J_MIN) return
        d(1) = -(ji(1) * r(1) + ji(2) * r(2) + ji(3) * r(3)) / scl
        d(2) = -(ji(2) * r(1) + ji(4) * r(2) + ji(5) * r(3)) / scl
        d(3) = -(ji(3) * r(1) + ji(5) * r(2) + ji(6) * r(3)) / scl
        dn2 = d(1)**2 + d(2)**2 + d(3)**2
        if (rn < LME_TOL_CONV) exit
        if (.not. far .and. 0.5_wp * (sqrt(x2max) + rn)**3 * dn2 < LME_TOL_CONV) exit
        if (it >= maxit .or. dn2 > LME_STEP_MAX**2) return
        guard = rn > LME_TOL_GUARD
        if (guard) then
          slope = r(1) * d(1) + r(2) * d(2) + r(3) * d(3); logz0 = logz; far = .true.
        end if
        l = l + d
        it = it + 1
        if (.not. all(abs(l) <= LME_LAM_MAX)) return
        fmax = -huge(1.0_wp); amax = 0
        do a = 1, nn
          f = -qa(a) + ((l(1) * dN(1, a) + l(2) * dN(2, a)) + l(3) * dN(3, a))
          N(a) = f
          if (f > fmax) then
            fmax = f; amax = a
          end if
        end do
        c = dN(:, amax)
        call weights_3d(nn, fmax, c, dN, N, sw, m1, m2, logz, r, jm)
        if (guard) then
          if (.not. (logz <= logz0 + LME_ARMIJO_C * slope)) return
        end if
      end do
      ! Final values as in lme_point_2d: p̂ ∝ w (1 + q·u) with (S1 + S0 c) + (S2 + c⊗S1) q = 0,
      ! here a 3×3 system solved by its adjugate; the moments of p̂ from S0..S3.
      call third_3d(nn, c, dN, N, m3)
      b = m1 + sw * c
      mm(:, 1) = m2([1, 2, 3]) + c * m1(1)
      mm(:, 2) = m2([2, 4, 5]) + c * m1(2)
      mm(:, 3) = m2([3, 5, 6]) + c * m1(3)
      adj(1, 1) = mm(2, 2) * mm(3, 3) - mm(2, 3) * mm(3, 2)
      adj(1, 2) = mm(1, 3) * mm(3, 2) - mm(1, 2) * mm(3, 3)
      adj(1, 3) = mm(1, 2) * mm(2, 3) - mm(1, 3) * mm(2, 2)
      adj(2, 1) = mm(2, 3) * mm(3, 1) - mm(2, 1) * mm(3, 3)
      adj(2, 2) = mm(1, 1) * mm(3, 3) - mm(1, 3) * mm(3, 1)
      adj(2, 3) = mm(1, 3) * mm(2, 1) - mm(1, 1) * mm(2, 3)
      adj(3, 1) = mm(2, 1) * mm(3, 2) - mm(2, 2) * mm(3, 1)
      adj(3, 2) = mm(1, 2) * mm(3, 1) - mm(1, 1) * mm(3, 2)
      adj(3, 3) = mm(1, 1) * mm(2, 2) - mm(1, 2) * mm(2, 1)
      det = mm(1, 1) * adj(1, 1) + mm(1, 2) * adj(2, 1) + mm(1, 3) * adj(3, 1)
      if (.not. (abs(det) > LME_J_MIN * sw**3)) return
      do i = 1, 3
        qv(i) = -(adj(i, 1) * b(1) + adj(i, 2) * b(2) + adj(i, 3) * b(3)) / det
      end do
      if (sqrt(qv(1)**2 + qv(2)**2 + qv(3)**2) * (sqrt(x2max) + sqrt(c(1)**2 + c(2)**2 + &
          c(3)**2)) > 0.5_wp) return
      st = sw + (m1(1) * qv(1) + m1(2) * qv(2) + m1(3) * qv(3))
      t1(1) = m1(1) + (m2(1) * qv(1) + m2(2) * qv(2) + m2(3) * qv(3))
      t1(2) = m1(2) + (m2(2) * qv(1) + m2(4) * qv(2) + m2(5) * qv(3))
      t1(3) = m1(3) + (m2(3) * qv(1) + m2(5) * qv(2) + m2(6) * qv(3))
      t2(1) = m2(1) + (m3(1) * qv(1) + m3(2) * qv(2) + m3(3) * qv(3))
      t2(2) = m2(2) + (m3(2) * qv(1) + m3(4) * qv(2) + m3(5) * qv(3))
      t2(3) = m2(3) + (m3(3) * qv(1) + m3(5) * qv(2) + m3(6) * qv(3))
      t2(4) = m2(4) + (m3(4) * qv(1) + m3(7) * qv(2) + m3(8) * qv(3))
      t2(5) = m2(5) + (m3(5) * qv(1) + m3(8) * qv(2) + m3(9) * qv(3))
      t2(6) = m2(6) + (m3(6) * qv(1) + m3(9) * qv(2) + m3(10) * qv(3))
      rt = t1 / st
      jm(1) = t2(1) / st - rt(1) * rt(1)
      jm(2) = t2(2) / st - rt(1) * rt(2)
      jm(3) = t2(3) / st - rt(1) * rt(3)
      jm(4) = t2(4) / st - rt(2) * rt(2)
      jm(5) = t2(5) / st - rt(2) * rt(3)
      jm(6) = t2(6) / st - rt(3) * rt(3)
      call inverse_3d(jm, ji, scl)
      if (scl < LME_J_MIN) return
      ji = ji / scl
      ! r̂ − c = rt; ∇p̂_a = −p̂_a Ĵ⁻¹ (ξ_a − r̂)/h.
      do a = 1, nn
        v(1) = dN(1, a) - c(1); v(2) = dN(2, a) - c(2); v(3) = dN(3, a) - c(3)
        p = N(a) * (1.0_wp + (qv(1) * v(1) + qv(2) * v(2) + qv(3) * v(3))) / st
        N(a) = p
        v = v - rt
        dN(1, a) = -p * (ji(1) * v(1) + ji(2) * v(2) + ji(3) * v(3)) / h
        dN(2, a) = -p * (ji(2) * v(1) + ji(4) * v(2) + ji(5) * v(3)) / h
        dN(3, a) = -p * (ji(3) * v(1) + ji(5) * v(2) + ji(6) * v(3)) / h
      end do
      if (far) then
        lam = l / h
      else
        lam = (l + d) / h
      end if
      iters = it
    end subroutine lme_point_3d

    !> 3D weights w_a = exp(f_a − fm) (f in `w` on entry) and their moments about c up to
    !> second order (S2 as (11, 12, 13, 22, 23, 33)), and log Z, r and J (as S2) of the
    !> normalised weights. The third moments, needed once, are [[third_3d]]'s.
    pure subroutine weights_3d(nn, fm, c, xi, w, sw, m1, m2, logz, r, jm)
      integer, intent(in) :: nn            !! number of nodes
      real(wp), intent(in) :: fm           !! max f
      real(wp), intent(in) :: c(3)         !! centre of the moments
      real(wp), intent(in) :: xi(3, *)     !! ξ_a
      real(wp), intent(inout) :: w(*)      !! in: f_a; out: w_a
      real(wp), intent(out) :: sw          !! S0
      real(wp), intent(out) :: m1(3)       !! S1
      real(wp), intent(out) :: m2(6)       !! S2
      real(wp), intent(out) :: logz        !! log Z
      real(wp), intent(out) :: r(3)        !! r = Σ p ξ
      real(wp), intent(out) :: jm(6)       !! J
      real(wp) :: e, u1, u2, u3, e1, e2, e3, g(3)
      integer :: b
      ! The exponentials in a loop of their own (vectorised): a call inside the summing loop
      ! would spill its accumulators (the SSE registers are caller-saved).
      do b = 1, nn
        w(b) = exp(w(b) - fm)
      end do
      sw = 0.0_wp; m1 = 0.0_wp; m2 = 0.0_wp
      do b = 1, nn
        e = w(b)
        u1 = xi(1, b) - c(1); u2 = xi(2, b) - c(2); u3 = xi(3, b) - c(3)
        e1 = e * u1; e2 = e * u2; e3 = e * u3
        sw = sw + e
        m1(1) = m1(1) + e1; m1(2) = m1(2) + e2; m1(3) = m1(3) + e3
        m2(1) = m2(1) + e1 * u1; m2(2) = m2(2) + e1 * u2; m2(3) = m2(3) + e1 * u3
        m2(4) = m2(4) + e2 * u2; m2(5) = m2(5) + e2 * u3; m2(6) = m2(6) + e3 * u3
      end do
      logz = fm + log(sw)
      g = m1 / sw
      r = c + g
      jm(1) = m2(1) / sw - g(1) * g(1); jm(2) = m2(2) / sw - g(1) * g(2)
      jm(3) = m2(3) / sw - g(1) * g(3); jm(4) = m2(4) / sw - g(2) * g(2)
      jm(5) = m2(5) / sw - g(2) * g(3); jm(6) = m2(6) / sw - g(3) * g(3)
    end subroutine weights_3d

    !> Third moments S3 = Σ w u⊗u⊗u about c, u = ξ − c, as (111, 112, 113, 122, 123, 133, 222,
    !> 223, 233, 333): a pass of their own after Newton, since the ten sums spill when every
    !> weight pass carries them (unlike 2D's four).
    pure subroutine third_3d(nn, c, xi, w, m3)
      integer, intent(in) :: nn            !! number of nodes
      real(wp), intent(in) :: c(3)         !! centre of the moments
      real(wp), intent(in) :: xi(3, *)     !! ξ_a
      real(wp), intent(in) :: w(*)         !! w_a
      real(wp), intent(out) :: m3(10)      !! S3
      real(wp) :: u1, u2, u3, e11, e12, e13, e22, e23, e33
      integer :: b
      m3 = 0.0_wp
      do b = 1, nn
        u1 = xi(1, b) - c(1); u2 = xi(2, b) - c(2); u3 = xi(3, b) - c(3)
        e11 = (w(b) * u1) * u1; e12 = (w(b) * u1) * u2; e13 = (w(b) * u1) * u3
        e22 = (w(b) * u2) * u2; e23 = (w(b) * u2) * u3; e33 = (w(b) * u3) * u3
        m3(1) = m3(1) + e11 * u1; m3(2) = m3(2) + e11 * u2; m3(3) = m3(3) + e11 * u3
        m3(4) = m3(4) + e12 * u2; m3(5) = m3(5) + e12 * u3; m3(6) = m3(6) + e13 * u3
        m3(7) = m3(7) + e22 * u2; m3(8) = m3(8) + e22 * u3; m3(9) = m3(9) + e23 * u3
        m3(10) = m3(10) + e33 * u3
      end do
    end subroutine third_3d

    !> (J/‖J‖_F)⁻¹ of a symmetric 3×3 J = (11, 12, 13, 22, 23, 33) by its adjugate, and ‖J‖_F;
    !> `nrm` = 0 when J is not positive definite to within the Frobenius condition
    !> LME_COND_MAX (the test of the general path's `sym_inverse`).
    pure subroutine inverse_3d(jj, jinv, nrm)
      real(wp), intent(in) :: jj(6)        !! J
      real(wp), intent(out) :: jinv(6)     !! (J/‖J‖)⁻¹
      real(wp), intent(out) :: nrm         !! ‖J‖_F, or 0 on failure
      real(wp) :: bb(6), ad(6), det, nadj
      nrm = sqrt(jj(1)**2 + jj(4)**2 + jj(6)**2 + 2.0_wp * (jj(2)**2 + jj(3)**2 + jj(5)**2))
      jinv = 0.0_wp
      if (.not. (nrm > sqrt(SUMSQ_LO) .and. nrm < sqrt(SUMSQ_HI))) then
        nrm = 0.0_wp; return
      end if
      bb = jj / nrm
      ad(1) = bb(4) * bb(6) - bb(5) * bb(5)
      ad(2) = bb(3) * bb(5) - bb(2) * bb(6)
      ad(3) = bb(2) * bb(5) - bb(3) * bb(4)
      ad(4) = bb(1) * bb(6) - bb(3) * bb(3)
      ad(5) = bb(2) * bb(3) - bb(1) * bb(5)
      ad(6) = bb(1) * bb(4) - bb(2) * bb(2)
      det = bb(1) * ad(1) + bb(2) * ad(2) + bb(3) * ad(3)
      nadj = sqrt(ad(1)**2 + ad(4)**2 + ad(6)**2 + 2.0_wp * (ad(2)**2 + ad(3)**2 + ad(5)**2))
      if (.not. (det > 0.0_wp .and. det * LME_COND_MAX > nadj)) then
        nrm = 0.0_wp; return
      end if
      jinv = ad / det
    end subroutine inverse_3d
  end subroutine lme_batch

  !> [[lme_point]] from the caller's warm start and, if that fails for a reason other than the
  !> point's position or the storage, once more from λ = 0: a warm start is a hint, and a
  !> failure from it says nothing about the basis at x.
  pure subroutine lme_point_retry(self, grid, x, lam, nn, node, N, dN, iters, info)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: x(:)               !! point (ndim)
    real(wp), intent(inout) :: lam(:)          !! λ: warm start in, converged λ out
    integer, intent(out) :: nn                 !! number of supporting nodes
    integer, intent(out) :: node(:)            !! supporting node indices
    real(wp), intent(out) :: N(:)              !! values
    real(wp), intent(out) :: dN(:,:)           !! gradients (ndim, :)
    integer, intent(out) :: iters              !! Newton iterations, both attempts
    integer, intent(out) :: info               !! SHAPE_OK or the cold attempt's failure
    integer :: it0
    logical :: warm
    warm = any(lam(1:grid%ndim) /= 0.0_wp)
    call lme_point(self, grid, x, lam, 1.0_wp, nn, node, N, dN, iters, info)
    if (info == SHAPE_OK .or. info == SHAPE_OUTSIDE_GRID .or. info == SHAPE_TOO_MANY_NODES &
        .or. .not. warm) return
    it0 = iters
    lam(1:grid%ndim) = 0.0_wp
    call lme_point(self, grid, x, lam, 1.0_wp, nn, node, N, dN, iters, info)
    iters = iters + it0
  end subroutine lme_point_retry

  !> The 'enlarge' remedy, after the first attempt at x failed with `info`: while the failure
  !> is one a larger support can cure, evaluate again from λ = 0 with every γ halved, then
  !> quartered; the first success (or the last failure) is returned.
  pure subroutine lme_remedy(self, grid, x, lam, nn, node, N, dN, iters, info)
    type(empm_shape_lme_t), intent(in) :: self !! shape family
    type(empm_grid_t), intent(in) :: grid      !! background grid
    real(wp), intent(in) :: x(:)               !! point (ndim)
    real(wp), intent(inout) :: lam(:)          !! λ: converged λ out on success
    integer, intent(inout) :: nn               !! number of supporting nodes (0 on failure)
    integer, intent(inout) :: node(:)          !! supporting node indices
    real(wp), intent(inout) :: N(:)            !! values
    real(wp), intent(inout) :: dN(:,:)         !! gradients (ndim, :)
    integer, intent(inout) :: iters            !! Newton iterations of the last attempt
    integer, intent(inout) :: info             !! in: the first attempt's failure; out: result
    integer :: k
    do k = 1, LME_REMEDY_TRIES
      select case (info)
      case (SHAPE_OUTSIDE_HULL, SHAPE_SUPPORT_CLIPPED, SHAPE_SINGULAR, SHAPE_NOT_CONVERGED)
        lam(1:grid%ndim) = 0.0_wp
        call lme_point(self, grid, x, lam, LME_REMEDY_FACTOR**k, nn, node, N, dN, iters, info)
      case default
        return
      end select
    end do
  end subroutine lme_remedy
end submodule empm_shape_lme_batch
