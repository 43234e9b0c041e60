"""The contact patches and the leakage of one surface computed on the slabs of 1, 2 and 4
MPI ranks against the serial run (docs/decisions/026-distributed-patches-and-leakage.md):
k_eff along x and y and their relative difference to the serial run's, the CG iterations of
each direction, the leakage's own time (/leakage wall_time, the slowest rank's is the run's)
and whether the patch list is the serial one to the bit.

    .venv/bin/python bench/mpi_observables.py [--n 512] [--ranks 2 4] [--pressure 0.05 1.0]
        [--leakage-tol 1e-6] [--executable PATH]

Scene: self-affine H = 0.8, shortest wavelength n/16 points of a 64-point grid scaled to n
(short_wavelength 1/16), flat spectrum above a quarter of the cell (rolloff_wavelength
0.25), seed 3, on an incompressible layer h/lambda = 0.05, frictionless, tol 1e-10;
normalised_pressure 0.05 (5 % contact, far from percolation) and 1.0 (at percolation along
y) by default. One thread per rank; four ranks on two cores are oversubscribed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import h5py
import numpy as np


def executable(given: str | None) -> str:
    found = given or shutil.which("layercontact", path=sysconfig.get_path("scripts")) or shutil.which("layercontact")
    if not found:
        sys.exit("bench/mpi_observables.py: the layercontact executable is not installed (pip install .)")
    return found


def scene(directory: Path, n: int, pressure: float, leakage_tol: float, output: str) -> Path:
    nml = directory / f"{output}.nml"
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n"
        "&layer thickness = 0.05, poisson = 0.5 /\n&friction coefficient = 0.0 /\n"
        "&profile kind = 'self_affine', hurst = 0.8, seed = 3, short_wavelength = 0.0625, "
        "rolloff_wavelength = 0.25 /\n"
        f"&loading control = 'load', normalised_pressure = {pressure} /\n&solver tol = 1e-10 /\n"
        f"&output file = '{output}.h5', overwrite = .true., stress = .false., leakage = .true., "
        f"leakage_tol = {leakage_tol} /\n")
    return nml


def run(program: str, nml: Path, ranks: int) -> dict[str, object]:
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if ranks == 0:
        for name in [k for k in env if k.startswith(("OMPI_", "PMIX_", "PMI_"))]:
            del env[name]
        command = [program, str(nml)]
    else:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        command = ["mpirun", "--oversubscribe", "--mca", "mpi_yield_when_idle", "1", "-n", str(ranks), program,
                   str(nml)]
    done = subprocess.run(command, cwd=nml.parent, capture_output=True, text=True, env=env)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({done.returncode}): {done.stderr}")
    with h5py.File(nml.with_suffix(".h5"), "r") as f:
        out = dict(f["leakage"].attrs)
        out["area"] = np.asarray(f["patches/area"])
        out["perimeter"] = np.asarray(f["patches/perimeter"])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=512)
    parser.add_argument("--ranks", type=int, nargs="+", default=[2, 4])
    parser.add_argument("--pressure", type=float, nargs="+", default=[0.05, 1.0])
    parser.add_argument("--leakage-tol", type=float, default=1e-6)
    parser.add_argument("--executable")
    args = parser.parse_args()
    program = executable(args.executable)
    print(f"n = {args.n}, leakage_tol = {args.leakage_tol:g}, load average {os.getloadavg()[0]:.1f}")
    print(f"{'p':>5} {'ranks':>6} {'k_eff_x':>13} {'k_eff_y':>13} {'rel. diff x':>11} {'rel. diff y':>11} "
          f"{'iter x/y':>9} {'leakage (s)':>11} {'patches':>8} {'same':>5}")
    with tempfile.TemporaryDirectory() as tmp:
        for pressure in args.pressure:
            serial = None
            for ranks in [0, *args.ranks]:
                name = f"p{pressure}_r{ranks}"
                out = run(program, scene(Path(tmp), args.n, pressure, args.leakage_tol, name), ranks)
                serial = serial or out

                def diff(axis: str) -> float:
                    ref = serial[f"k_eff_{axis}"]
                    return abs(out[f"k_eff_{axis}"] - ref) / ref if ref else abs(out[f"k_eff_{axis}"])

                same = np.array_equal(out["area"], serial["area"]) and np.array_equal(out["perimeter"],
                                                                                      serial["perimeter"])
                print(f"{pressure:>5g} {ranks or 'serial':>6} {out['k_eff_x']:>13.6e} {out['k_eff_y']:>13.6e} "
                      f"{diff('x'):>11.1e} {diff('y'):>11.1e} {out['iterations_x']:>4}/{out['iterations_y']:<4} "
                      f"{out['wall_time']:>11.3f} {len(out['area']):>8} {str(same):>5}")


if __name__ == "__main__":
    main()
