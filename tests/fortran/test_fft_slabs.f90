!> lc_fft_plans' products on a surface shared among the ranks (convolve with a real
!> multiplier and its energy, with a complex multiplier, and convolve_passes) against the
!> same products of the whole surface on one process, which every rank computes for
!> itself. Run by tests/test_mpi.py under `mpirun -n P`, P = 2..4 (on one rank a plan is
!> not distributed, and the program stops with an error).
!>
!> The distributed products exchange whole blocks between the ranks and hold the spectrum
!> by row slabs between the exchanges; the whole surface's product is FFTW's 2D transform,
!> the product on its spectrum and the inverse, steps apart. The two are different
!> algorithms on the same modes: they agree to rounding, 1e-13 of the largest value (a few
!> hundred operations a value, each 1e-16). The energy, scale * sum over the whole spectrum
!> of the multiplier times |c|^2 for the bare r2c's coefficients c, is checked against
!> Parseval's identity in real space, sum_j f_j (M f)_j, to 1e-13. The grids: 96 x 70
!> (49 columns of the half spectrum: blocks of 8 and a last of 1; on 3 ranks slabs of 24,
!> 24 and 22 rows, 17, 17 and 15 columns), 95 x 67 (odd nx: 48 columns; no P of 2..4
!> divides the 67 rows) and 10 x 40 (6 columns: on 4 ranks the last has none). The multipliers depend on the mode, real, and complex with an
!> imaginary part odd in my, so that both keep the product of a real field real.
program test_fft_slabs
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_parallel, only: parallel_start, parallel_end, global_sum
   use lc_fft_plans, only: fft_plan
   use lc_test_checks, only: check, finish
   use lc_test_copy_work, only: copy_work
   implicit none (type, external)

   real(wp), parameter :: tolerance = 1.0e-13_wp
   type(error_type), allocatable :: error
   integer, parameter :: grids(2, 3) = reshape([96, 70, 95, 67, 10, 40], [2, 3])
   integer :: k

   call parallel_start(error)
   if (allocated(error)) error stop 2
   do k = 1, size(grids, 2)
      call check_grid(grids(1, k), grids(2, k))
   end do
   ! (the ranks leave together: a rank leaving before parallel_end would end the job)
   call parallel_end()
   call finish('fft on slabs')

contains

   subroutine check_grid(nx, ny)
      integer, intent(in) :: nx, ny
      type(fft_plan) :: whole, slabs
      type(copy_work) :: work
      real(wp), allocatable :: field(:), real_whole(:), real_slabs(:), product(:)
      real(wp), allocatable, target :: slab_input(:), slab_output(:)
      complex(wp), allocatable :: complex_whole(:), complex_slabs(:)
      real(wp) :: scale, energy, whole_energy, largest
      character(len=:), allocatable :: grid
      integer :: i, first, last

      grid = ' (' // itoa(nx) // ' x ' // itoa(ny) // ')'
      scale = 1.0_wp/(real(nx, wp)*ny)
      allocate (field(nx*ny))
      do i = 1, nx*ny
         field(i) = sin(0.37_wp*i) + 0.5_wp*cos(1.0e-3_wp*real(i, wp)**1.1_wp)
      end do
      call whole%init(nx, ny, 1, error)
      if (allocated(error)) error stop 2
      call slabs%init(nx, ny, 1, error, distributed=.true.)
      if (allocated(error)) error stop 2
      if (.not. slabs%distributed) error stop 'test_fft_slabs: run it under mpirun with 2 or more ranks'
      call multipliers(whole, real_whole, complex_whole)
      call multipliers(slabs, real_slabs, complex_slabs)
      first = slabs%y_start*nx + 1
      last = (slabs%y_start + slabs%ny_local)*nx

      ! a real multiplier and its energy
      whole%real_buffer = field
      call whole%forward_unscaled()
      whole%spectrum = whole%spectrum*(real_whole*scale)
      call whole%backward()
      product = whole%real_buffer
      whole_energy = sum(field*product)
      largest = maxval(abs(product))
      slabs%real_buffer = field(first:last)
      call slabs%convolve(scale, real_multiplier=real_slabs, energy=energy)
      energy = global_sum(energy)
      call check(maxval(abs(slabs%real_buffer - product(first:last)))/largest <= tolerance, &
         & 'convolve, a real multiplier, on the slabs' // grid, maxval(abs(slabs%real_buffer - product(first:last)))/largest)
      call check(abs(energy - whole_energy) <= tolerance*abs(whole_energy), 'its energy' // grid, &
         & abs(energy - whole_energy)/abs(whole_energy))

      ! the same through convolve_passes
      work%nx = nx
      slab_input = field(first:last)
      allocate (slab_output(last - first + 1))
      work%input => slab_input
      work%output => slab_output
      call slabs%convolve_passes(scale, real_slabs, work, error)
      if (allocated(error)) error stop 2
      call check(maxval(abs(slab_output - product(first:last)))/largest <= tolerance, &
         & 'convolve_passes on the slabs' // grid, maxval(abs(slab_output - product(first:last)))/largest)
      call check(abs(work%energy - whole_energy) <= tolerance*abs(whole_energy), 'its energy' // grid, &
         & abs(work%energy - whole_energy)/abs(whole_energy))

      ! a complex multiplier
      whole%real_buffer = field
      call whole%forward_unscaled()
      whole%spectrum = whole%spectrum*(complex_whole*scale)
      call whole%backward()
      product = whole%real_buffer
      largest = maxval(abs(product))
      slabs%real_buffer = field(first:last)
      call slabs%convolve(scale, complex_multiplier=complex_slabs)
      call check(maxval(abs(slabs%real_buffer - product(first:last)))/largest <= tolerance, &
         & 'convolve, a complex multiplier, on the slabs' // grid, &
         & maxval(abs(slabs%real_buffer - product(first:last)))/largest)
   end subroutine check_grid

   !> The multipliers on a plan's modes (its layout), functions of (mx, my): real, and
   !> complex with an imaginary part odd in my (Hermitian on the columns mx = 0 and nx/2).
   subroutine multipliers(plan, real_multiplier, complex_multiplier)
      type(fft_plan), intent(in) :: plan
      real(wp), allocatable, intent(out) :: real_multiplier(:)
      complex(wp), allocatable, intent(out) :: complex_multiplier(:)
      integer :: i, mx, my, ky
      allocate (real_multiplier(plan%nk), complex_multiplier(plan%nk))
      do i = 1, plan%nk
         call plan%mode_indices(i, mx, my)
         ky = min(my, plan%ny - my)
         real_multiplier(i) = 1.0_wp/(1.0_wp + 0.3_wp*mx + 0.7_wp*ky) + 0.01_wp*mod(mx*7 + ky*3, 11)
         complex_multiplier(i) = cmplx(real_multiplier(i), 0.2_wp*sin(6.283185307179586_wp*my/plan%ny)/(1.0_wp + mx), &
            & kind=wp)
      end do
   end subroutine multipliers

   pure function itoa(n) result(text)
      integer, intent(in) :: n
      character(len=:), allocatable :: text
      character(len=12) :: buffer
      write (buffer, '(i0)') n
      text = trim(buffer)
   end function itoa
end program test_fft_slabs
