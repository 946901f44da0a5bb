!> The general LME path: candidates through the grid ([[lme_point]]) and the guarded Newton
!> kernel ([[lme_kernel]], shared with the procedural entry point empm_lme_basis) with its
!> moments and small symmetric inverses, and the parameter helpers `params_ok`, `lme_h` and
!> `gamma_lowest`. The hull tests of the failure path are in the child submodule
!> empm_shape_lme_hull, which uses this one's linear algebra.
submodule (empm_shape_lme) empm_shape_lme_newton
  use empm_shape, only: SHAPE_OK, SHAPE_OUTSIDE_GRID, SHAPE_SUPPORT_CLIPPED, SHAPE_NOT_CONVERGED, &
                        SHAPE_OUTSIDE_HULL, SHAPE_SINGULAR, SHAPE_TOO_MANY_NODES
  implicit none

  !> Smallest Armijo step fraction (the constant is LME_ARMIJO_C, shared with the batch's lean paths).
  real(wp), parameter :: ARMIJO_TMIN = 1.0e-12_wp
  !> Most candidates for the direct hull test on failure (C(40, 4) = 91390 simplices in 3D).
  integer, parameter :: HULL_TEST_MAXN = 40
  !> Largest Frobenius condition of the candidates' covariance before they count as flat.
  real(wp), parameter :: FLAT_COND_MAX = 1.0e10_wp
  !> Most candidates whose exponents [[moments]] keeps between its two passes (2D fast path).
  integer, parameter :: MOM_BUF = 128

contains

  ! The parameter helpers live here, next to their per-point caller lme_point: a call across
  ! files is never inlined (and within the file only without semantic interposition).

  module procedure params_ok
    params_ok = grid%ndim >= 1 .and. grid%ndim <= 3 .and. self%gamma > 0.0_wp .and. &
                self%tol0 > 0.0_wp .and. self%tol0 < 1.0_wp .and. self%max_iter >= 1
    if (params_ok .and. allocated(self%gamma_node)) &
      params_ok = size(self%gamma_node) == grid%nnode .and. self%gamma_min > 0.0_wp
  end procedure params_ok

  module procedure lme_h
    lme_h = maxval(grid%h(1:grid%ndim))
  end procedure lme_h

  module procedure gamma_lowest
    if (allocated(self%gamma_node)) then
      gamma_lowest = self%gamma_min
    else
      gamma_lowest = self%gamma
    end if
  end procedure gamma_lowest

  module procedure lme_point
    real(wp) :: hs, cut, rmax, s, rd, xi(3), q, ga, xr(256), s1, rem, w
    integer :: nd, d, lo(3), hi(3), i, j, k, id, id0, cap, i0, i1
    logical :: varying, hoist
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
    ! ξ₁ of the box's columns once (the same expression): no division per candidate (in the
    ! loop for a box wider than xr: γ below about 1e-3).
    hoist = hi(1) - lo(1) < size(xr)
    if (hoist) then
      do i = lo(1), hi(1)
        xr(i - lo(1) + 1) = (x(1) - (grid%origin(1) + i * grid%h(1))) / hs
      end do
    end if
    s1 = (x(1) - grid%origin(1)) * grid%inv_h(1)
    do k = lo(3), hi(3)
      if (nd >= 3) xi(3) = (x(3) - (grid%origin(3) + k * grid%h(3))) / hs
      do j = lo(2), hi(2)
        if (nd >= 2) xi(2) = (x(2) - (grid%origin(2) + j * grid%h(2))) / hs
        id0 = grid%id0 + grid%ln(1) * (j + grid%ln(2) * k)
        i0 = lo(1); i1 = hi(1)
        if (.not. varying) then
          ! Only the row's columns that can pass the test below, |ξ₁|² ≤ cut/γ − ξ₂² − ξ₃²
          ! (a disk or ball, not the whole box), widened against rounding (in ξ₁², relative
          ! to cut/γ; and 1e-6 cell): the test still decides, so the candidates and their
          ! order are the same.
          rem = cut / ga - (xi(2)**2 + xi(3)**2)
          if (rem < -1.0e-9_wp * (cut / ga)) cycle
          w = sqrt(max(rem, 0.0_wp) + 1.0e-12_wp * (cut / ga)) * hs * grid%inv_h(1) + 1.0e-6_wp
          i0 = max(lo(1), ceiling(s1 - w)); i1 = min(hi(1), floor(s1 + w))
        end if
        do i = i0, i1
          id = id0 + i
          if (hoist) then
            xi(1) = xr(i - lo(1) + 1)
          else
            xi(1) = (x(1) - (grid%origin(1) + i * grid%h(1))) / hs
          end if
          if (varying) ga = scale * self%gamma_node(id)
          q = ga * (xi(1)**2 + xi(2)**2 + xi(3)**2)
          if (q > cut) cycle
          nn = nn + 1
          if (nn > cap) then
            nn = 0
            info = SHAPE_TOO_MANY_NODES; return
          end if
          node(nn) = id
          ! Explicit copies: a slice of run-time length costs ~30 instructions, or a memcpy call
          ! when the compiler cannot bound nd.
          if (nd == 2) then
            dN(1, nn) = xi(1)
            dN(2, nn) = xi(2)
          else if (nd == 3) then
            dN(1, nn) = xi(1)
            dN(2, nn) = xi(2)
            dN(3, nn) = xi(3)
          else
            dN(1, nn) = xi(1)
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
  end procedure lme_point

  module procedure lme_kernel
    real(wp) :: cut, q, qmax, lh(3), lt(3), r(3), rt(3), jm(3, 3), jt(3, 3), jinv(3, 3)
    real(wp) :: del(3), y(3), bm(3, 3), mv(3), logz, logzt, rn, t, slope, dnorm, zlow, p, ga
    real(wp) :: cmean(3), cov(3, 3), cinv(3, 3), v(3), s, ximax, x2, x2max, scl, cen(3), cent(3)
    real(wp) :: xlo(3), xhi(3)
    integer :: a, i, nact
    logical :: varying, ok, qvalid, fast2d, fast3d, early, far

    iters = 0
    info = SHAPE_OK
    lh = 0.0_wp
    ok = .true.
    qvalid = .true.
    nact = 0
    varying = present(gnode) .and. present(node)
    fast2d = nd == 2 .and. .not. varying
    fast3d = nd == 3 .and. .not. varying
    ! 3D with uniform γ stops as the lean paths do, on a bound of the residual after the
    ! final linearised step (1D keeps the test on ‖r‖ alone: its verification results rest on it).
    early = nd == 3 .and. .not. varying
    far = .false.
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
      else if (fast3d) then
        ! 3D with scalars: the general loop's expressions (its sum adds from the first term).
        do a = 1, nc
          x2 = (dN(1, a)**2 + dN(2, a)**2) + dN(3, a)**2
          q = gamma * x2
          if (q <= cut) then
            N(a) = 0.0_wp
            nact = nact + 1
            qmax = max(qmax, q)
            x2max = max(x2max, x2)
            cmean(1) = cmean(1) + dN(1, a)
            cmean(2) = cmean(2) + dN(2, a)
            cmean(3) = cmean(3) + dN(3, a)
            xlo(1) = min(xlo(1), dN(1, a))
            xhi(1) = max(xhi(1), dN(1, a))
            xlo(2) = min(xlo(2), dN(2, a))
            xhi(2) = max(xhi(2), dN(2, a))
            xlo(3) = min(xlo(3), dN(3, a))
            xhi(3) = max(xhi(3), dN(3, a))
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
      else if (fast3d) then
        ! As the general loop, with scalars (cov(i, j) = cov(j, i) exactly there too).
        do a = 1, nc
          if (N(a) < 0.0_wp) cycle
          y(1) = dN(1, a) - cmean(1)
          y(2) = dN(2, a) - cmean(2)
          y(3) = dN(3, a) - cmean(3)
          cov(1, 1) = cov(1, 1) + y(1) * y(1)
          cov(2, 1) = cov(2, 1) + y(2) * y(1)
          cov(3, 1) = cov(3, 1) + y(3) * y(1)
          cov(2, 2) = cov(2, 2) + y(2) * y(2)
          cov(3, 2) = cov(3, 2) + y(3) * y(2)
          cov(3, 3) = cov(3, 3) + y(3) * y(3)
        end do
        cov(1, 2) = cov(2, 1); cov(1, 3) = cov(3, 1); cov(2, 3) = cov(3, 2)
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
        if (iters >= maxit .and. .not. early) then
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
        ! Done when r(λ + Δ), bounded by ½(ξmax + ‖r‖)³|Δ|², is within the tolerance: the final
        ! step below is that Δ, linearised (docs/shape-functions.md, "The lean batch paths"); after
        ! a far start (a guarded step) only on ‖r‖, as in 2D.
        if (early .and. .not. far) then
          if (0.5_wp * (ximax + rn)**3 * (dnorm / scl)**2 < LME_TOL_CONV) exit
        end if
        if (iters >= maxit) then ! (after the bound, as in 2D: an iterate that meets it is done)
          info = SHAPE_NOT_CONVERGED; exit main
        end if
        if (dnorm > LME_STEP_MAX * scl) then
          del = -del * (LME_STEP_MAX / dnorm)
        else
          del = -del / scl
        end if
        t = 1.0_wp
        ! The first trial is the full step, and its moments are kept: the guard costs extra
        ! evaluations only when it actually backtracks.
        if (rn > LME_TOL_GUARD) then
          far = .true.
          slope = dot_product(r(1:nd), del(1:nd))
          do
            lt = lh + t * del
            call moments(nd, nc, gamma, N, dN, lt, logzt, rt, jt, cent, gnode, node)
            if (logzt <= logz + LME_ARMIJO_C * t * slope) exit
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
      ! first order (error O(|Δ|²): < 1e-18 after ‖r‖ < 1e-10, below the tolerance after the
      ! 3D bound), costs no exponential, and makes Σp̃ = 1 and
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
      else if (nd == 3 .and. .not. varying) then
        ! 3D with scalars: the general loop's expressions (dot_product adds from zero).
        do a = 1, nc
          if (N(a) < 0.0_wp) then
            N(a) = 0.0_wp
            cycle
          end if
          v(1) = dN(1, a) - r(1)
          v(2) = dN(2, a) - r(2)
          v(3) = dN(3, a) - r(3)
          p = N(a) * (1.0_wp + (((0.0_wp + v(1) * del(1)) + v(2) * del(2)) + v(3) * del(3)))
          N(a) = p
          ! The sums about cen as in the general loop (all nine jt(i, j)), written out.
          s = s + p
          v(1) = dN(1, a) - cen(1)
          v(2) = dN(2, a) - cen(2)
          v(3) = dN(3, a) - cen(3)
          rt(1) = rt(1) + p * v(1)
          rt(2) = rt(2) + p * v(2)
          rt(3) = rt(3) + p * v(3)
          do i = 1, 3
            jt(1, i) = jt(1, i) + (p * v(i)) * v(1)
            jt(2, i) = jt(2, i) + (p * v(i)) * v(2)
            jt(3, i) = jt(3, i) + (p * v(i)) * v(3)
          end do
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
      else if (nd == 3 .and. .not. varying) then
        ! 3D with scalars, as the general loop below.
        do a = 1, nc
          if (N(a) == 0.0_wp) then
            dN(1:3, a) = 0.0_wp
            cycle
          end if
          N(a) = N(a) / s
          v(1) = dN(1, a) - r(1)
          v(2) = dN(2, a) - r(2)
          v(3) = dN(3, a) - r(3)
          ! matvec's sums, from the same zero.
          y(1) = ((0.0_wp + jinv(1, 1) * v(1)) + jinv(1, 2) * v(2)) + jinv(1, 3) * v(3)
          y(2) = ((0.0_wp + jinv(2, 1) * v(1)) + jinv(2, 2) * v(2)) + jinv(2, 3) * v(3)
          y(3) = ((0.0_wp + jinv(3, 1) * v(1)) + jinv(3, 2) * v(2)) + jinv(3, 3) * v(3)
          dN(1, a) = -N(a) * y(1) / h
          dN(2, a) = -N(a) * y(2) / h
          dN(3, a) = -N(a) * y(3) / h
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
  end procedure lme_kernel

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
    else if (nd == 3 .and. .not. varying .and. nc <= MOM_BUF) then
      ! 3D the same way: the general loop's expressions written out (sum and dot_product of
      ! three terms add from the first; all nine sj(i, j) as there), the exponents kept.
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        f = -(gamma * ((xi(1, a)**2 + xi(2, a)**2) + xi(3, a)**2)) + &
            ((lh(1) * xi(1, a) + lh(2) * xi(2, a)) + lh(3) * xi(3, a))
        fa(a) = f
        if (f > fmax) then
          fmax = f
          amax = a
        end if
      end do
      if (amax > 0) c(1:3) = xi(1:3, amax)
      ! The weights first, then their sums: an exp call in the summing loop made every
      ! accumulator spill around it (the SSE registers are caller-saved). Not vectorised:
      ! the vector exp may round differently from the scalar one, the general loop's.
      !GCC$ novector
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        w(a) = exp(fa(a) - fmax)
      end do
      do a = 1, nc
        if (w(a) < 0.0_wp) cycle
        e = w(a)
        ! S0 += e, S1 += e u, S2 += (e u_i) u_j (all nine), u = ξ − c: the general loop's
        ! sums written out (a call per node was 20 % of a 3D LME step).
        s = s + e
        u(1) = xi(1, a) - c(1)
        u(2) = xi(2, a) - c(2)
        u(3) = xi(3, a) - c(3)
        sr(1) = sr(1) + e * u(1)
        sr(2) = sr(2) + e * u(2)
        sr(3) = sr(3) + e * u(3)
        do i = 1, 3
          sj(1, i) = sj(1, i) + (e * u(i)) * u(1)
          sj(2, i) = sj(2, i) + (e * u(i)) * u(2)
          sj(3, i) = sj(3, i) + (e * u(i)) * u(3)
        end do
      end do
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
    if (nd == 3) then
      ! The loops' sums in the same order, from the same zero.
      do i = 1, 3
        y(i) = ((0.0_wp + a(i, 1) * v(1)) + a(i, 2) * v(2)) + a(i, 3) * v(3)
      end do
      return
    end if
    y = 0.0_wp
    do j = 1, nd
      do i = 1, nd
        y(i) = y(i) + a(i, j) * v(j)
      end do
    end do
  end function matvec
end submodule empm_shape_lme_newton
