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
!> Comparing them checks the solver and the sign conventions (docs/theory.md).
!> On a surface (lc_base_grid) the derivatives are along the sliding direction x. On a
!> surface shared among MPI ranks (the operator's slab and its columns of the spectrum) each
!> rank sums its modes and the sums are added over the ranks.
module lc_observables_friction
   use lc_base_kinds, only: wp
   use lc_base_parallel, only: global_sum, sum_over_ranks
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: interlocking_friction

contains

   !> The four routes for pressure p, displacement w and profile r, and the power dissipated
   !> in a viscoelastic layer per unit nominal area (S L/T) at sliding speed V:
   !>    D = V sum_q q_x Im[s^* T s],  s = (mu_c p^, 0, p^),
   !> over the whole spectrum, T the surface compliance (lc_greens_kernel); on a line
   !>    D = V sum_{k>0} 4 Im[(1-nu^2) J*(kV) ((1-A) + mu_c^2 (1-B))] |p^(k)|^2
   !> (the normal-tangential coupling drops out of the quadratic form). The steady power
   !> balance (work of the tractions = dissipation) reads D = V p_m (Delta mu - by_energy), so
   !> for an elastic layer Delta mu = by_energy, and for a viscoelastic one the difference is
   !> the hysteretic part.
   subroutine interlocking_friction(op, p, w, r, by_displacement, by_spectrum, by_energy, by_profile, dissipation)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: p(:), w(:), r(:)
      real(wp), intent(out) :: by_displacement, by_spectrum, by_energy, by_profile, dissipation
      complex(wp), allocatable :: ph(:), rh(:), wh(:)
      real(wp) :: pm, qx, qy, q, cx, cy, im_g, power, mu
      complex(wp) :: uxh, compliance, anti, one_minus_a, one_minus_b, c, t
      real(wp) :: sums(5)
      integer :: i, mx

      pm = sum(p)/op%n
      if (op%distributed) pm = global_sum(sum(p))/op%grid%points()
      mu = op%friction
      allocate (ph(op%nk), rh(op%nk), wh(op%nk))
      call spectrum_of(op, p, ph)
      call spectrum_of(op, r, rh)
      call spectrum_of(op, w, wh)

      by_displacement = 0.0_wp
      by_profile = 0.0_wp
      by_spectrum = 0.0_wp
      by_energy = 0.0_wp
      dissipation = 0.0_wp
      ! Parseval on the half spectrum: <f g_x> = sum 2 Re[conj(f^) i q_x g^] over the modes
      ! with 0 < mx < nx/2 (mx = 0 has no x-derivative, nor has the Nyquist column); a
      ! distributed spectrum holds each of them on one rank.
      do i = 1, op%nk
         call op%column_mode(i, qx, qy, mx)
         if (mx == 0 .or. 2*mx == op%grid%nx) cycle
         q = hypot(qx, qy)
         cx = qx/q
         cy = qy/q
         call op%kernel%factors(q, qx, one_minus_a, one_minus_b, c, t)
         compliance = op%compliance(mx + 1)
         anti = op%kernel%antiplane(q, compliance, t)
         by_displacement = by_displacement - 2*real(conjg(ph(i))*cmplx(0.0_wp, qx, wp)*wh(i), wp)
         by_profile = by_profile - 2*real(conjg(ph(i))*cmplx(0.0_wp, qx, wp)*rh(i), wp)
         im_g = 0.0_wp
         if (op%coupled) im_g = aimag(op%full(i))
         power = abs(ph(i))**2
         by_spectrum = by_spectrum + 2*qx*im_g*power
         ! u_x^ = {2C/q [i c cx + mu_c (1-B) cx^2] + mu_c cy^2 tanh(qh)/(G q)} p^
         uxh = (2.0_wp/q*compliance*(mu*one_minus_b*cx**2 + (0.0_wp, 1.0_wp)*c*cx) + mu*cy**2*anti)*ph(i)
         by_energy = by_energy + mu*2*real(conjg(ph(i))*cmplx(0.0_wp, qx, wp)*uxh, wp)
         ! (the coupling c drops out of the quadratic form: Maxwell-Betti, complex c too)
         dissipation = dissipation + 2*qx*power*(2*aimag(compliance*(one_minus_a + mu**2*one_minus_b*cx**2))/q &
            & + mu**2*cy**2*aimag(anti))
      end do
      if (op%distributed) then
         sums = [by_displacement, by_profile, by_spectrum, by_energy, dissipation]
         call sum_over_ranks(sums)
         by_displacement = sums(1)
         by_profile = sums(2)
         by_spectrum = sums(3)
         by_energy = sums(4)
         dissipation = sums(5)
      end if
      by_displacement = by_displacement/pm
      by_profile = by_profile/pm
      by_spectrum = by_spectrum/pm
      by_energy = by_energy/pm
      dissipation = op%kernel%speed*dissipation
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
