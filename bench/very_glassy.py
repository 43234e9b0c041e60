"""Very glassy layers with friction near their loss peak: convergence and cost of the
multigrid method and of method 'auto' across moduli ratios and sliding speeds, on both
roughness families.

    .venv/bin/python bench/very_glassy.py                   # n = 16384 (~2 min)
    .venv/bin/python bench/very_glassy.py --sizes 4096 65536 --e-inf 1000 2000 --speeds 0.003 0.01 0.03

The layer: h/lambda = 0.16, nu = 0.5, mu_c = 0.5, a standard linear solid with E0 = 1,
tau = 1 and E_inf/E0 = 500, 1000, 2000 (largest loss tangent 11.2, 15.8, 22.3), sliding at
V tau/lambda = 0.003 .. 0.1 (the loss peak among the grid's middle and short waves),
p_m = 0.02 E0. The profile: self-affine, H = 0.8, rms gradient 0.1, seed 1, its spectrum
fixed in physical wavenumbers (shortest wavelength lambda/64) or with the shortest
wavelength 8 grid points. tol 1e-8, the default budget of 100000 iterations, one thread,
one run each (transform pairs are deterministic; times are of one run). Per row and
method: the solver that ran, transform pairs, seconds, or "stops" with the residual
reached.
"""

from __future__ import annotations

import argparse

import layercontact as lc


def cell(r) -> str:
    if not r.converged:
        return f"stops at {r.residual:.1e} ({r.fft_pairs} pairs, {r.wall_time:.3g} s)"
    return f"{r.solver}: {r.fft_pairs}, {r.wall_time:.3g}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[16384])
    parser.add_argument("--e-inf", type=float, nargs="+", default=[500.0, 1000.0, 2000.0])
    parser.add_argument("--speeds", type=float, nargs="+", default=[0.003, 0.01, 0.03, 0.1])
    parser.add_argument("--methods", nargs="+", default=["multigrid", "auto"])
    args = parser.parse_args()
    print(f"layercontact {lc.__version__}; h/lambda = 0.16, nu = 0.5, mu_c = 0.5, p_m = 0.02 E0, tol 1e-8, "
          "one thread\n")
    print("| family | n | E_inf/E0 | V tau/lambda | " + " | ".join(args.methods) + " |")
    print("|---|---:|---:|---:|" + "---|" * len(args.methods))
    for family, shortest in (("physical", lambda n: 1 / 64), ("8 points", lambda n: 8 / n)):
        for n in args.sizes:
            h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=shortest(n), rms_gradient=0.1)
            for e_inf in args.e_inf:
                material = lc.StandardLinearSolid(e0=1.0, e_inf=e_inf, tau=1.0)
                for speed in args.speeds:
                    cells = []
                    for method in args.methods:
                        r = lc.solve_line(h, method=method, thickness=0.16, poisson=0.5, friction=0.5,
                                          mean_pressure=0.02, tol=1e-8, threads=1, stress=False,
                                          material=material, speed=speed)
                        cells.append(cell(r))
                    print(f"| {family} | {n} | {e_inf:g} | {speed:g} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
