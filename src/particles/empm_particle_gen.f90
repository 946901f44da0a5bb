!> Particle generation: fill a box (interval in 1D) or a disk/sphere with n particles per cell
!> direction, at Gauss–Legendre positions or at cell-centred voxel positions; a box face inside
!> a cell clips that cell's points to the body.
module empm_particle_gen
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_particles, only: empm_particles_t
  use empm_error, only: empm_error_t
  implicit none
  private
  public :: empm_fill, empm_deal_t, GEOM_BOX, GEOM_DISK, PLACE_GAUSS, PLACE_VOXEL

  integer, parameter :: GEOM_BOX = 1     !! axis-aligned box [lo, hi] (interval in 1D)
  integer, parameter :: GEOM_DISK = 2    !! disk (2D) or ball (3D) of given centre and radius
  integer, parameter :: PLACE_GAUSS = 1  !! Gauss–Legendre points, volume = Gauss weight share
  integer, parameter :: PLACE_VOXEL = 2  !! centres of ppc^d equal sub-cells (voxels)
  !> A box face within this fraction of a cell of a grid line is taken to be on it.
  real(wp), parameter :: SLIVER = 1.0e-9_wp

  !> Generated particles dealt out to the processes of a run that will share them by place
  !> (docs/parallel.md, "Set-up"): every process generates the whole sequence, and particle k
  !> of it (its id) is stored by process mod(k − 1, every) only, so that no process holds
  !> every particle. One process (`every` = 1) stores them all, with the same ids.
  type :: empm_deal_t
    integer :: n = 0      !! particles generated so far, by every process together
    integer :: every = 1  !! number of processes
    integer :: rank = 0   !! this process, 0 .. every − 1
  contains
    procedure :: next => deal_next
  end type empm_deal_t

contains

  !> One more particle generated: its id, and whether this process stores it.
  subroutine deal_next(self, id, mine)
    class(empm_deal_t), intent(inout) :: self !! the dealing
    integer, intent(out) :: id                !! the particle's id (1-based generation order)
    logical, intent(out) :: mine              !! this process stores it
    self%n = self%n + 1
    id = self%n
    mine = mod(id - 1, self%every) == self%rank
  end subroutine deal_next

  !> Append the particles of one body. A box fills each grid cell it meets with ppc points
  !> per direction (Gauss or voxel positions) on the part of the cell inside it, so a face
  !> anywhere in a cell gets the body's exact volume; a disk keeps the points of whole cells
  !> that lie inside it. A particle's volume is the filled volume times its quadrature weight
  !> share, and its half-length is half its voxel's size (used by uGIMP).
  !> The particles' state variables start at zero (the model's set-up initialises them).
  !> With `deal`, only this process's share of them is stored ([[empm_deal_t]]).
  subroutine empm_fill(pts, grid, geom, lo, hi, center, radius, ppc, placement, rho, mat, &
                       nadded, info, err, deal)
    type(empm_particles_t), intent(inout) :: pts !! particle set (appended to)
    type(empm_grid_t), intent(in) :: grid        !! background grid
    integer, intent(in) :: geom                  !! GEOM_BOX or GEOM_DISK
    real(wp), intent(in) :: lo(3), hi(3)         !! box corners (GEOM_BOX) [m]
    real(wp), intent(in) :: center(3)            !! centre (GEOM_DISK) [m]
    real(wp), intent(in) :: radius               !! radius (GEOM_DISK) [m]
    integer, intent(in) :: ppc                   !! particles per cell and direction, 1..4
    integer, intent(in) :: placement             !! PLACE_GAUSS or PLACE_VOXEL
    real(wp), intent(in) :: rho                  !! density [kg/m³]
    integer, intent(in) :: mat                   !! material index
    integer, intent(out) :: nadded               !! particles the body has (with `deal`:
                                                 !! on every process together)
    integer, intent(out) :: info                 !! 0 ok, 1 bad ppc, 2 bad geometry/placement,
                                                 !! 3 out of memory (with `err`)
    type(empm_error_t), intent(inout), optional :: err !! allocation failure when the storage
                                                       !! grows; without it the program stops
    type(empm_deal_t), intent(inout), optional :: deal !! dealing out to processes: ids and
                                                       !! this process's share
    type(empm_error_t) :: e
    real(wp) :: xi(4), wi(4), x(3), lp(3), w, cellvol, a(3), b(3), wd(3)
    integer :: d, nd, c(3), s(3), cmax(3), k, c1, c2, c3
    logical :: inside, clip(3), mine
    integer :: id
    nadded = 0; info = 0
    nd = grid%ndim
    if (ppc < 1 .or. ppc > 4) then
      info = 1; return
    end if
    if ((geom /= GEOM_BOX .and. geom /= GEOM_DISK) .or. &
        (placement /= PLACE_GAUSS .and. placement /= PLACE_VOXEL)) then
      info = 2; return
    end if
    call points_1d(ppc, placement, xi, wi)
    cmax = 0; cmax(1:nd) = grid%ncell(1:nd) - 1
    s = 1
    do c3 = 0, cmax(3)
      do c2 = 0, cmax(2)
        do c1 = 0, cmax(1)
          c = [c1, c2, c3]
          ! The part [a, b] of the cell that the points fill: the whole cell, or for a box
          ! its intersection with the box, so that a box ending inside a cell gets exactly
          ! its own volume (its particles shrink with the part of the cell it covers).
          lp = 0.0_wp; cellvol = 1.0_wp; inside = .true.
          do d = 1, nd
            a(d) = grid%origin(d) + c(d) * grid%h(d)
            wd(d) = grid%h(d)
            clip(d) = .false.
            if (geom == GEOM_BOX) then
              ! A face on a grid line up to round-off leaves no sliver on the far side.
              b(d) = a(d) + grid%h(d)
              if (lo(d) > a(d) + SLIVER * grid%h(d)) then
                a(d) = lo(d); clip(d) = .true.
              end if
              if (hi(d) < b(d) - SLIVER * grid%h(d)) then
                b(d) = hi(d); clip(d) = .true.
              end if
              if (b(d) - a(d) <= SLIVER * grid%h(d)) inside = .false.
              if (clip(d)) wd(d) = b(d) - a(d)
            end if
            lp(d) = 0.5_wp * wd(d) / ppc
            cellvol = cellvol * wd(d)
          end do
          if (.not. inside) cycle
          do k = 0, ppc**nd - 1
            ! Sub-point index per direction, x fastest.
            s(1) = 1 + mod(k, ppc)
            if (nd >= 2) s(2) = 1 + mod(k / ppc, ppc)
            if (nd >= 3) s(3) = 1 + k / (ppc * ppc)
            x = 0.0_wp; w = 1.0_wp
            do d = 1, nd
              if (clip(d)) then
                x(d) = a(d) + 0.5_wp * (1.0_wp + xi(s(d))) * wd(d)
              else
                x(d) = grid%origin(d) + (c(d) + 0.5_wp * (1.0_wp + xi(s(d)))) * grid%h(d)
              end if
              w = w * wi(s(d))
            end do
            if (geom == GEOM_DISK) inside = sum((x(1:nd) - center(1:nd))**2) <= radius**2
            if (.not. inside) cycle
            nadded = nadded + 1
            id = pts%np + 1
            if (present(deal)) then
              call deal%next(id, mine)
              if (.not. mine) cycle
            end if
            if (present(err)) then
              call pts%append(x(1:nd), w * cellvol, rho, lp(1:nd), mat, e, id=id)
              if (e%code /= 0) then
                err = e; info = 3; nadded = nadded - 1; return
              end if
            else
              call pts%append(x(1:nd), w * cellvol, rho, lp(1:nd), mat, id=id)
            end if
          end do
        end do
      end do
    end do
  end subroutine empm_fill

  !> Reference coordinates in [−1, 1] and weight shares (summing to 1) of n points.
  pure subroutine points_1d(n, placement, xi, wi)
    integer, intent(in) :: n, placement
    real(wp), intent(out) :: xi(4), wi(4)
    integer :: i
    xi = 0.0_wp; wi = 0.0_wp
    if (placement == PLACE_VOXEL) then
      do i = 1, n
        xi(i) = -1.0_wp + (2.0_wp * i - 1.0_wp) / n
        wi(i) = 1.0_wp / n
      end do
      return
    end if
    select case (n)
    case (1)
      xi(1) = 0.0_wp; wi(1) = 1.0_wp
    case (2)
      xi(1:2) = [-1.0_wp, 1.0_wp] / sqrt(3.0_wp); wi(1:2) = 0.5_wp
    case (3)
      xi(1:3) = [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)]
      wi(1:3) = [5.0_wp, 8.0_wp, 5.0_wp] / 18.0_wp
    case default
      xi = [-0.861136311594052575_wp, -0.339981043584856265_wp, &
             0.339981043584856265_wp, 0.861136311594052575_wp]
      wi = 0.5_wp * [0.347854845137453857_wp, 0.652145154862546143_wp, &
                     0.652145154862546143_wp, 0.347854845137453857_wp]
    end select
  end subroutine points_1d
end module empm_particle_gen
