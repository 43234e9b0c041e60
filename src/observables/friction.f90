!> Interlocking friction Delta mu (seed Eq. 11) by four routes:
!>  - Eq. 11 as written: Delta mu = <p v_z'>/p_m = -<p w'>/p_m from the computed surface
!>                    displacement w (derivative by FFT, average on the grid);
!>  - spectral:       Delta mu = (2/p_m) sum_{k>0} k Im G_eff(k) |p^(k)|^2 (any linear
!>                    multiplier, elastic or viscoelastic): equal to the first to rounding;
!>  - energy:         Delta mu = mu_c <p du_x/dx>/p_m for elastic layers (the work of the
!>                    normal load over a period equals that of the shear: nothing is stored);
!>  - profile (force balance on the rigid indenter): Delta mu = -<p r'>/p_m, equal to the
!>                    others only where w' = r', i.e. when the contact problem is solved; on
!>                    a grid it differs by a discretisation error that vanishes as the grid
!>                    is refined (the spectral slope of w - r is not zero at contact nodes
!>                    next to an edge), which makes it a per-run accuracy indicator.
!> Comparing them checks the solver and the sign conventions (DESIGN.md §3).
module lc_observables_friction
   use lc_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   use lc_greens_layer, only: layer_coefficients
   implicit none (type, external)
   private
   public :: interlocking_friction

contains

   !> The four routes for pressure p, displacement w and profile r, and the power dissipated
   !> in a viscoelastic layer per unit nominal area (S L/T) at sliding speed V:
   !>    D = V sum_{k>0} 4 Im[(1-nu^2) J*(kV)] |p^(k)|^2 [(1-A) + mu_c^2 (1-B)]
   !> (the normal-tangential coupling drops out of the quadratic form). The steady power
   !> balance (work of the tractions = dissipation) reads D = V p_m (Delta mu - by_energy), so
   !> for an elastic layer Delta mu = by_energy, and for a viscoelastic one the difference is
   !> the hysteretic part.
   subroutine interlocking_friction(op, p, w, r, thickness, poisson, speed, by_displacement, by_spectrum, &
         & by_energy, by_profile, dissipation)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: p(:), w(:), r(:), thickness, poisson, speed
      real(wp), intent(out) :: by_displacement, by_spectrum, by_energy, by_profile, dissipation
      complex(wp), allocatable :: ph(:), rh(:), wh(:)
      real(wp) :: pm, k, one_minus_a, one_minus_b, c, im_g, power
      complex(wp) :: uxh
      integer :: m, nk, n

      n = op%n
      nk = op%nk
      pm = sum(p)/n
      allocate (ph(nk), rh(nk), wh(nk))
      call spectrum_of(op, p, ph)
      call spectrum_of(op, r, rh)
      call spectrum_of(op, w, wh)

      by_displacement = 0.0_wp
      by_profile = 0.0_wp
      by_spectrum = 0.0_wp
      by_energy = 0.0_wp
      dissipation = 0.0_wp
      ! Parseval on the half spectrum: <f g'> = sum_{k>0} 2 Re[conj(f^) i k g^]; the
      ! Nyquist mode has no derivative.
      do m = 1, nk - 1
         if (2*m == n) cycle
         k = op%wavenumber(m)
         call layer_coefficients(k*thickness, poisson, one_minus_a, one_minus_b, c)
         by_displacement = by_displacement - 2*real(conjg(ph(m + 1))*cmplx(0.0_wp, k, wp)*wh(m + 1), wp)
         by_profile = by_profile - 2*real(conjg(ph(m + 1))*cmplx(0.0_wp, k, wp)*rh(m + 1), wp)
         im_g = 0.0_wp
         if (op%coupled) im_g = aimag(op%full(m + 1))
         power = abs(ph(m + 1))**2
         by_spectrum = by_spectrum + 2*k*im_g*power
         uxh = 2.0_wp/k*op%compliance(m + 1)*cmplx(op%friction*one_minus_b, c, wp)*ph(m + 1)
         by_energy = by_energy + op%friction*2*real(conjg(ph(m + 1))*cmplx(0.0_wp, k, wp)*uxh, wp)
         dissipation = dissipation + 4*aimag(op%compliance(m + 1))*power*(one_minus_a + op%friction**2*one_minus_b)
      end do
      by_displacement = by_displacement/pm
      by_profile = by_profile/pm
      by_spectrum = by_spectrum/pm
      by_energy = by_energy/pm
      dissipation = speed*dissipation
   end subroutine interlocking_friction

   subroutine spectrum_of(op, f, fh)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: f(:)
      complex(wp), intent(out) :: fh(:)
      op%fft%real_buffer = f
      call op%fft%forward()
      fh = op%fft%spectrum
   end subroutine spectrum_of
end module lc_observables_friction
