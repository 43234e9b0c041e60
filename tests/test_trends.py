"""The seed's line-contact trends on small cheap cases (n = 1024, 4 realisations): the
full figures come from inputs/sweeps/fig2*.nml and postproc/fig2.py. Thresholds sit well
inside the measured values quoted in each test (they are trends, not references)."""

import numpy as np
import pytest

import layercontact as lc

GBAR = 0.1
PROFILES = [lc.self_affine_profile(1024, 0.8, seed=s, short_wavelength=1 / 32, rms_gradient=GBAR) for s in (1, 2, 3, 4)]


def ensemble(thickness, friction, pressure):
    """Mean a/a0 and Delta mu over the realisations at p_m/(E* Lambda/lambda) = pressure."""
    a, dmu = [], []
    for h in PROFILES:
        lam = h.max() - h.mean()
        r = lc.solve_line(h, thickness=thickness, friction=friction, mean_pressure=pressure * 4 / 3 * lam,
                          companion=True, stress=False)
        assert r.converged and r.companion.converged
        a.append(r.a_over_a0)
        dmu.append(r.delta_mu)
    return np.mean(a), np.mean(dmu)


@pytest.fixture(scope="module")
def thin():
    """h/lambda = 0.01 at three loads and three friction coefficients."""
    return {(mu, p): ensemble(0.01, mu, p) for mu in (0.2, 0.5, 1.0) for p in (1.0, 10.0, 100.0)}


def test_thin_layer_friction_increases_contact_area(thin):
    # measured a/a0 at p = 10, 100: 1.16, 1.15 (mu 0.2); 1.34, 1.60 (0.5); 1.58, 1.89 (1.0)
    for mu in (0.2, 0.5, 1.0):
        assert thin[mu, 10.0][0] > 1.05 and thin[mu, 100.0][0] > 1.05
    assert thin[1.0, 100.0][0] > thin[0.5, 100.0][0] > thin[0.2, 100.0][0]


def test_interlocking_friction_positive_growing_and_falling_relative_to_mu(thin):
    # measured Delta mu/(mu g) at p = 1, 10, 100: 0.54 1.16 1.37 (mu 0.2); 0.53 0.70 0.81 (0.5);
    # 0.48 0.43 0.43 (1.0)
    rel = {k: v[1] / (k[0] * GBAR) for k, v in thin.items()}
    assert all(v[1] > 0 for v in thin.values())
    assert rel[0.2, 100.0] > rel[0.2, 1.0] * 1.5 and rel[0.5, 100.0] > rel[0.5, 1.0] * 1.2
    assert rel[0.2, 100.0] > rel[0.5, 100.0] > rel[1.0, 100.0]


@pytest.mark.parametrize("thickness", [1.0, 2.0])
def test_thick_layers_behave_like_a_frictionless_halfspace(thickness):
    # measured |a/a0 - 1| = 8e-5 (h = 1) and 0 (h = 2); Delta mu/(mu g) = 8e-5 and 1e-9
    a, dmu = ensemble(thickness, 0.5, 3.0)
    assert abs(a - 1) < 2e-3 and dmu / (0.5 * GBAR) < 1e-3
