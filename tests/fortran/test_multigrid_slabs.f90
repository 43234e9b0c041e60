!> The multigrid hierarchy's finest grid on the slabs of a surface shared among MPI ranks
!> (lc_contact_multigrid_hierarchy, `on_slabs`). Run by tests/test_mpi_multigrid.py under
!> `mpirun -n P`, P = 1..4 (not by `meson test`: on one rank there is no slab). Every rank
!> builds the hierarchy of the whole grid on a plan of its own (serial) and the hierarchy on
!> its slab (the distributed plan), with the same symbol and the same contact set, and checks
!> on its rows that
!>  - the preconditioner B r (the slabs' shares of P^T r summed over the ranks, the first
!>    coarse grid's penalty made of the slabs' rows of the contact set, the V-cycle below
!>    whole, the correction interpolated onto the slab) is the whole grid's;
!>  - K x and x.K x (summed over the ranks) are the whole grid's;
!>  - the spectral interpolation of a field of the first coarse grid onto the slab is the
!>    whole grid's;
!> for a real symbol (Jacobi steps), a complex one (its odd imaginary part), and a complex
!> one smoothed by rows, on 32 x 32 points: with P = 3 the second slab starts on an odd row
!> (rows 11..21) and the last ends on the last row (the periodic wrap of the restriction).
!> A share added into the wrong coarse row, a halo row missed or a mode of the transposed
!> spectrum read at the wrong index changes B r by a fraction of its size.
!>
!> The GCR's orthogonalisation of a direction and its image against the stored unit images
!> on the free points (orthogonalise_over_ranks: classical Gram-Schmidt, every product summed
!> over the ranks in one message) is checked against the whole grid's modified Gram-Schmidt
!> (orthogonalise) on the same fields; a product left unsummed misses the other slabs'
!> share of it, half of it on two ranks.
!>
!> Tolerance: 1e-12 of the largest entry: the same sums in another order (the distributed
!> transforms, the ranks' shares added after their rows; Gram-Schmidt's products taken
!> before, not between, the subtractions, the same in exact arithmetic for orthonormal
!> images, apart by a few roundings of the products here).
program test_multigrid_slabs
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_grid, only: surface_grid
   use lc_base_parallel, only: parallel_start, parallel_end, this_rank
   use lc_contact_operator, only: compliance_operator
   use lc_contact_multigrid_hierarchy, only: hierarchy, build_hierarchy, set_grid, set_contact, precondition, &
      & apply_stiffness, interpolate, interpolate_onto_slab
   use lc_contact_solver_multigrid, only: orthogonalise, orthogonalise_over_ranks
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_identity = 1.0e-12_wp
   real(wp), parameter :: pi = acos(-1.0_wp)
   integer, parameter :: nx = 32, ny = 32
   type(error_type), allocatable :: error

   call parallel_start(error)
   if (allocated(error)) error stop 2
   call check_slabs('real symbol, Jacobi steps', .false., .false.)
   call check_slabs('complex symbol, Jacobi steps', .true., .false.)
   call check_slabs('complex symbol, smoothed by rows', .true., .true.)
   call check_orthogonalisation()
   call finish('multigrid on slabs (rank ' // achar(iachar('0') + this_rank()) // ')')
   call parallel_end()

contains

   !> The symbol K = |q| (1 + 0.4 i sin(2 pi kx/nx) if complex), about 30 % of the points in
   !> contact; the checks of the program's header.
   subroutine check_slabs(what, complex_symbol, rows)
      character(len=*), intent(in) :: what
      logical, intent(in) :: complex_symbol, rows
      type(compliance_operator), target :: whole, slab
      type(hierarchy), target :: hw, hs
      real(wp), allocatable :: symbol(:), odd(:), free(:), r(:), zw(:), zs(:), yw(:), ys(:), uc(:), uw(:), us(:)
      integer :: kx, ky, sy, nkx, i, first, last
      real(wp) :: dot_whole, dot_slab

      nkx = nx/2 + 1
      allocate (symbol(nkx*ny), odd(nkx*ny))
      do ky = 0, ny - 1
         sy = merge(ky, ky - ny, 2*ky <= ny)
         do kx = 0, nx/2
            symbol(kx + nkx*ky + 1) = hypot(real(kx, wp), real(sy, wp))
            odd(kx + nkx*ky + 1) = 0.0_wp
            if (complex_symbol .and. 2*kx /= nx) odd(kx + nkx*ky + 1) = 0.4_wp*symbol(kx + nkx*ky + 1)*sin(2*pi*kx/nx)
         end do
      end do
      if (.not. (planned(what, whole, .false.) .and. planned(what, slab, .true.))) return
      call build(hw, whole, symbol, odd, complex_symbol, rows)
      call build(hs, slab, symbol, odd, complex_symbol, rows)
      if (allocated(error)) then
         call check(.false., what // ': ' // error%message)
         return
      end if
      first = nx*slab%fft%y_start + 1
      last = nx*(slab%fft%y_start + slab%fft%ny_local)
      free = [(merge(0.0_wp, 1.0_wp, mod(i*7919, 10) < 3), i = 1, nx*ny)]
      hw%free(1:nx*ny) = free
      hs%free(1:last - first + 1) = free(first:last)
      call set_contact(hw)
      call set_contact(hs)

      r = [(free(i)*(sin(1.3_wp*i) + 0.5_wp*cos(0.7_wp*i*i)), i = 1, nx*ny)]
      allocate (zw(nx*ny), zs(last - first + 1))
      zw = 0.0_wp
      zs = 0.0_wp
      call precondition(hw, r, zw)
      call precondition(hs, r(first:last), zs)
      call check(maxval(abs(zs - zw(first:last))) <= tol_identity*maxval(abs(zw)), &
         & what // ': B r on the slab is the whole grid''s')

      allocate (yw(nx*ny), ys(last - first + 1))
      call apply_stiffness(hw, r, yw, xy=dot_whole)
      call apply_stiffness(hs, r(first:last), ys, xy=dot_slab)
      call check(maxval(abs(ys - yw(first:last))) <= tol_identity*maxval(abs(yw)) .and. &
         & abs(dot_slab - dot_whole) <= tol_identity*abs(dot_whole), what // ': K x and x.K x are the whole grid''s')

      if (rows) return
      ! (the nested iteration's grids: both axes halved)
      associate (c => hw%level(1))
      uc = [(sin(0.9_wp*i) + cos(0.31_wp*i*i), i = 1, c%n)]
      end associate
      allocate (uw(nx*ny), us(last - first + 1))
      call interpolate(hw, 0, uc, uw)
      call interpolate_onto_slab(hs, uc, us)
      call check(maxval(abs(us - uw(first:last))) <= tol_identity*maxval(abs(uw)), &
         & what // ': the interpolation onto the slab is the whole grid''s')
   end subroutine check_slabs

   !> The GCR's orthogonalisation on the slabs against the whole grid's (see the header): four
   !> stored images made orthonormal on the free points (about 70 % of them) by the whole
   !> grid's Gram-Schmidt, then a direction z and its image kz orthogonalised against them.
   subroutine check_orthogonalisation()
      integer, parameter :: stored = 4
      type(compliance_operator) :: slab
      real(wp), allocatable :: free(:), dirs(:, :), kdirs(:, :), zw(:), kzw(:), zs(:), kzs(:)
      real(wp) :: norm, leftover
      integer :: i, k, first, last
      if (.not. planned('orthogonalisation', slab, .true.)) return
      first = nx*slab%fft%y_start + 1
      last = nx*(slab%fft%y_start + slab%fft%ny_local)
      free = [(merge(0.0_wp, 1.0_wp, mod(i*7919, 10) < 3), i = 1, nx*ny)]
      allocate (dirs(nx*ny, stored), kdirs(nx*ny, stored))
      do k = 1, stored
         dirs(:, k) = [(sin(0.37_wp*k*i) + 0.2_wp*k, i = 1, nx*ny)]
         kdirs(:, k) = [(cos(0.53_wp*k*i + 0.1_wp*i*i) + 0.1_wp*k, i = 1, nx*ny)]
         call orthogonalise(dirs(:, k), kdirs(:, k), dirs(:, :k - 1), kdirs(:, :k - 1), free)
         norm = sqrt(sum(free*kdirs(:, k)**2))
         dirs(:, k) = dirs(:, k)/norm
         kdirs(:, k) = kdirs(:, k)/norm
      end do
      zw = [(sin(1.7_wp*i) + 0.3_wp, i = 1, nx*ny)]
      kzw = [(cos(0.29_wp*i*i) + 0.5_wp*sin(0.11_wp*i) + 0.4_wp, i = 1, nx*ny)]
      zs = zw(first:last)
      kzs = kzw(first:last)
      call orthogonalise(zw, kzw, dirs, kdirs, free)
      call orthogonalise_over_ranks(zs, kzs, dirs(first:last, :), kdirs(first:last, :), free(first:last))
      call check(maxval(abs(kzs - kzw(first:last))) <= tol_identity*maxval(abs(kzw)) .and. &
         & maxval(abs(zs - zw(first:last))) <= tol_identity*maxval(abs(zw)), &
         & 'the GCR''s orthogonalisation on the slab (one message) is the whole grid''s Gram-Schmidt')
      ! (and what is left is orthogonal to the stored images on the free points)
      leftover = 0.0_wp
      do k = 1, stored
         leftover = max(leftover, abs(sum(free*kzw*kdirs(:, k))))
      end do
      call check(leftover <= tol_identity*sqrt(sum(free*kzw**2)), &
         & 'the image orthogonalised on the whole grid is orthogonal to the stored ones', leftover)
   end subroutine check_orthogonalisation

   !> h for op with the symbol (+ i odd where complex_symbol), smoothed by rows if `rows`.
   subroutine build(h, op, symbol, odd, complex_symbol, rows)
      type(hierarchy), intent(out), target :: h
      type(compliance_operator), intent(inout), target :: op
      real(wp), contiguous, intent(in) :: symbol(:), odd(:)
      logical, intent(in) :: complex_symbol, rows
      if (allocated(error)) return
      if (complex_symbol) then
         call build_hierarchy(h, op, error, symbol, odd, rows=rows)
         if (.not. allocated(error)) call set_grid(h, 0, symbol, odd)
      else
         call build_hierarchy(h, op, error, symbol, rows=rows)
         if (.not. allocated(error)) call set_grid(h, 0, symbol)
      end if
   end subroutine build

   !> op on the whole grid (a serial plan) or on this rank's slab (distributed)
   logical function planned(what, op, distributed)
      character(len=*), intent(in) :: what
      type(compliance_operator), intent(inout) :: op
      logical, intent(in) :: distributed
      op%grid = surface_grid(nx, ny, 1.0_wp, 1.0_wp)
      call op%fft%init(nx, ny, 1, error, distributed=distributed)
      planned = .not. allocated(error)
      if (.not. planned) then
         call check(.false., what // ': ' // error%message)
         return
      end if
      op%distributed = op%fft%distributed
      op%n = op%fft%n
      op%nk = op%fft%nk
   end function planned
end program test_multigrid_slabs
