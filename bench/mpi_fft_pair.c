/* One r2c + c2r pair of an nx x ny surface (bench/mpi.py): FFTW's serial 2D plan, and
 * FFTW-MPI's plans on the ranks of the job, in the natural layout (the spectrum by rows,
 * as lc_fft_plans keeps it; with and without the row copies into FFTW-MPI's padded real
 * array that the library makes around each transform) and with FFTW_MPI_TRANSPOSED_OUT/IN
 * (the spectrum by columns kx: two transposes a pair fewer), the latter also with the copies
 * and with the copies and an r2c that may destroy its input (FFTW_DESTROY_INPUT, as the
 * library plans it: FFTW-MPI then transposes out of place, with no buffer allocated at each
 * execution). FFTW_ESTIMATE, as the library. Then the library's own pairs: "own stages", its
 * stages around FFTW-MPI's transposes (forward and backward), and, on several ranks, "own
 * exchanges", a product's stages around MPI_Alltoallv of whole blocks (convolve), with the
 * time of each stage on rank 0.
 *
 *     mpicc -O2 bench/mpi_fft_pair.c -lfftw3_mpi -lfftw3 -o fft_pair && mpirun -n 2 ./fft_pair 2048 2048 10
 *
 * Prints one line per variant: the median over `repeats` pairs of the slowest rank (ms). */
#include <fftw3-mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int compare(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n) {
    qsort(t, n, sizeof *t, compare);
    return t[n / 2];
}

enum { BLOCK = 8 };

/* The library's pair in stages (see above), median over `repeats` pairs of the slowest rank.
 * exchange 0: FFTW-MPI's transposes between the stages; 1: the products' exchanges, whole
 * blocks by MPI_Alltoallv, the spectrum then by row slabs (rank s's rows of every column of
 * this rank together), each block of columns gathered into a buffer for its DFTs and put
 * back, and each block of rows gathered from the rows' spectra by column for its c2r.
 * stages (exchange 1): the median of each stage's time on rank 0, ms: the rows' r2c, the
 * exchange, the columns, the exchange back, the rows' c2r. */
static double own_stages(ptrdiff_t nx, ptrdiff_t ny, int repeats, double *times, int exchange, double *stages) {
    ptrdiff_t nkx = nx / 2 + 1, rows, row_start, cols, col_start;
    ptrdiff_t values = fftw_mpi_local_size_many_transposed(2, (ptrdiff_t[]){ny, nkx}, 2, FFTW_MPI_DEFAULT_BLOCK,
                                                           FFTW_MPI_DEFAULT_BLOCK, MPI_COMM_WORLD, &rows,
                                                           &row_start, &cols, &col_start);
    double *field = fftw_alloc_real(nx * rows + 1), *by_rows = fftw_alloc_real(values), *by_columns = fftw_alloc_real(values);
    fftw_complex *row_spectra = (fftw_complex *)by_rows, *spectrum = (fftw_complex *)by_columns;
    fftw_complex *buffer = fftw_alloc_complex(BLOCK * nkx), *columns = fftw_alloc_complex(BLOCK * ny);
    int size, rank;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    /* the exchanges' counts and offsets (complex numbers), and each rank's first row and rows */
    int *column_counts = malloc(4 * sizeof(int) * size), *column_offsets = column_counts + size,
        *slab_counts = column_counts + 2 * size, *slab_offsets = column_counts + 3 * size;
    ptrdiff_t *slab_first = malloc(2 * sizeof(ptrdiff_t) * size), *slab_rows = slab_first + size;
    for (int q = 0; q < size; ++q) {
        ptrdiff_t row_block = (ny + size - 1) / size, column_block = (nkx + size - 1) / size;
        ptrdiff_t x_first = q * column_block < nkx ? q * column_block : nkx;
        ptrdiff_t x_count = nkx - x_first < column_block ? nkx - x_first : column_block;
        slab_first[q] = q * row_block < ny ? q * row_block : ny;
        slab_rows[q] = ny - slab_first[q] < row_block ? ny - slab_first[q] : row_block;
        column_counts[q] = (int)(x_count * rows);
        column_offsets[q] = (int)(x_first * rows);
        slab_counts[q] = (int)(cols * slab_rows[q]);
        slab_offsets[q] = (int)(cols * slab_first[q]);
    }
    /* this rank's own block (its rows of its columns) lies in row_spectra as the spectrum
     * would hold it: it is not sent, and the columns' stage reads and writes it there */
    fftw_complex *own_block = row_spectra + column_offsets[rank];
    column_counts[rank] = slab_counts[rank] = 0;
    double *stage_times = malloc(sizeof(double) * 5 * repeats);
    memset(field, 0, sizeof(double) * (nx * rows + 1));
    memset(by_rows, 0, sizeof(double) * values);
    memset(by_columns, 0, sizeof(double) * values);
    int n[] = {(int)nx}, m[] = {(int)ny}, last_rows = (int)(rows % BLOCK), last_cols = (int)(cols % BLOCK);
    fftw_plan to_columns = fftw_mpi_plan_many_transpose(ny, nkx, 2, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                                                        by_rows, by_columns, MPI_COMM_WORLD,
                                                        FFTW_ESTIMATE | FFTW_MPI_TRANSPOSED_IN);
    fftw_plan to_rows = fftw_mpi_plan_many_transpose(nkx, ny, 2, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                                                     by_columns, by_rows, MPI_COMM_WORLD,
                                                     FFTW_ESTIMATE | FFTW_DESTROY_INPUT);
    fftw_plan c2r = fftw_plan_many_dft_c2r(1, n, (int)rows, row_spectra, NULL, 1, (int)nkx, field, NULL, 1, (int)nx,
                                           FFTW_ESTIMATE | FFTW_DESTROY_INPUT);
    fftw_plan r2c[2], rows_c2r[2], forward[2] = {0, 0}, backward[2] = {0, 0};
    for (int last = 0; last < 2; ++last) {
        int count = last ? last_rows : (int)(rows < BLOCK ? rows : BLOCK);
        r2c[last] = count ? fftw_plan_many_dft_r2c(1, n, count, field, NULL, 1, (int)nx, buffer, NULL, count, 1,
                                                   FFTW_ESTIMATE) : 0;
        rows_c2r[last] = count ? fftw_plan_many_dft_c2r(1, n, count, buffer, (int[]){(int)nkx}, count, 1, field, NULL, 1,
                                                        (int)nx, FFTW_ESTIMATE | FFTW_DESTROY_INPUT) : 0;
        count = last ? last_cols : (int)(cols < BLOCK ? cols : BLOCK);
        if (count) {
            fftw_complex *at = exchange ? columns : spectrum;
            forward[last] = fftw_plan_many_dft(1, m, count, at, NULL, 1, (int)ny, at, NULL, 1, (int)ny,
                                               FFTW_FORWARD, FFTW_ESTIMATE | FFTW_NO_BUFFERING);
            backward[last] = fftw_plan_many_dft(1, m, count, at, NULL, 1, (int)ny, at, NULL, 1, (int)ny,
                                                FFTW_BACKWARD, FFTW_ESTIMATE | FFTW_NO_BUFFERING);
        }
    }
    for (int k = -1; k < repeats; ++k) {
        double t, slowest;
        MPI_Barrier(MPI_COMM_WORLD);
        t = MPI_Wtime();
        for (ptrdiff_t first = 0; first < rows; first += BLOCK) {
            int count = rows - first < BLOCK ? (int)(rows - first) : BLOCK, last = count < BLOCK;
            fftw_execute_dft_r2c(r2c[last], field + first * nx, buffer);
            for (ptrdiff_t kx = 0; kx < nkx; ++kx)   /* row r's mode kx at buffer[kx*count + r] */
                memcpy(row_spectra + kx * rows + first, buffer + kx * count, sizeof(fftw_complex) * count);
        }
        double mark[6];
        mark[0] = t;
        mark[1] = MPI_Wtime();
        if (!exchange) {
            fftw_mpi_execute_r2r(to_columns, by_rows, by_columns);
            for (int direction = 0; direction < 2; ++direction)
                for (ptrdiff_t first = 0; first < cols; first += BLOCK) {
                    int last = cols - first < BLOCK;
                    fftw_plan plan = direction ? backward[last] : forward[last];
                    fftw_execute_dft(plan, spectrum + first * ny, spectrum + first * ny);
                }
            fftw_mpi_execute_r2r(to_rows, by_columns, by_rows);
            fftw_execute_dft_c2r(c2r, row_spectra, field);
        } else {
            MPI_Alltoallv(row_spectra, column_counts, column_offsets, MPI_C_DOUBLE_COMPLEX, spectrum, slab_counts,
                          slab_offsets, MPI_C_DOUBLE_COMPLEX, MPI_COMM_WORLD);
            mark[2] = MPI_Wtime();
            for (ptrdiff_t first = 0; first < cols; first += BLOCK) {
                int count = cols - first < BLOCK ? (int)(cols - first) : BLOCK, last = count < BLOCK;
                for (int into = 1; into >= 0; --into) {
                    for (int s = 0; s < size; ++s)
                        for (int c = 0; c < count; ++c) {
                            fftw_complex *slab = (s == rank ? own_block : spectrum + slab_offsets[s]) +
                                                 (first + c) * slab_rows[s];
                            fftw_complex *column = columns + c * ny + slab_first[s];
                            if (into) memcpy(column, slab, sizeof(fftw_complex) * slab_rows[s]);
                            else memcpy(slab, column, sizeof(fftw_complex) * slab_rows[s]);
                        }
                    if (into) {
                        fftw_execute_dft(forward[last], columns, columns);
                        fftw_execute_dft(backward[last], columns, columns);
                    }
                }
            }
            mark[3] = MPI_Wtime();
            MPI_Alltoallv(spectrum, slab_counts, slab_offsets, MPI_C_DOUBLE_COMPLEX, row_spectra, column_counts,
                          column_offsets, MPI_C_DOUBLE_COMPLEX, MPI_COMM_WORLD);
            mark[4] = MPI_Wtime();
            for (ptrdiff_t first = 0; first < rows; first += BLOCK) {
                int count = rows - first < BLOCK ? (int)(rows - first) : BLOCK, last = count < BLOCK;
                for (ptrdiff_t kx = 0; kx < nkx; ++kx)
                    memcpy(buffer + kx * count, row_spectra + kx * rows + first, sizeof(fftw_complex) * count);
                fftw_execute_dft_c2r(rows_c2r[last], buffer, field + first * nx);
            }
            mark[5] = MPI_Wtime();
            if (k >= 0)
                for (int stage = 0; stage < 5; ++stage) stage_times[stage * repeats + k] = mark[stage + 1] - mark[stage];
        }
        t = MPI_Wtime() - t;
        MPI_Allreduce(&t, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        if (k >= 0) times[k] = slowest;
    }
    fftw_destroy_plan(to_columns);
    fftw_destroy_plan(to_rows);
    fftw_destroy_plan(c2r);
    for (int last = 0; last < 2; ++last) {
        if (r2c[last]) fftw_destroy_plan(r2c[last]);
        if (rows_c2r[last]) fftw_destroy_plan(rows_c2r[last]);
        if (forward[last]) fftw_destroy_plan(forward[last]);
        if (backward[last]) fftw_destroy_plan(backward[last]);
    }
    fftw_free(field);
    fftw_free(by_rows);
    fftw_free(by_columns);
    fftw_free(buffer);
    fftw_free(columns);
    if (exchange)
        for (int stage = 0; stage < 5; ++stage) stages[stage] = 1e3 * median(stage_times + stage * repeats, repeats);
    free(stage_times);
    free(column_counts);
    free(slab_first);
    return median(times, repeats);
}

int main(int argc, char **argv) {
    int rank, size, repeats;
    ptrdiff_t nx, ny, nkx, local_complex, local_rows, local_start, local_cols, local_col_start;
    MPI_Init(&argc, &argv);
    fftw_mpi_init();
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    nx = argc > 1 ? atol(argv[1]) : 2048;
    ny = argc > 2 ? atol(argv[2]) : nx;
    repeats = argc > 3 ? atoi(argv[3]) : 10;
    nkx = nx / 2 + 1;
    double *times = malloc(sizeof(double) * repeats);

    if (size == 1) {   /* the serial plan */
        double *real = fftw_alloc_real(nx * ny);
        fftw_complex *spectrum = fftw_alloc_complex(nkx * ny);
        memset(real, 0, sizeof(double) * nx * ny);
        fftw_plan r2c = fftw_plan_dft_r2c_2d(ny, nx, real, spectrum, FFTW_ESTIMATE);
        fftw_plan c2r = fftw_plan_dft_c2r_2d(ny, nx, spectrum, real, FFTW_ESTIMATE | FFTW_DESTROY_INPUT);
        for (int k = -1; k < repeats; ++k) {
            double t = MPI_Wtime();
            fftw_execute(r2c);
            fftw_execute(c2r);
            if (k >= 0) times[k] = MPI_Wtime() - t;
        }
        printf("serial plan        %ld x %ld  1 rank   %9.2f ms\n", (long)nx, (long)ny, 1e3 * median(times, repeats));
        fftw_destroy_plan(r2c);
        fftw_destroy_plan(c2r);
        fftw_free(real);
        fftw_free(spectrum);
    }

    static const char *names[] = {"mpi rows", "mpi rows + copies", "mpi transposed", "transposed + copies",
                                  "+ input destroyed"};
    for (int variant = 0; variant < 5; ++variant) {
        int transposed = variant >= 2, copies = variant == 1 || variant >= 3, destroy = variant == 4;
        if (transposed)
            local_complex = fftw_mpi_local_size_2d_transposed(ny, nkx, MPI_COMM_WORLD, &local_rows, &local_start,
                                                              &local_cols, &local_col_start);
        else
            local_complex = fftw_mpi_local_size_2d(ny, nkx, MPI_COMM_WORLD, &local_rows, &local_start);
        double *padded = fftw_alloc_real(2 * local_complex);
        double *rows = fftw_alloc_real(nx * local_rows + 1);
        fftw_complex *spectrum = fftw_alloc_complex(local_complex);
        memset(padded, 0, sizeof(double) * 2 * local_complex);
        memset(rows, 0, sizeof(double) * (nx * local_rows + 1));
        unsigned out = transposed ? FFTW_MPI_TRANSPOSED_OUT : 0, in = transposed ? FFTW_MPI_TRANSPOSED_IN : 0;
        fftw_plan r2c = fftw_mpi_plan_dft_r2c_2d(ny, nx, padded, spectrum, MPI_COMM_WORLD,
                                                 FFTW_ESTIMATE | (destroy ? FFTW_DESTROY_INPUT : 0) | out);
        fftw_plan c2r = fftw_mpi_plan_dft_c2r_2d(ny, nx, spectrum, padded, MPI_COMM_WORLD,
                                                 FFTW_ESTIMATE | FFTW_DESTROY_INPUT | in);
        for (int k = -1; k < repeats; ++k) {
            double t, slowest;
            MPI_Barrier(MPI_COMM_WORLD);
            t = MPI_Wtime();
            if (copies)
                for (ptrdiff_t j = 0; j < local_rows; ++j) memcpy(padded + j * 2 * nkx, rows + j * nx, sizeof(double) * nx);
            fftw_execute(r2c);
            fftw_execute(c2r);
            if (copies)
                for (ptrdiff_t j = 0; j < local_rows; ++j) memcpy(rows + j * nx, padded + j * 2 * nkx, sizeof(double) * nx);
            t = MPI_Wtime() - t;
            MPI_Allreduce(&t, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            if (k >= 0) times[k] = slowest;
        }
        if (rank == 0)
            printf("%-19s %ld x %ld  %d rank%s %9.2f ms\n", names[variant], (long)nx, (long)ny, size,
                   size == 1 ? " " : "s", 1e3 * median(times, repeats));
        fftw_destroy_plan(r2c);
        fftw_destroy_plan(c2r);
        fftw_free(padded);
        fftw_free(rows);
        fftw_free(spectrum);
    }
    double staged = own_stages(nx, ny, repeats, times, 0, NULL), stages[5];
    if (rank == 0)
        printf("%-19s %ld x %ld  %d rank%s %9.2f ms\n", "own stages", (long)nx, (long)ny, size, size == 1 ? " " : "s",
               1e3 * staged);
    if (size > 1) {
        double exchanged = own_stages(nx, ny, repeats, times, 1, stages);
        if (rank == 0)
            printf("%-19s %ld x %ld  %d ranks %9.2f ms (rows %.2f, exchange %.2f, columns %.2f, back %.2f, "
                   "rows %.2f on rank 0)\n", "own exchanges", (long)nx, (long)ny, size, 1e3 * exchanged, stages[0],
                   stages[1], stages[2], stages[3], stages[4]);
    }
    free(times);
    fftw_mpi_cleanup();
    MPI_Finalize();
    return 0;
}
