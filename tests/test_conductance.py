"""The contact's conductance and its normal interfacial stiffness (lc_observables_conductance,
docs/theory.md "Contact conductance and interfacial stiffness") against closed forms
(a periodic strip, Holm's spot with the periodic-array correction, Greenwood's cluster, the
thin layer's local limit), Barber's analogy on a half-space, and the solver's own
load-approach curve."""

import subprocess

import h5py
import numpy as np
import pytest

import layercontact as lc
from conftest import ROOT
from test_inputs import executable

#: The regularised lattice sum sum'_{n in Z^2} 1/|n| = 4 zeta(1/2) beta(1/2) (the Epstein
#: zeta function of the square lattice at s = 1/2): the potential a periodic array of unit
#: point currents on a half-space (mean surface potential removed) adds at one of them is
#: LATTICE/(2 pi sigma L).
LATTICE = 4 * -1.4603545088095868 * 0.6676914571896092


def disk_map(n, centres, radius, period=1.0):
    """Grid points (x = axis 1) within `radius` of any of `centres`."""
    x = np.arange(n) * period / n
    xx, yy = np.meshgrid(x, x)
    mask = np.zeros((n, n), bool)
    for cx, cy in centres:
        mask |= (xx - cx) ** 2 + (yy - cy) ** 2 <= radius**2
    return mask


def rough_surface(n, rms=0.02, seed=1):
    """A smooth random surface of a few modes (its contact spots span many grid points)."""
    rng = np.random.default_rng(seed)
    x = np.arange(n) / n
    xx, yy = np.meshgrid(x, x)
    h = sum(rng.normal() / (kx * kx + ky * ky + 1) * np.cos(2 * np.pi * (kx * xx + ky * yy) + rng.uniform(0, 2 * np.pi))
            for kx in range(-6, 7) for ky in range(0, 7))
    return h * rms / h.std()


def test_periodic_strips_on_a_half_space_match_the_conformal_map_and_converge_as_one_over_n():
    """A line: equipotential strips of half-width a, period L, on a half-space. The conformal
    map gives the constriction resistance per unit depth R = ln(1/sin(pi a/L))/(pi sigma)
    (the uniform flux's far field taken off: the half-space's convention). The map's edge
    is a grid spacing uncertain, so the error falls as 1/n: at n = 64000 it is below 1e-4."""
    period, a, sigma = 2.0, 0.2, 3.0
    exact = np.log(1 / np.sin(np.pi * a / period)) / (np.pi * sigma)
    errors = []
    for n in (1000, 4000, 16000, 64000):
        x = np.arange(n) * period / n
        mask = np.abs(x - period / 2) <= a + 1e-12
        resistance = 1 / (lc.contact_conductance(mask, period, sigma) * period)
        errors.append(abs(resistance / exact - 1))
    assert all(e2 < 0.3 * e1 for e1, e2 in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-4, errors


def test_holm_spot_with_the_periodic_array_correction_converges():
    """Holm's circular spot of radius a on a half-space: R = 1/(4 sigma a) per side; in a
    periodic square array of period L the other spots and the convention add
    LATTICE/(2 pi sigma L) (first order in a/L; the next term, ~0.3 (a sqrt(pi)/L)^3 as for
    a circular flux tube, is 0.2 % at a/L = 0.1). The pixelated disk's edge is uncertain by a
    grid spacing: the error falls with refinement, and at 51 points per radius it is within
    1 % (that spacing over the radius, halved as the strips measure it, plus the 0.2 %)."""
    period, a, sigma = 1.0, 0.1, 1.0
    holm = 1 / (4 * sigma * a) + LATTICE / (2 * np.pi * sigma * period)
    errors = []
    for n in (128, 256, 512):
        conductance = lc.contact_conductance(disk_map(n, [(0.5, 0.5)], a), period, sigma)
        errors.append(abs(1 / (conductance * period**2) / holm - 1))
    assert errors[2] < errors[1] < errors[0], errors
    assert errors[-1] < 0.01, errors


def test_a_cluster_of_spots_follows_greenwoods_formula():
    """Greenwood ("Constriction resistance and the real area of contact"): spots of radii
    a_i at distances s_ij, per side, R = 1/(4 sigma sum a) + sum_{i != j} a_i a_j/(2 pi sigma
    s_ij (sum a)^2); on the periodic cell 1/(2 pi s) is the periodic half-space Green's
    function (mean removed, by FFT) and each spot's own images add LATTICE/(2 pi L). The
    interaction is a third of R here; Greenwood's uniform-potential-per-spot approximation
    and the 41-point disks' edges (0.6 %, as for Holm's spot) leave 0.9 %: bound 1.5 %."""
    period, a, n, fine = 1.0, 0.04, 1024, 2048
    k = np.fft.fftfreq(fine, 1 / fine) * 2 * np.pi / period
    q = np.hypot(*np.meshgrid(k, k))
    q[0, 0] = np.inf
    green = np.real(np.fft.ifft2(1 / q)) * fine**2 / period**2
    for side in (0.15, 0.25):
        centres = [(0.5 + sx * side / 2, 0.5 + sy * side / 2) for sx in (-1, 1) for sy in (-1, 1)]
        weight = 1 / len(centres)
        greenwood = 0.0
        for i, ci in enumerate(centres):
            for j, cj in enumerate(centres):
                if i == j:
                    greenwood += weight**2 * (1 / (4 * a) + LATTICE / (2 * np.pi * period))
                else:
                    dx, dy = (np.round(np.subtract(cj, ci) / period * fine).astype(int) % fine)
                    greenwood += weight**2 * green[dy, dx]
        alone = 1 / (4 * a * len(centres)) + LATTICE / (2 * np.pi * period)
        resistance = 1 / lc.contact_conductance(disk_map(n, centres, a), period, 1.0)
        assert abs(resistance / greenwood - 1) < 0.015, (side, resistance, greenwood)
        assert greenwood - alone > 0.2 * greenwood   # the interaction is tested, not negligible


def test_a_thin_layer_conducts_like_its_contact_area():
    """A layer of thickness h on a conducting base under a spot much wider than h:
    C -> sigma A_real/(h A0). The edge adds a fringe, (2 ln 2/pi) sigma per unit perimeter
    (the equipotential half-plane on a slab), so the excess is ~0.44 h P/A: below 0.5 h P/A
    and falling with h."""
    period, a, n, sigma = 1.0, 0.3, 512, 2.0
    mask = disk_map(n, [(0.5, 0.5)], a)
    fraction = mask.mean()
    excess = []
    for h in (0.04, 0.02, 0.01):
        c = lc.contact_conductance(mask, period, sigma, thickness=h)
        excess.append(c / (sigma * fraction / h) - 1)
        assert 0 < excess[-1] < 0.5 * h * 2 / a, (h, excess)
    assert excess[2] < 0.6 * excess[1] < 0.36 * excess[0]


def test_full_and_empty_contact():
    """No contact conducts nothing; full contact on a layer gives sigma/h exactly (uniform
    flux), on a half-space an infinite constriction conductance."""
    assert lc.contact_conductance(np.zeros((8, 8), bool), 1.0, 2.0) == 0.0
    assert lc.contact_conductance(np.ones(16, bool), 1.0, 2.0, thickness=0.25) == pytest.approx(8.0, rel=1e-14)
    assert lc.contact_conductance(np.ones((8, 8), bool), 1.0, 2.0) == np.inf


@pytest.mark.parametrize("poisson", [0.5, 0.3])
def test_barbers_analogy_holds_to_rounding_on_a_half_space(poisson):
    """On a half-space sigma G_c = 1/q and G = (2/E*)/q: the two masked systems are one, so
    C = (2 sigma/E*) K to the iterations' tolerance (1e-12 here: both stop at |r| <= 1e-12
    |b|, and mean(x) carries the square of that)."""
    sigma, young = 3.0, 2.0
    res = lc.solve_areal(rough_surface(128), period=1.0, young=young, poisson=poisson, normalised_pressure=0.02,
                         stress=False, tol=1e-12, conductance=True, conductivity=sigma)
    e_star = young / (1 - poisson**2)
    assert res.converged and res.conductance_converged and 0 < res.contact_fraction < 0.1
    assert res.conductance == pytest.approx(2 * sigma / e_star * res.contact_stiffness, rel=1e-10)


def test_barbers_analogy_fails_on_a_thin_layer():
    """On a thin layer G_c -> h/sigma and G -> h/M at long waves: C E*/(2 sigma K) departs
    from 1 (the departure is the physics: the conducting base is close, the rigid base
    confines the layer)."""
    sigma = 1.0
    res = lc.solve_areal(rough_surface(128), period=1.0, thickness=0.05, poisson=0.3, normalised_pressure=0.05,
                         stress=False, conductance=True, conductivity=sigma)
    e_star = 1 / (1 - 0.3**2)
    assert abs(res.conductance * e_star / (2 * sigma * res.contact_stiffness) - 1) > 0.2


@pytest.mark.parametrize("friction", [0.0, 0.5])
@pytest.mark.parametrize("areal", [False, True])
def test_stiffness_is_the_slope_of_the_load_approach_curve(areal, friction):
    """K against the central difference of the solver's p_m(Delta) under displacement control
    at Delta +- 1e-7 (the contact set checked unchanged: on it p_m is linear in Delta).
    Solved to tol = 1e-13, p_m carries ~1e-13 of the profile's scale, over 2e-7: 1e-6
    relative; K itself is solved to 1e-13. With friction the coupled operator (BiCGSTAB). The
    same K from a load-controlled solve, whose operator dropped its uniform mode."""
    if areal:
        heights, solve = rough_surface(64), lc.solve_areal
    else:
        x = np.arange(2048) / 2048
        heights = 0.02 * (np.cos(2 * np.pi * x) + 0.3 * np.cos(6 * np.pi * x + 1) + 0.1 * np.cos(22 * np.pi * x))
        solve = lc.solve_line
    keywords = dict(period=1.0, thickness=0.2, poisson=0.3, friction=friction, stress=False, tol=1e-13)
    delta, step = 0.01, 1e-7
    res = solve(heights, penetration=delta, conductance=True, **keywords)
    above = solve(heights, penetration=delta + step, **keywords)
    below = solve(heights, penetration=delta - step, **keywords)
    for other in (above, below):
        np.testing.assert_array_equal(other.pressure > 0, res.pressure > 0)
    slope = (above.mean_pressure - below.mean_pressure) / (2 * step)
    assert res.conductance_converged and res.stiffness_iterations > 0
    assert res.contact_stiffness == pytest.approx(slope, rel=1e-6)
    loaded = solve(heights, mean_pressure=res.mean_pressure, conductance=True, **keywords)
    np.testing.assert_array_equal(loaded.pressure > 0, res.pressure > 0)
    assert loaded.contact_stiffness == pytest.approx(res.contact_stiffness, rel=1e-8)


def test_friction_changes_the_stiffness_of_a_layer():
    """On a thin compressible layer the Coulomb coupling enters the operator: K with
    mu_c = 0.5 differs from the frictionless companion's at the same load by percents (each
    K is the slope of its own load-approach curve: the test above), far beyond the
    iterations' tolerance; the conductance sees friction only through the contact set."""
    res = lc.solve_areal(rough_surface(64), period=1.0, thickness=0.05, poisson=0.45, friction=0.5,
                         normalised_pressure=0.05, companion=True, stress=False, conductance=True)
    assert abs(res.contact_stiffness / res.companion.contact_stiffness - 1) > 0.01


def test_the_example_scene_writes_both_scalars_with_units(tmp_path):
    """inputs/areal_conductance.nml through the executable: /results@conductance and
    @contact_stiffness with their units, for the run and its companion, read back by Python."""
    nml = tmp_path / "areal_conductance.nml"
    nml.write_text((ROOT / "inputs" / "areal_conductance.nml").read_text())
    proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "conductance C" in proc.stdout and "contact stiffness K, mu_c = 0" in proc.stdout
    out = tmp_path / "out" / "areal_conductance.h5"
    with h5py.File(out) as f:
        attrs = f["results"].attrs
        units = attrs["units"].decode()
        assert "conductance sigma/L" in units and "contact_stiffness S/L" in units
        written = float(attrs["conductance"]), float(attrs["contact_stiffness"])
        assert "conductance" in f["companion/results"].attrs
    res = lc.read_result(out)
    assert res.conductance_converged and res.companion.conductance > 0
    assert (res.conductance, res.contact_stiffness) == written and min(written) > 0


def test_a_scene_without_conductance_computes_none():
    res = lc.solve_line(0.01 * np.cos(2 * np.pi * np.arange(256) / 256), normalised_pressure=0.1)
    assert np.isnan(res.conductance) and np.isnan(res.contact_stiffness)


BAD_MAPS = [
    (dict(contact_mask=np.full(8, 0.5)), "contact_mask: 8 values other than 0 and 1"),
    (dict(contact_mask=np.zeros((1, 8))), "contact_mask: an array of shape (1, 8) is not allowed"),
    (dict(contact_mask=np.array(["a", "b"])), "contact_mask: an array of dtype <U1 is not allowed"),
    (dict(conductivity=-1.0), "conductivity = -1.0 is not allowed; allowed: > 0 and finite"),
    (dict(conductivity=np.inf), "conductivity = inf is not allowed"),
    (dict(thickness=0.0), "thickness = 0.0 is not allowed; allowed: > 0, or Inf"),
    (dict(period=(1.0, 2.0)), "period = (1.0, 2.0) is not allowed; allowed: one positive length for a line"),
    (dict(period=-1.0), "period = -1.0 is not allowed"),
    (dict(tol=1.0), "tol = 1.0 is not allowed; allowed: 1e-14 <= tol <= 1e-2"),
    (dict(max_iter=0), "max_iter = 0 is not allowed"),
]


@pytest.mark.parametrize("change, message", BAD_MAPS)
def test_bad_input_to_contact_conductance_is_refused(change, message):
    arguments = dict(contact_mask=np.arange(8) % 2 == 0, period=1.0, conductivity=1.0)
    arguments.update(change)
    mask = arguments.pop("contact_mask")
    with pytest.raises(lc.InputError) as caught:
        lc.contact_conductance(mask, **arguments)
    assert message in str(caught.value) and caught.value.code == 2


def test_an_unconverged_conductance_raises_code_3():
    with pytest.raises(lc.LayercontactError) as caught:
        lc.contact_conductance(disk_map(64, [(0.5, 0.5)], 0.2), 1.0, 1.0, max_iter=1, tol=1e-14)
    assert caught.value.code == 3 and "not converged" in str(caught.value)


@pytest.mark.parametrize("text, message", [
    ("&output\n conductance = .true.\n conductance_base = 'insulating'\n/\n",
     "&output: conductance_base = 'insulating' is not allowed; allowed: 'conducting' (a layer on an insulating base"),
    ("&output\n conductivity = -2.0\n/\n", "&output: conductivity"),
    ("&output\n conductance_base = 'floating'\n/\n", "&output: conductance_base"),
])
def test_bad_conductance_input_in_a_scene_is_refused(text, message, tmp_path):
    nml = tmp_path / "bad.nml"
    nml.write_text("&scene\n n = 64\n/\n&loading\n normalised_pressure = 0.1\n/\n" + text)
    proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert not list(tmp_path.rglob("*.h5"))


def test_a_sweep_summary_has_both_columns(tmp_path, monkeypatch):
    """A sweep of scenes with &output conductance: its summary (CSV and HDF5) carries
    conductance and contact_stiffness for each scene and its companion, equal to the
    result files'."""
    monkeypatch.chdir(tmp_path)
    sweep_file = tmp_path / "c.nml"
    sweep_file.write_text("&scene\n n = 256\n/\n&layer\n thickness = 0.16\n poisson = 0.3\n/\n"
                          "&friction\n companion = .true.\n/\n&profile\n short_wavelength = 0.03125\n/\n"
                          "&loading\n normalised_pressure = 1.0\n/\n&output\n conductance = .true.\n conductivity = 2.0\n/\n"
                          "&sweep\n directory = 'out/c'\n processes = 1\n friction = 0.0, 0.5\n/\n")
    rows = lc.sweep(sweep_file, progress=False)
    summary = lc.read_summary("out/c/c_summary.csv")
    for k, row in enumerate(rows):
        res = lc.read_result(row["result_file"])
        assert row["conductance"] == res.conductance > 0 and row["contact_stiffness"] == res.contact_stiffness > 0
        assert row["companion_conductance"] == res.companion.conductance
        assert summary["conductance"][k] == pytest.approx(res.conductance, rel=1e-12)
        assert summary["contact_stiffness"][k] == pytest.approx(res.contact_stiffness, rel=1e-12)


@pytest.mark.parametrize("friction", [0.0, 0.5])
@pytest.mark.parametrize("stack", [dict(substrate_young=0.3, substrate_poisson=0.3),
                                   dict(lower_thickness=[0.1], lower_young=[3.0], lower_poisson=[0.45])],
                         ids=["soft substrate", "stiff lower layer"])
def test_stiffness_on_a_stack_is_the_slope_of_its_load_approach_curve(stack, friction):
    """The stiffness uses only the scene's operator, so it holds on a layer resting on a stack:
    K against (p_m2 - p_m1)/(Delta2 - Delta1) of two load-controlled solves 1e-6 apart in
    load (the contact set checked unchanged). Delta carries the rounding of a solve at
    tol = 1e-13 (~1e-13 of the profile's scale) over a step of ~1e-6 of it: 1e-5 relative."""
    heights = rough_surface(64)
    keywords = dict(period=1.0, thickness=0.05, poisson=0.3, friction=friction, stress=False, tol=1e-13, **stack)
    load = 0.002
    res = lc.solve_areal(heights, mean_pressure=load, conductance=True, **keywords)
    above = lc.solve_areal(heights, mean_pressure=load * (1 + 1e-6), **keywords)
    np.testing.assert_array_equal(above.pressure > 0, res.pressure > 0)
    slope = (above.mean_pressure - res.mean_pressure) / (above.penetration - res.penetration)
    assert res.conductance_converged and 0 < res.contact_fraction < 0.5
    assert res.contact_stiffness == pytest.approx(slope, rel=1e-5)


@pytest.mark.parametrize("thickness", [np.inf, 0.02])
def test_the_mean_is_within_the_tolerance(thickness):
    """The conjugate gradients stop on the estimated error of the mean (the energy of the
    last steps): the conductance at tol is within tol of the one at 1e-14 (measured: 3e-7 at
    tol = 1e-3, 2e-11 at 1e-6; the estimate's delay makes it conservative)."""
    heights = rough_surface(256)
    mask = heights > np.quantile(heights, 0.93)
    reference = lc.contact_conductance(mask, 1.0, 1.0, thickness=thickness, tol=1e-14)
    for tol in (1e-3, 1e-4, 1e-6, 1e-8):
        assert abs(lc.contact_conductance(mask, 1.0, 1.0, thickness=thickness, tol=tol) / reference - 1) <= tol
