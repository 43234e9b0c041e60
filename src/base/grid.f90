!> The periodic grid of a contact: nx points along the sliding direction x, ny across it
!> (a line contact is the grid with ny = 1), periods lx and ly (L).
!>
!> Fields are stored flat, x fastest: f(ix + nx*iy + 1) = f(x = ix*lx/nx, y = iy*ly/ny),
!> which is the memory order of a Fortran array f(nx, ny) and of a C/numpy array
!> f[ny, nx]. Spectra are the half spectra of a real-to-complex transform along x:
!> nkx = nx/2 + 1 columns mx = 0..nx/2 times ny rows my = 0..ny-1 (my > ny/2 stands for
!> my - ny), stored flat with mx fastest. A mode with 0 < mx < nx/2 stands for itself and
!> its mirror image -q; the columns mx = 0 and (for even nx) mx = nx/2 hold their own
!> mirror images, so in sums over the whole spectrum they count once (`mode_weight`).
module lc_base_grid
   use lc_base_kinds, only: wp
   implicit none (type, external)
   private
   public :: grid_type, line_grid, surface_grid

   real(wp), parameter :: pi = acos(-1.0_wp)

   type :: grid_type
      integer :: nx = 0, ny = 1
      real(wp) :: lx = 1.0_wp, ly = 1.0_wp
   contains
      procedure :: points
      procedure :: modes
      procedure :: nkx
      procedure :: is_line
      procedure :: wavevector
      procedure :: mode_weight
      procedure :: can_coarsen
      procedure :: coarse
   end type grid_type

contains

   !> A line of n points on a period (L).
   pure function line_grid(n, period) result(grid)
      integer, intent(in) :: n
      real(wp), intent(in) :: period
      type(grid_type) :: grid
      grid = grid_type(nx=n, ny=1, lx=period, ly=period)
   end function line_grid

   !> A surface of nx x ny points on periods lx, ly (L).
   pure function surface_grid(nx, ny, lx, ly) result(grid)
      integer, intent(in) :: nx, ny
      real(wp), intent(in) :: lx, ly
      type(grid_type) :: grid
      grid = grid_type(nx=nx, ny=ny, lx=lx, ly=ly)
   end function surface_grid

   !> Grid points, nx*ny.
   pure integer function points(self)
      class(grid_type), intent(in) :: self
      points = self%nx*self%ny
   end function points

   !> Columns of the half spectrum, nx/2 + 1.
   pure integer function nkx(self)
      class(grid_type), intent(in) :: self
      nkx = self%nx/2 + 1
   end function nkx

   !> Modes of the half spectrum, (nx/2 + 1)*ny.
   pure integer function modes(self)
      class(grid_type), intent(in) :: self
      modes = self%nkx()*self%ny
   end function modes

   pure logical function is_line(self)
      class(grid_type), intent(in) :: self
      is_line = self%ny == 1
   end function is_line

   !> Wavevector (qx, qy) (1/L) of the half-spectrum mode with flat index i (1-based).
   pure subroutine wavevector(self, i, qx, qy)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: i
      real(wp), intent(out) :: qx, qy
      integer :: mx, my
      mx = mod(i - 1, self%nkx())
      my = (i - 1)/self%nkx()
      if (2*my > self%ny) my = my - self%ny
      qx = 2.0_wp*pi*mx/self%lx
      qy = 2.0_wp*pi*my/self%ly
   end subroutine wavevector

   !> How many modes of the whole spectrum the half-spectrum mode i stands for: 2, or 1 in
   !> the columns mx = 0 and (even nx) mx = nx/2, which hold their own mirror images.
   pure integer function mode_weight(self, i)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: i
      integer :: mx
      mx = mod(i - 1, self%nkx())
      mode_weight = merge(1, 2, mx == 0 .or. 2*mx == self%nx)
   end function mode_weight

   !> True when the grid of every second point exists (even sizes) and has at least
   !> `smallest` points.
   pure logical function can_coarsen(self, smallest)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: smallest
      can_coarsen = mod(self%nx, 2) == 0 .and. (self%ny == 1 .or. mod(self%ny, 2) == 0) &
         & .and. (self%nx/2)*max(self%ny/2, 1) >= smallest
   end function can_coarsen

   !> The grid of every second point (along both axes of a surface).
   pure function coarse(self) result(grid)
      class(grid_type), intent(in) :: self
      type(grid_type) :: grid
      grid = self
      grid%nx = self%nx/2
      if (self%ny > 1) grid%ny = self%ny/2
   end function coarse
end module lc_base_grid
