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
   use lc_greens_kernel, only: layer_kernel, make_kernel, place_on
   use lc_greens_stack, only: stack_layer, stack_base, base_rigid, base_halfspace
   use lc_leakage_reynolds, only: leakage_tol_allowed, leakage_tol_range
   use lc_profiles_measured, only: check_treatments
   use lc_io_files, only: same_file
   implicit none (type, external)
   private
   public :: scene_type, profile_spec, solver_settings, check_scene, is_halfspace, not_set, material_of, &
      & static_contact_modulus, grid_of, kernel_of, is_areal, pressure_scale, companion_of, foundation
   public :: relief_pressure_scale
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
      !> GFMD's masses: auto | one (one mass for every node) | mode (a mass per mode on the
      !> free set; lc_contact_solver_gfmd)
      character(len=max_string) :: gfmd_mass = 'auto'
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
      !> What the layer rests on (a finite layer only; docs/theory.md, "Layered stacks"): the
      !> interface below it ('bonded' or 'slip'), elastic lower layers from the top down (each
      !> with the interface below it, one word per layer in lower_interfaces, '' all bonded),
      !> and an elastic half-space substrate, or a rigid base where substrate_young is not set
      !> (substrate_poisson not set: the layer's poisson).
      character(len=max_string) :: interface = 'bonded'
      real(wp), allocatable :: lower_thickness(:), lower_young(:), lower_poisson(:)
      !> viscoelastic lower layers: a standard linear solid where lower_tau > 0 (lower_young
      !> its low-frequency modulus, lower_e_inf its high-frequency one)
      real(wp), allocatable :: lower_tau(:), lower_e_inf(:)
      character(len=max_string) :: lower_interfaces = ''
      real(wp) :: substrate_young = not_set
      real(wp) :: substrate_poisson = not_set
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
      !> storage of the maps in the result file: 'double' (float64) or 'single' (float32)
      character(len=max_string) :: precision = 'double'
      !> areal scenes: the Reynolds leakage of the gap (k_eff along x and y, lc_leakage_reynolds)
      logical :: leakage = .false.
      real(wp) :: leakage_tol = 1.0e-6_wp !< relative accuracy of k_eff
      !> the contact's conductance and normal interfacial stiffness (lc_observables_conductance)
      logical :: conductance = .false.
      real(wp) :: conductivity = 1.0_wp   !< sigma of the layer (siemens/L)
      !> what lies under a layer: 'conducting' (a perfect conductor at the far potential)
      character(len=max_string) :: conductance_base = 'conducting'
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

   !> The scene's layer kernel (lc_greens_kernel), resting on its lower layers and substrate.
   function kernel_of(scene) result(kernel)
      type(scene_type), intent(in) :: scene
      type(layer_kernel) :: kernel
      type(stack_layer), allocatable :: lower(:)
      type(stack_base) :: base
      real(wp), allocatable :: tau(:), e_inf(:)
      kernel = make_kernel(scene%thickness, material_of(scene), scene%poisson, scene%speed)
      if (is_halfspace(scene)) return
      call lower_layers(scene, lower, tau, e_inf)
      if (scene%substrate_young /= not_set) then
         base = stack_base(kind=base_halfspace, young=cmplx(scene%substrate_young, 0.0_wp, wp), &
            & poisson=merge(scene%substrate_poisson, scene%poisson, scene%substrate_poisson /= not_set))
      else
         base = stack_base(kind=base_rigid)
      end if
      call place_on(kernel, trim(scene%interface) == 'slip', lower, base, tau, e_inf)
   end function kernel_of

   !> What a finite layer rests on, in words for the summary ('' for the usual rigid base
   !> bonded to it): the interface below it, the lower layers and the substrate.
   function foundation(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      integer :: n
      text = ''
      n = 0
      if (allocated(scene%lower_thickness)) n = size(scene%lower_thickness)
      if (is_halfspace(scene) .or. (trim(scene%interface) == 'bonded' .and. n == 0 .and. &
         & scene%substrate_young == not_set)) return
      text = trim(scene%interface)
      if (n > 0) text = text // ' on ' // to_string(n) // ' lower layer' // trim(merge('s', ' ', n > 1))
      if (scene%substrate_young /= not_set) then
         text = text // ' on a half-space, E_s = ' // to_string(scene%substrate_young) // ' (S)'
      else
         text = text // ' on a rigid base'
      end if
   end function foundation

   !> The scene's lower layers (none if it gives none); lower_poisson defaults to 0.5 each.
   pure subroutine lower_layers(scene, lower, tau, e_inf)
      type(scene_type), intent(in) :: scene
      type(stack_layer), allocatable, intent(out) :: lower(:)
      !> per lower layer: retardation time (0: elastic) and high-frequency modulus
      real(wp), allocatable, intent(out) :: tau(:), e_inf(:)
      character(len=8), allocatable :: words(:)
      integer :: i, n
      n = 0
      if (allocated(scene%lower_thickness)) n = size(scene%lower_thickness)
      allocate (lower(n), tau(n), e_inf(n))
      if (n == 0) return
      tau = 0.0_wp
      e_inf = scene%lower_young
      if (count_of(scene%lower_tau) == n) then
         tau = scene%lower_tau
         where (tau > 0.0_wp) e_inf = scene%lower_e_inf
      end if
      words = interface_words(scene%lower_interfaces)
      do i = 1, n
         lower(i)%thickness = scene%lower_thickness(i)
         lower(i)%young = cmplx(scene%lower_young(i), 0.0_wp, wp)
         lower(i)%poisson = 0.5_wp
         if (allocated(scene%lower_poisson)) then
            if (size(scene%lower_poisson) > 0) lower(i)%poisson = scene%lower_poisson(i)
         end if
         if (size(words) == n) lower(i)%slip_below = words(i) == 'slip'
      end do
   end subroutine lower_layers

   !> The words of a list separated by blanks or commas (each cut to 8 characters: a longer
   !> one is no interface word anyway).
   pure function interface_words(text) result(words)
      character(len=*), intent(in) :: text
      character(len=8), allocatable :: words(:)
      integer :: i, start
      allocate (words(0))
      start = 0
      do i = 1, len_trim(text) + 1
         if (i > len_trim(text)) then
            if (start > 0) words = [character(len=8) :: words, text(start:i - 1)]
         else if (text(i:i) == ' ' .or. text(i:i) == ',') then
            if (start > 0) words = [character(len=8) :: words, text(start:i - 1)]
            start = 0
         else if (start == 0) then
            start = i
         end if
      end do
   end function interface_words

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
      pressure_scale = relief_pressure_scale(scene, maxval(height) - sum(height)/size(height))
   end function pressure_scale

   !> pressure_scale from the relief Lambda0 = max r - mean r (L) of the whole profile (a
   !> surface shared among MPI ranks has it from the extremes and sums over the ranks).
   real(wp) function relief_pressure_scale(scene, lambda0)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: lambda0
      if (is_areal(scene) .and. .not. is_halfspace(scene)) then
         relief_pressure_scale = static_contact_modulus(scene)*scene%thickness/scene%period
      else
         relief_pressure_scale = static_contact_modulus(scene)*lambda0/scene%period
      end if
   end function relief_pressure_scale

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
         if (.not. (is_viscoelastic(scene%material) .or. any_positive(scene%lower_tau)) .and. &
            & scene%speed /= 0.0_wp) then
            call input_error(error, 'material', 'speed', to_string(scene%speed), &
               & "0 with model = 'elastic' and elastic lower layers (an elastic layer does not depend on the speed)")
            return
         end if
         call check_stack_below(scene, error)
         if (allocated(error)) return

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
            else if (same_file(trim(p%file), trim(scene%output_file))) then
               ! (through a symbolic link or `..` too: the result would replace the heights it
               ! is computed from)
               call input_error(error, 'output', 'file', "'" // trim(scene%output_file) // "'", &
                  & "another file than &profile file = '" // trim(p%file) // "' (they name one file)")
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
         else if (scene%conductance .and. trim(scene%conductance_base) == 'insulating') then
            call input_error(error, 'output', 'conductance_base', "'insulating'", &
               & "'conducting' (a layer on an insulating base carries no current from the contact to the far " // &
               & "potential: its conductance is zero; a half-space has no base)")
         end if
      end associate
   end subroutine check_scene


   !> What the layer rests on: only a finite layer rests on anything; one Young's modulus (and
   !> none or one Poisson's ratio, and none or one interface word) per lower layer, each in
   !> range; substrate_poisson with substrate_young.
   subroutine check_stack_below(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      character(len=8), allocatable :: words(:)
      integer :: n, i
      n = 0
      if (allocated(scene%lower_thickness)) n = size(scene%lower_thickness)
      if (is_halfspace(scene)) then
         if (trim(scene%interface) /= 'bonded') then
            call input_error(error, 'layer', 'interface', trim(scene%interface), &
               & "'bonded' with thickness = Inf (a half-space has nothing below it)")
         else if (n > 0) then
            call input_error(error, 'layer', 'lower_thickness', to_string(n) // ' layers', &
               & 'none with thickness = Inf (a half-space has nothing below it)')
         else if (scene%substrate_young /= not_set) then
            call input_error(error, 'layer', 'substrate_young', to_string(scene%substrate_young), &
               & 'not set with thickness = Inf (a half-space has nothing below it)')
         end if
         if (allocated(error)) return
      end if
      if (scene%substrate_poisson /= not_set .and. scene%substrate_young == not_set) then
         call input_error(error, 'layer', 'substrate_poisson', to_string(scene%substrate_poisson), &
            & 'not set without substrate_young (a rigid base has no Poisson ratio)')
         return
      end if
      if (count_of(scene%lower_young) /= n) then
         call input_error(error, 'layer', 'lower_young', to_string(count_of(scene%lower_young)) // ' values', &
            & 'one per lower layer: ' // to_string(n) // ' (as many as lower_thickness)')
         return
      end if
      if (count_of(scene%lower_poisson) /= 0 .and. count_of(scene%lower_poisson) /= n) then
         call input_error(error, 'layer', 'lower_poisson', to_string(count_of(scene%lower_poisson)) // ' values', &
            & 'none (0.5 each) or one per lower layer: ' // to_string(n))
         return
      end if
      do i = 1, n
         if (.not. positive_finite(scene%lower_thickness(i))) then
            call input_error(error, 'layer', 'lower_thickness(' // to_string(i) // ')', &
               & to_string(scene%lower_thickness(i)), '> 0 and finite')
         else if (.not. positive_finite(scene%lower_young(i))) then
            call input_error(error, 'layer', 'lower_young(' // to_string(i) // ')', to_string(scene%lower_young(i)), &
               & '> 0 and finite')
         else if (count_of(scene%lower_poisson) > 0) then
            if (.not. (scene%lower_poisson(i) > -1.0_wp .and. scene%lower_poisson(i) <= 0.5_wp)) &
               & call input_error(error, 'layer', 'lower_poisson(' // to_string(i) // ')', &
               & to_string(scene%lower_poisson(i)), '-1 < lower_poisson <= 0.5')
         end if
         if (allocated(error)) return
      end do
      if (count_of(scene%lower_tau) /= 0 .and. count_of(scene%lower_tau) /= n) then
         call input_error(error, 'layer', 'lower_tau', to_string(count_of(scene%lower_tau)) // ' values', &
            & 'none (elastic lower layers) or one per lower layer: ' // to_string(n))
         return
      end if
      if (count_of(scene%lower_e_inf) /= count_of(scene%lower_tau)) then
         call input_error(error, 'layer', 'lower_e_inf', to_string(count_of(scene%lower_e_inf)) // ' values', &
            & 'one per lower_tau value: ' // to_string(count_of(scene%lower_tau)))
         return
      end if
      do i = 1, count_of(scene%lower_tau)
         if (.not. (scene%lower_tau(i) >= 0.0_wp .and. ieee_is_finite(scene%lower_tau(i)))) then
            call input_error(error, 'layer', 'lower_tau(' // to_string(i) // ')', to_string(scene%lower_tau(i)), &
               & '>= 0 and finite (0: an elastic lower layer)')
         else if (scene%lower_tau(i) > 0.0_wp .and. .not. (scene%lower_e_inf(i) >= scene%lower_young(i) .and. &
            & ieee_is_finite(scene%lower_e_inf(i)))) then
            call input_error(error, 'layer', 'lower_e_inf(' // to_string(i) // ')', to_string(scene%lower_e_inf(i)), &
               & '>= lower_young(' // to_string(i) // ') = ' // to_string(scene%lower_young(i)) // &
               & ' and finite (the glassy modulus is the larger one)')
         end if
         if (allocated(error)) return
      end do
      words = interface_words(scene%lower_interfaces)
      if (size(words) /= 0 .and. size(words) /= n) then
         call input_error(error, 'layer', 'lower_interfaces', trim(scene%lower_interfaces), &
            & "'' (all bonded) or one word per lower layer: " // to_string(n))
         return
      end if
      do i = 1, size(words)
         if (words(i) /= 'bonded' .and. words(i) /= 'slip') then
            call input_error(error, 'layer', 'lower_interfaces', trim(scene%lower_interfaces), &
               & "words 'bonded' or 'slip', one per lower layer")
            return
         end if
      end do
   end subroutine check_stack_below

   !> Whether a list holds a positive value (a viscoelastic lower layer).
   pure logical function any_positive(values)
      real(wp), allocatable, intent(in) :: values(:)
      any_positive = .false.
      if (allocated(values)) any_positive = any(values > 0.0_wp)
   end function any_positive

   pure integer function count_of(values)
      real(wp), allocatable, intent(in) :: values(:)
      count_of = 0
      if (allocated(values)) count_of = size(values)
   end function count_of

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
