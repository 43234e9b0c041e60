!> The ranks of a job sharing one surface (docs/decisions/023-mpi-slabs.md): the
!> communicator, this rank and the rank count, this rank's slab of rows, and the global sums
!> and maxima over the ranks. A build without MPI (no LC_MPI) compiles the one-rank version.
!>
!> The slab contract (FFTW-MPI's `fftw_mpi_local_size_2d` with n0 = ny, n1 = nx): a field
!> f(nx, ny) (x fastest) is split by whole rows; with P ranks the block is ceiling(ny/P) rows
!> and rank r holds rows y_start+1 .. y_start+ny_local (y_start = r*block). A rank count that
!> would leave a rank without rows is refused (`check_rank_count`).
!>
!> One rank (no launcher, or a launcher with one process) is not distributed: every caller
!> then takes the serial code path, and the reductions here return their argument.
module lc_base_parallel
   use, intrinsic :: iso_c_binding, only: c_int
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   use lc_base_strings, only: to_string
   use lc_base_slab, only: row_slab, slab_of
#ifdef LC_MPI
   use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_Allgatherv, &
      & MPI_Gatherv, MPI_Scatterv, MPI_Bcast, MPI_Abort, MPI_Initialized, MPI_IN_PLACE, MPI_SUM, MPI_MAX, MPI_MIN, &
      & MPI_LOR, MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_LOGICAL, MPI_Barrier, MPI_Allgather, MPI_Alltoallv, MPI_Exscan, MPI_Op
#endif
   implicit none (type, external)
   private
   public :: parallel_start, parallel_end, is_distributed, rank_count, this_rank, is_root, slab, slab_rows, check_rank_count
   public :: largest_rank_count, global_sum, global_max, sum_over_ranks, max_over_ranks, global_any
   public :: min_over_lower_ranks, max_over_lower_ranks
   public :: gather_rows, allgather_rows, scatter_rows, redistribute_rows
   public :: broadcast, abort_job, mpi_available, barrier
   public :: broadcast_from, sum_counts_over_ranks, global_maxloc, shifted_rows
#ifdef LC_MPI
   public :: communicator
#endif

   integer :: ranks = 1, rank = 0
#ifdef LC_MPI
   type(MPI_Comm) :: communicator
#endif

   interface broadcast_from
      module procedure broadcast_scalar_from, broadcast_array_from
   end interface broadcast_from

   interface global_sum
      module procedure global_sum_scalar, global_sum_integer
   end interface global_sum

   interface
      function lc_mpi_start() bind(c, name='lc_mpi_start') result(status)
         import :: c_int
         integer(c_int) :: status
      end function lc_mpi_start
      function lc_launch_size() bind(c, name='lc_launch_size') result(size)
         import :: c_int
         integer(c_int) :: size
      end function lc_launch_size
      function lc_launch_rank() bind(c, name='lc_launch_rank') result(rank)
         import :: c_int
         integer(c_int) :: rank
      end function lc_launch_rank
      subroutine lc_mpi_run_begins() bind(c, name='lc_mpi_run_begins')
      end subroutine lc_mpi_run_begins
      subroutine lc_mpi_run_ends() bind(c, name='lc_mpi_run_ends')
      end subroutine lc_mpi_run_ends
   end interface

contains

   !> True if this build can share a surface among the ranks of a job (MPI and FFTW-MPI).
   pure logical function mpi_available()
#ifdef LC_MPI
      mpi_available = .true.
#else
      mpi_available = .false.
#endif
   end function mpi_available

   !> Start MPI when a launcher started this process (once; a plain run does nothing) and
   !> take the job's ranks: MPI_COMM_WORLD, or the communicator whose Fortran handle is
   !> `handle` (a caller's own, as mpi4py's `comm.py2f()` gives it: MPI already started).
   !> Until parallel_end every caller works on these ranks. A build without MPI started as
   !> one of several ranks is refused: each rank would solve the whole scene alone.
   subroutine parallel_start(error, handle)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: handle
#ifdef LC_MPI
      logical :: initialized
      integer :: value
      ranks = 1
      rank = 0
      if (.not. present(handle)) then
         if (lc_mpi_start() /= 0) then
            call fatal_error(error, 'MPI could not be started under the launcher', code_internal)
            return
         end if
      end if
      call MPI_Initialized(initialized)
      if (.not. initialized) return
      communicator = MPI_COMM_WORLD
      if (present(handle)) communicator%MPI_VAL = handle
      call MPI_Comm_size(communicator, value)
      ranks = value
      call MPI_Comm_rank(communicator, value)
      rank = value
      ! (a rank leaving before parallel_end ends the job: src/base/launcher.c)
      if (ranks > 1) call lc_mpi_run_begins()
#else
      ranks = 1
      rank = 0
      if (present(handle)) return
      ! (the launcher's rank 0 is the one that says why)
      if (lc_launch_size() > 1) rank = lc_launch_rank()
      if (lc_launch_size() > 1) call fatal_error(error, 'this build of layercontact has no MPI (meson option ' // &
         & "'mpi': MPI for Fortran or FFTW-MPI not found) and was started as one of " // &
         & to_string(int(lc_launch_size())) // ' ranks, each of which would solve the whole scene alone; ' // &
         & 'allowed: one process (no mpirun, or mpirun -n 1), or a build with MPI (docs/clusters.md)', code_input)
#endif
   end subroutine parallel_start

   !> Back to one rank (MPI itself stays started: it is finished at exit): what runs after
   !> a distributed run in the same process (a Python program's in-memory solves) is serial.
   subroutine parallel_end()
      call lc_mpi_run_ends()
      ranks = 1
      rank = 0
   end subroutine parallel_end

   !> More than one rank shares the surface.
   logical function is_distributed()
      is_distributed = ranks > 1
   end function is_distributed

   integer function rank_count()
      rank_count = ranks
   end function rank_count

   integer function this_rank()
      this_rank = rank
   end function this_rank

   !> Rank 0: the one that reads and writes files.
   logical function is_root()
      is_root = rank == 0
   end function is_root

   !> The slab of rank r of a surface of ny rows (lc_base_slab, the split FFTW-MPI and the
   !> slab files share): its first row y_start (0-based) and its row count.
   pure subroutine slab_rows(ny, p, r, y_start, ny_local)
      integer, intent(in) :: ny, p, r
      integer, intent(out) :: y_start, ny_local
      type(row_slab) :: rows
      rows = slab_of(1, ny, p, r)
      y_start = min(rows%y_start, ny)
      ny_local = rows%ny_local
   end subroutine slab_rows

   !> This rank's slab of a surface of ny rows.
   subroutine slab(ny, y_start, ny_local)
      integer, intent(in) :: ny
      integer, intent(out) :: y_start, ny_local
      call slab_rows(ny, ranks, rank, y_start, ny_local)
   end subroutine slab

   !> The largest rank count up to `most` that leaves every rank at least one row of ny
   !> (the last rank's slab starts at (P - 1) ceiling(ny/P), which must be below ny; the
   !> counts allowed are not contiguous: 6 rows take 3 or 6 ranks, not 4 or 5).
   pure integer function largest_rank_count(ny, most) result(p)
      integer, intent(in) :: ny, most
      integer :: y_start, rows
      do p = max(min(ny, most), 1), 2, -1
         call slab_rows(ny, p, p - 1, y_start, rows)
         if (rows > 0) return
      end do
      p = 1
   end function largest_rank_count

   !> Refuse a rank count that would leave a rank without rows of a surface of ny rows.
   subroutine check_rank_count(ny, error)
      integer, intent(in) :: ny
      type(error_type), allocatable, intent(out) :: error
      if (largest_rank_count(ny, ranks) < ranks) &
         & call fatal_error(error, '&scene ny = ' // to_string(ny) // ' rows cannot be shared among ' // &
         & to_string(ranks) // ' MPI ranks (slabs of ceiling(ny/ranks) rows leave a rank without rows); ' // &
         & 'allowed: at most ' // to_string(largest_rank_count(ny, ranks)) // ' ranks here, or a count P ' // &
         & 'with (P - 1) ceiling(ny/P) < ny', code_input)
   end subroutine check_rank_count

   !> The sum over the ranks (the ranks' partial sums added in rank order by MPI).
   real(wp) function global_sum_scalar(x) result(total)
      real(wp), intent(in) :: x
      total = x
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(x, total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, communicator)
#endif
   end function global_sum_scalar

   integer function global_sum_integer(x) result(total)
      integer, intent(in) :: x
      total = x
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(x, total, 1, MPI_INTEGER, MPI_SUM, communicator)
#endif
   end function global_sum_integer

   !> x <- its sum over the ranks, element by element (one message for several sums).
   subroutine sum_over_ranks(x)
      real(wp), contiguous, intent(inout) :: x(:)
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, communicator)
#else
      if (.false.) x = x
#endif
   end subroutine sum_over_ranks

   real(wp) function global_max(x) result(largest)
      real(wp), intent(in) :: x
      largest = x
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(x, largest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, communicator)
#endif
   end function global_max

   subroutine max_over_ranks(x)
      real(wp), contiguous, intent(inout) :: x(:)
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_MAX, communicator)
#else
      if (.false.) x = x
#endif
   end subroutine max_over_ranks

   !> x <- the least of the lower ranks' x, element by element (huge on the first rank):
   !> what a walk through the ranks in their order has seen before it reaches this one.
   subroutine min_over_lower_ranks(x)
      real(wp), contiguous, intent(inout) :: x(:)
#ifdef LC_MPI
      call over_lower_ranks(x, MPI_MIN, huge(1.0_wp))
#else
      x = huge(1.0_wp)
#endif
   end subroutine min_over_lower_ranks

   !> x <- the largest of the lower ranks' x, element by element (-huge on the first rank).
   subroutine max_over_lower_ranks(x)
      real(wp), contiguous, intent(inout) :: x(:)
#ifdef LC_MPI
      call over_lower_ranks(x, MPI_MAX, -huge(1.0_wp))
#else
      x = -huge(1.0_wp)
#endif
   end subroutine max_over_lower_ranks
#ifdef LC_MPI

   !> x <- the lower ranks' x combined by `operation`, element by element (one MPI_Exscan);
   !> `first` on the first rank, which has none below it (and on one rank).
   subroutine over_lower_ranks(x, operation, first)
      real(wp), contiguous, intent(inout) :: x(:)
      type(MPI_Op), intent(in) :: operation
      real(wp), intent(in) :: first
      real(wp), allocatable :: below(:)
      if (ranks == 1) then
         x = first
         return
      end if
      allocate (below(size(x)))
      call MPI_Exscan(x, below, size(x), MPI_DOUBLE_PRECISION, operation, communicator)
      ! (MPI leaves the first rank's result undefined)
      if (rank == 0) below = first
      x = below
   end subroutine over_lower_ranks
#endif

   logical function global_any(x) result(any_rank)
      logical, intent(in) :: x
      any_rank = x
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(x, any_rank, 1, MPI_LOGICAL, MPI_LOR, communicator)
#endif
   end function global_any

   !> x from rank 0 on every rank.
   subroutine broadcast(x)
      real(wp), intent(inout) :: x
#ifdef LC_MPI
      if (ranks > 1) call MPI_Bcast(x, 1, MPI_DOUBLE_PRECISION, 0, communicator)
#else
      if (.false.) x = x
#endif
   end subroutine broadcast

   !> x from rank `owner` on every rank.
   subroutine broadcast_scalar_from(x, owner)
      real(wp), intent(inout) :: x
      integer, intent(in) :: owner
#ifdef LC_MPI
      if (ranks > 1) call MPI_Bcast(x, 1, MPI_DOUBLE_PRECISION, owner, communicator)
#else
      if (.false. .and. owner > 0) x = x
#endif
   end subroutine broadcast_scalar_from

   !> x(:) from rank `owner` on every rank (every rank's x of the same size).
   subroutine broadcast_array_from(x, owner)
      real(wp), contiguous, intent(inout) :: x(:)
      integer, intent(in) :: owner
#ifdef LC_MPI
      if (ranks > 1) call MPI_Bcast(x, size(x), MPI_DOUBLE_PRECISION, owner, communicator)
#else
      if (.false. .and. owner > 0) x = x
#endif
   end subroutine broadcast_array_from

   !> counts <- their sum over the ranks, element by element.
   subroutine sum_counts_over_ranks(counts)
      integer, contiguous, intent(inout) :: counts(:)
#ifdef LC_MPI
      if (ranks > 1) call MPI_Allreduce(MPI_IN_PLACE, counts, size(counts), MPI_INTEGER, MPI_SUM, communicator)
#else
      if (.false.) counts = counts
#endif
   end subroutine sum_counts_over_ranks

   !> The largest of the slabs' values over the ranks, the rank holding it and its index in
   !> that rank's slab (ties: the first in the whole field's order, as maxloc takes it on one
   !> process; the slabs follow each other in rank order).
   subroutine global_maxloc(values, largest, owner, position)
      real(wp), intent(in) :: values(:)
      real(wp), intent(out) :: largest
      integer, intent(out) :: owner, position
      real(wp) :: first_owner
      position = maxloc(values, dim=1)
      largest = values(position)
      owner = rank
      if (ranks == 1) return
      largest = global_max(largest)
      ! (the lowest rank holding the largest value: the first of them in the field's order)
      first_owner = -real(ranks, wp)
      if (values(position) == largest) first_owner = -real(rank, wp)
      owner = nint(-global_max(first_owner))
   end subroutine global_maxloc

   !> The field (nx x ny) shifted periodically by `shift` rows, this rank's slab of it:
   !> shifted's row j is the field's row j + shift (mod ny), `local` this rank's slab. Each
   !> rank sends every other the rows of its slab that the other's shifted slab holds (one
   !> MPI_Alltoallv; a slab needs rows of at most two ranks when |shift| is below a block).
   subroutine shifted_rows(local, nx, ny, shift, shifted)
      real(wp), contiguous, intent(in) :: local(:)
      integer, intent(in) :: nx, ny, shift
      real(wp), allocatable, intent(out) :: shifted(:)
      integer :: y_start, rows, row
#ifdef LC_MPI
      integer :: send_counts(0:ranks - 1), send_offsets(0:ranks - 1), receive_counts(0:ranks - 1), &
         & receive_offsets(0:ranks - 1), r, first, count_rows
      if (ranks > 1) then
         call slab(ny, y_start, rows)
         allocate (shifted(nx*rows))
         ! what rank r's shifted slab takes from mine, and what mine takes from rank r
         do r = 0, ranks - 1
            call overlap(r, rank, first, count_rows)
            send_counts(r) = nx*count_rows
            send_offsets(r) = nx*first
            call overlap(rank, r, first, count_rows)
            receive_counts(r) = nx*count_rows
            receive_offsets(r) = nx*modulo(first + (r*block_of(ny) - y_start) - shift, ny)
         end do
         call MPI_Alltoallv(local, send_counts, send_offsets, MPI_DOUBLE_PRECISION, shifted, receive_counts, &
            & receive_offsets, MPI_DOUBLE_PRECISION, communicator)
         return
      end if
#endif
      call slab(ny, y_start, rows)
      allocate (shifted(nx*rows))
      do row = 0, rows - 1
         shifted(row*nx + 1:(row + 1)*nx) = local(modulo(row + shift, ny)*nx + 1:(modulo(row + shift, ny) + 1)*nx)
      end do
#ifdef LC_MPI

   contains

      !> The rows of `source`'s slab that `target`'s shifted slab holds: the first (0-based,
      !> in the source's slab) and how many (one run: the ranks' rows are one period).
      subroutine overlap(target, source, first, count_rows)
         integer, intent(in) :: target, source
         integer, intent(out) :: first, count_rows
         integer :: target_start, target_rows, source_start, source_rows, k, g
         call slab_rows(ny, ranks, target, target_start, target_rows)
         call slab_rows(ny, ranks, source, source_start, source_rows)
         first = -1
         count_rows = 0
         do k = 0, target_rows - 1
            g = modulo(target_start + k + shift, ny)
            if (g < source_start .or. g >= source_start + source_rows) cycle
            if (first < 0) first = g - source_start
            count_rows = count_rows + 1
         end do
         first = max(first, 0)
      end subroutine overlap
#endif
   end subroutine shifted_rows

   !> The rows of a block of ny rows among the job's ranks (lc_base_slab).
   pure integer function block_of(ny)
      integer, intent(in) :: ny
      block_of = (ny + ranks - 1)/ranks
   end function block_of

   !> The counts and offsets (in values) of every rank's slab of a field of nx x ny.
   subroutine slab_counts(nx, ny, counts, offsets)
      integer, intent(in) :: nx, ny
      integer, intent(out) :: counts(0:), offsets(0:)
      integer :: r, y_start, rows
      do r = 0, ranks - 1
         call slab_rows(ny, ranks, r, y_start, rows)
         counts(r) = nx*rows
         offsets(r) = nx*y_start
      end do
   end subroutine slab_counts

   !> The whole field (nx x ny) on rank 0 from every rank's slab `local` (`full` is
   !> allocated on rank 0 only; one rank: a copy).
   subroutine gather_rows(local, nx, ny, full)
      real(wp), contiguous, intent(in) :: local(:)
      integer, intent(in) :: nx, ny
      real(wp), allocatable, intent(out) :: full(:)
#ifdef LC_MPI
      integer :: counts(0:ranks - 1), offsets(0:ranks - 1)
      if (ranks > 1) then
         call slab_counts(nx, ny, counts, offsets)
         allocate (full(merge(nx*ny, 0, rank == 0)))
         call MPI_Gatherv(local, size(local), MPI_DOUBLE_PRECISION, full, counts, offsets, MPI_DOUBLE_PRECISION, 0, &
            & communicator)
         return
      end if
#endif
      full = local
   end subroutine gather_rows

   !> The whole field (nx x ny) on every rank from every rank's slab `local`.
   subroutine allgather_rows(local, nx, ny, full)
      real(wp), contiguous, intent(in) :: local(:)
      integer, intent(in) :: nx, ny
      real(wp), allocatable, intent(out) :: full(:)
#ifdef LC_MPI
      integer :: counts(0:ranks - 1), offsets(0:ranks - 1)
      if (ranks > 1) then
         call slab_counts(nx, ny, counts, offsets)
         allocate (full(nx*ny))
         call MPI_Allgatherv(local, size(local), MPI_DOUBLE_PRECISION, full, counts, offsets, MPI_DOUBLE_PRECISION, &
            & communicator)
         return
      end if
#endif
      full = local
   end subroutine allgather_rows

   !> Every rank's slab `local` of the field `full` (nx x ny) that rank 0 holds.
   subroutine scatter_rows(full, nx, ny, local)
      real(wp), contiguous, intent(in) :: full(:)
      integer, intent(in) :: nx, ny
      real(wp), allocatable, intent(out) :: local(:)
      integer :: y_start, rows
#ifdef LC_MPI
      integer :: counts(0:ranks - 1), offsets(0:ranks - 1)
      if (ranks > 1) then
         call slab_counts(nx, ny, counts, offsets)
         call slab(ny, y_start, rows)
         allocate (local(nx*rows))
         call MPI_Scatterv(full, counts, offsets, MPI_DOUBLE_PRECISION, local, nx*rows, MPI_DOUBLE_PRECISION, 0, &
            & communicator)
         return
      end if
#endif
      call slab(ny, y_start, rows)
      local = full(nx*y_start + 1:nx*(y_start + rows))
   end subroutine scatter_rows

   !> Rows of a field of `ny` rows of `row_length` values, moved between two layouts over the
   !> ranks: this rank holds the rows `held_first` .. `held_first` + size(held)/row_length - 1
   !> (0-based; the ranks' held rows are disjoint and cover the field, in any split) and
   !> receives in `wanted` the rows `wanted_first` .. `wanted_first` + `wanted_rows` - 1,
   !> counted modulo ny (periodic: a halo row past the last is row 0), from whichever ranks
   !> hold them. The ranks' wanted rows may overlap. One message each way between each pair
   !> of ranks (MPI_Alltoallv); one rank: a copy.
   subroutine redistribute_rows(held, row_length, ny, held_first, wanted_first, wanted_rows, wanted)
      real(wp), contiguous, intent(in) :: held(:)
      integer, intent(in) :: row_length, ny, held_first, wanted_first, wanted_rows
      real(wp), contiguous, intent(out) :: wanted(:)
      integer :: k, row
#ifdef LC_MPI
      integer :: ranges(4, 0:ranks - 1), send_counts(0:ranks - 1), send_offsets(0:ranks - 1)
      integer :: receive_counts(0:ranks - 1), receive_offsets(0:ranks - 1), filled(0:ranks - 1)
      real(wp), allocatable :: outgoing(:), incoming(:)
      integer :: q, owner, next
      if (ranks > 1) then
         ! (every rank's held and wanted rows: what each sends to each, and in which order)
         call MPI_Allgather([held_first, size(held)/row_length, wanted_first, wanted_rows], 4, MPI_INTEGER, ranges, 4, &
            & MPI_INTEGER, communicator)
         send_counts = 0
         do q = 0, ranks - 1
            do k = 0, ranges(4, q) - 1
               row = modulo(ranges(3, q) + k, ny)
               if (row_owner(row, ranges) == rank) send_counts(q) = send_counts(q) + row_length
            end do
         end do
         receive_counts = 0
         do k = 0, wanted_rows - 1
            owner = row_owner(modulo(wanted_first + k, ny), ranges)
            receive_counts(owner) = receive_counts(owner) + row_length
         end do
         send_offsets(0) = 0
         receive_offsets(0) = 0
         do q = 1, ranks - 1
            send_offsets(q) = send_offsets(q - 1) + send_counts(q - 1)
            receive_offsets(q) = receive_offsets(q - 1) + receive_counts(q - 1)
         end do
         allocate (outgoing(max(sum(send_counts), 1)), incoming(max(sum(receive_counts), 1)))
         ! each rank's wanted rows that this one holds, in the order that rank wants them
         next = 1
         do q = 0, ranks - 1
            do k = 0, ranges(4, q) - 1
               row = modulo(ranges(3, q) + k, ny)
               if (row_owner(row, ranges) /= rank) cycle
               outgoing(next:next + row_length - 1) = held((row - held_first)*row_length + 1:(row - held_first + 1)*row_length)
               next = next + row_length
            end do
         end do
         call MPI_Alltoallv(outgoing, send_counts, send_offsets, MPI_DOUBLE_PRECISION, incoming, receive_counts, &
            & receive_offsets, MPI_DOUBLE_PRECISION, communicator)
         filled = receive_offsets
         do k = 0, wanted_rows - 1
            owner = row_owner(modulo(wanted_first + k, ny), ranges)
            wanted(k*row_length + 1:(k + 1)*row_length) = incoming(filled(owner) + 1:filled(owner) + row_length)
            filled(owner) = filled(owner) + row_length
         end do
         return
      end if
#endif
      do k = 0, wanted_rows - 1
         row = modulo(wanted_first + k, ny) - held_first
         wanted(k*row_length + 1:(k + 1)*row_length) = held(row*row_length + 1:(row + 1)*row_length)
      end do
   end subroutine redistribute_rows
#ifdef LC_MPI

   !> The rank whose held rows (ranges(1:2, r): first, count) include `row`.
   pure integer function row_owner(row, ranges) result(owner)
      integer, intent(in) :: row, ranges(:, 0:)
      do owner = 0, size(ranges, 2) - 1
         if (row >= ranges(1, owner) .and. row < ranges(1, owner) + ranges(2, owner)) return
      end do
      owner = -1
   end function row_owner
#endif

   !> Wait for every rank.
   subroutine barrier()
#ifdef LC_MPI
      if (ranks > 1) call MPI_Barrier(communicator)
#endif
   end subroutine barrier

   !> End every rank of the job with exit code `code` (a failure on one rank: the others
   !> would wait for it in their next reduction). One rank: returns.
   subroutine abort_job(code)
      integer, intent(in) :: code
#ifdef LC_MPI
      if (ranks > 1) call MPI_Abort(communicator, code)
#else
      if (.false. .and. code > 0) return
#endif
   end subroutine abort_job
end module lc_base_parallel
