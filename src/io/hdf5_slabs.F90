!> The result file of a surface solved on several MPI ranks, written by all of them
!> together from the rows each holds (lc_base_slab), without gathering the maps on one rank.
!>
!> The file is the serial writer's (lc_io_hdf5: datasets, shapes, dtypes, attributes, the
!> same contiguous maps and the same chunked, deflated maps that are mostly zeros): the
!> ranks make the same HDF5 calls, through MPI-IO, each writes its rows of every map by a
!> collective hyperslab, and rank 0 the data of what every rank holds whole (coordinates,
!> histories, lists). Parallel HDF5 (1.10.2 and later) writes filtered datasets
!> collectively (without a type conversion: float32 maps are rounded before the write), so
!> the deflated maps stay deflated.
!>
!> The file is complete or absent as the serial writer's (docs/guarantees.md): every rank
!> writes into rank 0's temporary name; the ranks agree on whether any of them failed
!> (at the sizes, the creation, the writes, the flush of HDF5's metadata, the close) before rank 0 checks the closed
!> file and moves it into place, and all return rank 0's verdict. (Within the writes the
!> ranks make the same collective HDF5 calls on the same metadata, so a failing call fails on
!> all of them; they agree at the end of each step.) The scalars of the result
!> (reductions over the whole grid) must be the same on every rank; the provenance that is
!> not (the host, the time, the run's wall time) is rank 0's.
!>
!> A build whose HDF5 is serial (no LC_PARALLEL_HDF5) gathers the rows on rank 0, which
!> writes the file alone with lc_io_hdf5; the file is the same.
module lc_io_hdf5_slabs
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Gatherv, MPI_DOUBLE_PRECISION, MPI_Allreduce, &
      & MPI_IN_PLACE, MPI_INTEGER8, MPI_SUM, MPI_MIN
   use hdf5, only: hid_t, hsize_t, h5open_f, h5close_f, h5eset_auto_f, h5pcreate_f, h5pclose_f, h5fcreate_f, &
      & h5fclose_f, h5fflush_f, H5F_SCOPE_GLOBAL_F, H5P_FILE_ACCESS_F, H5F_ACC_TRUNC_F
#ifdef LC_PARALLEL_HDF5
   use hdf5, only: h5pset_fapl_mpio_f, h5pset_dxpl_mpio_f, H5P_DATASET_XFER_F, H5FD_MPIO_COLLECTIVE_F
   use mpi_f08, only: MPI_INFO_NULL
#endif
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_io, code_internal
   use lc_base_strings, only: to_string
   use lc_base_slab, only: row_slab
   use lc_scene, only: scene_type
   use lc_result, only: contact_result
   use lc_io_files, only: free_bytes
   use lc_io_hdf5, only: map_writer, h5_status, temporary_name, delete_file, write_contents, publish, map_bytes, &
      & announce_large, check_sizes, run_record, write_results
   use lc_io_mpi_agree, only: agree_error, shared_error, broadcast_text, broadcast_real
   implicit none (type, external)
   private
   public :: write_result_slabs, parallel_hdf5

   !> Whether this build writes by slabs with parallel HDF5 (else rank 0 writes the gathered rows).
#ifdef LC_PARALLEL_HDF5
   logical, parameter :: parallel_hdf5 = .true.
#else
   logical, parameter :: parallel_hdf5 = .false.
#endif
   !> the rank that names, checks and moves the file, and whose provenance it records
   integer, parameter :: root = 0

   !> Maps held by rows on the ranks of a communicator (see lc_io_hdf5's map_writer).
   type, extends(map_writer) :: slab_writer
      type(MPI_Comm) :: comm
      type(row_slab) :: slab
      integer(hid_t) :: xfer = -1   !< collective transfer
   contains
      procedure :: rows => slab_rows
      procedure :: mostly_zeros => slab_mostly_zeros
      procedure :: transfer => slab_transfer
      procedure :: writes_whole => root_writes
      procedure :: agreed_text => root_text
      procedure :: agreed_real => root_real
   end type slab_writer

contains

   !> Write the result file of a surface whose maps are spread by rows over the ranks of
   !> `comm`: `height` and the result's (and companion's) maps are this rank's rows
   !> slab%ny_local of the grid (nx, ny) as `slab` describes them; the scalars and lists are
   !> every rank's same values. Collective: every rank of `comm` calls it with the same
   !> file name and scene, and every rank returns the same error (none when the file is
   !> written).
   subroutine write_result_slabs(filename, scene, namelist_text, height, result, version, slab, comm, error, &
      & companion, run)
      character(len=*), intent(in) :: filename
      type(scene_type), intent(in) :: scene
      !> the input namelist text, echoed to /input/namelist
      character(len=*), intent(in) :: namelist_text
      !> this rank's rows of the rigid profile (L)
      real(wp), intent(in) :: height(:)
      !> the solution: this rank's rows of its maps
      type(contact_result), intent(in) :: result
      !> layercontact version string
      character(len=*), intent(in) :: version
      !> this rank's rows of the grid
      type(row_slab), intent(in) :: slab
      type(MPI_Comm), intent(in) :: comm
      type(error_type), allocatable, intent(out) :: error
      !> frictionless companion run (its maps by rows too)
      type(contact_result), intent(in), optional :: companion
      !> how the run was started, for the root's provenance
      type(run_record), intent(in), optional :: run
      integer :: rank, ranks

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      if (slab%ranks /= ranks .or. slab%rank /= rank .or. slab%nx /= scene%n .or. slab%ny /= max(scene%ny, 1) &
         & .or. slab%ny_local < 1) then
         call fatal_error(error, 'write_result_slabs: the slab (rank ' // to_string(slab%rank) // ' of ' // &
            & to_string(slab%ranks) // ', rows ' // to_string(slab%y_start + 1) // '..' // &
            & to_string(slab%y_start + slab%ny_local) // ' of ' // to_string(slab%ny) // ') is not this rank''s (' &
            & // to_string(rank) // ' of ' // to_string(ranks) // ') of the scene''s grid (' // to_string(scene%n) &
            & // ', ' // to_string(max(scene%ny, 1)) // ') with rows on every rank', code_internal)
      else if (size(height) /= slab%nx*slab%ny_local) then
         call fatal_error(error, "write_result_slabs: the height's " // to_string(size(height)) // ' values are ' // &
            & 'not the ' // to_string(slab%nx*slab%ny_local) // ' of rank ' // to_string(rank) // "'s rows", &
            & code_internal)
      else
         call check_sizes(result, size(height), 'result', error)
         if (.not. allocated(error) .and. present(companion)) call check_sizes(companion, size(height), 'companion', &
            & error)
      end if
      call agree_error(error, comm)
      if (allocated(error)) return
#ifdef LC_PARALLEL_HDF5
      call write_collectively(filename, scene, namelist_text, height, result, version, slab, comm, error, &
         & companion, run)
#else
      call write_gathered(filename, scene, namelist_text, height, result, version, slab, comm, error, companion, run)
#endif
   end subroutine write_result_slabs

#ifdef LC_PARALLEL_HDF5
   !> Every rank writes its rows into one file through MPI-IO (see the module header).
   subroutine write_collectively(filename, scene, namelist_text, height, result, version, slab, comm, error, &
      & companion, run)
      character(len=*), intent(in) :: filename, namelist_text, version
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(in) :: result
      type(row_slab), intent(in) :: slab
      type(MPI_Comm), intent(in) :: comm
      type(error_type), allocatable, intent(out) :: error
      type(contact_result), intent(in), optional :: companion
      type(run_record), intent(in), optional :: run
      character(len=:), allocatable :: tmp
      type(h5_status) :: st
      type(slab_writer), allocatable :: maps
      integer(hid_t) :: fapl, file
      integer :: ignore, hdferr

      tmp = broadcast_text(temporary_name(filename), root, comm)
      if (slab%rank == root) then
         call delete_file(tmp, error)
         if (.not. allocated(error)) call announce_large(filename, map_bytes(scene, result, present(companion)))
      end if
      call agree_error(error, comm)
      if (allocated(error)) return

      allocate (maps)
      maps%comm = comm
      maps%slab = slab
      call h5open_f(st%hdferr)
      call h5eset_auto_f(0, ignore)
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, ignore)
      call h5pset_fapl_mpio_f(fapl, comm%mpi_val, MPI_INFO_NULL%mpi_val, ignore)
      call h5pcreate_f(H5P_DATASET_XFER_F, maps%xfer, ignore)
      call h5pset_dxpl_mpio_f(maps%xfer, H5FD_MPIO_COLLECTIVE_F, ignore)
      if (st%hdferr == 0) then
         call h5fcreate_f(tmp, H5F_ACC_TRUNC_F, file, st%hdferr, access_prp=fapl)
         if (st%hdferr /= 0) st%object = 'the file itself'
      end if
      call agree_status(st, comm)
      if (st%hdferr == 0) then
         call move_alloc(maps, st%maps)
         call write_contents(file, scene, namelist_text, height, result, version, st, companion, run)
         call agree_status(st, comm)
         ! HDF5's metadata to the file while it is open, so that a full disk fails here, agreed,
         ! rather than in the close (MPI-IO files have no size to reserve before it: HDF5 1.10's
         ! MPI-IO driver does not tell their end)
         if (st%hdferr == 0) then
            call h5fflush_f(file, H5F_SCOPE_GLOBAL_F, st%hdferr)
            if (st%hdferr /= 0) then
               st%object = 'the writing of its metadata'
               st%free = free_bytes(tmp)
            end if
         end if
         call agree_status(st, comm)
         call h5fclose_f(file, hdferr)
         if (st%hdferr == 0 .and. hdferr /= 0) then
            st%hdferr = hdferr
            st%object = 'the closing of the file'
         end if
         call agree_status(st, comm)
      end if
      ! the transfer list, with the writer that holds it (in st once the file was created)
      if (allocated(maps)) call move_alloc(maps, st%maps)
      select type (m => st%maps)
      type is (slab_writer)
         call h5pclose_f(m%xfer, ignore)
      end select
      call h5pclose_f(fapl, ignore)
      call h5close_f(ignore)
      ! every rank's writes are in the closed file; rank 0 checks it and moves it into place
      if (slab%rank == root) call publish(tmp, filename, scene%overwrite, st, error)
      call shared_error(error, root, comm)
   end subroutine write_collectively

   !> After a collective step: if any rank failed, every rank's status records the first
   !> failing rank's object (and the space left that it saw).
   subroutine agree_status(st, comm)
      type(h5_status), intent(inout) :: st
      type(MPI_Comm), intent(in) :: comm
      type(error_type), allocatable :: failure
      integer(i8) :: free
      integer :: rank
      if (st%hdferr /= 0) then
         if (.not. allocated(st%object)) st%object = 'the HDF5 library'
         call fatal_error(failure, st%object)
      end if
      call agree_error(failure, comm)
      if (.not. allocated(failure)) return
      call MPI_Comm_rank(comm, rank)
      if (st%hdferr == 0) st%hdferr = -1
      st%object = failure%message
      ! the space left as the failing ranks saw it: the least of them
      free = huge(free)
      if (st%free >= 0) free = st%free
      call MPI_Allreduce(MPI_IN_PLACE, free, 1, MPI_INTEGER8, MPI_MIN, comm)
      st%free = merge(-1_i8, free, free == huge(free))
   end subroutine agree_status
#endif

#ifndef LC_PARALLEL_HDF5
   !> A serial HDF5: rank 0 gathers every map's rows and writes the file alone.
   subroutine write_gathered(filename, scene, namelist_text, height, result, version, slab, comm, error, &
      & companion, run)
      character(len=*), intent(in) :: filename, namelist_text, version
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(in) :: result
      type(row_slab), intent(in) :: slab
      type(MPI_Comm), intent(in) :: comm
      type(error_type), allocatable, intent(out) :: error
      type(contact_result), intent(in), optional :: companion
      type(run_record), intent(in), optional :: run
      type(contact_result) :: whole, whole_companion
      real(wp), allocatable :: whole_height(:)

      call gather_rows(height, whole_height, slab, comm)
      call gather_result(result, whole, slab, comm)
      if (present(companion)) call gather_result(companion, whole_companion, slab, comm)
      if (slab%rank == root) then
         if (present(companion)) then
            call write_results(filename, scene, namelist_text, whole_height, whole, whole_companion, version, error, run)
         else
            call write_results(filename, scene, namelist_text, whole_height, whole, version=version, error=error, &
               & run=run)
         end if
      end if
      call shared_error(error, root, comm)
   end subroutine write_gathered

   !> The result with its maps' rows gathered on rank 0 (the scalars and lists as they are).
   subroutine gather_result(local, whole, slab, comm)
      type(contact_result), intent(in) :: local
      type(contact_result), intent(out) :: whole
      type(row_slab), intent(in) :: slab
      type(MPI_Comm), intent(in) :: comm
      whole = local
      call gather_rows(local%pressure, whole%pressure, slab, comm)
      call gather_rows(local%gap, whole%gap, slab, comm)
      call gather_rows(local%displacement_z, whole%displacement_z, slab, comm)
      if (allocated(local%stress_xx)) then
         call gather_rows(local%displacement_x, whole%displacement_x, slab, comm)
         call gather_rows(local%shear, whole%shear, slab, comm)
         call gather_rows(local%stress_xx, whole%stress_xx, slab, comm)
      end if
      if (allocated(local%stress_yy)) then
         call gather_rows(local%displacement_y, whole%displacement_y, slab, comm)
         call gather_rows(local%stress_yy, whole%stress_yy, slab, comm)
         call gather_rows(local%stress_xy, whole%stress_xy, slab, comm)
      end if
   end subroutine gather_result

   !> Every rank's rows of a map, in order, on rank 0 (others: an empty array).
   subroutine gather_rows(rows, whole, slab, comm)
      real(wp), intent(in) :: rows(:)
      real(wp), allocatable, intent(inout) :: whole(:)
      type(row_slab), intent(in) :: slab
      type(MPI_Comm), intent(in) :: comm
      integer, allocatable :: counts(:), displacements(:)
      integer :: r, block
      if (allocated(whole)) deallocate (whole)
      block = (slab%ny + slab%ranks - 1)/slab%ranks
      counts = [(slab%nx*max(0, min(block, slab%ny - r*block)), r=0, slab%ranks - 1)]
      displacements = [(slab%nx*r*block, r=0, slab%ranks - 1)]
      if (slab%rank == root) then
         allocate (whole(slab%nx*slab%ny))
      else
         allocate (whole(0))
      end if
      call MPI_Gatherv(rows, size(rows), MPI_DOUBLE_PRECISION, whole, counts, displacements, MPI_DOUBLE_PRECISION, &
         & root, comm)
   end subroutine gather_rows
#endif

   ! The slab_writer's answers.

   pure subroutine slab_rows(self, ny, y_start, ny_local)
      class(slab_writer), intent(in) :: self
      integer, intent(in) :: ny
      integer, intent(out) :: y_start, ny_local
      y_start = self%slab%y_start
      ny_local = self%slab%ny_local
      if (ny /= self%slab%ny) then
         ! a map of another grid (none is written so): whole on every rank
         y_start = 0
         ny_local = ny
      end if
   end subroutine slab_rows

   !> Over every rank's rows: the dataset's creation (chunked and deflated or not) is the
   !> same on all.
   logical function slab_mostly_zeros(self, values)
      class(slab_writer), intent(in) :: self
      real(wp), intent(in) :: values(:)
      integer(i8) :: counts(2)
      counts = [count(values == 0.0_wp, kind=i8), size(values, kind=i8)]
      call MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INTEGER8, MPI_SUM, self%comm)
      slab_mostly_zeros = 2*counts(1) > counts(2)
   end function slab_mostly_zeros

   integer(hid_t) function slab_transfer(self)
      class(slab_writer), intent(in) :: self
      slab_transfer = self%xfer
   end function slab_transfer

   logical function root_writes(self)
      class(slab_writer), intent(in) :: self
      root_writes = self%slab%rank == root
   end function root_writes

   function root_text(self, text) result(agreed)
      class(slab_writer), intent(in) :: self
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: agreed
      agreed = broadcast_text(text, root, self%comm)
   end function root_text

   real(wp) function root_real(self, value)
      class(slab_writer), intent(in) :: self
      real(wp), intent(in) :: value
      root_real = broadcast_real(value, root, self%comm)
   end function root_real
end module lc_io_hdf5_slabs
