program downstream
  use empm, only: empm_version, empm_grid_t, empm_wp
  implicit none
  type(empm_grid_t) :: grid
  integer :: info
  call grid%init(2, [0.0_empm_wp, 0.0_empm_wp], [1.0_empm_wp, 1.0_empm_wp], [4, 4], info)
  if (info /= 0 .or. grid%nnode /= 25) error stop 1
  print '(a)', 'downstream (core): empm '//empm_version()//' ok'
end program downstream
