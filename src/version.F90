!> The code version, set by the build (meson project version).
module lc_version
   implicit none (type, external)
   private
   public :: version_string

   !> layercontact's version, written into every result file.
   character(len=*), parameter :: version_string = LC_VERSION
end module lc_version
