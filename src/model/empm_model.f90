!> The state of one MPM simulation: grid, nodal fields, particles, basis, shape family,
!> materials and loads. No global state: everything a step needs lives here.
module empm_model
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_nodes, only: empm_nodes_t
  use empm_particles, only: empm_particles_t
  use empm_shape, only: empm_shape_t, empm_basis_t
  use empm_material, only: empm_material_t
  use empm_loads, only: empm_loads_t
  implicit none
  private
  public :: empm_model_t, empm_material_slot_t, empm_step_status_t
  public :: STEP_OK, STEP_SHAPE_FAILED, STEP_MATERIAL_FAILED

  integer, parameter :: STEP_OK = 0              !! step succeeded
  integer, parameter :: STEP_SHAPE_FAILED = 1    !! a particle's shape functions failed
  integer, parameter :: STEP_MATERIAL_FAILED = 2 !! a particle's stress update failed

  !> A material and a name for it.
  type :: empm_material_slot_t
    character(len=:), allocatable :: label           !! user label
    class(empm_material_t), allocatable :: model     !! constitutive model
  end type empm_material_slot_t

  !> Outcome of one time step.
  type :: empm_step_status_t
    integer :: code = STEP_OK   !! STEP_* code
    integer :: detail = 0       !! SHAPE_* code, or the failing particle's material index
    integer :: particle = 0     !! offending particle, 0 if none
  end type empm_step_status_t

  !> One simulation.
  type :: empm_model_t
    type(empm_grid_t) :: grid                           !! background grid
    type(empm_nodes_t) :: nodes                         !! nodal fields and constraints
    type(empm_particles_t) :: pts                       !! material points
    type(empm_basis_t) :: basis                         !! shape functions at the particles
    class(empm_shape_t), allocatable :: shape           !! shape-function family
    type(empm_material_slot_t), allocatable :: mats(:)  !! materials, indexed by pts%mat
    type(empm_loads_t) :: loads                         !! external loads
    integer, allocatable :: run_first(:)                !! particle runs with one material: first
    integer, allocatable :: run_last(:)                 !! ... last particle of the run
    real(wp) :: t = 0.0_wp                              !! current time [s]
    integer :: step = 0                                 !! steps taken
  contains
    procedure :: finalize_setup => model_finalize_setup
  end type empm_model_t

contains

  !> Prepare the derived data once particles, grid, shape and materials are set: basis storage,
  !> nodal storage, material runs and the empty-node mass threshold. Call before stepping.
  subroutine model_finalize_setup(self)
    class(empm_model_t), intent(inout) :: self !! model
    integer :: p, nrun, np
    np = self%pts%np
    ! Keep constraints set earlier with nodes%fix_box.
    if (.not. allocated(self%nodes%mass) .or. self%nodes%nnode /= self%grid%nnode) &
      call self%nodes%alloc(self%grid)
    call self%nodes%list_fixed()
    call self%basis%alloc(self%grid%ndim, self%shape%max_nodes(self%grid), np, &
                          self%shape%layout(self%grid))
    ! Contiguous runs of particles sharing a material: one batched update per run.
    nrun = 0
    do p = 1, np
      if (p == 1) then
        nrun = nrun + 1
      else if (self%pts%mat(p) /= self%pts%mat(p - 1)) then
        nrun = nrun + 1
      end if
    end do
    if (allocated(self%run_first)) deallocate(self%run_first, self%run_last)
    allocate(self%run_first(nrun), self%run_last(nrun))
    nrun = 0
    do p = 1, np
      if (p == 1) then
        nrun = nrun + 1; self%run_first(nrun) = p
      else if (self%pts%mat(p) /= self%pts%mat(p - 1)) then
        self%run_last(nrun) = p - 1
        nrun = nrun + 1; self%run_first(nrun) = p
      end if
    end do
    if (nrun > 0) self%run_last(nrun) = np
    ! Nodes holding less than this are empty: dividing by their mass would amplify round-off.
    if (np > 0) then
      self%nodes%mass_tol = 1.0e-10_wp * minval(self%pts%m(1:np))
    end if
  end subroutine model_finalize_setup
end module empm_model
