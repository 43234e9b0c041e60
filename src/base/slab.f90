!> The rows of a surface's real-space fields that one of several MPI ranks holds. A field
!> f(nx, ny) (x fastest) is split by whole rows y, as FFTW-MPI splits its first dimension
!> n0 = ny by default: with P ranks, block = ceiling(ny/P), rank r holds the rows
!> y_start+1 .. y_start+ny_local with y_start = r*block and
!> ny_local = max(0, min(block, ny - y_start)). A split that leaves a rank without rows is
!> refused before a solve (`empty_rank`).
module lc_base_slab
   implicit none (type, external)
   private
   public :: row_slab, slab_of, empty_rank

   type :: row_slab
      integer :: nx = 0, ny = 0          !< the whole field's sizes
      integer :: ranks = 1, rank = 0     !< P, and this rank r (0-based)
      integer :: y_start = 0             !< rows before this rank's
      integer :: ny_local = 0            !< this rank's rows
   end type row_slab

contains

   !> The rows of rank `rank` of `ranks` of a field (nx, ny).
   pure function slab_of(nx, ny, ranks, rank) result(slab)
      integer, intent(in) :: nx, ny, ranks, rank
      type(row_slab) :: slab
      integer :: block
      block = (ny + ranks - 1)/ranks
      slab = row_slab(nx=nx, ny=ny, ranks=ranks, rank=rank, y_start=rank*block, &
         & ny_local=max(0, min(block, ny - rank*block)))
   end function slab_of

   !> Whether some rank of `ranks` holds no row of ny rows (e.g. ny = 4 on 3 ranks: blocks
   !> of 2 leave the third rank none).
   pure logical function empty_rank(ny, ranks)
      integer, intent(in) :: ny, ranks
      empty_rank = (ranks - 1)*((ny + ranks - 1)/ranks) >= ny
   end function empty_rank
end module lc_base_slab
