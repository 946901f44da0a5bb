!> Umbrella module of the analysis component (`empm::analysis`): exact and manufactured
!> solutions, power spectra (FFTW) and eigenvalues (LAPACK), in one `use empm_analysis`.
!> The core library (`use empm`) needs none of them.
module empm_analysis
  use empm_exact_bar, only: empm_vibrating_bar_t
  use empm_mms, only: empm_mms_t
  use empm_spectrum, only: empm_power_spectrum, empm_energy_share_above
  use empm_linalg, only: empm_eigenvalues, empm_spectral_radius
  use empm_stress_point, only: empm_sp_point_t, empm_sp_history_t, empm_sp_check_t, &
    empm_sp_segment, empm_sp_increment
  implicit none
  private
  public :: empm_vibrating_bar_t, empm_mms_t, empm_power_spectrum, empm_energy_share_above
  public :: empm_eigenvalues, empm_spectral_radius
  public :: empm_sp_point_t, empm_sp_history_t, empm_sp_check_t, empm_sp_segment, &
    empm_sp_increment
end module empm_analysis
