"""Leakage against contact area, and the contact area at which the flow stops percolating.

Random isotropic self-affine surfaces (``lc.self_affine_surface``: H = 0.8, rms gradient 0.1,
roll-off at the period, shortest wavelength --short-wavelength) pressed on a frictionless
incompressible elastic half-space (``lc.solve_areal``, E = 1, nu = 0.5, tol 1e-8) over a range
of mean pressures; for each gap the Reynolds conductance ``k_eff`` along x and along y
(``lc.reynolds_leakage``, contact = the cells with positive pressure).

Table 1: per load, the mean relative contact area, the geometric mean of ``k_eff`` over the
percolating (realisation, direction) pairs in units of ``<g>^3`` at the lightest load, and
the fraction of pairs that percolate.

Threshold: for each (realisation, direction) pair, the load at which the fluid stops winding
around the cell is bracketed by the sweep and refined by bisection (--bisections steps);
the threshold is the contact area there. Printed: mean, standard deviation and standard
error per grid size, next to the literature (Wang and Müser, Tribol. Lett. 2021: about 0.42
for isotropic roughness; Bruggeman's effective medium: 0.5), and a rough fit of
``k_eff ~ (a_c - a)^t`` near each pair's threshold (Dapp and Müser, EPL 109, 44001, 2015:
t about 3.45, on much larger systems).

The fluid connects through cell faces only, so contact cells touching at a corner close
the flow: on a coarse grid that lowers the threshold; the same surfaces at two resolutions
(the default sizes at a fixed shortest wavelength) show by how much.

    .venv/bin/python bench/percolation.py [--sizes 128 256] [--realisations 10]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

LITERATURE = {"Wang and Müser (isotropic roughness)": 0.42, "Bruggeman effective medium (2D)": 0.5}


def surface(n: int, seed: int, short_wavelength: float) -> np.ndarray:
    return lc.self_affine_surface(
        n=n, hurst=0.8, seed=seed, short_wavelength=short_wavelength, rms_gradient=0.1
    )


def contact_and_flow(heights: np.ndarray, pressure: float) -> tuple[float, float, dict]:
    """Contact fraction, mean gap and the leakage results along x and y at one load."""
    sol = lc.solve_areal(heights, stress=False,
                         thickness=np.inf, poisson=0.5, mean_pressure=pressure, tol=1e-8)
    contact = sol.pressure > 0
    flow = {d: lc.reynolds_leakage(sol.gap, contact=contact, direction=d) for d in ("x", "y")}
    return sol.contact_fraction, sol.mean_gap, flow


def threshold(heights, direction, low, high, steps):
    """Bisect the load between ``low`` (percolating) and ``high`` (not) for the contact
    fraction where the flow along ``direction`` stops; returns the midpoint of the bracket
    in contact fraction."""
    a_low = a_high = None
    for _ in range(steps):
        middle = np.sqrt(low * high)  # loads span decades: bisect in log
        a, _, flow = contact_and_flow(heights, middle)
        if flow[direction].percolating:
            low, a_low = middle, a
        else:
            high, a_high = middle, a
    if a_low is None:
        a_low = contact_and_flow(heights, low)[0]
    if a_high is None:
        a_high = contact_and_flow(heights, high)[0]
    return 0.5 * (a_low + a_high)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[128, 256])
    parser.add_argument("--realisations", type=int, default=10)
    parser.add_argument("--short-wavelength", type=float, default=1 / 32, help="in units of the period")
    parser.add_argument(
        "--loads",
        type=float,
        nargs="+",
        default=[0.002, 0.004, 0.007, 0.01, 0.014, 0.018, 0.022, 0.026, 0.03, 0.035, 0.04, 0.05, 0.07],
    )
    parser.add_argument("--bisections", type=int, default=7)
    args = parser.parse_args()
    loads = sorted(args.loads)
    start = time.perf_counter()
    print(
        f"H = 0.8, rms gradient 0.1, shortest wavelength {args.short_wavelength:g} L, half-space nu = 0.5, "
        f"E = 1 (E* = 4/3); {args.realisations} realisations; k_eff along x and y\n"
    )

    summary = {}
    for n in args.sizes:
        areas = np.zeros((args.realisations, len(loads)))
        k = np.zeros((args.realisations, len(loads), 2))
        scale = np.zeros(args.realisations)
        thresholds = np.full((args.realisations, 2), np.nan)
        for seed in range(1, args.realisations + 1):
            heights = surface(n, seed, args.short_wavelength)
            for j, pressure in enumerate(loads):
                areas[seed - 1, j], mean_gap, flow = contact_and_flow(heights, pressure)
                k[seed - 1, j] = flow["x"].k_eff, flow["y"].k_eff
                if j == 0:
                    scale[seed - 1] = mean_gap**3
            for d, direction in enumerate(("x", "y")):
                open_ = np.flatnonzero(k[seed - 1, :, d] > 0)
                closed = np.flatnonzero(k[seed - 1, :, d] == 0)
                if open_.size == 0 or closed.size == 0:
                    continue  # the sweep does not bracket the threshold
                thresholds[seed - 1, d] = threshold(
                    heights, direction, loads[open_.max()], loads[closed.min()], args.bisections
                )

        print(f"## {n}^2 ({args.short_wavelength * n:g} grid steps per shortest wavelength)\n")
        print("| p/E | contact area | sd | geometric mean k_eff/<g0>^3 | percolating pairs |")
        print("|---|---|---|---|---|")
        relative = k / scale[:, None, None]
        for j, pressure in enumerate(loads):
            values = relative[:, j].ravel()
            flowing = values[values > 0]
            mean_k = f"{np.exp(np.log(flowing).mean()):.3e}" if flowing.size else "0"
            print(
                f"| {pressure:g} | {areas[:, j].mean():.4f} | {areas[:, j].std():.4f} | {mean_k} | "
                f"{flowing.size}/{values.size} |"
            )
        # k ~ (a_c - a)^t: each pair against its own threshold (the thresholds scatter more
        # than the distance of the last loads to them), pooled over the pairs
        distance = thresholds[:, None, :] - areas[:, :, None]
        near = (relative > 0) & (distance > 0) & (distance < 0.15)
        thresholds = thresholds[np.isfinite(thresholds)]
        summary[n] = thresholds
        print(
            f"\nthreshold a_c over {thresholds.size} (realisation, direction) pairs: mean {thresholds.mean():.4f}, "
            f"sd {thresholds.std(ddof=1):.4f}, standard error {thresholds.std(ddof=1) / np.sqrt(thresholds.size):.4f}"
        )
        if np.count_nonzero(near) >= 4:
            slope = np.polyfit(np.log(distance[near]), np.log(relative[near]), 1)[0]
            print(
                f"pooled fit k_eff ~ (a_c - a)^t over {np.count_nonzero(near)} points within 0.15 of their "
                f"threshold: t = {slope:.2f}"
            )
        print()

    print("| estimate | a_c |")
    print("|---|---|")
    for n, values in summary.items():
        print(
            f"| this bench, {n}^2 | {values.mean():.3f} +- {values.std(ddof=1) / np.sqrt(values.size):.3f} |"
        )
    for name, value in LITERATURE.items():
        print(f"| {name} | {value} |")
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
