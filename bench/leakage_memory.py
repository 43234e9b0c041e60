"""Peak memory of the compiled leakage (``layercontact.core_leakage``) per cell, n x n cells
for n = 64 .. 1024: the numbers behind ``leakage_bytes`` in src/base/memory.f90.

Each size runs in a fresh process: a random gap with about 21 % of the cells closed, then the
increase of the resident peak (VmHWM) and of the address space peak (VmPeak) over the call.
The first leakage of a process also starts MPI, whose address space (about 196 MiB, with
little of it resident) shows as the fixed part; the slope between the two largest sizes is
the memory per cell (Fortran arrays, hypre's matrix and BoomerAMG hierarchy).

    .venv/bin/python bench/leakage_memory.py [--sizes 64 256 512 1024]
"""

from __future__ import annotations

import argparse
import subprocess
import sys

CHILD = """
import sys
import numpy as np
import layercontact as lc

def status():
    values = {}
    for line in open('/proc/self/status'):
        key, _, value = line.partition(':')
        if key in ('VmPeak', 'VmHWM'):
            values[key] = int(value.split()[0]) * 1024
    return values

n = int(sys.argv[1])
gap = np.ascontiguousarray(np.maximum(np.random.default_rng(1).standard_normal((n, n)) + 0.8, 0.0))
before = status()
lc.core_leakage(gap)
after = status()
print(n, (gap > 0).mean(), after['VmHWM'] - before['VmHWM'], after['VmPeak'] - before['VmPeak'])
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256, 512, 1024])
    sizes = parser.parse_args().sizes
    rows = []
    print(f"{'n':>6} {'open':>6} {'resident MiB':>13} {'address MiB':>12} {'B/cell res.':>12} {'B/cell addr.':>13}")
    for n in sizes:
        out = subprocess.run([sys.executable, "-c", CHILD, str(n)], capture_output=True, text=True, check=True)
        _, open_fraction, resident, address = out.stdout.split()
        rows.append((n, int(resident), int(address)))
        print(f"{n:>6} {float(open_fraction):>6.3f} {int(resident) / 2**20:>13.1f} {int(address) / 2**20:>12.1f} "
              f"{int(resident) / n**2:>12.1f} {int(address) / n**2:>13.1f}")
    if len(rows) >= 2:
        (n0, r0, a0), (n1, r1, a1) = rows[-2], rows[-1]
        cells = n1**2 - n0**2
        print(f"slope between {n0}^2 and {n1}^2: {(r1 - r0) / cells:.0f} B/cell resident, "
              f"{(a1 - a0) / cells:.0f} B/cell address space; fixed address space at n = {rows[0][0]}: "
              f"{rows[0][2] / 2**20:.0f} MiB")


if __name__ == "__main__":
    main()
