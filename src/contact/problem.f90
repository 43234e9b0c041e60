!> The objects every contact solver works on (docs/maintainers.md, "The solver layer"):
!> the problem (operator, target, control, tolerance, budget), the state it changes
!> (p, w = G_eff p, gap, s) and the outcome it reports.
!>
!> The problem, in the notation of docs/theory.md: find p >= 0 with
!>    gap = G_eff p - b - s >= 0,   p gap = 0,
!> under load control (mean(p) = p_m given, the constant s found) or displacement control
!> (s given). The solvers stop on the complementarity residual (lc_contact_residual).
module lc_contact_problem
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: contact_problem, contact_state, solve_outcome

   !> What a solver is given. The operator and the target are the caller's (pointers: a
   !> field of a 4096^2 grid is 128 MiB, not to be copied).
   type :: contact_problem
      type(compliance_operator), pointer :: op => null()
      real(wp), pointer, contiguous :: b(:) => null()   !< the target: the rigid profile r (L)
      logical :: load_control = .true.
      real(wp) :: mean_pressure = 0.0_wp   !< p_m (S), under load control
      real(wp) :: g_ref = 1.0_wp           !< the residual's gap scale (L): the profile's peak-to-valley
      real(wp) :: tol = 1.0e-8_wp          !< on the complementarity residual
      integer :: max_iter = 100000         !< iterations of the whole solve, every method's counted
      integer :: memory = 20               !< directions kept by the GCR and the Anderson iteration
      logical :: precondition = .true.     !< the Fourier preconditioners of the CG and the GCR
      character(len=8) :: gfmd_mass = 'auto'   !< GFMD's masses: 'auto', 'one' or 'mode' (lc_contact_solver_gfmd)
   end type contact_problem

   !> The fields a solver changes: on entry the start, on exit the solution (or the best
   !> iterate found). On a grid of n points, flat with x fastest (lc_base_grid).
   type :: contact_state
      real(wp), allocatable :: p(:)     !< pressure (S), >= 0 on exit
      real(wp), allocatable :: w(:)     !< w = G_eff p (L)
      real(wp), allocatable :: gap(:)   !< gap = w - b - s (L)
      real(wp) :: s = 0.0_wp            !< the gap's constant (L): given, or the load's multiplier
   end type contact_state

   !> What a solve did: one method, or several that went on from each other's last iterate.
   type :: solve_outcome
      !> the methods that ran, joined by '+' (e.g. 'gcr+kept+anderson')
      character(len=:), allocatable :: path
      logical :: converged = .false.
      integer :: iterations = 0         !< iterations of every method (inner CG ones for the Anderson iteration)
      integer :: outer_iterations = 0   !< outer (Anderson) iterations; 1 where none ran
      integer :: fft_pairs = 0          !< transform pairs on this grid's points
      real(wp) :: residual = huge(1.0_wp)
      real(wp), allocatable :: history(:)   !< the residual after each iteration (or check) recorded
      !> what a method chose for itself, for the result's reason (e.g. GFMD's masses; '' if nothing)
      character(len=:), allocatable :: note
   end type solve_outcome

end module lc_contact_problem
