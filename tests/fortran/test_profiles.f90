!> Tests of profile synthesis (lc_profiles_random, lc_profiles_self_affine,
!> lc_profiles_surface, lc_profiles_height_file, lc_profiles_measured, lc_profiles_profile). One line per check;
!> exit 0 on pass, error stop 1 on failure.
!>
!> Tolerances:
!> - tol_target = 1e-12: rms height / gradient vs target. The scale is exact for the
!>   discrete series, so only FFT and summation roundoff (~1e-15 relative) remain.
!> - tol_mean = 1e-14 (times the rms height): the mean coefficient is set to zero and the
!>   c2r transform adds only roundoff.
!> - tol_slope = 1e-12: amplitudes are deterministic, so the log-log fit of the measured
!>   amplitudes is exact up to roundoff in the smallest coefficients.
!> - tol_closed = 1e-13 (times the amplitude): closed forms evaluated by the same formula,
!>   differing only in the rounding of the cosine's argument (up to ~2 pi (mode+mode_y)).
program test_profiles
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, code_input
   use lc_scene, only: scene_type, not_set, check_scene
   use lc_fft_plans, only: fft_plan
   use lc_profiles_random, only: splitmix64, splitmix64_uniform
   use lc_profiles_self_affine, only: self_affine_profile, sinusoid_profile
   use lc_profiles_surface, only: self_affine_surface, sinusoid_surface, spherical_cap, surface_mode_index
   use lc_profiles_measured, only: measured_heights, detrend_heights, mirror_heights, resample_heights
   use lc_profiles_profile, only: make_profile, profile_statistics
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_target = 1.0e-12_wp
   real(wp), parameter :: tol_mean = 1.0e-14_wp
   real(wp), parameter :: tol_slope = 1.0e-12_wp
   real(wp), parameter :: tol_closed = 1.0e-13_wp
   real(wp), parameter :: pi = acos(-1.0_wp)

   call check_splitmix64()
   call check_scaling(512, 0.8_wp, 7_i8, 0.05_wp, not_set, 'rms gradient, n = 512, H = 0.8')
   call check_scaling(1001, 0.3_wp, 42_i8, 0.2_wp, not_set, 'rms gradient, odd n = 1001, H = 0.3')
   call check_scaling(4096, 0.7_wp, 1_i8, not_set, 1.0e-3_wp, 'rms height, n = 4096, H = 0.7')
   call check_reproducible()
   call check_slope()
   call check_sinusoid()
   call check_errors()
   call check_make_profile()
   call check_surface_scaling(64, 48, 1.0_wp, 0.75_wp, 0.8_wp, 0.1_wp, not_set, 'surface rms gradient, 64 x 48')
   call check_surface_scaling(45, 63, 2.0_wp, 3.0_wp, 0.4_wp, not_set, 0.3_wp, 'surface rms height, odd 45 x 63')
   call check_surface_modes()
   call check_surface_refinement()
   call check_surface_errors()
   call check_sinusoid_surface()
   call check_spherical_cap()
   call check_surface_text_file()
   call check_measured()
   call check_make_surface()

   call finish('profile')

contains

   !> 64-bit pattern from two 32-bit halves written in hex.
   pure integer(i8) function word(high, low)
      integer(i8), intent(in) :: high, low
      word = ior(shiftl(high, 32), low)
   end function word

   subroutine check_splitmix64()
      ! Reference outputs of Vigna's splitmix64.c next(), checked with a Python big-int
      ! implementation.
      call check(splitmix64(0_i8, 1_i8) == word(int(z'E220A839', i8), int(z'7B1DCDAF', i8)), &
         & 'splitmix64(seed 0) output 1 = 0xE220A8397B1DCDAF')
      call check(splitmix64(0_i8, 2_i8) == word(int(z'6E789E6A', i8), int(z'A1B965F4', i8)), &
         & 'splitmix64(seed 0) output 2 = 0x6E789E6AA1B965F4')
      call check(splitmix64(1_i8, 1_i8) == word(int(z'910A2DEC', i8), int(z'89025CC1', i8)), &
         & 'splitmix64(seed 1) output 1 = 0x910A2DEC89025CC1')
      call check(splitmix64(12345_i8, 3_i8) == word(int(z'1E9A57BC', i8), int(z'80E6721D', i8)), &
         & 'splitmix64(seed 12345) output 3 = 0x1E9A57BC80E6721D')
      ! (z >> 11) * 2^-53 is exact, so equality is the right test.
      call check(splitmix64_uniform(0_i8, 1_i8) == 0.8833108082136426_wp, 'splitmix64_uniform(seed 0) output 1')
      call check(splitmix64_uniform(1_i8, 1_i8) == 0.5665615751722809_wp, 'splitmix64_uniform(seed 1) output 1')
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
         call check(.false., label // ': ' // error%message)
         return
      end if
      call profile_statistics(height, period, measured_height, measured_gradient, max_height, error)
      if (allocated(error)) then
         call check(.false., label // ': ' // error%message)
         return
      end if
      if (rms_gradient /= not_set) then
         deviation = abs(measured_gradient/rms_gradient - 1)
      else
         deviation = abs(measured_height/rms_height - 1)
      end if
      call check(deviation <= tol_target, label // ' equals target (relative error)', deviation)
      deviation = abs(sum(height)/n)/measured_height
      call check(deviation <= tol_mean, label // ' zero mean (|mean|/rms)', deviation)
      call check(max_height > 0.0_wp .and. max_height >= measured_height, label // ' max height >= rms height')
   end subroutine check_scaling

   subroutine check_reproducible()
      integer, parameter :: n = 1024
      type(error_type), allocatable :: error
      real(wp) :: first(n), second(n), other(n)

      call self_affine_profile(n, 1.0_wp, 0.8_wp, 3_i8, not_set, not_set, 0.1_wp, not_set, first, error)
      call self_affine_profile(n, 1.0_wp, 0.8_wp, 3_i8, not_set, not_set, 0.1_wp, not_set, second, error)
      call self_affine_profile(n, 1.0_wp, 0.8_wp, 4_i8, not_set, not_set, 0.1_wp, not_set, other, error)
      call check(all(transfer(first, 1_i8, n) == transfer(second, 1_i8, n)), 'same seed gives identical bits')
      call check(maxval(abs(first - other)) > 0.1_wp*maxval(abs(first)), 'different seed gives a different profile')
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
         call check(.false., 'spectrum slope: ' // error%message)
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
      call check(abs(slope - expected) <= tol_slope, 'spectrum slope -(1+2H)/2 over m_r..m_s (error)', &
         & abs(slope - expected))
      call check(maxval(abs(amplitude(1:m_r - 1)/amplitude(m_r) - 1)) <= tol_target, 'flat spectrum below m_r', &
         & maxval(abs(amplitude(1:m_r - 1)/amplitude(m_r) - 1)))
      call check(maxval(amplitude(m_s + 1:))/amplitude(m_s) <= tol_target, 'no modes above m_s (relative)', &
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
      call check(deviation <= 1.0e-14_wp, 'sinusoid values amplitude cos(2 pi mode j/n) (max relative error)', deviation)
      call profile_statistics(height, period, rms_height, rms_gradient, max_height, error)
      deviation = abs(rms_height*sqrt(2.0_wp)/amplitude - 1)
      call check(deviation <= tol_target, 'sinusoid rms height = amplitude/sqrt(2) (relative error)', deviation)
      deviation = abs(rms_gradient*sqrt(2.0_wp)*period/(2*pi*mode*amplitude) - 1)
      call check(deviation <= tol_target, 'sinusoid rms gradient = 2 pi mode amplitude/(sqrt(2) period)', deviation)
      deviation = abs(max_height/amplitude - 1)
      call check(deviation <= tol_target, 'sinusoid max height = amplitude (relative error)', deviation)
   end subroutine check_sinusoid

   subroutine check_errors()
      type(error_type), allocatable :: error
      real(wp) :: height(64)

      call self_affine_profile(64, 1.0_wp, 1.2_wp, 1_i8, not_set, not_set, 0.1_wp, not_set, height, error)
      call check(allocated(error), 'hurst = 1.2 is rejected')
      if (allocated(error)) call check(error%code == code_input .and. index(error%message, 'hurst') > 0, &
         & 'its message names hurst: ' // error%message)
      call self_affine_profile(64, 1.0_wp, 0.8_wp, 1_i8, not_set, not_set, 0.1_wp, 0.1_wp, height, error)
      call check(allocated(error), 'both rms_gradient and rms_height given is rejected')
      call self_affine_profile(64, 1.0_wp, 0.8_wp, 1_i8, 0.01_wp, 0.1_wp, 0.1_wp, not_set, height, error)
      call check(allocated(error), 'rolloff_wavelength shorter than short_wavelength is rejected')
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
      call check(.not. allocated(error) .and. all(height == direct), 'make_profile self_affine = self_affine_profile')

      scene%profile%kind = 'sinusoid'
      scene%profile%amplitude = 0.5_wp
      scene%profile%mode = 2
      call make_profile(scene, height, error)
      call sinusoid_profile(scene%n, scene%period, 0.5_wp, 2, direct)
      call check(.not. allocated(error) .and. all(height == direct), 'make_profile sinusoid = sinusoid_profile')

      scene%profile%amplitude = not_set
      call check_scene(scene, error)
      call check(allocated(error), 'a sinusoid scene without amplitude is refused by check_scene')

      scene%profile%kind = 'file'
      scene%profile%file = '/nonexistent/layercontact_profile.h5'
      call make_profile(scene, height, error)
      call check(allocated(error), 'make_profile file: a missing file is an error')

      scene%profile%kind = 'hertz'
      call make_profile(scene, height, error)
      call check(allocated(error), 'make_profile unknown kind is an error')
   end subroutine check_make_profile

   !> Rms height and gradient of a surface: the height from the grid values, the gradient by
   !> Parseval over the half spectrum (lc_base_grid's mode weights: 1 in the column mx = 0 and
   !> the Nyquist column, 2 elsewhere).
   subroutine surface_statistics(nx, ny, lx, ly, height, rms_height, rms_gradient, mean)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: lx, ly, height(nx*ny)
      real(wp), intent(out) :: rms_height, rms_gradient, mean
      type(fft_plan) :: plan
      type(error_type), allocatable :: error
      integer :: mx, my, myy
      real(wp) :: weight

      mean = sum(height)/size(height)
      rms_height = sqrt(sum((height - mean)**2)/size(height))
      call plan%init(nx, ny, 1, error)
      plan%real_buffer = height
      call plan%forward()
      rms_gradient = 0.0_wp
      do my = 0, ny - 1
         myy = my
         if (2*my > ny) myy = my - ny
         do mx = 0, nx/2
            weight = merge(1.0_wp, 2.0_wp, mx == 0 .or. 2*mx == nx)
            rms_gradient = rms_gradient + weight*(2*pi)**2*((mx/lx)**2 + (myy/ly)**2) &
               & *abs(plan%spectrum(1 + mx + (nx/2 + 1)*my))**2
         end do
      end do
      rms_gradient = sqrt(rms_gradient)
   end subroutine surface_statistics

   subroutine check_surface_scaling(nx, ny, lx, ly, hurst, rms_gradient, rms_height, label)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: lx, ly, hurst, rms_gradient, rms_height
      character(len=*), intent(in) :: label
      type(error_type), allocatable :: error
      real(wp) :: height(nx*ny), measured_height, measured_gradient, mean, deviation

      call self_affine_surface(nx, ny, lx, ly, hurst, 11_i8, not_set, min(lx, ly)/8, rms_gradient, rms_height, &
         & height, error)
      if (allocated(error)) then
         call check(.false., label // ': ' // error%message)
         return
      end if
      call surface_statistics(nx, ny, lx, ly, height, measured_height, measured_gradient, mean)
      if (rms_gradient /= not_set) then
         deviation = abs(measured_gradient/rms_gradient - 1)
      else
         deviation = abs(measured_height/rms_height - 1)
      end if
      call check(deviation <= tol_target, label // ' equals target (relative error)', deviation)
      call check(abs(mean)/measured_height <= tol_mean, label // ' zero mean (|mean|/rms)', abs(mean)/measured_height)
   end subroutine check_surface_scaling

   !> The coefficients of a synthesised surface, by a forward FFT: every kept mode has the
   !> phase 2 pi u of its index and |f| proportional to (max(kappa, kappa_r)/kappa_r)^(-1-H)
   !> (the log-log slope -(1+H) above kappa_r), the other modes are zero. The modes of the
   !> column mx = 0 come back with their phases only if both (0, my) and (0, -my) were
   !> filled (c2r reads both), so this checks the Hermitian filling too.
   subroutine check_surface_modes()
      !> the grid and its largest mode numbers (nx-1)/2, (ny-1)/2
      integer, parameter :: nx = 40, ny = 36, mx_max = 19, my_max = 17
      real(wp), parameter :: lx = 1.0_wp, ly = 1.0_wp, hurst = 0.7_wp, rolloff = 0.25_wp, short = 1.0_wp/12
      integer(i8), parameter :: seed = 5_i8
      type(error_type), allocatable :: error
      type(fft_plan) :: plan
      real(wp) :: height(nx*ny), kappa2, kappa_r2, kappa_s2, ratio, ratio0, phase_error, amplitude_error, outside
      real(wp) :: sxy, sxx, sx, sy, slope
      complex(wp) :: f
      integer :: mx, my, count, kept

      call self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff, short, not_set, 1.0_wp, height, error)
      call plan%init(nx, ny, 1, error)
      plan%real_buffer = height
      call plan%forward()
      kappa_r2 = 1/rolloff**2
      kappa_s2 = 1/short**2
      phase_error = 0
      amplitude_error = 0
      outside = 0
      ratio0 = -1
      kept = 0
      sx = 0; sy = 0; sxx = 0; sxy = 0; count = 0
      do my = -my_max, my_max
         do mx = 0, mx_max
            if (mx == 0 .and. my <= 0) cycle
            f = plan%spectrum(1 + mx + (nx/2 + 1)*modulo(my, ny))
            kappa2 = (mx/lx)**2 + (my/ly)**2
            if (kappa2 > kappa_s2*(1 + 1.0e-9_wp)) then
               outside = max(outside, abs(f))
               cycle
            end if
            kept = kept + 1
            phase_error = max(phase_error, abs(f/abs(f) - exp(cmplx(0.0_wp, 2*pi*splitmix64_uniform(seed, &
               & surface_mode_index(mx, my)), wp))))
            ratio = abs(f)/(max(kappa2, kappa_r2)/kappa_r2)**(-0.5_wp*(1 + hurst))
            if (ratio0 < 0) ratio0 = ratio
            amplitude_error = max(amplitude_error, abs(ratio/ratio0 - 1))
            if (kappa2 >= kappa_r2) then
               count = count + 1
               sx = sx + 0.5_wp*log(kappa2)
               sy = sy + log(abs(f))
               sxx = sxx + (0.5_wp*log(kappa2))**2
               sxy = sxy + 0.5_wp*log(kappa2)*log(abs(f))
            end if
         end do
      end do
      slope = (count*sxy - sx*sy)/(count*sxx - sx**2)
      call check(kept == count_kept(), 'surface keeps the modes inside the circle kappa <= 1/short_wavelength')
      call check(phase_error <= tol_target, 'surface phases 2 pi u(index(mx, my)) (max |exp(i phi) error|)', phase_error)
      call check(amplitude_error <= tol_target, 'surface amplitudes (max(kappa, kappa_r)/kappa_r)^(-1-H)', &
         & amplitude_error)
      call check(abs(slope + (1 + hurst)) <= tol_slope, 'surface log-log slope of |f| = -(1+H) (error)', &
         & abs(slope + (1 + hurst)))
      call check(outside <= tol_target*ratio0, 'surface: no modes beyond the short cut-off (relative)', outside/ratio0)
      call check(abs(plan%spectrum(1)) <= tol_mean*ratio0, 'surface: zero mean coefficient')

   end subroutine check_surface_modes

   !> Modes of the half plane with kappa <= 12 on the 40 x 36 grid of check_surface_modes,
   !> counted directly: mx = 1..19 with any my = -17..17, and mx = 0 with my = 1..12.
   integer function count_kept()
      integer :: i, j
      count_kept = 12
      do j = -17, 17
         do i = 1, 19
            if (i**2 + j**2 <= 144) count_kept = count_kept + 1
         end do
      end do
   end function count_kept

   !> The phases and amplitudes depend on (mx, my) only: at a fixed short_wavelength a grid
   !> twice as fine gives the same surface at twice as many points.
   subroutine check_surface_refinement()
      type(error_type), allocatable :: error
      real(wp) :: coarse(32, 24), fine(64, 48), deviation

      call self_affine_surface(32, 24, 1.0_wp, 0.75_wp, 0.6_wp, 3_i8, not_set, 0.1_wp, 0.1_wp, not_set, coarse, error)
      call self_affine_surface(64, 48, 1.0_wp, 0.75_wp, 0.6_wp, 3_i8, not_set, 0.1_wp, 0.1_wp, not_set, fine, error)
      deviation = maxval(abs(fine(1::2, 1::2) - coarse))/maxval(abs(coarse))
      call check(deviation <= tol_target, 'surface on a grid twice as fine = the same surface (max relative)', &
         & deviation)
   end subroutine check_surface_refinement

   subroutine check_surface_errors()
      type(error_type), allocatable :: error
      real(wp) :: height(16, 16)

      call self_affine_surface(16, 16, 1.0_wp, 1.0_wp, 0.0_wp, 1_i8, not_set, not_set, 0.1_wp, not_set, height, error)
      call check(allocated(error), 'surface hurst = 0 is rejected')
      if (allocated(error)) call check(error%code == code_input .and. index(error%message, '&profile: hurst') > 0, &
         & 'its message names &profile hurst: ' // error%message)
      call self_affine_surface(16, 2, 1.0_wp, 1.0_wp, 0.8_wp, 1_i8, not_set, not_set, 0.1_wp, not_set, height, error)
      call check(allocated(error), 'surface ny = 2 is rejected')
      call self_affine_surface(16, 16, 1.0_wp, 1.0_wp, 0.8_wp, 1_i8, 0.05_wp, 0.2_wp, 0.1_wp, not_set, height, error)
      call check(allocated(error), 'surface rolloff_wavelength shorter than short_wavelength is rejected')
      call self_affine_surface(16, 16, 1.0_wp, 1.0_wp, 0.8_wp, 1_i8, not_set, not_set, not_set, not_set, height, error)
      call check(allocated(error), 'surface without rms_gradient and rms_height is rejected')
   end subroutine check_surface_errors

   subroutine check_sinusoid_surface()
      integer, parameter :: nx = 32, ny = 24, mode = 3, mode_y = -2
      real(wp), parameter :: lx = 2.0_wp, ly = 1.5_wp, amplitude = 0.2_wp
      real(wp) :: height(nx, ny), expected(nx, ny), rms_height, rms_gradient, mean, deviation
      integer :: ix, iy

      call sinusoid_surface(nx, ny, lx, ly, amplitude, mode, mode_y, height)
      do iy = 0, ny - 1
         do ix = 0, nx - 1
            expected(ix + 1, iy + 1) = amplitude*cos(2*pi*(real(mode*ix, wp)/nx + real(mode_y*iy, wp)/ny))
         end do
      end do
      deviation = maxval(abs(height - expected))/amplitude
      call check(deviation <= tol_closed, 'sinusoid surface = amplitude cos(2 pi (mode ix/nx + mode_y iy/ny))', deviation)
      call surface_statistics(nx, ny, lx, ly, height, rms_height, rms_gradient, mean)
      deviation = abs(rms_gradient*sqrt(2.0_wp)/(2*pi*amplitude*sqrt((mode/lx)**2 + (mode_y/ly)**2)) - 1)
      call check(deviation <= tol_target, 'sinusoid surface rms gradient = 2 pi |kappa| amplitude/sqrt(2)', deviation)
   end subroutine check_sinusoid_surface

   subroutine check_spherical_cap()
      integer, parameter :: nx = 33, ny = 20
      real(wp), parameter :: lx = 1.0_wp, ly = 0.8_wp, radius = 0.3_wp
      real(wp) :: height(nx, ny), rho2, expected, deviation, x0, y0
      integer :: ix, iy

      call spherical_cap(nx, ny, lx, ly, radius, height)
      ! the apex: grid point (nx/2, ny/2) (integer halves: 16 and 10)
      x0 = 16*lx/nx
      y0 = 10*ly/ny
      deviation = 0
      do iy = 0, ny - 1
         do ix = 0, nx - 1
            rho2 = (ix*lx/nx - x0)**2 + (iy*ly/ny - y0)**2
            expected = merge(sqrt(max(radius**2 - rho2, 0.0_wp)) - radius, -radius, rho2 < radius**2)
            deviation = max(deviation, abs(height(ix + 1, iy + 1) - expected)/radius)
         end do
      end do
      call check(deviation <= tol_closed, 'spherical cap = sqrt(R^2 - rho^2) - R inside, -R outside', deviation)
      call check(height(17, 11) == 0.0_wp .and. maxval(height) == 0.0_wp, &
         & 'spherical cap apex at (nx/2, ny/2) is the maximum, 0')
      call check(minval(height) == -radius, 'spherical cap is -R beyond the sphere')
   end subroutine check_spherical_cap

   subroutine check_surface_text_file()
      integer, parameter :: nx = 5, ny = 3
      character(len=*), parameter :: name = 'test_profiles_surface.txt'
      type(error_type), allocatable :: error
      real(wp) :: written(nx, ny), read_back(nx, ny), small(nx, ny - 1)
      integer :: unit, iy

      written = reshape([(0.1_wp*iy - 0.7_wp, iy=1, nx*ny)], [nx, ny])
      open (newunit=unit, file=name, status='replace', action='write')
      write (unit, '(a)') '# a comment line, then rows of nx heights'
      do iy = 1, ny
         write (unit, '(*(es25.17, 1x))') written(:, iy)
      end do
      close (unit)
      call measured_heights(name, '', .true., 'auto', 'periodic', 'none', nx, ny, read_back, error)
      call check(.not. allocated(error) .and. all(read_back == written), 'text surface file round trip (17 digits)')
      call measured_heights(name, '', .true., 'auto', 'periodic', 'none', nx, ny - 1, small, error)
      call check(allocated(error), 'text surface file with too many lines is rejected')
      if (allocated(error)) call check(error%code == code_input .and. index(error%message, "&profile: file = '") > 0, &
         & 'its message names &profile file: ' // error%message)
      open (newunit=unit, file=name, status='old')
      close (unit, status='delete')
      call measured_heights('/nonexistent/surface.npy', '', .true., 'auto', 'periodic', 'none', nx, ny, read_back, &
         & error)
      call check(allocated(error), 'missing .npy surface file is an error')
      if (allocated(error)) call check(error%code == code_input, 'its code is code_input (bad input): ' // error%message)
   end subroutine check_surface_text_file

   !> Detrending, mirroring and resampling of measured heights against closed forms.
   subroutine check_measured()
      real(wp), allocatable :: height(:, :), expected(:, :), resampled(:, :)
      type(error_type), allocatable :: error
      integer :: ix, iy, sizes(2, 3), k

      ! a plane and a quadric in physical coordinates go to zero (rounding)
      allocate (height(7, 5))
      do iy = 1, 5
         do ix = 1, 7
            height(ix, iy) = 3.0_wp + 0.2_wp*ix - 0.7_wp*iy
         end do
      end do
      call detrend_heights(height, 'plane')
      call check(maxval(abs(height)) < 1.0e-13_wp, 'detrend plane removes a plane', maxval(abs(height)))
      do iy = 1, 5
         do ix = 1, 7
            height(ix, iy) = 1.0_wp + 0.2_wp*ix - 0.7_wp*iy + 0.05_wp*ix**2 - 0.1_wp*iy**2 + 0.03_wp*ix*iy
         end do
      end do
      call detrend_heights(height, 'curvature')
      call check(maxval(abs(height)) < 1.0e-12_wp, 'detrend curvature removes a quadric', maxval(abs(height)))

      ! mirror: (mx, my) -> (2 mx, 2 my), h(2m-1-j) = h(j)
      height = reshape([(real(ix, wp), ix=1, 6)], [3, 2])
      call mirror_heights(height, .true.)
      call check(all(shape(height) == [6, 4]) .and. all(height(:, 1) == [1, 2, 3, 3, 2, 1]) .and. &
         & all(height(:, 4) == height(:, 1)) .and. all(height(:, 3) == height(:, 2)), 'mirror of a surface patch')

      ! Fourier resampling of a band-limited surface (modes 2 along x, 1 along y) is exact
      sizes = reshape([16, 12, 24, 20, 9, 7], [2, 3])
      do k = 2, 3
         height = band_limited(sizes(1, 1), sizes(2, 1))
         expected = band_limited(sizes(1, k), sizes(2, k))
         allocate (resampled(sizes(1, k), sizes(2, k)))
         call resample_heights(height, resampled, error)
         call check(.not. allocated(error) .and. maxval(abs(resampled - expected)) < 1.0e-13_wp, &
            & 'Fourier resampling of a band-limited surface ' // trim(adjustl(to_text(sizes(:, k)))), &
            & maxval(abs(resampled - expected)))
         deallocate (resampled)
      end do
   end subroutine check_measured

   !> A surface of modes (2, 1) and (0, 1) on an nx x ny grid of one period.
   function band_limited(nx, ny) result(h)
      integer, intent(in) :: nx, ny
      real(wp) :: h(nx, ny)
      integer :: i, j
      do j = 1, ny
         do i = 1, nx
            h(i, j) = 0.3_wp*cos((8*atan(1.0_wp))*(2*(i - 1)/real(nx, wp) + (j - 1)/real(ny, wp)) + 0.4_wp) + &
               & 0.1_wp*sin((8*atan(1.0_wp))*(j - 1)/real(ny, wp))
         end do
      end do
   end function band_limited

   function to_text(n) result(s)
      integer, intent(in) :: n(2)
      character(len=24) :: s
      write (s, '(i0, " x ", i0)') n
   end function to_text

   subroutine check_make_surface()
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      real(wp), allocatable :: height(:), direct(:)

      scene%geometry = 'areal'
      scene%n = 32
      scene%ny = 16
      scene%period = 2.0_wp
      scene%period_y = 1.0_wp
      allocate (height(scene%n*scene%ny), direct(scene%n*scene%ny))
      call make_profile(scene, height, error)
      call self_affine_surface(32, 16, 2.0_wp, 1.0_wp, scene%profile%hurst, scene%profile%seed, not_set, not_set, &
         & 0.1_wp, not_set, direct, error)
      call check(.not. allocated(error) .and. all(height == direct), 'make_profile areal self_affine = self_affine_surface')

      scene%profile%kind = 'sinusoid'
      scene%profile%amplitude = 0.5_wp
      scene%profile%mode = 0
      scene%profile%mode_y = 7
      call make_profile(scene, height, error)
      call sinusoid_surface(32, 16, 2.0_wp, 1.0_wp, 0.5_wp, 0, 7, direct)
      call check(.not. allocated(error) .and. all(height == direct), 'make_profile areal sinusoid = sinusoid_surface')
      scene%profile%mode_y = 8
      call make_profile(scene, height, error)
      call check(allocated(error), 'areal sinusoid mode_y = ny/2 (Nyquist) is rejected')
      if (allocated(error)) call check(index(error%message, '&profile: mode_y') > 0, 'its message names mode_y: ' &
         & // error%message)

      scene%profile%kind = 'sphere'
      call make_profile(scene, height, error)
      call check(allocated(error), 'areal sphere without radius is rejected')
      scene%profile%radius = 0.4_wp
      call make_profile(scene, height, error)
      call spherical_cap(32, 16, 2.0_wp, 1.0_wp, 0.4_wp, direct)
      call check(.not. allocated(error) .and. all(height == direct), 'make_profile areal sphere = spherical_cap')
   end subroutine check_make_surface
end program test_profiles
