"""The contact patches and the leakage of a surface shared among the ranks of an MPI job,
computed on the slabs (docs/decisions/026-distributed-patches-and-leakage.md), against the
serial run of the same scene and against references computed here from the fields.

Patches: each rank labels its slab, the labels are joined across the slabs' edges and the
periodic one on rank 0, and the node and edge counts are summed as integers, so the patch
list is the serial one exactly (same count, same order, the same areas and perimeters to the
bit), on scenes whose patches cross every slab edge and the periodic edges. The fields of the
distributed run are those of the serial run to 1e-10 (tests/test_mpi.py), not to the bit: a
node whose pressure is at the rounding of zero could be in contact in one run and not in the
other, which the scenes here avoid (their contact sets are compared node by node first). The
patches are also checked against a labelling of the pressure field written here (numpy, its
own union-find with the periodic wrap), and the single patch of a ridge against its closed
form.

Leakage: on several ranks hypre's BoomerAMG coarsens the distributed matrix otherwise than
on one, so the conjugate gradients take other iterations; each run stops when the energy
decrease over its last five iterations is below leakage_tol times k_eff (docs/leakage.md),
and k_eff, the dissipation at the iterate, exceeds the exact value by the squared energy
error: both runs are within about leakage_tol of the exact k_eff, above it, so they agree to
LEAKAGE = 10 leakage_tol relative (a factor 10 for the lag of the five-iteration estimate),
while a slab edge missed or a cluster's winding lost moves k_eff by percents or to zero.
The counts of the clusters (fluid and connected fractions, unknowns, percolation) are the
serial ones exactly.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from test_mpi import executable, needs_mpi, run_mpi, run_serial

#: the leakage tolerance of the scenes here (&output leakage_tol)
LEAKAGE_TOL = 1e-10
#: relative agreement of two k_eff each stopped at LEAKAGE_TOL (see the module docstring)
LEAKAGE = 10 * LEAKAGE_TOL
#: a closed form computed from the same integer counts: rounding only
EXACT = 1e-12

RANKS = (1, 2, 3, 4)
#: a rough surface of many asperities (flat spectrum above a quarter of the cell)
ROUGH = "kind = 'self_affine', hurst = 0.8, seed = 3, short_wavelength = 0.0625, rolloff_wavelength = 0.25"


def write_scene(directory: Path, name: str, n: int, profile: str, pressure: float, output: str,
                leakage: bool = False) -> Path:
    nml = directory / f"{name}.nml"
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n"
        "&layer thickness = 0.05, poisson = 0.5 /\n&friction coefficient = 0.0 /\n"
        f"&profile {profile} /\n"
        f"&loading control = 'load', normalised_pressure = {pressure} /\n"
        "&solver tol = 1e-13 /\n"
        f"&output file = '{output}', overwrite = .true., stress = .false., "
        f"leakage = {'.true.' if leakage else '.false.'}, leakage_tol = {LEAKAGE_TOL} /\n")
    return nml


def read(path: Path) -> dict[str, object]:
    with h5py.File(path, "r") as f:
        out = {"area": np.asarray(f["patches/area"]), "perimeter": np.asarray(f["patches/perimeter"]),
               "pressure": np.asarray(f["fields/pressure"]), "n_spots": int(f["results"].attrs["n_spots"]),
               "lx": float(f["profile/x"][1] - f["profile/x"][0]) * f["fields/pressure"].shape[1],
               "ly": float(f["profile/y"][1] - f["profile/y"][0]) * f["fields/pressure"].shape[0]}
        if "leakage" in f:
            out["leakage"] = dict(f["leakage"].attrs)
    return out


def runs(tmp_path: Path, n: int, profile: str, pressure: float, leakage: bool = False) -> dict[int, dict]:
    """The serial run (key 0) and the runs on RANKS ranks of one scene."""
    results = {}
    nml = write_scene(tmp_path, "serial", n, profile, pressure, "serial.h5", leakage)
    done = run_serial(nml)
    assert done.returncode == 0, done.stderr
    results[0] = read(tmp_path / "serial.h5")
    for ranks in RANKS:
        nml = write_scene(tmp_path, f"ranks{ranks}", n, profile, pressure, f"ranks{ranks}.h5", leakage)
        done = run_mpi(ranks, [executable(), str(nml)], tmp_path)
        assert done.returncode == 0, done.stderr
        results[ranks] = read(tmp_path / f"ranks{ranks}.h5")
    return results


def reference_patches(pressure: np.ndarray, lx: float, ly: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Areas and perimeters of the 4-connected periodic patches of pressure > 0 (rows y,
    columns x), largest first, ties in the order of their first node (x fastest), and the
    number of rows each patch has nodes in."""
    ny, nx = pressure.shape
    contact = pressure > 0
    parent = np.arange(nx * ny)

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for y, x in zip(*np.nonzero(contact)):
        for yy, xx in ((y, (x + 1) % nx), ((y + 1) % ny, x)):
            if contact[yy, xx]:
                a, b = find(y * nx + x), find(yy * nx + xx)
                parent[max(a, b)] = min(a, b)
    roots = np.array([find(j) for j in range(nx * ny)]).reshape(ny, nx)
    first = {}
    for j in np.flatnonzero(contact.ravel()):
        first.setdefault(roots.ravel()[j], len(first))
    counts = np.zeros(len(first), int)
    edges_x = np.zeros(len(first), int)  # edges normal to x (length dy)
    edges_y = np.zeros(len(first), int)
    rows = [set() for _ in first]
    for y, x in zip(*np.nonzero(contact)):
        k = first[roots[y, x]]
        counts[k] += 1
        rows[k].add(y)
        edges_x[k] += (not contact[y, (x + 1) % nx]) + (not contact[y, (x - 1) % nx])
        edges_y[k] += (not contact[(y + 1) % ny, x]) + (not contact[(y - 1) % ny, x])
    order = sorted(range(len(counts)), key=lambda k: (-counts[k], k))
    dx, dy = lx / nx, ly / ny
    return counts[order] * dx * dy, edges_x[order] * dy + edges_y[order] * dx, np.array([len(rows[k]) for k in order])


def assert_same_patches(results: dict[int, dict]) -> None:
    serial = results[0]
    for ranks in RANKS:
        run = results[ranks]
        # (the contact sets themselves first: the patches are a function of them)
        assert np.array_equal(run["pressure"] > 0, serial["pressure"] > 0), ranks
        assert run["n_spots"] == serial["n_spots"] == len(serial["area"]), ranks
        assert np.array_equal(run["area"], serial["area"]), ranks
        assert np.array_equal(run["perimeter"], serial["perimeter"]), ranks
    area, perimeter, _ = reference_patches(serial["pressure"], serial["lx"], serial["ly"])
    assert np.allclose(serial["area"], area, rtol=EXACT, atol=0)
    assert np.allclose(serial["perimeter"], perimeter, rtol=EXACT, atol=0)


@needs_mpi
def test_large_patches_across_the_slabs_are_the_serial_ones(tmp_path):
    """A rough surface pressed to 30 % contact: some 20 patches, the largest of hundreds of
    nodes across several slabs, on 1-4 ranks (3: uneven slabs of 22, 22, 20 rows)."""
    results = runs(tmp_path, 64, ROUGH, 0.4)
    serial = results[0]
    assert 0.2 < np.mean(serial["pressure"] > 0) < 0.5
    assert serial["n_spots"] > 10
    # patches over more rows than a slab of 2 ranks holds (32): each crosses slab edges
    _, _, rows = reference_patches(serial["pressure"], serial["lx"], serial["ly"])
    assert np.max(rows) > 32 and np.sum(rows > 16) >= 2
    assert_same_patches(results)


@needs_mpi
@pytest.mark.parametrize("mode_y", [0, 1])
def test_a_ridge_through_every_slab_is_one_wrapping_patch(mode_y, tmp_path):
    """A sinusoidal ridge along y (mode_y = 0) or along the diagonal (mode_y = 1) pressed
    into a band of contact: one patch crossing every slab and closing on itself across the
    periodic edge between the last rank and rank 0 (and across x for the diagonal). Its area
    is the contact fraction of the cell; the band along y has two straight edges, so its
    perimeter is twice the cell's side; the diagonal band's rows are one run each, shifted
    by one node a row, a staircase whose edges add up to 2 (lx + ly)."""
    results = runs(tmp_path, 32, f"kind = 'sinusoid', amplitude = 0.02, mode = 1, mode_y = {mode_y}", 0.3)
    serial = results[0]
    contact = serial["pressure"] > 0
    assert serial["n_spots"] == 1
    assert 0.05 < contact.mean() < 0.95
    assert serial["area"][0] == pytest.approx(contact.mean() * serial["lx"] * serial["ly"], rel=EXACT)
    if mode_y == 0:
        # every row has the same run of contact nodes: two straight edges along y
        assert all(np.array_equal(row, contact[0]) for row in contact)
        assert serial["perimeter"][0] == pytest.approx(2 * serial["ly"], rel=EXACT)
    else:
        shift = 1 if np.array_equal(np.roll(contact[1], 1), contact[0]) else -1
        assert all(np.array_equal(np.roll(row, shift * y), contact[0]) for y, row in enumerate(contact))
        assert serial["perimeter"][0] == pytest.approx(2 * (serial["lx"] + serial["ly"]), rel=EXACT)
    assert_same_patches(results)


def assert_same_leakage(results: dict[int, dict]) -> None:
    serial = results[0]["leakage"]
    for ranks in RANKS:
        run = results[ranks]["leakage"]
        for axis in ("x", "y"):
            assert run["converged"] and serial["converged"]
            assert run[f"k_eff_{axis}"] == pytest.approx(serial[f"k_eff_{axis}"], rel=LEAKAGE, abs=0), (ranks, axis)
            for name in (f"percolating_{axis}", f"unknowns_{axis}", f"connected_fraction_{axis}"):
                assert run[name] == serial[name], (ranks, name)
        assert run["fluid_fraction"] == serial["fluid_fraction"], ranks


@needs_mpi
@pytest.mark.parametrize("pressure, near", [(0.05, False), (1.0, True)])
def test_the_leakage_on_the_slabs_is_the_serial_one(pressure, near, tmp_path):
    """k_eff along x and y on 1-4 ranks, far from percolation (5 % in contact: one fluid
    cluster) and at it (half the cells in contact: the fluid winds round the cell along y
    only, through necks, k_eff_y some 3e-5 of its value at light load, and a tenth of the
    fluid in pools): the serial k_eff to LEAKAGE."""
    results = runs(tmp_path, 64, ROUGH, pressure, leakage=True)
    serial = results[0]["leakage"]
    if near:
        assert serial["percolating_y"] and not serial["percolating_x"] and serial["k_eff_x"] == 0
        assert serial["connected_fraction_y"] < 0.95 * serial["fluid_fraction"]
    else:
        assert serial["percolating_x"] and serial["percolating_y"]
        assert serial["connected_fraction_x"] == serial["fluid_fraction"] > 0.9
    assert_same_leakage(results)


@needs_mpi
def test_a_rank_whose_slab_is_all_contact(tmp_path):
    """A ridge along x closes rows 0-4 of 32: on 8 ranks (4 rows each) rank 0 holds no
    fluid cell, so no row of hypre's matrix, and the flow along x passes through the other
    slabs; across the ridge (y) nothing flows. The serial k_eff to LEAKAGE and counts."""
    n = 32
    x = np.arange(n) / n
    xx, yy = np.meshgrid(x, x - 1.5 / n)
    heights = (0.02 * np.cos(2 * np.pi * yy) + 0.004 * np.cos(6 * np.pi * xx + 1) * np.sin(2 * np.pi * yy) ** 2
               + 0.003 * np.cos(2 * np.pi * (2 * xx + 3 * yy)))
    np.save(tmp_path / "ridge.npy", heights.astype("<f8"))
    results = {}
    for ranks in (0, 8):
        out = f"ridge{ranks}"
        nml = write_scene(tmp_path, out, n, "kind = 'file', file = 'ridge.npy'", 1.0, f"{out}.h5", leakage=True)
        done = run_serial(nml) if ranks == 0 else run_mpi(ranks, [executable(), str(nml)], tmp_path)
        assert done.returncode == 0, done.stderr
        results[ranks] = read(tmp_path / f"{out}.h5")
    closed_rows = np.all(results[0]["pressure"] > 0, axis=1)
    assert closed_rows[:4].all() and not closed_rows[5:-1].any()
    serial, run = results[0]["leakage"], results[8]["leakage"]
    assert serial["k_eff_x"] > 0 and serial["k_eff_y"] == 0 and serial["iterations_x"] > 0
    assert run["k_eff_x"] == pytest.approx(serial["k_eff_x"], rel=LEAKAGE, abs=0) and run["k_eff_y"] == 0
    assert run["unknowns_x"] == serial["unknowns_x"] and run["converged"]
    assert np.array_equal(results[8]["area"], results[0]["area"])
