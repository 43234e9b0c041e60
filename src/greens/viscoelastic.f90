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
!>
!> The namelist's &material values are a record (material_law); the kernel works with the
!> model it describes, a type extending material_model (material_model_of). A new model is
!> a type here, its case in material_model_of and check_material, and its &material
!> variables in the scene schema.
module lc_greens_viscoelastic
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, input_error, positive_finite
   use lc_base_strings, only: to_string
   implicit none (type, external)
   private
   public :: material_law, material_model, material_model_of, creep_compliance, static_modulus, check_material, &
      & is_viscoelastic, max_prony_terms
   public :: elastic_material, standard_linear_solid, prony_series

   !> The value of a parameter that was not given.
   real(wp), parameter :: unset = -1.0_wp
   !> Largest number of Prony terms.
   integer, parameter :: max_prony_terms = 64

   !> The &material values: model = 'elastic', 'sls' or 'prony' (form 'creep' or 'relaxation').
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

   !> A linear material law in steady sliding: its complex creep compliance J*(omega).
   type, abstract :: material_model
   contains
      procedure(compliance_interface), deferred :: compliance
      procedure(check_interface), deferred :: check
      procedure :: viscoelastic => depends_on_frequency
      procedure :: static_modulus => modulus_at_rest
   end type material_model

   abstract interface
      !> J*(omega) (1/S) at the sliding frequencies omega = k V (1/T), any real.
      pure function compliance_interface(self, omega) result(j)
         import :: material_model, wp
         class(material_model), intent(in) :: self
         real(wp), intent(in) :: omega(:)
         complex(wp) :: j(size(omega))
      end function compliance_interface

      !> Validate the law; messages name the &material variable and the allowed range.
      subroutine check_interface(self, error)
         import :: material_model, error_type
         class(material_model), intent(in) :: self
         type(error_type), allocatable, intent(out) :: error
      end subroutine check_interface
   end interface

   !> J = 1/E.
   type, extends(material_model) :: elastic_material
      real(wp) :: young = 1.0_wp   !< E (S)
   contains
      procedure :: compliance => elastic_compliance
      procedure :: check => check_elastic
      procedure :: viscoelastic => elastic_is_not
   end type elastic_material

   !> Seed Eq. (15): J*(k) = 1/E_inf + (1/E0 - 1/E_inf)/(1 - i k V tau).
   type, extends(material_model) :: standard_linear_solid
      real(wp) :: e0 = unset, e_inf = unset, tau = unset
   contains
      procedure :: compliance => sls_compliance
      procedure :: check => check_sls
   end type standard_linear_solid

   !> A Prony series in creep form (J_g, J_i) or relaxation form (E_r, E_i), times tau_i.
   type, extends(material_model) :: prony_series
      character(len=512) :: form = 'relaxation'
      real(wp) :: equilibrium = unset
      real(wp), allocatable :: times(:), values(:)
   contains
      procedure :: compliance => prony_compliance
      procedure :: check => check_prony
   end type prony_series

contains

   !> Number of Prony terms given (0 if none).
   pure integer function terms(self)
      class(material_law), intent(in) :: self
      terms = 0
      if (allocated(self%times)) terms = size(self%times)
   end function terms

   !> The model the &material values describe (not allocated for an unknown model name:
   !> check_material says so).
   subroutine material_model_of(law, model)
      type(material_law), intent(in) :: law
      class(material_model), allocatable, intent(out) :: model
      select case (trim(law%model))
      case ('elastic')
         allocate (model, source=elastic_material(young=law%young))
      case ('sls')
         allocate (model, source=standard_linear_solid(e0=law%e0, e_inf=law%e_inf, tau=law%tau))
      case ('prony')
         if (allocated(law%times) .and. allocated(law%values)) then
            allocate (model, source=prony_series(form=law%form, equilibrium=law%equilibrium, times=law%times, &
               & values=law%values))
         else
            allocate (model, source=prony_series(form=law%form, equilibrium=law%equilibrium))
         end if
      end select
   end subroutine material_model_of

   !> J*(k) of seed Eq. (14) for the &material values `law` (1/S).
   function creep_compliance(law, omega) result(j)
      type(material_law), intent(in) :: law
      real(wp), intent(in) :: omega(:)
      complex(wp) :: j(size(omega))
      class(material_model), allocatable :: model
      call material_model_of(law, model)
      j = model%compliance(omega)
   end function creep_compliance

   !> The low-frequency (V -> 0) modulus of the &material values `law` (S).
   real(wp) function static_modulus(law)
      type(material_law), intent(in) :: law
      class(material_model), allocatable :: model
      call material_model_of(law, model)
      static_modulus = model%static_modulus()
   end function static_modulus

   !> Whether the law's compliance depends on the frequency (sliding changes it).
   logical function is_viscoelastic(law)
      type(material_law), intent(in) :: law
      class(material_model), allocatable :: model
      call material_model_of(law, model)
      is_viscoelastic = .false.
      if (allocated(model)) is_viscoelastic = model%viscoelastic()
   end function is_viscoelastic

   !> Validate the &material values: values the model does not use are refused rather than
   !> ignored, then the model checks its own.
   subroutine check_material(law, error)
      type(material_law), intent(in) :: law
      type(error_type), allocatable, intent(out) :: error
      class(material_model), allocatable :: model
      call material_model_of(law, model)
      if (.not. allocated(model)) then
         call input_error(error, 'material', 'model', trim(law%model), "'elastic', 'sls' or 'prony'")
         return
      end if
      if (trim(law%model) /= 'sls' .and. any([law%e0, law%e_inf, law%tau] /= unset)) then
         call input_error(error, 'material', 'e0/e_inf/tau', 'given', "only with model = 'sls'")
      else if (trim(law%model) /= 'prony' .and. (law%equilibrium /= unset .or. law%terms() > 0 .or. &
         & allocated(law%values))) then
         call input_error(error, 'material', 'prony_equilibrium/prony_times/prony_values', 'given', &
            & "only with model = 'prony'")
      else
         call model%check(error)
      end if
   end subroutine check_material

   !> Frequency dependence: a viscoelastic law has it.
   pure logical function depends_on_frequency(self)
      class(material_model), intent(in) :: self
      depends_on_frequency = .true.
   end function depends_on_frequency

   !> The modulus at rest, 1/Re J*(0) (S): the elastic limit used for normalisations.
   pure real(wp) function modulus_at_rest(self)
      class(material_model), intent(in) :: self
      complex(wp) :: j(1)
      j = self%compliance([0.0_wp])
      modulus_at_rest = 1.0_wp/real(j(1), wp)
   end function modulus_at_rest

   pure function elastic_compliance(self, omega) result(j)
      class(elastic_material), intent(in) :: self
      real(wp), intent(in) :: omega(:)
      complex(wp) :: j(size(omega))
      j = 1.0_wp/self%young
   end function elastic_compliance

   pure logical function elastic_is_not(self)
      class(elastic_material), intent(in) :: self
      elastic_is_not = .false.
   end function elastic_is_not

   !> (E is &layer young, checked with the layer.)
   subroutine check_elastic(self, error)
      class(elastic_material), intent(in) :: self
      type(error_type), allocatable, intent(out) :: error
   end subroutine check_elastic

   pure function sls_compliance(self, omega) result(j)
      class(standard_linear_solid), intent(in) :: self
      real(wp), intent(in) :: omega(:)
      complex(wp) :: j(size(omega))
      j = 1.0_wp/self%e_inf + (1.0_wp/self%e0 - 1.0_wp/self%e_inf)/cmplx(1.0_wp, -omega*self%tau, wp)
   end function sls_compliance

   subroutine check_sls(self, error)
      class(standard_linear_solid), intent(in) :: self
      type(error_type), allocatable, intent(out) :: error
      if (.not. positive_finite(self%e0)) then
         call input_error(error, 'material', 'e0', to_string(self%e0), '> 0 and finite')
      else if (.not. positive_finite(self%e_inf)) then
         call input_error(error, 'material', 'e_inf', to_string(self%e_inf), '> 0 and finite')
      else if (self%e_inf < self%e0) then
         call input_error(error, 'material', 'e_inf', to_string(self%e_inf), &
            & '>= e0 = ' // to_string(self%e0) // ' (the glassy modulus is the larger one)')
      else if (.not. positive_finite(self%tau)) then
         call input_error(error, 'material', 'tau', to_string(self%tau), '> 0 and finite')
      end if
   end subroutine check_sls

   pure function prony_compliance(self, omega) result(j)
      class(prony_series), intent(in) :: self
      real(wp), intent(in) :: omega(:)
      complex(wp) :: j(size(omega))
      complex(wp), parameter :: one = (1.0_wp, 0.0_wp)
      complex(wp) :: modulus, iwt
      integer :: i, m
      if (trim(self%form) == 'creep') then
         j = self%equilibrium
         do i = 1, size(self%times)
            j = j + self%values(i)/cmplx(1.0_wp, -omega*self%times(i), wp)
         end do
      else
         do m = 1, size(omega)
            modulus = self%equilibrium
            do i = 1, size(self%times)
               iwt = cmplx(0.0_wp, -omega(m)*self%times(i), wp)
               modulus = modulus + self%values(i)*iwt/(one + iwt)
            end do
            j(m) = one/modulus
         end do
      end if
   end function prony_compliance

   subroutine check_prony(self, error)
      class(prony_series), intent(in) :: self
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      if (.not. (trim(self%form) == 'creep' .or. trim(self%form) == 'relaxation')) then
         call input_error(error, 'material', 'prony_form', trim(self%form), "'creep' or 'relaxation'")
      else if (.not. allocated(self%times) .or. .not. allocated(self%values)) then
         call input_error(error, 'material', 'prony_times/prony_values', 'not given', 'at least one term')
      else if (size(self%times) < 1 .or. size(self%times) > max_prony_terms .or. &
         & size(self%times) /= size(self%values)) then
         call input_error(error, 'material', 'prony_times/prony_values', &
            & to_string(size(self%times)) // ' times, ' // to_string(size(self%values)) // ' values', &
            & 'the same number of times and values, 1 to ' // to_string(max_prony_terms))
      else if (.not. (ieee_is_finite(self%equilibrium) .and. self%equilibrium >= 0.0_wp)) then
         call input_error(error, 'material', 'prony_equilibrium', to_string(self%equilibrium), '>= 0 and finite')
      else if (self%equilibrium == 0.0_wp .and. trim(self%form) == 'relaxation') then
         call input_error(error, 'material', 'prony_equilibrium', '0', &
            & "> 0 for form 'relaxation' (a fluid has no static compliance)")
      end if
      if (allocated(error)) return
      do i = 1, size(self%times)
         if (.not. positive_finite(self%times(i))) then
            call input_error(error, 'material', 'prony_times(' // to_string(i) // ')', to_string(self%times(i)), &
               & '> 0 and finite')
         else if (.not. positive_finite(self%values(i))) then
            call input_error(error, 'material', 'prony_values(' // to_string(i) // ')', to_string(self%values(i)), &
               & '> 0 and finite (a Prony series must be positive)')
         end if
         if (allocated(error)) return
         if (i == 1) cycle
         if (.not. self%times(i) > self%times(i - 1)) then
            call input_error(error, 'material', 'prony_times(' // to_string(i) // ')', to_string(self%times(i)), &
               & '> prony_times(' // to_string(i - 1) // ') (sorted, increasing, no repeats)')
            return
         end if
      end do
      if (trim(self%form) == 'creep' .and. self%equilibrium == 0.0_wp) then
         call input_error(error, 'material', 'prony_equilibrium', '0', &
            & "> 0 for form 'creep' (the glassy compliance J_g of an elastic solid is not zero)")
      end if
   end subroutine check_prony

end module lc_greens_viscoelastic
