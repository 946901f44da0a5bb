!> Stability curves of every time integrator (docs/integrators.md, "Stability"), from the
!> amplification matrices of [[empm_stability]]:
!> - on the one-cell oscillator (particle at the cell centre; Ω = ωΔt = CFL, ω = c/h): the
!>   spectral radius ρ, the numerical damping ratio ξ̄ and the relative period error
!>   (T̄ − T)/T over Ω ∈ (0, 2.5], and the critical Ω; the same with the particle on the node
!>   (the nodal scheme itself; for gen_alpha_grid the Hulbert–Chung scheme);
!> - on the fixed-free 20-cell lattice with 1 and 2 particles per cell: the critical CFL from
!>   the lattice amplification matrix, and from direct runs (real steps from small random
!>   velocities, CFL raised by 0.01 until the energy grows by 1e4 within 2000 steps).
!>
!> Usage: `stability_curves [outdir]` (default `reports/integrators`); writes
!> `outdir/stability.h5` (groups `oscillator/<label>` and `oscillator_node/<label>` with
!> datasets omega, rho, xi, period_error, oscillatory; attributes with the critical values) and
!> prints the table of critical Ω and CFL. Plot: `reports/integrators/plot_stability.py`.
program stability_curves
  use hdf5, only: h5open_f, h5close_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F
  use empm_kinds, only: wp
  use empm_h5, only: hid_t, h5_group, h5_close_group, h5_write, h5_attr
  use empm_files, only: empm_mkdir_p
  use empm_stability, only: empm_scheme_spec_t, empm_root_t, empm_oscillator_curve, &
    empm_critical_omega, empm_lattice_critical_cfl, empm_lattice_growth, empm_hc_omega_crit
  use empm_namelist, only: empm_kv
  implicit none
  integer, parameter :: NS = 9, NOM = 500, NCELL = 20, NSTEPS = 2000
  real(wp), parameter :: OMAX = 2.5_wp, GROWTH = 1.0e4_wp
  type(empm_scheme_spec_t) :: sp(NS)
  ! ρ_b and γ_N of each scheme, as recorded in stability.h5 (the defaults where the scheme has
  ! no such parameter); only gen_alpha_grid gets rho_b in its spec (an undeclared key is an error).
  real(wp) :: rho_b(NS) = 0.8_wp, newmark_gamma(NS) = 0.5_wp
  character(len=24) :: label(NS)
  type(empm_root_t) :: roots(NOM)
  real(wp) :: om(NOM), oc, ocn, cl1, cl2, cg1, cg2
  character(len=:), allocatable :: outdir
  character(len=512) :: buf
  integer(hid_t) :: fid, g0, g1, g
  integer :: i, k, info, ierr, e1, e2

  outdir = 'reports/integrators'
  if (command_argument_count() >= 1) then
    call get_command_argument(1, buf)
    outdir = trim(buf)
  end if
  if (empm_mkdir_p(outdir) /= 0) error stop 'stability_curves: cannot create the output folder'

  sp(1)%name = 'usf'; sp(2)%name = 'usl'; sp(3)%name = 'musl'
  sp(4)%name = 'pc_published'; sp(5)%name = 'pc_newmark'
  label(1:5) = sp(1:5)%name
  do i = 6, 9
    sp(i)%name = 'gen_alpha_grid'
  end do
  rho_b(6:9) = [0.0_wp, 0.5_wp, 0.8_wp, 1.0_wp]
  do i = 6, 9
    sp(i)%params = empm_kv('rho_b', rho_b(i))
  end do
  label(6:9) = [character(len=24) :: 'gen_alpha_grid_rb0.0', 'gen_alpha_grid_rb0.5', 'gen_alpha_grid_rb0.8', &
                'gen_alpha_grid_rb1.0']
  om = [(OMAX * k / NOM, k = 1, NOM)]

  ierr = 0
  call h5open_f(ierr)
  call h5fcreate_f(outdir//'/stability.h5', H5F_ACC_TRUNC_F, fid, ierr)
  if (ierr /= 0) error stop 'stability_curves: cannot create stability.h5'
  call h5_attr(fid, 'description', 'Amplification-matrix stability curves of the empm '// &
    'integrators (benchmarks/stability_curves.f90, docs/integrators.md)', ierr)
  call h5_attr(fid, 'omega_definition', 'Omega = omega*dt with omega = c/h, the particle-state '// &
    'frequency of the one-cell oscillator; Omega = CFL', ierr)
  call h5_attr(fid, 'lattice_cells', NCELL, ierr)
  call h5_group(fid, 'oscillator', g0, ierr)
  call h5_group(fid, 'oscillator_node', g1, ierr)

  write(*, '(a)') 'scheme            Omega_crit  Omega_crit  HC formula   CFL_crit lattice (matrix)'// &
    '   CFL_crit lattice (runs)'
  write(*, '(a)') '                  (centre)    (on node)                ppc=1       ppc=2'// &
    '          ppc=1   ppc=2'
  do i = 1, NS
    ! Particle at the cell centre.
    call empm_oscillator_curve(sp(i), om, roots, info)
    if (info /= 0) error stop 'stability_curves: oscillator curve failed'
    call empm_critical_omega(sp(i), oc, info)
    call h5_group(g0, trim(label(i)), g, ierr)
    call write_curve(g, roots, oc)
    call h5_close_group(g, ierr)
    ! Particle on the free node: the nodal time integrator without the particle projection.
    call empm_oscillator_curve(sp(i), om, roots, info, position=1.0_wp)
    if (info /= 0) error stop 'stability_curves: oscillator curve failed'
    call empm_critical_omega(sp(i), ocn, info, position=1.0_wp)
    call h5_group(g1, trim(label(i)), g, ierr)
    call write_curve(g, roots, ocn)
    call h5_close_group(g, ierr)
    ! Lattices.
    call empm_lattice_critical_cfl(sp(i), NCELL, 1, cl1, info)
    call empm_lattice_critical_cfl(sp(i), NCELL, 2, cl2, info)
    cg1 = growth_cfl(sp(i), 1)
    cg2 = growth_cfl(sp(i), 2)
    call attrs(trim(label(i)))
    if (sp(i)%name == 'gen_alpha_grid') then
      write(*, '(a16,3f12.6,2f12.6,3x,2f8.2)') label(i), oc, ocn, empm_hc_omega_crit(rho_b(i)), &
        cl1, cl2, cg1, cg2
    else
      write(*, '(a16,2f12.6,12x,2f12.6,3x,2f8.2)') label(i), oc, ocn, cl1, cl2, cg1, cg2
    end if
  end do
  call h5_close_group(g0, ierr)
  call h5_close_group(g1, ierr)
  ! ierr has collected every write's status: the closes get their own, so none is lost.
  call h5fclose_f(fid, e1)
  call h5close_f(e2)
  if (ierr /= 0 .or. e1 /= 0 .or. e2 /= 0) error stop 'stability_curves: HDF5 error'
  write(*, '(a)') 'wrote '//outdir//'/stability.h5'

contains

  !> Datasets of one curve: Ω, ρ, ξ̄, period error and the oscillatory mask (1 where the
  !> principal pair exists), and the critical Ω as an attribute.
  subroutine write_curve(gid, r, omega_crit)
    integer(hid_t), intent(in) :: gid            !! group
    type(empm_root_t), intent(in) :: r(:)        !! measures at each Ω
    real(wp), intent(in) :: omega_crit           !! critical Ω
    real(wp) :: col(size(r))
    integer :: mask(size(r))
    call h5_write(gid, 'omega', om, ierr)
    ! Contiguous copies: components of an array of structures are strided.
    col = r%rho
    call h5_write(gid, 'rho', col, ierr)
    col = r%xi
    call h5_write(gid, 'xi', col, ierr)
    col = r%period_error
    call h5_write(gid, 'period_error', col, ierr)
    mask = merge(1, 0, r%oscillatory)
    call h5_write(gid, 'oscillatory', mask, ierr)
    call h5_attr(gid, 'omega_crit', omega_crit, ierr)
    call h5_attr(gid, 'scheme', trim(sp(i)%name), ierr)
    call h5_attr(gid, 'rho_b', rho_b(i), ierr)
    call h5_attr(gid, 'newmark_gamma', newmark_gamma(i), ierr)
  end subroutine write_curve

  !> Lattice results as attributes of oscillator/<name> (reopened through a fresh group handle).
  subroutine attrs(name)
    character(len=*), intent(in) :: name !! group name under /oscillator
    integer(hid_t) :: gid
    call open_group(g0, name, gid)
    call h5_attr(gid, 'cfl_crit_lattice_ppc1', cl1, ierr)
    call h5_attr(gid, 'cfl_crit_lattice_ppc2', cl2, ierr)
    call h5_attr(gid, 'cfl_growth_ppc1', cg1, ierr)
    call h5_attr(gid, 'cfl_growth_ppc2', cg2, ierr)
    call h5_close_group(gid, ierr)
  end subroutine attrs

  !> Open an existing group.
  subroutine open_group(loc, name, gid)
    use hdf5, only: h5gopen_f
    integer(hid_t), intent(in) :: loc     !! parent
    character(len=*), intent(in) :: name  !! group name
    integer(hid_t), intent(out) :: gid    !! opened group
    integer :: e
    call h5gopen_f(loc, name, gid, e)
    if (e /= 0) ierr = e
  end subroutine open_group

  !> Smallest CFL on the grid 0.50, 0.51, ... at which a direct lattice run grows by GROWTH.
  real(wp) function growth_cfl(s, ppc) result(cfl)
    type(empm_scheme_spec_t), intent(in) :: s !! scheme
    integer, intent(in) :: ppc                !! particles per cell
    real(wp) :: gr
    integer :: j, st
    cfl = -1.0_wp
    do j = 50, 300
      call empm_lattice_growth(s, NCELL, ppc, 0.01_wp * j, NSTEPS, gr, st, stop_ratio=GROWTH)
      if (gr > GROWTH .or. st == 2) then
        cfl = 0.01_wp * j; return
      end if
    end do
  end function growth_cfl
end program stability_curves
