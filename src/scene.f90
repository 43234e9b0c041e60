!> A scene is data: geometry, layer, friction, profile, loading, solver settings and
!> output of one contact problem, as read from a namelist file or built from Python.
!> The operator and the solver are built from it (only what it needs); `check_scene`
!> validates it and names the namelist group and variable of every bad value.
!>
!> Units: any consistent set. Lengths (period, thickness, heights, penetration) in one
!> length unit L, moduli and pressures in one stress unit S. The results are in the same
!> units; the seed's normalised values are stored next to them.
module lc_scene
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, input_error, positive_finite
   use lc_base_strings, only: to_string
   use lc_greens_viscoelastic, only: material_law, check_material, static_modulus, is_viscoelastic
   use lc_base_grid, only: grid_type, line_grid, surface_grid
   use lc_greens_kernel, only: layer_kernel, make_kernel
   use lc_leakage_reynolds, only: leakage_tol_allowed, leakage_tol_range
   use lc_profiles_measured, only: check_treatments
   implicit none (type, external)
   private
   public :: scene_type, profile_spec, solver_settings, check_scene, is_halfspace, not_set, material_of, &
      & static_contact_modulus, grid_of, kernel_of, is_areal, pressure_scale, companion_of
   public :: max_string, default_rms_gradient

   !> Sentinel for "not given" in optional positive quantities: a value nobody types, so
   !> that a wrong input such as rms_gradient = -1 is reported, not taken for "not given".
   real(wp), parameter :: not_set = -huge(1.0_wp)
   !> rms gradient of a self-affine profile when neither rms_gradient nor rms_height is given
   !> (under linear elasticity the scale only matters relative to the pressure).
   real(wp), parameter :: default_rms_gradient = 0.1_wp
   !> +Inf (the bits of IEEE double +Inf): the thickness of a half-space.
   real(wp), parameter :: half_space = transfer(int(z'7FF0000000000000', i8), 1.0_wp)
   !> Length of the fixed-size character components (file names, keywords).
   integer, parameter :: max_string = 512

   !> Rigid indenter profile: how it is made (kind = self_affine | sinusoid | sphere | file).
   type :: profile_spec
      character(len=max_string) :: kind = 'self_affine'
      !> self_affine: Hurst exponent, seed, roll-off and shortest wavelengths (L)
      real(wp) :: hurst = 0.8_wp
      integer(i8) :: seed = 1_i8
      real(wp) :: rolloff_wavelength = not_set   !< default: the period
      real(wp) :: short_wavelength = not_set     !< default: period/128
      !> scale: give at most one of rms_gradient (-) and rms_height (L); default rms_gradient 0.1
      real(wp) :: rms_gradient = not_set
      real(wp) :: rms_height = not_set
      !> sinusoid r(x) = amplitude cos(2 pi mode x / period); on a surface
      !> r(x, y) = amplitude cos(2 pi (mode x/period + mode_y y/period_y))
      real(wp) :: amplitude = not_set
      integer :: mode = 1
      integer :: mode_y = 0
      !> sphere (areal): a spherical cap of this radius (L), its apex at the cell's centre
      real(wp) :: radius = not_set
      !> file: heights (L) from an HDF5 file (dataset below), a .npy file, or a text file
      !> (whitespace-separated; a surface: one row of nx heights per line, ny lines; a line
      !> profile: one row or one column), fitted to the grid by lc_profiles_measured
      character(len=max_string) :: file = ''
      character(len=max_string) :: dataset = '/profile/height'
      !> file: auto | none | mean | plane | curvature (auto: none if periodic, plane if mirrored)
      character(len=max_string) :: detrend = 'auto'
      !> file: periodic (the file is one period) | mirror (the patch and its mirror image)
      character(len=max_string) :: boundary = 'periodic'
      !> file: none (the file has the grid's size) | fourier (Fourier interpolation/truncation)
      character(len=max_string) :: resample = 'none'
   end type profile_spec

   !> Solver choice and stopping rule.
   type :: solver_settings
      !> auto | cg | gcr | anderson | gfmd: auto picks cg for symmetric operators, gcr
      !> otherwise (going on with anderson if gcr stalls); gfmd: damped dynamics (FIRE)
      character(len=max_string) :: method = 'auto'
      !> tolerance on the dimensionless complementarity residual
      real(wp) :: tol = 1.0e-10_wp
      integer :: max_iter = 100000
      !> Anderson memory (number of previous iterates mixed) for coupled problems
      integer :: memory = 12
      !> precondition the constrained CG with the stiffness 1/M (Fourier) on the contact set:
      !> one more FFT pair per iteration, far fewer iterations on fine grids (docs/numerics.md,
      !> 'Symmetric problems'; bench/iterations.py)
      logical :: precondition = .true.
      !> start from the solution on the grid of every second point (recursively): the
      !> contact set is then nearly known and the fine-grid iterations few
      logical :: coarse_start = .true.
      !> threads of one solve; 0: what the job was given (lc_base_threads)
      integer :: threads = 0
      !> progress on standard error: a line per grid level and every 2 s within one
      logical :: verbose = .false.
      !> target error of the observables: when set, &scene n and tol are chosen by the
      !> accuracy rule (lc_application_accuracy)
      real(wp) :: target_error = not_set
   end type solver_settings

   !> One contact problem.
   type :: scene_type
      character(len=max_string) :: geometry = 'line'
      character(len=max_string) :: title = ''
      real(wp) :: period = 1.0_wp          !< lambda (L), along x (the sliding direction)
      integer :: n = 4096                  !< grid points per period along x
      !> areal geometry: grid points and period along y (period_y not_set: = period)
      integer :: ny = 1
      real(wp) :: period_y = not_set
      !> &scene n, nx or ny given: without them a profile file sets the grid (its size)
      logical :: grid_given = .false.
      real(wp) :: thickness = half_space   !< h (L); +Inf = half-space (the default: no length scale)
      real(wp) :: young = 1.0_wp           !< E (S)
      real(wp) :: poisson = 0.5_wp         !< nu
      !> material law (elastic: young; sls, prony: see lc_greens_viscoelastic) and the
      !> sliding speed V (L/T) that sets the frequency k V of each mode
      type(material_law) :: material
      real(wp) :: speed = 0.0_wp
      character(len=max_string) :: prony_file = ''   !< two columns: tau_i, value_i
      real(wp) :: friction = 0.0_wp        !< Coulomb coefficient mu_c
      logical :: companion = .false.       !< also solve the frictionless companion
      type(profile_spec) :: profile
      character(len=max_string) :: control = 'load'   !< load | displacement
      real(wp) :: mean_pressure = not_set       !< p_m (S)
      real(wp) :: normalised_pressure = not_set !< p_m/(E* Lambda/lambda), the seed's scale
      real(wp) :: penetration = not_set         !< Delta (L), displacement control
      type(solver_settings) :: solver
      character(len=max_string) :: output_file = 'layercontact.h5'
      logical :: overwrite = .false.
      logical :: stress = .true.      !< compute u_x, tau and the surface stress sigma_xx
      integer :: gap_bins = 64        !< bins of the gap histogram (0: none)
      !> write the maps (the profile and the solution fields) to the result file; without
      !> them a result holds the scalars, histograms, spots and patches (sweeps of large grids)
      logical :: fields = .true.
      !> areal scenes: the Reynolds leakage of the gap (k_eff along x and y, lc_leakage_reynolds)
      logical :: leakage = .false.
      real(wp) :: leakage_tol = 1.0e-6_wp !< relative accuracy of k_eff
   end type scene_type

contains

   !> True when the layer is a half-space (thickness = +Inf).
   pure logical function is_halfspace(scene)
      type(scene_type), intent(in) :: scene
      is_halfspace = .not. ieee_is_finite(scene%thickness) .and. .not. ieee_is_nan(scene%thickness)
   end function is_halfspace

   !> True for an areal (surface) contact.
   pure logical function is_areal(scene)
      type(scene_type), intent(in) :: scene
      is_areal = trim(scene%geometry) == 'areal'
   end function is_areal

   !> The scene's grid: a line of n points, or a surface of n x ny points.
   pure function grid_of(scene) result(grid)
      type(scene_type), intent(in) :: scene
      type(grid_type) :: grid
      if (is_areal(scene)) then
         grid = surface_grid(scene%n, scene%ny, scene%period, merge(scene%period_y, scene%period, &
            & scene%period_y /= not_set))
      else
         grid = line_grid(scene%n, scene%period)
      end if
   end function grid_of

   !> The scene's layer kernel (lc_greens_kernel).
   function kernel_of(scene) result(kernel)
      type(scene_type), intent(in) :: scene
      type(layer_kernel) :: kernel
      kernel = make_kernel(scene%thickness, material_of(scene), scene%poisson, scene%speed)
   end function kernel_of

   !> The scene's material law (an elastic law takes &layer young).
   pure function material_of(scene) result(law)
      type(scene_type), intent(in) :: scene
      type(material_law) :: law
      law = scene%material
      law%young = scene%young
   end function material_of

   !> E* = E/(1 - nu^2) with the static (V -> 0) modulus: the seed's pressure scale (S).
   real(wp) function static_contact_modulus(scene)
      type(scene_type), intent(in) :: scene
      static_contact_modulus = static_modulus(material_of(scene))/(1.0_wp - scene%poisson**2)
   end function static_contact_modulus

   !> The seed's pressure scale (S): E* Lambda0/lambda for line contacts and for an areal
   !> contact on a half-space (Lambda0 = max r - mean r, the highest summit above the mean
   !> plane), E* h/lambda for an areal contact on a layer; E* with the static modulus,
   !> lambda the period along x.
   real(wp) function pressure_scale(scene, height)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      real(wp) :: lambda0
      if (is_areal(scene) .and. .not. is_halfspace(scene)) then
         pressure_scale = static_contact_modulus(scene)*scene%thickness/scene%period
      else
         lambda0 = maxval(height) - sum(height)/size(height)
         pressure_scale = static_contact_modulus(scene)*lambda0/scene%period
      end if
   end function pressure_scale

   !> The frictionless companion of a scene: a/a0 compares contact areas at the same load,
   !> the scene's own under load control and otherwise the `mean_pressure` its solve found.
   !> (The friction coefficient is passed to the solve, zero for the companion.)
   pure function companion_of(scene, mean_pressure) result(companion)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: mean_pressure
      type(scene_type) :: companion
      companion = scene
      if (trim(scene%control) == 'load') return
      companion%control = 'load'
      companion%mean_pressure = mean_pressure
      companion%normalised_pressure = not_set
      companion%penetration = not_set
   end function companion_of

   !> Validate a scene; the message names the namelist group, the variable, the value
   !> and the allowed range.
   subroutine check_scene(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error

      call check_ranges(scene, error)
      if (allocated(error)) return
      ! a file name holds no control character: a newline would be read back as another name
      ! (or another line of a job script)
      if (has_control(scene%output_file)) then
         call input_error(error, 'output', 'file', 'a name with a control character', &
            & 'a file name without control characters (newline, tab, ...)')
         return
      else if (has_control(scene%profile%file)) then
         call input_error(error, 'profile', 'file', 'a name with a control character', &
            & 'a file name without control characters (newline, tab, ...)')
         return
      end if
      associate (p => scene%profile, s => scene%solver)
         if (.not. is_areal(scene) .and. (scene%n < 8 .or. scene%n > 2**26)) then
            call input_error(error, 'scene', 'n', to_string(scene%n), '8 <= n <= 2**26')
         else if (.not. is_areal(scene) .and. scene%ny /= 1) then
            call input_error(error, 'scene', 'ny', to_string(scene%ny), "1 with geometry = 'line'")
         else if (is_areal(scene) .and. (scene%n < 4 .or. scene%n > 2**16)) then
            call input_error(error, 'scene', 'nx (or n)', to_string(scene%n), "4 <= nx <= 65536 with geometry = 'areal'")
         else if (is_areal(scene) .and. (scene%ny < 4 .or. scene%ny > 2**16)) then
            call input_error(error, 'scene', 'ny (or n)', to_string(scene%ny), "4 <= ny <= 65536 with geometry = 'areal'")
         else if (is_areal(scene) .and. int(scene%n, i8)*scene%ny > 2_i8**28) then
            call input_error(error, 'scene', 'nx*ny', to_string(int(scene%n, i8)*scene%ny), &
               & '<= 2**28 (16384 x 16384) grid points')
         else if (.not. is_areal(scene) .and. .not. one_of(p%kind, [character(len=16) :: 'self_affine', 'sinusoid', &
            & 'file'])) then
            call input_error(error, 'profile', 'kind', trim(p%kind), "'self_affine', 'sinusoid' or 'file'")
         else if (is_areal(scene) .and. .not. one_of(p%kind, [character(len=16) :: 'self_affine', 'sinusoid', &
            & 'sphere', 'file'])) then
            call input_error(error, 'profile', 'kind', trim(p%kind), "'self_affine', 'sinusoid', 'sphere' or 'file'")
         end if
         if (allocated(error)) return
         call check_material(scene%material, error)
         if (allocated(error)) return
         if (.not. is_viscoelastic(scene%material) .and. scene%speed /= 0.0_wp) then
            call input_error(error, 'material', 'speed', to_string(scene%speed), &
               & "0 with model = 'elastic' (an elastic layer does not depend on the speed)")
            return
         end if

         select case (trim(p%kind))
         case ('self_affine')
            if (.not. (p%hurst > 0.0_wp .and. p%hurst < 1.0_wp)) then
               call input_error(error, 'profile', 'hurst', to_string(p%hurst), '0 < hurst < 1')
            else if (p%seed < 0_i8) then
               call input_error(error, 'profile', 'seed', to_string(p%seed), '>= 0')
            else if (.not. is_areal(scene) .and. p%rolloff_wavelength /= not_set .and. &
               & .not. (positive_finite(p%rolloff_wavelength) .and. p%rolloff_wavelength <= scene%period)) then
               call input_error(error, 'profile', 'rolloff_wavelength', to_string(p%rolloff_wavelength), &
                  & '0 < rolloff_wavelength <= period')
            else if (.not. is_areal(scene) .and. p%short_wavelength /= not_set .and. &
               & .not. (p%short_wavelength >= 2*scene%period/scene%n .and. p%short_wavelength <= scene%period)) then
               call input_error(error, 'profile', 'short_wavelength', to_string(p%short_wavelength), &
                  & '2*period/n <= short_wavelength <= period (at least two grid points per wavelength)')
            else if (is_areal(scene) .and. p%rolloff_wavelength /= not_set .and. &
               & .not. (positive_finite(p%rolloff_wavelength) .and. p%rolloff_wavelength <= max(scene%period, &
               & scene%period_y))) then
               call input_error(error, 'profile', 'rolloff_wavelength', to_string(p%rolloff_wavelength), &
                  & '0 < rolloff_wavelength <= max(period, period_y)')
            else if (is_areal(scene) .and. p%short_wavelength /= not_set .and. &
               & .not. (p%short_wavelength >= 2*max(scene%period/scene%n, merge(scene%period_y, scene%period, &
               & scene%period_y /= not_set)/scene%ny) .and. p%short_wavelength <= max(scene%period, scene%period_y))) then
               ! along both axes at least two grid points per wavelength, as on a line
               call input_error(error, 'profile', 'short_wavelength', to_string(p%short_wavelength), &
                  & '2*max(period/nx, period_y/ny) <= short_wavelength <= max(period, period_y)')
            else if (p%rms_gradient /= not_set .and. p%rms_height /= not_set) then
               call input_error(error, 'profile', 'rms_gradient/rms_height', 'both given', 'at most one of them')
            else if (p%rms_gradient /= not_set .and. .not. positive_finite(p%rms_gradient)) then
               call input_error(error, 'profile', 'rms_gradient', to_string(p%rms_gradient), '> 0 and finite')
            else if (p%rms_height /= not_set .and. .not. positive_finite(p%rms_height)) then
               call input_error(error, 'profile', 'rms_height', to_string(p%rms_height), '> 0 and finite')
            end if
         case ('sinusoid')
            if (.not. positive_finite(p%amplitude)) then
               call input_error(error, 'profile', 'amplitude', to_string(p%amplitude), '> 0 and finite')
            else if (.not. is_areal(scene) .and. (p%mode < 1 .or. p%mode > (scene%n - 1)/2)) then
               call input_error(error, 'profile', 'mode', to_string(p%mode), '1 <= mode <= (n-1)/2')
            else if (is_areal(scene) .and. (p%mode < 0 .or. p%mode > (scene%n - 1)/2)) then
               ! a surface's modes stay below the grid's Nyquist limits, as a line's
               call input_error(error, 'profile', 'mode', to_string(p%mode), '0 <= mode <= (nx-1)/2')
            else if (is_areal(scene) .and. abs(p%mode_y) > (scene%ny - 1)/2) then
               call input_error(error, 'profile', 'mode_y', to_string(p%mode_y), '|mode_y| <= (ny-1)/2')
            else if (is_areal(scene) .and. p%mode == 0 .and. p%mode_y == 0) then
               call input_error(error, 'profile', 'mode/mode_y', '0/0', 'not both zero (a flat surface)')
            end if
         case ('sphere')
            if (.not. positive_finite(p%radius)) then
               call input_error(error, 'profile', 'radius', to_string(p%radius), '> 0 and finite')
            end if
         case ('file')
            if (len_trim(p%file) == 0) then
               call input_error(error, 'profile', 'file', "''", &
                  & 'the name of a file holding the heights (.h5/.hdf5, .npy or text)')
            else
               call check_treatments(p%detrend, p%boundary, p%resample, error)
            end if
         end select
         if (allocated(error)) return
         ! the treatment of measured heights means nothing for a generated profile
         if (trim(p%kind) /= 'file') then
            if (trim(p%detrend) /= 'auto') then
               call input_error(error, 'profile', 'detrend', "'" // trim(p%detrend) // "'", &
                  & "not set unless kind = 'file'")
            else if (trim(p%boundary) /= 'periodic') then
               call input_error(error, 'profile', 'boundary', "'" // trim(p%boundary) // "'", &
                  & "not set unless kind = 'file'")
            else if (trim(p%resample) /= 'none') then
               call input_error(error, 'profile', 'resample', "'" // trim(p%resample) // "'", &
                  & "not set unless kind = 'file'")
            end if
            if (allocated(error)) return
         end if

         if (trim(scene%control) == 'load' .and. &
            & count([scene%mean_pressure /= not_set, scene%normalised_pressure /= not_set]) /= 1) then
            call input_error(error, 'loading', 'mean_pressure/normalised_pressure', 'both or neither given', &
               & "exactly one of them with control = 'load'")
         else if (trim(scene%control) == 'load' .and. scene%mean_pressure /= not_set &
            & .and. .not. positive_finite(scene%mean_pressure)) then
            call input_error(error, 'loading', 'mean_pressure', to_string(scene%mean_pressure), '> 0 and finite')
         else if (trim(scene%control) == 'load' .and. scene%normalised_pressure /= not_set &
            & .and. .not. positive_finite(scene%normalised_pressure)) then
            call input_error(error, 'loading', 'normalised_pressure', to_string(scene%normalised_pressure), '> 0 and finite')
         else if (trim(scene%control) == 'load' .and. scene%penetration /= not_set) then
            call input_error(error, 'loading', 'penetration', to_string(scene%penetration), &
               & "not set with control = 'load' (the load fixes the penetration)")
         else if (trim(scene%control) == 'displacement' .and. &
            & (scene%mean_pressure /= not_set .or. scene%normalised_pressure /= not_set)) then
            call input_error(error, 'loading', 'mean_pressure/normalised_pressure', 'given', &
               & "neither with control = 'displacement' (the penetration fixes the load)")
         else if (trim(scene%control) == 'displacement' .and. .not. positive_finite(scene%penetration)) then
            call input_error(error, 'loading', 'penetration', to_string(scene%penetration), &
               & "> 0 and finite with control = 'displacement'")
         else if (scene%leakage .and. .not. is_areal(scene)) then
            call input_error(error, 'output', 'leakage', '.true.', &
               & ".false. with geometry = 'line' (the Reynolds leakage needs the gap of an areal contact)")
         else if (.not. leakage_tol_allowed(scene%leakage_tol)) then
            call input_error(error, 'output', 'leakage_tol', to_string(scene%leakage_tol), leakage_tol_range)
         end if
      end associate
   end subroutine check_scene


   !> The values every scene variable with a range or a list of words in the scene schema
   !> may take, whatever the other variables (the first one outside is reported).
   subroutine check_ranges(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      include 'scene_checks.inc'
   end subroutine check_ranges

   !> Whether `text` (trailing blanks aside) holds a control character.
   pure logical function has_control(text)
      character(len=*), intent(in) :: text
      integer :: i
      has_control = .false.
      do i = 1, len_trim(text)
         if (iachar(text(i:i)) < 32 .or. iachar(text(i:i)) == 127) has_control = .true.
      end do
   end function has_control

   pure logical function one_of(word, words)
      character(len=*), intent(in) :: word
      character(len=*), intent(in) :: words(:)
      integer :: i
      one_of = .false.
      do i = 1, size(words)
         if (trim(word) == trim(words(i))) one_of = .true.
      end do
   end function one_of



end module lc_scene
