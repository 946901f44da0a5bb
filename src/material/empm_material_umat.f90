!> The `umat` material: an adapter that calls an Abaqus-style user material subroutine (UMAT)
!> loaded at run time from a shared library named in the case file.
!>
!> The library is loaded once, in `configure` ([[empm_dynlib]]); a missing library or symbol is
!> an input error quoting the loader's message. Each step, for each particle, the adapter
!>
!> 1. rotates the stress and the total strain with the step's Cayley rotation Q (the formula and
!>    operations of [[jaumann_rotate]], as the native rate-form models) and passes Q as DROT;
!> 2. converts to the Abaqus conventions: components 11, 22, 33, 12, 13, 23 (empm stores xx, yy,
!>    zz, yz, xz, xy), engineering shear strains in STRAN and DSTRAN; 3D: NDI = 3, NSHR = 3;
!>    2D plane strain and 1D uniaxial strain: NDI = 3, NSHR = 1 (in 1D the shears stay zero);
!> 3. calls the UMAT with DSTRAN = Δt sym(L) turned by half the step's rotation (the native
!>    models' increment, [[corotated_increment]]; as Abaqus, the increment of the midpoint
!>    configuration seen in the end one), DFGRD0 = F at the start, DFGRD1 = F advanced with L
!>    (F₁ = F₀ + Δt L F₀; with the midpoint form of `pc_newmark` and `gen_alpha`,
!>    F₁ = (I − ½ΔtL)⁻¹(I + ½ΔtL) F₀, [[empm_plasticity]]), TIME = t (step time = total
!>    time), DTIME = Δt, KSTEP = 1, KINC = the step number, NOEL = the particle's id (generation order; the batch index when the caller gives
!>    no ids), NPT = LAYER = KSPT = 1, CELENT = the smallest grid spacing, COORDS = 0 (the
!>    material interface carries no positions), TEMP = DTEMP = 0;
!> 4. checks the result: a non-finite STRESS, a write past STATEV(NSTATV) (guard values after
!>    the state variables) or PNEWDT < 1 even at the smallest sub-increment fail the particle;
!>    PNEWDT < 1 otherwise discards the attempt (it ran on copies) and retries the step in k
!>    equal sub-increments (k ≥ k_previous/PNEWDT and ≥ 2 k_previous, at most UMAT_MAX_SUB); a
!>    particle whose step was cut adds 1 to its state variable `umat_cuts`.
!>
!> The density follows ρ ← ρ/J with J the step's [[volume_ratio]], as in the native rate-form
!> models. State variables:
!> STATEV(1..NSTATV) as `statev1..statevN`, then SSE, SPD, SCD (carried between increments, as
!> Abaqus does) as `umat_sse`, `umat_spd`, `umat_scd`, then `umat_cuts`. The stored energy
!> density reported for the energy balance is SSE (energy per unit volume in the Abaqus
!> convention). The CFL wave speed comes from `E`/`nu` or `wave_modulus` given in the case file:
!> the adapter cannot know the UMAT's stiffness before calling it.
module empm_material_umat
  use, intrinsic :: iso_c_binding, only: c_ptr, c_funptr, c_double, c_int, c_char, c_size_t, &
    c_f_procpointer, c_null_ptr, c_null_funptr, c_associated, c_loc
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_params, only: empm_param_t, empm_param, PARAM_REAL, PARAM_INT, PARAM_STR, &
    PARAM_LOGICAL
  use empm_namelist, only: empm_group_t
  use empm_material, only: empm_material_t, empm_material_ctx_t, STATE_NAME_LEN
  use empm_material_linear_elastic, only: empm_lame
  use empm_plasticity, only: corotated_increment, volume_ratio, midpoint_increment
  use empm_dynlib, only: empm_dynlib_open, empm_dynlib_symbol
  use empm_files, only: empm_path_beside
  implicit none
  private
  public :: empm_umat_t, UMAT_MAX_PROPS, UMAT_MAX_SUB

  integer, parameter :: UMAT_MAX_PROPS = 100 !! most material constants (PROPS) in a case file
  integer, parameter :: UMAT_MAX_SUB = 64    !! most sub-increments of a step cut by PNEWDT
  integer, parameter :: MAX_STATEV = 1000    !! most state variables (NSTATV)
  integer, parameter :: NGUARD = 8           !! guard values after STATEV(NSTATV)
  integer, parameter :: NEXTRA = 4           !! sse, spd, scd, cuts after the STATEV rows
  integer, parameter :: CMNAME_LEN = 80      !! CHARACTER*80 CMNAME
  !> Guard value: a quiet NaN with a payload no arithmetic produces, compared bit for bit.
  integer(int64), parameter :: GUARD_BITS = int(z'7FF8E3A1C0DE5EED', int64)

  ! Why the last failing particle failed (for failure_text).
  integer, parameter :: WHY_VOLUME = 1, WHY_NONFINITE = 2, WHY_NSTATV = 3, WHY_PNEWDT = 4

  !> The Abaqus UMAT argument list as gfortran's external `SUBROUTINE UMAT` receives it: every
  !> argument by reference, CMNAME's length appended by value (size_t, gfortran ≥ 8).
  abstract interface
    subroutine umat_iface(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
        stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, ntens, &
        nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, npt, layer, &
        kspt, kstep, kinc, cmname_len) bind(C)
      import :: c_double, c_int, c_char, c_size_t
      real(c_double), intent(inout) :: stress(*)   !! STRESS(NTENS)
      real(c_double), intent(inout) :: statev(*)   !! STATEV(NSTATV)
      real(c_double), intent(inout) :: ddsdde(*)   !! DDSDDE(NTENS, NTENS)
      real(c_double), intent(inout) :: sse         !! specific elastic strain energy
      real(c_double), intent(inout) :: spd         !! plastic dissipation
      real(c_double), intent(inout) :: scd         !! creep dissipation
      real(c_double), intent(inout) :: rpl         !! volumetric heat generation
      real(c_double), intent(inout) :: ddsddt(*)   !! DDSDDT(NTENS)
      real(c_double), intent(inout) :: drplde(*)   !! DRPLDE(NTENS)
      real(c_double), intent(inout) :: drpldt      !! d RPL / d T
      real(c_double), intent(inout) :: stran(*)    !! STRAN(NTENS)
      real(c_double), intent(inout) :: dstran(*)   !! DSTRAN(NTENS)
      real(c_double), intent(inout) :: time(*)     !! TIME(2)
      real(c_double), intent(inout) :: dtime       !! time increment
      real(c_double), intent(inout) :: temp        !! temperature
      real(c_double), intent(inout) :: dtemp       !! its increment
      real(c_double), intent(inout) :: predef(*)   !! predefined fields
      real(c_double), intent(inout) :: dpred(*)    !! their increments
      character(kind=c_char), intent(inout) :: cmname(*) !! CHARACTER*80 CMNAME
      integer(c_int), intent(inout) :: ndi         !! direct components
      integer(c_int), intent(inout) :: nshr        !! shear components
      integer(c_int), intent(inout) :: ntens       !! NDI + NSHR
      integer(c_int), intent(inout) :: nstatv      !! state variables
      real(c_double), intent(inout) :: props(*)    !! PROPS(NPROPS) (a copy)
      integer(c_int), intent(inout) :: nprops      !! material constants
      real(c_double), intent(inout) :: coords(*)   !! COORDS(3)
      real(c_double), intent(inout) :: drot(*)     !! DROT(3,3)
      real(c_double), intent(inout) :: pnewdt      !! suggested Δt ratio
      real(c_double), intent(inout) :: celent      !! characteristic length
      real(c_double), intent(inout) :: dfgrd0(*)   !! DFGRD0(3,3)
      real(c_double), intent(inout) :: dfgrd1(*)   !! DFGRD1(3,3)
      integer(c_int), intent(inout) :: noel        !! element (particle) number
      integer(c_int), intent(inout) :: npt         !! integration point
      integer(c_int), intent(inout) :: layer       !! layer
      integer(c_int), intent(inout) :: kspt        !! section point
      integer(c_int), intent(inout) :: kstep       !! step number
      integer(c_int), intent(inout) :: kinc        !! increment number
      integer(c_size_t), value :: cmname_len       !! hidden length of CMNAME
    end subroutine umat_iface
  end interface

  !> The same subroutine with each argument's address passed as a value: the same calling
  !> sequence as [[umat_iface]] (an address by value is a reference), used by the common path.
  !> Its addresses are taken once per batch (the arguments are the same variables for every
  !> particle) and pushed as they are: by reference, each was recomputed and spilled at every
  !> call (about 100 instructions, half of what the elastic test UMAT executes).
  abstract interface
    subroutine umat_at_iface(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, &
        drpldt, stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, &
        ntens, nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, npt, &
        layer, kspt, kstep, kinc, cmname_len) bind(C)
      import :: c_ptr, c_size_t
      type(c_ptr), value, intent(in) :: stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt
      type(c_ptr), value, intent(in) :: drplde, drpldt, stran, dstran, time, dtime, temp, dtemp
      type(c_ptr), value, intent(in) :: predef, dpred, cmname, ndi, nshr, ntens, nstatv, props
      type(c_ptr), value, intent(in) :: nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1
      type(c_ptr), value, intent(in) :: noel, npt, layer, kspt, kstep, kinc
      integer(c_size_t), value, intent(in) :: cmname_len !! hidden length of CMNAME
    end subroutine umat_at_iface
  end interface

  !> The UMAT's arguments for a batch: the adapter's copies (the UMAT receives them by
  !> reference, and a careless one may write to any of them). Fixed sizes: no allocation in the
  !> time loop, and an overrun of STATEV past the guards still lands in `statev` (up to
  !> MAX_STATEV + NGUARD values). No default values: a local of the type is not cleared on
  !> every batch.
  !> STRESS, STRAN, DSTRAN, DROT, DFGRD0 and DFGRD1 are not here: they are the particle's
  !> (prepared a chunk at a time in `update_batch`, or in `increments`).
  type :: umat_args_t
    real(wp) :: statev(MAX_STATEV + NGUARD), ddsdde(36), sse, spd, scd, rpl
    real(wp) :: ddsddt(6), drplde(6), drpldt, time(2), dtime, temp
    real(wp) :: dtemp, predef(1), dpred(1)
    character(kind=c_char) :: cmname(CMNAME_LEN)
    integer(c_int) :: ndi, nshr, ntens, nstatv
    real(wp) :: props(UMAT_MAX_PROPS)
    integer(c_int) :: nprops
    real(wp) :: coords(3), pnewdt, celent
    integer(c_int) :: noel, npt, layer, kspt, kstep, kinc
    !> The addresses of the 37 arguments, in order, for [[umat_at_iface]]. Here, in the record
    !> whose addresses the UMAT receives, so that the compiler reads them from memory at each
    !> call: it may not assume that they survive the previous one, and does not recompute and
    !> spill them (as it did for a local array, whose values it knew).
    type(c_ptr) :: at(37)
  end type umat_args_t

  !> Adapter to a user material subroutine with the Abaqus UMAT argument list.
  type, extends(empm_material_t) :: empm_umat_t
    character(len=:), allocatable :: library   !! library path as opened
    character(len=:), allocatable :: symbol    !! symbol name
    character(len=80) :: cmname = ' '          !! CMNAME: the material's name, upper case
    real(wp), allocatable :: props(:)          !! PROPS
    integer :: nstatv = 0                      !! NSTATV
    logical :: thread_safe = .false.           !! the UMAT may run concurrently
    logical :: uses_stran = .true.             !! keep STRAN rotated with the material
    logical :: uses_dfgrd = .true.             !! advance F for DFGRD1
    real(wp) :: lambda = 0.0_wp                !! Lamé λ for the CFL bound [Pa]
    real(wp) :: mu = 0.0_wp                    !! shear modulus for the CFL bound [Pa]
    type(c_ptr) :: handle = c_null_ptr         !! loaded library (kept open for the run)
    type(c_funptr) :: fun = c_null_funptr      !! the UMAT
    integer, pointer :: why => null()          !! reason of the last failure (WHY_*); a
                                               !! pointer so that `update` (self intent(in))
                                               !! can record it
  contains
    procedure :: configure => um_configure
    procedure :: family => um_family
    procedure :: summary => um_summary
    procedure :: params => um_params
    procedure :: update => um_update
    procedure :: wave_speed => um_wave_speed
    procedure :: energy_density => um_energy_density
    procedure :: state_names => um_state_names
    procedure :: failure_text => um_failure_text
  end type empm_umat_t

contains

  !> Registry name "umat".
  pure function um_family(self) result(s)
    class(empm_umat_t), intent(in) :: self !! material
    character(len=:), allocatable :: s     !! "umat"
    associate (unused_ => self); end associate
    s = 'umat'
  end function um_family

  !> One-line description.
  pure function um_summary(self) result(s)
    class(empm_umat_t), intent(in) :: self !! material
    character(len=:), allocatable :: s     !! summary
    associate (unused_ => self); end associate
    s = 'user material subroutine with the Abaqus UMAT argument list, loaded from a shared ' &
      //'library at run time'
  end function um_summary

  !> Parameters: `library`, `symbol`, `props`, `nstatv`, `density`, `E`, `nu`, `wave_modulus`,
  !> `thread_safe`, `uses_stran`, `uses_dfgrd`.
  pure function um_params(self) result(p)
    class(empm_umat_t), intent(in) :: self !! material
    type(empm_param_t), allocatable :: p(:) !! declarations
    associate (unused_ => self); end associate
    p = [ &
      empm_param('library', PARAM_STR, '-', "shared library holding the UMAT, relative to " &
        //"the case file's folder (or absolute)"), &
      empm_param('symbol', PARAM_STR, '-', "external name of the subroutine in the library " &
        //"(gfortran names SUBROUTINE UMAT 'umat_')", default="'umat_'"), &
      empm_param('props', PARAM_REAL, '-', 'material constants passed as PROPS (NPROPS = ' &
        //'the number given)', count=UMAT_MAX_PROPS, optional=.true.), &
      empm_param('nstatv', PARAM_INT, '-', 'number of state variables STATEV (output as ' &
        //'state/statev1..)', default='0', lo=0.0_wp, hi=real(MAX_STATEV, wp)), &
      empm_param('density', PARAM_REAL, 'kg/m3', 'initial density', lo=1.0e-30_wp, &
        hi=1.0e30_wp), &
      empm_param('E', PARAM_REAL, 'Pa', "Young's modulus bounding the UMAT's stiffness, for " &
        //'the CFL time step (give E or wave_modulus)', lo=0.0_wp, lo_open=.true., &
        hi=1.0e30_wp, optional=.true.), &
      empm_param('nu', PARAM_REAL, '-', "Poisson's ratio with E, for the CFL time step", &
        default='0', lo=-1.0_wp, hi=0.5_wp, lo_open=.true., hi_open=.true.), &
      empm_param('wave_modulus', PARAM_REAL, 'Pa', 'P-wave modulus bounding the UMAT''s ' &
        //'stiffness (lambda + 2 mu), for the CFL time step, instead of E and nu', &
        lo=0.0_wp, lo_open=.true., hi=1.0e30_wp, optional=.true.), &
      empm_param('thread_safe', PARAM_LOGICAL, '-', 'the UMAT may be called concurrently ' &
        //'(no SAVEd or COMMON data); when false the calls are serialised', &
        default='.false.'), &
      empm_param('uses_stran', PARAM_LOGICAL, '-', 'the UMAT reads STRAN: the total strain ' &
        //'is rotated with the stress every step (false: it is accumulated unrotated, as the ' &
        //'native models store it, and passed as such; saves a rotation per particle)', &
        default='.true.'), &
      empm_param('uses_dfgrd', PARAM_LOGICAL, '-', 'the UMAT reads DFGRD0/DFGRD1: F is ' &
        //'advanced every step (false: F is left unchanged, as by the native rate-form ' &
        //'models, and passed as both)', default='.true.')]
  end function um_params

  !> Read the keys, load the library and look the symbol up.
  subroutine um_configure(self, group, err)
    class(empm_umat_t), intent(inout) :: self  !! material
    type(empm_group_t), intent(inout) :: group !! the `&material` group
    type(empm_error_t), intent(inout) :: err   !! set on a missing or invalid value, a missing
                                               !! library or symbol
    type(empm_param_t), allocatable :: p(:)
    character(len=:), allocatable :: lib, msg, name
    real(wp) :: props(UMAT_MAX_PROPS), E, nu, m
    integer :: nprops, i
    allocate(p, source=self%params())
    lib = ''
    self%symbol = 'umat_'
    props = 0.0_wp; nprops = 0
    E = 0.0_wp; nu = 0.0_wp; m = 0.0_wp
    call group%get(p(1), lib, err)
    call group%get(p(2), self%symbol, err)
    call group%get(p(3), props, nprops, err)
    call group%get(p(4), self%nstatv, err)
    call group%get(p(5), self%rho0, err)
    call group%get(p(6), E, err)
    call group%get(p(7), nu, err)
    call group%get(p(8), m, err)
    call group%get(p(9), self%thread_safe, err)
    call group%get(p(10), self%uses_stran, err)
    call group%get(p(11), self%uses_dfgrd, err)
    if (err%code /= 0) return
    self%props = props(1:nprops)
    ! The stiffness bound for the CFL step: exactly one of E (with nu) and wave_modulus.
    if (group%has('wave_modulus') .and. group%has('E')) then
      call group%fail(err, 'wave_modulus', 'give either E (with nu) or wave_modulus, not both')
      return
    else if (.not. (group%has('wave_modulus') .or. group%has('E'))) then
      call group%fail(err, '', 'E (with nu) or wave_modulus is required: the CFL time step ' &
        //'needs a bound on the UMAT''s stiffness')
      return
    end if
    if (group%has('E')) then
      call empm_lame(E, nu, self%lambda, self%mu)
    else
      self%lambda = m; self%mu = 0.0_wp
    end if
    ! CMNAME: the material's name, upper case as Abaqus passes it.
    name = ''
    call group%get(empm_param('name', PARAM_STR, '-', 'material name', optional=.true.), &
      name, err)
    if (err%code /= 0) return
    self%cmname = name
    do i = 1, len(self%cmname)
      if (self%cmname(i:i) >= 'a' .and. self%cmname(i:i) <= 'z') &
        self%cmname(i:i) = achar(iachar(self%cmname(i:i)) - 32)
    end do
    self%library = case_relative(group%file, lib)
    call empm_dynlib_open(self%library, self%handle, msg)
    if (len(msg) > 0) then
      call group%fail(err, 'library', msg)
      return
    end if
    call empm_dynlib_symbol(self%handle, self%symbol, self%fun, msg)
    if (len(msg) > 0) then
      call group%fail(err, 'symbol', msg)
      return
    end if
    allocate(self%why)
    self%why = 0
  end subroutine um_configure

  ! `file` relative to the folder of the case file (as `&particles file`); './' for a case file
  ! in the working folder, so that dlopen never searches the system's library path.
  pure function case_relative(case_file, file) result(path)
    character(len=:), allocatable, intent(in) :: case_file
    character(len=*), intent(in) :: file
    character(len=:), allocatable :: path
    if (allocated(case_file)) then
      path = empm_path_beside(case_file, file)
      if (index(case_file, '/') > 0) return
    else
      path = trim(adjustl(file))
    end if
    if (len(path) == 0) return
    if (path(1:1) /= '/') path = './'//path
  end function case_relative

  !> State variables: `statev1..statevN`, `umat_sse`, `umat_spd`, `umat_scd`, `umat_cuts`.
  pure subroutine um_state_names(self, names)
    class(empm_umat_t), intent(in) :: self                              !! material
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:) !! names
    integer :: i
    character(len=12) :: buf
    allocate(names(self%nstatv + NEXTRA))
    do i = 1, self%nstatv
      write(buf, '(i0)') i
      names(i) = 'statev'//trim(buf)
    end do
    names(self%nstatv + 1) = 'umat_sse'
    names(self%nstatv + 2) = 'umat_spd'
    names(self%nstatv + 3) = 'umat_scd'
    names(self%nstatv + 4) = 'umat_cuts'
  end subroutine um_state_names

  !> Update `n = size(rho)` particles by calling the UMAT (see the module notes). Unless
  !> `thread_safe`, the batch's calls run in one critical section (legacy UMATs keep SAVEd data).
  !> `info = k > 0`: particle k failed (the first such; its state is left as at the start of the
  !> step, the others are updated); `info = -1`: array extents disagree with n.
  subroutine um_update(self, dt, L, F, strain, stress, state, rho, ctx, info)
    class(empm_umat_t), intent(in) :: self                 !! material
    real(wp), intent(in) :: dt                             !! time step [s]
    real(wp), intent(in), contiguous :: L(:,:,:)           !! velocity gradient (3,3,n) [1/s]
    real(wp), intent(inout), contiguous :: F(:,:,:)        !! deformation gradient (3,3,n)
    real(wp), intent(inout), contiguous :: strain(:,:)     !! strain, Voigt (6,n), rotated with
                                                           !! the stress (Abaqus's STRAN)
    real(wp), intent(inout), contiguous :: stress(:,:)     !! Cauchy stress, Voigt (6,n) [Pa]
    real(wp), intent(inout), contiguous :: state(:,:)      !! STATEV, SSE, SPD, SCD, cuts
    real(wp), intent(inout), contiguous :: rho(:)          !! density (n) [kg/m³]
    type(empm_material_ctx_t), intent(in) :: ctx           !! time, step, batch position
    integer, intent(out) :: info                           !! 0 ok; k > 0 particle k failed
    integer :: n
    info = 0
    n = size(rho)
    if (size(L, 3) /= n .or. size(F, 3) /= n .or. size(strain, 2) /= n &
        .or. size(stress, 2) /= n .or. size(state, 2) /= n &
        .or. size(state, 1) < self%nstatv + NEXTRA) then
      info = -1
      return
    end if
    if (self%thread_safe) then
      call update_batch(self, dt, n, L, F, strain, stress, size(state, 1), state, rho, ctx, info)
    else
      !$omp critical (empm_umat_calls)
      call update_batch(self, dt, n, L, F, strain, stress, size(state, 1), state, rho, ctx, info)
      !$omp end critical (empm_umat_calls)
    end if
  end subroutine um_update

  ! The particles of a batch, a chunk at a time: pass 1 prepares every particle's STRESS, STRAN,
  ! DSTRAN, DROT and DFGRD1, pass 2 calls the UMAT on them particle after particle and stores
  ! what it accepts; a refused increment (PNEWDT < 1) is retried from the particle's unchanged
  ! state in more sub-increments (`increments`).
  !
  ! Written for the cost around the call, which was most of what the adapter did (more than
  ! twice the time of the elastic test UMAT): the rotation's chain of dependent products no
  ! longer waits between two calls; explicit-shape particle arrays (fixed strides, no descriptors); no internal
  ! procedures (host association kept the variables they touch in a frame record in memory,
  ! reloaded after each store to an argument); the UMAT's addresses taken once per batch and
  ! pushed as they are ([[umat_at_iface]]); statev copied without a call of memcpy; one test of
  ! the guards and the stress when all is well.
  subroutine update_batch(self, dt, n, L, F, strain, stress, lds, state, rho, ctx, info)
    class(empm_umat_t), intent(in) :: self
    real(wp), intent(in) :: dt
    integer, intent(in) :: n, lds
    real(wp), intent(in) :: L(3,3,n)
    real(wp), intent(inout), target :: F(3,3,n)
    real(wp), intent(inout) :: strain(6,n), stress(6,n), state(lds,n), rho(n)
    type(empm_material_ctx_t), intent(in) :: ctx
    integer, intent(inout) :: info
    type(umat_args_t), target :: a
    procedure(umat_at_iface), pointer :: umat_at
    ! A chunk is a stress block of the integrator: its arguments stay in cache.
    integer, parameter :: CHUNK = 32
    ! Per particle of the chunk: the UMAT's STRESS, STRAN, DSTRAN (Abaqus order), DROT, DFGRD1
    ! (or the copy of F passed as both DFGRD0 and DFGRD1), the strain after an accepted step,
    ! 1 + tr Δε (the volume ratio) and ρ's divisor (stays 1 for a particle that failed).
    real(wp), target :: sigc(6, CHUNK), stranc(6, CHUNK), dstranc(6, CHUNK)
    real(wp), target :: drotc(3, 3, CHUNK), f1c(3, 3, CHUNK)
    real(wp) :: epc(6, CHUNK), vr(CHUNK), jac(CHUNK)
    real(wp) :: d(6), d1, d2, d3, d4, d5, d6, t, hdt, a3, cq, ct, st, s1, s2, s6, e1, e2, e6
    real(wp) :: r1, r2, pn
    integer(int64) :: x
    integer :: p, p0, m, j, k, why, nsv, ntens, i, first
    logical :: rs, rf
    nsv = self%nstatv
    t = ctx%t; first = ctx%first
    rs = self%uses_stran; rf = self%uses_dfgrd
    hdt = 0.5_wp * dt
    call umat_args_init(self, ctx, a)
    ntens = a%ntens
    call c_f_procpointer(self%fun, umat_at)
    do p0 = 1, n, CHUNK
    m = min(n - p0 + 1, CHUNK)

    ! Pass 1, the arguments, for the chunk. Its iterations are independent, so that their
    ! latencies overlap (the rotation's dependent products, a division); in the pass of the
    ! calls they would add up particle after particle.
    do j = 1, m
      p = p0 + j - 1
      d1 = dt * L(1,1,p)
      d2 = dt * L(2,2,p)
      d3 = dt * L(3,3,p)
      d4 = hdt * (L(2,3,p) + L(3,2,p)) ! 0.5 Δt once: the same product
      d5 = hdt * (L(1,3,p) + L(3,1,p))
      d6 = hdt * (L(1,2,p) + L(2,1,p))
      vr(j) = 1.0_wp + (d1 + d2 + d3)
      if (ctx%midpoint) vr(j) = volume_ratio(dt, L(:,:,p), .true.)
      if (L(3,2,p) /= L(2,3,p) .or. L(1,3,p) /= L(3,1,p) .or. L(2,1,p) /= L(1,2,p)) then
        ! With spin, Δε turned by half the step's rotation, as the native models' increment.
        d = corotated_increment(dt, L(:,:,p))
        d1 = d(1); d2 = d(2); d3 = d(3); d4 = d(4); d5 = d(5); d6 = d(6)
      end if
      jac(j) = 1.0_wp
      if (ntens == 4 .and. L(3,2,p) == L(2,3,p) .and. L(1,3,p) == L(3,1,p)) then
        ! Plane strain and 1D (spin about z alone): the closed form of `rotate` written
        ! straight into the Abaqus order, scalar by scalar; Q = I when a₃ = 0 (not the
        ! rotation by the identity, which may change the sign of a zero), c = 2/(1 + a₃²) as
        ! in jaumann_rotate.
        a3 = 0.25_wp * dt * (L(2,1,p) - L(1,2,p))
        cq = 2.0_wp / (1.0_wp + a3**2)
        s1 = stress(1,p); s2 = stress(2,p); s6 = stress(6,p)
        e1 = strain(1,p); e2 = strain(2,p); e6 = strain(6,p)
        if (a3 /= 0.0_wp) then
          ct = 1.0_wp - cq * a3**2; st = cq * a3
          r1 = ct * ct * s1 - 2.0_wp * ct * st * s6 + st * st * s2
          r2 = st * st * s1 + 2.0_wp * ct * st * s6 + ct * ct * s2
          s6 = ct * st * (s1 - s2) + (ct * ct - st * st) * s6
          s1 = r1; s2 = r2
          if (rs) then
            r1 = ct * ct * e1 - 2.0_wp * ct * st * e6 + st * st * e2
            r2 = st * st * e1 + 2.0_wp * ct * st * e6 + ct * ct * e2
            e6 = ct * st * (e1 - e2) + (ct * ct - st * st) * e6
            e1 = r1; e2 = r2
          end if
        else
          ct = 1.0_wp; st = 0.0_wp
        end if
        sigc(1, j) = s1; sigc(2, j) = s2; sigc(3, j) = stress(3,p); sigc(4, j) = s6
        stranc(1, j) = e1; stranc(2, j) = e2; stranc(3, j) = strain(3,p)
        stranc(4, j) = 2.0_wp * e6
        dstranc(1, j) = d1; dstranc(2, j) = d2; dstranc(3, j) = d3
        dstranc(4, j) = 2.0_wp * d6
        ! Past NTENS = 4: defined, though no UMAT reads them.
        sigc(5, j) = 0.0_wp; sigc(6, j) = 0.0_wp; stranc(5, j) = 0.0_wp; stranc(6, j) = 0.0_wp
        dstranc(5, j) = 0.0_wp; dstranc(6, j) = 0.0_wp
        epc(1, j) = e1 + d1; epc(2, j) = e2 + d2; epc(3, j) = strain(3,p) + d3
        epc(4, j) = strain(4,p) + d4; epc(5, j) = strain(5,p) + d5; epc(6, j) = e6 + d6
        drotc(1, 1, j) = ct; drotc(2, 1, j) = st; drotc(3, 1, j) = 0.0_wp
        drotc(1, 2, j) = -st; drotc(2, 2, j) = ct; drotc(3, 2, j) = 0.0_wp
        drotc(1, 3, j) = 0.0_wp; drotc(2, 3, j) = 0.0_wp; drotc(3, 3, j) = 1.0_wp
      else
        call prepare_general(ntens, dt, rs, L(:,:,p), stress(:,p), strain(:,p), &
          [d1, d2, d3, d4, d5, d6], sigc(:, j), stranc(:, j), dstranc(:, j), drotc(:, :, j), &
          epc(:, j))
      end if
      ! DFGRD1: F advanced with L (DFGRD0 is the particle's F); or F unchanged, a copy
      ! passed as both (a careless UMAT writing to them does not change the particle's F).
      if (rf .and. ctx%midpoint) then
        f1c(:,:,j) = matmul(midpoint_increment(dt, L(:,:,p)), F(:,:,p))
      else if (rf) then
        call advance(a%ntens, dt, L(:,:,p), F(:,:,p), f1c(:,:,j))
      else
        f1c(:,:,j) = F(:,:,p)
      end if
    end do

    ! Pass 2, the calls, particle after particle: the particle is written only when the UMAT's
    ! result is accepted (a refused step is rerun below from the particle's unchanged values).
    do j = 1, m
      p = p0 + j - 1
      if (vr(j) <= 0.0_wp) then ! as the native models: an inverted particle
        call record_failure(self, p, WHY_VOLUME, info)
        cycle
      end if
      a%at(1) = c_loc(sigc(1, j)); a%at(11) = c_loc(stranc(1, j))
      a%at(12) = c_loc(dstranc(1, j)); a%at(27) = c_loc(drotc(1, 1, j))
      a%at(31) = c_loc(f1c(1, 1, j))
      if (rf) then
        a%at(30) = c_loc(F(1, 1, p))
      else
        a%at(30) = a%at(31)
      end if
      ! STATEV, SSE, SPD, SCD from the particle. Two values an iteration: a plain copy loop is
      ! compiled to a call of memcpy, which costs more than the copy of a few values.
      do i = 1, nsv - 1, 2
        a%statev(i) = state(i,p); a%statev(i + 1) = state(i + 1,p)
      end do
      if (iand(nsv, 1) == 1) a%statev(nsv) = state(nsv,p)
      a%sse = state(nsv + 1,p); a%spd = state(nsv + 2,p); a%scd = state(nsv + 3,p)
      a%time = t
      a%dtime = dt
      a%pnewdt = 1.0e36_wp ! "no limit": a UMAT lowers it to ask for a smaller increment
      if (p <= ctx%nid) then
        a%noel = int(ctx%id(p), c_int)
      else
        a%noel = int(first + p - 1, c_int)
      end if
      associate (r => a%at)
        call umat_at(r(1), r(2), r(3), r(4), r(5), r(6), r(7), r(8), r(9), r(10), r(11), r(12), &
          r(13), r(14), r(15), r(16), r(17), r(18), r(19), r(20), r(21), r(22), r(23), r(24), &
          r(25), r(26), r(27), r(28), r(29), r(30), r(31), r(32), r(33), r(34), r(35), r(36), &
          r(37), int(CMNAME_LEN, c_size_t))
      end associate
      ! The verdict's test (`verdict`, which names the reason, runs only when it fails).
      x = ior(guards_changed(a%statev(nsv + 1:nsv + NGUARD)), nonfinite_stress(ntens, sigc(:, j)))
      if (x == 0) then
        if (.not. (a%pnewdt < 1.0_wp)) then
          call from_abaqus(a%ntens, sigc(:, j), stress(:,p))
          strain(:,p) = epc(:, j)
          if (rf) F(:,:,p) = f1c(:,:,j)
          do i = 1, nsv - 1, 2
            state(i,p) = a%statev(i); state(i + 1,p) = a%statev(i + 1)
          end do
          if (iand(nsv, 1) == 1) state(nsv,p) = a%statev(nsv)
          state(nsv + 1,p) = a%sse; state(nsv + 2,p) = a%spd; state(nsv + 3,p) = a%scd
          jac(j) = vr(j)
          cycle
        end if
      end if
      why = verdict(a%statev(nsv + 1:nsv + NGUARD), ntens, sigc(:, j), a%pnewdt)
      if (why /= WHY_PNEWDT) then
        call record_failure(self, p, why, info)
        cycle
      end if
      ! Refused: the step again from the particle's unchanged values, in k sub-increments.
      pn = a%pnewdt
      k = min(UMAT_MAX_SUB, max(2, ceiling(1.0_wp / max(pn, 1.0_wp / UMAT_MAX_SUB))))
      ! Δε as in pass 1 (not from DSTRAN, which a careless UMAT may have changed)
      d = corotated_increment(dt, L(:,:,p))
      do
        call increments(self, a, t, dt, L(:,:,p), d, ctx%midpoint, stress(:,p), strain(:,p), &
          F(:,:,p), state(1:nsv + NEXTRA, p), k, why, pn)
        if (why /= WHY_PNEWDT .or. k >= UMAT_MAX_SUB) exit
        ! At least the ratio asked for, and at least twice as many as refused.
        k = min(UMAT_MAX_SUB, max(2 * k, &
          ceiling(real(k, wp) / max(pn, 1.0_wp / UMAT_MAX_SUB))))
      end do
      if (why /= 0) then
        call record_failure(self, p, why, info)
        cycle
      end if
      if (k > 1) state(nsv + NEXTRA, p) = state(nsv + NEXTRA, p) + 1.0_wp
      jac(j) = vr(j)
    end do
    ! The density ρ ← ρ/(1 + tr Δε), for the chunk in one vectorised division; a particle that
    ! failed keeps ρ (divided by 1).
    rho(p0:p0 + m - 1) = rho(p0:p0 + m - 1) / jac(1:m)
    end do
  end subroutine update_batch

  ! The batch's constant arguments (copies: the UMAT receives them by reference and a careless
  ! one may write to them), the outputs the adapter does not use, and the guards after
  ! STATEV(NSTATV): set once per batch (the guards are checked after every call, and a changed
  ! one ends the batch's use).
  subroutine umat_args_init(self, ctx, a)
    class(empm_umat_t), intent(in) :: self
    type(empm_material_ctx_t), intent(in) :: ctx
    type(umat_args_t), intent(inout), target :: a
    integer :: i, np
    np = size(self%props)
    a%props(1:np) = self%props
    a%props(np + 1:) = 0.0_wp
    do i = 1, CMNAME_LEN
      a%cmname(i) = self%cmname(i:i)
    end do
    a%ndi = 3
    a%nshr = merge(3, 1, ctx%ndim == 3)
    a%ntens = a%ndi + a%nshr
    a%nstatv = int(self%nstatv, c_int); a%nprops = int(np, c_int)
    a%npt = 1; a%layer = 1; a%kspt = 1; a%kstep = 1; a%kinc = int(ctx%step, c_int)
    a%coords = 0.0_wp; a%celent = ctx%h; a%temp = 0.0_wp; a%dtemp = 0.0_wp
    a%predef = 0.0_wp; a%dpred = 0.0_wp
    a%ddsdde = 0.0_wp; a%ddsddt = 0.0_wp; a%drplde = 0.0_wp; a%rpl = 0.0_wp; a%drpldt = 0.0_wp
    do i = self%nstatv + 1, self%nstatv + NGUARD
      a%statev(i) = transfer(GUARD_BITS, 1.0_wp)
    end do
    ! The addresses; those of STRESS (1), STRAN (11), DSTRAN (12), DROT (27), DFGRD0 (30) and
    ! DFGRD1 (31) are set per particle.
    a%at(2) = c_loc(a%statev); a%at(3) = c_loc(a%ddsdde); a%at(4) = c_loc(a%sse)
    a%at(5) = c_loc(a%spd); a%at(6) = c_loc(a%scd); a%at(7) = c_loc(a%rpl)
    a%at(8) = c_loc(a%ddsddt); a%at(9) = c_loc(a%drplde); a%at(10) = c_loc(a%drpldt)
    a%at(13) = c_loc(a%time); a%at(14) = c_loc(a%dtime); a%at(15) = c_loc(a%temp)
    a%at(16) = c_loc(a%dtemp); a%at(17) = c_loc(a%predef); a%at(18) = c_loc(a%dpred)
    a%at(19) = c_loc(a%cmname); a%at(20) = c_loc(a%ndi); a%at(21) = c_loc(a%nshr)
    a%at(22) = c_loc(a%ntens); a%at(23) = c_loc(a%nstatv); a%at(24) = c_loc(a%props)
    a%at(25) = c_loc(a%nprops); a%at(26) = c_loc(a%coords); a%at(28) = c_loc(a%pnewdt)
    a%at(29) = c_loc(a%celent); a%at(32) = c_loc(a%noel); a%at(33) = c_loc(a%npt)
    a%at(34) = c_loc(a%layer); a%at(35) = c_loc(a%kspt); a%at(36) = c_loc(a%kstep)
    a%at(37) = c_loc(a%kinc)
  end subroutine umat_args_init

  ! Particle p failed for `code` (WHY_*): info names the batch's first failure.
  subroutine record_failure(self, p, code, info)
    class(empm_umat_t), intent(in) :: self
    integer, intent(in) :: p, code
    integer, intent(inout) :: info
    if (info == 0) info = p
    !$omp atomic write
    self%why = code
  end subroutine record_failure

  ! STRESS, STRAN, DSTRAN, DROT for one particle in the general case (3D, or a spin not about z
  ! alone): Q from step_rotation, the stress (and the strain when `rs`) rotated, the Abaqus
  ! order; epn = the strain after the step.
  pure subroutine prepare_general(ntens, dt, rs, Lp, sp, ep, de, sig, stran, dstran, drot, epn)
    integer, intent(in) :: ntens
    real(wp), intent(in) :: dt, Lp(3,3), sp(6), ep(6), de(6)
    logical, intent(in) :: rs
    real(wp), intent(out) :: sig(6), stran(6), dstran(6), drot(3,3), epn(6)
    real(wp) :: s(6), e(6)
    logical :: spin
    s = sp; e = ep
    call step_rotation(dt, Lp, drot, spin)
    if (spin) then
      call rotate(drot, s)
      if (rs) call rotate(drot, e)
    end if
    call to_abaqus(int(ntens, c_int), s, 1.0_wp, sig)
    call to_abaqus(int(ntens, c_int), e, 2.0_wp, stran)
    call to_abaqus(int(ntens, c_int), de, 2.0_wp, dstran)
    epn = e + de
  end subroutine prepare_general

  ! What a UMAT call returned: WHY_NSTATV when it wrote past STATEV(NSTATV) (the guards, checked
  ! bit for bit), WHY_NONFINITE for a non-finite stress, WHY_PNEWDT when it asked for a smaller
  ! increment, else 0.
  pure integer function verdict(guards, ntens, sg, pnew) result(why)
    real(wp), intent(in) :: guards(NGUARD), sg(6), pnew
    integer, intent(in) :: ntens
    why = 0
    if (guards_changed(guards) /= 0) then
      why = WHY_NSTATV
    else if (nonfinite_stress(ntens, sg) /= 0) then
      why = WHY_NONFINITE
    else if (pnew < 1.0_wp) then
      why = WHY_PNEWDT
    end if
  end function verdict

  ! Nonzero when a guard after STATEV(NSTATV) is no longer GUARD_BITS: the differences or-ed,
  ! without a branch per value.
  pure integer(int64) function guards_changed(guards) result(g)
    real(wp), intent(in) :: guards(NGUARD)
    integer :: i
    g = 0
    do i = 1, NGUARD
      g = ior(g, ieor(transfer(guards(i), GUARD_BITS), GUARD_BITS))
    end do
  end function guards_changed

  ! Nonzero when a component of STRESS(1:NTENS) is Inf or NaN ([[nonfinite]], or-ed).
  pure integer(int64) function nonfinite_stress(ntens, sg) result(x)
    integer, intent(in) :: ntens
    real(wp), intent(in) :: sg(6)
    x = ior(ior(nonfinite(sg(1)), nonfinite(sg(2))), ior(nonfinite(sg(3)), nonfinite(sg(4))))
    if (ntens == 6) x = ior(x, ior(nonfinite(sg(5)), nonfinite(sg(6))))
  end function nonfinite_stress

  ! One particle's step in k equal sub-increments, on local copies that are stored only when
  ! every sub-increment succeeded (so a refusal or a failure leaves the particle as it was).
  ! why = 0 on success, else WHY_* (pnewdt then holds the UMAT's ratio when it refused).
  ! Explicit-shape dummies: the particle's values are then plain memory, not sections.
  subroutine increments(self, a, t, dt, Lp, de, mid, sp, ep, Fp, stp, k, why, pnewdt)
    class(empm_umat_t), intent(in) :: self
    type(umat_args_t), intent(inout) :: a
    real(wp), intent(in) :: t, dt, Lp(3,3), de(6)
    logical, intent(in) :: mid
    real(wp), intent(inout) :: sp(6), ep(6), Fp(3,3), stp(self%nstatv + NEXTRA)
    integer, intent(in) :: k
    integer, intent(out) :: why
    real(wp), intent(out) :: pnewdt
    procedure(umat_iface), pointer :: umat
    real(wp) :: h, dsub(6), drot(3,3), F0(3,3), F1(3,3), sig(6), stran(6), dstran(6)
    real(wp) :: s(6), e(6)
    integer :: j, i, nsv
    logical :: spin
    call c_f_procpointer(self%fun, umat)
    nsv = self%nstatv
    h = dt / k
    if (k == 1) then
      dsub = de
    else
      dsub = corotated_increment(h, Lp)
    end if
    s = sp; e = ep; F0 = Fp
    do i = 1, nsv
      a%statev(i) = stp(i)
    end do
    a%sse = stp(nsv + 1); a%spd = stp(nsv + 2); a%scd = stp(nsv + 3)
    why = 0; pnewdt = 1.0_wp
    call step_rotation(h, Lp, drot, spin)
    do j = 1, k
      if (spin) then
        call rotate(drot, s)
        if (self%uses_stran) call rotate(drot, e)
      end if
      if (self%uses_dfgrd .and. mid) then
        F1 = matmul(midpoint_increment(h, Lp), F0)
      else if (self%uses_dfgrd) then
        call advance(a%ntens, h, Lp, F0, F1)
      else
        F1 = F0
      end if
      call to_abaqus(a%ntens, s, 1.0_wp, sig)
      call to_abaqus(a%ntens, e, 2.0_wp, stran)
      call to_abaqus(a%ntens, dsub, 2.0_wp, dstran)
      a%time = t + (j - 1) * h
      a%dtime = h
      pnewdt = 1.0e36_wp ! "no limit": a UMAT lowers it to ask for a smaller increment
      call umat(sig, a%statev, a%ddsdde, a%sse, a%spd, a%scd, a%rpl, a%ddsddt, a%drplde, &
        a%drpldt, stran, dstran, a%time, a%dtime, a%temp, a%dtemp, a%predef, a%dpred, &
        a%cmname, a%ndi, a%nshr, a%ntens, a%nstatv, a%props, a%nprops, a%coords, drot, &
        pnewdt, a%celent, F0, F1, a%noel, a%npt, a%layer, a%kspt, a%kstep, a%kinc, &
        int(CMNAME_LEN, c_size_t))
      why = verdict(a%statev(nsv + 1:nsv + NGUARD), int(a%ntens), sig, pnewdt)
      if (why /= 0) return
      call from_abaqus(a%ntens, sig, s)
      e = e + dsub
      F0 = F1
    end do
    sp = s; ep = e; Fp = F0
    do i = 1, nsv
      stp(i) = a%statev(i)
    end do
    stp(nsv + 1) = a%sse; stp(nsv + 2) = a%spd; stp(nsv + 3) = a%scd
  end subroutine increments

  ! The step's rotation Q = (I − ½ΔtW)⁻¹(I + ½ΔtW), W = skew(L), with the formula of
  ! jaumann_rotate in empm_plasticity, which the native rate-form models use: the UMAT's stress
  ! is rotated as theirs. spin = false when W = 0 (Q = I). A spin about z alone (every 2D
  ! step) gives the in-plane rotation cos = 1 − c a₃², sin = c a₃ and Q₃₃ = 1 exactly.
  pure subroutine step_rotation(dt, L, Q, spin)
    real(wp), intent(in) :: dt, L(3,3)
    real(wp), intent(out) :: Q(3,3)
    logical, intent(out) :: spin
    real(wp) :: a(3), c
    integer :: i, j
    a(1) = 0.25_wp * dt * (L(3,2) - L(2,3))
    a(2) = 0.25_wp * dt * (L(1,3) - L(3,1))
    a(3) = 0.25_wp * dt * (L(2,1) - L(1,2))
    Q = 0.0_wp
    Q(1,1) = 1.0_wp; Q(2,2) = 1.0_wp; Q(3,3) = 1.0_wp
    if (a(1) == 0.0_wp .and. a(2) == 0.0_wp) then
      spin = a(3) /= 0.0_wp
      if (.not. spin) return
      c = 2.0_wp / (1.0_wp + a(3)**2)
      Q(1,1) = 1.0_wp - c * a(3)**2; Q(2,2) = Q(1,1)
      Q(2,1) = c * a(3); Q(1,2) = -Q(2,1)
      return
    end if
    spin = .true.
    c = 2.0_wp / (1.0_wp + a(1)**2 + a(2)**2 + a(3)**2)
    do j = 1, 3
      do i = 1, 3
        Q(i,j) = c * a(i) * a(j)
      end do
    end do
    Q(1,1) = Q(1,1) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(2,2) = Q(2,2) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(3,3) = Q(3,3) + 1.0_wp - c * (a(1)**2 + a(2)**2 + a(3)**2)
    Q(1,2) = Q(1,2) - c * a(3); Q(2,1) = Q(2,1) + c * a(3)
    Q(1,3) = Q(1,3) + c * a(2); Q(3,1) = Q(3,1) - c * a(2)
    Q(2,3) = Q(2,3) - c * a(1); Q(3,2) = Q(3,2) + c * a(1)
  end subroutine step_rotation

  ! t ← Q t Qᵀ for a symmetric tensor in Voigt form (tensor shears), as jaumann_rotate does: for
  ! an in-plane Q (Q₁₃ = Q₂₃ = Q₃₁ = Q₃₂ = 0, Q₃₃ = 1: every 2D step) its closed form with
  ! cos = Q₁₁, sin = Q₂₁, otherwise Q (t Qᵀ) and the symmetric part.
  pure subroutine rotate(Q, t)
    real(wp), intent(in) :: Q(3,3)
    real(wp), intent(inout) :: t(6)
    real(wp) :: T3(3,3), R(3,3), ct, st, t11, t22, t12, t13
    if (Q(1,3) == 0.0_wp .and. Q(2,3) == 0.0_wp .and. Q(3,1) == 0.0_wp .and. &
        Q(3,2) == 0.0_wp .and. Q(3,3) == 1.0_wp) then
      ct = Q(1,1); st = Q(2,1)
      t11 = ct * ct * t(1) - 2.0_wp * ct * st * t(6) + st * st * t(2)
      t22 = st * st * t(1) + 2.0_wp * ct * st * t(6) + ct * ct * t(2)
      t12 = ct * st * (t(1) - t(2)) + (ct * ct - st * st) * t(6)
      t13 = ct * t(5) - st * t(4)
      t(4) = st * t(5) + ct * t(4)
      t(1) = t11; t(2) = t22; t(5) = t13; t(6) = t12
      return
    end if
    T3(1,1) = t(1); T3(2,2) = t(2); T3(3,3) = t(3)
    T3(2,3) = t(4); T3(3,2) = t(4)
    T3(1,3) = t(5); T3(3,1) = t(5)
    T3(1,2) = t(6); T3(2,1) = t(6)
    R = matmul(Q, matmul(T3, transpose(Q)))
    t(1) = R(1,1); t(2) = R(2,2); t(3) = R(3,3)
    t(4) = 0.5_wp * (R(2,3) + R(3,2))
    t(5) = 0.5_wp * (R(1,3) + R(3,1))
    t(6) = 0.5_wp * (R(1,2) + R(2,1))
  end subroutine rotate

  ! F₁ = F₀ + Δt L F₀ (as advance_f in empm_tensor, here to be inlined). In plane strain L
  ! and F have no 13, 23, 31, 32 entries and F₃₃ stays: only the in-plane block changes.
  pure subroutine advance(ntens, dt, L, F0, F1)
    integer(c_int), intent(in) :: ntens
    real(wp), intent(in) :: dt, L(3,3), F0(3,3)
    real(wp), intent(out) :: F1(3,3)
    integer :: i, j
    if (ntens == 4) then
      F1 = F0
      do j = 1, 2
        do i = 1, 2
          F1(i,j) = F0(i,j) + dt * (L(i,1) * F0(1,j) + L(i,2) * F0(2,j))
        end do
      end do
      return
    end if
    do j = 1, 3
      do i = 1, 3
        F1(i,j) = F0(i,j) + dt * (L(i,1) * F0(1,j) + L(i,2) * F0(2,j) + L(i,3) * F0(3,j))
      end do
    end do
  end subroutine advance

  ! empm Voigt (xx, yy, zz, yz, xz, xy) → Abaqus (11, 22, 33, 12, 13, 23) with the shears
  ! scaled by `g` (2 for engineering strains); NTENS = 4 keeps 12 only.
  pure subroutine to_abaqus(ntens, v, g, a)
    integer(c_int), intent(in) :: ntens
    real(wp), intent(in) :: v(6), g
    real(wp), intent(out) :: a(6)
    a(1:3) = v(1:3)
    a(4) = g * v(6)
    a(5) = g * v(5)
    a(6) = g * v(4)
    if (ntens == 4) a(5:6) = 0.0_wp
  end subroutine to_abaqus

  pure subroutine from_abaqus(ntens, a, v)
    integer(c_int), intent(in) :: ntens
    real(wp), intent(in) :: a(6)
    real(wp), intent(inout) :: v(6)
    v(1:3) = a(1:3)
    v(6) = a(4)
    if (ntens == 6) then
      v(5) = a(5); v(4) = a(6)
    end if
  end subroutine from_abaqus

  ! 1 when x is Inf or NaN (its 11 exponent bits all set: the exponent field + 1 carries into
  ! bit 11), else 0. By its bits: no floating-point comparison, so no invalid-operation flag
  ! (trapped in Debug builds) for a NaN the UMAT returned, and no branch (a stress's values are
  ! or-ed, then tested once).
  elemental integer(int64) function nonfinite(x)
    real(wp), intent(in) :: x
    integer(int64), parameter :: EXPONENT_BITS = int(z'7FF0000000000000', int64)
    nonfinite = ishft(ishft(iand(transfer(x, 1_int64), EXPONENT_BITS), -52) + 1, -11)
  end function nonfinite

  !> P-wave speed sqrt((λ + 2μ)/ρ) from the case's `E`/`nu` or `wave_modulus` [m/s].
  pure real(wp) function um_wave_speed(self, rho)
    class(empm_umat_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho            !! current density [kg/m³]
    um_wave_speed = sqrt((self%lambda + 2.0_wp * self%mu) / rho)
  end function um_wave_speed

  !> Stored energy density: the UMAT's SSE (energy per unit volume, Abaqus's convention).
  pure subroutine um_energy_density(self, F, strain, stress, state, psi)
    class(empm_umat_t), intent(in) :: self !! material
    real(wp), intent(in) :: F(:,:,:)       !! deformation gradient (3,3,n), unused
    real(wp), intent(in) :: strain(:,:)    !! strain (6,n), unused
    real(wp), intent(in) :: stress(:,:)    !! stress (6,n), unused
    real(wp), intent(in) :: state(:,:)     !! state variables, row nstatv+1 is SSE
    real(wp), intent(out) :: psi(:)        !! SSE (n) [J/m³]
    integer :: p
    associate (unused_ => F, unused2_ => strain, unused3_ => stress); end associate
    do p = 1, min(size(psi), size(state, 2))
      psi(p) = state(self%nstatv + 1, p)
    end do
  end subroutine um_energy_density

  !> Why the UMAT adapter stopped a particle.
  function um_failure_text(self) result(s)
    class(empm_umat_t), intent(in) :: self !! material
    character(len=:), allocatable :: s     !! reason
    character(len=12) :: buf
    integer :: why
    why = 0
    if (associated(self%why)) why = self%why
    select case (why)
    case (WHY_NONFINITE)
      s = 'the UMAT returned a non-finite stress'
    case (WHY_NSTATV)
      write(buf, '(i0)') self%nstatv
      s = 'the UMAT wrote past STATEV(NSTATV) with NSTATV = '//trim(buf)// &
        ': nstatv in the case file is smaller than the number of state variables the UMAT uses'
    case (WHY_PNEWDT)
      write(buf, '(i0)') UMAT_MAX_SUB
      s = 'the UMAT asked for a smaller increment (PNEWDT < 1) even with the step cut into ' &
        //trim(buf)//' sub-increments'
    case default
      s = 'its volume ratio became <= 0 (e.g. det F <= 0: the particle is inverted)'
    end select
  end function um_failure_text
end module empm_material_umat
