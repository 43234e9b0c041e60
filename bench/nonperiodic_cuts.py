"""Non-periodic patches in a periodic solver: cut a periodic surface into K x K patches,
solve each patch as a measured, non-periodic topography (docs/topographies.md) and compare
its contact fraction with that of the full periodic solve inside the same patch.

Treatments (lc.prepare_heights): 'as is' (the patch as one period, its edges meeting with a
step), 'plane' (the same after a plane detrend), 'mirror' (the patch and its mirror images,
plane detrend as by default) and 'mirror, none' (mirrored without detrending). Each patch is
solved at the mean pressure of the full solve inside it, so that the comparison shows what
the cell's edges do, not how the load happens to be shared between patches.

    python bench/nonperiodic_cuts.py                      # half-space, 512², 4 x 4 patches
    python bench/nonperiodic_cuts.py --thickness 0.02     # a thin layer (h = period/50)
"""

from __future__ import annotations

import argparse

import numpy as np

import layercontact as lc

TREATMENTS = {
    "as is": {"detrend": "none"},
    "plane": {"detrend": "plane"},
    "mirror": {"boundary": "mirror"},
    "mirror, none": {"boundary": "mirror", "detrend": "none"},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=512, help="grid points per side of the full surface")
    parser.add_argument("--cuts", type=int, default=4, help="patches per side")
    parser.add_argument("--thickness", type=float, default=np.inf, help="layer thickness (inf: half-space)")
    parser.add_argument("--pressure", type=float, default=0.01, help="mean pressure (E = 1, nu = 0.5)")
    args = parser.parse_args()

    n, k = args.n, args.cuts
    period = 1.0
    h = lc.self_affine_surface(n=n, hurst=0.8, period=period, short_wavelength=period / 32,
                               rolloff_wavelength=period / 4, seed=11, rms_gradient=0.1)
    common = {"thickness": args.thickness, "young": 1.0, "poisson": 0.5, "tol": 1e-8}
    full = lc.solve_areal(h, stress=False, period=period, mean_pressure=args.pressure, **common)
    print(f"full periodic surface {n}², thickness {args.thickness:g}, mean pressure {args.pressure:g}: "
          f"contact fraction {full.contact_fraction:.4f}")
    m = n // k
    errors = {name: [] for name in TREATMENTS}
    fractions = {name: [] for name in ["reference", *TREATMENTS]}
    jumps = []
    for iy in range(k):
        for ix in range(k):
            cut = (slice(iy * m, (iy + 1) * m), slice(ix * m, (ix + 1) * m))
            patch, inside = h[cut], full.pressure[cut]
            reference = np.mean(inside > 0)
            # the step between opposite edges against the step between neighbours
            edges = np.concatenate([patch[:, -1] - patch[:, 0], patch[-1, :] - patch[0, :]])
            steps = np.concatenate([np.diff(patch, axis=1).ravel(), np.diff(patch, axis=0).ravel()])
            jumps.append(np.sqrt(np.mean(edges**2) / np.mean(steps**2)))
            if inside.mean() <= 0:
                continue
            fractions["reference"].append(reference)
            for name, treatment in TREATMENTS.items():
                cell = lc.prepare_heights(patch, **treatment)
                size = period / k * (2 if treatment.get("boundary") == "mirror" else 1)
                result = lc.solve_areal(cell, stress=False, period=size, mean_pressure=inside.mean(),
                                        **common)
                fractions[name].append(result.contact_fraction)
                errors[name].append(result.contact_fraction / reference - 1)
    print(f"{k * k} patches of {m}²: rms edge step / rms neighbour step = {np.mean(jumps):.1f}")
    print(f"{'treatment':<14}{'mean fraction':>14}{'mean error':>12}{'rms error':>11}")
    print(f"{'reference':<14}{np.mean(fractions['reference']):>14.4f}")
    for name in TREATMENTS:
        mean = np.mean(fractions[name])
        print(f"{name:<14}{mean:>14.4f}{mean / np.mean(fractions['reference']) - 1:>+12.3f}"
              f"{np.sqrt(np.mean(np.square(errors[name]))):>11.3f}")


if __name__ == "__main__":
    main()
