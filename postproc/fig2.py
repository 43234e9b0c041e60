"""The seed's Fig. 2 from the sweeps in inputs/sweeps/ (reads only HDF5), and the table of
numbers quoted in docs/figures.md.

    .venv/bin/python -m layercontact sweep inputs/sweeps/fig2a.nml   # and fig2b, fig2c, fig2d
    .venv/bin/python postproc/fig2.py [--out docs/fig2.png]

a/a0 is the contact length with friction over the frictionless one for the same profile
realisation and load; means and their standard errors (the spread over the profile
realisations / sqrt(realisations); the figure's bars) are over the realisations.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SWEEPS = ROOT / "out" / "fig2"


def summary(name: str) -> dict[str, np.ndarray]:
    """Columns of a sweep summary (HDF5)."""
    path = SWEEPS / name
    files = sorted(path.glob("*_summary.h5"))
    if not files:
        raise SystemExit(f"{path}: no summary; run the sweep first (see the docstring)")
    with h5py.File(files[0], "r") as f:
        cols = {k: f["summary"][k][()] for k in f["summary"]}
    if np.any(cols["converged"] != 1):
        raise SystemExit(f"{files[0]}: {np.count_nonzero(cols['converged'] != 1)} scenes did not converge")
    return cols


def rms_gradient(name: str) -> float:
    """g_bar of the sweep's profiles (all realisations are scaled to the same value)."""
    first = sorted((SWEEPS / name / "results").glob("*.h5"))[0]
    with h5py.File(first, "r") as f:
        return float(f["input"].attrs["rms_gradient"])


def ratio_to_frictionless(cols, quantity: str, keys: tuple[str, ...]):
    """For every scene with friction > 0: quantity / quantity of the frictionless scene with
    the same values of `keys` (pressure, thickness, seed)."""
    reference = {}
    for i in np.flatnonzero(cols["friction"] == 0):
        reference[tuple(cols[k][i] for k in keys)] = cols[quantity][i]
    out = np.full(cols[quantity].shape, np.nan)
    for i in np.flatnonzero(cols["friction"] > 0):
        out[i] = cols[quantity][i] / reference[tuple(cols[k][i] for k in keys)]
    return out


def mean_spread(x, y, groups):
    """Mean and standard deviation of y over the realisations at each x, for each group."""
    table = {}
    for g in np.unique(groups):
        sel = groups == g
        xs = np.unique(x[sel])
        ys = [y[sel & (x == v)] for v in xs]
        table[g] = (xs, np.array([v.mean() for v in ys]), np.array([v.std(ddof=1) for v in ys]),
                    np.array([v.size for v in ys]))
    return table


def panel_a(ax):
    files = sorted((SWEEPS / "a" / "results").glob("*.h5"))
    if not files:
        raise SystemExit("out/fig2/a: no results; run inputs/sweeps/fig2a.nml first")
    for k, path in enumerate(files):
        with h5py.File(path, "r") as f:
            x = f["profile/x"][()]
            r = f["profile/height"][()]
            mu = float(f["results"].attrs["friction"])
            surface = float(f["results"].attrs["penetration"]) - f["fields/displacement_z"][()]
        if k == 0:
            ax.plot(x, r.max() - r, color="0.2", lw=0.8, label="rigid profile")
        ax.plot(x, surface, lw=0.8, label=f"mu_c = {mu:g}")
    ax.set_xlim(0.25, 0.55)
    ax.set_ylim(-0.001, 0.012)
    ax.set_xlabel("x / lambda (indenter slides along +x)")
    ax.set_ylabel("height (L), lambda = 1")
    ax.set_title("(a) h/lambda = 0.16, p_m/(E* Lambda/lambda) = 3", fontsize=9)
    ax.legend(fontsize=7)


def draw(ax, stats, label, xlabel, ylabel, title, unity=True):
    """Mean +- standard error curves (one per group) on a log x axis."""
    for group, (x, m, s, n) in stats.items():
        ax.errorbar(x, m, yerr=s / np.sqrt(n), capsize=2, lw=1, label=label.format(group))
    if unity:
        ax.axhline(1, color="0.5", lw=0.5)
    ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    return stats


PRESSURE = "p_m / (E* Lambda/lambda)"


def panel_b(ax, cols):
    a = ratio_to_frictionless(cols, "contact_fraction", ("normalised_pressure", "seed"))
    fr = cols["friction"] > 0
    stats = mean_spread(cols["normalised_pressure"][fr], a[fr], cols["friction"][fr])
    return draw(ax, stats, "mu_c = {:g}", PRESSURE, "a / a0", "(b) h/lambda = 0.16")


def panel_c(ax, cols, gbar):
    fr = cols["friction"] > 0
    y = cols["delta_mu"][fr] / (cols["friction"][fr] * gbar)
    stats = mean_spread(cols["normalised_pressure"][fr], y, cols["friction"][fr])
    return draw(ax, stats, "mu_c = {:g}", PRESSURE, "Delta mu / (mu_c g_bar)", "(c) h/lambda = 0.01", unity=False)


def panel_d(ax, cols):
    a = ratio_to_frictionless(cols, "contact_fraction", ("normalised_pressure", "thickness", "seed"))
    fr = cols["friction"] > 0
    stats = mean_spread(cols["thickness"][fr], a[fr], cols["normalised_pressure"][fr])
    return draw(ax, stats, "p_m/(E* Lambda/lambda) = {:g}", "h / lambda", "a / a0", "(d) mu_c = 0.5")


def print_table(b, c, d, robustness) -> None:
    """The table of docs/figures.md: a/a0 extremes, thick-layer limit, Delta mu trends, robustness."""
    print("| quantity | value (mean +- standard error over realisations) |")
    print("|---|---|")
    for mu in (min(b), max(b)):
        x, m, s, n = b[mu]
        i = np.argmax(m)
        j = np.argmin(m)
        print(f"| h/lambda = 0.16, mu_c = {mu:g}: largest mean a/a0 | {m[i]:.4f} +- {s[i] / np.sqrt(n[i]):.4f} "
              f"at p_m/(E* Lambda/lambda) = {x[i]:.3g}; smallest {m[j]:.4f} +- {s[j] / np.sqrt(n[j]):.4f} at {x[j]:.3g} |")
    for p, (x, m, s, n) in d.items():
        thick = x >= 0.5
        thin = np.argmax(m)
        print(f"| mu_c = 0.5, p_m/(E* Lambda/lambda) = {p:g}: a/a0 for h/lambda >= 0.5 | "
              f"{m[thick].min():.4f} to {m[thick].max():.4f}; largest {m[thin]:.3f} at h/lambda = {x[thin]:.3g} |")
    for mu, (x, m, s, n) in c.items():
        print(f"| h/lambda = 0.01, mu_c = {mu:g}: Delta mu/(mu_c g_bar) at p = {x[0]:.3g}, {x[len(x) // 2]:.3g}, "
              f"{x[-1]:.3g} | {m[0]:.4f}, {m[len(x) // 2]:.4f}, {m[-1]:.4f} (+- {s.max() / np.sqrt(n.min()):.4f}) |")
    for name, (label, stats) in robustness.items():
        pressures = ", ".join(f"{v:g}" for v in stats[max(stats)][0])
        line = ", ".join(f"mu_c {mu:g}: " + " ".join(f"{v:.3f}" for v in stats[mu][1]) for mu in sorted(stats))
        print(f"| robustness {name}: {label} at p = {pressures} | {line} |")


def robustness_table() -> dict:
    """The profile-parameter variants of panels (b) and (c) that have been run."""
    out = {}
    for name in ("b_hurst05", "b_short256"):
        if (SWEEPS / name).exists():
            cols = summary(name)
            a = ratio_to_frictionless(cols, "contact_fraction", ("normalised_pressure", "seed"))
            fr = cols["friction"] > 0
            out[name] = ("a/a0", mean_spread(cols["normalised_pressure"][fr], a[fr], cols["friction"][fr]))
    if (SWEEPS / "c_hurst05").exists():
        cols = summary("c_hurst05")
        fr = cols["friction"] > 0
        y = cols["delta_mu"][fr] / (cols["friction"][fr] * rms_gradient("c_hurst05"))
        out["c_hurst05"] = ("Delta mu/(mu_c g_bar)", mean_spread(cols["normalised_pressure"][fr], y, cols["friction"][fr]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "fig2.png"))
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8), constrained_layout=True)
    fig.suptitle("means over profile realisations; bars: standard errors of the means", fontsize=9)
    panel_a(axes[0, 0])
    b = panel_b(axes[0, 1], summary("b"))
    c = panel_c(axes[1, 0], summary("c"), rms_gradient("c"))
    d = panel_d(axes[1, 1], summary("d"))
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"figure: {args.out}")

    print_table(b, c, d, robustness_table())


if __name__ == "__main__":
    main()
