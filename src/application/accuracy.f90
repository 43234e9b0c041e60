!> The accuracy option: a scene may give &solver target_error instead of n and tol, and
!> the grid and tolerance are chosen by the rule measured in bench/accuracy.py (lines) and
!> bench/accuracy_areal.py (surfaces); tables and the check of the rule: docs/accuracy.md.
!>
!> The error is the largest relative error of the contact fraction, a/a0, Delta mu, the
!> penetration (relative to the profile's peak-to-valley) and the largest surface tension
!> (on surfaces also the Reynolds leakage k_eff along and across x), against a converged
!> reference. Measured convergence: the contact fraction is first order in the grid step
!> (each contact edge sits within one step), relative to the mean contact spot size, and it
!> sets the grid; a tolerance tol blurs the edges by ~5 tol^(2/3). Hence, with lambda_s the
!> shortest roughness wavelength and ppw the grid points per lambda_s:
!>    ppw = the smallest power of two >= 4 with ppw >= C (lambda_s/spot size)/eps,
!>          C = 0.75 on a line, 0.3 on a surface;
!>    tol = the largest of 1e-2, 1e-3, 1e-4, 1e-6, 1e-8 that is <= (eps/12)^1.5;
!> where the spot size comes from a pilot solve at tol 1e-4: on a line the mean spot length
!> (ppw 8), on a surface the mean patch size 2 A/P, contact area over half the patches'
!> perimeter (ppw 4; a line spot's length by the same formula). Checked on four line scenes
!> (frictionless half-space, h/lambda = 0.16 and 0.01 with mu_c = 0.5, a viscoelastic layer)
!> for eps = 1e-1 .. 1e-3 and three areal scenes for eps = 1e-1 .. 1e-2, each on the fitted
!> surface and on a second one. On a surface the rule leaves out the largest tension: its
!> grid value converges more slowly (the trailing-edge cusp is resolved sub-grid on lines
!> only; docs/accuracy.md), so it is reported, not targeted.
module lc_application_accuracy
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, input_error, code_input
   use lc_base_strings, only: to_string
   use lc_scene, only: scene_type, not_set, is_areal
   use lc_result, only: contact_result
   use lc_profiles_profile, only: make_profile
   use lc_application_scene_solve, only: solve_scene
   implicit none (type, external)
   private
   public :: choose_resolution

   !> Constants of the rule (bench/accuracy.py and bench/accuracy_areal.py: RULE_SPOT).
   real(wp), parameter :: spot_constant = 0.75_wp, spot_constant_areal = 0.3_wp
   !> The tolerances the rule was measured with.
   real(wp), parameter :: tested_tols(5) = [1.0e-2_wp, 1.0e-3_wp, 1.0e-4_wp, 1.0e-6_wp, 1.0e-8_wp]
   !> Largest grid the rule may ask for (memory ~0.1 GB; beyond, the target is refused).
   integer, parameter :: largest_grid = 2**24
   integer, parameter :: pilot_ppw = 8
   !> Pilot of an areal scene: 4 points per shortest wavelength (a 512^2 pilot for the default
   !> short_wavelength of period/128).
   integer, parameter :: pilot_ppw_areal = 4

contains

   !> Set the grid (scene%n, and scene%ny on a surface) and scene%solver%tol from
   !> scene%solver%target_error (a generated profile: self_affine or sinusoid). Runs the
   !> pilot solve.
   subroutine choose_resolution(scene, error)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: pilot
      type(contact_result) :: result
      real(wp), allocatable :: height(:)
      real(wp) :: eps, wavelengths(2), shortest, spot, period_y
      integer :: ppw, first_ppw
      integer(kind=8) :: points

      eps = scene%solver%target_error
      period_y = merge(scene%period_y, scene%period, scene%period_y /= not_set)
      ! shortest wavelengths per period along x and y (y: 0 on a line)
      select case (trim(scene%profile%kind))
      case ('self_affine')
         if (is_areal(scene)) then
            wavelengths = [scene%period, period_y]/(min(scene%period, period_y)/128)
         else
            wavelengths = [128.0_wp, 0.0_wp]
         end if
         if (scene%profile%short_wavelength /= not_set) &
            & wavelengths = [scene%period, merge(period_y, 0.0_wp, is_areal(scene))]/scene%profile%short_wavelength
         shortest = scene%period/wavelengths(1)
      case ('sinusoid')
         wavelengths = real([abs(scene%profile%mode), abs(scene%profile%mode_y)], wp)
         shortest = 1/norm2(wavelengths/[scene%period, period_y])
      case default
         call input_error(error, 'solver', 'target_error', to_string(eps), &
            & "a generated rough profile (&profile kind = 'self_affine' or 'sinusoid'; a profile file fixes " // &
            & 'the grid, a sphere has no shortest wavelength): give &scene n and &solver tol instead')
         return
      end select

      ! the pilot: the same scene at a few points per shortest wavelength, loose tolerance
      first_ppw = merge(pilot_ppw_areal, pilot_ppw, is_areal(scene))
      pilot = scene
      call set_grid(pilot, first_ppw, wavelengths)
      pilot%solver%tol = 1.0e-4_wp
      pilot%stress = .false.
      pilot%conductance = .false.
      pilot%gap_bins = 0
      allocate (height(int(pilot%n, kind=8)*pilot%ny))
      call make_profile(pilot, height, error)
      if (allocated(error)) return
      call solve_scene(pilot, height, scene%friction, result, error)
      if (allocated(error)) return
      spot = spot_size(pilot, result)/shortest   ! in shortest wavelengths

      ppw = predicted_ppw(eps, spot, merge(spot_constant_areal, spot_constant, is_areal(scene)))
      points = max(4_8, int(ppw, kind=8)*ceiling(wavelengths(1), kind=8))
      if (is_areal(scene)) points = points*max(4_8, int(ppw, kind=8)*ceiling(wavelengths(2), kind=8))
      if (ppw < 0 .or. points > largest_grid) then
         call fatal_error(error, '&solver: target_error = ' // to_string(eps) // ' needs more than ' // &
            & to_string(largest_grid) // ' grid points (' // to_string(ppw) // ' per shortest wavelength, ' // &
            & 'for contact spots of ' // to_string(spot) // ' shortest wavelengths); allowed: a larger ' // &
            & 'target_error, a longer short_wavelength, or give &scene n and &solver tol', code_input)
         return
      end if
      call set_grid(scene, ppw, wavelengths)
      scene%solver%tol = rule_tol(eps)
   end subroutine choose_resolution

   !> The grid of ppw points per shortest wavelength along each axis: n along x; on a
   !> surface also ny (at least 4 each: a sinusoid constant along one axis needs no more).
   subroutine set_grid(scene, ppw, wavelengths)
      type(scene_type), intent(inout) :: scene
      integer, intent(in) :: ppw
      real(wp), intent(in) :: wavelengths(2)
      scene%n = grid_points(ppw, wavelengths(1))
      if (is_areal(scene)) then
         scene%n = max(4, scene%n)
         scene%ny = max(4, grid_points(ppw, wavelengths(2)))
      end if
   end subroutine set_grid

   !> Mean contact spot size of a solve (L): the spot length on a line, 2 A/P over the
   !> patches of a surface (the same on a line, where a spot has two edges); one grid step
   !> without contact (the grid cannot resolve any spot: the rule then asks for its finest grid).
   real(wp) function spot_size(scene, result) result(spot)
      type(scene_type), intent(in) :: scene
      type(contact_result), intent(in) :: result
      spot = scene%period/real(scene%n, wp)
      if (is_areal(scene)) then
         if (allocated(result%patch_perimeter)) then
            if (sum(result%patch_perimeter) > 0) spot = max(spot, 2*sum(result%patch_area)/sum(result%patch_perimeter))
         end if
      else if (result%n_spots > 0) then
         spot = max(spot, result%contact_length/result%n_spots)
      end if
   end function spot_size

   !> Points per shortest wavelength for target eps and mean spot size `spot` (in shortest
   !> wavelengths) with the rule's constant; -1 if beyond 2^30.
   pure integer function predicted_ppw(eps, spot, constant) result(ppw)
      real(wp), intent(in) :: eps, spot, constant
      real(wp) :: need
      need = constant/(spot*eps)
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
      if (n > 0 .and. 2*nint(wavelengths) >= n) n = 2*nint(wavelengths) + 1
   end function grid_points
end module lc_application_accuracy
