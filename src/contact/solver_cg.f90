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
module lc_contact_solver_cg
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
   use lc_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: constrained_cg, cg_outcome, complementarity_residual, rounding_floor

   !> Iterations without the residual halving after which the preconditioner is dropped.
   integer, parameter :: stall_window = 100
   !> Iterations after which w = M p is recomputed even if it could be updated in place
   !> (bounds the drift of the update w <- w - tau M t, a few ulps per iteration).
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

contains

   !> Solve the symmetric problem with metric M. On entry p is the starting guess
   !> (any array; it is made feasible), on exit the solution; w = M p, gap and s as above.
   !> history(1:outcome%iterations) receives the residual of each iteration when present.
   subroutine constrained_cg(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, precondition, p, w, &
         & gap, outcome, history)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: the multiplier
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      !> precondition the residual with the stiffness 1/M on the contact set
      logical, intent(in) :: precondition
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(cg_outcome), intent(out) :: outcome
      real(wp), intent(inout), optional :: history(:)
      real(wp), allocatable :: t(:), z(:)
      real(wp), pointer, contiguous :: buffer(:), r(:)
      !> 1 on the contact set (p > 0), 0 elsewhere: masks by multiplication keep the passes
      !> over the grid free of branches, so that they vectorise
      real(wp), allocatable :: inside(:)
      real(wp) :: gnorm, gnorm_old, tau, denominator, best, beta, b_max, m_max
      real(wp) :: p_sum, z_sum, r_sum, rt_sum, t_sum, gt_sum, load_scale
      integer :: it, j, n, n_contact, last_progress, since_fresh, n_changed
      real(wp) :: trial, p_new, z_mean, g, c, changed_count, entered_count
      logical :: restart, preconditioned, stale

      ! The loops below are written out (one pass over the grid for each group of
      ! quantities) because at large n the solver is memory-bound: whole-array expressions
      ! with masks cost a pass each, about as much as the FFTs together.
      n = size(p)
      allocate (t(n), z(n), inside(n))
      ! The operator's FFT buffer is written and read in place (two passes fewer per
      ! transform than copying in and out); r = M t is the buffer's content after the
      ! transform, and the buffer is overwritten by the next transform.
      buffer => op%fft%real_buffer
      r => buffer
      t = 0.0_wp
      gnorm_old = 1.0_wp
      restart = .true.
      p = max(p, 0.0_wp)
      if (load_control) call normalise(p, mean_pressure)
      preconditioned = precondition
      best = huge(1.0_wp)
      last_progress = 0
      b_max = maxval(abs(b))
      m_max = op%largest

      stale = .true.
      since_fresh = 0
      load_scale = 1.0_wp
      do it = 1, max_iter + 1
         ! w = M p is recomputed only when p changed other than along t (a point clipped or
         ! let in), every refresh_interval iterations, and to confirm convergence or return
         ! at max_iter (so that the fields returned belong together); otherwise it was
         ! updated in place (w <- w - tau M t), which saves one FFT pair per iteration.
         do
            if (stale .or. since_fresh >= refresh_interval) then
               call op%apply_metric(p, w)
               outcome%fft_pairs = outcome%fft_pairs + 1
               since_fresh = 0
               stale = .false.
            end if
            call evaluate_state(p, w, b, load_scale, load_control, mean_pressure, g_ref, b_max, m_max, gap, inside, s, &
               & n_contact, gnorm, outcome%residual, buffer)
            load_scale = 1.0_wp
            if (since_fresh == 0 .or. .not. (outcome%residual <= tol .or. it > max_iter)) exit
            stale = .true.
         end do
         outcome%converged = outcome%residual <= tol
         outcome%preconditioned = preconditioned
         outcome%iterations = min(it, max_iter)
         if (present(history)) then
            if (it <= size(history)) history(it) = outcome%residual
         end if
         if (outcome%converged .or. it > max_iter) return
         ! The Fourier preconditioner amplifies short waves; where the compliance falls
         ! steeply with k (a glassy viscoelastic layer) its directions make the contact set
         ! oscillate. If the residual has not halved in `stall_window` iterations, continue
         ! with plain Polonsky-Keer steps, which always make progress.
         if (outcome%residual < 0.5_wp*best) then
            best = outcome%residual
            last_progress = it
         else if (preconditioned .and. it - last_progress > stall_window) then
            preconditioned = .false.
            restart = .true.
            last_progress = it
         end if

         if (n_contact == 0) then
            ! Displacement control with nothing in contact yet: load the overlapping points
            ! (the diagonal of M is the natural scale of a first step).
            p = max(-gap, 0.0_wp)/op%diagonal
            restart = .true.
            stale = .true.
            cycle
         end if

         ! search direction t: the (preconditioned) residual on the contact set, conjugated
         if (preconditioned) then
            ! (evaluate_state left the gap on the contact set in the buffer)
            call op%inverse_metric_in_buffer()
            outcome%fft_pairs = outcome%fft_pairs + 1
            z_sum = 0.0_wp
            !$omp simd reduction(+:z_sum)
            do j = 1, n
               z_sum = z_sum + buffer(j)*inside(j)
            end do
            if (.not. load_control) z_sum = 0.0_wp
            z_mean = z_sum/n_contact
            gnorm = 0.0_wp
            !$omp simd reduction(+:gnorm)
            do j = 1, n
               z(j) = (buffer(j) - z_mean)*inside(j)
               gnorm = gnorm + gap(j)*z(j)
            end do
         end if
         beta = merge(0.0_wp, gnorm/gnorm_old, restart)
         gnorm_old = gnorm
         if (preconditioned) then
            do j = 1, n
               t(j) = (z(j) + beta*t(j))*inside(j)
               buffer(j) = t(j)
            end do
         else
            do j = 1, n
               t(j) = (gap(j) + beta*t(j))*inside(j)
               buffer(j) = t(j)
            end do
         end if
         call op%metric_in_buffer()   ! r = M t
         outcome%fft_pairs = outcome%fft_pairs + 1
         ! step along t on the contact set; with load control the mean of M t over the
         ! contact set is removed (the multiplier s absorbs it):
         ! denominator = sum (r - <r>) t = sum r t - <r> sum t
         r_sum = 0.0_wp
         rt_sum = 0.0_wp
         t_sum = 0.0_wp
         gt_sum = 0.0_wp
         ! (t = 0 off the contact set)
         !$omp simd reduction(+:r_sum, rt_sum, t_sum, gt_sum)
         do j = 1, n
            r_sum = r_sum + r(j)*inside(j)
            rt_sum = rt_sum + r(j)*t(j)
            t_sum = t_sum + t(j)
            gt_sum = gt_sum + gap(j)*t(j)
         end do
         denominator = rt_sum
         if (load_control) denominator = rt_sum - r_sum/n_contact*t_sum
         if (.not. denominator > 0.0_wp) then
            ! t is (numerically) in the null space of the projected operator (e.g. a single
            ! point in contact under load control: its gap is s exactly): let the
            ! overlapping points in, as for an empty contact set, and start afresh
            if (any(p <= 0.0_wp .and. gap < 0.0_wp)) then
               where (p <= 0.0_wp .and. gap < 0.0_wp) p = -gap/op%diagonal
               if (load_control) call normalise(p, mean_pressure)
               stale = .true.
            end if
            restart = .true.
            cycle
         end if
         tau = gt_sum/denominator
         ! update, clip at zero, and let overlapping points (p = 0, gap < 0) into the contact;
         ! w follows p along t here, and the points clipped or let in below
         p_sum = 0.0_wp
         changed_count = 0.0_wp
         entered_count = 0.0_wp
         !$omp simd reduction(+:p_sum, changed_count, entered_count) private(trial, p_new, g, c)
         do j = 1, n
            ! t = 0 off the contact set, so p - tau t is p there
            trial = p(j) - tau*t(j)
            p_new = merge(trial, 0.0_wp, trial >= 0.0_wp)   ! clip (a NaN too)
            ! let in where p = 0 and gap < 0; max(): once the contact set is solved tau is a
            ! ratio of rounding noise and may be negative, and a negative pressure would
            ! never be clipped again
            g = gap(j)
            c = merge(1.0_wp, 0.0_wp, g < 0.0_wp)*merge(1.0_wp, 0.0_wp, p_new <= 0.0_wp)
            p_new = c*max(-tau*g, 0.0_wp) + (1.0_wp - c)*p_new
            entered_count = entered_count + c
            w(j) = w(j) - tau*r(j)
            ! r is free from here on: it keeps the change that is not along t
            r(j) = p_new - trial
            changed_count = changed_count + merge(1.0_wp, 0.0_wp, p_new /= trial)
            p(j) = p_new
            p_sum = p_sum + p_new
         end do
         restart = entered_count > 0.0_wp
         n_changed = nint(changed_count)
         ! w - tau M t is M p for p - tau t; the few points clipped or let in are added
         ! column by column (M is circulant), more of them cost a transform
         if (n_changed > column_updates) then
            stale = .true.
         else if (n_changed > 0) then
            do j = 1, n
               if (r(j) /= 0.0_wp) call op%add_column(j, r(j), w)
            end do
         end if
         since_fresh = since_fresh + 1
         ! load control: p is scaled to the load (and w alike, M being linear) in the next
         ! pass over the grid, evaluate_state
         if (load_control) then
            if (p_sum > 0.0_wp) then
               load_scale = mean_pressure*n/p_sum
            else
               call normalise(p, mean_pressure)
               stale = .true.
            end if
         end if
      end do
   end subroutine constrained_cg

   !> The state of p and w, both first scaled by load_scale: the gap (and the gap masked to
   !> the contact set), the contact mask `inside`, s (found under load control), the number
   !> of contact points, the squared gap norm on the contact set and the complementarity
   !> residual.
   subroutine evaluate_state(p, w, b, load_scale, load_control, mean_pressure, g_ref, b_max, m_max, gap, inside, &
         & s, n_contact, gnorm, residual, masked_gap)
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(in) :: b(:)
      real(wp), intent(in) :: load_scale, mean_pressure, g_ref, b_max, m_max
      logical, intent(in) :: load_control
      real(wp), contiguous, intent(out) :: gap(:), inside(:)
      real(wp), intent(inout) :: s
      integer, intent(out) :: n_contact
      real(wp), intent(out) :: gnorm, residual
      !> the gap on the contact set, 0 elsewhere (the preconditioner's input, written here to
      !> save a pass over the grid)
      real(wp), contiguous, intent(out) :: masked_gap(:)
      real(wp) :: contact_count, gap_sum, p_sum, w_max, p_max, p_ref, pscale, g_floor, check, g, c
      integer :: j, n

      n = size(p)
      contact_count = 0.0_wp
      gap_sum = 0.0_wp
      p_sum = 0.0_wp
      w_max = 0.0_wp
      p_max = 0.0_wp
      !$omp simd reduction(+:contact_count, gap_sum, p_sum) reduction(max:w_max, p_max)
      do j = 1, n
         p(j) = p(j)*load_scale
         w(j) = w(j)*load_scale
         gap(j) = w(j) - b(j)
         w_max = max(w_max, abs(w(j)))
         p_max = max(p_max, p(j))
         p_sum = p_sum + p(j)
         inside(j) = merge(1.0_wp, 0.0_wp, p(j) > 0.0_wp)
         contact_count = contact_count + inside(j)
         gap_sum = gap_sum + gap(j)*inside(j)
      end do
      n_contact = nint(contact_count)
      if (load_control) s = gap_sum/max(n_contact, 1)
      p_ref = merge(mean_pressure, p_sum/n, load_control)
      pscale = 1.0_wp/max(p_ref, tiny(1.0_wp))
      ! gaps below the rounding floor of w - b count as zero (see rounding_floor)
      g_floor = rounding_floor(w_max, b_max, p_max, m_max)
      residual = 0.0_wp
      gnorm = 0.0_wp
      check = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:gnorm, check) private(g, c)
      do j = 1, n
         g = gap(j) - s
         gap(j) = g
         c = abs(min(p(j)*pscale, g/g_ref))
         residual = max(residual, merge(c, 0.0_wp, abs(g) > g_floor))
         gnorm = gnorm + g*g*inside(j)
         masked_gap(j) = g*inside(j)
         check = check + g
      end do
      ! a NaN or Inf gap or pressure (which max() may skip) makes a sum non-finite:
      ! count it as infinitely wrong
      if (.not. (ieee_is_finite(check) .and. ieee_is_finite(p_sum))) residual = huge(1.0_wp)
   end subroutine evaluate_state

   !> max_j |min(p_j/p_ref, gap_j/g_ref)|: zero iff p >= 0, gap >= 0 and p gap = 0.
   !> Gaps within `g_floor` of zero count as zero: below that the gap is rounding noise of
   !> w - b (see rounding_floor), and no iteration can make it smaller.
   pure real(wp) function complementarity_residual(p, gap, p_ref, g_ref, g_floor) result(res)
      real(wp), intent(in) :: p(:), gap(:), p_ref, g_ref, g_floor
      real(wp) :: pscale
      integer :: j
      pscale = 1.0_wp/max(p_ref, tiny(1.0_wp))
      res = 0.0_wp
      do j = 1, size(p)
         if (abs(gap(j)) > g_floor) res = max(res, abs(min(p(j)*pscale, gap(j)/g_ref)))
         if (ieee_is_nan(gap(j)) .or. ieee_is_nan(p(j))) res = huge(1.0_wp)
         if (p(j) < 0.0_wp) res = max(res, -p(j)*pscale)
      end do
   end function complementarity_residual

   !> Attainable accuracy of a gap g = w - b with w = G p computed through FFTs: a few
   !> hundred ulps of the largest term, max|w|, max|b| or max|p| max_k|G(k)| (the rounding of
   !> the transforms of p; it dominates w when a large uniform pressure is nearly
   !> annihilated, as on a half-space in full contact). Matters only at extreme loads.
   pure real(wp) function rounding_floor(w_max, b_max, p_max, m_max) result(floor)
      real(wp), intent(in) :: w_max, b_max, p_max, m_max
      floor = 256*epsilon(1.0_wp)*max(w_max, b_max, p_max*m_max)
   end function rounding_floor

   !> Scale p to mean p_m (uniform if p vanished altogether).
   pure subroutine normalise(p, mean_pressure)
      real(wp), intent(inout) :: p(:)
      real(wp), intent(in) :: mean_pressure
      real(wp) :: total
      total = sum(p)
      if (total > 0.0_wp) then
         p = p*(mean_pressure*size(p)/total)
      else
         p = mean_pressure
      end if
   end subroutine normalise
end module lc_contact_solver_cg
