!> Tangential surface displacement and surface in-plane stress of a line contact (a grid
!> with one row).
!>
!> Convention P (docs/theory.md), tau = mu_c p along +x on the layer:
!>    u_x^(k) = 2/(E*|k|) [ i sgn(k) c p^(k) + (1-B) tau^(k) ],
!> with 1/E* -> (1 - nu^2) J*(kV) for a viscoelastic layer (Poisson's ratio constant),
!> and at z = 0, from Hooke's law in plane strain with sigma_zz = -p (exact at the surface):
!>    sigma_xx = -(nu/(1-nu)) p + E* du_x/dx.
!> The uniform modes are set explicitly: a bonded layer sheared by the mean traction moves by
!> u_x = mu_c p_m h/G (summed over a stack's layers; zero where an interface slips) and has
!> sigma_xx = -(nu/(1-nu)) p_m (uniaxial strain); a half-space has no defined uniform u_x
!> (set to zero) and sigma_xx = -p_m, the k -> 0 limit of its modes (on a frictionless
!> half-space every mode gives sigma_xx = -p at the surface); a stack on a half-space takes
!> the k -> 0 limit of its own modes.
!> Grid values next to a trailing edge converge slowly (like dx^(1/2)): sigma_xx has a
!> square-root cusp there. `edge_stress_field` gives the smooth field that equals sigma_xx at
!> every contact edge, from which the cusp's peak is interpolated sub-grid
!> (lc_observables_geometry's spot_tension).
module lc_observables_surface
   use lc_base_kinds, only: wp
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: surface_fields, edge_stress_field

contains

   !> u_x (L) and sigma_xx (S) at the surface for pressure p (S) and shear tau = friction p.
   subroutine surface_fields(op, p, displacement_x, stress_xx)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: displacement_x(:), stress_xx(:)
      complex(wp), allocatable :: ph(:), uh(:), sh(:)
      real(wp) :: k, unused, pm, contraction, friction
      complex(wp) :: one_minus_a, one_minus_b, c, t, multiplier
      integer :: m, n

      associate (fft => op%fft, poisson => op%kernel%poisson)
      n = fft%n
      friction = op%friction
      contraction = poisson/(1.0_wp - poisson)
      fft%real_buffer = p
      call fft%forward()
      allocate (ph(fft%nk), uh(fft%nk), sh(fft%nk))
      ph = fft%spectrum
      pm = real(ph(1), wp)

      ! Per mode: u_x^ = 2/(E*k) [i c + mu (1-B)] p^ and, since i k/|k| = i sgn(k),
      ! E* i k u_x^ = [-2 c + 2 i mu (1-B)] p^.
      if (op%kernel%unbounded()) then
         ! the k -> 0 limit of sigma_xx's multiplier below (-p_m on a half-space)
         uh(1) = 0.0_wp
         sh(1) = real(-contraction - 2.0_wp*op%kernel%long_wave_coupling(), wp)*pm
      else
         ! simple shear of the bonded layer (or stack): u_x = tau_m h/G summed over the layers
         uh(1) = friction*pm*op%kernel%shear_uniform(real(op%compliance(1), wp))
         sh(1) = -contraction*pm
      end if
      do m = 1, fft%nk - 1
         call op%grid%wavevector(m + 1, k, unused)
         call op%kernel%factors(k, k, one_minus_a, one_minus_b, c, t)
         ! (1 - nu^2) J*(kV) = 1/E* for an elastic layer; sigma_xx does not depend on it
         multiplier = 2.0_wp/k*op%compliance(m + 1)*(friction*one_minus_b + (0.0_wp, 1.0_wp)*c)
         uh(m + 1) = multiplier*ph(m + 1)
         sh(m + 1) = (-contraction - 2.0_wp*c + (0.0_wp, 2.0_wp)*friction*one_minus_b)*ph(m + 1)
         if (2*m == n) then
            ! the Nyquist mode is its own mirror image: mirror averages (real parts) of the
            ! multipliers
            uh(m + 1) = real(multiplier, wp)*ph(m + 1)
            sh(m + 1) = real(-contraction - 2.0_wp*c + (0.0_wp, 2.0_wp)*friction*one_minus_b, wp)*ph(m + 1)
         end if
      end do

      fft%spectrum = uh
      call fft%backward()
      displacement_x = fft%real_buffer
      fft%spectrum = sh
      call fft%backward()
      stress_xx = fft%real_buffer
      end associate
   end subroutine surface_fields

   !> Q = sigma_xx - a p - b dg/dx (S): the surface stress without its two cusps, equal to
   !> sigma_xx wherever p = 0 and dg/dx = 0, i.e. at every contact edge.
   !>
   !> Per mode, with C(k) = (1 - nu^2) J*(kV) and w'^ = 2 C [i sgn(k) (1-A) + c mu_c] p^,
   !>    sigma_xx^ = a(k) p^ + b(k) w'^,   b = mu_c (1-B)/((1-A) C),
   !>    a = -nu/(1-nu) - 2c - 2 mu_c^2 c (1-B)/(1-A),
   !> and a(k), b(k) tend to the half-space constants a, b below (1-A, 1-B -> 1, c -> Dundurs'
   !> (1-2nu)/(2(1-nu)), C -> its value at the grid's shortest wave) exponentially fast in kh.
   !> Near an edge p ~ sqrt(s) inside and g' ~ sqrt(-s) outside carry the cusp of sigma_xx
   !> (on an incompressible half-space sigma_xx = -p - 2 mu_c H[p] = -p + mu_c E* w'); since
   !> w' = r' + g', Q = b r' + (a(k) - a) p + (b(k) - b) w' is as smooth as the profile
   !> and the layer's exponentially decaying corrections, so it can be interpolated to a
   !> sub-grid edge position from the grid.
   subroutine edge_stress_field(op, stress_xx, p, gap, field)
      type(compliance_operator), intent(inout) :: op
      real(wp), intent(in) :: stress_xx(:), p(:), gap(:)
      real(wp), intent(out) :: field(:)
      real(wp) :: a, b, dundurs, k, unused
      integer :: m

      associate (fft => op%fft, poisson => op%kernel%poisson)
      dundurs = (1.0_wp - 2.0_wp*poisson)/(2.0_wp*(1.0_wp - poisson))
      a = -poisson/(1.0_wp - poisson) - 2.0_wp*dundurs*(1.0_wp + op%friction**2)
      b = op%friction/real(op%compliance(fft%nk), wp)
      ! dg/dx spectrally (the Nyquist mode has no defined derivative: dropped)
      fft%real_buffer = gap
      call fft%forward()
      fft%spectrum(1) = 0.0_wp
      do m = 1, fft%nk - 1
         call op%grid%wavevector(m + 1, k, unused)
         fft%spectrum(m + 1) = cmplx(0.0_wp, k, wp)*fft%spectrum(m + 1)
         if (2*m == fft%n) fft%spectrum(m + 1) = 0.0_wp
      end do
      call fft%backward()
      field = stress_xx - a*p - b*fft%real_buffer
      end associate
   end subroutine edge_stress_field
end module lc_observables_surface
