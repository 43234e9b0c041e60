"""Viscoelastic layers in steady sliding (seed Eqs. 12-15) through the contact solver:
elastic limits, the exact full-contact sinusoid, the loss peak, the Delta mu routes and the
power balance, uniqueness warnings, and bad material input. The compliance J*(kV) itself is
checked against a direct quadrature of Eq. (14) in test_viscoelastic_kernel.py."""

import subprocess

import numpy as np
import pytest

import layercontact as lc
from conftest import contact_violation, g_eff
from test_inputs import run_exe

SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)


@pytest.mark.parametrize("friction", [0.0, 0.6])
def test_slow_and_fast_sliding_give_the_elastic_limits(rough_profile, friction):
    """V -> 0: elastic with E0; V -> inf: elastic with E_inf (same pressure to 1e-6: the
    compliance differs from its limit by at most k V tau or 1/(k V tau), below 1e-8 on
    every mode at these speeds)."""
    pm = 0.5 * rough_profile.max()
    kw = dict(thickness=0.1, friction=friction, mean_pressure=pm, tol=1e-11)
    for speed, young in ((1e-12, SLS.e0), (1e12, SLS.e_inf)):
        visco = lc.solve_line(rough_profile, material=SLS, speed=speed, **kw)
        elastic = lc.solve_line(rough_profile, young=young, **kw)
        assert visco.converged and elastic.converged
        assert np.abs(visco.pressure - elastic.pressure).max() <= 1e-6 * elastic.pressure.max()
        assert visco.contact_fraction == elastic.contact_fraction


@pytest.mark.parametrize("material", [SLS, lc.Prony([0.1, 1.0, 10.0], [2.0, 3.0, 4.0], 1.0, "relaxation"),
                                      lc.Prony([0.5, 5.0], [0.3, 0.4], 0.2, "creep")])
@pytest.mark.parametrize("friction", [0.0, 0.8])
def test_full_contact_sinusoid_is_exact(material, friction):
    """Full contact: p = p_m + h0 Re[exp(ikx)/G(k)] with the viscoelastic multiplier, and
    Delta mu = k h0^2 Im G(k)/(2 p_m |G(k)|^2) (derived in test_solver.py)."""
    n, h0, mode, thickness, speed = 256, 1e-3, 2, 0.05, 0.3
    g = g_eff(n, 1.0, thickness, 1.0, 0.5, friction, material, speed)
    k = 2 * np.pi * mode
    pm = 2 * h0 / abs(g[mode])
    x = np.arange(n) / n
    p_ref = pm + h0 * np.real(np.exp(1j * k * x) / g[mode])
    dmu_ref = k * h0**2 * g[mode].imag / (2 * pm * abs(g[mode]) ** 2)
    res = lc.solve_line(lc.sinusoid_profile(n, h0, mode=mode), thickness=thickness, friction=friction,
                        material=material, speed=speed, mean_pressure=pm, tol=1e-11)
    assert res.converged and res.contact_fraction == 1.0
    assert np.abs(res.pressure - p_ref).max() <= 1e-9 * pm
    assert res.delta_mu == pytest.approx(dmu_ref, rel=1e-8)
    assert res.delta_mu_spectral == pytest.approx(dmu_ref, rel=1e-8)
    assert res.delta_mu > 0  # hysteresis opposes the sliding whatever the coupling


def test_loss_peak_of_a_single_relaxation_time():
    """Frictionless full contact: Delta mu = -(k h0^2/2 p_m) Im(1/G) is proportional to the
    loss modulus E''(kV), which for the SLS peaks at k V tau = E_inf/E0 (tau is a
    retardation time). Speeds on a 0.5 % grid: the peak is found to that resolution."""
    n, h0, mode = 128, 1e-4, 1
    k = 2 * np.pi * mode
    ratio = SLS.e_inf / SLS.e0
    speeds = ratio / (k * SLS.tau) * np.geomspace(0.5, 2.0, 279)  # 0.5 % steps
    pm = 5 * h0 * k * SLS.e_inf  # full contact at every speed
    dmu = [lc.solve_line(lc.sinusoid_profile(n, h0, mode=mode), poisson=0.3, material=SLS, speed=v,
                         mean_pressure=pm, stress=False).delta_mu for v in speeds]
    peak = speeds[int(np.argmax(dmu))] * k * SLS.tau
    assert peak == pytest.approx(ratio, rel=0.006)


@pytest.mark.parametrize("friction", [0.0, 0.5])
def test_power_balance_and_delta_mu_routes(rough_profile, friction):
    """Partial contact on a thin viscoelastic layer: Eq. 11 equals the spectral route to
    rounding; the energy route of elastic layers does not hold, and the difference is the
    dissipation: D = V p_m (Delta mu - mu_c <p u_x'>/p_m), with D computed from Im J* alone."""
    speed = 0.05
    res = lc.solve_line(rough_profile, thickness=0.1, friction=friction, material=SLS, speed=speed,
                        mean_pressure=3.0 * rough_profile.max(), tol=1e-11)
    assert res.converged and 0.02 < res.contact_fraction < 0.98
    v = contact_violation(res, 0.1, 1.0, 0.5, SLS, speed)
    assert v["overlap"] <= 1e-10 and v["gap_in_contact"] <= 1e-10 and v["w_error"] <= 1e-12
    assert res.delta_mu_spectral == pytest.approx(res.delta_mu, rel=1e-10)
    assert res.dissipated_power > 0
    balance = speed * res.mean_pressure * (res.delta_mu - res.delta_mu_energy)
    assert res.dissipated_power == pytest.approx(balance, rel=1e-10)
    assert abs(res.delta_mu - res.delta_mu_energy) > 0.1 * abs(res.delta_mu)


def test_non_monotone_operator_is_reported(tmp_path):
    """on a thin layer with friction, coupling times the loss compliance can
    make Re G_eff < 0 for some modes (h/lambda = 0.05, mu_c = 0.5, k V tau ~ 1)."""
    h = lc.self_affine_profile(1024, 0.8, short_wavelength=1 / 32)
    res = lc.solve_line(h, thickness=0.05, friction=0.5, material=SLS, speed=1 / (2 * np.pi),
                        mean_pressure=h.max())
    assert not res.monotone
    elastic = lc.solve_line(h, thickness=0.05, friction=0.5, mean_pressure=h.max())
    assert elastic.monotone
    nml = tmp_path / "s.nml"
    nml.write_text("&scene\n n = 1024\n/\n&layer\n thickness = 0.05\n/\n&material\n model = 'sls'\n e0 = 1.0\n"
                   " e_inf = 10.0\n tau = 1.0\n speed = 0.15915494309189535\n/\n&friction\n coefficient = 0.5\n/\n"
                   "&profile\n short_wavelength = 0.03125\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   "&output\n file = 'r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert "may not be unique" in proc.stdout


BAD = [
    ("model = 'sls'\n e0 = 10.0\n e_inf = 1.0\n tau = 1.0", "&material: e_inf"),
    ("model = 'sls'\n e0 = 1.0\n e_inf = 10.0\n tau = 0.0", "&material: tau"),
    ("model = 'sls'\n e0 = -1.0\n e_inf = 10.0\n tau = 1.0", "&material: e0"),
    ("model = 'sls'\n e0 = 1.0\n e_inf = 10.0\n tau = 1.0\n speed = -1.0", "&material: speed"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_times = 1.0, 0.5\n prony_values = 1.0, 1.0",
     "prony_times(2)"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_times = 1.0, 2.0\n prony_values = 1.0, -1.0",
     "prony_values(2)"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_times = 1.0, 2.0\n prony_values = 1.0",
     "the same number of times and values"),
    ("model = 'maxwell'", "&material: model"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'unsorted.txt'", "prony_times(3)"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'nan.txt'", "prony_values(2)"),
]


@pytest.mark.parametrize("material, message", BAD, ids=[m for _, m in BAD])
def test_bad_material_input(material, message, tmp_path):
    (tmp_path / "unsorted.txt").write_text("# tau E\n0.1 1.0\n1.0 2.0\n0.5 3.0\n")
    (tmp_path / "nan.txt").write_text("0.1 1.0\n1.0 nan\n")
    nml = tmp_path / "bad.nml"
    nml.write_text(f"&material\n {material}\n/\n&loading\n normalised_pressure = 1.0\n/\n&output\n file = 'r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr
    assert not (tmp_path / "r.h5").exists()


def test_prony_file_equals_inline_terms(tmp_path):
    (tmp_path / "rubber.txt").write_text("# tau_i  E_i\n0.01 5.0\n0.1 3.0\n1.0 2.0 ! comment\n")
    common = "&scene\n n = 512\n/\n&layer\n thickness = 0.1\n/\n&loading\n normalised_pressure = 1.0\n/\n"
    (tmp_path / "file.nml").write_text(common + "&material\n model = 'prony'\n prony_equilibrium = 1.0\n"
                                       " prony_file = 'rubber.txt'\n speed = 0.3\n/\n&output\n file = 'a.h5'\n/\n")
    (tmp_path / "inline.nml").write_text(common + "&material\n model = 'prony'\n prony_equilibrium = 1.0\n"
                                         " prony_times = 0.01, 0.1, 1.0\n prony_values = 5.0, 3.0, 2.0\n speed = 0.3\n/\n"
                                         "&output\n file = 'b.h5'\n/\n")
    for name in ("file.nml", "inline.nml"):
        assert run_exe(tmp_path / name, tmp_path).returncode == 0
    a, b = lc.read_result(tmp_path / "a.h5"), lc.read_result(tmp_path / "b.h5")
    assert np.array_equal(a.pressure, b.pressure) and a.dissipated_power > 0
    ref = lc.solve_line(a.height, thickness=0.1, material=lc.Prony([0.01, 0.1, 1.0], [5.0, 3.0, 2.0], 1.0),
                        speed=0.3, mean_pressure=a.mean_pressure)
    np.testing.assert_allclose(a.pressure, ref.pressure, rtol=0, atol=1e-12 * ref.pressure.max())


def test_contact_shifts_towards_the_leading_edge():
    """A single asperity on a viscoelastic layer: the contact and its pressure move
    ahead (+x) of the summit when sliding (measured at V = 0.1: summit shift 0.037 lambda,
    pressure shift 0.021 lambda), and not at rest (symmetric: zero to rounding)."""
    h = lc.sinusoid_profile(1024, 1e-3)
    rest = lc.solve_line(h, thickness=0.5, material=SLS, speed=0.0, mean_pressure=1e-3)
    moving = lc.solve_line(h, thickness=0.5, material=SLS, speed=0.1, mean_pressure=1e-3)
    assert abs(rest.pressure_shift) < 1e-12 and rest.summit_shift == 0.0
    assert moving.summit_shift > 0.02 and moving.pressure_shift > 0.01
    assert moving.contact_fraction < rest.contact_fraction  # stiffer when moving


MORE_BAD = [
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_times(1) = 0.1\n prony_times(3) = 5.0\n"
     " prony_values = 1.0, 1.0, 1.0", "in order from the first, without gaps"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'three.txt'", "got more"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'empty.txt'", "holds no terms"),
    ("model = 'prony'\n prony_equilibrium = 1.0\n prony_file = 'one.txt'", "expected two numbers"),
    ("model = 'elastic'\n speed = 3.0", "&material: speed"),
    ("model = 'elastic'\n e0 = 5.0", "only with model = 'sls'"),
    ("model = 'sls'\n e0 = 1.0\n e_inf = 10.0\n tau = 1.0\n prony_equilibrium = 1.0", "only with model = 'prony'"),
    ("model = 'prony'\n prony_form = 'relaxation'\n prony_equilibrium = 1.0\n prony_times = 1.0\n"
     " prony_values = 1.0\n speed = 1e306", "non-finite compliances"),
]


@pytest.mark.parametrize("material, message", MORE_BAD, ids=[m for _, m in MORE_BAD])
def test_more_bad_material_input(material, message, tmp_path):
    (tmp_path / "three.txt").write_text("0.1 1.0 99\n")
    (tmp_path / "empty.txt").write_text("# nothing\n")
    (tmp_path / "one.txt").write_text("0.1\n")
    nml = tmp_path / "bad.nml"
    nml.write_text(f"&scene\n n = 256\n/\n&material\n {material}\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                   "&output\n file = 'r.h5'\n/\n")
    proc = run_exe(nml, tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr
    assert not (tmp_path / "r.h5").exists()


def test_prony_term_limit_in_python():
    with pytest.raises(ValueError, match="1 to 64"):
        lc.Prony(np.arange(1, 66), np.ones(65), 1.0)
    with pytest.raises(ValueError, match="1 to 64"):
        lc.Prony([], [], 1.0)
