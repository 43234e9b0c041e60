"""Layer kernel factors 1-A, 1-B, c (seed Eqs. 7-9 in convention P): mpmath references,
the independent LAPACK mode solve, the limits and the sign checks of docs/theory.md."""

import numpy as np
import pytest

import layercontact as lc
from conftest import ROOT

mpmath = pytest.importorskip("mpmath")

# Closed forms are evaluated without cancellation: a few ulp is the target. 1e-13 leaves
# room for the one place where c crosses zero (0.25 < nu < 0.5) and only its absolute
# accuracy is meaningful: there we compare against max(|c|, 1e-13 * (1-A)).
RTOL = 1e-13


def load_reference():
    data = np.loadtxt(ROOT / "tests/data/kernel_reference.txt")
    return data[:, 0], data[:, 1], data[:, 2:5]


def test_against_stored_mpmath_reference():
    x, nu, ref = load_reference()
    worst = 0.0
    for v in np.unique(nu):
        sel = nu == v
        got = np.column_stack(lc.layer_multipliers(x[sel], v))
        scale = np.maximum(np.abs(ref[sel]), 1e-300)
        scale[:, 2] = np.maximum(np.abs(ref[sel, 2]), RTOL * ref[sel, 0])
        err = np.abs(got - ref[sel]) / scale
        worst = max(worst, err.max())
    assert worst <= RTOL, worst


def _mp_coefficients(x, nu):
    """Seed Eqs. (7)-(9) as printed, at 50 digits (independent of the stored file)."""
    mpmath.mp.dps = 50
    x, nu = mpmath.mpf(x), mpmath.mpf(nu)
    d = 5 + 2 * x**2 - 4 * nu * (3 - 2 * nu) + (3 - 4 * nu) * mpmath.cosh(2 * x)
    a = 1 + (2 * x - (3 - 4 * nu) * mpmath.sinh(2 * x)) / d
    b = 1 - (2 * x + (3 - 4 * nu) * mpmath.sinh(2 * x)) / d
    cc = 4 * (1 - nu) * (2 + x**2 - 6 * nu + 4 * nu**2) / d
    c = ((1 - 2 * nu) - cc) / (2 * (1 - nu))
    return float(1 - a), float(1 - b), float(c)


@pytest.mark.parametrize("nu", [-0.9, 0.0, 0.3, 0.5])
@pytest.mark.parametrize("x", [1e-8, 3e-5, 0.07, 0.999, 1.001, 1.999, 2.001, 19.99, 20.01, 200.0])
def test_against_mpmath_in_test(x, nu):
    ref = _mp_coefficients(x, nu)
    got = [float(v[0]) for v in lc.layer_multipliers([x], nu)]
    for g, r in zip(got[:2], ref[:2]):
        assert g == pytest.approx(r, rel=RTOL)
    assert abs(got[2] - ref[2]) <= RTOL * max(abs(ref[2]), RTOL * ref[0])


@pytest.mark.parametrize("nu", [-0.9, -0.5, 0.0, 0.3, 0.49, 0.5])
def test_closed_form_matches_lapack_mode_solve(nu):
    x = np.geomspace(1e-3, 20, 41)
    closed = np.column_stack(lc.layer_multipliers(x, nu))
    lapack = np.column_stack(lc.layer_multipliers_lapack(x, nu))
    # The mode solve loses digits like eps/x^2 at small x (its potentials are O(1) while
    # the surface displacement is O(x)); 1e-10 at x >= 1e-2 (measured: ~1e-12 at 1e-2).
    tol = 1e-10 * np.maximum(1.0, (1e-2 / x) ** 2)
    scale = np.abs(closed)
    # c is compared on the scale of the 2x2 compliance: where it decays like exp(-2x) its
    # relative digits are not meaningful for the operator
    scale[:, 2] = np.maximum(scale[:, 2], 1e-4 * np.sqrt(closed[:, 0] * closed[:, 1]))
    assert np.all(np.abs(lapack - closed) / scale <= tol[:, None])


@pytest.mark.parametrize("nu", [-0.999, -0.5, 0.0, 0.3, 0.5])
def test_finite_everywhere_and_limits(nu):
    x = np.concatenate([[0.0], np.geomspace(1e-8, 1e6, 2001), [np.inf]])
    a, b, c = lc.layer_multipliers(x, nu)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(np.isfinite(c))
    beta = (1 - 2 * nu) / (2 * (1 - nu))
    assert (a[0], b[0], c[0]) == (0.0, 0.0, 0.0)
    assert a[-1] == 1.0 and b[-1] == 1.0 and c[-1] == pytest.approx(beta, abs=1e-16)
    # thin layer: 1-B ~ x/(1-nu), c ~ x^2 (1-4nu)/(4(1-nu)^2), 1-A ~ (2/3) x^3 at nu = 1/2
    xs = 1e-6
    sa, sb, sc = (v[0] for v in lc.layer_multipliers([xs], nu))
    assert sb == pytest.approx(xs / (1 - nu), rel=1e-9)
    assert sc == pytest.approx(xs**2 * (1 - 4 * nu) / (4 * (1 - nu) ** 2), rel=1e-9)
    if nu == 0.5:
        assert sa == pytest.approx(2 / 3 * xs**3, rel=1e-9)
        # incompressible layer: coupling negative at every thickness (until it underflows)
        assert c[1:-1].max() <= 0 and c[(x > 0) & (x < 300)].max() < 0
    # monotone approach to the half-space: 1-A and 1-B increase to 1 (no overshoot past 1 + eps)
    assert a.max() <= 1 + 1e-15 and b.max() <= 1 + 1e-15


def test_sign_check_1_halfspace_surface_moves_toward_line_load():
    """Convention P, check 1: under a compressive line load at x = 0 on a compressible
    half-space, surface points on either side move toward the load (Johnson §2.2)."""
    n, nu = 4096, 0.3
    m = np.arange(n // 2 + 1)
    k = 2 * np.pi * m
    _, _, c = lc.layer_multipliers(np.full(m.size - 1, np.inf), nu)
    p_hat = np.full(m.size, 1.0 / n, dtype=complex)  # unit line load at x = 0
    ux_hat = np.zeros(m.size, dtype=complex)
    ux_hat[1:] = 2 / k[1:] * 1j * c * p_hat[1:]
    ux_hat[-1] = 0
    ux = np.fft.irfft(ux_hat * n, n=n)
    x = np.arange(n) / n
    right, left = ux[(x > 0.05) & (x < 0.45)], ux[(x > 0.55) & (x < 0.95)]
    assert np.all(right < 0) and np.all(left > 0)
    assert c[0] == pytest.approx((1 - 2 * nu) / (2 * (1 - nu)), rel=1e-15)


def test_sign_check_2_thin_incompressible_coupling_is_negative():
    for x in [1e-4, 1e-2, 0.1]:
        _, _, c = lc.layer_multipliers([x], 0.5)
        assert c[0] < 0 and c[0] == pytest.approx(-(x**2), rel=2 * x**2 + 1e-12)


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.45])
def test_uniform_mode_of_a_layer_is_h_over_constrained_modulus(nu):
    """k -> 0: 2(1-A)/(E* k) -> h/M, M = E(1-nu)/((1+nu)(1-2nu)) (uniaxial strain)."""
    young, h = 2.0, 0.3
    m_mod = young * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    k = 1e-7 / h
    a, _, _ = lc.layer_multipliers([k * h], nu)
    assert 2 * a[0] / (young / (1 - nu**2) * k) == pytest.approx(h / m_mod, rel=1e-12)


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_flat_punch_on_layer_compresses_by_p_h_over_m(nu):
    """A flat rigid surface on a compressible layer: uniform pressure, Delta = p_m h/M."""
    young, h, pm = 2.0, 0.3, 0.01
    res = lc.solve_line(np.zeros(64), thickness=h, young=young, poisson=nu, friction=0.5, mean_pressure=pm)
    m_mod = young * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    assert res.converged and res.contact_fraction == 1.0
    assert np.allclose(res.pressure, pm, rtol=1e-13)
    assert res.penetration == pytest.approx(pm * h / m_mod, rel=1e-13)
