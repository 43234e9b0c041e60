"""Run records of sweep scenes: where, when, how long and with what outcome each scene ran.

Every run of a sweep scene leaves ``DIRECTORY/runs/STEM.json`` next to its result
``DIRECTORY/results/STEM.h5``. The record is written when the run starts (``state =
"running"``) and replaced when it ends (``"finished"``, or ``"killed"`` when a batch system
stopped it), each time atomically (a temporary file renamed over the old one), so a reader
sees one complete record or the previous one. It holds what the result file does not: the
host, the process, the Slurm job and array ids, the start and end times, the wall time of
the whole run (input, solve and output) and the exit code.

Two writers produce the same fields: the local sweep (Python, :func:`start_record` and
:func:`finish_record`) and the Slurm array job script (bash, see
:mod:`layercontact.sweeps.slurm`), so status and summaries read local and batch runs alike.

Fields
------
scene : str
    The scene's stem (``NAME_XXXX``).
runner : str
    ``"local"`` (a worker process of ``python -m layercontact sweep``) or ``"slurm"`` (an
    array task).
state : str
    ``"running"``, ``"finished"`` or ``"killed"``.
exit_code : int or None
    The executable's exit code (0 converged, 2 bad input, 3 not converged, 4 I/O failure,
    5 not enough memory or internal failure; 127 not found; 128 + N killed by signal N);
    None while running.
host : str
    The machine that ran the scene.
pid : int
    The process that ran it (the worker, or the array task's batch shell).
slurm_job_id, slurm_array_job_id, slurm_array_task_id : int or None
    ``SLURM_JOB_ID``, ``SLURM_ARRAY_JOB_ID``, ``SLURM_ARRAY_TASK_ID`` of the run (None
    outside Slurm; a local sweep inside an allocation records the allocation's job id).
submission : int or None
    The number of the Slurm submission (``slurm/NAME_NNN.*``) that ran it.
started, finished : str or None
    UTC times, ``YYYY-MM-DDTHH:MM:SSZ``.
wall_time : float or None
    Seconds from start to end of the run.
error : str
    Why a local run failed (the exception's message); empty otherwise. An array task's
    message is in its log.
log : str
    The executable's output, relative to the sweep directory (array tasks only).
"""

from __future__ import annotations

import json
import os
import socket
import time
from pathlib import Path

RUNS = "runs"
LOGS = "logs"

#: Exit codes of the ``layercontact`` executable and of a killed run, as words.
EXIT_MEANINGS = {
    0: "converged",
    1: "usage error",
    2: "bad input",
    3: "did not converge",
    4: "I/O failure",
    5: "not enough memory or internal failure",
    126: "the executable could not be run (permission)",
    127: "the executable was not found",
}

#: The columns a summary row takes from the run record, in the record's field names.
PROVENANCE_FIELDS = ("host", "slurm_job_id", "slurm_array_job_id", "slurm_array_task_id", "started")


def record_file(directory: Path, stem: str) -> Path:
    """``DIRECTORY/runs/STEM.json``."""
    return Path(directory) / RUNS / f"{stem}.json"


def log_file(directory: Path, stem: str) -> Path:
    """``DIRECTORY/logs/STEM.log`` (written by array tasks)."""
    return Path(directory) / LOGS / f"{stem}.log"


def utc_now() -> str:
    """The current UTC time as ``YYYY-MM-DDTHH:MM:SSZ`` (the format the job script writes)."""
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())


def _slurm_id(variable: str) -> int | None:
    value = os.environ.get(variable, "")
    return int(value) if value.isdigit() else None


def start_record(stem: str) -> dict[str, object]:
    """The record of a local run that starts now in this process."""
    return {
        "scene": stem,
        "runner": "local",
        "state": "running",
        "exit_code": None,
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "slurm_job_id": _slurm_id("SLURM_JOB_ID"),
        "slurm_array_job_id": _slurm_id("SLURM_ARRAY_JOB_ID"),
        "slurm_array_task_id": _slurm_id("SLURM_ARRAY_TASK_ID"),
        "submission": None,
        "started": utc_now(),
        "finished": None,
        "wall_time": None,
        "error": "",
    }


def finish_record(record: dict[str, object], exit_code: int, wall_time: float, error: str = "") -> dict:
    """``record`` as finished with ``exit_code`` after ``wall_time`` seconds."""
    return {
        **record,
        "state": "finished",
        "exit_code": int(exit_code),
        "finished": utc_now(),
        "wall_time": round(float(wall_time), 3),
        "error": error,
    }


def write_record(path: Path, record: dict[str, object]) -> None:
    """Replace the record at ``path`` atomically (write a temporary file, rename it)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(record) + "\n", encoding="utf-8")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def read_record(path: Path) -> dict[str, object] | None:
    """The record at ``path``, or None if there is none (or it cannot be read: a run
    that never got as far as its first record)."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def describe_exit(code: int) -> str:
    """``'exit 4 (I/O failure)'``, ``'exit 143 (killed by signal 15, SIGTERM)'``."""
    if code in EXIT_MEANINGS:
        return f"exit {code} ({EXIT_MEANINGS[code]})"
    if code > 128:
        import signal

        try:
            name = signal.Signals(code - 128).name
        except ValueError:
            name = "unknown signal"
        return f"exit {code} (killed by signal {code - 128}, {name})"
    return f"exit {code}"


def last_error_line(path: Path) -> str:
    """The last line of a log that says what went wrong (the executable's
    ``layercontact: error: ...`` or ``warning``), else its last non-empty line."""
    try:
        lines = [line.strip() for line in path.read_text(encoding="utf-8", errors="replace").splitlines()]
    except OSError:
        return ""
    lines = [line for line in lines if line]
    for line in reversed(lines):
        if line.startswith("layercontact: "):
            return line
    return lines[-1] if lines else ""


def provenance_columns(record: dict[str, object] | None) -> dict[str, object]:
    """The summary columns of a run record: host, Slurm ids, start time and ``run_time``
    (the wall time of the whole run, input to output; ``wall_time`` in the result is the
    solver's). None where the record has no value (a local run has no Slurm ids)."""
    record = record or {}
    columns = {field: record.get(field) for field in PROVENANCE_FIELDS}
    columns["run_time"] = record.get("wall_time")
    return columns
