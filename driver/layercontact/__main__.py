"""Command line: ``python -m layercontact run FILE.nml [--png PICTURE]``, or
``python -m layercontact sweep FILE.nml [--processes N] [--no-progress]``.

Runs the scene like the ``layercontact`` executable (same library routine, same HDF5
file, same summary and exit codes) and draws the seed's Fig. 2(a) view next to the
result file.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .api import LayercontactError, _check
from .native import core as _core


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m layercontact", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run_p = sub.add_parser("run", help="run a namelist scene, write HDF5 and a PNG")
    run_p.add_argument("nml", help="namelist input file")
    run_p.add_argument("--png", help="picture to draw (default: the result file with .png)")
    run_p.add_argument("--no-png", action="store_true", help="do not draw a picture")
    sweep_p = sub.add_parser(
        "sweep", help="run a parameter sweep (a scene plus &sweep); exit 1 if a scene failed, 2 bad input"
    )
    sweep_p.add_argument("nml", help="sweep namelist file")
    sweep_p.add_argument(
        "--processes", type=int, help="worker processes (default: &sweep processes, or all CPUs)"
    )
    sweep_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.command == "sweep":
        return sweep_command(args.nml, args.processes, not args.no_progress)

    out, converged, stat, errmsg = _core.py_run(args.nml, 1)
    try:
        _check(stat, errmsg)
    except LayercontactError as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return err.code
    h5 = Path(out.decode().strip() if isinstance(out, bytes) else str(out).strip())
    if not args.no_png:
        from .plot import plot_result

        png = Path(args.png) if args.png else h5.with_suffix(".png")
        plot_result(h5, png)
        print(f"  {'picture':<32}{png}")
    if not converged:
        print("layercontact: warning: the solver did not reach its tolerance", file=sys.stderr)
        return 3
    return 0


def sweep_command(nml: str, processes: int | None, progress: bool) -> int:
    """``python -m layercontact sweep``: run the sweep, print where the summary is and
    which scenes failed. Exit code 0 all converged, 1 some scene failed or did not
    converge (the others ran), 2 bad sweep (nothing ran)."""
    from .sweep import execute, failed, read_sweep

    try:
        plan = read_sweep(nml)
        rows = execute(plan, processes=processes, progress=progress)
    except (ValueError, LayercontactError, OSError) as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    bad = failed(rows)
    print(f"sweep '{plan.name}': {len(rows)} scenes, {len(bad)} failed")
    print(f"  {'summary':<32}{plan.summary_file('csv')}, {plan.summary_file('h5')}")
    for row in bad:
        print(f"layercontact: scene {row['scene_file']}: {row['error']}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
