"""Sweeps on clusters (layercontact.sweeps: slurm, submit, status, provenance): the job
script written from the &sweep group and the command line, bad options refused by name,
the script's tasks run by hand (a failing scene and a killed task lose nothing else, run
records hold the provenance), status and collect of local and batch sweeps, local workers
that follow the CPUs allocated, and a real single-node Slurm: a job array with one task
cancelled mid-way, resubmitted, collected."""

from __future__ import annotations

import json
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import layercontact as lc
from layercontact.sweeps import provenance, slurm
from layercontact.sweeps import status as sweep_status
from layercontact.sweeps import sweep as sweep_module
from layercontact.__main__ import main

from areal_sweep import write_areal_sweep


BASE = """\
&scene
   n = 256
/
&layer
   thickness = 0.16
   poisson = 0.5
/
&friction
   coefficient = 0.0
/
&profile
   short_wavelength = 0.03125
/
&loading
   normalised_pressure = 1.0
/
"""
#: 6 scenes, 2 per array task: tasks 0, 1, 2 run (s_0000, s_0001), (s_0002, s_0003), (s_0004, s_0005)
LISTS = " friction = 0.0, 0.5\n seed = 1, 2, 3\n slurm_scenes_per_task = 2\n"
#: Longest wait for the test Slurm (it runs these 6 small scenes in a few seconds).
SLURM_TIMEOUT = 60


def write_sweep(directory: Path, settings: str = "", lists: str = LISTS, name: str = "s") -> Path:
    """A sweep file; its directory is out/NAME unless `settings` gives one (a variable is
    assigned once in &sweep)."""
    path = directory / f"{name}.nml"
    own = "" if "directory =" in settings else f" directory = 'out/{name}'\n"
    path.write_text(BASE + f"&sweep\n{own}{lists}{settings}/\n")
    return path


def slow_executable(directory: Path, stem: str, seconds: int = 60) -> Path:
    """A stand-in for layercontact that holds scene ``stem`` for ``seconds`` (so its task
    can be stopped mid-way) and runs the real program for the others."""
    wrapper = directory / "slow_layercontact"
    wrapper.write_text(
        f'#!/bin/bash\ncase "$1" in *{stem}.nml) sleep {seconds} ;; esac\n'
        f'exec {slurm.default_executable()} "$@"\n'
    )
    wrapper.chmod(0o755)
    return wrapper


def failing_executable(directory: Path, stem: str) -> Path:
    """A stand-in for layercontact that fails scene ``stem`` as the program does when it
    cannot write (exit 4, an error line) and runs the real program for the others."""
    wrapper = directory / "failing_layercontact"
    wrapper.write_text(
        f'#!/bin/bash\ncase "$1" in *{stem}.nml)\n'
        "  echo \"layercontact: error: cannot create result file 'x.h5.tmp'\" >&2; exit 4 ;;\nesac\n"
        f'exec {slurm.default_executable()} "$@"\n'
    )
    wrapper.chmod(0o755)
    return wrapper


def run_task(script: Path, task: int, job: int = 77, **popen) -> subprocess.Popen:
    """Start array task ``task`` of ``script`` by hand, as Slurm would (its environment)."""
    env = {
        **os.environ,
        "SLURM_ARRAY_TASK_ID": str(task),
        "SLURM_ARRAY_JOB_ID": str(job),
        "SLURM_JOB_ID": str(job + 1 + task),
    }
    return subprocess.Popen(
        ["bash", str(script)], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **popen
    )


def wait_for(condition, what: str, timeout: float = SLURM_TIMEOUT):
    """Poll ``condition()`` until it is true; fail naming ``what`` after ``timeout`` s."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.2)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


def stems(*numbers: int) -> list[str]:
    """``['s_0001', 's_0003']`` for 1, 3."""
    return [f"s_{number:04d}" for number in numbers]


def record(out: Path, stem: str) -> dict:
    return provenance.read_record(provenance.record_file(out, stem)) or {}


def states(out: Path) -> dict[str, str]:
    return {s.stem: s.state for s in sweep_status.sweep_status(out).states}


def temporary_files(root: Path) -> list[Path]:
    return [p for p in root.rglob("*") if p.name.endswith(".tmp")]


# ---------------------------------------------------------------------------------------
# local workers


def test_local_workers_follow_the_cpus_allocated(tmp_path, monkeypatch):
    # the affinity mask (taskset, a batch system's cpuset), not the machine's CPU count
    pinned = subprocess.run(
        [
            "taskset",
            "-c",
            "0",
            sys.executable,
            "-c",
            "from layercontact.sweeps.sweep import allocated_cpus; print(allocated_cpus())",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert pinned.stdout.strip() == "1"
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 2, 3})
    for variable in ("SLURM_CPUS_PER_TASK", "SLURM_CPUS_ON_NODE", "SLURM_JOB_ID"):
        monkeypatch.delenv(variable, raising=False)
    assert sweep_module.allocated_cpus() == 4
    monkeypatch.setenv("SLURM_CPUS_ON_NODE", "2")  # outside a job: not ours
    assert sweep_module.allocated_cpus() == 4
    monkeypatch.setenv("SLURM_JOB_ID", "12")  # inside an allocation without -c
    assert sweep_module.allocated_cpus() == 2
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", "3")  # -c 3 wins over the node's count
    assert sweep_module.allocated_cpus() == 3
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {5})
    assert sweep_module.allocated_cpus() == 1  # never more than the mask
    monkeypatch.chdir(tmp_path)
    plan = sweep_module.read_sweep(write_sweep(tmp_path, lists=" friction = 0.0\n"))
    assert sweep_module._resolve_processes(plan, None) == 1


# ---------------------------------------------------------------------------------------
# the job script


def test_dry_run_writes_the_job_script_from_the_sweep_group_and_the_command_line(
    tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    settings = (
        " slurm_partition = 'short'\n slurm_account = 'proj7'\n slurm_time = '0:30:00'\n"
        " slurm_memory = '2G'\n slurm_array_limit = 2\n"
        " slurm_sbatch_lines = '--qos=low', '#SBATCH --nice=5'\n"
        " slurm_setup_lines = 'module load hdf5', 'export LC_MARK=1'\n"
    )
    path = write_sweep(tmp_path, settings)
    assert (
        main(["sweep", str(path), "--slurm", "--dry-run", "--time", "10", "--sbatch", "constraint=avx2"]) == 0
    )
    out = capsys.readouterr().out
    script = (tmp_path / "out/s/slurm/s_001.sbatch").read_text()
    assert script in out and "nothing submitted" in out
    head = [line.removeprefix("#SBATCH ") for line in script.splitlines() if line.startswith("#SBATCH")]
    assert head == [
        "--job-name=lc-s",
        "--array=0-2%2",
        "--ntasks=1",
        "--cpus-per-task=1",
        f"--chdir={tmp_path}",
        f"--output={tmp_path}/out/s/slurm/s_001_%A_%a.out",
        "--time=10",
        "--mem=2G",
        "--partition=short",
        "--account=proj7",
        "--constraint=avx2",
    ]
    # the command line's --sbatch replaces the file's lines, as every option does
    assert script.index("module load hdf5") < script.index("export LC_MARK=1") < script.index("set -u")
    assert f"executable={slurm.default_executable()}" in script
    assert (tmp_path / "out/s/slurm/s_001.scenes").read_text().split() == stems(*range(6))
    assert subprocess.run(["bash", "-n"], input=script, text=True).returncode == 0
    assert not (tmp_path / "out/s/slurm/s_001.json").exists() and not (tmp_path / "out/s/results").exists()
    assert len(list((tmp_path / "out/s/scenes").glob("*.nml"))) == 6


BAD_OPTIONS = [
    # (&sweep settings, command-line arguments, words the message must contain)
    (" slurm_time = '1h'\n", [], ["&sweep slurm_time: '1h' is not allowed", "D-HH:MM:SS"]),
    ("", ["--time", "90 min"], ["--time: '90 min' is not allowed"]),
    ("", ["--memory", "2X"], ["--memory: '2X' is not allowed", "K, M, G or T"]),
    (" slurm_memory = -1\n", [], ["&sweep slurm_memory: -1 is not allowed"]),
    ("", ["--scenes-per-task", "0"], ["--scenes-per-task: 0 is not allowed; allowed: an integer >= 1"]),
    (
        " slurm_array_limit = 2.5\n",
        [],
        ["&sweep slurm_array_limit: 2.5 is not allowed; allowed: an integer >= 1"],
    ),
    ("", ["--array-limit", "many"], ["--array-limit: 'many' is not allowed"]),
    ("", ["--cpus-per-task", "-1"], ["--cpus-per-task: -1 is not allowed"]),
    ("", ["--partition", "a b"], ["--partition: 'a b' is not allowed", "a Slurm name"]),
    (" slurm_sbatch_lines = '#SBATCH'\n", [], ["&sweep slurm_sbatch_lines: '#SBATCH' is not allowed"]),
    (
        "",
        ["--executable", "/nonexistent/layercontact"],
        ["--executable", "'/nonexistent/layercontact' is not allowed"],
    ),
    (" slurm_partiton = 'x'\n", [], ["&sweep slurm_partiton: unknown variable", "slurm_partition"]),
    ("", ["--processes", "2"], ["--processes applies to a local sweep"]),
]


@pytest.mark.parametrize("settings, arguments, words", BAD_OPTIONS, ids=[w[0] for _, _, w in BAD_OPTIONS])
def test_a_bad_slurm_option_is_refused_naming_it(settings, arguments, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, settings)
    assert main(["sweep", str(path), "--slurm", "--dry-run", *arguments]) == 2
    err = capsys.readouterr().err
    for word in words:
        assert word in err
    assert not (tmp_path / "out/s/slurm").exists()


def test_slurm_options_need_slurm_and_a_fitting_name_and_array(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path)
    assert main(["sweep", str(path), "--partition", "short"]) == 2
    assert "--partition applies only with --slurm" in capsys.readouterr().err
    spaced = write_sweep(tmp_path, " name = 'my sweep'\n", name="t")
    assert main(["sweep", str(spaced), "--slurm", "--dry-run"]) == 2
    assert "&sweep name 'my sweep' is not allowed for a Slurm sweep" in capsys.readouterr().err
    # more array tasks than the cluster allows: the message says how many scenes per task fit
    monkeypatch.setattr(slurm, "max_array_size", lambda: 4)
    assert main(["sweep", str(path), "--slurm", "--dry-run", "--scenes-per-task", "1"]) == 2
    err = capsys.readouterr().err
    assert "--scenes-per-task (&sweep slurm_scenes_per_task): 1 gives 6 array tasks" in err
    assert "MaxArraySize = 4; allowed: scenes per task >= 2" in err


# ---------------------------------------------------------------------------------------
# the tasks of a job script, run by hand


def test_tasks_write_results_and_provenance_as_a_local_sweep(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path)
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    script = tmp_path / "out/s/slurm/s_001.sbatch"
    for task in range(3):
        done = run_task(script, task)
        assert done.wait(timeout=60) == 0, done.stdout.read()
    out = tmp_path / "out/s"
    assert set(states(out).values()) == {"done"}
    rec = record(out, "s_0003")
    assert rec["state"] == "finished" and rec["exit_code"] == 0 and rec["runner"] == "slurm"
    assert (rec["slurm_array_job_id"], rec["slurm_array_task_id"], rec["slurm_job_id"]) == (77, 1, 79)
    assert rec["host"] == os.uname().nodename and rec["wall_time"] > 0 and rec["submission"] == 1
    assert "contact fraction" in (out / "logs/s_0003.log").read_text()

    assert main(["collect", str(out)]) == 0
    batch = lc.read_summary(out / "s_summary.h5")
    local_dir = tmp_path / "local"
    local_dir.mkdir()
    monkeypatch.chdir(local_dir)
    lc.sweep(path, progress=False)
    local = lc.read_summary(local_dir / "out/s/s_summary.h5")
    assert list(batch) == list(local)
    for name in (
        "friction",
        "seed",
        "scene_file",
        "result_file",
        "converged",
        "error",
        "layercontact_version",
    ):
        np.testing.assert_array_equal(batch[name], local[name], err_msg=name)
    # the program is the portable build, the Python extension may be the x86-64-v3 one:
    # the same solution to rounding (tests/test_build.py)
    np.testing.assert_allclose(batch["penetration"], local["penetration"], rtol=1e-6)
    assert batch["slurm_array_task_id"].tolist() == [0, 0, 1, 1, 2, 2]
    assert np.isnan(local["slurm_array_job_id"]).all() and (local["host"] == os.uname().nodename).all()
    assert (batch["run_time"] > 0).all() and (batch["layercontact_version"] == lc.__version__).all()


def test_a_failing_scene_does_not_stop_its_task(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path)
    wrapper = failing_executable(tmp_path, "s_0002")
    assert main(["sweep", str(path), "--slurm", "--dry-run", "--executable", str(wrapper)]) == 0
    task = run_task(tmp_path / "out/s/slurm/s_001.sbatch", 1)
    assert task.wait(timeout=60) == 1  # the task reports a failure to Slurm ...
    out = tmp_path / "out/s"
    assert states(out) == {
        "s_0000": "missing",
        "s_0001": "missing",
        "s_0002": "failed",
        "s_0003": "done",
        "s_0004": "missing",
        "s_0005": "missing",
    }  # ... and ran the scene after it
    capsys.readouterr()
    assert main(["status", str(out)]) == 1
    report = capsys.readouterr().out
    assert (
        "s_0002  (friction = 0.0, seed = 3): exit 4 (I/O failure) in Slurm job 77_1 on "
        f"{os.uname().nodename}: layercontact: error: cannot create result file"
    ) in report
    assert "runs the 5 failed or missing scene(s) again" in report
    # submitting again takes the failed and the missing scenes, not the done one
    # (a dry run is not a submission: the next one replaces its files)
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    assert (out / "slurm/s_001.scenes").read_text().split() == stems(0, 1, 2, 4, 5)


def test_a_killed_task_loses_only_the_scene_it_cut_short(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(
        tmp_path, lists=LISTS.replace("slurm_scenes_per_task = 2", "slurm_scenes_per_task = 3")
    )
    wrapper = slow_executable(tmp_path, "s_0001")
    assert main(["sweep", str(path), "--slurm", "--dry-run", "--executable", str(wrapper)]) == 0
    out = tmp_path / "out/s"
    task = run_task(tmp_path / "out/s/slurm/s_001.sbatch", 0, start_new_session=True)
    wait_for(lambda: record(out, "s_0001").get("state") == "running", "s_0001 to start")
    # a time limit or scancel: SIGTERM to every process of the task (the group here)
    os.killpg(task.pid, signal.SIGTERM)
    assert task.wait(timeout=30) == 128 + signal.SIGTERM
    rec = record(out, "s_0001")
    # "killed" by the task's trap (also when the program died of the signal first and the
    # shell's trap came after `wait`), or "finished" with 143 when it came after the record
    assert rec["state"] in ("killed", "finished") and rec["exit_code"] == 143 and rec["finished"]
    # a write cut short leaves RESULT.tmp: not a result
    (out / "results/s_0001.h5.tmp").write_bytes(b"partial")
    found = sweep_status.sweep_status(out)
    by_stem = {s.stem: s for s in found.states}
    assert [by_stem[s].state for s in ("s_0000", "s_0001", "s_0002")] == ["done", "failed", "missing"]
    assert by_stem["s_0001"].reason.startswith("killed in Slurm job 77_0 on ")
    assert "exit 143 (killed by signal 15, SIGTERM)" in by_stem["s_0001"].reason
    assert "s_0001.h5.tmp left from an interrupted write" in by_stem["s_0001"].reason
    assert by_stem["s_0001"].rerun and by_stem["s_0002"].rerun and not by_stem["s_0000"].rerun

    # SIGKILL (or a node failure) leaves the record at "running": interrupted, runs again
    interrupted = {**record(out, "s_0000"), "scene": "s_0003", "state": "running", "exit_code": None}
    provenance.write_record(provenance.record_file(out, "s_0003"), interrupted)
    reason = sweep_status.scene_states(out, "s", ["s_0003"])["s_0003"].reason
    assert reason.startswith("interrupted in Slurm job 77_0 on") and "without recording an exit" in reason

    # the next submission runs every scene without a result, and replaces RESULT.tmp
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    assert (out / "slurm/s_001.scenes").read_text().split() == stems(1, 2, 3, 4, 5)
    for number in range(2):
        assert run_task(out / "slurm/s_001.sbatch", number, job=90).wait(timeout=60) == 0
    assert set(states(out).values()) == {"done"} and not temporary_files(tmp_path)
    assert (
        record(out, "s_0001")["slurm_array_job_id"] == 90
        and record(out, "s_0000")["slurm_array_job_id"] == 77
    )


def test_a_signal_while_the_task_writes_a_record_leaves_a_readable_record(tmp_path, monkeypatch):
    # the record "running" is in place, but the task's shell is still in its function that
    # writes records (held here in its first `mv`) when SIGTERM comes: the trap's record must not
    # read that function's variables for the loop's
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path)
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    out = tmp_path / "out/s"
    holding = tmp_path / "bin"
    holding.mkdir()
    (holding / "mv").write_text(
        f'#!/bin/bash\n{shutil.which("mv")} "$@" || exit\n'
        f'case "$*" in *s_0000.json) [ -e {holding}/held ] || {{ touch {holding}/held; sleep 60; }} ;; esac\n'
    )
    (holding / "mv").chmod(0o755)
    monkeypatch.setenv("PATH", f"{holding}:{os.environ['PATH']}")
    task = run_task(out / "slurm/s_001.sbatch", 0, start_new_session=True)
    wait_for(lambda: record(out, "s_0000").get("state") == "running", "s_0000 to start")
    os.killpg(task.pid, signal.SIGTERM)
    assert task.wait(timeout=30) == 128 + signal.SIGTERM
    rec = record(out, "s_0000")
    assert rec["state"] == "killed" and rec["exit_code"] == 143
    assert rec["started"] <= rec["finished"] and rec["started"].endswith("Z")
    assert not (out / "runs/s_0001.json").exists()


# ---------------------------------------------------------------------------------------
# status and collect


def test_status_and_collect_of_a_local_sweep(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, lists=" friction = 0.0, 0.5\n seed = 1, 2\n")
    out = tmp_path / "out/s"
    lc.sweep(path, progress=False)
    written = (out / "s_summary.csv").read_text()
    assert main(["status", str(out)]) == 0
    assert "4 scenes: 4 done, 0 failed, 0 running, 0 queued, 0 missing" in capsys.readouterr().out
    # collect writes what the sweep wrote, from the directory alone (here: by the sweep file)
    (out / "s_summary.csv").unlink()
    assert main(["collect", str(path)]) == 0
    assert (out / "s_summary.csv").read_text() == written
    rec = record(out, "s_0002")
    assert rec["runner"] == "local" and rec["exit_code"] == 0 and rec["host"] == os.uname().nodename

    # a local run whose process died (Ctrl-C, OOM killer) and a lost result
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    provenance.write_record(
        provenance.record_file(out, "s_0001"),
        {**rec, "scene": "s_0001", "state": "running", "pid": int(dead.stdout)},
    )
    (out / "results/s_0001.h5").unlink()
    (out / "results/s_0003.h5").unlink()
    provenance.record_file(out, "s_0003").unlink()
    assert main(["collect", str(out)]) == 1
    summary = lc.read_summary(out / "s_summary.csv")
    assert summary["converged"].tolist() == [1, 0, 1, 0]
    assert summary["error"][1].startswith("failed: interrupted on ")
    assert summary["error"][3] == "missing: never run"
    assert np.isnan(summary["penetration"][3])
    # the local sweep runs what is missing, as --slurm would submit it
    lc.sweep(path, progress=False)
    assert main(["status", str(out)]) == 0


def test_status_of_something_that_is_not_a_sweep(tmp_path, capsys):
    assert main(["status", str(tmp_path)]) == 2
    assert f"{tmp_path}: not a sweep directory" in capsys.readouterr().err
    assert main(["collect", str(tmp_path / "nowhere")]) == 2
    assert "no such file or directory" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------
# a real Slurm


def submissions(out: Path) -> list[slurm.Submission]:
    return slurm.read_submissions(out, "s")


def test_a_job_array_survives_a_cancelled_task_and_resubmits_only_what_is_missing(
    slurm_cluster, tmp_path, monkeypatch, capsys
):
    monkeypatch.setenv("SLURM_CONF", str(slurm_cluster))
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, " slurm_memory = '100M'\n slurm_time = '5'\n")
    out = tmp_path / "out/s"
    wrapper = slow_executable(tmp_path, "s_0003")
    assert main(["sweep", str(path), "--slurm", "--executable", str(wrapper), "--array-limit", "2"]) == 0
    assert "submitted Slurm job" in capsys.readouterr().out
    first = submissions(out)[0]
    assert first.scenes == tuple(stems(*range(6))) and first.tasks == 3

    # task 1 runs s_0002, then holds s_0003: cancel it there
    wait_for(lambda: record(out, "s_0003").get("state") == "running", "task 1 to start s_0003")
    assert main(["status", str(out)]) == 1
    assert f"s_0003  (friction = 0.5, seed = 1): in Slurm job {first.job_id}_1 on" in capsys.readouterr().out
    subprocess.run(["scancel", f"{first.job_id}_1"], check=True)
    wait_for(lambda: slurm.active_tasks([first.job_id]) == {}, "the first job to end")
    (out / "results/s_0003.h5.tmp").write_bytes(b"partial")  # as if killed while writing
    found = {s.stem: s for s in sweep_status.sweep_status(out).states}
    assert [s.state for s in found.values()] == ["done", "done", "done", "failed", "done", "done"]
    assert "killed" in found["s_0003"].reason and "CANCELLED" in found["s_0003"].reason

    # resubmitted with the real program: only s_0003 runs again
    assert main(["sweep", str(path), "--slurm"]) == 0
    second = submissions(out)[1]
    assert second.scenes == ("s_0003",)
    wait_for(lambda: sweep_status.sweep_status(out).finished, "the resubmitted scene")
    assert main(["sweep", str(path), "--slurm"]) == 0
    assert "nothing to submit" in capsys.readouterr().out and len(submissions(out)) == 2

    assert main(["collect", str(out)]) == 0
    summary = lc.read_summary(out / "s_summary.h5")
    assert sorted(summary["result_file"]) == [f"out/s/results/s_000{i}.h5" for i in range(6)]  # each once
    assert (summary["converged"] == 1).all() and (summary["error"] == "").all()
    jobs = [second.job_id if i == 3 else first.job_id for i in range(6)]
    assert summary["slurm_array_job_id"].tolist() == jobs
    assert summary["slurm_array_task_id"].tolist() == [0, 0, 1, 0, 2, 2]
    assert (summary["host"] == os.uname().nodename).all() and (summary["run_time"] > 0).all()
    assert (summary["layercontact_version"] == lc.__version__).all() and (
        summary["layercontact_build"] != ""
    ).all()
    assert not temporary_files(tmp_path)
    with open(out / "slurm/s_002.json") as f:
        assert json.load(f)["job_id"] == second.job_id


def test_a_leakage_scene_runs_in_a_slurm_array_task(slurm_cluster, tmp_path, monkeypatch, capsys):
    # the executable alone on the node computes the leakage (hypre starts MPI by itself, no
    # mpirun) and the collected summary carries it
    from test_leakage_core import AREAL

    monkeypatch.setenv("SLURM_CONF", str(slurm_cluster))
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "leak.nml"
    path.write_text(AREAL + "&output\n leakage = .true.\n/\n&sweep\n directory = 'out/leak'\n"
                    " normalised_pressure = 0.1, 0.3\n slurm_memory = '500M'\n slurm_time = '5'\n/\n")
    out = tmp_path / "out/leak"
    assert main(["sweep", str(path), "--slurm"]) == 0
    assert "submitted Slurm job" in capsys.readouterr().out
    wait_for(lambda: sweep_status.sweep_status(out).finished, "the leakage scenes")
    assert main(["collect", str(out)]) == 0
    summary = lc.read_summary(out / "leak_summary.h5")
    assert (summary["error"] == "").all() and (summary["leakage_converged"] == 1).all()
    assert (summary["slurm_array_job_id"] > 0).all()
    # each equals the same scene run here
    for result_file, k in zip(summary["result_file"], summary["leakage_k_eff_x"]):
        gap_result = lc.read_result(tmp_path / result_file)
        ref = lc.reynolds_leakage(gap_result.gap, period=gap_result.period, contact=gap_result.pressure > 0,
                                  method="direct")
        # the task's k_eff meets leakage_tol 1e-6 (an upper bound); 2e-6 leaves the rounding
        # of the direct solve its share
        assert k == pytest.approx(ref.k_eff, rel=2e-6)
    assert summary["leakage_k_eff_x"][0] > summary["leakage_k_eff_x"][1] > 0


# ---------------------------------------------------------------------------------------
# hostile names: nothing from an input reaches a shell as a command (docs/clusters.md)

#: A directory name with a space, both quotes, a command substitution, a variable, a '#'
#: (sbatch's comment) and a '%' (sbatch's filename pattern): legal, and kept as it is.
ODD_DIRECTORY = "it's a \"dir\" $(touch pwned) `touch pwned` $HOME #x 100%"


def pwned(root: Path) -> list[Path]:
    return list(root.rglob("pwned")) + list(Path.cwd().rglob("pwned"))


REFUSED_NAMES = [
    # (sweep settings, command-line arguments, working directory, words of the message)
    (" directory = 'w\ntouch pwned\n'\n", [], "work",
     ["&sweep directory: 'w\\ntouch pwned\\n' is not allowed",
      "allowed: a non-empty string, text without control characters"]),
    (" name = 's\ntouch pwned'\n", [], "work", ["&sweep name: 's\\ntouch pwned' is not allowed"]),
    ("", [], "w\ntouch pwned\n", ["the working directory (submit from another one)", "w\\ntouch pwned\\n'",
                                  "allowed: text without control characters"]),
    (" slurm_setup_lines = 'module load hdf5\ttouch pwned'\n", [], "work",
     ["&sweep slurm_setup_lines: 'module load hdf5\\ttouch pwned' is not allowed",
      "text without control characters"]),
    ("", ["--sbatch", "qos=low\ntouch pwned"], "work",
     ["--sbatch: 'qos=low\\ntouch pwned' is not allowed", "text without control characters"]),
    ("", ["--executable", "/bin/true\ntouch pwned"], "work", ["--executable", "is not allowed"]),
]


@pytest.mark.parametrize("settings, arguments, workdir, words", REFUSED_NAMES,
                         ids=["directory", "name", "working-directory", "setup-line", "sbatch-line",
                              "executable"])
def test_a_control_character_in_a_name_is_refused_before_anything_is_written(
    settings, arguments, workdir, words, tmp_path, monkeypatch, capsys
):
    work = tmp_path / workdir
    work.mkdir()
    monkeypatch.chdir(work)
    path = write_sweep(work, settings)
    assert main(["sweep", str(path), "--slurm", "--dry-run", *arguments]) == 2
    err = capsys.readouterr().err
    for word in words:
        assert word in err, err
    assert not list(work.rglob("*.sbatch")) and not pwned(tmp_path)
    # a local sweep refuses the names that reach its files too
    if settings and "slurm_" not in settings:
        assert main(["sweep", str(path), "--dry-run"]) == 2
        assert words[0] in capsys.readouterr().err


def test_spaces_quotes_and_substitutions_in_paths_stay_paths(tmp_path, monkeypatch):
    """A working directory and a sweep directory with every character a shell would read
    (spaces, quotes, $(...), backquotes, $VAR, #, %): the job script passes bash -n, its
    task runs the scenes and writes their results in those directories, and nothing runs."""
    work = tmp_path / ODD_DIRECTORY
    work.mkdir()
    monkeypatch.chdir(work)
    path = work / "s.nml"
    quoted = ODD_DIRECTORY.replace("'", "''")
    path.write_text(BASE + f"&sweep\n directory = 'out/{quoted}'\n{LISTS}/\n")
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    out = work / "out" / ODD_DIRECTORY
    script = out / "slurm/s_001.sbatch"
    text = script.read_text()
    assert subprocess.run(["bash", "-n", str(script)]).returncode == 0
    task = run_task(script, 0)
    output, _ = task.communicate(timeout=300)
    assert task.returncode == 0, output
    assert (out / "results/s_0000.h5").is_file() and (out / "results/s_0001.h5").is_file()
    assert record(out, "s_0000")["exit_code"] == 0
    assert not pwned(tmp_path)
    # sbatch reads quotes in #SBATCH lines ('...' and "'"), a doubled % as one %
    assert f"#SBATCH --chdir={shlex.quote(str(work))}" in text
    assert "100%%" in text and "_%A_%a.out" in text


def test_sbatch_takes_the_quoted_paths_of_a_hostile_directory(slurm_cluster, tmp_path, monkeypatch, capsys):
    """The real sbatch reads the quoted --chdir and --output: the task runs in the odd
    working directory and its output file appears in the odd sweep directory."""
    monkeypatch.setenv("SLURM_CONF", str(slurm_cluster))
    work = tmp_path / ODD_DIRECTORY
    work.mkdir()
    monkeypatch.chdir(work)
    path = work / "s.nml"
    path.write_text(BASE + "&sweep\n directory = 'out'\n seed = 1, 2\n/\n")
    assert main(["sweep", str(path), "--slurm"]) == 0
    assert "submitted Slurm job" in capsys.readouterr().out
    out = work / "out"
    wait_for(lambda: sweep_status.sweep_status(out).finished, "the two scenes")
    assert sorted(p.name for p in (out / "results").glob("*.h5")) == ["s_0000.h5", "s_0001.h5"]
    job = slurm.read_submissions(out, "s")[0].job_id
    assert slurm.task_output_file(out, "s", 1, job, 0).is_file()
    assert not pwned(tmp_path)


@pytest.mark.parametrize("directory", ["/tmp/lc w\ntouch pwned", "/tmp/lc $(touch pwned)", "/tmp/lc slurm"])
def test_the_test_slurm_refuses_a_directory_it_would_write_into_its_configuration(directory, tmp_path):
    """tools/local_slurm.sh puts DIR in slurm.conf and the daemons' command lines: anything
    but a plain path is refused (exit 2) before anything is written or run."""
    script = Path(__file__).resolve().parents[1] / "tools" / "local_slurm.sh"
    done = subprocess.run(["bash", str(script), "start", directory], cwd=tmp_path, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 2
    assert "is not allowed; allowed: letters, digits and . _ / + -" in done.stderr
    assert not Path(directory).exists() and not list(tmp_path.iterdir())


def test_a_task_removes_only_temporary_files_of_ended_runs_of_its_host(tmp_path, monkeypatch):
    """Before a scene runs, its task removes STEM.h5.HOST.PID.tmp only where HOST is this
    one and PID has ended (and STEM.h5.tmp of earlier versions); another run's file in
    flight, here or elsewhere, is left alone."""
    import socket

    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path)
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    results = tmp_path / "out/s/results"
    results.mkdir(parents=True)
    ended = subprocess.Popen(["true"])
    ended.wait()
    alive = subprocess.Popen(["sleep", "60"])
    host = socket.gethostname()
    files = {
        "ended": results / f"s_0000.h5.{host}.{ended.pid}.tmp",
        "earlier version": results / "s_0000.h5.tmp",
        "alive here": results / f"s_0000.h5.{host}.{alive.pid}.tmp",
        "elsewhere": results / f"s_0000.h5.other-node.{ended.pid}.tmp",
    }
    for file in files.values():
        file.write_bytes(b"partial")
    try:
        task = run_task(tmp_path / "out/s/slurm/s_001.sbatch", 0)
        output, _ = task.communicate(timeout=120)
    finally:
        alive.kill()
        alive.wait()
    assert task.returncode == 0, output
    assert not files["ended"].exists() and not files["earlier version"].exists()
    assert files["alive here"].read_bytes() == b"partial" and files["elsewhere"].read_bytes() == b"partial"
    assert (results / "s_0000.h5").is_file()


# ---------------------------------------------------------------------------------------
# scenes on several MPI ranks (--ranks-per-scene)


def test_ranks_per_scene_gives_array_tasks_of_k_ranks_started_by_srun(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = write_areal_sweep(tmp_path, " slurm_cpus_per_task = 2\n")
    assert main(["sweep", str(path), "--slurm", "--dry-run", "--ranks-per-scene", "4"]) == 0
    script = (tmp_path / "out/a/slurm/a_001.sbatch").read_text()
    head = [line.removeprefix("#SBATCH ") for line in script.splitlines() if line.startswith("#SBATCH")]
    # one array task per scene, of 4 tasks (ranks) of 2 CPUs each
    assert head[:4] == ["--job-name=lc-a", "--array=0-1", "--ntasks=4", "--cpus-per-task=2"]
    run = [line.strip() for line in script.splitlines() if '"$executable"' in line and "scenes/" in line]
    assert run == ['srun --mpi=pmix --ntasks=4 --cpus-per-task=2 "$executable" '
                   '"$sweep_directory/scenes/$scene.nml" >"$sweep_directory/logs/$scene.log" 2>&1 &']
    assert "# Each scene runs on 4 MPI ranks (srun --mpi=pmix), 2 CPU(s) per rank." in script
    assert subprocess.run(["bash", "-n"], input=script, text=True).returncode == 0

    # one rank (the default): the executable alone, one task (a dry run's script is
    # replaced by the next one)
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 0
    script = (tmp_path / "out/a/slurm/a_001.sbatch").read_text()
    assert "#SBATCH --ntasks=1\n" in script and "srun" not in script
    assert '  "$executable" "$sweep_directory/scenes/$scene.nml"' in script


@pytest.mark.parametrize("slurm_flag", [[], ["--slurm", "--dry-run"]], ids=["local", "slurm"])
def test_ranks_per_scene_below_one_or_for_lines_is_refused_before_anything_is_written(
    slurm_flag, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    areal = write_areal_sweep(tmp_path)
    assert main(["sweep", str(areal), *slurm_flag, "--ranks-per-scene", "0"]) == 2
    assert "--ranks-per-scene = 0 is not allowed; allowed: an integer >= 1" in capsys.readouterr().err
    line = write_sweep(tmp_path)
    assert main(["sweep", str(line), *slurm_flag, "--ranks-per-scene", "2"]) == 2
    err = capsys.readouterr().err
    assert "--ranks-per-scene = 2 is not allowed" in err and "lines (&scene geometry = 'line')" in err
    assert "allowed: 1" in err
    assert not (tmp_path / "out").exists()


def test_a_scene_on_two_ranks_runs_in_a_slurm_array_task(slurm_cluster, tmp_path, monkeypatch, capsys):
    # the task gets two Slurm tasks; srun starts the executable on both (PMIx), and the
    # scene's result is written
    monkeypatch.setenv("SLURM_CONF", str(slurm_cluster))
    monkeypatch.chdir(tmp_path)
    path = write_areal_sweep(tmp_path, " slurm_time = '5'\n")
    out = tmp_path / "out/a"
    assert main(["sweep", str(path), "--slurm", "--ranks-per-scene", "2",
                 "--setup", "echo task ranks: $SLURM_NTASKS"]) == 0
    assert "submitted Slurm job" in capsys.readouterr().out
    wait_for(lambda: sweep_status.sweep_status(out).finished, "the scenes on two ranks")
    assert main(["collect", str(out)]) == 0
    summary = lc.read_summary(out / "a_summary.h5")
    assert (summary["error"] == "").all() and len(summary["error"]) == 2
    # (a task writes its scene's record, then its exit line: wait for the line as well)
    def exit_lines():
        outputs = list((out / "slurm").glob("a_001_*.out"))
        return len(outputs) == 2 and all(": exit " in output.read_text() for output in outputs)
    wait_for(exit_lines, "the tasks' exit lines")
    for output in (out / "slurm").glob("a_001_*.out"):
        text = output.read_text()
        assert "task ranks: 2" in text and ": exit 0 on " in text, text
