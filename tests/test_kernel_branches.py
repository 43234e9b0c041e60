"""The layer factors 1-A, 1-B, c at and around every internal branch switch of
src/greens/layer.f90 (`layer_coefficients`), their limits (half-space, incompressible),
and the inequalities that elasticity imposes on them.

Branch switches of `layer_coefficients` (read from the source below, so the tests follow
the constants if they move):
  - sinh_minus_identity(y) sums a series for y < x_series and takes sinh(y) - y above:
    1-A uses y = 2x (switch at x = x_series/2), c uses y = x (switch at x = x_series);
  - x <= x_large: direct forms; x > x_large: numerator and denominator times exp(-2x);
  - in the large-x form, exp(-x) underflows to 0 above x_u = 745.133...: x exp(-2x) and
    x^2 exp(-2x) are then set to 0 instead of computed (and x = inf takes this path).
nu enters without branches (e = 1-2nu and g = 1-nu are formed directly, e = 0 at
nu = 1/2), so the incompressible limit is tested as a limit. The creep compliance
J*(k V) of src/greens/viscoelastic.f90 has no branch switch (one closed form per model,
tested in test_viscoelastic_kernel.py); the switches of the operator built from these
factors (coupled or not, viscoelastic or not) are tested at the end.

Error bounds. Every form is a ratio whose numerator is a sum of a few terms; the longest
chain of rounded operations is about 20 (libm sinh/exp within 1 ulp, the series at most
13 positive terms with a truncation below u/4 of the sum, e = 1-2nu, g = 1-nu, kappa,
products and one division), so the computed value is within K u S/|den| of the exact
one, K = 32, u = 2^-53, S the sum of the magnitudes of the numerator's terms (with
sinh y + y for a directly evaluated sinh y - y, and 1 + 4|nu| for 1 - 4nu). S/|den| is the
value itself for 1-A and 1-B (terms >= 0, except inside sinh y - y) and larger for c,
where terms cancel near its zero (1/4 < nu < 1/2). `bound` evaluates this with mpmath;
the comparisons below therefore use no tolerance that is not derived from the formulas.
"""

import importlib.util
import math
import re

import numpy as np
import pytest

import layercontact as lc
from conftest import ROOT

_spec = importlib.util.spec_from_file_location("make_kernel_reference",
                                               ROOT / "tests" / "reference" / "make_kernel_reference.py")
_reference = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_reference)

mpmath = pytest.importorskip("mpmath")

NUS = (-0.9, 0.0, 0.3, 0.49, 0.5, float(np.nextafter(0.5, 0.0)))  # the grid, and 1/2 - ulp
U = 2.0**-53
K = 32
# a subnormal result is exact only to its spacing 2^-1074: a few roundings of it, times
# 1/(g td) <= 4, for c of the incompressible layer near x ~ 360..745
UNDERFLOW = 16 * 2.0**-1074


def _parameter(name: str) -> float:
    text = (ROOT / "src/greens/layer.f90").read_text()
    match = re.search(rf"real\(wp\), parameter :: {name} = ([0-9.eE+-]+)_wp", text)
    assert match, f"{name} not found in src/greens/layer.f90"
    return float(match.group(1))


X_SERIES = _parameter("x_series")
X_LARGE = _parameter("x_large")


def _exp_underflow() -> float:
    """Smallest double x with exp(-x) == 0 (libm, as the Fortran code uses)."""
    lo, hi = 700.0, 800.0
    while np.nextafter(lo, hi) < hi:
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (lo, mid) if math.exp(-mid) == 0.0 else (mid, hi)
    return hi


X_UNDERFLOW = _exp_underflow()
SWITCHES = {"1-A series/direct": X_SERIES / 2, "c series/direct": X_SERIES, "direct/large-x": X_LARGE,
            "exp(-x) underflow": X_UNDERFLOW}


def lib(x, nu):
    return np.column_stack(lc.layer_multipliers(np.atleast_1d(np.asarray(x, dtype=float)), nu))


def exact(x, nu, dps: int | None = 60):
    """Seed Eqs. (7)-(9) in convention P at the exact inputs, `dps` digits (None: the
    current precision, for mpmath.diff, which raises it for its difference quotients);
    the formulas of tests/reference/make_kernel_reference.py."""
    with mpmath.workdps(dps or mpmath.mp.dps):
        return _reference.coefficients(x, nu)


def bound(x: float, nu: float):
    """Absolute error bounds of the computed 1-A, 1-B, c at the double x, nu (see the
    module docstring), following the branch the code takes at x."""
    with mpmath.workdps(40):
        x, nu = mpmath.mpf(x), mpmath.mpf(nu)
        kappa, e, g = 3 - 4 * nu, 1 - 2 * nu, 1 - nu

        def smi(y):  # magnitude of sinh(y) - y as evaluated
            return mpmath.sinh(y) + y if y >= X_SERIES else mpmath.sinh(y) - y

        if x <= X_LARGE:
            s = mpmath.sinh(x)
            den = 2 * (kappa * s * s + x * x + 4 * g * g)
            sa = kappa * smi(2 * x) + 4 * e * x
            sb = kappa * mpmath.sinh(2 * x) + 2 * x
            sc = (2 * g * (1 + 4 * abs(nu)) * x * x + e * kappa * smi(x) * (s + x)) / g
        else:
            t = mpmath.exp(-2 * x)
            den = kappa / 2 * (1 - t) ** 2 + 2 * (x * x * t + 4 * g * g * t)
            sa = sb = kappa / 2 * (1 - t) * (1 + t) + 2 * x * t
            sc = (e * kappa / 4 * (1 - t) ** 2 + x * x * t) / g
        return np.array([float(K * U * v / den) for v in (sa, sb, sc)]) + np.array([0, 0, UNDERFLOW])


def check_against_exact(x: float, nu: float):
    got = lib(x, nu)[0]
    ref = np.array([float(v) for v in exact(x, nu)])
    err = np.abs(got - ref)
    tol = bound(x, nu)
    assert np.all(err <= tol), (x, nu, got, ref, err / tol)
    return got, ref


@pytest.mark.parametrize("nu", NUS)
@pytest.mark.parametrize("switch", SWITCHES)
def test_both_sides_of_each_switch(switch, nu):
    """Around each switch point x_s: the neighbouring doubles, x_s itself and points
    1e-12 .. 1e-3 away, against 60-digit mpmath within the bound of the branch used;
    then the jump between the two doubles adjacent to x_s is bounded by the two error
    bounds plus the exact change of the function over those 2 ulp."""
    xs = SWITCHES[switch]
    below, above = np.nextafter(xs, 0.0), np.nextafter(xs, np.inf)
    for x in [xs * (1 - d) for d in (1e-3, 1e-6, 1e-12)] + [below, xs, above] + \
             [xs * (1 + d) for d in (1e-12, 1e-6, 1e-3)]:
        check_against_exact(float(x), nu)
    lo, hi = lib(below, nu)[0], lib(above, nu)[0]
    exact_change = np.abs(np.array([float(p - q) for p, q in zip(exact(above, nu), exact(below, nu))]))
    assert np.all(np.abs(hi - lo) <= bound(below, nu) + bound(above, nu) + exact_change), (lo, hi)


@pytest.mark.parametrize("nu", NUS)
def test_approach_to_the_halfspace(nu):
    """x -> inf: 1-A -> 1, 1-B -> 1, c -> beta = (1-2nu)/(2(1-nu)). Against mpmath up to
    x = 1000 (which covers both sides of the exp(-x) underflow); beyond, the exact values
    differ from the limits by < exp(-2000), so the limits are the reference. 1-A and 1-B
    are exactly 1 once their distance to 1, < (2 + 4x + 4x^2 + 16) exp(-2x), is below
    u/2 (x >= 40), since then every term but kappa/2 is lost in rounding; x = +inf gives
    the same bits as the largest double."""
    beta = (1 - 2 * nu) / (2 * (1 - nu))
    for x in (20.5, 25.0, 30.0, 40.0, 100.0, 354.0, 372.0, 745.0, 746.0, 1000.0):
        check_against_exact(x, nu)
    big = lib([40.0, 100.0, 1e4, 1e300, np.finfo(float).max, np.inf], nu)
    assert np.all(big[:, :2] == 1.0)
    assert np.all(np.abs(big[2:, 2] - beta) <= 4 * U * abs(beta) + UNDERFLOW)
    assert np.array_equal(big[-1], big[-2])
    if nu == 0.5:
        # incompressible: c = -x^2 exp(-2x)/(g td) < 0 while representable, then exactly 0
        c = lib(np.geomspace(1e-6, 370, 500), nu)[:, 2]
        assert np.all(c < 0)
        assert np.all(big[2:, 2] == 0.0)


@pytest.mark.parametrize("x", [1e-8, 1e-3, 0.3, 0.999, 1.0, 1.5, 2.0, 2.5, 5.0, 19.99, 20.0, 20.01, 30.0, 100.0])
def test_incompressible_limit(x):
    """nu -> 1/2 from below: at each nu = 1/2 - delta the factors match mpmath at that
    (double) nu, and f(1/2 - delta) - f(1/2) = -delta f'(1/2) + O(delta^2): the difference
    of the library values is within delta^2 max|f''| (Taylor remainder, f'' taken at both
    ends; factor 1 instead of 1/2 for the two-point estimate) plus both error bounds."""
    half = lib(x, 0.5)[0]
    check_against_exact(x, 0.5)
    with mpmath.workdps(60):
        d1 = [mpmath.diff(lambda v, i=i: exact(x, v, None)[i], mpmath.mpf(0.5), 1) for i in range(3)]
    for delta in (1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13, 1e-15, 0.5 - float(np.nextafter(0.5, 0.0))):
        nu = 0.5 - delta
        got, _ = check_against_exact(x, nu)
        delta = 0.5 - nu  # exactly the double difference
        with mpmath.workdps(60):
            d2 = [max(abs(mpmath.diff(lambda v, i=i: exact(x, v, None)[i], mpmath.mpf(w), 2)) for w in (0.5, nu))
                  for i in range(3)]
        predicted = np.array([float(-delta * d) for d in d1])
        slack = np.array([float(delta**2 * d) for d in d2]) + bound(x, nu) + bound(x, 0.5)
        assert np.all(np.abs((got - half) - predicted) <= slack), (nu, got - half, predicted, slack)


@pytest.mark.parametrize("nu", (-0.999,) + NUS)
def test_elastic_inequalities(nu):
    """Identities of elasticity on a dense grid through every switch:
    - the 2x2 compliance [[1-A, -ic], [ic, 1-B]] is positive semi-definite: (1-A)(1-B) >= c^2
      (mpmath: the ratio is >= 4/3 for these nu, so rounding cannot decide it);
    - a thicker layer is more compliant (its kinematically admissible fields contain those
      of a thinner one): 1-A and 1-B do not decrease with x = kh (up to rounding, 2 K u
      of the value), 1-A <= 1-B (their difference is 4x/D), and the half-space bounds them: C(inf) - C(x) is positive
      semi-definite, A B >= (beta - c)^2, with A = 1 - (1-A) absolutely accurate to K u."""
    x = np.unique(np.concatenate([np.geomspace(1e-6, 60, 4000)] +
                                 [xs * (1 + np.linspace(-1e-3, 1e-3, 41)) for xs in SWITCHES.values()]))
    oma, omb, c = lib(x, nu).T
    assert np.all(oma * omb >= c * c)
    assert np.all(np.diff(oma) >= -2 * K * U * oma[1:]) and np.all(np.diff(omb) >= -2 * K * U * omb[1:])
    # 1-B - (1-A) = 4x/D > 0 falls below rounding once both are ~1 (x ~ 20): 2 K u again
    assert np.all(oma <= 1.0) and np.all(omb <= 1.0) and np.all(oma <= omb * (1 + 2 * K * U))
    beta = (1 - 2 * nu) / (2 * (1 - nu))
    a, b = 1 - oma, 1 - omb
    assert np.all(a * b - (beta - c) ** 2 >= -K * U * (a + b + 2 * np.abs(beta - c)))


# ---------------------------------------------------------------------------------------
# Switches of the operator built from the kernels (src/contact/operator.f90): a real
# multiplier and constrained CG when uncoupled, a complex one and the constrained GCR (or,
# with method 'anderson', the Anderson outer iteration) when coupled (mu_c > 0, except the
# incompressible half-space, whose c = 0),
# complex compliances for a moving viscoelastic law (speed > 0). Across each switch the
# solution is continuous: a perturbation eps of the data changes p by O(eps) (the
# solution of a monotone LCP is Lipschitz in its data) on top of the solver's tolerance.
# Measured with tol 1e-12 on this scene: the differences are 6e-12 (mu_c), 8e-12 (nu),
# 1e-13 (speed) of max p; 1e-10 bounds them with a margin for rounding of the path taken.

@pytest.fixture(scope="module")
def switch_profile():
    return lc.self_affine_profile(512, 0.8, seed=3, short_wavelength=8 / 512)


@pytest.mark.parametrize("method", ["auto", "anderson"])
@pytest.mark.parametrize("base, perturbed", [
    (dict(thickness=0.05, poisson=0.3, friction=0.0), dict(friction=1e-15)),
    (dict(thickness=np.inf, poisson=0.5, friction=0.8), dict(poisson=float(np.nextafter(0.5, 0.0)))),
    (dict(thickness=0.05, poisson=0.5, friction=0.3, speed=0.0), dict(speed=1e-15)),
], ids=["coupling mu_c 0 -> 1e-15", "coupling nu 1/2 -> 1/2 - ulp", "viscoelastic V 0 -> 1e-15"])
def test_operator_switches_are_continuous(switch_profile, base, perturbed, method):
    material = lc.StandardLinearSolid(1.0, 10.0, 1.0) if "speed" in base else None
    a = lc.solve_line(switch_profile, mean_pressure=0.05, tol=1e-12, material=material, method=method, **base)
    b = lc.solve_line(switch_profile, mean_pressure=0.05, tol=1e-12, material=material, method=method,
                      **{**base, **perturbed})
    assert a.converged and b.converged
    # the two runs take different paths (CG alone vs a coupled solver, with whatever
    # fallbacks rounding leads it to)
    first = {a.solver.split("+")[0], b.solver.split("+")[0]}
    assert first == {"cg", "gcr" if method == "auto" else "anderson"} or "speed" in base
    assert np.array_equal(a.pressure > 0, b.pressure > 0)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-10 * a.pressure.max()
    assert abs(a.penetration - b.penetration) <= 1e-10 * np.ptp(switch_profile)
