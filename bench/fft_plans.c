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
 *
 * With --buffers: the column pass alone (forward, every block of 8 columns), after a pass
 * over 64 MiB, the blocks shared out among --threads OpenMP threads (1): FFTW's plan for a
 * block in place at the stride n/2 + 1 (a buffered plan that allocates its buffers at
 * every execution), against each block copied row by row into a buffer of its thread and
 * transformed there (the library's, src/fft/plans.F90); wall-clock ms, the best of
 * --rounds (6), the two alternately, and the minor page faults of each:
 *
 *     cc -O2 -fopenmp bench/fft_plans.c -lfftw3 -o /tmp/fft_plans
 *     /tmp/fft_plans --buffers [--threads 2] [--rounds 6] 1024 2048
 */
#include <fftw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <stdint.h>
#include <sys/resource.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(_OPENMP)
#include <omp.h>
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

static double wall_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static long minor_faults(void) {
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_minflt;
}

static int thread_number(void) {
#if defined(_OPENMP)
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* ms of one forward column pass of an n x n half spectrum on `threads` threads: in place
 * (own_buffers 0) or through each thread's buffer (1); *faults gets its page faults */
static double column_pass(int n, int threads, int own_buffers, fftw_complex *c, fftw_complex *buffers,
                          double *flush, long *faults) {
    enum { block = 8 };
    int nk = n / 2 + 1, blocks = nk / block;
    fftw_plan plan = own_buffers
        ? fftw_plan_many_dft(1, &n, block, buffers, NULL, block, 1, buffers, NULL, block, 1, FFTW_FORWARD,
                             FFTW_ESTIMATE)
        : fftw_plan_many_dft(1, &n, block, c, NULL, nk, 1, c, NULL, nk, 1, FFTW_FORWARD,
                             FFTW_ESTIMATE | FFTW_UNALIGNED);
    for (size_t i = 0; i < ((size_t)64 << 20) / sizeof(double); i++) flush[i] += 1.0;
    long before = minor_faults();
    double start = wall_seconds();
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int b = 0; b < blocks; b++) {
        fftw_complex *first = c + (size_t)b * block;
        if (!own_buffers) {
            fftw_execute_dft(plan, first, first);
            continue;
        }
        fftw_complex *mine = buffers + (size_t)thread_number() * block * n;
        for (int row = 0; row < n; row++) memcpy(mine + (size_t)row * block, first + (size_t)row * nk, sizeof(fftw_complex) * block);
        fftw_execute_dft(plan, mine, mine);
        for (int row = 0; row < n; row++) memcpy(first + (size_t)row * nk, mine + (size_t)row * block, sizeof(fftw_complex) * block);
    }
    double t = wall_seconds() - start;
    *faults = minor_faults() - before;
    for (size_t i = 0; i < (size_t)n * nk; i++) {   /* back to the scale it started at */
        c[i][0] /= n;
        c[i][1] /= n;
    }
    fftw_destroy_plan(plan);
    return 1e3 * t;
}

/* --buffers: FFTW's buffered block in place against the library's buffers, alternately */
static int compare_buffers(int argc, char **argv) {
    int rounds = 6, threads = 1, a = 2;
    for (; a + 1 < argc && strncmp(argv[a], "--", 2) == 0; a += 2) {
        if (strcmp(argv[a], "--rounds") == 0) rounds = atoi(argv[a + 1]);
        else if (strcmp(argv[a], "--threads") == 0) threads = atoi(argv[a + 1]);
    }
    double *flush = calloc(((size_t)64 << 20) / sizeof(double), sizeof(double));
    if (!flush) return 1;
    printf("| n | threads | FFTW's block in place (ms) | page faults | own buffers (ms) | page faults | own / FFTW's |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|\n");
    for (; a < argc; a++) {
        int n = atoi(argv[a]), nk = n / 2 + 1;
        fftw_complex *c = fftw_alloc_complex((size_t)n * nk);
        fftw_complex *buffers = fftw_alloc_complex((size_t)8 * n * threads);
        advise_huge_pages(c, sizeof(fftw_complex) * n * nk);
        for (size_t i = 0; i < (size_t)n * nk; i++) {
            c[i][0] = rand() / (double)RAND_MAX;
            c[i][1] = rand() / (double)RAND_MAX;
        }
        memset(buffers, 0, sizeof(fftw_complex) * 8 * n * threads);
        double best[2] = {1e300, 1e300};
        long faults[2] = {0, 0}, f;
        for (int k = 0; k < rounds; k++)
            for (int v = 0; v < 2; v++) {
                double t = column_pass(n, threads, v, c, buffers, flush, &f);
                if (t < best[v]) best[v] = t;
                if (k == rounds - 1) faults[v] = f;
            }
        printf("| %d^2 | %d | %.2f | %ld | %.2f | %ld | %.3f |\n", n, threads, best[0], faults[0], best[1], faults[1],
               best[1] / best[0]);
        fflush(stdout);
        fftw_free(c);
        fftw_free(buffers);
    }
    free(flush);
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "--blocks") == 0) return compare_blocks(argc, argv);
    if (argc > 1 && strcmp(argv[1], "--buffers") == 0) return compare_buffers(argc, argv);
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
