!> Reynolds thin-film leakage through the gap of an areal contact: the effective conductance
!> k_eff along x and along y, the same discretisation as the Python `reynolds_leakage`
!> (docs/leakage.md). One solver for a process alone and for a surface shared among the
!> ranks of an MPI job, each holding a slab of rows of the gap (lc_base_slab; one rank: its
!> slab is the whole surface), every rank getting the whole result
!> (docs/decisions/026-distributed-patches-and-leakage.md).
!>
!> div(g^3 grad P) = 0 on the periodic cell; a mean pressure gradient -G is imposed along the
!> flow direction s, P = G (-s + phi) with phi periodic. k_eff = 12 eta <q_s>/G (L^3), g^3 for
!> a uniform gap. Finite volumes with the unknown at each grid point; the face conductance is
!> the harmonic mean of the two g^3 (zero on every face of a closed cell). Fluid cells connect
!> through faces only. Clusters that do not wind around the cell along the flow carry no net
!> flux and are removed; one cell of each remaining cluster is pinned (phi = 0), so the system
!> is symmetric positive definite.
!>
!> k_eff is the mean dissipation sum_faces w (phi - phi_next + jump)^2/N: equal to the mean
!> flux at the solution and above it by the squared energy norm of the solver error, a sum of
!> positive terms that stays accurate when k_eff is 1e-12 of <g^3> near percolation.
!>
!> Linear solver: conjugate gradients preconditioned by one V-cycle of hypre's BoomerAMG on
!> the free cells (chosen by measurement: docs/decisions/006-leakage-in-the-core.md),
!> stopped on the energy error of phi as in Python: the decrease of the energy over the last
!> five iterations (Strakos and Tichy's lower bound of the error) below tol times the
!> dissipation, so tol is the relative accuracy of k_eff.
!>
!> On the slabs (what crosses their edges: lc_base_slab_exchange; one rank exchanges with
!> itself, its slab's edge rows being the periodic neighbours):
!> - Face conductances: each rank its cells' faces to the east and north, the row above its
!>   slab (the next rank's first, periodic) exchanged.
!> - Flow clusters: each rank finds its slab's clusters with their unwrapped x coordinates;
!>   the pairs of clusters that touch across the slabs' edges (the periodic edge along y
!>   included), with the number of periods the unwrapped coordinates differ by, are joined
!>   on rank 0 by a union-find that carries each cluster's offset: a pair that joins two
!>   clusters already joined at another offset closes a loop around the cell (along x, along
!>   y, or both). The clusters are numbered across the ranks in the order of their first
!>   cells, so the cell pinned is the first of its whole cluster whatever the rank count.
!> - The linear system: each rank owns the rows of its free cells, numbered across the
!>   ranks in grid order, in hypre's ParCSR matrix on the job's communicator (MPI_COMM_SELF
!>   on one rank) for the V-cycle; the matrix product is done here, row by row, with the
!>   neighbouring rows' values exchanged (on one rank the serial order of the sums, so its
!>   results are those of the whole-gap solver it replaced, to the bit); inner products
!>   summed over the ranks. BoomerAMG's coarsening differs on several ranks, so the
!>   iterations may too; k_eff meets the same tolerance.
module lc_leakage_reynolds
   use, intrinsic :: iso_c_binding, only: c_int, c_double
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, input_error, code_internal
   use lc_base_strings, only: to_string
   use lc_base_memory, only: check_leakage_memory
   use lc_base_parallel, only: global_sum, global_max, global_any, this_rank, rank_count, is_root
   use lc_base_slab_exchange, only: halo_rows, rank_counts, gather_integers, broadcast_integers, communicator_handle
   implicit none (type, external)
   private
   public :: leakage_flow, leakage_result, reynolds_leakage, leakage_tol_allowed, leakage_tol_range, &
      & leakage_max_iter, leakage_solver, leakage_memory_check, smallest_leakage_tol, largest_leakage_tol
   !> The tolerances allowed for &output leakage_tol (the relative accuracy of k_eff).
   real(wp), parameter :: smallest_leakage_tol = 1.0e-14_wp, largest_leakage_tol = 1.0e-2_wp
   character(len=*), parameter :: leakage_tol_range = '1e-14 <= leakage_tol <= 1e-2'
   !> CG iterations per direction of a run's leakage: one that has not met tol by then is
   !> reported as not converged (k_eff is then an upper bound); well above the iterations
   !> taken near percolation (docs/numerics.md, 'Constants of the solvers and their
   !> measurements').
   integer, parameter :: leakage_max_iter = 500
   !> What solves the flow (recorded in results).
   character(len=*), parameter :: leakage_solver = 'cg + hypre BoomerAMG'
   !> Default contact threshold relative to the largest gap: a converged contact solve leaves
   !> residual gaps of about 1e-8 of the largest gap in contact, and a cell at 1e-6 of it
   !> conducts 1e-18 of the largest cell, far below any solver tolerance.
   real(wp), parameter :: contact_threshold_relative = 1.0e-6_wp
   !> Gaps below this are closed whatever the threshold: above it g^3, 1/g^3 and their sums
   !> are normal floats, so a face between two open cells never conducts zero.
   real(wp), parameter :: smallest_gap = 1.0e-100_wp
   !> Iterations over which the energy decrease estimates the error (as in Python).
   integer, parameter :: cg_delay = 5
   !> BoomerAMG strength threshold: hypre's default for 2D Laplacians; 0.5 took more CG
   !> iterations and more time near percolation (docs/decisions/006-leakage-in-the-core.md).
   real(c_double), parameter :: amg_strength = 0.25_c_double
   !> lc_hypre_setup_boomeramg_rows' status when memory ran out (hypre_amg.c)
   integer(c_int), parameter :: hypre_out_of_memory = 3_c_int
   !> bytes of hypre's matrix and hierarchy per unknown that hypre_amg.c makes sure of before
   !> the setup (LC_HYPRE_BYTES_PER_UNKNOWN there), for messages
   integer(i8), parameter :: hypre_bytes_per_unknown = 160_i8

   !> The flow along one direction.
   type :: leakage_flow
      real(wp) :: k_eff = 0.0_wp             !< 12 eta <q_s>/G (L^3)
      logical :: percolating = .false.       !< a fluid cluster winds around the cell along s
      real(wp) :: connected_fraction = 0.0_wp !< cells of the flow-carrying clusters
      integer :: unknowns = 0                 !< size of the linear system
      integer :: iterations = 0               !< CG iterations
      real(wp) :: residual = 0.0_wp           !< ||b - A phi||/||b||
      logical :: converged = .true.
   end type leakage_flow

   !> Both directions and what they share.
   type :: leakage_result
      type(leakage_flow) :: x, y
      real(wp) :: fluid_fraction = 0.0_wp    !< cells with a gap (not in contact)
      real(wp) :: tol = 0.0_wp               !< relative accuracy of k_eff asked for
      character(len=32) :: solver = ''       !< the preconditioned CG that ran
      real(wp) :: wall_time = 0.0_wp         !< seconds
   end type leakage_result

   interface
      integer(c_int) function lc_hypre_mpi_started() bind(C)
         import :: c_int
      end function lc_hypre_mpi_started
      integer(c_int) function lc_hypre_setup_boomeramg_rows(comm, first, n, row_start, column, value, strength) &
         & bind(C)
         import :: c_int, c_double
         integer(c_int), value :: comm, first, n
         integer(c_int), intent(in) :: row_start(*), column(*)
         real(c_double), intent(in) :: value(*)
         real(c_double), value :: strength
      end function lc_hypre_setup_boomeramg_rows
      integer(c_int) function lc_hypre_apply(r, z) bind(C)
         import :: c_int, c_double
         real(c_double), intent(in) :: r(*)
         real(c_double), intent(out) :: z(*)
      end function lc_hypre_apply
      subroutine lc_hypre_free() bind(C)
      end subroutine lc_hypre_free
   end interface

contains

   !> k_eff along x and y of the gap g on the lx x ly cell of nx x ny points. g, closed: this
   !> rank's slab of rows (x fastest, lc_base_slab), the whole gap on one rank. Cells with
   !> closed(j) or g <= 1e-6 max(g) are in contact. tol: relative accuracy of k_eff. Called by
   !> every rank of the job; each gets the whole result.
   subroutine reynolds_leakage(g, closed, nx, ny, lx, ly, tol, max_iter, result, error)
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
      ! a gap too large for the memory left ends here (code 5), before MPI starts or anything
      ! is allocated; distributed: this rank's slab (a failure on some ranks only ends the
      ! job: the run's MPI_Abort, docs/clusters.md)
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
      call face_weights(g, fluid, nx, hx, hy, east, north, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its face conductances', 24*size(g, kind=i8))
         return
      end if
      call flow_clusters(fluid, nx, cluster, winds_x, winds_y, pinned, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its fluid clusters', 17*size(g, kind=i8))
         return
      end if
      active_x = fluid
      active_y = fluid
      where (fluid) active_x = winds_x(max(cluster, 1))
      where (fluid) active_y = winds_y(max(cluster, 1))
      ! the matrix depends on the flow-carrying cells only, not on the direction: one
      ! preconditioner serves both when they are the same on every rank
      same = .not. global_any(any(active_x .neqv. active_y))
      prepared = .false.
      call solve_direction(1, active_x, result%x)
      if (.not. allocated(error)) then
         if (.not. same) prepared = .false.
         call solve_direction(2, active_y, result%y)
      end if
      ! (hypre's matrix, vectors and hierarchy are freed on every path)
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
         call flow_solve(direction, active, pinned, east, north, nx, cells, hx, hy, tol, max_iter, prepared, &
            & flow, error)
      end subroutine solve_direction
   end subroutine reynolds_leakage

   !> c/h^2 of the face from each cell of this slab to its east (+x) and north (+y) neighbour:
   !> the harmonic mean of the two g^3, zero when either cell is closed; the north faces of
   !> the slab's last row reach the row above it (the next rank's first, periodic).
   subroutine face_weights(g, fluid, nx, hx, hy, east, north, stat)
      real(wp), intent(in) :: g(:), hx, hy
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx
      real(wp), allocatable, intent(out) :: east(:), north(:)
      !> nonzero: an allocation failed (nothing computed)
      integer, intent(out) :: stat
      real(wp), allocatable :: resistance(:)
      real(wp) :: edge_rows(2*nx), below(nx), above(nx), resistance_next
      integer :: i, j, k, ke, rows
      rows = size(g)/nx
      allocate (resistance(size(g)), east(size(g)), north(size(g)), stat=stat)
      if (stat /= 0) return
      where (fluid)
         resistance = 1.0_wp/(g*g*g)
      elsewhere
         resistance = 0.0_wp
      end where
      ! the row above: its cells' resistances, -1 where closed; only the slab's edge rows are
      ! exchanged
      edge_rows(:nx) = merge(resistance(:nx), -1.0_wp, fluid(:nx))
      edge_rows(nx + 1:) = merge(resistance(size(g) - nx + 1:), -1.0_wp, fluid(size(g) - nx + 1:))
      call halo_rows(edge_rows, nx, below, above)
      do j = 1, rows
         do i = 1, nx
            k = i + (j - 1)*nx
            ke = modulo(i, nx) + 1 + (j - 1)*nx
            east(k) = 0.0_wp
            north(k) = 0.0_wp
            ! in series: c = 2/(r + r_next) with r = 1/g^3
            if (fluid(k) .and. fluid(ke)) east(k) = 2.0_wp/(resistance(k) + resistance(ke))/(hx*hx)
            if (j < rows) then
               if (fluid(k) .and. fluid(k + nx)) north(k) = 2.0_wp/(resistance(k) + resistance(k + nx))/(hy*hy)
            else
               resistance_next = above(i)
               if (fluid(k) .and. resistance_next >= 0.0_wp) &
                  & north(k) = 2.0_wp/(resistance(k) + resistance_next)/(hy*hy)
            end if
         end do
      end do
   end subroutine face_weights

   !> The flow clusters of the whole surface seen from this slab: cluster(k) this slab's
   !> cluster of cell k (0: closed), whether each winds around the cell along x and along y
   !> (winds_x, winds_y, by this slab's clusters), and pinned(k): cell k is the first of its
   !> cluster on the whole surface (grid order).
   subroutine flow_clusters(fluid, nx, cluster, winds_x, winds_y, pinned, stat)
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx
      integer, allocatable, intent(out) :: cluster(:)
      logical, allocatable, intent(out) :: winds_x(:), winds_y(:), pinned(:)
      integer, intent(out) :: stat
      logical, allocatable :: local_x(:), seen(:)
      integer, allocatable :: ux(:), counts(:), edges(:), all_edges(:), flags(:), all_flags(:), codes(:)
      real(wp) :: edge_rows(2*nx), below(nx), cluster_above(nx), ux_above(nx)
      integer :: n_local, first, next_first, wrap, last, ix, k, n_edges, n_all

      call slab_clusters(fluid, nx, cluster, n_local, local_x, ux, stat)
      if (stat /= 0) return
      where (cluster == 0) ux = 0
      ! the clusters of all ranks numbered one after the other: in the order of their first cells
      call rank_counts(n_local, counts)
      first = sum(counts(:this_rank() - 1))
      n_all = sum(counts)
      next_first = merge(0, first + n_local, this_rank() == rank_count() - 1)
      ! the edge above the last rank's slab is the periodic one: one period along y
      wrap = merge(1, 0, this_rank() == rank_count() - 1)
      ! the first row of the slab above: its clusters and unwrapped x (only the edge rows are
      ! exchanged; integers below 2^53 are exact as doubles)
      last = size(fluid) - nx
      edge_rows(:nx) = real(cluster(:nx), wp)
      edge_rows(nx + 1:) = real(cluster(last + 1:), wp)
      call halo_rows(edge_rows, nx, below, cluster_above)
      edge_rows(:nx) = real(ux(:nx), wp)
      edge_rows(nx + 1:) = real(ux(last + 1:), wp)
      call halo_rows(edge_rows, nx, below, ux_above)
      ! the pairs across the edge above: (cluster, cluster above, periods along x, along y)
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
   end subroutine flow_clusters

   !> The fluid clusters of this slab (4-connected, periodic along x, the slab's first and last
   !> rows ends) by a breadth-first search that carries each cell's unwrapped x coordinate
   !> (ux, 0-based): an edge that reaches a labelled cell at another unwrapped coordinate
   !> closes a loop around the cell along x. Every loop is a sum of the loops the edges
   !> outside the search tree close, so a cluster winds along x within the slab exactly when
   !> one of its edges says so (winds_x). Labels 1 .. n_labels in the order of their first
   !> cells (x fastest); cluster(k) = 0 for a closed cell.
   pure subroutine slab_clusters(fluid, nx, cluster, n_labels, winds_x, ux, stat)
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx
      integer, allocatable, intent(out) :: cluster(:), ux(:)
      integer, intent(out) :: n_labels
      logical, allocatable, intent(out) :: winds_x(:)
      !> nonzero: an allocation failed
      integer, intent(out) :: stat
      integer, allocatable :: queue(:)
      logical, allocatable :: winds(:)
      integer, parameter :: step_x(4) = [1, -1, 0, 0], step_y(4) = [0, 0, 1, -1]
      integer :: seed, head, tail, k, m, i, j, ni, nj, next, rows
      n_labels = 0
      rows = size(fluid)/nx
      allocate (cluster(size(fluid)), queue(size(fluid)), ux(size(fluid)), winds(size(fluid)/2 + 1), stat=stat)
      if (stat /= 0) return
      cluster = 0
      winds = .false.
      do seed = 1, size(fluid)
         if (.not. fluid(seed) .or. cluster(seed) /= 0) cycle
         n_labels = n_labels + 1
         cluster(seed) = n_labels
         ux(seed) = modulo(seed - 1, nx)
         head = 1
         tail = 1
         queue(1) = seed
         do while (head <= tail)
            k = queue(head)
            head = head + 1
            i = modulo(k - 1, nx)
            j = (k - 1)/nx
            do m = 1, 4
               nj = j + step_y(m)
               if (nj < 0 .or. nj >= rows) cycle
               ni = modulo(i + step_x(m), nx)
               next = ni + nj*nx + 1
               if (.not. fluid(next)) cycle
               if (cluster(next) == 0) then
                  cluster(next) = n_labels
                  ux(next) = ux(k) + step_x(m)
                  tail = tail + 1
                  queue(tail) = next
               else if (ux(next) /= ux(k) + step_x(m)) then
                  winds(n_labels) = .true.
               end if
            end do
         end do
      end do
      allocate (winds_x(max(n_labels, 1)), stat=stat)
      if (stat /= 0) return
      winds_x = winds(:max(n_labels, 1))
   end subroutine slab_clusters

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

   !> Solve for phi along `direction` (1: x, 2: y) on the `active` cells of this slab (those
   !> `pinned` held at phi = 0) and set k_eff; `cells` on the whole surface.
   subroutine flow_solve(direction, active, pinned, east, north, nx, cells, hx, hy, tol, max_iter, &
         & prepared, flow, error)
      integer, intent(in) :: direction, nx, max_iter
      logical, intent(in) :: active(:), pinned(:)
      real(wp), intent(in) :: east(:), north(:), cells, hx, hy, tol
      !> a preconditioner of this matrix is set up (the other direction's, same cells)
      logical, intent(inout) :: prepared
      type(leakage_flow), intent(inout) :: flow
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: we(:), wn(:), b(:), phi(:), r(:), z(:), p(:), q(:), decreases(:), phi_grid(:)
      logical, allocatable :: free(:)
      integer, allocatable :: number(:), free_cells(:), counts(:)
      integer(c_int), allocatable :: row_start(:), column(:)
      real(c_double), allocatable :: value(:)
      real(wp) :: edge_rows(2*nx), wn_below(nx), number_below(nx), number_above(nx), unused(nx)
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
      edge_rows(:nx) = real(number(:nx), wp)
      edge_rows(nx + 1:) = real(number(n_cells - nx + 1:), wp)
      call halo_rows(edge_rows, nx, number_below, number_above)
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
      call assemble(.true.)
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
      ! (hypre holds its copy: the columns from here on index this rank's values, then the
      ! neighbouring rows', for the product in Fortran)
      call assemble(.false.)

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

      !> q = A v on this rank's free cells, with the values of the free cells of the rows next
      !> to the slab (exchanged; one rank: its own edge rows), each row summed in the order of
      !> its entries (the diagonal, east, west, north, south).
      subroutine apply_matrix(v, q)
         real(wp), intent(in) :: v(:)
         real(wp), intent(out) :: q(:)
         real(wp) :: halo(2*nx)
         integer :: i, m, e, c
         do i = 1, nx
            edge_rows(i) = 0.0_wp
            edge_rows(nx + i) = 0.0_wp
            if (free(i)) edge_rows(i) = v(number(i) - first_row + 1)
            if (free(n_cells - nx + i)) edge_rows(nx + i) = v(number(n_cells - nx + i) - first_row + 1)
         end do
         ! halo: the row below, then the row above
         call halo_rows(edge_rows, nx, halo(:nx), halo(nx + 1:))
         do m = 1, n_free
            q(m) = 0.0_wp
            do e = row_start(m) + 1, row_start(m + 1)
               c = column(e)
               if (c <= n_free) then
                  q(m) = q(m) + value(e)*v(c)
               else
                  q(m) = q(m) + value(e)*halo(c - n_free)
               end if
            end do
         end do
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

      !> This rank's rows of the matrix on the free cells in CSR form (zero-based row
      !> starts): the diagonal and the open faces to free neighbours, in the serial order.
      !> Columns: global and zero-based (hypre's), or (global false) one-based: this rank's
      !> free cells, then n_free + x for the row below the slab and n_free + nx + x above.
      subroutine assemble(global)
         logical, intent(in) :: global
         integer :: i, j, k, m, f, nnz, neighbours(4), columns(4), diagonal
         real(wp) :: weights(4)
         nnz = 0
         do m = 1, n_free
            k = free_cells(m)
            i = modulo(k - 1, nx) + 1
            j = (k - 1)/nx + 1
            ! global numbers of the east, west, north and south neighbours (-1: not free)
            neighbours(1) = number(modulo(i, nx) + 1 + (j - 1)*nx)
            neighbours(2) = number(modulo(i - 2, nx) + 1 + (j - 1)*nx)
            columns(1:2) = neighbours(1:2) - first_row + 1
            if (j < rows) then
               neighbours(3) = number(k + nx)
               columns(3) = neighbours(3) - first_row + 1
            else
               neighbours(3) = nint(number_above(i))
               columns(3) = n_free + nx + i
            end if
            if (j > 1) then
               neighbours(4) = number(k - nx)
               columns(4) = neighbours(4) - first_row + 1
            else
               neighbours(4) = nint(number_below(i))
               columns(4) = n_free + i
            end if
            if (global) then
               columns = neighbours
               diagonal = first_row + m - 1
            else
               diagonal = m
            end if
            weights = [we(k), we(modulo(i - 2, nx) + 1 + (j - 1)*nx), wn(k), south_weight(k, i, j)]
            row_start(m) = nnz
            nnz = nnz + 1
            column(nnz) = diagonal
            value(nnz) = sum(weights)
            do f = 1, 4
               if (weights(f) /= 0.0_wp .and. neighbours(f) >= 0) then
                  nnz = nnz + 1
                  column(nnz) = columns(f)
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
   end subroutine flow_solve
   !> Error code 5 if the leakage of `points` cells, with `resident` more doubles per cell
   !> allocated meanwhile, needs more memory than this process may use (lc_base_memory).
   subroutine leakage_memory_check(points, resident, error)
      integer(i8), intent(in) :: points
      integer, intent(in) :: resident
      type(error_type), allocatable, intent(out) :: error
      call check_leakage_memory(points, resident, lc_hypre_mpi_started() /= 0, error)
   end subroutine leakage_memory_check

   !> Error code 5 for an allocation of the leakage that failed: `what` it was for and about
   !> how many bytes it asked.
   pure subroutine out_of_memory(error, what, bytes)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: what
      integer(i8), intent(in) :: bytes
      call fatal_error(error, 'not enough memory: the leakage could not allocate ' // what // ' (' // &
         & to_string(bytes) // ' bytes); allowed: a smaller grid, &output leakage = .false., or a machine ' // &
         & 'or job with more memory (Slurm: --mem)', code_internal)
   end subroutine out_of_memory

   !> True for a tolerance in leakage_tol_range (false for NaN).
   pure logical function leakage_tol_allowed(tol)
      real(wp), intent(in) :: tol
      leakage_tol_allowed = tol >= smallest_leakage_tol .and. tol <= largest_leakage_tol
   end function leakage_tol_allowed
end module lc_leakage_reynolds
