/* Algebraic multigrid preconditioners from hypre for the Reynolds leakage solve
 * (lc_leakage_solve): BoomerAMG on the compressed system of the free cells (IJ interface),
 * or PFMG on the whole periodic grid (Struct interface, identity rows outside the free
 * cells). One preconditioner at a time lives here: set up, applied as one V-cycle per call
 * from the conjugate gradients of the Fortran core, then freed.
 *
 * Debian's hypre is built with MPI. MPI is started here only when a preconditioner is
 * first needed (singleton start: no mpirun), and finished at exit if it was started here,
 * so that runs that compute no leakage never touch MPI. Everything runs on MPI_COMM_SELF.
 */
#include <stdlib.h>
#include <string.h>
#include <mpi.h>
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <HYPRE_struct_ls.h>
#include <_hypre_parcsr_mv.h>

static int mpi_started_here = 0;
static int hypre_started = 0;

static void finish_at_exit(void) {
    int finalized = 0;
    if (hypre_started) HYPRE_Finalize();
    MPI_Finalized(&finalized);
    if (mpi_started_here && !finalized) MPI_Finalize();
}

/* Start MPI (if nobody did) and hypre, once per process; 0 on success. */
int lc_hypre_start(void) {
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
    return 0;
}

/* The live preconditioner. */
static struct {
    int kind; /* 0 none, 1 BoomerAMG, 2 PFMG */
    int n;
    HYPRE_IJMatrix ij_a;
    HYPRE_IJVector ij_b, ij_x;
    HYPRE_ParCSRMatrix par_a;
    HYPRE_ParVector par_b, par_x;
    HYPRE_StructGrid grid;
    HYPRE_StructStencil stencil;
    HYPRE_StructMatrix s_a;
    HYPRE_StructVector s_b, s_x;
    HYPRE_Solver solver;
    int lower[2], upper[2];
} amg = {0};

void lc_hypre_free(void) {
    switch (amg.kind) {
    case 1:
        HYPRE_BoomerAMGDestroy(amg.solver);
        HYPRE_IJMatrixDestroy(amg.ij_a);
        HYPRE_IJVectorDestroy(amg.ij_b);
        HYPRE_IJVectorDestroy(amg.ij_x);
        break;
    case 2:
        HYPRE_StructPFMGDestroy(amg.solver);
        HYPRE_StructMatrixDestroy(amg.s_a);
        HYPRE_StructVectorDestroy(amg.s_b);
        HYPRE_StructVectorDestroy(amg.s_x);
        HYPRE_StructStencilDestroy(amg.stencil);
        HYPRE_StructGridDestroy(amg.grid);
        break;
    }
    amg.kind = 0;
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

/* BoomerAMG of the symmetric matrix of n rows in CSR form (zero-based, row_start[n] entries). */
int lc_hypre_setup_boomeramg(int n, const int *row_start, const int *column, const double *value,
                             double strength) {
    int i, status;
    int *sizes, *rows;
    if ((status = lc_hypre_start()) != 0) return status;
    lc_hypre_free();
    amg.n = n;
    HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &amg.ij_a);
    HYPRE_IJMatrixSetObjectType(amg.ij_a, HYPRE_PARCSR);
    sizes = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    rows = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!sizes || !rows) { free(sizes); free(rows); return 3; }
    for (i = 0; i < n; i++) { sizes[i] = row_start[i + 1] - row_start[i]; rows[i] = i; }
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
    HYPRE_BoomerAMGSetPrintLevel(amg.solver, 0);
    HYPRE_BoomerAMGSetMaxIter(amg.solver, 1); /* one V-cycle: a preconditioner */
    HYPRE_BoomerAMGSetTol(amg.solver, 0.0);
    /* Settings measured on gaps near percolation (docs/decisions/006-leakage-in-the-core.md):
     * HMIS coarsening with extended+i interpolation truncated to 3 entries per row, one
     * level of aggressive coarsening (multipass interpolation) that halves the setup for a
     * few more CG iterations, and l1-scaled symmetric Gauss-Seidel, symmetric as CG needs. */
    HYPRE_BoomerAMGSetStrongThreshold(amg.solver, strength);
    HYPRE_BoomerAMGSetCoarsenType(amg.solver, 10);
    HYPRE_BoomerAMGSetInterpType(amg.solver, 6);
    HYPRE_BoomerAMGSetPMaxElmts(amg.solver, 3);
    HYPRE_BoomerAMGSetAggNumLevels(amg.solver, 1);
    HYPRE_BoomerAMGSetAggInterpType(amg.solver, 4);
    HYPRE_BoomerAMGSetRelaxType(amg.solver, 8);
    HYPRE_BoomerAMGSetNumSweeps(amg.solver, 1);
    HYPRE_BoomerAMGSetRelaxOrder(amg.solver, 0);
    status = HYPRE_BoomerAMGSetup(amg.solver, amg.par_a, amg.par_b, amg.par_x);
    amg.kind = 1;
    return status == 0 ? 0 : 4;
}

/* PFMG on the periodic nx x ny grid (x fastest): stencil coefficients centre, west, east,
 * south, north per point. */
int lc_hypre_setup_pfmg(int nx, int ny, const double *stencil_values) {
    int offsets[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    int entries[5] = {0, 1, 2, 3, 4};
    int periodic[2];
    int k, status;
    if ((status = lc_hypre_start()) != 0) return status;
    lc_hypre_free();
    amg.n = nx * ny;
    amg.lower[0] = 0; amg.lower[1] = 0;
    amg.upper[0] = nx - 1; amg.upper[1] = ny - 1;
    periodic[0] = nx; periodic[1] = ny;
    HYPRE_StructGridCreate(MPI_COMM_SELF, 2, &amg.grid);
    HYPRE_StructGridSetExtents(amg.grid, amg.lower, amg.upper);
    HYPRE_StructGridSetPeriodic(amg.grid, periodic);
    HYPRE_StructGridAssemble(amg.grid);
    HYPRE_StructStencilCreate(2, 5, &amg.stencil);
    for (k = 0; k < 5; k++) HYPRE_StructStencilSetElement(amg.stencil, k, offsets[k]);
    HYPRE_StructMatrixCreate(MPI_COMM_SELF, amg.grid, amg.stencil, &amg.s_a);
    HYPRE_StructMatrixInitialize(amg.s_a);
    HYPRE_StructMatrixSetBoxValues(amg.s_a, amg.lower, amg.upper, 5, entries, (double *)stencil_values);
    HYPRE_StructMatrixAssemble(amg.s_a);
    HYPRE_StructVectorCreate(MPI_COMM_SELF, amg.grid, &amg.s_b);
    HYPRE_StructVectorInitialize(amg.s_b);
    HYPRE_StructVectorAssemble(amg.s_b);
    HYPRE_StructVectorCreate(MPI_COMM_SELF, amg.grid, &amg.s_x);
    HYPRE_StructVectorInitialize(amg.s_x);
    HYPRE_StructVectorAssemble(amg.s_x);

    HYPRE_StructPFMGCreate(MPI_COMM_SELF, &amg.solver);
    HYPRE_StructPFMGSetMaxIter(amg.solver, 1);
    HYPRE_StructPFMGSetTol(amg.solver, 0.0);
    HYPRE_StructPFMGSetZeroGuess(amg.solver);
    HYPRE_StructPFMGSetRelaxType(amg.solver, 2); /* symmetric red-black Gauss-Seidel */
    HYPRE_StructPFMGSetRAPType(amg.solver, 0);   /* Galerkin coarse operators */
    HYPRE_StructPFMGSetNumPreRelax(amg.solver, 1);
    HYPRE_StructPFMGSetNumPostRelax(amg.solver, 1);
    HYPRE_StructPFMGSetSkipRelax(amg.solver, 0);
    status = HYPRE_StructPFMGSetup(amg.solver, amg.s_a, amg.s_b, amg.s_x);
    amg.kind = 2;
    return status == 0 ? 0 : 4;
}

/* z = M^-1 r: one V-cycle from a zero guess (n values, as set up). */
int lc_hypre_apply(const double *r, double *z) {
    double *data;
    switch (amg.kind) {
    case 1:
        data = hypre_VectorData(hypre_ParVectorLocalVector(amg.par_b));
        memcpy(data, r, sizeof(double) * (size_t)amg.n);
        HYPRE_ParVectorSetConstantValues(amg.par_x, 0.0);
        HYPRE_BoomerAMGSolve(amg.solver, amg.par_a, amg.par_b, amg.par_x);
        data = hypre_VectorData(hypre_ParVectorLocalVector(amg.par_x));
        memcpy(z, data, sizeof(double) * (size_t)amg.n);
        HYPRE_ClearAllErrors(); /* "not converged" after one cycle is the intent */
        return 0;
    case 2:
        HYPRE_StructVectorSetBoxValues(amg.s_b, amg.lower, amg.upper, (double *)r);
        HYPRE_StructVectorSetConstantValues(amg.s_x, 0.0);
        HYPRE_StructPFMGSolve(amg.solver, amg.s_a, amg.s_b, amg.s_x);
        HYPRE_StructVectorGetBoxValues(amg.s_x, amg.lower, amg.upper, z);
        HYPRE_ClearAllErrors();
        return 0;
    }
    return 5;
}
