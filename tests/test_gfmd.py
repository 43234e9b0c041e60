"""GFMD (&solver method = 'gfmd') against the default solvers: the same contact on
frictionless and coupled scenes, to the bound the two tolerances allow; honest reports
where the dynamics cannot converge."""

import numpy as np
import pytest

import layercontact as lc

TOL = 1e-9
P_M = 0.02


def surface(n=64, seed=2):
    return lc.self_affine_surface(n=n, hurst=0.8, seed=seed, short_wavelength=8 / n, rms_gradient=0.1)


def pressure_bound(heights, thickness, poisson, friction, tol):
    """What a residual tol allows the pressure to differ by: a gap off by tol g_ref moves the
    pressure by at most the largest stiffness |1/G_eff| times it, a pressure off by tol p_m
    directly (two solutions, each within its tolerance)."""
    ny, nx = heights.shape
    qx = 2 * np.pi * np.fft.rfftfreq(nx, 1 / nx)
    qy = 2 * np.pi * np.fft.fftfreq(ny, 1 / ny)
    t = lc.surface_tensor(*np.meshgrid(qx, qy), thickness=thickness, poisson=poisson)
    g = t[..., 2, 2] + friction * t[..., 2, 0]
    stiffness = np.max(1 / np.abs(g[np.abs(g) > 0]))
    g_ref = np.ptp(heights)
    return 2 * tol * (stiffness * g_ref + P_M)


@pytest.mark.parametrize(
    "thickness, poisson, friction",
    [(np.inf, 0.5, 0.0), (np.inf, 0.3, 0.0), (np.inf, 0.3, 0.5), (0.16, 0.5, 0.5), (0.5, 0.3, 0.3)],
    ids=["half-space", "compressible", "compressible-friction", "thin-layer-friction", "layer-friction"],
)
def test_gfmd_agrees_with_the_default_solver(thickness, poisson, friction):
    h = surface()
    ref = lc.solve_areal(h, thickness=thickness, poisson=poisson, friction=friction, mean_pressure=P_M, tol=1e-13)
    dyn = lc.solve_areal(h, thickness=thickness, poisson=poisson, friction=friction, mean_pressure=P_M, tol=TOL,
                         method="gfmd", max_iter=20000)
    assert dyn.solver == "gfmd" and dyn.converged and dyn.residual <= TOL
    bound = pressure_bound(h, thickness, poisson, friction, TOL + 1e-13)
    assert np.max(np.abs(dyn.pressure - ref.pressure)) <= bound
    assert dyn.mean_pressure == pytest.approx(P_M, rel=TOL)
    # the contact sets agree but for nodes whose pressure or gap is within the bound
    differ = (dyn.pressure > 0) != (ref.pressure > 0)
    assert np.all(ref.pressure[differ] <= bound)
    assert abs(dyn.delta_mu - ref.delta_mu) <= 1e-6 * max(abs(ref.delta_mu), friction, 1e-3)


def test_gfmd_under_displacement_control():
    """A compressible layer pressed to a given penetration: the uniform mode has a stiffness."""
    h = surface(seed=5)
    ref = lc.solve_areal(h, thickness=0.5, poisson=0.3, penetration=0.01, tol=1e-13)
    dyn = lc.solve_areal(h, thickness=0.5, poisson=0.3, penetration=0.01, tol=TOL, method="gfmd", max_iter=20000)
    assert dyn.converged
    assert dyn.mean_pressure == pytest.approx(ref.mean_pressure, rel=1e-6)
    assert dyn.penetration == pytest.approx(0.01, rel=1e-12)


def test_gfmd_reports_what_it_cannot_solve():
    """On a very thin incompressible layer with strong friction the stiffness is far from
    symmetric and the undamped follower force destabilises the dynamics: the solve stops,
    says so, and returns finite fields (the best state it checked)."""
    h = surface(n=32)
    dyn = lc.solve_areal(h, thickness=0.01, poisson=0.5, friction=1.5, mean_pressure=P_M, tol=TOL, method="gfmd",
                         max_iter=3000)
    assert not dyn.converged and dyn.residual > TOL
    assert np.all(np.isfinite(dyn.pressure)) and np.all(dyn.pressure >= 0)
    assert np.all(np.isfinite(dyn.gap))
