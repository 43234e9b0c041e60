"""Leak rate against load, with and without friction, on a thin incompressible layer
(after Menga, Carbone, Müller and Müser, "How does friction affect sliding contact
mechanics?").

Random isotropic self-affine surfaces (``lc.self_affine_surface``: n = 256, H = 0.8, rms
gradient 0.1, roll-off at the period, shortest wavelength 8 grid points; period lambda = 1;
seeds 0 .. --realisations-1) slide along +x with the local Coulomb friction mu_c = 0.5 on an
incompressible layer (nu = 0.5, E = 1, E* = 4/3) bonded to a rigid base, h/lambda = 0.05 and
0.16 (--thicknesses). Load control, tol 1e-10; every solve also gives its frictionless
companion (``companion=True``: the same surface at the same mean pressure with mu_c = 0).
The loads are log-spaced in the seed's areal scale P = p_m/(E* h/lambda) (--loads: from,
to, count; default 0.01 .. 5, 22 values), from a few per cent of contact to beyond the
percolation threshold (contact fraction ~0.4), where the leak rate vanishes.

Measured per surface and load: the contact fraction with (a) and without (a0) friction, and
the Reynolds conductance k_eff of the gap (``lc.reynolds_leakage``, contact = cells with
positive pressure) along x (sliding direction) and y, with friction (k) and for the
frictionless companion (k0), normalised by the cube of the surface's rms height. Printed:
means +- standard errors over the realisations (zeros, i.e. non-percolating gaps, included)
and the ratio k/k0 paired per surface, averaged over the surfaces whose frictionless gap
still percolates in that direction (their number in brackets). --figure draws k_eff/hrms^3
against P (log-log; x and y, mu_c = 0 and 0.5, standard-error bars) and the paired ratio.

    .venv/bin/python bench/leakage_load.py [--realisations 10] [--thicknesses 0.05 0.16]
        [--loads 0.01 5 22] [--workers 2] [--figure docs/leakage_load.png]

The default run (2 x 10 x 22 coupled solves with 4 leakage solves each) takes about
4 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import layercontact as lc

MU_C = 0.5
N = 256
TOL = 1e-10
E_STAR = 4.0 / 3.0  # E = 1, nu = 0.5
KEYS = ("a", "a0", "kx", "k0x", "ky", "k0y")


def surface(seed: int) -> np.ndarray:
    return lc.self_affine_surface(n=N, hurst=0.8, seed=seed, short_wavelength=8 / N, rms_gradient=0.1)


def run_surface(args: tuple[float, int, np.ndarray]) -> dict[str, np.ndarray]:
    """All loads of one (thickness, seed) pair."""
    h, seed, loads = args
    s = surface(seed)
    hrms3 = float(np.sqrt(np.mean((s - s.mean()) ** 2))) ** 3
    out = {k: np.zeros(len(loads)) for k in KEYS}
    converged = True
    for i, P in enumerate(loads):
        res = lc.solve_areal(s, stress=False,
                             thickness=h, poisson=0.5, friction=MU_C, mean_pressure=P * E_STAR * h,
                             companion=True, tol=TOL)
        c = res.companion
        converged &= bool(res.converged) and bool(c.converged)
        out["a"][i] = res.contact_fraction
        out["a0"][i] = c.contact_fraction
        for d in "xy":
            out["k" + d][i] = lc.reynolds_leakage(res.gap, period=1.0, direction=d,
                                                  contact=res.pressure > 0).k_eff / hrms3
            out["k0" + d][i] = lc.reynolds_leakage(c.gap, period=1.0, direction=d,
                                                   contact=c.pressure > 0).k_eff / hrms3
    out["converged"] = converged
    return out


def mse(v: np.ndarray) -> tuple[float, float]:
    v = np.asarray(v, float)
    if v.size == 0:
        return float("nan"), float("nan")
    return float(v.mean()), float(v.std(ddof=1) / np.sqrt(v.size)) if v.size > 1 else float("nan")


def ratio(k: np.ndarray, k0: np.ndarray) -> tuple[float, float, int]:
    """Paired k/k0 over the surfaces (rows) whose frictionless gap percolates."""
    ok = k0 > 0
    m, e = mse(k[ok] / k0[ok])
    return m, e, int(ok.sum())


def fmt(m: float, e: float, digits: int = 4) -> str:
    if np.isnan(m):
        return "–"
    return f"{m:.{digits}f} ± {e:.{digits}f}"


def fmte(m: float, e: float) -> str:
    if np.isnan(m):
        return "–"
    if m == 0:
        return "0"
    return f"{m:.3g} ± {e:.2g}"


def table(h: float, loads: np.ndarray, d: dict[str, np.ndarray]) -> str:
    lines = [f"h/lambda = {h}: k in units of hrms^3; k/k0 paired per surface [surfaces with k0 > 0]", "",
             "| P | a (mu_c=0.5) | a0 (mu_c=0) | kx | k0x | ky | k0y | kx/k0x | ky/k0y |",
             "|---|---|---|---|---|---|---|---|---|"]
    for i, P in enumerate(loads):
        row = [f"{P:.3g}", fmt(*mse(d["a"][:, i])), fmt(*mse(d["a0"][:, i]))]
        for k in ("kx", "k0x", "ky", "k0y"):
            row.append(fmte(*mse(d[k][:, i])))
        for k, k0 in (("kx", "k0x"), ("ky", "k0y")):
            m, e, n = ratio(d[k][:, i], d[k0][:, i])
            row.append("–" if n == 0 else f"{fmt(m, e, 3)} [{n}]")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def figure(path: str, loads: np.ndarray, data: dict[float, dict[str, np.ndarray]]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hs = list(data)
    fig, axes = plt.subplots(2, len(hs), figsize=(5.2 * len(hs), 7.5), squeeze=False, sharex="col",
                             gridspec_kw={"height_ratios": [1.6, 1]})
    style = {"kx": ("C0", "-", "o", "x, mu_c = 0.5"), "k0x": ("C0", "--", "s", "x, mu_c = 0"),
             "ky": ("C3", "-", "o", "y, mu_c = 0.5"), "k0y": ("C3", "--", "s", "y, mu_c = 0")}
    for j, h in enumerate(hs):
        d = data[h]
        ax = axes[0, j]
        for k, (col, ls, mk, lab) in style.items():
            m = d[k].mean(axis=0)
            e = d[k].std(axis=0, ddof=1) / np.sqrt(d[k].shape[0])
            ok = m > 0
            lo = np.minimum(e[ok], 0.999 * m[ok])  # keep the lower bar on the log axis
            ax.errorbar(loads[ok], m[ok], yerr=[lo, e[ok]], color=col, ls=ls, marker=mk, ms=4,
                        mfc="none" if ls == "--" else col, capsize=2, label=lab)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylabel("k_eff / hrms^3")
        ax.set_title(f"h/lambda = {h}, n = {N}, {d['kx'].shape[0]} surfaces")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        ax = axes[1, j]
        for k, k0, col in (("kx", "k0x", "C0"), ("ky", "k0y", "C3")):
            r = np.array([ratio(d[k][:, i], d[k0][:, i]) for i in range(len(loads))])
            ok = r[:, 2] > 0
            ax.errorbar(loads[ok], r[ok, 0], yerr=np.nan_to_num(r[ok, 1]), color=col, marker="o", ms=4,
                        capsize=2, label=f"k/k0 along {k[-1]}")
        ax.axhline(1, color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("P = p_m / (E* h/lambda)")
        ax.set_ylabel("k(mu_c = 0.5) / k(0), paired")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        # contact fraction on the right axis of the ratio panel
        ax2 = ax.twinx()
        ax2.plot(loads, d["a"].mean(axis=0), color="0.4", lw=1, label="a (mu_c = 0.5)")
        ax2.plot(loads, d["a0"].mean(axis=0), color="0.4", lw=1, ls="--", label="a0 (mu_c = 0)")
        ax2.set_ylabel("contact fraction (grey)")
        ax2.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--realisations", type=int, default=10)
    ap.add_argument("--thicknesses", type=float, nargs="+", default=[0.05, 0.16])
    ap.add_argument("--loads", type=float, nargs=3, default=[0.01, 5.0, 22])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--figure")
    a = ap.parse_args()
    loads = np.geomspace(a.loads[0], a.loads[1], int(a.loads[2]))
    t0 = time.time()
    jobs = [(h, seed, loads) for h in a.thicknesses for seed in range(a.realisations)]
    with ProcessPoolExecutor(a.workers) as ex:
        results = list(ex.map(run_surface, jobs))
    data: dict[float, dict[str, np.ndarray]] = {}
    nconv = 0
    for (h, _, _), r in zip(jobs, results):
        nconv += r["converged"]
        data.setdefault(h, {k: [] for k in KEYS})
        for k in KEYS:
            data[h][k].append(r[k])
    for h in data:
        data[h] = {k: np.array(v) for k, v in data[h].items()}
    print(f"mu_c = {MU_C}, n = {N}, H = 0.8, rms gradient 0.1, shortest wavelength 8/{N}, nu = 0.5, "
          f"{a.realisations} realisations, tol {TOL:g}, P = p_m/(E* h/lambda), E* = 4/3")
    print(f"converged: {nconv}/{len(jobs)} surfaces (all loads, both solves); {time.time() - t0:.0f} s")
    for h in data:
        print()
        print(table(h, loads, data[h]))
    if a.figure:
        figure(a.figure, loads, data)


if __name__ == "__main__":
    main()
