!> Fortran 77 entry points: external names as gfortran gives them by default (lower case and a
!> trailing underscore), explicit-shape arrays, no optional arguments, no module needed by the
!> caller (docs/embedding.md).
!>
!> A model handle is an `INTEGER*8` holding the address of the model (0 = none). Every routine
!> but [[f77_destroy]] ends with an `INTEGER IERR` status (0 or an EMPM_ERR_* code: 1 usage,
!> 2 input, 3 run-time guard, 4 I/O). CHARACTER arguments follow gfortran's calling convention:
!> the length of each is passed by value as a hidden `size_t` after all other arguments, in order;
!> other compilers that pass lengths the same way (Intel, flang, with default options) work too.
!> Only names (field, family, file names) are CHARACTER; no routine returns a string except
!> [[f77_errmsg]] and [[f77_open]], which blank-pad into the caller's variable.
module empm_f77
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_char, c_ptr, c_null_ptr, &
                                         c_int64_t, c_size_t, c_associated
  use empm_kinds, only: wp
  use empm_version_info, only: empm_version
  use empm_lme_legacy, only: empm_lme_basis
  use empm_capi, only: empm_capi_box_t, capi_box, capi_from_case, capi_create, capi_set_shape, &
                       capi_set_integrator, capi_add_material, capi_add_particles, capi_fix_box, &
                       capi_set_time_step, capi_finalize, capi_step, capi_advance_to, &
                       capi_get_field, capi_set_field, capi_energies, capi_write, capi_destroy, &
                       capi_set_gravity, capi_friction_box, capi_set_comm, capi_run_case_comm
  use empm_error, only: EMPM_ERR_USAGE
  implicit none
  private

contains

  !> Handle as an integer and back (the address, so that no table, i.e. no global state).
  function to_ptr(model) result(p)
    integer(c_int64_t), intent(in) :: model !! handle
    type(c_ptr) :: p                        !! address
    p = transfer(model, c_null_ptr)
  end function to_ptr

  !> Inverse of [[to_ptr]].
  function to_int(p) result(model)
    type(c_ptr), intent(in) :: p            !! address
    integer(c_int64_t) :: model             !! handle
    model = transfer(p, model)
  end function to_int

  !> A CHARACTER actual argument (bytes and hidden length) as a Fortran string, trailing
  !> blanks removed.
  function fstr(s, n) result(t)
    character(kind=c_char), intent(in) :: s(*) !! the caller's characters
    integer(c_size_t), intent(in) :: n         !! their number
    character(len=:), allocatable :: t         !! the text
    integer :: i
    allocate(character(len=n) :: t)
    do i = 1, int(n)
      t(i:i) = s(i)
    end do
    t = trim(t)
  end function fstr

  !> Blank-padded copy of `text` into a CHARACTER dummy of length n.
  subroutine fput(text, s, n)
    character(len=*), intent(in) :: text       !! text
    character(kind=c_char), intent(out) :: s(*) !! the caller's variable
    integer(c_size_t), intent(in) :: n         !! its length
    integer :: i
    do i = 1, int(n)
      s(i) = ' '
      if (i <= len(text)) s(i) = text(i:i)
    end do
  end subroutine fput

  !> `CALL EMPM_LME_BASIS(NDIM, NNODES, X, XA, GAMMA, H, TOL0, P, DP, LAMBDA, INFO)`: the LME
  !> basis ([[empm_lme_basis]]) under the name a Fortran 77 caller links against.
  subroutine f77_lme_basis(ndim, nnodes, x, xa, gamma, h, tol0, p, dp, lambda, info) &
      bind(C, name='empm_lme_basis_')
    integer(c_int), intent(in) :: ndim                  !! spatial dimension, 1..3
    integer(c_int), intent(in) :: nnodes                !! number of nodes
    real(c_double), intent(in) :: x(ndim)               !! evaluation point
    real(c_double), intent(in) :: xa(ndim, nnodes)      !! node coordinates
    real(c_double), intent(in) :: gamma                 !! γ = β h² > 0
    real(c_double), intent(in) :: h                     !! nodal spacing
    real(c_double), intent(in) :: tol0                  !! truncation tolerance
    real(c_double), intent(out) :: p(nnodes)            !! values
    real(c_double), intent(out) :: dp(ndim, nnodes)     !! gradients
    real(c_double), intent(inout) :: lambda(ndim)       !! Lagrange multiplier
    integer(c_int), intent(out) :: info                 !! 0 or a code
    call empm_lme_basis(ndim, nnodes, x, xa, gamma, h, tol0, p, dp, lambda, info)
  end subroutine f77_lme_basis

  !> `CALL EMPM_VERSION(V)`: version string, blank-padded.
  subroutine f77_version(v, n) bind(C, name='empm_version_')
    character(kind=c_char), intent(out) :: v(*) !! CHARACTER*(*) result
    integer(c_size_t), value :: n               !! hidden length
    call fput(empm_version(), v, n)
  end subroutine f77_version

  !> `CALL EMPM_CREATE(MODEL, NDIM, ORIGIN, H, NCELL, IERR)`: empty model on a grid.
  subroutine f77_create(model, ndim, origin, h, ncell, ierr) bind(C, name='empm_create_')
    integer(c_int64_t), intent(out) :: model    !! new handle (0 on failure)
    integer(c_int), intent(in) :: ndim          !! spatial dimension
    real(c_double), intent(in) :: origin(ndim)  !! origin
    real(c_double), intent(in) :: h(ndim)       !! cell sizes
    integer(c_int), intent(in) :: ncell(ndim)   !! cells per direction
    integer(c_int), intent(out) :: ierr         !! status
    type(c_ptr) :: p
    character(len=:), allocatable :: msg
    ierr = capi_create(int(ndim), origin, h, ncell, p, msg)
    model = 0
    if (c_associated(p)) model = to_int(p)
  end subroutine f77_create

  !> `CALL EMPM_OPEN(MODEL, PATH, MSG, IERR)`: model from a case file; MSG gets the error text.
  subroutine f77_open(model, path, msg, ierr, npath, nmsg) bind(C, name='empm_open_')
    integer(c_int64_t), intent(out) :: model     !! new handle (0 on failure)
    character(kind=c_char), intent(in) :: path(*) !! case file
    character(kind=c_char), intent(out) :: msg(*) !! error text, blank on success
    integer(c_int), intent(out) :: ierr          !! status
    integer(c_size_t), value :: npath            !! hidden length of PATH
    integer(c_size_t), value :: nmsg             !! hidden length of MSG
    type(c_ptr) :: p
    character(len=:), allocatable :: text
    ierr = capi_from_case(fstr(path, npath), p, text)
    call fput(text, msg, nmsg)
    model = 0
    if (c_associated(p)) model = to_int(p)
  end subroutine f77_open

  !> `CALL EMPM_ERRMSG(MODEL, MSG)`: last error of the model, blank-padded.
  subroutine f77_errmsg(model, msg, n) bind(C, name='empm_errmsg_')
    integer(c_int64_t), intent(in) :: model      !! handle
    character(kind=c_char), intent(out) :: msg(*) !! CHARACTER*(*) result
    integer(c_size_t), value :: n                !! hidden length
    type(empm_capi_box_t), pointer :: b
    b => capi_box(to_ptr(model))
    if (associated(b)) then
      call fput(trim(b%message), msg, n)
    else
      call fput('null empm model handle', msg, n)
    end if
  end subroutine f77_errmsg

  !> `CALL EMPM_SHAPE(MODEL, ID, PARAMS, IERR)`: shape family.
  subroutine f77_shape(model, id, params, ierr, nid, npar) bind(C, name='empm_shape_')
    integer(c_int64_t), intent(in) :: model        !! handle
    character(kind=c_char), intent(in) :: id(*)    !! family identifier
    character(kind=c_char), intent(in) :: params(*) !! keys as text (blank for none)
    integer(c_int), intent(out) :: ierr            !! status
    integer(c_size_t), value :: nid                !! hidden length of ID
    integer(c_size_t), value :: npar               !! hidden length of PARAMS
    ierr = capi_set_shape(capi_box(to_ptr(model)), fstr(id, nid), fstr(params, npar))
  end subroutine f77_shape

  !> `CALL EMPM_INTEG(MODEL, NAME, PARAMS, IERR)`: integrator.
  subroutine f77_integ(model, name, params, ierr, nname, npar) bind(C, name='empm_integ_')
    integer(c_int64_t), intent(in) :: model        !! handle
    character(kind=c_char), intent(in) :: name(*)  !! scheme name
    character(kind=c_char), intent(in) :: params(*) !! keys as text (blank for none)
    integer(c_int), intent(out) :: ierr            !! status
    integer(c_size_t), value :: nname              !! hidden length of NAME
    integer(c_size_t), value :: npar               !! hidden length of PARAMS
    ierr = capi_set_integrator(capi_box(to_ptr(model)), fstr(name, nname), fstr(params, npar))
  end subroutine f77_integ

  !> `CALL EMPM_MATERIAL(MODEL, NAME, PARAMS, ID, IERR)`: add a material, ID its number.
  subroutine f77_material(model, name, params, id, ierr, nname, npar) &
      bind(C, name='empm_material_')
    integer(c_int64_t), intent(in) :: model        !! handle
    character(kind=c_char), intent(in) :: name(*)  !! material model
    character(kind=c_char), intent(in) :: params(*) !! keys as text
    integer(c_int), intent(out) :: id              !! material id
    integer(c_int), intent(out) :: ierr            !! status
    integer(c_size_t), value :: nname              !! hidden length of NAME
    integer(c_size_t), value :: npar               !! hidden length of PARAMS
    integer :: k
    ierr = capi_add_material(capi_box(to_ptr(model)), fstr(name, nname), fstr(params, npar), k)
    id = k
  end subroutine f77_material

  !> `CALL EMPM_PARTICLES(MODEL, N, X, VOL, RHO, MAT, IERR)`: X(NDIM, N).
  subroutine f77_particles(model, n, x, vol, rho, mat, ierr) bind(C, name='empm_particles_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(in) :: n          !! particles
    real(c_double), intent(in) :: x(*)       !! positions, NDIM per particle
    real(c_double), intent(in) :: vol(n)     !! volumes
    real(c_double), intent(in) :: rho(n)     !! densities
    integer(c_int), intent(in) :: mat(n)     !! material ids
    integer(c_int), intent(out) :: ierr      !! status
    type(empm_capi_box_t), pointer :: b
    integer :: d
    b => capi_box(to_ptr(model))
    ierr = EMPM_ERR_USAGE
    if (.not. associated(b) .or. n < 0) return
    d = b%model%grid%ndim
    ierr = capi_add_particles(b, int(n), reshape(x(1:d * n), [d, int(n)]), vol, rho, mat)
  end subroutine f77_particles

  !> `CALL EMPM_FIXBOX(MODEL, LO, HI, MASK, VALUE, NSEL, IERR)`: 3 entries each.
  subroutine f77_fixbox(model, lo, hi, mask, value, nsel, ierr) bind(C, name='empm_fixbox_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(in) :: lo(3)      !! lower corner
    real(c_double), intent(in) :: hi(3)      !! upper corner
    integer(c_int), intent(in) :: mask(3)    !! nonzero: prescribed component
    real(c_double), intent(in) :: value(3)   !! prescribed velocity
    integer(c_int), intent(out) :: nsel      !! nodes selected
    integer(c_int), intent(out) :: ierr      !! status
    integer :: k
    ierr = capi_fix_box(capi_box(to_ptr(model)), lo, hi, int(mask), value, k)
    nsel = k
  end subroutine f77_fixbox

  !> `CALL EMPM_GRAVITY(MODEL, G, IERR)`: constant gravity, 3 entries (the first NDIM used).
  subroutine f77_gravity(model, g, ierr) bind(C, name='empm_gravity_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(in) :: g(3)       !! gravity [m/s²]
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_set_gravity(capi_box(to_ptr(model)), g)
  end subroutine f77_gravity

  !> `CALL EMPM_FRICBOX(MODEL, LO, HI, NORMAL, DELTA, NSEL, IERR)`: a frictional wall at rest
  !> on the nodes of the box (3 entries each), NORMAL = +-axis from the wall into the body,
  !> DELTA the friction angle in degrees.
  subroutine f77_fricbox(model, lo, hi, normal, delta, nsel, ierr) bind(C, name='empm_fricbox_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(in) :: lo(3)      !! lower corner
    real(c_double), intent(in) :: hi(3)      !! upper corner
    integer(c_int), intent(in) :: normal     !! +-axis from the wall into the body
    real(c_double), intent(in) :: delta      !! friction angle [deg]
    integer(c_int), intent(out) :: nsel      !! nodes selected
    integer(c_int), intent(out) :: ierr      !! status
    integer :: k
    ierr = capi_friction_box(capi_box(to_ptr(model)), lo, hi, int(normal), delta, k)
    nsel = k
  end subroutine f77_fricbox

  !> `CALL EMPM_SETCOMM(MODEL, ICOMM, IERR)`: before finalize, run the model on the processes
  !> of the INTEGER communicator ICOMM (mpif.h); every process then makes the same calls and
  !> adds every particle (docs/embedding.md, "MPI"). Called before the first particle, each
  !> process stores only its share of them as they are added.
  subroutine f77_setcomm(model, icomm, ierr) bind(C, name='empm_setcomm_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(in) :: icomm      !! the communicator (Fortran handle)
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_set_comm(capi_box(to_ptr(model)), int(icomm))
  end subroutine f77_setcomm

  !> `CALL EMPM_RUNCOMM(PATH, OUTPUT, ICOMM, MSG, IERR)`: run a case file on the processes of
  !> ICOMM (every one calls); OUTPUT blank for the case's file; MSG the error, blank on success.
  subroutine f77_runcomm(path, output, icomm, msg, ierr, npath, nout, nmsg) &
      bind(C, name='empm_runcomm_')
    character(kind=c_char), intent(in) :: path(*)   !! case file
    character(kind=c_char), intent(in) :: output(*) !! output override or blank
    integer(c_int), intent(in) :: icomm             !! the communicator (Fortran handle)
    character(kind=c_char), intent(out) :: msg(*)   !! error text, blank on success
    integer(c_int), intent(out) :: ierr             !! status
    integer(c_size_t), value :: npath               !! hidden length of PATH
    integer(c_size_t), value :: nout                !! hidden length of OUTPUT
    integer(c_size_t), value :: nmsg                !! hidden length of MSG
    character(len=:), allocatable :: text
    ierr = capi_run_case_comm(fstr(path, npath), fstr(output, nout), int(icomm), text)
    call fput(text, msg, nmsg)
  end subroutine f77_runcomm

  !> `CALL EMPM_TIMESTEP(MODEL, CFL, DT, IERR)`: DT = 0 for CFL times the stable step.
  subroutine f77_timestep(model, cfl, dt, ierr) bind(C, name='empm_timestep_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(in) :: cfl        !! Courant number
    real(c_double), intent(in) :: dt         !! fixed step or 0
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_set_time_step(capi_box(to_ptr(model)), cfl, dt)
  end subroutine f77_timestep

  !> `CALL EMPM_FINALIZE(MODEL, IERR)`.
  subroutine f77_finalize(model, ierr) bind(C, name='empm_finalize_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_finalize(capi_box(to_ptr(model)))
  end subroutine f77_finalize

  !> `CALL EMPM_STEP(MODEL, NSTEP, IERR)`.
  subroutine f77_step(model, nstep, ierr) bind(C, name='empm_step_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(in) :: nstep      !! steps
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_step(capi_box(to_ptr(model)), int(nstep))
  end subroutine f77_step

  !> `CALL EMPM_ADVANCE(MODEL, T, IERR)`: to time T.
  subroutine f77_advance(model, t, ierr) bind(C, name='empm_advance_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(in) :: t          !! target time
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_advance_to(capi_box(to_ptr(model)), t)
  end subroutine f77_advance

  !> `CALL EMPM_INFO(MODEL, NDIM, NP, T, NSTEP, IERR)`.
  subroutine f77_info(model, ndim, np, t, nstep, ierr) bind(C, name='empm_info_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(out) :: ndim      !! dimension
    integer(c_int), intent(out) :: np        !! particles
    real(c_double), intent(out) :: t         !! time
    integer(c_int), intent(out) :: nstep     !! steps taken
    integer(c_int), intent(out) :: ierr      !! status
    type(empm_capi_box_t), pointer :: b
    b => capi_box(to_ptr(model))
    ndim = 0; np = 0; t = 0.0_wp; nstep = 0; ierr = EMPM_ERR_USAGE
    if (.not. associated(b)) return
    ndim = b%model%grid%ndim; np = b%model%pts%np; t = b%model%t; nstep = b%model%step
    ierr = 0
  end subroutine f77_info

  !> `CALL EMPM_GETF(MODEL, FIELD, N, A, IERR)`: particle field into A(N).
  subroutine f77_getf(model, field, n, a, ierr, nf) bind(C, name='empm_getf_')
    integer(c_int64_t), intent(in) :: model       !! handle
    character(kind=c_char), intent(in) :: field(*) !! field name
    integer(c_int), intent(in) :: n               !! size of A
    real(c_double), intent(out) :: a(n)           !! values
    integer(c_int), intent(out) :: ierr           !! status
    integer(c_size_t), value :: nf                !! hidden length of FIELD
    ierr = capi_get_field(capi_box(to_ptr(model)), fstr(field, nf), a, int(n))
  end subroutine f77_getf

  !> `CALL EMPM_SETF(MODEL, FIELD, N, A, IERR)`: particle field from A(N).
  subroutine f77_setf(model, field, n, a, ierr, nf) bind(C, name='empm_setf_')
    integer(c_int64_t), intent(in) :: model       !! handle
    character(kind=c_char), intent(in) :: field(*) !! field name
    integer(c_int), intent(in) :: n               !! size of A
    real(c_double), intent(in) :: a(n)            !! values
    integer(c_int), intent(out) :: ierr           !! status
    integer(c_size_t), value :: nf                !! hidden length of FIELD
    ierr = capi_set_field(capi_box(to_ptr(model)), fstr(field, nf), a, int(n))
  end subroutine f77_setf

  !> `CALL EMPM_STRESS(MODEL, NP, S, IERR)`: stresses S(6, NP) (Voigt xx yy zz yz xz xy),
  !> without a CHARACTER argument.
  subroutine f77_stress(model, np, s, ierr) bind(C, name='empm_stress_')
    integer(c_int64_t), intent(in) :: model  !! handle
    integer(c_int), intent(in) :: np         !! particles (as the model has)
    real(c_double), intent(out) :: s(6, np)  !! stresses [Pa]
    integer(c_int), intent(out) :: ierr      !! status
    real(c_double) :: buf(6 * np)
    ierr = capi_get_field(capi_box(to_ptr(model)), 'stress', buf, 6 * int(np))
    if (ierr == 0) s = reshape(buf, [6, int(np)])
  end subroutine f77_stress

  !> `CALL EMPM_ENERGY(MODEL, EKIN, ESTRAIN, EGRAV, IERR)`.
  subroutine f77_energy(model, ekin, estrain, egrav, ierr) bind(C, name='empm_energy_')
    integer(c_int64_t), intent(in) :: model  !! handle
    real(c_double), intent(out) :: ekin      !! kinetic energy
    real(c_double), intent(out) :: estrain   !! stored energy
    real(c_double), intent(out) :: egrav     !! gravitational potential
    integer(c_int), intent(out) :: ierr      !! status
    ierr = capi_energies(capi_box(to_ptr(model)), ekin, estrain, egrav)
  end subroutine f77_energy

  !> `CALL EMPM_WRITE(MODEL, PATH, IERR)`: HDF5 (+ XDMF) output.
  subroutine f77_write(model, path, ierr, npath) bind(C, name='empm_write_')
    integer(c_int64_t), intent(in) :: model       !! handle
    character(kind=c_char), intent(in) :: path(*) !! output file
    integer(c_int), intent(out) :: ierr           !! status
    integer(c_size_t), value :: npath             !! hidden length of PATH
    ierr = capi_write(capi_box(to_ptr(model)), fstr(path, npath))
  end subroutine f77_write

  !> `CALL EMPM_DESTROY(MODEL)`: free the model; MODEL becomes 0.
  subroutine f77_destroy(model) bind(C, name='empm_destroy_')
    integer(c_int64_t), intent(inout) :: model !! handle
    call capi_destroy(to_ptr(model))
    model = 0
  end subroutine f77_destroy
end module empm_f77
