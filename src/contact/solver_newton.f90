!> Dense semismooth Newton method for small grids: the direct method behind the iterative
!> solvers. It solves the same collocation problem,
!>    p >= 0, gap = G p - b - s >= 0, p gap = 0,
!> under load control (mean(p) = p_m given, s found) or displacement control (s given),
!> for any operator G_eff, symmetric or not, with the Fischer-Burmeister function
!>    phi(a, b) = sqrt(a^2 + b^2) - a - b,  a = p/p_scale, b = gap/g_ref,
!> which vanishes iff a >= 0, b >= 0, a b = 0 (De Luca, Facchinei and Kanzow, "A
!> semismooth equation approach to the solution of nonlinear complementarity problems").
!> Each step solves the (n+1) x (n+1) Newton system with LAPACK (LU with partial
!> pivoting) and takes an Armijo step on |Phi|^2; the gap is linear in (p, s), so a trial
!> step costs no product with G. For a monotone operator (Re G_eff >= 0) the solution is
!> unique and the merit |Phi|^2 has no stationary point but the solution, so the damped
!> iteration does not get stuck on the way (every monotone run of the test grids converges);
!> near the solution it converges quadratically.
!>
!> The cost is that of the factorisation, ~(2/3) n^3 per step, and 2 n^2 doubles: it is
!> for grids where the iterative solvers stall (glassy viscoelastic layers near full
!> contact, thin incompressible layers with strong friction on a few points; see
!> docs/numerics.md), not a general solver.
module lc_contact_solver_newton
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_contact_residual, only: complementarity_residual, rounding_floor
   use lc_contact_progress, only: progress_log
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   implicit none (type, external)
   private
   public :: dense_newton, newton_outcome, dense_points, newton_step_limit, newton_solver

   !> Largest grid (points) the method is used on: the matrices take 2 n^2 doubles and a step
   !> ~(2/3) n^3 flops (docs/decisions/005-broadband-iterations.md, 'Small grids: a dense
   !> Newton method behind the iterative solvers'; docs/numerics.md, 'Constants of the
   !> solvers and their measurements').
   integer, parameter :: dense_points = 2048
   !> Newton steps at most when the method finishes a stalled iterative solve (the budget
   !> left permitting). A monotone problem converges from any start, but a glassy layer near
   !> full contact takes hundreds of steps: the Armijo steps stay short while many points
   !> change sides (docs/numerics.md, 'Constants of the solvers and their measurements').
   integer, parameter :: newton_step_limit = 400
   !> Smallest Armijo step tried before the iteration gives up.
   real(wp), parameter :: smallest_step = 1.0e-12_wp

   !> What one dense Newton solve did.
   type :: newton_outcome
      logical :: converged = .false.
      integer :: steps = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type newton_outcome

   interface
      !> LAPACK: solve A X = B by LU with partial pivoting (real double).
      subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: wp
         integer, intent(in) :: n, nrhs, lda, ldb
         real(wp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgesv
   end interface


   !> Method 'newton': the dense semismooth Newton method, on grids of at most dense_points.
   type, extends(contact_solver) :: newton_solver
   contains
      procedure :: solve => solve_by_newton
      procedure :: name => newton_name
      procedure :: step_limit => newton_steps
   end type newton_solver

contains

   !> Solve from the guess (p, s) (any p; it is clipped at zero and, under load control,
   !> scaled to the load). On exit p >= 0, w = G p, gap = w - b - s. `progress` (optional)
   !> hears of every step; steps count on from its offset (the iterations before).
   subroutine dense_newton(op, b, load_control, mean_pressure, s, g_ref, tol, budget, p, w, gap, outcome, progress)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref, tol
      integer, intent(in) :: budget   !< Newton steps at most
      real(wp), intent(inout) :: s, p(:)
      real(wp), intent(out) :: w(:), gap(:)
      type(newton_outcome), intent(out) :: outcome
      type(progress_log), intent(inout), optional :: progress
      real(wp), allocatable :: g(:, :), jacobian(:, :), phi(:), step(:), dgap(:), a_grad(:), b_grad(:)
      real(wp), allocatable :: p_trial(:), gap_trial(:), phi_trial(:)
      integer, allocatable :: pivots(:)
      real(wp) :: p_scale, merit, t, s_step, floor, shift
      integer :: n, m, j, info, step_count, max_steps

      n = size(p)
      m = merge(n + 1, n, load_control)
      max_steps = budget
      allocate (g(n, n), jacobian(m, m), phi(m), step(m), dgap(n), a_grad(n), b_grad(n))
      allocate (p_trial(n), gap_trial(n), phi_trial(m), pivots(m))
      call dense_operator(op, g)
      outcome%fft_pairs = 1

      p = max(p, 0.0_wp)
      if (load_control) then
         if (sum(p) > 0.0_wp) then
            p = p*(mean_pressure*n/sum(p))
         else
            p = mean_pressure
         end if
         p_scale = mean_pressure
      else
         ! any fixed positive scale of the pressure will do for the equations (here the
         ! larger of the start's mean and the pressure that closes a gap g_ref at one
         ! point); the stopping rule is the library's (p_ref = the current mean pressure)
         p_scale = max(sum(p)/n, g_ref/max(maxval(abs(g)), tiny(1.0_wp)))
      end if
      gap = matmul(g, p) - b - s
      if (load_control) then
         ! a start with the gap's mean at zero
         shift = sum(gap)/n
         s = s + shift
         gap = gap - shift
      end if

      do step_count = 0, max_steps
         outcome%steps = step_count
         outcome%residual = library_residual(p, gap)
         if (present(progress)) call progress%tick(step_count, outcome%residual, count(p > 0.0_wp)/real(n, wp))
         if (outcome%residual <= tol) exit
         if (step_count == max_steps) exit
         call fischer_burmeister(p, gap, phi, a_grad, b_grad)
         merit = dot_product(phi, phi)
         ! Newton system: d phi_j = a_grad_j dp_j/p_scale + b_grad_j (G dp - ds)_j/g_ref
         ! (b_grad divided by g_ref once, below);
         ! load control adds the row mean(dp)/p_scale = -(mean(p)/p_scale - 1)
         b_grad = b_grad/g_ref
         do j = 1, n
            jacobian(1:n, j) = b_grad*g(:, j)
            jacobian(j, j) = jacobian(j, j) + a_grad(j)/p_scale
         end do
         if (load_control) then
            jacobian(1:n, m) = -b_grad
            jacobian(m, 1:n) = 1.0_wp/(n*p_scale)
            jacobian(m, m) = 0.0_wp
         end if
         step = -phi
         call dgesv(m, 1, jacobian, m, pivots, step, m, info)
         if (info /= 0 .or. .not. all(ieee_is_finite(step))) exit
         s_step = 0.0_wp
         if (load_control) s_step = step(m)
         dgap = matmul(g, step(1:n)) - s_step
         t = 1.0_wp
         do while (t >= smallest_step)
            p_trial = p + t*step(1:n)
            gap_trial = gap + t*dgap
            call fischer_burmeister(p_trial, gap_trial, phi_trial)
            if (load_control) phi_trial(m) = sum(p_trial)/(n*p_scale) - 1.0_wp
            if (dot_product(phi_trial, phi_trial) <= (1.0_wp - 1.0e-4_wp*t)*merit) exit
            t = 0.5_wp*t
         end do
         if (t < smallest_step) exit
         p = p_trial
         s = s + t*s_step
         ! (recomputed rather than updated, so that rounding does not accumulate)
         gap = matmul(g, p) - b - s
      end do

      ! The fields returned. Where the gap is the larger of the pair the point is out of
      ! contact: its pressure, a Newton iterate's ~1e-20 p_m (or negative by rounding), is
      ! set to zero exactly, so that the contact set is {p > 0} as for the other solvers;
      ! w and the gap then from the operator as they compute them, and under load control
      ! s as the mean of w - b over that set.
      where (p/p_scale < gap/g_ref) p = 0.0_wp
      p = max(p, 0.0_wp)
      if (load_control .and. sum(p) > 0.0_wp) p = p*(mean_pressure*n/sum(p))
      call op%apply_full(p, w)
      outcome%fft_pairs = outcome%fft_pairs + 1
      if (load_control .and. count(p > 0.0_wp) > 0) s = sum(w - b, mask=p > 0.0_wp)/count(p > 0.0_wp)
      gap = w - b - s
      floor = rounding_floor(maxval(abs(w)), maxval(abs(b)), maxval(p), op%largest)
      outcome%residual = complementarity_residual(p, gap, reference_pressure(p), g_ref, floor)
      outcome%converged = outcome%residual <= tol

   contains

      !> phi (and, when asked, its generalised derivatives in a and b) at (p, gap); under
      !> load control phi(n+1) is the load equation. At a degenerate point (a = b = 0) the
      !> element (1/sqrt 2 - 1, 1/sqrt 2 - 1) of the generalised Jacobian is taken.
      subroutine fischer_burmeister(p, gap, phi, a_grad, b_grad)
         real(wp), intent(in) :: p(:), gap(:)
         real(wp), intent(out) :: phi(:)
         real(wp), intent(out), optional :: a_grad(:), b_grad(:)
         real(wp) :: a, bb, root
         integer :: j
         do j = 1, size(p)
            a = p(j)/p_scale
            bb = gap(j)/g_ref
            root = hypot(a, bb)
            phi(j) = root - a - bb
            if (present(a_grad)) then
               if (root > 0.0_wp) then
                  a_grad(j) = a/root - 1.0_wp
                  b_grad(j) = bb/root - 1.0_wp
               else
                  a_grad(j) = sqrt(0.5_wp) - 1.0_wp
                  b_grad(j) = sqrt(0.5_wp) - 1.0_wp
               end if
            end if
         end do
         if (size(phi) > size(p)) phi(size(phi)) = sum(p)/(size(p)*p_scale) - 1.0_wp
      end subroutine fischer_burmeister

      !> p_ref of the stopping rule: p_m under load control, the mean pressure otherwise.
      pure real(wp) function reference_pressure(p) result(p_ref)
         real(wp), intent(in) :: p(:)
         p_ref = merge(mean_pressure, sum(p)/size(p), load_control)
      end function reference_pressure

      !> The library's complementarity residual of the iterate, with negative pressures
      !> counted (p is not clipped during the iteration).
      real(wp) function library_residual(p, gap) result(res)
         real(wp), intent(in) :: p(:), gap(:)
         res = complementarity_residual(p, gap, reference_pressure(p), g_ref, &
            & rounding_floor(maxval(abs(gap + b + s)), maxval(abs(b)), maxval(p), op%largest))
         if (.not. ieee_is_finite(res)) res = huge(1.0_wp)
      end function library_residual
   end subroutine dense_newton

   !> The matrix of p -> G_eff p on the grid: the response to a unit load at the first
   !> point (one transform pair), shifted periodically along both axes (G is circulant).
   subroutine dense_operator(op, g)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(out) :: g(:, :)
      real(wp), allocatable :: unit(:), column(:)
      integer :: nx, ny, ix, iy, jx, jy, i, j
      nx = op%grid%nx
      ny = op%grid%ny
      allocate (unit(nx*ny), column(nx*ny))
      unit = 0.0_wp
      unit(1) = 1.0_wp
      call op%apply_full(unit, column)
      do jy = 0, ny - 1
         do jx = 0, nx - 1
            j = 1 + jx + nx*jy
            do iy = 0, ny - 1
               do ix = 0, nx - 1
                  i = 1 + ix + nx*iy
                  g(i, j) = column(1 + modulo(ix - jx, nx) + nx*modulo(iy - jy, ny))
               end do
            end do
         end do
      end do
   end subroutine dense_operator
   subroutine solve_by_newton(self, problem, state, budget, outcome, progress, error)
      class(newton_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(newton_outcome) :: newton
      if (problem%op%n > dense_points) then
         call fatal_error(error, "&solver: method = 'newton' (dense) needs a grid of at most " // &
            & to_string(dense_points) // ' points; this one has ' // to_string(problem%op%n), code_input)
         return
      end if
      call dense_newton(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
         & problem%tol, budget, state%p, state%w, state%gap, newton, progress)
      outcome = solve_outcome(converged=newton%converged, iterations=newton%steps, outer_iterations=0, &
         & fft_pairs=newton%fft_pairs, residual=newton%residual, history=[newton%residual])
   end subroutine solve_by_newton

   pure function newton_name(self) result(name)
      class(newton_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'newton'
   end function newton_name

   !> A step costs ~(2/3) n^3 flops: newton_step_limit at most.
   pure integer function newton_steps(self)
      class(newton_solver), intent(in) :: self
      newton_steps = newton_step_limit
   end function newton_steps

end module lc_contact_solver_newton
