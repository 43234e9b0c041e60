"""GFMD against the default solver on the paper's Fig. 3 family: steps, transform pairs and
time against the grid size, or the refusal where the damped dynamics cannot relax the scene.

The scenes of inputs/sweeps/fig3*.nml: a self-affine surface (H = 0.8, shortest wavelength
lambda/32, rms gradient 0.1) on an incompressible layer, h/lambda = 0.05 and 0.16, mu_c = 0,
0.2, 0.5 and 1, loads p_m/(E* h/lambda) from a few per cent to nearly full contact. Both
methods solve the same problem to the same complementarity residual; the ratio column is
GFMD's time over the default solver's, measured in one run.

    .venv/bin/python bench/gfmd.py [--sizes 64 128 256 512] [--tol 1e-8]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

THICKNESSES = (0.05, 0.16)
FRICTIONS = (0.0, 0.2, 0.5, 1.0)
LOADS = (0.02154, 1.0, 21.54)


def surface(n: int) -> np.ndarray:
    return lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=1 / 32, rms_gradient=0.1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256, 512])
    parser.add_argument("--tol", type=float, default=1e-8)
    parser.add_argument("--max-steps", type=int, default=20000)
    args = parser.parse_args()
    print(f"{'h/lambda':>8s} {'mu_c':>5s} {'load':>8s} {'n':>5s} {'contact':>7s} {'default it':>10s} "
          f"{'pairs':>6s} {'GFMD steps':>10s} {'pairs':>6s} {'conv':>5s} {'time ratio':>10s}")
    for thickness in THICKNESSES:
        for friction in FRICTIONS:
            for load in LOADS:
                for n in args.sizes:
                    h = surface(n)
                    keys = dict(thickness=thickness, poisson=0.5, friction=friction, normalised_pressure=load,
                                stress=False, tol=args.tol)
                    start = time.perf_counter()
                    ref = lc.solve_areal(h, **keys)
                    t_ref = time.perf_counter() - start
                    contact = np.mean(ref.pressure > 0)
                    head = (f"{thickness:8.2f} {friction:5.1f} {load:8.4g} {n:5d} {contact:7.3f} "
                            f"{ref.iterations:10d} {ref.fft_pairs:6d}")
                    try:
                        start = time.perf_counter()
                        dyn = lc.solve_areal(h, method="gfmd", max_iter=args.max_steps, **keys)
                        t_dyn = time.perf_counter() - start
                    except lc.InputError:
                        print(f"{head} {'refused':>10s}", flush=True)
                        continue
                    print(f"{head} {dyn.iterations:10d} {dyn.fft_pairs:6d} {str(dyn.converged):>5s} "
                          f"{t_dyn / t_ref:10.1f}", flush=True)


if __name__ == "__main__":
    main()
