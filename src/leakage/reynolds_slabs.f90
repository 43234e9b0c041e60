!> The Reynolds leakage (lc_leakage_reynolds, docs/leakage.md) of a surface shared among the
!> ranks of an MPI job, each holding a slab of rows of the gap (lc_base_slab): the same
!> equations, discretisation, clusters and stopping rule, solved on the slabs
!> (docs/decisions/026-distributed-patches-and-leakage.md).
!>
!> - Face conductances: each rank its cells' faces to the east and north, the row above its
!>   slab (the next rank's first, periodic) exchanged.
!> - Flow clusters: each rank finds its slab's clusters with their unwrapped x coordinates;
!>   the pairs of clusters that touch across the slabs' edges, with the number of periods
!>   the unwrapped coordinates differ by, are joined on rank 0 by a union-find that carries
!>   each cluster's offset: a pair that joins two clusters already joined at another offset
!>   closes a loop around the cell (along x, along y, or both). The clusters are numbered
!>   across the ranks in the order of their first cells, so the one pinned is the serial
!>   run's.
!> - The linear system: each rank owns the rows of its free cells, numbered across the
!>   ranks in grid order, in hypre's ParCSR matrix on the job's communicator; conjugate
!>   gradients with one V-cycle of hypre's distributed BoomerAMG, inner products summed over
!>   the ranks. BoomerAMG's coarsening differs on several ranks, so the iterations may too;
!>   k_eff meets the same tolerance.
!>
!> Every rank returns the whole result.
module lc_leakage_reynolds_slabs
   use, intrinsic :: iso_c_binding, only: c_int, c_double
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, input_error, code_internal
   use lc_base_strings, only: to_string
   use lc_base_parallel, only: global_sum, global_max, global_any, this_rank, rank_count, is_root
   use lc_base_slab_exchange, only: halo_rows, rank_counts, gather_integers, broadcast_integers, communicator_handle
   use lc_leakage_reynolds, only: leakage_flow, leakage_result, leakage_tol_allowed, leakage_tol_range, &
      & leakage_solver, leakage_memory_check, contact_threshold_relative, smallest_gap, cg_delay, amg_strength, &
      & hypre_out_of_memory, hypre_bytes_per_unknown, face_weights, flow_clusters, out_of_memory
   implicit none (type, external)
   private
   public :: reynolds_leakage_slab

   interface
      integer(c_int) function lc_hypre_setup_boomeramg_rows(comm, first, n, row_start, column, value, strength) &
         & bind(C)
         import :: c_int, c_double
         integer(c_int), value :: comm, first, n
         integer(c_int), intent(in) :: row_start(*), column(*)
         real(c_double), intent(in) :: value(*)
         real(c_double), value :: strength
      end function lc_hypre_setup_boomeramg_rows
      integer(c_int) function lc_hypre_matvec(x, y) bind(C)
         import :: c_int, c_double
         real(c_double), intent(in) :: x(*)
         real(c_double), intent(out) :: y(*)
      end function lc_hypre_matvec
      integer(c_int) function lc_hypre_apply(r, z) bind(C)
         import :: c_int, c_double
         real(c_double), intent(in) :: r(*)
         real(c_double), intent(out) :: z(*)
      end function lc_hypre_apply
      subroutine lc_hypre_free() bind(C)
      end subroutine lc_hypre_free
   end interface

contains

   !> k_eff along x and y of the gap whose slab of rows this rank holds (g, closed: its rows,
   !> x fastest, lc_base_slab) on the lx x ly cell of nx x ny points: the result of
   !> reynolds_leakage on the whole gap, on every rank. Called by every rank of the job.
   subroutine reynolds_leakage_slab(g, closed, nx, ny, lx, ly, tol, max_iter, result, error)
      real(wp), intent(in) :: g(:)
      logical, intent(in) :: closed(:)
      integer, intent(in) :: nx, ny, max_iter
      real(wp), intent(in) :: lx, ly, tol
      type(leakage_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: fluid(:), active_x(:), active_y(:), winds_x(:), winds_y(:), pinned(:)
      real(wp), allocatable :: east(:), north(:)
      integer, allocatable :: cluster(:)
      real(wp) :: threshold, hx, hy, cells
      integer(i8) :: start, finish, rate
      logical :: same, prepared
      integer :: stat

      call system_clock(start, rate)
      if (.not. leakage_tol_allowed(tol)) then
         call input_error(error, 'output', 'leakage_tol', to_string(tol), leakage_tol_range)
         return
      else if (max_iter < 1) then
         call fatal_error(error, 'leakage: max_iter = ' // to_string(max_iter) // ' is not allowed; allowed: >= 1', &
            & code_internal)
         return
      end if
      ! this rank's share: its slab's cells (a failure on some ranks only ends the job: the
      ! run's MPI_Abort, docs/clusters.md)
      call leakage_memory_check(size(g, kind=i8), 0, error)
      if (allocated(error)) return
      result%tol = tol
      result%solver = leakage_solver
      hx = lx/nx
      hy = ly/ny
      cells = real(nx, wp)*ny
      threshold = max(contact_threshold_relative*max(global_max(maxval(g)), 0.0_wp), smallest_gap)
      allocate (fluid(size(g)), active_x(size(g)), active_y(size(g)), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its cell masks', 3*size(g, kind=i8))
         return
      end if
      fluid = .not. closed .and. g > threshold
      result%fluid_fraction = global_sum(count(fluid))/cells
      call slab_face_weights(g, fluid, nx, hx, hy, east, north, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its face conductances', 24*size(g, kind=i8))
         return
      end if
      call slab_flow_clusters(fluid, nx, cluster, winds_x, winds_y, pinned, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its fluid clusters', 17*size(g, kind=i8))
         return
      end if
      active_x = fluid
      active_y = fluid
      where (fluid) active_x = winds_x(max(cluster, 1))
      where (fluid) active_y = winds_y(max(cluster, 1))
      same = .not. global_any(any(active_x .neqv. active_y))
      prepared = .false.
      call solve_direction(1, active_x, result%x)
      if (.not. allocated(error)) then
         if (.not. same) prepared = .false.
         call solve_direction(2, active_y, result%y)
      end if
      call lc_hypre_free()
      if (allocated(error)) return
      call system_clock(finish)
      result%wall_time = real(finish - start, wp)/real(rate, wp)

   contains

      subroutine solve_direction(direction, active, flow)
         integer, intent(in) :: direction
         logical, intent(in) :: active(:)
         type(leakage_flow), intent(out) :: flow
         flow%percolating = global_any(any(active))
         flow%connected_fraction = global_sum(count(active))/cells
         if (.not. flow%percolating) return
         call flow_solve_slab(direction, active, active .and. pinned, east, north, nx, cells, hx, hy, tol, &
            & max_iter, prepared, flow, error)
      end subroutine solve_direction
   end subroutine reynolds_leakage_slab

   !> The face conductances of this slab's cells to the east and north (face_weights on the
   !> slab and the row above it).
   subroutine slab_face_weights(g, fluid, nx, hx, hy, east, north, stat)
      real(wp), intent(in) :: g(:), hx, hy
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx
      real(wp), allocatable, intent(out) :: east(:), north(:)
      integer, intent(out) :: stat
      real(wp), allocatable :: open_gap(:), east_rows(:), north_rows(:)
      real(wp) :: below(nx), above(nx)
      integer :: n
      n = size(g)
      ! (the gap of the fluid cells of the row above, 0 where closed: fluid cells have g > 0)
      open_gap = merge(g, 0.0_wp, fluid)
      call halo_rows(open_gap, nx, below, above)
      call face_weights([g, above], [fluid, above > 0.0_wp], nx, n/nx + 1, hx, hy, east_rows, north_rows, stat)
      if (stat /= 0) return
      east = east_rows(:n)
      north = north_rows(:n)
   end subroutine slab_face_weights

   !> The flow clusters of the whole surface seen from this slab: cluster(k) this slab's
   !> cluster of cell k (0: closed), whether each winds around the cell along x and along y
   !> (winds_x, winds_y, by this slab's clusters), and pinned(k): cell k is the first of its
   !> cluster on the whole surface (grid order).
   subroutine slab_flow_clusters(fluid, nx, cluster, winds_x, winds_y, pinned, stat)
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx
      integer, allocatable, intent(out) :: cluster(:)
      logical, allocatable, intent(out) :: winds_x(:), winds_y(:), pinned(:)
      integer, intent(out) :: stat
      logical, allocatable :: local_x(:), local_y(:), seen(:)
      integer, allocatable :: ux(:), counts(:), edges(:), all_edges(:), flags(:), all_flags(:), codes(:)
      real(wp), allocatable :: values(:)
      real(wp) :: below(nx), cluster_above(nx), ux_above(nx)
      integer :: n_local, first, next_first, wrap, last, ix, k, n_edges, n_all

      call flow_clusters(fluid, nx, size(fluid)/nx, .false., cluster, local_x, local_y, stat, ux)
      if (stat /= 0) return
      n_local = 0
      if (size(cluster) > 0) n_local = maxval(cluster)
      where (cluster == 0) ux = 0
      ! the clusters of all ranks numbered one after the other: in the order of their first cells
      call rank_counts(n_local, counts)
      first = sum(counts(:this_rank() - 1))
      n_all = sum(counts)
      next_first = merge(0, first + n_local, this_rank() == rank_count() - 1)
      ! the edge above the last rank's slab is the periodic one: one period along y
      wrap = merge(1, 0, this_rank() == rank_count() - 1)
      values = real(cluster, wp)
      call halo_rows(values, nx, below, cluster_above)
      values = real(ux, wp)
      call halo_rows(values, nx, below, ux_above)
      deallocate (values)
      ! the pairs across the edge above: (cluster, cluster above, periods along x, along y)
      last = size(fluid) - nx
      allocate (edges(4*nx))
      n_edges = 0
      do ix = 1, nx
         k = last + ix
         if (cluster(k) == 0 .or. cluster_above(ix) <= 0.0_wp) cycle
         edges(n_edges + 1:n_edges + 4) = [first + cluster(k), next_first + nint(cluster_above(ix)), &
            & (ux(k) - nint(ux_above(ix)))/nx, wrap]
         n_edges = n_edges + 4
      end do
      flags = merge(1, 0, local_x(:n_local))
      call gather_integers(edges(:n_edges), all_edges)
      call gather_integers(flags, all_flags)
      allocate (codes(n_all))
      if (is_root()) call join_clusters(all_edges, all_flags, codes)
      call broadcast_integers(codes)
      ! codes: 1 winds along x, 2 along y, 4 the first cluster of its whole cluster
      allocate (winds_x(max(n_local, 1)), winds_y(max(n_local, 1)), pinned(size(fluid)), seen(max(n_local, 1)))
      winds_x = .false.
      winds_y = .false.
      do k = 1, n_local
         winds_x(k) = iand(codes(first + k), 1) /= 0
         winds_y(k) = iand(codes(first + k), 2) /= 0
      end do
      ! the first cell of the first cluster of each whole cluster is the one pinned
      seen = .false.
      pinned = .false.
      do k = 1, size(fluid)
         if (cluster(k) == 0) cycle
         if (seen(cluster(k))) cycle
         seen(cluster(k)) = .true.
         pinned(k) = iand(codes(first + cluster(k)), 4) /= 0
      end do
   end subroutine slab_flow_clusters

   !> Rank 0: the slabs' clusters (flags: 1 where one winds along x within its slab) joined by
   !> the pairs in `edges` (cluster a, cluster b, and the periods (px, py) by which a's
   !> unwrapped coordinates exceed b's at the cell they share); codes(k): 1 if k's whole
   !> cluster winds along x, 2 along y, 4 if k is its whole cluster's lowest (first) one.
   subroutine join_clusters(edges, flags, codes)
      integer, intent(in) :: edges(:), flags(:)
      integer, intent(out) :: codes(:)
      integer, allocatable :: parent(:), offset(:, :), winds(:)
      integer :: e, k, a, b, ra, rb, oa(2), ob(2), d(2)
      allocate (parent(size(codes)), offset(2, size(codes)))
      do k = 1, size(codes)
         parent(k) = k
      end do
      offset = 0
      winds = flags
      do e = 1, size(edges) - 3, 4
         a = edges(e)
         b = edges(e + 1)
         call find_offset(a, ra, oa)
         call find_offset(b, rb, ob)
         ! a point of b's coordinates is at p + ob in rb's and p + d + oa in ra's
         d = edges(e + 2:e + 3) + oa - ob
         if (ra == rb) then
            ! two paths between a and b at different offsets: a loop around the cell
            if (d(1) /= 0) winds(ra) = ior(winds(ra), 1)
            if (d(2) /= 0) winds(ra) = ior(winds(ra), 2)
         else if (ra < rb) then
            parent(rb) = ra
            offset(:, rb) = d
            winds(ra) = ior(winds(ra), winds(rb))
         else
            parent(ra) = rb
            offset(:, ra) = -d
            winds(rb) = ior(winds(rb), winds(ra))
         end if
      end do
      do k = 1, size(codes)
         call find_offset(k, ra, oa)
         codes(k) = winds(ra) + merge(4, 0, ra == k)
      end do

   contains

      !> The root of k and k's offset in its coordinates (offset(:, j): j's coordinates in
      !> its parent's are its own plus offset(:, j)), with the path compressed.
      subroutine find_offset(k, root, o)
         integer, intent(in) :: k
         integer, intent(out) :: root, o(2)
         integer :: j, next, step(2), rest(2)
         root = k
         o = 0
         do while (parent(root) /= root)
            o = o + offset(:, root)
            root = parent(root)
         end do
         j = k
         rest = o
         do while (parent(j) /= root .and. j /= root)
            next = parent(j)
            step = offset(:, j)
            parent(j) = root
            offset(:, j) = rest
            rest = rest - step
            j = next
         end do
      end subroutine find_offset
   end subroutine join_clusters

   !> Solve for phi along `direction` (1: x, 2: y) on the `active` cells of this slab (the
   !> `pinned` ones held at phi = 0) and set k_eff (as lc_leakage_reynolds' flow_solve, on the
   !> slabs).
   subroutine flow_solve_slab(direction, active, pinned, east, north, nx, cells, hx, hy, tol, max_iter, &
         & prepared, flow, error)
      integer, intent(in) :: direction, nx, max_iter
      logical, intent(in) :: active(:), pinned(:)
      real(wp), intent(in) :: east(:), north(:), cells, hx, hy, tol
      !> a preconditioner of this matrix is set up (the other direction's, same cells)
      logical, intent(inout) :: prepared
      type(leakage_flow), intent(inout) :: flow
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: we(:), wn(:), b(:), phi(:), r(:), z(:), p(:), q(:), decreases(:), phi_grid(:)
      real(wp), allocatable :: numbers(:)
      logical, allocatable :: free(:)
      integer, allocatable :: number(:), free_cells(:), counts(:)
      integer(c_int), allocatable :: row_start(:), column(:)
      real(c_double), allocatable :: value(:)
      real(wp) :: wn_below(nx), number_below(nx), number_above(nx), unused(nx)
      real(wp) :: jump_x, jump_y, rho, rho_next, alpha, bound, b_norm
      integer :: k, n_cells, n_free, first_row, iteration, status, stat, rows

      n_cells = size(active)
      rows = n_cells/nx
      allocate (we(n_cells), wn(n_cells), free(n_cells), number(n_cells), phi_grid(n_cells), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its weights and cell numbers', 33*int(n_cells, i8))
         return
      end if
      we = merge(east, 0.0_wp, active)
      wn = merge(north, 0.0_wp, active)
      jump_x = merge(hx, 0.0_wp, direction == 1)
      jump_y = merge(hy, 0.0_wp, direction == 2)
      free = active .and. .not. pinned
      n_free = count(free)
      ! the free cells numbered across the ranks in grid order (from 0, as hypre's rows)
      call rank_counts(n_free, counts)
      first_row = sum(counts(:this_rank() - 1))
      flow%unknowns = sum(counts)
      allocate (free_cells(n_free), b(n_free), phi(n_free), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its unknowns', 20*int(n_free, i8))
         return
      end if
      number = -1
      n_free = 0
      do k = 1, n_cells
         if (free(k)) then
            n_free = n_free + 1
            number(k) = first_row + n_free - 1
            free_cells(n_free) = k
         end if
      end do
      ! the neighbouring rows: their cells' numbers, and the north faces of the row below
      numbers = real(number, wp)
      call halo_rows(numbers, nx, number_below, number_above)
      deallocate (numbers)
      call halo_rows(wn, nx, wn_below, unused)
      call rhs_on_free_cells(b)
      phi = 0.0_wp
      b_norm = sqrt(global_sum(sum(b*b)))
      if (flow%unknowns == 0 .or. b_norm == 0.0_wp) then
         flow%k_eff = dissipation(phi)/cells
         return
      end if
      allocate (row_start(n_free + 1), column(5*n_free), value(5*n_free), r(n_free), z(n_free), p(n_free), &
         & q(n_free), decreases(max_iter), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its matrix and iteration vectors', 96*int(n_free, i8))
         return
      end if
      call assemble()
      if (.not. prepared) then
         status = lc_hypre_setup_boomeramg_rows(int(communicator_handle(), c_int), int(first_row, c_int), &
            & int(n_free, c_int), row_start, column, value, amg_strength)
         if (status == hypre_out_of_memory) then
            call out_of_memory(error, 'hypre''s BoomerAMG hierarchy', hypre_bytes_per_unknown*n_free)
            return
         else if (status /= 0) then
            call fatal_error(error, 'leakage: hypre''s BoomerAMG failed to set up (status ' // &
               & char(48 + min(status, 9)) // ')', code_internal)
            return
         end if
         prepared = .true.
      end if

      r = b
      call precondition(r, z)
      if (allocated(error)) return
      p = z
      rho = global_sum(sum(r*z))
      bound = dissipation(phi)
      flow%converged = .false.
      do iteration = 1, max_iter
         flow%iterations = iteration - 1
         if (rho <= 0.0_wp) then ! the residual vanished
            flow%converged = rho == 0.0_wp
            exit
         end if
         call apply_matrix(p, q)
         alpha = rho/global_sum(sum(p*q))
         phi = phi + alpha*p
         r = r - alpha*q
         decreases(iteration) = alpha*rho
         flow%iterations = iteration
         if (iteration >= cg_delay) then
            ! the dissipation only falls: a stale bound screens the test, a fresh one decides
            if (sum(decreases(iteration - cg_delay + 1:iteration)) <= tol*bound) then
               bound = dissipation(phi)
               if (sum(decreases(iteration - cg_delay + 1:iteration)) <= tol*bound) then
                  flow%converged = .true.
                  exit
               end if
            end if
         end if
         call precondition(r, z)
         if (allocated(error)) return
         rho_next = global_sum(sum(r*z))
         p = z + (rho_next/rho)*p
         rho = rho_next
      end do
      flow%k_eff = dissipation(phi)/cells
      call apply_matrix(phi, q)
      flow%residual = sqrt(global_sum(sum((b - q)**2)))/b_norm

   contains

      !> z = one V-cycle of BoomerAMG on r (an error if hypre reports a failure).
      subroutine precondition(r, z)
         real(wp), intent(in) :: r(:)
         real(wp), intent(out) :: z(:)
         integer(c_int) :: status
         status = lc_hypre_apply(r, z)
         if (status == hypre_out_of_memory) then
            z = 0.0_wp
            call out_of_memory(error, 'the work arrays of hypre''s V-cycle', hypre_bytes_per_unknown*size(r, kind=i8))
         else if (status /= 0) then
            z = 0.0_wp
            call fatal_error(error, 'leakage: hypre''s BoomerAMG failed to apply its V-cycle', code_internal)
         end if
      end subroutine precondition

      !> q = A v on this rank's free cells (hypre's distributed product).
      subroutine apply_matrix(v, q)
         real(wp), intent(in) :: v(:)
         real(wp), intent(out) :: q(:)
         if (lc_hypre_matvec(v, q) /= 0) q = 0.0_wp
      end subroutine apply_matrix

      !> The north face weight of the cell below cell k (column i, row j of the slab).
      real(wp) function south_weight(k, i, j)
         integer, intent(in) :: k, i, j
         if (j > 1) then
            south_weight = wn(k - nx)
         else
            south_weight = wn_below(i)
         end if
      end function south_weight

      !> The right-hand side on the free cells: the divergence of the face fluxes of the
      !> imposed jump.
      subroutine rhs_on_free_cells(b)
         real(wp), intent(out) :: b(:)
         integer :: i, j, k, m
         do m = 1, n_free
            k = free_cells(m)
            i = modulo(k - 1, nx) + 1
            j = (k - 1)/nx + 1
            b(m) = jump_x*(we(modulo(i - 2, nx) + 1 + (j - 1)*nx) - we(k)) + jump_y*(south_weight(k, i, j) - wn(k))
         end do
      end subroutine rhs_on_free_cells

      !> This rank's rows of the matrix on the free cells in CSR form (zero-based, global
      !> columns): the diagonal and the open faces to free neighbours, in the serial order.
      subroutine assemble()
         integer :: i, j, k, m, f, nnz, neighbours(4)
         real(wp) :: weights(4)
         nnz = 0
         do m = 1, n_free
            k = free_cells(m)
            i = modulo(k - 1, nx) + 1
            j = (k - 1)/nx + 1
            ! global numbers of the east, west, north and south neighbours (-1: not free)
            neighbours(1) = number(modulo(i, nx) + 1 + (j - 1)*nx)
            neighbours(2) = number(modulo(i - 2, nx) + 1 + (j - 1)*nx)
            if (j < rows) then
               neighbours(3) = number(k + nx)
            else
               neighbours(3) = nint(number_above(i))
            end if
            if (j > 1) then
               neighbours(4) = number(k - nx)
            else
               neighbours(4) = nint(number_below(i))
            end if
            weights = [we(k), we(modulo(i - 2, nx) + 1 + (j - 1)*nx), wn(k), south_weight(k, i, j)]
            row_start(m) = nnz
            nnz = nnz + 1
            column(nnz) = first_row + m - 1
            value(nnz) = sum(weights)
            do f = 1, 4
               if (weights(f) /= 0.0_wp .and. neighbours(f) >= 0) then
                  nnz = nnz + 1
                  column(nnz) = neighbours(f)
                  value(nnz) = -weights(f)
               end if
            end do
         end do
         row_start(n_free + 1) = nnz
      end subroutine assemble

      !> sum_faces w (phi - phi_next + jump)^2 over the whole surface: cells k_eff at the
      !> solution (phi zero at the pinned and inactive cells).
      real(wp) function dissipation(v) result(total)
         real(wp), intent(in) :: v(:)
         real(wp) :: phi_above(nx), phi_below(nx), dx, dy, next
         integer :: i, j, k
         phi_grid = 0.0_wp
         phi_grid(free_cells) = v
         call halo_rows(phi_grid, nx, phi_below, phi_above)
         total = 0.0_wp
         do j = 1, rows
            do i = 1, nx
               k = i + (j - 1)*nx
               if (j < rows) then
                  next = phi_grid(k + nx)
               else
                  next = phi_above(i)
               end if
               dx = phi_grid(k) - phi_grid(modulo(i, nx) + 1 + (j - 1)*nx) + jump_x
               dy = phi_grid(k) - next + jump_y
               total = total + we(k)*dx*dx + wn(k)*dy*dy
            end do
         end do
         total = global_sum(total)
      end function dissipation
   end subroutine flow_solve_slab
end module lc_leakage_reynolds_slabs
