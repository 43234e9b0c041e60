!> Truncated nonsmooth Newton multigrid (TNNMG) for the frictionless contact of a line or a
!> surface on an elastic half-space or layer: Graeser and Kornhuber, "Multigrid methods for
!> obstacle problems" (J. Comput. Math., 2009), and "Nonsmooth Newton methods for set-valued
!> saddle point problems" (SIAM J. Numer. Anal., 2009); and the same iteration for coupled
!> scenes (friction, sliding viscoelastic layers) with the non-symmetric stiffness
!> (coupled_tnnmg).
!>
!> Displacement form. With the stiffness K = 1/M (the inverse of the operator's real normal
!> compliance, mode by mode) and u the surface displacement seen from the rigid profile's
!> reference, the contact problem is the obstacle problem
!>    minimise J(u) = 1/2 u.K u + f sum(u)  subject to  u >= o,
!> whose optimality conditions are p = K u + f >= 0, gap = u - o >= 0, p gap = 0. Under load
!> control K(0) = 0 (the uniform mode is the rigid shift, see drop_uniform_mode), f = p_m and
!> o = b, so mean(p) = p_m holds by construction and no multiplier is iterated; under
!> displacement control K(0) = 1/M(0), f = 0 and o = b + s.
!>
!> One iteration on a grid: a projected damped Jacobi step (it releases every contact point
!> that carries tension at once, and lowers J); the truncated Newton problem K_II c_I = -p_I
!> (c = 0 on the contact set A), solved inexactly by at most two preconditioned CG
!> iterations; the direction projected onto u >= o and an exact line search (J is
!> quadratic). Both steps lower J, hence global convergence; the Newton step finds the
!> contact set in few iterations. Once the set has settled, a finishing CG phase solves the
!> linear problem on it and checks the complementarity residual at every iteration (going
!> on as a Newton step if a point leaves the set).
!>
!> The CG's preconditioner: a damped Jacobi step on the free points plus a coarse correction
!> by a V-cycle of Galerkin coarse operators whose penalty stands for the contact set
!> (lc_contact_multigrid_hierarchy). The Newton direction needs only to be a descent
!> direction, which is what lets the coarse operators be cheap.
!>
!> Nested iteration: the solve starts on the grid of every 2^J-th point (the coarsest of at
!> least nested_coarsest points), solved to tol from u = o; each finer grid starts from the
!> spectral interpolation of the coarser u and gets one iteration; the finest is iterated
!> to tol. The convergence measure is the library's complementarity residual
!> max_j |min(p_j/p_ref, gap_j/g_ref)| (gaps below the rounding floor count as zero),
!> evaluated on (K u + f, u - o) in the iteration and on the fields returned at the end.
!>
!> Applies where pointwise Jacobi smooths, i.e. the stiffness rises with |q| along each
!> axis (the operator's metric_falls, or nearly: allowed_rise), to symmetric (not coupled),
!> elastic lines and surfaces: multigrid_refusal; coupled ones whose metric passes
!> metric_refusal (a surface stiffer along one axis, a sliding viscoelastic layer, takes
!> grids halved along one axis, or smoothing by rows).
module lc_contact_solver_multigrid
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type
   use lc_base_memory, only: available_bytes
   use lc_base_strings, only: to_string, formatted
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_base_parallel, only: allgather_rows, slab, global_sum, global_max, global_any, sum_over_ranks, max_over_ranks, &
      & min_over_lower_ranks, max_over_lower_ranks
   use lc_base_threads, only: active_threads
   use lc_contact_multigrid_hierarchy, only: hierarchy, omega, jacobi_margin, coarsest_points, coarsest_limit, &
      & build_hierarchy, halvings, level_symbol, set_grid, set_contact, sample, interpolate, precondition, worst_smoothing, &
      & apply_stiffness, worst_row_smoothing, accepted_smoothing, across_ranks, interpolate_onto_slab, sampled_symbol, &
      & held_modes, modes_of, held_index
   use lc_contact_residual, only: complementarity_residual, rounding_floor, normalise
   use lc_contact_progress, only: progress_log
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   implicit none (type, external)
   private
   public :: multigrid_solver, multigrid, multigrid_outcome, multigrid_refusal, metric_refusal, coupled_refusal, coupled_tnnmg
   public :: size_refusal
   public :: allowed_rise, rows_ahead_of_gcr, loss_among_short_waves, short_loss_limit, whole_operator, solves_on_slabs
   public :: compliance_rise, loss_profile, loss_of, orthogonalise, orthogonalise_over_ranks

   !> Jacobi smooths K_II where the stiffness rises with |q|; a compliance that falls with |q|
   !> (op%metric_falls) is more than needed: it may rise over the grid by up to this factor
   !> relative to a longer wave (docs/decisions/009-multigrid-for-symmetric-lines.md,
   !> 'Where it applies, and the choice under 'auto'').
   real(wp), parameter :: allowed_rise = 4.0_wp
   !> A coupled scene whose compliance rises more is admitted (coupled_refusal) if its
   !> hierarchy's worst Jacobi smoothing factor is at most this: thin incompressible layers
   !> up to h/lambda ~ 0.01 (docs/decisions/014-thin-layers-by-multigrid.md, 'Measured').
   real(wp), parameter :: coupled_smoothing = 0.995_wp
   !> A coupled surface is smoothed by rows (rows_smooth) where the Jacobi steps' worst
   !> smoothing factor exceeds this and the rows' is at most accepted_smoothing: a layer
   !> sliding along x, whose modulus changes with q_x V, which Jacobi steps smooth poorly
   !> (docs/decisions/015-row-smoothing.md, 'What is done'; docs/numerics.md, 'Constants of
   !> the solvers and their measurements').
   real(wp), parameter :: row_smoothing = 0.85_wp
   !> A grid with more than twice as many points along x as along y is smoothed by rows
   !> (grids halved along x alone until square: row_shapes) only where the Jacobi steps'
   !> worst smoothing factor exceeds this (glassy layers): rows halving both axes stall
   !> there (docs/decisions/015-row-smoothing.md, 'What is done', 'Elongated grids').
   real(wp), parameter :: elongated_row_smoothing = 0.98_wp
   !> A coupled surface whose loss is not largest at long waves builds K's own hierarchy,
   !> smoothed by rows, where its loss among the waves short along x is at most this; above,
   !> the metric's, where rows on K's stall (coupled_symbol; docs/decisions/015-row-smoothing.md,
   !> 'What is done': 'A moderate loss among the short waves', 'A larger loss ...').
   real(wp), parameter :: short_loss_limit = 3.0_wp
   !> ... and a larger loss peaking in the grid's top band, short of its edge, is smoothed by
   !> rows on the metric's hierarchy only up to this loss, on grids no longer along x than
   !> across: rows stall beyond it (docs/decisions/015-row-smoothing.md, 'What is done':
   !> 'A larger loss among the short waves').
   real(wp), parameter :: top_band_loss = 5.0_wp
   !> A surface whose loss peaks at long waves takes K's own hierarchy; a loss above this one
   !> only while its peak lies at |kx| <= nx/48 or below glassy_peak_mode: nearer the long
   !> band's edge K's wanders and the metric's converges; lines keep K's at every loss
   !> (docs/decisions/015-row-smoothing.md, 'Very glassy layers whose loss peaks near the long
   !> band's edge').
   real(wp), parameter :: glassy_long_loss = 10.0_wp
   !> ... and a peak below this mode keeps K's hierarchy on any grid (the same section of
   !> docs/decisions/015-row-smoothing.md).
   integer, parameter :: glassy_peak_mode = 16
   !> The nested iteration starts on the coarsest grid of at least this many points.
   integer, parameter :: nested_coarsest = 256
   !> The inexact Newton solve: at most this many CG iterations, or a residual reduced by
   !> newton_reduction; more exact solves cost more transforms than the iterations saved
   !> (docs/decisions/009-multigrid-for-symmetric-lines.md, 'Measured').
   integer, parameter :: newton_iterations = 2
   real(wp), parameter :: newton_reduction = 0.1_wp
   !> The finishing phase starts when no contact point carries tension and at most this
   !> fraction of the contact set changed in the last iteration ...
   real(wp), parameter :: settled_fraction = 1.0e-3_wp
   !> ... and runs at most this many CG iterations. When a point leaves the feasible set it
   !> goes on as a Newton step until its residual fell by violated_reduction, so that the
   !> points leaving the set are handled together (docs/decisions/011-multigrid-for-surfaces.md,
   !> 'The finishing phase does not stop at the first point that leaves the set').
   integer, parameter :: finish_iterations = 40
   real(wp), parameter :: violated_reduction = 0.1_wp
   !> If the fields returned miss tol (their residual is evaluated on the pressure with the
   !> points out of contact set to zero), the iteration goes on to a tolerance this much
   !> smaller, at most `tightenings` times.
   real(wp), parameter :: tightening = 0.1_wp
   integer, parameter :: tightenings = 3
   !> coupled_tnnmg: directions kept by the GCR on the truncated Newton problem (restarted
   !> when full).
   integer, parameter :: gcr_memory = 10
   !> ... On a line whose finishing GCR stagnates (a strongly non-normal K) the directions
   !> kept double up to this many (twice that in the exact Newton steps) where half the memory
   !> available holds them; a surface keeps gcr_memory, its Gram-Schmidt passes outweighing
   !> the transforms saved (docs/decisions/012-coupled-multigrid.md, 'Very glassy lines: exact
   !> Newton steps after a stall'; docs/numerics.md, 'Constants of the solvers and their
   !> measurements').
   integer, parameter :: longest_gcr_memory = 40
   !> coupled_tnnmg: iterations without the residual halving after which it stops, or (a very
   !> lossy material: exact_loss) goes on with exact Newton steps taken in full, GCR to a
   !> residual reduced by exact_reduction in at most exact_iterations, where the line search
   !> crawls on a strongly non-symmetric K (docs/decisions/012-coupled-multigrid.md, 'Very
   !> glassy lines: exact Newton steps after a stall').
   integer, parameter :: coupled_stall = 30
   integer, parameter :: exact_iterations = 20
   real(wp), parameter :: exact_reduction = 0.01_wp
   !> ... The exact steps are taken where the material's loss tangent on the grid's sliding
   !> frequencies reaches this (material_loss); below, the GCR goes on at once: the exact
   !> steps cost more there and converge nothing it does not (docs/decisions/012-coupled-multigrid.md,
   !> 'Very glassy lines: exact Newton steps after a stall').
   real(wp), parameter :: exact_loss = 10.0_wp

   !> What one multigrid solve did. `iterations` counts the TNNMG iterations on the finest
   !> grid (a finishing CG phase counts as one); `fft_pairs` every transform pair on every
   !> grid, a pair of m points counting m/n, the nested iteration's grids included.
   type :: multigrid_outcome
      logical :: converged = .false.
      integer :: iterations = 0
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
      integer :: vcycles = 0   !< preconditioner applications (each a V-cycle of the coarser grids)
   end type multigrid_outcome

   !> The work arrays of the iterations, allocated once for the finest grid (the nested
   !> grids use their first points): the Newton direction c and K c, and the CG's three
   !> (which the projected line search reuses).
   type :: workspace
      real(wp), allocatable :: c(:), kc(:), cg(:, :)
   end type workspace

   !> The loss |Im K|/Re K of a coupled scene over its modes (loss_of): the largest and the
   !> |kx| where it is reached (a peak beyond the grid lies at its edge), the largest over
   !> the long waves (|kx| <= nx/16 and, on a surface, |ky| <= ny/16) and over the waves
   !> short along x (|kx| > nx/16, at any ky: a sliding layer's loss depends on kx alone; a
   !> standard linear solid's peaks at (E_inf/E0 - 1)/(2 sqrt(E_inf/E0))).
   type :: loss_profile
      real(wp) :: largest = 0.0_wp, long = 0.0_wp, short_x = 0.0_wp
      integer :: peak = 0
   end type loss_profile

   !> The scales of the residual, from the last full evaluation of the state.
   type :: residual_scales
      real(wp) :: p_scale = 1.0_wp, g_scale = 1.0_wp, floor = 0.0_wp
   end type residual_scales


   !> Method 'multigrid': the TNNMG iteration on the metric's hierarchy for a symmetric
   !> operator (multigrid), on K = 1/G_eff for a coupled one or for a compliance rising too
   !> steeply for the symmetric form (coupled_tnnmg; coupled_refusal admits the scene).
   type, extends(contact_solver) :: multigrid_solver
   contains
      procedure :: solve => solve_by_multigrid
      procedure :: name => multigrid_name
   end type multigrid_solver

contains

   !> Why the method cannot solve the scene of `op` (empty if it can).
   function multigrid_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      if (op%kernel%viscoelastic) then
         reason = 'the layer is viscoelastic and sliding (its compliance is complex)'
      else if (op%coupled) then
         reason = 'friction couples the normal and tangential fields and the operator is not symmetric'
      else
         reason = metric_refusal(op)
      end if
   end function multigrid_refusal

   !> Why the hierarchy of the operator's metric M = |G_eff| cannot precondition the method
   !> (empty if it can): multigrid_refusal without the refusal of coupled and viscoelastic
   !> operators, which coupled_tnnmg solves.
   function metric_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      reason = rise_refusal(op)
      if (len(reason) == 0) reason = size_refusal(op)
   end function metric_refusal

   !> Why the coupled multigrid method (coupled_tnnmg) cannot solve the scene of `op` (empty
   !> if it can): metric_refusal, except that a compliance rising with |q| is admitted where
   !> the hierarchy the method builds (coupled_symbol) still smooths on every grid, its
   !> worst Jacobi smoothing factor at most coupled_smoothing: a thin incompressible layer
   !> whose stiff long waves lie on the coarsest grid (with friction or without: the
   !> iteration takes a symmetric stiffness as well).
   function coupled_refusal(op, load_control) result(reason)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      character(len=:), allocatable :: reason
      real(wp), allocatable :: symbol(:), odd(:)
      real(wp) :: worst
      logical :: complex_symbol, rows
      reason = size_refusal(op)
      if (len(reason) > 0) return
      reason = rise_refusal(op)
      if (len(reason) == 0) return
      call coupled_symbol(op, load_control, symbol, odd, complex_symbol, rows)
      if (complex_symbol) then
         worst = worst_smoothing(op%grid%nx, op%grid%ny, symbol, odd, modes_of(op))
      else
         worst = worst_smoothing(op%grid%nx, op%grid%ny, symbol, modes=modes_of(op))
      end if
      if (worst <= coupled_smoothing) then
         reason = ''
      else
         reason = reason // ', and the Jacobi step would smooth with a factor ' // &
            & formatted(worst, '(f6.4)') // ' on its coarse grids (at most ' // formatted(coupled_smoothing, '(f5.3)') // ')'
      end if
   end function coupled_refusal

   !> The refusal of a compliance that rises with |q| along an axis by more than allowed_rise.
   function rise_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      real(wp) :: rise
      reason = ''
      rise = 1.0_wp
      if (.not. op%metric_falls) rise = compliance_rise(op)
      if (rise > allowed_rise) reason = 'the compliance rises with |q| over the grid by a factor ' // &
         & formatted(rise, '(f0.1)') // ' (a thin, nearly incompressible layer; pointwise smoothing needs at most ' // &
         & formatted(allowed_rise, '(f0.1)') // ')'
   end function rise_refusal

   !> The refusal of a grid whose coarsest grid would have more than coarsest_limit points.
   function size_refusal(op) result(reason)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: reason
      integer :: m, k
      reason = ''
      k = halvings(op%grid%nx, op%grid%ny, coarsest_points)
      m = op%grid%points()/2**(k*merge(1, 2, op%grid%is_line()))
      if (m <= coarsest_limit) return
      if (op%grid%is_line()) then
         reason = 'n = ' // to_string(op%grid%nx) // ' halves to an odd grid of ' // to_string(m) // &
            & ' points; it needs n = m 2^k with m <= ' // to_string(coarsest_limit)
      else
         reason = 'the ' // to_string(op%grid%nx) // ' x ' // to_string(op%grid%ny) // ' grid halves to one of ' &
            & // to_string(op%grid%nx/2**k) // ' x ' // to_string(op%grid%ny/2**k) // ' points; it needs ' // &
            & 'nx, ny = mx 2^k, my 2^k with mx my <= ' // to_string(coarsest_limit)
      end if
   end function size_refusal

   !> Whether the coupled method smooths the scene of `op` by rows (row_smoothing) where its
   !> Jacobi steps smooth poorly and GCR is slow: a surface sliding on a viscoelastic layer
   !> whose loss of K lies at long waves (loss_at_long_waves), or that is large among the
   !> short waves (the metric's hierarchy smoothed by rows, short_loss_limit). Slower
   !> sliding, smoothed by rows for its moderate loss among the short waves, is not one.
   logical function rows_ahead_of_gcr(op, load_control) result(rows)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      real(wp), allocatable :: symbol(:), odd(:)
      logical :: complex_symbol
      call coupled_symbol(op, load_control, symbol, odd, complex_symbol, rows)
      rows = rows .and. (loss_at_long_waves(op) .or. .not. complex_symbol)
   end function rows_ahead_of_gcr

   !> The rule of row_smoothing for the stiffness symbol (+ i odd) of the grid of `op` on the
   !> modes op holds (modes_of); `odd` not allocated (so absent) for a real symbol.
   logical function rows_smooth(op, symbol, odd) result(rows)
      type(compliance_operator), intent(in) :: op
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      type(held_modes) :: modes
      rows = .false.
      if (op%grid%is_line()) return
      modes = modes_of(op)
      ! (the rows' factor only where the Jacobi steps smooth poorly: an elastic surface with
      ! friction is decided by the cheaper one; on rows of more than twice as many points as
      ! there are rows, only where they barely smooth: see elongated_row_smoothing)
      if (worst_smoothing(op%grid%nx, op%grid%ny, symbol, odd, modes) <= &
         & merge(elongated_row_smoothing, row_smoothing, op%grid%nx > 2*op%grid%ny)) return
      rows = worst_row_smoothing(op%grid%nx, op%grid%ny, symbol, odd, modes) <= accepted_smoothing
   end function rows_smooth

   !> The stiffness symbol the coupled method's hierarchy is built on (half spectrum of the
   !> grid): K = 1/G_eff itself (symbol + i odd) where its loss lies at long waves
   !> (loss_at_long_waves; on a surface a loss above glassy_long_loss only where it peaks at
   !> |kx| <= nx/48 or below glassy_peak_mode), or where the loss among the waves short
   !> along x is at most short_loss_limit and the grid is smoothed by rows (rows_smooth);
   !> else the metric's 1/|G_eff| (level_symbol), smoothed by rows only for a larger loss
   !> peaking at the grid's edge or in its top band (see short_loss_limit, top_band_loss).
   !> rows: whether the grid is smoothed by rows. A distributed `op`: the symbol on its rank's
   !> modes (modes_of), the decisions the whole grid's (every measure reduced over the ranks).
   subroutine coupled_symbol(op, load_control, symbol, odd, complex_symbol, rows)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      real(wp), allocatable, intent(out) :: symbol(:), odd(:)
      logical, intent(out) :: complex_symbol, rows
      complex(wp), allocatable :: stiffness(:)
      type(loss_profile) :: loss
      logical :: long, large
      long = .false.
      large = .false.
      if (op%coupled) then
         loss = loss_of(op)
         long = at_long_waves(loss)
         if (long .and. .not. op%grid%is_line()) &
            & long = loss%largest <= glassy_long_loss .or. 48*loss%peak <= op%grid%nx .or. &
            & loss%peak < glassy_peak_mode
         large = .not. long .and. .not. op%grid%is_line() .and. loss%short_x > short_loss_limit
      end if
      complex_symbol = long .or. (op%coupled .and. .not. op%grid%is_line() .and. .not. large)
      rows = .false.
      if (complex_symbol) then
         allocate (stiffness(op%nk))
         where (abs(op%full) > 0.0_wp)
            stiffness = 1.0_wp/op%full
         elsewhere
            stiffness = (0.0_wp, 0.0_wp)
         end where
         symbol = real(stiffness)
         odd = aimag(stiffness)
         rows = rows_smooth(op, symbol, odd)
         ! (a loss among the short waves: K's hierarchy only where it is smoothed by rows)
         complex_symbol = long .or. rows
         if (complex_symbol) return
         deallocate (symbol, odd)
      end if
      symbol = finest_symbol(op, load_control)
      ! (a large loss peaking at the grid's edge or beyond it, or, if at most top_band_loss,
      ! among the other modes no coarser grid carries; on grids no longer along x than
      ! across: see top_band_loss)
      if (large .and. op%grid%nx <= op%grid%ny) then
         if (2*(loss%peak + 1) >= op%grid%nx .or. &
            & (4*loss%peak > op%grid%nx .and. loss%short_x <= top_band_loss)) rows = rows_smooth(op, symbol)
      end if
   end subroutine coupled_symbol

   !> level_symbol of the grid of `op` itself, on the modes op holds: K = 1/M mode by mode (0
   !> where M = 0, and at the uniform mode under load control).
   function finest_symbol(op, load_control) result(stiffness)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      real(wp) :: stiffness(op%nk)
      type(held_modes) :: modes
      modes = modes_of(op)
      where (op%metric > 0.0_wp)
         stiffness = 1.0_wp/op%metric
      elsewhere
         stiffness = 0.0_wp
      end where
      ! (the uniform mode: the first of the rank holding the column kx = 0)
      if (load_control .and. modes%x_start == 0 .and. op%nk > 0) stiffness(1) = 0.0_wp
   end function finest_symbol

   !> The symbol (`part`: its real or imaginary part) held on the modes of the distributed
   !> `op`, on the whole half spectrum on every rank: each rank's modes, summed over the ranks
   !> (each mode is one rank's, so the sum is exact). What the hierarchy is built on.
   function whole_symbol(op, part) result(whole)
      type(compliance_operator), intent(in) :: op
      real(wp), contiguous, intent(in) :: part(:)
      real(wp), allocatable :: whole(:)
      integer :: i, mx, my
      allocate (whole(op%grid%modes()))
      whole = 0.0_wp
      do i = 1, op%nk
         call op%fft%mode_indices(i, mx, my)
         whole(mx + (op%grid%nx/2 + 1)*my + 1) = part(i)
      end do
      call sum_over_ranks(whole)
   end function whole_symbol

   !> TNNMG iterations on the finest grid from u until the fields returned (p, w, gap, s;
   !> returned_fields) meet tol: where they miss it the iteration goes on to a smaller
   !> tolerance, at most `tightenings` times and while the residual of the fields halves.
   !> The outcome's counts.
   subroutine finest_iterations(h, work, op, u, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, &
         & outcome, history, progress)
      type(hierarchy), intent(inout) :: h
      type(workspace), intent(inout) :: work
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(inout) :: u(:)
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref, tol
      real(wp), intent(inout) :: s
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:), w(:), gap(:)
      type(multigrid_outcome), intent(inout) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      real(wp) :: target, before
      integer :: steps, tightened
      logical :: converged
      target = tol
      tightened = 0
      before = huge(1.0_wp)
      do
         ! (w holds the obstacle until the fields are returned)
         w = b
         if (.not. load_control) w = w + s
         call tnnmg(h, work, op, u, w, merge(mean_pressure, 0.0_wp, load_control), load_control, g_ref, target, &
            & max_iter - outcome%iterations, p, steps, converged, history(outcome%iterations + 1:), progress)
         outcome%iterations = outcome%iterations + steps
         call returned_fields(op, u, b, load_control, mean_pressure, g_ref, p, w, gap, s, outcome%residual)
         h%pairs = h%pairs + 1.0_wp
         if (outcome%iterations > 0) history(min(outcome%iterations, size(history))) = outcome%residual
         if (outcome%residual <= tol .or. outcome%iterations >= max_iter .or. tightened == tightenings) exit
         ! (a residual that did not halve is the rescaling's, near the rounding floor: the
         ! caller finishes)
         if (outcome%residual > 0.5_wp*before) exit
         before = outcome%residual
         target = target*tightening
         tightened = tightened + 1
      end do
      outcome%converged = outcome%residual <= tol
      outcome%fft_pairs = nint(h%pairs)
      outcome%vcycles = h%vcycles
   end subroutine finest_iterations

   !> The largest factor by which the normal compliance M(q) exceeds its value at a longer
   !> wave along the same axis: walking each row of the half spectrum from kx = 0 to nx/2
   !> and (a surface) each column from ky = 0 to +-ny/2. 1 where it falls with |q|
   !> (op%metric_falls). Along the axes, not by |q|: a sliding viscoelastic layer is stiffer
   !> along the sliding direction, tenfold between modes of one |q|, which the grids halved
   !> along one axis handle (coarsening_shapes); a rise along an axis is what pointwise
   !> smoothing cannot. A distributed op walks its rank's columns (whole columns), and its
   !> rows' walks go on from the least compliance of each row on the lower ranks' columns
   !> (min_over_lower_ranks): the same minima and ratios as one walk of the whole row.
   real(wp) function compliance_rise(op) result(rise)
      type(compliance_operator), intent(in) :: op
      type(held_modes) :: modes
      real(wp), allocatable :: lowest(:)
      integer :: nkx, ny, kx, ky, sign, step, last, i
      rise = 1.0_wp
      if (op%grid%modes() < 3) return
      modes = modes_of(op)
      nkx = op%grid%nx/2 + 1
      ny = op%grid%ny
      last = modes%x_start + modes%columns - 1
      ! the rows (kx in order within each row; the walk's least value so far a row each)
      allocate (lowest(0:ny - 1))
      if (modes%distributed) then
         lowest = huge(1.0_wp)
         do kx = modes%x_start, last
            do ky = 0, ny - 1
               i = (kx - modes%x_start)*ny + ky + 1
               if (.not. (kx == 0 .and. ky == 0) .and. op%metric(i) > 0.0_wp) lowest(ky) = min(lowest(ky), op%metric(i))
            end do
         end do
         call min_over_lower_ranks(lowest)
         do kx = modes%x_start, last
            do ky = 0, ny - 1
               call walk(kx, ky, lowest(ky), rise)
            end do
         end do
      else
         lowest = huge(1.0_wp)
         do ky = 0, ny - 1
            do kx = 0, nkx - 1
               call walk(kx, ky, lowest(ky), rise)
            end do
         end do
      end if
      ! the columns, each whole on the rank holding it
      if (ny > 1) then
         do kx = modes%x_start, last
            do sign = -1, 1, 2
               lowest(0) = huge(1.0_wp)
               do step = 0, ny/2
                  call walk(kx, sign*step, lowest(0), rise)
               end do
            end do
         end do
      end if
      if (modes%distributed) rise = global_max(rise)
   contains
      pure subroutine walk(kx, ky, lowest, rise)
         integer, intent(in) :: kx, ky
         real(wp), intent(inout) :: lowest, rise
         integer :: i
         ! (the uniform mode has no compliance of its own)
         if (kx == 0 .and. modulo(ky, ny) == 0) return
         if (modes%distributed) then
            i = (kx - modes%x_start)*ny + modulo(ky, ny) + 1
         else
            i = kx + nkx*modulo(ky, ny) + 1
         end if
         if (.not. op%metric(i) > 0.0_wp) return
         lowest = min(lowest, op%metric(i))
         rise = max(rise, op%metric(i)/lowest)
      end subroutine walk
   end function compliance_rise

   !> Solve the frictionless contact of a line or surface: w = M p, gap = w - b - s >= 0, p >= 0,
   !> p gap = 0, under load control (mean(p) = p_m, s found) or displacement control (s
   !> given). p: out the solution (on entry not used: the nested iteration makes its own
   !> start); w = M p; gap. history(1:outcome%iterations) receives the residual of each
   !> fine-grid iteration. The scene must pass multigrid_refusal.
   subroutine multigrid(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, history, &
         & progress, error)
      type(compliance_operator), intent(inout), target :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure   !< p_m (load control; ignored otherwise)
      real(wp), intent(inout) :: s            !< in: given (displacement control); out: found
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(multigrid_outcome), intent(out) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(hierarchy), target :: h
      type(workspace) :: work
      real(wp), allocatable :: u(:)
      real(wp) :: f
      integer :: n, j, nested, m, mc, steps
      logical :: converged

      n = size(p)
      call build_hierarchy(h, op, error)
      if (allocated(error)) return
      allocate (u(n), work%c(n), work%kc(n), work%cg(n, 3))
      f = merge(mean_pressure, 0.0_wp, load_control)

      ! (until the fields are returned w holds the obstacle o of the grid being solved, and
      ! gap is scratch)
      associate (o => w)
      nested = halvings(op%grid%nx, op%grid%ny, nested_coarsest)
      do j = nested, 0, -1
         m = h%level(j)%n
         call set_grid(h, j, level_symbol(op, load_control, h%level(j)%nx, h%level(j)%ny))
         call obstacle(j, o(1:m))
         if (j == nested) then
            u(1:m) = o(1:m)
         else
            mc = h%level(j + 1)%n
            gap(1:mc) = u(1:mc)   ! (a copy: the interpolation writes over u)
            call interpolate(h, j, gap(1:mc), u(1:m))
         end if
         if (j == 0) exit
         ! the coarsest grid to tol, the others one iteration each
         call tnnmg(h, work, op, u(1:m), o(1:m), f, load_control, g_ref, tol, merge(max_iter, 1, j == nested), &
            & p(1:m), steps, converged)
      end do
      end associate

      ! the finest grid, to tol on the fields returned
      call finest_iterations(h, work, op, u, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, &
         & outcome, history, progress)
   contains
      !> o = the obstacle on the grid of every 2^j-th point: b there (plus s under
      !> displacement control)
      subroutine obstacle(j, o)
         integer, intent(in) :: j
         real(wp), contiguous, intent(out) :: o(:)
         call sample(b, h%level(0)%nx, h%level(0)%ny, 2**j, o)
         if (.not. load_control) o = o + s
      end subroutine obstacle
   end subroutine multigrid

   !> Coupled contact (friction, or a sliding viscoelastic layer) in the displacement form
   !> with the non-symmetric stiffness K = 1/G_eff: u >= o, p = K u + f >= 0, p (u - o) = 0.
   !> The TNNMG iteration of the symmetric solver with K in place of the symmetric stiffness:
   !> projected damped Jacobi (d the real-space diagonal of Re K, or more: jacobi_margin), the
   !> truncated Newton problem
   !> I K I c = -I p by GCR right-preconditioned by the symmetric multigrid preconditioner of
   !> the metric |G_eff| (the hierarchy's, whose penalty stands for the contact set), the
   !> direction projected onto u >= o and its step from the quadratic model of the symmetric
   !> part. Where its residual has not halved in coupled_stall iterations it stops, or, on a
   !> very lossy material (exact_loss), goes on from its best iterate with exact Newton
   !> steps taken in full (a primal-dual active set iteration) and stops when those stall
   !> too. p: in, the
   !> start (the coarse start's interpolated solution, or the caller's guess); out, the
   !> solution, or the best iterate if it did not converge. The metric must pass
   !> metric_refusal. A distributed op (solves_on_slabs): p, w, gap and b are its slab, the
   !> finest grid's iteration on the slabs (docs/decisions/028-distributed-multigrid.md).
   subroutine coupled_tnnmg(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, &
         & history, progress, error)
      type(compliance_operator), intent(inout), target :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure
      real(wp), intent(inout) :: s
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(multigrid_outcome), intent(out) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(hierarchy), target :: h
      type(residual_scales) :: scales
      real(wp), allocatable :: u(:), o(:), c(:), kc(:), v(:), kv(:), dirs(:, :), kdirs(:, :), r(:), u_best(:)
      real(wp), allocatable :: symbol(:), odd(:)
      logical :: complex_symbol
      real(wp) :: f, d, b_max, residual, contact, best, best_residual, points
      integer :: n, step, changed, j, last_progress, memory
      logical :: settled, finished, clipped, tension, stagnated, exact
      logical :: rows, global

      n = size(p)
      ! (op on a slab of a distributed surface: the iteration's sums and maxima over the
      ! ranks, points the whole grid's; the symbol of the hierarchy chosen on the ranks' modes
      ! and gathered whole: whole_symbol)
      global = op%distributed
      points = merge(real(op%grid%points(), wp), real(n, wp), global)
      call op%prepare_gcr()
      ! (a surface's grids halved along the axes its symbol needs, or smoothed by rows)
      ! (the grids' shapes measured on the modes op holds, the symbol then held whole)
      call coupled_symbol(op, load_control, symbol, odd, complex_symbol, rows)
      if (complex_symbol) then
         call build_hierarchy(h, op, error, symbol, odd, rows=rows, modes=modes_of(op))
      else
         call build_hierarchy(h, op, error, symbol, rows=rows, modes=modes_of(op))
      end if
      if (allocated(error)) return
      if (global) then
         symbol = whole_symbol(op, symbol)
         if (complex_symbol) odd = whole_symbol(op, odd)
      end if
      if (complex_symbol) then
         call set_grid(h, 0, symbol, odd)
      else
         call set_grid(h, 0, symbol)
      end if
      ! (GCR takes a preconditioner that is not symmetric: a surface smooths only after the
      ! coarse correction, V(0,1), which saves transforms there; a line keeps V(1,1), whose
      ! pairs stay flat in the grid: docs/decisions/012-coupled-multigrid.md, 'The cost of a
      ! GCR iteration, and the sawtooth cycle')
      h%sawtooth = .not. op%grid%is_line()
      ! (the Jacobi diagonal: see jacobi_margin; modes with Re K <= 0 are not damped by any)
      d = op%inverse_diagonal
      do j = 1, op%nk
         if (real(op%inverse_full(j)) > 0.0_wp) &
            & d = max(d, jacobi_margin*omega*abs(op%inverse_full(j))**2/(2*real(op%inverse_full(j))))
      end do
      if (global) d = global_max(d)
      memory = gcr_memory
      allocate (u(n), o(n), c(n), kc(n), v(n), kv(n), r(n), u_best(n), dirs(n, memory), kdirs(n, memory))
      f = merge(mean_pressure, 0.0_wp, load_control)
      o = b
      if (.not. load_control) o = o + s
      b_max = maxval(abs(o))
      if (global) b_max = global_max(b_max)
      ! the start: u = G p, less (load control) the mean of G p - b over p's contact set
      call op%apply_full(p, u)
      h%pairs = h%pairs + 1.0_wp
      if (global) then
         if (load_control .and. global_any(any(p > 0.0_wp))) then
            s = global_sum(sum(u - b, mask=p > 0.0_wp))/global_sum(count(p > 0.0_wp))
            u = u - s
         end if
      else if (load_control .and. any(p > 0.0_wp)) then
         s = sum(u - b, mask=p > 0.0_wp)/count(p > 0.0_wp)
         u = u - s
      end if
      u = max(u, o)
      call apply_k(u, p)
      h%free = 1.0_wp
      outcome%iterations = 0
      best = huge(1.0_wp)
      best_residual = huge(1.0_wp)
      last_progress = 0
      exact = .false.
      do step = 1, max_iter
         outcome%iterations = step
         u = max(o, u - (omega/d)*p)
         call apply_k(u, p)
         scales = scales_of(u, p, load_control, f, g_ref, b_max, op%largest, global)
         call examine(u, p, o, scales, h%free(1:n), residual, contact, changed, tension)
         if (global) call examine_over_ranks(n, residual, contact, changed, tension)
         if (step <= size(history)) history(step) = residual
         call progress%tick(step, residual, contact)
         if (residual <= tol) exit
         if (residual < best_residual) then
            best_residual = residual
            u_best = u
         end if
         if (residual < 0.5_wp*best) then
            best = residual
            last_progress = step
         else if (step - last_progress > coupled_stall) then
            ! (the non-symmetric part defeats the iteration: strongly glassy layers)
            if (exact .or. material_loss(op) < exact_loss) exit
            exact = .true.
            best = best_residual
            last_progress = step
            u = u_best
            call apply_k(u, p)
            call examine(u, p, o, scales, h%free(1:n), residual, contact, changed, tension)
            if (global) call examine_over_ranks(n, residual, contact, changed, tension)
            changed = max(changed, 1)
         end if
         if (load_control .and. contact == 0.0_wp) then
            if (global) then
               u = u + global_max(maxval(o - u))
            else
               u = u - minval(u - o)
            end if
            cycle
         end if
         settled = step > 1 .and. changed <= settled_fraction*contact*points .and. .not. tension
         if (changed > 0 .or. step == 1) call set_contact(h)
         finished = .false.
         if (settled) then
            call truncated_gcr(max(finish_iterations, memory), 0.0_wp, .true.)
            if (stagnated) call lengthen_memory()
         else if (exact) then
            call truncated_gcr(exact_iterations, exact_reduction, .false.)
         else
            call truncated_gcr(newton_iterations, newton_reduction, .false.)
         end if
         if (finished) then
            u = u + c
            p = p + kc
            if (step <= size(history)) history(step) = residual
            exit
         end if
         call project_direction(u, o, c, v, clipped)
         if (global) clipped = global_any(clipped)
         if (clipped) then
            call apply_k(v, kv, shift=0.0_wp)
         else
            kv = kc
         end if
         if (exact) then
            u = u + v
            p = p + kv
         else if (global) then
            call line_step(v, kv, global_sum(dot_product(v, kv)), u, p, global_sum(dot_product(p, v)))
         else
            call line_step(v, kv, dot_product(v, kv), u, p)
         end if
      end do
      if (.not. (residual <= tol) .and. best_residual < residual) then
         u = u_best
         call apply_k(u, p)
      end if
      ! the fields: p where it is the larger term of the residual, w = G p
      w = o
      call returned_fields(op, u, b, load_control, mean_pressure, g_ref, p, w, gap, s, outcome%residual, full=.true.)
      h%pairs = h%pairs + 1.0_wp
      ! (the history ends on the residual of the fields returned, as the other solvers' do)
      if (outcome%iterations > 0) history(min(outcome%iterations, size(history))) = outcome%residual
      outcome%converged = outcome%residual <= tol
      outcome%fft_pairs = nint(h%pairs)
      outcome%vcycles = h%vcycles
   contains
      !> Doubles the GCR's directions on a line (up to longest_gcr_memory, twice that in the
      !> exact Newton steps) if their arrays fit in half the memory available.
      subroutine lengthen_memory()
         integer(i8) :: available
         character(len=:), allocatable :: limit
         integer :: longer
         if (.not. op%grid%is_line()) return
         longer = min(2*memory, merge(2*longest_gcr_memory, longest_gcr_memory, exact))
         if (longer == memory) return
         call available_bytes(available, limit)
         if (16_i8*(longer - memory)*n > available/2) return
         memory = longer
         deallocate (dirs, kdirs)
         allocate (dirs(n, memory), kdirs(n, memory))
      end subroutine lengthen_memory

      !> y = K x + shift (f by default): a transform pair of the finest grid
      subroutine apply_k(x, y, shift)
         real(wp), contiguous, intent(in) :: x(:)
         real(wp), contiguous, intent(out) :: y(:)
         real(wp), intent(in), optional :: shift
         real(wp), pointer, contiguous :: buffer(:)
         buffer => op%buffer()
         buffer = x
         call op%inverse_full_in_buffer()
         if (present(shift)) then
            y = buffer + shift
         else
            y = buffer + f
         end if
         h%pairs = h%pairs + 1.0_wp
      end subroutine apply_k

      !> GCR on I K I c = -I p from c = 0 (kc = K c), right-preconditioned by the multigrid
      !> preconditioner, restarted every `memory` iterations; at most max_steps
      !> iterations or a residual reduced by `reduction`. check: after every iteration the
      !> complementarity residual of (u + c, p + kc); `finished` when it is at most tol;
      !> once a point leaves the feasible set the checks stop and c is iterated as a Newton
      !> step to a residual reduced by violated_reduction; `stagnated` when all max_steps
      !> iterations of a checked phase ran and left more than violated_reduction of the
      !> Newton problem's residual.
      subroutine truncated_gcr(max_steps, reduction, check)
         integer, intent(in) :: max_steps
         real(wp), intent(in) :: reduction
         logical, intent(in) :: check
         real(wp) :: b_norm, r_norm, norm, gamma, res
         integer :: it, columns
         logical :: gone, violated
         c = 0.0_wp
         kc = 0.0_wp
         stagnated = .false.
         r = -h%free(1:n)*p
         b_norm = norm_over(r, global)
         if (b_norm == 0.0_wp) return
         columns = 0
         gone = .false.
         do it = 1, max_steps
            if (columns == memory) columns = 0
            columns = columns + 1
            associate (z => dirs(:, columns), kz => kdirs(:, columns), free => h%free(1:n))
            call precondition(h, r, z)
            call apply_k(z, kz, shift=0.0_wp)
            ! (orthogonal on the free points to the stored images)
            if (global) then
               call orthogonalise_over_ranks(z, kz, dirs(:, :columns - 1), kdirs(:, :columns - 1), free)
            else
               call orthogonalise(z, kz, dirs(:, :columns - 1), kdirs(:, :columns - 1), free)
            end if
            call masked_products(kz, r, free, norm, gamma)
            if (global) call add_pair_over_ranks(norm, gamma)
            norm = sqrt(norm)
            if (.not. norm > 0.0_wp) exit
            ! the minimal-residual step along z (z and kz then scaled to a unit image)
            gamma = gamma/norm**2
            if (check .and. .not. gone) then
               call step_and_check(u, o, p, gamma, z, kz, free, c, kc, r, scales, res, violated)
               if (global) then
                  res = global_max(res)
                  violated = global_any(violated)
               end if
               z = z/norm
               kz = kz/norm
               r_norm = norm_over(r, global)
               if (violated) then
                  ! the set is not yet the final one: go on as a Newton step
                  gone = .true.
                  if (r_norm <= violated_reduction*b_norm) exit
               else if (res <= tol) then
                  finished = .true.
                  residual = res
                  exit
               end if
            else
               call minimal_residual_step(gamma, norm, z, kz, free, c, kc, r, r_norm)
               if (global) r_norm = norm_over(r, global)
               if (r_norm <= merge(violated_reduction, reduction, gone)*b_norm) exit
            end if
            end associate
         end do
         stagnated = check .and. .not. finished .and. it > max_steps .and. norm_over(r, global) > violated_reduction*b_norm
      end subroutine truncated_gcr
   end subroutine coupled_tnnmg

   !> Whether the coupled scene's preconditioner takes the hierarchy of K = 1/G_eff itself
   !> (complex Galerkin symbols, LU on the coarsest grid) rather than that of the metric
   !> 1/|G_eff|: where the phase of K is largest (friction on a layer; a viscoelastic layer's
   !> loss peak V q tau ~ 1) at long waves, |kx| <= nx/16 (and |ky| <= ny/16 on a surface),
   !> which the coarse grids carry. A loss peak among the short waves (a slow glassy layer on
   !> a fine grid) is left to the metric's hierarchy (on a surface, unless it is moderate:
   !> short_loss_limit), whose Jacobi steps damp those modes better
   !> (docs/decisions/012-coupled-multigrid.md, 'The hierarchy of K itself where the loss lies
   !> at long waves').
   logical function loss_at_long_waves(op) result(long)
      type(compliance_operator), intent(in) :: op
      long = .false.
      if (op%coupled) long = at_long_waves(loss_of(op))
   end function loss_at_long_waves

   !> Whether the largest loss of `loss` is reached at long waves (loss_at_long_waves).
   pure logical function at_long_waves(loss) result(long)
      type(loss_profile), intent(in) :: loss
      ! (a sliding layer's loss depends on kx alone, so on a surface the largest is reached
      ! at long and short waves in y alike: ties go to the long waves)
      long = loss%largest > 0.0_wp .and. loss%long >= (1.0_wp - 1.0e-9_wp)*loss%largest
   end function at_long_waves

   !> The loss |Im K|/Re K of K = 1/G_eff (= |Im G_eff|/Re G_eff) of the coupled scene of
   !> `op`, mode by mode, summarised in one pass (loss_profile) over the half spectrum, row
   !> by row (kx fastest). The peak is the kx of the last mode whose loss exceeds by 1e-9 the
   !> largest before it in that order. A distributed op (its rank's columns): each of its
   !> modes compared with the largest loss before it in the same order, from the whole rows
   !> before its row and its row's modes on the lower ranks' columns (max_over_lower_ranks);
   !> the last such mode over the ranks gives the peak, the maxima are exact.
   type(loss_profile) function loss_of(op) result(profile)
      type(compliance_operator), intent(in) :: op
      type(held_modes) :: modes
      real(wp), allocatable :: before(:), rows(:), losses(:)
      real(wp) :: loss, summary(4), running
      integer :: i, nkx, kx, ky, last, position
      nkx = op%grid%nx/2 + 1
      if (.not. op%distributed) then
         do i = 2, op%nk
            if (.not. real(op%full(i)) > 0.0_wp) cycle
            loss = abs(aimag(op%full(i)))/real(op%full(i))
            kx = mod(i - 1, nkx)
            ky = (i - 1)/nkx
            if (loss > profile%largest*(1.0_wp + 1.0e-9_wp)) profile%peak = kx
            profile%largest = max(profile%largest, loss)
            call summarise(kx, ky, loss)
         end do
         return
      end if
      modes = modes_of(op)
      last = modes%x_start + modes%columns - 1
      ! (each row's largest on this rank's columns; then before(ky): the largest before this
      ! rank's first mode of row ky, in the whole spectrum's order. Each mode's loss kept for
      ! the second walk, -1 where it has none: one division a mode, as serially)
      allocate (rows(0:op%grid%ny - 1), before(0:op%grid%ny - 1), losses(op%nk))
      rows = 0.0_wp
      do kx = modes%x_start, last
         do ky = 0, op%grid%ny - 1
            losses(held_index(modes, kx, ky)) = -1.0_wp
            if (.not. loss_at(kx, ky, loss)) cycle
            losses(held_index(modes, kx, ky)) = loss
            rows(ky) = max(rows(ky), loss)
         end do
      end do
      before = rows
      call max_over_lower_ranks(before)
      call max_over_ranks(rows)
      running = 0.0_wp
      do ky = 0, op%grid%ny - 1
         before(ky) = max(before(ky), running)
         running = max(running, rows(ky))
      end do
      ! (the last mode, in that order, raising the largest: its position ky nkx + kx)
      position = -1
      do kx = modes%x_start, last
         do ky = 0, op%grid%ny - 1
            loss = losses(held_index(modes, kx, ky))
            if (loss < 0.0_wp) cycle
            if (loss > before(ky)*(1.0_wp + 1.0e-9_wp)) position = max(position, ky*nkx + kx)
            before(ky) = max(before(ky), loss)
            call summarise(kx, ky, loss)
         end do
      end do
      summary = [real(position, wp), running, profile%long, profile%short_x]
      call max_over_ranks(summary)
      profile%largest = summary(2)
      profile%long = summary(3)
      profile%short_x = summary(4)
      profile%peak = 0
      if (summary(1) >= 0.0_wp) profile%peak = mod(nint(summary(1)), nkx)
   contains
      !> the loss of the held mode (kx, ky), if it has one (Re G_eff > 0; not the uniform mode)
      logical function loss_at(kx, ky, loss) result(has)
         integer, intent(in) :: kx, ky
         real(wp), intent(out) :: loss
         complex(wp) :: g
         loss = 0.0_wp
         g = op%full(held_index(modes, kx, ky))
         has = .not. (kx == 0 .and. ky == 0) .and. real(g) > 0.0_wp
         if (has) loss = abs(aimag(g))/real(g)
      end function loss_at

      !> the long waves' and the short waves' largest
      subroutine summarise(kx, ky, loss)
         integer, intent(in) :: kx, ky
         real(wp), intent(in) :: loss
         integer :: signed_ky
         signed_ky = min(ky, op%grid%ny - ky)
         if (16*kx <= op%grid%nx .and. (op%grid%is_line() .or. 16*signed_ky <= op%grid%ny)) &
            & profile%long = max(profile%long, loss)
         if (16*kx > op%grid%nx) profile%short_x = max(profile%short_x, loss)
      end subroutine summarise
   end function loss_of

   !> The largest loss tangent |Im C|/Re C of the layer's material over the grid's sliding
   !> frequencies q_x V (C the contact compliance; 0 for an elastic layer).
   pure real(wp) function material_loss(op) result(loss)
      type(compliance_operator), intent(in) :: op
      integer :: i
      loss = 0.0_wp
      do i = 1, size(op%compliance)
         if (real(op%compliance(i)) > 0.0_wp) loss = max(loss, abs(aimag(op%compliance(i)))/real(op%compliance(i)))
      end do
   end function material_loss

   !> The largest loss |Im K|/Re K of a coupled scene among its waves short along x
   !> (|kx| > nx/16).
   real(wp) function loss_among_short_waves(op) result(loss)
      type(compliance_operator), intent(in) :: op
      type(loss_profile) :: profile
      profile = loss_of(op)
      loss = profile%short_x
   end function loss_among_short_waves

   !> TNNMG iterations on the grid h%top from u until the residual on (K u + f, u - o) is at
   !> most tol or max_steps ran; p = K u + f on exit. steps: iterations run. history and
   !> progress (the finest grid): the residual of each iteration.
   subroutine tnnmg(h, work, op, u, o, f, load_control, g_ref, tol, max_steps, p, steps, converged, history, progress)
      type(hierarchy), intent(inout) :: h
      type(workspace), intent(inout), target :: work
      type(compliance_operator), intent(in) :: op
      real(wp), contiguous, intent(inout) :: u(:)
      real(wp), contiguous, intent(in) :: o(:)
      real(wp), intent(in) :: f, g_ref, tol
      logical, intent(in) :: load_control
      integer, intent(in) :: max_steps
      real(wp), contiguous, intent(out) :: p(:)
      integer, intent(out) :: steps
      logical, intent(out) :: converged
      real(wp), contiguous, intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      type(residual_scales) :: scales
      real(wp) :: residual, diagonal, vkv, b_max, contact, points
      integer :: m, step, changed
      logical :: settled, finished, clipped, tension, global

      m = size(u)
      ! (the finest grid on the slabs: sums and maxima over the ranks, points the whole grid's)
      global = across_ranks(h)
      points = merge(real(h%n_fine, wp), real(m, wp), global)
      associate (c => work%c(1:m), kc => work%kc(1:m), cg_work => work%cg(1:m, :), v => work%cg(1:m, 1), &
         & kv => work%cg(1:m, 2))
      h%free(1:m) = 1.0_wp
      diagonal = h%level(h%top)%jacobi_diagonal
      b_max = maxval(abs(o))
      if (global) b_max = global_max(b_max)
      u = max(u, o)
      call apply_stiffness(h, u, p, shift=f)
      converged = .false.
      steps = 0
      do step = 1, max_steps
         steps = step
         ! nonlinear smoother: projected damped Jacobi
         u = max(o, u - (omega/diagonal)*p)
         call apply_stiffness(h, u, p, shift=f)
         scales = scales_of(u, p, load_control, f, g_ref, b_max, op%largest, global)
         ! (the free points and how many changed are found in the same pass: the
         ! truncated problem below needs them)
         call examine(u, p, o, scales, h%free(1:m), residual, contact, changed, tension)
         if (global) call examine_over_ranks(m, residual, contact, changed, tension)
         call record(step, residual, contact)
         if (residual <= tol) then
            converged = .true.
            exit
         end if
         if (load_control .and. contact == 0.0_wp) then
            ! nothing touches: the energy falls along the rigid shift until the lowest point
            ! touches (K(0) = 0, so p does not change); the truncated problem would be singular
            if (global) then
               u = u + global_max(maxval(o - u))
            else
               u = u - minval(u - o)
            end if
            cycle
         end if
         ! the truncated problem on the free points; the finishing phase once the contact set
         ! has settled
         settled = step > 1 .and. changed <= settled_fraction*contact*points .and. .not. tension
         ! (the coarse operators depend on the set only)
         if (changed > 0 .or. step == 1) call set_contact(h)
         finished = .false.
         if (settled) then
            call truncated_cg(h, u, o, p, finish_iterations, 0.0_wp, c, kc, cg_work, scales, tol, finished, residual)
         else
            call truncated_cg(h, u, o, p, newton_iterations, newton_reduction, c, kc, cg_work)
         end if
         if (finished) then
            u = u + c
            p = p + kc
            call record(step, residual, contact)
            converged = .true.
            exit
         end if
         ! projection onto u >= o and exact line search on the quadratic J
         call project_direction(u, o, c, v, clipped)
         if (global) clipped = global_any(clipped)
         if (clipped) then
            call apply_stiffness(h, v, kv, xy=vkv)
         else
            kv = kc
            vkv = dot_product(v, kv)
            if (global) vkv = global_sum(vkv)
         end if
         if (global) then
            call line_step(v, kv, vkv, u, p, global_sum(dot_product(p, v)))
         else
            call line_step(v, kv, vkv, u, p)
         end if
      end do
      end associate
   contains
      subroutine record(step, residual, contact)
         integer, intent(in) :: step
         real(wp), intent(in) :: residual, contact
         if (present(history)) then
            if (step <= size(history)) history(step) = residual
         end if
         if (present(progress)) call progress%tick(step, residual, contact)
      end subroutine record
   end subroutine tnnmg

   !> v = the Newton direction c projected onto u + v >= o; clipped: some point was.
   pure subroutine project_direction(u, o, c, v, clipped)
      real(wp), contiguous, intent(in) :: u(:), o(:), c(:)
      real(wp), contiguous, intent(out) :: v(:)
      logical, intent(out) :: clipped
      integer :: j
      clipped = .false.
      do j = 1, size(u)
         v(j) = c(j)
         if (u(j) + c(j) < o(j)) then
            v(j) = o(j) - u(j)
            clipped = .true.
         end if
      end do
   end subroutine project_direction

   !> u <- u + alpha v, p <- p + alpha K v with alpha = min(1, -p.v/v.K v), the exact line
   !> search of the (symmetric part's) quadratic energy along v; no step unless v.K v > 0.
   !> pv: p.v where it is given (a sum over the ranks).
   pure subroutine line_step(v, kv, vkv, u, p, pv)
      real(wp), contiguous, intent(in) :: v(:), kv(:)
      real(wp), intent(in) :: vkv
      real(wp), contiguous, intent(inout) :: u(:), p(:)
      real(wp), intent(in), optional :: pv
      real(wp) :: alpha
      if (.not. vkv > 0.0_wp) return
      if (present(pv)) then
         alpha = min(1.0_wp, max(0.0_wp, -pv/vkv))
      else
         alpha = min(1.0_wp, max(0.0_wp, -dot_product(p, v)/vkv))
      end if
      u = u + alpha*v
      p = p + alpha*kv
   end subroutine line_step

   !> CG on the truncated Newton problem I K I c = -I p (c = 0 on the contact set),
   !> preconditioned (precondition, below), from c = 0; kc = K c (carried along at no cost).
   !> work(:, 1:3): the residual, the direction and its image. Without `scales`: at most
   !> max_steps iterations, or until the residual fell by `reduction`. With them (the
   !> finishing phase): after every iteration the complementarity residual of
   !> (u + c, p + kc) is checked; `finished` when it is at most tol (with `residual`); once a
   !> point leaves the feasible set (u + c < o off the contact set, or p + kc < 0 on it) the
   !> checks stop and c becomes a direction for the line search, iterated until the
   !> residual fell by violated_reduction.
   subroutine truncated_cg(h, u, o, p, max_steps, reduction, c, kc, work, scales, tol, finished, residual)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: u(:), o(:), p(:)
      integer, intent(in) :: max_steps
      real(wp), intent(in) :: reduction
      real(wp), contiguous, intent(out) :: c(:), kc(:)
      real(wp), contiguous, intent(inout) :: work(:, :)
      type(residual_scales), intent(in), optional :: scales
      real(wp), intent(in), optional :: tol
      logical, intent(out), optional :: finished
      real(wp), intent(out), optional :: residual
      real(wp) :: rz, rz_old, b_norm, r_norm, dkd, a
      logical :: violated, gone   !< gone: a point left the feasible set
      logical :: global           !< the finest grid on the slabs: sums over the ranks
      integer :: it, m, j

      m = size(u)
      global = across_ranks(h)
      gone = .false.
      c = 0.0_wp
      kc = 0.0_wp
      if (present(finished)) finished = .false.
      associate (r => work(:, 1), d => work(:, 2), kd => work(:, 3), free => h%free(1:m))
      r = -free*p
      b_norm = norm_over(r, global)
      if (b_norm == 0.0_wp) return
      call precondition(h, r, d)
      rz = dot_product(r, d)
      if (global) rz = global_sum(rz)
      do it = 1, max_steps
         ! (d is zero on the contact set, as the preconditioner's output: d.I K d = d.K d)
         call apply_stiffness(h, d, kd, xy=dkd)
         if (.not. dkd > 0.0_wp) exit
         a = rz/dkd
         if (present(scales) .and. .not. gone) then
            call step_and_check(u, o, p, a, d, kd, free, c, kc, r, scales, residual, violated)
            if (global) then
               residual = global_max(residual)
               violated = global_any(violated)
            end if
            if (violated) then
               ! the set is not yet the final one: go on as a Newton step (to a residual
               ! reduced by violated_reduction), which the line search then projects
               gone = .true.
               if (norm_over(r, global) <= violated_reduction*b_norm) exit
            else if (residual <= tol) then
               finished = .true.
               exit
            end if
         else
            r_norm = 0.0_wp
            !$omp simd reduction(+:r_norm)
            do j = 1, m
               c(j) = c(j) + a*d(j)
               kc(j) = kc(j) + a*kd(j)
               r(j) = r(j) - a*free(j)*kd(j)
               r_norm = r_norm + r(j)**2
            end do
            if (global) r_norm = global_sum(r_norm)
            if (sqrt(r_norm) <= merge(violated_reduction, reduction, gone)*b_norm) exit
         end if
         if (it == max_steps) exit
         rz_old = rz
         call precondition(h, r, kd)
         rz = dot_product(r, kd)
         if (global) rz = global_sum(rz)
         d = kd + (rz/rz_old)*d
      end do
      end associate
   end subroutine truncated_cg

   !> p_ref (p_m, or the mean pressure under displacement control), g_ref and the rounding
   !> floor of the gap for the state (u, p).
   !> global: u and p are a slab, the maxima and the mean taken over the ranks.
   function scales_of(u, p, load_control, f, g_ref, b_max, largest, global) result(scales)
      real(wp), contiguous, intent(in) :: u(:), p(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: f, g_ref, b_max, largest
      logical, intent(in), optional :: global
      type(residual_scales) :: scales
      real(wp) :: p_ref, u_max, p_max, p_sum, points, maxima(2)
      integer :: j
      u_max = 0.0_wp
      p_max = -huge(1.0_wp)
      p_sum = 0.0_wp
      !$omp simd reduction(max:u_max, p_max) reduction(+:p_sum)
      do j = 1, size(u)
         u_max = max(u_max, abs(u(j)))
         p_max = max(p_max, p(j))
         p_sum = p_sum + p(j)
      end do
      points = size(p)
      if (present(global)) then
         if (global) then
            maxima = [u_max, p_max]
            call max_over_ranks(maxima)
            u_max = maxima(1)
            p_max = maxima(2)
            p_sum = global_sum(p_sum)
            points = global_sum(points)
         end if
      end if
      p_ref = merge(f, p_sum/points, load_control)
      scales%p_scale = 1.0_wp/max(p_ref, tiny(1.0_wp))
      scales%g_scale = 1.0_wp/g_ref
      scales%floor = rounding_floor(u_max, b_max, p_max, largest)
   end function scales_of

   !> The complementarity residual of (p, u - o) (gaps within the floor count as zero, and a
   !> tension (p < 0) there counts in full) and the contact fraction (u <= o); the free
   !> points (free: 1 where u > o) and how many changed from the free points on entry, and
   !> whether a contact point carries tension.
   pure subroutine examine(u, p, o, scales, free, residual, contact, changed, tension)
      real(wp), contiguous, intent(in) :: u(:), p(:), o(:)
      type(residual_scales), intent(in) :: scales
      real(wp), contiguous, intent(inout) :: free(:)
      real(wp), intent(out) :: residual, contact
      integer, intent(out) :: changed
      logical, intent(out) :: tension
      real(wp) :: g, check, touching, moved, pulled, now
      integer :: j
      residual = 0.0_wp
      check = 0.0_wp
      touching = 0.0_wp
      moved = 0.0_wp
      pulled = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:check, touching, moved, pulled) private(g, now)
      do j = 1, size(u)
         g = u(j) - o(j)
         residual = max(residual, merge(abs(min(p(j)*scales%p_scale, g*scales%g_scale)), &
            & max(-p(j)*scales%p_scale, 0.0_wp), g > scales%floor))
         check = check + g + p(j)
         now = merge(1.0_wp, 0.0_wp, g > 0.0_wp)
         touching = touching + (1.0_wp - now)
         moved = moved + abs(now - free(j))
         pulled = pulled + merge(1.0_wp, 0.0_wp, now == 0.0_wp .and. p(j) < 0.0_wp)
         free(j) = now
      end do
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
      contact = touching/size(u)
      changed = nint(moved)
      tension = pulled > 0.0_wp
   end subroutine examine

   !> examine's results on a slab made the whole surface's: the largest residual, the
   !> contact fraction and the changed points counted over the ranks (m: the slab's points),
   !> tension on any rank.
   subroutine examine_over_ranks(m, residual, contact, changed, tension)
      integer, intent(in) :: m
      real(wp), intent(inout) :: residual, contact
      integer, intent(inout) :: changed
      logical, intent(inout) :: tension
      real(wp) :: totals(4)
      ! (the slab's contact points recovered exactly from its fraction: integers below 2^53)
      totals = [real(nint(contact*m), wp), real(changed, wp), merge(1.0_wp, 0.0_wp, tension), real(m, wp)]
      call sum_over_ranks(totals)
      residual = global_max(residual)
      contact = totals(1)/totals(4)
      changed = nint(totals(2))
      tension = totals(3) > 0.0_wp
   end subroutine examine_over_ranks

   !> orthogonalise on a slab, by classical Gram-Schmidt: every beta_k = (I kz, kdirs_k) of
   !> the kz given, their sums over the ranks in one message, then the columns subtracted.
   !> The stored images are orthonormal on the free points (each orthogonalised and scaled
   !> to a unit image when it was stored, on the same free points), so these are modified
   !> Gram-Schmidt's betas in exact arithmetic; one message an iteration instead of one a
   !> column (up to gcr_memory - 1). The step that follows is exact whatever is left of the
   !> images' orthogonality: it minimises the residual along kz and updates it by kz.
   subroutine orthogonalise_over_ranks(z, kz, dirs, kdirs, free)
      real(wp), contiguous, intent(inout) :: z(:), kz(:)
      real(wp), contiguous, intent(in) :: dirs(:, :), kdirs(:, :), free(:)
      real(wp) :: beta(size(dirs, 2)), total
      integer :: k, j
      if (size(beta) == 0) return
      do k = 1, size(beta)
         total = 0.0_wp
         !$omp simd reduction(+:total)
         do j = 1, size(z)
            total = total + free(j)*kz(j)*kdirs(j, k)
         end do
         beta(k) = total
      end do
      call sum_over_ranks(beta)
      do k = 1, size(beta)
         !$omp simd
         do j = 1, size(z)
            z(j) = z(j) - beta(k)*dirs(j, k)
            kz(j) = kz(j) - beta(k)*kdirs(j, k)
         end do
      end do
   end subroutine orthogonalise_over_ranks

   !> a, b <- their sums over the ranks (one message).
   subroutine add_pair_over_ranks(a, b)
      real(wp), intent(inout) :: a, b
      real(wp) :: pair(2)
      pair = [a, b]
      call sum_over_ranks(pair)
      a = pair(1)
      b = pair(2)
   end subroutine add_pair_over_ranks

   !> |x| of a field, over the ranks where `global` (x a slab).
   real(wp) function norm_over(x, global) result(norm)
      real(wp), contiguous, intent(in) :: x(:)
      logical, intent(in) :: global
      if (global) then
         norm = sqrt(global_sum(sum(x**2)))
      else
         norm = euclidean_norm(x)
      end if
   end function norm_over

   !> z, kz <- z - sum_k beta_k dirs_k, kz - sum_k beta_k kdirs_k with beta_k = (I kz, kdirs_k),
   !> one column after the other (modified Gram-Schmidt on the free points against unit
   !> images kdirs_k). Its own procedure with contiguous dummies, which do not alias, so
   !> that the passes vectorise.
   pure subroutine orthogonalise(z, kz, dirs, kdirs, free)
      real(wp), contiguous, intent(inout) :: z(:), kz(:)
      real(wp), contiguous, intent(in) :: dirs(:, :), kdirs(:, :), free(:)
      real(wp) :: beta
      integer :: k, j
      do k = 1, size(dirs, 2)
         beta = 0.0_wp
         !$omp simd reduction(+:beta)
         do j = 1, size(z)
            beta = beta + free(j)*kz(j)*kdirs(j, k)
         end do
         !$omp simd
         do j = 1, size(z)
            z(j) = z(j) - beta*dirs(j, k)
            kz(j) = kz(j) - beta*kdirs(j, k)
         end do
      end do
   end subroutine orthogonalise

   !> |x|, in one vectorised pass (the intrinsic norm2 scales every element against
   !> overflow, several times the cost; these residuals are far from the overflow threshold)
   pure real(wp) function euclidean_norm(x) result(norm)
      real(wp), contiguous, intent(in) :: x(:)
      integer :: j
      norm = 0.0_wp
      !$omp simd reduction(+:norm)
      do j = 1, size(x)
         norm = norm + x(j)**2
      end do
      norm = sqrt(norm)
   end function euclidean_norm

   !> (I kz, kz) and (I r, kz)
   pure subroutine masked_products(kz, r, free, squared, projection)
      real(wp), contiguous, intent(in) :: kz(:), r(:), free(:)
      real(wp), intent(out) :: squared, projection
      integer :: j
      squared = 0.0_wp
      projection = 0.0_wp
      !$omp simd reduction(+:squared, projection)
      do j = 1, size(kz)
         squared = squared + free(j)*kz(j)**2
         projection = projection + free(j)*r(j)*kz(j)
      end do
   end subroutine masked_products

   !> The GCR step c += gamma z, kc += gamma kz, r -= gamma I kz, with z and kz then scaled
   !> by 1/norm (a unit image), and |r|.
   pure subroutine minimal_residual_step(gamma, norm, z, kz, free, c, kc, r, r_norm)
      real(wp), intent(in) :: gamma, norm
      real(wp), contiguous, intent(inout) :: z(:), kz(:), c(:), kc(:), r(:)
      real(wp), contiguous, intent(in) :: free(:)
      real(wp), intent(out) :: r_norm
      integer :: j
      r_norm = 0.0_wp
      !$omp simd reduction(+:r_norm)
      do j = 1, size(z)
         c(j) = c(j) + gamma*z(j)
         kc(j) = kc(j) + gamma*kz(j)
         r(j) = r(j) - gamma*free(j)*kz(j)
         z(j) = z(j)/norm
         kz(j) = kz(j)/norm
         r_norm = r_norm + r(j)**2
      end do
      r_norm = sqrt(r_norm)
   end subroutine minimal_residual_step

   !> The finishing phase's CG step (c += a d, kc += a kd, r -= a I kd) and its check of
   !> (u + c, p + kc), in one pass: the residual, and whether a point left the feasible set
   !> (a gap below zero off the contact set, a tension on it).
   pure subroutine step_and_check(u, o, p, a, d, kd, free, c, kc, r, scales, residual, violated)
      real(wp), contiguous, intent(in) :: u(:), o(:), p(:), d(:), kd(:), free(:)
      real(wp), intent(in) :: a
      real(wp), contiguous, intent(inout) :: c(:), kc(:), r(:)
      type(residual_scales), intent(in) :: scales
      real(wp), intent(out) :: residual
      logical, intent(out) :: violated
      real(wp) :: g, pt, bad, check
      integer :: j
      residual = 0.0_wp
      bad = 0.0_wp
      check = 0.0_wp
      !$omp simd reduction(max:residual) reduction(+:bad, check) private(g, pt)
      do j = 1, size(u)
         c(j) = c(j) + a*d(j)
         kc(j) = kc(j) + a*kd(j)
         r(j) = r(j) - a*free(j)*kd(j)
         g = u(j) + c(j) - o(j)
         pt = p(j) + kc(j)
         bad = bad + merge(1.0_wp, 0.0_wp, (free(j) > 0.0_wp .and. g < 0.0_wp) .or. (free(j) == 0.0_wp .and. pt < 0.0_wp))
         residual = max(residual, merge(abs(min(pt*scales%p_scale, g*scales%g_scale)), &
            & max(-pt*scales%p_scale, 0.0_wp), g > scales%floor))
         check = check + g + pt
      end do
      violated = bad > 0.0_wp
      if (.not. ieee_is_finite(check)) residual = huge(1.0_wp)
   end subroutine step_and_check

   !> The fields the other solvers return, from the displacement form's (u, p = K u + f):
   !> the pressure kept where the gap is the smaller term of the residual (p/p_ref >=
   !> gap/g_ref, the points in contact), 0 elsewhere (there |p| <= tol p_ref already),
   !> scaled to the load (load control); w = M p; s the mean of w - b over the contact set
   !> (load control); gap = w - b - s; and the residual of these fields. w holds the
   !> obstacle o on entry.
   subroutine returned_fields(op, u, b, load_control, mean_pressure, g_ref, p, w, gap, s, residual, full)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: u(:), b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure, g_ref
      real(wp), contiguous, intent(inout) :: p(:), w(:)
      real(wp), contiguous, intent(out) :: gap(:)
      real(wp), intent(inout) :: s
      real(wp), intent(out) :: residual
      logical, intent(in), optional :: full   !< w = G_eff p (a coupled operator)
      real(wp) :: p_ref, maxima(3)
      integer :: contact
      ! (a distributed operator: the fields are its slab, the sums and maxima over the ranks)
      p_ref = merge(mean_pressure, mean_of(p), load_control)
      where (p > 0.0_wp .and. p*g_ref >= (u - w)*p_ref)
         gap = p
      elsewhere
         gap = 0.0_wp
      end where
      p = gap
      if (load_control) call normalise(p, mean_pressure, across_ranks=op%distributed)
      if (present(full)) then
         call op%apply_full(p, w)
      else
         call op%apply_metric(p, w)
      end if
      contact = count(p > 0.0_wp)
      if (op%distributed) contact = global_sum(contact)
      if (load_control .and. contact > 0) then
         if (op%distributed) then
            s = global_sum(sum(w - b, mask=p > 0.0_wp))/contact
         else
            s = sum(w - b, mask=p > 0.0_wp)/contact
         end if
      end if
      gap = w - b - s
      p_ref = merge(mean_pressure, mean_of(p), load_control)
      maxima = [maxval(abs(w)), maxval(abs(b)), maxval(p)]
      if (op%distributed) call max_over_ranks(maxima)
      residual = complementarity_residual(p, gap, p_ref, g_ref, rounding_floor(maxima(1), maxima(2), maxima(3), op%largest))
      if (op%distributed) residual = global_max(residual)
   contains
      real(wp) function mean_of(x)
         real(wp), contiguous, intent(in) :: x(:)
         if (op%distributed) then
            mean_of = global_sum(sum(x))/global_sum(real(size(x), wp))
         else
            mean_of = sum(x)/size(x)
         end if
      end function mean_of
   end subroutine returned_fields
   subroutine solve_by_multigrid(self, problem, state, budget, outcome, progress, error)
      class(multigrid_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(multigrid_outcome) :: nested
      real(wp), allocatable :: history(:)
      allocate (history(budget))
      if (solves_on_slabs(problem%op)) then
         if (symmetric_form(problem%op)) then
            call multigrid_on_slabs(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, &
               & problem%g_ref, problem%tol, budget, state%p, state%w, state%gap, nested, history, progress, error)
         else
            call coupled_tnnmg(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, &
               & problem%g_ref, problem%tol, budget, state%p, state%w, state%gap, nested, history, progress, error)
         end if
      else if (problem%op%distributed) then
         call solve_gathered(problem, state, budget, nested, history, progress, error)
      else if (problem%op%coupled .or. len(multigrid_refusal(problem%op)) > 0) then
         call coupled_tnnmg(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, &
            & problem%g_ref, problem%tol, budget, state%p, state%w, state%gap, nested, history, progress, error)
      else
         call multigrid(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
            & problem%tol, budget, state%p, state%w, state%gap, nested, history, progress, error)
      end if
      if (allocated(error)) return
      outcome = solve_outcome(converged=nested%converged, iterations=nested%iterations, outer_iterations=0, &
         & fft_pairs=nested%fft_pairs, residual=nested%residual, &
         & history=history(1:min(nested%iterations, size(history))))
   end subroutine solve_by_multigrid

   !> Whether the multigrid method solves the scene of the distributed operator `op` on the
   !> slabs (multigrid_on_slabs, coupled_tnnmg): a grid whose V-cycle has a coarse grid
   !> below the finest and whose nested iteration starts on a coarser one (from 1024
   !> points). The others are gathered (solve_gathered).
   logical function solves_on_slabs(op)
      type(compliance_operator), intent(in) :: op
      solves_on_slabs = op%distributed
      if (solves_on_slabs) solves_on_slabs = len(size_refusal(op)) == 0 .and. &
         & halvings(op%grid%nx, op%grid%ny, nested_coarsest) >= 1
   end function solves_on_slabs

   !> Whether the scene of `op` takes the symmetric form (multigrid) rather than the coupled
   !> one, as solve_by_multigrid decides serially (a distributed operator's refusal measured
   !> on the ranks' modes, over the ranks).
   logical function symmetric_form(op) result(symmetric)
      type(compliance_operator), intent(in) :: op
      symmetric = .not. (op%coupled .or. op%kernel%viscoelastic)
      if (symmetric) symmetric = len(multigrid_refusal(op)) == 0
   end function symmetric_form

   !> multigrid on the slabs of a surface shared among the ranks (op on this rank's slab:
   !> docs/decisions/028-distributed-multigrid.md). The nested iteration's coarse grids are
   !> whole and alike on every rank (the profile at every second point gathered, one
   !> MPI_Allreduce of that grid); the finest grid's iteration runs on the slabs, its sums and
   !> maxima over the ranks, K applied by the operator's distributed transforms; its
   !> preconditioner's first coarse grid is gathered (restrict_slab), the V-cycle below it
   !> run whole and alike, and its correction interpolated onto each slab. p, w, gap: this
   !> rank's slab; s the whole surface's on every rank. The scene must pass solves_on_slabs.
   subroutine multigrid_on_slabs(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, &
         & history, progress, error)
      type(compliance_operator), intent(inout), target :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure
      real(wp), intent(inout) :: s
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(multigrid_outcome), intent(out) :: outcome
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(hierarchy), target :: h
      type(workspace) :: work, coarse_work
      real(wp), allocatable :: u(:), finest(:), b_half(:), uc(:), oc(:), pc(:), scratch(:)
      real(wp) :: f
      integer :: n, nx, ny, j, nested, m, mc, m1, steps
      logical :: converged

      n = size(p)
      nx = op%grid%nx
      ny = op%grid%ny
      finest = whole_stiffness(op, load_control)
      call build_hierarchy(h, op, error)
      if (allocated(error)) return
      f = merge(mean_pressure, 0.0_wp, load_control)
      nested = halvings(nx, ny, nested_coarsest)
      m1 = h%level(1)%n
      allocate (coarse_work%c(m1), coarse_work%kc(m1), coarse_work%cg(m1, 3), uc(m1), oc(m1), pc(m1), scratch(m1))
      b_half = gathered_half(b, nx, ny, h%y_start, h%ny_local)
      ! the coarse grids of the nested iteration, whole: the coarsest to tol, the others one
      ! iteration each
      do j = nested, 1, -1
         m = h%level(j)%n
         call set_grid(h, j, sampled_symbol(finest, nx, ny, h%level(j)%nx, h%level(j)%ny))
         call sample(b_half, nx/2, ny/2, 2**(j - 1), oc(1:m))
         if (.not. load_control) oc(1:m) = oc(1:m) + s
         if (j == nested) then
            uc(1:m) = oc(1:m)
         else
            mc = h%level(j + 1)%n
            scratch(1:mc) = uc(1:mc)
            call interpolate(h, j, scratch(1:mc), uc(1:m))
         end if
         call tnnmg(h, coarse_work, op, uc(1:m), oc(1:m), f, load_control, g_ref, tol, merge(max_iter, 1, j == nested), &
            & pc(1:m), steps, converged)
      end do
      deallocate (coarse_work%c, coarse_work%kc, coarse_work%cg, oc, pc, scratch, b_half)
      ! the finest grid, on the slabs, to tol on the fields returned
      call set_grid(h, 0, finest)
      deallocate (finest)
      allocate (u(n), work%c(n), work%kc(n), work%cg(n, 3))
      call interpolate_onto_slab(h, uc, u)
      deallocate (uc)
      call finest_iterations(h, work, op, u, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, &
         & outcome, history, progress)
   end subroutine multigrid_on_slabs

   !> The stiffness K = 1/M on the whole half spectrum of the distributed operator's grid
   !> (level_symbol's of the finest grid): each rank's modes, summed over the ranks.
   function whole_stiffness(op, load_control) result(stiffness)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      real(wp), allocatable :: stiffness(:)
      real(wp), allocatable :: held(:)
      allocate (held(op%nk), source=0.0_wp)
      where (op%metric(1:op%nk) > 0.0_wp) held = 1.0_wp/op%metric(1:op%nk)
      stiffness = whole_symbol(op, held)
      if (load_control) stiffness(1) = 0.0_wp
   end function whole_stiffness

   !> The field b of nx x ny points (this rank's slab: rows y_start+1 .. y_start+ny_local) at
   !> every second point along each axis, whole on every rank: each rank's even rows, summed
   !> over the ranks.
   function gathered_half(b, nx, ny, y_start, ny_local) result(half)
      real(wp), contiguous, intent(in) :: b(:)
      integer, intent(in) :: nx, ny, y_start, ny_local
      real(wp), allocatable :: half(:)
      integer :: j, y, mx
      mx = nx/2
      allocate (half(mx*(ny/2)))
      half = 0.0_wp
      do j = 0, ny_local - 1
         y = y_start + j
         if (mod(y, 2) == 0) half((y/2)*mx + 1:(y/2 + 1)*mx) = b(j*nx + 1:(j + 1)*nx:2)
      end do
      call sum_over_ranks(half)
   end function gathered_half

   !> The multigrid solve of a surface shared among the ranks (problem%op on this rank's
   !> slab; docs/decisions/028-distributed-multigrid.md): the profile and the start gathered
   !> onto every rank (MPI_Allgatherv), the serial iteration run on an operator of the whole
   !> grid, alike on every rank (same data, same plans: the same iterates), and each rank
   !> keeping its slab of p, w and gap. s is the whole surface's on every rank.
   subroutine solve_gathered(problem, state, budget, nested, history, progress, error)
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(multigrid_outcome), intent(out) :: nested
      real(wp), contiguous, intent(inout) :: history(:)
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(compliance_operator), target :: whole
      real(wp), allocatable :: b(:), p(:), w(:), gap(:)
      integer :: nx, ny, y_start, ny_local, first, last
      nx = problem%op%grid%nx
      ny = problem%op%grid%ny
      call whole_operator(problem%op, whole, error)
      if (allocated(error)) return
      call allgather_rows(problem%b, nx, ny, b)
      call allgather_rows(state%p, nx, ny, p)
      allocate (w(nx*ny), gap(nx*ny))
      if (whole%coupled .or. len(multigrid_refusal(whole)) > 0) then
         call coupled_tnnmg(whole, b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
            & problem%tol, budget, p, w, gap, nested, history, progress, error)
      else
         call multigrid(whole, b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, problem%tol, &
            & budget, p, w, gap, nested, history, progress, error)
      end if
      if (allocated(error)) return
      call slab(ny, y_start, ny_local)
      first = nx*y_start + 1
      last = nx*(y_start + ny_local)
      state%p = p(first:last)
      state%w = w(first:last)
      state%gap = gap(first:last)
   end subroutine solve_gathered

   !> The operator of the whole grid of `op` (a slab's, distributed) on this rank alone: the
   !> same grid, layer and friction, and its uniform mode left out where op's is
   !> (drop_uniform_mode): what the gathered multigrid solve (solve_gathered) iterates on.
   subroutine whole_operator(op, whole, error)
      type(compliance_operator), intent(in) :: op
      type(compliance_operator), intent(out) :: whole
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: uniform
      call build_operator(whole, op%grid, op%kernel, op%friction, active_threads(), error, distributed=.false.)
      if (allocated(error)) return
      if (op%dropped_uniform /= 0.0_wp) call whole%drop_uniform_mode(uniform)
   end subroutine whole_operator

   pure function multigrid_name(self) result(name)
      class(multigrid_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'multigrid'
   end function multigrid_name

end module lc_contact_solver_multigrid
