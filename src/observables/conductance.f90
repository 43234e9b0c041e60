!> The electrical (or thermal) conductance of a contact and its normal interfacial
!> stiffness, per unit nominal area (docs/theory.md, "Contact conductance and interfacial
!> stiffness").
!>
!> Both are the response of the body to a uniform change held on the contact set A, the
!> rest of the surface free:
!> - conductance: the surface potential of a surface flux density J is phi^ = G_c(q) J^ with
!>   G_c = 1/(sigma q) on a half-space and tanh(q h)/(sigma q) on a layer of thickness h on a
!>   perfectly conducting base (h/sigma at q = 0; 0 at q = 0 on a half-space: the
!>   constriction convention, the potential measured from the mean surface potential). With
!>   phi = 1 on A and J = 0 elsewhere, C = mean(J) (sigma/L). G_c is real, even and positive,
!>   so the masked system is symmetric positive definite: the conjugate gradients,
!>   preconditioned by the Fourier inverse 1/G_c masked to A, stopped when the mean is
!>   within a relative tol (its error is the energy norm of the iterate's, masked_cg).
!> - stiffness: with the scene's own compliance operator G (lc_contact_operator, its Coulomb
!>   coupling included), an extra approach delta = 1 held on A gives the pressure increment
!>   G Delta p = 1 on A, Delta p = 0 elsewhere, and K = mean(Delta p) (S/L). Symmetric
!>   operators: the same conjugate gradients with the operator's metric; coupled (non-symmetric)
!>   ones: BiCGSTAB, both preconditioned by the operator's Fourier preconditioner masked to A.
!>
!> On a half-space G = (2/E*)/q and G_c = (1/sigma)/q: C = (2 sigma/E*) K (Barber's analogy,
!> J. R. Barber, "Bounds on the electrical resistance between contacting elastic rough bodies").
!>
!> On a surface shared among MPI ranks (a distributed operator, or `distributed` for the
!> conductance) the contact set is this rank's slab: the transforms are the distributed
!> plans', the multipliers on this rank's columns of the spectrum, and every dot product,
!> norm and mean a sum over the ranks, as in the contact solver's conjugate gradients.
module lc_observables_conductance
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   use lc_base_grid, only: grid_type
   use lc_fft_plans, only: fft_plan
   use lc_base_parallel, only: global_sum, global_any, slab
   use lc_contact_operator, only: compliance_operator
   implicit none (type, external)
   private
   public :: conduction_multiplier, contact_conductance, contact_stiffness, masked_outcome

   !> Iterations over which the conjugate gradients sum alpha_j (r_j.z_j) to estimate the
   !> error of the mean of an iterate that many steps back (docs/decisions/021).
   integer, parameter :: error_delay = 3

   !> How an iteration on the contact set ended.
   type :: masked_outcome
      integer :: iterations = 0           !< CG or BiCGSTAB iterations
      integer :: fft_pairs = 0            !< FFT r2c+c2r pairs spent
      real(wp) :: residual = 0.0_wp       !< final |r|/|b| on the contact set
      logical :: converged = .false.
   end type masked_outcome

   !> A linear system restricted to the contact set A: y = P_A A x and its preconditioner
   !> z = P_A B r, on the values at the points of A only (a field vanishing off A; the vector
   !> operations then cost a pass over A, not over the grid).
   type, abstract :: masked_system
      integer, allocatable :: contact(:)   !< the points of A (flat indices of the grid, or of this rank's slab)
      integer :: n = 0                     !< grid points (of the whole grid)
      integer :: fft_pairs = 0
      !> the points are this rank's of a surface shared among MPI ranks: sums over the ranks
      logical :: distributed = .false.
   contains
      procedure :: dot => masked_dot
      procedure :: norm => masked_norm
      procedure :: total => masked_total
      procedure(masked_map), deferred :: apply
      procedure(masked_map), deferred :: precondition
   end type masked_system

   abstract interface
      subroutine masked_map(self, x, y)
         import :: masked_system, wp
         class(masked_system), intent(inout) :: self
         real(wp), intent(in) :: x(:)
         real(wp), intent(out) :: y(:)
      end subroutine masked_map
   end interface

   !> The conduction problem: sigma G_c as a multiplier on the half spectrum, with plans of
   !> its own (a prescribed contact map needs no compliance operator).
   type, extends(masked_system) :: conduction_system
      type(fft_plan) :: fft
      real(wp), allocatable :: multiplier(:)   !< sigma G_c(q)/n (L/n)
      real(wp), allocatable :: inverse(:)      !< 1/(sigma G_c(q) n), 0 where G_c = 0
   contains
      procedure :: apply => conduction_apply
      procedure :: precondition => conduction_precondition
   end type conduction_system

   !> The stiffness problem on the scene's compliance operator.
   type, extends(masked_system) :: stiffness_system
      type(compliance_operator), pointer :: op => null()
   contains
      procedure :: apply => stiffness_apply
      procedure :: precondition => stiffness_precondition
   end type stiffness_system

contains

   !> sigma G_c(q) (L) on the half spectrum of `grid` for a layer of `thickness` on a
   !> perfectly conducting base (+Inf: a half-space, whose uniform mode is 0).
   function conduction_multiplier(grid, thickness) result(multiplier)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: thickness
      real(wp), allocatable :: multiplier(:)
      integer :: i
      allocate (multiplier(grid%modes()))
      do i = 1, size(multiplier)
         multiplier(i) = conduction_of_mode(grid, i, thickness)
      end do
   end function conduction_multiplier

   !> conduction_multiplier on the modes of the plan `fft` (a distributed plan: this rank's
   !> columns of the spectrum).
   function plan_multiplier(fft, grid, thickness) result(multiplier)
      type(fft_plan), intent(in) :: fft
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: thickness
      real(wp), allocatable :: multiplier(:)
      integer :: i, mx, my
      allocate (multiplier(fft%nk))
      do i = 1, fft%nk
         call fft%mode_indices(i, mx, my)
         multiplier(i) = conduction_of_mode(grid, my*grid%nkx() + mx + 1, thickness)
      end do
   end function plan_multiplier

   !> sigma G_c (L) of the mode `index` of the half spectrum of `grid` (1: the uniform mode).
   real(wp) function conduction_of_mode(grid, index, thickness) result(multiplier)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: index
      real(wp), intent(in) :: thickness
      real(wp) :: qx, qy, q
      if (index == 1) then
         multiplier = 0.0_wp
         if (ieee_is_finite(thickness)) multiplier = thickness
         return
      end if
      call grid%wavevector(index, qx, qy)
      q = hypot(qx, qy)
      if (ieee_is_finite(thickness)) then
         multiplier = tanh(q*thickness)/q
      else
         multiplier = 1.0_wp/q
      end if
   end function conduction_of_mode

   !> The conductance per unit nominal area and per unit conductivity (1/L) of the contact
   !> set `contact` (flat, x fastest) on `grid`, for a layer of `thickness` on a perfectly
   !> conducting base (+Inf: a half-space, constriction convention): C/sigma = mean(J) with
   !> sigma G_c J = 1 on the contact set, to a relative tol (masked_cg), within max_iter
   !> iterations. `distributed`: the surface is shared among the job's MPI ranks (if there
   !> are several) and `contact` is this rank's slab of rows.
   subroutine contact_conductance(grid, contact, thickness, tol, max_iter, threads, conductance, outcome, error, &
         & distributed)
      type(grid_type), intent(in) :: grid
      logical, intent(in) :: contact(:)
      real(wp), intent(in) :: thickness, tol
      integer, intent(in) :: max_iter, threads
      real(wp), intent(out) :: conductance
      type(masked_outcome), intent(out) :: outcome
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: distributed
      type(conduction_system) :: system
      real(wp), allocatable :: solution(:)
      integer :: points, y_start, rows

      conductance = 0.0_wp
      system%distributed = .false.
      if (present(distributed)) system%distributed = distributed .and. .not. grid%is_line()
      points = grid%points()
      if (system%distributed) then
         call slab(grid%ny, y_start, rows)
         points = grid%nx*rows
      end if
      if (size(contact) /= points) then
         call fatal_error(error, 'conductance: the contact map has ' // to_string(size(contact)) // &
            & ' points; allowed: the grid''s ' // to_string(points), code_input)
         return
      end if
      if (.not. thickness > 0.0_wp) then
         call fatal_error(error, 'conductance: thickness = ' // to_string(thickness) // &
            & ' is not allowed; allowed: > 0, or Inf for a half-space', code_input)
         return
      end if
      if (trivial(contact, system%distributed, ieee_is_finite(thickness), thickness, conductance, outcome)) return
      call system%fft%init(grid%nx, grid%ny, threads, error, system%distributed)
      if (allocated(error)) return
      ! (a one-rank job has no distributed plan: its system is the serial one)
      system%distributed = system%fft%distributed
      call restrict(system, contact, grid%points())
      system%multiplier = plan_multiplier(system%fft, grid, thickness)/grid%points()
      allocate (system%inverse(size(system%multiplier)))
      where (system%multiplier > 0.0_wp)
         system%inverse = 1.0_wp/(system%multiplier*real(grid%points(), wp)**2)
      elsewhere
         system%inverse = 0.0_wp
      end where
      call masked_cg(system, tol, max_iter, solution, outcome)
      conductance = system%total(solution)/system%n
      call system%fft%destroy()
   end subroutine contact_conductance

   !> The normal interfacial stiffness dp_m/d(delta) (S/L) at the contact set `contact` of a
   !> solved contact with the operator `op` it was solved with: mean(Delta p) with
   !> G Delta p = 1 on the contact set (the uniform mode a load-controlled solve dropped
   !> added back). The conjugate gradients for a symmetric operator (the mean to a relative
   !> tol), BiCGSTAB for a coupled one (stopped at |r| <= tol |b|).
   subroutine contact_stiffness(op, contact, tol, max_iter, stiffness, outcome)
      type(compliance_operator), target, intent(inout) :: op
      logical, intent(in) :: contact(:)
      real(wp), intent(in) :: tol
      integer, intent(in) :: max_iter
      real(wp), intent(out) :: stiffness
      type(masked_outcome), intent(out) :: outcome
      type(stiffness_system) :: system
      real(wp), allocatable :: solution(:)
      logical :: bounded
      real(wp) :: uniform

      ! a uniform mode in the operator: full contact has the finite stiffness 1/G(0)
      ! (distributed: the rank holding the uniform mode has its multiplier)
      uniform = 0.0_wp
      if (op%holds_uniform .and. op%nk > 0) uniform = op%metric(1)
      if (op%distributed) uniform = global_sum(uniform)
      uniform = uniform + op%dropped_uniform
      bounded = uniform > 0.0_wp
      if (trivial(contact, op%distributed, bounded, uniform, stiffness, outcome)) return
      system%op => op
      system%distributed = op%distributed
      call restrict(system, contact, op%grid%points())
      if (op%coupled) then
         call masked_bicgstab(system, tol, max_iter, solution, outcome)
      else
         call masked_cg(system, tol, max_iter, solution, outcome)
      end if
      stiffness = system%total(solution)/system%n
   end subroutine contact_stiffness

   !> The answers without an iteration: no contact gives 0, full contact 1/uniform (or +Inf
   !> where the operator has no uniform mode). True if one of them applies.
   !> (`distributed`: `contact` is this rank's part of the contact set.)
   logical function trivial(contact, distributed, bounded, uniform, value, outcome)
      logical, intent(in) :: contact(:), distributed, bounded
      real(wp), intent(in) :: uniform
      real(wp), intent(out) :: value
      type(masked_outcome), intent(inout) :: outcome
      trivial = .true.
      outcome%converged = .true.
      value = 0.0_wp
      if (.not. anywhere(any(contact))) return
      if (.not. anywhere(.not. all(contact))) then
         if (bounded) then
            value = 1.0_wp/uniform
         else
            value = ieee_value(1.0_wp, ieee_positive_inf)
         end if
         return
      end if
      trivial = .false.
      outcome%converged = .false.

   contains

      logical function anywhere(here)
         logical, intent(in) :: here
         anywhere = here
         if (distributed) anywhere = global_any(here)
      end function anywhere
   end function trivial

   !> Preconditioned conjugate gradients for the symmetric positive definite P_A A P_A x =
   !> 1 on A, from x = 0. What is wanted is the mean, b.x/n with b = 1 on A, and from x_0 = 0
   !> b.x - b.x_k = |x - x_k|_A^2 = sum_{j >= k} alpha_j (r_j.z_j) (Hestenes and Stiefel):
   !> the iteration stops when the last error_delay terms, an estimate of the error of the
   !> iterate error_delay steps back, are at most tol times b.x_k (the mean to a relative
   !> tol), or when |r| <= tol |b|.
   subroutine masked_cg(system, tol, max_iter, x, outcome)
      class(masked_system), intent(inout) :: system
      real(wp), intent(in) :: tol
      integer, intent(in) :: max_iter
      real(wp), allocatable, intent(out) :: x(:)
      type(masked_outcome), intent(inout) :: outcome
      real(wp), allocatable :: r(:), z(:), d(:), ad(:)
      real(wp) :: rz, rz_next, alpha, b_norm, r_norm, energy, recent(0:error_delay - 1)
      integer :: n

      n = size(system%contact)
      allocate (x(n), z(n), ad(n), r(n))
      x = 0.0_wp
      r = 1.0_wp
      b_norm = system%norm(r)
      r_norm = b_norm
      call system%precondition(r, z)
      d = z
      rz = system%dot(r, z)
      energy = 0.0_wp
      recent = huge(1.0_wp)/error_delay   ! (no estimate before error_delay steps)
      do while (outcome%iterations < max_iter)
         call system%apply(d, ad)
         alpha = rz/system%dot(d, ad)
         x = x + alpha*d
         r = r - alpha*ad
         outcome%iterations = outcome%iterations + 1
         energy = energy + alpha*rz
         recent(mod(outcome%iterations, error_delay)) = alpha*rz
         r_norm = system%norm(r)
         outcome%converged = r_norm <= tol*b_norm .or. sum(recent) <= tol*energy
         if (outcome%converged) exit
         call system%precondition(r, z)
         rz_next = system%dot(r, z)
         d = z + (rz_next/rz)*d
         rz = rz_next
      end do
      outcome%residual = r_norm/b_norm
      outcome%fft_pairs = system%fft_pairs
   end subroutine masked_cg

   !> Right-preconditioned BiCGSTAB (H. A. van der Vorst, "Bi-CGSTAB: a fast and smoothly
   !> converging variant of Bi-CG for the solution of nonsymmetric linear systems") for
   !> P_A A P_A x = 1 on A, from x = 0.
   subroutine masked_bicgstab(system, tol, max_iter, x, outcome)
      class(masked_system), intent(inout) :: system
      real(wp), intent(in) :: tol
      integer, intent(in) :: max_iter
      real(wp), allocatable, intent(out) :: x(:)
      type(masked_outcome), intent(inout) :: outcome
      real(wp), allocatable :: r(:), shadow(:), p(:), v(:), p_hat(:), s(:), s_hat(:), t(:)
      real(wp) :: rho, rho_next, alpha, omega, b_norm, r_norm
      integer :: n

      n = size(system%contact)
      allocate (x(n), p_hat(n), s_hat(n), t(n), r(n))
      x = 0.0_wp
      r = 1.0_wp
      shadow = r
      b_norm = system%norm(r)
      r_norm = b_norm
      allocate (p(n), v(n), s(n))
      p = 0.0_wp
      v = 0.0_wp
      rho = 1.0_wp
      alpha = 1.0_wp
      omega = 1.0_wp
      do while (outcome%iterations < max_iter)
         rho_next = system%dot(shadow, r)
         ! a breakdown (rho or omega at rounding): restart from the current iterate
         if (abs(rho_next) <= epsilon(1.0_wp)*b_norm*r_norm .or. omega == 0.0_wp) then
            call system%apply(x, v)
            r = 1.0_wp - v
            shadow = r
            p = 0.0_wp
            v = 0.0_wp
            rho = 1.0_wp
            alpha = 1.0_wp
            omega = 1.0_wp
            rho_next = system%dot(shadow, r)
         end if
         p = r + (rho_next/rho)*(alpha/omega)*(p - omega*v)
         rho = rho_next
         call system%precondition(p, p_hat)
         call system%apply(p_hat, v)
         alpha = rho/system%dot(shadow, v)
         s = r - alpha*v
         outcome%iterations = outcome%iterations + 1
         if (system%norm(s) <= tol*b_norm) then
            x = x + alpha*p_hat
            r = s
            r_norm = system%norm(r)
            exit
         end if
         call system%precondition(s, s_hat)
         call system%apply(s_hat, t)
         omega = system%dot(t, s)/system%dot(t, t)
         x = x + alpha*p_hat + omega*s_hat
         r = s - omega*t
         r_norm = system%norm(r)
         if (r_norm <= tol*b_norm) exit
      end do
      outcome%residual = r_norm/b_norm
      outcome%converged = r_norm <= tol*b_norm
      outcome%fft_pairs = system%fft_pairs
   end subroutine masked_bicgstab

   !> y = P_A sigma G_c x.
   subroutine conduction_apply(self, x, y)
      class(conduction_system), intent(inout) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      call multiply(self, self%multiplier, x, y)
   end subroutine conduction_apply

   !> y = P_A (sigma G_c)^-1 x.
   subroutine conduction_precondition(self, x, y)
      class(conduction_system), intent(inout) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      call multiply(self, self%inverse, x, y)
   end subroutine conduction_precondition

   !> y = P_A F^-1[multiplier F[x]] with the plans of the conduction system (the multiplier
   !> holds the 1/n of the unscaled forward transform).
   subroutine multiply(self, multiplier, x, y)
      class(conduction_system), intent(inout) :: self
      real(wp), intent(in) :: multiplier(:), x(:)
      real(wp), intent(out) :: y(:)
      self%fft%real_buffer = 0.0_wp
      self%fft%real_buffer(self%contact) = x
      call self%fft%forward_unscaled()
      self%fft%spectrum = self%fft%spectrum*multiplier
      call self%fft%backward()
      y = self%fft%real_buffer(self%contact)
      self%fft_pairs = self%fft_pairs + 1
   end subroutine multiply

   !> y = P_A (G x + G_dropped mean(x)): the full operator, its Coulomb coupling and the
   !> uniform mode a load-controlled solve took out included.
   subroutine stiffness_apply(self, x, y)
      class(stiffness_system), intent(inout) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      real(wp), pointer, contiguous :: field(:)
      field => self%op%buffer()
      field = 0.0_wp
      field(self%contact) = x
      call self%op%full_in_buffer()
      y = field(self%contact) + self%op%dropped_uniform*self%total(x)/self%n
      self%fft_pairs = self%fft_pairs + 1
   end subroutine stiffness_apply

   !> y = P_A B x with the operator's Fourier preconditioner B (about the inverse of its
   !> metric).
   subroutine stiffness_precondition(self, x, y)
      class(stiffness_system), intent(inout) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      real(wp), pointer, contiguous :: field(:)
      field => self%op%buffer()
      field = 0.0_wp
      field(self%contact) = x
      call self%op%inverse_metric_in_buffer()
      y = field(self%contact)
      self%fft_pairs = self%fft_pairs + 1
   end subroutine stiffness_precondition

   !> a.b over the contact set (over every rank's part of it, distributed).
   real(wp) function masked_dot(self, a, b) result(dot)
      class(masked_system), intent(in) :: self
      real(wp), intent(in) :: a(:), b(:)
      dot = dot_product(a, b)
      if (self%distributed) dot = global_sum(dot)
   end function masked_dot

   !> |a| over the contact set.
   real(wp) function masked_norm(self, a) result(norm)
      class(masked_system), intent(in) :: self
      real(wp), intent(in) :: a(:)
      if (self%distributed) then
         norm = sqrt(global_sum(dot_product(a, a)))
      else
         norm = norm2(a)
      end if
   end function masked_norm

   !> The sum of a over the contact set.
   real(wp) function masked_total(self, a) result(total)
      class(masked_system), intent(in) :: self
      real(wp), intent(in) :: a(:)
      total = sum(a)
      if (self%distributed) total = global_sum(total)
   end function masked_total

   !> The points of the contact set `contact` (flat, x fastest) as the system's unknowns.
   subroutine restrict(system, contact, points)
      class(masked_system), intent(inout) :: system
      logical, intent(in) :: contact(:)
      !> the whole grid's points
      integer, intent(in) :: points
      integer :: i
      system%n = points
      system%contact = pack([(i, i = 1, size(contact))], contact)
   end subroutine restrict

end module lc_observables_conductance
