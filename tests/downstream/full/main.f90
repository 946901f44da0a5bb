program downstream_full
  use empm, only: empm_version, empm_wp
  use empm_analysis, only: empm_vibrating_bar_t
  use empm_verify_suite, only: empm_glob_match
  implicit none
  type(empm_vibrating_bar_t) :: bar
  bar%L = 25.0_empm_wp; bar%E = 100.0_empm_wp; bar%rho = 1.0_empm_wp; bar%v0 = 0.1_empm_wp
  if (.not. empm_glob_match('a/*', 'a/b')) error stop 1
  if (.not. (bar%omega() > 0.0_empm_wp)) error stop 2
  print '(a)', 'downstream (analysis, verify): empm '//empm_version()//' ok'
end program downstream_full
