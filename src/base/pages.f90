!> The large work arrays of a solve on transparent huge pages (src/base/pages.c): a fresh
!> array of a 2048^2 grid (32 MiB) is otherwise first touched in 8192 page faults of 4 KiB,
!> which the kernel serves one by one (docs/decisions/024-fft-floor.md). Call it right after
!> the allocation, before the first write; the values are not changed.
module lc_base_pages
   use, intrinsic :: iso_c_binding, only: c_size_t
   use lc_base_kinds, only: wp
   implicit none (type, external)
   private
   public :: advise_huge_pages

   !> Arrays smaller than this are left alone: they hold no whole 2 MiB page, or few.
   integer, parameter :: least_bytes = 4*2**20

   interface
      subroutine lc_advise_huge_pages(start, bytes) bind(c, name='lc_advise_huge_pages')
         import :: c_size_t
         type(*), dimension(*), intent(in) :: start
         integer(c_size_t), value, intent(in) :: bytes
      end subroutine lc_advise_huge_pages
   end interface

   interface advise_huge_pages
      module procedure advise_real, advise_real_2d, advise_complex
   end interface advise_huge_pages

contains

   subroutine advise_real(array)
      real(wp), contiguous, intent(in) :: array(:)
      integer(c_size_t) :: bytes
      bytes = size(array, kind=c_size_t)*(storage_size(array, kind=c_size_t)/8)
      if (bytes >= least_bytes) call lc_advise_huge_pages(array, bytes)
   end subroutine advise_real

   subroutine advise_real_2d(array)
      real(wp), contiguous, intent(in) :: array(:, :)
      integer(c_size_t) :: bytes
      bytes = size(array, kind=c_size_t)*(storage_size(array, kind=c_size_t)/8)
      if (bytes >= least_bytes) call lc_advise_huge_pages(array, bytes)
   end subroutine advise_real_2d

   subroutine advise_complex(array)
      complex(wp), contiguous, intent(in) :: array(:)
      integer(c_size_t) :: bytes
      bytes = size(array, kind=c_size_t)*(storage_size(array, kind=c_size_t)/8)
      if (bytes >= least_bytes) call lc_advise_huge_pages(array, bytes)
   end subroutine advise_complex
end module lc_base_pages
