"""Friction against sliding speed on a viscoelastic layer (reads only HDF5), and the table
of numbers quoted in docs/figures.md.

    .venv/bin/python -m layercontact sweep inputs/sweeps/viscoelastic_speed.nml
    .venv/bin/python postproc/friction_speed.py [--out docs/friction_speed.png]

Total friction mu_c + Delta mu (mean over the profile realisations) against V tau/lambda on
a log axis, one panel per thickness, one line per mu_c; the sweep's speeds 0 and 1e12 are
the elastic limits with E0 and E_inf, drawn as dashed and dotted lines.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DIRECTORY = ROOT / "out" / "viscoelastic_speed"
FAST = 1e11  # speeds above this are the V -> inf limit


def summary() -> dict[str, np.ndarray]:
    path = DIRECTORY / "viscoelastic_speed_summary.h5"
    if not path.exists():
        raise SystemExit(f"{path}: run the sweep first (see the docstring)")
    with h5py.File(path, "r") as f:
        cols = {k: f["summary"][k][()] for k in f["summary"]}
    bad = cols["converged"] != 1
    if np.any(bad):
        # reported, and left out of the means (not silently averaged in)
        print(f"{np.count_nonzero(bad)} of {bad.size} scenes did not converge and are left out "
              f"({np.count_nonzero(bad & (cols['monotone'] == 0))} of them with Re G_eff < 0 on some mode):")
        for k in np.flatnonzero(bad):
            print(f"  h/lambda = {cols['thickness'][k]:g}, mu_c = {cols['friction'][k]:g}, V = {cols['speed'][k]:g}, "
                  f"seed {cols['seed'][k]}: residual {cols['residual'][k]:.1e}")
        cols = {k: v[~bad] for k, v in cols.items()}
    return cols


def time_scale() -> float:
    """tau/lambda of the sweep's material and period (from a result file's /input)."""
    first = sorted((DIRECTORY / "results").glob("*.h5"))[0]
    with h5py.File(first, "r") as f:
        return float(f["input"].attrs["tau"]) / float(f["input"].attrs["period"])


def curves(cols):
    """{(thickness, mu): (speeds, mean friction, std, dissipated power mean)}."""
    out = {}
    total = cols["friction"] + cols["delta_mu"]
    for h in np.unique(cols["thickness"]):
        for mu in np.unique(cols["friction"]):
            sel = (cols["thickness"] == h) & (cols["friction"] == mu)
            speeds = np.unique(cols["speed"][sel])
            rows = [sel & (cols["speed"] == v) for v in speeds]
            out[h, mu] = (speeds, np.array([total[r].mean() for r in rows]), np.array([total[r].std(ddof=1) for r in rows]),
                          np.array([cols["dissipated_power"][r].mean() for r in rows]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "friction_speed.png"))
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = curves(summary())
    scale = time_scale()
    thicknesses = sorted({h for h, _ in data})
    fig, axes = plt.subplots(1, len(thicknesses), figsize=(4 * len(thicknesses), 3.6), sharey=True,
                             constrained_layout=True)
    print("| h/lambda | mu_c | mu (V -> 0) | peak mu_c + Delta mu | at V tau/lambda | mu (V -> inf) |")
    print("|---|---|---|---|---|---|")
    for ax, h in zip(np.atleast_1d(axes), thicknesses):
        for (hh, mu), (v, m, s, _) in sorted(data.items()):
            if hh != h:
                continue
            moving = (v > 0) & (v < FAST)
            line = ax.errorbar(v[moving] * scale, m[moving], yerr=s[moving], capsize=2, lw=1, label=f"mu_c = {mu:g}")
            colour = line[0].get_color()
            ax.axhline(m[v == 0][0], color=colour, ls="--", lw=0.8)
            ax.axhline(m[v > FAST][0], color=colour, ls=":", lw=0.8)
            peak = np.argmax(np.where(moving, m, -np.inf))
            print(f"| {h:g} | {mu:g} | {m[v == 0][0]:.4f} | {m[peak]:.4f} | {v[peak] * scale:.3g} | {m[v > FAST][0]:.4f} |")
        ax.set_xscale("log")
        ax.set_xlabel("V tau / lambda")
        ax.set_title(f"h/lambda = {h:g}  (dashed: E0, dotted: E_inf)", fontsize=9)
    np.atleast_1d(axes)[0].set_ylabel("mu_c + Delta mu")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"figure: {args.out}")


if __name__ == "__main__":
    main()
