!> Truncated nonsmooth Newton multigrid (TNNMG) for the frictionless contact of a line on an
!> elastic half-space or layer: Graeser and Kornhuber, "Multigrid methods for obstacle
!> problems" (J. Comput. Math., 2009), and "Nonsmooth Newton methods for set-valued saddle
!> point problems" (SIAM J. Numer. Anal., 2009).
!>
!> Displacement form. With the stiffness K = 1/M (the inverse of the operator's real normal
!> compliance, mode by mode) and u the surface displacement seen from the rigid profile's
!> reference, the contact problem is the obstacle problem
!>    minimise J(u) = 1/2 u.K u + f sum(u)  subject to  u >= o,
!> whose optimality conditions are p = K u + f >= 0, gap = u - o >= 0, p gap = 0. Under load
!> control K(0) = 0 (the uniform mode is the rigid shift, see drop_uniform_mode), f = p_m and
!> o = b, so mean(p) = p_m holds by construction and no multiplier is iterated; under
!> displacement control K(0) = 1/M(0), f = 0 and o = b + s.
!>
!> One iteration on a grid: a projected damped Jacobi step (it releases every contact point
!> that carries tension at once, and lowers J); the truncated Newton problem K_II c_I = -p_I
!> (c = 0 on the contact set A), solved inexactly by at most two CG iterations preconditioned
!> by a V-cycle; the direction projected onto u >= o and an exact line search (J is
!> quadratic). Both steps lower J, hence global convergence; the Newton step finds the
!> contact set in few iterations. Once the set has settled, a finishing CG phase solves the
!> linear problem on it and checks the complementarity residual at every iteration.
!>
!> V-cycle (for K_II): linear interpolation P, restriction P^T; on the grid being solved the
!> exactly truncated operator I K I (one transform pair), on the coarser ones the Galerkin
!> product of the penalised operator K + d D_A (D_A the indicator of the contact set, d the
!> diagonal of K): a Galerkin circulant (a transform on the coarse grid; its symbol does not
!> depend on the contact set) plus a tridiagonal part rebuilt in O(n) when the set changes.
!> The penalty stands in for the truncated Galerkin operator P^T I K I P, whose application
!> would cost a transform of the finest grid. Damped Jacobi smoothing; a dense Cholesky
!> solve on the coarsest grid (at most coarsest_limit points). The Newton direction needs
!> only to be a descent direction, which is what lets the coarse operators be this cheap.
!>
!> Nested iteration: the solve starts on the grid of every 2^J-th point (the coarsest of at
!> least nested_coarsest points), solved to tol from u = o; each finer grid starts from the
!> spectral interpolation of the coarser u and gets one iteration; the finest is iterated
!> to tol. The convergence measure is the library's complementarity residual
!> max_j |min(p_j/p_ref, gap_j/g_ref)| (gaps below the rounding floor count as zero),
!> evaluated on (K u + f, u - o) in the iteration and on the fields returned at the end.
!>
!> Applies where pointwise Jacobi smooths, i.e. the stiffness rises with |q| (the
!> operator's metric_falls, or nearly: allowed_rise), to symmetric (not coupled), elastic
!> lines: multigrid_refusal.
module lc_contact_solver_multigrid
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp
   use lc_errors, only: error_type
   use lc_strings, only: to_string, formatted
   use lc_fft_plans, only: fft_plan
   use lc_contact_operator, only: compliance_operator
   use lc_contact_solver_cg, only: complementarity_residual, rounding_floor, normalise
   use lc_contact_progress, only: progress_log
   implicit none (type, external)
   private
   public :: multigrid, multigrid_outcome, multigrid_refusal
   public :: metric_refusal, multigrid_warm

   !> Damping of the Jacobi steps (nonlinear smoother and V-cycle): below 1 the projected
   !> step lowers the energy monotonically; 2/3 damps the upper half of the spectrum best.
   real(wp), parameter :: omega = 2.0_wp/3.0_wp
   !> Jacobi smooths K_II where the stiffness rises with |q|; a compliance that falls with |q|
   !> (op%metric_falls) is more than needed: it may rise over the grid by up to this factor
   !> relative to a longer wave. (Measured to tol 1e-8, n = 4096 and 65536, both roughness
   !> families: 2-4 fine iterations on compressible layers, whose compliance rises by 2 %
   !> (nu = 0.3) to 2.1 (nu = 0.45) below |q| h ~ 1, and on incompressible ones rising by
   !> up to 31; 6 iterations but 300-1200 pairs at 16.5 (h/lambda = 0.001, nu = 0.495), no
   !> convergence in 300 iterations at 123 (h/lambda = 0.01, nu = 0.5).)
   real(wp), parameter :: allowed_rise = 4.0_wp
   !> The V-cycle coarsens while the next grid has at least this many points ...
   integer, parameter :: coarsest_points = 64
   !> ... and its coarsest grid (solved densely) may have at most this many.
   integer, parameter :: coarsest_limit = 256
   !> The nested iteration starts on the coarsest grid of at least this many points.
   integer, parameter :: nested_coarsest = 256
   !> Weight of the contact-set penalty d D_A in the coarse operators (in units of the
   !> diagonal d of K): 1 gave the fewest CG iterations on the final set against 0.5, 2, 10.
   real(wp), parameter :: penalty = 1.0_wp
   !> The inexact Newton solve: at most this many CG iterations, or a residual reduced by
   !> newton_reduction; more exact solves cost more transforms than the iterations saved.
   integer, parameter :: newton_iterations = 2
   real(wp), parameter :: newton_reduction = 0.1_wp
   !> The finishing phase starts when no contact point carries tension and at most this
   !> fraction of the contact set changed in the last iteration ...
   real(wp), parameter :: settled_fraction = 1.0e-3_wp
   !> ... and runs at most this many CG iterations.
   integer, parameter :: finish_iterations = 40
   !> If the fields returned miss tol (their residual is evaluated on the pressure with the
   !> points out of contact set to zero), the iteration goes on to a tolerance this much
   !> smaller, at most `tightenings` times.
   real(wp), parameter :: tightening = 0.1_wp
   integer, parameter :: tightenings = 3

   !> What one multigrid solve did. `iterations` counts the TNNMG iterations on the finest
   !> grid (a finishing CG phase counts as one); `fft_pairs` every transform pair on every
   !> grid, a pair of m points counting m/n, the nested iteration's grids included.
   type :: multigrid_outcome
      logical :: converged = .false.
      integer :: iterations = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
      integer :: vcycles = 0   !< V-cycles started on the grid being solved, all grids
   end type multigrid_outcome

   !> One grid of n/2^t points: its plan, the operator on it for the current hierarchy, and
   !> the V-cycle's work arrays.
   type :: grid_level
      integer :: n = 0
      type(fft_plan) :: fft
      real(wp) :: inv_n = 1.0_wp
      real(wp), allocatable :: symbol(:)       !< circulant part, half spectrum (n/2 + 1)
      real(wp), allocatable :: multiplier(:)   !< symbol/n, as applied after an unscaled r2c
      real(wp) :: circulant_diagonal = 0.0_wp
      !> tridiagonal penalty: diagonal, and off(i) coupling i and i + 1 (periodic)
      real(wp), allocatable :: penalty_diagonal(:), penalty_off(:)
      real(wp), allocatable :: jacobi(:)       !< omega over the diagonal of the operator
      real(wp), allocatable :: rhs(:), x(:), residual(:)
   end type grid_level

   !> The grids n/2^t, t = 0..coarsest (one plan per size, shared by the nested grids), the
   !> grid being solved (`top`: its operator is I K I, the coarser ones are the V-cycle's)
   !> and the transform count.
   type :: hierarchy
      type(grid_level), allocatable :: level(:)
      integer :: top = 0, coarsest = 0, n_fine = 0
      real(wp), allocatable :: free(:)           !< 1 off the contact set, 0 on it (top grid)
      real(wp), allocatable :: dense(:, :)       !< Cholesky factor of the coarsest operator
      real(wp), allocatable :: coarse_column(:)  !< real-space column of its circulant part
      real(wp) :: pairs = 0.0_wp
      integer :: vcycles = 0
   end type hierarchy

   !> The scales of the residual, from the last full evaluation of the state.
   type :: residual_scales
      real(wp) :: p_scale = 1.0_wp, g_scale = 1.0_wp, floor = 0.0_wp
   end type residual_scales


contains

   !> Why the method cannot solve the scene of `op` (empty if it can).
   function multigrid_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      integer :: m
      reason = ''
      if (op%grid%ny /= 1) then
         reason = 'it solves lines, and this scene is a surface'
      else if (op%kernel%viscoelastic) then
         reason = 'the layer is viscoelastic and sliding (its compliance is complex)'
      else if (op%coupled) then
         reason = 'friction couples the normal and tangential fields and the operator is not symmetric'
      else if (.not. op%metric_falls .and. compliance_rise(op) > allowed_rise) then
         reason = 'the compliance rises with |q| over the grid by a factor ' // formatted(compliance_rise(op), &
            & '(f0.1)') // ' (a thin, nearly incompressible layer; pointwise smoothing needs at most ' // &
            & formatted(allowed_rise, '(f0.1)') // ')'
      else
         m = op%grid%nx/2**halvings(op%grid%nx, coarsest_points)
         if (m > coarsest_limit) reason = 'n = ' // to_string(op%grid%nx) // ' halves to an odd grid of ' // &
            & to_string(m) // ' points; it needs n = m 2^k with m <= ' // to_string(coarsest_limit)
      end if
   end function multigrid_refusal

   !> Why the method cannot solve the symmetric problem with the operator's metric
   !> M = |G_eff| (empty if it can): multigrid_refusal without the refusal of coupled and
   !> viscoelastic operators, for the inner solves of an outer iteration on a coupled line.
   function metric_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      integer :: m
      reason = ''
      if (op%grid%ny /= 1) then
         reason = 'it solves lines, and this scene is a surface'
      else if (.not. op%metric_falls .and. compliance_rise(op) > allowed_rise) then
         reason = 'the compliance rises with |q| over the grid by a factor ' // formatted(compliance_rise(op), &
            & '(f0.1)') // ' (a thin, nearly incompressible layer; pointwise smoothing needs at most ' // &
            & formatted(allowed_rise, '(f0.1)') // ')'
      else
         m = op%grid%nx/2**halvings(op%grid%nx, coarsest_points)
         if (m > coarsest_limit) reason = 'n = ' // to_string(op%grid%nx) // ' halves to an odd grid of ' // &
            & to_string(m) // ' points; it needs n = m 2^k with m <= ' // to_string(coarsest_limit)
      end if
   end function metric_refusal

   !> The symmetric problem with the operator's metric M (as multigrid), iterated on the
   !> finest grid only from the pressure p given on entry (its displacement M p, less, under
   !> load control, the mean of M p - b over p's contact set), without the nested iteration:
   !> for a sequence of problems whose solutions are close (the inner solves of an outer
   !> iteration). s: in the given constant (displacement control); out as multigrid.
   subroutine multigrid_warm(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, &
         & history, progress, error)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure
      real(wp), intent(inout) :: s
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(multigrid_outcome), intent(out) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(hierarchy) :: h
      real(wp), allocatable :: stiffness(:), u(:), o(:)
      real(wp) :: f, target
      integer :: n, steps, tightened
      logical :: converged

      n = size(p)
      call build_hierarchy(h, n, error)
      if (allocated(error)) return
      allocate (stiffness(n/2 + 1), u(n), o(n))
      where (op%metric(1:n/2 + 1) > 0.0_wp)
         stiffness = 1.0_wp/op%metric(1:n/2 + 1)
      elsewhere
         stiffness = 0.0_wp
      end where
      if (load_control) stiffness(1) = 0.0_wp
      f = merge(mean_pressure, 0.0_wp, load_control)
      call set_grid(h, 0, stiffness)
      o = b
      if (.not. load_control) o = o + s
      call op%apply_metric(p, u)
      h%pairs = h%pairs + 1.0_wp
      ! (the gap of p is zero on its contact set; the constant is not taken from the caller,
      ! whose s may hold the uniform mode's shift)
      if (load_control .and. any(p > 0.0_wp)) s = sum(u - b, mask=p > 0.0_wp)/count(p > 0.0_wp)
      if (load_control) u = u - s
      target = tol
      tightened = 0
      do
         call tnnmg(h, op, u, o, f, load_control, g_ref, target, max_iter - outcome%iterations, p, steps, &
            & converged, history(outcome%iterations + 1:), progress)
         outcome%iterations = outcome%iterations + steps
         call returned_fields(op, u, o, b, load_control, mean_pressure, g_ref, p, w, gap, s, outcome%residual)
         h%pairs = h%pairs + 1.0_wp
         if (outcome%residual <= tol .or. outcome%iterations >= max_iter .or. tightened == tightenings) exit
         target = target*tightening
         tightened = tightened + 1
      end do
      outcome%converged = outcome%residual <= tol
      outcome%fft_pairs = nint(h%pairs)
      outcome%vcycles = h%vcycles
   end subroutine multigrid_warm

   !> How many times a grid of n points halves while the result stays even-sized and
   !> at least `smallest` points long (n/2**k with k the count is the coarsest grid).
   pure integer function halvings(n, smallest) result(k)
      integer, intent(in) :: n, smallest
      integer :: m
      k = 0
      m = n
      do while (mod(m, 2) == 0 .and. m/2 >= smallest)
         m = m/2
         k = k + 1
      end do
   end function halvings

   !> The largest factor by which the normal compliance M(q) on the grid's modes exceeds its
   !> value at a longer wave: 1 where it falls with |q| (op%metric_falls).
   pure real(wp) function compliance_rise(op) result(rise)
      type(compliance_operator), intent(in) :: op
      real(wp) :: lowest
      integer :: k
      rise = 1.0_wp
      if (op%nk < 3) return
      lowest = op%metric(2)
      do k = 3, op%nk
         lowest = min(lowest, op%metric(k))
         rise = max(rise, op%metric(k)/lowest)
      end do
   end function compliance_rise

   !> Solve the frictionless contact of a line: w = M p, gap = w - b - s >= 0, p >= 0,
   !> p gap = 0, under load control (mean(p) = p_m, s found) or displacement control (s
   !> given). p: out the solution (the guess on entry is not used: the nested iteration makes
   !> its own); w = M p; gap. history(1:outcome%iterations) receives the residual of each
   !> fine-grid iteration. The scene must pass multigrid_refusal.
   subroutine multigrid(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, history, &
         & progress, error)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: found
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(multigrid_outcome), intent(out) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(hierarchy) :: h
      real(wp), allocatable :: stiffness(:), u(:), o(:)
      real(wp) :: f, target
      integer :: n, j, nested, m, steps, tightened
      logical :: converged

      n = size(p)
      call build_hierarchy(h, n, error)
      if (allocated(error)) return
      ! K = 1/M on the modes k = 0..n/2; a coarser grid of the nested iteration samples the
      ! same wavenumbers, so its symbol is the first m/2 + 1 of these. (M(0) = 0 under load
      ! control, the uniform mode being dropped: K(0) = 0.)
      allocate (stiffness(n/2 + 1), u(n), o(n))
      where (op%metric(1:n/2 + 1) > 0.0_wp)
         stiffness = 1.0_wp/op%metric(1:n/2 + 1)
      elsewhere
         stiffness = 0.0_wp
      end where
      if (load_control) stiffness(1) = 0.0_wp
      f = merge(mean_pressure, 0.0_wp, load_control)

      nested = halvings(n, nested_coarsest)
      do j = nested, 0, -1
         m = h%level(j)%n
         call set_grid(h, j, stiffness(1:m/2 + 1))
         o(1:m) = b(1:n:2**j)
         if (.not. load_control) o(1:m) = o(1:m) + s
         if (j == nested) then
            u(1:m) = o(1:m)
         else
            gap(1:m/2) = u(1:m/2)   ! (a copy: the interpolation writes over u)
            call interpolate(h, j, gap(1:m/2), u(1:m))
         end if
         if (j == 0) exit
         ! the coarsest grid to tol, the others one iteration each
         call tnnmg(h, op, u(1:m), o(1:m), f, load_control, g_ref, tol, merge(max_iter, 1, j == nested), &
            & p(1:m), steps, converged)
      end do

      ! the finest grid, to tol on the fields returned
      target = tol
      tightened = 0
      do
         call tnnmg(h, op, u, o, f, load_control, g_ref, target, max_iter - outcome%iterations, p, steps, &
            & converged, history(outcome%iterations + 1:), progress)
         outcome%iterations = outcome%iterations + steps
         call returned_fields(op, u, o, b, load_control, mean_pressure, g_ref, p, w, gap, s, outcome%residual)
         h%pairs = h%pairs + 1.0_wp
         if (outcome%iterations > 0) history(min(outcome%iterations, size(history))) = outcome%residual
         if (outcome%residual <= tol .or. outcome%iterations >= max_iter .or. tightened == tightenings) exit
         target = target*tightening
         tightened = tightened + 1
      end do
      outcome%converged = outcome%residual <= tol
      outcome%fft_pairs = nint(h%pairs)
      outcome%vcycles = h%vcycles
   end subroutine multigrid

   !> TNNMG iterations on the grid h%top from u until the residual on (K u + f, u - o) is at
   !> most tol or max_steps ran; p = K u + f on exit. steps: iterations run. history and
   !> progress (the finest grid): the residual of each iteration.
   subroutine tnnmg(h, op, u, o, f, load_control, g_ref, tol, max_steps, p, steps, converged, history, progress)
      type(hierarchy), intent(inout) :: h
      type(compliance_operator), intent(in) :: op
      real(wp), contiguous, intent(inout) :: u(:)
      real(wp), contiguous, intent(in) :: o(:)
      real(wp), intent(in) :: f, g_ref, tol
      logical, intent(in) :: load_control
      integer, intent(in) :: max_steps
      real(wp), contiguous, intent(out) :: p(:)
      integer, intent(out) :: steps
      logical, intent(out) :: converged
      real(wp), contiguous, intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      ! (allocated once per grid: the iterations below allocate nothing)
      real(wp), allocatable :: c(:), kc(:), v(:), kv(:), previous(:), work(:, :)
      type(residual_scales) :: scales
      real(wp) :: residual, diagonal, alpha, vkv, b_max, contact
      integer :: m, step, changed, j
      logical :: settled, finished, clipped, tension

      m = size(u)
      allocate (c(m), kc(m), v(m), kv(m), previous(m), work(m, 3))
      previous = 1.0_wp
      diagonal = h%level(h%top)%circulant_diagonal
      b_max = maxval(abs(o))
      u = max(u, o)
      call apply_stiffness(h, u, p)
      p = p + f
      converged = .false.
      steps = 0
      do step = 1, max_steps
         steps = step
         ! nonlinear smoother: projected damped Jacobi
         u = max(o, u - (omega/diagonal)*p)
         call apply_stiffness(h, u, p)
         p = p + f
         scales = scales_of(u, p, load_control, f, g_ref, b_max, op%largest)
         residual = residual_of(u, p, o, scales)
         contact = count(u <= o)/real(m, wp)
         call record(step, residual, contact)
         if (residual <= tol) then
            converged = .true.
            exit
         end if
         if (load_control .and. contact == 0.0_wp) then
            ! nothing touches: the energy falls along the rigid shift until the lowest point
            ! touches (K(0) = 0, so p does not change); the truncated problem would be singular
            u = u - minval(u - o)
            cycle
         end if
         ! the truncated problem on the free points; the finishing phase once the contact set
         ! has settled
         changed = 0
         tension = .false.
         do j = 1, m
            h%free(j) = merge(1.0_wp, 0.0_wp, u(j) > o(j))
            if (h%free(j) /= previous(j)) changed = changed + 1
            if (h%free(j) == 0.0_wp .and. p(j) < 0.0_wp) tension = .true.
         end do
         settled = step > 1 .and. changed <= settled_fraction*contact*m .and. .not. tension
         previous = h%free(1:m)
         call set_contact(h)
         finished = .false.
         if (settled) then
            call truncated_cg(h, u, o, p, finish_iterations, 0.0_wp, c, kc, work, scales, tol, finished, residual)
         else
            call truncated_cg(h, u, o, p, newton_iterations, newton_reduction, c, kc, work)
         end if
         if (finished) then
            u = u + c
            p = p + kc
            call record(step, residual, contact)
            converged = .true.
            exit
         end if
         ! projection onto u >= o and exact line search on the quadratic J
         clipped = .false.
         do j = 1, m
            v(j) = c(j)
            if (u(j) + c(j) < o(j)) then
               v(j) = o(j) - u(j)
               clipped = .true.
            end if
         end do
         if (clipped) then
            call apply_stiffness(h, v, kv)
         else
            kv = kc
         end if
         vkv = dot_product(v, kv)
         if (.not. vkv > 0.0_wp) cycle
         alpha = min(1.0_wp, max(0.0_wp, -dot_product(p, v)/vkv))
         u = u + alpha*v
         p = p + alpha*kv
      end do
   contains
      subroutine record(step, residual, contact)
         integer, intent(in) :: step
         real(wp), intent(in) :: residual, contact
         if (present(history)) then
            if (step <= size(history)) history(step) = residual
         end if
         if (present(progress)) call progress%tick(step, residual, contact)
      end subroutine record
   end subroutine tnnmg

   !> CG on the truncated Newton problem I K I c = -I p (c = 0 on the contact set),
   !> preconditioned by the V-cycle, from c = 0; kc = K c (carried along at no cost).
   !> work(:, 1:3): the residual, the direction and its image. Without `scales`: at most
   !> max_steps iterations, or until the residual fell by `reduction`. With them (the
   !> finishing phase): after every iteration the complementarity residual of
   !> (u + c, p + kc) is checked; `finished` when it is at most tol (with `residual`); the
   !> phase stops early, c then a direction for the line search, when a point leaves the
   !> feasible set (u + c < o off the contact set, or p + kc < 0 on it).
   subroutine truncated_cg(h, u, o, p, max_steps, reduction, c, kc, work, scales, tol, finished, residual)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: u(:), o(:), p(:)
      integer, intent(in) :: max_steps
      real(wp), intent(in) :: reduction
      real(wp), contiguous, intent(out) :: c(:), kc(:)
      real(wp), contiguous, intent(inout) :: work(:, :)
      type(residual_scales), intent(in), optional :: scales
      real(wp), intent(in), optional :: tol
      logical, intent(out), optional :: finished
      real(wp), intent(out), optional :: residual
      real(wp) :: rz, rz_old, b_norm, r_norm, dkd, a
      logical :: violated
      integer :: it, m, j

      m = size(u)
      c = 0.0_wp
      kc = 0.0_wp
      if (present(finished)) finished = .false.
      associate (r => work(:, 1), d => work(:, 2), kd => work(:, 3), free => h%free(1:m))
      r = -free*p
      b_norm = norm2(r)
      if (b_norm == 0.0_wp) return
      call precondition(r, d)
      rz = dot_product(r, d)
      do it = 1, max_steps
         ! (d is zero on the contact set, as the V-cycle's output: d.I K d = d.K d)
         call apply_stiffness(h, d, kd)
         dkd = dot_product(d, kd)
         if (.not. dkd > 0.0_wp) exit
         a = rz/dkd
         r_norm = 0.0_wp
         !$omp simd reduction(+:r_norm)
         do j = 1, m
            c(j) = c(j) + a*d(j)
            kc(j) = kc(j) + a*kd(j)
            r(j) = r(j) - a*free(j)*kd(j)
            r_norm = r_norm + r(j)**2
         end do
         if (present(scales)) then
            call check_finish(u, o, p, c, kc, free, scales, residual, violated)
            if (violated) exit
            if (residual <= tol) then
               finished = .true.
               exit
            end if
         else if (sqrt(r_norm) <= reduction*b_norm) then
            exit
         end if
         if (it == max_steps) exit
         rz_old = rz
         call precondition(r, kd)
         rz = dot_product(r, kd)
         d = kd + (rz/rz_old)*d
      end do
      end associate
   contains
      !> z = the V-cycle applied to r on the grid being solved
      subroutine precondition(r, z)
         real(wp), contiguous, intent(in) :: r(:)
         real(wp), contiguous, intent(inout) :: z(:)
         h%level(h%top)%rhs = r
         h%vcycles = h%vcycles + 1
         call vcycle(h, h%top)
         z = h%level(h%top)%x
      end subroutine precondition
   end subroutine truncated_cg

   !> One V(1,1)-cycle on level t: x ~ A_t^-1 rhs, with A the truncated I K I on the grid
   !> being solved (h%top; x stays 0 on the contact set) and the penalised Galerkin
   !> operators below; the coarsest grid is solved exactly.
   recursive subroutine vcycle(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      if (t == h%coarsest) then
         h%level(t)%x = h%level(t)%rhs
         call cholesky_solve(h%dense, h%level(t)%x)
         return
      end if
      associate (lv => h%level(t))
      lv%x = lv%jacobi*lv%rhs
      call level_residual(h, t)
      call restrict(lv%residual, h%level(t + 1)%rhs)
      call vcycle(h, t + 1)
      if (t == h%top) then
         call prolong_add(h%level(t + 1)%x, lv%x, h%free(1:lv%n))
      else
         call prolong_add(h%level(t + 1)%x, lv%x)
      end if
      call level_residual(h, t)
      lv%x = lv%x + lv%jacobi*lv%residual
      end associate
   end subroutine vcycle

   !> residual = rhs - A_t x on level t (one transform pair of that grid).
   subroutine level_residual(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      integer :: i, m
      associate (lv => h%level(t))
      m = lv%n
      lv%fft%real_buffer = lv%x
      call transform(h, t)
      if (t == h%top) then
         lv%residual = lv%rhs - h%free(1:m)*lv%fft%real_buffer
      else
         associate (x => lv%x, dg => lv%penalty_diagonal, off => lv%penalty_off)
         lv%residual(1) = lv%rhs(1) - lv%fft%real_buffer(1) - dg(1)*x(1) - off(1)*x(2) - off(m)*x(m)
         do i = 2, m - 1
            lv%residual(i) = lv%rhs(i) - lv%fft%real_buffer(i) - dg(i)*x(i) - off(i)*x(i + 1) - off(i - 1)*x(i - 1)
         end do
         lv%residual(m) = lv%rhs(m) - lv%fft%real_buffer(m) - dg(m)*x(m) - off(m)*x(1) - off(m - 1)*x(m - 1)
         end associate
      end if
      end associate
   end subroutine level_residual

   !> y = K x on the grid being solved (one transform pair).
   subroutine apply_stiffness(h, x, y)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: x(:)
      real(wp), contiguous, intent(out) :: y(:)
      h%level(h%top)%fft%real_buffer = x
      call transform(h, h%top)
      y = h%level(h%top)%fft%real_buffer
   end subroutine apply_stiffness

   !> The buffer of level t times its circulant, counted in pairs of the finest grid.
   subroutine transform(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      integer :: k
      associate (lv => h%level(t))
      call lv%fft%forward_unscaled()
      do k = 1, size(lv%symbol)
         lv%fft%spectrum(k) = lv%fft%spectrum(k)*lv%multiplier(k)
      end do
      call lv%fft%backward()
      h%pairs = h%pairs + real(lv%n, wp)/h%n_fine
      end associate
   end subroutine transform

   !> Coarse = P^T fine (P: linear interpolation, periodic).
   pure subroutine restrict(fine, coarse)
      real(wp), contiguous, intent(in) :: fine(:)
      real(wp), contiguous, intent(out) :: coarse(:)
      integer :: i, m
      m = size(coarse)
      coarse(1) = fine(1) + 0.5_wp*(fine(2) + fine(2*m))
      do i = 2, m
         coarse(i) = fine(2*i - 1) + 0.5_wp*(fine(2*i) + fine(2*i - 2))
      end do
   end subroutine restrict

   !> fine <- fine + P coarse (linear interpolation, periodic), masked by `free` if given.
   pure subroutine prolong_add(coarse, fine, free)
      real(wp), contiguous, intent(in) :: coarse(:)
      real(wp), contiguous, intent(inout) :: fine(:)
      real(wp), contiguous, intent(in), optional :: free(:)
      integer :: i, m
      m = size(coarse)
      if (present(free)) then
         do i = 1, m
            fine(2*i - 1) = fine(2*i - 1) + free(2*i - 1)*coarse(i)
            fine(2*i) = fine(2*i) + free(2*i)*0.5_wp*(coarse(i) + coarse(mod(i, m) + 1))
         end do
      else
         do i = 1, m
            fine(2*i - 1) = fine(2*i - 1) + coarse(i)
            fine(2*i) = fine(2*i) + 0.5_wp*(coarse(i) + coarse(mod(i, m) + 1))
         end do
      end if
   end subroutine prolong_add

   !> The grids n, n/2, ... while the next has at least coarsest_points points, with their
   !> plans and work arrays (allocated once, for all the nested grids).
   subroutine build_hierarchy(h, n, error)
      type(hierarchy), intent(out) :: h
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: t, m, levels
      levels = 1 + halvings(n, coarsest_points)
      m = n/2**(levels - 1)
      h%n_fine = n
      h%coarsest = levels - 1
      allocate (h%level(0:h%coarsest), h%free(n), h%dense(m, m), h%coarse_column(m))
      h%free = 1.0_wp
      do t = 0, h%coarsest
         m = n/2**t
         associate (lv => h%level(t))
         lv%n = m
         lv%inv_n = 1.0_wp/m
         call lv%fft%init(m, 1, 1, error)
         if (allocated(error)) return
         allocate (lv%symbol(m/2 + 1), lv%multiplier(m/2 + 1), lv%penalty_diagonal(m), lv%penalty_off(m), lv%jacobi(m), lv%rhs(m), &
            & lv%x(m), lv%residual(m))
         lv%penalty_diagonal = 0.0_wp
         lv%penalty_off = 0.0_wp
         end associate
      end do
   end subroutine build_hierarchy

   !> Make grid `top` the one being solved, with the stiffness symbol K(0..m/2) on it: the
   !> Galerkin circulants P^T C P below it (their symbols in closed form: a coarse mode k
   !> gathers the fine modes k and m_c - k with the weights 2 alpha^2 and 2 beta^2,
   !> alpha, beta = (1 +- cos(pi k/m_c))/2), their diagonals, and the real-space column of
   !> the coarsest one.
   subroutine set_grid(h, top, symbol)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: top
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), parameter :: pi = acos(-1.0_wp)
      real(wp) :: alpha, beta
      integer :: t, k, mc
      h%top = top
      h%level(top)%symbol = symbol
      do t = top + 1, h%coarsest
         mc = h%level(t)%n
         do k = 0, mc/2
            alpha = 0.5_wp*(1.0_wp + cos(pi*k/mc))
            beta = 0.5_wp*(1.0_wp - cos(pi*k/mc))
            h%level(t)%symbol(k + 1) = 2*alpha**2*h%level(t - 1)%symbol(k + 1) + 2*beta**2*h%level(t - 1)%symbol(mc - k + 1)
         end do
      end do
      do t = top, h%coarsest
         associate (lv => h%level(t))
         ! (1/n) sum over the whole spectrum: the Nyquist mode of an even grid counts once
         lv%circulant_diagonal = (lv%symbol(1) + 2*sum(lv%symbol(2:)) &
            & - merge(lv%symbol(size(lv%symbol)), 0.0_wp, mod(lv%n, 2) == 0))*lv%inv_n
         lv%multiplier = lv%symbol*lv%inv_n
         end associate
      end do
      h%level(top)%jacobi = omega/h%level(top)%circulant_diagonal
      associate (lv => h%level(h%coarsest))
      lv%fft%spectrum = cmplx(lv%multiplier, 0.0_wp, kind=wp)
      call lv%fft%backward()
      h%coarse_column = lv%fft%real_buffer
      end associate
   end subroutine set_grid

   !> The coarse operators for the contact set of h%free: the Galerkin products of the
   !> penalty d D_A (tridiagonal on every coarser grid, by the recursion below), the Jacobi
   !> weights, and the Cholesky factor of the coarsest operator.
   subroutine set_contact(h)
      type(hierarchy), intent(inout) :: h
      integer :: t, i, m, info, attempt
      real(wp) :: shift
      do t = h%top + 1, h%coarsest
         m = h%level(t)%n
         associate (dg => h%level(t - 1)%penalty_diagonal, off => h%level(t - 1)%penalty_off, &
            & cdg => h%level(t)%penalty_diagonal, coff => h%level(t)%penalty_off)
         if (t == h%top + 1) then
            dg = (1.0_wp - h%free(1:2*m))*penalty*h%level(h%top)%circulant_diagonal
            off = 0.0_wp
         end if
         ! energy sum dg f^2 + 2 off f_i f_i+1 with f = P c, f(2i-1) = c(i),
         ! f(2i) = (c(i) + c(i+1))/2
         cdg(1) = dg(1) + 0.25_wp*(dg(2) + dg(2*m)) + off(1) + off(2*m)
         do i = 2, m
            cdg(i) = dg(2*i - 1) + 0.25_wp*(dg(2*i) + dg(2*i - 2)) + off(2*i - 1) + off(2*i - 2)
         end do
         do i = 1, m
            coff(i) = 0.25_wp*dg(2*i) + 0.5_wp*(off(2*i - 1) + off(2*i))
         end do
         h%level(t)%jacobi = omega/(h%level(t)%circulant_diagonal + cdg)
         end associate
      end do
      ! the coarsest operator, dense: circulant plus penalty (on the grid being solved, when
      ! it is the coarsest, I K I with the contact points' rows and columns the identity)
      shift = 0.0_wp
      do attempt = 1, 10
         call fill_dense(h, shift)
         call cholesky_factor(h%dense, info)
         if (info == 0) exit
         ! numerically singular (a rounding-level null space): shift the diagonal slightly;
         ! the V-cycle only preconditions, and the Newton direction only needs descent
         shift = max(10*shift, 1.0e-12_wp*h%level(h%coarsest)%circulant_diagonal)
      end do
   end subroutine set_contact

   !> The dense matrix of the coarsest grid's operator (see set_contact), its diagonal
   !> shifted by `shift`.
   pure subroutine fill_dense(h, shift)
      type(hierarchy), intent(inout) :: h
      real(wp), intent(in) :: shift
      integer :: i, r, m, next
      associate (lv => h%level(h%coarsest), a => h%dense)
      m = lv%n
      do i = 1, m
         do r = 1, m
            a(r, i) = h%coarse_column(modulo(r - i, m) + 1)
         end do
      end do
      if (h%top == h%coarsest) then
         do i = 1, m
            if (h%free(i) == 0.0_wp) then
               a(:, i) = 0.0_wp
               a(i, :) = 0.0_wp
               a(i, i) = 1.0_wp
            end if
         end do
      else
         do i = 1, m
            next = mod(i, m) + 1
            a(i, i) = a(i, i) + lv%penalty_diagonal(i)
            a(next, i) = a(next, i) + lv%penalty_off(i)
            a(i, next) = a(i, next) + lv%penalty_off(i)
         end do
      end if
      do i = 1, m
         a(i, i) = a(i, i) + shift
      end do
      end associate
   end subroutine fill_dense

   !> The lower Cholesky factor L of the symmetric positive definite a (its lower triangle),
   !> in place; info = the column where a pivot was not positive (0: factorised). (Written
   !> out rather than LAPACK's dpotrf: for the few hundred points of the coarsest grid a
   !> threaded BLAS spent more time waking and parking its threads than factorising.)
   pure subroutine cholesky_factor(a, info)
      real(wp), contiguous, intent(inout) :: a(:, :)
      integer, intent(out) :: info
      integer :: j, k
      info = 0
      do j = 1, size(a, 2)
         do k = 1, j - 1
            a(j:, j) = a(j:, j) - a(j, k)*a(j:, k)
         end do
         if (.not. a(j, j) > 0.0_wp) then
            info = j
            return
         end if
         a(j:, j) = a(j:, j)/sqrt(a(j, j))
      end do
   end subroutine cholesky_factor

   !> x <- (L L^T)^-1 x with the factor of cholesky_factor.
   pure subroutine cholesky_solve(l, x)
      real(wp), contiguous, intent(in) :: l(:, :)
      real(wp), contiguous, intent(inout) :: x(:)
      integer :: j, m
      m = size(x)
      do j = 1, m
         x(j) = x(j)/l(j, j)
         x(j + 1:) = x(j + 1:) - x(j)*l(j + 1:, j)
      end do
      do j = m, 1, -1
         x(j) = (x(j) - dot_product(l(j + 1:, j), x(j + 1:)))/l(j, j)
      end do
   end subroutine cholesky_solve

   !> uf (on grid j) = the spectral interpolation of uc (on grid j + 1).
   subroutine interpolate(h, j, uc, uf)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: j
      real(wp), contiguous, intent(in) :: uc(:)
      real(wp), contiguous, intent(out) :: uf(:)
      integer :: mc
      mc = size(uc)
      associate (coarse => h%level(j + 1)%fft, fine => h%level(j)%fft)
      coarse%real_buffer = uc
      call coarse%forward()
      fine%spectrum = (0.0_wp, 0.0_wp)
      fine%spectrum(1:mc/2 + 1) = coarse%spectrum
      ! the coarse Nyquist mode is a cosine: on the fine grid half of it is its mirror image
      if (mod(mc, 2) == 0) fine%spectrum(mc/2 + 1) = 0.5_wp*fine%spectrum(mc/2 + 1)
      call fine%backward()
      uf = fine%real_buffer
      end associate
      h%pairs = h%pairs + 0.5_wp*(3*mc)/h%n_fine
   end subroutine interpolate

   !> p_ref (p_m, or the mean pressure under displacement control), g_ref and the rounding
   !> floor of the gap for the state (u, p).
   pure function scales_of(u, p, load_control, f, g_ref, b_max, largest) result(scales)
      real(wp), contiguous, intent(in) :: u(:), p(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: f, g_ref, b_max, largest
      type(residual_scales) :: scales
      real(wp) :: p_ref
      p_ref = merge(f, sum(p)/size(p), load_control)
      scales%p_scale = 1.0_wp/max(p_ref, tiny(1.0_wp))
      scales%g_scale = 1.0_wp/g_ref
      scales%floor = rounding_floor(maxval(abs(u)), b_max, maxval(p), largest)
   end function scales_of

   !> The complementarity residual of (p, u - o): gaps within the floor count as zero, and a
   !> tension (p < 0) there counts in full.
   pure real(wp) function residual_of(u, p, o, scales) result(residual)
      real(wp), contiguous, intent(in) :: u(:), p(:), o(:)
      type(residual_scales), intent(in) :: scales
      real(wp) :: g, check
      integer :: j
      residual = 0.0_wp
      check = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:check) private(g)
      do j = 1, size(u)
         g = u(j) - o(j)
         residual = max(residual, merge(abs(min(p(j)*scales%p_scale, g*scales%g_scale)), &
            & max(-p(j)*scales%p_scale, 0.0_wp), g > scales%floor))
         check = check + g + p(j)
      end do
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
   end function residual_of

   !> The finishing phase's check of (u + c, p + kc): its residual, and whether a point
   !> left the feasible set (a gap below zero off the contact set, a tension on it).
   pure subroutine check_finish(u, o, p, c, kc, free, scales, residual, violated)
      real(wp), contiguous, intent(in) :: u(:), o(:), p(:), c(:), kc(:), free(:)
      type(residual_scales), intent(in) :: scales
      real(wp), intent(out) :: residual
      logical, intent(out) :: violated
      real(wp) :: g, pt, bad, check
      integer :: j
      residual = 0.0_wp
      bad = 0.0_wp
      check = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:bad, check) private(g, pt)
      do j = 1, size(u)
         g = u(j) + c(j) - o(j)
         pt = p(j) + kc(j)
         bad = bad + merge(1.0_wp, 0.0_wp, (free(j) > 0.0_wp .and. g < 0.0_wp) .or. (free(j) == 0.0_wp .and. pt < 0.0_wp))
         residual = max(residual, merge(abs(min(pt*scales%p_scale, g*scales%g_scale)), &
            & max(-pt*scales%p_scale, 0.0_wp), g > scales%floor))
         check = check + g + pt
      end do
      violated = bad > 0.0_wp
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
   end subroutine check_finish

   !> The fields the other solvers return, from the displacement form's (u, p = K u + f):
   !> the pressure kept where the gap is the smaller term of the residual (p/p_ref >=
   !> gap/g_ref, the points in contact), 0 elsewhere (there |p| <= tol p_ref already),
   !> scaled to the load (load control); w = M p; s the mean of w - b over the contact set
   !> (load control); gap = w - b - s; and the residual of these fields.
   subroutine returned_fields(op, u, o, b, load_control, mean_pressure, g_ref, p, w, gap, s, residual)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: u(:), o(:), b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      real(wp), intent(inout) :: s
      real(wp), intent(out) :: residual
      real(wp) :: p_ref
      integer :: contact
      p_ref = merge(mean_pressure, sum(p)/size(p), load_control)
      where (p > 0.0_wp .and. p*g_ref >= (u - o)*p_ref)
         gap = p
      elsewhere
         gap = 0.0_wp
      end where
      p = gap
      if (load_control) call normalise(p, mean_pressure)
      call op%apply_metric(p, w)
      contact = count(p > 0.0_wp)
      if (load_control .and. contact > 0) s = sum(w - b, mask=p > 0.0_wp)/contact
      gap = w - b - s
      p_ref = merge(mean_pressure, sum(p)/size(p), load_control)
      residual = complementarity_residual(p, gap, p_ref, g_ref, &
         & rounding_floor(maxval(abs(w)), maxval(abs(b)), maxval(p), op%largest))
   end subroutine returned_fields
end module lc_contact_solver_multigrid
