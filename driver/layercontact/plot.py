"""Pictures of a result file (reads only HDF5)."""

from __future__ import annotations

import os

import numpy as np


def plot_result(h5file: str | os.PathLike, png: str | os.PathLike) -> None:
    """The seed's Fig. 2(a) view: the rigid profile and the deformed layer surface (with
    the frictionless companion when the file has one), and the contact pressure."""
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with h5py.File(h5file, "r") as f:
        x = f["profile/x"][()]
        r = f["profile/height"][()]
        period = float(f["input"].attrs["period"])
        runs = [("friction", f["results"].attrs, f["fields"])]
        if "companion" in f:
            runs.append(("companion", f["companion/results"].attrs, f["companion/fields"]))
        runs = [(name, dict(a), {k: g[k][()] for k in g}) for name, a, g in runs]

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6), constrained_layout=True)
    lam = r.max()
    top.plot(x / period, r - lam, color="0.3", lw=0.8, label="rigid profile r - Lambda")
    for name, attrs, fields in runs:
        mu = attrs["friction"]
        delta = attrs["penetration"]
        # surface of the layer in the indenter's frame: -(w) + Delta, so the indenter is r - Lambda
        surface = fields["displacement_z"] - delta
        top.plot(x / period, -surface - 0 * surface, lw=1.0, label=f"layer surface, mu_c = {mu:g}")
        bottom.plot(x / period, fields["pressure"], lw=1.0, label=f"mu_c = {mu:g}")
    top.set_ylabel("height (L)")
    top.legend(fontsize=8)
    bottom.set_ylabel("pressure p (S)")
    bottom.set_xlabel("x / lambda  (indenter slides along +x)")
    bottom.legend(fontsize=8)
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return None


__all__ = ["plot_result", "np"]
