!> Counter-based random numbers for profile synthesis: SplitMix64 (Steele, Lea & Flood,
!> "Fast splittable pseudorandom number generators", OOPSLA 2014; the reference `next()`
!> of Vigna's splitmix64.c). The m-th output (m = 1, 2, ...) for a seed is
!>
!>   state_m = seed + m*0x9E3779B97F4A7C15            (mod 2^64)
!>   z = state_m
!>   z = (z xor (z >> 30)) * 0xBF58476D1CE4E5B9       (mod 2^64)
!>   z = (z xor (z >> 27)) * 0x94D049BB133111EB       (mod 2^64)
!>   z = z xor (z >> 31)
!>   u_m = (z >> 11) * 2^-53                          (in [0, 1))
!>
!> with logical shifts. Being a function of (seed, m) only, it needs no state, is pure
!> and gives the same numbers in any order, on any thread, and in numpy uint64
!> (tests/reference_profiles.py).
!>
!> The 64-bit words are held as integer(int64) bit patterns. Fortran has no unsigned
!> arithmetic and signed overflow is not defined (it traps with -ftrapv and is flagged by
!> -fsanitize=undefined), so the sums and products mod 2^64 are done on 16-bit limbs,
!> where no intermediate exceeds 2^35.
module lc_profiles_random
   use lc_base_kinds, only: wp, i8
   implicit none (type, external)
   private
   public :: splitmix64, splitmix64_uniform

   ! The constants are built from two 32-bit halves so that no literal exceeds
   ! huge(1_i8) and no -fno-range-check flag is needed.
   !> Golden-ratio increment 0x9E3779B97F4A7C15.
   integer(i8), parameter :: gamma = ior(shiftl(int(z'9E3779B9', i8), 32), int(z'7F4A7C15', i8))
   !> First mixing multiplier 0xBF58476D1CE4E5B9.
   integer(i8), parameter :: mix1 = ior(shiftl(int(z'BF58476D', i8), 32), int(z'1CE4E5B9', i8))
   !> Second mixing multiplier 0x94D049BB133111EB.
   integer(i8), parameter :: mix2 = ior(shiftl(int(z'94D049BB', i8), 32), int(z'133111EB', i8))
   !> Mask of one 16-bit limb.
   integer(i8), parameter :: limb_mask = int(z'FFFF', i8)

contains

   !> The m-th SplitMix64 output for `seed`, as the bit pattern of a signed 64-bit integer.
   pure elemental integer(i8) function splitmix64(seed, m) result(z)
      !> Seed (any 64-bit pattern)
      integer(i8), intent(in) :: seed
      !> Output index, 1 for the first output
      integer(i8), intent(in) :: m

      z = add_mod64(seed, multiply_mod64(m, gamma))
      z = multiply_mod64(ieor(z, shiftr(z, 30)), mix1)
      z = multiply_mod64(ieor(z, shiftr(z, 27)), mix2)
      z = ieor(z, shiftr(z, 31))
   end function splitmix64

   !> The m-th SplitMix64 output for `seed` mapped to [0, 1): its top 53 bits times 2^-53.
   pure elemental real(wp) function splitmix64_uniform(seed, m) result(u)
      !> Seed (any 64-bit pattern)
      integer(i8), intent(in) :: seed
      !> Output index, 1 for the first output
      integer(i8), intent(in) :: m

      ! 53 bits fit the double mantissa, so the conversion is exact.
      u = real(shiftr(splitmix64(seed, m), 11), wp)*2.0_wp**(-53)
   end function splitmix64_uniform

   !> The four 16-bit limbs of a 64-bit pattern, least significant first (each 0..2^16-1).
   pure function limbs(x) result(l)
      integer(i8), intent(in) :: x
      integer(i8) :: l(0:3)
      integer :: i

      do i = 0, 3
         l(i) = iand(shiftr(x, 16*i), limb_mask)
      end do
   end function limbs

   !> a + b mod 2^64 on bit patterns, without signed overflow.
   pure elemental integer(i8) function add_mod64(a, b) result(r)
      integer(i8), intent(in) :: a, b
      integer(i8) :: al(0:3), bl(0:3), column
      integer :: c

      al = limbs(a)
      bl = limbs(b)
      r = 0_i8
      column = 0_i8
      do c = 0, 3
         column = shiftr(column, 16) + al(c) + bl(c)
         r = ior(r, shiftl(iand(column, limb_mask), 16*c))
      end do
   end function add_mod64

   !> a * b mod 2^64 on bit patterns, without signed overflow: schoolbook product of the
   !> limbs, keeping only the columns below 2^64 (each column < 4*2^32 + carry < 2^35).
   pure elemental integer(i8) function multiply_mod64(a, b) result(r)
      integer(i8), intent(in) :: a, b
      integer(i8) :: al(0:3), bl(0:3), column
      integer :: c, i

      al = limbs(a)
      bl = limbs(b)
      r = 0_i8
      column = 0_i8
      do c = 0, 3
         column = shiftr(column, 16)
         do i = 0, c
            column = column + al(i)*bl(c - i)
         end do
         r = ior(r, shiftl(iand(column, limb_mask), 16*c))
      end do
   end function multiply_mod64
end module lc_profiles_random
