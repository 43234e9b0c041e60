!> The contact methods by name: `&solver method` and the stages of a plan
!> (lc_contact_policy) name them. A new method is a type extending contact_solver in a
!> file of its own and one line here (and its name in the namelist's allowed list).
module lc_contact_registry
   use lc_contact_solver, only: contact_solver
   use lc_contact_solver_cg, only: cg_solver
   use lc_contact_solver_gcr, only: gcr_solver
   use lc_contact_solver_anderson, only: anderson_solver
   use lc_contact_solver_gfmd, only: gfmd_solver
   use lc_contact_solver_newton, only: newton_solver
   use lc_contact_solver_multigrid, only: multigrid_solver
   implicit none (type, external)
   private
   public :: new_solver

contains

   !> The solver of method `name` ('kept': the GCR keeping its history across clips);
   !> not allocated for an unknown name.
   subroutine new_solver(name, solver)
      character(len=*), intent(in) :: name
      class(contact_solver), allocatable, intent(out) :: solver
      select case (name)
      case ('cg');        allocate (cg_solver :: solver)
      case ('gcr');       allocate (gcr_solver :: solver)
      case ('kept');      allocate (solver, source=gcr_solver(keep_history=.true.))
      case ('anderson');  allocate (anderson_solver :: solver)
      case ('gfmd');      allocate (gfmd_solver :: solver)
      case ('newton');    allocate (newton_solver :: solver)
      case ('multigrid'); allocate (multigrid_solver :: solver)
      end select
   end subroutine new_solver

end module lc_contact_registry
