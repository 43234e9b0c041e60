!> Coupled (non-symmetric) contact problem G_eff = M + N, N = G_eff - M (lc_contact_operator):
!>    find p >= 0, gap = G_eff p - r - s >= 0, p gap = 0 (+ load or displacement control).
!>
!> Outer fixed point x -> T(x): T(x) solves the symmetric problem with metric M and target
!> b = r - N x (constrained CG, warm-started); its fixed point solves the coupled problem.
!> The outer iteration is accelerated with Anderson mixing (Walker & Ni, SIAM J. Numer.
!> Anal. 49 (2011) 1715), which for the linearised map behaves like GMRES: with
!> M = |G_eff| the map's eigenvalues lie on the right half of the unit circle, so the rate
!> does not degrade with the strength of the coupling.
!>
!> Convergence is judged on the complementarity residual of the full coupled problem at
!> T's output (which is always feasible: p >= 0 and the load is exact). A run that stops
!> without converging returns its best iterate (the smallest residual).
!>
!> On an operator on a slab of a surface shared among the ranks (docs/decisions/023-mpi-slabs.md)
!> the fields and the history are this rank's rows: the inner products, the Gram matrix's
!> row and the projections are summed over the ranks (one message an iteration), so every
!> rank solves the same small least-squares problem and mixes its rows with the same gamma.
module lc_contact_solver_anderson
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_base_parallel, only: global_sum, global_max, sum_over_ranks
   use lc_contact_operator, only: compliance_operator
   use lc_contact_solver_cg, only: constrained_cg, cg_outcome
   use lc_contact_residual, only: complementarity_residual, rounding_floor
   use lc_contact_progress, only: progress_log
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   implicit none (type, external)
   private
   public :: anderson_coupled, anderson_outcome, anderson_solver
   !> the mixing's passes and small least-squares problem (also for lc_contact_solver_gfmd)
   public :: least_squares, history_products, mix

   !> Rows per block of the sweeps over the history (a few columns' blocks fit in L1/L2).
   integer, parameter :: block_rows = 2048
   !> On stagnation the history grows by factors of two up to this factor of &solver memory.
   integer, parameter :: max_memory_factor = 4
   !> A mixing step shorter than this (relative to max|x|) is a plateau (see below).
   real(wp), parameter :: plateau_step = 1.0e-12_wp

   !> What one coupled solve did.
   type :: anderson_outcome
      logical :: converged = .false.
      integer :: outer_iterations = 0
      integer :: cg_iterations = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type anderson_outcome

   interface
      subroutine dgelsd(m, n, nrhs, a, lda, b, ldb, s, rcond, rank, work, lwork, iwork, info)
         import :: wp
         integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
         real(wp), intent(inout) :: a(lda, *), b(ldb, *)
         real(wp), intent(out) :: s(*), work(*)
         real(wp), intent(in) :: rcond
         integer, intent(out) :: rank, iwork(*), info
      end subroutine dgelsd
   end interface


   !> Method 'anderson': the Anderson outer iteration around the constrained CG on the metric.
   type, extends(contact_solver) :: anderson_solver
   contains
      procedure :: solve => solve_by_anderson
      procedure :: name => anderson_name
   end type anderson_solver

contains

   !> Solve the coupled problem. p: starting guess in, solution out; w = G_eff p;
   !> gap and s as in lc_contact_solver_cg. history(k) = residual after outer iteration k.
   subroutine anderson_coupled(op, r, load_control, mean_pressure, s, g_ref, tol, max_iter, memory, &
         & precondition, p, w, gap, outcome, history, error, progress)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: r(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref, tol
      real(wp), intent(inout) :: s
      integer, intent(in) :: max_iter   !< budget of inner CG iterations
      integer, intent(in) :: memory
      logical, intent(in) :: precondition   !< passed to the inner constrained CG
      real(wp), intent(inout) :: p(:)
      real(wp), intent(out) :: w(:), gap(:)
      type(anderson_outcome), intent(out) :: outcome
      real(wp), intent(inout) :: history(:)
      type(error_type), allocatable, intent(out) :: error
      type(progress_log), intent(inout), optional :: progress
      real(wp), allocatable :: x(:), f(:), x_old(:), f_old(:), tx(:), dx(:, :), df(:, :), b(:), nw(:), p_best(:)
      real(wp), allocatable :: gamma(:), gram(:, :), projection(:), products(:)
      type(cg_outcome) :: inner
      real(wp) :: inner_tol, s_full, s_inner, best, best_residual
      integer :: n, k, columns, newest, j, last_progress, depth
      logical :: preconditioned, across_ranks
      real(wp) :: points

      across_ranks = op%distributed
      n = size(p)
      points = n
      if (across_ranks) points = global_sum(points)
      allocate (x(n), f(n), x_old(n), f_old(n), tx(n), b(n), nw(n), dx(n, memory), df(n, memory), p_best(n))
      allocate (gamma(memory), gram(memory, memory), projection(memory))
      depth = memory   ! the history kept now (grows on stagnation)
      x = p
      columns = 0
      newest = 0
      inner_tol = max(0.1_wp*tol, 1.0e-4_wp)
      s_inner = s
      s_full = s
      best = huge(1.0_wp)
      best_residual = huge(1.0_wp)
      p_best = p
      last_progress = 0
      preconditioned = precondition

      do k = 1, size(history)
         call op%apply_difference(x, nw)
         b = r - nw
         tx = p   ! warm start from the previous output of T
         if (present(progress)) progress%offset = outcome%cg_iterations
         call constrained_cg(op, b, load_control, mean_pressure, s_inner, g_ref, inner_tol, &
            & max_iter - outcome%cg_iterations, preconditioned, tx, w, gap, inner, progress=progress)
         if (present(progress)) progress%offset = 0
         ! once the preconditioner has stalled on this operator, do not try it again
         preconditioned = inner%preconditioned
         outcome%cg_iterations = outcome%cg_iterations + inner%iterations
         outcome%fft_pairs = outcome%fft_pairs + inner%fft_pairs + 2
         outcome%outer_iterations = k
         p = tx

         call coupled_state(op, r, load_control, mean_pressure, s, g_ref, p, w, gap, s_full, outcome%residual)
         history(k) = outcome%residual
         if (present(progress)) then
            if (progress%enabled) call progress%tick(outcome%cg_iterations, outcome%residual, &
               & contact_count(p, across_ranks)/points)
         end if
         if (outcome%residual <= tol) then
            outcome%converged = .true.
            s = s_full
            return
         end if
         if (outcome%residual < best_residual) then
            best_residual = outcome%residual
            p_best = p
         end if
         if (outcome%cg_iterations >= max_iter) exit
         ! Stagnation (thin layers with friction, h/lambda <= 1e-3, where G_eff is nearly
         ! skew, so that the map's eigenvalues crowd towards +-i): restart the mixing with
         ! twice the memory, up to max_memory_factor times the given one; then stop and
         ! report (docs/numerics.md, 'Constants of the solvers and their measurements').
         if (outcome%residual < 0.5_wp*best) then
            best = outcome%residual
            last_progress = k
         else if (k - last_progress > 4*memory) then
            if (depth >= max_memory_factor*memory) exit
            depth = min(2*depth, max_memory_factor*memory)
            call grow_history(dx, df, gram, gamma, projection, depth)
            last_progress = k
            columns = 0
            newest = 0
         end if
         ! Inner solves only need to be a little more accurate than the outer iterate.
         inner_tol = max(0.1_wp*tol, min(1.0e-4_wp, 0.01_wp*outcome%residual))

         ! Anderson mixing on f = T(x) - x: the new history column (one pass), the Gram
         ! matrix's new row and the projections DF^T f (one sweep over the history), the
         ! mixed x (another); the passes over the history are what an outer iteration costs
         ! besides the inner solve.
         if (k > 1) then
            newest = mod(newest, depth) + 1
            columns = min(columns + 1, depth)
         end if
         !$omp simd
         do j = 1, n
            f(j) = tx(j) - x(j)
         end do
         if (k > 1) then
            !$omp simd
            do j = 1, n
               dx(j, newest) = x(j) - x_old(j)
               df(j, newest) = f(j) - f_old(j)
            end do
         end if
         x_old = x
         f_old = f
         if (columns == 0) then
            x = tx
         else
            call history_products(df(:, 1:columns), newest, f, gram(1:columns, newest), projection(1:columns))
            if (across_ranks) then
               products = [gram(1:columns, newest), projection(1:columns)]
               call sum_over_ranks(products)
               gram(1:columns, newest) = products(1:columns)
               projection(1:columns) = products(columns + 1:)
            end if
            gram(newest, 1:columns) = gram(1:columns, newest)
            call least_squares(gram(1:columns, 1:columns), projection(1:columns), gamma(1:columns), error)
            if (allocated(error)) return
            call mix(tx, dx(:, 1:columns), df(:, 1:columns), gamma(1:columns), x)
            ! A plateau: the inner solve accepted its warm start (T(x) within inner_tol of
            ! the previous output) and the mixing returns the x it was given; it would do so
            ! forever. Restart it from a plain step x = T(x), whose inner problem is the
            ! coupled one at the current p.
            if (largest(abs(x - x_old), across_ranks) <= plateau_step*largest(abs(x_old), across_ranks)) then
               columns = 0
               newest = 0
               x = tx
            end if
         end if
      end do
      ! not converged: return the best iterate (the mixing may have wandered off it)
      if (best_residual < outcome%residual) then
         p = p_best
         call coupled_state(op, r, load_control, mean_pressure, s, g_ref, p, w, gap, s_full, outcome%residual)
      end if
      s = s_full
   end subroutine anderson_coupled

   !> The coupled problem's state at p: w = G_eff p, the constant s_full (found under load
   !> control, `s` otherwise), gap and the complementarity residual.
   subroutine coupled_state(op, r, load_control, mean_pressure, s, g_ref, p, w, gap, s_full, residual)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: r(:), mean_pressure, s, g_ref, p(:)
      logical, intent(in) :: load_control
      real(wp), intent(out) :: w(:), gap(:), s_full, residual
      real(wp) :: p_ref, points
      logical :: across_ranks
      across_ranks = op%distributed
      call op%apply_full(p, w)
      gap = w - r
      if (load_control) then
         s_full = total(sum(gap, mask=p > 0.0_wp), across_ranks)/max(contact_count(p, across_ranks), 1)
      else
         s_full = s
      end if
      gap = gap - s_full
      points = total(real(size(p), wp), across_ranks)
      p_ref = merge(mean_pressure, total(sum(p), across_ranks)/points, load_control)
      residual = largest([complementarity_residual(p, gap, p_ref, g_ref, rounding_floor(largest(abs(w), across_ranks), &
         & largest(abs(r), across_ranks), largest(p, across_ranks), op%largest))], across_ranks)
   end subroutine coupled_state

   !> The contact points (p > 0) of p, over the ranks where `across_ranks`.
   integer function contact_count(p, across_ranks) result(points)
      real(wp), intent(in) :: p(:)
      logical, intent(in) :: across_ranks
      points = count(p > 0.0_wp)
      if (across_ranks) points = global_sum(points)
   end function contact_count

   !> x summed over the ranks where `across_ranks`.
   real(wp) function total(x, across_ranks)
      real(wp), intent(in) :: x
      logical, intent(in) :: across_ranks
      total = x
      if (across_ranks) total = global_sum(x)
   end function total

   !> The largest value of x, over the ranks where `across_ranks`.
   real(wp) function largest(x, across_ranks)
      real(wp), intent(in) :: x(:)
      logical, intent(in) :: across_ranks
      largest = maxval(x)
      if (across_ranks) largest = global_max(largest)
   end function largest

   !> Room for `depth` history columns (the contents are dropped: the mixing restarts).
   subroutine grow_history(dx, df, gram, gamma, projection, depth)
      real(wp), allocatable, intent(inout) :: dx(:, :), df(:, :), gram(:, :), gamma(:), projection(:)
      integer, intent(in) :: depth
      integer :: n
      n = size(dx, 1)
      deallocate (dx, df, gram, gamma, projection)
      allocate (dx(n, depth), df(n, depth), gram(depth, depth), gamma(depth), projection(depth))
   end subroutine grow_history

   !> gamma = argmin || f - DF gamma ||_2 from the normal equations: gram = DF^T DF and
   !> projection = DF^T f. The columns are scaled to unit norm and the small system solved
   !> by SVD (dgelsd), dropping directions below 1e-12 of the largest singular value of the
   !> scaled Gram matrix (1e-6 of DF's: the mixing only needs a few digits of gamma). The
   !> Gram matrix is updated by one row per iteration, so the cost is two passes over the
   !> history per iteration instead of a dense least-squares problem of n rows (which on
   !> top ran threaded in OpenBLAS, busy-waiting on the other core).
   subroutine least_squares(gram, projection, gamma, error)
      real(wp), intent(in) :: gram(:, :), projection(:)
      real(wp), intent(out) :: gamma(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: a(:, :), rhs(:, :), sv(:), work(:), scale(:)
      integer, allocatable :: iwork(:)
      real(wp) :: query(1)
      integer :: ncol, rank, info, lwork, iquery(1), i

      ncol = size(gram, 1)
      allocate (a(ncol, ncol), rhs(ncol, 1), sv(ncol), scale(ncol))
      do i = 1, ncol
         scale(i) = sqrt(gram(i, i))
         if (.not. scale(i) > 0.0_wp) scale(i) = 1.0_wp   ! a zero column: gamma(i) = 0
      end do
      do i = 1, ncol
         a(:, i) = gram(:, i)/(scale*scale(i))
      end do
      rhs(:, 1) = projection/scale
      call dgelsd(ncol, ncol, 1, a, ncol, rhs, ncol, sv, 1.0e-12_wp, rank, query, -1, iquery, info)
      lwork = int(query(1))
      allocate (work(lwork), iwork(max(1, iquery(1))))
      call dgelsd(ncol, ncol, 1, a, ncol, rhs, ncol, sv, 1.0e-12_wp, rank, work, lwork, iwork, info)
      if (info /= 0) then
         call fatal_error(error, 'anderson: LAPACK dgelsd failed in the mixing step', code_internal)
         return
      end if
      gamma = rhs(:, 1)/scale
   end subroutine least_squares

   !> gram_column(j) = df(:, j) . df(:, newest) and projection(j) = df(:, j) . f for every
   !> column j, in one sweep over df by blocks of rows (df(:, newest) and f stay in cache).
   pure subroutine history_products(df, newest, f, gram_column, projection)
      real(wp), intent(in) :: df(:, :), f(:)
      integer, intent(in) :: newest
      real(wp), intent(out) :: gram_column(:), projection(:)
      real(wp) :: g, q
      integer :: i, i0, i1, j, n
      n = size(df, 1)
      gram_column = 0.0_wp
      projection = 0.0_wp
      do i0 = 1, n, block_rows
         i1 = min(n, i0 + block_rows - 1)
         do j = 1, size(df, 2)
            g = 0.0_wp
            q = 0.0_wp
            !$omp simd reduction(+:g, q)
            do i = i0, i1
               g = g + df(i, j)*df(i, newest)
               q = q + df(i, j)*f(i)
            end do
            gram_column(j) = gram_column(j) + g
            projection(j) = projection(j) + q
         end do
      end do
   end subroutine history_products

   !> x = tx - sum_j gamma_j (dx_j + df_j), by blocks of rows (x stays in cache).
   pure subroutine mix(tx, dx, df, gamma, x)
      real(wp), intent(in) :: tx(:), dx(:, :), df(:, :), gamma(:)
      real(wp), intent(out) :: x(:)
      integer :: i, i0, i1, j
      do i0 = 1, size(x), block_rows
         i1 = min(size(x), i0 + block_rows - 1)
         x(i0:i1) = tx(i0:i1)
         do j = 1, size(gamma)
            !$omp simd
            do i = i0, i1
               x(i) = x(i) - gamma(j)*(dx(i, j) + df(i, j))
            end do
         end do
      end do
   end subroutine mix
   subroutine solve_by_anderson(self, problem, state, budget, outcome, progress, error)
      class(anderson_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(anderson_outcome) :: outer
      real(wp), allocatable :: history(:)
      allocate (history(budget))
      call anderson_coupled(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, &
         & problem%g_ref, problem%tol, budget, problem%memory, problem%precondition, state%p, state%w, state%gap, &
         & outer, history, error, progress)
      if (allocated(error)) return
      outcome = solve_outcome(converged=outer%converged, iterations=outer%cg_iterations, &
         & outer_iterations=outer%outer_iterations, fft_pairs=outer%fft_pairs, residual=outer%residual, &
         & history=history(1:outer%outer_iterations))
   end subroutine solve_by_anderson

   pure function anderson_name(self) result(name)
      class(anderson_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'anderson'
   end function anderson_name

end module lc_contact_solver_anderson
