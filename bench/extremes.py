"""Iteration counts of the solver across the stability grid of tests/test_extremes.py.

The grid (tests/extremes_grid.py): rough, sinusoid and narrow-bump profiles, h/lambda
1e-4 .. 1e3 and the half-space, nu in {-0.9, 0, 0.3, 0.49, 0.5}, mu_c in {0, 0.5, 1, 1.5},
loads from one node in contact to full contact, n = 8, 9, 63, 1024 (8400 runs, ~3 s).
Prints markdown tables of the iterations (CG, or GCR for coupled scenes, plus all inner CG
iterations after an Anderson fallback) and the outer (Anderson) iterations of the converged
runs (1 without the fallback), min / median / max, grouped by h/lambda, by
mu_c and by the measured contact fraction, with the number of runs not converged (and how
many of those have Re G_eff < 0 on some mode, where the solution need not be unique), of
runs that method 'auto' started in the multigrid method, of runs whose GCR stalled (and
went on with its history kept across clips, after the multigrid method or alone), of those
that went on with the Anderson iteration, and the FFT pairs; ``--list`` also lists the runs
that did not converge, with what stopped them. ``--viscoelastic`` runs the viscoelastic grid
instead (standard linear solids, E_inf/E0 10..1000, V tau/lambda 1e-4..1e2; n = 63 and
1024, 2592 runs, ~30 s) and groups it also by E_inf/E0 and speed.

    .venv/bin/python bench/extremes.py [--viscoelastic] [--list] [--sizes 63 1024]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import extremes_grid as grid  # noqa: E402


def stats(values) -> str:
    if len(values) == 0:
        return "– | – | –"
    v = np.asarray(values)
    return f"{v.min()} | {int(np.median(v))} | {v.max()}"


def table(title: str, key: str, labels, rows) -> None:
    print(f"| {title} | runs | not conv. (not monotone) | multigrid | GCR stalled | then Anderson | "
          f"it. min | median | max | outer it. min | median | max | FFT pairs median | max |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for label in labels:
        sel = [r for r in rows if r[key] == label]
        conv = [r for r in sel if r["converged"]]
        failed = [r for r in sel if not r["converged"]]
        odd = sum(not r["monotone"] for r in failed)
        multigrid = sum(r["solver"].startswith("multigrid") for r in sel)
        stalled = sum("gcr+" in r["solver"] for r in sel)
        fallback = sum("gcr+" in r["solver"] and "anderson" in r["solver"] for r in sel)
        pairs = [r["pairs"] for r in conv]
        pair_stats = f"{int(np.median(pairs))} | {max(pairs)}" if pairs else "– | –"
        name = "inf" if label == np.inf else f"{label:g}" if isinstance(label, float) else label
        print(f"| {name} | {len(sel)} | {len(failed)} ({odd}) | {multigrid} | {stalled} | {fallback} | "
              f"{stats([r['iterations'] for r in conv])} | {stats([r['outer'] for r in conv])} | {pair_stats} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="list the runs that did not converge")
    parser.add_argument("--sizes", type=int, nargs="+")
    parser.add_argument("--viscoelastic", action="store_true",
                        help="the viscoelastic grid (standard linear solids) instead of the elastic one")
    args = parser.parse_args()
    sizes = args.sizes or list(grid.VISCO_SIZES if args.viscoelastic else grid.SIZES)
    rows, failures = [], []
    start = time.perf_counter()
    for n in sizes:
        for scene in (grid.viscoelastic_scenes(n) if args.viscoelastic else grid.scenes(n)):
            res = grid.solve(scene)
            rows.append(dict(n=n, profile=scene["profile"], thickness=scene["thickness"], nu=scene["nu"],
                             friction=scene["friction"], ratio=scene.get("ratio"), speed=scene.get("speed"),
                             band=grid.band(res.contact_fraction), monotone=res.monotone, solver=res.solver,
                             pairs=res.fft_pairs, converged=res.converged, iterations=res.iterations,
                             outer=res.outer_iterations))
            if not res.converged:
                failures.append((scene, res))
    elapsed = time.perf_counter() - start
    conv = sum(r["converged"] for r in rows)
    print(f"{len(rows)} runs (n = {', '.join(map(str, sizes))}), {conv} converged, tol {grid.TOL:g}, "
          f"max_iter {grid.MAX_ITER}, {elapsed:.0f} s; iteration counts of the converged runs; "
          f"mu_c = 0 and the incompressible half-space are solved by CG, coupled scenes by GCR or the "
          f"multigrid method (1 outer it.) or, where GCR stalls, GCR again keeping its history across clips "
          f"(1 outer it.), then Anderson (1 + its outer it.)")
    print()
    if args.viscoelastic:
        table("E_inf/E0", "ratio", grid.VISCO_RATIOS, rows)
        table("V tau/lambda", "speed", grid.VISCO_SPEEDS, rows)
        table("h/lambda", "thickness", grid.VISCO_THICKNESSES, rows)
        table("mu_c", "friction", grid.VISCO_FRICTIONS, rows)
    else:
        table("h/lambda", "thickness", grid.THICKNESSES, rows)
        table("mu_c", "friction", grid.FRICTIONS, rows)
    table("contact fraction", "band", grid.BANDS, rows)
    per_n = ", ".join(f"n = {n}: {sum(r['converged'] for r in rows if r['n'] == n)}" for n in sizes)
    print(f"converged per grid size: {per_n} (of {len(rows) // len(sizes)} each)")
    if args.list:
        print()
        print("| n | profile | E_inf/E0 | V tau/lambda | h/lambda | nu | mu_c | monotone | p_m/p_full | contact | "
              "residual | it. | outer | what stopped it |")
        print("|---:|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---|")
        for scene, res in failures:
            print(f"| {scene['n']} | {scene['profile']} | {scene.get('ratio', '–')} | {scene.get('speed', '–')} | "
                  f"{scene['thickness']:g} | {scene['nu']:g} | {scene['friction']:g} | {res.monotone} | "
                  f"{scene['load_factor']:g} | {res.contact_fraction:.4f} | {res.residual:.1e} | {res.iterations} | "
                  f"{res.outer_iterations} | {grid.diagnose(scene, res)} |")


if __name__ == "__main__":
    main()
