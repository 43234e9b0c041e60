"""Thin layers by the multigrid method against the Krylov solvers: which the method admits
(its coarse grids' worst Jacobi smoothing factor at most 0.995) and what a solve costs.

    .venv/bin/python bench/thin_layers.py                     # n = 4096, 65536 (~3 min)
    .venv/bin/python bench/thin_layers.py --sizes 4096 --thickness 0.01 0.003

Lines, self-affine (H = 0.8, rms gradient 0.1, seed 1) with the shortest wavelength 8
grid points; layers h/lambda = 0.03, 0.01, 0.003, 0.001 with nu = 0.5, 0.49, 0.45 and
mu_c = 0 (frictionless: the constrained CG for reference), 0.1, 0.5, 1.5 (GCR), at two
loads (p_m/E* = 0.0015 and 0.015: 1-25 % contact), and at nu = 0.5, mu_c = 0.5 the standard
linear solid E0 = 1, E_inf = 10, tau = 1 sliding at V = 0.1. tol 1e-8, one thread. Per row:
method 'multigrid' (solver, transform pairs, ms) or the reason it refuses the scene, the
Krylov solver's pairs and ms, the contact fraction.
"""

from __future__ import annotations

import argparse
import itertools

import layercontact as lc

E_STAR = 4 / 3  # E = 1, nu = 0.5 (the pressure scale of every row)
SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[4096, 65536])
    parser.add_argument("--thickness", type=float, nargs="+", default=[0.03, 0.01, 0.003, 0.001])
    parser.add_argument("--poisson", type=float, nargs="+", default=[0.5, 0.49, 0.45])
    parser.add_argument("--friction", type=float, nargs="+", default=[0.0, 0.1, 0.5, 1.5])
    args = parser.parse_args()
    print(f"layercontact {lc.__version__} ({lc.BUILD} build); tol 1e-8; one thread\n")
    print("| n | h/lambda | nu | mu_c | p_m/E* | layer | multigrid | pairs | ms | Krylov | pairs | ms | contact |")
    print("|---:|---:|---:|---:|---:|---|---|---:|---:|---|---:|---:|---:|")
    for n in args.sizes:
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=8 / n, rms_gradient=0.1)
        for thickness, poisson, friction, load, sliding in itertools.product(
                args.thickness, args.poisson, args.friction, (0.0015, 0.015), (False, True)):
            if sliding and (poisson != 0.5 or friction != 0.5):
                continue
            kw = dict(thickness=thickness, poisson=poisson, friction=friction, mean_pressure=load * E_STAR,
                      tol=1e-8, stress=False, threads=1)
            if sliding:
                kw.update(material=SLS, speed=0.1)
            krylov = lc.solve_line(h, method="gcr" if friction > 0 or sliding else "cg", **kw)
            try:
                mg = lc.solve_line(h, method="multigrid", **kw)
                multigrid = (f"{mg.solver}{'' if mg.converged else ' NOT CONVERGED'} | {mg.fft_pairs} "
                             f"| {mg.wall_time * 1e3:.0f}")
            except lc.InputError as err:
                factor = str(err).split("smooth with a factor ")[-1].split(" ")[0] if "smooth with" in str(err) else "-"
                multigrid = f"refused (smoothing factor {factor}) | | "
            print(f"| {n} | {thickness:g} | {poisson:g} | {friction:g} | {load:g} | {'SLS' if sliding else 'elastic'} "
                  f"| {multigrid} | {krylov.solver}{'' if krylov.converged else ' NOT CONVERGED'} | "
                  f"{krylov.fft_pairs} | {krylov.wall_time * 1e3:.0f} | {krylov.contact_fraction:.3f} |", flush=True)


if __name__ == "__main__":
    main()
