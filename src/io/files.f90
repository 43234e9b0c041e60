!> File-system questions the Fortran runtime cannot answer (C helpers in files.c): the kind
!> of file a path names (inquire cannot tell a FIFO, which blocks a read until a writer
!> comes, from a regular file), fsync of a file or a directory, disk space reserved for a
!> file, the space left on a file system, whether two paths name one file. Used for "a result file is complete or absent" (docs/output.md) and for refusing
!> input files that are not regular files.
module lc_io_files
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_long_long, c_null_char
   use lc_base_kinds, only: i8
   implicit none (type, external)
   private
   public :: path_kind, kind_name, sync_path, reserve_space, free_bytes, system_error_text, same_file
   public :: kind_regular, kind_directory, kind_fifo, kind_device, kind_socket, kind_other, kind_missing, &
      & kind_loop, kind_unknown

   !> Kinds of path_kind: the first six as files.c returns them, then the failures of stat().
   integer, parameter :: kind_regular = 0, kind_directory = 1, kind_fifo = 2, kind_device = 3, kind_socket = 4, &
      & kind_other = 5, kind_missing = 6, kind_loop = 7, kind_unknown = 8
   !> errno values of Linux that path_kind tells apart
   integer(c_int), parameter :: enoent = 2_c_int, enotdir = 20_c_int, eloop = 40_c_int

   interface
      integer(c_int) function lc_file_kind(path, kind) bind(C, name='lc_file_kind')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), intent(out) :: kind
      end function lc_file_kind
      integer(c_int) function lc_same_file(a, b, same) bind(C, name='lc_same_file')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: a(*), b(*)
         integer(c_int), intent(out) :: same
      end function lc_same_file
      integer(c_int) function lc_sync_path(path, directory) bind(C, name='lc_sync_path')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value, intent(in) :: directory
      end function lc_sync_path
      integer(c_int) function lc_reserve_space(path, bytes) bind(C, name='lc_reserve_space')
         import :: c_int, c_char, c_long_long
         character(kind=c_char), intent(in) :: path(*)
         integer(c_long_long), value, intent(in) :: bytes
      end function lc_reserve_space
      integer(c_int) function lc_free_bytes(path, bytes) bind(C, name='lc_free_bytes')
         import :: c_int, c_char, c_long_long
         character(kind=c_char), intent(in) :: path(*)
         integer(c_long_long), intent(out) :: bytes
      end function lc_free_bytes
      subroutine lc_error_text(code, text, length) bind(C, name='lc_error_text')
         import :: c_int, c_char
         integer(c_int), value, intent(in) :: code
         character(kind=c_char), intent(out) :: text(*)
         integer(c_int), value, intent(in) :: length
      end subroutine lc_error_text
   end interface

contains

   !> What `path` names, following symbolic links: one of the kind_* parameters; `detail`
   !> is the system's word when stat() failed for another reason than those named
   !> (kind_unknown, e.g. 'Permission denied').
   subroutine path_kind(path, kind, detail)
      !> the path, as given
      character(len=*), intent(in) :: path
      !> kind_regular, kind_directory, ..., kind_missing, kind_loop or kind_unknown
      integer, intent(out) :: kind
      !> why stat() failed (kind_unknown), else ''
      character(len=:), allocatable, intent(out) :: detail
      integer(c_int) :: code, found
      detail = ''
      found = int(kind_other, c_int)
      code = lc_file_kind(path // c_null_char, found)
      select case (code)
      case (0)
         kind = int(found)
      case (enoent, enotdir)
         kind = kind_missing
      case (eloop)
         kind = kind_loop
      case default
         kind = kind_unknown
         detail = system_error_text(code)
      end select
   end subroutine path_kind

   !> Whether two paths name one existing file (through symbolic links, `..` or hard links);
   !> false when either is not there.
   logical function same_file(a, b)
      !> the paths, as given
      character(len=*), intent(in) :: a, b
      integer(c_int) :: same
      same_file = .false.
      if (lc_same_file(a // c_null_char, b // c_null_char, same) == 0) same_file = same /= 0
   end function same_file

   !> A kind in words, for messages ('a FIFO (named pipe)', 'a directory', ...).
   pure function kind_name(kind) result(name)
      !> one of the kind_* parameters
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      select case (kind)
      case (kind_regular)
         name = 'a regular file'
      case (kind_directory)
         name = 'a directory'
      case (kind_fifo)
         name = 'a FIFO (named pipe)'
      case (kind_device)
         name = 'a device'
      case (kind_socket)
         name = 'a socket'
      case (kind_missing)
         name = 'not found'
      case (kind_loop)
         name = 'a loop of symbolic links'
      case default
         name = 'not a regular file'
      end select
   end function kind_name

   !> fsync a file (directory = .false.) or a directory: on return with ok its contents
   !> (a directory's: its entries) are on the disk; otherwise `reason` says why not.
   subroutine sync_path(path, directory, ok, reason)
      !> the file or directory
      character(len=*), intent(in) :: path
      !> whether path is a directory
      logical, intent(in) :: directory
      !> whether the sync succeeded
      logical, intent(out) :: ok
      !> the system's word on a failure ('No space left on device'), else ''
      character(len=:), allocatable, intent(out) :: reason
      integer(c_int) :: code
      code = lc_sync_path(path // c_null_char, merge(1_c_int, 0_c_int, directory))
      ok = code == 0
      reason = ''
      if (.not. ok) reason = system_error_text(code)
   end subroutine sync_path

   !> Allocate the disk blocks of the first `bytes` bytes of an existing file (extending it
   !> to that size if shorter): writes into them cannot then fail for want of space.
   subroutine reserve_space(path, bytes, ok, reason)
      !> the file
      character(len=*), intent(in) :: path
      !> bytes from the start of the file
      integer(i8), intent(in) :: bytes
      !> whether the space is reserved
      logical, intent(out) :: ok
      !> the system's word on a failure ('No space left on device'), else ''
      character(len=:), allocatable, intent(out) :: reason
      integer(c_int) :: code
      code = lc_reserve_space(path // c_null_char, int(bytes, c_long_long))
      ok = code == 0
      reason = ''
      if (.not. ok) reason = system_error_text(code)
   end subroutine reserve_space

   !> Bytes still free for a writer on the file system of `path` (-1: unknown).
   function free_bytes(path) result(bytes)
      !> a file or directory on that file system
      character(len=*), intent(in) :: path
      integer(i8) :: bytes
      integer(c_long_long) :: found
      bytes = -1_i8
      if (lc_free_bytes(path // c_null_char, found) == 0) bytes = int(found, i8)
   end function free_bytes

   !> The C library's text for errno `code` ('No space left on device').
   function system_error_text(code) result(text)
      !> an errno value
      integer(c_int), intent(in) :: code
      character(len=:), allocatable :: text
      character(kind=c_char, len=200) :: buffer
      integer :: length
      buffer = ''
      call lc_error_text(code, buffer, len(buffer, c_int))
      length = index(buffer, c_null_char) - 1
      if (length < 0) length = len_trim(buffer)
      text = buffer(:length)
   end function system_error_text
end module lc_io_files
