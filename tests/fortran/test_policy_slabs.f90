!> The policy's measures on the slabs of a surface shared among MPI ranks against the same
!> measures of the whole grid (lc_contact_solver_multigrid, lc_contact_multigrid_hierarchy,
!> lc_contact_policy; docs/decisions/028-distributed-multigrid.md). Run by
!> tests/test_mpi_multigrid.py under `mpirun -n P`, P = 1..4 (not by `meson test`: on one
!> rank there is no slab). Every rank builds the operator of the whole grid on a plan of its
!> own (serial) and the operator on its slab (the distributed plan, its rank's columns of the
!> transposed half spectrum), and checks that the measures of the slab, each taken on the
!> rank's modes and reduced over the ranks, are the whole grid's:
!>  - the compliance's rise along the axes (compliance_rise: its rows' walks go on from the
!>    lower ranks' columns);
!>  - the loss profile of a coupled operator (loss_of: the largest loss, at long waves, among
!>    the waves short along x, and the kx of its peak, which depends on the order of the
!>    modes: a sliding layer's loss ties along ky);
!>  - the Jacobi steps' and the row steps' worst smoothing factors over the grids of the
!>    V-cycle (worst_smoothing, worst_row_smoothing) of the real symbol 1/M and the complex
!>    one 1/G_eff read at the coarse grids' modes;
!>  - the refusals, the rows' rule, the loss among the short waves and the policy's
!>    indicators (measure_problem) they give.
!> Scenes: a thin incompressible layer with friction (its compliance rises), a compressible
!> one frictionless, standard linear solids sliding with and without friction at two speeds
!> (the loss peaking at long and among short waves); on 32 x 32 points (P = 3: columns of 11,
!> 11 and 11 of the 17; P = 4: 5, 5, 5 and 2) and 64 x 48 (halved along one axis first).
!>
!> Tolerance: none, bit for bit. The operators' multipliers are the same bits on both plans
!> (each mode computed from its own wavevector), and every reduction here is exact: maxima
!> and minima, a column's sum taken on the rank that holds it and the columns' sums added in
!> the order of kx on every rank (the whole grid's order too). A mode read at the wrong
!> index, a lower rank's walk left out, or a sum over the ranks in another order shows.
program test_policy_slabs
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_grid, only: surface_grid, grid_type
   use lc_base_parallel, only: parallel_start, parallel_end, this_rank
   use lc_greens_kernel, only: layer_kernel, make_kernel
   use lc_greens_viscoelastic, only: material_law
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_contact_multigrid_hierarchy, only: worst_smoothing, worst_row_smoothing, modes_of
   use lc_contact_solver_multigrid, only: compliance_rise, loss_profile, loss_of, multigrid_refusal, coupled_refusal, &
      & metric_refusal, rows_ahead_of_gcr, loss_among_short_waves
   use lc_contact_policy, only: problem_indicators, measure_problem
   use lc_base_strings, only: to_string
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   type(error_type), allocatable :: error
   type(material_law) :: elastic, sls, glassy

   call parallel_start(error)
   if (allocated(error)) error stop 2
   elastic%young = 1.0_wp
   sls%model = 'sls'
   sls%e0 = 1.0_wp
   sls%e_inf = 10.0_wp
   sls%tau = 1.0_wp
   glassy = sls
   glassy%e_inf = 100.0_wp
   call check_measures('thin incompressible layer, friction', make_kernel(0.05_wp, elastic, 0.5_wp, 0.0_wp), 0.5_wp, &
      & 32, 32)
   call check_measures('compressible layer, frictionless', make_kernel(0.16_wp, elastic, 0.3_wp, 0.0_wp), 0.0_wp, 32, 32)
   call check_measures('SLS sliding, V tau/lambda 0.1, friction', make_kernel(0.16_wp, sls, 0.5_wp, 0.1_wp), 0.5_wp, &
      & 32, 32)
   call check_measures('SLS sliding, V tau/lambda 0.1, frictionless', make_kernel(0.16_wp, sls, 0.5_wp, 0.1_wp), &
      & 0.0_wp, 32, 32)
   call check_measures('glassy SLS sliding, V tau/lambda 0.1, friction', make_kernel(0.16_wp, glassy, 0.5_wp, 0.1_wp), &
      & 0.5_wp, 32, 32)
   call check_measures('glassy SLS sliding, V tau/lambda 0.002, frictionless', &
      & make_kernel(0.16_wp, glassy, 0.5_wp, 0.002_wp), 0.0_wp, 64, 48)
   call check_measures('thin incompressible layer, friction, 64 x 48', make_kernel(0.05_wp, elastic, 0.5_wp, 0.0_wp), &
      & 0.5_wp, 64, 48)
   call finish('policy measures on slabs (rank ' // to_string(this_rank()) // ')')
   call parallel_end()

contains

   !> The checks of the program's header for the scene of `kernel` with Coulomb coefficient
   !> `friction` on nx x ny points.
   subroutine check_measures(what, kernel, friction, nx, ny)
      character(len=*), intent(in) :: what
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in) :: friction
      integer, intent(in) :: nx, ny
      type(compliance_operator) :: whole, slab
      type(grid_type) :: grid
      type(loss_profile) :: loss_whole, loss_slab
      real(wp), allocatable :: symbol_whole(:), odd_whole(:), symbol_slab(:), odd_slab(:)

      grid = surface_grid(nx, ny, 1.0_wp, real(ny, wp)/nx)
      call build_operator(whole, grid, kernel, friction, 1, error, distributed=.false.)
      if (.not. allocated(error)) call build_operator(slab, grid, kernel, friction, 1, error, distributed=.true.)
      if (allocated(error)) then
         call check(.false., what // ': ' // error%message)
         return
      end if
      call check(compliance_rise(slab) == compliance_rise(whole), what // ': the compliance''s rise (' // &
         & to_string(compliance_rise(whole)) // ') is the whole grid''s')

      ! the real symbol 1/M
      symbol_whole = inverse(whole%metric)
      symbol_slab = inverse(slab%metric)
      call check(worst_smoothing(nx, ny, symbol_slab, modes=modes_of(slab)) == worst_smoothing(nx, ny, symbol_whole) &
         & .and. worst_row_smoothing(nx, ny, symbol_slab, modes=modes_of(slab)) == &
         & worst_row_smoothing(nx, ny, symbol_whole), what // ': the smoothing factors of 1/M (' // &
         & to_string(worst_smoothing(nx, ny, symbol_whole)) // ', rows ' // &
         & to_string(worst_row_smoothing(nx, ny, symbol_whole)) // ') are the whole grid''s')

      call compare_refusals(what, whole, slab, .true.)
      call compare_refusals(what, whole, slab, .false.)

      if (.not. whole%coupled) return
      loss_whole = loss_of(whole)
      loss_slab = loss_of(slab)
      call check(loss_slab%largest == loss_whole%largest .and. loss_slab%long == loss_whole%long .and. &
         & loss_slab%short_x == loss_whole%short_x .and. loss_slab%peak == loss_whole%peak, what // &
         & ': the loss profile (largest ' // to_string(loss_whole%largest) // ' at kx = ' // &
         & to_string(loss_whole%peak) // ', long ' // to_string(loss_whole%long) // ', short ' // &
         & to_string(loss_whole%short_x) // ') is the whole grid''s')
      call check(loss_among_short_waves(slab) == loss_among_short_waves(whole), &
         & what // ': the loss among the short waves is the whole grid''s')

      ! the complex symbol 1/G_eff
      call complex_inverse(whole%full, symbol_whole, odd_whole)
      call complex_inverse(slab%full, symbol_slab, odd_slab)
      call check(worst_smoothing(nx, ny, symbol_slab, odd_slab, modes_of(slab)) == &
         & worst_smoothing(nx, ny, symbol_whole, odd_whole) .and. &
         & worst_row_smoothing(nx, ny, symbol_slab, odd_slab, modes_of(slab)) == &
         & worst_row_smoothing(nx, ny, symbol_whole, odd_whole), what // ': the smoothing factors of 1/G_eff (' // &
         & to_string(worst_smoothing(nx, ny, symbol_whole, odd_whole)) // ', rows ' // &
         & to_string(worst_row_smoothing(nx, ny, symbol_whole, odd_whole)) // ') are the whole grid''s')
   end subroutine check_measures

   !> The refusals, the rows' rule and the policy's indicators of the slab's operator against
   !> the whole grid's, under load control or displacement control.
   subroutine compare_refusals(what, whole, slab, load_control)
      character(len=*), intent(in) :: what
      type(compliance_operator), intent(in) :: whole, slab
      logical, intent(in) :: load_control
      type(problem_indicators) :: ind_whole, ind_slab
      character(len=:), allocatable :: control
      control = trim(merge(' (load control)        ', ' (displacement control)', load_control))
      call check(multigrid_refusal(slab) == multigrid_refusal(whole) .and. &
         & metric_refusal(slab) == metric_refusal(whole) .and. &
         & coupled_refusal(slab, load_control) == coupled_refusal(whole, load_control), &
         & what // control // ': the refusals are the whole grid''s ("' // coupled_refusal(whole, load_control) // '")')
      if (whole%coupled) call check(rows_ahead_of_gcr(slab, load_control) .eqv. rows_ahead_of_gcr(whole, load_control), &
         & what // control // ': the rows'' rule is the whole grid''s')
      ! (method 'multigrid' takes every measure before the start; 'auto' leaves some to it)
      ind_whole = measure_problem(whole, 'multigrid', load_control)
      ind_slab = measure_problem(slab, 'multigrid', load_control)
      call check(ind_slab%refusal == ind_whole%refusal .and. (ind_slab%rising .eqv. ind_whole%rising) .and. &
         & (ind_slab%metric_admitted .eqv. ind_whole%metric_admitted), &
         & what // control // ': the policy''s indicators are the whole grid''s')
   end subroutine compare_refusals

   !> 1/x where x > 0, else 0 (the stiffness of a compliance)
   pure function inverse(x) result(k)
      real(wp), intent(in) :: x(:)
      real(wp) :: k(size(x))
      where (x > 0.0_wp)
         k = 1.0_wp/x
      elsewhere
         k = 0.0_wp
      end where
   end function inverse

   !> The real and imaginary parts of 1/g (0 where g = 0)
   pure subroutine complex_inverse(g, re, im)
      complex(wp), intent(in) :: g(:)
      real(wp), allocatable, intent(out) :: re(:), im(:)
      complex(wp) :: k(size(g))
      where (abs(g) > 0.0_wp)
         k = 1.0_wp/g
      elsewhere
         k = (0.0_wp, 0.0_wp)
      end where
      re = real(k)
      im = aimag(k)
   end subroutine complex_inverse
end program test_policy_slabs
