!> A solve in stages: the methods of a plan (lc_contact_policy) in turn, each going on from
!> the last one's iterate while the solve has not converged and budget is left. Written
!> once for any pair of methods:
!>  - the first method has the whole budget (&solver max_iter); a later one what is left,
!>    less a reserve for a method after it with a step limit of its own (the dense Newton
!>    method: up to half of what is left);
!>  - where a method may end worse than it started (contact_solver%ends_no_worse), the
!>    better of its state and the one it started from is kept;
!>  - the outcome adds up the iterations and transform pairs, joins the residual histories,
!>    and names the path, e.g. 'gcr+kept+anderson'.
module lc_contact_stages
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   use lc_contact_registry, only: new_solver
   use lc_contact_progress, only: progress_log
   implicit none (type, external)
   private
   public :: solve_in_stages

contains

   !> Solve `problem` from `state` by the methods named in `stages`, in turn.
   subroutine solve_in_stages(stages, problem, state, outcome, progress, error)
      character(len=*), intent(in) :: stages(:)
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      class(contact_solver), allocatable :: solver
      type(solve_outcome) :: stage
      type(contact_state) :: start
      integer :: k, left, budget
      logical :: keep_better

      outcome%path = ''
      allocate (outcome%history(0))
      do k = 1, size(stages)
         if (k > 1 .and. (outcome%converged .or. outcome%iterations >= problem%max_iter)) exit
         call new_solver(trim(stages(k)), solver)
         if (.not. allocated(solver)) then
            call fatal_error(error, 'solve: no contact method is named ' // trim(stages(k)), code_internal)
            return
         end if
         left = problem%max_iter - outcome%iterations
         budget = left
         keep_better = .false.
         if (k > 1) then
            budget = min(left, solver%step_limit()) - reserve(stages(k + 1:), left)
            keep_better = .not. solver%ends_no_worse()
            if (keep_better) start = state
            progress%offset = outcome%iterations
         end if
         call solver%solve(problem, state, budget, stage, progress, error)
         progress%offset = 0
         if (allocated(error)) return
         if (k == 1) then
            outcome = stage
            outcome%path = solver%name()
            outcome%outer_iterations = max(1, stage%outer_iterations)
            cycle
         end if
         outcome%path = outcome%path // '+' // solver%name()
         if (allocated(stage%note)) then
            if (.not. allocated(outcome%note)) outcome%note = ''
            if (len(outcome%note) > 0 .and. len(stage%note) > 0) outcome%note = outcome%note // '; '
            outcome%note = outcome%note // stage%note
         end if
         outcome%iterations = outcome%iterations + stage%iterations
         outcome%outer_iterations = outcome%outer_iterations + stage%outer_iterations
         outcome%fft_pairs = outcome%fft_pairs + stage%fft_pairs
         outcome%history = [outcome%history, stage%history]
         if (.not. keep_better .or. stage%residual <= outcome%residual) then
            outcome%converged = stage%converged
            outcome%residual = stage%residual
         else
            call move_state(start, state)
         end if
      end do
   end subroutine solve_in_stages

   !> Iterations a later method with a step limit of its own is guaranteed: up to half of
   !> the `left` ones.
   integer function reserve(later, left)
      character(len=*), intent(in) :: later(:)
      integer, intent(in) :: left
      class(contact_solver), allocatable :: solver
      integer :: k
      reserve = 0
      do k = 1, size(later)
         call new_solver(trim(later(k)), solver)
         if (.not. allocated(solver)) cycle
         if (solver%step_limit() < huge(1)) reserve = reserve + min(solver%step_limit(), left/2)
      end do
   end function reserve

   !> state = start, moving its arrays.
   subroutine move_state(start, state)
      type(contact_state), intent(inout) :: start, state
      call move_alloc(start%p, state%p)
      call move_alloc(start%w, state%w)
      call move_alloc(start%gap, state%gap)
      state%s = start%s
   end subroutine move_state

end module lc_contact_stages
