"""Reynolds leakage through a gap (lc.reynolds_leakage): exact layered solutions, the exact 1D
integral, grid convergence, blocked and pocketed gaps, symmetries, and an independent dense
solve of the same finite-volume equations."""

import numpy as np
import pytest

import layercontact as lc

# A direct solve of a well-conditioned system leaves rounding only: N^(1/2) eps-sized errors
# over at most a few thousand cells.
DIRECT = 1e-12
# CG stopped at tol=1e-12 on k_eff: the estimate of the energy error has a delay of a few
# iterations, so allow two orders above it.
ITERATIVE = 1e-10


def grid(nx, ny=None, period=(1.0, 1.0)):
    """Coordinates ``(x, y)`` of the ``(ny, nx)`` grid of the periodic cell."""
    ny = ny or nx
    return np.meshgrid(np.arange(nx) * period[0] / nx, np.arange(ny) * period[1] / ny)


def smooth_gap(nx, ny=None, period=(1.0, 1.0)):
    """A positive smooth anisotropic gap (between 0.2 and 1.8)."""
    x, y = grid(nx, ny, period)
    u, v = 2 * np.pi * x / period[0], 2 * np.pi * y / period[1]
    return 1 + 0.5 * np.cos(u) * np.cos(v) + 0.3 * np.sin(u + 2 * v)


def random_gap(shape, contact_fraction, seed, smooth=3):
    """A correlated random gap with about ``contact_fraction`` of the cells in contact: a
    periodic smoothed random field cut at its quantile."""
    rng = np.random.default_rng(seed)
    field = rng.standard_normal(shape)
    qy = np.fft.fftfreq(shape[0])[:, None]
    qx = np.fft.fftfreq(shape[1])[None, :]
    field = np.fft.ifft2(np.fft.fft2(field) * np.exp(-((smooth * np.pi) ** 2) * (qx**2 + qy**2))).real
    level = np.quantile(field, contact_fraction)
    return np.maximum(field - level, 0.0)


def test_uniform_gap_is_g_cubed():
    g = 0.37
    for direction in ("x", "y"):
        res = lc.reynolds_leakage(
            np.full((6, 10), g), period=(2.0, 0.5), direction=direction, viscosity=3.0, pressure_gradient=5.0
        )
        assert res.k_eff == pytest.approx(g**3, rel=DIRECT)
        assert res.flux == pytest.approx(g**3 * 5.0 / (12 * 3.0), rel=DIRECT)
        assert res.k_transverse == pytest.approx(0.0, abs=DIRECT * g**3)
        assert res.percolating and res.connected_fraction == 1.0
    # the pressure is the imposed gradient alone: P = -G x (x from the first grid point)
    res = lc.reynolds_leakage(np.full((6, 10), g), period=(2.0, 0.5), pressure_gradient=5.0)
    x, _ = grid(10, 6, (2.0, 0.5))
    assert np.allclose(res.pressure, -5.0 * x, rtol=0, atol=DIRECT * 10)


def test_stripes_along_and_across_the_flow():
    # Flow along stripes sees the arithmetic mean of g^3 (parallel channels), flow across
    # them the harmonic mean (in series); both are exact in the cell-constant model.
    stripes = np.random.default_rng(4).uniform(0.2, 2.0, 24)
    along = np.tile(stripes[:, None], (1, 16))  # g depends on y only
    g3 = stripes**3
    for method, tol in (("direct", DIRECT), ("amg", ITERATIVE)):
        res_along = lc.reynolds_leakage(along, direction="x", method=method, tol=1e-12)
        res_across = lc.reynolds_leakage(along, direction="y", method=method, tol=1e-12)
        assert res_along.k_eff == pytest.approx(g3.mean(), rel=tol)
        assert res_across.k_eff == pytest.approx(1 / np.mean(1 / g3), rel=tol)
        assert res_across.conservation_error < 1e3 * tol


def test_sinusoid_against_exact_integral():
    # g = g0 (1 + a cos(2 pi x/L)) across the flow: k = 1/<g^-3> = g0^3 2 (1-a^2)^(5/2)/(2+a^2).
    # The scheme gives the periodic trapezoidal rule of <g^-3>, whose error falls like
    # exp(-n acosh(1/a)) (about 1e-36 at n = 64, a = 0.5): rounding only.
    g0, a, n = 0.8, 0.5, 64
    x, _ = grid(n, 5)
    gap = g0 * (1 + a * np.cos(2 * np.pi * x))
    exact = g0**3 * 2 * (1 - a**2) ** 2.5 / (2 + a**2)
    assert lc.reynolds_leakage(gap).k_eff == pytest.approx(exact, rel=DIRECT)
    assert lc.reynolds_leakage(gap, method="amg", tol=1e-12).k_eff == pytest.approx(exact, rel=ITERATIVE)
    # along the flow: <g^3> = g0^3 (1 + 3 a^2/2), exact for a trigonometric polynomial
    assert lc.reynolds_leakage(gap, direction="y").k_eff == pytest.approx(
        g0**3 * (1 + 1.5 * a**2), rel=DIRECT
    )


def test_grid_convergence_second_order():
    # A smooth 2D gap: both face rules converge like h^2; the harmonic rule (a lower bound
    # face by face, by the power-mean inequality) stays below the arithmetic one.
    ns = (16, 32, 64, 128)
    k = {
        face: np.array([lc.reynolds_leakage(smooth_gap(n), face=face).k_eff for n in ns])
        for face in ("harmonic", "arithmetic")
    }
    for face, values in k.items():
        steps = np.diff(values)
        orders = np.log2(np.abs(steps[:-1] / steps[1:]))
        # measured 1.93 and 1.98 (harmonic), 1.87 and 1.97 (arithmetic): h^2 with an h^4 term
        assert np.all(np.abs(orders - 2) < 0.15), (face, orders)
    assert np.all(k["harmonic"] < k["arithmetic"])
    # Richardson-extrapolated values agree to the h^4 remainder
    extrapolated = {face: v[-1] + (v[-1] - v[-2]) / 3 for face, v in k.items()}
    assert extrapolated["harmonic"] == pytest.approx(extrapolated["arithmetic"], rel=1e-5)


def test_contact_line_blocks_flow_across_not_along():
    g = np.full((12, 20), 0.5)
    g[:, 7] = 0.0  # a closed contact stripe at x = 7/20 across the whole cell
    across = lc.reynolds_leakage(g, direction="x")
    assert across.k_eff == 0.0 and across.flux == 0.0 and not across.percolating
    assert np.all(np.isnan(across.pressure)) and across.solver == "none"
    assert lc.reynolds_leakage(g, direction="x", face="arithmetic").k_eff == 0.0
    along = lc.reynolds_leakage(g, direction="y")
    assert along.k_eff == pytest.approx(0.5**3 * 19 / 20, rel=DIRECT)
    # A zigzag line whose cells touch only at corners also blocks: fluid cells connect
    # through faces, not corners.
    zigzag = np.full((16, 16), 0.5)
    zigzag[np.arange(16), 7 + np.arange(16) % 2] = 0.0
    assert lc.reynolds_leakage(zigzag, direction="x").k_eff == 0.0
    assert lc.reynolds_leakage(zigzag, direction="y").k_eff > 0.0
    # A diagonal line winds along (1, 1): the fluid beside it flows along the line, with
    # equal mean fluxes along x and y whichever the gradient.
    diagonal = np.full((16, 16), 0.5)
    diagonal[np.arange(16), np.arange(16)] = 0.0
    res = lc.reynolds_leakage(diagonal, direction="x")
    assert res.k_eff > 0 and res.k_transverse == pytest.approx(res.k_eff, rel=DIRECT)


def test_isolated_pockets_do_not_change_the_flow():
    g = smooth_gap(32) * 0.1
    ring = np.zeros_like(g, dtype=bool)
    ring[10:19, 10:19] = True
    ring[11:18, 11:18] = False  # a closed contact ring around a 7x7 pocket of fluid
    pocket = g.copy()
    pocket[ring] = 0.0
    filled = pocket.copy()
    filled[11:18, 11:18] = 0.0
    with_pocket = lc.reynolds_leakage(pocket)
    without = lc.reynolds_leakage(filled)
    assert with_pocket.k_eff == pytest.approx(without.k_eff, rel=DIRECT)
    assert np.all(np.isnan(with_pocket.pressure[11:18, 11:18]))
    assert with_pocket.fluid_fraction - with_pocket.connected_fraction == pytest.approx(49 / 32**2)
    # a cluster that wraps across the flow but not along it carries nothing either
    g = np.full((10, 10), 0.3)
    g[:, 2] = g[:, 6] = 0.0
    res = lc.reynolds_leakage(g, direction="x")
    assert res.k_eff == 0.0 and res.connected_fraction == 0.0


def test_transpose_reciprocity_and_shifts():
    g = random_gap((48, 40), 0.25, seed=1)
    period = (2.0, 1.5)
    kx = lc.reynolds_leakage(g, period=period, direction="x")
    ky = lc.reynolds_leakage(g, period=period, direction="y")
    assert kx.percolating and ky.percolating
    # the transposed gap on the transposed cell swaps the directions
    kx_t = lc.reynolds_leakage(g.T, period=period[::-1], direction="x")
    assert kx_t.k_eff == pytest.approx(ky.k_eff, rel=DIRECT)
    # reciprocity: the conductance tensor is symmetric, k_xy = k_yx
    assert abs(kx.k_transverse) > 1e-3 * kx.k_eff
    assert kx.k_transverse == pytest.approx(ky.k_transverse, rel=1e-9)
    # a periodic shift changes nothing but the place of the fields
    shifted = lc.reynolds_leakage(np.roll(g, (7, 13), axis=(0, 1)), period=period, direction="x")
    assert shifted.k_eff == pytest.approx(kx.k_eff, rel=DIRECT)
    fluctuation = np.roll(kx.fluctuation, (7, 13), axis=(0, 1))
    difference = shifted.fluctuation - fluctuation
    assert np.nanmax(difference) - np.nanmin(difference) < DIRECT * np.nanmax(np.abs(fluctuation)) * 100


def test_amg_agrees_with_direct_near_percolation():
    g = random_gap((160, 160), 0.45, seed=2)
    direct = lc.reynolds_leakage(g, method="direct")
    iterative = lc.reynolds_leakage(g, method="amg", tol=1e-12)
    assert direct.percolating and iterative.solver == "amg" and iterative.converged
    assert iterative.k_eff == pytest.approx(direct.k_eff, rel=ITERATIVE)
    assert direct.conservation_error < 1e-6
    # the default tolerance (1e-6 on k_eff) and the energy-error stop
    default = lc.reynolds_leakage(g, method="amg")
    assert default.k_eff == pytest.approx(direct.k_eff, rel=1e-6)
    assert default.k_eff >= direct.k_eff * (1 - DIRECT)  # the dissipation is an upper bound
    stopped = lc.reynolds_leakage(g, method="amg", tol=1e-12, max_iter=2)
    assert not stopped.converged and stopped.iterations == 2 and stopped.k_eff > direct.k_eff


def dense_reference(gap, h):
    """Flow along x by an independent route: loops over the cells for the full singular
    Laplacian of all fluid cells (no cluster analysis), its minimum-norm least-squares
    solution, and the mean flux through one grid line."""
    ny, nx = gap.shape
    n = gap.size
    a = np.zeros((n, n))
    b = np.zeros(n)

    def conductance(g1, g2):
        return 0.0 if g1 <= 0 or g2 <= 0 else 2 * g1**3 * g2**3 / (g1**3 + g2**3)

    for i in range(ny):
        for j in range(nx):
            p = i * nx + j
            for di, dj, jump in ((0, 1, h), (1, 0, 0.0)):
                q = (i + di) % ny * nx + (j + dj) % nx
                c = conductance(gap[i, j], gap[(i + di) % ny, (j + dj) % nx]) / h**2
                a[p, p] += c
                a[q, q] += c
                a[p, q] -= c
                a[q, p] -= c
                b[p] -= c * jump
                b[q] += c * jump
    phi = np.linalg.lstsq(a, b, rcond=1e-13)[0].reshape(ny, nx)
    flux = [conductance(gap[i, 3], gap[i, 4]) * (phi[i, 3] - phi[i, 4] + h) / h for i in range(ny)]
    return float(np.sum(flux) / ny)


def test_matches_dense_reference():
    for seed, percolating in ((1, True), (2, False)):
        g = random_gap((14, 14), 0.4, seed=seed, smooth=1.5)
        g[2:5, 2:5] = 0.0
        g[3, 3] = 0.2  # a one-cell pocket
        res = lc.reynolds_leakage(g, period=1.0)
        assert res.percolating == percolating
        # seed 1 also has fluid clusters that do not percolate besides the pocket
        assert res.fluid_fraction - res.connected_fraction > (2 / 14**2 if percolating else 0.5)
        # least squares on a singular matrix: rounding amplified by its condition number
        assert res.k_eff == pytest.approx(dense_reference(g, 1 / 14), rel=1e-9, abs=1e-12)


def test_contact_from_a_solve():
    h = lc.self_affine_surface(n=64, hurst=0.8, seed=3, short_wavelength=1 / 16, rms_gradient=0.1)
    sol = lc.solve_areal(h, thickness=np.inf, poisson=0.5, mean_pressure=0.01, tol=1e-10)
    by_mask = lc.reynolds_leakage(sol.gap, contact=sol.pressure > 0)
    by_threshold = lc.reynolds_leakage(sol.gap)  # the residual gaps in contact are ~1e-8 max(gap)
    assert by_threshold.fluid_fraction == pytest.approx(1 - sol.contact_fraction)
    assert by_threshold.k_eff == pytest.approx(by_mask.k_eff, rel=DIRECT)
    # units: k scales like g^3 and is unchanged by a uniform change of the period
    assert lc.reynolds_leakage(2 * sol.gap, period=3.0).k_eff == pytest.approx(
        8 * by_threshold.k_eff, rel=DIRECT
    )


def test_bad_input_raises():
    g = np.ones((4, 4))
    with pytest.raises(ValueError, match="direction"):
        lc.reynolds_leakage(g, direction="z")
    with pytest.raises(ValueError, match=">= 0"):
        lc.reynolds_leakage(g - 2.0)
    with pytest.raises(ValueError, match="shape"):
        lc.reynolds_leakage(g, contact=np.zeros((3, 4), dtype=bool))
    with pytest.raises(ValueError, match="period"):
        lc.reynolds_leakage(g, period=(1.0, -1.0))
