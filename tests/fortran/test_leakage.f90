!> Tests of the Reynolds leakage in the core (lc_leakage_reynolds). One line per check;
!> exit 0 on pass, error stop 1 on failure.
!>
!> Tolerances:
!> - tol_exact = 1e-12: a uniform gap and the flow along stripes need no linear solve (the
!>   right-hand side vanishes): the dissipation sums rounding only.
!> - tol_solve = 1e-10: the flow across stripes is solved by CG stopped at tol = 1e-12 on
!>   k_eff; its energy-error estimate lags a few iterations, so two orders above it.
program test_leakage
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_leakage_reynolds, only: leakage_result, reynolds_leakage
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_exact = 1.0e-12_wp
   real(wp), parameter :: tol_solve = 1.0e-10_wp

   call check_uniform()
   call check_stripes()
   call check_blocked()
   call check_diagonal_channel()
   call check_periodic_edge()
   call finish('leakage')

contains

   subroutine leakage_of(g, nx, ny, lx, ly, tol, res)
      real(wp), intent(in) :: g(:), lx, ly, tol
      integer, intent(in) :: nx, ny
      type(leakage_result), intent(out) :: res
      type(error_type), allocatable :: error
      call reynolds_leakage(g, spread(.false., 1, size(g)), nx, ny, lx, ly, tol, 500, res, error)
      if (allocated(error)) call check(.false., 'leakage: ' // error%message)
   end subroutine leakage_of

   !> k_eff = g^3 both ways on a non-square cell.
   subroutine check_uniform()
      type(leakage_result) :: res
      call leakage_of(spread(0.37_wp, 1, 60), 10, 6, 2.0_wp, 0.5_wp, 1.0e-6_wp, res)
      call check(abs(res%x%k_eff/0.37_wp**3 - 1) < tol_exact .and. abs(res%y%k_eff/0.37_wp**3 - 1) < tol_exact, &
         & 'uniform gap: k_eff = g^3 along x and y')
      call check(res%x%percolating .and. res%y%percolating .and. res%x%unknowns == 59, &
         & 'uniform gap: percolating, one pinned cell')
   end subroutine check_uniform

   !> g(y) only: the arithmetic mean of g^3 along x, the harmonic mean along y.
   subroutine check_stripes()
      integer, parameter :: nx = 16, ny = 24
      real(wp) :: stripes(ny), g(nx*ny)
      type(leakage_result) :: res
      integer :: j
      stripes = [(0.2_wp + 1.8_wp*modulo(7*j, ny)/real(ny - 1, wp), j=0, ny - 1)]
      do j = 1, ny
         g((j - 1)*nx + 1:j*nx) = stripes(j)
      end do
      call leakage_of(g, nx, ny, 1.0_wp, 1.0_wp, 1.0e-12_wp, res)
      call check(abs(res%x%k_eff/(sum(stripes**3)/ny) - 1) < tol_exact, 'stripes: arithmetic mean of g^3 along them')
      call check(abs(res%y%k_eff*sum(1/stripes**3)/ny - 1) < tol_solve .and. res%y%converged, &
         & 'stripes: harmonic mean of g^3 across them')
   end subroutine check_stripes

   !> A contact column blocks the flow along x, not along y.
   subroutine check_blocked()
      integer, parameter :: nx = 20, ny = 12
      real(wp) :: g(nx*ny)
      type(leakage_result) :: res
      integer :: j
      g = 0.5_wp
      do j = 1, ny
         g((j - 1)*nx + 8) = 0.0_wp
      end do
      call leakage_of(g, nx, ny, 1.0_wp, 1.0_wp, 1.0e-6_wp, res)
      call check(res%x%k_eff == 0.0_wp .and. .not. res%x%percolating .and. res%x%iterations == 0, &
         & 'contact line across x: k_eff_x = 0, not percolating')
      call check(abs(res%y%k_eff/(0.5_wp**3*19/20) - 1) < tol_exact, 'contact line across x: k_eff_y of 19 open columns')
   end subroutine check_blocked

   !> A diagonal contact line leaves a channel that winds along x and y at once.
   subroutine check_diagonal_channel()
      integer, parameter :: n = 16
      real(wp) :: g(n*n)
      type(leakage_result) :: res
      integer :: i
      g = 0.5_wp
      do i = 1, n
         g((i - 1)*n + i) = 0.0_wp
      end do
      call leakage_of(g, n, n, 1.0_wp, 1.0_wp, 1.0e-12_wp, res)
      call check(res%x%percolating .and. res%y%percolating .and. res%x%k_eff > 0, &
         & 'diagonal channel: percolates along x and y')
      call check(abs(res%x%k_eff/res%y%k_eff - 1) < tol_solve, 'diagonal channel: symmetric, k_eff_x = k_eff_y')
   end subroutine check_diagonal_channel

   !> The clusters joined across the periodic edge along y. On one rank the slab is the whole
   !> surface and the clusters that wind along y only through its periodic edge are joined by
   !> the pairs across that edge (the join of the slabs); the same map shifted by half the
   !> rows (and some columns) has them inside the slab and others across the edge. The flow
   !> is invariant under the shift: the counts exactly, k_eff to tol_solve (both CG stopped
   !> at 1e-12; they differ by the order of the sums and the preconditioner's coarsening).
   !> A contact map with clusters that wind along y only through that edge, along x only,
   !> both, and pools that carry no flow.
   subroutine check_periodic_edge()
      integer, parameter :: nx = 48, ny = 40, shift_x = 7, shift_y = ny/2
      real(wp), parameter :: pi = acos(-1.0_wp)
      real(wp) :: g(nx*ny), g_shifted(nx*ny), x, y
      type(leakage_result) :: res, shifted
      type(error_type), allocatable :: error
      integer :: i, j, k
      logical :: closed(nx*ny), closed_shifted(nx*ny)
      ! a smooth gap closed on half the cells, connected along x and y through necks
      do j = 1, ny
         do i = 1, nx
            x = 2*pi*(i - 1)/nx
            y = 2*pi*(j - 1)/ny
            g(i + (j - 1)*nx) = max(0.0_wp, 0.03_wp + sin(3*x + 1.3_wp)*cos(2*y) + 0.5_wp*sin(5*x + 7*y + 0.4_wp) &
               & + 0.3_wp*cos(x - 4*y))
         end do
      end do
      ! two rings of contact around pools, one across the periodic edge y (rows ny-2 .. 2)
      closed = .false.
      do j = -2, 2
         do i = -2, 2
            if (max(abs(i), abs(j)) /= 2) cycle
            closed(11 + i + (10 + j)*nx) = .true.
            closed(21 + i + modulo(j, ny)*nx) = .true.
         end do
      end do
      do j = 1, ny
         do i = 1, nx
            k = modulo(i - 1 + shift_x, nx) + 1 + modulo(j - 1 + shift_y, ny)*nx
            g_shifted(i + (j - 1)*nx) = g(k)
            closed_shifted(i + (j - 1)*nx) = closed(k)
         end do
      end do
      call reynolds_leakage(g, closed, nx, ny, 1.0_wp, 1.2_wp, 1.0e-12_wp, 500, res, error)
      if (allocated(error)) call check(.false., 'leakage: ' // error%message)
      call reynolds_leakage(g_shifted, closed_shifted, nx, ny, 1.0_wp, 1.2_wp, 1.0e-12_wp, 500, shifted, error)
      if (allocated(error)) call check(.false., 'leakage of the shifted gap: ' // error%message)
      call check(res%fluid_fraction < 0.8_wp .and. res%x%connected_fraction < res%fluid_fraction, &
         & 'periodic edge: the map has pools that carry no flow')
      call check(shifted%fluid_fraction == res%fluid_fraction .and. &
         & (shifted%x%connected_fraction == res%x%connected_fraction) .and. &
         & (shifted%y%connected_fraction == res%y%connected_fraction) .and. shifted%x%unknowns == res%x%unknowns &
         & .and. shifted%y%unknowns == res%y%unknowns .and. (shifted%x%percolating .eqv. res%x%percolating) .and. &
         & (shifted%y%percolating .eqv. res%y%percolating), 'periodic edge: the same clusters and unknowns shifted')
      call check(abs(shifted%x%k_eff/res%x%k_eff - 1) < tol_solve .and. abs(shifted%y%k_eff/res%y%k_eff - 1) &
         & < tol_solve .and. res%x%k_eff > 0 .and. res%y%k_eff > 0, 'periodic edge: k_eff along x and y shifted')
   end subroutine check_periodic_edge
end program test_leakage
