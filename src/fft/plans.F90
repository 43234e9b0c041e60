!> FFTW plans owned by a type: one real-to-complex / complex-to-real pair of size n,
!> made once per operator, with their own aligned buffers.
!>
!> Convention: f(x_j) = sum_k f^(k) exp(i k x_j). `forward` returns f^(k) for
!> k = 0..n/2 (r2c, divided by n); `backward` is its exact inverse (c2r, no scaling).
module lc_fft_plans
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_double_complex, c_size_t, &
      & c_f_pointer, c_associated, c_null_ptr
   use lc_fft_fftw3, only: fftw_alloc_real, fftw_alloc_complex, fftw_free, fftw_plan_dft_r2c_1d, &
      & fftw_plan_dft_c2r_1d, fftw_execute_dft_r2c, fftw_execute_dft_c2r, fftw_destroy_plan, &
      & fftw_init_threads, fftw_plan_with_nthreads, FFTW_ESTIMATE, FFTW_DESTROY_INPUT
   use lc_kinds, only: wp
   use lc_errors, only: error_type, fatal_error, code_internal
   use lc_strings, only: to_string
   implicit none (type, external)
   private
   public :: fft_plan, fft_threads_available

   !> A 1D r2c/c2r plan pair with its buffers: copy data into `real_buffer`, call
   !> `forward`, work on `spectrum`, call `backward`, read `real_buffer`.
   type :: fft_plan
      integer :: n = 0
      integer :: nk = 0   !< n/2 + 1 spectral coefficients
      real(c_double), pointer, contiguous :: real_buffer(:) => null()
      complex(c_double_complex), pointer, contiguous :: spectrum(:) => null()
      type(c_ptr), private :: r2c = c_null_ptr, c2r = c_null_ptr
      type(c_ptr), private :: real_memory = c_null_ptr, complex_memory = c_null_ptr
      logical, private :: owns_plans = .false.   !< plans not in the cache (destroyed with it)
   contains
      procedure :: init
      procedure :: forward
      procedure :: forward_unscaled
      procedure :: backward
      procedure :: destroy
      final :: finalize
   end type fft_plan

   !> Plans made so far, by size and thread count. FFTW_ESTIMATE planning costs several
   !> transforms of the size (~0.2 ms at n = 8192, ~40 us at 1024: as much as a small
   !> solve), and a solve builds one operator per coarse level; so the plans are made once
   !> and executed on each operator's own buffers (new-array execute: the buffers come
   !> from fftw_alloc, with the alignment the plans were made for). Kept for the life of
   !> the process (a run uses a few sizes). Like FFTW's planner, not thread-safe.
   type :: cached_plans
      integer :: n = 0
      integer :: threads = 0
      type(c_ptr) :: r2c = c_null_ptr, c2r = c_null_ptr
   end type cached_plans
   integer, parameter :: cache_size = 64
   type(cached_plans), save :: cache(cache_size)
   integer, save :: cached = 0

contains

   !> True if this build links FFTW's OpenMP threads.
   pure logical function fft_threads_available()
#ifdef LC_OPENMP
      fft_threads_available = .true.
#else
      fft_threads_available = .false.
#endif
   end function fft_threads_available

   !> Make plans and buffers for size n with `threads` FFTW threads (ignored without OpenMP).
   subroutine init(self, n, threads, error)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: n, threads
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: status
      integer :: i

      call self%destroy()
#ifdef LC_OPENMP
      status = fftw_init_threads()
      call fftw_plan_with_nthreads(int(threads, c_int))
#else
      status = int(threads, c_int)
#endif
      self%n = n
      self%nk = n/2 + 1
      self%real_memory = fftw_alloc_real(int(n, c_size_t))
      self%complex_memory = fftw_alloc_complex(int(self%nk, c_size_t))
      if (.not. (c_associated(self%real_memory) .and. c_associated(self%complex_memory))) then
         call fatal_error(error, 'fft: cannot allocate FFTW buffers of size ' // to_string(n), code_internal)
         return
      end if
      call c_f_pointer(self%real_memory, self%real_buffer, [n])
      call c_f_pointer(self%complex_memory, self%spectrum, [self%nk])
      self%real_buffer = 0.0_wp
      do i = 1, cached
         if (cache(i)%n == n .and. cache(i)%threads == threads) then
            self%r2c = cache(i)%r2c
            self%c2r = cache(i)%c2r
            self%owns_plans = .false.
            return
         end if
      end do
      ! FFTW_ESTIMATE: the same plan (and so the same bits) on every run; it does not
      ! touch the buffers.
      self%r2c = fftw_plan_dft_r2c_1d(int(n, c_int), self%real_buffer, self%spectrum, FFTW_ESTIMATE)
      self%c2r = fftw_plan_dft_c2r_1d(int(n, c_int), self%spectrum, self%real_buffer, &
         & ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      if (.not. (c_associated(self%r2c) .and. c_associated(self%c2r))) then
         call fatal_error(error, 'fft: FFTW could not plan a transform of size ' // to_string(n), code_internal)
         return
      end if
      self%owns_plans = cached == cache_size
      if (.not. self%owns_plans) then
         cached = cached + 1
         cache(cached) = cached_plans(n, threads, self%r2c, self%c2r)
      end if
   end subroutine init

   !> spectrum <- Fourier coefficients of real_buffer (r2c / n). real_buffer is kept.
   subroutine forward(self)
      class(fft_plan), intent(inout) :: self
      call fftw_execute_dft_r2c(self%r2c, self%real_buffer, self%spectrum)
      self%spectrum = self%spectrum*(1.0_wp/self%n)
   end subroutine forward

   !> spectrum <- n times the Fourier coefficients (the bare r2c): for operators that fold
   !> the 1/n into their multipliers and so save a pass over the spectrum.
   subroutine forward_unscaled(self)
      class(fft_plan), intent(inout) :: self
      call fftw_execute_dft_r2c(self%r2c, self%real_buffer, self%spectrum)
   end subroutine forward_unscaled

   !> real_buffer <- sum_k spectrum(k) exp(i k x). The spectrum is destroyed.
   subroutine backward(self)
      class(fft_plan), intent(inout) :: self
      call fftw_execute_dft_c2r(self%c2r, self%spectrum, self%real_buffer)
   end subroutine backward

   subroutine destroy(self)
      class(fft_plan), intent(inout) :: self
      if (self%owns_plans .and. c_associated(self%r2c)) call fftw_destroy_plan(self%r2c)
      if (self%owns_plans .and. c_associated(self%c2r)) call fftw_destroy_plan(self%c2r)
      self%owns_plans = .false.
      if (c_associated(self%real_memory)) call fftw_free(self%real_memory)
      if (c_associated(self%complex_memory)) call fftw_free(self%complex_memory)
      self%r2c = c_null_ptr
      self%c2r = c_null_ptr
      self%real_memory = c_null_ptr
      self%complex_memory = c_null_ptr
      self%real_buffer => null()
      self%spectrum => null()
      self%n = 0
      self%nk = 0
   end subroutine destroy

   subroutine finalize(self)
      type(fft_plan), intent(inout) :: self
      call self%destroy()
   end subroutine finalize

end module lc_fft_plans
