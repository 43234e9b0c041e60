"""Solve time of two builds of the package against each other, on the scenes of
bench/scaling.py: the check that a change to the compiled core's passes saves time, not
only transform pairs.

    pip install --no-deps --target /tmp/before .     # at the earlier commit
    pip install --no-deps --target /tmp/after .      # at the later one
    .venv/bin/python bench/compare_builds.py /tmp/before /tmp/after
    .venv/bin/python bench/compare_builds.py /tmp/before /tmp/after --cases line:65536:8:2 areal:512:0:4

A case is geometry:n:family:scene (family 0: physical, k: shortest wavelength k points;
scene 1-4 as in bench/scaling.py), solved with --method (default 'multigrid'). Each
round runs every case once with each build, in alternating processes, each process
solving it --inner times (the first solve included: plans and allocations are part of a
solve's cost). The table gives the best ``wall_time`` of each build, their iterations and
FFT pairs (equal unless rounding tipped a contact set change) and the time ratio
after/before measured in this run.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

DEFAULT_CASES = ["line:16384:8:2", "line:16384:0:4", "line:65536:8:2", "line:65536:8:3", "line:65536:8:4",
                 "line:262144:8:4", "areal:512:8:2", "areal:512:8:4", "areal:1024:8:2"]


def worker(case: str, inner: int, method: str) -> None:
    """Solve one case `inner` times with the package on sys.path; print solver, its., pairs, time."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import scaling

    geometry, n, family, scene = case.split(":")
    n, family = int(n), int(family)
    short = scaling.PHYSICAL_SHORTEST[geometry] if family == 0 else family / n
    heights = scaling.heights(geometry, n, short)
    settings = scaling.SCENES[list(scaling.SCENES)[int(scene) - 1]]
    best = float("inf")
    for _ in range(inner):
        result = scaling.solve(geometry, heights, settings, 1e-8, method=method)
        if not result.converged:
            raise SystemExit(f"{case}: not converged ({result.solver}, residual {result.residual:.2e})")
        best = min(best, result.wall_time)
    print(result.solver, result.iterations, result.fft_pairs, best)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", nargs="?", help="directory holding the first build (pip install --target)")
    parser.add_argument("after", nargs="?", help="directory holding the second build")
    parser.add_argument("--cases", nargs="+", default=DEFAULT_CASES, help="geometry:n:family:scene")
    parser.add_argument("--method", default="multigrid")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--inner", type=int, default=3, help="solves per process")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker, args.inner, args.method)
        return
    if args.before is None or args.after is None:
        parser.error("two build directories are needed")
    builds = [str(Path(b).resolve()) for b in (args.before, args.after)]
    for b in builds:
        if not (Path(b) / "layercontact").is_dir():
            parser.error(f"{b} holds no layercontact package (pip install --no-deps --target {b} .)")
    print(f"before: {builds[0]}\nafter:  {builds[1]}\nmethod {args.method}, tol 1e-8, one thread, "
          f"best of {args.rounds} rounds x {args.inner} solves\n")
    print("| case | before: solver, it., pairs | after | before (ms) | after (ms) | after/before |")
    print("|---|---|---|---:|---:|---:|")
    for case in args.cases:
        best = {}
        counts = {}
        for _ in range(args.rounds):
            for build in builds:
                env = dict(os.environ, PYTHONPATH=build, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
                out = subprocess.run([sys.executable, __file__, "--worker", case, "--inner", str(args.inner),
                                      "--method", args.method], env=env, capture_output=True, text=True, check=True)
                solver, iterations, pairs, seconds = out.stdout.split()
                counts[build] = f"{solver}, {iterations}, {pairs}"
                best[build] = min(best.get(build, float("inf")), float(seconds))
        before, after = builds
        print(f"| {case} | {counts[before]} | {counts[after]} | {1e3 * best[before]:.1f} | {1e3 * best[after]:.1f} "
              f"| {best[after] / best[before]:.3f} |", flush=True)


if __name__ == "__main__":
    main()
