"""The multigrid solver (&solver method = 'multigrid', src/contact/solver_multigrid.f90)
against the constrained CG, Westergaard's closed form and its own contact conditions, and
its refusal of the scenes it does not solve."""

import numpy as np
import pytest

import layercontact as lc
from conftest import contact_violation, g_eff

E_STAR = 4 / 3  # E = 1, nu = 0.5
TOL = 1e-10
TOL_CG = 1e-12
# (GCR stops at ~1e-12 on the broadband viscoelastic line of 65536 points: rounding)
TOL_GCR = 1e-11


def profile(n: int, family: str) -> np.ndarray:
    """The two families of bench/scaling.py: spectrum fixed in physical wavenumbers, or
    shortest wavelength 8 grid points (broadband: more scales and spots on finer grids)."""
    short = 1 / 64 if family == "physical" else 8 / n
    return lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=short, rms_gradient=0.1)


def max_stiffness(n: int, thickness: float, poisson: float) -> float:
    """The largest stiffness 1/|G_eff(k)| on the grid (k > 0): a gap residual tol * ptp(h)
    on the contact set allows pressure differences up to this times tol * ptp(h)."""
    g = g_eff(n, 1.0, thickness, 1.0, poisson, 0.0)
    return np.max(1 / np.abs(g[1:]))


@pytest.mark.parametrize("n", [4096, 65536])
@pytest.mark.parametrize("family", ["physical", "broadband"])
def test_agrees_with_constrained_cg(n, family):
    """Two methods to the same fixed point: the pressure to the bound the two tolerances
    allow (their sum, times ptp(h), times the largest stiffness |k_max| E*/2), the same
    contact set and penetration; and far fewer transforms than the CG on broadband lines."""
    h = profile(n, family)
    kw = dict(thickness=np.inf, poisson=0.5, mean_pressure=0.0125 * E_STAR, stress=False)
    cg = lc.solve_line(h, method="cg", tol=TOL_CG, **kw)
    mg = lc.solve_line(h, method="multigrid", tol=TOL, **kw)
    assert cg.converged and mg.converged and mg.solver == "multigrid"
    assert mg.residual <= TOL and len(mg.residual_history) == mg.iterations
    bound = (TOL + TOL_CG) * np.ptp(h) * max_stiffness(n, np.inf, 0.5)
    assert np.abs(mg.pressure - cg.pressure).max() <= bound
    assert np.array_equal(mg.pressure > 0, cg.pressure > 0)
    assert mg.penetration == pytest.approx(cg.penetration, abs=(TOL + TOL_CG) * np.ptp(h))
    # measured: 2-5 fine-grid iterations and 46-74 pairs from n = 1024 to 262144
    assert mg.iterations <= 8 and mg.fft_pairs <= 120


@pytest.mark.parametrize("control", ["load", "displacement"])
def test_thin_compressible_layer_agrees_with_cg(rough_profile, control):
    """A thin compressible layer (h/lambda = 0.01, nu = 0.3: the stiffness is flat, ~M/h, up
    to |k| h ~ 1, dipping by 2 %, and rises beyond, so Jacobi still smooths) under load and
    displacement control: the CG's pressure to the bound of the tolerances with the layer's largest
    stiffness, and the same load."""
    h = rough_profile
    thickness, poisson = 0.01, 0.3
    loads = {"load": dict(mean_pressure=16 * h.max()), "displacement": dict(penetration=0.5 * np.ptp(h))}
    control_kw = loads[control]
    kw = dict(thickness=thickness, poisson=poisson, stress=False, **control_kw)
    cg = lc.solve_line(h, method="cg", tol=TOL_CG, **kw)
    mg = lc.solve_line(h, method="multigrid", tol=TOL, **kw)
    assert cg.converged and mg.converged
    assert 0.05 < mg.contact_fraction < 0.95
    bound = (TOL + TOL_CG) * np.ptp(h) * max_stiffness(h.size, thickness, poisson)
    assert np.abs(mg.pressure - cg.pressure).max() <= bound
    assert mg.mean_pressure == pytest.approx(cg.mean_pressure, rel=1e-8)
    assert mg.penetration == pytest.approx(cg.penetration, abs=(TOL + TOL_CG) * np.ptp(h))


@pytest.mark.parametrize(
    "kw, reason",
    [
        (dict(thickness=0.01, poisson=0.5),
         "the compliance rises with \\|q\\| over the grid by a factor 123.0 "
         "\\(a thin, nearly incompressible layer; pointwise smoothing needs at most 4.0\\)"),
        (dict(thickness=0.01, poisson=0.5, friction=1.5),
         "the compliance rises with \\|q\\| over the grid by a factor [0-9.]+ "
         "\\(a thin, nearly incompressible layer; pointwise smoothing needs at most 4.0\\)"),
    ],
)
def test_refuses_scenes_it_does_not_solve(rough_profile, kw, reason):
    """Thin incompressible scenes, with or without friction, are bad input (code 2) for the
    method, with a message that names it, says why and what is allowed."""
    message = "&solver: method = 'multigrid' cannot solve this scene: " + reason
    with pytest.raises(lc.InputError, match=message) as err:
        lc.solve_line(rough_profile, method="multigrid", mean_pressure=0.01, stress=False, **kw)
    assert err.value.code == 2
    assert "allowed here: 'auto'" in str(err.value)


SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)


@pytest.mark.parametrize("n", [4096, 65536])
@pytest.mark.parametrize("family", ["physical", "broadband"])
@pytest.mark.parametrize("scene", [dict(friction=0.5), dict(friction=0.5, material=SLS, speed=0.1)],
                         ids=["friction", "viscoelastic"])
def test_coupled_lines_agree_with_gcr(n, family, scene):
    """Coupled lines (friction; a sliding standard linear solid) by the Anderson iteration
    with multigrid inner solves: GCR's fixed point (pressure to the bound of the two
    tolerances with the largest stiffness |1/G_eff|, the load, the penetration); the
    transform pairs bounded on broadband lines, where GCR's grow with n."""
    h = profile(n, family)
    kw = dict(thickness=0.16, poisson=0.5, mean_pressure=0.015 * E_STAR, stress=False, **scene)
    gcr = lc.solve_line(h, method="gcr", tol=TOL_GCR, **kw)
    mg = lc.solve_line(h, method="multigrid", tol=TOL, **kw)
    assert gcr.converged and mg.converged and mg.solver.startswith("anderson+multigrid")
    assert mg.residual <= TOL
    g = g_eff(n, 1.0, 0.16, 1.0, 0.5, 0.5, scene.get("material"), scene.get("speed", 0.0))
    bound = (TOL + TOL_GCR) * np.ptp(h) * np.max(1 / np.abs(g[1:]))
    assert np.abs(mg.pressure - gcr.pressure).max() <= bound
    assert mg.mean_pressure == pytest.approx(gcr.mean_pressure, rel=1e-10)
    assert mg.penetration == pytest.approx(gcr.penetration, abs=(TOL + TOL_GCR) * np.ptp(h))
    # measured at tol 1e-8 from n = 1024 to 2^20: 131-265 pairs (friction) and 641-803
    # (viscoelastic) on broadband lines; tol 1e-10 here
    assert mg.fft_pairs <= 1500


def test_refuses_surfaces_and_sizes_without_a_small_coarsest_grid():
    s = lc.self_affine_surface(n=64, hurst=0.8, seed=1, short_wavelength=1 / 16, rms_gradient=0.1)
    with pytest.raises(lc.InputError, match="it solves lines, and this scene is a surface"):
        lc.solve_areal(s, method="multigrid", mean_pressure=0.01)
    h = profile(4095, "physical")
    with pytest.raises(lc.InputError, match="n = 4095 halves to an odd grid of 4095 points"):
        lc.solve_line(h, method="multigrid", mean_pressure=0.01, stress=False)


@pytest.mark.parametrize("n", [100, 1000, 4096])
def test_load_is_exact_and_contact_conditions_hold(n):
    """p >= 0, the load to rounding, and the contact conditions recomputed with numpy's FFT
    to the tolerance, on sizes with and without coarse grids (100: one dense grid; 1000:
    coarsest 125 points)."""
    h = profile(n, "broadband")
    pm = 0.0125 * E_STAR
    res = lc.solve_line(h, method="multigrid", mean_pressure=pm, tol=TOL)
    assert res.converged
    assert np.all(res.pressure >= 0)
    assert res.mean_pressure == pytest.approx(pm, rel=1e-13)
    assert res.gap.min() >= -res.gap_resolution * np.ptp(h)
    v = contact_violation(res, np.inf, 1.0, 0.5)
    assert v["overlap"] <= 2 * TOL and v["gap_in_contact"] <= 2 * TOL
    assert v["w_error"] <= 1e-12
