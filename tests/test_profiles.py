"""Profiles: the Fortran synthesis (what a namelist run uses) against an independent numpy
implementation of the documented algorithm, seeds, scaling, and file input."""

import numpy as np
import pytest

import layercontact as lc
from reference_profiles import self_affine_reference


@pytest.mark.parametrize(
    "n, kw",
    [
        (4096, dict(hurst=0.8, seed=1, rms_gradient=0.1)),
        (1001, dict(hurst=0.3, seed=2**60 + 7, rolloff_wavelength=0.25, short_wavelength=0.01, rms_height=2.0)),
        (512, dict(hurst=0.5, seed=0, period=3.0, short_wavelength=0.1, rms_gradient=1.0)),
    ],
)
def test_fortran_matches_numpy_reference(n, kw):
    got = lc.self_affine_profile(n, **kw)
    hurst = kw.pop("hurst")
    ref = self_affine_reference(n, kw.pop("period", 1.0), hurst, kw.pop("seed"), **kw)
    # same algorithm, different FFTs (FFTW vs numpy): rounding only
    assert np.abs(got - ref).max() <= 1e-13 * np.abs(ref).max()


def test_seed_reproducible_and_scaled():
    a = lc.self_affine_profile(2048, 0.8, seed=5, rms_gradient=0.2)
    b = lc.self_affine_profile(2048, 0.8, seed=5, rms_gradient=0.2)
    c = lc.self_affine_profile(2048, 0.8, seed=6, rms_gradient=0.2)
    assert np.array_equal(a, b) and not np.allclose(a, c)
    k = 2 * np.pi * np.fft.rfftfreq(a.size, 1 / a.size)
    slope = np.fft.irfft(1j * k * np.fft.rfft(a), n=a.size)
    assert np.sqrt(np.mean(slope**2)) == pytest.approx(0.2, rel=1e-12)
    assert abs(a.mean()) <= 1e-14 * np.abs(a).max()


def test_bad_profile_arguments_raise():
    with pytest.raises(lc.LayercontactError, match="hurst") as err:
        lc.self_affine_profile(256, 1.5)
    assert err.value.code == 2
    with pytest.raises(lc.LayercontactError, match="rms_gradient"):
        lc.self_affine_profile(256, 0.8, rms_gradient=0.1, rms_height=1.0)


def test_load_profile_formats(tmp_path):
    h = lc.self_affine_profile(128, 0.7, short_wavelength=1 / 16)
    np.save(tmp_path / "h.npy", h)
    np.savetxt(tmp_path / "h.txt", h)
    assert np.array_equal(lc.load_profile(tmp_path / "h.npy"), h)
    assert np.allclose(lc.load_profile(tmp_path / "h.txt"), h, rtol=0, atol=1e-15 * np.abs(h).max() * 100)
