!> Namelist input: a text file of up to eight optional groups (&scene, &layer, &material,
!> &friction, &profile, &loading, &solver, &output) -> `scene_type`, and back (`write_scene_namelist`).
!>
!> Defaults live only in `scene_type`: each group is read into local variables that start
!> from the scene's current (default) values. The group readers, the writer and the lists
!> of variables in messages are generated from the scene schema
!> (driver/layercontact/scene_schema.py, tools/scene_codegen.py) as include files; the
!> hooks of the grid's variables and of the Prony terms are here. A Fortran namelist read
!> silently skips groups it does not know, so the text is pre-scanned for `&name` tokens
!> first; unknown or repeated groups are errors that name the line. The assignments of each
!> group are listed from the text too (the namelist read keeps the last of two silently): a
!> variable given twice, or under both of its names (`period` and `period_x`), is refused,
!> and so is a variable of surfaces only (`period_y`, `ny`, ...) in a line scene.
module lc_io_namelist
   use, intrinsic :: iso_fortran_env, only: iostat_end
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use lc_base_kinds, only: wp, i8
   use lc_base_errors, only: error_type, fatal_error, input_error, code_input, code_io
   use lc_base_strings, only: to_string, lower_case
   use lc_scene, only: scene_type, check_scene, not_set, max_string
   use lc_greens_viscoelastic, only: max_prony_terms
   use lc_io_files, only: path_kind, kind_name, kind_regular, kind_missing, kind_unknown
   implicit none (type, external)
   private
   public :: read_scene, read_scene_text, write_scene_namelist, read_prony_file, default_scene

   ! n_groups, group_names, group_variables and the variables of each type (for messages),
   ! from the scene schema
   include 'scene_groups.inc'

   character(len=*), parameter :: newline = new_line('a')
   !> The status of a string variable too long for the scene (not an iostat value: those
   !> are positive for errors, -1 and -2 for the ends of file and record)
   integer, parameter :: stat_too_long = -4242
   !> Marks array entries a namelist did not set (any real a user could type is a value,
   !> so that a wrong sign is reported rather than taken for "not given").
   real(wp), parameter :: unset_entry = -huge(1.0_wp)
   !> The same for grid sizes.
   integer, parameter :: unset_count = -huge(1)
   !> Characters kept of a variable's name (with its index) and of its value, for messages.
   integer, parameter :: name_width = 64
   !> Grid points per side of an areal scene that gives no n, nx or ny.
   integer, parameter :: default_areal_n = 256

   !> Where one group sits in the text: characters first..last, starting on `line`.
   type :: group_span
      integer :: index = 0   !< position in `group_names`
      integer :: line = 0
      integer :: first = 0
      integer :: last = 0
   end type group_span

   !> One `name = value` of the text: the variable (lower case, an index kept: `prony_times(2)`),
   !> the first value written after it, its group (position in `group_names`) and its line.
   type :: assignment
      character(len=name_width) :: name = ''
      character(len=name_width) :: value = ''
      integer :: group = 0
      integer :: line = 0
   end type assignment

contains

   !> Read a namelist file into a scene (defaults from scene_type), keep the file text.
   subroutine read_scene(filename, scene, text, error)
      !> namelist file
      character(len=*), intent(in) :: filename
      !> the scene: defaults, overridden by the file, validated by `check_scene`
      type(scene_type), intent(out) :: scene
      !> the whole file, for /input/namelist
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, nbytes
      character(len=512) :: msg

      open (newunit=unit, file=filename, access='stream', form='unformatted', action='read', &
         & status='old', iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, "cannot open namelist file '" // filename // "': " // trim(msg), code_io)
         return
      end if
      inquire (unit=unit, size=nbytes)
      allocate (character(len=max(nbytes, 0)) :: text)
      if (nbytes > 0) read (unit, iostat=stat, iomsg=msg) text
      close (unit)
      if (stat /= 0 .or. nbytes < 0) then
         call fatal_error(error, "cannot read namelist file '" // filename // "': " // trim(msg), code_io)
         return
      end if
      call read_scene_text(text, filename, scene, error)
   end subroutine read_scene

   !> Parse namelist text into a scene and validate it (`check_scene`).
   subroutine read_scene_text(text, source, scene, error)
      !> the namelist text (lines separated by LF or CR LF)
      character(len=*), intent(in) :: text
      !> where the text came from, for messages (a file name)
      character(len=*), intent(in) :: source
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(group_span) :: groups(n_groups)
      type(assignment), allocatable :: given(:)
      character(len=512) :: msg
      character(len=:), allocatable :: name
      integer :: n_found, i, stat, line

      call find_groups(text, source, groups, n_found, error)
      if (allocated(error)) return
      allocate (given(0))
      do i = 1, n_found
         call list_assignments(text(groups(i)%first:groups(i)%last), groups(i)%index, groups(i)%line, given)
      end do
      call check_repeated(given, source, error)
      if (allocated(error)) return

      do i = 1, n_found
         call read_group(text(groups(i)%first:groups(i)%last), groups(i)%index, scene, stat, msg, line)
         if (stat /= 0) then
            if (stat == iostat_end) msg = trim(msg) // " (is the closing '/' of the group missing?)"
            name = trim(group_names(groups(i)%index))
            if (stat /= stat_too_long) msg = trim(msg) // '; allowed variables in &' // name // ': ' &
               & // trim(group_variables(groups(i)%index))
            call fatal_error(error, source // ', line ' // to_string(groups(i)%line - 1 + line) &
               & // ', group &' // name // ': ' // trim(msg), code_input)
            return
         end if
      end do
      if (trim(scene%geometry) == 'line') then
         call check_line_scene(given, source, error)
         if (allocated(error)) return
      end if

      if (len_trim(scene%prony_file) > 0) then
         if (scene%material%terms() > 0 .or. allocated(scene%material%values)) then
            call fatal_error(error, '&material: prony_file and prony_times/prony_values are both given; ' // &
               & 'allowed: one of them', code_input)
            return
         end if
         call read_prony_file(trim(scene%prony_file), scene%material%times, scene%material%values, error)
         if (allocated(error)) return
      end if
      call check_scene(scene, error)
   end subroutine read_scene_text

   !> The scene as a complete namelist text with all eight groups and every variable of the
   !> scene schema; `read_scene_text` of it gives the same scene back (reals are written with
   !> 17 significant digits, a variable that is not set as a comment).
   subroutine write_scene_namelist(scene, text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable, intent(out) :: text

      include 'scene_namelist_writer.inc'
   end subroutine write_scene_namelist

   !> The default scene of a geometry ('line' or 'areal': its grid of
   !> default_areal_n x default_areal_n points), as a file that sets only the geometry
   !> reads it (not checked: a default scene has no load).
   pure function default_scene(geometry) result(scene)
      character(len=*), intent(in) :: geometry
      type(scene_type) :: scene
      scene%geometry = geometry
      if (trim(geometry) == 'areal') then
         scene%n = default_areal_n
         scene%ny = default_areal_n
      end if
   end function default_scene

   !> Read one group from its piece of text (one record per line); on failure `line` is the
   !> line within the piece of the entry that failed.
   subroutine read_group(segment, group, config, stat, msg, line)
      character(len=*), intent(in) :: segment
      integer, intent(in) :: group
      type(scene_type), intent(inout) :: config
      integer, intent(out) :: stat
      character(len=*), intent(out) :: msg
      integer, intent(out) :: line
      character(len=line_width(segment)) :: lines(count_char(segment, newline) + 1)

      call split_lines(segment, lines)
      msg = ''
      ! values of the wrong type, found before the namelist library reports them by an item
      ! number (`overwrite = 1.5`: "Bad repeat count in item 1 of list input")
      do line = 1, size(lines)
         if (wrong_type(code_of(lines(line), line == 1), msg)) then
            stat = stat_too_long
            return
         end if
      end do
      call read_named_group(trim(group_names(group)), lines, config, stat, msg)
      line = 1
      if (stat /= 0) then
         line = offending_line(lines, msg)
         call explain_value(code_of(lines(line), line == 1), msg)
      end if
   end subroutine read_group

   !> The namelist library reports a value of the wrong type as an unknown name (`n = 4096.5`:
   !> "Cannot match namelist object name .5"): when the name it quotes is not the variable
   !> assigned on the offending line, say which value does not fit which variable and what
   !> the variable takes. An index beyond an array gets the array's length.
   pure subroutine explain_value(code, msg)
      character(len=*), intent(in) :: code   !< the offending line, lower case, no comment
      character(len=*), intent(inout) :: msg
      character(len=*), parameter :: marker = 'Cannot match namelist object name '
      character(len=:), allocatable :: token, name, value
      integer :: k
      if (index(msg, 'out of range for namelist variable prony_') > 0) then
         msg = trim(msg) // ' (prony_times and prony_values hold at most ' // to_string(max_prony_terms) // &
            & ' terms, indexed from 1)'
         return
      end if
      if (index(msg, 'out of range for namelist variable lower_') > 0) then
         msg = trim(msg) // ' (lower_thickness, lower_young and lower_poisson hold at most ' // &
            & to_string(max_prony_terms) // ' layers, indexed from 1)'
         return
      end if
      k = index(msg, marker)
      if (k /= 1) return
      token = lower_case(trim(msg(len(marker) + 1:)))
      k = index(code, '=')
      if (k <= 1) return
      name = trim(adjustl(code(:k - 1)))
      value = trim(adjustl(code(k + 1:)))
      ! (only the first value on the line: `n = 64, period = abc` is about period, not n)
      if (index(value, ',') > 0) value = value(:index(value, ',') - 1)
      if (len(name) == 0 .or. name == token .or. index(value, token) == 0) return
      msg = "'" // name // ' = ' // value // "': " // name // ' takes ' // value_kind(name)
   end subroutine explain_value

   !> True (and the message) if `code` assigns a scalar variable a value that its type cannot
   !> read: an integer with a decimal point, a number for a logical, a word for a number.
   !> Names that are not scalar variables of a known type are left to the namelist library.
   logical function wrong_type(code, msg)
      character(len=*), intent(in) :: code   !< one line, lower case, without its comment
      character(len=*), intent(inout) :: msg
      character(len=:), allocatable :: name, value, kind
      integer :: k, stat
      integer(i8) :: as_integer   ! (the widest integer variable, &profile seed)
      real(wp) :: as_real
      logical :: as_logical
      wrong_type = .false.
      k = index(code, '=')
      if (k <= 1) return
      name = trim(adjustl(code(:k - 1)))
      value = trim(adjustl(code(k + 1:)))
      if (len(name) == 0 .or. len(value) == 0 .or. verify(name, 'abcdefghijklmnopqrstuvwxyz0123456789_') /= 0) return
      kind = value_kind(name)
      if (kind == '.true. or .false.') then
         read (value, *, iostat=stat) as_logical
      else if (kind(1:4) == 'an i') then
         read (value, *, iostat=stat) as_integer
      else if (index(real_variables, ' ' // name // ' ') > 0) then
         read (value, *, iostat=stat) as_real
      else
         return
      end if
      if (stat == 0) return
      wrong_type = .true.
      msg = "'" // name // ' = ' // value // "': " // name // ' takes ' // kind
   end function wrong_type

   !> What a namelist variable takes, for messages.
   pure function value_kind(name) result(kind)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: kind
      if (index(integer_variables, ' ' // name // ' ') > 0) then
         kind = 'an integer (no decimal point or exponent)'
      else if (index(logical_variables, ' ' // name // ' ') > 0) then
         kind = '.true. or .false.'
      else if (index(string_variables, ' ' // name // ' ') > 0) then
         kind = "a quoted string ('...')"
      else
         kind = 'a number (e.g. 0.16 or 1.6e-1)'
      end if
   end function value_kind

   ! ---------------------------------------------------------------------------------------
   ! One reader per group, generated from the scene schema (read_named_group calls them),
   ! and the hooks of the groups whose variables are not plain copies: the grid's variables
   ! of &scene and the Prony terms of &material.

   include 'scene_readers.inc'

   !> &scene before the read: unset_count and not_set mark the grid variables the text does
   !> not give (areal grids: n for nx = ny = n, or nx and ny; period = period_x).
   pure subroutine before_scene(config, period, period_x, n, nx, ny)
      type(scene_type), intent(in) :: config
      real(wp), intent(out) :: period, period_x
      integer, intent(out) :: n, nx, ny
      period = config%period
      period_x = not_set
      n = unset_count
      nx = unset_count
      ny = unset_count
   end subroutine before_scene

   !> &scene after the read: the period and the grid, with the defaults of the geometry
   !> (without n, an areal grid of default_areal_n points per side); `grid_given` says
   !> whether the text sets the grid (else a profile file may).
   pure subroutine after_scene(config, period, period_x, n, nx, ny)
      type(scene_type), intent(inout) :: config
      real(wp), intent(in) :: period, period_x
      integer, intent(in) :: n, nx, ny
      integer :: points
      config%period = merge(period_x, period, period_x /= not_set)
      config%grid_given = n /= unset_count .or. nx /= unset_count .or. ny /= unset_count
      points = n
      if (points == unset_count) points = merge(default_areal_n, config%n, trim(config%geometry) == 'areal')
      config%n = merge(nx, points, nx /= unset_count)
      config%ny = merge(ny, merge(points, 1, trim(config%geometry) == 'areal'), ny /= unset_count)
   end subroutine after_scene

   !> &layer before the read: the lower layers the scene holds, the other entries unset.
   pure subroutine before_layer(config, lower_thickness, lower_young, lower_poisson, lower_tau, lower_e_inf)
      type(scene_type), intent(in) :: config
      real(wp), intent(out) :: lower_thickness(:), lower_young(:), lower_poisson(:), lower_tau(:), lower_e_inf(:)
      call start_list(config%lower_thickness, lower_thickness)
      call start_list(config%lower_young, lower_young)
      call start_list(config%lower_poisson, lower_poisson)
      call start_list(config%lower_tau, lower_tau)
      call start_list(config%lower_e_inf, lower_e_inf)
   end subroutine before_layer

   !> &layer after the read: each list is its leading entries that were set; a gap is refused.
   pure subroutine after_layer(config, lower_thickness, lower_young, lower_poisson, lower_tau, lower_e_inf, stat, msg)
      type(scene_type), intent(inout) :: config
      real(wp), intent(in) :: lower_thickness(:), lower_young(:), lower_poisson(:), lower_tau(:), lower_e_inf(:)
      integer, intent(inout) :: stat
      character(len=*), intent(inout) :: msg
      if (gapped(lower_thickness) .or. gapped(lower_young) .or. gapped(lower_poisson) .or. gapped(lower_tau) .or. &
         & gapped(lower_e_inf)) then
         stat = -1
         msg = 'lower_thickness/lower_young/lower_poisson/lower_tau/lower_e_inf: give the entries in order from the ' &
            & // 'first, without gaps'
         return
      end if
      config%lower_thickness = lower_thickness(:count_set(lower_thickness))
      config%lower_young = lower_young(:count_set(lower_young))
      config%lower_poisson = lower_poisson(:count_set(lower_poisson))
      config%lower_tau = lower_tau(:count_set(lower_tau))
      config%lower_e_inf = lower_e_inf(:count_set(lower_e_inf))
   end subroutine after_layer

   !> Whether a list has an unset entry before a set one.
   pure logical function gapped(values)
      real(wp), intent(in) :: values(:)
      gapped = count_set(values) /= count(values /= unset_entry)
   end function gapped

   !> A list's local copy before a read: the scene's entries, the others unset.
   pure subroutine start_list(held, local)
      real(wp), allocatable, intent(in) :: held(:)
      real(wp), intent(out) :: local(:)
      local = unset_entry
      if (allocated(held)) local(:size(held)) = held
   end subroutine start_list

   !> &material before the read: the terms the scene holds, the other entries marked unset.
   pure subroutine before_material(config, prony_times, prony_values)
      type(scene_type), intent(in) :: config
      real(wp), intent(out) :: prony_times(:), prony_values(:)
      prony_times = unset_entry
      prony_values = unset_entry
      if (allocated(config%material%times)) prony_times(:size(config%material%times)) = config%material%times
      if (allocated(config%material%values)) prony_values(:size(config%material%values)) = config%material%values
   end subroutine before_material

   !> &material after the read: the terms given are the leading entries that were set; a gap
   !> is refused.
   pure subroutine after_material(config, prony_times, prony_values, stat, msg)
      type(scene_type), intent(inout) :: config
      real(wp), intent(in) :: prony_times(:), prony_values(:)
      integer, intent(inout) :: stat
      character(len=*), intent(inout) :: msg
      if (count_set(prony_times) /= count(prony_times /= unset_entry) .or. &
         & count_set(prony_values) /= count(prony_values /= unset_entry)) then
         stat = -1
         msg = 'prony_times/prony_values: give the entries in order from the first, without gaps'
         return
      end if
      associate (m => config%material)
         if (allocated(m%times)) deallocate (m%times)
         if (allocated(m%values)) deallocate (m%values)
         if (count_set(prony_times) > 0) m%times = prony_times(:count_set(prony_times))
         if (count_set(prony_values) > 0) m%values = prony_values(:count_set(prony_values))
      end associate
   end subroutine after_material

   !> A string variable read into a buffer one character longer than the scene keeps: if it
   !> fills more than max_string characters it would be cut, so it is refused
   !> (stat = stat_too_long).
   logical function too_long(name, value, stat, msg)
      character(len=*), intent(in) :: name, value
      integer, intent(inout) :: stat
      character(len=*), intent(inout) :: msg
      too_long = len_trim(value) > max_string
      if (.not. too_long) return
      stat = stat_too_long
      msg = name // " = '" // value(:24) // "...' is longer than " // to_string(max_string) // &
         & ' characters; allowed: at most ' // to_string(max_string) // ' characters'
   end function too_long

   !> Number of leading entries that were given (not `unset_entry`).
   pure integer function count_set(values)
      real(wp), intent(in) :: values(:)
      count_set = 0
      do while (count_set < size(values))
         if (values(count_set + 1) == unset_entry) exit
         count_set = count_set + 1
      end do
   end function count_set

   !> Prony terms from a text file: one term per line, `tau_i value_i` (comments after '#'
   !> or '!'). Sorting and positivity are checked with the material (check_material).
   subroutine read_prony_file(filename, times, values, error)
      character(len=*), intent(in) :: filename
      real(wp), allocatable, intent(out) :: times(:), values(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=1024) :: line, msg
      real(wp) :: pair(2), extra
      integer :: unit, stat, lineno, cut, kind
      character(len=:), allocatable :: detail

      allocate (times(0), values(0))
      ! a file that is not there, or not a regular file (a loop of symbolic links, a
      ! directory, a FIFO), is bad input (as for &profile file); one that is there but cannot
      ! be opened an I/O failure
      call path_kind(filename, kind, detail)
      if (kind == kind_missing) then
         call input_error(error, 'material', 'prony_file', "'" // filename // "'", &
            & 'an existing text file of tau_i value_i lines, relative to the working directory')
         return
      else if (kind /= kind_regular .and. kind /= kind_unknown) then
         call fatal_error(error, "&material: prony_file = '" // filename // "' is " // kind_name(kind) // &
            & '; allowed: a regular text file of tau_i value_i lines', code_input)
         return
      end if
      open (newunit=unit, file=filename, status='old', action='read', iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, "&material: cannot open prony_file '" // filename // "': " // trim(msg), code_io)
         return
      end if
      lineno = 0
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         lineno = lineno + 1
         cut = scan(line, '#!')
         if (cut > 0) line(cut:) = ''
         if (len_trim(line) == 0) cycle
         read (line, *, iostat=stat) pair, extra
         if (stat == 0) then
            call fatal_error(error, "&material: prony_file '" // filename // "', line " // to_string(lineno) // &
               & ": expected two numbers 'tau_i value_i', got more: '" // trim(line) // "'", code_input)
            close (unit)
            return
         end if
         read (line, *, iostat=stat) pair
         if (stat /= 0) then
            call fatal_error(error, "&material: prony_file '" // filename // "', line " // to_string(lineno) // &
               & ": expected two numbers 'tau_i value_i', got '" // trim(line) // "'", code_input)
            close (unit)
            return
         end if
         if (size(times) >= max_prony_terms) then
            call fatal_error(error, "&material: prony_file '" // filename // "' has more than " // &
               & to_string(max_prony_terms) // ' terms', code_input)
            close (unit)
            return
         end if
         times = [times, pair(1)]
         values = [values, pair(2)]
      end do
      close (unit)
      if (size(times) == 0) then
         call fatal_error(error, "&material: prony_file '" // filename // "' holds no terms; allowed: lines " // &
            & "'tau_i value_i', 1 to " // to_string(max_prony_terms), code_input)
      end if
   end subroutine read_prony_file

   ! ---------------------------------------------------------------------------------------
   ! The assignments of the text: variables given twice, variables of surfaces in a line scene.

   !> Append the assignments of one group's text (`segment`, starting on line `first_line`
   !> of the file) to `given`.
   subroutine list_assignments(segment, group, first_line, given)
      character(len=*), intent(in) :: segment
      integer, intent(in) :: group, first_line
      type(assignment), allocatable, intent(inout) :: given(:)
      character(len=line_width(segment)) :: lines(count_char(segment, newline) + 1)
      character(len=:), allocatable :: code
      type(assignment) :: item
      integer :: k, i, start, finish

      call split_lines(segment, lines)
      do k = 1, size(lines)
         code = blank_strings(code_of(lines(k), k == 1))
         do i = 1, len(code)
            if (code(i:i) /= '=') cycle
            ! the name before the '=', with its index: `name =`, `name(2) =`
            finish = len_trim(code(:i - 1))
            if (finish == 0) cycle
            start = finish
            if (code(finish:finish) == ')') start = index(code(:finish), '(', back=.true.) - 1
            if (start < 1) cycle
            start = len_trim(code(:start))
            do while (start > 1)
               if (.not. is_name_char(code(start - 1:start - 1))) exit
               start = start - 1
            end do
            if (start < 1) cycle
            if (.not. is_name_char(code(start:start))) cycle
            item%name = remove_blanks(code(start:finish))
            item%value = first_value(code_of(lines(k), k == 1), i)
            item%group = group
            item%line = first_line + k - 1
            given = [given, item]
         end do
      end do
   end subroutine list_assignments

   !> A variable assigned twice in a group, or under both of its names, is an error naming
   !> the group, the variable(s), their lines and which one to keep.
   subroutine check_repeated(given, source, error)
      type(assignment), intent(in) :: given(:)
      character(len=*), intent(in) :: source
      type(error_type), allocatable, intent(out) :: error
      integer :: i, j
      character(len=:), allocatable :: place

      do j = 2, size(given)
         do i = 1, j - 1
            if (given(i)%group /= given(j)%group) cycle
            if (quantity(given(i)) /= quantity(given(j))) cycle
            place = source // ', line ' // to_string(given(j)%line) // ', group &' // trim(group_names(given(j)%group))
            if (given(i)%name == given(j)%name) then
               call fatal_error(error, place // ': ' // trim(given(j)%name) // ' is given twice (lines ' // &
                  & to_string(given(i)%line) // ' and ' // to_string(given(j)%line) // '); allowed: one ' // &
                  & 'assignment of each variable: keep the one you mean and remove the other', code_input)
            else
               call fatal_error(error, place // ': ' // trim(given(i)%name) // ' and ' // trim(given(j)%name) // &
                  & ' are both given (lines ' // to_string(given(i)%line) // ' and ' // to_string(given(j)%line) // &
                  & ') and are two names of one variable; allowed: one of them: keep ' // quantity(given(j)) // &
                  & ' and remove the other', code_input)
            end if
            return
         end do
      end do
   end subroutine check_repeated

   !> The variables that only surfaces use (`period_y`, `ny`, `mode_y`, ...: the scene schema's
   !> uses 'areal') are refused in a line scene, which would ignore them.
   subroutine check_line_scene(given, source, error)
      type(assignment), intent(in) :: given(:)
      character(len=*), intent(in) :: source
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: group
      integer :: i

      do i = 1, size(given)
         group = trim(group_names(given(i)%group))
         if (index(areal_only_variables, ' ' // group // ':' // bare_name(given(i)%name) // ' ') == 0) cycle
         call fatal_error(error, source // ', line ' // to_string(given(i)%line) // ', group &' // group // ': ' // &
            & trim(given(i)%name) // ' = ' // trim(given(i)%value) // " is not allowed; allowed: not given with " // &
            & "geometry = 'line' (" // bare_name(given(i)%name) // " applies to surfaces only, geometry = 'areal')", &
            & code_input)
         return
      end do
   end subroutine check_line_scene

   !> The variable an assignment sets: its name with the index kept, a second name
   !> (`period_x`, `nx`) replaced by the first (`period`, `n`).
   pure function quantity(given) result(name)
      type(assignment), intent(in) :: given
      character(len=:), allocatable :: name
      character(len=:), allocatable :: key
      integer :: k, finish
      name = trim(given%name)
      key = ' ' // trim(group_names(given%group)) // ':' // bare_name(given%name) // '='
      k = index(alias_names, key)
      if (k == 0) return
      finish = k + len(key) - 1 + index(alias_names(k + len(key):), ' ') - 1
      name = alias_names(k + len(key):finish) // name(len(bare_name(given%name)) + 1:)
   end function quantity

   !> A name without its index (`prony_times(2)` -> `prony_times`).
   pure function bare_name(name) result(bare)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: bare
      bare = trim(name)
      if (index(name, '(') > 0) bare = name(:index(name, '(') - 1)
   end function bare_name

   !> The first value after the '=' at `at` of a line (up to the next comma outside quotes).
   pure function first_value(code, at) result(value)
      character(len=*), intent(in) :: code
      integer, intent(in) :: at
      character(len=:), allocatable :: value
      character :: quote
      integer :: i
      quote = ' '
      do i = at + 1, len(code)
         if (quote /= ' ') then
            if (code(i:i) == quote) quote = ' '
         else if (code(i:i) == '"' .or. code(i:i) == "'") then
            quote = code(i:i)
         else if (code(i:i) == ',' .or. code(i:i) == '/') then
            exit
         end if
      end do
      value = trim(adjustl(code(at + 1:i - 1)))
   end function first_value

   !> The line with the characters of quoted strings blanked (a '=' there is no assignment).
   pure function blank_strings(code) result(out)
      character(len=*), intent(in) :: code
      character(len=len(code)) :: out
      character :: quote
      integer :: i
      out = code
      quote = ' '
      do i = 1, len(code)
         if (quote /= ' ') then
            if (code(i:i) == quote) quote = ' '
            out(i:i) = ' '
         else if (code(i:i) == '"' .or. code(i:i) == "'") then
            quote = code(i:i)
            out(i:i) = ' '
         end if
      end do
   end function blank_strings

   pure function remove_blanks(text) result(out)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: out
      integer :: i
      out = ''
      do i = 1, len(text)
         if (text(i:i) /= ' ') out = out // text(i:i)
      end do
   end function remove_blanks

   ! ---------------------------------------------------------------------------------------
   ! Scanning the text.

   !> Find every `&name` outside comments and quotes; unknown or repeated names are errors.
   !> `&end` is skipped: gfortran accepts it as a legacy group terminator. Text outside the
   !> groups (other than comments) is an error too: gfortran would silently ignore it, as in
   !> a value written on the line after a group's closing '/'.
   subroutine find_groups(text, source, groups, n_found, error)
      character(len=*), intent(in) :: text, source
      type(group_span), intent(out) :: groups(n_groups)
      integer, intent(out) :: n_found
      type(error_type), allocatable, intent(out) :: error
      character(len=max_string) :: name
      character :: quote
      integer :: i, j, line, k
      logical :: inside

      n_found = 0
      line = 1
      quote = ' '
      inside = .false.
      i = 1
      do while (i <= len(text))
         if (text(i:i) == newline) then
            ! (a string that goes on to the next line would silently lose its newline: a file
            ! name 'out<newline>put.h5' would become another name)
            if (quote /= ' ') then
               call fatal_error(error, source // ', line ' // to_string(line) // ': a string goes on to the ' // &
                  & "next line; allowed: a string on one line (no newline in a name)", code_input)
               return
            end if
            line = line + 1
         else if (quote /= ' ') then
            ! a doubled quote inside a string is an escaped quote, not the end of the string
            if (text(i:i) == quote) then
               if (text(i:min(i + 1, len(text))) == quote // quote) then
                  i = i + 1
               else
                  quote = ' '
               end if
            end if
         else if (text(i:i) == '!') then
            j = index(text(i:), newline)
            if (j == 0) exit
            i = i + j - 2
         else if (text(i:i) == '"' .or. text(i:i) == "'") then
            quote = text(i:i)
         else if (inside .and. text(i:i) == '/') then
            inside = .false.
         else if (.not. inside .and. text(i:i) /= '&' .and. verify(text(i:i), ' ' // achar(9) // achar(13)) /= 0) &
            & then
            call fatal_error(error, source // ', line ' // to_string(line) // ": text outside a namelist group ('" &
               & // trim(text(i:line_end(text, i))) // "'): every value must stand between '&group' and its " &
               & // "closing '/'", code_input)
            return
         else if (text(i:i) == '&') then
            j = i + 1
            do while (j <= len(text))
               if (.not. is_name_char(text(j:j))) exit
               j = j + 1
            end do
            name = lower_case(text(i + 1:j - 1))
            inside = .false.
            if (name /= 'end') then
               inside = .true.
               k = group_index(name)
               if (k == 0) then
                  call fatal_error(error, source // ', line ' // to_string(line) // ": unknown namelist group '&" &
                     & // trim(name) // "'; allowed groups: " // allowed_groups(), code_input)
                  return
               end if
               if (any(groups(:n_found)%index == k)) then
                  call fatal_error(error, source // ', line ' // to_string(line) // ": namelist group '&" &
                     & // trim(name) // "' given twice (at most once each); allowed groups: " // allowed_groups(), &
                     & code_input)
                  return
               end if
               if (n_found > 0) groups(n_found)%last = i - 1
               n_found = n_found + 1
               groups(n_found) = group_span(index=k, line=line, first=i, last=len(text))
            end if
            i = j - 1
         end if
         i = i + 1
      end do
   end subroutine find_groups

   !> Length of the longest line of `text` (at least 1).
   pure integer function line_width(text)
      character(len=*), intent(in) :: text
      integer :: start, finish
      line_width = 1
      start = 1
      do while (start <= len(text))
         finish = line_end(text, start)
         line_width = max(line_width, finish - start + 1)
         start = finish + 2
      end do
   end function line_width

   !> Split text at LF into lines (one record each, trailing CR removed); `lines` is sized
   !> by `line_width` and `count_char(text, newline) + 1`.
   pure subroutine split_lines(text, lines)
      character(len=*), intent(in) :: text
      character(len=*), intent(out) :: lines(:)
      integer :: start, finish, i

      start = 1
      do i = 1, size(lines)
         finish = min(line_end(text, start), len(text))
         lines(i) = text(min(start, len(text) + 1):finish)
         if (finish >= start) then
            if (text(finish:finish) == achar(13)) lines(i) = text(start:finish - 1)
         end if
         start = finish + 2
      end do
   end subroutine split_lines

   !> Last character of the line that starts at `start` (before its LF or the end).
   pure integer function line_end(text, start)
      character(len=*), intent(in) :: text
      integer, intent(in) :: start
      line_end = index(text(min(start, len(text) + 1):), newline)
      if (line_end == 0) then
         line_end = len(text)
      else
         line_end = start + line_end - 2
      end if
   end function line_end

   !> Line (1-based, within the group) of the entry gfortran's iomsg complains about.
   !> gfortran names the token it could not match ("Cannot match namelist object name X"):
   !> a misspelt variable (`X =`) or, for a bad value, a piece of the value. Look for
   !> `X =` first, then for X anywhere outside comments; fall back to the group's first line.
   pure integer function offending_line(lines, msg) result(line)
      character(len=*), intent(in) :: lines(:), msg
      character(len=*), parameter :: marker = 'object name '
      character(len=:), allocatable :: token
      integer :: k

      line = 1
      k = index(msg, marker)
      if (k > 0) then
         token = lower_case(trim(msg(k + len(marker):)))
      else
         ! "Index 1 out of range for namelist variable prony_times": the line of that variable
         k = index(msg, 'namelist variable ')
         if (k == 0) return
         token = lower_case(trim(msg(k + len('namelist variable '):)))
      end if
      if (len(token) == 0) return
      do k = 1, size(lines)
         if (is_assigned(code_of(lines(k), k == 1), token)) then
            line = k
            return
         end if
      end do
      do k = 1, size(lines)
         if (index(code_of(lines(k), k == 1), token) > 0) then
            line = k
            return
         end if
      end do
   end function offending_line

   !> A line in lower case without its comment (and without the `&name` on the first line).
   pure function code_of(line, first) result(code)
      character(len=*), intent(in) :: line
      logical, intent(in) :: first
      character(len=:), allocatable :: code
      code = lower_case(strip_comment(line))
      if (first) code = skip_group_name(code)
   end function code_of

   !> True when `name` appears in `code` as a whole word followed by `=`, `(` or `%`.
   pure logical function is_assigned(code, name)
      character(len=*), intent(in) :: code, name
      integer :: pos, k, after
      is_assigned = .false.
      pos = 0
      do
         k = index(code(pos + 1:), name)
         if (k == 0) return
         pos = pos + k
         after = pos + len(name)
         if (pos > 1) then
            if (is_name_char(code(pos - 1:pos - 1))) cycle
         end if
         if (after > len(code)) return
         if (scan(adjustl(code(after:)), '=(%') == 1) then
            is_assigned = .true.
            return
         end if
      end do
   end function is_assigned

   !> The line with the leading `&name` token blanked (so a bad value is not found there).
   pure function skip_group_name(code) result(rest)
      character(len=*), intent(in) :: code
      character(len=:), allocatable :: rest
      integer :: i
      rest = code
      i = index(code, '&')
      if (i == 0) return
      do while (i <= len(code))
         if (code(i:i) /= '&' .and. .not. is_name_char(code(i:i))) exit
         rest(i:i) = ' '
         i = i + 1
      end do
   end function skip_group_name

   !> The line up to a `!` that is not inside quotes.
   pure function strip_comment(line) result(code)
      character(len=*), intent(in) :: line
      character(len=:), allocatable :: code
      character :: quote
      integer :: i
      quote = ' '
      code = line
      do i = 1, len(line)
         if (quote /= ' ') then
            if (line(i:i) == quote) quote = ' '
         else if (line(i:i) == '"' .or. line(i:i) == "'") then
            quote = line(i:i)
         else if (line(i:i) == '!') then
            code = line(:i - 1)
            return
         end if
      end do
   end function strip_comment

   ! ---------------------------------------------------------------------------------------
   ! Small text helpers.

   !> Position of `name` in `group_names`, 0 if it is not a group.
   pure integer function group_index(name)
      character(len=*), intent(in) :: name
      do group_index = n_groups, 1, -1
         if (trim(group_names(group_index)) == name) return
      end do
   end function group_index

   pure function allowed_groups() result(list)
      character(len=:), allocatable :: list
      integer :: k
      list = '&' // trim(group_names(1))
      do k = 2, n_groups
         list = list // ', &' // trim(group_names(k))
      end do
   end function allowed_groups

   pure function entry(name, value) result(line)
      character(len=*), intent(in) :: name, value
      character(len=:), allocatable :: line
      line = '   ' // name // ' = ' // value // newline
   end function entry

   !> A real that reads back bit for bit (17 significant digits); Inf/NaN as gfortran reads them.
   pure function real_value(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=32) :: buffer
      if (ieee_is_nan(x)) then
         s = 'NaN'
      else if (.not. ieee_is_finite(x)) then
         s = merge('Inf ', '-Inf', x > 0.0_wp)
         s = trim(s)
      else
         write (buffer, '(es24.16e3)') x
         s = trim(adjustl(buffer))
      end if
   end function real_value

   !> A list variable as `name = v1, v2, ...` (nothing if it has no entries).
   pure function list_entry(name, values) result(s)
      character(len=*), intent(in) :: name
      real(wp), allocatable, intent(in) :: values(:)
      character(len=:), allocatable :: s
      integer :: i
      s = ''
      if (.not. allocated(values)) return
      if (size(values) == 0) return
      s = '   ' // name // ' = ' // real_value(values(1))
      do i = 2, size(values)
         s = s // ', ' // real_value(values(i))
      end do
      s = s // newline
   end function list_entry

   !> A quoted string, inner apostrophes doubled.
   pure function str_value(word) result(s)
      character(len=*), intent(in) :: word
      character(len=:), allocatable :: s
      integer :: i
      s = "'"
      do i = 1, len_trim(word)
         s = s // word(i:i)
         if (word(i:i) == "'") s = s // "'"
      end do
      s = s // "'"
   end function str_value

   pure function logical_value(flag) result(s)
      logical, intent(in) :: flag
      character(len=:), allocatable :: s
      if (flag) then
         s = '.true.'
      else
         s = '.false.'
      end if
   end function logical_value



   pure logical function is_name_char(c)
      character, intent(in) :: c
      is_name_char = verify(c, 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_') == 0
   end function is_name_char

   pure integer function count_char(text, c)
      character(len=*), intent(in) :: text
      character, intent(in) :: c
      integer :: i
      count_char = 0
      do i = 1, len(text)
         if (text(i:i) == c) count_char = count_char + 1
      end do
   end function count_char

end module lc_io_namelist
