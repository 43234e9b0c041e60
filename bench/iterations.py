"""Iteration counts and time versus grid size on one problem family.

The same physical problem is solved at every n: a self-affine profile whose spectrum is
fixed in physical wavenumbers (roll-off at the period, cutoff at period/64), so that
refining the grid only adds resolution. The tolerance is the dimensionless
complementarity residual, which means the same thing at every n.

    .venv/bin/python bench/iterations.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

SCENES = {
    "half-space, mu_c = 0": dict(thickness=np.inf, friction=0.0, pressure=0.3),
    "h/lambda = 0.16, mu_c = 0.5": dict(thickness=0.16, friction=0.5, pressure=3.0),
    "h/lambda = 0.01, mu_c = 0.5": dict(thickness=0.01, friction=0.5, pressure=30.0),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n up to 8192 only")
    parser.add_argument("--tol", type=float, default=1e-8)
    args = parser.parse_args()
    sizes = [1024, 2048, 4096, 8192] if args.quick else [1024, 4096, 16384, 65536]
    print(f"tol = {args.tol:g}; pressure in the seed's scale p_m/(E* Lambda/lambda); nu = 0.5")
    print(f"{'scene':<30}{'precond':>8}{'n':>7}{'CG it':>8}{'outer':>7}{'FFT pairs':>11}{'time (s)':>10}"
          f"{'contact':>9}")
    for name, s in SCENES.items():
        for precondition in (False, True):
            for n in sizes:
                h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
                pm = s["pressure"] * (4 / 3) * h.max()
                t = time.perf_counter()
                r = lc.solve_line(h, thickness=s["thickness"], friction=s["friction"], mean_pressure=pm,
                                  tol=args.tol, precondition=precondition)
                t = time.perf_counter() - t
                flag = "" if r.converged else "  NOT CONVERGED"
                print(f"{name:<30}{str(precondition):>8}{n:>7}{r.iterations:>8}{r.outer_iterations:>7}"
                      f"{r.fft_pairs:>11}{t:>10.3f}{r.contact_fraction:>9.4f}{flag}")


if __name__ == "__main__":
    main()
