"""Command line of layercontact.

    python -m layercontact run FILE.nml [--png PICTURE | --no-png]
    python -m layercontact sweep FILE.nml [--processes N] [--ranks-per-scene K] [--no-progress] [--dry-run]
    python -m layercontact sweep FILE.nml --slurm [--ranks-per-scene K] [--dry-run] [Slurm options]
    python -m layercontact status DIR [--all]
    python -m layercontact collect DIR
    python -m layercontact convert INPUT OUTPUT.h5 [--unit UNIT] [--channel N]
    python -m layercontact plot RESULT.h5|SWEEP_DIR [-o PICTURE]
    python -m layercontact defaults [line|areal]

``run`` runs a scene like the ``layercontact`` executable (same library routine, same
HDF5 file, same summary and exit codes) and draws the seed's Fig. 2(a) view next to the
result file. ``sweep`` runs a parameter sweep here in worker processes, or with ``--slurm``
submits it as a Slurm job array (layercontact.sweeps.submit). ``status`` and ``collect`` read a
sweep directory (or a sweep file): where each scene stands, and the summary. ``convert``
reads an instrument topography file (with the optional SurfaceTopography package) and
writes the HDF5 height file that ``&profile kind = 'file'`` reads, printing the &scene and
&profile lines that run it. ``plot`` draws a result file (maps and profiles) or a sweep's
summary (observables against the swept variables, mean and standard error over the
realisations) without solving anything. ``defaults`` prints the default scene as a complete namelist,
as ``layercontact --defaults`` does.

Exit codes:
    run       0 converged, 2 bad input, 3 not converged, 4 I/O failure, 5 internal failure
    sweep     0 every scene converged, 1 some scene failed (the others ran), 2 bad sweep or
              option (nothing ran)
    --slurm   0 submitted, or nothing left to submit (also for --dry-run), 2 bad sweep or
              option (nothing submitted), 4 Slurm's commands missing or the job refused
    status    0 every scene done, 1 some scene failed, running, queued or missing, 2 not a
              sweep (directory)
    collect   0 every scene converged, 1 some did not or are not done (the summary is
              written all the same), 2 not a sweep (directory)
    convert   0 written, 2 the input cannot be read as a topography, 4 SurfaceTopography
              missing or the output not writable
    plot      0 written, 2 not a result file or a sweep with a summary, 4 the picture not
              writable
    Ctrl-C    130 (a local sweep ends the scenes in flight; the same command resumes it)
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import sys
from pathlib import Path

from ._library import LayercontactError, _check
from .native import core as _core

_BAD_SWEEP = (ValueError, LayercontactError, OSError)


def _parser() -> argparse.ArgumentParser:
    from .sweeps.slurm import OPTIONS

    parser = argparse.ArgumentParser(
        prog="python -m layercontact",
        description="layercontact: run scenes and sweeps",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Exit codes:" + __doc__.split("Exit codes:")[1],
    )
    from . import BUILD, __version__

    # the executable's `layercontact --version`, with the core this interpreter runs
    parser.add_argument("--version", action="version", version=f"layercontact {__version__} ({BUILD})")
    sub = parser.add_subparsers(dest="command", required=True)
    run_p = sub.add_parser("run", help="run a namelist scene, write HDF5 and a PNG")
    run_p.add_argument("nml", help="namelist input file")
    run_p.add_argument("--png", help="picture to draw (default: the result file with .png)")
    run_p.add_argument("--no-png", action="store_true", help="do not draw a picture")

    sweep_p = sub.add_parser(
        "sweep", help="run a parameter sweep (a scene plus &sweep) here, or submit it to Slurm with --slurm"
    )
    sweep_p.add_argument("nml", help="sweep namelist file")
    sweep_p.add_argument(
        "--processes", type=int, help="worker processes (default: &sweep processes, or the CPUs allocated)"
    )
    sweep_p.add_argument(
        "--ranks-per-scene",
        type=int,
        default=1,
        metavar="K",
        help="MPI ranks of each (areal) scene: here under mpirun -n K, with --slurm srun in tasks of "
        "--ntasks=K (default 1)",
    )
    sweep_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    sweep_p.add_argument(
        "--max-scenes",
        type=int,
        help="the most scenes allowed (default: &sweep max_scenes, or 20000); a larger sweep is refused",
    )
    sweep_p.add_argument(
        "--dry-run",
        action="store_true",
        help="write and check the scenes (with --slurm also the job script, printed); run nothing",
    )
    sweep_p.add_argument(
        "--slurm",
        action="store_true",
        help="submit the scenes that are missing or failed as a Slurm job array",
    )
    group = sweep_p.add_argument_group(
        "Slurm options", "with --slurm; each overrides the &sweep variable slurm_NAME"
    )
    for attribute, option in OPTIONS.items():
        repeatable = attribute in ("sbatch_lines", "setup_lines")
        group.add_argument(
            option.flag,
            dest=attribute,
            action="append" if repeatable else "store",
            metavar="LINE" if repeatable else option.flag.lstrip("-").upper().replace("-", "_"),
            help=option.help,
        )

    status_p = sub.add_parser(
        "status", help="where each scene of a sweep stands: done, failed, running, queued, missing"
    )
    status_p.add_argument("directory", help="the sweep directory (or the sweep file)")
    status_p.add_argument(
        "--all", action="store_true", help="list every scene that is not done (default: 20 per state)"
    )
    collect_p = sub.add_parser(
        "collect", help="write the summary (CSV and HDF5) of a sweep from its directory"
    )
    collect_p.add_argument("directory", help="the sweep directory (or the sweep file)")
    convert_p = sub.add_parser(
        "convert",
        help="write an instrument topography file as the HDF5 height file &profile kind = 'file' reads",
    )
    convert_p.add_argument("input", help="topography file (a format SurfaceTopography reads)")
    convert_p.add_argument("output", help="HDF5 file to write (/profile/height)")
    convert_p.add_argument("--unit", help="length unit of heights and sizes, e.g. um (default: the file's)")
    convert_p.add_argument("--channel", type=int, help="data channel (default: the file's default)")
    plot_p = sub.add_parser(
        "plot", help="draw a result file or a sweep's summary (nothing is solved again)"
    )
    plot_p.add_argument("target", help="a result file (.h5), or a sweep directory (or its sweep file)")
    plot_p.add_argument("-o", "--output", help="picture to write (default: RESULT.png, or DIR/NAME_summary.png)")
    defaults_p = sub.add_parser("defaults", help="print the default scene as a complete namelist")
    defaults_p.add_argument("geometry", nargs="?", default="line", choices=("line", "areal"))
    return parser


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.command == "sweep":
        if args.slurm:
            return slurm_command(args)
        given = _slurm_values(args)
        if given:
            from .sweeps.slurm import OPTIONS

            flag = OPTIONS[next(iter(given))].flag
            print(f"layercontact: error: {flag} applies only with --slurm", file=sys.stderr)
            return 2
        return sweep_command(args.nml, args.processes, not args.no_progress, args.dry_run, args.max_scenes,
                             args.ranks_per_scene)
    if args.command == "status":
        return status_command(args.directory, args.all)
    if args.command == "collect":
        return collect_command(args.directory)
    if args.command == "convert":
        return convert_command(args.input, args.output, args.unit, args.channel)
    if args.command == "plot":
        return plot_command(args.target, args.output)
    if args.command == "defaults":
        from .api import default_scene

        print(default_scene(args.geometry), end="")
        return 0
    return run_command(args)


def _launched_rank() -> int:
    """This process's rank in an MPI job (0 without a launcher): what the launchers set,
    as the library's start of MPI reads them (src/base/launcher.c)."""
    import os

    for name in ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"):
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    if os.environ.get("SLURM_STEP_ID") is not None and os.environ.get("SLURM_PROCID", "").isdigit():
        return int(os.environ["SLURM_PROCID"])
    return 0


def run_command(args: argparse.Namespace) -> int:
    """``python -m layercontact run``: exit codes as the executable's. Under ``mpirun -n P``
    the ranks share the surface (docs/clusters.md, "One surface on several ranks"): rank 0
    writes the result file, prints the summary and the messages, and draws the picture."""
    root = _launched_rank() == 0
    out, converged, stat, errmsg = _core.py_run(args.nml, 1, -1)
    try:
        _check(stat, errmsg)
    except LayercontactError as err:
        if root:
            print(f"layercontact: error: {err}", file=sys.stderr)
        return err.code
    h5 = Path(out.decode().strip() if isinstance(out, bytes) else str(out).strip())
    if not root:
        return 0 if converged else 3
    if not args.no_png:
        import h5py

        import matplotlib.pyplot as plt

        from .plot import plot_result

        with h5py.File(h5, "r") as f:
            has_maps = "fields" in f
        if has_maps:
            png = Path(args.png) if args.png else h5.with_suffix(".png")
            plt.close(plot_result(h5, png))
            print(f"  {'picture':<32}{png}")
        else:
            print(f"  {'picture':<32}none (&output fields = .false.: the result has no maps)")
    if not converged:
        print("layercontact: warning: the solver did not reach its tolerance", file=sys.stderr)
        return 3
    return 0


def sweep_command(nml: str, processes: int | None, progress: bool, dry_run: bool = False,
                  max_scenes: int | None = None, ranks_per_scene: int = 1) -> int:
    """``python -m layercontact sweep``: run the sweep, print where the summary is and
    which scenes failed. Exit code 0 all converged, 1 some scene failed or did not
    converge (the others ran), 2 bad sweep (nothing ran)."""
    from .sweeps.sweep import execute, failed, read_sweep

    try:
        plan = read_sweep(nml, max_scenes)
        rows = execute(plan, processes=processes, progress=progress, dry_run=dry_run,
                       ranks_per_scene=ranks_per_scene)
    except _BAD_SWEEP as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # the scenes finished so far keep their results; the scene files say what is left
        print("\nlayercontact: sweep interrupted; run the same command again to resume (finished scenes "
              "are kept and skipped)", file=sys.stderr)
        return 130
    if dry_run:
        print(
            f"sweep '{plan.name}': {len(rows)} scenes written to {plan.directory / 'scenes'} and checked; "
            "nothing run (dry run)"
        )
        return 0
    bad = failed(rows)
    print(f"sweep '{plan.name}': {len(rows)} scenes, {len(bad)} failed")
    print(f"  {'summary':<32}{plan.summary_file('csv')}, {plan.summary_file('h5')}")
    for row in bad:
        print(f"layercontact: scene {row['scene_file']}: {row['error']}", file=sys.stderr)
    return 1 if bad else 0


def _slurm_values(args: argparse.Namespace) -> dict[str, object]:
    """The Slurm options given on the command line, by attribute (numbers converted; a
    value that is not one is left for the option's check to name)."""
    from .sweeps.slurm import INTEGER_OPTIONS, OPTIONS

    values = {}
    for attribute in OPTIONS:
        value = getattr(args, attribute, None)
        if value is None:
            continue
        if attribute in INTEGER_OPTIONS:
            value = int(value) if value.strip().lstrip("+-").isdigit() else value
        values[attribute] = value
    return values


def slurm_command(args: argparse.Namespace) -> int:
    """``python -m layercontact sweep FILE --slurm``: submit (or with --dry-run show) the
    job array of the scenes that are missing or failed; record the job id."""
    from .sweeps.slurm import SlurmError, resolve_options
    from .sweeps.submit import submit_sweep
    from .sweeps.sweep import check_ranks_per_scene, read_sweep

    if args.processes is not None:
        print(
            "layercontact: error: --processes applies to a local sweep; a Slurm sweep runs one scene at a "
            "time per array task (--scenes-per-task, --array-limit)",
            file=sys.stderr,
        )
        return 2
    try:
        plan = read_sweep(args.nml, args.max_scenes)
        options = resolve_options(plan.slurm, _slurm_values(args))
        options = replace(options, ranks_per_scene=check_ranks_per_scene(plan, args.ranks_per_scene))
        outcome = submit_sweep(plan, options, dry_run=args.dry_run)
    except _BAD_SWEEP as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    except SlurmError as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 4
    states = list(outcome.states.values())
    counts = ", ".join(
        f"{sum(s.state == name for s in states)} {name}"
        for name in ("done", "failed", "running", "queued", "missing")
    )
    print(f"sweep '{plan.name}' ({plan.directory}): {len(states)} scenes: {counts}")
    if not outcome.scenes:
        print(
            "nothing to submit: every scene is done, queued or running (or failed to converge, which a rerun "
            "would repeat)"
        )
        print(f"  follow it: python -m layercontact status {plan.directory}")
        return 0
    per = options.scenes_per_task
    if args.dry_run:
        print(outcome.script_text, end="")
        print(
            f"dry run: {len(outcome.scenes)} scenes in {outcome.tasks} array task(s) ({per} per task); "
            f"job script {outcome.script}; nothing submitted"
        )
        return 0
    first = outcome.states[outcome.scenes[0]]
    again = (
        ""
        if first.state == "missing" and first.reason == "never run"
        else f" (e.g. {first.stem}: {first.reason})"
    )
    print(
        f"submitted Slurm job {outcome.submission.job_id}: {len(outcome.scenes)} scenes{again} in "
        f"{outcome.tasks} array task(s), {per} per task; job script {outcome.script}"
    )
    print(f"  follow it: python -m layercontact status {plan.directory}")
    print(f"  then:      python -m layercontact collect {plan.directory}")
    return 0


def status_command(directory: str, list_all: bool = False) -> int:
    """``python -m layercontact status DIR``: 0 every scene done, 1 not (yet), 2 no sweep."""
    from .sweeps.status import report, sweep_status

    try:
        status = sweep_status(directory)
    except _BAD_SWEEP as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    report(status, limit=None if list_all else 20)
    return 0 if status.finished else 1


def collect_command(directory: str) -> int:
    """``python -m layercontact collect DIR``: write the summary; 0 every scene converged,
    1 not, 2 no sweep."""
    from .sweeps.status import DONE, collect

    try:
        status, rows = collect(directory)
    except _BAD_SWEEP as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    sweep = status.sweep
    bad = [row for row in rows if row.get("error")]
    print(f"sweep '{sweep.name}': {status.counts_line()}")
    print(
        f"  {'summary':<32}{sweep.directory / (sweep.name + '_summary.csv')}, "
        f"{sweep.directory / (sweep.name + '_summary.h5')}"
    )
    for scene in status.states:
        if scene.state != DONE:
            print(f"layercontact: scene {scene.stem}: {scene.state}: {scene.reason}", file=sys.stderr)
    return 1 if bad else 0


def plot_command(target: str, output: str | None) -> int:
    """``python -m layercontact plot TARGET [-o PICTURE]``: 0 written, 2 not a result file or
    a sweep with a summary, 4 the picture not writable."""
    import matplotlib.pyplot as plt

    from .plot import plot_result, plot_sweep

    path = Path(target)
    try:
        if path.is_file() and path.suffix.lower() in (".h5", ".hdf5"):
            import h5py

            from ._library import regular_file

            regular_file(path, "result file")
            try:
                with h5py.File(path, "r") as f:
                    is_result = "results" in f and "input" in f
                    is_summary = "summary" in f
            except OSError as err:
                raise ValueError(f"{path}: not an HDF5 file ({err})") from None
            if is_result:
                picture = Path(output) if output else path.with_suffix(".png")
                figure = plot_result(path)
            elif is_summary:
                picture = Path(output) if output else path.with_suffix(".png")
                figure = plot_sweep(path)
            else:
                raise ValueError(f"{path}: neither a result file (/input, /results) nor a sweep summary")
        else:
            figure = plot_sweep(path)
            from .plot import _summary_of

            summary, _, _ = _summary_of(path)
            picture = Path(output) if output else summary.with_suffix(".png")
    except (ValueError, OSError, LayercontactError) as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 2
    try:
        figure.savefig(picture, dpi=120)
    except OSError as err:
        print(f"layercontact: error: {picture}: {err}", file=sys.stderr)
        return 4
    finally:
        plt.close(figure)
    print(f"  {'picture':<32}{picture}")
    return 0


def convert_command(source: str, output: str, unit: str | None, channel: int | None) -> int:
    """``python -m layercontact convert INPUT OUTPUT.h5``: 0 written, 2 unreadable as a
    topography, 4 SurfaceTopography missing or the output not writable."""
    from .topography import read_topography, scene_lines, write_height_file

    try:
        topography = read_topography(source, unit=unit, channel=channel)
    except ImportError as err:
        print(f"layercontact: error: {err}", file=sys.stderr)
        return 4
    except Exception as err:  # noqa: BLE001 (the readers of SurfaceTopography raise many kinds)
        print(f"layercontact: error: {source}: cannot be read as a topography: {err}", file=sys.stderr)
        return 2
    try:
        write_height_file(output, topography)
    except OSError as err:
        print(f"layercontact: error: {output}: {err}", file=sys.stderr)
        return 4
    shape = " x ".join(str(s) for s in topography.height.shape[::-1])
    size = " x ".join(f"{s:g}" for s in topography.size)
    print(f"{output}: {shape} heights over {size} {topography.unit or '(no unit stated)'}, "
          f"{'periodic' if topography.periodic else 'not periodic'}, from {topography.source}")
    print(scene_lines(topography, output))
    return 0


if __name__ == "__main__":
    sys.exit(main())
