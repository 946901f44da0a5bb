!> Reads and validates a case file (Fortran namelist groups, one per concern) into an
!> [[empm_case_t]]. Every key is documented in docs/input.md.
!>
!> Validation is strict: an unknown group or key, a missing required key, a value out of range
!> or an inconsistent combination gives an error with code EMPM_ERR_INPUT (exit status 2)
!> naming the file, the group, the key and what was expected.
module empm_input
  use, intrinsic :: iso_fortran_env, only: iostat_end
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_raise, EMPM_ERR_INPUT
  use empm_strings, only: str, lower
  use empm_case, only: empm_case_t, empm_overrides_t
  use empm_model, only: empm_material_slot_t
  use empm_loads, only: RAMP_NONE, RAMP_SINE
  use empm_particle_gen, only: empm_fill, GEOM_BOX, GEOM_DISK, PLACE_GAUSS, PLACE_VOXEL
  use empm_shape, only: shape_status_text
  use empm_shape_factory, only: empm_shape_create, empm_shape_names, SHAPE_CREATE_BAD_PARAM
  use empm_shape_lme, only: empm_shape_lme_t, LME_REMEDY_NONE, LME_REMEDY_ENLARGE
  use empm_material_factory, only: empm_material_create, material_status_text, MAT_UNKNOWN_NAME
  use empm_integrator_factory, only: empm_integrator_create, empm_integrator_names
  implicit none
  private
  public :: empm_read_case

  real(wp), parameter :: UNSET = -huge(1.0_wp)  ! sentinel for required reals
  integer, parameter :: IUNSET = -huge(1)       ! sentinel for required integers
  integer, parameter :: MAXSNAP = 1000          ! capacity of output%snapshot_times
  character(len=*), parameter :: GROUPS = 'grid material particles shape integrator loads '// &
                                          'boundary probe output verify'

contains

  !> Read, validate and set up the case in `path`. On error, `err` (or a stop with status 2)
  !> names the file, group and key.
  subroutine empm_read_case(path, cs, err, overrides)
    character(len=*), intent(in) :: path               !! case file
    type(empm_case_t), intent(inout) :: cs             !! the case, ready to run
    type(empm_error_t), intent(out), optional :: err   !! error, if present
    type(empm_overrides_t), intent(in), optional :: overrides !! changes to the file's values
    type(empm_overrides_t) :: ov
    integer :: u, ios
    character(len=512) :: msg
    character(len=:), allocatable :: emsg

    if (present(overrides)) ov = overrides
    cs%file = path
    open(newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call empm_raise(EMPM_ERR_INPUT, path//': cannot open case file: '//trim(msg), err); return
    end if
    emsg = ''
    call slurp(u, cs%text)
    call check_groups(path, cs%text, emsg)
    if (len(emsg) == 0) call read_grid(u, path, cs, ov, emsg)
    if (len(emsg) == 0) call read_materials(u, path, cs, emsg)
    if (len(emsg) == 0) call read_shape(u, path, cs, ov, emsg)
    if (len(emsg) == 0) call read_particles(u, path, cs, emsg)
    if (len(emsg) == 0) call read_integrator(u, path, cs, ov, emsg)
    if (len(emsg) == 0) call read_loads(u, path, cs, emsg)
    if (len(emsg) == 0) call read_boundaries(u, path, cs, emsg)
    if (len(emsg) == 0) call read_probes(u, path, cs, emsg)
    if (len(emsg) == 0) call read_output(u, path, cs, emsg)
    close(u)
    if (len(emsg) == 0) call check_initial_basis(path, cs, emsg)
    if (len(emsg) > 0) call empm_raise(EMPM_ERR_INPUT, emsg, err)
  end subroutine empm_read_case

  ! ---- helpers ----------------------------------------------------------------------------

  subroutine slurp(u, text)
    integer, intent(in) :: u
    character(len=:), allocatable, intent(out) :: text
    character(len=1024) :: line
    integer :: ios
    text = ''
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      text = text//trim(line)//new_line('a')
    end do
    rewind(u)
  end subroutine slurp

  !> Valid keys of a group, space-separated ('' for an unknown group).
  pure function group_keys(group) result(keys)
    character(len=*), intent(in) :: group
    character(len=:), allocatable :: keys
    select case (group)
    case ('grid'); keys = 'ndim origin h cells'
    case ('material'); keys = 'name model e nu density'
    case ('particles'); keys = 'material geometry lo hi center radius ppc placement velocity '// &
      'velocity_sine_amplitude velocity_sine_wavenumber velocity_sine_phase stress'
    case ('shape'); keys = 'family gamma tol0 remedy gamma_inside gamma_box_lo gamma_box_hi'
    case ('integrator'); keys = 'scheme cfl dt t_end max_steps newmark_gamma rho_b'
    case ('loads'); keys = 'gravity ramp ramp_time'
    case ('boundary'); keys = 'lo hi fix velocity'
    case ('probe'); keys = 'name particle point'
    case ('output'); keys = 'file history_every snapshot_times'
    case ('verify'); keys = 'benchmark study shapes schemes levels cfls metrics thresholds '// &
      'min_order max_order expect_fail quick_levels quick'
    case default; keys = ''
    end select
  end function group_keys

  !> Scan the file before the namelist reads: every `&group` must be known, and every `key =`
  !> inside it must be one of the group's keys. (The namelist reader would skip unknown groups,
  !> and may report an unknown key as a bad value of the previous array key.)
  subroutine check_groups(path, text, emsg)
    character(len=*), intent(in) :: path, text
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: IDCHARS = 'abcdefghijklmnopqrstuvwxyz_0123456789'
    integer :: i, j, k, lineno, n
    character(len=:), allocatable :: group, keys, key
    character(len=1) :: c, quote
    n = len(text)
    lineno = 1; group = ''; quote = ' '
    i = 1
    do while (i <= n)
      c = text(i:i)
      if (c == new_line('a')) lineno = lineno + 1
      if (quote /= ' ') then
        if (c == quote) quote = ' '
      else if (c == '''' .or. c == '"') then
        quote = c
      else if (c == '!') then
        do while (i < n)
          if (text(i + 1:i + 1) == new_line('a')) exit
          i = i + 1
        end do
      else if (c == '&') then
        j = i + 1
        do while (j <= n)
          if (index(IDCHARS, lower(text(j:j))) == 0) exit
          j = j + 1
        end do
        group = lower(text(i + 1:j - 1))
        if (len(group) > 0) then
          if (len(group_keys(group)) == 0) then
            emsg = path//':'//str(lineno)//': unknown group &'//group//'; expected one of: '// &
              GROUPS
            return
          end if
        end if
        i = j - 1
      else if (c == '/' .and. len(group) > 0) then
        group = ''
      else if (len(group) > 0 .and. index(IDCHARS, lower(c)) > 0 .and. &
               index('0123456789', c) == 0) then
        ! An identifier inside a group: a key if followed by '=' (optionally after "(...)").
        j = i
        do while (j <= n)
          if (index(IDCHARS, lower(text(j:j))) == 0) exit
          j = j + 1
        end do
        key = lower(text(i:j - 1))
        k = skip_blanks(j)
        if (k <= n) then
          if (text(k:k) == '(') k = skip_blanks(index(text(k:), ')') + k)
        end if
        if (k <= n) then
          if (text(k:k) == '=') then
            keys = group_keys(group)
            if (index(' '//keys//' ', ' '//key//' ') == 0) then
              emsg = path//':'//str(lineno)//': group &'//group//': unknown key '''//key// &
                '''; valid keys: '//keys
              return
            end if
          end if
        end if
        i = j - 1
      end if
      i = i + 1
    end do
  contains
    pure integer function skip_blanks(from) result(pos)
      integer, intent(in) :: from
      pos = from
      do while (pos <= n)
        if (text(pos:pos) /= ' ') exit
        pos = pos + 1
      end do
    end function skip_blanks
  end subroutine check_groups

  !> Message for a failed namelist read (unknown key or malformed value).
  function nml_error(path, group, keys, msg) result(e)
    character(len=*), intent(in) :: path, group, keys, msg
    character(len=:), allocatable :: e
    e = path//': group &'//group//': '//trim(msg)//' (valid keys: '//keys//')'
  end function nml_error

  function req(path, group, key, what) result(e)
    character(len=*), intent(in) :: path, group, key, what
    character(len=:), allocatable :: e
    e = path//': group &'//group//': key '''//key//''': '//what
  end function req

  ! ---- groups -----------------------------------------------------------------------------

  subroutine read_grid(u, path, cs, ov, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'ndim, origin, h, cells'
    integer :: ndim, cells(3), ios, info
    real(wp) :: origin(3), h(3)
    character(len=512) :: msg
    namelist /grid/ ndim, origin, h, cells
    ndim = IUNSET; origin = 0.0_wp; h = UNSET; cells = IUNSET
    rewind(u)
    read(u, nml=grid, iostat=ios, iomsg=msg)
    if (ios == iostat_end) then
      emsg = path//': missing required group &grid (keys: '//K//')'; return
    else if (ios /= 0) then
      emsg = nml_error(path, 'grid', K, msg); return
    end if
    if (ndim == IUNSET) then
      emsg = req(path, 'grid', 'ndim', 'required: spatial dimension 1, 2 or 3'); return
    else if (ndim < 1 .or. ndim > 3) then
      emsg = req(path, 'grid', 'ndim', 'expected 1, 2 or 3, got '//str(ndim)); return
    end if
    if (h(1) == UNSET) then
      emsg = req(path, 'grid', 'h', 'required: cell size [m] (one value or one per direction)')
      return
    end if
    where (h(2:3) == UNSET) h(2:3) = h(1)
    if (any(h(1:ndim) <= 0.0_wp)) then
      emsg = req(path, 'grid', 'h', 'expected positive cell sizes, got '//str(minval(h(1:ndim))))
      return
    end if
    if (any(cells(1:ndim) == IUNSET)) then
      emsg = req(path, 'grid', 'cells', 'required: '//str(ndim)//' cell counts'); return
    end if
    if (any(cells(1:ndim) < 1)) then
      emsg = req(path, 'grid', 'cells', 'expected cell counts >= 1'); return
    end if
    h = h / ov%refine; cells = cells * ov%refine
    call cs%model%grid%init(ndim, origin, h, cells, info)
    if (info /= 0) then
      ! Not reachable after the checks above; kept so that no grid error passes silently.
      emsg = path//': group &grid: invalid grid (grid_init status '//str(info)//')'; return
    end if
    call cs%model%pts%alloc(ndim, 1024)
  end subroutine read_grid

  subroutine read_materials(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'name, model, E, nu, density'
    character(len=64) :: name, model
    real(wp) :: E, nu, density
    integer :: ios, info, n, i
    character(len=512) :: msg
    type(empm_material_slot_t), allocatable :: tmp(:)
    namelist /material/ name, model, E, nu, density
    rewind(u)
    allocate(cs%model%mats(0))
    n = 0
    do
      name = ''; model = 'linear_elastic'; E = UNSET; nu = 0.0_wp; density = UNSET
      read(u, nml=material, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        emsg = nml_error(path, 'material', K, msg); return
      end if
      n = n + 1
      if (len_trim(name) == 0) then
        emsg = req(path, 'material', 'name', 'required: a label referenced by &particles '// &
          '(material number '//str(n)//')'); return
      end if
      do i = 1, n - 1
        if (cs%model%mats(i)%label == trim(name)) then
          emsg = req(path, 'material', 'name', 'duplicate label '''//trim(name)//''''); return
        end if
      end do
      if (E == UNSET) then
        emsg = req(path, 'material', 'E', 'required: Young''s modulus [Pa] > 0 (material '''// &
          trim(name)//''')'); return
      end if
      if (density == UNSET) then
        emsg = req(path, 'material', 'density', 'required: density [kg/m3] > 0 (material '''// &
          trim(name)//''')'); return
      end if
      allocate(tmp(n))
      do i = 1, n - 1
        call move_alloc(cs%model%mats(i)%model, tmp(i)%model)
        tmp(i)%label = cs%model%mats(i)%label
      end do
      call move_alloc(tmp, cs%model%mats)
      cs%model%mats(n)%label = trim(name)
      call empm_material_create(trim(lower(model)), E, nu, density, cs%model%mats(n)%model, info)
      if (info == MAT_UNKNOWN_NAME) then
        emsg = req(path, 'material', 'model', 'unknown model '''//trim(model)//''': '// &
          material_status_text(info)); return
      else if (info /= 0) then
        emsg = path//': group &material '''//trim(name)//''': '//material_status_text(info)// &
          ' (got E = '//str(E)//', nu = '//str(nu)//', density = '//str(density)//')'; return
      end if
    end do
    if (n == 0) emsg = path//': missing required group &material (keys: '//K//')'
  end subroutine read_materials

  subroutine read_shape(u, path, cs, ov, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'family, gamma, tol0, remedy, gamma_inside, '// &
      'gamma_box_lo, gamma_box_hi'
    character(len=64) :: family, remedy
    real(wp) :: gamma, tol0, gamma_inside, gamma_box_lo(3), gamma_box_hi(3)
    integer :: ios, info, nd
    logical :: lme_keys
    character(len=512) :: msg
    namelist /shape/ family, gamma, tol0, remedy, gamma_inside, gamma_box_lo, gamma_box_hi
    family = 'linear'; gamma = UNSET; tol0 = UNSET; remedy = ''; gamma_inside = UNSET
    gamma_box_lo = UNSET; gamma_box_hi = UNSET
    nd = cs%model%grid%ndim
    rewind(u)
    read(u, nml=shape, iostat=ios, iomsg=msg)
    if (ios /= 0 .and. ios /= iostat_end) then
      emsg = nml_error(path, 'shape', K, msg); return
    end if
    ! LME keys with another family are an error, unless the family is overridden.
    lme_keys = gamma /= UNSET .or. tol0 /= UNSET .or. len_trim(remedy) > 0 .or. &
      gamma_inside /= UNSET .or. any(gamma_box_lo /= UNSET) .or. any(gamma_box_hi /= UNSET)
    if (lme_keys .and. .not. allocated(ov%shape)) then
      if (index(lower(adjustl(family)), 'lme') /= 1) then
        emsg = req(path, 'shape', 'family', 'keys gamma, tol0, remedy and gamma_* apply to '// &
          'family ''lme'' only, got '''//trim(family)//''''); return
      end if
    end if
    if (allocated(ov%shape)) family = ov%shape
    if (gamma == UNSET) gamma = 3.0_wp
    if (tol0 == UNSET) tol0 = 1.0e-6_wp
    if (.not. (gamma > 0.0_wp)) then
      emsg = req(path, 'shape', 'gamma', 'expected gamma > 0, got '//str(gamma)); return
    end if
    if (.not. (tol0 > 0.0_wp .and. tol0 < 1.0_wp)) then
      emsg = req(path, 'shape', 'tol0', 'expected 0 < tol0 < 1, got '//str(tol0)); return
    end if
    call empm_shape_create(trim(lower(family)), nd, cs%model%shape, info, gamma, tol0)
    if (info == SHAPE_CREATE_BAD_PARAM) then
      emsg = req(path, 'shape', 'family', 'expected gamma > 0 in '''//trim(family)//''''); return
    else if (info /= 0) then
      emsg = req(path, 'shape', 'family', 'unknown family '''//trim(family)// &
        '''; expected one of: '//empm_shape_names()//' (or lme_g<gamma>)'); return
    end if
    select type (s => cs%model%shape)
    type is (empm_shape_lme_t)
      select case (trim(lower(remedy)))
      case ('', 'none'); s%remedy = LME_REMEDY_NONE
      case ('enlarge'); s%remedy = LME_REMEDY_ENLARGE
      case default
        emsg = req(path, 'shape', 'remedy', 'expected ''none'' or ''enlarge'', got '''// &
          trim(remedy)//''''); return
      end select
      if (gamma_inside /= UNSET) then
        if (.not. (gamma_inside > 0.0_wp)) then
          emsg = req(path, 'shape', 'gamma_inside', 'expected > 0, got '//str(gamma_inside))
          return
        end if
        if (any(gamma_box_lo(1:nd) == UNSET) .or. any(gamma_box_hi(1:nd) == UNSET)) then
          emsg = req(path, 'shape', 'gamma_box_lo/hi', 'required with gamma_inside: '// &
            str(nd)//' coordinates each [m]'); return
        end if
        if (any(gamma_box_hi(1:nd) < gamma_box_lo(1:nd))) then
          emsg = req(path, 'shape', 'gamma_box_hi', 'expected hi >= lo in every direction')
          return
        end if
        call s%set_gamma_box(cs%model%grid, gamma_box_lo(1:nd), gamma_box_hi(1:nd), &
                             gamma_inside, info)
      else if (any(gamma_box_lo /= UNSET) .or. any(gamma_box_hi /= UNSET)) then
        emsg = req(path, 'shape', 'gamma_inside', 'required with gamma_box_lo/hi: the gamma '// &
          'of the nodes in the box'); return
      end if
    end select
    cs%shape_name = cs%model%shape%name()
  end subroutine read_shape

  subroutine read_particles(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'material, geometry, lo, hi, center, radius, ppc, '// &
      'placement, velocity, velocity_sine_amplitude, velocity_sine_wavenumber, '// &
      'velocity_sine_phase, stress'
    character(len=64) :: material, geometry, placement
    real(wp) :: lo(3), hi(3), center(3), radius, velocity(3), velocity_sine_amplitude(3), &
                velocity_sine_wavenumber(3), velocity_sine_phase, stress(6)
    integer :: ppc, ios, info, nbody, imat, i, geom, place, nadded, p0, p, nd
    character(len=512) :: msg
    namelist /particles/ material, geometry, lo, hi, center, radius, ppc, placement, velocity, &
      velocity_sine_amplitude, velocity_sine_wavenumber, velocity_sine_phase, stress
    nd = cs%model%grid%ndim
    rewind(u)
    nbody = 0
    do
      material = ''; geometry = 'box'; placement = 'gauss'; ppc = 2
      lo = UNSET; hi = UNSET; center = UNSET; radius = UNSET
      velocity = 0.0_wp; velocity_sine_amplitude = 0.0_wp; velocity_sine_wavenumber = 0.0_wp
      velocity_sine_phase = 0.0_wp; stress = 0.0_wp
      read(u, nml=particles, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        emsg = nml_error(path, 'particles', K, msg); return
      end if
      nbody = nbody + 1
      imat = 0
      do i = 1, size(cs%model%mats)
        if (cs%model%mats(i)%label == trim(material)) imat = i
      end do
      if (imat == 0) then
        emsg = req(path, 'particles', 'material', 'expected the name of a &material group, '// &
          'got '''//trim(material)//''' (body '//str(nbody)//')'); return
      end if
      select case (trim(lower(geometry)))
      case ('box', 'interval')
        geom = GEOM_BOX
        if (any(lo(1:nd) == UNSET) .or. any(hi(1:nd) == UNSET)) then
          emsg = req(path, 'particles', 'lo/hi', 'required for geometry = ''box'': '// &
            str(nd)//' coordinates each [m] (body '//str(nbody)//')'); return
        end if
        if (any(hi(1:nd) <= lo(1:nd))) then
          emsg = req(path, 'particles', 'hi', 'expected hi > lo in every direction (body '// &
            str(nbody)//')'); return
        end if
      case ('disk', 'sphere')
        geom = GEOM_DISK
        if (nd < 2) then
          emsg = req(path, 'particles', 'geometry', '''disk'' needs ndim >= 2; use ''box'''// &
            ' (an interval) in 1D'); return
        end if
        if (any(center(1:nd) == UNSET) .or. radius == UNSET .or. radius <= 0.0_wp) then
          emsg = req(path, 'particles', 'center/radius', 'required for geometry = ''disk'': '// &
            'a centre and a radius > 0 [m] (body '//str(nbody)//')'); return
        end if
      case default
        emsg = req(path, 'particles', 'geometry', 'expected ''box'', ''interval'' or ''disk'','// &
          ' got '''//trim(geometry)//''''); return
      end select
      select case (trim(lower(placement)))
      case ('gauss'); place = PLACE_GAUSS
      case ('voxel'); place = PLACE_VOXEL
      case default
        emsg = req(path, 'particles', 'placement', 'expected ''gauss'' or ''voxel'', got '''// &
          trim(placement)//''''); return
      end select
      if (ppc < 1 .or. ppc > 4) then
        emsg = req(path, 'particles', 'ppc', 'expected 1..4 particles per cell and direction,'// &
          ' got '//str(ppc)); return
      end if
      p0 = cs%model%pts%np
      call empm_fill(cs%model%pts, cs%model%grid, geom, lo, hi, center, radius, ppc, place, &
        cs%model%mats(imat)%model%rho0, imat, nadded, info)
      if (nadded == 0) then
        emsg = path//': group &particles (body '//str(nbody)//'): the geometry contains no '// &
          'particle position of the grid: check lo/hi or center/radius against &grid'; return
      end if
      do p = p0 + 1, p0 + nadded
        associate (x => cs%model%pts%x(:, p))
          cs%model%pts%v(:, p) = velocity(1:nd) + velocity_sine_amplitude(1:nd) * &
            sin(sum(velocity_sine_wavenumber(1:nd) * x) + velocity_sine_phase)
        end associate
        cs%model%pts%stress(:, p) = stress
      end do
    end do
    if (nbody == 0) emsg = path//': missing required group &particles (keys: '//K//')'
  end subroutine read_particles

  subroutine read_integrator(u, path, cs, ov, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    type(empm_overrides_t), intent(in) :: ov
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'scheme, cfl, dt, t_end, max_steps, newmark_gamma, rho_b'
    character(len=64) :: scheme
    real(wp) :: cfl, dt, t_end, newmark_gamma, rho_b
    integer :: max_steps, ios, info
    character(len=512) :: msg
    namelist /integrator/ scheme, cfl, dt, t_end, max_steps, newmark_gamma, rho_b
    scheme = 'musl'; cfl = 0.5_wp; dt = 0.0_wp; t_end = UNSET; max_steps = 100000000
    newmark_gamma = 0.5_wp; rho_b = 0.8_wp
    rewind(u)
    read(u, nml=integrator, iostat=ios, iomsg=msg)
    if (ios == iostat_end) then
      emsg = path//': missing required group &integrator (keys: '//K//')'; return
    else if (ios /= 0) then
      emsg = nml_error(path, 'integrator', K, msg); return
    end if
    if (allocated(ov%scheme)) scheme = ov%scheme
    if (ov%cfl > 0.0_wp) cfl = ov%cfl
    if (ov%dt > 0.0_wp) dt = ov%dt
    if (ov%t_end > 0.0_wp) t_end = ov%t_end
    if (.not. (newmark_gamma >= 0.0_wp .and. newmark_gamma <= 1.0_wp)) then
      emsg = req(path, 'integrator', 'newmark_gamma', 'expected 0 <= newmark_gamma <= 1, got '// &
        str(newmark_gamma)); return
    end if
    if (.not. (rho_b >= 0.0_wp .and. rho_b <= 1.0_wp)) then
      emsg = req(path, 'integrator', 'rho_b', 'expected 0 <= rho_b <= 1, got '//str(rho_b)); return
    end if
    call empm_integrator_create(trim(lower(scheme)), cs%integ, info, newmark_gamma, rho_b)
    if (info /= 0) then
      emsg = req(path, 'integrator', 'scheme', 'unknown scheme '''//trim(scheme)// &
        '''; expected one of: '//empm_integrator_names()); return
    end if
    cs%scheme_name = cs%integ%name()
    if (t_end == UNSET) then
      emsg = req(path, 'integrator', 't_end', 'required: end time [s] > 0'); return
    else if (t_end <= 0.0_wp) then
      emsg = req(path, 'integrator', 't_end', 'expected > 0, got '//str(t_end)); return
    end if
    if (.not. (cfl > 0.0_wp .and. cfl <= 1.0_wp)) then
      emsg = req(path, 'integrator', 'cfl', 'expected 0 < cfl <= 1, got '//str(cfl)); return
    end if
    if (dt < 0.0_wp) then
      emsg = req(path, 'integrator', 'dt', 'expected dt >= 0 (0 = from cfl), got '//str(dt))
      return
    end if
    if (max_steps < 1) then
      emsg = req(path, 'integrator', 'max_steps', 'expected >= 1, got '//str(max_steps)); return
    end if
    cs%run%t_end = t_end; cs%run%cfl = cfl; cs%run%dt = dt; cs%run%max_steps = max_steps
  end subroutine read_integrator

  subroutine read_loads(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'gravity, ramp, ramp_time'
    real(wp) :: gravity(3), ramp_time
    character(len=64) :: ramp
    integer :: ios
    character(len=512) :: msg
    namelist /loads/ gravity, ramp, ramp_time
    gravity = 0.0_wp; ramp = 'none'; ramp_time = UNSET
    rewind(u)
    read(u, nml=loads, iostat=ios, iomsg=msg)
    if (ios /= 0 .and. ios /= iostat_end) then
      emsg = nml_error(path, 'loads', K, msg); return
    end if
    cs%model%loads%gravity = 0.0_wp
    cs%model%loads%gravity(1:cs%model%grid%ndim) = gravity(1:cs%model%grid%ndim)
    select case (trim(lower(ramp)))
    case ('none')
      cs%model%loads%ramp = RAMP_NONE
    case ('sine')
      cs%model%loads%ramp = RAMP_SINE
      if (ramp_time == UNSET .or. ramp_time <= 0.0_wp) then
        emsg = req(path, 'loads', 'ramp_time', 'required with ramp = ''sine'': period T [s] '// &
          '> 0 of eq. (46)'); return
      end if
      cs%model%loads%t_ramp = ramp_time
    case default
      emsg = req(path, 'loads', 'ramp', 'expected ''none'' or ''sine'', got '''//trim(ramp)//'''')
      return
    end select
  end subroutine read_loads

  subroutine read_boundaries(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'lo, hi, fix, velocity'
    real(wp) :: lo(3), hi(3), velocity(3)
    logical :: fix(3)
    integer :: ios, nb, nsel, nd
    character(len=512) :: msg
    namelist /boundary/ lo, hi, fix, velocity
    nd = cs%model%grid%ndim
    call cs%model%nodes%alloc(cs%model%grid)
    rewind(u)
    nb = 0
    do
      lo = UNSET; hi = UNSET; fix = .false.; velocity = 0.0_wp
      read(u, nml=boundary, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        emsg = nml_error(path, 'boundary', K, msg); return
      end if
      nb = nb + 1
      if (any(lo(1:nd) == UNSET) .or. any(hi(1:nd) == UNSET)) then
        emsg = req(path, 'boundary', 'lo/hi', 'required: the box selecting the nodes, '// &
          str(nd)//' coordinates each [m] (boundary '//str(nb)//')'); return
      end if
      if (.not. any(fix(1:nd))) then
        emsg = req(path, 'boundary', 'fix', 'expected at least one .true. component '// &
          '(boundary '//str(nb)//')'); return
      end if
      call cs%model%nodes%fix_box(cs%model%grid, lo, hi, fix, velocity, nsel)
      if (nsel == 0) then
        emsg = req(path, 'boundary', 'lo/hi', 'the box selects no grid node (boundary '// &
          str(nb)//'): nodes lie at origin + i*h'); return
      end if
    end do
  end subroutine read_boundaries

  subroutine read_probes(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'name, particle, point'
    character(len=64) :: name
    integer :: particle, ios, n, nd, p
    real(wp) :: point(3)
    character(len=512) :: msg
    character(len=64), allocatable :: names(:)
    integer, allocatable :: parts(:)
    namelist /probe/ name, particle, point
    nd = cs%model%grid%ndim
    allocate(names(0), parts(0))
    rewind(u)
    n = 0
    do
      name = ''; particle = IUNSET; point = UNSET
      read(u, nml=probe, iostat=ios, iomsg=msg)
      if (ios == iostat_end) exit
      if (ios /= 0) then
        emsg = nml_error(path, 'probe', K, msg); return
      end if
      n = n + 1
      if (len_trim(name) == 0) then
        emsg = req(path, 'probe', 'name', 'required (probe '//str(n)//')'); return
      end if
      if (any(names == name)) then
        emsg = req(path, 'probe', 'name', 'duplicate probe name '''//trim(name)//''''); return
      end if
      if ((particle == IUNSET) .eqv. (point(1) == UNSET)) then
        emsg = req(path, 'probe', 'particle/point', 'give exactly one of particle (index) '// &
          'or point (coordinates) for probe '''//trim(name)//''''); return
      end if
      if (particle /= IUNSET) then
        if (particle < 1 .or. particle > cs%model%pts%np) then
          emsg = req(path, 'probe', 'particle', 'expected 1..'//str(cs%model%pts%np)// &
            ', got '//str(particle)); return
        end if
        p = particle
      else
        if (any(point(1:nd) == UNSET)) then
          emsg = req(path, 'probe', 'point', 'expected '//str(nd)//' coordinates'); return
        end if
        ! A point probe follows the material point nearest to it at t = 0.
        p = minloc(sum((cs%model%pts%x(:, 1:cs%model%pts%np) - &
                   spread(point(1:nd), 2, cs%model%pts%np))**2, dim=1), dim=1)
      end if
      names = [character(len=64) :: names, name]; parts = [parts, p]
    end do
    call move_alloc(names, cs%probe_name); call move_alloc(parts, cs%probe_particle)
  end subroutine read_probes

  subroutine read_output(u, path, cs, emsg)
    integer, intent(in) :: u
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    character(len=*), parameter :: K = 'file, history_every, snapshot_times'
    character(len=512) :: file, msg
    integer :: history_every, ios, n, i
    real(wp) :: snapshot_times(MAXSNAP)
    namelist /output/ file, history_every, snapshot_times
    file = ''; history_every = 1; snapshot_times = UNSET
    rewind(u)
    read(u, nml=output, iostat=ios, iomsg=msg)
    if (ios /= 0 .and. ios /= iostat_end) then
      emsg = nml_error(path, 'output', K, msg); return
    end if
    if (history_every < 1) then
      emsg = req(path, 'output', 'history_every', 'expected >= 1, got '//str(history_every))
      return
    end if
    n = count(snapshot_times /= UNSET)
    if (any(snapshot_times(1:n) == UNSET)) then
      emsg = req(path, 'output', 'snapshot_times', 'expected consecutive values from index 1')
      return
    end if
    do i = 1, n
      if (snapshot_times(i) < 0.0_wp .or. snapshot_times(i) > cs%run%t_end .or. &
          (i > 1 .and. snapshot_times(max(i - 1, 1)) >= snapshot_times(i))) then
        emsg = req(path, 'output', 'snapshot_times', 'expected increasing times in [0, t_end]'// &
          ', got '//str(snapshot_times(i))//' at index '//str(i)); return
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

  !> Finish the set-up and evaluate the shape functions once: a particle whose support does not
  !> fit the grid is an input error, reported before any step is taken.
  subroutine check_initial_basis(path, cs, emsg)
    character(len=*), intent(in) :: path
    type(empm_case_t), intent(inout) :: cs
    character(len=:), allocatable, intent(inout) :: emsg
    integer :: ibad, info, d
    character(len=:), allocatable :: xs
    call cs%model%finalize_setup()
    call cs%model%shape%eval_batch(cs%model%grid, cs%model%pts, cs%model%basis, ibad, info)
    if (info /= 0) then
      xs = ''
      if (ibad >= 1 .and. ibad <= cs%model%pts%np) then
        do d = 1, cs%model%grid%ndim
          xs = xs//merge(' (', ', ', d == 1)//str(cs%model%pts%x(d, ibad))
        end do
        xs = ' at x ='//xs//')'
      end if
      emsg = path//': groups &grid/&particles/&shape are inconsistent: at particle '// &
        str(ibad)//xs//' the '//cs%shape_name//' shape functions fail: '//shape_status_text(info)
    end if
  end subroutine check_initial_basis
end module empm_input
