!> The grids and coarse operators of the multigrid solvers (lc_contact_solver_multigrid):
!> the grids of a line or surface, each made of the one before by halving it along x, y or
!> both (coarsening_shapes: both, unless the symbol is anisotropic), and the preconditioner
!> B = omega/d I + I P V P^T I of the truncated Newton problem I K I c = -I p (I the
!> indicator of the free points, off the contact set A): a damped Jacobi step on the free
!> points plus the coarse correction, added (no transform on the grid being solved), V a
!> V(1,1)-cycle on the coarser grids. Linear interpolation P along the axes halved
!> (bilinear where both are), restriction P^T; the coarse operators are the Galerkin
!> products of the penalised operator K + d D_A (D_A the indicator of the contact set, d the
!> diagonal of K): a Galerkin circulant (a transform on the coarse grid; its symbol does not
!> depend on the contact set) plus a 3-point (line) or 9-point (surface) stencil rebuilt in
!> O(n) when the set changes. The penalty stands in for the truncated Galerkin operator
!> P^T I K I P, whose application would cost a transform of the finest grid. Damped Jacobi
!> smoothing, or on a surface sliding on a viscoelastic layer smoothing by rows (solve_rows:
!> each row's part of the operator solved by transforms of the rows, on grids halved along
!> both axes, or along y alone where a grid has more rows than points along them and that
!> smooths better; in B the masked row step in place of the Jacobi step); a dense Cholesky
!> solve on the coarsest grid (at most coarsest_limit points).
!> K is real and even (a symmetric stiffness: the operator's metric inverted), or complex
!> (the non-symmetric stiffness 1/G_eff of a coupled scene, whose imaginary part is odd),
!> with an LU factor of the coarsest operator in place of Cholesky's; the solvers
!> only need B to approximate the truncated problem's inverse, which is what lets the
!> coarse operators be this cheap. Fields are stored as the rest of the library stores
!> them: nx x ny points, x fastest; spectra on the half spectrum (nx/2 + 1) x ny.
module lc_contact_multigrid_hierarchy
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_fft_plans, only: fft_plan
   use lc_contact_operator, only: compliance_operator, multiply_spectrum, multiply_complex
   use lc_base_threads, only: active_threads, parallel_points, reduction_blocks, block_range
   use lc_base_parallel, only: global_sum, sum_over_ranks, global_max, max_over_ranks
   implicit none (type, external)
   private
   interface
      subroutine dgetrf(m, n, a, lda, ipiv, info)
         import :: wp
         integer, intent(in) :: m, n, lda
         real(wp), intent(inout) :: a(lda, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgetrf
      subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: wp
         character, intent(in) :: trans
         integer, intent(in) :: n, nrhs, lda, ldb
         real(wp), intent(in) :: a(lda, *)
         integer, intent(in) :: ipiv(*)
         real(wp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dgetrs
   end interface
   public :: grid_level, hierarchy, omega, jacobi_margin, coarsest_points, coarsest_limit, penalty, accepted_smoothing
   public :: build_hierarchy, halvings, level_symbol, set_grid, set_contact, sample, interpolate, worst_smoothing
   public :: worst_row_smoothing, solve_rows
   public :: precondition, apply_stiffness, level_operator
   public :: across_ranks, interpolate_onto_slab, sampled_symbol
   public :: held_modes, modes_of, held_index

   !> Damping of the Jacobi steps (nonlinear smoother and V-cycle): below 1 the projected
   !> step lowers the energy monotonically; 2/3 damps the upper half of the spectrum best.
   real(wp), parameter :: omega = 2.0_wp/3.0_wp

   !> A damped Jacobi step with the diagonal d multiplies the error's mode q by
   !> 1 - omega K(q)/d, which grows if it exceeds 1 in modulus: where the symbol rises faster
   !> than |q| (a viscoelastic layer stiffening with the frequency q V) the steps take
   !> d >= jacobi_margin omega max K/2 (for a complex K, max |K|^2/(2 Re K)) instead of the
   !> mean. K ~ |q| has max K = 2 mean on a line (1.9 on a square surface), below the bound,
   !> and keeps the mean (docs/decisions/012-coupled-multigrid.md, 'What does: the TNNMG
   !> iteration with the non-symmetric stiffness').
   real(wp), parameter :: jacobi_margin = 1.1_wp

   !> The V-cycle coarsens while the next grid has at least this many points (and, on a
   !> surface, at least shortest_side points along each axis) ...
   integer, parameter :: coarsest_points = 64
   integer, parameter :: shortest_side = 4

   !> ... and its coarsest grid (solved densely) may have at most this many.
   integer, parameter :: coarsest_limit = 256

   !> coarsening_shapes halves both axes of a surface's grid while the Jacobi step's
   !> smoothing factor over the modes the next grid cannot carry is at most this (K ~ |q|:
   !> about 0.6).
   real(wp), parameter :: accepted_smoothing = 0.75_wp

   !> Weight of the contact-set penalty d D_A in the coarse operators (in units of the
   !> diagonal d of K): the fewest CG iterations on the final set
   !> (docs/decisions/009-multigrid-for-symmetric-lines.md, 'Measured').
   real(wp), parameter :: penalty = 1.0_wp

   !> Row smoothing on a coarse grid: the shift of a row's solve, in units of the geometric
   !> mean of two values of the penalty's diagonal over the row, its mean (the contact
   !> points' stiffness spread over the row) and its largest (one contact point's). Without
   !> a shift a soft row's inverse overshoots where the penalty pins the points; a share of
   !> the mean alone is too much for rows with many contact points and too little for rows
   !> with few (docs/decisions/015-row-smoothing.md, 'What is done').
   real(wp), parameter :: row_shift_weight = 0.05_wp

   !> One grid of nx/2^t x ny/2^t points (ny = 1 on a line): its plan, the operator on it
   !> for the current hierarchy, and the V-cycle's work arrays.
   type :: grid_level
      integer :: nx = 0, ny = 1, n = 0
      !> how the next grid is made of this one: along which axes it is halved (a line: x)
      logical :: halve_x = .true., halve_y = .false.
      !> the plan: the operator's own on the finest grid, `plan` on the coarser ones
      type(fft_plan), pointer :: fft => null()
      type(fft_plan), allocatable :: plan
      !> the rows' transforms (solve_rows): fft's, or on a slab (h%on_slabs) a plan of the
      !> slab's rows of its own, whose rows are whole
      type(fft_plan), pointer :: rows_fft => null()
      real(wp) :: inv_n = 1.0_wp
      real(wp), allocatable :: symbol(:)       !< circulant part, half spectrum (nx/2 + 1) x ny
      real(wp), allocatable :: multiplier(:)   !< symbol/n, as applied after an unscaled r2c
      !> a non-symmetric hierarchy (h%complex): the symbol's imaginary part (odd in kx) and
      !> the complex multiplier
      real(wp), allocatable :: odd(:)
      complex(wp), allocatable :: cmultiplier(:)
      real(wp) :: circulant_diagonal = 0.0_wp
      !> the diagonal of the Jacobi steps: circulant_diagonal, or more where the symbol rises
      !> so steeply that omega K/d would exceed 2 on some mode (see jacobi_margin)
      real(wp) :: jacobi_diagonal = 0.0_wp
      !> the penalty's stencil (coarse grids): penalty(ex, ey, i) couples point i with its
      !> neighbour i + (ex, ey), periodic (ey = 0 only on a line)
      real(wp), allocatable :: penalty(:, :, :)
      !> the smoother's weights: omega over the diagonal of the operator (Jacobi steps), or
      !> omega scaled down where the point is stiffer than its row (row smoothing: set_contact)
      real(wp), allocatable :: jacobi(:)
      !> row smoothing (hierarchy%rows): K_row(kx), the mean of the symbol over ky; its
      !> inverse with the 1/nx of the rows' unscaled transform folded in; and per row the
      !> shift added to K_row (coarse grids: see row_shift_weight)
      complex(wp), allocatable :: row_symbol(:), row_inverse(:)
      real(wp), allocatable :: row_shift(:)
      real(wp), allocatable :: rhs(:), x(:), residual(:)
      !> a surface's transfers work axis by axis: the field on the next grid's x and this ny
      real(wp), allocatable :: halfway(:)
      !> the stencils of three rows coarsened along x, for the next grid's rows in turn
      real(wp), allocatable :: window(:, :, :, :)
   end type grid_level

   !> The grids of every 2^t-th point, t = 0..coarsest (one plan per size, shared by the
   !> nested grids), the grid being solved (`top`: its operator is I K I, the coarser ones
   !> are the V-cycle's) and the transform count.
   type :: hierarchy
      type(grid_level), allocatable :: level(:)
      integer :: top = 0, coarsest = 0, n_fine = 0
      logical :: surface = .false.   !< both axes are halved
      logical :: complex = .false.   !< a complex symbol (lines): LU on the coarsest grid
      !> Smoothing by rows (solve_rows) in place of Jacobi steps, on the grids of row_shapes:
      !> for a layer sliding along x, whose modulus depends on q_x
      logical :: rows = .false.
      !> V(0,1)-cycles: each coarse grid smooths only after its coarse correction (one
      !> residual, one transform pair of the grid, where V(1,1) takes two). The
      !> preconditioner of a flexible method (GCR) need not be symmetric; CG's must.
      logical :: sawtooth = .false.
      integer, allocatable :: pivots(:)
      real(wp), allocatable :: free(:)           !< 1 off the contact set, 0 on it (top grid)
      real(wp), allocatable :: dense(:, :)       !< Cholesky (LU) factor of the coarsest operator
      real(wp), allocatable :: coarse_column(:)  !< real-space column of its circulant part
      real(wp) :: pairs = 0.0_wp
      integer :: vcycles = 0
      !> The finest grid on this rank's slab of a surface shared among the job's ranks
      !> (docs/decisions/028-distributed-multigrid.md): its fields hold the rows y_start+1 ..
      !> y_start+ny_local, its multiplier the rank's columns of the transposed spectrum (the
      !> operator's plan); the coarser grids are whole, and alike on every rank.
      logical :: on_slabs = .false.
      integer :: y_start = 0, ny_local = 0
   end type hierarchy

   !> The modes of a finest nx x ny grid's half spectrum that a symbol array holds: all of
   !> them, kx fastest (a whole grid), or on a surface shared among the ranks this rank's
   !> columns kx = x_start .. x_start+columns-1 with all ny rows, ky fastest (the distributed
   !> plan's transposed spectrum: lc_fft_plans' mode_indices). The measures read off such a
   !> symbol (smoothing_factors, row_smoothing_factor) take each column on the rank that holds
   !> it and reduce over the ranks: a column's sum is added on its rank and the columns' sums
   !> in the order of kx on every rank, maxima are exact, so every rank gets the whole grid's
   !> values to the bit.
   type :: held_modes
      integer :: nx = 0, ny = 1
      integer :: x_start = 0, columns = 0
      logical :: distributed = .false.
   end type held_modes

contains

   !> The modes `op` holds of its grid's half spectrum (its rank's columns if distributed).
   function modes_of(op) result(modes)
      type(compliance_operator), intent(in) :: op
      type(held_modes) :: modes
      modes = whole_modes(op%grid%nx, op%grid%ny)
      if (.not. op%distributed) return
      modes%x_start = op%fft%x_start
      modes%columns = op%fft%nkx_local
      modes%distributed = .true.
   end function modes_of

   !> All the modes of the half spectrum of an nx x ny grid (ny = 1: a line), kx fastest.
   pure function whole_modes(nx, ny) result(modes)
      integer, intent(in) :: nx, ny
      type(held_modes) :: modes
      modes = held_modes(nx=nx, ny=ny, x_start=0, columns=nx/2 + 1, distributed=.false.)
   end function whole_modes

   !> The index in the held array of the mode (kx, ky), kx one of the held columns, ky any
   !> integer (periodic).
   pure integer function held_index(modes, kx, ky) result(i)
      type(held_modes), intent(in) :: modes
      integer, intent(in) :: kx, ky
      if (modes%distributed) then
         i = (kx - modes%x_start)*modes%ny + modulo(ky, modes%ny) + 1
      else
         i = kx + (modes%nx/2 + 1)*modulo(ky, modes%ny) + 1
      end if
   end function held_index

   !> How many times a grid of nx x ny points (ny = 1: a line) halves along every axis
   !> longer than 1 while the result has at least `smallest` points (and at least
   !> shortest_side along each axis of a surface): the coarsest grid is nx/2**k x ny/2**k.
   pure integer function halvings(nx, ny, smallest) result(k)
      integer, intent(in) :: nx, ny, smallest
      integer :: mx, my
      k = 0
      mx = nx
      my = ny
      do while (mod(mx, 2) == 0 .and. (mx/2)*max(my/2, 1) >= smallest)
         if (my > 1) then
            if (mod(my, 2) /= 0 .or. min(mx, my)/2 < shortest_side) exit
            my = my/2
         end if
         mx = mx/2
         k = k + 1
      end do
   end function halvings

   !> The shapes (nx, ny) of the grids t = 0..coarsest of the V-cycle. Every 2^t-th point
   !> along every axis (halvings), or, given the stiffness symbol of a surface (finest half
   !> spectrum, `odd` its imaginary part), grid by grid the halving that leaves the damped
   !> Jacobi step the smallest smoothing factor (smoothing_factors): both axes while that
   !> factor is at most accepted_smoothing, else the one axis along which the step damps the
   !> modes the next grid cannot carry. A layer sliding with a frequency-dependent modulus is
   !> stiffer along the sliding direction (E_inf/E0 = 10: tenfold between modes of one |q|);
   !> halving both axes leaves the short waves across it, soft, to a step that barely damps
   !> them. The full coarsening is kept if the other would end on a grid of more than
   !> coarsest_limit points.
   subroutine coarsening_shapes(nx, ny, shapes, symbol, odd, modes, worst)
      integer, intent(in) :: nx, ny
      integer, allocatable, intent(out) :: shapes(:, :)
      real(wp), contiguous, intent(in), optional :: symbol(:), odd(:)
      !> the modes `symbol` holds (default: the whole half spectrum)
      type(held_modes), intent(in), optional :: modes
      !> where the shapes are chosen by the smoothing factors: the largest factor of the
      !> halvings taken (worst_smoothing's), else -1
      real(wp), intent(out), optional :: worst
      integer, allocatable :: chosen(:, :)
      integer :: t, k, mx, my
      real(wp) :: mu_x, mu_y, mu_both, taken
      logical :: can_x, can_y, can_both
      if (present(worst)) worst = -1.0_wp
      taken = 0.0_wp
      k = halvings(nx, ny, coarsest_points)
      allocate (shapes(2, 0:k))
      do t = 0, k
         shapes(:, t) = [nx/2**t, merge(ny/2**t, 1, ny > 1)]
      end do
      if (.not. present(symbol) .or. ny == 1) return
      mx = nx
      my = ny
      allocate (chosen(2, 0:0))
      chosen(:, 0) = [mx, my]
      do
         can_x = halvable(mx) .and. (mx/2)*my >= coarsest_points
         can_y = halvable(my) .and. mx*(my/2) >= coarsest_points
         can_both = halvable(mx) .and. halvable(my) .and. (mx/2)*(my/2) >= coarsest_points
         if (.not. (can_x .or. can_y)) exit
         call smoothing_factors(held(nx, ny, modes), symbol, odd, mx, my, mu_x, mu_y, mu_both)
         if (can_both .and. mu_both <= accepted_smoothing) then
            mx = mx/2
            my = my/2
            taken = max(taken, mu_both)
         else if (can_x .and. (.not. can_y .or. mu_x <= mu_y)) then
            mx = mx/2
            taken = max(taken, mu_x)
         else
            my = my/2
            taken = max(taken, mu_y)
         end if
         chosen = reshape([chosen, mx, my], [2, size(chosen, 2) + 1])
      end do
      if (mx*my > coarsest_limit) return
      deallocate (shapes)
      allocate (shapes(2, 0:size(chosen, 2) - 1))
      shapes(:, :) = chosen
      if (present(worst)) worst = taken
   end subroutine coarsening_shapes

   !> Whether an axis of m points halves to one of at least shortest_side points.
   pure logical function halvable(m)
      integer, intent(in) :: m
      halvable = mod(m, 2) == 0 .and. m/2 >= shortest_side
   end function halvable

   !> The shapes (nx, ny) of the grids t = 0..coarsest of a V-cycle smoothed by rows, given
   !> the stiffness symbol of the finest surface (`odd` its imaginary part): both axes halved
   !> (as halvings), but y alone on a grid with more rows than points along them where
   !> halving both would leave the row step a smoothing factor above accepted_smoothing, and
   !> x alone until square where the finest grid has more than twice as many points along x
   !> as along y (elongated: see elongated_row_smoothing in lc_contact_solver_multigrid).
   !> The row step solves along x exactly, so on a grid halved along y alone it need only
   !> damp the waves short across the rows, as a line relaxation does; the 2:1 grids after
   !> it halve both axes (docs/decisions/015-row-smoothing.md, 'What is done', 'Grids with
   !> more rows than points along them').
   subroutine row_shapes(nx, ny, symbol, odd, shapes, modes)
      integer, intent(in) :: nx, ny
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      integer, allocatable, intent(out) :: shapes(:, :)
      type(held_modes), intent(in), optional :: modes
      integer :: mx, my, k
      integer :: chosen(2, 0:64)
      logical :: can_x, can_y, can_both
      mx = nx
      my = ny
      k = 0
      chosen(:, 0) = [mx, my]
      do
         can_x = nx > 2*ny .and. mx > my .and. halvable(mx) .and. (mx/2)*my >= coarsest_points
         if (can_x) then
            mx = mx/2
            k = k + 1
            chosen(:, k) = [mx, my]
            cycle
         end if
         can_y = my > mx .and. halvable(my) .and. mx*(my/2) >= coarsest_points
         can_both = halvable(mx) .and. halvable(my) .and. (mx/2)*(my/2) >= coarsest_points
         if (can_y .and. can_both) &
            & can_both = row_smoothing_factor(held(nx, ny, modes), symbol, odd, mx, my, .true.) <= accepted_smoothing
         if (can_both) then
            mx = mx/2
            my = my/2
         else if (can_y) then
            my = my/2
         else
            exit
         end if
         k = k + 1
         chosen(:, k) = [mx, my]
      end do
      allocate (shapes(2, 0:k))
      shapes(:, :) = chosen(:, 0:k)
   end subroutine row_shapes

   !> The largest smoothing factor of the damped Jacobi step over the grids of the V-cycle
   !> (coarsening_shapes; smoothing_factors for the halving each grid takes), for the
   !> stiffness symbol of the finest nx x ny grid (`odd` its imaginary part): near 1, some
   !> mode that the next grid cannot carry is barely damped.
   function worst_smoothing(nx, ny, symbol, odd, modes) result(worst)
      integer, intent(in) :: nx, ny
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      !> the modes `symbol` holds (default: the whole half spectrum)
      type(held_modes), intent(in), optional :: modes
      real(wp) :: worst
      integer, allocatable :: shapes(:, :)
      real(wp) :: mu_x, mu_y, mu_both
      logical :: along_x, along_y
      integer :: t
      ! (the shapes chosen by their smoothing factors come with the worst of them)
      call coarsening_shapes(nx, ny, shapes, symbol, odd, modes, worst)
      if (worst >= 0.0_wp) return
      worst = 0.0_wp
      do t = 0, ubound(shapes, 2) - 1
         call smoothing_factors(held(nx, ny, modes), symbol, odd, shapes(1, t), shapes(2, t), mu_x, mu_y, mu_both)
         along_x = shapes(1, t + 1) < shapes(1, t)
         along_y = shapes(2, t + 1) < shapes(2, t)
         if (along_x .and. along_y) then
            worst = max(worst, mu_both)
         else if (along_y) then
            worst = max(worst, mu_y)
         else
            worst = max(worst, mu_x)
         end if
      end do
   end function worst_smoothing

   !> The largest smoothing factor of the row smoothing step (solve_rows, damped by omega)
   !> over the grids of row_shapes, for the stiffness symbol of the finest nx x ny surface
   !> (`odd` its imaginary part).
   function worst_row_smoothing(nx, ny, symbol, odd, modes) result(worst)
      integer, intent(in) :: nx, ny
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      !> the modes `symbol` holds (default: the whole half spectrum)
      type(held_modes), intent(in), optional :: modes
      real(wp) :: worst
      integer, allocatable :: shapes(:, :)
      integer :: t
      call row_shapes(nx, ny, symbol, odd, shapes, modes)
      worst = 0.0_wp
      do t = 0, ubound(shapes, 2) - 1
         worst = max(worst, row_smoothing_factor(held(nx, ny, modes), symbol, odd, shapes(1, t), shapes(2, t), &
            & shapes(1, t + 1) < shapes(1, t)))
      end do
   end function worst_row_smoothing

   !> `modes` if present, else the whole half spectrum of the nx x ny grid.
   pure function held(nx, ny, modes)
      integer, intent(in) :: nx, ny
      type(held_modes), intent(in), optional :: modes
      type(held_modes) :: held
      if (present(modes)) then
         held = modes
      else
         held = whole_modes(nx, ny)
      end if
   end function held

   !> The smoothing factor of the row step on an mx x my grid for the stiffness symbol of the
   !> finest nx x ny surface read at the grid's modes: the largest |1 - omega K(q)/K_row(kx)|
   !> over the modes the next grid cannot carry (halved along y, and along x if along_x).
   !> A column's sum is its own: each rank takes its columns, the largest over the ranks.
   function row_smoothing_factor(modes, symbol, odd, mx, my, along_x) result(worst)
      type(held_modes), intent(in) :: modes
      integer, intent(in) :: mx, my
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      logical, intent(in) :: along_x
      real(wp) :: worst
      complex(wp) :: row   !< the sum of a column, then 1/K_row
      integer :: kx, ky
      worst = 0.0_wp
      ! (each column read twice, for its sum and for the factors, rather than stored)
      do kx = modes%x_start, min(mx/2, modes%x_start + modes%columns - 1)
         row = 0.0_wp
         do ky = 0, my - 1
            row = row + stiffness_at(kx, ky)
         end do
         if (abs(row) == 0.0_wp) cycle
         row = my*inverse(row)
         do ky = 0, my - 1
            if ((along_x .and. 4*kx > mx) .or. 4*abs(signed(ky)) > my) &
               & worst = max(worst, abs(1.0_wp - omega*stiffness_at(kx, ky)*row))
         end do
      end do
      if (modes%distributed) worst = global_max(worst)
   contains
      !> the finest symbol at the mode (kx, ky) of the current grid
      pure complex(wp) function stiffness_at(kx, ky) result(k)
         integer, intent(in) :: kx, ky
         integer :: i
         i = held_index(modes, kx, signed(ky))
         k = symbol(i)
         if (present(odd)) k = cmplx(symbol(i), odd(i), kind=wp)
      end function stiffness_at

      pure integer function signed(ky)
         integer, intent(in) :: ky
         signed = merge(ky, ky - my, 2*ky <= my)
      end function signed
   end function row_smoothing_factor

   !> The smoothing factors of the damped Jacobi step (its diagonal as set_grid takes it, with
   !> the mean over the half spectrum) on
   !> an mx x my grid for the stiffness symbol of the finest grid (the modes `modes` holds)
   !> read at the coarse grid's modes: the largest |1 - omega K(q)/d| over the modes a grid
   !> halved along x (mu_x), along y (mu_y) or along both (mu_both) does not carry. The mean
   !> is summed column by column, then over the columns in the order of kx: held by several
   !> ranks, each column's sum is its rank's and the same on any number of ranks.
   subroutine smoothing_factors(modes, symbol, odd, mx, my, mu_x, mu_y, mu_both)
      type(held_modes), intent(in) :: modes
      integer, intent(in) :: mx, my
      real(wp), intent(in) :: symbol(:)
      real(wp), intent(in), optional :: odd(:)
      real(wp), intent(out) :: mu_x, mu_y, mu_both
      real(wp) :: mean, bound, factors(3)
      real(wp) :: column(0:mx/2), shared(0:mx/2 + 1)
      integer :: kx, ky, sy, pass, last, base
      last = min(mx/2, modes%x_start + modes%columns - 1)
      column = 0.0_wp
      mean = 0.0_wp
      bound = 0.0_wp
      mu_x = 0.0_wp
      mu_y = 0.0_wp
      mu_both = 0.0_wp
      do pass = 1, 2
         ! (the modes in the order they are stored: the columns in turn on a slab, the rows
         ! on a whole grid; a column's sum runs over ky in order either way)
         if (modes%distributed) then
            ! (ky in order, its rows 0..my/2 and then the negative ones, -(my - 1)/2..-1,
            ! which lie at the column's end: no division a mode)
            do kx = modes%x_start, last
               base = (kx - modes%x_start)*modes%ny + 1
               do ky = 0, my/2
                  call take(kx, ky, base + ky)
               end do
               do ky = my/2 + 1, my - 1
                  call take(kx, ky - my, base + modes%ny + ky - my)
               end do
            end do
         else
            do ky = 0, my - 1
               sy = merge(ky, ky - my, 2*ky <= my)
               base = (modes%nx/2 + 1)*modulo(sy, modes%ny) + 1
               do kx = 0, last
                  call take(kx, sy, base + kx)
               end do
            end do
         end if
         ! (the second pass takes the Jacobi diagonal for `mean`)
         if (pass == 1) then
            if (modes%distributed) then
               ! (a column's sum is its rank's, at least 0, and 0 on the others: its largest
               ! over the ranks, exactly; one message with the bound)
               shared(0:mx/2) = column
               shared(mx/2 + 1) = bound
               call max_over_ranks(shared)
               column = shared(0:mx/2)
               bound = shared(mx/2 + 1)
            end if
            do kx = 0, mx/2
               mean = mean + column(kx)
            end do
            mean = max(mean/((mx/2 + 1)*my), jacobi_margin*omega*bound)
         end if
      end do
      if (modes%distributed) then
         factors = [mu_x, mu_y, mu_both]
         call max_over_ranks(factors)
         mu_x = factors(1)
         mu_y = factors(2)
         mu_both = factors(3)
      end if
   contains
      !> the mode (kx, sy) of the mx x my grid, at index i of the held modes
      subroutine take(kx, sy, i)
         integer, intent(in) :: kx, sy, i
         complex(wp) :: stiffness
         real(wp) :: factor
         stiffness = cmplx(symbol(i), 0.0_wp, kind=wp)
         if (present(odd)) stiffness = cmplx(symbol(i), odd(i), kind=wp)
         if (.not. real(stiffness) > 0.0_wp) return
         if (pass == 1) then
            column(kx) = column(kx) + real(stiffness)
            bound = max(bound, abs(stiffness)**2/(2*real(stiffness)))
         else
            factor = abs(1.0_wp - omega*stiffness/mean)
            if (4*kx > mx) mu_x = max(mu_x, factor)
            if (4*abs(sy) > my) mu_y = max(mu_y, factor)
            if (4*kx > mx .or. 4*abs(sy) > my) mu_both = max(mu_both, factor)
         end if
      end subroutine take
   end subroutine smoothing_factors

   !> z = B r, B = omega/d I + I P V P^T I: a damped Jacobi step and the coarse correction
   !> added (not one after the other: no transform on the grid being solved; symmetric, as CG
   !> needs), V the V-cycle of the next grid; the dense solve where the grid being solved is
   !> the coarsest. Smoothing by rows, the row step omega I K_row^-1 I in place of the Jacobi
   !> step (the rows' transforms on the grid being solved). r is zero on the contact set, and
   !> so is z.
   subroutine precondition(h, r, z)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: r(:)
      real(wp), contiguous, intent(inout) :: z(:)
      h%vcycles = h%vcycles + 1
      if (h%top == h%coarsest) then
         z = r
         call coarsest_solve(h, z)
         return
      end if
      if (across_ranks(h)) then
         ! (the first coarse grid whole on every rank: each slab's share of P^T r summed over
         ! the ranks, the V-cycle run alike, and each rank interpolating onto its own rows)
         call restrict_slab(h, r, h%level(1)%rhs)
         call vcycle(h, 1)
         if (h%rows) then
            call solve_rows(h, 0, r)
            associate (step => h%level(0)%rows_fft%real_buffer)
            step = h%free(1:size(r))*step
            call prolong_slab_add(h, h%level(1)%x, z, h%free(1:size(r)), step, omega)
            end associate
         else
            call prolong_slab_add(h, h%level(1)%x, z, h%free(1:size(r)), r, omega/h%level(0)%jacobi_diagonal)
         end if
         return
      end if
      call restrict(h, h%top, r, h%level(h%top + 1)%rhs)
      call vcycle(h, h%top + 1)
      if (h%rows) then
         ! (the step masked, as r is; the coarse levels have their own buffers, so this one
         ! still holds it for prolong_add)
         call solve_rows(h, h%top, r)
         associate (step => h%level(h%top)%rows_fft%real_buffer)
         step = h%free(1:size(r))*step
         call prolong_add(h, h%top, h%level(h%top + 1)%x, z, h%free(1:size(r)), step, omega)
         end associate
      else
         call prolong_add(h, h%top, h%level(h%top + 1)%x, z, h%free(1:size(r)), r, &
            & omega/h%level(h%top)%jacobi_diagonal)
      end if
   end subroutine precondition

   !> One V(1,1)-cycle (V(0,1) for a sawtooth hierarchy) on the coarse level t > h%top:
   !> x ~ A_t^-1 rhs with the penalised Galerkin operators; the coarsest grid is solved
   !> exactly.
   recursive subroutine vcycle(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      if (t == h%coarsest) then
         h%level(t)%x = h%level(t)%rhs
         call coarsest_solve(h, h%level(t)%x)
         return
      end if
      associate (lv => h%level(t))
      if (h%sawtooth) then
         call restrict(h, t, lv%rhs, h%level(t + 1)%rhs)
         call vcycle(h, t + 1)
         lv%x = 0.0_wp
      else
         if (h%rows) then
            call solve_rows(h, t, lv%rhs)
            call multiply(lv%jacobi, lv%fft%real_buffer, lv%x)
         else
            lv%x = lv%jacobi*lv%rhs
         end if
         call level_residual(h, t)
         call restrict(h, t, lv%residual, h%level(t + 1)%rhs)
         call vcycle(h, t + 1)
      end if
      call prolong_add(h, t, h%level(t + 1)%x, lv%x)
      call level_residual(h, t)
      if (h%rows) then
         call solve_rows(h, t, lv%residual)
         call multiply(lv%jacobi, lv%fft%real_buffer, lv%x, accumulate=.true.)
      else
         lv%x = lv%x + lv%jacobi*lv%residual
      end if
      end associate
   end subroutine vcycle

   !> The buffer of level t <- (K_row + s)^-1 r, row by row: the exact inverse of the part of
   !> the circulant that couples the points of one row (its real-space column at y = 0, whose
   !> symbol along x is K_row), s the row's shift. A layer sliding along x has a modulus
   !> E(q_x V): within a column of the spectrum K/K_row does not depend on E, so the step
   !> damps the modes the next grid cannot carry as a Jacobi step damps those of an elastic
   !> layer, soft and lossy modes alike (docs/decisions/015-row-smoothing.md, 'What is
   !> done', 'Row smoothing'). The rows' transforms are counted as half a
   !> transform pair of the grid.
   subroutine solve_rows(h, t, r)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      real(wp), contiguous, intent(in) :: r(:)
      integer :: row, nkx, rows
      associate (lv => h%level(t), fft => h%level(t)%rows_fft)
      ! (on a slab, its rows)
      rows = merge(h%ny_local, lv%ny, t == 0 .and. h%on_slabs)
      call copy(r, fft%real_buffer)
      call fft%rows_forward_unscaled()
      nkx = lv%nx/2 + 1
      do row = 0, rows - 1
         associate (coefficients => fft%spectrum(row*nkx + 1:(row + 1)*nkx))
         if (lv%row_shift(row + 1) == 0.0_wp) then
            coefficients = coefficients*lv%row_inverse
         else
            coefficients = coefficients*inverse(lv%row_symbol + lv%row_shift(row + 1))/lv%nx
         end if
         end associate
      end do
      call fft%rows_backward()
      h%pairs = h%pairs + 0.5_wp*real(lv%n, wp)/h%n_fine
      end associate
   end subroutine solve_rows

   !> residual = rhs - A_t x on the coarse level t (one transform pair of that grid).
   subroutine level_residual(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      associate (lv => h%level(t))
      call copy(lv%x, lv%fft%real_buffer)
      call transform(h, t)
      call difference(lv%rhs, lv%fft%real_buffer, lv%residual)
      call subtract_stencil(lv%penalty, lv%x, lv%residual, lv%nx, lv%ny)
      end associate
   end subroutine level_residual

   !> The passes through a plan's buffer (a pointer component, which gfortran reads through
   !> its descriptor at every element, unvectorised) go through these procedures, whose
   !> contiguous dummies vectorise: b = a; c = a - b; c = a b, or c = c + a b.
   pure subroutine copy(a, b)
      real(wp), contiguous, intent(in) :: a(:)
      real(wp), contiguous, intent(out) :: b(:)
      b = a
   end subroutine copy

   pure subroutine difference(a, b, c)
      real(wp), contiguous, intent(in) :: a(:), b(:)
      real(wp), contiguous, intent(out) :: c(:)
      c = a - b
   end subroutine difference

   pure subroutine multiply(a, b, c, accumulate)
      real(wp), contiguous, intent(in) :: a(:), b(:)
      real(wp), contiguous, intent(inout) :: c(:)
      logical, intent(in), optional :: accumulate
      logical :: add
      add = .false.
      if (present(accumulate)) add = accumulate
      if (add) then
         c = c + a*b
      else
         c = a*b
      end if
   end subroutine multiply

   !> y = A_t x, the operator of level t: its circulant plus, on a coarse level, the
   !> penalty's stencil (the V-cycle's operator; on the grid being solved the circulant K
   !> alone). For checks of the coarse operators against P^T A_(t-1) P.
   subroutine level_operator(h, t, x, y)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      real(wp), contiguous, intent(in) :: x(:)
      real(wp), contiguous, intent(out) :: y(:)
      associate (lv => h%level(t))
      lv%fft%real_buffer = x
      call transform(h, t)
      y = 0.0_wp
      if (t > h%top) call subtract_stencil(lv%penalty, x, y, lv%nx, lv%ny)
      y = lv%fft%real_buffer - y
      end associate
   end subroutine level_operator

   !> r <- r - S x for the 9-point (3-point on a line, ny = 1) periodic stencil S:
   !> (S x)(i) = sum over (ex, ey) of s(ex, ey, i) x(i + (ex, ey)).
   pure subroutine subtract_stencil(s, x, r, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: s(-1:1, -min(ny - 1, 1):min(ny - 1, 1), 0:nx - 1, 0:ny - 1), x(0:nx - 1, 0:ny - 1)
      real(wp), intent(inout) :: r(0:nx - 1, 0:ny - 1)
      integer :: iy, ey, row
      do iy = 0, ny - 1
         do ey = merge(-1, 0, ny > 1), merge(1, 0, ny > 1)
            row = modulo(iy + ey, ny)
            call subtract_row(s(:, :, :, iy), min(ny - 1, 1), ey, x(:, row), r(:, iy), nx)
         end do
      end do
   contains
      !> rr <- rr - the stencil's row ey applied to the row xr, periodic
      pure subroutine subtract_row(a, reach, ey, xr, rr, n)
         integer, intent(in) :: n, reach, ey
         real(wp), intent(in) :: a(-1:1, -reach:reach, 0:n - 1), xr(0:n - 1)
         real(wp), intent(inout) :: rr(0:n - 1)
         integer :: i
         rr(0) = rr(0) - (a(-1, ey, 0)*xr(n - 1) + a(0, ey, 0)*xr(0) + a(1, ey, 0)*xr(1))
         do i = 1, n - 2
            rr(i) = rr(i) - (a(-1, ey, i)*xr(i - 1) + a(0, ey, i)*xr(i) + a(1, ey, i)*xr(i + 1))
         end do
         rr(n - 1) = rr(n - 1) - (a(-1, ey, n - 1)*xr(n - 2) + a(0, ey, n - 1)*xr(n - 1) + a(1, ey, n - 1)*xr(0))
      end subroutine subtract_row
   end subroutine subtract_stencil

   !> y = K x (+ shift) on the grid being solved (one transform pair), and x.K x.
   subroutine apply_stiffness(h, x, y, shift, xy)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: x(:)
      real(wp), contiguous, intent(out) :: y(:)
      real(wp), intent(in), optional :: shift   !< added to y
      real(wp), intent(out), optional :: xy     !< x.y (without the shift)
      real(wp) :: f, dot
      call copy(x, h%level(h%top)%fft%real_buffer)
      call transform(h, h%top)
      ! (the shift and the product in the pass that reads the result out)
      f = 0.0_wp
      if (present(shift)) f = shift
      call read_out(h%level(h%top)%fft%real_buffer, x, f, y, dot)
      if (present(xy)) then
         if (across_ranks(h)) dot = global_sum(dot)
         xy = dot
      end if
   end subroutine apply_stiffness

   !> y = buffer + f and x.buffer in one pass (see copy)
   subroutine read_out(buffer, x, f, y, dot)
      real(wp), contiguous, intent(in) :: buffer(:), x(:)
      real(wp), intent(in) :: f
      real(wp), contiguous, intent(out) :: y(:)
      real(wp), intent(out) :: dot
      real(wp) :: partial
      real(wp) :: block_sums(reduction_blocks(size(x)))
      integer :: j, block, first, last
      ! (by blocks, added in order: the same bits on any number of threads)
      !$omp parallel do schedule(static) private(first, last, partial) if(size(x) >= parallel_points)
      do block = 1, size(block_sums)
         call block_range(block, size(x), first, last)
         partial = 0.0_wp
         !$omp simd reduction(+:partial)
         do j = first, last
            partial = partial + x(j)*buffer(j)
            y(j) = buffer(j) + f
         end do
         block_sums(block) = partial
      end do
      dot = sum(block_sums)
   end subroutine read_out

   !> The buffer of level t times its circulant, counted in pairs of the finest grid.
   subroutine transform(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      associate (lv => h%level(t))
      call lv%fft%forward_unscaled()
      if (h%complex) then
         call multiply_complex(lv%fft%spectrum, lv%cmultiplier)
      else
         call multiply_spectrum(lv%fft%spectrum, lv%multiplier)
      end if
      call lv%fft%backward()
      h%pairs = h%pairs + real(lv%n, wp)/h%n_fine
      end associate
   end subroutine transform

   !> coarse (level t + 1) = P^T fine (level t); P: linear interpolation, periodic, along x
   !> and (a surface) along y.
   subroutine restrict(h, t, fine, coarse)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      real(wp), contiguous, intent(in) :: fine(:)
      real(wp), contiguous, intent(out) :: coarse(:)
      associate (lv => h%level(t))
      if (lv%halve_x .and. lv%halve_y) then
         call restrict_x(fine, lv%halfway, lv%nx, lv%ny)
         call restrict_y(lv%halfway, coarse, lv%nx/2, lv%ny)
      else if (lv%halve_y) then
         call restrict_y(fine, coarse, lv%nx, lv%ny)
      else
         call restrict_x(fine, coarse, lv%nx, lv%ny)
      end if
      end associate
   end subroutine restrict

   !> fine (level t) <- fine + P coarse (level t + 1), masked by `free` if given; with
   !> `base` fine <- scale base + P coarse masked (the grid being solved: its Jacobi step
   !> and coarse correction in one pass).
   subroutine prolong_add(h, t, coarse, fine, free, base, scale)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      real(wp), contiguous, intent(in) :: coarse(:)
      real(wp), contiguous, intent(inout) :: fine(:)
      real(wp), contiguous, intent(in), optional :: free(:), base(:)
      real(wp), intent(in), optional :: scale
      associate (lv => h%level(t))
      if (lv%halve_x .and. lv%halve_y) then
         call prolong_y(coarse, lv%halfway, lv%nx/2, lv%ny)
         call prolong_x_add(lv%halfway, fine, lv%nx, lv%ny, free, base, scale)
      else if (lv%halve_y) then
         call prolong_y(coarse, lv%halfway, lv%nx, lv%ny)
         call add_masked(lv%halfway, fine, free, base, scale)
      else
         call prolong_x_add(coarse, fine, lv%nx, lv%ny, free, base, scale)
      end if
      end associate
   end subroutine prolong_add

   !> fine <- fine + x, masked by `free` if given; with `base` (and free),
   !> fine <- scale base + free x (prolong_x_add's cases for a grid not halved along x).
   pure subroutine add_masked(x, fine, free, base, scale)
      real(wp), contiguous, intent(in) :: x(:)
      real(wp), contiguous, intent(inout) :: fine(:)
      real(wp), contiguous, intent(in), optional :: free(:), base(:)
      real(wp), intent(in), optional :: scale
      if (present(base)) then
         fine = scale*base + free*x
      else if (present(free)) then
         fine = fine + free*x
      else
         fine = fine + x
      end if
   end subroutine add_masked

   !> Along x, row by row: coarse(i) = fine(2i - 1) + (fine(2i) + fine(2i - 2))/2.
   pure subroutine restrict_x(fine, coarse, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: fine(nx, ny)
      real(wp), intent(out) :: coarse(nx/2, ny)
      integer :: i, j, m
      m = nx/2
      do j = 1, ny
         coarse(1, j) = fine(1, j) + 0.5_wp*(fine(2, j) + fine(2*m, j))
         do i = 2, m
            coarse(i, j) = fine(2*i - 1, j) + 0.5_wp*(fine(2*i, j) + fine(2*i - 2, j))
         end do
      end do
   end subroutine restrict_x

   !> Along y: the same for the rows.
   pure subroutine restrict_y(fine, coarse, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: fine(nx, ny)
      real(wp), intent(out) :: coarse(nx, ny/2)
      integer :: j, m
      m = ny/2
      coarse(:, 1) = fine(:, 1) + 0.5_wp*(fine(:, 2) + fine(:, 2*m))
      do j = 2, m
         coarse(:, j) = fine(:, 2*j - 1) + 0.5_wp*(fine(:, 2*j) + fine(:, 2*j - 2))
      end do
   end subroutine restrict_y

   !> Along x, row by row: fine <- fine + P coarse, masked by `free` if given; with `base`
   !> (and free), fine <- scale base + free P coarse.
   pure subroutine prolong_x_add(coarse, fine, nx, ny, free, base, scale)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: coarse(nx/2, ny)
      real(wp), intent(inout) :: fine(nx, ny)
      real(wp), intent(in), optional :: free(nx, ny), base(nx, ny)
      real(wp), intent(in), optional :: scale
      integer :: j, m
      ! (the last point of a row, between the last coarse point and the first, apart: the
      ! passes over the others then vectorise)
      m = nx/2
      do j = 1, ny
         if (present(base)) then
            fine(1:nx:2, j) = scale*base(1:nx:2, j) + free(1:nx:2, j)*coarse(:, j)
            fine(2:nx - 2:2, j) = scale*base(2:nx - 2:2, j) + free(2:nx - 2:2, j)*0.5_wp*(coarse(1:m - 1, j) + &
               & coarse(2:m, j))
            fine(nx, j) = scale*base(nx, j) + free(nx, j)*0.5_wp*(coarse(m, j) + coarse(1, j))
         else if (present(free)) then
            fine(1:nx:2, j) = fine(1:nx:2, j) + free(1:nx:2, j)*coarse(:, j)
            fine(2:nx - 2:2, j) = fine(2:nx - 2:2, j) + free(2:nx - 2:2, j)*0.5_wp*(coarse(1:m - 1, j) + coarse(2:m, j))
            fine(nx, j) = fine(nx, j) + free(nx, j)*0.5_wp*(coarse(m, j) + coarse(1, j))
         else
            fine(1:nx:2, j) = fine(1:nx:2, j) + coarse(:, j)
            fine(2:nx - 2:2, j) = fine(2:nx - 2:2, j) + 0.5_wp*(coarse(1:m - 1, j) + coarse(2:m, j))
            fine(nx, j) = fine(nx, j) + 0.5_wp*(coarse(m, j) + coarse(1, j))
         end if
      end do
   end subroutine prolong_x_add

   !> Along y: fine = P coarse (assigned).
   pure subroutine prolong_y(coarse, fine, nx, ny)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: coarse(nx, ny/2)
      real(wp), intent(out) :: fine(nx, ny)
      integer :: j, m
      m = ny/2
      do j = 1, m
         fine(:, 2*j - 1) = coarse(:, j)
         fine(:, 2*j) = 0.5_wp*(coarse(:, j) + coarse(:, mod(j, m) + 1))
      end do
   end subroutine prolong_y

   !> The grids of the V-cycle (coarsening_shapes), with their plans and work arrays
   !> (allocated once, for all the nested grids). With `symbol` (a surface's stiffness on the
   !> finest grid's half spectrum, `odd` its imaginary part) a grid may be halved along one
   !> axis only. `modes`: the modes `symbol` holds (default: the whole half spectrum).
   subroutine build_hierarchy(h, op, error, symbol, odd, rows, modes)
      type(hierarchy), intent(out), target :: h
      type(compliance_operator), intent(inout), target :: op
      type(error_type), allocatable, intent(out) :: error
      real(wp), contiguous, intent(in), optional :: symbol(:), odd(:)
      logical, intent(in), optional :: rows
      type(held_modes), intent(in), optional :: modes
      integer, allocatable :: shapes(:, :)
      integer :: t, m, nx, ny, reach
      nx = op%grid%nx
      ny = op%grid%ny
      reach = merge(1, 0, ny > 1)
      h%surface = ny > 1
      if (present(rows)) h%rows = rows .and. h%surface
      if (h%rows) then
         call row_shapes(nx, ny, symbol, odd, shapes, modes)
      else
         call coarsening_shapes(nx, ny, shapes, symbol, odd, modes)
      end if
      h%coarsest = ubound(shapes, 2)
      h%n_fine = nx*ny
      h%on_slabs = op%distributed
      if (h%on_slabs) then
         if (h%coarsest == 0) then
            call fatal_error(error, 'multigrid: a hierarchy on slabs needs a coarser grid', code_internal)
            return
         end if
         h%y_start = op%fft%y_start
         h%ny_local = op%fft%ny_local
         ! (the slab's contact set, or a whole coarse grid's in the nested iteration)
         allocate (h%level(0:h%coarsest), h%free(max(nx*h%ny_local, shapes(1, 1)*shapes(2, 1))))
      else
         allocate (h%level(0:h%coarsest), h%free(nx*ny))
      end if
      h%free = 1.0_wp
      do t = 0, h%coarsest
         associate (lv => h%level(t))
         lv%nx = shapes(1, t)
         lv%ny = shapes(2, t)
         if (t < h%coarsest) then
            lv%halve_x = shapes(1, t + 1) < lv%nx
            lv%halve_y = shapes(2, t + 1) < lv%ny
         end if
         lv%n = lv%nx*lv%ny
         m = lv%n
         lv%inv_n = 1.0_wp/m
         if (t == 0) then
            lv%fft => op%fft
         else
            allocate (lv%plan)
            ! (FFTW's threads on the grids large enough for them to pay)
            call lv%plan%init(lv%nx, lv%ny, merge(active_threads(), 1, m >= parallel_points), error)
            if (allocated(error)) return
            lv%fft => lv%plan
         end if
         if (h%rows) then
            lv%rows_fft => lv%fft
            if (t == 0 .and. h%on_slabs) then
               allocate (lv%plan)
               call lv%plan%init(lv%nx, h%ny_local, 1, error)
               if (allocated(error)) return
               lv%rows_fft => lv%plan
            end if
            call lv%rows_fft%plan_rows(error)
            if (allocated(error)) return
            allocate (lv%row_symbol(lv%nx/2 + 1), lv%row_inverse(lv%nx/2 + 1), lv%row_shift(lv%ny))
            lv%row_shift = 0.0_wp
         end if
         ! (on slabs the finest grid's symbol is whole, for the Galerkin symbols below it, its
         ! multiplier the rank's modes)
         allocate (lv%symbol((lv%nx/2 + 1)*lv%ny), lv%multiplier(merge(op%nk, (lv%nx/2 + 1)*lv%ny, &
            & t == 0 .and. h%on_slabs)))
         ! (the finest grid is never a coarse one of the V-cycle)
         ! (the stencil couples rows on a surface only)
         if (t > 0) allocate (lv%penalty(-1:1, -reach:reach, m), lv%jacobi(m), lv%rhs(m), lv%x(m), lv%residual(m))
         if (t == 0 .and. h%on_slabs) then
            ! (the slab's rows on the next grid's x: restrict_slab, prolong_slab_add)
            allocate (lv%halfway(merge(lv%nx/2, lv%nx, lv%halve_x)*h%ny_local))
         else if (t < h%coarsest .and. lv%halve_y) then
            allocate (lv%halfway(merge(m/2, m, lv%halve_x)), lv%window(-1:1, -1:1, shapes(1, t + 1), -1:1))
         end if
         end associate
      end do
      m = h%level(h%coarsest)%n
      allocate (h%dense(m, m), h%coarse_column(m))
   end subroutine build_hierarchy

   !> The flat index on the half spectrum of an nx x ny grid of the mode (kx, ky), any
   !> integers: periodic, and a mode outside the half spectrum is read at its mirror image
   !> -(kx, ky) (the symbols here are real and even).
   pure integer function mode_index(nx, ny, kx, ky) result(i)
      integer, intent(in) :: nx, ny, kx, ky
      integer :: mx, my
      mx = modulo(kx, nx)
      my = modulo(ky, ny)
      if (2*mx > nx) then
         mx = nx - mx
         my = modulo(-my, ny)
      end if
      i = mx + (nx/2 + 1)*my + 1
   end function mode_index

   !> The stiffness K = 1/M on the half spectrum of grid `coarse` of the nested iteration
   !> (K = 0 where M = 0; K(0) = 0 under load control, the uniform mode being dropped: see
   !> drop_uniform_mode): the coarse grid's wavevectors are among the finest grid's (its
   !> Nyquist modes read at +pi/dx: M is even in each component, |q| being all it depends on).
   pure function level_symbol(op, load_control, nx, ny) result(stiffness)
      type(compliance_operator), intent(in) :: op
      logical, intent(in) :: load_control
      integer, intent(in) :: nx, ny
      real(wp) :: stiffness((nx/2 + 1)*ny)
      real(wp) :: m
      integer :: kx, ky, my
      do ky = 0, ny - 1
         my = merge(ky, ky - ny, 2*ky <= ny)
         do kx = 0, nx/2
            m = op%metric(mode_index(op%grid%nx, op%grid%ny, kx, my))
            stiffness(kx + (nx/2 + 1)*ky + 1) = 0.0_wp
            if (m > 0.0_wp) stiffness(kx + (nx/2 + 1)*ky + 1) = 1.0_wp/m
         end do
      end do
      if (load_control) stiffness(1) = 0.0_wp
   end function level_symbol

   !> level_symbol from the stiffness `finest` on the half spectrum of the nx x ny grid
   !> (level_symbol's of that grid): the same values on the mx x my grid, where the operator
   !> holds only its rank's modes.
   pure function sampled_symbol(finest, nx, ny, mx, my) result(stiffness)
      real(wp), contiguous, intent(in) :: finest(:)
      integer, intent(in) :: nx, ny, mx, my
      real(wp) :: stiffness((mx/2 + 1)*my)
      integer :: kx, ky, sy
      do ky = 0, my - 1
         sy = merge(ky, ky - my, 2*ky <= my)
         do kx = 0, mx/2
            stiffness(kx + (mx/2 + 1)*ky + 1) = finest(mode_index(nx, ny, kx, sy))
         end do
      end do
   end function sampled_symbol

   !> f (nx x ny) at every step-th point along each axis longer than 1.
   pure subroutine sample(f, nx, ny, step, fc)
      integer, intent(in) :: nx, ny, step
      real(wp), intent(in) :: f(nx, ny)
      real(wp), intent(out) :: fc(nx/step, max(ny/step, 1))
      if (ny > 1) then
         fc = f(1:nx:step, 1:ny:step)
      else
         fc = f(1:nx:step, :)
      end if
   end subroutine sample

   !> Make grid `top` the one being solved, with the stiffness symbol K on its half spectrum:
   !> the Galerkin circulants P^T C P below it (their symbols in closed form: along each
   !> halved axis a coarse mode k gathers the fine modes k and k + m_c with the weights
   !> 2 alpha^2 and 2 beta^2, alpha, beta = (1 +- cos(pi k/m_c))/2; on a surface halved along
   !> both axes the products of the two axes' weights over the four fine modes: galerkin),
   !> their diagonals, and the real-space column of the coarsest one. With `odd` the symbol is
   !> complex, symbol + i odd, its imaginary part odd (odd in kx on a line): the hierarchy of
   !> a non-symmetric stiffness.
   subroutine set_grid(h, top, symbol, odd)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: top
      real(wp), contiguous, intent(in) :: symbol(:)
      real(wp), contiguous, intent(in), optional :: odd(:)
      integer :: t, kx, ky, nkx, row, first, last, k
      h%top = top
      h%level(top)%symbol = symbol
      h%complex = present(odd)
      if (h%complex) then
         do t = top, h%coarsest
            associate (lv => h%level(t))
            if (.not. allocated(lv%odd)) allocate (lv%odd(size(lv%symbol)), lv%cmultiplier(size(lv%multiplier)))
            end associate
         end do
         if (.not. allocated(h%pivots)) allocate (h%pivots(size(h%dense, 1)))
         h%level(top)%odd = odd
      end if
      do t = top + 1, h%coarsest
         associate (c => h%level(t), f => h%level(t - 1))
         nkx = c%nx/2 + 1
         do ky = 0, c%ny - 1
            do kx = 0, c%nx/2
               c%symbol(kx + nkx*ky + 1) = galerkin(f, c, kx, ky, .false.)
               if (h%complex) c%odd(kx + nkx*ky + 1) = galerkin(f, c, kx, ky, .true.)
            end do
         end do
         end associate
      end do
      do t = top, h%coarsest
         associate (lv => h%level(t))
         ! (1/n) sum over the whole spectrum, row by row of the half spectrum: the modes of a
         ! row stand for two, but for its mx = 0 and (even nx) Nyquist ones
         nkx = lv%nx/2 + 1
         lv%circulant_diagonal = 0.0_wp
         do row = 1, lv%ny
            first = (row - 1)*nkx + 1
            last = row*nkx
            lv%circulant_diagonal = lv%circulant_diagonal + (lv%symbol(first) + 2*sum(lv%symbol(first + 1:last)) &
               & - merge(lv%symbol(last), 0.0_wp, mod(lv%nx, 2) == 0))
         end do
         lv%circulant_diagonal = lv%circulant_diagonal*lv%inv_n
         lv%jacobi_diagonal = max(lv%circulant_diagonal, jacobi_margin*omega*maxval(lv%symbol)/2)
         if (t == 0 .and. h%on_slabs) then
            call slab_multiplier(lv)
         else
            lv%multiplier = lv%symbol*lv%inv_n
         end if
         if (h%complex) then
            if (t == 0 .and. h%on_slabs) then
               call slab_multiplier(lv)
            else
               lv%cmultiplier = cmplx(lv%symbol, lv%odd, kind=wp)*lv%inv_n
            end if
            do k = 1, size(lv%symbol)
               if (lv%symbol(k) > 0.0_wp) lv%jacobi_diagonal = max(lv%jacobi_diagonal, &
                  & jacobi_margin*omega*(lv%symbol(k)**2 + lv%odd(k)**2)/(2*lv%symbol(k)))
            end do
         end if
         if (h%rows) call set_rows(lv, h%complex)
         end associate
      end do
      associate (lv => h%level(h%coarsest))
      lv%fft%spectrum = cmplx(lv%multiplier, 0.0_wp, kind=wp)
      if (h%complex) lv%fft%spectrum = lv%cmultiplier
      call lv%fft%backward()
      h%coarse_column = lv%fft%real_buffer
      end associate
   end subroutine set_grid

   !> Row smoothing's K_row on level lv, the mean over ky of its symbol (with the imaginary
   !> part if `complex`), and its inverse (0 where K_row is 0).
   pure subroutine set_rows(lv, complex)
      type(grid_level), intent(inout) :: lv
      logical, intent(in) :: complex
      complex(wp) :: mean
      integer :: kx, nkx
      nkx = lv%nx/2 + 1
      do kx = 1, nkx
         mean = cmplx(sum(lv%symbol(kx::nkx)), 0.0_wp, kind=wp)
         if (complex) mean = cmplx(real(mean), sum(lv%odd(kx::nkx)), kind=wp)
         mean = mean/lv%ny
         lv%row_symbol(kx) = mean
         lv%row_inverse(kx) = 0.0_wp
         if (abs(mean) > 0.0_wp) lv%row_inverse(kx) = inverse(mean)/lv%nx
      end do
   end subroutine set_rows

   !> 1/z as conj(z)/|z|^2 (z /= 0): complex division raises spurious floating-point flags
   !> in vectorised code.
   elemental complex(wp) function inverse(z)
      complex(wp), intent(in) :: z
      inverse = conjg(z)/(real(z)**2 + aimag(z)**2)
   end function inverse

   !> The Galerkin symbol of grid c at its mode (kx, ky) from that of the grid f it is made
   !> of (its real part, or with `imaginary` its odd imaginary part): along a halved axis the
   !> modes k and k + m_c with the weights 2 alpha^2 and 2 beta^2, alpha, beta =
   !> (1 +- cos(pi k/m_c))/2, along the other the mode k alone.
   pure real(wp) function galerkin(f, c, kx, ky, imaginary) result(value)
      type(grid_level), intent(in) :: f, c
      integer, intent(in) :: kx, ky
      logical, intent(in) :: imaginary
      real(wp), parameter :: pi = acos(-1.0_wp)
      real(wp) :: wx(0:1), wy(0:1)
      wx = [1.0_wp, 0.0_wp]
      wy = [1.0_wp, 0.0_wp]
      if (f%halve_x) wx = [0.5_wp*(1.0_wp + cos(pi*kx/c%nx))**2, 0.5_wp*(1.0_wp - cos(pi*kx/c%nx))**2]
      if (f%halve_y) wy = [0.5_wp*(1.0_wp + cos(pi*ky/c%ny))**2, 0.5_wp*(1.0_wp - cos(pi*ky/c%ny))**2]
      value = wx(0)*(wy(0)*symbol_part(f, kx, ky, imaginary) + wy(1)*symbol_part(f, kx, ky + c%ny, imaginary)) &
         & + wx(1)*(wy(0)*symbol_part(f, kx + c%nx, ky, imaginary) &
         &          + wy(1)*symbol_part(f, kx + c%nx, ky + c%ny, imaginary))
   end function galerkin

   !> Level lv's symbol at the mode (kx, ky), any integers: its real part (even), or its
   !> imaginary part (odd: a mode read at its mirror image, mode_index, takes the opposite sign).
   pure real(wp) function symbol_part(lv, kx, ky, imaginary) result(value)
      type(grid_level), intent(in) :: lv
      integer, intent(in) :: kx, ky
      logical, intent(in) :: imaginary
      if (imaginary) then
         value = lv%odd(mode_index(lv%nx, lv%ny, kx, ky))
         if (2*modulo(kx, lv%nx) > lv%nx) value = -value
      else
         value = lv%symbol(mode_index(lv%nx, lv%ny, kx, ky))
      end if
   end function symbol_part

   !> The coarse operators for the contact set of h%free: the Galerkin products of the
   !> penalty d D_A (a 3- or 9-point stencil on every coarser grid), the
   !> Jacobi weights, and the Cholesky factor of the coarsest operator.
   subroutine set_contact(h)
      type(hierarchy), intent(inout) :: h
      integer :: t, info, attempt
      real(wp) :: shift
      real(wp), allocatable :: row_penalty(:, :)
      do t = h%top + 1, h%coarsest
         associate (c => h%level(t), f => h%level(t - 1))
         if (across_ranks(h) .and. t == 1) then
            call coarsen_slab(h)
         else if (h%surface) then
            call coarsen_surface(h, t)
         else if (t == h%top + 1) then
            call galerkin_diagonal(h%free, penalty*h%level(h%top)%circulant_diagonal, f%nx, 0, c%penalty)
         else
            call coarsen_x(f%penalty, f%nx, 0, c%penalty)
         end if
         if (h%rows) then
            ! the row solve takes a shift for the contact points' stiffness (see
            ! row_shift_weight); a point stiffer than that, its step scaled down as a Jacobi
            ! step would be
            row_penalty = reshape(c%penalty(0, 0, :), [c%nx, c%ny])
            c%row_shift = row_shift_weight*sqrt(sum(row_penalty, dim=1)/c%nx*maxval(row_penalty, dim=1))
            c%jacobi = omega*min(1.0_wp, reshape(spread(c%circulant_diagonal + c%row_shift, 1, c%nx), [c%n]) &
               & /(c%circulant_diagonal + c%penalty(0, 0, :)))
         else
            c%jacobi = omega/(c%jacobi_diagonal + c%penalty(0, 0, :))
         end if
         end associate
      end do
      ! the coarsest operator, dense: circulant plus penalty (on the grid being solved, when
      ! it is the coarsest, I K I with the contact points' rows and columns the identity)
      shift = 0.0_wp
      do attempt = 1, 10
         call fill_dense(h, shift)
         if (h%complex) then
            call dgetrf(size(h%dense, 1), size(h%dense, 1), h%dense, size(h%dense, 1), h%pivots, info)
         else
            call cholesky_factor(h%dense, info)
         end if
         if (info == 0) exit
         ! numerically singular (a rounding-level null space): shift the diagonal slightly;
         ! the V-cycle only preconditions, and the Newton direction only needs descent
         shift = max(10*shift, 1.0e-12_wp*h%level(h%coarsest)%circulant_diagonal)
      end do
   end subroutine set_contact

   !> The penalty stencil of the surface's level t = P^T A P, A that of level t - 1 (on the
   !> grid being solved the diagonal d D_A), P = Px Py (Px or Py the identity along an axis
   !> not halved): row by row of level t, from the rows of level t - 1 that reach it, each
   !> coarsened along x (coarsened_row), then along y (coarsen_y_row). (Halving both axes, a
   !> row between two coarse ones is coarsened twice: the window holds 3 rows, not a whole
   !> grid coarsened along x.)
   subroutine coarsen_surface(h, t)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: t
      integer :: cy, k, row
      associate (f => h%level(t - 1), c => h%level(t))
      if (f%halve_y) then
         do cy = 0, c%ny - 1
            do k = -1, 1
               call coarsened_row(modulo(2*cy + k, f%ny), f%window(:, :, :, k))
            end do
            call coarsen_y_row(f%window, c%nx, c%penalty(:, :, cy*c%nx + 1:(cy + 1)*c%nx))
         end do
      else
         do row = 0, f%ny - 1
            call coarsened_row(row, c%penalty(:, :, row*c%nx + 1:(row + 1)*c%nx))
         end do
      end if
      end associate
   contains
      !> b = the row `row` of level t - 1's stencil, coarsened along x if that grid is halved
      !> along x (galerkin_diagonal, coarsen_x)
      subroutine coarsened_row(row, b)
         integer, intent(in) :: row
         real(wp), contiguous, intent(out) :: b(:, :, :)
         integer :: nx
         associate (f => h%level(t - 1))
         nx = f%nx
         if (t == h%top + 1) then
            if (f%halve_x) then
               call galerkin_diagonal(h%free(row*nx + 1:(row + 1)*nx), penalty*f%circulant_diagonal, nx, 1, b)
            else
               b = 0.0_wp
               b(2, 2, :) = penalty*f%circulant_diagonal*(1.0_wp - h%free(row*nx + 1:(row + 1)*nx))
            end if
         else if (f%halve_x) then
            call coarsen_x(f%penalty(:, :, row*nx + 1:(row + 1)*nx), nx, 1, b)
         else
            b = f%penalty(:, :, row*nx + 1:(row + 1)*nx)
         end if
         end associate
      end subroutine coarsened_row
   end subroutine coarsen_surface

   !> b = Px^T D Px for a row of nx points with the diagonal D = `weight` on the contact set
   !> (free = 0) and 0 off it, Px linear interpolation: the 3-point stencil (ey = 0) of the
   !> row of nx/2 points, in a stencil array reaching `reach` rows (0 on a line).
   pure subroutine galerkin_diagonal(free, weight, nx, reach, b)
      integer, intent(in) :: nx, reach
      real(wp), intent(in) :: free(0:nx - 1), weight
      real(wp), intent(out) :: b(-1:1, -reach:reach, 0:nx/2 - 1)
      real(wp) :: left, centre, right
      integer :: cx
      b = 0.0_wp
      do cx = 0, nx/2 - 1
         ! the fine points 2 cx - 1, 2 cx, 2 cx + 1 (weights 1/2, 1, 1/2 from cx)
         left = weight*(1.0_wp - free(merge(nx - 1, 2*cx - 1, cx == 0)))
         centre = weight*(1.0_wp - free(2*cx))
         right = weight*(1.0_wp - free(2*cx + 1))
         b(0, 0, cx) = centre + 0.25_wp*(left + right)
         b(-1, 0, cx) = 0.25_wp*left
         b(1, 0, cx) = 0.25_wp*right
      end do
   end subroutine galerkin_diagonal

   !> The Galerkin products below use that the fine point 2I + k of an axis (zero-based,
   !> k = -2..2 from the coarse point I) takes the values of the coarse points I + to(1:2, k)
   !> with the weights of(1:2, k) under linear interpolation (a weight 0: no second point).
   pure subroutine interpolation_weights(to, of)
      integer, intent(out) :: to(2, -2:2)
      real(wp), intent(out) :: of(2, -2:2)
      to = reshape([-1, 0, -1, 0, 0, 0, 0, 1, 1, 0], [2, 5])
      of = reshape([1.0_wp, 0.0_wp, 0.5_wp, 0.5_wp, 1.0_wp, 0.0_wp, 0.5_wp, 0.5_wp, 1.0_wp, 0.0_wp], [2, 5])
   end subroutine interpolation_weights

   !> b = Px^T a Px for the 3 x 3 stencil `a` of a row of nx points, Px linear interpolation
   !> along x: the stencil of the row of nx/2 points. `reach`: 1 if the stencil couples rows
   !> (a surface), 0 on a line (ey = 0 only).
   pure subroutine coarsen_x(a, nx, reach, b)
      integer, intent(in) :: nx, reach
      real(wp), intent(in) :: a(-1:1, -reach:reach, 0:nx - 1)
      real(wp), intent(out) :: b(-1:1, -reach:reach, 0:nx/2 - 1)
      integer :: cx, l, c, r
      ! (the coarse point cx takes the fine points l, c, r = 2 cx - 1, 2 cx, 2 cx + 1 with
      ! the weights 1/2, 1, 1/2: interpolation_weights written out, one pass without branches)
      do cx = 0, nx/2 - 1
         l = merge(nx - 1, 2*cx - 1, cx == 0)
         c = 2*cx
         r = 2*cx + 1
         b(0, :, cx) = a(0, :, c) + 0.5_wp*(a(-1, :, c) + a(1, :, c) + a(1, :, l) + a(-1, :, r)) &
            & + 0.25_wp*(a(0, :, l) + a(0, :, r))
         b(1, :, cx) = 0.5_wp*(a(1, :, c) + a(1, :, r)) + 0.25_wp*a(0, :, r)
         b(-1, :, cx) = 0.5_wp*(a(-1, :, c) + a(-1, :, l)) + 0.25_wp*a(0, :, l)
      end do
   end subroutine coarsen_x

   !> c = the row of Py^T b Py from the three rows rows(:, :, :, k) = b's rows 2 cy + k
   !> (k = -1, 0, 1) of nx points, Py linear interpolation along y.
   pure subroutine coarsen_y_row(rows, nx, c)
      integer, intent(in) :: nx
      real(wp), intent(in) :: rows(-1:1, -1:1, 0:nx - 1, -1:1)
      real(wp), intent(out) :: c(-1:1, -1:1, 0:nx - 1)
      integer :: to(2, -2:2), ix, k, e, j
      real(wp) :: of(2, -2:2)
      call interpolation_weights(to, of)
      c = 0.0_wp
      do k = -1, 1
         do e = -1, 1
            do j = 1, 2
               do ix = 0, nx - 1
                  c(:, to(j, k + e), ix) = c(:, to(j, k + e), ix) + (of(1, k)*of(j, k + e))*rows(:, e, ix, k)
               end do
            end do
         end do
      end do
   end subroutine coarsen_y_row

   !> The dense matrix of the coarsest grid's operator (see set_contact), its diagonal
   !> shifted by `shift`.
   pure subroutine fill_dense(h, shift)
      type(hierarchy), intent(inout) :: h
      real(wp), intent(in) :: shift
      integer :: i, j, m, ix, iy, jx, jy, ex, ey
      associate (lv => h%level(h%coarsest), a => h%dense)
      m = lv%n
      do i = 1, m
         ix = mod(i - 1, lv%nx)
         iy = (i - 1)/lv%nx
         do j = 1, m
            jx = mod(j - 1, lv%nx)
            jy = (j - 1)/lv%nx
            a(j, i) = h%coarse_column(modulo(jx - ix, lv%nx) + lv%nx*modulo(jy - iy, lv%ny) + 1)
         end do
      end do
      if (h%top == h%coarsest) then
         do i = 1, m
            if (h%free(i) == 0.0_wp) then
               a(:, i) = 0.0_wp
               a(i, :) = 0.0_wp
               a(i, i) = 1.0_wp
            end if
         end do
      else
         ! row i: sum over the stencil of penalty(ex, ey, i) x(i + (ex, ey))
         do i = 1, m
            ix = mod(i - 1, lv%nx)
            iy = (i - 1)/lv%nx
            do ey = lbound(lv%penalty, 2), ubound(lv%penalty, 2)
               do ex = -1, 1
                  if (lv%penalty(ex, ey, i) == 0.0_wp) cycle
                  j = modulo(ix + ex, lv%nx) + lv%nx*modulo(iy + ey, lv%ny) + 1
                  a(i, j) = a(i, j) + lv%penalty(ex, ey, i)
               end do
            end do
         end do
      end if
      do i = 1, m
         a(i, i) = a(i, i) + shift
      end do
      end associate
   end subroutine fill_dense

   !> The lower Cholesky factor L of the symmetric positive definite a (its lower triangle),
   !> in place; info = the column where a pivot was not positive (0: factorised). (Written
   !> out rather than LAPACK's dpotrf: for the few hundred points of the coarsest grid a
   !> threaded BLAS spent more time waking and parking its threads than factorising.)
   pure subroutine cholesky_factor(a, info)
      real(wp), contiguous, intent(inout) :: a(:, :)
      integer, intent(out) :: info
      integer :: j, k
      info = 0
      do j = 1, size(a, 2)
         do k = 1, j - 1
            a(j:, j) = a(j:, j) - a(j, k)*a(j:, k)
         end do
         if (.not. a(j, j) > 0.0_wp) then
            info = j
            return
         end if
         a(j:, j) = a(j:, j)/sqrt(a(j, j))
      end do
   end subroutine cholesky_factor

   !> x <- A^-1 x on the coarsest grid: Cholesky, or LU for a complex symbol.
   subroutine coarsest_solve(h, x)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(inout) :: x(:)
      integer :: info
      if (h%complex) then
         call dgetrs('N', size(x), 1, h%dense, size(x), h%pivots, x, size(x), info)
      else
         call cholesky_solve(h%dense, x)
      end if
   end subroutine coarsest_solve

   !> x <- (L L^T)^-1 x with the factor of cholesky_factor.
   pure subroutine cholesky_solve(l, x)
      real(wp), contiguous, intent(in) :: l(:, :)
      real(wp), contiguous, intent(inout) :: x(:)
      integer :: j, m
      m = size(x)
      do j = 1, m
         x(j) = x(j)/l(j, j)
         x(j + 1:) = x(j + 1:) - x(j)*l(j + 1:, j)
      end do
      do j = m, 1, -1
         x(j) = (x(j) - dot_product(l(j + 1:, j), x(j + 1:)))/l(j, j)
      end do
   end subroutine cholesky_solve

   !> uf (on grid j) = the spectral interpolation of uc (on grid j + 1): its Fourier
   !> coefficients, zero-padded. (The nested iteration's grids: both axes halved, as a
   !> hierarchy built without a symbol has them.)
   subroutine interpolate(h, j, uc, uf)
      type(hierarchy), intent(inout) :: h
      integer, intent(in) :: j
      real(wp), contiguous, intent(in) :: uc(:)
      real(wp), contiguous, intent(out) :: uf(:)
      complex(wp) :: value
      integer :: kx, ky, fy, nkc, nkf
      associate (coarse => h%level(j + 1), fine => h%level(j))
      nkc = coarse%nx/2 + 1
      nkf = fine%nx/2 + 1
      coarse%fft%real_buffer = uc
      call coarse%fft%forward()
      fine%fft%spectrum = (0.0_wp, 0.0_wp)
      do ky = 0, coarse%ny - 1
         ! (rows of negative ky move to the end of the longer fine axis)
         fy = merge(ky, ky + fine%ny - coarse%ny, 2*ky <= coarse%ny)
         do kx = 0, coarse%nx/2
            value = coarse%fft%spectrum(kx + nkc*ky + 1)
            ! a coarse Nyquist mode is a cosine: on the fine grid half of it is its mirror image
            if (2*kx == coarse%nx) value = 0.5_wp*value
            if (h%surface .and. 2*ky == coarse%ny) then
               value = 0.5_wp*value
               fine%fft%spectrum(kx + nkf*(fine%ny - ky) + 1) = value
            end if
            fine%fft%spectrum(kx + nkf*fy + 1) = value
         end do
      end do
      call fine%fft%backward()
      uf = fine%fft%real_buffer
      h%pairs = h%pairs + 0.5_wp*(coarse%n + fine%n)/h%n_fine
      end associate
   end subroutine interpolate
   !> Whether the grid being solved is the finest one on this rank's slab (h%on_slabs): its
   !> sums and maxima then run over the ranks.
   pure logical function across_ranks(h)
      type(hierarchy), intent(in) :: h
      across_ranks = h%on_slabs .and. h%top == 0
   end function across_ranks

   !> The finest grid's multiplier (and complex one, where the symbol has an imaginary part)
   !> on this rank's modes of the operator's transposed spectrum (fft_plan%mode_indices),
   !> from its whole symbol.
   subroutine slab_multiplier(lv)
      type(grid_level), intent(inout) :: lv
      integer :: i, mx, my, k
      do i = 1, size(lv%multiplier)
         call lv%fft%mode_indices(i, mx, my)
         k = mx + (lv%nx/2 + 1)*my + 1
         lv%multiplier(i) = lv%symbol(k)*lv%inv_n
         if (allocated(lv%odd)) lv%cmultiplier(i) = cmplx(lv%symbol(k), lv%odd(k), kind=wp)*lv%inv_n
      end do
   end subroutine slab_multiplier

   !> coarse (level 1, whole) = P^T fine, fine this rank's slab of level 0: its rows
   !> restricted along x, each row's share then added into the coarse rows it reaches along
   !> y (an even row y into y/2, an odd one half into (y - 1)/2 and half into (y + 1)/2,
   !> periodic), and the shares summed over the ranks: the halo rows of a restriction
   !> without messages between neighbours (one MPI_Allreduce of the coarse grid).
   subroutine restrict_slab(h, fine, coarse)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: fine(:)
      real(wp), contiguous, intent(out) :: coarse(:)
      integer :: mx, j, y, cy, first
      associate (lv => h%level(0), c => h%level(1))
      mx = c%nx
      if (lv%halve_x) then
         call restrict_x(fine, lv%halfway, lv%nx, h%ny_local)
      else
         lv%halfway = fine
      end if
      coarse = 0.0_wp
      do j = 0, h%ny_local - 1
         y = h%y_start + j
         first = j*mx + 1
         associate (row => lv%halfway(first:first + mx - 1))
         if (.not. lv%halve_y) then
            coarse(y*mx + 1:(y + 1)*mx) = row
         else if (mod(y, 2) == 0) then
            cy = y/2
            coarse(cy*mx + 1:(cy + 1)*mx) = coarse(cy*mx + 1:(cy + 1)*mx) + row
         else
            cy = (y - 1)/2
            coarse(cy*mx + 1:(cy + 1)*mx) = coarse(cy*mx + 1:(cy + 1)*mx) + 0.5_wp*row
            cy = modulo(cy + 1, c%ny)
            coarse(cy*mx + 1:(cy + 1)*mx) = coarse(cy*mx + 1:(cy + 1)*mx) + 0.5_wp*row
         end if
         end associate
      end do
      call sum_over_ranks(coarse)
      end associate
   end subroutine restrict_slab

   !> fine (this rank's slab of level 0) <- scale base + free P coarse, coarse level 1's
   !> whole field (every rank holds it: no halo row is sent): the slab's rows of P along y,
   !> then along x (prolong_slab_add is precondition's prolong_add on the slab).
   subroutine prolong_slab_add(h, coarse, fine, free, base, scale)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: coarse(:)
      real(wp), contiguous, intent(inout) :: fine(:)
      real(wp), contiguous, intent(in) :: free(:), base(:)
      real(wp), intent(in) :: scale
      integer :: mx, j, y, cy, first
      associate (lv => h%level(0), c => h%level(1))
      mx = c%nx
      do j = 0, h%ny_local - 1
         y = h%y_start + j
         first = j*mx + 1
         if (.not. lv%halve_y) then
            lv%halfway(first:first + mx - 1) = coarse(y*mx + 1:(y + 1)*mx)
         else if (mod(y, 2) == 0) then
            cy = y/2
            lv%halfway(first:first + mx - 1) = coarse(cy*mx + 1:(cy + 1)*mx)
         else
            cy = (y - 1)/2
            lv%halfway(first:first + mx - 1) = 0.5_wp*(coarse(cy*mx + 1:(cy + 1)*mx) &
               & + coarse(modulo(cy + 1, c%ny)*mx + 1:(modulo(cy + 1, c%ny) + 1)*mx))
         end if
      end do
      if (lv%halve_x) then
         call prolong_x_add(lv%halfway, fine, lv%nx, h%ny_local, free, base, scale)
      else
         call add_masked(lv%halfway, fine, free, base, scale)
      end if
      end associate
   end subroutine prolong_slab_add

   !> Level 1's penalty stencil P^T (d D_A) P from this rank's rows of the contact set: each
   !> fine row's 3-point stencil coarsened along x (galerkin_diagonal), its share added into
   !> the coarse rows it reaches along y (coarsen_y_row's terms of that row), and the shares
   !> summed over the ranks (one MPI_Allreduce of the stencil).
   subroutine coarsen_slab(h)
      type(hierarchy), intent(inout) :: h
      real(wp), allocatable :: b(:, :, :), flat(:)
      integer :: nx, j, y, cy, k, shares, share
      associate (f => h%level(0), c => h%level(1))
      nx = f%nx
      allocate (b(-1:1, -1:1, c%nx))
      c%penalty = 0.0_wp
      do j = 0, h%ny_local - 1
         y = h%y_start + j
         associate (free => h%free(j*nx + 1:(j + 1)*nx))
         if (f%halve_x) then
            call galerkin_diagonal(free, penalty*f%circulant_diagonal, nx, 1, b)
         else
            b = 0.0_wp
            b(0, 0, :) = penalty*f%circulant_diagonal*(1.0_wp - free)
         end if
         end associate
         if (.not. f%halve_y) then
            c%penalty(:, :, y*c%nx + 1:(y + 1)*c%nx) = b
            cycle
         end if
         ! (an even row is row 2 cy of the coarse row cy; an odd one row 2 cy + 1 of cy and
         ! 2 cy' - 1 of cy' = cy + 1)
         shares = merge(1, 2, mod(y, 2) == 0)
         do share = 1, shares
            if (shares == 1) then
               cy = y/2
               k = 0
            else if (share == 1) then
               cy = (y - 1)/2
               k = 1
            else
               cy = modulo((y - 1)/2 + 1, c%ny)
               k = -1
            end if
            call add_y_share(b, k, c%nx, c%penalty(:, :, cy*c%nx + 1:(cy + 1)*c%nx))
         end do
      end do
      flat = reshape(c%penalty, [size(c%penalty)])
      call sum_over_ranks(flat)
      c%penalty = reshape(flat, shape(c%penalty))
      end associate
   end subroutine coarsen_slab

   !> c <- c + the terms of coarsen_y_row that the row `row` (the fine row 2 cy + k of the
   !> coarse row cy) contributes.
   pure subroutine add_y_share(row, k, nx, c)
      integer, intent(in) :: k, nx
      real(wp), intent(in) :: row(-1:1, -1:1, 0:nx - 1)
      real(wp), intent(inout) :: c(-1:1, -1:1, 0:nx - 1)
      integer :: to(2, -2:2), ix, e, j
      real(wp) :: of(2, -2:2)
      call interpolation_weights(to, of)
      do e = -1, 1
         do j = 1, 2
            do ix = 0, nx - 1
               c(:, to(j, k + e), ix) = c(:, to(j, k + e), ix) + (of(1, k)*of(j, k + e))*row(:, e, ix)
            end do
         end do
      end do
   end subroutine add_y_share

   !> uf (this rank's slab of level 0) = the spectral interpolation of uc (level 1, whole on
   !> every rank): interpolate, each rank filling its own modes of the transposed spectrum.
   subroutine interpolate_onto_slab(h, uc, uf)
      type(hierarchy), intent(inout) :: h
      real(wp), contiguous, intent(in) :: uc(:)
      real(wp), contiguous, intent(out) :: uf(:)
      complex(wp) :: value
      integer :: i, mx, my, sy, nkc
      associate (coarse => h%level(1), fine => h%level(0))
      nkc = coarse%nx/2 + 1
      coarse%fft%real_buffer = uc
      call coarse%fft%forward()
      do i = 1, fine%fft%nk
         call fine%fft%mode_indices(i, mx, my)
         sy = merge(my, my - fine%ny, 2*my <= fine%ny)
         value = (0.0_wp, 0.0_wp)
         if (2*mx <= coarse%nx .and. 2*abs(sy) <= coarse%ny) then
            value = coarse%fft%spectrum(mx + nkc*modulo(sy, coarse%ny) + 1)
            ! (a coarse Nyquist mode is a cosine: half of it at each of its two fine images)
            if (2*mx == coarse%nx) value = 0.5_wp*value
            if (2*abs(sy) == coarse%ny) value = 0.5_wp*value
         end if
         fine%fft%spectrum(i) = value
      end do
      call fine%fft%backward()
      uf = fine%fft%real_buffer
      h%pairs = h%pairs + 0.5_wp*(coarse%n + fine%n)/h%n_fine
      end associate
   end subroutine interpolate_onto_slab
end module lc_contact_multigrid_hierarchy
