"""Areal rigid surfaces: the Fortran synthesis (what a namelist run uses) against an
independent numpy implementation of the documented algorithm, its scaling, spectrum and
isotropy, the closed forms of the sinusoid and the spherical cap, and the surface file
readers (HDF5, .npy, text) with their error messages."""

import numpy as np
import pytest

import layercontact as lc
from layercontact.profiles import read_surface
from reference_profiles import self_affine_surface_reference

# Same algorithm, different FFTs (FFTW c2r vs numpy's complex ifft2) and, on the x86-64-v3
# core, fused multiply-adds: the heights differ by rounding only (~1e-15 relative).
TOL_REFERENCE = 1e-12
# Scale targets: the scale is exact for the discrete surface (Parseval over distinct modes
# below Nyquist), so only FFT and summation rounding remain.
TOL_TARGET = 1e-12
# Closed forms evaluated by the same formula up to the rounding of the argument.
TOL_CLOSED = 1e-13


def spectral_gradient(h, lx, ly):
    """Return (dr/dx, dr/dy) of a periodic (ny, nx) surface by spectral differentiation."""
    ny, nx = h.shape
    qx = 2 * np.pi * np.fft.fftfreq(nx, lx / nx)
    qy = 2 * np.pi * np.fft.fftfreq(ny, ly / ny)
    f = np.fft.fft2(h)
    return np.fft.ifft2(1j * qx[None, :] * f).real, np.fft.ifft2(1j * qy[:, None] * f).real


@pytest.mark.parametrize(
    "nx, ny, period, kw",
    [
        (64, 64, 1.0, {"hurst": 0.8, "seed": 1, "short_wavelength": 1 / 16, "rms_gradient": 0.1}),
        (
            45,
            30,
            (1.5, 1.0),
            {
                "hurst": 0.3,
                "seed": 2**60 + 7,
                "rolloff_wavelength": 0.5,
                "short_wavelength": None,
                "rms_height": 2.0,
            },
        ),
        (
            96,
            128,
            (0.75, 1.0),
            {
                "hurst": 0.6,
                "seed": 0,
                "rolloff_wavelength": 0.2,
                "short_wavelength": 0.02,
                "rms_gradient": 1.0,
            },
        ),
        (33, 17, 2.0, {"hurst": 0.5, "seed": 12, "short_wavelength": None, "rms_gradient": 0.3}),
    ],
)
def test_fortran_matches_numpy_reference(nx, ny, period, kw):
    got = lc.self_affine_surface(nx=nx, ny=ny, period=period, **kw)
    lx, ly = (period, period) if np.ndim(period) == 0 else period
    ref = self_affine_surface_reference(nx, ny, lx, ly, kw.pop("hurst"), kw.pop("seed"), **kw)
    assert got.shape == (ny, nx) and got.dtype == np.float64
    assert np.abs(got - ref).max() <= TOL_REFERENCE * np.abs(ref).max()


@pytest.mark.parametrize("target", ["rms_gradient", "rms_height"])
@pytest.mark.parametrize("nx, ny, period", [(128, 128, 1.0), (75, 50, (3.0, 2.0))])
def test_scaled_exactly_and_zero_mean(target, nx, ny, period):
    value = 0.37
    h = lc.self_affine_surface(
        nx=nx, ny=ny, period=period, hurst=0.7, seed=9, short_wavelength=None, **{target: value}
    )
    lx, ly = (period, period) if np.ndim(period) == 0 else period
    if target == "rms_gradient":
        gx, gy = spectral_gradient(h, lx, ly)
        measured = np.sqrt(np.mean(gx**2 + gy**2))
    else:
        measured = np.sqrt(np.mean((h - h.mean()) ** 2))
    assert measured == pytest.approx(value, rel=TOL_TARGET)
    assert abs(h.mean()) <= 1e-14 * np.abs(h).max()


def test_default_scale_and_seeds():
    a = lc.self_affine_surface(64, seed=5)
    assert np.array_equal(a, lc.self_affine_surface(64, seed=5))
    assert not np.allclose(a, lc.self_affine_surface(64, seed=6))
    gx, gy = spectral_gradient(a, 1.0, 1.0)
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(0.1, rel=TOL_TARGET)


def test_same_surface_on_a_finer_grid():
    # Phases depend on the mode only: at a fixed short wavelength, twice the points give
    # the same surface at twice the resolution.
    coarse = lc.self_affine_surface(nx=48, ny=32, period=(1.5, 1.0), short_wavelength=0.1, seed=3)
    fine = lc.self_affine_surface(nx=96, ny=64, period=(1.5, 1.0), short_wavelength=0.1, seed=3)
    assert np.abs(fine[::2, ::2] - coarse).max() <= TOL_REFERENCE * np.abs(coarse).max()


def test_radial_spectrum_power_law():
    n, hurst, m_r, m_s = 128, 0.8, 4, 50
    h = lc.self_affine_surface(n, hurst, seed=4, short_wavelength=1 / m_s, rolloff_wavelength=1 / m_r)
    power = np.abs(np.fft.fft2(h) / h.size) ** 2
    m = np.fft.fftfreq(n, 1 / n)
    kappa = np.hypot(m[None, :], m[:, None])  # |q|/(2 pi) in modes per period

    # Every mode between the cut-offs lies on C ~ q^(-2-2H) exactly (deterministic
    # amplitudes): the fit over single modes is exact up to rounding.
    power_law = (kappa >= m_r) & (kappa <= m_s)
    slope = np.polyfit(np.log(kappa[power_law]), np.log(power[power_law]), 1)[0]
    assert slope == pytest.approx(-2 - 2 * hurst, abs=1e-10)

    # The radial average over annuli one mode wide, from m = 8 up: averaging a power law
    # q^-a over an annulus of width dq biases it by a(a+1)/24 (dq/q)^2 (1.1 % at q = 8,
    # falling as q^-2), which tilts the fitted exponent by about that over ln(50/8) = 1.8:
    # at most 0.006, so 0.01.
    centres, averages = [], []
    for lower in np.arange(8, m_s) - 0.5:
        ring = (kappa >= lower) & (kappa < lower + 1)
        centres.append(kappa[ring].mean())
        averages.append(power[ring].mean())
    radial_slope = np.polyfit(np.log(centres), np.log(averages), 1)[0]
    assert radial_slope == pytest.approx(-2 - 2 * hurst, abs=0.01)

    # flat below the roll-off, nothing above the short cut-off or at q = 0
    flat = (kappa > 0) & (kappa < m_r)
    assert np.ptp(power[flat]) <= 1e-12 * power[flat].max()
    assert power[flat].max() == pytest.approx(
        power[power_law & (np.abs(kappa - m_r) < 1e-9)].max(), rel=1e-12
    )
    assert power[kappa > m_s * (1 + 1e-9)].max() <= 1e-24 * power[power_law].min()
    assert power[0, 0] <= 1e-28 * power.max()


def test_isotropy():
    # The mean squares of the slopes are second-order statistics, fixed by the amplitudes
    # alone (Parseval): on a square cell the kept modes are symmetric under mx <-> my, so
    # <(dr/dx)^2> = <(dr/dy)^2> to rounding.
    h = lc.self_affine_surface(nx=128, ny=96, period=1.0, hurst=0.8, seed=2)
    gx, gy = spectral_gradient(h, 1.0, 1.0)
    assert np.mean(gx**2) == pytest.approx(np.mean(gy**2), rel=1e-12)

    # On a rectangular cell the longest waves sit on an anisotropic lattice of modes
    # (spacing 1/lx along x, 1/ly along y); a roll-off at a quarter of the shorter period
    # leaves the longest waves flat, where they carry little slope. The remaining lattice
    # error measured on this grid is 1.0e-3; 2e-3.
    h = lc.self_affine_surface(
        nx=128, ny=96, period=(1.0, 0.75), rolloff_wavelength=0.25, short_wavelength=1 / 32
    )
    gx, gy = spectral_gradient(h, 1.0, 0.75)
    assert np.mean(gx**2) / np.mean(gy**2) == pytest.approx(1.0, abs=2e-3)

    # What depends on the random phases is of higher order: the kurtosis of the slopes
    # along x and along y (3 for a Gaussian field). Over 40 seeds their mean difference
    # must be within 4 standard errors of 0 (a statistical test with fixed seeds, so
    # reproducible; 4 sigma would fail by chance with probability 6e-5).
    kx, ky = [], []
    for seed in range(1, 41):
        h = lc.self_affine_surface(64, 0.8, seed=seed, short_wavelength=1 / 16)
        gx, gy = spectral_gradient(h, 1.0, 1.0)
        kx.append(np.mean(gx**4) / np.mean(gx**2) ** 2)
        ky.append(np.mean(gy**4) / np.mean(gy**2) ** 2)
    difference = np.array(kx) - np.array(ky)
    standard_error = difference.std(ddof=1) / np.sqrt(difference.size)
    assert abs(difference.mean()) <= 4 * standard_error
    assert abs(np.mean(kx + ky) - 3) <= 4 * np.std(kx + ky, ddof=1) / np.sqrt(2 * difference.size)


def test_bad_surface_arguments_raise():
    with pytest.raises(lc.LayercontactError, match="&profile: hurst") as err:
        lc.self_affine_surface(32, 1.2)
    assert err.value.code == 2
    with pytest.raises(lc.LayercontactError, match="rms_gradient/rms_height"):
        lc.self_affine_surface(32, rms_gradient=0.1, rms_height=1.0)
    with pytest.raises(lc.LayercontactError, match=r"&scene: ny \(or n\)"):
        lc.self_affine_surface(nx=32, ny=2)


def test_sinusoid_surface_closed_form():
    nx, ny, lx, ly, amplitude, mode, mode_y = 40, 30, 2.0, 1.5, 0.3, 3, -5
    h = lc.sinusoid_surface(nx, amplitude, mode=mode, mode_y=mode_y, period=(lx, ly), ny=ny)
    y, x = np.meshgrid(np.arange(ny) * ly / ny, np.arange(nx) * lx / nx, indexing="ij")
    assert (
        np.abs(h - amplitude * np.cos(2 * np.pi * (mode * x / lx + mode_y * y / ly))).max()
        <= TOL_CLOSED * amplitude
    )
    gx, gy = spectral_gradient(h, lx, ly)
    expected = 2 * np.pi * amplitude * np.hypot(mode / lx, mode_y / ly) / np.sqrt(2)
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(expected, rel=TOL_TARGET)
    with pytest.raises(lc.LayercontactError, match="&profile: mode_y") as err:
        lc.sinusoid_surface(16, 1.0, mode=1, mode_y=8)  # the Nyquist row
    assert err.value.code == 2
    with pytest.raises(lc.LayercontactError, match="not both zero"):
        lc.sinusoid_surface(16, 1.0, mode=0, mode_y=0)


def test_spherical_cap_closed_form():
    nx, ny, lx, ly, radius = 41, 32, 1.0, 0.8, 0.3
    h = lc.spherical_cap(nx, radius, period=(lx, ly), ny=ny)
    y, x = np.meshgrid(np.arange(ny) * ly / ny, np.arange(nx) * lx / nx, indexing="ij")
    rho2 = (x - (nx // 2) * lx / nx) ** 2 + (y - (ny // 2) * ly / ny) ** 2
    expected = np.where(rho2 < radius**2, np.sqrt(np.maximum(radius**2 - rho2, 0)) - radius, -radius)
    assert np.abs(h - expected).max() <= TOL_CLOSED * radius
    assert h[ny // 2, nx // 2] == 0.0 and h.max() == 0.0 and h.min() == -radius
    for bad in (-1.0, 0.0, np.inf):
        with pytest.raises(lc.LayercontactError, match="&profile: radius") as err:
            lc.spherical_cap(16, bad)
        assert err.value.code == 2


# ---------------------------------------------------------------------------------------
# Surface files


@pytest.fixture
def surface():
    """A (ny, nx) = (12, 20) surface with distinct values, so a transposition shows."""
    return lc.self_affine_surface(nx=20, ny=12, period=(1.0, 0.6), short_wavelength=None, seed=8)


def write_h5(path, data, dataset="/profile/height"):
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "w") as f:
        f[dataset] = data


@pytest.mark.parametrize("suffix", [".h5", ".hdf5", ".npy", ".npy2", ".txt", ".dat"])
def test_surface_files_round_trip(tmp_path, surface, suffix):
    path = tmp_path / ("h" + suffix.replace("npy2", "npy"))
    if suffix in (".h5", ".hdf5"):
        write_h5(path, surface)
    elif suffix == ".npy":
        np.save(path, surface)
    elif suffix == ".npy2":
        with open(path, "wb") as f:
            np.lib.format.write_array(f, surface, version=(2, 0))
    else:
        np.savetxt(path, surface, fmt="%.17e", header="a comment line, as numpy writes it")
    got = read_surface(path, 20, 12)
    assert np.array_equal(got, surface)
    assert np.array_equal(lc.load_surface(path), surface)


def test_surface_files_through_a_namelist_scene(tmp_path, surface):
    # The same reader a namelist run uses (make_profile of an areal scene), with another
    # dataset name and an HDF5 float32 dataset, which is converted.
    write_h5(tmp_path / "s.h5", surface.astype(np.float32), dataset="/measured/z")
    got = read_surface(tmp_path / "s.h5", 20, 12, dataset="/measured/z")
    assert np.array_equal(got, surface.astype(np.float32).astype(np.float64))


def bad_files(tmp_path, surface):
    """(file, dataset, expected code, words of the message) of surface files that a 20 x 12
    scene must refuse."""
    cases = []
    write_h5(tmp_path / "transposed.h5", surface.T)
    cases.append(("transposed.h5", None, 2, "holds shape (20, 12)"))
    write_h5(tmp_path / "integers.h5", np.ones((12, 20), dtype=np.int32))
    cases.append(("integers.h5", None, 2, "not floating point"))
    write_h5(tmp_path / "line.h5", surface.ravel())
    cases.append(("line.h5", None, 2, "holds shape (240,)"))
    cases.append(("line.h5", "/other", 2, "has no dataset '/other'"))
    (tmp_path / "text.h5").write_text("not HDF5\n")
    cases.append(("text.h5", None, 2, "is not an HDF5 file"))
    np.save(tmp_path / "single.npy", surface.astype(np.float32))
    cases.append(("single.npy", None, 2, "dtype '<f4'"))
    np.save(tmp_path / "big_endian.npy", surface.astype(">f8"))
    cases.append(("big_endian.npy", None, 2, "dtype '>f8'"))
    np.save(tmp_path / "fortran.npy", np.asfortranarray(surface))
    cases.append(("fortran.npy", None, 2, "fortran_order = True"))
    np.save(tmp_path / "shape.npy", surface[:, :-1])
    cases.append(("shape.npy", None, 2, "holds shape (12, 19)"))
    np.save(tmp_path / "whole.npy", surface)
    (tmp_path / "short.npy").write_bytes((tmp_path / "whole.npy").read_bytes()[:-8])
    cases.append(("short.npy", None, 2, "ends before its 240 heights"))
    (tmp_path / "magic.npy").write_bytes(b"hello world, not numpy" * 10)
    cases.append(("magic.npy", None, 2, "magic string"))
    np.savetxt(tmp_path / "rows.txt", surface[:-1])
    cases.append(("rows.txt", None, 2, "holds shape (11, 20)"))
    np.savetxt(tmp_path / "columns.txt", surface[:, 1:])
    cases.append(("columns.txt", None, 2, "holds shape (12, 19)"))
    bad = surface.copy()
    bad[3, 4] = np.nan
    np.savetxt(tmp_path / "nan.txt", bad)
    cases.append(("nan.txt", None, 2, "at (ix, iy) = (4, 3)"))
    (tmp_path / "word.txt").write_text(
        "\n".join(" ".join(["1.0"] * 20) for _ in range(11)) + "\n1.0 x" + " 1" * 18
    )
    cases.append(("word.txt", None, 2, "line 12: 'x' is not a number"))
    # a file that is not there is bad input (2), from Python as in a run
    cases.append(("missing.npy", None, 2, "is not found"))
    cases.append(("missing.txt", None, 2, "is not found"))
    cases.append(("missing.h5", None, 2, "is not found"))
    return cases


def test_bad_surface_files_raise(tmp_path, surface):
    for name, dataset, code, words in bad_files(tmp_path, surface):
        path = tmp_path / name
        with pytest.raises(lc.LayercontactError) as err:
            read_surface(path, 20, 12, dataset=dataset)
        message = str(err.value)
        assert err.value.code == code, message
        assert message.startswith(f"&profile: file = '{path}'"), message
        assert words in message, message
        assert "allowed" in message, message


def test_load_surface_refuses_what_the_reader_refuses(tmp_path, surface):
    for name, dataset, code, _ in bad_files(tmp_path, surface):
        if name in ("shape.npy", "columns.txt", "rows.txt", "transposed.h5"):
            continue  # a consistent array of another size: only the scene's grid refuses it
        with pytest.raises((ValueError, OSError)):
            lc.load_surface(tmp_path / name, dataset=dataset)


# ---------------------------------------------------------------------------------------
# Through a namelist run (the executable's path: read_scene, check_scene, make_profile)

SCENE = """&scene
   geometry = 'areal'
   nx = 32
   ny = 24
   period = 1.0
   period_y = 0.75
/
&layer
   thickness = Inf
/
&profile
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


def run_areal(tmp_path, profile):
    """Run a 32 x 24 areal half-space scene with the given &profile lines; its result."""
    nml = tmp_path / "scene.nml"
    nml.write_text(SCENE.format(profile=profile, output=tmp_path / "result.h5"))
    return lc.run(nml)


@pytest.mark.parametrize("name", ["h.h5", "h.npy", "h.txt"])
def test_namelist_reads_surface_files(tmp_path, name):
    heights = lc.self_affine_surface(nx=32, ny=24, period=(1.0, 0.75), short_wavelength=None, seed=8)
    path = tmp_path / name
    if name.endswith(".h5"):
        write_h5(path, heights)
    elif name.endswith(".npy"):
        np.save(path, heights)
    else:
        np.savetxt(path, heights, fmt="%.17e")
    result = run_areal(tmp_path, f"   kind = 'file'\n   file = '{path}'")
    assert np.array_equal(result.height, heights)


def test_namelist_makes_the_same_surfaces_as_python(tmp_path):
    result = run_areal(
        tmp_path, "   kind = 'self_affine'\n   hurst = 0.6\n   seed = 4\n   short_wavelength = 0.1"
    )
    expected = lc.self_affine_surface(
        nx=32, ny=24, period=(1.0, 0.75), hurst=0.6, seed=4, short_wavelength=0.1
    )
    assert np.array_equal(result.height, expected)
    result = run_areal(tmp_path, "   kind = 'sinusoid'\n   amplitude = 0.01\n   mode = 2\n   mode_y = -3")
    assert np.array_equal(
        result.height, lc.sinusoid_surface(32, 0.01, mode=2, mode_y=-3, period=(1.0, 0.75), ny=24)
    )
    result = run_areal(tmp_path, "   kind = 'sphere'\n   radius = 2.0")
    assert np.array_equal(result.height, lc.spherical_cap(32, 2.0, period=(1.0, 0.75), ny=24))


@pytest.mark.parametrize(
    "profile, words",
    [
        ("   kind = 'sinusoid'\n   amplitude = 0.01\n   mode = 1\n   mode_y = 12", "&profile: mode_y = 12"),
        ("   kind = 'sphere'", "&profile: radius"),
        ("   kind = 'self_affine'\n   short_wavelength = 0.05", "&profile: short_wavelength"),
        ("   kind = 'file'\n   file = 'missing_surface.npy'", "&profile: file = 'missing_surface.npy'"),
    ],
)
def test_namelist_refuses_bad_areal_profiles(tmp_path, profile, words):
    with pytest.raises(lc.LayercontactError, match=words) as err:
        run_areal(tmp_path, profile)
    assert err.value.code in (2, 4)
    assert not (tmp_path / "result.h5").exists()
