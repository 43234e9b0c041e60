!> The compliance operator of a scene: w = G_eff * p as a Fourier multiplier on a grid
!> (a line, or a surface: lc_base_grid), the same code for both.
!>
!> Convention P (docs/theory.md): for a mode q of p(x) = sum_q p^(q) exp(i q.x),
!>    w^(q) = 2 C(q_x)/|q| [ (1-A) - i (q_x/|q|) mu_c c ] p^(q),
!> the layer's normal response to p and to the friction traction tau_x = mu_c p
!> (lc_greens_kernel; on a line q_x/|q| = sgn(k)), with C = 1/E* for an elastic layer and
!> (1 - nu^2) J*(q_x V) for a viscoelastic one sliding at speed V (seed Eq. 14). The q = 0
!> mode of a finite layer is h/M (M = E(1-nu)/((1+nu)(1-2nu)), zero for nu = 0.5); for
!> a half-space it is set to zero (the penetration is then measured from the mean
!> displacement).
!>
!> Only what the scene needs is built: a real multiplier when there is no coupling
!> (mu_c = 0, or a half-space with nu = 0.5), a complex one otherwise. The coupled
!> operator is split as G = M + (G - M) with the real, even, positive "metric"
!> M(k) = |G_eff(k)|: the symmetric solver works with M, the outer iteration with G - M.
!> With this metric the linearised outer map has eigenvalues exp(i arg G_eff(k)) on the
!> right half of the unit circle however strong the coupling or the viscoelastic loss
!> (the real part Re G_eff as the metric would give the eigenvalues
!> 1 - i Im G/Re G, up to ~300 in modulus for thin incompressible layers).
module lc_contact_operator
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   use lc_fft_plans, only: fft_plan, row_work
   use lc_base_grid, only: grid_type
   use lc_greens_kernel, only: layer_kernel
   use lc_base_threads, only: parallel_points, reduction_blocks, block_range, copy_field, fill_field
   use lc_base_pages, only: advise_huge_pages
   use lc_base_parallel, only: global_sum, global_max, max_over_ranks, global_any, broadcast
   implicit none (type, external)
   private
   public :: compliance_operator, build_operator, multiply_spectrum, multiply_complex

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> The Fourier preconditioner of the inner CG is (|J*(kV)|/|J*(k1 V)|)^preconditioner_exponent/M:
   !> half of the material's frequency dependence, between the exact inverse of the metric
   !> (0: on a glassy layer the contact set oscillates and the CG stalls) and the elastic one
   !> (1: a condition number ~E_inf/E0). Relative to k1, so that V -> 0 and V -> inf give back
   !> the elastic preconditioner (docs/decisions/000-line-solver-measurements.md, 'Solver
   !> speed: what dominated, what changed'; docs/numerics.md, 'Constants of the solvers and
   !> their measurements').
   real(wp), parameter :: preconditioner_exponent = 0.5_wp

   !> Fourier multipliers of one scene on one grid and the FFT plans to apply them. The
   !> solvers use it through its procedures only; multipliers are on the grid's half
   !> spectrum (lc_base_grid), fields flat with x fastest.
   type :: compliance_operator
      type(grid_type) :: grid
      type(layer_kernel) :: kernel
      integer :: n = 0                      !< grid points (of this rank's slab, if distributed)
      integer :: nk = 0                     !< modes of the half spectrum (of this rank's slab)
      !> a surface shared among the job's ranks (lc_base_parallel): fields are this rank's
      !> slab of rows, multipliers its columns of the transposed spectrum (lc_fft_plans,
      !> `mode_indices`); `holds_uniform`: its first mode is q = 0; `once`: its modes that
      !> stand for themselves only (mx = 0, and nx/2 for even nx). The real-space columns
      !> (column updates of CG and GCR) are not made then.
      logical :: distributed = .false.
      logical :: holds_uniform = .true.
      integer, allocatable :: once(:)
      real(wp) :: friction = 0.0_wp
      logical :: coupled = .false.          !< complex multiplier (not symmetric)
      real(wp), allocatable :: metric(:)    !< M(q) = |G_eff(q)| on the half spectrum (L/S)
      real(wp) :: diagonal = 0.0_wp         !< real-space diagonal of the circulant M (L/S)
      !> largest |multiplier| of M and G_eff (L/S): sets the rounding noise of w = G p
      real(wp) :: largest = 0.0_wp
      real(wp) :: inv_n = 1.0_wp            !< 1/n, folded into the multipliers when applied
      !> the uniform multiplier drop_uniform_mode took out (L/S; 0 while it is in): what a
      !> response to a change of the load (the contact stiffness) adds back
      real(wp) :: dropped_uniform = 0.0_wp
      !> C = (1 - nu^2) J*(q_x V) per column mx = 0..nx/2 of the half spectrum (1/S)
      complex(wp), allocatable :: compliance(:)
      !> Fourier preconditioner of the constrained CG: 1/M(k) with half the material's
      !> frequency dependence taken out (see preconditioner_exponent); 0 where M = 0 (k = 0
      !> of a half-space, or under load control)
      real(wp), allocatable :: preconditioner(:)
      logical :: monotone = .true.          !< Re G_eff(k) >= 0 for every mode (unique solution)
      !> symmetric (not coupled) with a metric that falls with |q| over the grid's modes: the
      !> masked Fourier inverse then preconditions the constrained CG well at every scale
      logical :: metric_falls = .false.
      complex(wp), allocatable :: full(:)   !< G_eff(q), only when coupled
      !> M in real space: (M p)(x_i) = sum_j column(i - j) p_j, i - j taken periodically on
      !> both axes (L/S); for the constrained CG only (prepare_cg: a coupled solve by GCR
      !> does without this array of n doubles)
      real(wp), allocatable :: column(:)
      !> For the constrained GCR only (prepare_gcr): 1/G_eff(k) (0 where G_eff = 0), the
      !> real-space column of G_eff, and the real-space diagonal of 1/G_eff
      complex(wp), allocatable :: inverse_full(:)
      real(wp), allocatable :: full_column(:)
      real(wp) :: inverse_diagonal = 0.0_wp
      type(fft_plan) :: fft
   contains
      procedure :: apply_metric
      procedure :: apply_full
      procedure :: apply_difference
      procedure :: add_full_columns
      procedure :: add_metric_columns
      procedure :: buffer
      procedure :: column_mode
      procedure :: metric_in_buffer
      procedure :: metric_with_work
      procedure :: add_metric_columns_at
      procedure :: inverse_metric_in_buffer
      procedure :: prepare_cg
      procedure :: prepare_gcr
      procedure :: full_in_buffer
      procedure :: inverse_full_in_buffer
      procedure :: multiply_complex_in_buffer
      procedure :: drop_uniform_mode
   end type compliance_operator

contains

   !> Build the operator on `grid` for the layer `kernel` and Coulomb coefficient
   !> `friction`, with `threads` FFTW threads; `distributed`: on this rank's slab of a surface
   !> shared among the job's ranks, if there are several.
   subroutine build_operator(op, grid, kernel, friction, threads, error, distributed)
      type(compliance_operator), intent(out) :: op
      type(grid_type), intent(in) :: grid
      type(layer_kernel), intent(in) :: kernel
      real(wp), intent(in) :: friction
      integer, intent(in) :: threads
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: distributed
      real(wp) :: q_min, q_max, extremes(2)
      real(wp), allocatable :: factor(:), q_ranges(:, :)
      integer :: i, mx, nkx, block, first, last

      call op%fft%init(grid%nx, grid%ny, threads, error, distributed)
      if (allocated(error)) return
      op%grid = grid
      op%kernel = kernel
      op%distributed = op%fft%distributed
      op%n = op%fft%n
      op%nk = op%fft%nk
      op%holds_uniform = .true.
      if (op%distributed) then
         op%holds_uniform = op%nk > 0 .and. op%fft%x_start == 0
         op%once = pack([(i, i=1, op%nk)], [(once_mode(op, i), i=1, op%nk)])
      end if
      op%inv_n = 1.0_wp/grid%points()
      op%friction = friction
      nkx = grid%nkx()
      ! C per column: a viscoelastic mode sees the frequency q_x V
      op%compliance = kernel%contact_compliance([(2.0_wp*pi*mx/grid%lx, mx = 0, nkx - 1)])
      if (.not. all(ieee_is_finite(real(op%compliance, wp)) .and. ieee_is_finite(aimag(op%compliance)))) then
         call fatal_error(error, '&material: speed = ' // to_string(kernel%speed) // ' gives non-finite compliances ' // &
            & '(k V tau overflows); allowed: a speed with k V tau_max well inside the floating-point range', &
            & code_input)
         return
      end if
      op%coupled = kernel%coupled(friction)

      allocate (op%metric(op%nk))
      if (op%coupled) then
         allocate (op%full(op%nk))
         call advise_huge_pages(op%full)
      end if
      call advise_huge_pages(op%metric)
      ! h/M with the static compliance (0 for a half-space), on the rank holding the mode
      if (op%holds_uniform) then
         op%metric(1) = kernel%normal_uniform(real(op%compliance(1), wp))
         if (op%coupled) op%full(1) = op%metric(1)
      end if

      ! (the modes by blocks on the solve's threads: each mode's multipliers are its own,
      ! and minima and maxima are exact in any order)
      allocate (q_ranges(2, reduction_blocks(op%nk)))
      !$omp parallel do schedule(static) private(first, last) if(op%nk >= parallel_points)
      do block = 1, size(q_ranges, 2)
         call block_range(block, op%nk, first, last)
         call mode_multipliers(op, first, last, q_ranges(:, block))
      end do
      q_min = minval(q_ranges(1, :))
      q_max = maxval(q_ranges(2, :))
      if (op%distributed) then
         call mirror_columns(op)
      else
         call mirror_rows(op, nkx)
      end if
      allocate (op%preconditioner(op%nk))
      call advise_huge_pages(op%preconditioner)
      ! (an elastic law has one compliance: no factor)
      if (kernel%viscoelastic) factor = (abs(op%compliance)/abs(op%compliance(2)))**preconditioner_exponent
      !$omp parallel do schedule(static) private(first, last) if(op%nk >= parallel_points)
      do block = 1, reduction_blocks(op%nk)
         call block_range(block, op%nk, first, last)
         call preconditioner_block(op, factor, first, last)
      end do
      ! The solution is unique when the operator is monotone, Re G_eff >= 0 on every mode
      ! (always for elastic layers; not always for viscoelastic ones with friction).
      op%monotone = .true.
      if (op%coupled) op%monotone = all(real(op%full, wp) >= 0.0_wp)
      if (op%distributed) op%monotone = .not. global_any(.not. op%monotone)
      if (op%distributed) then
         extremes = [-q_min, q_max]
         call max_over_ranks(extremes)
         q_min = -extremes(1)
         q_max = extremes(2)
      end if
      op%metric_falls = .not. op%coupled .and. grid%modes() > 1
      if (op%metric_falls) op%metric_falls = kernel%compliance_falls(q_min, q_max)
      call derive(op)
   end subroutine build_operator

   !> build_operator's multipliers of the modes first..last (metric, and full where coupled);
   !> q_range = (the least, the largest |q| among them; huge and 0 if none).
   subroutine mode_multipliers(op, first, last, q_range)
      type(compliance_operator), intent(inout) :: op
      integer, intent(in) :: first, last
      real(wp), intent(out) :: q_range(2)
      real(wp) :: qx, qy, q
      complex(wp) :: g, one_minus_a, one_minus_b, c, t
      integer :: i, mx, my, nkx
      nkx = op%grid%nkx()
      q_range = [huge(1.0_wp), 0.0_wp]
      do i = first, last
         call op%fft%mode_indices(i, mx, my)
         if (mx == 0 .and. my == 0) cycle
         ! (a row my > ny/2 has the q_y of row ny - my negated, and the multipliers depend
         ! on |q| and q_x alone: mirror_rows, or on a slab mirror_columns, copies it, the
         ! same bits)
         if (2*my > op%grid%ny) cycle
         call op%grid%wavevector(my*nkx + mx + 1, qx, qy)
         q = hypot(qx, qy)
         q_range(1) = min(q_range(1), q)
         q_range(2) = max(q_range(2), q)
         call op%kernel%factors(q, qx, one_minus_a, one_minus_b, c, t)
         g = 2.0_wp/q*op%compliance(mx + 1)*(one_minus_a - (0.0_wp, 1.0_wp)*op%friction*c*(qx/q))
         ! A Nyquist column mode is its own mirror image (q_x = +-pi/dx), so its multiplier is
         ! the mirror average (G(q_x, q_y) + G(-q_x, q_y))/2 = Re G
         if (2*mx == op%grid%nx) g = real(g, wp)
         op%metric(i) = abs(g)
         if (op%coupled) op%full(i) = g
      end do
   end subroutine mode_multipliers

   !> The preconditioner of the modes first..last: 1/M (0 where M = 0), times the
   !> material's factor of the mode's column where `factor` is allocated (viscoelastic).
   subroutine preconditioner_block(op, factor, first, last)
      type(compliance_operator), intent(inout) :: op
      real(wp), allocatable, intent(in) :: factor(:)
      integer, intent(in) :: first, last
      integer :: i, mx, my
      do i = first, last
         if (op%metric(i) > 0.0_wp) then
            op%preconditioner(i) = 1.0_wp/op%metric(i)
         else
            op%preconditioner(i) = 0.0_wp
         end if
      end do
      if (.not. allocated(factor)) return
      do i = first, last
         call op%fft%mode_indices(i, mx, my)
         op%preconditioner(i) = op%preconditioner(i)*factor(mx + 1)
      end do
   end subroutine preconditioner_block

   !> The multipliers of the rows my > ny/2 of a whole surface's half spectrum from the rows
   !> ny - my (q_y negated: |q| and q_x are the same), which build_operator left out: half
   !> the kernel's evaluations on a surface.
   subroutine mirror_rows(op, nkx)
      type(compliance_operator), intent(inout) :: op
      integer, intent(in) :: nkx
      integer :: my
      !$omp parallel do schedule(static) if(op%nk >= parallel_points)
      do my = op%grid%ny/2 + 1, op%grid%ny - 1
         call mirror_row(op, nkx, my)
      end do
   end subroutine mirror_rows

   !> mirror_rows on the row my.
   subroutine mirror_row(op, nkx, my)
      type(compliance_operator), intent(inout) :: op
      integer, intent(in) :: nkx, my
      integer :: row, mirror
      row = my*nkx
      mirror = (op%grid%ny - my)*nkx
      op%metric(row + 1:row + nkx) = op%metric(mirror + 1:mirror + nkx)
      if (op%coupled) op%full(row + 1:row + nkx) = op%full(mirror + 1:mirror + nkx)
   end subroutine mirror_row

   !> mirror_rows on a slab: in each of this rank's columns of the transposed half spectrum
   !> (all ny rows, my fastest) the rows my > ny/2 from the rows ny - my of the same column.
   subroutine mirror_columns(op)
      type(compliance_operator), intent(inout) :: op
      integer :: column
      !$omp parallel do schedule(static) if(op%nk >= parallel_points)
      do column = 0, op%fft%nkx_local - 1
         call mirror_column(op, column*op%grid%ny)
      end do
   end subroutine mirror_columns

   !> mirror_columns on the column whose row my is the mode base + my + 1.
   subroutine mirror_column(op, base)
      type(compliance_operator), intent(inout) :: op
      integer, intent(in) :: base
      integer :: my, ny
      ny = op%grid%ny
      do my = ny/2 + 1, ny - 1
         op%metric(base + my + 1) = op%metric(base + ny - my + 1)
         if (op%coupled) op%full(base + my + 1) = op%full(base + ny - my + 1)
      end do
   end subroutine mirror_column

   !> The quantities derived from the multipliers: diagonal, largest (the real-space column
   !> is made when a CG solve asks for it: prepare_cg).
   subroutine derive(op)
      type(compliance_operator), intent(inout) :: op
      real(wp), allocatable :: row_sums(:), maxima(:, :)
      integer :: n, row, nkx, block, first, last
      n = op%grid%points()
      nkx = op%grid%nkx()
      ! (1/n) sum over the whole spectrum, row by row of the half spectrum: modes
      ! 1..ceil(nx/2)-1 of a row stand for two, its mx = 0 and Nyquist modes for one
      op%diagonal = 0.0_wp
      if (op%distributed) then
         ! (this rank's columns: every mode twice, less those standing for themselves)
         op%diagonal = global_sum(2*sum(op%metric) - sum(op%metric(op%once)))
      else
         ! (each row's sum on the solve's threads, the rows' added in order: the same bits
         ! on any number of threads)
         allocate (row_sums(op%grid%ny))
         !$omp parallel do schedule(static) if(op%nk >= parallel_points)
         do row = 1, op%grid%ny
            row_sums(row) = row_weighted_sum(op%metric((row - 1)*nkx + 1:row*nkx), mod(op%grid%nx, 2) == 0)
         end do
         do row = 1, op%grid%ny
            op%diagonal = op%diagonal + row_sums(row)
         end do
      end if
      op%diagonal = op%diagonal/n
      ! (the largest multipliers by blocks: maxima are exact in any order)
      allocate (maxima(2, reduction_blocks(op%nk)))
      !$omp parallel do schedule(static) private(first, last) if(op%nk >= parallel_points)
      do block = 1, size(maxima, 2)
         call block_range(block, op%nk, first, last)
         call largest_multipliers(op, first, last, maxima(:, block))
      end do
      op%largest = maxval(maxima(1, :))
      if (op%coupled) op%largest = max(op%largest, maxval(maxima(2, :)))
      if (op%distributed) op%largest = global_max(op%largest)
      if (allocated(op%column)) deallocate (op%column)
   end subroutine derive

   !> A row of the half spectrum's share of the diagonal: its mode mx = 0 once, the others
   !> twice, less the Nyquist mode once more (`even`: nx even).
   pure real(wp) function row_weighted_sum(metric, even) result(total)
      real(wp), contiguous, intent(in) :: metric(:)
      logical, intent(in) :: even
      total = metric(1) + 2*sum(metric(2:)) - merge(metric(size(metric)), 0.0_wp, even)
   end function row_weighted_sum

   !> derive's maxima on the modes first..last: (max M, max |G_eff| where coupled).
   subroutine largest_multipliers(op, first, last, maxima)
      type(compliance_operator), intent(in) :: op
      integer, intent(in) :: first, last
      real(wp), intent(out) :: maxima(2)
      maxima(1) = maxval(op%metric(first:last))
      maxima(2) = 0.0_wp
      if (op%coupled) maxima(2) = maxval(abs(op%full(first:last)))
   end subroutine largest_multipliers

   !> Make the real-space column of M that the constrained CG's column updates need.
   subroutine prepare_cg(self)
      class(compliance_operator), intent(inout) :: self
      if (allocated(self%column) .or. self%distributed) return
      allocate (self%column(self%n))
      call advise_huge_pages(self%column)
      call column_in_buffer(self, real_multiplier=self%metric)
      call copy_field(self%fft%real_buffer, self%column)
   end subroutine prepare_cg

   !> Leave the uniform (k = 0) mode out of the operator and return its multiplier (h/M for
   !> a compressible layer, L/S). Under load control the uniform mode of p is the given
   !> p_m, so its displacement is a rigid shift that the constant s absorbs; without it w
   !> has the size of its fluctuations, and the rounding floor of the gap does not grow
   !> with the thickness (at h/lambda = 1e15, h p_m/M would hide every gap).
   subroutine drop_uniform_mode(self, uniform)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(out) :: uniform
      uniform = 0.0_wp
      if (self%holds_uniform) uniform = self%metric(1)
      if (self%distributed) call broadcast(uniform)
      if (uniform == 0.0_wp) return   ! half-space, incompressible layer
      self%dropped_uniform = self%dropped_uniform + uniform
      if (self%holds_uniform) then
         self%metric(1) = 0.0_wp
         self%preconditioner(1) = 0.0_wp
         if (self%coupled) self%full(1) = 0.0_wp
      end if
      ! (derived afresh: subtracting uniform/n from the column would cancel catastrophically
      ! on thick layers, where it dominates)
      call derive(self)
   end subroutine drop_uniform_mode

   !> The operator's FFT input/output buffer (n points): for the solvers that write the
   !> input of a *_in_buffer procedure into it and read the output from it.
   function buffer(self) result(field)
      class(compliance_operator), intent(in) :: self
      real(wp), pointer, contiguous :: field(:)
      field => self%fft%real_buffer
   end function buffer

   !> Wavevector (qx, qy) (1/L) and column mx of the half-spectrum mode i.
   pure subroutine column_mode(self, i, qx, qy, mx)
      class(compliance_operator), intent(in) :: self
      integer, intent(in) :: i
      real(wp), intent(out) :: qx, qy
      integer, intent(out) :: mx
      integer :: my
      call self%fft%mode_indices(i, mx, my)
      call self%grid%wavevector(my*self%grid%nkx() + mx + 1, qx, qy)
   end subroutine column_mode

   !> w = M p with the real symmetric metric.
   subroutine apply_metric(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      call apply_real(self, self%metric, p, w)
   end subroutine apply_metric

   !> w = G_eff p with the full (possibly complex) multiplier.
   subroutine apply_full(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      if (self%coupled) then
         call apply_complex(self, self%full, p, w)
      else
         call apply_real(self, self%metric, p, w)
      end if
   end subroutine apply_full

   !> w = (G_eff - M) p, the part the outer iteration of a coupled problem carries.
   subroutine apply_difference(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      if (self%coupled) then
         call apply_complex(self, self%full - self%metric, p, w)
      else
         w = 0.0_wp
      end if
   end subroutine apply_difference

   !> w <- w + sum_j delta_j G_eff e_j over the points j with delta_j /= 0: the response to
   !> a few point loads, a pass over the grid each (after prepare_gcr).
   subroutine add_full_columns(self, delta, w)
      class(compliance_operator), intent(in) :: self
      real(wp), contiguous, intent(in) :: delta(:)
      real(wp), contiguous, intent(inout) :: w(:)
      real(wp) :: unused
      unused = 0.0_wp
      call add_columns(self%grid, self%full_column, delta, w, unused)
   end subroutine add_full_columns

   !> d <- d + sum_j r_j M e_j over the points j with r_j /= 0 (a pass over the grid each),
   !> and d_contact <- d_contact + the sum of that change where p > 0.
   subroutine add_metric_columns(self, r, p, d, d_contact)
      class(compliance_operator), intent(in) :: self
      real(wp), contiguous, intent(in) :: r(:), p(:)
      real(wp), contiguous, intent(inout) :: d(:)
      real(wp), intent(inout) :: d_contact
      call add_columns(self%grid, self%column, r, d, d_contact, p)
   end subroutine add_metric_columns

   !> add_metric_columns for the loads r_k at the points points(k) alone.
   subroutine add_metric_columns_at(self, points, r, p, d, d_contact)
      class(compliance_operator), intent(in) :: self
      integer, intent(in) :: points(:)
      real(wp), intent(in) :: r(:)
      real(wp), contiguous, intent(in) :: p(:)
      real(wp), contiguous, intent(inout) :: d(:)
      real(wp), intent(inout) :: d_contact
      integer :: k
      do k = 1, size(points)
         call add_column(self%grid, self%column, points(k), r(k), d, d_contact, p)
      end do
   end subroutine add_metric_columns_at

   !> d <- d + sum_j r_j column(. - j), the circulant column shifted to each point j with
   !> r_j /= 0 (periodically along x and y), and, with p, total <- total + the sum of the
   !> change where p > 0.
   subroutine add_columns(grid, column, r, d, total, p)
      type(grid_type), intent(in) :: grid
      real(wp), contiguous, intent(in) :: column(:), r(:)
      real(wp), contiguous, intent(inout) :: d(:)
      real(wp), intent(inout) :: total
      real(wp), contiguous, intent(in), optional :: p(:)
      integer :: j
      do j = 1, size(r)
         if (r(j) /= 0.0_wp) call add_column(grid, column, j, r(j), d, total, p)
      end do
   end subroutine add_columns

   !> add_columns for the one point j.
   subroutine add_column(grid, column, j, value, d, total, p)
      type(grid_type), intent(in) :: grid
      real(wp), contiguous, intent(in) :: column(:)
      integer, intent(in) :: j
      real(wp), intent(in) :: value
      real(wp), contiguous, intent(inout) :: d(:)
      real(wp), intent(inout) :: total
      real(wp), contiguous, intent(in), optional :: p(:)
      integer :: jx, jy, iy, nx, target, source
      nx = grid%nx
      jx = mod(j - 1, nx) + 1
      jy = (j - 1)/nx
      do iy = 0, grid%ny - 1
         ! row iy of the response holds row iy - jy of the column, shifted by jx - 1:
         ! column(1..nx-jx+1) for ix = jx..nx, wrapped round for ix < jx
         target = iy*nx
         source = modulo(iy - jy, grid%ny)*nx
         call add_segment(value, column(source + 1:source + nx - jx + 1), d(target + jx:target + nx), total, &
            & p, target + jx)
         call add_segment(value, column(source + nx - jx + 2:source + nx), d(target + 1:target + jx - 1), total, &
            & p, target + 1)
      end do
   end subroutine add_column

   !> d <- d + value column, and (with p) total <- total + the sum of the change where
   !> p(offset:) > 0.
   pure subroutine add_segment(value, column, d, total, p, offset)
      real(wp), intent(in) :: value
      real(wp), contiguous, intent(in) :: column(:)
      real(wp), contiguous, intent(inout) :: d(:)
      real(wp), intent(inout) :: total
      real(wp), contiguous, intent(in), optional :: p(:)
      integer, intent(in) :: offset
      real(wp) :: added, v
      integer :: i
      if (.not. present(p)) then
         d = d + value*column
         return
      end if
      added = 0.0_wp
      !$omp simd reduction(+:added) private(v)
      do i = 1, size(d)
         v = value*column(i)
         d(i) = d(i) + v
         added = added + v*merge(1.0_wp, 0.0_wp, p(offset + i - 1) > 0.0_wp)
      end do
      total = total + added
   end subroutine add_segment

   !> fft%real_buffer <- M fft%real_buffer: for a solver that writes its input into the
   !> buffer and reads the output from it (two passes over the grid fewer than apply_metric).
   !> energy = sum_j t_j (M t)_j for the input t, by Parseval from the spectrum (in the
   !> multiplying pass, so without a pass over the grid).
   subroutine metric_in_buffer(self, energy)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(out), optional :: energy
      if (present(energy)) then
         if (self%fft%fuses_products()) then
            ! (the energy summed in the product's pass, between each block's column transforms)
            call self%fft%convolve(self%inv_n, real_multiplier=self%metric, energy=energy)
            if (self%distributed) energy = global_sum(energy)
            return
         end if
         call self%fft%forward_unscaled()
         call multiply_with_energy(self%fft%spectrum, self%metric, self%inv_n, self%grid%nkx(), &
            & mod(self%grid%nx, 2) == 0, energy)
         call self%fft%backward()
      else
         call multiply_in_buffer(self, self%metric)
      end if
   end subroutine metric_in_buffer

   !> The product with the metric, r = M t, with a solver's passes fused into its row
   !> stages (lc_fft_plans' convolve_passes: `work` writes t by blocks of rows, gets
   !> sum t M t, reads r by blocks of rows), for an operator whose plan fuses_products.
   subroutine metric_with_work(self, work, error)
      class(compliance_operator), intent(inout) :: self
      class(row_work), intent(inout) :: work
      type(error_type), allocatable, intent(out) :: error
      call self%fft%convolve_passes(self%inv_n, self%metric, work, error)
   end subroutine metric_with_work

   !> spectrum <- spectrum * multiplier/n, and energy = (1/n) sum over the whole spectrum of
   !> multiplier |spectrum|^2 (the modes of the half spectrum stand for two, q and -q, but
   !> those of each row's columns mx = 0 and, for even nx, mx = nx/2 for one).
   subroutine multiply_with_energy(spectrum, multiplier, inv_n, nkx, even, energy)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      real(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: inv_n
      integer, intent(in) :: nkx
      logical, intent(in) :: even
      real(wp), intent(out) :: energy
      real(wp) :: once
      real(wp) :: block_sums(reduction_blocks(size(spectrum)))
      integer :: first, last, block
      once = 0.0_wp
      do first = 1, size(spectrum), nkx
         once = once + multiplier(first)*inv_n*abs(spectrum(first))**2
         last = first + nkx - 1
         if (even .and. nkx > 1) once = once + multiplier(last)*inv_n*abs(spectrum(last))**2
      end do
      ! (by blocks on the solve's threads, their sums added in order: lc_base_threads)
      !$omp parallel do schedule(static) private(first, last) if(size(spectrum) >= parallel_points)
      do block = 1, size(block_sums)
         call block_range(block, size(spectrum), first, last)
         block_sums(block) = multiplied_energy(spectrum(first:last), multiplier(first:last), inv_n)
      end do
      energy = 2.0_wp*sum(block_sums) - once
   end subroutine multiply_with_energy

   !> True if mode i of the operator's spectrum stands for itself only (its column is mx = 0
   !> or, for even nx, nx/2).
   logical function once_mode(op, i)
      type(compliance_operator), intent(in) :: op
      integer, intent(in) :: i
      integer :: mx, my
      call op%fft%mode_indices(i, mx, my)
      once_mode = mx == 0 .or. 2*mx == op%grid%nx
   end function once_mode

   !> multiply_with_energy on a block: spectrum <- spectrum * multiplier/n and the sum of
   !> multiplier/n |spectrum|^2 before.
   real(wp) function multiplied_energy(spectrum, multiplier, inv_n) result(twice)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      real(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: inv_n
      real(wp) :: f
      integer :: m
      twice = 0.0_wp
      !$omp simd reduction(+:twice) private(f)
      do m = 1, size(spectrum)
         f = multiplier(m)*inv_n
         twice = twice + f*(real(spectrum(m), wp)**2 + aimag(spectrum(m))**2)
         spectrum(m) = spectrum(m)*f
      end do
   end function multiplied_energy

   !> spectrum <- spectrum * multiplier (times scale), by blocks on the solve's threads.
   subroutine multiply_spectrum(spectrum, multiplier, scale)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      real(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in), optional :: scale
      real(wp) :: f
      integer :: block, first, last
      f = 1.0_wp
      if (present(scale)) f = scale
      !$omp parallel do schedule(static) private(first, last) if(size(spectrum) >= parallel_points)
      do block = 1, reduction_blocks(size(spectrum))
         call block_range(block, size(spectrum), first, last)
         call multiply_real_block(spectrum(first:last), multiplier(first:last), f)
      end do
   end subroutine multiply_spectrum

   !> The same with a complex multiplier.
   subroutine multiply_complex(spectrum, multiplier, scale)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      complex(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in), optional :: scale
      real(wp) :: f
      integer :: block, first, last
      f = 1.0_wp
      if (present(scale)) f = scale
      !$omp parallel do schedule(static) private(first, last) if(size(spectrum) >= parallel_points)
      do block = 1, reduction_blocks(size(spectrum))
         call block_range(block, size(spectrum), first, last)
         call multiply_complex_block(spectrum(first:last), multiplier(first:last), f)
      end do
   end subroutine multiply_complex

   pure subroutine multiply_real_block(spectrum, multiplier, f)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      real(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: f
      spectrum = spectrum*(multiplier*f)
   end subroutine multiply_real_block

   pure subroutine multiply_complex_block(spectrum, multiplier, f)
      complex(wp), contiguous, intent(inout) :: spectrum(:)
      complex(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: f
      spectrum = spectrum*(multiplier*f)
   end subroutine multiply_complex_block

   !> fft%real_buffer <- P fft%real_buffer with the preconditioner P (see metric_in_buffer).
   subroutine inverse_metric_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      call multiply_in_buffer(self, self%preconditioner)
   end subroutine inverse_metric_in_buffer

   !> What the constrained GCR needs besides G_eff (built on first use, after the uniform
   !> mode was dropped or not): its Fourier inverse, its real-space column and the
   !> real-space diagonal of the inverse.
   subroutine prepare_gcr(self)
      class(compliance_operator), intent(inout) :: self
      ! (G_eff itself where it is complex: no copy of the multiplier)
      if (self%coupled) then
         call prepare_gcr_with(self, self%full)
      else
         call prepare_gcr_with(self, cmplx(self%metric, 0.0_wp, kind=wp))
      end if
   end subroutine prepare_gcr

   !> prepare_gcr with G_eff = g on the half spectrum.
   subroutine prepare_gcr_with(self, g)
      class(compliance_operator), intent(inout) :: self
      complex(wp), contiguous, intent(in) :: g(:)
      integer :: n, block, first, last
      n = self%n
      if (allocated(self%inverse_full)) deallocate (self%inverse_full)
      allocate (self%inverse_full(self%nk))
      call advise_huge_pages(self%inverse_full)
      !$omp parallel do schedule(static) private(first, last) if(self%nk >= parallel_points)
      do block = 1, reduction_blocks(self%nk)
         call block_range(block, self%nk, first, last)
         call invert_block(g(first:last), self%inverse_full(first:last))
      end do
      if (.not. self%distributed) then
         if (.not. allocated(self%full_column)) then
            allocate (self%full_column(n))
            call advise_huge_pages(self%full_column)
         end if
         call column_in_buffer(self, complex_multiplier=g)
         call copy_field(self%fft%real_buffer, self%full_column)
      end if
      ! (the inverse's real-space diagonal, its column's value at the load: (1/n) times the
      ! sum of the inverse over the whole spectrum, whose imaginary parts cancel between q
      ! and -q; summed as derive sums the metric's diagonal)
      self%inverse_diagonal = spectrum_sum(self, real(self%inverse_full, wp))
   end subroutine prepare_gcr_with

   !> fft%real_buffer <- the real-space column of a multiplier on the half spectrum: its
   !> response to a unit load at the first point. The bare r2c of that load is 1 on every
   !> mode, so the product is the multiplier times 1/n, and only the backward transform is
   !> needed.
   subroutine column_in_buffer(self, real_multiplier, complex_multiplier)
      class(compliance_operator), intent(inout) :: self
      real(wp), contiguous, intent(in), optional :: real_multiplier(:)
      complex(wp), contiguous, intent(in), optional :: complex_multiplier(:)
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(self%nk >= parallel_points)
      do block = 1, reduction_blocks(self%nk)
         call block_range(block, self%nk, first, last)
         if (present(real_multiplier)) then
            self%fft%spectrum(first:last) = real_multiplier(first:last)*self%inv_n
         else
            self%fft%spectrum(first:last) = complex_multiplier(first:last)*self%inv_n
         end if
      end do
      call self%fft%backward()
   end subroutine column_in_buffer

   !> (1/n) times the sum over the whole spectrum of `values` on the half spectrum (each
   !> mode standing for q and -q, those of the columns mx = 0 and, for even nx, nx/2 for
   !> themselves only): on a distributed surface over every rank's columns.
   real(wp) function spectrum_sum(self, values) result(total)
      class(compliance_operator), intent(in) :: self
      real(wp), contiguous, intent(in) :: values(:)
      real(wp), allocatable :: row_sums(:)
      integer :: row, nkx
      if (self%distributed) then
         total = global_sum(2*sum(values) - sum(values(self%once)))*self%inv_n
         return
      end if
      nkx = self%grid%nkx()
      allocate (row_sums(self%grid%ny))
      do row = 1, self%grid%ny
         row_sums(row) = row_weighted_sum(values((row - 1)*nkx + 1:row*nkx), mod(self%grid%nx, 2) == 0)
      end do
      total = sum(row_sums)*self%inv_n
   end function spectrum_sum

   !> inverse = 1/g (0 where g = 0) on a block of modes.
   pure subroutine invert_block(g, inverse)
      complex(wp), contiguous, intent(in) :: g(:)
      complex(wp), contiguous, intent(out) :: inverse(:)
      where (abs(g) > 0.0_wp)
         inverse = 1.0_wp/g
      elsewhere
         inverse = (0.0_wp, 0.0_wp)
      end where
   end subroutine invert_block

   !> fft%real_buffer <- G_eff fft%real_buffer (see metric_in_buffer).
   subroutine full_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      if (self%coupled) then
         call multiply_complex_in_buffer(self, self%full)
      else
         call multiply_in_buffer(self, self%metric)
      end if
   end subroutine full_in_buffer

   !> fft%real_buffer <- G_eff^-1 fft%real_buffer (0 on the modes where G_eff = 0; after
   !> prepare_gcr).
   subroutine inverse_full_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      call multiply_complex_in_buffer(self, self%inverse_full)
   end subroutine inverse_full_in_buffer

   !> fft%real_buffer <- multiplier * fft%real_buffer with a complex multiplier on the half
   !> spectrum (for a solver's own multipliers of the scene: lc_contact_solver_gfmd).
   subroutine multiply_complex_in_buffer(self, multiplier)
      class(compliance_operator), intent(inout) :: self
      complex(wp), contiguous, intent(in) :: multiplier(:)
      if (self%fft%fuses_products()) then
         call self%fft%convolve(self%inv_n, complex_multiplier=multiplier)
         return
      end if
      call self%fft%forward_unscaled()
      call multiply_complex(self%fft%spectrum, multiplier, self%inv_n)
      call self%fft%backward()
   end subroutine multiply_complex_in_buffer

   !> w = multiplier * p through the plans; the 1/n of the forward transform is folded in.
   subroutine apply_real(self, multiplier, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      self%fft%real_buffer = p
      call multiply_in_buffer(self, multiplier)
      w = self%fft%real_buffer
   end subroutine apply_real

   !> fft%real_buffer <- multiplier * fft%real_buffer.
   subroutine multiply_in_buffer(self, multiplier)
      class(compliance_operator), intent(inout) :: self
      real(wp), contiguous, intent(in) :: multiplier(:)
      if (self%fft%fuses_products()) then
         call self%fft%convolve(self%inv_n, real_multiplier=multiplier)
         return
      end if
      call self%fft%forward_unscaled()
      call multiply_spectrum(self%fft%spectrum, multiplier, self%inv_n)
      call self%fft%backward()
   end subroutine multiply_in_buffer

   !> The same with a complex multiplier.
   subroutine apply_complex(self, multiplier, p, w)
      class(compliance_operator), intent(inout) :: self
      complex(wp), contiguous, intent(in) :: multiplier(:)
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      self%fft%real_buffer = p
      call multiply_complex_in_buffer(self, multiplier)
      w = self%fft%real_buffer
   end subroutine apply_complex
end module lc_contact_operator
