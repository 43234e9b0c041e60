!> The rigid indenter profile of a scene (docs/theory.md): made from
!> scene%profile (self_affine | sinusoid | file; on an areal scene also sphere) on the
!> scene's grid, and the statistics of a line profile. A line scene gets n heights
!> (lc_profiles_self_affine), an areal scene n*ny heights, x fastest (lc_profiles_surface;
!> a file's heights through lc_profiles_measured, for lines and surfaces alike).
!>
!> Statistics of heights r_j on x_j = j*period/n, with mean r0 = sum_j r_j / n:
!>   rms height   = sqrt(sum_j (r_j - r0)^2 / n)
!>   rms gradient = sqrt(sum_j (r'_j)^2 / n), r' the spectral derivative
!>                = sqrt(2 sum_{k=1}^{kmax} q_k^2 |f^(k)|^2) by Parseval, with f^(k) the
!>                  Fourier coefficients (lc_fft_plans) and kmax = (n-1)/2: the Nyquist
!>                  mode of even n is left out, as its derivative vanishes on the grid
!>   max height   = max_j r_j - r0, measured from the mean line (the seed's Lambda).
!> For a self-affine profile (lc_profiles_self_affine) these equal its scaling target to
!> roundoff.
module lc_profiles_profile
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input, input_error, positive_finite
   use lc_base_strings, only: to_string
   use lc_scene, only: scene_type, not_set, default_rms_gradient, is_areal
   use lc_fft_plans, only: fft_plan
   use lc_profiles_self_affine, only: self_affine_profile, sinusoid_profile
   use lc_profiles_surface, only: self_affine_surface, sinusoid_surface, spherical_cap, sinusoid_rows, spherical_cap_rows
   use lc_profiles_measured, only: measured_heights
   use lc_profiles_measured_slab, only: reads_by_slab, measured_slab
   use lc_base_parallel, only: slab
   implicit none (type, external)
   private
   public :: make_profile, make_profile_slab, profile_statistics

   real(wp), parameter :: pi = acos(-1.0_wp)

contains

   !> Heights of the scene's profile on its grid, dispatching on the geometry and on
   !> scene%profile%kind.
   subroutine make_profile(scene, height, error)
      !> Scene whose grid (%n, %ny, %period, %period_y) and %profile are used
      type(scene_type), intent(in) :: scene
      !> Heights r(x_j) of a line, or r(x, y) of a surface flat with x fastest (L)
      real(wp), intent(out) :: height(scene%n*scene%ny)
      type(error_type), allocatable, intent(out) :: error

      height = 0.0_wp
      if (is_areal(scene)) then
         call make_surface(scene, height, error)
         return
      end if
      associate (p => scene%profile)
         select case (trim(p%kind))
         case ('self_affine')
            if (p%rms_gradient == not_set .and. p%rms_height == not_set) then
               call self_affine_profile(scene%n, scene%period, p%hurst, p%seed, p%rolloff_wavelength, &
                  & p%short_wavelength, default_rms_gradient, not_set, height, error)
            else
               call self_affine_profile(scene%n, scene%period, p%hurst, p%seed, p%rolloff_wavelength, &
                  & p%short_wavelength, p%rms_gradient, p%rms_height, height, error)
            end if
         case ('sinusoid')
            ! amplitude and mode were validated with the scene (check_scene)
            call sinusoid_profile(scene%n, scene%period, p%amplitude, p%mode, height)
         case ('file')
            call measured_heights(trim(p%file), trim(p%dataset), .false., p%detrend, p%boundary, p%resample, &
               & scene%n, 1, height, error)
         case default
            call fatal_error(error, "&profile: kind = '" // trim(p%kind) // "' is not allowed; allowed: " // &
               & "'self_affine', 'sinusoid' or 'file'", code_input)
         end select
      end associate
   end subroutine make_profile

   !> This rank's slab of rows of an areal scene's profile (a surface shared among MPI
   !> ranks, lc_base_parallel), no rank making the whole surface: a self-affine surface is
   !> made on the slabs by the distributed c2r (the same heights as on one process, to
   !> rounding); a sinusoid or a sphere row by row (the same values); a height file is read,
   !> mirrored and resampled by slabs (lc_profiles_measured_slab). A line is made whole and
   !> cut.
   subroutine make_profile_slab(scene, height, error)
      type(scene_type), intent(in) :: scene
      real(wp), allocatable, intent(out) :: height(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: whole(:), slab_rows(:, :)
      real(wp) :: period_y
      integer :: y_start, rows
      call slab(scene%ny, y_start, rows)
      period_y = scene%period
      if (scene%period_y /= not_set) period_y = scene%period_y
      associate (p => scene%profile, nx => scene%n, ny => scene%ny, lx => scene%period)
         if (is_areal(scene)) then
            select case (trim(p%kind))
            case ('file')
               if (reads_by_slab(p%boundary, p%resample)) then
                  call measured_slab(trim(p%file), trim(p%dataset), p%detrend, p%boundary, p%resample, nx, ny, &
                     & height, error)
                  return
               end if
            case ('sinusoid', 'sphere')
               call check_analytic(scene, error)
               if (allocated(error)) return
               allocate (slab_rows(nx, rows))
               if (trim(p%kind) == 'sinusoid') then
                  call sinusoid_rows(nx, ny, lx, period_y, p%amplitude, p%mode, p%mode_y, y_start, slab_rows)
               else
                  call spherical_cap_rows(nx, ny, lx, period_y, p%radius, y_start, slab_rows)
               end if
               height = reshape(slab_rows, [nx*rows])
               return
            end select
         end if
      end associate
      if (.not. (is_areal(scene) .and. trim(scene%profile%kind) == 'self_affine')) then
         allocate (whole(scene%n*scene%ny))
         call make_profile(scene, whole, error)
         if (allocated(error)) return
         height = whole(scene%n*y_start + 1:scene%n*(y_start + rows))
         return
      end if
      allocate (height(scene%n*rows))
      height = 0.0_wp
      associate (p => scene%profile)
         if (p%rms_gradient == not_set .and. p%rms_height == not_set) then
            call self_affine_surface(scene%n, scene%ny, scene%period, period_y, p%hurst, p%seed, &
               & p%rolloff_wavelength, p%short_wavelength, default_rms_gradient, not_set, height, error, .true.)
         else
            call self_affine_surface(scene%n, scene%ny, scene%period, period_y, p%hurst, p%seed, &
               & p%rolloff_wavelength, p%short_wavelength, p%rms_gradient, p%rms_height, height, error, .true.)
         end if
      end associate
   end subroutine make_profile_slab

   subroutine make_surface(scene, height, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: height(scene%n, scene%ny)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: period_y

      height = 0.0_wp
      period_y = scene%period
      if (scene%period_y /= not_set) period_y = scene%period_y
      associate (p => scene%profile, nx => scene%n, ny => scene%ny, lx => scene%period)
         select case (trim(p%kind))
         case ('self_affine')
            if (p%rms_gradient == not_set .and. p%rms_height == not_set) then
               call self_affine_surface(nx, ny, lx, period_y, p%hurst, p%seed, p%rolloff_wavelength, &
                  & p%short_wavelength, default_rms_gradient, not_set, height, error)
            else
               call self_affine_surface(nx, ny, lx, period_y, p%hurst, p%seed, p%rolloff_wavelength, &
                  & p%short_wavelength, p%rms_gradient, p%rms_height, height, error)
            end if
         case ('sinusoid')
            call check_analytic(scene, error)
            if (.not. allocated(error)) &
               & call sinusoid_surface(nx, ny, lx, period_y, p%amplitude, p%mode, p%mode_y, height)
         case ('sphere')
            call check_analytic(scene, error)
            if (.not. allocated(error)) call spherical_cap(nx, ny, lx, period_y, p%radius, height)
         case ('file')
            call measured_heights(trim(p%file), trim(p%dataset), .true., p%detrend, p%boundary, p%resample, &
               & nx, ny, height, error)
         case default
            call fatal_error(error, "&profile: kind = '" // trim(p%kind) // "' is not allowed; allowed: " // &
               & "'self_affine', 'sinusoid', 'sphere' or 'file'", code_input)
         end select
      end associate
   end subroutine make_surface

   !> The areal sinusoid's amplitude and modes and the sphere's radius (the surface routines
   !> cannot fail).
   subroutine check_analytic(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      associate (p => scene%profile, nx => scene%n, ny => scene%ny)
         select case (trim(p%kind))
         case ('sinusoid')
            if (.not. positive_finite(p%amplitude)) then
               call input_error(error, 'profile', 'amplitude', to_string(p%amplitude), '> 0 and finite')
            else if (p%mode < 0 .or. p%mode > (nx - 1)/2) then
               call input_error(error, 'profile', 'mode', to_string(p%mode), &
                  & '0 <= mode <= (nx-1)/2 = ' // to_string((nx - 1)/2))
            else if (abs(p%mode_y) > (ny - 1)/2) then
               call input_error(error, 'profile', 'mode_y', to_string(p%mode_y), &
                  & '|mode_y| <= (ny-1)/2 = ' // to_string((ny - 1)/2))
            else if (p%mode == 0 .and. p%mode_y == 0) then
               call input_error(error, 'profile', 'mode/mode_y', '0/0', 'not both zero (a flat surface)')
            end if
         case ('sphere')
            if (.not. positive_finite(p%radius)) &
               & call input_error(error, 'profile', 'radius', to_string(p%radius), '> 0 and finite')
         end select
      end associate
   end subroutine check_analytic

   !> Rms height, rms gradient and maximum height above the mean line (definitions in the
   !> module header). A plain subroutine: the gradient needs an FFT plan.
   subroutine profile_statistics(height, period, rms_height, rms_gradient, max_height, error)
      !> Heights r(x_j) on a uniform grid over one period (L)
      real(wp), intent(in) :: height(:)
      !> Period lambda (L)
      real(wp), intent(in) :: period
      !> Rms height about the mean line (L)
      real(wp), intent(out) :: rms_height
      !> Rms gradient (-)
      real(wp), intent(out) :: rms_gradient
      !> max_j r_j minus the mean height (L)
      real(wp), intent(out) :: max_height
      type(error_type), allocatable, intent(out) :: error

      type(fft_plan) :: plan
      real(wp) :: mean
      integer :: n, k

      rms_height = 0.0_wp
      rms_gradient = 0.0_wp
      max_height = 0.0_wp
      n = size(height)
      if (n < 2) then
         call fatal_error(error, 'profile_statistics: need at least 2 heights', code_input)
         return
      end if

      mean = sum(height)/n
      rms_height = sqrt(sum((height - mean)**2)/n)
      max_height = maxval(height) - mean

      call plan%init(n, 1, 1, error)
      if (allocated(error)) return
      plan%real_buffer = height
      call plan%forward()
      do k = 1, (n - 1)/2
         rms_gradient = rms_gradient + (2*pi*k/period)**2*abs(plan%spectrum(k + 1))**2
      end do
      rms_gradient = sqrt(2*rms_gradient)
   end subroutine profile_statistics
end module lc_profiles_profile
