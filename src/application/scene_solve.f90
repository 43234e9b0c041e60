!> The solves of a scene and what is computed from them: the contact solve
!> (lc_contact_solve), the observables the scene asks for (lc_observables), the Reynolds
!> leakage of the gap (lc_leakage_reynolds), the conductance and interfacial stiffness
!> (lc_observables_conductance), and the frictionless companion. The
!> executable's run, the Python driver and the resolution pilot all solve through it.
module lc_application_scene_solve
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error
   use lc_scene, only: scene_type, grid_of, companion_of
   use lc_base_parallel, only: is_distributed, is_root, gather_rows, broadcast_from
   use lc_base_grid, only: grid_type
   use lc_leakage_reynolds, only: reynolds_leakage, leakage_max_iter, leakage_flow
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
      if (is_distributed() .and. .not. grid%is_line()) then
         call leakage_on_rank_0(scene, grid, result, error)
         return
      end if
      call reynolds_leakage(result%gap, result%pressure > 0.0_wp, grid%nx, grid%ny, grid%lx, grid%ly, &
         & scene%leakage_tol, leakage_max_iter, result%leakage, error)
   end subroutine leakage_of

   !> The leakage of a surface shared among MPI ranks (the result's fields: this rank's
   !> slab): the gap and the pressure gathered to rank 0, which solves the Reynolds problem
   !> of the whole map; its answer then sent to every rank (the result file's attributes are
   !> written by all). A failure there fails every rank.
   subroutine leakage_on_rank_0(scene, grid, result, error)
      type(scene_type), intent(in) :: scene
      type(grid_type), intent(in) :: grid
      type(contact_result), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: gap(:), pressure(:), packed(:)
      real(wp) :: code
      integer :: i
      call gather_rows(result%gap, grid%nx, grid%ny, gap)
      call gather_rows(result%pressure, grid%nx, grid%ny, pressure)
      if (is_root()) call reynolds_leakage(gap, pressure > 0.0_wp, grid%nx, grid%ny, grid%lx, grid%ly, &
         & scene%leakage_tol, leakage_max_iter, result%leakage, error)
      ! (rank 0's exit code on every rank: a job ends with the code of its failure)
      code = 0.0_wp
      if (allocated(error)) code = error%code
      call broadcast_from(code, 0)
      if (code /= 0.0_wp) then
         if (.not. allocated(error)) call fatal_error(error, 'the leakage failed on MPI rank 0', nint(code))
         return
      end if
      associate (leakage => result%leakage)
         packed = [flow_values(leakage%x), flow_values(leakage%y), leakage%fluid_fraction, leakage%tol, &
            & leakage%wall_time, (real(ichar(leakage%solver(i:i)), wp), i = 1, len(leakage%solver))]
         call broadcast_from(packed, 0)
         call set_flow(leakage%x, packed(1:7))
         call set_flow(leakage%y, packed(8:14))
         leakage%fluid_fraction = packed(15)
         leakage%tol = packed(16)
         leakage%wall_time = packed(17)
         do i = 1, len(leakage%solver)
            leakage%solver(i:i) = achar(nint(packed(17 + i)))
         end do
      end associate

   contains

      function flow_values(flow) result(values)
         type(leakage_flow), intent(in) :: flow
         real(wp) :: values(7)
         values = [flow%k_eff, merge(1.0_wp, 0.0_wp, flow%percolating), flow%connected_fraction, &
            & real(flow%unknowns, wp), real(flow%iterations, wp), flow%residual, merge(1.0_wp, 0.0_wp, flow%converged)]
      end function flow_values

      subroutine set_flow(flow, values)
         type(leakage_flow), intent(inout) :: flow
         real(wp), intent(in) :: values(7)
         flow%k_eff = values(1)
         flow%percolating = values(2) > 0.5_wp
         flow%connected_fraction = values(3)
         flow%unknowns = nint(values(4))
         flow%iterations = nint(values(5))
         flow%residual = values(6)
         flow%converged = values(7) > 0.5_wp
      end subroutine set_flow
   end subroutine leakage_on_rank_0

end module lc_application_scene_solve
