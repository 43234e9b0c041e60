!> Reynolds thin-film leakage through the gap of an areal contact: the effective conductance
!> k_eff along x and along y, the same discretisation as the Python `reynolds_leakage`
!> (docs/leakage.md).
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
module lc_leakage_reynolds
   use, intrinsic :: iso_c_binding, only: c_int, c_double
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, input_error, code_internal
   use lc_base_strings, only: to_string
   use lc_base_memory, only: check_leakage_memory
   implicit none (type, external)
   private
   public :: leakage_flow, leakage_result, reynolds_leakage, leakage_tol_allowed, leakage_tol_range, &
      & leakage_max_iter, leakage_solver, leakage_memory_check, smallest_leakage_tol, largest_leakage_tol
   ! (shared with the leakage on the slabs of a distributed surface, lc_leakage_reynolds_slabs)
   public :: contact_threshold_relative, smallest_gap, cg_delay, amg_strength, hypre_out_of_memory, &
      & hypre_bytes_per_unknown, face_weights, flow_clusters, out_of_memory
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
   !> lc_hypre_setup_boomeramg's status when memory ran out (hypre_amg.c)
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
      integer(c_int) function lc_hypre_setup_boomeramg(n, row_start, column, value, strength) bind(C)
         import :: c_int, c_double
         integer(c_int), value :: n
         integer(c_int), intent(in) :: row_start(*), column(*)
         real(c_double), intent(in) :: value(*)
         real(c_double), value :: strength
      end function lc_hypre_setup_boomeramg
      integer(c_int) function lc_hypre_mpi_started() bind(C)
         import :: c_int
      end function lc_hypre_mpi_started
      integer(c_int) function lc_hypre_apply(r, z) bind(C)
         import :: c_int, c_double
         real(c_double), intent(in) :: r(*)
         real(c_double), intent(out) :: z(*)
      end function lc_hypre_apply
      subroutine lc_hypre_free() bind(C)
      end subroutine lc_hypre_free
   end interface

contains

   !> k_eff along x and y of the gap g (nx*ny, x fastest) of the lx x ly cell. Cells with
   !> closed(j) or g <= 1e-6 max(g) are in contact. tol: relative accuracy of k_eff.
   subroutine reynolds_leakage(g, closed, nx, ny, lx, ly, tol, max_iter, result, error)
      real(wp), intent(in) :: g(:)
      logical, intent(in) :: closed(:)
      integer, intent(in) :: nx, ny, max_iter
      real(wp), intent(in) :: lx, ly, tol
      type(leakage_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: fluid(:), active_x(:), active_y(:)
      real(wp), allocatable :: east(:), north(:)
      integer, allocatable :: cluster(:)
      logical, allocatable :: winds_x(:), winds_y(:)
      real(wp) :: threshold, hx, hy
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
      ! a gap too large for the memory left ends here (code 5), before MPI starts or
      ! anything is allocated
      call leakage_memory_check(size(g, kind=i8), 0, error)
      if (allocated(error)) return
      result%tol = tol
      result%solver = leakage_solver
      hx = lx/nx
      hy = ly/ny
      threshold = max(contact_threshold_relative*max(maxval(g), 0.0_wp), smallest_gap)
      allocate (fluid(size(g)), active_x(size(g)), active_y(size(g)), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its cell masks', 3*size(g, kind=i8))
         return
      end if
      fluid = .not. closed .and. g > threshold
      result%fluid_fraction = real(count(fluid), wp)/size(g)
      call face_weights(g, fluid, nx, ny, hx, hy, east, north, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its face conductances', 24*size(g, kind=i8))
         return
      end if
      call flow_clusters(fluid, nx, ny, .true., cluster, winds_x, winds_y, stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its fluid clusters', 17*size(g, kind=i8))
         return
      end if
      active_x = fluid
      active_y = fluid
      where (fluid) active_x = winds_x(max(cluster, 1))
      where (fluid) active_y = winds_y(max(cluster, 1))
      ! the matrix depends on the flow-carrying cells only, not on the direction: one
      ! preconditioner serves both when they are the same
      same = all(active_x .eqv. active_y)
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
         flow%percolating = any(active)
         flow%connected_fraction = real(count(active), wp)/size(g)
         if (.not. flow%percolating) return
         call flow_solve(direction, active, cluster, east, north, nx, ny, hx, hy, tol, max_iter, &
            & prepared, flow, error)
      end subroutine solve_direction
   end subroutine reynolds_leakage

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

   !> c/h^2 of the face from each cell to its east (+x) and north (+y) neighbour: the harmonic
   !> mean of the two g^3, zero when either cell is closed.
   pure subroutine face_weights(g, fluid, nx, ny, hx, hy, east, north, stat)
      real(wp), intent(in) :: g(:), hx, hy
      logical, intent(in) :: fluid(:)
      integer, intent(in) :: nx, ny
      real(wp), allocatable, intent(out) :: east(:), north(:)
      !> nonzero: an allocation failed (nothing computed)
      integer, intent(out) :: stat
      real(wp), allocatable :: resistance(:)
      integer :: i, j, k, ke, kn
      allocate (resistance(size(g)), east(size(g)), north(size(g)), stat=stat)
      if (stat /= 0) return
      where (fluid)
         resistance = 1.0_wp/(g*g*g)
      elsewhere
         resistance = 0.0_wp
      end where
      do j = 1, ny
         do i = 1, nx
            k = i + (j - 1)*nx
            ke = modulo(i, nx) + 1 + (j - 1)*nx
            kn = i + modulo(j, ny)*nx
            east(k) = 0.0_wp
            north(k) = 0.0_wp
            ! in series: c = 2/(r + r_next) with r = 1/g^3
            if (fluid(k) .and. fluid(ke)) east(k) = 2.0_wp/(resistance(k) + resistance(ke))/(hx*hx)
            if (fluid(k) .and. fluid(kn)) north(k) = 2.0_wp/(resistance(k) + resistance(kn))/(hy*hy)
         end do
      end do
   end subroutine face_weights

   !> Fluid clusters (4-connected, periodic) by a breadth-first search that carries each
   !> cell's unwrapped coordinates: an edge that reaches a labelled cell at other unwrapped
   !> coordinates closes a loop around the cell, along x when the x coordinates differ. Every
   !> loop is a sum of the loops the edges outside the search tree close, so the cluster winds
   !> along x exactly when one of its edges says so. On a slab of rows (periodic_y false:
   !> no edge between the last row and the first) the clusters are those of the slab.
   pure subroutine flow_clusters(fluid, nx, ny, periodic_y, cluster, winds_x, winds_y, stat, unwrapped_x)
      logical, intent(in) :: fluid(:), periodic_y
      integer, intent(in) :: nx, ny
      integer, allocatable, intent(out) :: cluster(:)
      logical, allocatable, intent(out) :: winds_x(:), winds_y(:)
      !> nonzero: an allocation failed
      integer, intent(out) :: stat
      !> each cell's unwrapped x coordinate (0-based) along its cluster's search
      integer, allocatable, intent(out), optional :: unwrapped_x(:)
      integer, allocatable :: queue(:), ux(:), uy(:)
      logical, allocatable :: winds(:, :)
      integer, parameter :: step_x(4) = [1, -1, 0, 0], step_y(4) = [0, 0, 1, -1]
      integer :: seed, head, tail, k, m, i, j, ni, nj, next, label, n_labels
      allocate (cluster(size(fluid)), queue(size(fluid)), ux(size(fluid)), uy(size(fluid)), &
         & winds(2, size(fluid)/2 + 1), stat=stat)
      if (stat /= 0) return
      cluster = 0
      winds = .false.
      n_labels = 0
      do seed = 1, size(fluid)
         if (.not. fluid(seed) .or. cluster(seed) /= 0) cycle
         n_labels = n_labels + 1
         label = n_labels
         cluster(seed) = label
         ux(seed) = modulo(seed - 1, nx)
         uy(seed) = (seed - 1)/nx
         head = 1
         tail = 1
         queue(1) = seed
         do while (head <= tail)
            k = queue(head)
            head = head + 1
            i = modulo(k - 1, nx)
            j = (k - 1)/nx
            do m = 1, 4
               if (.not. periodic_y .and. (j + step_y(m) < 0 .or. j + step_y(m) >= ny)) cycle
               ni = modulo(i + step_x(m), nx)
               nj = modulo(j + step_y(m), ny)
               next = ni + nj*nx + 1
               if (.not. fluid(next)) cycle
               if (cluster(next) == 0) then
                  cluster(next) = label
                  ux(next) = ux(k) + step_x(m)
                  uy(next) = uy(k) + step_y(m)
                  tail = tail + 1
                  queue(tail) = next
               else
                  if (ux(next) /= ux(k) + step_x(m)) winds(1, label) = .true.
                  if (uy(next) /= uy(k) + step_y(m)) winds(2, label) = .true.
               end if
            end do
         end do
      end do
      allocate (winds_x(max(n_labels, 1)), winds_y(max(n_labels, 1)), stat=stat)
      if (stat /= 0) return
      winds_x = winds(1, :max(n_labels, 1))
      winds_y = winds(2, :max(n_labels, 1))
      if (present(unwrapped_x)) call move_alloc(ux, unwrapped_x)
   end subroutine flow_clusters

   !> Solve for phi along `direction` (1: x, 2: y) on the `active` cells and set k_eff.
   subroutine flow_solve(direction, active, cluster, east, north, nx, ny, hx, hy, tol, max_iter, &
         & prepared, flow, error)
      integer, intent(in) :: direction, nx, ny, max_iter
      logical, intent(in) :: active(:)
      !> a preconditioner of this matrix is set up (the other direction's, same cells)
      logical, intent(inout) :: prepared
      integer, intent(in) :: cluster(:)
      real(wp), intent(in) :: east(:), north(:), hx, hy, tol
      type(leakage_flow), intent(inout) :: flow
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: we(:), wn(:), b(:), phi(:), r(:), z(:), p(:), q(:), decreases(:)
      real(wp), allocatable :: phi_grid(:)
      logical, allocatable :: free(:), pinned_cluster(:)
      integer, allocatable :: number(:), free_cells(:)
      integer(c_int), allocatable :: row_start(:), column(:)
      real(c_double), allocatable :: value(:)
      real(wp) :: jump_x, jump_y, rho, rho_next, alpha, bound, b_norm
      integer :: k, n_cells, n_free, iteration, status, stat

      n_cells = size(active)
      ! weights restricted to the flow-carrying clusters: an open face joins two cells of one
      ! cluster, so these are exactly its faces
      allocate (we(n_cells), wn(n_cells), free(n_cells), pinned_cluster(maxval(cluster)), number(n_cells), &
         & phi_grid(n_cells), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its weights and cell numbers', 33*int(n_cells, i8))
         return
      end if
      we = merge(east, 0.0_wp, active)
      wn = merge(north, 0.0_wp, active)
      jump_x = merge(hx, 0.0_wp, direction == 1)
      jump_y = merge(hy, 0.0_wp, direction == 2)
      ! pin the first cell of each flow-carrying cluster
      pinned_cluster = .false.
      free = active
      do k = 1, n_cells
         if (active(k)) then
            if (.not. pinned_cluster(cluster(k))) then
               pinned_cluster(cluster(k)) = .true.
               free(k) = .false.
            end if
         end if
      end do
      n_free = count(free)
      flow%unknowns = n_free
      allocate (free_cells(n_free), b(n_free), phi(n_free), stat=stat)
      if (stat /= 0) then
         call out_of_memory(error, 'its unknowns', 20*int(n_free, i8))
         return
      end if
      number = 0
      n_free = 0
      do k = 1, n_cells
         if (free(k)) then
            n_free = n_free + 1
            number(k) = n_free
            free_cells(n_free) = k
         end if
      end do
      ! b = -D^T W j: the jump on the faces along the flow
      call rhs_on_free_cells(b)
      phi = 0.0_wp
      b_norm = sqrt(sum(b*b))
      if (n_free == 0 .or. b_norm == 0.0_wp) then
         flow%k_eff = dissipation(phi)/n_cells
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
         status = lc_hypre_setup_boomeramg(int(n_free, c_int), row_start, column, value, amg_strength)
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
      rho = sum(r*z)
      bound = dissipation(phi)
      flow%converged = .false.
      do iteration = 1, max_iter
         flow%iterations = iteration - 1
         if (rho <= 0.0_wp) then ! the residual vanished
            flow%converged = rho == 0.0_wp
            exit
         end if
         call apply_matrix(p, q)
         alpha = rho/sum(p*q)
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
         rho_next = sum(r*z)
         p = z + (rho_next/rho)*p
         rho = rho_next
      end do
      flow%k_eff = dissipation(phi)/n_cells
      call apply_matrix(phi, q)
      flow%residual = sqrt(sum((b - q)**2))/b_norm

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

      !> The right-hand side on the free cells: the divergence of the face fluxes of the
      !> imposed jump.
      subroutine rhs_on_free_cells(b)
         real(wp), intent(out) :: b(:)
         integer :: i, j, k, m
         do m = 1, n_free
            k = free_cells(m)
            i = modulo(k - 1, nx) + 1
            j = (k - 1)/nx + 1
            b(m) = jump_x*(we(modulo(i - 2, nx) + 1 + (j - 1)*nx) - we(k)) &
               & + jump_y*(wn(i + modulo(j - 2, ny)*nx) - wn(k))
         end do
      end subroutine rhs_on_free_cells

      !> The matrix on the free cells in CSR form (zero-based, as hypre takes it): rows of the
      !> diagonal and the open faces to free neighbours; a face to a pinned cell only adds
      !> to the diagonal.
      subroutine assemble()
         integer :: i, j, k, m, f, nnz, neighbours(4)
         real(wp) :: weights(4)
         nnz = 0
         do m = 1, n_free
            k = free_cells(m)
            i = modulo(k - 1, nx) + 1
            j = (k - 1)/nx + 1
            neighbours = [modulo(i, nx) + 1 + (j - 1)*nx, modulo(i - 2, nx) + 1 + (j - 1)*nx, &
               & i + modulo(j, ny)*nx, i + modulo(j - 2, ny)*nx]
            weights = [we(k), we(neighbours(2)), wn(k), wn(neighbours(4))]
            row_start(m) = nnz
            nnz = nnz + 1
            column(nnz) = m - 1
            value(nnz) = sum(weights)
            do f = 1, 4
               if (weights(f) /= 0.0_wp .and. free(neighbours(f))) then
                  nnz = nnz + 1
                  column(nnz) = number(neighbours(f)) - 1
                  value(nnz) = -weights(f)
               end if
            end do
         end do
         row_start(n_free + 1) = nnz
      end subroutine assemble

      !> q = A v on the free cells.
      subroutine apply_matrix(v, q)
         real(wp), intent(in) :: v(:)
         real(wp), intent(out) :: q(:)
         integer :: m, e
         do m = 1, n_free
            q(m) = 0.0_wp
            do e = row_start(m) + 1, row_start(m + 1)
               q(m) = q(m) + value(e)*v(column(e) + 1)
            end do
         end do
      end subroutine apply_matrix

      !> sum_faces w (phi - phi_next + jump)^2: n_cells k_eff at the solution (phi zero at the
      !> pinned and inactive cells).
      real(wp) function dissipation(v) result(total)
         real(wp), intent(in) :: v(:)
         integer :: i, j, k
         real(wp) :: dx, dy
         phi_grid = 0.0_wp
         phi_grid(free_cells) = v
         total = 0.0_wp
         do j = 1, ny
            do i = 1, nx
               k = i + (j - 1)*nx
               dx = phi_grid(k) - phi_grid(modulo(i, nx) + 1 + (j - 1)*nx) + jump_x
               dy = phi_grid(k) - phi_grid(i + modulo(j, ny)*nx) + jump_y
               total = total + we(k)*dx*dx + wn(k)*dy*dy
            end do
         end do
      end function dissipation
   end subroutine flow_solve
end module lc_leakage_reynolds
