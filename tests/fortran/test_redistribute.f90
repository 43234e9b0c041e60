!> lc_base_parallel's redistribute_rows: the rows of a field moved between two layouts over
!> the ranks. Run by `meson test` on one rank (the copy of the one-rank version) and by
!> tests/test_mpi.py under `mpirun -n P`, P = 1..4. Every rank checks what it received
!> against the closed form the field was made from, f(x, y) = x + 1000 y (exact in
!> binary), so a row from the wrong rank or in the wrong order fails by at least 1.
!>
!> The layouts are those of the coarse start on the slabs (lc_contact_solve): the coarse
!> rows a fine slab samples (its even rows) into the coarse grid's slab contract, and
!> back, each rank its coarse rows with the next one (periodic: the last rank's wraps to
!> row 0); and the whole field on every rank, from a rank-dependent row on (wrapping).
!> The coarse grids have 21 rows (no P of 2..4 divides them; their fine grids 42, blocks
!> of 21, 14 and 11 rows) and 32 rows; a field of one row per rank with P = 4 is too small
!> for the slab contract and not tried.
program test_redistribute
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_parallel, only: parallel_start, parallel_end, rank_count, this_rank, slab_rows, redistribute_rows
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   integer, parameter :: nx = 5
   type(error_type), allocatable :: error
   integer :: ranks, rank, k
   integer, parameter :: coarse_rows(2) = [21, 32]

   call parallel_start(error)
   if (allocated(error)) error stop 2
   ranks = rank_count()
   rank = this_rank()
   do k = 1, size(coarse_rows)
      call check_coarse_layouts(coarse_rows(k))
      call check_whole_field(coarse_rows(k))
   end do
   ! (the ranks leave together: a rank leaving before parallel_end would end the job)
   call parallel_end()
   call finish('redistribute_rows')

contains

   !> f(x, y) on the rows first .. first + rows - 1 (modulo ny), row after row.
   pure function closed_form(first, rows, ny) result(f)
      integer, intent(in) :: first, rows, ny
      real(wp) :: f(nx*rows)
      integer :: k, x
      do k = 0, rows - 1
         do x = 1, nx
            f(k*nx + x) = x + 1000.0_wp*modulo(first + k, ny)
         end do
      end do
   end function closed_form

   !> The sampled even rows of the fine slabs into the coarse slabs, and from the coarse
   !> slabs the rows each fine slab interpolates from (its halo row past the end).
   subroutine check_coarse_layouts(nyc)
      integer, intent(in) :: nyc
      integer :: y_start, ny_local, first, last, yc_start, nyc_local, halo_first, halo_rows
      real(wp), allocatable :: held(:), wanted(:)
      character(len=64) :: what
      call slab_rows(2*nyc, ranks, rank, y_start, ny_local)
      first = (y_start + 1)/2
      last = (y_start + ny_local - 1)/2
      call slab_rows(nyc, ranks, rank, yc_start, nyc_local)
      held = closed_form(first, max(last - first + 1, 0), nyc)
      allocate (wanted(nx*nyc_local))
      call redistribute_rows(held, nx, nyc, first, yc_start, nyc_local, wanted)
      write (what, '(a, i0, a)') 'coarse slab of ', nyc, ' rows from the sampled fine rows'
      call check(all(wanted == closed_form(yc_start, nyc_local, nyc)), trim(what))

      halo_first = y_start/2
      halo_rows = (y_start + ny_local - 1)/2 - halo_first + 2
      held = closed_form(yc_start, nyc_local, nyc)
      deallocate (wanted)
      allocate (wanted(nx*halo_rows))
      call redistribute_rows(held, nx, nyc, yc_start, halo_first, halo_rows, wanted)
      write (what, '(a, i0, a)') 'coarse rows of a fine slab with the periodic next (', nyc, ' rows)'
      call check(all(wanted == closed_form(halo_first, halo_rows, nyc)), trim(what))
   end subroutine check_coarse_layouts

   !> Every row on every rank, starting at row 5 r (an all-gather with a rotation).
   subroutine check_whole_field(ny)
      integer, intent(in) :: ny
      integer :: y_start, ny_local
      real(wp), allocatable :: wanted(:)
      character(len=64) :: what
      call slab_rows(ny, ranks, rank, y_start, ny_local)
      allocate (wanted(nx*ny))
      call redistribute_rows(closed_form(y_start, ny_local, ny), nx, ny, y_start, 5*rank, ny, wanted)
      write (what, '(a, i0, a)') 'the whole field of ', ny, ' rows from row 5 r'
      call check(all(wanted == closed_form(5*rank, ny, ny)), trim(what))
   end subroutine check_whole_field
end program test_redistribute
