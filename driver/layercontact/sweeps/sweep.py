"""Parameter sweeps: one namelist file with a base scene and a ``&sweep`` group, run as the
cartesian product of the swept values in parallel worker processes, resumable, with a
CSV and an HDF5 summary.

A sweep file holds the usual groups (``&scene &layer &material &friction &profile &loading &solver
&output``) plus::

    &sweep
       name = 'fig2b'                    ! used in file names; default: the file's stem
       directory = 'out/fig2b'           ! default: 'out/NAME' (relative to the cwd)
       friction = 0.0, 0.2, 0.5          ! -> &friction coefficient
       normalised_pressure = 0.3, 1, 3   ! -> &loading (or mean_pressure; load control)
       thickness = 0.16, 0.01            ! -> &layer thickness
       speed = 0.01, 0.1, 1              ! -> &material speed (viscoelastic layers)
       seed = 1, 2, 3                    ! -> &profile seed (or realisations = N: 1..N)
       processes = 2                     ! worker processes (default: the CPUs allocated)
       max_scenes = 50000                ! the most scenes allowed (default: MAX_SCENES, 20000)
       slurm_time = '0:30:00'            ! slurm_*: options of a Slurm job array
    /                                    ! (layercontact.sweeps.slurm, docs/clusters.md)

Layout of ``DIRECTORY``: ``scenes/NAME_XXXX.nml`` (one complete scene each),
``results/NAME_XXXX.h5`` (written by the library, complete or absent), ``runs/NAME_XXXX.json``
(the run record: host, Slurm ids, times, exit code; :mod:`layercontact.sweeps.provenance`),
``NAME_sweep.json`` (the list of scenes, read by ``status`` and ``collect``) and
``NAME_summary.csv`` / ``NAME_summary.h5`` (one row per scene). A Slurm sweep adds
``logs/`` (the executable's output per scene) and ``slurm/`` (job scripts and submissions).
"""

from __future__ import annotations

import copy
import csv
import fcntl
import io
import itertools
import json
import math
import shutil
import signal
import subprocess
import threading
import multiprocessing
import os
import re
import socket
import sys
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import f90nml
import numpy as np

from .. import scene_schema
from . import provenance
from ..api import LayercontactError, check_scene_file, regular_file, run_to_file
from .. import native
from .slurm import CONTROL_CHARACTERS, NO_CONTROL, SWEEP_VARIABLES, options_from_sweep

SWEEP_GROUP = "sweep"
SUMMARY_GROUP = "summary"
_SETTINGS = ("name", "directory", "realisations", "processes", "max_scenes")
#: The most scenes a sweep may have unless ``&sweep max_scenes`` (or ``--max-scenes``)
#: allows more: writing and checking a scene takes about 5 ms and planning holds about
#: 1.3 kB per scene (so 20000 scenes take under two minutes before the first one runs), and
#: each scene leaves a scene file and a result (docs/sweeps.md).
MAX_SCENES = 20000
#: Format of ``NAME_sweep.json`` (raised when its meaning changes).
PLAN_RECORD_FORMAT = 1
_PRESSURES = ("mean_pressure", "normalised_pressure")


@dataclass(frozen=True)
class _Parameter:
    """Where a swept variable goes in the scene namelist.

    Attributes
    ----------
    group, variable : str
        The namelist group and variable it overrides.
    kind : type
        ``float`` or ``int`` (the values' type).
    replaces : tuple of str
        Variables of ``group`` removed first (the alternatives of this one).
    sets : tuple of (str, object)
        Other variables of ``group`` set with it.
    """

    group: str
    variable: str
    kind: type
    replaces: tuple[str, ...] = ()
    sets: tuple[tuple[str, object], ...] = ()

    def apply(self, nml: f90nml.Namelist, value: float | int) -> None:
        """Override this parameter in ``nml`` (in place)."""
        if self.group not in nml:
            nml[self.group] = {}
        group = nml[self.group]
        for variable in self.replaces:
            group.pop(variable, None)
        for variable, fixed in self.sets:
            group[variable] = fixed
        group[self.variable] = value


def _parameter(variable: scene_schema.Variable) -> _Parameter:
    """The sweep parameter of a scene variable: a load replaces the other loads and sets load
    control."""
    kind = float if variable.type == "real" else int
    if variable.group != "loading":
        # (the variable's second name in the base scene would be a second value of it: `nx` for `n`)
        aliases = tuple(v.name for v in scene_schema.group_variables(variable.group) if v.alias_of == variable.name)
        return _Parameter(variable.group, variable.name, kind, aliases)
    loads = tuple(v.name for v in scene_schema.group_variables("loading") if v.type == "real")
    return _Parameter(variable.group, variable.name, kind, loads, (("control", "load"),))


#: The &sweep lists, in the order of the product (the last one varies fastest): the scene
#: variables the schema marks as sweep parameters, by their /input names.
PARAMETERS: dict[str, _Parameter] = {v.result_name: _parameter(v) for v in scene_schema.sweep_parameters()}


@dataclass(frozen=True)
class SweepPlan:
    """A parsed sweep file.

    Attributes
    ----------
    source : Path
        The sweep file.
    name : str
        Prefix of the scene, result and summary file names.
    directory : Path
        Where everything is written (relative to the cwd unless absolute).
    base : f90nml.Namelist
        The base scene (every group except ``&sweep``).
    values : dict of str to list
        The swept variables (``realisations`` already turned into ``seed``), in product
        order.
    processes : int or None
        Worker processes asked for in the file.
    slurm : dict of str to object, or None
        The ``slurm_*`` variables of the &sweep group, checked, by
        :class:`layercontact.sweeps.slurm.SlurmOptions` attribute (see
        :func:`layercontact.sweeps.slurm.options_from_sweep`).
    """

    source: Path
    name: str
    directory: Path
    base: f90nml.Namelist
    values: dict[str, list]
    processes: int | None
    slurm: dict[str, object] | None = None
    max_scenes: int = MAX_SCENES

    @property
    def scene_count(self) -> int:
        """The number of scenes: the product of the lists' lengths (1 without lists)."""
        return math.prod(len(values) for values in self.values.values())

    def plan_record_file(self) -> Path:
        """``DIRECTORY/NAME_sweep.json``: the scenes, for ``status`` and ``collect``."""
        return plan_record_file(self.directory, self.name)

    def summary_file(self, suffix: str) -> Path:
        """``DIRECTORY/NAME_summary.SUFFIX`` (suffix ``'csv'`` or ``'h5'``)."""
        return self.directory / f"{self.name}_summary.{suffix}"


@dataclass(frozen=True)
class Scene:
    """One scene of a sweep: its swept values, files and namelist text."""

    index: int
    values: dict[str, float | int]
    scene_file: Path
    result_file: Path
    text: str

    @property
    def stem(self) -> str:
        """``NAME_XXXX``: the name of its scene, result, run record and log files."""
        return self.scene_file.stem

    def planned_row(self) -> dict[str, object]:
        """The swept values and the file names (the first columns of the summary)."""
        return {**self.values, "scene_file": str(self.scene_file), "result_file": str(self.result_file)}


# ---------------------------------------------------------------------------------------
# reading the sweep file


def _sweep_error(source: Path, variable: str, message: str) -> ValueError:
    return ValueError(f"{source}: &sweep {variable}: {message}")


def _as_list(value: object) -> list:
    return list(value) if isinstance(value, list) else [value]


def _typed_values(source: Path, variable: str, raw: object, kind: type) -> list:
    """The list ``variable = raw`` of a &sweep group, checked to be ``kind`` numbers."""
    values = [v for v in _as_list(raw) if v is not None]
    if not values:
        raise _sweep_error(source, variable, "no values given")
    for value in values:
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not number or (kind is int and not isinstance(value, int)):
            expected = "an integer" if kind is int else "a number"
            raise _sweep_error(source, variable, f"value {value!r} is not {expected}")
    return [kind(v) for v in values]


def _positive_int(source: Path, variable: str, raw: object) -> int:
    if isinstance(raw, bool) or not isinstance(raw, int) or raw < 1:
        raise _sweep_error(source, variable, f"{raw!r} is not allowed; allowed: an integer >= 1")
    return raw


def _name_setting(source: Path, variable: str, raw: object) -> str:
    # a control character (a value spanning two lines) would reach file names, scene files
    # and a Slurm job script
    if not isinstance(raw, str) or not raw.strip() or CONTROL_CHARACTERS.search(raw):
        allowed = f"a non-empty string, {NO_CONTROL}"
        raise _sweep_error(source, variable, f"{raw!r} is not allowed; allowed: {allowed}")
    return raw.strip()


def _text_outside_groups(text: str) -> int | None:
    """The first line (1-based) with text outside a namelist group (the library refuses it
    in scene files; f90nml would drop it silently), or None."""
    inside, quote = False, ""
    for number, line in enumerate(text.splitlines(), start=1):
        k = 0
        while k < len(line):
            char = line[k]
            if quote:
                quote = "" if char == quote else quote
            elif char in "'\"":
                quote = char
            elif char == "!":
                break
            elif not inside and char == "&":
                inside = True
            elif inside and char == "/":
                inside = False
            elif not inside and not char.isspace():
                return number
            k += 1
    return None


def _read_namelist(source: Path) -> f90nml.Namelist:
    outside = _text_outside_groups(source.read_text()) if source.is_file() else None
    if outside is not None:
        raise ValueError(f"{source}, line {outside}: text outside a namelist group; allowed: comments (!) and "
                         "blank lines between groups")
    try:
        nml = f90nml.read(os.fspath(source))
    except FileNotFoundError:
        raise
    except Exception as err:  # f90nml raises several types for syntax errors
        raise ValueError(f"{source}: cannot parse the namelist file: {err}") from err
    # f90nml keeps a repeated group as a "cogroup" (its name twice in keys()); the library
    # reads each group once
    names = list(nml.keys())
    repeated = [name for name in dict.fromkeys(names) if names.count(name) > 1]
    if repeated:
        raise ValueError(f"{source}: &{repeated[0]} is given more than once; allowed: one &{repeated[0]} group")
    # f90nml merges a variable given twice element by element, and keeps both names of one
    # variable (period, period_x): refused, as the library refuses them in a scene file and
    # as the lists of a sweep are read whole
    twice = _repeated_variable(source.read_text()) if source.is_file() else None
    if twice is not None:
        group, first, second = twice
        if group == SWEEP_GROUP:
            raise _sweep_error(source, second, "given more than once; allowed: one assignment with its whole list")
        both = f"{second} is given more than once" if first == second else \
            f"{first} and {second} are both given (two names of one variable)"
        raise ValueError(f"{source}: &{group}: {both}; allowed: one of them: keep the one you mean and remove "
                         "the other")
    return nml


#: The second names of scene variables, as (group, name) -> the first name (period_x -> period).
_ALIASES = {(v.group, v.name): v.alias_of for v in scene_schema.VARIABLES if v.alias_of}


def _repeated_variable(text: str) -> tuple[str, str, str] | None:
    """The first variable of a namelist text assigned twice in its group, directly or under
    its second name: ``(group, first name, second name)``, or None."""
    seen: dict[tuple[str, str], str] = {}
    group = None
    for line in text.splitlines():
        code = re.sub(r"'[^']*'|\"[^\"]*\"", "''", line).split("!")[0]
        if group is None:
            match = re.match(r"\s*&(\w+)\b(.*)", code)
            if not match:
                continue
            group, code = match.group(1).lower(), match.group(2)
        for name, index in re.findall(r"(?:^|[\s,])([A-Za-z_]\w*)\s*(\([^)]*\))?\s*=", code):
            name = name.lower()
            # (elements of a scene's list may be given one by one; a &sweep list is read whole)
            element = "" if group == SWEEP_GROUP else index.replace(" ", "")
            key = (group, _ALIASES.get((group, name), name) + element)
            if key in seen:
                return group, seen[key], name
            seen[key] = name
        if "/" in code:
            group = None
    return None


def _swept_values(source: Path, group: f90nml.Namelist) -> dict[str, list]:
    """The swept lists of a &sweep group, in product order, ``realisations`` -> ``seed``."""
    for first, second in (_PRESSURES, ("seed", "realisations")):
        if first in group and second in group:
            raise _sweep_error(source, f"{first}, {second}", "give at most one of them")
    values = {
        var: _typed_values(source, var, group[var], p.kind) for var, p in PARAMETERS.items() if var in group
    }
    if "realisations" in group:
        values["seed"] = list(range(1, _positive_int(source, "realisations", group["realisations"]) + 1))
    return values


def read_sweep(path: str | os.PathLike, max_scenes: int | None = None) -> SweepPlan:
    """Read and check a sweep file (the &sweep group only; the scenes are checked by the
    library once written). The number of scenes is counted first: beyond the limit the
    sweep is refused before anything is planned.

    Parameters
    ----------
    path : str or os.PathLike
        The sweep namelist file.
    max_scenes : int, optional
        The most scenes allowed; default: ``&sweep max_scenes``, else :data:`MAX_SCENES`.

    Returns
    -------
    SweepPlan

    Raises
    ------
    ValueError
        For a missing &sweep group, a bad &sweep variable (named in the message) or more
        scenes than allowed.
    """
    source = Path(regular_file(path, "sweep file"))
    nml = _read_namelist(source)
    if SWEEP_GROUP not in nml:
        raise ValueError(f"{source}: no &sweep group (a sweep file is a scene plus a &sweep group)")
    group = nml.pop(SWEEP_GROUP)
    known = (*PARAMETERS, *_SETTINGS, *SWEEP_VARIABLES)
    unknown = [var for var in group if var not in known]
    if unknown:
        allowed = ", ".join(known)
        raise _sweep_error(source, unknown[0], f"unknown variable; allowed: {allowed}")
    name = _name_setting(source, "name", group.get("name", source.stem))
    if "/" in name or os.sep in name:
        raise _sweep_error(source, "name", f"{name!r} must not contain a path separator")
    directory = _name_setting(source, "directory", group.get("directory", f"out/{name}"))
    processes = _positive_int(source, "processes", group["processes"]) if "processes" in group else None
    slurm = options_from_sweep(source, {var: group[var] for var in SWEEP_VARIABLES if var in group})
    if max_scenes is None:
        limit = MAX_SCENES
        if "max_scenes" in group:
            limit = _positive_int(source, "max_scenes", group["max_scenes"])
    elif isinstance(max_scenes, bool) or not isinstance(max_scenes, int) or max_scenes < 1:
        raise ValueError(f"--max-scenes: {max_scenes!r} is not allowed; allowed: an integer >= 1")
    else:
        limit = max_scenes
    values = _swept_values(source, group)
    plan = SweepPlan(source, name, Path(directory), nml, values, processes, slurm, limit)
    check_scene_count(plan)
    return plan


def check_scene_count(plan: SweepPlan) -> None:
    """Refuse a sweep with more scenes than ``plan.max_scenes`` (ValueError naming the
    count, the lists and how to allow more); nothing is planned before this."""
    if plan.scene_count <= plan.max_scenes:
        return
    lists = " x ".join(f"{len(values)} {name}" for name, values in plan.values.items())
    raise ValueError(
        f"{plan.source}: &sweep: the lists give {plan.scene_count} scenes ({lists}), more than "
        f"{plan.max_scenes}; allowed: at most {plan.max_scenes} scenes, or more with &sweep max_scenes = N "
        "(or --max-scenes N); each scene takes about 5 ms to write and check before any runs, and "
        "leaves a scene file and a result file"
    )


# ---------------------------------------------------------------------------------------
# writing and checking the scenes


def _describe(values: dict[str, float | int]) -> str:
    """``'friction = 0.5, seed = 2'`` (the swept values of a scene)."""
    return ", ".join(f"{k} = {v!r}" for k, v in values.items()) or "the base scene"


def _scene_text(plan: SweepPlan, index: int, values: dict, result_file: Path) -> str:
    """The namelist text of one scene: the base with the overrides and its result file."""
    nml = copy.deepcopy(plan.base)
    for variable, value in values.items():
        PARAMETERS[variable].apply(nml, value)
    if "output" not in nml:
        nml["output"] = {}
    nml["output"]["file"] = str(result_file)
    nml["output"]["overwrite"] = True
    out = io.StringIO()
    out.write(f"! sweep '{plan.name}' ({plan.source.name}), scene {index}: {_describe(values)}\n")
    nml.write(out)
    return out.getvalue()


def iter_scenes(plan: SweepPlan) -> Iterator[Scene]:
    """The scenes of a sweep one at a time (the product is never held whole): the cartesian
    product of its lists (none: the base alone), in product order (the last swept variable
    varies fastest), numbered from 0. Refuses a sweep beyond its scene limit first
    (:func:`check_scene_count`)."""
    check_scene_count(plan)
    width = max(4, len(str(plan.scene_count - 1)))
    for index, combo in enumerate(itertools.product(*plan.values.values())):
        values = dict(zip(plan.values, combo))
        stem = f"{plan.name}_{index:0{width}d}"
        scene_file = plan.directory / "scenes" / f"{stem}.nml"
        result_file = plan.directory / "results" / f"{stem}.h5"
        yield Scene(index, values, scene_file, result_file, _scene_text(plan, index, values, result_file))


def plan_scenes(plan: SweepPlan) -> list[Scene]:
    """The scenes of a sweep as a list (see :func:`iter_scenes`).

    Parameters
    ----------
    plan : SweepPlan

    Returns
    -------
    list of Scene
        In product order (the last swept variable varies fastest), numbered from 0.
    """
    return list(iter_scenes(plan))


def _temporary(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}.tmp")


@contextmanager
def _atomic(path: Path) -> Iterator[Path]:
    """Yield a temporary name next to ``path``; on success it replaces ``path``, on
    failure it is removed (``path`` is then untouched)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temporary(path)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _write_scene(scene: Scene) -> None:
    """Write the scene file unless it already holds the same text (keeps its mtime). A
    changed scene loses its run record and log: they describe the old input."""
    if scene.scene_file.is_file() and scene.scene_file.read_text() == scene.text:
        return
    directory = scene.scene_file.parent.parent
    provenance.record_file(directory, scene.stem).unlink(missing_ok=True)
    provenance.log_file(directory, scene.stem).unlink(missing_ok=True)
    with _atomic(scene.scene_file) as tmp:
        tmp.write_text(scene.text)


def _check_scene(plan: SweepPlan, scene: Scene, scratch: Path) -> None:
    """Check the scene's text with the library from a scratch copy (the sweep's directory is
    not touched until every scene passed); the message names the scene file it will be."""
    copy = scratch / scene.scene_file.name
    copy.write_text(scene.text)
    try:
        check_scene_file(copy)
    except LayercontactError as err:
        where = f"&sweep '{plan.name}' ({plan.source}): scene file {scene.scene_file}"
        message = str(err).replace(str(copy), str(scene.scene_file))
        raise LayercontactError(f"{where} ({_describe(scene.values)}): {message}", err.code) from err


def write_scenes(plan: SweepPlan) -> list[Scene]:
    """Check every scene of ``plan`` with the library, then write the scene files (a sweep
    with a bad scene leaves nothing behind).

    Raises
    ------
    LayercontactError
        For the first invalid scene, naming its scene file, its swept values and the
        library's message (group, variable, value, allowed range).
    """
    import tempfile

    with tempfile.TemporaryDirectory(prefix="layercontact-sweep-") as scratch:
        for scene in iter_scenes(plan):
            _check_scene(plan, scene, Path(scratch))
    scenes = plan_scenes(plan)
    for scene in scenes:
        _write_scene(scene)
    return scenes


def plan_record_file(directory: Path, name: str) -> Path:
    """``DIRECTORY/NAME_sweep.json``."""
    return Path(directory) / f"{name}_sweep.json"


def write_plan_record(plan: SweepPlan, scenes: list[Scene]) -> None:
    """Write ``DIRECTORY/NAME_sweep.json``: the sweep's name, file and working directory
    and, per scene, its stem, swept values and file names as a summary shows them. It
    lets ``status`` and ``collect`` work from the directory alone (scene, result, run
    files are found under it by stem, so the directory may be moved)."""
    record = {
        "format": PLAN_RECORD_FORMAT,
        "name": plan.name,
        "sweep_file": str(plan.source),
        "working_directory": os.getcwd(),
        "directory": str(plan.directory),
        "parameters": list(plan.values),
        "scenes": [{"stem": s.stem, "index": s.index, "values": s.values, "scene_file": str(s.scene_file),
                    "result_file": str(s.result_file)} for s in scenes],
    }
    text = json.dumps(record, indent=1) + "\n"
    path = plan.plan_record_file()
    if path.is_file() and path.read_text(encoding="utf-8") == text:
        return
    with _atomic(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


# ---------------------------------------------------------------------------------------
# running


def _scalar_attributes(attrs, prefix: str = "") -> dict[str, object]:
    """Scalar attributes as Python values (strings decoded), names prefixed."""
    out = {}
    for key, value in attrs.items():
        value = np.asarray(value)
        if value.ndim != 0:
            continue
        item = value.item()
        out[prefix + key] = item.decode() if isinstance(item, bytes) else item
    return out


#: Root attributes of a result file that a summary row shows (its provenance).
_ROOT_COLUMNS = ("layercontact_version", "layercontact_build")


def _result_columns(result_file: Path) -> dict[str, object]:
    """Every scalar attribute of ``/results`` and of ``/companion/results``
    (``companion_`` prefix) of a result file, of ``/leakage`` (``leakage_``, with the
    companion's ``companion_leakage_``) where the scene asked for the leakage, the version and build that wrote it, and
    the provenance fields of the run record where the file holds them itself (a result
    file that records its host and Slurm ids is believed over the run record)."""
    import h5py

    with h5py.File(result_file, "r") as f:
        columns = _scalar_attributes(f["results"].attrs)
        if "companion/results" in f:
            columns.update(_scalar_attributes(f["companion/results"].attrs, "companion_"))
        # the Reynolds leakage, where the scene asked for it (&output leakage)
        for group, prefix in (("leakage", "leakage_"), ("companion/leakage", "companion_leakage_")):
            if group in f:
                columns.update(_scalar_attributes(f[group].attrs, prefix))
        # (the units of the attributes are a text about them, not a result)
        for prefix in ("", "companion_", "leakage_", "companion_leakage_"):
            columns.pop(f"{prefix}units", None)
        root = _scalar_attributes(f.attrs)
    columns.update({name: root.get(name) for name in _ROOT_COLUMNS})
    for name in provenance.PROVENANCE_FIELDS:
        if name in root:  # @host and, under Slurm, @slurm_*_id (job ids as text: made integers)
            value = root[name]
            columns[name] = int(value) if name.startswith("slurm_") and str(value).isdigit() else value
    return columns


def _outcome(columns: dict[str, object]) -> dict[str, object]:
    """Add the ``error`` column: empty for a converged run, else why not."""
    failed = [prefix for prefix in ("", "companion_") if columns.get(f"{prefix}converged", 1) == 0]
    if failed:
        what = "companion run" if failed[0] else "solver"
        residual = columns.get(f"{failed[0]}residual", float("nan"))
        return {**columns, "error": f"{what} did not converge (residual {residual:.3e})"}
    return {**columns, "error": ""}


def _failure(message: str) -> dict[str, object]:
    return {"converged": 0, "error": message}


def temporary_results(results: Path, stem: str) -> list[Path]:
    """The temporary files of a scene's result: the program writes ``STEM.h5.HOST.PID.tmp``
    and moves it to ``STEM.h5`` when complete."""
    return [p for p in results.glob(f"{stem}.h5.*tmp") if p.name.endswith(".tmp")]


def _writer_is_gone(path: Path, stem: str) -> bool:
    """True if the temporary result ``STEM.h5.HOST.PID.tmp`` was left by a run of this host
    that has ended (killed while writing), or has a name no run writes now (``STEM.h5.tmp``
    of earlier versions); a run elsewhere, or still alive, may be writing it."""
    writer = path.name[len(f"{stem}.h5.") :].removesuffix(".tmp")
    host, _, pid = writer.rpartition(".")
    if not host or not pid.isdigit():
        return True
    if host != socket.gethostname():
        return False
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # another user's process: alive
        return False
    return False


def stale_temporary_results(results: Path, stem: str) -> list[Path]:
    """The temporary files of a scene's result that killed runs of this host left (those of
    runs still writing, here or on another host, are not stale)."""
    return [p for p in temporary_results(results, stem) if _writer_is_gone(p, stem)]


@contextmanager
def _scene_lock(record_file: Path) -> Iterator[None]:
    """Hold ``runs/.STEM.lock`` while the scene runs: two sweeps of one directory run a
    scene one after the other (the second finds its result), never at once."""
    lock_file = record_file.with_name(f".{record_file.stem}.lock")
    lock_file.parent.mkdir(parents=True, exist_ok=True)
    with open(lock_file, "a") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX)
        except OSError:  # a parallel file system mounted without locks: go on unlocked
            yield
            return
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def check_ranks_per_scene(plan: SweepPlan, ranks: object) -> int:
    """The MPI ranks each scene of ``plan`` runs on (``--ranks-per-scene``), checked: an
    integer >= 1, and 1 for line scenes (a line is solved on one process) or for a build
    without MPI.

    Raises
    ------
    ValueError
        Naming the option, the value and what is allowed.
    """
    if isinstance(ranks, bool) or not isinstance(ranks, int) or ranks < 1:
        raise ValueError(f"--ranks-per-scene = {ranks!r} is not allowed; allowed: an integer >= 1")
    scene = plan.base.get("scene", {})
    geometry = str(scene.get("geometry", "line")).strip().lower()
    if ranks > 1 and geometry != "areal":
        raise ValueError(
            f"--ranks-per-scene = {ranks} is not allowed for the sweep {plan.source}: its scenes are "
            f"lines (&scene geometry = '{geometry}'), which run on one process; allowed: 1 (several ranks "
            "share the rows of an areal scene)"
        )
    if ranks > 1 and not native.core.py_mpi_available():
        raise ValueError(
            f"--ranks-per-scene = {ranks} is not allowed: this build of layercontact has no MPI (meson option "
            "'mpi': MPI for Fortran or FFTW-MPI not found); allowed: 1, or a build with MPI (docs/clusters.md)"
        )
    return ranks


def mpi_command(ranks: int) -> list[str]:
    """The start of the command line that runs one scene on ``ranks`` MPI ranks here:
    ``mpirun -n K --bind-to none`` (several scenes run at once: no rank is pinned to a core
    another scene's rank has) and the installed ``layercontact`` executable.

    Raises
    ------
    ValueError
        When mpirun or the executable is not found.
    """
    from .slurm import default_executable

    mpirun = shutil.which("mpirun")
    executable = default_executable()
    if mpirun is None or executable is None:
        missing = "mpirun" if mpirun is None else "the layercontact executable"
        raise ValueError(f"--ranks-per-scene = {ranks} runs each scene under mpirun, but {missing} is not "
                         "found on PATH; allowed: 1, or install MPI (Debian: openmpi-bin) and layercontact")
    return [mpirun, "-n", str(ranks), "--bind-to", "none", executable]


def _solve(scene_file: str, result_file: str, record_file: str, launcher: list[str] | None = None,
           environment: dict[str, str] | None = None) -> dict[str, object]:
    """Worker: run one scene file, return its result columns (or its error); its run
    record says it is running, then how it ended. The scene's lock is held throughout: a
    scene that another sweep of the same directory completed meanwhile is not run again,
    and only temporary files of killed runs of this host are removed first (another
    sweep's write in flight is left alone)."""
    with _scene_lock(Path(record_file)):
        if result_matches(Path(result_file), Path(scene_file).read_text()):
            return _outcome(_result_columns(Path(result_file)))
        for left in stale_temporary_results(Path(result_file).parent, Path(scene_file).stem):
            left.unlink(missing_ok=True)
        return _run_scene(scene_file, result_file, record_file, launcher, environment)


def _run_scene(scene_file: str, result_file: str, record_file: str, launcher: list[str] | None = None,
               environment: dict[str, str] | None = None) -> dict[str, object]:
    """Run one scene file with its run record (see :func:`_solve`): in this process, or,
    with a ``launcher`` (:func:`mpi_command`), by the executable on several MPI ranks, in
    the sweep's ``environment``."""
    record = provenance.start_record(Path(scene_file).stem)
    provenance.write_record(Path(record_file), record)
    start = time.monotonic()
    try:
        if launcher:
            code = _launch(launcher, scene_file, environment)
        else:
            run_to_file(scene_file)
            code = 0
        if code in (0, 3):  # a result file (converged or not)
            outcome = _outcome(_result_columns(Path(result_file)))
            code = 0 if not outcome["error"] else 3
        else:
            outcome = _failure(_launch_failure(launcher or [], code, scene_file))
    except LayercontactError as err:  # reported in the summary, the other scenes go on
        outcome, code = _failure(f"{type(err).__name__}: {err}"), err.code
    except Exception as err:  # same, for a failure outside the library (e.g. reading h5)
        outcome, code = _failure(f"{type(err).__name__}: {err}"), 5
    finished = provenance.finish_record(record, code, time.monotonic() - start, outcome["error"])
    provenance.write_record(Path(record_file), finished)
    return outcome


def _log_file(scene_file: str) -> Path:
    """The executable's output of a scene run under mpirun: DIRECTORY/logs/STEM.log, as a
    Slurm task writes it."""
    return Path(scene_file).parent.parent / "logs" / (Path(scene_file).stem + ".log")


def _launch(launcher: list[str], scene_file: str, environment: dict[str, str] | None) -> int:
    """Run the executable on a scene under ``launcher`` in ``environment`` (the sweep's:
    a worker started by a fork server has the environment of that server's start); its
    exit code (the executable's: 0 converged, 3 not converged, 2 bad input, 4 I/O, 5
    internal)."""
    log = _log_file(scene_file)
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        return subprocess.run([*launcher, scene_file], stdout=out, stderr=subprocess.STDOUT,
                              env=environment).returncode


def _launch_failure(launcher: list[str], code: int, scene_file: str) -> str:
    """The error of a scene whose launched run failed: the command, its exit code and the
    last lines of its log."""
    try:
        tail = _log_file(scene_file).read_text(errors="replace").strip().splitlines()[-3:]
    except OSError:
        tail = []
    return f"{' '.join(launcher[:3])}: exit code {code}" + (": " + " | ".join(tail) if tail else "")


def result_matches(result_file: Path, text: str) -> bool:
    """True if ``result_file`` is a readable result made from the namelist ``text`` (a
    killed run leaves no result file, only a temporary ``RESULT.HOST.PID.tmp``: that is
    not a result)."""
    import h5py

    try:
        with h5py.File(result_file, "r") as f:
            stored = f["input/namelist"][()]
    except (OSError, KeyError):
        return False
    return (stored.decode() if isinstance(stored, bytes) else str(stored)) == text


def result_outcome(result_file: Path) -> dict[str, object]:
    """The summary columns of a complete result file: its attributes and ``error``
    (empty if it converged)."""
    return _outcome(_result_columns(result_file))


def _is_complete(scene: Scene) -> bool:
    """True if the scene's result file is readable and was made from the same text."""
    return result_matches(scene.result_file, scene.text)


def _record_file(scene: Scene) -> Path:
    """The scene's run record, ``DIRECTORY/runs/STEM.json``."""
    return provenance.record_file(scene.scene_file.parent.parent, scene.stem)


def allocated_cpus() -> int:
    """The CPUs this process may use: its affinity mask (``taskset``, the cpuset a batch
    system confines a job to), bounded inside a Slurm job by ``SLURM_CPUS_PER_TASK`` or,
    without it, ``SLURM_CPUS_ON_NODE`` (a cluster without CPU binding leaves the mask at
    the whole node, so the mask alone would oversubscribe the allocation).

    Returns
    -------
    int
        At least 1.
    """
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # no affinity on this platform
        cpus = os.cpu_count() or 1
    in_job = "SLURM_JOB_ID" in os.environ
    for variable in ("SLURM_CPUS_PER_TASK", "SLURM_CPUS_ON_NODE"):
        value = os.environ.get(variable, "")
        # SLURM_CPUS_ON_NODE may be left in a login shell's environment: trust it in a job only
        if value.isdigit() and int(value) > 0 and (variable == "SLURM_CPUS_PER_TASK" or in_job):
            cpus = min(cpus, int(value))
            break
    return max(1, cpus)


def _pool_context() -> multiprocessing.context.BaseContext:
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _start_worker(directory: str, sweep_pid: int, threads: int) -> None:
    """A worker runs in the caller's working directory (a forkserver keeps its own),
    leaves Ctrl-C to the sweep's process (which ends the scenes in flight and stops),
    and ends when that process is gone (killed with SIGKILL, it cannot stop its workers).
    On Ctrl-C the sweep's process ends its workers with SIGTERM, whose default action ends
    one at once, inside the library too. Its scenes' solves take ``threads`` threads where
    ``&solver threads`` is not given and the sweep's environment sets no
    ``OMP_NUM_THREADS``: the workers share the CPUs."""
    os.chdir(directory)
    os.environ.setdefault("OMP_NUM_THREADS", str(threads))
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)

    def watch() -> None:
        while True:
            time.sleep(1.0)
            try:
                os.kill(sweep_pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:  # the pid now belongs to another user's process
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="layercontact-sweep-watch").start()


def _run_pending(
    name: str, pending: list[Scene], total: int, processes: int, progress: bool, ranks: int = 1
) -> dict[int, dict[str, object]]:
    """Run ``pending`` scenes in a process pool, each on ``ranks`` MPI ranks (under
    mpirun when more than 1); outcomes by scene index."""
    from tqdm import tqdm

    outcomes: dict[int, dict[str, object]] = {}
    bar = tqdm(total=total, initial=total - len(pending), desc=name, unit="scene", file=sys.stderr,
               disable=not progress)
    workers = min(processes, len(pending))
    threads = max(1, len(os.sched_getaffinity(0)) // (workers * ranks))
    launcher = mpi_command(ranks) if ranks > 1 else None
    # each rank of a launched scene takes its share of the CPUs as threads
    environment = {**os.environ, "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS", str(threads))} \
        if launcher else None
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=_pool_context(),
                               initializer=_start_worker, initargs=(os.getcwd(), os.getpid(), threads))
    futures = {}
    try:
        futures = {
            pool.submit(_solve, str(s.scene_file), str(s.result_file), str(_record_file(s)), launcher,
                        environment): s
            for s in pending
        }
        for future in as_completed(futures):
            try:
                outcomes[futures[future].index] = future.result()
            except Exception as err:  # a worker died (e.g. killed): report, go on
                outcomes[futures[future].index] = _failure(f"{type(err).__name__}: {err}")
            bar.update()
    except KeyboardInterrupt:
        bar.close()
        # (a scene queued for a worker counts as running too: it has not started, which its
        # run record says)
        running = [s for f, s in futures.items() if f.running()]
        print(f"\nlayercontact: Ctrl-C: stopping the sweep '{name}': ending the scenes in flight (they run "
              "again on resume)", file=sys.stderr, flush=True)
        _stop_workers(pool, running)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        bar.close()
    return outcomes


#: Seconds a worker is given to end on SIGTERM before SIGKILL.
_STOP_GRACE = 0.5


def _stop_workers(pool: ProcessPoolExecutor, running: list[Scene]) -> None:
    """End the pool's workers now (a scene in flight may take hours: Ctrl-C does not wait
    for it), then remove what their scenes left: the temporary result files, and a run record
    that says "running" becomes "interrupted" (the scene has no result: a resume runs it)."""
    # (the executor keeps its worker processes by pid, until it shuts down; it offers no call
    # that ends them)
    workers = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    for worker in workers:
        if worker.is_alive():
            worker.terminate()
    deadline = time.monotonic() + _STOP_GRACE
    for worker in workers:
        worker.join(max(0.0, deadline - time.monotonic()))
        if worker.is_alive():
            worker.kill()
            worker.join(1.0)
    # (the executor's manager thread closes its wake-up pipe once it sees the workers gone;
    # the interpreter's exit wakes every executor through that pipe, so a thread still
    # closing it then races the exit and prints a traceback: let it finish first)
    if manager is not None:
        manager.join(5.0)
    for scene in running:
        for left in stale_temporary_results(scene.result_file.parent, scene.stem):
            left.unlink(missing_ok=True)
        record = provenance.read_record(_record_file(scene))
        if record and record.get("state") == "running" and record.get("host") == socket.gethostname():
            provenance.write_record(_record_file(scene), provenance.finish_record(
                record, 130, 0.0, "interrupted (Ctrl-C); the next run of the sweep runs it again"))


def _resolve_processes(plan: SweepPlan, processes: int | None) -> int:
    chosen = processes if processes is not None else plan.processes
    if chosen is None:
        return allocated_cpus()
    if isinstance(chosen, bool) or not isinstance(chosen, int) or chosen < 1:
        raise ValueError(f"processes = {chosen!r} is not allowed; allowed: an integer >= 1")
    return chosen


def execute(plan: SweepPlan, processes: int | None = None, progress: bool = True,
            dry_run: bool = False, ranks_per_scene: int = 1) -> list[dict[str, object]]:
    """Write and check the scenes of ``plan``, run those without a matching result,
    write the summary. See :func:`sweep`."""
    ranks = check_ranks_per_scene(plan, ranks_per_scene)
    if ranks > 1 and not dry_run:
        mpi_command(ranks)  # mpirun and the executable are there, before anything runs
    # the CPUs are shared by the scenes' ranks: K ranks per scene, CPUs/K scenes at once
    workers = _resolve_processes(plan, processes) if processes is not None or plan.processes is not None \
        else max(1, allocated_cpus() // ranks)
    scenes = write_scenes(plan)
    write_plan_record(plan, scenes)
    if dry_run:
        return [scene.planned_row() for scene in scenes]
    pending = [scene for scene in scenes if not _is_complete(scene)]
    if progress and len(pending) < len(scenes):
        print(f"sweep '{plan.name}': {len(scenes) - len(pending)} of {len(scenes)} scenes already have their "
              f"result (same input): skipped; running {len(pending)}", file=sys.stderr)
    outcomes = _run_pending(plan.name, pending, len(scenes), workers, progress, ranks) if pending else {}
    rows = [_row(scene, outcomes) for scene in scenes]
    write_summary(rows, plan)
    return rows


def _row(scene: Scene, outcomes: dict[int, dict[str, object]]) -> dict[str, object]:
    """The summary row of a scene: its planned columns, then its outcome (just run, or
    read from its existing result file) and its provenance (run record)."""
    if scene.index in outcomes:
        outcome = outcomes[scene.index]
    else:
        outcome = _outcome(_result_columns(scene.result_file))
    return summary_row(scene.planned_row(), outcome, provenance.read_record(_record_file(scene)))


def summary_row(planned: dict[str, object], outcome: dict[str, object],
                record: dict[str, object] | None) -> dict[str, object]:
    """One row of a summary: the planned columns (swept values, file names), the outcome
    (result attributes, ``error``) and the provenance columns of the run record. A swept
    input value wins over a result attribute of the same name (e.g.
    ``normalised_pressure``, recomputed by the library to rounding)."""
    row = dict(planned)
    row.update({key: value for key, value in outcome.items() if key not in row})
    # the provenance columns in one order, whether the result file or the run record
    # gave them (a value in the result file wins)
    for key, value in provenance.provenance_columns(record).items():
        row[key] = row.pop(key) if key in row else value
    row["error"] = row.pop("error", "")  # last, as in the summary files
    return row


def sweep(path: str | os.PathLike, processes: int | None = None, progress: bool = True,
          dry_run: bool = False, max_scenes: int | None = None,
          ranks_per_scene: int = 1) -> list[dict[str, object]]:
    """Run a parameter sweep file (a scene plus a ``&sweep`` group).

    Every scene is written to ``DIRECTORY/scenes/NAME_XXXX.nml`` and checked by the
    library before anything runs. Scenes whose result file exists and was made from the
    same namelist text are not run again (an interrupted sweep resumes); the others run
    in ``processes`` worker processes. The summary is written to
    ``DIRECTORY/NAME_summary.csv`` and ``.h5``.

    Parameters
    ----------
    path : str or os.PathLike
        The sweep file.
    processes : int, optional
        Worker processes; default: ``&sweep processes``, else the CPUs allocated to this
        process (:func:`allocated_cpus`).
    progress : bool
        Show a progress bar on stderr.
    dry_run : bool
        Only write and check the scenes; return the planned rows (swept values and file
        names), solve nothing, write no summary.
    max_scenes : int, optional
        The most scenes allowed (default: ``&sweep max_scenes``, else
        :data:`MAX_SCENES`); a sweep with more is refused before anything is planned.
    ranks_per_scene : int
        MPI ranks of each scene (default 1: solved in the worker process). With K > 1
        every scene runs as ``mpirun -n K --bind-to none layercontact SCENE.nml`` (its
        output in ``DIRECTORY/logs/``), and ``processes`` defaults to the CPUs divided
        by K. Areal scenes only (a line runs on one process).

    Returns
    -------
    list of dict
        One row per scene: the swept values, ``scene_file``, ``result_file``, every
        scalar attribute of ``/results`` and of ``/companion/results`` (``companion_``
        prefix), of ``/leakage`` (``leakage_`` prefix, with ``&output leakage``), the provenance (``layercontact_version``, ``layercontact_build``,
        ``host``, ``slurm_job_id``, ``slurm_array_job_id``, ``slurm_array_task_id``,
        ``started``, ``run_time``) and ``error`` (empty if the scene ran and converged). A swept value is
        the input value; a result attribute of the same name is not repeated. A scene
        that failed has ``converged = 0`` and its message in ``error``.

    Raises
    ------
    ValueError
        A bad ``&sweep`` group (the message names the variable), or more scenes than
        allowed.
    LayercontactError
        A scene the library refuses (the message names the scene file and the variable).
    """
    return execute(read_sweep(path, max_scenes), processes=processes, progress=progress, dry_run=dry_run,
                   ranks_per_scene=ranks_per_scene)


def failed(rows: list[dict[str, object]]) -> list[dict[str, object]]:
    """The rows of scenes that raised or did not converge."""
    return [row for row in rows if row.get("error")]


# ---------------------------------------------------------------------------------------
# summary


def _column_names(rows: list[dict[str, object]]) -> list[str]:
    """Planned columns first (in row order), then the results, the companion, error."""
    head = list(rows[0]) if rows else []
    rest = {key for row in rows for key in row} - set(head) - {"error"}
    own = sorted(k for k in rest if not k.startswith("companion_"))
    companion = sorted(k for k in rest if k.startswith("companion_"))
    return [k for k in head if k != "error"] + own + companion + ["error"]


def _column_array(values: list[object]) -> np.ndarray:
    """A typed column: strings, int64 (all present integers) or float64 (NaN if missing)."""
    present = [v for v in values if v is not None]
    if any(isinstance(v, str) for v in present):
        return np.array(["" if v is None else str(v) for v in values], dtype=str)
    if len(present) == len(values) and all(isinstance(v, (int, np.integer)) for v in present):
        return np.array(values, dtype=np.int64)
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


def summary_columns(rows: list[dict[str, object]]) -> dict[str, np.ndarray]:
    """The rows as typed columns (see :func:`read_summary`)."""
    return {name: _column_array([row.get(name) for row in rows]) for name in _column_names(rows)}


def _cell(value: object) -> str:
    return repr(float(value)) if isinstance(value, (float, np.floating)) else str(value)


def _write_csv(columns: dict[str, np.ndarray], path: Path) -> None:
    with _atomic(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(columns)
        writer.writerows(zip(*([_cell(v) for v in col.tolist()] for col in columns.values())))


def _write_h5(columns: dict[str, np.ndarray], path: Path, name: str, sweep_file: str) -> None:
    import h5py

    with _atomic(path) as tmp:
        with h5py.File(tmp, "w") as f:
            group = f.create_group(SUMMARY_GROUP, track_order=True)
            group.attrs["name"] = name
            group.attrs["sweep_file"] = sweep_file
            for name, col in columns.items():
                if col.dtype.kind == "U":
                    group.create_dataset(name, data=col.astype(object), dtype=h5py.string_dtype("utf-8"))
                else:
                    group.create_dataset(name, data=col)


def write_summary(rows: list[dict[str, object]], plan: SweepPlan) -> None:
    """Write ``NAME_summary.csv`` and ``NAME_summary.h5`` of ``plan`` atomically."""
    write_summary_files(rows, plan.directory, plan.name, str(plan.source))


def write_summary_files(rows: list[dict[str, object]], directory: Path, name: str, sweep_file: str) -> None:
    """Write ``DIRECTORY/NAME_summary.csv`` and ``.h5`` atomically (``sweep_file`` is
    recorded in the HDF5 summary)."""
    columns = summary_columns(rows)
    _write_csv(columns, Path(directory) / f"{name}_summary.csv")
    _write_h5(columns, Path(directory) / f"{name}_summary.h5", name, sweep_file)


def _parse_column(cells: list[str]) -> np.ndarray:
    """A CSV column back to int64, float64 or str (the narrowest that fits every cell)."""
    for parse, dtype in ((int, np.int64), (float, np.float64)):
        try:
            return np.array([parse(c) for c in cells], dtype=dtype)
        except ValueError:
            continue
    return np.array(cells, dtype=str)


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as f:
        header, *body = list(csv.reader(f))
    cells = list(zip(*body)) if body else [() for _ in header]
    return {name: _parse_column(list(col)) for name, col in zip(header, cells)}


def _read_h5(path: Path) -> dict[str, np.ndarray]:
    import h5py

    with h5py.File(path, "r") as f:
        group = f[SUMMARY_GROUP]
        return {
            name: np.array(ds.asstr()[()], dtype=str) if h5py.check_string_dtype(ds.dtype) else ds[()]
            for name, ds in group.items()
        }


def read_summary(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a sweep summary (``NAME_summary.csv`` or ``NAME_summary.h5``).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv`` or ``.h5`` / ``.hdf5`` summary file.

    Returns
    -------
    dict of str to numpy.ndarray
        One array per column, in the file's column order: int64, float64 or str.
    """
    path = Path(path)
    readers = {".csv": _read_csv, ".h5": _read_h5, ".hdf5": _read_h5}
    if path.suffix.lower() not in readers:
        raise ValueError(f"{path}: unknown summary format; expected .csv, .h5 or .hdf5")
    return readers[path.suffix.lower()](path)
