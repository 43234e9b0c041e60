!> Tests of lc_greens_layer (layer multipliers 1-A, 1-B, c of convention P, docs/theory.md):
!> limits, continuity at the branch switches, closed form against the LAPACK mode solver,
!> reciprocity and sign checks, and the mpmath table tests/data/kernel_reference.txt
!> (path as first argument). Prints one line per check; error stop 1 on any failure.
program test_greens_layer
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_positive_inf
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, code_input
   use lc_greens_layer, only: layer_coefficients, halfspace_coupling, layer_coefficients_lapack, &
      layer_mode_response, x_series, x_large, lapack_x_min, lapack_x_max
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   !> Identities and exact limits: a few rounding errors.
   real(wp), parameter :: tol_identity = 100*epsilon(1.0_wp)
   !> Closed form against mpmath and across a branch switch: "full double precision".
   real(wp), parameter :: tol_reference = 1.0e-13_wp
   !> Closed form against the LAPACK mode solve for x_h >= 1e-2. Below, the potentials'
   !> cancellation costs digits like eps/x_h^2 (measured), so the tolerance grows as (1e-2/x_h)^2.
   real(wp), parameter :: tol_lapack = 1.0e-10_wp
   !> Leading-order small-x asymptotics at x = 1e-7: relative corrections are O(x^2/(1-2nu))
   !> for 1-A (1.7e-12 at nu = 0.499), O(x^2) otherwise.
   real(wp), parameter :: tol_asymptotic = 1.0e-10_wp
   real(wp), parameter :: nus(*) = [-0.999_wp, -0.9_wp, -0.5_wp, 0.0_wp, 0.1_wp, 0.25_wp, 0.3_wp, 0.45_wp, &
                                    0.49_wp, 0.499_wp, 0.5_wp]

   call check_limits()
   call check_invalid_input()
   call check_switch_continuity()
   call check_lapack()
   call check_reference_table()
   call finish('layer compliance')

contains

   pure real(wp) function rel(a, b, floor)
      real(wp), intent(in) :: a, b, floor
      rel = abs(a - b)/max(abs(b), floor)
   end function rel

   subroutine check_limits()
      real(wp) :: a, b, c, x, nu, worst, inf, beta
      logical :: ok
      integer :: i

      ! x = 0: no layer, no compliance (all numerators vanish exactly).
      worst = 0
      do i = 1, size(nus)
         call layer_coefficients(0.0_wp, nus(i), a, b, c)
         worst = max(worst, abs(a), abs(b), abs(c))
      end do
      call check(worst <= 0.0_wp, 'x = 0 gives 1-A = 1-B = c = 0', worst)

      ! x -> inf (1e6 and +inf): half-space, c = Dundurs' beta.
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      worst = 0
      ok = .true.
      do i = 1, size(nus)
         beta = halfspace_coupling(nus(i))
         call layer_coefficients(1.0e6_wp, nus(i), a, b, c)
         worst = max(worst, abs(a - 1), abs(b - 1), abs(c - beta))
         call layer_coefficients(inf, nus(i), a, b, c)
         worst = max(worst, abs(a - 1), abs(b - 1), abs(c - beta))
         ok = ok .and. .not. ieee_is_nan(c)
      end do
      call check(ok .and. worst <= tol_identity, 'x = 1e6, +inf give the half-space (1, 1, beta)', worst)

      ! Half-space sign check 1: beta > 0 for nu < 0.5 (surface moves toward a compressive
      ! line load), 0 at nu = 0.5.
      ok = halfspace_coupling(0.3_wp) > 0 .and. abs(halfspace_coupling(0.5_wp)) <= 0.0_wp &
           .and. abs(halfspace_coupling(0.0_wp) - 0.5_wp) <= tol_identity
      call check(ok, 'half-space beta: +0.5 at nu=0, > 0 for nu<0.5, 0 at nu=0.5')

      ! Small x: 1-A ~ (1-2nu) x/(2(1-nu)^2) (constrained modulus, nu < 0.5) or (2/3) x^3
      ! (nu = 0.5), 1-B ~ x/(1-nu), c ~ x^2 (1-4nu)/(4(1-nu)^2) (c ~ -x^2 at nu = 0.5).
      x = 1.0e-7_wp
      worst = 0
      do i = 1, size(nus)
         nu = nus(i)
         call layer_coefficients(x, nu, a, b, c)
         if (nu < 0.5_wp) then
            worst = max(worst, rel(a, (1 - 2*nu)*x/(2*(1 - nu)**2), tiny(1.0_wp)))
         else
            worst = max(worst, rel(a, 2*x**3/3, tiny(1.0_wp)))
         end if
         worst = max(worst, rel(b, x/(1 - nu), tiny(1.0_wp)))
         if (abs(1 - 4*nu) > 0.01_wp) worst = max(worst, rel(c, x**2*(1 - 4*nu)/(4*(1 - nu)**2), tiny(1.0_wp)))
      end do
      call check(worst <= tol_asymptotic, 'small-x asymptotics at x = 1e-7', worst)
      call layer_coefficients(x, 0.5_wp, a, b, c)
      call check(c < 0, 'sign check 2: thin incompressible layer has c ~ -x^2 < 0', rel(c, -x**2, tiny(1.0_wp)))
   end subroutine check_limits

   subroutine check_invalid_input()
      real(wp) :: a, b, c
      logical :: ok
      type(error_type), allocatable :: error

      call layer_coefficients(1.0_wp, -1.0_wp, a, b, c)
      ok = ieee_is_nan(a) .and. ieee_is_nan(b) .and. ieee_is_nan(c)
      call layer_coefficients(1.0_wp, 0.6_wp, a, b, c)
      ok = ok .and. ieee_is_nan(c)
      call layer_coefficients(-1.0_wp, 0.3_wp, a, b, c)
      ok = ok .and. ieee_is_nan(a)
      call check(ok, 'invalid x or nu give NaN')

      call layer_coefficients_lapack(0.5_wp*lapack_x_min, 0.3_wp, a, b, c, error)
      ok = allocated(error)
      if (ok) ok = error%code == code_input
      call layer_coefficients_lapack(2*lapack_x_max, 0.3_wp, a, b, c, error)
      if (ok) ok = allocated(error)
      if (ok) ok = error%code == code_input
      call layer_coefficients_lapack(1.0_wp, 0.7_wp, a, b, c, error)
      if (ok) ok = allocated(error)
      call check(ok, 'LAPACK solver rejects x_h or nu outside its range (code_input)')
   end subroutine check_invalid_input

   subroutine check_switch_continuity()
      real(wp), parameter :: switches(*) = [0.5_wp*x_series, x_series, x_large]
      real(wp) :: v(3, -1:1), x, worst, scale_c
      integer :: i, j, side

      worst = 0
      do j = 1, size(switches)
         do i = 1, size(nus)
            do side = -1, 1
               x = switches(j)
               if (side == -1) x = nearest(x, -1.0_wp)
               if (side == 1) x = nearest(x, 1.0_wp)
               call layer_coefficients(x, nus(i), v(1, side), v(2, side), v(3, side))
            end do
            ! c crosses zero near x = 1 for nu = 0.3: judge its jump against the 2x2
            ! compliance [[1-A, -ic], [ic, 1-B]] rather than against c alone.
            scale_c = max(abs(v(3, 0)), sqrt(v(1, 0)*v(2, 0)))
            worst = max(worst, rel(v(1, -1), v(1, 1), tiny(1.0_wp)), rel(v(2, -1), v(2, 1), tiny(1.0_wp)), &
                        abs(v(3, -1) - v(3, 1))/scale_c)
         end do
      end do
      call check(worst <= tol_reference, 'continuity across switches x = 1, 2, 20 (one ulp either side)', worst)
   end subroutine check_switch_continuity

   subroutine check_lapack()
      real(wp), parameter :: lapack_nus(*) = [0.5_wp, 0.49_wp, 0.3_wp, 0.0_wp, -0.5_wp, -0.9_wp]
      integer, parameter :: n_x = 61
      real(wp) :: x, a, b, c, al, bl, cl, worst_a, worst_b, worst_c, worst_recip, worst_imag, tol, scale_c
      complex(wp) :: w_p, ux_p, w_tau, ux_tau
      type(error_type), allocatable :: error
      logical :: ok, signs
      integer :: i, j

      worst_a = 0
      worst_b = 0
      worst_c = 0
      worst_recip = 0
      worst_imag = 0
      ok = .true.
      do j = 1, size(lapack_nus)
         do i = 0, n_x - 1
            x = lapack_x_min*(lapack_x_max/lapack_x_min)**(real(i, wp)/(n_x - 1))
            x = min(max(x, lapack_x_min), lapack_x_max)
            tol = tol_lapack*max(1.0_wp, (1.0e-2_wp/x)**2)
            call layer_coefficients(x, lapack_nus(j), a, b, c)
            call layer_coefficients_lapack(x, lapack_nus(j), al, bl, cl, error)
            if (allocated(error)) then
               print '(a, a)', 'error: ', error%message
               ok = .false.
               cycle
            end if
            call layer_mode_response(x, lapack_nus(j), w_p, ux_p, w_tau, ux_tau, error)
            scale_c = max(abs(c), sqrt(a*b))
            worst_a = max(worst_a, rel(al, a, tiny(1.0_wp))/tol)
            worst_b = max(worst_b, rel(bl, b, tiny(1.0_wp))/tol)
            worst_c = max(worst_c, abs(cl - c)/scale_c/tol)
            ! Reciprocity (sign check 3): d u_x/d p = - d w/d tau, mode by mode.
            worst_recip = max(worst_recip, abs(ux_p + w_tau)/scale_c/tol)
            ! Convention P: direct terms real, coupling terms purely imaginary.
            worst_imag = max(worst_imag, abs(aimag(w_p))/a/tol, abs(aimag(ux_tau))/b/tol, &
                             abs(real(ux_p, wp))/scale_c/tol, abs(real(w_tau, wp))/scale_c/tol)
         end do
      end do
      print '(a, es9.2, a, es9.2, a)', '      (LAPACK range [', lapack_x_min, ', ', lapack_x_max, &
         '], errors in units of tol = 1e-10*max(1, (1e-2/x)^2))'
      call check(ok .and. worst_a <= 1, 'closed form vs LAPACK: 1-A', worst_a*tol_lapack)
      call check(ok .and. worst_b <= 1, 'closed form vs LAPACK: 1-B', worst_b*tol_lapack)
      call check(ok .and. worst_c <= 1, 'closed form vs LAPACK: c (same sign convention)', worst_c*tol_lapack)
      call check(ok .and. worst_recip <= 1, 'reciprocity d u_x/d p = -d w/d tau (LAPACK)', worst_recip*tol_lapack)
      call check(ok .and. worst_imag <= 1, 'direct terms real, coupling imaginary (LAPACK)', worst_imag*tol_lapack)

      ! Sign checks from the independent solve: thick compressible layer c > 0 (beta),
      ! thin incompressible layer c < 0, direct compliances positive.
      call layer_coefficients_lapack(lapack_x_max, 0.3_wp, al, bl, cl, error)
      signs = .not. allocated(error) .and. cl > 0 .and. abs(cl - halfspace_coupling(0.3_wp)) <= 1.0e-12_wp
      call layer_coefficients_lapack(0.01_wp, 0.5_wp, al, bl, cl, error)
      signs = signs .and. .not. allocated(error) .and. cl < 0 .and. al > 0 .and. bl > 0
      call check(signs, 'LAPACK signs: c -> +beta (x=20, nu=0.3), c < 0 (x=0.01, nu=0.5)')
   end subroutine check_lapack

   subroutine check_reference_table()
      character(len=512) :: path, line, message
      real(wp) :: x, nu, ref(3), val(3), err, worst(3), worst_x(3), worst_nu(3)
      integer :: unit, ios, n, q
      character(len=*), parameter :: names(3) = ['1-A', '1-B', 'c  ']

      path = 'tests/data/kernel_reference.txt'
      if (command_argument_count() >= 1) call get_command_argument(1, path)
      open (newunit=unit, file=trim(path), status='old', action='read', iostat=ios, iomsg=message)
      if (ios /= 0) then
         call check(.false., 'mpmath table: open '//trim(path)//': '//trim(message))
         return
      end if
      worst = 0
      worst_x = 0
      worst_nu = 0
      n = 0
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (len_trim(line) == 0 .or. line(1:1) == '#') cycle
         read (line, *, iostat=ios) x, nu, ref
         if (ios /= 0) then
            call check(.false., 'mpmath table: unreadable line: '//trim(line))
            cycle
         end if
         n = n + 1
         call layer_coefficients(x, nu, val(1), val(2), val(3))
         do q = 1, 3
            if (q < 3) then
               err = rel(val(q), ref(q), 1.0e-300_wp)
            else
               err = rel(val(q), ref(q), tiny(1.0_wp))
            end if
            if (.not. (err <= worst(q))) then
               worst(q) = err
               worst_x(q) = x
               worst_nu(q) = nu
            end if
         end do
      end do
      close (unit)
      print '(a, i0, a, a)', '      (', n, ' rows of ', trim(path)//')'
      do q = 1, 3
         print '(a, a, a, es9.2, a, es9.2)', '      worst ', names(q), ' at x = ', worst_x(q), ', nu = ', worst_nu(q)
         call check(n > 0 .and. worst(q) <= tol_reference, 'mpmath table: '//trim(names(q)), worst(q))
      end do
   end subroutine check_reference_table
end program test_greens_layer
