!> Transfer kernels on the compact 3 × 3 × 3 stencils of a 3D grid (`BASIS_B27` and
!> `BASIS_G27` of [[empm_basis_t]]): per particle the first node `id` of its stencil and the
!> local coordinates (t1, t2, t3) — for uGIMP the stored 1D factors (`wg`); the nodes are
!> id + a + s·b + s2·c (a, b, c = 0, 1, 2; s = nodes along x, s2 = nodes per x-y plane) and the
!> values and gradients are formed here: 3 + 3 + 3 one-dimensional factors (B-splines:
!> recomputed; uGIMP: read, as in [[empm_transfer_s9]]), then their products.
!>
!> Why: the node lists of a 3D basis with 27 nodes hold 972 B per particle, written by the shape
!> phase and read by four passes a step; the compact layouts hold 28 B (B-splines) or 148 B
!> (uGIMP). The products are those of the lists (`shape_tp_store`), and every kernel does the
!> arithmetic of its node-list counterpart in [[empm_transfer_3d]] / [[empm_transfer]] in the
!> same order; a zero-valued stencil node adds ±0, so the results are the lists', the sign of
!> a zero aside (tests/unit/test_transfer_compact.pf). One particle at a time
!> (`!GCC$ novector`), as in [[empm_transfer_s9]]. Arrays are explicit-shape and contiguous;
!> kernels work on particles p0..p1.
module empm_transfer_s27
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  implicit none
  private
  public :: mass_s27, weighted_s27, mass_momentum_s27, body_force_s27, internal_force_s27, &
            velocity_gradient_s27, g2p_s27, gradient_g2p_s27

contains

  ! b9_factors, g9_factors: the one text of the stencils' 1D factors (src/shape).
  include '../shape/empm_stencil_weights.inc'

  !> m_I += Σ N_Ip m_p.
  pure subroutine mass_s27(s, s2, h, p0, p1, cell, t, gimp, wg, m, mass)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp) :: w(3, 3), g(3, 3), w23
    integer :: p, a, b, c
    integer(int64) :: I ! 64-bit: the neighbours' addresses are offsets of the first node's
    !GCC$ novector
    do p = p0, p1
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      do c = 1, 3
        do b = 1, 3
          w23 = w(b, 2) * w(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            mass(I) = mass(I) + (w(a, 1) * w23) * m(p)
            I = I + 1
          end do
        end do
      end do
    end do
  end subroutine mass_s27

  !> q_I += Σ N_Ip m_p (u_p + c w_p) (cw = 0 ignores w).
  pure subroutine weighted_s27(s, s2, h, p0, p1, cell, t, gimp, wg, m, u, cw, w, q)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: cw               !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    real(wp) :: wf(3, 3), g(3, 3), mu(3), w23
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      if (cw == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + cw * w(:, p))
      end if
      if (gimp) then
        wf = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), wf(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), wf(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), wf(:, 3), g(:, 3))
      end if
      do c = 1, 3
        do b = 1, 3
          w23 = wf(b, 2) * wf(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            q(:, I) = q(:, I) + (wf(a, 1) * w23) * mu
            I = I + 1
          end do
        end do
      end do
    end do
  end subroutine weighted_s27

  !> m_I += Σ N_Ip m_p and q_I += Σ N_Ip m_p (u_p + cw w_p), one pass (cw = 0 ignores w); with
  !> `fill` also V_I += Σ N_Ip vol_p (the fill volumes).
  pure subroutine mass_momentum_s27(s, s2, h, p0, p1, cell, t, gimp, wg, m, u, cw, w, mass, q, &
                               fill, vol, vn)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: cw               !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    logical, intent(in) :: fill              !! also the fill volumes
    real(wp), intent(in) :: vol(*)           !! particle fill volumes (with `fill`)
    real(wp), intent(inout) :: vn(*)         !! nodal fill volumes (with `fill`; accumulated)
    real(wp) :: wf(3, 3), g(3, 3), mu(3), w23, nk
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      if (cw == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + cw * w(:, p))
      end if
      if (gimp) then
        wf = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), wf(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), wf(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), wf(:, 3), g(:, 3))
      end if
      do c = 1, 3
        do b = 1, 3
          w23 = wf(b, 2) * wf(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            nk = wf(a, 1) * w23
            mass(I) = mass(I) + nk * m(p)
            q(:, I) = q(:, I) + nk * mu
            if (fill) vn(I) = vn(I) + nk * vol(p)
            I = I + 1
          end do
        end do
      end do
    end do
  end subroutine mass_momentum_s27

  !> f_I += Σ N_Ip m_p (g + b_p) (b only with `use_b`).
  pure subroutine body_force_s27(s, s2, h, p0, p1, cell, t, gimp, wg, m, ga, bf, use_b, f)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: ga(3)            !! uniform acceleration
    real(wp), intent(in) :: bf(3, *)         !! body force per unit mass (with `use_b`)
    logical, intent(in) :: use_b             !! whether `bf` holds data
    real(wp), intent(inout) :: f(3, *)       !! nodal forces (accumulated)
    real(wp) :: w(3, 3), g(3, 3), fp(3), w23
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      fp = ga
      if (use_b) fp = fp + bf(:, p)
      fp = m(p) * fp
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      do c = 1, 3
        do b = 1, 3
          w23 = w(b, 2) * w(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            f(:, I) = f(:, I) + (w(a, 1) * w23) * fp
            I = I + 1
          end do
        end do
      end do
    end do
  end subroutine body_force_s27

  !> f_I −= Σ V_p σ_p ∇N_Ip (σ in Voigt order: xx, yy, zz, yz, xz, xy).
  pure subroutine internal_force_s27(s, s2, h, p0, p1, cell, t, gimp, wg, vol, stress, f)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: vol(*)           !! particle volumes
    real(wp), intent(in) :: stress(6, *)     !! Cauchy stresses
    real(wp), intent(inout) :: f(3, *)       !! nodal forces (accumulated)
    real(wp) :: w(3, 3), g(3, 3), sv(3, 3), d1, d2, d3, tc
    integer :: p, a, b, c, k
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      sv(1, 1) = stress(1, p); sv(2, 2) = stress(2, p); sv(3, 3) = stress(3, p)
      sv(2, 3) = stress(4, p); sv(3, 2) = stress(4, p)
      sv(1, 3) = stress(5, p); sv(3, 1) = stress(5, p)
      sv(1, 2) = stress(6, p); sv(2, 1) = stress(6, p)
      sv = vol(p) * sv
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      do c = 1, 3
        do b = 1, 3
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            ! ∇N: the lists' products (shape_tp_store).
            d1 = g(a, 1) * (w(b, 2) * w(c, 3))
            d2 = g(b, 2) * (w(a, 1) * w(c, 3))
            d3 = g(c, 3) * (w(a, 1) * w(b, 2))
            do k = 1, 3
              tc = ((0.0_wp + sv(k, 1) * d1) + sv(k, 2) * d2) + sv(k, 3) * d3
              f(k, I) = f(k, I) - tc
            end do
            I = I + 1
          end do
        end do
      end do
    end do
  end subroutine internal_force_s27

  !> L_p = Σ v_I ⊗ ∇N_Ip, the full 3×3 gradient, into L(:, :, 1..p1−p0+1).
  pure subroutine velocity_gradient_s27(s, s2, h, p0, p1, cell, t, gimp, wg, v, L)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients
    real(wp) :: w(3, 3), g(3, 3), lx(3), ly(3), lz(3)
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      lx = 0.0_wp; ly = 0.0_wp; lz = 0.0_wp
      do c = 1, 3
        do b = 1, 3
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            lx = lx + v(:, I) * (g(a, 1) * (w(b, 2) * w(c, 3)))
            ly = ly + v(:, I) * (g(b, 2) * (w(a, 1) * w(c, 3)))
            lz = lz + v(:, I) * (g(c, 3) * (w(a, 1) * w(b, 2)))
            I = I + 1
          end do
        end do
      end do
      L(:, 1, p - p0 + 1) = lx; L(:, 2, p - p0 + 1) = ly; L(:, 3, p - p0 + 1) = lz
    end do
  end subroutine velocity_gradient_s27

  !> u_p = Σ N_Ip q_I, or with `add` u_p += c Σ N_Ip q_I.
  pure subroutine g2p_s27(s, s2, h, p0, p1, cell, t, gimp, wg, q, add, cs, u)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: q(3, *)          !! nodal vectors
    logical, intent(in) :: add               !! accumulate cs Σ N q instead of overwriting
    real(wp), intent(in) :: cs               !! scale (with `add`)
    real(wp), intent(inout) :: u(3, *)       !! particle vectors
    real(wp) :: w(3, 3), g(3, 3), sm(3), w23
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      sm = 0.0_wp
      do c = 1, 3
        do b = 1, 3
          w23 = w(b, 2) * w(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            sm = sm + (w(a, 1) * w23) * q(:, I)
            I = I + 1
          end do
        end do
      end do
      if (add) then
        u(:, p) = u(:, p) + cs * sm
      else
        u(:, p) = sm
      end if
    end do
  end subroutine g2p_s27

  !> The two of [[velocity_gradient_s27]] and [[g2p_s27]] (with `add`) on the same nodal field
  !> in one pass: L_p = Σ v_I ⊗ ∇N_Ip into L(:, :, 1..p1−p0+1) and u_p += cs Σ N_Ip v_I, each
  !> sum in its own kernel's order (the same bits); the factors are formed and the nodes read
  !> once.
  pure subroutine gradient_g2p_s27(s, s2, h, p0, p1, cell, t, gimp, wg, v, L, cs, u)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! first node of each particle's stencil
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    logical, intent(in) :: gimp              !! uGIMP: factors stored in `wg` (else B-splines)
    real(wp), intent(in) :: wg(3, 2, 3, *)   !! uGIMP: values, slopes per direction
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients
    real(wp), intent(in) :: cs               !! scale of the interpolated velocity
    real(wp), intent(inout) :: u(3, *)       !! particle vectors (accumulated)
    real(wp) :: w(3, 3), g(3, 3), lx(3), ly(3), lz(3), sm(3), w23
    integer :: p, a, b, c
    integer(int64) :: I
    !GCC$ novector
    do p = p0, p1
      if (gimp) then
        w = wg(:, 1, :, p); g = wg(:, 2, :, p)
      else
        call b9_factors(t(1, p), h(1), w(:, 1), g(:, 1))
        call b9_factors(t(2, p), h(2), w(:, 2), g(:, 2))
        call b9_factors(t(3, p), h(3), w(:, 3), g(:, 3))
      end if
      lx = 0.0_wp; ly = 0.0_wp; lz = 0.0_wp; sm = 0.0_wp
      do c = 1, 3
        do b = 1, 3
          w23 = w(b, 2) * w(c, 3)
          I = cell(p) + int(s, int64) * (b - 1) + int(s2, int64) * (c - 1)
          do a = 1, 3
            lx = lx + v(:, I) * (g(a, 1) * w23)
            ly = ly + v(:, I) * (g(b, 2) * (w(a, 1) * w(c, 3)))
            lz = lz + v(:, I) * (g(c, 3) * (w(a, 1) * w(b, 2)))
            sm = sm + (w(a, 1) * w23) * v(:, I)
            I = I + 1
          end do
        end do
      end do
      L(:, 1, p - p0 + 1) = lx; L(:, 2, p - p0 + 1) = ly; L(:, 3, p - p0 + 1) = lz
      u(:, p) = u(:, p) + cs * sm
    end do
  end subroutine gradient_g2p_s27

end module empm_transfer_s27
