!> A solver's work for lc_fft_plans' convolve_passes in the tests: each block's rows copied
!> in from `input` and out to `output`, the energy handed over between them kept.
module lc_test_copy_work
   use lc_base_kinds, only: wp
   use lc_fft_plans, only: row_work
   implicit none (type, external)
   private
   public :: copy_work

   !> Copies `input` into each block's rows and each block's output into `output`.
   type, extends(row_work) :: copy_work
      integer :: nx = 0
      real(wp), pointer, contiguous :: input(:) => null(), output(:) => null()
      real(wp) :: energy = 0.0_wp
   contains
      procedure :: before => copy_in
      procedure :: between => keep_energy
      procedure :: after => copy_out
   end type copy_work

contains

   subroutine copy_in(self, first, rows, values, block)
      class(copy_work), intent(inout) :: self
      integer, intent(in) :: first, rows, block
      real(wp), contiguous, intent(inout) :: values(:)
      values = self%input((first - 1)*self%nx + 1:(first - 1 + rows)*self%nx)
      if (block < 1) error stop 'block numbers start at 1'
   end subroutine copy_in

   subroutine keep_energy(self, energy)
      class(copy_work), intent(inout) :: self
      real(wp), intent(in) :: energy
      self%energy = energy
   end subroutine keep_energy

   subroutine copy_out(self, first, rows, values, block)
      class(copy_work), intent(inout) :: self
      integer, intent(in) :: first, rows, block
      real(wp), contiguous, intent(inout) :: values(:)
      self%output((first - 1)*self%nx + 1:(first - 1 + rows)*self%nx) = values
      if (block < 1) error stop 'block numbers start at 1'
   end subroutine copy_out
end module lc_test_copy_work
