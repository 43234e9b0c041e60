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


def test_coarse_levels_on_the_slabs_down_to_eight_rows_a_rank():
    # 2048² on 16 ranks: 1024, 512, 256 and 128 rows (64, 32, 16, 8 a rank) on the slabs;
    # 64 rows (4 a rank) gathered, and 32 below it; 16² = 256 < 512 points is not a level
    levels = model.coarse_levels(2048, 16)
    assert [level["rows"] for level in levels] == [1024, 512, 256, 128, 64, 32]
    assert [level["on_slabs"] for level in levels] == [True] * 4 + [False] * 2
    assert sum(level["share"] for level in levels) == pytest.approx(1.0, rel=1e-14)
    # one rank: nothing on slabs (the serial solve); 5 ranks do not divide the rows of 256²:
    # ceil(128/5) = 26 and ceil(64/5) = 13 a rank on the slabs, ceil(32/5) = 7 gathered
    assert not any(level["on_slabs"] for level in model.coarse_levels(2048, 1))
    assert [level["on_slabs"] for level in model.coarse_levels(256, 5)] == [True, True, False]


def test_memory_per_rank_takes_the_larger_of_slab_and_gathered_tail_on_every_rank():
    n, d = 4096, 20.0
    # P = 2: every coarse level on the slabs (down to 32² = 1024 points, 16 rows, 8 a rank):
    # the fine slab d N / 2 is the peak
    m = model.model_memory(n, 2, d)
    assert m["other"] == pytest.approx(8 * d * n * n / 2, rel=1e-14)
    # (no field gathered to rank 0: the observables and the file on the slabs)
    assert m["rank0"] == m["other"]
    # P = 64: 2048 .. 512 rows on the slabs, 256² gathered: the slab d N / 64 is larger
    assert model.model_memory(n, 64, d)["other"] == pytest.approx(8 * d * n * n / 64, rel=1e-14)
    # P = 1024: 2048 rows are 2 a rank: the first coarse grid gathered, whole on every rank
    assert model.model_memory(n, 1024, d)["other"] == pytest.approx(8 * d * n * n / 4, rel=1e-14)


def test_serial_time_scales_the_transforms_as_n_log_n_and_the_passes_as_n():
    small = model.model_serial(2048, COEFFICIENT, REF)
    large = model.model_serial(4096, COEFFICIENT, REF)
    assert large["pair"] / small["pair"] == pytest.approx(4 * 24 / 22, rel=1e-14)
    assert large["coarse"] / small["coarse"] == pytest.approx(4 * 24 / 22, rel=1e-14)
    assert large["passes"] / small["passes"] == pytest.approx(4.0, rel=1e-14)


def test_coarse_start_on_the_slabs_shrinks_with_the_ranks_down_to_its_gathered_tail():
    # an ideal network: a level on the slabs takes its serial share over P, the gathered
    # tail its whole share; the shares are N_l log2 N_l of the levels 1024² .. 32² of 2048²
    weights = [(2048 >> k) ** 2 * math.log2((2048 >> k) ** 2) for k in range(1, 7)]
    serial = model.model_serial(2048, COEFFICIENT, REF)["coarse"]
    t = model.model_time(2048, 16, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0)
    expected = serial * (sum(weights[:4]) / 16 + sum(weights[4:])) / sum(weights)
    assert t["coarse"] == pytest.approx(expected, rel=1e-12)
    # where no level has 8 rows a rank, the coarse start is gathered and solved whole, and
    # bounds the speed-up as Amdahl: 1 / 0.13 of the split (0.87 / 2**20 left)
    t = model.model_time(2048, 2**20, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0)
    assert t["coarse"] == pytest.approx(serial, rel=1e-12)
    assert t["serial"] / t["total"] == pytest.approx(1 / 0.13, rel=1e-4)
    # below that, 2 ranks: every level on the slabs, the whole solve halves
    t = model.model_time(2048, 2, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0)
    assert t["serial"] / t["total"] == pytest.approx(2.0, rel=1e-12)
    # the coarse start takes over half the solve once its gathered tail outweighs the rest
    # over P: at P = 128 the levels from 512 rows (4 a rank) on, about a quarter of the
    # coarse time (0.13/4 = 0.033 of the serial solve against the rest's 0.87/128 = 0.007);
    # at P = 64 the tail from 256 rows, about 1/16 (0.008 against 0.014)
    assert model.coarse_dominates_from(2048, COEFFICIENT, REF, bandwidth=math.inf, latency=0.0) == 128
