"""Cost of a solve in units of one FFTW r2c + c2r pair of the same size, and the cost of
friction and viscoelasticity relative to the frictionless elastic solve of the same layer.

    .venv/bin/python bench/fft_ratio.py [--sizes 1024 8192 65536] [--no-marginal]

A second table gives the time of one iteration without the setup and the coarse levels:
the difference of two runs on one grid level stopped short of convergence.

All ratios are measured in this run on this machine: times are the best of 5 repetitions
of the library's own solve time (`wall_time`: operator, coarse levels and iterations; no
Python, no observables), the FFT pair is timed by the library on its own plans.
"""

from __future__ import annotations

import argparse

import numpy as np

import layercontact as lc
from layercontact.native import core as _core

SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)
# name: (settings, the scene it is compared with)
SCENES = {
    "half-space, mu_c = 0, plain CG": (dict(thickness=np.inf, pressure=0.3, precondition=False, coarse_start=False,
                                            method="cg"), None),
    "half-space, mu_c = 0": (dict(thickness=np.inf, pressure=0.3, method="cg"), None),
    "half-space, mu_c = 0, multigrid": (dict(thickness=np.inf, pressure=0.3), "half-space, mu_c = 0"),
    "h/lambda = 0.16, mu_c = 0": (dict(thickness=0.16, pressure=3.0, method="cg"), None),
    "h/lambda = 0.16, mu_c = 0, multigrid": (dict(thickness=0.16, pressure=3.0), "h/lambda = 0.16, mu_c = 0"),
    "h/lambda = 0.16, mu_c = 0.5": (dict(thickness=0.16, friction=0.5, pressure=3.0), "h/lambda = 0.16, mu_c = 0"),
    "h/lambda = 0.01, mu_c = 0": (dict(thickness=0.01, pressure=30.0), None),
    "h/lambda = 0.01, mu_c = 0.5": (dict(thickness=0.01, friction=0.5, pressure=30.0), "h/lambda = 0.01, mu_c = 0"),
    "h/lambda = 0.01, mu_c = 0.5, anderson": (dict(thickness=0.01, friction=0.5, pressure=30.0, method="anderson"),
                                              "h/lambda = 0.01, mu_c = 0"),
    "h/lambda = 0.16, elastic E0": (dict(thickness=0.16, pressure=1.0, method="cg"), None),
    "h/lambda = 0.16, SLS, V = 0.1": (dict(thickness=0.16, pressure=1.0, material=SLS, speed=0.1),
                                      "h/lambda = 0.16, elastic E0"),
    "h/lambda = 0.16, SLS, V = 0.1, anderson": (dict(thickness=0.16, pressure=1.0, material=SLS, speed=0.1,
                                                     method="anderson"), "h/lambda = 0.16, elastic E0"),
    "h/lambda = 0.16, SLS, V = 0.1, mu_c = 0.5": (dict(thickness=0.16, pressure=1.0, material=SLS, speed=0.1,
                                                       friction=0.5), "h/lambda = 0.16, elastic E0"),
}


def fft_pair_seconds(n: int) -> float:
    seconds, stat, errmsg = _core.py_fft_pair_seconds(n, max(10, 2**22 // n), 5)
    if stat:
        raise RuntimeError(errmsg)
    return seconds


def best_solve(h, settings, repeats=5):
    s = dict(settings)
    pressure = s.pop("pressure")
    best = None
    for _ in range(repeats):
        r = lc.solve_line(h, mean_pressure=pressure * (4 / 3) * h.max(), tol=1e-8, stress=False, **s)
        if best is None or r.wall_time < best.wall_time:
            best = r
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1024, 8192, 65536])
    parser.add_argument("--no-marginal", action="store_true", help="skip the table of the cost of one iteration")
    args = parser.parse_args()
    print(f"core: {lc.BUILD} build; tol 1e-8; frictionless rows: method 'cg' (preconditioned, coarse start), "
          "'multigrid' rows method 'auto'; coupled rows: method 'auto' (GCR) unless said otherwise; nu = 0.5; "
          "SLS: E0 = 1, E_inf = 10, tau = 1 (loss peak near V = 0.1 for the roughness here); times: best of 5; "
          "it.: CG or GCR iterations on the finest grid (all inner CG iterations for anderson); FFT pair: the bare "
          "FFTW r2c + c2r pair\n")
    print("| scene | solver | n | FFT pair (ms) | solve (ms) | it. | outer it. | FFT pairs | solve / pair | "
          "per it. (pairs) | per pair spent | vs |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for n in args.sizes:
        pair = min(fft_pair_seconds(n) for _ in range(3))
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        times = {}
        for name, (settings, reference) in SCENES.items():
            r = best_solve(h, settings)
            times[name] = r.wall_time
            ratio = f"{r.wall_time / times[reference]:.2f}x {reference}" if reference else ""
            flag = "" if r.converged else " (NOT CONVERGED)"
            print(f"| {name}{flag} | {r.solver} | {n} | {pair * 1e3:.4f} | {r.wall_time * 1e3:.2f} | {r.iterations} | "
                  f"{r.outer_iterations} | {r.fft_pairs} | {r.wall_time / pair:.0f} | "
                  f"{r.wall_time / r.iterations / pair:.2f} | {r.wall_time / r.fft_pairs / pair:.2f} | {ratio} |")


    if not args.no_marginal:
        marginal_table(args.sizes)


# One grid level (no coarse start), so that the iterations counted are those timed; GCR
# without the Anderson fallback. name: (settings, the cap on the iterations of the longer run)
MARGINAL = {
    "half-space, plain CG": (dict(thickness=np.inf, pressure=0.3, precondition=False), None),
    "half-space, preconditioned CG": (dict(thickness=np.inf, pressure=0.3), None),
    "h/lambda = 0.16, mu_c = 0.5, GCR": (dict(thickness=0.16, friction=0.5, pressure=3.0, method="gcr"), 24),
    "h/lambda = 0.16, SLS, V = 0.1, GCR": (dict(thickness=0.16, pressure=1.0, material=SLS, speed=0.1, method="gcr"),
                                            24),
}


def marginal_table(sizes) -> None:
    """The time of one iteration, without the setup: (t(k2) - t(k1))/(k2 - k1) from two runs
    stopped at k1 and k2 iterations, both short of convergence (a third and two thirds of
    the converged run; a GCR below its stall window), in FFT pairs of time, and the
    transform pairs per iteration by the same difference."""
    print()
    print("One iteration, without the setup: (time of k2 iterations - time of k1)/(k2 - k1) on one grid level "
          "(no coarse start), best of 5; transforms: FFT pairs per iteration by the same difference")
    print()
    print("| scene | n | k1 | k2 | one iteration (FFT pairs of time) | transforms per iteration |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in sizes:
        pair = min(fft_pair_seconds(n) for _ in range(3))
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        for name, (settings, cap) in MARGINAL.items():
            settings = dict(settings, coarse_start=False)
            full = best_solve(h, settings, repeats=1)
            k2 = max(6, (2 * full.iterations) // 3)
            if cap:
                k2 = min(k2, cap)
            k1 = max(2, k2 // 2)
            short = best_solve(h, dict(settings, max_iter=k1))
            long = best_solve(h, dict(settings, max_iter=k2))
            if long.converged or long.iterations == short.iterations:
                print(f"| {name} | {n} | {k1} | {k2} | (converged too early) | |")
                continue
            steps = long.iterations - short.iterations
            print(f"| {name} | {n} | {short.iterations} | {long.iterations} | "
                  f"{(long.wall_time - short.wall_time) / steps / pair:.2f} | "
                  f"{(long.fft_pairs - short.fft_pairs) / steps:.2f} |")


if __name__ == "__main__":
    main()
