!> Tests of the contact patches (lc_observables_patches). One line per check; exit 0 on
!> pass, error stop 1 on failure.
!>
!> The areas and perimeters are integer counts of nodes and cell edges times dx dy, dy or
!> dx, so the closed forms below hold to rounding (tol_exact) and the patches measured on
!> the slabs (one rank here: its slab is the whole surface, its labels joined across the
!> periodic edge y by the join of the slabs) are the serial ones to the bit.
program test_patches
   use lc_base_kinds, only: wp, i8
   use lc_base_grid, only: grid_type, surface_grid
   use lc_observables_patches, only: contact_patches, contact_patches_slab
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_exact = 1.0e-13_wp

   call check_ring()
   call check_band_across_the_periodic_edge()
   call check_one_slab_is_the_serial_list()
   call finish('patches')

contains

   !> A square ring of side 9 and width 2 (interior 5 x 5 open) on a non-square cell: one
   !> patch of 81 - 25 nodes; its edges: 4 x 9 outside and 4 x 5 inside.
   subroutine check_ring()
      integer, parameter :: nx = 20, ny = 16
      type(grid_type) :: grid
      real(wp) :: p(nx*ny), dx, dy
      real(wp), allocatable :: area(:), perimeter(:)
      integer, allocatable :: label(:)
      integer :: i, j
      grid = surface_grid(nx, ny, 2.0_wp, 1.0_wp)
      dx = 2.0_wp/nx
      dy = 1.0_wp/ny
      p = 0.0_wp
      do j = 3, 11
         do i = 5, 13
            if (max(abs(i - 9), abs(j - 7)) >= 3) p(i + (j - 1)*nx) = 1.0_wp
         end do
      end do
      call contact_patches(grid, p, area, perimeter, label)
      call check(size(area) == 1 .and. count(label == 1) == 56, 'ring: one patch of 56 nodes')
      call check(abs(area(1) - 56*dx*dy) < tol_exact*area(1), 'ring: area 56 dx dy')
      call check(abs(perimeter(1) - (2*(9 + 5)*dx + 2*(9 + 5)*dy)) < tol_exact*perimeter(1), &
         & 'ring: perimeter of the outer and the inner square')
   end subroutine check_ring

   !> A band of rows 1-2 and ny-1..ny: one patch across the periodic edge y, two straight
   !> edges along x; a single node elsewhere is the second, smaller one.
   subroutine check_band_across_the_periodic_edge()
      integer, parameter :: nx = 12, ny = 10
      type(grid_type) :: grid
      real(wp) :: p(nx*ny)
      real(wp), allocatable :: area(:), perimeter(:), slab_area(:), slab_perimeter(:)
      integer, allocatable :: label(:)
      grid = surface_grid(nx, ny, 1.0_wp, 1.0_wp)
      p = 0.0_wp
      p(1:2*nx) = 2.0_wp
      p((ny - 2)*nx + 1:) = 2.0_wp
      p(6 + 4*nx) = 1.0_wp
      call contact_patches(grid, p, area, perimeter, label)
      call check(size(area) == 2 .and. abs(area(1) - 4.0_wp/ny) < tol_exact, 'band: one patch across the edge y')
      call check(abs(perimeter(1) - 2.0_wp) < tol_exact .and. abs(perimeter(2) - (2.0_wp/nx + 2.0_wp/ny)) < tol_exact, &
         & 'band: two straight edges; the single node its four')
      call contact_patches_slab(grid, p, slab_area, slab_perimeter)
      call check(all(slab_area == area) .and. all(slab_perimeter == perimeter), 'band: the same on one slab')
   end subroutine check_band_across_the_periodic_edge

   !> Random contact maps from 10 % to 70 % of the nodes (many patches, ties of size, and
   !> patches across both periodic edges): on one slab, the serial list to the bit.
   subroutine check_one_slab_is_the_serial_list()
      integer, parameter :: nx = 40, ny = 36
      type(grid_type) :: grid
      real(wp) :: p(nx*ny), u(nx*ny)
      real(wp), allocatable :: area(:), perimeter(:), slab_area(:), slab_perimeter(:)
      integer, allocatable :: label(:)
      integer(i8) :: state
      integer :: level, k
      logical :: same
      grid = surface_grid(nx, ny, 1.0_wp, 1.5_wp)
      ! (Park and Miller's minimal standard generator: the same map on every compiler)
      state = 12345
      do k = 1, size(u)
         state = modulo(16807_i8*state, 2147483647_i8)
         u(k) = real(state, wp)/2147483647.0_wp
      end do
      same = .true.
      do level = 1, 7
         p = merge(1.0_wp, 0.0_wp, u < 0.1_wp*level)
         call contact_patches(grid, p, area, perimeter, label)
         call contact_patches_slab(grid, p, slab_area, slab_perimeter)
         same = same .and. size(slab_area) == size(area) .and. size(area) > 0
         if (same) same = all(slab_area == area) .and. all(slab_perimeter == perimeter)
      end do
      call check(same, 'random maps: one slab gives the serial patches to the bit')
   end subroutine check_one_slab_is_the_serial_list
end program test_patches
