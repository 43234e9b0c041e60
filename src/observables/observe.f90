!> The observables of a solved contact, from the solution and the operator's kernel,
!> computed only as the scene asks: gap statistics and the interlocking friction on any
!> grid; contact spots, leak rate and the surface stress of line contacts.
!>
!> On a surface shared among MPI ranks (a distributed operator: `height` and the result's
!> fields are this rank's slab of rows) every observable is computed on the slabs: sums and
!> extremes over the ranks, the spectral ones on each rank's columns of the distributed
!> spectrum, the contact patches labelled on the slabs and joined across their edges
!> (lc_observables_patches).
module lc_observables
   use lc_base_kinds, only: wp
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use lc_base_grid, only: grid_type
   use lc_base_parallel, only: global_sum, global_max, sum_counts_over_ranks, global_maxloc, broadcast_from, &
      & slab, this_rank
   use lc_scene, only: scene_type, relief_pressure_scale
   use lc_result, only: contact_result
   use lc_contact_operator, only: compliance_operator
   use lc_observables_friction, only: interlocking_friction
   use lc_observables_surface, only: surface_fields, edge_stress_field
   use lc_observables_stress, only: surface_stress
   use lc_observables_patches, only: contact_patches, contact_patches_slab
   use lc_observables_geometry, only: contact_spots, leak_rate, gap_histogram, nearest_trailing_offset, &
      & spot_tension, spot_asymmetry
   implicit none (type, external)
   private
   public :: observe

contains

   !> The observables of a solved contact, computed only as the scene asks.
   subroutine observe(scene, op, height, result)
      type(scene_type), intent(in) :: scene
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(inout) :: result
      real(wp), allocatable :: edge_field(:)
      real(wp) :: scale
      integer :: where_max, top

      associate (p => result%pressure)
         result%mean_gap = total(op, result%gap)/op%grid%points()
         scale = relief_pressure_scale(scene, highest(op, height) - total(op, height)/op%grid%points())
         result%normalised_pressure = ieee_value(1.0_wp, ieee_quiet_nan)
         if (scale > 0.0_wp) result%normalised_pressure = result%mean_pressure/scale
         result%normalised_thickness = scene%thickness/scene%period
         if (scene%gap_bins > 0) then
            allocate (result%gap_edges(scene%gap_bins + 1), result%gap_counts(scene%gap_bins))
            if (op%distributed) then
               call gap_histogram(result%gap, result%gap_edges, result%gap_counts, highest(op, result%gap))
               call sum_counts_over_ranks(result%gap_counts)
            else
               call gap_histogram(result%gap, result%gap_edges, result%gap_counts)
            end if
         end if
         if (result%mean_pressure > 0.0_wp) then
            call interlocking_friction(op, p, result%displacement_z, height, result%delta_mu, &
               & result%delta_mu_spectral, result%delta_mu_energy, result%delta_mu_profile, result%dissipated_power)
         end if
         if (.not. op%grid%is_line()) then
            call observe_surface(scene, op, result)
            return
         end if
         call contact_spots(p, scene%period, result%n_spots, result%spot_trailing, result%spot_leading)
         result%contact_length = scene%period*count(p > 0.0_wp)/size(p)
         call spot_asymmetry(p, height, scene%period, result%spot_trailing, result%spot_leading, &
            & result%pressure_shift, result%summit_shift)
         result%leak_rate = leak_rate(result%gap)
         if (scene%stress) then
            allocate (result%displacement_x(size(p)), result%stress_xx(size(p)))
            result%shear = result%friction*p
            call surface_fields(op, p, result%displacement_x, result%stress_xx)
            where_max = maxloc(result%stress_xx, dim=1)
            result%max_tension_grid = result%stress_xx(where_max)
            result%max_tension = result%max_tension_grid
            result%max_tension_x = (where_max - 1)*scene%period/size(p)
            allocate (result%spot_max_tension(result%n_spots), result%spot_tension_offset(result%n_spots), &
               & result%spot_max_tension_grid(result%n_spots))
            if (result%friction > 0.0_wp) then
               ! the trailing-edge cusp, sub-grid (a square root: the grid value is off by ~dx^(1/2))
               allocate (edge_field(size(p)))
               call edge_stress_field(op, result%stress_xx, p, result%gap, edge_field)
               call spot_tension(result%stress_xx, scene%period, result%spot_trailing, result%spot_leading, &
                  & result%spot_max_tension, result%spot_tension_offset, result%spot_max_tension_grid, &
                  & edge_field, p, result%gap)
            else
               call spot_tension(result%stress_xx, scene%period, result%spot_trailing, result%spot_leading, &
                  & result%spot_max_tension, result%spot_tension_offset, result%spot_max_tension_grid)
            end if
            if (result%n_spots > 0) then
               top = maxloc(result%spot_max_tension, dim=1)
               if (result%spot_max_tension(top) > result%max_tension) then
                  result%max_tension = result%spot_max_tension(top)
                  result%max_tension_x = modulo(result%spot_trailing(top) + result%spot_tension_offset(top), &
                     & scene%period)
               end if
            end if
            result%max_tension_offset = nearest_trailing_offset(result%max_tension_x, result%spot_trailing, &
               & result%spot_leading, scene%period)
         end if
      end associate
   end subroutine observe

   !> What an areal contact adds: its patches, and with &output stress the in-plane
   !> displacements, the surface stress tensor, the largest tension sigma_xx and the largest
   !> principal stress with where they sit. The largest tension's offset is measured along
   !> its row of the grid from the trailing (-x) edge of the nearest run of contact nodes
   !> (negative: behind it), as for a line contact.
   subroutine observe_surface(scene, op, result)
      type(scene_type), intent(in) :: scene
      type(compliance_operator), intent(inout) :: op
      type(contact_result), intent(inout) :: result
      integer, allocatable :: label(:)
      real(wp), allocatable :: principal(:), trailing(:), leading(:)
      real(wp) :: largest
      integer :: where_max, nx, row, runs, owner, y_start, rows

      associate (p => result%pressure, grid => op%grid)
         nx = grid%nx
         if (op%distributed) then
            call contact_patches_slab(grid, p, result%patch_area, result%patch_perimeter)
         else
            call contact_patches(grid, p, result%patch_area, result%patch_perimeter, label)
         end if
         result%n_spots = size(result%patch_area)
         if (.not. scene%stress) return
         allocate (result%displacement_x(size(p)), result%displacement_y(size(p)), result%stress_xx(size(p)), &
            & result%stress_yy(size(p)), result%stress_xy(size(p)))
         result%shear = result%friction*p
         call surface_stress(op, p, result%displacement_x, result%displacement_y, result%stress_xx, &
            & result%stress_yy, result%stress_xy)
         ! (a distributed surface: the largest value over the ranks, on the slab of its owner;
         ! y_start = 0 on one process)
         y_start = 0
         if (op%distributed) call slab(grid%ny, y_start, rows)
         call largest_where(op, result%stress_xx, largest, owner, where_max)
         result%max_tension = largest
         result%max_tension_grid = result%max_tension
         result%max_tension_x = mod(where_max - 1, nx)*grid%lx/nx
         row = (where_max - 1)/nx
         result%max_tension_y = (y_start + row)*grid%ly/grid%ny
         ! the offset from the contact of its row, on the rank that holds the row
         result%max_tension_offset = 0.0_wp
         if (owner == this_rank()) then
            call contact_spots(p(row*nx + 1:row*nx + nx), grid%lx, runs, trailing, leading)
            result%max_tension_offset = nearest_trailing_offset(result%max_tension_x, trailing, leading, grid%lx)
         end if
         if (op%distributed) then
            call broadcast_from(result%max_tension_x, owner)
            call broadcast_from(result%max_tension_y, owner)
            call broadcast_from(result%max_tension_offset, owner)
         end if
         principal = 0.5_wp*(result%stress_xx + result%stress_yy) + &
            & sqrt((0.5_wp*(result%stress_xx - result%stress_yy))**2 + result%stress_xy**2)
         call largest_where(op, principal, largest, owner, where_max)
         result%max_principal_stress = largest
         result%max_principal_x = mod(where_max - 1, nx)*grid%lx/nx
         result%max_principal_y = (y_start + (where_max - 1)/nx)*grid%ly/grid%ny
         if (op%distributed) then
            call broadcast_from(result%max_principal_x, owner)
            call broadcast_from(result%max_principal_y, owner)
         end if
      end associate
   end subroutine observe_surface

   !> The sum of a field over the whole grid (over the ranks' slabs for a distributed operator).
   real(wp) function total(op, field)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: field(:)
      total = sum(field)
      if (op%distributed) total = global_sum(total)
   end function total

   !> The largest value of a field over the whole grid.
   real(wp) function highest(op, field)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: field(:)
      highest = maxval(field)
      if (op%distributed) highest = global_max(highest)
   end function highest

   !> The largest value of a field over the whole grid, the rank holding it (`owner`; this
   !> one on one process) and its index in that rank's slab.
   subroutine largest_where(op, field, largest, owner, position)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: field(:)
      real(wp), intent(out) :: largest
      integer, intent(out) :: owner, position
      if (op%distributed) then
         call global_maxloc(field, largest, owner, position)
      else
         position = maxloc(field, dim=1)
         largest = field(position)
         owner = this_rank()
      end if
   end subroutine largest_where

end module lc_observables
