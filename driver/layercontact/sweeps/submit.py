"""Submitting a sweep to Slurm as one job array: ``python -m layercontact sweep FILE
--slurm``.

The scenes are written and checked as for a local sweep; then the scenes that have no
complete result and are not already queued or running (all of them the first time;
those missing or failed afterwards) go into a scene list and one sbatch script
(:func:`layercontact.sweeps.slurm.job_script`), which is submitted (or only written and shown,
with ``dry_run``). The job id is recorded in ``slurm/NAME_NNN.json``. Submitting again is
safe at any time: scenes that are done, queued or running are left alone.
"""

from __future__ import annotations

import fcntl
import json
import math
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from . import slurm
from .provenance import utc_now
from .sweep import SweepPlan, plan_scenes, write_plan_record, write_scenes
from .status import QUEUED, RUNNING, SceneState, scene_states


@dataclass(frozen=True)
class SubmitOutcome:
    """What a submission did.

    Attributes
    ----------
    states : dict of str to SceneState
        Every scene's state before the submission.
    scenes : list of str
        The scenes put in the job array (empty: nothing to do).
    script : Path or None
        The job script written (None when there was nothing to submit).
    script_text : str
        Its text.
    submission : Submission or None
        The submission (None for a dry run or nothing to do).
    tasks : int
        Array tasks.
    """

    states: dict[str, SceneState]
    scenes: list[str]
    script: Path | None = None
    script_text: str = ""
    submission: slurm.Submission | None = None
    tasks: int = 0


@contextmanager
def _locked(directory: Path, name: str) -> Iterator[None]:
    """Hold ``slurm/.NAME.lock``: two submissions of one sweep at once would run the same
    scenes twice."""
    folder = slurm.slurm_directory(directory)
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / f".{name}.lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX)
        except OSError:  # a parallel file system mounted without locks: go on unlocked
            yield
            return
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _write_atomically(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def submit_sweep(plan: SweepPlan, options: slurm.SlurmOptions, dry_run: bool = False) -> SubmitOutcome:
    """Submit the scenes of ``plan`` that are missing or failed as one Slurm job array.

    Parameters
    ----------
    plan : SweepPlan
        The sweep (:func:`layercontact.sweeps.sweep.read_sweep`); the tasks run in the current
        working directory, where the scene files name their results.
    options : SlurmOptions
        See :func:`layercontact.sweeps.slurm.resolve_options`.
    dry_run : bool
        Write the scenes, the scene list and the script; submit nothing.

    Returns
    -------
    SubmitOutcome

    Raises
    ------
    ValueError
        A bad option (named), a sweep name unfit for file names, too many array tasks, or
        a scene whose input changed while it is queued or running.
    LayercontactError
        A scene the library refuses (as for a local sweep).
    SlurmError
        sbatch is missing or refused the job (its message).
    """
    if not slurm.SAFE_NAME.match(plan.name):
        raise ValueError(
            f"{plan.source}: &sweep name {plan.name!r} is not allowed for a Slurm sweep; allowed: "
            "letters, digits and . _ + - (it names files the job script reads)"
        )
    executable = slurm.check_executable(options)
    directory = plan.directory
    scenes = plan_scenes(plan)
    stems = [scene.stem for scene in scenes]
    with _locked(directory, plan.name):
        before = scene_states(directory, plan.name, stems)
        changed = [
            s.stem
            for s in scenes
            if before[s.stem].state in (RUNNING, QUEUED)
            and s.scene_file.is_file()
            and s.scene_file.read_text() != s.text
        ]
        if changed:
            raise ValueError(
                f"{plan.source}: the input of {len(changed)} scene(s) changed while they are queued or "
                f"running ({', '.join(changed[:5])}); wait for them or cancel them (scancel), then "
                "submit again"
            )
        write_scenes(plan)
        write_plan_record(plan, scenes)
        states = scene_states(directory, plan.name, stems)
        chosen = [stem for stem in stems if states[stem].rerun]
        if not chosen:
            return SubmitOutcome(states, [])
        number = slurm.next_submission_number(directory, plan.name)
        files = slurm.submission_files(directory, plan.name, number)
        text = slurm.job_script(
            name=plan.name,
            sweep_file=plan.source,
            directory=directory,
            workdir=Path.cwd(),
            submission=number,
            scenes=len(chosen),
            options=options,
            executable=executable,
            max_array_size=slurm.max_array_size(),
        )
        tasks = math.ceil(len(chosen) / options.scenes_per_task)
        _write_atomically(files["scene_list"], "".join(f"{stem}\n" for stem in chosen))
        _write_atomically(files["script"], text)
        files["script"].chmod(0o755)
        if dry_run:
            return SubmitOutcome(states, chosen, files["script"], text, None, tasks)
        try:
            job_id, cluster = slurm.sbatch(files["script"])
        except slurm.SlurmError:
            files["script"].unlink(missing_ok=True)
            files["scene_list"].unlink(missing_ok=True)
            raise
        submission = slurm.Submission(
            number, job_id, cluster, utc_now(), tuple(chosen), options.scenes_per_task
        )
        record = {
            "number": number,
            "job_id": job_id,
            "cluster": cluster,
            "submitted": submission.submitted,
            "scenes_per_task": options.scenes_per_task,
            "tasks": tasks,
            "script": str(files["script"]),
            "executable": executable,
            "scenes": chosen,
        }
        _write_atomically(files["record"], json.dumps(record, indent=1) + "\n")
        return SubmitOutcome(states, chosen, files["script"], text, submission, tasks)
