!> Working precision and shared numeric constants: the only place kinds are chosen.
module empm_kinds
  use, intrinsic :: iso_fortran_env, only: real64, int64
  implicit none
  private
  public :: wp, i8, pi

  integer, parameter :: wp = real64 !! working real kind
  integer, parameter :: i8 = int64  !! 64-bit integer kind (counters, sizes)
  real(wp), parameter :: pi = 3.14159265358979323846264338327950288_wp !! π
end module empm_kinds
