!> Scenes given as namelist text: the route of the Python driver, whose keywords become
!> the text of the groups they belong to. Defaults, validation and messages are therefore
!> those of a namelist file (lc_io_namelist, lc_scene); a keyword that is not given keeps
!> the scene's default. What a solve returns is described by name, with the names of the
!> result file (lc_io_hdf5): /results attributes, /fields, /spots or /patches datasets,
!> /convergence/residual, and the same under companion/ for the frictionless companion.
module lc_application_scene_text
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_base_strings, only: to_string
   use lc_scene, only: scene_type, profile_spec, is_areal, material_of, not_set, grid_of, &
      & kernel_of, default_rms_gradient
   use lc_result, only: contact_result, result_scalar, result_scalars
   use lc_io_namelist, only: read_scene_text
   use lc_application_scene_solve, only: solve_runs
   use lc_profiles_profile, only: make_profile
   use lc_greens_viscoelastic, only: material_law, max_prony_terms
   use lc_greens_kernel, only: layer_kernel
   use lc_contact_operator, only: compliance_operator, build_operator
   use lc_observables_surface, only: surface_fields
   use lc_observables_stress, only: surface_stress
   use lc_leakage_reynolds, only: leakage_max_iter, leakage_solver, smallest_leakage_tol, largest_leakage_tol
   implicit none (type, external)
   private
   public :: solve_scene_text, profile_of_text, material_of_text, surface_stress_of_text, tensor_of_text, &
      & library_constants

   !> Where keyword text comes from, for the messages of the namelist reader.
   character(len=*), parameter :: source = 'keywords'
   !> Width of a real in the description: 17 significant digits give the double back.
   character(len=*), parameter :: real_format = '(es25.17e3)'
   character(len=*), parameter :: newline = new_line('a')
   !> A load for the texts of a profile or a material alone (a scene is checked whole and
   !> needs one; neither the heights nor the law depend on it).
   character(len=*), parameter :: any_load = '&loading' // newline // ' normalised_pressure = 1.0' // newline // &
      & '/' // newline

contains

   !> Solve the scene of `text` on `height` (n*ny values, x fastest) and, when the scene asks
   !> for it (&friction companion), its frictionless companion as run 2. fields(:, :, run),
   !> spots(:, :, run) and history(:, run) receive the arrays that `table` names, in its
   !> order: the field and spot columns, and the number of residuals kept (the last ones).
   subroutine solve_scene_text(text, height, fields, spots, history, table, error)
      character(len=*), intent(in) :: text
      real(wp), intent(in) :: height(:)
      real(wp), intent(out) :: fields(:, :, :), spots(:, :, :), history(:, :)
      character(len=*), intent(out) :: table
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(contact_result) :: result, companion
      character(len=:), allocatable :: description

      ! fields and spots are filled after the solve, only as far as they are described: sized
      ! for the most a scene can return (a patch per two points), their untouched pages stay
      ! out of memory, and the solve's peak is not raised by them
      history = 0
      table = ''
      call read_scene_text(text, source, scene, error)
      if (allocated(error)) return
      if (size(height) /= scene%n*scene%ny .or. size(fields, 1) /= size(height) .or. &
         & (scene%companion .and. size(fields, 3) < 2)) then
         call fatal_error(error, 'solve_scene_text: ' // to_string(size(height)) // ' heights and room for ' // &
            & to_string(size(fields, 3)) // ' runs do not fit the scene', code_internal)
         return
      end if
      ! the heights are given: no profile is made; nothing asks for the gap histogram
      scene%profile%kind = 'file'
      scene%profile%file = '(heights given as an array)'
      scene%gap_bins = 0
      call solve_runs(scene, height, result, companion, error)
      if (allocated(error)) return
      ! the cell, as /input of a result file has it (period_y resolved)
      description = 'input/period = ' // real_text(scene%period) // newline // 'input/period_y = ' // &
         & real_text(merge(scene%period_y, scene%period, scene%period_y /= not_set)) // newline
      if (scene%companion) then
         call describe_run(result, is_areal(scene), '', fields(:, :, 1), spots(:, :, 1), history(:, 1), &
            & description, result%contact_fraction/companion%contact_fraction)
         call describe_run(companion, is_areal(scene), 'companion/', fields(:, :, 2), spots(:, :, 2), &
            & history(:, 2), description)
      else
         call describe_run(result, is_areal(scene), '', fields(:, :, 1), spots(:, :, 1), history(:, 1), description)
      end if
      if (len(description) > len(table)) then
         call fatal_error(error, 'solve_scene_text: the description needs ' // to_string(len(description)) // &
            & ' characters, room for ' // to_string(len(table)), code_internal)
         return
      end if
      table = description
   end subroutine solve_scene_text

   !> The heights of the scene's &profile (n*ny values, x fastest), made as a namelist run
   !> makes them. The text gives no &loading.
   subroutine profile_of_text(text, height, error)
      character(len=*), intent(in) :: text
      real(wp), intent(out) :: height(:)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      height = 0
      call read_scene_text(any_load // text, source, scene, error)
      if (allocated(error)) return
      if (size(height) /= scene%n*scene%ny) then
         call fatal_error(error, 'profile_of_text: room for ' // to_string(size(height)) // ' heights, the scene has ' &
            & // to_string(scene%n*scene%ny), code_internal)
         return
      end if
      call make_profile(scene, height, error)
   end subroutine profile_of_text

   !> The material law of the scene's &layer and &material (an elastic law takes young). The
   !> text gives no &loading.
   subroutine material_of_text(text, law, error)
      character(len=*), intent(in) :: text
      type(material_law), intent(out) :: law
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      call read_scene_text(any_load // text, source, scene, error)
      if (.not. allocated(error)) law = material_of(scene)
   end subroutine material_of_text

   !> In-plane surface displacements and stresses of the scene's layer under the prescribed
   !> pressure p (n*ny values, x fastest) and the shear friction*p along x, without a
   !> contact solve: fields(:, 1:5) = u_x, u_y, sigma_xx, sigma_yy, sigma_xy (a line: u_y,
   !> sigma_yy and sigma_xy zero). The text gives no &loading.
   subroutine surface_stress_of_text(text, p, fields, error)
      character(len=*), intent(in) :: text
      real(wp), intent(in) :: p(:)
      real(wp), intent(out) :: fields(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(compliance_operator) :: op
      fields = 0
      call read_scene_text(any_load // text, source, scene, error)
      if (allocated(error)) return
      if (size(p) /= scene%n*scene%ny .or. size(fields, 1) /= size(p) .or. size(fields, 2) < 5) then
         call fatal_error(error, 'surface_stress_of_text: ' // to_string(size(p)) // ' pressures for a scene of ' // &
            & to_string(scene%n*scene%ny) // ' points', code_internal)
         return
      end if
      call build_operator(op, grid_of(scene), kernel_of(scene), scene%friction, 1, error)
      if (allocated(error)) return
      if (is_areal(scene)) then
         call surface_stress(op, p, fields(:, 1), fields(:, 2), fields(:, 3), fields(:, 4), fields(:, 5))
      else
         call surface_fields(op, p, fields(:, 1), fields(:, 3))
      end if
   end subroutine surface_stress_of_text

   !> The 3x3 surface compliance of the scene's layer (lc_greens_kernel) for the wavevectors
   !> (qx(i), qy(i)): (u_x^, u_y^, w^) = tensor(i, :, :) (tau_x^, tau_y^, p^). The text gives
   !> no &loading.
   subroutine tensor_of_text(text, qx, qy, tensor, error)
      character(len=*), intent(in) :: text
      real(wp), intent(in) :: qx(:), qy(:)
      complex(wp), intent(out) :: tensor(:, :, :)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(layer_kernel) :: kernel
      integer :: i
      tensor = 0
      call read_scene_text(any_load // text, source, scene, error)
      if (allocated(error)) return
      kernel = kernel_of(scene)
      do i = 1, min(size(qx), size(qy), size(tensor, 1))
         tensor(i, :, :) = kernel%tensor(qx(i), qy(i))
      end do
   end subroutine tensor_of_text

   !> The library's limits, markers and the defaults of a self-affine &profile, as
   !> `name = value` lines (for callers that take the profile's values one by one).
   pure function library_constants() result(text)
      character(len=:), allocatable :: text
      type(profile_spec) :: profile
      type(scene_type) :: scene
      text = 'max_prony_terms = ' // to_string(max_prony_terms) // newline // &
         & 'output/leakage_tol = ' // real_text(scene%leakage_tol) // newline // &
         & 'leakage/max_iter = ' // to_string(leakage_max_iter) // newline // &
         & 'leakage/tol_range = ' // real_text(smallest_leakage_tol) // ' ' // real_text(largest_leakage_tol) // &
         & newline // &
         & 'leakage/solver = ' // leakage_solver // newline // &
         & 'not_set = ' // real_text(not_set) // newline // &
         & 'profile/hurst = ' // real_text(profile%hurst) // newline // &
         & 'profile/seed = ' // to_string(profile%seed) // newline // &
         & 'profile/rms_gradient = ' // real_text(default_rms_gradient) // newline
   end function library_constants

   !> Append what one run returns to `description` (lines `name = value unit`, the names
   !> prefixed with `prefix`) and copy its arrays out.
   subroutine describe_run(res, areal, prefix, fields, spots, history, description, a_over_a0)
      type(contact_result), intent(in) :: res
      logical, intent(in) :: areal
      character(len=*), intent(in) :: prefix
      real(wp), intent(out) :: fields(:, :), spots(:, :), history(:)
      character(len=:), allocatable, intent(inout) :: description
      real(wp), intent(in), optional :: a_over_a0
      type(result_scalar), allocatable :: scalars(:)
      character(len=:), allocatable :: text, names
      integer :: i, stored

      if (present(a_over_a0)) then
         scalars = result_scalars(res, areal, a_over_a0)
      else
         scalars = result_scalars(res, areal)
      end if
      text = ''
      do i = 1, size(scalars)
         text = text // prefix // 'results/' // trim(scalars(i)%name) // ' = ' // value_text(scalars(i))
         if (.not. scalars(i)%is_text) text = text // ' ' // trim(scalars(i)%unit)
         text = text // newline
      end do

      names = ''
      call add_column(names, fields, 'pressure', res%pressure)
      call add_column(names, fields, 'gap', res%gap)
      call add_column(names, fields, 'displacement_z', res%displacement_z)
      call add_column(names, fields, 'displacement_x', res%displacement_x)
      call add_column(names, fields, 'shear', res%shear)
      call add_column(names, fields, 'stress_xx', res%stress_xx)
      call add_column(names, fields, 'displacement_y', res%displacement_y)
      call add_column(names, fields, 'stress_yy', res%stress_yy)
      call add_column(names, fields, 'stress_xy', res%stress_xy)
      text = text // prefix // 'fields =' // names // newline

      names = ''
      if (allocated(res%patch_area)) then
         call add_column(names, spots, 'area', res%patch_area)
         call add_column(names, spots, 'perimeter', res%patch_perimeter)
         text = text // prefix // 'patches =' // names // newline
      else
         call add_column(names, spots, 'trailing_edge', res%spot_trailing)
         call add_column(names, spots, 'leading_edge', res%spot_leading)
         call add_column(names, spots, 'max_tension', res%spot_max_tension)
         call add_column(names, spots, 'max_tension_grid', res%spot_max_tension_grid)
         call add_column(names, spots, 'max_tension_offset', res%spot_tension_offset)
         text = text // prefix // 'spots =' // names // newline
      end if

      stored = 0
      if (allocated(res%residual_history)) stored = min(size(res%residual_history), size(history))
      if (stored > 0) history(:stored) = res%residual_history(size(res%residual_history) - stored + 1:)
      description = description // text // prefix // 'convergence/residual = ' // to_string(stored) // newline
   end subroutine describe_run

   !> Copy `values` (if computed) into the next free column of `columns` (the leading rows)
   !> and append its name.
   subroutine add_column(names, columns, name, values)
      character(len=:), allocatable, intent(inout) :: names
      real(wp), intent(inout) :: columns(:, :)
      character(len=*), intent(in) :: name
      real(wp), allocatable, intent(in) :: values(:)
      integer :: k, i
      if (.not. allocated(values)) return
      k = count([(names(i:i) == ' ', i = 1, len(names))]) + 1
      if (k > size(columns, 2) .or. size(values) > size(columns, 1)) return
      columns(:size(values), k) = values
      names = names // ' ' // name
   end subroutine add_column

   pure function value_text(scalar) result(text)
      type(result_scalar), intent(in) :: scalar
      character(len=:), allocatable :: text
      if (scalar%is_text) then
         text = trim(scalar%text)
         if (len(text) == 0) text = "''"
      else if (scalar%is_integer) then
         text = to_string(nint(scalar%value))
      else
         text = real_text(scalar%value)
      end if
   end function value_text

   pure function real_text(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      write (buffer, real_format) x
      text = trim(adjustl(buffer))
   end function real_text
end module lc_application_scene_text
