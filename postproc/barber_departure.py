"""Barber's analogy on thin layers: C E*/(2 sigma K) against the contact fraction, and the
table of numbers quoted in docs/figures.md.

    .venv/bin/python postproc/barber_departure.py [--n 256] [--out docs/barber_departure.png]

A self-affine surface (H = 0.8, seed 1, cutoff 8 grid steps, rms gradient 0.1) pressed on
layers of h/lambda = 0.05 and 0.01 bonded to a rigid, perfectly conducting base (nu = 0.3
and 0.5), frictionless and with mu_c = 0.5, at loads p_m/(E* h/lambda) from 0.01 to 2, and
on a half-space (where the ratio is 1 to rounding). Each point is one solve with
``conductance=True``: the conductance C and the stiffness K at its contact set.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import layercontact as lc

ROOT = Path(__file__).resolve().parents[1]
LOADS = np.geomspace(0.01, 2.0, 8)
LAYERS = [(0.05, 0.3), (0.05, 0.5), (0.01, 0.3), (0.01, 0.5)]
FRICTIONS = (0.0, 0.5)


def ratio(res, poisson: float) -> float:
    """C E*/(2 sigma K) with E = 1 and sigma = 1."""
    return res.conductance / (2 * res.contact_stiffness) / (1 - poisson**2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=256)
    parser.add_argument("--out", default=str(ROOT / "docs" / "barber_departure.png"))
    args = parser.parse_args()
    heights = lc.self_affine_surface(n=args.n, hurst=0.8, seed=1, short_wavelength=8 / args.n, rms_gradient=0.1)
    curves = {}
    print("| h/lambda | nu | mu_c | p_m/(E* h/lambda) | contact fraction | C/sigma (1/L) | K (E/L) | C E*/(2 sigma K) |")
    print("|---|---|---|---|---|---|---|---|")
    for thickness, poisson in LAYERS:
        for friction in FRICTIONS:
            points = []
            for load in LOADS:
                res = lc.solve_areal(heights, period=1.0, thickness=thickness, poisson=poisson, friction=friction,
                                     normalised_pressure=load, stress=False, tol=1e-10, conductance=True)
                if not (res.converged and res.conductance_converged):
                    print(f"not converged: h = {thickness}, nu = {poisson}, mu_c = {friction}, load {load:.3g}")
                    continue
                points.append((res.contact_fraction, ratio(res, poisson)))
                if load in (LOADS[0], LOADS[3], LOADS[-1]):
                    print(f"| {thickness:g} | {poisson:g} | {friction:g} | {load:.3g} | {res.contact_fraction:.4f} | "
                          f"{res.conductance:.4g} | {res.contact_stiffness:.4g} | {points[-1][1]:.4f} |")
            curves[thickness, poisson, friction] = np.array(points)
    half = lc.solve_areal(heights, period=1.0, poisson=0.3, normalised_pressure=0.05, stress=False, tol=1e-10,
                          conductance=True)
    print(f"half-space, nu = 0.3, frictionless: C E*/(2 sigma K) - 1 = {ratio(half, 0.3) - 1:.1e}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.0, 4.6))
    colours = {LAYERS[0]: "C0", LAYERS[1]: "C1", LAYERS[2]: "C2", LAYERS[3]: "C3"}
    for (thickness, poisson, friction), points in curves.items():
        style = "-o" if friction == 0 else "--s"
        ax.plot(points[:, 0], points[:, 1], style, color=colours[thickness, poisson], ms=4,
                label=f"h/lambda = {thickness:g}, nu = {poisson:g}, mu_c = {friction:g}")
    ax.axhline(1.0, color="k", lw=0.8, label="half-space (Barber's analogy)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("contact fraction A/A0")
    ax.set_ylabel("C E* / (2 sigma K)")
    ax.set_title(f"Barber's analogy on thin layers ({args.n}$^2$, self-affine H = 0.8)")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"figure: {args.out}")


if __name__ == "__main__":
    main()
