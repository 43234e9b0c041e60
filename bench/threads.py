"""One solve on 1 and 2 threads (&solver threads, docs/decisions/022-threads.md): a 2048²
coupled surface and a 2048² frictionless one, each thread count alternately, in one run.

    .venv/bin/python bench/threads.py [--n 2048] [--threads 1 2] [--repeats 2]
    .venv/bin/python bench/threads.py --pairs    # FFT pairs of lines and surfaces only
    .venv/bin/python bench/threads.py --contention [--n 1024 2048]   # two processes' pairs at once

Scenes: the isotropic self-affine surface of lc.self_affine_surface (H = 0.8, shortest
wavelength 8 points, rms gradient 0.1, seed 1) on an incompressible layer of
h/lambda = 0.05 (nu = 0.5), p_m = 0.15 E* h/lambda; coupled: Coulomb friction mu_c = 0.5;
frictionless: mu_c = 0. tol 1e-8, no surface stress (the solve alone). "solve" is the
result's ``wall_time`` (operator, coarse start, iterations), the best of ``--repeats``.
"FFT" is the solve's own time inside its transforms, every grid's (the result's
``transform_time``, read off the clock around each r2c and c2r during the solve); "rest" is
solve - FFT: the set-up and the passes over the grid. One bare pair of the finest grid on
each thread count (py_grid_fft_pair_seconds) is printed as well: it is timed alone, before
the solves, so it shows the transforms' own gain on an undisturbed machine, not the
solve's. Ratios are 1 thread over n threads, measured within this run. The load average is printed before and after: on a shared machine a second thread
competes with whatever else runs.

``--pairs`` times one FFT pair of lines of 2^14 .. 2^21 points and surfaces of 256² ..
2048² on 1 and 2 threads instead (the best of 3 rounds, both thread counts twice,
alternately): what lc_contact_solve's smallest_threaded_line rests on.

``--contention`` times one FFT pair of each grid on one thread in a process alone, then in
two processes started together (each its own pair, the same grid: what the two cores'
shared memory bandwidth and caches leave each), and on two threads in one process, in
rounds alternating the three (the best of each kept): if two processes' pairs take as long
as one alone, two threads are bounded by the split of the work, not by the memory.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import layercontact as lc
from layercontact.native import core as _core

SCENES = {"coupled": 0.5, "frictionless": 0.0}


def pair_seconds(nx: int, threads: int, ny: int | None = None) -> float:
    """One unscaled r2c + c2r pair of an nx x ny grid (ny = nx by default) on `threads` threads
    (best of 3 rounds)."""
    ny = nx if ny is None else ny
    seconds, stat, errmsg = _core.py_grid_fft_pair_seconds(nx, ny, threads, max(3, 2**22 // (nx * ny)), 3)
    if stat:
        raise SystemExit(errmsg.decode().strip() if isinstance(errmsg, bytes) else str(errmsg).strip())
    return seconds


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def pairs_table(threads: list[int]) -> None:
    """One FFT pair per grid on each thread count (alternately, twice; the best kept)."""
    print("| grid | points | " + " | ".join(f"{t} threads (ms)" for t in threads) + " | ratio |")
    print("|---|---:|" + "---:|" * len(threads) + "---:|")
    grids = [(2**k, 1) for k in range(14, 22)] + [(n, n) for n in (256, 512, 1024, 2048)]
    for nx, ny in grids:
        best = {t: min(pair_seconds(nx, t, ny) for _ in range(2)) for t in threads}
        label = f"line {nx}" if ny == 1 else f"{nx}²"
        print(f"| {label} | {nx * ny} | " + " | ".join(f"{best[t] * 1e3:.2f}" for t in threads)
              + f" | {best[threads[0]] / best[threads[-1]]:.2f} |", flush=True)


def timed_processes(nx: int, processes: int, rounds: int) -> list[float]:
    """One pair of an nx x nx grid on one thread in each of `processes` processes started
    together (each best of `rounds` rounds), seconds."""
    code = ("import sys; sys.path.insert(0, %r); import threads as t; "
            "print(min(t.pair_seconds(%d, 1) for _ in range(%d)))") % (os.path.dirname(os.path.abspath(__file__)), nx,
                                                                    rounds)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    started = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=env)
               for _ in range(processes)]
    return [float(p.communicate()[0].split()[-1]) for p in started]


def contention_table(sizes: list[int], rounds: int) -> None:
    """One pair alone, in two processes at once and on two threads (best of `rounds`)."""
    print("| grid | 1 process, 1 thread (ms) | 2 processes at once, each (ms) | slowdown | 1 process, 2 threads (ms) "
          "| 2 threads / 1 |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in sizes:
        alone, shared, threaded = [], [], []
        for _ in range(rounds):
            alone += timed_processes(n, 1, 3)
            shared.append(max(timed_processes(n, 2, 3)))
            threaded.append(pair_seconds(n, 2))
        print(f"| {n}² | {min(alone) * 1e3:.1f} | {min(shared) * 1e3:.1f} | {min(shared) / min(alone):.2f} "
              f"| {min(threaded) * 1e3:.1f} | {min(alone) / min(threaded):.2f} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[2048],
                        help="grid size (the first; --contention: each)")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=2, help="solves per scene and thread count (best kept)")
    parser.add_argument("--pairs", action="store_true", help="time FFT pairs of lines and surfaces only")
    parser.add_argument("--contention", action="store_true",
                        help="one pair alone, in two single-thread processes at once, on two threads")
    args = parser.parse_args()
    n = args.n[0]
    print(f"load average (1, 5, 15 min) before: {load()}; CPUs of this process: {len(os.sched_getaffinity(0))}")
    if args.pairs:
        pairs_table(args.threads)
        print(f"load average after: {load()}")
        return
    if args.contention:
        contention_table(args.n, max(args.repeats, 1))
        print(f"load average after: {load()}")
        return
    heights = lc.self_affine_surface(n, 0.8, seed=1, short_wavelength=8 / n)
    pairs_time = {t: pair_seconds(n, t) for t in args.threads}
    best: dict[tuple[str, int], object] = {}
    start = time.perf_counter()
    for _ in range(args.repeats):
        for name, friction in SCENES.items():
            for t in args.threads:
                result = lc.solve_areal(heights, thickness=0.05, poisson=0.5, friction=friction,
                                        normalised_pressure=0.15, tol=1e-8, stress=False, threads=t)
                if not result.converged:
                    raise SystemExit(f"{name}, {t} threads: not converged ({result.solver}, {result.residual:.2e})")
                if result.omp_threads != t:
                    raise SystemExit(f"{name}: asked for {t} threads, ran on {result.omp_threads}")
                key = (name, t)
                if key not in best or result.wall_time < best[key].wall_time:
                    best[key] = result
    print(f"load average after ({time.perf_counter() - start:.0f} s of solves): {load()}")
    print(f"\none FFT pair of {n}²: " + ", ".join(f"{t} threads {pairs_time[t] * 1e3:.1f} ms" for t in args.threads)
          + f" (ratio {pairs_time[args.threads[0]] / pairs_time[args.threads[-1]]:.2f})\n")
    print("| scene | threads | solver | it. | pairs | solve (s) | FFT (s) | rest (s) | solve ratio | FFT ratio "
          "| rest ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in SCENES:
        base = best[(name, args.threads[0])]
        base_fft = base.transform_time
        for t in args.threads:
            r = best[(name, t)]
            fft = r.transform_time
            rest = r.wall_time - fft
            print(f"| {name} | {t} | {r.solver} | {r.iterations} | {r.fft_pairs} | {r.wall_time:.2f} | {fft:.2f} "
                  f"| {rest:.2f} | {base.wall_time / r.wall_time:.2f} | {base_fft / fft:.2f} "
                  f"| {(base.wall_time - base_fft) / rest:.2f} |")


if __name__ == "__main__":
    main()
