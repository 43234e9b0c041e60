!> The only file f2py sees: thin py_* wrappers with plain, explicit-shape arguments.
!> Each builds the library's types from its arguments, calls one library routine, copies
!> the results out and maps an error to stat (the exit code it would have) and errmsg.
!> stat = 0 means success. A scene comes as namelist text (lc_application_scene_text), so that its
!> defaults, checks and messages are those of scene_type and a namelist file.

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
   use lc_base_errors, only: error_type, status_of
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
   do i = 1, n
      call layer_coefficients_lapack(kh(i), nu, one_minus_a(i), one_minus_b(i), c(i), error)
      if (allocated(error)) exit
   end do
   call status_of(error, stat, errmsg)
end subroutine py_layer_coefficients_lapack

!> Solve the scene that the namelist `text` describes (made from Python keywords: the
!> defaults, checks and messages of a namelist file) on the given heights (n = nx*ny, x
!> fastest); with &friction companion, the frictionless companion is run 2. `table` names
!> what each run returns (lc_application_scene_text): its scalars, the columns of fields(:, :, run) and
!> spots(:, :, run), and how many of the last residuals history(:, run) holds.
subroutine py_solve_scene(text, n, height, runs, n_fields, spot_capacity, spot_columns, capacity, fields, spots, &
      & history, table, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_application_scene_text, only: solve_scene_text
   implicit none (type, external)
   character(len=*), intent(in) :: text
   integer, intent(in) :: n, runs, n_fields, spot_capacity, spot_columns, capacity
   real(8), intent(in) :: height(n)
   real(8), intent(out) :: fields(n, n_fields, runs), spots(spot_capacity, spot_columns, runs), history(capacity, runs)
   character(len=16384), intent(out) :: table
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   call solve_scene_text(text, height, fields, spots, history, table, error)
   call status_of(error, stat, errmsg)
end subroutine py_solve_scene

!> The heights of the &profile of the scene in the namelist `text` (n = nx*ny values, x
!> fastest), made as a namelist run makes them.
subroutine py_make_profile(text, n, height, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_application_scene_text, only: profile_of_text
   implicit none (type, external)
   character(len=*), intent(in) :: text
   integer, intent(in) :: n
   real(8), intent(out) :: height(n)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   call profile_of_text(text, height, error)
   call status_of(error, stat, errmsg)
end subroutine py_make_profile

!> The library's limits and markers as `name = value` lines (lc_application_scene_text).
subroutine py_constants(table)
   use lc_application_scene_text, only: library_constants
   implicit none (type, external)
   character(len=1024), intent(out) :: table
   table = library_constants()
end subroutine py_constants

!> Prony terms from a two-column text file, read as &material prony_file reads it: the
!> first `count` of times and values (room for `capacity`).
subroutine py_read_prony_file(filename, capacity, times, values, count, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_io_namelist, only: read_prony_file
   implicit none (type, external)
   character(len=*), intent(in) :: filename
   integer, intent(in) :: capacity
   real(8), intent(out) :: times(capacity), values(capacity)
   integer, intent(out) :: count, stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   real(8), allocatable :: read_times(:), read_values(:)
   call read_prony_file(filename, read_times, read_values, error)
   count = min(size(read_times), capacity)
   times = 0
   values = 0
   times(:count) = read_times(:count)
   values(:count) = read_values(:count)
   call status_of(error, stat, errmsg)
end subroutine py_read_prony_file

!> Check a Prony series of `nt` times and `nv` values as &material checks it (form
!> 'relaxation' or 'creep', the number of terms, their signs and order); times and values
!> have room for one more than the larger count.
subroutine py_check_prony(form, equilibrium, nt, nv, capacity, times, values, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_greens_viscoelastic, only: material_law, check_material
   implicit none (type, external)
   character(len=*), intent(in) :: form
   integer, intent(in) :: nt, nv, capacity
   real(8), intent(in) :: equilibrium, times(capacity), values(capacity)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: capacity
   type(error_type), allocatable :: error
   call check_material(material_law(model='prony', form=form, equilibrium=equilibrium, times=times(:nt), &
      & values=values(:nv)), error)
   call status_of(error, stat, errmsg)
end subroutine py_check_prony

!> Run a namelist file exactly like the executable (HDF5 written, nothing printed unless
!> verbose = 1). converged: 0/1. communicator: the Fortran handle of an MPI communicator
!> whose ranks share the scene (mpi4py's comm.py2f()), or -1 for the launcher's job.
subroutine py_run(input, verbose, communicator, output_file, converged, stat, errmsg)
   use, intrinsic :: iso_fortran_env, only: output_unit
   use lc_base_errors, only: error_type, status_of
   use lc_application_run, only: run_scene_file
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(in) :: verbose, communicator
   character(len=1024), intent(out) :: output_file
   integer, intent(out) :: converged, stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   character(len=:), allocatable :: written
   logical :: ok
   output_file = ''
   if (communicator == -1) then
      call run_scene_file(input, merge(output_unit, -1, verbose == 1), written, ok, error)
   else
      call run_scene_file(input, merge(output_unit, -1, verbose == 1), written, ok, error, communicator)
   end if
   converged = merge(1, 0, ok)
   if (allocated(written)) output_file = written
   call status_of(error, stat, errmsg)
   flush (output_unit)
end subroutine py_run

!> The scene of the namelist `text` written back as a complete namelist (every variable of
!> the scene schema; lc_io_namelist's write_scene_namelist), or of the default scene of
!> `geometry` ('line' or 'areal') when `text` is blank.
subroutine py_scene_namelist(text, geometry, echo, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_scene, only: scene_type
   use lc_io_namelist, only: read_scene_text, write_scene_namelist, default_scene
   implicit none (type, external)
   character(len=*), intent(in) :: text, geometry
   character(len=65536), intent(out) :: echo
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   character(len=:), allocatable :: written
   echo = ''
   if (len_trim(text) == 0) then
      scene = default_scene(geometry)
   else
      call read_scene_text(text, 'keywords', scene, error)
   end if
   if (.not. allocated(error)) call write_scene_namelist(scene, written)
   if (allocated(written)) echo = written
   call status_of(error, stat, errmsg)
end subroutine py_scene_namelist

!> Read and validate a namelist file without solving (what the executable checks first).
subroutine py_check_scene_file(input, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_scene, only: scene_type
   use lc_io_namelist, only: read_scene
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   character(len=:), allocatable :: text
   call read_scene(input, scene, text, error)
   call status_of(error, stat, errmsg)
end subroutine py_check_scene_file

!> The grid (n, and ny: 1 on a line) and tolerance tol the accuracy rule picks for a scene
!> file with &solver target_error (runs the pilot solve; writes nothing).
subroutine py_choose_resolution(input, n, ny, tol, stat, errmsg)
   use lc_base_errors, only: error_type, fatal_error, code_input, status_of
   use lc_scene, only: scene_type, not_set
   use lc_io_namelist, only: read_scene
   use lc_application_accuracy, only: choose_resolution
   implicit none (type, external)
   character(len=*), intent(in) :: input
   integer, intent(out) :: n, ny
   real(8), intent(out) :: tol
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   character(len=:), allocatable :: text
   n = 0
   ny = 0
   tol = 0
   call read_scene(input, scene, text, error)
   if (.not. allocated(error) .and. scene%solver%target_error == not_set) &
      & call fatal_error(error, '&solver: target_error is not given in ' // input, code_input)
   if (.not. allocated(error)) call choose_resolution(scene, error)
   call status_of(error, stat, errmsg)
   if (allocated(error)) return
   n = scene%n
   ny = scene%ny
   tol = scene%solver%tol
end subroutine py_choose_resolution

!> In-plane surface displacements and stresses (fields(:, 1:5): u_x, u_y, sigma_xx,
!> sigma_yy, sigma_xy) of the layer of the scene in the namelist `text` under a prescribed
!> pressure p (n = nx*ny values, x fastest) and the shear friction*p along x (no contact
!> solve; a line has u_x and sigma_xx only).
subroutine py_surface_stress(text, n, p, fields, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_application_scene_text, only: surface_stress_of_text
   implicit none (type, external)
   character(len=*), intent(in) :: text
   integer, intent(in) :: n
   real(8), intent(in) :: p(n)
   real(8), intent(out) :: fields(n, 5)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   call surface_stress_of_text(text, p, fields, error)
   call status_of(error, stat, errmsg)
end subroutine py_surface_stress

!> J*(k) of seed Eq. (14) at omega = k V for the material law of the &layer and &material
!> groups of the namelist `text`.
subroutine py_creep_compliance(text, nw, omega, compliance, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_greens_viscoelastic, only: material_law, creep_compliance
   use lc_application_scene_text, only: material_of_text
   implicit none (type, external)
   character(len=*), intent(in) :: text
   integer, intent(in) :: nw
   real(8), intent(in) :: omega(nw)
   complex(8), intent(out) :: compliance(nw)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: nw
   type(error_type), allocatable :: error
   type(material_law) :: law
   compliance = 0
   call material_of_text(text, law, error)
   if (.not. allocated(error)) compliance = creep_compliance(law, omega)
   call status_of(error, stat, errmsg)
end subroutine py_creep_compliance

!> Seconds per FFTW r2c + c2r pair of size n (the cost unit of the benchmarks), the best
!> of `rounds` timings of `repeats` pairs each.
subroutine py_fft_pair_seconds(n, repeats, rounds, seconds, stat, errmsg)
   use, intrinsic :: iso_fortran_env, only: int64
   use lc_base_errors, only: error_type, status_of
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
   call fft%init(n, 1, 1, error)
   call status_of(error, stat, errmsg)
   if (allocated(error)) return
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

!> Seconds of one unscaled r2c + c2r pair of an nx x ny grid (ny = 1: a line) on `threads`
!> threads, as a solve's operator runs it (the best of `rounds` means of `repeats` pairs).
subroutine py_grid_fft_pair_seconds(nx, ny, threads, repeats, rounds, seconds, stat, errmsg)
   use, intrinsic :: iso_fortran_env, only: int64
   use lc_base_errors, only: error_type, status_of
   use lc_base_threads, only: solve_threads, use_threads
   use lc_fft_plans, only: fft_plan
   implicit none (type, external)
   integer, intent(in) :: nx, ny, threads, repeats, rounds
   real(8), intent(out) :: seconds
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   type(fft_plan) :: fft
   integer(int64) :: start, finish, rate
   integer :: i, r, used
   seconds = huge(1d0)
   call solve_threads(threads, used, error)
   if (.not. allocated(error)) then
      call use_threads(used)
      call fft%init(nx, ny, used, error)
   end if
   call status_of(error, stat, errmsg)
   if (allocated(error)) return
   call random_number(fft%real_buffer)
   do r = 1, rounds
      call system_clock(start, rate)
      do i = 1, repeats
         call fft%forward_unscaled()
         call fft%backward()
      end do
      call system_clock(finish)
      seconds = min(seconds, real(finish - start, 8)/rate/repeats)
   end do
end subroutine py_grid_fft_pair_seconds

!> What the build and the processor offer: level = 3 if the processor runs the x86-64-v3
!> build (AVX2, FMA), else 1; isa = the instruction set this extension was compiled for.
subroutine py_cpu_level(level, isa)
   use lc_cpu, only: cpu_level
   use lc_base_version, only: build_isa
   implicit none (type, external)
   integer, intent(out) :: level
   character(len=16), intent(out) :: isa
   level = cpu_level()
   isa = build_isa
end subroutine py_cpu_level

!> 1 if this build can share a surface among MPI ranks (MPI and FFTW-MPI found), else 0.
subroutine py_mpi_available(available)
   use lc_base_parallel, only: mpi_available
   implicit none (type, external)
   integer, intent(out) :: available
   available = merge(1, 0, mpi_available())
end subroutine py_mpi_available

!> The 3x3 surface compliance (lc_greens_kernel) of the layer of the scene in the namelist
!> `text` for the wavevectors (qx, qy): (u_x^, u_y^, w^) = tensor(i, :, :) (tau_x^, tau_y^, p^).
subroutine py_surface_tensor(text, n, qx, qy, tensor, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_application_scene_text, only: tensor_of_text
   implicit none (type, external)
   character(len=*), intent(in) :: text
   integer, intent(in) :: n
   real(8), intent(in) :: qx(n), qy(n)
   complex(8), intent(out) :: tensor(n, 3, 3)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   call tensor_of_text(text, qx, qy, tensor, error)
   call status_of(error, stat, errmsg)
end subroutine py_surface_tensor

!> A random isotropic self-affine surface (lc_profiles_surface), heights flat with x fastest
!> (numpy height.reshape(ny, nx)). Not-given lengths and targets are passed as -1.
subroutine py_self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff, short, rms_gradient, rms_height, height, &
      & stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_profiles_surface, only: self_affine_surface
   implicit none (type, external)
   integer, intent(in) :: nx, ny
   real(8), intent(in) :: lx, ly, hurst, rolloff, short, rms_gradient, rms_height
   integer(8), intent(in) :: seed
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   call self_affine_surface(nx, ny, lx, ly, hurst, seed, rolloff, short, rms_gradient, rms_height, height, error)
   call status_of(error, stat, errmsg)
end subroutine py_self_affine_surface

!> Sizes of the heights in a file (&profile file, dataset), read by the reader of
!> &profile kind = 'file' (lc_profiles_height_file): nx x ny with x fastest, (n, 1) for a
!> 1D array.
subroutine py_height_file_shape(filename, dataset, nx, ny, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_profiles_height_file, only: read_height_file
   implicit none (type, external)
   character(len=*), intent(in) :: filename, dataset
   integer, intent(out) :: nx, ny
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   real(8), allocatable :: height(:, :)
   nx = 0
   ny = 0
   call read_height_file(filename, dataset, height, error)
   call status_of(error, stat, errmsg)
   if (allocated(error)) return
   nx = size(height, 1)
   ny = size(height, 2)
end subroutine py_height_file_shape

!> Heights of a file on a scene's grid (lc_profiles_measured: the shape rule, detrend,
!> boundary, resample), as &profile kind = 'file' makes them; areal = 0: a line of nx
!> points (ny = 1).
subroutine py_measured_heights(filename, dataset, areal, detrend, boundary, resample, nx, ny, height, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_profiles_measured, only: measured_heights
   implicit none (type, external)
   character(len=*), intent(in) :: filename, dataset, detrend, boundary, resample
   integer, intent(in) :: areal, nx, ny
   real(8), intent(out) :: height(nx*ny)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   type(error_type), allocatable :: error
   call measured_heights(filename, dataset, areal /= 0, detrend, boundary, resample, nx, ny, height, error)
   call status_of(error, stat, errmsg)
end subroutine py_measured_heights

!> Detrend, boundary and resample (lc_profiles_measured) of heights raw (mx x n/mx, x
!> fastest) onto an nx x ny grid; areal = 0: a line (ny = 1).
subroutine py_prepare_heights(n, raw, mx, areal, detrend, boundary, resample, nx, ny, height, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
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
   height = 0
   call prepare_heights(reshape(raw, [mx, n/mx]), areal /= 0, detrend, boundary, resample, nx, ny, height, error)
   call status_of(error, stat, errmsg)
end subroutine py_prepare_heights

!> Reynolds leakage of a gap (nx*ny, x fastest) by the core: k_eff along x and y and the
!> diagnostics (lc_leakage_reynolds). closed(j) /= 0 marks contact. values = [k_eff_x,
!> k_eff_y, connected_fraction_x, connected_fraction_y, fluid_fraction, residual_x,
!> residual_y, wall_time]; counts = [percolating_x, percolating_y,
!> iterations_x, iterations_y, unknowns_x, unknowns_y, converged_x, converged_y].
subroutine py_reynolds_leakage(n, gap, closed, nx, lx, ly, tol, max_iter, values, counts, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
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
   values = 0
   counts = 0
   call reynolds_leakage(gap, closed /= 0, nx, n/nx, lx, ly, tol, max_iter, res, error)
   call status_of(error, stat, errmsg)
   if (allocated(error)) return
   values = [res%x%k_eff, res%y%k_eff, res%x%connected_fraction, res%y%connected_fraction, &
      & res%fluid_fraction, res%x%residual, res%y%residual, res%wall_time]
   counts = [merge(1, 0, res%x%percolating), merge(1, 0, res%y%percolating), res%x%iterations, &
      & res%y%iterations, res%x%unknowns, res%y%unknowns, merge(1, 0, res%x%converged), merge(1, 0, res%y%converged)]
end subroutine py_reynolds_leakage

!> The conductance per unit nominal area and per unit conductivity (1/L) of the prescribed
!> contact map `contact` (1 in contact, 0 elsewhere; nx*ny values, x fastest; ny = 1: a
!> line of period lx) on a layer of `thickness` on a perfectly conducting base (Inf: a
!> half-space) (lc_observables_conductance).
subroutine py_contact_conductance(n, nx, ny, lx, ly, contact, thickness, tol, max_iter, conductance, iterations, &
   & converged, stat, errmsg)
   use lc_base_errors, only: error_type, status_of
   use lc_base_grid, only: grid_type, line_grid, surface_grid
   use lc_observables_conductance, only: contact_conductance, masked_outcome
   implicit none (type, external)
   integer, intent(in) :: n, nx, ny, max_iter
   real(8), intent(in) :: lx, ly, thickness, tol
   integer(1), intent(in) :: contact(n)
   real(8), intent(out) :: conductance
   integer, intent(out) :: iterations, converged, stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   type(grid_type) :: grid
   type(masked_outcome) :: outcome
   if (ny == 1) then
      grid = line_grid(nx, lx)
   else
      grid = surface_grid(nx, ny, lx, ly)
   end if
   call contact_conductance(grid, contact /= 0, thickness, tol, max_iter, 1, conductance, outcome, error)
   iterations = outcome%iterations
   converged = merge(1, 0, outcome%converged)
   call status_of(error, stat, errmsg)
end subroutine py_contact_conductance
