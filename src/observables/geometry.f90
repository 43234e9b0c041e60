!> Contact geometry and gap statistics of a line contact on a periodic grid.
!>
!> Contact spots are maximal runs of grid nodes with p > 0, joined across the periodic
!> boundary. The indenter slides along +x, so a spot's leading edge is its +x end and its
!> trailing edge its -x end (seed Fig. 2(a)); edges are reported as the positions of the
!> end nodes +-dx/2, so that leading - trailing = (number of nodes) dx and the total
!> contact length a = (contact nodes) dx.
!>
!> Leakage across the sliding direction: the gap g(x) is uniform along the grooves (y), so a
!> pressure gradient dP/dy drives the Poiseuille flow q = -(g^3/(12 eta)) dP/dy per unit
!> length in x; averaged over x, the flow per unit length, per unit pressure gradient and
!> per unit inverse viscosity is <g^3>/12 (L^3). Along x a line contact does not leak once
!> any point touches.
module lc_observables_geometry
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use lc_base_kinds, only: wp
   implicit none (type, external)
   private
   public :: contact_spots, leak_rate, gap_histogram, nearest_trailing_offset, spot_tension, spot_asymmetry

contains

   !> Spots of the contact set p > 0: count, trailing and leading edges (L, in [0, period)
   !> for the trailing edge; the leading edge may exceed the period for a spot that wraps).
   subroutine contact_spots(p, period, n_spots, trailing, leading)
      real(wp), intent(in) :: p(:), period
      integer, intent(out) :: n_spots
      real(wp), allocatable, intent(out) :: trailing(:), leading(:)
      logical, allocatable :: contact(:)
      integer, allocatable :: first(:), length(:)
      integer :: n, j, start, i
      real(wp) :: dx

      n = size(p)
      dx = period/n
      allocate (contact(n), first(n/2 + 1), length(n/2 + 1))
      contact = p > 0.0_wp
      n_spots = 0
      if (all(contact)) then
         ! full contact: one spot covering the period
         n_spots = 1
         first(1) = 1
         length(1) = n
      else if (any(contact)) then
         ! start scanning just after a gap node, so that no spot is cut by the boundary
         start = findloc(contact, .false., dim=1)
         j = 0
         do while (j < n)
            i = mod(start - 1 + j, n) + 1
            if (contact(i) .and. .not. contact(mod(i - 2 + n, n) + 1)) then
               n_spots = n_spots + 1
               first(n_spots) = i
               length(n_spots) = 0
            end if
            if (contact(i)) length(n_spots) = length(n_spots) + 1
            j = j + 1
         end do
      end if
      allocate (trailing(n_spots), leading(n_spots))
      do i = 1, n_spots
         trailing(i) = (first(i) - 1)*dx - 0.5_wp*dx
         if (trailing(i) < 0.0_wp) trailing(i) = trailing(i) + period
         leading(i) = trailing(i) + length(i)*dx
      end do
   end subroutine contact_spots

   !> Offset (L) of position x from the trailing edge closest to it (periodic, in
   !> [-period/2, period/2)); zero when there are no spots, NaN in full contact.
   pure real(wp) function nearest_trailing_offset(x, trailing, leading, period) result(offset)
      real(wp), intent(in) :: x, trailing(:), leading(:), period
      real(wp) :: d
      integer :: i
      offset = 0.0_wp
      if (size(trailing) == 0) return
      ! full contact (one spot as long as the period) has no trailing edge
      offset = ieee_value(1.0_wp, ieee_quiet_nan)
      if (size(trailing) == 1 .and. leading(1) - trailing(1) > (1.0_wp - 1.0e-12_wp)*period) return
      offset = huge(1.0_wp)
      do i = 1, size(trailing)
         d = modulo(x - trailing(i) + 0.5_wp*period, period) - 0.5_wp*period
         if (abs(d) < abs(offset)) offset = d
      end do
   end function nearest_trailing_offset

   !> Largest sigma_xx around each spot and its offset from the spot's trailing edge (L,
   !> negative: behind it). The gap between two spots is split in the middle, so a spot's
   !> window runs from the middle of the gap behind it to the middle of the gap ahead and the
   !> windows cover the period. In full contact there is no trailing edge: offset = NaN.
   !>
   !> `grid_tension` is the largest grid value in the window. With `edge_field` (the smooth
   !> field Q of lc_observables_surface's edge_stress_field, for mu_c > 0) the square-root
   !> cusp of sigma_xx at the trailing edge is resolved sub-grid: the edge x_e is placed from
   !> the gap behind it, g ~ (x_e - x)^(3/2), i.e. g^(2/3) linear through the second and
   !> third gap nodes (the nodes next to the edge carry the discretisation's largest
   !> errors), or the first and second ones if that does not land between the last gap node
   !> and the first contact node (a coarse grid), or from p^2 ~ (x - x_e) through the first
   !> two contact nodes if there are fewer than two gap nodes; sigma_xx(x_e) = Q(x_e) by cubic
   !> interpolation of Q through the four nodes around x_e. `max_tension` is the larger of
   !> that and the grid value; spots of fewer than `min_edge_nodes` nodes keep the grid
   !> value. Error of the sub-grid value: order 1-1.5, ~1e-4 at 64 points per shortest
   !> wavelength on rough profiles (bench/accuracy.py), against order 1/2 for the grid value.
   pure subroutine spot_tension(stress, period, trailing, leading, max_tension, offset, grid_tension, &
         & edge_field, p, gap)
      real(wp), intent(in) :: stress(:), period, trailing(:), leading(:)
      real(wp), intent(out) :: max_tension(:), offset(:), grid_tension(:)
      real(wp), intent(in), optional :: edge_field(:), p(:), gap(:)
      !> contact nodes a spot needs for the sub-grid edge (1-2 nodes: not a resolved edge)
      integer, parameter :: min_edge_nodes = 3
      integer :: i, j, n, spots, first, last, behind, ahead, top
      real(wp) :: t, edge_value
      logical :: found

      n = size(stress)
      spots = size(trailing)
      do i = 1, spots
         call spot_nodes(i, first, last)
         ! gap lengths (nodes) behind and ahead, from the neighbouring spots (a single spot
         ! is its own neighbour)
         behind = gap_behind(i)
         ahead = gap_behind(modulo(i, spots) + 1)
         top = first
         do j = first - (behind - behind/2), last + ahead/2
            if (stress(modulo(j, n) + 1) > stress(modulo(top, n) + 1)) top = j
         end do
         grid_tension(i) = stress(modulo(top, n) + 1)
         max_tension(i) = grid_tension(i)
         offset(i) = (top - first + 0.5_wp)*period/n
         if (last - first + 1 >= n) then
            offset(i) = ieee_value(1.0_wp, ieee_quiet_nan)
            cycle
         end if
         if (.not. present(edge_field) .or. last - first + 1 < min_edge_nodes) cycle
         call trailing_edge(first, behind, t, found)
         if (.not. found) cycle
         edge_value = cubic(first, t)
         if (edge_value > max_tension(i)) then
            max_tension(i) = edge_value
            offset(i) = (t + 0.5_wp)*period/n
         end if
      end do

   contains

      !> 0-based node indices of spot i (last >= first, unwrapped).
      pure subroutine spot_nodes(i, first, last)
         integer, intent(in) :: i
         integer, intent(out) :: first, last
         first = nint(trailing(i)*n/period + 0.5_wp)
         last = first + nint((leading(i) - trailing(i))*n/period) - 1
      end subroutine spot_nodes

      !> Number of gap nodes between spot i and the spot behind it.
      pure integer function gap_behind(i)
         integer, intent(in) :: i
         integer :: first, last, previous_first, previous_last
         call spot_nodes(i, first, last)
         call spot_nodes(modulo(i - 2, spots) + 1, previous_first, previous_last)
         gap_behind = modulo(first - previous_last - 1, n)
         if (spots == 1 .and. last - first + 1 >= n) gap_behind = 0
      end function gap_behind

      !> Sub-grid trailing edge x_e = (first + t) dx, -1 <= t <= 0, of the spot whose first
      !> contact node is `first`, with `behind` gap nodes behind it.
      pure subroutine trailing_edge(first, behind, t, found)
         integer, intent(in) :: first, behind
         real(wp), intent(out) :: t
         logical, intent(out) :: found
         real(wp) :: near, far
         found = .false.
         t = 0.0_wp
         if (behind >= 3) then
            near = gap(modulo(first - 2, n) + 1)
            far = gap(modulo(first - 3, n) + 1)
            if (far > near .and. near > 0.0_wp) then
               t = -2.0_wp + near**(2.0_wp/3)/(far**(2.0_wp/3) - near**(2.0_wp/3))
               found = t >= -1.0_wp .and. t <= 0.0_wp
            end if
         end if
         if (.not. found .and. behind >= 2) then
            near = gap(modulo(first - 1, n) + 1)
            far = gap(modulo(first - 2, n) + 1)
            if (far > near .and. near > 0.0_wp) then
               t = -1.0_wp + near**(2.0_wp/3)/(far**(2.0_wp/3) - near**(2.0_wp/3))
               found = .true.
            end if
         end if
         if (.not. found) then
            near = p(modulo(first, n) + 1)**2
            far = p(modulo(first + 1, n) + 1)**2
            if (far > near .and. near > 0.0_wp) then
               t = -near/(far - near)
               found = .true.
            end if
         end if
         t = min(max(t, -1.0_wp), 0.0_wp)
      end subroutine trailing_edge

      !> edge_field at (first + t) dx, cubic through the nodes first - 2 .. first + 1.
      pure real(wp) function cubic(first, t) result(value)
         integer, intent(in) :: first
         real(wp), intent(in) :: t
         integer :: a, b
         real(wp) :: weight
         value = 0.0_wp
         do a = -2, 1
            weight = 1.0_wp
            do b = -2, 1
               if (b /= a) weight = weight*(t - b)/real(a - b, wp)
            end do
            value = value + weight*edge_field(modulo(first + a, n) + 1)
         end do
      end function cubic
   end subroutine spot_tension

   !> Asymmetry of the spots, load-weighted over the spots (L, positive = towards the
   !> leading edge, +x): `pressure_shift`, the offset of each spot's pressure centroid from
   !> its midpoint, and `summit_shift`, the offset of each spot's midpoint from the highest
   !> point of the rigid profile within it. Both vanish for symmetric asperities on a
   !> frictionless elastic layer; friction on thin layers and viscoelasticity shift them.
   pure subroutine spot_asymmetry(p, r, period, trailing, leading, pressure_shift, summit_shift)
      real(wp), intent(in) :: p(:), r(:), period, trailing(:), leading(:)
      real(wp), intent(out) :: pressure_shift, summit_shift
      integer :: i, j, n, first, last, top
      real(wp) :: dx, load, moment, middle, total

      n = size(p)
      dx = period/n
      pressure_shift = 0.0_wp
      summit_shift = 0.0_wp
      total = 0.0_wp
      do i = 1, size(trailing)
         first = nint(trailing(i)/dx + 0.5_wp)
         last = first + nint((leading(i) - trailing(i))/dx) - 1
         if (last - first + 1 >= n) cycle   ! full contact: no spot edges to compare with
         load = 0.0_wp
         moment = 0.0_wp
         top = first
         do j = first, last
            load = load + p(modulo(j, n) + 1)
            moment = moment + p(modulo(j, n) + 1)*j*dx
            if (r(modulo(j, n) + 1) > r(modulo(top, n) + 1)) top = j
         end do
         middle = 0.5_wp*(first + last)*dx
         pressure_shift = pressure_shift + (moment - middle*load)
         summit_shift = summit_shift + load*(middle - top*dx)
         total = total + load
      end do
      if (total > 0.0_wp) then
         pressure_shift = pressure_shift/total
         summit_shift = summit_shift/total
      end if
   end subroutine spot_asymmetry

   !> <g^3>/12: flow across the sliding direction per unit length, per unit pressure
   !> gradient, times the viscosity (L^3).
   pure real(wp) function leak_rate(gap)
      real(wp), intent(in) :: gap(:)
      leak_rate = sum(max(gap, 0.0_wp)**3)/(12.0_wp*size(gap))
   end function leak_rate

   !> Histogram of the gap over the whole period: `counts(i)` nodes with
   !> edges(i) <= g < edges(i+1), uniform bins from 0 to the largest gap (contact nodes,
   !> g = 0, fall in the first bin). `largest`: the largest gap of the whole map, where `gap`
   !> is a part of it (a slab of a surface shared among MPI ranks), whose counts are then
   !> added to the other parts'.
   pure subroutine gap_histogram(gap, edges, counts, largest)
      real(wp), intent(in) :: gap(:)
      real(wp), intent(out) :: edges(:)
      integer, intent(out) :: counts(:)
      real(wp), intent(in), optional :: largest
      real(wp) :: top, width
      integer :: j, bin, bins

      bins = size(counts)
      if (present(largest)) then
         top = max(largest, tiny(1.0_wp))
      else
         top = max(maxval(gap), tiny(1.0_wp))
      end if
      width = top/bins
      edges = [(width*j, j = 0, bins)]
      counts = 0
      do j = 1, size(gap)
         bin = min(max(int(max(gap(j), 0.0_wp)/width) + 1, 1), bins)
         counts(bin) = counts(bin) + 1
      end do
   end subroutine gap_histogram
end module lc_observables_geometry
