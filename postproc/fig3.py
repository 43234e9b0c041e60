"""The seed's Fig. 3 (interlocking friction of areal contacts) from the sweeps
inputs/sweeps/fig3.nml and fig3_thick.nml (reads only HDF5), and the tables of docs/fig3.md.

    .venv/bin/python -m layercontact sweep inputs/sweeps/fig3.nml        # h/lambda = 0.05
    .venv/bin/python -m layercontact sweep inputs/sweeps/fig3_thick.nml  # h/lambda = 0.16
    .venv/bin/python postproc/fig3.py [--out docs/fig3.png]

Delta mu is the seed's Eq. (11) (`delta_mu` of the results), g_bar the rms gradient
sqrt(<|grad r|^2>) of the surfaces, the pressure p_m/(E* h/lambda). Means and standard errors
(standard deviation / sqrt(realisations)) are over the profile realisations; a/a0 is the
contact fraction with friction over that of the frictionless scene (mu_c = 0) of the same
realisation and load. Paired differences (same realisations) are given with their own
standard errors.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SWEEPS = ROOT / "out" / "fig3"
NAMES = ("h005", "h016")  # directories of inputs/sweeps/fig3.nml and fig3_thick.nml
PRESSURE = "p_m / (E* h/lambda)"
FULL = 0.999  # a mean contact fraction at or above this counts as full contact


def summary(name: str) -> dict[str, np.ndarray]:
    """Columns of a sweep summary (HDF5), checked: converged, areal, one thickness."""
    path = SWEEPS / name
    files = sorted(path.glob("*_summary.h5"))
    if not files:
        raise SystemExit(f"{path}: no summary; run the sweep first (see the docstring)")
    with h5py.File(files[0], "r") as f:
        cols = {k: f["summary"][k][()] for k in f["summary"]}
    bad = np.count_nonzero(cols["converged"] != 1)
    if bad:
        raise SystemExit(f"{files[0]}: {bad} scenes did not converge")
    if np.unique(cols["normalised_thickness"]).size != 1:
        raise SystemExit(f"{files[0]}: expected one thickness per sweep")
    return cols


def surface_parameters(name: str) -> dict[str, object]:
    """Input values of the sweep's first result (all scenes share the surface parameters)."""
    first = sorted((SWEEPS / name / "results").glob("*.h5"))[0]
    with h5py.File(first, "r") as f:
        attrs = f["input"].attrs
        if attrs["geometry"] != b"areal":
            raise SystemExit(f"{first}: not an areal scene")
        return {k: attrs[k] for k in ("rms_gradient", "hurst", "short_wavelength", "n", "poisson", "tol")}


class Sweep:
    """One thickness: the per-realisation arrays y[mu][pressure index, seed index]."""

    def __init__(self, name: str):
        cols = summary(name)
        self.name = name
        self.params = surface_parameters(name)
        self.gbar = float(self.params["rms_gradient"])
        self.h = float(cols["normalised_thickness"][0])
        self.p = np.unique(cols["normalised_pressure"])
        self.seeds = np.unique(cols["seed"])
        self.mus = [m for m in np.unique(cols["friction"]) if m > 0]
        if 0.0 not in cols["friction"]:
            raise SystemExit(f"{name}: the frictionless reference (friction = 0) is missing")
        shape = (self.p.size, self.seeds.size)

        def table(mu: float, column: str) -> np.ndarray:
            out = np.full(shape, np.nan)
            sel = np.flatnonzero(cols["friction"] == mu)
            i = np.searchsorted(self.p, cols["normalised_pressure"][sel])
            j = np.searchsorted(self.seeds, cols["seed"][sel])
            out[i, j] = cols[column][sel]
            if np.isnan(out).any():
                raise SystemExit(f"{name}: mu_c = {mu:g}: missing scenes")
            return out

        self.a0 = table(0.0, "contact_fraction")
        self.dmu0 = table(0.0, "delta_mu")
        self.frac = {m: table(m, "contact_fraction") for m in self.mus}
        self.dmu = {m: table(m, "delta_mu") for m in self.mus}
        self.dmu_profile = {m: table(m, "delta_mu_profile") for m in self.mus}
        # Delta mu/(mu_c g_bar) per realisation
        self.y = {m: self.dmu[m] / (m * self.gbar) for m in self.mus}

    @property
    def n(self) -> int:
        return self.seeds.size


def mean_se(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard error over the realisations (last axis)."""
    return a.mean(axis=-1), a.std(axis=-1, ddof=1) / np.sqrt(a.shape[-1])


def fmt(m: float, s: float) -> str:
    return f"{m:.4f} +- {s:.4f}"


def draw(sweeps: list[Sweep], out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {0.2: "tab:blue", 0.5: "tab:orange", 1.0: "tab:red"}
    styles = {0: ("-", "o"), 1: ("--", "s")}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    for k, s in enumerate(sweeps):
        style = dict(ls=styles[k % 2][0], marker=styles[k % 2][1], ms=3, capsize=2, lw=1)
        for m in s.mus:
            label = f"h/lambda = {s.h:g}, mu_c = {m:g}"
            for ax, values in zip(axes, (s.y[m], s.dmu[m] / s.gbar, s.frac[m])):
                mean, se = mean_se(values)
                ax.errorbar(s.p, mean, yerr=se, color=colours.get(round(m, 3)), label=label, **style)
        mean, se = mean_se(s.a0)
        axes[2].errorbar(s.p, mean, yerr=se, color="k", label=f"h/lambda = {s.h:g}, mu_c = 0", **style)
    g = sweeps[0]
    titles = ("(a) Delta mu / (mu_c g_bar)", "(b) Delta mu / g_bar", "(c) contact fraction A/A_nominal")
    ylabels = ("Delta mu / (mu_c g_bar)", "Delta mu / g_bar", "contact fraction")
    for ax, title, ylabel in zip(axes, titles, ylabels):
        ax.set_xscale("log")
        ax.set_xlabel(PRESSURE)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=10)
    axes[2].set_yscale("log")
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=6, loc="lower right")
    fig.suptitle(
        f"Areal contact, incompressible layer, self-affine surface (H = {float(g.params['hurst']):g}, "
        f"g_bar = {g.gbar:g}, shortest wavelength lambda/{round(1 / float(g.params['short_wavelength']))}, "
        f"{int(g.params['n'])}^2 grid); means +- standard error over {g.n} realisations",
        fontsize=10)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"figure: {out}")


def print_table(s: Sweep) -> None:
    """Per pressure: a0 and, per mu_c, Delta mu/(mu_c g_bar) (mean +- SE) and the contact fraction."""
    print(f"\n### h/lambda = {s.h:g} ({s.n} realisations; means +- standard error)\n")
    head = "| p_m/(E* h/lambda) | contact fraction, mu_c = 0 |"
    rule = "|---:|---:|"
    for m in s.mus:
        head += f" mu_c = {m:g}: Delta mu/(mu_c g_bar) | contact fraction | a/a0 |"
        rule += "---:|---:|---:|"
    print(head)
    print(rule)
    a0, a0_se = mean_se(s.a0)
    for i, p in enumerate(s.p):
        row = f"| {p:.4g} | {fmt(a0[i], a0_se[i])} |"
        for m in s.mus:
            ym, ys = mean_se(s.y[m][i])
            fm, fs = mean_se(s.frac[m][i])
            rm, rs = mean_se(s.frac[m][i] / s.a0[i])
            row += f" {fmt(ym, ys)} | {fm:.4f} | {rm:.4f} +- {rs:.4f} |"
        print(row)


def print_peaks(sweeps: list[Sweep]) -> None:
    """The peak of each curve, the decrease after it, and where each realisation peaks."""
    print("\n### Peak and decrease (Delta mu/(mu_c g_bar); paired differences over the same realisations)\n")
    print("| h/lambda | mu_c | peak: p_m/(E* h/lambda) | peak value | Delta mu/mu_c at peak "
          "| contact fraction at peak "
          "| last partial contact: p | value there | peak - there (paired) | at the largest p | "
          "realisations whose own maximum is inside the range |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for s in sweeps:
        for m in s.mus:
            y = s.y[m]
            mean, se = mean_se(y)
            k = int(np.argmax(mean))
            frac = s.frac[m].mean(axis=1)
            partial = np.flatnonzero(frac < FULL)
            last = int(partial[-1])
            d, ds = mean_se(y[k] - y[last])
            own = np.argmax(y, axis=0)
            inside = np.count_nonzero((own > 0) & (own < s.p.size - 1))
            print(f"| {s.h:g} | {m:g} | {s.p[k]:.4g} | {fmt(mean[k], se[k])} | "
                  f"{mean[k] * s.gbar:.4f} +- {se[k] * s.gbar:.4f} | {frac[k]:.3f} | "
                  f"{s.p[last]:.4g} (fraction {frac[last]:.3f}) | {fmt(mean[last], se[last])} | "
                  f"{fmt(d, ds)} | {fmt(mean[-1], se[-1])} at {s.p[-1]:.4g} | {inside} of {s.n} |")


def print_ordering(sweeps: list[Sweep]) -> None:
    """Delta mu/mu_c for the smallest against the largest mu_c, paired, at every pressure."""
    print("\n### Delta mu/mu_c: smaller mu_c against larger (paired over the same realisations)\n")
    lo, hi = min(sweeps[0].mus), max(sweeps[0].mus)
    mid = [m for m in sweeps[0].mus if lo < m < hi]
    cols = [lo, *mid, hi]
    head = "| h/lambda | p_m/(E* h/lambda) | " + " | ".join(f"Delta mu/mu_c, mu_c = {m:g}" for m in cols)
    head += f" | mu_c = {lo:g} minus {hi:g} | ratio {lo:g}/{hi:g} |"
    print(head)
    print("|---:|---:|" + "---:|" * (len(cols) + 2))
    for s in sweeps:
        for i, p in enumerate(s.p):
            values = [mean_se(s.dmu[m][i] / m) for m in cols]
            d, ds = mean_se(s.dmu[lo][i] / lo - s.dmu[hi][i] / hi)
            ratio = (s.dmu[lo][i] / lo).mean() / (s.dmu[hi][i] / hi).mean()
            print(f"| {s.h:g} | {p:.4g} | " + " | ".join(f"{v:.5f} +- {e:.5f}" for v, e in values)
                  + f" | {d:.5f} +- {ds:.5f} | {ratio:.3f} |")


def print_checks(sweeps: list[Sweep]) -> None:
    """Frictionless references and the full-contact law Delta mu ~ 1/p_m."""
    print("\n### Checks\n")
    for s in sweeps:
        print(f"- h/lambda = {s.h:g}: largest |Delta mu| of the frictionless scenes "
              f"{np.abs(s.dmu0).max():.1e}")
        partial = [s.frac[m].mean(axis=1) < FULL for m in s.mus]
        cv = np.concatenate([(s.y[m].std(axis=1, ddof=1) / s.y[m].mean(axis=1))[sel]
                             for m, sel in zip(s.mus, partial)])
        se = cv / np.sqrt(s.n)
        print(f"- h/lambda = {s.h:g}: spread of one realisation's Delta mu (standard deviation / mean) "
              f"in partial contact {cv.min():.2f} .. {cv.max():.2f} (median {np.median(cv):.2f}); "
              f"standard error of the mean with {s.n} realisations "
              f"{se.min():.3f} .. {se.max():.3f} of the mean")
        rel = np.mean([np.abs(s.dmu_profile[m] / s.dmu[m] - 1).mean(axis=1) for m in s.mus], axis=0)
        print(f"- h/lambda = {s.h:g}: force balance -<p dr/dx>/p_m against Eq. (11) (discretisation "
              "indicator), mean relative difference at p = "
              + ", ".join(f"{p:.4g}: {r:.1e}" for p, r in zip(s.p, rel)))
        full = np.flatnonzero(np.all([s.frac[m].min(axis=1) == 1.0 for m in s.mus], axis=0))
        if full.size:
            for m in s.mus:
                prod = s.dmu[m][full].mean(axis=1) * s.p[full]
                print(f"- h/lambda = {s.h:g}, mu_c = {m:g}: full contact at p >= {s.p[full[0]]:.4g}; "
                      f"Delta mu * p_m/(E* h/lambda) there {prod.min():.5f} .. {prod.max():.5f} "
                      f"(spread over realisations {s.dmu[m][full].std(axis=1, ddof=1).max():.1e})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "fig3.png"))
    args = parser.parse_args()
    sweeps = [Sweep(name) for name in NAMES]
    draw(sweeps, args.out)
    for s in sweeps:
        print_table(s)
    print_peaks(sweeps)
    print_ordering(sweeps)
    print_checks(sweeps)


if __name__ == "__main__":
    main()
