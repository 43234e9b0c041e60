"""The seed's Fig. 3 at h/lambda = 0.05 by GFMD beside the default solver: the sweeps
inputs/sweeps/fig3_gfmd.nml (method 'gfmd') and fig3_gfmd_default.nml (the default method),
the same 560 scenes (256^2, realisations 1-10, tol 1e-8), read from their HDF5 summaries;
docs/fig3_gfmd.png and the table of docs/fig3.md, "Fig. 3 by GFMD".

    .venv/bin/python -m layercontact sweep inputs/sweeps/fig3_gfmd.nml
    .venv/bin/python -m layercontact sweep inputs/sweeps/fig3_gfmd_default.nml
    .venv/bin/python postproc/fig3_gfmd.py [--out docs/fig3_gfmd.png]

Both methods solve each scene to the same complementarity residual, so they agree scene by
scene to what that residual allows; the table gives, per pressure, the largest difference
of Delta mu over the scenes with friction (relative), of the contact fraction (in grid
nodes), and GFMD's cost against the default solver's (the medians over the pressure's 40
scenes of the ratio of solve times and of transform pairs; the solves ran in the same
sweep order on the same shared machine, so the time ratio carries its load).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import h5py
import numpy as np

import fig3

ROOT = Path(__file__).resolve().parents[1]
# (the two sweeps' directories are out/fig3_gfmd and out/fig3_gfmd_default)
fig3.SWEEPS = ROOT / "out"
NAMES = {"gfmd": "fig3_gfmd", "default": "fig3_gfmd_default"}


def columns(name: str) -> dict[str, np.ndarray]:
    """The summary's columns sorted by (friction, pressure, seed), so two sweeps line up."""
    cols = fig3.summary(name)
    order = np.lexsort((cols["seed"], cols["normalised_pressure"], cols["friction"]))
    return {k: v[order] for k, v in cols.items()}


def solvers(cols: dict[str, np.ndarray]) -> set[str]:
    return {s.decode() if isinstance(s, bytes) else str(s) for s in cols["solver"]}


def compare(dyn: dict[str, np.ndarray], ref: dict[str, np.ndarray], n: int) -> list[tuple]:
    """Per pressure: contact fraction (mean, mu_c = 0), the largest |Delta Delta mu|/|Delta mu|
    over the scenes with friction, the largest contact difference in nodes, the medians of the
    time and pair ratios, and the largest GFMD steps."""
    for key in ("friction", "normalised_pressure", "seed"):
        if not np.array_equal(dyn[key], ref[key]):
            raise SystemExit(f"the two sweeps hold different scenes ({key})")
    rows = []
    for p in np.unique(ref["normalised_pressure"]):
        at = ref["normalised_pressure"] == p
        rubbing = at & (ref["friction"] > 0)
        ddmu = np.abs(dyn["delta_mu"][rubbing] - ref["delta_mu"][rubbing]) / np.abs(ref["delta_mu"][rubbing])
        nodes = np.abs(dyn["contact_fraction"][at] - ref["contact_fraction"][at]) * n * n
        rows.append((p, ref["contact_fraction"][at & (ref["friction"] == 0)].mean(), ddmu.max(), nodes.max(),
                     np.median(dyn["wall_time"][at] / ref["wall_time"][at]),
                     np.median(dyn["fft_pairs"][at] / ref["fft_pairs"][at]), dyn["iterations"][at].max()))
    return rows


def draw(dyn: fig3.Sweep, ref: fig3.Sweep, out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {0.2: "tab:blue", 0.5: "tab:orange", 1.0: "tab:red"}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    for m in ref.mus:
        colour = colours.get(round(m, 3))
        for ax, r, d in zip(axes, (ref.y[m], ref.dmu[m] / ref.gbar, ref.frac[m]),
                            (dyn.y[m], dyn.dmu[m] / dyn.gbar, dyn.frac[m])):
            mean, se = fig3.mean_se(r)
            ax.errorbar(ref.p, mean, yerr=se, color=colour, ls="-", lw=1, capsize=2,
                        label=f"mu_c = {m:g}, default solver")
            ax.plot(dyn.p, fig3.mean_se(d)[0], ls="none", marker="o", mfc="none", ms=7, color=colour,
                    label=f"mu_c = {m:g}, GFMD")
    axes[2].errorbar(ref.p, *fig3.mean_se(ref.a0), color="k", ls="-", lw=1, capsize=2,
                     label="mu_c = 0, default solver")
    axes[2].plot(dyn.p, fig3.mean_se(dyn.a0)[0], ls="none", marker="o", mfc="none", ms=7, color="k",
                 label="mu_c = 0, GFMD")
    titles = ("(a) Delta mu / (mu_c g_bar)", "(b) Delta mu / g_bar", "(c) contact fraction A/A_nominal")
    for ax, title in zip(axes, titles):
        ax.set_xscale("log")
        ax.set_xlabel(fig3.PRESSURE)
        ax.set_ylabel(title[4:])
        ax.set_title(title, fontsize=10)
    axes[2].set_yscale("log")
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=6, loc="lower right")
    fig.suptitle(
        f"Fig. 3 by GFMD (circles) and the default solver (lines, +- standard error), h/lambda = {ref.h:g}, "
        f"{int(ref.params['n'])}^2 grid, tol {float(ref.params['tol']):g}; means over {ref.n} realisations",
        fontsize=10)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"figure: {out}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "fig3_gfmd.png"))
    args = parser.parse_args()
    dyn_cols, ref_cols = columns(NAMES["gfmd"]), columns(NAMES["default"])
    if solvers(dyn_cols) != {"gfmd"}:
        raise SystemExit(f"{NAMES['gfmd']}: scenes not solved by GFMD alone: {sorted(solvers(dyn_cols))}")
    dyn, ref = fig3.Sweep(NAMES["gfmd"]), fig3.Sweep(NAMES["default"])
    n = int(ref.params["n"])
    print(f"h/lambda = {ref.h:g}, {n}^2, tol {float(ref.params['tol']):g}, {ref.n} realisations, "
          f"{dyn_cols['seed'].size} scenes each, all converged\n")
    print("| p_m/(E* h/lambda) | contact fraction (mu_c = 0) | largest \\|Delta mu difference\\|/Delta mu "
          "(mu_c > 0) | largest contact difference (nodes) | GFMD/default time (median) | "
          "GFMD/default pairs (median) | GFMD steps (largest) |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    rows = compare(dyn_cols, ref_cols, n)
    for p, a0, ddmu, nodes, t, pairs, steps in rows:
        print(f"| {p:g} | {a0:.4f} | {ddmu:.1e} | {nodes:.0f} | {t:.1f} | {pairs:.1f} | {steps:d} |")
    worst_mean = max(np.max(np.abs(dyn.y[m].mean(axis=1) - ref.y[m].mean(axis=1)) / ref.y[m].mean(axis=1))
                     for m in ref.mus)
    print(f"\nlargest relative difference of the means Delta mu/(mu_c g_bar): {worst_mean:.1e}")
    print(f"time ratio over all scenes: median {np.median(dyn_cols['wall_time'] / ref_cols['wall_time']):.1f}, "
          f"total {dyn_cols['wall_time'].sum() / ref_cols['wall_time'].sum():.1f} "
          f"({dyn_cols['wall_time'].sum():.0f} s against {ref_cols['wall_time'].sum():.0f} s)")
    draw(dyn, ref, args.out)


if __name__ == "__main__":
    main()
