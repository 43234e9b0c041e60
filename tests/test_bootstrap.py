"""tools/bootstrap.sh as a normal user: where the build's libraries are found (pkg-config,
the compilers, hypre's headers and library) it builds without calling dpkg, apt-get or sudo;
where something is missing and apt-get cannot be used it stops and lists what is missing.

The bootstrap runs on a copy of the repository as the unprivileged user 65534 (nobody), with
fake dpkg, apt-get and sudo first on PATH: each records its call and fails."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the user the bootstrap runs as (nobody on Debian)
USER = 65534
#: what a copy of the repository leaves out: builds, environments, results
SKIP = shutil.ignore_patterns(".git", ".venv", "build", "out", "__pycache__", "*.h5", ".pytest_cache")


def as_user() -> list[str]:
    """The command prefix that runs a program as USER (nothing if this process is not root)."""
    if os.geteuid() != 0:
        return []
    if shutil.which("setpriv") is None:
        pytest.skip("running as root and setpriv is missing: no way to drop privileges")
    return ["setpriv", f"--reuid={USER}", f"--regid={USER}", "--clear-groups"]


def python_for_user() -> str | None:
    """An interpreter of this Python's version that USER may run: the system's, or this one
    (which may live where only root reads, as under /root/.pyenv); None if none."""
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    for candidate in (f"/usr/bin/python{version}", f"/usr/local/bin/python{version}", os.path.realpath(sys.executable)):
        if not os.path.exists(candidate):
            continue
        check = subprocess.run([*as_user(), candidate, "-c", "import sys; print(sys.version_info[:2])"],
                               capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"})
        # (and may test it: bash's `test -x` is what the bootstrap asks)
        test = subprocess.run([*as_user(), "test", "-x", candidate])
        if check.returncode == test.returncode == 0 and check.stdout.strip() == str(sys.version_info[:2]):
            return candidate
    return None


@pytest.fixture
def workspace():
    """A directory USER owns (under /tmp: pytest's own is private to root), with the copy of
    the repository, a home and the fake package managers; removed afterwards."""
    top = Path(tempfile.mkdtemp(prefix="layercontact-bootstrap-"))
    try:
        repo = top / "repo"
        shutil.copytree(ROOT, repo, ignore=SKIP, symlinks=True)
        (top / "home").mkdir()
        fake = top / "fake-bin"
        fake.mkdir()
        calls = top / "calls.log"
        calls.touch()
        for tool in ("dpkg", "apt-get", "sudo"):
            script = fake / tool
            script.write_text(f'#!/bin/sh\necho "{tool} $*" >> "{calls}"\nexit 1\n')
            script.chmod(0o755)
        if os.geteuid() == 0:
            subprocess.run(["chown", "-R", f"{USER}:{USER}", str(top)], check=True)
            top.chmod(0o755)
        yield top
    finally:
        shutil.rmtree(top, ignore_errors=True)


def environment(top: Path, **extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env.update(PATH=f"{top / 'fake-bin'}:{env.get('PATH', '/usr/bin:/bin')}", HOME=str(top / "home"),
               XDG_CACHE_HOME=str(top / "home" / ".cache"), TMPDIR=str(top / "home"))
    env.update(extra)
    return env


def test_bootstrap_builds_as_a_normal_user_without_package_managers(workspace):
    """All libraries are installed here (CI installs them as Debian packages): the bootstrap
    builds as nobody and calls none of dpkg, apt-get, sudo; the executable it built then
    solves Westergaard's problem as the closed form says."""
    repo = workspace / "repo"
    env = environment(workspace)
    python = python_for_user()
    if sys.prefix != sys.base_prefix and python is not None:
        # The running environment as the copy's .venv, on an interpreter of the same version
        # that the user may run, so that the build downloads only what pip's build isolation
        # asks for (the test tools are there already).
        venv = repo / ".venv"
        subprocess.run(["cp", "-a", sys.prefix, str(venv)], check=True)
        (venv / ".layercontact-installed").unlink(missing_ok=True)
        for link in ("python", "python3", f"python3.{sys.version_info.minor}"):
            (venv / "bin" / link).unlink(missing_ok=True)
            (venv / "bin" / link).symlink_to(python)
        config = (venv / "pyvenv.cfg").read_text().splitlines()
        config = [f"home = {Path(python).parent}" if line.startswith("home") else line for line in config
                  if not line.startswith(("executable", "command"))]
        (venv / "pyvenv.cfg").write_text("\n".join(config) + "\n")
        if os.geteuid() == 0:
            subprocess.run(["chown", "-R", f"{USER}:{USER}", str(venv)], check=True)
    elif python is not None:
        env["PYTHON"] = python
    proc = subprocess.run([*as_user(), "bash", "tools/bootstrap.sh"], cwd=repo, env=env,
                          capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (workspace / "calls.log").read_text() == "", "a package manager was called"
    assert (repo / ".venv" / ".layercontact-installed").exists()

    run = subprocess.run([*as_user(), ".venv/bin/layercontact", "inputs/westergaard.nml"], cwd=repo,
                         env=environment(workspace), capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    with h5py.File(repo / "out" / "westergaard.h5") as f:
        fraction = float(f["results"].attrs["contact_fraction"])
    # p_m/p* = 1/4: 2a/lambda = (2/pi) asin(1/2) = 1/3; the grid resolves the contact's two
    # edges to a grid spacing each: 2/2048
    assert fraction == pytest.approx(2 / math.pi * math.asin(0.5), abs=2 / 2048)


def test_bootstrap_lists_what_is_missing_where_apt_cannot_be_used(workspace):
    """With pkg-config finding nothing, FFTW and LAPACK are missing (HDF5 and MPI are still
    found by their compiler wrappers); as nobody, with sudo failing, the bootstrap stops
    with exit 1 before any build, naming them, the Debian packages and modules, and never
    calls apt-get or dpkg."""
    repo = workspace / "repo"
    env = environment(workspace, PKG_CONFIG_PATH="", PKG_CONFIG_LIBDIR=str(workspace / "nowhere"))
    proc = subprocess.run([*as_user(), "bash", "tools/bootstrap.sh"], cwd=repo, env=env, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "apt-get cannot be used" in proc.stderr
    assert "- FFTW 3: fftw3.pc in PKG_CONFIG_PATH (module load fftw)" in proc.stderr
    assert "- LAPACK:" in proc.stderr and "HDF5" not in proc.stderr and "hypre" not in proc.stderr
    assert "apt-get install libfftw3-dev liblapack-dev libopenblas-dev" in proc.stderr
    assert "docs/clusters.md" in proc.stderr
    calls = (workspace / "calls.log").read_text().splitlines()
    assert all(line.startswith("sudo -n true") for line in calls), calls
    assert not (repo / ".venv").exists()
