"""One solve on several threads (&solver threads, docs/decisions/022-threads.md): the
thread count a solve takes when none is given (OMP_NUM_THREADS, SLURM_CPUS_PER_TASK, the
process's affinity mask), and the same answers on one thread and on two.

The oracle of the second group is the single-threaded solve itself. The passes over the
grid add their sums in blocks of a fixed size, in order, and FFTW's threads split the
transforms' independent rows and columns, so the fields and scalars agree to rounding at
most; SAME (1e-10 relative, against the field's largest value) leaves room for a
threaded library reordering a sum, far below any solver tolerance used here (1e-8).
The grids have at least 256 x 256 points: passes over fewer than lc_base_threads'
parallel_points (32768) run on one thread, and a 1024 x 1024 grid takes the two-pass
transform whose column blocks are shared out among the threads.
"""

from __future__ import annotations

import os
import resource

import h5py
import numpy as np
import pytest

import layercontact as lc

#: relative agreement of one and two threads (see the module docstring)
SAME = 1e-10


def openmp_build() -> bool:
    """True if this build runs a solve on several threads (a request of 2 is refused otherwise)."""
    try:
        lc.solve_line(np.cos(2 * np.pi * np.arange(64) / 64), mean_pressure=0.1, threads=2, stress=False)
    except lc.LayercontactError:
        return False
    return True


#: CI (.ci/run) requires the threads: there these tests fail in a build without OpenMP
needs_openmp = pytest.mark.skipif(not openmp_build() and not os.environ.get("LAYERCONTACT_REQUIRE_OPENMP"),
                                  reason="a build without OpenMP runs one thread")


def solve_small_surface(**keywords):
    """A frictionless 64 x 64 surface (the thread count is decided before the solve)."""
    h = lc.self_affine_surface(64, 0.8, seed=1, short_wavelength=8 / 64)
    return lc.solve_areal(h, thickness=0.1, normalised_pressure=0.15, tol=1e-6, stress=False, **keywords)


def test_a_build_without_openmp_refuses_more_threads():
    """Without OpenMP, threads = 2 is refused naming the variable; threads = 0 runs one."""
    if openmp_build():
        assert solve_small_surface(threads=2).omp_threads == 2
        return
    with pytest.raises(lc.LayercontactError, match="&solver: threads = 2 needs a build with OpenMP") as err:
        solve_small_surface(threads=2)
    assert err.value.code == 2
    assert solve_small_surface(threads=0).omp_threads == 1


@pytest.mark.parametrize("threads", [-1, 1025])
def test_thread_counts_out_of_range_are_refused(threads):
    with pytest.raises(lc.InputError, match=r"&solver.*threads.*0 <= threads <= 1024") as err:
        lc.solve_line(np.cos(2 * np.pi * np.arange(64) / 64), mean_pressure=0.1, threads=threads)
    assert err.value.code == 2


@needs_openmp
def test_threads_not_given_are_what_the_job_was_given(monkeypatch):
    """threads = 0 (the default): OMP_NUM_THREADS, else SLURM_CPUS_PER_TASK, else the CPUs
    of the affinity mask (not os.cpu_count(): a job confined to some CPUs sees those)."""
    def threads_used(**keywords):
        return solve_small_surface(**keywords).omp_threads

    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.delenv("SLURM_CPUS_PER_TASK", raising=False)
    assert threads_used() == len(os.sched_getaffinity(0))
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", "3")
    assert threads_used() == 3
    monkeypatch.setenv("OMP_NUM_THREADS", "2,1")   # (the outer level of a nested setting)
    assert threads_used() == 2
    monkeypatch.setenv("OMP_NUM_THREADS", "many")  # not a count: passed over
    assert threads_used() == 3
    assert threads_used(threads=1) == 1            # &solver threads overrides the job's
    monkeypatch.delenv("SLURM_CPUS_PER_TASK")
    monkeypatch.delenv("OMP_NUM_THREADS")
    original = os.sched_getaffinity(0)
    try:
        os.sched_setaffinity(0, {min(original)})
        assert threads_used() == 1
    finally:
        os.sched_setaffinity(0, original)


def assert_same(one, two, names):
    for name in names:
        a, b = getattr(one, name), getattr(two, name)
        if isinstance(a, np.ndarray):
            scale = max(np.max(np.abs(a)), np.finfo(float).tiny)
            assert np.max(np.abs(a - b)) <= SAME * scale, name
        elif isinstance(a, (bool, int, np.integer, str)):
            assert a == b, name
        else:
            assert b == pytest.approx(a, rel=SAME, abs=SAME * 1e-300), name


FIELDS = ["pressure", "gap", "displacement_z"]
STRESS = ["displacement_x", "displacement_y", "stress_xx", "stress_yy", "stress_xy"]
SCALARS = ["mean_pressure", "penetration", "contact_fraction", "delta_mu", "delta_mu_spectral", "dissipated_power",
           "max_tension", "max_principal_stress", "converged", "iterations", "fft_pairs", "residual", "solver",
           "mean_gap"]

AREAL = """&scene geometry = 'areal', n = {n} /
&layer thickness = {thickness}, poisson = 0.5 /
{material}
&friction coefficient = {friction} /
&profile kind = 'self_affine', hurst = 0.8, seed = 3, short_wavelength = {short!r}, rms_gradient = 0.1 /
&loading normalised_pressure = 0.15 /
&solver tol = 1e-8, threads = {threads} /
&output file = '{file}', stress = .true., leakage = .true., overwrite = .true. /
"""

SLS = "&material model = 'sls', e0 = 1.0, e_inf = 10.0, tau = 1.0, speed = 0.05 /"


@needs_openmp
@pytest.mark.parametrize("scene", [
    dict(friction=0.0, thickness=0.05, material=""),                   # frictionless: the constrained CG
    dict(friction=0.5, thickness=0.05, material=""),                   # coupled, thin layer: GCR
    dict(friction=0.3, thickness=0.16, material=SLS),                  # sliding viscoelastic layer
], ids=["frictionless", "coupled", "viscoelastic"])
def test_areal_scenes_are_the_same_on_two_threads(tmp_path, scene):
    """A 256 x 256 scene with stress and leakage, run from a namelist on 1 and 2 threads:
    the same fields, scalars and leakage; the root attributes say the threads used."""
    runs = {}
    for threads in (1, 2):
        path = tmp_path / f"scene_{threads}.nml"
        path.write_text(AREAL.format(n=256, short=8 / 256, threads=threads, file=tmp_path / f"out_{threads}.h5",
                                     **scene))
        runs[threads] = lc.run(path)
        with h5py.File(tmp_path / f"out_{threads}.h5") as f:
            assert f.attrs["omp_threads"] == threads and f.attrs["mpi_ranks"] == 1
        assert runs[threads].omp_threads == threads and runs[threads].mpi_ranks == 1
    one, two = runs[1], runs[2]
    assert one.converged
    assert_same(one, two, FIELDS + STRESS + SCALARS + ["patches"])
    for name in ("k_eff_x", "k_eff_y"):
        assert getattr(two.leakage, name) == pytest.approx(getattr(one.leakage, name), rel=SAME)


@needs_openmp
def test_a_large_surface_is_the_same_on_two_threads():
    """1024 x 1024 points: the two-pass transform (rows, then blocks of columns shared out
    among the threads) and every pass over the grid threaded."""
    h = lc.self_affine_surface(1024, 0.8, seed=5, short_wavelength=8 / 1024)
    one, two = (lc.solve_areal(h, thickness=0.05, friction=0.5, normalised_pressure=0.15, tol=1e-8, stress=False,
                               threads=threads) for threads in (1, 2))
    assert one.converged and (one.omp_threads, two.omp_threads) == (1, 2)
    assert_same(one, two, FIELDS + ["mean_pressure", "penetration", "delta_mu", "iterations", "solver", "residual"])


@needs_openmp
def test_two_thread_transforms_take_no_fresh_memory():
    """Once planned, a 2048 x 2048 transform pair on two threads touches no new page: the
    two-pass column blocks go through buffers of the plan's own (lc_fft_plans), where
    FFTW's plans for a strided block allocate buffers at every execution, which on the
    second thread's malloc arena came as fresh pages (5000-8300 page faults a pair). 20
    pairs more than a first pair may fault fewer times than there are pairs."""
    from layercontact.native import core

    def faults(repeats):
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        core.py_grid_fft_pair_seconds(2048, 2048, 2, repeats, 1)
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

    faults(1)  # the second thread's arena and FFTW's twiddle tables exist from here on
    assert faults(21) - faults(1) < 20


@needs_openmp
def test_a_short_line_runs_on_one_thread():
    """Below 2^18 points a line's passes and transforms are too short to share (lc_contact_solve's
    smallest_threaded_line): it runs on one thread whatever is asked."""
    h = lc.self_affine_profile(2**18 - 2, 0.8, seed=4, short_wavelength=16 / 2**18)
    assert lc.solve_line(h, mean_pressure=0.01, threads=2, stress=False, tol=1e-6).omp_threads == 1


@needs_openmp
def test_a_line_is_the_same_on_two_threads():
    """A coupled line (friction on a thin layer) with its stress, 2^18 points."""
    h = lc.self_affine_profile(2**18, 0.8, seed=4, short_wavelength=16 / 2**18)
    one, two = (lc.solve_line(h, thickness=0.05, friction=0.5, normalised_pressure=0.5, tol=1e-8, threads=threads)
                for threads in (1, 2))
    assert one.converged and two.omp_threads == 2
    assert_same(one, two, FIELDS + ["displacement_x", "stress_xx", "mean_pressure", "penetration", "delta_mu",
                                    "iterations", "fft_pairs", "solver", "max_tension", "n_spots"])
