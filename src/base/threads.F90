!> The threads of one solve (docs/decisions/022-threads.md): how many the job was given, and
!> the OpenMP setting that the solvers' parallel loops and FFTW's threads then use.
!>
!> `&solver threads = 0` (the default) means "what the job was given": OMP_NUM_THREADS if set,
!> else Slurm's SLURM_CPUS_PER_TASK, else the CPUs this process may run on (its affinity
!> mask, not the machine's count: a job sharing a node sees its own CPUs). A build without
!> OpenMP runs one thread.
module lc_base_threads
   use, intrinsic :: iso_c_binding, only: c_int
#ifdef LC_OPENMP
   use omp_lib, only: omp_set_num_threads, omp_get_max_threads, omp_get_thread_num
#endif
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   implicit none (type, external)
   private
   public :: openmp_available, job_threads, solve_threads, use_threads, active_threads, thread_number, most_threads
   public :: parallel_points, reduction_block, reduction_blocks, block_range
   public :: copy_field, fill_field, largest_magnitude

   !> The largest thread count &solver threads accepts.
   integer, parameter :: most_threads = 1024
   !> A pass over fewer points than this runs on one thread: waking the others costs a few
   !> microseconds, the time of a pass over some 10^4 points (docs/decisions/022-threads.md).
   integer, parameter :: parallel_points = 32768
   !> Sums over the grid add blocks of this many points each in order, then the blocks' sums
   !> in order: the same bits on any number of threads (reduction_blocks).
   integer, parameter :: reduction_block = 8192

   interface
      function lc_affinity_cpus() bind(c, name='lc_affinity_cpus') result(count)
         import :: c_int
         integer(c_int) :: count
      end function lc_affinity_cpus
   end interface

contains

   !> The blocks of reduction_block points that a sum over n points adds separately.
   pure integer function reduction_blocks(n)
      integer, intent(in) :: n
      reduction_blocks = max((n + reduction_block - 1)/reduction_block, 1)
   end function reduction_blocks

   !> The points first..last of reduction block `block` of a sum over n points.
   pure subroutine block_range(block, n, first, last)
      integer, intent(in) :: block, n
      integer, intent(out) :: first, last
      first = (block - 1)*reduction_block + 1
      last = min(block*reduction_block, n)
   end subroutine block_range

   !> target <- source, by blocks on the solve's threads. A copy into a fresh array is its
   !> first touch too: each thread then zeroes the pages of its own blocks (the kernel's
   !> page clearing, a sizeable part of a solve's set-up, is shared as the pass is).
   subroutine copy_field(source, target)
      real(wp), contiguous, intent(in) :: source(:)
      real(wp), contiguous, intent(out) :: target(:)
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(source) >= parallel_points)
      do block = 1, reduction_blocks(size(source))
         call block_range(block, size(source), first, last)
         call copy_block(source(first:last), target(first:last))
      end do
   end subroutine copy_field

   !> field <- value, by blocks on the solve's threads (the first touch of a fresh field,
   !> as copy_field).
   subroutine fill_field(field, value)
      real(wp), contiguous, intent(out) :: field(:)
      real(wp), intent(in) :: value
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(field) >= parallel_points)
      do block = 1, reduction_blocks(size(field))
         call block_range(block, size(field), first, last)
         call fill_block(field(first:last), value)
      end do
   end subroutine fill_field

   !> max |field| (0 for an empty field), by blocks on the solve's threads: a maximum is
   !> exact in any order, so the same on any thread count.
   real(wp) function largest_magnitude(field) result(largest)
      real(wp), contiguous, intent(in) :: field(:)
      real(wp) :: maxima(reduction_blocks(size(field)))
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(field) >= parallel_points)
      do block = 1, size(maxima)
         call block_range(block, size(field), first, last)
         maxima(block) = block_largest(field(first:last))
      end do
      largest = maxval(maxima)
   end function largest_magnitude

   !> largest_magnitude on a block.
   pure real(wp) function block_largest(field) result(largest)
      real(wp), contiguous, intent(in) :: field(:)
      largest = maxval(abs(field))
   end function block_largest

   !> copy_field on a block (a procedure of its own: decisions/022).
   pure subroutine copy_block(source, target)
      real(wp), contiguous, intent(in) :: source(:)
      real(wp), contiguous, intent(out) :: target(:)
      target = source
   end subroutine copy_block

   !> fill_field on a block.
   pure subroutine fill_block(field, value)
      real(wp), contiguous, intent(out) :: field(:)
      real(wp), intent(in) :: value
      field = value
   end subroutine fill_block

   !> True if this build runs a solve on several threads (OpenMP and FFTW's threads).
   pure logical function openmp_available()
#ifdef LC_OPENMP
      openmp_available = .true.
#else
      openmp_available = .false.
#endif
   end function openmp_available

   !> The threads the job was given: OMP_NUM_THREADS (its first entry: the outer level),
   !> else SLURM_CPUS_PER_TASK, else the CPUs of the process's affinity mask; at least 1, at
   !> most most_threads. A variable that is not a positive integer is passed over.
   integer function job_threads() result(threads)
      threads = positive_variable('OMP_NUM_THREADS')
      if (threads == 0) threads = positive_variable('SLURM_CPUS_PER_TASK')
      if (threads == 0) threads = int(lc_affinity_cpus())
      threads = min(max(threads, 1), most_threads)
   end function job_threads

   !> The threads a solve runs on for `requested` (&solver threads: 0 = what the job was
   !> given); 1 in a build without OpenMP, where a request of more is refused.
   subroutine solve_threads(requested, threads, error)
      integer, intent(in) :: requested
      integer, intent(out) :: threads
      type(error_type), allocatable, intent(out) :: error
      threads = 1
      if (requested < 0 .or. requested > most_threads) then
         call fatal_error(error, '&solver: threads = ' // to_string(requested) // ' is out of range; allowed: ' // &
            & '0 <= threads <= ' // to_string(most_threads) // ' (0: what the job was given)', code_input)
         return
      end if
      if (.not. openmp_available()) then
         if (requested > 1) call fatal_error(error, '&solver: threads = ' // to_string(requested) // &
            & ' needs a build with OpenMP (meson option openmp, found where OpenMP and FFTW''s threads are); ' // &
            & 'allowed in this build: threads = 0 or 1', code_input)
         return
      end if
      threads = requested
      if (threads == 0) threads = job_threads()
   end subroutine solve_threads

   !> Run the OpenMP regions that this thread starts on `threads` threads (the setting is the
   !> calling thread's own: solves started from several Python threads keep theirs).
   subroutine use_threads(threads)
      integer, intent(in) :: threads
#ifdef LC_OPENMP
      call omp_set_num_threads(max(threads, 1))
#else
      if (threads < 0) return
#endif
   end subroutine use_threads

   !> The threads the OpenMP regions of this thread run on now (1 without OpenMP).
   integer function active_threads()
#ifdef LC_OPENMP
      active_threads = omp_get_max_threads()
#else
      active_threads = 1
#endif
   end function active_threads

   !> This thread's number in the team that runs it, 0 .. threads-1 (0 outside a parallel
   !> region and without OpenMP).
   integer function thread_number()
#ifdef LC_OPENMP
      thread_number = omp_get_thread_num()
#else
      thread_number = 0
#endif
   end function thread_number

   !> A positive integer environment variable's value, or 0 (unset, empty, or not one).
   integer function positive_variable(name) result(value)
      character(len=*), intent(in) :: name
      character(len=64) :: text
      integer :: length, status, comma
      value = 0
      call get_environment_variable(name, text, length, status)
      if (status /= 0 .or. length == 0) return
      comma = index(text, ',')
      if (comma > 0) text = text(:comma - 1)
      if (verify(trim(adjustl(text)), '0123456789') /= 0 .or. len_trim(text) == 0) return
      read (text, *, iostat=status) value
      if (status /= 0 .or. value < 0) value = 0
   end function positive_variable

end module lc_base_threads
