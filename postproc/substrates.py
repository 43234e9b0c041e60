"""A coating on substrates from rigid to as soft as the coating, bonded and slipping: the
interlocking friction Delta mu, a/a0 and the largest surface tension against the load
(docs/figures.md, "Coatings on compliant substrates").

    .venv/bin/python postproc/substrates.py [--n 128] [--seeds 3] [--out docs/substrates.png]

The coating: an incompressible layer, h/lambda = 0.05, E = 1, Coulomb friction mu_c = 0.5,
sliding along +x; the substrate an elastic half-space of Young's modulus E_s (nu_s = 0.3),
or rigid; the interface bonded or slipping (frictionless). The surfaces are seeded
self-affine ones (H = 0.8, rms gradient 0.1, shortest wavelength lambda/32); each point is
the mean over the realisations, with its standard error. The load is p_m/(E* h/lambda), the
seed's areal scale with the coating's E* and h. a/a0 compares each scene's contact area with
that of its frictionless companion at the same load. Prints the table of docs/figures.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import layercontact as lc

ROOT = Path(__file__).resolve().parents[1]
THICKNESS, FRICTION = 0.05, 0.5
SUBSTRATES = (None, 100.0, 10.0, 3.0, 1.0)   # E_s/E; None: rigid
INTERFACES = ("bonded", "slip")
LOADS = (0.02, 0.05, 0.1, 0.2, 0.4)
OBSERVABLES = (("delta_mu", "Delta mu"), ("a_over_a0", "a/a0"), ("max_tension", "largest sigma_xx / p_m"))


def label(substrate) -> str:
    return "rigid" if substrate is None else f"E_s/E = {substrate:g}"


def solve_all(n: int, seeds: int) -> dict:
    """values[substrate, interface][observable] -> (loads, seeds) array."""
    surfaces = [lc.self_affine_surface(n, seed=seed + 1, rms_gradient=0.1, short_wavelength=1/32)
                for seed in range(seeds)]
    values = {}
    for substrate in SUBSTRATES:
        for interface in INTERFACES:
            table = {name: np.empty((len(LOADS), seeds)) for name, _ in OBSERVABLES}
            for i, load in enumerate(LOADS):
                for k, heights in enumerate(surfaces):
                    res = lc.solve_areal(heights, thickness=THICKNESS, poisson=0.5, friction=FRICTION,
                                         normalised_pressure=load, substrate_young=substrate, substrate_poisson=(
                                             None if substrate is None else 0.3), interface=interface,
                                         companion=True, tol=1e-8)
                    if not (res.converged and res.companion.converged):
                        raise SystemExit(f"{label(substrate)}, {interface}, load {load}, seed {k + 1}: not converged")
                    table["delta_mu"][i, k] = res.delta_mu
                    table["a_over_a0"][i, k] = res.a_over_a0
                    table["max_tension"][i, k] = res.max_tension/res.mean_pressure
            values[substrate, interface] = table
            print(f"{label(substrate)}, {interface}: done", flush=True)
    return values


def mean_error(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    k = a.shape[1]
    return a.mean(axis=1), (a.std(axis=1, ddof=1)/np.sqrt(k) if k > 1 else np.zeros(a.shape[0]))


def draw(values: dict, out: Path) -> None:
    import matplotlib
    import matplotlib.ticker
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), constrained_layout=True)
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(SUBSTRATES)))
    for (name, title), ax in zip(OBSERVABLES, axes):
        for substrate, colour in zip(SUBSTRATES, colours):
            for interface, style in zip(INTERFACES, ("-", "--")):
                m, e = mean_error(values[substrate, interface][name])
                ax.errorbar(LOADS, m, yerr=e, color=colour, linestyle=style, marker="o", ms=3, capsize=2,
                            label=f"{label(substrate)}, {interface}")
        ax.set_xscale("log")
        ax.set_xticks(LOADS, [f"{load:g}" for load in LOADS])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("p_m / (E* h/lambda)")
        ax.set_title(title)
    axes[0].legend(fontsize=7, ncol=1)
    fig.suptitle(f"coating h/lambda = {THICKNESS}, nu = 0.5, mu_c = {FRICTION} on substrates (nu_s = 0.3)")
    fig.savefig(out, dpi=120)


def table(values: dict) -> str:
    rows = ["| substrate | interface | p_m/(E* h/lambda) | Delta mu | a/a0 | largest sigma_xx / p_m |",
            "|---|---|---|---|---|---|"]
    for substrate in SUBSTRATES:
        for interface in INTERFACES:
            for i, load in enumerate(LOADS):
                cells = []
                for name, _ in OBSERVABLES:
                    m, e = mean_error(values[substrate, interface][name])
                    cells.append(f"{m[i]:.4f} ± {e[i]:.4f}")
                rows.append(f"| {label(substrate)} | {interface} | {load:g} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=128, help="grid points per side (default 128)")
    parser.add_argument("--seeds", type=int, default=3, help="surface realisations (default 3)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "substrates.png")
    args = parser.parse_args()
    values = solve_all(args.n, args.seeds)
    draw(values, args.out)
    print(table(values))


if __name__ == "__main__":
    main()
