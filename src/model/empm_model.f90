!> The state of one MPM simulation: grid, nodal fields, particles, basis, shape family,
!> materials and loads. No global state: everything a step needs lives here.
module empm_model
  use, intrinsic :: iso_fortran_env, only: int64
  use empm_kinds, only: wp
  use empm_error, only: empm_error_t, empm_alloc_error, empm_raise_error, EMPM_ERR_USAGE
  use empm_strings, only: str
  use empm_grid, only: empm_grid_t
  use empm_nodes, only: empm_nodes_t
  use empm_particles, only: empm_particles_t
  use empm_shape, only: empm_shape_t, empm_basis_t
  use empm_material, only: empm_material_t, STATE_NAME_LEN
  use empm_loads, only: empm_loads_t
  use empm_comm, only: empm_comm_t
  use empm_halo, only: empm_halo_t
  implicit none
  private
  public :: empm_model_t, empm_material_slot_t, empm_step_status_t
  public :: STEP_OK, STEP_SHAPE_FAILED, STEP_MATERIAL_FAILED

  integer, parameter :: STEP_OK = 0              !! step succeeded
  integer, parameter :: STEP_SHAPE_FAILED = 1    !! a particle's shape functions failed
  integer, parameter :: STEP_MATERIAL_FAILED = 2 !! a particle's stress update failed

  !> Nodes a window keeps beyond its region on each side, so that it moves only every few
  !> cells of motion ([[model_fit_window]]).
  integer, parameter :: WINDOW_SLACK = 4

  !> A material and a name for it.
  type :: empm_material_slot_t
    character(len=:), allocatable :: label           !! user label
    class(empm_material_t), allocatable :: model     !! constitutive model
  end type empm_material_slot_t

  !> Outcome of one time step.
  type :: empm_step_status_t
    integer :: code = STEP_OK   !! STEP_* code
    integer :: detail = 0       !! SHAPE_* code, or the failing particle's material index
    integer :: particle = 0     !! offending particle (its id: number in generation order),
                                !! 0 if none
    integer :: rank = 0         !! the process that holds it
    integer :: local = 0        !! its index there
  end type empm_step_status_t

  !> One simulation.
  type :: empm_model_t
    type(empm_grid_t) :: grid                           !! background grid; in a parallel run
                                                        !! it stores the window of nodes this
                                                        !! process needs ([[model_fit_window]])
    type(empm_nodes_t) :: nodes                         !! nodal fields and constraints
    type(empm_particles_t) :: pts                       !! material points
    type(empm_basis_t) :: basis                         !! shape functions at the particles
    class(empm_shape_t), allocatable :: shape           !! shape-function family
    type(empm_material_slot_t), allocatable :: mats(:)  !! materials, indexed by pts%mat
    type(empm_loads_t) :: loads                         !! external loads
    type(empm_comm_t) :: comm                           !! the processes sharing the run: each
                                                        !! holds its particles and the window
                                                        !! of the grid they reach
                                                        !! (docs/parallel.md); serial default
    type(empm_halo_t) :: halo                           !! nodal sums over the processes by
                                                        !! neighbour exchange (parallel runs)
    integer, allocatable :: boxes(:,:,:)                !! the processes' boxes of cells,
                                                        !! first and last cell (3, 2, nranks)
    integer, allocatable :: boxes0(:,:,:)               !! the first ones (a static split's)
    integer :: windows = 0                              !! new windows taken ([[model_fit_window]])
    integer :: stored_peak = 0                          !! most grid nodes stored at once by
                                                        !! this process (its windows)
    integer, allocatable :: run_first(:)                !! particle runs with one material: first
    integer, allocatable :: run_last(:)                 !! ... last particle of the run
    real(wp) :: t = 0.0_wp                              !! current time [s]
    integer :: step = 0                                 !! steps taken
    logical :: track = .false.                          !! compute the residual (and the
                                                        !! reactions) at every force assembly
    real(wp) :: residual = -1.0_wp                      !! from the last assembly (with
                                                        !! `track`): ‖f_unbalanced‖/‖f_ext‖,
                                                        !! −1 when unknown or no load acts
    ! What a stress update computes while each block is in cache, for the time loop:
    logical :: want_energy = .false.                    !! set before a step: the stress update
                                                        !! also evaluates the stored energy
                                                        !! densities (into diag_psi)
    integer :: diag_step = -1                           !! the step whose stress update computed
                                                        !! the two below (−1: none)
    logical :: diag_fine = .true.                       !! its screen of the material fields
                                                        !! (stress, strain, state finite;
                                                        !! density, volume finite and > 0)
    real(wp), allocatable :: diag_psi(:)                !! with want_energy, the stored energy
                                                        !! density ψ of each particle after it
                                                        !! (np) [J/m³]; allocated by the
                                                        !! time loop
    real(wp) :: diag_cmax = 0.0_wp                      !! the largest wave speed after it
                                                        !! (`max_wave_speed`) [m/s]
  contains
    procedure :: finalize_setup => model_finalize_setup
    procedure :: set_runs => model_set_runs
    procedure :: fit_window => model_fit_window
    procedure :: share_region => model_share_region
  end type empm_model_t

contains

  !> Prepare the derived data once particles, grid, shape and materials are set: basis storage,
  !> nodal storage, material runs, the empty-node mass threshold, and the particles' state
  !> variables (as many rows as the most demanding material needs, each material's particles
  !> initialised by its `init_state`). Call before stepping; calling it again re-initialises
  !> the state variables. Errors (a material whose `state_names` disagree with `nstate`, a
  !> particle without a material, out of memory) go to `err` when present, which never stops
  !> the program; otherwise they are printed and the program stops.
  subroutine model_finalize_setup(self, err, shared)
    class(empm_model_t), intent(inout) :: self          !! model
    type(empm_error_t), intent(inout), optional :: err  !! set-up error, if present
    logical, intent(in), optional :: shared             !! the particles will be shared among
                                                        !! processes: no basis storage yet
                                                        !! (each process's comes with its
                                                        !! share, [[model_set_runs]])
    type(empm_error_t) :: e
    integer :: nrun, np, nsmax, im, r, ns
    np = self%pts%np
    ! Keep constraints set earlier with nodes%fix_box.
    if (.not. allocated(self%nodes%mass) .or. self%nodes%nnode /= self%grid%nnode) &
      call self%nodes%alloc(self%grid, e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    call self%set_runs(e, basis=.not. opt_flag(shared, .false.))
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    nrun = size(self%run_first)
    ! Nodes holding less than this are empty: dividing by their mass would amplify round-off.
    if (np > 0) then
      self%nodes%mass_tol = 1.0e-10_wp * minval(self%pts%m(1:np))
    end if

    ! State variables: rows for the most demanding material, then each run's initial values.
    nsmax = 0
    if (allocated(self%mats)) then
      do im = 1, size(self%mats)
        if (.not. allocated(self%mats(im)%model)) cycle
        call check_state_names(self%mats(im)%model, im, e)
        if (e%code /= 0) then
          call empm_raise_error(e, err); return
        end if
        nsmax = max(nsmax, self%mats(im)%model%nstate())
      end do
    end if
    if (.not. allocated(self%pts%state) .or. self%pts%nstate /= nsmax) then
      call self%pts%set_nstate(nsmax, e)
      if (e%code /= 0) then
        call empm_raise_error(e, err); return
      end if
    else
      self%pts%state = 0.0_wp ! rows a material does not own stay zero
    end if
    if (nsmax == 0) return
    do r = 1, nrun
      im = self%pts%mat(self%run_first(r))
      if (im < 1 .or. im > size(self%mats)) then
        call e%set(EMPM_ERR_USAGE, 'particle '//str(self%run_first(r))//' has material '// &
          str(im)//', but the model has '//str(size(self%mats))//' materials')
        call empm_raise_error(e, err); return
      end if
      if (.not. allocated(self%mats(im)%model)) then
        call e%set(EMPM_ERR_USAGE, 'material '//str(im)//' is not allocated')
        call empm_raise_error(e, err); return
      end if
      ns = self%mats(im)%model%nstate()
      if (ns > 0) call self%mats(im)%model%init_state( &
        self%pts%state(1:ns, self%run_first(r):self%run_last(r)))
    end do
  end subroutine model_finalize_setup

  !> The particles' basis storage and material runs (contiguous particles sharing a material:
  !> one batched update per run), for the particles the model holds now; set-up, and again
  !> when a process has taken its share of them.
  subroutine model_set_runs(self, err, basis)
    class(empm_model_t), intent(inout) :: self          !! model
    type(empm_error_t), intent(inout), optional :: err  !! allocation failure, if present
    logical, intent(in), optional :: basis              !! allocate the basis storage
                                                        !! (default .true.)
    type(empm_error_t) :: e
    integer :: p, nrun, np, st
    character(len=256) :: msg
    np = self%pts%np
    if (opt_flag(basis, .true.)) &
      call self%basis%alloc(self%grid%ndim, self%shape%max_nodes(self%grid), np, &
                            self%shape%layout(self%grid), e)
    if (e%code /= 0) then
      call empm_raise_error(e, err); return
    end if
    nrun = 0
    do p = 1, np
      if (p == 1) then
        nrun = nrun + 1
      else if (self%pts%mat(p) /= self%pts%mat(p - 1)) then
        nrun = nrun + 1
      end if
    end do
    if (allocated(self%run_first)) deallocate(self%run_first)
    if (allocated(self%run_last)) deallocate(self%run_last)
    st = 0; msg = ''
    allocate(self%run_first(nrun), self%run_last(nrun), stat=st, errmsg=msg)
    if (st /= 0) then
      call empm_raise_error(empm_alloc_error('material runs ('//str(nrun)//')', &
        8_int64 * nrun, trim(msg)), err)
      return
    end if
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
  end subroutine model_set_runs

  !> Parallel runs: the nodes this process's particles reach at their current positions (the
  !> box of their cells widened by the family's reach), agreed with the other processes
  !> ([[empm_halo]]); when the boxes changed, the stored window of the grid is fitted to this
  !> process's region ([[model_fit_window]]) and the exchange plan rebuilt on it. Before every
  !> basis evaluation, and when a process has taken its share of the particles (its first
  !> window). Collective.
  subroutine model_share_region(model)
    class(empm_model_t), intent(inout) :: model !! simulation state (parallel)
    real(wp) :: xlo(3), xhi(3), v
    integer :: lo(3), hi(3), d, p, nd, reach
    logical :: moved
    nd = model%grid%ndim
    reach = model%shape%reach_cells(model%grid)
    ! A traction acts at its face centre, up to a particle's size past the particle.
    if (model%loads%ntraction() > 0) reach = reach + 1
    lo = 0; hi = -1
    if (model%pts%np > 0) then
      xlo = 0.0_wp; xhi = 0.0_wp
      do d = 1, nd
        xlo(d) = huge(1.0_wp); xhi(d) = -huge(1.0_wp)
        do p = 1, model%pts%np
          v = model%pts%x(d, p)
          if (v == v) then ! a NaN is left to the shape functions (min/max would trap it)
            xlo(d) = min(xlo(d), v); xhi(d) = max(xhi(d), v)
          end if
        end do
      end do
      lo = 0; hi = 0
      do d = 1, nd
        ! Node c is at origin + c h: a particle in cell c reaches nodes c − reach .. c + 1 + reach.
        ! Clamped to the grid (and past a non-finite position): a particle outside it is the
        ! shape functions' to report, after this agreement.
        lo(d) = floor((clamp(xlo(d), d) - model%grid%origin(d)) * model%grid%inv_h(d)) - reach
        hi(d) = floor((clamp(xhi(d), d) - model%grid%origin(d)) * model%grid%inv_h(d)) + 1 + reach
      end do
    end if
    call model%halo%update(model%comm, model%grid, lo, hi, reach)
    if (model%halo%replan) then
      call model%fit_window(model%halo%region(:, :, model%comm%rank + 1), moved)
      call model%halo%plan(model%grid)
    end if
    model%stored_peak = max(model%stored_peak, model%grid%nnode)
  contains
    ! A coordinate along d within the grid box (an infinite one, or none: ±huge, too).
    pure real(wp) function clamp(x, d)
      real(wp), intent(in) :: x
      integer, intent(in) :: d
      clamp = min(max(x, model%grid%origin(d)), &
                  model%grid%origin(d) + model%grid%ncell(d) * model%grid%h(d))
    end function clamp
  end subroutine model_share_region

  !> Parallel runs: keep the nodal storage on a window of the grid that holds `region`, the
  !> nodes this process needs (whole-grid 0-based ijk box from [[empm_halo]]; lo > hi: none),
  !> with WINDOW_SLACK nodes to spare on each side. A new window is taken when the region
  !> leaves the current one or lies more than 2 WINDOW_SLACK nodes inside one of its faces;
  !> the nodal fields keep their values on the nodes both windows hold
  !> ([[empm_nodes_t:window]]). `moved`: the stored grid changed (its node numbers with it).
  !> The basis holds node numbers: call before evaluating it.
  subroutine model_fit_window(self, region, moved)
    class(empm_model_t), intent(inout) :: self !! model
    integer, intent(in) :: region(3, 2)        !! the nodes this process needs
    logical, intent(out) :: moved              !! a new window was taken
    type(empm_grid_t) :: new
    integer :: nd, need(3, 2), lim(3, 2), cur(3, 2)
    nd = self%grid%ndim
    moved = .false.
    ! Node-wise data of the shape family is indexed by the whole grid's node ids.
    if (self%shape%node_data()) return
    need = 0; lim = 0
    if (all(region(1:nd, 1) <= region(1:nd, 2))) then
      need(1:nd, :) = region(1:nd, :)
      lim(1:nd, 1) = max(region(1:nd, 1) - 2 * WINDOW_SLACK, 0)
      lim(1:nd, 2) = min(region(1:nd, 2) + 2 * WINDOW_SLACK, self%grid%nn(1:nd) - 1)
    end if
    cur(:, 1) = self%grid%off; cur(:, 2) = self%grid%off + self%grid%ln - 1
    moved = .not. all(cur(1:nd, 1) <= need(1:nd, 1) .and. cur(1:nd, 2) >= need(1:nd, 2) .and. &
                      cur(1:nd, 1) >= lim(1:nd, 1) .and. cur(1:nd, 2) <= lim(1:nd, 2))
    if (.not. moved) return
    if (all(region(1:nd, 1) <= region(1:nd, 2))) then
      new = self%grid%window(need(:, 1) - WINDOW_SLACK, need(:, 2) + WINDOW_SLACK)
    else
      new = self%grid%window(need(:, 1), need(:, 1)) ! no particle: one node
    end if
    call self%nodes%window(self%grid, new)
    self%grid = new
    self%windows = self%windows + 1
  end subroutine model_fit_window

  ! An optional flag's value, `default` when it is absent.
  pure logical function opt_flag(flag, default)
    logical, intent(in), optional :: flag
    logical, intent(in) :: default
    opt_flag = default
    if (present(flag)) opt_flag = flag
  end function opt_flag

  !> A material's state variables must have as many names as `nstate`, each made of letters,
  !> digits and '_' (they name HDF5 datasets and XDMF attributes), without repeats.
  subroutine check_state_names(mat, im, e)
    class(empm_material_t), intent(in) :: mat
    integer, intent(in) :: im
    type(empm_error_t), intent(inout) :: e
    character(len=STATE_NAME_LEN), allocatable :: names(:)
    character(len=*), parameter :: OK = &
      'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_'
    integer :: k
    call mat%state_names(names)
    if (size(names) /= mat%nstate()) then
      call e%set(EMPM_ERR_USAGE, 'material '//str(im)//' ('//mat%name()//') declares '// &
        str(mat%nstate())//' state variables but names '//str(size(names)))
      return
    end if
    do k = 1, size(names)
      if (len_trim(names(k)) == 0 .or. verify(trim(names(k)), OK) > 0 .or. &
          any(names(1:k - 1) == names(k))) then
        call e%set(EMPM_ERR_USAGE, 'material '//str(im)//' ('//mat%name()//'): state '// &
          'variable name '''//trim(names(k))//''' must be unique and made of letters, '// &
          'digits and _')
        return
      end if
    end do
  end subroutine check_state_names
end module empm_model
