/* The two-pass transform's block passes (src/fft/columns.c) against how many rows ahead
 * they ask for: every block of 8 adjacent columns of an n x n half spectrum copied into a
 * buffer row by row, multiplied by a real multiplier's same columns with its energy
 * summed, and copied back, as a product between the column transforms does (without the
 * transforms themselves, which do not depend on it). Each row of a block lies n/2 + 1
 * complex numbers from the last, on a new 4 KiB page. The spectrum and the multiplier
 * are on huge pages, as the library's; each sweep follows a pass over 64 MiB (as in a
 * solve, whose passes push them out of the cache); the best of --rounds (10) sweeps per
 * distance, the distances alternately.
 *
 *     cc -O2 -march=native bench/rows_ahead.c -o /tmp/rows_ahead && /tmp/rows_ahead 1024 2048
 */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void *huge(size_t bytes) {
    const size_t page = (size_t)2 << 20;
    void *p = aligned_alloc(page, (bytes + page - 1) / page * page);
    if (!p) exit(1);
    madvise(p, bytes, MADV_HUGEPAGE);
    memset(p, 0, bytes);
    return p;
}

/* One sweep over every block: copy in, product with energy, copy out. */
static double sweep(double *spectrum, const double *multiplier, double *block, int nkx, int ny, int ahead) {
    const int columns = 8;
    const ptrdiff_t stride = 2 * (ptrdiff_t)nkx, width = 2 * columns;
    double energy = 0.0;
    for (int first = 0; first + columns <= nkx; first += columns) {
        double *column = spectrum + 2 * (ptrdiff_t)first;
        const double *m0 = multiplier + first;
        for (int row = 0; row < ny; ++row) {
            if (ahead && row + ahead < ny) {
                __builtin_prefetch(column + (row + ahead) * stride);
                __builtin_prefetch(column + (row + ahead) * stride + width - 1);
            }
            memcpy(block + row * width, column + row * stride, width * sizeof(double));
        }
        for (int row = 0; row < ny; ++row) {
            const double *m = m0 + (ptrdiff_t)row * nkx;
            double *b = block + row * width;
            if (ahead && row + ahead < ny) {
                __builtin_prefetch(m + (ptrdiff_t)ahead * nkx);
                __builtin_prefetch(m + (ptrdiff_t)ahead * nkx + columns - 1);
            }
            for (int c = 0; c < columns; ++c) {
                const double f = m[c], re = b[2 * c], im = b[2 * c + 1];
                energy += f * (re * re + im * im);
                b[2 * c] = re * f;
                b[2 * c + 1] = im * f;
            }
        }
        for (int row = 0; row < ny; ++row) {
            if (ahead && row + ahead < ny) {
                __builtin_prefetch(column + (row + ahead) * stride, 1);
                __builtin_prefetch(column + (row + ahead) * stride + width - 1, 1);
            }
            memcpy(column + row * stride, block + row * width, width * sizeof(double));
        }
    }
    return energy;
}

int main(int argc, char **argv) {
    static const int distances[] = {0, 2, 4, 8, 16, 32};
    const int count = sizeof distances / sizeof distances[0];
    int rounds = 10, first_size = 1;
    if (argc > 2 && strcmp(argv[1], "--rounds") == 0) {
        rounds = atoi(argv[2]);
        first_size = 3;
    }
    if (first_size >= argc) {
        fprintf(stderr, "usage: %s [--rounds R] n [n ...]\n", argv[0]);
        return 2;
    }
    const size_t flush_bytes = (size_t)64 << 20;
    char *flush = huge(flush_bytes);
    printf("| n | rows ahead | sweep (ms) | against none |\n|---:|---:|---:|---:|\n");
    for (int a = first_size; a < argc; ++a) {
        const int n = atoi(argv[a]), nkx = n / 2 + 1, ny = n;
        double *spectrum = huge(sizeof(double) * 2 * (size_t)nkx * ny);
        double *multiplier = huge(sizeof(double) * (size_t)nkx * ny);
        double *block = huge(sizeof(double) * 2 * 8 * (size_t)ny);
        for (size_t i = 0; i < (size_t)nkx * ny; ++i) {
            spectrum[2 * i] = 1e-3 * (double)(i % 101);
            spectrum[2 * i + 1] = 1.0;
            multiplier[i] = 1.0 / (1.0 + (double)(i % 37) / 37.0);   /* in (0.5, 1]: no underflow over many sweeps */
        }
        double best[sizeof distances / sizeof distances[0]], check = 0.0;
        for (int d = 0; d < count; ++d) best[d] = 1e30;
        for (int r = 0; r < rounds; ++r) {
            for (int d = 0; d < count; ++d) {
                memset(flush, r + d, flush_bytes);
                const double t0 = now();
                check += sweep(spectrum, multiplier, block, nkx, ny, distances[d]);
                const double t = now() - t0;
                if (t < best[d]) best[d] = t;
            }
        }
        for (int d = 0; d < count; ++d)
            printf("| %d | %d | %.2f | %.2f |\n", n, distances[d], 1e3 * best[d], best[d] / best[0]);
        if (check == 42.0) printf("\n");
        free(spectrum);
        free(multiplier);
        free(block);
    }
    free(flush);
    return 0;
}
