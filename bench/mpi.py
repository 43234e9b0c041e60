"""One surface on 1 and 2 MPI ranks (docs/decisions/023-mpi-slabs.md): a 2048² coupled scene
solved serially (no launcher), by `mpirun -n 1` and by `mpirun -n 2`, one thread per rank,
with the time and the peak memory of each rank; and one FFT pair of the surface on 1, 2
and 4 ranks (4 oversubscribed on a 2-core machine) in FFTW-MPI's two layouts.

    .venv/bin/python bench/mpi.py [--n 2048] [--repeats 1] [--pairs-only] [--executable PATH]
                                  [--runs serial,1,2] [--fields] [--before PATH] [--method auto]
    .venv/bin/python bench/mpi.py --scene sliding --n 1024 --no-pairs

With --scene frictionless: the same scene without friction (the constrained CG).
--family physical: the shortest wavelength period/32 at every n (bench/scaling.py's family
(a)) instead of 8 grid points.
With --scene sliding (docs/decisions/028-distributed-multigrid.md): a standard linear solid
(E_inf/E0 = 10, V tau/lambda = 0.1) sliding on a layer h/lambda = 0.16, nu = 0.5, with
mu_c = 0.5 and p_m = 0.02 E0, which 'auto' sends to the multigrid method serially (from
512^2), solved serially, by `mpirun -n 2` under method 'multigrid' (its finest grid on the
slabs, its coarse grids whole on both ranks) and by `mpirun -n 2` under method 'gcr' (the
GCR on the slabs), with their iterations.
With --before PATH another build's program runs each case alternately with this one.
--method sets the coupled scene's &solver method ('auto' by default). On 8192² two ranks
need 'gcr': under 'auto' the memory check counts the coupled multigrid's arrays, which the
policy may take at that size, and each rank's share of them does not fit in 24 GiB.

Scene: self-affine H = 0.8, shortest wavelength 8 points, rms gradient 0.1, seed 1, on an
incompressible layer h/lambda = 0.05 (nu = 0.5), Coulomb friction mu_c = 0.5,
p_m = 0.15 E* h/lambda, tol 1e-8, no surface stress and no fields written (--fields: the
pressure, gap and displacement maps and the heights written, by slabs on several ranks).
"solve" is the summary's solver time (operator, coarse start, iterations; the best of
--repeats), "run" the whole process, "peak RSS" each rank's largest resident set
(/usr/bin/time's %M), "of serial" each rank's peak over the serial run's, and "doubles/pt"
each rank's peak over 8 bytes a point of the whole grid, and their sum. Ratios are
measured within this run. --runs chooses the runs (serial: no launcher; P: mpirun -n P);
"set-up" is the result's setup_time (the operator, its plans and the policy's measures of the
finest grid), "coarse" the coarse start's time (the result's coarse_time), "FFT" the time
inside the transforms, every grid's, the transposes included (transform_time).
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


def scene(directory: Path, n: int, kind: str = "coupled", method: str = "auto", fields: bool = False,
          family: str = "points") -> Path:
    nml = directory / f"{kind}_{method}.nml"
    if kind in ("coupled", "frictionless"):
        body = ("&layer thickness = 0.05, poisson = 0.5 /\n" +
                ("&friction coefficient = 0.5 /\n" if kind == "coupled" else "") +
                "&loading control = 'load', normalised_pressure = 0.15 /\n")
    else:
        body = ("&layer thickness = 0.16, poisson = 0.5 /\n&friction coefficient = 0.5 /\n"
                "&material model = 'sls', e0 = 1.0, e_inf = 10.0, tau = 1.0, speed = 0.1 /\n"
                "&loading control = 'load', mean_pressure = 0.02 /\n")
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n" + body +
        f"&profile kind = 'self_affine', hurst = 0.8, seed = 1, short_wavelength = {8 / n if family == 'points' else 1 / 32}, rms_gradient = 0.1 /\n"
        f"&solver tol = 1e-8, method = '{method}' /\n"
        f"&output file = '{kind}.h5', overwrite = .true., stress = .false., "
        f"fields = {'.true.' if fields else '.false.'} /\n")
    return nml


Measured = tuple[float, float, list[float], str, int, float, float, float]


def run(ranks: int, nml: Path, program: str) -> Measured:
    """(solve s, run s, peak RSS MiB of each rank, solver, iterations, coarse start s, set-up s,
    transforms s) of one run of `program`; ranks 0: no launcher."""
    # (each rank's /usr/bin/time report in a file of its own: rank.N)
    timed = ["sh", "-c", '/usr/bin/time -f "peak_rss_kib %M elapsed %e" -o "rank.${OMPI_COMM_WORLD_RANK:-0}" "$0" "$1"',
             program, str(nml)]
    command = timed if ranks == 0 else ["mpirun", "--oversubscribe", "-n", str(ranks), *timed]
    done = subprocess.run(command, cwd=nml.parent, capture_output=True, text=True, env=environment(ranks > 0))
    if done.returncode != 0:
        sys.exit(f"bench/mpi.py: {' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    solve = float(re.search(r"solver time\s+(\S+)", done.stdout).group(1))
    solver = re.search(r"solver\s+(\S+)", done.stdout).group(1)
    iterations = int(re.search(r"iterations\s+(\d+)", done.stdout).group(1))
    reports = [(nml.parent / f"rank.{r}").read_text() for r in range(max(ranks, 1))]
    peaks = [int(re.search(r"peak_rss_kib (\d+)", text).group(1)) / 1024 for text in reports]
    elapsed = max(float(re.search(r"elapsed (\S+)", text).group(1)) for text in reports)
    with h5py.File(nml.parent / f"{nml.stem.split('_')[0]}.h5", "r") as f:
        coarse = float(f["results"].attrs["coarse_time"])
        setup = float(f["results"].attrs["setup_time"])
        transforms = float(f["results"].attrs["transform_time"])
    return solve, elapsed, peaks, solver, iterations, coarse, setup, transforms


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
    parser.add_argument("--runs", default="serial,1,2", help="runs: serial (no launcher) and rank counts")
    parser.add_argument("--fields", action="store_true", help="write the maps (the result file by slabs)")
    parser.add_argument("--scene", choices=("coupled", "frictionless", "sliding"), default="coupled")
    parser.add_argument("--before", help="another build's layercontact program, run alternately with this one")
    parser.add_argument("--family", choices=("points", "physical"), default="points",
                        help="shortest wavelength 8 grid points, or period/32 at every n")
    parser.add_argument("--method", default="auto", choices=("auto", "gcr", "multigrid"),
                        help="&solver method of the coupled scene")
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
    if args.scene in ("coupled", "frictionless"):
        cases = [(0 if name == "serial" else int(name), args.method) for name in args.runs.split(",")]
        title = (f"{args.n}² coupled (mu_c 0.5, h/lambda 0.05, nu 0.5)" if args.scene == "coupled" else
                 f"{args.n}² frictionless (h/lambda 0.05, nu 0.5)")
    else:
        cases = [(0, "auto"), (2, "multigrid"), (2, "gcr")]
        title = f"{args.n}² sliding SLS (E_inf/E0 10, V tau/lambda 0.1, h/lambda 0.16, mu_c 0.5)"
    with tempfile.TemporaryDirectory() as tmp:
        rows = {}
        for _ in range(args.repeats):
            for ranks, method in cases:
                nml = scene(Path(tmp), args.n, args.scene, method, args.fields, args.family)
                for label, program in programs.items():
                    measured = run(ranks, nml, program)
                    best = rows.get((label, ranks, method))
                    if best is None or measured[0] < best[0]:
                        rows[(label, ranks, method)] = measured
        print(f"\n{title}, tol 1e-8, one thread per rank" + (", fields written" if args.fields else ""))
        print(f"{'run':<30}{'solver':<16}{'iterations':>11}{'solve (s)':>10}{'set-up (s)':>11}"
              f"{'coarse (s)':>11}{'FFT (s)':>9}{'run (s)':>9}"
              f"{'serial/this':>13}{'peak RSS/rank (MiB)':>22}{'of serial':>14}{'doubles/pt':>18}")
        points = args.n**2
        for (label, ranks, method), measured in rows.items():
            solve, elapsed, peaks, solver, iterations, coarse, setup, transforms = measured
            serial = rows.get((label, 0, "auto")) or rows.get((label, 0, method))
            name = label + ("serial" if ranks == 0 else f"mpirun -n {ranks}")
            if method != "auto":
                name += f" ({method})"
            rss = "/".join(f"{p:.0f}" for p in peaks)
            speed = f"{serial[0] / solve:.2f}" if serial else "-"
            share = "/".join(f"{p / max(serial[2]):.2f}" for p in peaks) if serial else "-"
            doubles = [p * 2**20 / 8 / points for p in peaks]
            per_point = "/".join(f"{d:.1f}" for d in doubles)
            if len(doubles) > 1:
                per_point += f" ({sum(doubles):.1f})"
            print(f"{name:<30}{solver:<16}{iterations:>11}{solve:>10.2f}{setup:>11.2f}{coarse:>11.2f}"
                  f"{transforms:>9.2f}{elapsed:>9.2f}{speed:>13}"
                  f"{rss:>22}{share:>14}{per_point:>18}")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
