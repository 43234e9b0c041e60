"""A model of one coupled surface solve on P MPI ranks beyond this machine (decision 023):
time and peak memory per rank for nx = ny = 16384, 32768, 65536 on P = 16, 64, 256, 1024,
built from parts measured here and from stated network assumptions.

    OMP_NUM_THREADS=1 .venv/bin/python bench/mpi_model.py [--bandwidth 10e9] [--latency 2e-6]
        [--fft-coefficient S] [--memcpy-bandwidth B] [--sizes ...] [--ranks ...]

Measured by the script (unless given by a flag): the serial r2c + c2r pair of n x n at
n = 512, 1024, 2048 (``py_grid_fft_pair_seconds``, the plan a solve's operator makes, one
thread), fitted as c N log2 N (N = n², c in s per point log point, from the largest), and this machine's
memory copy bandwidth (the "network" of ranks on one node, for the check against the
2048² runs). Read from flags, with defaults measured on this machine (2048² coupled,
bench/mpi.py and bench/fft_floor.py): the serial solve (12.75 s, 22 GCR iterations, 64
transform pairs in finest-grid units), its split (set-up 5 %, coarse start 13 %, fine
iterations 82 %), the serial peak memory (535 MiB) and the measured 2-rank solve (10.55 s,
431 / 295 MiB per rank).

The model (model_* functions, which take every measured part as an argument):
- serial solve of n: the set-up and the coarse start scale as the transforms, N log N; the
  fine iterations are their transform pairs (the solve's pairs shared between the coarse
  start and the fine iterations as their time is) times the fitted pair, plus the passes
  between the transforms, which scale as N;
- the set-up on P ranks: the share `--setup-fixed` of the serial set-up does not fall with
  P (an Amdahl term: what every rank does alike, its waits at the set-up's reductions and
  FFTW-MPI's planning), the rest falls as 1/P; the share is fitted to the measured serial
  and two-rank set-ups, fixed = 2 S_2/S_1 - 1;
- on P ranks: local transforms and passes divided by P; each pair's two global
  transposes (FFTW_MPI_TRANSPOSED_OUT/IN) move the half spectrum twice, in total
  2 x 16 B x nx/2 x ny x (P-1)/P, a rank's share 1/P of it, over the link's bandwidth,
  plus P-1 messages a transpose per rank at the latency; every iteration's MPI_Allreduce
  calls cost latency x ceil(log2 P) each;
- the coarse start: its levels (every second point, recursively, down to 512 points) share
  the serial coarse time as their N log N. A level of at least 8 rows a rank
  (distributed_coarse_rows of src/contact/solve.f90) is solved on its own slabs like the
  fine grid (its time over P, its pairs' transposes, its iterations' reductions, and the
  moves of its height and pressure into its slabs and of its solution back: 3 all-to-alls
  of its N_l doubles); the first thinner level is gathered (the level above's height and
  pressure, MPI_Allgatherv) and it and every level below are solved whole on every rank:
  that tail does not shrink with P;
- memory per rank: the serial doubles per point over P, or the gathered tail's serial
  solve (its first level's points at the same doubles per point), whichever is larger
  (the 2-rank peaks follow the larger, not the sum; a coarse level on the slabs holds
  a quarter of the level above's slab), plus on rank 0 the gathered fields (pressure, gap,
  displacement, heights: 4 doubles per point of the whole grid).
Assumptions (flags): the iterations, pairs and split of the 2048² solve at every size
(they grow with the size: docs/performance.md says by how much), one rank per core, no
overlap of communication with computation, the padding copies around each transform
counted with the passes.
"""

from __future__ import annotations

import argparse
import math
import os
import time

# MPI_Allreduce calls in one plain GCR iteration with load control, counted in
# src/contact/solver_gcr.f90 (evaluate: sum_over_ranks, max_over_ranks, field_points,
# sum_over_ranks, global_max; project_on_set's set_mean; history_products; set_norm's
# two (the centre's sums, then the norm and the step's product); update; scale_to_load's
# field_points; one fewer where the compiler skips merge's unused field_points). An
# iteration that lets points in adds reorthonormalise's 3, one after a change of the set
# history_products, clip_negative, total_pressure and another evaluate (8). The history's
# products (history_products) are one message for all the stored columns. (The multigrid's
# GCR on the slabs, not modelled here, orthogonalises in one message too: it took one a
# stored column, up to 9, before.)
ALLREDUCES_PER_ITERATION = 10
#: The share of the serial set-up that does not fall with P (model_setup): 0, the set-up's
#: work divided among the ranks; the shares fitted to this machine's serial and two-rank
#: set-ups (bench/mpi.py) are quoted in docs/performance.md, 'Beyond one node: a model'
SETUP_FIXED = 0.0

MIB = 2.0**20
#: src/contact/solve.f90: a coarse level is solved on the slabs from this many rows a rank,
#: and the coarse start stops before a grid of fewer than COARSEST_GRID points
DISTRIBUTED_COARSE_ROWS = 8
COARSEST_GRID = 512


def transpose_bytes_total(nx: int, ny: int, ranks: int) -> float:
    """Bytes all ranks together send in one transposed r2c + c2r pair: the half spectrum
    (nx/2 x ny complex doubles, 16 B each) twice, all but the own 1/P of it."""
    return 2 * 16.0 * (nx // 2) * ny * (ranks - 1) / ranks


def transpose_seconds(nx: int, ny: int, ranks: int, bandwidth: float, latency: float) -> float:
    """One pair's two global transposes on one rank: its 1/P share of the volume over its
    link, and P-1 messages per transpose."""
    if ranks == 1:
        return 0.0
    return transpose_bytes_total(nx, ny, ranks) / ranks / bandwidth + 2 * (ranks - 1) * latency


def pair_seconds(n: int, coefficient: float) -> float:
    """The serial r2c + c2r pair of n x n from the fit c N log2 N."""
    points = n * n
    return coefficient * points * math.log2(points)


def allreduce_seconds(ranks: int, latency: float) -> float:
    """One MPI_Allreduce of a few doubles: a tree of ceil(log2 P) latencies."""
    return 0.0 if ranks == 1 else math.ceil(math.log2(ranks)) * latency


def coarse_levels(n: int, ranks: int) -> list[dict]:
    """The coarse start's levels of an n x n grid on P ranks: their points, rows, whether
    each is solved on the slabs (at least DISTRIBUTED_COARSE_ROWS rows a rank, every level
    above on the slabs too) and its share of the serial coarse time (N_l log N_l)."""
    levels, side = [], n
    while side % 2 == 0 and (side // 2) ** 2 >= COARSEST_GRID:
        side //= 2
        above = not levels or levels[-1]["on_slabs"]
        on_slabs = ranks > 1 and above and math.ceil(side / ranks) >= DISTRIBUTED_COARSE_ROWS
        levels.append({"points": side * side, "rows": side, "on_slabs": on_slabs,
                       "weight": side * side * math.log2(side * side)})
    total = sum(level["weight"] for level in levels) or 1.0
    for level in levels:
        level["share"] = level["weight"] / total
    return levels


def model_coarse(n: int, ranks: int, s: dict, bandwidth: float, latency: float, allreduces: int) -> float:
    """The coarse start's time on P ranks (s): the levels on the slabs as the fine grid (a
    level's pairs: the serial coarse pairs shared alike among the levels, each in its own
    units), the gathered tail whole."""
    levels = coarse_levels(n, ranks)
    if ranks == 1 or not levels:
        return s["coarse"]
    own_pairs = s["coarse_pairs"] / sum(level["points"] / (n * n) for level in levels)
    seconds, above = 0.0, n * n
    for level in levels:
        serial = s["coarse"] * level["share"]
        if level["on_slabs"]:
            side = level["rows"]
            moves = 3 * (level["points"] * 8.0 * (ranks - 1) / ranks / ranks / bandwidth
                         + (ranks - 1) * latency)
            seconds += (serial / ranks + own_pairs * transpose_seconds(side, side, ranks, bandwidth, latency)
                        + s["iterations"] * allreduces * allreduce_seconds(ranks, latency) + moves)
        else:
            if above is not None:
                seconds += (2 * above * 8.0 * (ranks - 1) / ranks / bandwidth
                            + allreduce_seconds(ranks, latency))
            seconds += serial
            above = None
            continue
        above = level["points"]
    return seconds


def model_serial(n: int, coefficient: float, ref: dict) -> dict:
    """The serial solve of n x n in parts (s), scaled from the reference solve ref (n,
    solve, pairs, split) with the fitted pair."""
    n0 = ref["n"]
    fft_scale = pair_seconds(n, 1.0) / pair_seconds(n0, 1.0)
    point_scale = (n * n) / (n0 * n0)
    setup0, coarse0, fine0 = (share * ref["solve"] for share in ref["split"])
    fine_pairs = ref["pairs"] * fine0 / (fine0 + coarse0)
    passes0 = max(fine0 - fine_pairs * pair_seconds(n0, coefficient), 0.0)
    return {"setup": setup0 * fft_scale, "coarse": coarse0 * fft_scale, "fine_pairs": fine_pairs,
            "coarse_pairs": ref["pairs"] - fine_pairs,
            "pair": pair_seconds(n, coefficient), "passes": passes0 * point_scale,
            "iterations": ref["iterations"]}


def model_setup(serial: float, ranks: int, fixed: float) -> float:
    """The set-up on P ranks (s): its share `fixed` whatever P, the rest over P."""
    return serial if ranks == 1 else serial * (fixed + (1.0 - fixed) / ranks)


def model_time(n: int, ranks: int, coefficient: float, ref: dict, bandwidth: float, latency: float,
               allreduces: int = ALLREDUCES_PER_ITERATION) -> dict:
    """Solve time on P ranks (s) and its parts: set-up (model_setup, ref["setup_fixed"]),
    coarse start (model_coarse), fine iterations (local transforms, transposes, passes,
    reductions)."""
    s = model_serial(n, coefficient, ref)
    parts = {
        "setup": model_setup(s["setup"], ranks, ref.get("setup_fixed", 0.0)),
        "coarse": model_coarse(n, ranks, s, bandwidth, latency, allreduces),
        "fft": s["fine_pairs"] * s["pair"] / ranks,
        "transpose": s["fine_pairs"] * transpose_seconds(n, n, ranks, bandwidth, latency),
        "passes": s["passes"] / ranks,
        "reductions": s["iterations"] * allreduces * allreduce_seconds(ranks, latency),
    }
    parts["total"] = sum(parts.values())
    parts["serial"] = s["setup"] + s["coarse"] + s["fine_pairs"] * s["pair"] + s["passes"]
    return parts


def model_memory(n: int, ranks: int, doubles_per_point: float) -> dict:
    """Peak bytes per rank: rank 0 and the others (alike: the observables run on the slabs
    and the file is written by them, decisions 025 and 026; no field is gathered)."""
    points = n * n
    slab = doubles_per_point * points / ranks
    gathered = [level["points"] for level in coarse_levels(n, ranks) if not level["on_slabs"]]
    coarse = 0.0 if ranks == 1 or not gathered else doubles_per_point * gathered[0]
    solve = 8.0 * max(slab, coarse)
    return {"rank0": solve, "other": solve}


def part_dominates_from(part: str, n: int, coefficient: float, ref: dict, bandwidth: float, latency: float) -> int:
    """The smallest power-of-two P at which `part` of model_time ("coarse", "setup") takes
    more than half the solve; 0 if none up to 2^20."""
    ranks = 1
    while ranks <= 2**20:
        parts = model_time(n, ranks, coefficient, ref, bandwidth, latency)
        if parts[part] > 0.5 * parts["total"]:
            return ranks
        ranks *= 2
    return 0


def coarse_dominates_from(n: int, coefficient: float, ref: dict, bandwidth: float, latency: float) -> int:
    """The smallest power-of-two P at which the coarse start takes more than half the solve."""
    return part_dominates_from("coarse", n, coefficient, ref, bandwidth, latency)


def setup_dominates_from(n: int, coefficient: float, ref: dict, bandwidth: float, latency: float) -> int:
    """The smallest power-of-two P at which the set-up takes more than half the solve."""
    return part_dominates_from("setup", n, coefficient, ref, bandwidth, latency)


def best_speed_up(n: int, coefficient: float, ref: dict, bandwidth: float,
                  latency: float) -> tuple[int, float]:
    """The power-of-two P (up to 2^20) of the largest speed-up, and that speed-up."""
    best = (1, 1.0)
    for power in range(21):
        t = model_time(n, 2**power, coefficient, ref, bandwidth, latency)
        if t["serial"] / t["total"] > best[1]:
            best = (2**power, t["serial"] / t["total"])
    return best


def measure_fft_coefficient(sizes=(512, 1024, 2048)) -> float:
    """c of t = c N log2 N at the largest size (best of 3 rounds): c grows with the size as
    the grid leaves the caches (the smaller sizes are printed to show it), so the largest
    measured is the one nearest the modelled grids' slabs, and still a lower bound."""
    from layercontact.native import core as _core
    ratios = []
    for n in sizes:
        seconds, stat, errmsg = _core.py_grid_fft_pair_seconds(n, n, 1, max(3, 2**22 // (n * n)), 3)
        if stat:
            raise SystemExit(str(errmsg).strip())
        ratios.append(seconds / pair_seconds(n, 1.0))
        print(f"serial pair {n}²: {seconds * 1e3:.2f} ms, {ratios[-1] * 1e9:.3f} ns per point log point")
    return ratios[-1]


def measure_memcpy_bandwidth() -> float:
    """Bytes per second of a 64 MiB copy (best of 5): the transposes on one node."""
    import numpy as np
    a = np.ones(2**23)
    b = np.empty_like(a)
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        np.copyto(b, a)
        best = min(best, time.perf_counter() - start)
    # (a copy reads and writes each byte; a message is written once by the sender's copy
    # into shared memory and read once by the receiver's: two copies)
    return a.nbytes / best / 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[16384, 32768, 65536])
    parser.add_argument("--ranks", type=int, nargs="+", default=[16, 64, 256, 1024])
    parser.add_argument("--bandwidth", type=float, default=10e9,
                        help="bytes/s a rank's share of the link (assumed: HDR InfiniBand node)")
    parser.add_argument("--latency", type=float, default=2e-6, help="s per message (assumed)")
    parser.add_argument("--node-memory", type=float, default=256.0, help="GiB of a node (assumed)")
    parser.add_argument("--ranks-per-node", type=int, default=64, help="(assumed)")
    parser.add_argument("--fft-coefficient", type=float, help="s per point log point (default: measured)")
    parser.add_argument("--memcpy-bandwidth", type=float, help="bytes/s on this machine (default: measured)")
    parser.add_argument("--shared-latency", type=float, default=1e-6,
                        help="s per message on one node (assumed)")
    parser.add_argument("--reference", type=float, nargs=4, default=[2048, 12.75, 22, 64],
                        metavar=("N", "SOLVE_S", "ITERATIONS", "PAIRS"))
    parser.add_argument("--split", type=float, nargs=3, default=[0.05, 0.13, 0.82],
                        metavar=("SETUP", "COARSE", "FINE"))
    parser.add_argument("--setup-fixed", type=float, default=SETUP_FIXED,
                        help="share of the serial set-up that does not fall with P (2 S_2/S_1 - 1)")
    parser.add_argument("--serial-mib", type=float, default=535.0, help="serial peak RSS of the reference")
    parser.add_argument("--two-ranks", type=float, nargs=3, default=[10.55, 431.0, 295.0],
                        metavar=("SOLVE_S", "RANK0_MIB", "RANK1_MIB"))
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f}")
    ref = {"n": int(args.reference[0]), "solve": args.reference[1], "iterations": args.reference[2],
           "pairs": args.reference[3], "split": args.split, "setup_fixed": args.setup_fixed}
    coefficient = args.fft_coefficient or measure_fft_coefficient()
    memcpy = args.memcpy_bandwidth or measure_memcpy_bandwidth()
    doubles = args.serial_mib * MIB / 8.0 / ref["n"] ** 2
    print(f"fit: {coefficient * 1e9:.3f} ns per point log point "
          f"(2048² pair {pair_seconds(2048, coefficient) * 1e3:.0f} ms); "
          f"memory copy {memcpy / 1e9:.1f} GB/s; serial peak {doubles:.1f} doubles per point")

    print(f"\nCheck on this machine ({ref['n']}², shared memory {memcpy / 1e9:.1f} GB/s, "
          f"{args.shared_latency * 1e6:.0f} us a message):")
    for ranks, solve, mib in ((1, ref["solve"], (args.serial_mib,)),
                              (2, args.two_ranks[0], tuple(args.two_ranks[1:]))):
        t = model_time(ref["n"], ranks, coefficient, ref, memcpy, args.shared_latency)["total"]
        m = model_memory(ref["n"], ranks, doubles)
        model_mib = (m["rank0"] / MIB,) if ranks == 1 else (m["rank0"] / MIB, m["other"] / MIB)
        print(f"  P = {ranks}: model {t:.2f} s, measured {solve:.2f} s ({100 * (t / solve - 1):+.0f} %); "
              f"memory model {' / '.join(f'{x:.0f}' for x in model_mib)} MiB, measured "
              f"{' / '.join(f'{x:.0f}' for x in mib)} MiB "
              f"({' / '.join(f'{100 * (x / y - 1):+.0f} %' for x, y in zip(model_mib, mib))})")

    print(f"\nNetwork: {args.bandwidth / 1e9:.0f} GB/s a rank, {args.latency * 1e6:.1f} us a message; "
          f"{ALLREDUCES_PER_ITERATION} MPI_Allreduce an iteration; node {args.node_memory:.0f} GiB, "
          f"{args.ranks_per_node} ranks a node")
    print("| n | P | serial (s) | ideal serial/P (s) | model (s) | speed-up | set-up | coarse start | "
          "local FFT | transposes | passes | reductions | speed-up without the coarse start | rank 0 (GiB) | "
          "other ranks (GiB) | node (GiB) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in args.sizes:
        for ranks in args.ranks:
            t = model_time(n, ranks, coefficient, ref, args.bandwidth, args.latency)
            serial_coarse = model_serial(n, coefficient, ref)["coarse"]
            m = model_memory(n, ranks, doubles)
            node = (m["rank0"] + (min(ranks, args.ranks_per_node) - 1) * m["other"]) / 2**30
            print(f"| {n} | {ranks} | {t['serial']:.1f} | {t['serial'] / ranks:.2f} | {t['total']:.2f} | "
                  f"{t['serial'] / t['total']:.1f} | {t['setup']:.2f} | {t['coarse']:.2f} | {t['fft']:.2f} | "
                  f"{t['transpose']:.2f} | {t['passes']:.2f} | {t['reductions']:.3f} | "
                  f"{(t['serial'] - serial_coarse) / (t['total'] - t['coarse']):.0f} | "
                  f"{m['rank0'] / 2**30:.0f} | "
                  f"{m['other'] / 2**30:.0f} | {node:.0f}{' (over)' if node > args.node_memory else ''} |")
    print()
    for n in args.sizes:
        p = coarse_dominates_from(n, coefficient, ref, args.bandwidth, args.latency)
        m = model_memory(n, max(args.ranks), doubles)
        room = args.node_memory * 2**30 - m["rank0"]
        fit = ("rank 0 alone does not fit" if room < 0
               else f"{1 + int(room // m['other'])} ranks fit on rank 0's node")
        best, speed_up = best_speed_up(n, coefficient, ref, args.bandwidth, args.latency)
        q = setup_dominates_from(n, coefficient, ref, args.bandwidth, args.latency)
        print(f"{n}²: the set-up ({100 * args.setup_fixed:.0f} % of it fixed) takes over half the solve from "
              f"P = {q or 'none up to 2^20'}")
        print(f"{n}²: the coarse start takes over half the solve from P = {p or 'none up to 2^20'}; "
              f"the largest speed-up {speed_up:.0f}x at P = {best}; at P = {max(args.ranks)} "
              f"{fit} ({m['rank0'] / 2**30:.0f} GiB rank 0, {m['other'] / 2**30:.0f} GiB each other rank)")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
