"""The result file and the height files by slabs of rows on several MPI ranks
(src/io/hdf5_slabs.F90, src/profiles/height_slabs.F90), through the test program
tests/fortran/test_slab_io.f90 run under `mpirun -n P` for P = 1, 2, 3, 4 (3 does not
divide the 64 rows: slabs of 22, 22 and 20 rows).

The oracles: the serial writer's file of the same result (every dataset, dtype, shape,
filter and attribute equal: the slab writer makes the same file), the closed forms the
program computes the maps from, and the heights this test writes.

Skipped when mpirun or a build with MPI's Fortran bindings is absent, unless
LAYERCONTACT_REQUIRE_MPI is set (CI sets it): then a missing piece fails.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import build_unit_program

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build" / "unit"
PROGRAM = BUILD / "tests" / "fortran" / "test_slab_io"
#: the program's grid (test_slab_io.f90) and the height files' (40 x 64)
NX, NY, LX, LY = 24, 64, 2.0, 1.5
HEIGHT_NX = 40


def _unavailable(reason: str):
    if os.environ.get("LAYERCONTACT_REQUIRE_MPI"):
        pytest.fail(reason + " (LAYERCONTACT_REQUIRE_MPI is set)")
    pytest.skip(reason)


@pytest.fixture(scope="module")
def program() -> Path:
    """The test program, built in build/unit (as `make unit-tests` builds it) when needed."""
    if shutil.which("mpirun") is None:
        _unavailable("mpirun not found")
    built, _ = build_unit_program("test_slab_io")
    if built.returncode != 0 or not PROGRAM.exists():
        _unavailable("this build has no MPI Fortran bindings (no test_slab_io): " + built.stdout[-500:])
    if "-DLC_PARALLEL_HDF5" not in (BUILD / "build.ninja").read_text():
        _unavailable("this build's HDF5 is serial (no LC_PARALLEL_HDF5)")
    return PROGRAM


def mpirun(program: Path, ranks: int, directory: Path, *arguments: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    command = ["mpirun", "--oversubscribe", "-n", str(ranks), str(program), str(directory), *arguments]
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)


def heights() -> np.ndarray:
    """h[iy, ix] = ix + 1000.25 iy: exact in binary and in numpy.savetxt's text."""
    return np.arange(HEIGHT_NX)[None, :] + 1000.25 * np.arange(NY)[:, None]


def write_height_files(directory: Path) -> None:
    with h5py.File(directory / "heights.h5", "w") as f:
        f["h"] = heights()
    np.save(directory / "heights.npy", heights())
    np.savetxt(directory / "heights.txt", heights())
    np.savetxt(directory / "few.txt", heights()[:2])
    with h5py.File(directory / "few.h5", "w") as f:
        f["h"] = heights()[:2]


def slabs(output: str) -> list[tuple[int, int, int]]:
    """The (rank, y_start, ny_local) lines the ranks printed, by rank."""
    return sorted(tuple(int(v) for v in line.split()[1:]) for line in output.splitlines()
                  if line.startswith("rank "))


def contract(ranks: int) -> list[tuple[int, int, int]]:
    """The slab contract: blocks of ceiling(ny/P) rows, FFTW-MPI's split of n0 = ny."""
    block = -(-NY // ranks)
    return [(r, r * block, max(0, min(block, NY - r * block))) for r in range(ranks)]


def items(f: h5py.File) -> dict[str, object]:
    found = {"/": f}
    f.visititems(lambda name, obj: found.__setitem__(name, obj))
    return found


@pytest.mark.parametrize("ranks,precision", [(1, "double"), (2, "double"), (3, "double"), (4, "double"),
                                             (3, "single")])
def test_slab_file_is_the_serial_file_and_slab_reads_are_the_file_rows(program, tmp_path, ranks, precision):
    write_height_files(tmp_path)
    run = mpirun(program, ranks, tmp_path, "write", precision)
    assert run.returncode == 0, run.stdout + run.stderr
    # every rank's checks of the heights it read (its rows, each height exact) passed
    assert run.stdout.count("all slab I/O checks passed") == ranks, run.stdout
    assert slabs(run.stdout) == contract(ranks)
    assert not list(tmp_path.glob("*.tmp"))

    with h5py.File(tmp_path / "slabs.h5") as parallel, h5py.File(tmp_path / "serial.h5") as serial:
        a, b = items(parallel), items(serial)
        assert sorted(a) == sorted(b)
        for name in a:
            x, y = a[name], b[name]
            assert type(x) is type(y), name
            if isinstance(x, h5py.Dataset):
                assert (x.shape, x.dtype, x.chunks, x.compression, x.shuffle) == \
                    (y.shape, y.dtype, y.chunks, y.compression, y.shuffle), name
                assert np.array_equal(x[()], y[()]), name
            # the creation time is each writer's own second; everything else is the same
            assert set(x.attrs) == set(y.attrs), name
            for key in x.attrs:
                if key != "created":
                    assert np.array_equal(x.attrs[key], y.attrs[key]), (name, key)
        assert parallel.attrs["mpi_ranks"] == ranks
        assert parallel["fields/gap"].dtype == np.dtype("<f4" if precision == "single" else "<f8")
        # the maps more than half zeros are deflated in chunks of whole rows, the others contiguous
        assert parallel["fields/pressure"].compression == "gzip"
        assert parallel["fields/gap"].chunks is None

        # the maps against the closed forms of the program (cos and sin of two libraries:
        # a few units in the last place of values of order 1, hence 1e-14; float32 maps:
        # rounded to 2**-24 relative, values below 3.5, hence 3.5 * 2**-24 < 3e-7)
        atol = 3e-7 if precision == "single" else 1e-14
        x = np.arange(NX) * LX / NX
        y = (np.arange(NY) * LY / NY)[:, None]
        cap = np.maximum(0.0, np.cos(2 * np.pi * x / LX) * np.cos(2 * np.pi * y / LY) - 0.5)
        np.testing.assert_allclose(parallel["fields/pressure"][()], cap, rtol=0, atol=atol)
        np.testing.assert_allclose(parallel["fields/gap"][()], 1 + np.sin(2 * np.pi * x / LX) + 0.25 * y,
                                   rtol=0, atol=atol)
        np.testing.assert_allclose(parallel["fields/displacement_z"][()],
                                   1e-3 * (np.arange(NX) + 1000 * np.arange(NY)[:, None]), rtol=1e-7 if
                                   precision == "single" else 1e-15, atol=0)
        assert np.count_nonzero(cap) < cap.size / 2


@pytest.mark.parametrize("ranks,failing", [(2, 1), (3, 2), (4, 0)])
def test_a_failure_on_one_rank_fails_every_rank_and_writes_nothing(program, tmp_path, ranks, failing):
    run = mpirun(program, ranks, tmp_path, "fail", str(failing))
    assert run.returncode == 5, run.stdout + run.stderr
    errors = [line for line in run.stdout.splitlines() if line.startswith("error ")]
    # every rank returns the failing rank's error
    assert len(errors) == ranks and len(set(errors)) == 1, run.stdout
    assert f"of rank {failing}'s rows" in errors[0]
    assert not (tmp_path / "failed.h5").exists()
    assert not list(tmp_path.glob("*.tmp"))


def test_a_refused_move_keeps_the_old_file_on_every_rank(program, tmp_path):
    old = tmp_path / "slabs.h5"
    with h5py.File(old, "w") as f:
        f["kept"] = np.arange(3.0)
    before = old.read_bytes()
    run = mpirun(program, 3, tmp_path, "keep")
    assert run.returncode == 4, run.stdout + run.stderr
    errors = [line for line in run.stdout.splitlines() if line.startswith("error ")]
    assert len(errors) == 3 and len(set(errors)) == 1, run.stdout
    assert "overwrite" in errors[0]
    assert old.read_bytes() == before
    assert not list(tmp_path.glob("*.tmp"))


@pytest.mark.parametrize("ranks,name", [(3, "few.txt"), (4, "few.txt"), (3, "few.h5")])
def test_a_height_file_with_fewer_rows_than_ranks_is_refused_on_every_rank(program, tmp_path, ranks, name):
    write_height_files(tmp_path)
    run = mpirun(program, ranks, tmp_path, "few", name)
    assert run.returncode == 2, run.stdout + run.stderr
    errors = [line for line in run.stdout.splitlines() if line.startswith("error ")]
    assert len(errors) == ranks and len(set(errors)) == 1
    assert f"{name}' holds 2 rows" in errors[0] and f"{ranks} MPI ranks" in errors[0]
