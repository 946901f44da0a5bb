!> Data for docs/figures/lme_basis.png (docs/figures/make_lme_figure.py): LME basis functions
!> and derivatives for several γ, like Fig. 3 of the paper.
!>
!> Writes, in the directory given as the first argument (default: the working directory):
!> - `lme_basis_1d.txt`: nodes 0..10 (h = 1), the basis function of node 5 and of node 0 (at
!>   the boundary of the node set) and their derivatives, for γ = 0.8, 1.8, 3, 6.8, 10 and, as
!>   the γ → ∞ reference, linear finite elements. Columns: x, then per γ p5, dp5/dx, p0, dp0/dx.
!> - `lme_basis_2d_g<γ>.txt` for γ = 0.8 and 3: the basis function of node (5, 5) of a 10 × 10
!>   grid on a 121 × 121 raster of [2, 8]², columns x, y, p, ∂p/∂x.
program lme_figure_data
  use empm_kinds, only: wp
  use empm_grid, only: empm_grid_t
  use empm_shape, only: SHAPE_OK
  use empm_shape_lme, only: empm_shape_lme_t, lme_format_gamma
  implicit none
  real(wp), parameter :: G1(5) = [0.8_wp, 1.8_wp, 3.0_wp, 6.8_wp, 10.0_wp]
  real(wp), parameter :: G2(2) = [0.8_wp, 3.0_wp]
  integer, parameter :: NX = 1001, NR = 121
  character(len=:), allocatable :: outdir
  character(len=512) :: buf
  type(empm_grid_t) :: grid
  type(empm_shape_lme_t) :: shp
  real(wp) :: cols(4 * (size(G1) + 1)), x, y
  integer :: i, j, k, u, info

  outdir = '.'
  if (command_argument_count() >= 1) then
    call get_command_argument(1, buf)
    outdir = trim(buf)
  end if

  ! 1D: node 5 (interior) and node 0 (boundary) of the nodes 0..10.
  call grid%init(1, [0.0_wp], [1.0_wp], [10], info)
  open(newunit=u, file=outdir//'/lme_basis_1d.txt', status='replace', action='write')
  write(u, '(a)', advance='no') '# x'
  do k = 1, size(G1)
    write(u, '(4(a,a))', advance='no') (' ', trim(lab(G1(k), j)), j = 1, 4)
  end do
  write(u, '(a)') ' p5_fe dp5_fe p0_fe dp0_fe'
  do i = 1, NX
    x = 10.0_wp * (i - 1) / (NX - 1)
    do k = 1, size(G1)
      shp%gamma = G1(k)
      call node_values(shp, grid, [x], 6, cols(4 * k - 3), cols(4 * k - 2))
      call node_values(shp, grid, [x], 1, cols(4 * k - 1), cols(4 * k))
    end do
    k = size(G1) + 1
    cols(4 * k - 3) = max(0.0_wp, 1.0_wp - abs(x - 5.0_wp))
    cols(4 * k - 2) = merge(sign(1.0_wp, 5.0_wp - x), 0.0_wp, abs(x - 5.0_wp) < 1.0_wp)
    cols(4 * k - 1) = max(0.0_wp, 1.0_wp - x)
    cols(4 * k) = merge(-1.0_wp, 0.0_wp, x < 1.0_wp)
    write(u, '(*(es15.7))') x, cols
  end do
  close(u)

  ! 2D: node (5, 5) of a 10 × 10 grid.
  call grid%init(2, [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], [10, 10], info)
  do k = 1, size(G2)
    shp%gamma = G2(k)
    open(newunit=u, file=outdir//'/lme_basis_2d_g'//lme_format_gamma(G2(k))//'.txt', &
         status='replace', action='write')
    write(u, '(a)') '# x y p dpdx (node (5,5), gamma = '//lme_format_gamma(G2(k))//')'
    do j = 1, NR
      y = 2.0_wp + 6.0_wp * (j - 1) / (NR - 1)
      do i = 1, NR
        x = 2.0_wp + 6.0_wp * (i - 1) / (NR - 1)
        call node_values(shp, grid, [x, y], grid%node_id([5, 5, 0]), cols(1), cols(2))
        write(u, '(4es15.7)') x, y, cols(1), cols(2)
      end do
    end do
    close(u)
  end do

contains

  !> Value and x-derivative of the basis function of grid node `id` at x (0 outside its
  !> support); stops on a failed evaluation.
  subroutine node_values(shp, grid, x, id, p, dpdx)
    type(empm_shape_lme_t), intent(in) :: shp
    type(empm_grid_t), intent(in) :: grid
    real(wp), intent(in) :: x(:)
    integer, intent(in) :: id
    real(wp), intent(out) :: p, dpdx
    integer :: node(200), nn, info, a
    real(wp) :: N(200), dN(2, 200), lam(2)
    lam = 0.0_wp
    call shp%eval_point(grid, x, x, lam(1:size(x)), nn, node, N, dN(1:size(x), :), info)
    if (info /= SHAPE_OK) error stop 'lme_figure_data: LME evaluation failed'
    p = 0.0_wp; dpdx = 0.0_wp
    do a = 1, nn
      if (node(a) == id) then
        p = N(a); dpdx = dN(1, a)
      end if
    end do
  end subroutine node_values

  !> Column label: p5, dp5, p0 or dp0 and γ.
  function lab(g, j) result(s)
    real(wp), intent(in) :: g
    integer, intent(in) :: j
    character(len=:), allocatable :: s
    character(len=4), parameter :: NAMES(4) = [character(len=4) :: 'p5', 'dp5', 'p0', 'dp0']
    s = trim(NAMES(j))//'_g'//lme_format_gamma(g)
  end function lab
end program lme_figure_data
