"""The contact solvers against independent truth: exact full-contact solutions, the
contact conditions recomputed with numpy's FFT, the Delta mu identities, limits where
friction must change nothing, and honest non-convergence."""

import numpy as np
import pytest

import layercontact as lc
from conftest import first_method, apply, contact_violation, g_eff
from dense_reference import solve_dense
import extremes_grid

TOL = 1e-10


def full_contact_sinusoid(h0, mode, pm, thickness, young, poisson, friction, n, period=1.0):
    """Exact solution of r = h0 cos(k x) pressed into full contact on any linear
    multiplier G_eff (derived in the docstring of test_full_contact_sinusoid_is_exact)."""
    g = g_eff(n, period, thickness, young, poisson, friction)
    k = 2 * np.pi * mode / period
    gk, g0 = g[mode], g[0].real
    x = np.arange(n) * period / n
    p = pm + h0 * np.real(np.exp(1j * k * x) / gk)
    penetration = h0 + g0 * pm
    delta_mu = k * h0**2 * gk.imag / (2 * pm * abs(gk) ** 2)
    return p, penetration, delta_mu, abs(gk)


@pytest.mark.parametrize(
    "thickness, poisson, friction",
    [(0.16, 0.5, 0.5), (0.01, 0.5, 1.5), (0.05, 0.3, 0.8), (np.inf, 0.3, 0.5), (1e-3, 0.49, 1.0)],
)
def test_full_contact_sinusoid_is_exact(thickness, poisson, friction):
    """In full contact w = r - h0 + Delta everywhere, so mode k of the pressure is
    h0/(2 G_eff(k)): p = p_m + h0 Re[exp(ikx)/G_eff(k)], Delta = h0 + G_eff(0) p_m, and
    Delta mu = -<p r'>/p_m = k h0^2 Im G_eff(k) / (2 p_m |G_eff(k)|^2). Full contact needs
    p_m > h0/|G_eff(k)|; we load to twice that."""
    n, h0, mode = 512, 1e-3, 3
    _, _, _, gabs = full_contact_sinusoid(h0, mode, 1.0, thickness, 1.0, poisson, friction, n)
    pm = 2 * h0 / gabs
    p_ref, pen_ref, dmu_ref, _ = full_contact_sinusoid(h0, mode, pm, thickness, 1.0, poisson, friction, n)
    h = lc.sinusoid_profile(n, h0, mode=mode)
    res = lc.solve_line(h, thickness=thickness, poisson=poisson, friction=friction, mean_pressure=pm, tol=TOL)
    assert res.converged and res.residual <= TOL
    assert res.contact_fraction == 1.0
    # residual is relative to p_m; the pressure field's error is of the same order
    assert np.abs(res.pressure - p_ref).max() <= 10 * TOL * pm
    assert res.penetration == pytest.approx(pen_ref, abs=10 * TOL * 2 * h0)
    for dmu in (res.delta_mu, res.delta_mu_spectral, res.delta_mu_energy, res.delta_mu_profile):
        assert dmu == pytest.approx(dmu_ref, rel=1e-8, abs=1e-14)


@pytest.mark.parametrize("thickness", [np.inf, 1.0, 0.16, 0.01, 1e-3])
@pytest.mark.parametrize("friction", [0.0, 0.5, 1.5])
def test_rough_contact_satisfies_contact_conditions(rough_profile, thickness, friction):
    """Partial contact on a rough profile: recompute w = G_eff p with numpy and check
    complementarity (no overlap, no gap in contact) to the solver tolerance."""
    h = rough_profile
    estar_scale = h.max() * (1.0 if thickness > 0.1 else 0.16 / thickness)
    res = lc.solve_line(h, thickness=thickness, friction=friction, mean_pressure=estar_scale, tol=TOL)
    assert res.converged and res.residual <= TOL
    assert 0.01 < res.contact_fraction < 0.99
    v = contact_violation(res, thickness, 1.0, 0.5)
    assert v["overlap"] <= 2 * TOL and v["gap_in_contact"] <= 2 * TOL
    assert v["w_error"] <= 1e-12
    assert res.mean_pressure == pytest.approx(estar_scale, rel=1e-13)
    assert np.all(res.pressure >= 0)


def test_delta_mu_identities_in_partial_contact(rough_profile):
    """-<p w'>/p_m (Eq. 11), the spectral sum and the energy route agree to
    rounding; the force balance on the rigid profile -<p r'>/p_m differs by a
    discretisation error that shrinks with the grid (measured: 2e-3 relative at n = 2048,
    below 1e-4 from n = 8192 on)."""
    res = lc.solve_line(rough_profile, thickness=0.16, friction=0.5, mean_pressure=0.1 * 4 * rough_profile.max())
    assert res.delta_mu > 0
    assert res.delta_mu_spectral == pytest.approx(res.delta_mu, rel=1e-10)
    assert res.delta_mu_energy == pytest.approx(res.delta_mu, rel=1e-10)
    errors = []
    for n in (2048, 32768):
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        r = lc.solve_line(h, thickness=0.16, friction=0.5, mean_pressure=0.4 * h.max(), tol=1e-11)
        errors.append(abs(r.delta_mu_profile - r.delta_mu) / r.delta_mu)
    assert errors[1] < 2e-4 and errors[1] < errors[0] / 10


def test_incompressible_halfspace_friction_changes_nothing(rough_profile):
    """c = 0 on an incompressible half-space: the scene is built without coupling; and
    approaching nu = 1/2 through the coupled solver (c ~ 1e-9) gives the same answer."""
    pm = 0.3 * rough_profile.max()
    r0 = lc.solve_line(rough_profile, poisson=0.5, friction=0.0, mean_pressure=pm)
    r1 = lc.solve_line(rough_profile, poisson=0.5, friction=0.9, mean_pressure=pm)
    near = lc.solve_line(rough_profile, poisson=0.5 - 1e-9, friction=0.9, mean_pressure=pm)
    # (near 1/2 the coupled path)
    assert first_method(r1) == first_method(r0) == "multigrid" and first_method(near) == "gcr"
    assert np.abs(near.pressure - r0.pressure).max() <= 1e-6 * r0.pressure.max()
    assert np.array_equal(r0.pressure, r1.pressure)
    assert r1.delta_mu_spectral == 0.0 and abs(r1.delta_mu) < 1e-14
    assert r1.penetration == r0.penetration


def test_sign_check_2_thin_incompressible_layer_shifts_pressure_forward():
    """Sign check 2 of docs/theory.md: on a thin incompressible layer friction moves the pressure
    maximum ahead of the asperity (+x), the leading edge forward, and Delta mu > 0; a
    compressible half-space gives Delta mu < 0."""
    n = 2048
    h = lc.sinusoid_profile(n, 1e-3)
    x = np.arange(n) / n
    x = np.where(x > 0.5, x - 1, x)  # crest at 0, contact around it
    r0 = lc.solve_line(h, thickness=0.05, friction=0.0, mean_pressure=0.02)
    r1 = lc.solve_line(h, thickness=0.05, friction=0.8, mean_pressure=0.02)
    assert 0.05 < r0.contact_fraction < 0.9
    centroid = lambda r: np.sum(x * r.pressure) / np.sum(r.pressure)  # noqa: E731
    assert abs(centroid(r0)) < 1e-12 and centroid(r1) > 1e-3
    assert x[r1.pressure > 0].max() > x[r0.pressure > 0].max()  # leading edge moved forward
    assert r1.delta_mu > 0
    hs = lc.solve_line(h, thickness=np.inf, poisson=0.3, friction=0.8, mean_pressure=1e-3)
    assert hs.delta_mu < 0


def test_displacement_control_matches_load_control(rough_profile):
    kw = dict(thickness=0.2, poisson=0.3, friction=0.6, tol=TOL)
    load = lc.solve_line(rough_profile, mean_pressure=0.2 * rough_profile.max(), **kw)
    disp = lc.solve_line(rough_profile, penetration=load.penetration, **kw)
    assert disp.converged
    assert disp.mean_pressure == pytest.approx(load.mean_pressure, rel=1e-8)
    assert np.abs(disp.pressure - load.pressure).max() <= 1e-7 * load.pressure.max()


def test_displacement_control_of_halfspace_is_refused(rough_profile):
    with pytest.raises(lc.LayercontactError, match="control = 'displacement'") as err:
        lc.solve_line(rough_profile, penetration=1e-3)
    assert err.value.code == 2


def test_not_converged_is_reported_honestly(rough_profile):
    res = lc.solve_line(rough_profile, thickness=0.01, friction=1.0, mean_pressure=rough_profile.max() * 16,
                        max_iter=5)
    assert not res.converged and res.residual > 1e-10
    assert np.all(np.isfinite(res.pressure))
    # the fields written for a stopped run belong together
    assert contact_violation(res, 0.01, 1.0, 0.5)["w_error"] <= 1e-12
    sym = lc.solve_line(rough_profile, thickness=0.16, mean_pressure=rough_profile.max(), max_iter=7,
                        method="cg")
    assert not sym.converged and contact_violation(sym, 0.16, 1.0, 0.5)["w_error"] <= 1e-12
    nested = lc.solve_line(rough_profile, thickness=0.16, mean_pressure=rough_profile.max(), max_iter=1)
    assert first_method(nested) == "multigrid" and not nested.converged and nested.iterations == 1
    assert contact_violation(nested, 0.16, 1.0, 0.5)["w_error"] <= 1e-12


def test_extreme_load_full_contact_stops_and_is_honest():
    """At loads far beyond full contact the gap is rounding noise of a large w - r. The
    solver stops (gaps below the rounding floor count as zero) instead of iterating
    forever, and the flag stays honest: converged only if the residual recomputed without
    the floor is within tol, otherwise unconverged with that residual and a gap
    resolution above tol. The pressure is the exact full-contact one either way."""
    h = lc.self_affine_profile(1024, 0.8, short_wavelength=1 / 32)
    for thickness, nu in ((0.16, 0.5), (0.16, 0.3), (np.inf, 0.5)):
        for load, tol in ((1e8, 1e-10), (1e8, 1e-6), (1e300, 1e-6)):
            pm = load * h.max()
            res = lc.solve_line(h, thickness=thickness, poisson=nu, mean_pressure=pm, max_iter=200, tol=tol)
            assert res.iterations < 200 and res.contact_fraction == 1.0
            plain = np.abs(np.minimum(res.pressure / pm, res.gap / np.ptp(h))).max()
            if res.converged:
                assert plain <= tol
            else:
                assert res.gap_resolution > tol and res.residual > tol
                assert res.residual == pytest.approx(plain, rel=1e-12)
            # full contact: p = p_m + the pressure that flattens r - mean r, exact from numpy
            g = g_eff(1024, 1.0, thickness, 1.0, nu, 0.0)
            g[0] = np.inf   # the uniform mode carries p_m
            exact = pm + apply(1 / g, h - h.mean())
            assert np.abs(res.pressure - exact).max() <= 1e-10 * pm
        # at 1e8 x the profile's peak a tolerance of 1e-6 is resolved; at 1e300 it is not
        assert lc.solve_line(h, thickness=thickness, poisson=nu, mean_pressure=1e8 * h.max(), tol=1e-6).converged
        assert not lc.solve_line(h, thickness=thickness, poisson=nu, mean_pressure=1e300, tol=1e-6).converged


def test_partial_contact_on_odd_grid(rough_profile):
    h = lc.self_affine_profile(501, 0.8, seed=4, short_wavelength=1 / 32)
    res = lc.solve_line(h, thickness=0.05, friction=0.8, mean_pressure=2 * h.max())
    assert res.converged and 0.05 < res.contact_fraction < 0.95
    v = contact_violation(res, 0.05, 1.0, 0.5)
    assert v["overlap"] <= 2 * TOL and v["gap_in_contact"] <= 2 * TOL


def test_cg_refuses_coupled_problem(rough_profile):
    with pytest.raises(lc.LayercontactError, match="not symmetric"):
        lc.solve_line(rough_profile, thickness=0.1, friction=0.5, mean_pressure=0.1, method="cg")


def test_odd_grid_and_first_mode_profile():
    """An odd number of points (no Nyquist mode) and the full-contact sinusoid."""
    n, h0 = 501, 1e-3
    p_ref, pen_ref, dmu_ref, gabs = full_contact_sinusoid(h0, 1, 1.0, 0.1, 1.0, 0.5, 0.7, n)
    pm = 2 * h0 / gabs
    p_ref, pen_ref, dmu_ref, _ = full_contact_sinusoid(h0, 1, pm, 0.1, 1.0, 0.5, 0.7, n)
    res = lc.solve_line(lc.sinusoid_profile(n, h0), thickness=0.1, friction=0.7, mean_pressure=pm)
    assert np.abs(res.pressure - p_ref).max() <= 10 * TOL * pm
    assert res.delta_mu == pytest.approx(dmu_ref, rel=1e-8)


@pytest.mark.parametrize("thickness, friction", [(np.inf, 0.0), (0.16, 0.5), (0.01, 1.0)])
def test_preconditioned_and_plain_cg_agree(rough_profile, thickness, friction):
    """Two iterations to the same fixed point: the Fourier-preconditioned constrained CG
    and the plain Polonsky-Keer one give the same pressure to the solver tolerance."""
    pm = rough_profile.max() * (1.0 if thickness > 0.1 else 16.0)
    kw = dict(thickness=thickness, friction=friction, mean_pressure=pm, tol=1e-11,
              method="cg" if friction == 0 else "auto")
    a = lc.solve_line(rough_profile, precondition=True, **kw)
    b = lc.solve_line(rough_profile, precondition=False, **kw)
    assert a.converged and b.converged
    assert a.iterations < b.iterations
    # A gap residual tol * ptp(profile) on the contact set allows pressure differences up to
    # the largest stiffness, |k_max| E*/2, times that.
    e_star = 1.0 / (1 - 0.5**2)
    bound = 1e-11 * np.ptp(rough_profile) * e_star * np.pi * rough_profile.size / 2
    assert np.abs(a.pressure - b.pressure).max() <= bound
    assert a.penetration == pytest.approx(b.penetration, rel=1e-9)


@pytest.mark.parametrize("case", ["half-space", "coupled", "thin coupled", "viscoelastic", "displacement"])
def test_coarse_start_reaches_the_same_solution(rough_profile, case):
    """Starting from the solution on the grids of every second point changes the path, not
    the fixed point: the same pressure to the solver tolerance, in fewer fine-grid
    iterations (n = 4096 has coarse levels 2048 and 1024)."""
    pm = rough_profile.max()
    kw = {
        "half-space": dict(mean_pressure=pm),
        "coupled": dict(thickness=0.16, friction=0.5, mean_pressure=pm),
        "thin coupled": dict(thickness=0.01, friction=1.0, mean_pressure=16 * pm),
        "viscoelastic": dict(thickness=0.16, friction=0.3, mean_pressure=pm, speed=0.1,
                             material=lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)),
        "displacement": dict(thickness=0.16, poisson=0.3, penetration=0.5 * np.ptp(rough_profile)),
    }[case]
    # (the constrained CG for the symmetric cases: the multigrid solver makes its own start)
    method = "cg" if case in ("half-space", "displacement") else "auto"
    a = lc.solve_line(rough_profile, coarse_start=True, tol=1e-11, method=method, **kw)
    b = lc.solve_line(rough_profile, coarse_start=False, tol=1e-11, method=method, **kw)
    assert a.converged and b.converged
    assert a.iterations < b.iterations
    # A gap residual tol * ptp(profile) on the contact set allows pressure differences up to
    # the largest stiffness, |k_max| E*/2 (E_inf for the glassy short waves of the
    # viscoelastic layer), times that.
    e_star = (10.0 if case == "viscoelastic" else 1.0) / (1 - kw.get("poisson", 0.5) ** 2)
    bound = 1e-11 * np.ptp(rough_profile) * e_star * np.pi * rough_profile.size / 2
    assert np.abs(a.pressure - b.pressure).max() <= bound
    assert a.penetration == pytest.approx(b.penetration, rel=1e-9)


def test_coarse_start_needs_an_even_grid():
    """An odd grid has no grid of every second point: the solve is the plain one."""
    h = lc.self_affine_profile(1025, 0.8, seed=3, short_wavelength=1 / 64)
    a = lc.solve_line(h, mean_pressure=h.max(), coarse_start=True)
    b = lc.solve_line(h, mean_pressure=h.max(), coarse_start=False)
    assert a.iterations == b.iterations and np.array_equal(a.pressure, b.pressure)


@pytest.mark.parametrize("method", ["cg", "multigrid"])
@pytest.mark.parametrize("n", [1024, 8192])
@pytest.mark.parametrize("ratio", [0.05, 0.25, 0.7])
def test_westergaard(n, ratio, method):
    """Frictionless sinusoid on a half-space against Westergaard's solution
    (tests/analytic.py). Point collocation resolves the contact edge to one grid step, so
    2a/lambda is within 2/n; the mean gap and the interior pressure converge much faster
    (measured worst over the three loads: mean gap 8e-7 h0 at n = 1024 and 2e-8 h0 at
    8192; pressure within 0.8 a, 3e-5 and 2e-7 of the peak). Tolerances: 10x those. The
    constrained CG and the multigrid solver solve the same collocation problem."""
    from analytic import westergaard_half_width, westergaard_mean_gap, westergaard_pressure

    h0, estar = 0.01, 4 / 3
    pm = ratio * np.pi * estar * h0
    res = lc.solve_line(lc.sinusoid_profile(n, h0), poisson=0.5, mean_pressure=pm, tol=1e-12, method=method)
    assert res.converged and first_method(res) == method
    assert abs(res.contact_fraction - 2 * westergaard_half_width(pm, estar, h0, 1.0)) <= 2 / n
    gap_tol = 1e-5 if n == 1024 else 2e-7
    assert abs((h0 - res.penetration) - westergaard_mean_gap(pm, estar, h0, 1.0)) <= gap_tol * h0
    # pressure away from the edges (square-root singular slope there)
    p_ref = westergaard_pressure(res.x, pm, estar, h0, 1.0)
    a = westergaard_half_width(pm, estar, h0, 1.0)
    xc = np.where(res.x > 0.5, res.x - 1, res.x)
    interior = np.abs(xc) < 0.8 * a
    assert np.abs(res.pressure - p_ref)[interior].max() <= (3e-4 if n == 1024 else 2e-6) * p_ref.max()


@pytest.mark.parametrize("case", ["thin coupled", "viscoelastic with friction", "displacement"])
def test_gcr_and_anderson_agree(rough_profile, case):
    """Two different coupled solvers, the constrained GCR and the Anderson
    outer iteration around the symmetric CG, reach the same fixed point: the same pressure
    to the bound the tolerance allows (a gap residual tol * ptp(profile) times the largest
    stiffness |k_max| E*/2, E_inf for the glassy short waves) and the same penetration."""
    pm = rough_profile.max()
    kw, e_star = {
        "thin coupled": (dict(thickness=0.01, friction=1.0, mean_pressure=16 * pm), 4 / 3),
        "viscoelastic with friction": (dict(thickness=0.16, friction=0.3, mean_pressure=pm, speed=0.1,
                                            material=lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)), 40 / 3),
        "displacement": (dict(thickness=0.16, poisson=0.3, friction=0.5, penetration=0.5 * np.ptp(rough_profile)),
                         1 / (1 - 0.3**2)),
    }[case]
    a = lc.solve_line(rough_profile, tol=1e-11, stress=False, method="gcr", **kw)
    b = lc.solve_line(rough_profile, tol=1e-11, stress=False, method="anderson", **kw)
    assert a.converged and b.converged
    bound = 1e-11 * np.ptp(rough_profile) * e_star * np.pi * rough_profile.size / 2
    assert np.abs(a.pressure - b.pressure).max() <= bound
    assert a.penetration == pytest.approx(b.penetration, rel=1e-9)
    assert a.mean_pressure == pytest.approx(b.mean_pressure, rel=1e-9)


@pytest.mark.parametrize("e_inf, speed, shortest, friction",
                         [(100.0, 4.64e-3, 1 / 128, 0.0), (2000.0, 0.0215, 1 / 64, 0.5)])
def test_auto_converges_on_glassy_lines_near_their_loss_peak(e_inf, speed, shortest, friction):
    """A glassy layer near its loss peak on a line of 512 points, where the plain GCR
    stalls: method 'auto' converges (going on from the GCR's best iterate, whichever way),
    to the solution the Anderson iteration alone finds, at about its cost.

    Both counts are some 4000 transform pairs of stalls and restarts that move with the
    rounding: two builds differing only in what the compiler inlines (and so in its fused
    multiply-adds) measured 3662 and 4516 pairs for 'auto', 4556 and 4078 for Anderson
    alone. The bound, a quarter more than Anderson's, holds on both and still fails a
    policy that wastes a stage."""
    h = lc.self_affine_profile(512, 0.8, seed=1, short_wavelength=shortest, rms_gradient=0.1)
    kw = dict(thickness=0.16, mean_pressure=(4 / 3) * (h.max() - h.mean()), speed=speed, friction=friction,
              tol=1e-8, stress=False, material=lc.StandardLinearSolid(e0=1.0, e_inf=e_inf, tau=1.0))
    auto = lc.solve_line(h, **kw)
    anderson = lc.solve_line(h, method="anderson", **kw)
    assert auto.converged and auto.residual <= 1e-8
    assert anderson.converged and auto.fft_pairs <= 1.25 * anderson.fft_pairs
    # tol 1e-8 on a gap scale ptp(h) with stiffness up to |k_max| E_inf*/2
    bound = 1e-8 * np.ptp(h) * (e_inf / 0.75) * np.pi * h.size / 2
    assert np.abs(auto.pressure - anderson.pressure).max() <= bound


@pytest.mark.parametrize("case", ["glassy half-space near full contact", "lossy layer with friction",
                                  "glassy bump, fast", "thin coupled elastic"])
def test_dense_newton_agrees(case):
    """A third, independent method: the dense semismooth Newton solution of the same
    discretised problem (tests/dense_reference.py, numpy LU) equals the library's to the
    bound the tolerances allow (a gap residual tol * ptp(profile) times the operator's
    largest stiffness max 1/|G_eff(k)|), with the same penetration multiplier. The first
    case is of the class whose n = 1024 versions the library cannot solve within the grid's
    budget (docs/performance.md, stability at the extremes); at n = 256 it does."""
    n = 256
    r = extremes_grid.profiles(n)["bump" if "bump" in case else "rough"]
    thickness, nu, friction, material, speed, factor = {
        "glassy half-space near full contact": (np.inf, 0.5, 0.0, lc.StandardLinearSolid(1.0, 100.0, 1.0), 0.01, 0.3),
        "lossy layer with friction": (0.16, 0.3, 0.5, lc.StandardLinearSolid(1.0, 10.0, 1.0), 1.0, 0.3),
        "glassy bump, fast": (0.16, 0.5, 0.0, lc.StandardLinearSolid(1.0, 1000.0, 1.0), 100.0, 1e-3),
        "thin coupled elastic": (0.01, 0.49, 1.0, None, 0.0, 0.3),
    }[case]
    g = g_eff(n, 1.0, thickness, 1.0, nu, friction, material, speed)
    assert np.all(g.real >= 0)  # monotone: the solution is unique
    pm = factor * extremes_grid.full_contact_pressure(r, thickness, nu, friction, material, speed)
    tol = 1e-11
    res = lc.solve_line(r, thickness=thickness, poisson=nu, friction=friction, material=material, speed=speed,
                        mean_pressure=pm, tol=tol, stress=False)
    p, s, residual = solve_dense(r, g, pm)
    assert res.converged and residual <= 1e-13
    bound = tol * np.ptp(r) * np.max(1 / np.abs(g[1:]))
    assert np.abs(res.pressure - p).max() <= bound
    # (the Newton iterate is ~1e-20 rather than 0 out of contact: count pressures above the bound)
    assert np.count_nonzero(res.pressure > bound) == np.count_nonzero(p > bound)


@pytest.mark.parametrize("n, profile, thickness, friction, factor", [
    (9, "rough", 1e-4, 0.5, 0.3), (9, "sinusoid", 1e-4, 1.0, 0.03), (8, "bump", 1e-4, 0.5, 0.3)])
def test_auto_converges_where_the_iterative_solvers_stall(n, profile, thickness, friction, factor):
    """Thin incompressible layers with strong friction on a few points: G_eff is nearly skew
    there and the plain GCR may stall. Method 'auto' converges whatever path it takes (the
    GCR with its kept history, the Anderson iteration or the dense Newton method, which may
    differ with rounding from one processor to another), to the independent numpy solver's
    solution (tests/dense_reference.py) within the bound the tolerance allows (see
    test_dense_newton_agrees)."""
    r = extremes_grid.profiles(n)[profile]
    g = g_eff(n, 1.0, thickness, 1.0, 0.5, friction)
    assert np.all(g.real >= 0)  # monotone: the solution is unique
    pm = factor * extremes_grid.full_contact_pressure(r, thickness, 0.5, friction)
    tol = 1e-9
    res = lc.solve_line(r, thickness=thickness, poisson=0.5, friction=friction, mean_pressure=pm, tol=tol,
                        stress=False)
    assert res.converged and res.residual <= tol
    p, s, residual = solve_dense(r, g, pm)
    assert residual <= 1e-13
    bound = tol * np.ptp(r) * np.max(1 / np.abs(g[1:]))
    assert np.abs(res.pressure - p).max() <= bound


def test_dense_newton_respects_the_budget(rough_profile):
    """A run stopped by max_iter stays stopped: the dense method only finishes solves that
    stalled with budget left, and its steps count as iterations."""
    res = lc.solve_line(rough_profile, thickness=0.01, friction=1.0, mean_pressure=rough_profile.max() * 16,
                        max_iter=5)
    assert not res.converged and res.iterations == 5 and "newton" not in res.solver


@pytest.mark.parametrize("case", ["glassy half-space near full contact", "lossy layer with friction",
                                  "thin coupled elastic"])
def test_newton_method_agrees(case):
    """method = 'newton' alone (the dense semismooth Newton method, from the coarse start)
    against the independent numpy solver of tests/dense_reference.py: the same solution to
    the bound the tolerance allows (see test_dense_newton_agrees)."""
    n = 256
    r = extremes_grid.profiles(n)["rough"]
    thickness, nu, friction, material, speed = {
        "glassy half-space near full contact": (np.inf, 0.5, 0.0, lc.StandardLinearSolid(1.0, 100.0, 1.0), 0.01),
        "lossy layer with friction": (0.16, 0.3, 0.5, lc.StandardLinearSolid(1.0, 10.0, 1.0), 1.0),
        "thin coupled elastic": (0.01, 0.49, 1.0, None, 0.0),
    }[case]
    g = g_eff(n, 1.0, thickness, 1.0, nu, friction, material, speed)
    pm = 0.3 * extremes_grid.full_contact_pressure(r, thickness, nu, friction, material, speed)
    tol = 1e-11
    res = lc.solve_line(r, thickness=thickness, poisson=nu, friction=friction, material=material, speed=speed,
                        mean_pressure=pm, tol=tol, stress=False, method="newton")
    assert res.converged and res.solver == "newton" and 1 <= res.iterations <= 200
    p, s, residual = solve_dense(r, g, pm)
    bound = tol * np.ptp(r) * np.max(1 / np.abs(g[1:]))
    assert np.abs(res.pressure - p).max() <= bound
    assert res.contact_fraction == np.count_nonzero(p > bound) / n


@pytest.mark.parametrize("friction", [0.0, 1.0])
def test_newton_method_under_displacement_control(friction):
    """Displacement control (the penetration given, the load found): the dense Newton
    method and the iterative solvers reach the same pressure and load on a finite
    compressible layer, symmetric (CG) and coupled (GCR)."""
    rough_profile = lc.self_affine_profile(1024, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
    kw = dict(thickness=0.16, poisson=0.3, friction=friction, penetration=0.3 * np.ptp(rough_profile), tol=1e-11,
              stress=False)
    newton = lc.solve_line(rough_profile, method="newton", **kw)
    iterative = lc.solve_line(rough_profile, **kw)
    assert newton.converged and iterative.converged and newton.solver == "newton"
    e_star = 1 / (1 - 0.3**2)
    bound = 1e-11 * np.ptp(rough_profile) * e_star * np.pi * rough_profile.size / 2
    assert np.abs(newton.pressure - iterative.pressure).max() <= 2 * bound
    assert newton.mean_pressure == pytest.approx(iterative.mean_pressure, rel=1e-9)


def test_newton_method_refuses_large_grids():
    h = lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
    with pytest.raises(lc.LayercontactError, match="method = 'newton' \\(dense\\) needs a grid of at most 2048") as err:
        lc.solve_line(h, method="newton", mean_pressure=0.01, stress=False)
    assert err.value.code == 2


def test_progress_lines_name_every_level_and_the_final_count(capfd):
    """progress=True: one line per grid level of the coarse start (512 .. n points), the
    finest with the iterations and residual the result reports; silent by default."""
    h = lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=8 / 4096, rms_gradient=0.1)
    quiet = lc.solve_line(h, mean_pressure=0.0167, tol=1e-8, method="cg")
    assert capfd.readouterr().err == ""
    res = lc.solve_line(h, mean_pressure=0.0167, tol=1e-8, progress=True, method="cg")
    lines = [line for line in capfd.readouterr().err.splitlines() if line.startswith("layercontact: n = ")]
    done = [line for line in lines if " converged in " in line]
    assert [line.split(":")[1].strip() for line in done] == [f"n = {n}" for n in (512, 1024, 2048, 4096)]
    assert f"cg converged in {res.iterations} iterations" in done[-1]
    assert f"residual {res.residual:.3E}" in done[-1]
    assert f"contact fraction {res.contact_fraction:.4f}" in done[-1]
    # printing changes nothing
    assert res.iterations == quiet.iterations and np.array_equal(res.pressure, quiet.pressure)


def test_broadband_line_needs_few_cg_iterations():
    """A regression guard (not a timing): on a self-affine line with roughness down to 8 grid
    points at n = 65536 (~1000 contact spots) points enter the contact set at most
    iterations; the constrained CG keeps its conjugacy through them and needs ~300
    iterations, where restarting at every entry (and dropping the preconditioner after a
    stall) needs ~5700 (docs/decisions/005-broadband-iterations.md, bench/scaling.py)."""
    n = 65536
    h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=8 / n, rms_gradient=0.1)
    res = lc.solve_line(h, mean_pressure=0.0167, tol=1e-8, stress=False, method="cg")
    assert res.converged and first_method(res) == "cg"
    assert res.iterations <= 600, res.iterations


def test_broadband_line_takes_the_multigrid_solver_with_few_transforms():
    """A regression guard (not a timing): the same line under method 'auto' goes to the
    multigrid solver, whose cost does not grow with the roughness scales: 4 fine-grid
    iterations and 68 transform pairs in all measured (bench/scaling.py --method multigrid),
    against 1220 pairs for the constrained CG; and the two agree to the tolerance (a gap
    error tol * ptp(h) times the largest stiffness |k_max| E*/2)."""
    n = 65536
    h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=8 / n, rms_gradient=0.1)
    res = lc.solve_line(h, mean_pressure=0.0167, tol=1e-8, stress=False)
    assert res.converged and first_method(res) == "multigrid"
    assert res.iterations <= 8 and res.fft_pairs <= 100, (res.iterations, res.fft_pairs)
    ref = lc.solve_line(h, mean_pressure=0.0167, tol=1e-10, stress=False, method="cg")
    bound = (1e-8 + 1e-10) * np.ptp(h) * (4 / 3) * np.pi * n / 2
    assert np.abs(res.pressure - ref.pressure).max() <= bound


def test_timers_split_the_solve_time():
    """setup_time and coarse_time are parts of wall_time, which is part of the call's time
    measured around it here; without the coarse start there is nothing to time there (0
    exactly), with it the coarser grids' solves take a positive time (on 128², grids of
    64² .. 32²). transform_time, the solve's time inside its transforms, is a part of
    wall_time too, and positive (the solve makes fft_pairs > 0 pairs). The clocks are the
    same monotonic clock, so the inequalities hold to its resolution (1e-9 s)."""
    import time

    h = lc.self_affine_surface(128, 0.8, seed=3, short_wavelength=8 / 128)
    for coarse_start in (True, False):
        start = time.perf_counter()
        r = lc.solve_areal(h, thickness=0.1, poisson=0.5, friction=0.5, normalised_pressure=0.1, tol=1e-8,
                           stress=False, coarse_start=coarse_start, threads=1)
        call = time.perf_counter() - start
        assert r.converged
        assert 0 < r.setup_time and 0 <= r.coarse_time
        assert r.setup_time + r.coarse_time <= r.wall_time + 1e-9 <= call + 2e-9
        assert (r.coarse_time > 0) == coarse_start
        assert r.fft_pairs > 0 and 0 < r.transform_time <= r.wall_time + 1e-9
