!> Tests of the multigrid hierarchy's coarse operators (lc_contact_multigrid_hierarchy): on
!> every coarse grid t the operator A_t (Galerkin circulant plus penalty stencil) applied to
!> a field equals P^T A_(t-1) P applied to it, with P the linear interpolation written out
!> here; A_0 is the circulant of the stiffness plus the penalty d D_A on the contact set.
!> Real and complex (odd imaginary part) symbols, on a line and on surfaces whose grids are
!> halved along both axes or along one (an anisotropic symbol). And the row smoothing's solve
!> (solve_rows): for a field on one row, its result x lies on that row and (C + s) x = r
!> there, C the grid's circulant and s the row's shift. One line per check; exit 0 on pass,
!> error stop 1 on failure.
!>
!> Tolerance: tol_identity = 1e-12 of the largest entry: the two sides are the same sums in
!> another order (transforms of a few hundred points against explicit stencils).
program test_multigrid_hierarchy
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_grid, only: line_grid, surface_grid
   use lc_contact_operator, only: compliance_operator
   use lc_contact_multigrid_hierarchy, only: hierarchy, build_hierarchy, set_grid, set_contact, level_operator, &
      & penalty, solve_rows, worst_row_smoothing
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   real(wp), parameter :: tol_identity = 1.0e-12_wp
   real(wp), parameter :: pi = acos(-1.0_wp)

   ! (expected: how each grid is made of the one before, 'b' both axes halved, 'x', 'y')
   call check_galerkin('line, real symbol', 512, 1, 1.0_wp, 1.0_wp, .false., 'xxx')
   call check_galerkin('line, complex symbol', 512, 1, 1.0_wp, 1.0_wp, .true., 'xxx')
   call check_galerkin('isotropic surface, real symbol', 32, 32, 1.0_wp, 1.0_wp, .false., 'bb')
   call check_galerkin('isotropic surface, complex symbol', 32, 32, 1.0_wp, 1.0_wp, .true., 'bb')
   call check_galerkin('surface stiff along x, complex symbol', 32, 32, 10.0_wp, 1.0_wp, .true., 'xxb')
   call check_galerkin('surface stiff along y, complex symbol', 32, 16, 1.0_wp, 10.0_wp, .true., 'yb')
   call check_rows('rows, real symbol', 32, 16, .false.)
   call check_rows('rows, complex symbol', 32, 16, .true.)
   call check_rows('rows, stiff across the rows, more rows than points along them', 16, 64, .true., 4.0_wp)
   call check_rows('rows, more than twice as many points along x as along y', 64, 16, .true.)
   call finish('multigrid hierarchy')

contains

   !> The hierarchy of the symbol K = sqrt((ax kx)^2 + (ay ky)^2) (1 + 0.4 i sin(2 pi kx/nx)
   !> if complex) on an nx x ny grid with about 30 % of the points in contact: its halvings
   !> as `expected`, and A_t = P^T A_(t-1) P on every coarse grid.
   subroutine check_galerkin(what, nx, ny, ax, ay, complex_symbol, expected)
      character(len=*), intent(in) :: what, expected
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: ax, ay
      logical, intent(in) :: complex_symbol
      type(compliance_operator), target :: op
      type(hierarchy), target :: h
      type(error_type), allocatable :: error
      real(wp), allocatable :: symbol(:), odd(:), xc(:), xf(:), af(:), reference(:), coarse(:)
      character(len=:), allocatable :: made
      integer :: kx, ky, sy, nkx, i, t
      real(wp) :: worst

      if (.not. planned(what, op, nx, ny)) return
      nkx = nx/2 + 1
      allocate (symbol(nkx*ny), odd(nkx*ny))
      do ky = 0, ny - 1
         sy = merge(ky, ky - ny, 2*ky <= ny)
         do kx = 0, nx/2
            symbol(kx + nkx*ky + 1) = hypot(ax*kx, ay*sy)
            odd(kx + nkx*ky + 1) = 0.0_wp
            if (complex_symbol .and. 2*kx /= nx) odd(kx + nkx*ky + 1) = 0.4_wp*symbol(kx + nkx*ky + 1)*sin(2*pi*kx/nx)
         end do
      end do
      if (complex_symbol) then
         call build_hierarchy(h, op, error, symbol, odd)
         if (.not. allocated(error)) call set_grid(h, 0, symbol, odd)
      else
         call build_hierarchy(h, op, error, symbol)
         if (.not. allocated(error)) call set_grid(h, 0, symbol)
      end if
      if (allocated(error)) then
         call check(.false., what // ': ' // error%message)
         return
      end if
      h%free = [(merge(0.0_wp, 1.0_wp, mod(i*7919, 10) < 3), i = 1, nx*ny)]
      call set_contact(h)

      made = ''
      do t = 0, h%coarsest - 1
         if (h%level(t)%halve_x .and. h%level(t)%halve_y) then
            made = made // 'b'
         else if (h%level(t)%halve_y) then
            made = made // 'y'
         else
            made = made // 'x'
         end if
      end do
      call check(made == expected, what // ': grids made by halving ' // made // ' (expected ' // expected // ')')

      worst = 0.0_wp
      do t = 1, h%coarsest
         associate (f => h%level(t - 1), c => h%level(t))
         xc = [(sin(1.3_wp*i) + 0.5_wp*cos(0.7_wp*i*i), i = 1, c%n)]
         xf = interpolated(xc, c%nx, c%ny, f%halve_x, f%halve_y)
         allocate (af(f%n), coarse(c%n))
         call level_operator(h, t - 1, xf, af)
         if (t == 1) af = af + penalty*f%circulant_diagonal*(1.0_wp - h%free)*xf
         reference = restricted(af, f%nx, f%ny, f%halve_x, f%halve_y)
         call level_operator(h, t, xc, coarse)
         worst = max(worst, maxval(abs(coarse - reference))/maxval(abs(reference)))
         deallocate (af, coarse)
         end associate
      end do
      call check(worst <= tol_identity, what // ': A_t = P^T A_(t-1) P on every coarse grid')
   end subroutine check_galerkin

   !> A sliding layer's symbol K = E(kx) |q|, E(kx) = (1 + 100 i kx/nx)/(1 + i kx/nx) (a
   !> standard linear solid, E_inf/E0 = 100; |E| if not complex) on an nx x ny
   !> surface smoothed by rows: its grids halved along both axes, the rows' smoothing factor
   !> that of K ~ |q| (E cancels in K/K_row: 0.55 at most). With `stretch` the symbol is
   !> E(kx) |(kx, stretch ky)|, stiffer across the rows, on a grid with more rows than points
   !> along them: halving both axes would leave the row step its short waves along x at low
   !> ky, barely damped (factor 0.8), so the grids are halved along y alone until square
   !> (row_shapes). A grid with more than twice as many points along x as along y is halved
   !> along x alone until square. And on every grid, for a field r
   !> on one row j, x = (C + s)^-1 r row by row lies on row j with (C x + s x) = r there,
   !> with the shift s = 0 and s = 3 d.
   subroutine check_rows(what, nx, ny, complex_symbol, stretch)
      character(len=*), intent(in) :: what
      integer, intent(in) :: nx, ny
      logical, intent(in) :: complex_symbol
      real(wp), intent(in), optional :: stretch
      type(compliance_operator), target :: op
      type(hierarchy), target :: h
      type(error_type), allocatable :: error
      real(wp), allocatable :: symbol(:), odd(:), r(:), x(:), cx(:)
      complex(wp) :: modulus
      integer :: kx, ky, sy, nkx, i, t, row, attempt
      real(wp) :: worst, off_row, shift, q
      logical :: full

      if (.not. planned(what, op, nx, ny)) return
      nkx = nx/2 + 1
      allocate (symbol(nkx*ny), odd(nkx*ny))
      do ky = 0, ny - 1
         sy = merge(ky, ky - ny, 2*ky <= ny)
         do kx = 0, nx/2
            modulus = (1.0_wp + (0.0_wp, 100.0_wp)*kx/nx)*(1.0_wp - (0.0_wp, 1.0_wp)*kx/nx)/(1.0_wp + (real(kx, wp)/nx)**2)
            if (2*kx == nx .or. .not. complex_symbol) modulus = abs(modulus)
            q = hypot(real(kx, wp), real(sy, wp))
            if (present(stretch)) q = hypot(real(kx, wp), stretch*sy)
            symbol(kx + nkx*ky + 1) = real(modulus)*q
            odd(kx + nkx*ky + 1) = aimag(modulus)*q
         end do
      end do
      if (complex_symbol) then
         call build_hierarchy(h, op, error, symbol, odd, rows=.true.)
         if (.not. allocated(error)) call set_grid(h, 0, symbol, odd)
         worst = worst_row_smoothing(nx, ny, symbol, odd)
      else
         call build_hierarchy(h, op, error, symbol, rows=.true.)
         if (.not. allocated(error)) call set_grid(h, 0, symbol)
         worst = worst_row_smoothing(nx, ny, symbol)
      end if
      if (allocated(error)) then
         call check(.false., what // ': ' // error%message)
         return
      end if
      if (present(stretch)) then
         full = all([(h%level(t)%halve_y .and. (h%level(t)%halve_x .eqv. h%level(t)%ny <= h%level(t)%nx), &
            & t = 0, h%coarsest - 1)])
         call check(full, what // ': grids halved along y alone until square, then along both axes')
      else if (nx > 2*ny) then
         call check(worst <= 0.55_wp, what // ': smoothing factor ' // trim(adjustl(fmt(worst))) // ' (at most 0.55)')
         full = all([(h%level(t)%halve_x .and. (h%level(t)%halve_y .eqv. h%level(t)%nx <= h%level(t)%ny), &
            & t = 0, h%coarsest - 1)])
         call check(full, what // ': grids halved along x alone until square, then along both axes')
      else
         call check(worst <= 0.55_wp, what // ': smoothing factor ' // trim(adjustl(fmt(worst))) // ' (at most 0.55)')
         full = all([(h%level(t)%halve_x .and. h%level(t)%halve_y, t = 0, h%coarsest - 1)])
         call check(full, what // ': every grid halved along both axes')
      end if
      h%free = 1.0_wp
      call set_contact(h)

      worst = 0.0_wp
      off_row = 0.0_wp
      do t = 0, h%coarsest - 1
         associate (lv => h%level(t))
         row = lv%ny/2
         allocate (r(lv%n), cx(lv%n))
         do attempt = 1, 2
            shift = merge(0.0_wp, 3*lv%circulant_diagonal, attempt == 1)
            lv%row_shift = 0.0_wp
            lv%row_shift(row + 1) = shift
            r = 0.0_wp
            r(row*lv%nx + 1:(row + 1)*lv%nx) = [(sin(1.3_wp*i) + 0.5_wp*cos(0.7_wp*i*i), i = 1, lv%nx)]
            call solve_rows(h, t, r)
            x = lv%fft%real_buffer
            call level_operator(h, t, x, cx)
            cx = cx + shift*x
            worst = max(worst, maxval(abs(cx(row*lv%nx + 1:(row + 1)*lv%nx) - r(row*lv%nx + 1:(row + 1)*lv%nx))) &
               & /maxval(abs(r)))
            off_row = max(off_row, maxval(abs(x(:row*lv%nx))), maxval(abs(x((row + 1)*lv%nx + 1:))))
         end do
         deallocate (r, cx)
         end associate
      end do
      call check(off_row == 0.0_wp, what // ': the row solve stays on its row')
      call check(worst <= tol_identity, what // ': (C + s) x = r on the row, every grid')
   end subroutine check_rows

   !> op on a line (ny = 1) or surface of unit period with its plans; false (a failed
   !> check) if FFTW could not plan it.
   logical function planned(what, op, nx, ny)
      character(len=*), intent(in) :: what
      type(compliance_operator), intent(inout) :: op
      integer, intent(in) :: nx, ny
      type(error_type), allocatable :: error
      if (ny == 1) then
         op%grid = line_grid(nx, 1.0_wp)
      else
         op%grid = surface_grid(nx, ny, 1.0_wp, 1.0_wp)
      end if
      call op%fft%init(nx, ny, 1, error)
      planned = .not. allocated(error)
      if (.not. planned) call check(.false., what // ': ' // error%message)
   end function planned

   pure function fmt(x) result(text)
      real(wp), intent(in) :: x
      character(len=12) :: text
      write (text, '(f8.4)') x
   end function fmt

   !> P x: x (mx x my) interpolated linearly (periodic) along the axes halved.
   pure function interpolated(x, mx, my, along_x, along_y) result(fine)
      real(wp), intent(in) :: x(:)
      integer, intent(in) :: mx, my
      logical, intent(in) :: along_x, along_y
      real(wp), allocatable :: fine(:)
      real(wp), allocatable :: a(:, :), b(:, :)
      integer :: i, j
      a = reshape(x, [mx, my])
      if (along_x) then
         allocate (b(2*mx, my))
         do i = 0, mx - 1
            b(2*i + 1, :) = a(i + 1, :)
            b(2*i + 2, :) = 0.5_wp*(a(i + 1, :) + a(mod(i + 1, mx) + 1, :))
         end do
         a = b
         deallocate (b)
      end if
      if (along_y) then
         allocate (b(size(a, 1), 2*my))
         do j = 0, my - 1
            b(:, 2*j + 1) = a(:, j + 1)
            b(:, 2*j + 2) = 0.5_wp*(a(:, j + 1) + a(:, mod(j + 1, my) + 1))
         end do
         a = b
      end if
      fine = reshape(a, [size(a)])
   end function interpolated

   !> P^T y: y (nx x ny) restricted along the axes halved (the transpose of interpolated).
   pure function restricted(y, nx, ny, along_x, along_y) result(coarse)
      real(wp), intent(in) :: y(:)
      integer, intent(in) :: nx, ny
      logical, intent(in) :: along_x, along_y
      real(wp), allocatable :: coarse(:)
      real(wp), allocatable :: a(:, :), b(:, :)
      integer :: i, j, m
      a = reshape(y, [nx, ny])
      if (along_x) then
         m = nx/2
         allocate (b(m, ny))
         do i = 0, m - 1
            b(i + 1, :) = a(2*i + 1, :) + 0.5_wp*(a(2*i + 2, :) + a(modulo(2*i - 1, nx) + 1, :))
         end do
         a = b
         deallocate (b)
      end if
      if (along_y) then
         m = ny/2
         allocate (b(size(a, 1), m))
         do j = 0, m - 1
            b(:, j + 1) = a(:, 2*j + 1) + 0.5_wp*(a(:, 2*j + 2) + a(:, modulo(2*j - 1, ny) + 1))
         end do
         a = b
      end if
      coarse = reshape(a, [size(a)])
   end function restricted
end program test_multigrid_hierarchy
