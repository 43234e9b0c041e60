!> The convergence measure every contact solver stops on, and what bounds it: the
!> dimensionless complementarity residual of (p, gap), the rounding floor below which a
!> gap w - b computed through FFTs is noise, and the scaling of p to the load.
module lc_contact_residual
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   use lc_base_kinds, only: wp
   use lc_base_parallel, only: global_sum
   use lc_base_threads, only: parallel_points, reduction_blocks, block_range
   implicit none (type, external)
   private
   public :: complementarity_residual, field_residual, rounding_floor, normalise

contains

   !> max_j |min(p_j/p_ref, gap_j/g_ref)|: zero iff p >= 0, gap >= 0 and p gap = 0.
   !> Gaps within `g_floor` of zero count as zero: below that the gap is rounding noise of
   !> w - b (see rounding_floor), and no iteration can make it smaller.
   pure real(wp) function complementarity_residual(p, gap, p_ref, g_ref, g_floor) result(res)
      real(wp), intent(in) :: p(:), gap(:), p_ref, g_ref, g_floor
      real(wp) :: pscale
      integer :: j
      pscale = 1.0_wp/max(p_ref, tiny(1.0_wp))
      res = 0.0_wp
      do j = 1, size(p)
         if (abs(gap(j)) > g_floor) res = max(res, abs(min(p(j)*pscale, gap(j)/g_ref)))
         if (ieee_is_nan(gap(j)) .or. ieee_is_nan(p(j))) res = huge(1.0_wp)
         if (p(j) < 0.0_wp) res = max(res, -p(j)*pscale)
      end do
   end function complementarity_residual

   !> complementarity_residual by blocks on the solve's threads (a maximum: the same on any
   !> thread count).
   real(wp) function field_residual(p, gap, p_ref, g_ref, g_floor) result(res)
      real(wp), contiguous, intent(in) :: p(:), gap(:)
      real(wp), intent(in) :: p_ref, g_ref, g_floor
      real(wp) :: maxima(reduction_blocks(size(p)))
      integer :: block, first, last
      !$omp parallel do schedule(static) private(first, last) if(size(p) >= parallel_points)
      do block = 1, size(maxima)
         call block_range(block, size(p), first, last)
         maxima(block) = complementarity_residual(p(first:last), gap(first:last), p_ref, g_ref, g_floor)
      end do
      res = maxval(maxima)
   end function field_residual

   !> Attainable accuracy of a gap g = w - b with w = G p computed through FFTs: a few
   !> hundred ulps of the largest term, max|w|, max|b| or max|p| max_k|G(k)| (the rounding of
   !> the transforms of p; it dominates w when a large uniform pressure is nearly
   !> annihilated, as on a half-space in full contact). Matters only at extreme loads.
   pure real(wp) function rounding_floor(w_max, b_max, p_max, m_max) result(floor)
      real(wp), intent(in) :: w_max, b_max, p_max, m_max
      floor = 256*epsilon(1.0_wp)*max(w_max, b_max, p_max*m_max)
   end function rounding_floor

   !> Scale p to mean p_m (uniform if p vanished altogether); `across_ranks`: p is a slab of
   !> a field shared among the job's ranks (the mean over all of them).
   subroutine normalise(p, mean_pressure, across_ranks)
      real(wp), intent(inout) :: p(:)
      real(wp), intent(in) :: mean_pressure
      logical, intent(in), optional :: across_ranks
      real(wp) :: total, points
      total = sum(p)
      points = size(p)
      if (present(across_ranks)) then
         if (across_ranks) then
            total = global_sum(total)
            points = global_sum(points)
         end if
      end if
      if (total > 0.0_wp) then
         p = p*(mean_pressure*points/total)
      else
         p = mean_pressure
      end if
   end subroutine normalise

end module lc_contact_residual
