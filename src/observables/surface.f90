!> Tangential surface displacement and surface in-plane stress of a line contact.
!>
!> Convention P (DESIGN.md §1), tau = mu_c p along +x on the layer:
!>    u_x^(k) = 2/(E*|k|) [ i sgn(k) c p^(k) + (1-B) tau^(k) ],
!> and at z = 0, from Hooke's law in plane strain with sigma_zz = -p (exact at the surface):
!>    sigma_xx = -(nu/(1-nu)) p + E* du_x/dx.
!> The uniform modes are set explicitly: a bonded layer sheared by the mean traction moves by
!> u_x = mu_c p_m h/G and has sigma_xx = -(nu/(1-nu)) p_m (uniaxial strain); a half-space has
!> no defined uniform u_x (set to zero) and sigma_xx = -p_m, the k -> 0 limit of its modes
!> (on a frictionless half-space every mode gives sigma_xx = -p at the surface).
!> Edge values converge slowly with the grid (like dx^(1/2)): compare interior values.
module lc_observables_surface
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp
   use lc_fft_plans, only: fft_plan
   use lc_greens_layer, only: layer_coefficients
   implicit none (type, external)
   private
   public :: surface_fields

   real(wp), parameter :: pi = acos(-1.0_wp)

contains

   !> u_x (L) and sigma_xx (S) at the surface for pressure p (S) and shear tau = friction p.
   subroutine surface_fields(fft, period, thickness, young, poisson, friction, p, displacement_x, stress_xx)
      type(fft_plan), intent(inout) :: fft
      real(wp), intent(in) :: period, thickness, young, poisson, friction
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: displacement_x(:), stress_xx(:)
      complex(wp), allocatable :: ph(:), uh(:), sh(:)
      real(wp) :: estar, k, one_minus_a, one_minus_b, c, pm, shear_modulus, contraction, odd
      integer :: m, n
      logical :: halfspace

      n = fft%n
      halfspace = .not. ieee_is_finite(thickness)
      estar = young/(1.0_wp - poisson**2)
      shear_modulus = young/(2.0_wp*(1.0_wp + poisson))
      contraction = poisson/(1.0_wp - poisson)
      fft%real_buffer = p
      call fft%forward()
      allocate (ph(fft%nk), uh(fft%nk), sh(fft%nk))
      ph = fft%spectrum
      pm = real(ph(1), wp)

      ! Per mode: u_x^ = 2/(E*k) [i c + mu (1-B)] p^ and, since i k/|k| = i sgn(k),
      ! E* i k u_x^ = [-2 c + 2 i mu (1-B)] p^. On the Nyquist mode the odd parts (i sgn(k))
      ! average to zero; the even parts stay.
      if (halfspace) then
         uh(1) = 0.0_wp
         sh(1) = -pm
      else
         uh(1) = friction*pm*thickness/shear_modulus
         sh(1) = -contraction*pm
      end if
      do m = 1, fft%nk - 1
         k = 2.0_wp*pi*m/period
         call layer_coefficients(k*thickness, poisson, one_minus_a, one_minus_b, c)
         odd = merge(0.0_wp, 1.0_wp, 2*m == n)
         uh(m + 1) = 2.0_wp/(estar*k)*cmplx(friction*one_minus_b, odd*c, wp)*ph(m + 1)
         sh(m + 1) = cmplx(-contraction - 2.0_wp*c, odd*2.0_wp*friction*one_minus_b, wp)*ph(m + 1)
      end do

      fft%spectrum = uh
      call fft%backward()
      displacement_x = fft%real_buffer
      fft%spectrum = sh
      call fft%backward()
      stress_xx = fft%real_buffer
   end subroutine surface_fields
end module lc_observables_surface
