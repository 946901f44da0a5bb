!> Three-dimensional transfer kernels: the hot particle loops of [[empm_transfer]] with the
!> dimension fixed at compile time, as [[empm_transfer_2d]] does for plane strain.
!>
!> The generic loops run over a run-time dimension (and zero small temporaries) inside the
!> loop over a particle's nodes, and cost a 3D linear step half its time; here the vectors are
!> fixed-size and the loops over components unrolled. Each kernel does the same arithmetic in
!> the same order as its generic counterpart, so results are identical bit for bit. Arrays are
!> explicit-shape and contiguous; the caller passes the basis arrays of an [[empm_basis_t]]
!> with `mx = basis%maxn` and a particle range p0..p1.
module empm_transfer_3d
  use empm_kinds, only: wp
  implicit none
  private
  public :: weighted_3d, mass_momentum_3d, internal_force_3d, velocity_gradient_3d, g2p_3d, &
            gradient_g2p_3d

contains

  !> q_I += Σ N_Ip m_p (u_p + c w_p) (c = 0 ignores w).
  pure subroutine weighted_3d(mx, p0, p1, nn, node, N, m, u, c, w, q)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    real(wp) :: mu(3)
    integer :: p, k, I
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      do k = 1, nn(p)
        I = node(k, p)
        q(:, I) = q(:, I) + N(k, p) * mu
      end do
    end do
  end subroutine weighted_3d

  !> m_I += Σ N_Ip m_p and q_I += Σ N_Ip m_p (u_p + c w_p), one pass (c = 0 ignores w); with
  !> `fill` also V_I += Σ N_Ip vol_p (the fill volumes).
  pure subroutine mass_momentum_3d(mx, p0, p1, nn, node, N, m, u, c, w, mass, q, fill, vol, vn)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(3, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(3, *)          !! second particle vectors
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp), intent(inout) :: q(3, *)       !! nodal vectors (accumulated)
    logical, intent(in) :: fill              !! also the fill volumes
    real(wp), intent(in) :: vol(*)           !! particle fill volumes (with `fill`)
    real(wp), intent(inout) :: vn(*)         !! nodal fill volumes (with `fill`; accumulated)
    real(wp) :: mu(3), nk
    integer :: p, k, I
    do p = p0, p1
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      do k = 1, nn(p)
        I = node(k, p); nk = N(k, p)
        mass(I) = mass(I) + nk * m(p)
        q(:, I) = q(:, I) + nk * mu
        if (fill) vn(I) = vn(I) + nk * vol(p)
      end do
    end do
  end subroutine mass_momentum_3d

  !> f_I −= Σ V_p σ_p ∇N_Ip (σ in Voigt order: xx, yy, zz, yz, xz, xy).
  pure subroutine internal_force_3d(mx, p0, p1, nn, node, dN, vol, stress, f)
    integer, intent(in) :: mx                !! basis capacity
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: dN(3, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: vol(*)           !! particle volumes
    real(wp), intent(in) :: stress(6, *)     !! Cauchy stresses
    real(wp), intent(inout) :: f(3, *)       !! nodal forces (accumulated)
    real(wp) :: s(3, 3), t
    integer :: p, k, I, a
    do p = p0, p1
      s(1, 1) = stress(1, p); s(2, 2) = stress(2, p); s(3, 3) = stress(3, p)
      s(2, 3) = stress(4, p); s(3, 2) = stress(4, p)
      s(1, 3) = stress(5, p); s(3, 1) = stress(5, p)
      s(1, 2) = stress(6, p); s(2, 1) = stress(6, p)
      s = vol(p) * s
      do k = 1, nn(p)
        I = node(k, p)
        ! (σV ∇N)_a summed over b in order, from 0 (as the generic loop).
        do a = 1, 3
          t = ((0.0_wp + s(a, 1) * dN(1, k, p)) + s(a, 2) * dN(2, k, p)) + s(a, 3) * dN(3, k, p)
          f(a, I) = f(a, I) - t
        end do
      end do
    end do
  end subroutine internal_force_3d

  !> L_p = Σ v_I ⊗ ∇N_Ip, the full 3×3 gradient.
  pure subroutine velocity_gradient_3d(mx, p0, p1, nn, node, dN, v, L)
    integer, intent(in) :: mx                !! basis capacity
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: dN(3, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients
    real(wp) :: gx(3), gy(3), gz(3)
    integer :: p, k, I
    do p = p0, p1
      gx = 0.0_wp; gy = 0.0_wp; gz = 0.0_wp
      do k = 1, nn(p)
        I = node(k, p)
        gx = gx + v(:, I) * dN(1, k, p)
        gy = gy + v(:, I) * dN(2, k, p)
        gz = gz + v(:, I) * dN(3, k, p)
      end do
      L(:, 1, p) = gx; L(:, 2, p) = gy; L(:, 3, p) = gz
    end do
  end subroutine velocity_gradient_3d

  !> u_p = Σ N_Ip q_I, or with `add` u_p += c Σ N_Ip q_I.
  pure subroutine g2p_3d(mx, p0, p1, nn, node, N, q, add, c, u)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: q(3, *)          !! nodal vectors
    logical, intent(in) :: add               !! accumulate c Σ N q instead of overwriting
    real(wp), intent(in) :: c                !! scale (with `add`)
    real(wp), intent(inout) :: u(3, *)       !! particle vectors
    real(wp) :: s(3)
    integer :: p, k
    do p = p0, p1
      s = 0.0_wp
      do k = 1, nn(p)
        s = s + N(k, p) * q(:, node(k, p))
      end do
      if (add) then
        u(:, p) = u(:, p) + c * s
      else
        u(:, p) = s
      end if
    end do
  end subroutine g2p_3d

  !> The two of [[velocity_gradient_3d]] and [[g2p_3d]] (with `add`) on the same nodal field in
  !> one pass, for particles p0..p1: L_p = Σ v_I ⊗ ∇N_Ip into L(:, :, 1..p1−p0+1) and
  !> u_p += c Σ N_Ip v_I, each sum in its own kernel's order (the same bits); the node indices
  !> and velocities are read once.
  pure subroutine gradient_g2p_3d(mx, p0, p1, nn, node, N, dN, v, L, c, u)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: dN(3, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: v(3, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (written)
    real(wp), intent(in) :: c                !! scale of the interpolated velocity
    real(wp), intent(inout) :: u(3, *)       !! particle vectors (accumulated)
    real(wp) :: gx(3), gy(3), gz(3), s(3)
    integer :: p, k, I
    do p = p0, p1
      gx = 0.0_wp; gy = 0.0_wp; gz = 0.0_wp; s = 0.0_wp
      do k = 1, nn(p)
        I = node(k, p)
        gx = gx + v(:, I) * dN(1, k, p)
        gy = gy + v(:, I) * dN(2, k, p)
        gz = gz + v(:, I) * dN(3, k, p)
        s = s + N(k, p) * v(:, I)
      end do
      L(:, 1, p - p0 + 1) = gx; L(:, 2, p - p0 + 1) = gy; L(:, 3, p - p0 + 1) = gz
      u(:, p) = u(:, p) + c * s
    end do
  end subroutine gradient_g2p_3d

end module empm_transfer_3d
