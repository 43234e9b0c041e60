"""Iterations, FFT pairs and wall time of layercontact's areal solver against the grid
size, for two surface families, frictionless half-space and a coupled layer.

    .venv/bin/python bench/areal_iterations.py                   # n = 256, 512, 1024 (~1 min)
    .venv/bin/python bench/areal_iterations.py --sizes 256 512 1024 2048

Surfaces (``layercontact.self_affine_surface``): isotropic self-affine, Hurst
exponent 0.8, rms gradient 0.1, seed 1, n x n points of a unit square period.

- family (a): spectrum fixed in physical wavenumbers, shortest wavelength period/32: the
  same surface at every n (the generator's phases depend on the mode, not the grid), so
  refining the grid only adds resolution (8 points per shortest wavelength at 256^2, 64 at
  2048^2);
- family (b): shortest wavelength 8 grid points (period/32 at 256^2, period/256 at
  2048^2), so finer grids carry more roughness scales (the harder problem for a solver).

Scenes: frictionless half-space (nu = 0.5, p_m/E* = 0.0125; constrained CG) and a coupled
layer (h/period = 0.16 bonded to a rigid base, nu = 0.5, mu_c = 0.5, p_m/E* = 0.015;
GCR), both ~25 % contact at 256^2, and the same layer as a standard linear solid (E0 = 1,
E_inf = 10, tau = 1) sliding at V = 0.1 (GCR; ~7 % contact at the same load); load fixed
across n. layercontact's defaults otherwise
(method 'auto', Fourier preconditioner, coarse start), tol 1e-8 (the dimensionless
complementarity residual), threads = 1. "it.": CG or GCR iterations on the finest grid
(plus inner CG iterations after an Anderson fallback, marked +a); "pairs": FFT pairs in
units of the finest grid's (coarse levels included); "ms": the library's solve time
(``wall_time``: operator, coarse levels, iterations), best of ``--repeats``. The last table
gives max/min of the iterations over n per family and scene (target <= 1.5 on family (a)).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import layercontact as lc  # noqa: E402
from areal_surfaces import generator_name, surface  # noqa: E402

CONTACT_MODULUS = 4 / 3  # E = 1, nu = 0.5
SCENES = {
    "half-space, mu_c = 0": dict(thickness=np.inf, friction=0.0, pressure=0.0125),
    "h/lambda = 0.16, mu_c = 0.5": dict(thickness=0.16, friction=0.5, pressure=0.015),
    # a standard linear solid (E0 = 1, E_inf = 10, tau = 1) sliding at V = 0.1: the short
    # waves of the grid are glassy, the long ones rubbery
    "SLS h/lambda = 0.16, mu_c = 0.5, V = 0.1": dict(thickness=0.16, friction=0.5, pressure=0.015,
                                                    material=lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0),
                                                    speed=0.1),
}
FAMILIES = {
    "(a) lambda_s = period/32": lambda n: 1 / 32,
    "(b) lambda_s = 8 points": lambda n: 8 / n,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--tol", type=float, default=1e-8)
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    start = time.perf_counter()
    print(f"layercontact {lc.__version__} ({lc.BUILD} build); surface: {generator_name()}; tol {args.tol:g}; "
          f"threads 1\n")
    print("| family | scene | n | points per lambda_s | contact fraction | solver | it. | pairs | ms |")
    print("|---|---|---:|---:|---:|---|---:|---:|---:|")
    spread = []
    for family, short in FAMILIES.items():
        for scene, s in SCENES.items():
            iterations = []
            for n in args.sizes:
                h = surface(n, short_wavelength=short(n))
                best = None
                for _ in range(args.repeats):
                    r = lc.solve_areal(h, stress=False,
                                       thickness=s["thickness"], poisson=0.5, friction=s["friction"],
                                       mean_pressure=s["pressure"] * CONTACT_MODULUS, tol=args.tol, threads=1,
                                       material=s.get("material"), speed=s.get("speed", 0.0))
                    if best is None or r.wall_time < best.wall_time:
                        best = r
                r = best
                flag = "" if r.converged else " NOT CONVERGED"
                fallback = " +a" if "anderson" in r.solver else ""
                iterations.append(r.iterations)
                print(f"| {family} | {scene} | {n}^2 | {short(n) * n:.0f} | {r.contact_fraction:.4f} | {r.solver} "
                      f"| {r.iterations}{fallback}{flag} | {r.fft_pairs} | {r.wall_time * 1e3:.0f} |", flush=True)
            spread.append((family, scene, min(iterations), max(iterations)))
    print("\n| family | scene | min it. | max it. | max/min |")
    print("|---|---|---:|---:|---:|")
    for family, scene, low, high in spread:
        print(f"| {family} | {scene} | {low} | {high} | {high / low:.2f} |")
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
