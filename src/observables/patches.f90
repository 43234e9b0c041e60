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
   use lc_base_kinds, only: wp, i8
   use lc_base_grid, only: grid_type
   use lc_base_slab_exchange, only: halo_rows, rank_counts, gather_integers, broadcast_integers, sum_integers
   use lc_base_parallel, only: this_rank, is_root
   implicit none (type, external)
   private
   public :: contact_patches, contact_patches_slab

contains

   !> Label the patches of the contact set p > 0 and measure them: areas and perimeters
   !> (L^2, L), ordered by decreasing area; label(j) = the patch of node j (0 off contact).
   subroutine contact_patches(grid, p, area, perimeter, label)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: p(:)
      real(wp), allocatable, intent(out) :: area(:), perimeter(:)
      integer, allocatable, intent(out) :: label(:)
      integer, allocatable :: order(:), rank_of(:)
      integer(i8), allocatable :: measures(:, :)
      integer :: n_patches, k
      logical, allocatable :: contact(:)

      contact = p > 0.0_wp
      call label_rows(contact, grid%nx, .true., label, n_patches)
      ! (the rows around a whole periodic surface are its own last and first)
      call measure_rows(contact, label, n_patches, grid%nx, grid%ny > 1, contact(size(p) - grid%nx + 1:), &
         & contact(1:grid%nx), measures)
      call patch_statistics(grid, measures, area, perimeter, order)
      allocate (rank_of(n_patches))
      do k = 1, n_patches
         rank_of(order(k)) = k
      end do
      where (label > 0) label = rank_of(max(label, 1))
   end subroutine contact_patches

   !> The patches of a surface shared among MPI ranks, from this rank's slab p of rows
   !> (lc_base_slab): the areas and perimeters contact_patches gives
   !> on the whole surface, the same numbers in the same order, on every rank. Each rank
   !> labels its slab, the labels on the slabs' edge rows (and across the periodic edge
   !> between the last rank and rank 0) are joined on rank 0 from the pairs that touch, and
   !> each patch's node and edge counts are summed over the ranks.
   subroutine contact_patches_slab(grid, p, area, perimeter)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: p(:)
      real(wp), allocatable, intent(out) :: area(:), perimeter(:)
      logical, allocatable :: contact(:)
      integer, allocatable :: label(:), counts(:), pairs(:), all_pairs(:), patch_of(:), order(:)
      integer(i8), allocatable :: local(:, :), measures(:, :)
      real(wp), allocatable :: labels(:)
      real(wp) :: below(grid%nx), above(grid%nx), label_above(grid%nx)
      integer :: nx, n_local, first, next_first, n_labels, n_patches, ix, last, n_pairs, k, r

      nx = grid%nx
      contact = p > 0.0_wp
      call label_rows(contact, nx, .false., label, n_local)
      call halo_rows(p, nx, below, above)
      call measure_rows(contact, label, n_local, nx, grid%ny > 1, below > 0.0_wp, above > 0.0_wp, local)
      ! global label numbers: the ranks' local labels one after the other, so that the
      ! order of the labels is that of their first nodes on the whole grid (x fastest)
      call rank_counts(n_local, counts)
      first = sum(counts(:this_rank() - 1))
      n_labels = sum(counts)
      next_first = merge(0, first + n_local, this_rank() == size(counts) - 1)
      ! the pairs of labels joined across the edge above this slab
      labels = real(label, wp)
      call halo_rows(labels, nx, below, label_above)
      deallocate (labels)
      last = size(p) - nx
      allocate (pairs(2*nx))
      n_pairs = 0
      do ix = 1, nx
         if (label(last + ix) > 0 .and. label_above(ix) > 0.0_wp) then
            pairs(n_pairs + 1) = first + label(last + ix)
            pairs(n_pairs + 2) = next_first + nint(label_above(ix))
            n_pairs = n_pairs + 2
         end if
      end do
      call gather_integers(pairs(:n_pairs), all_pairs)
      ! rank 0 joins them; a patch's number is that of its first label (its first node)
      allocate (patch_of(n_labels + 1))
      if (is_root()) call join_labels(all_pairs, n_labels, patch_of(:n_labels), patch_of(n_labels + 1))
      call broadcast_integers(patch_of)
      n_patches = patch_of(n_labels + 1)
      allocate (measures(3, n_patches))
      measures = 0
      do k = 1, n_local
         r = patch_of(first + k)
         measures(:, r) = measures(:, r) + local(:, k)
      end do
      call sum_integers(measures)
      call patch_statistics(grid, measures, area, perimeter, order)
   end subroutine contact_patches_slab

   !> The connected components of `contact` (rows of nx, x periodic; y periodic when
   !> periodic_y, else the rows end at the first and last): label(j) = 1..n in the order
   !> of their first node (x fastest), 0 off contact.
   subroutine label_rows(contact, nx, periodic_y, label, n)
      logical, intent(in) :: contact(:), periodic_y
      integer, intent(in) :: nx
      integer, allocatable, intent(out) :: label(:)
      integer, intent(out) :: n
      integer, allocatable :: parent(:), root_to_label(:)
      integer :: rows, j, ix, iy, root

      rows = size(contact)/nx
      allocate (parent(size(contact)), label(size(contact)))
      do j = 1, size(contact)
         parent(j) = j
      end do
      ! union the contact nodes with their contact neighbours to the right and above
      do iy = 0, rows - 1
         do ix = 0, nx - 1
            j = ix + nx*iy + 1
            if (.not. contact(j)) cycle
            if (contact(modulo(ix + 1, nx) + nx*iy + 1)) call unite(parent, j, modulo(ix + 1, nx) + nx*iy + 1)
            if (iy + 1 < rows .or. periodic_y) then
               if (contact(ix + nx*modulo(iy + 1, rows) + 1)) call unite(parent, j, ix + nx*modulo(iy + 1, rows) + 1)
            end if
         end do
      end do
      ! number the roots 1..n
      allocate (root_to_label(size(contact)))
      root_to_label = 0
      n = 0
      label = 0
      do j = 1, size(contact)
         if (.not. contact(j)) cycle
         root = find(parent, j)
         if (root_to_label(root) == 0) then
            n = n + 1
            root_to_label(root) = n
         end if
         label(j) = root_to_label(root)
      end do
   end subroutine label_rows

   !> Each label's node count, and its cell edges to nodes out of contact: normal to x
   !> (length dy) and, with edges_y, normal to y (length dx); measures(:, k) = these three
   !> counts of label k. below and above: whether the nodes of the rows next to the first and
   !> the last are in contact.
   subroutine measure_rows(contact, label, n, nx, edges_y, below, above, measures)
      logical, intent(in) :: contact(:), edges_y, below(:), above(:)
      integer, intent(in) :: label(:), n, nx
      integer(i8), allocatable, intent(out) :: measures(:, :)
      integer :: rows, j, ix, iy, k
      logical :: up, down

      rows = size(contact)/nx
      allocate (measures(3, n))
      measures = 0
      do iy = 0, rows - 1
         do ix = 0, nx - 1
            j = ix + nx*iy + 1
            k = label(j)
            if (k == 0) cycle
            measures(1, k) = measures(1, k) + 1
            ! the four edges of the cell, each counted from the contact side
            if (.not. contact(modulo(ix + 1, nx) + nx*iy + 1)) measures(2, k) = measures(2, k) + 1
            if (.not. contact(modulo(ix - 1, nx) + nx*iy + 1)) measures(2, k) = measures(2, k) + 1
            if (edges_y) then
               if (iy + 1 < rows) then
                  up = contact(j + nx)
               else
                  up = above(ix + 1)
               end if
               if (iy > 0) then
                  down = contact(j - nx)
               else
                  down = below(ix + 1)
               end if
               if (.not. up) measures(3, k) = measures(3, k) + 1
               if (.not. down) measures(3, k) = measures(3, k) + 1
            end if
         end do
      end do
   end subroutine measure_rows

   !> Areas and perimeters of the patches whose counts are `measures` (measure_rows), largest
   !> first (ties: the lower number first, i.e. the first met in grid order); order(k) =
   !> the patch listed k-th.
   subroutine patch_statistics(grid, measures, area, perimeter, order)
      type(grid_type), intent(in) :: grid
      integer(i8), intent(in) :: measures(:, :)
      real(wp), allocatable, intent(out) :: area(:), perimeter(:)
      integer, allocatable, intent(out) :: order(:)
      real(wp) :: dx, dy
      integer :: k
      dx = grid%lx/grid%nx
      dy = grid%ly/grid%ny
      allocate (order(size(measures, 2)))
      do k = 1, size(order)
         order(k) = k
      end do
      call sort_by_count(order, measures(1, :))
      area = measures(1, order)*dx*dy
      perimeter = measures(2, order)*dy + measures(3, order)*dx
   end subroutine patch_statistics

   !> The patch of each of n labels joined by `pairs` (label a, label b, ...): numbered
   !> 1..n_patches in the order of their lowest label.
   subroutine join_labels(pairs, n, patch_of, n_patches)
      integer, intent(in) :: pairs(:), n
      integer, intent(out) :: patch_of(:), n_patches
      integer, allocatable :: parent(:)
      integer :: k, root
      allocate (parent(n))
      do k = 1, n
         parent(k) = k
      end do
      do k = 1, size(pairs) - 1, 2
         call unite(parent, pairs(k), pairs(k + 1))
      end do
      ! (unite keeps the lower root: a root is its patch's lowest label, met first here)
      n_patches = 0
      do k = 1, n
         root = find(parent, k)
         if (root == k) then
            n_patches = n_patches + 1
            patch_of(k) = n_patches
         else
            patch_of(k) = patch_of(root)
         end if
      end do
   end subroutine join_labels

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
      integer(i8), intent(in) :: count(:)
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
