!> Solve one contact scene, a line or a surface (lc_grid), for a given Coulomb
!> coefficient: build the operator the scene needs, pick the solver, fill a
!> contact_result.
!>
!> Geometry (seed Eq. 10, convention P): the indenter surface sits at r(x) - Lambda + Delta
!> with Lambda = max r, so the highest asperity touches at Delta = 0; the gap is
!> g = w - (r - Lambda + Delta) >= 0. Load control gives p_m (or the seed's normalised
!> p_m/(E* Lambda0/lambda), Lambda0 = max r - mean r) and finds Delta; displacement
!> control gives Delta and finds p_m.
module lc_contact_solve
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp, i8
   use lc_errors, only: error_type, fatal_error, code_input
   use lc_strings, only: to_string
   use lc_scene, only: scene_type, is_halfspace, not_set, grid_of, kernel_of, pressure_scale
   use lc_result, only: contact_result
   use lc_grid, only: grid_type
   use lc_greens_kernel, only: layer_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_contact_solver_cg, only: constrained_cg, cg_outcome, rounding_floor, complementarity_residual
   use lc_contact_solver_anderson, only: anderson_coupled, anderson_outcome
   use lc_contact_solver_gcr, only: constrained_gcr, gcr_outcome
   use lc_contact_solver_gfmd, only: gfmd, gfmd_outcome
   use lc_contact_solver_newton, only: dense_newton, newton_outcome, dense_points, newton_step_limit
   use lc_contact_solver_multigrid, only: multigrid, multigrid_outcome, multigrid_refusal, metric_refusal, coupled_refusal, &
      & coupled_tnnmg, allowed_rise, rows_ahead_of_gcr, loss_among_short_waves, short_loss_limit
   use lc_contact_progress, only: progress_log
   use lc_memory, only: check_memory
   use lc_observables, only: observe
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
   !> The coarse grids of a coupled scene under method 'multigrid' (each solved by the same
   !> method) are solved to this tolerance instead: the fine grid's iterations do not need a
   !> closer start. Coupled lines from 1024 to 2^20 points (bench/scaling.py --scenes 2 4
   !> --method multigrid) took 54-109 transform pairs, max/min 1.13-1.49 per family and
   !> scene, against 61-126 and 1.11-1.66 with coarse_tol; surfaces 1-3 % fewer
   !> (docs/decisions/012-coupled-multigrid.md).
   real(wp), parameter :: multigrid_coarse_tol = 1.0e-3_wp
   !> Under method 'auto' the multigrid solver takes the frictionless elastic scenes it
   !> applies to (multigrid_refusal) from this many points on, lines and surfaces
   !> (bench/scaling.py --scenes 1 --method multigrid --against cg, tol 1e-8): on lines
   !> from 4096 points, where the constrained CG takes 1.1-3.4x its time on broadband
   !> roughness (4.6-8.6x at 65536) and 0.6-0.8x on a spectrum fixed in physical
   !> wavenumbers; on surfaces from 1024^2, where the CG takes 1.5-2.3x its time broadband
   !> (2.1-3.4x at 2048^2) and 1.2x physical (at 512^2 0.8-1.3x: a multigrid pair costs
   !> 2-3x a CG pair there). docs/decisions/011-multigrid-for-surfaces.md.
   integer, parameter :: multigrid_points = 4096, multigrid_surface_points = 1024**2
   !> Under method 'auto' a coupled line of at least coupled_multigrid_points points goes to
   !> the multigrid method (where its metric passes metric_refusal) when the solve on the grid
   !> of every second point needed more than hard_coarse_iterations GCR iterations or went
   !> that way itself. Measured on bench/scaling.py's coupled scenes (friction, SLS): those
   !> coarse solves need 4-14 GCR iterations where the spectrum is fixed (n = 8192 to 65536),
   !> where GCR takes 0.5-0.7x the multigrid's time, and 15-340 on broadband lines, where it
   !> takes 0.8-1.5x at 8192 (0.5-1.2x at 4096), 1.2-2.2x at 16384, 1.8-3.5x at 32768 and
   !> 2.5-8x from 65536 on (docs/decisions/012-coupled-multigrid.md). A coupled surface of at least 1024^2 points
   !> goes the same way when its coarse solve needed more than 12 GCR iterations: those
   !> coarse solves need 5-7 on the physical family (512^2 to 2048^2), where GCR takes
   !> 0.3-0.5x the multigrid's time, and 7-28 on broadband surfaces, where it takes 1.3-1.6x
   !> at 2048^2 with 16-28 coarse iterations, 0.9x with 9, and at 1024^2 1.3x with 18,
   !> 0.7-0.9x with 8-12.
   integer, parameter :: coupled_multigrid_points = 8192, coupled_multigrid_surface_points = 1024**2
   !> A sliding viscoelastic surface that the multigrid method smooths by rows where GCR is
   !> slow (rows_ahead_of_gcr) goes to it from this many points, on the same condition. At
   !> 512^2 GCR takes 1.05-1.55x its time on the standard linear solid (bench/scaling.py
   !> --scenes 4, both families); on glassy layers (E_inf/E0 = 100) 0.8-1.2 s against
   !> 0.47-0.54 s at V tau/lambda = 0.1, 0.29-0.37 s against 0.37-0.41 s at 1; at 256^2 GCR
   !> takes 0.8-1.16x its time on the standard linear solid. Near the loss peak (E_inf/E0 =
   !> 100 to 1000 at V tau/lambda = 0.01, rows on the metric's hierarchy) GCR with the
   !> Anderson iteration took 11-16 s where the multigrid 2.1-6.5 s, but at 3e-3 0.6-0.8 s
   !> where 1.0-1.1 s. Slower sliding smoothed by rows for a moderate loss among the short
   !> waves waits for 1024^2: at 512^2 GCR took 0.5-1.6x its time (E_inf/E0 = 10, V
   !> tau/lambda = 0.01) (docs/decisions/015-row-smoothing.md).
   integer, parameter :: rows_multigrid_surface_points = 512**2
   integer, parameter :: hard_coarse_iterations = 20, hard_coarse_surface_iterations = 12
   !> A sliding viscoelastic line of at least lossy_multigrid_points points whose loss
   !> |Im K|/Re K among the waves short along x (|kx| > nx/16) reaches short_wave_loss (its
   !> loss peak among the short waves) goes to the multigrid method under 'auto' whatever its
   !> coarse solve took: GCR, with its kept history and the Anderson iteration, crawls there.
   !> The coarse grids of a longer line's coarse start go so too, by the same rule. Measured
   !> (h/lambda = 0.16, nu = 0.5, mu_c = 0.5, tol 1e-8, both roughness families): lines of
   !> 1024 to 16384 points with E_inf/E0 = 30 to 300 at V tau/lambda = 1e-3 to 0.03 took
   !> 2.5 s in all where the rule from 4096 points took 9.6 s (2.1 s where 2.5 s without the
   !> one line GCR crawled on), 39 of 96 lines faster, 24 slower (most by about a
   !> millisecond: lines of 1024 points whose loss peak lies beyond the grid); the 48 very
   !> glassy lines of 1024 and 16384 points (E_inf/E0 = 500 to 2000) 11.9 s where 13.5 s,
   !> those of 2048 points 1.41 s where 1.21 s; the physical family's figure sweep, whose
   !> coarse grids GCR solves easily, 3.3 s where 3.0 s. Where the loss lies at long waves
   !> (V tau/lambda >= 0.1) GCR took 0.3-0.8x the multigrid's time at 4096 points
   !> (docs/decisions/012-coupled-multigrid.md).
   integer, parameter :: lossy_multigrid_points = 1024
   !> ... where its coarse start holds at least lossy_line_contacts contact points: with one
   !> or a few, GCR solves a glassy line in 24-43 transform pairs, the multigrid method in
   !> 300-5000. On the viscoelastic extremes grid (tests/extremes_grid.py, 1296 lines of
   !> 1024 points) 12.8 s where 13.5 s without the condition and 30.8 s with the rule from
   !> 4096 points; 55 lines more than 2x slower than with that rule (at most 40x, 36 ms)
   !> where 134 were (91x, 47 ms). The glassy lines above choose as without it.
   integer, parameter :: lossy_line_contacts = 16
   real(wp), parameter :: short_wave_loss = 1.0_wp
   !> A sliding viscoelastic surface goes so from lossy_surface_points where that loss (along
   !> x, at any ky) reaches short_loss_limit, beyond which the multigrid method smooths it by
   !> rows on the metric's hierarchy, where its coarse start holds at least
   !> lossy_surface_contacts contact points and where its metric passes metric_refusal: GCR
   !> with its kept history and the Anderson iteration crawls there. A few contact points
   !> (GCR 58-80 pairs at 256^2, the multigrid 170-180; up to 45x the time at 128^2 with
   !> 0.2 % contact) and thin incompressible layers (h/lambda = 0.01: 3355 pairs, GCR 287) stay
   !> on GCR. Measured (h/lambda = 0.16, nu = 0.5, tol 1e-8; E_inf/E0 = 30 to 1000 at
   !> V tau/lambda = 1e-3 to 0.1, mu_c = 0 and 0.5, shortest wavelength 8 points, 40
   !> surfaces per size): at 128^2 2.5 s in all where 'auto' took 4.8 s with GCR, at 256^2
   !> 14.9 s where 38.6 s, every surface of 256^2 that changes method faster (1.2-5.4x); at
   !> 128^2 GCR takes half the multigrid's time at V tau/lambda = 0.01 (12 ms against 26)
   !> and up to 5.4x it at 0.03 and 0.1; at 512^2 (both families, E_inf/E0 = 100 and 1000 at
   !> 3e-3 to 0.1) 197 s where 328 s, one surface slower (the physical E_inf/E0 = 1000 at
   !> 0.03 with friction, 58 s where 35 s: the multigrid method stalls and GCR finishes); a
   !> grid of 96 surfaces of 128^2 (h/lambda = 0.01 to the half-space, nu = 0.3 and 0.5,
   !> E_inf/E0 = 100 and 1000 at 0.01 and 0.1, mu_c = 0 and 1.5, p_m = 0.001 and 0.3) 19.8 s
   !> where 21.2 s, at most 2.9x slower (31 ms where 11) (docs/decisions/015-row-smoothing.md).
   integer, parameter :: lossy_surface_points = 128**2
   integer, parameter :: lossy_surface_contacts = 256
   !> A line whose compliance rises with |q| (a thin incompressible layer, admitted by
   !> coupled_refusal) goes the same way from this many points, with friction or without
   !> (the coarse solve's CG iterations counted then): with friction its multigrid solves
   !> take 130-200 transform pairs, and GCR takes 0.2-0.8x their time up to 65536 points on
   !> broadband lines, 0.8-1.3x at 131072, 1.1-2.1x at 262144, 2.9-10.7x at 2^20 (0.1-0.3x
   !> on the physical family, whose coarse solves are easy: 10-14 GCR iterations); without,
   !> 95-286 pairs, and the constrained CG takes 1.3x their time at 65536 and 3.1x at
   !> 262144 with the shortest wavelength 8 points.
   integer, parameter :: rising_multigrid_points = 262144

contains

   !> The fewest points from which method 'auto' may take the multigrid method for a coupled
   !> scene on `grid` (a hard coarse solve given): a line's, or a surface's, lower for one
   !> smoothed by rows (`rows`: it may be, a sliding viscoelastic layer).
   pure integer function coupled_threshold(grid, rows) result(points)
      type(grid_type), intent(in) :: grid
      logical, intent(in) :: rows
      if (grid%is_line()) then
         points = coupled_multigrid_points
      else if (rows) then
         points = rows_multigrid_surface_points
      else
         points = coupled_multigrid_surface_points
      end if
   end function coupled_threshold

   !> p_m of a load-controlled scene on profile `height` (S): the given one, or the
   !> normalised pressure times its scale (pressure_scale).
   pure real(wp) function scene_mean_pressure(scene, height) result(pm)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      if (scene%mean_pressure /= not_set) then
         pm = scene%mean_pressure
      else
         pm = scene%normalised_pressure*pressure_scale(scene, height)
      end if
   end function scene_mean_pressure

   !> Solve the scene on profile `height` (flat, x fastest: lc_grid) with Coulomb
   !> coefficient `friction` (the scene's, or 0 for the frictionless companion).
   subroutine solve_contact(scene, height, friction, result, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      real(wp), intent(in) :: friction
      type(contact_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(compliance_operator) :: op
      type(grid_type) :: grid
      type(layer_kernel) :: kernel
      real(wp), allocatable :: p(:), w(:), gap(:)
      real(wp) :: pm, s, g_ref, lambda_max
      type(progress_log) :: progress
      integer(i8) :: start, finish, rate
      logical :: load_control, may_multigrid, coupled_memory
      real(wp), parameter :: pi = acos(-1.0_wp)
      integer :: n

      call system_clock(start, rate)
      call progress%begin(scene%solver%verbose)
      grid = grid_of(scene)
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
      ! a grid too large for this machine (or job) ends here, with how much it needs (the
      ! multigrid's coarse grids if the scene may go to it: refusals need the operator)
      if (kernel%coupled(friction)) then
         may_multigrid = scene%solver%method == 'multigrid' .or. (scene%solver%method == 'auto' .and. &
            & n >= coupled_threshold(grid, kernel%viscoelastic)) .or. (scene%solver%method == 'auto' .and. &
            & kernel%viscoelastic .and. n >= merge(lossy_multigrid_points, lossy_surface_points, grid%is_line()))
      else
         may_multigrid = scene%solver%method == 'multigrid' .or. (scene%solver%method == 'auto' .and. &
            & n >= merge(multigrid_points, multigrid_surface_points, grid%is_line()))
      end if
      ! (a frictionless line whose compliance rises too steeply for the symmetric multigrid
      ! method, a thin incompressible layer, may go to the coupled iteration and hold its arrays)
      coupled_memory = kernel%coupled(friction)
      if (.not. coupled_memory .and. may_multigrid .and. grid%is_line()) &
         & coupled_memory = kernel%compliance_rise(2*pi/grid%lx, pi*grid%nx/grid%lx) > allowed_rise
      call check_memory(n, coupled_memory, scene%solver%memory, scene%stress .and. grid%ny > 1, &
         & may_multigrid, grid%is_line(), error)
      if (allocated(error)) return
      lambda_max = maxval(height)
      g_ref = maxval(height) - minval(height)
      if (g_ref <= 0.0_wp) g_ref = scene%period   ! flat punch: any length scale will do
      allocate (p(n), w(n), gap(n))
      if (load_control) then
         pm = scene_mean_pressure(scene, height)
         if (.not. (pm > 0.0_wp .and. ieee_is_finite(pm))) then
            ! a flat surface has no relief to scale the seed's line pressure by
            call fatal_error(error, '&loading: normalised_pressure = ' // to_string(scene%normalised_pressure) // &
               & ' gives p_m = ' // to_string(pm) // ' on this profile (no summit above its mean plane); ' // &
               & 'allowed: a profile with relief, or mean_pressure', code_input)
            return
         end if
         p = pm
         s = 0.0_wp
      else
         pm = 0.0_wp
         p = 0.0_wp
         s = scene%penetration - lambda_max
      end if
      call solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, p, w, gap, s, &
         & result, progress, error)
      if (allocated(error)) return

      result%friction = friction
      result%mean_pressure = sum(p)/n
      result%penetration = s + lambda_max
      result%contact_fraction = real(count(p > 0.0_wp), wp)/n
      ! (moved, not copied: on a 4096^2 grid a field is 128 MiB)
      call move_alloc(p, result%pressure)
      call move_alloc(gap, result%gap)
      call move_alloc(w, result%displacement_z)
      result%monotone = op%monotone
      call system_clock(finish)
      result%wall_time = real(finish - start, wp)/real(rate, wp)
      call observe(scene, op, height, result)
   end subroutine solve_contact

   !> Build the operator on the grid of `height` and solve: p is the starting guess on
   !> entry and the solution on exit, w = G_eff p, gap; s the constant of the gap (given
   !> under displacement control, found under load control). Sets the solver statistics
   !> of `result`. With &solver coarse_start the guess is first replaced by the solution
   !> on the grid of every second point (recursively down to coarsest_grid points).
   recursive subroutine solve_on_grid(scene, grid, kernel, height, friction, load_control, pm, g_ref, op, p, w, &
         & gap, s, result, progress, error)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in) :: height(:), friction, pm, g_ref
      logical, intent(in) :: load_control
      type(compliance_operator), intent(out) :: op
      real(wp), intent(inout) :: p(:), s
      real(wp), intent(out) :: w(:), gap(:)
      type(contact_result), intent(inout) :: result
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(cg_outcome) :: cg
      type(anderson_outcome) :: outer
      type(gfmd_outcome) :: dynamics
      type(newton_outcome) :: newton
      type(multigrid_outcome) :: nested
      type(contact_result) :: previous
      real(wp), allocatable :: history(:)
      character(len=:), allocatable :: reason, allowed
      character(len=len(scene%solver%method)) :: method
      real(wp) :: uniform, plain, loss
      integer :: coarse_pairs
      logical :: coarse_hard, rising

      coarse_pairs = 0
      coarse_hard = .false.
      ! (the operator first: which solver runs depends on it, and refusals come before any
      ! coarse solve)
      call build_operator(op, grid, kernel, friction, scene%solver%threads, error)
      if (allocated(error)) return
      if (op%coupled .and. trim(scene%solver%method) == 'cg') then
         call fatal_error(error, "&solver: method = 'cg' cannot solve this scene: friction couples the normal " // &
            & "and tangential fields and the operator is not symmetric; allowed: 'auto', 'gcr' or 'anderson'", code_input)
         return
      end if
      method = scene%solver%method
      ! Why no multigrid method can take the scene (empty: one can): the symmetric one, or the
      ! coupled iteration for coupled scenes and for frictionless elastic ones whose compliance
      ! rises too steeply for the symmetric one (a thin incompressible layer: `rising`)
      reason = multigrid_refusal(op)
      rising = .false.
      if (op%coupled .or. (len(reason) > 0 .and. .not. op%kernel%viscoelastic)) then
         reason = coupled_refusal(op, load_control)
         rising = .not. op%coupled .and. len(reason) == 0
      end if
      if (method == 'multigrid' .and. len(reason) > 0) then
         allowed = "'auto', 'cg', 'gcr', 'anderson' or 'gfmd'"
         if (op%coupled) allowed = "'auto', 'gcr' or 'anderson'"
         call fatal_error(error, "&solver: method = 'multigrid' cannot solve this scene: " // reason // &
            & '; it solves lines and surfaces on an elastic half-space or layer (nu <= 0.47, or ' // &
            & 'h/lambda >~ 0.07), with friction or sliding viscoelastic, and lines on thinner layers down ' // &
            & 'to h/lambda ~ 0.01 at nu = 0.5; allowed here: ' // allowed, code_input)
         return
      end if
      if (method == 'auto' .and. .not. (op%coupled .or. rising) .and. len(reason) == 0 .and. &
         & grid%points() >= merge(multigrid_points, multigrid_surface_points, grid%is_line())) method = 'multigrid'
      ! (the multigrid solver makes its own nested iteration: one iteration per coarse grid
      ! on the displacement, where this start solves each coarse grid to coarse_tol; on a
      ! coupled scene it takes the start, whose contact set is nearly right)
      if (scene%solver%coarse_start .and. grid%can_coarsen(coarsest_grid) .and. &
         & (method /= 'multigrid' .or. op%coupled .or. rising)) then
         call coarse_solution(scene, grid, kernel, height, friction, load_control, pm, g_ref, p, s, coarse_pairs, &
            & coarse_hard, progress, error)
         if (allocated(error)) return
      end if
      ! (a sliding viscoelastic scene lossy among its short waves whose coarse start holds
      ! enough contact points: with a few, GCR is the faster method)
      if (method == 'auto' .and. op%kernel%viscoelastic .and. len(reason) == 0 .and. &
         & grid%points() >= merge(lossy_multigrid_points, lossy_surface_points, grid%is_line())) then
         loss = loss_among_short_waves(op)
         if (grid%is_line()) then
            if (loss >= short_wave_loss .and. count(p > 0.0_wp) >= lossy_line_contacts) method = 'multigrid'
         else if (loss >= short_loss_limit .and. count(p > 0.0_wp) >= lossy_surface_contacts .and. &
            & len(metric_refusal(op)) == 0) then
            method = 'multigrid'
         end if
      end if
      ! (a coupled scene, or a frictionless one whose compliance rises, where its coarse solve
      ! was hard: broadband roughness; a rising compliance from rising_multigrid_points)
      if (method == 'auto' .and. (op%coupled .or. rising) .and. coarse_hard .and. len(reason) == 0 .and. &
         & grid%points() >= coupled_threshold(grid, .false.)) then
         if (len(metric_refusal(op)) == 0 .or. grid%points() >= rising_multigrid_points) method = 'multigrid'
      else if (method == 'auto' .and. op%coupled .and. coarse_hard .and. len(reason) == 0 .and. &
         & grid%points() >= coupled_threshold(grid, .true.)) then
         if (rows_ahead_of_gcr(op, load_control)) method = 'multigrid'
      end if
      call progress%begin_level(grid%nx, grid%ny)
      uniform = 0.0_wp
      if (load_control) call op%drop_uniform_mode(uniform)
      ! only the first `iterations` entries are written and read (not zeroed: the budget may
      ! be 1e7 entries, and untouched pages cost nothing)
      allocate (history(scene%solver%max_iter))
      if (trim(scene%solver%method) == 'newton') then
         if (grid%points() > dense_points) then
            call fatal_error(error, "&solver: method = 'newton' (dense) needs a grid of at most " // &
               & to_string(dense_points) // ' points; this one has ' // to_string(grid%points()) // &
               & "; allowed here: 'auto', 'cg', 'gcr', 'anderson', 'gfmd' or 'multigrid'", code_input)
            return
         end if
         call dense_newton(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, p, w, &
            & gap, newton, progress)
         call record_solve(result, 'newton', newton%converged, newton%steps, 1, newton%fft_pairs, newton%residual, &
            & [newton%residual])
      else if (method == 'multigrid' .and. (op%coupled .or. rising)) then
         call coupled_tnnmg(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, p, w, &
            & gap, nested, history, progress, error)
         if (allocated(error)) return
         call record_solve(result, 'multigrid', nested%converged, nested%iterations, 1, nested%fft_pairs, &
            & nested%residual, history(1:min(nested%iterations, size(history))))
         ! (where the non-symmetric part defeats it, strongly glassy layers, the GCR goes on
         ! from its best iterate)
         if (.not. nested%converged .and. nested%iterations < scene%solver%max_iter) then
            previous = result
            call coupled_gcr(scene, grid, op, height, load_control, pm, g_ref, p, w, gap, s, history, result, &
               & progress, error, previous)
            if (allocated(error)) return
         end if
      else if (method == 'multigrid') then
         call multigrid(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, p, w, gap, &
            & nested, history, progress, error)
         if (allocated(error)) return
         call record_solve(result, 'multigrid', nested%converged, nested%iterations, 1, nested%fft_pairs, &
            & nested%residual, history(1:min(nested%iterations, size(history))))
         ! Near the rounding floor (tol 1e-12 on 2048^2) the fields returned from the
         ! displacement form can miss tol by their rescaling to the load (which moves w by
         ! ~tol on the contact set) whatever the iteration's own target; the constrained CG,
         ! which keeps the load exact in every iteration, finishes from them.
         if (.not. nested%converged .and. nested%iterations < scene%solver%max_iter) then
            call constrained_cg(op, height, load_control, pm, s, g_ref, scene%solver%tol, &
               & scene%solver%max_iter - nested%iterations, scene%solver%precondition, p, w, gap, cg, &
               & history(nested%iterations + 1:), progress)
            call record_solve(result, 'multigrid+cg', cg%converged, nested%iterations + cg%iterations, 1, &
               & nested%fft_pairs + cg%fft_pairs, cg%residual, &
               & history(1:min(nested%iterations + cg%iterations, size(history))))
         end if
      else if (trim(scene%solver%method) == 'gfmd') then
         call gfmd(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, p, w, gap, &
            & dynamics, history, progress)
         call record_solve(result, 'gfmd', dynamics%converged, dynamics%iterations, 1, dynamics%fft_pairs, &
            & dynamics%residual, history(1:min(dynamics%checks, size(history))))
      else if ((op%coupled .and. trim(scene%solver%method) == 'auto') .or. trim(scene%solver%method) == 'gcr') then
         call coupled_gcr(scene, grid, op, height, load_control, pm, g_ref, p, w, gap, s, history, result, progress, &
            & error)
         if (allocated(error)) return
      else if (op%coupled) then
         call anderson_coupled(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, &
            & scene%solver%memory, scene%solver%precondition, p, w, gap, outer, history, error, progress)
         if (allocated(error)) return
         call record_solve(result, 'anderson', outer%converged, outer%cg_iterations, outer%outer_iterations, &
            & outer%fft_pairs, outer%residual, history(1:outer%outer_iterations))
      else
         call constrained_cg(op, height, load_control, pm, s, g_ref, scene%solver%tol, scene%solver%max_iter, &
            & scene%solver%precondition, p, w, gap, cg, history, progress)
         call record_solve(result, 'cg', cg%converged, cg%iterations, 1, cg%fft_pairs, cg%residual, &
            & history(1:cg%iterations))
      end if
      if (.not. result%converged .and. dense_applies(scene, grid, op) .and. result%iterations < scene%solver%max_iter) &
         & call finish_dense(op, height, load_control, pm, g_ref, scene%solver%tol, &
         & min(newton_step_limit, scene%solver%max_iter - result%iterations), p, w, gap, s, result, progress)
      result%fft_pairs = result%fft_pairs + coarse_pairs
      ! The solvers stop when the residual, with gaps below the rounding floor of w - r
      ! counted as zero, reaches tol: no iteration resolves such gaps. At loads so large that
      ! this noise exceeds the tolerance (p_m = 1e300: the pressure's variation is lost in the
      ! rounding of p_m) the solution is not resolved to tol in double precision: the run
      ! reports the residual without the floor and does not claim convergence.
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
      s = s + uniform*pm
   end subroutine solve_on_grid

   !> A coupled scene by the constrained GCR from p; under method 'auto' (or after the
   !> multigrid method, `before`) a solve that stalls goes on with the GCR from its best
   !> iterate, now keeping its history across clips (on broadband fine grids the restarted
   !> GCR stalls while the set settles by a clip every iteration or two; the kept history
   !> costs more per set change than it saves elsewhere), then with the Anderson outer
   !> iteration, with the budget left, less the steps of the dense Newton method where that
   !> finishes what the Anderson iteration leaves (dense_applies: an Anderson iteration costs
   !> ~1e-3 of a Newton step there, so it goes first: a glassy layer at n = 1024 converges in
   !> 97362 of them in 0.6 s, the Newton method from GCR's iterate in 3.2 s). The counts of
   !> `before` are added to the result's.
   subroutine coupled_gcr(scene, grid, op, height, load_control, pm, g_ref, p, w, gap, s, history, result, &
         & progress, error, before)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: height(:), pm, g_ref
      logical, intent(in) :: load_control
      real(wp), intent(inout) :: p(:), s
      real(wp), intent(inout) :: w(:), gap(:)
      real(wp), intent(inout) :: history(:)
      type(contact_result), intent(inout) :: result
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(contact_result), intent(in), optional :: before
      type(gcr_outcome) :: gcr, kept
      type(anderson_outcome) :: outer
      real(wp), allocatable :: p_gcr(:), w_gcr(:), gap_gcr(:)
      character(len=:), allocatable :: prefix
      real(wp) :: s_gcr, residual_before
      integer :: reserve, spent, pairs_before, max_iter
      logical :: fallback

      fallback = trim(scene%solver%method) == 'auto' .or. present(before)
      prefix = ''
      spent = 0
      pairs_before = 0
      if (present(before)) then
         prefix = trim(before%solver) // '+'
         spent = before%iterations
         pairs_before = before%fft_pairs
      end if
      max_iter = scene%solver%max_iter - spent
      call constrained_gcr(op, height, load_control, pm, s, g_ref, scene%solver%tol, max_iter, &
         & scene%solver%memory, scene%solver%precondition, p, w, gap, gcr, history(spent + 1:), progress)
      call record_solve(result, prefix // 'gcr', gcr%converged, spent + gcr%iterations, 1, pairs_before + gcr%fft_pairs, &
         & gcr%residual, history(1:spent + gcr%iterations))
      if (.not. gcr%converged .and. fallback .and. result%iterations < scene%solver%max_iter) then
         reserve = 0
         if (dense_applies(scene, grid, op)) reserve = min(newton_step_limit, &
            & (scene%solver%max_iter - result%iterations)/2)
         call constrained_gcr(op, height, load_control, pm, s, g_ref, scene%solver%tol, &
            & scene%solver%max_iter - result%iterations - reserve, scene%solver%memory, scene%solver%precondition, &
            & p, w, gap, kept, history(result%iterations + 1:), progress, keep_clipped=.true.)
         ! (its first iterate is GCR's best, so its best is no worse)
         call record_solve(result, trim(result%solver) // '+kept', kept%converged, result%iterations + &
            & kept%iterations, 1, result%fft_pairs + kept%fft_pairs, kept%residual, &
            & history(1:result%iterations + kept%iterations))
      end if
      if (.not. result%converged .and. fallback .and. result%iterations < scene%solver%max_iter) then
         reserve = 0
         if (dense_applies(scene, grid, op)) reserve = min(newton_step_limit, &
            & (scene%solver%max_iter - result%iterations)/2)
         ! (GCR's best iterate is kept in case the Anderson iteration ends worse)
         residual_before = result%residual
         p_gcr = p
         w_gcr = w
         gap_gcr = gap
         s_gcr = s
         call anderson_coupled(op, height, load_control, pm, s, g_ref, scene%solver%tol, &
            & scene%solver%max_iter - result%iterations - reserve, scene%solver%memory, &
            & scene%solver%precondition, p, w, gap, outer, history, error, progress)
         if (allocated(error)) return
         call record_solve(result, trim(result%solver) // '+anderson', outer%converged, &
            & result%iterations + outer%cg_iterations, 1 + outer%outer_iterations, &
            & result%fft_pairs + outer%fft_pairs, min(outer%residual, result%residual), &
            & [result%residual_history, history(1:outer%outer_iterations)])
         if (outer%residual > residual_before) then
            p = p_gcr
            w = w_gcr
            gap = gap_gcr
            s = s_gcr
         end if
      end if
   end subroutine coupled_gcr

   !> Whether the dense Newton method may finish a solve that stalled: under method 'auto',
   !> on a grid of at most dense_points points, for a monotone operator (Re G_eff >= 0 on
   !> every mode), where the solution is unique and the merit has no other stationary point.
   !> (Elsewhere it may wander for its whole step limit at ~(2/3) n^3 a step.)
   pure logical function dense_applies(scene, grid, op)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(compliance_operator), intent(in) :: op
      dense_applies = trim(scene%solver%method) == 'auto' .and. grid%points() <= dense_points .and. op%monotone
   end function dense_applies

   !> A small grid that the iterative solvers left unconverged before the budget ran out
   !> (they stopped on stagnation) is solved by the dense semismooth Newton method from
   !> their last iterate (lc_contact_solver_newton), with the steps left in the budget; the
   !> better of the two is kept. The solver is reported as, e.g., 'gcr+kept+anderson+newton'.
   subroutine finish_dense(op, height, load_control, pm, g_ref, tol, budget, p, w, gap, s, result, progress)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: height(:), pm, g_ref, tol
      integer, intent(in) :: budget
      logical, intent(in) :: load_control
      real(wp), intent(inout) :: p(:), w(:), gap(:), s
      type(contact_result), intent(inout) :: result
      type(progress_log), intent(inout) :: progress
      type(newton_outcome) :: newton
      real(wp), allocatable :: p_iterative(:), w_iterative(:), gap_iterative(:)
      real(wp) :: s_iterative
      allocate (p_iterative, source=p)
      allocate (w_iterative, source=w)
      allocate (gap_iterative, source=gap)
      s_iterative = s
      progress%offset = result%iterations
      call dense_newton(op, height, load_control, pm, s, g_ref, tol, budget, p, w, gap, newton, progress)
      progress%offset = 0
      result%solver = trim(result%solver) // '+newton'
      result%iterations = result%iterations + newton%steps
      result%fft_pairs = result%fft_pairs + newton%fft_pairs
      result%residual_history = [result%residual_history, newton%residual]
      if (newton%residual <= result%residual) then
         result%converged = newton%converged
         result%residual = newton%residual
      else
         p = p_iterative
         w = w_iterative
         gap = gap_iterative
         s = s_iterative
      end if
   end subroutine finish_dense

   !> The solver statistics of `result`: which method ran and what it did.
   pure subroutine record_solve(result, solver, converged, iterations, outer_iterations, fft_pairs, residual, history)
      type(contact_result), intent(inout) :: result
      character(len=*), intent(in) :: solver
      logical, intent(in) :: converged
      integer, intent(in) :: iterations, outer_iterations, fft_pairs
      real(wp), intent(in) :: residual, history(:)
      result%solver = solver
      result%converged = converged
      result%iterations = iterations
      result%outer_iterations = outer_iterations
      result%fft_pairs = fft_pairs
      result%residual = residual
      result%residual_history = history
   end subroutine record_solve

   !> Replace the guess p (and s) by the solution on the grid of every second point,
   !> interpolated linearly (which keeps p >= 0). The coarse solve needs only the accuracy
   !> of a starting guess (coarse_tol); its FFT pairs are returned in units of pairs of
   !> this grid (2 or 4 times as long each, on a line or a surface).
   recursive subroutine coarse_solution(scene, grid, kernel, height, friction, load_control, pm, g_ref, p, s, &
         & pairs, hard, progress, error)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in) :: height(:), friction, pm, g_ref
      logical, intent(in) :: load_control
      real(wp), intent(inout) :: p(:), s
      integer, intent(out) :: pairs
      !> the coarse solve needed more than hard_coarse_iterations GCR (or CG) iterations
      !> (hard_coarse_surface_iterations on a surface), or went to the multigrid method
      logical, intent(out) :: hard
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: coarse
      type(grid_type) :: coarse_grid
      type(compliance_operator) :: coarse_op
      type(contact_result) :: coarse_result
      real(wp), allocatable :: pc(:), wc(:), gapc(:), hc(:)
      real(wp) :: sc
      integer :: ratio

      pairs = 0
      hard = .false.
      coarse_grid = grid%coarse()
      coarse = scene
      coarse%solver%tol = max(scene%solver%tol, coarse_tol*min(1.0_wp, real(coarse_tol_size, wp)/grid%nx))
      if (trim(scene%solver%method) == 'multigrid') coarse%solver%tol = max(scene%solver%tol, multigrid_coarse_tol)
      allocate (wc(coarse_grid%points()), gapc(coarse_grid%points()))
      hc = restrict(grid, height)
      pc = restrict(grid, p)
      sc = s
      call solve_on_grid(coarse, coarse_grid, kernel, hc, friction, load_control, pm, g_ref, coarse_op, pc, wc, &
         & gapc, sc, coarse_result, progress, error)
      if (allocated(error)) return
      call interpolate(grid, pc, p)
      if (load_control) s = sc
      ratio = grid%points()/coarse_grid%points()
      pairs = (coarse_result%fft_pairs + ratio - 1)/ratio
      hard = index(coarse_result%solver, 'multigrid') == 1 .or. ((index(coarse_result%solver, 'gcr') == 1 .or. &
         & index(coarse_result%solver, 'cg') == 1) .and. &
         & coarse_result%iterations > merge(hard_coarse_iterations, hard_coarse_surface_iterations, grid%is_line()))
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
