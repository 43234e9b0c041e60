"""How a run meets the ranks it is started with: `layercontact.run` in a Python script under
mpirun, on the launcher's job or on a communicator of the script's own (mpi4py), and a
build without MPI started as several ranks (refused: each rank would solve the whole scene
alone and write the same file).

Distributed answers are compared with the serial run's to tests/test_mpi.py's 1e-10
relative (both solved to tol = 1e-13: the solution is unique, so the two agree to the
tolerance's bound, far below 1e-10)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_mpi import SAME, SCENES, assert_same, launcher_env, needs_mpi, read, run_serial, write_scene

ROOT = Path(__file__).resolve().parents[1]

try:
    import mpi4py  # noqa: F401
    HAS_MPI4PY = True
except ImportError:
    HAS_MPI4PY = False

#: CI sets LAYERCONTACT_REQUIRE_MPI: there a missing mpi4py (a test extra) fails, not skips
needs_mpi4py = pytest.mark.skipif(not HAS_MPI4PY and not os.environ.get("LAYERCONTACT_REQUIRE_MPI"),
                                  reason="mpi4py is not installed")

SCRIPT = """
import json, os, sys
import numpy as np
from mpi4py import MPI
import layercontact as lc

world = MPI.COMM_WORLD
report = {"rank": world.rank}
# the job's ranks share one scene, as `python -m layercontact run` does
whole = lc.run("world.nml")
report["world"] = whole.mpi_ranks
# after it, an in-memory solve in the same process is serial again (one rank each)
alone = lc.solve_areal(np.asarray(whole.height), period=1.0, thickness=0.05, poisson=0.5, friction=0.5,
                       mean_pressure=whole.mean_pressure, tol=1e-13, stress=False)
report["alone_ranks"] = alone.mpi_ranks
report["alone_pressure_difference"] = float(np.max(np.abs(alone.pressure - whole.pressure)) /
                                            np.max(np.abs(whole.pressure)))
# two pairs of ranks, each sharing a scene of its own
pair = world.Split(color=world.rank // 2, key=world.rank)
shared = lc.run(f"pair{world.rank // 2}.nml", comm=pair)
report["pair"] = shared.mpi_ranks
# every rank a scene of its own
own = lc.run(f"own{world.rank}.nml", comm=MPI.COMM_SELF)
report["own"] = own.mpi_ranks
with open(f"report{world.rank}.json", "w") as f:
    json.dump(report, f)
"""


@needs_mpi
@needs_mpi4py
def test_run_under_mpi4py_on_the_job_and_on_its_own_communicators(tmp_path):
    """mpirun -n 4 python script: the world's scene, two scenes on pairs of ranks (a split
    communicator), one scene per rank (COMM_SELF), each the serial run's answer."""
    body = SCENES["coupled"]
    scenes = {"world": 3, "pair0": 5, "pair1": 7, **{f"own{r}": 11 + r for r in range(4)}}
    for name, seed in scenes.items():
        for suffix in ("", "_serial"):
            nml = write_scene(tmp_path, name + suffix, 32, body, f"{name}{suffix}.h5")
            nml.write_text(nml.read_text().replace("seed = 3", f"seed = {seed}"))
        assert run_serial(tmp_path / f"{name}_serial.nml").returncode == 0
    (tmp_path / "script.py").write_text(SCRIPT)
    done = subprocess.run(["mpirun", "--oversubscribe", "-n", "4", sys.executable, "script.py"], cwd=tmp_path,
                          capture_output=True, text=True, env=launcher_env(), timeout=600)
    assert done.returncode == 0, done.stderr
    for name in scenes:
        assert_same(tmp_path / f"{name}_serial.h5", tmp_path / f"{name}.h5")
    assert read(tmp_path / "world.h5")[2] == 4
    assert read(tmp_path / "pair0.h5")[2] == read(tmp_path / "pair1.h5")[2] == 2
    assert read(tmp_path / "own2.h5")[2] == 1
    for rank in range(4):
        report = json.loads((tmp_path / f"report{rank}.json").read_text())
        assert (report["world"], report["pair"], report["own"], report["alone_ranks"]) == (4, 2, 1, 1)
        assert report["alone_pressure_difference"] <= SAME


def test_a_communicator_must_be_one(tmp_path):
    import layercontact as lc
    nml = write_scene(tmp_path, "scene", 16, SCENES["frictionless"], "scene.h5")
    with pytest.raises(lc.InputError, match="allowed: an mpi4py communicator"):
        lc.run(nml, comm=7)
    assert not (tmp_path / "scene.h5").exists()


# ---- a build without MPI under a launcher -------------------------------------------------

DRIVER = """
program launch
   use lc_base_errors, only: error_type
   use lc_base_parallel, only: parallel_start, rank_count, is_root
   implicit none
   type(error_type), allocatable :: error
   call parallel_start(error)
   if (allocated(error)) then
      print '(i0, 1x, l1, 1x, a)', error%code, is_root(), error%message
   else
      print '(a, 1x, i0)', 'ranks', rank_count()
   end if
end program launch
"""


@pytest.fixture(scope="module")
def serial_launch(tmp_path_factory) -> Path:
    """The one-rank build of lc_base_parallel (no LC_MPI) with the launcher's C glue,
    linked to a program that starts it and prints what it says."""
    compiler = shutil.which("gfortran")
    if compiler is None:
        pytest.skip("no gfortran")
    build = tmp_path_factory.mktemp("serial_launch")
    base = ROOT / "src" / "base"
    sources = [base / name for name in ("kinds.f90", "errors.f90", "strings.f90", "slab.f90", "parallel.F90")]
    (build / "launch.f90").write_text(DRIVER)
    subprocess.run(["gcc", "-c", str(base / "launcher.c"), "-o", "launcher.o"], cwd=build, check=True)
    subprocess.run([compiler, "-ffree-line-length-132", *map(str, sources), "launch.f90", "launcher.o",
                    "-o", "launch"], cwd=build, check=True, capture_output=True)
    return build / "launch"


def launch(program: Path, **variables: str) -> str:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "SLURM_"))}
    env.update(variables)
    return subprocess.run([str(program)], capture_output=True, text=True, env=env, check=True).stdout.strip()


@pytest.mark.parametrize("variables, refused", [
    ({}, False),                                                     # a plain run
    ({"OMPI_COMM_WORLD_SIZE": "1"}, False),                          # mpirun -n 1
    ({"OMPI_COMM_WORLD_SIZE": "3"}, True),                           # mpirun -n 3
    ({"PMI_SIZE": "2"}, True),                                       # a PMI launcher (MPICH's, srun's)
    ({"SLURM_NTASKS": "4"}, False),                                  # a batch script's own process
    ({"SLURM_NTASKS": "4", "SLURM_STEP_ID": "0", "SLURM_PROCID": "0"}, True),   # srun -n 4
    ({"SLURM_NTASKS": "4", "SLURM_STEP_ID": "0", "SLURM_PROCID": "1"}, True),
])
def test_a_build_without_mpi_refuses_several_ranks(serial_launch, variables, refused):
    """Each of the ranks would solve the whole scene and write the same file: exit 2 (input)
    with the rank count and what is allowed, before any work, said by the launcher's rank 0
    alone; one process runs."""
    said = launch(serial_launch, **variables)
    if refused:
        count = variables.get("OMPI_COMM_WORLD_SIZE") or variables.get("PMI_SIZE") or variables["SLURM_NTASKS"]
        reporter = variables.get("SLURM_PROCID", "0") == "0"
        assert said.startswith(f"2 {'T' if reporter else 'F'} this build of layercontact has no MPI")
        assert f"started as one of {count} ranks" in said and "allowed: one process" in said
    else:
        assert said == "ranks 1"
