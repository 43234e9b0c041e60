/* The block passes of a two-pass surface transform (lc_fft_plans): a block of `columns`
 * adjacent columns of the half spectrum (nkx columns, ny rows, a row's columns adjacent)
 * copied into a thread's buffer and back, and an operator's product on that block.
 *
 * Each row of a block lies nkx complex numbers (8 KiB at nx = 1024) from the last, on a
 * new 4 KiB page: the hardware prefetchers do not cross pages, so without help every row
 * of the spectrum and of the multiplier waits for memory in turn. These loops ask for the
 * row `rows_ahead` rows on while they work on this one (docs/decisions/024-fft-floor.md,
 * 'Rows fetched ahead'). The arithmetic is that of the Fortran expressions they replace:
 * the same products, so the same bits. */
#include <stddef.h>

/* Far enough ahead to cover a memory access at a row's work; more gains nothing. */
enum { rows_ahead = 8 };

/* block(c, row) <- spectrum(first + c, row) (into_block != 0), or back; first 1-based. */
void lc_copy_columns(double *spectrum, int nkx, int ny, int first, int columns, double *block, int into_block) {
    const ptrdiff_t stride = 2 * (ptrdiff_t)nkx, width = 2 * (ptrdiff_t)columns;
    double *column = spectrum + 2 * (ptrdiff_t)(first - 1);
    for (int row = 0; row < ny; ++row) {
        double *from = column + row * stride, *to = block + row * width;
        if (row + rows_ahead < ny) {
            /* the row's first and last bytes: its cache lines, 128 bytes for 8 columns */
            __builtin_prefetch(from + rows_ahead * stride);
            __builtin_prefetch(from + rows_ahead * stride + width - 1);
        }
        if (into_block) {
            for (ptrdiff_t k = 0; k < width; ++k) to[k] = from[k];
        } else {
            for (ptrdiff_t k = 0; k < width; ++k) from[k] = to[k];
        }
    }
}

/* block(c, row) <- block(c, row) * (multiplier(first + c, row) * scale), a real multiplier
 * of nkx x ny values; with `weights` (one per column of the block), *energy = the sum of
 * weights(c) f |block(c, row)|^2 before the product, f = multiplier * scale. */
void lc_multiply_columns_real(double *block, int columns, int ny, const double *multiplier, int nkx, int first,
                              double scale, const double *weights, double *energy) {
    const double *column = multiplier + (first - 1);
    double sum = 0.0;
    for (int row = 0; row < ny; ++row) {
        const double *m = column + (ptrdiff_t)row * nkx;
        double *b = block + 2 * (ptrdiff_t)row * columns;
        if (row + rows_ahead < ny) {
            __builtin_prefetch(m + (ptrdiff_t)rows_ahead * nkx);
            __builtin_prefetch(m + (ptrdiff_t)rows_ahead * nkx + columns - 1);
        }
        if (weights) {
            for (int c = 0; c < columns; ++c) {
                const double f = m[c] * scale, re = b[2 * c], im = b[2 * c + 1];
                sum += weights[c] * f * (re * re + im * im);
                b[2 * c] = re * f;
                b[2 * c + 1] = im * f;
            }
        } else {
            for (int c = 0; c < columns; ++c) {
                const double f = m[c] * scale;
                b[2 * c] *= f;
                b[2 * c + 1] *= f;
            }
        }
    }
    if (weights) *energy = sum;
}

/* The same with a complex multiplier (pairs of doubles), without the energy. */
void lc_multiply_columns_complex(double *block, int columns, int ny, const double *multiplier, int nkx, int first,
                                 double scale) {
    const double *column = multiplier + 2 * (ptrdiff_t)(first - 1);
    for (int row = 0; row < ny; ++row) {
        const double *m = column + 2 * (ptrdiff_t)row * nkx;
        double *b = block + 2 * (ptrdiff_t)row * columns;
        if (row + rows_ahead < ny) {
            __builtin_prefetch(m + 2 * (ptrdiff_t)rows_ahead * nkx);
            __builtin_prefetch(m + 2 * (ptrdiff_t)rows_ahead * nkx + 2 * columns - 1);
        }
        for (int c = 0; c < columns; ++c) {
            const double mr = m[2 * c] * scale, mi = m[2 * c + 1] * scale, re = b[2 * c], im = b[2 * c + 1];
            b[2 * c] = re * mr - im * mi;
            b[2 * c + 1] = re * mi + im * mr;
        }
    }
}
