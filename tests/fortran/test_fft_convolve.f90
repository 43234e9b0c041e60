!> lc_fft_plans' convolve, the product fused between the column transforms of a two-pass
!> surface, against the three steps apart (forward_unscaled, the product on the whole
!> spectrum, backward), on 1024 x 1003 points (two-pass; 513 columns, so the last block
!> has one; 1003 rows, so the last block of rows has three) with a real and a complex
!> multiplier, on one thread and on two. The fused path
!> makes the same products in the same order on the same transforms, so the two agree to
!> rounding (1e-14 of the largest value). The energy convolve sums in the same pass,
!> sum over the whole spectrum of scale * multiplier |c|^2, is checked against Parseval's
!> identity in real space, sum_j f_j (M f)_j for the field f and its product M f, to
!> 1e-12 (two sums of a million terms in different orders). convolve_passes, a solver's
!> work on blocks of rows fused into the row stages, here copying the field in and the
!> product out, gives convolve's product and energy to rounding (its rows are transformed
!> by plans of a block of rows each: 1e-14). A 64 x 64 surface (the 2D plan) does not fuse.
program test_fft_convolve
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_fft_plans, only: fft_plan
   use lc_test_checks, only: check, finish
   use lc_test_copy_work, only: copy_work
   implicit none (type, external)

   integer, parameter :: nx = 1024, ny = 1003
   real(wp), parameter :: scale = 1.0_wp/(real(nx, wp)*ny)
   real(wp), allocatable, target :: field(:)
   real(wp), allocatable :: real_multiplier(:), reference(:)
   complex(wp), allocatable :: complex_multiplier(:)
   type(fft_plan) :: small
   type(error_type), allocatable :: error
   integer :: i, threads

   allocate (field(nx*ny), real_multiplier((nx/2 + 1)*ny), complex_multiplier((nx/2 + 1)*ny))
   ! (a field with every mode present, and multipliers that differ from mode to mode)
   do i = 1, nx*ny
      field(i) = sin(0.37_wp*i) + 0.5_wp*cos(1.0e-3_wp*real(i, wp)**1.1_wp)
   end do
   do i = 1, size(real_multiplier)
      real_multiplier(i) = 1.0_wp/(1.0_wp + mod(i, 37))
      complex_multiplier(i) = cmplx(real_multiplier(i), 0.1_wp*sin(0.01_wp*i), kind=wp)
   end do

   do threads = 1, 2
      call check_convolution(threads)
   end do

   call small%init(64, 64, 1, error)
   if (allocated(error)) error stop 2
   call check(.not. small%fuses_products(), '64 x 64 (the 2D plan) does not fuse the product')
   call finish('fft convolve')

contains

   subroutine check_convolution(threads)
      integer, intent(in) :: threads
      type(fft_plan) :: plan
      character(len=32) :: label
      call plan%init(nx, ny, threads, error)
      if (allocated(error)) error stop 2
      write (label, '(a, i0, a)') ' (', threads, ' threads)'
      call check(plan%fuses_products(), '1024 x 1003 fuses the product' // trim(label))
      call check_against_steps(plan, 'a real multiplier, fused = apart' // trim(label), &
         & real_multiplier=real_multiplier)
      call check_against_steps(plan, 'a complex multiplier, fused = apart' // trim(label), &
         & complex_multiplier=complex_multiplier)
      call check_energy(plan, 'the energy of a real multiplier = sum f (M f)' // trim(label))
      call check_passes(plan, 'the passes fused into the rows = convolve' // trim(label))
   end subroutine check_convolution

   !> convolve_passes with a work that copies the field in and the product out, against
   !> convolve's product and energy.
   subroutine check_passes(plan, what)
      type(fft_plan), intent(inout) :: plan
      character(len=*), intent(in) :: what
      type(copy_work) :: work
      type(error_type), allocatable :: error
      real(wp), allocatable, target :: output(:)
      real(wp) :: energy, worst
      plan%real_buffer = field
      call plan%convolve(scale, real_multiplier, energy=energy)
      reference = plan%real_buffer
      allocate (output(nx*ny))
      work%nx = nx
      work%input => field
      work%output => output
      call plan%convolve_passes(scale, real_multiplier, work, error)
      if (allocated(error)) error stop 2
      worst = max(maxval(abs(output - reference))/maxval(abs(reference)), abs(work%energy - energy)/abs(energy))
      call check(worst <= 1.0e-14_wp, what, worst)
   end subroutine check_passes

   !> convolve's energy against sum_j f_j (M f)_j (Parseval: the same sum, in real space),
   !> for an even multiplier M(q) = M(-q), as the operators' metrics are (on the columns
   !> mx = 0 and nx/2 the half spectrum holds both q and -q).
   subroutine check_energy(plan, what)
      type(fft_plan), intent(inout) :: plan
      character(len=*), intent(in) :: what
      real(wp) :: energy, direct, even(nx/2 + 1, ny)
      integer :: mx, my
      do my = 0, ny - 1
         do mx = 0, nx/2
            even(mx + 1, my + 1) = 1.0_wp/(1.0_wp + mod(mx + 3*min(my, ny - my), 37))
         end do
      end do
      plan%real_buffer = field
      call plan%convolve(scale, reshape(even, [size(even)]), energy=energy)
      direct = sum(field*plan%real_buffer)
      call check(abs(energy - direct) <= 1.0e-12_wp*abs(direct), what, abs(energy - direct)/abs(direct))
   end subroutine check_energy

   !> convolve against forward_unscaled, the product on the whole spectrum and backward.
   subroutine check_against_steps(plan, what, real_multiplier, complex_multiplier)
      type(fft_plan), intent(inout) :: plan
      character(len=*), intent(in) :: what
      real(wp), intent(in), optional :: real_multiplier(:)
      complex(wp), intent(in), optional :: complex_multiplier(:)
      real(wp) :: worst
      plan%real_buffer = field
      call plan%forward_unscaled()
      if (present(real_multiplier)) then
         plan%spectrum = plan%spectrum*(real_multiplier*scale)
      else
         plan%spectrum = plan%spectrum*(complex_multiplier*scale)
      end if
      call plan%backward()
      reference = plan%real_buffer
      plan%real_buffer = field
      call plan%convolve(scale, real_multiplier, complex_multiplier)
      worst = maxval(abs(plan%real_buffer - reference))/maxval(abs(reference))
      call check(worst <= 1.0e-14_wp, what, worst)
   end subroutine check_against_steps

end program test_fft_convolve
