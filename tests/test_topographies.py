"""Measured topographies (docs/topographies.md): one reader for line and surface files in
three formats, detrending, Fourier resampling onto the grid, mirroring of non-periodic
patches, their errors, and instrument files through SurfaceTopography."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

import layercontact as lc

SCENE = """&scene
   geometry = 'areal'
   nx = {nx}
   ny = {ny}
   period = 1.0
   period_y = 0.75
/
&layer
   thickness = 0.2
/
&profile
   kind = 'file'
   file = '{file}'
{profile}
/
&loading
   mean_pressure = 0.02
/
&output
   file = '{output}'
   overwrite = .true.
/
"""

LINE = """&scene
   n = {n}
   period = {period}
/
&layer
   thickness = 0.16
/
&profile
   kind = 'file'
   file = '{file}'
{profile}
/
&loading
   mean_pressure = 0.01
/
&output
   file = '{output}'
   overwrite = .true.
/
"""


def write(path, heights):
    """Heights in the format of the file name's extension (17 digits in text)."""
    if path.suffix == ".h5":
        with h5py.File(path, "w") as f:
            f["/profile/height"] = heights
    elif path.suffix == ".npy":
        np.save(path, heights)
    else:
        np.savetxt(path, heights, fmt="%.17e")
    return path


def run_surface(tmp_path, file, profile="", nx=32, ny=24, name="result"):
    nml = tmp_path / f"{name}.nml"
    nml.write_text(SCENE.format(nx=nx, ny=ny, file=file, profile=profile, output=tmp_path / f"{name}.h5"))
    return lc.run(nml)


def run_line(tmp_path, file, profile="", n=256, period=1.0, name="line"):
    nml = tmp_path / f"{name}.nml"
    nml.write_text(LINE.format(n=n, period=period, file=file, profile=profile, output=tmp_path / f"{name}.h5"))
    return lc.run(nml)


@pytest.fixture
def surface():
    return lc.self_affine_surface(nx=32, ny=24, period=(1.0, 0.75), short_wavelength=0.1, seed=3, rms_gradient=0.1)


def test_one_surface_in_three_formats_gives_one_solve(tmp_path, surface):
    results = [run_surface(tmp_path, write(tmp_path / f"s{suffix}", surface), name=suffix[1:])
               for suffix in (".npy", ".txt", ".h5")]
    for result in results:
        assert np.array_equal(result.height, surface)
        assert np.array_equal(result.pressure, results[0].pressure)
        assert result.contact_fraction == results[0].contact_fraction
    assert 0.05 < results[0].contact_fraction < 0.95


def test_line_profiles_are_files_of_one_row_or_column(tmp_path):
    h = lc.self_affine_profile(64, 0.7, short_wavelength=1 / 16)
    column = write(tmp_path / "column.txt", h)
    row = tmp_path / "row.txt"
    row.write_text(" ".join(f"{v:.17e}" for v in h) + "\n")
    write(tmp_path / "row.h5", h[None, :])
    write(tmp_path / "column.npy", h[:, None].copy())
    for path in (column, row, tmp_path / "row.h5", tmp_path / "column.npy"):
        assert np.array_equal(lc.load_profile(path), h), path
        assert np.array_equal(lc.read_profile(path, 64), h), path
    write(tmp_path / "surface.npy", np.ones((3, 64)))
    with pytest.raises(lc.LayercontactError, match=r"holds shape \(3, 64\); allowed: one row or one column") as err:
        lc.read_profile(tmp_path / "surface.npy", 64)
    assert err.value.code == 2
    with pytest.raises(ValueError, match="one row or one column"):
        lc.load_profile(tmp_path / "surface.npy")


def test_plane_detrend_removes_an_added_tilt_exactly(tmp_path, surface):
    ny, nx = surface.shape
    y, x = np.meshgrid(np.arange(ny) * 0.75 / ny, np.arange(nx) / nx, indexing="ij")
    tilted = surface + 0.05 * x - 0.03 * y + 0.2
    write(tmp_path / "flat.npy", surface)
    write(tmp_path / "tilted.npy", tilted)
    plain = lc.read_surface(tmp_path / "flat.npy", nx, ny, detrend="plane")
    untilted = lc.read_surface(tmp_path / "tilted.npy", nx, ny, detrend="plane")
    assert np.max(np.abs(untilted - plain)) < 1e-14 * np.max(np.abs(tilted))
    a = run_surface(tmp_path, tmp_path / "flat.npy", "   detrend = 'plane'", name="a")
    b = run_surface(tmp_path, tmp_path / "tilted.npy", "   detrend = 'plane'", name="b")
    # the heights agree to rounding, so the two solves may differ by the solver's tolerance
    # only (the default tol 1e-10 of the scenes; 1e-8 of the largest pressure leaves room)
    assert b.contact_fraction == pytest.approx(a.contact_fraction, abs=1e-12)
    assert np.max(np.abs(b.pressure - a.pressure)) < 1e-8 * np.max(a.pressure)
    # kept, the tilt is a sawtooth of the periodic cell and changes the contact by far more
    # than any tolerance (a shift of a few percent of the cell's points); the run says the
    # kept tilt makes the file non-periodic
    with pytest.warns(lc.PeriodicityWarning, match="tilted or non-periodic"):
        c = run_surface(tmp_path, tmp_path / "tilted.npy", "   detrend = 'none'", name="c")
    assert abs(c.contact_fraction - a.contact_fraction) > 0.01


def test_curvature_and_mean_detrend(tmp_path):
    u = np.linspace(-1, 1, 40)
    bowl = 0.3 + 0.1 * u - 0.4 * u**2
    ripple = 0.01 * np.cos(2 * np.pi * 5 * np.arange(40) / 40)
    out = lc.prepare_heights(bowl + ripple, detrend="curvature")
    # the ripple is orthogonal to 1 and u, not quite to u^2: compare with numpy's fit
    expected = (bowl + ripple) - np.polyval(np.polyfit(u, bowl + ripple, 2), u)
    assert np.max(np.abs(out - expected)) < 1e-14
    assert abs(np.mean(lc.prepare_heights(bowl, detrend="mean"))) < 1e-15
    # a quadratic needs three points along each axis
    with pytest.raises(lc.LayercontactError, match=r"holds shape \(2, 5\); allowed: at least 3 points") as err:
        lc.prepare_heights(np.ones((2, 5)), detrend="curvature")
    assert err.value.code == 2


def test_fourier_resampling_of_band_limited_heights_is_exact(tmp_path):
    # the synthesis is grid independent at a fixed short wavelength: the same modes, so
    # the same heights on any grid that holds them
    fine = lc.self_affine_surface(nx=64, ny=48, period=(1.0, 0.75), short_wavelength=1 / 8, seed=5)
    coarse = lc.self_affine_surface(nx=24, ny=20, period=(1.0, 0.75), short_wavelength=1 / 8, seed=5)
    write(tmp_path / "fine.npy", fine)
    got = lc.read_surface(tmp_path / "fine.npy", 24, 20, resample="fourier")
    assert np.max(np.abs(got - coarse)) < 1e-14 * np.ptp(fine)
    back = lc.prepare_heights(coarse, shape=(48, 64))
    assert np.max(np.abs(back - fine)) < 1e-14 * np.ptp(fine)
    line = lc.self_affine_profile(512, 0.8, short_wavelength=1 / 16)
    write(tmp_path / "line.npy", line)
    result = run_line(tmp_path, tmp_path / "line.npy", "   resample = 'fourier'", n=64)
    assert np.max(np.abs(result.height - lc.self_affine_profile(64, 0.8, short_wavelength=1 / 16))) < 1e-15
    # a file of another size without resample is refused, naming both sizes
    with pytest.raises(lc.LayercontactError, match=r"holds 512 heights; allowed: the grid, n = 64"):
        run_line(tmp_path, tmp_path / "line.npy", n=64, name="refused")


def test_coarsening_keeps_the_long_wavelengths_only():
    n = 256
    x = np.arange(n) / n
    h = np.cos(2 * np.pi * 3 * x) + 0.1 * np.cos(2 * np.pi * 40 * x + 0.3)
    coarse = lc.prepare_heights(h, shape=64)
    assert np.max(np.abs(coarse - np.cos(2 * np.pi * 3 * np.arange(64) / 64))) < 1e-14


def test_without_a_grid_size_the_file_sets_it(tmp_path, surface):
    line = lc.self_affine_profile(200, 0.8, short_wavelength=1 / 16)
    write(tmp_path / "line.txt", line)
    nml = tmp_path / "line.nml"
    nml.write_text(f"&profile\n kind = 'file'\n file = '{tmp_path / 'line.txt'}'\n/\n"
                   f"&loading\n mean_pressure = 0.01\n/\n&output\n file = '{tmp_path / 'l.h5'}'\n/\n")
    assert np.array_equal(lc.run(nml).height, line)
    write(tmp_path / "patch.npy", surface)
    nml = tmp_path / "surface.nml"
    nml.write_text(f"&scene\n geometry = 'areal'\n period = 2.0\n period_y = 1.5\n/\n&layer\n thickness = 0.2\n/\n"
                   f"&profile\n kind = 'file'\n file = '{tmp_path / 'patch.npy'}'\n boundary = 'mirror'\n/\n"
                   f"&loading\n mean_pressure = 0.02\n/\n&output\n file = '{tmp_path / 's.h5'}'\n/\n")
    result = lc.run(nml)
    assert result.height.shape == (48, 64)
    assert np.array_equal(result.height, lc.prepare_heights(surface, boundary="mirror"))


def test_mirror_makes_the_patch_periodic_with_twice_its_length(tmp_path):
    m = 32
    j = np.arange(m)
    # half a cosine sampled at the midpoints: with its mirror image one full period
    patch = np.cos(np.pi * (j + 0.5) / m)
    mirrored = lc.prepare_heights(patch, boundary="mirror", detrend="none")
    assert np.max(np.abs(mirrored - np.cos(2 * np.pi * (np.arange(2 * m) + 0.5) / (2 * m)))) < 1e-15
    # the namelist: period and n are those of the mirrored cell
    write(tmp_path / "patch.txt", 0.01 * patch)
    result = run_line(tmp_path, tmp_path / "patch.txt", "   boundary = 'mirror'\n   detrend = 'none'", n=2 * m,
                      period=2.0)
    assert np.array_equal(result.height, 0.01 * mirrored)
    # a surface patch is mirrored along both axes, with no step anywhere at the edges
    patch2 = lc.self_affine_surface(nx=12, ny=10, short_wavelength=None, seed=2)[:, :11]
    cell = lc.prepare_heights(patch2, boundary="mirror")
    assert cell.shape == (20, 22)
    assert np.array_equal(cell[:, 0], cell[:, -1]) and np.array_equal(cell[0, :], cell[-1, :])
    assert np.array_equal(cell[:10, :11], lc.prepare_heights(patch2, detrend="plane"))


@pytest.mark.parametrize(
    "name, content, profile, words",
    [
        ("shape.npy", np.ones((24, 31)), "", ["holds shape (24, 31)", "(ny, nx) = (24, 32)", "resample = 'fourier'"]),
        ("nan.npy", np.where(np.eye(24, 32) > 0, np.nan, 0.0), "", ["holds the height NaN", "(0, 0)",
                                                                    "allowed: finite heights"]),
        ("ok.npy", np.zeros((24, 32)), "   detrend = 'tilt'", ["&profile: detrend = 'tilt'",
                                                               "'none', 'mean', 'plane' or 'curvature'"]),
        ("ok.npy", np.zeros((24, 32)), "   boundary = 'pad'", ["&profile: boundary = 'pad'", "'periodic' or 'mirror'"]),
        ("ok.npy", np.zeros((24, 32)), "   resample = 'cubic'", ["&profile: resample = 'cubic'",
                                                                 "'none' or 'fourier'"]),
        ("word.txt", None, "", ["line 3: '0.5x' is not a number", "allowed: whitespace-separated numbers"]),
        ("ragged.txt", None, "", ["line 2 holds 31 numbers", "allowed: 32 per line"]),
        ("line.npy", np.zeros(32), "", ["holds shape (32,)", "a 2D array (ny, nx)"]),
    ],
)
def test_bad_measured_input_exits_2_and_writes_nothing(tmp_path, name, content, profile, words):
    path = tmp_path / name
    if name == "word.txt":
        path.write_text("\n".join(" ".join(["0.5"] * 32) for _ in range(2)) + "\n0.5x" + " 0.5" * 31 + "\n")
    elif name == "ragged.txt":
        path.write_text(" ".join(["0.5"] * 32) + "\n" + " ".join(["0.5"] * 31) + "\n")
    else:
        np.save(path, content)
    nml = tmp_path / "bad.nml"
    # the result would go to directories that do not exist yet: none may be created
    output = tmp_path / "new" / "sub" / "bad.h5"
    nml.write_text(SCENE.format(nx=32, ny=24, file=path, profile=profile, output=output))
    from test_inputs import run_exe

    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    for word in words:
        assert word in proc.stderr, proc.stderr
    assert "&profile" in proc.stderr and "allowed" in proc.stderr
    assert not (tmp_path / "new").exists() and not list(tmp_path.rglob("*.tmp"))


def test_a_file_that_sets_the_grid_is_named_when_its_size_is_refused(tmp_path):
    """Without &scene n the file's size is the grid: a surface of one row is refused
    naming the file, not a variable the scene does not set."""
    path = tmp_path / "row.txt"
    path.write_text(" ".join(["0.5"] * 64) + "\n")
    nml = tmp_path / "bad.nml"
    nml.write_text(f"&scene\n geometry = 'areal'\n/\n&profile\n kind = 'file'\n file = '{path}'\n/\n"
                   f"&loading\n mean_pressure = 0.01\n/\n&output\n file = '{tmp_path / 'new' / 'bad.h5'}'\n/\n")
    from test_inputs import run_exe

    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"&profile: file = '{path}' sets the grid" in proc.stderr and "ny (or n) = 1" in proc.stderr
    assert not (tmp_path / "new").exists()


def test_treatments_of_measured_heights_are_refused_for_generated_profiles(tmp_path):
    nml = tmp_path / "bad.nml"
    nml.write_text("&profile\n detrend = 'plane'\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   "&output\n file = 'bad.h5'\n/\n")
    with pytest.raises(lc.LayercontactError, match=r"&profile: detrend = 'plane' is not allowed; allowed: not set "
                                                    r"unless kind = 'file'") as err:
        lc.check_scene_file(nml)
    assert err.value.code == 2


# ---------------------------------------------------------------------------------------
# Instrument formats (the topography extra)


def test_read_topography_and_convert_an_instrument_file(tmp_path):
    surface_topography = pytest.importorskip("SurfaceTopography")
    heights = lc.self_affine_surface(nx=16, ny=12, period=(1.0, 0.75), short_wavelength=None, seed=4)
    # SurfaceTopography holds heights [ix, iy]; x3p stores metres
    measured = surface_topography.Topography(heights.T * 1e-6, (2e-6, 1.5e-6), unit="m", periodic=False)
    measured.to_x3p(str(tmp_path / "scan.x3p"))
    topography = lc.read_topography(tmp_path / "scan.x3p", unit="um")
    assert topography.height.shape == (12, 16) and topography.unit == "um" and not topography.periodic
    assert np.allclose(topography.size, (2.0, 1.5), rtol=1e-12)
    assert np.max(np.abs(topography.height - heights)) < 1e-9 * np.ptp(heights)
    proc = subprocess.run([sys.executable, "-m", "layercontact", "convert", str(tmp_path / "scan.x3p"),
                           str(tmp_path / "scan.h5"), "--unit", "um"], check=False, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "boundary = 'mirror'" in proc.stdout and "nx = 32" in proc.stdout and "period = 4.0" in proc.stdout
    assert np.array_equal(lc.load_surface(tmp_path / "scan.h5"), topography.height)
    cell = lc.read_surface(tmp_path / "scan.h5", 32, 24, boundary="mirror")
    assert cell.shape == (24, 32)
    proc = subprocess.run([sys.executable, "-m", "layercontact", "convert", str(tmp_path / "scan.h5"),
                           str(tmp_path / "again.h5")], check=False, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and "cannot be read as a topography" in proc.stderr


def test_without_the_extra_the_error_says_what_to_install(tmp_path, monkeypatch):
    # as if not installed, also when an earlier test imported it
    for name in ("SurfaceTopography", "SurfaceTopography.IO"):
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(ImportError, match=r"pip install 'layercontact\[topography\]'"):
        lc.read_topography(tmp_path / "scan.x3p")
    from layercontact.__main__ import main

    assert main(["convert", str(tmp_path / "scan.x3p"), str(tmp_path / "out.h5")]) == 4
    assert not (tmp_path / "out.h5").exists()
