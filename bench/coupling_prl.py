"""Two kinds of elastic coupling: compressibility and confinement (after Müller, Müser,
Carbone and Menga, "Significance of Elastic Coupling for Stresses and Leakage in Frictional
Contacts", Phys. Rev. Lett. 131, 156201, 2023).

Random isotropic self-affine surfaces (``lc.self_affine_surface``: n = 256, H = 0.8, rms
gradient 0.1, roll-off at the period, shortest wavelength 8 grid points; period 1) slide
along +x with the local Coulomb friction mu_c = 0.5 (``lc.solve_areal``, E = 1, load
control, tol 1e-10, stresses and the frictionless companion) on three bodies:

- ``uncoupled``:    incompressible half-space, nu = 0.5 (c = 0: friction does not act on
                    the normal problem);
- ``compressible``: half-space, nu = --poisson (default 0.3; c = (1-2nu)/(2(1-nu)) > 0);
- ``confined``:     incompressible layer bonded to a rigid base, h/lambda = --thickness
                    (default 0.05; c ~ -(|q|h)^2 < 0).

Loads: for each body and each target contact fraction (--targets, default 0.10 and 0.30)
the mean pressure p_m is found once, before the measurement, by a secant search in
log p - log a on frictionless solves of separate calibration surfaces (seeds 1000-1002), so
that the frictionless contact fraction is the target; the same p_m then serves all
realisations (seeds 0 .. --realisations-1) of that body. The frictional contact fraction
differs from the target by the coupling (a/a0 in the table).

Measured per realisation, reported as mean +- standard error over the realisations:

- ``dmu``: the interlocking friction Delta mu (total friction mu_c + Delta mu);
- ``a/A0``: the frictional contact fraction; ``a/a0``: its ratio to the companion's;
- ``sxx/pm``: the largest tension sigma_xx of the surface stress map over p_m;
- ``s1/pm``: the largest in-plane principal stress over p_m (tension positive); also in
  units of E* g (g = 0.1 the rms gradient), which does not depend on the load;
- ``f(s1>pm)``: the fraction of the nominal area where the largest principal stress
  exceeds p_m (the high-tension domain), and the same for the frictionless companion
  (``mu=0``); ``f(s1>E* g/2)`` the same with the load-independent threshold E* g/2;
- ``<g>/hrms``: the mean gap over the rms height of the surface, and its ratio to the
  companion's (``g/g0``);
- ``kx/k0x``, ``ky/k0y``: the Reynolds conductance of the gap along x (sliding) and y
  (``lc.reynolds_leakage``, contact = cells with positive pressure) over the frictionless
  companion's of the same body and load.

A second table gives the paired differences (same surfaces) of the coupled bodies against
the uncoupled one at the same target contact fraction. --figure writes maps of the largest
principal stress of one realisation (the three bodies at the larger target, contact
outlined) and bar charts of the means.

    .venv/bin/python bench/coupling_prl.py [--realisations 20] [--targets 0.1 0.3]
        [--poisson 0.3] [--thickness 0.05] [--workers 2] [--figure docs/coupling.png]

The default run (20 realisations, 120 coupled solves with 4 leakage solves each) takes
about 1-2 minutes on 2 cores.
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
CAL_SEEDS = (1000, 1001, 1002)
RMS_GRADIENT = 0.1


def surface(seed: int) -> np.ndarray:
    return lc.self_affine_surface(
        n=N, hurst=0.8, seed=seed, short_wavelength=8 / N, rms_gradient=RMS_GRADIENT
    )


def bodies(poisson: float, thickness: float) -> dict[str, tuple[float, float]]:
    return {
        "uncoupled": (np.inf, 0.5),
        "compressible": (np.inf, poisson),
        "confined": (thickness, 0.5),
    }


def calibrate(h: float, nu: float, target: float) -> float:
    """Mean pressure at which the frictionless contact fraction of the calibration
    surfaces averages ``target`` (secant in log-log, relative tolerance 1e-3)."""
    surfs = [surface(s) for s in CAL_SEEDS]

    def frac(p):
        return np.mean(
            [lc.solve_areal(s, stress=False,
                            thickness=h, poisson=nu, mean_pressure=p, tol=1e-8).contact_fraction
             for s in surfs]
        )

    p0, a0 = 0.01, frac(0.01)
    p1 = p0 * target / a0
    a1 = frac(p1)
    for _ in range(12):
        if abs(a1 / target - 1) < 1e-3:
            break
        slope = (np.log(a1) - np.log(a0)) / (np.log(p1) - np.log(p0)) if p1 != p0 else 1.0
        slope = slope if slope > 0.1 else 1.0
        p2 = p1 * np.exp((np.log(target) - np.log(a1)) / slope)
        p0, a0, p1 = p1, a1, p2
        a1 = frac(p1)
    return p1


def principal(res) -> np.ndarray:
    sxx, syy, sxy = res.stress_xx, res.stress_yy, res.stress_xy
    return 0.5 * (sxx + syy) + np.sqrt((0.5 * (sxx - syy)) ** 2 + sxy**2)


def measure(args):
    body, target, h, nu, p, seed = args
    s = surface(seed)
    hrms = np.std(s)
    res = lc.solve_areal(s, thickness=h, poisson=nu, friction=MU_C, mean_pressure=p,
                         tol=TOL, stress=True, companion=True)
    comp = res.companion
    s1 = principal(res)
    s1c = principal(comp) if getattr(comp, "stress_xx", None) is not None else None
    k = {}
    for name, r in (("f", res), ("c", comp)):
        for d in ("x", "y"):
            k[name + d] = lc.reynolds_leakage(r.gap, period=1.0, direction=d,
                                              contact=r.pressure > 0).k_eff
    pm = res.mean_pressure
    return dict(
        body=body, target=target, seed=seed, converged=bool(res.converged and comp.converged),
        dmu=res.delta_mu, a=res.contact_fraction, a_ratio=res.a_over_a0,
        a0=comp.contact_fraction,
        sxx=res.max_tension / pm, s1=res.max_principal_stress / pm,
        s1_check=s1.max() / pm,
        s1E=res.max_principal_stress * (1 - nu**2) / RMS_GRADIENT,
        f_ht=np.mean(s1 > pm),
        f_htE=np.mean(s1 > 0.5 * RMS_GRADIENT / (1 - nu**2)), f_ht0=(np.mean(s1c > pm) if s1c is not None else np.nan),
        s1_0=(s1c.max() / pm if s1c is not None else np.nan),
        gap=res.mean_gap / hrms, gap_ratio=res.mean_gap / comp.mean_gap,
        kx=k["fx"] / k["cx"] if k["cx"] > 0 else np.nan,
        ky=k["fy"] / k["cy"] if k["cy"] > 0 else np.nan,
        k0x=k["cx"], k0y=k["cy"],
    )


COLS = [
    ("dmu", "Delta mu", "{:+.4f}", 4),
    ("a", "a/A0", "{:.4f}", 4),
    ("a_ratio", "a/a0", "{:.4f}", 4),
    ("sxx", "max sxx/pm", "{:.3f}", 3),
    ("s1", "max s1/pm", "{:.3f}", 3),
    ("s1E", "max s1/(E* g)", "{:.3f}", 3),
    ("s1_0", "max s1/pm (mu=0)", "{:.3f}", 3),
    ("f_ht", "f(s1>pm)", "{:.4f}", 4),
    ("f_ht0", "f(s1>pm) (mu=0)", "{:.4f}", 4),
    ("f_htE", "f(s1>E* g/2)", "{:.4f}", 4),
    ("gap", "<g>/hrms", "{:.4f}", 4),
    ("gap_ratio", "<g>/<g0>", "{:.4f}", 4),
    ("kx", "kx/k0x", "{:.4f}", 4),
    ("ky", "ky/k0y", "{:.4f}", 4),
]


def pm_se(values, digits):
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return "n/a"
    se = v.std(ddof=1) / np.sqrt(v.size) if v.size > 1 else np.nan
    return f"{v.mean():.{digits}f} ± {se:.{digits}f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--realisations", type=int, default=20)
    ap.add_argument("--targets", type=float, nargs="+", default=[0.10, 0.30])
    ap.add_argument("--poisson", type=float, default=0.3)
    ap.add_argument("--thickness", type=float, default=0.05)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--figure", default=None)
    a = ap.parse_args()
    t0 = time.time()
    bd = bodies(a.poisson, a.thickness)

    cal_jobs = [(b, t, h, nu) for b, (h, nu) in bd.items() for t in a.targets]
    with ProcessPoolExecutor(a.workers) as ex:
        ps = list(ex.map(calibrate, *zip(*[(h, nu, t) for _, t, h, nu in cal_jobs])))
    loads = {(b, t): p for (b, t, _, _), p in zip(cal_jobs, ps)}
    print(f"mu_c = {MU_C}, n = {N}, H = 0.8, rms gradient 0.1, shortest wavelength 8/{N}, "
          f"{a.realisations} realisations, tol {TOL:g}")
    print("bodies: " + "; ".join(f"{b}: h/lambda = {h:g}, nu = {nu:g}" for b, (h, nu) in bd.items()))
    print("loads (E = 1; frictionless contact fraction of the calibration surfaces = target):")
    for (b, t), p in loads.items():
        h, nu = bd[b]
        print(f"  {b:13s} target {t:.2f}: p_m = {p:.5g}  (p_m/E* = {p * (1 - nu**2):.5g})")

    jobs = [(b, t, *bd[b], loads[(b, t)], s) for t in a.targets for b in bd for s in range(a.realisations)]
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(measure, jobs, chunksize=2))
    nconv = sum(r["converged"] for r in rows)
    dev = max(abs(r["s1"] - r["s1_check"]) / abs(r["s1"]) for r in rows)

    print(f"\nTable 1: means ± standard errors over {a.realisations} realisations "
          f"(converged {nconv}/{len(rows)}; max s1 from the maps vs result: rel. dev. {dev:.1e})\n")
    for t in a.targets:
        print(f"target contact fraction {t:.2f}\n")
        print("| quantity | " + " | ".join(bd) + " |")
        print("|---|" + "---|" * len(bd))
        print("| total friction mu_c + Delta mu | " + " | ".join(
            pm_se([MU_C + r["dmu"] for r in rows if r["body"] == b and r["target"] == t], 4) for b in bd) + " |")
        for key, label, _, dg in COLS:
            print(f"| {label} | " + " | ".join(
                pm_se([r[key] for r in rows if r["body"] == b and r["target"] == t], dg) for b in bd) + " |")
        print()

    print("Table 2: paired differences against the uncoupled half-space (same surfaces, same "
          "target), mean ± standard error\n")
    keys = [("sxx", "max sxx/pm", 3), ("s1", "max s1/pm", 3), ("f_ht", "f(s1>pm)", 4), ("f_htE", "f(s1>E* g/2)", 4),
            ("gap", "<g>/hrms", 4), ("kx", "kx/k0x", 4), ("ky", "ky/k0y", 4)]
    print("| target | body | " + " | ".join(f"Δ {l}" for _, l, _ in keys) + " |")
    print("|---|---|" + "---|" * len(keys))
    for t in a.targets:
        ref = {r["seed"]: r for r in rows if r["body"] == "uncoupled" and r["target"] == t}
        for b in list(bd)[1:]:
            cells = []
            for key, _, dg in keys:
                d = [r[key] - ref[r["seed"]][key] for r in rows if r["body"] == b and r["target"] == t]
                cells.append(pm_se(d, dg))
            print(f"| {t:.2f} | {b} | " + " | ".join(cells) + " |")
    print(f"\nwall time {time.time() - t0:.0f} s")

    if a.figure:
        figure(a.figure, bd, loads, a.targets, rows)


def figure(path, bd, loads, targets, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = max(targets)
    fig = plt.figure(figsize=(13, 8.2))
    gs = fig.add_gridspec(2, 4, height_ratios=[1.15, 1])
    s = surface(0)
    vmax = 3.0
    for i, (b, (h, nu)) in enumerate(bd.items()):
        p = loads[(b, t)]
        res = lc.solve_areal(s, thickness=h, poisson=nu, friction=MU_C, mean_pressure=p,
                             tol=TOL, stress=True)
        s1 = principal(res) / p
        ax = fig.add_subplot(gs[0, i])
        im = ax.imshow(s1, origin="lower", extent=(0, 1, 0, 1), cmap="RdBu_r", vmin=-vmax, vmax=vmax)
        ax.contour(np.linspace(0, 1, N, endpoint=False), np.linspace(0, 1, N, endpoint=False),
                   (res.pressure > 0).astype(float), levels=[0.5], colors="k", linewidths=0.4)
        ax.contour(np.linspace(0, 1, N, endpoint=False), np.linspace(0, 1, N, endpoint=False),
                   s1, levels=[1.0], colors="gold", linewidths=0.5)
        hs = "half-space" if np.isinf(h) else f"h/λ = {h:g}"
        ax.set_title(f"{b}: {hs}, ν = {nu:g}\nΔμ = {res.delta_mu:+.4f}, max σ1/p_m = {s1.max():.2f}",
                     fontsize=9)
        ax.set_xlabel("x/λ (sliding →)")
        if i == 0:
            ax.set_ylabel("y/λ")
    cax = fig.add_subplot(gs[0, 3])
    cax.set_axis_off()
    fig.colorbar(im, ax=cax, fraction=0.5, label="largest principal stress σ1/p_m (tension > 0)")
    cax.text(0.0, 0.05, f"seed 0, target a/A0 = {t:.2f}\nblack: contact outline\ngold: σ1 = p_m",
             transform=cax.transAxes, fontsize=9)

    panels = [("dmu", "Δμ"), ("s1", "max σ1 / p_m"), ("f_ht", "area fraction σ1 > p_m"),
              ("kx", "k_eff / k_eff(μ_c = 0)")]
    colors = {"uncoupled": "0.5", "compressible": "tab:blue", "confined": "tab:red"}
    for j, (key, label) in enumerate(panels):
        ax = fig.add_subplot(gs[1, j])
        width = 0.8 / len(bd)
        for i, b in enumerate(bd):
            for k, tt in enumerate(targets):
                keys = [key] if key != "kx" else ["kx", "ky"]
                for m, kk in enumerate(keys):
                    v = np.array([r[kk] for r in rows if r["body"] == b and r["target"] == tt], float)
                    v = v[np.isfinite(v)]
                    x = k * (len(keys) + 0.3) + m + (i - 1) * width if key == "kx" else k + (i - 1) * width
                    ax.bar(x, v.mean(), width, yerr=v.std(ddof=1) / np.sqrt(v.size), color=colors[b],
                           hatch="//" if m == 1 else None, edgecolor="k", linewidth=0.3,
                           label=b if (k == 0 and m == 0) else None)
        if key == "kx":
            ax.set_xticks([k * 2.3 + m for k in range(len(targets)) for m in range(2)])
            ax.set_xticklabels([f"{d}, {tt:.2f}" for tt in targets for d in ("x", "y")], fontsize=8)
            ax.axhline(1, color="k", lw=0.5)
            ax.set_ylim(bottom=0)
        else:
            ax.set_xticks(range(len(targets)))
            ax.set_xticklabels([f"a/A0 ≈ {tt:.2f}" for tt in targets])
        ax.axhline(0, color="k", lw=0.5)
        ax.set_title(label, fontsize=10)
        if j == 0:
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    print(f"figure: {path}")


if __name__ == "__main__":
    main()
