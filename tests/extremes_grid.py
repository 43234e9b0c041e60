"""The parameter grid of the stability tests at the extremes, shared by
tests/test_extremes.py (assertions) and bench/extremes.py (iteration table of docs/performance.md).

Grid: three profiles (a self-affine rough line, one cosine bump = Westergaard's sinusoid,
a narrow Gaussian bump whose tip is Hertz-like) x h/lambda in {1e-4, 1e-3, 1e-2, 0.16, 1,
1e3, inf} x nu in {-0.9, 0, 0.3, 0.49, 0.5} x mu_c in {0, 0.5, 1, 1.5} x five loads, on
n = 8 (the smallest grid allowed), 9, 63 (odd) and 1024 points: 2100 runs per grid size.

Loads are set relative to the full-contact pressure p_full of the scene itself: the
pressure of full contact is p(x) = p_m + [G_eff^-1 (r - mean r)](x) (w = r + const), so
full contact holds exactly when p_m >= p_full = -min_x [G_eff^-1 (r - mean r)](x). The
factors p_m/p_full = 1e-6 ... 0.3 cannot give full contact and 2 must; 1e-6 touches only
the highest point(s), i.e. one node (contact fraction 1/n ~ 0.1 % at n = 1024).

The viscoelastic grid (viscoelastic_scenes): the rough line and the narrow bump x standard
linear solids with E_inf/E0 in {10, 100, 1000} x V tau/lambda in {1e-4, 1e-2, 1, 1e2} x
h/lambda in {1e-3, 0.16, inf} x nu in {0.3, 0.5} x mu_c in {0, 0.5, 1.5} x loads
p_m/p_full in {1e-3, 0.3, 2} (p_full with the complex G_eff), on n = 63 and 1024: 1296
runs per grid size.
"""

from __future__ import annotations

import itertools

import numpy as np

import layercontact as lc
from reference_operator import g_eff as reference_g_eff

THICKNESSES = (1e-4, 1e-3, 1e-2, 0.16, 1.0, 1e3, np.inf)
POISSON = (-0.9, 0.0, 0.3, 0.49, 0.5)
FRICTIONS = (0.0, 0.5, 1.0, 1.5)
LOAD_FACTORS = (1e-6, 1e-3, 0.03, 0.3, 2.0)  # p_m / p_full
SIZES = (8, 9, 63, 1024)
PROFILES = ("rough", "sinusoid", "bump")
TOL = 1e-9
# Measured: the converged runs need at most ~2000 CG iterations (n = 1024); 10000 leaves
# a factor 5 and bounds the cost of the runs that stall.
MAX_ITER = 10000

# The viscoelastic grid: standard linear solids (E0 = 1, tau = 1) from mildly to strongly
# glassy, at speeds V tau/lambda from nearly relaxed to nearly glassy at the roughness scales
# (k V tau = 1 at the fundamental for V = 1/(2 pi)), on thin, thick and semi-infinite layers;
# friction up to 1.5 makes Re G_eff < 0 on some modes (not monotone: the solution need not
# be unique, or exist).
VISCO_RATIOS = (10.0, 100.0, 1000.0)  # E_inf/E0
VISCO_SPEEDS = (1e-4, 1e-2, 1.0, 1e2)
VISCO_THICKNESSES = (1e-3, 0.16, np.inf)
VISCO_POISSON = (0.3, 0.5)
VISCO_FRICTIONS = (0.0, 0.5, 1.5)
VISCO_LOAD_FACTORS = (1e-3, 0.3, 2.0)
VISCO_PROFILES = ("rough", "bump")
VISCO_SIZES = (63, 1024)


def profiles(n: int) -> dict[str, np.ndarray]:
    """The three indenter profiles on n points of a unit period (lengths in periods)."""
    x = np.arange(n) / n
    return {
        # self-affine, H = 0.8, rms gradient 0.1, shortest wavelength 4 grid steps
        "rough": lc.self_affine_profile(n, 0.8, seed=5, short_wavelength=4 / n),
        # one cosine bump per period: Westergaard's problem on the half-space
        "sinusoid": 0.01 * np.cos(2 * np.pi * x),
        # narrow bump, width 0.02 lambda, tip radius 0.04 lambda: Hertz-like at light loads
        "bump": 0.01 * np.exp(-0.5 * ((x - 0.5) / 0.02) ** 2),
    }


def g_eff(n: int, thickness: float, nu: float, friction: float, material=None, speed: float = 0.0) -> np.ndarray:
    """G_eff(k) (E = 1, period 1; J*(k V) with a viscoelastic material) for the modes
    k = 1..n/2 of numpy's rfft (reference_operator.py). The uniform mode is left out: under
    load control it only shifts the penetration."""
    return reference_g_eff(n, 1.0, thickness, 1.0, nu, friction, material, speed)[1:]


def full_contact_pressure(r: np.ndarray, thickness: float, nu: float, friction: float, material=None,
                          speed: float = 0.0) -> float:
    """Smallest mean pressure at which the whole period is in contact."""
    rh = np.fft.rfft(r)
    ph = np.zeros_like(rh)
    ph[1:] = rh[1:] / g_eff(r.size, thickness, nu, friction, material, speed)
    return float(-np.fft.irfft(ph, n=r.size).min())


def independent_residual(res: lc.LineResult, thickness: float, nu: float, material=None, speed: float = 0.0) -> float:
    """The solver's stopping quantity max_j |min(p_j/p_m, g_j/(max r - min r))|,
    recomputed from the returned pressure with numpy FFTs and without the uniform mode
    (the penetration is the mean gap on the contact set, as in the solver). Gaps within the
    rounding floor 256 eps max(|w|, |r|, max p max|G|) count as zero, as in the solver
    (docs/numerics.md, stopping rule): below it a gap is rounding noise of w - r."""
    r, p = res.height, res.pressure
    g = g_eff(r.size, thickness, nu, res.friction, material, speed)
    ph = np.fft.rfft(p)
    ph[0] = 0.0
    ph[1:] *= g
    w = np.fft.irfft(ph, n=r.size)
    gap = w - r
    contact = p > 0
    gap -= gap[contact].mean()
    floor = 256 * np.finfo(float).eps * max(np.abs(w).max(), np.ptp(r), p.max() * np.abs(g).max())
    gap = np.where(np.abs(gap) > floor, gap, 0.0)
    return float(np.max(np.abs(np.minimum(p / res.mean_pressure, gap / np.ptp(r)))))


def coupled(scene: dict) -> bool:
    """Whether the solver takes the coupled (GCR) path: a moving viscoelastic layer, or
    friction on anything but an incompressible half-space, whose coupling c is zero
    (src/contact/operator.f90)."""
    if scene.get("material") is not None and scene.get("speed", 0.0) > 0:
        return True
    return scene["friction"] > 0 and not (np.isinf(scene["thickness"]) and scene["nu"] == 0.5)


def scenes(n: int):
    """Every scene of the grid on n points: dicts of the parameters and the profile."""
    for name, r in profiles(n).items():
        for thickness, nu, friction in itertools.product(THICKNESSES, POISSON, FRICTIONS):
            p_full = full_contact_pressure(r, thickness, nu, friction)
            for factor in LOAD_FACTORS:
                yield dict(n=n, profile=name, heights=r, thickness=thickness, nu=nu, friction=friction,
                           load_factor=factor, mean_pressure=factor * p_full)


def solve(scene: dict) -> lc.LineResult:
    return lc.solve_line(scene["heights"], thickness=scene["thickness"], poisson=scene["nu"],
                         friction=scene["friction"], mean_pressure=scene["mean_pressure"], tol=TOL,
                         max_iter=MAX_ITER, material=scene.get("material"), speed=scene.get("speed", 0.0))


def viscoelastic_scenes(n: int):
    """Every scene of the viscoelastic grid on n points (standard linear solids, tau = 1)."""
    for name in VISCO_PROFILES:
        r = profiles(n)[name]
        for ratio, speed, thickness, nu, friction in itertools.product(VISCO_RATIOS, VISCO_SPEEDS, VISCO_THICKNESSES,
                                                                        VISCO_POISSON, VISCO_FRICTIONS):
            material = lc.StandardLinearSolid(e0=1.0, e_inf=ratio, tau=1.0)
            g = g_eff(n, thickness, nu, friction, material, speed)
            p_full = full_contact_pressure(r, thickness, nu, friction, material, speed)
            for factor in VISCO_LOAD_FACTORS:
                yield dict(n=n, profile=name, heights=r, thickness=thickness, nu=nu, friction=friction,
                           ratio=ratio, speed=speed, material=material, monotone=bool(np.all(g.real >= 0)),
                           load_factor=factor, mean_pressure=factor * p_full)


def band(contact_fraction: float) -> str:
    """Contact-fraction band of a run (labels of the bench table)."""
    if contact_fraction <= 0.005:
        return "<= 0.5 %"
    if contact_fraction <= 0.05:
        return "0.5-5 %"
    if contact_fraction <= 0.5:
        return "5-50 %"
    if contact_fraction < 1:
        return "50-100 %"
    return "full"


BANDS = ("<= 0.5 %", "0.5-5 %", "5-50 %", "50-100 %", "full")


def diagnose(scene: dict, res: lc.LineResult) -> str:
    """Why a run stopped without converging, from what the result reports."""
    p, gap = res.pressure, res.gap
    scale = np.ptp(res.height)
    contact = int(np.count_nonzero(p > 0))
    overlap = int(np.count_nonzero((p == 0) & (gap < -1e-12 * scale)))
    if res.iterations >= MAX_ITER:
        if contact == 1 and overlap > 0:
            return (f"CG budget spent with 1 contact node and {overlap} overlapping node(s) after "
                    f"{res.outer_iterations} outer it.: inner CG makes no step")
        return f"CG budget spent ({res.outer_iterations} outer it.)"
    if coupled(scene):
        hist = res.residual_history
        return (f"{res.solver} stopped on stagnation after {res.iterations} it., {res.outer_iterations} outer "
                f"(best residual {hist.min():.1e} at entry {int(hist.argmin()) + 1} of its history)")
    return "stopped early"
