!> The registry: the one list of shape-function families, material models and integrators by
!> name, and the one place that creates them from a case-file group.
!>
!> A registry is a value, not global state: [[empm_default_registry]] returns one holding the
!> built-in families, and an embedding code or a test may add its own (`add_shape`,
!> `add_material`, `add_integrator`) and pass it to the case reader. Adding a built-in family is
!> one new file plus one line in [[empm_default_registry]].
!>
!> Creating a family: a copy of its prototype is configured from the group (`configure`, which
!> reads and validates the family's declared parameters), then every key of the group must be
!> one of the family's parameters or one of the caller's common keys (e.g. `name`, `model` of
!> `&material`): anything else is an error naming the file, line, group and key.
!>
!> Shape identifiers: a shape may be named by its family ('lme') or by an identifier that also
!> sets tagged parameters, `family_<tag><value>...` ('lme_g0.8': the parameter with tag 'g',
!> γ, is 0.8), which is what an LME instance's `name()` returns and what results record.
module empm_registry
  use empm_error, only: empm_error_t, EMPM_ERR_USAGE
  use empm_strings, only: lower, str
  use empm_params, only: empm_param_t, empm_params_markdown
  use empm_namelist, only: empm_group_t, empm_group_from_text
  use empm_grid, only: empm_grid_t
  use empm_shape, only: empm_shape_t
  use empm_shape_linear, only: empm_shape_linear_t
  use empm_shape_ugimp, only: empm_shape_ugimp_t
  use empm_shape_bspline, only: empm_shape_bspline_t
  use empm_shape_lme, only: empm_shape_lme_t
  use empm_material, only: empm_material_t
  use empm_material_linear_elastic, only: empm_linear_elastic_t
  use empm_material_neohookean, only: empm_neohookean_t
  use empm_material_drucker_prager, only: empm_drucker_prager_t
  use empm_material_mohr_coulomb, only: empm_mohr_coulomb_t
  use empm_material_camclay, only: empm_camclay_t
  use empm_material_umat, only: empm_umat_t
  use empm_integrator, only: empm_integrator_t
  use empm_integrator_euler, only: empm_euler_t, EULER_USF, EULER_USL, EULER_MUSL
  use empm_integrator_pc, only: empm_pc_t, PC_PUBLISHED, PC_NEWMARK
  use empm_integrator_genalpha, only: empm_genalpha_t, GA_PUBLISHED, GA_PARTICLE
  implicit none
  private
  public :: empm_registry_t, empm_default_registry
  public :: empm_create_shape, empm_create_material, empm_create_integrator

  type :: shape_entry_t
    class(empm_shape_t), allocatable :: proto
  end type shape_entry_t
  type :: material_entry_t
    class(empm_material_t), allocatable :: proto
  end type material_entry_t
  type :: integrator_entry_t
    class(empm_integrator_t), allocatable :: proto
  end type integrator_entry_t

  !> Families by name.
  type :: empm_registry_t
    type(shape_entry_t), allocatable :: shapes(:)           !! shape-function families
    type(material_entry_t), allocatable :: materials(:)     !! material models
    type(integrator_entry_t), allocatable :: integrators(:) !! time integrators
  contains
    procedure :: add_shape => reg_add_shape
    procedure :: add_material => reg_add_material
    procedure :: add_integrator => reg_add_integrator
    procedure :: create_shape => reg_create_shape
    procedure :: create_material => reg_create_material
    procedure :: create_integrator => reg_create_integrator
    procedure :: shape_names => reg_shape_names
    procedure :: material_names => reg_material_names
    procedure :: integrator_names => reg_integrator_names
    procedure :: markdown => reg_markdown
  end type empm_registry_t

contains

  !> The built-in families: the one place that lists them.
  function empm_default_registry() result(reg)
    type(empm_registry_t) :: reg !! registry with every built-in family
    call reg%add_shape(empm_shape_linear_t())
    call reg%add_shape(empm_shape_ugimp_t())
    call reg%add_shape(empm_shape_bspline_t(order=2))
    call reg%add_shape(empm_shape_bspline_t(order=3))
    call reg%add_shape(empm_shape_bspline_t(order=2, clamped=.true.))
    call reg%add_shape(empm_shape_bspline_t(order=3, clamped=.true.))
    call reg%add_shape(empm_shape_lme_t())
    call reg%add_material(empm_linear_elastic_t())
    call reg%add_material(empm_neohookean_t())
    call reg%add_material(empm_drucker_prager_t())
    call reg%add_material(empm_mohr_coulomb_t())
    call reg%add_material(empm_camclay_t())
    call reg%add_material(empm_umat_t())
    call reg%add_integrator(empm_euler_t(variant=EULER_USF))
    call reg%add_integrator(empm_euler_t(variant=EULER_USL))
    call reg%add_integrator(empm_euler_t(variant=EULER_MUSL))
    call reg%add_integrator(empm_pc_t(variant=PC_PUBLISHED))
    call reg%add_integrator(empm_pc_t(variant=PC_NEWMARK))
    call reg%add_integrator(empm_genalpha_t(variant=GA_PUBLISHED))
    call reg%add_integrator(empm_genalpha_t(variant=GA_PARTICLE))
  end function empm_default_registry

  ! ---- convenience, for programs that build a model without a case file ------------------

  !> Create a built-in shape family: `id` as in a case file ('linear', 'lme', 'lme_g0.8'),
  !> `params` the other keys of its `&shape` group as text (e.g. 'gamma = 2, tol0 = 1e-8'; see
  !> [[empm_kv]] for exact numbers). `grid` is the model's grid (only its dimension is needed
  !> unless a parameter refers to nodes, like LME's gamma box).
  subroutine empm_create_shape(id, grid, shape, err, params)
    character(len=*), intent(in) :: id                        !! family or identifier
    type(empm_grid_t), intent(in) :: grid                     !! background grid
    class(empm_shape_t), allocatable, intent(out) :: shape    !! the family, configured
    type(empm_error_t), intent(inout) :: err                  !! set on failure
    character(len=*), intent(in), optional :: params          !! 'key = value, ...'
    type(empm_group_t) :: g
    type(empm_registry_t) :: reg
    call text_group('shape', params, g, err)
    if (err%code /= 0) return
    reg = empm_default_registry()
    call reg%create_shape(id, grid, shape, err, g)
  end subroutine empm_create_shape

  !> Create a built-in material model from its keys as text, e.g.
  !> `empm_create_material('linear_elastic', 'E = 1e7, nu = 0.3, density = 1000', mat, err)`.
  subroutine empm_create_material(model, params, mat, err)
    character(len=*), intent(in) :: model                     !! model name
    character(len=*), intent(in) :: params                    !! 'key = value, ...'
    class(empm_material_t), allocatable, intent(out) :: mat   !! the model, configured
    type(empm_error_t), intent(inout) :: err                  !! set on failure
    type(empm_group_t) :: g
    type(empm_registry_t) :: reg
    call text_group('material', params, g, err)
    if (err%code /= 0) return
    reg = empm_default_registry()
    call reg%create_material(model, mat, err, g)
  end subroutine empm_create_material

  !> Create a built-in integrator, with its keys as text (e.g. 'rho_b = 0.5') if any.
  subroutine empm_create_integrator(scheme, integ, err, params)
    character(len=*), intent(in) :: scheme                      !! scheme name
    class(empm_integrator_t), allocatable, intent(out) :: integ !! the scheme, configured
    type(empm_error_t), intent(inout) :: err                    !! set on failure
    character(len=*), intent(in), optional :: params            !! 'key = value, ...'
    type(empm_group_t) :: g
    type(empm_registry_t) :: reg
    call text_group('integrator', params, g, err)
    if (err%code /= 0) return
    reg = empm_default_registry()
    call reg%create_integrator(scheme, integ, err, g)
  end subroutine empm_create_integrator

  subroutine text_group(name, params, g, err)
    character(len=*), intent(in) :: name
    character(len=*), intent(in), optional :: params
    type(empm_group_t), intent(out) :: g
    type(empm_error_t), intent(inout) :: err
    if (present(params)) then
      call empm_group_from_text('&'//name//' '//params//' /', g, err)
    else
      call empm_group_from_text('&'//name//' /', g, err)
    end if
  end subroutine text_group

  ! ---- adding --------------------------------------------------------------------------------

  !> Add a shape family (its prototype, with default parameters); a family of the same name is
  !> replaced.
  subroutine reg_add_shape(self, proto)
    class(empm_registry_t), intent(inout) :: self !! registry
    class(empm_shape_t), intent(in) :: proto      !! prototype instance
    type(shape_entry_t), allocatable :: tmp(:)
    integer :: k, n
    if (.not. allocated(self%shapes)) allocate(self%shapes(0))
    n = size(self%shapes)
    do k = 1, n
      if (self%shapes(k)%proto%family() == proto%family()) then
        deallocate(self%shapes(k)%proto)
        allocate(self%shapes(k)%proto, source=proto)
        return
      end if
    end do
    allocate(tmp(n + 1))
    do k = 1, n
      call move_alloc(self%shapes(k)%proto, tmp(k)%proto)
    end do
    allocate(tmp(n + 1)%proto, source=proto)
    call move_alloc(tmp, self%shapes)
  end subroutine reg_add_shape

  !> Add a material model (its prototype); a model of the same name is replaced.
  subroutine reg_add_material(self, proto)
    class(empm_registry_t), intent(inout) :: self !! registry
    class(empm_material_t), intent(in) :: proto   !! prototype instance
    type(material_entry_t), allocatable :: tmp(:)
    integer :: k, n
    if (.not. allocated(self%materials)) allocate(self%materials(0))
    n = size(self%materials)
    do k = 1, n
      if (self%materials(k)%proto%family() == proto%family()) then
        deallocate(self%materials(k)%proto)
        allocate(self%materials(k)%proto, source=proto)
        return
      end if
    end do
    allocate(tmp(n + 1))
    do k = 1, n
      call move_alloc(self%materials(k)%proto, tmp(k)%proto)
    end do
    allocate(tmp(n + 1)%proto, source=proto)
    call move_alloc(tmp, self%materials)
  end subroutine reg_add_material

  !> Add an integrator (its prototype); a scheme of the same name is replaced.
  subroutine reg_add_integrator(self, proto)
    class(empm_registry_t), intent(inout) :: self !! registry
    class(empm_integrator_t), intent(in) :: proto !! prototype instance
    type(integrator_entry_t), allocatable :: tmp(:)
    integer :: k, n
    if (.not. allocated(self%integrators)) allocate(self%integrators(0))
    n = size(self%integrators)
    do k = 1, n
      if (self%integrators(k)%proto%family() == proto%family()) then
        deallocate(self%integrators(k)%proto)
        allocate(self%integrators(k)%proto, source=proto)
        return
      end if
    end do
    allocate(tmp(n + 1))
    do k = 1, n
      call move_alloc(self%integrators(k)%proto, tmp(k)%proto)
    end do
    allocate(tmp(n + 1)%proto, source=proto)
    call move_alloc(tmp, self%integrators)
  end subroutine reg_add_integrator

  ! ---- creating ------------------------------------------------------------------------------

  !> Create the shape family `id` (a family name or an identifier such as 'lme_g0.8', case
  !> ignored) for `grid`, configured from `group` (the case's `&shape` group; defaults when
  !> absent). `common` lists the group's keys the caller reads itself (e.g. `family`). On
  !> failure `shape` is unallocated and `err` says why.
  subroutine reg_create_shape(self, id, grid, shape, err, group, common)
    class(empm_registry_t), intent(in) :: self                !! registry
    character(len=*), intent(in) :: id                        !! family or identifier
    type(empm_grid_t), intent(in) :: grid                     !! background grid
    class(empm_shape_t), allocatable, intent(out) :: shape    !! the family, configured
    type(empm_error_t), intent(inout) :: err                  !! set on failure
    type(empm_group_t), intent(inout), optional :: group      !! `&shape` group
    type(empm_param_t), intent(in), optional :: common(:)     !! keys read by the caller
    type(empm_group_t) :: g
    type(empm_param_t), allocatable :: keys(:)
    character(len=:), allocatable :: key, f
    integer :: k, kk
    if (err%code /= 0) return
    if (grid%ndim < 1 .or. grid%ndim > 3) then
      call err%set(EMPM_ERR_USAGE, 'create_shape: the grid is not set up (ndim = '// &
        str(grid%ndim)//'): call grid%init first')
      return
    end if
    call group_or_empty(g, 'shape', group)
    key = lower(trim(adjustl(id)))
    k = 0
    do kk = 1, size(self%shapes)
      if (self%shapes(kk)%proto%family() == key) k = kk
    end do
    if (k == 0) then
      ! family_<tag><value>...: the longest family name that prefixes the identifier.
      do kk = 1, size(self%shapes)
        ! (a named copy, not an associate: gfortran 12 frees an associated function result twice)
        f = self%shapes(kk)%proto%family()
        if (len(key) > len(f) + 1) then
          if (key(1:len(f) + 1) == f//'_') then
            if (k == 0) then
              k = kk
            else if (len(f) > len(self%shapes(k)%proto%family())) then
              k = kk
            end if
          end if
        end if
      end do
      if (k > 0) then
        call apply_tags(self%shapes(k)%proto%params(), key, &
                        len(self%shapes(k)%proto%family()) + 2, g, err)
        if (err%code /= 0) return
      end if
    end if
    if (k == 0) then
      call g%fail(err, merge('family', '      ', g%has('family')), 'unknown shape family '''// &
        trim(id)//'''; expected one of: '//self%shape_names()//' (or an identifier such as '// &
        '''lme_g0.8'')')
      return
    end if
    allocate(shape, source=self%shapes(k)%proto)
    shape%ndim = grid%ndim
    call shape%configure(grid, g, err)
    keys = shape%params()
    if (present(common)) keys = [common, keys]
    call g%check_keys(keys, err, context=' for shape family '''//shape%family()//'''')
    if (present(group)) group = g
    if (err%code /= 0) deallocate(shape)
  end subroutine reg_create_shape

  !> Create the material model `name` configured from `group` (the case's `&material` group).
  !> `common` lists the keys the caller reads itself (`name`, `model`).
  subroutine reg_create_material(self, name, mat, err, group, common)
    class(empm_registry_t), intent(in) :: self                !! registry
    character(len=*), intent(in) :: name                      !! model name
    class(empm_material_t), allocatable, intent(out) :: mat   !! the model, configured
    type(empm_error_t), intent(inout) :: err                  !! set on failure
    type(empm_group_t), intent(inout), optional :: group      !! `&material` group
    type(empm_param_t), intent(in), optional :: common(:)     !! keys read by the caller
    type(empm_group_t) :: g
    type(empm_param_t), allocatable :: keys(:)
    integer :: k, kk
    if (err%code /= 0) return
    call group_or_empty(g, 'material', group)
    k = 0
    do kk = 1, size(self%materials)
      if (self%materials(kk)%proto%family() == lower(trim(adjustl(name)))) k = kk
    end do
    if (k == 0) then
      call g%fail(err, merge('model', '     ', g%has('model')), 'unknown material model '''// &
        trim(name)//'''; expected one of: '//self%material_names())
      return
    end if
    allocate(mat, source=self%materials(k)%proto)
    call mat%configure(g, err)
    keys = mat%params()
    if (present(common)) keys = [common, keys]
    call g%check_keys(keys, err, context=' for material model '''//mat%family()//'''')
    if (present(group)) group = g
    if (err%code /= 0) deallocate(mat)
  end subroutine reg_create_material

  !> Create the integrator `name` configured from `group` (the case's `&integrator` group).
  !> `common` lists the keys the caller reads itself (`scheme` and the run controls).
  subroutine reg_create_integrator(self, name, integ, err, group, common)
    class(empm_registry_t), intent(in) :: self                  !! registry
    character(len=*), intent(in) :: name                        !! scheme name
    class(empm_integrator_t), allocatable, intent(out) :: integ !! the scheme, configured
    type(empm_error_t), intent(inout) :: err                    !! set on failure
    type(empm_group_t), intent(inout), optional :: group        !! `&integrator` group
    type(empm_param_t), intent(in), optional :: common(:)       !! keys read by the caller
    type(empm_group_t) :: g
    type(empm_param_t), allocatable :: keys(:)
    integer :: k, kk
    if (err%code /= 0) return
    call group_or_empty(g, 'integrator', group)
    k = 0
    do kk = 1, size(self%integrators)
      if (self%integrators(kk)%proto%family() == lower(trim(adjustl(name)))) k = kk
    end do
    if (k == 0) then
      call g%fail(err, merge('scheme', '      ', g%has('scheme')), 'unknown scheme '''// &
        trim(name)//'''; expected one of: '//self%integrator_names())
      return
    end if
    allocate(integ, source=self%integrators(k)%proto)
    call integ%configure(g, err)
    keys = integ%params()
    if (present(common)) keys = [common, keys]
    call g%check_keys(keys, err, context=' for scheme '''//integ%family()//'''')
    if (present(group)) group = g
    if (err%code /= 0) deallocate(integ)
  end subroutine reg_create_integrator

  subroutine group_or_empty(g, name, group)
    type(empm_group_t), intent(out) :: g
    character(len=*), intent(in) :: name
    type(empm_group_t), intent(in), optional :: group
    if (present(group)) then
      g = group
      if (.not. allocated(g%kv)) allocate(g%kv(0))
      if (.not. allocated(g%name)) g%name = name
      if (.not. allocated(g%file)) g%file = '(no file)'
    else
      g%name = name; g%file = '(no file)'
      allocate(g%kv(0))
    end if
  end subroutine group_or_empty

  !> Set the parameters tagged in `id(from:)`: tokens `<tag><value>` separated by '_'.
  subroutine apply_tags(params, id, from, g, err)
    type(empm_param_t), intent(in) :: params(:)
    character(len=*), intent(in) :: id
    integer, intent(in) :: from
    type(empm_group_t), intent(inout) :: g
    type(empm_error_t), intent(inout) :: err
    integer :: i, j, k, best
    character(len=:), allocatable :: tok
    i = from
    do while (i <= len(id))
      j = index(id(i:), '_')
      if (j == 0) then
        j = len(id) + 1
      else
        j = i + j - 1
      end if
      tok = id(i:j - 1)
      ! the longest tag that prefixes the token
      best = 0
      do k = 1, size(params)
        if (len(params(k)%tag) == 0 .or. len(params(k)%tag) >= len(tok)) cycle
        if (tok(1:len(params(k)%tag)) /= params(k)%tag) cycle
        if (best == 0) then
          best = k
        else if (len(params(k)%tag) > len(params(best)%tag)) then
          best = k
        end if
      end do
      if (best == 0) then
        call g%fail(err, '', 'unknown shape identifier '''//id//''': no parameter of the '// &
          'family has the tag of '''//tok//'''')
        return
      end if
      call g%set(params(best)%name, [tok(len(params(best)%tag) + 1:)])
      i = j + 1
    end do
  end subroutine apply_tags

  ! ---- listing -------------------------------------------------------------------------------

  !> Names of the shape families, comma-separated.
  function reg_shape_names(self) result(s)
    class(empm_registry_t), intent(in) :: self !! registry
    character(len=:), allocatable :: s         !! e.g. "linear, ugimp, bspline2, bspline3, lme"
    integer :: k
    s = ''
    do k = 1, size(self%shapes)
      s = s//merge(', ', '  ', k > 1)//self%shapes(k)%proto%family()
    end do
    s = trim(adjustl(s))
  end function reg_shape_names

  !> Names of the material models, comma-separated.
  function reg_material_names(self) result(s)
    class(empm_registry_t), intent(in) :: self !! registry
    character(len=:), allocatable :: s         !! e.g. "linear_elastic, neohookean"
    integer :: k
    s = ''
    do k = 1, size(self%materials)
      s = s//merge(', ', '  ', k > 1)//self%materials(k)%proto%family()
    end do
    s = trim(adjustl(s))
  end function reg_material_names

  !> Names of the integrators, comma-separated.
  function reg_integrator_names(self) result(s)
    class(empm_registry_t), intent(in) :: self !! registry
    character(len=:), allocatable :: s         !! e.g. "usf, usl, musl, ..."
    integer :: k
    s = ''
    do k = 1, size(self%integrators)
      s = s//merge(', ', '  ', k > 1)//self%integrators(k)%proto%family()
    end do
    s = trim(adjustl(s))
  end function reg_integrator_names

  !> Markdown reference of every family and its parameters, for docs/input.md: one section
  !> per extension point (`kind` = 'shape', 'material' or 'integrator'), one table per family.
  function reg_markdown(self, kind) result(s)
    class(empm_registry_t), intent(in) :: self !! registry
    character(len=*), intent(in) :: kind       !! 'shape', 'material' or 'integrator'
    character(len=:), allocatable :: s         !! Markdown
    character(len=*), parameter :: NL = new_line('a')
    integer :: k
    s = ''
    select case (kind)
    case ('shape')
      do k = 1, size(self%shapes)
        associate (f => self%shapes(k)%proto)
          s = s//section(f%family(), f%summary(), f%params())
        end associate
      end do
    case ('material')
      do k = 1, size(self%materials)
        associate (f => self%materials(k)%proto)
          s = s//section(f%family(), f%summary(), f%params())
        end associate
      end do
    case ('integrator')
      do k = 1, size(self%integrators)
        associate (f => self%integrators(k)%proto)
          s = s//section(f%family(), f%summary(), f%params())
        end associate
      end do
    end select
  contains
    function section(name, summary, params) result(t)
      character(len=*), intent(in) :: name, summary
      type(empm_param_t), intent(in) :: params(:)
      character(len=:), allocatable :: t
      t = '#### `'''//name//'''`'//NL//NL
      if (len(summary) > 0) then
        t = t//upper_first(summary)//'.'//NL//NL
      end if
      if (size(params) > 0) then
        t = t//empm_params_markdown(params)//NL
      else
        t = t//'No parameters.'//NL//NL
      end if
    end function section
    pure function upper_first(x) result(y)
      character(len=*), intent(in) :: x
      character(len=len(x)) :: y
      y = x
      if (y(1:1) >= 'a' .and. y(1:1) <= 'z') y(1:1) = achar(iachar(y(1:1)) - 32)
    end function upper_first
  end function reg_markdown
end module empm_registry
