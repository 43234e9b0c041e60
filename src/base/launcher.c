/* Whether this process was started by an MPI launcher, and MPI's start and finish for a
 * surface shared among the ranks of a job (lc_base_parallel).
 *
 * A plain `layercontact scene.nml` must not need mpirun: MPI is started only when a launcher's
 * variables say the process is one of a job (Open MPI's mpirun: OMPI_COMM_WORLD_SIZE; PMIx:
 * PMIX_RANK; PMI and Slurm's srun: PMI_SIZE, SLURM_NTASKS with SLURM_STEP_ID). Whoever comes
 * first starts MPI, at thread level FUNNELED (the solve's OpenMP threads never call MPI): this
 * file or the leakage's hypre glue (src/leakage/hypre_amg.c), which checks MPI_Initialized
 * as this does. MPI is finished at exit by the one that started it.
 */
#include <stdlib.h>
#include <string.h>
#ifdef LC_MPI
#include <mpi.h>
#endif

static int positive(const char *name) {
    const char *value = getenv(name);
    return value != NULL && atoi(value) > 0;
}

/* 1 if a launcher started this process as one of a job's ranks. */
int lc_launched(void) {
    if (positive("OMPI_COMM_WORLD_SIZE") || positive("PMI_SIZE")) return 1;
    if (getenv("PMIX_RANK") != NULL) return 1;
    /* srun sets SLURM_STEP_ID in each task; SLURM_NTASKS alone is set in a batch script too */
    return positive("SLURM_NTASKS") && getenv("SLURM_STEP_ID") != NULL && getenv("SLURM_PROCID") != NULL;
}

/* The number of ranks the launcher started (its variables), 0 where it does not say or no
 * launcher started this process: a build without MPI refuses a job of several ranks. */
int lc_launch_size(void) {
    static const char *const sizes[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"};
    for (size_t i = 0; i < sizeof sizes / sizeof *sizes; i++)
        if (positive(sizes[i])) return atoi(getenv(sizes[i]));
    if (lc_launched() && positive("SLURM_NTASKS")) return atoi(getenv("SLURM_NTASKS"));
    return 0;
}

/* This process's rank as the launcher numbers it (0 where it does not say): the one of a
 * refused job that reports why. */
int lc_launch_rank(void) {
    static const char *const ranks[] = {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "SLURM_PROCID"};
    if (!lc_launched()) return 0;
    for (size_t i = 0; i < sizeof ranks / sizeof *ranks; i++)
        if (getenv(ranks[i]) != NULL) return atoi(getenv(ranks[i]));
    return 0;
}

#ifdef LC_MPI
static int started_here = 0;

static void finish_at_exit(void) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (started_here && !finalized) MPI_Finalize();
}

/* Start MPI under a launcher (if nobody did); 0 on success or when not launched. */
int lc_mpi_start(void) {
    int initialized = 0, provided = 0;
    if (!lc_launched()) return 0;
    MPI_Initialized(&initialized);
    if (initialized) return 0;
    if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) return 1;
    started_here = 1;
    atexit(finish_at_exit);
    return 0;
}

/* A process that leaves while its ranks share a scene (a runtime error in the middle of a
 * solve, an allocation the compiler's runtime could not make) must not call MPI_Finalize:
 * that waits for the other ranks, which wait in their next reduction for this one, and the
 * job hangs. While a run is in flight the exit ends the whole job instead, with code 5 (an
 * internal failure, the executable's code for memory), whoever started MPI (this file, the
 * leakage's hypre glue or a caller's mpi4py: this handler, registered last, runs first). */
static int in_flight = 0;

static void abort_if_in_flight(void) {
    int initialized = 0, finalized = 0;
    if (!in_flight) return;
    MPI_Initialized(&initialized);
    MPI_Finalized(&finalized);
    if (initialized && !finalized) MPI_Abort(MPI_COMM_WORLD, 5);
}

void lc_mpi_run_begins(void) {
    static int registered = 0;
    if (!registered) atexit(abort_if_in_flight);
    registered = 1;
    in_flight = 1;
}

void lc_mpi_run_ends(void) { in_flight = 0; }
#else
int lc_mpi_start(void) { return 0; }
void lc_mpi_run_begins(void) {}
void lc_mpi_run_ends(void) {}
#endif
