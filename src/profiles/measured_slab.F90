!> A height file's surface shared among the MPI ranks of a job (&profile kind = 'file'),
!> each rank reading a slab of rows of the file (lc_profiles_height_slabs), so that no rank
!> holds the whole surface (but rank 0 reading a .npy or text file). The detrending's
!> least-squares sums are added over the ranks (lc_profiles_measured's detrend_slab). A
!> mirrored patch (boundary = 'mirror') is detrended on the file's slabs, then each rank
!> receives the file rows its slab of the mirrored surface holds (row j is file row j, or
!> 2 my - 1 - j in the mirror image along y) and mirrors them along x. A surface resampled
!> to the grid (resample = 'fourier') is mapped row by row along x, then on blocks of
!> columns along y (resample_slab). The steps are those of lc_profiles_measured's
!> prepare_heights, in its order. A build without MPI has no slabs: `reads_by_slab` is
!> false there.
module lc_profiles_measured_slab
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   use lc_base_strings, only: to_string
   use lc_profiles_measured, only: detrend_slab, check_treatments
   use lc_profiles_height_file, only: named, shape_text
#ifdef LC_MPI
   use mpi_f08, only: MPI_Alltoallv, MPI_DOUBLE_PRECISION
   use lc_base_parallel, only: communicator, slab, redistribute_rows, rank_count, this_rank
   use lc_base_slab, only: row_slab, slab_of
   use lc_fft_plans, only: fft_plan
   use lc_io_mpi_agree, only: agree_error
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
      reads_by_slab = (trim(boundary) == 'periodic' .or. trim(boundary) == 'mirror') .and. &
         & (trim(resample) == 'none' .or. trim(resample) == 'fourier')
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
      real(wp), allocatable :: rows(:, :), mirrored_rows(:)
      type(row_slab) :: file_slab
      character(len=:), allocatable :: mode
      integer :: least, factor, mx, my, y_start, count
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
      if ((factor*mx /= nx .or. factor*my /= ny) .and. trim(resample) /= 'fourier') then
         call fatal_error(error, named(filename) // ' holds shape ' // &
            & shape_text([int(factor*my, i8), int(factor*mx, i8)]) // trim(merge(' (mirrored)', '           ', &
            & mirrored)) // '; allowed: the grid, (ny, nx) = (' // to_string(ny) // ', ' // to_string(nx) // &
            & "), or &profile resample = 'fourier'", code_input)
         return
      end if
      call detrend_slab(rows, file_slab%y_start, my, mode)
      if (mirrored) then
         call mirror_slab(rows, file_slab%y_start, mx, my, mirrored_rows)
         mx = 2*mx
         my = 2*my
         call slab(my, y_start, count)
         rows = reshape(mirrored_rows, [mx, count])
      end if
      if (mx == nx .and. my == ny) then
         height = reshape(rows, [size(rows)])
      else
         call resample_slab(rows, mx, my, nx, ny, height, error)
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

   !> The heights of an mx x my surface whose slab of rows this rank holds (`rows`, mx x its
   !> rows, lc_base_slab) mapped onto the nx x ny grid by their Fourier series, as
   !> lc_profiles_measured's resample_heights maps the whole surface: this rank's slab of the
   !> grid's rows (flat, x fastest). The map keeps a rectangle of modes, so it is the map of
   !> each row along x followed by that of each column along y (each the 1D map of the same
   !> rule: a kept size is left as it is, a changed one keeps the modes both sizes hold
   !> below their Nyquist modes). Along y a column needs every row: the rows are moved to
   !> blocks of columns (each rank ceiling(nx/P) columns, all my rows; MPI_Alltoallv),
   !> mapped, and moved to the grid's slabs. No rank holds more than its share of either
   !> surface; the heights are the serial ones to rounding (the transforms' order).
   subroutine resample_slab(rows, mx, my, nx, ny, height, error)
      real(wp), intent(in) :: rows(:, :)
      integer, intent(in) :: mx, my, nx, ny
      real(wp), allocatable, intent(out) :: height(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: wide(:, :), outgoing(:), incoming(:), columns(:, :), resampled(:, :)
      integer, allocatable :: send_counts(:), send_offsets(:), receive_counts(:), receive_offsets(:)
      integer :: ranks, rank, q, block, first, count, own_first, own_count, rows_here, j, c, next
      type(row_slab) :: target, other_source, other_target

      ranks = rank_count()
      rank = this_rank()
      target = slab_of(nx, ny, ranks, rank)
      rows_here = size(rows, 2)
      ! along x: each row on its own
      if (mx /= nx) then
         call resample_lines(rows, nx, wide, error)
         call agree_error(error, communicator)
         if (allocated(error)) return
      else
         wide = rows
      end if
      if (my == ny) then
         height = reshape(wide, [size(wide)])
         return
      end if
      ! the columns of the grid in blocks, rank q's from q*block (some ranks may hold none)
      block = (nx + ranks - 1)/ranks
      call columns_of(rank, own_first, own_count)
      allocate (send_counts(0:ranks - 1), send_offsets(0:ranks - 1), receive_counts(0:ranks - 1), &
         & receive_offsets(0:ranks - 1))
      ! rows -> columns: to rank q this rank's rows of q's columns, row by row
      do q = 0, ranks - 1
         call columns_of(q, first, count)
         other_source = slab_of(mx, my, ranks, q)
         send_counts(q) = count*rows_here
         receive_counts(q) = own_count*other_source%ny_local
      end do
      call buffers_of(send_counts, receive_counts, send_offsets, receive_offsets, outgoing, incoming)
      next = 0
      do q = 0, ranks - 1
         call columns_of(q, first, count)
         do j = 1, rows_here
            outgoing(next + 1:next + count) = wide(first + 1:first + count, j)
            next = next + count
         end do
      end do
      deallocate (wide)
      call MPI_Alltoallv(outgoing, send_counts, send_offsets, MPI_DOUBLE_PRECISION, incoming, receive_counts, &
         & receive_offsets, MPI_DOUBLE_PRECISION, communicator)
      ! columns(:, c): all my rows of this rank's column own_first + c
      allocate (columns(my, own_count))
      do q = 0, ranks - 1
         other_source = slab_of(mx, my, ranks, q)
         do j = 1, other_source%ny_local
            do c = 1, own_count
               columns(other_source%y_start + j, c) = incoming(receive_offsets(q) + (j - 1)*own_count + c)
            end do
         end do
      end do
      deallocate (outgoing, incoming)
      ! along y: each column on its own
      if (own_count > 0) then
         call resample_lines(columns, ny, resampled, error)
      else
         allocate (resampled(ny, 0))
      end if
      call agree_error(error, communicator)
      if (allocated(error)) return
      deallocate (columns)
      ! columns -> rows: to rank q its rows of this rank's columns, row by row
      do q = 0, ranks - 1
         call columns_of(q, first, count)
         other_target = slab_of(nx, ny, ranks, q)
         send_counts(q) = own_count*other_target%ny_local
         receive_counts(q) = count*target%ny_local
      end do
      call buffers_of(send_counts, receive_counts, send_offsets, receive_offsets, outgoing, incoming)
      next = 0
      do q = 0, ranks - 1
         other_target = slab_of(nx, ny, ranks, q)
         do j = 1, other_target%ny_local
            outgoing(next + 1:next + own_count) = resampled(other_target%y_start + j, :)
            next = next + own_count
         end do
      end do
      deallocate (resampled)
      call MPI_Alltoallv(outgoing, send_counts, send_offsets, MPI_DOUBLE_PRECISION, incoming, receive_counts, &
         & receive_offsets, MPI_DOUBLE_PRECISION, communicator)
      allocate (height(nx*target%ny_local))
      do q = 0, ranks - 1
         call columns_of(q, first, count)
         do j = 1, target%ny_local
            height(nx*(j - 1) + first + 1:nx*(j - 1) + first + count) = &
               & incoming(receive_offsets(q) + (j - 1)*count + 1:receive_offsets(q) + j*count)
         end do
      end do

   contains

      !> The grid's columns first+1 .. first+count in rank q's block (none past nx).
      pure subroutine columns_of(q, first, count)
         integer, intent(in) :: q
         integer, intent(out) :: first, count
         first = min(q*block, nx)
         count = max(0, min(nx, first + block) - first)
      end subroutine columns_of
   end subroutine resample_slab

   !> Each line (column) of `lines` (m values each) mapped by its Fourier series onto n
   !> points (n /= m): the modes below both Nyquist modes kept, as resample_heights keeps
   !> them along an axis whose size changes. out(n, size(lines, 2)).
   subroutine resample_lines(lines, n, out, error)
      real(wp), intent(in) :: lines(:, :)
      integer, intent(in) :: n
      real(wp), allocatable, intent(out) :: out(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(fft_plan) :: from, to
      integer :: m, count, k_max, j
      m = size(lines, 1)
      count = size(lines, 2)
      allocate (out(n, count))
      call from%init(m, count, 1, error)
      if (allocated(error)) return
      call from%plan_rows(error)
      if (allocated(error)) return
      call to%init(n, count, 1, error)
      if (allocated(error)) return
      call to%plan_rows(error)
      if (allocated(error)) return
      from%real_buffer = reshape(lines, [m*count])
      call from%rows_forward_unscaled()
      k_max = min((m - 1)/2, (n - 1)/2)
      to%spectrum = (0.0_wp, 0.0_wp)
      do j = 0, count - 1
         to%spectrum(j*(n/2 + 1) + 1:j*(n/2 + 1) + k_max + 1) = &
            & from%spectrum(j*(m/2 + 1) + 1:j*(m/2 + 1) + k_max + 1)*(1.0_wp/m)
      end do
      call to%rows_backward()
      out = reshape(to%real_buffer, [n, count])
   end subroutine resample_lines

   !> The offsets (from 0) of consecutive blocks of the send and receive counts of an
   !> MPI_Alltoallv, and its buffers.
   pure subroutine buffers_of(send_counts, receive_counts, send_offsets, receive_offsets, outgoing, incoming)
      integer, intent(in) :: send_counts(0:), receive_counts(0:)
      integer, intent(out) :: send_offsets(0:), receive_offsets(0:)
      real(wp), allocatable, intent(inout) :: outgoing(:), incoming(:)
      integer :: q
      send_offsets(0) = 0
      receive_offsets(0) = 0
      do q = 1, size(send_counts) - 1
         send_offsets(q) = send_offsets(q - 1) + send_counts(q - 1)
         receive_offsets(q) = receive_offsets(q - 1) + receive_counts(q - 1)
      end do
      if (allocated(outgoing)) deallocate (outgoing)
      if (allocated(incoming)) deallocate (incoming)
      allocate (outgoing(max(sum(send_counts), 1)), incoming(max(sum(receive_counts), 1)))
   end subroutine buffers_of
#endif
end module lc_profiles_measured_slab
