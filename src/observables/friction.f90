!> Interlocking friction Delta mu (seed Eq. 11) by three independent routes:
!>  - force balance:  Delta mu = -<p r'>/p_m (in contact w' = r', so <p v_z'> = -<p r'>);
!>  - spectral:       Delta mu = (2/p_m) sum_{k>0} k Im G_eff(k) |p^(k)|^2, which holds for
!>                    any linear multiplier, elastic or viscoelastic;
!>  - energy:         Delta mu = mu_c <p du_x/dx>/p_m for elastic layers (the work of the
!>                    normal load over a period equals that of the shear: nothing is stored).
!> They agree only when the contact problem is solved (complementarity), so comparing them
!> checks the solver and the sign conventions (DESIGN.md §3).
module lc_observables_friction
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_greens_layer, only: layer_coefficients, halfspace_coupling
   implicit none (type, external)
   private
   public :: interlocking_friction

contains

   !> The three routes for pressure p on profile r (line contact of the operator's scene).
   subroutine interlocking_friction(op, p, r, thickness, young, poisson, by_force, by_spectrum, by_energy)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: p(:), r(:), thickness, young, poisson
      real(wp), intent(out) :: by_force, by_spectrum, by_energy
      complex(wp), allocatable :: ph(:), rh(:)
      real(wp) :: pm, k, estar, one_minus_a, one_minus_b, c, im_g
      complex(wp) :: uxh
      integer :: m, nk, n
      logical :: halfspace

      n = op%n
      nk = op%nk
      pm = sum(p)/n
      estar = young/(1.0_wp - poisson**2)
      halfspace = .not. ieee_is_finite(thickness)
      allocate (ph(nk), rh(nk))
      op%fft%real_buffer = p
      call op%fft%forward()
      ph = op%fft%spectrum
      op%fft%real_buffer = r
      call op%fft%forward()
      rh = op%fft%spectrum

      by_force = 0.0_wp
      by_spectrum = 0.0_wp
      by_energy = 0.0_wp
      ! Parseval on the half spectrum: <f g'> = sum_{k>0} 2 Re[conj(f^) i k g^]; the
      ! Nyquist mode has no derivative.
      do m = 1, nk - 1
         if (2*m == n) cycle
         k = op%wavenumber(m)
         if (halfspace) then
            one_minus_b = 1.0_wp
            c = halfspace_coupling(poisson)
         else
            call layer_coefficients(k*thickness, poisson, one_minus_a, one_minus_b, c)
         end if
         by_force = by_force - 2*real(conjg(ph(m + 1))*cmplx(0.0_wp, k, wp)*rh(m + 1), wp)
         im_g = -2.0_wp/(estar*k)*op%friction*c
         by_spectrum = by_spectrum + 2*k*im_g*abs(ph(m + 1))**2
         uxh = 2.0_wp/(estar*k)*cmplx(op%friction*one_minus_b, c, wp)*ph(m + 1)
         by_energy = by_energy + op%friction*2*real(conjg(ph(m + 1))*cmplx(0.0_wp, k, wp)*uxh, wp)
      end do
      by_force = by_force/pm
      by_spectrum = by_spectrum/pm
      by_energy = by_energy/pm
   end subroutine interlocking_friction
end module lc_observables_friction
