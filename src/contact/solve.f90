!> Solve one contact scene, a line or a surface (lc_base_grid), for a given Coulomb
!> coefficient: build the operator the scene needs, ask the policy (lc_contact_policy)
!> which methods solve it, run them (lc_contact_stages), fill a contact_result.
!>
!> Geometry (seed Eq. 10, convention P): the indenter surface sits at r(x) - Lambda + Delta
!> with Lambda = max r, so the highest asperity touches at Delta = 0; the gap is
!> g = w - (r - Lambda + Delta) >= 0. Load control gives p_m (or the seed's normalised
!> p_m/(E* Lambda0/lambda), Lambda0 = max r - mean r) and finds Delta; displacement
!> control gives Delta and finds p_m.
!>
!> The coarse start: with &solver coarse_start the guess is first replaced by the solution
!> on the grid of every second point, recursively, each coarse grid solved (and planned)
!> as a scene of its own to a tolerance a starting guess needs.
module lc_contact_solve
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   use lc_scene, only: scene_type, is_halfspace, not_set, grid_of, kernel_of, pressure_scale, is_areal, &
      & static_contact_modulus
   use lc_result, only: contact_result
   use lc_base_grid, only: grid_type
   use lc_greens_kernel, only: layer_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_contact_residual, only: rounding_floor, field_residual
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_policy, only: problem_indicators, solve_plan, measure_problem, measure_start, plan_solve, &
      & may_take_multigrid
   use lc_contact_stages, only: solve_in_stages
   use lc_contact_solver_multigrid, only: allowed_rise
   use lc_contact_progress, only: progress_log
   use lc_base_memory, only: check_memory
   use lc_base_pages, only: advise_huge_pages
   use lc_fft_plans, only: transform_seconds
   use lc_base_threads, only: solve_threads, use_threads, active_threads, fill_field, largest_magnitude, &
      & parallel_points
   use lc_base_parallel, only: is_distributed, slab, global_sum, global_max, allgather_rows, rank_count, &
      & redistribute_rows
   use lc_base_slab, only: empty_rank
   implicit none (type, external)
   private
   public :: solve_contact, scene_mean_pressure

   !> The coarse-start recursion stops before a grid of fewer than coarsest_grid points:
   !> below that a solve costs less than the set-up of another level.
   integer, parameter :: coarsest_grid = 512
   !> A distributed surface's coarse grid is itself solved on the slabs where each rank gets
   !> at least this many of its rows (ceiling((ny/2)/P) rows a rank); a thinner coarse grid
   !> is gathered onto every rank and solved whole there, as its own coarse grids are: a
   !> thin slab pays its transforms' 2(P - 1) messages a pair for little work, while the
   !> grid it would share is small (docs/decisions/027-distributed-coarse-start.md).
   integer, parameter :: distributed_coarse_rows = 8
   !> Tolerance of the coarse solves (or the scene's, if looser): a starting guess only
   !> needs to be closer than the discretisation difference between the two grids, which
   !> falls like the grid step (contact edges within a grid step): coarse_tol up to a fine
   !> grid of coarse_tol_size points along x, coarse_tol coarse_tol_size/nx beyond.
   real(wp), parameter :: coarse_tol = 1.0e-4_wp
   integer, parameter :: coarse_tol_size = 8192
   !> The coarse grids of a scene under method 'multigrid' (each solved by the same method)
   !> are solved to this tolerance instead: the fine grid's iterations do not need a closer
   !> start (docs/numerics.md, "The coarse start").
   real(wp), parameter :: multigrid_coarse_tol = 1.0e-3_wp
   !> A line of fewer points runs on one thread whatever &solver threads says: its transforms
   !> and passes are too short for a second thread to pay (docs/decisions/022-threads.md).
   integer, parameter :: smallest_threaded_line = 262144

contains

   !> p_m of a load-controlled scene on profile `height` (S): the given one, or the
   !> normalised pressure times its scale (pressure_scale).
   real(wp) function scene_mean_pressure(scene, height) result(pm)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      if (scene%mean_pressure /= not_set) then
         pm = scene%mean_pressure
      else
         pm = scene%normalised_pressure*pressure_scale(scene, height)
      end if
   end function scene_mean_pressure

   !> Solve the scene on profile `height` (flat, x fastest: lc_base_grid) with Coulomb
   !> coefficient `friction` (the scene's, or 0 for the frictionless companion). `op`: the
   !> operator of the grid solved, for the observables. A surface under several MPI ranks
   !> (lc_base_parallel) is solved distributed: `height` and the result's fields are this
   !> rank's slab of rows, its scalars those of the whole surface.
   subroutine solve_contact(scene, height, friction, result, op, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in), target :: height(:)
      real(wp), intent(in) :: friction
      type(contact_result), intent(out) :: result
      type(compliance_operator), intent(out), target :: op
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(layer_kernel) :: kernel
      type(contact_state) :: state
      real(wp) :: pm, g_ref, lambda_max
      type(progress_log) :: progress
      integer(i8) :: start, finish, rate
      logical :: load_control, may_multigrid, coupled_memory
      real(wp), parameter :: pi = acos(-1.0_wp)
      integer :: n, n_local, y_start, ny_local
      logical :: distributed
      real(wp) :: transforms_before

      call system_clock(start, rate)
      transforms_before = transform_seconds()
      call solve_threads(scene%solver%threads, result%omp_threads, error)
      if (allocated(error)) return
      call progress%begin(scene%solver%verbose)
      grid = grid_of(scene)
      if (grid%is_line() .and. grid%points() < smallest_threaded_line) result%omp_threads = 1
      call use_threads(result%omp_threads)
      kernel = kernel_of(scene)
      n = grid%points()
      distributed = is_distributed() .and. .not. grid%is_line()
      n_local = n
      if (distributed) then
         call slab(grid%ny, y_start, ny_local)
         n_local = grid%nx*ny_local
      end if
      if (size(height) /= n_local) then
         call fatal_error(error, 'solve: the profile has ' // to_string(size(height)) // ' heights, the grid ' &
            & // to_string(grid%nx) // ' x ' // to_string(grid%ny) // ' points', code_input)
         return
      end if
      load_control = trim(scene%control) == 'load'
      if (.not. load_control .and. (is_halfspace(scene) .or. scene%poisson == 0.5_wp)) then
         call fatal_error(error, "&loading: control = 'displacement' needs a finite layer with poisson < 0.5: " // &
            & 'the uniform mode of a half-space or of an incompressible bonded layer has no compliance, ' // &
            & "so the penetration does not fix the load; use control = 'load'", code_input)
         return
      end if

      if (global_count(count(.not. ieee_is_finite(height)), distributed) > 0) then
         call fatal_error(error, '&profile: the heights hold ' // &
            & to_string(global_count(count(.not. ieee_is_finite(height)), distributed)) // &
            & ' NaN or infinite values; allowed: finite heights', code_input)
         return
      end if
      ! a grid too large for this machine (or job) ends here, with how much it needs: the
      ! multigrid's coarse grids where the policy may take it whatever the coarse start
      ! gives, the coupled arrays where the operator is coupled or, a symmetric line whose
      ! compliance rises too steeply for the symmetric form, may go to the coupled form
      may_multigrid = may_take_multigrid(scene%solver%method, n, grid%is_line(), kernel%coupled(friction), &
         & kernel%viscoelastic)
      coupled_memory = kernel%coupled(friction)
      if (.not. coupled_memory .and. may_multigrid .and. grid%is_line()) &
         & coupled_memory = kernel%compliance_rise(2*pi/grid%lx, pi*grid%nx/grid%lx) > allowed_rise
      ! (a shared surface's multigrid holds its slab and, on every rank, the whole first coarse
      ! grid and those below it, and the finest grid's symbols: counted as a quarter of the
      ! grid's points at the multigrid's doubles a point, decision 028)
      call check_memory(merge(n_local + n/4, n_local, distributed .and. may_multigrid), coupled_memory, &
         & scene%solver%memory, &
         & scene%stress .and. grid%ny > 1, &
         & may_multigrid, grid%is_line(), trim(scene%solver%method) == 'gfmd', error)
      if (allocated(error)) return
      lambda_max = maxval(height)
      g_ref = maxval(height) - minval(height)
      if (distributed) then
         lambda_max = global_max(lambda_max)
         g_ref = lambda_max + global_max(-minval(height))
      end if
      if (g_ref <= 0.0_wp) g_ref = scene%period   ! flat punch: any length scale will do
      allocate (state%p(n_local), state%w(n_local), state%gap(n_local))
      call advise_huge_pages(state%p)
      call advise_huge_pages(state%w)
      call advise_huge_pages(state%gap)
      if (load_control) then
         if (distributed) then
            pm = distributed_mean_pressure(scene, height, lambda_max, n)
         else
            pm = scene_mean_pressure(scene, height)
         end if
         if (.not. (pm > 0.0_wp .and. ieee_is_finite(pm))) then
            ! a flat surface has no relief to scale the seed's line pressure by
            call fatal_error(error, '&loading: normalised_pressure = ' // to_string(scene%normalised_pressure) // &
               & ' gives p_m = ' // to_string(pm) // ' on this profile (no summit above its mean plane); ' // &
               & 'allowed: a profile with relief, or mean_pressure', code_input)
            return
         end if
         ! (the first touch of p's pages on the solve's threads)
         call fill_field(state%p, pm)
         state%s = 0.0_wp
      else
         pm = 0.0_wp
         call fill_field(state%p, 0.0_wp)
         state%s = scene%penetration - lambda_max
      end if
      call system_clock(finish)
      result%setup_time = real(finish - start, wp)/real(rate, wp)
      call solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, state, result, &
         & progress, error, distributed=distributed)
      if (allocated(error)) return

      result%friction = friction
      if (distributed) then
         result%mean_pressure = global_sum(sum(state%p))/n
         result%contact_fraction = real(global_count(count(state%p > 0.0_wp), distributed), wp)/n
      else
         result%mean_pressure = sum(state%p)/n
         result%contact_fraction = real(count(state%p > 0.0_wp), wp)/n
      end if
      result%penetration = state%s + lambda_max
      if (distributed) result%mpi_ranks = rank_count()
      ! (moved, not copied: on a 4096^2 grid a field is 128 MiB)
      call move_alloc(state%p, result%pressure)
      call move_alloc(state%gap, result%gap)
      call move_alloc(state%w, result%displacement_z)
      result%monotone = op%monotone
      call system_clock(finish)
      result%wall_time = real(finish - start, wp)/real(rate, wp)
      result%transform_time = transform_seconds() - transforms_before
   end subroutine solve_contact

   !> The count over the ranks (distributed) or this one's.
   integer function global_count(count, distributed)
      integer, intent(in) :: count
      logical, intent(in) :: distributed
      global_count = count
      if (distributed) global_count = global_sum(count)
   end function global_count

   !> scene_mean_pressure on this rank's slab `height` of a distributed surface of n points
   !> whose highest point is lambda_max: the relief Lambda0 from the whole surface.
   real(wp) function distributed_mean_pressure(scene, height, lambda_max, n) result(pm)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:), lambda_max
      integer, intent(in) :: n
      real(wp) :: lambda0
      if (scene%mean_pressure /= not_set) then
         pm = scene%mean_pressure
      else if (is_areal(scene) .and. .not. is_halfspace(scene)) then
         pm = scene%normalised_pressure*pressure_scale(scene, height)
      else
         lambda0 = lambda_max - global_sum(sum(height))/n
         pm = scene%normalised_pressure*static_contact_modulus(scene)*lambda0/scene%period
      end if
   end function distributed_mean_pressure

   !> Build the operator on the grid of `height` and solve: state%p is the starting guess
   !> on entry and the solution on exit, state%w = G_eff p, state%gap; state%s the constant
   !> of the gap (given under displacement control, found under load control). Sets the
   !> solver statistics of `result` and returns the plan it followed.
   recursive subroutine solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, state, &
         & result, progress, error, followed, distributed)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in), target :: height(:)
      real(wp), intent(in) :: friction, pm, g_ref
      logical, intent(in) :: load_control
      type(compliance_operator), intent(out), target :: op
      type(contact_state), intent(inout) :: state
      type(contact_result), intent(inout) :: result
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(solve_plan), intent(out), optional :: followed
      !> `height` and the state are this rank's slab of a surface shared among the ranks
      logical, intent(in), optional :: distributed
      type(problem_indicators) :: indicators
      type(solve_plan) :: plan
      type(contact_problem) :: problem
      type(solve_outcome) :: outcome
      real(wp) :: uniform, plain
      integer :: coarse_pairs, coarse_iterations
      integer(i8) :: start, finish, rate
      logical :: coarse_multigrid, started, across_ranks

      across_ranks = .false.
      if (present(distributed)) across_ranks = distributed
      ! (the operator first: which methods run depends on it, and refusals come before any
      ! coarse solve)
      call system_clock(start, rate)
      call build_operator(op, grid, kernel, friction, active_threads(), error, across_ranks)
      if (allocated(error)) return
      indicators = measure_problem(op, scene%solver%method, load_control)
      call plan_solve(indicators, scene%solver%coarse_start .and. grid%can_coarsen(coarsest_grid), plan, error)
      if (allocated(error)) return
      call system_clock(finish)
      result%setup_time = result%setup_time + real(finish - start, wp)/real(rate, wp)
      coarse_pairs = 0
      coarse_iterations = 0
      coarse_multigrid = .false.
      if (plan%coarse_start) then
         call system_clock(start)
         call coarse_solution(scene, grid, kernel, height, friction, load_control, pm, g_ref, state, coarse_pairs, &
            & coarse_iterations, coarse_multigrid, progress, error, across_ranks)
         if (allocated(error)) return
         call system_clock(finish)
         result%coarse_time = real(finish - start, wp)/real(rate, wp)
      end if
      if (trim(scene%solver%method) == 'auto') then
         ! (the start decides what the fine grid is: the rules of lc_contact_policy, step 3)
         call measure_start(indicators, op, load_control, coarse_iterations, coarse_multigrid, state%p)
         started = plan%coarse_start
         call plan_solve(indicators, started, plan, error)
         if (allocated(error)) return
      end if
      call progress%begin_level(grid%nx, grid%ny)
      if (progress%enabled .and. across_ranks) &
         & progress%level = progress%level // ' on the slabs of ' // to_string(rank_count()) // ' ranks'
      call progress%plan(plan%reason)
      uniform = 0.0_wp
      if (load_control) call op%drop_uniform_mode(uniform)

      problem%op => op
      problem%b => height
      problem%load_control = load_control
      problem%mean_pressure = pm
      problem%g_ref = g_ref
      problem%tol = scene%solver%tol
      problem%max_iter = scene%solver%max_iter
      problem%memory = scene%solver%memory
      problem%precondition = scene%solver%precondition
      problem%gfmd_mass = scene%solver%gfmd_mass
      call solve_in_stages(plan%stages(1:plan%count), problem, state, outcome, progress, error)
      if (allocated(error)) return
      result%solver = outcome%path
      result%solver_reason = plan%reason
      if (allocated(outcome%note)) then
         if (len(outcome%note) > 0) result%solver_reason = result%solver_reason // '; ' // outcome%note
      end if
      result%converged = outcome%converged
      result%iterations = outcome%iterations
      result%outer_iterations = outcome%outer_iterations
      result%fft_pairs = outcome%fft_pairs + coarse_pairs
      result%residual = outcome%residual
      call move_alloc(outcome%history, result%residual_history)
      ! The solvers stop when the residual, with gaps below the rounding floor of w - r
      ! counted as zero, reaches tol: no iteration resolves such gaps. At loads so large that
      ! this noise exceeds the tolerance (p_m = 1e300: the pressure's variation is lost in the
      ! rounding of p_m) the solution is not resolved to tol in double precision: the run
      ! reports the residual without the floor and does not claim convergence.
      associate (p => state%p, w => state%w, gap => state%gap)
         if (across_ranks) then
            result%gap_resolution = rounding_floor(global_max(largest_magnitude(w)), global_max(maxval(abs(height))), &
               & global_max(maxval(p)), op%largest)/g_ref
         else
            result%gap_resolution = rounding_floor(largest_magnitude(w), maxval(abs(height)), maxval(p), op%largest)/g_ref
         end if
         if (result%converged) then
            if (across_ranks) then
               plain = global_max(field_residual(p, gap, merge(pm, global_sum(sum(p))/grid%points(), &
                  & load_control), g_ref, 0.0_wp))
            else
               plain = field_residual(p, gap, merge(pm, sum(p)/size(p), load_control), g_ref, 0.0_wp)
            end if
            if (plain > scene%solver%tol) then
               result%converged = .false.
               result%residual = plain
            end if
         end if
         if (progress%enabled) call progress%level_done(result%solver, result%converged, result%iterations, &
            & result%residual, global_count(count(p > 0.0_wp), across_ranks)/real(grid%points(), wp))
         ! the uniform mode's rigid shift (see drop_uniform_mode)
         w = w + uniform*pm
      end associate
      state%s = state%s + uniform*pm
      if (present(followed)) followed = plan
   end subroutine solve_on_grid

   !> Replace the guess state%p (and s) by the solution on the grid of every second point,
   !> interpolated linearly (which keeps p >= 0). The coarse solve needs only the accuracy
   !> of a starting guess (coarse_tol); its FFT pairs are returned in units of pairs of
   !> this grid (2 or 4 times as long each, on a line or a surface), with its iterations
   !> and whether its plan took the multigrid method: what the policy reads of it.
   !> Distributed (`across_ranks`: height and state%p are this rank's slab): the coarse grid
   !> is a distributed surface of its own (its slabs by the same contract, its own plans)
   !> where it leaves each rank at least distributed_coarse_rows rows (coarse_on_slabs);
   !> a thinner one is gathered to every rank and solved there, serially and identically,
   !> each rank then taking its slab of the interpolated start.
   recursive subroutine coarse_solution(scene, grid, kernel, height, friction, load_control, pm, g_ref, state, &
         & pairs, iterations, took_multigrid, progress, error, across_ranks)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in) :: height(:), friction, pm, g_ref
      logical, intent(in) :: load_control
      type(contact_state), intent(inout) :: state
      integer, intent(out) :: pairs, iterations
      logical, intent(out) :: took_multigrid
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: across_ranks
      type(scene_type) :: coarse
      type(grid_type) :: coarse_grid
      type(compliance_operator) :: coarse_op
      type(contact_result) :: coarse_result
      type(contact_state) :: coarse_state
      type(solve_plan) :: coarse_plan
      real(wp), allocatable, target :: hc(:)
      real(wp), allocatable :: whole(:)
      integer :: ratio, y_start, ny_local
      logical :: on_slabs

      pairs = 0
      iterations = 0
      took_multigrid = .false.
      coarse_grid = grid%coarse()
      coarse = scene
      coarse%solver%tol = max(scene%solver%tol, coarse_tol*min(1.0_wp, real(coarse_tol_size, wp)/grid%nx))
      if (trim(scene%solver%method) == 'multigrid') coarse%solver%tol = max(scene%solver%tol, multigrid_coarse_tol)
      on_slabs = across_ranks .and. coarse_on_slabs(coarse_grid)
      if (on_slabs) then
         call restrict_to_slabs(grid, height, hc)
         call restrict_to_slabs(grid, state%p, coarse_state%p)
      else if (across_ranks) then
         call allgather_rows(height, grid%nx, grid%ny, whole)
         hc = restrict(grid, whole)
         call allgather_rows(state%p, grid%nx, grid%ny, whole)
         coarse_state%p = restrict(grid, whole)
      else
         hc = restrict(grid, height)
         coarse_state%p = restrict(grid, state%p)
      end if
      allocate (coarse_state%w(size(hc)), coarse_state%gap(size(hc)))
      coarse_state%s = state%s
      call solve_on_grid(coarse, coarse_grid, kernel, hc, friction, load_control, pm, g_ref, coarse_op, coarse_state, &
         & coarse_result, progress, error, coarse_plan, distributed=on_slabs)
      if (allocated(error)) return
      if (on_slabs) then
         call interpolate_from_slabs(grid, coarse_state%p, state%p)
      else if (across_ranks) then
         call interpolate(grid, coarse_state%p, whole)
         call slab(grid%ny, y_start, ny_local)
         state%p = whole(grid%nx*y_start + 1:grid%nx*(y_start + ny_local))
      else
         call interpolate(grid, coarse_state%p, state%p)
      end if
      if (load_control) state%s = coarse_state%s
      ratio = grid%points()/coarse_grid%points()
      pairs = (coarse_result%fft_pairs + ratio - 1)/ratio
      iterations = coarse_result%iterations
      took_multigrid = coarse_plan%stages(1) == 'multigrid'
   end subroutine coarse_solution

   !> Whether the coarse grid of a distributed surface is solved on the slabs: at least
   !> distributed_coarse_rows rows a rank, and no rank left without rows or without columns
   !> of the transposed half spectrum (nx/2 + 1 of them).
   logical function coarse_on_slabs(coarse_grid)
      type(grid_type), intent(in) :: coarse_grid
      integer :: p
      p = rank_count()
      coarse_on_slabs = (coarse_grid%ny + p - 1)/p >= distributed_coarse_rows .and. &
         & .not. empty_rank(coarse_grid%ny, p) .and. .not. empty_rank(coarse_grid%nx/2 + 1, p)
   end function coarse_on_slabs

   !> fc: this rank's slab (the contract of the grid of every second point) of f sampled at
   !> every second point, from this rank's slab of f. Each rank samples the even rows of
   !> its own slab; those rows are moved to the ranks whose coarse slabs hold them.
   subroutine restrict_to_slabs(grid, f, fc)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: f(:)
      real(wp), allocatable, intent(out) :: fc(:)
      real(wp), allocatable :: sampled(:)
      integer :: y_start, ny_local, first, last, yc_start, nyc_local, nxc, j, row
      call slab(grid%ny, y_start, ny_local)
      nxc = grid%nx/2
      ! (the coarse rows j whose fine row 2j is in this slab)
      first = (y_start + 1)/2
      last = (y_start + ny_local - 1)/2
      allocate (sampled(nxc*max(last - first + 1, 0)))
      do j = first, last
         row = 2*j - y_start
         sampled((j - first)*nxc + 1:(j - first + 1)*nxc) = f(row*grid%nx + 1:(row + 1)*grid%nx:2)
      end do
      call slab(grid%ny/2, yc_start, nyc_local)
      allocate (fc(nxc*nyc_local))
      call redistribute_rows(sampled, nxc, grid%ny/2, first, yc_start, nyc_local, fc)
   end subroutine restrict_to_slabs

   !> f: this rank's slab of the bilinear interpolation (interpolate_surface, the same
   !> operations in the same order) of fc, this rank's slab of the grid of every second
   !> point. A fine row between two coarse rows needs both: the coarse rows that cover
   !> this slab, and the next (periodic: past the last row, row 0), are brought here.
   subroutine interpolate_from_slabs(grid, fc, f)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: fc(:)
      real(wp), intent(out) :: f(:)
      real(wp), allocatable :: near(:), along_x(:, :)
      integer :: y_start, ny_local, yc_start, nyc_local, first, rows, nxc, i, y, k
      call slab(grid%ny, y_start, ny_local)
      call slab(grid%ny/2, yc_start, nyc_local)
      nxc = grid%nx/2
      first = y_start/2
      rows = (y_start + ny_local - 1)/2 - first + 2
      allocate (near(nxc*rows), along_x(grid%nx, rows))
      call redistribute_rows(fc, nxc, grid%ny/2, yc_start, first, rows, near)
      do k = 1, rows
         associate (coarse_row => near((k - 1)*nxc + 1:k*nxc))
            along_x(1:grid%nx:2, k) = coarse_row
            along_x(2:grid%nx:2, k) = 0.5_wp*(coarse_row + cshift(coarse_row, 1))
         end associate
      end do
      do i = 1, ny_local
         y = y_start + i - 1
         k = y/2 - first + 1
         if (mod(y, 2) == 0) then
            f((i - 1)*grid%nx + 1:i*grid%nx) = along_x(:, k)
         else
            f((i - 1)*grid%nx + 1:i*grid%nx) = 0.5_wp*(along_x(:, k) + along_x(:, k + 1))
         end if
      end do
   end subroutine interpolate_from_slabs

   !> The values of f at every second point (along both axes of a surface; its rows on the
   !> solve's threads).
   function restrict(grid, f) result(fc)
      type(grid_type), intent(in) :: grid
      real(wp), contiguous, intent(in) :: f(:)
      real(wp), allocatable :: fc(:)
      integer :: nxc, k
      if (grid%is_line()) then
         fc = f(1:grid%nx:2)
         return
      end if
      nxc = grid%nx/2
      allocate (fc(grid%points()/4))
      !$omp parallel do schedule(static) if(grid%points() >= parallel_points)
      do k = 1, grid%ny/2
         call sample_row(f(2*(k - 1)*grid%nx + 1:(2*k - 1)*grid%nx), fc((k - 1)*nxc + 1:k*nxc))
      end do
   end function restrict

   !> Every second value of a row (the first, third, ...).
   pure subroutine sample_row(row, sampled)
      real(wp), contiguous, intent(in) :: row(:)
      real(wp), contiguous, intent(out) :: sampled(:)
      sampled = row(1:size(row):2)
   end subroutine sample_row

   !> f on this grid from fc on the grid of every second point: linear (bilinear on a
   !> surface) interpolation, periodic.
   subroutine interpolate(grid, fc, f)
      type(grid_type), intent(in) :: grid
      real(wp), contiguous, intent(in) :: fc(:)
      real(wp), contiguous, intent(out) :: f(:)
      integer :: n
      if (grid%is_line()) then
         n = grid%nx
         f(1:n:2) = fc
         f(2:n:2) = 0.5_wp*(fc + cshift(fc, 1))
      else
         call interpolate_surface(fc, f, grid%nx, grid%ny)
      end if
   end subroutine interpolate

   !> The bilinear interpolation of a surface, its rows on the solve's threads: the rows of
   !> the coarse points along x first (fine rows 1, 3, ...), then the rows between them, the
   !> mean of their neighbours (periodic).
   subroutine interpolate_surface(fc, f, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), contiguous, intent(in) :: fc(:)
      real(wp), contiguous, intent(out) :: f(:)
      integer :: k, nxc, below, above
      nxc = nx/2
      !$omp parallel do schedule(static) if(nx*ny >= parallel_points)
      do k = 1, ny/2
         call interpolate_row(fc((k - 1)*nxc + 1:k*nxc), f(2*(k - 1)*nx + 1:(2*k - 1)*nx))
      end do
      !$omp parallel do schedule(static) private(below, above) if(nx*ny >= parallel_points)
      do k = 1, ny/2
         below = 2*(k - 1)*nx
         above = modulo(2*k, ny)*nx
         call mean_row(f(below + 1:below + nx), f(above + 1:above + nx), f(below + nx + 1:below + 2*nx))
      end do
   end subroutine interpolate_surface

   !> A fine row from a coarse one: the coarse values at the odd points, the mean of their
   !> neighbours (periodic) between them.
   pure subroutine interpolate_row(coarse, fine)
      real(wp), contiguous, intent(in) :: coarse(:)
      real(wp), contiguous, intent(out) :: fine(:)
      integer :: i, m
      m = size(coarse)
      do i = 1, m - 1
         fine(2*i - 1) = coarse(i)
         fine(2*i) = 0.5_wp*(coarse(i) + coarse(i + 1))
      end do
      fine(2*m - 1) = coarse(m)
      fine(2*m) = 0.5_wp*(coarse(m) + coarse(1))
   end subroutine interpolate_row

   !> between = the mean of the rows below and above it.
   pure subroutine mean_row(below, above, between)
      real(wp), contiguous, intent(in) :: below(:), above(:)
      real(wp), contiguous, intent(out) :: between(:)
      between = 0.5_wp*(below + above)
   end subroutine mean_row

end module lc_contact_solve
