!> Heights read from a file (&profile kind = 'file') by the MPI ranks that share a surface,
!> each keeping its rows (lc_base_slab) of the file's array: an HDF5 file by hyperslabs,
!> every rank reading its rows through MPI-IO (collectively, when this build's HDF5 is
!> parallel; else each rank opens the file to read its rows); a .npy or text file by rank 0,
!> which sends every rank its rows (MPI_Scatterv). The checks and messages are those of
!> lc_profiles_height_file, and every rank returns the same error.
module lc_profiles_height_slabs
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Bcast, MPI_Scatterv, MPI_INTEGER, &
      & MPI_DOUBLE_PRECISION
   use hdf5, only: hid_t, hsize_t, h5open_f, h5close_f, h5pcreate_f, h5pclose_f, H5P_FILE_ACCESS_F, H5P_DEFAULT_F
#ifdef LC_PARALLEL_HDF5
   use hdf5, only: h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, H5P_DATASET_XFER_F, H5FD_MPIO_COLLECTIVE_F
   use mpi_f08, only: MPI_INFO_NULL
#endif
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_slab, only: row_slab, slab_of, empty_rank
   use lc_profiles_height_file, only: read_height_file, check_height_path, read_hdf5, check_heights, is_hdf5_name, &
      & too_few_rows
   use lc_io_mpi_agree, only: agree_error, shared_error
   implicit none (type, external)
   private
   public :: read_height_slab

   integer, parameter :: root = 0

contains

   !> This rank's rows of the heights of `filename` (formats as read_height_file):
   !> height(nx, slab%ny_local) with `slab` the rows of the file's (nx, ny) on this rank of
   !> `comm`. A file with fewer rows than ranks is refused (code_input). Collective.
   subroutine read_height_slab(filename, dataset, comm, height, slab, error)
      !> File name (&profile file)
      character(len=*), intent(in) :: filename
      !> Dataset inside an HDF5 file (&profile dataset)
      character(len=*), intent(in) :: dataset
      type(MPI_Comm), intent(in) :: comm
      !> This rank's rows of the heights (L)
      real(wp), allocatable, intent(out) :: height(:, :)
      !> the rows of the file's array this rank holds
      type(row_slab), intent(out) :: slab
      type(error_type), allocatable, intent(out) :: error
      integer :: rank, ranks

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      if (is_hdf5_name(filename)) then
         call read_hdf5_rows(filename, dataset, comm, rank, ranks, height, slab, error)
      else
         call read_scattered(filename, dataset, comm, rank, ranks, height, slab, error)
      end if
      if (allocated(error) .and. allocated(height)) deallocate (height)
   end subroutine read_height_slab

   !> Every rank reads its rows of the HDF5 dataset.
   subroutine read_hdf5_rows(filename, dataset, comm, rank, ranks, height, slab, error)
      character(len=*), intent(in) :: filename, dataset
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: rank, ranks
      real(wp), allocatable, intent(out) :: height(:, :)
      type(row_slab), intent(out) :: slab
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: fapl, xfer
      integer(hsize_t) :: sizes(2)
      integer :: hdferr, ignore

      call check_height_path(filename, error)
      call agree_error(error, comm)
      if (allocated(error)) return
      call h5open_f(hdferr)
      fapl = H5P_DEFAULT_F
      xfer = H5P_DEFAULT_F
#ifdef LC_PARALLEL_HDF5
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, ignore)
      call h5pset_fapl_mpio_f(fapl, comm%mpi_val, MPI_INFO_NULL%mpi_val, ignore)
      call h5pcreate_f(H5P_DATASET_XFER_F, xfer, ignore)
      call h5pset_dxpl_mpio_f(xfer, H5FD_MPIO_COLLECTIVE_F, ignore)
#else
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, ignore)
#endif
      call read_hdf5(filename, dataset, height, error, sizes, fapl, xfer, ranks, rank)
      call h5pclose_f(fapl, ignore)
      if (xfer /= H5P_DEFAULT_F) call h5pclose_f(xfer, ignore)
      call h5close_f(ignore)
      if (.not. allocated(error)) then
         slab = slab_of(int(sizes(1)), int(sizes(2)), ranks, rank)
         call check_heights(filename, height, slab%y_start, error)
      end if
      call agree_error(error, comm)
   end subroutine read_hdf5_rows

   !> Rank 0 reads the whole file and sends every rank its rows.
   subroutine read_scattered(filename, dataset, comm, rank, ranks, height, slab, error)
      character(len=*), intent(in) :: filename, dataset
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: rank, ranks
      real(wp), allocatable, intent(out) :: height(:, :)
      type(row_slab), intent(out) :: slab
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: whole(:, :)
      integer, allocatable :: counts(:), displacements(:)
      integer :: sizes(2), r
      type(row_slab) :: other

      sizes = 0
      if (rank == root) then
         call read_height_file(filename, dataset, whole, error)
         if (.not. allocated(error)) then
            sizes = shape(whole)
            if (empty_rank(sizes(2), ranks)) call fatal_error(error, too_few_rows(filename, sizes(2), ranks), code_input)
         end if
      end if
      call shared_error(error, root, comm)
      if (allocated(error)) return
      call MPI_Bcast(sizes, 2, MPI_INTEGER, root, comm)
      slab = slab_of(sizes(1), sizes(2), ranks, rank)
      allocate (counts(ranks), displacements(ranks))
      do r = 0, ranks - 1
         other = slab_of(sizes(1), sizes(2), ranks, r)
         counts(r + 1) = sizes(1)*other%ny_local
         displacements(r + 1) = sizes(1)*other%y_start
      end do
      if (rank /= root) allocate (whole(0, 0))
      allocate (height(sizes(1), slab%ny_local))
      call MPI_Scatterv(whole, counts, displacements, MPI_DOUBLE_PRECISION, height, size(height), &
         & MPI_DOUBLE_PRECISION, root, comm)
   end subroutine read_scattered

end module lc_profiles_height_slabs
