!> A case: everything read from a case file, ready to run (model, integrator, run controls,
!> probes, output settings) and the values recorded as HDF5 attributes.
module empm_case
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t
  use empm_integrator, only: empm_integrator_t
  use empm_solver, only: empm_run_config_t
  use empm_particle_gen, only: empm_deal_t
  implicit none
  private
  public :: empm_case_t, empm_overrides_t

  !> Changes applied while reading a case (used by the verification suite to run one case file
  !> with several shapes, schemes and resolutions). Unset fields leave the file's value.
  type :: empm_overrides_t
    integer :: refine = 1                        !! multiply `cells` and divide `h` by this
    character(len=:), allocatable :: shape       !! shape identifier, e.g. 'linear', 'lme_g0.8'
    character(len=:), allocatable :: scheme      !! integrator name
    real(wp) :: cfl = -1.0_wp                    !! Courant number (if > 0)
    real(wp) :: dt = -1.0_wp                     !! fixed time step (if > 0)
    real(wp) :: t_end = -1.0_wp                  !! end time (if > 0)
    integer :: ppc = 0                           !! particles per cell of every generated body
                                                 !! (if > 0)
  end type empm_overrides_t

  !> A runnable case.
  type :: empm_case_t
    character(len=:), allocatable :: file            !! case file path
    character(len=:), allocatable :: text            !! full text of the case file
    character(len=:), allocatable :: output_file     !! HDF5 output path
    type(empm_model_t) :: model                      !! simulation state
    class(empm_integrator_t), allocatable :: integ   !! time integrator
    type(empm_run_config_t) :: run                   !! run controls
    character(len=64), allocatable :: probe_name(:)  !! probe names
    integer, allocatable :: probe_particle(:)        !! particle followed by each probe
    character(len=:), allocatable :: shape_name      !! shape family identifier
    character(len=:), allocatable :: scheme_name     !! integrator identifier
    !> The particles generated, and this process's share of them when the case is read to be
    !> shared by place among processes (each stores its share only: body_first..body_last
    !> below are then its own particles of each body).
    type(empm_deal_t) :: deal
    integer :: local = 1                             !! processes of the run on this machine
    ! Bodies (&particles groups, in order): their particles are body_first..body_last.
    character(len=64), allocatable :: body_name(:)   !! body labels ('' when unnamed)
    integer, allocatable :: body_first(:)            !! first particle of each body
    integer, allocatable :: body_last(:)             !! last particle of each body
    real(wp), allocatable :: body_k0(:)              !! K0 of a geostatic body, −1 otherwise
    integer, allocatable :: body_group(:)            !! index of its group in the parsed file
    real(wp), allocatable :: body_lo(:,:)            !! a box body's lower corner (3, nbody)
    real(wp), allocatable :: body_hi(:,:)            !! a box body's upper corner (3, nbody)
    logical, allocatable :: body_box(:)              !! the body is a box
  end type empm_case_t
end module empm_case
