"""The runs of the viscoelastic extremes grid with a monotone operator (Re G_eff >= 0 on
every mode, so the solution is unique) that the library's iterative solvers do not finish:
those its dense Newton method finishes (`solver` ending in '+newton', grids up to 2048
points) and any left unconverged. Each is solved again by the dense semismooth Newton
method of tests/dense_reference.py (numpy, from a uniform start, independent of the
library; 3-15 s each at n = 1024), and the two solutions are compared against the bound the
tolerance allows: tol * ptp(profile) * max 1/|G_eff(k)| (a gap error of tol ptp(profile)
times the largest stiffness).

    .venv/bin/python bench/dense_check.py [--n 1024] [--max-iter 10000]

Prints one row per such run: the library's solver and residual (with the grid's max_iter)
and that of the independent solution, the largest pressure difference (in p_m and relative
to the bound) and the contact fractions.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import extremes_grid as grid  # noqa: E402
from dense_reference import solve_dense  # noqa: E402
from reference_operator import g_eff  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1024)
    parser.add_argument("--max-iter", type=int, default=grid.MAX_ITER)
    args = parser.parse_args()
    grid.MAX_ITER = args.max_iter
    start = time.perf_counter()
    print(f"n = {args.n}, library tol {grid.TOL:g} with max_iter {args.max_iter}; independent: semismooth "
          "Newton to 1e-13")
    print()
    print("| profile | E_inf/E0 | V tau/lambda | h/lambda | nu | mu_c | p_m/p_full | library solver | library residual | "
          "independent residual | max abs(p - p_dense)/p_m | / bound | contact (library) | contact (independent) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    rows = solved = unconverged = 0
    worst = 0.0
    for scene in grid.viscoelastic_scenes(args.n):
        res = grid.solve(scene)
        if not res.monotone or (res.converged and "newton" not in res.solver):
            continue
        g = g_eff(args.n, 1.0, scene["thickness"], 1.0, scene["nu"], scene["friction"], scene["material"],
                  scene["speed"])
        p, _, residual = solve_dense(scene["heights"], g, scene["mean_pressure"])
        pm = scene["mean_pressure"]
        rows += 1
        solved += residual <= 1e-12
        unconverged += not res.converged
        difference = float(np.abs(res.pressure - p).max() / pm)
        bound = grid.TOL * np.ptp(scene["heights"]) * np.max(1 / np.abs(g[1:])) / pm
        if res.converged:
            worst = max(worst, difference / bound)
        print(f"| {scene['profile']} | {scene['ratio']:g} | {scene['speed']:g} | {scene['thickness']:g} | "
              f"{scene['nu']:g} | {scene['friction']:g} | {scene['load_factor']:g} | {res.solver} | {res.residual:.1e} | "
              f"{residual:.1e} | {difference:.1e} | {difference / bound:.1e} | {res.contact_fraction:.4f} | "
              f"{np.count_nonzero(p > 1e-12 * pm) / args.n:.4f} |")
    print()
    print(f"{rows} monotone runs the iterative solvers do not finish; the library converges on "
          f"{rows - unconverged}, the independent method on {solved} (to <= 1e-12); largest pressure difference "
          f"of the converged ones {worst:.1e} of the bound; {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
