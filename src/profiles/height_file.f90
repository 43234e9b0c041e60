!> Heights read from a file (&profile kind = 'file'): one reader for line profiles and
!> areal surfaces. It returns the file's array as it is, height(nx, ny) with x fastest and
!> (nx, ny) the file's own sizes; lc_profiles_measured fits it to the scene's grid. The
!> format follows the file name's extension:
!>
!> - '.h5', '.hdf5': HDF5 file, `dataset` a 1D or 2D floating-point dataset; a 2D dataset
!>   of shape [ny, nx] in C order (what h5py writes for a numpy array height[ny, nx]; the
!>   HDF5 Fortran API reports it as (nx, ny)), a 1D dataset of n values as (n, 1);
!> - '.npy': NumPy format 1.0, 2.0 or 3.0 (the header is parsed here), dtype '<f8'
!>   (little-endian float64), C order, shape (ny, nx) or (n,);
!> - anything else: text, ny lines of nx whitespace-separated numbers (one row y = const
!>   per line, x growing along the line, every line as long as the first); blank lines and
!>   text after '#' are skipped, as numpy.loadtxt does.
!>
!> A line profile is a file of one row or one column: a 1D dataset or array, a 2D one of
!> shape (1, n) or (n, 1), a text file of one line or of one number per line (what
!> numpy.savetxt writes for a 1D array). The file must be a regular file (not a FIFO, a
!> directory or a device). Every height must be finite. Errors name
!> &profile file and the value found, with code code_io when the file cannot be opened or
!> read and code_input when its content is not heights (an '.h5' file that is not HDF5 too).
module lc_profiles_height_file
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: iso_fortran_env, only: int8, int16, int32, iostat_end
   use hdf5, only: hid_t, hsize_t, h5open_f, h5close_f, h5eset_auto_f, h5fis_hdf5_f, h5fopen_f, h5fclose_f, H5F_ACC_RDONLY_F, &
      & H5F_CLOSE_STRONG_F, h5pcreate_f, h5pclose_f, h5pset_fclose_degree_f, H5P_FILE_ACCESS_F, h5dopen_f, h5dclose_f, &
      & h5dread_f, h5dget_space_f, h5dget_type_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
      & h5sget_simple_extent_dims_f, h5tget_class_f, h5tclose_f, H5T_NATIVE_DOUBLE, H5T_FLOAT_F, &
      & h5screate_simple_f, h5sselect_hyperslab_f, H5S_SELECT_SET_F, H5P_DEFAULT_F
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, code_input, code_io, code_internal
   use lc_base_strings, only: to_string, lower_case
   use lc_io_files, only: path_kind, kind_name, kind_regular, kind_missing, kind_unknown
   use lc_base_slab, only: row_slab, slab_of, empty_rank
   implicit none (type, external)
   private
   public :: read_height_file, named, shape_text
   ! for the reader of one file by several processes (lc_profiles_height_slabs)
   public :: check_height_path, read_hdf5, check_heights, is_hdf5_name, too_few_rows

   !> The largest rank HDF5 allows (H5S_MAX_RANK).
   integer, parameter :: max_rank = 32
   !> The most heights a file may hold (more than the largest grid, 2**28 points, so that a
   !> finer measurement can still be resampled onto it).
   integer(i8), parameter :: max_heights = 2_i8**30

contains

   !> Heights of `filename` (format from its extension, see the module header) as
   !> height(nx, ny), x fastest, with the file's sizes.
   subroutine read_height_file(filename, dataset, height, error)
      !> File name (&profile file)
      character(len=*), intent(in) :: filename
      !> Dataset inside an HDF5 file (&profile dataset), e.g. /profile/height
      character(len=*), intent(in) :: dataset
      !> Heights (L): (nx, ny) of a surface, (n, 1) of a 1D array
      real(wp), allocatable, intent(out) :: height(:, :)
      type(error_type), allocatable, intent(out) :: error

      call check_height_path(filename, error)
      if (allocated(error)) return
      if (is_hdf5_name(filename)) then
         call read_hdf5(filename, dataset, height, error)
      else if (ends_with(filename, '.npy')) then
         call read_npy(filename, height, error)
      else
         call read_text(filename, height, error)
      end if
      if (.not. allocated(error) .and. .not. allocated(height)) &
         & call fatal_error(error, named(filename) // ': no heights read', code_internal)
      if (allocated(error)) then
         if (allocated(height)) deallocate (height)
         return
      end if
      call check_heights(filename, height, 0, error)
      if (allocated(error)) deallocate (height)
   end subroutine read_height_file

   !> A file that is not there, or not a regular file (a FIFO would block the read until a
   !> writer comes, a directory or a device holds no heights), is bad input (exit 2), from
   !> every route; one that is there but cannot be examined is an I/O failure (4).
   subroutine check_height_path(filename, error)
      character(len=*), intent(in) :: filename
      type(error_type), allocatable, intent(out) :: error
      integer :: kind
      character(len=:), allocatable :: detail
      call path_kind(filename, kind, detail)
      if (kind == kind_missing) then
         call fatal_error(error, named(filename) // ' is not found; allowed: an existing file (HDF5, .npy or ' // &
            & 'text), relative to the working directory', code_input)
      else if (kind == kind_unknown) then
         call fatal_error(error, named(filename) // ' cannot be examined: ' // detail, code_io)
      else if (kind /= kind_regular) then
         call fatal_error(error, named(filename) // ' is ' // kind_name(kind) // '; allowed: a regular file ' // &
            & '(HDF5, .npy or text)', code_input)
      end if
   end subroutine check_height_path

   !> Whether the file name says HDF5 ('.h5', '.hdf5').
   pure logical function is_hdf5_name(filename)
      character(len=*), intent(in) :: filename
      is_hdf5_name = ends_with(filename, '.h5') .or. ends_with(filename, '.hdf5')
   end function is_hdf5_name

   !> Heights read are some, and all finite; `y_start` rows of the file come before those of
   !> `height` (for the row named in the message).
   subroutine check_heights(filename, height, y_start, error)
      character(len=*), intent(in) :: filename
      real(wp), intent(in) :: height(:, :)
      integer, intent(in) :: y_start
      type(error_type), allocatable, intent(out) :: error
      integer :: ix, iy
      if (size(height) == 0) then
         call fatal_error(error, named(filename) // ' holds no heights; allowed: one or more rows of heights', &
            & code_input)
         return
      end if
      do iy = 1, size(height, 2)
         do ix = 1, size(height, 1)
            if (.not. ieee_is_finite(height(ix, iy))) then
               call fatal_error(error, named(filename) // ' holds the height ' // to_string(height(ix, iy)) // &
                  & ' at (ix, iy) = (' // to_string(ix - 1) // ', ' // to_string(y_start + iy - 1) // &
                  & '), 0-based; allowed: finite heights', code_input)
               return
            end if
         end do
      end do
   end subroutine check_heights

   !> The refusal of a file whose ny rows leave some of `ranks` processes without a row.
   pure function too_few_rows(filename, ny, ranks) result(message)
      character(len=*), intent(in) :: filename
      integer, intent(in) :: ny, ranks
      character(len=:), allocatable :: message
      message = named(filename) // ' holds ' // to_string(ny) // ' rows, which leave some of the ' // &
         & to_string(ranks) // ' MPI ranks without a row (blocks of ceiling(ny/ranks) rows); allowed: ' // &
         & 'a file whose rows fill every rank'
   end function too_few_rows

   !> "&profile: file = '<filename>'", the start of every message.
   pure function named(filename) result(s)
      character(len=*), intent(in) :: filename
      character(len=:), allocatable :: s
      s = "&profile: file = '" // filename // "'"
   end function named

   pure logical function ends_with(text, tail)
      character(len=*), intent(in) :: text, tail
      integer :: n
      n = len_trim(text)
      ends_with = .false.
      if (n >= len(tail)) ends_with = lower_case(text(n - len(tail) + 1:n)) == tail
   end function ends_with

   ! ---------------------------------------------------------------------------------------
   ! HDF5

   !> The heights of an HDF5 file's dataset: all of them, or, with `ranks` and `rank`, the
   !> rows of that rank (lc_base_slab: height(nx, ny_local)), read through the file access
   !> list `access` and the transfer list `xfer` (a collective MPI-IO read by several
   !> processes: lc_profiles_height_slabs). `sizes` are the dataset's (nx, ny). A dataset
   !> whose rows leave a rank without one is refused (on every rank alike, before any read).
   subroutine read_hdf5(filename, dataset, height, error, sizes, access, xfer, ranks, rank)
      character(len=*), intent(in) :: filename, dataset
      real(wp), allocatable, intent(out) :: height(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer(hsize_t), intent(out), optional :: sizes(2)
      !> a file access list made by the caller (closed by the caller)
      integer(hid_t), intent(in), optional :: access
      !> a transfer list made by the caller
      integer(hid_t), intent(in), optional :: xfer
      !> the processes sharing the rows, and this one's number (0-based)
      integer, intent(in), optional :: ranks, rank
      integer(hid_t) :: fapl, file, dset, space, dtype, memory, transfer
      integer(hsize_t) :: dims(max_rank), maxdims(max_rank), held(2)
      integer :: hdferr, ignore, dataset_rank, class, i, y_start, ny_local
      type(row_slab) :: slab
      character(len=:), allocatable :: found
      logical :: is_hdf5

      call h5open_f(hdferr)
      call h5eset_auto_f(0, ignore)
      if (present(access)) then
         fapl = access
      else
         call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, ignore)
         call h5pset_fclose_degree_f(fapl, H5F_CLOSE_STRONG_F, ignore)
      end if
      transfer = H5P_DEFAULT_F
      if (present(xfer)) transfer = xfer
      if (present(sizes)) sizes = 0
      reading: block
         if (hdferr /= 0) then
            call fatal_error(error, named(filename) // ': cannot initialise HDF5 to read it', code_internal)
            exit reading
         end if
         ! a file without the HDF5 signature holds no heights (bad input, as a text file with
         ! a word for a number); one that HDF5 cannot even look into is an I/O failure
         call h5fis_hdf5_f(filename, is_hdf5, hdferr)
         if (hdferr == 0 .and. .not. is_hdf5) then
            call fatal_error(error, named(filename) // ' is not an HDF5 file (no HDF5 signature); allowed: an ' // &
               & 'HDF5 file (.h5, .hdf5), a .npy file or a text file of heights', code_input)
            exit reading
         end if
         call h5fopen_f(filename, H5F_ACC_RDONLY_F, file, hdferr, access_prp=fapl)
         if (hdferr /= 0) then
            call fatal_error(error, named(filename) // ' cannot be opened as HDF5; allowed: an existing, ' // &
               & 'readable HDF5 file', code_io)
            exit reading
         end if
         call h5dopen_f(file, dataset, dset, hdferr)
         if (hdferr /= 0) then
            call fatal_error(error, named(filename) // " has no dataset '" // dataset // "' (&profile dataset); " // &
               & 'allowed: the path of a 1D or 2D floating-point dataset in the file', code_input)
         else
            call h5dget_space_f(dset, space, hdferr)
            call h5sget_simple_extent_ndims_f(space, dataset_rank, ignore)
            dims = 0
            if (dataset_rank >= 1 .and. dataset_rank <= max_rank) &
               & call h5sget_simple_extent_dims_f(space, dims, maxdims, ignore)
            call h5sclose_f(space, ignore)
            call h5dget_type_f(dset, dtype, ignore)
            call h5tget_class_f(dtype, class, ignore)
            call h5tclose_f(dtype, ignore)
            if (class /= H5T_FLOAT_F .or. dataset_rank < 1 .or. dataset_rank > 2) then
               ! The Fortran API lists the dimensions fastest first; print them in C order.
               found = '('
               do i = dataset_rank, 1, -1
                  found = found // to_string(int(dims(i), i8))
                  if (i > 1) found = found // ', '
               end do
               found = found // ')'
               if (class /= H5T_FLOAT_F) found = found // ' of numbers that are not floating point'
               call fatal_error(error, named(filename) // ", dataset '" // dataset // "' holds shape " // found // &
                  & '; allowed: a 1D or 2D floating-point dataset (C order, as h5py writes height[ny, nx])', &
                  & code_input)
            else
               if (dataset_rank == 1) dims(2) = 1
               if (present(sizes)) sizes = dims(1:2)
               y_start = 0
               ny_local = int(dims(2))
               if (present(ranks) .and. present(rank)) then
                  slab = slab_of(int(dims(1)), int(dims(2)), ranks, rank)
                  y_start = slab%y_start
                  ny_local = slab%ny_local
                  if (empty_rank(int(dims(2)), ranks)) then
                     call fatal_error(error, too_few_rows(filename, int(dims(2)), ranks), code_input)
                  end if
               end if
            end if
            if (.not. allocated(error)) then
               held = [dims(1), int(ny_local, hsize_t)]
               allocate (height(held(1), held(2)))
               call h5dget_space_f(dset, space, hdferr)
               memory = space
               if (hdferr == 0 .and. held(2) /= dims(2)) then
                  ! the rows y_start+1 .. y_start+ny_local of the file's [ny, nx] (a 1D dataset has one)
                  call h5sselect_hyperslab_f(space, H5S_SELECT_SET_F, [0_hsize_t, int(y_start, hsize_t)], held, &
                     & hdferr)
                  if (hdferr == 0) call h5screate_simple_f(2, held, memory, hdferr)
               end if
               if (hdferr == 0) call h5dread_f(dset, H5T_NATIVE_DOUBLE, height, held, hdferr, mem_space_id=memory, &
                  & file_space_id=space, xfer_prp=transfer)
               if (memory /= space) call h5sclose_f(memory, ignore)
               call h5sclose_f(space, ignore)
               if (hdferr /= 0) call fatal_error(error, named(filename) // ": cannot read dataset '" // dataset // "'", &
                  & code_io)
            end if
            call h5dclose_f(dset, ignore)
         end if
         call h5fclose_f(file, ignore)
      end block reading
      if (.not. present(access)) call h5pclose_f(fapl, ignore)
      call h5close_f(ignore)
   end subroutine read_hdf5

   ! ---------------------------------------------------------------------------------------
   ! NumPy .npy: magic '\x93NUMPY', major and minor version bytes, the header length
   ! (2 bytes little-endian in version 1, 4 bytes in versions 2 and 3), the header (a Python
   ! dict literal: {'descr': '<f8', 'fortran_order': False, 'shape': (ny, nx), }, padded
   ! with spaces and a newline), then the data.

   subroutine read_npy(filename, height, error)
      character(len=*), intent(in) :: filename
      real(wp), allocatable, intent(out) :: height(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=6) :: magic
      integer(int8) :: version(2)
      integer(int16) :: length16
      integer(int32) :: length32
      integer :: unit, ios, header_length, data_start
      integer(i8) :: shape(max_rank)
      integer :: rank
      character(len=256) :: message
      character(len=:), allocatable :: header, descr, order, found

      if (.not. little_endian()) then
         call fatal_error(error, named(filename) // ': reading .npy files needs a little-endian machine', code_internal)
         return
      end if
      open (newunit=unit, file=filename, access='stream', form='unformatted', status='old', action='read', &
         & iostat=ios, iomsg=message)
      if (ios /= 0) then
         call fatal_error(error, named(filename) // ' cannot be opened (' // trim(message) // &
            & '); allowed: an existing, readable .npy file', code_io)
         return
      end if
      parsing: block
         read (unit, iostat=ios) magic, version
         ! the first byte is 0x93 (outside ASCII, so char, not achar)
         if (ios /= 0 .or. magic /= char(147) // 'NUMPY') then
            call fatal_error(error, named(filename) // ' does not start with the .npy magic string; allowed: a file ' // &
               & 'written by numpy.save', code_input)
            exit parsing
         end if
         select case (version(1))
         case (1)
            read (unit, iostat=ios) length16
            header_length = int(length16)
            ! the two bytes are unsigned
            if (header_length < 0) header_length = header_length + 65536
            data_start = 11 + header_length
         case (2, 3)
            read (unit, iostat=ios) length32
            header_length = int(length32)
            data_start = 13 + header_length
         case default
            call fatal_error(error, named(filename) // ' has .npy format version ' // to_string(int(version(1))) // &
               & '; allowed: 1, 2 or 3', code_input)
            exit parsing
         end select
         if (ios == 0 .and. header_length > 0) then
            allocate (character(len=header_length) :: header)
            read (unit, iostat=ios) header
         end if
         if (ios /= 0 .or. header_length <= 0) then
            call fatal_error(error, named(filename) // ' has a truncated .npy header; allowed: a file written by ' // &
               & 'numpy.save', code_input)
            exit parsing
         end if

         descr = quoted_value(header, 'descr')
         order = word_value(header, 'fortran_order')
         call shape_value(header, shape, rank)
         if (descr /= '<f8') then
            call fatal_error(error, named(filename) // " holds dtype '" // descr // "'; allowed: '<f8' " // &
               & "(little-endian float64: save numpy.asarray(height, dtype='<f8'))", code_input)
         else if (order /= 'False') then
            call fatal_error(error, named(filename) // ' holds fortran_order = ' // order // '; allowed: False ' // &
               & '(C order: save numpy.ascontiguousarray(height))', code_input)
         else if (rank < 1 .or. rank > 2) then
            if (rank < 0) then
               found = 'that cannot be parsed'
            else
               found = shape_text(shape(1:rank))
            end if
            call fatal_error(error, named(filename) // ' holds shape ' // found // '; allowed: a 1D or 2D array, ' // &
               & '(ny, nx) or (n,)', code_input)
         end if
         if (allocated(error)) exit parsing
         if (product(shape(1:rank)) > max_heights) then
            call fatal_error(error, named(filename) // ' holds shape ' // shape_text(shape(1:rank)) // &
               & '; allowed: at most 2**30 heights', code_input)
            exit parsing
         end if
         ! C order (ny, nx) is x fastest: height(nx, ny); a 1D array (n,) is (n, 1)
         if (rank == 1) then
            allocate (height(shape(1), 1))
         else
            allocate (height(shape(2), shape(1)))
         end if
         read (unit, pos=data_start, iostat=ios, iomsg=message) height
         if (ios == iostat_end) then
            call fatal_error(error, named(filename) // ' ends before its ' // to_string(size(height, kind=i8)) // &
               & ' heights; allowed: a complete .npy file of shape ' // shape_text(shape(1:rank)), code_input)
         else if (ios /= 0) then
            call fatal_error(error, named(filename) // ': cannot read the heights (' // trim(message) // ')', code_io)
         end if
      end block parsing
      close (unit)
   end subroutine read_npy

   !> True when the least significant byte comes first (the byte order of '<f8').
   pure logical function little_endian()
      little_endian = all(transfer(1_int16, [0_int8, 0_int8]) == [1_int8, 0_int8])
   end function little_endian

   !> Text after `key` and the next ':' in a header, left-adjusted ('' if the key is absent).
   pure function after_key(header, key) result(s)
      character(len=*), intent(in) :: header, key
      character(len=:), allocatable :: s
      integer :: at, colon
      s = ''
      at = index(header, "'" // key // "'")
      if (at == 0) at = index(header, '"' // key // '"')
      if (at == 0) return
      colon = index(header(at:), ':')
      if (colon == 0) return
      s = trim(adjustl(header(at + colon:)))
   end function after_key

   !> The quoted string value of `key` ('' if absent or unquoted).
   pure function quoted_value(header, key) result(s)
      character(len=*), intent(in) :: header, key
      character(len=:), allocatable :: s, rest
      integer :: close_quote
      rest = after_key(header, key)
      s = ''
      if (len(rest) < 2) return
      if (rest(1:1) /= "'" .and. rest(1:1) /= '"') return
      close_quote = index(rest(2:), rest(1:1))
      if (close_quote > 0) s = rest(2:close_quote)
   end function quoted_value

   !> The bare word value of `key` (up to ',' or '}'), e.g. True or False.
   pure function word_value(header, key) result(s)
      character(len=*), intent(in) :: header, key
      character(len=:), allocatable :: s, rest
      integer :: word_end
      rest = after_key(header, key)
      word_end = scan(rest, ',}')
      if (word_end == 0) word_end = len(rest) + 1
      s = trim(rest(1:word_end - 1))
   end function word_value

   !> The shape tuple of the header; rank = -1 when it cannot be parsed.
   pure subroutine shape_value(header, shape, rank)
      character(len=*), intent(in) :: header
      integer(i8), intent(out) :: shape(max_rank)
      integer, intent(out) :: rank
      character(len=:), allocatable :: rest, item
      integer :: close_paren, start, comma, ios

      shape = 0
      rank = -1
      rest = after_key(header, 'shape')
      if (len(rest) < 2) return
      if (rest(1:1) /= '(') return
      close_paren = index(rest, ')')
      if (close_paren == 0) return
      rest = rest(2:close_paren - 1) // ','
      rank = 0
      start = 1
      do while (start <= len(rest))
         comma = index(rest(start:), ',') + start - 1
         item = trim(adjustl(rest(start:comma - 1)))
         start = comma + 1
         if (len(item) == 0) cycle   ! the trailing comma of a 1-tuple
         if (rank == max_rank .or. verify(item, '0123456789') /= 0) then
            rank = -1
            return
         end if
         rank = rank + 1
         read (item, *, iostat=ios) shape(rank)
         if (ios /= 0) then
            rank = -1
            return
         end if
      end do
   end subroutine shape_value

   pure function shape_text(shape) result(s)
      integer(i8), intent(in) :: shape(:)
      character(len=:), allocatable :: s
      integer :: i
      s = '('
      do i = 1, size(shape)
         s = s // to_string(shape(i))
         if (i < size(shape) .or. size(shape) == 1) s = s // ','
         if (i < size(shape)) s = s // ' '
      end do
      s = s // ')'
   end function shape_text

   ! ---------------------------------------------------------------------------------------
   ! Text

   subroutine read_text(filename, height, error)
      character(len=*), intent(in) :: filename
      real(wp), allocatable, intent(out) :: height(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: line, token
      character(len=256) :: message
      real(wp), allocatable :: values(:), grown(:)
      integer(i8) :: stored
      integer :: unit, ios, line_number, rows, columns, count, start, finish, hash
      real(wp) :: value

      open (newunit=unit, file=filename, status='old', action='read', form='formatted', iostat=ios, iomsg=message)
      if (ios /= 0) then
         call fatal_error(error, named(filename) // ' cannot be opened (' // trim(message) // &
            & '); allowed: an existing, readable text file', code_io)
         return
      end if
      allocate (values(4096))
      stored = 0
      line_number = 0
      rows = 0
      columns = 0
      lines: do
         call read_line(unit, line, ios)
         if (ios == iostat_end) exit lines
         if (ios /= 0) then
            call fatal_error(error, named(filename) // ': cannot read line ' // to_string(line_number + 1), code_io)
            exit lines
         end if
         line_number = line_number + 1
         hash = index(line, '#')
         if (hash > 0) line = line(1:hash - 1)
         line = tabs_to_spaces(line)
         if (len_trim(line) == 0) cycle lines
         rows = rows + 1
         count = 0
         finish = 0
         tokens: do
            start = verify(line(finish + 1:), ' ') + finish
            if (start == finish) exit tokens
            finish = index(line(start:), ' ') + start - 2
            if (finish < start) finish = len(line)
            token = line(start:finish)
            count = count + 1
            ! list-directed input would take ',', '/' and 'r*' as separators and repeats
            ios = 1
            if (scan(token, ",/*;'""()") == 0) read (token, *, iostat=ios) value
            if (ios /= 0) then
               call fatal_error(error, named(filename) // ', line ' // to_string(line_number) // ": '" // token // &
                  & "' is not a number; allowed: whitespace-separated numbers", code_input)
               exit lines
            end if
            if (stored == size(values, kind=i8)) then
               if (stored >= max_heights) then
                  call fatal_error(error, named(filename) // ' holds more than 2**30 heights; allowed: at most ' // &
                     & '2**30', code_input)
                  exit lines
               end if
               allocate (grown(2*stored))
               grown(1:stored) = values
               call move_alloc(grown, values)
            end if
            stored = stored + 1
            values(stored) = value
         end do tokens
         if (rows == 1) columns = count
         if (count /= columns) then
            call fatal_error(error, named(filename) // ', line ' // to_string(line_number) // ' holds ' // &
               & to_string(count) // ' numbers; allowed: ' // to_string(columns) // ' per line, as on the first ' // &
               & 'line of numbers (ny lines of nx numbers)', code_input)
            exit lines
         end if
      end do lines
      close (unit)
      if (allocated(error)) return
      ! one row y = const per line: x fastest, as stored
      height = reshape(values(1:stored), [columns, rows])
   end subroutine read_text

   !> One whole line of a formatted file, of any length.
   subroutine read_line(unit, line, ios)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: line
      integer, intent(out) :: ios
      character(len=4096) :: chunk
      integer :: got

      line = ''
      do
         read (unit, '(a)', advance='no', iostat=ios, size=got) chunk
         line = line // chunk(1:got)
         if (ios /= 0) exit
      end do
      ! the end of a record ends the line; the end of the file ends it only if it was empty
      if (is_iostat_eor(ios)) ios = 0
      if (ios == iostat_end .and. len(line) > 0) ios = 0
   end subroutine read_line

   pure function tabs_to_spaces(text) result(s)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: s
      integer :: i
      s = text
      do i = 1, len(s)
         if (s(i:i) == achar(9) .or. s(i:i) == achar(13)) s(i:i) = ' '
      end do
   end function tabs_to_spaces
end module lc_profiles_height_file
