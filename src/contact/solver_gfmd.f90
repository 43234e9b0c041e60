!> Green's function molecular dynamics (GFMD): damped dynamics of the surface displacement
!> against a hard wall, with FIRE (Campañá and Müser, Phys. Rev. B 74, 075420, for GFMD;
!> Bitzek, Koskinen, Gähler, Moseler and Gumbsch, Phys. Rev. Lett. 97, 170201, for FIRE).
!>
!> The surface displacement u (= w) moves under the elastic force of the layer, the
!> pressure p = K u per mode (K = 1/G_eff, the operator's stiffness; with friction the
!> shear traction mu_c p is the in-plane load that G_eff contains, so the force is not the
!> gradient of an energy), and the load; the rigid surface is a hard wall at a fixed
!> position, u_j >= b_j + s, enforced by projection after each step. Under load control
!> the uniform mode of u has no stiffness and the mean pressure p_m pushes the surface
!> against the wall: p = K u + p_m. The wall carries lambda = max(p, 0) where u touches it;
!> the unbalanced pressure rho = p - lambda drives the motion,
!>    m d2u/dt2 = -rho,
!> with one mass m for every node, the largest stiffness of a mode, so that the stiffest
!> mode has unit frequency; FIRE's damped semi-implicit Euler steps integrate it. A mass
!> per mode equal to its stiffness (all modes at one frequency) is not used: with the
!> wall's projection in real space it makes FIRE's step collapse (docs/decisions).
!>
!> Convergence is judged, as for the other solvers, on the complementarity residual of the
!> pressure the wall carries (p = lambda, w = G_eff p, gap = w - b - s), not on an energy.
!> A step costs one transform pair, a check one more.
!>
!> The stiffness 1/G_eff of a coupled scene has a phase on each mode: the friction (or the
!> loss of a sliding viscoelastic layer) makes it a follower force, and FIRE's damping
!> relaxes the dynamics only while |Im G_eff|/Re G_eff stays small. gfmd_refusal measures
!> that ratio on the operator before any step and refuses the scenes beyond the measured
!> limit max_stiffness_phase (docs/decisions/001-gfmd-masses.md), naming the methods that
!> solve them.
module lc_contact_solver_gfmd
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_contact_residual, only: complementarity_residual, rounding_floor
   use lc_contact_progress, only: progress_log
   use lc_base_errors, only: error_type
   use lc_base_strings, only: formatted
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   implicit none (type, external)
   private
   public :: gfmd, gfmd_outcome, gfmd_solver, gfmd_refusal

   !> FIRE's parameters (Bitzek et al.): steps with positive power before the step grows,
   !> growth and shrink factors of the step, the initial and the decay of the mixing.
   integer, parameter :: fire_min_steps = 5
   real(wp), parameter :: fire_grow = 1.1_wp, fire_shrink = 0.5_wp
   real(wp), parameter :: fire_alpha0 = 0.1_wp, fire_alpha_decay = 0.99_wp
   !> Time step and its largest value, in units of 1/omega_max (the stiffest mode): the
   !> semi-implicit Euler step is stable below 2.
   real(wp), parameter :: dt_start = 0.25_wp, dt_max = 1.0_wp
   !> Steps between two convergence checks (a check costs one transform pair).
   integer, parameter :: check_interval = 10
   !> The largest |Im G_eff|/Re G_eff over the modes that the dynamics is given: measured
   !> between the scenes that relax (ratio up to 0.47) and those that creep, stall or grow
   !> (from 0.61) (docs/decisions/001-gfmd-masses.md).
   real(wp), parameter :: max_stiffness_phase = 0.5_wp

   !> What one GFMD solve did.
   type :: gfmd_outcome
      logical :: converged = .false.
      integer :: iterations = 0      !< time steps
      integer :: checks = 0          !< convergence checks (the entries of the history)
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type gfmd_outcome


   !> Method 'gfmd': damped dynamics of the normal displacement.
   type, extends(contact_solver) :: gfmd_solver
   contains
      procedure :: solve => solve_by_gfmd
      procedure :: name => gfmd_name
   end type gfmd_solver

contains

   !> Solve the contact problem w = G_eff p, gap = w - b - s >= 0, p >= 0, p gap = 0 (load
   !> control: mean(p) = p_m, s found; displacement control: s given). p: starting guess in,
   !> solution out (the best checked state if not converged); w = G_eff p; gap.
   !> history(k) receives the residual of the k-th check (every check_interval steps) when
   !> present.
   subroutine gfmd(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, history, progress)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure
      real(wp), intent(inout) :: s
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(gfmd_outcome), intent(out) :: outcome
      real(wp), intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      real(wp), allocatable :: u(:), v(:), a(:), rho(:), lambda(:), p_best(:)
      real(wp), pointer, contiguous :: buffer(:)
      real(wp) :: dt, alpha, power, v_norm, a_norm, s_best, uniform, b_max, mass, residual
      integer :: step, since_negative, checks, n, j

      n = size(p)
      call op%prepare_gcr()   ! the stiffness 1/G_eff
      buffer => op%buffer()
      allocate (u(n), v(n), a(n), rho(n), lambda(n))
      b_max = maxval(abs(b))
      uniform = merge(mean_pressure, 0.0_wp, load_control)
      mass = maxval(abs(op%inverse_full))
      ! start from the displacement of the guess; under load control the wall is placed
      ! where it touches the highest point of the gap, and the load moves the surface
      p = max(p, 0.0_wp)
      call op%apply_full(p, u)
      if (load_control) s = minval(u - b)
      u = max(u, b + s)
      v = 0.0_wp
      dt = dt_start
      alpha = fire_alpha0
      since_negative = 0
      checks = 0
      p_best = p
      s_best = s

      do step = 1, max_iter
         ! the layer's reaction p = K u (+ p_m), what the wall carries and what is left
         buffer = u
         call op%inverse_full_in_buffer()
         outcome%fft_pairs = outcome%fft_pairs + 1
         !$omp simd
         do j = 1, n
            lambda(j) = merge(max(buffer(j) + uniform, 0.0_wp), 0.0_wp, u(j) <= b(j) + s)
            rho(j) = buffer(j) + uniform - lambda(j)
            a(j) = -rho(j)/mass
         end do
         ! FIRE: mix the velocity towards the force, grow the step while the power is
         ! positive, stop and shrink it when it turns negative
         power = dot_product(v, a)
         if (power > 0.0_wp) then
            v_norm = norm2(v)
            a_norm = norm2(a)
            if (a_norm > 0.0_wp) v = (1.0_wp - alpha)*v + (alpha*v_norm/a_norm)*a
            since_negative = since_negative + 1
            if (since_negative > fire_min_steps) then
               dt = min(dt*fire_grow, dt_max)
               alpha = alpha*fire_alpha_decay
            end if
         else
            v = 0.0_wp
            dt = dt*fire_shrink
            alpha = fire_alpha0
            since_negative = 0
         end if
         ! the step, and the hard wall
         !$omp simd
         do j = 1, n
            v(j) = v(j) + dt*a(j)
            u(j) = u(j) + dt*v(j)
            if (u(j) < b(j) + s) then
               u(j) = b(j) + s
               v(j) = max(v(j), 0.0_wp)
            end if
         end do
         outcome%iterations = step

         if (mod(step, check_interval) == 0 .or. step == max_iter .or. .not. ieee_is_finite(power)) then
            call check(lambda, residual)
            checks = checks + 1
            if (present(history)) then
               if (checks <= size(history)) history(checks) = residual
            end if
            if (present(progress)) then
               if (progress%enabled) call progress%tick(step, residual, count(lambda > 0.0_wp)/real(n, wp))
            end if
            if (residual < outcome%residual) then
               outcome%residual = residual
               p_best = lambda
               s_best = s
            end if
            ! (a dynamics that blew up cannot recover)
            if (residual <= tol .or. .not. ieee_is_finite(power)) exit
         end if
      end do
      outcome%converged = outcome%residual <= tol
      outcome%checks = checks
      p = p_best
      s = s_best
      call op%apply_full(p, w)
      outcome%fft_pairs = outcome%fft_pairs + 1
      if (load_control) call contact_shift(p, w, b, s)
      gap = w - b - s
   contains
      !> The residual of the pressure the wall carries: w = G_eff lambda, s of the contact set.
      subroutine check(pressure, res)
         real(wp), intent(in) :: pressure(:)
         real(wp), intent(out) :: res
         real(wp) :: shift, p_ref
         call op%apply_full(pressure, w)
         outcome%fft_pairs = outcome%fft_pairs + 1
         shift = s
         if (load_control) call contact_shift(pressure, w, b, shift)
         gap = w - b - shift
         p_ref = merge(mean_pressure, sum(pressure)/n, load_control)
         res = complementarity_residual(pressure, gap, p_ref, g_ref, &
            & rounding_floor(maxval(abs(w)), b_max, maxval(pressure), op%largest))
         ! the load the wall carries must be the given one
         if (load_control) res = max(res, abs(sum(pressure)/n - mean_pressure)/mean_pressure)
      end subroutine check
   end subroutine gfmd

   !> Why the damped dynamics cannot relax the scene of `op` ('' if it can): the ratio
   !> |Im G_eff|/Re G_eff of some mode exceeds max_stiffness_phase.
   function gfmd_refusal(op) result(refusal)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: refusal
      real(wp) :: ratio
      refusal = ''
      if (.not. op%coupled) return
      ratio = stiffness_phase(op%full)
      if (ratio <= max_stiffness_phase) return
      if (ratio < huge(1.0_wp)) then
         refusal = 'its stiffness 1/G_eff is far from symmetric, |Im G_eff|/Re G_eff reaches ' // &
            & formatted(ratio, '(g0.3)') // ' on a mode'
      else
         refusal = 'its stiffness 1/G_eff is far from symmetric, Re G_eff <= 0 on a mode'
      end if
      refusal = refusal // ' (the friction or the loss acts as a follower force; the damped dynamics relaxes up to ' // &
         & formatted(max_stiffness_phase, '(g0.2)') // ')'
   end function gfmd_refusal

   !> The largest |Im g|/Re g over the multipliers g /= 0 (huge where Re g <= 0).
   pure real(wp) function stiffness_phase(g) result(ratio)
      complex(wp), intent(in) :: g(:)
      integer :: i
      ratio = 0.0_wp
      do i = 1, size(g)
         if (g(i) == (0.0_wp, 0.0_wp)) cycle
         if (real(g(i), wp) <= 0.0_wp) then
            ratio = huge(1.0_wp)
            return
         end if
         ratio = max(ratio, abs(aimag(g(i)))/real(g(i), wp))
      end do
   end function stiffness_phase

   !> s = the mean of w - b over the contact set (p > 0): the wall position the contact
   !> points agree on (unchanged without contact).
   pure subroutine contact_shift(p, w, b, s)
      real(wp), intent(in) :: p(:), w(:), b(:)
      real(wp), intent(inout) :: s
      integer :: contact
      contact = count(p > 0.0_wp)
      if (contact > 0) s = sum(w - b, mask=p > 0.0_wp)/contact
   end subroutine contact_shift
   subroutine solve_by_gfmd(self, problem, state, budget, outcome, progress, error)
      class(gfmd_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(gfmd_outcome) :: dynamics
      real(wp), allocatable :: history(:)
      allocate (history(budget))
      call gfmd(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
         & problem%tol, budget, state%p, state%w, state%gap, dynamics, history, progress)
      outcome = solve_outcome(converged=dynamics%converged, iterations=dynamics%iterations, outer_iterations=0, &
         & fft_pairs=dynamics%fft_pairs, residual=dynamics%residual, &
         & history=history(1:min(dynamics%checks, size(history))))
   end subroutine solve_by_gfmd

   pure function gfmd_name(self) result(name)
      class(gfmd_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'gfmd'
   end function gfmd_name

end module lc_contact_solver_gfmd
