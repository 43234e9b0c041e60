!> A height file's surface shared among the MPI ranks of a job (&profile kind = 'file'),
!> each rank reading a slab of rows of the file (lc_profiles_height_slabs) where no
!> resampling is asked (resample = 'none': the file is one period of the grid, or with
!> boundary = 'mirror' the patch that its mirror images make the grid of). The detrending's
!> least-squares sums are added over the ranks (lc_profiles_measured's detrend_slab), so no
!> rank holds the whole surface. A mirrored patch is detrended on the file's slabs, then
!> each rank receives the file rows its slab of the grid holds (row j of the grid is file
!> row j, or 2 my - 1 - j in the mirror image along y) and mirrors them along x. A file
!> resampled to another grid (resample = 'fourier', where every height depends on the whole
!> file) is read whole by every rank (lc_profiles_measured), which keeps its rows. A build
!> without MPI has no slabs: `reads_by_slab` is false there.
module lc_profiles_measured_slab
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   use lc_base_strings, only: to_string
   use lc_profiles_measured, only: detrend_slab, check_treatments
   use lc_profiles_height_file, only: named, shape_text
#ifdef LC_MPI
   use lc_base_parallel, only: communicator, slab, redistribute_rows
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
      reads_by_slab = (trim(boundary) == 'periodic' .or. trim(boundary) == 'mirror') .and. trim(resample) == 'none'
#else
      reads_by_slab = .false. .and. len(boundary) + len(resample) > 0
#endif
   end function reads_by_slab

   !> The grid of the file's heights (nx, ny; twice the file's along each axis with
   !> boundary = 'mirror'), read by slabs (collective).
   subroutine measured_slab_grid(filename, dataset, boundary, nx, ny, error)
      character(len=*), intent(in) :: filename, dataset, boundary
      integer, intent(out) :: nx, ny
      type(error_type), allocatable, intent(out) :: error
#ifdef LC_MPI
      real(wp), allocatable :: rows(:, :)
      type(row_slab) :: file_slab
      call read_height_slab(filename, dataset, communicator, rows, file_slab, error)
      nx = merge(2, 1, trim(boundary) == 'mirror')*file_slab%nx
      ny = merge(2, 1, trim(boundary) == 'mirror')*file_slab%ny
#else
      nx = 0
      ny = 0
      call fatal_error(error, "height file '" // filename // "' (" // dataset // ', boundary ' // trim(boundary) // &
         & ') by slabs: this build has no MPI', code_internal)
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
      integer :: least, factor, mx, my
      logical :: mirrored

      call check_treatments(detrend, boundary, resample, error)
      if (allocated(error)) return
      call read_height_slab(filename, dataset, communicator, rows, file_slab, error)
      if (allocated(error)) return
      mirrored = trim(boundary) == 'mirror'
      factor = merge(2, 1, mirrored)
      mx = file_slab%nx
      my = file_slab%ny
      ! ('auto' detrends a periodic file not at all and a patch to be mirrored by its plane,
      ! as on one process)
      mode = trim(detrend)
      if (mode == 'auto') mode = merge('plane', 'none ', mirrored)
      least = merge(3, merge(2, 1, mode == 'plane'), mode == 'curvature')
      if (min(mx, my) < least) then
         call fatal_error(error, named(filename) // ' holds shape ' // shape_text([int(my, i8), int(mx, i8)]) // &
            & '; allowed: at least ' // to_string(least) // " points along each axis with detrend = '" // mode // &
            & "'", code_input)
         return
      end if
      if (factor*mx /= nx .or. factor*my /= ny) then
         call fatal_error(error, named(filename) // ' holds shape ' // &
            & shape_text([int(factor*my, i8), int(factor*mx, i8)]) // trim(merge(' (mirrored)', '           ', &
            & mirrored)) // '; allowed: the grid, (ny, nx) = (' // to_string(ny) // ', ' // to_string(nx) // &
            & "), or &profile resample = 'fourier'", code_input)
         return
      end if
      call detrend_slab(rows, file_slab%y_start, my, mode)
      if (mirrored) then
         call mirror_slab(rows, file_slab%y_start, mx, my, height)
      else
         height = reshape(rows, [size(rows)])
      end if
#else
      allocate (height(0))
      call fatal_error(error, named(filename) // ' (' // dataset // ', detrend ' // trim(detrend) // ', boundary ' // &
         & trim(boundary) // ', resample ' // trim(resample) // ', ' // to_string(nx) // ' x ' // to_string(ny) // &
         & ') by slabs: this build has no MPI', code_internal)
#endif
   end subroutine measured_slab
#ifdef LC_MPI
   !> This rank's slab of rows of the mirrored surface (2 mx x 2 my, x fastest, lc_base_slab)
   !> from the file's rows y_start+1 .. each rank holds (`rows`, mx x rows, the ranks' rows
   !> covering the file once): row j (0-based) of the surface is file row j for j < my and
   !> 2 my - 1 - j beyond (the mirror image along y), each mirrored along x as
   !> lc_profiles_measured's mirror_heights does. Collective: the file rows a slab needs come
   !> from the ranks holding them, its rows below my in one piece and those above in another
   !> (their file rows ascending, then reversed).
   subroutine mirror_slab(rows, y_start, mx, my, height)
      real(wp), intent(in) :: rows(:, :)
      integer, intent(in) :: y_start, mx, my
      real(wp), allocatable, intent(out) :: height(:)
      real(wp), allocatable :: held(:), lower(:), upper(:), patch(:, :)
      integer :: first, count, below, above, j
      call slab(2*my, first, count)
      held = reshape(rows, [size(rows)])
      ! the slab's rows first .. first + below - 1 lie in the file as they are; the rows from
      ! first + below on are the mirror images of file rows 2 my - first - count .. upwards
      below = max(0, min(first + count, my) - first)
      above = count - below
      allocate (lower(mx*below), upper(mx*above), patch(mx, count))
      call redistribute_rows(held, mx, my, y_start, first, below, lower)
      call redistribute_rows(held, mx, my, y_start, 2*my - first - count, above, upper)
      patch(:, 1:below) = reshape(lower, [mx, below])
      do j = 1, above
         patch(:, below + j) = upper(mx*(above - j) + 1:mx*(above - j + 1))
      end do
      allocate (height(2*mx*count))
      do j = 1, count
         height(2*mx*(j - 1) + 1:2*mx*(j - 1) + mx) = patch(:, j)
         height(2*mx*j:2*mx*(j - 1) + mx + 1:-1) = patch(:, j)
      end do
   end subroutine mirror_slab
#endif
end module lc_profiles_measured_slab
