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
   use lc_scene, only: scene_type, is_halfspace, not_set, grid_of, kernel_of, pressure_scale
   use lc_result, only: contact_result
   use lc_base_grid, only: grid_type
   use lc_greens_kernel, only: layer_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_contact_residual, only: rounding_floor, complementarity_residual
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_policy, only: problem_indicators, solve_plan, measure_problem, measure_start, plan_solve, &
      & may_take_multigrid
   use lc_contact_stages, only: solve_in_stages
   use lc_contact_solver_multigrid, only: allowed_rise
   use lc_contact_progress, only: progress_log
   use lc_base_memory, only: check_memory
   use lc_base_pages, only: advise_huge_pages
   use lc_base_threads, only: solve_threads, use_threads, active_threads
   implicit none (type, external)
   private
   public :: solve_contact, scene_mean_pressure

   !> The coarse-start recursion stops before a grid of fewer than coarsest_grid points:
   !> below that a solve costs less than the set-up of another level.
   integer, parameter :: coarsest_grid = 512
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
   !> operator of the grid solved, for the observables.
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
      integer :: n

      call system_clock(start, rate)
      call solve_threads(scene%solver%threads, result%omp_threads, error)
      if (allocated(error)) return
      call progress%begin(scene%solver%verbose)
      grid = grid_of(scene)
      if (grid%is_line() .and. grid%points() < smallest_threaded_line) result%omp_threads = 1
      call use_threads(result%omp_threads)
      kernel = kernel_of(scene)
      n = grid%points()
      if (size(height) /= n) then
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

      if (.not. all(ieee_is_finite(height))) then
         call fatal_error(error, '&profile: the heights hold ' // to_string(count(.not. ieee_is_finite(height))) // &
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
      call check_memory(n, coupled_memory, scene%solver%memory, scene%stress .and. grid%ny > 1, &
         & may_multigrid, grid%is_line(), error)
      if (allocated(error)) return
      lambda_max = maxval(height)
      g_ref = maxval(height) - minval(height)
      if (g_ref <= 0.0_wp) g_ref = scene%period   ! flat punch: any length scale will do
      allocate (state%p(n), state%w(n), state%gap(n))
      call advise_huge_pages(state%p)
      call advise_huge_pages(state%w)
      call advise_huge_pages(state%gap)
      if (load_control) then
         pm = scene_mean_pressure(scene, height)
         if (.not. (pm > 0.0_wp .and. ieee_is_finite(pm))) then
            ! a flat surface has no relief to scale the seed's line pressure by
            call fatal_error(error, '&loading: normalised_pressure = ' // to_string(scene%normalised_pressure) // &
               & ' gives p_m = ' // to_string(pm) // ' on this profile (no summit above its mean plane); ' // &
               & 'allowed: a profile with relief, or mean_pressure', code_input)
            return
         end if
         state%p = pm
         state%s = 0.0_wp
      else
         pm = 0.0_wp
         state%p = 0.0_wp
         state%s = scene%penetration - lambda_max
      end if
      call system_clock(finish)
      result%setup_time = real(finish - start, wp)/real(rate, wp)
      call solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, state, result, &
         & progress, error)
      if (allocated(error)) return

      result%friction = friction
      result%mean_pressure = sum(state%p)/n
      result%penetration = state%s + lambda_max
      result%contact_fraction = real(count(state%p > 0.0_wp), wp)/n
      ! (moved, not copied: on a 4096^2 grid a field is 128 MiB)
      call move_alloc(state%p, result%pressure)
      call move_alloc(state%gap, result%gap)
      call move_alloc(state%w, result%displacement_z)
      result%monotone = op%monotone
      call system_clock(finish)
      result%wall_time = real(finish - start, wp)/real(rate, wp)
   end subroutine solve_contact

   !> Build the operator on the grid of `height` and solve: state%p is the starting guess
   !> on entry and the solution on exit, state%w = G_eff p, state%gap; state%s the constant
   !> of the gap (given under displacement control, found under load control). Sets the
   !> solver statistics of `result` and returns the plan it followed.
   recursive subroutine solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, state, &
         & result, progress, error, followed)
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
      type(problem_indicators) :: indicators
      type(solve_plan) :: plan
      type(contact_problem) :: problem
      type(solve_outcome) :: outcome
      real(wp) :: uniform, plain
      integer :: coarse_pairs, coarse_iterations
      integer(i8) :: start, finish, rate
      logical :: coarse_multigrid, started

      ! (the operator first: which methods run depends on it, and refusals come before any
      ! coarse solve)
      call system_clock(start, rate)
      call build_operator(op, grid, kernel, friction, active_threads(), error)
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
            & coarse_iterations, coarse_multigrid, progress, error)
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
      call solve_in_stages(plan%stages(1:plan%count), problem, state, outcome, progress, error)
      if (allocated(error)) return
      result%solver = outcome%path
      result%solver_reason = plan%reason
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
         result%gap_resolution = rounding_floor(maxval(abs(w)), maxval(abs(height)), maxval(p), op%largest)/g_ref
         if (result%converged) then
            plain = complementarity_residual(p, gap, merge(pm, sum(p)/size(p), load_control), g_ref, 0.0_wp)
            if (plain > scene%solver%tol) then
               result%converged = .false.
               result%residual = plain
            end if
         end if
         if (progress%enabled) call progress%level_done(result%solver, result%converged, result%iterations, &
            & result%residual, count(p > 0.0_wp)/real(size(p), wp))
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
   recursive subroutine coarse_solution(scene, grid, kernel, height, friction, load_control, pm, g_ref, state, &
         & pairs, iterations, took_multigrid, progress, error)
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
      type(scene_type) :: coarse
      type(grid_type) :: coarse_grid
      type(compliance_operator) :: coarse_op
      type(contact_result) :: coarse_result
      type(contact_state) :: coarse_state
      type(solve_plan) :: coarse_plan
      real(wp), allocatable, target :: hc(:)
      integer :: ratio

      pairs = 0
      iterations = 0
      took_multigrid = .false.
      coarse_grid = grid%coarse()
      coarse = scene
      coarse%solver%tol = max(scene%solver%tol, coarse_tol*min(1.0_wp, real(coarse_tol_size, wp)/grid%nx))
      if (trim(scene%solver%method) == 'multigrid') coarse%solver%tol = max(scene%solver%tol, multigrid_coarse_tol)
      allocate (coarse_state%w(coarse_grid%points()), coarse_state%gap(coarse_grid%points()))
      hc = restrict(grid, height)
      coarse_state%p = restrict(grid, state%p)
      coarse_state%s = state%s
      call solve_on_grid(coarse, coarse_grid, kernel, hc, friction, load_control, pm, g_ref, coarse_op, coarse_state, &
         & coarse_result, progress, error, coarse_plan)
      if (allocated(error)) return
      call interpolate(grid, coarse_state%p, state%p)
      if (load_control) state%s = coarse_state%s
      ratio = grid%points()/coarse_grid%points()
      pairs = (coarse_result%fft_pairs + ratio - 1)/ratio
      iterations = coarse_result%iterations
      took_multigrid = coarse_plan%stages(1) == 'multigrid'
   end subroutine coarse_solution

   !> The values of f at every second point (along both axes of a surface).
   pure function restrict(grid, f) result(fc)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: f(:)
      real(wp), allocatable :: fc(:)
      if (grid%is_line()) then
         fc = f(1:grid%nx:2)
      else
         fc = reshape(reshape_grid(f, grid%nx, grid%ny, 2), [grid%points()/4])
      end if
   end function restrict

   !> f(nx, ny) sampled at every `step`-th point along both axes.
   pure function reshape_grid(f, nx, ny, step) result(fc)
      real(wp), intent(in) :: f(nx, ny)
      integer, intent(in) :: nx, ny, step
      real(wp) :: fc(nx/step, ny/step)
      fc = f(1:nx:step, 1:ny:step)
   end function reshape_grid

   !> f on this grid from fc on the grid of every second point: linear (bilinear on a
   !> surface) interpolation, periodic.
   pure subroutine interpolate(grid, fc, f)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: fc(:)
      real(wp), intent(out) :: f(:)
      integer :: n
      if (grid%is_line()) then
         n = grid%nx
         f(1:n:2) = fc
         f(2:n:2) = 0.5_wp*(fc + cshift(fc, 1))
      else
         call interpolate_surface(fc, f, grid%nx, grid%ny)
      end if
   end subroutine interpolate

   pure subroutine interpolate_surface(fc, f, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: fc(nx/2, ny/2)
      real(wp), intent(out) :: f(nx, ny)
      f(1:nx:2, 1:ny:2) = fc
      f(2:nx:2, 1:ny:2) = 0.5_wp*(fc + cshift(fc, 1, dim=1))
      f(:, 2:ny:2) = 0.5_wp*(f(:, 1:ny:2) + cshift(f(:, 1:ny:2), 1, dim=2))
   end subroutine interpolate_surface

end module lc_contact_solve
