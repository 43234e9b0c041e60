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
   use lc_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: constrained_cg, cg_outcome, complementarity_residual, rounding_floor

   !> Iterations without the residual halving after which the preconditioner is dropped.
   integer, parameter :: stall_window = 100

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
      real(wp), intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: the multiplier
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      !> precondition the residual with the stiffness 1/M on the contact set
      logical, intent(in) :: precondition
      real(wp), intent(inout) :: p(:)
      real(wp), intent(out) :: w(:), gap(:)
      type(cg_outcome), intent(out) :: outcome
      real(wp), intent(inout), optional :: history(:)
      real(wp), allocatable :: t(:), r(:), z(:)
      logical, allocatable :: contact(:), overlap(:)
      real(wp) :: gnorm, gnorm_old, tau, denominator, p_ref, best
      integer :: it, n, n_contact, last_progress
      logical :: restart, preconditioned

      n = size(p)
      allocate (t(n), r(n), z(n), contact(n), overlap(n))
      t = 0.0_wp
      gnorm_old = 1.0_wp
      restart = .true.
      p = max(p, 0.0_wp)
      if (load_control) call normalise(p, mean_pressure)
      preconditioned = precondition
      best = huge(1.0_wp)
      last_progress = 0

      do it = 1, max_iter + 1
         ! state (w, gap, s, residual) of the current p; on the last pass only this, so that
         ! a run stopped by max_iter returns fields that belong together
         call op%apply_metric(p, w)
         outcome%fft_pairs = outcome%fft_pairs + 1
         gap = w - b
         contact = p > 0.0_wp
         n_contact = count(contact)
         if (load_control) s = sum(gap, mask=contact)/max(n_contact, 1)
         gap = gap - s
         p_ref = merge(mean_pressure, sum(p)/n, load_control)
         outcome%residual = complementarity_residual(p, gap, p_ref, g_ref, rounding_floor(w, b))
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
            cycle
         end if
         z = merge(gap, 0.0_wp, contact)
         if (preconditioned) then
            call op%apply_inverse_metric(z, r)
            outcome%fft_pairs = outcome%fft_pairs + 1
            z = merge(r, 0.0_wp, contact)
            if (load_control) where (contact) z = z - sum(z, mask=contact)/n_contact
         end if
         gnorm = sum(gap*z, mask=contact)
         if (restart) then
            t = z
         else
            t = merge(z + (gnorm/gnorm_old)*t, 0.0_wp, contact)
         end if
         gnorm_old = gnorm
         call op%apply_metric(t, r)
         outcome%fft_pairs = outcome%fft_pairs + 1
         if (load_control) r = r - sum(r, mask=contact)/n_contact
         denominator = sum(r*t, mask=contact)
         if (.not. denominator > 0.0_wp) then
            ! t is (numerically) in the null space of the projected operator: start afresh.
            restart = .true.
            cycle
         end if
         tau = sum(gap*t, mask=contact)/denominator
         where (contact) p = p - tau*t
         p = max(p, 0.0_wp)
         overlap = p <= 0.0_wp .and. gap < 0.0_wp
         restart = any(overlap)
         if (restart) where (overlap) p = p - tau*gap
         if (load_control) call normalise(p, mean_pressure)
      end do
   end subroutine constrained_cg

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
         if (p(j) < 0.0_wp) res = max(res, -p(j)*pscale)
      end do
   end function complementarity_residual

   !> Attainable accuracy of a gap g = w - b computed through FFTs: a few hundred ulps of the
   !> largest term (matters only when the load makes w much larger than the profile).
   pure real(wp) function rounding_floor(w, b) result(floor)
      real(wp), intent(in) :: w(:), b(:)
      floor = 256*epsilon(1.0_wp)*max(maxval(abs(w)), maxval(abs(b)))
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
