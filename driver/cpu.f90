!> The processor's instruction-set level, from driver/cpu_level.c (kept out of wrappers.f90,
!> which f2py reads).
module lc_cpu
   use, intrinsic :: iso_c_binding, only: c_int
   implicit none (type, external)
   private
   public :: cpu_level

   interface
      integer(c_int) function lc_cpu_has_x86_64_v3() bind(c)
         import :: c_int
      end function lc_cpu_has_x86_64_v3
   end interface

contains

   !> 3 if the processor runs the x86-64-v3 build, else 1.
   integer function cpu_level()
      cpu_level = merge(3, 1, lc_cpu_has_x86_64_v3() /= 0)
   end function cpu_level
end module lc_cpu
