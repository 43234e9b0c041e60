!> layercontact: solve the sliding contact scene of a namelist file, write an HDF5 result.
!>
!>    layercontact FILE.nml | --defaults [line|areal] | --help | --version
!>
!> Exit codes: 0 converged; 2 bad input (nothing written); 3 not converged (results
!> written, flagged converged = 0); 4 I/O failure; 5 not enough memory or internal failure; 1 usage.
program layercontact
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use lc_base_errors, only: error_type, code_not_converged
   use lc_application_run, only: run_scene_file
   use lc_io_namelist, only: default_scene, write_scene_namelist
   use lc_base_version, only: version_string, build_isa
   implicit none (type, external)
   character(len=*), parameter :: usage = 'usage: layercontact FILE.nml | --defaults [line|areal] | --help | --version'
   type(error_type), allocatable :: error
   character(len=:), allocatable :: input, output_file, text
   character(len=16) :: geometry
   integer :: length
   logical :: converged, root

   if (command_argument_count() < 1 .or. command_argument_count() > 2) then
      write (error_unit, '(a)') usage
      stop 1, quiet=.true.
   end if
   call get_command_argument(1, length=length)
   allocate (character(len=length) :: input)
   call get_command_argument(1, input)
   if (command_argument_count() == 2 .and. input /= '--defaults') then
      write (error_unit, '(a)') usage
      stop 1, quiet=.true.
   end if
   select case (input)
   case ('--defaults')
      geometry = 'line'
      if (command_argument_count() == 2) call get_command_argument(2, geometry)
      if (geometry /= 'line' .and. geometry /= 'areal') then
         write (error_unit, '(a)') "layercontact: --defaults takes 'line' (the default) or 'areal', not '" // &
            & trim(geometry) // "'"
         stop 1, quiet=.true.
      end if
      call write_scene_namelist(default_scene(geometry), text)
      write (output_unit, '(a)', advance='no') text
      stop
   case ('--help', '-h')
      write (output_unit, '(a)') usage, &
         & '  Solve the sliding contact scene of a namelist file and write its HDF5 result.', &
         & '  --defaults [line|areal]: print the default scene as a namelist (every variable).', &
         & '  Exit codes: 0 converged; 1 usage; 2 bad input (nothing written); 3 not converged', &
         & '  (results written with converged = 0); 4 I/O failure; 5 not enough memory or internal failure.'
      stop
   case ('--version')
      write (output_unit, '(a)') 'layercontact ' // version_string // ' (' // build_isa // ')'
      stop
   end select

   call run_scene_file(input, output_unit, output_file, converged, error, root=root)
   if (allocated(error)) then
      ! (under MPI every rank refuses bad input alike: rank 0 says why)
      if (root) write (error_unit, '(a)') 'layercontact: error: ' // error%message
      stop error%code, quiet=.true.
   end if
   if (.not. converged) then
      if (root) write (error_unit, '(a)') 'layercontact: warning: the solver did not reach its tolerance; ' // &
         & 'results written to ' // output_file // ' with converged = 0'
      stop code_not_converged, quiet=.true.
   end if
end program layercontact
