!> C API of empm: `bind(C)` procedures behind `include/empm.h` (docs/embedding.md).
!>
!> A model handle is a `c_ptr` to an [[empm_capi_box_t]] allocated here: it holds the model,
!> its integrator, run controls, history and the handle's last error message. There is no
!> module-level state, so any number of models live in one process. Every entry point returns
!> an integer status (0 or an EMPM_ERR_* code) and never stops the program: library routines
!> are always called with `err`.
!>
!> Stepping goes through [[empm_solve]] (its stability, NaN and grid guards included): "n steps"
!> is n calls advancing by one step Δt = cfl·Δt_stable (or the fixed dt), "to time t" one call
!> with t_end = t. A tripped guard restores the last good state and returns EMPM_ERR_RUNTIME.
!>
!> The Fortran-level procedures (`capi_*`, character arguments) are shared with the Fortran 77
!> entry points of [[empm_f77]]; the C entry points only convert NUL-terminated strings.
module empm_capi
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_char, c_ptr, c_null_ptr, c_null_char, &
                                         c_associated, c_f_pointer, c_loc, c_size_t
  use empm_kinds, only: wp, pi
  use empm_version_info, only: empm_version
  use empm_strings, only: str
  use empm_friction, only: empm_wall_problem
  use empm_error, only: empm_error_t, EMPM_OK, EMPM_ERR_USAGE, EMPM_ERR_INPUT, EMPM_ERR_IO
  use empm_model, only: empm_model_t, empm_material_slot_t
  use empm_integrator, only: empm_integrator_t, WALL_SCHEMES
  use empm_material, only: STATE_NAME_LEN
  use empm_registry, only: empm_create_shape, empm_create_material, empm_create_integrator
  use empm_history, only: empm_history_t
  use empm_solver, only: empm_run_config_t, empm_solve, empm_stable_dt, empm_energies
  use empm_case, only: empm_case_t
  use empm_input, only: empm_read_case
  use empm_output, only: empm_write_results, empm_output_meta_t
  use empm_driver, only: empm_run_case, empm_write_shared
  use empm_comm, only: empm_comm_t, empm_comm_from_handle, empm_comm_handle_problem
  use empm_partition, only: empm_partition_particles, empm_copy_for_output
  use empm_particle_gen, only: empm_deal_t
  implicit none
  private
  public :: empm_capi_box_t
  public :: capi_from_case, capi_create, capi_set_shape, capi_set_integrator, capi_add_material
  public :: capi_add_particles, capi_fix_box, capi_set_time_step, capi_finalize, capi_step
  public :: capi_set_gravity, capi_friction_box
  public :: capi_advance_to, capi_field_size, capi_get_field, capi_set_field, capi_write
  public :: capi_destroy, capi_box, capi_run_case, capi_energies, capi_probe
  public :: capi_copy_message, capi_run_case_comm, capi_set_comm

  integer, parameter :: MSG_LEN = 1024 !! longest stored message (longer ones are cut)

  !> What a handle points to.
  type :: empm_capi_box_t
    type(empm_model_t) :: model                        !! the simulation
    class(empm_integrator_t), allocatable :: integ     !! time integrator
    type(empm_run_config_t) :: run                     !! cfl / dt of the steps
    type(empm_history_t) :: hist                       !! energies and probes of the steps
    character(len=64), allocatable :: probe_name(:)    !! probe names (case files)
    integer, allocatable :: probe_particle(:)          !! particle of each probe
    character(len=:), allocatable :: shape_name        !! for the output attributes
    character(len=:), allocatable :: scheme_name       !! for the output attributes
    character(len=:), allocatable :: case_file         !! '' for a programmatic model
    character(len=:), allocatable :: case_text         !! text of the case file
    logical :: ready = .false.                         !! finalized, may step
    !> On a communicator from before the first particle: the particles added, dealt out (each
    !> process stores every `deal%every`-th), and the grid's fields not allocated until the
    !> windows (docs/embedding.md, "MPI")
    logical :: dealt = .false.
    type(empm_deal_t) :: deal                          !! the dealing (ids, this process)
    integer :: nmat = 0                                !! materials added
    character(len=MSG_LEN) :: message = ''             !! last error ('' after a success)
  end type empm_capi_box_t

contains

  ! ---- helpers ------------------------------------------------------------------------------

  !> The box behind a handle, or a null pointer.
  function capi_box(h) result(b)
    type(c_ptr), intent(in) :: h                 !! handle
    type(empm_capi_box_t), pointer :: b          !! its box (null for a null handle)
    b => null()
    if (c_associated(h)) call c_f_pointer(h, b)
  end function capi_box

  !> Store `e` as the box's last error and return its code.
  integer function remember(b, e) result(code)
    type(empm_capi_box_t), intent(inout) :: b !! box
    type(empm_error_t), intent(in) :: e       !! outcome
    code = e%code
    b%message = ''
    if (e%code /= EMPM_OK) then
      if (allocated(e%message)) b%message = e%message
      if (len_trim(b%message) == 0) b%message = 'error'
    end if
  end function remember

  !> Set an error with code and text.
  integer function fail(b, code, text) result(rc)
    type(empm_capi_box_t), intent(inout) :: b !! box
    integer, intent(in) :: code               !! EMPM_ERR_* code
    character(len=*), intent(in) :: text      !! message
    b%message = text
    rc = code
  end function fail

  !> Copy `text` into a C buffer of `n` bytes, NUL-terminated and cut to fit (nothing when the
  !> buffer is null or `n` is 0).
  subroutine capi_copy_message(text, buf, n)
    character(len=*), intent(in) :: text       !! message
    type(c_ptr), intent(in) :: buf             !! char buffer, may be null
    integer(c_size_t), intent(in) :: n         !! its size in bytes
    character(kind=c_char), pointer :: c(:)
    integer :: i, m
    if (.not. c_associated(buf) .or. n < 1) return
    call c_f_pointer(buf, c, [n])
    m = int(min(int(len_trim(text), c_size_t), n - 1))
    do i = 1, m
      c(i) = text(i:i)
    end do
    c(m + 1) = c_null_char
  end subroutine capi_copy_message

  !> A NUL-terminated C string as Fortran text ('' for a null pointer; at most 4096 bytes).
  function fstr(p) result(s)
    type(c_ptr), intent(in) :: p            !! const char *
    character(len=:), allocatable :: s      !! the text
    character(kind=c_char), pointer :: c(:)
    integer :: n
    s = ''
    if (.not. c_associated(p)) return
    call c_f_pointer(p, c, [4096])
    n = 0
    do while (n < 4096)
      if (c(n + 1) == c_null_char) exit
      n = n + 1
    end do
    deallocate(s)
    allocate(character(len=n) :: s)
    s = transfer(c(1:n), s)
  end function fstr

  ! ---- Fortran-level operations (shared by the C and Fortran 77 entry points) ------------------

  !> Run a case file as `empm run` does (quiet), writing its output (or `output` if not blank).
  integer function capi_run_case(path, output, msg, comm) result(rc)
    character(len=*), intent(in) :: path                 !! case file
    character(len=*), intent(in) :: output               !! output override, '' for the case's
    character(len=:), allocatable, intent(out) :: msg    !! error text, '' on success
    type(empm_comm_t), intent(in), optional :: comm      !! the processes (default: this one)
    type(empm_error_t) :: e
    call empm_run_case(path, output=output, progress=.false., err=e, comm=comm)
    rc = e%code
    msg = ''
    if (e%code /= EMPM_OK .and. allocated(e%message)) msg = e%message
  end function capi_run_case

  !> [[capi_run_case]] on the processes of a host's communicator (its Fortran handle): every
  !> process calls with the same arguments; the root writes the results; every process gets
  !> the same status and message.
  integer function capi_run_case_comm(path, output, handle, msg) result(rc)
    character(len=*), intent(in) :: path                 !! case file
    character(len=*), intent(in) :: output               !! output override, '' for the case's
    integer, intent(in) :: handle                        !! the host's communicator
    character(len=:), allocatable, intent(out) :: msg    !! error text, '' on success
    type(empm_comm_t) :: comm
    integer :: info
    call empm_comm_from_handle(handle, comm, info)
    if (info /= 0) then
      rc = EMPM_ERR_USAGE
      msg = 'empm_run_case_file_comm: '//empm_comm_handle_problem(info)
      return
    end if
    rc = capi_run_case(path, output, msg, comm)
    call comm%finish()
  end function capi_run_case_comm

  !> Run a programmatic model on the processes of a host's communicator (its Fortran handle;
  !> before finalize). Every process then makes the same calls: it adds every particle, and
  !> finalize moves each to the process of its box ([[empm_partition_particles]]). Called
  !> before the first particle is added, each process stores only every P-th particle as they
  !> are added, and no nodal field of the whole grid (the set-up of `empm run` under MPI);
  !> called later, each stores every particle until finalize. Fields, `info` and `set_field`
  !> are then this process's particles (field "id": their numbers in the order they were
  !> added); steps, energies and `write` (the root writes every particle) are collective.
  integer function capi_set_comm(b, handle) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    integer, intent(in) :: handle                   !! the host's communicator
    type(empm_comm_t) :: comm
    integer :: info
    rc = check_open(b, 'empm_model_set_comm', .true.)
    if (rc /= EMPM_OK) return
    if (b%dealt .and. (b%deal%n > 0 .or. allocated(b%model%nodes%mass))) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_set_comm: the model already has particles or '// &
        'boundaries on a communicator (set it once, before them)'); return
    end if
    call empm_comm_from_handle(handle, comm, info)
    if (info /= 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_set_comm: '//empm_comm_handle_problem(info))
      return
    end if
    call b%model%comm%finish()
    b%model%comm = comm
    b%message = ''
    b%dealt = .false.; b%deal%every = 1; b%deal%rank = 0
    if (comm%parallel() .and. b%deal%n == 0) then
      b%dealt = .true.
      b%deal = empm_deal_t(every=comm%nranks, rank=comm%rank)
    end if
  end function capi_set_comm

  !> A dealt model's nodes, before its first boundary or finalize: the boundaries are kept as
  !> lists, without the whole grid's fields (the windows come at finalize). Boundaries set
  !> before set_comm already hold the whole grid's fields, which finalize gives back.
  subroutine dealt_nodes(b, e)
    type(empm_capi_box_t), intent(inout) :: b !! box
    type(empm_error_t), intent(inout) :: e    !! an allocation failure
    if (b%dealt .and. .not. allocated(b%model%nodes%mass)) &
      call b%model%nodes%alloc(b%model%grid, e, fields=.false.)
  end subroutine dealt_nodes

  !> New handle from a case file (read with extra_groups='verify'), finalized and ready to step.
  integer function capi_from_case(path, h, msg) result(rc)
    character(len=*), intent(in) :: path                 !! case file
    type(c_ptr), intent(out) :: h                        !! new handle (null on failure)
    character(len=:), allocatable, intent(out) :: msg    !! error text, '' on success
    type(empm_case_t), allocatable :: cs
    type(empm_capi_box_t), pointer :: b
    type(empm_error_t) :: e
    integer :: st
    h = c_null_ptr; msg = ''
    allocate(cs, stat=st)
    if (st /= 0) then
      rc = EMPM_ERR_IO; msg = 'out of memory'; return
    end if
    call empm_read_case(path, cs, e, extra_groups='verify')
    if (e%code /= EMPM_OK) then
      rc = e%code; msg = 'empm_read_case failed'
      if (allocated(e%message)) msg = e%message
      return
    end if
    allocate(b, stat=st)
    if (st /= 0) then
      rc = EMPM_ERR_IO; msg = 'out of memory'; return
    end if
    call move_alloc(cs%integ, b%integ)
    b%model = cs%model
    b%run = cs%run
    b%run%progress = .false.
    b%run%max_steps = huge(1)
    b%probe_name = cs%probe_name; b%probe_particle = cs%probe_particle
    b%shape_name = cs%shape_name; b%scheme_name = cs%scheme_name
    b%case_file = path; b%case_text = cs%text
    b%nmat = 0
    if (allocated(b%model%mats)) b%nmat = size(b%model%mats)
    b%ready = .true.
    call b%hist%init(b%model%grid%ndim, b%probe_name, b%probe_particle, 1024, 0, e)
    if (e%code /= EMPM_OK) then
      rc = e%code; msg = e%message; deallocate(b); return
    end if
    h = c_loc(b)
    rc = EMPM_OK
  end function capi_from_case

  !> New empty handle with a grid of `ncell` cells of size `hcell` from `origin`.
  integer function capi_create(ndim, origin, hcell, ncell, h, msg) result(rc)
    integer, intent(in) :: ndim                          !! spatial dimension 1..3
    real(wp), intent(in) :: origin(:)                    !! origin (ndim)
    real(wp), intent(in) :: hcell(:)                     !! cell sizes (ndim)
    integer, intent(in) :: ncell(:)                      !! cells per direction (ndim)
    type(c_ptr), intent(out) :: h                        !! new handle (null on failure)
    character(len=:), allocatable, intent(out) :: msg    !! error text, '' on success
    type(empm_capi_box_t), pointer :: b
    integer :: info, st
    h = c_null_ptr; msg = ''
    if (ndim < 1 .or. ndim > 3) then
      rc = EMPM_ERR_USAGE; msg = 'empm_model_create: ndim must be 1, 2 or 3'; return
    end if
    allocate(b, stat=st)
    if (st /= 0) then
      rc = EMPM_ERR_IO; msg = 'out of memory'; return
    end if
    call b%model%grid%init(ndim, origin(1:ndim), hcell(1:ndim), ncell(1:ndim), info)
    if (info /= 0) then
      deallocate(b)
      rc = EMPM_ERR_INPUT
      msg = 'empm_model_create: invalid grid (positive cell sizes and cell counts needed)'
      return
    end if
    call b%model%pts%alloc(ndim, 16)
    allocate(b%model%mats(0), b%probe_name(0), b%probe_particle(0))
    b%shape_name = 'linear'; b%scheme_name = 'musl'; b%case_file = ''; b%case_text = ''
    b%run%progress = .false.
    h = c_loc(b)
    rc = EMPM_OK
  end function capi_create

  !> Refuse changes to a finalized model and calls on a null handle.
  integer function check_open(b, what, setup) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box (may be null)
    character(len=*), intent(in) :: what            !! entry point, for the message
    logical, intent(in) :: setup                    !! true: only before finalize; false: after
    rc = EMPM_OK
    if (.not. associated(b)) then
      rc = EMPM_ERR_USAGE; return
    end if
    if (setup .and. b%ready) rc = fail(b, EMPM_ERR_USAGE, what//': the model is already finalized')
    if (.not. setup .and. .not. b%ready) &
      rc = fail(b, EMPM_ERR_USAGE, what//': call empm_model_finalize first')
  end function check_open

  !> Choose the shape family by identifier ('linear', 'lme', ...) and its keys as text.
  integer function capi_set_shape(b, id, params) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: id              !! family identifier
    character(len=*), intent(in) :: params          !! 'key = value, ...'
    type(empm_error_t) :: e
    rc = check_open(b, 'empm_model_set_shape', .true.)
    if (rc /= EMPM_OK) return
    if (allocated(b%model%shape)) deallocate(b%model%shape)
    call empm_create_shape(id, b%model%grid, b%model%shape, e, params)
    if (e%code == EMPM_OK) b%shape_name = id
    rc = remember(b, e)
  end function capi_set_shape

  !> Choose the integrator by name and its keys as text.
  integer function capi_set_integrator(b, name, params) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: name            !! scheme name
    character(len=*), intent(in) :: params          !! 'key = value, ...'
    type(empm_error_t) :: e
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    if (allocated(b%integ)) deallocate(b%integ)
    call empm_create_integrator(name, b%integ, e, params)
    if (e%code == EMPM_OK) b%scheme_name = name
    rc = remember(b, e)
  end function capi_set_integrator

  !> Add a material; `id` is its 1-based index for the particles' material ids.
  integer function capi_add_material(b, model, params, id) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: model           !! material model name
    character(len=*), intent(in) :: params          !! 'key = value, ...'
    integer, intent(out) :: id                      !! its index (0 on failure)
    type(empm_material_slot_t), allocatable :: tmp(:)
    type(empm_error_t) :: e
    integer :: i
    id = 0
    rc = check_open(b, 'empm_model_add_material', .true.)
    if (rc /= EMPM_OK) return
    allocate(tmp(b%nmat + 1))
    do i = 1, b%nmat
      call move_alloc(b%model%mats(i)%model, tmp(i)%model)
      if (allocated(b%model%mats(i)%label)) tmp(i)%label = b%model%mats(i)%label
    end do
    call empm_create_material(model, params, tmp(b%nmat + 1)%model, e)
    if (e%code == EMPM_OK) then
      tmp(b%nmat + 1)%label = model
      call move_alloc(tmp, b%model%mats)
      b%nmat = b%nmat + 1; id = b%nmat
    else
      do i = 1, b%nmat
        call move_alloc(tmp(i)%model, b%model%mats(i)%model)
      end do
    end if
    rc = remember(b, e)
  end function capi_add_material

  !> Append `n` particles at rest: positions x(ndim, n), volumes, densities, material ids.
  integer function capi_add_particles(b, n, x, vol, rho, mat) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    integer, intent(in) :: n                        !! number of particles
    real(wp), intent(in) :: x(:,:)                  !! positions (ndim, n)
    real(wp), intent(in) :: vol(:)                  !! volumes (n) [m³]
    real(wp), intent(in) :: rho(:)                  !! densities (n) [kg/m³]
    integer, intent(in) :: mat(:)                   !! material ids (n), 1..number of materials
    type(empm_error_t) :: e
    integer :: p, d, id
    logical :: mine
    real(wp) :: lp(3)
    rc = check_open(b, 'empm_model_add_particles', .true.)
    if (rc /= EMPM_OK) return
    d = b%model%grid%ndim
    if (n < 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_add_particles: n < 0'); return
    end if
    do p = 1, n
      if (mat(p) < 1 .or. mat(p) > b%nmat) then
        rc = fail(b, EMPM_ERR_USAGE, 'empm_model_add_particles: a material id is not that of '// &
                  'an added material'); return
      end if
      if (.not. (vol(p) > 0.0_wp .and. rho(p) > 0.0_wp)) then
        rc = fail(b, EMPM_ERR_USAGE, 'empm_model_add_particles: volumes and densities must '// &
                  'be positive'); return
      end if
      if (.not. b%model%grid%inside(x(1:d, p))) then
        rc = fail(b, EMPM_ERR_USAGE, 'empm_model_add_particles: a particle lies outside the '// &
                  'grid'); return
      end if
    end do
    do p = 1, n
      ! Dealt out (every process checked every particle above): this process's only.
      call b%deal%next(id, mine)
      if (b%dealt .and. .not. mine) cycle
      ! Particle domain: a cube of the particle's volume (GIMP-type shapes need its size).
      lp = 0.5_wp * vol(p)**(1.0_wp / d)
      call b%model%pts%append(x(1:d, p), vol(p), rho(p), lp(1:d), mat(p), e, id=id)
      if (e%code /= EMPM_OK) exit
    end do
    rc = remember(b, e)
  end function capi_add_particles

  !> Prescribe velocity components (mask(i) /= 0) on the nodes inside the box [lo, hi].
  integer function capi_fix_box(b, lo, hi, mask, value, nsel) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(in) :: lo(3)                   !! lower corner [m]
    real(wp), intent(in) :: hi(3)                   !! upper corner [m]
    integer, intent(in) :: mask(3)                  !! nonzero: prescribe that component
    real(wp), intent(in) :: value(3)                !! prescribed velocity [m/s]
    integer, intent(out) :: nsel                    !! nodes selected
    type(empm_error_t) :: e
    nsel = 0
    rc = check_open(b, 'empm_model_fix_box', .true.)
    if (rc /= EMPM_OK) return
    call dealt_nodes(b, e)
    if (e%code /= EMPM_OK) then
      rc = remember(b, e); return
    end if
    call b%model%nodes%fix_box(b%model%grid, lo, hi, mask /= 0, value, nsel)
    b%message = ''
  end function capi_fix_box

  !> Gravity (constant, from t = 0) [m/s²]; its first ndim components are used.
  integer function capi_set_gravity(b, g) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(in) :: g(3)                    !! gravity vector [m/s²]
    rc = check_open(b, 'empm_model_set_gravity', .true.)
    if (rc /= EMPM_OK) return
    if (.not. all(abs(g) <= huge(1.0_wp))) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_set_gravity: g must be finite'); return
    end if
    b%model%loads%gravity = 0.0_wp
    b%model%loads%gravity(1:b%model%grid%ndim) = g(1:b%model%grid%ndim)
    b%message = ''
  end function capi_set_gravity

  !> A frictional wall at rest on the nodes inside the box [lo, hi] (flat along the normal's
  !> axis): normal component fixed at zero, Coulomb friction tan δ on the others
  !> (docs/input.md, `&boundary friction_angle`). `normal` = ±axis (1..ndim), the direction from
  !> the wall into the body.
  integer function capi_friction_box(b, lo, hi, normal, delta, nsel) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(in) :: lo(3)                   !! lower corner [m]
    real(wp), intent(in) :: hi(3)                   !! upper corner [m]
    integer, intent(in) :: normal                   !! ±axis from the wall into the body
    real(wp), intent(in) :: delta                   !! friction angle [deg], in [0, 90)
    integer, intent(out) :: nsel                    !! nodes selected
    character(len=*), parameter :: WHAT = 'empm_model_friction_box: '
    type(empm_error_t) :: e
    integer :: info
    nsel = 0
    rc = check_open(b, 'empm_model_friction_box', .true.)
    if (rc /= EMPM_OK) return
    if (normal == 0 .or. abs(normal) > b%model%grid%ndim) then
      rc = fail(b, EMPM_ERR_USAGE, WHAT//'normal must be +-1..+-'//str(b%model%grid%ndim)// &
        ' (the axis from the wall into the body), got '//str(normal)); return
    end if
    if (.not. (delta >= 0.0_wp .and. delta < 90.0_wp)) then
      rc = fail(b, EMPM_ERR_USAGE, WHAT//'the friction angle must be in [0, 90) degrees, got '// &
        str(delta)); return
    end if
    call dealt_nodes(b, e)
    if (e%code /= EMPM_OK) then
      rc = remember(b, e); return
    end if
    call b%model%nodes%friction_box(b%model%grid, lo, hi, normal, tan(delta * pi / 180.0_wp), &
                                    nsel, info)
    if (info /= 0) then
      rc = fail(b, EMPM_ERR_USAGE, WHAT//empm_wall_problem(info, abs(normal)))
    else
      b%message = ''
    end if
  end function capi_friction_box

  !> Time step rule: Δt = cfl·Δt_stable when dt = 0, otherwise the fixed dt (checked against
  !> the stability limit at every step).
  integer function capi_set_time_step(b, cfl, dt) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(in) :: cfl                     !! Courant number, 0 < cfl <= 1
    real(wp), intent(in) :: dt                      !! fixed step [s], 0 = from cfl
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    if (.not. (cfl > 0.0_wp .and. cfl <= 1.0_wp) .or. .not. (dt >= 0.0_wp)) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_set_time_step: need 0 < cfl <= 1 and dt >= 0')
      return
    end if
    b%run%cfl = cfl; b%run%dt = dt
    b%message = ''; rc = EMPM_OK
  end function capi_set_time_step

  !> Finish the set-up (shape 'linear' and integrator 'musl' unless chosen); then the model steps.
  integer function capi_finalize(b) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    type(empm_error_t) :: e
    rc = check_open(b, 'empm_model_finalize', .true.)
    if (rc /= EMPM_OK) return
    ! On a communicator every process must pass the checks below or none (the collective
    ! steps after them): a process whose calls were refused fails them for all.
    if (b%model%comm%min_int(merge(1, 0, b%nmat > 0 .and. b%deal%n > 0)) == 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_finalize: add materials and particles first')
      return
    end if
    if (.not. allocated(b%model%shape)) then
      call empm_create_shape('linear', b%model%grid, b%model%shape, e)
      if (e%code /= EMPM_OK) then
        rc = remember(b, e); return
      end if
    end if
    if (.not. allocated(b%integ)) then
      call empm_create_integrator('musl', b%integ, e)
      if (e%code /= EMPM_OK) then
        rc = remember(b, e); return
      end if
    end if
    if (b%model%nodes%fric%n > 0 .and. .not. b%integ%walls()) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_finalize: integrator '''//b%integ%family()// &
        ''' does not support frictional walls ('//WALL_SCHEMES//' do)'); return
    end if
    call dealt_nodes(b, e)
    if (e%code == EMPM_OK) call b%model%finalize_setup(e, shared=b%dealt)
    ! An error one process met (its memory) is everyone's before the collective steps.
    call b%model%comm%agree(e)
    if (e%code == EMPM_OK .and. b%model%comm%parallel()) then
      ! Every process added every particle: each keeps, or is sent, those of its box.
      if (b%model%comm%min_int(b%deal%n) /= b%model%comm%max_int(b%deal%n)) then
        rc = fail(b, EMPM_ERR_USAGE, 'empm_model_finalize: the processes added different '// &
          'numbers of particles (each must add all of them; finalize shares them out)')
        return
      end if
      call empm_partition_particles(b%model, e, dealt=b%dealt)
    end if
    if (e%code == EMPM_OK) call b%hist%init(b%model%grid%ndim, b%probe_name, b%probe_particle, &
                                            1024, 0, e)
    if (e%code == EMPM_OK) b%ready = .true.
    rc = remember(b, e)
  end function capi_finalize

  !> Advance to time `t` with the solver (guards included).
  integer function capi_advance_to(b, t) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(in) :: t                       !! target time [s], > current time
    type(empm_error_t) :: e
    rc = check_open(b, 'empm_model_advance_to', .false.)
    if (rc /= EMPM_OK) return
    b%run%t_end = t
    if (allocated(b%run%snapshot_times)) deallocate(b%run%snapshot_times)
    allocate(b%run%snapshot_times(0))
    call empm_solve(b%model, b%integ, b%run, b%hist, e)
    rc = remember(b, e)
  end function capi_advance_to

  !> Take `n` steps of Δt = cfl·Δt_stable (or the fixed dt).
  integer function capi_step(b, n) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    integer, intent(in) :: n                        !! steps, >= 0
    integer :: k
    real(wp) :: dt
    rc = check_open(b, 'empm_model_step', .false.)
    if (rc /= EMPM_OK) return
    if (n < 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_step: n < 0'); return
    end if
    do k = 1, n
      dt = b%run%dt
      if (dt <= 0.0_wp) dt = b%run%cfl * empm_stable_dt(b%model)
      rc = capi_advance_to(b, b%model%t + dt)
      if (rc /= EMPM_OK) return
    end do
    b%message = ''
  end function capi_step

  !> Number of values of a particle field: components × particles (0 and an error if unknown).
  integer function capi_field_size(b, field, n, ncomp, row) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: field           !! field name
    integer, intent(out) :: n                       !! values in the field
    integer, intent(out) :: ncomp                   !! components per particle
    integer, intent(out) :: row                     !! state row for a state variable, else 0
    character(len=STATE_NAME_LEN), allocatable :: names(:)
    integer :: im, k
    n = 0; ncomp = 0; row = 0
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    if (b%dealt .and. .not. b%ready) then
      ! Each process holds only its share of the particles added, until finalize sends each
      ! to the process of its box: fields by index would mean other particles there.
      rc = fail(b, EMPM_ERR_USAGE, 'particle field "'//field//'": the model''s particles are '// &
        'dealt out on its communicator; read and set fields after empm_model_finalize, each '// &
        'process its own particles (field "id" names them)'); return
    end if
    select case (field)
    case ('x', 'v')
      ncomp = b%model%grid%ndim
    case ('stress', 'strain')
      ncomp = 6
    case ('mass', 'volume', 'density', 'id')
      ncomp = 1
    case default
      ! A state variable by the name its material gives it.
      if (allocated(b%model%mats)) then
        do im = 1, size(b%model%mats)
          if (.not. allocated(b%model%mats(im)%model)) cycle
          call b%model%mats(im)%model%state_names(names)
          do k = 1, size(names)
            if (trim(names(k)) == field) then
              ncomp = 1; row = k
            end if
          end do
        end do
      end if
      if (row == 0) then
        rc = fail(b, EMPM_ERR_USAGE, 'unknown particle field "'//field//'" (x, v, stress, '// &
                  'strain, mass, volume, density, id or a state variable name)')
        return
      end if
      if (.not. b%ready) then
        rc = fail(b, EMPM_ERR_USAGE, 'state variable "'//field//'": finalize the model first')
        return
      end if
    end select
    n = ncomp * b%model%pts%np
    b%message = ''; rc = EMPM_OK
  end function capi_field_size

  !> Copy a particle field out (column-major: component fastest) into buf(1:n).
  integer function capi_get_field(b, field, buf, n) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: field           !! field name
    real(wp), intent(out) :: buf(:)                 !! destination, size n
    integer, intent(in) :: n                        !! its size (must equal the field's)
    integer :: nf, nc, row, np
    rc = capi_field_size(b, field, nf, nc, row)
    if (rc /= EMPM_OK) return
    if (n /= nf) then
      rc = size_error(b, field, n, nf); return
    end if
    np = b%model%pts%np
    associate (pts => b%model%pts)
      select case (field)
      case ('x'); buf(1:n) = reshape(pts%x(:, 1:np), [n])
      case ('v'); buf(1:n) = reshape(pts%v(:, 1:np), [n])
      case ('stress'); buf(1:n) = reshape(pts%stress(:, 1:np), [n])
      case ('strain'); buf(1:n) = reshape(pts%strain(:, 1:np), [n])
      case ('mass'); buf(1:n) = pts%m(1:np)
      case ('volume'); buf(1:n) = pts%vol(1:np)
      case ('density'); buf(1:n) = pts%rho(1:np)
      case ('id'); buf(1:n) = real(pts%id(1:np), wp)
      case default; buf(1:n) = pts%state(row, 1:np)
      end select
    end associate
  end function capi_get_field

  !> Copy a particle field in from buf(1:n) (same layout as [[capi_get_field]]).
  integer function capi_set_field(b, field, buf, n) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: field           !! field name
    real(wp), intent(in) :: buf(:)                  !! source, size n
    integer, intent(in) :: n                        !! its size (must equal the field's)
    integer :: nf, nc, row, np
    rc = capi_field_size(b, field, nf, nc, row)
    if (rc /= EMPM_OK) return
    if (field == 'id') then
      rc = fail(b, EMPM_ERR_USAGE, 'field "id" is read-only'); return
    end if
    if (n /= nf) then
      rc = size_error(b, field, n, nf); return
    end if
    np = b%model%pts%np
    associate (pts => b%model%pts)
      select case (field)
      case ('x'); pts%x(:, 1:np) = reshape(buf(1:n), [nc, np])
      case ('v'); pts%v(:, 1:np) = reshape(buf(1:n), [nc, np])
      case ('stress'); pts%stress(:, 1:np) = reshape(buf(1:n), [nc, np])
      case ('strain'); pts%strain(:, 1:np) = reshape(buf(1:n), [nc, np])
      case ('mass'); pts%m(1:np) = buf(1:n)
      case ('volume'); pts%vol(1:np) = buf(1:n)
      case ('density'); pts%rho(1:np) = buf(1:n)
      case default; pts%state(row, 1:np) = buf(1:n)
      end select
      ! A pending pc_newmark drift correction belongs to the old positions. (Each step goes
      ! through empm_solve, which prepares the integrator afresh: no basis is carried across
      ! the calls.)
      if (field == 'x') pts%dx(:, 1:np) = 0.0_wp
    end associate
  end function capi_set_field

  !> Wrong buffer size: the message names the field and both sizes.
  integer function size_error(b, field, n, nf) result(rc)
    type(empm_capi_box_t), intent(inout) :: b !! box
    character(len=*), intent(in) :: field     !! field name
    integer, intent(in) :: n                  !! size given
    integer, intent(in) :: nf                 !! size of the field
    character(len=24) :: s1, s2
    write(s1, '(i0)') n; write(s2, '(i0)') nf
    rc = fail(b, EMPM_ERR_USAGE, 'field "'//field//'" has '//trim(s2)//' values, the buffer '// &
              'holds '//trim(s1))
  end function size_error

  !> Kinetic, stored and gravitational energy [J].
  integer function capi_energies(b, ekin, estrain, egrav) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    real(wp), intent(out) :: ekin                   !! kinetic energy
    real(wp), intent(out) :: estrain                !! stored energy
    real(wp), intent(out) :: egrav                  !! gravitational potential
    real(wp), allocatable :: psi(:)
    ekin = 0.0_wp; estrain = 0.0_wp; egrav = 0.0_wp
    rc = check_open(b, 'empm_model_energies', .false.)
    if (rc /= EMPM_OK) return
    allocate(psi(max(1, b%model%pts%np)))
    call empm_energies(b%model, psi, ekin, estrain, egrav)
    b%message = ''
  end function capi_energies

  !> Values of a field at a probe (case-file `&probe`), by probe name.
  integer function capi_probe(b, name, field, buf, n) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: name            !! probe name
    character(len=*), intent(in) :: field           !! particle field name
    real(wp), intent(out) :: buf(:)                 !! destination, size n
    integer, intent(in) :: n                        !! components of the field
    real(wp), allocatable :: all(:)
    integer :: k, p, nf, nc, row
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    p = 0
    do k = 1, size(b%probe_name)
      if (trim(b%probe_name(k)) == name) p = b%probe_particle(k)
    end do
    if (p == 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'unknown probe "'//name//'"'); return
    end if
    rc = capi_field_size(b, field, nf, nc, row)
    if (rc /= EMPM_OK) return
    if (n /= nc) then
      rc = size_error(b, field//' at a probe', n, nc); return
    end if
    allocate(all(nf))
    rc = capi_get_field(b, field, all, nf)
    if (rc == EMPM_OK) buf(1:n) = all((p - 1) * nc + 1:p * nc)
  end function capi_probe

  !> Write the model state and its history to HDF5 (+ XDMF).
  integer function capi_write(b, path) result(rc)
    type(empm_capi_box_t), pointer, intent(in) :: b !! box
    character(len=*), intent(in) :: path            !! output file
    type(empm_output_meta_t) :: meta
    type(empm_error_t) :: e
    rc = check_open(b, 'empm_model_write', .false.)
    if (rc /= EMPM_OK) return
    if (len_trim(path) == 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_write: empty path'); return
    end if
    meta%case_file = b%case_file; meta%case_text = b%case_text
    meta%shape = b%shape_name; meta%integrator = b%scheme_name
    meta%cfl = b%run%cfl; meta%t_end = b%model%t
    if (b%model%comm%parallel()) then
      ! Copies (the model goes on with its share): blocks of ids written together (parallel
      ! HDF5), or every particle gathered on the root.
      call write_gathered()
    else
      call empm_write_results(trim(path), b%model, b%hist, meta, .true., '', e)
    end if
    rc = remember(b, e)
  contains
    subroutine write_gathered()
      type(empm_model_t), allocatable :: whole
      type(empm_history_t), allocatable :: hall
      allocate(whole)
      call empm_copy_for_output(b%model, whole)
      allocate(hall, source=b%hist)
      call empm_write_shared(trim(path), whole, hall, meta, .true., '', e)
    end subroutine write_gathered
  end function capi_write

  !> Free a handle (nothing for a null one).
  subroutine capi_destroy(h)
    type(c_ptr), intent(in) :: h !! handle
    type(empm_capi_box_t), pointer :: b
    b => capi_box(h)
    if (.not. associated(b)) return
    call b%model%comm%finish() ! frees a host communicator's duplicate (MPI stays the host's)
    deallocate(b)
  end subroutine capi_destroy

  ! ---- C entry points ----------------------------------------------------------------------

  !> Version string "major.minor.patch" into buf (size len). Returns 0.
  integer(c_int) function c_version(buf, len) result(rc) bind(C, name='empm_version_string')
    type(c_ptr), value :: buf            !! char buffer
    integer(c_size_t), value :: len      !! its size
    call capi_copy_message(empm_version(), buf, len)
    rc = 0
  end function c_version

  !> Run a case file; `output` may be NULL; errors into errbuf (may be NULL).
  integer(c_int) function c_run_case(path, output, errbuf, errlen) result(rc) &
      bind(C, name='empm_run_case_file')
    type(c_ptr), value :: path             !! const char *: case file
    type(c_ptr), value :: output           !! const char *: output override or NULL
    type(c_ptr), value :: errbuf           !! char *: message buffer or NULL
    integer(c_size_t), value :: errlen     !! its size
    character(len=:), allocatable :: msg
    if (.not. c_associated(path)) then
      rc = EMPM_ERR_USAGE
      call capi_copy_message('empm_run_case_file: path is NULL', errbuf, errlen); return
    end if
    rc = capi_run_case(fstr(path), fstr(output), msg)
    call capi_copy_message(msg, errbuf, errlen)
  end function c_run_case

  !> `empm_run_case_file` on the processes of a host's communicator, given by its Fortran
  !> handle (`MPI_Comm_c2f(comm)`); every process calls it with the same arguments.
  integer(c_int) function c_run_case_comm(path, output, fcomm, errbuf, errlen) result(rc) &
      bind(C, name='empm_run_case_file_comm')
    type(c_ptr), value :: path             !! const char *: case file
    type(c_ptr), value :: output           !! const char *: output override or NULL
    integer(c_int), value :: fcomm         !! MPI_Fint: the communicator's Fortran handle
    type(c_ptr), value :: errbuf           !! char *: message buffer or NULL
    integer(c_size_t), value :: errlen     !! its size
    character(len=:), allocatable :: msg
    if (.not. c_associated(path)) then
      rc = EMPM_ERR_USAGE
      call capi_copy_message('empm_run_case_file_comm: path is NULL', errbuf, errlen); return
    end if
    rc = capi_run_case_comm(fstr(path), fstr(output), int(fcomm), msg)
    call capi_copy_message(msg, errbuf, errlen)
  end function c_run_case_comm

  !> `empm_model_set_comm`: run the model on a host's communicator (Fortran handle).
  integer(c_int) function c_set_comm(m, fcomm) result(rc) bind(C, name='empm_model_set_comm')
    type(c_ptr), value :: m                !! empm_model *
    integer(c_int), value :: fcomm         !! MPI_Fint: the communicator's Fortran handle
    rc = capi_set_comm(capi_box(m), int(fcomm))
  end function c_set_comm

  !> New model from a case file; on failure *out = NULL and the message goes to errbuf.
  integer(c_int) function c_from_case(path, out, errbuf, errlen) result(rc) &
      bind(C, name='empm_model_from_case')
    type(c_ptr), value :: path             !! const char *: case file
    type(c_ptr), intent(out) :: out        !! empm_model **: new handle
    type(c_ptr), value :: errbuf           !! char *: message buffer or NULL
    integer(c_size_t), value :: errlen     !! its size
    character(len=:), allocatable :: msg
    out = c_null_ptr
    if (.not. c_associated(path)) then
      rc = EMPM_ERR_USAGE
      call capi_copy_message('empm_model_from_case: path is NULL', errbuf, errlen); return
    end if
    rc = capi_from_case(fstr(path), out, msg)
    call capi_copy_message(msg, errbuf, errlen)
  end function c_from_case

  !> New empty model on a grid; on failure *out = NULL and the message goes to errbuf.
  integer(c_int) function c_create(ndim, origin, h, ncell, out, errbuf, errlen) result(rc) &
      bind(C, name='empm_model_create')
    integer(c_int), value :: ndim          !! spatial dimension 1..3
    real(c_double), intent(in) :: origin(*) !! origin (ndim)
    real(c_double), intent(in) :: h(*)     !! cell sizes (ndim)
    integer(c_int), intent(in) :: ncell(*) !! cells per direction (ndim)
    type(c_ptr), intent(out) :: out        !! empm_model **: new handle
    type(c_ptr), value :: errbuf           !! char *: message buffer or NULL
    integer(c_size_t), value :: errlen     !! its size
    character(len=:), allocatable :: msg
    integer :: d
    out = c_null_ptr
    d = max(1, min(3, int(ndim)))
    rc = capi_create(int(ndim), origin(1:d), h(1:d), ncell(1:d), out, msg)
    call capi_copy_message(msg, errbuf, errlen)
  end function c_create

  !> Last error message of a handle ('' after a success) into buf.
  integer(c_int) function c_error(m, buf, len) result(rc) bind(C, name='empm_model_error')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: buf              !! char buffer
    integer(c_size_t), value :: len        !! its size
    type(empm_capi_box_t), pointer :: b
    b => capi_box(m)
    if (.not. associated(b)) then
      call capi_copy_message('null empm_model handle', buf, len); rc = EMPM_ERR_USAGE; return
    end if
    call capi_copy_message(trim(b%message), buf, len); rc = 0
  end function c_error

  !> `empm_model_set_shape`: shape family by identifier, keys as text.
  integer(c_int) function c_set_shape(m, id, params) result(rc) &
      bind(C, name='empm_model_set_shape')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: id               !! const char *: family identifier
    type(c_ptr), value :: params           !! const char *: keys as text, or NULL
    rc = capi_set_shape(capi_box(m), fstr(id), fstr(params))
  end function c_set_shape

  !> `empm_model_set_integrator`: integrator by name, keys as text.
  integer(c_int) function c_set_integrator(m, name, params) result(rc) &
      bind(C, name='empm_model_set_integrator')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: name             !! const char *: scheme name
    type(c_ptr), value :: params           !! const char *: keys as text, or NULL
    rc = capi_set_integrator(capi_box(m), fstr(name), fstr(params))
  end function c_set_integrator

  !> `empm_model_add_material`: add a material by model name, keys as text.
  integer(c_int) function c_add_material(m, model, params, id) result(rc) &
      bind(C, name='empm_model_add_material')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: model            !! const char *: material model name
    type(c_ptr), value :: params           !! const char *: keys as text
    integer(c_int), intent(out) :: id      !! 1-based material id
    integer :: i
    rc = capi_add_material(capi_box(m), fstr(model), fstr(params), i)
    id = int(i, c_int)
  end function c_add_material

  !> `empm_model_add_particles`: append particles at rest from arrays.
  integer(c_int) function c_add_particles(m, n, x, vol, rho, mat) result(rc) &
      bind(C, name='empm_model_add_particles')
    type(c_ptr), value :: m                !! handle
    integer(c_int), value :: n             !! number of particles
    real(c_double), intent(in) :: x(*)     !! positions, ndim per particle
    real(c_double), intent(in) :: vol(*)   !! volumes (n)
    real(c_double), intent(in) :: rho(*)   !! densities (n)
    integer(c_int), intent(in) :: mat(*)   !! material ids (n)
    type(empm_capi_box_t), pointer :: b
    integer :: d
    b => capi_box(m)
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    if (n < 0) then
      rc = fail(b, EMPM_ERR_USAGE, 'empm_model_add_particles: n < 0'); return
    end if
    d = b%model%grid%ndim
    rc = capi_add_particles(b, int(n), reshape(x(1:d * n), [d, int(n)]), vol(1:n), rho(1:n), &
                            mat(1:n))
  end function c_add_particles

  !> `empm_model_fix_box`: prescribe nodal velocity components in a box.
  integer(c_int) function c_fix_box(m, lo, hi, mask, value, nsel) result(rc) &
      bind(C, name='empm_model_fix_box')
    type(c_ptr), value :: m                !! handle
    real(c_double), intent(in) :: lo(3)    !! lower corner
    real(c_double), intent(in) :: hi(3)    !! upper corner
    integer(c_int), intent(in) :: mask(3)  !! nonzero: prescribe this component
    real(c_double), intent(in) :: value(3) !! prescribed velocity
    integer(c_int), intent(out) :: nsel    !! nodes selected
    integer :: k
    rc = capi_fix_box(capi_box(m), lo, hi, int(mask), value, k)
    nsel = int(k, c_int)
  end function c_fix_box

  !> `empm_model_set_gravity`: constant gravity g[3] (the first ndim entries used).
  integer(c_int) function c_set_gravity(m, g) result(rc) bind(C, name='empm_model_set_gravity')
    type(c_ptr), value :: m                !! handle
    real(c_double), intent(in) :: g(3)     !! gravity [m/s²]
    rc = capi_set_gravity(capi_box(m), g)
  end function c_set_gravity

  !> `empm_model_friction_box`: a frictional wall at rest on the nodes of a box.
  integer(c_int) function c_friction_box(m, lo, hi, normal, delta, nsel) result(rc) &
      bind(C, name='empm_model_friction_box')
    type(c_ptr), value :: m                !! handle
    real(c_double), intent(in) :: lo(3)    !! lower corner
    real(c_double), intent(in) :: hi(3)    !! upper corner
    integer(c_int), value :: normal        !! ±axis from the wall into the body
    real(c_double), value :: delta         !! friction angle [deg]
    integer(c_int), intent(out) :: nsel    !! nodes selected
    integer :: k
    rc = capi_friction_box(capi_box(m), lo, hi, int(normal), delta, k)
    nsel = int(k, c_int)
  end function c_friction_box

  !> `empm_model_set_time_step`: Δt = cfl·Δt_stable (dt = 0) or a fixed dt.
  integer(c_int) function c_set_time_step(m, cfl, dt) result(rc) &
      bind(C, name='empm_model_set_time_step')
    type(c_ptr), value :: m                !! handle
    real(c_double), value :: cfl           !! Courant number
    real(c_double), value :: dt            !! fixed step, 0 = from cfl
    rc = capi_set_time_step(capi_box(m), cfl, dt)
  end function c_set_time_step

  !> `empm_model_finalize`: end of the set-up.
  integer(c_int) function c_finalize(m) result(rc) bind(C, name='empm_model_finalize')
    type(c_ptr), value :: m                !! handle
    rc = capi_finalize(capi_box(m))
  end function c_finalize

  !> `empm_model_step`: n steps through the solver.
  integer(c_int) function c_step(m, n) result(rc) bind(C, name='empm_model_step')
    type(c_ptr), value :: m                !! handle
    integer(c_int), value :: n             !! steps
    rc = capi_step(capi_box(m), int(n))
  end function c_step

  !> `empm_model_advance_to`: advance to a time through the solver.
  integer(c_int) function c_advance_to(m, t) result(rc) bind(C, name='empm_model_advance_to')
    type(c_ptr), value :: m                !! handle
    real(c_double), value :: t             !! target time
    rc = capi_advance_to(capi_box(m), t)
  end function c_advance_to

  !> `empm_model_info`: dimension, particles, time and steps taken.
  integer(c_int) function c_info(m, ndim, np, t, nstep) result(rc) bind(C, name='empm_model_info')
    type(c_ptr), value :: m                !! handle
    integer(c_int), intent(out) :: ndim    !! spatial dimension
    integer(c_int), intent(out) :: np      !! particles
    real(c_double), intent(out) :: t       !! current time
    integer(c_int), intent(out) :: nstep   !! steps taken
    type(empm_capi_box_t), pointer :: b
    b => capi_box(m)
    ndim = 0; np = 0; t = 0.0_wp; nstep = 0
    rc = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    ndim = b%model%grid%ndim; np = b%model%pts%np; t = b%model%t; nstep = b%model%step
    rc = 0
  end function c_info

  !> `empm_model_field_size`: number of values of a particle field.
  integer(c_int) function c_field_size(m, field, n) result(rc) &
      bind(C, name='empm_model_field_size')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: field            !! const char *: field name
    integer(c_size_t), intent(out) :: n    !! number of values
    integer :: k, nc, row
    rc = capi_field_size(capi_box(m), fstr(field), k, nc, row)
    n = int(k, c_size_t)
  end function c_field_size

  !> `empm_model_get_field`: copy a particle field out.
  integer(c_int) function c_get_field(m, field, buf, n) result(rc) &
      bind(C, name='empm_model_get_field')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: field            !! const char *: field name
    real(c_double), intent(inout) :: buf(*) !! destination (n)
    integer(c_size_t), value :: n          !! its size
    rc = capi_get_field(capi_box(m), fstr(field), buf(1:n), int(n))
  end function c_get_field

  !> `empm_model_set_field`: copy a particle field in.
  integer(c_int) function c_set_field(m, field, buf, n) result(rc) &
      bind(C, name='empm_model_set_field')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: field            !! const char *: field name
    real(c_double), intent(in) :: buf(*)   !! source (n)
    integer(c_size_t), value :: n          !! its size
    rc = capi_set_field(capi_box(m), fstr(field), buf(1:n), int(n))
  end function c_set_field

  !> `empm_model_energies`: kinetic, stored and gravitational energy.
  integer(c_int) function c_energies(m, ekin, estrain, egrav) result(rc) &
      bind(C, name='empm_model_energies')
    type(c_ptr), value :: m                !! handle
    real(c_double), intent(out) :: ekin    !! kinetic energy
    real(c_double), intent(out) :: estrain !! stored energy
    real(c_double), intent(out) :: egrav   !! gravitational potential
    rc = capi_energies(capi_box(m), ekin, estrain, egrav)
  end function c_energies

  !> `empm_model_probe`: a field at a case file's probe.
  integer(c_int) function c_probe(m, name, field, buf, n) result(rc) &
      bind(C, name='empm_model_probe')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: name             !! const char *: probe name
    type(c_ptr), value :: field            !! const char *: field name
    real(c_double), intent(inout) :: buf(*) !! destination (n)
    integer(c_size_t), value :: n          !! components of the field
    rc = capi_probe(capi_box(m), fstr(name), fstr(field), buf(1:n), int(n))
  end function c_probe

  !> `empm_model_write`: HDF5 (+ XDMF) output.
  integer(c_int) function c_write(m, path) result(rc) bind(C, name='empm_model_write')
    type(c_ptr), value :: m                !! handle
    type(c_ptr), value :: path             !! const char *: HDF5 file
    rc = capi_write(capi_box(m), fstr(path))
  end function c_write

  !> `empm_model_destroy`: free a handle.
  subroutine c_destroy(m) bind(C, name='empm_model_destroy')
    type(c_ptr), value :: m                !! handle (NULL is ignored)
    call capi_destroy(m)
  end subroutine c_destroy
end module empm_capi
