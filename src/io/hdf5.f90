!> HDF5 output (self-describing result file, written atomically) and profile input.
!>
!> Layout written by `write_results` (units: lengths L, stresses S, as in the input):
!>   /                     attrs layercontact_version, layercontact_build, geometry, convention, units,
!>                         omp_threads, mpi_ranks (the threads and processes the solve ran on)
!>   /input/namelist       the namelist text; /input attrs: every scene variable that is set
!>   /profile/x, height    grid positions j*period/n and the rigid profile r(x)
!>   /fields/pressure, gap, displacement_z
!>                         (/profile and /fields only with &output fields, the default)
!>   /results              attrs: scalar observables, solver record, the seed's normalised values
!>   /convergence/residual residual per iteration
!>   /companion/...        the same fields/results/convergence for the frictionless companion
!>
!> HDF5 1.10 Fortran API only. Every public routine opens and closes the library itself
!> (h5open_f/h5close_f) and switches off HDF5's own error printing: failures come back as
!> `error_type` messages naming the file and the object instead.
module lc_io_hdf5
   use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_char, c_null_char, c_ptr, c_loc, c_size_t, c_float
   use, intrinsic :: iso_fortran_env, only: error_unit
   use hdf5, only: hid_t, hsize_t, size_t, h5kind_to_type, H5_INTEGER_KIND, h5open_f, h5close_f, h5eset_auto_f, &
      & h5fis_hdf5_f, h5fcreate_f, h5fopen_f, h5fclose_f, h5fget_filesize_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, &
      & H5F_CLOSE_STRONG_F, &
      & h5pcreate_f, h5pclose_f, h5pset_fclose_degree_f, H5P_FILE_ACCESS_F, H5P_DATASET_CREATE_F, h5pset_chunk_f, &
      & h5pset_deflate_f, h5pset_shuffle_f, &
      & h5gcreate_f, h5gclose_f, h5iget_name_f, &
      & h5screate_f, h5screate_simple_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
      & h5sget_simple_extent_dims_f, H5S_SCALAR_F, h5sselect_hyperslab_f, H5S_SELECT_SET_F, H5P_DEFAULT_F, &
      & h5tcopy_f, h5tset_size_f, h5tset_strpad_f, h5tclose_f, h5tget_class_f, &
      & H5T_FORTRAN_S1, H5T_STR_NULLTERM_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_REAL, H5T_IEEE_F32LE, H5T_NATIVE_INTEGER, H5T_FLOAT_F, &
      & h5acreate_f, h5awrite_f, h5aclose_f, &
      & h5dcreate_f, h5dopen_f, h5dwrite_f, h5dread_f, h5dclose_f, h5dget_space_f, h5dget_type_f
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, code_io, code_internal
   use lc_base_strings, only: to_string, lower_case
   use lc_scene, only: scene_type, is_areal, is_halfspace, not_set
   use lc_result, only: contact_result, result_scalar, result_scalars
   use lc_leakage_reynolds, only: leakage_result
   use lc_base_version, only: build_isa
   use lc_io_files, only: sync_path, reserve_space, free_bytes
   implicit none (type, external)
   private
   public :: check_output, write_results, run_record, utc_now
   ! for the writers of one file by several processes (lc_io_hdf5_slabs)
   public :: map_writer, h5_status, temporary_name, delete_file, write_contents, publish, map_bytes, announce_large, &
      & check_sizes

   character(len=*), parameter :: convention = 'P: x = sliding direction of the indenter, z into the layer, ' // &
      & 'p > 0 compressive, w = u_z > 0 indentation, tau = +mu_c p'
   character(len=*), parameter :: units_note = "lengths in the input's length unit L, " // &
      & 'pressures/moduli in its stress unit S'
   character(len=*), parameter :: overwrite_hint = 'set &output overwrite = .true.'
   character(len=*), parameter :: leakage_units = 'k_eff_x L^3; k_eff_y L^3 (12 eta times the mean flux per ' // &
      & 'unit width per unit mean pressure gradient: g^3 for a uniform gap g); wall_time s; ' // &
      & 'the others are dimensionless (fractions, residuals, tolerances, flags 0/1) or counts'

   !> How a run was started, for the result's provenance (root attributes @input_file,
   !> @started, @run_wall_time).
   type :: run_record
      character(len=:), allocatable :: input_file   !< the namelist file as given
      character(len=20) :: started = ''             !< UTC, ISO 8601
      real(wp) :: seconds = 0.0_wp                  !< from the start to the write (s)
   end type run_record

   !> How the maps of a result reach its file. This default writes whole maps from one
   !> process; lc_io_hdf5_slabs extends it for maps whose rows y are spread over several MPI
   !> ranks that write one file together: every rank makes the same HDF5 calls, each writes
   !> its rows of a map, one rank the data of what every rank holds whole.
   type :: map_writer
   contains
      !> the rows y_start+1 .. y_start+ny_local of a map of ny rows that this process holds
      procedure :: rows => whole_rows
      !> whether more than half of a map's values (all processes' rows) are exact zeros
      procedure :: mostly_zeros => whole_mostly_zeros
      !> the dataset transfer property list for the maps' writes
      procedure :: transfer => default_transfer
      !> whether this process writes the data of the datasets every process holds whole
      procedure :: writes_whole => always_writes
      !> a text (host, time) as all processes write it: one process's
      procedure :: agreed_text => own_text
      !> a real (run time) as all processes write it: one process's
      procedure :: agreed_real => own_real
   end type map_writer

   !> Sticky status of a sequence of HDF5 calls: after the first failure every helper does
   !> nothing, so a writer reads as a plain list of objects and is checked once at the end.
   !> It also carries how the maps are written.
   type :: h5_status
      integer :: hdferr = 0
      character(len=:), allocatable :: object   !< path of the object that failed
      integer(i8) :: free = -1                  !< bytes free on the file system then (-1: unknown)
      class(map_writer), allocatable :: maps    !< unallocated: whole maps from this process
   end type h5_status

   interface
      !> int mkdir(const char *path, mode_t mode); mode_t is a 32-bit unsigned on Linux
      integer(c_int) function c_mkdir(path, mode) bind(C, name='mkdir')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value, intent(in) :: mode
      end function c_mkdir
      !> int access(const char *path, int mode)
      integer(c_int) function c_access(path, mode) bind(C, name='access')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value, intent(in) :: mode
      end function c_access
      !> int rename(const char *old, const char *new): atomic within one file system
      integer(c_int) function c_rename(old, new) bind(C, name='rename')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: old(*), new(*)
      end function c_rename
      !> int remove(const char *path)
      !> int gethostname(char *name, size_t len)
      integer(c_int) function c_gethostname(name, length) bind(C, name='gethostname')
         import :: c_int, c_char, c_size_t
         character(kind=c_char), intent(out) :: name(*)
         integer(c_size_t), value, intent(in) :: length
      end function c_gethostname
      integer(c_int) function c_remove(path) bind(C, name='remove')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
      end function c_remove
      !> int link(const char *old, const char *new): fails (EEXIST) if `new` exists
      integer(c_int) function c_link(old, new) bind(C, name='link')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: old(*), new(*)
      end function c_link
      !> Point an open file's descriptor at memory before a close that cannot succeed
      integer(c_int) function lc_hdf5_discard_file(file) bind(C, name='lc_hdf5_discard_file')
         import :: c_int, c_int64_t
         !> hid_t, int64_t in HDF5 1.10
         integer(c_int64_t), value, intent(in) :: file
      end function lc_hdf5_discard_file
      !> pid_t getpid(void)
      integer(c_int) function c_getpid() bind(C, name='getpid')
         import :: c_int
      end function c_getpid
   end interface

   !> maps from this size on (bytes) make the write announce itself on stderr
   integer(i8), parameter :: large_file = 64_i8*2_i8**20
   !> access() modes: write and search permission on a directory
   integer(c_int), parameter :: w_ok = 2_c_int, x_ok = 1_c_int
   !> rwxrwxrwx, reduced by the process umask as `mkdir -p` does
   integer(c_int), parameter :: dir_mode = int(o'777', c_int)

contains

   !> Fail early (before any computing) if the output cannot be written:
   !> existing file and not overwrite -> error code_io with the file name and the hint
   !> "set &output overwrite = .true."; an existing file that is not an HDF5 file (a
   !> directory, a device such as /dev/null, other data) is never replaced, overwrite or
   !> not; parent directory missing -> create it (mkdir -p).
   subroutine check_output(filename, overwrite, error)
      !> the result file to be written
      character(len=*), intent(in) :: filename
      !> whether an existing file may be replaced
      logical, intent(in) :: overwrite
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: parent
      logical :: exists
      integer :: k, ignore

      if (len_trim(filename) == 0) then
         call fatal_error(error, "&output: file = '' is not allowed; allowed: a file name", code_input)
         return
      end if
      inquire (file=filename, exist=exists)
      if (exists) then
         if (.not. is_hdf5_file(filename)) then
            call fatal_error(error, "output file '" // filename // "' exists and is not an HDF5 file (a " // &
               & 'directory, a device or other data): it is not replaced; choose another name', code_io)
            return
         end if
      end if
      if (exists .and. .not. overwrite) then
         call fatal_error(error, "output file '" // filename // "' exists; choose another name or " &
            & // overwrite_hint, code_io)
         return
      end if

      parent = parent_of(filename)
      ! mkdir -p: create every prefix; failures for existing prefixes are expected, so the
      ! result is judged once, by whether the parent is now a writable directory.
      do k = 2, len(parent)
         if (parent(k:k) == '/') ignore = c_mkdir(parent(:k - 1) // c_null_char, dir_mode)
      end do
      ignore = c_mkdir(parent // c_null_char, dir_mode)
      if (c_access(parent // c_null_char, ior(w_ok, x_ok)) /= 0) then
         call fatal_error(error, "cannot create or write to the directory '" // parent // "' of output file '" &
            & // filename // "'", code_io)
      end if
   end subroutine check_output

   !> Write a complete, self-describing result file atomically: write a temporary file of
   !> this run's own (filename.HOST.PID.tmp, so that two runs never share it), with every
   !> HDF5 call checked; reserve its disk space, close, reopen it (complete?) and fsync it,
   !> then move it to filename: with &output overwrite by rename (which replaces atomically),
   !> otherwise by link + remove, which never replaces a file that another run wrote
   !> meanwhile (on a file system without hard links: rename after checking that filename
   !> is still absent). On any failure (a full disk): delete the temporary file, keep the
   !> file that was there, return error code_io naming the file, the object and the space
   !> left.
   subroutine write_results(filename, scene, namelist_text, height, result, companion, version, error, run)
      character(len=*), intent(in) :: filename
      type(scene_type), intent(in) :: scene
      !> the input namelist text, echoed to /input/namelist
      character(len=*), intent(in) :: namelist_text
      !> the rigid profile r(x) (L)
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(in) :: result
      !> frictionless companion run
      type(contact_result), intent(in), optional :: companion
      !> layercontact version string
      character(len=*), intent(in) :: version
      type(error_type), allocatable, intent(out) :: error
      !> how the run was started, for the root's provenance
      type(run_record), intent(in), optional :: run
      character(len=:), allocatable :: tmp
      type(h5_status) :: st
      integer(hid_t) :: fapl, file
      integer :: ignore, n

      n = size(height)
      call check_sizes(result, n, 'result', error)
      if (allocated(error)) return
      if (present(companion)) then
         call check_sizes(companion, n, 'companion', error)
         if (allocated(error)) return
      end if

      tmp = temporary_name(filename)
      call delete_file(tmp, error)
      if (allocated(error)) return
      call announce_large(filename, map_bytes(scene, result, present(companion)))

      call h5open_f(st%hdferr)
      call h5eset_auto_f(0, ignore)
      ! strong close degree: closing the file also closes whatever a failed sequence left open
      call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, ignore)
      call h5pset_fclose_degree_f(fapl, H5F_CLOSE_STRONG_F, ignore)
      if (st%hdferr == 0) then
         call h5fcreate_f(tmp, H5F_ACC_TRUNC_F, file, st%hdferr, access_prp=fapl)
         if (st%hdferr /= 0) st%object = 'the file itself'
      end if
      if (st%hdferr == 0) then
         call write_contents(file, scene, namelist_text, height, result, version, st, companion, run)
         call close_file(file, tmp, st)
      end if
      call h5pclose_f(fapl, ignore)
      call h5close_f(ignore)
      call publish(tmp, filename, scene%overwrite, st, error)
   end subroutine write_results

   !> This run's own temporary file for `filename`: filename.HOST.PID.tmp, so that two runs
   !> never share it.
   function temporary_name(filename) result(tmp)
      character(len=*), intent(in) :: filename
      character(len=:), allocatable :: tmp
      tmp = filename // '.' // host_name() // '.' // to_string(int(c_getpid())) // '.tmp'
   end function temporary_name

   !> A large file takes seconds to reach the disk: say so meanwhile, as the solver's
   !> progress does.
   subroutine announce_large(filename, maps)
      character(len=*), intent(in) :: filename
      !> the bytes of the maps (map_bytes)
      integer(i8), intent(in) :: maps
      if (maps < large_file) return
      write (error_unit, '(a)') "layercontact: writing result file '" // filename // "' (" // &
         & to_string(maps/10_i8**6) // ' MB of maps)'
      flush (error_unit)
   end subroutine announce_large

   !> Everything a result file holds, written into the open `file`: the root's attributes,
   !> /input, /profile, the solution and the companion's. `height` and the result's maps are
   !> the rows st%maps says this process holds.
   subroutine write_contents(file, scene, namelist_text, height, result, version, st, companion, run)
      integer(hid_t), intent(in) :: file
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: namelist_text
      real(wp), intent(in) :: height(:)
      type(contact_result), intent(in) :: result
      character(len=*), intent(in) :: version
      type(h5_status), intent(inout) :: st
      type(contact_result), intent(in), optional :: companion
      type(run_record), intent(in), optional :: run
      integer(hid_t) :: group
      integer :: j

      if (.not. allocated(st%maps)) allocate (map_writer :: st%maps)
      call write_attr_string(file, 'layercontact_version', version, st)
      call write_attr_string(file, 'layercontact_build', build_isa, st)
      call write_attr_string(file, 'geometry', trim(scene%geometry), st)
      call write_attr_string(file, 'convention', convention, st)
      call write_attr_string(file, 'units', units_note, st)
      call write_attr_int(file, 'omp_threads', result%omp_threads, st)
      call write_attr_int(file, 'mpi_ranks', result%mpi_ranks, st)
      call write_provenance(file, st)
      if (present(run)) then
         call write_attr_string(file, 'input_file', run%input_file, st)
         call write_attr_string(file, 'started', run%started, st)
         call write_attr_real(file, 'run_wall_time', st%maps%agreed_real(run%seconds), st)
      end if

      call create_group(file, 'input', group, st)
      call write_dataset_string(group, 'namelist', namelist_text, st)
      call write_scene_attrs(group, scene, st)
      call close_group(group, st)

      if (scene%fields) then
         call create_group(file, 'profile', group, st)
         call write_dataset_1d(group, 'x', [(j*scene%period/scene%n, j=0, scene%n - 1)], 'L', st)
         if (is_areal(scene)) then
            associate (ly => merge(scene%period_y, scene%period, scene%period_y > 0.0_wp))
               call write_dataset_1d(group, 'y', [(j*ly/scene%ny, j=0, scene%ny - 1)], 'L', st)
            end associate
         end if
         call write_field(group, 'height', height, 'L', scene, st)
         call close_group(group, st)
      end if

      if (present(companion)) then
         call write_solution(file, result, scene, st, &
            & a_over_a0=result%contact_fraction / companion%contact_fraction)
         call create_group(file, 'companion', group, st)
         call write_solution(group, companion, scene, st)
         call close_group(group, st)
      else
         call write_solution(file, result, scene, st)
      end if
   end subroutine write_contents

   !> After the temporary file `tmp` is closed: on a failure recorded in `st` delete it and
   !> return error code_io naming the file, the object and the space left; else check it
   !> (check_on_disk) and move it to `filename` (move_into_place).
   subroutine publish(tmp, filename, overwrite, st, error)
      character(len=*), intent(in) :: tmp, filename
      !> &output overwrite
      logical, intent(in) :: overwrite
      type(h5_status), intent(inout) :: st
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: reason
      integer :: ignore
      logical :: synced
      if (st%hdferr /= 0) then
         ignore = c_remove(tmp // c_null_char)
         if (.not. allocated(st%object)) st%object = 'the HDF5 library'
         if (st%free < 0) st%free = free_bytes(parent_of(filename))
         call fatal_error(error, "cannot write result file '" // filename // "': the write failed at " // &
            & st%object // space_note(filename, st%free), code_io)
         return
      end if
      call check_on_disk(tmp, filename, error)
      if (allocated(error)) return
      call move_into_place(tmp, filename, overwrite, error)
      if (allocated(error)) return
      ! the new name on the disk too (a file system that cannot sync a directory has done it)
      call sync_path(parent_of(filename), .true., synced, reason)
   end subroutine publish

   !> Close a written file so that none of HDF5's writes can fail: HDF5 1.10 writes the
   !> metadata it caches when the file closes, and a failed write of it leaves the library
   !> holding a file it can neither close nor forget (the process then crashes at exit). So
   !> the disk blocks up to the file's end are reserved first. When they cannot be (a full
   !> disk), or an earlier write failed, the file is lost anyway and the writes of its close
   !> go to memory (hdf5_discard.c).
   subroutine close_file(file, tmp, st)
      integer(hid_t), intent(in) :: file
      !> the file's name
      character(len=*), intent(in) :: tmp
      type(h5_status), intent(inout) :: st
      integer(hsize_t) :: size
      character(len=:), allocatable :: reason
      integer :: hdferr, ignore
      logical :: ok
      if (st%hdferr == 0) then
         call h5fget_filesize_f(file, size, st%hdferr)
         if (st%hdferr /= 0) st%object = 'the size of the file'
      end if
      if (st%hdferr == 0) then
         call reserve_space(tmp, int(size, i8), ok, reason)
         if (.not. ok) then
            st%hdferr = -1
            st%object = 'reserving the disk space of its ' // to_string(int(size, i8)) // ' bytes (' // reason // ')'
         end if
      end if
      if (st%hdferr /= 0) then
         st%free = free_bytes(tmp)
         ignore = lc_hdf5_discard_file(int(file, c_int64_t))
      end if
      call h5fclose_f(file, hdferr)
      if (st%hdferr == 0 .and. hdferr /= 0) then
         st%hdferr = hdferr
         st%object = 'the closing of the file'
      end if
   end subroutine close_file

   !> The closed temporary file `tmp` is complete (HDF5 opens it: it refuses a file shorter
   !> than the end it records) and on the disk (fsync: a file system may accept writes that
   !> it cannot keep, and say so only here); else it is deleted and the error names
   !> `filename` and the reason.
   subroutine check_on_disk(tmp, filename, error)
      character(len=*), intent(in) :: tmp, filename
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: reason
      integer(hid_t) :: file
      integer(i8) :: free
      integer :: hdferr, ignore
      logical :: ok
      call h5open_f(hdferr)
      call h5eset_auto_f(0, ignore)
      if (hdferr == 0) call h5fopen_f(tmp, H5F_ACC_RDONLY_F, file, hdferr)
      if (hdferr == 0) call h5fclose_f(file, hdferr)
      call h5close_f(ignore)
      ok = hdferr == 0
      reason = 'its temporary file does not open as a complete HDF5 file'
      if (ok) then
         call sync_path(tmp, .false., ok, reason)
         if (.not. ok) reason = 'its data did not reach the disk (' // reason // ')'
      end if
      if (.not. ok) then
         free = free_bytes(tmp)
         ignore = c_remove(tmp // c_null_char)
         call fatal_error(error, "cannot write result file '" // filename // "': " // reason // &
            & space_note(filename, free), code_io)
      end if
   end subroutine check_on_disk

   !> The end of a write failure's message: the space that was free when it failed (a full
   !> file system is named so) and whether an older result file is kept.
   function space_note(filename, free) result(note)
      character(len=*), intent(in) :: filename
      !> bytes free on the file system when the write failed (-1: unknown)
      integer(i8), intent(in) :: free
      character(len=:), allocatable :: note
      !> below this, a file system is called full (a few HDF5 chunks)
      integer(i8), parameter :: nearly_full = 2_i8**20
      logical :: exists
      note = ''
      if (free >= 0 .and. free < nearly_full) then
         note = '; its file system is full (' // to_string(free) // ' bytes free)'
      else if (free >= 0) then
         note = '; ' // to_string(free) // ' bytes were free on its file system'
      end if
      inquire (file=filename, exist=exists)
      if (exists) note = note // '; the file that was there is kept'
   end function space_note

   !> The directory of `filename` ('.' for a bare name).
   pure function parent_of(filename) result(parent)
      character(len=*), intent(in) :: filename
      character(len=:), allocatable :: parent
      integer :: k
      k = index(filename, '/', back=.true.)
      if (k == 0) then
         parent = '.'
      else if (k == 1) then
         parent = '/'
      else
         parent = filename(:k - 1)
      end if
   end function parent_of

   !> Move the complete temporary file `tmp` to `filename` (see write_results); on failure
   !> `tmp` is deleted and the error names both.
   subroutine move_into_place(tmp, filename, overwrite, error)
      character(len=*), intent(in) :: tmp, filename
      logical, intent(in) :: overwrite
      type(error_type), allocatable, intent(out) :: error
      logical :: exists
      integer :: ignore
      if (.not. overwrite) then
         if (c_link(tmp // c_null_char, filename // c_null_char) == 0) then
            ignore = c_remove(tmp // c_null_char)
            return
         end if
         inquire (file=filename, exist=exists)
         if (exists) then
            ignore = c_remove(tmp // c_null_char)
            call fatal_error(error, "output file '" // filename // "' was written by another run while this one " // &
               & 'computed; it is kept and this result is not written; choose another name or ' // overwrite_hint, &
               & code_io)
            return
         end if
      end if
      if (c_rename(tmp // c_null_char, filename // c_null_char) /= 0) then
         ignore = c_remove(tmp // c_null_char)
         call fatal_error(error, "cannot rename '" // tmp // "' to result file '" // filename // "'", code_io)
      end if
   end subroutine move_into_place

   !> Whether `filename` is an HDF5 file (false for a directory, a device, other data).
   logical function is_hdf5_file(filename) result(yes)
      character(len=*), intent(in) :: filename
      integer :: hdferr, ignore
      call h5open_f(hdferr)
      call h5eset_auto_f(0, ignore)
      yes = .false.
      if (hdferr == 0) call h5fis_hdf5_f(filename, yes, hdferr)
      if (hdferr /= 0) yes = .false.
      call h5close_f(ignore)
   end function is_hdf5_file

   ! ---------------------------------------------------------------------------------------
   ! Pieces of the layout.

   !> Every scene variable that is set as an attribute of /input (a list as a dataset),
   !> named and ordered as the scene schema (driver/layercontact/scene_schema.py) gives
   !> them; a variable that is not set is absent. @units gives their units, and
   !> @normalised_pressure_scale the seed's pressure scale that normalised values use.
   subroutine write_scene_attrs(loc, scene, st)
      integer(hid_t), intent(in) :: loc
      type(scene_type), intent(in) :: scene
      type(h5_status), intent(inout) :: st

      include 'scene_input_writer.inc'
      if (is_areal(scene) .and. .not. is_halfspace(scene)) then
         call write_attr_string(loc, 'normalised_pressure_scale', 'E* thickness/period (an areal scene on a layer)', st)
      else
         call write_attr_string(loc, 'normalised_pressure_scale', 'E* Lambda0/period (Lambda0 = max r - mean r)', st)
      end if
   end subroutine write_scene_attrs

   !> fields/, results (attributes) and convergence/ of one solve, under `loc`.
   subroutine write_solution(loc, res, scene, st, a_over_a0)
      integer(hid_t), intent(in) :: loc
      type(contact_result), intent(in) :: res
      type(scene_type), intent(in) :: scene
      type(h5_status), intent(inout) :: st
      !> contact area relative to the frictionless companion's
      real(wp), intent(in), optional :: a_over_a0
      integer(hid_t) :: group
      type(result_scalar), allocatable :: table(:)
      integer :: i

      if (scene%fields) then
         call create_group(loc, 'fields', group, st)
         call write_field(group, 'pressure', res%pressure, 'S', scene, st)
         call write_field(group, 'gap', res%gap, 'L', scene, st)
         call write_field(group, 'displacement_z', res%displacement_z, 'L', scene, st)
         if (allocated(res%stress_xx)) then
            call write_field(group, 'displacement_x', res%displacement_x, 'L', scene, st)
            call write_field(group, 'shear', res%shear, 'S', scene, st)
            call write_field(group, 'stress_xx', res%stress_xx, 'S', scene, st)
         end if
         if (allocated(res%stress_yy)) then
            call write_field(group, 'displacement_y', res%displacement_y, 'L', scene, st)
            call write_field(group, 'stress_yy', res%stress_yy, 'S', scene, st)
            call write_field(group, 'stress_xy', res%stress_xy, 'S', scene, st)
         end if
         call close_group(group, st)
      end if

      if (allocated(res%patch_area)) then
         call create_group(loc, 'patches', group, st)
         call write_dataset_1d(group, 'area', res%patch_area, 'L^2', st)
         call write_dataset_1d(group, 'perimeter', res%patch_perimeter, 'L', st)
         call close_group(group, st)
      end if

      if (allocated(res%spot_trailing)) then
         call create_group(loc, 'spots', group, st)
         call write_dataset_1d(group, 'trailing_edge', res%spot_trailing, 'L', st)
         call write_dataset_1d(group, 'leading_edge', res%spot_leading, 'L', st)
         if (allocated(res%spot_max_tension)) then
            call write_dataset_1d(group, 'max_tension', res%spot_max_tension, 'S', st)
            call write_dataset_1d(group, 'max_tension_grid', res%spot_max_tension_grid, 'S', st)
            call write_dataset_1d(group, 'max_tension_offset', res%spot_tension_offset, 'L', st)
         end if
         call close_group(group, st)
      end if
      if (allocated(res%gap_counts)) then
         call create_group(loc, 'gap_histogram', group, st)
         call write_dataset_1d(group, 'edges', res%gap_edges, 'L', st)
         call write_dataset_1d(group, 'counts', real(res%gap_counts, wp), '1', st)
         call close_group(group, st)
      end if

      call create_group(loc, 'results', group, st)
      if (present(a_over_a0)) then
         table = result_scalars(res, is_areal(scene), a_over_a0)
      else
         table = result_scalars(res, is_areal(scene))
      end if
      call write_attr_string(group, 'units', results_units(table), st)
      do i = 1, size(table)
         if (table(i)%is_text) then
            call write_attr_string(group, trim(table(i)%name), trim(table(i)%text), st)
         else if (table(i)%is_integer) then
            call write_attr_int(group, trim(table(i)%name), nint(table(i)%value), st)
         else
            call write_attr_real(group, trim(table(i)%name), table(i)%value, st)
         end if
      end do
      call close_group(group, st)

      if (allocated(res%leakage)) call write_leakage(loc, res%leakage, st)

      call create_group(loc, 'convergence', group, st)
      if (allocated(res%residual_history)) then
         call write_dataset_1d(group, 'residual', res%residual_history, '1', st)
      else
         call write_dataset_1d(group, 'residual', [real(wp) ::], '1', st)
      end if
      call close_group(group, st)
   end subroutine write_solution

   !> The Reynolds leakage (computed in the run, lc_leakage_reynolds) as attributes of /leakage.
   subroutine write_leakage(loc, leakage, st)
      integer(hid_t), intent(in) :: loc
      type(leakage_result), intent(in) :: leakage
      type(h5_status), intent(inout) :: st
      integer(hid_t) :: group
      call create_group(loc, 'leakage', group, st)
      call write_attr_string(group, 'units', leakage_units, st)
      call write_attr_real(group, 'k_eff_x', leakage%x%k_eff, st)
      call write_attr_real(group, 'k_eff_y', leakage%y%k_eff, st)
      call write_attr_int(group, 'percolating_x', merge(1, 0, leakage%x%percolating), st)
      call write_attr_int(group, 'percolating_y', merge(1, 0, leakage%y%percolating), st)
      call write_attr_real(group, 'fluid_fraction', leakage%fluid_fraction, st)
      call write_attr_real(group, 'connected_fraction_x', leakage%x%connected_fraction, st)
      call write_attr_real(group, 'connected_fraction_y', leakage%y%connected_fraction, st)
      call write_attr_int(group, 'unknowns_x', leakage%x%unknowns, st)
      call write_attr_int(group, 'unknowns_y', leakage%y%unknowns, st)
      call write_attr_int(group, 'iterations_x', leakage%x%iterations, st)
      call write_attr_int(group, 'iterations_y', leakage%y%iterations, st)
      call write_attr_real(group, 'residual_x', leakage%x%residual, st)
      call write_attr_real(group, 'residual_y', leakage%y%residual, st)
      call write_attr_int(group, 'converged', merge(1, 0, leakage%x%converged .and. leakage%y%converged), st)
      call write_attr_real(group, 'tol', leakage%tol, st)
      call write_attr_string(group, 'solver', trim(leakage%solver), st)
      call write_attr_real(group, 'wall_time', leakage%wall_time, st)
      call close_group(group, st)
   end subroutine write_leakage

   !> A unit of the scene schema for this scene: 'S or 1/S' (Prony values) as the Prony
   !> form gives it.
   pure function resolved_unit(unit, scene) result(resolved)
      character(len=*), intent(in) :: unit
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: resolved
      resolved = unit
      if (unit == 'S or 1/S') resolved = trim(merge('S  ', '1/S', trim(scene%material%form) == 'relaxation'))
   end function resolved_unit

   !> The /results@units text: the unit of every dimensional attribute (L and S: the input's
   !> length and stress units), then a word on the others.
   pure function results_units(table) result(units)
      type(result_scalar), intent(in) :: table(:)
      character(len=:), allocatable :: units
      integer :: i
      units = ''
      do i = 1, size(table)
         if (trim(table(i)%unit) /= '1') units = units // trim(table(i)%name) // ' ' // trim(table(i)%unit) // '; '
      end do
      units = units // 'the others are dimensionless (fractions, friction coefficients, residuals, ' // &
         & 'normalised values) or counts'
   end function results_units

   !> Fields must match the profile's grid (a mismatch is a bug in the caller).
   subroutine check_sizes(res, n, label, error)
      type(contact_result), intent(in) :: res
      integer, intent(in) :: n
      character(len=*), intent(in) :: label
      type(error_type), allocatable, intent(out) :: error
      logical :: ok
      ok = allocated(res%pressure) .and. allocated(res%gap) .and. allocated(res%displacement_z)
      if (ok) ok = size(res%pressure) == n .and. size(res%gap) == n .and. size(res%displacement_z) == n
      if (.not. ok) call fatal_error(error, 'write_results: the ' // label // &
         & ' fields (pressure, gap, displacement_z) must be allocated with the size of the profile, n = ' &
         & // to_string(int(n, hsize_t)), code_internal)
   end subroutine check_sizes

   ! ---------------------------------------------------------------------------------------
   ! HDF5 helpers: each does nothing once `st` has failed, and records the failing object.

   subroutine create_group(loc, name, group, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      integer(hid_t), intent(out) :: group
      type(h5_status), intent(inout) :: st
      group = -1
      if (st%hdferr /= 0) return
      call h5gcreate_f(loc, name, group, st%hdferr)
      if (st%hdferr /= 0) call failed(loc, name, st)
   end subroutine create_group

   subroutine close_group(group, st)
      integer(hid_t), intent(in) :: group
      type(h5_status), intent(inout) :: st
      if (st%hdferr /= 0) return
      call h5gclose_f(group, st%hdferr)
      if (st%hdferr /= 0) call failed(group, '', st)
   end subroutine close_group

   subroutine write_attr_real(loc, name, value, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      real(wp), intent(in), target :: value
      type(h5_status), intent(inout) :: st
      call write_attr(loc, name, H5T_NATIVE_DOUBLE, c_loc(value), st)
   end subroutine write_attr_real

   subroutine write_attr_int(loc, name, value, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      integer, intent(in), target :: value
      type(h5_status), intent(inout) :: st
      call write_attr(loc, name, H5T_NATIVE_INTEGER, c_loc(value), st)
   end subroutine write_attr_int

   !> 64-bit integer attribute (a seed need not fit the 53 bits of a double).
   subroutine write_attr_int64(loc, name, value, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      integer(i8), intent(in), target :: value
      type(h5_status), intent(inout) :: st
      call write_attr(loc, name, h5kind_to_type(i8, H5_INTEGER_KIND), c_loc(value), st)
   end subroutine write_attr_int64

   !> Close a written dataset, checked: HDF5 writes the chunks it cached now.
   subroutine close_dataset(dset, st)
      integer(hid_t), intent(in) :: dset
      type(h5_status), intent(inout) :: st
      integer :: hdferr
      call h5dclose_f(dset, hdferr)
      if (st%hdferr == 0) st%hdferr = hdferr
   end subroutine close_dataset

   !> Null-terminated fixed-length string attribute (h5py reads it as bytes).
   subroutine write_attr_string(loc, name, value, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name, value
      type(h5_status), intent(inout) :: st
      character(len=len(value) + 1), target :: buffer
      integer(hid_t) :: stype
      integer :: ignore
      if (st%hdferr /= 0) return
      call string_type(len(value), stype, st%hdferr)
      if (st%hdferr /= 0) then
         call failed(loc, '@' // name, st)
         return
      end if
      buffer = value // c_null_char
      call write_attr(loc, name, stype, c_loc(buffer), st)
      call h5tclose_f(stype, ignore)
   end subroutine write_attr_string

   !> Scalar attribute `name` of type `dtype` (file and memory) holding the value at `buffer`.
   subroutine write_attr(loc, name, dtype, buffer, st)
      integer(hid_t), intent(in) :: loc, dtype
      character(len=*), intent(in) :: name
      type(c_ptr), intent(in) :: buffer
      type(h5_status), intent(inout) :: st
      integer(hid_t) :: space, attr
      integer :: ignore
      if (st%hdferr /= 0) return
      call h5screate_f(H5S_SCALAR_F, space, st%hdferr)
      if (st%hdferr == 0) then
         call h5acreate_f(loc, name, dtype, space, attr, st%hdferr)
         if (st%hdferr == 0) then
            call h5awrite_f(attr, dtype, buffer, st%hdferr)
            call h5aclose_f(attr, ignore)
         end if
         call h5sclose_f(space, ignore)
      end if
      if (st%hdferr /= 0) call failed(loc, '@' // name, st)
   end subroutine write_attr

   !> Scalar string dataset.
   subroutine write_dataset_string(loc, name, value, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name, value
      type(h5_status), intent(inout) :: st
      integer(hid_t) :: space, dset, stype
      integer :: ignore
      if (st%hdferr /= 0) return
      call string_type(len(value), stype, st%hdferr)
      if (st%hdferr == 0) then
         call h5screate_f(H5S_SCALAR_F, space, st%hdferr)
         if (st%hdferr == 0) then
            call h5dcreate_f(loc, name, stype, space, dset, st%hdferr)
            if (st%hdferr == 0) then
               if (st%maps%writes_whole()) call h5dwrite_f(dset, stype, value // c_null_char, [1_hsize_t], st%hdferr)
               call close_dataset(dset, st)
            end if
            call h5sclose_f(space, ignore)
         end if
         call h5tclose_f(stype, ignore)
      end if
      if (st%hdferr /= 0) call failed(loc, name, st)
   end subroutine write_dataset_string

   !> 1D float64 dataset with a `units` attribute (L, S or 1).
   subroutine write_dataset_1d(loc, name, values, units, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: values(:)
      character(len=*), intent(in) :: units
      type(h5_status), intent(inout) :: st
      integer(hid_t) :: space, dset
      integer(hsize_t) :: dims(1)
      integer :: ignore
      if (st%hdferr /= 0) return
      dims = size(values, kind=hsize_t)
      call h5screate_simple_f(1, dims, space, st%hdferr)
      if (st%hdferr == 0) then
         call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, space, dset, st%hdferr)
         if (st%hdferr == 0) then
            ! nothing to transfer for an empty history (and no element to point the C call at)
            if (size(values) > 0 .and. st%maps%writes_whole()) &
               & call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, dims, st%hdferr)
            if (st%hdferr == 0) call write_attr_string(dset, 'units', units, st)
            call close_dataset(dset, st)
         end if
         call h5sclose_f(space, ignore)
      end if
      if (st%hdferr /= 0 .and. .not. allocated(st%object)) call failed(loc, name, st)
   end subroutine write_dataset_1d

   !> A map on the scene's grid: a 1D dataset of a line, or a 2D dataset of a surface (shape
   !> [ny, nx] as C and h5py see it, x fastest), float64 or float32 (&output precision; HDF5
   !> converts while it writes). Stored contiguous and unfiltered: deflate runs slower than
   !> the disk writes and saves little on dense maps. A map whose values are mostly exact
   !> zeros (the pressure and the shear outside the contact) is stored in chunks of whole rows
   !> with shuffle + deflate level 1, which there costs little and saves ~90 %
   !> (docs/decisions/020-result-writing.md). `values` are the rows st%maps says this
   !> process holds (all of them when one process writes).
   subroutine write_field(loc, name, values, units, scene, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: values(:)
      character(len=*), intent(in) :: units
      type(scene_type), intent(in) :: scene
      type(h5_status), intent(inout) :: st
      integer(hid_t) :: space, memory, dset, dcpl, file_type
      integer(hsize_t) :: dims(2), chunk(2), held(2)
      integer :: rank, ignore, y_start, ny_local
      if (st%hdferr /= 0) return
      rank = merge(2, 1, is_areal(scene))
      dims = [int(scene%n, hsize_t), int(max(scene%ny, 1), hsize_t)]
      call st%maps%rows(int(dims(2)), y_start, ny_local)
      held = [dims(1), int(ny_local, hsize_t)]
      file_type = H5T_NATIVE_DOUBLE
      if (trim(scene%precision) == 'single') file_type = H5T_IEEE_F32LE
      call h5screate_simple_f(rank, dims(:rank), space, st%hdferr)
      memory = space
      ! this process's rows: a block of whole rows of the file's dataspace
      if (st%hdferr == 0 .and. any(held /= dims)) then
         call h5sselect_hyperslab_f(space, H5S_SELECT_SET_F, [0_hsize_t, int(y_start, hsize_t)], held, st%hdferr)
         if (st%hdferr == 0) call h5screate_simple_f(rank, held(:rank), memory, st%hdferr)
      end if
      if (st%hdferr == 0) then
         call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, st%hdferr)
         if (st%hdferr == 0 .and. st%maps%mostly_zeros(values)) then
            ! chunks of about 2**16 values (512 KiB in double): whole rows of a surface
            chunk = [min(dims(1), 65536_hsize_t), max(1_hsize_t, min(dims(2), 65536_hsize_t/dims(1)))]
            call h5pset_chunk_f(dcpl, rank, chunk(:rank), st%hdferr)
            if (st%hdferr == 0) call h5pset_shuffle_f(dcpl, st%hdferr)
            if (st%hdferr == 0) call h5pset_deflate_f(dcpl, 1, st%hdferr)
         end if
         if (st%hdferr == 0) then
            call h5dcreate_f(loc, name, file_type, space, dset, st%hdferr, dcpl_id=dcpl)
            if (st%hdferr == 0) then
               if (size(values) > 0 .and. file_type == H5T_IEEE_F32LE) then
                  ! rounded here (to nearest, as HDF5's conversion does): parallel HDF5 1.10
                  ! writes a deflated dataset collectively only without a type conversion
                  call h5dwrite_f(dset, H5T_NATIVE_REAL, real(values, c_float), held(:rank), st%hdferr, &
                     & mem_space_id=memory, file_space_id=space, xfer_prp=st%maps%transfer())
               else if (size(values) > 0) then
                  call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, held(:rank), st%hdferr, &
                     & mem_space_id=memory, file_space_id=space, xfer_prp=st%maps%transfer())
               end if
               if (st%hdferr == 0) call write_attr_string(dset, 'units', units, st)
               call close_dataset(dset, st)
            end if
         end if
         call h5pclose_f(dcpl, ignore)
      end if
      if (memory /= space) call h5sclose_f(memory, ignore)
      call h5sclose_f(space, ignore)
      if (st%hdferr /= 0 .and. .not. allocated(st%object)) call failed(loc, name, st)
   end subroutine write_field

   ! The default map_writer: one process, whole maps.

   !> All ny rows.
   pure subroutine whole_rows(self, ny, y_start, ny_local)
      class(map_writer), intent(in) :: self
      integer, intent(in) :: ny
      integer, intent(out) :: y_start, ny_local
      y_start = 0
      ny_local = ny
   end subroutine whole_rows

   logical function whole_mostly_zeros(self, values)
      class(map_writer), intent(in) :: self
      real(wp), intent(in) :: values(:)
      whole_mostly_zeros = mostly_zeros(values)
   end function whole_mostly_zeros

   integer(hid_t) function default_transfer(self)
      class(map_writer), intent(in) :: self
      default_transfer = H5P_DEFAULT_F
   end function default_transfer

   logical function always_writes(self)
      class(map_writer), intent(in) :: self
      always_writes = .true.
   end function always_writes

   function own_text(self, text) result(agreed)
      class(map_writer), intent(in) :: self
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: agreed
      agreed = text
   end function own_text

   real(wp) function own_real(self, value)
      class(map_writer), intent(in) :: self
      real(wp), intent(in) :: value
      own_real = value
   end function own_real

   !> Whether more than half of the values are exact zeros (a map deflate shrinks cheaply).
   pure logical function mostly_zeros(values)
      real(wp), intent(in) :: values(:)
      mostly_zeros = 2*count(values == 0.0_wp, kind=i8) > size(values, kind=i8)
   end function mostly_zeros

   !> The bytes of the maps a result holds (for the progress line of a large file).
   pure function map_bytes(scene, res, companion_present) result(bytes)
      type(scene_type), intent(in) :: scene
      type(contact_result), intent(in) :: res
      logical, intent(in) :: companion_present
      integer(i8) :: bytes
      integer :: maps
      maps = 3
      if (allocated(res%stress_xx)) maps = maps + 3
      if (allocated(res%stress_yy)) maps = maps + 3
      if (companion_present) maps = 2*maps
      bytes = 0
      if (scene%fields) bytes = int(maps + 1, i8)*scene%n*max(scene%ny, 1)*merge(4, 8, trim(scene%precision) == 'single')
   end function map_bytes

   !> Where and when the result was made: @host, @created (UTC, ISO 8601), and under Slurm
   !> @slurm_job_id, @slurm_array_job_id, @slurm_array_task_id, @slurm_cluster_name,
   !> @slurm_restart_count (as the scheduler set them; job ids are unique per cluster, the
   !> restart count tells a requeued task).
   subroutine write_provenance(loc, st)
      integer(hid_t), intent(in) :: loc
      type(h5_status), intent(inout) :: st
      character(len=64) :: value
      character(len=*), parameter :: slurm(5) = [character(len=19) :: 'SLURM_JOB_ID', 'SLURM_ARRAY_JOB_ID', &
         & 'SLURM_ARRAY_TASK_ID', 'SLURM_CLUSTER_NAME', 'SLURM_RESTART_COUNT']
      integer :: i, length, status

      call write_attr_string(loc, 'host', st%maps%agreed_text(host_name()), st)
      call write_attr_string(loc, 'created', st%maps%agreed_text(utc_now()), st)
      do i = 1, size(slurm)
         call get_environment_variable(trim(slurm(i)), value, length, status)
         if (status == 0 .and. length > 0) call write_attr_string(loc, lower_case(trim(slurm(i))), trim(value), st)
      end do
   end subroutine write_provenance

   !> This machine's host name ('unknown' if the system does not say).
   function host_name() result(name)
      character(len=:), allocatable :: name
      character(kind=c_char, len=256) :: host
      integer :: length
      host = ''
      if (c_gethostname(host, len(host, c_size_t)) /= 0) host = 'unknown'
      length = index(host, c_null_char) - 1
      if (length < 0) length = len_trim(host)
      name = host(:max(length, 0))
      if (len(name) == 0) name = 'unknown'
   end function host_name

   !> The current time, 'YYYY-MM-DDThh:mm:ssZ' (UTC).
   function utc_now() result(stamp)
      character(len=20) :: stamp
      character(len=8) :: date
      character(len=10) :: time
      character(len=5) :: zone
      integer :: values(8)
      call date_and_time(date, time, zone, values)
      stamp = utc_stamp(values(1), values(2), values(3), values(5)*60 + values(6) - values(4), values(7))
   end function utc_now

   !> 'YYYY-MM-DDThh:mm:ssZ' for a local date and the minutes since its midnight in UTC
   !> (which may fall on the day before or after).
   pure function utc_stamp(year, month, day, minutes, seconds) result(stamp)
      integer, intent(in) :: year, month, day, minutes, seconds
      character(len=20) :: stamp
      integer :: y, m, d, t, shift
      integer, parameter :: month_days(12) = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]
      y = year
      m = month
      d = day
      t = minutes
      shift = 0
      if (t < 0) shift = -1
      if (t >= 24*60) shift = 1
      t = t - shift*24*60
      d = d + shift
      if (d < 1) then
         m = m - 1
         if (m < 1) then
            m = 12
            y = y - 1
         end if
         d = days_in(y, m)
      else if (d > days_in(y, m)) then
         d = 1
         m = m + 1
         if (m > 12) then
            m = 1
            y = y + 1
         end if
      end if
      write (stamp, '(i4.4, "-", i2.2, "-", i2.2, "T", i2.2, ":", i2.2, ":", i2.2, "Z")') y, m, d, t/60, mod(t, 60), &
         & seconds
   contains
      pure integer function days_in(yy, mm)
         integer, intent(in) :: yy, mm
         days_in = month_days(mm)
         if (mm == 2 .and. (mod(yy, 4) == 0 .and. (mod(yy, 100) /= 0 .or. mod(yy, 400) == 0))) days_in = 29
      end function days_in
   end function utc_stamp


   !> A fixed-length, null-terminated string type for `length` characters.
   subroutine string_type(length, stype, hdferr)
      integer, intent(in) :: length
      integer(hid_t), intent(out) :: stype
      integer, intent(out) :: hdferr
      call h5tcopy_f(H5T_FORTRAN_S1, stype, hdferr)
      if (hdferr == 0) call h5tset_size_f(stype, int(length + 1, size_t), hdferr)
      if (hdferr == 0) call h5tset_strpad_f(stype, H5T_STR_NULLTERM_F, hdferr)
   end subroutine string_type

   !> Record the path of the object that failed: the location's path plus `name`.
   subroutine failed(loc, name, st)
      integer(hid_t), intent(in) :: loc
      character(len=*), intent(in) :: name
      type(h5_status), intent(inout) :: st
      character(len=256) :: path
      integer(size_t) :: path_len
      integer :: ignore
      if (allocated(st%object)) return
      path = ''
      call h5iget_name_f(loc, path, len(path, kind=size_t), path_len, ignore)
      if (name(1:min(1, len(name))) == '@') then
         st%object = "attribute '" // name(2:) // "' of '" // trim(path) // "'"
      else if (trim(path) == '/') then
         st%object = "'/" // name // "'"
      else
         st%object = "'" // trim(path) // merge('/', ' ', len(name) > 0) // name // "'"
      end if
   end subroutine failed

   !> Delete a stale file if there is one.
   subroutine delete_file(filename, error)
      character(len=*), intent(in) :: filename
      type(error_type), allocatable, intent(out) :: error
      logical :: exists
      inquire (file=filename, exist=exists)
      if (.not. exists) return
      if (c_remove(filename // c_null_char) /= 0) &
         & call fatal_error(error, "cannot delete the stale temporary file '" // filename // "'", code_io)
   end subroutine delete_file

end module lc_io_hdf5
