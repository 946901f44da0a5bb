!> LME set-up: declared parameters and `configure`, the family's names, the storage bound
!> `max_nodes`, the support radius and node-wise γ.
submodule (empm_shape_lme) empm_shape_lme_setup
  use empm_shape, only: SHAPE_OK
  use empm_params, only: empm_param, PARAM_REAL, PARAM_STR
  use empm_strings, only: str
  implicit none

  !> The keys, in the order of `params()`: indices of [[declaration]].
  integer, parameter :: P_GAMMA = 1, P_TOL0 = 2, P_REMEDY = 3, P_GAMMA_INSIDE = 4, P_BOX_LO = 5, &
                        P_BOX_HI = 6, NPARAM = 6

contains

  module procedure lme_family
    associate (unused_ => self); end associate
    s = 'lme'
  end procedure lme_family

  module procedure lme_summary
    associate (unused_ => self); end associate
    s = 'local maximum-entropy (Arroyo & Ortiz 2006): smooth, non-negative, linearly '// &
        'reproducing; support radius h·sqrt(−ln tol0/γ); no padding needed'
  end procedure lme_summary

  module procedure lme_params
    integer :: i
    associate (unused_ => self); end associate
    allocate(p(NPARAM))
    do i = 1, NPARAM
      p(i) = declaration(i)
    end do
  end procedure lme_params

  module procedure lme_configure
    character(len=:), allocatable :: remedy
    real(wp) :: gin, lo(3), hi(3)
    integer :: nd, nlo, nhi, info
    remedy = 'none'
    gin = 0.0_wp; lo = 0.0_wp; hi = 0.0_wp
    ! A failed configure leaves no table of the previous parameters behind.
    if (allocated(self%start_tab)) deallocate(self%start_tab)
    ! The getters do nothing once `err` is set: the first problem is the one reported.
    call group%get(declaration(P_GAMMA), self%gamma, err)
    call group%get(declaration(P_TOL0), self%tol0, err)
    call group%get(declaration(P_REMEDY), remedy, err)
    call group%get(declaration(P_GAMMA_INSIDE), gin, err)
    call group%get(declaration(P_BOX_LO), lo, nlo, err)
    call group%get(declaration(P_BOX_HI), hi, nhi, err)
    if (err%code /= 0) return
    select case (remedy)
    case ('enlarge'); self%remedy = LME_REMEDY_ENLARGE
    case default; self%remedy = LME_REMEDY_NONE  ! 'none' (the getter checked the choices)
    end select
    ! Node-wise γ from the box only: configuring again starts from uniform γ.
    if (allocated(self%gamma_node)) deallocate(self%gamma_node)
    self%gamma_min = 0.0_wp
    nd = grid%ndim
    if (group%has('gamma_inside')) then
      if (nlo /= nd) then
        call group%fail(err, 'gamma_box_lo', box_count_text(nlo, nd)); return
      end if
      if (nhi /= nd) then
        call group%fail(err, 'gamma_box_hi', box_count_text(nhi, nd)); return
      end if
      if (any(hi(1:nd) < lo(1:nd))) then
        call group%fail(err, 'gamma_box_hi', 'expected gamma_box_hi >= gamma_box_lo in every '// &
          'direction'); return
      end if
      call self%set_gamma_box(grid, lo(1:nd), hi(1:nd), gin, info)
      if (info /= 0) then
        call group%fail(err, 'gamma_inside', 'node-wise gamma cannot be set on this grid'); return
      end if
    else if (group%has('gamma_box_lo') .or. group%has('gamma_box_hi')) then
      call group%fail(err, 'gamma_inside', 'required with gamma_box_lo/hi: the gamma of the '// &
        'nodes in the box'); return
    end if
    call lme_build_start(self, grid)
  end procedure lme_configure

  ! With uniform γ the exponent −γ|ξ|² + λ·ξ is a sum over the directions, so on the whole box
  ! of candidates (every lattice node within R of x in each direction) the weights are products
  ! of one-dimensional LME weights, and λ_k solves the problem of direction k alone: a smooth
  ! function of the position in the cell, tabulated here. The actual candidates are the nodes
  ! within R (a disk, a ball), whose λ* differs from it by about tol0 (‖Δλh‖ ~ 1e-5 for γ = 3):
  ! one Newton step from this start reaches the tolerance wherever the particle is, while the
  ! extrapolation from a particle's last two λ needs two or more once it crosses cells.
  module procedure lme_build_start
    real(wp) :: hs, rd, c, s, lam(1), xi(1, 64), w(64)
    integer :: k, j, i, lo, hi, n, it, info
    if (allocated(self%start_tab)) deallocate(self%start_tab)
    self%start_h = 0.0_wp
    if (allocated(self%gamma_node) .or. .not. params_ok(self, grid)) return
    hs = lme_h(grid)
    allocate(self%start_tab(0:LME_START_N, grid%ndim))
    do k = 1, grid%ndim
      ! Direction k: ξ_i = (s − i) h_k/h for the nodes i with |s − i| ≤ R/h_k, s the position
      ! in cells, solved by the general path's guarded Newton (lme_kernel in 1D), each point
      ! from the previous one's λ.
      c = grid%h(k) / hs
      rd = sqrt(-log(self%tol0) / self%gamma) * hs * grid%inv_h(k)
      lam = 0.0_wp
      do j = 0, LME_START_N
        s = real(j, wp) / LME_START_N
        lo = ceiling(s - rd); hi = floor(s + rd); n = hi - lo + 1
        if (n > size(w)) then
          deallocate(self%start_tab); return ! no usable start: the extrapolation only
        end if
        do i = lo, hi
          xi(1, i - lo + 1) = (s - i) * c
        end do
        call lme_kernel(1, n, self%gamma, self%tol0, hs, self%max_iter, lam, w(1:n), &
                        xi(:, 1:n), it, info)
        if (info /= SHAPE_OK) then
          deallocate(self%start_tab); return
        end if
        self%start_tab(j, k) = lam(1) * hs
      end do
      self%start_h(k) = grid%h(k)
    end do
    self%start_gamma = self%gamma; self%start_tol0 = self%tol0
  end procedure lme_build_start

  module procedure lme_name
    s = 'lme_g'//lme_format_gamma(self%gamma)
  end procedure lme_name

  module procedure lme_radius
    rr = 0.0_wp
    if (.not. params_ok(self, grid)) return
    rr = lme_support_radius(gamma_lowest(self), self%tol0, lme_h(grid))
  end procedure lme_radius

  module procedure lme_support_radius
    rr = h * sqrt(-log(tol0) / gamma)
  end procedure lme_support_radius

  module procedure lme_format_gamma
    character(len=40) :: buf
    character(len=8) :: fmt
    real(wp) :: back
    integer :: d, ios
    do d = 0, 17
      write(fmt, '("(f0.",i0,")")') d
      write(buf, fmt, iostat=ios) g
      if (ios /= 0) exit
      read(buf, *, iostat=ios) back
      if (ios == 0 .and. back == g) then
        s = trim(adjustl(buf))
        if (s(len(s):len(s)) == '.') s = s(1:len(s) - 1)
        if (s(1:1) == '.') s = '0'//s
        return
      end if
    end do
    write(buf, '(es24.16e3)') g
    s = trim(adjustl(buf))
  end procedure lme_format_gamma

  module procedure lme_node_data
    lme_node_data = allocated(self%gamma_node)
  end procedure lme_node_data

  module procedure lme_reach_cells
    real(wp) :: rr
    n = 0
    if (.not. params_ok(self, grid)) return
    rr = lme_radius(self, grid)
    if (self%remedy == LME_REMEDY_ENLARGE) rr = rr / sqrt(LME_REMEDY_FACTOR**LME_REMEDY_TRIES)
    n = maxval(ceiling(rr * grid%inv_h(1:grid%ndim)))
  end procedure lme_reach_cells

  module procedure lme_max_nodes
    real(wp) :: rr, c, dd, dist2
    integer :: kk(3), i, j, k, d, ijk(3)
    lme_max_nodes = 0
    if (.not. params_ok(self, grid)) return
    rr = lme_radius(self, grid)
    if (self%remedy == LME_REMEDY_ENLARGE) rr = rr / sqrt(LME_REMEDY_FACTOR**LME_REMEDY_TRIES)
    kk = 0
    do d = 1, grid%ndim
      kk(d) = ceiling(rr * grid%inv_h(d)) + 1
    end do
    if (grid%ndim == 2) then
      lme_max_nodes = max_depth_2d(grid%h(1), grid%h(2), rr, kk)
      return
    end if
    ! Distance from lattice node ijk to the cell [0, h1]×[0, h2]×[0, h3], times (1 + 1e-12).
    do k = -kk(3), kk(3) + min(1, kk(3))
      do j = -kk(2), kk(2) + min(1, kk(2))
        do i = -kk(1), kk(1) + min(1, kk(1))
          ijk = [i, j, k]
          dist2 = 0.0_wp
          do d = 1, grid%ndim
            c = ijk(d) * grid%h(d)
            dd = max(0.0_wp, -c, c - grid%h(d))
            dist2 = dist2 + dd * dd
          end do
          if (dist2 <= rr * rr * (1.0_wp + 1.0e-12_wp)) lme_max_nodes = lme_max_nodes + 1
        end do
      end do
    end do
  end procedure lme_max_nodes

  !> Exact largest number of lattice nodes (spacing h1, h2) within the closed disk of radius rr
  !> around any point: the deepest point of an arrangement of closed disks can be taken at a
  !> vertex (an intersection of two circles), so every pairwise intersection of the circles
  !> around the nodes near one cell is tried (lattice periodicity covers every other cell).
  !> Counting is inflated by 1e-9 rr so that vertices, which lie on circles, count. Tighter than
  !> the union over the cell (e.g. 24 -> 21 nodes at gamma = 3), which sizes the basis storage.
  pure integer function max_depth_2d(h1, h2, rr, kk) result(depth)
    real(wp), intent(in) :: h1, h2   !! cell sizes
    real(wp), intent(in) :: rr       !! support radius
    integer, intent(in) :: kk(3)     !! index half-widths of the node neighbourhood
    real(wp) :: xs(4 * (2 * kk(1) + 2) * (2 * kk(2) + 2)), ys(size(xs))
    real(wp) :: dx, dy, d2, a, hh, mx, my, px, py, r2
    integer :: i, j, n, q, m, s
    ! Nodes within 2 rr of the cell (those that can lie within rr of a point of the cell).
    n = 0
    do j = -kk(2) - 1, kk(2) + 2
      do i = -kk(1) - 1, kk(1) + 2
        dx = max(0.0_wp, -i * h1, i * h1 - h1); dy = max(0.0_wp, -j * h2, j * h2 - h2)
        if (dx * dx + dy * dy <= 4.0_wp * rr * rr * (1.0_wp + 1.0e-9_wp) .and. n < size(xs)) then
          n = n + 1; xs(n) = i * h1; ys(n) = j * h2
        end if
      end do
    end do
    r2 = (rr * (1.0_wp + 1.0e-9_wp))**2
    depth = 1
    do q = 1, n
      do m = q + 1, n
        dx = xs(m) - xs(q); dy = ys(m) - ys(q); d2 = dx * dx + dy * dy
        if (d2 > 4.0_wp * rr * rr .or. d2 == 0.0_wp) cycle
        ! The two intersection points: midpoint ± hh along the perpendicular.
        a = 0.5_wp; hh = sqrt(max(0.0_wp, rr * rr / d2 - 0.25_wp))
        mx = xs(q) + a * dx; my = ys(q) + a * dy
        do s = -1, 1, 2
          px = mx - s * hh * dy; py = my + s * hh * dx
          if (px < 0.0_wp .or. px > h1 .or. py < 0.0_wp .or. py > h2) cycle
          depth = max(depth, count((xs(1:n) - px)**2 + (ys(1:n) - py)**2 <= r2))
        end do
      end do
    end do
  end function max_depth_2d

  module procedure lme_set_gamma_nodes
    info = 1
    if (size(gamma_node) /= grid%nnode .or. grid%nnode < 1) return
    if (.not. all(gamma_node > 0.0_wp .and. gamma_node <= huge(1.0_wp))) return
    self%gamma_node = gamma_node
    self%gamma_min = minval(gamma_node)
    info = 0
  end procedure lme_set_gamma_nodes

  module procedure lme_set_gamma_box
    real(wp), allocatable :: g(:)
    real(wp) :: xi(3), tol
    integer :: id, nd
    nd = grid%ndim
    tol = 1.0e-9_wp * grid%hmin()
    allocate(g(grid%nnode))
    g = self%gamma
    do id = 1, grid%nnode
      xi = grid%node_coord(id)
      if (all(xi(1:nd) >= lo(1:nd) - tol .and. xi(1:nd) <= hi(1:nd) + tol)) g(id) = gamma_inside
    end do
    call lme_set_gamma_nodes(self, grid, g, info)
  end procedure lme_set_gamma_box

  !> Declaration `i` (a `P_*` index) of the `&shape` keys of LME (wording: docs/input.md).
  pure function declaration(i) result(p)
    integer, intent(in) :: i          !! P_GAMMA .. P_BOX_HI
    type(empm_param_t) :: p           !! the declaration
    select case (i)
    case (P_GAMMA)
      p = empm_param('gamma', PARAM_REAL, '-', 'γ = β h² (h = the largest grid spacing); '// &
        'support radius R = h·sqrt(−ln tol0/γ)', default='3', lo=0.0_wp, lo_open=.true., tag='g')
    case (P_TOL0)
      p = empm_param('tol0', PARAM_REAL, '-', 'truncation tolerance of the weights', &
        default='1e-6', lo=0.0_wp, hi=1.0_wp, lo_open=.true., hi_open=.true.)
    case (P_REMEDY)
      p = empm_param('remedy', PARAM_STR, '-', '`''none''` (a particle whose basis fails '// &
        'stops: at set-up as an input error, exit status 2; during the run with exit status 3; '// &
        'the message names the particle, its position and the reason) or `''enlarge''` '// &
        '(retry that particle with γ/2, then γ/4)', default='''none''', choices='none enlarge')
    case (P_GAMMA_INSIDE)
      p = empm_param('gamma_inside', PARAM_REAL, '-', 'node-wise γ: the nodes in the box '// &
        '[`gamma_box_lo`, `gamma_box_hi`] get this γ, the others `gamma`', lo=0.0_wp, &
        lo_open=.true., optional=.true.)
    case (P_BOX_LO)
      p = empm_param('gamma_box_lo', PARAM_REAL, 'm', 'lower corner of that box, ndim values, '// &
        'required with `gamma_inside` (nodes within 1e-9 h count as inside)', count=3, &
        optional=.true.)
    case default
      p = empm_param('gamma_box_hi', PARAM_REAL, 'm', 'upper corner of that box, ndim values '// &
        '≥ `gamma_box_lo`, required with `gamma_inside`', count=3, optional=.true.)
    end select
  end function declaration

  !> Message for a box corner with `n` coordinates on an `nd`-dimensional grid.
  pure function box_count_text(n, nd) result(s)
    integer, intent(in) :: n          !! coordinates given
    integer, intent(in) :: nd         !! grid dimension
    character(len=:), allocatable :: s !! message
    if (n == 0) then
      s = 'required with gamma_inside: gamma_box_lo/hi, '//str(nd)//' coordinates each [m]'
    else
      s = 'expected '//str(nd)//' coordinates (one per grid direction), got '//str(n)
    end if
  end function box_count_text
end submodule empm_shape_lme_setup
