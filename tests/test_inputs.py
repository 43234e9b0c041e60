"""Every scene in inputs/ runs, through the executable and through Python, with the same
result; bad input gives a clear error naming group and variable, exit code 2, and
writes nothing; an existing result is not overwritten unless the input says so."""

import os
import re
import shutil
import subprocess
import sys
import sysconfig
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

import layercontact as lc
from conftest import ROOT

INPUTS = sorted((ROOT / "inputs").glob("*.nml"))


def executable() -> str:
    """The installed `layercontact` program (next to this Python's scripts)."""
    found = shutil.which("layercontact") or shutil.which("layercontact", path=sysconfig.get_path("scripts"))
    assert found, "the layercontact executable is not installed (pip install . puts it in the venv's bin/)"
    return found


def run_exe(nml: Path, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([executable(), str(nml)], cwd=cwd, capture_output=True, text=True, timeout=600)


def run_example(name: str, directory: Path) -> subprocess.CompletedProcess:
    """Run inputs/NAME.nml through the executable in `directory` (its result goes there)."""
    nml = directory / f"{name}.nml"
    nml.write_text((ROOT / "inputs" / f"{name}.nml").read_text())
    return run_exe(nml, directory)


@pytest.fixture(scope="module")
def default_result(tmp_path_factory) -> Path:
    """The result file of inputs/default.nml, run once for the checks that read it."""
    directory = tmp_path_factory.mktemp("default")
    proc = run_example("default", directory)
    assert proc.returncode == 0, proc.stderr
    return directory / "out" / "default.h5"


@pytest.mark.parametrize("nml", INPUTS, ids=[p.stem for p in INPUTS])
def test_every_input_runs_the_same_in_fortran_and_python(nml, tmp_path, monkeypatch):
    exe_dir, py_dir = tmp_path / "exe", tmp_path / "py"
    exe_dir.mkdir()
    py_dir.mkdir()
    proc = run_exe(nml, exe_dir)
    assert proc.returncode == 0, proc.stderr
    assert "contact fraction" in proc.stdout
    monkeypatch.chdir(py_dir)
    # the program is the portable build: so is the comparison (the x86-64-v3 core agrees to
    # rounding, tests/test_build.py)
    monkeypatch.setattr(lc.api, "_core", lc.native.portable)
    res = lc.run(nml)
    out = next(exe_dir.rglob("*.h5"))
    with h5py.File(out) as f:
        tol = f["input"].attrs["tol"]   # the scene's, or the one &solver target_error chose
    assert res.converged and res.residual <= tol <= 1e-6
    ref = lc.read_result(out)
    assert not list(exe_dir.rglob("*.tmp"))
    np.testing.assert_array_equal(res.pressure, ref.pressure)
    assert res.penetration == ref.penetration and res.delta_mu == ref.delta_mu
    # the method that ran is recorded; the first it tried is a symmetric one (CG or
    # multigrid) exactly where the operator is symmetric: a frictionless companion is, unless
    # a moving viscoelastic layer dissipates (the fallbacks after it may vary with rounding)
    symmetric = ("cg", "multigrid")
    first = lambda solver: solver.split("+")[0]  # noqa: E731
    assert res.solver == ref.solver and first(ref.solver) in symmetric + ("gcr",)
    if ref.companion is not None:
        assert (first(ref.companion.solver) in symmetric) == (first(ref.solver) in symmetric
                                                              or ref.dissipated_power == 0.0)
    with h5py.File(out) as f:
        assert f.attrs["layercontact_version"].decode() == lc.__version__
        assert f.attrs["layercontact_build"].decode() == "x86-64"
        assert f["input/namelist"][()].decode() == nml.read_text()
        # a line's fields hold n values; an areal scene's are (ny, nx) maps
        grid = (f["input"].attrs["n"],)
        if f.attrs["geometry"].decode() == "areal":
            grid = (f["input"].attrs["ny"], f["input"].attrs["n"])
        assert f["fields/pressure"].shape == grid


BAD = [
    ("&material\n model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'absent_terms.txt'\n/\n",
     "&material: prony_file = 'absent_terms.txt' is not allowed; allowed: an existing text file"),
    ("&profile\n kindd = 'sinusoid'\n/\n", "allowed variables in &profile: kind, hurst, seed, rolloff_wavelength, "
     "short_wavelength, rms_gradient, rms_height, amplitude, mode, mode_y, radius, file, dataset, detrend, boundary, "
     "resample"),
    ("&output\n file = 'bad.h5'\n leakag = .true.\n/\n",
     "allowed variables in &output: file, overwrite, stress, gap_bins, fields, precision, leakage, leakage_tol, "
     "conductance, conductivity, conductance_base"),
    ("&layer\n thickness = -1.0\n/\n", "&layer: thickness"),
    ("&layer\n poisson = 0.7\n/\n", "-1 < poisson <= 0.5"),
    ("&layr\n thickness = 1.0\n/\n", "line 1: unknown namelist group '&layr'"),
    ("&scene\n n = 64\n/\n&layer\n thicknes = 1.0\n/\n", "line 5, group &layer: Cannot match namelist object name thicknes"),
    ("&friction\n coefficient = -0.1\n/\n", "&friction: coefficient"),
    ("&loading\n mean_pressure = 0.1\n normalised_pressure = 1.0\n/\n", "exactly one of them"),
    ("&profile\n hurst = 1.2\n/\n", "&profile: hurst"),
    ("&solver\n tol = 0.5\n/\n", "&solver: tol"),
    # a negative value is refused like any other (no number means "not given")
    ("&profile\n rms_gradient = -1.0\n/\n", "&profile: rms_gradient"),
    ("&loading\n mean_pressure = -1.0\n/\n", "&loading: mean_pressure"),
    ("&profile\n short_wavelength = -1.0\n/\n", "&profile: short_wavelength"),
    ("&solver\n method = 'gmres'\n/\n", "'auto', 'cg', 'gcr', 'anderson', 'gfmd', 'newton' or 'multigrid'"),
    ("&loading\n control = 'displacement'\n penetration = 1e-3\n/\n", "needs a finite layer"),
    ("&loading\n normalised_pressure = 1.0\n penetration = 1e-3\n/\n", "&loading: penetration"),
    ("&profile\n kind = 'sinusoid'\n amplitude = 0.1\n mode = 2000000000\n/\n", "&profile: mode"),
    ("&solver\n max_iter = 2000000000\n/\n", "&solver: max_iter"),
    ("&layer\n thickness = 0.1\n/\n poisson = 0.3\n", "line 4: text outside a namelist group"),
    # a value of the wrong type names the value, the variable and what it takes
    ("&scene\n n = 4096.5\n/\n", "line 2, group &scene: 'n = 4096.5': n takes an integer"),
    ("&scene\n n = 1e3\n/\n", "'n = 1e3': n takes an integer (no decimal point or exponent)"),
    ("&layer\n thickness = .true.\n/\n", "'thickness = .true.': thickness takes a number"),
    ("&layer\n poisson = half\n/\n", "'poisson = half': poisson takes a number"),
    ("&solver\n tol = 1e-8\n precondition = 1.5\n/\n",
     "line 3, group &solver: 'precondition = 1.5': precondition takes .true. or .false."),
    ("&friction\n companion = yes\n/\n", "'companion = yes': companion takes .true. or .false."),
    ("&material\n model = 'prony'\n prony_times(100) = 1.0\n/\n",
     "line 3, group &material: Index 1 out of range for namelist variable prony_times (prony_times and "
     "prony_values hold at most 64 terms"),
    # every range of the scene's check: the group, the variable, the value and what is allowed
    ("&scene\n geometry = 'volume'\n/\n", "&scene: geometry = volume is not allowed; allowed: 'line' or 'areal'"),
    ("&scene\n period = 0.0\n/\n", "&scene: period = 0"),
    ("&scene\n n = 4\n/\n", "allowed: 8 <= n <= 2**26"),
    ("&scene\n n = 128\n ny = 16\n/\n", "line 3, group &scene: ny = 16 is not allowed; allowed: not given with "
     "geometry = 'line' (ny applies to surfaces only, geometry = 'areal')"),
    ("&scene\n geometry = 'areal'\n n = 2\n/\n", "allowed: 4 <= nx <= 65536 with geometry = 'areal'"),
    ("&scene\n geometry = 'areal'\n nx = 64\n ny = 100000\n/\n", "allowed: 4 <= ny <= 65536"),
    ("&scene\n geometry = 'areal'\n nx = 65536\n ny = 65536\n/\n", "&scene: nx*ny"),
    ("&scene\n geometry = 'areal'\n n = 64\n period_y = -2.0\n/\n", "&scene: period_y"),
    ("&layer\n young = 0.0\n/\n", "&layer: young = 0"),
    ("&layer\n poisson = -1.0\n/\n", "allowed: -1 < poisson <= 0.5"),
    ("&material\n speed = -1.0\n/\n", "&material: speed"),
    ("&friction\n coefficient = 11.0\n/\n", "allowed: 0 <= coefficient <= 10"),
    ("&profile\n kind = 'fractal'\n/\n", "allowed: 'self_affine', 'sinusoid' or 'file'"),
    ("&profile\n kind = 'sphere'\n/\n", "allowed: 'self_affine', 'sinusoid' or 'file'"),
    ("&profile\n hurst = 0.0\n/\n", "allowed: 0 < hurst < 1"),
    ("&profile\n seed = -3\n/\n", "&profile: seed = -3"),
    ("&profile\n rolloff_wavelength = 2.0\n/\n", "&profile: rolloff_wavelength"),
    ("&profile\n short_wavelength = 1e-6\n/\n", "at least two grid points per wavelength"),
    ("&profile\n rms_gradient = 0.1\n rms_height = 0.01\n/\n", "allowed: at most one of them"),
    ("&profile\n rms_height = 0.0\n/\n", "&profile: rms_height"),
    ("&profile\n kind = 'sinusoid'\n amplitude = -0.1\n/\n", "&profile: amplitude"),
    ("&profile\n kind = 'sinusoid'\n amplitude = 0.1\n mode = 0\n/\n", "allowed: 1 <= mode <= (n-1)/2"),
    ("&scene\n geometry = 'areal'\n n = 64\n/\n&profile\n kind = 'sinusoid'\n amplitude = 0.1\n mode = 0\n"
     " mode_y = 0\n/\n", "not both zero (a flat surface)"),
    ("&scene\n geometry = 'areal'\n n = 64\n/\n&profile\n kind = 'sinusoid'\n amplitude = 0.1\n mode = 1\n"
     " mode_y = 40\n/\n", "&profile: mode_y"),
    ("&scene\n geometry = 'areal'\n n = 64\n/\n&profile\n kind = 'sphere'\n radius = -1.0\n/\n",
     "&profile: radius"),
    ("&profile\n kind = 'file'\n/\n", "&profile: file"),
    ("&profile\n kind = 'file'\n file = 'x.h5'\n detrend = 'tilt'\n/\n",
     "&profile: detrend = 'tilt' is not allowed; allowed: 'auto', 'none', 'mean', 'plane' or 'curvature'"),
    ("&profile\n kind = 'file'\n file = 'x.h5'\n boundary = 'pad'\n/\n", "&profile: boundary = 'pad'"),
    ("&profile\n resample = 'fourier'\n/\n", "&profile: resample = 'fourier' is not allowed; allowed: not set"),
    ("&loading\n control = 'force'\n/\n", "allowed: 'load' or 'displacement'"),
    ("&loading\n normalised_pressure = 0.0\n/\n", "&loading: normalised_pressure = 0"),
    ("&layer\n poisson = 0.3\n/\n&loading\n control = 'displacement'\n penetration = -1e-3\n/\n",
     "&loading: penetration"),
    ("&solver\n tol = 1e-16\n/\n", "allowed: 1e-14 <= tol <= 1e-2"),
    ("&output\n gap_bins = -1\n/\n", "twice (at most once each)"),   # the harness adds its own &output
    ("&solver\n max_iter = 0\n/\n", "allowed: 1 <= max_iter <= 10000000"),
    ("&solver\n memory = 0\n/\n", "allowed: 1 <= memory <= 100"),
    ("&solver\n threads = -1\n/\n", "allowed: 0 <= threads <= 1024"),
    ("&solver\n target_error = 0.9\n/\n", "&solver: target_error"),
    ("&profile\n kind = 'file'\n file = 'nope.h5'\n/\n", "&profile: file = 'nope.h5' is not found"),
    # strings that the scene could keep only cut are refused, not cut
    (f"&scene\n title = '{'t' * 513}'\n/\n", "group &scene: title = 'tttttttttttttttttttttttt...' is longer than 512"),
    (f"&material\n model = 'prony'\n prony_file = '{'p' * 600}'\n/\n", "prony_file = 'pppp"),
    (f"&profile\n kind = 'file'\n file = 'x.h5'\n dataset = '/{'d' * 520}'\n/\n", "dataset = '/ddd"),
    (f"&solver\n method = '{'m' * 700}'\n/\n", "method = 'mmm"),
    # the leakage needs an areal gap (cases that bring their own &output, writing bad.h5)
    ("&output\n file = 'bad.h5'\n leakage = .true.\n/\n",
     "group &output: leakage = .true. is not allowed; allowed: not given with geometry = 'line' (leakage applies "
     "to surfaces only"),
    ("&scene\n geometry = 'areal'\n n = 32\n/\n&output\n file = 'bad.h5'\n leakage = .true.\n leakage_tol = 0.5\n/\n",
     "&output: leakage_tol = 5.00000E-01 is not allowed; allowed: 1e-14 <= leakage_tol <= 1e-2"),
    ("&output\n file = 'bad.h5'\n leakage = 1\n/\n", "'leakage = 1': leakage takes .true. or .false."),
    # a variable given twice, or under both of its names, is refused (the read would keep the
    # last one silently), naming the group, the lines and which one to keep
    ("&scene\n n = 64\n period = 2.0\n n = 128\n/\n", "line 4, group &scene: n is given twice (lines 2 and 4); "
     "allowed: one assignment of each variable: keep the one you mean and remove the other"),
    ("&scene\n period = 2.0, period_x = 3.0\n/\n", "line 2, group &scene: period and period_x are both given "
     "(lines 2 and 2) and are two names of one variable; allowed: one of them: keep period"),
    ("&scene\n geometry = 'areal'\n n = 64\n nx = 32\n/\n", "group &scene: n and nx are both given"),
    ("&layer\n thickness = 0.1\n/\n&friction\n coefficient = 0.1\n coefficient = 0.2\n/\n",
     "line 6, group &friction: coefficient is given twice (lines 5 and 6)"),
    ("&solver\n tol = 1e-8\n TOL = 1e-9\n/\n", "group &solver: tol is given twice"),
    # the variables of surfaces only are refused in a line scene (it would ignore them)
    ("&scene\n period_y = 2.0\n/\n", "line 2, group &scene: period_y = 2.0 is not allowed; allowed: not given "
     "with geometry = 'line' (period_y applies to surfaces only, geometry = 'areal')"),
    ("&scene\n nx = 64\n/\n", "group &scene: nx = 64 is not allowed; allowed: not given with geometry = 'line'"),
    ("&profile\n kind = 'sinusoid'\n amplitude = 0.1\n mode_y = 1\n/\n",
     "line 4, group &profile: mode_y = 1 is not allowed; allowed: not given with geometry = 'line' (mode_y "
     "applies to surfaces only"),
    ("&profile\n kind = 'sinusoid'\n amplitude = 0.1\n radius = 2.0\n/\n", "radius applies to surfaces only"),
    ("&output\n file = 'bad.h5'\n leakage_tol = 1e-8\n/\n", "leakage_tol applies to surfaces only"),
]


@pytest.mark.parametrize("text, message", BAD, ids=[m for _, m in BAD])
def test_bad_input_is_refused_and_writes_nothing(text, message, tmp_path, monkeypatch):
    base = "&loading\n normalised_pressure = 1.0\n/\n" if "&loading" not in text else ""
    nml = tmp_path / "bad.nml"
    output = "" if "file = 'bad.h5'" in text else "&output\n file = 'bad.h5'\n/\n"
    nml.write_text(text + base + output)
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr
    assert not (tmp_path / "bad.h5").exists() and not list(tmp_path.glob("*.tmp"))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(lc.LayercontactError) as err:
        lc.run(nml)
    assert err.value.code == 2 and message in str(err.value)


def scene_writing(path: Path, output: str, overwrite: bool = False, n: int = 256) -> Path:
    path.write_text(f"&scene\n n = {n}\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                    f"&output\n file = '{output}'\n overwrite = {'.true.' if overwrite else '.false.'}\n/\n")
    return path


def test_existing_result_is_not_overwritten(tmp_path):
    nml = scene_writing(tmp_path / "scene.nml", "r.h5")
    with h5py.File(tmp_path / "r.h5", "w") as f:
        f.attrs["note"] = "precious"
    before = (tmp_path / "r.h5").read_bytes()
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 4 and "set &output overwrite = .true." in proc.stderr
    assert (tmp_path / "r.h5").read_bytes() == before
    assert not list(tmp_path.glob("*.tmp"))


@pytest.mark.parametrize("kind", ["data", "directory", "device"])
def test_what_is_not_a_result_file_is_never_replaced(kind, tmp_path):
    """Even with overwrite = .true., an existing path that is not an HDF5 file (other data,
    a directory, a device such as /dev/null) is refused with exit 4 and left as it was."""
    target = {"data": tmp_path / "r.h5", "directory": tmp_path / "d.h5", "device": Path("/dev/null")}[kind]
    if kind == "data":
        target.write_bytes(b"precious")
    elif kind == "directory":
        target.mkdir()
    nml = scene_writing(tmp_path / "scene.nml", str(target), overwrite=True)
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 4, proc.stderr
    assert f"output file '{target}' exists and is not an HDF5 file" in proc.stderr
    if kind == "data":
        assert target.read_bytes() == b"precious"
    elif kind == "directory":
        assert target.is_dir() and not any(target.iterdir())
    else:
        assert target.is_char_device()
    assert not list(tmp_path.glob("*.tmp")) and not list(Path("/dev").glob("null.*.tmp"))


def test_two_runs_writing_one_file_lose_nothing(tmp_path):
    """Two runs started together with the same output (overwrite = .false.) each write
    their own temporary file; the first to finish places the result, the second finds it
    there, exits 4 and replaces nothing: one complete result, no temporary file left."""
    nml = scene_writing(tmp_path / "scene.nml", "r.h5", n=262144)
    runs = [subprocess.Popen([executable(), str(nml)], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True) for _ in range(2)]
    outcomes = sorted((proc.wait(timeout=600), proc.stderr.read()) for proc in runs)
    for proc in runs:
        proc.stdout.close()
        proc.stderr.close()
    assert [code for code, _ in outcomes] == [0, 4], outcomes
    assert "was written by another run while this one computed" in outcomes[1][1]
    with h5py.File(tmp_path / "r.h5") as f:
        assert f["fields/pressure"].shape == (262144,) and f["results"].attrs["converged"] == 1
    assert not list(tmp_path.glob("*.tmp"))


def test_not_converged_exits_3_and_writes_flagged_result(tmp_path):
    nml = tmp_path / "scene.nml"
    nml.write_text(
        "&scene\n n = 1024\n/\n&layer\n thickness = 0.01\n/\n&friction\n coefficient = 1.0\n/\n"
        "&loading\n normalised_pressure = 30.0\n/\n&solver\n max_iter = 10\n/\n&output\n file = 'r.h5'\n/\n"
    )
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 3
    with h5py.File(tmp_path / "r.h5") as f:
        assert f["results"].attrs["converged"] == 0 and f["results"].attrs["residual"] > 1e-10


def test_profile_from_hdf5_file(tmp_path):
    """&profile kind = 'file': heights read from an HDF5 dataset, stored unchanged, and
    the same solution as solving the array from Python."""
    h = lc.self_affine_profile(512, 0.6, seed=9, short_wavelength=1 / 32)
    with h5py.File(tmp_path / "measured.h5", "w") as f:
        f["/topography/heights"] = h
    nml = tmp_path / "scene.nml"
    nml.write_text(
        "&scene\n n = 512\n/\n&layer\n thickness = 0.3\n poisson = 0.4\n/\n&friction\n coefficient = 0.4\n/\n"
        "&profile\n kind = 'file'\n file = 'measured.h5'\n dataset = '/topography/heights'\n/\n"
        "&loading\n mean_pressure = 0.002\n/\n&output\n file = 'r.h5'\n/\n"
    )
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 0, proc.stderr
    res = lc.read_result(tmp_path / "r.h5")
    np.testing.assert_array_equal(res.height, h)
    ref = lc.solve_line(h, thickness=0.3, poisson=0.4, friction=0.4, mean_pressure=0.002)
    np.testing.assert_allclose(res.pressure, ref.pressure, rtol=0, atol=1e-12 * ref.pressure.max())

    wrong = tmp_path / "wrong.nml"
    wrong.write_text(nml.read_text().replace("n = 512", "n = 256").replace("'r.h5'", "'w.h5'"))
    proc = run_exe(wrong, tmp_path)
    assert proc.returncode == 2 and "512" in proc.stderr and not (tmp_path / "w.h5").exists()


def test_executable_usage_help_and_version():
    """No argument is a usage error (exit 1, on stderr); --help and --version print and exit 0."""
    exe = executable()
    none = subprocess.run([exe], capture_output=True, text=True, timeout=60)
    assert none.returncode == 1 and "usage: layercontact FILE.nml" in none.stderr
    helped = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=60)
    assert helped.returncode == 0 and "Exit codes: 0 converged; 1 usage; 2 bad input" in helped.stdout
    version = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=60)
    assert version.returncode == 0 and version.stdout.split()[:2] == ["layercontact", lc.__version__]


@pytest.mark.parametrize("bad", [np.nan, np.inf], ids=["nan", "inf"])
def test_heights_that_are_not_finite_are_refused(bad, tmp_path):
    """NaN or Inf heights, from Python or from a file, are bad input (code 2), not a run
    with NaN fields; the executable writes nothing."""
    line = np.cos(2 * np.pi * np.arange(64) / 64)
    line[5] = bad
    with pytest.raises(lc.LayercontactError, match="NaN or infinite") as err:
        lc.solve_line(line, mean_pressure=0.1)
    assert err.value.code == 2
    with pytest.raises(lc.LayercontactError, match="NaN or infinite"):
        lc.solve_areal(np.tile(line, (8, 1)), mean_pressure=0.1)
    with h5py.File(tmp_path / "measured.h5", "w") as f:
        f["/profile/height"] = line
    nml = tmp_path / "scene.nml"
    nml.write_text("&scene\n n = 64\n/\n&profile\n kind = 'file'\n file = 'measured.h5'\n/\n"
                   "&loading\n mean_pressure = 0.1\n/\n&output\n file = 'r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2 and "&profile" in proc.stderr
    assert not (tmp_path / "r.h5").exists()


def test_flat_profile_with_a_normalised_pressure_is_refused(tmp_path):
    """A flat profile has no relief for the seed's line pressure scale: p_m would be 0."""
    with h5py.File(tmp_path / "flat.h5", "w") as f:
        f["/profile/height"] = np.zeros(64)
    nml = tmp_path / "scene.nml"
    nml.write_text("&scene\n n = 64\n/\n&profile\n kind = 'file'\n file = 'flat.h5'\n/\n"
                   "&loading\n normalised_pressure = 1.0\n/\n&output\n file = 'r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2 and "&loading: normalised_pressure" in proc.stderr
    assert not (tmp_path / "r.h5").exists()


def test_verbose_solver_reports_progress_on_stderr(tmp_path):
    """&solver verbose = .true.: a progress line per grid level on standard error, the
    finest with the iterations the result file records; the default is silent."""
    text = (ROOT / "inputs" / "default.nml").read_text()
    quiet = tmp_path / "quiet.nml"
    quiet.write_text(text)
    loud = tmp_path / "loud.nml"
    loud.write_text(text.replace("&solver", "&solver\n   verbose = .true.", 1))
    assert "verbose = .true." in loud.read_text()
    proc = run_exe(quiet, tmp_path)
    assert proc.returncode == 0 and proc.stderr == ""
    (tmp_path / "out" / "default.h5").unlink()
    proc = run_exe(loud, tmp_path)
    assert proc.returncode == 0, proc.stderr
    # the scene (GCR, with friction) level by level, then its frictionless companion
    # (multigrid, which makes its own nested iteration: one line)
    done = [line for line in proc.stderr.splitlines() if " converged in " in line]
    with h5py.File(tmp_path / "out" / "default.h5") as f:
        iterations = {group: int(f[group].attrs["iterations"]) for group in ("/results", "/companion/results")}
    finest = [line for line in done if line.startswith("layercontact: n = 4096: ")]
    assert len(finest) == 2 and len(done) == 5   # 512, 1024, 2048, 4096 (the scene's n), 4096
    assert f"gcr converged in {iterations['/results']} iterations" in finest[0]
    assert f"multigrid converged in {iterations['/companion/results']} iterations" in finest[1]


def limited_address_space(gib: float):
    """A preexec_fn: the child may map at most `gib` GiB (ulimit -v)."""
    import resource

    def limit():
        size = int(gib * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (size, size))
    return limit


def test_a_grid_too_large_for_the_memory_ends_with_code_5_and_writes_nothing(tmp_path):
    """Under ulimit -v 2 GiB an areal coupled scene of 4096^2 points (about 9.0 GiB: method
    'auto' may take the multigrid method there) is refused before it allocates: exit 5, a
    message with what it needs and which limit; 256^2 runs under the same limit."""
    text = ("&scene\n geometry = 'areal'\n n = {n}\n/\n&layer\n thickness = 0.16\n/\n&friction\n coefficient = 0.5\n/\n"
            "&loading\n normalised_pressure = 0.1\n/\n&output\n file = 'r{n}.h5'\n/\n")
    for n, code in ((4096, 5), (256, 0)):
        nml = tmp_path / f"s{n}.nml"
        nml.write_text(text.format(n=n))
        proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                              preexec_fn=limited_address_space(2.0))
        assert proc.returncode == code, proc.stderr
        if code == 5:
            assert "not enough memory: this scene (16777216 grid points) needs about 9.0 GiB" in proc.stderr
            assert "the address space limit (ulimit -v)" in proc.stderr and "Slurm: --mem" in proc.stderr
            assert not (tmp_path / f"r{n}.h5").exists() and not list(tmp_path.glob("*.tmp"))
        else:
            assert (tmp_path / f"r{n}.h5").exists()


def test_python_raises_for_a_grid_too_large_for_the_memory():
    """The same check from Python: LayercontactError with code 5, the interpreter lives on.
    (A coupled line this long may go to the multigrid method under method 'auto': the
    estimate holds its arrays, 62 doubles per point; so may a frictionless line on a thin
    incompressible layer, whose compliance rises (the coupled iteration), while a thicker
    frictionless layer's symmetric multigrid holds 40.)"""
    script = ("import numpy as np, layercontact as lc\n"
              "h = 1e-3 * np.cos(2 * np.pi * np.arange(2**24) / 2**24)\n"
              "for thickness, friction in ((0.16, 0.5), (0.01, 0.0), (0.16, 0.0)):\n"
              "    try:\n"
              "        lc.solve_line(h, thickness=thickness, friction=friction, mean_pressure=0.01, max_iter=2)\n"
              "    except lc.LayercontactError as err:\n"
              "        print('code', err.code, str(err))\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600,
                          preexec_fn=limited_address_space(2.5))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 3 and all(line.startswith("code 5 ") for line in lines), proc.stdout
    for line, gib in zip(lines, ("7.8", "7.8", "5.0")):
        assert f"(16777216 grid points) needs about {gib} GiB" in line, line


def test_result_without_maps_holds_the_same_scalars(tmp_path, monkeypatch, capsys):
    """&output fields = .false.: no /profile and /fields, every scalar as with the maps;
    read_result gives the maps as None."""
    text = ("&scene\n geometry = 'areal'\n n = 64\n/\n&friction\n coefficient = 0.5\n companion = .true.\n/\n"
            "&loading\n normalised_pressure = 0.1\n/\n&output\n file = '{name}.h5'\n fields = {fields}\n/\n")
    for name, fields in (("maps", ".true."), ("scalars", ".false.")):
        (tmp_path / f"{name}.nml").write_text(text.format(name=name, fields=fields))
        assert run_exe(tmp_path / f"{name}.nml", tmp_path).returncode == 0
    with h5py.File(tmp_path / "maps.h5") as full, h5py.File(tmp_path / "scalars.h5") as small:
        assert {"profile", "fields"} <= set(full) and not {"profile", "fields"} & set(small)
        assert "fields" not in small["companion"] and "patches" in small
        for group in ("results", "companion/results"):
            a, b = dict(full[group].attrs), dict(small[group].attrs)
            assert a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a if not k.endswith("_time"))
    r = lc.read_result(tmp_path / "scalars.h5")
    assert r.pressure is None and r.height is None and r.companion.gap is None
    assert r.contact_fraction == lc.read_result(tmp_path / "maps.h5").contact_fraction
    # `python -m layercontact run` draws no picture then, and says so
    from layercontact.__main__ import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "scalars.h5").unlink()
    assert main(["run", "scalars.nml"]) == 0
    assert "none (&output fields = .false.: the result has no maps)" in capsys.readouterr().out
    assert not (tmp_path / "scalars.png").exists()


def test_a_missing_profile_file_is_bad_input_and_creates_nothing(tmp_path):
    """Found before the output's directories are made: exit 2, no directory, no file."""
    nml = tmp_path / "scene.nml"
    nml.write_text("&profile\n kind = 'file'\n file = 'measured.npy'\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   "&output\n file = 'deep/er/r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2 and "&profile: file = 'measured.npy' is not found" in proc.stderr
    assert not (tmp_path / "deep").exists()


#: A line scene whose heights come from the file 'heights.txt', result in 'deep/er/r.h5'.
FILE_SCENE = ("&profile\n kind = 'file'\n file = 'heights.txt'\n/\n&loading\n normalised_pressure = 1.0\n/\n"
              "&output\n file = 'deep/er/r.h5'\n/\n")


@pytest.mark.parametrize("which", ["height file", "namelist file"])
def test_a_fifo_is_refused_at_once_and_creates_nothing(which, tmp_path):
    """A FIFO (named pipe) would block the read until a writer comes: refused at once as
    something that is not a regular file, exit 2 / InputError, nothing created."""
    nml = tmp_path / "scene.nml"
    nml.write_text(FILE_SCENE)
    fifo = tmp_path / ("heights.txt" if which == "height file" else "fifo.nml")
    os.mkfifo(fifo)
    given = nml if which == "height file" else fifo
    proc = subprocess.run([executable(), str(given)], cwd=tmp_path, capture_output=True, text=True,
                          timeout=60)
    named = "&profile: file = 'heights.txt'" if which == "height file" else f"namelist file '{fifo}'"
    assert proc.returncode == 2, proc.stderr
    assert f"{named} is a FIFO (named pipe); allowed: a regular file" in proc.stderr
    # the same from Python (in a process of its own: a regression would block it, not the tests)
    script = ("import layercontact as lc\n"
              f"try:\n    lc.run({str(given)!r})\nexcept lc.InputError as err:\n    print(err.code, err)\n")
    py = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True,
                        timeout=60)
    assert py.stdout.startswith("2 "), py.stderr
    assert "is a FIFO (named pipe); allowed: a regular file" in py.stdout
    assert not (tmp_path / "deep").exists()


def test_a_directory_given_as_the_height_file_is_refused_as_bad_input(tmp_path):
    nml = tmp_path / "scene.nml"
    nml.write_text(FILE_SCENE)
    (tmp_path / "heights.txt").mkdir()
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2
    assert "&profile: file = 'heights.txt' is a directory; allowed: a regular file" in proc.stderr


def test_every_result_attribute_has_its_unit(default_result):
    """/results@units names the unit of each dimensional attribute; the others are said to
    be dimensionless or counts."""
    with h5py.File(default_result) as f:
        attrs = dict(f["results"].attrs)
    units = attrs.pop("units").decode()
    named = {entry.split()[0] for entry in units.split("; ")[:-1]}
    assert units.endswith("dimensionless (fractions, friction coefficients, residuals, normalised values) or counts")
    dimensional = {"mean_pressure", "penetration", "contact_length", "mean_gap", "leak_rate", "pressure_shift",
                   "summit_shift", "max_tension", "max_tension_grid", "max_tension_x", "max_tension_offset",
                   "dissipated_power", "wall_time", "setup_time", "coarse_time", "transform_time"}
    assert dimensional <= named and dimensional <= set(attrs)


def test_summary_echoes_the_normalised_load_and_prints_rounding_as_zero(tmp_path):
    """The summary states p_m in the seed's scale, and a frictionless elastic Delta mu (zero
    exactly; its computed value is rounding, ~1e-19 here) as 0 with the bound below which
    it is rounding; the result file keeps the computed value."""
    proc = run_example("westergaard", tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = {line[:34].strip(): line[34:].strip() for line in proc.stdout.splitlines()[1:]}
    # the file gives p_m = 0.25 pi E* h0 with h0 = Lambda0 = max r - mean r: p_m/(E* Lambda0/lambda) = pi/4
    value, scale = lines["normalised pressure"].split(maxsplit=1)
    # (7 digits printed)
    assert scale == "(p_m/(E* Lambda0/lambda))" and float(value) == pytest.approx(np.pi / 4, rel=1e-6)
    assert lines["interlocking friction Delta mu"].startswith("0 (|Delta mu| <")
    with h5py.File(next(tmp_path.rglob("*.h5"))) as f:
        delta_mu = f["results"].attrs["delta_mu"]
    bound = float(lines["interlocking friction Delta mu"].split("<")[1].split(",")[0])
    assert abs(delta_mu) < bound < 1e-13


def test_picture_title_carries_the_scene_and_its_outcome(default_result):
    """The picture of a result says what was solved and how it came out."""
    from layercontact.plot import _headline

    with h5py.File(default_result) as f:
        title, scene, outcome = _headline(f).splitlines()
        attrs = dict(f["results"].attrs)
    assert title.startswith("default: self-affine profile on a thin incompressible layer")
    assert scene == "h/lambda = 0.16, nu = 0.5, mu_c = 0.5, p_m = 0.0235 (3 in the seed's scale)"
    assert outcome == (f"contact fraction {attrs['contact_fraction']:.3f}, Delta mu = {attrs['delta_mu']:.3g}, "
                       "converged")


def test_the_shipped_scene_files_give_no_variable_twice_and_no_surface_variable_to_a_line():
    """Every file of inputs/ passes the checks of a variable given twice and of the
    variables of surfaces in a line scene (they run: test_every_input_runs...; this names
    the file that would not)."""
    for nml in INPUTS:
        lc.check_scene_file(nml)


def test_the_scene_written_back_reads_again_for_lines_and_surfaces():
    """A scene written back as a namelist leaves the variables of surfaces as comments in a
    line scene (a line scene refuses them) and gives them in an areal one."""
    line = lc.default_scene("line")
    assert "! ny: surfaces only" in line and "! period_y: surfaces only" in line
    surfaces_only = [v.name for v in lc.scene_schema.VARIABLES if v.uses == "areal" and v.alias_of is None]
    again = lc.scene_namelist(line.replace("&loading", "&loading\n   normalised_pressure = 1.0", 1))
    assert [name for name in surfaces_only if f"! {name}: surfaces only" in again] == surfaces_only
    areal = lc.default_scene("areal")
    assert "surfaces only" not in areal and "   ny = 256" in areal


@pytest.mark.parametrize("how", ["same path", "symbolic link", "dot-dot"])
def test_a_result_file_that_is_the_height_file_is_refused_and_nothing_is_clobbered(how, tmp_path, monkeypatch):
    """&output file naming the HDF5 height file itself (its path, a symbolic link to it, a
    path through `..`), with overwrite, is refused before anything is solved: exit 2, the
    heights untouched."""
    heights = np.cos(2 * np.pi * np.arange(256) / 256) * 0.01
    (tmp_path / "sub").mkdir()
    with h5py.File(tmp_path / "heights.h5", "w") as f:
        f["profile/height"] = heights
    before = (tmp_path / "heights.h5").read_bytes()
    output = {"same path": "heights.h5", "symbolic link": "link.h5", "dot-dot": "sub/../heights.h5"}[how]
    if how == "symbolic link":
        (tmp_path / "link.h5").symlink_to("heights.h5")
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&profile\n kind = 'file'\n file = 'heights.h5'\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   f"&output\n file = '{output}'\n overwrite = .true.\n/\n")
    message = (f"&output: file = '{output}' is not allowed; allowed: another file than &profile file = "
               "'heights.h5' (they name one file)")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    monkeypatch.chdir(tmp_path)
    with pytest.raises(lc.InputError, match=re.escape(message)):
        lc.run(nml)
    cli = subprocess.run([sys.executable, "-m", "layercontact", "run", str(nml), "--no-png"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert cli.returncode == 2 and message in cli.stderr
    assert (tmp_path / "heights.h5").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["heights.h5", "scene.nml", "sub"]
                                                               + (["link.h5"] if how == "symbolic link" else []))


def scene_reading(tmp_path: Path, name: str) -> Path:
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&profile\n kind = 'file'\n file = '{name}'\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   "&output\n file = 'r.h5'\n/\n")
    return nml


@pytest.mark.parametrize("name, found", [
    # what is there but holds no heights is bad input (2), as a word in a text file is
    ("garbage.h5", "is not an HDF5 file (no HDF5 signature)"),
    ("x.npy", "is a directory"),
    ("loop.txt", "is a loop of symbolic links"),
])
def test_a_height_file_that_holds_no_heights_is_bad_input(name, found, tmp_path, monkeypatch):
    """docs/topographies.md: whatever the reader refuses is bad input, exit 2 (4 only for a
    file there that cannot be opened or read); a loop of symbolic links is named as one."""
    path = tmp_path / name
    if name == "garbage.h5":
        path.write_bytes(np.random.default_rng(1).bytes(4096))
    elif name == "x.npy":
        path.mkdir()
    else:
        (tmp_path / "other.txt").symlink_to("loop.txt")
        path.symlink_to("other.txt")
    nml = scene_reading(tmp_path, name)
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"&profile: file = '{name}' {found}" in proc.stderr
    monkeypatch.chdir(tmp_path)
    with pytest.raises(lc.InputError, match=re.escape(found)):
        lc.run(nml)
    with pytest.raises((ValueError, OSError), match=re.escape(found)):
        lc.load_profile(path)
    assert not (tmp_path / "r.h5").exists()


def test_an_unreadable_height_file_is_an_io_failure(tmp_path):
    """A file that is there but cannot be opened: exit 4 (not as root: root reads it)."""
    if os.geteuid() == 0:
        pytest.skip("root opens a file without read permission")
    path = tmp_path / "heights.h5"
    path.write_bytes(b"")
    path.chmod(0)
    proc = run_exe(scene_reading(tmp_path, "heights.h5"), tmp_path)
    assert proc.returncode == 4, proc.stderr


@pytest.mark.parametrize("what", ["namelist file", "prony file", "sweep file"])
def test_a_loop_of_symbolic_links_is_named_as_one(what, tmp_path):
    """ELOOP is reported as a loop of symbolic links, not as a missing file, exit 2."""
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    if what == "namelist file":
        command = [executable(), "a"]
        named = "namelist file 'a' is a loop of symbolic links"
    elif what == "prony file":
        (tmp_path / "scene.nml").write_text("&material\n model = 'prony'\n prony_equilibrium = 1.0\n"
                                            " prony_file = 'a'\n/\n&loading\n normalised_pressure = 1.0\n/\n")
        command = [executable(), "scene.nml"]
        named = "&material: prony_file = 'a' is a loop of symbolic links"
    else:
        command = [sys.executable, "-m", "layercontact", "sweep", "a"]
        named = "sweep file 'a' is a loop of symbolic links"
    proc = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and named in proc.stderr, proc.stderr
    status = subprocess.run([sys.executable, "-m", "layercontact", "status", "a"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=120)
    assert status.returncode == 2 and "a: a loop of symbolic links" in status.stderr


def tilted(n: int) -> np.ndarray:
    """A plane rising by 0.01 over the cell and a small periodic roughness: not periodic."""
    x = np.arange(n) / n
    return 0.01 * x + 1e-4 * np.cos(2 * np.pi * 3 * x)


@pytest.mark.parametrize("surface", ["tilted", "periodic"])
def test_a_height_file_taken_as_periodic_that_is_not_gets_a_warning(surface, tmp_path, monkeypatch):
    """A tilted plane taken as one period warns (stderr; PeriodicityWarning in Python) and
    names what to set; a periodic self-affine surface (the generator's) does not. The jump
    the warning reports is the one numpy computes (lc.periodicity_mismatch) to the two
    printed decimals."""
    heights = tilted(512) if surface == "tilted" else lc.self_affine_profile(512, 0.8, seed=3)
    np.savetxt(tmp_path / "heights.txt", heights)
    nml = scene_reading(tmp_path, "heights.txt")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 0, proc.stderr
    jump, kink = lc.periodicity_mismatch(heights)
    if surface == "tilted":
        # a plane's jump is sqrt(12) (n-1)/n rms heights (the roughness is 1 % of it)
        assert jump == pytest.approx(np.sqrt(12) * 511 / 512, rel=0.01)
        assert f"its heights jump by {jump:.2f} rms heights" in proc.stderr
        assert "set &profile boundary = 'mirror'" in proc.stderr and "detrend = 'plane'" in proc.stderr
    else:
        assert jump < lc.profiles.EDGE_JUMP_LIMIT and kink < lc.profiles.EDGE_KINK_LIMIT
        assert "warning" not in proc.stderr
    monkeypatch.chdir(tmp_path)
    (tmp_path / "r.h5").unlink()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lc.run(nml)
        lc.read_profile(tmp_path / "heights.txt", 512)
        lc.read_profile(tmp_path / "heights.txt", 1024, boundary="mirror")   # mirrored: periodic, no warning
    warned = [w for w in caught if issubclass(w.category, lc.PeriodicityWarning)]
    assert len(warned) == (2 if surface == "tilted" else 0), [str(w.message) for w in caught]
    # the setting the warning names removes it: the plane detrended, the heights are periodic
    if surface == "tilted":
        (tmp_path / "r.h5").unlink()
        nml.write_text(nml.read_text().replace("file = 'heights.txt'", "file = 'heights.txt'\n detrend = 'plane'"))
        assert "warning" not in run_exe(nml, tmp_path).stderr


@pytest.mark.parametrize("text, message", [
    ("&scene\n n = 64\n n = 128\n/\n", "group &scene: n is given twice (lines 2 and 3)"),
    ("&scene\n period_y = 2.0\n/\n", "period_y applies to surfaces only"),
])
def test_the_module_refuses_what_the_executable_refuses(text, message, tmp_path):
    """`python -m layercontact run` reads the scene with the same routine: exit 2, the same
    message, nothing written."""
    nml = tmp_path / "bad.nml"
    nml.write_text(text + "&loading\n normalised_pressure = 1.0\n/\n&output\n file = 'bad.h5'\n/\n")
    proc = subprocess.run([sys.executable, "-m", "layercontact", "run", str(nml)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert not (tmp_path / "bad.h5").exists()


def test_the_module_warns_of_a_tilted_height_file(tmp_path):
    np.savetxt(tmp_path / "heights.txt", tilted(256))
    proc = subprocess.run([sys.executable, "-m", "layercontact", "run", str(scene_reading(tmp_path, "heights.txt")),
                           "--no-png"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "layercontact: warning: &profile: file = 'heights.txt' is taken as one period" in proc.stderr
