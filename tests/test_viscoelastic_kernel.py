"""Complex creep compliance J*(k) of steady sliding (seed Eqs. 12-15, docs/theory.md
"Viscoelasticity") against a direct mpmath quadrature of seed Eq. (14), plus its symmetry,
limits, sign of the loss and the position of the loss peaks.

Where the transform comes from. Seed Eq. (14) is
    Gamma_ij(x) = J(0+) G_ij(x) + int_0^inf G_ij(x + V t) J'(t) dt
for an indenter sliding at speed V along +x. For one Fourier mode G(x) = G^ exp(i k x),
G(x + V t) = G(x) exp(i k V t), so the mode is multiplied by
    J*(k) = J(0+) + int_0^inf J'(t) exp(i omega t) dt,      omega = k V,
with the sign of i fixed by Eq. (14) itself (not by a textbook convention). That integral
is what the mpmath reference below evaluates, literally, from the time-domain laws
(J(t) or E(t)), with no use of the closed forms of src/greens/viscoelastic.f90.

Each frequency magnitude is integrated once, with alternating signs of omega along the
log grid (so both signs are covered against the quadrature without paying twice for the
same |omega|); the Hermitian symmetry test then covers every omega in both signs.
"""

import math

import numpy as np
import pytest

import layercontact as lc

mpmath = pytest.importorskip("mpmath")

# ---------------------------------------------------------------------------------------
# Materials. Units are arbitrary but deliberately not 1 (a tau or a modulus dropped
# somewhere would not cancel). e_inf/e0 = 9, so the modulus-loss peak of the SLS is well
# away from omega tau = 1, where the compliance-loss peak is.
SLS = {"e0": 3.0, "e_inf": 27.0, "tau": 0.37}
# Creep Prony: J(t) = J_g + sum J_i (1 - exp(-t/tau_i)), times spread over two decades.
CREEP = {"times": (0.02, 0.3, 4.0), "values": (0.05, 0.11, 0.2), "equilibrium": 0.01}
# Relaxation Prony: E(t) = E_r + sum E_i exp(-t/tau_i).
RELAX = {"times": (0.01, 0.2, 3.0), "values": (5.0, 2.0, 0.7), "equilibrium": 1.3}


def sls_material(p=SLS):
    return lc.StandardLinearSolid(p["e0"], p["e_inf"], p["tau"])


def prony_material(p, form):
    return lc.Prony(list(p["times"]), list(p["values"]), p["equilibrium"], form)


def lib(material, omega):
    """lc.creep_compliance as a complex numpy array (1-D)."""
    return np.asarray(lc.creep_compliance(material, np.atleast_1d(np.asarray(omega, dtype=float))))


def omega_grid(tau_ref):
    """10 frequencies, |omega| tau_ref log-spaced over 1e-3 .. 1e3, signs alternating."""
    mags = np.logspace(-3.0, 3.0, 10)
    signs = np.array([1.0, -1.0] * 5)
    return signs * mags / tau_ref


# ---------------------------------------------------------------------------------------
# mpmath reference: I(omega) = int_0^inf f(t) exp(i omega t) dt for a rate f(t) that decays
# like a sum of exp(-t/tau_i). The integrand f(t) exp(i omega t) = f cos + i f sin is
# integrated as one complex function (mpmath.quad/nsum take complex values; one pass
# instead of two halves the cost), and its real and imaginary parts are then compared
# separately with the library.
#
# - Few oscillations on the support (|omega| * 45 tau_max / pi <= 30 half-periods): plain
#   Gauss-Legendre on [0, T], T = 45 tau_max, with breakpoints at every half-period and
#   at tau_min * 4^n (so a fast term is resolved near t = 0). The dropped tail is bounded
#   by exp(-45) int_0^inf |f| dt ~ 3e-20 relative: negligible.
# - Many oscillations (up to ~1.4e4 half-periods at omega tau = 1e3): the integral is
#   summed half-period by half-period (each piece by Gauss-Legendre) and the infinite sum
#   is extrapolated by Shanks' transformation (mpmath.nsum). For f = sum_i c_i exp(-t/tau_i)
#   the half-period integrals are a sum of geometric series with ratios
#   -exp(-pi/(|omega| tau_i)), which the iterated Shanks transform sums essentially exactly,
#   whatever the number of oscillations. (This is what mpmath.quadosc does, but with
#   nsum's default Richardson+Shanks, which is several times slower here.)
# Every Gauss-Legendre piece is capped at degree 6 (96 nodes: degree 7 nodes alone cost
# ~1 s at 30 digits) and must report an error estimate below 1e-20 of int |f| dt (nsum
# stops when successive Shanks estimates agree to ~1e-30 but reports no error). At
# mp.dps = 30 both
# routes agree with the exact transform to ~1e-17 relative (measured while writing this
# test, for the models below at all the frequencies used): far below the 1e-8 tested.
DPS = 30
TAIL = 45  # T = TAIL * tau_max; exp(-45) = 2.9e-20
REF_TOL = 1e-20


def _fourier_half_line(f, omega, times, scale):
    """(Re, Im) of int_0^inf f(t) exp(i omega t) dt; scale = int_0^inf |f| dt."""
    w = mpmath.mpf(omega)
    tmin, tmax = mpmath.mpf(min(times)), mpmath.mpf(max(times))
    T = TAIL * tmax
    scales = []
    t = tmin
    while t < T:
        scales.append(t)
        t *= 4
    errors = []

    def gl(g, pts):
        value, err = mpmath.quad(g, pts, method="gauss-legendre", maxdegree=6, error=True)
        errors.append(err)
        return value

    def integrand(t):  # f(t) exp(i omega t) = f(t) cos(omega t) + i f(t) sin(omega t)
        return f(t) * mpmath.expj(w * t)

    half = mpmath.pi / abs(w) if w else mpmath.inf
    if T / half <= 30:
        pts = sorted(set([mpmath.mpf(0)] + scales + [k * half for k in range(1, int(T / half) + 1)] + [T]))
        total = gl(integrand, pts)
    else:
        first = [mpmath.mpf(0)] + [s for s in scales if s < half] + [half]
        head = gl(integrand, first)
        tail = mpmath.nsum(
            lambda k: gl(integrand, [k * half, (k + 1) * half]), [1, mpmath.inf], method="shanks"
        )
        total = head + tail
    assert max(errors) <= REF_TOL * scale, f"mpmath reference not converged: {max(errors)} vs {scale}"
    return mpmath.re(total), mpmath.im(total)


def _law(kind, p):
    """(X(t), X'(t), time constants) of the time-domain law as mpmath callables, written
    from the definitions (seed Eq. 15 and the Prony forms), not from the closed forms.
    (X' is by hand; test_reference_derivative_is_the_derivative_of_the_law checks it.)"""
    mpf, exp = mpmath.mpf, mpmath.exp
    if kind == "sls":
        e0, einf, tau = mpf(p["e0"]), mpf(p["e_inf"]), mpf(p["tau"])
        dj = 1 / e0 - 1 / einf
        rate = 1 / tau

        def x(t):  # seed Eq. (15), t > 0
            return 1 / e0 - dj * exp(-t / tau)

        def dx(t):
            return dj * rate * exp(-t * rate)

        return x, dx, [p["tau"]]
    taus = [mpf(v) for v in p["times"]]
    vals = [mpf(v) for v in p["values"]]
    eq = mpf(p["equilibrium"])
    rates = [1 / s for s in taus]
    sign = 1 if kind == "creep" else -1  # E'(t) < 0 for a relaxation modulus
    coef = [sign * v / s for s, v in zip(taus, vals)]

    def dx(t):  # plain sum: all terms of one sign, no cancellation
        total = 0
        for c, r in zip(coef, rates):
            total += c * exp(-t * r)
        return total

    if kind == "creep":

        def x(t):
            return eq + mpmath.fsum(v * (1 - exp(-t / s)) for s, v in zip(taus, vals))

    else:  # relaxation modulus E(t)

        def x(t):
            return eq + mpmath.fsum(v * exp(-t / s) for s, v in zip(taus, vals))

    return x, dx, list(p["times"])


def reference_transform(kind, p, omega):
    """X(0+) + int_0^inf X'(t) exp(i omega t) dt by quadrature, at DPS digits: J*(omega)
    for a creep law, E*(omega) for a relaxation law (stress = E * strain history, the same
    hereditary integral as Eq. (14) with E in place of J)."""
    with mpmath.workdps(DPS):
        x, dx, times = _law(kind, p)
        x0 = x(mpmath.mpf(0))  # X(0+): the formulas are for t > 0 (H(t) in Eq. 15) and continuous at 0+
        scale = abs(x(TAIL * mpmath.mpf(max(times))) - x0)  # int |X'| dt: X' has one sign
        re, im = _fourier_half_line(dx, omega, times, scale)
        return float(x0 + re), float(im)


@pytest.mark.parametrize("kind", ["sls", "creep", "relaxation"])
def test_reference_derivative_is_the_derivative_of_the_law(kind):
    """Guard on the reference itself: the hand-written X'(t) is dX/dt of the law."""
    p = {"sls": SLS, "creep": CREEP, "relaxation": RELAX}[kind]
    with mpmath.workdps(DPS):
        x, dx, times = _law(kind, p)
        for t in (0.3 * min(times), max(times), 7.0 * max(times)):
            t = mpmath.mpf(t)
            assert abs(mpmath.diff(x, t) - dx(t)) <= mpmath.mpf(10) ** -20 * abs(dx(t))


def _assert_close(got, ref, rtol, what):
    """Complex relative error, and each of Re and Im relative to itself (the imaginary
    part is small at both ends of the frequency range: a wrong sign of i there would hide
    inside a purely complex-relative tolerance of a larger real part)."""
    err = abs(got - ref) / abs(ref)
    assert err <= rtol, f"{what}: |got - ref|/|ref| = {err:.3e} (got {got!r}, ref {ref!r})"
    assert abs(got.real - ref.real) <= rtol * abs(ref.real), f"{what}: Re: got {got!r}, ref {ref!r}"
    assert abs(got.imag - ref.imag) <= rtol * abs(ref.imag), f"{what}: Im: got {got!r}, ref {ref!r}"


# Required: relative 1e-8. The reference is good to ~1e-17 and the closed forms
# in double precision to a few ulp (no cancellation: every term of Re and of Im has one
# sign), so this only leaves room: a wrong sign of i flips Im (>= 2e-3 even in |J*| on
# this grid) and a wrong tau is an O(1) error in Im.
RTOL_QUAD = 1e-8


@pytest.mark.parametrize("omega", omega_grid(SLS["tau"]), ids=lambda w: f"w={w:.3g}")
def test_sls_matches_quadrature_of_eq14(omega):
    re, im = reference_transform("sls", SLS, omega)
    got = complex(lib(sls_material(), omega)[0])
    _assert_close(got, complex(re, im), RTOL_QUAD, f"SLS J*(omega={omega:g})")


@pytest.mark.parametrize("omega", omega_grid(CREEP["times"][1]), ids=lambda w: f"w={w:.3g}")
def test_creep_prony_matches_quadrature_of_eq14(omega):
    re, im = reference_transform("creep", CREEP, omega)
    got = complex(lib(prony_material(CREEP, "creep"), omega)[0])
    _assert_close(got, complex(re, im), RTOL_QUAD, f"creep Prony J*(omega={omega:g})")


@pytest.mark.parametrize("omega", omega_grid(RELAX["times"][1]), ids=lambda w: f"w={w:.3g}")
def test_relaxation_prony_modulus_matches_quadrature(omega):
    """E*(omega) = E(0+) + int_0^inf E'(t) exp(i omega t) dt (quadrature) = 1/J*(omega)."""
    re, im = reference_transform("relaxation", RELAX, omega)
    got = 1.0 / complex(lib(prony_material(RELAX, "relaxation"), omega)[0])
    _assert_close(got, complex(re, im), RTOL_QUAD, f"relaxation Prony E*(omega={omega:g})")


# ---------------------------------------------------------------------------------------
# Symmetry and limits.

MODELS = {
    "sls": (lambda: sls_material(), SLS["tau"], SLS["tau"]),
    "creep": (lambda: prony_material(CREEP, "creep"), min(CREEP["times"]), max(CREEP["times"])),
    "relaxation": (lambda: prony_material(RELAX, "relaxation"), min(RELAX["times"]), max(RELAX["times"])),
}


def static_and_glassy(kind):
    """(J(omega -> 0), J(omega -> inf)) from the parameters."""
    if kind == "sls":
        return 1 / SLS["e0"], 1 / SLS["e_inf"]
    if kind == "creep":
        return CREEP["equilibrium"] + sum(CREEP["values"]), CREEP["equilibrium"]
    return 1 / RELAX["equilibrium"], 1 / (RELAX["equilibrium"] + sum(RELAX["values"]))


@pytest.mark.parametrize("kind", MODELS)
def test_hermitian_symmetry(kind):
    """J*(-omega) = conj J*(omega): the kernel is real in x. The closed forms only flip
    the sign of an imaginary part, so this holds to rounding; 1e-14 leaves a few ulp."""
    make, tmin, tmax = MODELS[kind]
    w = np.concatenate([[0.0], np.geomspace(1e-5 / tmax, 1e5 / tmin, 121)])
    jp, jm = lib(make(), w), lib(make(), -w)
    assert jp.dtype.kind == "c" and jp.shape == w.shape
    assert np.all(np.abs(jm - np.conj(jp)) <= 1e-14 * np.abs(jp))
    assert jp[0].imag == 0.0


@pytest.mark.parametrize("kind", MODELS)
def test_low_and_high_frequency_limits(kind):
    """omega -> 0: 1/E0, J_g + sum J_i, 1/E_r; omega -> +-inf: 1/E_inf, J_g, 1/(E_r + sum E_i).
    Distance to the limit is O(|omega| tau_max) (the imaginary part is first order) at the
    low end and O(1/(|omega| tau_min)) at the high end, so omega tau_max = 1e-14 and
    omega tau_min = 1e16 are within ~1e-14 of the limits; 1e-12 leaves room for rounding."""
    make, tmin, tmax = MODELS[kind]
    static, glassy = static_and_glassy(kind)
    low = lib(make(), [0.0, 1e-14 / tmax, -1e-14 / tmax])
    high = lib(make(), [1e16 / tmin, -1e16 / tmin])
    assert np.all(np.abs(low - static) <= 1e-12 * static), (low, static)
    assert np.all(np.abs(high - glassy) <= 1e-12 * glassy), (high, glassy)


@pytest.mark.parametrize("kind", MODELS)
def test_extreme_frequencies_stay_finite(kind):
    """'any real omega': |omega| tau up to 1e300 must not overflow (omega^2 tau^2 would,
    in a naive complex division) and sits at the glassy limit."""
    make, tmin, tmax = MODELS[kind]
    _, glassy = static_and_glassy(kind)
    j = lib(make(), [1e300 / tmax, -1e300 / tmax, 1e-300, -1e-300])
    assert np.all(np.isfinite(j.real)) and np.all(np.isfinite(j.imag)), j
    assert np.all(np.abs(j[:2] - glassy) <= 1e-12 * glassy), (j, glassy)


def test_vectorised_equals_scalar_calls():
    w = omega_grid(CREEP["times"][1])
    mat = prony_material(CREEP, "creep")
    vec = lib(mat, w)
    one = np.array([complex(lib(mat, x)[0]) for x in w])
    assert np.array_equal(vec, one)


# ---------------------------------------------------------------------------------------
# Loss: sign and peak positions.


@pytest.mark.parametrize("kind", MODELS)
def test_loss_is_positive_for_positive_omega(kind):
    """Im J*(omega) > 0 for omega = k V > 0: for k > 0 with the indenter sliding along +x the
    dissipation (hysteretic friction, Delta mu ~ sum_k k Im G_eff(k) |p_k|^2) is positive.
    Equivalently the loss modulus -Im(1/J*) > 0; both flip sign for omega < 0."""
    make, tmin, tmax = MODELS[kind]
    w = np.geomspace(1e-6 / tmax, 1e6 / tmin, 241)
    jp, jm = lib(make(), w), lib(make(), -w)
    assert np.all(jp.imag > 0), w[jp.imag <= 0]
    assert np.all(-(1 / jp).imag > 0)
    assert np.all(jm.imag < 0)


# Derivation (SLS, x = omega tau, J_g = 1/E_inf, J_r = 1/E0, dJ = J_r - J_g > 0):
#   J*  = J_g + dJ/(1 - i x) = J_g + dJ (1 + i x)/(1 + x^2)
#   Im J* = dJ x/(1 + x^2) = (dJ/2) sech(ln x)                  -> peak at x = 1, value dJ/2.
#   1/J* = (1 - i x)/(J_g (1 - i x) + dJ) = (1 - i x)/(J_r - i x J_g)
#        = (1 - i x)(J_r + i x J_g)/(J_r^2 + x^2 J_g^2)
#   -Im(1/J*) = x (J_r - J_g)/(J_r^2 + x^2 J_g^2)
#             = ((E_inf - E0)/2) sech(ln(x J_g/J_r))            -> peak at x = J_r/J_g = E_inf/E0,
#                                                                  value (E_inf - E0)/2.
# Both are sech of ln(omega): unimodal in ln(omega), so a grid maximum followed by a
# golden-section search on ln(omega) finds them. Near the top sech(d) = 1 - d^2/2: in double
# precision comparisons stop resolving d below ~sqrt(2 eps) = 2e-8, so the located peak is
# good to ~2e-8 relative in omega, well inside the 1e-6 tested.


def _argmax_log(f, lo, hi):
    """argmax of f(omega) for omega in [lo, hi] (f unimodal in ln omega), vectorised f."""
    grid = np.geomspace(lo, hi, 2001)
    i = int(np.argmax(f(grid)))
    assert 0 < i < grid.size - 1, "peak at the edge of the search range"
    a, b = math.log(grid[i - 1]), math.log(grid[i + 1])
    g = (math.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(np.exp([c]))[0], f(np.exp([d]))[0]
    while b - a > 1e-10:
        if fc >= fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(np.exp([c]))[0]
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(np.exp([d]))[0]
    return math.exp(0.5 * (a + b))


def test_sls_loss_peaks():
    mat = sls_material()
    tau, e0, einf = SLS["tau"], SLS["e0"], SLS["e_inf"]

    def modulus_loss(w):
        return -(1.0 / lib(mat, w)).imag

    def compliance_loss(w):
        return lib(mat, w).imag

    w_mod = _argmax_log(modulus_loss, 1e-3 / tau, 1e4 / tau)
    w_cmp = _argmax_log(compliance_loss, 1e-3 / tau, 1e4 / tau)
    assert w_mod * tau == pytest.approx(einf / e0, rel=1e-6)
    assert w_cmp * tau == pytest.approx(1.0, rel=1e-6)
    # the peak heights (flat tops: exact to rounding at the located maximum)
    assert modulus_loss([w_mod])[0] == pytest.approx((einf - e0) / 2, rel=1e-12)
    assert compliance_loss([w_cmp])[0] == pytest.approx((1 / e0 - 1 / einf) / 2, rel=1e-12)


# ---------------------------------------------------------------------------------------
# Equivalent parametrisations.


def test_sls_equals_one_term_creep_prony():
    """J_g = 1/E_inf, J_1 = 1/E0 - 1/E_inf, tau_1 = tau is seed Eq. (15) term by term. The
    two code paths do the same floating-point operations on the same doubles, so 1e-15."""
    tau, e0, einf = SLS["tau"], SLS["e0"], SLS["e_inf"]
    prony = lc.Prony([tau], [1 / e0 - 1 / einf], 1 / einf, "creep")
    w = np.concatenate([[0.0], np.geomspace(1e-6 / tau, 1e6 / tau, 61)])
    w = np.concatenate([w, -w])
    a, b = lib(sls_material(), w), lib(prony, w)
    assert np.all(np.abs(a - b) <= 1e-15 * np.abs(a)), np.max(np.abs(a - b) / np.abs(a))


def test_one_term_relaxation_prony_is_an_sls_with_retardation_time():
    """E(t) = E_r + E_1 exp(-t/tau_r) is the SLS with E0 = E_r, E_inf = E_r + E_1 and the
    retardation time tau = tau_r E_inf/E0 (the SLS tau is a creep time):
    (E_r - i x_r E_inf)/(1 - i x_r) = 1/J*_SLS with x_r = omega tau_r. Different arithmetic
    on the two sides: a few ulp, 1e-13."""
    er, e1, tr = 1.3, 7.7, 0.05
    relax = lc.Prony([tr], [e1], er, "relaxation")
    sls = lc.StandardLinearSolid(er, er + e1, tr * (er + e1) / er)
    w = np.geomspace(1e-5 / tr, 1e5 / tr, 81)
    w = np.concatenate([[0.0], w, -w])
    a, b = lib(relax, w), lib(sls, w)
    assert np.all(np.abs(a - b) <= 1e-13 * np.abs(b)), np.max(np.abs(a - b) / np.abs(b))
