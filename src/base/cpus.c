/* How many CPUs this process may run on (lc_base_threads): the CPUs of its affinity mask,
 * which a batch system (Slurm's --cpus-per-task, taskset, cgroups' cpusets) narrows, not the
 * machine's count. Returns 0 where the mask cannot be read. */
#define _GNU_SOURCE
#include <sched.h>

int lc_affinity_cpus(void) {
    cpu_set_t mask;
    CPU_ZERO(&mask);
    if (sched_getaffinity(0, sizeof(mask), &mask) != 0) return 0;
    return CPU_COUNT(&mask);
}
