!> What the Fortran unit tests share: one line per check ('ok' or 'FAIL' and what it
!> checked), the failures counted, and the end of a test program (error stop 1 on any).
module lc_test_checks
   implicit none (type, external)
   private
   public :: check, finish

   integer :: failures = 0

contains

   subroutine check(ok, what)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: what
      if (ok) then
         write (*, '(a)') 'ok    ' // what
      else
         write (*, '(a)') 'FAIL  ' // what
         failures = failures + 1
      end if
   end subroutine check

   !> End the program: error stop 1 if a check failed, else say that all of `what` passed.
   subroutine finish(what)
      character(len=*), intent(in) :: what
      if (failures > 0) then
         write (*, '(a, i0, a)') 'FAILED: ', failures, ' check(s)'
         error stop 1
      end if
      write (*, '(a)') 'all ' // what // ' checks passed'
   end subroutine finish
end module lc_test_checks
