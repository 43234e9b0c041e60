"""Shared helpers for the pytest suite: the contact conditions of a result checked with the
independent numpy operator of reference_operator.py (numpy FFT + the kernel factors), without
going through the Fortran operator.

The kernel factors themselves come from `lc.layer_multipliers`, so these checks test the
operator assembly and the solver, not the kernels: those are tested against mpmath and the
LAPACK mode solve in test_kernels.py.

Also the `slurm_cluster` fixture: a private single-node Slurm for the batch tests
(test_slurm.py)."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

import layercontact as lc
from reference_operator import apply, g_eff  # noqa: F401 (shared with the tests)

ROOT = Path(__file__).resolve().parents[1]


UNIT_BUILD = ROOT / "build" / "unit"


def build_unit_program(name: str) -> tuple[subprocess.CompletedProcess, Path]:
    """Build the Fortran unit-test program tests/fortran/`name` in build/unit (as `make
    unit-tests` does; meson set up there when needed) with this Python's environment's
    meson and ninja; returns ninja's outcome and the program's path."""
    import sys
    env = dict(os.environ, PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
    if not (UNIT_BUILD / "build.ninja").exists():
        subprocess.run(["meson", "setup", str(UNIT_BUILD), "-Dunit_tests=true", "--buildtype=debugoptimized"],
                       cwd=ROOT, env=env, check=True, capture_output=True)
    built = subprocess.run(["ninja", "-C", str(UNIT_BUILD), f"tests/fortran/{name}"], env=env,
                           capture_output=True, text=True)
    return built, UNIT_BUILD / "tests" / "fortran" / name

def first_method(res) -> str:
    """The method a solve started with (the policy's choice): the path's first name. Which
    methods went on after it where it stalled may differ with rounding from one processor
    to another; tests assert the solution, not that path."""
    return res.solver.split("+")[0]


def contact_violation(res: lc.LineResult, thickness: float, young: float, poisson: float, material=None,
                      speed: float = 0.0) -> dict:
    """Contact conditions of a result, recomputed independently: returns the worst
    overlap and the worst gap in contact, both relative to the profile's peak-to-valley,
    and the relative error of the mean pressure."""
    r = res.height
    n = r.size
    w = apply(g_eff(n, res.period, thickness, young, poisson, res.friction, material, speed), res.pressure)
    gap = w - (r - r.max() + res.penetration)
    scale = np.ptp(r)
    contact = res.pressure > 0
    return {
        "overlap": max(0.0, -gap.min()) / scale,
        "gap_in_contact": np.abs(gap[contact]).max() / scale,
        "w_error": np.abs(w - res.displacement_z).max() / np.abs(w).max(),
    }


@pytest.fixture(scope="module")
def rough_profile():
    """A self-affine profile used by several tests (n = 4096, H = 0.8, seed 1)."""
    return lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)


def _free_ports(count: int) -> list[int]:
    """Ports nobody listens on now (held open together, so they differ)."""
    sockets = [socket.socket() for _ in range(count)]
    try:
        for s in sockets:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in sockets]
    finally:
        for s in sockets:
            s.close()


@pytest.fixture(scope="module")
def slurm_cluster():
    """A private single-node Slurm for the tests of a module (tools/local_slurm.sh): Debian's
    slurm-wlm and munge are installed when missing, then munged, slurmctld and slurmd start
    as root with every path under a temporary directory and free ports. Yields the path of
    its slurm.conf (for SLURM_CONF); the daemons are stopped by PID afterwards, and by a
    guard process if pytest dies first. Where it cannot start, the tests that use it
    are skipped, except in CI (CI=true), where that is a failure."""
    script = ROOT / "tools" / "local_slurm.sh"

    def unavailable(reason: str):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"the test Slurm cannot start: {reason}", pytrace=False)
        pytest.skip(f"the test Slurm cannot start: {reason}")

    if os.geteuid() != 0:
        unavailable("it runs its daemons as root")
    if shutil.which("slurmctld") is None and shutil.which("apt-get") is None:
        unavailable("Slurm is not installed and there is no apt-get to install it")
    installed = subprocess.run(["bash", script, "install"], capture_output=True, text=True, timeout=900)
    if installed.returncode != 0:
        unavailable(f"installing it failed: {installed.stderr.strip()}")
    # short: munge's socket path must fit in 108 bytes
    directory = Path(tempfile.mkdtemp(prefix="lc-slurm-"))
    ports = ",".join(map(str, _free_ports(2)))
    try:
        command = ["bash", script, "start", directory, "--ports", ports, "--watch", str(os.getpid())]
        started = subprocess.run(command, capture_output=True, text=True, timeout=120)
        if started.returncode != 0:
            unavailable(started.stderr.strip())
        yield directory / "slurm.conf"
    finally:
        subprocess.run(["bash", script, "stop", directory], capture_output=True, timeout=120)
        shutil.rmtree(directory, ignore_errors=True)

