!> Stress-point studies of the verification suite (`study = 'stress_point'`): a material point
!> driven by [[empm_stress_point]] through an element-test path, compared with the closed forms
!> of [[empm_exact_soil]]. The case file holds the model's `&material` group and a
!> `&stress_point` group (keys below); the `&verify` group names the metrics and thresholds.
!>
!> Paths (`path`): `rotation` (rigid rotation by `angle` about z, strain control, from the
!> pre-stress `stress0`); `triaxial_compression` and `triaxial_extension` (axial strain rate
!> along x, the lateral stresses yy and zz held at their initial values); `simple_shear`
!> (plane-strain simple shear ε̇xy with ε̇xx = ε̇zz = 0 and σyy held; the velocity gradient is
!> the symmetric part only, so that the small-strain closed form is not mixed with the
!> rotation of the stress); `mcc_drained` (as triaxial compression); `mcc_undrained`
!> (isochoric triaxial compression, strain control).
!>
!> Metrics: `closed_form_error` (per path, docs/benchmarks.md), `path_error` (drained: the
!> path q = 3(p' − p'0); undrained: p' against the closed-form p'(η) on the yield surface),
!> `yield_violation` (largest relative violation of the yield condition after every update,
!> from a model-independent check), `split_dependence` (largest difference of the stresses at
!> the increment ends between the path and a replay of its increments (the velocity gradients
!> the path applied, unknown rates included) each split into `split` equal sub-increments,
!> relative to the largest stress), `split_dependence_end` (the same at the end of the
!> path only), `control_residual` (largest relative residual of the stress-controlled
!> components).
module empm_verify_stress_point
  use hdf5, only: h5open_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F
  use empm_kinds, only: wp, pi
  use empm_strings, only: str, lower
  use empm_error, only: empm_error_t, EMPM_OK
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_INT, PARAM_STR
  use empm_namelist, only: empm_group_t, empm_parse_namelist
  use empm_files, only: empm_read_text
  use empm_material, only: empm_material_t, STATE_NAME_LEN
  use empm_plasticity, only: principal_decompose
  use empm_registry, only: empm_registry_t, empm_default_registry
  use empm_input, only: empm_input_group_params
  use empm_h5, only: hid_t, h5_write, h5_attr
  use empm_stress_point, only: empm_sp_point_t, empm_sp_history_t, empm_sp_check_t, &
    empm_sp_segment, empm_sp_replay
  use empm_exact_soil, only: empm_mc_triax_compression, empm_mc_triax_extension, empm_dp_match, &
    empm_dp_triax_compression, empm_dp_triax_extension, empm_dp_plane_strain, &
    empm_simple_shear_ratio, empm_mcc_drained_end, empm_mcc_undrained_p, &
    empm_mcc_undrained_end, empm_mc_yield, empm_dp_yield, empm_soil_pq, empm_rotate_z
  implicit none
  private
  public :: empm_sp_study, empm_sp_params

  character(len=*), parameter :: PATHS = 'rotation triaxial_compression triaxial_extension '// &
    'simple_shear mcc_drained mcc_undrained'

  !> Yield check of the Mohr–Coulomb surface.
  type, extends(empm_sp_check_t) :: mc_check_t
    real(wp) :: c = 0.0_wp, phi = 0.0_wp
  contains
    procedure :: violation => mc_violation
  end type mc_check_t

  !> Yield check of a Drucker–Prager cone √J2 = α p' + k.
  type, extends(empm_sp_check_t) :: dp_check_t
    real(wp) :: alpha = 0.0_wp, k = 0.0_wp
  contains
    procedure :: violation => dp_violation
  end type dp_check_t

  !> Yield check of the Modified Cam-Clay ellipse; p'c is state variable `ipc`.
  type, extends(empm_sp_check_t) :: mcc_check_t
    real(wp) :: M = 1.0_wp
    integer :: ipc = 1
  contains
    procedure :: violation => mcc_violation
  end type mcc_check_t

  !> No yield surface (elastic models).
  type, extends(empm_sp_check_t) :: no_check_t
  contains
    procedure :: violation => no_violation
  end type no_check_t

contains

  !> The keys of the `&stress_point` group.
  function empm_sp_params() result(p)
    type(empm_param_t), allocatable :: p(:) !! declarations
    p = [ &
      empm_param('path', PARAM_STR, '-', 'element-test path', choices=PATHS), &
      empm_param('stress0', PARAM_REAL, 'Pa', 'initial Cauchy stress, Voigt (xx, yy, zz, yz, '// &
        'xz, xy), tension positive', count=6, lo=-1.0e12_wp, hi=1.0e12_wp), &
      empm_param('strain_end', PARAM_REAL, '-', 'axial (triaxial) or engineering shear '// &
        '(simple shear) strain at the end of the path', default='0.1', lo=0.0_wp, &
        lo_open=.true., hi=1.0_wp), &
      empm_param('angle', PARAM_REAL, 'deg', 'rotation: angle about z', default='90', &
        lo=-3600.0_wp, hi=3600.0_wp), &
      empm_param('duration', PARAM_REAL, 's', 'duration of the path', default='1', &
        lo=0.0_wp, lo_open=.true., hi=1.0e12_wp), &
      empm_param('steps', PARAM_INT, '-', 'increments of the path (× the level factor)', &
        lo=1.0_wp, hi=1.0e7_wp), &
      empm_param('split', PARAM_INT, '-', 'sub-increments per increment of the split-'// &
        'dependence run (1: no such run)', default='10', lo=1.0_wp, hi=1000.0_wp)]
  end function empm_sp_params

  !> Run the stress-point study of case file `file` with `steps × factor` increments, write its
  !> histories to `out` (HDF5), and return the values of the metrics `names`; `dt` is the
  !> increment. `msg` is '' on success, else why the run failed.
  subroutine empm_sp_study(file, factor, out, names, values, dt, msg)
    character(len=*), intent(in) :: file             !! case file
    integer, intent(in) :: factor                    !! multiplier of `steps`
    character(len=*), intent(in) :: out              !! HDF5 file for the histories
    character(len=*), intent(in) :: names(:)         !! metric names
    real(wp), intent(out) :: values(:)               !! metric values (huge when unavailable)
    real(wp), intent(out) :: dt                      !! increment [s]
    character(len=:), allocatable, intent(out) :: msg !! '' or the failure
    type(empm_error_t) :: e
    type(empm_group_t), allocatable :: gs(:)
    type(empm_group_t) :: gm, gp
    type(empm_registry_t) :: reg
    class(empm_material_t), allocatable :: mat
    class(empm_sp_check_t), allocatable :: chk
    type(empm_param_t), allocatable :: pp(:), pm(:)
    type(empm_sp_point_t) :: p0, pt
    type(empm_sp_history_t) :: h1, h2
    character(len=:), allocatable :: text, path, model
    real(wp) :: s0(6), strain_end, angle, T, L(3,3), exact, err1, scale, rate, p, q, pe, qe
    real(wp) :: c, phi, psi, alpha, k, beta, kb, sphi, spsi, ccp, M, lam, kap, pc0, p0v
    logical :: mask(6)
    integer :: steps, split, ns, i, info, ipc, ierr
    integer(hid_t) :: fid
    real(wp), allocatable :: ex(:)
    character(len=STATE_NAME_LEN), allocatable :: snames(:)

    values = huge(1.0_wp); dt = 0.0_wp; msg = ''
    call empm_read_text(file, text, e)
    if (e%code == EMPM_OK) call empm_parse_namelist(text, file, gs, e)
    if (e%code /= EMPM_OK) then
      msg = e%message; return
    end if
    ! The model, through the registry, exactly as a run would create it.
    do i = 1, size(gs)
      if (gs(i)%name == 'material') gm = gs(i)
      if (gs(i)%name == 'stress_point') gp = gs(i)
    end do
    if (.not. allocated(gm%name) .or. .not. allocated(gp%name)) then
      msg = file//': a stress-point study needs the groups &material and &stress_point'; return
    end if
    pm = empm_input_group_params('material')
    model = 'linear_elastic'
    call gm%get(pm(2), model, e)
    reg = empm_default_registry()
    call reg%create_material(model, mat, e, gm, pm)
    ! The &stress_point group.
    pp = empm_sp_params()
    path = ''; s0 = 0.0_wp; strain_end = 0.1_wp; angle = 90.0_wp; T = 1.0_wp; steps = 0
    split = 10
    call gp%get(pp(1), path, e)
    call gp%get(pp(2), s0, i, e)
    call gp%get(pp(3), strain_end, e)
    call gp%get(pp(4), angle, e)
    call gp%get(pp(5), T, e)
    call gp%get(pp(6), steps, e)
    call gp%get(pp(7), split, e)
    call gp%check_keys(pp, e)
    if (e%code /= EMPM_OK) then
      msg = e%message; return
    end if
    ! Model parameters for the closed forms and the yield check, read from the &material
    ! group by this module (not from the model), so that a model that misreads them fails.
    call soil_params(gm, c, phi, psi, M, lam, kap, e)
    if (e%code /= EMPM_OK) then
      msg = e%message; return
    end if
    allocate(p0%state(mat%nstate()))
    block
      real(wp) :: st(size(p0%state), 1)
      call mat%init_state(st)
      p0%state = st(:, 1)
    end block
    p0%stress = s0; p0%rho = mat%rho0
    ns = size(p0%state)
    call mat%state_names(snames)
    ipc = 0
    do i = 1, ns
      if (lower(trim(snames(i))) == 'pc' .or. lower(trim(snames(i))) == 'p_c') ipc = i
    end do

    ! Closed-form family and yield check from the model's name.
    select case (mat%family())
    case ('mohr_coulomb')
      allocate(chk, source=mc_check_t(c=c, phi=phi))
    case ('drucker_prager')
      call dp_cone(gm, c, phi, psi, alpha, k, beta, kb, e)
      allocate(chk, source=dp_check_t(alpha=alpha, k=k))
    case ('camclay')
      if (ipc == 0) then
        msg = 'camclay: no state variable named pc'; return
      end if
      allocate(chk, source=mcc_check_t(M=M, ipc=ipc))
    case default
      allocate(chk, source=no_check_t())
    end select

    dt = T / real(steps * factor, wp)
    rate = strain_end / T
    L = 0.0_wp; mask = .false.
    select case (path)
    case ('rotation')
      L(2,1) = angle * pi / 180.0_wp / T; L(1,2) = -L(2,1)
    case ('triaxial_compression', 'mcc_drained')
      L(1,1) = -rate; mask(2:3) = .true.
    case ('triaxial_extension')
      L(1,1) = rate; mask(2:3) = .true.
    case ('simple_shear')
      L(1,2) = 0.5_wp * rate; L(2,1) = 0.5_wp * rate; mask(2) = .true.
    case ('mcc_undrained')
      L(1,1) = -rate; L(2,2) = 0.5_wp * rate; L(3,3) = 0.5_wp * rate
    end select
    pt = p0
    call empm_sp_segment(mat, pt, L, mask, s0, s0, T, steps * factor, 1, h1, info, chk)
    if (info /= 0) then
      msg = 'the path stopped at increment '//str(h1%n + 1)//' (code '//str(info)//')'; return
    end if
    if (split > 1) then
      pt = p0
      call empm_sp_replay(mat, pt, h1, split, h2, info, chk)
      if (info /= 0) then
        msg = 'the split path stopped at increment '//str(h2%n + 1)//' (code '//str(info)//')'
        return
      end if
    end if

    ! Metrics.
    allocate(ex(0:h1%n)); ex = 0.0_wp
    scale = max(maxval(abs(h1%stress)), tiny(1.0_wp))
    exact = 0.0_wp; err1 = huge(1.0_wp)
    select case (path)
    case ('rotation')
      exact = norm_voigt(s0)
      err1 = 0.0_wp
      do i = 0, h1%n
        ex(i) = angle * pi / 180.0_wp * h1%t(i) / T
        err1 = max(err1, norm_voigt(h1%stress(:,i) - empm_rotate_z(s0, ex(i))) / exact)
      end do
      ! Only the end point is compared (a study of the error at the final angle).
      err1 = norm_voigt(h1%stress(:,h1%n) - empm_rotate_z(s0, ex(h1%n))) / exact
    case ('triaxial_compression', 'triaxial_extension')
      select case (mat%family())
      case ('mohr_coulomb')
        if (path == 'triaxial_compression') then
          exact = empm_mc_triax_compression(-s0(2), c, phi)
        else
          exact = empm_mc_triax_extension(-s0(2), c, phi)
        end if
      case ('drucker_prager')
        if (path == 'triaxial_compression') then
          exact = empm_dp_triax_compression(-s0(2), alpha, k)
        else
          exact = empm_dp_triax_extension(-s0(2), alpha, k)
        end if
      end select
      q = 0.0_wp
      do i = 0, h1%n
        call empm_soil_pq(h1%stress(:,i), p, ex(i))
        q = max(q, ex(i))
      end do
      if (exact > 0.0_wp) err1 = abs(q - exact) / exact
      ex = exact
    case ('simple_shear')
      sphi = sin(phi); spsi = sin(psi)
      if (mat%family() == 'drucker_prager') call empm_dp_plane_strain(alpha, beta, k, sphi, &
                                                                       spsi, ccp)
      exact = empm_simple_shear_ratio(sphi, spsi)
      do i = 0, h1%n
        ex(i) = h1%stress(6,i) / max(-h1%stress(2,i), tiny(1.0_wp))
      end do
      if (exact > 0.0_wp) err1 = abs(ex(h1%n) - exact) / exact
    case ('mcc_drained', 'mcc_undrained')
      call empm_soil_pq(s0, p0v, q)
      pc0 = p0%state(ipc)
      if (path == 'mcc_drained') then
        call empm_mcc_drained_end(p0v, M, pe, qe)
      else
        call empm_mcc_undrained_end(p0v, pc0, M, (lam - kap) / lam, pe, qe)
      end if
      call empm_soil_pq(h1%stress(:,h1%n), p, q)
      exact = qe
      err1 = max(abs(p - pe) / pe, abs(q - qe) / qe)
    end select

    do i = 1, size(names)
      select case (trim(names(i)))
      case ('closed_form_error')
        values(i) = err1
      case ('path_error')
        values(i) = path_error()
      case ('yield_violation')
        values(i) = max(h1%max_yield, merge(h2%max_yield, 0.0_wp, split > 1))
      case ('split_dependence')
        if (split > 1) values(i) = maxval(abs(h1%stress - h2%stress)) / scale
      case ('split_dependence_end')
        if (split > 1) values(i) = maxval(abs(h1%stress(:,h1%n) - h2%stress(:,h2%n))) / scale
      case ('control_residual')
        values(i) = max(h1%max_residual, merge(h2%max_residual, 0.0_wp, split > 1))
      case default
        msg = 'unknown stress-point metric '''//trim(names(i))//''''
      end select
    end do

    ! Histories for the report.
    ierr = 0
    call h5open_f(ierr)
    call h5fcreate_f(out, H5F_ACC_TRUNC_F, fid, ierr)
    if (ierr /= 0) then
      msg = out//': cannot create'; return
    end if
    call h5_write(fid, 't', h1%t, ierr)
    call h5_write(fid, 'stress', h1%stress, ierr)
    call h5_write(fid, 'strain', h1%strain, ierr)
    if (ns > 0) call h5_write(fid, 'state', h1%state, ierr)
    call h5_write(fid, 'exact', ex, ierr)
    if (split > 1) call h5_write(fid, 'stress_split', h2%stress, ierr)
    call h5_attr(fid, 'path', path, ierr)
    call h5_attr(fid, 'model', mat%family(), ierr)
    call h5_attr(fid, 'exact_value', exact, ierr)
    call h5_attr(fid, 'M', M, ierr)
    call h5_attr(fid, 'Lambda', merge((lam - kap) / max(lam, tiny(1.0_wp)), 0.0_wp, lam > 0.0_wp), &
                 ierr)
    if (ipc > 0) call h5_attr(fid, 'pc0', p0%state(ipc), ierr)
    call h5fclose_f(fid, ierr)
    if (ierr /= 0 .and. len(msg) == 0) msg = out//': writing the histories failed'

  contains

    !> Largest deviation from the closed-form path (MCC studies), relative to p'0.
    real(wp) function path_error() result(r)
      integer :: j
      real(wp) :: pj, qj
      r = huge(1.0_wp)
      if (path == 'mcc_drained') then
        r = 0.0_wp
        do j = 0, h1%n
          call empm_soil_pq(h1%stress(:,j), pj, qj)
          r = max(r, abs(qj - 3.0_wp * (pj - p0v)) / p0v)
        end do
      else if (path == 'mcc_undrained') then
        r = 0.0_wp
        do j = 0, h1%n
          call empm_soil_pq(h1%stress(:,j), pj, qj)
          ! On the yield surface only (an overconsolidated start is elastic at first).
          if (chk%violation(h1%stress(:,j), h1%state(:,j)) > 0.0_wp .or. &
              abs(mcc_radius(pj, qj, M, h1%state(ipc,j))) <= 1.0e-8_wp) &
            r = max(r, abs(pj - empm_mcc_undrained_p(qj / pj, p0v, pc0, M, &
                                                       (lam - kap) / lam)) / p0v)
        end do
      end if
    end function path_error
  end subroutine empm_sp_study

  !> Norm of a Voigt stress as a tensor (shears counted twice).
  pure real(wp) function norm_voigt(s) result(n)
    real(wp), intent(in) :: s(6)
    n = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2.0_wp * (s(4)**2 + s(5)**2 + s(6)**2))
  end function norm_voigt

  !> Soil parameters of the &material group (zero when absent): c, φ, ψ [rad], M, λ, κ.
  subroutine soil_params(g, c, phi, psi, M, lam, kap, e)
    type(empm_group_t), intent(in) :: g
    real(wp), intent(out) :: c, phi, psi, M, lam, kap
    type(empm_error_t), intent(inout) :: e
    type(empm_group_t) :: gc
    real(wp) :: phics
    gc = g
    c = 0.0_wp; phi = 0.0_wp; psi = 0.0_wp; M = 0.0_wp; lam = 0.0_wp; kap = 0.0_wp
    phics = 0.0_wp
    call gc%get(rp('cohesion'), c, e)
    call gc%get(rp('friction_angle'), phi, e)
    call gc%get(rp('dilatancy_angle'), psi, e)
    call gc%get(rp('M'), M, e)
    call gc%get(rp('phi_cs'), phics, e)
    call gc%get(rp('lambda'), lam, e)
    call gc%get(rp('kappa'), kap, e)
    phi = phi * pi / 180.0_wp; psi = psi * pi / 180.0_wp
    if (M == 0.0_wp .and. phics > 0.0_wp) M = 6.0_wp * sin(phics * pi / 180.0_wp) / &
                                              (3.0_wp - sin(phics * pi / 180.0_wp))
  contains
    function rp(name) result(p)
      character(len=*), intent(in) :: name
      type(empm_param_t) :: p
      p = empm_param(name, PARAM_REAL, '-', 'read for the closed forms', default='0', &
                     lo=-1.0e30_wp, hi=1.0e30_wp)
    end function rp
  end subroutine soil_params

  !> The Drucker–Prager cone and potential of the &material group's `match`.
  subroutine dp_cone(g, c, phi, psi, alpha, k, beta, kb, e)
    type(empm_group_t), intent(in) :: g
    real(wp), intent(in) :: c, phi, psi
    real(wp), intent(out) :: alpha, k, beta, kb
    type(empm_error_t), intent(inout) :: e
    type(empm_group_t) :: gc
    character(len=:), allocatable :: match
    gc = g
    match = 'plane_strain'
    call gc%get(empm_param('match', PARAM_STR, '-', 'cone match', default="'plane_strain'"), &
                match, e)
    call empm_dp_match(match, c, phi, alpha, k)
    call empm_dp_match(match, c, psi, beta, kb)
  end subroutine dp_cone

  real(wp) function mc_violation(self, stress, state) result(v)
    class(mc_check_t), intent(in) :: self
    real(wp), intent(in) :: stress(6)
    real(wp), intent(in) :: state(:)
    real(wp) :: sig(3), Q(3,3), scale
    associate (unused_ => state); end associate
    call principal_decompose(stress, sig, Q)
    scale = max(-(sig(1) + sig(3)) * sin(self%phi) + 2.0_wp * self%c * cos(self%phi), &
                1.0e-12_wp * maxval(abs(sig)), tiny(1.0_wp))
    v = max(0.0_wp, empm_mc_yield(sig, self%c, self%phi)) / scale
  end function mc_violation

  real(wp) function dp_violation(self, stress, state) result(v)
    class(dp_check_t), intent(in) :: self
    real(wp), intent(in) :: stress(6)
    real(wp), intent(in) :: state(:)
    real(wp) :: p, q
    associate (unused_ => state); end associate
    call empm_soil_pq(stress, p, q)
    v = max(0.0_wp, empm_dp_yield(stress, self%alpha, self%k)) / &
        max(self%alpha * p + self%k, 1.0e-12_wp * max(p, q), tiny(1.0_wp))
  end function dp_violation

  !> Relative distance outside the MCC ellipse: its normalised radius minus one.
  pure real(wp) function mcc_radius(p, q, M, pc) result(r)
    real(wp), intent(in) :: p, q, M, pc
    r = sqrt((q / M)**2 + (p - 0.5_wp * pc)**2) / (0.5_wp * pc) - 1.0_wp
  end function mcc_radius

  real(wp) function mcc_violation(self, stress, state) result(v)
    class(mcc_check_t), intent(in) :: self
    real(wp), intent(in) :: stress(6)
    real(wp), intent(in) :: state(:)
    real(wp) :: p, q
    call empm_soil_pq(stress, p, q)
    v = max(0.0_wp, mcc_radius(p, q, self%M, state(self%ipc)))
  end function mcc_violation

  real(wp) function no_violation(self, stress, state) result(v)
    class(no_check_t), intent(in) :: self
    real(wp), intent(in) :: stress(6)
    real(wp), intent(in) :: state(:)
    associate (unused_ => self, unused2_ => stress, unused3_ => state); end associate
    v = 0.0_wp
  end function no_violation
end module empm_verify_stress_point
