!> The result file of a run: on one process the serial writer's (lc_io_hdf5); on a surface
!> shared among MPI ranks every rank writes its rows of the maps into the same file
!> (lc_io_hdf5_slabs, collective: parallel HDF5, or rank 0 writing the gathered rows where
!> this build's HDF5 is serial). The file is the same either way (docs/output.md). A build
!> without MPI (no LC_MPI) has the serial writer only.
module lc_application_result_file
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_scene, only: scene_type
   use lc_result, only: contact_result
   use lc_io_hdf5, only: write_results, run_record
   use lc_base_parallel, only: is_distributed, broadcast
#ifdef LC_MPI
   use lc_base_parallel, only: communicator, rank_count, this_rank
   use lc_base_slab, only: slab_of
   use lc_io_hdf5_slabs, only: write_result_slabs
#endif
   implicit none (type, external)
   private
   public :: write_result_file

contains

   !> Write the result file of `scene`: `height` and the results' maps are the whole grid's
   !> on one process, this rank's slab of rows on several (then every rank calls it, and
   !> every rank returns the same error).
   subroutine write_result_file(filename, scene, namelist_text, height, result, version, run, error, companion)
      character(len=*), intent(in) :: filename, namelist_text, version
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(inout) :: result
      type(run_record), intent(in) :: run
      type(error_type), allocatable, intent(out) :: error
      type(contact_result), intent(inout), optional :: companion
      if (.not. is_distributed() .or. scene%ny <= 1) then
         call write_results(filename, scene, namelist_text, height, result, companion, version, error, run)
         return
      end if
      ! the times of the solves differ from rank to rank: the file records rank 0's
      call agree_on_times(result)
      if (present(companion)) call agree_on_times(companion)
#ifdef LC_MPI
      call write_result_slabs(filename, scene, namelist_text, height, result, version, &
         & slab_of(scene%n, scene%ny, rank_count(), this_rank()), communicator, error, companion, run)
#endif
   end subroutine write_result_file

   !> Rank 0's solver times on every rank.
   subroutine agree_on_times(result)
      type(contact_result), intent(inout) :: result
      call broadcast(result%wall_time)
      call broadcast(result%setup_time)
      call broadcast(result%coarse_time)
      call broadcast(result%transform_time)
   end subroutine agree_on_times
end module lc_application_result_file
