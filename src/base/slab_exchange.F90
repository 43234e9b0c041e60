!> What the observables computed on the slabs of a surface exchange between the ranks
!> (docs/decisions/026-distributed-patches-and-leakage.md): the neighbouring slabs' edge
!> rows (the periodic halo of one row each side), the counts of the ranks, short integer
!> lists gathered to rank 0 and broadcast from it, and integer sums. A build without MPI (no
!> LC_MPI) compiles the one-rank version: the halo of the only slab is its own edge rows, as
!> on a periodic surface of one slab.
module lc_base_slab_exchange
   use lc_base_kinds, only: wp, i8
   use lc_base_parallel, only: rank_count
#ifdef LC_MPI
   use lc_base_parallel, only: communicator, this_rank
   use mpi_f08, only: MPI_Sendrecv, MPI_Allgather, MPI_Gatherv, MPI_Bcast, MPI_Allreduce, MPI_IN_PLACE, MPI_SUM, &
      & MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_INTEGER8, MPI_STATUS_IGNORE
#endif
   implicit none (type, external)
   private
   public :: halo_rows, rank_counts, gather_integers, broadcast_integers, sum_integers, communicator_handle

contains

   !> The row below this slab (the previous rank's last, periodic: the last rank's for rank 0)
   !> and the row above it (the next rank's first; rank 0's for the last rank) of a field
   !> whose slab `local` has rows of nx values.
   subroutine halo_rows(local, nx, below, above)
      real(wp), contiguous, intent(in) :: local(:)
      integer, intent(in) :: nx
      real(wp), intent(out) :: below(nx), above(nx)
      integer :: rows
#ifdef LC_MPI
      integer :: previous, next
#endif
      rows = size(local)/nx
#ifdef LC_MPI
      if (rank_count() > 1) then
         previous = modulo(this_rank() - 1, rank_count())
         next = modulo(this_rank() + 1, rank_count())
         ! the first row goes down (it is the previous rank's row above), the last row up
         call MPI_Sendrecv(local(1:nx), nx, MPI_DOUBLE_PRECISION, previous, 1, above, nx, MPI_DOUBLE_PRECISION, &
            & next, 1, communicator, MPI_STATUS_IGNORE)
         call MPI_Sendrecv(local(nx*(rows - 1) + 1:nx*rows), nx, MPI_DOUBLE_PRECISION, next, 2, below, nx, &
            & MPI_DOUBLE_PRECISION, previous, 2, communicator, MPI_STATUS_IGNORE)
         return
      end if
#endif
      below = local(nx*(rows - 1) + 1:nx*rows)
      above = local(1:nx)
   end subroutine halo_rows

   !> Every rank's value of n, in rank order (counts(0:P-1)).
   subroutine rank_counts(n, counts)
      integer, intent(in) :: n
      integer, allocatable, intent(out) :: counts(:)
      allocate (counts(0:rank_count() - 1))
      counts = n
#ifdef LC_MPI
      if (rank_count() > 1) call MPI_Allgather(n, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, communicator)
#endif
   end subroutine rank_counts

   !> Every rank's list `local` one after the other in rank order, on rank 0 (`all` is empty
   !> on the others).
   subroutine gather_integers(local, all)
      integer, contiguous, intent(in) :: local(:)
      integer, allocatable, intent(out) :: all(:)
#ifdef LC_MPI
      integer, allocatable :: counts(:), offsets(:)
      integer :: r
      if (rank_count() > 1) then
         call rank_counts(size(local), counts)
         allocate (offsets(0:rank_count() - 1))
         offsets(0) = 0
         do r = 1, rank_count() - 1
            offsets(r) = offsets(r - 1) + counts(r - 1)
         end do
         allocate (all(merge(sum(counts), 0, this_rank() == 0)))
         call MPI_Gatherv(local, size(local), MPI_INTEGER, all, counts, offsets, MPI_INTEGER, 0, communicator)
         return
      end if
#endif
      all = local
   end subroutine gather_integers

   !> x from rank 0 on every rank (its size is the same on every rank).
   subroutine broadcast_integers(x)
      integer, contiguous, intent(inout) :: x(:)
#ifdef LC_MPI
      if (rank_count() > 1) call MPI_Bcast(x, size(x), MPI_INTEGER, 0, communicator)
#else
      if (.false.) x = x
#endif
   end subroutine broadcast_integers

   !> x <- its sum over the ranks, element by element (exact: integers); x(:, k): the
   !> counts of item k.
   subroutine sum_integers(x)
      integer(i8), contiguous, intent(inout) :: x(:, :)
#ifdef LC_MPI
      if (rank_count() > 1) call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_INTEGER8, MPI_SUM, communicator)
#else
      if (.false.) x = x
#endif
   end subroutine sum_integers

   !> The Fortran handle of the job's communicator for C (hypre's distributed matrices), or
   !> -1 on one rank (then this process alone: MPI_COMM_SELF).
   integer function communicator_handle() result(handle)
      handle = -1
#ifdef LC_MPI
      if (rank_count() > 1) handle = communicator%MPI_VAL
#endif
   end function communicator_handle
end module lc_base_slab_exchange
