"""Pictures of a result file (reads only HDF5)."""

from __future__ import annotations

import math
import os


def plot_result(h5file: str | os.PathLike, png: str | os.PathLike) -> None:
    """The seed's Fig. 2(a) view of a line contact: the rigid profile and the deformed
    layer surface (with the frictionless companion when the file has one), and the contact
    pressure; for an areal contact, the pressure and gap maps."""
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with h5py.File(h5file, "r") as f:
        geometry = f.attrs.get("geometry", b"line")
        if (geometry.decode() if isinstance(geometry, bytes) else str(geometry)) == "areal":
            _plot_areal(f, png, plt)
            return
        x = f["profile/x"][()]
        r = f["profile/height"][()]
        period = float(f["input"].attrs["period"])
        runs = [("friction", f["results"].attrs, f["fields"])]
        if "companion" in f:
            runs.append(("companion", f["companion/results"].attrs, f["companion/fields"]))
        runs = [(name, dict(a), {k: g[k][()] for k in g}) for name, a, g in runs]
        headline = _headline(f)

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6), constrained_layout=True)
    fig.suptitle(headline, fontsize=9)
    lam = r.max()
    # Heights point out of the layer, in the indenter's frame: the indenter is Lambda - r
    # (its highest asperity at 0), the deformed layer surface Delta - w (equal in contact).
    top.plot(x / period, lam - r, color="0.2", lw=0.9, label="rigid indenter  Lambda - r")
    for _, attrs, fields in runs:
        mu = attrs["friction"]
        surface = attrs["penetration"] - fields["displacement_z"]
        top.plot(x / period, surface, lw=0.9, label=f"layer surface  Delta - w,  mu_c = {mu:g}")
        bottom.plot(x / period, fields["pressure"], lw=0.9, label=f"mu_c = {mu:g}")
    top.set_ylabel("height (L)")
    top.legend(fontsize=8)
    bottom.set_ylabel("pressure p (S)")
    bottom.set_xlabel("x / lambda  (indenter slides along +x)")
    bottom.legend(fontsize=8)
    fig.savefig(png, dpi=120)
    plt.close(fig)


def _headline(f) -> str:
    """The scene's key parameters and results, for a picture's title: its title, h/lambda,
    nu, mu_c, the load (also in the seed's scale), contact fraction, Delta mu, convergence."""
    inp = dict(f["input"].attrs)
    res = dict(f["results"].attrs)

    def text(value) -> str:
        return value.decode() if isinstance(value, bytes) else str(value)

    thickness = float(inp["thickness"]) / float(inp["period"])
    layer = "half-space" if math.isinf(thickness) else f"h/lambda = {thickness:.3g}"
    load = f"p_m = {float(res['mean_pressure']):.3g}"
    normalised = float(res.get("normalised_pressure", float("nan")))
    if math.isfinite(normalised):
        load += f" ({normalised:.3g} in the seed's scale)"
    state = "converged" if int(res["converged"]) else f"NOT converged (residual {float(res['residual']):.2g})"
    first = text(inp.get("title", "")).strip()
    scene = f"{layer}, nu = {float(inp['poisson']):g}, mu_c = {float(res['friction']):g}, {load}"
    outcome = (f"contact fraction {float(res['contact_fraction']):.3f}, Delta mu = {float(res['delta_mu']):.3g}, "
               f"{state}")
    return "\n".join(line for line in (first, scene, outcome) if line)


def _plot_areal(f, png, plt) -> None:
    """Pressure and gap maps of an areal result (x, the sliding direction, to the right)."""
    import numpy as np

    inp = f["input"].attrs
    lx = float(inp["period"])
    # period_y is absent when not set (a negative number in files of earlier versions)
    ly = float(inp.get("period_y", lx))
    ly = ly if ly > 0 else lx
    p = f["fields/pressure"][()]
    g = f["fields/gap"][()]
    attrs = dict(f["results"].attrs)
    extent = (0.0, 1.0, 0.0, ly / lx)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.8), constrained_layout=True)
    fig.suptitle(_headline(f), fontsize=9)
    shown = left.imshow(p, origin="lower", extent=extent, cmap="magma")
    fig.colorbar(shown, ax=left, label="pressure p (S)")
    left.set_title(f"contact fraction {attrs['contact_fraction']:.3f},  mu_c = {attrs['friction']:g}")
    shown = right.imshow(np.where(p > 0, np.nan, g), origin="lower", extent=extent, cmap="viridis")
    fig.colorbar(shown, ax=right, label="gap g (L); contact blank")
    right.set_title(f"mean gap {attrs['mean_gap']:.3g},  Delta mu = {attrs['delta_mu']:.3g}")
    for ax in (left, right):
        ax.set_xlabel("x / lambda  (indenter slides along +x)")
        ax.set_ylabel("y / lambda")
    fig.savefig(png, dpi=120)
    plt.close(fig)
