"""Parameter sweeps (layercontact.sweeps.sweep): the product of the &sweep lists, results equal to
running each scene alone, resume after an interruption or a change, fail-fast checks of
the base scene and the lists, CSV and HDF5 summaries that agree, failing scenes reported
while the others complete, and every sweep in inputs/sweeps/ (dry run; example.nml in
full)."""

from __future__ import annotations

import itertools
import json
import os
import shutil
import sys
from pathlib import Path

import f90nml
import numpy as np
import pytest

import layercontact as lc
from layercontact.sweeps import sweep as sweep_module
from layercontact.__main__ import main
from conftest import ROOT
from areal_sweep import write_areal_sweep

SWEEPS = sorted((ROOT / "inputs" / "sweeps").glob("*.nml"))

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
LISTS = "friction = 0.0, 0.5\n normalised_pressure = 0.5, 2.0\n seed = 1, 2\n"


def write_sweep(directory: Path, lists: str = LISTS, base: str = BASE, name: str = "s") -> Path:
    """A sweep file ``name.nml`` in ``directory`` writing to ``out/NAME``."""
    path = directory / f"{name}.nml"
    path.write_text(base + f"&sweep\n directory = 'out/{name}'\n processes = 2\n {lists}/\n")
    return path


def result_stamps(directory: Path) -> dict[str, tuple[int, int]]:
    """(inode, mtime) of every result file: changes when a result is rewritten."""
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in sorted(directory.glob("results/*.h5"))}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """One sweep of 2 x 2 x 2 scenes, run once for the read-only checks."""
    root = tmp_path_factory.mktemp("sweep")
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(root)
        rows = lc.sweep(write_sweep(root), progress=False)
    return root, rows


def test_the_scenes_are_the_product_of_the_lists(finished):
    root, rows = finished
    expected = list(itertools.product([0.0, 0.5], [0.5, 2.0], [1, 2]))
    assert [(r["friction"], r["normalised_pressure"], r["seed"]) for r in rows] == expected
    for row, (mu, pm, seed) in zip(rows, expected):
        scene = f90nml.read(root / row["scene_file"])
        assert scene["friction"]["coefficient"] == mu and scene["profile"]["seed"] == seed
        assert scene["loading"]["normalised_pressure"] == pm and "sweep" not in scene
        assert scene["output"]["file"] == row["result_file"] and scene["output"]["overwrite"] is True
        assert row["converged"] == 1 and row["error"] == ""
        assert row["contact_fraction"] > 0 and row["normalised_thickness"] == 0.16
    assert len({r["result_file"] for r in rows}) == 8
    assert rows[0]["scene_file"] == "out/s/scenes/s_0000.nml"


def test_each_result_equals_running_the_scene_alone(finished, tmp_path, monkeypatch):
    root, rows = finished
    monkeypatch.chdir(tmp_path)
    for row in rows[::3]:
        alone = tmp_path / "alone.nml"
        alone.write_text((root / row["scene_file"]).read_text().replace(row["result_file"], "alone.h5"))
        res = lc.run(alone)
        swept = lc.read_result(root / row["result_file"])
        np.testing.assert_array_equal(swept.pressure, res.pressure)
        assert swept.penetration == res.penetration and swept.delta_mu == row["delta_mu"]


def test_csv_and_hdf5_summaries_agree(finished):
    root, rows = finished
    csv, h5 = lc.read_summary(root / "out/s/s_summary.csv"), lc.read_summary(root / "out/s/s_summary.h5")
    assert list(csv) == list(h5) == list(rows[0])
    assert list(csv)[:5] == ["friction", "normalised_pressure", "seed", "scene_file", "result_file"]
    assert list(csv)[-1] == "error" and "companion_converged" not in csv
    for name in csv:
        assert csv[name].dtype.kind == h5[name].dtype.kind, name
        np.testing.assert_array_equal(csv[name], h5[name], err_msg=name)
        # a value a row does not have (None: no Slurm ids in a local run) is NaN in the files
        expected = [np.nan if row[name] is None else row[name] for row in rows]
        np.testing.assert_array_equal(csv[name], expected, err_msg=name)
    assert csv["seed"].dtype == np.int64 and csv["scene_file"].dtype.kind == "U"


def test_no_temporary_files_are_left(finished):
    root, _ = finished
    assert not [p for p in root.rglob("*") if p.name.endswith(".tmp")]


def test_resume_skips_completed_scenes_and_reruns_changed_ones(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, lists="friction = 0.0, 0.5\n seed = 1, 2\n")
    out = tmp_path / "out/s"
    first = lc.sweep(path, progress=False)
    stamps = result_stamps(out)
    assert lc.sweep(path, progress=False) == first and result_stamps(out) == stamps

    # a result made from another namelist is run again, the others are not
    shutil.copy(out / "results/s_0000.h5", out / "results/s_0001.h5")
    lc.sweep(path, progress=False)
    now = result_stamps(out)
    assert [name for name in now if now[name] != stamps[name]] == ["s_0001.h5"]

    # a changed list value changes the namelists of those scenes only
    path.write_text(path.read_text().replace("friction = 0.0, 0.5", "friction = 0.0, 0.4"))
    stamps = now
    rows = lc.sweep(path, progress=False)
    now = result_stamps(out)
    assert [name for name in now if now[name] != stamps[name]] == ["s_0002.h5", "s_0003.h5"]
    assert [r["friction"] for r in rows] == [0.0, 0.0, 0.4, 0.4]
    assert lc.read_result(out / "results/s_0003.h5").friction == 0.4


def test_interrupted_sweep_completes_only_the_missing_scene(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, lists="realisations = 4\n")
    out = tmp_path / "out/s"
    first = lc.sweep(path, progress=False)
    assert [r["seed"] for r in first] == [1, 2, 3, 4]
    stamps = result_stamps(out)
    (out / "results/s_0002.h5").unlink()
    rows = lc.sweep(path, processes=1, progress=False)
    now = result_stamps(out)
    assert [name for name in now if now[name] != stamps[name]] == ["s_0002.h5"]
    assert [r["penetration"] for r in rows] == [r["penetration"] for r in first]


BAD_SCENES = [
    # (base scene change, &sweep lists, words the message must contain)
    (("thickness = 0.16", "thickness = -1.0"), "friction = 0.0, 0.5\n", ["&layer: thickness", "s_0000.nml"]),
    (None, "friction = 0.1, -0.5\n", ["&friction: coefficient", "s_0001.nml", "friction = -0.5"]),
    (None, "thickness = 0.16, 0.0\n", ["&layer: thickness", "s_0001.nml"]),
    (("n = 256", "n = 4"), "seed = 1, 2\n", ["&scene: n", "s_0000.nml"]),
]


@pytest.mark.parametrize("change, lists, words", BAD_SCENES, ids=[w[0] for _, _, w in BAD_SCENES])
def test_a_bad_scene_fails_before_anything_runs(change, lists, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = BASE.replace(*change) if change else BASE
    with pytest.raises(lc.LayercontactError) as err:
        lc.sweep(write_sweep(tmp_path, lists=lists, base=base), progress=False)
    assert err.value.code == 2
    for word in words:
        assert word in str(err.value)
    assert not (tmp_path / "out").exists()   # not even the scene files


BAD_SWEEPS = [
    ("friction = 0.1, 'a'\n", "&sweep friction: value 'a' is not a number"),
    ("seed = 1, 2.5\n", "&sweep seed: value 2.5 is not an integer"),
    ("frictoin = 0.1\n", "&sweep frictoin: unknown variable"),
    ("seed = 1\n realisations = 3\n", "&sweep seed, realisations: give at most one"),
    ("mean_pressure = 0.1\n normalised_pressure = 1\n", "&sweep mean_pressure, normalised_pressure"),
    ("realisations = 0\n", "&sweep realisations: 0 is not allowed"),
    ("processes = -2\n", "&sweep processes: -2 is not allowed"),
    ("seed = 1\n/\n&sweep\n seed = 2\n", "&sweep is given more than once; allowed: one &sweep group"),
    ("seed = 1\n/\n friction = 0.5\n&solver\n tol = 1e-8\n", "line 20: text outside a namelist group"),
]


@pytest.mark.parametrize("lists, message", BAD_SWEEPS, ids=[m for _, m in BAD_SWEEPS])
def test_a_bad_sweep_group_is_refused_naming_the_variable(lists, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "s.nml"
    path.write_text(BASE + f"&sweep\n {lists}/\n")
    with pytest.raises(ValueError, match="^" + str(path).replace(".", r"\.")) as err:
        lc.sweep(path, progress=False)
    assert message in str(err.value)
    assert not (tmp_path / "out").exists()
    assert main(["sweep", str(path), "--no-progress"]) == 2


def test_a_failing_scene_is_reported_and_the_others_complete(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    # thin layer: 30 CG iterations are enough without friction, not with mu_c = 1 and the
    # Anderson outer iteration (the GCR of method 'auto' would converge)
    base = BASE.replace("thickness = 0.16", "thickness = 0.05") + "&solver\n max_iter = 30\n method = 'anderson'\n/\n"
    path = write_sweep(tmp_path, lists="friction = 0.0, 1.0\n seed = 1, 2\n", base=base)
    (tmp_path / "out/s/results/s_0001.h5").mkdir(parents=True)  # its result cannot be written
    assert main(["sweep", str(path), "--no-progress"]) == 1
    assert "4 scenes, 3 failed" in capsys.readouterr().out
    summary = lc.read_summary(tmp_path / "out/s/s_summary.h5")
    assert summary["converged"].tolist() == [1, 0, 0, 0]
    assert summary["error"][0] == ""
    assert "LayercontactError" in summary["error"][1] and "s_0001.h5" in summary["error"][1]
    assert "did not converge" in summary["error"][2] and "did not converge" in summary["error"][3]
    assert np.isnan(summary["penetration"][1]) and summary["penetration"][0] > 0
    results = sorted(p.name for p in (tmp_path / "out/s/results").glob("*.h5") if p.is_file())
    assert results == ["s_0000.h5", "s_0002.h5", "s_0003.h5"]
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith(".tmp")]


@pytest.mark.parametrize("path", SWEEPS, ids=[p.stem for p in SWEEPS])
def test_every_sweep_input_writes_valid_scenes(path, tmp_path, monkeypatch):
    """Dry run: the scenes are written and each passes the library's check; nothing is
    solved."""
    monkeypatch.chdir(tmp_path)
    rows = lc.sweep(path, dry_run=True, progress=False)
    plan = sweep_module.read_sweep(path)
    assert len(rows) == int(np.prod([len(v) for v in plan.values.values()]))
    for row in rows:
        lc.check_scene_file(row["scene_file"])
        assert not Path(row["result_file"]).exists()
    assert not plan.summary_file("csv").exists()


def test_example_sweep_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rows = lc.sweep(ROOT / "inputs/sweeps/example.nml", progress=False)
    assert len(rows) == 8 and all(r["converged"] == 1 and r["companion_converged"] == 1 for r in rows)
    assert {(r["friction"], r["normalised_pressure"], r["seed"]) for r in rows} == set(
        itertools.product([0.0, 0.5], [1.0, 3.0], [1, 2])
    )
    assert all(0 < r["a_over_a0"] for r in rows)
    summary = lc.read_summary("out/sweeps/example/example_summary.csv")
    assert summary["friction"].size == 8


def test_poisson_hurst_and_grid_size_can_be_swept(tmp_path, monkeypatch):
    """&sweep poisson, hurst and n land in &layer, &profile and &scene of each scene; each
    scene solves as the same scene run alone."""
    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, lists="poisson = 0.3, 0.5\n hurst = 0.6\n n = 256, 512\n")
    rows = lc.sweep(path, progress=False)
    assert [(r["poisson"], r["hurst"], r["n"]) for r in rows] == [(0.3, 0.6, 256), (0.3, 0.6, 512),
                                                                   (0.5, 0.6, 256), (0.5, 0.6, 512)]
    for row in rows:
        scene = f90nml.read(row["scene_file"])
        assert (scene["layer"]["poisson"], scene["profile"]["hurst"], scene["scene"]["n"]) == (
            row["poisson"], row["hurst"], row["n"])
        result = lc.read_result(row["result_file"])
        assert result.pressure.size == row["n"] and result.converged


def test_ctrl_c_stops_the_sweep_cleanly_and_a_rerun_resumes(tmp_path):
    """Ctrl-C (SIGINT to the sweep's process group) ends the sweep with exit code 130 and a
    one-line message, no traceback; running it again skips the finished scenes and says so.
    (Scenes of 65536 points, ~30 ms each: the sweep must still be running when the first
    result appears and the signal is sent, also on a loaded machine.)"""
    import os
    import signal
    import subprocess
    import time

    path = write_sweep(tmp_path, lists="seed = " + ", ".join(map(str, range(1, 201))) + "\n",
                       base=BASE.replace("n = 256", "n = 65536"))
    command = [sys.executable, "-m", "layercontact", "sweep", str(path), "--no-progress"]
    proc = subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True,
                            preexec_fn=interactive_sigint)
    results = tmp_path / "out/s/results"
    deadline = time.monotonic() + 120
    while not (results.is_dir() and any(results.glob("*.h5"))) and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert "sweep interrupted; run the same command again to resume" in err and "Traceback" not in err
    done = len(list(results.glob("*.h5")))
    assert 0 < done < 200
    rerun = subprocess.run([sys.executable, "-m", "layercontact", "sweep", str(path)], cwd=tmp_path,
                           capture_output=True, text=True, timeout=600)
    assert rerun.returncode == 0, rerun.stderr
    skipped = int(rerun.stderr.split("sweep 's': ")[1].split(" of 200 scenes already")[0])
    assert skipped >= done - 2   # a result being written at the signal may be cut (its .tmp is not a result)


def interactive_sigint() -> None:
    """In the child, before it starts: SIGINT's default action, as in a terminal. A test
    run as a background job inherits SIGINT ignored, and Python then takes no Ctrl-C."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def descendants(pid: int) -> set[int]:
    """The processes below ``pid`` (Linux /proc)."""
    found, todo = set(), [pid]
    while todo:
        parent = todo.pop()
        for task in Path(f"/proc/{parent}/task").glob("*"):
            try:
                children = {int(c) for c in (task / "children").read_text().split()}
            except OSError:
                continue
            todo.extend(children - found)
            found |= children
    return found


def test_workers_end_when_the_sweep_process_is_killed(tmp_path):
    """SIGKILL of the sweep's process (it cannot stop its workers then): the workers notice
    within seconds and end, with the rest of the process tree."""
    import os
    import signal
    import subprocess
    import time

    path = write_sweep(tmp_path, lists="seed = " + ", ".join(map(str, range(1, 101))) + "\n",
                       base=BASE.replace("n = 256", "n = 65536"))
    proc = subprocess.Popen([sys.executable, "-m", "layercontact", "sweep", str(path), "--no-progress"],
                            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results = tmp_path / "out/s/results"
    deadline = time.monotonic() + 120
    while not (results.is_dir() and any(results.glob("*.h5"))) and time.monotonic() < deadline:
        time.sleep(0.05)
    tree = descendants(proc.pid)
    assert len(tree) >= 2   # the forkserver and its workers (and the resource tracker)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    deadline = time.monotonic() + 30
    while any(Path(f"/proc/{pid}").exists() for pid in tree) and time.monotonic() < deadline:
        time.sleep(0.2)
    left = [pid for pid in tree if Path(f"/proc/{pid}").exists()]
    assert not left, [Path(f"/proc/{pid}/cmdline").read_bytes()[:80] for pid in left]


def test_two_concurrent_sweeps_of_one_directory_report_every_scene_converged(tmp_path):
    """Two sweeps of the same file and directory at once (two workers each): a scene runs
    under its lock, so the second sweep to reach it waits and finds its result; neither
    removes the other's result in flight. Both summaries say every scene converged, every
    result is complete, and no temporary file is left."""
    import subprocess

    path = write_sweep(tmp_path, lists="seed = " + ", ".join(map(str, range(1, 13))) + "\n",
                       base=BASE.replace("n = 256", "n = 65536"))
    command = [sys.executable, "-m", "layercontact", "sweep", str(path), "--no-progress"]
    sweeps = [
        subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for _ in range(2)
    ]
    for proc in sweeps:
        out, err = proc.communicate(timeout=600)
        assert proc.returncode == 0, (out, err)
        assert "12 scenes, 0 failed" in out
    summary = lc.read_summary(tmp_path / "out/s/s_summary.csv")
    assert len(summary["error"]) == 12
    assert (summary["error"] == "").all() and (summary["converged"] == 1).all()
    for result in (tmp_path / "out/s/results").glob("*.h5"):
        assert lc.read_result(result).converged
    assert not [p for p in (tmp_path / "out/s").rglob("*") if p.name.endswith(".tmp")]


def test_a_worker_removes_only_temporary_files_of_ended_runs_of_its_host(tmp_path, monkeypatch):
    """Before a scene runs, its temporary results STEM.h5.HOST.PID.tmp are removed only
    when HOST is this one and process PID has ended (and STEM.h5.tmp of earlier versions);
    a live run's file (here or on another host) is left alone."""
    import socket
    import subprocess

    monkeypatch.chdir(tmp_path)
    path = write_sweep(tmp_path, lists="seed = 1\n")
    plan = sweep_module.read_sweep(path)
    scene = sweep_module.write_scenes(plan)[0]
    results = scene.result_file.parent
    results.mkdir(parents=True)
    ended = subprocess.Popen(["true"])
    ended.wait()
    alive = subprocess.Popen(["sleep", "60"])   # another run of this host, writing
    host = socket.gethostname()
    files = {
        "ended": results / f"{scene.stem}.h5.{host}.{ended.pid}.tmp",
        "earlier version": results / f"{scene.stem}.h5.tmp",
        "alive here": results / f"{scene.stem}.h5.{host}.{alive.pid}.tmp",
        "elsewhere": results / f"{scene.stem}.h5.other-node.{ended.pid}.tmp",
    }
    for file in files.values():
        file.write_bytes(b"partial")
    try:
        record_file = sweep_module._record_file(scene)
        sweep_module._solve(str(scene.scene_file), str(scene.result_file), str(record_file))
    finally:
        alive.kill()
        alive.wait()
    assert not files["ended"].exists() and not files["earlier version"].exists()
    assert files["alive here"].read_bytes() == b"partial" and files["elsewhere"].read_bytes() == b"partial"
    assert lc.read_result(scene.result_file).converged


def test_a_sweep_beyond_the_scene_limit_is_refused_before_anything_is_planned(tmp_path, monkeypatch, capsys):
    """1.7 million scenes are counted, not planned: refused at once (exit 2) with the count,
    the lists and how to allow more; max_scenes (or --max-scenes) raises the limit."""
    import time

    monkeypatch.chdir(tmp_path)
    many = ", ".join(str(0.01 * k) for k in range(1, 101))
    path = write_sweep(tmp_path, lists=f"friction = {many}\n thickness = {many}\n realisations = 170\n")
    start = time.monotonic()
    assert main(["sweep", str(path), "--no-progress"]) == 2
    assert time.monotonic() - start < 10
    err = capsys.readouterr().err
    lists = "100 friction x 100 thickness x 170 seed"
    assert f"&sweep: the lists give 1700000 scenes ({lists}), more than 20000" in err
    assert "allowed: at most 20000 scenes, or more with &sweep max_scenes = N (or --max-scenes N)" in err
    assert not (tmp_path / "out").exists()
    assert main(["sweep", str(path), "--slurm", "--dry-run"]) == 2
    assert "1700000 scenes" in capsys.readouterr().err and not (tmp_path / "out").exists()
    # a lower limit from the command line or the file; a higher one lets the sweep through
    small = write_sweep(tmp_path, lists="seed = 1, 2, 3\n", name="small")
    assert main(["sweep", str(small), "--dry-run", "--max-scenes", "2"]) == 2
    assert "the lists give 3 scenes (3 seed), more than 2" in capsys.readouterr().err
    small.write_text(small.read_text().replace("processes = 2", "processes = 2\n max_scenes = 2"))
    with pytest.raises(ValueError, match="the lists give 3 scenes"):
        lc.sweep(small, dry_run=True)
    assert len(lc.sweep(small, dry_run=True, max_scenes=3)) == 3
    assert main(["sweep", str(small), "--dry-run", "--max-scenes", "0"]) == 2
    assert "--max-scenes: 0 is not allowed; allowed: an integer >= 1" in capsys.readouterr().err


def test_a_fifo_given_as_the_sweep_file_is_refused_at_once(tmp_path):
    import subprocess

    fifo = tmp_path / "s.nml"
    os.mkfifo(fifo)
    done = subprocess.run([sys.executable, "-m", "layercontact", "sweep", str(fifo)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert f"sweep file '{fifo}' is a FIFO (named pipe); allowed: a regular file" in done.stderr


@pytest.mark.parametrize("lists", [
    "friction = 0.0, 0.5\n friction = 0.2\n",
    "friction = 0.0, 0.5\n seed = 1\n friction(3) = 1.0\n",
    "seed = 1, 2 ! seed = 3 in a comment is not an assignment\n friction = 0.0, 0.5, seed = 4\n",
])
def test_a_sweep_variable_given_twice_is_refused(tmp_path, lists):
    """Two assignments of one &sweep variable (which the namelist parser would merge
    element by element) are refused before anything is planned, naming the variable."""
    name = "seed" if lists.startswith("seed") else "friction"
    path = write_sweep(tmp_path, lists)
    with pytest.raises(ValueError, match=f"&sweep {name}: given more than once"):
        sweep_module.read_sweep(path)
    assert not (tmp_path / "out").exists()


def test_a_sweep_variable_in_a_comment_or_a_string_is_not_counted(tmp_path):
    path = write_sweep(tmp_path, "friction = 0.0, 0.5 ! friction = 1.0\n seed = 1, 2\n")
    assert sweep_module.read_sweep(path).values["friction"] == [0.0, 0.5]


def test_a_scene_variable_given_twice_in_a_sweep_file_is_refused(tmp_path):
    """The scene groups of a sweep file are checked as a scene file is: a variable given
    twice, or under both of its names, is refused before anything is planned."""
    path = write_sweep(tmp_path, "seed = 1, 2\n", base=BASE.replace("n = 256", "n = 256\n   period = 1.0\n"
                                                                    "   period_x = 2.0"))
    with pytest.raises(ValueError, match="&scene: period and period_x are both given .*keep the one you mean"):
        sweep_module.read_sweep(path)
    path = write_sweep(tmp_path, "seed = 1, 2\n", base=BASE.replace("poisson = 0.5", "poisson = 0.5\n   poisson = 0.3"))
    with pytest.raises(ValueError, match="&layer: poisson is given more than once"):
        sweep_module.read_sweep(path)
    assert not (tmp_path / "out").exists()


def test_a_swept_grid_replaces_the_second_name_of_the_base(tmp_path, monkeypatch):
    """A sweep of n over an areal base that gives nx: each scene's grid is the swept n (the
    base's nx, the same variable, is replaced rather than given twice)."""
    monkeypatch.chdir(tmp_path)
    base = ("&scene\n   geometry = 'areal'\n   nx = 16\n   ny = 16\n/\n&profile\n   kind = 'sinusoid'\n"
            "   amplitude = 0.01\n/\n&loading\n   normalised_pressure = 1.0\n/\n")
    path = write_sweep(tmp_path, "n = 16, 32\n", base=base)
    rows = sweep_module.sweep(path, processes=1, progress=False)
    assert [lc.read_result(row["result_file"]).pressure.shape for row in rows] == [(16, 16), (16, 32)]


def processes_marked(marker: str) -> list[int]:
    """The processes whose environment holds ``marker`` (a sweep's and all it started)."""
    found = []
    for environ in Path("/proc").glob("[0-9]*/environ"):
        try:
            if marker.encode() in environ.read_bytes():
                found.append(int(environ.parent.name))
        except OSError:
            continue
    return found


#: Scenes that each take seconds (a line of 2^18 points with friction on a thin layer: 11 s
#: on a loaded 2-core machine): a Ctrl-C reaches them inside the library.
SLOW_BASE = BASE.replace("n = 256", "n = 1048576").replace("coefficient = 0.0", "coefficient = 0.3") \
    .replace("short_wavelength = 0.03125", "short_wavelength = 0.0001")


def test_ctrl_c_ends_the_scenes_in_flight_at_once_and_a_rerun_completes(tmp_path):
    """Ctrl-C while every worker is inside a scene's solve: the sweep says at once that it
    stops, ends its workers (no process it started is left, no temporary file), marks the
    scenes in flight as interrupted and exits with 130 within seconds, not after the
    scenes; the same command then runs them and completes the sweep."""
    import os
    import signal
    import subprocess
    import time
    import uuid

    path = write_sweep(tmp_path, lists="seed = 1, 2\n", base=SLOW_BASE)
    marker = f"LAYERCONTACT_TEST_SWEEP={uuid.uuid4().hex}"
    env = {**os.environ, "LAYERCONTACT_TEST_SWEEP": marker.split("=")[1]}
    command = [sys.executable, "-m", "layercontact", "sweep", str(path), "--no-progress"]
    proc = subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, env=env, preexec_fn=interactive_sigint)
    runs = tmp_path / "out/s/runs"
    deadline = time.monotonic() + 300

    def running() -> int:
        records = [json.loads(p.read_text()) for p in runs.glob("*.json")] if runs.is_dir() else []
        return sum(r.get("state") == "running" for r in records)

    while running() < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert running() == 2, "both scenes should be running"
    time.sleep(1.0)   # inside the library's solve by now
    start = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    elapsed = time.monotonic() - start
    assert proc.returncode == 130, (out, err)
    # one scene alone takes several seconds here; ending the workers takes well under one
    # (SIGTERM, then SIGKILL after 0.5 s): 3 s leaves room for a loaded machine
    assert elapsed < 3.0, elapsed
    assert "Ctrl-C: stopping the sweep 's': ending the scenes in flight" in err and "Traceback" not in err
    deadline = time.monotonic() + 2.0
    while processes_marked(marker) and time.monotonic() < deadline:   # the forkserver ends with its pipe
        time.sleep(0.05)
    assert not processes_marked(marker)
    assert not list((tmp_path / "out").rglob("*.tmp")) and not list((tmp_path / "out/s/results").glob("*.h5"))
    records = [json.loads(p.read_text()) for p in sorted(runs.glob("*.json"))]
    assert [(r["state"], r["exit_code"]) for r in records] == [("finished", 130)] * 2
    assert all("interrupted (Ctrl-C)" in r["error"] for r in records)
    rerun = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert rerun.returncode == 0, rerun.stderr
    assert len(list((tmp_path / "out/s/results").glob("*.h5"))) == 2


def test_several_ranks_per_scene_need_a_build_with_mpi(tmp_path, monkeypatch):
    """A build without MPI would run each scene's ranks as whole copies of the scene: the
    sweep refuses --ranks-per-scene > 1 before any scene runs, and 1 stays allowed."""
    from layercontact.sweeps.sweep import check_ranks_per_scene, read_sweep
    plan = read_sweep(write_areal_sweep(tmp_path))
    monkeypatch.setattr(lc.native.core, "py_mpi_available", lambda: 0)
    with pytest.raises(ValueError, match="--ranks-per-scene = 2 is not allowed: this build of layercontact has no MPI"):
        check_ranks_per_scene(plan, 2)
    assert check_ranks_per_scene(plan, 1) == 1


def test_a_local_sweep_on_two_ranks_per_scene_runs_each_scene_under_mpirun(tmp_path, monkeypatch):
    """Each scene runs as `mpirun -n 2 layercontact SCENE.nml` (its output in logs/); the
    results equal the scenes solved in this process, to the solver's tolerance."""
    if shutil.which("mpirun") is None:
        if os.environ.get("LAYERCONTACT_REQUIRE_MPI"):
            pytest.fail("mpirun not found (LAYERCONTACT_REQUIRE_MPI is set)")
        pytest.skip("mpirun not found")
    monkeypatch.chdir(tmp_path)
    # Open MPI as root, and 2 ranks where fewer cores are free
    monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT", "1")
    monkeypatch.setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    monkeypatch.setenv("OMPI_MCA_rmaps_base_oversubscribe", "1")
    path = write_areal_sweep(tmp_path)
    rows = lc.sweep(path, processes=1, progress=False, ranks_per_scene=2)
    assert [row["error"] for row in rows] == ["", ""]
    for row in rows:
        stem = Path(row["scene_file"]).stem
        assert (tmp_path / "out/a/logs" / f"{stem}.log").exists()
        alone = lc.run(tmp_path / row["scene_file"])
        # both solves meet &solver tol (1e-8 by default, relative): 1e-6 leaves them room
        assert row["contact_fraction"] == pytest.approx(alone.contact_fraction, rel=1e-6)
        assert row["mean_pressure"] == pytest.approx(alone.mean_pressure, rel=1e-6)
