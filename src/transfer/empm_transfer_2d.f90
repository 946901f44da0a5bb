!> Two-dimensional transfer kernels: the hot particle loops of [[empm_transfer]] with the
!> dimension fixed at compile time.
!>
!> Plane-strain runs are the common case, and the generic kernels spend most of their
!> instructions on run-time-sized inner loops (and on zeroing small temporaries); here the
!> nodal and particle vectors are scalars in registers. Each kernel does the same arithmetic in
!> the same order as its generic counterpart, so results are identical bit for bit. The
!> (x, y) pairs are written as two-element array operations so that the compiler can keep each
!> pair in one SIMD register. Arrays are
!> explicit-shape (leading extents known) and contiguous; the caller passes the basis arrays of
!> an [[empm_basis_t]] with `mx = basis%maxn` and a particle range p0..p1.
module empm_transfer_2d
  use empm_kinds, only: wp
  implicit none
  private
  public :: weighted_2d, mass_momentum_2d, internal_force_2d, velocity_gradient_2d, g2p_2d, &
            gradient_g2p_2d

contains

  !> q_I += Σ N_Ip m_p (u_p + c w_p) (c = 0 ignores w).
  pure subroutine weighted_2d(mx, p0, p1, nn, node, N, m, u, c, w, q)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(2, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(2, *)          !! second particle vectors
    real(wp), intent(inout) :: q(2, *)       !! nodal vectors (accumulated)
    real(wp) :: mu(2)
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
  end subroutine weighted_2d

  !> m_I += Σ N_Ip m_p and q_I += Σ N_Ip m_p (u_p + c w_p), one pass (c = 0 ignores w); with
  !> `fill` also V_I += Σ N_Ip vol_p (the fill volumes).
  pure subroutine mass_momentum_2d(mx, p0, p1, nn, node, N, m, u, c, w, mass, q, fill, vol, vn)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: m(*)             !! particle masses
    real(wp), intent(in) :: u(2, *)          !! particle vectors
    real(wp), intent(in) :: c                !! scale of `w`
    real(wp), intent(in) :: w(2, *)          !! second particle vectors
    real(wp), intent(inout) :: mass(*)       !! nodal masses (accumulated)
    real(wp), intent(inout) :: q(2, *)       !! nodal vectors (accumulated)
    logical, intent(in) :: fill              !! also the fill volumes
    real(wp), intent(in) :: vol(*)           !! particle fill volumes (with `fill`)
    real(wp), intent(inout) :: vn(*)         !! nodal fill volumes (with `fill`; accumulated)
    real(wp) :: mu(2), nk
    integer :: p, k, I
    ! Two-component vector operations throughout: the compiler packs them into SIMD pairs.
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
  end subroutine mass_momentum_2d

  !> f_I −= Σ V_p σ_p ∇N_Ip (σ in Voigt order: xx, yy, zz, yz, xz, xy).
  pure subroutine internal_force_2d(mx, p0, p1, nn, node, dN, vol, stress, f)
    integer, intent(in) :: mx                !! basis capacity
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: dN(2, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: vol(*)           !! particle volumes
    real(wp), intent(in) :: stress(6, *)     !! Cauchy stresses
    real(wp), intent(inout) :: f(2, *)       !! nodal forces (accumulated)
    real(wp) :: sx(2), sy(2)
    integer :: p, k, I
    do p = p0, p1
      ! Columns of V σ: f_I −= sx ∂xN + sy ∂yN.
      sx(1) = vol(p) * stress(1, p); sx(2) = vol(p) * stress(6, p)
      sy(1) = sx(2); sy(2) = vol(p) * stress(2, p)
      do k = 1, nn(p)
        I = node(k, p)
        f(:, I) = f(:, I) - (sx * dN(1, k, p) + sy * dN(2, k, p))
      end do
    end do
  end subroutine internal_force_2d

  !> L_p = Σ v_I ⊗ ∇N_Ip, the 2×2 block of the 3×3 gradient.
  pure subroutine velocity_gradient_2d(mx, p0, p1, nn, node, dN, v, L)
    integer, intent(in) :: mx                !! basis capacity
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: dN(2, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: v(2, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (2×2 block written)
    real(wp) :: gx(2), gy(2)
    integer :: p, k, I
    do p = p0, p1
      gx = 0.0_wp; gy = 0.0_wp
      do k = 1, nn(p)
        I = node(k, p)
        gx = gx + v(:, I) * dN(1, k, p)
        gy = gy + v(:, I) * dN(2, k, p)
      end do
      L(1:2, 1, p) = gx; L(1:2, 2, p) = gy
    end do
  end subroutine velocity_gradient_2d

  !> u_p = Σ N_Ip q_I, or with `add` u_p += c Σ N_Ip q_I.
  pure subroutine g2p_2d(mx, p0, p1, nn, node, N, q, add, c, u)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: q(2, *)          !! nodal vectors
    logical, intent(in) :: add               !! accumulate c Σ N q instead of overwriting
    real(wp), intent(in) :: c                !! scale (with `add`)
    real(wp), intent(inout) :: u(2, *)       !! particle vectors
    real(wp) :: s(2)
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
  end subroutine g2p_2d

  !> The two of [[velocity_gradient_2d]] and [[g2p_2d]] (with `add`) on the same nodal field in
  !> one pass, for particles p0..p1: L_p = Σ v_I ⊗ ∇N_Ip into L(:, :, 1..p1−p0+1) and
  !> u_p += c Σ N_Ip v_I, each sum in its own kernel's order (the same bits); the node indices
  !> and velocities are read once.
  pure subroutine gradient_g2p_2d(mx, p0, p1, nn, node, N, dN, v, L, c, u)
    integer, intent(in) :: mx                !! basis capacity (nodes per particle)
    integer, intent(in) :: p0                !! first particle
    integer, intent(in) :: p1                !! last particle
    integer, intent(in) :: nn(*)             !! nodes per particle
    integer, intent(in) :: node(mx, *)       !! node indices
    real(wp), intent(in) :: N(mx, *)         !! shape-function values
    real(wp), intent(in) :: dN(2, mx, *)     !! shape-function gradients
    real(wp), intent(in) :: v(2, *)          !! nodal velocities
    real(wp), intent(inout) :: L(3, 3, *)    !! velocity gradients (2×2 block written)
    real(wp), intent(in) :: c                !! scale of the interpolated velocity
    real(wp), intent(inout) :: u(2, *)       !! particle vectors (accumulated)
    real(wp) :: gx(2), gy(2), s(2)
    integer :: p, k, I
    do p = p0, p1
      gx = 0.0_wp; gy = 0.0_wp; s = 0.0_wp
      do k = 1, nn(p)
        I = node(k, p)
        gx = gx + v(:, I) * dN(1, k, p)
        gy = gy + v(:, I) * dN(2, k, p)
        s = s + N(k, p) * v(:, I)
      end do
      L(1:2, 1, p - p0 + 1) = gx; L(1:2, 2, p - p0 + 1) = gy
      u(:, p) = u(:, p) + c * s
    end do
  end subroutine gradient_g2p_2d

end module empm_transfer_2d
