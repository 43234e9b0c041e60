!> The memory a solve needs against what this process may use, checked before the large
!> allocations: a grid too large for the machine (or for the job's limit) ends with a
!> clear error (code 5, "needs about X GiB, Y GiB available") instead of an allocation
!> failure or the kernel's out-of-memory killer.
!>
!> What may be used is the smallest of: the memory the kernel reports available
!> (/proc/meminfo MemAvailable), the cgroup's limit less this process's resident memory
!> (cgroup v2 memory.max: batch schedulers such as Slurm confine jobs so), and the address
!> space limit (ulimit -v) less this process's address space. Where none of these can be
!> read (not Linux) the check passes.
module lc_base_memory
   use, intrinsic :: iso_c_binding, only: c_int, c_long_long
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_base_strings, only: to_string
   implicit none (type, external)
   private
   public :: check_memory, solve_bytes, available_bytes, leakage_bytes, check_leakage_memory

   integer(i8), parameter :: unlimited = huge(1_i8)
   !> Linux's RLIMIT_AS
   integer(c_int), parameter :: rlimit_as = 9_c_int

   !> struct rlimit on 64-bit Linux: two rlim_t (unsigned long; RLIM_INFINITY = all ones)
   type, bind(c) :: c_rlimit
      integer(c_long_long) :: current
      integer(c_long_long) :: maximum
   end type c_rlimit

   interface
      integer(c_int) function c_getrlimit(resource, limit) bind(C, name='getrlimit')
         import :: c_int, c_rlimit
         integer(c_int), value, intent(in) :: resource
         type(c_rlimit), intent(out) :: limit
      end function c_getrlimit
   end interface

contains

   !> Bytes a solve of `points` grid points needs: the fields, the multipliers, the FFT
   !> buffers and the solver's work arrays, in doubles per point by solver and geometry, as
   !> bench/memory.py measures them (docs/performance.md, 'Throughput and memory'; docs/numerics.md,
   !> 'Constants of the solvers and their measurements'), plus the in-plane fields of the
   !> stress observables.
   pure integer(i8) function solve_bytes(points, coupled, memory, stress, multigrid, line, gfmd) result(bytes)
      integer, intent(in) :: points
      !> friction or a moving viscoelastic law: the GCR (or Anderson) history; or a frictionless
      !> line that may go to the coupled multigrid iteration (a thin incompressible layer)
      logical, intent(in) :: coupled
      integer, intent(in) :: memory   !< &solver memory (history length)
      logical, intent(in) :: stress
      logical, intent(in) :: multigrid   !< the multigrid solver and its coarse grids
      logical, intent(in) :: line
      logical, intent(in) :: gfmd   !< &solver method = 'gfmd'
      integer :: doubles
      doubles = 15
      if (multigrid) doubles = merge(40, 27, line)
      ! (a coupled scene by the multigrid holds its arrays, then, if it stalls, GCR's history)
      if (coupled) doubles = 6 + 2*max(memory, 1)
      ! (a coupled line by the multigrid may keep up to 140 doubles per point more in its
      ! GCR's directions where a finishing phase stagnates, only where they fit in half the
      ! memory then left: not counted here)
      if (coupled .and. multigrid) doubles = max(doubles, merge(62, 66, line))
      ! (GFMD's positions, velocities, forces and reaction, and with friction the traction,
      ! G_x, 1/G_eff and the 11 fields of its Newton step's GMRES: peak resident 18.1 doubles
      ! per point frictionless at 1024², 34.5-37.6 with friction at 1024² and 512² with the
      ! Anderson history of 10 fields that the GMRES replaced, an upper bound now)
      if (gfmd) doubles = merge(38, 19, coupled)
      if (stress) doubles = doubles + 6
      bytes = 8_i8*doubles*points
   end function solve_bytes

   !> Bytes this process may still allocate (see the module's note); `limit` names the
   !> bound that set it.
   subroutine available_bytes(bytes, limit)
      integer(i8), intent(out) :: bytes
      character(len=:), allocatable, intent(out) :: limit
      integer(i8) :: value, own
      type(c_rlimit) :: rl

      bytes = unlimited
      limit = ''
      value = meminfo_kib('/proc/meminfo', 'MemAvailable:')
      if (value >= 0) call lower(value*1024_i8, 'the memory available on this machine (MemAvailable)')
      value = cgroup_limit()
      own = meminfo_kib('/proc/self/status', 'VmRSS:')
      if (value >= 0 .and. own >= 0) call lower(value - own*1024_i8, "this job's memory limit (cgroup memory.max)")
      if (c_getrlimit(rlimit_as, rl) == 0) then
         own = meminfo_kib('/proc/self/status', 'VmSize:')
         ! (RLIM_INFINITY reads as -1 here)
         if (rl%current > 0 .and. own >= 0) call lower(int(rl%current, i8) - own*1024_i8, &
            & 'the address space limit (ulimit -v)')
      end if
   contains
      subroutine lower(candidate, name)
         integer(i8), intent(in) :: candidate
         character(len=*), intent(in) :: name
         if (candidate < bytes) then
            bytes = max(candidate, 0_i8)
            limit = name
         end if
      end subroutine lower
   end subroutine available_bytes

   !> Error code 5 if a solve of `points` grid points needs more than this process may use.
   subroutine check_memory(points, coupled, memory, stress, multigrid, line, gfmd, error)
      integer, intent(in) :: points, memory
      logical, intent(in) :: coupled, stress, multigrid, line, gfmd
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: needed, available
      character(len=:), allocatable :: limit
      needed = solve_bytes(points, coupled, memory, stress, multigrid, line, gfmd)
      call available_bytes(available, limit)
      if (needed <= available) return
      call fatal_error(error, 'not enough memory: this scene (' // to_string(points) // ' grid points) needs about ' &
         & // gib(needed) // ' GiB, and ' // gib(available) // ' GiB are left under ' // limit // &
         & '; allowed: a smaller grid, or a machine or job with more memory (Slurm: --mem)', code_internal)
   end subroutine check_memory

   !> Bytes the Reynolds leakage of `points` cells needs at its peak: 36 doubles per cell
   !> (the Fortran arrays, hypre's matrix and BoomerAMG hierarchy; 268 bytes per cell measured
   !> from 256^2 to 1024^2 with 79 % of the cells open, resident and address space alike) and,
   !> where MPI does not run yet, the 200 MiB of address space its start maps (196 measured;
   !> bench/leakage_memory.py).
   pure integer(i8) function leakage_bytes(points, mpi_started) result(bytes)
      integer(i8), intent(in) :: points
      !> whether MPI already runs in this process
      logical, intent(in) :: mpi_started
      bytes = 8_i8*36*points
      if (.not. mpi_started) bytes = bytes + 200_i8*2_i8**20
   end function leakage_bytes

   !> Error code 5 if the leakage of `points` cells, with `resident` more doubles per cell
   !> allocated meanwhile (the solution's fields, when checked before the solve), needs more
   !> than this process may use.
   subroutine check_leakage_memory(points, resident, mpi_started, error)
      integer(i8), intent(in) :: points
      integer, intent(in) :: resident
      logical, intent(in) :: mpi_started
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: needed, available
      character(len=:), allocatable :: limit
      needed = leakage_bytes(points, mpi_started) + 8_i8*resident*points
      call available_bytes(available, limit)
      if (needed <= available) return
      call fatal_error(error, 'not enough memory: the leakage of ' // to_string(points) // ' cells needs about ' &
         & // gib(needed) // ' GiB, and ' // gib(available) // ' GiB are left under ' // limit // &
         & '; allowed: a smaller grid, &output leakage = .false., or a machine or job with more memory (Slurm: --mem)', &
         & code_internal)
   end subroutine check_leakage_memory

   !> Bytes in GiB with one decimal.
   function gib(bytes) result(text)
      integer(i8), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=24) :: buffer
      write (buffer, '(f0.1)') real(bytes, wp)/1024.0_wp**3
      text = trim(adjustl(buffer))
      if (text(1:1) == '.') text = '0' // text
   end function gib

   !> The value in kiB of the line starting with `key` in a /proc file of the form
   !> "Key:   1234 kB"; -1 if the file or the key cannot be read.
   function meminfo_kib(file, key) result(kib)
      character(len=*), intent(in) :: file, key
      integer(i8) :: kib
      character(len=256) :: line
      integer :: unit, stat
      kib = -1
      open (newunit=unit, file=file, status='old', action='read', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (index(line, key) == 1) then
            read (line(len(key) + 1:), *, iostat=stat) kib
            if (stat /= 0) kib = -1
            exit
         end if
      end do
      close (unit)
   end function meminfo_kib

   !> The memory limit (bytes) of this process's cgroup (v2: /proc/self/cgroup "0::PATH",
   !> /sys/fs/cgroup/PATH/memory.max); -1 if there is none or it cannot be read.
   function cgroup_limit() result(bytes)
      integer(i8) :: bytes
      character(len=4096) :: line
      character(len=32) :: text
      integer :: unit, stat
      bytes = -1
      open (newunit=unit, file='/proc/self/cgroup', status='old', action='read', iostat=stat)
      if (stat /= 0) return
      line = ''
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) then
            line = ''
            exit
         end if
         if (index(line, '0::') == 1) exit
      end do
      close (unit)
      if (len_trim(line) < 4) return
      open (newunit=unit, file='/sys/fs/cgroup' // trim(line(4:)) // '/memory.max', status='old', action='read', &
         & iostat=stat)
      if (stat /= 0) return
      read (unit, '(a)', iostat=stat) text
      close (unit)
      if (stat /= 0 .or. trim(text) == 'max') return
      read (text, *, iostat=stat) bytes
      if (stat /= 0) bytes = -1
   end function cgroup_limit
end module lc_base_memory
