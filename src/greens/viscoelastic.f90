!> Linear viscoelastic materials in steady sliding (seed Eqs. 12-15).
!>
!> For an indenter sliding at speed V along +x, seed Eq. (14) per Fourier mode
!> exp(i k x) is the elastic multiplier (with 1/E taken out) times
!>    J*(k) = J(0+) + int_0^inf J'(t) exp(i k V t) dt,
!> the complex creep compliance at frequency k V (with the sign of i that Eq. (14) fixes:
!> J*(k) = conj(J(omega = kV)) in the usual exp(i omega t) convention).
!>
!> Models (Poisson's ratio is constant in time):
!>  - elastic: J = 1/E;
!>  - standard linear solid (seed Eq. 15): J(t) = 1/E0 - (1/E0 - 1/E_inf) exp(-t/tau), E0 the
!>    low-frequency (rubbery) and E_inf the high-frequency (glassy) modulus, tau a
!>    retardation (creep) time: J*(k) = 1/E_inf + (1/E0 - 1/E_inf)/(1 - i k V tau);
!>  - Prony series in creep form J(t) = J_g + sum_i J_i (1 - exp(-t/tau_i)):
!>    J*(k) = J_g + sum_i J_i/(1 - i k V tau_i);
!>  - Prony series in relaxation form E(t) = E_r + sum_i E_i exp(-t/tau_i):
!>    E*(k) = E_r + sum_i E_i (-i k V tau_i)/(1 - i k V tau_i), J* = 1/E*.
!> V -> 0 gives the elastic compliance 1/E0 (1/E_r, J_g + sum J_i), V -> inf 1/E_inf
!> (J_g, 1/(E_r + sum E_i)).
module lc_greens_viscoelastic
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_kinds, only: wp
   use lc_errors, only: error_type, input_error, positive_finite
   use lc_strings, only: to_string
   implicit none (type, external)
   private
   public :: material_law, creep_compliance, static_modulus, check_material, max_prony_terms

   !> The value of a parameter that was not given.
   real(wp), parameter :: unset = -1.0_wp
   !> Largest number of Prony terms.
   integer, parameter :: max_prony_terms = 64

   !> A material law: model = 'elastic', 'sls' or 'prony' (form 'creep' or 'relaxation').
   type :: material_law
      character(len=512) :: model = 'elastic'      !< as long as the namelist's strings
      character(len=512) :: form = 'relaxation'
      real(wp) :: young = 1.0_wp           !< elastic: E (S)
      real(wp) :: e0 = -1.0_wp             !< sls: low-frequency modulus (S)
      real(wp) :: e_inf = -1.0_wp          !< sls: high-frequency modulus (S)
      real(wp) :: tau = -1.0_wp            !< sls: retardation time (T)
      real(wp) :: equilibrium = -1.0_wp    !< prony: E_r (relaxation) or J_g (creep)
      real(wp), allocatable :: times(:)    !< prony: tau_i (T), increasing
      real(wp), allocatable :: values(:)   !< prony: E_i (S) or J_i (1/S)
   contains
      procedure :: terms
   end type material_law

contains

   !> Number of Prony terms given (0 if none).
   pure integer function terms(self)
      class(material_law), intent(in) :: self
      terms = 0
      if (allocated(self%times)) terms = size(self%times)
   end function terms

   !> J*(k) of seed Eq. (14) at the sliding frequencies omega = k V (1/S); omega may be any
   !> real. (Whole arrays: the model is looked up once, not per mode.)
   pure function creep_compliance(law, omega) result(j)
      type(material_law), intent(in) :: law
      real(wp), intent(in) :: omega(:)
      complex(wp) :: j(size(omega))
      complex(wp), parameter :: one = (1.0_wp, 0.0_wp)
      complex(wp) :: modulus, iwt
      integer :: i, m

      select case (trim(law%model))
      case ('sls')
         j = 1.0_wp/law%e_inf + (1.0_wp/law%e0 - 1.0_wp/law%e_inf)/cmplx(1.0_wp, -omega*law%tau, wp)
      case ('prony')
         if (trim(law%form) == 'creep') then
            j = law%equilibrium
            do i = 1, size(law%times)
               j = j + law%values(i)/cmplx(1.0_wp, -omega*law%times(i), wp)
            end do
         else
            do m = 1, size(omega)
               modulus = law%equilibrium
               do i = 1, size(law%times)
                  iwt = cmplx(0.0_wp, -omega(m)*law%times(i), wp)
                  modulus = modulus + law%values(i)*iwt/(one + iwt)
               end do
               j(m) = one/modulus
            end do
         end if
      case default
         j = 1.0_wp/law%young
      end select
   end function creep_compliance

   !> The low-frequency (V -> 0) modulus: the elastic limit used for normalisations (S).
   pure real(wp) function static_modulus(law)
      type(material_law), intent(in) :: law
      real(wp), parameter :: zero(1) = [0.0_wp]
      complex(wp) :: j(1)
      j = creep_compliance(law, zero)
      static_modulus = 1.0_wp/real(j(1), wp)
   end function static_modulus

   !> Validate a material law; messages name the &material variable and the allowed range.
   subroutine check_material(law, error)
      type(material_law), intent(in) :: law
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      ! values that the chosen model does not use are refused rather than ignored
      select case (trim(law%model))
      case ('elastic', 'sls', 'prony')
         if (trim(law%model) /= 'sls' .and. any([law%e0, law%e_inf, law%tau] /= unset)) then
            call input_error(error, 'material', 'e0/e_inf/tau', 'given', "only with model = 'sls'")
         else if (trim(law%model) /= 'prony' .and. (law%equilibrium /= unset .or. law%terms() > 0 .or. &
            & allocated(law%values))) then
            call input_error(error, 'material', 'prony_equilibrium/prony_times/prony_values', 'given', &
               & "only with model = 'prony'")
         end if
         if (allocated(error)) return
      end select
      select case (trim(law%model))
      case ('elastic')
      case ('sls')
         if (.not. positive_finite(law%e0)) then
            call input_error(error, 'material', 'e0', to_string(law%e0), '> 0 and finite')
         else if (.not. positive_finite(law%e_inf)) then
            call input_error(error, 'material', 'e_inf', to_string(law%e_inf), '> 0 and finite')
         else if (law%e_inf < law%e0) then
            call input_error(error, 'material', 'e_inf', to_string(law%e_inf), &
               & '>= e0 = ' // to_string(law%e0) // ' (the glassy modulus is the larger one)')
         else if (.not. positive_finite(law%tau)) then
            call input_error(error, 'material', 'tau', to_string(law%tau), '> 0 and finite')
         end if
      case ('prony')
         if (.not. (trim(law%form) == 'creep' .or. trim(law%form) == 'relaxation')) then
            call input_error(error, 'material', 'prony_form', trim(law%form), "'creep' or 'relaxation'")
         else if (.not. allocated(law%times) .or. .not. allocated(law%values)) then
            call input_error(error, 'material', 'prony_times/prony_values', 'not given', 'at least one term')
         else if (size(law%times) < 1 .or. size(law%times) > max_prony_terms .or. &
            & size(law%times) /= size(law%values)) then
            call input_error(error, 'material', 'prony_times/prony_values', &
               & to_string(size(law%times)) // ' times, ' // to_string(size(law%values)) // ' values', &
               & 'the same number of times and values, 1 to ' // to_string(max_prony_terms))
         else if (.not. (ieee_is_finite(law%equilibrium) .and. law%equilibrium >= 0.0_wp)) then
            call input_error(error, 'material', 'prony_equilibrium', to_string(law%equilibrium), '>= 0 and finite')
         else if (law%equilibrium == 0.0_wp .and. trim(law%form) == 'relaxation') then
            call input_error(error, 'material', 'prony_equilibrium', '0', &
               & "> 0 for form 'relaxation' (a fluid has no static compliance)")
         end if
         if (allocated(error)) return
         do i = 1, size(law%times)
            if (.not. positive_finite(law%times(i))) then
               call input_error(error, 'material', 'prony_times(' // to_string(i) // ')', to_string(law%times(i)), &
                  & '> 0 and finite')
            else if (.not. positive_finite(law%values(i))) then
               call input_error(error, 'material', 'prony_values(' // to_string(i) // ')', to_string(law%values(i)), &
                  & '> 0 and finite (a Prony series must be positive)')
            end if
            if (allocated(error)) return
            if (i == 1) cycle
            if (.not. law%times(i) > law%times(i - 1)) then
               call input_error(error, 'material', 'prony_times(' // to_string(i) // ')', to_string(law%times(i)), &
                  & '> prony_times(' // to_string(i - 1) // ') (sorted, increasing, no repeats)')
               return
            end if
         end do
         if (trim(law%form) == 'creep' .and. law%equilibrium == 0.0_wp) then
            call input_error(error, 'material', 'prony_equilibrium', '0', &
               & "> 0 for form 'creep' (the glassy compliance J_g of an elastic solid is not zero)")
         end if
      case default
         call input_error(error, 'material', 'model', trim(law%model), "'elastic', 'sls' or 'prony'")
      end select
   end subroutine check_material

end module lc_greens_viscoelastic
