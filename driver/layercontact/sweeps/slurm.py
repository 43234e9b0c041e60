"""Slurm job arrays for sweeps: the options, the job script, the scheduler's commands and
the records of submissions.

A sweep submitted to Slurm (``python -m layercontact sweep FILE --slurm``, see
:mod:`layercontact.sweeps.submit`) is one job array. Each array task runs a chunk of consecutive
scenes of a scene list one after the other with the ``layercontact`` executable (no Python
on the compute nodes) and leaves, per scene, the result file (written atomically by the
executable), a run record (:mod:`layercontact.sweeps.provenance`) and a log. Files, under the
sweep directory ``DIRECTORY``::

    slurm/NAME_NNN.sbatch     the job script of submission NNN (001, 002, ...)
    slurm/NAME_NNN.scenes     its scene list: one stem per line, task i runs lines
                              i*S+1 .. (i+1)*S (S = scenes per task)
    slurm/NAME_NNN.json       the submission: job id, time, scenes, scenes per task
    slurm/NAME_NNN_J_T.out    the output of array task T of job J (Slurm's messages)
    runs/STEM.json, logs/STEM.log, results/STEM.h5

Options come from the ``&sweep`` group (``slurm_*`` variables) or the command line
(which wins): see :data:`OPTIONS`.
"""

from __future__ import annotations

import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sysconfig
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from .provenance import LOGS, RUNS

SLURM_DIRECTORY = "slurm"
#: Slurm's default MaxArraySize (array indices 0..1000), assumed when ``scontrol`` cannot
#: tell (a dry run on a machine without Slurm).
DEFAULT_MAX_ARRAY_SIZE = 1001
#: Seconds to wait for a Slurm command before calling the controller unreachable.
COMMAND_TIMEOUT = 60
#: Job states in which an array task still holds or waits for its scenes.
ACTIVE_STATES = frozenset(
    {
        "PENDING",
        "CONFIGURING",
        "RUNNING",
        "COMPLETING",
        "SUSPENDED",
        "REQUEUED",
        "REQUEUE_FED",
        "REQUEUE_HOLD",
        "RESIZING",
        "SIGNALING",
        "STAGE_OUT",
        "STOPPED",
        "RESV_DEL_HOLD",
    }
)


class SlurmError(RuntimeError):
    """The scheduler's commands are missing, failed or refused a job (the message holds
    the command and its own message)."""


# ---------------------------------------------------------------------------------------
# options


@dataclass(frozen=True)
class SlurmOptions:
    """How a sweep is submitted as a Slurm job array.

    Attributes
    ----------
    partition, account : str or None
        ``--partition`` and ``--account`` of the job (None: the cluster's default).
    time : str or None
        Time limit of one array task (all its scenes), in Slurm's format: ``MM``,
        ``MM:SS``, ``HH:MM:SS``, ``D-HH``, ``D-HH:MM`` or ``D-HH:MM:SS``.
    memory : str or None
        Memory of one array task (``--mem``): a number of megabytes or a number with
        ``K``, ``M``, ``G`` or ``T``.
    cpus_per_task : int
        CPUs of one array task (of each of its MPI ranks); its scenes run one after the
        other, each with ``OMP_NUM_THREADS`` set to this (for ``&solver threads``).
    ranks_per_scene : int
        MPI ranks of each scene (``--ntasks`` of an array task): with more than 1 a task
        runs its scenes by ``srun --mpi=pmix``, each rank on ``cpus_per_task`` CPUs.
    scenes_per_task : int
        Consecutive scenes run by one array task.
    array_limit : int or None
        At most this many array tasks run at once (``--array=...%N``).
    sbatch_lines : tuple of str
        Further sbatch options, one per ``#SBATCH`` line (``--qos=short``).
    setup_lines : tuple of str
        Shell lines run by each task before its scenes (``module load hdf5``).
    executable : str or None
        The ``layercontact`` program the tasks run (None: the one installed with this
        package).
    job_name : str or None
        The job's name (None: ``lc-NAME``).
    """

    partition: str | None = None
    account: str | None = None
    time: str | None = None
    memory: str | None = None
    cpus_per_task: int = 1
    ranks_per_scene: int = 1
    scenes_per_task: int = 1
    array_limit: int | None = None
    sbatch_lines: tuple[str, ...] = field(default_factory=tuple)
    setup_lines: tuple[str, ...] = field(default_factory=tuple)
    executable: str | None = None
    job_name: str | None = None


#: Sweep names fit for a Slurm sweep: they name the files the job script reads and the
#: JSON records it writes.
SAFE_NAME = re.compile(r"^[A-Za-z0-9._+-]+$")
_SLURM_NAME = re.compile(r"^[A-Za-z0-9_.+,:@-]+$")
_TIME = re.compile(r"^(\d+-\d{1,2}(:\d{1,2}){0,2}|\d+(:\d{1,2}){0,2}|unlimited|infinite)$", re.IGNORECASE)
_MEMORY = re.compile(r"^\d+[KMGT]?$", re.IGNORECASE)


def _not_allowed(where: str, value: object, allowed: str) -> ValueError:
    return ValueError(f"{where}: {value!r} is not allowed; allowed: {allowed}")


#: Characters no name or path may carry into a job script: a newline would end an #SBATCH
#: line or a comment and start a command.
CONTROL_CHARACTERS = re.compile(r"[\x00-\x1f\x7f]")
NO_CONTROL = "text without control characters (newline, carriage return, tab, ...)"


def plain_text(where: str, value: str) -> str:
    """``value`` unchanged, or ValueError naming ``where``, the value and what is allowed
    when it holds a control character (anything that reaches a job script passes here)."""
    if CONTROL_CHARACTERS.search(value):
        raise _not_allowed(where, value, NO_CONTROL)
    return value


def _sbatch_path(where: str, path: Path, pattern: str = "") -> str:
    """A path as the value of an #SBATCH option, quoted as sbatch reads quotes (a space or
    a '#' stays in the path); with a filename ``pattern`` appended (``%A``: the job id), a
    '%' of the path is doubled (sbatch reads '%%' as one '%'). A backslash, which sbatch
    takes as an escape, is refused."""
    text = plain_text(where, str(path))
    if "\\" in text:
        raise _not_allowed(where, text, "a path without a backslash (sbatch reads it as an escape)")
    return shlex.quote(text.replace("%", "%%") + pattern if pattern else text)


def _name(where: str, value: object) -> str:
    if not isinstance(value, str) or not _SLURM_NAME.match(value.strip()):
        raise _not_allowed(where, value, "a Slurm name: letters, digits and . _ + , : @ -")
    return value.strip()


def _time(where: str, value: object) -> str:
    if not isinstance(value, str) or not _TIME.match(value.strip()):
        raise _not_allowed(
            where, value, "a Slurm time limit: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS"
        )
    return value.strip()


def _memory(where: str, value: object) -> str:
    text = str(value).strip() if isinstance(value, (str, int)) and not isinstance(value, bool) else ""
    if not _MEMORY.match(text):
        raise _not_allowed(where, value, "megabytes, or a number with K, M, G or T (e.g. 2G)")
    return text.upper()


def _positive(where: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise _not_allowed(where, value, "an integer >= 1")
    return value


def _lines(where: str, value: object) -> tuple[str, ...]:
    values = value if isinstance(value, (list, tuple)) else [value]
    lines = []
    for line in values:
        if line is None:  # f90nml's empty list entries
            continue
        if not isinstance(line, str) or CONTROL_CHARACTERS.search(line) or not line.strip():
            raise _not_allowed(where, line, f"non-empty strings of one line each, {NO_CONTROL}")
        lines.append(line.strip())
    return tuple(lines)


def _sbatch_lines(where: str, value: object) -> tuple[str, ...]:
    """sbatch options, one per line: ``'--qos=short'``, ``'#SBATCH --qos=short'`` or
    ``'qos=short'`` (the dashes are added: on the command line a value starting with a
    dash must be written ``--sbatch=--qos=short``)."""
    lines = []
    for line in _lines(where, value):
        option = line[len("#SBATCH") :].strip() if line.upper().startswith("#SBATCH") else line
        if not option or option.startswith("#") or option.lstrip("-")[:1] in ("", "=", " "):
            raise _not_allowed(
                where, line, "sbatch options such as '--qos=short' (the '#SBATCH' is optional)"
            )
        lines.append(option if option.startswith("-") else "--" + option)
    return tuple(lines)


def _executable(where: str, value: object) -> str:
    if not isinstance(value, str) or not value.strip() or CONTROL_CHARACTERS.search(value):
        raise _not_allowed(where, value, f"the path of the layercontact executable, {NO_CONTROL}")
    return value.strip()


@dataclass(frozen=True)
class _Option:
    """One option: its &sweep variable, its command-line flag and its check."""

    attribute: str
    variable: str
    flag: str
    check: Callable[[str, object], object]
    help: str


#: The options, by :class:`SlurmOptions` attribute.
OPTIONS: dict[str, _Option] = {
    o.attribute: o
    for o in (
        _Option("partition", "slurm_partition", "--partition", _name, "partition (default: the cluster's)"),
        _Option("account", "slurm_account", "--account", _name, "account to charge (default: yours)"),
        _Option("time", "slurm_time", "--time", _time, "time limit of one array task, e.g. 1:00:00"),
        _Option("memory", "slurm_memory", "--memory", _memory, "memory of one array task, e.g. 2G"),
        _Option(
            "cpus_per_task",
            "slurm_cpus_per_task",
            "--cpus-per-task",
            _positive,
            "CPUs of one array task (default 1; for &solver threads)",
        ),
        _Option(
            "scenes_per_task",
            "slurm_scenes_per_task",
            "--scenes-per-task",
            _positive,
            "scenes run one after the other by one array task (default 1)",
        ),
        _Option(
            "array_limit",
            "slurm_array_limit",
            "--array-limit",
            _positive,
            "at most this many array tasks at once (default: no limit)",
        ),
        _Option(
            "sbatch_lines",
            "slurm_sbatch_lines",
            "--sbatch",
            _sbatch_lines,
            "an extra sbatch option, e.g. qos=short or --sbatch=--qos=short (repeatable)",
        ),
        _Option(
            "setup_lines",
            "slurm_setup_lines",
            "--setup",
            _lines,
            "a shell line each task runs first, e.g. 'module load hdf5' (repeatable)",
        ),
        _Option(
            "executable",
            "slurm_executable",
            "--executable",
            _executable,
            "the layercontact executable on the compute nodes (default: the installed one)",
        ),
        _Option("job_name", "slurm_job_name", "--job-name", _name, "the job's name (default: lc-NAME)"),
    )
}
#: The options whose values are integers.
INTEGER_OPTIONS = ("cpus_per_task", "scenes_per_task", "array_limit")
#: The &sweep variables of Slurm options.
SWEEP_VARIABLES = tuple(o.variable for o in OPTIONS.values())


def options_from_sweep(source: Path, variables: dict[str, object]) -> dict[str, object]:
    """Check the ``slurm_*`` variables of a &sweep group.

    Returns
    -------
    dict of str to object
        The checked values by :class:`SlurmOptions` attribute.

    Raises
    ------
    ValueError
        Naming the file, the variable, the value and what is allowed.
    """
    by_variable = {o.variable: o for o in OPTIONS.values()}
    return {
        by_variable[var].attribute: by_variable[var].check(f"{source}: &sweep {var}", value)
        for var, value in variables.items()
    }


def resolve_options(
    from_sweep: dict[str, object] | None, from_command_line: dict[str, object]
) -> SlurmOptions:
    """The options of a submission: the &sweep group's, overridden by the command line's
    (a value None is not given).

    Raises
    ------
    ValueError
        A bad command-line value, naming the flag, the value and what is allowed.
    """
    values = dict(from_sweep or {})
    for attribute, value in from_command_line.items():
        if value is None or (isinstance(value, (list, tuple)) and not value):
            continue
        values[attribute] = OPTIONS[attribute].check(OPTIONS[attribute].flag, value)
    return replace(SlurmOptions(), **values)


def default_executable() -> str | None:
    """The ``layercontact`` program installed with this package (next to this Python's
    scripts, else on ``PATH``), as an absolute path; None if there is none."""
    found = shutil.which("layercontact", path=sysconfig.get_path("scripts")) or shutil.which("layercontact")
    return str(Path(found).resolve()) if found else None


def check_executable(options: SlurmOptions) -> str:
    """The absolute path of the executable the tasks will run.

    Raises
    ------
    ValueError
        If it is not an executable file here (the compute nodes see the same file system
        on a cluster; a different path there is the user's choice, with ``--executable``).
    """
    chosen = options.executable or default_executable()
    where = OPTIONS["executable"].flag + " (&sweep slurm_executable)"
    if chosen is None:
        raise ValueError(
            f"{where}: no layercontact executable is installed next to this Python or on PATH; "
            "install the package (pip install .) or give the path"
        )
    path = Path(chosen).expanduser()
    if not path.is_file() or not os.access(path, os.X_OK):
        raise _not_allowed(where, chosen, "an executable file (the layercontact program)")
    return str(path.resolve())


# ---------------------------------------------------------------------------------------
# submissions


@dataclass(frozen=True)
class Submission:
    """One submitted job array (``slurm/NAME_NNN.json``).

    Attributes
    ----------
    number : int
        NNN.
    job_id : int
        The array's job id (``SLURM_ARRAY_JOB_ID`` of its tasks).
    cluster : str or None
        The cluster, when sbatch names one (federations).
    submitted : str
        UTC time of the submission.
    scenes : tuple of str
        The scene stems, in scene-list order.
    scenes_per_task : int
        Task i runs ``scenes[i*S:(i+1)*S]``.
    """

    number: int
    job_id: int
    cluster: str | None
    submitted: str
    scenes: tuple[str, ...]
    scenes_per_task: int

    @property
    def tasks(self) -> int:
        """Array tasks: 0 .. tasks-1."""
        return math.ceil(len(self.scenes) / self.scenes_per_task)

    def task_of(self, stem: str) -> int | None:
        """The array task that runs scene ``stem`` (None if it is not in this one)."""
        try:
            return self.scenes.index(stem) // self.scenes_per_task
        except ValueError:
            return None


def slurm_directory(directory: Path) -> Path:
    """``DIRECTORY/slurm``."""
    return Path(directory) / SLURM_DIRECTORY


def submission_files(directory: Path, name: str, number: int) -> dict[str, Path]:
    """The files of submission ``number``: ``script``, ``scene_list``, ``record``."""
    stem = slurm_directory(directory) / f"{name}_{number:03d}"
    return {
        "script": stem.with_suffix(".sbatch"),
        "scene_list": stem.with_suffix(".scenes"),
        "record": stem.with_suffix(".json"),
    }


def task_output_file(directory: Path, name: str, number: int, job_id: int, task: int) -> Path:
    """``slurm/NAME_NNN_J_T.out``: what Slurm and the task's shell printed."""
    return slurm_directory(directory) / f"{name}_{number:03d}_{job_id}_{task}.out"


def read_submissions(directory: Path, name: str) -> list[Submission]:
    """The submissions of sweep ``name`` in ``directory``, oldest first (unreadable
    records are left out: a submission is recorded once sbatch has answered)."""
    pattern = re.compile(rf"^{re.escape(name)}_(\d{{3,}})\.json$")
    found = []
    folder = slurm_directory(directory)
    for path in sorted(folder.glob(f"{name}_*.json")) if folder.is_dir() else []:
        if not pattern.match(path.name):
            continue
        try:
            raw = json.loads(path.read_text(encoding="utf-8"))
            found.append(
                Submission(
                    int(raw["number"]),
                    int(raw["job_id"]),
                    raw.get("cluster"),
                    str(raw["submitted"]),
                    tuple(raw["scenes"]),
                    int(raw["scenes_per_task"]),
                )
            )
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return sorted(found, key=lambda s: s.number)


def next_submission_number(directory: Path, name: str) -> int:
    """One more than the highest NNN of a recorded submission ``slurm/NAME_NNN.json`` (1
    for the first; a dry run's script and scene list are replaced by the next one)."""
    pattern = re.compile(rf"^{re.escape(name)}_(\d{{3,}})\.json$")
    folder = slurm_directory(directory)
    numbers = [
        int(m.group(1)) for p in (folder.iterdir() if folder.is_dir() else []) if (m := pattern.match(p.name))
    ]
    return max(numbers, default=0) + 1


# ---------------------------------------------------------------------------------------
# the job script

_SCRIPT_BODY = r"""
set -u
cd {workdir} || exit 4
executable={executable}
sweep_directory={directory}
scene_list={scene_list}
scenes_per_task={scenes_per_task}
submission={submission}
host=${{SLURMD_NODENAME:-$HOSTNAME}}
# each scene's solve runs on the task's CPUs (&solver threads = 0, the default, takes OMP_NUM_THREADS)
export OMP_NUM_THREADS=${{SLURM_CPUS_PER_TASK:-1}} OPENBLAS_NUM_THREADS=1
# the run records' times are UTC
export TZ=UTC
mkdir -p "$sweep_directory/{runs}" "$sweep_directory/{logs}" "$sweep_directory/results"

# Clock and records without command substitutions: bash may garble a command substitution
# that a signal interrupts (the trap below), so the loop and the trap use builtins only.
now() {{ printf -v REPLY '%(%Y-%m-%dT%H:%M:%SZ)T' -1; }}
if [ -n "${{EPOCHREALTIME:-}}" ]; then  # bash >= 5.0
  milliseconds() {{ local microseconds=${{EPOCHREALTIME/[.,]/}}; REPLY=$(( 10#$microseconds / 1000 )); }}
else
  milliseconds() {{ REPLY=$(( $(date +%s%N) / 1000000 )); }}
fi
seconds_since() {{  # the wall time since $1 (milliseconds), as seconds with 3 decimals
  milliseconds
  local elapsed=$(( REPLY - $1 ))
  printf -v REPLY '%d.%03d' $(( elapsed / 1000 )) $(( elapsed % 1000 ))
}}

# The run record of a scene (layercontact.sweeps.provenance), replaced atomically:
# $1 scene, $2 state, $3 exit code, $4 started, $5 finished, $6 wall time (empty: null).
# Its locals shadow none of the loop's variables: the trap may run while the loop is in
# here and then passes those variables, which must not read as this function's locals.
write_record() {{
  local file="$sweep_directory/{runs}/$1.json" tmp="$sweep_directory/{runs}/.$1.json.$$.tmp"
  local started_json=null finished_json=null
  [ -n "$4" ] && started_json="\"$4\""
  [ -n "$5" ] && finished_json="\"$5\""
  printf '{{"scene": "%s", "runner": "slurm", "state": "%s", "exit_code": %s, "host": "%s", "pid": %s, ' \
    "$1" "$2" "${{3:-null}}" "$host" "$$" >"$tmp"
  printf '"slurm_job_id": %s, "slurm_array_job_id": %s, "slurm_array_task_id": %s, "submission": %s, ' \
    "${{SLURM_JOB_ID:-null}}" "${{SLURM_ARRAY_JOB_ID:-null}}" "${{SLURM_ARRAY_TASK_ID:-null}}" \
    "$submission" >>"$tmp"
  printf '"started": %s, "finished": %s, "wall_time": %s, "error": "", "log": "{logs}/%s.log"}}\n' \
    "$started_json" "$finished_json" "${{6:-null}}" "$1" >>"$tmp"
  mv -f "$tmp" "$file"
}}

# Time limit, scancel, node shutdown: Slurm sends SIGTERM (SIGKILL after KillWait). Record
# which scene was cut short; the scenes after it stay without a record (missing).
# The same signal may reach the program first: then `wait` returns its status before the
# trap runs, and the scene (still current until its record is written) is recorded here by
# that status.
current="" child="" code="" started="" start_ms=0
on_signal() {{
  [ -n "$child" ] && kill -TERM "$child" 2>/dev/null
  if [ -n "$current" ]; then
    seconds_since "$start_ms"
    local wall=$REPLY
    now
    if [ -z "$child" ] && [ -n "$code" ] && [ "$code" -lt 128 ]; then
      write_record "$current" finished "$code" "$started" "$REPLY" "$wall"
    else
      write_record "$current" killed $(( 128 + $2 )) "$started" "$REPLY" "$wall"
    fi
  fi
  echo "layercontact sweep: task ${{SLURM_ARRAY_TASK_ID:-?}} stopped by SIG$1 during ${{current:-no scene}}"
  exit $(( 128 + $2 ))
}}
trap 'on_signal TERM 15' TERM
trap 'on_signal INT 2' INT
trap 'on_signal HUP 1' HUP

task=${{SLURM_ARRAY_TASK_ID:?this script is a Slurm job array: submit it with sbatch}}
mapfile -t listed <"$scene_list"
scenes=("${{listed[@]:task * scenes_per_task:scenes_per_task}}")
if [ ${{#scenes[@]}} -eq 0 ]; then
  echo "layercontact sweep: array task $task has no scenes in $scene_list" >&2
  exit 5
fi

failures=0
for scene in "${{scenes[@]}}"; do
  now
  started=$REPLY
  milliseconds
  start_ms=$REPLY
  current=$scene code=""
  write_record "$scene" running "" "$started" "" ""
  # temporary result files (STEM.h5.HOST.PID.tmp) that killed runs of this scene on this
  # host left, and those of earlier versions (STEM.h5.tmp); a run still writing one, here or
  # on another host, keeps its file
  for left in "$sweep_directory/results/$scene".h5.*tmp; do
    [ -e "$left" ] || continue
    writer=${{left#"$sweep_directory/results/$scene.h5."}}
    writer=${{writer%.tmp}}
    pid=${{writer##*.}}
    if [[ $writer != *.* || ! $pid =~ ^[0-9]+$ ]] \
      || {{ [ "${{writer%.*}}" = "$HOSTNAME" ] && ! kill -0 "$pid" 2>/dev/null; }}; then
      rm -f "$left"
    fi
  done
  # in the background, so that the trap runs at once when a signal arrives
  {launch}"$executable" "$sweep_directory/scenes/$scene.nml" >"$sweep_directory/{logs}/$scene.log" 2>&1 &
  child=$!
  wait "$child"
  code=$?
  child=""
  seconds_since "$start_ms"
  wall=$REPLY
  now
  write_record "$scene" finished "$code" "$started" "$REPLY" "$wall"
  current=""
  echo "$scene: exit $code on $host"
  [ "$code" -eq 0 ] || failures=$(( failures + 1 ))
done
# a task with a scene that failed or did not converge ends FAILED in Slurm's accounting
[ "$failures" -eq 0 ]
"""


def launch_prefix(options: SlurmOptions) -> str:
    """What runs the executable in a task: itself on one rank; on K ranks, ``srun`` of the
    task's K tasks (Open MPI programs start under Slurm through PMIx), each with the task's
    CPUs per rank (given again: srun does not take the job's --cpus-per-task from Slurm
    22.05 on)."""
    if options.ranks_per_scene == 1:
        return ""
    return (f"srun --mpi=pmix --ntasks={options.ranks_per_scene} "
            f"--cpus-per-task={options.cpus_per_task} ")


def job_script(
    *,
    name: str,
    sweep_file: Path,
    directory: Path,
    workdir: Path,
    submission: int,
    scenes: int,
    options: SlurmOptions,
    executable: str,
    max_array_size: int = DEFAULT_MAX_ARRAY_SIZE,
) -> str:
    """The sbatch script of one submission.

    Parameters
    ----------
    name, sweep_file, directory : the sweep's name, file and directory (``directory``
        relative to ``workdir`` or absolute, as the scene files name their results).
    workdir : Path
        Absolute working directory of the tasks (where the sweep was submitted from).
    submission : int
        NNN: the script reads ``slurm/NAME_NNN.scenes``.
    scenes : int
        Number of scenes in that list.
    options : SlurmOptions
    executable : str
        Absolute path of the ``layercontact`` program.
    max_array_size : int
        The cluster's MaxArraySize (the highest array index is one less).

    Raises
    ------
    ValueError
        If the array would be larger than ``max_array_size`` (the message says which
        scenes per task would fit).
    """
    tasks = math.ceil(scenes / options.scenes_per_task)
    if tasks > max_array_size:
        least = math.ceil(scenes / max_array_size)
        raise ValueError(
            f"--scenes-per-task (&sweep slurm_scenes_per_task): {options.scenes_per_task} gives {tasks} "
            f"array tasks for {scenes} scenes, more than this cluster's MaxArraySize = {max_array_size}; "
            f"allowed: scenes per task >= {least}"
        )
    # nothing from an input reaches a shell as a command: every name and path is checked
    # for control characters, and quoted
    plain_text("the working directory (submit from another one)", str(workdir))
    plain_text("the sweep name", name)
    plain_text("the sweep file", str(sweep_file))
    plain_text("&sweep directory", str(directory))
    plain_text("the executable", executable)
    files = submission_files(directory, name, submission)
    output = _sbatch_path(
        "the working directory and &sweep directory",
        (workdir / slurm_directory(directory)).resolve(),
        f"/{name}_{submission:03d}_%A_%a.out",
    )
    array = f"0-{tasks - 1}" + (f"%{options.array_limit}" if options.array_limit else "")
    sbatch = [
        f"--job-name={options.job_name or 'lc-' + name}",
        f"--array={array}",
        f"--ntasks={options.ranks_per_scene}",
        f"--cpus-per-task={options.cpus_per_task}",
        f"--chdir={_sbatch_path('the working directory (submit from another one)', workdir)}",
        f"--output={output}",
    ]
    sbatch += [f"--time={options.time}"] if options.time else []
    sbatch += [f"--mem={options.memory}"] if options.memory else []
    sbatch += [f"--partition={options.partition}"] if options.partition else []
    sbatch += [f"--account={options.account}"] if options.account else []
    sbatch += list(options.sbatch_lines)
    per = options.scenes_per_task
    head = [
        "#!/bin/bash",
        *(f"#SBATCH {line}" for line in sbatch),
        "#",
        f"# layercontact sweep '{name}' ({sweep_file}), submission {submission}: {scenes} scenes,",
        f"# {per} per array task, run one after the other by the layercontact executable (no",
        "# Python here). Per scene: results/STEM.h5 (written atomically by the executable),",
        "# runs/STEM.json (host, Slurm ids, times, exit code; replaced atomically at start and",
        "# end) and logs/STEM.log. A scene that fails does not stop the others. Written by",
        "# `python -m layercontact sweep --slurm`; `python -m layercontact status` reads the",
        "# results; submitting again runs only the scenes that are missing or failed.",
    ]
    if options.ranks_per_scene > 1:
        head.append(f"# Each scene runs on {options.ranks_per_scene} MPI ranks (srun --mpi=pmix), "
                    f"{options.cpus_per_task} CPU(s) per rank.")
    setup = ["", "# environment set-up", *options.setup_lines] if options.setup_lines else []
    body = _SCRIPT_BODY.format(
        workdir=shlex.quote(str(workdir)),
        executable=shlex.quote(executable),
        directory=shlex.quote(str(directory)),
        scene_list=shlex.quote(str(files["scene_list"])),
        scenes_per_task=per,
        submission=submission,
        runs=RUNS,
        logs=LOGS,
        launch=launch_prefix(options),
    )
    return "\n".join(head + setup) + "\n" + body


# ---------------------------------------------------------------------------------------
# the scheduler's commands


def _command(name: str) -> str:
    found = shutil.which(name)
    if found is None:
        raise SlurmError(
            f"'{name}' is not on PATH: run this on a machine with the Slurm client commands "
            "(a login node), or load them (module load slurm)"
        )
    return found


def _run(arguments: list[str]) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(arguments, capture_output=True, text=True, timeout=COMMAND_TIMEOUT, check=False)
    except subprocess.TimeoutExpired as err:
        raise SlurmError(f"{' '.join(arguments)}: no answer within {COMMAND_TIMEOUT} s") from err


def sbatch(script: Path) -> tuple[int, str | None]:
    """Submit ``script``; return its job id and cluster (None unless sbatch names one).

    Raises
    ------
    SlurmError
        With sbatch's own message (bad partition, account, limits, ...).
    """
    done = _run([_command("sbatch"), "--parsable", str(script)])
    answer = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""
    job, _, cluster = answer.partition(";")
    if done.returncode != 0 or not job.isdigit():
        message = (done.stderr or done.stdout).strip() or f"exit {done.returncode}"
        raise SlurmError(f"sbatch {script} failed: {message}")
    return int(job), cluster or None


def max_array_size() -> int:
    """The cluster's MaxArraySize (``scontrol show config``), else Slurm's default."""
    try:
        done = _run([_command("scontrol"), "show", "config"])
    except SlurmError:
        return DEFAULT_MAX_ARRAY_SIZE
    match = re.search(r"^MaxArraySize\s*=\s*(\d+)", done.stdout, re.MULTILINE)
    return int(match.group(1)) if match else DEFAULT_MAX_ARRAY_SIZE


def active_tasks(job_ids: list[int]) -> dict[tuple[int, int], str] | None:
    """The array tasks of ``job_ids`` that are still pending or running, with their state.

    Returns
    -------
    dict of (job id, task id) to str, or None
        ``{(1234, 3): 'RUNNING', ...}``; None if the scheduler cannot be asked (no
        ``squeue`` here, or no answer): then nobody knows whether a task still runs.
    """
    if not job_ids:
        return {}
    if shutil.which("squeue") is None:
        return None
    found: dict[tuple[int, int], str] = {}
    # squeue refuses a list in which every id is unknown (finished and forgotten jobs):
    # ask for each job alone so one forgotten job does not hide the others
    for job in sorted(set(job_ids)):
        try:
            done = _run(["squeue", "--noheader", "--array", f"--jobs={job}", "--format=%i %T"])
        except SlurmError:
            return None
        if done.returncode != 0:
            if "Invalid job id" in done.stderr:
                continue
            return None
        for line in done.stdout.split("\n"):
            ident, _, state = line.strip().partition(" ")
            array_job, _, task = ident.partition("_")
            if array_job.isdigit() and task.isdigit() and state in ACTIVE_STATES:
                found[(int(array_job), int(task))] = state
    return found


def task_end_message(directory: Path, name: str, submission: Submission, task: int) -> str:
    """Slurm's own word on how an array task ended, from its output file (``*** JOB 1235
    ON node CANCELLED AT ... DUE TO TIME LIMIT ***``), or ''."""
    path = task_output_file(directory, name, submission.number, submission.job_id, task)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""
    found = re.findall(r"\*\*\* (.*?) \*\*\*", text)
    return found[-1] if found else ""
