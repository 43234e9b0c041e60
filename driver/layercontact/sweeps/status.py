"""Where a sweep stands, and its summary, from its directory alone: for local sweeps and
for Slurm job arrays alike (``python -m layercontact status DIR`` and ``collect DIR``).

Each scene is in one of five states:

done
    its result file is complete (made from its scene file's text) and converged;
failed
    its result did not converge (the same input gives the same result: it is not run
    again), or its run ended without a result: a non-zero exit code (the log's error line
    says why), killed by a signal (time limit, ``scancel``), or interrupted without a word
    (``SIGKILL``, node failure); those run again when the sweep is submitted again;
running
    its run record says it is running and its process (local) or array task (Slurm) is
    alive;
queued
    its Slurm array task is pending, or running the scenes before it;
missing
    none of the above: never run, or its array task ended before it started, or its
    result is from another input. A ``RESULT.tmp`` left by a killed write does not count
    as a result (the next run replaces it).

The scheduler is asked with ``squeue`` (one call per submission); without it, a run
record that says "running" cannot be checked and is reported as running, unconfirmed.
"""

from __future__ import annotations

import errno
import os
import socket
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from . import provenance, slurm
from .sweep import (
    PLAN_RECORD_FORMAT,
    plan_record_file,
    read_sweep,
    result_matches,
    result_outcome,
    summary_row,
    temporary_results,
    write_summary_files,
)

DONE, FAILED, RUNNING, QUEUED, MISSING = "done", "failed", "running", "queued", "missing"
#: The states, in the order a report lists them.
STATES = (DONE, FAILED, RUNNING, QUEUED, MISSING)


@dataclass(frozen=True)
class SceneState:
    """Where one scene stands.

    Attributes
    ----------
    stem : str
        ``NAME_XXXX``.
    state : str
        One of :data:`STATES`.
    reason : str
        Why (failed, missing) or where (running, queued); empty when done.
    rerun : bool
        Submitting the sweep again runs it (missing, or failed without a result).
    record : dict or None
        Its run record (:mod:`layercontact.sweeps.provenance`).
    outcome : dict or None
        The summary columns of its result, when the result is complete.
    """

    stem: str
    state: str
    reason: str
    rerun: bool
    record: dict | None = None
    outcome: dict | None = None


@dataclass(frozen=True)
class SweepDirectory:
    """A sweep as its directory records it (``NAME_sweep.json``).

    Attributes
    ----------
    directory : Path
        Where the record is (the sweep directory).
    name : str
    sweep_file : str
        The sweep file as it was given to the sweep command.
    sweep_path : Path
        The same, absolute (joined to the working directory of the sweep command).
    scenes : list of dict
        Per scene: ``stem``, ``index``, ``values``, ``scene_file``, ``result_file``.
    """

    directory: Path
    name: str
    sweep_file: str
    sweep_path: Path
    scenes: list[dict]

    @property
    def stems(self) -> list[str]:
        return [entry["stem"] for entry in self.scenes]


def _record_of(path: Path) -> SweepDirectory:
    import json

    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as err:
        raise ValueError(f"{path}: cannot read the sweep record: {err}") from err
    if not isinstance(raw, dict) or raw.get("format") != PLAN_RECORD_FORMAT or "scenes" not in raw:
        raise ValueError(
            f"{path}: not a sweep record of this version (format {PLAN_RECORD_FORMAT}); "
            "run the sweep command again to rewrite it"
        )
    given = str(raw.get("sweep_file", ""))
    sweep_path = Path(given) if Path(given).is_absolute() else Path(raw.get("working_directory", ".")) / given
    return SweepDirectory(path.parent, str(raw["name"]), given, sweep_path, list(raw["scenes"]))


def find_sweep(path: str | os.PathLike) -> SweepDirectory:
    """The sweep of a directory (its one ``NAME_sweep.json``), of a record file, or of a
    sweep namelist file (its ``&sweep directory``).

    Raises
    ------
    ValueError
        No sweep there (never run or submitted), several (name the record file), or an
        unreadable record.
    FileNotFoundError
        ``path`` does not exist.
    """
    path = Path(path)
    if path.is_dir():
        records = sorted(path.glob("*_sweep.json"))
        if not records:
            raise ValueError(
                f"{path}: not a sweep directory (no NAME_sweep.json: the sweep command writes it)"
            )
        if len(records) > 1:
            names = ", ".join(str(r) for r in records)
            raise ValueError(f"{path}: holds several sweeps ({names}); give the one you mean")
        return _record_of(records[0])
    if not path.exists():
        # (a loop of symbolic links does not exist either: say which it is)
        try:
            os.stat(path)
        except OSError as err:
            if err.errno == errno.ELOOP:
                raise ValueError(f"{path}: a loop of symbolic links; allowed: a sweep directory or file") from None
        raise FileNotFoundError(f"{path}: no such file or directory")
    if path.suffix == ".json":
        return _record_of(path)
    plan = read_sweep(path)
    record = plan_record_file(plan.directory, plan.name)
    if not record.is_file():
        raise ValueError(f"{path}: its sweep has not been run or submitted yet (no {record})")
    return _record_of(record)


# ---------------------------------------------------------------------------------------
# the state of each scene


def _alive_here(record: dict) -> bool | None:
    """Whether a local run's process is alive: None if it ran on another machine."""
    if record.get("host") != socket.gethostname():
        return None
    try:
        os.kill(int(record.get("pid") or 0), 0)
    except ProcessLookupError:
        return False
    except (PermissionError, ValueError, OverflowError):
        return True
    return bool(record.get("pid"))


def _where(record: dict) -> str:
    """``'in Slurm job 1234_5 on node7'`` or ``'on node7 (pid 123)'``."""
    host = record.get("host", "?")
    if record.get("slurm_array_job_id") is not None:
        return f"in Slurm job {record['slurm_array_job_id']}_{record.get('slurm_array_task_id')} on {host}"
    return f"on {host} (pid {record.get('pid')})"


class _Context:
    """What the states of all scenes share: the submissions and the scheduler's answer."""

    def __init__(self, directory: Path, name: str, ask_scheduler: bool):
        self.directory = directory
        self.name = name
        self.submissions = slurm.read_submissions(directory, name)
        self.latest = {stem: sub for sub in self.submissions for stem in sub.scenes}
        self.by_job = {sub.job_id: sub for sub in self.submissions}
        if not self.submissions:
            self.active: dict | None = {}
        elif ask_scheduler:
            self.active = slurm.active_tasks([sub.job_id for sub in self.submissions])
        else:
            self.active = None

    def slurm_message(self, job_id: object, task: object) -> str:
        sub = self.by_job.get(job_id) if isinstance(job_id, int) else None
        if sub is None or not isinstance(task, int):
            return ""
        message = slurm.task_end_message(self.directory, self.name, sub, task)
        return f" (Slurm: {message})" if message else ""


def _exit_words(code: object) -> str:
    """``'exit 4 (I/O failure)'``; a record without a usable code says so."""
    return provenance.describe_exit(code) if isinstance(code, int) else f"exit code {code!r} unknown"


def _leftovers(directory: Path, stem: str) -> str:
    """A note on a temporary result left by a killed write, or ''."""
    left = sorted(p.name for p in temporary_results(directory / "results", stem))
    return f"; {', '.join(left)} left from an interrupted write (ignored; the next run removes it)" if left else ""


def _state_of(ctx: _Context, stem: str) -> SceneState:
    directory = ctx.directory
    scene_file = directory / "scenes" / f"{stem}.nml"
    result_file = directory / "results" / f"{stem}.h5"
    record = provenance.read_record(provenance.record_file(directory, stem))
    try:
        text = scene_file.read_text()
    except OSError:
        return SceneState(stem, MISSING, f"its scene file {scene_file} is missing", True, record)
    if result_matches(result_file, text):
        outcome = result_outcome(result_file)
        if outcome["error"]:
            return SceneState(
                stem,
                FAILED,
                f"{outcome['error']}; the same input gives the same result, so it is "
                "not run again (change &solver to retry)",
                False,
                record,
                outcome,
            )
        return SceneState(stem, DONE, "", False, record, outcome)

    sub = ctx.latest.get(stem)
    task = sub.task_of(stem) if sub else None
    from_task = bool(
        sub
        and record
        and record.get("slurm_array_job_id") == sub.job_id
        and record.get("slurm_array_task_id") == task
    )
    if sub is not None and ctx.active is not None:
        task_state = ctx.active.get((sub.job_id, task))
        if task_state is not None and from_task and record.get("state") == "running":
            return SceneState(stem, RUNNING, f"{_where(record)} since {record.get('started')}", False, record)
        if task_state is not None and not from_task:
            return SceneState(
                stem, QUEUED, f"in Slurm job {sub.job_id}_{task} ({task_state.lower()})", False, record
            )
    elif sub is not None and (record is None or record.get("submission") != sub.number):
        return SceneState(
            stem,
            QUEUED,
            f"submitted in Slurm job {sub.job_id}_{task}; not confirmed: the scheduler "
            "cannot be asked from here",
            False,
            record,
        )

    leftovers = _leftovers(directory, stem)
    if record is None:
        if sub is not None:
            why = f"its array task {sub.job_id}_{task} ended before it started" + ctx.slurm_message(
                sub.job_id, task
            )
        elif result_file.exists():
            why = f"its result {result_file.name} is from another input or unreadable"
        else:
            why = "never run"
        return SceneState(stem, MISSING, why + leftovers, True, record)

    state = record.get("state")
    code = record.get("exit_code")
    job, task_id = record.get("slurm_array_job_id"), record.get("slurm_array_task_id")
    if state == "finished" and code == 0:
        return SceneState(
            stem,
            MISSING,
            f"ran {_where(record)} (exit 0) but its result is missing or from another input" + leftovers,
            True,
            record,
        )
    # a signal may reach the program first, and its exit code 128 + N be recorded as finished
    killed = state == "killed" or (state == "finished" and isinstance(code, int) and code > 128)
    if state == "finished" and not killed:
        detail = record.get("error") or provenance.last_error_line(directory / str(record.get("log", "")))
        why = f"{_exit_words(code)} {_where(record)}" + (f": {detail}" if detail else "")
        return SceneState(stem, FAILED, why + leftovers, True, record)
    if killed:
        why = f"killed {_where(record)}: {_exit_words(code)}" + ctx.slurm_message(job, task_id)
        return SceneState(stem, FAILED, why + leftovers, True, record)
    # the record says running, and no live array task of ours runs it
    if record.get("runner") == "local":
        alive = _alive_here(record)
        if alive is None:
            return SceneState(
                stem,
                RUNNING,
                f"{_where(record)} since {record.get('started')}; not confirmed: it runs on another machine",
                False,
                record,
            )
        if alive:
            return SceneState(stem, RUNNING, f"{_where(record)} since {record.get('started')}", False, record)
        return SceneState(
            stem,
            FAILED,
            f"interrupted {_where(record)}: the process ended without recording an "
            "exit (it was killed)" + leftovers,
            True,
            record,
        )
    if ctx.active is None:
        return SceneState(
            stem,
            RUNNING,
            f"{_where(record)} since {record.get('started')}; not confirmed: the "
            "scheduler cannot be asked from here",
            False,
            record,
        )
    why = (
        f"interrupted {_where(record)}: the task ended during this scene without recording an exit (SIGKILL, "
        "node failure)" + ctx.slurm_message(job, task_id)
    )
    return SceneState(stem, FAILED, why + leftovers, True, record)


def scene_states(
    directory: Path, name: str, stems: list[str], ask_scheduler: bool = True
) -> dict[str, SceneState]:
    """The state of each scene of sweep ``name`` in ``directory``.

    Parameters
    ----------
    directory : Path
        The sweep directory.
    name : str
        The sweep's name (file prefix).
    stems : list of str
        The scenes.
    ask_scheduler : bool
        Ask Slurm which array tasks are still pending or running (``squeue``).

    Returns
    -------
    dict of str to SceneState
        In the order of ``stems``.
    """
    ctx = _Context(Path(directory), name, ask_scheduler)
    return {stem: _state_of(ctx, stem) for stem in stems}


# ---------------------------------------------------------------------------------------
# status and collect


@dataclass(frozen=True)
class SweepStatus:
    """The states of every scene of a sweep, in scene order."""

    sweep: SweepDirectory
    states: list[SceneState]

    def count(self, state: str) -> int:
        return sum(s.state == state for s in self.states)

    @property
    def finished(self) -> bool:
        """Every scene done."""
        return all(s.state == DONE for s in self.states)

    def counts_line(self) -> str:
        """``'6 scenes: 4 done, 1 failed, 0 running, 0 queued, 1 missing'``."""
        return f"{len(self.states)} scenes: " + ", ".join(f"{self.count(s)} {s}" for s in STATES)


def sweep_status(path: str | os.PathLike, ask_scheduler: bool = True) -> SweepStatus:
    """The state of every scene of the sweep at ``path`` (see :func:`find_sweep`)."""
    sweep = find_sweep(path)
    states = scene_states(sweep.directory, sweep.name, sweep.stems, ask_scheduler)
    return SweepStatus(sweep, list(states.values()))


def describe(values: dict) -> str:
    """``'friction = 0.5, seed = 2'``."""
    return ", ".join(f"{k} = {v!r}" for k, v in values.items()) or "the base scene"


def report(status: SweepStatus, write: Callable[[str], None] = print, limit: int | None = 20) -> None:
    """Write the status of a sweep: the counts, then the scenes that are not done (at most
    ``limit`` per state; None: all), then what to do next."""
    sweep = status.sweep
    write(f"sweep '{sweep.name}' ({sweep.directory}): {status.counts_line()}")
    values = {entry["stem"]: entry.get("values", {}) for entry in sweep.scenes}
    for state in (FAILED, RUNNING, QUEUED, MISSING):
        chosen = [s for s in status.states if s.state == state]
        if not chosen:
            continue
        write(f"{state}:")
        for scene in chosen[:limit]:
            write(f"  {scene.stem}  ({describe(values.get(scene.stem, {}))}): {scene.reason}")
        if limit is not None and len(chosen) > limit:
            write(f"  ... and {len(chosen) - limit} more (--all lists them)")
    rerun = sum(s.rerun for s in status.states)
    busy = status.count(RUNNING) + status.count(QUEUED)
    if rerun:
        write(
            f"next: `python -m layercontact sweep {sweep.sweep_path} --slurm` (or without --slurm, locally) "
            f"runs the {rerun} failed or missing scene(s) again"
        )
    elif busy:
        write(
            f"next: wait for the {busy} running or queued scene(s), then `python -m layercontact collect "
            f"{sweep.directory}`"
        )
    else:
        write(f"next: `python -m layercontact collect {sweep.directory}` writes the summary")


def _planned_row(entry: dict) -> dict[str, object]:
    return {**entry.get("values", {}), "scene_file": entry["scene_file"], "result_file": entry["result_file"]}


def collect(
    path: str | os.PathLike, ask_scheduler: bool = True
) -> tuple[SweepStatus, list[dict[str, object]]]:
    """Write the summary of a sweep (``NAME_summary.csv`` and ``.h5`` in its directory)
    from what is there, as a local sweep writes it: one row per scene, the columns of its
    complete result, or ``converged = 0`` and ``error`` = its state and why.

    Returns
    -------
    SweepStatus, list of dict
        The states and the rows.
    """
    status = sweep_status(path, ask_scheduler)
    sweep = status.sweep
    rows = []
    for entry, scene in zip(sweep.scenes, status.states):
        outcome = (
            scene.outcome
            if scene.outcome is not None
            else {"converged": 0, "error": f"{scene.state}: {scene.reason}"}
        )
        rows.append(summary_row(_planned_row(entry), outcome, scene.record))
    write_summary_files(rows, sweep.directory, sweep.name, sweep.sweep_file)
    return status, rows
