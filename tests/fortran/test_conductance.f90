!> Tests of the conductance and the interfacial stiffness (lc_observables_conductance). One
!> line per check; exit 0 on pass, error stop 1 on failure.
!>
!> Tolerances:
!> - tol_exact = 1e-13: full and empty contact need no iteration (1/h, 0, +Inf); the
!>   uniform flux of full contact on a layer is exact.
!> - tol_same = 1e-10: Barber's analogy on a half-space, both systems solved to 1e-12 on
!>   the same contact set (their means carry the square of that, the multipliers' rounding
!>   1e-16).
!> - tol_strip = 1e-3: periodic strips on a line against the conformal map; the strip's
!>   edge is uncertain by a grid spacing, 6e-4 at 4000 points.
program test_conductance
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_positive_inf
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_grid, only: grid_type, line_grid, surface_grid
   use lc_greens_viscoelastic, only: material_law
   use lc_greens_kernel, only: layer_kernel, make_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_observables_conductance, only: contact_conductance, contact_stiffness, masked_outcome
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_exact = 1.0e-13_wp
   real(wp), parameter :: tol_same = 1.0e-10_wp
   real(wp), parameter :: tol_strip = 1.0e-3_wp
   real(wp), parameter :: pi = acos(-1.0_wp)

   call check_trivial()
   call check_strips()
   call check_barber()
   call check_refusal()
   call finish('conductance')

contains

   !> +Inf: the thickness of a half-space.
   real(wp) function infinite()
      infinite = ieee_value(1.0_wp, ieee_positive_inf)
   end function infinite

   !> Full contact on a layer conducts sigma/h, on a half-space without bound; none, nothing.
   subroutine check_trivial()
      type(grid_type) :: grid
      type(masked_outcome) :: outcome
      type(error_type), allocatable :: error
      real(wp) :: c
      grid = surface_grid(8, 6, 1.0_wp, 2.0_wp)
      call contact_conductance(grid, spread(.true., 1, 48), 0.25_wp, 1.0e-10_wp, 100, 1, c, outcome, error)
      call check(.not. allocated(error) .and. abs(c*0.25_wp - 1) < tol_exact .and. outcome%converged, &
         & 'full contact on a layer: 1/h')
      call contact_conductance(grid, spread(.true., 1, 48), infinite(), 1.0e-10_wp, 100, 1, c, outcome, error)
      call check(.not. ieee_is_finite(c) .and. c > 0, 'full contact on a half-space: +Inf')
      call contact_conductance(grid, spread(.false., 1, 48), 0.25_wp, 1.0e-10_wp, 100, 1, c, outcome, error)
      call check(c == 0.0_wp, 'no contact: 0')
   end subroutine check_trivial

   !> Strips of half-width a, period L on a half-space: R = ln(1/sin(pi a/L))/pi per unit
   !> conductivity and depth (conformal map).
   subroutine check_strips()
      integer, parameter :: n = 4000
      real(wp), parameter :: period = 2.0_wp, a = 0.2_wp
      type(grid_type) :: grid
      type(masked_outcome) :: outcome
      type(error_type), allocatable :: error
      logical :: contact(n)
      real(wp) :: c, exact
      integer :: j
      grid = line_grid(n, period)
      contact = [(abs(j*period/n - period/2) <= a + 1.0e-12_wp, j = 0, n - 1)]
      call contact_conductance(grid, contact, infinite(), 1.0e-12_wp, 1000, 1, c, outcome, error)
      exact = log(1/sin(pi*a/period))/pi
      call check(.not. allocated(error) .and. outcome%converged .and. abs(1/(c*period)/exact - 1) < tol_strip, &
         & 'periodic strips: the conformal map')
   end subroutine check_strips

   !> On an elastic half-space (E* = E/(1 - nu^2)) G = 2/(E* q) = (2/E*) G_c: K = (E*/2) C.
   subroutine check_barber()
      integer, parameter :: nx = 32, ny = 24
      type(grid_type) :: grid
      type(material_law) :: law
      type(layer_kernel) :: kernel
      type(compliance_operator), target :: op
      type(masked_outcome) :: conduction, stiffness
      type(error_type), allocatable :: error
      logical :: contact(nx*ny)
      real(wp) :: c, k, x, y
      integer :: i
      grid = surface_grid(nx, ny, 1.0_wp, 0.75_wp)
      law%young = 3.0_wp
      kernel = make_kernel(infinite(), law, 0.3_wp, 0.0_wp)
      call build_operator(op, grid, kernel, 0.0_wp, 1, error)
      do i = 1, nx*ny
         x = mod(i - 1, nx)/real(nx, wp)
         y = ((i - 1)/nx)*0.75_wp/ny
         ! two spots of different sizes
         contact(i) = (x - 0.3_wp)**2 + (y - 0.3_wp)**2 < 0.15_wp**2 .or. (x - 0.75_wp)**2 + (y - 0.5_wp)**2 < 0.01_wp
      end do
      call contact_conductance(grid, contact, infinite(), 1.0e-12_wp, 1000, 1, c, conduction, error)
      call contact_stiffness(op, contact, 1.0e-12_wp, 1000, k, stiffness)
      call check(conduction%converged .and. stiffness%converged .and. &
         & abs(k/(3.0_wp/(1 - 0.3_wp**2)/2*c) - 1) < tol_same, 'half-space: Barber''s analogy K = (E*/2) C')
   end subroutine check_barber

   !> A map of the wrong size and a thickness <= 0 are bad input.
   subroutine check_refusal()
      type(masked_outcome) :: outcome
      type(error_type), allocatable :: error
      real(wp) :: c
      call contact_conductance(line_grid(16, 1.0_wp), spread(.true., 1, 8), 1.0_wp, 1.0e-10_wp, 10, 1, c, outcome, &
         & error)
      call check(allocated(error), 'a map of the wrong size is refused')
      call contact_conductance(line_grid(16, 1.0_wp), spread(.true., 1, 16), 0.0_wp, 1.0e-10_wp, 10, 1, c, outcome, &
         & error)
      call check(allocated(error), 'thickness = 0 is refused')
   end subroutine check_refusal

end program test_conductance
