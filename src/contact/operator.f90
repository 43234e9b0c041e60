!> The compliance operator of a scene: w = G_eff * p as a Fourier multiplier.
!>
!> Convention P (DESIGN.md §1): for a mode k of p(x) = sum_k p^(k) exp(i k x),
!>    w^(k) = 2/(E*|k|) [ (1-A) - i sgn(k) mu_c c ] p^(k),
!> and for a viscoelastic layer sliding at speed V (seed Eq. 14) 1/E* -> (1 - nu^2) J*(k V)
!> (lc_greens_viscoelastic),
!> with 1-A and c from seed Eqs. (7)-(9) (lc_greens_layer), tau = mu_c p. The k = 0
!> mode of a finite layer is h/M (M = E(1-nu)/((1+nu)(1-2nu)), zero for nu = 0.5); for
!> a half-space it is set to zero (the penetration is then measured from the mean
!> displacement).
!>
!> Only what the scene needs is built: a real multiplier when there is no coupling
!> (mu_c = 0, or a half-space with nu = 0.5), a complex one otherwise. The coupled
!> operator is split as G = M + (G - M) with the real, even, positive "metric"
!> M(k) = |G_eff(k)|: the symmetric solver works with M, the outer iteration with G - M.
!> With this metric the linearised outer map has eigenvalues exp(i arg G_eff(k)) on the
!> right half of the unit circle however strong the coupling or the viscoelastic loss
!> (DESIGN.md suggests the real part Re G_eff instead, whose map has eigenvalues
!> 1 - i Im G/Re G, up to ~300 in modulus for thin incompressible layers).
module lc_contact_operator
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp
   use lc_errors, only: error_type, fatal_error, code_input
   use lc_strings, only: to_string
   use lc_fft_plans, only: fft_plan, fft_threads_available
   use lc_greens_layer, only: layer_coefficients
   use lc_greens_viscoelastic, only: material_law, creep_compliance
   implicit none (type, external)
   private
   public :: compliance_operator, build_operator

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> The Fourier preconditioner of the inner CG is (|J*(kV)|/|J*(k1 V)|)^preconditioner_exponent/M:
   !> the exact inverse of the metric with exponent 0, which on a glassy layer (compliance
   !> falling by E_inf/E0 across the spectrum) amplifies the short waves so much that the
   !> contact set oscillates and the CG stalls; with exponent 1 (the elastic inverse) the
   !> preconditioned problem keeps a condition number ~E_inf/E0. Measured on 20 scenes
   !> (n = 8192, E_inf/E0 = 10 and 100, V = 0.003 .. 10, mu_c = 0 and 0.5, tol 1e-8): 1/2
   !> takes 2.6 s, exponent 0 8.0 s (18883 CG iterations on one scene against 2084), 1
   !> up to 20552 CG iterations on one. (The metric was |G_eff| (|J*(k1V)|/|J*(kV)|)^(1/2)
   !> before, which spread the outer map's eigenvalues in modulus: on
   !> inputs/sweeps/viscoelastic_speed.nml, 576 scenes, it failed 4 at tol 1e-8 and 6 at
   !> 1e-10 with 19021 outer iterations in all; |G_eff| with this preconditioner fails none
   !> at either tolerance, with 8155 outer iterations, in 50 s instead of 80.) Relative to
   !> k1, not k = 0, so that V -> 0 and V -> inf give back the elastic preconditioner.
   real(wp), parameter :: preconditioner_exponent = 0.5_wp

   !> Fourier multipliers of one scene and the FFT plans to apply them.
   type :: compliance_operator
      integer :: n = 0
      integer :: nk = 0
      real(wp) :: period = 1.0_wp
      real(wp) :: friction = 0.0_wp
      logical :: coupled = .false.          !< complex multiplier (not symmetric)
      real(wp), allocatable :: metric(:)    !< M(k) = |G_eff(k)|, k = 0..n/2 (L/S)
      real(wp) :: diagonal = 0.0_wp         !< real-space diagonal of the circulant M (L/S)
      !> largest |multiplier| of M and G_eff (L/S): sets the rounding noise of w = G p
      real(wp) :: largest = 0.0_wp
      real(wp) :: inv_n = 1.0_wp            !< 1/n, folded into the multipliers when applied
      complex(wp), allocatable :: compliance(:)   !< (1 - nu^2) J*(k V) per mode (1/S)
      !> Fourier preconditioner of the constrained CG: 1/M(k) with half the material's
      !> frequency dependence taken out (see preconditioner_exponent); 0 where M = 0 (k = 0
      !> of a half-space, or under load control)
      real(wp), allocatable :: preconditioner(:)
      logical :: viscoelastic = .false.     !< moving viscoelastic law: complex compliances
      logical :: monotone = .true.          !< Re G_eff(k) >= 0 for every mode (unique solution)
      complex(wp), allocatable :: full(:)   !< G_eff(k), only when coupled
      !> M in real space: (M p)(x_i) = sum_j column(i - j) p_j (L/S)
      real(wp), allocatable :: column(:)
      !> For the constrained GCR only (prepare_gcr): 1/G_eff(k) (0 where G_eff = 0), the
      !> real-space column of G_eff, and the real-space diagonal of 1/G_eff
      complex(wp), allocatable :: inverse_full(:)
      real(wp), allocatable :: full_column(:)
      real(wp) :: inverse_diagonal = 0.0_wp
      type(fft_plan) :: fft
   contains
      procedure :: apply_metric
      procedure :: apply_full
      procedure :: apply_difference
      procedure :: add_full_columns
      procedure :: metric_in_buffer
      procedure :: inverse_metric_in_buffer
      procedure :: prepare_gcr
      procedure :: full_in_buffer
      procedure :: inverse_full_in_buffer
      procedure :: drop_uniform_mode
      procedure :: wavenumber
   end type compliance_operator

contains

   !> Build the operator of a line contact: n points on a period, layer thickness
   !> (+Inf = half-space), material law (elastic: law%young) and Poisson ratio, Coulomb
   !> coefficient, sliding speed (for viscoelastic laws).
   subroutine build_operator(op, n, period, thickness, law, poisson, friction, speed, threads, error)
      type(compliance_operator), intent(out) :: op
      integer, intent(in) :: n, threads
      real(wp), intent(in) :: period, thickness, poisson, friction, speed
      type(material_law), intent(in) :: law
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: k, one_minus_a, one_minus_b, c
      complex(wp) :: g
      integer :: m
      logical :: halfspace

      if (threads > 1 .and. .not. fft_threads_available()) then
         call fatal_error(error, '&solver: threads > 1 needs a build with FFTW threads ' // &
            & '(meson option -Dopenmp=true, e.g. pip install . -Csetup-args=-Dopenmp=true); allowed here: threads = 1', &
            & code_input)
         return
      end if
      call op%fft%init(n, threads, error)
      if (allocated(error)) return
      op%n = n
      op%nk = n/2 + 1
      op%inv_n = 1.0_wp/n
      op%period = period
      op%friction = friction
      halfspace = .not. ieee_is_finite(thickness)
      ! (1 - nu^2) J*(k V) per mode: 1/E* for an elastic law. A viscoelastic law at rest is
      ! elastic with its static modulus: only a moving one needs complex compliances.
      op%viscoelastic = trim(law%model) /= 'elastic' .and. speed > 0.0_wp
      op%compliance = (1.0_wp - poisson**2)*creep_compliance(law, [(op%wavenumber(m)*speed, m = 0, op%nk - 1)])
      if (.not. all(ieee_is_finite(real(op%compliance, wp)) .and. ieee_is_finite(aimag(op%compliance)))) then
         call fatal_error(error, '&material: speed = ' // to_string(speed) // ' gives non-finite compliances ' // &
            & '(k V tau overflows); allowed: a speed with k V tau_max well inside the floating-point range', &
            & code_input)
         return
      end if
      ! A half-space of an incompressible material has c = 0: friction changes nothing.
      op%coupled = op%viscoelastic .or. (friction > 0.0_wp .and. .not. (halfspace .and. poisson == 0.5_wp))

      allocate (op%metric(op%nk))
      if (op%coupled) allocate (op%full(op%nk))
      if (halfspace) then
         op%metric(1) = 0.0_wp
      else
         ! h/M = h (1+nu)(1-2nu)/((1-nu) E) with the static compliance, exactly zero for nu = 0.5
         op%metric(1) = thickness*(1.0_wp - 2.0_wp*poisson)/(1.0_wp - poisson)**2*real(op%compliance(1), wp)
      end if
      if (op%coupled) op%full(1) = op%metric(1)

      do m = 1, op%nk - 1
         k = op%wavenumber(m)
         ! x = +Inf (half-space) gives 1-A = 1-B = 1 and Dundurs' c
         call layer_coefficients(k*thickness, poisson, one_minus_a, one_minus_b, c)
         g = 2.0_wp/k*op%compliance(m + 1)*cmplx(one_minus_a, -friction*c, kind=wp)
         ! sgn(k) = +1 on the half spectrum; the Nyquist mode is its own mirror image, so its
         ! multiplier is the mirror average (G(k) + G(-k))/2 = Re G(k)
         if (2*m == n) g = real(g, wp)
         op%metric(m + 1) = abs(g)
         if (op%coupled) op%full(m + 1) = g
      end do
      allocate (op%preconditioner(op%nk))
      where (op%metric > 0.0_wp)
         op%preconditioner = 1.0_wp/op%metric
      elsewhere
         op%preconditioner = 0.0_wp
      end where
      ! (an elastic law has one compliance: the factor is 1)
      if (op%viscoelastic) op%preconditioner = op%preconditioner* &
         & (abs(op%compliance)/abs(op%compliance(2)))**preconditioner_exponent
      ! The solution is unique when the operator is monotone, Re G_eff >= 0 on every mode
      ! (always for elastic layers; not always for viscoelastic ones with friction).
      op%monotone = .true.
      if (op%coupled) op%monotone = all(real(op%full, wp) >= 0.0_wp)
      call derive(op)
   end subroutine build_operator

   !> The quantities derived from the multipliers: diagonal, largest, column.
   subroutine derive(op)
      type(compliance_operator), intent(inout) :: op
      real(wp), allocatable :: unit_load(:)
      integer :: n
      n = op%n
      ! (1/n) sum over the whole spectrum: modes 1..ceil(n/2)-1 appear twice, Nyquist once
      op%diagonal = (op%metric(1) + 2*sum(op%metric(2:op%nk)) - merge(op%metric(op%nk), 0.0_wp, &
         & mod(n, 2) == 0))/n
      op%largest = maxval(op%metric)
      if (op%coupled) op%largest = max(op%largest, maxval(abs(op%full)))
      allocate (unit_load(n))
      unit_load = 0.0_wp
      unit_load(1) = 1.0_wp
      if (.not. allocated(op%column)) allocate (op%column(n))
      call op%apply_metric(unit_load, op%column)
   end subroutine derive

   !> Leave the uniform (k = 0) mode out of the operator and return its multiplier (h/M for
   !> a compressible layer, L/S). Under load control the uniform mode of p is the given
   !> p_m, so its displacement is a rigid shift that the constant s absorbs; without it w
   !> has the size of its fluctuations, and the rounding floor of the gap does not grow
   !> with the thickness (at h/lambda = 1e15, h p_m/M would hide every gap).
   subroutine drop_uniform_mode(self, uniform)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(out) :: uniform
      uniform = self%metric(1)
      if (uniform == 0.0_wp) return   ! half-space, incompressible layer
      self%metric(1) = 0.0_wp
      self%preconditioner(1) = 0.0_wp
      if (self%coupled) self%full(1) = 0.0_wp
      ! (derived afresh: subtracting uniform/n from the column would cancel catastrophically
      ! on thick layers, where it dominates)
      call derive(self)
   end subroutine drop_uniform_mode

   !> Wavenumber k = 2 pi m / period of mode index m (0..n/2).
   pure real(wp) function wavenumber(self, m)
      class(compliance_operator), intent(in) :: self
      integer, intent(in) :: m
      wavenumber = 2.0_wp*pi*m/self%period
   end function wavenumber

   !> w = M p with the real symmetric metric.
   subroutine apply_metric(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      call apply_real(self, self%metric, p, w)
   end subroutine apply_metric

   !> w = G_eff p with the full (possibly complex) multiplier.
   subroutine apply_full(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      if (self%coupled) then
         call apply_complex(self, self%full, p, w)
      else
         call apply_real(self, self%metric, p, w)
      end if
   end subroutine apply_full

   !> w = (G_eff - M) p, the part the outer iteration of a coupled problem carries.
   subroutine apply_difference(self, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      if (self%coupled) then
         call apply_complex(self, self%full - self%metric, p, w)
      else
         w = 0.0_wp
      end if
   end subroutine apply_difference

   !> w <- w + sum_j delta_j G_eff e_j over the points j with delta_j /= 0: the response to
   !> a few point loads, a pass over the grid each (after prepare_gcr).
   pure subroutine add_full_columns(self, delta, w)
      class(compliance_operator), intent(in) :: self
      real(wp), intent(in) :: delta(:)
      real(wp), intent(inout) :: w(:)
      integer :: j, n
      n = self%n
      do j = 1, n
         if (delta(j) == 0.0_wp) cycle
         ! column(i - j) for i = j..n is column(1..n-j+1); for i = 1..j-1 it wraps round
         w(j:n) = w(j:n) + delta(j)*self%full_column(1:n - j + 1)
         w(1:j - 1) = w(1:j - 1) + delta(j)*self%full_column(n - j + 2:n)
      end do
   end subroutine add_full_columns

   !> fft%real_buffer <- M fft%real_buffer: for a solver that writes its input into the
   !> buffer and reads the output from it (two passes over the grid fewer than apply_metric).
   !> energy = sum_j t_j (M t)_j for the input t, by Parseval from the spectrum (in the
   !> multiplying pass, so without a pass over the grid).
   subroutine metric_in_buffer(self, energy)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(out), optional :: energy
      if (present(energy)) then
         call self%fft%forward_unscaled()
         call multiply_with_energy(self%fft%spectrum, self%metric, self%inv_n, mod(self%n, 2) == 0, energy)
         call self%fft%backward()
      else
         call multiply_in_buffer(self, self%metric)
      end if
   end subroutine metric_in_buffer

   !> spectrum <- spectrum * multiplier/n, and energy = (1/n) sum over the whole spectrum of
   !> multiplier |spectrum|^2 (the modes 1..ceil(n/2)-1 of the half spectrum stand for two,
   !> k and -k; k = 0 and, for even n, the Nyquist mode for one).
   pure subroutine multiply_with_energy(spectrum, multiplier, inv_n, even, energy)
      complex(wp), intent(inout) :: spectrum(:)
      real(wp), intent(in) :: multiplier(:), inv_n
      logical, intent(in) :: even
      real(wp), intent(out) :: energy
      real(wp) :: f, twice, once
      integer :: m, nk
      nk = size(spectrum)
      once = multiplier(1)*inv_n*abs(spectrum(1))**2
      if (even .and. nk > 1) once = once + multiplier(nk)*inv_n*abs(spectrum(nk))**2
      twice = 0.0_wp
      !$omp simd reduction(+:twice) private(f)
      do m = 1, nk
         f = multiplier(m)*inv_n
         twice = twice + f*(real(spectrum(m), wp)**2 + aimag(spectrum(m))**2)
         spectrum(m) = spectrum(m)*f
      end do
      energy = 2.0_wp*twice - once
   end subroutine multiply_with_energy

   !> fft%real_buffer <- P fft%real_buffer with the preconditioner P (see metric_in_buffer).
   subroutine inverse_metric_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      call multiply_in_buffer(self, self%preconditioner)
   end subroutine inverse_metric_in_buffer

   !> What the constrained GCR needs besides G_eff (built on first use, after the uniform
   !> mode was dropped or not): its Fourier inverse, its real-space column and the
   !> real-space diagonal of the inverse.
   subroutine prepare_gcr(self)
      class(compliance_operator), intent(inout) :: self
      complex(wp), allocatable :: g(:)
      real(wp), allocatable :: unit_load(:)
      integer :: n
      n = self%n
      if (self%coupled) then
         g = self%full
      else
         g = cmplx(self%metric, 0.0_wp, kind=wp)
      end if
      if (allocated(self%inverse_full)) deallocate (self%inverse_full)
      allocate (self%inverse_full(self%nk), unit_load(n))
      where (abs(g) > 0.0_wp)
         self%inverse_full = 1.0_wp/g
      elsewhere
         self%inverse_full = (0.0_wp, 0.0_wp)
      end where
      unit_load = 0.0_wp
      unit_load(1) = 1.0_wp
      if (.not. allocated(self%full_column)) allocate (self%full_column(n))
      self%fft%real_buffer = unit_load
      call multiply_complex_in_buffer(self, g)
      self%full_column = self%fft%real_buffer
      self%fft%real_buffer = unit_load
      call multiply_complex_in_buffer(self, self%inverse_full)
      self%inverse_diagonal = self%fft%real_buffer(1)
   end subroutine prepare_gcr

   !> fft%real_buffer <- G_eff fft%real_buffer (see metric_in_buffer).
   subroutine full_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      if (self%coupled) then
         call multiply_complex_in_buffer(self, self%full)
      else
         call multiply_in_buffer(self, self%metric)
      end if
   end subroutine full_in_buffer

   !> fft%real_buffer <- G_eff^-1 fft%real_buffer (0 on the modes where G_eff = 0; after
   !> prepare_gcr).
   subroutine inverse_full_in_buffer(self)
      class(compliance_operator), intent(inout) :: self
      call multiply_complex_in_buffer(self, self%inverse_full)
   end subroutine inverse_full_in_buffer

   !> fft%real_buffer <- multiplier * fft%real_buffer with a complex multiplier.
   subroutine multiply_complex_in_buffer(self, multiplier)
      class(compliance_operator), intent(inout) :: self
      complex(wp), intent(in) :: multiplier(:)
      call self%fft%forward_unscaled()
      self%fft%spectrum = self%fft%spectrum*(multiplier*self%inv_n)
      call self%fft%backward()
   end subroutine multiply_complex_in_buffer

   !> w = multiplier * p through the plans; the 1/n of the forward transform is folded in.
   subroutine apply_real(self, multiplier, p, w)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: multiplier(:), p(:)
      real(wp), intent(out) :: w(:)
      self%fft%real_buffer = p
      call multiply_in_buffer(self, multiplier)
      w = self%fft%real_buffer
   end subroutine apply_real

   !> fft%real_buffer <- multiplier * fft%real_buffer.
   subroutine multiply_in_buffer(self, multiplier)
      class(compliance_operator), intent(inout) :: self
      real(wp), intent(in) :: multiplier(:)
      call self%fft%forward_unscaled()
      self%fft%spectrum = self%fft%spectrum*(multiplier*self%inv_n)
      call self%fft%backward()
   end subroutine multiply_in_buffer

   !> The same with a complex multiplier.
   subroutine apply_complex(self, multiplier, p, w)
      class(compliance_operator), intent(inout) :: self
      complex(wp), intent(in) :: multiplier(:)
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: w(:)
      self%fft%real_buffer = p
      call multiply_complex_in_buffer(self, multiplier)
      w = self%fft%real_buffer
   end subroutine apply_complex
end module lc_contact_operator
