"""Cost of a solver iteration in units of one FFTW r2c + c2r pair of the same size, and
the cost of friction and viscoelasticity relative to the frictionless elastic solve.

    .venv/bin/python bench/fft_ratio.py

All ratios are measured in this run on this machine (best of a few repetitions).
"""

from __future__ import annotations

import time

import numpy as np

import layercontact as lc
from layercontact import _core

SLS = lc.StandardLinearSolid(e0=1.0, e_inf=100.0, tau=1.0)
SCENES = {
    "half-space, mu_c = 0": dict(thickness=np.inf, friction=0.0, pressure=0.3),
    "h/lambda = 0.16, mu_c = 0": dict(thickness=0.16, friction=0.0, pressure=3.0),
    "h/lambda = 0.16, mu_c = 0.5": dict(thickness=0.16, friction=0.5, pressure=3.0),
    "h/lambda = 0.01, mu_c = 0.5": dict(thickness=0.01, friction=0.5, pressure=30.0),
    "viscoelastic h/lambda = 0.16, V = 0.1": dict(thickness=0.16, friction=0.0, pressure=3.0, material=SLS, speed=0.1),
}


def fft_pair_seconds(n: int) -> float:
    seconds, stat, errmsg = _core.py_fft_pair_seconds(n, max(10, 2**22 // n), 5)
    if stat:
        raise RuntimeError(errmsg)
    return seconds


def best_time(h, s, repeats=3):
    best = None
    for _ in range(repeats):
        t = time.perf_counter()
        r = lc.solve_line(h, thickness=s["thickness"], friction=s["friction"], material=s.get("material"),
                          speed=s.get("speed", 0.0), mean_pressure=s["pressure"] * (4 / 3) * h.max(), tol=1e-8,
                          stress=False)
        t = time.perf_counter() - t
        if best is None or t < best[0]:
            best = (t, r)
    return best


def main() -> None:
    print("tol 1e-8; times are the best of 3; 'per CG it.' and 'per pair' in units of one FFT pair")
    print(f"{'scene':<40}{'n':>7}{'pair (ms)':>10}{'time (ms)':>10}{'CG it.':>8}{'pairs':>7}"
          f"{'per CG it.':>11}{'per pair':>9}{'vs mu_c=0':>10}")
    for n in (1024, 8192, 65536):
        pair = fft_pair_seconds(n)
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        reference = None
        for name, s in SCENES.items():
            t, r = best_time(h, s)
            if name == "h/lambda = 0.16, mu_c = 0":
                reference = t
            ratio = f"{t / reference:10.2f}" if reference and name != "half-space, mu_c = 0" else f"{'':>10}"
            print(f"{name:<40}{n:>7}{pair * 1e3:>10.4f}{t * 1e3:>10.2f}{r.iterations:>8}{r.fft_pairs:>7}"
                  f"{t / r.iterations / pair:>11.2f}{t / r.fft_pairs / pair:>9.2f}{ratio}")


if __name__ == "__main__":
    main()
