!> Progress of a long solve on standard error (&solver verbose; Python progress=True): a
!> line when a grid level is solved, and within a level a line every `interval` seconds
!> (iteration, residual, contact fraction, elapsed time). Off by default: sweeps and the
!> library stay silent.
module lc_contact_progress
   use, intrinsic :: iso_fortran_env, only: error_unit
   use lc_base_kinds, only: wp, i8
   use lc_base_strings, only: to_string, formatted
   implicit none (type, external)
   private
   public :: progress_log

   !> Seconds between two lines within a level.
   real(wp), parameter :: interval = 2.0_wp

   type :: progress_log
      logical :: enabled = .false.
      integer(i8) :: start = 0
      integer(i8) :: last = 0
      integer(i8) :: rate = 1
      character(len=:), allocatable :: level   !< the grid being solved, e.g. '512 x 512'
      !> added to the iterations reported (the inner CG solves of the Anderson iteration
      !> count on from the iterations before them)
      integer :: offset = 0
   contains
      procedure :: begin
      procedure :: begin_level
      procedure :: plan
      procedure :: tick
      procedure :: level_done
      procedure :: elapsed
   end type progress_log

contains

   !> Start the clock of the whole solve.
   subroutine begin(self, enabled)
      class(progress_log), intent(inout) :: self
      logical, intent(in) :: enabled
      self%enabled = enabled
      call system_clock(self%start, self%rate)
      self%last = self%start
      self%level = ''
   end subroutine begin

   !> A grid level of nx x ny points starts (ny = 1: a line).
   subroutine begin_level(self, nx, ny)
      class(progress_log), intent(inout) :: self
      integer, intent(in) :: nx, ny
      if (.not. self%enabled) return
      if (ny == 1) then
         self%level = 'n = ' // to_string(nx)
      else
         self%level = to_string(nx) // ' x ' // to_string(ny)
      end if
   end subroutine begin_level

   !> The methods chosen for the level and why (lc_contact_policy).
   subroutine plan(self, reason)
      class(progress_log), intent(inout) :: self
      character(len=*), intent(in) :: reason
      if (.not. self%enabled) return
      call say(self%level // ': ' // reason)
   end subroutine plan

   !> Called once per iteration; writes a line if `interval` seconds passed since the last.
   subroutine tick(self, iteration, residual, contact_fraction)
      class(progress_log), intent(inout) :: self
      integer, intent(in) :: iteration
      real(wp), intent(in) :: residual, contact_fraction
      integer(i8) :: now
      if (.not. self%enabled) return
      call system_clock(now)
      if (real(now - self%last, wp) < interval*self%rate) return
      self%last = now
      call say(self%level // ': iteration ' // to_string(self%offset + iteration) // ', residual ' // &
         & formatted(residual, '(es10.3)') // ', contact fraction ' // formatted(contact_fraction, '(f6.4)') // &
         & ', ' // self%elapsed())
   end subroutine tick

   !> The level is solved: which solver, its iterations, residual and contact fraction.
   subroutine level_done(self, solver, converged, iterations, residual, contact_fraction)
      class(progress_log), intent(inout) :: self
      character(len=*), intent(in) :: solver
      logical, intent(in) :: converged
      integer, intent(in) :: iterations
      real(wp), intent(in) :: residual, contact_fraction
      if (.not. self%enabled) return
      call system_clock(self%last)
      call say(self%level // ': ' // trim(solver) // trim(merge(' converged    ', ' NOT converged', converged)) // &
         & ' in ' // to_string(iterations) // ' iterations, residual ' // formatted(residual, '(es10.3)') // &
         & ', contact fraction ' // formatted(contact_fraction, '(f6.4)') // ', ' // self%elapsed())
   end subroutine level_done

   function elapsed(self) result(text)
      class(progress_log), intent(in) :: self
      character(len=:), allocatable :: text
      integer(i8) :: now
      call system_clock(now)
      text = formatted(real(now - self%start, wp)/self%rate, '(f16.2)') // ' s'
   end function elapsed

   subroutine say(line)
      character(len=*), intent(in) :: line
      write (error_unit, '(a)') 'layercontact: ' // line
      flush (error_unit)
   end subroutine say
end module lc_contact_progress
