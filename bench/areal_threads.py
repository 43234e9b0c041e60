"""FFTW's OpenMP threads on areal solves: the Fortran executable of an OpenMP build run on
one areal namelist with ``&solver threads = 1`` and ``2``, alternately, several times.

The package is built without OpenMP; build a separate copy (the .venv is not touched;
``-Dx86_64_v3=disabled``: the executable is the portable core anyway):

    PATH=$PWD/.venv/bin:$PATH meson setup /tmp/omp-build -Dopenmp=true -Dx86_64_v3=disabled
    ninja -C /tmp/omp-build
    .venv/bin/python bench/areal_threads.py [--exe /tmp/omp-build/layercontact] [--sizes 1024 2048] \\
        [--repeats 5] [--threads 1 2]

Scene: frictionless incompressible half-space, the isotropic self-affine surface of
``&profile kind='self_affine'`` (H = 0.8, shortest wavelength 8 points, rms gradient 0.1,
seed 1), p_m/E* = 0.01, tol 1e-8, n x n points (namelists written to a temporary
directory in /tmp, results to HDF5 files in the same directory). Each run is a
fresh process; "solve" is the summary's solver time (operator, coarse levels, iterations;
no surface synthesis, no output), "process" the wall time of the whole run. The runs of
the thread counts alternate, so that the machine's background load falls on both; the
ratio is of the medians (and of the best runs). On a shared 2-core machine a second
thread competes with whatever else runs: compare with the load average printed.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import tempfile
import time

NAMELIST = """&scene geometry='areal', n={n} /
&layer thickness=Inf, young=1.0, poisson=0.5 /
&profile kind='self_affine', hurst=0.8, seed=1, short_wavelength={short!r}, rms_gradient=0.1 /
&loading control='load', mean_pressure={pressure!r} /
&solver threads={threads}, tol=1e-8 /
&output file='{output}', overwrite=.true. /
"""


def run(exe: str, directory: str, n: int, threads: int) -> dict:
    path = os.path.join(directory, f"areal_{n}_{threads}.nml")
    with open(path, "w") as f:
        f.write(NAMELIST.format(n=n, short=8 / n, pressure=0.01 * 4 / 3, threads=threads,
                                output=os.path.join(directory, f"areal_{n}_{threads}.h5")))
    start = time.perf_counter()
    done = subprocess.run([exe, path], capture_output=True, text=True,
                          env=dict(os.environ, OMP_NUM_THREADS=str(threads)))
    wall = time.perf_counter() - start
    if done.returncode:
        raise RuntimeError(f"{exe} {path}: exit {done.returncode}\n{done.stdout}{done.stderr}")

    def value(key):
        return float(re.search(rf"^\s*{key}\s+(\S+)", done.stdout, re.M).group(1))

    return dict(solve=value("solver time"), process=wall, iterations=int(value("iterations")),
                contact=value("contact fraction"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--exe", default="/tmp/omp-build/layercontact")
    parser.add_argument("--sizes", type=int, nargs="+", default=[1024, 2048])
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"executable: {args.exe}; load average at start: {os.getloadavg()}")
    print("| n | threads | runs | solve median (s) | solve best (s) | process median (s) | it. | contact "
          "| vs 1 thread (median) | vs 1 thread (best) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory(dir="/tmp") as directory:
        for n in args.sizes:
            runs = {t: [] for t in args.threads}
            for _ in range(args.repeats):
                for t in args.threads:
                    runs[t].append(run(args.exe, directory, n, t))
            base = runs[args.threads[0]]
            base_median = statistics.median(r["solve"] for r in base)
            base_best = min(r["solve"] for r in base)
            for t in args.threads:
                solve = [r["solve"] for r in runs[t]]
                median, best = statistics.median(solve), min(solve)
                print(f"| {n}^2 | {t} | {len(solve)} | {median:.2f} | {best:.2f} "
                      f"| {statistics.median(r['process'] for r in runs[t]):.2f} | {runs[t][0]['iterations']} "
                      f"| {runs[t][0]['contact']:.4f} | {median / base_median:.2f} | {best / base_best:.2f} |",
                      flush=True)
    print(f"load average at the end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
