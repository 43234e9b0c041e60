!> Constrained conjugate gradients (Polonsky & Keer, Wear 231 (1999) 206) for the
!> symmetric contact problem with the operator's metric M:
!>    find p >= 0, gap = M p - b - s >= 0, p gap = 0,
!> under load control (mean(p) = p_m given, the constant s is the Lagrange multiplier)
!> or displacement control (s given). b is the target (the rigid profile, possibly
!> shifted by the outer iteration of a coupled problem).
!>
!> Stopping rule: the dimensionless complementarity residual
!>    res = max_j | min(p_j/p_ref, gap_j/g_ref) |
!> (zero exactly at the solution) falls to tol; p_ref = p_m (load control) or the
!> current mean pressure, g_ref is given by the caller (the profile's peak-to-valley).
!>
!> The passes over the grid run on the solve's threads (lc_base_threads); their sums add
!> blocks of a fixed size in order, so that the iterates do not depend on the thread count.
module lc_contact_solver_cg
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_contact_progress, only: progress_log
   use lc_base_errors, only: error_type
   use lc_fft_plans, only: row_work
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   use lc_base_threads, only: parallel_points, reduction_blocks, block_range, copy_field, fill_field, largest_magnitude
   use lc_base_pages, only: advise_huge_pages
   use lc_contact_residual, only: complementarity_residual, rounding_floor, normalise
   use lc_base_parallel, only: global_sum, global_max, sum_over_ranks, max_over_ranks
   implicit none (type, external)
   private
   !> The solve's sums run over the job's ranks (an operator on a slab of a distributed
   !> surface: lc_base_parallel); set by constrained_cg for its passes.
   logical :: across_ranks = .false.
   public :: constrained_cg, cg_outcome, cg_solver

   !> Iterations without the residual halving after which the preconditioner is dropped.
   integer, parameter :: stall_window = 100
   !> Iterations after which w = M p is recomputed even if it could be updated in place
   !> (bounds the drift of the update d <- d - tau M t, a few ulps per iteration).
   integer, parameter :: refresh_interval = 50
   !> Most points whose pressure changed other than along t (clipped or let in) that are
   !> added to w column by column rather than by recomputing w = M p: one column costs one
   !> pass over the grid, a transform pair (log n passes, at least) several
   integer, parameter :: column_updates = 8

   !> What one constrained CG solve did.
   type :: cg_outcome
      logical :: converged = .false.
      logical :: preconditioned = .false.   !< still preconditioned at the end (not stalled)
      integer :: iterations = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type cg_outcome

   !> Sums over the grid that the state evaluation needs: contact points, sums of the raw
   !> gap d = w - b and of b over the contact set, max |w|, max p, sum p.
   type :: grid_sums
      real(wp) :: contact = 0.0_wp
      real(wp) :: d_contact = 0.0_wp
      real(wp) :: b_contact = 0.0_wp
      real(wp) :: w_max = 0.0_wp
      real(wp) :: p_max = 0.0_wp
      real(wp) :: p_sum = 0.0_wp
   end type grid_sums


   !> An iteration's direction pass (new_direction_range) and update pass (update_range)
   !> fused into the row stages of the product r = M t on a surface whose transforms fuse
   !> products (the operator's metric_with_work): each block's t goes from the pass into
   !> the transform's rows in the cache, and its r from them into the update, so that
   !> neither crosses the memory as a field. The update keeps r only at the points it
   !> changed (column updates), block by block.
   type, extends(row_work) :: direction_and_update
      integer :: nx = 0
      real(wp), pointer, contiguous :: p(:) => null(), d(:) => null(), b(:) => null(), t(:) => null(), z(:) => null()
      real(wp) :: s = 0.0_wp, z_mean = 0.0_wp, beta = 0.0_wp, t_shift = 0.0_wp
      logical :: preconditioned = .false., reenter = .false.
      !> each block's sums: the direction's (sum g t, sum t), the update's
      real(wp), allocatable :: gt_parts(:), t_parts(:), lefts(:)
      type(grid_sums), allocatable :: parts(:)
      integer, allocatable :: changed(:)
      logical, allocatable :: entries(:)
      !> each block's first column_updates + 1 points changed and their change of p
      integer, allocatable :: points(:, :)
      real(wp), allocatable :: changes(:, :)
      !> after the product: sum g t, sum t, sum t M t and the step (taken where it is > 0)
      real(wp) :: gt_sum = 0.0_wp, t_sum = 0.0_wp, energy = 0.0_wp, tau = 0.0_wp
      logical :: step = .false.
   contains
      procedure :: before => direction_rows
      procedure :: between => step_length
      procedure :: after => update_rows
   end type direction_and_update

   !> Method 'cg': the constrained CG on the metric M (a symmetric operator: M = G_eff).
   type, extends(contact_solver) :: cg_solver
   contains
      procedure :: solve => solve_by_cg
      procedure :: name => cg_name
   end type cg_solver

contains

   !> Solve the symmetric problem with metric M. On entry p is the starting guess
   !> (any array; it is made feasible), on exit the solution; w = M p, gap and s as above.
   !> history(1:outcome%iterations) receives the residual of each iteration when present.
   subroutine constrained_cg(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, precondition, p, w, &
         & gap, outcome, history, progress)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in), target :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: the multiplier
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      !> precondition the residual with the stiffness 1/M on the contact set
      logical, intent(in) :: precondition
      real(wp), contiguous, intent(inout), target :: p(:)
      real(wp), contiguous, intent(out) :: w(:)
      real(wp), contiguous, intent(out), target :: gap(:)
      type(cg_outcome), intent(out) :: outcome
      real(wp), intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      real(wp), allocatable, target :: t(:)
      !> the operator's FFT buffer: transform input and output, written and read in place
      real(wp), pointer, contiguous :: buffer(:)
      type(grid_sums) :: sums
      type(direction_and_update) :: fused
      type(error_type), allocatable :: error
      real(wp) :: gnorm, gnorm_old, tau, best, beta, b_max, m_max, load_scale, p_ref, g_floor
      real(wp) :: gt_sum, gz_sum, z_mean, t_sum, t_left, t_shift, denominator
      integer :: it, n, n_contact, last_progress, since_fresh, n_changed, block, first, last
      logical :: restart, preconditioned, stale, entered, safeguarded, fuses

      ! The iteration works on the raw gap d = w - b (kept in `gap`) instead of w: the
      ! update moves it with w (d <- d - tau M t), and the gap on the contact set is d - s.
      ! An iteration is then three or four passes over the grid (state, preconditioner's
      ! mean, direction, update) around the transforms; each pass costs a sizeable part of a
      ! transform (at n = 65536 they are compute-bound, not memory-bound:
      ! docs/decisions/000-line-solver-measurements.md), so every pass and every reduction
      ! saved shows.
      across_ranks = op%distributed
      n = op%grid%points()
      associate (d => gap)
      allocate (t(size(p)))
      call advise_huge_pages(t)
      call op%prepare_cg()
      buffer => op%buffer()
      ! (the passes fused into the product's rows where the plan fuses products; where FFTW
      ! cannot plan the blocks of rows, the passes apart)
      fuses = op%fft%fuses_products()
      if (fuses) call op%fft%plan_passes(error)
      fuses = fuses .and. .not. allocated(error)
      if (fuses) call prepare_fused(fused, op, p, d, b, t, buffer)
      call fill_field(t, 0.0_wp)
      t_sum = 0.0_wp
      t_left = 0.0_wp
      gnorm_old = 1.0_wp
      restart = .true.
      p = max(p, 0.0_wp)
      if (load_control) call normalise(p, mean_pressure, across_ranks)
      preconditioned = precondition
      ! Where the metric falls with |q| (half-space, compressible layers) its masked Fourier
      ! inverse preconditions well at every scale; on broadband roughness points enter at
      ! most iterations, and restarting the conjugacy at each entry would reduce CG to
      ! steepest descent; on a few hundred points the restarts are cheaper
      ! (docs/decisions/005-broadband-iterations.md, 'The constrained CG: conjugacy kept when
      ! points enter'). Elsewhere (the metric of
      ! a coupled operator in the Anderson iteration, thin incompressible layers whose
      ! compliance rises with |q|) the inverse is far off at the edges of the contact set:
      ! there the iteration is safeguarded: the conjugacy restarts when points are let in,
      ! a point clipped may enter again at once, and the preconditioner is dropped when the
      ! iteration stalls.
      safeguarded = .not. op%metric_falls
      best = huge(1.0_wp)
      last_progress = 0
      b_max = largest_magnitude(b)
      if (across_ranks) b_max = global_max(b_max)
      m_max = op%largest

      stale = .true.
      since_fresh = 0
      load_scale = 1.0_wp
      do it = 1, max_iter + 1
         ! w = M p is recomputed only when p changed other than along t (more than a few
         ! points clipped or let in), every refresh_interval iterations, and to confirm
         ! convergence or return at max_iter (so that the fields returned belong together);
         ! otherwise d was updated in place (d <- d - tau M t), which saves one FFT pair
         ! per iteration.
         do
            if (stale .or. since_fresh >= refresh_interval) then
               ! w = M p in the transform's buffer, read there by the state's pass (w itself
               ! is written once, at the end, from d)
               call copy_field(p, buffer)
               call op%metric_in_buffer()
               outcome%fft_pairs = outcome%fft_pairs + 1
               since_fresh = 0
               stale = .false.
               call fresh_state(p, buffer, b, load_scale, d, sums)
               load_scale = 1.0_wp
            end if
            ! the state is evaluated after scaling p by load_scale, and d so that d + b
            ! scales alike (in the same pass); the sums are those of the unscaled state
            call scale_sums(sums, load_scale)
            n_contact = nint(sums%contact)
            if (load_control) s = sums%d_contact/max(n_contact, 1)
            p_ref = merge(mean_pressure, sums%p_sum/n, load_control)
            g_floor = rounding_floor(sums%w_max, b_max, sums%p_max, m_max)
            call evaluate_state(p, d, b, load_scale, s, 1.0_wp/max(p_ref, tiny(1.0_wp)), 1.0_wp/g_ref, g_floor, &
               & gnorm, outcome%residual, buffer)
            load_scale = 1.0_wp
            if (since_fresh == 0 .or. .not. (outcome%residual <= tol .or. it > max_iter)) exit
            stale = .true.
         end do
         outcome%converged = outcome%residual <= tol
         outcome%preconditioned = preconditioned
         outcome%iterations = min(it, max_iter)
         if (present(history)) then
            ! (the evaluation after the last iteration replaces that iteration's residual)
            if (size(history) > 0) history(min(outcome%iterations, size(history))) = outcome%residual
         end if
         if (present(progress)) call progress%tick(it, outcome%residual, sums%contact/n)
         if (outcome%converged .or. it > max_iter) exit
         ! The Fourier preconditioner amplifies short waves; where the compliance falls
         ! steeply with k (a glassy viscoelastic layer) its directions make the contact set
         ! oscillate. If the residual has not halved in `stall_window` iterations, continue
         ! with plain Polonsky-Keer steps, which always make progress.
         if (outcome%residual < 0.5_wp*best) then
            best = outcome%residual
            last_progress = it
         else if (safeguarded .and. preconditioned .and. it - last_progress > stall_window) then
            preconditioned = .false.
            restart = .true.
            last_progress = it
         end if

         if (n_contact == 0) then
            ! Displacement control with nothing in contact yet: load the overlapping points
            ! (the diagonal of M is the natural scale of a first step).
            call let_in_overlaps(p, d, s, 1.0_wp/op%diagonal, n_changed)
            restart = .true.
            stale = .true.
            cycle
         end if

         ! Search direction t: the (preconditioned) residual on the contact set, conjugated.
         ! Under load control t sums to zero on the contact set (the load stays put, and
         ! the step needs only sum t M t, which the transform gives by Parseval): the old
         ! direction is shifted by its mean over the current set, known from the update
         ! (the points that left the set took theirs with them).
         t_shift = 0.0_wp
         if (load_control .and. .not. restart) t_shift = (t_sum - t_left)/n_contact
         if (preconditioned) then
            ! (evaluate_state left the gap on the contact set in the buffer)
            call op%inverse_metric_in_buffer()
            outcome%fft_pairs = outcome%fft_pairs + 1
            call preconditioned_products(p, d, s, buffer, gz_sum, z_mean)
            if (.not. load_control) z_mean = 0.0_wp
            ! sum g (z - <z>) over the set is sum g z: g sums to zero there (s is its mean)
            gnorm = gz_sum
         else
            z_mean = 0.0_wp
         end if
         beta = merge(0.0_wp, gnorm/gnorm_old, restart)
         gnorm_old = gnorm
         if (fuses) then
            ! the direction, r = M t and, where sum t M t > 0, the update in one product
            fused%s = s
            fused%z_mean = z_mean
            fused%beta = beta
            fused%t_shift = t_shift
            fused%preconditioned = preconditioned
            fused%reenter = safeguarded
            fused%parts = sums
            call op%metric_with_work(fused, error)   ! (planned above: no error)
            gt_sum = fused%gt_sum
            t_sum = fused%t_sum
            denominator = fused%energy
         else
            call new_direction(p, d, s, preconditioned, z_mean, beta, t_shift, t, buffer, gt_sum, t_sum)
            call op%metric_in_buffer(denominator)   ! buffer <- r = M t; denominator = sum t M t
         end if
         outcome%fft_pairs = outcome%fft_pairs + 1
         if (.not. denominator > 0.0_wp) then
            ! t is (numerically) in the null space of the projected operator (e.g. a single
            ! point in contact under load control: its gap is s exactly): let the
            ! overlapping points in, as for an empty contact set, and start afresh
            call let_in_overlaps(p, d, s, 1.0_wp/op%diagonal, n_changed)
            if (n_changed > 0) then
               if (load_control) call normalise(p, mean_pressure, across_ranks)
               stale = .true.
            end if
            restart = .true.
            cycle
         end if
         tau = gt_sum/denominator
         ! update, clip at zero, let overlapping points in; d follows p along t, and the
         ! points clipped or let in are added column by column (M is circulant) below
         if (fuses) then
            call combine_update(fused%parts, fused%lefts, fused%changed, fused%entries, sums, t_left, n_changed, entered)
         else
            call update(p, d, b, s, tau, t, buffer, safeguarded, sums, t_left, n_changed, entered)
         end if
         restart = entered .and. safeguarded
         if (n_changed > column_updates .or. (n_changed > 0 .and. op%distributed)) then
            ! (a distributed operator has no real-space column: the state is made afresh)
            stale = .true.
         else if (n_changed > 0 .and. fuses) then
            call op%add_metric_columns_at(pack(fused%points, fused%points > 0), pack(fused%changes, fused%points > 0), &
               & p, d, sums%d_contact)
         else if (n_changed > 0) then
            call op%add_metric_columns(buffer, p, d, sums%d_contact)
         end if
         since_fresh = since_fresh + 1
         ! load control: p is scaled to the load (and d alike, M being linear) before the
         ! next evaluation (a point clipped or let in changed the load)
         if (load_control) then
            if (sums%p_sum > 0.0_wp) then
               load_scale = mean_pressure*n/sums%p_sum
               ! within a few ulps of 1 it would only rescale rounding noise
               if (abs(load_scale - 1.0_wp) <= 8*epsilon(1.0_wp)) load_scale = 1.0_wp
            else
               call normalise(p, mean_pressure, across_ranks)
               stale = .true.
            end if
         end if
      end do
      ! the fields returned (w = M p was computed afresh for the last evaluation)
      ! (by blocks on the solve's threads: the first touch of w too)
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, reduction_blocks(size(p))
         call block_range(block, size(p), first, last)
         call final_fields(gap(first:last), b(first:last), s, w(first:last), gap(first:last))
      end do
      end associate
   end subroutine constrained_cg

   !> One pass after w = M p was computed: p <- load_scale p, d = load_scale w - b, and the
   !> sums of the state (fresh_state_range on the blocks of the grid, on the solve's threads;
   !> the blocks' sums added in order: the same bits on any number of threads).
   subroutine fresh_state(p, w, b, load_scale, d, sums)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(in) :: w(:), b(:)
      real(wp), intent(in) :: load_scale
      real(wp), contiguous, intent(out) :: d(:)
      type(grid_sums), intent(out) :: sums
      type(grid_sums) :: parts(reduction_blocks(size(p)))
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(parts)
         call block_range(block, size(p), first, last)
         call fresh_state_range(p(first:last), w(first:last), b(first:last), load_scale, d(first:last), parts(block))
      end do
      sums = added(parts)
      if (across_ranks) call add_over_ranks(sums)
   end subroutine fresh_state

   !> The sums of the ranks' states (one message for the sums, one for the maxima).
   subroutine add_over_ranks(sums)
      type(grid_sums), intent(inout) :: sums
      real(wp) :: totals(4), maxima(2)
      totals = [sums%contact, sums%d_contact, sums%b_contact, sums%p_sum]
      maxima = [sums%w_max, sums%p_max]
      call sum_over_ranks(totals)
      call max_over_ranks(maxima)
      sums%contact = totals(1)
      sums%d_contact = totals(2)
      sums%b_contact = totals(3)
      sums%p_sum = totals(4)
      sums%w_max = maxima(1)
      sums%p_max = maxima(2)
   end subroutine add_over_ranks

   !> The sums of the blocks' sums, in order, and the largest of their maxima.
   pure type(grid_sums) function added(parts) result(sums)
      type(grid_sums), intent(in) :: parts(:)
      integer :: block
      sums = grid_sums()
      do block = 1, size(parts)
         sums%contact = sums%contact + parts(block)%contact
         sums%d_contact = sums%d_contact + parts(block)%d_contact
         sums%b_contact = sums%b_contact + parts(block)%b_contact
         sums%p_sum = sums%p_sum + parts(block)%p_sum
         sums%w_max = max(sums%w_max, parts(block)%w_max)
         sums%p_max = max(sums%p_max, parts(block)%p_max)
      end do
   end function added

   !> One pass after w = M p was computed: p <- load_scale p, d = load_scale w - b, and the
   !> sums of the state.
   subroutine fresh_state_range(p, w, b, load_scale, d, sums)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(in) :: w(:), b(:)
      real(wp), intent(in) :: load_scale
      real(wp), contiguous, intent(out) :: d(:)
      type(grid_sums), intent(out) :: sums
      real(wp) :: contact, d_contact, b_contact, w_max, p_max, p_sum, inside, pj, wj
      integer :: j
      contact = 0.0_wp
      d_contact = 0.0_wp
      b_contact = 0.0_wp
      w_max = 0.0_wp
      p_max = 0.0_wp
      p_sum = 0.0_wp
      !$omp simd reduction(+:contact, d_contact, b_contact, p_sum) reduction(max:w_max, p_max) private(inside, pj, wj)
      do j = 1, size(p)
         pj = p(j)*load_scale
         wj = w(j)*load_scale
         p(j) = pj
         d(j) = wj - b(j)
         inside = merge(1.0_wp, 0.0_wp, pj > 0.0_wp)
         contact = contact + inside
         d_contact = d_contact + d(j)*inside
         b_contact = b_contact + b(j)*inside
         w_max = max(w_max, abs(wj))
         p_max = max(p_max, pj)
         p_sum = p_sum + pj
      end do
      sums = grid_sums(contact, d_contact, b_contact, w_max, p_max, p_sum)
   end subroutine fresh_state_range

   !> The sums of the state after p <- load_scale p, d <- load_scale d + (load_scale - 1) b.
   pure subroutine scale_sums(sums, load_scale)
      type(grid_sums), intent(inout) :: sums
      real(wp), intent(in) :: load_scale
      if (load_scale == 1.0_wp) return
      sums%d_contact = load_scale*sums%d_contact + (load_scale - 1.0_wp)*sums%b_contact
      sums%w_max = load_scale*sums%w_max
      sums%p_max = load_scale*sums%p_max
      sums%p_sum = load_scale*sums%p_sum
   end subroutine scale_sums

   !> evaluate_state_range on the blocks of the grid (see fresh_state).
   subroutine evaluate_state(p, d, b, load_scale, s, p_scale, g_scale, g_floor, gnorm, residual, masked_gap)
      real(wp), contiguous, intent(inout) :: p(:), d(:)
      real(wp), contiguous, intent(in) :: b(:)
      real(wp), intent(in) :: load_scale, s, p_scale, g_scale, g_floor
      real(wp), intent(out) :: gnorm, residual
      real(wp), contiguous, intent(inout) :: masked_gap(:)
      real(wp) :: gnorms(reduction_blocks(size(p))), residuals(reduction_blocks(size(p)))
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(gnorms)
         call block_range(block, size(p), first, last)
         call evaluate_state_range(p(first:last), d(first:last), b(first:last), load_scale, s, p_scale, g_scale, &
            & g_floor, gnorms(block), residuals(block), masked_gap(first:last))
      end do
      gnorm = sum(gnorms)
      residual = maxval(residuals)
      if (across_ranks) then
         gnorm = global_sum(gnorm)
         residual = global_max(residual)
      end if
   end subroutine evaluate_state

   !> One pass: scale p by load_scale and d so that d + b scales alike, then the
   !> complementarity residual and the squared norm of the gap g = d - s on the contact set;
   !> g on the contact set (0 elsewhere) goes into `masked_gap`, the preconditioner's input.
   !> (The stores are unconditional: a store under a condition keeps the loop from being
   !> vectorised, which costs more than the stores.)
   subroutine evaluate_state_range(p, d, b, load_scale, s, p_scale, g_scale, g_floor, gnorm, residual, masked_gap)
      real(wp), contiguous, intent(inout) :: p(:), d(:)
      real(wp), contiguous, intent(in) :: b(:)
      real(wp), intent(in) :: load_scale, s, p_scale, g_scale, g_floor
      real(wp), intent(out) :: gnorm, residual
      real(wp), contiguous, intent(inout) :: masked_gap(:)
      real(wp) :: check, g, c, inside, pj, dj, shift
      integer :: j
      shift = load_scale - 1.0_wp
      residual = 0.0_wp
      gnorm = 0.0_wp
      check = 0.0_wp
      if (load_scale == 1.0_wp) then
         ! (p and d stay: the same pass without writing them back, two streams fewer)
         !$omp simd reduction(max:residual) reduction(+:gnorm, check) private(g, c, inside)
         do j = 1, size(p)
            g = d(j) - s
            inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
            c = abs(min(p(j)*p_scale, g*g_scale))
            residual = max(residual, merge(c, 0.0_wp, abs(g) > g_floor))
            gnorm = gnorm + g*g*inside
            masked_gap(j) = g*inside
            check = check + g + p(j)
         end do
         if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
         return
      end if
      !$omp simd reduction(max:residual) reduction(+:gnorm, check) private(g, c, inside, pj, dj)
      do j = 1, size(p)
         pj = p(j)*load_scale
         dj = d(j)*load_scale + shift*b(j)
         p(j) = pj
         d(j) = dj
         g = dj - s
         inside = merge(1.0_wp, 0.0_wp, pj > 0.0_wp)
         c = abs(min(pj*p_scale, g*g_scale))
         residual = max(residual, merge(c, 0.0_wp, abs(g) > g_floor))
         gnorm = gnorm + g*g*inside
         masked_gap(j) = g*inside
         check = check + g + pj
      end do
      ! a NaN or Inf gap or pressure (which max() may skip) makes the sum non-finite:
      ! count it as infinitely wrong
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
   end subroutine evaluate_state_range

   !> One pass over the preconditioned residual z (the buffer after the inverse metric):
   !> gz_sum = sum g z and z_mean = <z> over the contact set (by blocks: see fresh_state).
   subroutine preconditioned_products(p, d, s, z, gz_sum, z_mean)
      real(wp), contiguous, intent(in) :: p(:), d(:), z(:)
      real(wp), intent(in) :: s
      real(wp), intent(out) :: gz_sum, z_mean
      real(wp) :: parts(3, reduction_blocks(size(p))), totals(3)
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(parts, 2)
         call block_range(block, size(p), first, last)
         call preconditioned_products_range(p(first:last), d(first:last), s, z(first:last), parts(1, block), &
            & parts(2, block), parts(3, block))
      end do
      totals = [sum(parts(1, :)), sum(parts(2, :)), sum(parts(3, :))]
      if (across_ranks) call sum_over_ranks(totals)
      gz_sum = totals(1)
      z_mean = totals(2)/max(totals(3), 1.0_wp)
   end subroutine preconditioned_products

   !> One pass over a block of the preconditioned residual z: gz_sum = sum g z, z_sum = sum z
   !> over the contact set and contact its points.
   subroutine preconditioned_products_range(p, d, s, z, gz_sum, z_sum, contact)
      real(wp), contiguous, intent(in) :: p(:), d(:), z(:)
      real(wp), intent(in) :: s
      real(wp), intent(out) :: gz_sum, z_sum, contact
      real(wp) :: inside
      integer :: j
      gz_sum = 0.0_wp
      z_sum = 0.0_wp
      contact = 0.0_wp
      !$omp simd reduction(+:gz_sum, z_sum, contact) private(inside)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         gz_sum = gz_sum + (d(j) - s)*z(j)*inside
         z_sum = z_sum + z(j)*inside
         contact = contact + inside
      end do
   end subroutine preconditioned_products_range

   !> new_direction_range on the blocks of the grid (see fresh_state).
   subroutine new_direction(p, d, s, preconditioned, z_mean, beta, t_shift, t, buffer, gt_sum, t_sum)
      real(wp), contiguous, intent(in) :: p(:), d(:)
      real(wp), intent(in) :: s, z_mean, beta, t_shift
      logical, intent(in) :: preconditioned
      real(wp), contiguous, intent(inout) :: t(:), buffer(:)
      real(wp), intent(out) :: gt_sum, t_sum
      real(wp) :: parts(2, reduction_blocks(size(p))), totals(2)
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(parts, 2)
         call block_range(block, size(p), first, last)
         call new_direction_range(p(first:last), d(first:last), s, preconditioned, z_mean, beta, t_shift, &
            & t(first:last), buffer(first:last), parts(1, block), parts(2, block))
      end do
      gt_sum = sum(parts(1, :))
      t_sum = sum(parts(2, :))
      if (across_ranks) then
         totals = [gt_sum, t_sum]
         call sum_over_ranks(totals)
         gt_sum = totals(1)
         t_sum = totals(2)
      end if
   end subroutine new_direction

   !> One pass: the new direction t = (e + beta (t - t_shift)) on the contact set (0
   !> elsewhere), with e = z - z_mean (preconditioned; z in the buffer) or the gap g; t is
   !> also written into the buffer (the transform's input). gt_sum = sum g t, t_sum = sum t.
   subroutine new_direction_range(p, d, s, preconditioned, z_mean, beta, t_shift, t, buffer, gt_sum, t_sum)
      real(wp), contiguous, intent(in) :: p(:), d(:)
      real(wp), intent(in) :: s, z_mean, beta, t_shift
      logical, intent(in) :: preconditioned
      real(wp), contiguous, intent(inout) :: t(:), buffer(:)
      real(wp), intent(out) :: gt_sum, t_sum
      real(wp) :: g, e, tj, inside, from_z
      integer :: j
      gt_sum = 0.0_wp
      t_sum = 0.0_wp
      ! a 0/1 weight rather than a branch, which would keep the loop from being vectorised
      ! (without the preconditioner the buffer holds the masked gap: finite)
      from_z = merge(1.0_wp, 0.0_wp, preconditioned)
      !$omp simd reduction(+:gt_sum, t_sum) private(g, e, tj, inside)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         g = d(j) - s
         e = from_z*(buffer(j) - z_mean) + (1.0_wp - from_z)*g
         tj = (e + beta*(t(j) - t_shift))*inside
         t(j) = tj
         buffer(j) = tj
         gt_sum = gt_sum + g*tj
         t_sum = t_sum + tj
      end do
   end subroutine new_direction_range

   !> update_range on the blocks of the grid (see fresh_state).
   subroutine update(p, d, b, s, tau, t, r, reenter, sums, t_left, n_changed, entered)
      real(wp), contiguous, intent(inout) :: p(:), d(:), r(:)
      real(wp), contiguous, intent(in) :: b(:), t(:)
      real(wp), intent(in) :: s, tau
      logical, intent(in) :: reenter
      type(grid_sums), intent(inout) :: sums
      real(wp), intent(out) :: t_left
      integer, intent(out) :: n_changed
      logical, intent(out) :: entered
      type(grid_sums) :: parts(reduction_blocks(size(p)))
      real(wp) :: lefts(size(parts))
      integer :: changed(size(parts))
      logical :: entries(size(parts))
      integer :: block, first, last
      parts = sums
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(parts)
         call block_range(block, size(p), first, last)
         call update_range(p(first:last), d(first:last), b(first:last), s, tau, t(first:last), r(first:last), &
            & reenter, parts(block), lefts(block), changed(block), entries(block))
      end do
      call combine_update(parts, lefts, changed, entries, sums, t_left, n_changed, entered)
   end subroutine update

   !> The state's sums after the update from its blocks' (added in order) and over the ranks.
   subroutine combine_update(parts, lefts, changed, entries, sums, t_left, n_changed, entered)
      type(grid_sums), intent(in) :: parts(:)
      real(wp), intent(in) :: lefts(:)
      integer, intent(in) :: changed(:)
      logical, intent(in) :: entries(:)
      type(grid_sums), intent(out) :: sums
      real(wp), intent(out) :: t_left
      integer, intent(out) :: n_changed
      logical, intent(out) :: entered
      real(wp) :: totals(7)
      sums = added(parts)
      t_left = sum(lefts)
      n_changed = sum(changed)
      entered = any(entries)
      if (across_ranks) then
         ! (the maxima are kept from the last full evaluation: the same on every rank)
         totals = [sums%contact, sums%d_contact, sums%b_contact, sums%p_sum, t_left, real(n_changed, wp), &
            & merge(1.0_wp, 0.0_wp, entered)]
         call sum_over_ranks(totals)
         sums%contact = totals(1)
         sums%d_contact = totals(2)
         sums%b_contact = totals(3)
         sums%p_sum = totals(4)
         t_left = totals(5)
         n_changed = nint(totals(6))
         entered = totals(7) > 0.0_wp
      end if
   end subroutine combine_update

   !> One pass: p <- p - tau t clipped at zero, overlapping points (p = 0, g < 0) let in,
   !> d <- d - tau r (r = M t, in the buffer); r then keeps the change of p that was not
   !> along t (nonzero at the points clipped or let in). Also the sums of the new state
   !> (all but the maxima, which only set the rounding floor and are kept from the last
   !> full evaluation: fewer reductions keep this loop in registers), t_left = the sum of t
   !> over the points that left the contact set, n_changed and whether points were let in
   !> (a safeguarded iteration restarts its conjugacy then). `reenter`: a point clipped by
   !> this step is let in again at once if its gap is negative (the safeguarded iteration);
   !> otherwise it stays out until the next evaluation.
   subroutine update_range(p, d, b, s, tau, t, r, reenter, sums, t_left, n_changed, entered)
      real(wp), contiguous, intent(inout) :: p(:), d(:), r(:)
      real(wp), contiguous, intent(in) :: b(:), t(:)
      real(wp), intent(in) :: s, tau
      logical, intent(in) :: reenter
      type(grid_sums), intent(inout) :: sums
      real(wp), intent(out) :: t_left
      integer, intent(out) :: n_changed
      logical, intent(out) :: entered
      real(wp) :: contact, d_contact, b_contact, p_sum, changed_count, entered_count
      real(wp) :: trial, p_new, d_new, g, c, inside, left, reenter_weight
      integer :: j
      contact = 0.0_wp
      d_contact = 0.0_wp
      b_contact = 0.0_wp
      p_sum = 0.0_wp
      changed_count = 0.0_wp
      entered_count = 0.0_wp
      t_left = 0.0_wp
      reenter_weight = merge(1.0_wp, 0.0_wp, reenter)
      !$omp simd reduction(+:contact, d_contact, b_contact, p_sum, changed_count, entered_count, t_left) &
      !$omp& private(trial, p_new, d_new, g, c, inside, left)
      do j = 1, size(p)
         ! t = 0 off the contact set, so p - tau t is p there
         trial = p(j) - tau*t(j)
         p_new = merge(trial, 0.0_wp, trial >= 0.0_wp)   ! clip (a NaN too)
         ! let in where p = 0 and g < 0 (g before the step; p after it with `reenter`, before
         ! it otherwise); max(): once the contact set is
         ! solved tau is a ratio of rounding noise and may be negative, and a negative
         ! pressure would never be clipped again
         g = d(j) - s
         c = merge(1.0_wp, 0.0_wp, g < 0.0_wp)*(reenter_weight*merge(1.0_wp, 0.0_wp, p_new <= 0.0_wp) &
            & + (1.0_wp - reenter_weight)*merge(1.0_wp, 0.0_wp, p(j) <= 0.0_wp))
         p_new = c*max(-tau*g, 0.0_wp) + (1.0_wp - c)*p_new
         entered_count = entered_count + c
         left = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)*merge(1.0_wp, 0.0_wp, p_new <= 0.0_wp)
         t_left = t_left + t(j)*left
         d_new = d(j) - tau*r(j)
         d(j) = d_new
         r(j) = p_new - trial
         changed_count = changed_count + merge(1.0_wp, 0.0_wp, p_new /= trial)
         p(j) = p_new
         inside = merge(1.0_wp, 0.0_wp, p_new > 0.0_wp)
         contact = contact + inside
         d_contact = d_contact + d_new*inside
         b_contact = b_contact + b(j)*inside
         p_sum = p_sum + p_new
      end do
      sums%contact = contact
      sums%d_contact = d_contact
      sums%b_contact = b_contact
      sums%p_sum = p_sum
      n_changed = nint(changed_count)
      entered = entered_count > 0.0_wp
   end subroutine update_range

   !> Load the overlapping points out of contact (p = 0, g = d - s < 0) with the pressure
   !> -g/M_jj of a first step; n_changed: how many.
   subroutine let_in_overlaps(p, d, s, inverse_diagonal, n_changed)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(in) :: d(:)
      real(wp), intent(in) :: s, inverse_diagonal
      integer, intent(out) :: n_changed
      real(wp) :: g
      integer :: j
      n_changed = 0
      do j = 1, size(p)
         g = d(j) - s
         if (p(j) <= 0.0_wp .and. g < 0.0_wp) then
            p(j) = -g*inverse_diagonal
            n_changed = n_changed + 1
         end if
      end do
      if (across_ranks) n_changed = global_sum(n_changed)
   end subroutine let_in_overlaps

   !> The fused passes' fields and their sums by block of rows (direction_and_update).
   subroutine prepare_fused(fused, op, p, d, b, t, z)
      type(direction_and_update), intent(out) :: fused
      type(compliance_operator), intent(in) :: op
      real(wp), contiguous, target, intent(in) :: p(:), d(:), b(:), t(:), z(:)
      integer :: blocks
      fused%nx = op%grid%nx
      fused%p => p
      fused%d => d
      fused%b => b
      fused%t => t
      fused%z => z
      blocks = op%fft%row_blocks()
      allocate (fused%gt_parts(blocks), fused%t_parts(blocks), fused%lefts(blocks), fused%parts(blocks), &
         & fused%changed(blocks), fused%entries(blocks), fused%points(column_updates + 1, blocks), &
         & fused%changes(column_updates + 1, blocks))
   end subroutine prepare_fused

   !> The direction on a block of rows (new_direction_range): the preconditioned residual z
   !> (or the masked gap) copied into the transform's rows, t written over it there and into t.
   subroutine direction_rows(self, first, rows, values, block)
      class(direction_and_update), intent(inout) :: self
      integer, intent(in) :: first, rows, block
      real(wp), contiguous, intent(inout) :: values(:)
      integer :: j0, j1
      j0 = (first - 1)*self%nx + 1
      j1 = (first - 1 + rows)*self%nx
      values = self%z(j0:j1)
      call new_direction_range(self%p(j0:j1), self%d(j0:j1), self%s, self%preconditioned, self%z_mean, self%beta, &
         & self%t_shift, self%t(j0:j1), values, self%gt_parts(block), self%t_parts(block))
   end subroutine direction_rows

   !> The direction's sums (over the ranks too) and the step tau = sum g t / sum t M t.
   subroutine step_length(self, energy)
      class(direction_and_update), intent(inout) :: self
      real(wp), intent(in) :: energy
      real(wp) :: totals(2)
      totals = [sum(self%gt_parts), sum(self%t_parts)]
      if (across_ranks) call sum_over_ranks(totals)
      self%gt_sum = totals(1)
      self%t_sum = totals(2)
      self%energy = energy
      self%step = energy > 0.0_wp
      self%tau = 0.0_wp
      if (self%step) self%tau = self%gt_sum/energy
   end subroutine step_length

   !> The update on a block of rows (update_range) with r = M t from the transform's rows,
   !> and the points whose pressure changed other than along t with their change.
   subroutine update_rows(self, first, rows, values, block)
      class(direction_and_update), intent(inout) :: self
      integer, intent(in) :: first, rows, block
      real(wp), contiguous, intent(inout) :: values(:)
      integer :: j0, j1, j, k
      self%points(:, block) = 0
      self%changed(block) = 0
      if (.not. self%step) return
      j0 = (first - 1)*self%nx + 1
      j1 = (first - 1 + rows)*self%nx
      call update_range(self%p(j0:j1), self%d(j0:j1), self%b(j0:j1), self%s, self%tau, self%t(j0:j1), values, &
         & self%reenter, self%parts(block), self%lefts(block), self%changed(block), self%entries(block))
      if (self%changed(block) == 0) return
      ! (values now holds the change of p not along t: nonzero at the changed points only)
      k = 0
      do j = 1, size(values)
         if (values(j) == 0.0_wp) cycle
         k = k + 1
         if (k > size(self%points, 1)) exit
         self%points(k, block) = j0 + j - 1
         self%changes(k, block) = values(j)
      end do
   end subroutine update_rows

   !> The fields returned from the raw gap d (= w - b): w = d + b, gap = d - s (in place).
   pure subroutine final_fields(d, b, s, w, gap)
      real(wp), contiguous, intent(in) :: d(:), b(:)
      real(wp), intent(in) :: s
      real(wp), contiguous, intent(out) :: w(:)
      real(wp), contiguous, intent(inout) :: gap(:)
      integer :: j
      do j = 1, size(d)
         w(j) = d(j) + b(j)
         gap(j) = d(j) - s
      end do
   end subroutine final_fields
   subroutine solve_by_cg(self, problem, state, budget, outcome, progress, error)
      class(cg_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(cg_outcome) :: cg
      real(wp), allocatable :: history(:)
      allocate (history(budget))
      call constrained_cg(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
         & problem%tol, budget, problem%precondition, state%p, state%w, state%gap, cg, history, progress)
      outcome = solve_outcome(converged=cg%converged, iterations=cg%iterations, outer_iterations=0, &
         & fft_pairs=cg%fft_pairs, residual=cg%residual, history=history(1:cg%iterations))
   end subroutine solve_by_cg

   pure function cg_name(self) result(name)
      class(cg_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'cg'
   end function cg_name

end module lc_contact_solver_cg
