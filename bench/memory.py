"""Peak memory of one line-contact solve per grid point, n = 2^12 .. 2^20, against the
number of double arrays the solver holds.

Every solve runs in a fresh subprocess: import layercontact, make the profile (the seed's
Fig. 2 profile: H = 0.8, shortest wavelength lambda/128, rms gradient 0.1), read the
resident set (VmRSS, the baseline), call ``layercontact.solve_line`` with its defaults (tol
1e-10, stress fields, coarse start, max_iter 100000, Anderson memory 12), read
``ru_maxrss`` (the peak). The baseline is the resident set rather than ``ru_maxrss`` after
the profile: making the profile has a transient peak of its own (32 MiB above the resident
set at n = 2^20, freed before the solve) which the solve's pages would otherwise hide; the
"profile transient" column shows it, and the solve's peak is above it in every row.
The increase over n is printed in bytes per grid point, next to the count of n-sized double
arrays alive at the peak (see ``expected`` below); "rest" is the increase minus those
arrays: mostly the two ``history(max_iter)`` arrays (2 x 100000 doubles = 1.6 MB whatever
n), FFTW's plans and heap slack. A least-squares fit ``increase = fixed + slope n``
(n >= 2^14) follows; for the coupled scenes the slope mixes grids whose Anderson history
holds different numbers of columns (the outer iteration count grows with n).

Scenes: frictionless half-space (symmetric: constrained CG), the coupled thin layer
h/lambda = 0.16, mu_c = 0.5 (Anderson outer iteration), and a viscoelastic layer
(StandardLinearSolid E0 = 1, E_inf = 10, tau = 1, V = 1, h/lambda = 0.16, mu_c = 0: complex
multiplier, Anderson with the full history in use; E_inf/E0 = 100 as in bench/fft_ratio.py
takes minutes at n = 2^20 and holds the same arrays).

    .venv/bin/python bench/memory.py [--quick] [--max-exponent 20]
    .venv/bin/python bench/memory.py --areal [--areal-sizes 1024 2048] [--big 4096]

``--quick``: n = 2^12, 2^14, 2^16 only.

``--areal``: the same measurement for ``layercontact.solve_areal`` on n x n grids
(default 1024^2 and 2048^2; about a minute): an isotropic self-affine surface
(``bench/areal_surfaces.py``: ``layercontact.self_affine_surface`` if the package has it,
else a numpy fallback; H = 0.8, shortest wavelength 8 points, rms gradient 0.1) on a
frictionless incompressible half-space (p_m/E* = 0.0125, constrained CG) and on the
coupled layer h/period = 0.16, nu = 0.5, mu_c = 0.5 (p_m/E* = 0.015, GCR), and the same
layer as a standard linear solid sliding at V = 0.1 (E0 = 1, E_inf = 10, tau = 1: the
multigrid method under 'auto' from 1024^2), solve_areal's
defaults (tol 1e-10, coarse start, memory 12, threads 1) without the stress fields. The
increase of the peak over the resident set after making the surface is printed in doubles
per grid point (targets: <= 20 frictionless, <= 30 coupled by GCR, <= 46 by the multigrid:
the memory check's allowance, src/base/memory.f90), and the slope between the two largest sizes (the
fixed part removed). ``--big 4096`` adds one frictionless half-space solve at 4096^2
(time and peak; skipped if the peak predicted from the largest measured size exceeds
~20 GiB or the memory available).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

SCENES = {
    "half-space, mu_c = 0": "dict(thickness=np.inf, friction=0.0, pressure=0.3)",
    "h/lambda = 0.16, mu_c = 0.5": "dict(thickness=0.16, friction=0.5, pressure=3.0)",
    "viscoelastic SLS, h/lambda = 0.16, V = 1": (
        "dict(thickness=0.16, friction=0.0, pressure=3.0, "
        "material=lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0), speed=1.0)"),
}

CHILD = """
import json, resource, sys, time
import numpy as np
import layercontact as lc

def status(key):
    with open('/proc/self/status') as f:
        for line in f:
            if line.startswith(key):
                return int(line.split()[1])

n = int(sys.argv[1])
s = eval(sys.argv[2])
h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 128, rms_gradient=0.1)
pm = s["pressure"] * (4 / 3) * (h.max() - h.mean())     # p_m/(E* Lambda0/lambda), E* = 4/3
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
current = status('VmRSS:')
t = time.perf_counter()
r = lc.solve_line(h, thickness=s["thickness"], friction=s["friction"], mean_pressure=pm,
                  material=s.get("material"), speed=s.get("speed", 0.0))
t = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps(dict(base=base, current=current, peak=peak, seconds=t, iterations=r.iterations,
                      outer=r.outer_iterations, converged=bool(r.converged))))
"""

#: n-sized double arrays alive in each phase of lc.solve_line (complex arrays of n/2 + 1
#: modes count as one); see the module docstring of each file named.
F2PY = 9        # driver/wrappers.f90 py_solve_scene: fields(n, 6) + spots(n/2+1, 5), zero-filled by f2py
SOLVE = 3       # src/contact/solve.f90: p, w, gap
OPERATOR = 5    # src/contact/operator.f90: metric 1/2, preconditioner 1/2, compliance (complex) 1,
#                 column 1; src/fft/plans.F90: real_buffer 1, spectrum (complex) 1
FULL = 1        # operator.f90: full (complex G_eff), coupled scenes only
CG = 4          # src/contact/solver_cg.f90: t, r, z, inside (a real 0/1 mask)
ANDERSON = 7    # src/contact/solver_anderson.f90: x, f, x_old, f_old, tx, b, nw
OBSERVE = 9     # src/result.f90 pressure, gap, displacement_z, displacement_x, shear, stress_xx;
#                 src/observables/surface.f90: ph, uh, sh (complex)
WRAP_END = 6    # lc_application_scene_text copying the result (6 fields) into `fields`
PYTHON = 7      # api._solve_scene: 6 field copies; solve_line: height copy
MEMORY = 12     # Anderson memory (default)


def expected(coupled: bool, outer: int) -> tuple[int, str]:
    """Doubles per grid point at the peak and the phase it is in. Anderson stores a
    history column per outer iteration after the first two (k = 2 .. K-1; the last one
    returns), at most MEMORY of them in dx and in df; the least-squares step copies the
    columns in use plus one right-hand side while the inner CG's 4 arrays are freed."""
    op = OPERATOR + (FULL if coupled else 0)
    columns = min(max(outer - 2, 0), MEMORY)
    solver = ANDERSON + 2 * columns + max(CG, columns + 1) if coupled else CG
    phases = {
        "solve": F2PY + SOLVE + op + solver,
        "observables": F2PY + SOLVE + op + OBSERVE,
        "wrapper copy-out": F2PY + WRAP_END,
        "Python copies": F2PY + PYTHON,
    }
    phase = max(phases, key=phases.get)
    return phases[phase], phase


AREAL_SCENES = {
    "areal half-space, mu_c = 0": "dict(thickness=np.inf, friction=0.0, pressure=0.0125)",
    "areal h/lambda = 0.16, mu_c = 0.5": "dict(thickness=0.16, friction=0.5, pressure=0.015)",
    "areal SLS h/lambda = 0.16, mu_c = 0.5, V = 0.1": "dict(thickness=0.16, friction=0.5, pressure=0.015, "
    "material=lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0), speed=0.1)",
}

AREAL_CHILD = """
import json, os, resource, sys, time
import numpy as np
sys.path.insert(0, sys.argv[3])
import layercontact as lc
from areal_surfaces import surface

def status(key):
    with open('/proc/self/status') as f:
        for line in f:
            if line.startswith(key):
                return int(line.split()[1])

n = int(sys.argv[1])
s = eval(sys.argv[2])
h = surface(n, short_wavelength=8 / n)
pm = s["pressure"] * 4 / 3                                  # p_m/E*, E* = 4/3
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
current = status('VmRSS:')
t = time.perf_counter()
r = lc.solve_areal(h, stress=False,
                   thickness=s["thickness"], poisson=0.5, friction=s["friction"], mean_pressure=pm,
                   material=s.get("material"), speed=s.get("speed", 0.0))
t = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps(dict(base=base, current=current, peak=peak, seconds=t, iterations=r.iterations,
                      outer=r.outer_iterations, converged=bool(r.converged), solver=r.solver,
                      library_seconds=r.wall_time, contact=r.contact_fraction)))
"""

TARGETS = {"areal half-space, mu_c = 0": 20, "areal h/lambda = 0.16, mu_c = 0.5": 30,
           "areal SLS h/lambda = 0.16, mu_c = 0.5, V = 0.1": 46}
GIB = 2**30


def measure_areal(n: int, scene: str) -> dict:
    bench = os.path.dirname(os.path.abspath(__file__))
    done = subprocess.run([sys.executable, "-c", AREAL_CHILD, str(n), scene, bench], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def available_bytes() -> int:
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    return 0


def areal_main(sizes: list[int], big: int | None) -> None:
    import layercontact as lc

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from areal_surfaces import generator_name

    start = time.perf_counter()
    print(f"layercontact {lc.__version__} ({lc.BUILD} build); surface: {generator_name()}")
    print("Peak RSS (ru_maxrss) of one solve_areal (defaults: tol 1e-10, coarse start, threads 1) minus the resident "
          "set after import and surface, fresh process each; doubles/point = increase / (8 n^2)\n")
    print("| scene | n | baseline RSS (MiB) | surface transient (MiB) | increase (MiB) | doubles/point | target "
          "| solver | it. | contact | solve (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|")
    slopes, last = [], None
    for name, scene in AREAL_SCENES.items():
        points, increases = [], []
        for n in sizes:
            m = measure_areal(n, scene)
            increase = (m["peak"] - m["current"]) * 1024
            points.append(n * n)
            increases.append(increase)
            flag = "" if m["converged"] else " (not converged)"
            print(f"| {name} | {n}^2 | {m['current'] / 1024:.1f} | {(m['base'] - m['current']) / 1024:+.1f} "
                  f"| {increase / 2**20:.1f} | {increase / (8 * n * n):.1f} | <= {TARGETS[name]} | {m['solver']} "
                  f"| {m['iterations']}{flag} | {m['contact']:.3f} | {m['seconds']:.2f} |", flush=True)
            if name == "areal half-space, mu_c = 0":
                last = (n, m)  # what --big extrapolates from
        if len(points) > 1:
            slope = (increases[-1] - increases[-2]) / (points[-1] - points[-2])  # bytes per point
            slopes.append((name, slope / 8, (increases[-1] - slope * points[-1]) / 2**20))
    if slopes:
        print(f"\nSlope between {sizes[-2]}^2 and {sizes[-1]}^2:\n")
        print("| scene | slope (doubles/point) | fixed (MiB) |")
        print("|---|---:|---:|")
        for name, slope, fixed in slopes:
            print(f"| {name} | {slope:.1f} | {fixed:.1f} |")
    if big:
        n_last, m_last = last
        per_point = (m_last["peak"] * 1024) / (n_last * n_last)  # whole peak, baseline included
        predicted = per_point * big * big
        limit = min(20 * GIB, available_bytes())
        if predicted > limit:
            print(f"\n{big}^2 frictionless half-space skipped: predicted peak {predicted / GIB:.1f} GiB > "
                  f"{limit / GIB:.1f} GiB")
        else:
            m = measure_areal(big, AREAL_SCENES["areal half-space, mu_c = 0"])
            increase = (m["peak"] - m["current"]) * 1024
            flag = "" if m["converged"] else " (NOT converged)"
            print(f"\n{big}^2 frictionless half-space{flag}: solve {m['seconds']:.1f} s (library {m['library_seconds']:.1f} s), "
                  f"{m['solver']} {m['iterations']} it., contact {m['contact']:.3f}; peak RSS {m['peak'] / 2**20:.2f} GiB "
                  f"(predicted {predicted / GIB:.2f}), increase {increase / GIB:.2f} GiB = "
                  f"{increase / (8 * big * big):.1f} doubles/point")
    print(f"\n({time.perf_counter() - start:.0f} s)")


def measure(n: int, scene: str) -> dict:
    done = subprocess.run([sys.executable, "-c", CHILD, str(n), scene], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n = 2^12, 2^14, 2^16 only")
    parser.add_argument("--max-exponent", type=int, default=20)
    parser.add_argument("--areal", action="store_true", help="areal solves (solve_areal) instead of lines")
    parser.add_argument("--areal-sizes", type=int, nargs="+", default=[1024, 2048])
    parser.add_argument("--big", type=int, default=None, help="with --areal: one frictionless solve at big^2")
    args = parser.parse_args()
    if args.areal:
        areal_main(args.areal_sizes, args.big)
        return
    exponents = [12, 14, 16] if args.quick else list(range(12, args.max_exponent + 1))
    start = time.perf_counter()
    fits = []
    print("Peak RSS (ru_maxrss) of one solve (lc.solve_line defaults, tol 1e-10) minus the resident set "
          "after import and profile, fresh process each; 'expected' counts the n-sized double arrays alive "
          "at the peak (8 bytes each; fixed-size arrays not included)\n")
    print("| scene | n | baseline RSS (MiB) | profile transient (MiB) | increase (MiB) | bytes/point "
          "| expected doubles/point (phase) | expected bytes/point | measured/expected | rest (MiB) "
          "| CG it. | outer it. | solve (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, scene in SCENES.items():
        ns, increases = [], []
        coupled = "friction=0.5" in scene or "material" in scene
        for e in exponents:
            n = 2**e
            m = measure(n, scene)
            if m["peak"] <= m["base"]:
                raise RuntimeError(f"n = {n}, {name}: the solve did not exceed the profile's peak")
            increase = (m["peak"] - m["current"]) * 1024
            doubles, phase = expected(coupled, m["outer"])
            ns.append(n)
            increases.append(increase)
            flag = "" if m["converged"] else " (not converged)"
            transient = (m["base"] - m["current"]) / 1024
            print(f"| {name} | 2^{e} | {m['current'] / 1024:.1f} | {transient:+.1f} | {increase / 2**20:.1f} "
                  f"| {increase / n:.0f} | {doubles} ({phase}) | {8 * doubles} "
                  f"| {increase / n / (8 * doubles):.2f} | {(increase - 8 * doubles * n) / 2**20:.2f} "
                  f"| {m['iterations']} | {m['outer']}{flag} | {m['seconds']:.2f} |", flush=True)
        large = [i for i, n in enumerate(ns) if n >= 2**14] or list(range(len(ns)))
        slope, fixed = np.polyfit(np.array(ns)[large], np.array(increases)[large], 1)
        fits.append((name, slope, fixed))
    print("\nLeast-squares fit increase = fixed + slope n (n >= 2^14):\n")
    print("| scene | slope (bytes/point) | slope (doubles/point) | fixed (MiB) |")
    print("|---|---:|---:|---:|")
    for name, slope, fixed in fits:
        print(f"| {name} | {slope:.0f} | {slope / 8:.1f} | {fixed / 2**20:.2f} |")
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
