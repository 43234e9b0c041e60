"""Iterations, FFT pairs and time of a solve against the grid size, lines and surfaces,
for the two families of rough surfaces that a solver must handle.

    .venv/bin/python bench/scaling.py --geometry line                 # n = 1024 .. 65536 (~1 min)
    .venv/bin/python bench/scaling.py --geometry line --sizes 1024 16384 262144 1048576
    .venv/bin/python bench/scaling.py --geometry areal                # 256^2 .. 1024^2 (~2 min)
    .venv/bin/python bench/scaling.py --geometry areal --sizes 256 512 1024 2048 --points 8
    .venv/bin/python bench/scaling.py --geometry line --scenes 1 --method multigrid  # frictionless only
    .venv/bin/python bench/scaling.py --geometry areal --scenes 1 --method multigrid --against cg --repeats 3

Surfaces: self-affine, Hurst exponent 0.8, rms gradient 0.1, seed 1, on a unit period
(``layercontact.self_affine_profile`` / ``self_affine_surface``: the phases depend on the
mode, not on the grid).

- family (a), "physical": the spectrum is fixed in physical wavenumbers (shortest
  wavelength period/64 for lines, period/32 for surfaces): the same surface at every n,
  refining the grid only adds resolution;
- family (b), "k points": the shortest wavelength is k grid points (--points, default 4, 8
  and 16), so finer grids carry more roughness scales: the broadband surfaces of real
  topographies, and the harder problem for a solver.

Scenes (nu = 0.5, E = 1; the load is fixed across n, ~20-25 % contact): a frictionless
half-space (constrained CG), a layer h/period = 0.16 with mu_c = 0.5 and a thin layer
h/period = 0.01 with mu_c = 1.5 (coupled: constrained GCR), and the first layer as a
standard linear solid (E0 = 1, E_inf = 10, tau = 1) sliding at V = 0.1 (GCR). The library's
defaults otherwise (method 'auto', Fourier preconditioner, coarse start), tol 1e-8 (the
dimensionless complementarity residual), one thread. "it.": CG or GCR iterations on the
finest grid (plus the inner CG iterations after an Anderson fallback, marked +a);
"pairs": FFT pairs in units of the finest grid's (coarse levels included); "ms": the
library's solve time (``wall_time``). The last table gives max/min of the iterations and
of the pairs over n per family and scene. ``--method`` sets ``&solver method`` (for
'multigrid', every scene on lines, scenes 1, 2 and 4 on surfaces: it refuses the thin
incompressible layer of scene 3 there). ``--against M`` solves every row with method M as well,
the two solves alternating (best of ``--repeats`` each), and prints M's iterations, pairs
and time and the time ratio M/method measured in this run: the comparison behind the
choice of method 'auto'.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc

CONTACT_MODULUS = 4 / 3  # E = 1, nu = 0.5
SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)
SCENES = {
    "half-space, mu_c = 0": dict(thickness=np.inf, friction=0.0, pressure=0.0125),
    "h/lambda = 0.16, mu_c = 0.5": dict(thickness=0.16, friction=0.5, pressure=0.015),
    "h/lambda = 0.01, mu_c = 1.5": dict(thickness=0.01, friction=1.5, pressure=0.0015),
    "SLS h/lambda = 0.16, mu_c = 0.5, V = 0.1": dict(thickness=0.16, friction=0.5, pressure=0.015, material=SLS,
                                                    speed=0.1),
}
PHYSICAL_SHORTEST = {"line": 1 / 64, "areal": 1 / 32}
DEFAULT_SIZES = {"line": [1024, 4096, 16384, 65536], "areal": [256, 512, 1024]}


def heights(geometry: str, n: int, short_wavelength: float) -> np.ndarray:
    if geometry == "line":
        return lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=short_wavelength, rms_gradient=0.1)
    return lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=short_wavelength, rms_gradient=0.1)


def solve(geometry: str, h: np.ndarray, scene: dict, tol: float, method: str = "auto"):
    solver = lc.solve_line if geometry == "line" else lc.solve_areal
    return solver(h, thickness=scene["thickness"], poisson=0.5, friction=scene["friction"],
                  mean_pressure=scene["pressure"] * CONTACT_MODULUS, tol=tol, threads=1, method=method,
                  material=scene.get("material"), speed=scene.get("speed", 0.0), stress=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--geometry", choices=["line", "areal"], default="line")
    parser.add_argument("--sizes", type=int, nargs="+", help="n (lines) or n of n x n (surfaces)")
    parser.add_argument("--points", type=int, nargs="+", default=[4, 8, 16],
                        help="grid points per shortest wavelength of family (b)")
    parser.add_argument("--scenes", type=int, nargs="+", help="scene numbers (1-4; default all)")
    parser.add_argument("--no-physical", action="store_true", help="family (b) only")
    parser.add_argument("--tol", type=float, default=1e-8)
    parser.add_argument("--method", default="auto", help="&solver method (default 'auto')")
    parser.add_argument("--against", help="a second method, timed against --method row by row")
    parser.add_argument("--repeats", type=int, default=1, help="solves per method and row, best time kept")
    args = parser.parse_args()
    sizes = args.sizes or DEFAULT_SIZES[args.geometry]
    scenes = list(SCENES.items())
    if args.scenes:
        scenes = [scenes[i - 1] for i in args.scenes]
    families = {} if args.no_physical else {"(a) physical": lambda n: PHYSICAL_SHORTEST[args.geometry]}
    for k in args.points:
        families[f"(b) {k} points"] = lambda n, k=k: k / n
    start = time.perf_counter()
    print(f"layercontact {lc.__version__} ({lc.BUILD} build); {args.geometry}; tol {args.tol:g}; "
          f"method {args.method}; one thread\n")
    against = f" {args.against}: it. | pairs | ms | time {args.against}/{args.method} |" if args.against else ""
    print("| family | scene | n | contact fraction | solver | it. | pairs | ms |" + against)
    print("|---|---|---:|---:|---|---:|---:|---:|" + ("---:|---:|---:|---:|" if args.against else ""))
    spread = []
    for family, shortest in families.items():
        for name, scene in scenes:
            iterations, pairs = [], []
            for n in sizes:
                h = heights(args.geometry, n, shortest(n))
                best = {}
                for _ in range(max(args.repeats, 1)):
                    for method in filter(None, (args.method, args.against)):
                        run = solve(args.geometry, h, scene, args.tol, method)
                        if method not in best or run.wall_time < best[method].wall_time:
                            best[method] = run
                r = best[args.method]
                flag = "" if r.converged else " NOT CONVERGED"
                fallback = " +a" if "anderson" in r.solver else ""
                iterations.append(r.iterations)
                pairs.append(r.fft_pairs)
                size = f"{n}^2" if args.geometry == "areal" else f"{n}"
                other = ""
                if args.against:
                    a = best[args.against]
                    other = (f" {a.iterations}{'' if a.converged else ' NOT CONVERGED'} | {a.fft_pairs} "
                             f"| {a.wall_time * 1e3:.0f} | {a.wall_time / r.wall_time:.2f} |")
                print(f"| {family} | {name} | {size} | {r.contact_fraction:.3f} | {r.solver} "
                      f"| {r.iterations}{fallback}{flag} | {r.fft_pairs} | {r.wall_time * 1e3:.0f} |" + other,
                      flush=True)
            spread.append((family, name, iterations, pairs))
    print("\n| family | scene | iterations | max/min | pairs | max/min |")
    print("|---|---|---|---:|---|---:|")
    for family, name, iterations, pairs in spread:
        print(f"| {family} | {name} | {', '.join(map(str, iterations))} | {max(iterations) / min(iterations):.2f} "
              f"| {', '.join(map(str, pairs))} | {max(pairs) / min(pairs):.2f} |")
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
