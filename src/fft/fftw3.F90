!> The FFTW3 Fortran 2003 interface (fftw3.f03) wrapped in a module, so that the rest of
!> the code can `use lc_fft_fftw3, only: ...` what it needs. The header needs all of
!> iso_c_binding in scope, which is why it lives alone here.
module lc_fft_fftw3
   use, intrinsic :: iso_c_binding
   implicit none
   public

#include <fftw3.f03>

end module lc_fft_fftw3
