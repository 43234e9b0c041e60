!> Green's function molecular dynamics (GFMD): damped dynamics of the surface displacement
!> against a hard wall, with FIRE (Campañá and Müser, Phys. Rev. B 74, 075420, for GFMD;
!> Bitzek, Koskinen, Gähler, Moseler and Gumbsch, Phys. Rev. Lett. 97, 170201, for FIRE).
!>
!> The layer's normal response splits into the response to the pressure and to the friction
!> traction tau = mu_c p, w = G_n p + G_x tau (convention P, lc_contact_operator:
!> G_n = 2C(1-A)/|q|, G_x = -i 2C c q_x/|q|^2; G_eff = G_n + mu_c G_x). The surface
!> displacement u (= w) moves under the elastic force of the layer, the pressure
!> p = K_n (u - G_x tau) per mode (K_n = 1/G_n, symmetric for an elastic layer), and the
!> load; the rigid surface is a hard wall at a fixed position, u_j >= b_j + s, enforced by
!> projection after each step. Under load control the uniform mode of u has no stiffness
!> and the mean pressure p_m pushes the surface against the wall: p = K_n (u - G_x tau) + p_m.
!> The wall carries lambda = max(p, 0) where u touches it; the unbalanced pressure
!> rho = p - lambda drives the motion,
!>    m d2u/dt2 = -rho,
!> with one mass m for every node, the largest stiffness of a mode, so that the stiffest
!> mode has unit frequency (&solver gfmd_mass = 'one'); FIRE's damped semi-implicit Euler
!> steps integrate it. Or a mass per mode, its stiffness M(q) = |K_n(q)| (every mode at unit
!> frequency; 'mode'), on the free set F (the nodes off the wall and those it releases):
!>    d2u/dt2 = -P_F M^-1 rho,
!> which on the current F is the dynamics preconditioned by the symmetric positive
!> P_F M^-1 P_F (rho = 0 off F). With the wall as the projection alone the mass per mode
!> spreads a free node's force onto the contact nodes and FIRE's step collapses. One mass
!> is the Nyquist mode's stiffness, which doubles with the grid, and the modes a sparse
!> contact leaves free slow down with it: its steps grow with the grid there (200 to 410
!> from 64² to 1024² at 2 % contact); the mass per mode's stay flat or fall (210 to 140),
!> at two transform pairs a step: 'auto' takes it where that was measured cheaper
!> (takes_mode_mass; docs/decisions/001-gfmd-masses.md).
!>
!> Friction. For the dynamics the friction traction is an external in-plane load on the
!> contact nodes, held between updates, so the dynamics relaxes a symmetric problem (with tau in the stiffness, the
!> force mu_c p is a follower force and FIRE stalls once mu_c |G_x|/G_n passes ~0.5). The
!> traction is updated towards its fixed point tau = mu_c lambda whenever the dynamics has
!> relaxed the current problem to a fraction update_ratio of the update's own mismatch
!> max|mu_c lambda - tau| (an inexact inner relaxation; the velocities are kept). On a
!> fixed contact set C the fixed point is linear in tau, and its Jacobian I + mu_c S G_x
!> (S the inverse of G_n on C) has the eigenvalues 1 + i[-beta, beta] (beta = mu_c
!> |G_x|/G_n up to 4.7 on the paper's thin layers): the update is its Newton step, the
!> change of the wall's pressure solved on C with G_eff by GMRES (right-preconditioned by
!> the masked 1/G_eff, exact at full contact) to a fraction update_forcing of its right
!> side (an inexact Newton step), and the surface off C moves with it to the new
!> traction's equilibrium on C. The dynamics finds the contact set; on a fixed set one
!> update settles the traction, so the updates follow the set's changes: 1-13 on the
!> Fig. 3 family (docs/decisions/001-gfmd-masses.md, docs/numerics.md).
!>
!> Convergence is judged, as for the other solvers, on the complementarity residual of the
!> pressure the wall carries (p = lambda, w = G_eff lambda, gap = w - b - s), not on an
!> energy. A step costs one transform pair (two with the mass per mode), a check one more.
!>
!> On a surface shared among the ranks of an MPI job (an operator on a slab,
!> docs/decisions/023-mpi-slabs.md) every step is the same: the points' work on the slab,
!> the distributed transforms, and the sums and maxima over the ranks (FIRE's power and
!> norms in one message, the residual's, the update's test, the Gram matrix of the
!> Anderson mixing); every rank takes the same decisions from the same global numbers.
!>
!> The loss of a sliding viscoelastic layer gives G_n itself a phase, which no traction
!> update removes: gfmd_refusal measures |Im G_n|/Re G_n on the operator before any step
!> and refuses the scenes beyond max_stiffness_phase, and the friction ratio
!> mu_c |G_x|/|G_n| beyond max_friction_ratio, naming the methods that solve them.
module lc_contact_solver_gfmd
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_strings, only: formatted, to_string
   use lc_base_parallel, only: global_sum, global_max, global_any, sum_over_ranks, max_over_ranks
   use lc_contact_operator, only: compliance_operator
   use lc_contact_residual, only: complementarity_residual, rounding_floor
   use lc_contact_progress, only: progress_log
   use lc_contact_problem, only: contact_problem, contact_state, solve_outcome
   use lc_contact_solver, only: contact_solver
   implicit none (type, external)
   private
   public :: gfmd, gfmd_outcome, gfmd_solver, gfmd_refusal

   !> FIRE's parameters (Bitzek et al.): steps with positive power before the step grows,
   !> growth and shrink factors of the step, the initial and the decay of the mixing.
   integer, parameter :: fire_min_steps = 5
   real(wp), parameter :: fire_grow = 1.1_wp, fire_shrink = 0.5_wp
   real(wp), parameter :: fire_alpha0 = 0.1_wp, fire_alpha_decay = 0.99_wp
   !> Time step and its largest value, in units of 1/omega_max (the stiffest mode): the
   !> semi-implicit Euler step is stable below 2.
   real(wp), parameter :: dt_start = 0.25_wp, dt_max = 1.0_wp
   !> Steps between two convergence checks (a check costs one transform pair).
   integer, parameter :: check_interval = 10
   !> The largest |Im G_n|/Re G_n over the modes (the loss of a sliding viscoelastic
   !> layer): measured between the scenes that relax (ratio up to 0.47) and those that
   !> creep, stall or grow (from 0.61) (docs/decisions/001-gfmd-masses.md).
   real(wp), parameter :: max_stiffness_phase = 0.5_wp
   !> The largest friction ratio mu_c |G_x|/|G_n| over the modes that the traction update
   !> relaxes: on the thinnest layer (h/lambda = 0.01) at 64² and 128² every load measured
   !> converges at 5.96 (0.2 % to full contact) and 6.44 (33-71 %), the dynamics diverges
   !> at half contact from 6.92 (at 32-42 % from 9.54, 22 % from 11.9, 15 % from 16.7); the
   !> limit keeps 13 % below the first divergence and above the Fig. 3 family's 4.68
   !> (docs/decisions/001-gfmd-masses.md).
   real(wp), parameter :: max_friction_ratio = 6.0_wp
   !> The traction is updated once the largest unbalanced pressure is below this fraction
   !> of the update's mismatch max|mu_c lambda - tau| (measured, the Fig. 3 surface at 64²,
   !> h/lambda = 0.05, mu_c = 1, 0.7 / 2 / 32 / 100 % contact: 451 / 344 / 338 / 62
   !> transform pairs at 0.01, 512 / 404 / 334 / 54 at 0.03, 688 / 482 / 293 / 52 at 0.1,
   !> 434 / 359 / 358 / 67 at 0.003), or after update_max_steps steps at the latest.
   real(wp), parameter :: update_ratio = 0.01_wp
   integer, parameter :: update_max_steps = 500
   !> Most GMRES steps of a Newton step of the traction, and the fraction of its right
   !> side's norm it stops at (measured as above: 0.3 takes 451 / 410 / 532 / 66 pairs,
   !> the steps of the dynamics growing where the traction is solved less well).
   integer, parameter :: update_krylov = 10
   real(wp), parameter :: update_forcing = 0.1_wp
   !> &solver gfmd_mass = 'auto' takes the mass per mode on surfaces of at least
   !> mode_mass_points points whose start has contact on at most mode_mass_contact of the
   !> surface (takes_mode_mass), where it was measured to take fewer transform pairs than one mass (the Fig. 3
   !> surface, h/lambda = 0.05 and 0.16, mu_c = 0, 0.5 and 1, tol 1e-8): at ~2 % contact
   !> 1.08 / 0.89 / 0.75 times one mass's pairs at 256² / 512² / 1024² (six scenes summed;
   !> 0.79 at 2048², frictionless), at 0.5 % 0.82 and 0.75 at 512² and 1024², but 1.08 and
   !> 1.24 at 6.6 % and 1.08-1.88 at 22-32 % (docs/decisions/001-gfmd-masses.md). The
   !> limit 4 % lies between 2.3 % (cheaper) and 6.6 % (not).
   real(wp), parameter :: mode_mass_points = 262144.0_wp, mode_mass_contact = 0.04_wp

   !> What one GFMD solve did.
   type :: gfmd_outcome
      logical :: converged = .false.
      integer :: iterations = 0      !< time steps
      integer :: updates = 0         !< updates of the friction traction
      integer :: checks = 0          !< convergence checks (the entries of the history)
      integer :: fft_pairs = 0
      real(wp) :: residual = huge(1.0_wp)
   end type gfmd_outcome


   !> Method 'gfmd': damped dynamics of the normal displacement.
   type, extends(contact_solver) :: gfmd_solver
   contains
      procedure :: solve => solve_by_gfmd
      procedure :: name => gfmd_name
   end type gfmd_solver

contains

   !> Solve the contact problem w = G_eff p, gap = w - b - s >= 0, p >= 0, p gap = 0 (load
   !> control: mean(p) = p_m, s found; displacement control: s given). p: starting guess in,
   !> solution out (the best checked state if not converged); w = G_eff p; gap.
   !> history(k) receives the residual of the k-th check (every check_interval steps) when
   !> present.
   subroutine gfmd(op, b, load_control, mean_pressure, s, g_ref, tol, max_iter, p, w, gap, outcome, error, &
         & history, progress, mode_mass)
      type(compliance_operator), intent(inout) :: op
      real(wp), contiguous, intent(in) :: b(:)
      logical, intent(in) :: load_control
      real(wp), intent(in) :: mean_pressure
      real(wp), intent(inout) :: s
      real(wp), intent(in) :: g_ref, tol
      integer, intent(in) :: max_iter
      real(wp), contiguous, intent(inout) :: p(:)
      real(wp), contiguous, intent(out) :: w(:), gap(:)
      type(gfmd_outcome), intent(out) :: outcome
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(inout), optional :: history(:)
      type(progress_log), intent(inout), optional :: progress
      !> a mass per mode on the free set (mode_mass) instead of one mass for every node
      logical, intent(in), optional :: mode_mass
      complex(wp), allocatable :: normal(:), tangential(:), stiffness(:), coupling(:), inverse_full(:)
      complex(wp), allocatable :: inverse_mass(:)
      real(wp), allocatable :: u(:), v(:), a(:), lambda(:), p_best(:)
      real(wp), allocatable :: tau(:), offset(:), basis(:, :), change(:), response(:)
      logical, allocatable :: inside(:)
      real(wp), pointer, contiguous :: buffer(:)
      real(wp) :: dt, alpha, power, v_norm, a_norm, s_best, uniform, b_max, mass, residual, friction
      real(wp) :: imbalance, mismatch, mismatch_floor, contact_points, points, sums(3), maxima(2)
      integer :: step, since_negative, checks, n, j, since_update
      logical :: with_traction, across_ranks, per_mode

      n = size(p)
      across_ranks = op%distributed
      points = real(op%grid%points(), wp)
      friction = op%friction
      call split_multiplier(op, normal, tangential)
      with_traction = friction > 0.0_wp .and. any(tangential /= (0.0_wp, 0.0_wp))
      if (across_ranks) with_traction = global_any(with_traction)
      allocate (stiffness(size(normal)), coupling(size(normal)))
      where (normal /= (0.0_wp, 0.0_wp))
         stiffness = 1.0_wp/normal
         coupling = tangential/normal
      elsewhere
         stiffness = (0.0_wp, 0.0_wp)
         coupling = (0.0_wp, 0.0_wp)
      end where
      deallocate (normal)   ! (the solve's memory: stiffness, coupling and, with friction, G_x)
      if (with_traction) then
         ! 1/G_eff = K_n/(1 + mu_c G_x/G_n), the Newton step's preconditioner (0 where K_n = 0)
         allocate (inverse_full(size(stiffness)))
         inverse_full = stiffness/(1.0_wp + friction*coupling)
      else
         deallocate (tangential)
      end if
      buffer => op%buffer()
      allocate (u(n), v(n), a(n), lambda(n), tau(n), offset(n))
      maxima = [maxval(abs(b)), maxval(abs(stiffness))]
      if (across_ranks) call max_over_ranks(maxima)
      b_max = maxima(1)
      mass = maxima(2)
      per_mode = .false.
      if (present(mode_mass)) per_mode = mode_mass
      if (per_mode) then
         ! the mass of a mode its stiffness |K_n(q)| (every mode at unit frequency); the
         ! modes without stiffness (the uniform mode under load control) get the smallest
         call mode_masses(stiffness, across_ranks, inverse_mass)
         mass = 1.0_wp
      end if
      uniform = merge(mean_pressure, 0.0_wp, load_control)
      ! start from the displacement of the guess (its friction traction held); under load
      ! control the wall is placed where it touches the highest point of the gap, and the
      ! load moves the surface
      p = max(p, 0.0_wp)
      call op%apply_full(p, u)
      outcome%fft_pairs = outcome%fft_pairs + 1
      tau = 0.0_wp
      offset = 0.0_wp
      if (with_traction) then
         tau = friction*p
         buffer = tau
         call op%multiply_complex_in_buffer(coupling)
         offset = buffer
         outcome%fft_pairs = outcome%fft_pairs + 1
         allocate (basis(n, update_krylov + 1), change(n), response(n), inside(n))
      end if
      if (load_control) then
         s = minval(u - b)
         if (across_ranks) s = -global_max(-s)
      end if
      u = max(u, b + s)
      v = 0.0_wp
      dt = dt_start
      alpha = fire_alpha0
      since_negative = 0
      since_update = 0
      checks = 0
      p_best = p
      s_best = s
      ! below this mismatch the traction is left as it is (the residual's rounding level)
      mismatch_floor = maxval(p)
      if (across_ranks) mismatch_floor = global_max(mismatch_floor)
      mismatch_floor = 0.01_wp*tol*max(mean_pressure, mismatch_floor, tiny(1.0_wp))*friction

      do step = 1, max_iter
         ! the layer's reaction p = K_n u - K_n G_x tau (+ p_m), what the wall carries and
         ! what is left
         buffer = u
         call op%multiply_complex_in_buffer(stiffness)
         outcome%fft_pairs = outcome%fft_pairs + 1
         !$omp simd
         do j = 1, n
            buffer(j) = buffer(j) - offset(j) + uniform
            lambda(j) = merge(max(buffer(j), 0.0_wp), 0.0_wp, u(j) <= b(j) + s)
            a(j) = -(buffer(j) - lambda(j))/mass   ! -rho/m
         end do
         if (with_traction) imbalance = mass*maxval(abs(a))   ! max |rho|
         if (per_mode) then
            ! a = P_F M^-1 (-rho): the mass per mode's multiplier, then the free set F, the
            ! nodes off the wall and those it releases (p < 0); on the others rho = 0, so
            ! that rho = P_F rho already. One more transform pair: the wall's reaction (the
            ! mask of the contact nodes) sits between K_n and M^-1, and the mask of F
            ! between M^-1 and the next step's K_n (docs/decisions/001-gfmd-masses.md)
            buffer = a
            call op%multiply_complex_in_buffer(inverse_mass)
            outcome%fft_pairs = outcome%fft_pairs + 1
            !$omp simd
            do j = 1, n
               a(j) = merge(buffer(j), 0.0_wp, u(j) > b(j) + s .or. a(j) /= 0.0_wp)
            end do
         end if
         ! FIRE: mix the velocity towards the force, grow the step while the power is
         ! positive, stop and shrink it when it turns negative
         ! (the power and the two norms in one sum over the ranks)
         sums = [dot_product(v, a), dot_product(v, v), dot_product(a, a)]
         if (across_ranks) call sum_over_ranks(sums)
         power = sums(1)
         if (power > 0.0_wp) then
            v_norm = sqrt(sums(2))
            a_norm = sqrt(sums(3))
            if (a_norm > 0.0_wp) v = (1.0_wp - alpha)*v + (alpha*v_norm/a_norm)*a
            since_negative = since_negative + 1
            if (since_negative > fire_min_steps) then
               dt = min(dt*fire_grow, dt_max)
               alpha = alpha*fire_alpha_decay
            end if
         else
            v = 0.0_wp
            dt = dt*fire_shrink
            alpha = fire_alpha0
            since_negative = 0
         end if
         ! the step, and the hard wall
         !$omp simd
         do j = 1, n
            v(j) = v(j) + dt*a(j)
            u(j) = u(j) + dt*v(j)
            if (u(j) < b(j) + s) then
               u(j) = b(j) + s
               v(j) = max(v(j), 0.0_wp)
            end if
         end do
         outcome%iterations = step

         if (mod(step, check_interval) == 0 .or. step == max_iter .or. .not. ieee_is_finite(power)) then
            call check(lambda, residual)
            checks = checks + 1
            if (present(history)) then
               if (checks <= size(history)) history(checks) = residual
            end if
            if (present(progress)) then
               if (progress%enabled) call progress%tick(step, residual, contacts(lambda)/points)
            end if
            if (residual < outcome%residual) then
               outcome%residual = residual
               p_best = lambda
               s_best = s
            end if
            ! (a dynamics that blew up cannot recover)
            if (residual <= tol .or. .not. ieee_is_finite(power)) exit
         end if

         if (with_traction) then
            ! the dynamics has relaxed the problem of the current traction well enough
            ! against what the traction itself is off by: update it
            since_update = since_update + 1
            maxima = [imbalance, maxval(abs(friction*lambda - tau))]   ! max |rho|, the mismatch
            if (across_ranks) call max_over_ranks(maxima)
            imbalance = maxima(1)
            mismatch = maxima(2)
            if (mismatch > mismatch_floor .and. &
               & (imbalance <= update_ratio*mismatch .or. since_update >= update_max_steps)) then
               call update_traction()
               since_update = 0
            end if
         end if
      end do
      outcome%converged = outcome%residual <= tol
      outcome%checks = checks
      p = p_best
      s = s_best
      call op%apply_full(p, w)
      outcome%fft_pairs = outcome%fft_pairs + 1
      if (load_control) call contact_shift(p, w, b, s, across_ranks)
      gap = w - b - s
   contains
      !> The residual of the pressure the wall carries: w = G_eff lambda, s of the contact set.
      subroutine check(pressure, res)
         real(wp), intent(in) :: pressure(:)
         real(wp), intent(out) :: res
         real(wp) :: shift, p_ref, mean, largest(2)
         call op%apply_full(pressure, w)
         outcome%fft_pairs = outcome%fft_pairs + 1
         shift = s
         if (load_control) call contact_shift(pressure, w, b, shift, across_ranks)
         gap = w - b - shift
         mean = sum(pressure)
         largest = [maxval(abs(w)), maxval(pressure)]
         if (across_ranks) then
            mean = global_sum(mean)
            call max_over_ranks(largest)
         end if
         mean = mean/points
         p_ref = merge(mean_pressure, mean, load_control)
         res = complementarity_residual(pressure, gap, p_ref, g_ref, &
            & rounding_floor(largest(1), b_max, largest(2), op%largest))
         if (across_ranks) res = global_max(res)
         ! the load the wall carries must be the given one
         if (load_control) res = max(res, abs(mean - mean_pressure)/mean_pressure)
      end subroutine check

      !> The contact points (lambda > 0) of the whole surface.
      real(wp) function contacts(pressure)
         real(wp), intent(in) :: pressure(:)
         contacts = real(count(pressure > 0.0_wp), wp)
         if (across_ranks) contacts = global_sum(contacts)
      end function contacts

      !> The Newton step of the traction on the current contact set C (lambda > 0), and the
      !> surface moved with it. On C the wall's pressure answers a change d of the traction
      !> by y = -S G_x d (S the inverse of G_n on C, the load held), so tau + d = mu_c
      !> (lambda + y) asks for
      !>    G_eff y + c = -G_x r on C,  sum(y) = 0 under load control (c = 0 otherwise),
      !> r = mu_c lambda - tau, solved by GMRES on C to update_forcing of its right side;
      !> then tau <- mu_c (lambda + y) on C (0 off it), and the surface off C moves by the
      !> displacement of the two changes, du = G_eff y + G_x r - c, so that the dynamics
      !> continues from the new traction's equilibrium on C. Transform pairs: one for G_x r,
      !> two a GMRES step and one more for its solution, one for du, one for the offset.
      subroutine update_traction()
         real(wp) :: shift
         integer :: pairs
         outcome%updates = outcome%updates + 1
         inside = lambda > 0.0_wp
         contact_points = real(count(inside), wp)
         if (across_ranks) contact_points = global_sum(contact_points)
         if (contact_points == 0.0_wp) return
         !$omp simd
         do j = 1, n
            buffer(j) = friction*lambda(j) - tau(j)
         end do
         call op%multiply_complex_in_buffer(tangential)
         response = buffer   ! G_x r
         change = merge(-response, 0.0_wp, inside)
         call remove_contact_mean(change)
         call gmres_on_contact(change, pairs)
         buffer = change
         call op%full_in_buffer()
         response = response + buffer   ! du + c = G_eff y + G_x r, = c on C
         shift = 0.0_wp
         if (load_control) then
            shift = sum(response, mask=inside)
            if (across_ranks) shift = global_sum(shift)
            shift = shift/contact_points
         end if
         !$omp simd
         do j = 1, n
            if (.not. inside(j)) u(j) = max(u(j) + response(j) - shift, b(j) + s)
            tau(j) = merge(friction*(lambda(j) + change(j)), 0.0_wp, inside(j))
         end do
         buffer = tau
         call op%multiply_complex_in_buffer(coupling)
         offset = buffer
         outcome%fft_pairs = outcome%fft_pairs + pairs + 3
      end subroutine update_traction

      !> x <- x less its mean over C under load control (the load held: the constant c).
      subroutine remove_contact_mean(x)
         real(wp), intent(inout) :: x(:)
         real(wp) :: total
         if (.not. load_control) return
         total = sum(x, mask=inside)
         if (across_ranks) total = global_sum(total)
         where (inside) x = x - total/contact_points
      end subroutine remove_contact_mean

      !> x <- the solution of Pi G_eff x = x on C (Pi: onto C, less the mean under load
      !> control) by GMRES right-preconditioned by Pi G_eff^-1 (exact at full contact), at
      !> most update_krylov steps, to update_forcing of the right side's norm; pairs: the
      !> transform pairs it took.
      subroutine gmres_on_contact(x, pairs)
         real(wp), intent(inout) :: x(:)
         integer, intent(out) :: pairs
         real(wp) :: h(update_krylov + 1, update_krylov), g(update_krylov + 1), z(update_krylov + 1)
         real(wp) :: cs(update_krylov), sn(update_krylov), column(update_krylov + 1)
         real(wp) :: norm0, rotated, subdiagonal
         integer :: k, i
         pairs = 0
         norm0 = norm(x)
         if (norm0 == 0.0_wp) return
         basis(:, 1) = x/norm0
         g = 0.0_wp
         g(1) = norm0
         h = 0.0_wp
         do k = 1, update_krylov
            buffer = basis(:, k)
            call precondition()
            call op%full_in_buffer()
            pairs = pairs + 2
            x = merge(buffer, 0.0_wp, inside)
            call remove_contact_mean(x)
            ! classical Gram-Schmidt, twice (one sum over the ranks each)
            column = 0.0_wp
            do i = 1, 2
               z(1:k) = matmul(x, basis(:, 1:k))
               if (across_ranks) call sum_over_ranks(z(1:k))
               x = x - matmul(basis(:, 1:k), z(1:k))
               column(1:k) = column(1:k) + z(1:k)
            end do
            subdiagonal = norm(x)
            column(k + 1) = subdiagonal
            ! the Givens rotations of the earlier columns, and this column's
            do i = 1, k - 1
               rotated = cs(i)*column(i) + sn(i)*column(i + 1)
               column(i + 1) = -sn(i)*column(i) + cs(i)*column(i + 1)
               column(i) = rotated
            end do
            rotated = hypot(column(k), column(k + 1))
            cs(k) = column(k)/rotated
            sn(k) = column(k + 1)/rotated
            column(k) = rotated
            g(k + 1) = -sn(k)*g(k)
            g(k) = cs(k)*g(k)
            h(1:k, k) = column(1:k)
            if (abs(g(k + 1)) <= update_forcing*norm0 .or. k == update_krylov) exit
            basis(:, k + 1) = x/subdiagonal
         end do
         do i = k, 1, -1
            z(i) = (g(i) - dot_product(h(i, i + 1:k), z(i + 1:k)))/h(i, i)
         end do
         buffer = matmul(basis(:, 1:k), z(1:k))
         call precondition()
         pairs = pairs + 1
         x = buffer
      end subroutine gmres_on_contact

      !> buffer <- Pi G_eff^-1 buffer.
      subroutine precondition()
         call op%multiply_complex_in_buffer(inverse_full)
         !$omp simd
         do j = 1, n
            if (.not. inside(j)) buffer(j) = 0.0_wp
         end do
         call remove_contact_mean(buffer)
      end subroutine precondition

      !> The Euclidean norm of x over the whole surface.
      real(wp) function norm(x)
         real(wp), intent(in) :: x(:)
         norm = dot_product(x, x)
         if (across_ranks) norm = global_sum(norm)
         norm = sqrt(norm)
      end function norm
   end subroutine gfmd

   !> The operator's multiplier split into the normal response to the pressure, G_n, and
   !> to the friction traction, G_x: G_eff = G_n + mu_c G_x (the operator's modes; G_x = 0
   !> for a symmetric operator). Where the layer's factors 1-A and c are real (one layer,
   !> or a stack of elastic layers) G_eff/C = (2/|q|)((1-A) - i mu_c c q_x/|q|) splits into
   !> its real and imaginary parts, from the operator's multiplier alone; elsewhere, and on
   !> a Nyquist column (whose multiplier is the mirror average, the real part, of each),
   !> from the layer's factors. The uniform mode is the operator's.
   subroutine split_multiplier(op, normal, tangential)
      type(compliance_operator), intent(in) :: op
      complex(wp), allocatable, intent(out) :: normal(:), tangential(:)
      complex(wp) :: one_minus_a, one_minus_b, c, t, compliance, reduced
      real(wp) :: qx, qy, q
      integer :: i, mx, my
      logical :: real_factors
      allocate (normal(op%nk), tangential(op%nk))
      tangential = (0.0_wp, 0.0_wp)
      if (.not. op%coupled) then
         normal = op%metric
         return
      end if
      real_factors = .not. (op%kernel%layered .and. op%kernel%viscoelastic)
      do i = 1, op%nk
         call op%fft%mode_indices(i, mx, my)
         if (mx == 0 .and. my == 0) then
            ! (the uniform mode: the first of the rank that holds it)
            normal(i) = op%full(i)
            cycle
         end if
         call op%column_mode(i, qx, qy, mx)
         compliance = op%compliance(mx + 1)
         if (real_factors .and. 2*mx /= op%grid%nx .and. compliance /= (0.0_wp, 0.0_wp)) then
            reduced = op%full(i)/compliance
            normal(i) = compliance*real(reduced, wp)
            if (op%friction > 0.0_wp) tangential(i) = compliance*cmplx(0.0_wp, aimag(reduced), wp)/op%friction
            cycle
         end if
         q = hypot(qx, qy)
         call op%kernel%factors(q, qx, one_minus_a, one_minus_b, c, t)
         normal(i) = 2.0_wp/q*compliance*one_minus_a
         tangential(i) = -(0.0_wp, 2.0_wp)/q*compliance*c*(qx/q)
         if (2*mx == op%grid%nx) then
            normal(i) = real(normal(i), wp)
            tangential(i) = real(tangential(i), wp)
         end if
      end do
   end subroutine split_multiplier

   !> Why the damped dynamics cannot relax the scene of `op` ('' if it can): the ratio
   !> |Im G_n|/Re G_n of some mode exceeds max_stiffness_phase (the loss of a sliding
   !> viscoelastic layer), or the friction ratio mu_c |G_x|/|G_n| exceeds max_friction_ratio.
   !> (On a slab, the largest over the ranks' modes: every rank gives the same answer.)
   function gfmd_refusal(op) result(refusal)
      type(compliance_operator), intent(in) :: op
      character(len=:), allocatable :: refusal
      complex(wp), allocatable :: normal(:), tangential(:)
      real(wp) :: ratio
      refusal = ''
      if (.not. op%coupled) return
      call split_multiplier(op, normal, tangential)
      ratio = stiffness_phase(normal)
      if (op%distributed) ratio = global_max(ratio)
      if (ratio > max_stiffness_phase) then
         if (ratio < huge(1.0_wp)) then
            refusal = "its stiffness 1/G_n (the layer's normal response without friction) is far from symmetric, " // &
               & '|Im G_n|/Re G_n reaches ' // formatted(ratio, '(g0.3)') // ' on a mode'
         else
            refusal = "its stiffness 1/G_n (the layer's normal response without friction) is far from symmetric, " // &
               & 'Re G_n <= 0 on a mode'
         end if
         refusal = refusal // ' (the loss acts as a follower force; the damped dynamics relaxes up to ' // &
            & formatted(max_stiffness_phase, '(g0.2)') // ')'
         return
      end if
      ratio = op%friction*friction_ratio(normal, tangential)
      if (op%distributed) ratio = global_max(ratio)
      if (ratio > max_friction_ratio) then
         refusal = 'its friction ratio mu_c |G_x|/|G_n| (the normal response to the friction traction against ' // &
            & 'that to the pressure) reaches ' // formatted(ratio, '(g0.3)') // &
            & ' on a mode; the update of the friction traction converges up to ' // &
            & formatted(max_friction_ratio, '(g0.2)')
      end if
   end function gfmd_refusal

   !> 1/M(q) of the mass per mode M(q) = |K_n(q)|, the modes with K_n = 0 (the uniform mode
   !> under load control) given the smallest nonzero |K_n| of the grid (on a slab: of every
   !> rank's modes).
   subroutine mode_masses(stiffness, across_ranks, inverse_mass)
      complex(wp), intent(in) :: stiffness(:)
      logical, intent(in) :: across_ranks
      complex(wp), allocatable, intent(out) :: inverse_mass(:)
      real(wp) :: smallest
      smallest = minval(abs(stiffness), mask=abs(stiffness) > 0.0_wp)   ! (huge on a rank without any)
      if (across_ranks) smallest = -global_max(-smallest)
      allocate (inverse_mass(size(stiffness)))
      where (abs(stiffness) > 0.0_wp)
         inverse_mass = 1.0_wp/abs(stiffness)
      elsewhere
         inverse_mass = 1.0_wp/smallest
      end where
   end subroutine mode_masses

   !> The largest |Im g|/Re g over the multipliers g /= 0 (huge where Re g <= 0).
   pure real(wp) function stiffness_phase(g) result(ratio)
      complex(wp), intent(in) :: g(:)
      integer :: i
      ratio = 0.0_wp
      do i = 1, size(g)
         if (g(i) == (0.0_wp, 0.0_wp)) cycle
         if (real(g(i), wp) <= 0.0_wp) then
            ratio = huge(1.0_wp)
            return
         end if
         ratio = max(ratio, abs(aimag(g(i)))/real(g(i), wp))
      end do
   end function stiffness_phase

   !> The largest |g_x|/|g_n| over the modes with g_n /= 0.
   pure real(wp) function friction_ratio(g_n, g_x) result(ratio)
      complex(wp), intent(in) :: g_n(:), g_x(:)
      integer :: i
      ratio = 0.0_wp
      do i = 1, size(g_n)
         if (g_n(i) /= (0.0_wp, 0.0_wp)) ratio = max(ratio, abs(g_x(i))/abs(g_n(i)))
      end do
   end function friction_ratio

   !> s = the mean of w - b over the contact set (p > 0): the wall position the contact
   !> points agree on (unchanged without contact); `across_ranks`: over the job's slabs.
   subroutine contact_shift(p, w, b, s, across_ranks)
      real(wp), intent(in) :: p(:), w(:), b(:)
      real(wp), intent(inout) :: s
      logical, intent(in) :: across_ranks
      real(wp) :: sums(2)
      sums = [real(count(p > 0.0_wp), wp), sum(w - b, mask=p > 0.0_wp)]
      if (across_ranks) call sum_over_ranks(sums)
      if (sums(1) > 0.0_wp) s = sums(2)/sums(1)
   end subroutine contact_shift

   subroutine solve_by_gfmd(self, problem, state, budget, outcome, progress, error)
      class(gfmd_solver), intent(inout) :: self
      type(contact_problem), intent(in) :: problem
      type(contact_state), intent(inout) :: state
      integer, intent(in) :: budget
      type(solve_outcome), intent(out) :: outcome
      type(progress_log), intent(inout) :: progress
      type(error_type), allocatable, intent(out) :: error
      type(gfmd_outcome) :: dynamics
      real(wp), allocatable :: history(:)
      character(len=:), allocatable :: masses
      logical :: per_mode
      select case (trim(problem%gfmd_mass))
      case ('mode')
         per_mode = .true.
         masses = 'GFMD with a mass per mode, as the scene asks'
      case ('one')
         per_mode = .false.
         masses = 'GFMD with unit masses, as the scene asks'
      case default   ! 'auto'
         per_mode = takes_mode_mass(problem%op, state%p)
         if (per_mode) then
            masses = "GFMD with a mass per mode (gfmd_mass 'auto': a surface of at least " // &
               & to_string(nint(mode_mass_points)) // ' points whose start touches on at most ' // &
               & to_string(nint(100*mode_mass_contact)) // ' % of it)'
         else
            masses = "GFMD with unit masses (gfmd_mass 'auto': a line, a surface of fewer than " // &
               & to_string(nint(mode_mass_points)) // ' points, or a start touching nowhere or on more than ' // &
               & to_string(nint(100*mode_mass_contact)) // ' % of it)'
         end if
      end select
      allocate (history(budget))
      call gfmd(problem%op, problem%b, problem%load_control, problem%mean_pressure, state%s, problem%g_ref, &
         & problem%tol, budget, state%p, state%w, state%gap, dynamics, error, history, progress, per_mode)
      if (allocated(error)) return
      outcome = solve_outcome(converged=dynamics%converged, iterations=dynamics%iterations, &
         & outer_iterations=dynamics%updates, fft_pairs=dynamics%fft_pairs, residual=dynamics%residual, &
         & history=history(1:min(dynamics%checks, size(history))), note=masses)
   end subroutine solve_by_gfmd

   !> Whether &solver gfmd_mass = 'auto' takes the mass per mode: on a surface of at least
   !> mode_mass_points points whose start (the coarse start's solution) has contact on at
   !> most mode_mass_contact of the surface, but some (a start without contact, or a uniform
   !> pressure, says nothing of the contact to come). Not on a line: measured on surfaces.
   logical function takes_mode_mass(op, p)
      type(compliance_operator), intent(in) :: op
      real(wp), intent(in) :: p(:)
      real(wp) :: points, touching
      points = real(op%grid%points(), wp)
      takes_mode_mass = .false.
      if (op%grid%is_line() .or. points < mode_mass_points) return
      touching = real(count(p > 0.0_wp), wp)
      if (op%distributed) touching = global_sum(touching)
      takes_mode_mass = touching > 0.0_wp .and. touching <= mode_mass_contact*points
   end function takes_mode_mass

   pure function gfmd_name(self) result(name)
      class(gfmd_solver), intent(in) :: self
      character(len=:), allocatable :: name
      name = 'gfmd'
   end function gfmd_name

end module lc_contact_solver_gfmd
