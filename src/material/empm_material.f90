!> Material extension point: the abstract constitutive model.
!>
!> A model updates a batch of particles (a contiguous range of the particle arrays) from the
!> velocity gradient of the step. Adding a material means adding one file that extends
!> [[empm_material_t]] and registering its prototype (see [[empm_registry]]).
!>
!> A model describes itself ([[empm_family_t]]): its registry name (`family`), a one-line
!> `summary` and its declared parameters (`params`), which `configure` reads from the
!> `&material` group (the common keys `name` and `model` are the reader's, not the model's).
!>
!> Per-particle state variables: a model that needs internal variables (plastic strain, damage,
!> a counter, ...) declares how many (`nstate`), their names (`call state_names(names)`, the
!> names of the output datasets) and their initial values (`init_state`). The particles carry
!> them as `pts%state(nstate_max, np)`, nstate_max being the largest count over the model's
!> materials; `update` and `energy_density` receive the particles' whole column block and the
!> model uses its first `nstate` rows (the others are zero and belong to nobody).
!>
!> Kinematics: 1D is uniaxial strain (only xx is non-zero), 2D is plane strain (zz strain zero,
!> zz stress generally not), 3D is general. Voigt order (xx, yy, zz, yz, xz, xy), tensor shears.
module empm_material
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t
  use empm_family, only: empm_family_t
  use empm_namelist, only: empm_group_t
  implicit none
  private
  public :: empm_material_t, empm_material_ctx_t, STATE_NAME_LEN, CTX_MAX_IDS

  integer, parameter :: STATE_NAME_LEN = 32 !! length of the names given by `state_names`
  integer, parameter :: CTX_MAX_IDS = 64    !! most particle ids a batch context carries

  !> Where and when a batch is updated: what a model may need besides the kinematics (a user
  !> subroutine's element number, time and increment number, a regularisation length).
  type :: empm_material_ctx_t
    real(wp) :: t = 0.0_wp  !! time at the start of the step [s]
    integer :: step = 1     !! number of the step being taken (1 for the first)
    integer :: first = 1    !! particle index of the batch's first particle (1-based, in the
                            !! particle arrays)
    integer :: nid = 0      !! batch size when `id` holds the particles' ids, else 0
    integer :: id(CTX_MAX_IDS) = 0 !! the batch's particle ids (generation order, the same on
                            !! any number of processes; a user subroutine's element number)
    integer :: ndim = 3     !! spatial dimension of the model (1, 2 or 3)
    real(wp) :: h = 0.0_wp  !! smallest grid spacing [m] (0 when there is no grid)
    logical :: midpoint = .false. !! the kinematics' form: .false., the increment of F is
                            !! I + ΔtL; .true. (`pc_newmark`, `gen_alpha` for a `rate_form`
                            !! model), L is the midpoint gradient and the increment is
                            !! (I − ½ΔtL)⁻¹(I + ½ΔtL) ([[empm_plasticity]])
  end type empm_material_ctx_t

  !> Abstract material.
  type, abstract, extends(empm_family_t) :: empm_material_t
    real(wp) :: rho0 = 0.0_wp           !! reference density [kg/m³]
  contains
    procedure(update_iface), deferred :: update
    procedure(wave_speed_iface), deferred :: wave_speed
    procedure(energy_iface), deferred :: energy_density
    procedure(configure_iface), deferred :: configure
    procedure :: name => material_name
    procedure :: nstate => material_nstate
    procedure :: state_names => material_state_names
    procedure :: init_state => material_init_state
    procedure :: failure_text => material_failure_text
    procedure :: max_wave_speed => material_max_wave_speed
    procedure :: rate_form => material_rate_form
  end type empm_material_t

  abstract interface
    !> Advance the state of `n` particles over a step `dt` with velocity gradients `L`.
    !> Updates the deformation gradient, the accumulated strain, the Cauchy stress, the state
    !> variables and the density (rho is updated as the model's kinematics dictate; see each
    !> model). The arrays are contiguous (the particle arrays' sections for a run of particles
    !> are; anything else is copied in and out by the compiler).
    !> Not required to be pure (a user subroutine behind an adapter is not), but it must be
    !> thread-safe: batches of one material are updated concurrently with OpenMP.
    subroutine update_iface(self, dt, L, F, strain, stress, state, rho, ctx, info)
      import :: empm_material_t, empm_material_ctx_t, wp
      class(empm_material_t), intent(in) :: self  !! material
      real(wp), intent(in) :: dt                  !! time step [s]
      real(wp), intent(in), contiguous :: L(:,:,:)         !! velocity gradient (3,3,n) [1/s]
      real(wp), intent(inout), contiguous :: F(:,:,:)      !! deformation gradient (3,3,n)
      real(wp), intent(inout), contiguous :: strain(:,:)   !! small strain, Voigt (6,n)
      real(wp), intent(inout), contiguous :: stress(:,:)   !! Cauchy stress, Voigt (6,n) [Pa]
      real(wp), intent(inout), contiguous :: state(:,:)    !! state variables (nstate_max,n):
                                                           !! the model owns rows 1..nstate
      real(wp), intent(inout), contiguous :: rho(:)        !! density (n) [kg/m³]
      type(empm_material_ctx_t), intent(in) :: ctx         !! time, step, batch position
      integer, intent(out) :: info                !! 0 ok; k > 0: particle k of the batch failed
    end subroutine update_iface

    !> Dilatational (P-) wave speed at density `rho`, used for the CFL time step [m/s].
    pure real(wp) function wave_speed_iface(self, rho)
      import :: empm_material_t, wp
      class(empm_material_t), intent(in) :: self !! material
      real(wp), intent(in) :: rho                !! current density [kg/m³]
    end function wave_speed_iface

    !> Stored energy per unit current volume for `n` particles [J/m³].
    pure subroutine energy_iface(self, F, strain, stress, state, psi)
      import :: empm_material_t, wp
      class(empm_material_t), intent(in) :: self !! material
      real(wp), intent(in) :: F(:,:,:)           !! deformation gradient (3,3,n)
      real(wp), intent(in) :: strain(:,:)        !! small strain (6,n)
      real(wp), intent(in) :: stress(:,:)        !! Cauchy stress (6,n)
      real(wp), intent(in) :: state(:,:)         !! state variables (nstate_max,n), rows
                                                 !! 1..nstate are the model's
      real(wp), intent(out) :: psi(:)            !! energy density per current volume (n)
    end subroutine energy_iface

    !> Read the model's declared parameters (`params`) from the `&material` group, validate
    !> them and set the model up. The common keys `name` and `model` are left to the reader.
    subroutine configure_iface(self, group, err)
      import :: empm_material_t, empm_group_t, empm_error_t
      class(empm_material_t), intent(inout) :: self !! material
      type(empm_group_t), intent(inout) :: group    !! the `&material` group
      type(empm_error_t), intent(inout) :: err      !! set on a missing or invalid value
    end subroutine configure_iface
  end interface

contains

  !> Identifier written to results, e.g. "linear_elastic": the registry name.
  function material_name(self) result(s)
    class(empm_material_t), intent(in) :: self !! material
    character(len=:), allocatable :: s         !! identifier
    s = self%family()
  end function material_name

  !> Number of state variables per particle; the default is the number of `state_names`
  !> (none unless the model declares some).
  pure integer function material_nstate(self) result(n)
    class(empm_material_t), intent(in) :: self !! material
    character(len=STATE_NAME_LEN), allocatable :: names(:)
    call self%state_names(names)
    n = size(names)
  end function material_nstate

  !> Names of the state variables (output dataset names: letters, digits and '_'); the default
  !> is none. A subroutine, not a function: gfortran 12 crashes on type-bound functions that
  !> return character arrays.
  pure subroutine material_state_names(self, names)
    class(empm_material_t), intent(in) :: self                            !! material
    character(len=STATE_NAME_LEN), allocatable, intent(out) :: names(:)   !! one per state
                                                                          !! variable
    associate (unused_ => self); end associate
    allocate(names(0))
  end subroutine material_state_names

  !> Initial values of the state variables of a block of particles; the default is zero.
  pure subroutine material_init_state(self, state)
    class(empm_material_t), intent(in) :: self  !! material
    real(wp), intent(out) :: state(:,:)         !! state variables (nstate, n) of the block
    associate (unused_ => self); end associate
    state = 0.0_wp
  end subroutine material_init_state

  !> Largest P-wave speed over a run of particles of this material, for the CFL time step
  !> (evaluated every step). It must be a maximum over the particles: the stress update asks
  !> it of groups of particles while they are in cache and the time loop takes the largest.
  !> The default is `wave_speed` at the smallest density (wave speeds do not increase with
  !> density); a model whose stiffness depends on the stress or the state (pressure-dependent
  !> elasticity) overrides it.
  pure real(wp) function material_max_wave_speed(self, rho, stress, state) result(c)
    class(empm_material_t), intent(in) :: self !! material
    real(wp), intent(in) :: rho(:)             !! densities of the run (n) [kg/m³]
    real(wp), intent(in) :: stress(:,:)        !! Cauchy stresses (6,n) [Pa]
    real(wp), intent(in) :: state(:,:)         !! state variables (nstate_max,n)
    associate (unused_ => stress, unused2_ => state); end associate
    c = self%wave_speed(minval(rho))
  end function material_max_wave_speed

  !> Whether the model is rate-form (its increments are Δt sym L and a rotation by Δt skw L:
  !> hypoelastic and return-mapping models; the default) rather than F-based (a hyperelastic
  !> model that advances F with I + ΔtL). A scheme whose increment of F is not I + ΔtL for
  !> any L (the trapezoidal drift) gives a rate-form model the midpoint gradient instead,
  !> `ctx%midpoint` set, and an F-based one the L of the exact increment.
  pure logical function material_rate_form(self) result(r)
    class(empm_material_t), intent(in) :: self !! material
    associate (unused_ => self); end associate
    r = .true.
  end function material_rate_form

  !> Why `update` reported a particle as failed (`info = k > 0`), for the run's error message.
  !> The default is the kinematic failure every model shares; a model that can fail otherwise
  !> (a return mapping that does not converge, ...) overrides it.
  function material_failure_text(self) result(s)
    class(empm_material_t), intent(in) :: self !! material
    character(len=:), allocatable :: s         !! reason
    associate (unused_ => self); end associate
    s = 'its volume ratio became <= 0 (e.g. det F <= 0: the particle is inverted)'
  end function material_failure_text
end module empm_material
