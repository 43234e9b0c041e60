"""Sliding viscoelastic surfaces across speeds by the multigrid method against GCR: that
every solve converges, and what it costs.

    .venv/bin/python bench/viscoelastic_surfaces.py                 # 128^2 (~20 s)
    .venv/bin/python bench/viscoelastic_surfaces.py --sizes 512     # (~4 min)
    .venv/bin/python bench/viscoelastic_surfaces.py --sizes 256 512 --ratios 100 300 1000 \
        --speeds 0.003 0.01 0.03 --poisson 0.3 0.5                  # near the loss peak (~20 min)
    .venv/bin/python bench/viscoelastic_surfaces.py --sizes 128 256 --ratios 30 100 300 1000 \
        --speeds 0.001 0.003 0.01 0.03 0.1 --methods auto          # what 'auto' picks (~2 min)

Surfaces, self-affine (H = 0.8, rms gradient 0.1, seed 1) with the spectrum fixed in
physical wavenumbers (shortest wavelength period/32) or the shortest wavelength 8 grid
points (broadband); a layer h/lambda = 0.16, nu = 0.5 (or --poisson), a standard linear
solid E0 = 1, tau = 1 with E_inf/E0 = 10 and 100 (or --ratios) sliding at V tau/lambda =
1e-3 .. 1e2 (or --speeds), mu_c = 0 and 0.5, p_m = 0.02 E0. Along the sliding direction
the layer's short waves are glassier than across it, so the multigrid halves its coarse
grids along one axis where that smooths better, or smooths by rows
(docs/decisions/013-anisotropic-coarsening.md, 015-row-smoothing.md). tol 1e-8, one
thread. Per row and method (--methods; 'multigrid' and 'gcr' unless given): the solver
that ran, transform pairs and time (the library's `wall_time`).
"""

from __future__ import annotations

import argparse
import itertools

import layercontact as lc


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[128])
    parser.add_argument("--ratios", type=float, nargs="+", default=[10.0, 100.0], help="E_inf/E0")
    parser.add_argument("--speeds", type=float, nargs="+", default=[1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0])
    parser.add_argument("--poisson", type=float, nargs="+", default=[0.5], help="the layer's Poisson ratios")
    parser.add_argument("--methods", nargs="+", default=["multigrid", "gcr"],
                        help="&solver methods, one column group each ('auto': the one the library picks)")
    args = parser.parse_args()
    print(f"layercontact {lc.__version__} ({lc.BUILD} build); tol 1e-8; one thread\n")
    print("| n | family | nu | E_inf/E0 | V tau/lambda | mu_c | "
          + " | ".join(f"{method} | pairs | ms" for method in args.methods) + " | contact |")
    print("|---:|---|---:|---:|---:|---:|" + "---|---:|---:|" * len(args.methods) + "---:|")
    for n in args.sizes:
        for family, shortest in (("physical", 1 / 32), ("8 points", 8 / n)):
            h = lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=shortest, rms_gradient=0.1)
            scenes = itertools.product(args.poisson, args.ratios, args.speeds, (0.0, 0.5))
            for nu, ratio, speed, friction in scenes:
                material = lc.StandardLinearSolid(e0=1.0, e_inf=ratio, tau=1.0)
                kw = dict(thickness=0.16, poisson=nu, friction=friction, material=material, speed=speed,
                          mean_pressure=0.02, tol=1e-8, threads=1, stress=False)
                cells = []
                for method in args.methods:
                    r = lc.solve_areal(h, method=method, **kw)
                    cells.append(f"{r.solver}{'' if r.converged else ' NOT CONVERGED'} | {r.fft_pairs} "
                                 f"| {r.wall_time * 1e3:.0f}")
                print(f"| {n}^2 | {family} | {nu:g} | {ratio:g} | {speed:g} | {friction:g} | "
                      + " | ".join(cells) + f" | {r.contact_fraction:.3f} |", flush=True)


if __name__ == "__main__":
    main()
