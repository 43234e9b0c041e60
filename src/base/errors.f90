!> Error handling: every library routine that can fail returns an allocatable
!> `error_type` (allocated = failed) instead of stopping. Only `app/main.f90` stops.
!>
!> Codes follow the executable's exit codes: 2 = bad input, 3 = not converged (used as a
!> status, not an error), 4 = I/O failure, 5 = internal/numerical failure.
module lc_base_errors
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   implicit none (type, external)
   private
   public :: error_type, fatal_error, input_error, positive_finite, status_of
   public :: code_input, code_not_converged, code_io, code_internal

   integer, parameter :: code_input = 2
   integer, parameter :: code_not_converged = 3
   integer, parameter :: code_io = 4
   integer, parameter :: code_internal = 5

   !> An error: a message that says what, where and the allowed range, and a code.
   type :: error_type
      integer :: code = code_internal
      character(len=:), allocatable :: message
   end type error_type

contains

   !> Allocate `error` with `message` (and `code`, default: internal failure).
   pure subroutine fatal_error(error, message, code)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      integer, intent(in), optional :: code
      allocate (error)
      error%message = message
      if (present(code)) error%code = code
   end subroutine fatal_error

   !> A bad input value: the message names the namelist group, the variable, the value
   !> and the allowed range (code: bad input).
   pure subroutine input_error(error, group, variable, value, allowed)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: group, variable, value, allowed
      call fatal_error(error, '&' // group // ': ' // variable // ' = ' // value // ' is not allowed; allowed: ' &
         & // allowed, code_input)
   end subroutine input_error

   !> An error as the plain status of the Python wrappers: stat = its code (0: no error)
   !> and errmsg = its message (cut to the length of errmsg).
   pure subroutine status_of(error, stat, errmsg)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(out) :: stat
      character(len=*), intent(out) :: errmsg
      stat = 0
      errmsg = ''
      if (.not. allocated(error)) return
      stat = error%code
      errmsg = error%message
   end subroutine status_of

   !> True for a finite x > 0 (the common input check; false for NaN and Inf).
   pure logical function positive_finite(x)
      real(wp), intent(in) :: x
      positive_finite = ieee_is_finite(x) .and. x > 0.0_wp
   end function positive_finite
end module lc_base_errors
