!> Surface compliance of a stack of layers on a rigid base or an elastic half-space, for one
!> in-plane wavenumber |q| (docs/theory.md, "Layered stacks"; docs/decisions/017-layered-stacks.md).
!>
!> Layer 1 is at the surface, layer N at the bottom; each has a thickness h_i, a Young's modulus
!> E_i (complex for a viscoelastic layer: its modulus at the mode's frequency q_x V) and a
!> Poisson ratio nu_i. Each interface below a layer is bonded or slipping (frictionless:
!> continuous normal displacement and normal traction, no shear traction on either side).
!> The base is rigid or an elastic half-space (E_s, nu_s); its interface with layer N is
!> bonded or slipping as flagged on layer N.
!>
!> Result, convention P, in the frame (l, t, z) with l = q/|q| and in units of layer 1:
!>
!>    (u_l, w) = 2/(E*_1 |q|) [ 1-B, i c ; -i c', 1-A ] (tau_l, p),    u_t = t/(G_1 |q|) tau_t,
!>
!> E*_1 = E_1/(1 - nu_1^2), G_1 = E_1/(2(1 + nu_1)). One layer bonded on a rigid base gives
!> lc_greens_layer's 1-A, 1-B, c and t = tanh(|q| h). Maxwell-Betti reciprocity gives c' = c,
!> for complex moduli too; elastic stacks give real 1-A, 1-B, c.
!>
!> The plane-strain fields use the variables (u_x/i, u_z) and (sigma_xz/i, sigma_zz), in which
!> every layer matrix is real. The stack is condensed from the bottom up: each layer thinner
!> than x_thin (|q| h) updates the compliance of what lies below through its transfer matrix
!> (entries O(1), no cancellation of O(1/(|q|h)^3) stiffnesses), each thicker one through its
!> stiffness matrix written with exp(-|q|h) factors (no overflow) and a Schur complement.
!> `stack_compliance_lapack` solves the same boundary-value problem as one dense linear system
!> (4 Papkovich-Neuber coefficients per layer), as a test oracle.
module lc_greens_stack
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input, code_internal
   use lc_greens_layer, only: mode_field_rows
   implicit none (type, external)
   private
   public :: stack_layer, stack_base, stack_compliance, stack_coefficients, stack_compliance_lapack
   public :: condense_stack, check_stack
   public :: base_rigid, base_halfspace, lapack_layer_x_min, lapack_layer_x_max

   !> Kinds of base below the last layer.
   integer, parameter :: base_rigid = 1, base_halfspace = 2
   !> Below this |q| h a layer is applied through its transfer matrix (entries within a factor
   !> ~2 of 1), above through its stiffness matrix (entries O(1) in units of 2G|q|); the two
   !> agree across the switch (docs/decisions/017-layered-stacks.md).
   real(wp), parameter :: x_thin = 1.0_wp
   !> Above this |q| h the stiffness is evaluated with numerator and denominator times
   !> 4 exp(-2|q|h): sinh^2 would overflow past |q|h ~ 355 and at 20 both forms are exact.
   real(wp), parameter :: x_large = 20.0_wp
   !> Range of |q| h_i per layer accepted by the mode solver: its potentials lose digits like
   !> eps/(|q|h)^2 in thin layers, as in lc_greens_layer (measured: docs/decisions/017-layered-stacks.md).
   real(wp), parameter :: lapack_layer_x_min = 1.0e-2_wp
   real(wp), parameter :: lapack_layer_x_max = 30.0_wp
   !> Depth parameter of the mode solver's half-space columns: its decaying family exp(-|q| z)
   !> is the first column of mode_field_rows for any |q| h above 1; the growing one is unused.
   real(wp), parameter :: halfspace_depth = 1.0e3_wp
   complex(wp), parameter :: i_unit = (0.0_wp, 1.0_wp)

   !> One layer of the stack.
   type :: stack_layer
      real(wp) :: thickness = 1.0_wp                  !< h (L), >= 0
      complex(wp) :: young = (1.0_wp, 0.0_wp)         !< E at the mode's frequency (S), Re > 0
      real(wp) :: poisson = 0.5_wp                    !< nu, -1 < nu <= 0.5
      logical :: slip_below = .false.                 !< frictionless contact with what lies below
   end type stack_layer

   !> What the last layer rests on.
   type :: stack_base
      integer :: kind = base_rigid                    !< base_rigid or base_halfspace
      complex(wp) :: young = (1.0_wp, 0.0_wp)         !< half-space E_s (S)
      real(wp) :: poisson = 0.5_wp                    !< half-space nu_s
   end type stack_base

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

   !> Plane-strain 2x2 compliance (u_l, w) <- (tau_l, p) in units of 2/(E*_1 |q|) and the
   !> antiplane factor t (u_t = t tau_t/(G_1 |q|)) of a stack for the wavenumber |q| > 0 (1/L).
   subroutine stack_compliance(layers, base, q, plane, antiplane, error)
      !> Layers from the surface down.
      type(stack_layer), intent(in) :: layers(:)
      !> The base below the last layer.
      type(stack_base), intent(in) :: base
      !> |q| (1/L), > 0.
      real(wp), intent(in) :: q
      !> [1-B, i c; -i c', 1-A] of convention P.
      complex(wp), intent(out) :: plane(2, 2)
      !> t of u_t = t tau_t/(G_1 |q|).
      complex(wp), intent(out) :: antiplane
      !> Allocated on invalid input or a singular condensation.
      type(error_type), allocatable, intent(out) :: error
      integer :: singular
      character(len=80) :: message

      plane = (0.0_wp, 0.0_wp)
      antiplane = (0.0_wp, 0.0_wp)
      call check_stack(layers, base, q, error)
      if (allocated(error)) return
      call condense_stack(layers, base, q, plane, antiplane, singular)
      if (singular > 0) then
         write (message, '(a, i0)') 'stack_compliance: singular condensation at layer ', singular
         call fatal_error(error, trim(message), code_internal)
      end if
   end subroutine stack_compliance

   !> stack_compliance for valid input (checked by the caller, once for all modes): the
   !> index of the layer where the condensation met a singular matrix in `singular` (0: none;
   !> the results are then NaN), so that it can run per mode in pure code.
   pure subroutine condense_stack(layers, base, q, plane, antiplane, singular)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      real(wp), intent(in) :: q
      complex(wp), intent(out) :: plane(2, 2)
      complex(wp), intent(out) :: antiplane
      integer, intent(out) :: singular
      ! b: the stack below as a 2-parameter family of (u_x/i, u_z, sigma_xz/i, sigma_zz) at the
      ! interface, [U; T] = b v, with T the traction on the plane of normal +z (units |q| = 1).
      complex(wp) :: b(4, 2), bn(4, 2), comp(2, 2), stiff(2, 2), m(2, 2), kl(4, 4), pl(4, 4)
      complex(wp) :: anti(2), anti_new(2), two_g, g, anti_comp, det
      real(wp) :: x, th
      integer :: i, n

      n = size(layers)
      call base_family(base, layers(n)%slip_below, b, anti)
      do i = n, 1, -1
         if (i < n) call interface_family(comp, anti_comp, layers(i)%slip_below, b, anti)
         x = q*layers(i)%thickness
         g = layers(i)%young/(2.0_wp*(1.0_wp + layers(i)%poisson))
         two_g = 2.0_wp*g
         if (x <= x_thin) then
            pl = transfer_hat(x, layers(i)%poisson)
            pl(1:2, 3:4) = pl(1:2, 3:4)/two_g
            pl(3:4, 1:2) = pl(3:4, 1:2)*two_g
            bn = matmul(pl, b)
            call inverse2(-bn(3:4, :), m, det)
            if (det == 0.0_wp) exit
            comp = matmul(bn(1:2, :), m)
         else
            kl = two_g*stiffness_hat(x, layers(i)%poisson)
            call inverse2(matmul(kl(3:4, 3:4), b(1:2, :)) - b(3:4, :), m, det)
            if (det == 0.0_wp) exit
            stiff = kl(1:2, 1:2) - matmul(kl(1:2, 3:4), matmul(b(1:2, :), matmul(m, kl(3:4, 1:2))))
            call inverse2(stiff, comp, det)
            if (det == 0.0_wp) exit
         end if
         ! Antiplane: u = u_b cosh(z - h) + (T_b/G) sinh(z - h), both rows divided by cosh(|q| h).
         th = tanh(x)
         anti_new(1) = anti(1) - th*anti(2)/g
         anti_new(2) = -g*th*anti(1) + anti(2)
         if (anti_new(2) == 0.0_wp) exit
         anti_comp = -anti_new(1)/anti_new(2)
      end do
      singular = max(i, 0)
      if (singular > 0) then
         plane = cmplx(ieee_value(1.0_wp, ieee_quiet_nan), 0.0_wp, wp)
         antiplane = plane(1, 1)
         return
      end if
      g = layers(1)%young/(2.0_wp*(1.0_wp + layers(1)%poisson))
      comp = comp*g/(1.0_wp - layers(1)%poisson)
      plane(1, 1) = comp(1, 1)
      plane(1, 2) = i_unit*comp(1, 2)
      plane(2, 1) = -i_unit*comp(2, 1)
      plane(2, 2) = comp(2, 2)
      antiplane = anti_comp*g
   end subroutine condense_stack

   !> The factors 1-A, 1-B, c (from d u_l/d p) and t of a stack (see stack_compliance).
   subroutine stack_coefficients(layers, base, q, one_minus_a, one_minus_b, c, t, error)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      !> |q| (1/L), > 0.
      real(wp), intent(in) :: q
      !> Normal, tangential and coupling factors (real for elastic stacks), antiplane factor.
      complex(wp), intent(out) :: one_minus_a, one_minus_b, c, t
      type(error_type), allocatable, intent(out) :: error
      complex(wp) :: plane(2, 2)
      call stack_compliance(layers, base, q, plane, t, error)
      one_minus_a = plane(2, 2)
      one_minus_b = plane(1, 1)
      c = -i_unit*plane(1, 2)
   end subroutine stack_coefficients

   !> The checks of stack_compliance's input (the layers, the base and |q|).
   subroutine check_stack(layers, base, q, error)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      real(wp), intent(in) :: q
      type(error_type), allocatable, intent(out) :: error
      character(len=160) :: message
      integer :: i

      if (size(layers) < 1) then
         call fatal_error(error, 'layered stack: at least one layer is needed', code_input)
         return
      end if
      if (.not. (q > 0.0_wp .and. q <= huge(q))) then
         write (message, '(a, es10.3, a)') 'layered stack: |q| = ', q, ' must be positive and finite'
         call fatal_error(error, trim(message), code_input)
         return
      end if
      do i = 1, size(layers)
         if (.not. (layers(i)%thickness >= 0.0_wp .and. layers(i)%thickness <= huge(q) &
                    .and. layers(i)%poisson > -1.0_wp .and. layers(i)%poisson <= 0.5_wp &
                    .and. real(layers(i)%young, wp) > 0.0_wp .and. abs(layers(i)%young) <= huge(q))) then
            write (message, '(a, i0, a)') 'layered stack: layer ', i, &
               ' needs a finite thickness >= 0, -1 < nu <= 0.5 and a finite modulus with Re E > 0'
            call fatal_error(error, trim(message), code_input)
            return
         end if
      end do
      if (base%kind == base_halfspace) then
         if (.not. (base%poisson > -1.0_wp .and. base%poisson <= 0.5_wp .and. real(base%young, wp) > 0.0_wp &
                    .and. abs(base%young) <= huge(q))) then
            call fatal_error(error, 'layered stack: the half-space needs -1 < nu <= 0.5 and a finite Re E > 0', &
                             code_input)
            return
         end if
      else if (base%kind /= base_rigid) then
         call fatal_error(error, 'layered stack: base kind must be base_rigid or base_halfspace', code_input)
         return
      end if
   end subroutine check_stack

   !> The base as a family [U; T] = b v (plane strain, units |q| = 1) and (u, T) = anti (antiplane).
   pure subroutine base_family(base, slip, b, anti)
      type(stack_base), intent(in) :: base
      logical, intent(in) :: slip
      complex(wp), intent(out) :: b(4, 2), anti(2)
      complex(wp) :: g, comp(2, 2)
      real(wp) :: nu

      b = (0.0_wp, 0.0_wp)
      if (base%kind == base_rigid) then
         if (slip) then
            ! u_x free, T_x = 0; u_z = 0, T_z free.
            b(1, 1) = 1.0_wp
            b(4, 2) = 1.0_wp
            anti = [(1.0_wp, 0.0_wp), (0.0_wp, 0.0_wp)]
         else
            b(3, 1) = 1.0_wp
            b(4, 2) = 1.0_wp
            anti = [(0.0_wp, 0.0_wp), (1.0_wp, 0.0_wp)]
         end if
      else
         ! Half-space surface compliance (1-nu)/G [1, beta; beta, 1] (reduced variables, |q| = 1).
         nu = base%poisson
         g = base%young/(2.0_wp*(1.0_wp + nu))
         comp(1, :) = [1.0_wp, (1.0_wp - 2.0_wp*nu)/(2.0_wp*(1.0_wp - nu))]
         comp(2, :) = [comp(1, 2), (1.0_wp, 0.0_wp)]
         comp = comp*(1.0_wp - nu)/g
         call interface_family(comp, 1.0_wp/g, slip, b, anti)
      end if
   end subroutine base_family

   !> The family of the body below an interface of compliance comp (U = comp F for the force F
   !> on its top face, F = -T), bonded or slipping.
   pure subroutine interface_family(comp, anti_comp, slip, b, anti)
      complex(wp), intent(in) :: comp(2, 2), anti_comp
      logical, intent(in) :: slip
      complex(wp), intent(out) :: b(4, 2), anti(2)
      b = (0.0_wp, 0.0_wp)
      if (slip) then
         ! The layer above slides freely (T_x = 0); the body below sees the normal traction only.
         b(1, 1) = 1.0_wp
         b(2, 2) = -comp(2, 2)
         b(4, 2) = 1.0_wp
         anti = [(1.0_wp, 0.0_wp), (0.0_wp, 0.0_wp)]
      else
         b(1:2, :) = -comp
         b(3, 1) = 1.0_wp
         b(4, 2) = 1.0_wp
         anti = [-anti_comp, (1.0_wp, 0.0_wp)]
      end if
   end subroutine interface_family

   pure subroutine inverse2(a, inv, det)
      complex(wp), intent(in) :: a(2, 2)
      complex(wp), intent(out) :: inv(2, 2), det
      det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
      if (det == 0.0_wp) then
         inv = (0.0_wp, 0.0_wp)
         return
      end if
      inv(1, 1) = a(2, 2)/det
      inv(2, 2) = a(1, 1)/det
      inv(1, 2) = -a(1, 2)/det
      inv(2, 1) = -a(2, 1)/det
   end subroutine inverse2

   !> x cosh x - sinh x >= 0 for x >= 0, by its series sum_{n>=1} 2n x^(2n+1)/(2n+1)! below 2
   !> (the direct difference loses log10(3/x^2) digits).
   pure real(wp) function xcosh_minus_sinh(x) result(r)
      real(wp), intent(in) :: x
      real(wp) :: term, x2
      integer :: n
      if (x >= 2.0_wp) then
         r = x*cosh(x) - sinh(x)
         return
      end if
      ! term_n = x^(2n+1)/(2n+1)!, r = sum 2n term_n: all terms positive.
      x2 = x*x
      term = x*x2/6.0_wp
      r = 2.0_wp*term
      do n = 2, 40
         term = term*x2/real((2*n)*(2*n + 1), wp)
         if (2*n*term <= 0.25_wp*epsilon(1.0_wp)*r) exit
         r = r + 2*n*term
      end do
   end function xcosh_minus_sinh

   !> Transfer matrix of a layer for |q| = 1 and 2G = 1: (2G U, T) at the top from (2G U, T) at
   !> the bottom, x = |q| h <= x_thin, with U = (u_x/i, u_z) and T = (sigma_xz/i, sigma_zz).
   pure function transfer_hat(x, nu) result(p)
      real(wp), intent(in) :: x, nu
      real(wp) :: p(4, 4)
      real(wp) :: s, c, d, e, g2, kappa, xs, xc
      s = sinh(x)
      c = cosh(x)
      d = xcosh_minus_sinh(x)
      e = 1.0_wp - 2.0_wp*nu
      g2 = 2.0_wp*(1.0_wp - nu)
      kappa = 3.0_wp - 4.0_wp*nu
      xs = x*s
      xc = x*c
      ! x cosh - (1-2nu) sinh = d + 2 nu sinh and x cosh - kappa sinh = d - 2(1-2nu) sinh: the
      ! small-x cancellations are in d, summed as a series.
      p(1, :) = [c + xs/g2, (e*s + xc)/g2, -(kappa*s + xc)/g2, -xs/g2]
      p(2, :) = [-(d + 2.0_wp*nu*s)/g2, c - xs/g2, xs/g2, (d - 2.0_wp*e*s)/g2]
      p(3, :) = [-(xc + s)/g2, -xs/g2, c + xs/g2, (d + 2.0_wp*nu*s)/g2]
      p(4, :) = [xs/g2, d/g2, -(e*s + xc)/g2, c - xs/g2]
   end function transfer_hat

   !> Stiffness matrix of a layer for |q| = 1 and 2G = 1: forces on the layer at its top and
   !> bottom faces (-T(0), T(h)) from (U(0), U(h)), x = |q| h > x_thin, same variables as
   !> transfer_hat. With S = sinh x, C = cosh x, kappa = 3 - 4nu, Delta = kappa^2 S^2 - x^2:
   !>    K_tt = [2(1-nu)(kappa SC - x), x^2 - (1-2nu) kappa S^2; sym, 2(1-nu)(kappa SC + x)]/Delta,
   !>    K_bb = K_tt with the off-diagonal negated,
   !>    K_tb = [-2(1-nu)(kappa S - xC), -2(1-nu) x S; 2(1-nu) x S, -2(1-nu)(kappa S + xC)]/Delta,
   !>    K_bt = K_tb^T.
   pure function stiffness_hat(x, nu) result(k)
      real(wp), intent(in) :: x, nu
      real(wp) :: k(4, 4)
      real(wp) :: s, sc, s2, xlin, xx, xs, xc, delta, g2, kappa, e, em, t, xem, off

      kappa = 3.0_wp - 4.0_wp*nu
      e = 1.0_wp - 2.0_wp*nu
      g2 = 2.0_wp*(1.0_wp - nu)
      if (x <= x_large) then
         s = sinh(x)
         sc = s*cosh(x)
         s2 = s*s
         xlin = x
         xx = x*x
         xs = x*s
         xc = x*cosh(x)
      else
         ! Every term times 4 exp(-2x), from em = exp(-x) (x em stays normal up to x ~ 708,
         ! and em = 0 must give 0, not inf*0).
         em = exp(-x)
         t = em*em
         xem = 0.0_wp
         if (em > 0.0_wp) xem = x*em
         s = 2.0_wp*em*(1.0_wp - t)
         sc = (1.0_wp - t)*(1.0_wp + t)
         s2 = (1.0_wp - t)**2
         xlin = 4.0_wp*xem*em
         xx = 4.0_wp*xem*xem
         xs = 2.0_wp*xem*(1.0_wp - t)
         xc = 2.0_wp*xem*(1.0_wp + t)
      end if
      delta = kappa*kappa*s2 - xx
      off = xx - e*kappa*s2
      k(1, :) = [g2*(kappa*sc - xlin), off, -g2*(kappa*s - xc), -g2*xs]
      k(2, :) = [off, g2*(kappa*sc + xlin), g2*xs, -g2*(kappa*s + xc)]
      k(3, :) = [-g2*(kappa*s - xc), g2*xs, g2*(kappa*sc - xlin), -off]
      k(4, :) = [-g2*xs, -g2*(kappa*s + xc), -off, g2*(kappa*sc + xlin)]
      k = k/delta
   end function stiffness_hat

   !> Oracle: the same compliance from one dense linear system, the Papkovich-Neuber solution of
   !> each layer (4 coefficients; 2 for the decaying half-space) with every surface, interface and
   !> base condition, solved by zgesv; the antiplane field likewise (2 per layer, 1 for the
   !> half-space). Accurate for lapack_layer_x_min <= |q| h_i <= lapack_layer_x_max.
   subroutine stack_compliance_lapack(layers, base, q, plane, antiplane, error)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      !> |q| (1/L), > 0.
      real(wp), intent(in) :: q
      !> As in stack_compliance.
      complex(wp), intent(out) :: plane(2, 2), antiplane
      type(error_type), allocatable, intent(out) :: error
      complex(wp), allocatable :: a(:, :), rhs(:, :), top(:, :, :), bottom(:, :, :), aa(:, :), ra(:)
      complex(wp) :: hs(4, 4), g1, ghs, atop(2, 2), abottom(2, 2)
      integer, allocatable :: ipiv(:)
      integer :: n, nu_, row, i, info, ci, cj, na
      real(wp) :: x
      logical :: halfspace, slip
      character(len=160) :: message

      plane = (0.0_wp, 0.0_wp)
      antiplane = (0.0_wp, 0.0_wp)
      call check_stack(layers, base, q, error)
      if (allocated(error)) return
      n = size(layers)
      do i = 1, n
         x = q*layers(i)%thickness
         if (.not. (x >= lapack_layer_x_min .and. x <= lapack_layer_x_max)) then
            write (message, '(a, i0, a, es10.3, a)') 'stack_compliance_lapack: layer ', i, ' has |q|h = ', x, &
               ' outside the accurate range'
            call fatal_error(error, trim(message), code_input)
            return
         end if
      end do
      halfspace = base%kind == base_halfspace
      nu_ = 4*n
      if (halfspace) nu_ = nu_ + 2
      allocate (a(nu_, nu_), rhs(nu_, 2), top(4, 4, n), bottom(4, 4, n), ipiv(nu_))
      ! Field rows (u_x, u_z, sigma_xz, sigma_zz) at the top and bottom of each layer, |q| = 1.
      do i = 1, n
         x = q*layers(i)%thickness
         top(:, :, i) = mode_field_rows(1.0_wp, x, layers(i)%poisson, 0.0_wp)
         bottom(:, :, i) = mode_field_rows(1.0_wp, x, layers(i)%poisson, x)
         top(1:2, :, i) = top(1:2, :, i)*(1.0_wp + layers(i)%poisson)/layers(i)%young
         bottom(1:2, :, i) = bottom(1:2, :, i)*(1.0_wp + layers(i)%poisson)/layers(i)%young
      end do
      if (halfspace) then
         hs = mode_field_rows(1.0_wp, halfspace_depth, base%poisson, 0.0_wp)
         hs(1:2, :) = hs(1:2, :)*(1.0_wp + base%poisson)/base%young
      end if
      a = (0.0_wp, 0.0_wp)
      rhs = (0.0_wp, 0.0_wp)
      ! Surface: sigma_zz = -p (column 1), sigma_xz = -tau (column 2).
      a(1, 1:4) = top(4, :, 1)
      a(2, 1:4) = top(3, :, 1)
      rhs(1, 1) = -1.0_wp
      rhs(2, 2) = -1.0_wp
      row = 2
      do i = 1, n
         ci = 4*(i - 1) + 1
         cj = ci + 4
         slip = layers(i)%slip_below
         if (i < n) then
            call continuity(bottom(:, :, i), top(:, :, i + 1), ci, cj)
         else if (halfspace) then
            call continuity(bottom(:, :, i), hs(:, [1, 3]), ci, cj)
         else
            ! Rigid base: u_z = 0 and u_x = 0 (bonded) or sigma_xz = 0 (slipping).
            a(row + 1, ci:ci + 3) = bottom(2, :, i)
            if (slip) then
               a(row + 2, ci:ci + 3) = bottom(3, :, i)
            else
               a(row + 2, ci:ci + 3) = bottom(1, :, i)
            end if
            row = row + 2
         end if
      end do
      call zgesv(nu_, 2, a, nu_, ipiv, rhs, nu_, info)
      if (info /= 0) then
         call fatal_error(error, 'stack_compliance_lapack: singular mode system', code_internal)
         return
      end if
      g1 = layers(1)%young/(2.0_wp*(1.0_wp + layers(1)%poisson))
      plane(1, 2) = sum(top(1, :, 1)*rhs(1:4, 1))
      plane(2, 2) = sum(top(2, :, 1)*rhs(1:4, 1))
      plane(1, 1) = sum(top(1, :, 1)*rhs(1:4, 2))
      plane(2, 1) = sum(top(2, :, 1)*rhs(1:4, 2))
      plane = plane*g1/(1.0_wp - layers(1)%poisson)

      ! Antiplane: u = a1 f1 + a2 f2 per layer, sigma_yz = G u'; half-space u = a exp(-z).
      na = 2*n
      if (halfspace) na = na + 1
      allocate (aa(na, na), ra(na))
      aa = (0.0_wp, 0.0_wp)
      ra = (0.0_wp, 0.0_wp)
      call antiplane_rows(1)
      aa(1, 1:2) = -atop(2, :)
      ra(1) = 1.0_wp
      row = 1
      do i = 1, n
         call antiplane_rows(i)
         ci = 2*(i - 1) + 1
         if (i < n) then
            cj = ci + 2
            if (layers(i)%slip_below) then
               aa(row + 1, ci:ci + 1) = abottom(2, :)
               row = row + 1
               call antiplane_rows(i + 1)
               aa(row + 1, cj:cj + 1) = atop(2, :)
               row = row + 1
            else
               aa(row + 1, ci:ci + 1) = abottom(1, :)
               aa(row + 2, ci:ci + 1) = abottom(2, :)
               call antiplane_rows(i + 1)
               aa(row + 1, cj:cj + 1) = -atop(1, :)
               aa(row + 2, cj:cj + 1) = -atop(2, :)
               row = row + 2
            end if
         else if (halfspace) then
            ghs = base%young/(2.0_wp*(1.0_wp + base%poisson))
            if (layers(i)%slip_below) then
               aa(row + 1, ci:ci + 1) = abottom(2, :)
               aa(row + 2, na) = -ghs
            else
               aa(row + 1, ci:ci + 1) = abottom(1, :)
               aa(row + 1, na) = -1.0_wp
               aa(row + 2, ci:ci + 1) = abottom(2, :)
               aa(row + 2, na) = ghs
            end if
            row = row + 2
         else
            if (layers(i)%slip_below) then
               aa(row + 1, ci:ci + 1) = abottom(2, :)
            else
               aa(row + 1, ci:ci + 1) = abottom(1, :)
            end if
            row = row + 1
         end if
      end do
      deallocate (ipiv)
      allocate (ipiv(na))
      call zgesv(na, 1, aa, na, ipiv, ra, na, info)
      if (info /= 0) then
         call fatal_error(error, 'stack_compliance_lapack: singular antiplane system', code_internal)
         return
      end if
      call antiplane_rows(1)
      antiplane = sum(atop(1, :)*ra(1:2))*g1

   contains

      !> Bonded: u_x, u_z, sigma_xz, sigma_zz continuous; slipping: u_z, sigma_zz continuous and
      !> sigma_xz = 0 on both sides. `upper` at the bottom of layer i, `lower` at the top of the next.
      subroutine continuity(upper, lower, cu, cl)
         complex(wp), intent(in) :: upper(:, :), lower(:, :)
         integer, intent(in) :: cu, cl
         integer :: m, nl
         nl = size(lower, 2)
         if (slip) then
            a(row + 1, cu:cu + 3) = upper(2, :)
            a(row + 1, cl:cl + nl - 1) = -lower(2, :)
            a(row + 2, cu:cu + 3) = upper(4, :)
            a(row + 2, cl:cl + nl - 1) = -lower(4, :)
            a(row + 3, cu:cu + 3) = upper(3, :)
            a(row + 4, cl:cl + nl - 1) = lower(3, :)
         else
            do m = 1, 4
               a(row + m, cu:cu + 3) = upper(m, :)
               a(row + m, cl:cl + nl - 1) = -lower(m, :)
            end do
         end if
         row = row + 4
      end subroutine continuity

      !> Rows (u, sigma_yz) at the top (atop) and bottom (abottom) of layer j for the basis
      !> cosh(x - z), sinh(x - z) (x <= 1) or exp(-z), exp(-(x - z)).
      subroutine antiplane_rows(j)
         integer, intent(in) :: j
         real(wp) :: xj
         complex(wp) :: gj
         xj = q*layers(j)%thickness
         gj = layers(j)%young/(2.0_wp*(1.0_wp + layers(j)%poisson))
         if (xj <= 1.0_wp) then
            atop(1, :) = [cosh(xj), sinh(xj)]
            atop(2, :) = gj*[-sinh(xj), -cosh(xj)]
            abottom(1, :) = [1.0_wp, 0.0_wp]
            abottom(2, :) = gj*[0.0_wp, -1.0_wp]
         else
            atop(1, :) = [1.0_wp, exp(-xj)]
            atop(2, :) = gj*[-1.0_wp, exp(-xj)]
            abottom(1, :) = [exp(-xj), 1.0_wp]
            abottom(2, :) = gj*[-exp(-xj), 1.0_wp]
         end if
      end subroutine antiplane_rows
   end subroutine stack_compliance_lapack
end module lc_greens_stack
