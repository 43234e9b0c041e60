"""The arithmetic of bench/mpi_model.py, the model of one surface solve on P MPI ranks
(docs/performance.md, "Beyond one node: a model"), on cases with a known answer. Nothing is
measured: the model's functions take the measured parts as arguments."""

from __future__ import annotations

import importlib.util
import math

import pytest

from conftest import ROOT

_spec = importlib.util.spec_from_file_location("mpi_model", ROOT / "bench" / "mpi_model.py")
model = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(model)

# the reference solve of the script's defaults: 2048², 12.75 s, 22 iterations, 64 pairs
REF = {"n": 2048, "solve": 12.75, "iterations": 22, "pairs": 64, "split": [0.05, 0.13, 0.82]}
COEFFICIENT = 1.0e-9   # s per point log point: 2048² pair 92 ms, below the fine time a pair


def moved_bytes_by_enumeration(nx: int, ny: int, ranks: int) -> int:
    """Bytes that change rank in the two transposes of a pair, counted element by element:
    the half spectrum (nx/2 columns of ny rows, complex, 16 B) held by row slabs before the
    transpose and by column slabs after it; an element stays where both owners agree."""
    rows, columns = ny // ranks, (nx // 2) // ranks
    moved = sum(1 for i in range(ny) for j in range(nx // 2) if i // rows != j // columns)
    return 2 * 16 * moved


@pytest.mark.parametrize("nx, ny, ranks", [(8, 8, 2), (16, 8, 4), (32, 32, 8), (16, 16, 1)])
def test_all_to_all_volume_counts_every_moved_element(nx, ny, ranks):
    # exact: integers, the slabs dividing the grid evenly
    assert model.transpose_bytes_total(nx, ny, ranks) == moved_bytes_by_enumeration(nx, ny, ranks)


def test_transpose_time_is_the_rank_share_over_the_link_plus_latencies():
    nx = ny = 1024
    bandwidth, latency = 1.0e9, 3.0e-6
    assert model.transpose_seconds(nx, ny, 1, bandwidth, latency) == 0.0
    # P = 4: a rank sends 3/4 of its quarter of the half spectrum, twice; 3 messages a transpose
    expected = 2 * 16 * 512 * 1024 * 0.75 / 4 / bandwidth + 2 * 3 * latency
    assert model.transpose_seconds(nx, ny, 4, bandwidth, latency) == pytest.approx(expected, rel=1e-14)


def test_allreduce_is_a_tree_of_latencies():
    assert model.allreduce_seconds(1, 2e-6) == 0.0
    assert model.allreduce_seconds(1024, 2e-6) == pytest.approx(10 * 2e-6, rel=1e-14)
    assert model.allreduce_seconds(1000, 2e-6) == pytest.approx(10 * 2e-6, rel=1e-14)


def test_one_rank_reproduces_the_reference_solve_and_its_memory():
    # P = 1 is the serial solve the model is scaled from: its parts add up to it again
    # (rounding only), and its memory is the serial doubles per point, nothing gathered
    t = model.model_time(REF["n"], 1, COEFFICIENT, REF, bandwidth=1e10, latency=2e-6)
    assert t["total"] == pytest.approx(REF["solve"], rel=1e-12)
    assert t["transpose"] == t["reductions"] == 0.0
    memory = model.model_memory(REF["n"], 1, doubles_per_point=16.7)
    assert memory["rank0"] == memory["other"] == pytest.approx(16.7 * 8 * 2048**2, rel=1e-14)


def test_memory_per_rank_takes_the_larger_of_slab_and_coarse_grid_and_rank0_the_fields():
    n, d = 4096, 20.0
    # P = 2: the slab, d N / 2, is larger than the coarse grid's d N / 4
    m = model.model_memory(n, 2, d)
    assert m["other"] == pytest.approx(8 * d * n * n / 2, rel=1e-14)
    assert m["rank0"] - m["other"] == pytest.approx(8 * 4 * n * n, rel=1e-14)
    # P = 64: the coarse grid, whole on every rank, is what is left
    assert model.model_memory(n, 64, d)["other"] == pytest.approx(8 * d * n * n / 4, rel=1e-14)


def test_serial_time_scales_the_transforms_as_n_log_n_and_the_passes_as_n():
    small = model.model_serial(2048, COEFFICIENT, REF)
    large = model.model_serial(4096, COEFFICIENT, REF)
    assert large["pair"] / small["pair"] == pytest.approx(4 * 24 / 22, rel=1e-14)
    assert large["coarse"] / small["coarse"] == pytest.approx(4 * 24 / 22, rel=1e-14)
    assert large["passes"] / small["passes"] == pytest.approx(4.0, rel=1e-14)


def test_coarse_start_bounds_the_speed_up_as_amdahl():
    # an ideal network: the time is coarse + rest / P; the coarse start takes over half from
    # P > rest / coarse = 0.87 / 0.13 = 6.7, so from P = 8 among the powers of two; the
    # speed-up tends to 1 / 0.13 of the reference size's split (N log N alike for both)
    p = model.coarse_dominates_from(2048, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0)
    assert p == 8
    t = model.model_time(2048, 2**20, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0)
    assert t["serial"] / t["total"] == pytest.approx(1 / 0.13, rel=1e-4)   # (0.87 / 2**20 left)
