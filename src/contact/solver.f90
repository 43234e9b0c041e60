!> The extension point of the solver layer: a contact solver is a type extending
!> `contact_solver` with its `solve`; lc_contact_registry makes one from its method name.
!> A method that may end worse than it started (it returns its last iterate, not its best
!> including the start) says so with `ends_no_worse`, so that a solve which goes on
!> from another method's iterate keeps the better of the two (lc_contact_stages).
module lc_contact_solver
   use lc_base_errors, only: error_type
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_progress, only: progress_log
   implicit none (type, external)
   private
   public :: contact_solver

   type, abstract :: contact_solver
   contains
      procedure(solve_interface), deferred :: solve
      procedure(name_interface), deferred :: name
      procedure :: step_limit
      procedure :: ends_no_worse
   end type contact_solver

   abstract interface
      !> Solve `problem` from `state` with at most `budget` iterations: `state` holds the
      !> solution (or the best iterate) on exit, `outcome` what was done (its `path` is set
      !> by the caller).
      subroutine solve_interface(self, problem, state, budget, outcome, progress, error)
         import :: contact_solver, contact_problem, contact_state, solve_outcome, progress_log, error_type
         class(contact_solver), intent(inout) :: self
         type(contact_problem), intent(in) :: problem
         type(contact_state), intent(inout) :: state
         integer, intent(in) :: budget
         type(solve_outcome), intent(out) :: outcome
         type(progress_log), intent(inout) :: progress
         type(error_type), allocatable, intent(out) :: error
      end subroutine solve_interface

      !> The method's name in the outcome's path and in messages.
      pure function name_interface(self) result(name)
         import :: contact_solver
         class(contact_solver), intent(in) :: self
         character(len=:), allocatable :: name
      end function name_interface
   end interface

contains

   !> Iterations the method needs at most whatever the budget (its steps being costly): a
   !> method with a limit of its own that finishes another's solve is left part of the
   !> budget by the methods before it (lc_contact_stages).
   pure integer function step_limit(self)
      class(contact_solver), intent(in) :: self
      step_limit = huge(1)
   end function step_limit

   !> Whether the state returned is never worse than the one given (the best iterate,
   !> the start included).
   pure logical function ends_no_worse(self)
      class(contact_solver), intent(in) :: self
      ends_no_worse = .false.
   end function ends_no_worse

end module lc_contact_solver
