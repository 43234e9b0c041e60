/* Large arrays on transparent huge pages (lc_base_pages): madvise(MADV_HUGEPAGE) on the
 * 2 MiB pages that lie wholly inside [start, start + bytes). Where the kernel's setting is
 * "madvise" (the default of several distributions) an array is otherwise first touched
 * 4 KiB at a time: a page fault each, 512 per huge page. Nothing happens elsewhere (not
 * Linux, THP off): the advice is only a hint, and the array's contents are untouched. */
#include <stddef.h>
#include <stdint.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

void lc_advise_huge_pages(void *start, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    uintptr_t first = ((uintptr_t)start + huge - 1) & ~(huge - 1);
    uintptr_t last = ((uintptr_t)start + bytes) & ~(huge - 1);
    if (last > first) (void)madvise((void *)first, last - first, MADV_HUGEPAGE);
#else
    (void)start;
    (void)bytes;
#endif
}
