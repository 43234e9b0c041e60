"""One surface on 1 and 2 MPI ranks (docs/decisions/023-mpi-slabs.md): a 2048² coupled scene
solved serially (no launcher), by `mpirun -n 1` and by `mpirun -n 2`, one thread per rank,
with the time and the peak memory of each rank; and one FFT pair of the surface on 1, 2
and 4 ranks (4 oversubscribed on a 2-core machine) in FFTW-MPI's two layouts.

    .venv/bin/python bench/mpi.py [--n 2048] [--repeats 1] [--pairs-only] [--executable PATH] [--before PATH]

Scene: self-affine H = 0.8, shortest wavelength 8 points, rms gradient 0.1, seed 1, on an
incompressible layer h/lambda = 0.05 (nu = 0.5), Coulomb friction mu_c = 0.5,
p_m = 0.15 E* h/lambda, tol 1e-8, no surface stress and no fields written (the solve and
the gathering of its fields to rank 0). "solve" is the summary's solver time (operator,
coarse start, iterations; the best of --repeats), "coarse" the coarse start's part of it
(the result's `coarse_time`, rank 0's), "run" the whole process, "peak RSS" each rank's
largest resident set (/usr/bin/time's %M). Ratios are measured within this run.
`--before PATH`: another build's program (e.g. the one before a change) run alternately
with this one in the same run, its rows marked "before".
The FFT pairs come from bench/mpi_fft_pair.c, compiled here with mpicc.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import h5py

HERE = Path(__file__).resolve().parent


EXECUTABLE: str | None = None


def executable() -> str:
    if EXECUTABLE:
        return EXECUTABLE
    found = shutil.which("layercontact", path=sysconfig.get_path("scripts")) or shutil.which("layercontact")
    if not found:
        sys.exit("bench/mpi.py: the layercontact executable is not installed (pip install .)")
    return found


def environment(launched: bool) -> dict[str, str]:
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if launched:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def scene(directory: Path, n: int) -> Path:
    nml = directory / "coupled.nml"
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n"
        "&layer thickness = 0.05, poisson = 0.5 /\n&friction coefficient = 0.5 /\n"
        f"&profile kind = 'self_affine', hurst = 0.8, seed = 1, short_wavelength = {8 / n}, rms_gradient = 0.1 /\n"
        "&loading control = 'load', normalised_pressure = 0.15 /\n&solver tol = 1e-8 /\n"
        "&output file = 'coupled.h5', overwrite = .true., stress = .false., fields = .false. /\n")
    return nml


def run(ranks: int, nml: Path, program: str) -> tuple[float, float, list[float], str, float]:
    """(solve s, run s, peak RSS MiB of each rank, solver, coarse start s) of one run of
    `program`; ranks 0: no launcher."""
    # (each rank's /usr/bin/time report in a file of its own: rank.N)
    timed = ["sh", "-c", '/usr/bin/time -f "peak_rss_kib %M elapsed %e" -o "rank.${OMPI_COMM_WORLD_RANK:-0}" "$0" "$1"',
             program, str(nml)]
    command = timed if ranks == 0 else ["mpirun", "--oversubscribe", "-n", str(ranks), *timed]
    done = subprocess.run(command, cwd=nml.parent, capture_output=True, text=True, env=environment(ranks > 0))
    if done.returncode != 0:
        sys.exit(f"bench/mpi.py: {' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    solve = float(re.search(r"solver time\s+(\S+)", done.stdout).group(1))
    solver = re.search(r"solver\s+(\S+)", done.stdout).group(1)
    reports = [(nml.parent / f"rank.{r}").read_text() for r in range(max(ranks, 1))]
    peaks = [int(re.search(r"peak_rss_kib (\d+)", text).group(1)) / 1024 for text in reports]
    elapsed = max(float(re.search(r"elapsed (\S+)", text).group(1)) for text in reports)
    with h5py.File(nml.parent / "coupled.h5", "r") as f:
        coarse = float(f["results"].attrs["coarse_time"])
    return solve, elapsed, peaks, solver, coarse


def pairs(n: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        program = Path(tmp) / "fft_pair"
        subprocess.run(["mpicc", "-O2", str(HERE / "mpi_fft_pair.c"), "-lfftw3_mpi", "-lfftw3", "-o", str(program)],
                       check=True)
        for ranks in (1, 2, 4):
            done = subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), str(program), str(n), str(n), "7"],
                                  capture_output=True, text=True, env=environment(True), check=True)
            print(done.stdout, end="")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2048)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--pairs-only", action="store_true")
    parser.add_argument("--no-pairs", action="store_true", help="the solves only")
    parser.add_argument("--executable", help="the layercontact program (default: the installed one)")
    parser.add_argument("--before",
                        help="another build's layercontact program, run alternately with this one")
    args = parser.parse_args()
    global EXECUTABLE
    EXECUTABLE = args.executable
    programs = {"": executable()}
    if args.before:
        programs = {"before ": args.before, "": executable()}
    print(f"load average before: {os.getloadavg()[0]:.1f}")
    if not args.no_pairs:
        print(f"FFT pair of {args.n}² (median of 7, slowest rank):")
        pairs(args.n)
    if args.pairs_only:
        return
    with tempfile.TemporaryDirectory() as tmp:
        nml = scene(Path(tmp), args.n)
        rows = {}
        for _ in range(args.repeats):
            for ranks in (0, 1, 2):
                for label, program in programs.items():
                    measured = run(ranks, nml, program)
                    best = rows.get((label, ranks))
                    if best is None or measured[0] < best[0]:
                        rows[(label, ranks)] = measured
        print(f"\n{args.n}² coupled (mu_c 0.5, h/lambda 0.05, nu 0.5), tol 1e-8, one thread per rank")
        print(f"{'run':<21}{'solver':<8}{'solve (s)':>10}{'coarse (s)':>11}{'run (s)':>9}{'serial/this':>13}"
              f"{'peak RSS/rank (MiB)':>22}{'of serial':>11}")
        for (label, ranks), (solve, elapsed, peaks, solver, coarse) in rows.items():
            serial = rows[(label, 0)]
            name = label + ("serial" if ranks == 0 else f"mpirun -n {ranks}")
            rss = "/".join(f"{p:.0f}" for p in peaks)
            print(f"{name:<21}{solver:<8}{solve:>10.2f}{coarse:>11.2f}{elapsed:>9.2f}"
                  f"{serial[0] / solve:>13.2f}"
                  f"{rss:>22}{max(peaks) / max(serial[2]):>11.2f}")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
