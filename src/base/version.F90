!> The code version and the instruction set of this build, set by the build (meson).
module lc_base_version
   implicit none (type, external)
   private
   public :: version_string, build_isa

   !> layercontact's version, written into every result file.
   character(len=*), parameter :: version_string = LC_VERSION
   !> The instruction set the library was compiled for ('x86-64' portable, 'x86-64-v3' with
   !> AVX2 and FMA, 'native'): the builds agree to rounding, not bit for bit.
   character(len=*), parameter :: build_isa = LC_ISA
end module lc_base_version
