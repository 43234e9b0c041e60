!> What several MPI ranks must agree on before one of them acts for all: whether any of
!> them failed (and, if so, the first failing rank's error, which all then return), and
!> one rank's text or number. Used by the writers and readers of files shared by the
!> ranks (lc_io_hdf5_slabs, lc_profiles_height_slabs), so that no rank renames a file
!> another rank failed to write, and every rank returns the same error.
module lc_io_mpi_agree
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_Bcast, MPI_Comm_rank, MPI_IN_PLACE, MPI_INTEGER, MPI_MIN, &
      & MPI_CHARACTER, MPI_DOUBLE_PRECISION
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error
   implicit none (type, external)
   private
   public :: agree_error, shared_error, broadcast_text, broadcast_real

contains

   !> After a step every rank took: if any rank's `error` is allocated, every rank's becomes
   !> the error of the lowest failing rank (its message and code); else none is. Collective.
   subroutine agree_error(error, comm)
      type(error_type), allocatable, intent(inout) :: error
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, first
      call MPI_Comm_rank(comm, rank)
      first = huge(first)
      if (allocated(error)) first = rank
      call MPI_Allreduce(MPI_IN_PLACE, first, 1, MPI_INTEGER, MPI_MIN, comm)
      if (first == huge(first)) return
      call shared_error(error, first, comm)
   end subroutine agree_error

   !> Every rank's `error` becomes that of rank `root` (none if root has none). Collective.
   subroutine shared_error(error, root, comm)
      type(error_type), allocatable, intent(inout) :: error
      integer, intent(in) :: root
      type(MPI_Comm), intent(in) :: comm
      integer :: header(2), rank
      character(len=:), allocatable :: message
      call MPI_Comm_rank(comm, rank)
      header = [0, -1]
      if (rank == root .and. allocated(error)) header = [error%code, len(error%message)]
      call MPI_Bcast(header, 2, MPI_INTEGER, root, comm)
      if (header(2) < 0) then
         if (allocated(error)) deallocate (error)
         return
      end if
      allocate (character(len=header(2)) :: message)
      if (rank == root) message = error%message
      if (header(2) > 0) call MPI_Bcast(message, header(2), MPI_CHARACTER, root, comm)
      call fatal_error(error, message, header(1))
   end subroutine shared_error

   !> Rank `root`'s `text`, on every rank. Collective.
   function broadcast_text(text, root, comm) result(shared)
      character(len=*), intent(in) :: text
      integer, intent(in) :: root
      type(MPI_Comm), intent(in) :: comm
      character(len=:), allocatable :: shared
      integer :: length, rank
      call MPI_Comm_rank(comm, rank)
      length = len(text)
      call MPI_Bcast(length, 1, MPI_INTEGER, root, comm)
      allocate (character(len=length) :: shared)
      if (rank == root) shared = text
      if (length > 0) call MPI_Bcast(shared, length, MPI_CHARACTER, root, comm)
   end function broadcast_text

   !> Rank `root`'s `value`, on every rank. Collective.
   real(wp) function broadcast_real(value, root, comm) result(shared)
      real(wp), intent(in) :: value
      integer, intent(in) :: root
      type(MPI_Comm), intent(in) :: comm
      shared = value
      call MPI_Bcast(shared, 1, MPI_DOUBLE_PRECISION, root, comm)
   end function broadcast_real
end module lc_io_mpi_agree
