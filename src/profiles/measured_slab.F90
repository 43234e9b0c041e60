!> A height file's surface shared among the MPI ranks of a job (&profile kind = 'file'),
!> each rank reading its slab of rows (lc_profiles_height_slabs) where the file is one
!> period of the scene's grid: boundary = 'periodic' and resample = 'none' (the file's size
!> is then the grid's). The detrending's least-squares sums are added over the ranks
!> (lc_profiles_measured's detrend_slab), so no rank holds the whole surface. A mirrored
!> file, or one resampled to another grid, is read whole by every rank
!> (lc_profiles_measured), which keeps its rows. A build without MPI has no slabs:
!> `reads_by_slab` is false there.
module lc_profiles_measured_slab
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   use lc_base_strings, only: to_string
   use lc_profiles_measured, only: detrend_slab, check_treatments
   use lc_profiles_height_file, only: named, shape_text
#ifdef LC_MPI
   use lc_base_parallel, only: communicator
   use lc_base_slab, only: row_slab
   use lc_profiles_height_slabs, only: read_height_slab
#endif
   implicit none (type, external)
   private
   public :: reads_by_slab, measured_slab, measured_slab_grid

contains

   !> Whether the file of these &profile settings is read by slabs on a distributed surface.
   pure logical function reads_by_slab(boundary, resample)
      character(len=*), intent(in) :: boundary, resample
#ifdef LC_MPI
      reads_by_slab = trim(boundary) == 'periodic' .and. trim(resample) == 'none'
#else
      reads_by_slab = .false. .and. len(boundary) + len(resample) > 0
#endif
   end function reads_by_slab

   !> The grid of the file's heights (nx, ny), read by slabs (collective).
   subroutine measured_slab_grid(filename, dataset, nx, ny, error)
      character(len=*), intent(in) :: filename, dataset
      integer, intent(out) :: nx, ny
      type(error_type), allocatable, intent(out) :: error
#ifdef LC_MPI
      real(wp), allocatable :: rows(:, :)
      type(row_slab) :: file_slab
      call read_height_slab(filename, dataset, communicator, rows, file_slab, error)
      nx = file_slab%nx
      ny = file_slab%ny
#else
      nx = 0
      ny = 0
      call fatal_error(error, "height file '" // filename // "' (" // dataset // ') by slabs: this build has no MPI', &
         & code_internal)
#endif
   end subroutine measured_slab_grid

   !> This rank's rows of the heights of `filename` on the grid nx x ny (flat, x fastest),
   !> detrended as &profile detrend says (collective; every rank returns the same error).
   subroutine measured_slab(filename, dataset, detrend, boundary, resample, nx, ny, height, error)
      character(len=*), intent(in) :: filename, dataset, detrend, boundary, resample
      integer, intent(in) :: nx, ny
      real(wp), allocatable, intent(out) :: height(:)
      type(error_type), allocatable, intent(out) :: error
#ifdef LC_MPI
      real(wp), allocatable :: rows(:, :)
      type(row_slab) :: file_slab
      character(len=:), allocatable :: mode
      integer :: least

      call check_treatments(detrend, boundary, resample, error)
      if (allocated(error)) return
      call read_height_slab(filename, dataset, communicator, rows, file_slab, error)
      if (allocated(error)) return
      if (file_slab%nx /= nx .or. file_slab%ny /= ny) then
         call fatal_error(error, named(filename) // ' holds shape ' // &
            & shape_text([int(file_slab%ny, i8), int(file_slab%nx, i8)]) // '; allowed: the grid, (ny, nx) = (' // &
            & to_string(ny) // ', ' // to_string(nx) // "), or &profile resample = 'fourier'", code_input)
         return
      end if
      ! ('auto' detrends a periodic file not at all, as on one process)
      mode = trim(detrend)
      if (mode == 'auto') mode = 'none'
      least = merge(3, merge(2, 1, mode == 'plane'), mode == 'curvature')
      if (min(nx, ny) < least) then
         call fatal_error(error, named(filename) // ' holds shape ' // shape_text([int(ny, i8), int(nx, i8)]) // &
            & '; allowed: at least ' // to_string(least) // " points along each axis with detrend = '" // mode // &
            & "'", code_input)
         return
      end if
      call detrend_slab(rows, file_slab%y_start, ny, mode)
      height = reshape(rows, [size(rows)])
#else
      allocate (height(0))
      call fatal_error(error, named(filename) // ' (' // dataset // ', detrend ' // trim(detrend) // ', boundary ' // &
         & trim(boundary) // ', resample ' // trim(resample) // ', ' // to_string(nx) // ' x ' // to_string(ny) // &
         & ') by slabs: this build has no MPI', code_internal)
#endif
   end subroutine measured_slab
end module lc_profiles_measured_slab
