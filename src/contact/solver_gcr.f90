!> Constrained GCR for the coupled (non-symmetric) contact problem
!>    find p >= 0, gap = G_eff p - b - s >= 0, p gap = 0,
!> under load control (mean(p) = p_m, s the multiplier) or displacement control (s given).
!>
!> GCR (Eisenstat, Elman & Schultz, SIAM J. Numer. Anal. 20 (1983) 345) is the
!> minimal-residual Krylov method that keeps the images A d_i of its directions
!> orthonormal; here A is G_eff restricted to the contact set (and, under load control,
!> projected to zero sum on it, so that every step keeps the load), right-preconditioned
!> by the Fourier inverse of G_eff masked to the set. As in Polonsky & Keer's constrained
!> CG the set changes inside the iteration: overlapping points are let in (the history is
!> kept, re-orthonormalised on the larger set without a transform, and the residual
!> projected on it once, a least-squares step that restores GCR's invariant) and negative
!> pressures are clipped (the history is dropped, or, with keep_clipped, kept with the
!> clipped points taken out of the stored directions and their images corrected). Each
!> iteration costs two transform pairs and a few sweeps over the history. Compared with the
!> outer fixed point of lc_contact_solver_anderson (symmetric inner solves with |G_eff|),
!> whose rate is set by the spread of arg G_eff (thin layers with friction, lossy
!> viscoelastic layers), the preconditioned operator here is close to the identity on a
!> large contact set whatever arg G_eff is.
!>
!> The images are stored centred on the contact set under load control: a constant added
!> to w everywhere only moves s. w is recomputed as G_eff p to confirm convergence, so the
!> fields returned belong together. Stopping rule and residual as in lc_contact_solver_cg,
!> and the passes over the grid threaded as there.
module lc_contact_solver_gcr
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_contact_residual, only: rounding_floor, normalise
   use lc_contact_progress, only: progress_log
   use lc_base_errors, only: error_type
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   use lc_base_threads, only: parallel_points, reduction_blocks, block_range, copy_field, largest_magnitude
   use lc_base_pages, only: advise_huge_pages
   use lc_base_parallel, only: global_sum, global_max, sum_over_ranks, max_over_ranks
   implicit none (type, external)
   private
   !> The solve's sums run over the job's ranks (an operator on a slab of a distributed
   !> surface: lc_base_parallel); set by constrained_gcr for its passes.
   logical :: across_ranks = .false.
   public :: constrained_gcr, gcr_outcome, gcr_solver

   !> Iterations without the residual halving after which the solve gives up (and reports
   !> non-convergence with its best iterate; under method 'auto' the Anderson outer
   !> iteration goes on from there). On a smooth surface a converging solve halves the
   !> residual every one to three iterations; on broadband roughness (the shortest
   !> wavelength a few grid points) the contact set settles over many iterations and the
   !> residual halves only every few dozen iterations on fine grids. What still stalls: glassy
   !> viscoelastic layers at low speeds, whose fine-grid contact sets settle slowly (a clip
   !> restarts the history) and erratically, and a few thin incompressible layers with
   !> strong friction on tiny grids (docs/decisions/005-broadband-iterations.md, 'The
   !> constrained GCR: a longer stall window').
   integer, parameter :: stall_window = 200
   !> Iterations after which w = G_eff p is recomputed (bounds the drift of the updates).
   integer, parameter :: refresh_interval = 50
   !> Most points clipped or let in whose change is added to w column by column.
   integer, parameter :: column_updates = 8
   interface
      subroutine dpotrf(uplo, n, a, lda, info)
         import :: wp
         character, intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(wp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf
   end interface

   !> A step that takes less than this fraction of the residual's squared norm on the set
   !> has stagnated: the history is dropped (a restart, as after a clip). Thin layers with
   !> strong friction and small contact sets stagnate so (G_eff restricted to the set is
   !> nearly skew, arg G_eff near -90 degrees at long waves, and nearly singular), with
   !> alpha^2/|r|^2 ~ 1e-16; slow steady progress on glassy viscoelastic layers takes
   !> 1e-3..1e-5 per step and must not be cut (docs/decisions/000-line-solver-measurements.md,
   !> 'Constrained GCR for coupled scenes').
   real(wp), parameter :: stagnation = 1.0e-10_wp
   !> Rows per block of the sweeps over the history.
   integer, parameter :: block_rows = 2048
   !> A new image whose norm falls below this fraction of its norm before the
   !> orthogonalisation is numerically in the span of the history: restart.
   real(wp), parameter :: breakdown = 1.0e-10_wp
   !> Least fraction of its norm on the set that a stored image keeps after centring and
   !> orthogonalisation against the older ones when the history is re-orthonormalised;
   !> below, the history is dropped: the rounding of directions and images grows like
   !> eps/pivot, 1e-10 here (docs/decisions/005-broadband-iterations.md, 'The kept history
   !> as a second stage').
   real(wp), parameter :: independence = 1.0e-6_wp
   !> keep_clipped: most points clipped at once whose removal from the stored directions is
   !> added to their images column by column (a pass over the grid per point and
   !> direction); beyond, each image is transformed afresh (docs/numerics.md, 'Constants of
   !> the solvers and their measurements').
   integer, parameter :: clipped_columns = 64
   !> keep_clipped: with the history full (memory columns), a step that takes less than this
   !> fraction of the residual's squared norm on the set restarts GCR: the sliding window
   !> of the truncated GCR stagnates on fixed contact sets at residuals near the tolerance
   !> (docs/decisions/005-broadband-iterations.md, 'The cause: a clip drops GCR's history').
   real(wp), parameter :: truncation = 1.0e-2_wp

   !> What one constrained GCR solve did.
   type :: gcr_outcome
      logical :: converged = .false.
      integer :: iterations = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type gcr_outcome


   !> Method 'gcr': the constrained GCR on G_eff. With `keep_history` ('kept') it keeps its
   !> history across clips, which costs more per set change than it saves where the set
   !> settles in a few clips but lets a broadband fine grid converge once the restarted
   !> iteration stalled.
   type, extends(contact_solver) :: gcr_solver
      logical :: keep_history = .false.
   contains
      procedure :: solve => solve_by_gcr
      procedure :: name => gcr_name
      procedure :: ends_no_worse => gcr_ends_no_worse
   end type gcr_solver

contains

   !> Solve the coupled problem. p: starting guess in (made feasible), solution out (the
   !> best iterate if not converged); w = G_eff p; gap = w - b - s.
   !> history(it) receives the residual of iteration it when present. keep_clipped (default
   !> false): keep the history across clips (the stored directions without the clipped
   !> points, their images corrected, re-orthonormalised, the residual projected on them).
   !> It costs up to ~memory^2 passes over the grid per set change, which is more than it
   !> saves where the set settles in a few clips, but it is what lets a broadband fine grid
   !> converge once the restarted iteration stalled (docs/decisions/005-broadband-iterations.md).
   subroutine constrained_gcr(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, memory, precondition, &
         & p, w, gap, outcome, history, progress, keep_clipped)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: the multiplier
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter, memory
      !> precondition the residual with the Fourier inverse of G_eff on the contact set
      logical, intent(in) :: precondition
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(gcr_outcome), intent(out) :: outcome
      real(wp), intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      logical, intent(in), optional :: keep_clipped
      real(wp), allocatable :: dirs(:, :), images(:, :), d(:), coeff(:), p_best(:)
      real(wp), pointer, contiguous :: buffer(:)
      real(wp) :: b_max, best, best_residual, norm_before, norm, alpha, step, centre, kappa, residual_norm2, p_sum
      real(wp) :: gap_product
      real(wp) :: load_scale
      integer :: it, n, columns, newest, n_contact, n_changed, since_fresh, last_progress
      logical :: stale, entered, set_changed, projected, keep, fresh
      !> p is the best iterate and p_best not yet a copy of it: the copy is taken by the next
      !> pass that changes p (the update's, as it reads p), not in a pass of its own
      logical :: best_pending
      integer :: n_clipped, n_negative

      across_ranks = op%distributed
      n = size(p)
      keep = .false.
      if (present(keep_clipped)) keep = keep_clipped
      call op%prepare_gcr()
      ! the real-space diagonal of the preconditioner, for letting points in
      kappa = merge(op%inverse_diagonal, 1.0_wp, precondition)
      allocate (dirs(n, memory), images(n, memory), d(n), coeff(memory), p_best(n))
      call advise_huge_pages(dirs)
      call advise_huge_pages(images)
      call advise_huge_pages(d)
      call advise_huge_pages(p_best)
      buffer => op%buffer()
      p = max(p, 0.0_wp)
      if (load_control) call normalise(p, mean_pressure, across_ranks)
      b_max = largest_magnitude(b)
      if (across_ranks) b_max = global_max(b_max)
      columns = 0
      newest = 0
      stale = .true.
      since_fresh = 0
      best = huge(1.0_wp)
      best_residual = huge(1.0_wp)
      last_progress = 0
      best_pending = .false.
      set_changed = .false.
      load_scale = 1.0_wp

      do it = 1, max_iter + 1
         ! as in the constrained CG: w is updated in place, recomputed every
         ! refresh_interval iterations, when many points changed, and to confirm convergence
         do
            fresh = stale .or. since_fresh >= refresh_interval
            if (fresh) then
               ! (G_eff p is left in the buffer: the evaluation's first pass scales it into w)
               call copy_field(p, buffer)
               call op%full_in_buffer()
               outcome%fft_pairs = outcome%fft_pairs + 1
               since_fresh = 0
               stale = .false.
            end if
            call evaluate(p, w, b, load_scale, load_control, mean_pressure, g_ref, b_max, op%largest, s, gap, &
               & n_contact, outcome%residual, residual_norm2, buffer, fresh)
            load_scale = 1.0_wp
            if (since_fresh == 0 .or. .not. (outcome%residual <= tol .or. it > max_iter)) exit
            stale = .true.
         end do
         outcome%converged = outcome%residual <= tol
         outcome%iterations = min(it, max_iter)
         if (present(history)) then
            if (it <= size(history)) history(it) = outcome%residual
         end if
         if (outcome%residual < best_residual) then
            best_residual = outcome%residual
            best_pending = .true.
         end if
         if (present(progress)) call progress%tick(it, outcome%residual, real(n_contact, wp)/op%grid%points())
         if (outcome%converged .or. it > max_iter) exit
         if (outcome%residual < 0.5_wp*best) then
            best = outcome%residual
            last_progress = it
         else if (it - last_progress > stall_window) then
            exit
         end if

         if (n_contact == 0) then
            ! displacement control with nothing in contact yet: load the overlapping points
            call keep_best()
            call let_in_overlaps(p, gap, 1.0_wp/op%diagonal, n_changed)
            if (n_changed == 0) exit
            columns = 0
            stale = .true.
            cycle
         end if

         projected = set_changed
         if (set_changed) then
            ! least squares in the span of the stored directions on the new set: p and w
            ! along them by coeff = (r, u_i) (r = -gap on the set, in the buffer); pressures
            ! it makes negative are clipped (and the history dropped then); state again
            set_changed = .false.
            call keep_best()
            call history_products(images(:, 1:columns), p, buffer, coeff(1:columns))
            call subtract_history(dirs(:, 1:columns), images(:, 1:columns), -coeff(1:columns), p, w)
            call clip_negative(p, d, n_negative)
            if (n_negative > 0) then
               columns = 0
               newest = 0
               if (n_negative > column_updates .or. op%distributed) then
                  call op%apply_full(p, w)
                  outcome%fft_pairs = outcome%fft_pairs + 1
                  since_fresh = 0
               else
                  call op%add_full_columns(d, w)
               end if
            end if
            if (load_control) call scale_to_load(p, mean_pressure, stale, total_pressure(p), load_scale)
            if (stale) cycle   ! (p vanished and was reset: w afresh first)
            call evaluate(p, w, b, load_scale, load_control, mean_pressure, g_ref, b_max, op%largest, s, gap, &
               & n_contact, outcome%residual, residual_norm2, buffer, .false.)
            load_scale = 1.0_wp
            if (n_contact == 0) cycle
         end if

         ! direction: the preconditioned residual on the set (evaluate left -gap there in
         ! the buffer), projected to zero sum on the set under load control
         if (precondition) then
            call op%inverse_full_in_buffer()
            outcome%fft_pairs = outcome%fft_pairs + 1
         end if
         call project_on_set(p, load_control, buffer, d)
         ! its image, orthogonalised against the stored ones on the set
         call op%full_in_buffer()
         outcome%fft_pairs = outcome%fft_pairs + 1
         coeff = 0.0_wp
         if (columns > 0) then
            call history_products(images(:, 1:columns), p, buffer, coeff(1:columns))
            call subtract_history(dirs(:, 1:columns), images(:, 1:columns), coeff(1:columns), d, buffer)
         end if
         call set_norm(p, load_control, buffer, gap, centre, norm, gap_product)
         ! (the stored images are orthonormal on the set: Pythagoras gives the norm before)
         norm_before = sqrt(norm**2 + sum(coeff(1:columns)**2))
         if (.not. norm_before > 0.0_wp) then
            ! no direction on the set (e.g. one point in contact under load control: its gap
            ! is s exactly): let the overlapping points in and start afresh
            call keep_best()
            call let_in_overlaps(p, gap, 1.0_wp/op%diagonal, n_changed)
            if (n_changed == 0) then
               ! (after a projection step, which may have left just this point and solved
               ! the problem, the state is first checked with w afresh)
               if (.not. projected) exit
               stale = .true.
               cycle
            end if
            if (load_control) call normalise(p, mean_pressure, across_ranks)
            columns = 0
            newest = 0
            stale = .true.
            cycle
         end if
         if (.not. norm > breakdown*norm_before) then
            ! nothing new in this direction (or not finite): start the history afresh
            if (columns == 0) exit
            columns = 0
            newest = 0
            cycle
         end if
         ! the minimal-residual step: alpha = (r, u) for the unit image u = (a - centre)/norm;
         ! r = -gap on the set (the update normalises the direction and image, straight into
         ! the history, in its pass)
         newest = mod(newest, memory) + 1
         columns = min(columns + 1, memory)
         alpha = -gap_product/norm
         ! the coefficient of the preconditioned residual in the step, for letting points in
         step = alpha/norm
         call update(p, w, gap, d, buffer, centre, 1.0_wp/norm, alpha, step*kappa, dirs(:, newest), &
            & images(:, newest), n_changed, n_clipped, entered, p_sum, best_pending, p_best)
         best_pending = .false.
         if (n_changed > column_updates .or. (n_changed > 0 .and. op%distributed)) then
            ! (a distributed operator has no real-space column: w is made afresh)
            stale = .true.
         else if (n_changed > 0) then
            call op%add_full_columns(buffer, w)
         end if
         since_fresh = since_fresh + 1
         ! (p and w are scaled to the load in the next evaluation's first pass)
         if (load_control) call scale_to_load(p, mean_pressure, stale, p_sum, load_scale)
         if (alpha**2 < stagnation*residual_norm2 .or. (n_clipped > 0 .and. .not. keep) .or. &
            & (keep .and. columns == memory .and. alpha**2 < truncation*residual_norm2)) then
            columns = 0
            newest = 0
         else if (n_clipped > 0) then
            ! keep_clipped: the history is kept without the clipped points, made orthonormal on
            ! the smaller set, and the residual projected on it as after an entry
            call take_out_clipped(op, p, buffer, load_control, dirs, images, columns, d, outcome%fft_pairs)
            call reorthonormalise(p, load_control, dirs, images, columns, newest)
            set_changed = columns > 0
         else if (entered .and. columns > 0) then
            ! points were let in: the history is kept, made orthonormal on the larger set, and
            ! the next iteration first projects the residual on it, which restores GCR's
            ! invariant (residual orthogonal to the stored images)
            call reorthonormalise(p, load_control, dirs, images, columns, newest)
            set_changed = columns > 0
         end if
      end do
      ! not converged: return the best iterate, with w = G_eff p afresh (the updated w may
      ! differ from it by a constant, see above, and by the drift of the updates)
      if (.not. outcome%converged) then
         ! (p itself where it was not changed since it was the best: a refreshed w may have
         ! moved its residual)
         if (best_residual < outcome%residual .and. .not. best_pending) call copy_field(p_best, p)
         call op%apply_full(p, w)
         outcome%fft_pairs = outcome%fft_pairs + 1
         call evaluate(p, w, b, 1.0_wp, load_control, mean_pressure, g_ref, b_max, op%largest, s, gap, &
            & n_contact, outcome%residual, residual_norm2, buffer, .false.)
      end if

   contains

      !> p_best <- p where p is the best iterate not yet copied, before p changes.
      subroutine keep_best()
         if (best_pending) call copy_field(p, p_best)
         best_pending = .false.
      end subroutine keep_best
   end subroutine constrained_gcr

   !> sum p (over the ranks, across_ranks).
   real(wp) function total_pressure(p) result(total)
      real(wp), contiguous, intent(in) :: p(:)
      total = sum(p)
      if (across_ranks) total = global_sum(total)
   end function total_pressure

   !> The points of the field whose slab p is (over the ranks, across_ranks).
   real(wp) function field_points(p) result(points)
      real(wp), contiguous, intent(in) :: p(:)
      points = size(p)
      if (across_ranks) points = global_sum(points)
   end function field_points

   !> Two passes: p and w scaled by load_scale, s (the mean of w - b over the contact set
   !> under load control), the gap w - b - s, the complementarity residual, and -gap on the
   !> contact set (0 elsewhere) in `masked`, the preconditioner's input. fresh: w is read
   !> from `masked` (the transform's buffer, holding G_eff p afresh), not from w.
   subroutine evaluate(p, w, b, load_scale, load_control, mean_pressure, g_ref, b_max, m_max, s, gap, n_contact, &
         & residual, norm2, masked, fresh)
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(in) :: b(:)
      real(wp), intent(in) :: load_scale
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref, b_max, m_max
      real(wp), intent(inout) :: s
      real(wp), contiguous, intent(out) :: gap(:)
      real(wp), contiguous, intent(inout) :: masked(:)
      logical, intent(in) :: fresh
      integer, intent(out) :: n_contact
      real(wp), intent(out) :: residual
      real(wp), intent(out) :: norm2   !< sum of gap^2 over the contact set
      real(wp) :: contact, gap_sum, p_sum, w_max, p_max, p_scale, g_scale, g_floor, check
      real(wp) :: sums(5, reduction_blocks(size(p))), totals(3), maxima(2)
      integer :: block, first, last
      ! (the passes on blocks of the grid, by procedures of their own, which vectorise: sums by
      ! blocks, added in order, the same bits on any number of threads)
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(sums, 2)
         call block_range(block, size(p), first, last)
         if (fresh) then
            call scale_fresh_and_sum(p(first:last), masked(first:last), w(first:last), b(first:last), load_scale, &
               & sums(:, block))
         else
            call scale_and_sum(p(first:last), w(first:last), b(first:last), load_scale, sums(:, block))
         end if
      end do
      w_max = maxval(sums(4, :))
      p_max = maxval(sums(5, :))
      contact = sum(sums(1, :))
      gap_sum = sum(sums(2, :))
      p_sum = sum(sums(3, :))
      if (across_ranks) then
         totals = [contact, gap_sum, p_sum]
         maxima = [w_max, p_max]
         call sum_over_ranks(totals)
         call max_over_ranks(maxima)
         contact = totals(1)
         gap_sum = totals(2)
         p_sum = totals(3)
         w_max = maxima(1)
         p_max = maxima(2)
      end if
      n_contact = nint(contact)
      if (load_control) s = gap_sum/max(contact, 1.0_wp)
      p_scale = 1.0_wp/max(merge(mean_pressure, p_sum/field_points(p), load_control), tiny(1.0_wp))
      g_scale = 1.0_wp/g_ref
      g_floor = rounding_floor(w_max, b_max, p_max, m_max)
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(sums, 2)
         call block_range(block, size(p), first, last)
         call gaps_and_residual(p(first:last), w(first:last), b(first:last), s, p_scale, g_scale, g_floor, &
            & gap(first:last), masked(first:last), sums(1:3, block))
      end do
      check = sum(sums(1, :))
      norm2 = sum(sums(2, :))
      residual = maxval(sums(3, :))
      if (across_ranks) then
         totals(1:2) = [check, norm2]
         call sum_over_ranks(totals(1:2))
         check = totals(1)
         norm2 = totals(2)
         residual = global_max(residual)
      end if
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
   end subroutine evaluate

   !> evaluate's first pass on a block: p and w scaled by load_scale; sums = (points in
   !> contact, sum of w - b over them, sum p, max |w|, max p).
   subroutine scale_and_sum(p, w, b, load_scale, sums)
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(in) :: b(:)
      real(wp), intent(in) :: load_scale
      real(wp), intent(out) :: sums(5)
      real(wp) :: contact, gap_sum, p_sum, w_max, p_max, inside
      integer :: j
      contact = 0.0_wp
      gap_sum = 0.0_wp
      p_sum = 0.0_wp
      w_max = 0.0_wp
      p_max = 0.0_wp
      ! (the stores are unconditional: a store under a condition is not vectorised)
      !$omp simd reduction(+:contact, gap_sum, p_sum) reduction(max:w_max, p_max) private(inside)
      do j = 1, size(p)
         p(j) = p(j)*load_scale
         w(j) = w(j)*load_scale
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         contact = contact + inside
         gap_sum = gap_sum + (w(j) - b(j))*inside
         p_sum = p_sum + p(j)
         w_max = max(w_max, abs(w(j)))
         p_max = max(p_max, p(j))
      end do
      sums = [contact, gap_sum, p_sum, w_max, p_max]
   end subroutine scale_and_sum

   !> scale_and_sum with w = load_scale times `fresh` (G_eff p, read from the buffer).
   subroutine scale_fresh_and_sum(p, fresh, w, b, load_scale, sums)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(in) :: fresh(:), b(:)
      real(wp), contiguous, intent(out) :: w(:)
      real(wp), intent(in) :: load_scale
      real(wp), intent(out) :: sums(5)
      real(wp) :: contact, gap_sum, p_sum, w_max, p_max, inside
      integer :: j
      contact = 0.0_wp
      gap_sum = 0.0_wp
      p_sum = 0.0_wp
      w_max = 0.0_wp
      p_max = 0.0_wp
      !$omp simd reduction(+:contact, gap_sum, p_sum) reduction(max:w_max, p_max) private(inside)
      do j = 1, size(p)
         p(j) = p(j)*load_scale
         w(j) = fresh(j)*load_scale
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         contact = contact + inside
         gap_sum = gap_sum + (w(j) - b(j))*inside
         p_sum = p_sum + p(j)
         w_max = max(w_max, abs(w(j)))
         p_max = max(p_max, p(j))
      end do
      sums = [contact, gap_sum, p_sum, w_max, p_max]
   end subroutine scale_fresh_and_sum

   !> evaluate's second pass on a block: the gap, -gap on the contact set in `masked`;
   !> sums = (sum of gap + p (finite unless a value is not), sum of gap^2 over the contact
   !> set, the largest complementarity term).
   subroutine gaps_and_residual(p, w, b, s, p_scale, g_scale, g_floor, gap, masked, sums)
      real(wp), contiguous, intent(in) :: p(:), w(:), b(:)
      real(wp), intent(in) :: s, p_scale, g_scale, g_floor
      real(wp), contiguous, intent(out) :: gap(:), masked(:)
      real(wp), intent(out) :: sums(3)
      real(wp) :: residual, check, norm2, g, c, inside
      integer :: j
      residual = 0.0_wp
      check = 0.0_wp
      norm2 = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:check, norm2) private(g, c, inside)
      do j = 1, size(p)
         g = w(j) - b(j) - s
         gap(j) = g
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         masked(j) = -g*inside
         norm2 = norm2 + g*g*inside
         c = abs(min(p(j)*p_scale, g*g_scale))
         residual = max(residual, merge(c, 0.0_wp, abs(g) > g_floor))
         check = check + g + p(j)
      end do
      sums = [check, norm2, residual]
   end subroutine gaps_and_residual

   !> The mean of v over the contact set (p > 0) under load control, 0 otherwise (one pass).
   real(wp) function set_mean(p, load_control, v) result(mean)
      real(wp), contiguous, intent(in) :: p(:), v(:)
      logical, intent(in) :: load_control
      real(wp) :: sums(2, reduction_blocks(size(p))), totals(2)
      integer :: block, first, last
      mean = 0.0_wp
      if (.not. load_control) return
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(sums, 2)
         call block_range(block, size(p), first, last)
         call set_sums(p(first:last), v(first:last), sums(:, block))
      end do
      totals = [sum(sums(1, :)), sum(sums(2, :))]
      if (across_ranks) call sum_over_ranks(totals)
      mean = totals(1)/max(totals(2), 1.0_wp)
   end function set_mean

   !> On a block: sums = (sum of v over the contact set, its points).
   subroutine set_sums(p, v, sums)
      real(wp), contiguous, intent(in) :: p(:), v(:)
      real(wp), intent(out) :: sums(2)
      real(wp) :: v_sum, contact, inside
      integer :: j
      v_sum = 0.0_wp
      contact = 0.0_wp
      !$omp simd reduction(+:v_sum, contact) private(inside)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         v_sum = v_sum + v(j)*inside
         contact = contact + inside
      end do
      sums = [v_sum, contact]
   end subroutine set_sums

   !> d = z on the contact set, minus its mean there under load control, 0 elsewhere; z
   !> (the buffer) is overwritten by d, the next transform's input.
   subroutine project_on_set(p, load_control, z, d)
      real(wp), contiguous, intent(in) :: p(:)
      logical, intent(in) :: load_control
      real(wp), contiguous, intent(inout) :: z(:)
      real(wp), contiguous, intent(out) :: d(:)
      real(wp) :: mean
      integer :: block, first, last
      mean = set_mean(p, load_control, z)
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, reduction_blocks(size(p))
         call block_range(block, size(p), first, last)
         call project_block(p(first:last), mean, z(first:last), d(first:last))
      end do
   end subroutine project_on_set

   !> project_on_set on a block.
   subroutine project_block(p, mean, z, d)
      real(wp), contiguous, intent(in) :: p(:)
      real(wp), intent(in) :: mean
      real(wp), contiguous, intent(inout) :: z(:)
      real(wp), contiguous, intent(out) :: d(:)
      real(wp) :: inside
      integer :: j
      !$omp simd private(inside)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         d(j) = (z(j) - mean)*inside
         z(j) = d(j)
      end do
   end subroutine project_block

   !> The mean of v over the contact set (`centre`, 0 without load control), the norm of
   !> v - centre on the set, and gap_product = the sum of gap (v - centre) over the set (the
   !> minimal-residual step along v's direction), in one pass over the grid: each block of
   !> points is centred on its own mean on the set while it is in the cache, and the blocks'
   !> sums are combined as the partial sums of a variance are (Chan, Golub & LeVeque,
   !> "Algorithms for computing the sample variance: analysis and recommendations"): no
   !> square of a mean is subtracted from a sum of squares.
   subroutine set_norm(p, load_control, v, gap, centre, norm, gap_product)
      real(wp), contiguous, intent(in) :: p(:), v(:), gap(:)
      logical, intent(in) :: load_control
      real(wp), intent(out) :: centre, norm, gap_product
      real(wp) :: sums(5, reduction_blocks(size(p))), totals(2), block_mean
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(sums, 2)
         call block_range(block, size(p), first, last)
         call centred_squares(p(first:last), v(first:last), gap(first:last), sums(:, block))
      end do
      ! (blocks added in order: the same bits on any number of threads)
      totals = [sum(sums(1, :)), sum(sums(2, :))]
      if (across_ranks) call sum_over_ranks(totals)
      centre = 0.0_wp
      if (load_control) centre = totals(2)/max(totals(1), 1.0_wp)
      totals = 0.0_wp
      do block = 1, size(sums, 2)
         block_mean = sums(2, block)/max(sums(1, block), 1.0_wp)
         totals(1) = totals(1) + sums(3, block) + sums(1, block)*(block_mean - centre)**2
         totals(2) = totals(2) + sums(4, block) + (block_mean - centre)*sums(5, block)
      end do
      if (across_ranks) call sum_over_ranks(totals)
      norm = sqrt(totals(1))
      gap_product = totals(2)
   end subroutine set_norm

   !> On a block, over the contact set: sums = (its points, the sum of v, of (v - m)^2, of
   !> gap (v - m), of gap), m the block's mean of v on the set (the block is read twice,
   !> the second time from the cache).
   subroutine centred_squares(p, v, gap, sums)
      real(wp), contiguous, intent(in) :: p(:), v(:), gap(:)
      real(wp), intent(out) :: sums(5)
      real(wp) :: inside, x, contact, v_sum, mean, v2_sum, gv_sum, g_sum
      integer :: j
      contact = 0.0_wp
      v_sum = 0.0_wp
      !$omp simd reduction(+:contact, v_sum) private(inside)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         contact = contact + inside
         v_sum = v_sum + v(j)*inside
      end do
      mean = v_sum/max(contact, 1.0_wp)
      v2_sum = 0.0_wp
      gv_sum = 0.0_wp
      g_sum = 0.0_wp
      !$omp simd reduction(+:v2_sum, gv_sum, g_sum) private(inside, x)
      do j = 1, size(p)
         inside = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         x = (v(j) - mean)*inside
         v2_sum = v2_sum + x*x
         gv_sum = gv_sum + gap(j)*x
         g_sum = g_sum + gap(j)*inside
      end do
      sums = [contact, v_sum, v2_sum, gv_sum, g_sum]
   end subroutine centred_squares

   !> coeff(i) = (a, images(:, i)) over the contact set, in one sweep by blocks of rows.
   !> (The stored images are centred on the set, so the mean of a need not be removed.)
   subroutine history_products(images, p, a, coeff)
      real(wp), contiguous, intent(in) :: images(:, :), p(:), a(:)
      real(wp), intent(out) :: coeff(:)
      real(wp), allocatable :: partial(:, :)
      integer :: i0, i1, block
      ! (each block's products apart, then added block by block in order: the same bits on
      ! any number of threads; the block's loops in a procedure of their own, which
      ! vectorises: decisions/022; on the heap: 10 to 80 products per 2048 rows)
      allocate (partial(size(coeff), (size(a) + block_rows - 1)/block_rows))
      !$omp parallel do schedule(static) private(i0, i1) if(size(a) >= parallel_points)
      do block = 1, size(partial, 2)
         i0 = (block - 1)*block_rows + 1
         i1 = min(size(a), i0 + block_rows - 1)
         call block_products(images, p, a, i0, i1, partial(:, block))
      end do
      coeff = 0.0_wp
      do block = 1, size(partial, 2)
         coeff = coeff + partial(:, block)
      end do
      if (across_ranks .and. size(coeff) > 0) call sum_over_ranks(coeff)
   end subroutine history_products

   !> history_products on the rows i0..i1: a weighted by the contact set once (the weight is
   !> 0 or 1, so the weighted a is exact), then its product with each image.
   subroutine block_products(images, p, a, i0, i1, coeff)
      real(wp), contiguous, intent(in) :: images(:, :), p(:), a(:)
      integer, intent(in) :: i0, i1
      real(wp), intent(out) :: coeff(:)
      real(wp) :: masked(i1 - i0 + 1), c
      integer :: i, k
      !$omp simd
      do i = i0, i1
         masked(i - i0 + 1) = a(i)*merge(1.0_wp, 0.0_wp, p(i) > 0.0_wp)
      end do
      do k = 1, size(coeff)
         c = 0.0_wp
         !$omp simd reduction(+:c)
         do i = i0, i1
            c = c + masked(i - i0 + 1)*images(i, k)
         end do
         coeff(k) = c
      end do
   end subroutine block_products

   !> d <- d - sum_k coeff(k) dirs(:, k), a <- a - sum_k coeff(k) images(:, k), by blocks.
   subroutine subtract_history(dirs, images, coeff, d, a)
      real(wp), contiguous, intent(in) :: dirs(:, :), images(:, :)
      real(wp), intent(in) :: coeff(:)
      real(wp), contiguous, intent(inout) :: d(:), a(:)
      integer :: i0, i1
      !$omp parallel do schedule(static) private(i1) if(size(a) >= parallel_points)
      do i0 = 1, size(a), block_rows
         i1 = min(size(a), i0 + block_rows - 1)
         call subtract_block(dirs, images, coeff, i0, i1, d, a)
      end do
   end subroutine subtract_history

   !> subtract_history on the rows i0..i1.
   subroutine subtract_block(dirs, images, coeff, i0, i1, d, a)
      real(wp), contiguous, intent(in) :: dirs(:, :), images(:, :)
      real(wp), intent(in) :: coeff(:)
      integer, intent(in) :: i0, i1
      real(wp), contiguous, intent(inout) :: d(:), a(:)
      integer :: i, k
      do k = 1, size(coeff)
         !$omp simd
         do i = i0, i1
            d(i) = d(i) - coeff(k)*dirs(i, k)
            a(i) = a(i) - coeff(k)*images(i, k)
         end do
      end do
   end subroutine subtract_block

   !> One pass: the direction d and its image a normalised, d_unit = scale d and a_unit =
   !> scale (a - centre) (into the history), p <- p + alpha d_unit and w <- w + alpha a_unit;
   !> points out of contact with a negative gap are let in with -let_in_scale gap (Polonsky &
   !> Keer's rule: the preconditioned step there), negative pressures clipped. a_delta: in,
   !> the image a; out, the change of p that was not along d (nonzero at the points clipped
   !> or let in), for the column updates of w; p_sum: sum p. keep: p_before <- p first (the
   !> copy of the best iterate, taken in this pass while it reads p).
   subroutine update(p, w, gap, d, a_delta, centre, scale, alpha, let_in_scale, d_unit, a_unit, n_changed, &
         & n_clipped, entered, p_sum, keep, p_before)
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(in) :: gap(:), d(:)
      real(wp), contiguous, intent(inout) :: a_delta(:)
      real(wp), intent(in) :: centre, scale, alpha, let_in_scale
      real(wp), contiguous, intent(out) :: d_unit(:), a_unit(:)
      integer, intent(out) :: n_changed
      integer, intent(out) :: n_clipped
      logical, intent(out) :: entered
      real(wp), intent(out) :: p_sum
      logical, intent(in) :: keep
      real(wp), contiguous, intent(inout) :: p_before(:)
      real(wp) :: clip_count, enter_count, changed_count, totals(4)
      real(wp) :: sums(4, reduction_blocks(size(p)))
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(sums, 2)
         call block_range(block, size(p), first, last)
         if (keep) call copy_block(p(first:last), p_before(first:last))
         call update_block(p(first:last), w(first:last), gap(first:last), d(first:last), a_delta(first:last), &
            & centre, scale, alpha, let_in_scale, d_unit(first:last), a_unit(first:last), sums(:, block))
      end do
      ! (the counts are exact in any order; the sum of p added block by block in order)
      clip_count = sum(sums(1, :))
      enter_count = sum(sums(2, :))
      changed_count = sum(sums(3, :))
      p_sum = sum(sums(4, :))
      if (across_ranks) then
         totals = [clip_count, enter_count, changed_count, p_sum]
         call sum_over_ranks(totals)
         clip_count = totals(1)
         enter_count = totals(2)
         changed_count = totals(3)
         p_sum = totals(4)
      end if
      n_changed = nint(changed_count)
      n_clipped = nint(clip_count)
      entered = enter_count > 0.0_wp
   end subroutine update

   !> copy = v on a block (left in the cache for the pass that goes on with it).
   subroutine copy_block(v, copy)
      real(wp), contiguous, intent(in) :: v(:)
      real(wp), contiguous, intent(out) :: copy(:)
      copy = v
   end subroutine copy_block

   !> update on a block; sums = (points clipped, let in, changed, sum of the new p).
   subroutine update_block(p, w, gap, d, a_delta, centre, scale, alpha, let_in_scale, d_unit, a_unit, sums)
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(in) :: gap(:), d(:)
      real(wp), contiguous, intent(inout) :: a_delta(:)
      real(wp), intent(in) :: centre, scale, alpha, let_in_scale
      real(wp), contiguous, intent(out) :: d_unit(:), a_unit(:)
      real(wp), intent(out) :: sums(4)
      real(wp) :: trial, p_new, c, du, au, clip_count, enter_count, changed_count, p_sum
      integer :: j
      clip_count = 0.0_wp
      enter_count = 0.0_wp
      changed_count = 0.0_wp
      p_sum = 0.0_wp
      !$omp simd reduction(+:clip_count, enter_count, changed_count, p_sum) private(trial, p_new, c, du, au)
      do j = 1, size(p)
         du = d(j)*scale
         au = (a_delta(j) - centre)*scale
         d_unit(j) = du
         a_unit(j) = au
         trial = p(j) + alpha*du   ! (d = 0 off the contact set)
         ! let in: out of contact (p = 0) and overlapping
         c = merge(1.0_wp, 0.0_wp, p(j) <= 0.0_wp)*merge(1.0_wp, 0.0_wp, gap(j) < 0.0_wp)
         p_new = c*max(-let_in_scale*gap(j), 0.0_wp) + (1.0_wp - c)*trial
         enter_count = enter_count + c*merge(1.0_wp, 0.0_wp, p_new > 0.0_wp)
         clip_count = clip_count + merge(1.0_wp, 0.0_wp, p_new < 0.0_wp)
         p_new = merge(p_new, 0.0_wp, p_new >= 0.0_wp)   ! clip (a NaN too)
         w(j) = w(j) + alpha*au
         a_delta(j) = p_new - trial
         changed_count = changed_count + merge(1.0_wp, 0.0_wp, p_new /= trial)
         p(j) = p_new
         p_sum = p_sum + p_new
      end do
      sums = [clip_count, enter_count, changed_count, p_sum]
   end subroutine update_block

   !> The factor that scales p (and w = G p, linear in p) to the load, from sum p; a vanished
   !> p is reset to uniform (w stale then, factor 1).
   subroutine scale_to_load(p, mean_pressure, stale, total, factor)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), intent(in) :: mean_pressure
      logical, intent(inout) :: stale
      real(wp), intent(in) :: total   !< sum p
      real(wp), intent(out) :: factor
      factor = 1.0_wp
      if (total > 0.0_wp) then
         factor = mean_pressure*field_points(p)/total
      else
         p = mean_pressure
         stale = .true.
      end if
   end subroutine scale_to_load

   !> p < 0 set to 0; delta = the change (0 elsewhere); n_negative: how many.
   subroutine clip_negative(p, delta, n_negative)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: delta(:)
      integer, intent(out) :: n_negative
      real(wp) :: count_negative
      integer :: j
      count_negative = 0.0_wp
      !$omp parallel do simd schedule(static) reduction(+:count_negative) if(size(p) >= parallel_points)
      do j = 1, size(p)
         delta(j) = merge(-p(j), 0.0_wp, p(j) < 0.0_wp)
         count_negative = count_negative + merge(1.0_wp, 0.0_wp, p(j) < 0.0_wp)
         p(j) = p(j) + delta(j)
      end do
      if (across_ranks) count_negative = global_sum(count_negative)
      n_negative = nint(count_negative)
   end subroutine clip_negative

   !> After the contact set changed: the stored images, centred again on the new contact set,
   !> are made orthonormal there again (Cholesky of their Gram matrix on the set: one sweep
   !> for the products, one for the triangular transform in place by blocks of rows, no
   !> FFT). The columns end oldest first; if the Gram matrix is not numerically positive
   !> definite the history is dropped.
   subroutine reorthonormalise(p, load_control, dirs, images, columns, newest)
      real(wp), contiguous, intent(in) :: p(:)
      logical, intent(in) :: load_control
      real(wp), contiguous, intent(inout) :: dirs(:, :), images(:, :)
      integer, intent(inout) :: columns, newest
      real(wp), allocatable :: gram(:, :), sums(:), centre(:), length(:), block_gram(:, :, :), block_sums(:, :)
      real(wp), allocatable :: flat(:)
      integer, allocatable :: order(:)
      real(wp) :: contact
      integer :: i0, i1, k, l, m, info, block

      m = columns
      ! oldest first
      allocate (order(m))
      do k = 1, m
         order(k) = modulo(newest - m + k - 1, size(dirs, 2)) + 1
      end do
      allocate (gram(m, m), sums(m), centre(m), length(m))
      contact = count(p > 0.0_wp)
      if (across_ranks) contact = global_sum(contact)
      ! (each block of rows apart, then added block by block in order: the same bits on any
      ! number of threads)
      allocate (block_gram(m, m, (size(p) + block_rows - 1)/block_rows), block_sums(m, (size(p) + block_rows - 1)/block_rows))
      !$omp parallel do schedule(static) private(i0, i1) if(size(p) >= parallel_points)
      do block = 1, size(block_gram, 3)
         i0 = (block - 1)*block_rows + 1
         i1 = min(size(p), i0 + block_rows - 1)
         call block_gram_on_set(images, order, p, i0, i1, block_sums(:, block), block_gram(:, :, block))
      end do
      gram = 0.0_wp
      sums = 0.0_wp
      do block = 1, size(block_gram, 3)
         do k = 1, m
            sums(k) = sums(k) + block_sums(k, block)
            gram(k, 1:k) = gram(k, 1:k) + block_gram(k, 1:k, block)
         end do
      end do
      if (across_ranks) then
         call sum_over_ranks(sums)
         flat = reshape(gram, [m*m])
         call sum_over_ranks(flat)
         gram = reshape(flat, [m, m])
      end if
      centre = 0.0_wp
      if (load_control) centre = sums/max(contact, 1.0_wp)
      do k = 1, m
         length(k) = sqrt(gram(k, k))
      end do
      do k = 1, m
         do l = 1, k
            gram(k, l) = gram(k, l) - contact*centre(k)*centre(l)
            gram(l, k) = gram(k, l)
         end do
      end do
      ! gram = L L^T; the new basis is V L^-T (column k a combination of the old 1..k)
      call dpotrf('L', m, gram, m, info)
      ! (an image that centring and the older ones leave little of is numerically in their
      ! span, as when the history has about as many columns as the set has points: a small
      ! pivot scales the rounding of the directions and images apart, and w, updated along
      ! them, drifts from G_eff p)
      if (info == 0) then
         do k = 1, m
            if (.not. gram(k, k) > independence*length(k)) info = k
         end do
      end if
      if (info /= 0) then
         columns = 0
         newest = 0
         return
      end if
      ! forward substitution, row block by row block: new_k = (old_k - sum_{l<k} L(k,l) new_l)/L(k,k)
      !$omp parallel do schedule(static) private(i1) if(size(p) >= parallel_points)
      do i0 = 1, size(p), block_rows
         i1 = min(size(p), i0 + block_rows - 1)
         call substitute_block(gram, centre, order, i0, i1, dirs, images)
      end do
      ! (slots oldest first, so that the sweeps over the history keep their order)
      if (any(order /= [(k, k=1, m)])) then
         dirs(:, 1:m) = dirs(:, order)
         images(:, 1:m) = images(:, order)
      end if
      newest = m
   end subroutine reorthonormalise

   !> reorthonormalise's products on the rows i0..i1: sums(k) = the sum of image order(k)
   !> over the contact set, gram(k, l) = the product of images order(k) and order(l) there
   !> (l <= k).
   subroutine block_gram_on_set(images, order, p, i0, i1, sums, gram)
      real(wp), contiguous, intent(in) :: images(:, :), p(:)
      integer, intent(in) :: order(:), i0, i1
      real(wp), intent(out) :: sums(:), gram(:, :)
      real(wp) :: x
      integer :: i, k, l
      do k = 1, size(order)
         sums(k) = 0.0_wp
         do i = i0, i1
            if (p(i) > 0.0_wp) sums(k) = sums(k) + images(i, order(k))
         end do
         do l = 1, k
            x = 0.0_wp
            !$omp simd reduction(+:x)
            do i = i0, i1
               x = x + images(i, order(k))*images(i, order(l))*merge(1.0_wp, 0.0_wp, p(i) > 0.0_wp)
            end do
            gram(k, l) = x
         end do
      end do
   end subroutine block_gram_on_set

   !> reorthonormalise's forward substitution on the rows i0..i1 (gram: the Cholesky factor).
   subroutine substitute_block(gram, centre, order, i0, i1, dirs, images)
      real(wp), intent(in) :: gram(:, :), centre(:)
      integer, intent(in) :: order(:), i0, i1
      real(wp), contiguous, intent(inout) :: dirs(:, :), images(:, :)
      integer :: i, k, l
      do k = 1, size(order)
         images(i0:i1, order(k)) = images(i0:i1, order(k)) - centre(k)
         do l = 1, k - 1
            !$omp simd
            do i = i0, i1
               dirs(i, order(k)) = dirs(i, order(k)) - gram(k, l)*dirs(i, order(l))
               images(i, order(k)) = images(i, order(k)) - gram(k, l)*images(i, order(l))
            end do
         end do
         dirs(i0:i1, order(k)) = dirs(i0:i1, order(k))/gram(k, k)
         images(i0:i1, order(k)) = images(i0:i1, order(k))/gram(k, k)
      end do
   end subroutine substitute_block

   !> keep_clipped, after a step clipped a few points: the stored directions without them
   !> (zero there, and under load control their sum over the smaller set restored to zero
   !> along the set's indicator), with their images corrected to match (a column pass per
   !> clipped point and stored direction, or a transform per direction beyond
   !> clipped_columns points; one transform for the indicator's image). delta: the change of
   !> p outside the step, nonzero at the points clipped or let in (the FFT buffer: read
   !> first); work: a field of n.
   subroutine take_out_clipped(op, p, delta, load_control, dirs, images, columns, work, fft_pairs)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: p(:)
      real(wp), contiguous, intent(in) :: delta(:)
      logical, intent(in) :: load_control
      real(wp), intent(inout) :: dirs(:, :), images(:, :)
      integer, intent(in) :: columns
      real(wp), contiguous, intent(out) :: work(:)
      integer, intent(inout) :: fft_pairs
      integer, allocatable :: clipped(:)
      real(wp), allocatable :: mean(:)
      real(wp), pointer, contiguous :: buffer(:)
      real(wp) :: contact
      integer :: j, k
      clipped = pack([(j, j=1, size(p))], p == 0.0_wp .and. delta /= 0.0_wp)
      allocate (mean(columns))
      contact = count(p > 0.0_wp)
      if (across_ranks) contact = global_sum(contact)
      buffer => op%buffer()
      ! (a distributed operator has no real-space column: the images are made afresh)
      if (size(clipped) > clipped_columns .or. op%distributed) then
         do k = 1, columns
            dirs(clipped, k) = 0.0_wp
            if (load_control) then
               mean(k) = sum(dirs(:, k))
               if (across_ranks) mean(k) = global_sum(mean(k))
               mean(k) = mean(k)/max(contact, 1.0_wp)
               where (p > 0.0_wp) dirs(:, k) = dirs(:, k) - mean(k)
            end if
            buffer = dirs(:, k)
            call op%full_in_buffer()
            fft_pairs = fft_pairs + 1
            images(:, k) = buffer
         end do
         return
      end if
      work = 0.0_wp
      do k = 1, columns
         work(clipped) = -dirs(clipped, k)
         mean(k) = sum(work(clipped))/max(contact, 1.0_wp)
         dirs(clipped, k) = 0.0_wp
         call op%add_full_columns(work, images(:, k))
         work(clipped) = 0.0_wp
      end do
      if (.not. load_control) return
      fft_pairs = fft_pairs + 1
      buffer = merge(1.0_wp, 0.0_wp, p > 0.0_wp)
      call op%full_in_buffer()
      do k = 1, columns
         where (p > 0.0_wp) dirs(:, k) = dirs(:, k) - mean(k)
         images(:, k) = images(:, k) - mean(k)*buffer
      end do
   end subroutine take_out_clipped

   !> Load the overlapping points out of contact (p = 0, gap < 0) with the pressure -gap/M_jj
   !> of a first step; n_changed: how many.
   subroutine let_in_overlaps(p, gap, inverse_diagonal, n_changed)
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(in) :: gap(:)
      real(wp), intent(in) :: inverse_diagonal
      integer, intent(out) :: n_changed
      integer :: j
      n_changed = 0
      do j = 1, size(p)
         if (p(j) <= 0.0_wp .and. gap(j) < 0.0_wp) then
            p(j) = -gap(j)*inverse_diagonal
            n_changed = n_changed + 1
         end if
      end do
      if (across_ranks) n_changed = global_sum(n_changed)
   end subroutine let_in_overlaps
   subroutine solve_by_gcr(self, problem, state, budget, outcome, progress, error)
      class(gcr_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(gcr_outcome) :: gcr
      real(wp), allocatable :: history(:)
      allocate (history(budget))
      call constrained_gcr(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, &
         & problem%g_ref, problem%tol, budget, problem%memory, problem%precondition, state%p, state%w, state%gap, &
         & gcr, history, progress, keep_clipped=self%keep_history)
      outcome = solve_outcome(converged=gcr%converged, iterations=gcr%iterations, outer_iterations=0, &
         & fft_pairs=gcr%fft_pairs, residual=gcr%residual, history=history(1:gcr%iterations))
   end subroutine solve_by_gcr

   pure function gcr_name(self) result(name)
      class(gcr_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = merge('kept', 'gcr ', self%keep_history)
      name = trim(name)
   end function gcr_name

   !> The best iterate is returned, the start (made feasible) included.
   pure logical function gcr_ends_no_worse(self)
      class(gcr_solver), intent(in) :: self
      gcr_ends_no_worse = .true.
   end function gcr_ends_no_worse

end module lc_contact_solver_gcr
