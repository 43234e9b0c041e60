"""A glassy viscoelastic layer with friction against the elastic layer at its relaxed
modulus: the cost of a solve across sliding speeds, on both roughness families.

    .venv/bin/python bench/glassy.py                        # n = 1024, 16384, 65536 (~1 min)
    .venv/bin/python bench/glassy.py --sizes 16384 --methods auto gcr multigrid

The layer: h/lambda = 0.16, nu = 0.5, mu_c = 0.5, a standard linear solid with
E_inf/E0 = 100 (E0 = 1, tau = 1) sliding at V tau/lambda = 1e-4 .. 1e2 (relaxed at the
slowest, glassy at the fastest, the hysteretic friction peak in between), p_m = 0.03 E0
(20-40 % contact); the reference is the elastic layer with E = E0. The profile: self-affine,
H = 0.8, rms gradient 0.1, seed 1, its spectrum fixed in physical wavenumbers (shortest
wavelength lambda/64) or with the shortest wavelength 8 grid points (broadband). tol 1e-8,
one thread, each solve the best of --repeats. Per row: the method that ran, iterations,
transform pairs, time (the library's `wall_time`), and the time and pairs relative to the
elastic layer's solve with the same method argument.
"""

from __future__ import annotations

import argparse

import layercontact as lc

GLASSY = lc.StandardLinearSolid(e0=1.0, e_inf=100.0, tau=1.0)
SPEEDS = [1e-4, 1e-2, 1.0, 1e2]


def solve(h, method: str, speed: float | None):
    kw = dict(thickness=0.16, poisson=0.5, friction=0.5, mean_pressure=0.03, tol=1e-8, threads=1, stress=False,
              method=method)
    if speed is not None:
        kw.update(material=GLASSY, speed=speed)
    return lc.solve_line(h, **kw)


def best_of(h, method: str, speed: float | None, repeats: int):
    runs = [solve(h, method, speed) for _ in range(max(repeats, 1))]
    return min(runs, key=lambda r: r.wall_time)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1024, 16384, 65536])
    parser.add_argument("--methods", nargs="+", default=["auto", "gcr"])
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    print(f"layercontact {lc.__version__}; E_inf/E0 = 100, h/lambda = 0.16, mu_c = 0.5, tol 1e-8, one thread\n")
    print("| family | n | method | V tau/lambda | solver | it. | pairs | ms | contact | time / elastic | "
          "pairs / elastic |")
    print("|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|")
    for family, shortest in (("physical", lambda n: 1 / 64), ("8 points", lambda n: 8 / n)):
        for n in args.sizes:
            h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=shortest(n), rms_gradient=0.1)
            for method in args.methods:
                try:
                    elastic = best_of(h, method, None, args.repeats)
                except lc.InputError as err:
                    print(f"| {family} | {n} | {method} | (elastic) | refused: {str(err)[:60]}... |")
                    continue
                print(f"| {family} | {n} | {method} | elastic E0 | {elastic.solver} | {elastic.iterations} "
                      f"| {elastic.fft_pairs} | {elastic.wall_time * 1e3:.1f} | {elastic.contact_fraction:.2f} | 1 | 1 |",
                      flush=True)
                for speed in SPEEDS:
                    try:
                        r = best_of(h, method, speed, args.repeats)
                    except lc.InputError as err:
                        print(f"| {family} | {n} | {method} | {speed:g} | refused: {str(err)[:60]}... |")
                        continue
                    flag = "" if r.converged else " NOT CONVERGED"
                    print(f"| {family} | {n} | {method} | {speed:g} | {r.solver} | {r.iterations}{flag} "
                          f"| {r.fft_pairs} | {r.wall_time * 1e3:.1f} | {r.contact_fraction:.2f} "
                          f"| {r.wall_time / elastic.wall_time:.1f} | {r.fft_pairs / elastic.fft_pairs:.1f} |",
                          flush=True)


if __name__ == "__main__":
    main()
