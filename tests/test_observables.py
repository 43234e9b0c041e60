"""Observables of a line contact: surface stress against Johnson's sliding Hertz contact,
the uniform-pressure limit of a layer, contact spots, gap statistics, the frictionless
companion, and the same numbers through the namelist runner (HDF5)."""

import numpy as np
import pytest

import layercontact as lc


def hertz(n, a, p0=1.0):
    x = (np.arange(n) / n + 0.5) % 1 - 0.5
    return x, p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_sliding_hertz_surface_stress_matches_johnson(nu):
    """Hertz pressure with tau = mu p on a half-space (Johnson, Contact Mechanics §7.1):
    sigma_xx = -p - 2 mu p0 x/a inside the contact, tension 2 mu p0 at the trailing edge
    x = -a (the indenter slides along +x), compression at the leading edge. The periodic
    images of a contact of half-width a = 0.02 lambda change interior values by
    O((a/lambda)^2 mu p0) (measured 6e-4 at mu = 0.5); the edge value converges like
    dx^(1/2) (measured error 0.035, 0.017, 0.007 at n = 2^14, 2^16, 2^18)."""
    mu, a = 0.5, 0.02
    edge_errors = []
    for n in (2**14, 2**16):
        x, p = hertz(n, a)
        _, sxx = lc.surface_fields(p, poisson=nu, friction=mu)
        inside = np.abs(x) < 0.9 * a
        assert np.abs(sxx - (-p - 2 * mu * x / a))[inside].max() <= 1e-3
        top = np.argmax(sxx)
        assert abs(x[top] + a) <= 1.0 / n  # the maximum tension sits at the trailing edge
        edge_errors.append(abs(sxx[top] - 2 * mu))
        lead = np.argmin(np.abs(x - a))
        assert sxx[lead] == pytest.approx(-2 * mu, abs=0.05)
    assert edge_errors[1] < edge_errors[0] and edge_errors[1] <= 0.02


@pytest.mark.parametrize("thickness", [0.05, 0.3, np.inf])
def test_frictionless_normal_stress_limits(thickness):
    """Uniform pressure on a layer: uniaxial strain, sigma_xx = -(nu/(1-nu)) p_m; a
    half-space gives -p_m. Any pressure without friction on a half-space: sigma_xx = -p."""
    nu, pm, n = 0.3, 0.7, 256
    _, sxx = lc.surface_fields(np.full(n, pm), thickness=thickness, poisson=nu)
    expected = -pm if np.isinf(thickness) else -nu / (1 - nu) * pm
    assert np.allclose(sxx, expected, rtol=1e-14)
    if np.isinf(thickness):
        _, p = hertz(n, 0.2)
        _, sxx = lc.surface_fields(p, poisson=nu)
        assert np.allclose(sxx, -p, atol=1e-13)


def test_spots_gap_and_leak_of_a_sinusoid():
    n, h0 = 2048, 0.01
    h = lc.sinusoid_profile(n, h0)
    res = lc.solve_line(h, thickness=0.1, friction=0.8, mean_pressure=0.01)
    assert res.n_spots == 1 and res.spots.shape == (1, 2)
    trailing, leading = res.spots[0]
    # one spot around the crest at x = 0 = 1 (periodic): trailing edge before it, leading after
    assert 0.5 < trailing < 1.0 and 1.0 < leading < 1.5
    assert leading - trailing == pytest.approx(res.contact_length, rel=1e-14)
    assert res.contact_length == pytest.approx(res.contact_fraction, rel=1e-14)
    assert res.mean_gap == pytest.approx(res.gap.mean(), rel=1e-13)
    assert res.leak_rate == pytest.approx(np.mean(res.gap**3) / 12, rel=1e-13)
    # friction pushes the leading edge forward on a thin incompressible layer
    r0 = lc.solve_line(h, thickness=0.1, friction=0.0, mean_pressure=0.01)
    assert leading > r0.spots[0, 1] and res.mean_gap != r0.mean_gap
    assert np.array_equal(res.shear, 0.8 * res.pressure)
    assert res.max_tension > 0 and abs(res.max_tension_offset) <= 2.0 / n


def test_spots_count_rough_profile_and_full_contact(rough_profile):
    res = lc.solve_line(rough_profile, thickness=0.16, friction=0.5, mean_pressure=0.3 * rough_profile.max())
    contact = res.pressure > 0
    starts = np.count_nonzero(contact & ~np.roll(contact, 1))
    assert res.n_spots == starts > 1
    widths = res.spots[:, 1] - res.spots[:, 0]
    assert widths.sum() == pytest.approx(res.contact_length, rel=1e-12)
    full = lc.solve_line(lc.sinusoid_profile(256, 1e-4), thickness=0.16, mean_pressure=1.0)
    assert full.contact_fraction == 1.0 and full.n_spots == 1 and full.leak_rate == pytest.approx(0, abs=1e-30)


def test_companion_gives_a_over_a0(rough_profile):
    pm = 0.5 * rough_profile.max()
    res = lc.solve_line(rough_profile, thickness=0.05, friction=0.7, mean_pressure=pm, companion=True)
    alone = lc.solve_line(rough_profile, thickness=0.05, friction=0.0, mean_pressure=pm)
    assert np.array_equal(res.companion.pressure, alone.pressure)
    assert res.a_over_a0 == res.contact_fraction / alone.contact_fraction
    assert res.companion.delta_mu_spectral == 0.0


def test_namelist_run_writes_observables(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.nml").write_text(
        "&scene\n n = 1024\n/\n&layer\n thickness = 0.1\n/\n&friction\n coefficient = 0.6\n companion = .true.\n/\n"
        "&profile\n short_wavelength = 0.03125\n/\n&loading\n normalised_pressure = 2.0\n/\n"
        "&output\n file = 'r.h5'\n gap_bins = 16\n/\n"
    )
    res = lc.run(tmp_path / "s.nml")
    ref = lc.solve_line(res.height, thickness=0.1, friction=0.6, mean_pressure=res.mean_pressure, companion=True)
    np.testing.assert_allclose(res.stress_xx, ref.stress_xx, rtol=0, atol=1e-12 * np.abs(ref.stress_xx).max())
    assert res.n_spots == ref.n_spots and np.array_equal(res.spots, ref.spots)
    assert res.a_over_a0 == pytest.approx(ref.a_over_a0, rel=1e-12)
    assert res.max_tension == pytest.approx(ref.max_tension, rel=1e-10) and res.max_tension > res.max_tension_grid
    assert res.max_tension_grid == pytest.approx(ref.max_tension_grid, rel=1e-10)
    np.testing.assert_allclose(res.spot_max_tension_grid, ref.spot_max_tension_grid, rtol=1e-10)
    import h5py

    with h5py.File(tmp_path / "r.h5") as f:
        assert f["gap_histogram/counts"][()].sum() == 1024 and f["gap_histogram/edges"].shape == (17,)
        assert f["results"].attrs["leak_rate"] == pytest.approx(ref.leak_rate, rel=1e-10)


def test_tension_peaks_at_each_trailing_edge(rough_profile):
    """Every spot's largest sigma_xx sits within a few grid steps of its trailing edge on a
    thin layer with friction (the seed's 'very high tensile stresses at the trailing edge'),
    and the global maximum is one of them."""
    res = lc.solve_line(rough_profile, thickness=0.16, friction=0.8, mean_pressure=0.5 * rough_profile.max())
    dx = 1.0 / rough_profile.size
    big = res.spot_max_tension > 0.5 * res.max_tension  # spots that carry real tension
    assert big.sum() >= 2
    assert np.all(np.abs(res.spot_tension_offset[big]) <= 3 * dx)
    assert res.max_tension == pytest.approx(res.spot_max_tension.max(), rel=1e-14)
    single = lc.solve_line(lc.sinusoid_profile(512, 1e-3), thickness=0.1, friction=0.5, mean_pressure=0.002)
    assert single.n_spots == 1 and single.spot_tension_offset[0] == pytest.approx(single.max_tension_offset)


def test_spot_windows_cover_the_period_and_full_contact_has_no_trailing_edge(rough_profile):
    """Each spot's tension window runs from the middle of the gap behind to the middle of
    the gap ahead, so the largest tension of the period is the largest over the spots."""
    for friction, pm in ((0.3, 0.2), (0.8, 0.6), (0.0, 1.0)):
        res = lc.solve_line(rough_profile, thickness=0.16, friction=friction,
                            mean_pressure=pm * rough_profile.max())
        assert res.n_spots > 1
        assert res.spot_max_tension_grid.max() == res.stress_xx.max() == res.max_tension_grid
        assert res.max_tension == res.spot_max_tension.max() >= res.max_tension_grid
    full = lc.solve_line(lc.sinusoid_profile(256, 1e-4), thickness=0.16, friction=0.5, mean_pressure=1.0)
    assert full.n_spots == 1 and np.isnan(full.spot_tension_offset[0]) and np.isnan(full.max_tension_offset)
