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
    variants = {"plain": dict(precondition=False, coarse_start=False),
                "precond.": dict(precondition=True, coarse_start=False),
                "precond. + coarse start": dict(precondition=True, coarse_start=True)}
    print(f"core: {lc.BUILD} build; tol = {args.tol:g}; pressure in the seed's scale p_m/(E* Lambda/lambda); nu = 0.5")
    print("iterations on the finest grid (CG for the half-space, GCR for the coupled scenes; after an Anderson "
          "fallback, marked +a, the GCR iterations plus all inner CG iterations); FFT pairs in units of pairs of "
          "the finest grid (coarse levels included); time in ms; 'plain': no Fourier preconditioner\n")
    header = "| scene | n | " + " | ".join(f"{v} it. | pairs | ms" for v in variants) + " |"
    print(header)
    print("|---|---:|" + "---:|---:|---:|" * len(variants))
    for name, s in SCENES.items():
        for n in sizes:
            h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
            pm = s["pressure"] * (4 / 3) * h.max()
            cells = []
            for settings in variants.values():
                t = time.perf_counter()
                r = lc.solve_line(h, thickness=s["thickness"], friction=s["friction"], mean_pressure=pm,
                                  tol=args.tol, stress=False, **settings)
                t = time.perf_counter() - t
                flag = "" if r.converged else " NOT CONVERGED"
                fallback = " +a" if r.solver.startswith("gcr+") and "anderson" in r.solver else ""
                cells.append(f"{r.iterations}{fallback}{flag} | {r.fft_pairs} | {t * 1e3:.0f}")
            print(f"| {name if n == sizes[0] else ''} | {n} | " + " | ".join(cells) + " |")

if __name__ == "__main__":
    main()
