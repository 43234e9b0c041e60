"""A surface solve against its FFT floor: the solve's time in units of its transform pairs'
own time, measured in the same run, and the split of the rest (docs/decisions/024-fft-floor.md).

    OMP_NUM_THREADS=1 .venv/bin/python bench/fft_floor.py [--sizes 1024 2048] [--repeats 2]

Scenes: the isotropic self-affine surface of lc.self_affine_surface (H = 0.8, shortest
wavelength 8 points, rms gradient 0.1, seed 1) on an incompressible layer of
h/lambda = 0.05 (nu = 0.5), p_m = 0.15 E* h/lambda, tol 1e-8, no surface stress, one
thread, method 'auto' (the constrained CG frictionless, GCR with Coulomb friction
mu_c = 0.5), as bench/threads.py. For each size the bare r2c + c2r pair of the grid is
timed first (py_grid_fft_pair_seconds: the plan a solve's operator makes, best of 3 rounds),
then each scene is solved --repeats times (the best kept). Printed: the solve's
``wall_time``, its transform pairs (the coarse grids' counted in pairs of the finest grid),
one pair's time, the ratio solve / (pairs x pair), the ratio of the solve to its own time
inside the transforms (``transform_time``, timed around each transform during the solve:
the same moments of the machine, so on a shared machine, whose speed drifts by tens of per
cent from one second to the next, the steadier of the two), and the split of ``wall_time`` from the
result's own timers: ``setup_time`` (checks, the finest grid's operator: plans and
multipliers), ``coarse_time`` (the coarse start: the coarser grids' solves) and the rest,
the finest grid's iterations. The surface's observables (contact fraction, patches) are
computed after ``wall_time``: "after" is the time the call took beyond it. The load average
is printed before and after: on a shared machine every figure is a ratio within this run.
"""

from __future__ import annotations

import argparse
import os
import time

import layercontact as lc
from layercontact.native import core as _core

SCENES = {"frictionless": 0.0, "coupled": 0.5}


def pair_seconds(n: int) -> float:
    """One unscaled r2c + c2r pair of an n x n grid on one thread (best of 3 rounds)."""
    seconds, stat, errmsg = _core.py_grid_fft_pair_seconds(n, n, 1, max(3, 2**22 // (n * n)), 3)
    if stat:
        raise SystemExit(errmsg.decode().strip() if isinstance(errmsg, bytes) else str(errmsg).strip())
    return seconds


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1024, 2048])
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--repeats", type=int, default=2, help="solves per scene (best kept)")
    args = parser.parse_args()
    print(f"load average (1, 5, 15 min) before: {load()}; build {lc.BUILD}; "
          f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', '(unset)')}")
    rows = []
    for n in args.sizes:
        heights = lc.self_affine_surface(n, 0.8, seed=1, short_wavelength=8 / n)
        pair = pair_seconds(n)
        for name in args.scenes:
            best, after = None, 0.0
            for _ in range(args.repeats):
                start = time.perf_counter()
                result = lc.solve_areal(heights, thickness=0.05, poisson=0.5, friction=SCENES[name],
                                        normalised_pressure=0.15, tol=1e-8, stress=False, threads=1)
                call = time.perf_counter() - start
                if not result.converged:
                    raise SystemExit(f"{n}², {name}: not converged ({result.solver}, {result.residual:.2e})")
                if best is None or result.wall_time < best.wall_time:
                    best, after = result, call - result.wall_time
            rows.append((n, name, pair, best, after))
    print(f"load average after: {load()}\n")
    print("| grid | scene | solver | it. | pairs | pair (ms) | solve (s) | solve / (pairs x pair) "
          "| transforms (s) | solve / transforms | set-up | coarse start | fine it. | after (s) |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n, name, pair, r, after in rows:
        # (a build before the timers, PYTHONPATH=an earlier --target install: the ratio alone)
        setup, coarse = getattr(r, "setup_time", float("nan")), getattr(r, "coarse_time", float("nan"))
        fine = r.wall_time - setup - coarse
        transforms = getattr(r, "transform_time", float("nan"))
        share = {key: f"{value:.2f} s ({100 * value / r.wall_time:.0f} %)"
                 for key, value in (("setup", setup), ("coarse", coarse), ("fine", fine))}
        print(f"| {n}² | {name} | {r.solver} | {r.iterations} | {r.fft_pairs} | {pair * 1e3:.1f} "
              f"| {r.wall_time:.2f} | {r.wall_time / (r.fft_pairs * pair):.2f} | {transforms:.2f} "
              f"| {r.wall_time / transforms:.2f} | {share['setup']} "
              f"| {share['coarse']} | {share['fine']} | {after:.2f} |")

if __name__ == "__main__":
    main()
