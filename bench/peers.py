"""Time to solution of layercontact against the PyPI codes Tamaas and ContactMechanics on
identical frictionless problems, at equal accuracy.

    .venv/bin/pip install tamaas contactmechanics     # the peers (not project dependencies)
    .venv/bin/python bench/peers.py

Problems (all normal, frictionless, load control, plane strain):

- Westergaard: rigid sinusoid ``h0 cos(2 pi x/lambda)`` on an elastic half-space,
  ``p_m = 0.5 p*`` (``p* = pi E* h0/lambda``), n = 1024 and 8192. Tamaas uses its 1D
  model (``model_type.basic_1d``), ContactMechanics a 1D ``PeriodicFFTElasticHalfSpace``.
- Layer: self-affine profile on a layer of thickness h bonded to a rigid base, nu = 0.3.
  ContactMechanics' finite-thickness kernel is applied only on 2D grids (its 1D
  substrate silently ignores ``thickness``), so it runs on an n x 1 grid, which is the
  same plane-strain problem; its kernel equals ours to rounding (checked below), but it
  cannot take nu = 0.5 (division by zero in its k = 0 stiffness). Tamaas is run on the
  half-space problem only.

Every code discretises the same way (point collocation, spectral multiplier), so all
converge to one discrete solution: each peer at a very tight tolerance is cross-checked
against layercontact at tol 1e-13 (printed). Equal accuracy: layercontact runs at
tol 1e-8; each peer runs at the loosest tolerance of a half-decade ladder whose pressure
error against that discrete solution ("solve err": max |p - p_ref|/max p_ref) does not
exceed layercontact's. The errors against the independent truth (Westergaard's closed
form; for the layer, the cross-checked discrete solution) are printed next to the times.
Times include building each code's operator (what a user pays per problem), best of
several repeats in this run; everything runs on one thread. The machine is shared, so
compare the ratios ("vs lc", measured minutes apart in one run) rather than raw times.
"""

from __future__ import annotations

import importlib.metadata
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # before the peers load their libraries

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from analytic import westergaard_half_width, westergaard_pressure  # noqa: E402

import layercontact as lc  # noqa: E402
from layercontact.native import core as _core  # noqa: E402

INSTALL = ".venv/bin/pip install tamaas contactmechanics"
TARGET_TOL = 1e-8  # layercontact's tolerance in the table
REFERENCE_TOL = 1e-13  # layercontact's "discrete truth"
LADDER = [10.0 ** (-k / 2) for k in range(10, 25)]  # 1e-5, 3.2e-6, ..., 1e-12
CROSS_CHECK_TOL = 1e-12  # a peer's tightest solve, compared with layercontact's
REPEATS = 5  # at least this many timed solves, and at least MIN_SECONDS of them
MIN_SECONDS = 1.0
WESTERGAARD_AMPLITUDE = 0.01  # h0/lambda
PERIOD = 1.0
YOUNG = 1.0


def fft_pair_seconds(n: int) -> float:
    """One bare FFTW r2c + c2r pair of size n (same plans as the solver), best of 5."""
    seconds, stat, errmsg = _core.py_fft_pair_seconds(n, max(10, 2**22 // n), 5)
    if stat:
        raise RuntimeError(errmsg)
    return seconds


def best_of(solve):
    """Best wall time of ``solve()`` and its last solution. Millisecond solves are repeated
    for MIN_SECONDS because one interruption by another job would otherwise dominate."""
    best, spent, count = np.inf, 0.0, 0
    while count < REPEATS or (spent < MIN_SECONDS and count < 200):
        start = time.perf_counter()
        solution = solve()
        seconds = time.perf_counter() - start
        best, spent, count = min(best, seconds), spent + seconds, count + 1
    return best, solution


# --------------------------------------------------------------------------- problems


class Problem:
    """One discrete contact problem: profile, elastic data, load, and its truth."""

    def __init__(self, name, heights, thickness, poisson, mean_pressure):
        self.name, self.heights, self.thickness = name, heights, thickness
        self.poisson, self.mean_pressure = poisson, mean_pressure
        self.n = heights.size
        self.contact_modulus = YOUNG / (1 - poisson**2)
        # The common discrete solution that every code converges to (cross-checked).
        self.reference = layercontact_solve(self, REFERENCE_TOL)["pressure"]

    def truth(self):
        """Independent truth: pressure field and contact fraction."""
        return self.reference, np.mean(self.reference > 0)

    def truth_window(self):
        """Nodes on which the pressure error is measured (all)."""
        return np.ones(self.n, dtype=bool)


class Westergaard(Problem):
    """The Westergaard problem on n points, with its closed form as the truth."""

    def __init__(self, n):
        self.h0 = WESTERGAARD_AMPLITUDE * PERIOD
        pstar = np.pi * YOUNG * self.h0 / PERIOD  # poisson = 0: E* = E
        heights = lc.sinusoid_profile(n, self.h0, period=PERIOD)
        super().__init__("Westergaard", heights, np.inf, 0.0, 0.5 * pstar)

    def truth(self):
        x = np.arange(self.n) * PERIOD / self.n
        pressure = westergaard_pressure(x, self.mean_pressure, self.contact_modulus, self.h0, PERIOD)
        half_width = westergaard_half_width(self.mean_pressure, self.contact_modulus, self.h0, PERIOD)
        return pressure, 2 * half_width / PERIOD

    def truth_window(self):
        # The closed-form pressure has a square-root edge; the maximum error is taken over
        # |x| < 0.8 a, where it measures accuracy rather than the edge's resolution.
        x = np.arange(self.n) * PERIOD / self.n
        x = np.where(x > PERIOD / 2, x - PERIOD, x)
        a = westergaard_half_width(self.mean_pressure, self.contact_modulus, self.h0, PERIOD)
        return np.abs(x) < 0.8 * a


def layer_problem(n, thickness, normalised_pressure):
    """Self-affine profile (as in bench/fft_ratio.py) on a compressible layer."""
    heights = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
    poisson = 0.3
    contact_modulus = YOUNG / (1 - poisson**2)
    # the seed's scale: p_m/(E* Lambda0/lambda), Lambda0 = max r - mean r
    pm = normalised_pressure * contact_modulus * (heights.max() - heights.mean()) / PERIOD
    return Problem(f"layer h/lambda={thickness:g}", heights, thickness, poisson, pm)


# --------------------------------------------------------------------------- solvers


def layercontact_solve(problem, tol):
    res = lc.solve_line(problem.heights, period=PERIOD, thickness=problem.thickness, young=YOUNG,
                        poisson=problem.poisson, mean_pressure=problem.mean_pressure, tol=tol, stress=False)
    return dict(pressure=res.pressure, iterations=res.iterations, converged=res.converged)


# Tamaas reports no iteration count to Python; its C++ log (whose last line starts with the
# count) is buffered outside Python's reach until exit, so the count comes from a child process.
TAMAAS_COUNT = """
import sys, numpy as np, tamaas as tm
path, period, young, poisson, pressure, tol = sys.argv[1:]
heights = np.load(path)
model = tm.ModelFactory.createModel(tm.model_type.basic_1d, [float(period)], [heights.size])
model.E, model.nu = float(young), float(poisson)
solver = tm.PolonskyKeerRey(model, heights, float(tol))
solver.max_iter, solver.dump_freq = 10**6, 10**9
tm.set_log_level(tm.LogLevel.info)
solver.solve(float(pressure))
"""


def tamaas_iterations(problem, tol):
    """Iterations of the same Tamaas solve, read from its final log line."""
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "heights.npy")
        np.save(path, problem.heights)
        values = (PERIOD, YOUNG, problem.poisson, problem.mean_pressure, tol)
        child = subprocess.run([sys.executable, "-c", TAMAAS_COUNT, path, *map(repr, map(float, values))],
                               capture_output=True, text=True, check=True)
    log = child.stdout + child.stderr  # the log stream is not the same in every build
    counts = [int(words[0]) for words in map(str.split, log.splitlines()) if words and words[0].isdigit()]
    return counts[-1] if counts else None


def tamaas_solve(problem, tol):
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.warning)  # no log output inside the timed solves
    model = tm.ModelFactory.createModel(tm.model_type.basic_1d, [PERIOD], [problem.n])
    model.E, model.nu = YOUNG, problem.poisson
    solver = tm.PolonskyKeerRey(model, problem.heights, tol)
    solver.max_iter = 10**6  # the default (1000) stops tight solves early
    error = solver.solve(problem.mean_pressure)
    return dict(pressure=np.array(model.traction).ravel(), iterations=None, converged=error <= tol)


def contactmechanics_substrate(n, thickness, poisson):
    """ContactMechanics' substrate: 1D for the half-space, n x 1 for a layer because its 1D
    substrate ignores ``thickness``."""
    from ContactMechanics import PeriodicFFTElasticHalfSpace

    if np.isinf(thickness):
        # poisson left at 0 in 1D: 'young' is then the contact modulus E*
        return PeriodicFFTElasticHalfSpace((n,), YOUNG / (1 - poisson**2), physical_sizes=(PERIOD,))
    width = PERIOD / n  # one square pixel across: the y size does not enter q
    return PeriodicFFTElasticHalfSpace((n, 1), YOUNG, physical_sizes=(PERIOD, width), thickness=thickness,
                                       poisson=poisson)


def contactmechanics_solve(problem, tol):
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography, UniformLineScan

    substrate = contactmechanics_substrate(problem.n, problem.thickness, problem.poisson)
    if substrate.dim == 1:
        topography = UniformLineScan(problem.heights, PERIOD, periodic=True)
    else:
        topography = Topography(problem.heights[:, None], substrate.physical_sizes, periodic=True)
    force = problem.mean_pressure * np.prod(substrate.physical_sizes)  # total force on the cell
    # Its tolerances are absolute; scaled like layercontact's residual (gap by the peak-to-
    # valley height, force by p_m per pixel) so that 'tol' means roughly the same.
    res = constrained_conjugate_gradients(
        substrate, topography, external_force=force, pentol=tol * np.ptp(problem.heights),
        forcetol=tol * problem.mean_pressure * substrate.area_per_pt, thermotol=tol, maxiter=10**6)
    return dict(pressure=np.asarray(res.jac).ravel() / substrate.area_per_pt, iterations=res.nit,
                converged=bool(res.success))


def contactmechanics_kernel_check(thickness=0.16, poisson=0.3, n=1024):
    """ContactMechanics' n x 1 finite-thickness compliance against ours (convention P:
    ``w^ = 2 (1-A)/(E* |k|) p^``, and ``h/M`` for k = 0, M the constrained modulus)."""
    substrate = contactmechanics_substrate(n, thickness, poisson)
    theirs = np.asarray(substrate.greens_function).ravel()[: n // 2 + 1]
    k = 2 * np.pi * np.arange(1, n // 2 + 1) / PERIOD
    one_minus_a, _, _ = lc.layer_multipliers(k * thickness, poisson)
    ours = 2 * one_minus_a / (YOUNG / (1 - poisson**2) * k)
    constrained_modulus = YOUNG * (1 - poisson) / ((1 + poisson) * (1 - 2 * poisson))
    return (f"ContactMechanics n x 1 thickness kernel vs layercontact (h/lambda = {thickness}, "
            f"nu = {poisson}): max rel. difference {np.abs(theirs[1:] / ours - 1).max():.1e} (k > 0), "
            f"{abs(theirs[0] * constrained_modulus / thickness - 1):.1e} (k = 0)")


# --------------------------------------------------------------------------- measures


def solve_error(problem, pressure):
    """Distance to the common discrete solution (the solver's own error)."""
    return np.abs(pressure - problem.reference).max() / problem.reference.max()


def truth_errors(problem, pressure):
    """Contact fraction error in grid steps, pressure RMS (all nodes) and max (window)
    errors relative to the truth's peak pressure."""
    p_true, fraction_true = problem.truth()
    peak = p_true.max()
    difference = pressure - p_true
    return (abs(np.mean(pressure > 0) - fraction_true) * problem.n,
            np.sqrt(np.mean(difference**2)) / peak,
            np.abs(difference[problem.truth_window()]).max() / peak)


def calibrated_tolerance(problem, solve, target_error):
    """Loosest ladder tolerance whose solve error is at most ``target_error``."""
    for tol in LADDER:
        solution = solve(problem, tol)
        if solution["converged"] and solve_error(problem, solution["pressure"]) <= target_error:
            return tol
    return LADDER[-1]


def available_peers():
    peers = {}
    for label, module, solve in (("tamaas", "tamaas", tamaas_solve),
                                 ("ContactMechanics", "ContactMechanics", contactmechanics_solve)):
        try:
            __import__(module)
            if module == "ContactMechanics":
                __import__("SurfaceTopography")
        except ImportError:
            print(f"{label} is not installed: skipped ({INSTALL})")
            continue
        # the package's own __version__ can report the git state of the working directory
        peers[label] = (solve, importlib.metadata.version(label.lower()))
    return peers


def main() -> None:
    peers = available_peers()
    print("versions: " + ", ".join([f"layercontact {lc.__version__} ({lc.BUILD} build)"]
                                   + [f"{name} {version}" for name, (_, version) in peers.items()]))
    if "ContactMechanics" in peers:
        print(contactmechanics_kernel_check())
    problems = [Westergaard(1024), Westergaard(8192), layer_problem(1024, 0.16, 3.0),
                layer_problem(8192, 0.16, 3.0), layer_problem(8192, 0.01, 30.0)]
    header = (f"{'code':<17}{'problem':<20}{'n':>6}{'tol':>9}{'it.':>6}{'time ms':>9}{'vs lc':>7}"
              f"{'it./pair':>9}{'contact':>8}{'p rms':>9}{'p max':>9}{'solve err':>10}")
    rows, checks, pairs = [], [], {}
    for problem in problems:
        if problem.n not in pairs:
            pairs[problem.n] = fft_pair_seconds(problem.n)
        pair = pairs[problem.n]
        lc_time, lc_solution = best_of(lambda: layercontact_solve(problem, TARGET_TOL))
        lc_error = solve_error(problem, lc_solution["pressure"])
        entries = [("layercontact", TARGET_TOL, lc_time, lc_solution)]
        for name, (solve, _) in peers.items():
            if name == "tamaas" and not np.isinf(problem.thickness):
                continue  # Tamaas has no finite-thickness model to compare
            tight = solve(problem, CROSS_CHECK_TOL)
            checks.append(f"{name} at tol {CROSS_CHECK_TOL:.0e} vs layercontact at tol {REFERENCE_TOL:.0e}, "
                          f"{problem.name}, n = {problem.n}: max |dp|/p_max = "
                          f"{solve_error(problem, tight['pressure']):.1e}")
            tols = [calibrated_tolerance(problem, solve, lc_error)]
            if name == "tamaas" and problem.n == 8192:
                tols.append(TARGET_TOL)  # layercontact's tolerance, for reference
            for tol in tols:
                seconds, solution = best_of(lambda: solve(problem, tol))
                if name == "tamaas":
                    solution["iterations"] = tamaas_iterations(problem, tol)
                entries.append((name, tol, seconds, solution))
        for name, tol, seconds, solution in entries:
            contact, rms, peak = truth_errors(problem, solution["pressure"])
            iterations = solution["iterations"]
            per_iteration = f"{seconds / iterations / pair:9.1f}" if iterations else f"{'-':>9}"
            flag = "" if solution["converged"] else " (not converged)"
            rows.append(f"{name:<17}{problem.name:<20}{problem.n:>6}{tol:>9.1e}{iterations or '-':>6}"
                        f"{seconds * 1e3:>9.2f}{seconds / lc_time:>7.1f}{per_iteration}{contact:>8.1f}"
                        f"{rms:>9.1e}{peak:>9.1e}{solve_error(problem, solution['pressure']):>10.1e}{flag}")
    print("FFTW r2c+c2r pair (ms): " + ", ".join(f"n = {n}: {s * 1e3:.4f}" for n, s in pairs.items()))
    print(f"times: best of >= {REPEATS} repeats (>= {MIN_SECONDS} s) in this run, building the operator "
          "included; 'vs lc': time / layercontact's; 'it./pair': time per iteration in FFT pairs")
    print("errors against the truth (Westergaard: closed form, 'p max' over |x| < 0.8a; layer: the "
          "discrete solution): 'contact' in grid steps, pressures relative to the peak;")
    print("'solve err': against the discrete solution (layercontact, tol 1e-13); peers' tol: loosest "
          "with solve err <= layercontact's at 1e-8")
    print(header)
    print("\n".join(rows))
    if checks:
        print("cross-checks of the discrete solution:")
        print("\n".join("  " + line for line in checks))


if __name__ == "__main__":
    main()
