!> Stress-point driver: one material point driven through a path of velocity gradients, with
!> strain control and mixed control, for verifying constitutive models without a grid.
!>
!> A path is a sequence of segments; a segment prescribes, over a duration `T` in `n`
!> increments, a constant velocity gradient `L` and, for the Voigt stress components selected by
!> `mask`, a stress target that moves linearly from `target0` to `target1` (e.g. the constant
!> cell pressure of a drained triaxial test, or the constant normal stress of a simple-shear
!> test). For each controlled component i the corresponding symmetric strain-rate component
!> D_i (tensor shear for i = 4..6) is an unknown added to `L`; each increment solves
!> σ_i(D) = target_i by Newton's method with a forward-difference Jacobian (the driver knows
!> nothing of the model but `update`), restarting the model from the state at the start of the
!> increment for every trial. Strain control is the special case of an empty mask.
!>
!> Any `class(empm_material_t)` can be driven; the model sees `ctx%ndim = 3` (general 3D
!> kinematics). Yield consistency is checked after every (sub-)increment through a
!> model-independent callback, an [[empm_sp_check_t]], which returns the relative violation of
!> the yield condition (0 inside or on the surface). Each increment may be split into `nsub`
!> equal sub-increments (the target interpolated linearly) while the history is recorded at the
!> ends of the whole increments only: two runs with different splits are then compared point by
!> point.
module empm_stress_point
  use empm_kinds, only: wp
  use empm_material, only: empm_material_t, empm_material_ctx_t
  implicit none
  private
  public :: empm_sp_point_t, empm_sp_history_t, empm_sp_check_t, empm_sp_segment
  public :: empm_sp_increment, empm_sp_unit_rate, empm_sp_replay

  !> The state of the material point.
  type :: empm_sp_point_t
    real(wp) :: stress(6) = 0.0_wp   !! Cauchy stress, Voigt (tension positive) [Pa]
    real(wp) :: strain(6) = 0.0_wp   !! small strain, Voigt, tensor shears
    real(wp) :: F(3,3) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                  0.0_wp, 0.0_wp, 1.0_wp], [3, 3]) !! deformation gradient
    real(wp) :: rho = 1.0_wp         !! density [kg/m³]
    real(wp), allocatable :: state(:) !! the model's state variables (nstate)
    real(wp) :: t = 0.0_wp           !! time [s]
    integer :: step = 0              !! increments taken
    real(wp) :: guess(6) = 0.0_wp    !! last solution of the unknown strain rates (warm start)
  end type empm_sp_point_t

  !> The record of a path, at the ends of the (whole) increments; column 0 is the start.
  type :: empm_sp_history_t
    integer :: n = 0                          !! increments recorded
    real(wp), allocatable :: t(:)             !! time (0:n) [s]
    real(wp), allocatable :: stress(:,:)      !! stress (6, 0:n) [Pa]
    real(wp), allocatable :: strain(:,:)      !! strain (6, 0:n)
    real(wp), allocatable :: state(:,:)       !! state variables (nstate, 0:n)
    real(wp), allocatable :: L(:,:,:)         !! velocity gradient of each increment, the
                                              !! unknown rates included (3, 3, n); for
                                              !! [[empm_sp_replay]] (set when nsub = 1)
    real(wp) :: max_yield = 0.0_wp            !! largest relative yield violation, over every
                                              !! sub-increment
    real(wp) :: max_residual = 0.0_wp         !! largest relative residual of the controlled
                                              !! stress components, over every sub-increment
    integer :: newton_max = 0                 !! most Newton iterations in one sub-increment
  end type empm_sp_history_t

  !> Model-independent yield check: `violation` returns f⁺/scale, the relative amount by which
  !> the stress lies outside the model's yield surface (0 on or inside it).
  type, abstract :: empm_sp_check_t
  contains
    procedure(violation_iface), deferred :: violation
  end type empm_sp_check_t

  abstract interface
    !> Relative violation of the yield condition (≥ 0).
    real(wp) function violation_iface(self, stress, state)
      import :: empm_sp_check_t, wp
      class(empm_sp_check_t), intent(in) :: self !! the check
      real(wp), intent(in) :: stress(6)          !! Cauchy stress, Voigt [Pa]
      real(wp), intent(in) :: state(:)           !! the model's state variables
    end function violation_iface
  end interface

  integer, parameter :: MAXIT = 60          !! Newton iterations per increment

contains

  !> The velocity gradient of unit symmetric strain rate in Voigt component `i`
  !> (tensor shears: component 6 is D_xy = D_yx = 1).
  pure function empm_sp_unit_rate(i) result(E)
    integer, intent(in) :: i   !! Voigt index 1..6
    real(wp) :: E(3,3)         !! the rate
    E = 0.0_wp
    select case (i)
    case (1:3)
      E(i,i) = 1.0_wp
    case (4)
      E(2,3) = 1.0_wp; E(3,2) = 1.0_wp
    case (5)
      E(1,3) = 1.0_wp; E(3,1) = 1.0_wp
    case (6)
      E(1,2) = 1.0_wp; E(2,1) = 1.0_wp
    end select
  end function empm_sp_unit_rate

  !> One increment of length `dt`: the prescribed gradient `L` plus the unknown strain rates of
  !> the components `mask`, solved so that those stress components equal `target` to `tol`
  !> relative to max(|target|, |σ|). `info`: 0 ok, > 0 the model failed (its own code), −1 no
  !> Newton convergence. `resid` is the final relative residual, `iters` the iterations.
  subroutine empm_sp_increment(mat, pt, dt, L, mask, target, tol, info, resid, iters, Lused)
    class(empm_material_t), intent(in) :: mat    !! the model
    type(empm_sp_point_t), intent(inout) :: pt   !! the point, advanced on success
    real(wp), intent(in) :: dt                   !! increment [s]
    real(wp), intent(in) :: L(3,3)               !! prescribed velocity gradient [1/s]
    logical, intent(in) :: mask(6)               !! stress-controlled components
    real(wp), intent(in) :: target(6)            !! their values at the end [Pa]
    real(wp), intent(in) :: tol                  !! relative tolerance of the residual
    integer, intent(out) :: info                 !! 0, model code, or −1
    real(wp), intent(out) :: resid               !! final relative residual
    integer, intent(out) :: iters                !! Newton iterations
    real(wp), intent(out), optional :: Lused(3,3) !! the gradient applied, unknowns included
    integer :: idx(6), nu, k, j, it, mi
    real(wp) :: x(6), xt(6), r(6), rt(6), jac(6,6), dx(6), h, scale, rnorm, rnew, lam, xscale
    real(wp) :: s(6), jtj(6,6), mu
    integer :: km
    real(wp), parameter :: MUS(6) = [1.0e-12_wp, 1.0e-9_wp, 1.0e-6_wp, 1.0e-3_wp, 1.0e-1_wp, &
                                     1.0e1_wp]
    type(empm_sp_point_t) :: trial
    nu = 0
    do k = 1, 6
      if (mask(k)) then
        nu = nu + 1; idx(nu) = k
      end if
    end do
    iters = 0; resid = 0.0_wp
    if (present(Lused)) Lused = L
    if (nu == 0) then
      call advance(pt, [real(wp) ::], s, info)
      if (info == 0) call accept(s)
      return
    end if
    ! Unknowns: strain rates; warm start from the previous increment's solution.
    x(1:nu) = pt%guess(idx(1:nu))
    xscale = max(maxval(abs(L)), maxval(abs(x(1:nu))), tiny(1.0_wp))
    call residual(x(1:nu), r(1:nu), s, info)
    if (info /= 0) return
    rnorm = maxval(abs(r(1:nu)))
    do it = 1, MAXIT
      iters = it
      scale = max(maxval(abs(target(idx(1:nu)))), maxval(abs(s)), tiny(1.0_wp))
      if (rnorm <= tol * scale) exit
      ! Forward-difference Jacobian dσ_i/dD_j.
      do j = 1, nu
        h = sqrt(epsilon(1.0_wp)) * max(abs(x(j)), xscale)
        xt(1:nu) = x(1:nu); xt(j) = x(j) + h
        call residual(xt(1:nu), rt(1:nu), s, mi)
        if (mi /= 0) then
          info = mi; return
        end if
        jac(1:nu, j) = (rt(1:nu) - r(1:nu)) / h
      end do
      ! The Newton step, then, if it does not reduce the residual, Levenberg–Marquardt steps
      ! (JᵀJ + μ I) dx = −Jᵀr of increasing μ: at a corner of a perfectly plastic surface the
      ! strain rates that hold the stresses are not unique (e.g. the split of the lateral
      ! flow between two active planes), J is singular and the Newton step wanders along
      ! its null space; the damped step is the shortest one.
      rnew = rnorm
      do km = 0, size(MUS)
        if (km == 0) then
          call solve(jac(1:nu, 1:nu), -r(1:nu), dx(1:nu), mi)
        else
          jtj(1:nu, 1:nu) = matmul(transpose(jac(1:nu, 1:nu)), jac(1:nu, 1:nu))
          mu = MUS(km) * max(maxval([(jtj(k, k), k = 1, nu)]), tiny(1.0_wp))
          do k = 1, nu
            jtj(k, k) = jtj(k, k) + mu
          end do
          call solve(jtj(1:nu, 1:nu), -matmul(transpose(jac(1:nu, 1:nu)), r(1:nu)), &
                     dx(1:nu), mi)
        end if
        if (mi /= 0) cycle
        ! Backtracking on the residual's max norm.
        lam = 1.0_wp
        do k = 1, 30
          xt(1:nu) = x(1:nu) + lam * dx(1:nu)
          call residual(xt(1:nu), rt(1:nu), s, mi)
          if (mi /= 0) then
            info = mi; return
          end if
          rnew = maxval(abs(rt(1:nu)))
          if (rnew < rnorm) exit
          lam = 0.5_wp * lam
        end do
        if (rnew < rnorm) exit
      end do
      if (.not. rnew < rnorm) exit ! stagnated: at the round-off floor
      x(1:nu) = xt(1:nu); r(1:nu) = rt(1:nu); rnorm = rnew
    end do
    call residual(x(1:nu), r(1:nu), s, info)
    if (info /= 0) return
    scale = max(maxval(abs(target(idx(1:nu)))), maxval(abs(s)), tiny(1.0_wp))
    resid = maxval(abs(r(1:nu))) / scale
    if (.not. resid <= max(tol, 1.0e3_wp * epsilon(1.0_wp))) then
      info = -1; return
    end if
    pt%guess = 0.0_wp; pt%guess(idx(1:nu)) = x(1:nu)
    call advance(pt, x(1:nu), s, info)
    if (info == 0) call accept(s)

  contains

    !> The point advanced with unknowns `xu`, into `trial`; `ss` its stress.
    subroutine advance(p0, xu, ss, inf)
      type(empm_sp_point_t), intent(in) :: p0
      real(wp), intent(in) :: xu(:)
      real(wp), intent(out) :: ss(6)
      integer, intent(out) :: inf
      real(wp) :: Lt(3,3,1), Ft(3,3,1), et(6,1), st(6,1), rt1(1)
      real(wp), allocatable :: zt(:,:)
      type(empm_material_ctx_t) :: ctx
      integer :: q
      Lt(:,:,1) = L
      do q = 1, size(xu)
        Lt(:,:,1) = Lt(:,:,1) + xu(q) * empm_sp_unit_rate(idx(q))
      end do
      Ft(:,:,1) = p0%F; et(:,1) = p0%strain; st(:,1) = p0%stress; rt1(1) = p0%rho
      allocate(zt(max(size(p0%state), 1), 1)); zt = 0.0_wp
      zt(1:size(p0%state), 1) = p0%state
      ctx%t = p0%t; ctx%step = p0%step + 1; ctx%first = 1; ctx%ndim = 3; ctx%h = 0.0_wp
      call mat%update(dt, Lt, Ft, et, st, zt, rt1, ctx, inf)
      trial = p0
      trial%F = Ft(:,:,1); trial%strain = et(:,1); trial%stress = st(:,1); trial%rho = rt1(1)
      trial%state = zt(1:size(p0%state), 1)
      ss = st(:,1)
      if (present(Lused)) Lused = Lt(:,:,1)
    end subroutine advance

    subroutine residual(xu, ru, ss, inf)
      real(wp), intent(in) :: xu(:)
      real(wp), intent(out) :: ru(:)
      real(wp), intent(out) :: ss(6)
      integer, intent(out) :: inf
      call advance(pt, xu, ss, inf)
      ru = ss(idx(1:size(xu))) - target(idx(1:size(xu)))
    end subroutine residual

    subroutine accept(ss)
      real(wp), intent(in) :: ss(6)
      associate (unused_ => ss); end associate
      pt = trial
      pt%t = pt%t + dt; pt%step = pt%step + 1
      pt%guess = 0.0_wp
      if (nu > 0) pt%guess(idx(1:nu)) = x(1:nu)
    end subroutine accept
  end subroutine empm_sp_increment

  !> Gaussian elimination with partial pivoting of a small system; `info` 1 when singular.
  pure subroutine solve(A, b, x, info)
    real(wp), intent(in) :: A(:,:), b(:)
    real(wp), intent(out) :: x(:)
    integer, intent(out) :: info
    real(wp) :: M(size(b), size(b) + 1), f
    integer :: n, i, k, p
    n = size(b); info = 0
    M(:, 1:n) = A; M(:, n + 1) = b
    do k = 1, n
      p = k - 1 + maxloc(abs(M(k:n, k)), 1)
      if (.not. abs(M(p, k)) > 0.0_wp) then
        info = 1; x = 0.0_wp; return
      end if
      if (p /= k) M([k, p], :) = M([p, k], :)
      do i = k + 1, n
        f = M(i, k) / M(k, k)
        M(i, k:n + 1) = M(i, k:n + 1) - f * M(k, k:n + 1)
      end do
    end do
    do i = n, 1, -1
      x(i) = (M(i, n + 1) - dot_product(M(i, i + 1:n), x(i + 1:n))) / M(i, i)
    end do
  end subroutine solve

  !> Drive the point through one segment: `n` increments over `T`, each split into `nsub`
  !> sub-increments, with gradient `L` and the components `mask` controlled to a target moving
  !> linearly from `target0` to `target1`. The history is (re)allocated for the segment and
  !> records the `n` increment ends. `check`, when given, is evaluated after every
  !> sub-increment. `info`: 0, the model's failure code, or −1 (no Newton convergence).
  subroutine empm_sp_segment(mat, pt, L, mask, target0, target1, T, n, nsub, hist, info, &
                             check, tol)
    class(empm_material_t), intent(in) :: mat          !! the model
    type(empm_sp_point_t), intent(inout) :: pt         !! the point
    real(wp), intent(in) :: L(3,3)                     !! prescribed gradient [1/s]
    logical, intent(in) :: mask(6)                     !! stress-controlled components
    real(wp), intent(in) :: target0(6), target1(6)     !! targets at start and end [Pa]
    real(wp), intent(in) :: T                          !! duration [s]
    integer, intent(in) :: n                           !! increments recorded
    integer, intent(in) :: nsub                        !! sub-increments per increment
    type(empm_sp_history_t), intent(out) :: hist       !! the record
    integer, intent(out) :: info                       !! 0 ok
    class(empm_sp_check_t), intent(in), optional :: check !! yield check
    real(wp), intent(in), optional :: tol              !! Newton tolerance (default 1e-13)
    integer :: k, m, it, ns
    real(wp) :: dt, w, resid, tl, Lk(3,3)
    tl = 1.0e-13_wp
    if (present(tol)) tl = tol
    ns = size(pt%state)
    hist%n = n
    allocate(hist%t(0:n), hist%stress(6, 0:n), hist%strain(6, 0:n), hist%state(ns, 0:n))
    allocate(hist%L(3, 3, n)); hist%L = 0.0_wp
    hist%t(0) = pt%t; hist%stress(:,0) = pt%stress; hist%strain(:,0) = pt%strain
    hist%state(:,0) = pt%state
    hist%max_yield = 0.0_wp; hist%max_residual = 0.0_wp; hist%newton_max = 0
    if (present(check)) hist%max_yield = check%violation(pt%stress, pt%state)
    dt = T / real(n * nsub, wp)
    info = 0
    do k = 1, n
      do m = 1, nsub
        w = real((k - 1) * nsub + m, wp) / real(n * nsub, wp)
        call empm_sp_increment(mat, pt, dt, L, mask, (1.0_wp - w) * target0 + w * target1, &
                               tl, info, resid, it, Lk)
        if (info /= 0) then
          hist%n = k - 1; return
        end if
        hist%max_residual = max(hist%max_residual, resid)
        hist%newton_max = max(hist%newton_max, it)
        if (present(check)) hist%max_yield = max(hist%max_yield, &
                                                 check%violation(pt%stress, pt%state))
      end do
      hist%t(k) = pt%t; hist%stress(:,k) = pt%stress; hist%strain(:,k) = pt%strain
      hist%state(:,k) = pt%state
      if (nsub == 1) hist%L(:,:,k) = Lk
    end do
  end subroutine empm_sp_segment

  !> Replay the increments of `ref` (a run with nsub = 1) under strain control, each split
  !> into `nsub` equal sub-increments of the same velocity gradient, i.e. the same straight
  !> strain path: the test of whether a model's result depends on how an increment is split.
  !> (Re-solving a mixed-control path with smaller increments would follow a different strain
  !> path, which is a discretisation of the path, not a property of the model.)
  subroutine empm_sp_replay(mat, pt, ref, nsub, hist, info, check)
    class(empm_material_t), intent(in) :: mat          !! the model
    type(empm_sp_point_t), intent(inout) :: pt         !! the point (at the start of `ref`)
    type(empm_sp_history_t), intent(in) :: ref         !! the reference run
    integer, intent(in) :: nsub                        !! sub-increments per increment
    type(empm_sp_history_t), intent(out) :: hist       !! the record
    integer, intent(out) :: info                       !! 0 ok
    class(empm_sp_check_t), intent(in), optional :: check !! yield check
    integer :: k, m, it, ns, n
    real(wp) :: dt, resid
    logical, parameter :: NOMASK(6) = .false.
    n = ref%n
    ns = size(pt%state)
    hist%n = n
    allocate(hist%t(0:n), hist%stress(6, 0:n), hist%strain(6, 0:n), hist%state(ns, 0:n))
    allocate(hist%L(3, 3, n)); hist%L = ref%L(:,:,1:n)
    hist%t(0) = pt%t; hist%stress(:,0) = pt%stress; hist%strain(:,0) = pt%strain
    hist%state(:,0) = pt%state
    hist%max_yield = 0.0_wp; hist%max_residual = 0.0_wp; hist%newton_max = 0
    if (present(check)) hist%max_yield = check%violation(pt%stress, pt%state)
    info = 0
    do k = 1, n
      dt = (ref%t(k) - ref%t(k - 1)) / real(nsub, wp)
      do m = 1, nsub
        call empm_sp_increment(mat, pt, dt, ref%L(:,:,k), NOMASK, pt%stress, 0.0_wp, info, &
                               resid, it)
        if (info /= 0) then
          hist%n = k - 1; return
        end if
        if (present(check)) hist%max_yield = max(hist%max_yield, &
                                                 check%violation(pt%stress, pt%state))
      end do
      hist%t(k) = pt%t; hist%stress(:,k) = pt%stress; hist%strain(:,k) = pt%strain
      hist%state(:,k) = pt%state
    end do
  end subroutine empm_sp_replay
end module empm_stress_point
