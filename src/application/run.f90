!> The main job of the executable (and of `layercontact.run` in Python): namelist file in,
!> HDF5 result out, a short summary on a unit.
!>
!> Order matters for "bad input loses nothing": the input is read and validated and the
!> output checked (an existing result is never overwritten unless &output overwrite) before
!> anything is computed; the result file appears only when it is complete.
module lc_application_run
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: iso_fortran_env, only: error_unit
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input
   use lc_base_strings, only: to_string
   use lc_io_files, only: path_kind, kind_name, kind_regular, kind_missing, kind_unknown
   use lc_scene, only: scene_type, not_set, is_areal, check_scene, foundation
   use lc_leakage_reynolds, only: leakage_memory_check
   use lc_result, only: contact_result
   use lc_io_namelist, only: read_scene
   use lc_io_hdf5, only: check_output, run_record, utc_now
   use lc_application_result_file, only: write_result_file
   use lc_profiles_profile, only: make_profile, make_profile_slab
   use lc_profiles_measured, only: measured_grid, periodicity_mismatch, edge_jump_limit, edge_kink_limit, &
      & slab_periodicity_mismatch
   use lc_application_scene_solve, only: solve_runs
   use lc_profiles_measured_slab, only: reads_by_slab, measured_slab_grid
   use lc_greens_viscoelastic, only: is_viscoelastic
   use lc_application_accuracy, only: choose_resolution
   use lc_base_version, only: version_string, build_isa
   use lc_base_parallel, only: parallel_start, parallel_end, is_distributed, is_root, rank_count, this_rank, &
      & check_rank_count, barrier, abort_job, global_any, global_max, slab
   implicit none (type, external)
   private
   public :: run_scene_file

contains

   !> Run the scene in `input`. converged = .false. means the solver stopped before its
   !> tolerance (results are still written). `unit` < 0 prints nothing.
   !>
   !> Under an MPI launcher with several ranks (docs/clusters.md, "One surface on several
   !> ranks") an areal scene is solved distributed: each rank reads the namelist and makes
   !> its slab of the profile, solves and computes the observables on the slabs, all write
   !> the result file together (each its rows), and rank 0 prints the summary.
   !> `communicator`: the Fortran handle of the ranks to share the scene among (a Python
   !> caller's mpi4py communicator), else the launcher's job. Input refused on every rank,
   !> and a failure of the file's writing (which every rank learns), return their error
   !> there; a failure on some rank only (memory) ends the whole job (MPI_Abort) with its
   !> exit code, since the other ranks would wait for it. `root`: this process is the one
   !> that reports (rank 0 of the ranks).
   subroutine run_scene_file(input, unit, output_file, converged, error, communicator, root)
      character(len=*), intent(in) :: input
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: output_file
      logical, intent(out) :: converged
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: communicator
      logical, intent(out), optional :: root
      logical :: agreed
      converged = .false.
      call parallel_start(error, communicator)
      if (present(root)) root = is_root()
      if (allocated(error)) then
         call parallel_end()
         return
      end if
      call run_scene(input, merge(unit, -1, is_root()), output_file, converged, agreed, error)
      if (is_distributed()) then
         if (allocated(error)) then
            if (error%code /= code_input .and. .not. agreed) then
               write (error_unit, '(a)') 'layercontact: error on MPI rank ' // to_string(this_rank()) // ' of ' // &
                  & to_string(rank_count()) // ': ' // error%message
               call abort_job(error%code)
            end if
         else
            ! (every rank returns once the result file is in place)
            call barrier()
         end if
      end if
      call parallel_end()
   end subroutine run_scene_file

   !> run_scene_file on this rank; `agreed`: the error is every rank's alike (the result
   !> file's writing).
   subroutine run_scene(input, unit, output_file, converged, agreed, error)
      character(len=*), intent(in) :: input
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: output_file
      logical, intent(out) :: converged, agreed
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(contact_result) :: result, companion
      character(len=:), allocatable :: text
      real(wp), allocatable :: height(:)
      type(run_record) :: run
      integer(i8) :: start, finish, rate
      integer :: y_start, rows
      real(wp) :: slope

      converged = .false.
      agreed = .false.
      call system_clock(start, rate)
      run%input_file = input
      run%started = utc_now()
      call check_input_file(input, error)
      if (allocated(error)) return
      call read_scene(input, scene, text, error)
      if (allocated(error)) return
      output_file = trim(scene%output_file)
      ! without &scene n (nx, ny) a profile file sets the grid: its own size
      if (trim(scene%profile%kind) == 'file' .and. .not. scene%grid_given) then
         if (is_distributed() .and. is_areal(scene) .and. reads_by_slab(scene%profile%boundary, &
            & scene%profile%resample)) then
            ! (by slabs: no rank reads the whole file)
            call measured_slab_grid(trim(scene%profile%file), trim(scene%profile%dataset), scene%profile%boundary, &
               & scene%n, scene%ny, error)
         else
            call measured_grid(trim(scene%profile%file), trim(scene%profile%dataset), is_areal(scene), &
               & scene%profile%boundary, scene%n, scene%ny, error)
         end if
         if (allocated(error)) return
         call check_scene(scene, error)
         if (allocated(error)) then
            error%message = "&profile: file = '" // trim(scene%profile%file) // "' sets the grid (no &scene n, " // &
               & 'nx or ny given), and ' // error%message
            return
         end if
      end if
      if (scene%solver%target_error /= not_set) then
         call choose_resolution(scene, error)
         if (allocated(error)) return
         ! (the grid chosen must be one the scene may have)
         call check_scene(scene, error)
         if (allocated(error)) return
      end if
      if (is_distributed()) then
         call check_distributed(scene, error)
         if (allocated(error)) return
      end if
      if (is_distributed()) then
         ! each rank makes its slab (a self-affine surface by the distributed c2r: its
         ! phases are seeded by mode; a height file read by slabs)
         call make_profile_slab(scene, height, error)
         if (global_failure(error)) return
      else
         allocate (height(scene%n*scene%ny))
         call make_profile(scene, height, error)
         if (allocated(error)) return
      end if
      call warn_if_not_periodic(scene, height, unit >= 0)
      ! bad input in the profile (a file's content) is found before anything is created
      call check_output(output_file, scene%overwrite, error)
      if (allocated(error)) return

      ! the leakage runs after the solve, next to the solution's fields (and the companion's):
      ! a grid whose leakage would not fit ends here, before the solve (distributed: each
      ! rank its slab's)
      if (scene%leakage) then
         call slab(max(scene%ny, 1), y_start, rows)
         call leakage_memory_check(int(scene%n, i8)*rows, &
            & merge(2, 1, scene%companion)*merge(10, 4, scene%stress), error)
         if (allocated(error)) return
      end if
      call solve_runs(scene, height, result, companion, error)
      if (allocated(error)) return
      converged = result%converged
      if (scene%companion) converged = converged .and. companion%converged
      call system_clock(finish)
      run%seconds = real(finish - start, wp)/real(rate, wp)
      if (scene%companion) then
         call write_result_file(output_file, scene, text, height, result, version_string, run, error, companion)
      else
         call write_result_file(output_file, scene, text, height, result, version_string, run, error)
      end if
      agreed = allocated(error)
      if (allocated(error)) return
      ! (x-differences lie inside a row: each rank its rows, the largest over the ranks)
      slope = largest_slope(result%displacement_z, scene)
      if (is_distributed()) slope = global_max(slope)
      if (unit >= 0) then
         if (scene%companion) then
            call print_summary(unit, input, output_file, scene, result, slope, companion)
         else
            call print_summary(unit, input, output_file, scene, result, slope)
         end if
      end if
   end subroutine run_scene

   !> True if some rank failed (every rank's profile is checked alike, but a file may be
   !> read by one rank only): the others then stop too, with their own or a common error.
   logical function global_failure(error)
      type(error_type), allocatable, intent(inout) :: error
      global_failure = global_any(allocated(error))
      if (global_failure .and. .not. allocated(error)) &
         & call fatal_error(error, 'the profile failed on another MPI rank', code_input)
   end function global_failure

   !> What a scene must be to be shared among the job's ranks: areal, with at least a row
   !> for each rank (lc_base_parallel).
   subroutine check_distributed(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      if (.not. is_areal(scene)) then
         call fatal_error(error, 'line scenes run on one rank: &scene n = ' // to_string(scene%n) // &
            & ' is a line and this run has ' // to_string(rank_count()) // ' MPI ranks; allowed: 1 rank ' // &
            & '(run it without mpirun, or with -n 1), or an areal scene (&scene ny > 1)', code_input)
         return
      end if
      call check_rank_count(scene%ny, error)
   end subroutine check_distributed

   !> A height file taken as one period (&profile boundary = 'periodic') whose heights jump
   !> or kink across the cell's edges is most likely a tilted or non-periodic measurement,
   !> which the solve would take as a periodic surface with a step (or kink) at each edge:
   !> a warning on standard error says so and what to set (limits: docs/decisions/019), if
   !> `speak`. A surface shared among MPI ranks (`height`: this rank's slab) is measured by
   !> all of them together.
   subroutine warn_if_not_periodic(scene, height, speak)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: height(:)
      logical, intent(in) :: speak
      real(wp) :: jump, kink
      if (trim(scene%profile%kind) /= 'file' .or. trim(scene%profile%boundary) /= 'periodic') return
      if (is_distributed() .and. is_areal(scene)) then
         call slab_periodicity_mismatch(height, scene%n, scene%ny, jump, kink)
      else
         if (.not. speak) return
         call periodicity_mismatch(reshape(height, [scene%n, max(scene%ny, 1)]), jump, kink)
      end if
      if (.not. speak .or. (jump <= edge_jump_limit .and. kink <= edge_kink_limit)) return
      write (error_unit, '(a, f0.2, a, es9.2, a)') "layercontact: warning: &profile: file = '" // &
         & trim(scene%profile%file) // "' is taken as one period (boundary = 'periodic'), but its heights jump by ", &
         & jump, ' rms heights across the edges of the cell and their slopes differ there by ', kink, &
         & " times their differences inside it: a tilted or non-periodic surface; set &profile boundary = " // &
         & "'mirror' (a non-periodic patch, detrended by a plane) or detrend = 'plane' (a tilt)"
   end subroutine warn_if_not_periodic

   !> A namelist file that is there must be a regular file: a FIFO would block the read
   !> until a writer comes (bad input, code 2; a missing file is the reader's to report).
   subroutine check_input_file(input, error)
      character(len=*), intent(in) :: input
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: detail
      integer :: kind
      call path_kind(input, kind, detail)
      if (kind /= kind_regular .and. kind /= kind_missing .and. kind /= kind_unknown) &
         & call fatal_error(error, "namelist file '" // input // "' is " // kind_name(kind) // &
         & '; allowed: a regular file', code_input)
   end subroutine check_input_file

   !> The largest |dw/dx| of the surface displacement along the sliding direction (of the
   !> rows `w` holds: all of them, or a rank's slab).
   pure real(wp) function largest_slope(w, scene) result(slope)
      real(wp), intent(in) :: w(:)
      type(scene_type), intent(in) :: scene
      integer :: nx, ny
      nx = scene%n
      ny = size(w)/max(nx, 1)
      slope = 0.0_wp
      if (nx < 2 .or. ny < 1 .or. size(w) /= nx*ny) return
      associate (rows => reshape(w, [nx, ny]))
         slope = maxval(abs(rows(2:, :) - rows(:nx - 1, :)))*nx/scene%period
      end associate
   end function largest_slope

   !> The summary of the run; `slope`: the largest |dw/dx| of the whole surface (largest_slope).
   subroutine print_summary(unit, input, output_file, scene, result, slope, companion)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: input, output_file
      type(scene_type), intent(in) :: scene
      type(contact_result), intent(in) :: result
      real(wp), intent(in) :: slope
      type(contact_result), intent(in), optional :: companion
      character(len=*), parameter :: real_fmt = '(2x, a, t34, es14.6, 1x, a)'
      character(len=*), parameter :: int_fmt = '(2x, a, t34, i14, 1x, a)'
      real(wp) :: resolution

      write (unit, '(a)') 'layercontact ' // version_string // ' (' // build_isa // '): ' // trim(input)
      if (len_trim(scene%title) > 0) write (unit, '(2x, a)') trim(scene%title)
      if (scene%ny > 1) write (unit, '(2x, a, t34, i6, a, i6, a)') 'areal grid nx x ny', scene%n, ' x', scene%ny
      write (unit, real_fmt) 'thickness h/lambda', scene%thickness/scene%period
      if (len(foundation(scene)) > 0) write (unit, '(2x, a, t34, a)') 'interface below the layer', foundation(scene)
      if (scene%solver%target_error /= not_set) then
         write (unit, real_fmt) 'target error', scene%solver%target_error
         write (unit, int_fmt) 'grid points n (chosen)', scene%n
         write (unit, real_fmt) 'tolerance tol (chosen)', scene%solver%tol
      end if
      write (unit, real_fmt) 'Coulomb friction mu_c', result%friction
      write (unit, real_fmt) 'mean pressure p_m', result%mean_pressure, '(S)'
      if (ieee_is_finite(result%normalised_pressure)) &
         & write (unit, real_fmt) 'normalised pressure', result%normalised_pressure, &
         & trim(merge('(p_m/(E* h/lambda))      ', '(p_m/(E* Lambda0/lambda))', &
         & scene%ny > 1 .and. ieee_is_finite(scene%thickness)))
      write (unit, real_fmt) 'contact fraction', result%contact_fraction
      if (present(companion)) then
         write (unit, real_fmt) 'contact fraction, mu_c = 0', companion%contact_fraction
         write (unit, real_fmt) 'a/a0', result%contact_fraction/companion%contact_fraction
      end if
      write (unit, real_fmt) 'penetration Delta', result%penetration, '(L)'
      if (present(companion)) write (unit, real_fmt) 'penetration Delta, mu_c = 0', companion%penetration, '(L)'
      if (is_viscoelastic(scene%material)) &
         & write (unit, '(2x, a, t34, a)') 'material', trim(scene%material%model) // ' (viscoelastic)'
      ! (a speed is allowed only where a layer is viscoelastic: the top one or a lower one)
      if (is_viscoelastic(scene%material) .or. scene%speed > 0.0_wp) then
         write (unit, real_fmt) 'sliding speed V', scene%speed, '(L/T)'
         write (unit, real_fmt) 'dissipated power', result%dissipated_power, '(S L/T)'
      end if
      if (.not. result%monotone) write (unit, '(2x, a)') 'WARNING: Re G_eff < 0 on some modes: ' // &
         & 'the contact solution may not be unique (viscoelastic coupling with friction)'
      if (.not. result%converged .and. result%gap_resolution > scene%solver%tol) &
         & write (unit, '(2x, a, es10.2e3, a, es9.2, a)') &
         & 'WARNING: at this load double precision resolves gaps only to', result%gap_resolution, &
         & ' of the profile''s height range, above tol =', scene%solver%tol, &
         & ': the pressure''s variation is lost in the rounding of p_m (not converged)'
      ! Delta mu = <p w'>/p_m carries the rounding of w' (a frictionless elastic scene's is
      ! zero exactly): below that it is printed as zero (the result file keeps the value)
      resolution = 64*epsilon(1.0_wp)*slope
      if (abs(result%delta_mu) > resolution) then
         write (unit, real_fmt) 'interlocking friction Delta mu', result%delta_mu
         write (unit, real_fmt) 'total friction mu_c + Delta mu', result%friction + result%delta_mu
      else
         write (unit, '(2x, a, t34, a14, a, es8.1, a)') 'interlocking friction Delta mu', '0', &
            & ' (|Delta mu| <', resolution, ', the rounding of w'')'
         write (unit, real_fmt) 'total friction mu_c + Delta mu', result%friction
      end if
      if (result%has_conductance) then
         write (unit, real_fmt) 'conductance C', result%conductance, '(sigma/L)'
         write (unit, real_fmt) 'contact stiffness K', result%contact_stiffness, '(S/L)'
         if (present(companion)) then
            write (unit, real_fmt) 'conductance C, mu_c = 0', companion%conductance, '(sigma/L)'
            write (unit, real_fmt) 'contact stiffness K, mu_c = 0', companion%contact_stiffness, '(S/L)'
         end if
         if (.not. result%conductance_converged) write (unit, '(2x, a)') &
            & 'WARNING: the conductance or stiffness iteration did not reach tol'
      end if
      if (allocated(result%leakage)) then
         write (unit, real_fmt) 'leakage k_eff along x', result%leakage%x%k_eff, '(L^3)'
         write (unit, real_fmt) 'leakage k_eff along y', result%leakage%y%k_eff, '(L^3)'
         if (present(companion)) then
            if (allocated(companion%leakage)) then
               write (unit, real_fmt) 'leakage k_eff x, mu_c = 0', companion%leakage%x%k_eff, '(L^3)'
               write (unit, real_fmt) 'leakage k_eff y, mu_c = 0', companion%leakage%y%k_eff, '(L^3)'
            end if
         end if
         if (.not. (result%leakage%x%converged .and. result%leakage%y%converged)) write (unit, '(2x, a)') &
            & 'WARNING: the leakage solve did not reach leakage_tol (k_eff is an upper bound)'
      end if
      write (unit, '(2x, a, t34, a14)') 'solver', trim(result%solver)
      write (unit, int_fmt) 'threads (OpenMP)', result%omp_threads
      write (unit, int_fmt) 'iterations', result%iterations
      if (result%outer_iterations > 1) write (unit, int_fmt) 'outer (Anderson) iterations', result%outer_iterations
      write (unit, real_fmt) 'residual', result%residual
      write (unit, '(2x, a, t34, l14)') 'converged', result%converged
      if (present(companion)) write (unit, '(2x, a, t34, l14)') 'converged, mu_c = 0', companion%converged
      if (present(companion)) then
         write (unit, real_fmt) 'solver time (both runs)', result%wall_time + companion%wall_time, '(s)'
      else
         write (unit, real_fmt) 'solver time', result%wall_time, '(s)'
      end if
      write (unit, '(2x, a, t34, a)') 'result file', output_file
   end subroutine print_summary
end module lc_application_run
