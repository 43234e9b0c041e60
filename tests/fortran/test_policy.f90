!> Tests of lc_contact_policy from its indicators alone (no solve): which methods 'auto'
!> plans for each kind of problem, that an explicit method is kept with the fallbacks it
!> owns, that refused methods are refused with exit code 2, and that the reason names the
!> rule. Prints one line per check; error stop 1 on any failure.
program test_policy
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, code_input
   use lc_contact_policy, only: problem_indicators, solve_plan, plan_solve, may_take_multigrid
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   call check_symmetric()
   call check_coupled()
   call check_after_a_hard_start()
   call check_lossy()
   call check_explicit_methods()
   call check_refusals()
   call check_memory_view()
   call check_distributed()
   call finish('policy')

contains

   !> The indicators of a problem, everything else as in the type's defaults.
   function problem(points, line, coupled, viscoelastic, method) result(ind)
      integer, intent(in) :: points
      logical, intent(in) :: line, coupled
      logical, intent(in), optional :: viscoelastic
      character(len=*), intent(in), optional :: method
      type(problem_indicators) :: ind
      ind%points = points
      ind%line = line
      ind%coupled = coupled
      if (present(viscoelastic)) ind%viscoelastic = viscoelastic
      if (present(method)) ind%method = method
      ind%refusal = ''
   end function problem

   !> The plan's stages joined by '+'.
   function path(plan) result(text)
      type(solve_plan), intent(in) :: plan
      character(len=:), allocatable :: text
      integer :: k
      text = trim(plan%stages(1))
      do k = 2, plan%count
         text = text // '+' // trim(plan%stages(k))
      end do
   end function path

   subroutine expect(name, ind, coarse_start, wanted, reason_has)
      character(len=*), intent(in) :: name
      type(problem_indicators), intent(in) :: ind
      logical, intent(in) :: coarse_start
      character(len=*), intent(in) :: wanted, reason_has
      type(solve_plan) :: plan
      type(error_type), allocatable :: error
      call plan_solve(ind, .true., plan, error)
      if (allocated(error)) then
         call check(.false., name, detail='refused: ' // error%message)
         return
      end if
      call check(path(plan) == wanted .and. (plan%coarse_start .eqv. coarse_start) .and. &
         & index(plan%reason, reason_has) > 0, name, detail=path(plan) // ' | ' // plan%reason)
   end subroutine expect

   subroutine check_symmetric()
      type(problem_indicators) :: ind
      call expect('symmetric small line: CG, dense Newton after it', problem(1024, .true., .false.), .true., &
         & 'cg+newton', 'constrained CG')
      call expect('symmetric line of 4095 points: CG', problem(4095, .true., .false.), .true., 'cg', 'constrained CG')
      call expect('symmetric line of 4096 points: multigrid, no coarse start', problem(4096, .true., .false.), &
         & .false., 'multigrid+cg', 'at least 4096')
      call expect('symmetric surface of 512^2: CG', problem(512**2, .false., .false.), .true., 'cg', 'constrained CG')
      call expect('symmetric surface of 1024^2: multigrid', problem(1024**2, .false., .false.), .false., &
         & 'multigrid+cg', 'the multigrid method')
      ind = problem(65536, .true., .false.)
      ind%refusal = 'the grid halves to an odd one'
      call expect('a refused multigrid: CG, and why', ind, .true., 'cg', 'no multigrid method: the grid halves')
      ind = problem(1024, .true., .false.)
      ind%monotone = .false.
      call expect('not monotone: no dense Newton', ind, .true., 'cg', 'constrained CG')
   end subroutine check_symmetric

   subroutine check_coupled()
      call expect('coupled line: GCR, its fallbacks, dense Newton', problem(1024, .true., .true.), .true., &
         & 'gcr+kept+anderson+newton', 'constrained GCR')
      call expect('coupled line of 65536 points, easy start: GCR', problem(65536, .true., .true.), .true., &
         & 'gcr+kept+anderson', 'the Anderson iteration')
   end subroutine check_coupled

   subroutine check_after_a_hard_start()
      type(problem_indicators) :: ind
      ind = problem(16384, .true., .true.)
      ind%start_iterations = 21
      call expect('coupled line of 16384, 21 coarse iterations: multigrid', ind, .true., &
         & 'multigrid+gcr+kept+anderson', '21 iterations, more than 20')
      ind%start_iterations = 20
      call expect('... 20 coarse iterations: GCR', ind, .true., 'gcr+kept+anderson', 'constrained GCR')
      ind = problem(4096, .true., .true.)
      ind%start_iterations = 300
      call expect('coupled line of 4096, hard start: GCR (below 8192 points)', ind, .true., 'gcr+kept+anderson', &
         & 'constrained GCR')
      ind = problem(1024**2, .false., .true.)
      ind%start_multigrid = .true.
      call expect('coupled surface of 1024^2 whose start took the multigrid: multigrid', ind, .true., &
         & 'multigrid+gcr+kept+anderson', 'it took the multigrid method')
      ind = problem(512**2, .false., .true., viscoelastic=.true.)
      ind%start_iterations = 13
      ind%rows_ahead = .true.
      call expect('sliding surface of 512^2 smoothed by rows, hard start: multigrid', ind, .true., &
         & 'multigrid+gcr+kept+anderson', 'smooths by rows')
      ind%rows_ahead = .false.
      call expect('... not smoothed by rows: GCR', ind, .true., 'gcr+kept+anderson', 'constrained GCR')
      ! a thin incompressible line: symmetric, only the coupled form of the multigrid admits it
      ind = problem(262144, .true., .false.)
      ind%rising = .true.
      ind%metric_admitted = .false.
      ind%start_iterations = 40
      call expect('rising compliance, 262144 points, hard start: multigrid', ind, .true., &
         & 'multigrid+gcr+kept+anderson', 'a rising compliance')
      ind%points = 131072
      call expect('rising compliance, 131072 points: CG', ind, .true., 'cg', 'constrained CG')
      ind%refusal = 'the Jacobi step would not smooth'
      ind%points = 262144
      call expect('rising compliance refused by the coupled form: CG', ind, .true., 'cg', 'constrained CG')
      ! before its start (or after an easy one) the coupled form's admission is not measured
      ind = problem(1024**2, .false., .false.)
      ind%refusal = 'the compliance rises with |q| over the grid by a factor 12.0'
      ind%multigrid_deferred = .true.
      call expect('rising compliance, its coupled form not measured: CG with the start', ind, .true., 'cg', &
         & 'rises too steeply for the symmetric multigrid method')
   end subroutine check_after_a_hard_start

   subroutine check_lossy()
      type(problem_indicators) :: ind
      ind = problem(1024, .true., .true., viscoelastic=.true.)
      ind%short_wave_loss = 4.95_wp
      ind%start_contacts = 16
      call expect('lossy line of 1024 points, 16 contacts: multigrid', ind, .true., &
         & 'multigrid+gcr+kept+anderson+newton', 'loss among the short waves is 4.95')
      ind%start_contacts = 15
      call expect('... 15 contacts: GCR', ind, .true., 'gcr+kept+anderson+newton', 'constrained GCR')
      ind%start_contacts = 16
      ind%short_wave_loss = 0.99_wp
      call expect('... loss 0.99: GCR', ind, .true., 'gcr+kept+anderson+newton', 'constrained GCR')
      ind = problem(128**2, .false., .true., viscoelastic=.true.)
      ind%short_wave_loss = 3.5_wp
      ind%start_contacts = 256
      call expect('lossy surface of 128^2, 256 contacts: multigrid', ind, .true., 'multigrid+gcr+kept+anderson', &
         & 'at least 256')
      ind%short_wave_loss = 2.65_wp
      call expect('... loss 2.65: GCR', ind, .true., 'gcr+kept+anderson', 'constrained GCR')
      ind%short_wave_loss = 3.5_wp
      ind%metric_admitted = .false.
      call expect('... metric refused (thin incompressible): GCR', ind, .true., 'gcr+kept+anderson', &
         & 'constrained GCR')
      ind = problem(64**2, .false., .true., viscoelastic=.true.)
      ind%short_wave_loss = 3.5_wp
      ind%start_contacts = 4096
      call expect('lossy surface of 64^2: GCR', ind, .true., 'gcr+kept+anderson', 'constrained GCR')
   end subroutine check_lossy

   subroutine check_explicit_methods()
      call expect('gcr as asked: no fallbacks', problem(1024, .true., .true., method='gcr'), .true., 'gcr', &
         & "method 'gcr'")
      call expect('multigrid on a coupled scene: the GCR goes on', problem(1024, .true., .true., method='multigrid'), &
         & .true., 'multigrid+gcr+kept+anderson', "method 'multigrid'")
      call expect('multigrid on a symmetric scene: the CG finishes, no coarse start', &
         & problem(1024, .true., .false., method='multigrid'), .false., 'multigrid+cg', "method 'multigrid'")
      call expect('anderson on a symmetric scene is the CG', problem(1024, .true., .false., method='anderson'), &
         & .true., 'cg', 'symmetric operator')
      call expect('anderson on a coupled scene', problem(1024, .true., .true., method='anderson'), .true., &
         & 'anderson', "method 'anderson'")
      call expect('gfmd as asked', problem(1024, .true., .true., method='gfmd'), .true., 'gfmd', "method 'gfmd'")
      call expect('newton as asked', problem(1024, .true., .true., method='newton'), .true., 'newton', &
         & "method 'newton'")
   end subroutine check_explicit_methods

   subroutine check_refusals()
      type(problem_indicators) :: ind
      call refused('cg on a coupled scene', problem(1024, .true., .true., method='cg'), "method = 'cg'")
      call refused('newton on 2049 points', problem(2049, .true., .true., method='newton'), 'at most 2048')
      ind = problem(4096, .true., .true., method='multigrid')
      ind%refusal = 'n = 4096 halves to an odd grid'
      call refused('multigrid on a refused grid', ind, 'halves to an odd grid')
   end subroutine check_refusals

   subroutine refused(name, ind, message_has)
      character(len=*), intent(in) :: name
      type(problem_indicators), intent(in) :: ind
      character(len=*), intent(in) :: message_has
      type(solve_plan) :: plan
      type(error_type), allocatable :: error
      call plan_solve(ind, .true., plan, error)
      if (.not. allocated(error)) then
         call check(.false., name, detail='not refused: ' // path(plan))
         return
      end if
      call check(error%code == code_input .and. index(error%message, message_has) > 0, name, detail=error%message)
   end subroutine refused

   !> A surface shared among MPI ranks: 'auto' plans as on one rank (the multigrid method
   !> included: its finest grid on the slabs, and the reason says so), but no dense Newton
   !> method; the multigrid method, Anderson and GFMD as asked; dense Newton refused by name.
   subroutine check_distributed()
      type(problem_indicators) :: ind
      ind = problem(2048**2, .false., .false.)
      ind%distributed = .true.
      ind%multigrid_on_slabs = .true.
      call expect('distributed symmetric 2048^2', ind, .false., 'multigrid+cg', 'its finest grid on the slabs')
      ind%points = 512**2
      call expect('distributed symmetric 512^2', ind, .true., 'cg', 'constrained CG')
      ind%points = 2048**2
      ind%coupled = .true.
      ind%start_iterations = 40
      ind%metric_admitted = .true.
      call expect('distributed coupled 2048^2, hard start', ind, .true., 'multigrid+gcr+kept+anderson', &
         & 'its finest grid on the slabs')
      ind%start_iterations = 5
      call expect('distributed coupled 2048^2, easy start', ind, .true., 'gcr+kept+anderson', 'the constrained GCR')
      ind%points = 32**2
      call expect('distributed coupled 32^2 (no dense Newton)', ind, .true., 'gcr+kept+anderson', 'the constrained GCR')
      ind%method = 'anderson'
      call expect('distributed anderson', ind, .true., 'anderson', "method 'anderson'")
      ind%method = 'newton'
      call refused('distributed dense Newton', ind, 'runs on one MPI rank')
      ind%method = 'gcr'
      call expect('distributed gcr', ind, .true., 'gcr', '')
      ind%method = 'gfmd'
      call expect('distributed gfmd', ind, .true., 'gfmd', "method 'gfmd'")
      ind%method = 'multigrid'
      ind%points = 2048**2
      call expect('distributed multigrid by name', ind, .true., 'multigrid+gcr+kept+anderson', "method 'multigrid'")
      ind%multigrid_on_slabs = .false.
      call expect('distributed multigrid by name, gathered', ind, .true., 'multigrid+gcr+kept+anderson', &
         & 'gathered whole onto every rank')
   end subroutine check_distributed

   !> What the memory check provides for: every grid where some start could send the
   !> scene to the multigrid method.
   subroutine check_memory_view()
      call check(may_take_multigrid('auto', 4096, .true., .false., .false.), 'memory: symmetric line of 4096')
      call check(.not. may_take_multigrid('auto', 2048, .true., .false., .false.), 'memory: symmetric line of 2048')
      call check(may_take_multigrid('auto', 8192, .true., .true., .false.), 'memory: coupled line of 8192')
      call check(.not. may_take_multigrid('auto', 4096, .true., .true., .false.), 'memory: elastic coupled line of 4096')
      call check(may_take_multigrid('auto', 1024, .true., .true., .true.), 'memory: viscoelastic line of 1024')
      call check(may_take_multigrid('auto', 128**2, .false., .true., .true.), 'memory: viscoelastic surface of 128^2')
      call check(.not. may_take_multigrid('auto', 512**2, .false., .true., .false.), 'memory: elastic coupled surface of 512^2')
      call check(.not. may_take_multigrid('gcr', 2**20, .true., .true., .true.), 'memory: method gcr never')
      call check(may_take_multigrid('multigrid', 64, .true., .false., .false.), 'memory: method multigrid always')
   end subroutine check_memory_view

end program test_policy
