/* hypre's BoomerAMG as the preconditioner of the Reynolds leakage solve (lc_leakage_reynolds):
 * set up on the symmetric matrix of the free cells (IJ interface), applied as one V-cycle per
 * call from the conjugate gradients of the Fortran core, then freed. One at a time.
 *
 * Each rank gives the rows of its slab's free cells, numbered across the ranks, on the job's
 * communicator (one process: all rows, on MPI_COMM_SELF): hypre's ParCSR matrix and its
 * V-cycle are then distributed as the slabs are.
 *
 * Debian's hypre is built with MPI. MPI is started here only when a preconditioner is
 * first needed (a singleton start: no mpirun), and finished at exit if it was started here,
 * so that runs that compute no leakage never touch MPI. A run of one process works on
 * MPI_COMM_SELF; a distributed one on its job's communicator (below).
 *
 * Open MPI keeps a directory of temporary files (ompi.HOST.UID/ with the singleton's) under
 * $TMPDIR and leaves it there after MPI_Finalize. MPI is therefore started with a directory
 * of its own as that base, made for this process in $TMPDIR (or in the base the caller set
 * with OMPI_MCA_orte_tmpdir_base), and that directory is removed, whole, at exit: the run
 * leaves $TMPDIR as it found it and touches no other process's files.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <ftw.h>
#include <link.h>
#include <setjmp.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <mpi.h>
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_mv.h>

/* The status of lc_hypre_setup_boomeramg_rows when memory ran out (lc_leakage_reynolds). */
enum { OUT_OF_MEMORY = 3 };

static int mpi_started_here = 0;
static int hypre_started = 0;
/* the temporary-file base made for this process's MPI ("" if none) */
static char scratch_base[4096] = "";

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

static int remove_entry(const char *path, const struct stat *info, int type, struct FTW *where) {
    (void)info;
    (void)type;
    (void)where;
    remove(path);
    return 0; /* go on: remove what can be removed */
}

static void finish_at_exit(void) {
    int finalized = 0;
    lc_hypre_free();
    if (hypre_started) HYPRE_Finalize();
    MPI_Finalized(&finalized);
    if (mpi_started_here && !finalized) MPI_Finalize();
    /* children first (FTW_DEPTH), symbolic links not followed (FTW_PHYS) */
    if (scratch_base[0] != '\0') nftw(scratch_base, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

/* Make this process's temporary-file base (see the top) and point Open MPI at it; without a
 * writable $TMPDIR Open MPI keeps its default. */
static void make_scratch_base(void) {
    const char *base = getenv("OMPI_MCA_orte_tmpdir_base");
    if (base == NULL || base[0] == '\0') base = getenv("TMPDIR");
    if (base == NULL || base[0] == '\0') base = "/tmp";
    if (snprintf(scratch_base, sizeof scratch_base, "%s/layercontact-mpi.XXXXXX", base) >= (int)sizeof scratch_base ||
        mkdtemp(scratch_base) == NULL) {
        scratch_base[0] = '\0';
        return;
    }
    setenv("OMPI_MCA_orte_tmpdir_base", scratch_base, 1);
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
        const char *given = getenv("OMPI_MCA_orte_tmpdir_base");
        char *caller_base = given ? strdup(given) : NULL;
        int status;
        make_scratch_base();
        status = MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided);
        /* the environment as the caller left it (Open MPI has read it) */
        if (caller_base) {
            setenv("OMPI_MCA_orte_tmpdir_base", caller_base, 1);
            free(caller_base);
        } else {
            unsetenv("OMPI_MCA_orte_tmpdir_base");
        }
        if (status != MPI_SUCCESS) {
            if (scratch_base[0] != '\0') nftw(scratch_base, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
            scratch_base[0] = '\0';
            return 1;
        }
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
    if (amg.solver) HYPRE_BoomerAMGDestroy(amg.solver);
    if (amg.ij_a) HYPRE_IJMatrixDestroy(amg.ij_a);
    if (amg.ij_b) HYPRE_IJVectorDestroy(amg.ij_b);
    if (amg.ij_x) HYPRE_IJVectorDestroy(amg.ij_x);
    amg.live = 0;
}

/* The status of a setup that hypre failed with its error flag `flag`: memory or another. */
static int failure(int flag) {
    HYPRE_ClearAllErrors();
    return (flag & HYPRE_ERROR_MEMORY) ? OUT_OF_MEMORY : 4;
}

/* hypre does not return from a failed allocation: it sets HYPRE_ERROR_MEMORY and calls
 * MPI_Abort, which ends the process (and a Python interpreter with it). MPI's profiling
 * interface lets a library define MPI_Abort itself and pass on to PMPI_Abort; while hypre
 * works for this file (abort_return set) an abort comes back to the caller instead, which
 * reports hypre's error. What hypre held at that moment stays allocated (its half-made
 * objects cannot be destroyed safely) until the process ends. */
static sigjmp_buf *abort_return = NULL;

/* Come back to this copy's waiting caller, if there is one (else return). Python loads two
 * builds of this file (the portable core and the x86-64-v3 one): hypre's MPI_Abort binds to
 * the first loaded, while the other may be the one that called hypre. */
__attribute__((visibility("default"))) void lc_hypre_abort_return(void) {
    if (abort_return != NULL) {
        sigjmp_buf *target = abort_return;
        abort_return = NULL;
        siglongjmp(*target, 1);
    }
}

/* Ask every loaded object that defines lc_hypre_abort_return (each build of this file). */
static int return_in_any_copy(struct dl_phdr_info *info, size_t size, void *data) {
    void *handle;
    void (*come_back)(void);
    (void)size;
    (void)data;
    handle = dlopen(info->dlpi_name[0] ? info->dlpi_name : NULL, RTLD_LAZY | RTLD_NOLOAD);
    if (handle == NULL) return 0;
    *(void **)&come_back = dlsym(handle, "lc_hypre_abort_return");
    if (come_back != NULL && come_back != lc_hypre_abort_return) come_back();
    dlclose(handle);
    return 0;
}

__attribute__((visibility("default"))) int MPI_Abort(MPI_Comm comm, int errorcode) {
    lc_hypre_abort_return();
    dl_iterate_phdr(return_in_any_copy, NULL);
    return PMPI_Abort(comm, errorcode);
}

/* After an abort inside hypre: forget its objects, and say why it gave up. */
static int aborted(void) {
    memset(&amg, 0, sizeof amg);
    return failure(HYPRE_GetError());
}

/* Bytes of hypre's copy of the matrix, its vectors and the BoomerAMG hierarchy per unknown:
 * hypre's share of the 268 bytes per cell bench/leakage_memory.py measures (about 130 besides
 * the Fortran arrays), with a margin. This much address space is made sure of before the
 * setup starts, so that a leakage too large for what is left is refused before hypre holds
 * anything; an allocation that fails all the same comes back through MPI_Abort above. */
#define LC_HYPRE_BYTES_PER_UNKNOWN 160

/* 1 if `bytes` more can be allocated now: a block that size is taken and given back
 * without being touched (mapped, not resident). */
static int room_for(size_t bytes) {
    void *probe = malloc(bytes);
    if (probe == NULL) return 0;
    free(probe);
    return 1;
}

/* An IJ vector of the n rows from `first` and its ParCSR object; 0 on success, else hypre's
 * error flag. */
static int ij_vector(MPI_Comm comm, int first, int n, HYPRE_IJVector *v, HYPRE_ParVector *par) {
    int status = HYPRE_IJVectorCreate(comm, first, first + n - 1, v);
    if (status == 0) status = HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
    if (status == 0) status = HYPRE_IJVectorInitialize(*v);
    if (status == 0) status = HYPRE_IJVectorAssemble(*v);
    if (status == 0) status = HYPRE_IJVectorGetObject(*v, (void **)par);
    return status;
}

/* hypre's matrix of the n rows from `first` of this process (`sizes` entries each, rows
 * numbered in `rows`) on `comm`, its vectors and BoomerAMG set up on it, into `amg`; 0 or
 * hypre's error flag (the objects made so far are then in `amg` for lc_hypre_free). */
static int build(MPI_Comm comm, int first, int n, const int *sizes, const int *rows, const int *column,
                 const double *value, double strength) {
    int status = HYPRE_IJMatrixCreate(comm, first, first + n - 1, first, first + n - 1, &amg.ij_a);
    if (status == 0) status = HYPRE_IJMatrixSetObjectType(amg.ij_a, HYPRE_PARCSR);
    if (status == 0) status = HYPRE_IJMatrixSetRowSizes(amg.ij_a, sizes);
    if (status == 0) status = HYPRE_IJMatrixInitialize(amg.ij_a);
    if (status == 0) status = HYPRE_IJMatrixSetValues(amg.ij_a, n, (int *)sizes, rows, column, value);
    if (status == 0) status = HYPRE_IJMatrixAssemble(amg.ij_a);
    if (status == 0) status = HYPRE_IJMatrixGetObject(amg.ij_a, (void **)&amg.par_a);
    if (status == 0) status = ij_vector(comm, first, n, &amg.ij_b, &amg.par_b);
    if (status == 0) status = ij_vector(comm, first, n, &amg.ij_x, &amg.par_x);
    if (status == 0) status = HYPRE_BoomerAMGCreate(&amg.solver);
    if (status != 0) return status;
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
    return HYPRE_BoomerAMGSetup(amg.solver, amg.par_a, amg.par_b, amg.par_x);
}

/* BoomerAMG on `comm` of the symmetric matrix whose rows first .. first + n - 1 (n >= 0)
 * this process holds, in CSR form (zero-based row starts, global columns). 0 on success; 1
 * or 2: MPI or hypre did not start; 3: not enough memory; 4: hypre failed otherwise. On a
 * failure nothing of this matrix is kept. */
static int setup_on(MPI_Comm comm, int first, int n, const int *row_start, const int *column,
                    const double *value, double strength) {
    int i, status;
    int *sizes, *rows;
    sigjmp_buf target;
    if ((status = start()) != 0) return status;
    lc_hypre_free();
    if (!room_for((size_t)LC_HYPRE_BYTES_PER_UNKNOWN * (size_t)n)) return OUT_OF_MEMORY;
    /* (one more: a rank whose slab holds no free cell gives no rows) */
    sizes = malloc(sizeof(int) * ((size_t)n + 1));
    rows = malloc(sizeof(int) * ((size_t)n + 1));
    if (!sizes || !rows) {
        free(sizes);
        free(rows);
        return OUT_OF_MEMORY;
    }
    for (i = 0; i < n; i++) {
        sizes[i] = row_start[i + 1] - row_start[i];
        rows[i] = first + i;
    }
    HYPRE_ClearAllErrors();
    memset(&amg, 0, sizeof amg);
    amg.n = n;
    amg.live = 1;
    if (sigsetjmp(target, 0) != 0) {
        free(sizes);
        free(rows);
        return aborted();
    }
    abort_return = &target;
    status = build(comm, first, n, sizes, rows, column, value, strength);
    abort_return = NULL;
    free(sizes);
    free(rows);
    if (status != 0) {
        lc_hypre_free();
        return failure(status);
    }
    return 0;
}

/* BoomerAMG (setup_on) on the communicator whose Fortran handle is `comm` (a negative handle:
 * this process alone, MPI_COMM_SELF), this process holding the n rows from `first`. */
int lc_hypre_setup_boomeramg_rows(int comm, int first, int n, const int *row_start, const int *column,
                                  const double *value, double strength) {
    int status = start();
    if (status != 0) return status;
    return setup_on(comm < 0 ? MPI_COMM_SELF : MPI_Comm_f2c((MPI_Fint)comm), first, n, row_start, column, value,
                    strength);
}

/* z = M^-1 r: one V-cycle from a zero guess (n values, as set up). */
int lc_hypre_apply(const double *r, double *z) {
    sigjmp_buf target;
    if (!amg.live) return 5;
    if (amg.n > 0) memcpy(hypre_VectorData(hypre_ParVectorLocalVector(amg.par_b)), r, sizeof(double) * (size_t)amg.n);
    HYPRE_ParVectorSetConstantValues(amg.par_x, 0.0);
    if (sigsetjmp(target, 0) != 0) return aborted();
    abort_return = &target;
    HYPRE_BoomerAMGSolve(amg.solver, amg.par_a, amg.par_b, amg.par_x);
    abort_return = NULL;
    if (amg.n > 0) memcpy(z, hypre_VectorData(hypre_ParVectorLocalVector(amg.par_x)), sizeof(double) * (size_t)amg.n);
    HYPRE_ClearAllErrors(); /* "not converged" after one cycle is the intent */
    return 0;
}
