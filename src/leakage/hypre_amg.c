/* hypre's BoomerAMG as the preconditioner of the Reynolds leakage solve (lc_leakage_reynolds):
 * set up on the symmetric matrix of the free cells (IJ interface), applied as one V-cycle per
 * call from the conjugate gradients of the Fortran core, then freed. One at a time.
 *
 * Debian's hypre is built with MPI. MPI is started here only when a preconditioner is
 * first needed (a singleton start: no mpirun), and finished at exit if it was started here,
 * so that runs that compute no leakage never touch MPI. Everything runs on MPI_COMM_SELF.
 */
#include <malloc.h>
#include <stdlib.h>
#include <string.h>
#include <mpi.h>
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_mv.h>

static int mpi_started_here = 0;
static int hypre_started = 0;

/* Loading Debian's hypre loads SuperLU_DIST, whose initialisation turns off glibc's mmap for
 * large blocks and the trimming of the heap (mallopt M_MMAP_MAX 0, M_TRIM_THRESHOLD -1): every
 * array then comes from the heap and stays there when freed, and a coupled 2048^2 solve
 * peaked 140 MiB higher (docs/decisions/006). Both are set back to glibc's default values
 * (which also fixes the mmap threshold at its default of 128 KiB instead of letting it grow)
 * when this library is loaded (after its dependencies) and again after MPI and hypre start;
 * nothing here needs the other setting. */
static void malloc_defaults(void) {
    mallopt(M_MMAP_MAX, 65536);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
}

__attribute__((constructor)) static void malloc_defaults_at_load(void) { malloc_defaults(); }

void lc_hypre_free(void);

static void finish_at_exit(void) {
    int finalized = 0;
    lc_hypre_free();
    if (hypre_started) HYPRE_Finalize();
    MPI_Finalized(&finalized);
    if (mpi_started_here && !finalized) MPI_Finalize();
}

/* 1 if MPI runs in this process (started by a first preconditioner, or by the caller). */
int lc_hypre_mpi_started(void) {
    int initialized = 0;
    MPI_Initialized(&initialized);
    return initialized;
}

/* Start MPI (if nobody did) and hypre, once per process; 0 on success. */
static int start(void) {
    int initialized = 0, provided = 0;
    if (hypre_started) return 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
        if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) return 1;
        mpi_started_here = 1;
        atexit(finish_at_exit);
    }
    if (HYPRE_Init() != 0) return 2;
    hypre_started = 1;
    malloc_defaults();
    return 0;
}

/* The live preconditioner. */
static struct {
    int live;
    int n;
    HYPRE_IJMatrix ij_a;
    HYPRE_IJVector ij_b, ij_x;
    HYPRE_ParCSRMatrix par_a;
    HYPRE_ParVector par_b, par_x;
    HYPRE_Solver solver;
} amg = {0};

void lc_hypre_free(void) {
    if (!amg.live) return;
    HYPRE_BoomerAMGDestroy(amg.solver);
    HYPRE_IJMatrixDestroy(amg.ij_a);
    HYPRE_IJVectorDestroy(amg.ij_b);
    HYPRE_IJVectorDestroy(amg.ij_x);
    amg.live = 0;
}

static HYPRE_IJVector ij_vector(int n, HYPRE_ParVector *par) {
    HYPRE_IJVector v;
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &v);
    HYPRE_IJVectorSetObjectType(v, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(v);
    HYPRE_IJVectorAssemble(v);
    HYPRE_IJVectorGetObject(v, (void **)par);
    return v;
}

/* BoomerAMG of the symmetric matrix of n > 0 rows in CSR form (zero-based). 0 on success. */
int lc_hypre_setup_boomeramg(int n, const int *row_start, const int *column, const double *value,
                             double strength) {
    int i, status;
    int *sizes, *rows;
    if ((status = start()) != 0) return status;
    lc_hypre_free();
    sizes = malloc(sizeof(int) * (size_t)n);
    rows = malloc(sizeof(int) * (size_t)n);
    if (!sizes || !rows) {
        free(sizes);
        free(rows);
        return 3;
    }
    for (i = 0; i < n; i++) {
        sizes[i] = row_start[i + 1] - row_start[i];
        rows[i] = i;
    }
    amg.n = n;
    HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &amg.ij_a);
    HYPRE_IJMatrixSetObjectType(amg.ij_a, HYPRE_PARCSR);
    HYPRE_IJMatrixSetRowSizes(amg.ij_a, sizes);
    HYPRE_IJMatrixInitialize(amg.ij_a);
    HYPRE_IJMatrixSetValues(amg.ij_a, n, sizes, rows, column, value);
    HYPRE_IJMatrixAssemble(amg.ij_a);
    HYPRE_IJMatrixGetObject(amg.ij_a, (void **)&amg.par_a);
    free(sizes);
    free(rows);
    amg.ij_b = ij_vector(n, &amg.par_b);
    amg.ij_x = ij_vector(n, &amg.par_x);

    HYPRE_BoomerAMGCreate(&amg.solver);
    amg.live = 1;
    HYPRE_BoomerAMGSetPrintLevel(amg.solver, 0);
    HYPRE_BoomerAMGSetMaxIter(amg.solver, 1); /* one V-cycle: a preconditioner */
    HYPRE_BoomerAMGSetTol(amg.solver, 0.0);
    /* Settings measured on gaps near percolation (docs/decisions/006-leakage-in-the-core.md):
     * HMIS coarsening with extended+i interpolation truncated to 3 entries per row, and one
     * level of aggressive coarsening (multipass interpolation), which halves the setup for a
     * few more CG iterations. Forward Gauss-Seidel down and backward up make the V-cycle
     * symmetric, as CG needs, at half the sweeps of a symmetric smoother on both sides;
     * Gaussian elimination on the coarsest level. */
    HYPRE_BoomerAMGSetStrongThreshold(amg.solver, strength);
    HYPRE_BoomerAMGSetCoarsenType(amg.solver, 10);
    HYPRE_BoomerAMGSetInterpType(amg.solver, 6);
    HYPRE_BoomerAMGSetPMaxElmts(amg.solver, 3);
    HYPRE_BoomerAMGSetAggNumLevels(amg.solver, 1);
    HYPRE_BoomerAMGSetAggInterpType(amg.solver, 4);
    HYPRE_BoomerAMGSetNumSweeps(amg.solver, 1);
    HYPRE_BoomerAMGSetCycleRelaxType(amg.solver, 3, 1);
    HYPRE_BoomerAMGSetCycleRelaxType(amg.solver, 4, 2);
    HYPRE_BoomerAMGSetCycleRelaxType(amg.solver, 9, 3);
    status = HYPRE_BoomerAMGSetup(amg.solver, amg.par_a, amg.par_b, amg.par_x);
    return status == 0 ? 0 : 4;
}

/* z = M^-1 r: one V-cycle from a zero guess (n values, as set up). */
int lc_hypre_apply(const double *r, double *z) {
    if (!amg.live) return 5;
    memcpy(hypre_VectorData(hypre_ParVectorLocalVector(amg.par_b)), r, sizeof(double) * (size_t)amg.n);
    HYPRE_ParVectorSetConstantValues(amg.par_x, 0.0);
    HYPRE_BoomerAMGSolve(amg.solver, amg.par_a, amg.par_b, amg.par_x);
    memcpy(z, hypre_VectorData(hypre_ParVectorLocalVector(amg.par_x)), sizeof(double) * (size_t)amg.n);
    HYPRE_ClearAllErrors(); /* "not converged" after one cycle is the intent */
    return 0;
}
