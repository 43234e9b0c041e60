!> The result file and the height files by slabs of rows on several MPI ranks, run by
!> tests/test_slab_io.py under `mpirun -n P`:
!>
!>   test_slab_io DIR write [single]
!>                            every rank writes its rows of closed-form maps into
!>                            DIR/slabs.h5 (lc_io_hdf5_slabs); rank 0 writes the same
!>                            result whole into DIR/serial.h5 (lc_io_hdf5), for the test to
!>                            compare; then every rank reads its rows of DIR/heights.h5,
!>                            .npy and .txt (lc_profiles_height_slabs) and checks them
!>                            against the closed form the test wrote them with;
!>   test_slab_io DIR fail R  rank R passes one height too few (a slab that is not its
!>                            rows): every rank must return the same error, no file;
!>   test_slab_io DIR keep    as write, without &output overwrite, into DIR/slabs.h5 which
!>                            the test wrote before: every rank returns rank 0's error (the
!>                            move into place refuses), the file there is kept;
!>   test_slab_io DIR few F   DIR/F (few.txt, few.h5) holds 2 rows: on 3 or more ranks
!>                            every rank must refuse it with the same error (code 2).
!>
!> Every rank prints 'rank R rows Y0 NY' for its slab and 'error CODE MESSAGE' for an
!> error; the exit status is 1 when a check fails, else the error's code (0: none).
program test_slab_io
   use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_Comm_size, MPI_COMM_WORLD
   use lc_base_kinds, only: wp
   use lc_base_errors, only: error_type
   use lc_base_slab, only: row_slab, slab_of
   use lc_scene, only: scene_type
   use lc_result, only: contact_result
   use lc_io_hdf5, only: write_results, run_record
   use lc_io_hdf5_slabs, only: write_result_slabs
   use lc_profiles_height_slabs, only: read_height_slab
   use lc_test_checks, only: check, finish
   implicit none (type, external)

   !> the grid of the maps: 64 rows, which 3 ranks do not divide (blocks of 22, 22, 20)
   integer, parameter :: nx = 24, ny = 64
   real(wp), parameter :: two_pi = 8*atan(1.0_wp), lx = 2.0_wp, ly = 1.5_wp
   character(len=256) :: dir, mode, argument
   type(error_type), allocatable :: error
   type(row_slab) :: slab
   type(scene_type) :: scene
   integer :: rank, ranks, failing, code

   call MPI_Init()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, ranks)
   call get_command_argument(1, dir)
   call get_command_argument(2, mode)
   slab = slab_of(nx, ny, ranks, rank)
   write (*, '(a, 3(1x, i0))') 'rank', rank, slab%y_start, slab%ny_local

   scene%geometry = 'areal'
   scene%n = nx
   scene%ny = ny
   scene%period = lx
   scene%period_y = ly
   scene%overwrite = .true.
   scene%friction = 0.3_wp

   select case (trim(mode))
   case ('write')
      ! `write single`: the maps stored as float32 (&output precision), converted by HDF5
      call get_command_argument(3, argument)
      if (trim(argument) == 'single') scene%precision = 'single'
      call write_both()
      call read_all()
   case ('fail')
      call get_command_argument(3, argument)
      read (argument, *) failing
      call write_slabs(trim(dir) // '/failed.h5', failing)
   case ('keep')
      scene%overwrite = .false.
      call write_slabs(trim(dir) // '/slabs.h5', -1)
   case ('few')
      call get_command_argument(3, argument)
      call read_few(trim(argument))
   end select

   code = 0
   if (allocated(error)) then
      write (*, '(a, 1x, i0, 1x, a)') 'error', error%code, error%message
      code = error%code
   end if
   call MPI_Finalize()
   call finish('slab I/O')
   if (code /= 0) error stop code

contains

   !> The closed-form maps at the global point (ix, iy), 0-based: a pressure that is zero on
   !> more than half of the grid (a cosine cap), dense gap, displacements and stresses.
   pure real(wp) function map(which, ix, iy)
      character(len=*), intent(in) :: which
      integer, intent(in) :: ix, iy
      real(wp) :: x, y
      x = ix*lx/nx
      y = iy*ly/ny
      select case (which)
      case ('pressure')
         map = max(0.0_wp, cos(two_pi*x/lx)*cos(two_pi*y/ly) - 0.5_wp)
      case ('shear')
         map = 0.3_wp*max(0.0_wp, cos(two_pi*x/lx)*cos(two_pi*y/ly) - 0.5_wp)
      case ('gap')
         map = 1.0_wp + sin(two_pi*x/lx) + 0.25_wp*y
      case ('displacement_z')
         map = 1.0e-3_wp*(ix + 1000*iy)
      case ('displacement_x')
         map = -2.0e-4_wp*(ix - iy)
      case ('stress_xx')
         map = cos(two_pi*y/ly) - 2*x
      case ('height')
         map = 0.01_wp*sin(two_pi*x/lx + 3*two_pi*y/ly)
      case default
         map = -1.0_wp
      end select
   end function map

   !> The map's rows y_start+1 .. y_start+rows, flat, x fastest.
   pure function rows_of(which, y_start, rows) result(values)
      character(len=*), intent(in) :: which
      integer, intent(in) :: y_start, rows
      real(wp) :: values(nx*rows)
      integer :: ix, iy
      do iy = 0, rows - 1
         do ix = 0, nx - 1
            values(1 + ix + nx*iy) = map(which, ix, y_start + iy)
         end do
      end do
   end function rows_of

   !> A result holding the rows y_start+1 .. y_start+rows of every map and the scalars and
   !> lists every rank holds whole.
   function result_of(y_start, rows) result(res)
      integer, intent(in) :: y_start, rows
      type(contact_result) :: res
      res%pressure = rows_of('pressure', y_start, rows)
      res%gap = rows_of('gap', y_start, rows)
      res%displacement_z = rows_of('displacement_z', y_start, rows)
      res%displacement_x = rows_of('displacement_x', y_start, rows)
      res%shear = rows_of('shear', y_start, rows)
      res%stress_xx = rows_of('stress_xx', y_start, rows)
      res%residual_history = [1.0_wp, 1.0e-4_wp, 1.0e-11_wp]
      res%friction = 0.3_wp
      res%mean_pressure = 0.1_wp
      res%penetration = 0.02_wp
      res%contact_fraction = 0.25_wp
      res%converged = .true.
      res%iterations = 3
      res%fft_pairs = 4
      res%residual = 1.0e-11_wp
      res%mpi_ranks = ranks
   end function result_of

   !> The frictionless companion: the same maps but the shear, other scalars.
   function companion_of(y_start, rows) result(res)
      integer, intent(in) :: y_start, rows
      type(contact_result) :: res
      res = result_of(y_start, rows)
      deallocate (res%displacement_x, res%shear, res%stress_xx)
      res%friction = 0.0_wp
      res%contact_fraction = 0.2_wp
      res%residual_history = [1.0_wp, 1.0e-9_wp]
   end function companion_of

   !> This rank's rows into `filename`; rank `failing` passes one height too few.
   subroutine write_slabs(filename, failing)
      character(len=*), intent(in) :: filename
      integer, intent(in) :: failing
      real(wp), allocatable :: height(:)
      type(run_record) :: run
      run%input_file = 'scene.nml'
      run%started = '2026-01-02T03:04:05Z'
      run%seconds = 1.5_wp
      height = rows_of('height', slab%y_start, slab%ny_local)
      if (rank == failing) height = height(2:)
      call write_result_slabs(filename, scene, '&scene geometry = ''areal'' /', height, &
         & result_of(slab%y_start, slab%ny_local), '0.1.0-test', slab, MPI_COMM_WORLD, error, &
         & companion=companion_of(slab%y_start, slab%ny_local), run=run)
   end subroutine write_slabs

   subroutine write_both()
      type(run_record) :: run
      call write_slabs(trim(dir) // '/slabs.h5', -1)
      call check(.not. allocated(error), 'the slabs are written')
      if (allocated(error)) then
         write (*, '(a)') error%message
         return
      end if
      if (rank == 0) then
         run%input_file = 'scene.nml'
         run%started = '2026-01-02T03:04:05Z'
         run%seconds = 1.5_wp
         call write_results(trim(dir) // '/serial.h5', scene, '&scene geometry = ''areal'' /', &
            & rows_of('height', 0, ny), result_of(0, ny), companion_of(0, ny), '0.1.0-test', error, run)
         call check(.not. allocated(error), 'the whole result is written by one rank')
      end if
   end subroutine write_both

   !> The heights the test wrote: h(ix, iy) = ix + 1000.25 iy (exact in binary and in text).
   subroutine read_all()
      character(len=*), parameter :: names(3) = [character(len=12) :: 'heights.h5', 'heights.npy', 'heights.txt']
      real(wp), allocatable :: height(:, :)
      type(row_slab) :: rows
      integer :: i, ix, iy
      logical :: exact
      do i = 1, size(names)
         call read_height_slab(trim(dir) // '/' // trim(names(i)), '/h', MPI_COMM_WORLD, height, rows, error)
         call check(.not. allocated(error), trim(names(i)) // ' is read by slabs')
         if (allocated(error)) return
         call check(rows%nx == 40 .and. rows%ny == ny .and. rows%y_start == slab%y_start .and. &
            & rows%ny_local == slab%ny_local, trim(names(i)) // ': the slab of the file''s (40, 64) is the contract''s')
         call check(all(shape(height) == [40, slab%ny_local]), trim(names(i)) // ': this rank''s rows only')
         exact = .true.
         do iy = 1, size(height, 2)
            do ix = 1, size(height, 1)
               exact = exact .and. height(ix, iy) == (ix - 1) + 1000.25_wp*(slab%y_start + iy - 1)
            end do
         end do
         call check(exact, trim(names(i)) // ': every height of the rows is the file''s')
      end do
   end subroutine read_all

   subroutine read_few(name)
      character(len=*), intent(in) :: name
      real(wp), allocatable :: height(:, :)
      type(row_slab) :: rows
      call read_height_slab(trim(dir) // '/' // name, '/h', MPI_COMM_WORLD, height, rows, error)
   end subroutine read_few
end program test_slab_io
