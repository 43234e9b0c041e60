!> Areal (doubly periodic) rigid surfaces on an nx x ny grid of periods lx, ly: a random
!> isotropic self-affine surface (power spectrum C(q) ~ |q|^(-2-2H), random phases, scaled
!> to an rms gradient or height), an oblique sinusoid and a spherical cap. Heights are
!> returned as height(nx, ny), x fastest (lc_base_grid's layout; numpy height[ny, nx]).
!>
!> Self-affine algorithm (tests/reference_profiles.py reproduces it up to roundoff; change
!> both together):
!>
!> 1. Grid x = ix*lx/nx, y = iy*ly/ny. Modes (mx, my) with |mx| <= (nx-1)/2 and
!>    |my| <= (ny-1)/2 (integer division: no Nyquist column or row of an even size),
!>    wavevector q = 2 pi (mx/lx, my/ly), kappa^2 = (mx/lx)^2 + (my/ly)^2 (|q| = 2 pi kappa).
!>    The pair {q, -q} is represented by the mode with mx > 0 (any my), or mx = 0 and
!>    my > 0; (0, 0) is left out.
!> 2. Cut-offs kappa_r = 1/rolloff_wavelength (default rolloff_wavelength = max(lx, ly),
!>    the longest fundamental, so that by default no mode is flat, as the line default)
!>    and kappa_s = min(1/short_wavelength, ((nx-1)/2)/lx, ((ny-1)/2)/ly) (default
!>    short_wavelength = min(lx, ly)/128). Capping at the largest circle that fits in the
!>    grid keeps the cut round, i.e. the surface isotropic. A mode is kept when
!>    kappa^2 <= kappa_s^2 (1 + 1e-9): the slack keeps the modes that lie on the circle
!>    (e.g. (64, 0) with short_wavelength = lx/64) whatever the rounding of kappa^2.
!> 3. Spectrum C = (max(kappa^2, kappa_r^2)/kappa_r^2)^(-1-H) (flat below the roll-off,
!>    continuous at it, ~ |q|^(-2-2H) above) for kept modes, 0 otherwise; amplitude
!>    a = sqrt(C).
!> 4. Phase phi = 2 pi u, u = splitmix64_uniform(seed, index(mx, my)) (lc_profiles_random)
!>    with the Cantor pairing index(mx, my) = (mx + k)(mx + k + 1)/2 + k + 1 of mx >= 0 and
!>    k = 2 my (my >= 0) or -2 my - 1 (my < 0). The index depends on (mx, my) only, not on
!>    the grid size, the periods or the cut-offs: refining the grid at a fixed
!>    short_wavelength gives the same surface at more points.
!> 5. Scale s = target/current, with current = sqrt(sum a^2/2) for an rms height and
!>    current = sqrt(sum (2 pi)^2 kappa^2 a^2/2) for an rms gradient sqrt(<|grad r|^2>),
!>    sums over the representatives. Both are exact for the discrete surface, since
!>    distinct modes below Nyquist are orthogonal on the grid.
!> 6. Coefficients f(q) = s (a/2) exp(i phi) on the representatives and f(-q) = conj f(q),
!>    so r(x, y) = sum_q f(q) exp(i q.x) = sum_representatives s a cos(q.x + phi): real,
!>    zero mean. The half spectrum of lc_fft_plans (columns mx >= 0) holds a
!>    representative with mx > 0 in row mod(my, ny); column mx = 0 holds both (0, my) and
!>    its conjugate (0, -my), which the c2r backward transform needs there.
!>
!> Isotropy: second-order statistics (rms slopes along x and y, the autocorrelation) are
!> fixed by the amplitudes alone, and on a square cell (lx = ly) the kept modes are
!> symmetric under mx <-> my, so they are isotropic to rounding. On a rectangular cell the
!> longest waves sit on an anisotropic lattice of modes (spacings 1/lx and 1/ly); a roll-off
!> wavelength well below min(lx, ly) keeps them flat, where they carry little slope
!> (tests/test_surfaces.py measures the rms slopes along x and y).
module lc_profiles_surface
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, input_error, positive_finite
   use lc_base_strings, only: to_string
   use lc_scene, only: not_set
   use lc_fft_plans, only: fft_plan
   use lc_profiles_random, only: splitmix64_uniform
   use lc_profiles_self_affine, only: check_roughness_scale
   implicit none (type, external)
   private
   public :: self_affine_surface, sinusoid_surface, spherical_cap, sinusoid_rows, spherical_cap_rows, surface_mode_index

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Default shortest wavelength as a fraction of the shorter period.
   real(wp), parameter :: default_short_fraction = 1.0_wp/128
   !> Relative slack of the short-wavelength cut on kappa^2 (step 2 of the header).
   real(wp), parameter :: edge_slack = 1.0e-9_wp

contains

   !> Random isotropic self-affine surface (algorithm in the module header). `distributed`
   !> (a surface shared among MPI ranks): `height` is this rank's slab of rows
   !> (lc_base_parallel), made by the distributed c2r from this rank's modes; every mode's
   !> phase comes from its own index, so the surface is the same on any rank count.
   subroutine self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff_wavelength, short_wavelength, &
      & rms_gradient, rms_height, height, error, distributed)
      !> Grid points along x and y (>= 4 each)
      integer, intent(in) :: nx, ny
      !> Periods along x and y (L)
      real(wp), intent(in) :: lx, ly
      !> Hurst exponent H, 0 < H < 1
      real(wp), intent(in) :: hurst
      !> Random seed (>= 0)
      integer(i8), intent(in) :: seed
      !> Roll-off wavelength (L), or not_set for max(lx, ly)
      real(wp), intent(in) :: rolloff_wavelength
      !> Shortest wavelength (L), or not_set for min(lx, ly)/128
      real(wp), intent(in) :: short_wavelength
      !> Target rms gradient sqrt(<|grad r|^2>), or not_set (give exactly one of the two)
      real(wp), intent(in) :: rms_gradient
      !> Target rms height (L), or not_set
      real(wp), intent(in) :: rms_height
      !> Heights r(x, y) (L): all ny rows, or this rank's slab (distributed)
      real(wp), intent(out) :: height(nx, *)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: distributed

      type(fft_plan) :: plan
      integer :: column
      real(wp) :: rolloff, short, longest, kappa_r2, kappa_s2, kappa2, amplitude, sum_height, sum_gradient, scale
      complex(wp) :: coefficient
      integer :: mx, my, nkx, mx_max, my_max

      longest = max(lx, ly)
      rolloff = longest
      if (rolloff_wavelength /= not_set) rolloff = rolloff_wavelength
      short = min(lx, ly)*default_short_fraction
      if (short_wavelength /= not_set) short = short_wavelength

      if (nx < 4) then
         call input_error(error, 'scene', 'nx (or n)', to_string(nx), '>= 4 (at least one mode below Nyquist)')
      else if (ny < 4) then
         call input_error(error, 'scene', 'ny (or n)', to_string(ny), '>= 4 (at least one mode below Nyquist)')
      else if (.not. positive_finite(lx)) then
         call input_error(error, 'scene', 'period', to_string(lx), '> 0 and finite')
      else if (.not. positive_finite(ly)) then
         call input_error(error, 'scene', 'period_y', to_string(ly), '> 0 and finite')
      else if (.not. (hurst > 0.0_wp .and. hurst < 1.0_wp)) then
         call input_error(error, 'profile', 'hurst', to_string(hurst), '0 < hurst < 1')
      else if (seed < 0_i8) then
         call input_error(error, 'profile', 'seed', to_string(seed), '>= 0')
      else if (.not. (positive_finite(rolloff) .and. rolloff <= longest)) then
         call input_error(error, 'profile', 'rolloff_wavelength', to_string(rolloff), &
            & '0 < rolloff_wavelength <= max(period, period_y)')
      else if (.not. (positive_finite(short) .and. short <= longest)) then
         call input_error(error, 'profile', 'short_wavelength', to_string(short), &
            & '0 < short_wavelength <= max(period, period_y)')
      end if
      if (allocated(error)) return
      call check_roughness_scale(rms_gradient, rms_height, error)
      if (allocated(error)) return

      mx_max = (nx - 1)/2
      my_max = (ny - 1)/2
      kappa_r2 = (1.0_wp/rolloff)**2
      kappa_s2 = min(1.0_wp/short, mx_max/lx, my_max/ly)**2
      if (kappa_r2 > kappa_s2) then
         ! Otherwise the modes between the two cut-offs would be both flat and cut off.
         call input_error(error, 'profile', 'rolloff_wavelength', to_string(rolloff), &
            & '>= the shortest wavelength kept, 1/min(1/short_wavelength, ((nx-1)/2)/period, ' // &
            & '((ny-1)/2)/period_y) = ' // to_string(1.0_wp/sqrt(kappa_s2)))
         return
      end if

      call plan%init(nx, ny, 1, error, distributed)
      if (allocated(error)) return
      nkx = nx/2 + 1
      plan%spectrum = (0.0_wp, 0.0_wp)
      sum_height = 0.0_wp
      sum_gradient = 0.0_wp
      do my = -my_max, my_max
         do mx = 0, mx_max
            if (mx == 0 .and. my <= 0) cycle
            kappa2 = (mx/lx)**2 + (my/ly)**2
            if (kappa2 > kappa_s2*(1 + edge_slack)) cycle
            amplitude = (max(kappa2, kappa_r2)/kappa_r2)**(-0.5_wp*(1 + hurst))
            sum_height = sum_height + amplitude**2
            sum_gradient = sum_gradient + kappa2*amplitude**2
            if (plan%distributed) then
               ! (this rank's columns of the transposed spectrum: my fastest)
               column = mx - plan%x_start
               if (column < 0 .or. column >= plan%nkx_local) cycle
               coefficient = amplitude/2*exp(cmplx(0.0_wp, 2*pi*splitmix64_uniform(seed, surface_mode_index(mx, my)), &
                  & wp))
               plan%spectrum(1 + modulo(my, ny) + ny*column) = coefficient
               if (mx == 0) plan%spectrum(1 + modulo(-my, ny) + ny*column) = conjg(coefficient)
               cycle
            end if
            coefficient = amplitude/2*exp(cmplx(0.0_wp, 2*pi*splitmix64_uniform(seed, surface_mode_index(mx, my)), wp))
            plan%spectrum(1 + mx + nkx*modulo(my, ny)) = coefficient
            if (mx == 0) plan%spectrum(1 + nkx*modulo(-my, ny)) = conjg(coefficient)
         end do
      end do

      if (rms_gradient /= not_set) then
         scale = rms_gradient/sqrt((2*pi)**2*sum_gradient/2)
      else
         scale = rms_height/sqrt(sum_height/2)
      end if
      plan%spectrum = scale*plan%spectrum
      call plan%backward()
      height(:, 1:plan%ny_local) = reshape(plan%real_buffer, [nx, plan%ny_local])
   end subroutine self_affine_surface

   !> Index of the random phase of mode (mx, my) (step 4 of the header): the Cantor pairing
   !> of mx >= 0 with my folded onto k >= 0 (0, -1, 1, -2, ... -> 0, 1, 2, 3, ...), plus 1.
   pure elemental integer(i8) function surface_mode_index(mx, my) result(index)
      !> Mode numbers along x (>= 0) and y
      integer, intent(in) :: mx, my
      integer(i8) :: k, s

      if (my >= 0) then
         k = 2_i8*my
      else
         k = -2_i8*my - 1
      end if
      s = mx + k
      index = s*(s + 1)/2 + k + 1
   end function surface_mode_index

   !> Oblique sinusoid r = amplitude cos(2 pi (mode x/lx + mode_y y/ly)), x = ix*lx/nx,
   !> y = iy*ly/ny, evaluated point by point.
   pure subroutine sinusoid_surface(nx, ny, lx, ly, amplitude, mode, mode_y, height)
      !> Grid points along x and y
      integer, intent(in) :: nx, ny
      !> Periods along x and y (L)
      real(wp), intent(in) :: lx, ly
      !> Amplitude (L)
      real(wp), intent(in) :: amplitude
      !> Wavelengths per period along x and along y
      integer, intent(in) :: mode, mode_y
      !> Heights (L)
      real(wp), intent(out) :: height(nx, ny)
      call sinusoid_rows(nx, ny, lx, ly, amplitude, mode, mode_y, 0, height)
   end subroutine sinusoid_surface

   !> The rows y_start+1 .. y_start+size(height, 2) of sinusoid_surface (a slab of rows of
   !> a surface shared among MPI ranks, lc_base_slab): the same values point by point.
   pure subroutine sinusoid_rows(nx, ny, lx, ly, amplitude, mode, mode_y, y_start, height)
      integer, intent(in) :: nx, ny, mode, mode_y
      real(wp), intent(in) :: lx, ly, amplitude
      !> rows before the first one here (0-based)
      integer, intent(in) :: y_start
      !> Heights of the rows (L), (nx, rows)
      real(wp), intent(out) :: height(:, :)
      real(wp) :: x, y
      integer :: ix, iy

      do iy = y_start, y_start + size(height, 2) - 1
         y = iy*ly/ny
         do ix = 0, nx - 1
            x = ix*lx/nx
            height(ix + 1, iy - y_start + 1) = amplitude*cos(2*pi*(mode*x/lx + mode_y*y/ly))
         end do
      end do
   end subroutine sinusoid_rows

   !> Spherical cap of radius R with its apex at the grid point (ix, iy) = (nx/2, ny/2)
   !> (0-based; the cell's centre (lx/2, ly/2) for even sizes): r = sqrt(R^2 - rho^2) - R
   !> for rho < R and -R beyond (the sphere's equator, where the cap ends continuously), so
   !> that the apex r = 0 is the maximum. rho is the in-plane distance to the apex within
   !> the cell, which for a centred apex is the distance to the nearest periodic image.
   pure subroutine spherical_cap(nx, ny, lx, ly, radius, height)
      !> Grid points along x and y
      integer, intent(in) :: nx, ny
      !> Periods along x and y (L)
      real(wp), intent(in) :: lx, ly
      !> Radius R of the sphere (L, > 0)
      real(wp), intent(in) :: radius
      !> Heights (L)
      real(wp), intent(out) :: height(nx, ny)
      call spherical_cap_rows(nx, ny, lx, ly, radius, 0, height)
   end subroutine spherical_cap

   !> The rows y_start+1 .. y_start+size(height, 2) of spherical_cap (a slab of rows): the
   !> same values point by point.
   pure subroutine spherical_cap_rows(nx, ny, lx, ly, radius, y_start, height)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: lx, ly, radius
      !> rows before the first one here (0-based)
      integer, intent(in) :: y_start
      !> Heights of the rows (L), (nx, rows)
      real(wp), intent(out) :: height(:, :)
      real(wp) :: dx, dy, rho2
      integer :: ix, iy

      do iy = y_start, y_start + size(height, 2) - 1
         dy = iy*ly/ny - (ny/2)*ly/ny
         do ix = 0, nx - 1
            dx = ix*lx/nx - (nx/2)*lx/nx
            rho2 = dx**2 + dy**2
            if (rho2 < radius**2) then
               ! sqrt(R^2 - rho^2) - R written without its cancellation near the apex (and
               ! as 0 - ..., so that the apex is +0, not -0)
               height(ix + 1, iy - y_start + 1) = 0.0_wp - rho2/(radius + sqrt(radius**2 - rho2))
            else
               height(ix + 1, iy - y_start + 1) = -radius
            end if
         end do
      end do
   end subroutine spherical_cap_rows
end module lc_profiles_surface
