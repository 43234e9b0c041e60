"""Pictures of a result file (reads only HDF5)."""

from __future__ import annotations

import os


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
