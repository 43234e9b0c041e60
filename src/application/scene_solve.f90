!> One solve of a scene and its observables: the contact solve (lc_contact_solve), then
!> what the scene asks to be computed from the solution (lc_observables). The executable,
!> the Python driver and the resolution pilot all solve through it.
module lc_application_scene_solve
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_scene, only: scene_type
   use lc_result, only: contact_result
   use lc_contact_operator, only: compliance_operator
   use lc_contact_solve, only: solve_contact
   use lc_observables, only: observe
   implicit none (type, external)
   private
   public :: solve_scene

contains

   !> Solve `scene` on the profile `height` (flat, x fastest) with Coulomb coefficient
   !> `friction` (the scene's, or 0 for the frictionless companion) and compute its
   !> observables.
   subroutine solve_scene(scene, height, friction, result, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in), target :: height(:)
      real(wp), intent(in) :: friction
      type(contact_result), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(compliance_operator), target :: op
      call solve_contact(scene, height, friction, result, op, error)
      if (allocated(error)) return
      call observe(scene, op, height, result)
   end subroutine solve_scene

end module lc_application_scene_solve
