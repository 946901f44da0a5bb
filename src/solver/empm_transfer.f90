!> Particle-grid transfer kernels shared by every integrator: P2G of mass, momentum-like
!> quantities and forces; G2P interpolation of values and gradients; nodal constraints.
!>
!> All kernels are pure loops over contiguous per-particle basis blocks; none allocates.
module empm_transfer
  use empm_kinds, only: wp
  use empm_shape, only: empm_basis_t
  use empm_nodes, only: empm_nodes_t
  implicit none
  private
  public :: p2g_mass, p2g_weighted, p2g_internal_force, p2g_body_force
  public :: g2p_value, g2p_add_scaled, velocity_gradient
  public :: nodal_divide_by_mass, constrain_velocity, constrain_force

contains

  !> Lumped mass m_I = Σ_p N_Ip m_p (accumulated into `mass`).
  pure subroutine p2g_mass(basis, m, mass)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: m(:)            !! particle masses
    real(wp), intent(inout) :: mass(:)      !! nodal masses (accumulated)
    integer :: p, k
    do p = 1, basis%np
      do k = 1, basis%nn(p)
        mass(basis%node(k, p)) = mass(basis%node(k, p)) + basis%N(k, p) * m(p)
      end do
    end do
  end subroutine p2g_mass

  !> Mass-weighted transfer q_I += Σ_p N_Ip m_p (u_p + c·w_p), e.g. momentum (c = 0) or the
  !> predictor's v_p + (1−γ)Δt a_p.
  pure subroutine p2g_weighted(basis, m, u, c, w, q)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: m(:)            !! particle masses
    real(wp), intent(in) :: u(:,:)          !! particle vectors (ndim, np)
    real(wp), intent(in) :: c               !! scale of the second vector (0 to ignore it)
    real(wp), intent(in) :: w(:,:)          !! second particle vectors (ndim, np)
    real(wp), intent(inout) :: q(:,:)       !! nodal vectors (ndim, nnode), accumulated
    real(wp) :: mu(size(u, 1))
    integer :: p, k, I
    do p = 1, basis%np
      if (c == 0.0_wp) then
        mu = m(p) * u(:, p)
      else
        mu = m(p) * (u(:, p) + c * w(:, p))
      end if
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        q(:, I) = q(:, I) + basis%N(k, p) * mu
      end do
    end do
  end subroutine p2g_weighted

  !> Internal force f_I −= Σ_p V_p σ_p ∇N_Ip (paper eq. 16), σ in Voigt order.
  pure subroutine p2g_internal_force(basis, vol, stress, f)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: vol(:)          !! particle volumes
    real(wp), intent(in) :: stress(:,:)     !! Cauchy stress (6, np)
    real(wp), intent(inout) :: f(:,:)       !! nodal forces (ndim, nnode), accumulated
    real(wp) :: s(3, 3), g(3)
    integer :: p, k, I, d
    d = basis%ndim
    do p = 1, basis%np
      s(1, 1) = stress(1, p); s(2, 2) = stress(2, p); s(3, 3) = stress(3, p)
      s(2, 3) = stress(4, p); s(3, 2) = stress(4, p)
      s(1, 3) = stress(5, p); s(3, 1) = stress(5, p)
      s(1, 2) = stress(6, p); s(2, 1) = stress(6, p)
      s = vol(p) * s
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        g(1:d) = basis%dN(:, k, p)
        f(:, I) = f(:, I) - matmul(s(1:d, 1:d), g(1:d))
      end do
    end do
  end subroutine p2g_internal_force

  !> External body force f_I += Σ_p N_Ip m_p (g + b_p) (paper eq. 17 without tractions).
  pure subroutine p2g_body_force(basis, m, g, b, use_b, f)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: m(:)            !! particle masses
    real(wp), intent(in) :: g(:)            !! uniform acceleration (gravity) (ndim)
    real(wp), intent(in) :: b(:,:)          !! per-particle body force per unit mass (ndim, np)
    logical, intent(in) :: use_b            !! whether `b` holds data
    real(wp), intent(inout) :: f(:,:)       !! nodal forces (ndim, nnode), accumulated
    real(wp) :: fp(size(g))
    integer :: p, k, I
    do p = 1, basis%np
      fp = g
      if (use_b) fp = fp + b(:, p)
      fp = m(p) * fp
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        f(:, I) = f(:, I) + basis%N(k, p) * fp
      end do
    end do
  end subroutine p2g_body_force

  !> Interpolate a nodal vector to the particles: u_p = Σ_I N_Ip q_I.
  pure subroutine g2p_value(basis, q, u)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: q(:,:)          !! nodal vectors (ndim, nnode)
    real(wp), intent(out) :: u(:,:)         !! particle vectors (ndim, np)
    integer :: p, k
    do p = 1, basis%np
      u(:, p) = 0.0_wp
      do k = 1, basis%nn(p)
        u(:, p) = u(:, p) + basis%N(k, p) * q(:, basis%node(k, p))
      end do
    end do
  end subroutine g2p_value

  !> Add a scaled interpolated nodal vector: u_p += c Σ_I N_Ip q_I.
  pure subroutine g2p_add_scaled(basis, c, q, u)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: c               !! scale (e.g. Δt)
    real(wp), intent(in) :: q(:,:)          !! nodal vectors (ndim, nnode)
    real(wp), intent(inout) :: u(:,:)       !! particle vectors (ndim, np)
    real(wp) :: s(size(u, 1))
    integer :: p, k
    do p = 1, basis%np
      s = 0.0_wp
      do k = 1, basis%nn(p)
        s = s + basis%N(k, p) * q(:, basis%node(k, p))
      end do
      u(:, p) = u(:, p) + c * s
    end do
  end subroutine g2p_add_scaled

  !> Velocity gradient L_p = Σ_I v_I ⊗ ∇N_Ip, embedded in 3×3 (zeros in unused directions).
  pure subroutine velocity_gradient(basis, v, L)
    type(empm_basis_t), intent(in) :: basis !! shape functions at the particles
    real(wp), intent(in) :: v(:,:)          !! nodal velocities (ndim, nnode)
    real(wp), intent(out) :: L(:,:,:)       !! velocity gradients (3, 3, np)
    integer :: p, k, I, a, b, d
    d = basis%ndim
    do p = 1, basis%np
      L(:, :, p) = 0.0_wp
      do k = 1, basis%nn(p)
        I = basis%node(k, p)
        do b = 1, d
          do a = 1, d
            L(a, b, p) = L(a, b, p) + v(a, I) * basis%dN(b, k, p)
          end do
        end do
      end do
    end do
  end subroutine velocity_gradient

  !> out_I = q_I / m_I on nodes with mass above the empty-node threshold, 0 elsewhere.
  pure subroutine nodal_divide_by_mass(nodes, q, out)
    type(empm_nodes_t), intent(in) :: nodes !! nodal fields (mass, mass_tol)
    real(wp), intent(in) :: q(:,:)          !! nodal vectors (ndim, nnode)
    real(wp), intent(out) :: out(:,:)       !! q/m (ndim, nnode)
    integer :: I
    do I = 1, nodes%nnode
      if (nodes%mass(I) > nodes%mass_tol) then
        out(:, I) = q(:, I) / nodes%mass(I)
      else
        out(:, I) = 0.0_wp
      end if
    end do
  end subroutine nodal_divide_by_mass

  !> Impose Dirichlet conditions on nodal velocity (and the matching momentum).
  pure subroutine constrain_velocity(nodes, v, mom)
    type(empm_nodes_t), intent(in) :: nodes   !! nodal constraints and masses
    real(wp), intent(inout) :: v(:,:)         !! nodal velocities (ndim, nnode)
    real(wp), intent(inout) :: mom(:,:)       !! nodal momenta (ndim, nnode)
    integer :: I
    do I = 1, nodes%nnode
      where (nodes%fixed(:, I))
        v(:, I) = nodes%vfix(:, I)
        mom(:, I) = nodes%mass(I) * nodes%vfix(:, I)
      end where
    end do
  end subroutine constrain_velocity

  !> Zero nodal forces on fixed dofs (zero acceleration there).
  pure subroutine constrain_force(nodes, f)
    type(empm_nodes_t), intent(in) :: nodes !! nodal constraints
    real(wp), intent(inout) :: f(:,:)       !! nodal forces (ndim, nnode)
    where (nodes%fixed) f = 0.0_wp
  end subroutine constrain_force
end module empm_transfer
