!> Transfer kernels on the compact bilinear basis (`BASIS_Q4` of [[empm_basis_t]]): per
!> particle the lowest node `id` of its cell and the local coordinates (t1, t2); the nodes are
!> id, id + 1, id + s, id + s + 1 (s = nodes along x) and the values and gradients are
!> recomputed here from (t1, t2).
!>
!> Why: 2D linear runs are limited by memory traffic on two threads; the node lists with
!> values and gradients (116 B per particle, written once and read by four passes) shrink to
!> 20 B, and the fixed four-node loops need no node count or index loads. The values are the
!> expressions of [[basis_q4_weights]], included from src/shape/empm_q4_weights.inc (one
!> text, compiled into this file so that it is inlined), and every kernel does the same
!> arithmetic in the same order as its node-list counterpart in [[empm_transfer_2d]] /
!> [[empm_transfer]], so results are identical bit for bit (tests/unit/test_transfer_q4.pf
!> checks both). Arrays are explicit-shape and contiguous; kernels work on particles p0..p1.
module empm_transfer_q4
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  implicit none
  private
  public :: mass_q4, weighted_q4, mass_momentum_q4, body_force_q4, internal_force_q4, &
            velocity_gradient_q4, g2p_q4, gradient_g2p_q4

contains

  ! q4_values and q4_gradients: the one text of the bilinear formulas (src/shape).
  include '../shape/empm_q4_weights.inc'

  !> m_I += Σ N_Ip m_p.
  pure subroutine mass_q4(s, p0, p1, cell, t, m, mass)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp) :: N(4)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      call q4_values(t(1, p), t(2, p), N)
      I = cell(p); J = I + s
      mass(I) = mass(I) + N(1) * m(p)
      mass(I + 1) = mass(I + 1) + N(2) * m(p)
      mass(J) = mass(J) + N(3) * m(p)
      mass(J + 1) = mass(J + 1) + N(4) * m(p)
    end do
  end subroutine mass_q4

  !> q_I += Σ N_Ip m_p (u_p + c w_p) (c = 0 ignores w).
  pure subroutine weighted_q4(s, p0, p1, cell, t, m, u, c, w, q)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(2, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(2, *)          !! second particle vectors
    real(wp), intent(inout) :: q(2, *)       !! nodal vectors (accumulated)
    real(wp) :: N(4), mu(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      call q4_values(t(1, p), t(2, p), N)
      I = cell(p); J = I + s
      q(:, I) = q(:, I) + N(1) * mu
      q(:, I + 1) = q(:, I + 1) + N(2) * mu
      q(:, J) = q(:, J) + N(3) * mu
      q(:, J + 1) = q(:, J + 1) + N(4) * mu
    end do
  end subroutine weighted_q4

  !> m_I += Σ N_Ip m_p and q_I += Σ N_Ip m_p (u_p + c w_p), one pass (c = 0 ignores w); with
  !> `fill` also V_I += Σ N_Ip vol_p (the fill volumes).
  pure subroutine mass_momentum_q4(s, p0, p1, cell, t, m, u, c, w, mass, q, fill, vol, vn)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(2, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(2, *)          !! second particle vectors
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp), intent(inout) :: q(2, *)       !! nodal vectors (accumulated)
    logical, intent(in) :: fill              !! also the fill volumes
    real(wp), intent(in) :: vol(*)           !! particle fill volumes (with `fill`)
    real(wp), intent(inout) :: vn(*)         !! nodal fill volumes (with `fill`; accumulated)
    real(wp) :: N(4), mu(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      call q4_values(t(1, p), t(2, p), N)
      I = cell(p); J = I + s
      mass(I) = mass(I) + N(1) * m(p);         q(:, I) = q(:, I) + N(1) * mu
      mass(I + 1) = mass(I + 1) + N(2) * m(p); q(:, I + 1) = q(:, I + 1) + N(2) * mu
      mass(J) = mass(J) + N(3) * m(p);         q(:, J) = q(:, J) + N(3) * mu
      mass(J + 1) = mass(J + 1) + N(4) * m(p); q(:, J + 1) = q(:, J + 1) + N(4) * mu
      if (fill) then
        vn(I) = vn(I) + N(1) * vol(p); vn(I + 1) = vn(I + 1) + N(2) * vol(p)
        vn(J) = vn(J) + N(3) * vol(p); vn(J + 1) = vn(J + 1) + N(4) * vol(p)
      end if
    end do
  end subroutine mass_momentum_q4

  !> f_I += Σ N_Ip m_p (g + b_p) (b only with `use_b`).
  pure subroutine body_force_q4(s, p0, p1, cell, t, m, g, b, use_b, f)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: g(2)             !! uniform acceleration
    real(wp), intent(in) :: b(2, *)          !! body force per unit mass (with `use_b`)
    logical, intent(in) :: use_b             !! whether `b` holds data
    real(wp), intent(inout) :: f(2, *)       !! nodal forces (accumulated)
    real(wp) :: N(4), fp(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      fp = g
      if (use_b) fp = fp + b(:, p)
      fp = m(p) * fp
      call q4_values(t(1, p), t(2, p), N)
      I = cell(p); J = I + s
      f(:, I) = f(:, I) + N(1) * fp
      f(:, I + 1) = f(:, I + 1) + N(2) * fp
      f(:, J) = f(:, J) + N(3) * fp
      f(:, J + 1) = f(:, J + 1) + N(4) * fp
    end do
  end subroutine body_force_q4

  !> f_I −= Σ V_p σ_p ∇N_Ip (σ in Voigt order: xx, yy, zz, yz, xz, xy).
  pure subroutine internal_force_q4(s, h, p0, p1, cell, t, vol, stress, f)
    integer, intent(in) :: s                 !! nodes along x
    real(wp), intent(in) :: h(2)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: vol(*)           !! particle volumes
    real(wp), intent(in) :: stress(6, *)     !! Cauchy stresses
    real(wp), intent(inout) :: f(2, *)       !! nodal forces (accumulated)
    real(wp) :: dN(2, 4), sx(2), sy(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      sx(1) = vol(p) * stress(1, p); sx(2) = vol(p) * stress(6, p)
      sy(1) = sx(2); sy(2) = vol(p) * stress(2, p)
      call q4_gradients(t(1, p), t(2, p), h(1), h(2), -h(1), -h(2), dN)
      I = cell(p); J = I + s
      f(:, I) = f(:, I) - (sx * dN(1, 1) + sy * dN(2, 1))
      f(:, I + 1) = f(:, I + 1) - (sx * dN(1, 2) + sy * dN(2, 2))
      f(:, J) = f(:, J) - (sx * dN(1, 3) + sy * dN(2, 3))
      f(:, J + 1) = f(:, J + 1) - (sx * dN(1, 4) + sy * dN(2, 4))
    end do
  end subroutine internal_force_q4

  !> L_p = Σ v_I ⊗ ∇N_Ip, the 2×2 block of the 3×3 gradient, into L(:, :, 1..p1−p0+1).
  pure subroutine velocity_gradient_q4(s, h, p0, p1, cell, t, v, L)
    integer, intent(in) :: s                 !! nodes along x
    real(wp), intent(in) :: h(2)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: v(2, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (2×2 block written)
    real(wp) :: dN(2, 4), gx(2), gy(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    !GCC$ novector
    do p = p0, p1
      call q4_gradients(t(1, p), t(2, p), h(1), h(2), -h(1), -h(2), dN)
      I = cell(p); J = I + s
      gx = 0.0_wp; gy = 0.0_wp
      gx = gx + v(:, I) * dN(1, 1);     gy = gy + v(:, I) * dN(2, 1)
      gx = gx + v(:, I + 1) * dN(1, 2); gy = gy + v(:, I + 1) * dN(2, 2)
      gx = gx + v(:, J) * dN(1, 3);     gy = gy + v(:, J) * dN(2, 3)
      gx = gx + v(:, J + 1) * dN(1, 4); gy = gy + v(:, J + 1) * dN(2, 4)
      L(1:2, 1, p - p0 + 1) = gx; L(1:2, 2, p - p0 + 1) = gy
    end do
  end subroutine velocity_gradient_q4

  !> u_p = Σ N_Ip q_I, or with `add` u_p += c Σ N_Ip q_I.
  pure subroutine g2p_q4(s, p0, p1, cell, t, q, add, c, u)
    integer, intent(in) :: s                 !! nodes along x
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: q(2, *)          !! nodal vectors
    logical, intent(in) :: add               !! accumulate c Σ N q instead of overwriting
    real(wp), intent(in) :: c                !! scale (with `add`)
    real(wp), intent(inout) :: u(2, *)       !! particle vectors
    real(wp) :: N(4), sm(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    do p = p0, p1
      call q4_values(t(1, p), t(2, p), N)
      I = cell(p); J = I + s
      sm = 0.0_wp
      sm = sm + N(1) * q(:, I)
      sm = sm + N(2) * q(:, I + 1)
      sm = sm + N(3) * q(:, J)
      sm = sm + N(4) * q(:, J + 1)
      if (add) then
        u(:, p) = u(:, p) + c * sm
      else
        u(:, p) = sm
      end if
    end do
  end subroutine g2p_q4

  !> The two of [[velocity_gradient_q4]] and [[g2p_q4]] (with `add`) on the same nodal field in
  !> one pass: L_p = Σ v_I ⊗ ∇N_Ip into L(:, :, 1..p1−p0+1) and u_p += c Σ N_Ip v_I, each sum in
  !> its own kernel's order (the same bits); the nodes are read and the weights formed once.
  pure subroutine gradient_g2p_q4(s, h, p0, p1, cell, t, v, L, c, u)
    integer, intent(in) :: s                 !! nodes along x
    real(wp), intent(in) :: h(2)             !! 1/h per direction
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: cell(*)           !! lowest node of each particle's cell
    real(wp), intent(in) :: t(2, *)          !! local coordinates
    real(wp), intent(in) :: v(2, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (2×2 block written)
    real(wp), intent(in) :: c                !! scale of the interpolated velocity
    real(wp), intent(inout) :: u(2, *)       !! particle vectors (accumulated)
    real(wp) :: N(4), dN(2, 4), gx(2), gy(2), sm(2)
    integer :: p
    integer(int64) :: I, J ! 64-bit: the neighbours' addresses are offsets of I's
    !GCC$ novector
    do p = p0, p1
      call q4_values(t(1, p), t(2, p), N)
      call q4_gradients(t(1, p), t(2, p), h(1), h(2), -h(1), -h(2), dN)
      I = cell(p); J = I + s
      gx = 0.0_wp; gy = 0.0_wp; sm = 0.0_wp
      gx = gx + v(:, I) * dN(1, 1);     gy = gy + v(:, I) * dN(2, 1);     sm = sm + N(1) * v(:, I)
      gx = gx + v(:, I + 1) * dN(1, 2); gy = gy + v(:, I + 1) * dN(2, 2); sm = sm + N(2) * v(:, I + 1)
      gx = gx + v(:, J) * dN(1, 3);     gy = gy + v(:, J) * dN(2, 3);     sm = sm + N(3) * v(:, J)
      gx = gx + v(:, J + 1) * dN(1, 4); gy = gy + v(:, J + 1) * dN(2, 4); sm = sm + N(4) * v(:, J + 1)
      L(1:2, 1, p - p0 + 1) = gx; L(1:2, 2, p - p0 + 1) = gy
      u(:, p) = u(:, p) + c * sm
    end do
  end subroutine gradient_g2p_q4

end module empm_transfer_q4
