"""Cost of the conductance and the interfacial stiffness against the contact solve they
follow, on a self-affine surface (H = 0.8, cutoff 8 grid steps, rms gradient 0.1) pressed
on an elastic half-space (nu = 0.5) and on a thin compressible layer with friction.

For each grid size: the contact solve (``lc.solve_areal``, stress off, tol 1e-8) timed
alone; the same solve with ``conductance=True`` (what ``&output conductance`` adds: the
conductance and the stiffness, each to the scene's tol); and ``lc.contact_conductance`` on
the solved contact map alone. Prints the seconds, the iterations of each and the ratios
within the run (the machine may be shared: compare ratios, not seconds).

    .venv/bin/python bench/conductance.py [--sizes 512 2048] [--scene halfspace layer]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

SCENES = {
    "halfspace": dict(thickness=np.inf, poisson=0.5, friction=0.0, normalised_pressure=0.05),
    "layer": dict(thickness=0.05, poisson=0.3, friction=0.5, normalised_pressure=0.05),
}


def timed(function, *args, **kwargs):
    start = time.perf_counter()
    out = function(*args, **kwargs)
    return out, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 2048])
    parser.add_argument("--scene", nargs="+", default=["halfspace", "layer"], choices=sorted(SCENES))
    args = parser.parse_args()
    print(f"{'scene':>10} {'n':>5} {'fraction':>9} {'solve s':>8} {'+cond s':>8} {'map s':>7} "
          f"{'solve it':>8} {'C it':>5} {'K it':>5} {'added/solve':>11} {'map/solve':>9}")
    for name in args.scene:
        for n in args.sizes:
            heights = lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=8 / n, rms_gradient=0.1)
            keywords = dict(SCENES[name], period=1.0, stress=False, tol=1e-8)
            plain, solve_seconds = timed(lc.solve_areal, heights, **keywords)
            full, with_seconds = timed(lc.solve_areal, heights, conductance=True, **keywords)
            _, map_seconds = timed(lc.contact_conductance, full.pressure > 0, 1.0, 1.0,
                                   thickness=keywords["thickness"], tol=1e-8)
            assert full.converged and full.conductance_converged
            added = with_seconds - solve_seconds
            print(f"{name:>10} {n:5d} {full.contact_fraction:9.4f} {solve_seconds:8.2f} {added:8.2f} "
                  f"{map_seconds:7.2f} {plain.iterations:8d} {full.conductance_iterations:5d} "
                  f"{full.stiffness_iterations:5d} {added / solve_seconds:11.3f} {map_seconds / solve_seconds:9.3f}")


if __name__ == "__main__":
    main()
