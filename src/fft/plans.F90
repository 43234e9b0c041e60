!> FFTW plans owned by a type: one real-to-complex / complex-to-real pair for a line of
!> nx points or a surface of nx x ny points (x fastest, lc_base_grid's layout), made by each
!> object for itself, with their own aligned buffers. No state outside the objects.
!>
!> Convention: f(x_j) = sum_q f^(q) exp(i q.x_j). `forward` returns f^(q) on the half
!> spectrum (r2c along x, divided by nx*ny); `backward` is its exact inverse (c2r, no
!> scaling).
!>
!> Distributed (`init` with `distributed`, under several MPI ranks: lc_base_parallel): the
!> surface's rows are split into slabs and `real_buffer` holds this rank's slab: rows
!> y_start+1 .. y_start+ny_local of the field. The spectrum is transposed (two global
!> transposes a pair fewer: docs/decisions/023-mpi-slabs.md): this rank holds the columns
!> mx = x_start .. x_start+nkx_local-1 of the half spectrum, each with all ny rows, my
!> fastest (`mode_indices`). A pair is three stages of the plan's own around FFTW-MPI's
!> transposes (decision 023, 'The distributed pair in stages of its own'): the rows' r2c
!> in blocks of `column_block` rows through a thread's buffer, written by column mx
!> (`row_spectra`), so that FFTW-MPI's transpose needs no local transpose before its
!> exchange; the columns' DFTs in place, contiguous, in blocks; the transpose back to
!> rows, and their c2r. An operator's product (`convolve`, `convolve_passes`) exchanges
!> whole blocks by MPI_Alltoallv instead, and no local transpose is left (decision 023,
!> 'The products' exchanges'): the spectrum lies by row slabs between the exchanges, each
!> block of columns gathered into a thread's buffer for its DFTs and the product, each
!> block of rows gathered from row_spectra for its c2r.
!>
!> `convolve_passes` (two-pass and distributed surfaces) takes a solver's passes over the
!> grid into a product's row stages (`row_work`): each block of rows is written by the
!> solver into a thread's buffer and transformed from there, and read back by it from
!> there after the c2r, so that the product's input and output never cross the memory as
!> fields (docs/decisions/024-fft-floor.md, 'Rows fetched ahead, and the CG's passes
!> inside its product's rows').
module lc_fft_plans
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_double_complex, c_size_t, &
      & c_f_pointer, c_associated, c_null_ptr
   use lc_fft_fftw3, only: fftw_alloc_real, fftw_alloc_complex, fftw_free, fftw_plan_dft_r2c_1d, &
      & fftw_plan_dft_c2r_1d, fftw_plan_dft_r2c_2d, fftw_plan_dft_c2r_2d, fftw_execute_dft_r2c, &
      & fftw_execute_dft_c2r, fftw_destroy_plan, fftw_init_threads, fftw_plan_with_nthreads, FFTW_ESTIMATE, &
      & FFTW_DESTROY_INPUT, fftw_plan_many_dft_r2c, fftw_plan_many_dft_c2r, fftw_plan_many_dft, fftw_execute_dft, &
      & FFTW_FORWARD, FFTW_BACKWARD, FFTW_NO_BUFFERING
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_internal
   use lc_base_strings, only: to_string
   use lc_base_pages, only: advise_huge_pages
   use lc_base_threads, only: fill_field, thread_number
   use lc_base_parallel, only: is_distributed, slab, global_sum
#ifdef LC_MPI
   use lc_base_parallel, only: communicator, rank_count, this_rank, slab_rows, global_any
   use mpi_f08, only: MPI_Alltoallv, MPI_DOUBLE_COMPLEX
   use lc_fft_fftw3_mpi, only: fftw_mpi_init, fftw_mpi_local_size_many_transposed, fftw_mpi_plan_many_transpose, &
      & fftw_mpi_execute_r2r, FFTW_MPI_TRANSPOSED_IN, FFTW_MPI_DEFAULT_BLOCK
   use, intrinsic :: iso_c_binding, only: c_intptr_t
#endif
   implicit none (type, external)
   private
   public :: fft_plan, transform_seconds, row_work

   !> Surfaces of at least this many points are transformed in two passes: the rows (r2c),
   !> then the columns of the half spectrum in blocks of `column_block` adjacent columns.
   !> FFTW_ESTIMATE's plan for the 2D transform walks the columns one at a time with a
   !> stride of nx/2 + 1 complex numbers, a cache line per element; blocks of 8 share the
   !> lines. The gain is steady from about 1000^2 on (docs/performance.md, 'Cost': 'Large surfaces:
   !> a two-pass transform'; bench/fft_plans.c). Each block is copied, row by row, into a
   !> buffer of its thread and transformed there: FFTW's plans for the block in place (stride
   !> nx/2 + 1) copy it into buffers they allocate at every execution, which on a second
   !> thread's malloc arena came as fresh pages each time, a page fault every 4 KiB
   !> (docs/decisions/022-threads.md, 'The column pass's buffers').
   integer, parameter :: split_points = 800000
   integer, parameter :: column_block = 8
   !> FFTW-MPI's own set-up is done (once per process)
   logical :: fftw_mpi_ready = .false.
   !> clock ticks this process spent in the grid transforms (forward_unscaled and backward,
   !> the distributed ones' transposes included): a solve's own FFT time (transform_seconds)
   integer(i8) :: transform_ticks = 0

   !> The block passes of a two-pass surface, rows fetched ahead (columns.c).
   interface
      subroutine lc_copy_columns(spectrum, nkx, ny, first, columns, block, into_block) bind(c, name='lc_copy_columns')
         import :: c_int
         type(*), dimension(*), intent(inout) :: spectrum, block
         integer(c_int), value, intent(in) :: nkx, ny, first, columns, into_block
      end subroutine lc_copy_columns

      subroutine lc_multiply_columns_real(block, columns, ny, multiplier, nkx, first, scale, weights, energy) &
            & bind(c, name='lc_multiply_columns_real')
         import :: c_int, c_double
         type(*), dimension(*), intent(inout) :: block
         integer(c_int), value, intent(in) :: columns, ny, nkx, first
         real(c_double), intent(in) :: multiplier(*)
         real(c_double), value, intent(in) :: scale
         real(c_double), intent(in), optional :: weights(*)
         real(c_double), intent(out), optional :: energy
      end subroutine lc_multiply_columns_real

      subroutine lc_multiply_columns_complex(block, columns, ny, multiplier, nkx, first, scale) &
            & bind(c, name='lc_multiply_columns_complex')
         import :: c_int, c_double, c_double_complex
         type(*), dimension(*), intent(inout) :: block
         integer(c_int), value, intent(in) :: columns, ny, nkx, first
         complex(c_double_complex), intent(in) :: multiplier(*)
         real(c_double), value, intent(in) :: scale
      end subroutine lc_multiply_columns_complex
   end interface

   !> A solver's passes over the grid fused into a product's row stages (convolve_passes):
   !> `before` writes the product's input on a block of rows (rows first .. first+rows-1,
   !> `values` their nx*rows values, `block` the block's number from 1, for sums kept by
   !> block), `between` gets the product's energy (as convolve's, summed over the ranks)
   !> once every block's input is in and before any output, and `after` reads the
   !> product's output on a block of rows. The blocks are shared among the solve's threads.
   type, abstract :: row_work
   contains
      procedure(rows_action), deferred :: before
      procedure(energy_action), deferred :: between
      procedure(rows_action), deferred :: after
   end type row_work

   abstract interface
      subroutine rows_action(self, first, rows, values, block)
         import :: row_work, wp
         class(row_work), intent(inout) :: self
         integer, intent(in) :: first, rows, block
         real(wp), contiguous, intent(inout) :: values(:)
      end subroutine rows_action

      subroutine energy_action(self, energy)
         import :: row_work, wp
         class(row_work), intent(inout) :: self
         real(wp), intent(in) :: energy
      end subroutine energy_action
   end interface

   !> An r2c/c2r plan pair with its buffers: copy data into `real_buffer`, call
   !> `forward`, work on `spectrum`, call `backward`, read `real_buffer`. Planning with
   !> FFTW_ESTIMATE costs a few transforms' time and gives the same plan, so the same bits,
   !> on every run (docs/decisions/002-one-core-for-lines-and-surfaces.md).
   type :: fft_plan
      integer :: n = 0    !< real points nx*ny
      integer :: nk = 0   !< spectral coefficients (nx/2 + 1)*ny
      integer :: nx = 0, ny = 1
      integer :: threads = 1   !< threads a transform runs on
      !> the slab of a distributed surface: rows y_start+1 .. y_start+ny_local (all rows
      !> otherwise); n and nk are then this slab's points and modes
      logical :: distributed = .false.
      integer :: y_start = 0, ny_local = 1
      !> distributed: the columns of the half spectrum this rank holds (transposed)
      integer :: x_start = 0, nkx_local = 0
      real(c_double), pointer, contiguous :: real_buffer(:) => null()
      complex(c_double_complex), pointer, contiguous :: spectrum(:) => null()
      type(c_ptr), private :: r2c = c_null_ptr, c2r = c_null_ptr
      type(c_ptr), private :: real_memory = c_null_ptr, complex_memory = c_null_ptr
      !> two-pass surfaces (split_points): r2c and c2r above transform the rows; these the
      !> columns, `column_block` at a time (the last block: `last_block` columns)
      logical, private :: split = .false.
      integer, private :: last_block = 0
      !> one buffer of column_block columns of ny modes a thread: the block a thread
      !> transforms, row by row (a row's columns adjacent) on a two-pass surface, column by
      !> column (a column's modes adjacent) in a distributed product
      complex(c_double_complex), pointer, contiguous, private :: column_buffer(:, :) => null()
      type(c_ptr), private :: column_memory = c_null_ptr
      type(c_ptr), private :: columns_forward = c_null_ptr, columns_backward = c_null_ptr
      type(c_ptr), private :: last_forward = c_null_ptr, last_backward = c_null_ptr
      !> the rows alone (plan_rows): r2c and c2r along x of each of the ny rows
      type(c_ptr), private :: rows_r2c = c_null_ptr, rows_c2r = c_null_ptr
      !> distributed: the rows' half spectra by column (row_spectra(my, mx), this rank's rows
      !> my), FFTW-MPI's transpose's input; after the transpose back, by row (the c2r's input)
      complex(c_double_complex), pointer, contiguous, private :: row_spectra(:) => null()
      type(c_ptr), private :: row_spectra_memory = c_null_ptr
      !> distributed: one buffer of column_block rows' half spectra a thread (a column's
      !> modes adjacent), and the plans of the last block of rows, of the transposes, and of
      !> the c2r of every row
      complex(c_double_complex), pointer, contiguous, private :: row_buffer(:, :) => null()
      type(c_ptr), private :: row_memory = c_null_ptr
      integer, private :: last_rows = 0
      type(c_ptr), private :: last_rows_r2c = c_null_ptr
      type(c_ptr), private :: to_columns = c_null_ptr, to_rows = c_null_ptr
      !> distributed: the products (convolve, convolve_passes) exchange whole blocks with
      !> MPI_Alltoallv, not by FFTW-MPI's transposes (`plan_exchanges`). Rank q's columns
      !> of row_spectra go to it as they lie (`column_counts`, `column_offsets`, complex
      !> numbers, by rank); the spectrum then holds this rank's columns by row slabs, rank s's
      !> rows of every column together (`slab_counts`, `slab_offsets`; its rows
      !> `slab_first` + 1 .. + `slab_row_counts`), each block of columns gathered into a thread's
      !> column_buffer for its DFTs and put back; the way back lands in row_spectra by column
      !> again, and each block of rows is gathered into its thread's row_buffer for its c2r
      !> (`rows_c2r_block`, the last, shorter block apart). This rank's own block, its rows of
      !> its columns, lies in row_spectra as the spectrum would hold it: it is not sent (its
      !> counts are 0), and the columns' stage reads and writes it there (rank `own_rank`).
      integer, private :: own_rank = 0
      integer, allocatable, private :: column_counts(:), column_offsets(:), slab_counts(:), slab_offsets(:)
      integer, allocatable, private :: slab_first(:), slab_row_counts(:)
      type(c_ptr), private :: rows_c2r_block = c_null_ptr, last_rows_c2r_block = c_null_ptr
      !> two-pass and distributed surfaces, made on convolve_passes' first call: a buffer of
      !> column_block rows of the field a thread (a block's input and output), and the r2c
      !> and c2r of a block of rows between it and the spectrum (one process; a distributed
      !> surface's are the rows' stage's and the exchanges' own), the last block apart
      real(c_double), pointer, contiguous, private :: rows_real(:, :) => null()
      type(c_ptr), private :: rows_real_memory = c_null_ptr
      type(c_ptr), private :: block_r2c = c_null_ptr, last_block_r2c = c_null_ptr
      type(c_ptr), private :: block_c2r = c_null_ptr, last_block_c2r = c_null_ptr
      !> the spectrum's and row_spectra's memory as pairs of doubles (the transposes' view)
      real(c_double), pointer, contiguous, private :: spectrum_values(:) => null(), row_values(:) => null()
   contains
      procedure :: init
      procedure :: forward
      procedure :: forward_unscaled
      procedure :: backward
      procedure :: fuses_products
      procedure :: convolve
      procedure :: convolve_passes
      procedure :: plan_passes
      procedure :: row_blocks
      procedure :: plan_rows
      procedure :: rows_forward_unscaled
      procedure :: rows_backward
      procedure :: destroy
      procedure :: mode_indices
      final :: finalize
   end type fft_plan

contains

   !> Make plans and buffers for nx x ny points (ny = 1: a line) for `threads` threads
   !> (ignored without OpenMP): FFTW's threads for the rows (and for a whole surface below
   !> split_points), OpenMP over the blocks of columns of a two-pass surface. `distributed`:
   !> a surface shared among the job's ranks, if there are several (see the module).
   subroutine init(self, nx, ny, threads, error, distributed)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: nx, ny, threads
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: distributed
      integer(c_int) :: status

      call self%destroy()
      if (present(distributed)) then
         if (distributed .and. ny > 1 .and. is_distributed()) then
            call init_distributed(self, nx, ny, threads, error)
            return
         end if
      end if
      self%threads = max(threads, 1)
#ifdef LC_OPENMP
      status = fftw_init_threads()
      call fftw_plan_with_nthreads(int(self%threads, c_int))
#else
      status = int(threads, c_int)
#endif
      self%nx = nx
      self%ny = ny
      self%ny_local = ny
      self%n = nx*ny
      self%nk = (nx/2 + 1)*ny
      self%real_memory = fftw_alloc_real(int(self%n, c_size_t))
      self%complex_memory = fftw_alloc_complex(int(self%nk, c_size_t))
      if (.not. (c_associated(self%real_memory) .and. c_associated(self%complex_memory))) then
         call fatal_error(error, 'fft: cannot allocate FFTW buffers for ' // to_string(nx) // ' x ' // &
            & to_string(ny) // ' points', code_internal)
         return
      end if
      call c_f_pointer(self%real_memory, self%real_buffer, [self%n])
      call c_f_pointer(self%complex_memory, self%spectrum, [self%nk])
      call advise_huge_pages(self%real_buffer)
      call advise_huge_pages(self%spectrum)
      ! (the first touch on the solve's threads, each its blocks' pages)
      call fill_field(self%real_buffer, 0.0_wp)
      ! FFTW's dimensions are in C order: the last one (x) is contiguous
      if (ny == 1) then
         self%r2c = fftw_plan_dft_r2c_1d(int(nx, c_int), self%real_buffer, self%spectrum, FFTW_ESTIMATE)
         self%c2r = fftw_plan_dft_c2r_1d(int(nx, c_int), self%spectrum, self%real_buffer, &
            & ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      else if (int(nx, i8)*ny < split_points) then
         self%r2c = fftw_plan_dft_r2c_2d(int(ny, c_int), int(nx, c_int), self%real_buffer, self%spectrum, &
            & FFTW_ESTIMATE)
         self%c2r = fftw_plan_dft_c2r_2d(int(ny, c_int), int(nx, c_int), self%spectrum, self%real_buffer, &
            & ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      else
         call plan_split(self)
      end if
      if (.not. (c_associated(self%r2c) .and. c_associated(self%c2r))) then
         call fatal_error(error, 'fft: FFTW could not plan a transform of ' // to_string(nx) // ' x ' // &
            & to_string(ny) // ' points', code_internal)
         return
      end if
   end subroutine init

   !> The plans and buffers of a surface shared among the job's ranks (FFTW-MPI, this
   !> rank's slab of rows: see the module).
   subroutine init_distributed(self, nx, ny, threads, error)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: nx, ny, threads
      type(error_type), allocatable, intent(out) :: error
#ifdef LC_MPI
      integer(c_intptr_t) :: local_values, local_complex, local_rows, local_start, local_columns, column_start
      integer(c_int) :: status
      integer :: nkx
      if (.not. fftw_mpi_ready) then
#ifdef LC_OPENMP
         status = fftw_init_threads()
#endif
         call fftw_mpi_init()
         fftw_mpi_ready = .true.
      end if
      self%threads = max(threads, 1)
#ifdef LC_OPENMP
      call fftw_plan_with_nthreads(int(self%threads, c_int))
#else
      status = int(threads, c_int)
#endif
      nkx = nx/2 + 1
      self%distributed = .true.
      self%nx = nx
      self%ny = ny
      call slab(ny, self%y_start, self%ny_local)
      ! (the transposes' sizes: ny rows of nkx complex values, pairs of doubles to FFTW-MPI)
      local_values = fftw_mpi_local_size_many_transposed(2_c_int, [int(ny, c_intptr_t), int(nkx, c_intptr_t)], &
         & 2_c_intptr_t, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, communicator%MPI_VAL, local_rows, &
         & local_start, local_columns, column_start)
      local_complex = (local_values + 1)/2
      if (local_rows /= self%ny_local .or. local_start /= self%y_start) then
         call fatal_error(error, 'fft: FFTW-MPI gives this rank rows ' // to_string(int(local_start)) // ' + ' // &
            & to_string(int(local_rows)) // ', the slab contract ' // to_string(self%y_start) // ' + ' // &
            & to_string(self%ny_local), code_internal)
         return
      end if
      self%x_start = int(column_start)
      self%nkx_local = int(local_columns)
      self%n = nx*self%ny_local
      self%nk = self%nkx_local*ny
      ! (row_spectra is the transposes' other array, of FFTW-MPI's local size as the spectrum)
      self%real_memory = fftw_alloc_real(int(max(self%n, 1), c_size_t))
      self%complex_memory = fftw_alloc_complex(int(max(local_complex, 1_c_intptr_t), c_size_t))
      self%row_spectra_memory = fftw_alloc_complex(int(max(local_complex, 1_c_intptr_t), c_size_t))
      self%row_memory = fftw_alloc_complex(int(column_block, c_size_t)*int(nkx, c_size_t)*int(self%threads, c_size_t))
      if (.not. (c_associated(self%real_memory) .and. c_associated(self%complex_memory) .and. &
         & c_associated(self%row_spectra_memory) .and. c_associated(self%row_memory))) then
         call fatal_error(error, 'fft: cannot allocate FFTW buffers for ' // to_string(nx) // ' x ' // &
            & to_string(self%ny_local) // ' points (a slab of ' // to_string(ny) // ' rows)', code_internal)
         return
      end if
      call c_f_pointer(self%real_memory, self%real_buffer, [self%n])
      call c_f_pointer(self%complex_memory, self%spectrum, [self%nk])
      call c_f_pointer(self%row_spectra_memory, self%row_spectra, [local_complex])
      call c_f_pointer(self%row_memory, self%row_buffer, [column_block*nkx, self%threads])
      call advise_huge_pages(self%real_buffer)
      call advise_huge_pages(self%spectrum)
      call advise_huge_pages(self%row_spectra)
      call fill_field(self%real_buffer, 0.0_wp)
      call plan_distributed(self, int(local_complex), error)
      if (.not. allocated(error)) call plan_exchanges(self, error)
#else
      call fatal_error(error, 'fft: this build has no FFTW-MPI (' // to_string(nx) // ' x ' // to_string(ny) // &
         & ' points on ' // to_string(threads) // ' threads)', code_internal)
#endif
   end subroutine init_distributed

#ifdef LC_MPI
   !> The plans of a distributed pair (see the module): a block of column_block rows' r2c
   !> into a thread's buffer (a column's modes adjacent) and the same for the last, shorter
   !> block; FFTW-MPI's transposes between row_spectra and the spectrum (the first's input
   !> by column, FFTW_MPI_TRANSPOSED_IN, so that it sends its blocks as they lie; the way
   !> back leaves the rows' spectra by row); the columns' DFTs in blocks in place; the c2r
   !> of every row. `local_complex`: FFTW-MPI's local size of both arrays.
   subroutine plan_distributed(self, local_complex, error)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: local_complex
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: nx, ny, nkx, rows, columns
      nx = int(self%nx, c_int)
      ny = int(self%ny, c_int)
      nkx = nx/2 + 1
      ! (the transposes see both arrays as pairs of doubles, and are zeroed through them)
      call c_f_pointer(self%complex_memory, self%spectrum_values, [2*local_complex])
      call c_f_pointer(self%row_spectra_memory, self%row_values, [2*local_complex])
      self%spectrum_values = 0.0_wp
      self%row_values = 0.0_wp
      self%to_columns = fftw_mpi_plan_many_transpose(int(ny, c_intptr_t), int(nkx, c_intptr_t), 2_c_intptr_t, &
         & FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, self%row_values, self%spectrum_values, communicator%MPI_VAL, &
         & ior(FFTW_ESTIMATE, FFTW_MPI_TRANSPOSED_IN))
      self%to_rows = fftw_mpi_plan_many_transpose(int(nkx, c_intptr_t), int(ny, c_intptr_t), 2_c_intptr_t, &
         & FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, self%spectrum_values, self%row_values, communicator%MPI_VAL, &
         & ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      self%c2r = fftw_plan_many_dft_c2r(1_c_int, [nx], int(self%ny_local, c_int), self%row_spectra, [nkx], 1_c_int, &
         & nkx, self%real_buffer, [nx], 1_c_int, nx, ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      ! (each block's plan runs on one thread: the blocks are shared out among the threads)
#ifdef LC_OPENMP
      call fftw_plan_with_nthreads(1_c_int)
#endif
      rows = int(min(column_block, self%ny_local), c_int)
      self%r2c = row_plan(rows)
      self%last_rows = mod(self%ny_local, column_block)
      if (self%last_rows > 0) self%last_rows_r2c = row_plan(int(self%last_rows, c_int))
      columns = int(min(column_block, self%nkx_local), c_int)
      if (columns > 0) then
         self%columns_forward = column_plan(columns, FFTW_FORWARD)
         self%columns_backward = column_plan(columns, FFTW_BACKWARD)
      end if
      self%last_block = mod(self%nkx_local, column_block)
      if (self%last_block > 0) then
         self%last_forward = column_plan(int(self%last_block, c_int), FFTW_FORWARD)
         self%last_backward = column_plan(int(self%last_block, c_int), FFTW_BACKWARD)
      end if
      if (.not. (c_associated(self%to_columns) .and. c_associated(self%to_rows) .and. c_associated(self%c2r) .and. &
         & c_associated(self%r2c) .and. (self%last_rows == 0 .or. c_associated(self%last_rows_r2c)) .and. &
         & (columns == 0 .or. (c_associated(self%columns_forward) .and. c_associated(self%columns_backward))) .and. &
         & (self%last_block == 0 .or. (c_associated(self%last_forward) .and. c_associated(self%last_backward))))) &
         & call fatal_error(error, 'fft: FFTW-MPI could not plan a transform of ' // to_string(self%nx) // ' x ' // &
         & to_string(self%ny) // ' points', code_internal)
   contains
      !> The r2c of `count` rows of the slab into the first thread's buffer, row r's
      !> coefficient mx at buffer(mx*count + r + 1).
      type(c_ptr) function row_plan(count)
         integer(c_int), intent(in) :: count
         row_plan = fftw_plan_many_dft_r2c(1_c_int, [nx], count, self%real_buffer, [nx], 1_c_int, nx, &
            & self%row_buffer(:, 1), [nkx], count, 1_c_int, FFTW_ESTIMATE)
      end function row_plan

      !> `count` adjacent columns of ny modes, each contiguous, in place in the spectrum.
      type(c_ptr) function column_plan(count, sign)
         integer(c_int), intent(in) :: count, sign
         column_plan = fftw_plan_many_dft(1_c_int, [ny], count, self%spectrum(1:), [ny], 1_c_int, ny, &
            & self%spectrum(1:), [ny], 1_c_int, ny, sign, ior(FFTW_ESTIMATE, FFTW_NO_BUFFERING))
      end function column_plan
   end subroutine plan_distributed

   !> The products' exchanges (see `column_counts`): what each rank sends to each and where it
   !> lands, a column buffer a thread, and the c2r of a block of rows from a thread's
   !> row_buffer. The same error on every rank where they cannot be made.
   subroutine plan_exchanges(self, error)
      class(fft_plan), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer :: p, q, x_first, x_count, nkx
      integer(c_int) :: rows
      logical :: made
      nkx = self%nx/2 + 1
      p = rank_count()
      ! (MPI's counts are default integers: the largest block, ceiling(nkx/P) columns of
      ! every row or every column of ceiling(ny/P) rows, must fit; the input's limit of
      ! 2^28 points keeps it below 2^27)
      if (max(int(nkx, i8)*((self%ny + p - 1)/p), int((nkx + p - 1)/p, i8)*self%ny) > huge(1)) then
         call fatal_error(error, 'fft: a block of the spectrum of ' // to_string(self%nx) // ' x ' // &
            & to_string(self%ny) // ' points on ' // to_string(p) // ' ranks exceeds an MPI count', code_internal)
         return
      end if
      allocate (self%column_counts(0:p - 1), self%column_offsets(0:p - 1), self%slab_counts(0:p - 1), &
         & self%slab_offsets(0:p - 1), self%slab_first(0:p - 1), self%slab_row_counts(0:p - 1))
      do q = 0, p - 1
         call slab_rows(nkx, p, q, x_first, x_count)
         ! (a rank without columns: FFTW-MPI's start is then 0)
         if (q == this_rank() .and. (x_count /= self%nkx_local .or. (x_count > 0 .and. x_first /= self%x_start))) then
            call fatal_error(error, 'fft: FFTW-MPI gives this rank columns ' // to_string(self%x_start) // ' + ' // &
               & to_string(self%nkx_local) // ', the slab contract ' // to_string(x_first) // ' + ' // &
               & to_string(x_count), code_internal)
            return
         end if
         call slab_rows(self%ny, p, q, self%slab_first(q), self%slab_row_counts(q))
         self%column_counts(q) = x_count*self%ny_local
         self%column_offsets(q) = x_first*self%ny_local
         self%slab_counts(q) = self%nkx_local*self%slab_row_counts(q)
         self%slab_offsets(q) = self%nkx_local*self%slab_first(q)
      end do
      self%own_rank = this_rank()
      self%column_counts(self%own_rank) = 0
      self%slab_counts(self%own_rank) = 0
      ! (a column buffer a thread, each a multiple of 8*ny*16 bytes from FFTW's aligned start)
      made = .true.
      if (self%nkx_local > 0) then
         self%column_memory = fftw_alloc_complex(int(column_block, c_size_t)*int(self%ny, c_size_t)* &
            & int(self%threads, c_size_t))
         made = c_associated(self%column_memory)
         if (made) call c_f_pointer(self%column_memory, self%column_buffer, [column_block*self%ny, self%threads])
      end if
      if (made) then
#ifdef LC_OPENMP
         call fftw_plan_with_nthreads(1_c_int)
#endif
         rows = int(min(column_block, self%ny_local), c_int)
         self%rows_c2r_block = rows_plan(rows)
         if (self%last_rows > 0) self%last_rows_c2r_block = rows_plan(int(self%last_rows, c_int))
         made = c_associated(self%rows_c2r_block) .and. (self%last_rows == 0 .or. c_associated(self%last_rows_c2r_block))
      end if
      if (global_any(.not. made)) call fatal_error(error, 'fft: cannot allocate or plan the blocks of a ' // &
         & to_string(self%nx) // ' x ' // to_string(self%ny) // ' surface''s slabs on ' // to_string(p) // ' ranks', &
         & code_internal)
   contains
      !> The c2r of `count` rows from the first thread's row_buffer (row r's coefficient mx
      !> at buffer(mx*count + r + 1), as the rows' r2c leaves them) into rows of the field.
      type(c_ptr) function rows_plan(count)
         integer(c_int), intent(in) :: count
         rows_plan = fftw_plan_many_dft_c2r(1_c_int, [int(self%nx, c_int)], count, self%row_buffer(:, 1), &
            & [int(nkx, c_int)], count, 1_c_int, self%real_buffer, [int(self%nx, c_int)], 1_c_int, &
            & int(self%nx, c_int), ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      end function rows_plan
   end subroutine plan_exchanges

   !> row_spectra's blocks of columns to their ranks, into the spectrum by row slabs
   !> (`to_columns`), or back (see `column_counts`).
   subroutine exchange_blocks(self, to_columns)
      class(fft_plan), intent(inout) :: self
      logical, intent(in) :: to_columns
      if (to_columns) then
         call MPI_Alltoallv(self%row_spectra, self%column_counts, self%column_offsets, MPI_DOUBLE_COMPLEX, &
            & self%spectrum, self%slab_counts, self%slab_offsets, MPI_DOUBLE_COMPLEX, communicator)
      else
         call MPI_Alltoallv(self%spectrum, self%slab_counts, self%slab_offsets, MPI_DOUBLE_COMPLEX, &
            & self%row_spectra, self%column_counts, self%column_offsets, MPI_DOUBLE_COMPLEX, communicator)
      end if
   end subroutine exchange_blocks

   !> The columns' stage of a product on the exchanged spectrum (convolve, convolve_passes):
   !> each block of column_block of this rank's columns gathered from the row slabs into its
   !> thread's buffer, column by column, forward, the product (with the block's energy
   !> where `block_energy` is allocated), backward, and put back.
   subroutine product_in_slab_columns(self, scale, block_energy, real_multiplier, complex_multiplier)
      class(fft_plan), intent(inout) :: self
      real(wp), intent(in) :: scale
      real(wp), allocatable, intent(inout) :: block_energy(:)
      real(wp), contiguous, intent(in), optional :: real_multiplier(:)
      complex(wp), contiguous, intent(in), optional :: complex_multiplier(:)
      integer :: first
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%nkx_local - self%last_block, column_block
         call product_block(self%columns_forward, self%columns_backward, first, column_block, &
            & self%column_buffer(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_block > 0) call product_block(self%last_forward, self%last_backward, &
         & self%nkx_local - self%last_block + 1, self%last_block, self%column_buffer(:, 1))
   contains
      subroutine product_block(forward_plan, backward_plan, first, columns, buffer)
         type(c_ptr), intent(in) :: forward_plan, backward_plan
         integer, intent(in) :: first, columns
         complex(c_double_complex), contiguous, intent(inout) :: buffer(:)
         call slab_columns(self, first, columns, buffer, .true.)
         call fftw_execute_dft(forward_plan, buffer, buffer)
         call multiply_local_columns(self, first, columns, buffer, scale, real_multiplier, complex_multiplier, &
            & block_energy)
         call fftw_execute_dft(backward_plan, buffer, buffer)
         call slab_columns(self, first, columns, buffer, .false.)
      end subroutine product_block
   end subroutine product_in_slab_columns

   !> block <- this rank's columns first .. first+columns-1 of the exchanged spectrum (row
   !> slabs, see `column_counts`), each column's ny modes adjacent; or back (`into_block` false).
   subroutine slab_columns(self, first, columns, block, into_block)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: first, columns
      complex(c_double_complex), contiguous, intent(inout) :: block(:)
      logical, intent(in) :: into_block
      complex(c_double_complex), pointer, contiguous :: slabs(:)
      integer :: s, c, rows, start, from, to
      do s = 0, size(self%slab_counts) - 1
         rows = self%slab_row_counts(s)
         if (s == self%own_rank) then
            slabs => self%row_spectra
            start = self%x_start*self%ny_local
         else
            slabs => self%spectrum
            start = self%slab_offsets(s)
         end if
         do c = 0, columns - 1
            from = start + (first - 1 + c)*rows
            to = c*self%ny + self%slab_first(s)
            if (into_block) then
               block(to + 1:to + rows) = slabs(from + 1:from + rows)
            else
               slabs(from + 1:from + rows) = block(to + 1:to + rows)
            end if
         end do
      end do
   end subroutine slab_columns

   !> real_buffer <- the c2r of row_spectra held by column (after the way back's exchange),
   !> each block of column_block rows gathered into its thread's row_buffer first.
   subroutine rows_from_columns(self)
      class(fft_plan), intent(inout) :: self
      integer :: first
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%ny_local - self%last_rows, column_block
         call rows_c2r(self, first, column_block, self%real_buffer((first - 1)*self%nx + 1:))
      end do
      !$omp end parallel do
      if (self%last_rows > 0) call rows_c2r(self, self%ny_local - self%last_rows + 1, self%last_rows, &
         & self%real_buffer((self%ny_local - self%last_rows)*self%nx + 1:))
   end subroutine rows_from_columns

   !> values <- the c2r of the rows first .. first+rows-1 of row_spectra held by column,
   !> through the calling thread's row_buffer.
   subroutine rows_c2r(self, first, rows, values)
      class(fft_plan), intent(inout) :: self
      integer, intent(in) :: first, rows
      real(c_double), contiguous, intent(inout) :: values(:)
      integer :: thread
      thread = thread_number() + 1
      call copy_columns(self%row_spectra, self%ny_local, self%nx/2 + 1, first, rows, self%row_buffer(:, thread), .true.)
      call fftw_execute_dft_c2r(merge(self%rows_c2r_block, self%last_rows_c2r_block, rows == column_block), &
         & self%row_buffer(:, thread), values)
   end subroutine rows_c2r

   !> row_spectra(my, mx) <- the r2c of the slab's rows my (unscaled), each block of
   !> column_block rows through its thread's buffer.
   subroutine rows_to_columns(self)
      class(fft_plan), intent(inout) :: self
      integer :: first, nkx
      nkx = self%nx/2 + 1
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%ny_local - self%last_rows, column_block
         call row_block(self%r2c, first, column_block, self%row_buffer(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_rows > 0) call row_block(self%last_rows_r2c, self%ny_local - self%last_rows + 1, self%last_rows, &
         & self%row_buffer(:, 1))
   contains
      subroutine row_block(plan, first, rows, buffer)
         type(c_ptr), intent(in) :: plan
         integer, intent(in) :: first, rows
         complex(c_double_complex), contiguous, intent(inout) :: buffer(:)
         call fftw_execute_dft_r2c(plan, self%real_buffer((first - 1)*self%nx + 1:), buffer)
         call copy_columns(self%row_spectra, self%ny_local, nkx, first, rows, buffer, .false.)
      end subroutine row_block
   end subroutine rows_to_columns
#endif

#ifdef LC_MPI
   !> The DFTs of this rank's columns of a distributed spectrum, in place, by blocks of
   !> column_block adjacent columns (each contiguous) on the solve's threads.
   subroutine transform_local_columns(self, block_plan, last_plan)
      class(fft_plan), intent(inout) :: self
      type(c_ptr), intent(in) :: block_plan, last_plan
      integer :: first
      ! (the same plan for a block whatever the thread count: the bits do not depend on it)
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%nkx_local - self%last_block, column_block
         call local_block(block_plan, first, column_block)
      end do
      !$omp end parallel do
      if (self%last_block > 0) call local_block(last_plan, self%nkx_local - self%last_block + 1, self%last_block)
   contains
      !> The plan on the columns first .. first+columns-1: modes (first-1) ny + 1 ..
      subroutine local_block(plan, first, columns)
         type(c_ptr), intent(in) :: plan
         integer, intent(in) :: first, columns
         integer :: start
         start = (first - 1)*self%ny + 1
         call fftw_execute_dft(plan, self%spectrum(start:start + columns*self%ny - 1), &
            & self%spectrum(start:start + columns*self%ny - 1))
      end subroutine local_block
   end subroutine transform_local_columns

   !> values <- values * (the multiplier's modes of this rank's columns first ..
   !> first+columns-1) * scale, the columns' ny modes each adjacent in values, a real or
   !> complex multiplier (the spectrum's layout), as the operators' product; with a real
   !> multiplier and `block_energy` allocated, also the block's share of convolve's energy.
   subroutine multiply_local_columns(self, first, columns, values, scale, real_multiplier, complex_multiplier, &
         & block_energy)
      class(fft_plan), intent(in) :: self
      integer, intent(in) :: first, columns
      complex(c_double_complex), contiguous, intent(inout) :: values(:)
      real(wp), intent(in) :: scale
      real(wp), contiguous, intent(in), optional :: real_multiplier(:)
      complex(wp), contiguous, intent(in), optional :: complex_multiplier(:)
      real(wp), allocatable, intent(inout), optional :: block_energy(:)
      integer :: start, count
      start = (first - 1)*self%ny + 1
      count = columns*self%ny
      if (present(block_energy)) then
         if (allocated(block_energy)) then
            call multiply_real_values_energy(columns, self%ny, values, real_multiplier(start:), scale, &
               & column_weights(self%x_start + first - 1, columns, self%nx), block_energy((first - 1)/column_block + 1))
            return
         end if
      end if
      if (present(real_multiplier)) then
         call multiply_real_values(count, values, real_multiplier(start:), scale)
      else
         call multiply_complex_values(count, values, complex_multiplier(start:), scale)
      end if
   end subroutine multiply_local_columns

   !> values <- values * (multiplier * scale), n of each (explicit shapes: a plain loop).
   pure subroutine multiply_real_values(n, values, multiplier, scale)
      integer, intent(in) :: n
      complex(c_double_complex), intent(inout) :: values(n)
      real(wp), intent(in) :: multiplier(n), scale
      values = values*(multiplier*scale)
   end subroutine multiply_real_values

   !> multiply_real_values on `columns` columns of ny modes each, and energy = the sum of
   !> weights(column) scale multiplier |values|^2 before the product (see convolve).
   pure subroutine multiply_real_values_energy(columns, ny, values, multiplier, scale, weights, energy)
      integer, intent(in) :: columns, ny
      complex(c_double_complex), intent(inout) :: values(ny, columns)
      real(wp), intent(in) :: multiplier(ny, columns), scale, weights(columns)
      real(wp), intent(out) :: energy
      real(wp) :: f, column_energy
      integer :: column, my
      energy = 0.0_wp
      do column = 1, columns
         column_energy = 0.0_wp
         do my = 1, ny
            f = multiplier(my, column)*scale
            column_energy = column_energy + f*(real(values(my, column), wp)**2 + aimag(values(my, column))**2)
            values(my, column) = values(my, column)*f
         end do
         energy = energy + weights(column)*column_energy
      end do
   end subroutine multiply_real_values_energy

   !> The same with a complex multiplier.
   pure subroutine multiply_complex_values(n, values, multiplier, scale)
      integer, intent(in) :: n
      complex(c_double_complex), intent(inout) :: values(n)
      complex(wp), intent(in) :: multiplier(n)
      real(wp), intent(in) :: scale
      values = values*(multiplier*scale)
   end subroutine multiply_complex_values
#endif

   !> The column mx (0..nx/2) and row my (0..ny-1) of this plan's spectrum entry i (1-based):
   !> mx fastest (serial), or my fastest in this rank's columns (distributed, transposed).
   pure subroutine mode_indices(self, i, mx, my)
      class(fft_plan), intent(in) :: self
      integer, intent(in) :: i
      integer, intent(out) :: mx, my
      if (self%distributed) then
         mx = self%x_start + (i - 1)/self%ny
         my = mod(i - 1, self%ny)
      else
         mx = mod(i - 1, self%nx/2 + 1)
         my = (i - 1)/(self%nx/2 + 1)
      end if
   end subroutine mode_indices

   !> The plans of a two-pass surface: rows r2c/c2r (contiguous), and a block of
   !> column_block columns of the half spectrum in a thread's column_buffer (row by row, in
   !> place: with this stride FFTW's plans need no buffer of their own). A null plan or
   !> buffer is caught by init.
   subroutine plan_split(self)
      class(fft_plan), intent(inout) :: self
      integer(c_int) :: nx, ny, nkx, block
      nx = int(self%nx, c_int)
      ny = int(self%ny, c_int)
      nkx = nx/2 + 1
      self%split = .true.
      self%r2c = fftw_plan_many_dft_r2c(1_c_int, [nx], ny, self%real_buffer, [nx], 1_c_int, nx, self%spectrum, &
         & [nkx], 1_c_int, nkx, FFTW_ESTIMATE)
      self%c2r = fftw_plan_many_dft_c2r(1_c_int, [nx], ny, self%spectrum, [nkx], 1_c_int, nkx, self%real_buffer, &
         & [nx], 1_c_int, nx, ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      block = int(min(column_block, nkx), c_int)
      ! (a buffer per thread, each a multiple of 8*ny*16 bytes from FFTW's aligned start, so
      ! every thread's buffer has the alignment the plans were made for)
      self%column_memory = fftw_alloc_complex(int(block, c_size_t)*int(ny, c_size_t)*int(self%threads, c_size_t))
      if (.not. c_associated(self%column_memory)) then
         call fftw_destroy_plan(self%r2c)
         self%r2c = c_null_ptr
         return
      end if
      call c_f_pointer(self%column_memory, self%column_buffer, [int(block)*self%ny, self%threads])
      ! (each block's plan runs on one thread: the blocks are shared out among the threads)
#ifdef LC_OPENMP
      call fftw_plan_with_nthreads(1_c_int)
#endif
      self%columns_forward = column_plan(block, FFTW_FORWARD)
      self%columns_backward = column_plan(block, FFTW_BACKWARD)
      self%last_block = int(mod(nkx, block))
      if (self%last_block > 0) then
         self%last_forward = column_plan(int(self%last_block, c_int), FFTW_FORWARD)
         self%last_backward = column_plan(int(self%last_block, c_int), FFTW_BACKWARD)
      end if
      if (.not. (c_associated(self%columns_forward) .and. c_associated(self%columns_backward) .and. &
         & (self%last_block == 0 .or. (c_associated(self%last_forward) .and. c_associated(self%last_backward))))) then
         ! (init reports a transform FFTW could not plan)
         call fftw_destroy_plan(self%r2c)
         self%r2c = c_null_ptr
      end if
   contains
      !> `columns` transforms of ny modes, row by row, in place in the first thread's buffer.
      type(c_ptr) function column_plan(columns, sign)
         integer(c_int), intent(in) :: columns, sign
         column_plan = fftw_plan_many_dft(1_c_int, [ny], columns, self%column_buffer(:, 1), [ny], columns, 1_c_int, &
            & self%column_buffer(:, 1), [ny], columns, 1_c_int, sign, FFTW_ESTIMATE)
      end function column_plan
   end subroutine plan_split

   !> Plans for transforming the rows alone (rows_forward_unscaled, rows_backward), on the
   !> same buffers: the spectrum of row j (its nx/2 + 1 coefficients) where the half
   !> spectrum's row j lies.
   subroutine plan_rows(self, error)
      class(fft_plan), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer(c_int) :: nx, ny, nkx
      if (c_associated(self%rows_r2c)) return
      if (self%distributed) then
         call fatal_error(error, 'fft: the rows alone are not planned on a distributed surface', code_internal)
         return
      end if
      nx = int(self%nx, c_int)
      ny = int(self%ny, c_int)
      nkx = nx/2 + 1
#ifdef LC_OPENMP
      call fftw_plan_with_nthreads(int(self%threads, c_int))
#endif
      self%rows_r2c = fftw_plan_many_dft_r2c(1_c_int, [nx], ny, self%real_buffer, [nx], 1_c_int, nx, &
         & self%spectrum, [nkx], 1_c_int, nkx, FFTW_ESTIMATE)
      self%rows_c2r = fftw_plan_many_dft_c2r(1_c_int, [nx], ny, self%spectrum, [nkx], 1_c_int, nkx, &
         & self%real_buffer, [nx], 1_c_int, nx, ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      if (.not. (c_associated(self%rows_r2c) .and. c_associated(self%rows_c2r))) &
         & call fatal_error(error, 'fft: FFTW could not plan the rows of ' // to_string(self%nx) // ' x ' // &
         & to_string(self%ny) // ' points', code_internal)
   end subroutine plan_rows

   !> spectrum <- the bare r2c of every row of real_buffer (after plan_rows).
   subroutine rows_forward_unscaled(self)
      class(fft_plan), intent(inout) :: self
      call fftw_execute_dft_r2c(self%rows_r2c, self%real_buffer, self%spectrum)
   end subroutine rows_forward_unscaled

   !> real_buffer <- the c2r of every row of the spectrum, which is destroyed.
   subroutine rows_backward(self)
      class(fft_plan), intent(inout) :: self
      call fftw_execute_dft_c2r(self%rows_c2r, self%spectrum, self%real_buffer)
   end subroutine rows_backward

   !> spectrum <- Fourier coefficients of real_buffer (r2c / (nx ny)). real_buffer is kept.
   subroutine forward(self)
      class(fft_plan), intent(inout) :: self
      call self%forward_unscaled()
      self%spectrum = self%spectrum*(1.0_wp/(real(self%nx, wp)*self%ny))
   end subroutine forward

   !> spectrum <- n times the Fourier coefficients (the bare r2c): for operators that fold
   !> the 1/n into their multipliers and so save a pass over the spectrum.
   subroutine forward_unscaled(self)
      class(fft_plan), intent(inout) :: self
      integer(i8) :: start, finish
      call system_clock(start)
      if (self%distributed) then
#ifdef LC_MPI
         call rows_to_columns(self)
         call fftw_mpi_execute_r2r(self%to_columns, self%row_values, self%spectrum_values)
         call transform_local_columns(self, self%columns_forward, self%last_forward)
#endif
      else
         call fftw_execute_dft_r2c(self%r2c, self%real_buffer, self%spectrum)
         if (self%split) call transform_columns(self, self%columns_forward, self%last_forward)
      end if
      call system_clock(finish)
      !$omp atomic
      transform_ticks = transform_ticks + (finish - start)
   end subroutine forward_unscaled

   !> real_buffer <- sum_q spectrum(q) exp(i q.x). The spectrum is destroyed.
   subroutine backward(self)
      class(fft_plan), intent(inout) :: self
      integer(i8) :: start, finish
      call system_clock(start)
      if (self%distributed) then
#ifdef LC_MPI
         call transform_local_columns(self, self%columns_backward, self%last_backward)
         call fftw_mpi_execute_r2r(self%to_rows, self%spectrum_values, self%row_values)
         call fftw_execute_dft_c2r(self%c2r, self%row_spectra, self%real_buffer)
#endif
      else
         if (self%split) call transform_columns(self, self%columns_backward, self%last_backward)
         call fftw_execute_dft_c2r(self%c2r, self%spectrum, self%real_buffer)
      end if
      call system_clock(finish)
      !$omp atomic
      transform_ticks = transform_ticks + (finish - start)
   end subroutine backward

   !> Whether `convolve` applies a product between the column transforms of each block
   !> (a two-pass surface on one process, or a distributed surface), so saving the pass
   !> over the spectrum (and on one process a copy of each block out and back in).
   pure logical function fuses_products(self)
      class(fft_plan), intent(in) :: self
      fuses_products = self%split .or. self%distributed
   end function fuses_products

   !> real_buffer <- the c2r of (multiplier * scale) times the bare r2c of real_buffer, for a
   !> plan that fuses_products: forward_unscaled, the product and backward in one, each
   !> block of columns multiplied between its two column transforms in its thread's buffer
   !> (on a distributed surface between the exchanges: see `column_counts`). One multiplier on the half
   !> spectrum (spectrum's layout), real or complex. The same bits as the three steps apart;
   !> the product's time counts as the transforms'. `energy` (a real multiplier): the sum
   !> over the whole spectrum (this rank's columns, on a distributed surface) of
   !> scale * multiplier |c|^2 for the bare r2c's coefficients c, taken in the same pass as
   !> the product (a mode of the half spectrum stands for q and -q, those of the columns
   !> mx = 0 and, for even nx, nx/2 for themselves only). Its blocks' sums are added in
   !> order: the same bits on any number of threads.
   subroutine convolve(self, scale, real_multiplier, complex_multiplier, energy)
      class(fft_plan), intent(inout) :: self
      real(wp), intent(in) :: scale
      real(wp), contiguous, intent(in), optional :: real_multiplier(:)
      complex(wp), contiguous, intent(in), optional :: complex_multiplier(:)
      real(wp), intent(out), optional :: energy
      real(wp), allocatable :: block_energy(:)
      integer(i8) :: start, finish
      integer :: nkx
      call system_clock(start)
      nkx = self%nx/2 + 1
      if (present(energy)) then
         allocate (block_energy((merge(self%nkx_local, nkx, self%distributed) + column_block - 1)/column_block))
         block_energy = 0.0_wp
      end if
      if (self%distributed) then
#ifdef LC_MPI
         call rows_to_columns(self)
         call exchange_blocks(self, .true.)
         call product_in_slab_columns(self, scale, block_energy, real_multiplier, complex_multiplier)
         call exchange_blocks(self, .false.)
         call rows_from_columns(self)
#endif
      else
         call fftw_execute_dft_r2c(self%r2c, self%real_buffer, self%spectrum)
         call product_in_columns(self, scale, block_energy, real_multiplier, complex_multiplier)
         call fftw_execute_dft_c2r(self%c2r, self%spectrum, self%real_buffer)
      end if
      if (present(energy)) energy = sum(block_energy)
      call system_clock(finish)
      !$omp atomic
      transform_ticks = transform_ticks + (finish - start)
   end subroutine convolve

   !> The columns' stage of a product on one process (convolve, convolve_passes): each block
   !> of column_block columns copied into its thread's buffer, forward, the product (with
   !> the block's energy where `block_energy` is allocated: a real multiplier), backward,
   !> and copied back.
   subroutine product_in_columns(self, scale, block_energy, real_multiplier, complex_multiplier)
      class(fft_plan), intent(inout) :: self
      real(wp), intent(in) :: scale
      real(wp), allocatable, intent(inout) :: block_energy(:)
      real(wp), contiguous, intent(in), optional :: real_multiplier(:)
      complex(wp), contiguous, intent(in), optional :: complex_multiplier(:)
      integer :: first, nkx
      nkx = self%nx/2 + 1
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, nkx - self%last_block, column_block
         call product_block(self%columns_forward, self%columns_backward, first, column_block, &
            & self%column_buffer(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_block > 0) call product_block(self%last_forward, self%last_backward, nkx - self%last_block + 1, &
         & self%last_block, self%column_buffer(:, 1))
   contains
      !> The columns first .. first+columns-1: forward, the product, backward, in `buffer`.
      subroutine product_block(forward_plan, backward_plan, first, columns, buffer)
         type(c_ptr), intent(in) :: forward_plan, backward_plan
         integer, intent(in) :: first, columns
         complex(c_double_complex), contiguous, intent(inout) :: buffer(:)
         call copy_columns(self%spectrum, nkx, self%ny, first, columns, buffer, .true.)
         call fftw_execute_dft(forward_plan, buffer, buffer)
         if (allocated(block_energy)) then
            call lc_multiply_columns_real(buffer, columns, self%ny, real_multiplier, nkx, first, scale, &
               & column_weights(first - 1, columns, self%nx), block_energy((first - 1)/column_block + 1))
         else if (present(real_multiplier)) then
            call lc_multiply_columns_real(buffer, columns, self%ny, real_multiplier, nkx, first, scale)
         else
            call lc_multiply_columns_complex(buffer, columns, self%ny, complex_multiplier, nkx, first, scale)
         end if
         call fftw_execute_dft(backward_plan, buffer, buffer)
         call copy_columns(self%spectrum, nkx, self%ny, first, columns, buffer, .false.)
      end subroutine product_block
   end subroutine product_in_columns

   !> The number of blocks of column_block rows of this plan's field (this rank's slab):
   !> convolve_passes' `block` runs from 1 to it.
   pure integer function row_blocks(self)
      class(fft_plan), intent(in) :: self
      row_blocks = (self%ny_local + column_block - 1)/column_block
   end function row_blocks

   !> convolve with a real multiplier and its energy, the solver's passes `work` fused into
   !> its row stages, for a plan that fuses_products: each block of column_block rows is
   !> written by work%before into a thread's buffer and transformed from there while in
   !> the cache, and after the columns' stage each block's c2r lands in that buffer for
   !> work%after. So the product's input and output never cross the memory as fields of
   !> their own: a pass writing the input and one reading the output save two of their
   !> fields' streams each, and the rows' transforms read and write the cache. real_buffer
   !> is not used. The passes' time is not counted as the transforms' (on several threads,
   !> their mean over the threads).
   subroutine convolve_passes(self, scale, multiplier, work, error)
      class(fft_plan), intent(inout) :: self
      real(wp), intent(in) :: scale
      real(wp), contiguous, intent(in) :: multiplier(:)
      class(row_work), intent(inout) :: work
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: block_energy(:)
      real(wp) :: energy
      integer(i8) :: start, finish, passes(0:max(self%threads, 1) - 1)
      integer :: first, nkx, last_first
      call self%plan_passes(error)
      if (allocated(error)) return
      call system_clock(start)
      passes = 0
      nkx = self%nx/2 + 1
      allocate (block_energy((merge(self%nkx_local, nkx, self%distributed) + column_block - 1)/column_block))
      block_energy = 0.0_wp
      last_first = self%ny_local - self%last_rows + 1
      ! the rows' stage: each block's input from the work, then its r2c
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%ny_local - self%last_rows, column_block
         call rows_in(first, column_block, self%rows_real(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_rows > 0) call rows_in(last_first, self%last_rows, self%rows_real(:, 1))
      ! the columns' stage, the product and its energy (as convolve)
      if (self%distributed) then
#ifdef LC_MPI
         call exchange_blocks(self, .true.)
         call product_in_slab_columns(self, scale, block_energy, multiplier)
         call exchange_blocks(self, .false.)
#endif
      else
         call product_in_columns(self, scale, block_energy, multiplier)
      end if
      energy = sum(block_energy)
      if (self%distributed) energy = global_sum(energy)
      call timed_work_between(energy)
      ! the rows' way back: each block's c2r, then its output to the work
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, self%ny_local - self%last_rows, column_block
         call rows_out(self%block_c2r, first, column_block, self%rows_real(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_rows > 0) call rows_out(self%last_block_c2r, last_first, self%last_rows, self%rows_real(:, 1))
      call system_clock(finish)
      !$omp atomic
      transform_ticks = transform_ticks + (finish - start) - sum(passes)/size(passes)
   contains
      !> Block `first`'s input written by the work, then its r2c: into the spectrum's rows
      !> (one process) or through the thread's row buffer into row_spectra (distributed).
      subroutine rows_in(first, rows, values)
         integer, intent(in) :: first, rows
         real(c_double), contiguous, intent(inout) :: values(:)
         integer(i8) :: began, ended
         call system_clock(began)
         call work%before(first, rows, values(1:self%nx*rows), (first - 1)/column_block + 1)
         call system_clock(ended)
         passes(thread_number()) = passes(thread_number()) + (ended - began)
         if (self%distributed) then
#ifdef LC_MPI
            call fftw_execute_dft_r2c(merge(self%r2c, self%last_rows_r2c, rows == column_block), values, &
               & self%row_buffer(:, thread_number() + 1))
            call copy_columns(self%row_spectra, self%ny_local, nkx, first, rows, self%row_buffer(:, thread_number() + 1), &
               & .false.)
#endif
         else
            call fftw_execute_dft_r2c(merge(self%block_r2c, self%last_block_r2c, rows == column_block), values, &
               & self%spectrum((first - 1)*nkx + 1:))
         end if
      end subroutine rows_in

      !> Block `first`'s c2r into the thread's buffer, then its output read by the work.
      subroutine rows_out(plan, first, rows, values)
         type(c_ptr), intent(in) :: plan
         integer, intent(in) :: first, rows
         real(c_double), contiguous, intent(inout) :: values(:)
         integer(i8) :: began, ended
         if (self%distributed) then
#ifdef LC_MPI
            call rows_c2r(self, first, rows, values)
#endif
         else
            call fftw_execute_dft_c2r(plan, self%spectrum((first - 1)*nkx + 1:), values)
         end if
         call system_clock(began)
         call work%after(first, rows, values(1:self%nx*rows), (first - 1)/column_block + 1)
         call system_clock(ended)
         passes(thread_number()) = passes(thread_number()) + (ended - began)
      end subroutine rows_out

      subroutine timed_work_between(energy)
         real(wp), intent(in) :: energy
         integer(i8) :: began, ended
         call system_clock(began)
         call work%between(energy)
         call system_clock(ended)
         passes = passes + (ended - began)
      end subroutine timed_work_between

   end subroutine convolve_passes

   !> Make convolve_passes' buffers and plans, if not made yet (an error where FFTW cannot).
   subroutine plan_passes(self, error)
      class(fft_plan), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      if (passes_planned()) return
      call plan_row_blocks(self)
      if (.not. passes_planned()) call fatal_error(error, 'fft: FFTW could not plan the blocks of rows of ' &
         & // to_string(self%nx) // ' x ' // to_string(self%ny_local) // ' points', code_internal)
   contains
      !> (a distributed surface's c2r of a block is the exchanges' own, from its row buffer)
      logical function passes_planned()
         passes_planned = c_associated(self%rows_real_memory) .and. (self%distributed .or. c_associated(self%block_c2r))
      end function passes_planned
   end subroutine plan_passes

   !> convolve_passes' buffers and plans (see the type): one buffer of column_block rows a
   !> thread and, on one process, the r2c and c2r of a block of rows between it and the
   !> spectrum's rows, the last, shorter block apart (a distributed surface's are the rows'
   !> stage's and the exchanges' own). Left null where FFTW could not plan (convolve_passes
   !> reports it).
   subroutine plan_row_blocks(self)
      class(fft_plan), intent(inout) :: self
      integer(c_int) :: nx, nkx, rows
      nx = int(self%nx, c_int)
      nkx = nx/2 + 1
      rows = int(min(column_block, self%ny_local), c_int)
      self%last_rows = mod(self%ny_local, column_block)
      if (.not. c_associated(self%rows_real_memory)) self%rows_real_memory = &
         & fftw_alloc_real(int(column_block, c_size_t)*int(nx, c_size_t)*int(self%threads, c_size_t))
      if (.not. c_associated(self%rows_real_memory)) return
      call c_f_pointer(self%rows_real_memory, self%rows_real, [column_block*self%nx, self%threads])
      if (self%distributed) return
      ! (each block's plan runs on one thread: the blocks are shared out among the threads)
#ifdef LC_OPENMP
      call fftw_plan_with_nthreads(1_c_int)
#endif
      self%block_r2c = block_plan_r2c(rows)
      if (self%last_rows > 0) self%last_block_r2c = block_plan_r2c(int(self%last_rows, c_int))
      self%block_c2r = block_plan_c2r(rows)
      if (self%last_rows > 0) self%last_block_c2r = block_plan_c2r(int(self%last_rows, c_int))
      if (.not. (c_associated(self%block_r2c) .and. (self%last_rows == 0 .or. c_associated(self%last_block_r2c)) .and. &
         & (self%last_rows == 0 .or. c_associated(self%last_block_c2r)))) then
         if (c_associated(self%block_c2r)) call fftw_destroy_plan(self%block_c2r)
         self%block_c2r = c_null_ptr
      end if
   contains
      type(c_ptr) function block_plan_r2c(count)
         integer(c_int), intent(in) :: count
         block_plan_r2c = fftw_plan_many_dft_r2c(1_c_int, [nx], count, self%rows_real(:, 1), [nx], 1_c_int, nx, &
            & self%spectrum, [nkx], 1_c_int, nkx, FFTW_ESTIMATE)
      end function block_plan_r2c

      type(c_ptr) function block_plan_c2r(count)
         integer(c_int), intent(in) :: count
         block_plan_c2r = fftw_plan_many_dft_c2r(1_c_int, [nx], count, self%spectrum, [nkx], 1_c_int, nkx, &
            & self%rows_real(:, 1), [nx], 1_c_int, nx, ior(FFTW_ESTIMATE, FFTW_DESTROY_INPUT))
      end function block_plan_c2r
   end subroutine plan_row_blocks

   !> The weight of each of the half spectrum's columns mx = first_mx .. first_mx+columns-1
   !> in a sum over the whole spectrum: 2 (q and -q), 1 for mx = 0 and, for even nx, nx/2.
   pure function column_weights(first_mx, columns, nx) result(weights)
      integer, intent(in) :: first_mx, columns, nx
      real(wp) :: weights(columns)
      integer :: c, mx
      do c = 1, columns
         mx = first_mx + c - 1
         weights(c) = merge(1.0_wp, 2.0_wp, mx == 0 .or. 2*mx == nx)
      end do
   end function column_weights

   !> Seconds this process has spent in the grid transforms so far (a solve takes the
   !> difference over its run: contact_result%transform_time).
   real(wp) function transform_seconds()
      integer(i8) :: rate
      call system_clock(count_rate=rate)
      transform_seconds = real(transform_ticks, wp)/real(rate, wp)
   end function transform_seconds

   !> The column pass of a two-pass surface: each block of adjacent columns through its
   !> thread's buffer.
   subroutine transform_columns(self, block_plan, last_plan)
      class(fft_plan), intent(inout) :: self
      type(c_ptr), intent(in) :: block_plan, last_plan
      integer :: first, nkx
      nkx = self%nx/2 + 1
      ! (fftw_execute_dft on new arrays is thread-safe; each block is transformed by the same
      ! plan whatever the thread count, so the bits do not depend on it)
      !$omp parallel do schedule(static) num_threads(self%threads) if(self%threads > 1)
      do first = 1, nkx - self%last_block, column_block
         call transform_block(self, block_plan, first, column_block, self%column_buffer(:, thread_number() + 1))
      end do
      !$omp end parallel do
      if (self%last_block > 0) call transform_block(self, last_plan, nkx - self%last_block + 1, self%last_block, &
         & self%column_buffer(:, 1))
   end subroutine transform_columns

   !> The columns first .. first+columns-1 of the spectrum, transformed by `plan` in `buffer`
   !> (row my's modes at buffer(my*columns + 1 : (my + 1)*columns)).
   subroutine transform_block(self, plan, first, columns, buffer)
      class(fft_plan), intent(inout) :: self
      type(c_ptr), intent(in) :: plan
      integer, intent(in) :: first, columns
      complex(c_double_complex), contiguous, intent(inout) :: buffer(:)
      call copy_columns(self%spectrum, self%nx/2 + 1, self%ny, first, columns, buffer, .true.)
      call fftw_execute_dft(plan, buffer, buffer)
      call copy_columns(self%spectrum, self%nx/2 + 1, self%ny, first, columns, buffer, .false.)
   end subroutine transform_block

   !> block <- the columns first .. first+columns-1 of the spectrum (nkx x ny), or back
   !> (`into_block` false): lc_copy_columns, each row fetched ahead.
   subroutine copy_columns(spectrum, nkx, ny, first, columns, block, into_block)
      integer, intent(in) :: nkx, ny, first, columns
      complex(c_double_complex), contiguous, intent(inout) :: spectrum(:), block(:)
      logical, intent(in) :: into_block
      call lc_copy_columns(spectrum, int(nkx, c_int), int(ny, c_int), int(first, c_int), int(columns, c_int), block, &
         & merge(1_c_int, 0_c_int, into_block))
   end subroutine copy_columns

   subroutine destroy(self)
      class(fft_plan), intent(inout) :: self
      if (c_associated(self%r2c)) call fftw_destroy_plan(self%r2c)
      if (c_associated(self%c2r)) call fftw_destroy_plan(self%c2r)
      if (c_associated(self%columns_forward)) call fftw_destroy_plan(self%columns_forward)
      if (c_associated(self%columns_backward)) call fftw_destroy_plan(self%columns_backward)
      if (c_associated(self%last_forward)) call fftw_destroy_plan(self%last_forward)
      if (c_associated(self%last_backward)) call fftw_destroy_plan(self%last_backward)
      if (c_associated(self%rows_r2c)) call fftw_destroy_plan(self%rows_r2c)
      if (c_associated(self%rows_c2r)) call fftw_destroy_plan(self%rows_c2r)
      self%rows_r2c = c_null_ptr
      self%rows_c2r = c_null_ptr
      self%columns_forward = c_null_ptr
      self%columns_backward = c_null_ptr
      self%last_forward = c_null_ptr
      self%last_backward = c_null_ptr
      self%split = .false.
      self%threads = 1
      self%last_block = 0
      if (c_associated(self%real_memory)) call fftw_free(self%real_memory)
      if (c_associated(self%complex_memory)) call fftw_free(self%complex_memory)
      if (c_associated(self%last_rows_r2c)) call fftw_destroy_plan(self%last_rows_r2c)
      if (c_associated(self%to_columns)) call fftw_destroy_plan(self%to_columns)
      if (c_associated(self%to_rows)) call fftw_destroy_plan(self%to_rows)
      self%last_rows_r2c = c_null_ptr
      self%to_columns = c_null_ptr
      self%to_rows = c_null_ptr
      if (c_associated(self%rows_c2r_block)) call fftw_destroy_plan(self%rows_c2r_block)
      if (c_associated(self%last_rows_c2r_block)) call fftw_destroy_plan(self%last_rows_c2r_block)
      self%rows_c2r_block = c_null_ptr
      self%last_rows_c2r_block = c_null_ptr
      if (allocated(self%column_counts)) deallocate (self%column_counts, self%column_offsets, self%slab_counts, &
         & self%slab_offsets, self%slab_first, self%slab_row_counts)
      self%last_rows = 0
      if (c_associated(self%row_spectra_memory)) call fftw_free(self%row_spectra_memory)
      if (c_associated(self%row_memory)) call fftw_free(self%row_memory)
      self%row_spectra_memory = c_null_ptr
      self%row_memory = c_null_ptr
      self%row_spectra => null()
      self%row_buffer => null()
      self%spectrum_values => null()
      self%row_values => null()
      self%distributed = .false.
      self%y_start = 0
      self%ny_local = 1
      self%x_start = 0
      self%nkx_local = 0
      self%r2c = c_null_ptr
      self%c2r = c_null_ptr
      self%real_memory = c_null_ptr
      self%complex_memory = c_null_ptr
      self%real_buffer => null()
      self%spectrum => null()
      if (c_associated(self%column_memory)) call fftw_free(self%column_memory)
      self%column_memory = c_null_ptr
      self%column_buffer => null()
      if (c_associated(self%block_r2c)) call fftw_destroy_plan(self%block_r2c)
      if (c_associated(self%last_block_r2c)) call fftw_destroy_plan(self%last_block_r2c)
      if (c_associated(self%block_c2r)) call fftw_destroy_plan(self%block_c2r)
      if (c_associated(self%last_block_c2r)) call fftw_destroy_plan(self%last_block_c2r)
      self%block_r2c = c_null_ptr
      self%last_block_r2c = c_null_ptr
      self%block_c2r = c_null_ptr
      self%last_block_c2r = c_null_ptr
      if (c_associated(self%rows_real_memory)) call fftw_free(self%rows_real_memory)
      self%rows_real_memory = c_null_ptr
      self%rows_real => null()
      self%n = 0
      self%nk = 0
      self%nx = 0
      self%ny = 1
   end subroutine destroy

   subroutine finalize(self)
      type(fft_plan), intent(inout) :: self
      call self%destroy()
   end subroutine finalize

end module lc_fft_plans
