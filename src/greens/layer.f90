!> Fourier multipliers of an elastic layer bonded to a rigid base: `1-A`, `1-B` and `c`
!> of Eqs. (7)-(9) of the seed paper (Menga, Carbone, Mueller, Mueser), written in the
!> sign convention "convention P" of docs/theory.md:
!>
!>    w^(k)   = 2/(E*|k|) [ (1-A) p^(k)      - i sgn(k) c tau^(k) ]
!>    u_x^(k) = 2/(E*|k|) [ i sgn(k) c p^(k) + (1-B) tau^(k)      ]
!>
!> with x_h = |k| h, `z` into the layer, `w = u_z > 0` indentation, `p > 0` compressive and
!> `tau` the shear traction on the layer along `+x`. With kappa = 3 - 4 nu,
!> D = kappa cosh(2x) + 2x^2 + (1 + kappa^2)/2:
!>
!>    1-A = (kappa sinh 2x - 2x)/D,  1-B = (kappa sinh 2x + 2x)/D,
!>    c = ((1-2nu) - C)/(2(1-nu)),   C = 4(1-nu)(2 + x^2 - 6nu + 4nu^2)/D.
!>
!> `layer_coefficients` evaluates these in forms without cancellation or overflow (see
!> the comments there); `layer_coefficients_lapack` recomputes them independently from
!> the plane-strain boundary-value problem of one Fourier mode, as a test oracle.
module lc_greens_layer
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   implicit none (type, external)
   private
   public :: layer_coefficients, halfspace_coupling
   public :: layer_coefficients_lapack, layer_mode_response, mode_field_rows
   public :: x_series, x_large, lapack_x_min, lapack_x_max

   !> Below this argument y, sinh(y) - y is summed as a series: the direct difference
   !> loses log10(6/y^2) digits, and at y = 2 the series needs only 12 terms.
   !> Switch points of `layer_coefficients`: x = x_series/2 (for 1-A) and x = x_series (for c).
   real(wp), parameter :: x_series = 2.0_wp
   !> Above this x_h, `layer_coefficients` divides numerator and denominator by
   !> exp(2 x_h)/2: cosh(2 x_h) would overflow past x_h ~ 355, and at x_h = 20 both forms
   !> are free of cancellation.
   real(wp), parameter :: x_large = 20.0_wp
   !> Range of x_h accepted by the mode solver: the Papkovich-Neuber potentials stay O(1)
   !> while the surface displacements are O(x_h) (1-A is O(x_h^3) at nu = 0.5), so digits
   !> are lost like eps/x_h^2; above x_h = 20 the layer is a half-space and needs no check
   !> (its accuracy against the closed forms: docs/numerics.md, 'Constants of the solvers and
   !> their measurements').
   real(wp), parameter :: lapack_x_min = 1.0e-3_wp
   real(wp), parameter :: lapack_x_max = 20.0_wp
   !> x_h where the mode solver changes its harmonic basis from cosh/sinh to exponentials,
   !> each basis accurate on its side (docs/numerics.md, 'Constants of the solvers and their
   !> measurements').
   real(wp), parameter :: basis_switch = 1.0_wp

   interface
      !> LAPACK: solve A X = B by LU with partial pivoting (complex double).
      subroutine zgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: wp
         integer, intent(in) :: n, nrhs, lda, ldb
         complex(wp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine zgesv
   end interface

contains

   !> 1-A, 1-B and c of convention P for x = |k| h >= 0 and -1 < nu <= 0.5.
   !> Accurate to a few ulp for every such x (x = +inf gives the half-space); outside the
   !> domain the results are NaN, so a missing input check cannot go unnoticed.
   pure elemental subroutine layer_coefficients(x, nu, one_minus_a, one_minus_b, c)
      !> Dimensionless layer thickness x_h = |k| h.
      real(wp), intent(in) :: x
      !> Poisson ratio.
      real(wp), intent(in) :: nu
      !> Normal compliance factor 1-A (Eq. 7).
      real(wp), intent(out) :: one_minus_a
      !> Tangential compliance factor 1-B (Eq. 8).
      real(wp), intent(out) :: one_minus_b
      !> Normal-tangential coupling c (from Eq. 9), convention P sign.
      real(wp), intent(out) :: c
      real(wp) :: kappa, e, g, s, half_d, em, t, xt, x2t, td

      if (.not. (x >= 0.0_wp .and. nu > -1.0_wp .and. nu <= 0.5_wp)) then
         one_minus_a = ieee_value(1.0_wp, ieee_quiet_nan)
         one_minus_b = one_minus_a
         c = one_minus_a
         return
      end if
      kappa = 3.0_wp - 4.0_wp*nu
      ! e = 1-2nu and g = 1-nu are formed from nu directly (exact for nu >= 1/4), so that
      ! nu = 0.5 gives e = 0 exactly and no digits are lost near the incompressible limit.
      e = 1.0_wp - 2.0_wp*nu
      g = 1.0_wp - nu

      if (x <= x_large) then
         ! With cosh(2x) - 1 = 2 sinh^2 x and kappa + (1 + kappa^2)/2 = (1 + kappa)^2/2 = 8(1-nu)^2:
         ! D/2 = kappa sinh^2 x + x^2 + 4(1-nu)^2, a sum of non-negative terms.
         s = sinh(x)
         half_d = kappa*s*s + x*x + 4.0_wp*g*g
         ! kappa sinh 2x - 2x = kappa (sinh 2x - 2x) + 2(1-2nu) 2x: both terms >= 0.
         one_minus_a = (kappa*sinh_minus_identity(2.0_wp*x) + 4.0_wp*e*x)/(2.0_wp*half_d)
         one_minus_b = (kappa*sinh(2.0_wp*x) + 2.0_wp*x)/(2.0_wp*half_d)
         ! (1-2nu) D - 4(1-nu)(2 + x^2 - 6nu + 4nu^2) = 2[(1-2nu) kappa sinh^2 x - x^2], and
         ! (1-2nu) kappa - 1 = 2(1-nu)(1-4nu); sinh^2 x - x^2 = (sinh x - x)(sinh x + x).
         ! The two terms cancel only near the genuine zero of c (for 1/4 < nu < 1/2).
         c = (2.0_wp*g*(1.0_wp - 4.0_wp*nu)*x*x + e*kappa*sinh_minus_identity(x)*(s + x)) &
             /(2.0_wp*g*half_d)
      else
         ! Numerator and denominator times t = exp(-2x) <= exp(-40): no overflow, and the
         ! kappa terms dominate, so there is no cancellation except near a zero of c.
         ! Products are formed from exp(-x) (normal up to x ~ 708) rather than exp(-2x),
         ! which goes subnormal past x ~ 354 and would cost c its relative accuracy (for
         ! nu = 0.5, c = -x^2 exp(-2x)/td) long before c itself underflows. exp(-x) = 0
         ! (x > ~745, or x = +inf) must give 0, not inf*0 = NaN.
         em = exp(-x)
         t = em*em
         if (em > 0.0_wp) then
            xt = (x*em)*em
            x2t = (x*em)*(x*em)
         else
            xt = 0.0_wp
            x2t = 0.0_wp
         end if
         td = 0.5_wp*kappa*(1.0_wp - t)**2 + 2.0_wp*(x2t + 4.0_wp*g*g*t)
         one_minus_a = (0.5_wp*kappa*(1.0_wp - t)*(1.0_wp + t) - 2.0_wp*xt)/td
         one_minus_b = (0.5_wp*kappa*(1.0_wp - t)*(1.0_wp + t) + 2.0_wp*xt)/td
         c = (0.25_wp*e*kappa*(1.0_wp - t)**2 - x2t)/(g*td)
      end if
   end subroutine layer_coefficients

   !> Half-space limits (x -> inf): 1-A = 1-B = 1, c = (1-2nu)/(2(1-nu)) (Dundurs' beta for a rigid counterface).
   pure elemental real(wp) function halfspace_coupling(nu)
      !> Poisson ratio, -1 < nu <= 0.5.
      real(wp), intent(in) :: nu
      halfspace_coupling = (1.0_wp - 2.0_wp*nu)/(2.0_wp*(1.0_wp - nu))
   end function halfspace_coupling

   !> sinh(y) - y for y >= 0 without the cancellation of the direct difference at small y.
   pure elemental real(wp) function sinh_minus_identity(y) result(r)
      real(wp), intent(in) :: y
      real(wp) :: term, y2
      integer :: n

      if (y >= x_series) then
         r = sinh(y) - y
         return
      end if
      ! sum_{n>=1} y^(2n+1)/(2n+1)!: all terms positive, so the forward sum is accurate.
      y2 = y*y
      term = y*y2/6.0_wp
      r = term
      do n = 2, 30
         term = term*y2/real((2*n)*(2*n + 1), wp)
         if (term <= epsilon(1.0_wp)*0.25_wp*r) exit
         r = r + term
      end do
   end function sinh_minus_identity

   !> Independent check: the same three numbers from the 4x4 plane-strain boundary-value problem of one
   !> Fourier mode (layer 0<z<h, z into the layer, bonded to a rigid base at z=h, surface tractions p, tau
   !> at z=0), solved with LAPACK zgesv. Returns error if the solve fails.
   !> Valid for lapack_x_min <= x <= lapack_x_max (error with code_input outside). c is read
   !> from the normal load (d u_x/d p); `layer_mode_response` gives both off-diagonal terms.
   subroutine layer_coefficients_lapack(x, nu, one_minus_a, one_minus_b, c, error)
      !> Dimensionless layer thickness x_h = |k| h.
      real(wp), intent(in) :: x
      !> Poisson ratio, -1 < nu <= 0.5.
      real(wp), intent(in) :: nu
      !> Normal compliance factor 1-A.
      real(wp), intent(out) :: one_minus_a
      !> Tangential compliance factor 1-B.
      real(wp), intent(out) :: one_minus_b
      !> Coupling c, convention P sign.
      real(wp), intent(out) :: c
      !> Allocated on bad input or a failed solve.
      type(error_type), allocatable, intent(out) :: error
      complex(wp) :: w_p, ux_p, w_tau, ux_tau

      one_minus_a = 0.0_wp
      one_minus_b = 0.0_wp
      c = 0.0_wp
      call layer_mode_response(x, nu, w_p, ux_p, w_tau, ux_tau, error)
      if (allocated(error)) return
      ! Convention P for k > 0: w = (1-A) p - i c tau, u_x = i c p + (1-B) tau (units 2/(E*k)).
      one_minus_a = real(w_p, wp)
      one_minus_b = real(ux_tau, wp)
      c = aimag(ux_p)
   end subroutine layer_coefficients_lapack

   !> Surface displacements of one mode exp(i k x), k > 0, in units of 2/(E* k), for a unit
   !> normal pressure (w_p, ux_p) and for a unit shear traction along +x (w_tau, ux_tau),
   !> from the Papkovich-Neuber solution of the layer solved with LAPACK zgesv.
   subroutine layer_mode_response(x, nu, w_p, ux_p, w_tau, ux_tau, error)
      !> Dimensionless layer thickness x_h = |k| h, lapack_x_min <= x <= lapack_x_max.
      real(wp), intent(in) :: x
      !> Poisson ratio, -1 < nu <= 0.5.
      real(wp), intent(in) :: nu
      !> u_z and u_x at z = 0 for p = 1, tau = 0.
      complex(wp), intent(out) :: w_p, ux_p
      !> u_z and u_x at z = 0 for p = 0, tau = 1.
      complex(wp), intent(out) :: w_tau, ux_tau
      !> Allocated on bad input or a failed solve.
      type(error_type), allocatable, intent(out) :: error
      ! Rows of the field matrix: 2G u_x, 2G u_z, sigma_xz, sigma_zz.
      integer, parameter :: row_ux = 1, row_uz = 2, row_sxz = 3, row_szz = 4
      complex(wp) :: surface(4, 4), base(4, 4), a(4, 4), b(4, 2)
      real(wp) :: k, h, scale
      integer :: ipiv(4), info
      character(len=120) :: message

      w_p = (0.0_wp, 0.0_wp)
      ux_p = w_p
      w_tau = w_p
      ux_tau = w_p
      if (.not. (x >= lapack_x_min .and. x <= lapack_x_max)) then
         write (message, '(a, es10.3, a, es9.2, a, es9.2, a)') 'layer_mode_response: x_h = ', x, &
            ' outside [', lapack_x_min, ', ', lapack_x_max, '] where the mode solve is accurate'
         call fatal_error(error, trim(message), code_input)
         return
      end if
      if (.not. (nu > -1.0_wp .and. nu <= 0.5_wp)) then
         write (message, '(a, es10.3, a)') 'layer_mode_response: nu = ', nu, ' outside (-1, 0.5]'
         call fatal_error(error, trim(message), code_input)
         return
      end if
      ! Wavenumber 1 and thickness x: only x_h = |k| h enters (units 2/(E* k) below).
      k = 1.0_wp
      h = x
      surface = mode_field_rows(k, h, nu, 0.0_wp)
      base = mode_field_rows(k, h, nu, h)
      ! Traction ON the layer at z = 0, where the outward normal is -e_z: t = -sigma . e_z,
      ! so pressure p (along +z) means sigma_zz = -p and shear tau along +x means
      ! sigma_xz = -tau. Bonding to the rigid base: u_x = u_z = 0 at z = h.
      a(1, :) = surface(row_szz, :)
      a(2, :) = surface(row_sxz, :)
      a(3, :) = base(row_ux, :)
      a(4, :) = base(row_uz, :)
      b = (0.0_wp, 0.0_wp)
      b(1, 1) = (-1.0_wp, 0.0_wp)
      b(2, 2) = (-1.0_wp, 0.0_wp)
      call zgesv(4, 2, a, 4, ipiv, b, 4, info)
      if (info /= 0) then
         write (message, '(a, i0, a, es10.3, a, es10.3)') 'layer_mode_response: zgesv info = ', info, &
            ' at x_h = ', x, ', nu = ', nu
         call fatal_error(error, trim(message), code_internal)
         return
      end if
      ! Rows give 2G u; 2G = E/(1+nu) with E = 1, and the unit is 2/(E* k), E* = 1/(1-nu^2):
      ! u/(2/(E* k)) = (2G u) k/(2(1-nu)).
      scale = k/(2.0_wp*(1.0_wp - nu))
      w_p = scale*sum(surface(row_uz, :)*b(:, 1))
      ux_p = scale*sum(surface(row_ux, :)*b(:, 1))
      w_tau = scale*sum(surface(row_uz, :)*b(:, 2))
      ux_tau = scale*sum(surface(row_ux, :)*b(:, 2))
   end subroutine layer_mode_response

   !> Field rows at depth z of the plane-strain Papkovich-Neuber solution
   !> 2G u = 4(1-nu) psi e_z - grad(z psi + phi) for the mode exp(i k x), with harmonic
   !> phi = a1 f1 + a2 f2, psi = b1 f1 + b2 f2, with f1, f2 = cosh(k(h-z)), sinh(k(h-z)) for
   !> k h <= basis_switch and exp(-k z), exp(-k(h-z)) above.
   !> It solves Navier's equation (2G div u = 2(1-2nu) psi_z, 2G lap u = -2 grad psi_z),
   !> and lambda div u = 2 nu psi_z stays finite at nu = 0.5. Columns: a1, a2, b1, b2.
   !> Rows: 2G u_x, 2G u_z, sigma_xz = d/dx[(1-2nu) psi - z psi_z - phi_z],
   !> sigma_zz = 2(1-nu) psi_z - z psi_zz - phi_zz.
   pure function mode_field_rows(k, h, nu, z) result(rows)
      real(wp), intent(in) :: k, h, nu, z
      complex(wp) :: rows(4, 4)
      complex(wp), parameter :: i_unit = (0.0_wp, 1.0_wp)
      real(wp) :: f(2), df(2), d2f(2)
      complex(wp) :: ik
      integer :: j

      if (k*h <= basis_switch) then
         ! Thin layer: cosh/sinh stay independent as k h -> 0 (exponentials would merge).
         f = [cosh(k*(h - z)), sinh(k*(h - z))]
         df = [-k*f(2), -k*f(1)]
      else
         ! Thick layer: each exponential decays away from its own boundary, so no column
         ! grows like e^(k h) and the surface rows do not cancel.
         f = [exp(-k*z), exp(-k*(h - z))]
         df = [-k*f(1), k*f(2)]
      end if
      d2f = k*k*f
      ik = i_unit*k
      do j = 1, 2
         ! phi columns
         rows(1, j) = -ik*f(j)
         rows(2, j) = -df(j)
         rows(3, j) = -ik*df(j)
         rows(4, j) = -d2f(j)
         ! psi columns
         rows(1, j + 2) = -ik*z*f(j)
         rows(2, j + 2) = (3.0_wp - 4.0_wp*nu)*f(j) - z*df(j)
         rows(3, j + 2) = ik*((1.0_wp - 2.0_wp*nu)*f(j) - z*df(j))
         rows(4, j + 2) = 2.0_wp*(1.0_wp - nu)*df(j) - z*d2f(j)
      end do
   end function mode_field_rows
end module lc_greens_layer
