!> Working precision and integer kinds shared by every module of layercontact.
module lc_base_kinds
   use, intrinsic :: iso_fortran_env, only: real64, int32, int64
   implicit none (type, external)
   private
   public :: wp, i8

   !> Working precision: IEEE double.
   integer, parameter :: wp = real64
   !> 64-bit integers (random-number state, large counts).
   integer, parameter :: i8 = int64
end module lc_base_kinds
