"""The two builds of the compiled core against each other: the portable x86-64 one and the
x86-64-v3 one (AVX2, FMA) that the package picks where the processor runs it
(layercontact/native.py), on the scenes of bench/fft_ratio.py.

    .venv/bin/python bench/builds.py [--sizes 8192 65536] [--rounds 5]

Each round solves every scene once with each core, in alternating order, in this process;
the table gives the best solve time (``wall_time``) of each and their ratio, with the
iterations and FFT pairs of both (equal unless rounding tipped a set change).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import layercontact as lc

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fft_ratio import SCENES  # noqa: E402


def solve(core, h, settings):
    s = dict(settings)
    pressure = s.pop("pressure")
    lc.api._core = core
    try:
        return lc.solve_line(h, mean_pressure=pressure * (4 / 3) * h.max(), tol=1e-8, stress=False, **s)
    finally:
        lc.api._core = lc.native.core


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[8192, 65536])
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    if lc.native.core is lc.native.portable:
        print(f"only the {lc.BUILD} build here (no x86-64-v3 core, or LAYERCONTACT_ISA=baseline): nothing to compare")
        return
    cores = {"portable": lc.native.portable, lc.BUILD: lc.native.core}
    print(f"best of {args.rounds} rounds, tol 1e-8; 'v3/portable': ratio of the best solve times\n")
    print("| scene | n | portable (ms) | x86-64-v3 (ms) | v3/portable | it. (portable, v3) | FFT pairs |")
    print("|---|---:|---:|---:|---:|---|---|")
    for n in args.sizes:
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        for name, (settings, _) in SCENES.items():
            best = {}
            for r in range(args.rounds):
                order = list(cores) if r % 2 == 0 else list(reversed(cores))
                for key in order:
                    res = solve(cores[key], h, settings)
                    if key not in best or res.wall_time < best[key].wall_time:
                        best[key] = res
            a, b = best["portable"], best[lc.BUILD]
            print(f"| {name} | {n} | {a.wall_time * 1e3:.2f} | {b.wall_time * 1e3:.2f} | "
                  f"{b.wall_time / a.wall_time:.2f} | {a.iterations}, {b.iterations} | {a.fft_pairs}, {b.fft_pairs} |")


if __name__ == "__main__":
    main()
