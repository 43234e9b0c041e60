"""Pictures of results, drawn from what a result file (or a result object) holds and from a
sweep's summary: nothing is solved again."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

#: The summary columns a sweep's picture shows against the swept variable, where present.
SWEEP_OBSERVABLES = ("contact_fraction", "delta_mu", "mean_gap", "penetration", "a_over_a0")


def _pyplot():
    import matplotlib

    # (no display is needed: the figure is written to a file or returned)
    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "cairo") and not os.environ.get("DISPLAY"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def plot_result(result, output: str | os.PathLike | None = None):
    """Draw a solved contact: a line, the rigid profile and the deformed layer surface (with
    the frictionless companion's where there is one) above the contact pressure (the seed's
    Fig. 2(a) view); a surface, the pressure and gap maps and the profiles along ``x``
    (heights and pressure) on the row that carries the largest pressure.

    Parameters
    ----------
    result : str, os.PathLike, LineResult or ArealResult
        A result file (what the executable, :func:`layercontact.run` or a sweep wrote) or a
        result object (:func:`layercontact.solve_line`, :func:`layercontact.solve_areal`,
        :func:`layercontact.read_result`).
    output : str or os.PathLike, optional
        A picture to write (the format from its extension, e.g. ``.png``, ``.pdf``).

    Returns
    -------
    matplotlib.figure.Figure
        The figure (the arrays it plots are the result's, in its units, ``x`` divided by
        the period).
    """
    plt = _pyplot()
    if isinstance(result, (str, os.PathLike)):
        import h5py

        from .api import read_result

        with h5py.File(result, "r") as f:
            headline = _headline(f)
        result = read_result(result)
    else:
        headline = _result_headline(result)
    fig = _areal_figure(result, headline, plt) if result.pressure.ndim == 2 else _line_figure(result, headline, plt)
    if output is not None:
        fig.savefig(output, dpi=120)
    return fig


def _line_figure(result, headline: str, plt):
    runs = [result] + ([result.companion] if result.companion is not None else [])
    x = result.x / result.period
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6), constrained_layout=True)
    fig.suptitle(headline, fontsize=9)
    lam = result.height.max()
    # Heights point out of the layer, in the indenter's frame: the indenter is Lambda - r
    # (its highest asperity at 0), the deformed layer surface Delta - w (equal in contact).
    top.plot(x, lam - result.height, color="0.2", lw=0.9, label="rigid indenter  Lambda - r")
    for run in runs:
        top.plot(x, run.penetration - run.displacement_z, lw=0.9,
                 label=f"layer surface  Delta - w,  mu_c = {run.friction:g}")
        bottom.plot(x, run.pressure, lw=0.9, label=f"mu_c = {run.friction:g}")
    top.set_ylabel("height (L)")
    top.legend(fontsize=8)
    bottom.set_ylabel("pressure p (S)")
    bottom.set_xlabel("x / lambda  (indenter slides along +x)")
    bottom.legend(fontsize=8)
    return fig


def _areal_figure(result, headline: str, plt):
    lx, ly = result.period
    extent = (0.0, 1.0, 0.0, ly / lx)
    p, g = result.pressure, result.gap
    fig = plt.figure(figsize=(11, 8), constrained_layout=True)
    grid = fig.add_gridspec(2, 2, height_ratios=(1.4, 1.0))
    left, right = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    fig.suptitle(headline, fontsize=9)
    shown = left.imshow(p, origin="lower", extent=extent, cmap="magma")
    fig.colorbar(shown, ax=left, label="pressure p (S)")
    left.set_title(f"contact fraction {result.contact_fraction:.3f},  mu_c = {result.friction:g}")
    shown = right.imshow(np.where(p > 0, np.nan, g), origin="lower", extent=extent, cmap="viridis")
    fig.colorbar(shown, ax=right, label="gap g (L); contact blank")
    right.set_title(f"mean gap {result.mean_gap:.3g},  Delta mu = {result.delta_mu:.3g}")
    for ax in (left, right):
        ax.set_xlabel("x / lambda  (indenter slides along +x)")
        ax.set_ylabel("y / lambda")
    # the row through the largest pressure: the indenter and the layer surface over it, and
    # the pressure, as the line view shows them
    row = int(np.unravel_index(np.argmax(p), p.shape)[0])
    x = result.x / lx
    heights, pressure = fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
    lam = result.height.max()
    heights.plot(x, lam - result.height[row], color="0.2", lw=0.9, label="rigid indenter  Lambda - r")
    heights.plot(x, result.penetration - result.displacement_z[row], lw=0.9, label="layer surface  Delta - w")
    heights.set_ylabel("height (L)")
    heights.legend(fontsize=8)
    pressure.plot(x, p[row], lw=0.9, label=f"mu_c = {result.friction:g}")
    pressure.set_ylabel("pressure p (S)")
    pressure.legend(fontsize=8)
    for ax in (heights, pressure):
        ax.set_xlabel(f"x / lambda  on the row y / lambda = {row * ly / (p.shape[0] * lx):.4g}")
    return fig


def _headline(f) -> str:
    """The scene's key parameters and results, for a picture's title: its title, h/lambda,
    nu, mu_c, the load (also in the seed's scale), contact fraction, Delta mu, convergence."""
    inp = dict(f["input"].attrs)
    res = dict(f["results"].attrs)
    thickness = float(inp["thickness"]) / float(inp["period"])
    layer = "half-space" if math.isinf(thickness) else f"h/lambda = {thickness:.3g}"
    load = f"p_m = {float(res['mean_pressure']):.3g}"
    normalised = float(res.get("normalised_pressure", float("nan")))
    if math.isfinite(normalised):
        load += f" ({normalised:.3g} in the seed's scale)"
    state = "converged" if int(res["converged"]) else f"NOT converged (residual {float(res['residual']):.2g})"
    first = _text(inp.get("title", "")).strip()
    scene = f"{layer}, nu = {float(inp['poisson']):g}, mu_c = {float(res['friction']):g}, {load}"
    outcome = (f"contact fraction {float(res['contact_fraction']):.3f}, Delta mu = {float(res['delta_mu']):.3g}, "
               f"{state}")
    return "\n".join(line for line in (first, scene, outcome) if line)


def _result_headline(result) -> str:
    """The title of a result object's picture (it does not hold the layer: the results only)."""
    load = f"p_m = {result.mean_pressure:.3g}"
    if math.isfinite(result.normalised_pressure):
        load += f" ({result.normalised_pressure:.3g} in the seed's scale)"
    state = "converged" if result.converged else f"NOT converged (residual {result.residual:.2g})"
    return (f"mu_c = {result.friction:g}, {load}\ncontact fraction {result.contact_fraction:.3f}, "
            f"Delta mu = {result.delta_mu:.3g}, {state}")


# ---------------------------------------------------------------------------------------
# sweeps


def sweep_statistics(summary: dict[str, np.ndarray], parameters: list[str], observable: str):
    """The mean and standard error over realisations (the ``seed`` column) of one observable
    of a summary, per combination of the other swept variables; the scenes that failed or
    did not converge (a non-empty ``error``) are left out.

    Returns
    -------
    dict
        ``(values of the other swept variables) -> (mean, standard error, count)``; the
        standard error is ``std(ddof=1)/sqrt(count)`` (NaN for one realisation, or without
        a ``seed`` list).
    """
    keys = [name for name in parameters if name != "seed"]
    good = np.array([not str(e) for e in summary.get("error", np.full(len(summary[observable]), ""))])
    values = np.asarray(summary[observable], dtype=float)
    groups: dict[tuple, list[float]] = {}
    for i in np.flatnonzero(good & np.isfinite(values)):
        groups.setdefault(tuple(summary[k][i].item() for k in keys), []).append(values[i])
    out = {}
    for key, samples in groups.items():
        samples = np.asarray(samples)
        error = samples.std(ddof=1) / math.sqrt(samples.size) if samples.size > 1 else float("nan")
        out[key] = (float(samples.mean()), float(error), int(samples.size))
    return out


def plot_sweep(source: str | os.PathLike, output: str | os.PathLike | None = None):
    """Draw a sweep's summary: each observable (:data:`SWEEP_OBSERVABLES` that the summary
    holds) against the first swept variable, one curve per value of the other swept
    variables; with a ``seed`` (``realisations``) list, the mean over the realisations with
    its standard error as error bars. Read from ``NAME_summary.h5`` (or ``.csv``); nothing is
    solved.

    Parameters
    ----------
    source : str or os.PathLike
        The sweep directory (or its sweep file, or its summary file).
    output : str or os.PathLike, optional
        A picture to write.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .sweeps.sweep import read_summary

    summary_file, parameters, name = _summary_of(Path(source))
    summary = read_summary(summary_file)
    observables = [o for o in SWEEP_OBSERVABLES if o in summary and summary[o].dtype.kind in "fiu"
                   and np.any(np.isfinite(np.asarray(summary[o], dtype=float)))]
    if not observables:
        raise ValueError(f"{summary_file}: holds none of {', '.join(SWEEP_OBSERVABLES)}; nothing to draw")
    swept = [p for p in parameters if p != "seed"]
    axis = swept[0] if swept else None
    plt = _pyplot()
    fig, axes = plt.subplots(len(observables), 1, sharex=True, figsize=(7, 2.4 * len(observables) + 0.8),
                             constrained_layout=True, squeeze=False)
    seeds = "seed" in parameters
    fig.suptitle(f"sweep '{name}'" + (" (mean and standard error over the realisations)" if seeds else ""),
                 fontsize=9)
    for ax, observable in zip(axes[:, 0], observables):
        stats = sweep_statistics(summary, parameters, observable)
        if axis is None:  # only realisations: one point per seed
            keep = [not str(e) for e in summary.get("error", [""] * len(summary[observable]))]
            ax.plot(np.asarray(summary["seed"])[keep], np.asarray(summary[observable], float)[keep], "o")
            ax.set_xlabel("seed")
        else:
            curves: dict[tuple, list[tuple]] = {}
            for key, (mean, error, _) in stats.items():
                curves.setdefault(key[1:], []).append((key[0], mean, error))
            for rest, points in sorted(curves.items()):
                points.sort()
                label = ", ".join(f"{k} = {v:g}" for k, v in zip(swept[1:], rest)) or None
                x, mean, error = (np.array(column) for column in zip(*points))
                if seeds:
                    ax.errorbar(x, mean, yerr=error, marker="o", ms=3, capsize=3, lw=0.9, label=label)
                else:
                    ax.plot(x, mean, marker="o", ms=3, lw=0.9, label=label)
            if any(rest for rest in curves):
                ax.legend(fontsize=7)
            ax.set_xlabel(axis)
        ax.set_ylabel(observable)
    if output is not None:
        fig.savefig(output, dpi=120)
    return fig


def _summary_of(source: Path) -> tuple[Path, list[str], str]:
    """The summary file, the swept variables (in the product's order) and the name of a
    sweep given by its directory, sweep file or summary file."""
    import json

    from .sweeps.status import find_sweep
    from .sweeps.sweep import plan_record_file

    if source.is_file() and source.suffix.lower() in (".h5", ".hdf5", ".csv"):
        record = sorted(source.parent.glob("*_sweep.json"))
        if len(record) != 1:
            raise ValueError(f"{source}: no sweep record (NAME_sweep.json) next to it: the swept variables "
                             "are not known")
        plan = json.loads(record[0].read_text(encoding="utf-8"))
        return source, list(plan["parameters"]), plan["name"]
    sweep = find_sweep(source)
    parameters = list(json.loads(plan_record_file(sweep.directory, sweep.name).read_text(encoding="utf-8"))
                      ["parameters"])
    for suffix in (".h5", ".csv"):
        summary = Path(sweep.directory) / f"{sweep.name}_summary{suffix}"
        if summary.is_file():
            return summary, parameters, sweep.name
    raise ValueError(f"{sweep.directory}: no summary ({sweep.name}_summary.h5): run python -m layercontact "
                     f"collect {sweep.directory}")
