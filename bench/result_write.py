"""Writing a result file against solving it: the storage of the maps (filters, chunks,
precision), measured on a coupled and a frictionless areal scene (default outputs: the
profile and nine maps each). The numbers behind docs/decisions/020-result-writing.md.

For each scene the executable runs twice (&output precision = 'double' and 'single'): its
solve time (the summary's 'solver time'), its write time (the run's wall time less the
time until the write began, /@run_wall_time: the write, its fsync, the rename) and the
file's size. Then the maps of the double result are written again with h5py under each
storage that h5py reads without plugins (HDF5's built-in filters: deflate, shuffle,
scaleoffset, fletcher32), each file fsynced, and the time is given as a ratio to the
executable's solve time.

    .venv/bin/python bench/result_write.py [--n 2048] [--thickness 0.05] [--scenes coupled frictionless]
        [--dir DIRECTORY] [--executable PROGRAM]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

SCENE = """&scene
   geometry = 'areal'
   n = {n}
/
&layer
   thickness = {thickness}
   poisson = 0.5
/
&friction
   coefficient = {friction}
/
&profile
   kind = 'self_affine'
   hurst = 0.8
   seed = 1
   short_wavelength = 0.0078125
   rms_gradient = 0.1
/
&loading
   normalised_pressure = 0.15
/
&output
   file = 'result.h5'
   overwrite = .true.
   precision = '{precision}'
/
"""

#: storages of the maps written with h5py: (name, dtype, keyword arguments of create_dataset)
ROWS = 65536  # values per chunk: whole rows of about 2**16 values


def storages(nx: int) -> list[tuple[str, type, dict]]:
    rows = (max(1, ROWS // nx), nx)
    return [
        ("contiguous", np.float64, {}),
        ("chunks of rows, no filter", np.float64, dict(chunks=rows)),
        ("deflate 4 (the former default)", np.float64, dict(chunks=rows, compression="gzip", compression_opts=4)),
        ("deflate 1", np.float64, dict(chunks=rows, compression="gzip", compression_opts=1)),
        ("shuffle + deflate 1", np.float64, dict(chunks=rows, shuffle=True, compression="gzip", compression_opts=1)),
        ("shuffle + deflate 1, 256 rows", np.float64,
         dict(chunks=(min(256, nx), nx), shuffle=True, compression="gzip", compression_opts=1)),
        ("scaleoffset 6 digits (lossy)", np.float64, dict(chunks=rows, scaleoffset=6)),
        ("fletcher32 (checksum only)", np.float64, dict(chunks=rows, fletcher32=True)),
        ("single, contiguous", np.float32, {}),
        ("single, shuffle + deflate 1", np.float32,
         dict(chunks=rows, shuffle=True, compression="gzip", compression_opts=1)),
        ("sparse maps shuffle + deflate 1 (the default)", np.float64, "sparse"),
    ]


def executable() -> str:
    found = shutil.which("layercontact", path=str(Path(sys.executable).parent))
    if found is None:
        raise SystemExit("layercontact executable not found next to this Python")
    return found


def run_scene(work: Path, n: int, thickness: float, friction: float, precision: str, program: str) -> dict:
    nml = work / "scene.nml"
    nml.write_text(SCENE.format(n=n, thickness=thickness, friction=friction, precision=precision))
    start = time.perf_counter()
    proc = subprocess.run([program, str(nml)], cwd=work, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode not in (0, 3):
        raise SystemExit(proc.stdout + proc.stderr)
    solve = float(re.search(r"solver time\S*\s+(\S+)", proc.stdout).group(1))
    with h5py.File(work / "result.h5") as f:
        before_write = float(f.attrs["run_wall_time"])
    return dict(solve=solve, write=wall - before_write, size=(work / "result.h5").stat().st_size,
                progress=[line for line in proc.stderr.splitlines() if "writing result file" in line])


def maps_of(path: Path) -> dict[str, np.ndarray]:
    maps = {}
    with h5py.File(path) as f:
        f.visititems(lambda name, obj: maps.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) and obj.ndim == 2 else None)
    return maps


def write_maps(path: Path, maps: dict[str, np.ndarray], dtype, options) -> float:
    start = time.perf_counter()
    with h5py.File(path, "w") as f:
        for name, values in maps.items():
            kwargs = options
            if options == "sparse":
                rows = (max(1, ROWS // values.shape[1]), values.shape[1])
                kwargs = (dict(chunks=rows, shuffle=True, compression="gzip", compression_opts=1)
                          if 2 * np.count_nonzero(values == 0) > values.size else {})
            f.create_dataset(name, data=values.astype(dtype, copy=False), **kwargs)
    descriptor = os.open(path, os.O_RDONLY)
    os.fsync(descriptor)
    os.close(descriptor)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2048)
    parser.add_argument("--thickness", type=float, default=0.05)
    parser.add_argument("--scenes", nargs="+", default=["coupled", "frictionless"])
    parser.add_argument("--dir", default=None, help="where to write (default: a temporary directory)")
    parser.add_argument("--executable", default=None, help="the layercontact program (default: next to this Python)")
    args = parser.parse_args()
    program = args.executable or executable()
    work = Path(tempfile.mkdtemp(dir=args.dir, prefix="result-write-"))
    try:
        for scene in args.scenes:
            friction = 0.5 if scene == "coupled" else 0.0
            print(f"== {scene}: {args.n}^2, h/lambda = {args.thickness}, nu = 0.5, mu_c = {friction}")
            single = run_scene(work, args.n, args.thickness, friction, "single", program)
            double = run_scene(work, args.n, args.thickness, friction, "double", program)
            solve = double["solve"]
            for label, r in (("double", double), ("single", single)):
                print(f"  executable, precision = '{label}': solve {r['solve']:.2f} s, write {r['write']:.2f} s "
                      f"({r['write'] / r['solve']:.0%} of its solve), {r['size'] / 1e6:.1f} MB")
            print("  progress: " + (double["progress"][0] if double["progress"] else "(none)"))
            maps = maps_of(work / "result.h5")
            raw = sum(m.nbytes for m in maps.values())
            print(f"  {len(maps)} maps, {raw / 1e6:.1f} MB in double; each storage written with h5py and fsynced:")
            print(f"  {'storage':48s} {'MB':>8s} {'s':>7s} {'of solve':>9s}")
            for name, dtype, options in storages(maps["profile/height"].shape[1]):
                path = work / "maps.h5"
                seconds = write_maps(path, maps, dtype, options)
                print(f"  {name:48s} {path.stat().st_size / 1e6:8.1f} {seconds:7.2f} {seconds / solve:9.0%}",
                      flush=True)
                path.unlink()
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
