!> The only file f2py sees: thin py_* wrappers with plain, explicit-shape arguments.
!> Each builds the library's types from its arguments, calls one library routine, copies
!> the results out and maps an error to stat (the exit code it would have) and errmsg.
!> stat = 0 means success.

!> 1-A, 1-B and c (convention P) for kh = |k| h, closed forms.
subroutine py_layer_coefficients(n, kh, nu, one_minus_a, one_minus_b, c)
   use lc_greens_layer, only: layer_coefficients
   implicit none (type, external)
   integer, intent(in) :: n
   real(8), intent(in) :: kh(n), nu
   real(8), intent(out) :: one_minus_a(n), one_minus_b(n), c(n)
   !f2py intent(hide) :: n
   call layer_coefficients(kh, nu, one_minus_a, one_minus_b, c)
end subroutine py_layer_coefficients

!> The same from the 4x4 plane-strain mode problem solved with LAPACK.
subroutine py_layer_coefficients_lapack(n, kh, nu, one_minus_a, one_minus_b, c, stat, errmsg)
   use lc_errors, only: error_type
   use lc_greens_layer, only: layer_coefficients_lapack
   implicit none (type, external)
   integer, intent(in) :: n
   real(8), intent(in) :: kh(n), nu
   real(8), intent(out) :: one_minus_a(n), one_minus_b(n), c(n)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   integer :: i
   stat = 0
   errmsg = ''
   do i = 1, n
      call layer_coefficients_lapack(kh(i), nu, one_minus_a(i), one_minus_b(i), c(i), error)
      if (allocated(error)) then
         stat = error%code
         errmsg = error%message
         return
      end if
   end do
end subroutine py_layer_coefficients_lapack

!> Seeded self-affine line profile (lengths as given; -huge = not set: layercontact.api.NOT_SET).
subroutine py_self_affine_profile(n, period, hurst, seed, rolloff_wavelength, short_wavelength, rms_gradient, &
      & rms_height, height, stat, errmsg)
   use lc_errors, only: error_type
   use lc_profiles_self_affine, only: self_affine_profile
   implicit none (type, external)
   integer, intent(in) :: n
   real(8), intent(in) :: period, hurst, rolloff_wavelength, short_wavelength, rms_gradient, rms_height
   integer(8), intent(in) :: seed
   real(8), intent(out) :: height(n)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   stat = 0
   errmsg = ''
   call self_affine_profile(n, period, hurst, seed, rolloff_wavelength, short_wavelength, rms_gradient, &
      & rms_height, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_self_affine_profile

!> Solve a contact on the given heights: a line (areal = 0; n heights) or a surface
!> (areal = 1; n = nx*ny heights, x fastest, period_y its period along y). control: 0 load,
!> 1 displacement; method: 0 auto, 1 cg, 2 anderson, 3 gcr, 4 gfmd; precondition, coarse_start,
!> verbose (progress lines on standard error), stress: 0/1.
!> fields(:, 1:n_fields): pressure, gap, displacement_z, then with stress = 1 (n_fields = 5
!> for a line, 8 for a surface) displacement_x, stress_xx (line) or displacement_x,
!> displacement_y, stress_xx, stress_yy, stress_xy (surface);
!> spots(1:n_spots, 1:n_columns) of a line (capacity nx/2 + 1): trailing and leading edges,
!> largest sigma_xx around the spot (sub-grid at the trailing edge with friction), its
!> offset from the trailing edge and the largest grid value (the last three with stress);
!> of a surface (capacity n/2 + 1, n_columns = 2): area and perimeter of each patch;
!> scalars: in the order of layercontact.api._SCALARS (the solver that ran as its index in
!> `solvers`); history(1:history_length): the last
!> residuals of the run, at most `capacity` (an array of max_iter entries would cost more
!> than a small solve).
subroutine py_solve(n, height, nx, areal, period, period_y, thickness, young, poisson, friction, control, &
      & mean_pressure, penetration, method, precondition, coarse_start, verbose, tol, max_iter, memory, threads, stress, &
      & model, &
      & form, e0, e_inf, tau, equilibrium, nt, times, values, speed, capacity, n_fields, spot_capacity, n_columns, &
      & fields, spots, scalars, history, stat, errmsg)
   use lc_errors, only: error_type
   use lc_scene, only: scene_type, check_scene
   use lc_result, only: contact_result
   use lc_contact_solve, only: solve_contact
   use lc_greens_viscoelastic, only: make_material_law
   implicit none (type, external)
   integer, intent(in) :: n, nx, areal, control, method, precondition, coarse_start, verbose, max_iter, memory, threads
   integer, intent(in) :: stress
   integer, intent(in) :: model, form, nt, capacity, n_fields, spot_capacity, n_columns
   real(8), intent(in) :: height(n), period, period_y, thickness, young, poisson, friction, mean_pressure, penetration
   real(8), intent(in) :: tol, e0, e_inf, tau, equilibrium, times(nt), values(nt), speed
   real(8), intent(out) :: fields(n, n_fields), spots(spot_capacity, n_columns), scalars(34), history(capacity)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n, nt
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   type(contact_result) :: r
   character(len=12), parameter :: controls(0:1) = [character(len=12) :: 'load', 'displacement']
   integer :: stored
   character(len=8), parameter :: methods(0:4) = [character(len=8) :: 'auto', 'cg', 'anderson', 'gcr', 'gfmd']
   !> the solver that ran, as scalars(27) (layercontact.api._SOLVERS)
   character(len=16), parameter :: solvers(5) = [character(len=16) :: 'cg', 'gcr', 'anderson', 'gcr+anderson', 'gfmd']
   stat = 0
   errmsg = ''
   scene = scene_type(n=nx, ny=n/max(nx, 1), period=period, period_y=period_y, thickness=thickness, young=young, &
      & poisson=poisson, friction=friction, control=controls(max(0, min(1, control))), mean_pressure=mean_pressure, &
      & penetration=penetration, stress=stress == 1, gap_bins=0)
   if (areal == 1) scene%geometry = 'areal'
   scene%profile%kind = 'file'
   scene%profile%file = '(array from Python)'
   scene%material = make_material_law(model, form, young, e0, e_inf, tau, equilibrium, times, values)
   scene%speed = speed
   scene%solver%method = methods(max(0, min(4, method)))
   scene%solver%tol = tol
   scene%solver%max_iter = max_iter
   scene%solver%memory = memory
   scene%solver%threads = threads
   scene%solver%precondition = precondition == 1
   scene%solver%coarse_start = coarse_start == 1
   scene%solver%verbose = verbose == 1
   call check_scene(scene, error)
   if (.not. allocated(error)) call solve_contact(scene, height, friction, r, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   fields = 0
   fields(:, 1) = r%pressure
   fields(:, 2) = r%gap
   fields(:, 3) = r%displacement_z
   spots = 0
   if (allocated(r%patch_area)) then
      spots(1:r%n_spots, 1) = r%patch_area
      if (n_columns > 1) spots(1:r%n_spots, 2) = r%patch_perimeter
   else
      spots(1:r%n_spots, 1) = r%spot_trailing
      spots(1:r%n_spots, 2) = r%spot_leading
   end if
   if (allocated(r%stress_xx) .and. n_fields >= 5) then
      fields(:, 4) = r%displacement_x
      if (allocated(r%stress_yy) .and. n_fields >= 8) then
         fields(:, 5) = r%displacement_y
         fields(:, 6) = r%stress_xx
         fields(:, 7) = r%stress_yy
         fields(:, 8) = r%stress_xy
      else
         fields(:, 5) = r%stress_xx
      end if
   end if
   if (allocated(r%spot_max_tension) .and. n_columns >= 5) then
      spots(1:r%n_spots, 3) = r%spot_max_tension
      spots(1:r%n_spots, 4) = r%spot_tension_offset
      spots(1:r%n_spots, 5) = r%spot_max_tension_grid
   end if
   stored = min(size(r%residual_history), capacity)
   history(1:stored) = r%residual_history(size(r%residual_history) - stored + 1:)
   scalars = [r%mean_pressure, r%penetration, r%contact_fraction, r%delta_mu, r%delta_mu_spectral, &
      & r%delta_mu_energy, r%delta_mu_profile, merge(1.0d0, 0.0d0, r%converged), real(r%iterations, 8), &
      & real(r%outer_iterations, 8), real(r%fft_pairs, 8), r%residual, r%wall_time, &
      & real(stored, 8), real(r%n_spots, 8), r%contact_length, r%mean_gap, r%leak_rate, &
      & r%max_tension, r%max_tension_x, r%max_tension_offset, r%dissipated_power, merge(1d0, 0d0, r%monotone), &
      & r%pressure_shift, r%summit_shift, r%max_tension_grid, real(findloc(solvers, r%solver, dim=1), 8), &
      & r%normalised_pressure, r%normalised_thickness, r%max_tension_y, r%max_principal_stress, &
      & r%max_principal_x, r%max_principal_y, r%gap_resolution]
end subroutine py_solve

!> Run a namelist file exactly like the executable (HDF5 written, nothing printed unless
!> verbose = 1). converged: 0/1.
subroutine py_run(input, verbose, output_file, converged, stat, errmsg)
   use, intrinsic :: iso_fortran_env, only: output_unit
   use lc_errors, only: error_type
   use lc_run, only: run_scene_file
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(in) :: verbose
   character(len=1024), intent(out) :: output_file
   integer, intent(out) :: converged, stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   character(len=:), allocatable :: written
   logical :: ok
   stat = 0
   errmsg = ''
   output_file = ''
   call run_scene_file(input, merge(output_unit, -1, verbose == 1), written, ok, error)
   converged = merge(1, 0, ok)
   if (allocated(written)) output_file = written
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
   flush (output_unit)
end subroutine py_run

!> Read and validate a namelist file without solving (what the executable checks first).
subroutine py_check_scene_file(input, stat, errmsg)
   use lc_errors, only: error_type
   use lc_scene, only: scene_type
   use lc_io_namelist, only: read_scene
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   character(len=:), allocatable :: text
   stat = 0
   errmsg = ''
   call read_scene(input, scene, text, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_check_scene_file

!> The grid (n, and ny: 1 on a line) and tolerance tol the accuracy rule picks for a scene
!> file with &solver target_error (runs the pilot solve; writes nothing).
subroutine py_choose_resolution(input, n, ny, tol, stat, errmsg)
   use lc_errors, only: error_type, fatal_error, code_input
   use lc_scene, only: scene_type, not_set
   use lc_io_namelist, only: read_scene
   use lc_accuracy, only: choose_resolution
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(out) :: n, ny
   real(8), intent(out) :: tol
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   character(len=:), allocatable :: text
   stat = 0
   errmsg = ''
   n = 0
   ny = 0
   tol = 0
   call read_scene(input, scene, text, error)
   if (.not. allocated(error) .and. scene%solver%target_error == not_set) &
      & call fatal_error(error, '&solver: target_error is not given in ' // input, code_input)
   if (.not. allocated(error)) call choose_resolution(scene, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   n = scene%n
   ny = scene%ny
   tol = scene%solver%tol
end subroutine py_choose_resolution

!> Surface displacement u_x and stress sigma_xx for a prescribed pressure p (no contact
!> solve): tau = friction p on an elastic layer (thickness = Inf: half-space).
subroutine py_surface_fields(n, p, period, thickness, young, poisson, friction, displacement_x, stress_xx, &
      & stat, errmsg)
   use lc_errors, only: error_type
   use lc_greens_viscoelastic, only: material_law
   use lc_grid, only: line_grid
   use lc_greens_kernel, only: make_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_observables_surface, only: surface_fields
   implicit none (type, external)
   integer, intent(in) :: n
   real(8), intent(in) :: p(n), period, thickness, young, poisson, friction
   real(8), intent(out) :: displacement_x(n), stress_xx(n)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   type(compliance_operator) :: op
   stat = 0
   errmsg = ''
   call build_operator(op, line_grid(n, period), make_kernel(thickness, material_law(young=young), poisson, 0d0), &
      & friction, 1, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   call surface_fields(op, p, displacement_x, stress_xx)
end subroutine py_surface_fields

!> J*(k) of seed Eq. (14) at omega = k V for a material law (codes as in py_solve_line).
subroutine py_creep_compliance(nw, omega, model, form, young, e0, e_inf, tau, equilibrium, nt, times, values, &
      & compliance, stat, errmsg)
   use lc_errors, only: error_type
   use lc_greens_viscoelastic, only: material_law, make_material_law, check_material, creep_compliance
   implicit none (type, external)
   integer, intent(in) :: nw, model, form, nt
   real(8), intent(in) :: omega(nw), young, e0, e_inf, tau, equilibrium, times(nt), values(nt)
   complex(8), intent(out) :: compliance(nw)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: nw, nt
   type(error_type), allocatable :: error
   type(material_law) :: law
   stat = 0
   errmsg = ''
   compliance = 0
   law = make_material_law(model, form, young, e0, e_inf, tau, equilibrium, times, values)
   call check_material(law, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   compliance = creep_compliance(law, omega)
end subroutine py_creep_compliance

!> Seconds per FFTW r2c + c2r pair of size n (the cost unit of the benchmarks), the best
!> of `rounds` timings of `repeats` pairs each.
subroutine py_fft_pair_seconds(n, repeats, rounds, seconds, stat, errmsg)
   use, intrinsic :: iso_fortran_env, only: int64
   use lc_errors, only: error_type
   use lc_fft_plans, only: fft_plan
   implicit none (type, external)
   integer, intent(in) :: n, repeats, rounds
   real(8), intent(out) :: seconds
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(fft_plan) :: fft
   integer(int64) :: start, finish, rate
   integer :: i, r
   stat = 0
   errmsg = ''
   call fft%init(n, 1, 1, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   call random_number(fft%real_buffer)
   seconds = huge(1d0)
   do r = 1, rounds
      call system_clock(start, rate)
      do i = 1, repeats
         call fft%forward_unscaled()   ! the bare r2c + c2r pair (no scaling pass)
         call fft%backward()
      end do
      call system_clock(finish)
      seconds = min(seconds, real(finish - start, 8)/rate/repeats)
   end do
end subroutine py_fft_pair_seconds

!> What the build and the processor offer: level = 3 if the processor runs the x86-64-v3
!> build (AVX2, FMA), else 1; isa = the instruction set this extension was compiled for.
subroutine py_cpu_level(level, isa)
   use lc_cpu, only: cpu_level
   use lc_version, only: build_isa
   implicit none (type, external)
   integer, intent(out) :: level
   character(len=16), intent(out) :: isa
   level = cpu_level()
   isa = build_isa
end subroutine py_cpu_level

!> The layer's 3x3 surface compliance (lc_greens_kernel) for the wavevectors (qx, qy):
!> (u_x^, u_y^, w^) = tensor(i, :, :) (tau_x^, tau_y^, p^), an elastic layer of thickness
!> h (Inf: half-space).
subroutine py_surface_tensor(n, qx, qy, thickness, young, poisson, tensor)
   use lc_greens_viscoelastic, only: material_law
   use lc_greens_kernel, only: layer_kernel, make_kernel
   implicit none (type, external)
   integer, intent(in) :: n
   real(8), intent(in) :: qx(n), qy(n), thickness, young, poisson
   complex(8), intent(out) :: tensor(n, 3, 3)
   !f2py intent(hide) :: n
   type(layer_kernel) :: kernel
   integer :: i
   kernel = make_kernel(thickness, material_law(young=young), poisson, 0d0)
   do i = 1, n
      tensor(i, :, :) = kernel%tensor(qx(i), qy(i))
   end do
end subroutine py_surface_tensor

!> A random isotropic self-affine surface (lc_profiles_surface), heights flat with x fastest
!> (numpy height.reshape(ny, nx)). Not-given lengths and targets are passed as -1.
subroutine py_self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff, short, rms_gradient, rms_height, height, &
      & stat, errmsg)
   use lc_errors, only: error_type
   use lc_profiles_surface, only: self_affine_surface
   implicit none (type, external)
   integer, intent(in) :: nx, ny
   real(8), intent(in) :: lx, ly, hurst, rolloff, short, rms_gradient, rms_height
   integer(8), intent(in) :: seed
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   stat = 0
   errmsg = ''
   call self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff, short, rms_gradient, rms_height, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_self_affine_surface

!> The surface of an areal scene's &profile (kind = sinusoid | sphere | file) on an
!> nx x ny grid, made by make_profile exactly as a namelist run makes it; heights flat with
!> x fastest. Not-given amplitude and radius are passed as -1.
subroutine py_make_surface(profile_kind, nx, ny, lx, ly, amplitude, mode, mode_y, radius, filename, dataset, height, &
      & stat, errmsg)
   use lc_errors, only: error_type
   use lc_scene, only: scene_type
   use lc_profiles_profile, only: make_profile
   implicit none (type, external)
   character(len=*), intent(in) :: profile_kind, filename, dataset
   integer, intent(in) :: nx, ny, mode, mode_y
   real(8), intent(in) :: lx, ly, amplitude, radius
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   stat = 0
   errmsg = ''
   scene%geometry = 'areal'
   scene%n = nx
   scene%ny = ny
   scene%period = lx
   scene%period_y = ly
   scene%profile%kind = profile_kind
   scene%profile%amplitude = amplitude
   scene%profile%mode = mode
   scene%profile%mode_y = mode_y
   scene%profile%radius = radius
   scene%profile%file = filename
   scene%profile%dataset = dataset
   call make_profile(scene, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_make_surface

!> In-plane displacements and surface stresses of an elastic layer (thickness Inf: half-space)
!> under a prescribed pressure p on a surface (n = nx*ny values, x fastest) and the shear
!> friction*p along x (no contact solve). fields(:, 1:5): u_x, u_y, sigma_xx, sigma_yy,
!> sigma_xy.
subroutine py_surface_stress(n, p, nx, period, period_y, thickness, young, poisson, friction, fields, stat, errmsg)
   use lc_errors, only: error_type
   use lc_greens_viscoelastic, only: material_law
   use lc_grid, only: surface_grid
   use lc_greens_kernel, only: make_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_observables_stress, only: surface_stress
   implicit none (type, external)
   integer, intent(in) :: n, nx
   real(8), intent(in) :: p(n), period, period_y, thickness, young, poisson, friction
   real(8), intent(out) :: fields(n, 5)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   type(compliance_operator) :: op
   stat = 0
   errmsg = ''
   fields = 0
   call build_operator(op, surface_grid(nx, n/nx, period, period_y), &
      & make_kernel(thickness, material_law(young=young), poisson, 0d0), friction, 1, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   call surface_stress(op, p, fields(:, 1), fields(:, 2), fields(:, 3), fields(:, 4), fields(:, 5))
end subroutine py_surface_stress

!> Sizes of the heights in a file (&profile file, dataset), read by the reader of
!> &profile kind = 'file' (lc_profiles_height_file): nx x ny with x fastest, (n, 1) for a
!> 1D array.
subroutine py_height_file_shape(filename, dataset, nx, ny, stat, errmsg)
   use lc_errors, only: error_type
   use lc_profiles_height_file, only: read_height_file
   implicit none (type, external)
   character(len=*), intent(in) :: filename, dataset
   integer, intent(out) :: nx, ny
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   real(8), allocatable :: height(:, :)
   stat = 0
   errmsg = ''
   nx = 0
   ny = 0
   call read_height_file(filename, dataset, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   nx = size(height, 1)
   ny = size(height, 2)
end subroutine py_height_file_shape

!> The heights of a file as the reader of &profile kind = 'file' reads them, flat with x
!> fastest; nx x ny from py_height_file_shape (a file of another size now is an error).
subroutine py_read_height_file(filename, dataset, nx, ny, height, stat, errmsg)
   use lc_errors, only: error_type, fatal_error, code_io
   use lc_profiles_height_file, only: read_height_file, named
   implicit none (type, external)
   character(len=*), intent(in) :: filename, dataset
   integer, intent(in) :: nx, ny
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   real(8), allocatable :: read_back(:, :)
   stat = 0
   errmsg = ''
   height = 0
   call read_height_file(filename, dataset, read_back, error)
   if (.not. allocated(error)) then
      if (size(read_back, 1) /= nx .or. size(read_back, 2) /= ny) &
         & call fatal_error(error, named(filename) // ' changed while it was read', code_io)
   end if
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   height = reshape(read_back, [nx*ny])
end subroutine py_read_height_file

!> Heights of a file on a scene's grid (lc_profiles_measured: the shape rule, detrend,
!> boundary, resample), as &profile kind = 'file' makes them; areal = 0: a line of nx
!> points (ny = 1).
subroutine py_measured_heights(filename, dataset, areal, detrend, boundary, resample, nx, ny, height, stat, errmsg)
   use lc_errors, only: error_type
   use lc_profiles_measured, only: measured_heights
   implicit none (type, external)
   character(len=*), intent(in) :: filename, dataset, detrend, boundary, resample
   integer, intent(in) :: areal, nx, ny
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   stat = 0
   errmsg = ''
   call measured_heights(filename, dataset, areal /= 0, detrend, boundary, resample, nx, ny, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_measured_heights

!> Detrend, boundary and resample (lc_profiles_measured) of heights raw (mx x n/mx, x
!> fastest) onto an nx x ny grid; areal = 0: a line (ny = 1).
subroutine py_prepare_heights(n, raw, mx, areal, detrend, boundary, resample, nx, ny, height, stat, errmsg)
   use lc_errors, only: error_type
   use lc_profiles_measured, only: prepare_heights
   implicit none (type, external)
   integer, intent(in) :: n, mx, areal, nx, ny
   real(8), intent(in) :: raw(n)
   character(len=*), intent(in) :: detrend, boundary, resample
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   stat = 0
   errmsg = ''
   height = 0
   call prepare_heights(reshape(raw, [mx, n/mx]), areal /= 0, detrend, boundary, resample, nx, ny, height, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
   end if
end subroutine py_prepare_heights

!> Reynolds leakage of a gap (nx*ny, x fastest) by the core: k_eff along x and y and the
!> diagnostics (lc_leakage_reynolds). closed(j) /= 0 marks contact. values = [k_eff_x, k_eff_y, connected_fraction_x, connected_fraction_y,
!> fluid_fraction, residual_x, residual_y, wall_time]; counts = [percolating_x, percolating_y,
!> iterations_x, iterations_y, unknowns_x, unknowns_y, converged_x, converged_y].
subroutine py_reynolds_leakage(n, gap, closed, nx, lx, ly, tol, max_iter, values, counts, stat, errmsg)
   use lc_errors, only: error_type
   use lc_leakage_reynolds, only: leakage_result, reynolds_leakage
   implicit none (type, external)
   integer, intent(in) :: n, nx, max_iter
   real(8), intent(in) :: gap(n), lx, ly, tol
   integer, intent(in) :: closed(n)
   real(8), intent(out) :: values(8)
   integer, intent(out) :: counts(8)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   type(leakage_result) :: res
   stat = 0
   errmsg = ''
   values = 0
   counts = 0
   call reynolds_leakage(gap, closed /= 0, nx, n/nx, lx, ly, tol, max_iter, res, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   values = [res%x%k_eff, res%y%k_eff, res%x%connected_fraction, res%y%connected_fraction, &
      & res%fluid_fraction, res%x%residual, res%y%residual, res%wall_time]
   counts = [merge(1, 0, res%x%percolating), merge(1, 0, res%y%percolating), res%x%iterations, &
      & res%y%iterations, res%x%unknowns, res%y%unknowns, merge(1, 0, res%x%converged), merge(1, 0, res%y%converged)]
end subroutine py_reynolds_leakage
