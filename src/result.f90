!> What a contact solve returns: fields on the grid, scalar observables, and the
!> convergence record. Units are the scene's (lengths L, pressures S).
module lc_result
   use lc_base_kinds, only: wp
   use lc_leakage_reynolds, only: leakage_result
   implicit none (type, external)
   private
   public :: contact_result, result_scalar, result_scalars

   !> The longest text a scalar holds (the solver's reason).
   integer, parameter :: text_length = 1024

   !> One solved contact problem (a scene, or its frictionless companion).
   type :: contact_result
      real(wp), allocatable :: pressure(:)         !< p >= 0 (S), compressive positive
      real(wp), allocatable :: gap(:)              !< g >= 0 (L), zero in contact
      real(wp), allocatable :: displacement_z(:)   !< w = u_z (L), positive into the layer
      real(wp), allocatable :: residual_history(:) !< complementarity residual per iteration
      !> only when the scene asks for surface stress (&output stress):
      real(wp), allocatable :: displacement_x(:)   !< u_x (L), along the sliding direction
      real(wp), allocatable :: shear(:)            !< tau = mu_c p (S), on the layer along +x
      real(wp), allocatable :: stress_xx(:)        !< sigma_xx at the surface (S), tension positive
      !> areal contacts, with &output stress: u_y (L), sigma_yy, sigma_xy (S)
      real(wp), allocatable :: displacement_y(:)
      real(wp), allocatable :: stress_yy(:)
      real(wp), allocatable :: stress_xy(:)
      !> areal contacts: the contact patches, largest first (lc_observables_patches): area (L^2)
      !> and perimeter (L)
      real(wp), allocatable :: patch_area(:)
      real(wp), allocatable :: patch_perimeter(:)
      real(wp), allocatable :: spot_trailing(:)    !< trailing (-x) edge of each contact spot (L)
      real(wp), allocatable :: spot_leading(:)     !< leading (+x) edge of each contact spot (L)
      !> largest sigma_xx around each spot (S), with stress; with friction the trailing-edge
      !> cusp is resolved sub-grid
      real(wp), allocatable :: spot_max_tension(:)
      real(wp), allocatable :: spot_max_tension_grid(:) !< the largest grid value of sigma_xx around each spot (S)
      real(wp), allocatable :: spot_tension_offset(:) !< its offset from the spot's trailing edge (L)
      real(wp), allocatable :: gap_edges(:)        !< gap histogram bin edges (L)
      integer, allocatable :: gap_counts(:)        !< gap histogram counts (grid nodes)
      real(wp) :: friction = 0.0_wp           !< mu_c used for this solve
      real(wp) :: mean_pressure = 0.0_wp      !< p_m (S)
      real(wp) :: penetration = 0.0_wp        !< Delta (L) of the highest asperity
      real(wp) :: contact_fraction = 0.0_wp   !< fraction of grid points in contact
      real(wp) :: delta_mu = 0.0_wp           !< interlocking friction <p v_z'>/p_m (seed Eq. 11)
      real(wp) :: delta_mu_spectral = 0.0_wp  !< the same from the Fourier multiplier
      real(wp) :: delta_mu_energy = 0.0_wp    !< mu_c <p du_x/dx>/p_m (elastic layers)
      real(wp) :: delta_mu_profile = 0.0_wp   !< -<p r'>/p_m: force balance on the rigid profile
      real(wp) :: pressure_shift = 0.0_wp     !< load-weighted pressure centroid - spot midpoint (L)
      real(wp) :: summit_shift = 0.0_wp       !< load-weighted spot midpoint - profile summit in it (L)
      real(wp) :: dissipated_power = 0.0_wp   !< power dissipated in a viscoelastic layer per nominal area (S L/T)
      logical :: monotone = .true.            !< Re G_eff >= 0 on every mode: the solution is unique
      integer :: n_spots = 0                  !< number of contact spots (line) or patches (areal)
      real(wp) :: max_tension_y = 0.0_wp      !< areal: where the largest sigma_xx sits across x (L)
      !> areal: the largest principal surface stress (S) and where it sits (L)
      real(wp) :: max_principal_stress = 0.0_wp
      real(wp) :: max_principal_x = 0.0_wp
      real(wp) :: max_principal_y = 0.0_wp
      real(wp) :: contact_length = 0.0_wp     !< a = total length in contact (L)
      real(wp) :: mean_gap = 0.0_wp           !< <g> (L)
      !> p_m over the seed's pressure scale (lc_contact_solve's pressure_scale; NaN for a
      !> flat profile on a line) and h/lambda
      real(wp) :: normalised_pressure = 0.0_wp
      real(wp) :: normalised_thickness = 0.0_wp
      real(wp) :: leak_rate = 0.0_wp          !< <g^3>/12 (L^3): flow across x per unit gradient and 1/viscosity
      real(wp) :: max_tension = 0.0_wp        !< max sigma_xx (S), if stress was asked for (sub-grid at trailing edges)
      real(wp) :: max_tension_grid = 0.0_wp   !< the largest grid value of sigma_xx (S)
      real(wp) :: max_tension_x = 0.0_wp      !< where it sits (L)
      real(wp) :: max_tension_offset = 0.0_wp !< its offset from the nearest spot's trailing edge (L)
      !> with &output conductance (lc_observables_conductance): the conductance per unit nominal
      !> area (sigma/L: S/m^2 with sigma in S/m and L in m), the normal interfacial stiffness
      !> dp_m/d(Delta) (S/L), whether both iterations converged and their iteration counts
      logical :: has_conductance = .false.
      real(wp) :: conductance = 0.0_wp
      real(wp) :: contact_stiffness = 0.0_wp
      logical :: conductance_converged = .false.
      integer :: conductance_iterations = 0
      integer :: stiffness_iterations = 0
      logical :: converged = .false.
      !> CG or GCR iterations (all inner CG solves for anderson; fine-grid ones for multigrid)
      integer :: iterations = 0
      integer :: outer_iterations = 0         !< outer (Anderson) iterations; 1 for cg and gcr
      !> the solver that ran: 'cg', 'gcr', 'anderson', 'gfmd', 'newton', 'multigrid',
      !> 'multigrid+cg' (the CG finished the multigrid's fields), 'multigrid+gcr' (GCR went
      !> on where the multigrid stalled on a coupled scene; '+kept', '+anderson' may
      !> follow as after 'gcr'), 'gcr+kept'
      !> (gcr stalled and went on keeping its history across clips) or 'gcr+kept+anderson' (that
      !> stalled too and the Anderson outer iteration went on from its best iterate);
      !> '+newton' when the dense Newton method finished a small grid the iterative solver
      !> left unconverged
      character(len=48) :: solver = ''
      !> why the policy chose those methods (lc_contact_policy), e.g. 'a coupled operator
      !> (friction, or a sliding viscoelastic layer): the constrained GCR; where it stalls, ...'
      character(len=:), allocatable :: solver_reason
      integer :: fft_pairs = 0                !< FFT r2c+c2r pairs spent
      real(wp) :: residual = huge(1.0_wp)     !< final dimensionless complementarity residual
      !> an upper bound of the rounding of w - r relative to the profile's peak-to-valley:
      !> the smallest gap that double precision resolves at this load (see solve_on_grid)
      real(wp) :: gap_resolution = 0.0_wp
      real(wp) :: wall_time = 0.0_wp          !< seconds spent in the solver
      !> of wall_time: the finest grid's set-up (checks, operator: plans and multipliers) and
      !> the coarse start (the solves on the coarser grids, their set-up included); the rest
      !> is the finest grid's iterations (s)
      real(wp) :: setup_time = 0.0_wp
      real(wp) :: coarse_time = 0.0_wp
      !> of wall_time: the time in the grids' transforms (every r2c and c2r of the solve, the
      !> coarse grids' included; a distributed run's transposes included, rank 0's) (s)
      real(wp) :: transform_time = 0.0_wp
      !> threads the solve ran on (&solver threads, or what the job was given: lc_base_threads)
      integer :: omp_threads = 1
      integer :: mpi_ranks = 1                !< processes sharing the grid (1: this build has no MPI)
      !> areal contacts, with &output leakage: the Reynolds leakage of the gap (lc_leakage_reynolds)
      type(leakage_result), allocatable :: leakage
   end type contact_result

   !> One scalar of a result under its name: the /results attribute of the result file and
   !> the attribute of the Python result object. unit '1': dimensionless or a count. Counts
   !> and flags (0/1) are integers; the solver that ran is text.
   type :: result_scalar
      character(len=24) :: name = ''
      real(wp) :: value = 0.0_wp
      character(len=8) :: unit = '1'
      logical :: is_integer = .false.
      logical :: is_text = .false.
      character(len=text_length) :: text = ''
   end type result_scalar

contains

   !> The scalars of a result by name, in the order the result file lists them: those of
   !> the surface stress only when it was computed (and, for max_tension_y and the principal
   !> stress, on a surface); a_over_a0 when a frictionless companion was solved.
   pure function result_scalars(res, areal, a_over_a0) result(table)
      type(contact_result), intent(in) :: res
      logical, intent(in) :: areal
      real(wp), intent(in), optional :: a_over_a0
      type(result_scalar), allocatable :: table(:)

      table = [real_scalar('mean_pressure', res%mean_pressure, 'S'), &
         & real_scalar('penetration', res%penetration, 'L'), &
         & real_scalar('contact_fraction', res%contact_fraction), &
         & real_scalar('delta_mu', res%delta_mu), &
         & real_scalar('delta_mu_spectral', res%delta_mu_spectral), &
         & real_scalar('delta_mu_energy', res%delta_mu_energy), &
         & real_scalar('delta_mu_profile', res%delta_mu_profile), &
         & real_scalar('total_friction', res%friction + res%delta_mu), &
         & real_scalar('dissipated_power', res%dissipated_power, 'S L/T'), &
         & real_scalar('pressure_shift', res%pressure_shift, 'L'), &
         & real_scalar('summit_shift', res%summit_shift, 'L'), &
         & integer_scalar('monotone', merge(1, 0, res%monotone)), &
         & integer_scalar('converged', merge(1, 0, res%converged)), &
         & integer_scalar('iterations', res%iterations), &
         & integer_scalar('outer_iterations', res%outer_iterations), &
         & result_scalar('solver', is_text=.true., text=res%solver), &
         & result_scalar('solver_reason', is_text=.true., text=reason(res)), &
         & integer_scalar('fft_pairs', res%fft_pairs), &
         & real_scalar('residual', res%residual), &
         & real_scalar('gap_resolution', res%gap_resolution), &
         & real_scalar('wall_time', res%wall_time, 's'), &
         & real_scalar('setup_time', res%setup_time, 's'), &
         & real_scalar('coarse_time', res%coarse_time, 's'), &
         & real_scalar('transform_time', res%transform_time, 's'), &
         & integer_scalar('omp_threads', res%omp_threads), &
         & integer_scalar('mpi_ranks', res%mpi_ranks), &
         & real_scalar('friction', res%friction), &
         & integer_scalar('n_spots', res%n_spots), &
         & real_scalar('contact_length', res%contact_length, 'L'), &
         & real_scalar('mean_gap', res%mean_gap, 'L'), &
         & real_scalar('leak_rate', res%leak_rate, 'L^3')]
      if (allocated(res%stress_xx)) then
         table = [table, real_scalar('max_tension', res%max_tension, 'S'), &
            & real_scalar('max_tension_grid', res%max_tension_grid, 'S'), &
            & real_scalar('max_tension_x', res%max_tension_x, 'L'), &
            & real_scalar('max_tension_offset', res%max_tension_offset, 'L')]
         if (areal) table = [table, real_scalar('max_tension_y', res%max_tension_y, 'L'), &
            & real_scalar('max_principal_stress', res%max_principal_stress, 'S'), &
            & real_scalar('max_principal_x', res%max_principal_x, 'L'), &
            & real_scalar('max_principal_y', res%max_principal_y, 'L')]
      end if
      if (res%has_conductance) table = [table, real_scalar('conductance', res%conductance, 'sigma/L'), &
         & real_scalar('contact_stiffness', res%contact_stiffness, 'S/L'), &
         & integer_scalar('conductance_converged', merge(1, 0, res%conductance_converged)), &
         & integer_scalar('conductance_iterations', res%conductance_iterations), &
         & integer_scalar('stiffness_iterations', res%stiffness_iterations)]
      table = [table, real_scalar('normalised_pressure', res%normalised_pressure), &
         & real_scalar('normalised_thickness', res%normalised_thickness)]
      if (present(a_over_a0)) table = [table, real_scalar('a_over_a0', a_over_a0)]
   end function result_scalars

   !> The solver's reason, or '' where none was recorded.
   pure function reason(res) result(text)
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: text
      text = ''
      if (allocated(res%solver_reason)) text = res%solver_reason
   end function reason

   pure type(result_scalar) function real_scalar(name, value, unit)
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: value
      character(len=*), intent(in), optional :: unit
      real_scalar = result_scalar(name, value)
      if (present(unit)) real_scalar%unit = unit
   end function real_scalar

   pure type(result_scalar) function integer_scalar(name, value)
      character(len=*), intent(in) :: name
      integer, intent(in) :: value
      integer_scalar = result_scalar(name, real(value, wp), is_integer=.true.)
   end function integer_scalar
end module lc_result
