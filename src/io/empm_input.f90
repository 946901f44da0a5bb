!> Reads and validates a case file (namelist groups, one per concern) into an [[empm_case_t]].
!> Every key is documented in docs/input.md, whose key tables are generated from the
!> declarations here and in the families (`empm keys`).
!>
!> The file is parsed into groups ([[empm_namelist]]); each group's keys are declared below
!> (the core groups) or by the family the group selects (shape, material model, integrator,
!> created through the [[empm_registry]]). The reader knows no family: it passes each group to
!> the registry. Validation is strict: an unknown group or key, a missing required key, a value
!> out of range, a group given twice that may appear once, or an inconsistent combination gives
!> an error with code EMPM_ERR_INPUT (exit status 2) naming the file, the line, the group, the
!> key and what was expected.
module empm_input
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_parallel, only: empm_max_threads
  use empm_error, only: empm_error_t, empm_raise_error, EMPM_ERR_INPUT, EMPM_OK
  use empm_strings, only: str, str_short
  use empm_files, only: empm_read_text, empm_physical_memory, empm_path_beside
  use empm_params, only: empm_param_t, empm_param, empm_params_markdown, empm_param_names, &
                         PARAM_REAL, PARAM_INT, PARAM_STR, PARAM_LOGICAL
  use empm_namelist, only: empm_group_t, empm_parse_namelist
  use empm_case, only: empm_case_t, empm_overrides_t
  use empm_integrator, only: WALL_SCHEMES
  use empm_friction, only: empm_wall_problem
  use empm_model, only: empm_material_slot_t
  use empm_loads, only: RAMP_NONE, RAMP_SINE, RAMP_LINEAR, empm_traction_t, empm_geostatic_stress
  use empm_extension, only: EXT_THETA_DEFAULT
  use empm_particle_gen, only: empm_fill, empm_deal_t, GEOM_BOX, GEOM_DISK, PLACE_GAUSS, &
    PLACE_VOXEL
  use empm_comm, only: empm_comm_t
  use empm_partition, only: empm_list_loaded
  use empm_shape, only: shape_status_text
  use empm_registry, only: empm_registry_t, empm_default_registry
  use empm_solver, only: empm_run_params
  use empm_bodies, only: empm_body_points_t, empm_read_body
  implicit none
  private
  public :: empm_read_case, empm_input_markdown, empm_input_group_params, empm_check_basis

  character(len=*), parameter :: GROUPS = 'grid material particles shape integrator loads '// &
                                          'traction boundary probe output'
  character(len=*), parameter :: REPEATABLE = 'material particles traction boundary probe'
  !> Characters of a name that becomes an HDF5 group (a '/' would make it a path).
  character(len=*), parameter :: NAME_CHARS = &
    'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-'
  integer, parameter :: MAXSNAP = 1000          !! capacity of output%snapshot_times
  !> Largest magnitude of a length or coordinate [m] (and of a speed [m/s], an acceleration
  !> [m/s²]): beyond it the products a step forms (x², m v², σ V) overflow double precision.
  real(wp), parameter :: LMAX = 1.0e15_wp

contains

  ! ---- declarations ------------------------------------------------------------------------

  !> The keys of a core group (for the shape, material and integrator groups: the common keys,
  !> which select the family; the family declares the rest). Empty for an unknown group.
  function empm_input_group_params(group) result(p)
    character(len=*), intent(in) :: group    !! group name without '&'
    type(empm_param_t), allocatable :: p(:)  !! declarations
    select case (group)
    case ('grid')
      p = [ &
        empm_param('ndim', PARAM_INT, '-', 'spatial dimension: 1 (uniaxial strain), 2 (plane '// &
          'strain) or 3', lo=1.0_wp, hi=3.0_wp), &
        empm_param('origin', PARAM_REAL, 'm', 'coordinates of the first node', default='0', &
          count=3, lo=-LMAX, hi=LMAX), &
        empm_param('h', PARAM_REAL, 'm', 'cell size per direction; one value applies to every '// &
          'direction', count=3, lo=0.0_wp, lo_open=.true., hi=LMAX), &
        empm_param('cells', PARAM_INT, '-', 'number of cells per direction (ndim values); the '// &
          'grid must fit in memory (checked before allocating)', count=3, lo=1.0_wp, &
          hi=1.0e8_wp), &
        empm_param('min_fill', PARAM_REAL, '-', 'a free node whose support the bodies fill '// &
          'less than this fraction (sum of N_Ip V_p over h^ndim) is extrapolated from its '// &
          'well-filled neighbours instead of divided by its tiny mass (docs/free-surfaces.md); '// &
          '0 turns the extension off', default=str_short(EXT_THETA_DEFAULT), &
          lo=0.0_wp, hi=0.5_wp)]
    case ('material')
      p = [ &
        empm_param('name', PARAM_STR, '-', 'label referenced by &particles material (unique)'), &
        empm_param('model', PARAM_STR, '-', 'material model (see the models below)', &
          default='''linear_elastic''')]
    case ('particles')
      p = [ &
        empm_param('material', PARAM_STR, '-', 'a &material name'), &
        empm_param('geometry', PARAM_STR, '-', 'body shape: box (interval in 1D), disk '// &
          '(sphere in 3D, ndim >= 2) or file (points or mesh read from `file`); a box face '// &
          'inside a cell fills only the part of the cell inside the box (docs/free-surfaces.md)', &
          default='''box''', choices='box interval disk sphere file'), &
        empm_param('lo', PARAM_REAL, 'm', 'box: lower corner (required for a box)', count=3, &
          lo=-LMAX, hi=LMAX, optional=.true.), &
        empm_param('hi', PARAM_REAL, 'm', 'box: upper corner, hi > lo (required for a box)', &
          count=3, lo=-LMAX, hi=LMAX, optional=.true.), &
        empm_param('center', PARAM_REAL, 'm', 'disk: centre (required for a disk)', count=3, &
          lo=-LMAX, hi=LMAX, optional=.true.), &
        empm_param('radius', PARAM_REAL, 'm', 'disk: radius (required for a disk)', &
          lo=0.0_wp, lo_open=.true., hi=LMAX, optional=.true.), &
        empm_param('file', PARAM_STR, '-', 'file: point list (.csv, .h5/.hdf5) or Gmsh 4.1 '// &
          'mesh (.msh), relative to the case file''s folder (required for a file)', &
          optional=.true.), &
        empm_param('ppc', PARAM_INT, '-', 'particles per cell per direction (ppc^ndim per '// &
          'cell; the particles must fit in memory, estimated before they are generated); for a '// &
          'mesh, the quadrature order per direction', default='2', lo=1.0_wp, &
          hi=4.0_wp), &
        empm_param('placement', PARAM_STR, '-', 'gauss: Gauss-Legendre points, volume = Gauss '// &
          'weight x cell volume; voxel: centres of ppc^ndim equal sub-cells', &
          default='''gauss''', choices='gauss voxel'), &
        empm_param('velocity', PARAM_REAL, 'm/s', 'uniform initial velocity', default='0', &
          count=3, lo=-LMAX, hi=LMAX), &
        empm_param('velocity_sine_amplitude', PARAM_REAL, 'm/s', 'A in v += A sin(k.x + phi)', &
          default='0', count=3, lo=-LMAX, hi=LMAX), &
        empm_param('velocity_sine_wavenumber', PARAM_REAL, '1/m', 'k in the same', &
          default='0', count=3, lo=-LMAX, hi=LMAX), &
        empm_param('velocity_sine_phase', PARAM_REAL, 'rad', 'phi in the same', default='0', &
          lo=-LMAX, hi=LMAX), &
        empm_param('stress', PARAM_REAL, 'Pa', 'uniform initial Cauchy stress, Voigt order '// &
          'xx, yy, zz, yz, xz, xy', default='0', count=6, lo=-1.0e30_wp, hi=1.0e30_wp), &
        empm_param('name', PARAM_STR, '-', 'body label (unique), referenced by &traction '// &
          'body', optional=.true.), &
        empm_param('geostatic', PARAM_LOGICAL, '-', 'initial stress from the overburden '// &
          'under the final gravity: sigma_v = -rho |g| depth, sigma_h = k0 sigma_v (instead '// &
          'of `stress`)', default='.false.'), &
        empm_param('k0', PARAM_REAL, '-', 'lateral earth pressure coefficient K0 of the '// &
          'geostatic stress (required with geostatic)', lo=0.0_wp, hi=100.0_wp, &
          optional=.true.)]
    case ('shape')
      p = [empm_param('family', PARAM_STR, '-', 'shape-function family (see the families '// &
        'below), or an identifier that also sets tagged parameters, e.g. ''lme_g0.8''', &
        default='''linear''')]
    case ('integrator')
      p = [empm_param('scheme', PARAM_STR, '-', 'time integrator (see the schemes below)', &
        default='''musl'''), empm_run_params(), &
        empm_param('damping', PARAM_REAL, '-', 'local non-viscous damping alpha: nodal force '// &
          'f -= alpha |f| sign(v) (0: none; for reaching static equilibrium)', default='0', &
          lo=0.0_wp, hi=1.0_wp, hi_open=.true.), &
        empm_param('volumetric_smoothing', PARAM_LOGICAL, '-', 'replace each particle''s '// &
          'volumetric strain rate by its mass-weighted nodal average (against volumetric '// &
          'locking in nearly incompressible plastic flow; docs/integrators.md)', &
          default='.false.')]
    case ('loads')
      p = [ &
        empm_param('gravity', PARAM_REAL, 'm/s^2', 'gravity vector (final value)', &
          default='0', count=3, lo=-LMAX, hi=LMAX), &
        empm_param('ramp', PARAM_STR, '-', 'none (constant) or sine: the paper''s eq. (46), '// &
          'g(t) = g (sin(2 pi t/T - pi/2) + 1)/2 for t <= T/2, g after', default='''none''', &
          choices='none sine'), &
        empm_param('ramp_time', PARAM_REAL, 's', 'T of eq. (46) (required with ramp = sine)', &
          lo=0.0_wp, lo_open=.true., hi=LMAX, optional=.true.)]
    case ('boundary')
      p = [ &
        empm_param('lo', PARAM_REAL, 'm', 'lower corner of the box selecting the nodes', &
          count=3, lo=-LMAX, hi=LMAX), &
        empm_param('hi', PARAM_REAL, 'm', 'upper corner of the box selecting the nodes', &
          count=3, lo=-LMAX, hi=LMAX), &
        empm_param('fix', PARAM_LOGICAL, '-', 'which velocity components are prescribed '// &
          '(at least one)', default='.false.', count=3), &
        empm_param('velocity', PARAM_REAL, 'm/s', 'prescribed velocity of the fixed components', &
          default='0', count=3, lo=-LMAX, hi=LMAX), &
        empm_param('name', PARAM_STR, '-', 'record the reaction force of this node set as '// &
          '/history/reaction/<name> (unique)', optional=.true.), &
        empm_param('mirror', PARAM_STR, '-', 'a mirror plane: the box is flat along this '// &
          'axis (a grid line), its nodes get the fix components fixed at zero, and the nodes '// &
          'on the given side of it are ghosts with the mirrored values (fix components odd, '// &
          'the others even): a fixed end with symmetric supports (docs/free-surfaces.md)', &
          default='''none''', choices='none -x +x -y +y -z +z'), &
        empm_param('friction_angle', PARAM_REAL, 'deg', 'a frictional wall at rest: the '// &
          'box is flat along the axis of normal, its nodes get the normal component fixed at '// &
          'zero and Coulomb friction tan(friction_angle) on the others (replaces fix; '// &
          'docs/input.md)', lo=0.0_wp, hi=90.0_wp, hi_open=.true., optional=.true.), &
        empm_param('normal', PARAM_STR, '-', 'with friction_angle: the direction from the '// &
          'wall into the body (''+y'' for a base under it)', optional=.true., &
          choices='-x +x -y +y -z +z'), &
        empm_param('velocity_gradient', PARAM_REAL, '1/s', 'a kinematic driver: the fixed '// &
          'components get velocity + G x_I at each node x_I (G given row by row, ndim x ndim '// &
          'values; steady in space and time: rigid rotation, simple shear, triaxial paths)', &
          count=9, lo=-LMAX, hi=LMAX, optional=.true.)]
    case ('traction')
      p = [ &
        empm_param('name', PARAM_STR, '-', 'label (messages)', optional=.true.), &
        empm_param('body', PARAM_STR, '-', 'a &particles name: load that body only '// &
          '(default: every body)', optional=.true.), &
        empm_param('lo', PARAM_REAL, 'm', 'lower corner of the box selecting the loaded '// &
          'particles (the outer layer); its side on the face side is the loaded surface', &
          count=3, lo=-LMAX, hi=LMAX), &
        empm_param('hi', PARAM_REAL, 'm', 'upper corner of that box', count=3, lo=-LMAX, &
          hi=LMAX), &
        empm_param('face', PARAM_STR, '-', 'the loaded face of each particle, its outward '// &
          'normal: +x, -x, +y, -y, +z or -z', choices='+x -x +y -y +z -z'), &
        empm_param('pressure', PARAM_REAL, 'Pa', 'normal pressure, positive pushing into the '// &
          'body (traction = -pressure n); give pressure or traction', lo=-1.0e30_wp, &
          hi=1.0e30_wp, optional=.true.), &
        empm_param('traction', PARAM_REAL, 'Pa', 'traction vector (force per area); give '// &
          'pressure or traction', count=3, lo=-1.0e30_wp, hi=1.0e30_wp, optional=.true.), &
        empm_param('ramp', PARAM_STR, '-', 'none (constant), linear (0 at t = 0 to the full '// &
          'value at ramp_time) or sine (as &loads ramp: full value at ramp_time/2)', &
          default='''none''', choices='none linear sine'), &
        empm_param('ramp_time', PARAM_REAL, 's', 'ramp time (required with a ramp)', &
          lo=0.0_wp, lo_open=.true., hi=LMAX, optional=.true.)]
    case ('probe')
      p = [ &
        empm_param('name', PARAM_STR, '-', 'probe name (HDF5 group /probes/<name>)'), &
        empm_param('particle', PARAM_INT, '-', 'follow this particle (1-based index in '// &
          'generation order)', lo=1.0_wp, optional=.true.), &
        empm_param('point', PARAM_REAL, 'm', 'follow the particle nearest to this point at '// &
          't = 0', count=3, lo=-LMAX, hi=LMAX, optional=.true.)]
    case ('output')
      p = [ &
        empm_param('file', PARAM_STR, '-', 'HDF5 output (overridden by empm run -o); '// &
          'default: the case name + .h5', optional=.true.), &
        empm_param('history_every', PARAM_INT, '-', 'sample energies and probes every n steps '// &
          '(and at t_end)', default='1', lo=1.0_wp), &
        empm_param('snapshot_times', PARAM_REAL, 's', 'increasing times in [0, t_end] at '// &
          'which the particle state is stored (each written to OUT.h5.snapshots/ as it is taken, '// &
          'copied into OUT.h5 at the end; docs/output.md)', count=MAXSNAP, lo=0.0_wp, hi=LMAX, &
          optional=.true.), &
        empm_param('checkpoint_every', PARAM_INT, '-', 'write a restart checkpoint every n '// &
          'steps (OUT.ckpt.h5, the previous one kept as OUT.ckpt.prev.h5; docs/output.md); '// &
          '0: none', default='0', lo=0.0_wp), &
        empm_param('checkpoint_seconds', PARAM_REAL, 's', 'write a restart checkpoint when '// &
          'this much wall-clock time has passed since the last one (with or without '// &
          'checkpoint_every); 0: none', default='0', lo=0.0_wp, hi=LMAX)]
    case default
      allocate(p(0))
    end select
  end function empm_input_group_params

  !> The generated part of docs/input.md: the key table of every core group, then the families
  !> of each extension point with their parameters (from `registry`, default the built-ins).
  function empm_input_markdown(registry) result(s)
    type(empm_registry_t), intent(in), optional :: registry !! families to document
    character(len=:), allocatable :: s                      !! Markdown
    character(len=*), parameter :: NL = new_line('a')
    type(empm_registry_t) :: reg
    character(len=16), parameter :: ORDER(10) = [character(len=16) :: 'grid', 'material', &
      'particles', 'shape', 'integrator', 'loads', 'traction', 'boundary', 'probe', 'output']
    integer :: k
    if (present(registry)) then
      reg = registry
    else
      reg = empm_default_registry()
    end if
    s = ''
    do k = 1, size(ORDER)
      s = s//'### `&'//trim(ORDER(k))//'`'//NL//NL// &
        empm_params_markdown(empm_input_group_params(trim(ORDER(k))))//NL
      select case (trim(ORDER(k)))
      case ('material')
        s = s//'Models (`model`) and their keys:'//NL//NL//reg%markdown('material')
      case ('shape')
        s = s//'Families (`family`) and their keys:'//NL//NL//reg%markdown('shape')
      case ('integrator')
        s = s//'Schemes (`scheme`) and their keys:'//NL//NL//reg%markdown('integrator')
      end select
    end do
  end function empm_input_markdown

  ! ---- reading -----------------------------------------------------------------------------

  !> Read, validate and set up the case in `path`. On error, `err` (or a stop with status 2)
  !> names the file, the line, the group and the key. `extra_groups` (blank-separated) are
  !> groups the caller reads itself (e.g. 'verify'): they are skipped, not rejected.
  subroutine empm_read_case(path, cs, err, overrides, registry, extra_groups, shared, comm)
    character(len=*), intent(in) :: path                      !! case file
    type(empm_case_t), intent(inout) :: cs                    !! the case, ready to run
    type(empm_error_t), intent(out), optional :: err          !! error, if present
    type(empm_overrides_t), intent(in), optional :: overrides !! changes to the file's values
    type(empm_registry_t), intent(in), optional :: registry   !! families (default: built-ins)
    character(len=*), intent(in), optional :: extra_groups    !! groups read by the caller
    logical, intent(in), optional :: shared                   !! the case will be shared among
                                                              !! processes: the nodal fields
                                                              !! wait for each one's window of
                                                              !! the grid, the basis and its
                                                              !! check for each one's share:
                                                              !! call empm_partition_particles,
                                                              !! then [[empm_check_basis]]
                                                              !! (docs/parallel.md)
    type(empm_comm_t), intent(in), optional :: comm           !! with `shared`: the processes
                                                              !! (collective); each generates
                                                              !! every particle and stores its
                                                              !! share of them only
    type(empm_overrides_t) :: ov
    type(empm_registry_t) :: reg
    type(empm_group_t), allocatable :: gs(:)
    type(empm_error_t) :: e
    character(len=:), allocatable :: extra
    logical :: fields
    integer :: at(2)

    cs = empm_case_t()  ! a case object may be read into again
    if (present(overrides)) ov = overrides
    if (present(registry)) then
      reg = registry
    else
      reg = empm_default_registry()
    end if
    extra = ''
    if (present(extra_groups)) extra = extra_groups
    cs%file = path
    if (present(comm) .and. present(shared)) then
      if (shared .and. comm%parallel()) then
        cs%model%comm = comm
        cs%deal = empm_deal_t(every=comm%nranks, rank=comm%rank)
        cs%local = comm%machine_size()
      end if
    end if
    call empm_read_text(path, cs%text, e)
    if (e%code /= EMPM_OK) &
      call e%set(EMPM_ERR_INPUT, 'cannot open case file: '//e%message, file=path)
    ! Dealt out among processes (cs%deal), the reading has collective steps: an error only one
    ! process has (a file missing on its machine, its memory) is everyone's before them.
    call cs%model%comm%agree(e)
    if (e%code /= EMPM_OK) then
      call empm_raise_error(e, err); return
    end if
    call empm_parse_namelist(cs%text, path, gs, e)
    if (e%code == EMPM_OK) call check_groups(path, gs, extra, e)
    if (e%code == EMPM_OK) call read_grid(path, gs, cs, ov, e)
    if (e%code == EMPM_OK) call read_materials(path, gs, cs, reg, e)
    if (e%code == EMPM_OK) call read_shape(gs, cs, ov, reg, e)
    at = 0
    if (e%code == EMPM_OK) call read_particles(path, gs, cs, ov, e, at)
    call agree_first(cs%model%comm, e, at)
    if (e%code == EMPM_OK) call same_particles(path, cs, e)
    if (e%code == EMPM_OK) call read_integrator(path, gs, cs, ov, reg, e)
    if (e%code == EMPM_OK) call read_loads(gs, cs, e)
    if (e%code == EMPM_OK) call apply_geostatic(gs, cs, e)
    fields = .true.
    if (present(shared)) fields = .not. shared
    if (e%code == EMPM_OK) call read_boundaries(gs, cs, fields, e)
    if (e%code == EMPM_OK) call read_tractions(gs, cs, e)
    if (e%code == EMPM_OK) cs%model%track = cs%integ%damping > 0.0_wp .or. &
      any(cs%body_k0 >= 0.0_wp) .or. cs%model%loads%ntraction() > 0 .or. &
      cs%model%nodes%nset > 0
    if (e%code == EMPM_OK) call read_probes(gs, cs, e)
    if (e%code == EMPM_OK) call read_output(path, gs, cs, e)
    if (e%code == EMPM_OK) call cs%model%finalize_setup(e, shared=.not. fields)
    if (e%code == EMPM_OK .and. fields) call check_basis(path, cs, e)
    call empm_raise_error(e, err)
  end subroutine empm_read_case

  ! ---- helpers ----------------------------------------------------------------------------

  !> The error every process reports after reading the particles: that of the earliest place
  !> `at` (body, then line of its file: 0 before it, huge after) over the processes. Dealt out,
  !> each process checks the values of its own points of a CSV file only ([[empm_bodies]]), so
  !> that the earliest is the error one process reading every point meets first. Collective.
  subroutine agree_first(comm, e, at)
    type(empm_comm_t), intent(in) :: comm
    type(empm_error_t), intent(inout) :: e
    integer, intent(in) :: at(2)
    integer :: b, l
    if (.not. comm%parallel()) return
    b = comm%min_int(merge(at(1), huge(1), e%code /= EMPM_OK))
    l = comm%min_int(merge(at(2), huge(1), e%code /= EMPM_OK .and. at(1) == b))
    if (e%code /= EMPM_OK .and. (at(1) /= b .or. at(2) /= l)) e = empm_error_t()
    call comm%agree(e)
  end subroutine agree_first

  !> Dealt out among processes (cs%deal), every process must have generated the same number of
  !> particles: a body file that differs between machines would otherwise give ids twice or
  !> not at all. Collective.
  subroutine same_particles(path, cs, e)
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(in) :: cs
    type(empm_error_t), intent(inout) :: e
    integer :: lo, hi
    if (cs%deal%every <= 1) return
    lo = cs%model%comm%min_int(cs%deal%n); hi = cs%model%comm%max_int(cs%deal%n)
    if (lo /= hi) call e%set(EMPM_ERR_INPUT, 'the processes generated different numbers of '// &
      'particles ('//str(lo)//' to '//str(hi)//'): do the bodies'' files differ between '// &
      'the machines?', file=path)
  end subroutine same_particles

  !> Every group must be known (or one of `extra`), and a group that may appear once must not
  !> appear twice.
  subroutine check_groups(path, gs, extra, e)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    character(len=*), intent(in) :: extra
    type(empm_error_t), intent(inout) :: e
    integer :: i, j
    do i = 1, size(gs)
      if (index(' '//extra//' ', ' '//gs(i)%name//' ') > 0) cycle
      if (index(' '//GROUPS//' ', ' '//gs(i)%name//' ') == 0) then
        call e%set(EMPM_ERR_INPUT, 'unknown group &'//gs(i)%name//'; expected one of: '// &
          trim(GROUPS//' '//extra), file=path, line=gs(i)%line)
        return
      end if
      if (index(' '//REPEATABLE//' ', ' '//gs(i)%name//' ') > 0) cycle
      do j = 1, i - 1
        if (gs(j)%name == gs(i)%name) then
          call e%set(EMPM_ERR_INPUT, 'group &'//gs(i)%name//' given twice (first at line '// &
            str(gs(j)%line)//'); it may appear once', file=path, line=gs(i)%line)
          return
        end if
      end do
    end do
  end subroutine check_groups

  !> Index of the first group called `name`, 0 if none.
  pure integer function first(gs, name) result(k)
    type(empm_group_t), intent(in) :: gs(:)
    character(len=*), intent(in) :: name
    do k = 1, size(gs)
      if (gs(k)%name == name) return
    end do
    k = 0
  end function first

  !> The group `name`, or an empty one (so that defaults apply) when absent.
  subroutine group_or_empty(path, gs, name, g)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    character(len=*), intent(in) :: name
    type(empm_group_t), intent(out) :: g
    integer :: k
    k = first(gs, name)
    if (k > 0) then
      g = gs(k)
    else
      g%file = path; g%name = name; g%line = 0
      allocate(g%kv(0))
    end if
  end subroutine group_or_empty

  subroutine missing_group(path, name, e)
    character(len=*), intent(in) :: path, name
    type(empm_error_t), intent(inout) :: e
    call e%set(EMPM_ERR_INPUT, 'missing required group &'//name//' (keys: '// &
      empm_param_names(empm_input_group_params(name))//')', file=path)
  end subroutine missing_group

  ! ---- groups -----------------------------------------------------------------------------

  subroutine read_grid(path, gs, cs, ov, e)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    integer :: ndim, cells(3), info, n
    integer(int64) :: nnode, bytes, mem
    real(wp) :: origin(3), h(3)
    if (first(gs, 'grid') == 0) then
      call missing_group(path, 'grid', e); return
    end if
    g = gs(first(gs, 'grid'))
    allocate(p, source=empm_input_group_params('grid'))
    call g%check_keys(p, e)
    ndim = 0; origin = 0.0_wp; h = 0.0_wp; cells = 0
    call g%get(p(1), ndim, e)
    call g%get(p(2), origin, n, e)
    call g%get(p(3), h, n, e)
    if (e%code /= EMPM_OK) return
    h(max(n, 1) + 1:3) = h(1)  ! one value applies to every direction
    call g%get(p(4), cells, n, e)
    call g%get(p(5), cs%model%nodes%ext%theta, e)
    if (e%code /= EMPM_OK) return
    if (n < ndim) then
      call g%fail(e, 'cells', 'expected '//str(ndim)//' cell counts (one per direction), got '// &
        str(n)); return
    end if
    ! Counts in 64 bits: cells x refine and the node count can exceed 2^31.
    if (any(int(cells(1:ndim), int64) * ov%refine > 100000000_int64)) then
      call g%fail(e, 'cells', 'expected at most 1e8 cells per direction after refinement '// &
        'by '//str(ov%refine)); return
    end if
    h = h / ov%refine; cells = cells * ov%refine
    nnode = product(int(cells(1:ndim), int64) + 1_int64)
    if (nnode > int(huge(1), int64)) then
      call g%fail(e, 'cells', 'the grid has '//str(real(nnode, wp))//' nodes, more than '// &
        str(huge(1))//' (node numbers are default integers)'); return
    end if
    ! Nodal fields (mass, 6 vectors, the constraint mask) and the per-thread P2G buffers.
    bytes = nnode * (8_int64 + 52_int64 * ndim) + &
      (empm_max_threads() - 1) * nnode * 8_int64 * (ndim + 1)
    mem = empm_physical_memory()
    if (mem > 0 .and. bytes > mem) then
      call g%fail(e, 'cells', 'the grid ('//str(real(nnode, wp))//' nodes) needs about '// &
        str_short(real(bytes, wp) / 2.0_wp**30)//' GiB of node storage, more than this '// &
        'machine''s '//str_short(real(mem, wp) / 2.0_wp**30)//' GiB'); return
    end if
    call cs%model%grid%init(ndim, origin, h, cells, info)
    if (info /= 0) then
      ! Not reachable after the checks above; kept so that no grid error passes silently.
      call g%fail(e, '', 'invalid grid (grid_init status '//str(info)//')'); return
    end if
    call cs%model%pts%alloc(ndim, 1024)
  end subroutine read_grid

  subroutine read_materials(path, gs, cs, reg, e)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_registry_t), intent(in) :: reg
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    type(empm_material_slot_t), allocatable :: tmp(:)
    character(len=:), allocatable :: name, model
    integer :: k, n, i
    allocate(p, source=empm_input_group_params('material'))
    allocate(cs%model%mats(0))
    n = 0
    do k = 1, size(gs)
      if (gs(k)%name /= 'material') cycle
      g = gs(k)
      n = n + 1
      name = ''; model = 'linear_elastic'
      call g%get(p(1), name, e)
      call g%get(p(2), model, e)
      if (e%code /= EMPM_OK) return
      if (len_trim(name) == 0) then
        call g%fail(e, 'name', 'expected a label (material '//str(n)//')'); return
      end if
      do i = 1, n - 1
        if (cs%model%mats(i)%label == name) then
          call g%fail(e, 'name', 'duplicate label '''//name//''''); return
        end if
      end do
      allocate(tmp(n))
      do i = 1, n - 1
        call move_alloc(cs%model%mats(i)%model, tmp(i)%model)
        tmp(i)%label = cs%model%mats(i)%label
      end do
      call move_alloc(tmp, cs%model%mats)
      cs%model%mats(n)%label = name
      call reg%create_material(model, cs%model%mats(n)%model, e, g, p)
      if (e%code /= EMPM_OK) return
    end do
    if (n == 0) call missing_group(path, 'material', e)
  end subroutine read_materials

  subroutine read_shape(gs, cs, ov, reg, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    type(empm_registry_t), intent(in) :: reg
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    character(len=:), allocatable :: family
    allocate(p, source=empm_input_group_params('shape'))
    call group_or_empty(cs%file, gs, 'shape', g)
    family = 'linear'
    call g%get(p(1), family, e)
    if (e%code /= EMPM_OK) return
    if (allocated(ov%shape)) then
      ! The study replaces the family: the file's keys of another family do not apply (the
      ! file's family named as it is keeps them, e.g. LME with node-wise γ).
      if (ov%shape /= family) call g%keep_only(p)
      family = ov%shape
    end if
    call reg%create_shape(family, cs%model%grid, cs%model%shape, e, g, p)
    if (e%code /= EMPM_OK) return
    cs%shape_name = cs%model%shape%name()
  end subroutine read_shape

  subroutine read_particles(path, gs, cs, ov, e, at)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    type(empm_error_t), intent(inout) :: e
    integer, intent(inout) :: at(2)   ! where an error was met ([[agree_first]]): the body,
                                      ! and 0 before its file, the file's line, or huge after
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    character(len=:), allocatable :: material, geometry, placement, file
    real(wp) :: lo(3), hi(3), center(3), radius, velocity(3), amp(3), wavenumber(3), phase, &
                stress(6)
    integer :: ppc, info, nbody, imat, i, geom, place, nadded, p0, q, nd, k, n, nlo, nhi, nc
    integer(int64) :: nest
    type(empm_body_points_t) :: body
    character(len=:), allocatable :: bname
    logical :: geostatic
    real(wp) :: k0
    allocate(p, source=empm_input_group_params('particles'))
    nd = cs%model%grid%ndim
    nbody = 0
    allocate(cs%body_name(0), cs%body_first(0), cs%body_last(0), cs%body_k0(0), &
      cs%body_group(0), cs%body_lo(3, 0), cs%body_hi(3, 0), cs%body_box(0))
    nest = 0
    do k = 1, size(gs)
      if (gs(k)%name /= 'particles') cycle
      g = gs(k)
      nbody = nbody + 1
      at = [nbody, 0]
      call g%check_keys(p, e)
      bname = ''; geostatic = .false.; k0 = -1.0_wp
      call g%get(p(15), bname, e)
      call g%get(p(16), geostatic, e)
      call g%get(p(17), k0, e)
      if (e%code /= EMPM_OK) return
      if (g%has('name')) then
        if (.not. valid_name(bname)) then
          call g%fail(e, 'name', 'expected letters, digits, ''_'', ''.'' or ''-'' (at most '// &
            '64), got '''//bname//''''); return
        end if
        if (any(cs%body_name == bname)) then
          call g%fail(e, 'name', 'duplicate body name '''//bname//''''); return
        end if
      end if
      if (geostatic .and. .not. g%has('k0')) then
        call g%fail(e, 'k0', 'required with geostatic = .true.: K0 = sigma_h/sigma_v (body '// &
          str(nbody)//')'); return
      end if
      if (geostatic .and. g%has('stress')) then
        call g%fail(e, 'stress', 'give geostatic or stress, not both (body '//str(nbody)//')')
        return
      end if
      if (.not. geostatic) k0 = -1.0_wp
      cs%body_name = [character(len=64) :: cs%body_name, bname]
      cs%body_first = [cs%body_first, cs%model%pts%np + 1]
      cs%body_k0 = [cs%body_k0, k0]; cs%body_group = [cs%body_group, k]
      material = ''; geometry = 'box'; placement = 'gauss'; ppc = 2; file = ''
      lo = 0.0_wp; hi = 0.0_wp; center = 0.0_wp; radius = 0.0_wp
      velocity = 0.0_wp; amp = 0.0_wp; wavenumber = 0.0_wp; phase = 0.0_wp; stress = 0.0_wp
      call g%get(p(1), material, e)
      call g%get(p(2), geometry, e)
      call g%get(p(3), lo, nlo, e)
      call g%get(p(4), hi, nhi, e)
      call g%get(p(5), center, nc, e)
      call g%get(p(6), radius, e)
      call g%get(p(7), file, e)
      call g%get(p(8), ppc, e)
      if (ov%ppc > 0) ppc = ov%ppc
      call g%get(p(9), placement, e)
      call g%get(p(10), velocity, n, e)
      call g%get(p(11), amp, n, e)
      call g%get(p(12), wavenumber, n, e)
      call g%get(p(13), phase, e)
      call g%get(p(14), stress, n, e)
      if (e%code /= EMPM_OK) return
      cs%body_box = [cs%body_box, geometry == 'box' .or. geometry == 'interval']
      cs%body_lo = reshape([cs%body_lo, lo], [3, nbody])
      cs%body_hi = reshape([cs%body_hi, hi], [3, nbody])
      imat = 0
      do i = 1, size(cs%model%mats)
        if (cs%model%mats(i)%label == material) imat = i
      end do
      if (imat == 0) then
        call g%fail(e, 'material', 'expected the name of a &material group, got '''// &
          material//''' (body '//str(nbody)//')'); return
      end if
      if (geometry /= 'file' .and. g%has('file')) then
        call g%fail(e, 'file', 'used with geometry = ''file'' only (body '//str(nbody)//')')
        return
      end if
      select case (geometry)
      case ('file')
        call read_file_body()
        if (e%code /= EMPM_OK) return
        if (geostatic .and. body%has_stress) then
          call g%fail(e, 'geostatic', 'the file '''//file//''' gives stresses: give them '// &
            'there or use geostatic, not both (body '//str(nbody)//')'); return
        end if
        cs%body_last = [cs%body_last, cs%model%pts%np]
        cycle
      case ('box', 'interval')
        geom = GEOM_BOX
        if (nlo < nd .or. nhi < nd) then
          call g%fail(e, merge('lo', 'hi', nlo < nd), 'required for geometry = ''box'': '// &
            str(nd)//' coordinates each of lo and hi [m] (body '//str(nbody)//')'); return
        end if
        if (any(hi(1:nd) <= lo(1:nd))) then
          call g%fail(e, 'hi', 'expected hi > lo in every direction (body '//str(nbody)//')')
          return
        end if
      case default
        geom = GEOM_DISK
        if (nd < 2) then
          call g%fail(e, 'geometry', '''disk'' needs ndim >= 2; use ''box'' (an interval) in 1D')
          return
        end if
        if (nc < nd .or. .not. g%has('radius')) then
          call g%fail(e, merge('center', 'radius', nc < nd), 'required for geometry = '// &
            '''disk'': a centre ('//str(nd)//' coordinates) and a radius > 0 [m] (body '// &
            str(nbody)//')'); return
        end if
      end select
      place = merge(PLACE_GAUSS, PLACE_VOXEL, placement == 'gauss')
      ! Refuse up front a body set whose particles would not fit in memory.
      nest = nest + estimate_particles(cs%model%grid, geom, lo, hi, center, radius, ppc)
      call check_particle_memory(g, cs, nest, e)
      if (e%code /= EMPM_OK) return
      p0 = cs%model%pts%np
      call empm_fill(cs%model%pts, cs%model%grid, geom, lo, hi, center, radius, ppc, place, &
        cs%model%mats(imat)%model%rho0, imat, nadded, info, err=e, deal=cs%deal)
      if (info == 3) return ! out of memory, in e
      if (nadded == 0) then
        call g%fail(e, '', 'body '//str(nbody)//': the geometry contains no particle '// &
          'position of the grid: check lo/hi or center/radius against &grid'); return
      end if
      do q = p0 + 1, cs%model%pts%np
        associate (x => cs%model%pts%x(:, q))
          cs%model%pts%v(:, q) = velocity(1:nd) + amp(1:nd) * &
            sin(sum(wavenumber(1:nd) * x) + phase)
        end associate
        cs%model%pts%stress(:, q) = stress
      end do
      cs%body_last = [cs%body_last, cs%model%pts%np]
    end do
    at = [nbody, huge(1)]
    if (nbody == 0) call missing_group(path, 'particles', e)

  contains

    !> geometry = 'file': one particle per point of the list or quadrature point of the mesh,
    !> with the group's material; velocity and stress from the file, else from the keys.
    subroutine read_file_body()
      character(len=9), parameter :: SHAPE_KEYS(5) = [character(len=9) :: 'lo', 'hi', &
        'center', 'radius', 'placement']
      character(len=:), allocatable :: full
      real(wp) :: lp(3)
      integer :: j, k, id
      logical :: mine
      if (.not. g%has('file') .or. len_trim(file) == 0) then
        call g%fail(e, 'file', 'required for geometry = ''file'': a point list (.csv, .h5) '// &
          'or a Gmsh mesh (.msh) (body '//str(nbody)//')'); return
      end if
      do j = 1, size(SHAPE_KEYS)
        if (g%has(trim(SHAPE_KEYS(j)))) then
          call g%fail(e, trim(SHAPE_KEYS(j)), 'not used with geometry = ''file'' (body '// &
            str(nbody)//')'); return
        end if
      end do
      full = empm_path_beside(path, file)
      ! Shared, this process keeps the points dealt to it only: those whose ids (the next
      ! ones, in the file's order) are its own.
      call empm_read_body(full, nd, ppc, body, e, keep=[modulo(cs%deal%rank - cs%deal%n, &
        cs%deal%every), cs%deal%every])
      at(2) = merge(e%line, huge(1), e%code /= EMPM_OK)
      if (e%code /= EMPM_OK) then
        ! The file's own location first, then the group that asked for it.
        e%message = e%message//' (&particles body '//str(nbody)//', '//path//':'// &
          str(g%key_line('file'))//')'
        return
      end if
      if (body%has_velocity .and. (g%has('velocity') .or. g%has('velocity_sine_amplitude'))) &
        then
        call g%fail(e, 'velocity', 'the file '''//file//''' gives velocities: give them '// &
          'there or with the velocity keys, not both (body '//str(nbody)//')'); return
      end if
      if (body%has_stress .and. g%has('stress')) then
        call g%fail(e, 'stress', 'the file '''//file//''' gives stresses: give them there '// &
          'or with the stress key, not both (body '//str(nbody)//')'); return
      end if
      k = 0
      do j = 1, body%total
        call cs%deal%next(id, mine)
        if (.not. mine) cycle
        k = k + 1 ! the kept point of this id
        ! uGIMP half-lengths: half the side of the cube (square, segment) of the volume.
        lp = 0.0_wp
        lp(1:nd) = 0.5_wp * body%vol(k)**(1.0_wp / nd)
        call cs%model%pts%append(body%x(:, k), body%vol(k), cs%model%mats(imat)%model%rho0, &
          lp(1:nd), imat, e, id=id)
        if (e%code /= EMPM_OK) return
        q = cs%model%pts%np
        if (body%has_velocity) then
          cs%model%pts%v(:, q) = body%v(:, k)
        else
          cs%model%pts%v(:, q) = velocity(1:nd) + amp(1:nd) * &
            sin(sum(wavenumber(1:nd) * body%x(:, k)) + phase)
        end if
        if (body%has_stress) then
          cs%model%pts%stress(:, q) = body%stress(:, k)
        else
          cs%model%pts%stress(:, q) = stress
        end if
      end do
    end subroutine read_file_body
  end subroutine read_particles

  ! Particles a box or disk/ball body gets at most: the cells its bounding box overlaps (within
  ! the grid) times ppc per direction, times the disk's (π/4) or ball's (π/6) share of its
  ! bounding square or cube. 64-bit: the product exceeds 2^31 for large cases.
  function estimate_particles(grid, geom, lo, hi, center, radius, ppc) result(n)
    use empm_grid, only: empm_grid_t
    type(empm_grid_t), intent(in) :: grid
    integer, intent(in) :: geom, ppc
    real(wp), intent(in) :: lo(3), hi(3), center(3), radius
    integer(int64) :: n
    real(wp) :: a(3), b(3), top(3), cells, share
    integer :: d, nd
    nd = grid%ndim
    top = grid%upper()
    if (geom == GEOM_BOX) then
      a = lo; b = hi; share = 1.0_wp
    else
      a = center - radius; b = center + radius
      share = merge(acos(-1.0_wp) / 4.0_wp, acos(-1.0_wp) / 6.0_wp, nd == 2)
    end if
    cells = 1.0_wp
    do d = 1, nd
      a(d) = max(a(d), grid%origin(d)); b(d) = min(b(d), top(d))
      if (b(d) <= a(d)) then
        n = 0; return
      end if
      cells = cells * min(real(grid%ncell(d), wp), real(ceiling((b(d) - a(d)) / grid%h(d)), wp) &
        + 1.0_wp)
    end do
    n = int(min(share * cells * real(ppc, wp)**nd, 9.0e18_wp), int64)
  end function estimate_particles

  ! The memory `np` particles need with the nodes (estimate): per particle its storage
  ! (positions, velocities, accelerations, reference positions, domain half-lengths and LME
  ! multipliers: 7 ndim values; masses, volumes, densities: 4; stress, strain: 12; F: 9; the
  ! state variables; the material index), the solver's copy of the last good state (as much
  ! again), the shape-function basis (max_nodes node indices, values and ndim gradients) and
  ! scratch; refused (key ppc) when above the machine's physical memory (for a case shared by
  ! place among processes, the shares of the processes on this machine, each with the grid).
  subroutine check_particle_memory(g, cs, np, e)
    type(empm_group_t), intent(in) :: g
    type(empm_case_t), intent(in) :: cs
    integer(int64), intent(in) :: np
    type(empm_error_t), intent(inout) :: e
    integer(int64) :: per, maxn, nnode, bytes, mem, nstate
    integer :: nd, im
    character(len=:), allocatable :: share
    nd = cs%model%grid%ndim
    nstate = 0
    do im = 1, size(cs%model%mats)
      nstate = max(nstate, int(cs%model%mats(im)%model%nstate(), int64))
    end do
    maxn = cs%model%shape%max_nodes(cs%model%grid)
    per = 2_int64 * (8_int64 * (7_int64 * nd + 25_int64 + nstate) + 4_int64) + &
      maxn * (4_int64 + 8_int64 + 8_int64 * nd) + 4_int64 + 8_int64 * (2_int64 * nd + 1_int64)
    nnode = product(int(cs%model%grid%ncell(1:nd), int64) + 1_int64)
    ! Shared by place among processes, each stores its share (cs%deal), and the processes on
    ! this machine share its memory.
    share = ''
    if (cs%deal%every > 1) share = ' (each of the '//str(cs%deal%every)//' processes about '// &
      i64(np / cs%deal%every)//', '//str(cs%local)//' of them on this machine)'
    bytes = cs%local * ((np / cs%deal%every) * per + nnode * (8_int64 + 52_int64 * nd))
    mem = empm_physical_memory()
    if (np > int(huge(1), int64)) then
      call g%fail(e, 'ppc', 'the bodies would have about '//i64(np)// &
        ' particles, more than '//str(huge(1))//' (particle numbers are default integers)')
    else if (mem > 0 .and. bytes > mem) then
      call g%fail(e, 'ppc', 'the bodies would have about '//i64(np)// &
        ' particles'//share//', which with the grid need about '// &
        str_short(real(bytes, wp) / 2.0_wp**30)// &
        ' GiB'//trim(merge(' here', '     ', cs%deal%every > 1))//' ('//i64(bytes)// &
        ' bytes), more than this machine''s '// &
        str_short(real(mem, wp) / 2.0_wp**30)//' GiB ('//i64(mem)//' bytes)')
    end if
  contains
    pure function i64(v) result(t)
      integer(int64), intent(in) :: v
      character(len=:), allocatable :: t
      character(len=24) :: b
      write(b, '(i0)') v
      t = trim(b)
    end function i64
  end subroutine check_particle_memory

  subroutine read_integrator(path, gs, cs, ov, reg, e)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    type(empm_registry_t), intent(in) :: reg
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    character(len=:), allocatable :: scheme
    real(wp) :: cfl, dt, t_end, damping
    integer :: max_steps
    logical :: vsmooth
    if (first(gs, 'integrator') == 0) then
      call missing_group(path, 'integrator', e); return
    end if
    g = gs(first(gs, 'integrator'))
    allocate(p, source=empm_input_group_params('integrator'))
    ! Overrides replace the file's values before validation.
    if (allocated(ov%scheme)) call g%set('scheme', [ov%scheme])
    if (ov%cfl > 0.0_wp) call g%set('cfl', [str(ov%cfl)])
    if (ov%dt > 0.0_wp) call g%set('dt', [str(ov%dt)])
    if (ov%t_end > 0.0_wp) call g%set('t_end', [str(ov%t_end)])
    scheme = 'musl'; cfl = 0.5_wp; dt = 0.0_wp; t_end = 0.0_wp; max_steps = 100000000
    call g%get(p(1), scheme, e)
    call g%get(p(2), t_end, e)
    call g%get(p(3), cfl, e)
    call g%get(p(4), dt, e)
    call g%get(p(5), max_steps, e)
    damping = 0.0_wp
    call g%get(p(6), damping, e)
    vsmooth = .false.
    call g%get(p(7), vsmooth, e)
    if (e%code /= EMPM_OK) return
    if (vsmooth .and. cs%model%grid%ndim < 2) then
      ! In 1D the volumetric strain rate is the whole strain rate: nothing would be left.
      call g%fail(e, 'volumetric_smoothing', 'a 2D or 3D grid'); return
    end if
    ! Exact override values (their text form above is for validation only).
    if (ov%cfl > 0.0_wp) cfl = ov%cfl
    if (ov%dt > 0.0_wp) dt = ov%dt
    if (ov%t_end > 0.0_wp) t_end = ov%t_end
    call reg%create_integrator(scheme, cs%integ, e, g, p)
    if (e%code /= EMPM_OK) return
    cs%scheme_name = cs%integ%name()
    cs%integ%damping = damping
    cs%integ%vol_smooth = vsmooth
    cs%run%t_end = t_end; cs%run%cfl = cfl; cs%run%dt = dt; cs%run%max_steps = max_steps
  end subroutine read_integrator

  subroutine read_loads(gs, cs, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    real(wp) :: gravity(3), ramp_time
    character(len=:), allocatable :: ramp
    integer :: n, nd
    allocate(p, source=empm_input_group_params('loads'))
    call group_or_empty(cs%file, gs, 'loads', g)
    call g%check_keys(p, e)
    gravity = 0.0_wp; ramp = 'none'; ramp_time = 0.0_wp
    call g%get(p(1), gravity, n, e)
    call g%get(p(2), ramp, e)
    call g%get(p(3), ramp_time, e)
    if (e%code /= EMPM_OK) return
    nd = cs%model%grid%ndim
    cs%model%loads%gravity = 0.0_wp
    cs%model%loads%gravity(1:nd) = gravity(1:nd)
    if (ramp == 'sine') then
      cs%model%loads%ramp = RAMP_SINE
      if (.not. g%has('ramp_time')) then
        call g%fail(e, 'ramp_time', 'required with ramp = ''sine'': period T [s] > 0 of '// &
          'eq. (46)'); return
      end if
      cs%model%loads%t_ramp = ramp_time
    else
      cs%model%loads%ramp = RAMP_NONE
    end if
  end subroutine read_loads

  subroutine read_boundaries(gs, cs, fields, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    logical, intent(in) :: fields
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    real(wp) :: lo(3), hi(3), velocity(3), gv(9), grad(3, 3)
    logical :: fix(3)
    integer :: nb, nsel, nd, k, nlo, nhi, n, ng, i
    character(len=:), allocatable :: name, mirror
    allocate(p, source=empm_input_group_params('boundary'))
    nd = cs%model%grid%ndim
    call cs%model%nodes%alloc(cs%model%grid, fields=fields)
    nb = 0
    do k = 1, size(gs)
      if (gs(k)%name /= 'boundary') cycle
      g = gs(k)
      nb = nb + 1
      call g%check_keys(p, e)
      lo = 0.0_wp; hi = 0.0_wp; fix = .false.; velocity = 0.0_wp
      call g%get(p(1), lo, nlo, e)
      call g%get(p(2), hi, nhi, e)
      call g%get(p(3), fix, n, e)
      call g%get(p(4), velocity, n, e)
      name = ''
      call g%get(p(5), name, e)
      mirror = 'none'
      call g%get(p(6), mirror, e)
      if (e%code /= EMPM_OK) return
      if (g%has('name')) then
        if (.not. valid_name(name)) then
          call g%fail(e, 'name', 'expected letters, digits, ''_'', ''.'' or ''-'' (at most '// &
            '64), got '''//name//''''); return
        end if
        if (any(cs%model%nodes%set_name(1:cs%model%nodes%nset) == name)) then
          call g%fail(e, 'name', 'duplicate boundary name '''//name//''''); return
        end if
      end if
      if (nlo < nd .or. nhi < nd) then
        call g%fail(e, merge('lo', 'hi', nlo < nd), 'required: the box selecting the nodes, '// &
          str(nd)//' coordinates each of lo and hi [m] (boundary '//str(nb)//')'); return
      end if
      if (g%has('friction_angle') .or. g%has('normal')) then
        call read_wall(g, p, cs, lo, hi, name, nb, e)
        if (e%code /= EMPM_OK) return
        cycle
      end if
      if (.not. any(fix(1:nd))) then
        call g%fail(e, 'fix', 'expected at least one .true. component (boundary '//str(nb)//')')
        return
      end if
      if (g%has('velocity_gradient')) then
        gv = 0.0_wp
        call g%get(p(9), gv, ng, e)
        if (e%code /= EMPM_OK) return
        if (ng /= nd * nd) then
          call g%fail(e, 'velocity_gradient', 'expected ndim x ndim = '//str(nd * nd)// &
            ' values, row by row, got '//str(ng)//' (boundary '//str(nb)//')'); return
        end if
        if (mirror /= 'none' .or. g%has('name')) then
          call g%fail(e, 'velocity_gradient', 'not with '//trim(merge('mirror', 'name  ', &
            mirror /= 'none'))//': a kinematic driver is neither a mirror plane nor a '// &
            'reaction set (boundary '//str(nb)//')'); return
        end if
        grad = 0.0_wp
        do i = 1, nd
          grad(i, 1:nd) = gv((i - 1) * nd + 1:i * nd)
        end do
        call cs%model%nodes%fix_box(cs%model%grid, lo, hi, fix, velocity, nsel, gradient=grad)
        if (nsel == 0) then
          call g%fail(e, 'lo', 'the box [lo, hi] selects no grid node (boundary '//str(nb)// &
            '): nodes lie at origin + i*h'); return
        end if
        cycle
      end if
      if (mirror /= 'none') then
        call read_mirror(g, cs, lo, hi, fix, velocity, trim(mirror), nb, e)
        if (e%code /= EMPM_OK) return
        cycle
      end if
      if (g%has('name')) then
        call cs%model%nodes%fix_box(cs%model%grid, lo, hi, fix, velocity, nsel, name)
      else
        call cs%model%nodes%fix_box(cs%model%grid, lo, hi, fix, velocity, nsel)
      end if
      if (nsel == 0) then
        call g%fail(e, 'lo', 'the box [lo, hi] selects no grid node (boundary '//str(nb)// &
          '): nodes lie at origin + i*h'); return
      end if
    end do
  end subroutine read_boundaries

  ! A frictional wall (`friction_angle`, `normal`): checks, then the wall's nodes.
  subroutine read_wall(g, p, cs, lo, hi, name, nb, e)
    type(empm_group_t), intent(inout) :: g
    type(empm_param_t), intent(in) :: p(:)
    type(empm_case_t), intent(inout) :: cs
    real(wp), intent(in) :: lo(3), hi(3)
    character(len=*), intent(in) :: name
    integer, intent(in) :: nb
    type(empm_error_t), intent(inout) :: e
    real(wp), parameter :: DEG = acos(-1.0_wp) / 180.0_wp
    character(len=:), allocatable :: normal
    character(len=*), parameter :: KEYS(4) = [character(len=17) :: 'fix', 'velocity', 'mirror', &
      'velocity_gradient']
    real(wp) :: delta
    integer :: a, side, k, nsel, info
    if (.not. g%has('friction_angle') .or. .not. g%has('normal')) then
      call g%fail(e, trim(merge('normal        ', 'friction_angle', g%has('friction_angle'))), &
        'a frictional wall needs both friction_angle and normal (boundary '//str(nb)//')')
      return
    end if
    do k = 1, size(KEYS)
      if (g%has(trim(KEYS(k)))) then
        call g%fail(e, trim(KEYS(k)), 'not with friction_angle: a frictional wall is at '// &
          'rest and fixes its normal component itself (boundary '//str(nb)//')'); return
      end if
    end do
    delta = 0.0_wp; normal = ''
    call g%get(p(7), delta, e)
    call g%get(p(8), normal, e)
    if (e%code /= EMPM_OK) return
    a = index('xyz', normal(2:2)); side = merge(-a, a, normal(1:1) == '-')
    if (a > cs%model%grid%ndim) then
      call g%fail(e, 'normal', 'axis '''//normal(2:2)//''' beyond ndim = '// &
        str(cs%model%grid%ndim)//' (boundary '//str(nb)//')'); return
    end if
    if (.not. cs%integ%walls()) then
      call g%fail(e, 'friction_angle', 'scheme '''//cs%integ%family()//''' does not '// &
        'support frictional walls ('//WALL_SCHEMES//' do) (boundary '//str(nb)//')'); return
    end if
    if (g%has('name')) then
      call cs%model%nodes%friction_box(cs%model%grid, lo, hi, side, tan(delta * DEG), nsel, &
                                       info, name)
    else
      call cs%model%nodes%friction_box(cs%model%grid, lo, hi, side, tan(delta * DEG), nsel, info)
    end if
    if (info /= 0) call g%fail(e, 'lo', empm_wall_problem(info, a)//' (boundary '//str(nb)//')')
  end subroutine read_wall

  ! A mirror-plane boundary (`mirror = '-x'` ...): checks, the plane and its ghosts, and no
  ! particle on the ghost side.
  subroutine read_mirror(g, cs, lo, hi, fix, velocity, mirror, nb, e)
    type(empm_group_t), intent(inout) :: g
    type(empm_case_t), intent(inout) :: cs
    real(wp), intent(in) :: lo(3), hi(3), velocity(3)
    logical, intent(in) :: fix(3)
    character(len=*), intent(in) :: mirror
    integer, intent(in) :: nb
    type(empm_error_t), intent(inout) :: e
    integer :: a, side, nsel, info, p, np, bad
    real(wp) :: plane, tol
    a = index('xyz', mirror(2:2)); side = merge(-a, a, mirror(1:1) == '-')
    if (a > cs%model%grid%ndim) then
      call g%fail(e, 'mirror', 'axis '''//mirror(2:2)//''' beyond ndim = '// &
        str(cs%model%grid%ndim)); return
    end if
    if (any(fix .and. velocity /= 0.0_wp)) then
      call g%fail(e, 'velocity', 'a mirror plane is at rest: the fixed components must be 0 '// &
        '(boundary '//str(nb)//')'); return
    end if
    if (g%has('name')) then
      call g%fail(e, 'name', 'reaction sets are not recorded on mirror planes (boundary '// &
        str(nb)//')'); return
    end if
    call cs%model%nodes%mirror_box(cs%model%grid, lo, hi, side, fix, nsel, info)
    select case (info)
    case (1)
      call g%fail(e, 'lo', 'a mirror box must be flat along '//mirror(2:2)//' (lo = hi) and '// &
        'on a grid line (nodes lie at origin + i*h) (boundary '//str(nb)//')'); return
    case (2)
      call g%fail(e, 'lo', 'the box [lo, hi] selects no grid node (boundary '//str(nb)//')')
      return
    case (3)
      call g%fail(e, 'mirror', 'a ghost node on the '//mirror//' side is fixed by another '// &
        '&boundary or is already a ghost (boundary '//str(nb)//')'); return
    case (4)
      call g%fail(e, 'mirror', 'no ghost node: the grid must continue past the plane on the '// &
        mirror//' side, by the shape functions'' reach (boundary '//str(nb)//')'); return
    end select
    ! The ghost side must hold no particle (the mirror stands for the body's image there).
    plane = lo(a); tol = 1.0e-9_wp * cs%model%grid%h(a)
    ! The first such particle (lowest id, over every process when the set is dealt out).
    np = cs%model%pts%np
    bad = huge(1)
    do p = 1, np
      if (sign(1.0_wp, real(side, wp)) * (cs%model%pts%x(a, p) - plane) > tol) then
        bad = cs%model%pts%id(p); exit
      end if
    end do
    bad = cs%model%comm%min_int(bad)
    if (bad < huge(1)) then
      call g%fail(e, 'mirror', 'particle '//str(bad)//' lies on the ghost side '//mirror// &
        ' of the plane at '//str_short(plane)//' m (boundary '//str(nb)//')'); return
    end if
  end subroutine read_mirror

  !> A name that can be an HDF5 group: 1..64 of NAME_CHARS, not '.' or '..'.
  pure logical function valid_name(name)
    character(len=*), intent(in) :: name
    valid_name = verify(name, NAME_CHARS) == 0 .and. len(name) > 0 .and. len(name) <= 64 &
      .and. name /= '.' .and. name /= '..'
  end function valid_name

  !> Geostatic bodies: their particles' stress from the overburden under the final gravity
  !> ([[empm_geostatic_stress]]), once &particles and &loads are read.
  subroutine apply_geostatic(gs, cs, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    type(empm_group_t) :: g
    integer :: b, i0, i1, info, nd, a
    real(wp) :: surf
    nd = cs%model%grid%ndim
    do b = 1, size(cs%body_k0)
      if (cs%body_k0(b) < 0.0_wp) cycle
      g = gs(cs%body_group(b))
      i0 = cs%body_first(b); i1 = cs%body_last(b)
      associate (pts => cs%model%pts, grid => cs%model%grid, gv => cs%model%loads%gravity)
        if (cs%body_box(b) .and. count(gv(1:nd) /= 0.0_wp) == 1) then
          ! A box's top is known: its upper (lower, for g > 0) side along g.
          a = findloc(gv(1:nd) /= 0.0_wp, .true., dim=1)
          surf = merge(cs%body_hi(a, b), -cs%body_lo(a, b), gv(a) < 0.0_wp)
          call empm_geostatic_stress(nd, grid%origin, grid%h, pts%x(:, i0:i1), &
            pts%lp(:, i0:i1), pts%rho(i0:i1), gv, cs%body_k0(b), pts%stress(:, i0:i1), info, &
            surface=surf, comm=cs%model%comm)
        else
          ! Dealt out among processes (cs%deal), the columns' tops are agreed.
          call empm_geostatic_stress(nd, grid%origin, grid%h, pts%x(:, i0:i1), &
            pts%lp(:, i0:i1), pts%rho(i0:i1), gv, cs%body_k0(b), pts%stress(:, i0:i1), info, &
            comm=cs%model%comm)
        end if
      end associate
      if (info == 1) then
        call g%fail(e, 'geostatic', 'needs a non-zero &loads gravity along one grid axis '// &
          '(the vertical) (body '//str(b)//')'); return
      else if (info /= 0) then
        call g%fail(e, 'geostatic', 'the body spans more than 1e8 grid columns (body '// &
          str(b)//')'); return
      end if
    end do
  end subroutine apply_geostatic

  !> &traction groups: the particles of the body (or of every body) inside the box, their face
  !> areas, the traction vector and its ramp.
  subroutine read_tractions(gs, cs, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    type(empm_traction_t), allocatable :: trs(:)
    character(len=:), allocatable :: name, body, face, ramp
    real(wp) :: lo(3), hi(3), pressure, trac(3), ramp_time, tol, plane
    integer :: k, nt, nd, nlo, nhi, n, ib, i0, i1, q, ax, d, cnt, bad, badid
    character(len=:), allocatable :: text
    allocate(p, source=empm_input_group_params('traction'))
    nd = cs%model%grid%ndim
    tol = 1.0e-9_wp * cs%model%grid%hmin()
    allocate(trs(0))
    nt = 0
    do k = 1, size(gs)
      if (gs(k)%name /= 'traction') cycle
      g = gs(k)
      nt = nt + 1
      call g%check_keys(p, e)
      name = ''; body = ''; face = ''; ramp = 'none'
      lo = 0.0_wp; hi = 0.0_wp; pressure = 0.0_wp; trac = 0.0_wp; ramp_time = 0.0_wp
      call g%get(p(1), name, e)
      call g%get(p(2), body, e)
      call g%get(p(3), lo, nlo, e)
      call g%get(p(4), hi, nhi, e)
      call g%get(p(5), face, e)
      call g%get(p(6), pressure, e)
      call g%get(p(7), trac, n, e)
      call g%get(p(8), ramp, e)
      call g%get(p(9), ramp_time, e)
      if (e%code /= EMPM_OK) return
      if (.not. g%has('name')) name = 'traction '//str(nt)
      if (nlo < nd .or. nhi < nd) then
        call g%fail(e, merge('lo', 'hi', nlo < nd), 'required: the box selecting the loaded '// &
          'particles, '//str(nd)//' coordinates each of lo and hi [m] ('//name//')'); return
      end if
      if (.not. g%has('face')) then
        call g%fail(e, 'face', 'required: the outward normal of the loaded face, one of '// &
          '+x -x +y -y +z -z ('//name//')'); return
      end if
      ax = index('xyz', face(2:2))
      if (ax > nd) then
        call g%fail(e, 'face', 'expected an axis of the '//str(nd)//'D grid, got '''//face// &
          ''' ('//name//')'); return
      end if
      if (g%has('pressure') .eqv. g%has('traction')) then
        call g%fail(e, 'pressure', 'give exactly one of pressure and traction ('//name//')')
        return
      end if
      if (ramp /= 'none' .and. .not. g%has('ramp_time')) then
        call g%fail(e, 'ramp_time', 'required with ramp = '''//ramp//''': the ramp time [s] '// &
          '> 0 ('//name//')'); return
      end if
      ib = 0
      if (g%has('body')) then
        do q = 1, size(cs%body_name)
          if (trim(cs%body_name(q)) == body) ib = q
        end do
        if (ib == 0 .or. len(body) == 0) then
          call g%fail(e, 'body', 'expected the name of a &particles group, got '''//body// &
            ''' ('//name//')'); return
        end if
      end if
      trs = [trs, empm_traction_t()]
      associate (tr => trs(nt))
        tr%name = name; tr%axis = ax; tr%side = merge(1, -1, face(1:1) == '+')
        tr%traction = 0.0_wp
        if (g%has('pressure')) then
          tr%traction(ax) = -pressure * tr%side
        else
          tr%traction(1:nd) = trac(1:nd)
        end if
        select case (ramp)
        case ('linear'); tr%ramp = RAMP_LINEAR
        case ('sine'); tr%ramp = RAMP_SINE
        case default; tr%ramp = RAMP_NONE
        end select
        tr%t_ramp = ramp_time
        i0 = 1; i1 = cs%model%pts%np
        if (ib > 0) then
          i0 = cs%body_first(ib); i1 = cs%body_last(ib)
        end if
        ! The particles in the box (this process's, when the set is dealt out: cs%deal).
        associate (x => cs%model%pts%x, pts => cs%model%pts)
          cnt = 0
          do q = i0, i1
            if (all(x(1:nd, q) >= lo(1:nd) - tol .and. x(1:nd, q) <= hi(1:nd) + tol)) cnt = cnt + 1
          end do
          if (cs%model%comm%sum_int(cnt) == 0) then
            call g%fail(e, 'lo', 'the box [lo, hi] selects no particle ('//name//')'); return
          end if
          allocate(tr%part(cnt), tr%area(cnt), tr%offset(cnt))
          ! The loaded plane is the box's outer side; every particle must lie within its own
          ! size 2 lp of it (the outer layer only). The first one that does not (lowest id) is
          ! reported.
          plane = merge(hi(ax), lo(ax), tr%side > 0)
          cnt = 0; bad = 0
          do q = i0, i1
            if (all(x(1:nd, q) >= lo(1:nd) - tol .and. x(1:nd, q) <= hi(1:nd) + tol)) then
              cnt = cnt + 1; tr%part(cnt) = q
              tr%offset(cnt) = max(tr%side * (plane - x(ax, q)), 0.0_wp)
              if (tr%offset(cnt) > 2.0_wp * pts%lp(ax, q) + tol .and. bad == 0) bad = cnt
              ! Face area: the domain's side lengths across the normal (per unit thickness).
              tr%area(cnt) = 1.0_wp
              do d = 1, nd
                if (d /= ax) tr%area(cnt) = tr%area(cnt) * 2.0_wp * pts%lp(d, q)
              end do
            end if
          end do
          badid = huge(1)
          if (bad > 0) badid = pts%id(tr%part(bad))
          badid = cs%model%comm%min_int(badid)
          if (badid < huge(1)) then
            if (bad > 0) then
              if (pts%id(tr%part(bad)) == badid) then
                text = 'particle '//str(badid)//' lies '//str(tr%offset(bad))// &
                  ' m inside the loaded face (the box''s '// &
                  merge('upper', 'lower', tr%side > 0)//' side along '//face(2:2)// &
                  '), more than its size '//str(2.0_wp * pts%lp(ax, tr%part(bad)))// &
                  ': the box must select the outer layer of particles only ('//name//')'
              end if
            end if
            call cs%model%comm%bcast_text(text, mod(badid - 1, cs%deal%every))
            call g%fail(e, merge('lo', 'hi', tr%side > 0), text); return
          end if
          if (cs%deal%every > 1) call empm_list_loaded(cs%model, tr)
        end associate
      end associate
    end do
    call move_alloc(trs, cs%model%loads%tractions)
  end subroutine read_tractions

  subroutine read_probes(gs, cs, e)
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    character(len=:), allocatable :: name
    integer :: particle, n, nd, q, k, npt, i
    real(wp) :: point(3), dmin
    real(wp), allocatable :: dist(:)
    character(len=64), allocatable :: names(:)
    integer, allocatable :: parts(:)
    allocate(p, source=empm_input_group_params('probe'))
    nd = cs%model%grid%ndim
    allocate(names(0), parts(0))
    n = 0
    do k = 1, size(gs)
      if (gs(k)%name /= 'probe') cycle
      g = gs(k)
      n = n + 1
      call g%check_keys(p, e)
      name = ''; particle = 0; point = 0.0_wp
      call g%get(p(1), name, e)
      call g%get(p(2), particle, e)
      call g%get(p(3), point, npt, e)
      if (e%code /= EMPM_OK) return
      if (len(name) > 64) then
        call g%fail(e, 'name', 'expected at most 64 characters, got '''//name//''''); return
      end if
      if (any(names == name)) then
        call g%fail(e, 'name', 'duplicate probe name '''//name//''''); return
      end if
      ! The name becomes an HDF5 group: a '/' would make it a path.
      if (.not. valid_name(name)) then
        call g%fail(e, 'name', 'expected letters, digits, ''_'', ''.'' or ''-'', got '''// &
          name//''''); return
      end if
      if (g%has('particle') .eqv. g%has('point')) then
        call g%fail(e, 'particle', 'give exactly one of particle (index) or point '// &
          '(coordinates) for probe '''//name//''''); return
      end if
      ! Particles by id (generation order; cs%deal%n of them, on every process together).
      if (g%has('particle')) then
        if (particle > cs%deal%n) then
          call g%fail(e, 'particle', 'expected 1..'//str(cs%deal%n)//', got '// &
            str(particle)); return
        end if
        q = particle
      else
        if (npt < nd) then
          call g%fail(e, 'point', 'expected '//str(nd)//' coordinates'); return
        end if
        ! A point probe follows the material point nearest to it at t = 0 (the lowest id of
        ! the nearest).
        associate (pts => cs%model%pts, comm => cs%model%comm)
          dist = sum((pts%x(:, 1:pts%np) - spread(point(1:nd), 2, pts%np))**2, dim=1)
          dmin = comm%min_real(minval(dist)) ! huge on a process without particles
          q = huge(1)
          if (pts%np > 0) then
            i = minloc(dist, dim=1)
            if (dist(i) == dmin) q = pts%id(i)
          end if
          q = comm%min_int(q)
        end associate
      end if
      names = [character(len=64) :: names, name]; parts = [parts, q]
    end do
    call move_alloc(names, cs%probe_name); call move_alloc(parts, cs%probe_particle)
  end subroutine read_probes

  subroutine read_output(path, gs, cs, e)
    character(len=*), intent(in) :: path
    type(empm_group_t), intent(in) :: gs(:)
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    type(empm_param_t), allocatable :: p(:)
    type(empm_group_t) :: g
    character(len=:), allocatable :: file
    integer :: history_every, n, i, ckpt_every
    real(wp) :: snapshot_times(MAXSNAP), ckpt_seconds
    allocate(p, source=empm_input_group_params('output'))
    call group_or_empty(path, gs, 'output', g)
    call g%check_keys(p, e)
    file = ''; history_every = 1; snapshot_times = 0.0_wp
    call g%get(p(1), file, e)
    call g%get(p(2), history_every, e)
    call g%get(p(3), snapshot_times, n, e)
    ckpt_every = 0; ckpt_seconds = 0.0_wp
    call g%get(p(4), ckpt_every, e)
    call g%get(p(5), ckpt_seconds, e)
    if (e%code /= EMPM_OK) return
    cs%run%checkpoint_every = ckpt_every
    cs%run%checkpoint_seconds = ckpt_seconds
    do i = 1, n
      if (snapshot_times(i) > cs%run%t_end .or. &
          (i > 1 .and. snapshot_times(max(i - 1, 1)) >= snapshot_times(i))) then
        call g%fail(e, 'snapshot_times', 'expected increasing times in [0, t_end], got '// &
          str(snapshot_times(i))//' at index '//str(i)); return
      end if
    end do
    cs%run%snapshot_times = snapshot_times(1:n)
    cs%run%history_every = history_every
    if (len_trim(file) > 0) then
      cs%output_file = trim(file)
    else
      cs%output_file = default_output(path)
    end if
  end subroutine read_output

  !> `dir/name.nml` -> `name.h5` in the working directory.
  pure function default_output(path) result(out)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: out
    integer :: s, d
    s = index(path, '/', back=.true.)
    d = index(path, '.', back=.true.)
    if (d <= s) d = len(path) + 1
    out = path(s + 1:d - 1)//'.h5'
  end function default_output

  !> Evaluate the shape functions once at the particles a process holds, after a case read
  !> with `shared` has been shared among the processes (`empm_partition_particles`): what
  !> [[empm_read_case]] does for a serial run. A particle whose support does not fit the grid
  !> is an input error (exit 2), reported before any step is taken; under several processes
  !> every process reports the serial run's error, that of the particle with the smallest id.
  !> Collective.
  subroutine empm_check_basis(path, cs, err)
    character(len=*), intent(in) :: path                !! case file (for the message)
    type(empm_case_t), intent(inout) :: cs              !! the case, shared
    type(empm_error_t), intent(out), optional :: err    !! error, if present
    type(empm_error_t) :: e
    integer :: first
    call check_basis(path, cs, e)
    first = cs%model%comm%min_int(merge(e%particle, huge(1), e%code /= EMPM_OK))
    if (first == huge(1)) then
      e = empm_error_t()
    else if (e%particle /= first) then
      e = empm_error_t() ! another process holds the particle the serial run names
    end if
    call empm_raise_error(e, err)
  end subroutine empm_check_basis

  ! Evaluate the shape functions once (the basis storage allocated): a particle whose support
  ! does not fit the grid is an input error, reported before any step is taken.
  subroutine check_basis(path, cs, e)
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    type(empm_error_t), intent(inout) :: e
    integer :: ibad, info, d
    character(len=:), allocatable :: xs
    call cs%model%shape%eval_batch(cs%model%grid, cs%model%pts, cs%model%basis, ibad, info)
    if (info /= 0) then
      xs = ''
      if (ibad >= 1 .and. ibad <= cs%model%pts%np) then
        do d = 1, cs%model%grid%ndim
          xs = xs//merge(' (', ', ', d == 1)//str(cs%model%pts%x(d, ibad))
        end do
        xs = ' at x ='//xs//')'
      end if
      ! Named by its id (its number in generation order, whatever process holds it).
      if (ibad >= 1 .and. ibad <= cs%model%pts%np) ibad = cs%model%pts%id(ibad)
      call e%set(EMPM_ERR_INPUT, 'groups &grid/&particles/&shape are inconsistent: at '// &
        'particle '//str(ibad)//xs//' the '//cs%shape_name//' shape functions fail: '// &
        shape_status_text(info), file=path, particle=ibad)
    end if
  end subroutine check_basis
end module empm_input
