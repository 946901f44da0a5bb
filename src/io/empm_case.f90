!> A case: everything read from a case file, ready to run (model, integrator, run controls,
!> probes, output settings) and the values recorded as HDF5 attributes.
module empm_case
  use empm_kinds, only: wp
  use empm_model, only: empm_model_t
  use empm_integrator, only: empm_integrator_t
  use empm_solver, only: empm_run_config_t
  implicit none
  private
  public :: empm_case_t

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
  end type empm_case_t
end module empm_case
