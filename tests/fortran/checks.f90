!> What the Fortran unit tests share: one line per check ('ok' or 'FAIL', what it checked
!> and, if given, the value it measured), the failures counted, and the end of a test
!> program (error stop 1 on any).
module lc_test_checks
   use lc_base_kinds, only: wp
   implicit none (type, external)
   private
   public :: check, finish

   integer :: failures = 0

contains

   !> One check: `what` passed if `ok`. `value` (e.g. the worst relative error met) is
   !> printed on the line; `detail` only under a failure, on the next line.
   subroutine check(ok, what, value, detail)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: what
      real(wp), intent(in), optional :: value
      character(len=*), intent(in), optional :: detail
      character(len=6) :: status
      status = 'ok    '
      if (.not. ok) then
         status = 'FAIL  '
         failures = failures + 1
      end if
      if (present(value)) then
         write (*, '(a, a, a, es10.3, a)') status, what, '  (', value, ')'
      else
         write (*, '(a, a)') status, what
      end if
      if (.not. ok .and. present(detail)) write (*, '(6x, a)') detail
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
