!> Benchmarks of the verification suite: the exact or manufactured solution behind each
!> benchmark id, the initial state and body force it needs, the metrics computed from a run
!> against it, and the exact fields stored beside the run for the report's plots.
!> Definitions: docs/benchmarks.md; metrics: docs/verification.md.
module empm_verify_bench
  use hdf5, only: h5open_f, h5fopen_f, h5fclose_f, H5F_ACC_RDWR_F
  use empm_kinds, only: wp, pi
  use empm_strings, only: str
  use empm_case, only: empm_case_t
  use empm_history, only: empm_history_t
  use empm_h5, only: hid_t, h5_group, h5_close_group, h5_write, h5_attr
  use empm_tensor, only: det3, adjugate3, mat_to_voigt, identity3
  use empm_verify_metrics, only: rms_error, weighted_l2, history_l2, noise_share
  use empm_exact_bar, only: empm_vibrating_bar_t
  use empm_exact_characteristics, only: empm_char_bar_t, empm_dyka_bar
  use empm_exact_column, only: empm_column_t, empm_andersen_column
  use empm_mms, only: empm_mms_t
  use empm_mms_linear, only: empm_mms_linear_1d_t, empm_mms_linear_2d_t
  use empm_mms_neohookean, only: empm_mms_neohookean_1d_t, empm_mms_axis_aligned_2d_t, &
    empm_mms_axis_aligned_3d_t
  use empm_exact_homogeneous, only: empm_homogeneous_t, HOM_JAUMANN, HOM_SMALL_STRAIN, &
    HOM_NEOHOOKEAN
  use empm_material_linear_elastic, only: empm_linear_elastic_t
  use empm_material_mohr_coulomb, only: empm_mohr_coulomb_t
  use empm_material_drucker_prager, only: empm_drucker_prager_t
  use empm_material_camclay, only: empm_camclay_t
  use empm_material_neohookean, only: empm_neohookean_t
  implicit none
  private
  public :: empm_bench_t, bench_known

  character(len=*), parameter :: KNOWN = 'dyka vibrating_bar andersen mms_linear_1d '// &
    'mms_linear_2d mms_neohookean_1d mms_axis_aligned_2d mms_axis_aligned_3d homogeneous '// &
    'colliding_disks footing column_collapse'

  ! Prandtl strip footing (docs/benchmarks.md): undrained cohesion, footing half-width of the
  ! half model, and the material's P-wave speed (E = 5 MPa, nu = 0.3, rho = 2000 kg/m3).
  real(wp), parameter :: FOOT_C = 1.0e4_wp, FOOT_HALF = 0.5_wp
  real(wp), parameter :: FOOT_CP = 58.011935111532_wp

  !> A benchmark: its exact solution and the scales that make errors relative.
  type :: empm_bench_t
    character(len=32) :: id = ''                !! benchmark id
    real(wp) :: vscale = 1.0_wp                 !! velocity scale [m/s]
    real(wp) :: uscale = 1.0_wp                 !! displacement scale [m]
    real(wp) :: sscale = 1.0_wp                 !! stress scale [Pa]
    real(wp) :: fcut = 0.0_wp                   !! noise cutoff frequency [Hz] (dyka)
    type(empm_char_bar_t) :: dyka               !! Dyka bar by characteristics
    type(empm_vibrating_bar_t) :: bar           !! vibrating bar
    type(empm_column_t) :: column               !! self-weight column (Andersen block)
    real(wp) :: box(2, 2) = 0.0_wp              !! column_collapse: the initial column
                                                !! [x_lo, y_lo; x_hi, y_hi] [m]
    real(wp) :: bin = 0.0_wp                    !! column_collapse: profile bin width [m]
    class(empm_mms_t), allocatable :: mms       !! manufactured solution (mms_* benchmarks)
  contains
    procedure :: prepare => bench_prepare
    procedure :: metric => bench_metric
    procedure :: exact => bench_exact
    procedure :: has_exact => bench_has_exact
    procedure :: write_exact => bench_write_exact
  end type empm_bench_t

contains

  !> True when `benchmark` is implemented.
  pure logical function bench_known(benchmark)
    character(len=*), intent(in) :: benchmark !! benchmark id
    bench_known = index(' '//KNOWN//' ', ' '//trim(benchmark)//' ') > 0
  end function bench_known

  !> True when the benchmark has a pointwise exact solution.
  elemental logical function bench_has_exact(self)
    class(empm_bench_t), intent(in) :: self !! benchmark
    bench_has_exact = self%id /= 'colliding_disks' .and. self%id /= 'footing' .and. &
                      self%id /= 'column_collapse'
  end function bench_has_exact

  !> Exact displacement, velocity and Cauchy stress (Voigt) at reference position `X`, time `t`.
  subroutine bench_exact(self, X, t, u, v, s)
    class(empm_bench_t), intent(in) :: self  !! benchmark
    real(wp), intent(in) :: X(:)             !! reference position (ndim)
    real(wp), intent(in) :: t                !! time [s]
    real(wp), intent(out) :: u(size(X))      !! displacement [m]
    real(wp), intent(out) :: v(size(X))      !! velocity [m/s]
    real(wp), intent(out) :: s(6)            !! stress [Pa]
    real(wp) :: F(3,3), b(size(X))
    u = 0.0_wp; v = 0.0_wp; s = 0.0_wp
    select case (trim(self%id))
    case ('dyka')
      ! Small-strain theory: the displacement is not tracked by characteristics.
      v(1) = self%dyka%velocity(X(1), t); s(1) = self%dyka%stress(X(1), t)
    case ('vibrating_bar')
      u(1) = self%bar%displacement(X(1), t); v(1) = self%bar%velocity(X(1), t)
      s(1) = self%bar%stress(X(1), t)
    case ('andersen')
      ! 1D uniaxial-strain column along y (plane strain, rollers, nu = 0).
      u(2) = self%column%displacement(X(2), t); v(2) = self%column%velocity(X(2), t)
      s(2) = self%column%stress(X(2), t)
    case ('mms_linear_1d', 'mms_linear_2d', 'mms_neohookean_1d', 'mms_axis_aligned_2d', &
          'mms_axis_aligned_3d', 'homogeneous')
      call self%mms%fields(X, t, u, v, F, s, b)
    end select
  end subroutine bench_exact

  !> Set the benchmark up for `cs`: check the case against the exact solution's data, and
  !> impose what the benchmark needs beyond the case file (initial fields, body forces).
  subroutine bench_prepare(self, id, cs, emsg)
    class(empm_bench_t), intent(inout) :: self         !! benchmark
    character(len=*), intent(in) :: id                 !! benchmark id
    type(empm_case_t), intent(inout) :: cs             !! case read from its file
    character(len=:), allocatable, intent(out) :: emsg !! '' or the problem
    real(wp) :: c_case
    integer :: p, np
    emsg = ''
    self%id = id
    np = cs%model%pts%np
    c_case = cs%model%mats(1)%model%wave_speed(cs%model%mats(1)%model%rho0)
    select case (trim(id))
    case ('dyka')
      self%dyka = empm_dyka_bar()
      call expect_speed(self%dyka%wave_speed())
      self%vscale = 5.0_wp; self%sscale = self%dyka%impedance() * 5.0_wp
      ! Wavelengths shorter than 8h travel more than 2.5 % slow on the grid (lumped linear
      ! elements: sin(kh/2)/(kh/2) at kh = pi/4): content above c/(8h) is numerical noise.
      self%fcut = self%dyka%wave_speed() / (8.0_wp * cs%model%grid%hmin())
    case ('vibrating_bar')
      ! Amplitude from the initial velocities (least squares on sin(beta X)).
      self%bar%v0 = sum(cs%model%pts%v(1, 1:np) * sin(self%bar%beta() * cs%model%pts%x0(1, 1:np))) &
                    / sum(sin(self%bar%beta() * cs%model%pts%x0(1, 1:np))**2)
      call expect_speed(sqrt(self%bar%E / self%bar%rho))
      do p = 1, np
        if (abs(cs%model%pts%v(1, p) - self%bar%velocity(cs%model%pts%x0(1, p), 0.0_wp)) > &
            1.0e-12_wp * abs(self%bar%v0)) emsg = cs%file// &
          ': the initial velocity is not the first mode of the vibrating bar (L = 25, E = 100)'
      end do
      self%vscale = abs(self%bar%v0)
      self%uscale = abs(self%bar%v0) / self%bar%omega()
      self%sscale = self%bar%E * self%bar%beta() * self%uscale
    case ('andersen')
      self%column = empm_andersen_column()
      call expect_speed(self%column%wave_speed())
      self%sscale = self%column%rho * self%column%g * self%column%H
      self%uscale = self%column%settlement()
      self%vscale = self%uscale * 2.0_wp * pi / self%column%period()
    case ('mms_linear_1d')
      block
        type(empm_mms_linear_1d_t) :: m
        call expect_speed(sqrt(m%modulus() / m%rho))
        self%uscale = m%A; self%vscale = m%A * 2.0_wp * pi / m%period
        self%sscale = m%E * m%A * 2.0_wp * pi / m%L
        allocate(self%mms, source=m)
      end block
    case ('mms_linear_2d')
      block
        type(empm_mms_linear_2d_t) :: m
        self%uscale = m%A; self%vscale = m%A * 2.0_wp * pi / m%period
        self%sscale = m%E * m%A * pi / m%L
        allocate(self%mms, source=m)
      end block
    case ('mms_neohookean_1d')
      block
        type(empm_mms_neohookean_1d_t) :: m
        self%uscale = m%A; self%vscale = m%A * pi * sqrt(m%E / m%rho0) / m%L
        self%sscale = m%E * m%A * 2.0_wp * pi / m%L
        allocate(self%mms, source=m)
      end block
    case ('mms_axis_aligned_2d')
      block
        type(empm_mms_axis_aligned_2d_t) :: m
        self%uscale = m%A; self%vscale = m%A * pi * sqrt(m%E / m%rho0) / m%L
        self%sscale = m%E * m%A * 2.0_wp * pi / m%L
        allocate(self%mms, source=m)
      end block
    case ('mms_axis_aligned_3d')
      block
        type(empm_mms_axis_aligned_3d_t) :: m
        if (cs%model%grid%ndim /= 3) then
          emsg = cs%file//': mms_axis_aligned_3d is a 3D benchmark'; return
        end if
        self%uscale = m%A; self%vscale = m%A * pi * sqrt(m%E / m%rho0) / m%L
        self%sscale = m%E * m%A * 2.0_wp * pi / m%L
        allocate(self%mms, source=m)
      end block
    case ('homogeneous')
      call homogeneous()
    case ('colliding_disks')
    case ('footing')
      ! Prandtl: q = (2 + pi) c for a rigid rough strip on weightless Tresca soil.
      call expect_speed(FOOT_CP)
      self%sscale = (2.0_wp + pi) * FOOT_C; self%uscale = 2.0_wp * FOOT_HALF
    case ('column_collapse')
      call column_box()
    case default
      emsg = 'unknown benchmark '''//trim(id)//'''; known: '//KNOWN
    end select
    if (allocated(self%mms) .and. len(emsg) == 0) then
      call set_initial_state(cs)
      allocate(cs%model%loads%body_force, source=self%mms)
    end if

  contains

    ! Homogeneous motion (docs/benchmarks.md): G by least squares from the nodes' prescribed
    ! velocities (every dof of every node prescribed, v = G x to 1e-12), the start stress from
    ! the particles (uniform), the stress law from the one material.
    subroutine homogeneous()
      type(empm_homogeneous_t) :: m
      real(wp) :: A(3,3), B(3,3), x(3), v(3), s0(6), vmax, res, Dm(3,3), u(3), vv(3), F(3,3), &
        se(6), bb(3)
      integer :: nd, node, k, q
      nd = cs%model%grid%ndim
      if (size(cs%model%mats) /= 1) then
        emsg = cs%file//': homogeneous needs one material'; return
      end if
      A = 0.0_wp; B = 0.0_wp; vmax = 0.0_wp
      do node = 1, cs%model%grid%nnode
        x = 0.0_wp; v = 0.0_wp
        x = cs%model%grid%node_coord(node)
        do k = 1, nd
          if (.not. cs%model%nodes%is_fixed(k, node)) then
            emsg = cs%file//': homogeneous needs every node driven (&boundary fix = .true. '// &
              'on every component with velocity_gradient); node '//str(node)//' is free'; return
          end if
          v(k) = cs%model%nodes%fixed_velocity(k, node)
        end do
        A = A + spread(v, 2, 3) * spread(x, 1, 3)
        B = B + spread(x, 2, 3) * spread(x, 1, 3)
        vmax = max(vmax, maxval(abs(v)))
      end do
      do k = nd + 1, 3
        B(k, k) = 1.0_wp
      end do
      m%G = matmul(A, adjugate3(B)) / det3(B)
      res = 0.0_wp
      do node = 1, cs%model%grid%nnode
        x = cs%model%grid%node_coord(node)
        v = matmul(m%G, x)
        do k = 1, nd
          res = max(res, abs(v(k) - cs%model%nodes%fixed_velocity(k, node)))
        end do
      end do
      if (.not. (vmax > 0.0_wp .and. res <= 1.0e-12_wp * vmax)) then
        emsg = cs%file//': homogeneous needs nodal velocities v = G x (velocity = 0 with '// &
          'velocity_gradient = G on every node)'; return
      end if
      s0 = cs%model%pts%stress(:, 1)
      do q = 1, np
        if (any(abs(cs%model%pts%stress(:, q) - s0) > 1.0e-12_wp * maxval(abs(s0)))) then
          emsg = cs%file//': homogeneous needs a uniform start stress (&particles stress)'; return
        end if
      end do
      m%s0 = s0
      Dm = 0.5_wp * (m%G + transpose(m%G))
      select type (mat => cs%model%mats(1)%model)
      type is (empm_linear_elastic_t)
        m%lambda = mat%lambda; m%mu = mat%mu
        m%kind = merge(HOM_JAUMANN, HOM_SMALL_STRAIN, mat%jaumann)
      type is (empm_mohr_coulomb_t)
        ! Elastic while the strength is out of reach (the case's cohesion); the metrics show
        ! a yield as an error that does not converge.
        m%lambda = mat%K - 2.0_wp * mat%G / 3.0_wp; m%mu = mat%G
      type is (empm_drucker_prager_t)
        m%lambda = mat%lambda; m%mu = mat%G
      type is (empm_camclay_t)
        ! Isochoric motion (tr G = 0) from inside the yield surface: p' and v stay constant
        ! (tr S = 0 and the rotation keeps the trace), so K and G do: the Jaumann solution
        ! with G(p', v) holds while the path stays elastic (the case keeps q below the
        ! surface; a yield shows as an error that does not converge). The specific volume is
        ! 1 + e0 (the case gives e0). Under volume change the stiffness varies: no closed form.
        if (abs(Dm(1,1) + Dm(2,2) + Dm(3,3)) > 1.0e-12_wp * maxval(abs(m%G))) then
          emsg = cs%file//': homogeneous with camclay: isochoric motion only (tr G = 0)'
          return
        end if
        if (maxval(abs(Dm)) > 1.0e-12_wp * maxval(abs(m%G))) then
          if (.not. mat%e0 >= 0.0_wp) then
            emsg = cs%file//': homogeneous with camclay under strain: give e0'; return
          end if
          ! From the model's parameters, not its code: G = 3K(1 − 2ν)/(2(1 + ν)),
          ! K = v p'/κ (or the constant G given).
          if (mat%G > 0.0_wp) then
            m%mu = mat%G
          else
            m%mu = 1.5_wp * (1.0_wp - 2.0_wp * mat%nu) / (1.0_wp + mat%nu) * (1.0_wp + mat%e0) &
                   * (-(s0(1) + s0(2) + s0(3)) / 3.0_wp) / mat%kap
          end if
        end if
      type is (empm_neohookean_t)
        m%lambda = mat%lambda; m%mu = mat%mu; m%kind = HOM_NEOHOOKEAN
        if (any(s0 /= 0.0_wp)) then
          emsg = cs%file//': homogeneous with neohookean: the reference is stress-free'; return
        end if
      class default
        emsg = cs%file//': homogeneous: no exact stress for material model '''// &
          trim(cs%model%mats(1)%model%name())//''' (linear_elastic, mohr_coulomb, '// &
          'drucker_prager, neohookean; camclay in isochoric motion)'; return
      end select
      ! Scales: the largest exact displacement, velocity and stress component at the end.
      self%uscale = 0.0_wp; self%vscale = 0.0_wp
      do q = 1, np
        call m%fields(cs%model%pts%x0(:, q), cs%run%t_end, u(1:nd), vv(1:nd), F, se, bb(1:nd))
        self%uscale = max(self%uscale, maxval(abs(u(1:nd))))
        self%vscale = max(self%vscale, maxval(abs(vv(1:nd))))
      end do
      self%sscale = max(maxval(abs(s0)), maxval(abs(m%stress(cs%run%t_end))))
      if (.not. (self%uscale > 0.0_wp .and. self%sscale > 0.0_wp)) then
        emsg = cs%file//': homogeneous: no motion or no stress to measure'; return
      end if
      allocate(self%mms, source=m)
    end subroutine homogeneous

    ! Granular column collapse (docs/benchmarks.md): a 2D column of whole cells under gravity
    ! along -y; its box from the particles' reference positions, checked by its volume.
    subroutine column_box()
      real(wp) :: h(2), g(3)
      if (cs%model%grid%ndim /= 2) then
        emsg = cs%file//': column_collapse is a 2D (plane-strain) benchmark'; return
      end if
      g = cs%model%loads%gravity_at(huge(1.0_wp))
      if (.not. (g(2) < 0.0_wp .and. g(1) == 0.0_wp)) then
        emsg = cs%file//': column_collapse needs gravity along -y'; return
      end if
      h = cs%model%grid%h(1:2)
      self%box(:, 1) = h * floor(minval(cs%model%pts%x0(:, 1:np), dim=2) / h + 1.0e-9_wp)
      self%box(:, 2) = h * ceiling(maxval(cs%model%pts%x0(:, 1:np), dim=2) / h - 1.0e-9_wp)
      if (abs(sum(cs%model%pts%vol0(1:np)) - product(self%box(:, 2) - self%box(:, 1))) > &
          1.0e-9_wp * product(self%box(:, 2) - self%box(:, 1))) then
        emsg = cs%file//': column_collapse needs one rectangular column of whole cells'; return
      end if
      self%bin = 0.5_wp * h(1)
      self%uscale = self%box(1, 2) - self%box(1, 1)
    end subroutine column_box

    subroutine expect_speed(c)
      real(wp), intent(in) :: c
      if (abs(c_case - c) > 1.0e-10_wp * c) emsg = cs%file//': the material of the case '// &
        '(wave speed '//str(c_case)//' m/s) differs from the '//trim(id)//' benchmark''s ('// &
        str(c)//' m/s)'
    end subroutine expect_speed

    ! Particles start on the manufactured solution: x = X + u(X,0), v, F, stress, density.
    subroutine set_initial_state(cs)
      type(empm_case_t), intent(inout) :: cs
      real(wp) :: u(3), v(3), s(6), F(3, 3), J, b(3)
      integer :: q, d
      d = cs%model%grid%ndim
      do q = 1, cs%model%pts%np
        call self%mms%fields(cs%model%pts%x0(:, q), 0.0_wp, u(1:d), v(1:d), F, s, b(1:d))
        J = det3(F)
        cs%model%pts%x(:, q) = cs%model%pts%x0(:, q) + u(1:d)
        cs%model%pts%v(:, q) = v(1:d)
        cs%model%pts%F(:, :, q) = F
        cs%model%pts%strain(:, q) = mat_to_voigt(F - identity3())
        cs%model%pts%stress(:, q) = s
        cs%model%pts%rho(q) = cs%model%pts%rho(q) / J
        cs%model%pts%vol(q) = cs%model%pts%vol0(q) * J
      end do
    end subroutine set_initial_state
  end subroutine bench_prepare

  !> Compute metric `name` of a finished run. `emsg` is '' on success.
  subroutine bench_metric(self, name, cs, hist, value, emsg)
    class(empm_bench_t), intent(in) :: self            !! benchmark
    character(len=*), intent(in) :: name               !! metric name
    type(empm_case_t), intent(in) :: cs                !! the run (final state)
    type(empm_history_t), intent(in) :: hist           !! its histories
    real(wp), intent(out) :: value                     !! metric value
    character(len=:), allocatable, intent(out) :: emsg !! '' or the problem
    real(wp), allocatable :: ue(:,:), ve(:,:), se(:,:), pv(:), ps(:)
    real(wp) :: g
    integer :: np, d, p, k, info, i0
    emsg = ''; value = huge(1.0_wp)
    np = cs%model%pts%np; d = cs%model%grid%ndim
    allocate(ue(d, np), ve(d, np), se(6, np))
    if (self%has_exact()) then
      do p = 1, np
        call self%exact(cs%model%pts%x0(:, p), cs%model%t, ue(:, p), ve(:, p), se(:, p))
      end do
    end if
    associate (pts => cs%model%pts)
      select case (trim(name))
      case ('rms_velocity')
        ! Paper eq. (45), axial component, at the final time [m/s].
        value = rms_error(pts%v(1, 1:np), ve(1, :))
      case ('velocity_l2')
        value = weighted_l2(pts%vol0(1:np), pts%v(:, 1:np), ve) / self%vscale
      case ('displacement_l2')
        value = weighted_l2(pts%vol0(1:np), pts%x(:, 1:np) - pts%x0(:, 1:np), ue) / self%uscale
      case ('stress_l2')
        value = weighted_l2(pts%vol0(1:np), pts%stress(:, 1:np), se) / self%sscale
      case ('density_l2')
        ! Against ρ₀/det F of a manufactured solution, relative to the mean start density.
        if (.not. allocated(self%mms)) then
          emsg = 'density_l2 is defined for the manufactured and homogeneous benchmarks only'
          return
        end if
        block
          real(wp) :: re(1, np), F(3,3), uu(d), vv(d), sv(6), bb(d)
          do p = 1, np
            call self%mms%fields(pts%x0(:, p), cs%model%t, uu, vv, F, sv, bb)
            re(1, p) = pts%m(p) / pts%vol0(p) / det3(F)
          end do
          value = weighted_l2(pts%vol0(1:np), reshape(pts%rho(1:np), [1, np]), re) / &
                  (sum(pts%m(1:np)) / sum(pts%vol0(1:np)))
        end block
      case ('history_l2_velocity', 'noise_share', 'history_l2_stress', 'overshoot')
        k = merge(2, 1, trim(name) == 'history_l2_stress')
        if (hist%nprobe < k) then
          emsg = trim(name)//' needs probe '//str(k)//' in the case file'; return
        end if
        call probe_exact(k, pv, ps)
        if (trim(name) == 'history_l2_velocity') then
          value = history_l2(hist%t(1:hist%nt), hist%pv(1, k, 1:hist%nt), pv) / self%vscale
        else if (trim(name) == 'overshoot') then
          ! Peak velocity beyond the exact peak at the probe, relative to the velocity scale.
          value = (maxval(abs(hist%pv(1, k, 1:hist%nt))) - maxval(abs(pv))) / self%vscale
        else if (trim(name) == 'history_l2_stress') then
          value = history_l2(hist%t(1:hist%nt), hist%ps(1, k, 1:hist%nt), ps) / self%sscale
        else
          call noise_share(hist%t(1:hist%nt), hist%pv(1, k, 1:hist%nt), pv, self%fcut, value, info)
          if (info /= 0) emsg = 'noise_share: spectrum failed (status '//str(info)//')'
        end if
      case ('history_rms_velocity', 'history_rms_velocity_current', 'history_rms_velocity_end')
        ! RMS over time of the free-end probe's velocity error [m/s], the exact solution taken
        ! at the probe particle's reference position (small-strain, Lagrangian), at its current
        ! position x(t), or at the bar's end X = L (a fixed point in space).
        if (hist%nprobe < 1) then
          emsg = trim(name)//' needs a probe in the case file'; return
        end if
        if (trim(self%id) /= 'dyka') then
          emsg = trim(name)//' is defined for the dyka benchmark only'; return
        end if
        call probe_exact(1, pv, ps)
        if (trim(name) == 'history_rms_velocity_current') then
          do k = 1, hist%nt
            pv(k) = self%dyka%velocity(min(hist%px(1, 1, k), self%dyka%L), hist%t(k))
          end do
        else if (trim(name) == 'history_rms_velocity_end') then
          do k = 1, hist%nt
            pv(k) = self%dyka%velocity(self%dyka%L, hist%t(k))
          end do
        end if
        value = history_l2(hist%t(1:hist%nt), hist%pv(1, 1, 1:hist%nt), pv)
      case ('base_stress_error')
        ! Bottom row of particles: sigma_yy against the exact column at their reference height.
        g = minval(pts%x0(2, 1:np))
        value = maxval(abs(pts%stress(2, 1:np) - se(2, :)), mask=pts%x0(2, 1:np) <= g + 1.0e-9_wp) &
                / self%sscale
      case ('profile_error')
        value = rms_error(pts%stress(2, 1:np), se(2, :)) / self%sscale
      case ('settlement_error')
        ! Top particle against the small-strain static displacement at its height.
        i0 = maxloc(pts%x0(2, 1:np), dim=1)
        value = abs((pts%x(2, i0) - pts%x0(2, i0)) - &
                    self%column%static_displacement(pts%x0(2, i0))) / self%uscale
      case ('max_speed')
        value = sqrt(maxval(sum(pts%v(:, 1:np)**2, dim=1))) / self%vscale
      case ('energy_growth')
        ! max_t E(t)/E(0) - 1: an explicit scheme that is stable and dissipative never gains.
        value = maxval(hist%kinetic(1:hist%nt) + hist%strain(1:hist%nt)) / &
                (hist%kinetic(1) + hist%strain(1)) - 1.0_wp
      case ('energy_loss')
        value = 1.0_wp - (hist%kinetic(hist%nt) + hist%strain(hist%nt)) / &
                (hist%kinetic(1) + hist%strain(1))
      case ('limit_pressure_error', 'limit_pressure_ratio')
        call limit_pressure(value)
        if (len(emsg) == 0) then
          value = value / self%sscale
          if (trim(name) == 'limit_pressure_error') value = abs(value - 1.0_wp)
        end if
      case ('runout', 'runout_error_linear', 'runout_error_power', 'final_height', &
            'kinetic_end')
        if (trim(self%id) /= 'column_collapse') then
          emsg = trim(name)//' is defined for the column_collapse benchmark only'; return
        end if
        call collapse(trim(name), value)
      case default
        emsg = 'unknown metric '''//trim(name)//''''
      end select
    end associate

  contains

    ! Column collapse (docs/benchmarks.md). The deposit's profile: the particles' reference
    ! volumes (mass over initial density, so that a loose front does not count as height)
    ! per bin of half a cell from the back wall, over the bin width. The deposit ends at the
    ! first bin from the wall thinner than 1 % of H0, a gap (one particle alone gives 2.5 % of
    ! H0 at 2 x 2 particles per cell and H0 = 20 cells): stray particles beyond it are not the
    ! deposit. runout = (L_f - L0)/L0; the errors are against Lube et al.'s (2005) fits 1.2 a
    ! and 1.9 a^(2/3); final_height = the profile's highest bin / H0; kinetic_end = the last
    ! kinetic energy over the largest (at rest: the elastic ringing only).
    subroutine collapse(metric, v)
      character(len=*), intent(in) :: metric
      real(wp), intent(out) :: v
      real(wp), allocatable :: hgt(:)
      real(wp) :: l0, h0, a
      integer :: nb, p, i
      l0 = self%box(1, 2) - self%box(1, 1); h0 = self%box(2, 2) - self%box(2, 1)
      a = h0 / l0
      if (metric == 'kinetic_end') then
        v = hist%kinetic(hist%nt) / maxval(hist%kinetic(1:hist%nt)); return
      end if
      nb = int((maxval(cs%model%pts%x(1, 1:np)) - self%box(1, 1)) / self%bin) + 2
      allocate(hgt(nb)); hgt = 0.0_wp
      do p = 1, np
        i = max(1, int((cs%model%pts%x(1, p) - self%box(1, 1)) / self%bin) + 1)
        hgt(i) = hgt(i) + cs%model%pts%vol0(p) / self%bin
      end do
      if (metric == 'final_height') then
        v = maxval(hgt) / h0; return
      end if
      i = 1
      do while (i < nb .and. hgt(i) >= 0.01_wp * h0)
        i = i + 1
      end do
      v = ((i - 1) * self%bin - l0) / l0
      select case (metric)
      case ('runout_error_linear'); v = abs(v / (1.2_wp * a) - 1.0_wp)
      case ('runout_error_power'); v = abs(v / (1.9_wp * a**(2.0_wp / 3.0_wp)) - 1.0_wp)
      end select
    end subroutine collapse

    ! Footing: the limit pressure is the mean of p = -R_y/b over the samples of the last
    ! quarter of the penetration (delta >= 3/4 of the final one), where the curve has
    ! plateaued; averaging smooths the oscillation of the reaction as particles cross cells.
    subroutine limit_pressure(pl)
      real(wp), intent(out) :: pl
      real(wp) :: dend
      integer :: s, i, n
      pl = huge(1.0_wp)
      s = 0
      do i = 1, hist%nset
        if (trim(hist%set_name(i)) == 'footing') s = i
      end do
      if (s == 0 .or. hist%nt < 2 .or. d < 2) then
        emsg = trim(name)//' needs a 2D &boundary named ''footing'''; return
      end if
      dend = -hist%set_disp(2, s, hist%nt)
      if (.not. dend > 0.0_wp) then
        emsg = trim(name)//': the footing was not pushed down (velocity(2) < 0)'; return
      end if
      pl = 0.0_wp; n = 0
      do i = 1, hist%nt
        if (-hist%set_disp(2, s, i) >= 0.75_wp * dend) then
          pl = pl - hist%reaction(2, s, i) / FOOT_HALF; n = n + 1
        end if
      end do
      pl = pl / n
    end subroutine limit_pressure

    subroutine probe_exact(k, pv, ps)
      integer, intent(in) :: k
      real(wp), allocatable, intent(out) :: pv(:), ps(:)
      real(wp) :: u(d), v(d), s(6)
      integer :: i
      allocate(pv(hist%nt), ps(hist%nt))
      do i = 1, hist%nt
        call self%exact(cs%model%pts%x0(:, hist%probe_particle(k)), hist%t(i), u, v, s)
        pv(i) = v(1); ps(i) = s(1)
      end do
    end subroutine probe_exact
  end subroutine bench_metric

  !> Store the exact fields beside a run in its HDF5 file, group /verification: exact
  !> velocity and stress histories at every probe, exact final displacement, velocity and
  !> stress at the particles, and the benchmark's scales.
  subroutine bench_write_exact(self, path, cs, hist, ierr)
    class(empm_bench_t), intent(in) :: self      !! benchmark
    character(len=*), intent(in) :: path         !! the run's HDF5 file (complete)
    type(empm_case_t), intent(in) :: cs          !! the run
    type(empm_history_t), intent(in) :: hist     !! its histories
    integer, intent(out) :: ierr                 !! 0 ok
    integer(hid_t) :: fid, g, gp
    real(wp), allocatable :: ue(:,:), ve(:,:), se(:,:), hv(:,:), hs(:,:)
    integer :: e, p, k, i, d, np
    ierr = 0
    d = cs%model%grid%ndim; np = cs%model%pts%np
    call h5open_f(e)
    call h5fopen_f(path, H5F_ACC_RDWR_F, fid, e)
    if (e /= 0) then
      ierr = 1; return
    end if
    call h5_group(fid, 'verification', g, ierr)
    call h5_attr(g, 'benchmark', trim(self%id), ierr)
    call h5_attr(g, 'velocity_scale', self%vscale, ierr)
    call h5_attr(g, 'displacement_scale', self%uscale, ierr)
    call h5_attr(g, 'stress_scale', self%sscale, ierr)
    if (self%has_exact()) then
      allocate(ue(d, np), ve(d, np), se(6, np), hv(d, hist%nt), hs(6, hist%nt))
      do p = 1, np
        call self%exact(cs%model%pts%x0(:, p), cs%model%t, ue(:, p), ve(:, p), se(:, p))
      end do
      call h5_write(g, 'final_displacement', ue, ierr)
      call h5_write(g, 'final_velocity', ve, ierr)
      call h5_write(g, 'final_stress', se, ierr)
      do k = 1, hist%nprobe
        do i = 1, hist%nt
          call self%exact(cs%model%pts%x0(:, hist%probe_particle(k)), hist%t(i), ue(:, 1), &
                          hv(:, i), hs(:, i))
        end do
        call h5_group(g, 'probe_'//trim(hist%probe_name(k)), gp, ierr)
        call h5_write(gp, 'v', hv, ierr)
        call h5_write(gp, 'stress', hs, ierr)
        call h5_close_group(gp, ierr)
      end do
    end if
    call h5_close_group(g, ierr)
    call h5fclose_f(fid, e)
    if (e /= 0) ierr = e
  end subroutine bench_write_exact
end module empm_verify_bench
