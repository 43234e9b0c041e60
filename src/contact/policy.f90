!> Which methods solve a scene under &solver method = 'auto', and why: one place, from
!> measured indicators of the problem, never from which method ran before. The rules and
!> the measurements behind each constant are in docs/numerics.md ("How 'auto' chooses");
!> the benchmarks that rerun them are named there.
!>
!> The plan is a list of stages (lc_contact_stages): a first method, then those that go on
!> from its iterate where it stalls. Under 'auto':
!>  1. symmetric operators take the constrained CG, and the multigrid method from
!>     multigrid_points (lines) or multigrid_surface_points (surfaces);
!>  2. coupled operators (friction, a sliding viscoelastic layer) take the constrained GCR;
!>  3. after the coarse start (the solve on the grid of every second point), the multigrid
!>     method where that start says the fine grid is hard for the Krylov methods:
!>     a. a sliding viscoelastic layer lossy among its short waves, with enough contact
!>        points in the start (lossy_*);
!>     b. broadband roughness: the start took many iterations (hard_coarse_*), on large
!>        grids (coupled_multigrid_*; rows_multigrid_surface_points where the multigrid
!>        method smooths by rows; rising_multigrid_points where only the coupled form
!>        admits a thin incompressible layer);
!>  4. where a Krylov method stalls the GCR goes on keeping its history across clips,
!>     then the Anderson iteration, and on small grids of a monotone operator the dense
!>     Newton method finishes.
module lc_contact_policy
   use lc_base_kinds, only: wp
   use lc_base_parallel, only: global_sum
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string, formatted
   use lc_contact_operator, only: compliance_operator
   use lc_contact_solver_newton, only: dense_points
   use lc_contact_solver_gfmd, only: gfmd_refusal
   use lc_contact_solver_multigrid, only: multigrid_refusal, metric_refusal, coupled_refusal, size_refusal, &
      & rows_ahead_of_gcr, loss_among_short_waves, short_loss_limit, solves_on_slabs
   implicit none (type, external)
   private
   public :: problem_indicators, solve_plan, measure_problem, measure_start, plan_solve, max_stages
   public :: may_take_multigrid

   !> 1. Symmetric operators: the multigrid method from this many points.
   integer, parameter :: multigrid_points = 4096, multigrid_surface_points = 1024**2
   !> 3b. A coarse start is hard when it took more than this many iterations (or the
   !> multigrid method) ...
   integer, parameter :: hard_coarse_iterations = 20, hard_coarse_surface_iterations = 12
   !> ... and then a coupled scene takes the multigrid method from this many points ...
   integer, parameter :: coupled_multigrid_points = 8192, coupled_multigrid_surface_points = 1024**2
   !> ... a surface the multigrid method smooths by rows (rows_ahead_of_gcr) from this many ...
   integer, parameter :: rows_multigrid_surface_points = 512**2
   !> ... and one whose metric the symmetric hierarchy refuses (a thin incompressible
   !> layer, admitted by the coupled form) from this many.
   integer, parameter :: rising_multigrid_points = 262144
   !> 3a. A sliding viscoelastic scene from this many points whose loss |Im K|/Re K among
   !> the waves short along x reaches the line's or the surface's limit (short_loss_limit),
   !> with at least 16 (line) or 16^2 (surface) contact points in its start.
   integer, parameter :: lossy_multigrid_points = 1024, lossy_surface_points = 128**2
   real(wp), parameter :: lossy_line_loss = 1.0_wp
   integer, parameter :: lossy_contacts_per_axis = 16

   integer, parameter :: max_stages = 5
   integer, parameter :: name_length = 12

   !> What the rules look at: properties of the operator, and of the coarse start once it ran.
   type :: problem_indicators
      character(len=name_length) :: method = 'auto'   !< &solver method
      logical :: line = .true.
      integer :: points = 0
      logical :: coupled = .false.         !< G_eff not symmetric: friction, or a sliding viscoelastic layer
      logical :: viscoelastic = .false.
      logical :: monotone = .true.         !< Re G_eff >= 0 on every mode
      !> symmetric, but its compliance rises too steeply for the symmetric multigrid
      !> method: only the coupled form takes it (a thin incompressible layer)
      logical :: rising = .false.
      !> why no multigrid form can solve the scene ('' if one can)
      character(len=:), allocatable :: refusal
      !> why the GFMD dynamics cannot relax the scene ('' if it can; measured for method 'gfmd' only)
      character(len=:), allocatable :: gfmd_refusal
      !> the metric's hierarchy would precondition it (metric_refusal is empty)
      logical :: metric_admitted = .true.
      !> the coarse start (where it ran): its iterations and whether it took the multigrid
      !> method; the contact points of the start the fine grid gets
      integer :: start_iterations = 0
      logical :: start_multigrid = .false.
      integer :: start_contacts = 0
      !> where measured (sliding viscoelastic, from lossy_*_points): the loss among the
      !> waves short along x
      real(wp) :: short_wave_loss = 0.0_wp
      !> where measured (a hard coupled surface from rows_multigrid_surface_points): the
      !> multigrid method smooths it by rows where the GCR is slow
      logical :: rows_ahead = .false.
      !> a surface shared among the ranks of an MPI job (docs/decisions/023-mpi-slabs.md):
      !> the constrained CG and GCR (GCR keeping its history, then Anderson's iteration),
      !> GFMD and the multigrid method (its finest grid: docs/decisions/028-distributed-multigrid.md)
      !> solve it on the slabs; dense Newton not
      logical :: distributed = .false.
      !> ... the multigrid method with its finest grid on the slabs (solves_on_slabs); else
      !> the grid, too small to halve into a nested coarse grid, is gathered onto every rank
      logical :: multigrid_on_slabs = .false.
      !> the multigrid method's measures (refusal, metric_admitted) are left to measure_start:
      !> under 'auto' a coupled operator reads them only where its start is hard or it may be
      !> lossy among its short waves (rules 3a, 3b), a symmetric one that the symmetric
      !> method refuses whether the coupled form admits it (`rising`) only where its start
      !> is hard (refusal then holds the symmetric method's)
      logical :: multigrid_deferred = .false.
   end type problem_indicators

   !> The methods a distributed surface may ask for by name.
   character(len=*), parameter :: distributed_methods = "'auto', 'cg', 'gcr', 'anderson', 'gfmd' or 'multigrid'"

   !> The methods to run, in turn, the coarse start before them, and why.
   type :: solve_plan
      character(len=name_length) :: stages(max_stages) = ''
      integer :: count = 0
      logical :: coarse_start = .false.
      character(len=:), allocatable :: reason
   end type solve_plan

contains

   !> The indicators of the operator `op` for &solver method `method`.
   function measure_problem(op, method, load_control) result(ind)
      type(compliance_operator), intent(in) :: op
      character(len=*), intent(in) :: method
      logical, intent(in) :: load_control
      type(problem_indicators) :: ind
      ind%method = method
      ind%line = op%grid%is_line()
      ind%points = op%grid%points()
      ind%coupled = op%coupled
      ind%viscoelastic = op%kernel%viscoelastic
      ind%monotone = op%monotone
      ind%gfmd_refusal = ''
      ind%refusal = ''
      ! (GFMD's measure is a largest ratio over the modes: taken over the ranks on a slab)
      if (trim(method) == 'gfmd') ind%gfmd_refusal = gfmd_refusal(op)
      if (op%distributed) then
         ind%distributed = .true.
         ind%multigrid_on_slabs = solves_on_slabs(op)
         if (all(trim(method) /= [character(len=9) :: 'auto', 'multigrid'])) return
      end if
      ! (a coupled operator under 'auto' takes the constrained GCR unless its start says
      ! otherwise: the measures wait for the start, which most grids never need. A symmetric
      ! one needs before its start only whether the symmetric method takes it; where that
      ! refuses a rising compliance, whether the coupled form admits it waits as well: it
      ! matters only after a hard start, rule 3b)
      if (trim(method) == 'auto') then
         ind%multigrid_deferred = op%coupled
         if (ind%multigrid_deferred) return
         ind%refusal = multigrid_refusal(op)
         ! (deferred: the compliance's rise alone refused, which the coupled form may admit)
         ind%multigrid_deferred = len(ind%refusal) > 0 .and. .not. op%kernel%viscoelastic .and. &
            & len(size_refusal(op)) == 0
         return
      end if
      ! (on a slab each measure takes the rank's modes, reduced over the ranks: the whole
      ! grid's values, docs/decisions/028-distributed-multigrid.md)
      call measure_multigrid(ind, op, load_control)
   end function measure_problem

   !> Whether the multigrid method can solve the scene of `op` (its refusals), and in which form.
   subroutine measure_multigrid(ind, op, load_control)
      type(problem_indicators), intent(inout) :: ind
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      ind%refusal = multigrid_refusal(op)
      if (op%coupled .or. (len(ind%refusal) > 0 .and. .not. op%kernel%viscoelastic)) then
         ind%refusal = coupled_refusal(op, load_control)
         ind%rising = .not. op%coupled .and. len(ind%refusal) == 0
      end if
      if (len(ind%refusal) == 0 .and. (ind%coupled .or. ind%rising)) ind%metric_admitted = len(metric_refusal(op)) == 0
   end subroutine measure_multigrid

   !> Add what the start tells (the coarse start's iterations, 0 where none ran, whether it
   !> took the multigrid method, the contact points of the start `p`) and what the rules
   !> then need of `op`.
   subroutine measure_start(ind, op, load_control, iterations, took_multigrid, p)
      type(problem_indicators), intent(inout) :: ind
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      integer, intent(in) :: iterations
      logical, intent(in) :: took_multigrid
      real(wp), intent(in) :: p(:)
      ind%start_iterations = iterations
      ind%start_multigrid = took_multigrid
      ind%start_contacts = count(p > 0.0_wp)
      if (ind%distributed) ind%start_contacts = global_sum(ind%start_contacts)
      if (trim(ind%method) /= 'auto') return
      if (ind%multigrid_deferred .and. (hard(ind) .or. loss_needed(ind))) then
         call measure_multigrid(ind, op, load_control)
         ind%multigrid_deferred = .false.
      end if
      if (ind%multigrid_deferred .or. len(ind%refusal) > 0) return
      if (loss_needed(ind)) ind%short_wave_loss = loss_among_short_waves(op)
      if (rows_needed(ind)) ind%rows_ahead = rows_ahead_of_gcr(op, load_control)
   end subroutine measure_start

   !> The plan for a problem with indicators `ind` (before the coarse start: the first
   !> method, and whether the start runs; after it: the final plan). Errors for a method
   !> the scene refuses. `coarse_start`: &solver coarse_start and the grid can be halved.
   subroutine plan_solve(ind, coarse_start, plan, error)
      type(problem_indicators), intent(in) :: ind
      logical, intent(in) :: coarse_start
      type(solve_plan), intent(out) :: plan
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: first, why, allowed

      first = trim(ind%method)
      why = ''
      if (ind%distributed .and. all(trim(ind%method) /= [character(len=9) :: 'auto', 'cg', 'gcr', 'kept', &
         & 'anderson', 'gfmd', 'multigrid'])) then
         call fatal_error(error, "&solver: method = '" // trim(ind%method) // "' runs on one MPI rank; a surface " // &
            & 'shared among ranks is solved by ' // distributed_methods, code_input)
         return
      end if
      select case (trim(ind%method))
      case ('auto')
         call choose(ind, first, why)
      case ('cg')
         if (ind%coupled) then
            call fatal_error(error, "&solver: method = 'cg' cannot solve this scene: friction couples the normal " // &
               & "and tangential fields and the operator is not symmetric; allowed: 'auto', 'gcr' or 'anderson'", &
               & code_input)
            return
         end if
      case ('multigrid')
         if (len(ind%refusal) > 0) then
            allowed = "'auto', 'cg', 'gcr', 'anderson' or 'gfmd'"
            if (ind%coupled) allowed = "'auto', 'gcr' or 'anderson'"
            call fatal_error(error, "&solver: method = 'multigrid' cannot solve this scene: " // ind%refusal // &
               & '; it solves lines and surfaces on an elastic half-space or layer (nu <= 0.47, or ' // &
               & 'h/lambda >~ 0.07), with friction or sliding viscoelastic, and lines on thinner layers down ' // &
               & 'to h/lambda ~ 0.01 at nu = 0.5; allowed here: ' // allowed, code_input)
            return
         end if
      case ('gfmd')
         if (allocated(ind%gfmd_refusal)) then
            if (len(ind%gfmd_refusal) > 0) then
               call fatal_error(error, "&solver: method = 'gfmd' cannot solve this scene: " // ind%gfmd_refusal // &
                  & "; allowed here: 'auto' (the default method), 'gcr' or 'anderson'", code_input)
               return
            end if
         end if
      case ('newton')
         if (ind%points > dense_points) then
            call fatal_error(error, "&solver: method = 'newton' (dense) needs a grid of at most " // &
               & to_string(dense_points) // ' points; this one has ' // to_string(ind%points) // &
               & "; allowed here: 'auto', 'cg', 'gcr', 'anderson', 'gfmd' or 'multigrid'", code_input)
            return
         end if
      end select
      if (trim(ind%method) /= 'auto') then
         first = trim(ind%method)
         why = "method '" // first // "', as the scene asks"
         if (first == 'anderson' .and. .not. ind%coupled) then
            ! (its outer iteration has nothing to iterate on: G_eff is its own metric)
            first = 'cg'
            why = "method 'anderson' on a symmetric operator: the constrained CG it iterates around"
         end if
      end if

      ! (a shared surface: where the multigrid method holds its finest grid)
      if (first == 'multigrid' .and. ind%distributed) then
         if (ind%multigrid_on_slabs) then
            why = why // ' (its finest grid on the slabs, its coarse grids whole on every rank)'
         else
            why = why // ' (the grid gathered whole onto every rank)'
         end if
      end if
      call add(plan, first)
      ! (the multigrid method makes its own nested iteration on a symmetric operator; on the
      ! coupled form it takes the start, whose contact set is nearly right)
      plan%coarse_start = coarse_start .and. (first /= 'multigrid' .or. ind%coupled .or. ind%rising)
      ! where it stalls: on the coupled form the GCR goes on (under 'auto' or after the
      ! multigrid method), on the symmetric one the CG finishes the multigrid's fields
      if (first == 'multigrid' .and. .not. (ind%coupled .or. ind%rising)) then
         call add(plan, 'cg')
      else if (first == 'multigrid') then
         call add(plan, 'gcr')
      end if
      if (plan%stages(plan%count) == 'gcr' .and. (trim(ind%method) == 'auto' .or. first == 'multigrid')) then
         call add(plan, 'kept')
         call add(plan, 'anderson')
      end if
      if (trim(ind%method) == 'auto' .and. ind%points <= dense_points .and. ind%monotone .and. first /= 'newton' &
         & .and. .not. ind%distributed) call add(plan, 'newton')
      plan%reason = why
      if (plan%count > 1) plan%reason = plan%reason // '; where it stalls, ' // fallbacks(plan)
   end subroutine plan_solve

   !> The first method under 'auto', and why.
   subroutine choose(ind, first, why)
      type(problem_indicators), intent(in) :: ind
      character(len=:), allocatable, intent(out) :: first, why
      character(len=:), allocatable :: size_text
      integer :: contacts

      first = 'cg'
      why = ''
      size_text = to_string(ind%points) // ' points'
      if (.not. ind%line) size_text = 'a surface of ' // size_text
      if (.not. ind%coupled) then
         if (.not. ind%rising .and. len(ind%refusal) == 0 .and. ind%points >= symmetric_points(ind%line)) then
            first = 'multigrid'
            why = 'a symmetric operator on ' // size_text // ' (at least ' // to_string(symmetric_points(ind%line)) // &
               & '): the multigrid method'
         else
            first = 'cg'
            why = 'a symmetric operator: the constrained CG'
            if (ind%rising .or. ind%multigrid_deferred) then
               why = why // ' (its compliance rises too steeply for the symmetric multigrid method)'
            else if (len(ind%refusal) > 0) then
               why = why // ' (no multigrid method: ' // ind%refusal // ')'
            end if
         end if
         if (.not. ind%rising) return
      end if
      if (ind%coupled) then
         first = 'gcr'
         why = 'a coupled operator (friction, or a sliding viscoelastic layer): the constrained GCR'
      end if
      if (len(ind%refusal) > 0) return

      ! 3a: lossy among the short waves
      contacts = lossy_contacts_per_axis**merge(1, 2, ind%line)
      if (ind%viscoelastic .and. ind%points >= lossy_points(ind%line) .and. ind%start_contacts >= contacts .and. &
         & ind%short_wave_loss >= lossy_loss(ind%line) .and. (ind%line .or. ind%metric_admitted)) then
         first = 'multigrid'
         why = 'a sliding viscoelastic layer whose loss among the short waves is ' // &
            & formatted(ind%short_wave_loss, '(g0.3)') // ' (at least ' // formatted(lossy_loss(ind%line), '(g0.2)') // &
            & '), with ' // to_string(ind%start_contacts) // ' contact points in its start (at least ' // &
            & to_string(contacts) // ') on ' // size_text // ': the multigrid method'
         return
      end if
      ! 3b: a hard start
      if (.not. hard(ind)) return
      if (ind%points >= coupled_points(ind%line)) then
         if (.not. (ind%metric_admitted .or. ind%points >= rising_multigrid_points)) return
         first = 'multigrid'
         why = merge('a coupled operator     ', 'a rising compliance    ', ind%coupled)
         why = trim(why) // ' whose coarse start was hard (' // start_text(ind) // ') on ' // size_text // &
            & ' (at least ' // to_string(merge(coupled_points(ind%line), rising_multigrid_points, &
            & ind%metric_admitted)) // '): the multigrid method'
      else if (ind%coupled .and. .not. ind%line .and. ind%points >= rows_multigrid_surface_points .and. &
         & ind%rows_ahead) then
         first = 'multigrid'
         why = 'a coupled operator the multigrid method smooths by rows, whose coarse start was hard (' // &
            & start_text(ind) // ') on ' // size_text // ' (at least ' // to_string(rows_multigrid_surface_points) // &
            & '): the multigrid method'
      end if
   end subroutine choose

   !> Whether the multigrid method may solve a scene on a grid of `points` points (a line
   !> or a surface) whose operator is `coupled`, or `viscoelastic`, under &solver method
   !> `method`, whatever its coarse start turns out to be: what the memory check provides for.
   pure logical function may_take_multigrid(method, points, line, coupled, viscoelastic) result(may)
      character(len=*), intent(in) :: method
      integer, intent(in) :: points
      logical, intent(in) :: line, coupled, viscoelastic
      may = trim(method) == 'multigrid'
      if (trim(method) /= 'auto') return
      if (coupled) then
         may = points >= coupled_points(line) .or. (viscoelastic .and. points >= lossy_points(line)) .or. &
            & (viscoelastic .and. .not. line .and. points >= rows_multigrid_surface_points)
      else
         may = points >= min(symmetric_points(line), coupled_points(line))
      end if
   end function may_take_multigrid

   !> Rule 3a reads the loss among the short waves ...
   pure logical function loss_needed(ind)
      type(problem_indicators), intent(in) :: ind
      loss_needed = ind%viscoelastic .and. ind%points >= lossy_points(ind%line)
   end function loss_needed

   !> ... and 3b on a surface between rows_multigrid_surface_points and coupled_points
   !> whether rows smooth it.
   pure logical function rows_needed(ind)
      type(problem_indicators), intent(in) :: ind
      rows_needed = ind%coupled .and. .not. ind%line .and. hard(ind) .and. &
         & ind%points >= rows_multigrid_surface_points .and. ind%points < coupled_points(ind%line)
   end function rows_needed

   pure logical function hard(ind)
      type(problem_indicators), intent(in) :: ind
      hard = ind%start_multigrid .or. &
         & ind%start_iterations > merge(hard_coarse_iterations, hard_coarse_surface_iterations, ind%line)
   end function hard

   function start_text(ind) result(text)
      type(problem_indicators), intent(in) :: ind
      character(len=:), allocatable :: text
      if (ind%start_multigrid) then
         text = 'it took the multigrid method'
      else
         text = to_string(ind%start_iterations) // ' iterations, more than ' // &
            & to_string(merge(hard_coarse_iterations, hard_coarse_surface_iterations, ind%line))
      end if
   end function start_text

   pure integer function symmetric_points(line)
      logical, intent(in) :: line
      symmetric_points = merge(multigrid_points, multigrid_surface_points, line)
   end function symmetric_points

   pure integer function coupled_points(line)
      logical, intent(in) :: line
      coupled_points = merge(coupled_multigrid_points, coupled_multigrid_surface_points, line)
   end function coupled_points

   pure integer function lossy_points(line)
      logical, intent(in) :: line
      lossy_points = merge(lossy_multigrid_points, lossy_surface_points, line)
   end function lossy_points

   pure real(wp) function lossy_loss(line)
      logical, intent(in) :: line
      lossy_loss = merge(lossy_line_loss, short_loss_limit, line)
   end function lossy_loss

   subroutine add(plan, stage)
      type(solve_plan), intent(inout) :: plan
      character(len=*), intent(in) :: stage
      plan%count = plan%count + 1
      plan%stages(plan%count) = stage
   end subroutine add

   !> The methods after the first, in words.
   function fallbacks(plan) result(text)
      type(solve_plan), intent(in) :: plan
      character(len=:), allocatable :: text
      integer :: k
      text = ''
      do k = 2, plan%count
         if (k > 2) text = text // ', then '
         select case (trim(plan%stages(k)))
         case ('cg');       text = text // 'the constrained CG finishes its fields'
         case ('gcr');      text = text // 'the GCR goes on from its best iterate'
         case ('kept');     text = text // 'the GCR keeping its history across clips'
         case ('anderson'); text = text // 'the Anderson iteration'
         case ('newton')
            text = text // 'the dense Newton method (a monotone operator on at most ' // to_string(dense_points) // &
               & ' points)'
         case default;      text = text // trim(plan%stages(k))
         end select
      end do
   end function fallbacks

end module lc_contact_policy
