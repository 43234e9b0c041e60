!> Measured heights fitted to a scene's grid (&profile kind = 'file'; docs/topographies.md).
!> The file's array (lc_profiles_height_file) goes through, in this order:
!>
!> 1. the shape rule: a line scene takes a file of one row or one column, an areal scene a
!>    2D array of at least 2 x 2 heights;
!> 2. detrend (&profile detrend): the least-squares fit of a polynomial in x and y over the
!>    file's points is subtracted: 'mean' (a constant), 'plane' (1, x, y), 'curvature'
!>    (1, x, y, x^2, y^2, x y); 'none' leaves the heights as they are. 'auto' is 'none' for
!>    a periodic file and 'plane' for a patch to be mirrored: a tilt cannot be part of a
!>    periodic surface (a least-squares plane of one is a fit to its roughness, and taking
!>    it away would put a step at the cell's edges), while the tilt of a measured patch is
!>    its levelling, which the mirror image would turn into a long triangular wave;
!> 3. boundary (&profile boundary): 'periodic' takes the file as one period of the surface;
!>    'mirror' appends the patch's mirror image along x (and along y for a surface), so
!>    that the cell holds 2 m points per m measured and its edges meet without a step
!>    (h(2m-1-j) = h(j)); &scene period is then the mirrored cell, twice the patch;
!> 4. resample (&profile resample): 'none' asks for the grid's size; 'fourier' maps the
!>    heights onto the grid by their Fourier series: modes shorter than either grid allows
!>    are dropped (the Nyquist mode of an even size too, unless the size is kept), the
!>    others are kept exactly, so a band-limited periodic surface is resampled exactly and
!>    coarsening loses the wavelengths shorter than two new grid steps.
!>
!> Detrending uses the index coordinates, centred and scaled to [-1, 1]: a polynomial
!> space of x and y is the same in any affine coordinates, so the fit does not depend on
!> the periods, and the scaled normal equations stay well conditioned.
module lc_profiles_measured
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, input_error, code_input
   use lc_base_strings, only: to_string
   use lc_fft_plans, only: fft_plan
   use lc_base_parallel, only: global_sum, slab, shifted_rows, sum_over_ranks
   use lc_profiles_height_file, only: read_height_file, named, shape_text
   implicit none (type, external)
   private
   public :: measured_heights, measured_grid, prepare_heights, detrend_heights, mirror_heights, resample_heights
   public :: detrend_modes, boundary_modes, resample_modes, check_treatments
   public :: periodicity_mismatch, edge_jump_limit, edge_kink_limit, slab_periodicity_mismatch, &
      & detrend_slab, c_shape

   !> Allowed values of &profile detrend, boundary and resample, for checks and messages.
   character(len=*), parameter :: detrend_modes = "'auto', 'none', 'mean', 'plane' or 'curvature'"
   character(len=*), parameter :: boundary_modes = "'periodic' or 'mirror'"
   character(len=*), parameter :: resample_modes = "'none' or 'fourier'"
   !> Heights taken as one period are suspect of not being periodic above these
   !> (periodicity_mismatch): a jump across the cell's edges of 2 rms heights (a tilted plane
   !> gives sqrt(12) = 3.46, the periodic self-affine surfaces measured at most 1.61), a kink
   !> of 4 times the cell's own (those surfaces measured at most 3.14; docs/decisions/019).
   real(wp), parameter :: edge_jump_limit = 2.0_wp, edge_kink_limit = 4.0_wp

contains

   !> Heights of `filename` on the scene's grid of nx x ny points (ny = 1 and areal false:
   !> a line), through the steps of the module header.
   subroutine measured_heights(filename, dataset, areal, detrend, boundary, resample, nx, ny, height, error)
      !> File and dataset (&profile file, dataset)
      character(len=*), intent(in) :: filename, dataset
      !> True for an areal scene
      logical, intent(in) :: areal
      !> &profile detrend, boundary and resample
      character(len=*), intent(in) :: detrend, boundary, resample
      !> The scene's grid
      integer, intent(in) :: nx, ny
      !> Heights on the grid (L), x fastest
      real(wp), intent(out) :: height(nx, ny)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: raw(:, :)

      height = 0.0_wp
      call read_height_file(filename, dataset, raw, error)
      if (allocated(error)) return
      if (.not. areal) then
         ! a line: one row or one column, as a (n, 1) array
         if (size(raw, 2) /= 1 .and. size(raw, 1) /= 1) then
            call fatal_error(error, named(filename) // ' holds shape ' // c_shape(raw) // "; allowed: one row " // &
               & "or one column of heights with geometry = 'line'", code_input)
            return
         end if
         if (size(raw, 2) /= 1) raw = reshape(raw, [size(raw), 1])
      else if (size(raw, 1) < 2 .or. size(raw, 2) < 2) then
         call fatal_error(error, named(filename) // ' holds shape ' // c_shape(raw) // "; allowed: a 2D array " // &
            & "(ny, nx) of at least 2 x 2 heights with geometry = 'areal'", code_input)
         return
      end if
      call prepare_heights(raw, areal, detrend, boundary, resample, nx, ny, height, error)
      if (allocated(error)) then
         if (index(error%message, '&profile') /= 1) error%message = named(filename) // ' ' // error%message
      end if
   end subroutine measured_heights

   !> The grid a file's heights give without resampling: the file's size after the shape
   !> rule, twice along each mirrored axis with boundary = 'mirror' (ny = 1 for a line).
   subroutine measured_grid(filename, dataset, areal, boundary, nx, ny, error)
      character(len=*), intent(in) :: filename, dataset, boundary
      logical, intent(in) :: areal
      integer, intent(out) :: nx, ny
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: raw(:, :)
      integer :: factor

      nx = 0
      ny = 1
      call read_height_file(filename, dataset, raw, error)
      if (allocated(error)) return
      factor = merge(2, 1, trim(boundary) == 'mirror')
      if (.not. areal) then
         if (size(raw, 2) /= 1 .and. size(raw, 1) /= 1) then
            call fatal_error(error, named(filename) // ' holds shape ' // c_shape(raw) // "; allowed: one row " // &
               & "or one column of heights with geometry = 'line'", code_input)
            return
         end if
         nx = factor*size(raw)
      else
         nx = factor*size(raw, 1)
         ny = factor*size(raw, 2)
      end if
   end subroutine measured_grid

   !> The values of &profile detrend, boundary and resample (the namelist check and the
   !> Python route both ask here).
   subroutine check_treatments(detrend, boundary, resample, error)
      character(len=*), intent(in) :: detrend, boundary, resample
      type(error_type), allocatable, intent(out) :: error
      select case (trim(detrend))
      case ('auto', 'none', 'mean', 'plane', 'curvature')
      case default
         call input_error(error, 'profile', 'detrend', "'" // trim(detrend) // "'", detrend_modes)
         return
      end select
      if (trim(boundary) /= 'periodic' .and. trim(boundary) /= 'mirror') then
         call input_error(error, 'profile', 'boundary', "'" // trim(boundary) // "'", boundary_modes)
      else if (trim(resample) /= 'none' .and. trim(resample) /= 'fourier') then
         call input_error(error, 'profile', 'resample', "'" // trim(resample) // "'", resample_modes)
      end if
   end subroutine check_treatments

   !> Steps 2 to 4 of the module header on heights raw(mx, my) (my = 1 for a line): the
   !> heights on an nx x ny grid. Messages of the grid's size start with 'holds'.
   subroutine prepare_heights(raw, areal, detrend, boundary, resample, nx, ny, height, error)
      real(wp), intent(in) :: raw(:, :)
      logical, intent(in) :: areal
      character(len=*), intent(in) :: detrend, boundary, resample
      integer, intent(in) :: nx, ny
      real(wp), intent(out) :: height(nx, ny)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: work(:, :)
      character(len=:), allocatable :: mode

      height = 0.0_wp
      call check_treatments(detrend, boundary, resample, error)
      if (allocated(error)) return
      mode = trim(detrend)
      if (mode == 'auto') mode = merge('plane', 'none ', trim(boundary) == 'mirror')

      ! a polynomial of degree d needs d + 1 points along each axis it varies along
      select case (mode)
      case ('plane', 'curvature')
         if (size(raw, 1) < merge(3, 2, mode == 'curvature') .or. &
            & (areal .and. size(raw, 2) < merge(3, 2, mode == 'curvature'))) then
            call fatal_error(error, 'holds shape ' // c_shape(raw) // "; allowed: at least " // &
               & trim(merge('3', '2', mode == 'curvature')) // " points along each axis with detrend = '" // &
               & mode // "'", code_input)
            return
         end if
      end select
      work = raw
      call detrend_heights(work, mode)
      if (trim(boundary) == 'mirror') call mirror_heights(work, areal)
      if (size(work, 1) == nx .and. size(work, 2) == ny) then
         height = work
      else if (trim(resample) == 'fourier') then
         call resample_heights(work, height, error)
      else if (areal) then
         call fatal_error(error, 'holds shape ' // c_shape(work) // trim(merge(' (mirrored)', '           ', &
            & trim(boundary) == 'mirror')) // '; allowed: the grid, (ny, nx) = (' // to_string(ny) // ', ' // &
            & to_string(nx) // "), or &profile resample = 'fourier'", code_input)
      else
         call fatal_error(error, 'holds ' // to_string(size(work)) // ' heights' // trim(merge(' (mirrored)', &
            & '           ', trim(boundary) == 'mirror')) // '; allowed: the grid, n = ' // to_string(nx) // &
            & ", or &profile resample = 'fourier'", code_input)
      end if
   end subroutine prepare_heights

   !> The shape of height(nx, ny) in C order, as numpy shows it: (ny, nx), or (n,) for
   !> a single row.
   pure function c_shape(height) result(s)
      real(wp), intent(in) :: height(:, :)
      character(len=:), allocatable :: s
      if (size(height, 2) == 1) then
         s = shape_text([size(height, 1, kind=i8)])
      else
         s = shape_text([size(height, 2, kind=i8), size(height, 1, kind=i8)])
      end if
   end function c_shape

   !> Subtract the least-squares fit of 'mean', 'plane' or 'curvature' (module header,
   !> step 2); 'none' keeps the heights. A single row (my = 1) is a line: no y terms.
   pure subroutine detrend_heights(height, mode)
      real(wp), intent(inout) :: height(:, :)
      character(len=*), intent(in) :: mode
      real(wp) :: normal(6, 6), rhs(6), basis(6), coefficients(6), u, v
      integer :: terms, ix, iy, mx, my

      mx = size(height, 1)
      my = size(height, 2)
      select case (mode)
      case ('mean')
         terms = 1
      case ('plane')
         terms = merge(2, 3, my == 1)
      case ('curvature')
         terms = merge(3, 6, my == 1)
      case default
         return
      end select
      normal = 0.0_wp
      rhs = 0.0_wp
      do iy = 1, my
         v = centred(iy, my)
         do ix = 1, mx
            u = centred(ix, mx)
            basis = terms_at(u, v, my == 1)
            call add_outer(normal, basis, terms)
            rhs(1:terms) = rhs(1:terms) + basis(1:terms)*height(ix, iy)
         end do
      end do
      call solve_small(normal(1:terms, 1:terms), rhs(1:terms), coefficients(1:terms))
      do iy = 1, my
         v = centred(iy, my)
         do ix = 1, mx
            u = centred(ix, mx)
            basis = terms_at(u, v, my == 1)
            height(ix, iy) = height(ix, iy) - dot_product(coefficients(1:terms), basis(1:terms))
         end do
      end do
   end subroutine detrend_heights

   !> detrend_heights on a surface shared among MPI ranks: `height` holds the rows
   !> y_start+1 .. of the ny rows; the least-squares sums are added over the ranks.
   subroutine detrend_slab(height, y_start, ny, mode)
      real(wp), intent(inout) :: height(:, :)
      integer, intent(in) :: y_start, ny
      character(len=*), intent(in) :: mode
      real(wp) :: normal(6, 6), rhs(6), basis(6), coefficients(6), sums(42), u, v
      integer :: terms, ix, iy, mx

      mx = size(height, 1)
      select case (mode)
      case ('mean')
         terms = 1
      case ('plane')
         terms = 3
      case ('curvature')
         terms = 6
      case default
         return
      end select
      normal = 0.0_wp
      rhs = 0.0_wp
      do iy = 1, size(height, 2)
         v = centred(y_start + iy, ny)
         do ix = 1, mx
            u = centred(ix, mx)
            basis = terms_at(u, v, .false.)
            call add_outer(normal, basis, terms)
            rhs(1:terms) = rhs(1:terms) + basis(1:terms)*height(ix, iy)
         end do
      end do
      sums = [reshape(normal, [36]), rhs]
      call sum_over_ranks(sums)
      normal = reshape(sums(1:36), [6, 6])
      rhs = sums(37:42)
      call solve_small(normal(1:terms, 1:terms), rhs(1:terms), coefficients(1:terms))
      do iy = 1, size(height, 2)
         v = centred(y_start + iy, ny)
         do ix = 1, mx
            u = centred(ix, mx)
            basis = terms_at(u, v, .false.)
            height(ix, iy) = height(ix, iy) - dot_product(coefficients(1:terms), basis(1:terms))
         end do
      end do
   end subroutine detrend_slab

   !> Index i of 1..m mapped onto [-1, 1] (0 for m = 1).
   pure real(wp) function centred(i, m)
      integer, intent(in) :: i, m
      centred = 0.0_wp
      if (m > 1) centred = (2*i - m - 1)/real(m - 1, wp)
   end function centred

   !> The basis 1, u, v, u^2, v^2, u v (a line: 1, u, u^2).
   pure function terms_at(u, v, line) result(basis)
      real(wp), intent(in) :: u, v
      logical, intent(in) :: line
      real(wp) :: basis(6)
      if (line) then
         basis = [1.0_wp, u, u**2, 0.0_wp, 0.0_wp, 0.0_wp]
      else
         basis = [1.0_wp, u, v, u**2, v**2, u*v]
      end if
   end function terms_at

   pure subroutine add_outer(normal, basis, terms)
      real(wp), intent(inout) :: normal(6, 6)
      real(wp), intent(in) :: basis(6)
      integer, intent(in) :: terms
      integer :: j
      do j = 1, terms
         normal(1:terms, j) = normal(1:terms, j) + basis(1:terms)*basis(j)
      end do
   end subroutine add_outer

   !> Solve the symmetric positive definite system a x = b (at most 6 x 6) by Gaussian
   !> elimination with partial pivoting.
   pure subroutine solve_small(a, b, x)
      real(wp), intent(in) :: a(:, :), b(:)
      real(wp), intent(out) :: x(:)
      real(wp) :: m(size(b), size(b) + 1), row(size(b) + 1)
      integer :: n, k, p, i

      n = size(b)
      m(:, 1:n) = a
      m(:, n + 1) = b
      do k = 1, n
         p = k - 1 + maxloc(abs(m(k:n, k)), 1)
         if (p /= k) then
            row = m(k, :)
            m(k, :) = m(p, :)
            m(p, :) = row
         end if
         do i = k + 1, n
            m(i, k:) = m(i, k:) - m(i, k)/m(k, k)*m(k, k:)
         end do
      end do
      do k = n, 1, -1
         x(k) = (m(k, n + 1) - dot_product(m(k, k + 1:n), x(k + 1:n)))/m(k, k)
      end do
   end subroutine solve_small

   !> Append the mirror image: (mx, my) -> (2 mx, 2 my) for a surface, (2 mx, 1) for a
   !> line, with h(2m-1-j) = h(j) (0-based) along each mirrored axis.
   pure subroutine mirror_heights(height, areal)
      real(wp), allocatable, intent(inout) :: height(:, :)
      logical, intent(in) :: areal
      real(wp), allocatable :: mirrored(:, :)
      integer :: mx, my, ny

      mx = size(height, 1)
      my = size(height, 2)
      ny = merge(2*my, my, areal)
      allocate (mirrored(2*mx, ny))
      mirrored(1:mx, 1:my) = height
      mirrored(2*mx:mx + 1:-1, 1:my) = height
      if (areal) mirrored(:, 2*my:my + 1:-1) = mirrored(:, 1:my)
      call move_alloc(mirrored, height)
   end subroutine mirror_heights

   !> Fourier resampling of a periodic raw(mx, my) onto height(nx, ny) (module header,
   !> step 4).
   subroutine resample_heights(raw, height, error)
      real(wp), intent(in) :: raw(:, :)
      real(wp), intent(out) :: height(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(fft_plan) :: from, to
      integer :: mx, my, nx, ny, kx_max, ky_max, kx, ky, mkx, nkx

      mx = size(raw, 1)
      my = size(raw, 2)
      nx = size(height, 1)
      ny = size(height, 2)
      height = 0.0_wp
      call from%init(mx, my, 1, error)
      if (allocated(error)) return
      call to%init(nx, ny, 1, error)
      if (allocated(error)) return
      from%real_buffer = reshape(raw, [mx*my])
      call from%forward()
      ! a kept size keeps its Nyquist mode; a changed one drops it (it has no unique
      ! continuation: cos and sin of the Nyquist wavenumber differ between the grids)
      kx_max = merge(mx/2, min((mx - 1)/2, (nx - 1)/2), mx == nx)
      ky_max = merge(my/2, min((my - 1)/2, (ny - 1)/2), my == ny)
      mkx = mx/2 + 1
      nkx = nx/2 + 1
      to%spectrum = (0.0_wp, 0.0_wp)
      do ky = -ky_max, ky_max
         if (my == ny .and. ky == -ky_max .and. 2*ky_max == my .and. ky_max > 0) cycle   ! one Nyquist row
         do kx = 0, kx_max
            to%spectrum(1 + kx + nkx*modulo(ky, ny)) = from%spectrum(1 + kx + mkx*modulo(ky, my))
         end do
      end do
      call to%backward()
      height = reshape(to%real_buffer, [nx, ny])
   end subroutine resample_heights
   !> How far heights taken as one period are from periodic, the larger value along x and
   !> along y (an axis of fewer than 16 points is not measured):
   !> `jump`, the rms over the rows of the step across the cell's edge, h(1) - h(n), in rms
   !> heights (about the mean); `kink`, the rms over the rows of the mismatch of the slopes
   !> across the edge, the second difference h(1+m) - 2 h(1) + h(n+1-m) over m = max(2, n/16)
   !> points of the periodic continuation, in units of the rms of the same second difference
   !> at the points at least 2m from the edges (a periodic surface's edge is one of its
   !> points: about 1; a kink the cell does not have elsewhere: large, Inf on a smooth one).
   pure subroutine periodicity_mismatch(height, jump, kink)
      !> Heights on the grid (L), (nx, ny), x fastest
      real(wp), intent(in) :: height(:, :)
      !> The step across the edges in rms heights, the slope mismatch in the cell's own units
      real(wp), intent(out) :: jump, kink
      real(wp) :: rms, axis_jump, axis_kink
      rms = sqrt(sum((height - sum(height)/size(height))**2)/size(height))
      jump = 0.0_wp
      kink = 0.0_wp
      if (.not. rms > 0.0_wp) return
      if (size(height, 1) >= 16) then
         call edge_mismatch(height, rms, axis_jump, axis_kink)
         jump = max(jump, axis_jump)
         kink = max(kink, axis_kink)
      end if
      if (size(height, 2) >= 16) then
         call edge_mismatch(transpose(height), rms, axis_jump, axis_kink)
         jump = max(jump, axis_jump)
         kink = max(kink, axis_kink)
      end if
   end subroutine periodicity_mismatch

   !> periodicity_mismatch of a surface (nx, ny) shared among MPI ranks, from this rank's slab
   !> of rows `height` (flat, x fastest); every rank calls it and gets the same values. Along
   !> x the edges and second differences lie inside each row: each rank sums over its rows.
   !> Along y they join rows of other ranks: the slab of the surface shifted by -1, m and -m
   !> rows (lc_base_parallel's shifted_rows) gives each row its partners.
   subroutine slab_periodicity_mismatch(height, nx, ny, jump, kink)
      real(wp), intent(in) :: height(:)
      integer, intent(in) :: nx, ny
      real(wp), intent(out) :: jump, kink
      real(wp), allocatable :: rows(:, :), before(:, :), ahead(:, :), behind(:, :), flat(:)
      real(wp) :: rms, mean, sums(4)
      integer :: y_start, ny_local, m, j, g
      call slab(ny, y_start, ny_local)
      rows = reshape(height, [nx, ny_local])
      mean = global_sum(sum(rows))/(real(nx, wp)*ny)
      rms = sqrt(global_sum(sum((rows - mean)**2))/(real(nx, wp)*ny))
      jump = 0.0_wp
      kink = 0.0_wp
      if (.not. rms > 0.0_wp) return
      if (nx >= 16) then
         ! (sums over this rank's rows: jump^2, edge, inside, and the inside's count)
         m = max(2, nx/16)
         sums = 0.0_wp
         sums(1) = sum((rows(1, :) - rows(nx, :))**2)
         sums(2) = sum((rows(1 + m, :) - 2*rows(1, :) + rows(nx + 1 - m, :))**2)
         do j = 2*m + 1, nx - 2*m
            sums(3) = sums(3) + sum((rows(j + m, :) - 2*rows(j, :) + rows(j - m, :))**2)
         end do
         sums(4) = real(max(nx - 4*m, 0), wp)*ny
         call add_axis(sums, ny)
      end if
      if (ny >= 16) then
         m = max(2, ny/16)
         call shifted_rows(height, nx, ny, -1, flat)
         before = reshape(flat, [nx, ny_local])
         call shifted_rows(height, nx, ny, m, flat)
         ahead = reshape(flat, [nx, ny_local])
         call shifted_rows(height, nx, ny, -m, flat)
         behind = reshape(flat, [nx, ny_local])
         sums = 0.0_wp
         do j = 1, ny_local
            g = y_start + j - 1
            if (g == 0) then
               sums(1) = sum((rows(:, j) - before(:, j))**2)
               sums(2) = sum((ahead(:, j) - 2*rows(:, j) + behind(:, j))**2)
            end if
            if (g >= 2*m .and. g <= ny - 2*m - 1) sums(3) = sums(3) + sum((ahead(:, j) - 2*rows(:, j) + behind(:, j))**2)
         end do
         sums(4) = real(max(ny - 4*m, 0), wp)*nx
         call add_axis(sums, nx)
      end if

   contains

      !> jump and kink of one axis from the sums over the ranks (`lines`: the lines across it).
      subroutine add_axis(sums, lines)
         real(wp), intent(inout) :: sums(4)
         integer, intent(in) :: lines
         real(wp) :: edge, inside, axis_kink
         sums(1:3) = [global_sum(sums(1)), global_sum(sums(2)), global_sum(sums(3))]
         jump = max(jump, sqrt(sums(1)/lines)/rms)
         edge = sums(2)/lines
         inside = 0.0_wp
         if (sums(4) > 0.0_wp) inside = sums(3)/sums(4)
         if (inside > 0.0_wp) then
            axis_kink = sqrt(edge/inside)
         else if (edge > 0.0_wp) then
            axis_kink = huge(1.0_wp)
         else
            axis_kink = 0.0_wp
         end if
         kink = max(kink, axis_kink)
      end subroutine add_axis
   end subroutine slab_periodicity_mismatch

   !> periodicity_mismatch along the first axis of `rows` (n, rows).
   pure subroutine edge_mismatch(rows, rms, jump, kink)
      real(wp), intent(in) :: rows(:, :), rms
      real(wp), intent(out) :: jump, kink
      real(wp) :: edge, inside
      integer :: n, m, j, count_inside
      n = size(rows, 1)
      m = max(2, n/16)
      jump = sqrt(sum((rows(1, :) - rows(n, :))**2)/size(rows, 2))/rms
      edge = sum((rows(1 + m, :) - 2*rows(1, :) + rows(n + 1 - m, :))**2)/size(rows, 2)
      inside = 0.0_wp
      count_inside = 0
      do j = 2*m + 1, n - 2*m
         inside = inside + sum((rows(j + m, :) - 2*rows(j, :) + rows(j - m, :))**2)
         count_inside = count_inside + size(rows, 2)
      end do
      if (count_inside > 0) inside = inside/count_inside
      if (inside > 0.0_wp) then
         kink = sqrt(edge/inside)
      else if (edge > 0.0_wp) then
         kink = huge(1.0_wp)
      else
         kink = 0.0_wp
      end if
   end subroutine edge_mismatch

end module lc_profiles_measured
