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

!> Seeded self-affine line profile (lengths as given; -1 = not set).
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

!> Solve a line contact on the given heights. control: 0 load, 1 displacement;
!> method: 0 auto, 1 cg, 2 anderson; precondition: 0/1. scalars: mean_pressure, penetration, contact_fraction,
!> delta_mu, delta_mu_spectral, delta_mu_energy, converged (0/1), iterations,
!> outer_iterations, fft_pairs, residual, wall_time, history length, delta_mu_profile.
subroutine py_solve_line(n, height, period, thickness, young, poisson, friction, control, mean_pressure, &
      & penetration, method, precondition, tol, max_iter, memory, threads, pressure, gap, displacement_z, scalars, history, &
      & stat, errmsg)
   use lc_errors, only: error_type
   use lc_scene, only: scene_type, check_scene
   use lc_result, only: contact_result
   use lc_contact_solve, only: solve_line_contact
   implicit none (type, external)
   integer, intent(in) :: n, control, method, precondition, max_iter, memory, threads
   real(8), intent(in) :: height(n), period, thickness, young, poisson, friction, mean_pressure, penetration, tol
   real(8), intent(out) :: pressure(n), gap(n), displacement_z(n), scalars(14), history(max_iter)
   integer, intent(out) :: stat
   character(len=1024), intent(out) :: errmsg
   !f2py intent(hide) :: n
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   type(contact_result) :: res
   character(len=12), parameter :: controls(0:1) = [character(len=12) :: 'load', 'displacement']
   character(len=8), parameter :: methods(0:2) = [character(len=8) :: 'auto', 'cg', 'anderson']
   stat = 0
   errmsg = ''
   scene%n = n
   scene%period = period
   scene%thickness = thickness
   scene%young = young
   scene%poisson = poisson
   scene%friction = friction
   scene%profile%kind = 'file'
   scene%profile%file = '(array from Python)'
   scene%control = controls(max(0, min(1, control)))
   scene%mean_pressure = mean_pressure
   scene%penetration = penetration
   scene%solver%method = methods(max(0, min(2, method)))
   scene%solver%tol = tol
   scene%solver%max_iter = max_iter
   scene%solver%memory = memory
   scene%solver%threads = threads
   scene%solver%precondition = precondition == 1
   call check_scene(scene, error)
   if (.not. allocated(error)) call solve_line_contact(scene, height, friction, res, error)
   if (allocated(error)) then
      stat = error%code
      errmsg = error%message
      return
   end if
   pressure = res%pressure
   gap = res%gap
   displacement_z = res%displacement_z
   history = 0
   history(1:size(res%residual_history)) = res%residual_history
   scalars = [res%mean_pressure, res%penetration, res%contact_fraction, res%delta_mu, res%delta_mu_spectral, &
      & res%delta_mu_energy, merge(1.0d0, 0.0d0, res%converged), real(res%iterations, 8), &
      & real(res%outer_iterations, 8), real(res%fft_pairs, 8), res%residual, res%wall_time, &
      & real(size(res%residual_history), 8), res%delta_mu_profile]
end subroutine py_solve_line

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
