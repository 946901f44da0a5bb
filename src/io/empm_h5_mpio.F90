!> Parallel HDF5 for the output: the file access and transfer properties with which the
!> processes of a run open one file and write their parts of its datasets together (MPI-IO,
!> collective transfers). Compiled with `EMPM_HDF5_MPIO` when the MPI build found a parallel
!> HDF5 (CMakeLists.txt); otherwise [[empm_h5_collective]] is false and the root process
!> writes the output alone (docs/parallel.md, "Output").
module empm_h5_mpio
  use hdf5, only: hid_t, h5pcreate_f, h5pclose_f, H5P_FILE_ACCESS_F, H5P_DATASET_XFER_F
#ifdef EMPM_HDF5_MPIO
  use hdf5, only: h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, H5FD_MPIO_COLLECTIVE_F
  use mpi_f08, only: MPI_INFO_NULL
#endif
  use empm_comm, only: empm_comm_t
  implicit none
  private
  public :: empm_h5_collective, h5_mpio_properties, h5_mpio_close

#ifdef EMPM_HDF5_MPIO
  logical, parameter :: MPIO = .true.
#else
  logical, parameter :: MPIO = .false.
#endif

contains

  !> Whether the processes of `comm` write one file together: several processes and an HDF5
  !> built for MPI.
  pure logical function empm_h5_collective(comm)
    type(empm_comm_t), intent(in) :: comm !! the run's processes
    empm_h5_collective = MPIO .and. comm%parallel()
  end function empm_h5_collective

  !> File access (MPI-IO on `comm`) and data transfer (collective) properties; both 0 (HDF5's
  !> defaults) unless [[empm_h5_collective]]. ierr ≠ 0 on failure.
  subroutine h5_mpio_properties(comm, fapl, xfer, ierr)
    type(empm_comm_t), intent(in) :: comm !! the run's processes
    integer(hid_t), intent(out) :: fapl   !! file access properties
    integer(hid_t), intent(out) :: xfer   !! data transfer properties
    integer, intent(out) :: ierr          !! 0 on success
    integer :: e(4)
    fapl = 0; xfer = 0; ierr = 0
    if (.not. empm_h5_collective(comm)) return
    e = 0
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, e(1))
    call h5pcreate_f(H5P_DATASET_XFER_F, xfer, e(2))
#ifdef EMPM_HDF5_MPIO
    call h5pset_fapl_mpio_f(fapl, comm%handle%mpi_val, MPI_INFO_NULL%mpi_val, e(3))
    call h5pset_dxpl_mpio_f(xfer, H5FD_MPIO_COLLECTIVE_F, e(4))
#endif
    ierr = maxval(abs(e))
  end subroutine h5_mpio_properties

  !> Close what [[h5_mpio_properties]] made.
  subroutine h5_mpio_close(fapl, xfer)
    integer(hid_t), intent(in) :: fapl !! file access properties (0: none)
    integer(hid_t), intent(in) :: xfer !! data transfer properties (0: none)
    integer :: e
    if (fapl /= 0) call h5pclose_f(fapl, e)
    if (xfer /= 0) call h5pclose_f(xfer, e)
  end subroutine h5_mpio_close
end module empm_h5_mpio
