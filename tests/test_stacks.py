"""Layers on compliant substrates (docs/theory.md, "Layered stacks"): the kernel of a layer
resting on lower layers and an elastic half-space, bonded or slipping, against its limits
and identities, in the tensor (`lc.surface_tensor`) and in solved contacts (lines and
surfaces, friction, viscoelastic sliding, stresses, leakage); the &layer variables that
describe a stack, and their errors.

The stack's own algebra is checked against a dense mode solve and closed forms in
tests/fortran/test_greens_stack.f90, and against a collocation solve of the Navier equations
in tests/test_stack_navier.py."""

import subprocess

import h5py
import numpy as np
import pytest

import layercontact as lc
from test_inputs import executable

# |q| h from 1e-6 to 1e4, as the kernel is used: on grids from the longest waves of a thin
# layer to the shortest of a thick one
QH = np.logspace(-6, 4, 61)


def tensor(qh, thickness=1.0, **layer):
    """T at |q| = qh (1/L, a layer of thickness 1 by default) along a direction that mixes
    x and y (all nine entries non-zero)."""
    return lc.surface_tensor(qh*np.cos(0.3), qh*np.sin(0.3), thickness=thickness, **layer)


def relative(a, b):
    """Largest entry difference per wavenumber, against the largest entry of b there."""
    return np.max(np.abs(a - b), axis=(-2, -1))/np.max(np.abs(b), axis=(-2, -1))


def test_equal_moduli_bonded_is_the_half_space_and_slipping_is_not():
    half = lc.surface_tensor(np.cos(0.3)*QH, np.sin(0.3)*QH, young=2.0, poisson=0.3)
    bonded = tensor(QH, young=2.0, poisson=0.3, substrate_young=2.0, substrate_poisson=0.3)
    slipping = tensor(QH, young=2.0, poisson=0.3, substrate_young=2.0, substrate_poisson=0.3, interface="slip")
    # the same body: equal to rounding (a few condensation steps, each O(eps))
    assert np.all(relative(bonded, half) < 1e-12)
    # a frictionless interface at depth h changes the modes that reach it (|q| h < ~3) by O(1)
    assert np.all(relative(slipping, half)[QH < 1.0] > 0.1)
    # and not those that decay before it: exp(-2|q|h) below 1e-13 from |q| h = 15
    assert np.all(relative(slipping, half)[QH > 15.0] < 1e-11)


def test_a_rigid_substrate_gives_the_layer_on_a_rigid_base():
    layer = tensor(QH, young=1.0, poisson=0.3)
    for ratio in (1e6, 1e10):
        stiff = tensor(QH, young=1.0, poisson=0.3, substrate_young=ratio, substrate_poisson=0.3)
        # the substrate adds its own compliance ~ 1/(E_s |q|) in series with the layer's
        # ~ h/E: a relative change of order (E/E_s)(1 + 1/(|q| h)); 10x that is the bound
        bound = 10.0/ratio*(1.0 + 1.0/QH)
        assert np.all(relative(stiff, layer) <= bound)


def test_a_thick_coating_is_its_own_half_space_a_thin_one_the_substrate():
    coating = dict(young=1.0, poisson=0.35)
    substrate = dict(young=20.0, poisson=0.25)
    stack = dict(**coating, substrate_young=substrate["young"], substrate_poisson=substrate["poisson"])
    thick = QH[QH >= 40.0]
    # what lies below |q| h = 40 reaches the surface with weight exp(-2|q|h) < 1e-34
    assert np.all(relative(tensor(thick, **stack), tensor(thick, thickness=np.inf, **coating)) < 1e-12)
    thin = QH[QH <= 1e-4]
    # a coating of |q| h << 1 changes the substrate's compliance by O(|q| h E_s/E)
    change = relative(tensor(thin, **stack), tensor(thin, thickness=np.inf, **substrate))
    assert np.all(change <= 10*thin*substrate["young"]/coating["young"])


def test_two_layers_of_one_material_are_one_layer():
    one = tensor(QH, thickness=1.0, young=3.0, poisson=0.45)
    two = lc.surface_tensor(np.cos(0.3)*QH, np.sin(0.3)*QH, thickness=0.3, young=3.0, poisson=0.45,
                            lower_thickness=[0.7], lower_young=[3.0], lower_poisson=[0.45])
    assert np.all(relative(two, one) < 1e-12)
    three = lc.surface_tensor(np.cos(0.3)*QH, np.sin(0.3)*QH, thickness=0.2, young=3.0, poisson=0.45,
                              lower_thickness=[0.5, 0.3], lower_young=[3.0, 3.0], lower_poisson=[0.45, 0.45],
                              lower_interfaces="bonded, bonded")
    assert np.all(relative(three, one) < 1e-12)


def test_a_slipping_rigid_base_against_its_closed_form():
    """1-A = S^2/(SC + x) (docs/theory.md): w = 2(1-A)/(E* |q|) p, for any nu."""
    x = QH[QH <= 300.0]
    for nu in (0.2, 0.5):
        t = tensor(x, young=1.0, poisson=nu, interface="slip")
        e_star = 1.0/(1.0 - nu**2)
        with np.errstate(over="ignore"):
            s, c = np.sinh(x), np.cosh(x)
            closed = np.where(x < 20, s**2/(s*c + x), np.tanh(x)/(1.0 + 2*x/np.sinh(2*x)))
        np.testing.assert_allclose(t[:, 2, 2].real*e_star*x/2, closed, rtol=1e-12)


def test_elastic_stacks_are_hermitian_with_a_positive_definite_real_part():
    rng = np.random.default_rng(17)
    for _ in range(6):
        n = int(rng.integers(0, 3))
        layer = dict(young=float(10**rng.uniform(-1, 1)), poisson=float(rng.uniform(0.0, 0.5)),
                     interface=str(rng.choice(["bonded", "slip"])))
        if n:
            layer.update(lower_thickness=list(10**rng.uniform(-1, 0.5, n)), lower_young=list(10**rng.uniform(-1, 1, n)),
                         lower_poisson=list(rng.uniform(0.0, 0.5, n)),
                         lower_interfaces=" ".join(rng.choice(["bonded", "slip"], n)))
        if rng.uniform() < 0.5:
            layer.update(substrate_young=float(10**rng.uniform(-1, 1)), substrate_poisson=0.3)
        t = tensor(QH, **layer)
        scale = np.max(np.abs(t), axis=(-2, -1))[:, None, None]
        assert np.all(np.abs(t - np.conj(np.swapaxes(t, -1, -2)))/scale < 1e-12), layer
        eigenvalues = np.linalg.eigvalsh(0.5*(t + np.conj(np.swapaxes(t, -1, -2))))
        assert np.all(eigenvalues > 0.0), layer


def test_uniform_modes_of_a_stack():
    """q = 0: the layers' h/G and h/M in series on a rigid bonded base; no uniform mode where
    a half-space lies below (zero, as for a half-space); no in-plane one where an interface
    slips."""
    e, nu, h = [2.0, 5.0], [0.3, 0.25], [0.4, 0.6]
    t = lc.surface_tensor(0.0, 0.0, thickness=h[0], young=e[0], poisson=nu[0], lower_thickness=[h[1]],
                          lower_young=[e[1]], lower_poisson=[nu[1]])
    shear = sum(hi*2*(1 + ni)/ei for hi, ei, ni in zip(h, e, nu))
    normal = sum(hi*(1 + ni)*(1 - 2*ni)/((1 - ni)*ei) for hi, ei, ni in zip(h, e, nu))
    np.testing.assert_allclose(np.diag(t).real, [shear, shear, normal], rtol=1e-14)
    slipping = lc.surface_tensor(0.0, 0.0, thickness=h[0], young=e[0], poisson=nu[0], lower_thickness=[h[1]],
                                 lower_young=[e[1]], lower_poisson=[nu[1]], lower_interfaces="slip")
    np.testing.assert_allclose(np.diag(slipping).real, [0.0, 0.0, normal], rtol=1e-14)
    on_half_space = lc.surface_tensor(0.0, 0.0, thickness=h[0], young=e[0], poisson=nu[0], substrate_young=e[1])
    assert np.all(on_half_space == 0.0)


ROUGH_LINE = 0.01*np.cos(2*np.pi*np.arange(256)/256) + 0.002*np.cos(2*np.pi*7*np.arange(256)/256 + 0.3)


@pytest.fixture(scope="module")
def rough_surface():
    return lc.self_affine_surface(64, seed=3, rms_gradient=0.1)


def test_solved_line_on_a_rigid_substrate_is_the_layer_on_a_rigid_base():
    kw = dict(thickness=0.1, poisson=0.45, friction=0.3, mean_pressure=0.01)
    base = lc.solve_line(ROUGH_LINE, **kw)
    stiff = lc.solve_line(ROUGH_LINE, **kw, substrate_young=1e12, substrate_poisson=0.3)
    # the kernels differ by O(E/E_s (1 + 1/(kh))) ~ 1e-11 (test above), the solves converge to
    # tol = 1e-10: agreement to a few 1e-10 of the peak pressure
    assert base.converged and stiff.converged
    assert np.max(np.abs(base.pressure - stiff.pressure)) <= 1e-8*base.pressure.max()
    assert abs(base.delta_mu - stiff.delta_mu) <= 1e-8*abs(base.delta_mu)
    assert abs(base.max_tension - stiff.max_tension) <= 1e-8*abs(base.max_tension)


def test_solved_surface_on_an_equal_substrate_is_the_half_space(rough_surface):
    """A bonded coating on a substrate of its own material is a half-space: pressures,
    friction and every surface stress (the uniform mode of a stack on a half-space included)
    as the half-space's, with friction on a compressible material (coupled)."""
    kw = dict(poisson=0.3, friction=0.5, mean_pressure=0.02)
    half = lc.solve_areal(rough_surface, **kw)
    stack = lc.solve_areal(rough_surface, thickness=0.05, substrate_young=1.0, substrate_poisson=0.3, **kw)
    assert half.converged and stack.converged
    # both solved to tol = 1e-10 on operators equal to rounding: 1e-8 leaves a factor 100
    # for the conditioning of the contact problem on 64^2
    peak = half.pressure.max()
    assert np.max(np.abs(half.pressure - stack.pressure)) <= 1e-8*peak
    for name in ("stress_xx", "stress_yy", "stress_xy", "displacement_x", "displacement_y"):
        a, b = getattr(half, name), getattr(stack, name)
        assert np.max(np.abs(a - b)) <= 1e-8*np.max(np.abs(a)), name
    assert abs(half.delta_mu - stack.delta_mu) <= 1e-8*peak/half.mean_pressure*abs(half.delta_mu)


def test_solved_surface_of_two_equal_layers_is_one_layer(rough_surface):
    kw = dict(poisson=0.5, friction=0.5, mean_pressure=0.01, young=2.0)
    one = lc.solve_areal(rough_surface, thickness=0.05, **kw)
    two = lc.solve_areal(rough_surface, thickness=0.02, lower_thickness=[0.03], lower_young=[2.0],
                         lower_poisson=[0.5], **kw)
    assert one.converged and two.converged
    assert np.max(np.abs(one.pressure - two.pressure)) <= 1e-8*one.pressure.max()
    assert np.max(np.abs(one.stress_xx - two.stress_xx)) <= 1e-8*np.max(np.abs(one.stress_xx))
    assert abs(one.delta_mu - two.delta_mu) <= 1e-8*abs(one.delta_mu)


def test_a_softer_substrate_spreads_the_contact_and_a_slipping_interface_more(rough_surface):
    """At one load, a softer substrate gives more contact area; a slipping interface, which
    removes the layer's shear constraint, more still (the thin incompressible layer is
    stiff only through that constraint)."""
    kw = dict(thickness=0.05, poisson=0.5, friction=0.5, mean_pressure=0.005)
    fractions = {}
    for substrate in (None, 10.0, 1.0):
        for interface in ("bonded", "slip"):
            res = lc.solve_areal(rough_surface, substrate_young=substrate, interface=interface, stress=False, **kw)
            assert res.converged
            fractions[substrate, interface] = res.contact_fraction
    assert fractions[None, "bonded"] < fractions[10.0, "bonded"] < fractions[1.0, "bonded"]
    for substrate in (None, 10.0, 1.0):
        assert fractions[substrate, "bonded"] < fractions[substrate, "slip"]


def test_a_viscoelastic_coating_on_an_elastic_substrate_balances_its_power(rough_surface):
    """The coating's complex modulus against the substrate's real one makes 1-A, 1-B and c
    complex; the steady power balance D = V p_m (Delta mu - Delta mu_energy) must still hold
    (the coupling drops out of the dissipation by reciprocity, complex c too)."""
    material = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)
    for line in (True, False):
        kw = dict(thickness=0.05, poisson=0.5, friction=0.3, material=material, speed=0.05,
                  substrate_young=3.0, substrate_poisson=0.3)
        res = (lc.solve_line(ROUGH_LINE, mean_pressure=0.01, **kw) if line
               else lc.solve_areal(rough_surface, normalised_pressure=0.1, **kw))
        assert res.converged and res.dissipated_power > 0.0
        balance = 0.05*res.mean_pressure*(res.delta_mu - res.delta_mu_energy)
        # both sides are sums over the same spectrum, equal to rounding of the larger terms
        assert balance == pytest.approx(res.dissipated_power, rel=1e-9)


def test_a_viscoelastic_lower_layer_between_its_limits_and_in_power_balance(rough_surface):
    """A lower layer that is a standard linear solid: without dispersion (e_inf = young) it
    is the elastic layer; sliding so fast that every mode is glassy it is the elastic layer
    of modulus e_inf; in between it dissipates, and the power balance holds under an elastic
    coating (the whole loss is in the lower layer)."""
    stack = dict(thickness=0.05, poisson=0.45, friction=0.3, mean_pressure=0.01, lower_thickness=[0.1],
                 lower_poisson=[0.4], substrate_young=50.0, substrate_poisson=0.3)
    elastic = lc.solve_line(ROUGH_LINE, lower_young=[2.0], **stack)
    flat = lc.solve_line(ROUGH_LINE, lower_young=[2.0], lower_tau=[1.0], lower_e_inf=[2.0], speed=0.3, **stack)
    # the same kernel (J = 1/E exactly); the viscoelastic path solves it as coupled: both to
    # tol = 1e-10
    assert np.max(np.abs(flat.pressure - elastic.pressure)) <= 1e-8*elastic.pressure.max()
    assert flat.dissipated_power == pytest.approx(0.0, abs=1e-14)
    glassy = lc.solve_line(ROUGH_LINE, lower_young=[2.0], lower_tau=[1e7], lower_e_inf=[20.0], speed=1.0, **stack)
    stiff = lc.solve_line(ROUGH_LINE, lower_young=[20.0], **stack)
    # the modulus differs from e_inf by O((e_inf/e0 - 1)/(k V tau)) ~ 1.5e-6 at the longest
    # wave (k = 2 pi): the pressures move by less than that
    assert np.max(np.abs(glassy.pressure - stiff.pressure)) <= 1e-5*stiff.pressure.max()
    for line in (True, False):
        kw = dict(stack, lower_young=[2.0], lower_tau=[1.0], lower_e_inf=[20.0], speed=0.1)
        res = (lc.solve_line(ROUGH_LINE, **kw) if line else lc.solve_areal(rough_surface, **kw))
        assert res.converged and res.dissipated_power > 0.0
        balance = 0.1*res.mean_pressure*(res.delta_mu - res.delta_mu_energy)
        assert balance == pytest.approx(res.dissipated_power, rel=1e-9)


def test_leakage_on_a_stack_runs_and_a_rigid_substrate_changes_nothing(tmp_path):
    text = """&scene geometry = 'areal', n = 64 /
&layer thickness = 0.05, poisson = 0.45, {extra} /
&friction coefficient = 0.3 /
&profile rms_gradient = 0.1, seed = 5 /
&loading normalised_pressure = 0.05 /
&output file = '{name}.h5', leakage = .true. /
"""
    results = {}
    for name, extra in (("rigid", "interface = 'bonded'"), ("stiff", "substrate_young = 1e12"),
                        ("soft", "substrate_young = 0.5")):
        nml = tmp_path / f"{name}.nml"
        nml.write_text(text.format(extra=extra, name=name))
        proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        results[name] = lc.read_result(tmp_path / f"{name}.h5")
    rigid, stiff, soft = results["rigid"], results["stiff"], results["soft"]
    assert stiff.leakage.k_eff_x == pytest.approx(rigid.leakage.k_eff_x, rel=1e-6)
    # a softer substrate closes more of the gap at the same load: less leakage
    assert soft.leakage.k_eff_x < rigid.leakage.k_eff_x
    with h5py.File(tmp_path / "soft.h5") as f:
        assert f["input"].attrs["substrate_young"] == 0.5


@pytest.mark.parametrize("layer, variable, allowed", [
    ("substrate_young = 2.0", "substrate_young", "thickness = Inf"),
    ("thickness = 0.1, substrate_poisson = 0.3", "substrate_poisson", "without substrate_young"),
    ("thickness = 0.1, lower_thickness = 0.1, 0.2, lower_young = 1.0", "lower_young", "one per lower layer"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = 1.0, lower_poisson = 0.6", "lower_poisson(1)",
     "-1 < lower_poisson <= 0.5"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = -1.0", "lower_young(1)", "> 0"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = 1.0, lower_interfaces = 'glued'",
     "lower_interfaces", "'bonded' or 'slip'"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = 1.0, lower_interfaces = 'slip slip'",
     "lower_interfaces", "one word per lower layer"),
    ("thickness = 0.1, interface = 'welded'", "interface", "'bonded' or 'slip'"),
    ("thickness = 0.1, lower_thickness = 0.1, 0.1, lower_young = 1.0, 1.0, lower_tau = 1.0, lower_e_inf = 2.0",
     "lower_tau", "one per lower layer"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = 1.0, lower_tau = 1.0", "lower_e_inf",
     "one per lower_tau value"),
    ("thickness = 0.1, lower_thickness = 0.1, lower_young = 2.0, lower_tau = 1.0, lower_e_inf = 1.0",
     "lower_e_inf(1)", ">= lower_young(1)"),
    ("thickness = 0.1, lower_thickness(2) = 0.1, lower_young(2) = 1.0", "lower_thickness", "without gaps"),
])
def test_stack_errors_name_the_variable_and_write_nothing(tmp_path, layer, variable, allowed):
    nml = tmp_path / "bad.nml"
    nml.write_text(f"&layer {layer} /\n&loading mean_pressure = 0.01 /\n&output file = 'bad.h5' /\n")
    proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "&layer" in proc.stderr and variable in proc.stderr and allowed in proc.stderr, proc.stderr
    assert not (tmp_path / "bad.h5").exists()


def test_python_stack_keywords_are_checked():
    with pytest.raises(TypeError, match="stack keywords"):
        lc.surface_tensor(1.0, 0.0, thickness=1.0, substrate_modulus=2.0)
    with pytest.raises(lc.InputError, match="lower_young"):
        lc.solve_line(ROUGH_LINE, thickness=0.1, mean_pressure=0.01, lower_thickness=[0.1], lower_young=[1.0 + 1j])
    with pytest.raises(lc.InputError, match="substrate_young"):
        lc.solve_line(ROUGH_LINE, mean_pressure=0.01, substrate_young=2.0)


def test_a_stack_scene_round_trips_through_its_result(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    nml = tmp_path / "stack.nml"
    nml.write_text("""&scene n = 512 /
&layer thickness = 0.05, poisson = 0.45, interface = 'slip',
       lower_thickness = 0.1, 0.2, lower_young = 5.0, 50.0, lower_poisson = 0.3, 0.3,
       lower_interfaces = 'bonded slip', substrate_young = 200.0, substrate_poisson = 0.28 /
&friction coefficient = 0.4 /
&loading normalised_pressure = 0.2 /
&output file = 'stack.h5' /
""")
    res = lc.run(nml)
    assert res.converged
    with h5py.File(tmp_path / "stack.h5") as f:
        attrs = f["input"].attrs
        assert attrs["interface"].decode() == "slip" and attrs["lower_interfaces"].decode() == "bonded slip"
        np.testing.assert_array_equal(f["input/lower_young"][()], [5.0, 50.0])
    again = lc.solve_line(res.height, period=1.0, thickness=0.05, poisson=0.45, interface="slip",
                          lower_thickness=[0.1, 0.2], lower_young=[5.0, 50.0], lower_poisson=[0.3, 0.3],
                          lower_interfaces=["bonded", "slip"], substrate_young=200.0, substrate_poisson=0.28,
                          friction=0.4, mean_pressure=res.mean_pressure)
    np.testing.assert_allclose(again.pressure, res.pressure, rtol=0, atol=1e-9*res.pressure.max())


def test_a_sweep_of_a_stack_scene_keeps_the_stack(tmp_path, monkeypatch):
    """A sweep writes each scene back as text: the stack's lists and words go with it, the
    substrate's modulus may be swept, and each result equals the scene solved alone."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "stack_sweep.nml"
    path.write_text("""&scene n = 256 /
&layer thickness = 0.1, poisson = 0.45, interface = 'slip', lower_thickness = 0.05, lower_young = 3.0,
       lower_poisson = 0.3, lower_interfaces = 'bonded', substrate_young = 30.0, substrate_poisson = 0.3 /
&profile short_wavelength = 0.03125 /
&loading normalised_pressure = 0.5 /
&sweep directory = 'out/stack', processes = 1, friction = 0.0, 0.5, substrate_young = 30.0, 3.0 /
""")
    rows = lc.sweep(path, progress=False)
    assert sorted((row["friction"], row["substrate_young"]) for row in rows) == [
        (0.0, 3.0), (0.0, 30.0), (0.5, 3.0), (0.5, 30.0)]
    results = sorted((tmp_path / "out" / "stack" / "results").glob("*.h5"))
    assert len(results) == 4
    for result in results:
        res = lc.read_result(result)
        with h5py.File(result) as f:
            friction = float(f["input"].attrs["friction"])
            substrate = float(f["input"].attrs["substrate_young"])
        alone = lc.solve_line(res.height, thickness=0.1, poisson=0.45, interface="slip", lower_thickness=[0.05],
                              lower_young=[3.0], lower_poisson=[0.3], substrate_young=substrate, substrate_poisson=0.3,
                              friction=friction, mean_pressure=res.mean_pressure)
        # the same scene solved twice to tol = 1e-10: equal to the solver's rounding
        np.testing.assert_allclose(alone.pressure, res.pressure, rtol=0, atol=1e-9*res.pressure.max())
