/* Time of one r2c + c2r pair of an n x n surface with three FFTW plans: the 2D plan under
 * FFTW_ESTIMATE (what the library used for every surface), the same under FFTW_MEASURE
 * (planned by timing: 0.3-0.9 s, and a plan that may differ from run to run), and the
 * library's two-pass transform for large surfaces (src/fft/plans.F90: rows, then blocks of
 * 16 adjacent columns of the half spectrum where 16 columns hold at most 256 KiB, else 8;
 * all under FFTW_ESTIMATE). CPU time of the
 * process, 20 pairs after one.
 *
 *     cc -O2 bench/fft_plans.c -lfftw3 -o /tmp/fft_plans && /tmp/fft_plans 512 640 1024 2048
 *
 * With --blocks: the two-pass transform with blocks of 8 and of 16 columns, on buffers
 * advised as huge pages (as the library's), each pair after a pass over 64 MiB (as a
 * solve's pairs, whose buffers the passes between them have pushed out of the cache);
 * the two alternately, --rounds rounds (5), the best of each:
 *
 *     /tmp/fft_plans --blocks [--rounds 5] 1024 2048
 */
#include <fftw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <stdint.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

enum { repeats = 20 };

/* the library's block of columns for n rows (src/fft/plans.F90: block_bytes) */
static int library_block(int n) { return 16L * n * 16 <= 262144 ? 16 : 8; }

/* madvise(MADV_HUGEPAGE) on the 2 MiB pages inside [p, p + bytes), as src/base/pages.c */
static void advise_huge_pages(void *p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    uintptr_t first = ((uintptr_t)p + huge - 1) & ~(huge - 1), last = ((uintptr_t)p + bytes) & ~(huge - 1);
    if (last > first) (void)madvise((void *)first, last - first, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

static double cpu_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void fill(double *r, size_t n) {
    for (size_t i = 0; i < n; i++) r[i] = rand() / (double)RAND_MAX;
}

/* ms per pair of the 2D plan with the given planner flag; *planning gets the planning time */
static double plan_2d(int n, unsigned flag, double *planning) {
    double *r = fftw_alloc_real((size_t)n * n);
    fftw_complex *c = fftw_alloc_complex((size_t)n * (n / 2 + 1));
    double t = cpu_seconds();
    fftw_plan forward = fftw_plan_dft_r2c_2d(n, n, r, c, flag);
    fftw_plan backward = fftw_plan_dft_c2r_2d(n, n, c, r, flag | FFTW_DESTROY_INPUT);
    *planning = cpu_seconds() - t;
    fill(r, (size_t)n * n);
    fftw_execute(forward);
    fftw_execute(backward);
    t = cpu_seconds();
    for (int k = 0; k < repeats; k++) {
        fftw_execute(forward);
        fftw_execute(backward);
    }
    t = (cpu_seconds() - t) / repeats;
    fftw_destroy_plan(forward);
    fftw_destroy_plan(backward);
    fftw_free(r);
    fftw_free(c);
    return 1e3 * t;
}

/* ms per pair of the two-pass transform with blocks of `block` columns; `flush` (64 MiB
 * or NULL): a pass over it before each pair, whose time is not counted */
static double two_pass(int n, int block, double *flush) {
    int nk = n / 2 + 1, last = nk % block;
    double *r = fftw_alloc_real((size_t)n * n);
    fftw_complex *c = fftw_alloc_complex((size_t)n * nk);
    advise_huge_pages(r, sizeof(double) * n * n);
    advise_huge_pages(c, sizeof(fftw_complex) * n * nk);
    unsigned column = FFTW_ESTIMATE | FFTW_UNALIGNED;
    fftw_plan rows = fftw_plan_many_dft_r2c(1, &n, n, r, NULL, 1, n, c, NULL, 1, nk, FFTW_ESTIMATE);
    fftw_plan rows_back = fftw_plan_many_dft_c2r(1, &n, n, c, NULL, 1, nk, r, NULL, 1, n,
                                                 FFTW_ESTIMATE | FFTW_DESTROY_INPUT);
    fftw_plan cols[2][2] = {{NULL, NULL}, {NULL, NULL}};
    for (int d = 0; d < 2; d++) {
        int sign = d ? FFTW_BACKWARD : FFTW_FORWARD;
        cols[d][0] = fftw_plan_many_dft(1, &n, block, c, NULL, nk, 1, c, NULL, nk, 1, sign, column);
        if (last) cols[d][1] = fftw_plan_many_dft(1, &n, last, c, NULL, nk, 1, c, NULL, nk, 1, sign, column);
    }
    fill(r, (size_t)n * n);
    double t = 0, start = 0;
    for (int k = 0; k <= repeats; k++) {
        if (flush) {
            for (size_t i = 0; i < ((size_t)64 << 20) / sizeof(double); i++) flush[i] += 1.0;
        }
        start = cpu_seconds();
        fftw_execute(rows);
        for (int d = 0; d < 2; d++) {
            int m = 0;
            for (; m + block <= nk; m += block) fftw_execute_dft(cols[d][0], c + m, c + m);
            if (last) fftw_execute_dft(cols[d][1], c + m, c + m);
        }
        fftw_execute(rows_back);
        if (k > 0) t += cpu_seconds() - start;
    }
    t /= repeats;
    fftw_destroy_plan(rows);
    fftw_destroy_plan(rows_back);
    for (int d = 0; d < 2; d++)
        for (int b = 0; b < 2; b++)
            if (cols[d][b]) fftw_destroy_plan(cols[d][b]);
    fftw_free(r);
    fftw_free(c);
    return 1e3 * t;
}

/* --blocks: blocks of 8 against 16, alternately, the best of `rounds` each */
static int compare_blocks(int argc, char **argv) {
    int rounds = 5, a = 2;
    if (argc > 3 && strcmp(argv[2], "--rounds") == 0) {
        rounds = atoi(argv[3]);
        a = 4;
    }
    double *flush = malloc((size_t)64 << 20);
    if (!flush) return 1;
    memset(flush, 0, (size_t)64 << 20);
    printf("| n | blocks of 8 (ms) | blocks of 16 (ms) | 16 / 8 |\n|---:|---:|---:|---:|\n");
    for (; a < argc; a++) {
        int n = atoi(argv[a]);
        double best[2] = {1e300, 1e300};
        for (int k = 0; k < rounds; k++)
            for (int b = 0; b < 2; b++) {
                double t = two_pass(n, b ? 16 : 8, flush);
                if (t < best[b]) best[b] = t;
            }
        printf("| %d^2 | %.2f | %.2f | %.3f |\n", n, best[0], best[1], best[1] / best[0]);
        fflush(stdout);
    }
    free(flush);
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "--blocks") == 0) return compare_blocks(argc, argv);
    printf("| n | 2D, ESTIMATE (ms) | 2D, MEASURE (ms) | MEASURE's planning (s) | two-pass, ESTIMATE (ms) |\n");
    printf("|---:|---:|---:|---:|---:|\n");
    for (int a = 1; a < argc; a++) {
        int n = atoi(argv[a]);
        double unused, planning;
        double estimate = plan_2d(n, FFTW_ESTIMATE, &unused);
        double measure = plan_2d(n, FFTW_MEASURE, &planning);
        printf("| %d^2 | %.2f | %.2f | %.2f | %.2f |\n", n, estimate, measure, planning, two_pass(n, library_block(n), NULL));
        fflush(stdout);
    }
    return 0;
}
