!> Line profiles made from a Fourier series: a random self-affine profile (docs/theory.md
!> "Profiles": power spectrum C(q) ~ q^(-1-2H), random phases, scaled to an rms gradient
!> or height) and a sinusoid for analytic checks.
!>
!> Self-affine algorithm (tests/reference_profiles.py reproduces it bit for bit up to
!> roundoff; change both together):
!>
!> 1. Grid x_j = j*period/n, j = 0..n-1. Modes m = 1 .. (n-1)/2 (integer division; no
!>    mean, no Nyquist mode of an even n), wavenumber q_m = 2 pi m / period.
!> 2. Cut-offs m_r = nint(period/rolloff_wavelength) (default rolloff_wavelength = period,
!>    so m_r = 1) and m_s = min(nint(period/short_wavelength), (n-1)/2) (default
!>    short_wavelength = period/128).
!> 3. Spectrum C_m = 1 for m < m_r, (m/m_r)^(-1-2H) for m_r <= m <= m_s, 0 for m > m_s;
!>    amplitude a_m = sqrt(C_m).
!> 4. Phase phi_m = 2 pi u_m, u_m = splitmix64_uniform(seed, m) (lc_profiles_random).
!> 5. Scale s = target/current, with current = sqrt(sum_m q_m^2 a_m^2/2) when
!>    rms_gradient is given, sqrt(sum_m a_m^2/2) when rms_height is given. Both are exact
!>    for the discrete series, since distinct modes below Nyquist are orthogonal on
!>    the grid.
!> 6. Coefficients f^(m) = s (a_m/2) exp(i phi_m) for m = 1..n/2-1, zero otherwise, and
!>    r_j = sum_k f^(k) exp(i q_k x_j) over k = -(n/2-1)..n/2-1 with f^(-k) = conj f^(k),
!>    i.e. r_j = sum_m s a_m cos(q_m x_j + phi_m): the c2r backward transform of
!>    lc_fft_plans. The heights have zero mean.
module lc_profiles_self_affine
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, input_error, positive_finite
   use lc_base_strings, only: to_string
   use lc_scene, only: not_set
   use lc_fft_plans, only: fft_plan
   use lc_profiles_random, only: splitmix64_uniform
   implicit none (type, external)
   private
   public :: self_affine_profile, sinusoid_profile, check_roughness_scale

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Default shortest wavelength as a fraction of the period.
   real(wp), parameter :: default_short_fraction = 1.0_wp/128

contains

   !> Random self-affine line profile (algorithm in the module header).
   subroutine self_affine_profile(n, period, hurst, seed, rolloff_wavelength, short_wavelength, &
      & rms_gradient, rms_height, height, error)
      !> Grid points per period (>= 4)
      integer, intent(in) :: n
      !> Period lambda (L)
      real(wp), intent(in) :: period
      !> Hurst exponent H, 0 < H < 1
      real(wp), intent(in) :: hurst
      !> Random seed (>= 0)
      integer(i8), intent(in) :: seed
      !> Roll-off wavelength (L), or not_set for the period
      real(wp), intent(in) :: rolloff_wavelength
      !> Shortest wavelength (L), or not_set for period/128
      real(wp), intent(in) :: short_wavelength
      !> Target rms gradient, or not_set (give exactly one of rms_gradient and rms_height)
      real(wp), intent(in) :: rms_gradient
      !> Target rms height (L), or not_set
      real(wp), intent(in) :: rms_height
      !> Heights r(x_j) (L)
      real(wp), intent(out) :: height(n)
      type(error_type), allocatable, intent(out) :: error

      type(fft_plan) :: plan
      real(wp) :: rolloff, short, current, scale
      real(wp), allocatable :: amplitude(:), q(:)
      integer :: m, m_r, m_s, m_max

      height = 0.0_wp
      rolloff = period
      if (rolloff_wavelength /= not_set) rolloff = rolloff_wavelength
      short = period*default_short_fraction
      if (short_wavelength /= not_set) short = short_wavelength

      if (n < 4) then
         call input_error(error, 'scene', 'n', to_string(n), '>= 4 (at least one mode below Nyquist)')
      else if (.not. positive_finite(period)) then
         call input_error(error, 'scene', 'period', to_string(period), '> 0 and finite')
      else if (.not. (hurst > 0.0_wp .and. hurst < 1.0_wp)) then
         call input_error(error, 'profile', 'hurst', to_string(hurst), '0 < hurst < 1')
      else if (seed < 0_i8) then
         call input_error(error, 'profile', 'seed', to_string(seed), '>= 0')
      else if (.not. (positive_finite(rolloff) .and. rolloff <= period)) then
         call input_error(error, 'profile', 'rolloff_wavelength', to_string(rolloff), '0 < rolloff_wavelength <= period')
      else if (.not. (positive_finite(short) .and. short <= period)) then
         call input_error(error, 'profile', 'short_wavelength', to_string(short), '0 < short_wavelength <= period')
      end if
      if (allocated(error)) return
      call check_roughness_scale(rms_gradient, rms_height, error)
      if (allocated(error)) return

      m_max = (n - 1)/2
      m_r = nint(period/rolloff)
      m_s = min(nint(period/short), m_max)
      if (m_r > m_s) then
         ! Otherwise the modes between m_s and m_r would be both flat and cut off.
         call input_error(error, 'profile', 'rolloff_wavelength', to_string(rolloff), &
            & 'a roll-off mode nint(period/rolloff_wavelength) = ' // to_string(m_r) // &
            & ' <= the shortest mode min(nint(period/short_wavelength), n/2-1) = ' // to_string(m_s))
         return
      end if

      allocate (amplitude(m_max), q(m_max))
      do m = 1, m_max
         q(m) = 2*pi*m/period
         if (m < m_r) then
            amplitude(m) = 1.0_wp
         else if (m <= m_s) then
            amplitude(m) = (real(m, wp)/m_r)**(-0.5_wp*(1 + 2*hurst))
         else
            amplitude(m) = 0.0_wp
         end if
      end do

      if (rms_gradient /= not_set) then
         current = sqrt(sum((q*amplitude)**2)/2)
         scale = rms_gradient/current
      else
         current = sqrt(sum(amplitude**2)/2)
         scale = rms_height/current
      end if

      call plan%init(n, 1, 1, error)
      if (allocated(error)) return
      plan%spectrum = (0.0_wp, 0.0_wp)
      do m = 1, m_max
         plan%spectrum(m + 1) = scale*amplitude(m)/2 &
            & *exp(cmplx(0.0_wp, 2*pi*splitmix64_uniform(seed, int(m, i8)), wp))
      end do
      call plan%backward()
      height = plan%real_buffer
   end subroutine self_affine_profile

   !> Sinusoid r(x_j) = amplitude cos(2 pi mode x_j / period), x_j = j*period/n.
   pure subroutine sinusoid_profile(n, period, amplitude, mode, height)
      !> Grid points per period
      integer, intent(in) :: n
      !> Period lambda (L)
      real(wp), intent(in) :: period
      !> Amplitude (L)
      real(wp), intent(in) :: amplitude
      !> Number of wavelengths per period
      integer, intent(in) :: mode
      !> Heights (L)
      real(wp), intent(out) :: height(n)
      integer :: j
      real(wp) :: x

      do j = 0, n - 1
         x = j*period/n
         height(j + 1) = amplitude*cos(2*pi*mode*x/period)
      end do
   end subroutine sinusoid_profile





   !> Exactly one of rms_gradient (-) and rms_height (L) given, positive and finite (the
   !> scale of a self-affine line or surface).
   subroutine check_roughness_scale(rms_gradient, rms_height, error)
      real(wp), intent(in) :: rms_gradient, rms_height
      type(error_type), allocatable, intent(out) :: error
      if (count([rms_gradient /= not_set, rms_height /= not_set]) /= 1) then
         call input_error(error, 'profile', 'rms_gradient/rms_height', 'both or neither given', 'exactly one of them')
      else if (rms_gradient /= not_set .and. .not. positive_finite(rms_gradient)) then
         call input_error(error, 'profile', 'rms_gradient', to_string(rms_gradient), '> 0 and finite')
      else if (rms_height /= not_set .and. .not. positive_finite(rms_height)) then
         call input_error(error, 'profile', 'rms_height', to_string(rms_height), '> 0 and finite')
      end if
   end subroutine check_roughness_scale

end module lc_profiles_self_affine
