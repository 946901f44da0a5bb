!> Umbrella module: the public API of empm in one `use empm`.
!>
!> Embedding codes can either drive a case file ([[empm_run_case]]) or assemble a model
!> themselves: grid, particles, shape family, materials, loads and constraints, then
!> [[empm_solve]] with an integrator. Extension points: [[empm_shape_t]],
!> [[empm_material_t]], [[empm_integrator_t]] (families registered in an [[empm_registry_t]]).
!> Every name exported here carries the `empm_`/`EMPM_` prefix (renamed on export where the
!> defining module uses a short name), so that a host code's own names never clash.
module empm
  use empm_kinds, only: empm_wp => wp, empm_pi => pi
  use empm_version_info, only: empm_version
  use empm_error, only: empm_error_t, EMPM_OK, EMPM_ERR_USAGE, EMPM_ERR_INPUT, &
                        EMPM_ERR_RUNTIME, EMPM_ERR_IO, EMPM_ERR_INTERRUPTED
  use empm_tensor, only: empm_voigt_to_mat => voigt_to_mat, empm_mat_to_voigt => mat_to_voigt
  use empm_grid, only: empm_grid_t
  use empm_nodes, only: empm_nodes_t
  use empm_particles, only: empm_particles_t
  use empm_particle_gen, only: empm_fill, EMPM_GEOM_BOX => GEOM_BOX, EMPM_GEOM_DISK => GEOM_DISK, &
                               EMPM_PLACE_GAUSS => PLACE_GAUSS, EMPM_PLACE_VOXEL => PLACE_VOXEL
  use empm_shape, only: empm_shape_t, empm_basis_t, empm_shape_status_text => shape_status_text, &
                        EMPM_SHAPE_OK => SHAPE_OK, EMPM_BASIS_LISTS => BASIS_LISTS, &
                        EMPM_BASIS_Q4 => BASIS_Q4, EMPM_BASIS_B9 => BASIS_B9, &
                        EMPM_BASIS_B27 => BASIS_B27, EMPM_BASIS_G9 => BASIS_G9, &
                        EMPM_BASIS_G27 => BASIS_G27, EMPM_BASIS_Q8 => BASIS_Q8
  use empm_shape_lme, only: empm_shape_lme_t, EMPM_LME_REMEDY_NONE => LME_REMEDY_NONE, &
                            EMPM_LME_REMEDY_ENLARGE => LME_REMEDY_ENLARGE
  use empm_lme_legacy, only: empm_lme_basis
  use empm_material, only: empm_material_t
  use empm_loads, only: empm_loads_t, empm_body_force_t, EMPM_RAMP_NONE => RAMP_NONE, &
                        EMPM_RAMP_SINE => RAMP_SINE
  use empm_model, only: empm_model_t, empm_material_slot_t, empm_step_status_t, &
                        EMPM_STEP_OK => STEP_OK
  use empm_integrator, only: empm_integrator_t
  use empm_registry, only: empm_registry_t, empm_default_registry, empm_create_shape, &
                           empm_create_material, empm_create_integrator
  use empm_params, only: empm_param_t, empm_param, EMPM_PARAM_REAL => PARAM_REAL, &
                         EMPM_PARAM_INT => PARAM_INT, EMPM_PARAM_STR => PARAM_STR, &
                         EMPM_PARAM_LOGICAL => PARAM_LOGICAL
  use empm_namelist, only: empm_group_t, empm_group_from_text, empm_kv
  use empm_family, only: empm_family_t
  use empm_history, only: empm_history_t, empm_snapshot_t
  use empm_solver, only: empm_run_config_t, empm_solve, empm_stable_dt, empm_energies, &
    empm_run_hook_t, empm_solver_state_t
  use empm_output, only: empm_write_results, empm_output_meta_t
  use empm_driver, only: empm_run_case
  use empm_comm, only: empm_comm_t, empm_comm_world, empm_comm_serial, empm_comm_from_handle, &
                       empm_comm_handle_problem, EMPM_MPI_BUILT
  use empm_partition, only: empm_partition_particles, empm_gather_particles
  implicit none
  private
  ! Kinds, version, errors
  public :: empm_wp, empm_pi, empm_version, empm_error_t
  public :: EMPM_OK, EMPM_ERR_USAGE, EMPM_ERR_INPUT, EMPM_ERR_RUNTIME, EMPM_ERR_IO, &
            EMPM_ERR_INTERRUPTED
  public :: empm_voigt_to_mat, empm_mat_to_voigt
  ! Discretisation
  public :: empm_grid_t, empm_nodes_t, empm_particles_t
  public :: empm_fill, EMPM_GEOM_BOX, EMPM_GEOM_DISK, EMPM_PLACE_GAUSS, EMPM_PLACE_VOXEL
  public :: empm_shape_t, empm_basis_t, empm_shape_status_text, EMPM_SHAPE_OK, EMPM_BASIS_LISTS
  public :: EMPM_BASIS_Q4, EMPM_BASIS_Q8, EMPM_BASIS_B9, EMPM_BASIS_B27, EMPM_BASIS_G9, &
            EMPM_BASIS_G27
  public :: empm_shape_lme_t, EMPM_LME_REMEDY_NONE, EMPM_LME_REMEDY_ENLARGE, empm_lme_basis
  ! Materials and loads
  public :: empm_material_t
  public :: empm_loads_t, empm_body_force_t, EMPM_RAMP_NONE, EMPM_RAMP_SINE
  ! Model, integrators, solver, output
  public :: empm_model_t, empm_material_slot_t, empm_step_status_t, EMPM_STEP_OK
  public :: empm_integrator_t
  ! Families: registry, parameter declarations, case-file groups
  public :: empm_family_t, empm_registry_t, empm_default_registry, empm_create_shape
  public :: empm_create_material, empm_create_integrator
  public :: empm_param_t, empm_param, EMPM_PARAM_REAL, EMPM_PARAM_INT, EMPM_PARAM_STR
  public :: EMPM_PARAM_LOGICAL, empm_group_t, empm_group_from_text, empm_kv
  public :: empm_history_t, empm_snapshot_t
  public :: empm_run_config_t, empm_solve, empm_stable_dt, empm_energies
  public :: empm_run_hook_t, empm_solver_state_t
  ! Processes (MPI builds; one process otherwise): docs/parallel.md
  public :: empm_comm_t, empm_comm_world, empm_comm_serial, empm_comm_from_handle
  public :: empm_comm_handle_problem, EMPM_MPI_BUILT
  public :: empm_partition_particles, empm_gather_particles
  public :: empm_write_results, empm_output_meta_t, empm_run_case
end module empm
