!> Unit tests of the input/output modules: namelist parsing and its error messages,
!> the namelist echo round trip, the output pre-check, the HDF5 writer and profile reader,
!> the result's scalars by name and scenes solved from namelist text (the Python route).
!> Run in a scratch directory: files are created under ./test_io_scratch/.
program test_io
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, code_input, code_io
   use lc_scene, only: scene_type, not_set, companion_of
   use lc_result, only: contact_result, result_scalar, result_scalars
   use lc_application_scene_text, only: solve_scene_text
   use lc_io_namelist, only: read_scene, read_scene_text, write_scene_namelist
   use lc_io_hdf5, only: check_output, write_results
   use lc_profiles_measured, only: measured_heights
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   character(len=*), parameter :: dir = 'test_io_scratch'
   character(len=*), parameter :: nl = new_line('a')

   ! start from an empty scratch directory: the checks below expect files not to exist
   call execute_command_line('rm -rf ' // dir)
   call test_valid_namelist()
   call test_namelist_errors()
   call test_round_trip()
   call test_check_output()
   call test_write_and_read()
   call test_result_scalars()
   call test_companion_of()
   call test_solve_scene_text()
   call finish('input/output')

contains

   !> The error exists, has `code` and its message contains every one of `parts`.
   subroutine check_error(error, code, parts, label)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(in) :: code
      character(len=*), intent(in) :: parts(:)
      character(len=*), intent(in) :: label
      integer :: i
      call check(allocated(error), label // ': an error is returned')
      if (.not. allocated(error)) return
      call check(error%code == code, label // ': error code')
      do i = 1, size(parts)
         call check(index(error%message, trim(parts(i))) > 0, label // ": message contains '" // trim(parts(i)) &
            & // "'; got: " // error%message)
      end do
   end subroutine check_error

   subroutine write_text(filename, text)
      character(len=*), intent(in) :: filename, text
      integer :: unit
      open (newunit=unit, file=filename, access='stream', form='unformatted', status='replace', action='write')
      write (unit) text
      close (unit)
   end subroutine write_text

   !> No file ending in .tmp in `directory` (the writer's temporary files are NAME.HOST.PID.tmp).
   logical function no_temporary_files(directory)
      character(len=*), intent(in) :: directory
      integer :: status
      call execute_command_line('test -z "$(find ' // directory // " -maxdepth 1 -name '*.tmp')" // '"', &
         & exitstat=status)
      no_temporary_files = status == 0
   end function no_temporary_files

   logical function file_exists(filename)
      character(len=*), intent(in) :: filename
      inquire (file=filename, exist=file_exists)
   end function file_exists

   subroutine test_valid_namelist()
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      character(len=:), allocatable :: text, input

      call make_dir()
      ! comments, quotes holding '&' and '!', upper case, CR LF and an `&end` terminator
      input = '! a comment naming &nothing' // nl &
         & // "&scene title = 'A & B ! not a comment', n = 64 /" // nl &
         & // '&LAYER thickness = Inf, young = 2.5 ! modulus' // achar(13) // nl &
         & // '  poisson = 0.3 /' // nl &
         & // '&profile kind = "sinusoid", amplitude = 0.01, mode = 3' // nl &
         & // '&end' // nl &
         & // '&loading normalised_pressure = 0.2 /' // nl &
         & // '&friction coefficient = 0.4, companion = .true. /' // nl
      call write_text(dir // '/valid.nml', input)
      call read_scene(dir // '/valid.nml', scene, text, error)
      call check(.not. allocated(error), 'valid namelist is accepted')
      if (allocated(error)) then
         write (*, '(a)') error%message
         return
      end if
      call check(text == input, 'the file text is kept')
      call check(trim(scene%title) == 'A & B ! not a comment', 'title')
      call check(scene%n == 64, 'n')
      call check(scene%thickness > huge(1.0_wp), 'thickness = Inf')
      call check(scene%young == 2.5_wp .and. scene%poisson == 0.3_wp, 'young, poisson')
      call check(trim(scene%profile%kind) == 'sinusoid' .and. scene%profile%mode == 3, 'profile')
      call check(scene%normalised_pressure == 0.2_wp .and. scene%mean_pressure == not_set, 'loading')
      call check(scene%friction == 0.4_wp .and. scene%companion, 'friction')
      call check(scene%period == 1.0_wp .and. scene%solver%max_iter == 100000, 'defaults from scene_type')
   end subroutine test_valid_namelist

   subroutine test_namelist_errors()
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      character(len=:), allocatable :: text
      character(len=*), parameter :: loading = '&loading mean_pressure = 0.1 /' // nl

      call read_scene_text('&scene n = 64 /' // nl // nl // '&layr thickness = 1 /' // nl, 'a.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'a.nml', 'line 3', "'&layr'", &
         & '&scene, &layer, &material, &friction', '&output'], 'unknown group')

      call read_scene_text('&layer young = 2 /' // nl // "&scene title = '&x' /" // nl // '&layer /' // nl, &
         & 'b.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'b.nml', 'line 3', "'&layer'", 'twice'], &
         & 'repeated group')

      call read_scene_text(loading // '&layer' // nl // '   young = 2,' // nl // '   thicknes = 1' // nl // '/' // nl, &
         & 'c.nml', scene, error)
      call check_error(error, code_input, [character(len=60) :: 'c.nml', 'line 4', 'group &layer', &
         & 'Cannot match namelist object name thicknes', 'allowed variables in &layer: thickness, young, poisson'], &
         & 'unknown variable')

      call read_scene_text(loading // '&layer thickness = 1' // nl // nl // '  young = abc /' // nl, &
         & 'd.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'd.nml', 'line 4', 'group &layer', 'abc'], &
         & 'bad real value')

      call read_scene_text(loading // '&scene' // nl // '  period = 2.0' // nl // '  n = 2.5' // nl // '/', &
         & 'e.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'e.nml', 'line 4', 'group &scene', &
         & "'n = 2.5': n takes an integer"], 'bad integer value')

      call read_scene_text(loading // '&friction companion = yes /', 'f.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'f.nml', 'line 2', 'group &friction'], &
         & 'bad logical value')

      call read_scene_text(loading // '&solver tol = 1e-8' // nl // 'max_iter = 10' // nl, 'g.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: 'g.nml', 'line 2', 'group &solver', "'/'"], &
         & 'missing terminator')

      call read_scene_text(loading // '&layer poisson = 0.7 /', 'h.nml', scene, error)
      call check_error(error, code_input, [character(len=40) :: '&layer: poisson'], 'check_scene error is returned')

      call read_scene(dir // '/does_not_exist.nml', scene, text, error)
      call check_error(error, code_io, [character(len=40) :: 'does_not_exist.nml'], 'missing file')
   end subroutine test_namelist_errors

   subroutine test_round_trip()
      type(scene_type) :: scene, back
      type(error_type), allocatable :: error
      character(len=:), allocatable :: text, again

      scene%title = "it's a test, with & and !"
      scene%period = 3.0_wp
      scene%n = 512
      scene%thickness = ieee_value(1.0_wp, ieee_positive_inf)
      scene%young = 1.0_wp / 3.0_wp
      scene%poisson = 0.25_wp
      scene%friction = 0.3_wp
      scene%companion = .true.
      scene%material%model = 'prony'
      scene%material%form = 'creep'
      scene%material%equilibrium = 0.5_wp
      scene%material%times = [0.1_wp, 1.0_wp/3.0_wp, 10.0_wp]
      scene%material%values = [0.2_wp, 0.3_wp, 1.0_wp/7.0_wp]
      scene%speed = 0.7_wp
      scene%profile%hurst = 0.7_wp
      scene%profile%seed = 123456789012_i8
      scene%profile%rolloff_wavelength = 0.5_wp
      scene%profile%short_wavelength = 0.1_wp
      scene%profile%rms_height = 1.0e-3_wp / 7.0_wp
      scene%profile%file = 'heights.h5'
      scene%control = 'displacement'
      scene%penetration = 2.0e-3_wp
      scene%solver%method = 'anderson'
      scene%solver%tol = 1.0e-9_wp
      scene%solver%memory = 7
      scene%output_file = 'out/result.h5'
      scene%overwrite = .true.

      call write_scene_namelist(scene, text)
      call read_scene_text(text, 'echo', back, error)
      call check(.not. allocated(error), 'the echo is a valid namelist')
      if (allocated(error)) then
         write (*, '(a)') error%message
         return
      end if
      call check(same_scene(scene, back), 'read_scene_text(write_scene_namelist(scene)) == scene')
      call write_scene_namelist(back, again)
      call check(text == again, 'the echo of the echo is identical')

      call write_text(dir // '/echo.nml', text)
      call read_scene(dir // '/echo.nml', back, again, error)
      call check(.not. allocated(error), 'the echo reads back from a file')
      call check(same_scene(scene, back), 'read_scene(echo file) == scene')

      ! the defaults too: a default scene fails check_scene (no load, no roughness scale)
      back = scene_type()
      back%normalised_pressure = 0.1_wp
      back%profile%rms_gradient = 0.1_wp
      call write_scene_namelist(back, text)
      call read_scene_text(text, 'default echo', scene, error)
      call check(.not. allocated(error), 'the echo of the default scene is valid')
      call check(same_scene(scene, back), 'default scene round trip')
   end subroutine test_round_trip

   logical function same_scene(a, b)
      type(scene_type), intent(in) :: a, b
      same_scene = a%geometry == b%geometry .and. a%title == b%title .and. a%period == b%period &
         & .and. a%n == b%n .and. a%thickness == b%thickness .and. a%young == b%young &
         & .and. a%poisson == b%poisson .and. a%friction == b%friction .and. (a%companion .eqv. b%companion) &
         & .and. a%material%model == b%material%model .and. a%material%form == b%material%form &
         & .and. a%material%e0 == b%material%e0 .and. a%material%e_inf == b%material%e_inf &
         & .and. a%material%tau == b%material%tau .and. a%material%equilibrium == b%material%equilibrium &
         & .and. a%speed == b%speed .and. a%material%terms() == b%material%terms() .and. same_terms(a, b) &
         & .and. a%profile%kind == b%profile%kind .and. a%profile%hurst == b%profile%hurst &
         & .and. a%profile%seed == b%profile%seed .and. a%profile%rolloff_wavelength == b%profile%rolloff_wavelength &
         & .and. a%profile%short_wavelength == b%profile%short_wavelength &
         & .and. a%profile%rms_gradient == b%profile%rms_gradient .and. a%profile%rms_height == b%profile%rms_height &
         & .and. a%profile%amplitude == b%profile%amplitude .and. a%profile%mode == b%profile%mode &
         & .and. a%profile%file == b%profile%file .and. a%profile%dataset == b%profile%dataset &
         & .and. a%control == b%control .and. a%mean_pressure == b%mean_pressure &
         & .and. a%normalised_pressure == b%normalised_pressure .and. a%penetration == b%penetration &
         & .and. a%solver%method == b%solver%method .and. a%solver%tol == b%solver%tol &
         & .and. a%solver%max_iter == b%solver%max_iter .and. a%solver%memory == b%solver%memory &
         & .and. a%solver%threads == b%solver%threads .and. a%output_file == b%output_file &
         & .and. (a%overwrite .eqv. b%overwrite) .and. (a%solver%precondition .eqv. b%solver%precondition) &
         & .and. (a%solver%coarse_start .eqv. b%solver%coarse_start) &
         & .and. a%solver%target_error == b%solver%target_error &
         & .and. (a%stress .eqv. b%stress) .and. a%gap_bins == b%gap_bins
   end function same_scene

   logical function same_terms(a, b)
      type(scene_type), intent(in) :: a, b
      same_terms = a%material%terms() == b%material%terms()
      if (same_terms .and. a%material%terms() > 0) same_terms = all(a%material%times == b%material%times) &
         & .and. all(a%material%values == b%material%values)
   end function same_terms

   subroutine test_check_output()
      type(error_type), allocatable :: error
      logical :: exists

      type(scene_type) :: scene
      type(contact_result) :: result
      real(wp) :: height(8)

      ! a file that is not an HDF5 file is never replaced, overwrite or not
      call write_text(dir // '/existing.h5', 'x')
      call check_output(dir // '/existing.h5', .false., error)
      call check_error(error, code_io, [character(len=40) :: 'existing.h5', 'is not an HDF5 file'], &
         & 'an existing file that is not HDF5 is refused')
      call check_output(dir // '/existing.h5', .true., error)
      call check_error(error, code_io, [character(len=40) :: 'existing.h5', 'is not an HDF5 file'], &
         & 'an existing file that is not HDF5 is refused with overwrite')

      ! an existing result: refused without overwrite, accepted with it
      scene%n = 8
      height = 0.0_wp
      call fake_result(8, 0.0_wp, 0.5_wp, result)
      call write_results(dir // '/result_there.h5', scene, '', height, result, version='x', error=error)
      call check(.not. allocated(error), 'a result to be in the way is written')
      call check_output(dir // '/result_there.h5', .false., error)
      call check_error(error, code_io, [character(len=40) :: 'result_there.h5', 'set &output overwrite = .true.'], &
         & 'existing output file is refused')
      call check_output(dir // '/result_there.h5', .true., error)
      call check(.not. allocated(error), 'existing output file with overwrite is accepted')

      call check_output(dir // '/new/deeper/result.h5', .false., error)
      call check(.not. allocated(error), 'missing parent directories are created')
      inquire (file=dir // '/new/deeper/.', exist=exists)
      call check(exists, 'the parent directory exists afterwards')

      call check_output(dir // '/existing.h5/result.h5', .false., error)
      call check_error(error, code_io, [character(len=40) :: 'existing.h5'], 'a file in the way of the directory')
   end subroutine test_check_output

   subroutine test_write_and_read()
      integer, parameter :: n = 16
      character(len=*), parameter :: file = dir // '/new/deeper/result.h5'
      type(scene_type) :: scene
      type(contact_result) :: result, companion
      type(error_type), allocatable :: error
      real(wp) :: height(n), back(n), short(n/2)
      integer :: j

      scene%n = n
      scene%friction = 0.2_wp
      scene%companion = .true.
      scene%normalised_pressure = 0.1_wp
      height = [(0.01_wp*cos(8*atan(1.0_wp)*j/n), j=0, n - 1)]
      call fake_result(n, 0.2_wp, 0.5_wp, result)
      call fake_result(n, 0.0_wp, 0.4_wp, companion)

      call write_results(file, scene, '&scene n = 16 /', height, result, companion, '0.1.0-test', error)
      call check(.not. allocated(error), 'write_results succeeds')
      if (allocated(error)) write (*, '(a)') error%message
      call check(file_exists(file), 'the result file exists')
      call check(no_temporary_files(dir // '/new/deeper'), 'no temporary file remains')
      ! without overwrite a second write keeps the first result and says why
      call write_results(file, scene, '&scene n = 16 /', height, result, companion, '0.1.0-test', error)
      call check_error(error, code_io, [character(len=40) :: 'was written by another run'], &
         & 'a result written meanwhile is not replaced')
      call check(no_temporary_files(dir // '/new/deeper'), 'no temporary file remains after the refusal')

      ! again, over the existing file and without a companion (HDF5 opened and closed again)
      call write_results(dir // '/plain.h5', scene, '', height, result, version='0.1.0-test', error=error)
      call check(.not. allocated(error), 'write_results succeeds a second time')

      call write_results(dir // '/no_such_dir/result.h5', scene, '', height, result, version='x', error=error)
      call check_error(error, code_io, [character(len=40) :: 'no_such_dir/result.h5', 'the write failed at'], &
         & 'write into a missing directory')
      call check(no_temporary_files(dir), 'no temporary file after a failure')

      ! a result's profile is a line profile the reader of &profile kind = 'file' takes
      call measured_heights(file, '/profile/height', .false., 'auto', 'periodic', 'none', n, 1, back, error)
      call check(.not. allocated(error), 'measured_heights reads a result file')
      call check(all(back == height), 'the heights read back exactly')

      call measured_heights(file, '/profile/height', .false., 'auto', 'periodic', 'none', n/2, 1, short, error)
      call check_error(error, code_input, [character(len=40) :: 'result.h5', 'holds 16 heights', 'n = 8'], &
         & 'wrong number of heights')
      call measured_heights(file, '/profile/nothing', .false., 'auto', 'periodic', 'none', n, 1, back, error)
      call check_error(error, code_input, [character(len=40) :: 'result.h5', '/profile/nothing'], 'missing dataset')
      call measured_heights(dir // '/valid.nml', '/profile/height', .false., 'auto', 'periodic', 'none', n, 1, &
         & back, error)
      ! the extension picks the format: a namelist is text, and not numbers
      call check_error(error, code_input, [character(len=40) :: 'valid.nml', 'is not a number'], 'not heights')
   end subroutine test_write_and_read

   subroutine test_result_scalars()
      type(contact_result) :: result
      type(result_scalar), allocatable :: table(:)
      integer :: i
      call fake_result(16, 0.2_wp, 0.5_wp, result)
      table = result_scalars(result, .false.)
      call check(all([(count(table%name == table(i)%name) == 1, i = 1, size(table))]), 'every scalar name once')
      call check(.not. any(table%name == 'max_tension'), 'no stress scalars without the stress')
      call check(.not. any(table%name == 'a_over_a0'), 'no a_over_a0 without a companion')
      call check(any(table%name == 'mean_pressure' .and. table%value == 0.1_wp .and. table%unit == 'S'), &
         & 'mean_pressure by name, with its unit')
      call check(any(table%name == 'iterations' .and. table%is_integer .and. table%value == 3), 'a count')
      allocate (result%stress_xx(16))
      table = result_scalars(result, .true., 0.9_wp)
      call check(any(table%name == 'max_tension') .and. any(table%name == 'max_principal_stress'), &
         & 'the stress scalars of a surface')
      call check(table(size(table))%name == 'a_over_a0' .and. table(size(table))%value == 0.9_wp, 'a_over_a0 last')
   end subroutine test_result_scalars

   subroutine test_companion_of()
      type(scene_type) :: scene, companion
      scene%mean_pressure = 0.25_wp
      companion = companion_of(scene, 0.2500001_wp)
      call check(companion%mean_pressure == 0.25_wp, 'under load control the companion keeps the load')
      scene%control = 'displacement'
      scene%mean_pressure = not_set
      scene%penetration = 0.01_wp
      companion = companion_of(scene, 0.3_wp)
      call check(trim(companion%control) == 'load' .and. companion%mean_pressure == 0.3_wp .and. &
         & companion%penetration == not_set, 'under displacement control, the load found')
   end subroutine test_companion_of

   subroutine test_solve_scene_text()
      integer, parameter :: n = 64
      real(wp) :: height(n), fields(n, 6, 2), spots(n/2 + 1, 5, 2), history(100, 2)
      character(len=8192) :: table
      character(len=27) :: digits
      type(error_type), allocatable :: error
      real(wp) :: printed
      integer :: j, status
      height = [(0.01_wp*cos(8*atan(1.0_wp)*j/n), j=0, n - 1)]
      call solve_scene_text('&scene' // nl // ' n = 64' // nl // '/' // nl // '&friction' // nl // &
         & ' coefficient = 0.3' // nl // ' companion = .true.' // nl // '/' // nl // '&layer' // nl // &
         & ' thickness = 0.2' // nl // '/' // nl // '&loading' // nl // ' mean_pressure = 1e-3' // nl // '/' // nl, &
         & height, fields, spots, history, table, error)
      call check(.not. allocated(error), 'solve_scene_text succeeds')
      if (allocated(error)) write (*, '(a)') error%message
      call check(index(table, 'input/period = 1.0') > 0, 'the period, resolved')
      ! (printed with all 17 significant digits and its unit; the value is p_m to the rounding
      ! of the solver's scaling to the load and of the mean, a few ulps: the last digit moves
      ! with the order of the solver's sums)
      j = index(table, nl // 'results/mean_pressure = ')
      printed = 0.0_wp
      if (j > 0) then
         digits = table(j + 25:j + 25 + len('1.00000000000000002E-003 S'))
         read (digits(1:24), *, iostat=status) printed
      end if
      call check(j > 0 .and. status == 0 .and. verify(digits(1:1) // digits(3:19), '0123456789') == 0 .and. &
         & digits(2:2) == '.' .and. digits(20:20) == 'E' .and. digits(25:27) == ' S' // nl .and. &
         & abs(printed - 1.0e-3_wp) <= 4*spacing(1.0e-3_wp), 'mean_pressure by name, all its digits and its unit')
      call check(index(table, nl // 'fields = pressure gap displacement_z displacement_x shear stress_xx' // nl) > 0, &
         & 'the field columns by name')
      call check(index(table, nl // 'companion/results/friction = 0.') > 0, 'the frictionless companion')
      call check(index(table, 'results/a_over_a0 = ') > 0, 'a/a0')
      call check(all(fields(:, 1, 1) >= 0) .and. abs(sum(fields(:, 1, 1))/n - 1.0e-3_wp) < 1.0e-15_wp, &
         & 'the pressure carries the load')
      call solve_scene_text('&layer' // nl // ' poisson = 0.7' // nl // '/' // nl, height, fields, spots, history, &
         & table, error)
      call check_error(error, code_input, [character(len=60) :: '&layer: poisson = 7.00000E-01 is not allowed'], &
         & 'a bad value in the text: the namelist message')
   end subroutine test_solve_scene_text

   !> A made-up result with recognisable values (no solver involved).
   subroutine fake_result(n, friction, fraction, res)
      integer, intent(in) :: n
      real(wp), intent(in) :: friction, fraction
      type(contact_result), intent(out) :: res
      integer :: j
      allocate (res%pressure(n), res%gap(n), res%displacement_z(n), res%residual_history(3))
      do j = 1, n
         res%pressure(j) = max(0.0_wp, real(n/2 - j, wp))
         res%gap(j) = max(0.0_wp, real(j - n/2, wp))
         res%displacement_z(j) = 1.0e-3_wp*j
      end do
      res%residual_history(:) = [1.0_wp, 1.0e-4_wp, 1.0e-11_wp]
      res%friction = friction
      res%mean_pressure = 0.1_wp
      res%penetration = 0.02_wp
      res%contact_fraction = fraction
      res%delta_mu = 0.01_wp
      res%converged = .true.
      res%iterations = 3
      res%fft_pairs = 4
      res%residual = 1.0e-11_wp
      res%wall_time = 0.5_wp
   end subroutine fake_result

   subroutine make_dir()
      type(error_type), allocatable :: error
      ! check_output creates the directory (mkdir -p) and is itself under test below
      call check_output(dir // '/placeholder', .true., error)
      call check(.not. allocated(error), 'scratch directory')
   end subroutine make_dir
end program test_io
