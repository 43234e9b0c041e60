"""The areal reference solutions of areal_reference.py checked against each other (and, for the
line limit only, against the library's line multipliers).

Error measure for compliance tensors: ``|dT_ij|/sqrt(|T_ii T_jj|)``, the natural scale of a
Hermitian positive definite matrix (entries that vanish physically, e.g. the coupling of an
incompressible layer's ``c ~ x^2 exp(-2x)`` at large ``x``, are then compared at the scale of
the tensor, not at their own, which no O(1)-scaled linear solve can resolve).
"""

from __future__ import annotations

import numpy as np
import pytest

import areal_reference as ar
import layercontact as lc

YOUNG = 2.5
ANGLES = (0.0, 30.0, 45.0, 71.0)


def _nerr(a, b):
    d = np.sqrt(np.abs(np.diagonal(b, axis1=-2, axis2=-1)))
    return float(np.max(np.abs(a - b) / (d[..., :, None] * d[..., None, :])))


def _q(kh, angle_deg, h=1.0):
    t = np.deg2rad(angle_deg)
    return kh / h * np.cos(t), kh / h * np.sin(t)


# --- half-space ------------------------------------------------------------------------------

@pytest.mark.parametrize("nu", [-0.7, 0.0, 0.3, 0.5])
def test_boussinesq_cerruti_plane_strain_and_antiplane_limits(nu):
    """q along +-x: the half-plane formulas of convention P with Dundurs' c, and antiplane
    shear for tau_y."""
    es = YOUNG / (1 - nu**2)
    c = (1 - 2 * nu) / (2 * (1 - nu))
    for k in (0.7, -0.7):
        t = ar.boussinesq_cerruti_tensor(k, 0.0, YOUNG, nu)
        s = 2 / (es * abs(k))
        sg = np.sign(k)
        expect = np.array([[s, 0, 1j * sg * c * s],
                           [0, 2 * (1 + nu) / (YOUNG * abs(k)), 0],
                           [-1j * sg * c * s, 0, s]])
        assert np.max(np.abs(t - expect)) <= 1e-15 * s


def test_boussinesq_cerruti_sign_surface_moves_toward_load():
    """A compressive load p = cos(q x) (maximum at x = 0) on a compressible half-space: u_x
    = Re[T_xz exp(iqx)] points toward x = 0 (negative for small x > 0), like Johnson's
    Boussinesq solution u_r = -(1-2nu)(1+nu) P/(2 pi E r)."""
    t = ar.boussinesq_cerruti_tensor(1.0, 0.0, YOUNG, 0.3)
    x = 0.3
    ux = np.real(t[0, 2] * np.exp(1j * x))  # T_xz: u_x due to p
    assert ux < 0


# --- layer: mode solve vs half-space, vs closed form -------------------------------------------

@pytest.mark.parametrize("nu", [-0.7, 0.0, 0.3, 0.5])
def test_mode_solve_thick_layer_is_half_space(nu):
    """|q| h = 30: the layer differs from the half-space by ~x exp(-2x) ~ 1e-25: only rounding
    remains (measured <= 4e-16)."""
    for ang in ANGLES + (135.0, -60.0):
        qx, qy = _q(30.0, ang)
        t = ar.layer_tensor_mode_solve(qx, qy, 1.0, YOUNG, nu)
        hs = ar.boussinesq_cerruti_tensor(qx, qy, YOUNG, nu)
        assert _nerr(t, hs) < 1e-13
        # the closed form too, including h = inf
        assert _nerr(ar.layer_tensor_closed_form(qx, qy, 1.0, YOUNG, nu), hs) < 1e-14
        assert _nerr(ar.layer_tensor_closed_form(qx, qy, np.inf, YOUNG, nu), hs) < 1e-15


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_mode_solve_matches_rotated_closed_form(nu):
    """The 3D Navier solve (6x6 LAPACK system, no rotation) against the plane-strain +
    antiplane closed form in the wavevector's frame. Tolerance 1e-9: the 6x6 matrix's
    decaying and growing solutions become nearly parallel as x = |q| h -> 0, and for nu = 1/2
    the normal compliance (~x^3) is a cancellation of O(1) coefficients: the measured error
    grows like x^-3.5, 1.4e-10 at x = 0.01 for nu = 1/2 and <= 7e-14 for nu < 1/2; for
    x >= 1 a few ulps."""
    for kh in (0.01, 0.1, 1.0, 10.0):
        for ang in ANGLES:
            qx, qy = _q(kh, ang, h=0.7)
            t = ar.layer_tensor_mode_solve(qx, qy, 0.7, YOUNG, nu)
            cf = ar.layer_tensor_closed_form(qx, qy, 0.7, YOUNG, nu)
            assert _nerr(t, cf) < (1e-9 if kh < 0.1 else 1e-11)
            if kh >= 1:
                assert _nerr(t, cf) < 1e-14


@pytest.mark.parametrize("nu", [-0.9, 0.0, 0.25, 0.3, 0.45])
def test_mode_solve_thin_compressible_layers(nu):
    """nu < 1/2 keeps the full accuracy down to x = 1e-3 (measured <= 1e-12)."""
    for ang in ANGLES:
        qx, qy = _q(1e-3, ang)
        t = ar.layer_tensor_mode_solve(qx, qy, 1.0, YOUNG, nu)
        cf = ar.layer_tensor_closed_form(qx, qy, 1.0, YOUNG, nu)
        assert _nerr(t, cf) < 1e-11


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.5])
def test_uniform_limit(nu):
    """|q| -> 0: uniform shear h/G and uniaxial strain h/M of the layer (corrections O(x^2),
    x = 1e-3), from the mode solve, without any closed form."""
    h = 0.8
    qx, qy = _q(1e-3, 30.0, h)
    t = ar.layer_tensor_mode_solve(qx, qy, h, YOUNG, nu)
    u = ar.layer_uniform_compliance(h, YOUNG, nu)
    assert abs(t[0, 0] / u[0, 0] - 1) < 1e-5
    assert abs(t[1, 1] / u[1, 1] - 1) < 1e-5
    if nu < 0.5:
        assert abs(t[2, 2] / u[2, 2] - 1) < 1e-5
    else:  # Johnson's thin incompressible layer: T_zz = 2(1-A)/(E*|q|), 1-A ~ (2/3) x^3
        x = np.hypot(qx, qy) * h
        es = YOUNG / (1 - nu**2)
        assert abs(t[2, 2] / (2 * (2 / 3) * x**3 / (es * x / h)) - 1) < 1e-5
    # closed form at q = 0 returns the same uniform compliance
    assert np.array_equal(ar.layer_tensor_closed_form(0.0, 0.0, h, YOUNG, nu), u)


# --- symmetry: reciprocity, reality, positivity --------------------------------------------

@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.5])
def test_reciprocity_hermitian_positive(nu):
    """Betti: T_ij(q) = T_ji(-q); real fields: T(-q) = conj T(q); so T is Hermitian:
    T_xz = -T_zx (imaginary), T_xy = T_yx (real); strain energy: positive definite."""
    for kh in (0.05, 0.5, 3.0):
        for ang in ANGLES + (160.0,):
            qx, qy = _q(kh, ang)
            tensors = [ar.layer_tensor_mode_solve(qx, qy, 1.0, YOUNG, nu),
                       ar.layer_tensor_closed_form(qx, qy, 1.0, YOUNG, nu),
                       ar.boussinesq_cerruti_tensor(qx, qy, YOUNG, nu)]
            minus = [ar.layer_tensor_mode_solve(-qx, -qy, 1.0, YOUNG, nu),
                     ar.layer_tensor_closed_form(-qx, -qy, 1.0, YOUNG, nu),
                     ar.boussinesq_cerruti_tensor(-qx, -qy, YOUNG, nu)]
            for t, tm in zip(tensors, minus):
                scale = np.abs(t).max()
                assert np.abs(t[0, 2] + t[2, 0]).max() <= 1e-12 * scale
                assert np.abs(t[1, 2] + t[2, 1]).max() <= 1e-12 * scale
                assert abs(t[0, 1] - t[1, 0]) <= 1e-12 * scale
                assert abs(t[0, 2].real) <= 1e-12 * scale and abs(t[0, 1].imag) <= 1e-12 * scale
                assert np.abs(t - t.conj().T).max() <= 1e-12 * scale
                assert np.abs(tm - t.conj()).max() <= 1e-12 * scale
                assert np.linalg.eigvalsh(0.5 * (t + t.conj().T)).min() > 0


# --- line limit against the library ----------------------------------------------------------

@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.5])
def test_q_along_x_gives_repo_line_multipliers(nu):
    """(1-A, 1-B, c) read off T for q along +x: closed form to 1e-13 over 1e-3..300, the mode
    solve to 1e-12 (normalised like T) over 0.1..10."""
    es = YOUNG / (1 - nu**2)
    xs = np.array([1e-3, 0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 30.0, 300.0])
    oma, omb, c = lc.layer_multipliers(xs, nu)
    t = ar.layer_tensor_closed_form(xs, 0.0, 1.0, YOUNG, nu)
    s = 2 / (es * xs)
    got = (t[:, 2, 2].real / s, t[:, 0, 0].real / s, t[:, 0, 2].imag / s)
    for g, ref in zip(got, (oma, omb, c)):
        assert np.max(np.abs(g - ref) / np.sqrt(oma * omb)) < 1e-13
    np.testing.assert_allclose(t[:, 1, 1].real, np.tanh(xs) / (YOUNG / (2 * (1 + nu)) * xs), rtol=1e-14)
    for i, x in enumerate(xs):
        if 0.1 <= x <= 10:
            tm = ar.layer_tensor_mode_solve(x, 0.0, 1.0, YOUNG, nu) / s[i]
            scale = np.sqrt(oma[i] * omb[i])
            assert abs(tm[2, 2] - oma[i]) < 1e-12 * scale
            assert abs(tm[0, 0] - omb[i]) < 1e-12 * scale
            assert abs(tm[0, 2] - 1j * c[i]) < 1e-12 * scale
            assert abs(tm[2, 0] + 1j * c[i]) < 1e-12 * scale


@pytest.mark.parametrize("nu", [-0.9, 0.0, 0.25, 0.3, 0.5])
def test_factors_are_the_seed_coefficients(nu):
    """The stable rearrangement in layer_factors equals the seed's Eqs. (7)-(9) transcribed
    literally, mapped to convention P (c = ((1-2nu) - C)/(2(1-nu))), where the literal form has
    no cancellation (0.3 <= x <= 5, 1e-13; below, the literal 1-A of nu = 1/2, ~x^3, loses
    digits)."""
    xs = np.linspace(0.3, 5.0, 23)
    a, b, cc = ar.seed_coefficients(xs, nu)
    oma, omb, c = ar.layer_factors(xs, nu)
    np.testing.assert_allclose(oma, 1 - a, rtol=1e-13)
    np.testing.assert_allclose(omb, 1 - b, rtol=1e-13)
    assert np.max(np.abs(c - ((1 - 2 * nu) - cc) / (2 * (1 - nu)))) < 1e-13


@pytest.mark.parametrize("nu", [-0.999, -0.5, 0.0, 0.2499, 0.25, 0.3, 0.4999, 0.5])
def test_factors_against_mpmath(nu):
    """layer_factors against the seed's formulas in 40-digit arithmetic for 1e-8 <= x <= 1e6:
    1-A, 1-B to 2e-15 relative; c to 2e-15 of sqrt((1-A)(1-B)) (c crosses zero for
    nu > 1/4, where no relative bound holds). Measured: <= 6e-16."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    xs = np.logspace(-8, 6, 29)
    oma, omb, c = ar.layer_factors(xs, nu)
    n = mp.mpf(nu)
    k = 3 - 4 * n
    for i, x in enumerate(xs):
        xm = mp.mpf(x)
        d = k * mp.cosh(2 * xm) + 2 * xm**2 + (1 + k**2) / 2
        ra = (k * mp.sinh(2 * xm) - 2 * xm) / d
        rb = (k * mp.sinh(2 * xm) + 2 * xm) / d
        rc = ((1 - 2 * n) - 4 * (1 - n) * (2 + xm**2 - 6 * n + 4 * n**2) / d) / (2 * (1 - n))
        assert abs(oma[i] - float(ra)) <= 2e-15 * float(ra)
        assert abs(omb[i] - float(rb)) <= 2e-15 * float(rb)
        assert abs(c[i] - float(rc)) <= 2e-15 * float(mp.sqrt(ra * rb))


def test_factor_signs_and_limits():
    """The sign checks of docs/theory.md: c -> Dundurs' beta > 0 for the half-space; c ~ -x^2 < 0
    for a thin incompressible layer; c ~ x^2 (1-4nu)/(4(1-nu)^2) for small x."""
    _, _, c = ar.layer_factors(np.array([1e3, np.inf]), 0.3)
    np.testing.assert_allclose(c, 0.4 / 1.4, rtol=1e-15)
    x = 1e-4
    assert abs(ar.layer_factors(x, 0.5)[2] / (-x**2) - 1) < 1e-7
    for nu in (-0.5, 0.0, 0.3):
        assert abs(ar.layer_factors(x, nu)[2] / (x**2 * (1 - 4 * nu) / (4 * (1 - nu) ** 2)) - 1) < 1e-7


# --- the oblique sinusoid in full contact --------------------------------------------------

def _g_closed(h, nu, mu):
    return lambda qx, qy: ar.effective_normal_multiplier(
        ar.layer_tensor_closed_form(qx, qy, h, YOUNG, nu), mu)


SCENES = [  # (thickness, nu, mu_c)
    (0.05, 0.3, 0.5),     # thin compressible layer, uniform mode h/M
    (0.05, 0.5, 0.5),     # thin incompressible layer
    (0.3, -0.4, 0.8),
    (np.inf, 0.3, 0.5),   # half-space
    (np.inf, 0.5, 0.0),
]


@pytest.mark.parametrize("h, nu, mu", SCENES)
def test_sinusoid_full_contact_gap_vanishes_on_fft_grid(h, nu, mu):
    """w = ifft2(G fft2(p)) with the same G on a 64 x 48 grid (lx = 1, ly = 1.5, mode (3, -2)),
    G(0) = the layer's uniform compliance (h/M, or 0 for a half-space): the gap
    w - (r - Lambda + Delta) is rounding (<= 1e-13 of the amplitude)."""
    lx, ly, nx, ny, mx, my = 1.0, 1.5, 64, 48, 3, -2
    amp = 1e-3
    gfun = _g_closed(h, nu, mu)
    g0 = ar.layer_uniform_compliance(h, YOUNG, nu)[2, 2].real
    probe = ar.oblique_sinusoid_full_contact(mx, my, lx, ly, amp, 1.0, gfun, g0)
    pm = 1.5 * probe.min_mean_pressure
    sol = ar.oblique_sinusoid_full_contact(mx, my, lx, ly, amp, pm, gfun, g0)
    x = np.arange(nx) * lx / nx
    y = np.arange(ny) * ly / ny
    X, Y = np.meshgrid(x, y, indexing="ij")
    qx, qy = sol.wavevector
    r = amp * np.cos(qx * X + qy * Y)
    p = sol.pressure(X, Y)
    assert p.min() > 0
    kx = 2 * np.pi * np.fft.fftfreq(nx, lx / nx)
    ky = 2 * np.pi * np.fft.fftfreq(ny, ly / ny)
    KX, KY = np.meshgrid(kx, ky, indexing="ij")
    gg = gfun(KX, KY)
    w_hat = np.fft.fft2(p) * gg
    w = np.fft.ifft2(w_hat)
    assert np.abs(w.imag).max() < 1e-14 * amp
    gap = w.real - (r - amp + sol.penetration)
    assert np.abs(gap).max() < 1e-13 * amp
    assert sol.penetration == pytest.approx(amp + g0 * pm, rel=1e-15)
    np.testing.assert_allclose(np.mean(p), pm, rtol=1e-14)
    # Delta_mu three ways: the grid average of -p dr/dx, the closed form, the spectral form
    drdx = -amp * qx * np.sin(qx * X + qy * Y)
    dmu_grid = -np.mean(p * drdx) / pm
    p_hat = np.fft.fft2(p) / p.size
    half = KX > 0
    dmu_spec = 2 / pm * np.sum(KX[half] * gg[half].imag * np.abs(p_hat[half]) ** 2)
    scale = amp * abs(qx) * abs(sol.pressure_coefficient) / pm  # size of the averaged product
    assert abs(dmu_grid - sol.delta_mu) < 1e-13 * scale
    assert abs(dmu_spec - sol.delta_mu) < 1e-13 * scale


def test_sinusoid_positivity_threshold():
    """p >= 0 everywhere iff p_m >= |a|/|G(q)|; the minimum sits at q.x = min_phase."""
    gfun = _g_closed(0.05, 0.5, 0.5)
    amp, lx, ly = 1e-3, 1.0, 1.5
    base = ar.oblique_sinusoid_full_contact(2, 1, lx, ly, amp, 1.0, gfun)
    pmin = base.min_mean_pressure
    qx, qy = base.wavevector
    q2 = qx * qx + qy * qy
    xs = np.linspace(0, lx, 801)
    ys = np.linspace(0, ly, 803)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    for factor in (1 + 1e-9, 1.0, 1 - 1e-9, 0.9):
        sol = ar.oblique_sinusoid_full_contact(2, 1, lx, ly, amp, factor * pmin, gfun)
        at_min = sol.pressure(sol.min_phase * qx / q2, sol.min_phase * qy / q2)
        assert at_min == pytest.approx((factor - 1) * pmin, abs=1e-12 * pmin)
        assert sol.pressure(X, Y).min() >= at_min - 1e-12 * pmin  # nothing below the minimum
        if factor < 1:
            assert at_min < 0
        else:
            assert at_min >= -1e-12 * pmin


def test_sinusoid_frictionless_half_space_is_westergaard():
    """Frictionless half-space, mode along x: full contact needs p* = pi E* a/lambda
    (Westergaard), the pressure is p_m + p* cos(qx) and Delta_mu = 0."""
    nu, amp, lam = 0.3, 2e-3, 0.8
    sol = ar.oblique_sinusoid_full_contact(1, 0, lam, 1.0, amp, 1.0, _g_closed(np.inf, nu, 0.0))
    pstar = np.pi * YOUNG / (1 - nu**2) * amp / lam
    assert sol.min_mean_pressure == pytest.approx(pstar, rel=1e-14)
    assert sol.pressure(0.0, 0.3) == pytest.approx(1.0 + pstar, rel=1e-14)
    assert sol.delta_mu == 0.0


def test_sinusoid_mode_solve_multiplier_agrees():
    """The same contact with G from the 3D mode solve (|q| h = 0.5) gives the same pressure
    coefficient to the mode solve's accuracy."""
    h, nu, mu = 0.05, 0.5, 0.5
    lx = ly = 2 * np.pi * h / 0.5 * np.sqrt(2)   # |q| h = 0.5 for mode (1, 1)

    def gmode(qx, qy):
        return ar.effective_normal_multiplier(ar.layer_tensor_mode_solve(qx, qy, h, YOUNG, nu), mu)

    a = ar.oblique_sinusoid_full_contact(1, 1, lx, ly, 1e-3, 1.0, gmode)
    b = ar.oblique_sinusoid_full_contact(1, 1, lx, ly, 1e-3, 1.0, _g_closed(h, nu, mu))
    assert abs(a.pressure_coefficient / b.pressure_coefficient - 1) < 1e-12
    assert a.delta_mu == pytest.approx(b.delta_mu, rel=1e-11)


def test_delta_mu_signs():
    """Thin incompressible layer (nu = 1/2, |q| h = 0.5, mu_c = 0.5, q oblique, q_x > 0):
    c < 0 and Delta_mu > 0 (the seed's interlocking friction). Compressible half-space
    (nu = 0.3): c > 0 and Delta_mu < 0. Without friction Delta_mu = 0."""
    h = 0.05
    lx = 2 * np.pi * h / (0.5 * np.cos(np.deg2rad(30)))
    ly = 2 * np.pi * h / (0.5 * np.sin(np.deg2rad(30)))   # mode (1, 1): |q| h = 0.5, 30 deg
    thin = ar.oblique_sinusoid_full_contact(1, 1, lx, ly, 1e-3, 10.0, _g_closed(h, 0.5, 0.5))
    assert np.hypot(*thin.wavevector) * h == pytest.approx(0.5)
    assert ar.layer_factors(0.5, 0.5)[2] < 0
    assert thin.delta_mu > 0
    half = ar.oblique_sinusoid_full_contact(1, 1, lx, ly, 1e-3, 10.0, _g_closed(np.inf, 0.3, 0.5))
    assert half.delta_mu < 0
    none = ar.oblique_sinusoid_full_contact(1, 1, lx, ly, 1e-3, 10.0, _g_closed(h, 0.3, 0.0))
    assert none.delta_mu == 0.0
    # mode (-1, 1) is the mirror image in y of mode (1, 1): the same Delta_mu
    mirror = ar.oblique_sinusoid_full_contact(-1, 1, lx, ly, 1e-3, 10.0, _g_closed(h, 0.5, 0.5))
    assert mirror.delta_mu == pytest.approx(thin.delta_mu, rel=1e-12)


# --- Hertz ----------------------------------------------------------------------------------

def test_hertz_against_boussinesq_kernel():
    """w(rho) = (1/(pi E*)) int p(s)/|x - s| dA of the Hertz pressure equals delta - rho^2/(2R)
    inside the contact (polar coordinates about the field point, inner integral in closed form,
    outer by the trapezoid rule, spectrally accurate): 1e-12."""
    nu, radius, load = 0.3, 2.0, 0.01
    hz = ar.hertz_sphere(radius, load, YOUNG, nu)
    a, p0, delta = hz["contact_radius"], hz["max_pressure"], hz["penetration"]
    es = YOUNG / (1 - nu**2)
    phi = np.linspace(0, 2 * np.pi, 256, endpoint=False)
    for rho in (0.0, 0.3 * a, 0.7 * a, 0.95 * a):
        m = -rho * np.cos(phi)
        rr = np.sqrt(a * a - (rho * np.sin(phi)) ** 2)
        t0 = np.arccos(np.clip(-m / rr, -1, 1))
        inner = p0 / a * rr**2 * (t0 / 2 - np.sin(2 * t0) / 4)
        w = np.mean(inner) * 2 * np.pi / (np.pi * es)
        assert w == pytest.approx(delta - rho**2 / (2 * radius), rel=1e-12)
    # total load and the second moment
    assert 2 / 3 * np.pi * a * a * p0 == pytest.approx(load, rel=1e-15)


def test_square_lattice_constants():
    """Z(s) = 4 zeta(s) beta(s) at s = +-1/2 (mpmath)."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 30
    for s, val in ((0.5, ar.SQUARE_LATTICE_Z_HALF), (-0.5, ar.SQUARE_LATTICE_Z_MINUS_HALF)):
        ref = 4 * mp.zeta(s) * mp.dirichlet(s, [0, 1, 0, -1])
        assert abs(float(ref) - val) < 1e-15 * abs(val)


def test_periodic_image_constants_with_gaussian_load():
    """A Gaussian load of width sigma = 0.02 L: the periodic zero-mean displacement minus the
    isolated one, w_per - w_inf = c0 F + c2 F (rho^2 + 2 sigma^2) + O(L^-5). w_per is the
    lattice sum (exponentially convergent), w_inf = F exp(-y) I0(y)/(E* sigma sqrt(2 pi)),
    y = rho^2/(4 sigma^2). Measured: c0 to 2e-7 at rho = 0, c2 to 0.3 % at rho = 0.05 L."""
    nu, L, F, sig = 0.3, 1.0, 1.0, 0.02
    es = YOUNG / (1 - nu**2)
    hp = ar.hertz_periodic_correction(1.0, F, YOUNG, nu, L)
    c0, c2 = hp["c0"], hp["c2"]
    N = 73
    n = np.arange(-N, N + 1)
    QX, QY = np.meshgrid(2 * np.pi * n / L, 2 * np.pi * n / L, indexing="ij")
    q = np.hypot(QX, QY)
    q[N, N] = 1.0
    mult = 2 / (es * q) * np.exp(-q**2 * sig**2 / 2) * F / L**2
    mult[N, N] = 0.0

    def diff(rho):
        y = rho**2 / (4 * sig**2)
        return np.sum(mult * np.cos(QX * rho)) - F * np.exp(-y) * np.i0(y) / (es * sig * np.sqrt(2 * np.pi))

    d0 = diff(0.0)
    assert abs(d0 - (c0 * F + 2 * c2 * F * sig**2)) < 1e-6 * abs(c0 * F)
    rho = 0.05 * L
    assert (diff(rho) - d0) / (c2 * F * rho**2) == pytest.approx(1.0, rel=1e-2)


def test_hertz_periodic_correction_orders():
    """a and p0 change at O((a/L)^3), the penetration at O(a/L)."""
    nu, radius = 0.3, 1.0
    es = YOUNG / (1 - nu**2)
    for a_over_l in (0.05, 0.1):
        L = 1.0
        a = a_over_l * L
        load = 4 * es * a**3 / (3 * radius)
        hp = ar.hertz_periodic_correction(radius, load, YOUNG, nu, L)
        hz = hp["hertz"]
        assert hz["contact_radius"] == pytest.approx(a, rel=1e-14)
        rel_a = hp["contact_radius"] / a - 1
        assert rel_a == pytest.approx(8 * np.pi / 9 * ar.SQUARE_LATTICE_Z_MINUS_HALF * a_over_l**3, rel=5 * a_over_l**3)
        rel_p = hp["max_pressure"] / hz["max_pressure"] - 1
        assert rel_p == pytest.approx(-2 * rel_a, rel=5 * a_over_l**3)
        shift = hp["penetration_first_order"] / hz["penetration"] - 1
        assert shift == pytest.approx(4 / (3 * np.pi) * ar.SQUARE_LATTICE_Z_HALF * a_over_l, rel=1e-13)
        assert abs(hp["penetration"] / hp["penetration_first_order"] - 1) < 3 * a_over_l**3
