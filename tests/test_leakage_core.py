"""The Reynolds leakage computed by the core (&output leakage, lc.core_leakage): exact
layered solutions, blocked flow, agreement with the Python reynolds_leakage on the same gap
(synthetic and an areal result's), the /leakage group of the result file, and runs in a
sweep's worker processes."""

from pathlib import Path

import h5py
import numpy as np
import pytest

import layercontact as lc
from test_inputs import run_exe
from test_leakage import random_gap

# Closed forms reached without a linear solve (a uniform gap, flow along stripes: the
# right-hand side vanishes) or by a direct solve: rounding only.
EXACT = 1e-12
# CG stopped at tol = 1e-12 on k_eff: its energy-error estimate lags a few iterations, so
# allow two orders above it (as the Python solver's tests do).
ITERATIVE = 1e-10


def test_uniform_gap_is_g_cubed_both_ways():
    g = 0.37
    res = lc.core_leakage(np.full((6, 10), g), period=(2.0, 0.5))
    assert res.k_eff_x == pytest.approx(g**3, rel=EXACT)
    assert res.k_eff_y == pytest.approx(g**3, rel=EXACT)
    assert res.percolating_x and res.percolating_y and res.converged
    assert res.fluid_fraction == 1.0 and res.connected_fraction_x == 1.0 == res.connected_fraction_y
    # one cell pinned: the other 59 are unknowns
    assert res.unknowns_x == res.unknowns_y == 59


def test_stripes_give_the_arithmetic_and_harmonic_means():
    # g depends on y only: flow along x sees parallel channels (arithmetic mean of g^3),
    # flow along y the same channels in series (harmonic mean)
    stripes = np.random.default_rng(4).uniform(0.2, 2.0, 24)
    gap = np.tile(stripes[:, None], (1, 16))
    res = lc.core_leakage(gap, tol=1e-12)
    assert res.k_eff_x == pytest.approx(np.mean(stripes**3), rel=EXACT)
    assert res.k_eff_y == pytest.approx(1 / np.mean(1 / stripes**3), rel=ITERATIVE)
    # (the energy stop at tol 1e-12 leaves the relative residual near sqrt(tol) = 1e-6)
    assert res.converged and res.residual_y < 1e-5


def test_a_contact_line_blocks_the_flow_across_it():
    g = np.full((12, 20), 0.5)
    g[:, 7] = 0.0  # a contact stripe across the whole cell at x = 7/20
    res = lc.core_leakage(g)
    assert res.k_eff_x == 0.0 and not res.percolating_x and res.connected_fraction_x == 0.0
    assert res.iterations_x == 0 and res.unknowns_x == 0
    assert res.percolating_y and res.k_eff_y == pytest.approx(0.5**3 * 19 / 20, rel=EXACT)
    assert res.fluid_fraction == pytest.approx(19 / 20)


@pytest.mark.parametrize("contact_fraction, seed", [(0.25, 1), (0.45, 2)])
def test_agrees_with_the_python_solver(contact_fraction, seed):
    # a correlated random gap on a non-square cell, up to near percolation (0.45)
    g = random_gap((96, 80), contact_fraction, seed=seed)
    period = (2.0, 1.5)
    core = lc.core_leakage(g, period=period, tol=1e-12)
    tight = lc.core_leakage(g, period=period)  # default tol = 1e-6 on k_eff
    for d in ("x", "y"):
        ref = lc.reynolds_leakage(g, period=period, direction=d, method="direct")
        k = getattr(core, f"k_eff_{d}")
        assert getattr(core, f"percolating_{d}") == ref.percolating
        assert getattr(core, f"connected_fraction_{d}") == ref.connected_fraction
        assert k == pytest.approx(ref.k_eff, rel=ITERATIVE, abs=1e-300)
        # the dissipation is an upper bound, within tol of the converged value
        k_default = getattr(tight, f"k_eff_{d}")
        assert ref.k_eff * (1 - EXACT) <= k_default <= ref.k_eff * (1 + 1e-6)
    assert core.fluid_fraction == pytest.approx(1 - contact_fraction, abs=1 / g.size)


def test_a_gap_that_percolates_along_neither_axis():
    g = np.full((16, 16), 0.2)
    g[4, :] = 0.0
    g[:, 9] = 0.0  # a closed cross: four-sided pockets only
    res = lc.core_leakage(g)
    assert (res.k_eff_x, res.k_eff_y) == (0.0, 0.0)
    assert not res.percolating_x and not res.percolating_y
    assert res.fluid_fraction == pytest.approx(225 / 256)


AREAL = """\
&scene
   geometry = 'areal'
   n = 64
/
&layer
   thickness = 0.1
   poisson = 0.5
/
&friction
   coefficient = 0.5
/
&profile
   kind = 'self_affine'
   seed = 3
   short_wavelength = 0.125
   rms_gradient = 0.1
/
&loading
   normalised_pressure = 0.3
/
&solver
   tol = 1e-10
/
"""


def write_scene(directory: Path, leakage: bool = True, name: str = "leak") -> Path:
    nml = directory / f"{name}.nml"
    extra = " leakage = .true.\n leakage_tol = 1e-12\n" if leakage else ""
    nml.write_text(AREAL + f"&output\n file = '{name}.h5'\n{extra}/\n")
    return nml


def test_result_file_holds_the_leakage_of_its_gap(tmp_path, monkeypatch):
    proc = run_exe(write_scene(tmp_path), tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "leakage k_eff along x" in proc.stdout and "leakage k_eff along y" in proc.stdout
    res = lc.read_result(tmp_path / "leak.h5")
    leak = res.leakage
    assert leak.converged and leak.solver == "cg + hypre BoomerAMG" and leak.tol == 1e-12
    assert 0.1 < res.contact_fraction < 0.4 and leak.percolating_x and leak.percolating_y
    # the same gap and contact through the Python solver (direct): the core stops at
    # leakage_tol = 1e-12 on k_eff
    for d in ("x", "y"):
        ref = lc.reynolds_leakage(res.gap, period=res.period, direction=d, contact=res.pressure > 0,
                                  method="direct")
        assert getattr(leak, f"k_eff_{d}") == pytest.approx(ref.k_eff, rel=ITERATIVE)
        assert getattr(leak, f"connected_fraction_{d}") == ref.connected_fraction
    assert leak.fluid_fraction == pytest.approx(1 - res.contact_fraction)
    # sliding along x makes the gap anisotropic: the two conductances differ
    assert abs(leak.k_eff_x / leak.k_eff_y - 1) > 1e-3
    with h5py.File(tmp_path / "leak.h5") as f:
        assert "k_eff_x L^3" in f["leakage"].attrs["units"].decode()
    # lc.run is the same library routine: the same numbers
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(lc.api, "_core", lc.native.portable)
    again = lc.run(write_scene(tmp_path, name="again"))
    assert again.leakage.k_eff_x == pytest.approx(leak.k_eff_x, rel=ITERATIVE)


def test_no_leakage_unless_asked(tmp_path):
    proc = run_exe(write_scene(tmp_path, leakage=False), tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "leakage k_eff" not in proc.stdout
    assert lc.read_result(tmp_path / "leak.h5").leakage is None
    with h5py.File(tmp_path / "leak.h5") as f:
        assert "leakage" not in f


def test_sweep_workers_compute_the_leakage(tmp_path, monkeypatch):
    # two scenes in two worker processes, each starting MPI for hypre on its own
    sweep = tmp_path / "s.nml"
    base = AREAL.replace("&solver\n   tol = 1e-10\n/\n", "&solver\n   tol = 1e-8\n/\n")
    sweep.write_text(base + "&output\n leakage = .true.\n/\n"
                     "&sweep\n directory = 'out/s'\n processes = 2\n normalised_pressure = 0.1, 0.3\n/\n")
    monkeypatch.chdir(tmp_path)
    rows = lc.sweep(sweep, progress=False)
    assert len(rows) == 2 and all(row["error"] == "" for row in rows)
    k = [lc.read_result(tmp_path / row["result_file"]).leakage.k_eff_x for row in rows]
    # a larger load closes the gap: less leakage
    assert k[0] > k[1] > 0
    assert [row["leakage_k_eff_x"] for row in rows] == k


# ---------------------------------------------------------------------------------------
# memory: the leakage's needs are in the memory check (exit 5 / code 5, never a crash)

def _address_space(gib: float):
    """A preexec_fn: the child may map at most ``gib`` GiB (ulimit -v)."""
    import resource

    def limit():
        size = int(gib * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (size, size))
    return limit


#: A frictionless 1024^2 scene with the leakage: its solve fits in 586 MiB of address
#: space, its leakage (about 0.6 GiB with MPI's start) does not.
LEAKY_1024 = (AREAL.replace("n = 64", "n = 1024").replace("coefficient = 0.5", "coefficient = 0.0")
              .replace("tol = 1e-10", "tol = 1e-8") + "&output\n file = 'leak.h5'\n leakage = .true.\n/\n")


def test_a_leakage_too_large_for_the_memory_ends_with_code_5_before_the_solve(tmp_path):
    """1024^2 cells with the leakage under ulimit -v 600000 (586 MiB), a scene whose solve
    fits: the leakage's needs (36 doubles per cell, and the address space that starting MPI
    maps) are checked before the solve, so the run ends at once with exit 5 and a message,
    no result and no crash (it used to solve, then die in the leakage with SIGSEGV)."""
    import subprocess
    import time

    from test_inputs import executable

    nml = tmp_path / "leak.nml"
    nml.write_text(LEAKY_1024)
    start = time.monotonic()
    proc = subprocess.run([executable(), str(nml)], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                          preexec_fn=_address_space(600000 / 2**20))
    assert proc.returncode == 5, proc.stderr
    assert "not enough memory: the leakage of 1048576 cells needs about" in proc.stderr
    assert "the address space limit (ulimit -v)" in proc.stderr and "&output leakage = .false." in proc.stderr
    assert time.monotonic() - start < 30   # before the solve (about 20 s here)
    assert not (tmp_path / "leak.h5").exists() and not list(tmp_path.glob("*.tmp"))


def test_python_raises_code_5_for_a_leakage_too_large_and_lives_on(tmp_path):
    """lc.core_leakage of 8192^2 cells under 3 GiB and lc.run of the 1024^2 leakage scene
    under 900 MiB raise LayercontactError with code 5; the interpreter goes on and ends
    normally."""
    import subprocess
    import sys

    (tmp_path / "leak.nml").write_text(LEAKY_1024)
    cases = ((3.0, "lc.core_leakage(np.ones((8192, 8192)))", "the leakage of 67108864 cells"),
             (900 / 1024, "lc.run('leak.nml')", "the leakage of 1048576 cells"))
    for limit, call, words in cases:
        script = (
            "import numpy as np, layercontact as lc\n"
            f"try:\n    {call}\nexcept lc.LayercontactError as err:\n    print(err.code, err)\n"
            "print(lc.core_leakage(np.ones((8, 8))).k_eff_x)\n"
        )
        proc = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True,
                              timeout=600, preexec_fn=_address_space(limit))
        assert proc.returncode == 0, proc.stdout + proc.stderr
        first, last = proc.stdout.splitlines()[0], proc.stdout.splitlines()[-1]
        assert first.startswith(f"5 not enough memory: {words} needs about"), proc.stdout
        assert float(last) == pytest.approx(1.0)   # a uniform gap of 1: k_eff = g^3
        assert not (tmp_path / "leak.h5").exists()


#: A child Python: a striped gap of n x n cells (g along y only: the closed forms above),
#: then, under a soft address-space limit of `extra` bytes above what the process maps by
#: then, lc.core_leakage; after it the limit is lifted and a small leakage computed, to show
#: the interpreter lives on. Prints "ok k_x k_y" or "error CODE MESSAGE", then "after K".
OUT_OF_MEMORY_CHILD = """
import resource, sys
import numpy as np
import layercontact as lc

n, extra = int(sys.argv[1]), int(sys.argv[2])
stripes = 1.0 + 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
gap = np.ascontiguousarray(np.tile(stripes[:, None], (1, n)))
mapped = next(int(line.split()[1]) * 1024 for line in open('/proc/self/status') if line.startswith('VmSize:'))
soft, hard = resource.getrlimit(resource.RLIMIT_AS)
resource.setrlimit(resource.RLIMIT_AS, (mapped + extra, hard))
try:
    res = lc.core_leakage(gap, tol=1e-8)
    print('ok', repr(res.k_eff_x), repr(res.k_eff_y))
except lc.LayercontactError as err:
    print('error', err.code, err)
resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
small = np.tile((1.0 + 0.5 * np.cos(2 * np.pi * np.arange(16) / 16))[:, None], (1, 16))
print('after', repr(lc.core_leakage(small, tol=1e-12).k_eff_y))
"""


def test_a_leakage_that_runs_out_of_memory_raises_code_5_at_every_limit():
    """lc.core_leakage of 1024^2 striped cells under address-space limits from 100 MiB to
    1.2 GiB above what the process maps: each call raises LayercontactError code 5 (before
    it allocates, or when an allocation of its own or of hypre's fails) or gives the closed
    forms; the interpreter never crashes and computes on afterwards. Some limits fall
    between the check before the leakage and what it allocates: there the allocations'
    own checks end it."""
    import subprocess
    import sys

    def harmonic(rows):
        stripes = 1.0 + 0.5 * np.cos(2 * np.pi * np.arange(rows) / rows)
        return 1 / np.mean(1 / stripes**3)

    n = 1024
    stripes = 1.0 + 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    outcomes = {}
    for mib in (100, 300, 450, 500, 550, 600, 650, 700, 800, 1200):
        proc = subprocess.run([sys.executable, "-c", OUT_OF_MEMORY_CHILD, str(n), str(mib * 2**20)],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, f"{mib} MiB: exit {proc.returncode}\n{proc.stdout}{proc.stderr}"
        first, last = proc.stdout.splitlines()[0], proc.stdout.splitlines()[-1]
        # the small gap's flow across its stripes, by hypre again: the harmonic mean
        assert float(last.split()[1]) == pytest.approx(harmonic(16), rel=ITERATIVE), f"{mib} MiB"
        if first.startswith("ok"):
            k_x, k_y = map(float, first.split()[1:])
            assert k_x == pytest.approx(np.mean(stripes**3), rel=EXACT)
            # CG stopped at tol = 1e-8 on k_eff (an upper bound): 1e-8 above, with rounding
            assert k_y == pytest.approx(harmonic(n), rel=1e-7)
            outcomes[mib] = "ok"
        else:
            assert first.startswith("error 5 not enough memory: the leakage"), f"{mib} MiB: {first}"
            outcomes[mib] = "allocation" if "could not allocate" in first else "check"
    assert outcomes[100] == "check" and outcomes[1200] == "ok", outcomes
    assert "allocation" in outcomes.values(), outcomes


def test_a_leakage_leaves_tmpdir_as_it_found_it(tmp_path):
    """A run with the leakage (the executable) and lc.core_leakage in a Python process, with
    TMPDIR a fresh directory holding another process's Open MPI temporary files: afterwards it
    holds those files only, as they were; the leakage is the closed form's."""
    import subprocess
    import sys

    from test_inputs import executable

    tmpdir = tmp_path / "tmp"
    other = tmpdir / "ompi.host.0" / "pid.1"
    other.mkdir(parents=True)
    (other / "contact.txt").write_text("another process's temporary file\n")
    before = sorted(str(p.relative_to(tmpdir)) for p in tmpdir.rglob("*"))
    env = dict(__import__("os").environ, TMPDIR=str(tmpdir))

    (tmp_path / "leak.nml").write_text(AREAL + "&output\n file = 'leak.h5'\n leakage = .true.\n/\n")
    run = subprocess.run([executable(), "leak.nml"], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert lc.read_result(tmp_path / "leak.h5").leakage.k_eff_x > 0
    assert sorted(str(p.relative_to(tmpdir)) for p in tmpdir.rglob("*")) == before

    # stripes along x: the flow across them needs hypre, and so starts MPI
    stripes = np.random.default_rng(4).uniform(0.2, 2.0, 24)
    script = ("import numpy as np, layercontact as lc\n"
              f"gap = np.tile(np.array({stripes.tolist()!r})[:, None], (1, 16))\n"
              "print(repr(lc.core_leakage(gap, tol=1e-12).k_eff_y))\n")
    proc = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert float(proc.stdout) == pytest.approx(1 / np.mean(1 / stripes**3), rel=ITERATIVE)
    assert sorted(str(p.relative_to(tmpdir)) for p in tmpdir.rglob("*")) == before
    assert (other / "contact.txt").read_text() == "another process's temporary file\n"
