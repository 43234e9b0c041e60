"""The multigrid method on a surface shared among the ranks of an MPI job
(docs/decisions/028-distributed-multigrid.md): `mpirun -n P layercontact scene.nml` iterates
its finest grid on the slabs (each rank its rows; the coarse grids whole on every rank) and
gives the serial run's answer in the serial run's iterations, by name and where 'auto' plans
it as it does on one process.

The oracle is the serial run of the same scene (no launcher). What differs from it is the
rounding of the profile (made on the slabs by FFTW-MPI's c2r), of the transforms on the
slabs and of every sum the iteration takes over the ranks (the energies, line searches,
CG and GCR products, the restriction's shares of the first coarse grid). Both solves run to
tol = 1e-12 (the complementarity residual relative to p_m and the relief); two solutions
that close to the unique one agree to about that, so SAME = 1e-10 relative (test_mpi.py) is
met with two decades to spare (measured: 3e-15 to 4e-14) and fails on a sum left on one
rank (the ranks would take different steps and the transforms would mix them) or a
symbol read at the wrong modes (another operator: another answer). A preconditioner gone
wrong still reaches the unique answer, in the same or more iterations: the slabs'
preconditioner, stiffness and interpolation are checked against the whole grid's by
tests/fortran/test_multigrid_slabs.f90, run here under mpirun (a share of the restriction
moved to the wrong coarse row fails it on 2 and 3 ranks).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import h5py
import pytest

from conftest import build_unit_program
from test_mpi import assert_same, executable, launcher_env, needs_mpi, run_mpi, run_serial

#: a standard linear solid sliding on a thin incompressible layer with friction whose loss
#: among the waves short along x exceeds 3 (E_inf/E0 = 100 at V tau/lambda = 0.1, h/lambda =
#: 0.16): serially 'auto' takes the multigrid method from 128^2 (test_multigrid.py,
#: "lossy among its short waves")
SLIDING = ("&layer thickness = 0.16, poisson = 0.5 /\n"
           "&material model = 'sls', e0 = 1.0, e_inf = 100.0, tau = 1.0, speed = 0.1 /\n"
           "&friction coefficient = 0.5 /\n"
           "&loading control = 'load', mean_pressure = 0.02 /\n")
#: a compressible layer, frictionless (the symmetric multigrid) and with friction (the
#: coupled form), both under &solver method = 'multigrid'
ELASTIC = "&layer thickness = 0.16, poisson = 0.3 /\n&loading control = 'load', normalised_pressure = 0.15 /\n"
SCENES = {
    "sliding": (128, SLIDING + "&solver method = 'multigrid', tol = 1e-12 /\n"),
    "frictionless": (64, ELASTIC + "&friction coefficient = 0.0 /\n&solver method = 'multigrid', tol = 1e-12 /\n"),
    "coupled": (64, ELASTIC + "&friction coefficient = 0.5 /\n&solver method = 'multigrid', tol = 1e-12 /\n"),
}


def write_scene(directory: Path, name: str, n: int, body: str, output: str) -> Path:
    nml = directory / f"{name}.nml"
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n" + body +
        f"&profile kind = 'self_affine', hurst = 0.8, seed = 1, short_wavelength = {8 / n}, rms_gradient = 0.1 /\n"
        f"&output file = '{output}', overwrite = .true., stress = .false. /\n")
    return nml


def counts(path: Path) -> tuple[str, int, int]:
    with h5py.File(path, "r") as f:
        attrs = f["results"].attrs
        solver = attrs["solver"]
        return (solver.decode() if isinstance(solver, bytes) else str(solver)), int(attrs["iterations"]), \
            int(attrs["fft_pairs"])


@needs_mpi
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_the_distributed_multigrid_gives_the_serial_answer(scene, tmp_path):
    """P = 1..4 ranks (3 splits the rows unevenly, and a slab of P = 3 starts on an even row
    and ends on an odd one): every field and scalar of the serial run, the same methods in
    turn (the `solver` path, compared as a string), the multigrid first; the serial run's
    iteration count (the same iteration, its sums rounded in another order); and, on several
    ranks, the reason saying the finest grid was on the slabs."""
    n, body = SCENES[scene]
    done = run_serial(write_scene(tmp_path, scene, n, body, "serial.h5"))
    assert done.returncode == 0, done.stderr
    serial = counts(tmp_path / "serial.h5")
    assert serial[0].startswith("multigrid"), serial
    for ranks in (1, 2, 3, 4):
        out = f"ranks{ranks}.h5"
        done = run_mpi(ranks, [executable(), str(write_scene(tmp_path, f"{scene}{ranks}", n, body, out))], tmp_path)
        assert done.returncode == 0, done.stderr
        assert_same(tmp_path / "serial.h5", tmp_path / out)
        distributed = counts(tmp_path / out)
        print(scene, ranks, "serial", serial, "distributed", distributed)
        assert distributed[:2] == serial[:2], (serial, distributed)
        with h5py.File(tmp_path / out, "r") as f:
            assert int(f["results"].attrs["mpi_ranks"]) == ranks
            if ranks > 1:
                assert "its finest grid on the slabs" in f["results"].attrs["solver_reason"].decode()


@needs_mpi
@pytest.mark.parametrize("ranks", [2, 3])
def test_auto_plans_the_multigrid_on_a_shared_surface_as_on_one_process(ranks, tmp_path):
    """The sliding scene that 'auto' sends to the multigrid method on one process (its loss
    among the short waves, measured on the ranks' modes over the ranks): on two
    and three ranks 'auto' plans it too, says the finest grid is on the slabs, and gives the
    serial answer (SAME) in the serial run's iterations. (Its transform pairs may differ by a
    few: the coarse start runs on the slabs with its own sums.)"""
    n, body = SCENES["sliding"]
    body = body.replace("method = 'multigrid', ", "")
    assert run_serial(write_scene(tmp_path, "serial", n, body, "serial.h5")).returncode == 0
    serial = counts(tmp_path / "serial.h5")
    assert serial[0].startswith("multigrid"), serial
    done = run_mpi(ranks, [executable(), str(write_scene(tmp_path, "ranks", n, body, "ranks.h5"))], tmp_path)
    assert done.returncode == 0, done.stderr
    distributed = counts(tmp_path / "ranks.h5")
    print("auto", ranks, "serial", serial, "distributed", distributed)
    assert distributed[:2] == serial[:2], (serial, distributed)
    with h5py.File(tmp_path / "ranks.h5", "r") as f:
        reason = f["results"].attrs["solver_reason"].decode()
    assert "loss among the short waves" in reason and "its finest grid on the slabs" in reason, reason
    assert_same(tmp_path / "serial.h5", tmp_path / "ranks.h5")


#: a standard linear solid sliding with a moderate loss (E_inf/E0 = 10, V tau/lambda = 0.1,
#: h/lambda = 0.16, nu = 0.5, mu_c = 0.5): below the loss among the short waves that sends
#: SLIDING to the multigrid method at 128^2 (the GCR); at 512^2 its coarse start is hard and
#: the multigrid method smooths it by rows where the GCR is slow (rule 3b, rows_ahead_of_gcr)
MODERATE = SLIDING.replace("e_inf = 100.0", "e_inf = 10.0")
#: a frictionless incompressible layer (nu = 0.5): h/lambda = 0.05 rises too steeply for the
#: symmetric multigrid method (whether the coupled form admits it is measured only after a
#: hard start, and compared bit for bit by test_the_policy_measures_the_slabs_as_the_whole_grid)
THIN = "&layer thickness = 0.05, poisson = 0.5 /\n&loading control = 'load', normalised_pressure = 0.15 /\n"
#: under 'auto': the grid, the scene, the method it takes first serially and what its reason
#: says of the measures; both sides of each threshold the measures on the slabs decide
PLANS = {
    "lossy": (128, SLIDING, "multigrid", "loss among the short waves is"),
    "moderate loss": (128, MODERATE, "gcr", "a coupled operator"),
    "rows ahead": (512, MODERATE, "multigrid", "smooths by rows"),
    "rising": (64, THIN, "cg", "rises too steeply for the symmetric multigrid method"),
    "coupled, rising": (64, THIN + "&friction coefficient = 0.5 /\n", "gcr", "a coupled operator"),
    "compressible": (64, ELASTIC, "cg", "a symmetric operator: the constrained CG"),
}


def plan(path: Path) -> tuple[str, str]:
    """The method a run took first and the policy's reason, without what a shared surface adds
    where the multigrid method runs (where its grids are)."""
    with h5py.File(path, "r") as f:
        attrs = f["results"].attrs
        reason = attrs["solver_reason"].decode()
        solver = attrs["solver"].decode()
    for added in (" (its finest grid on the slabs, its coarse grids whole on every rank)",
                  " (the grid gathered whole onto every rank)"):
        reason = reason.replace(added, "")
    return solver.split("+")[0], reason


@needs_mpi
@pytest.mark.parametrize("scene", sorted(PLANS))
def test_auto_plans_a_shared_surface_as_one_process(scene, tmp_path):
    """On P = 2, 3, 4 ranks 'auto' takes the serial run's first method for the serial run's
    reason, word for word: the measures of the slabs (the compliance's rise; the loss among
    the short waves, quoted; whether rows smooth a hard coupled surface), each on the
    rank's modes and reduced over the ranks, decide as the whole grid's. The scenes lie on
    both sides of each threshold: the loss 3 among the short waves (lossy, moderate), the
    rows' rule from 512^2 (rows ahead), the rise 4 (rising), and the plain cases (coupled,
    compressible). The 512^2 scene runs on
    2 ranks only (its solve takes seconds a run)."""
    n, body, first, said = PLANS[scene]
    body += "&solver tol = 1e-6 /\n"
    assert run_serial(write_scene(tmp_path, "serial", n, body, "serial.h5")).returncode == 0
    serial = plan(tmp_path / "serial.h5")
    assert serial[0] == first and said in serial[1], serial
    for ranks in (2,) if n > 128 else (2, 3, 4):
        out = f"ranks{ranks}.h5"
        nml = write_scene(tmp_path, f"ranks{ranks}", n, body, out)
        done = run_mpi(ranks, [executable(), str(nml)], tmp_path)
        assert done.returncode == 0, done.stderr
        assert plan(tmp_path / out) == serial, (ranks, serial, plan(tmp_path / out))


@pytest.fixture(scope="module")
def policy_program() -> Path:
    """tests/fortran/test_policy_slabs, built in build/unit when needed."""
    built, program = build_unit_program("test_policy_slabs")
    assert built.returncode == 0 and program.exists(), built.stdout[-2000:]
    return program


@needs_mpi
@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_the_policy_measures_the_slabs_as_the_whole_grid(ranks, policy_program):
    """The policy's measures on the slabs against the whole grid's on every rank
    (tests/fortran/test_policy_slabs.f90): the compliance's rise, the loss profile and its
    peak, the smoothing factors of the real and the complex symbol, the refusals and the
    policy's indicators, bit for bit."""
    done = subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), str(policy_program)],
                          capture_output=True, text=True, env=launcher_env(), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("checks passed") == ranks
    assert "FAIL" not in done.stdout


@needs_mpi
@pytest.mark.parametrize("method", ["newton"])
def test_serial_methods_are_refused_by_name_on_several_ranks(method, tmp_path):
    """The method that runs on one rank only (dense Newton): exit 2 with a message naming
    the method and the methods a distributed surface takes, the multigrid among them; no
    result file."""
    n, body = SCENES["frictionless"]
    body = body.replace("method = 'multigrid'", f"method = '{method}'")
    done = run_mpi(2, [executable(), str(write_scene(tmp_path, method, n, body, "refused.h5"))], tmp_path)
    assert done.returncode == 2, done.stderr
    message = done.stderr + done.stdout
    assert f"method = '{method}' runs on one MPI rank" in message and "'multigrid'" in message, message
    assert not (tmp_path / "refused.h5").exists()


@pytest.fixture(scope="module")
def slabs_program() -> Path:
    """tests/fortran/test_multigrid_slabs, built in build/unit when needed."""
    built, program = build_unit_program("test_multigrid_slabs")
    assert built.returncode == 0 and program.exists(), built.stdout[-2000:]
    return program


@needs_mpi
@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_the_slabs_precondition_as_the_whole_grid(ranks, slabs_program):
    """The hierarchy on the slabs against the whole grid's on every rank
    (tests/fortran/test_multigrid_slabs.f90): B r, K x and x.K x, the interpolation onto the
    slab, for a real symbol, a complex one, and one smoothed by rows, and the GCR's
    orthogonalisation in one message against the whole grid's Gram-Schmidt, to 1e-12."""
    done = subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), str(slabs_program)], capture_output=True,
                          text=True, env=launcher_env(), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("checks passed") == ranks
    assert "FAIL" not in done.stdout
