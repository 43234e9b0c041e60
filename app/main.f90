!> layercontact: solve the sliding contact scene of a namelist file, write an HDF5 result.
!>
!>    layercontact FILE.nml | --help | --version
!>
!> Exit codes: 0 converged; 2 bad input (nothing written); 3 not converged (results
!> written, flagged converged = 0); 4 I/O failure; 5 not enough memory or internal failure; 1 usage.
program layercontact
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use lc_base_errors, only: error_type, code_not_converged
   use lc_application_run, only: run_scene_file
   use lc_base_version, only: version_string, build_isa
   implicit none (type, external)
   type(error_type), allocatable :: error
   character(len=:), allocatable :: input, output_file
   integer :: length
   logical :: converged

   if (command_argument_count() /= 1) then
      write (error_unit, '(a)') 'usage: layercontact FILE.nml'
      stop 1, quiet=.true.
   end if
   call get_command_argument(1, length=length)
   allocate (character(len=length) :: input)
   call get_command_argument(1, input)
   select case (input)
   case ('--help', '-h')
      write (output_unit, '(a)') 'usage: layercontact FILE.nml', &
         & '  Solve the sliding contact scene of a namelist file and write its HDF5 result.', &
         & '  Exit codes: 0 converged; 1 usage; 2 bad input (nothing written); 3 not converged', &
         & '  (results written with converged = 0); 4 I/O failure; 5 not enough memory or internal failure.'
      stop
   case ('--version')
      write (output_unit, '(a)') 'layercontact ' // version_string // ' (' // build_isa // ')'
      stop
   end select

   call run_scene_file(input, output_unit, output_file, converged, error)
   if (allocated(error)) then
      write (error_unit, '(a)') 'layercontact: error: ' // error%message
      stop error%code, quiet=.true.
   end if
   if (.not. converged) then
      write (error_unit, '(a)') 'layercontact: warning: the solver did not reach its tolerance; ' // &
         & 'results written to ' // output_file // ' with converged = 0'
      stop code_not_converged, quiet=.true.
   end if
end program layercontact
