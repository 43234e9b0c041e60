!> Text helpers: numbers as text for messages (one `to_string` for every kind the code
!> prints) and ASCII lower case.
module lc_base_strings
   use lc_base_kinds, only: wp
   use, intrinsic :: iso_fortran_env, only: int32, int64
   implicit none (type, external)
   private
   public :: to_string, lower_case, formatted

   !> Shortest text of an integer; a real with 6 significant digits (es12.5).
   interface to_string
      module procedure int32_string, int64_string, real_string
   end interface to_string

contains

   pure function int32_string(i) result(s)
      integer(int32), intent(in) :: i
      character(len=:), allocatable :: s
      character(len=16) :: buffer
      write (buffer, '(i0)') i
      s = trim(buffer)
   end function int32_string

   pure function int64_string(i) result(s)
      integer(int64), intent(in) :: i
      character(len=:), allocatable :: s
      character(len=24) :: buffer
      write (buffer, '(i0)') i
      s = trim(buffer)
   end function int64_string

   pure function real_string(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      s = formatted(x, '(es12.5)')
   end function real_string

   !> x written with the edit descriptor `format` (e.g. '(f6.4)'), without blanks around it.
   pure function formatted(x, format) result(s)
      real(wp), intent(in) :: x
      character(len=*), intent(in) :: format
      character(len=:), allocatable :: s
      character(len=40) :: buffer
      write (buffer, format) x
      s = trim(adjustl(buffer))
   end function formatted

   !> The text with ASCII letters in lower case.
   pure function lower_case(text) result(low)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: low
      integer :: i
      low = text
      do i = 1, len(text)
         if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') low(i:i) = achar(iachar(text(i:i)) + 32)
      end do
   end function lower_case
end module lc_base_strings
