!> Contact patches of an areal contact: the connected components of the contact set
!> (p > 0) on the periodic grid.
!>
!> Connectivity rule: two contact nodes belong to one patch when they are neighbours along x
!> or y (4-connectivity: nodes that touch only at a corner are separate patches), across the
!> periodic boundaries too. A node stands for the cell dx x dy around it: a patch's area is
!> its node count times dx dy; its perimeter counts the cell edges between a contact node
!> and a node out of contact (an edge normal to x has length dy, one normal to y length dx),
!> so a patch that wraps round the cell has no edge there.
module lc_observables_patches
   use lc_base_kinds, only: wp
   use lc_base_grid, only: grid_type
   implicit none (type, external)
   private
   public :: contact_patches

contains

   !> Label the patches of the contact set p > 0 and measure them: areas and perimeters
   !> (L^2, L), ordered by decreasing area; label(j) = the patch of node j (0 off contact).
   subroutine contact_patches(grid, p, area, perimeter, label)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: p(:)
      real(wp), allocatable, intent(out) :: area(:), perimeter(:)
      integer, allocatable, intent(out) :: label(:)
      integer, allocatable :: parent(:), order(:), root_to_patch(:), count_nodes(:)
      real(wp), allocatable :: edges(:)
      real(wp) :: dx, dy
      integer :: nx, ny, j, ix, iy, right, up, n_patches, root, k

      nx = grid%nx
      ny = grid%ny
      dx = grid%lx/nx
      dy = grid%ly/ny
      allocate (parent(size(p)), label(size(p)))
      do j = 1, size(p)
         parent(j) = j
      end do
      ! union the contact nodes with their contact neighbours to the right and above
      do iy = 0, ny - 1
         do ix = 0, nx - 1
            j = ix + nx*iy + 1
            if (.not. p(j) > 0.0_wp) cycle
            right = modulo(ix + 1, nx) + nx*iy + 1
            up = ix + nx*modulo(iy + 1, ny) + 1
            if (p(right) > 0.0_wp) call unite(parent, j, right)
            if (p(up) > 0.0_wp) call unite(parent, j, up)
         end do
      end do
      ! number the roots 1..n_patches
      allocate (root_to_patch(size(p)))
      root_to_patch = 0
      n_patches = 0
      label = 0
      do j = 1, size(p)
         if (.not. p(j) > 0.0_wp) cycle
         root = find(parent, j)
         if (root_to_patch(root) == 0) then
            n_patches = n_patches + 1
            root_to_patch(root) = n_patches
         end if
         label(j) = root_to_patch(root)
      end do
      allocate (count_nodes(n_patches), edges(n_patches))
      count_nodes = 0
      edges = 0.0_wp
      do iy = 0, ny - 1
         do ix = 0, nx - 1
            j = ix + nx*iy + 1
            k = label(j)
            if (k == 0) cycle
            count_nodes(k) = count_nodes(k) + 1
            ! the four edges of the cell, each counted from the contact side
            if (label(modulo(ix + 1, nx) + nx*iy + 1) == 0) edges(k) = edges(k) + dy
            if (label(modulo(ix - 1, nx) + nx*iy + 1) == 0) edges(k) = edges(k) + dy
            if (ny > 1) then
               if (label(ix + nx*modulo(iy + 1, ny) + 1) == 0) edges(k) = edges(k) + dx
               if (label(ix + nx*modulo(iy - 1, ny) + 1) == 0) edges(k) = edges(k) + dx
            end if
         end do
      end do
      ! largest first (ties: the lower label first, i.e. the first met in grid order)
      allocate (order(n_patches))
      do k = 1, n_patches
         order(k) = k
      end do
      call sort_by_count(order, count_nodes)
      area = count_nodes(order)*dx*dy
      perimeter = edges(order)
      root_to_patch(1:n_patches) = 0
      do k = 1, n_patches
         root_to_patch(order(k)) = k
      end do
      where (label > 0) label = root_to_patch(max(label, 1))
   end subroutine contact_patches

   !> Root of j, with path halving.
   integer function find(parent, j) result(root)
      integer, intent(inout) :: parent(:)
      integer, intent(in) :: j
      root = j
      do while (parent(root) /= root)
         parent(root) = parent(parent(root))
         root = parent(root)
      end do
   end function find

   subroutine unite(parent, a, b)
      integer, intent(inout) :: parent(:)
      integer, intent(in) :: a, b
      integer :: ra, rb
      ra = find(parent, a)
      rb = find(parent, b)
      if (ra /= rb) parent(max(ra, rb)) = min(ra, rb)
   end subroutine unite

   !> order <- order sorted by decreasing count(order), stable (insertion sort on the few
   !> patches of a scene would be quadratic on many: a merge sort).
   recursive subroutine sort_by_count(order, count)
      integer, intent(inout) :: order(:)
      integer, intent(in) :: count(:)
      integer, allocatable :: left(:), right(:)
      integer :: n, mid, i, j, k
      n = size(order)
      if (n < 2) return
      mid = n/2
      left = order(1:mid)
      right = order(mid + 1:n)
      call sort_by_count(left, count)
      call sort_by_count(right, count)
      i = 1
      j = 1
      do k = 1, n
         if (j > size(right)) then
            order(k) = left(i)
            i = i + 1
         else if (i > size(left)) then
            order(k) = right(j)
            j = j + 1
         else if (count(left(i)) >= count(right(j))) then
            order(k) = left(i)
            i = i + 1
         else
            order(k) = right(j)
            j = j + 1
         end if
      end do
   end subroutine sort_by_count
end module lc_observables_patches
