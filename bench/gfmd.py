"""GFMD against the default solver on areal contacts: steps, transform pairs and time
against the grid size, for the two surface families (spectrum fixed in physical
wavenumbers; shortest wavelength a fixed number of grid points), frictionless and coupled.

Both solve the same problem to the same complementarity residual; the ratio column is
GFMD's time over the default solver's, measured in one run.

    .venv/bin/python bench/gfmd.py [--sizes 64 128 256 512] [--tol 1e-8]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

SCENES = {
    "half-space, mu_c = 0": dict(thickness=np.inf, poisson=0.5, friction=0.0),
    "half-space nu = 0.3, mu_c = 0.5": dict(thickness=np.inf, poisson=0.3, friction=0.5),
    "h/lambda = 0.16, mu_c = 0.5": dict(thickness=0.16, poisson=0.5, friction=0.5),
}


def surface(n: int, family: str) -> np.ndarray:
    short = 1 / 32 if family == "fixed" else 8 / n
    return lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=short, rms_gradient=0.1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256, 512])
    parser.add_argument("--tol", type=float, default=1e-8)
    parser.add_argument("--max-steps", type=int, default=50000)
    args = parser.parse_args()
    print(f"{'scene':34s} {'family':8s} {'n':>5s} {'default it':>10s} {'pairs':>6s} {'GFMD steps':>10s} "
          f"{'pairs':>6s} {'conv':>5s} {'time ratio':>10s}")
    for name, scene in SCENES.items():
        for family in ("fixed", "8 points"):
            for n in args.sizes:
                h = surface(n, family)
                start = time.perf_counter()
                ref = lc.solve_areal(h, stress=False, mean_pressure=0.02, tol=args.tol, **scene)
                t_ref = time.perf_counter() - start
                start = time.perf_counter()
                dyn = lc.solve_areal(h, stress=False, mean_pressure=0.02, tol=args.tol, method="gfmd",
                                     max_iter=args.max_steps, **scene)
                t_dyn = time.perf_counter() - start
                print(f"{name:34s} {family:8s} {n:5d} {ref.iterations:10d} {ref.fft_pairs:6d} {dyn.iterations:10d} "
                      f"{dyn.fft_pairs:6d} {str(dyn.converged):>5s} {t_dyn / t_ref:10.1f}", flush=True)


if __name__ == "__main__":
    main()
