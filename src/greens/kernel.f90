!> The layer's surface response per in-plane wavevector q: what the operator, the
!> observables and the areal tensor are built from, in one place.
!>
!> Convention P (docs/theory.md): for tractions (tau_x, tau_y, p) on the surface, in the
!> frame (l, t, z) with l = q/|q|, the (l, z) block is the plane-strain multiplier with
!> |k| -> |q|, sgn(k) -> +1,
!>    w^   = 2 C/|q| [ (1-A) p^     - i c tau_l^ ],
!>    u_l^ = 2 C/|q| [ i c p^       + (1-B) tau_l^ ],
!> and the transverse direction decouples (antiplane shear of a layer bonded to a rigid
!> base): u_t^ = 2 C/((1-nu)|q|) tanh(|q| h) tau_t^, i.e. tanh(|q|h)/(G|q|). Here
!> C = (1 - nu^2) J*(q_x V) is the contact compliance, 1/E* for an elastic layer; for a
!> viscoelastic layer sliding at speed V along x a mode sees the frequency q_x V (the
!> sliding component of q). 1-A, 1-B, c are lc_greens_layer's. At q = 0 a finite layer has
!> the compliances h/M (normal, M the constrained modulus) and h/G (shear); a half-space
!> has none (set to zero).
!>
!> A layer resting on more than a rigid base bonded to it (deeper elastic layers, a slipping
!> interface, an elastic half-space substrate: `place_on`) is a stack: its 1-A, 1-B, c and the
!> antiplane factor t (tanh(|q|h) for one bonded layer) come from lc_greens_stack per mode, in
!> units of the top layer's compliance C, complex where the top layer's modulus is (a
!> viscoelastic coating on an elastic substrate).
module lc_greens_kernel
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_greens_layer, only: layer_coefficients, halfspace_coupling
   use lc_greens_stack, only: stack_layer, stack_base, condense_stack, base_rigid, base_halfspace
   use lc_greens_viscoelastic, only: material_law, material_model, material_model_of, standard_linear_solid
   implicit none (type, external)
   private
   public :: layer_kernel, make_kernel, place_on

   !> A layer (or half-space) of one material sliding at one speed.
   type :: layer_kernel
      real(wp) :: thickness = 1.0_wp     !< h (L); +Inf = half-space
      real(wp) :: poisson = 0.5_wp       !< nu, constant in time
      real(wp) :: speed = 0.0_wp         !< V (L/T)
      !> the layer's material (material_model_of its &material values)
      class(material_model), allocatable :: material
      logical :: halfspace = .false.
      !> a moving viscoelastic law: complex compliances (an elastic law, or any law at rest,
      !> has the real compliance of its static modulus)
      logical :: viscoelastic = .false.
      !> The layer rests on a stack (place_on) rather than bonded to a rigid base.
      logical :: layered = .false.
      !> The stack from the top: stack(1) is this layer (its modulus is set per mode), then
      !> the deeper layers; each flags a slipping interface below it.
      type(stack_layer), allocatable :: stack(:)
      !> What the stack rests on: rigid, or an elastic half-space.
      type(stack_base) :: base
      !> Per layer of the stack below the top one: a standard linear solid where lower_tau > 0
      !> (retardation time, T; its low-frequency modulus is the stack layer's young), with the
      !> high-frequency modulus lower_e_inf (S); elastic where 0.
      real(wp), allocatable :: lower_tau(:), lower_e_inf(:)
   contains
      procedure :: contact_compliance
      procedure :: factors
      procedure :: compliance_falls
      procedure :: compliance_rise
      procedure :: coupled
      procedure :: normal_uniform
      procedure :: shear_uniform
      procedure :: antiplane
      procedure :: unbounded
      procedure :: long_wave_coupling
      procedure :: tensor
      procedure :: tensor_with
   end type layer_kernel

contains

   !> The kernel of a layer of thickness h (+Inf: half-space), material law, Poisson ratio
   !> and sliding speed.
   function make_kernel(thickness, law, poisson, speed) result(kernel)
      real(wp), intent(in) :: thickness, poisson, speed
      type(material_law), intent(in) :: law
      type(layer_kernel) :: kernel
      kernel%thickness = thickness
      kernel%poisson = poisson
      kernel%speed = speed
      call material_model_of(law, kernel%material)
      kernel%halfspace = .not. ieee_is_finite(thickness)
      kernel%viscoelastic = .false.
      if (allocated(kernel%material)) kernel%viscoelastic = kernel%material%viscoelastic() .and. speed > 0.0_wp
   end function make_kernel

   !> Rest the kernel's layer on `deeper` elastic layers (from the top down, each flagging a
   !> slipping interface below it) and a base: rigid or an elastic half-space. `slip`: the
   !> interface below the kernel's own layer slips (frictionless). Without deeper layers, on a
   !> rigid bonded base, the kernel stays the closed-form single layer. A deeper layer with
   !> tau(i) > 0 is a standard linear solid (its young the low-frequency modulus, e_inf(i)
   !> the high-frequency one). The caller checks the values; the layer must be finite.
   subroutine place_on(self, slip, deeper, base, tau, e_inf)
      class(layer_kernel), intent(inout) :: self
      logical, intent(in) :: slip
      type(stack_layer), intent(in) :: deeper(:)
      type(stack_base), intent(in) :: base
      real(wp), intent(in) :: tau(:), e_inf(:)
      self%layered = slip .or. size(deeper) > 0 .or. base%kind == base_halfspace
      if (.not. self%layered) return
      self%stack = [stack_layer(thickness=self%thickness, young=(1.0_wp, 0.0_wp), poisson=self%poisson, &
         & slip_below=slip), deeper]
      self%base = base
      self%lower_tau = tau
      self%lower_e_inf = e_inf
      if (self%speed > 0.0_wp .and. any(tau > 0.0_wp)) self%viscoelastic = .true.
   end subroutine place_on

   !> C = (1 - nu^2) J*(q_x V) (1/S) for the sliding wavenumbers q_x (1/L).
   pure function contact_compliance(self, qx) result(c)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: qx(:)
      complex(wp) :: c(size(qx))
      c = (1.0_wp - self%poisson**2)*self%material%compliance(qx*self%speed)
   end function contact_compliance

   !> 1-A, 1-B, c and the antiplane factor t for |q| > 0 (1/L) and the sliding wavenumber q_x
   !> (1/L; the top layer of a stack sees the frequency q_x V): real for one layer, and for
   !> any stack of elastic layers.
   pure elemental subroutine factors(self, q, qx, one_minus_a, one_minus_b, c, t)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: q, qx
      complex(wp), intent(out) :: one_minus_a, one_minus_b, c, t
      type(stack_layer), allocatable :: layers(:)
      type(standard_linear_solid) :: lower_law
      complex(wp) :: plane(2, 2), compliance(1)
      real(wp) :: a, b, coupling
      integer :: singular, i
      if (.not. self%layered) then
         ! x = +Inf (half-space) gives 1-A = 1-B = 1 and Dundurs' c
         call layer_coefficients(q*self%thickness, self%poisson, a, b, coupling)
         one_minus_a = a
         one_minus_b = b
         c = coupling
         t = 1.0_wp
         if (.not. self%halfspace) t = tanh(q*self%thickness)
         return
      end if
      layers = self%stack
      compliance = self%material%compliance([qx*self%speed])
      layers(1)%young = 1.0_wp/compliance(1)
      do i = 2, size(layers)
         if (self%lower_tau(i - 1) > 0.0_wp) then
            lower_law = standard_linear_solid(e0=real(layers(i)%young, wp), e_inf=self%lower_e_inf(i - 1), &
               & tau=self%lower_tau(i - 1))
            compliance = lower_law%compliance([qx*self%speed])
            layers(i)%young = 1.0_wp/compliance(1)
         end if
      end do
      call condense_stack(layers, self%base, q, plane, t, singular)
      one_minus_a = plane(2, 2)
      one_minus_b = plane(1, 1)
      c = cmplx(aimag(plane(1, 2)), -real(plane(1, 2), wp), wp)
   end subroutine factors

   !> Whether the normal and tangential fields are coupled under Coulomb friction
   !> `friction` (a complex, non-symmetric operator): always for a moving viscoelastic law;
   !> with friction unless on an incompressible half-space, whose c = 0 (a stack's c is not).
   pure logical function coupled(self, friction)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: friction
      coupled = self%viscoelastic .or. (friction > 0.0_wp .and. .not. (self%halfspace .and. self%poisson == 0.5_wp))
   end function coupled

   !> Whether the normal compliance (1-A(|q| h))/|q| falls with |q| on [q_min, q_max] (1/L)
   !> (compliance_rise at most 1, to rounding): true for a half-space and for compressible
   !> layers (a constant below |q| h ~ 1, then 1/|q|); false for thin, nearly incompressible
   !> layers, whose compliance rises like (|q| h)^2 up to |q| h ~ 1.
   pure logical function compliance_falls(self, q_min, q_max) result(falls)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: q_min, q_max
      ! (a relative margin for the rounding of 1-A where it is flat)
      falls = self%compliance_rise(q_min, q_max) <= 1.0_wp + 1.0e-12_wp
   end function compliance_falls

   !> The largest factor by which the normal compliance (1-A(|q| h))/|q| exceeds its value at
   !> a longer wave on [q_min, q_max] (1/L), sampled at 64 points per decade: 1 where it falls.
   pure real(wp) function compliance_rise(self, q_min, q_max) result(rise)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: q_min, q_max
      real(wp) :: q, lowest, current
      complex(wp) :: one_minus_a, one_minus_b, c, t
      integer :: i, samples
      rise = 1.0_wp
      if (self%halfspace .or. .not. q_max > q_min) return
      samples = max(2, ceiling(64*log10(q_max/q_min))) + 1
      lowest = huge(1.0_wp)
      do i = 0, samples - 1
         q = q_min*(q_max/q_min)**(real(i, wp)/(samples - 1))
         call self%factors(q, 0.0_wp, one_minus_a, one_minus_b, c, t)
         current = real(one_minus_a, wp)/q
         lowest = min(lowest, current)
         rise = max(rise, current/lowest)
      end do
   end function compliance_rise

   !> Normal compliance of the uniform mode, h/M = h (1+nu)(1-2nu)/((1-nu) E) (L/S) with the
   !> static compliance C0 = (1 - nu^2) J(0) given, summed over a stack's layers; 0 where a
   !> half-space lies below (no uniform mode) and exactly 0 for nu = 0.5.
   pure real(wp) function normal_uniform(self, c0)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: c0
      integer :: i
      normal_uniform = 0.0_wp
      if (self%unbounded()) return
      normal_uniform = self%thickness*(1.0_wp - 2.0_wp*self%poisson)/(1.0_wp - self%poisson)**2*c0
      if (.not. self%layered) return
      do i = 2, size(self%stack)
         associate (layer => self%stack(i))
            normal_uniform = normal_uniform + layer%thickness*(1.0_wp + layer%poisson)*(1.0_wp - 2.0_wp*layer%poisson) &
               & /((1.0_wp - layer%poisson)*real(layer%young, wp))
         end associate
      end do
   end function normal_uniform

   !> Shear compliance of the uniform mode, h/G = 2 h C0/(1 - nu) (L/S), summed over a
   !> stack's layers; 0 where a half-space lies below or an interface slips (the uniform
   !> tangential displacement is not defined there).
   pure real(wp) function shear_uniform(self, c0)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: c0
      integer :: i
      shear_uniform = 0.0_wp
      if (self%unbounded()) return
      if (self%layered) then
         if (any(self%stack%slip_below)) return
      end if
      shear_uniform = 2.0_wp*self%thickness*c0/(1.0_wp - self%poisson)
      if (.not. self%layered) return
      do i = 2, size(self%stack)
         associate (layer => self%stack(i))
            shear_uniform = shear_uniform + 2.0_wp*layer%thickness*(1.0_wp + layer%poisson)/real(layer%young, wp)
         end associate
      end do
   end function shear_uniform

   !> Whether a half-space lies below the surface (the layer is one, or the stack rests on
   !> one): the uniform mode has no finite compliance.
   pure logical function unbounded(self)
      class(layer_kernel), intent(in) :: self
      unbounded = self%halfspace
      if (self%layered) unbounded = self%base%kind == base_halfspace
   end function unbounded

   !> The coupling factor c of the longest waves (|q| -> 0) at rest: Dundurs' c of a
   !> half-space; for a stack on a half-space, its value at |q| H = 1e-9 (H the stack's
   !> depth; the limit is reached to O(|q| H)). It sets the uniform mode's in-plane surface
   !> stress where a half-space lies below.
   pure complex(wp) function long_wave_coupling(self) result(c)
      class(layer_kernel), intent(in) :: self
      complex(wp) :: one_minus_a, one_minus_b, t
      if (.not. self%layered) then
         c = halfspace_coupling(self%poisson)
         return
      end if
      call self%factors(1.0e-9_wp/sum(self%stack%thickness), 0.0_wp, one_minus_a, one_minus_b, c, t)
   end function long_wave_coupling

   !> Antiplane compliance 2 C t/((1-nu)|q|) = t/(G|q|) for |q| > 0, with the contact
   !> compliance C of the mode and the antiplane factor t of `factors` (tanh(|q|h) for one
   !> bonded layer).
   pure elemental complex(wp) function antiplane(self, q, c, t)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: q
      complex(wp), intent(in) :: c, t
      antiplane = 2.0_wp*c*t/((1.0_wp - self%poisson)*q)
   end function antiplane

   !> The 3x3 surface compliance in the (x, y, z) frame: (u_x^, u_y^, w^) = T (tau_x^, tau_y^,
   !> p^) for the wavevector (qx, qy) (1/L); q = 0 gives the uniform mode (h/G, h/G, h/M).
   pure function tensor(self, qx, qy) result(t)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: qx, qy
      complex(wp) :: t(3, 3)
      complex(wp) :: c(1)
      c = self%contact_compliance([qx])
      if (hypot(qx, qy) == 0.0_wp) then
         t = (0.0_wp, 0.0_wp)
         t(1, 1) = self%shear_uniform(real(c(1), wp))
         t(2, 2) = t(1, 1)
         t(3, 3) = self%normal_uniform(real(c(1), wp))
      else
         t = self%tensor_with(qx, qy, c(1))
      end if
   end function tensor

   !> The same for |q| > 0 with the mode's contact compliance C given (looked up once per
   !> column by the caller).
   pure function tensor_with(self, qx, qy, c) result(t)
      class(layer_kernel), intent(in) :: self
      real(wp), intent(in) :: qx, qy
      complex(wp), intent(in) :: c
      complex(wp) :: t(3, 3)
      complex(wp) :: plane, anti, one_minus_a, one_minus_b, coupling, factor_t
      real(wp) :: q, cx, cy
      q = hypot(qx, qy)
      cx = qx/q
      cy = qy/q
      call self%factors(q, qx, one_minus_a, one_minus_b, coupling, factor_t)
      plane = 2.0_wp*c/q
      anti = self%antiplane(q, c, factor_t)
      ! u_l = plane ((1-B) tau_l + i c p), u_t = anti tau_t, w = plane ((1-A) p - i c tau_l),
      ! with tau_l = cx tau_x + cy tau_y, tau_t = -cy tau_x + cx tau_y, u_x = cx u_l - cy u_t,
      ! u_y = cy u_l + cx u_t
      t(1, 1) = plane*one_minus_b*cx**2 + anti*cy**2
      t(1, 2) = (plane*one_minus_b - anti)*cx*cy
      t(2, 1) = t(1, 2)
      t(2, 2) = plane*one_minus_b*cy**2 + anti*cx**2
      t(1, 3) = plane*(0.0_wp, 1.0_wp)*coupling*cx
      t(2, 3) = plane*(0.0_wp, 1.0_wp)*coupling*cy
      t(3, 1) = -t(1, 3)
      t(3, 2) = -t(2, 3)
      t(3, 3) = plane*one_minus_a
   end function tensor_with
end module lc_greens_kernel
