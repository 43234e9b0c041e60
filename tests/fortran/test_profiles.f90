!> Tests of profile synthesis (lc_profiles_random, lc_profiles_self_affine,
!> lc_profiles_profile). One line per check; exit 0 on pass, error stop 1 on failure.
!>
!> Tolerances:
!> - tol_target = 1e-12: rms height / gradient vs target. The scale is exact for the
!>   discrete series, so only FFT and summation roundoff (~1e-15 relative) remain.
!> - tol_mean = 1e-14 (times the rms height): the mean coefficient is set to zero and the
!>   c2r transform adds only roundoff.
!> - tol_slope = 1e-12: amplitudes are deterministic, so the log-log fit of the measured
!>   amplitudes is exact up to roundoff in the smallest coefficients.
program test_profiles
   use lc_kinds, only: wp, i8
   use lc_errors, only: error_type, code_input
   use lc_scene, only: scene_type, not_set, check_scene
   use lc_fft_plans, only: fft_plan
   use lc_profiles_random, only: splitmix64, splitmix64_uniform
   use lc_profiles_self_affine, only: self_affine_profile, sinusoid_profile
   use lc_profiles_profile, only: make_profile, profile_statistics
   implicit none (type, external)

   real(wp), parameter :: tol_target = 1.0e-12_wp
   real(wp), parameter :: tol_mean = 1.0e-14_wp
   real(wp), parameter :: tol_slope = 1.0e-12_wp
   real(wp), parameter :: pi = acos(-1.0_wp)
   integer :: failures

   failures = 0
   call check_splitmix64()
   call check_scaling(512, 0.8_wp, 7_i8, 0.05_wp, not_set, 'rms gradient, n = 512, H = 0.8')
   call check_scaling(1001, 0.3_wp, 42_i8, 0.2_wp, not_set, 'rms gradient, odd n = 1001, H = 0.3')
   call check_scaling(4096, 0.7_wp, 1_i8, not_set, 1.0e-3_wp, 'rms height, n = 4096, H = 0.7')
   call check_reproducible()
   call check_slope()
   call check_sinusoid()
   call check_errors()
   call check_make_profile()

   if (failures > 0) then
      write (*, '(a, i0, a)') 'FAILED: ', failures, ' check(s)'
      error stop 1
   end if
   write (*, '(a)') 'all profile checks passed'

contains

   subroutine report(ok, name, value)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: name
      real(wp), intent(in), optional :: value
      character(len=4) :: status

      status = 'PASS'
      if (.not. ok) then
         status = 'FAIL'
         failures = failures + 1
      end if
      if (present(value)) then
         write (*, '(a, 1x, a, a, es10.3)') status, name, ': ', value
      else
         write (*, '(a, 1x, a)') status, name
      end if
   end subroutine report

   !> 64-bit pattern from two 32-bit halves written in hex.
   pure integer(i8) function word(high, low)
      integer(i8), intent(in) :: high, low
      word = ior(shiftl(high, 32), low)
   end function word

   subroutine check_splitmix64()
      ! Reference outputs of Vigna's splitmix64.c next(), checked with a Python big-int
      ! implementation.
      call report(splitmix64(0_i8, 1_i8) == word(int(z'E220A839', i8), int(z'7B1DCDAF', i8)), &
         & 'splitmix64(seed 0) output 1 = 0xE220A8397B1DCDAF')
      call report(splitmix64(0_i8, 2_i8) == word(int(z'6E789E6A', i8), int(z'A1B965F4', i8)), &
         & 'splitmix64(seed 0) output 2 = 0x6E789E6AA1B965F4')
      call report(splitmix64(1_i8, 1_i8) == word(int(z'910A2DEC', i8), int(z'89025CC1', i8)), &
         & 'splitmix64(seed 1) output 1 = 0x910A2DEC89025CC1')
      call report(splitmix64(12345_i8, 3_i8) == word(int(z'1E9A57BC', i8), int(z'80E6721D', i8)), &
         & 'splitmix64(seed 12345) output 3 = 0x1E9A57BC80E6721D')
      ! (z >> 11) * 2^-53 is exact, so equality is the right test.
      call report(splitmix64_uniform(0_i8, 1_i8) == 0.8833108082136426_wp, 'splitmix64_uniform(seed 0) output 1')
      call report(splitmix64_uniform(1_i8, 1_i8) == 0.5665615751722809_wp, 'splitmix64_uniform(seed 1) output 1')
   end subroutine check_splitmix64

   subroutine check_scaling(n, hurst, seed, rms_gradient, rms_height, label)
      integer, intent(in) :: n
      real(wp), intent(in) :: hurst, rms_gradient, rms_height
      integer(i8), intent(in) :: seed
      character(len=*), intent(in) :: label
      type(error_type), allocatable :: error
      real(wp), allocatable :: height(:)
      real(wp) :: period, measured_height, measured_gradient, max_height, deviation

      period = 2.5_wp
      allocate (height(n))
      call self_affine_profile(n, period, hurst, seed, not_set, not_set, rms_gradient, rms_height, height, error)
      if (allocated(error)) then
         call report(.false., label // ': ' // error%message)
         return
      end if
      call profile_statistics(height, period, measured_height, measured_gradient, max_height, error)
      if (allocated(error)) then
         call report(.false., label // ': ' // error%message)
         return
      end if
      if (rms_gradient /= not_set) then
         deviation = abs(measured_gradient/rms_gradient - 1)
      else
         deviation = abs(measured_height/rms_height - 1)
      end if
      call report(deviation <= tol_target, label // ' equals target (relative error)', deviation)
      deviation = abs(sum(height)/n)/measured_height
      call report(deviation <= tol_mean, label // ' zero mean (|mean|/rms)', deviation)
      call report(max_height > 0.0_wp .and. max_height >= measured_height, label // ' max height >= rms height')
   end subroutine check_scaling

   subroutine check_reproducible()
      integer, parameter :: n = 1024
      type(error_type), allocatable :: error
      real(wp) :: first(n), second(n), other(n)

      call self_affine_profile(n, 1.0_wp, 0.8_wp, 3_i8, not_set, not_set, 0.1_wp, not_set, first, error)
      call self_affine_profile(n, 1.0_wp, 0.8_wp, 3_i8, not_set, not_set, 0.1_wp, not_set, second, error)
      call self_affine_profile(n, 1.0_wp, 0.8_wp, 4_i8, not_set, not_set, 0.1_wp, not_set, other, error)
      call report(all(transfer(first, 1_i8, n) == transfer(second, 1_i8, n)), 'same seed gives identical bits')
      call report(maxval(abs(first - other)) > 0.1_wp*maxval(abs(first)), 'different seed gives a different profile')
   end subroutine check_reproducible

   !> Least-squares slope of log a_m vs log m over m_r..m_s, with a_m = 2 |f^(m)| from a
   !> forward FFT of the synthesised heights; also flat below m_r and zero above m_s.
   subroutine check_slope()
      integer, parameter :: n = 512, m_r = 4, m_s = 64
      real(wp), parameter :: hurst = 0.65_wp, period = 1.0_wp
      type(error_type), allocatable :: error
      type(fft_plan) :: plan
      real(wp) :: height(n), amplitude(n/2 - 1), x(m_s - m_r + 1), y(m_s - m_r + 1), slope, expected
      integer :: m

      call self_affine_profile(n, period, hurst, 9_i8, period/m_r, period/m_s, not_set, 1.0_wp, height, error)
      call plan%init(n, 1, 1, error)
      if (allocated(error)) then
         call report(.false., 'spectrum slope: ' // error%message)
         return
      end if
      plan%real_buffer = height
      call plan%forward()
      do m = 1, n/2 - 1
         amplitude(m) = 2*abs(plan%spectrum(m + 1))
      end do
      x = log([(real(m, wp), m=m_r, m_s)])
      y = log(amplitude(m_r:m_s))
      slope = sum((x - sum(x)/size(x))*(y - sum(y)/size(y)))/sum((x - sum(x)/size(x))**2)
      expected = -(1 + 2*hurst)/2
      call report(abs(slope - expected) <= tol_slope, 'spectrum slope -(1+2H)/2 over m_r..m_s (error)', &
         & abs(slope - expected))
      call report(maxval(abs(amplitude(1:m_r - 1)/amplitude(m_r) - 1)) <= tol_target, 'flat spectrum below m_r', &
         & maxval(abs(amplitude(1:m_r - 1)/amplitude(m_r) - 1)))
      call report(maxval(amplitude(m_s + 1:))/amplitude(m_s) <= tol_target, 'no modes above m_s (relative)', &
         & maxval(amplitude(m_s + 1:))/amplitude(m_s))
   end subroutine check_slope

   subroutine check_sinusoid()
      integer, parameter :: n = 256, mode = 3
      real(wp), parameter :: amplitude = 0.2_wp, period = 2.0_wp
      type(error_type), allocatable :: error
      real(wp) :: height(n), rms_height, rms_gradient, max_height, deviation
      integer :: j

      call sinusoid_profile(n, period, amplitude, mode, height)
      deviation = maxval(abs(height - [(amplitude*cos(2*pi*mode*real(j, wp)/n), j=0, n - 1)]))/amplitude
      call report(deviation <= 1.0e-14_wp, 'sinusoid values amplitude cos(2 pi mode j/n) (max relative error)', deviation)
      call profile_statistics(height, period, rms_height, rms_gradient, max_height, error)
      deviation = abs(rms_height*sqrt(2.0_wp)/amplitude - 1)
      call report(deviation <= tol_target, 'sinusoid rms height = amplitude/sqrt(2) (relative error)', deviation)
      deviation = abs(rms_gradient*sqrt(2.0_wp)*period/(2*pi*mode*amplitude) - 1)
      call report(deviation <= tol_target, 'sinusoid rms gradient = 2 pi mode amplitude/(sqrt(2) period)', deviation)
      deviation = abs(max_height/amplitude - 1)
      call report(deviation <= tol_target, 'sinusoid max height = amplitude (relative error)', deviation)
   end subroutine check_sinusoid

   subroutine check_errors()
      type(error_type), allocatable :: error
      real(wp) :: height(64)

      call self_affine_profile(64, 1.0_wp, 1.2_wp, 1_i8, not_set, not_set, 0.1_wp, not_set, height, error)
      call report(allocated(error), 'hurst = 1.2 is rejected')
      if (allocated(error)) call report(error%code == code_input .and. index(error%message, 'hurst') > 0, &
         & 'its message names hurst: ' // error%message)
      call self_affine_profile(64, 1.0_wp, 0.8_wp, 1_i8, not_set, not_set, 0.1_wp, 0.1_wp, height, error)
      call report(allocated(error), 'both rms_gradient and rms_height given is rejected')
      call self_affine_profile(64, 1.0_wp, 0.8_wp, 1_i8, 0.01_wp, 0.1_wp, 0.1_wp, not_set, height, error)
      call report(allocated(error), 'rolloff_wavelength shorter than short_wavelength is rejected')
   end subroutine check_errors

   subroutine check_make_profile()
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      real(wp), allocatable :: height(:), direct(:)

      scene%n = 2048
      scene%period = 3.0_wp
      scene%profile%rms_gradient = 0.1_wp
      allocate (height(scene%n), direct(scene%n))
      call make_profile(scene, height, error)
      call self_affine_profile(scene%n, scene%period, scene%profile%hurst, scene%profile%seed, not_set, not_set, &
         & 0.1_wp, not_set, direct, error)
      call report(.not. allocated(error) .and. all(height == direct), 'make_profile self_affine = self_affine_profile')

      scene%profile%kind = 'sinusoid'
      scene%profile%amplitude = 0.5_wp
      scene%profile%mode = 2
      call make_profile(scene, height, error)
      call sinusoid_profile(scene%n, scene%period, 0.5_wp, 2, direct)
      call report(.not. allocated(error) .and. all(height == direct), 'make_profile sinusoid = sinusoid_profile')

      scene%profile%amplitude = not_set
      call check_scene(scene, error)
      call report(allocated(error), 'a sinusoid scene without amplitude is refused by check_scene')

      scene%profile%kind = 'file'
      scene%profile%file = '/nonexistent/layercontact_profile.h5'
      call make_profile(scene, height, error)
      call report(allocated(error), 'make_profile file: a missing file is an error')

      scene%profile%kind = 'hertz'
      call make_profile(scene, height, error)
      call report(allocated(error), 'make_profile unknown kind is an error')
   end subroutine check_make_profile
end program test_profiles
