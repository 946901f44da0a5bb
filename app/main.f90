program empm_main
  use empm, only: empm_version
  implicit none
  print '(a)', empm_version()
end program empm_main
