"""Time of lc.reynolds_leakage on gaps near percolation at 512^2, 1024^2 and 2048^2.

Gaps: by default the bearing-area cut ``g = max(level - r, 0)^(3/2)`` of a self-affine surface
(H = 0.8, cutoff 8 grid steps) at a contact fraction of 0.45, close to the 0.5 at which the
cut of a Gaussian surface stops percolating; the power 3/2 mimics the opening of an elastic
gap at the contact edge. With --solve, the gap of a frictionless elastic half-space pressed
by ``lc.solve_areal`` (nu = 0.5, E = 1) at --pressure (0.0275: contact fraction about 0.37
for this surface); that takes minutes at 2048^2 and is not timed.

Each size reports the flow-carrying unknowns, the CG iterations, wall and CPU seconds of the
default call (AMG + CG, tol 1e-6 on k_eff) and the error of its k_eff against a reference
(the sparse direct solver up to 1024^2, AMG with tol 1e-13 beyond). --compare adds, on the
same systems, the sparse direct solver and pyamg's stock smoothed aggregation
(``smoothed_aggregation_solver`` defaults) under the same CG. --core adds the compiled
core's leakage (what ``&output leakage`` computes: CG with hypre's BoomerAMG, both
directions) against the Python solver on both directions of the same gap.

    .venv/bin/python bench/leakage_speed.py [--sizes 512 1024 2048] [--solve] [--compare] [--core]

The stock pyamg comparison calls threaded BLAS (its coarse ``pinv``), which is slow when
the cores are shared; OPENBLAS_NUM_THREADS=1 makes the comparison fairer on a busy machine.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import layercontact as lc
from layercontact import leakage


def synthetic_gap(n: int, contact_fraction: float, seed: int) -> tuple[np.ndarray, None]:
    r = lc.self_affine_surface(n=n, hurst=0.8, seed=seed, short_wavelength=8 / n, rms_gradient=0.1)
    level = np.quantile(r, 1 - contact_fraction)
    return np.maximum(level - r, 0.0) ** 1.5, None


def solved_gap(n: int, pressure: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    r = lc.self_affine_surface(n=n, hurst=0.8, seed=seed, short_wavelength=8 / n, rms_gradient=0.1)
    sol = lc.solve_areal(r, stress=False, thickness=np.inf, poisson=0.5, mean_pressure=pressure, tol=1e-8)
    return sol.gap, sol.pressure > 0


def timed(function, *args, **kwargs):
    wall, cpu = time.perf_counter(), time.process_time()
    out = function(*args, **kwargs)
    return out, time.perf_counter() - wall, time.process_time() - cpu


def stock_pyamg(gap, contact, tol):
    """The same system under the same CG with pyamg's default smoothed aggregation."""
    import pyamg

    fluid = (gap > 1e-6 * gap.max()) if contact is None else (~contact & (gap > 1e-6 * gap.max()))
    g = np.where(fluid, gap, 0.0)
    n = g.shape[1]
    c_flow, c_across = leakage._face_conductances(g, "harmonic")
    cluster, winds = leakage._flow_clusters(fluid)
    system = leakage._assemble(winds[cluster], cluster, c_flow, c_across, 1 / n, 1 / n)
    hierarchy = pyamg.smoothed_aggregation_solver(system.matrix, symmetry="hermitian")
    phi, iterations, _ = leakage._pcg(
        system.matrix, system.rhs, hierarchy.aspreconditioner().matvec, system.dissipation, tol, 1000
    )
    return system.dissipation(phi) / g.size, iterations


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024, 2048])
    parser.add_argument("--solve", action="store_true", help="gaps from lc.solve_areal instead of the cut")
    parser.add_argument("--pressure", type=float, default=0.0275, help="mean pressure of --solve (E = 1)")
    parser.add_argument("--contact-fraction", type=float, default=0.45, help="of the synthetic cut")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--tol", type=float, default=1e-6)
    parser.add_argument("--compare", action="store_true", help="also the direct solver and stock pyamg")
    parser.add_argument("--core", action="store_true", help="the core's leakage (both directions) against Python's")
    args = parser.parse_args()

    source = "elastic half-space solve" if args.solve else f"bearing-area cut at {args.contact_fraction}"
    print(f"gaps: {source}, H = 0.8, cutoff 8 grid steps, seed {args.seed}; tol = {args.tol:g} on k_eff\n")
    print("| n | contact | connected | unknowns | it. | wall s | CPU s | k_eff | rel. error | reference |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    extra, core_rows = [], []
    if args.core:
        # the first call of the process starts MPI (for hypre): timed apart, once
        stripes = np.tile(1.0 + 0.5 * np.cos(2 * np.pi * np.arange(8) / 8), (8, 1))  # flow across needs a solve
        _, start_wall, _ = timed(lc.core_leakage, stripes)
        core_rows.append(f"| - | core: MPI and hypre start (once per process) | - | - | {start_wall:.2f} | - | - | - | - |")
    for n in args.sizes:
        gap, contact = (
            solved_gap(n, args.pressure, args.seed)
            if args.solve
            else synthetic_gap(n, args.contact_fraction, args.seed)
        )
        if args.core:
            core_rows += core_against_python(n, gap, contact, args.tol)
        res, wall, cpu = timed(lc.reynolds_leakage, gap, contact=contact, method="amg", tol=args.tol)
        if not res.percolating:
            print(f"| {n} | {1 - res.fluid_fraction:.3f} | 0 | 0 | - | {wall:.2f} | {cpu:.2f} | 0 | - | - |")
            continue
        if n <= 1024:
            ref, ref_wall, ref_cpu = timed(lc.reynolds_leakage, gap, contact=contact, method="direct")
            label = "direct"
        else:
            ref, ref_wall, ref_cpu = timed(lc.reynolds_leakage, gap, contact=contact, method="amg", tol=1e-13)
            label = "AMG 1e-13"
        error = (res.k_eff - ref.k_eff) / ref.k_eff
        print(
            f"| {n} | {1 - res.fluid_fraction:.3f} | {res.connected_fraction:.3f} | {res.unknowns} | "
            f"{res.iterations} | {wall:.2f} | {cpu:.2f} | {res.k_eff:.6e} | {error:.1e} | {label} |",
            flush=True,
        )
        if args.compare:
            if label == "direct":
                extra.append(
                    f"| {n} | direct (SuperLU, MMD on A+A^T) | - | {ref_wall:.2f} | {ref_cpu:.2f} | 0 |"
                )
            (k, iterations), stock_wall, stock_cpu = timed(stock_pyamg, gap, contact, args.tol)
            extra.append(
                f"| {n} | pyamg stock SA + CG | {iterations} | {stock_wall:.2f} | {stock_cpu:.2f} | "
                f"{(k - ref.k_eff) / ref.k_eff:.1e} |"
            )
    if extra:
        print("\n| n | solver | it. | wall s | CPU s | rel. error |")
        print("|---|---|---|---|---|---|")
        print("\n".join(extra))
    if core_rows:
        print("\nBoth directions; rel. difference of k_eff against the Python solver's\n")
        print("| n | solver | unknowns x, y | it. x, y | wall s | CPU s | k_eff_x | k_eff_y | rel. diff. x, y |")
        print("|---|---|---|---|---|---|---|---|---|")
        print("\n".join(core_rows))


def core_against_python(n, gap, contact, tol):
    """Rows of the core's leakage (x and y in one call) and of the Python solver (one call
    per direction) on the same gap."""
    rows = []
    python = {}
    wall_python = cpu_python = 0.0
    for direction in ("x", "y"):
        res, wall, cpu = timed(lc.reynolds_leakage, gap, contact=contact, direction=direction, method="auto", tol=tol)
        python[direction] = res
        wall_python += wall
        cpu_python += cpu
    rows.append(
        f"| {n} | Python (pyamg SA + CG) | {python['x'].unknowns}, {python['y'].unknowns} | "
        f"{python['x'].iterations}, {python['y'].iterations} | {wall_python:.2f} | {cpu_python:.2f} | "
        f"{python['x'].k_eff:.6e} | {python['y'].k_eff:.6e} | - |"
    )
    core, wall, cpu = timed(lc.core_leakage, gap, contact=contact, tol=tol)
    difference = [
        (k - python[d].k_eff) / python[d].k_eff if python[d].k_eff > 0 else k
        for d, k in (("x", core.k_eff_x), ("y", core.k_eff_y))
    ]
    note = "" if core.converged else " (not converged)"
    rows.append(
        f"| {n} | core: {core.solver}{note} | {core.unknowns_x}, {core.unknowns_y} | "
        f"{core.iterations_x}, {core.iterations_y} | {wall:.2f} | {cpu:.2f} | {core.k_eff_x:.6e} | {core.k_eff_y:.6e} | "
        f"{difference[0]:.1e}, {difference[1]:.1e} |"
    )
    return rows


if __name__ == "__main__":
    main()
