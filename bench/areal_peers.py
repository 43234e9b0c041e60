"""Time to solution of layercontact's areal solver against Tamaas and ContactMechanics on
identical frictionless half-space problems, at equal accuracy; with ``--geometry line``,
the same for broadband lines against Tamaas.

    .venv/bin/pip install tamaas==2.9.* ContactMechanics==1.8.*   # the peers (not project dependencies)
    .venv/bin/python bench/areal_peers.py                          # 256^2: ~20 s
    .venv/bin/python bench/areal_peers.py --sizes 256 1024         # + 1024^2: ~8 min
    .venv/bin/python bench/areal_peers.py --sizes 2048 --peers tamaas --peer-tol tamaas=1e-8 \\
        --timeout 3600                                             # one Tamaas run at 2048^2 (~10-20 min)
    .venv/bin/python bench/areal_peers.py --geometry line          # lines, n = 65536: ~11 min
    .venv/bin/python bench/areal_peers.py --geometry line --sizes 1048576 --peer-tol tamaas=1e-10 \\
        --timeout 2400                                             # one Tamaas run at 2^20 (see below)

Problem: an isotropic self-affine surface, Hurst
exponent 0.8, spectrum from the period down to a shortest wavelength of 8 grid points, rms
gradient 0.1 (``layercontact.self_affine_surface``), n x n points of a
unit square period, periodic, pressed on an incompressible elastic half-space (E = 1,
nu = 0.5, E* = 4/3) at p_m/E* = 0.01 (~20 % contact), frictionless, load control. Tamaas
runs ``PolonskyKeerRey`` on a ``basic_2d`` model (its defaults otherwise, as bench/peers.py
does for lines), ContactMechanics its constrained conjugate gradients
(``constrained_conjugate_gradients``, Polonsky & Keer) on a ``PeriodicFFTElasticHalfSpace``
with E* as its modulus. All three discretise the same way (point collocation, the
multiplier 2/(E*|q|)), so they converge to one discrete solution; each peer's tight solve
(tol 1e-12) is cross-checked against layercontact's (printed, n <= 512 by default).

Equal accuracy. The reference is layercontact at tol 1e-12. layercontact runs at tol 1e-8
(``--tol``). The contact fraction (points with p > 0) and the mean gap are computed from
each code's pressure field by one post-processor (``areal_surfaces.halfspace_observables``,
numpy FFT) so that every code is judged the same way. A peer's tolerance is the loosest of
a half-decade ladder (1e-4, 3.2e-5, ..., 1e-13) at which BOTH its contact-fraction error
(in grid points) and its relative mean-gap error are no larger than layercontact's at tol
1e-8 ("acc. ok" = yes); the ladder is walked from ``--start-tol`` (looser while the
criterion holds, tighter until it does). The peers' tolerances are their own (Tamaas:
its error measure; ContactMechanics: absolute, scaled as in bench/peers.py: penetration
by the peak-to-valley height, force by p_m per pixel), so only the measured errors are
comparable. ``--peer-tol CODE=TOL`` skips the search (for 2048^2, where one peer solve
takes ~15 min) and reports whether that tolerance met the criterion.

Times are CPU (process) time of the solve alone, single thread (OMP_NUM_THREADS=1, and
layercontact ``threads=1``), building each code's operator included: layercontact in this
process (best of ``--repeats``), each peer solve in a fresh child process (which also
gives Tamaas' iteration count from its log and each code's peak RSS); a peer's time is
that of its run at the chosen tolerance (the best of ``--peer-repeats`` runs there). The
ratio "peer/lc" is the peer's CPU time over layercontact's, measured in this run.

Lines (``--geometry line``): the broadband profile of bench/scaling.py's "8 points" family,
``layercontact.self_affine_profile(n, 0.8, seed=1, short_wavelength=8/n, rms_gradient=0.1)``,
on the same incompressible half-space at p_m/E* = 0.0125 (~25 % contact), frictionless, load
control, periodic, unit period, n = 65536 by default. layercontact runs ``solve_line`` with
its default method ('auto': the multigrid solver for these lines), Tamaas ``PolonskyKeerRey``
on a ``basic_1d`` model; equal accuracy, reference, ladder and times exactly as above, with
the contact error counted in points of the line (the post-processor takes the line as a grid
of one row); "p err" (bench/peers.py's criterion) is printed but not used. The cross-check at tol 1e-12 runs up to 2^18 points (512^2 or a line of
262144) unless ``--cross-check``. A Tamaas solve takes about a minute at n = 65536 and much
longer at 2^20, so there ``--peer-tol tamaas=TOL`` with ``--timeout`` runs one tolerance; a
timed-out run is reported as such (its time is a lower bound). ContactMechanics is not run
on lines here (bench/peers.py runs it on lines of up to 8192 points).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # before the peers (and numpy) load their libraries
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import layercontact as lc  # noqa: E402
from areal_surfaces import generator_name, halfspace_observables, surface  # noqa: E402

HURST = 0.8
SHORT_POINTS = 8  # shortest wavelength in grid points
RMS_GRADIENT = 0.1
YOUNG, POISSON = 1.0, 0.5
CONTACT_MODULUS = YOUNG / (1 - POISSON**2)
PRESSURE = {"areal": 0.01, "line": 0.0125}  # p_m/E*: ~20-25 % contact
REFERENCE_TOL = 1e-12
CROSS_CHECK_TOL = 1e-12
LADDER = [10.0 ** (-k / 2) for k in range(8, 27)]  # 1e-4, 3.2e-5, ..., 1e-13
PEERS = ("tamaas", "ContactMechanics")
CROSS_CHECK_POINTS = 2**18  # the tight cross-check by default up to this many points
DEFAULT_SIZES = {"areal": [256], "line": [65536]}

# One peer solve in a fresh process: heights from a .npy file, result (JSON) and pressure
# (.npy) to files, because Tamaas' C++ log shares the child's output streams.
CHILD = r"""
import json, os, resource, sys, time
os.environ["OMP_NUM_THREADS"] = "1"
import numpy as np
code, path, tol, pm, young, poisson, out = sys.argv[1:]
tol, pm, young, poisson = float(tol), float(pm), float(young), float(poisson)
h = np.load(path)  # (n,) for a line, (ny, nx) for a surface
contact_modulus = young / (1 - poisson**2)
if code == "tamaas":
    import tamaas as tm
    if h.ndim == 1:
        model = tm.ModelFactory.createModel(tm.model_type.basic_1d, [1.0], [h.size])
    else:
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], list(h.shape))
    model.E, model.nu = young, poisson
    solver = tm.PolonskyKeerRey(model, h, tol)
    solver.max_iter, solver.dump_freq = 10**6, 10**9  # the log: first and last iteration only
    tm.set_log_level(tm.LogLevel.info)
    cpu, wall = time.process_time(), time.perf_counter()
    error = solver.solve(pm)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    pressure = np.array(model.traction).reshape(h.shape)
    iterations, converged = None, bool(error <= tol)
else:
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography
    ny, nx = h.shape
    cpu, wall = time.process_time(), time.perf_counter()
    substrate = PeriodicFFTElasticHalfSpace((ny, nx), contact_modulus, physical_sizes=(1.0, 1.0))
    topography = Topography(h, (1.0, 1.0), periodic=True)
    # absolute tolerances, scaled like layercontact's residual (as in bench/peers.py)
    res = constrained_conjugate_gradients(
        substrate, topography, external_force=pm, pentol=tol * np.ptp(h),
        forcetol=tol * pm * substrate.area_per_pt, thermotol=tol, maxiter=10**6)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    pressure = np.asarray(res.jac) / substrate.area_per_pt
    iterations, converged = int(res.nit), bool(res.success)
np.save(out + ".npy", pressure)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB
with open(out + ".json", "w") as f:
    json.dump(dict(cpu=cpu, wall=wall, iterations=iterations, converged=converged, peak_kib=peak), f)
"""


def line_profile(n: int) -> np.ndarray:
    """n heights on the unit period (bench/scaling.py's "8 points" family)."""
    return lc.self_affine_profile(n, HURST, seed=1, short_wavelength=SHORT_POINTS / n, rms_gradient=RMS_GRADIENT)


class Problem:
    """One n x n (or, for a line, n-point) problem, its reference solution and
    layercontact's accuracy at ``tol``."""

    def __init__(self, geometry: str, n: int, tol: float, repeats: int, directory: str):
        self.geometry, self.n = geometry, n
        if geometry == "line":
            self.heights = line_profile(n)
        else:
            self.heights = surface(n, short_wavelength=SHORT_POINTS / n, hurst=HURST, rms_gradient=RMS_GRADIENT)
        self.points = self.heights.size
        self.label = f"{n}" if geometry == "line" else f"{n}^2"
        self.mean_pressure = PRESSURE[geometry] * CONTACT_MODULUS
        self.path = os.path.join(directory, f"heights_{geometry}_{n}.npy")
        np.save(self.path, self.heights)
        reference = self.lc_solve(REFERENCE_TOL)
        if not reference.converged:
            raise RuntimeError(f"n = {n}: the reference did not converge")
        self.reference = reference.pressure
        self.fraction, self.mean_gap = self.observables(self.reference)
        best = None
        for _ in range(repeats):
            cpu, wall = time.process_time(), time.perf_counter()
            result = self.lc_solve(tol)
            cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
            if best is None or cpu < best[0]:
                best = (cpu, wall, result)
        self.lc_cpu, lc_wall, result = best
        self.lc_row = dict(code="layercontact", tol=tol, iterations=result.iterations, cpu=self.lc_cpu,
                           wall=lc_wall, converged=result.converged, peak_kib=None, fft_pairs=result.fft_pairs,
                           **self.errors(result.pressure))
        self.lc_row["ok"] = True
        self.target = (self.lc_row["fraction_points"], self.lc_row["gap_error"])

    def lc_solve(self, tol):
        solve = lc.solve_line if self.geometry == "line" else lc.solve_areal
        return solve(self.heights, stress=False, period=1.0, thickness=np.inf, young=YOUNG, poisson=POISSON,
                     friction=0.0, mean_pressure=self.mean_pressure, tol=tol, threads=1)

    def observables(self, pressure):
        """Contact fraction and mean gap (a line as a grid of one row)."""
        return halfspace_observables(np.atleast_2d(pressure), np.atleast_2d(self.heights), CONTACT_MODULUS)

    def errors(self, pressure):
        fraction, mean_gap = self.observables(pressure)
        return dict(fraction=fraction, fraction_points=round(abs(fraction - self.fraction) * self.points),
                    gap_error=abs(mean_gap / self.mean_gap - 1),
                    pressure_error=float(np.abs(pressure - self.reference).max() / self.reference.max()))

    def accurate(self, row) -> bool:
        return row["converged"] and row["fraction_points"] <= self.target[0] and row["gap_error"] <= self.target[1]


def run_peer(problem: Problem, code: str, tol: float, timeout: float | None, directory: str) -> dict:
    """One peer solve in a child process; its row (``timeout=True`` if killed)."""
    out = os.path.join(directory, f"{code}_{problem.geometry}_{problem.n}_{tol:.3e}")
    args = [sys.executable, "-c", CHILD, code, problem.path, repr(tol), repr(problem.mean_pressure),
            repr(YOUNG), repr(POISSON), out]
    try:
        child = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(code=code, tol=tol, timeout=True)
    if child.returncode:
        raise RuntimeError(f"{code} at n = {problem.label}, tol {tol:g} failed:\n{child.stderr[-2000:]}")
    with open(out + ".json") as f:
        row = dict(json.load(f), code=code, tol=tol, timeout=False)
    if code == "tamaas":
        # its log's last line starts with the iteration count
        counts = [int(words[0]) for words in map(str.split, (child.stdout + child.stderr).splitlines())
                  if words and words[0].isdigit()]
        row["iterations"] = counts[-1] if counts else None
    row.update(problem.errors(np.load(out + ".npy")))
    row["ok"] = problem.accurate(row)
    os.remove(out + ".npy")
    return row


def calibrate(problem: Problem, code: str, start: float, timeout, directory, log) -> dict:
    """The loosest ladder tolerance meeting the criterion, walking from ``start``."""
    i = int(np.argmin([abs(np.log(t / start)) for t in LADDER]))
    rows = {}

    def at(j):
        if j not in rows:
            rows[j] = run_peer(problem, code, LADDER[j], timeout, directory)
            r = rows[j]
            log(f"  {code} n = {problem.label} tol {LADDER[j]:.1e}: " + (
                "timed out" if r["timeout"] else
                f"{r['cpu']:.2f} s, contact {r['fraction_points']} pts, gap err {r['gap_error']:.1e} "
                f"-> {'ok' if r['ok'] else 'not accurate enough'}"))
        return rows[j]

    if at(i).get("ok"):
        while i > 0 and at(i - 1).get("ok"):
            i -= 1
        return rows[i]
    while i + 1 < len(LADDER) and not at(i).get("timeout"):
        i += 1
        if at(i).get("ok"):
            return rows[i]
    return rows[i]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--geometry", choices=["areal", "line"], default="areal")
    parser.add_argument("--sizes", type=int, nargs="+",
                        help="n of the n x n grids (default 256) or of the lines (default 65536)")
    parser.add_argument("--peers", nargs="*", default=None, choices=PEERS,
                        help="default: both for surfaces, tamaas for lines")
    parser.add_argument("--tol", type=float, default=1e-8, help="layercontact's tolerance (default 1e-8)")
    parser.add_argument("--start-tol", type=float, default=1e-8, help="where the peers' ladder walk starts")
    parser.add_argument("--peer-tol", nargs="*", default=[], metavar="CODE=TOL",
                        help="fixed tolerance for a peer (no search), e.g. tamaas=1e-8")
    parser.add_argument("--repeats", type=int, default=0,
                        help="layercontact repeats (default 5 up to 2^18 points, else 3)")
    parser.add_argument("--peer-repeats", type=int, default=0,
                        help="runs of a peer at its chosen tolerance (default 3 up to 2^18 points, else 1)")
    parser.add_argument("--timeout", type=float, default=None, help="seconds per peer solve (default none)")
    parser.add_argument("--cross-check", action="store_true", help="peer at tol 1e-12 against the reference at every n "
                        "(default: up to 2^18 points only)")
    args = parser.parse_args()
    line = args.geometry == "line"
    sizes = args.sizes or DEFAULT_SIZES[args.geometry]
    peers = args.peers if args.peers is not None else (["tamaas"] if line else list(PEERS))
    if line and "ContactMechanics" in peers:
        parser.error("lines: tamaas only (bench/peers.py runs ContactMechanics on lines)")
    fixed = {code: float(tol) for code, tol in (item.split("=") for item in args.peer_tol)}
    start = time.perf_counter()

    def log(text):
        print(f"[{time.perf_counter() - start:6.0f} s] {text}", flush=True)

    versions = [f"layercontact {lc.__version__} ({lc.BUILD} build)"]
    for code in peers:
        versions.append(f"{code} {importlib.metadata.version(code)}")
    print("versions: " + ", ".join(versions))
    generator = "layercontact.self_affine_profile" if line else generator_name()
    print(f"{args.geometry}: {generator}; H = {HURST}, shortest wavelength {SHORT_POINTS} points, "
          f"rms gradient {RMS_GRADIENT}; half-space E* = {CONTACT_MODULUS:.4g} (nu = {POISSON}); "
          f"p_m/E* = {PRESSURE[args.geometry]}")
    rows, checks = [], []
    with tempfile.TemporaryDirectory() as directory:
        for n in sizes:
            small = (n if line else n * n) <= CROSS_CHECK_POINTS
            repeats = args.repeats or (5 if small else 3)
            peer_repeats = args.peer_repeats or (3 if small else 1)
            problem = Problem(args.geometry, n, args.tol, repeats, directory)
            log(f"n = {problem.label}: layercontact {problem.lc_cpu:.3f} s CPU, contact fraction "
                f"{problem.fraction:.5f}, mean gap {problem.mean_gap:.6e}; its errors at tol {args.tol:g}: "
                f"{problem.target[0]} pts, {problem.target[1]:.1e}")
            rows.append((problem.label, problem.lc_row, problem.lc_cpu))
            for code in peers:
                if args.cross_check or small:
                    tight = run_peer(problem, code, CROSS_CHECK_TOL, args.timeout, directory)
                    if not tight["timeout"]:
                        checks.append(f"{code} at tol {CROSS_CHECK_TOL:.0e} vs layercontact at tol {REFERENCE_TOL:.0e}, "
                                      f"n = {problem.label}: max |dp|/p_max = {tight['pressure_error']:.1e}, contact "
                                      f"{tight['fraction_points']} pts, mean gap {tight['gap_error']:.1e}")
                if code in fixed:
                    row = run_peer(problem, code, fixed[code], args.timeout, directory)
                else:
                    row = calibrate(problem, code, args.start_tol, args.timeout, directory, log)
                for _ in range(peer_repeats - 1):
                    if row["timeout"]:
                        break
                    again = run_peer(problem, code, row["tol"], args.timeout, directory)
                    if not again["timeout"] and again["cpu"] < row["cpu"]:
                        row["cpu"], row["wall"] = again["cpu"], again["wall"]
                log(f"n = {problem.label}: {code} at tol {row['tol']:.1e}: " +
                    ("timed out" if row["timeout"] else f"{row['cpu']:.2f} s CPU, {'ok' if row['ok'] else 'NOT ok'}"))
                rows.append((problem.label, row, problem.lc_cpu))
    print()
    print("CPU: process time of the solve (s); peer/lc: CPU time ratio; pairs: layercontact's FFT pairs (in units of "
          "the finest grid's); contact: |contact fraction error| in grid points; gap err: relative mean-gap error; "
          f"p err: max |p - p_ref|/max p_ref; reference: layercontact at tol {REFERENCE_TOL:g}; acc. ok: both errors "
          f"<= layercontact's at tol {args.tol:g}; RSS: peak resident set of the peer's child process (MiB)\n")
    print("| code | n | tol | it. | pairs | CPU (s) | wall (s) | peer/lc | contact fraction | contact (pts) | gap err "
          "| p err | acc. ok | RSS (MiB) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for label, r, lc_cpu in rows:
        if r.get("timeout"):
            # the timeout is on wall time: the ratio's bound is the timeout over layercontact's CPU time
            print(f"| {r['code']} | {label} | {r['tol']:.1e} | | | | > {args.timeout:g} (timed out) "
                  f"| > {args.timeout / lc_cpu:.0f} (wall) | | | | | | |")
            continue
        flag = "" if r["converged"] else " (not converged)"
        ratio = "1" if r["code"] == "layercontact" else f"{r['cpu'] / lc_cpu:.1f}"
        rss = f"{r['peak_kib'] / 1024:.0f}" if r.get("peak_kib") else ""
        print(f"| {r['code']}{flag} | {label} | {r['tol']:.1e} | {r['iterations'] if r['iterations'] is not None else '-'} "
              f"| {r.get('fft_pairs', '')} | {r['cpu']:.3f} | {r['wall']:.3f} | {ratio} | {r['fraction']:.6f} "
              f"| {r['fraction_points']} | {r['gap_error']:.1e} | {r['pressure_error']:.1e} "
              f"| {'yes' if r['ok'] else 'NO'} | {rss} |")
    if checks:
        print("\ncross-checks of the discrete solution:")
        print("\n".join("  " + line for line in checks))
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
