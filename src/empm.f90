!> Umbrella module: the public API of empm in one `use`.
module empm
  use empm_kinds, only: wp
  use empm_version_info, only: empm_version
  use empm_error, only: empm_error_t
  implicit none
  private
  public :: wp, empm_version, empm_error_t
end module empm
