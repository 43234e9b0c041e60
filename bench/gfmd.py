"""GFMD against the default solver on the paper's Fig. 3 family: steps, updates of the
friction traction, transform pairs and time against the grid size, or the refusal where the
damped dynamics cannot relax the scene.

The scenes of inputs/sweeps/fig3*.nml: a self-affine surface (H = 0.8, shortest wavelength
lambda/32, rms gradient 0.1) on an incompressible layer, h/lambda = 0.05 and 0.16, mu_c = 0,
0.2, 0.5 and 1, loads p_m/(E* h/lambda) from ~0.5 % contact to full contact. Both methods
solve the same problem to the same complementarity residual, one after the other in the same
run: the ratio column is GFMD's time over the default solver's. The agreement columns: the
largest pressure difference over p_m, the contact nodes that differ, Delta mu's and the
penetration's relative differences.

    .venv/bin/python bench/gfmd.py [--sizes 64 128 256 512] [--tol 1e-8] [--repeat 1]
        [--thicknesses 0.05 0.16] [--frictions 0 0.2 0.5 1] [--loads ...] [--seeds 1]
        [--masses auto]

--masses one mode: each scene by GFMD with one mass for every node and with a mass per mode
on the free set (&solver gfmd_mass), against the same default solve.

With several seeds (realisations of the surface) it ends with the ratio of the total times.
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np

import layercontact as lc

THICKNESSES = (0.05, 0.16)
FRICTIONS = (0.0, 0.2, 0.5, 1.0)
# p_m/(E* h/lambda): ~0.5 %, 2 %, ~10 %, ~30 % contact, and nearly full or full contact
LOADS = {0.05: (0.004642, 0.02154, 0.2154, 1.0, 21.54), 0.16: (0.001, 0.02154, 0.2154, 1.0, 10.0)}


def surface(n: int, seed: int = 1) -> np.ndarray:
    return lc.self_affine_surface(n=n, hurst=0.8, seed=seed, short_wavelength=1 / 32, rms_gradient=0.1)


def timed(repeat, solve):
    """The least wall time of `repeat` runs of `solve` (the machine is shared) and its result."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        result = solve()
        best = min(best, time.perf_counter() - start)
    return best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256, 512])
    parser.add_argument("--tol", type=float, default=1e-8)
    parser.add_argument("--max-steps", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=1, help="time each solve as the least of this many runs")
    parser.add_argument("--thicknesses", type=float, nargs="+", default=list(THICKNESSES))
    parser.add_argument("--frictions", type=float, nargs="+", default=list(FRICTIONS))
    parser.add_argument("--loads", type=float, nargs="+", default=None,
                        help="p_m/(E* h/lambda); default: five from ~0.5 %% to full contact per thickness")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1], help="realisations of the surface")
    parser.add_argument("--masses", nargs="+", default=["auto"], choices=["auto", "one", "mode"],
                        help="GFMD's masses (&solver gfmd_mass), each a run of its own")
    args = parser.parse_args()
    print(f"{'seed':>4s} {'h/lambda':>8s} {'mu_c':>5s} {'load':>8s} {'n':>5s} {'contact':>7s} {'default it':>10s} "
          f"{'pairs':>6s} {'mass':>4s} {'GFMD steps':>10s} {'updates':>7s} {'pairs':>6s} {'conv':>5s} {'time ratio':>10s} "
          f"{'dp/p_m':>8s} {'nodes':>5s} {'dDmu':>8s} {'dpen':>8s}")
    totals = [0.0, 0.0]   # the default solver's and GFMD's time over the scenes both solved
    for seed, thickness, friction in itertools.product(args.seeds, args.thicknesses, args.frictions):
        for load in args.loads or LOADS.get(thickness, LOADS[0.16]):
            for n in args.sizes:
                h = surface(n, seed)
                keys = dict(thickness=thickness, poisson=0.5, friction=friction, normalised_pressure=load,
                            stress=False, tol=args.tol)
                t_ref, ref = timed(args.repeat, lambda: lc.solve_areal(h, **keys))
                contact = np.mean(ref.pressure > 0)
                head = (f"{seed:4d} {thickness:8.2f} {friction:5.1f} {load:8.4g} {n:5d} {contact:7.3f} "
                        f"{ref.iterations:10d} {ref.fft_pairs:6d}")
                for mass in args.masses:
                    try:
                        t_dyn, dyn = timed(args.repeat, lambda: lc.solve_areal(
                            h, method="gfmd", gfmd_mass=mass, max_iter=args.max_steps, **keys))
                    except lc.InputError:
                        print(f"{head} {mass:>4s} {'refused':>10s}", flush=True)
                        continue
                    nodes = np.count_nonzero((dyn.pressure > 0) != (ref.pressure > 0))
                    dp = np.max(np.abs(dyn.pressure - ref.pressure)) / ref.mean_pressure
                    ddmu = abs(dyn.delta_mu - ref.delta_mu) / max(abs(ref.delta_mu), 1e-3)
                    dpen = abs(dyn.penetration - ref.penetration) / abs(ref.penetration)
                    updates = dyn.outer_iterations if friction > 0 else 0   # (1 where none ran)
                    totals[0] += t_ref
                    totals[1] += t_dyn
                    print(f"{head} {mass:>4s} {dyn.iterations:10d} {updates:7d} {dyn.fft_pairs:6d} "
                          f"{str(dyn.converged):>5s} {t_dyn / t_ref:10.1f} {dp:8.1e} {nodes:5d} {ddmu:8.1e} "
                          f"{dpen:8.1e}", flush=True)
    if totals[0] > 0:
        print(f"GFMD's time over the default solver's, all scenes: {totals[1] / totals[0]:.2f}")


if __name__ == "__main__":
    main()
