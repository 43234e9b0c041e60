"""Throughput of the seed's Fig. 2(b) sweep at n = 2^14 through ``python -m layercontact sweep``:
worker processes against FFTW OpenMP threads, and the time spent outside the solver.

The sweep is inputs/sweeps/fig2b.nml with ``&scene n = 16384``: h/lambda = 0.16, 5 mu_c
(0.2 .. 1.0) plus the mu_c = 0 scenes that a/a0 is divided by (one per pressure and
realisation, as in the file: cheaper than ``&friction companion``, which would solve the
same frictionless scene once per mu_c), x 20 pressures x 10 realisations = 1200 scenes
(1000 with friction + 200 frictionless), tol 1e-10. Every variant runs the whole sweep from
scratch in a temporary directory (deleted at the end; nothing is written in the repository):

  (a) processes = 2, threads = 1       (.venv, as shipped)
  (b) processes = 1, threads = 1       (.venv)
  (c) processes = 1, &solver threads = 2 (FFTW OpenMP build)
  (d) as (a) with OPENBLAS_NUM_THREADS=1
  (e) as (c) with OPENBLAS_NUM_THREADS=1
  optional: (f) as (b) with OPENBLAS_NUM_THREADS=1; (g) as (e) with OMP_WAIT_POLICY=passive

Why OPENBLAS_NUM_THREADS: the library's LAPACK is Debian's OpenBLAS (openblas-pthread).
A least-squares call (dgelsd) on an n x (<= 12) matrix in the Anderson mixing step would
run on as many threads as there are cores, spinning while waiting (a single-process solve
burns ~1.8 cores, and (d) is faster than (a)). The mixing step solves a small Gram system,
and (d) checks that nothing threaded is left (measured: no gain).

(c), (e) and (g) need a second venv built with the meson option ``openmp`` (docs/namelist.md: &solver
threads), e.g. ``--build-openmp`` or by hand::

    python3 -m venv build/venv-openmp
    build/venv-openmp/bin/pip install . -Csetup-args=-Dopenmp=enabled

(``build/`` is git-ignored.) Without it they are skipped.

Then the same run's overheads: "solver" is the sum of the ``wall_time`` every result file
holds (``/results@wall_time``: building the operator and solving, not the observables);
"outside" is worker-seconds (wall x workers) minus that. A sample of scenes is then run
in this process, step by step, to split the per-scene overhead (Fortran ``py_run``: namelist,
profile, solve, observables, HDF5 write; the read-back in ``layercontact.run``, which the
sweep worker skips; the
summary columns the sweep worker reads again), and the fixed costs of the sweep command
(writing and checking the scene files; a resumed run with every result complete).

    .venv/bin/python bench/sweep_throughput.py [--quick] [--variants a b c d e f g] [--build-openmp]

``--quick``: 2 realisations (240 scenes) instead of 10. All numbers are measured in this
run; the machine is shared, so each variant first waits (``--wait``) until the other
processes are quiet, and the CPU time they used during the variant is printed (/proc/stat
busy time minus this sweep's process tree): a variant with a large value there was slowed.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import f90nml
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SWEEP_FILE = ROOT / "inputs" / "sweeps" / "fig2b.nml"
DEFAULT_PYTHON = ROOT / ".venv" / "bin" / "python"
OPENMP_VENV = ROOT / "build" / "venv-openmp"
N = 2**14

#: name: (description, which python, processes, threads, extra environment)
ONE_BLAS = {"OPENBLAS_NUM_THREADS": "1"}
VARIANTS = {
    "a": ("processes = 2", "default", 2, 1, {}),
    "b": ("processes = 1", "default", 1, 1, {}),
    "c": ("processes = 1, threads = 2 (OpenMP build)", "openmp", 1, 2, {}),
    "d": ("processes = 2, OPENBLAS_NUM_THREADS=1", "default", 2, 1, ONE_BLAS),
    "e": ("processes = 1, threads = 2 (OpenMP build), OPENBLAS_NUM_THREADS=1", "openmp", 1, 2, ONE_BLAS),
    "f": ("processes = 1, OPENBLAS_NUM_THREADS=1", "default", 1, 1, ONE_BLAS),
    "g": ("processes = 1, threads = 2 (OpenMP build), OMP_WAIT_POLICY=passive, OPENBLAS_NUM_THREADS=1",
          "openmp", 1, 2, {**ONE_BLAS, "OMP_WAIT_POLICY": "passive"}),
}
DEFAULT_VARIANTS = ["a", "b", "c", "d", "e"]


def build_openmp() -> None:
    """The second venv with FFTW's OpenMP threads (meson option openmp)."""
    python = os.environ.get("PYTHON", "python3")
    if not (OPENMP_VENV / "bin" / "python").exists():
        subprocess.run([python, "-m", "venv", str(OPENMP_VENV)], check=True)
        subprocess.run([str(OPENMP_VENV / "bin" / "pip"), "install", "-q", "--upgrade", "pip"], check=True)
    pip = str(OPENMP_VENV / "bin" / "pip")
    subprocess.run([pip, "install", "-q", str(ROOT), "-Csetup-args=-Dopenmp=enabled"], check=True)


def write_sweep(directory: Path, name: str, realisations: int, processes: int, threads: int) -> Path:
    """fig2b.nml with n = 2^14, the given processes/threads, results under ``directory``."""
    nml = f90nml.read(SWEEP_FILE)
    nml["scene"]["n"] = N
    nml.setdefault("solver", {})["threads"] = threads
    nml["sweep"]["name"] = name
    nml["sweep"]["directory"] = str(directory / "out")
    nml["sweep"]["realisations"] = realisations
    nml["sweep"]["processes"] = processes
    path = directory / f"{name}.nml"
    nml.write(path, force=True)
    return path


def busy_seconds() -> float:
    """CPU-seconds all processes on the machine have used (/proc/stat, since boot)."""
    with open("/proc/stat") as f:
        fields = [int(v) for v in f.readline().split()[1:]]
    idle = fields[3] + fields[4]   # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def wait_for_quiet(limit: float) -> float:
    """Wait (at most ``limit`` seconds) until the machine's other processes use less than a
    fifth of a core over 3 s; returns the seconds waited. This machine is shared: a variant
    run while someone else's job holds a core can take twice as long."""
    start = time.perf_counter()
    while time.perf_counter() - start < limit:
        busy = busy_seconds()
        time.sleep(3.0)
        if busy_seconds() - busy < 0.6:
            break
    return time.perf_counter() - start


def process_table() -> dict[int, tuple[int, float]]:
    """pid -> (parent pid, CPU-seconds used so far) of every process (/proc/PID/stat)."""
    tick = os.sysconf("SC_CLK_TCK")
    table = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                after = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        table[int(entry)] = (int(after[1]), (int(after[11]) + int(after[12])) / tick)
    return table


def run_sweep(python: Path, sweep_file: Path, env_extra: dict[str, str]) -> tuple[float, float, float]:
    """Wall time of ``python -m layercontact sweep FILE`` in a fresh interpreter, the CPU
    time of its process tree (the command, its forkserver and workers: polled every 0.1 s,
    the last tenth of a second of a worker may be missed) and the CPU time the rest of the
    machine used meanwhile (other users of this shared machine slow every variant)."""
    env = {**os.environ, **env_extra}
    busy = busy_seconds()
    start = time.perf_counter()
    proc = subprocess.Popen([str(python), "-m", "layercontact", "sweep", str(sweep_file), "--no-progress"],
                            cwd=sweep_file.parent, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    tree = {proc.pid}
    used: dict[int, float] = {}
    while proc.poll() is None:
        table = process_table()
        grown = True
        while grown:
            new = {pid for pid, (parent, _) in table.items() if parent in tree and pid not in tree}
            tree |= new
            grown = bool(new)
        used.update({pid: table[pid][1] for pid in tree if pid in table})
        time.sleep(0.1)
    out, err = proc.communicate()
    seconds = time.perf_counter() - start
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    used[proc.pid] = max(used.get(proc.pid, 0.0), usage.ru_utime + usage.ru_stime - run_sweep.reaped)
    run_sweep.reaped = usage.ru_utime + usage.ru_stime
    own = sum(used.values())
    foreign = max(busy_seconds() - busy - own, 0.0)
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"sweep failed ({proc.returncode}):\n{out}\n{err}")
    return seconds, own, foreign


run_sweep.reaped = 0.0


def summary(directory: Path, name: str) -> dict[str, np.ndarray]:
    from layercontact.sweeps.sweep import read_summary

    return read_summary(directory / "out" / f"{name}_summary.h5")


def solver_seconds(cols: dict[str, np.ndarray]) -> np.ndarray:
    """Per-scene solver time (main run plus companion, if any) from the result files."""
    total = np.asarray(cols["wall_time"], dtype=float)
    if "companion_wall_time" in cols:
        total = total + np.nan_to_num(np.asarray(cols["companion_wall_time"], dtype=float))
    return total


def per_scene_steps(directory: Path, name: str, sample: int) -> dict[str, float]:
    """Mean seconds per scene of each step a sweep worker does (sweep._solve: api.run, then
    sweep._result_columns), on ``sample`` scenes spread over the sweep, run again here one at
    a time into a scratch directory."""
    import h5py

    import layercontact as lc
    from layercontact.native import core as _core
    from layercontact.sweeps.sweep import _result_columns

    scenes = sorted((directory / "out" / "scenes").glob(f"{name}_*.nml"))
    picks = [scenes[i] for i in np.linspace(0, len(scenes) - 1, sample).round().astype(int)]
    scratch = directory / "steps"
    scratch.mkdir()
    run = solver = profile = read_back = columns = 0.0
    for k, scene in enumerate(picks):
        nml = f90nml.read(scene)
        out = scratch / f"{k}.h5"
        nml["output"]["file"] = str(out)
        local = scratch / f"{k}.nml"
        nml.write(local, force=True)
        t0 = time.perf_counter()
        _, _, stat, errmsg = _core.py_run(str(local), 0, -1)
        t1 = time.perf_counter()
        lc.read_result(out)
        t2 = time.perf_counter()
        _result_columns(out)
        t3 = time.perf_counter()
        p = nml["profile"]
        lc.self_affine_profile(N, p["hurst"], seed=p["seed"], short_wavelength=p["short_wavelength"],
                               rms_gradient=p["rms_gradient"])
        t4 = time.perf_counter()
        if stat:
            raise RuntimeError(errmsg)
        with h5py.File(out, "r") as f:
            solver += float(f["results"].attrs["wall_time"])
        run += t1 - t0
        read_back += t2 - t1
        columns += t3 - t2
        profile += t4 - t3
    steps = {
        "py_run (Fortran: the whole scene, as the executable)": run,
        "- solver (/results@wall_time)": solver,
        "- profile generation (timed alone)": profile,
        "- the rest: namelist, observables, HDF5 write": run - solver - profile,
        "read-back of the whole result in layercontact.run (the sweep worker skips it)": read_back,
        "sweep._result_columns (opens the result again)": columns,
        "outside the solver, total (sweep worker)": run - solver + columns,
    }
    return {key: value / len(picks) for key, value in steps.items()}


def fixed_costs(directory: Path, name: str, python: Path) -> dict[str, float]:
    """The sweep command's costs that do not scale with the solves: writing and checking
    every scene file (a dry run into a fresh directory) and a resumed run of the finished
    sweep (interpreter start, scene check, completeness check of every result, summary)."""
    from layercontact.sweeps.sweep import execute, read_sweep

    sweep_file = directory / f"{name}.nml"
    plan = read_sweep(sweep_file)
    dry = dataclasses.replace(plan, directory=directory / "dry")
    t0 = time.perf_counter()
    execute(dry, progress=False, dry_run=True)
    dry_seconds = time.perf_counter() - t0
    resume_seconds = run_sweep(python, sweep_file, {})[0]
    return {"write + check scene files (dry run)": dry_seconds,
            "resumed run, all complete (whole command)": resume_seconds}


def variant_table(rows: list[tuple], realisations: int) -> None:
    print(f"Fig. 2(b) sweep, n = {N}, h/lambda = 0.16, tol 1e-10, {realisations} realisations: "
          f"5 mu_c (0.2..1) + mu_c = 0 references, 20 pressures; {os.cpu_count()} cores\n")
    print("| variant | scenes (failed) | wall (s) | scenes/s | CPU (s) | other processes' CPU (s) "
          "| solver wall_time sum (s) | mean solver time/scene (ms) | worker-s/scene (ms) "
          "| outside the solver | wall vs first |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    first = rows[0]["wall"] if rows else None
    for r in rows:
        count, solver = len(r["solver"]), r["solver"]
        worker = r["wall"] * r["processes"]
        print(f"| ({r['key']}) {r['label']} | {count} ({r['failed']}) | {r['wall']:.1f} "
              f"| {count / r['wall']:.1f} | {r['own']:.1f} | {r['foreign']:.1f} | {solver.sum():.1f} "
              f"| {solver.mean() * 1e3:.1f} "
              f"| {worker / count * 1e3:.1f} | {1.0 - solver.sum() / worker:.0%} | {r['wall'] / first:.2f} |")


def friction_table(row: dict) -> None:
    cols, solver = row["cols"], row["solver"]
    print(f"\nSolver time per scene by mu_c, variant ({row['key']}):\n")
    print("| mu_c | scenes | mean wall_time (ms) | max (ms) | mean CG it. | mean outer it. |")
    print("|---:|---:|---:|---:|---:|---:|")
    for mu in np.unique(cols["friction"]):
        sel = cols["friction"] == mu
        print(f"| {mu:g} | {sel.sum()} | {solver[sel].mean() * 1e3:.1f} | {solver[sel].max() * 1e3:.1f} "
              f"| {cols['iterations'][sel].mean():.0f} | {cols['outer_iterations'][sel].mean():.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 realisations (240 scenes) instead of 10")
    parser.add_argument("--variants", nargs="+", default=DEFAULT_VARIANTS, choices=list(VARIANTS),
                        help=f"default: {' '.join(DEFAULT_VARIANTS)}")
    parser.add_argument("--build-openmp", action="store_true",
                        help=f"build {OPENMP_VENV.relative_to(ROOT)} first (openmp build of this checkout)")
    parser.add_argument("--sample", type=int, default=24, help="scenes timed step by step (default 24)")
    parser.add_argument("--wait", type=float, default=300.0,
                        help="before each variant, wait up to this many seconds for the other processes "
                             "on the machine to go quiet (default 300; 0: do not wait)")
    args = parser.parse_args()
    realisations = 2 if args.quick else 10
    if args.build_openmp:
        build_openmp()
    pythons = {"default": DEFAULT_PYTHON, "openmp": OPENMP_VENV / "bin" / "python"}

    tmp = Path(tempfile.mkdtemp(prefix="lc_sweep_throughput_"))
    rows, skipped = [], []
    try:
        for key in args.variants:
            label, which, processes, threads, env = VARIANTS[key]
            if not pythons[which].exists():
                skipped.append(f"({key}) {label}: no {pythons[which]} (see --build-openmp)")
                continue
            directory = tmp / key
            directory.mkdir()
            sweep_file = write_sweep(directory, f"fig2b_{key}", realisations, processes, threads)
            waited = wait_for_quiet(args.wait)
            wall, own, foreign = run_sweep(pythons[which], sweep_file, env)
            cols = summary(directory, f"fig2b_{key}")
            rows.append(dict(key=key, label=label, which=which, processes=processes, directory=directory,
                             cols=cols, solver=solver_seconds(cols), own=own, foreign=foreign, wall=wall,
                             failed=int(np.count_nonzero(cols["converged"] != 1))))
            print(f"({key}) {label}: {wall:.1f} s (waited {waited:.0f} s for a quiet machine; other "
                  f"processes {foreign:.1f} CPU-s)", file=sys.stderr, flush=True)

        variant_table(rows, realisations)
        for line in skipped:
            print(f"\nskipped: {line}")
        default = next((r for r in rows if r["which"] == "default"), None)
        if default is None:
            return
        friction_table(default)
        name = f"fig2b_{default['key']}"
        steps = per_scene_steps(default["directory"], name, args.sample)
        print(f"\nOne worker's steps per scene: {args.sample} scenes of ({default['key']}) run again one at "
              "a time in this process (mean):\n")
        print("| step | ms/scene |")
        print("|---|---:|")
        for step, seconds in steps.items():
            print(f"| {step} | {seconds * 1e3:.2f} |")
        fixed = fixed_costs(default["directory"], name, DEFAULT_PYTHON)
        print(f"\nFixed costs of the sweep command ({len(default['solver'])} scenes):\n")
        print("| step | s |")
        print("|---|---:|")
        for step, seconds in fixed.items():
            print(f"| {step} | {seconds:.2f} |")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
