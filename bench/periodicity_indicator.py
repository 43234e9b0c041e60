"""The periodicity measure of height files taken as one period (lc.periodicity_mismatch,
docs/decisions/019): its largest values over periodic self-affine surfaces of the generator
(which must not warn), and its values for non-periodic ones (which must): a tilted plane, a
parabola, the same under roughness, and the cuts of a periodic surface that
bench/nonperiodic_cuts.py solves. Prints the jump (rms heights) and the kink (the cell's
own slope mismatch) next to the limits the library warns above; then what a tilt does to
the contact fraction of a rough line (1024 points, half-space, H = 0.8) taken as it is, plane
detrended or mirrored, against that of the untilted periodic roughness at the same mean
pressure.

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
    tilt_effect()


def tilt_effect(n: int = 1024) -> None:
    """Contact fraction of a tilted rough line against the untilted one, per treatment."""
    x = np.arange(n) / n
    rough = lc.self_affine_profile(n, 0.8, seed=3)
    rough = 1e-3 * rough / rough.std()
    ramp = 1e-3 * (x - x.mean()) / (x - x.mean()).std()
    pressure = lc.solve_line(rough, normalised_pressure=1.0).mean_pressure
    reference = lc.solve_line(rough, mean_pressure=pressure).contact_fraction
    print(f"tilted rough line: contact fraction against the untilted one ({reference:.4f} at p_m = {pressure:.3g})")
    treatments = {"as is": {"detrend": "none"}, "plane": {"detrend": "plane"}, "mirror": {"boundary": "mirror"}}
    for tilt in (0.25, 0.5, 1.0, 2.0, 4.0):
        heights = rough + tilt * ramp
        jump, kink = lc.periodicity_mismatch(heights)
        shown = []
        for name, options in treatments.items():
            prepared = lc.prepare_heights(heights, **options)
            period = 2.0 if options.get("boundary") == "mirror" else 1.0
            fraction = lc.solve_line(prepared, period=period, mean_pressure=pressure).contact_fraction
            shown.append(f"{name} {fraction / reference - 1:+.1%}")
        warned = "warns" if jump > EDGE_JUMP_LIMIT or kink > EDGE_KINK_LIMIT else "no warning"
        print(f"  tilt {tilt:4} rms: jump {jump:5.2f}, kink {kink:6.2f} ({warned:>10}):  " + ",  ".join(shown))


if __name__ == "__main__":
    main()
