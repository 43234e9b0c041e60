"""The periodicity measure of height files taken as one period (lc.periodicity_mismatch,
docs/decisions/019): its largest values over periodic self-affine surfaces of the generator
(which must not warn), and its values for non-periodic ones (which must): a tilted plane, a
parabola, the same under roughness, and the cuts of a periodic surface that
bench/nonperiodic_cuts.py solves. Prints the jump (rms heights) and the kink (the cell's
own slope mismatch) next to the limits the library warns above.

    python bench/periodicity_indicator.py            # 100 seeds per line, 40 per surface
"""

from __future__ import annotations

import argparse

import numpy as np

import layercontact as lc
from layercontact.profiles import EDGE_JUMP_LIMIT, EDGE_KINK_LIMIT


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    args = parser.parse_args()
    print(f"limits: jump {EDGE_JUMP_LIMIT}, kink {EDGE_KINK_LIMIT}")
    print("periodic self-affine (largest over the seeds):")
    print(f"  {'kind':<8}{'H':>6}{'n':>7}{'jump':>8}{'kink':>8}")
    largest = np.zeros(2)
    for hurst in (0.3, 0.5, 0.8, 0.95):
        for n in (64, 256, 4096):
            values = np.array([lc.periodicity_mismatch(lc.self_affine_profile(n, hurst, seed=s))
                               for s in range(1, args.seeds + 1)]).max(axis=0)
            largest = np.maximum(largest, values)
            print(f"  {'line':<8}{hurst:>6}{n:>7}{values[0]:>8.2f}{values[1]:>8.2f}")
        for n in (32, 128):
            values = np.array([lc.periodicity_mismatch(lc.self_affine_surface(nx=n, ny=n, hurst=hurst, seed=s))
                               for s in range(1, args.seeds // 2 - 9)]).max(axis=0)
            largest = np.maximum(largest, values)
            print(f"  {'surface':<8}{hurst:>6}{n:>7}{values[0]:>8.2f}{values[1]:>8.2f}")
    print(f"  largest: jump {largest[0]:.2f}, kink {largest[1]:.2f}")
    x = np.arange(512) / 512
    rough = lc.self_affine_profile(512, 0.8, seed=3)
    rough = rough / rough.std()
    ramp = (x - x.mean()) / (x - x.mean()).std()
    bowl = ((x - 0.5) ** 2 - ((x - 0.5) ** 2).mean()) / ((x - 0.5) ** 2).std()
    print("not periodic:")
    for name, heights in (("tilted plane", ramp), ("parabola", bowl), ("rough + tilt 1 rms", rough + ramp),
                          ("rough + parabola 1 rms", rough + bowl)):
        jump, kink = lc.periodicity_mismatch(heights)
        warned = jump > EDGE_JUMP_LIMIT or kink > EDGE_KINK_LIMIT
        print(f"  {name:<24} jump {jump:6.2f}  kink {kink:9.2f}  {'warns' if warned else 'no warning'}")
    surface = lc.self_affine_surface(512, 0.8, seed=1)
    cuts = [surface[i:i + 128, j:j + 128] for i in range(0, 512, 128) for j in range(0, 512, 128)]
    values = np.array([lc.periodicity_mismatch(c) for c in cuts])
    warned = np.mean((values[:, 0] > EDGE_JUMP_LIMIT) | (values[:, 1] > EDGE_KINK_LIMIT))
    print(f"  16 cuts 128² of a 512² surface: jump {np.median(values[:, 0]):.2f} (median), kink "
          f"{np.median(values[:, 1]):.2f} (median); {warned:.0%} warn")


if __name__ == "__main__":
    main()
