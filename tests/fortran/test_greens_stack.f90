!> Tests of lc_greens_stack (surface compliance of layered stacks, docs/theory.md "Layered
!> stacks"): the single bonded layer against lc_greens_layer's closed form, N equal layers
!> against one, a layer of the substrate's material, thick and thin limits, a stiff substrate,
!> the frictionless rigid base against its closed form, the dense mode solve of the whole stack
!> (bonded and slipping, elastic and viscoelastic), reciprocity and positivity.
!> Prints one line per check; error stop 1 on any failure.
program test_greens_stack
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, code_input
   use lc_greens_layer, only: layer_coefficients, halfspace_coupling
   use lc_greens_stack, only: stack_layer, stack_base, stack_compliance, stack_compliance_lapack, &
      base_rigid, base_halfspace
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   !> Stack against a closed form (single layer, N equal layers, own material, frictionless
   !> base): the condensation costs a few rounding errors per layer (measured <= ~1e-14).
   real(wp), parameter :: tol_closed = 1.0e-12_wp
   !> Stack against the dense mode solve with |q|h_i in [0.02, 10]: the mode solve loses
   !> digits like eps/(|q|h)^2 in thin layers (lc_greens_layer), ~1e-12 at |q|h = 0.02.
   real(wp), parameter :: tol_modes = 1.0e-9_wp
   !> Thin- and thick-layer limits: the next terms are O(|q|h) and O(|q|h exp(-2|q|h)).
   real(wp), parameter :: tol_limit = 1.0e-5_wp
   !> Reciprocity c' = c: rounding only.
   real(wp), parameter :: tol_identity = 1.0e-13_wp
   real(wp), parameter :: nus(*) = [-0.5_wp, 0.0_wp, 0.3_wp, 0.45_wp, 0.49_wp, 0.5_wp]
   complex(wp), parameter :: i_unit = (0.0_wp, 1.0_wp)

   call check_single_layer()
   call check_equal_layers()
   call check_own_material()
   call check_limits()
   call check_stiff_substrate()
   call check_frictionless_base()
   call check_mode_solver()
   call check_symmetry_positivity()
   call check_invalid_input()
   call finish('stack compliance')

contains

   !> Distance between two compliances [1-B, i c; -i c', 1-A]: each entry relative to the scale
   !> sqrt(|(1-A)(1-B)|) of its row and column (c has genuine zeros).
   pure real(wp) function distance(p, r) result(d)
      complex(wp), intent(in) :: p(2, 2), r(2, 2)
      integer :: i, j
      d = 0
      do j = 1, 2
         do i = 1, 2
            d = max(d, abs(p(i, j) - r(i, j))/sqrt(abs(r(i, i)*r(j, j))))
         end do
      end do
   end function distance

   !> Convention P matrix of the factors 1-A, 1-B, c (c' = c).
   pure function p_matrix(one_minus_a, one_minus_b, c) result(p)
      real(wp), intent(in) :: one_minus_a, one_minus_b, c
      complex(wp) :: p(2, 2)
      p(1, 1) = one_minus_b
      p(1, 2) = i_unit*c
      p(2, 1) = -i_unit*c
      p(2, 2) = one_minus_a
   end function p_matrix

   !> Log-spaced |q|h samples, `per_decade` per decade from lo to hi.
   pure subroutine log_grid(lo, hi, per_decade, x)
      real(wp), intent(in) :: lo, hi
      integer, intent(in) :: per_decade
      real(wp), allocatable, intent(out) :: x(:)
      integer :: i, n
      n = nint(per_decade*log10(hi/lo)) + 1
      allocate (x(n))
      do i = 1, n
         x(i) = lo*(hi/lo)**(real(i - 1, wp)/(n - 1))
      end do
   end subroutine log_grid

   subroutine compliance(layers, base, q, plane, anti)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      real(wp), intent(in) :: q
      complex(wp), intent(out) :: plane(2, 2), anti
      type(error_type), allocatable :: error
      call stack_compliance(layers, base, q, plane, anti, error)
      if (allocated(error)) then
         call check(.false., 'stack_compliance: ' // error%message)
      end if
   end subroutine compliance

   subroutine check_single_layer()
      type(stack_layer) :: layer(1)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      real(wp) :: a, b, c, worst, worst_t
      complex(wp) :: plane(2, 2), anti
      integer :: i, j

      call log_grid(1.0e-6_wp, 1.0e6_wp, 8, xs)
      worst = 0
      worst_t = 0
      do j = 1, size(nus)
         layer(1)%poisson = nus(j)
         layer(1)%young = 2.5_wp
         do i = 1, size(xs)
            call compliance(layer, base, xs(i), plane, anti)
            call layer_coefficients(xs(i), nus(j), a, b, c)
            worst = max(worst, distance(plane, p_matrix(a, b, c)))
            worst_t = max(worst_t, abs(anti - tanh(xs(i)))/tanh(xs(i)))
         end do
      end do
      call check(worst <= tol_closed, 'one bonded layer on a rigid base == closed form (|q|h 1e-6..1e6)', worst)
      call check(worst_t <= tol_closed, 'one bonded layer: antiplane t == tanh(|q|h)', worst_t)
   end subroutine check_single_layer

   subroutine check_equal_layers()
      type(stack_layer), allocatable :: layers(:)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      real(wp) :: a, b, c, worst, worst_t
      complex(wp) :: plane(2, 2), anti
      integer :: i, j, k, n
      integer, parameter :: counts(*) = [2, 3, 7]

      call log_grid(1.0e-6_wp, 1.0e4_wp, 6, xs)
      worst = 0
      worst_t = 0
      do k = 1, size(counts)
         n = counts(k)
         if (allocated(layers)) deallocate (layers)
         allocate (layers(n))
         do j = 1, size(nus)
            layers%poisson = nus(j)
            layers%young = 0.7_wp
            do i = 1, size(xs)
               layers%thickness = 1.0_wp/n
               call compliance(layers, base, xs(i), plane, anti)
               call layer_coefficients(xs(i), nus(j), a, b, c)
               worst = max(worst, distance(plane, p_matrix(a, b, c)))
               worst_t = max(worst_t, abs(anti - tanh(xs(i)))/tanh(xs(i)))
            end do
         end do
      end do
      call check(worst <= tol_closed, '2, 3, 7 equal bonded layers of h/N == one layer of h', worst)
      call check(worst_t <= tol_closed, 'equal layers: antiplane', worst_t)
   end subroutine check_equal_layers

   subroutine check_own_material()
      type(stack_layer) :: layers(2)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      real(wp) :: worst, worst_t, slip_gap
      complex(wp) :: plane(2, 2), anti
      integer :: i, j

      call log_grid(1.0e-6_wp, 1.0e4_wp, 6, xs)
      base%kind = base_halfspace
      worst = 0
      worst_t = 0
      do j = 1, size(nus)
         base%poisson = nus(j)
         base%young = 3.0_wp
         layers%poisson = nus(j)
         layers%young = 3.0_wp
         layers%thickness = [0.4_wp, 0.6_wp]
         do i = 1, size(xs)
            call compliance(layers(1:1), base, xs(i), plane, anti)
            worst = max(worst, distance(plane, p_matrix(1.0_wp, 1.0_wp, halfspace_coupling(nus(j)))))
            worst_t = max(worst_t, abs(anti - 1))
            call compliance(layers, base, xs(i), plane, anti)
            worst = max(worst, distance(plane, p_matrix(1.0_wp, 1.0_wp, halfspace_coupling(nus(j)))))
            worst_t = max(worst_t, abs(anti - 1))
         end do
      end do
      call check(worst <= tol_closed, 'one and two bonded layers of the substrate''s material == half-space', worst)
      call check(worst_t <= tol_closed, 'the same, antiplane t == 1', worst_t)
      ! A slipping interface between equal materials is not the half-space.
      layers(1)%slip_below = .true.
      base%poisson = 0.3_wp
      layers%poisson = 0.3_wp
      call compliance(layers(1:1), base, 1.0_wp, plane, anti)
      slip_gap = distance(plane, p_matrix(1.0_wp, 1.0_wp, halfspace_coupling(0.3_wp)))
      call check(slip_gap > 1.0e-2_wp, 'a slipping interface in one material departs from the half-space (> 1e-2)', slip_gap)
   end subroutine check_own_material

   subroutine check_limits()
      type(stack_layer) :: layer(1)
      type(stack_base) :: base
      real(wp) :: worst_thick, worst_thin, ratio
      complex(wp) :: plane(2, 2), anti
      integer :: j

      base%kind = base_halfspace
      worst_thick = 0
      worst_thin = 0
      do j = 1, size(nus)
         layer(1)%poisson = nus(j)
         layer(1)%young = 1.0_wp
         base%poisson = nus(size(nus) + 1 - j)
         base%young = 7.0_wp
         ! Thick: the layer's own half-space.
         call compliance(layer, base, 1.0e4_wp, plane, anti)
         worst_thick = max(worst_thick, distance(plane, p_matrix(1.0_wp, 1.0_wp, halfspace_coupling(nus(j)))))
         worst_thick = max(worst_thick, abs(anti - 1))
         ! Thin: the substrate's half-space in units of the layer, E*_1/E*_s and G_1/G_s.
         call compliance(layer, base, 1.0e-8_wp, plane, anti)
         ratio = (1.0_wp/(1.0_wp - nus(j)**2))/(7.0_wp/(1.0_wp - base%poisson**2))
         worst_thin = max(worst_thin, distance(plane, ratio*p_matrix(1.0_wp, 1.0_wp, halfspace_coupling(base%poisson))))
         ratio = (1.0_wp/(1.0_wp + nus(j)))/(7.0_wp/(1.0_wp + base%poisson))
         worst_thin = max(worst_thin, abs(anti - ratio)/ratio)
      end do
      call check(worst_thick <= tol_closed, 'layer on a half-space, |q|h = 1e4: the layer''s half-space', worst_thick)
      call check(worst_thin <= tol_limit, 'layer on a half-space, |q|h = 1e-8: the substrate''s half-space', worst_thin)
   end subroutine check_limits

   subroutine check_stiff_substrate()
      type(stack_layer) :: layer(1)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      real(wp) :: a, b, c, worst
      complex(wp) :: plane(2, 2), anti
      integer :: i, j

      call log_grid(1.0e-2_wp, 1.0e4_wp, 6, xs)
      base%kind = base_halfspace
      base%young = 1.0e14_wp
      base%poisson = 0.3_wp
      worst = 0
      do j = 1, size(nus)
         layer(1)%poisson = nus(j)
         do i = 1, size(xs)
            call compliance(layer, base, xs(i), plane, anti)
            call layer_coefficients(xs(i), nus(j), a, b, c)
            worst = max(worst, distance(plane, p_matrix(a, b, c)))
         end do
      end do
      ! The substrate's own compliance enters at O(E/E_s) = 1e-14 relative to a compliance of
      ! the layer that is O(|q|h)^3 at nu = 0.5: 1e-8 relative at |q|h = 1e-2.
      call check(worst <= 1.0e-7_wp, 'layer on a half-space 1e14 times stiffer == rigid base', worst)
   end subroutine check_stiff_substrate

   !> Frictionless rigid base (derived in docs/theory.md): 1-A = S^2/(SC + x),
   !> 1-B = C^2/(SC + x), c = ((1-2nu) SC - x)/(2(1-nu)(SC + x)), independent of the mode solve.
   subroutine check_frictionless_base()
      type(stack_layer) :: layers(3)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      real(wp) :: a, b, c, worst, worst_t, s, co, sc, x, em, t, d
      complex(wp) :: plane(2, 2), anti
      integer :: i, j

      call log_grid(1.0e-6_wp, 1.0e4_wp, 6, xs)
      worst = 0
      worst_t = 0
      do j = 1, size(nus)
         do i = 1, size(xs)
            x = xs(i)
            if (x <= 20.0_wp) then
               s = sinh(x)
               co = cosh(x)
               sc = s*co
               d = sc + x
               a = s*s/d
               b = co*co/d
            else
               em = exp(-x)
               t = em*em
               sc = (1 - t)*(1 + t)
               d = sc + 4*x*t
               a = (1 - t)**2/d
               b = (1 + t)**2/d
            end if
            c = ((1 - 2*nus(j))*sc - (d - sc))/(2*(1 - nus(j))*d)
            layers(1)%poisson = nus(j)
            layers(1)%young = 4.0_wp
            layers(1)%slip_below = .true.
            call compliance(layers(1:1), base, x, plane, anti)
            worst = max(worst, distance(plane, p_matrix(a, b, c)))
            worst_t = max(worst_t, abs(anti - 1/tanh(x))*tanh(x))
            ! Three equal bonded layers on the same base.
            layers%poisson = nus(j)
            layers%young = 4.0_wp
            layers%thickness = 1.0_wp/3
            layers%slip_below = [.false., .false., .true.]
            call compliance(layers, base, x, plane, anti)
            worst = max(worst, distance(plane, p_matrix(a, b, c)))
            layers%thickness = 1.0_wp
         end do
      end do
      call check(worst <= tol_closed, 'frictionless rigid base == closed form (1 and 3 layers, |q|h 1e-6..1e4)', worst)
      call check(worst_t <= tol_closed, 'frictionless rigid base: antiplane t == coth(|q|h)', worst_t)
   end subroutine check_frictionless_base

   !> A family of stacks against the dense mode solve.
   subroutine check_mode_solver()
      type(stack_layer), allocatable :: layers(:)
      type(stack_base) :: base
      real(wp) :: worst(4), seed
      integer :: counts(4)
      character(len=12) :: tally
      real(wp), parameter :: qs(*) = [0.02_wp, 0.3_wp, 1.0_wp, 3.0_wp, 10.0_wp]
      integer :: n, iq, kind, slip, visco, trial, group, m
      character(len=*), parameter :: names(4) = [character(len=60) :: &
         'two equal layers, slipping interface', 'multilayers, bonded interfaces', &
         'multilayers, slipping interfaces', 'viscoelastic multilayers (complex moduli)']

      worst = 0
      counts = 0
      seed = 0.5_wp
      ! Two identical layers with a slipping interface, on every base.
      do kind = 1, 4
         allocate (layers(2))
         layers%poisson = 0.45_wp
         layers%young = 2.0_wp
         layers%thickness = 0.5_wp
         layers(1)%slip_below = .true.
         layers(2)%slip_below = kind > 2
         base%kind = merge(base_rigid, base_halfspace, mod(kind, 2) == 1)
         base%young = 5.0_wp
         base%poisson = 0.2_wp
         do iq = 1, size(qs)
            call compare(layers, base, qs(iq)*2, worst(1), counts(1))
         end do
         deallocate (layers)
      end do
      ! Pseudo-random stacks: 1 to 4 layers, every base, interfaces bonded or slipping.
      do trial = 1, 96
         n = 1 + mod(trial, 4)
         kind = 1 + mod(trial/4, 2)
         slip = mod(trial/8, 2)
         visco = mod(trial/16, 2)
         allocate (layers(n))
         do m = 1, n
            layers(m)%thickness = 0.2_wp + 2*next(seed)
            layers(m)%poisson = -0.5_wp + next(seed)
            if (next(seed) < 0.3_wp) layers(m)%poisson = 0.5_wp
            layers(m)%young = 10.0_wp**(2*next(seed) - 1)
            if (visco == 1) layers(m)%young = layers(m)%young*cmplx(1.0_wp, 1.5_wp*next(seed), wp)
            layers(m)%slip_below = slip == 1 .and. next(seed) < 0.6_wp
         end do
         base%kind = merge(base_rigid, base_halfspace, kind == 1)
         base%young = 10.0_wp**(2*next(seed) - 1)
         if (visco == 1) base%young = base%young*cmplx(1.0_wp, next(seed), wp)
         base%poisson = -0.5_wp + next(seed)
         group = 2 + slip
         if (visco == 1) group = 4
         do iq = 1, size(qs)
            call compare(layers, base, qs(iq)/maxval(layers%thickness)*min(1.0_wp, 5*minval(layers%thickness)), worst(group), &
                         counts(group))
         end do
         deallocate (layers)
      end do
      do m = 1, 4
         write (tally, '(a, i0, a)') ' (', counts(m), ' cases)'
         call check(worst(m) <= tol_modes .and. counts(m) >= 10, &
            & 'mode solve of the whole stack: '//trim(names(m))//trim(tally), worst(m))
      end do

   end subroutine check_mode_solver

   !> A deterministic sequence in [0, 1) for the pseudo-random stacks.
   real(wp) function next(seed)
      real(wp), intent(inout) :: seed
      seed = mod(seed*997.0_wp + 0.123456789_wp, 1.0_wp)
      next = seed
   end function next

   !> Stack against mode solve at |q| when every |q|h_i is in [0.02, 30]; worst distance kept.
   subroutine compare(layers, base, q, worst, count)
      type(stack_layer), intent(in) :: layers(:)
      type(stack_base), intent(in) :: base
      real(wp), intent(in) :: q
      real(wp), intent(inout) :: worst
      integer, intent(inout) :: count
      type(error_type), allocatable :: error
      complex(wp) :: plane(2, 2), anti, plane_ref(2, 2), anti_ref
      if (q*minval(layers%thickness) < 0.02_wp .or. q*maxval(layers%thickness) > 30.0_wp) return
      call compliance(layers, base, q, plane, anti)
      call stack_compliance_lapack(layers, base, q, plane_ref, anti_ref, error)
      if (allocated(error)) then
         call check(.false., 'mode solve: ' // error%message)
         return
      end if
      worst = max(worst, distance(plane, plane_ref), abs(anti - anti_ref)/abs(anti_ref))
      count = count + 1
   end subroutine compare

   subroutine check_symmetry_positivity()
      type(stack_layer) :: layers(3)
      type(stack_base) :: base
      real(wp), allocatable :: xs(:)
      complex(wp) :: plane(2, 2), anti
      real(wp) :: worst_rec, worst_im, lowest
      integer :: i, j, k

      call log_grid(1.0e-6_wp, 1.0e4_wp, 4, xs)
      worst_rec = 0
      worst_im = 0
      lowest = huge(1.0_wp)
      do k = 1, 8
         layers%thickness = [0.3_wp, 1.0_wp, 0.2_wp]
         layers%young = [1.0_wp, 20.0_wp, 0.1_wp]
         layers%slip_below = [mod(k, 2) == 1, mod(k/2, 2) == 1, .false.]
         base%kind = merge(base_rigid, base_halfspace, k <= 4)
         base%young = 3.0_wp
         base%poisson = 0.25_wp
         do j = 1, size(nus)
            layers%poisson = [nus(j), 0.3_wp, 0.5_wp]
            do i = 1, size(xs)
               call compliance(layers, base, xs(i), plane, anti)
               worst_rec = max(worst_rec, abs(plane(1, 2) + plane(2, 1))/sqrt(abs(plane(1, 1)*plane(2, 2))))
               worst_im = max(worst_im, abs(aimag(plane(1, 1))), abs(aimag(plane(2, 2))), abs(real(plane(1, 2))), &
                              abs(aimag(anti)))
               ! Positive normal compliance and a positive-definite 2x2 (Hermitian for elastic stacks).
               lowest = min(lowest, real(plane(2, 2), wp)/abs(plane(2, 2)), &
                            real(plane(1, 1)*plane(2, 2) - plane(1, 2)*plane(2, 1), wp)/abs(plane(1, 1)*plane(2, 2)), &
                            real(anti, wp)/abs(anti))
            end do
         end do
         ! Viscoelastic layers: reciprocity still holds (a symmetric, not Hermitian, operator).
         layers%young = [cmplx(1.0_wp, 0.8_wp, wp), cmplx(20.0_wp, 3.0_wp, wp), cmplx(0.1_wp, 0.2_wp, wp)]
         do i = 1, size(xs)
            call compliance(layers, base, xs(i), plane, anti)
            worst_rec = max(worst_rec, abs(plane(1, 2) + plane(2, 1))/sqrt(abs(plane(1, 1)*plane(2, 2))))
         end do
      end do
      call check(worst_rec <= 1.0e-10_wp, 'reciprocity: d u_l/d p == -d w/d tau_l (elastic and viscoelastic)', worst_rec)
      call check(worst_im <= 0.0_wp, 'elastic stacks: real 1-A, 1-B, c, t', worst_im)
      call check(lowest > 0.0_wp, 'elastic stacks: Re(1-A) > 0 and positive-definite 2x2 (smallest ratio)', lowest)
   end subroutine check_symmetry_positivity

   !> Invalid stacks are errors with code_input, never NaN.
   subroutine check_invalid_input()
      type(stack_layer) :: layer(1), none(0)
      type(stack_base) :: base
      type(error_type), allocatable :: error
      complex(wp) :: plane(2, 2), anti
      integer :: caught

      caught = 0
      call stack_compliance(none, base, 1.0_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      call stack_compliance(layer, base, 0.0_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      layer(1)%poisson = 0.6_wp
      call stack_compliance(layer, base, 1.0_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      layer(1)%poisson = 0.3_wp
      layer(1)%thickness = -1.0_wp
      call stack_compliance(layer, base, 1.0_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      layer(1)%thickness = 1.0_wp
      base%kind = base_halfspace
      base%young = -1.0_wp
      call stack_compliance(layer, base, 1.0_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      base%young = 1.0_wp
      call stack_compliance_lapack(layer, base, 1.0e-4_wp, plane, anti, error)
      if (allocated(error)) caught = caught + merge(1, 0, error%code == code_input)
      call check(caught == 6, 'invalid stacks and mode-solve ranges are input errors (6 of 6)', real(caught, wp))
   end subroutine check_invalid_input
end program test_greens_stack
