"""One areal scene shared among the ranks of an MPI job (docs/decisions/023-mpi-slabs.md):
`mpirun -n P layercontact scene.nml` and `mpirun -n P python -m layercontact run scene.nml`
solve one surface split into slabs of rows, and give the serial run's fields and scalars.

The oracle is the serial run of the same scene (no launcher: one process, the code path of
a build without MPI). The distributed run transforms with FFTW-MPI and adds its sums over
the ranks, so its rounding differs from the serial run's by some ulps per step, and where
the serial CG or GCR updates a few points by the operator's real-space column the
distributed one takes a transform instead. Both solves run to tol = 1e-13 (the
complementarity residual relative to p_m and the relief); two solutions each that close
to the exact one agree to about that, so SAME = 1e-10 relative (against a field's largest
value, a scalar's size) is met with three decades to spare yet fails on any slab that is
misplaced, any sum taken on one rank only, or a mode's wavevector taken from the local
index (each of those moves the answer by percents). The run with 3 ranks splits the rows
unevenly (64 = 22 + 22 + 20, 128 = 43 + 43 + 42).

A distributed run computes its observables on the slabs and every rank writes its rows of
the result file, which must be the serial run's file: every dataset (dtype, shape, chunks,
filters, values) and every attribute, but for what records the run rather than the answer
(times, counts of iterations, the rank count, the host and the clock).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import build_unit_program

#: relative agreement of the distributed and the serial run (see the module docstring)
SAME = 1e-10
#: scalars that vanish physically (the interlocking friction of a frictionless elastic scene,
#: zero but for the rounding of w', ~1e-18 here) are compared to this absolute floor
VANISHING = 1e-14
#: the counts and the time of a solve differ between runs by design: not compared
NOT_COMPARED = {"wall_time", "setup_time", "coarse_time", "transform_time", "residual", "iterations", "fft_pairs", "outer_iterations", "mpi_ranks",
                "solver_reason", "omp_threads"}
#: what else in a file records the run, not the answer: its clock, and the counts and
#: residuals of the iterations that stop at a tolerance (conductance, stiffness, leakage)
RUN_RECORD = NOT_COMPARED | {"created", "started", "run_wall_time", "input_file", "conductance_iterations",
                             "stiffness_iterations"}
#: datasets recording the run: the solver's residual history (its length is its iterations)
RUN_DATASETS = {"convergence/residual", "companion/convergence/residual"}


def executable() -> str:
    """The installed `layercontact` program of this Python's environment."""
    found = shutil.which("layercontact", path=sysconfig.get_path("scripts")) or shutil.which("layercontact")
    assert found, "the layercontact executable is not installed (pip install . puts it in the venv's bin/)"
    return found


def mpi_build() -> bool:
    """True where mpirun exists and the executable was built with FFTW-MPI."""
    if shutil.which("mpirun") is None:
        return False
    linked = subprocess.run(["ldd", executable()], capture_output=True, text=True).stdout
    return "libfftw3_mpi" in linked


#: CI (.ci/run) sets LAYERCONTACT_REQUIRE_MPI: there these tests fail, not skip, without MPI
needs_mpi = pytest.mark.skipif(not mpi_build() and not os.environ.get("LAYERCONTACT_REQUIRE_MPI"),
                               reason="no mpirun or a build without FFTW-MPI")


def launcher_env() -> dict[str, str]:
    """The environment of an mpirun child: root allowed (CI runs as root), one thread."""
    env = dict(os.environ)
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    return env


def serial_env() -> dict[str, str]:
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = "1"
    for name in [k for k in env if k.startswith(("OMPI_", "PMIX_", "PMI_"))]:
        del env[name]
    return env


SCENES = {
    # frictionless thin incompressible layer: the constrained CG
    "frictionless": "&layer thickness = 0.05, poisson = 0.5 /\n&friction coefficient = 0.0 /\n",
    # friction couples the fields (h/lambda 0.05, mu_c 0.5, nu 0.5): the constrained GCR
    "coupled": "&layer thickness = 0.05, poisson = 0.5 /\n&friction coefficient = 0.5 /\n",
    # a sliding standard linear solid (the methods the serial policy plans, distributed as well)
    "viscoelastic": "&layer thickness = 0.05, poisson = 0.5 /\n"
                    "&material model = 'sls', e0 = 1.0, e_inf = 10.0, tau = 1.0, speed = 0.5 /\n"
                    "&friction coefficient = 0.0 /\n",
}
SIZES = {"frictionless": 64, "coupled": 64, "viscoelastic": 128}


def write_scene(directory: Path, name: str, n: int, body: str, output: str,
                observables: str = "stress = .false.", profile: str = "") -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    nml = directory / f"{name}.nml"
    profile = profile or (f"&profile kind = 'self_affine', hurst = 0.8, seed = 3, "
                          f"short_wavelength = {8 / n} /\n")
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n" + body + profile +
        "&loading control = 'load', normalised_pressure = 0.15 /\n"
        "&solver tol = 1e-13 /\n"
        f"&output file = '{output}', overwrite = .true., {observables} /\n")
    return nml


def run_serial(nml: Path) -> subprocess.CompletedProcess:
    return subprocess.run([executable(), str(nml)], cwd=nml.parent, capture_output=True, text=True,
                          env=serial_env(), timeout=600)


def run_mpi(ranks: int, command: list[str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), *command], cwd=cwd, capture_output=True,
                          text=True, env=launcher_env(), timeout=600)


def read(path: Path) -> tuple[dict[str, np.ndarray], dict[str, object], int]:
    with h5py.File(path, "r") as f:
        fields = {k: np.asarray(v) for k, v in f["fields"].items()}
        # (the profile: made on the slabs by the distributed c2r, gathered to rank 0)
        fields["profile height"] = np.asarray(f["profile/height"])
        scalars = dict(f["results"].attrs)
        ranks = int(f.attrs["mpi_ranks"])
    return fields, scalars, ranks


def assert_same(serial: Path, distributed: Path) -> None:
    fields_1, scalars_1, ranks_1 = read(serial)
    fields_p, scalars_p, _ = read(distributed)
    assert ranks_1 == 1
    assert set(fields_1) == set(fields_p)
    for name, field in fields_1.items():
        scale = max(np.max(np.abs(field)), np.finfo(float).tiny)
        assert np.max(np.abs(fields_p[name] - field)) <= SAME * scale, name
    for name, value in scalars_1.items():
        if name in NOT_COMPARED:
            continue
        other = scalars_p[name]
        if isinstance(value, (bytes, str)):
            assert other == value, name
            continue
        a, b = np.asarray(value, float), np.asarray(other, float)
        assert np.all(np.abs(a - b) <= SAME * np.abs(a) + VANISHING), name


def contents(path: Path) -> tuple[dict[str, h5py.Dataset], dict[str, object]]:
    """Every dataset's description and values, and every attribute, by path, of a file."""
    datasets, attributes = {}, {}
    with h5py.File(path, "r") as f:
        def visit(name, item):
            for key, value in item.attrs.items():
                attributes[f"{name}@{key}"] = value
            if isinstance(item, h5py.Dataset):
                datasets[name] = (item.dtype, item.shape, item.chunks, item.compression,
                                  item.compression_opts, item.shuffle, np.asarray(item[()]))
        for key, value in f.attrs.items():
            attributes[f"@{key}"] = value
        f.visititems(visit)
    return datasets, attributes


def assert_same_file(serial: Path, distributed: Path) -> None:
    """The distributed run's file is the serial run's: the same datasets with the same dtype,
    shape, chunks and filters, their values to SAME, and the same attributes (texts equal,
    numbers to SAME), but for what records the run (RUN_RECORD, RUN_DATASETS)."""
    datasets_1, attributes_1 = contents(serial)
    datasets_p, attributes_p = contents(distributed)
    assert set(datasets_1) == set(datasets_p)
    assert set(attributes_1) == set(attributes_p)
    for name, (dtype, shape, chunks, compression, options, shuffle, values) in datasets_1.items():
        other = datasets_p[name]
        assert other[0] == dtype, name
        if name in RUN_DATASETS:
            continue
        assert other[1:6] == (shape, chunks, compression, options, shuffle), name
        if values.dtype.kind in "fc":
            scale = max(np.max(np.abs(values), initial=0.0), np.finfo(float).tiny)
            assert np.max(np.abs(other[6] - values), initial=0.0) <= SAME * scale, name
        else:
            assert np.array_equal(other[6], values), name
    for name, value in attributes_1.items():
        key = name.rsplit("@", 1)[1]
        if key in RUN_RECORD or key.startswith(("wall_time", "residual", "iterations")):
            continue
        other = attributes_p[name]
        if isinstance(value, (bytes, str)):
            assert other == value, name
            continue
        a, b = np.asarray(value, float), np.asarray(other, float)
        close = SAME
        if key.startswith("k_eff"):
            # (the leakage's CG with hypre's distributed BoomerAMG: each run stops within
            # leakage_tol of the exact k_eff, above it; tests/test_mpi_observables.py)
            close = 10 * float(attributes_1[name.rsplit("@", 1)[0] + "@tol"])
        assert np.all(np.abs(a - b) <= close * np.abs(a) + VANISHING), name


#: the observables on the slabs: surface stress, conductance and stiffness, gap histogram
OBSERVABLES = "stress = .true., conductance = .true., gap_bins = 24"


@needs_mpi
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_distributed_files_are_the_serial_file(scene, tmp_path):
    """P = 1..4 ranks, the observables on (stress, conductance, stiffness, gap histogram):
    the whole result file is the serial run's, and @mpi_ranks = P."""
    nml = write_scene(tmp_path / "serial", "scene", SIZES[scene], SCENES[scene], "result.h5", OBSERVABLES)
    done = run_serial(nml)
    assert done.returncode == 0, done.stderr
    for ranks in (1, 2, 3, 4):
        directory = tmp_path / f"ranks{ranks}"
        write_scene(directory, "scene", SIZES[scene], SCENES[scene], "result.h5", OBSERVABLES)
        done = run_mpi(ranks, [executable(), "scene.nml"], directory)
        assert done.returncode == 0, done.stderr
        assert_same_file(nml.parent / "result.h5", directory / "result.h5")
        with h5py.File(directory / "result.h5", "r") as f:
            assert int(f.attrs["mpi_ranks"]) == ranks
            assert int(f["results"].attrs["mpi_ranks"]) == ranks
            assert f["results"].attrs["conductance"] > 0 and f["results"].attrs["contact_stiffness"] > 0
            assert "stress_xy" in f["fields"] and "counts" in f["gap_histogram"]
            # ('auto' plans a shared surface as one process: the serial run's reason)
            with h5py.File(nml.parent / "result.h5", "r") as serial:
                assert f["results"].attrs["solver_reason"] == serial["results"].attrs["solver_reason"]
        # one summary, from rank 0
        assert done.stdout.count("result file") == 1


#: grids, their fine level and coarse levels, and the coarse levels each rank count solves
#: on the slabs (the others: gathered; src/contact/solve.f90: distributed_coarse_rows = 8).
#: 256 x 32: 128 x 16 on the slabs on 2 ranks (8 rows a rank), 64 x 8 (4 a rank) gathered
#: below it; on 3 and 4 ranks (6 and 4 rows a rank) both gathered. 64 x 42: the fine slabs
#: of 2 ranks start at rows 0 and 21 (odd: the second samples its rows 22, 24, ..), the 21
#: coarse rows on the slabs (11 + 10), the last one's next row periodic (row 0); on 3 and
#: 4 ranks (7 and 6 rows a rank) gathered.
COARSE_CASES = {
    "256 x 32": (["128 x 16", "64 x 8"], {1: [], 2: ["128 x 16"], 3: [], 4: []}),
    "64 x 42": (["32 x 21"], {1: [], 2: ["32 x 21"], 3: [], 4: []}),
}


@needs_mpi
@pytest.mark.parametrize("fine", sorted(COARSE_CASES))
def test_coarse_levels_on_the_slabs_and_gathered_give_the_serial_answer(fine, tmp_path):
    """The coarse start on its own slabs (the coarse rows moved between the two slab
    layouts, interpolated with the next coarse row) and, below 8 rows a rank, gathered:
    P = 1..4 give the serial answer, each level where COARSE_CASES says (`&solver verbose`
    names a level solved on the slabs). 64^2 in the test above covers 32 coarse rows on 3
    ranks (11 + 11 + 10, on the slabs).

    The converged answer does not show a wrong start, so each level's own outcome is
    compared with the serial run's too: a coarse level solves the same problem from the
    same start to 1e-4, its iterations, its residual (4 digits) and contact fraction are
    the serial ones unless a row of its heights or start is misplaced; the finest grid's
    iterations are the serial ones unless the interpolated start is (rounding, ~1e-16 of
    the fields, moves neither)."""
    coarse_levels, on_slabs = COARSE_CASES[fine]
    nx, ny = (int(size) for size in fine.split(" x "))

    def scene(name: str, output: str) -> Path:
        nml = write_scene(tmp_path, name, 32, SCENES["coupled"], output)
        text = nml.read_text().replace("&scene geometry = 'areal', n = 32, ny = 32 /\n",
                                       f"&scene geometry = 'areal', nx = {nx}, ny = {ny} /\n")
        nml.write_text(text.replace("&solver tol = 1e-13 /", "&solver tol = 1e-13, verbose = .true. /"))
        return nml

    def levels(log: str) -> dict[str, tuple[str, ...]]:
        found = re.findall(r"(\d+ x \d+)(?: on the slabs of \d ranks)?: gcr converged in (\d+) iterations, "
                           r"residual (\S+), contact fraction (\S+)", log)
        return {level: (iterations,) if level == fine else (iterations, residual, fraction)
                for level, iterations, residual, fraction in found}

    done = run_serial(scene("serial", "serial.h5"))
    assert done.returncode == 0, done.stderr
    serial_levels = levels(done.stderr)
    assert set(serial_levels) == {fine, *coarse_levels}
    for ranks in (1, 2, 3, 4):
        out = f"ranks{ranks}.h5"
        done = run_mpi(ranks, [executable(), str(scene(f"grid{ranks}", out))], tmp_path)
        assert done.returncode == 0, done.stderr
        assert_same(tmp_path / "serial.h5", tmp_path / out)
        for level in coarse_levels:
            slabs = f"{level} on the slabs of {ranks} ranks: gcr converged"
            whole = f"{level}: gcr converged"
            assert (slabs in done.stderr) == (level in on_slabs[ranks]), (ranks, level)
            assert (whole in done.stderr) == (level not in on_slabs[ranks]), (ranks, level)
        if ranks > 1:
            assert f"{fine} on the slabs of {ranks} ranks: gcr converged" in done.stderr
        assert levels(done.stderr) == serial_levels


@needs_mpi
def test_anderson_on_the_slabs_gives_the_serial_answer(tmp_path):
    """&solver method = 'anderson' on the coupled scene: its Gram matrix and projections
    summed over the ranks, the same mixing on every rank; P = 1..4 give the serial answer
    (both converged to tol 1e-13: SAME holds as for the other methods)."""
    nml = write_scene(tmp_path, "serial", 64, SCENES["coupled"], "serial.h5")
    anderson = "&solver method = 'anderson', tol = 1e-13 /"
    nml.write_text(nml.read_text().replace("&solver tol = 1e-13 /", anderson))
    assert "method = 'anderson', tol = 1e-13" in nml.read_text()
    done = run_serial(nml)
    assert done.returncode == 0, done.stderr
    for ranks in (1, 2, 3, 4):
        out = f"ranks{ranks}.h5"
        nml_p = tmp_path / f"anderson{ranks}.nml"
        nml_p.write_text(nml.read_text().replace("'serial.h5'", f"'{out}'"))
        done = run_mpi(ranks, [executable(), str(nml_p)], tmp_path)
        assert done.returncode == 0, done.stderr
        assert_same(tmp_path / "serial.h5", tmp_path / out)
        with h5py.File(tmp_path / out, "r") as f:
            assert f["results"].attrs["solver"].decode() == "anderson"
            assert f["results"].attrs["converged"]
            assert f["results"].attrs["outer_iterations"] > 1


@needs_mpi
@pytest.mark.parametrize("scene", ["coupled", "frictionless"])
def test_threads_within_the_ranks_give_the_serial_answer(scene, tmp_path):
    """Two ranks of two threads each (&solver threads = 2): the rows' blocks and the column
    blocks of each rank's transform are shared out among its threads, each through its
    own buffer (src/fft/plans.F90), and the operator's products are fused into the column
    blocks; the serial run's answer to SAME, and the run records 2 ranks, 2 threads.
    64 rows: 32 a rank, 4 blocks of 8 rows; 33 columns of the half spectrum: 17 and 16 a
    rank, two blocks of 8 and one shorter block on the first."""
    nml = write_scene(tmp_path, "serial", 64, SCENES[scene], "serial.h5")
    done = run_serial(nml)
    assert done.returncode == 0, done.stderr
    threaded = tmp_path / "threaded.nml"
    threaded.write_text(nml.read_text().replace("&solver tol = 1e-13 /", "&solver tol = 1e-13, threads = 2 /")
                        .replace("'serial.h5'", "'threaded.h5'"))
    assert "threads = 2" in threaded.read_text()
    done = run_mpi(2, [executable(), str(threaded)], tmp_path)
    assert done.returncode == 0, done.stderr
    assert_same(tmp_path / "serial.h5", tmp_path / "threaded.h5")
    with h5py.File(tmp_path / "threaded.h5", "r") as f:
        assert int(f.attrs["mpi_ranks"]) == 2
        assert int(f["results"].attrs["omp_threads"]) == 2


@pytest.fixture(scope="module")
def redistribute_program() -> Path:
    """tests/fortran/test_redistribute, built in build/unit when needed."""
    built, program = build_unit_program("test_redistribute")
    assert built.returncode == 0 and program.exists(), built.stdout[-2000:]
    return program


@needs_mpi
@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_rows_move_between_slab_layouts(ranks, redistribute_program):
    """lc_base_parallel's redistribute_rows under mpirun (tests/fortran/test_redistribute.f90:
    every rank checks its rows against the closed form they were made from)."""
    program = redistribute_program
    done = subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), str(program)], capture_output=True,
                          text=True, env=launcher_env(), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("all redistribute_rows checks passed") == ranks
    assert "FAIL" not in done.stdout


@pytest.fixture(scope="module")
def fft_slabs_program() -> Path:
    """tests/fortran/test_fft_slabs, built in build/unit when needed."""
    built, program = build_unit_program("test_fft_slabs")
    assert built.returncode == 0 and program.exists(), built.stdout[-2000:]
    return program


@needs_mpi
@pytest.mark.parametrize("ranks", [2, 3, 4])
def test_products_on_the_slabs_match_the_whole_surface(ranks, fft_slabs_program):
    """lc_fft_plans' products on the slabs (their blocks exchanged between the ranks) against
    the whole surface's on one process, to 1e-13 of the largest value
    (tests/fortran/test_fft_slabs.f90: real and complex multipliers, the energy, the
    solver's passes in the rows' stages; 96 x 70 and 95 x 67 points)."""
    done = subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), str(fft_slabs_program)],
                          capture_output=True, text=True, env=launcher_env(), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("all fft on slabs checks passed") == ranks
    assert "FAIL" not in done.stdout


@needs_mpi
def test_companion_patches_and_leakage(tmp_path):
    """The frictionless companion, the contact patches and the leakage (both on the slabs:
    tests/test_mpi_observables.py): the serial run's file, on 2 and 3 ranks."""
    body = SCENES["coupled"].replace("coefficient = 0.5", "coefficient = 0.5, companion = .true.")
    observables = OBSERVABLES + ", leakage = .true."
    nml = write_scene(tmp_path / "serial", "scene", 64, body, "result.h5", observables)
    assert run_serial(nml).returncode == 0
    for ranks in (2, 3):
        directory = tmp_path / f"ranks{ranks}"
        write_scene(directory, "scene", 64, body, "result.h5", observables)
        done = run_mpi(ranks, [executable(), "scene.nml"], directory)
        assert done.returncode == 0, done.stderr
        assert_same_file(nml.parent / "result.h5", directory / "result.h5")
    with h5py.File(tmp_path / "ranks3" / "result.h5", "r") as f:
        for group in ("", "companion/"):
            # the patches cover the contact: their areas add up to the contact fraction of the
            # cell (period 1 x 1; each node dx dy, exact but for the sum's rounding)
            area = f[group + "patches/area"]
            assert area.size == f[group + "results"].attrs["n_spots"] >= 1
            assert abs(np.sum(area) - f[group + "results"].attrs["contact_fraction"]) <= 1e-12
            assert f[group + "leakage"].attrs["fluid_fraction"] > 0


@needs_mpi
def test_python_run_under_mpirun_gives_the_serial_answer(tmp_path):
    """`mpirun -n P python -m layercontact run` (the same library routine, in-process)."""
    nml = write_scene(tmp_path, "coupled", 64, SCENES["coupled"], "serial.h5")
    assert run_serial(nml).returncode == 0
    for ranks in (2, 3):
        out = f"python{ranks}.h5"
        nml_p = write_scene(tmp_path, f"python{ranks}", 64, SCENES["coupled"], out)
        done = run_mpi(ranks, [sys.executable, "-m", "layercontact", "run", str(nml_p), "--no-png"], tmp_path)
        assert done.returncode == 0, done.stderr
        assert_same(tmp_path / "serial.h5", tmp_path / out)
        assert read(tmp_path / out)[2] == ranks


@needs_mpi
def test_too_many_ranks_for_the_rows_are_refused(tmp_path):
    """ny = 6 on 4 ranks leaves the last without rows (blocks of 2): exit 2 before any work,
    naming the variable, its value and the largest count allowed (3), one message, no file."""
    nml = tmp_path / "few.nml"
    nml.write_text("&scene geometry = 'areal', nx = 8, ny = 6 /\n&loading normalised_pressure = 0.1 /\n"
                   "&output file = 'few.h5' /\n")
    done = run_mpi(4, [executable(), str(nml)], tmp_path)
    assert done.returncode == 2, done.stderr
    assert "&scene ny = 6" in done.stderr and "at most 3 ranks" in done.stderr
    assert done.stderr.count("layercontact: error:") == 1
    assert not (tmp_path / "few.h5").exists()
    # 3 ranks (2 rows each) are allowed
    done = run_mpi(3, [executable(), str(nml)], tmp_path)
    assert done.returncode == 0, done.stderr


@needs_mpi
def test_line_scenes_are_refused_on_several_ranks(tmp_path):
    nml = tmp_path / "line.nml"
    nml.write_text("&scene geometry = 'line', n = 256 /\n&loading normalised_pressure = 0.1 /\n"
                   "&output file = 'line.h5' /\n")
    done = run_mpi(2, [executable(), str(nml)], tmp_path)
    assert done.returncode == 2
    assert "line scenes run on one rank" in done.stderr
    assert not (tmp_path / "line.h5").exists()
    done = run_mpi(2, [sys.executable, "-m", "layercontact", "run", str(nml), "--no-png"], tmp_path)
    assert done.returncode == 2
    assert done.stderr.count("line scenes run on one rank") == 1


@needs_mpi
@pytest.mark.parametrize("n", [2048, 1024])
def test_a_failure_on_one_rank_ends_the_job_with_its_code(n, tmp_path):
    """Rank 1 alone has too little address space (ulimit -v): at 2048² its slab fails the
    memory check (code 5, its message naming the rank); at 1024² the check passes and an
    allocation inside the solve fails in the compiler's runtime, which ends the process
    (the job is then ended with code 5 rather than left waiting: src/base/launcher.c). Both
    end the job with exit 5; the result file of an earlier run is left as it was (the file
    is written to a temporary name and renamed)."""
    nml = write_scene(tmp_path, "big", n, SCENES["coupled"], "big.h5")
    (tmp_path / "big.h5").write_bytes(b"")
    earlier = h5py.File(tmp_path / "big.h5", "w")
    earlier.attrs["earlier"] = 1
    earlier.close()
    before = (tmp_path / "big.h5").read_bytes()
    wrapper = tmp_path / "rank1_limited.sh"
    wrapper.write_text('#!/bin/sh\nif [ "$OMPI_COMM_WORLD_RANK" = 1 ]; then ulimit -v 450000; fi\nexec "$@"\n')
    wrapper.chmod(0o755)
    done = run_mpi(2, [str(wrapper), executable(), str(nml)], tmp_path)
    assert done.returncode == 5, done.stderr
    if n == 2048:
        assert "error on MPI rank 1 of 2" in done.stderr
    else:
        assert "error on MPI rank 1 of 2" in done.stderr or "allocat" in done.stderr.lower()
    assert (tmp_path / "big.h5").read_bytes() == before


@needs_mpi
def test_height_files_by_slabs(tmp_path):
    """A height file that is one period of the grid is read by slabs (each rank its rows of
    the HDF5 dataset, or of a .npy file that rank 0 reads and scatters) and detrended on the
    slabs: a self-affine surface plus a tilt, detrend = 'plane', gives the serial run's file
    on 2 and 3 ranks. Kept tilted (detrend = 'none') it is not periodic: the warning that
    says so, computed over the slabs (the tilt is along y: its edges are the first and last
    rows, on the first and last ranks), is printed once, with the serial run's jump and
    kink."""
    source = write_scene(tmp_path / "source", "scene", 64, SCENES["coupled"], "result.h5")
    assert run_serial(source).returncode == 0
    with h5py.File(source.parent / "result.h5", "r") as f:
        surface = np.asarray(f["profile/height"]).reshape(64, 64)
    # a rise of 4 rms heights over the cell along y: the tilted surface's heights jump by 2.6
    # of its rms heights across the edges (the warning's limit: 2)
    tilted = surface + 4 * surface.std() * np.arange(64)[:, None] / 64
    for name in ("heights.h5", "heights.npy"):
        for detrend in ("plane", "none"):
            profile = f"&profile kind = 'file', file = '../{name}', dataset = 'h', detrend = '{detrend}' /\n"
            runs = {"serial": 1, "ranks2": 2, "ranks3": 3}
            for directory, ranks in runs.items():
                nml = write_scene(tmp_path / detrend / name / directory, "scene", 64, SCENES["coupled"],
                                  "result.h5", profile=profile)
                target = nml.parent.parent / name
                if name.endswith(".h5"):
                    with h5py.File(target, "w") as f:
                        f["h"] = tilted
                else:
                    np.save(target, tilted)
                if ranks == 1:
                    done = run_serial(nml)
                else:
                    done = run_mpi(ranks, [executable(), "scene.nml"], nml.parent)
                assert done.returncode == 0, done.stderr
                # (detrended by the plane the surface is periodic again: no warning)
                warnings = [line for line in done.stderr.splitlines() if "is taken as one period" in line]
                assert len(warnings) == (1 if detrend == "none" else 0), done.stderr
                # (the same jump and kink, as printed: 2 decimals and 3 digits)
                if ranks == 1:
                    serial_warnings = warnings
                assert warnings == serial_warnings
            for directory in ("ranks2", "ranks3"):
                assert_same_file(tmp_path / detrend / name / "serial" / "result.h5",
                                 tmp_path / detrend / name / directory / "result.h5")


@needs_mpi
@pytest.mark.parametrize("name", ["patch.h5", "patch.npy"])
def test_mirrored_height_files_by_slabs(name, tmp_path):
    """A patch mirrored to the grid (boundary = 'mirror') is read by slabs too: detrended on
    the file's slabs by its plane (detrend = 'auto'), then each rank takes the file rows its
    slab of the mirrored grid holds, in the mirror image along y where it lies past the
    patch. A 25 x 16 patch (ny x nx: a 50 x 32 grid, its rows split unevenly on 3 and 4
    ranks, where a slab straddles the patch's edge) of a random surface with a tilt along y gives the serial run's file on 2 to 4 ranks; without &scene n the grid is the
    mirrored patch's on every rank count."""
    rng = np.random.default_rng(5)
    ky, kx = np.meshgrid(np.fft.fftfreq(25) * 25, np.fft.fftfreq(16) * 16, indexing="ij")
    spectrum = (rng.standard_normal((25, 16)) + 1j * rng.standard_normal((25, 16))) / (1 + kx**2 + ky**2)
    patch = np.fft.ifft2(spectrum).real
    patch = 0.05 * patch / patch.std() + 0.02 * np.arange(25)[:, None] / 25
    for grid in ("given", "from the file"):
        scene = "&scene geometry = 'areal', n = 32, ny = 50 /\n" if grid == "given" else "&scene geometry = 'areal' /\n"
        for ranks in (1, 2, 3, 4):
            directory = tmp_path / grid.replace(" ", "_") / f"ranks{ranks}"
            directory.mkdir(parents=True)
            if name.endswith(".h5"):
                with h5py.File(directory / name, "w") as f:
                    f["h"] = patch
            else:
                np.save(directory / name, patch)
            (directory / "scene.nml").write_text(
                scene + SCENES["coupled"] +
                f"&profile kind = 'file', file = '{name}', dataset = 'h', boundary = 'mirror' /\n"
                "&loading control = 'load', normalised_pressure = 0.15 /\n&solver tol = 1e-13 /\n"
                "&output file = 'result.h5', overwrite = .true., stress = .false. /\n")
            if ranks == 1:
                done = run_serial(directory / "scene.nml")
            else:
                done = run_mpi(ranks, [executable(), "scene.nml"], directory)
            assert done.returncode == 0, done.stderr
        with h5py.File(tmp_path / grid.replace(" ", "_") / "ranks1" / "result.h5", "r") as f:
            height = np.asarray(f["profile/height"]).reshape(50, 32)
        # (the serial heights are the mirror images of the detrended patch: an independent
        # check that the file compared against is the mirrored surface)
        assert np.array_equal(height[:25, :16], height[:25, :15:-1]) and np.array_equal(height[:25], height[:24:-1])
        for ranks in (2, 3, 4):
            assert_same_file(tmp_path / grid.replace(" ", "_") / "ranks1" / "result.h5",
                             tmp_path / grid.replace(" ", "_") / f"ranks{ranks}" / "result.h5")


@needs_mpi
@pytest.mark.parametrize("boundary", ["periodic", "mirror"])
def test_resampled_height_files_by_slabs(boundary, tmp_path):
    """A file resampled to the grid (resample = 'fourier') is read and resampled on the
    slabs: each row along x, then each column along y on blocks of columns. A 20 x 24 file
    (ny x nx; mirrored: a 40 x 48 surface) onto a 50 x 32 grid gives the serial run's file on
    2-4 ranks (to 1e-10: the same map, its transforms in another order). The file is a
    band-limited periodic surface, two oblique waves below both grids' Nyquist modes: the
    serial heights are its values on the grid (to 1e-12: FFT rounding on heights of order
    0.05), an independent check of what the runs are compared against."""
    ny_file, nx_file = 20, 24
    y, x = np.meshgrid(np.arange(ny_file) / ny_file, np.arange(nx_file) / nx_file, indexing="ij")

    def waves(x, y):
        return 0.03 * np.cos(2 * np.pi * (2 * x + 3 * y)) + 0.02 * np.sin(2 * np.pi * (5 * x - 4 * y) + 0.3)

    for ranks in (1, 2, 3, 4):
        directory = tmp_path / f"ranks{ranks}"
        directory.mkdir()
        with h5py.File(directory / "heights.h5", "w") as f:
            f["h"] = waves(x, y)
        (directory / "scene.nml").write_text(
            "&scene geometry = 'areal', n = 32, ny = 50 /\n" + SCENES["coupled"] +
            f"&profile kind = 'file', file = 'heights.h5', dataset = 'h', boundary = '{boundary}', "
            "detrend = 'none', resample = 'fourier' /\n"
            "&loading control = 'load', normalised_pressure = 0.15 /\n&solver tol = 1e-13 /\n"
            "&output file = 'result.h5', overwrite = .true., stress = .false. /\n")
        done = run_serial(directory / "scene.nml") if ranks == 1 else run_mpi(ranks, [executable(), "scene.nml"],
                                                                             directory)
        assert done.returncode == 0, done.stderr
    if boundary == "periodic":
        with h5py.File(tmp_path / "ranks1" / "result.h5", "r") as f:
            height = np.asarray(f["profile/height"]).reshape(50, 32)
        y, x = np.meshgrid(np.arange(50) / 50, np.arange(32) / 32, indexing="ij")
        assert np.abs(height - waves(x, y)).max() < 1e-12
    for ranks in (2, 3, 4):
        assert_same_file(tmp_path / "ranks1" / "result.h5", tmp_path / f"ranks{ranks}" / "result.h5")

@needs_mpi
@pytest.mark.parametrize("profile", ["&profile kind = 'sinusoid', amplitude = 0.05, mode = 2, mode_y = -3 /\n",
                                     "&profile kind = 'sphere', radius = 2.0 /\n"])
def test_sinusoid_and_sphere_by_slabs(profile, tmp_path):
    """An oblique sinusoid and a spherical cap are made row by row on each rank's slab (no
    rank makes the whole surface): the serial run's file on 2, 3 and 4 ranks (50 rows: 3
    and 4 ranks split them unevenly)."""
    for ranks in (1, 2, 3, 4):
        nml = write_scene(tmp_path / f"ranks{ranks}", "scene", 50, SCENES["frictionless"], "result.h5",
                          profile=profile)
        done = run_serial(nml) if ranks == 1 else run_mpi(ranks, [executable(), "scene.nml"], nml.parent)
        assert done.returncode == 0, done.stderr
    for ranks in (2, 3, 4):
        assert_same_file(tmp_path / "ranks1" / "result.h5", tmp_path / f"ranks{ranks}" / "result.h5")
