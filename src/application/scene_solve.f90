!> The solves of a scene and what is computed from them: the contact solve
!> (lc_contact_solve), the observables the scene asks for (lc_observables), the Reynolds
!> leakage of the gap (lc_leakage_reynolds), the conductance and interfacial stiffness
!> (lc_observables_conductance), and the frictionless companion. The
!> executable's run, the Python driver and the resolution pilot all solve through it.
module lc_application_scene_solve
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error
   use lc_scene, only: scene_type, grid_of, companion_of
   use lc_base_grid, only: grid_type
   use lc_leakage_reynolds, only: reynolds_leakage, leakage_max_iter
   use lc_result, only: contact_result
   use lc_contact_operator, only: compliance_operator
   use lc_contact_solve, only: solve_contact
   use lc_observables, only: observe
   use lc_observables_conductance, only: contact_conductance, contact_stiffness, masked_outcome
   implicit none (type, external)
   private
   public :: solve_scene, solve_runs

contains

   !> Solve `scene` on the profile `height` (flat, x fastest) with Coulomb coefficient
   !> `friction` (the scene's, or 0 for the frictionless companion) and compute its
   !> observables (with &output conductance, the conductance and stiffness too). A surface
   !> shared among MPI ranks (`height`: this rank's slab) is solved distributed and its
   !> observables computed on the slabs (lc_observables): every rank's result holds its rows
   !> of the fields and the scalars of the whole grid.
   subroutine solve_scene(scene, height, friction, result, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in), target :: height(:)
      real(wp), intent(in) :: friction
      type(contact_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(compliance_operator), allocatable, target :: op
      allocate (op)
      call solve_contact(scene, height, friction, result, op, error)
      if (allocated(error)) return
      call observe(scene, op, height, result)
      if (scene%conductance) call conductance_of(scene, op, result, error)
   end subroutine solve_scene

   !> The conductance and the normal interfacial stiffness at the solved contact set (p > 0),
   !> each to the scene's tolerance and within its budget of iterations.
   subroutine conductance_of(scene, op, result, error)
      type(scene_type), intent(in) :: scene
      type(compliance_operator), target, intent(inout) :: op
      type(contact_result), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      type(masked_outcome) :: conduction, stiffness
      logical, allocatable :: contact(:)
      real(wp) :: per_conductivity
      contact = result%pressure > 0.0_wp
      call contact_conductance(op%grid, contact, scene%thickness, scene%solver%tol, scene%solver%max_iter, &
         & scene%solver%threads, per_conductivity, conduction, error, op%distributed)
      if (allocated(error)) return
      result%conductance = scene%conductivity*per_conductivity
      call contact_stiffness(op, contact, scene%solver%tol, scene%solver%max_iter, result%contact_stiffness, stiffness)
      result%has_conductance = .true.
      result%conductance_converged = conduction%converged .and. stiffness%converged
      result%conductance_iterations = conduction%iterations
      result%stiffness_iterations = stiffness%iterations
   end subroutine conductance_of

   !> The runs the scene asks for: the scene with its Coulomb coefficient and, with
   !> &friction companion, its frictionless companion at the mean pressure the first found
   !> (`companion` is left as it is otherwise); each with its observables and, with &output
   !> leakage, the Reynolds leakage of its gap.
   subroutine solve_runs(scene, height, result, companion, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in), target :: height(:)
      type(contact_result), intent(out) :: result
      type(contact_result), intent(inout) :: companion
      type(error_type), allocatable, intent(out) :: error
      call solve_scene(scene, height, scene%friction, result, error)
      if (allocated(error)) return
      if (scene%leakage) then
         call leakage_of(scene, result, error)
         if (allocated(error)) return
      end if
      if (.not. scene%companion) return
      call solve_scene(companion_of(scene, result%mean_pressure), height, 0.0_wp, companion, error)
      if (allocated(error)) return
      if (scene%leakage) call leakage_of(scene, companion, error)
   end subroutine solve_runs

   !> The Reynolds leakage of the solved gap along x and y; contact is where p > 0 (and gaps
   !> at the rounding of a converged solve, lc_leakage_reynolds).
   subroutine leakage_of(scene, result, error)
      type(scene_type), intent(in) :: scene
      type(contact_result), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      grid = grid_of(scene)
      allocate (result%leakage)
      ! (distributed: on the slabs, every rank getting the whole answer)
      call reynolds_leakage(result%gap, result%pressure > 0.0_wp, grid%nx, grid%ny, grid%lx, grid%ly, &
         & scene%leakage_tol, leakage_max_iter, result%leakage, error)
   end subroutine leakage_of

end module lc_application_scene_solve
