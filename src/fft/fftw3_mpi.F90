!> FFTW-MPI's Fortran 2003 interface (fftw3-mpi.f03, which includes fftw3.f03 once more:
!> import from here only the MPI procedures, by name). Empty without MPI (no LC_MPI).
module lc_fft_fftw3_mpi
#ifdef LC_MPI
   use, intrinsic :: iso_c_binding
   implicit none
   public

#include <fftw3-mpi.f03>
#endif
end module lc_fft_fftw3_mpi
