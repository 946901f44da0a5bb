!> Transfer kernels on the compact trilinear basis (`BASIS_Q8` of [[empm_basis_t]]): per
!> particle the lowest node `id` of its cell and the local coordinates t ∈ [0, 1]³; the eight
!> nodes are id + a + s·b + s2·c (a, b, c = 0, 1; s nodes along x, s2 per x-y plane), in that
!> order (x fastest), and the values and gradients are recomputed here from t.
!>
!> Why: the node lists of a 3D linear basis hold 292 B per particle (8 node indices, values
!> and gradients), written by the shape phase and read by six passes a step; the compact
!> layout holds 28 B, and the fixed eight-node loops need no node count or index loads. The
!> values are the expressions of [[basis_q8_weights]], included from
!> src/shape/empm_q8_weights.inc (one text, compiled into this file so that it is inlined),
!> and every kernel does the same arithmetic in the same order as its node-list counterpart in
!> [[empm_transfer_3d]] / [[empm_transfer]], so results are identical bit for bit
!> (tests/unit/test_transfer_q8.pf checks both). Arrays are explicit-shape and contiguous;
!> kernels work on particles p0..p1.
module empm_transfer_q8
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  implicit none
  private
  public :: mass_q8, weighted_q8, mass_momentum_q8, body_force_q8, internal_force_q8, &
            velocity_gradient_q8, g2p_q8, gradient_g2p_q8

contains

  ! q8_values and q8_gradients: the one text of the trilinear formulas (src/shape).
  include '../shape/empm_q8_weights.inc'

  !> The offsets of the eight nodes from the cell's lowest node (64-bit: they are added to
  !> addresses).
  pure function offsets(s, s2) result(off)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer(int64) :: off(8)                 !! offsets, in the basis's node order
    off = int([0, 1, s, s + 1, s2, s2 + 1, s2 + s, s2 + s + 1], int64)
  end function offsets

  !> m_I += Σ N_Ip m_p.
  pure subroutine mass_q8(s, s2, p0, p1, cell, t, m, mass)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp) :: N(8)
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    do p = p0, p1
      call q8_values(t(:, p), N)
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        mass(I) = mass(I) + N(k) * m(p)
      end do
    end do
  end subroutine mass_q8

  !> q_I += Σ N_Ip m_p (u_p + c w_p) (c = 0 ignores w).
  pure subroutine weighted_q8(s, s2, p0, p1, cell, t, m, u, c, w, q)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    real(wp) :: N(8), mu(3)
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      call q8_values(t(:, p), N)
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        q(:, I) = q(:, I) + N(k) * mu
      end do
    end do
  end subroutine weighted_q8

  !> m_I += Σ N_Ip m_p and q_I += Σ N_Ip m_p (u_p + c w_p), one pass (c = 0 ignores w); with
  !> `fill` also V_I += Σ N_Ip vol_p (the fill volumes).
  pure subroutine mass_momentum_q8(s, s2, p0, p1, cell, t, m, u, c, w, mass, q, fill, vol, vn)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    logical, intent(in) :: fill              !! also the fill volumes
    real(wp), intent(in) :: vol(*)           !! particle fill volumes (with `fill`)
    real(wp), intent(inout) :: vn(*)         !! nodal fill volumes (with `fill`; accumulated)
    real(wp) :: N(8), mu(3)
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      call q8_values(t(:, p), N)
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        mass(I) = mass(I) + N(k) * m(p)
        q(:, I) = q(:, I) + N(k) * mu
        if (fill) vn(I) = vn(I) + N(k) * vol(p)
      end do
    end do
  end subroutine mass_momentum_q8

  !> f_I += Σ N_Ip m_p (g + b_p) (b only with `use_b`).
  pure subroutine body_force_q8(s, s2, p0, p1, cell, t, m, g, b, use_b, f)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: g(3)             !! uniform acceleration
    real(wp), intent(in) :: b(3, *)          !! body force per unit mass (with `use_b`)
    logical, intent(in) :: use_b             !! whether `b` holds data
    real(wp), intent(inout) :: f(3, *)       !! nodal forces (accumulated)
    real(wp) :: N(8), fp(3)
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    do p = p0, p1
      fp = g
      if (use_b) fp = fp + b(:, p)
      fp = m(p) * fp
      call q8_values(t(:, p), N)
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        f(:, I) = f(:, I) + N(k) * fp
      end do
    end do
  end subroutine body_force_q8

  !> f_I −= Σ V_p σ_p ∇N_Ip (σ in Voigt order: xx, yy, zz, yz, xz, xy).
  pure subroutine internal_force_q8(s, s2, h, p0, p1, cell, t, vol, stress, f)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: vol(*)           !! particle volumes
    real(wp), intent(in) :: stress(6, *)     !! Cauchy stresses
    real(wp), intent(inout) :: f(3, *)       !! nodal forces (accumulated)
    real(wp) :: dN(3, 8), sg(3, 3), m(3), r
    real(wp) :: tp(3), u1, u2, u3, a00, a10, a01, a11, c00, c10, c01, c11, e00, e10, e01, e11
    integer(int64) :: off(8), I
    integer :: p, k, a
    off = offsets(s, s2)
    m = -h
    do p = p0, p1
      sg(1, 1) = stress(1, p); sg(2, 2) = stress(2, p); sg(3, 3) = stress(3, p)
      sg(2, 3) = stress(4, p); sg(3, 2) = stress(4, p)
      sg(1, 3) = stress(5, p); sg(3, 1) = stress(5, p)
      sg(1, 2) = stress(6, p); sg(2, 1) = stress(6, p)
      sg = vol(p) * sg
      tp = t(:, p)
      include '../shape/empm_q8_gradients.inc'
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        ! (σV ∇N)_a summed over b in order, from 0 (as the node lists' loop).
        do a = 1, 3
          r = ((0.0_wp + sg(a, 1) * dN(1, k)) + sg(a, 2) * dN(2, k)) + sg(a, 3) * dN(3, k)
          f(a, I) = f(a, I) - r
        end do
      end do
    end do
  end subroutine internal_force_q8

  !> L_p = Σ v_I ⊗ ∇N_Ip, the full 3×3 gradient, into L(:, :, 1..p1−p0+1).
  pure subroutine velocity_gradient_q8(s, s2, h, p0, p1, cell, t, v, L)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients
    real(wp) :: dN(3, 8), gx(3), gy(3), gz(3), m(3)
    real(wp) :: tp(3), u1, u2, u3, a00, a10, a01, a11, c00, c10, c01, c11, e00, e10, e01, e11
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    m = -h
    do p = p0, p1
      tp = t(:, p)
      include '../shape/empm_q8_gradients.inc'
      gx = 0.0_wp; gy = 0.0_wp; gz = 0.0_wp
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        gx = gx + v(:, I) * dN(1, k)
        gy = gy + v(:, I) * dN(2, k)
        gz = gz + v(:, I) * dN(3, k)
      end do
      L(:, 1, p - p0 + 1) = gx; L(:, 2, p - p0 + 1) = gy; L(:, 3, p - p0 + 1) = gz
    end do
  end subroutine velocity_gradient_q8

  !> u_p = Σ N_Ip q_I, or with `add` u_p += c Σ N_Ip q_I.
  pure subroutine g2p_q8(s, s2, p0, p1, cell, t, q, add, c, u)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: q(3, *)          !! nodal vectors
    logical, intent(in) :: add               !! accumulate c Σ N q instead of overwriting
    real(wp), intent(in) :: c                !! scale (with `add`)
    real(wp), intent(inout) :: u(3, *)       !! particle vectors
    real(wp) :: N(8), sm(3)
    integer(int64) :: off(8)
    integer :: p, k
    off = offsets(s, s2)
    do p = p0, p1
      call q8_values(t(:, p), N)
      sm = 0.0_wp
      !GCC$ novector
      do k = 1, 8
        sm = sm + N(k) * q(:, cell(p) + off(k))
      end do
      if (add) then
        u(:, p) = u(:, p) + c * sm
      else
        u(:, p) = sm
      end if
    end do
  end subroutine g2p_q8

  !> The two of [[velocity_gradient_q8]] and [[g2p_q8]] (with `add`) on the same nodal field in
  !> one pass: L_p = Σ v_I ⊗ ∇N_Ip into L(:, :, 1..p1−p0+1) and u_p += c Σ N_Ip v_I, each sum in
  !> its own kernel's order (the same bits); the nodes are read and the weights formed once.
  pure subroutine gradient_g2p_q8(s, s2, h, p0, p1, cell, t, v, L, c, u)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: s2                !! nodes per x-y plane
    real(wp), intent(in) :: h(3)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(3, *)          !! local coordinates
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (written)
    real(wp), intent(in) :: c                !! scale of the interpolated velocity
    real(wp), intent(inout) :: u(3, *)       !! particle vectors (accumulated)
    real(wp) :: N(8), dN(3, 8), gx(3), gy(3), gz(3), sm(3), m(3)
    real(wp) :: tp(3), u1, u2, u3, a00, a10, a01, a11, c00, c10, c01, c11, e00, e10, e01, e11
    integer(int64) :: off(8), I
    integer :: p, k
    off = offsets(s, s2)
    m = -h
    do p = p0, p1
      call q8_values(t(:, p), N)
      tp = t(:, p)
      include '../shape/empm_q8_gradients.inc'
      gx = 0.0_wp; gy = 0.0_wp; gz = 0.0_wp; sm = 0.0_wp
      !GCC$ novector
      do k = 1, 8
        I = cell(p) + off(k)
        gx = gx + v(:, I) * dN(1, k)
        gy = gy + v(:, I) * dN(2, k)
        gz = gz + v(:, I) * dN(3, k)
        sm = sm + N(k) * v(:, I)
      end do
      L(:, 1, p - p0 + 1) = gx; L(:, 2, p - p0 + 1) = gy; L(:, 3, p - p0 + 1) = gz
      u(:, p) = u(:, p) + c * sm
    end do
  end subroutine gradient_g2p_q8

end module empm_transfer_q8
