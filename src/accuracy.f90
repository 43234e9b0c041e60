!> The accuracy option: a scene may give &solver target_error instead of n and tol, and
!> the grid and tolerance are chosen by the rule measured in bench/accuracy.py (tables,
!> Pareto fronts and the check of the rule: docs/accuracy.md).
!>
!> The error is the largest relative error of the contact fraction, a/a0, Delta mu, the
!> penetration (relative to the profile's peak-to-valley) and the largest surface tension,
!> against a converged reference. Measured convergence: the contact fraction is first order
!> in the grid step (each contact edge sits within one step), relative to the mean contact
!> spot length, and it sets the grid; the largest tension of a sliding layer, resolved
!> sub-grid at the trailing edge (lc_observables_geometry's spot_tension), converges at order
!> 1-1.5 and stays below the contact fraction's error at the rule's settings (it needed
!> ppw >= (1.2/eps)^2 as a grid maximum, order 1/2); a tolerance tol blurs the edges by
!> ~5 tol^(2/3). Hence, with lambda_s the shortest roughness wavelength and ppw the grid
!> points per lambda_s:
!>    ppw = the smallest power of two >= 4 with ppw >= 0.75 (lambda_s/spot length)/eps;
!>    tol = the largest of 1e-2, 1e-3, 1e-4, 1e-6, 1e-8 that is <= (eps/12)^1.5;
!> where the mean spot length comes from a pilot solve at ppw = 8 and tol 1e-4. Checked on
!> four scenes (frictionless half-space, h/lambda = 0.16 and 0.01 with mu_c = 0.5, a
!> viscoelastic layer) for eps = 1e-1 .. 1e-3, on the fitted profile and on a second one.
module lc_accuracy
   use lc_kinds, only: wp
   use lc_errors, only: error_type, fatal_error, input_error, code_input
   use lc_strings, only: to_string
   use lc_scene, only: scene_type, not_set
   use lc_result, only: contact_result
   use lc_profiles_profile, only: make_profile
   use lc_contact_solve, only: solve_contact
   implicit none (type, external)
   private
   public :: choose_resolution

   !> Constant of the rule (bench/accuracy.py: RULE_SPOT).
   real(wp), parameter :: spot_constant = 0.75_wp
   !> The tolerances the rule was measured with.
   real(wp), parameter :: tested_tols(5) = [1.0e-2_wp, 1.0e-3_wp, 1.0e-4_wp, 1.0e-6_wp, 1.0e-8_wp]
   !> Largest grid the rule may ask for (memory ~0.1 GB; beyond, the target is refused).
   integer, parameter :: largest_grid = 2**24
   integer, parameter :: pilot_ppw = 8

contains

   !> Set scene%n and scene%solver%tol from scene%solver%target_error (a generated profile:
   !> self_affine or sinusoid). Runs the pilot solve.
   subroutine choose_resolution(scene, error)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: pilot
      type(contact_result) :: result
      real(wp), allocatable :: height(:)
      real(wp) :: eps, wavelengths, spot
      integer :: ppw
      integer(kind=8) :: n

      eps = scene%solver%target_error
      select case (trim(scene%profile%kind))
      case ('self_affine')
         wavelengths = 128.0_wp   ! the default short_wavelength: period/128
         if (scene%profile%short_wavelength /= not_set) wavelengths = scene%period/scene%profile%short_wavelength
      case ('sinusoid')
         wavelengths = scene%profile%mode
      case default
         call input_error(error, 'solver', 'target_error', to_string(eps), &
            & "a generated profile (&profile kind = 'self_affine' or 'sinusoid'): a profile file fixes n; " // &
            & 'give &scene n and &solver tol instead')
         return
      end select

      ! the pilot: the same scene on pilot_ppw points per shortest wavelength
      pilot = scene
      pilot%n = grid_points(pilot_ppw, wavelengths)
      pilot%solver%tol = 1.0e-4_wp
      pilot%stress = .false.
      pilot%gap_bins = 0
      allocate (height(pilot%n))
      call make_profile(pilot, height, error)
      if (allocated(error)) return
      call solve_contact(pilot, height, scene%friction, result, error)
      if (allocated(error)) return
      ! mean spot length in shortest wavelengths (no spot: the grid cannot resolve any,
      ! take one grid step, which asks for the finest grid the rule allows)
      spot = scene%period/real(pilot%n, wp)
      if (result%n_spots > 0) spot = max(spot, result%contact_length/result%n_spots)
      spot = spot*wavelengths/scene%period

      ppw = predicted_ppw(eps, spot)
      n = int(ppw, kind=8)*ceiling(wavelengths, kind=8)
      if (ppw < 0 .or. n > largest_grid) then
         call fatal_error(error, '&solver: target_error = ' // to_string(eps) // ' needs more than ' // &
            & to_string(largest_grid) // ' grid points (' // to_string(ppw) // ' per shortest wavelength, ' // &
            & 'for contact spots of ' // to_string(spot) // ' shortest wavelengths); allowed: a larger ' // &
            & 'target_error, a longer short_wavelength, or give &scene n and &solver tol', code_input)
         return
      end if
      scene%n = grid_points(ppw, wavelengths)
      scene%solver%tol = rule_tol(eps)
   end subroutine choose_resolution

   !> Points per shortest wavelength for target eps and mean spot length `spot` (in shortest
   !> wavelengths); -1 if beyond 2^30.
   pure integer function predicted_ppw(eps, spot) result(ppw)
      real(wp), intent(in) :: eps, spot
      real(wp) :: need
      need = spot_constant/(spot*eps)
      ppw = 4
      do while (ppw < need)
         if (ppw >= 2**29) then
            ppw = -1
            return
         end if
         ppw = 2*ppw
      end do
   end function predicted_ppw

   !> The largest tested tolerance <= (eps/12)^1.5 (the smallest if none is).
   pure real(wp) function rule_tol(eps) result(tol)
      real(wp), intent(in) :: eps
      real(wp) :: bound
      integer :: i
      bound = (eps/12)**1.5_wp
      tol = tested_tols(size(tested_tols))
      do i = 1, size(tested_tols)
         if (tested_tols(i) <= bound*(1 + 1.0e-9_wp)) then
            tol = tested_tols(i)
            return
         end if
      end do
   end function rule_tol

   !> Grid points for ppw points per shortest wavelength (one more where the shortest mode
   !> would sit on the Nyquist frequency, which the profile generator leaves out).
   pure integer function grid_points(ppw, wavelengths) result(n)
      integer, intent(in) :: ppw
      real(wp), intent(in) :: wavelengths
      n = ppw*ceiling(wavelengths)
      if (2*nint(wavelengths) >= n) n = 2*nint(wavelengths) + 1
   end function grid_points
end module lc_accuracy
