"""Stability at the extremes of the parameter space: every run either converges with its
residual below the tolerance or says it did not, and no output is NaN or Inf.

Grid: h/lambda 1e-4 .. 1e3 and the half-space, nu in {-0.9, 0, 0.3, 0.49, 0.5}, mu_c in
{0, 0.5, 1.5}, loads from a single touching asperity to full contact, n = 63 (odd) and 256.
Measured: 620 of the 630 runs converge (the others: h/lambda = 1e-4 with friction, and
near-zero contact with mu_c = 1.5 on compressible or thin layers), in under a second."""

import itertools

import numpy as np

import layercontact as lc

TOL = 1e-9


def test_every_run_converges_or_says_so():
    converged = 0
    runs = 0
    for n in (63, 256):
        h = lc.self_affine_profile(n, 0.8, seed=5, short_wavelength=4 / n)
        grid = itertools.product([1e-4, 1e-3, 1e-2, 0.16, 1.0, 1e3, np.inf], [-0.9, 0.0, 0.3, 0.49, 0.5],
                                 [0.0, 0.5, 1.5], [1e-3, 1.0, 1e4])
        for thickness, nu, friction, load in grid:
            scale = 0.16 / thickness if thickness < 0.16 else 1.0
            r = lc.solve_line(h, thickness=thickness, poisson=nu, friction=friction,
                              mean_pressure=load * scale * h.max(), tol=TOL, max_iter=20000)
            runs += 1
            fields = (r.pressure, r.gap, r.displacement_z, r.displacement_x, r.stress_xx)
            assert all(np.all(np.isfinite(f)) for f in fields), (n, thickness, nu, friction, load)
            assert np.isfinite(r.delta_mu) and np.isfinite(r.penetration) and np.isfinite(r.residual)
            assert r.converged == (r.residual <= TOL)
            assert np.all(r.pressure >= 0) and r.mean_pressure > 0
            converged += r.converged
    assert runs == 630
    assert converged >= 615  # measured 620: a regression guard, not a target
