!> In-plane surface displacements and the surface stress tensor of an areal contact.
!>
!> Convention P (docs/theory.md): tractions (tau_x, tau_y, p) = (mu_c p, 0, p) on the
!> surface, displacements (u_x, u_y) from the layer's 3x3 tensor (lc_greens_kernel). At
!> z = 0, from Hooke's law with sigma_zz = -p (exact at the surface; the shear tractions do
!> not enter the in-plane stresses):
!>    sigma_xx = -(nu/(1-nu)) p + 2G [eps_xx + (nu/(1-nu)) (eps_xx + eps_yy)],
!>    sigma_yy = -(nu/(1-nu)) p + 2G [eps_yy + (nu/(1-nu)) (eps_xx + eps_yy)],
!>    sigma_xy = 2G eps_xy,
!> tension positive. Per mode 2G u^ = (1-nu) u^/C with C the contact compliance, so the
!> stress multipliers do not depend on the material's frequency (Poisson's ratio constant).
!> The uniform modes: a bonded layer sheared by the mean traction moves by
!> u_x = mu_c p_m h/G and is in uniaxial strain, sigma_xx = sigma_yy = -(nu/(1-nu)) p_m;
!> a half-space has no defined uniform displacement (set to zero), and its modes have no
!> unique limit as q -> 0 (it depends on the direction of q): the uniform stress is their
!> limit along the sliding direction, sigma_xx = -p_m, sigma_yy = -2 nu p_m (plane strain),
!> as on a line contact, so that a surface constant along y gives the line's stresses.
!> A mode of the Nyquist column (even nx) is its own mirror image: its multiplier M is the
!> mirror average (M(q_x, q_y) + conj M(q_x, -q_y))/2; a mode of the Nyquist row (even ny)
!> stands for q_y = +-pi/dy: (M(q_x, q_y) + M(q_x, -q_y))/2.
!> On a surface shared among MPI ranks the multipliers act on each rank's columns of the
!> distributed spectrum and the operator's distributed plans give each rank its rows.
module lc_observables_stress
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: surface_stress

   !> Fields of one mode: u_x, u_y, sigma_xx, sigma_yy, sigma_xy per unit p^.
   integer, parameter :: n_fields = 5

contains

   !> u_x, u_y (L) and sigma_xx, sigma_yy, sigma_xy (S) at the surface for the pressure p
   !> (S, flat on the operator's grid) and the shear tau_x = mu_c p (mu_c of the operator).
   subroutine surface_stress(op, p, displacement_x, displacement_y, stress_xx, stress_yy, stress_xy)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: displacement_x(:), displacement_y(:), stress_xx(:), stress_yy(:), stress_xy(:)
      complex(wp), allocatable :: ph(:), fh(:, :)
      complex(wp) :: m(n_fields)
      real(wp) :: qx, qy
      integer :: i, mx, my, field

      associate (fft => op%fft)
      fft%real_buffer = p
      call fft%forward()
      ph = fft%spectrum
      allocate (fh(op%nk, n_fields))
      ! (a distributed spectrum: this rank's columns, the uniform mode on the rank holding it)
      if (op%holds_uniform .and. op%nk > 0) fh(1, :) = uniform_fields(op, real(ph(1), wp))
      do i = 1, op%nk
         call op%column_mode(i, qx, qy, mx)
         call op%fft%mode_indices(i, mx, my)
         if (mx == 0 .and. my == 0) cycle
         m = mode_multipliers(op, qx, qy, mx)
         if (2*mx == op%grid%nx) m = 0.5_wp*(m + conjg(mode_multipliers(op, qx, -qy, mx)))
         if (2*my == op%grid%ny) m = 0.5_wp*(m + mode_multipliers(op, qx, -qy, mx))
         fh(i, :) = m*ph(i)
      end do
      do field = 1, n_fields
         fft%spectrum = fh(:, field)
         call fft%backward()
         select case (field)
         case (1)
            displacement_x = fft%real_buffer
         case (2)
            displacement_y = fft%real_buffer
         case (3)
            stress_xx = fft%real_buffer
         case (4)
            stress_yy = fft%real_buffer
         case (5)
            stress_xy = fft%real_buffer
         end select
      end do
      end associate
   end subroutine surface_stress

   !> (u_x, u_y, sigma_xx, sigma_yy, sigma_xy) of the uniform mode for the mean pressure pm.
   function uniform_fields(op, pm) result(fields)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: pm
      complex(wp) :: fields(n_fields)
      real(wp) :: contraction, c0
      associate (poisson => op%kernel%poisson)
      contraction = poisson/(1.0_wp - poisson)
      c0 = real(op%compliance(1), wp)
      if (op%kernel%halfspace) then
         fields = [complex(wp) :: 0.0_wp, 0.0_wp, -pm, -2.0_wp*poisson*pm, 0.0_wp]
      else if (op%kernel%unbounded()) then
         ! a stack on a half-space: the limit of its modes along x (as the half-space's row
         ! above), u undefined (zero)
         fields = real(mode_multipliers(op, 1.0e-9_wp/sum(op%kernel%stack%thickness), 0.0_wp, 0), wp)*pm
         fields(1:2) = 0.0_wp
      else
         fields = [complex(wp) :: op%friction*pm*op%kernel%shear_uniform(c0), 0.0_wp, -contraction*pm, &
            & -contraction*pm, 0.0_wp]
      end if
      end associate
   end function uniform_fields

   !> (u_x, u_y, sigma_xx, sigma_yy, sigma_xy) per unit p^ of the mode (qx, qy), |q| > 0,
   !> with tau_x = mu_c p; mx is the column (for the contact compliance C(q_x V)).
   function mode_multipliers(op, qx, qy, mx) result(m)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: qx, qy
      integer, intent(in) :: mx
      complex(wp) :: m(n_fields)
      complex(wp) :: t(3, 3), ux, uy, exx, eyy, exy
      real(wp) :: nu, contraction
      complex(wp) :: c
      nu = op%kernel%poisson
      contraction = nu/(1.0_wp - nu)
      c = op%compliance(mx + 1)
      t = op%kernel%tensor_with(qx, qy, c)
      ux = t(1, 3) + op%friction*t(1, 1)
      uy = t(2, 3) + op%friction*t(2, 1)
      ! strains of u/C: 2G u = (1 - nu) u/C
      exx = cmplx(0.0_wp, qx, wp)*ux/c
      eyy = cmplx(0.0_wp, qy, wp)*uy/c
      exy = 0.5_wp*(cmplx(0.0_wp, qy, wp)*ux + cmplx(0.0_wp, qx, wp)*uy)/c
      m(1) = ux
      m(2) = uy
      m(3) = -contraction + (1.0_wp - nu)*(exx + contraction*(exx + eyy))
      m(4) = -contraction + (1.0_wp - nu)*(eyy + contraction*(exx + eyy))
      m(5) = (1.0_wp - nu)*exy
   end function mode_multipliers
end module lc_observables_stress
