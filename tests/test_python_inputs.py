"""Bad values given to the Python functions that make or read arrays are refused with an
InputError (code 2, a LayercontactError and a ValueError) that names the argument and the
allowed range, before anything is allocated; none is taken silently (a complex height
losing its imaginary part, True taken as 1, 16.7 points taken as 16)."""

from __future__ import annotations

import numpy as np
import pytest

import layercontact as lc


def refused(match: str):
    return pytest.raises(lc.InputError, match=match)


@pytest.mark.parametrize("heights, word", [
    (np.ones(64, dtype=complex), "complex"),
    (np.ones(64, dtype=bool), "boolean"),
    (np.array(["a"] * 64), "dtype"),
    (np.full(64, np.nan), "NaN"),
    (np.ones((4, 4, 4)), "shape"),
    (np.ones(0), "shape"),
])
def test_prepare_heights_refuses_what_is_not_real_heights(heights, word):
    with refused(word) as err:
        lc.prepare_heights(heights)
    assert err.value.code == 2 and isinstance(err.value, ValueError) and "height" in str(err.value)


@pytest.mark.parametrize("n", [16.7, True, "16"])
def test_a_generator_refuses_a_grid_that_is_not_an_integer_of_points(n):
    with refused("allowed: an integer number of points") as err:
        lc.self_affine_surface(n)
    assert err.value.code == 2
    with refused("allowed: an integer number of points"):
        lc.self_affine_profile(n)


@pytest.mark.parametrize("n", [-8, 2])
def test_the_library_checks_the_range_of_an_integer_grid(n):
    with pytest.raises(lc.LayercontactError, match="&scene: ") as err:
        lc.self_affine_surface(n)
    assert err.value.code == 2


def test_a_whole_float_is_a_number_of_points():
    assert lc.self_affine_surface(16.0).shape == (16, 16)


@pytest.mark.parametrize("n", [2**31, 2**16])
def test_a_grid_too_large_is_refused_before_anything_is_allocated(n):
    with refused("at most 1073741824 points"):
        lc.self_affine_surface(n)


@pytest.mark.parametrize("period", [(1.0,), (1.0, 2.0, 3.0), (1.0, -1.0), "one", np.inf])
def test_a_period_is_one_length_or_a_pair(period):
    with refused("period"):
        lc.self_affine_surface(16, period=period)


def test_a_pair_of_periods_is_taken():
    assert lc.self_affine_surface(16, period=(2.0, 1.0), nx=32).shape == (16, 32)


@pytest.mark.parametrize("tol", [-1.0, 0.0, 0.5, float("nan")])
def test_the_leakage_refuses_a_tolerance_out_of_range(tol):
    gap = np.ones((8, 8))
    with refused("tol"):
        lc.reynolds_leakage(gap, tol=tol)
    with refused("tol"):
        lc.core_leakage(gap, tol=tol)


@pytest.mark.parametrize("max_iter", [0, -5, 2.5, True])
def test_the_leakage_refuses_a_budget_that_is_not_a_positive_integer(max_iter):
    gap = np.ones((8, 8))
    with refused("max_iter") as err:
        lc.core_leakage(gap, max_iter=max_iter)
    assert err.value.code == 2
    with refused("max_iter"):
        lc.reynolds_leakage(gap, max_iter=max_iter)


@pytest.mark.parametrize("gap, word", [
    (np.ones((8, 8), dtype=complex), "complex"),
    (np.ones((8, 8), dtype=bool), "boolean"),
    (np.full((8, 8), np.inf), "infinite"),
    (np.ones(8), "shape"),
])
def test_the_leakage_refuses_a_gap_that_is_not_a_real_map(gap, word):
    with refused(word):
        lc.reynolds_leakage(gap)
    with refused(word):
        lc.core_leakage(gap)


@pytest.mark.parametrize("pressure, word", [
    (np.full((8, 8), np.nan), "NaN"),
    (np.ones((8, 8), dtype=complex), "complex"),
    (np.ones((2, 8, 8)), "shape"),
])
def test_surface_stress_refuses_a_pressure_that_is_not_a_real_map(pressure, word):
    with refused(word):
        lc.surface_stress(pressure)


def test_reading_a_file_that_is_not_a_result_names_it(tmp_path):
    """What is there but is not a result is bad input (code 2), as for the height files;
    so are a missing file and a loop of symbolic links, named as what they are."""
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5\n")
    with refused("cannot read result file '.*notes.h5': not an HDF5 file") as err:
        lc.read_result(text)
    assert err.value.code == 2
    import h5py

    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f["x"] = np.ones(3)
    with refused("not a layercontact result") as err:
        lc.read_result(other)
    assert err.value.code == 2
    with refused("result file '.*missing.h5' is not found"):
        lc.read_result(tmp_path / "missing.h5")
    (tmp_path / "a.h5").symlink_to("b.h5")
    (tmp_path / "b.h5").symlink_to("a.h5")
    with refused("result file '.*a.h5' is a loop of symbolic links"):
        lc.read_result(tmp_path / "a.h5")


def test_the_module_says_its_version_and_core():
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "layercontact", "--version"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0
    assert proc.stdout.strip() == f"layercontact {lc.__version__} ({lc.BUILD})"


def test_a_name_across_two_lines_of_a_namelist_is_refused(tmp_path):
    """A string that goes on to the next line would lose its newline (another file name):
    the namelist file is refused, naming the line, and nothing is written."""
    scene = tmp_path / "scene.nml"
    scene.write_text("&scene\n n = 64\n/\n&loading\n normalised_pressure = 1.0\n/\n"
                     "&output\n file = 'out\nput.h5'\n/\n")
    with refused("line 8: a string goes on to the next line") as err:
        lc.check_scene_file(scene)
    assert err.value.code == 2 and not list(tmp_path.glob("*.h5"))


@pytest.mark.parametrize("method", ["a\nb", "cg\t"])
def test_a_keyword_with_a_control_character_is_refused(method, rough_profile):
    with refused("control characters"):
        lc.solve_line(rough_profile, mean_pressure=0.1, method=method)


@pytest.mark.parametrize("solve, heights", [
    (lc.solve_line, np.cos(2 * np.pi * np.arange(64) / 64)),
    (lc.solve_areal, np.cos(2 * np.pi * np.arange(16) / 16)[None, :] * np.ones((16, 1))),
])
def test_young_and_a_material_both_given_are_refused(solve, heights):
    """``young`` and ``material`` both give the layer's modulus (the material's wins inside
    the library): both given are refused, as a namelist variable given twice is."""
    material = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)
    with refused("young = 2.0 and material = .* both give the layer's modulus; allowed: one of them") as err:
        solve(heights, young=2.0, material=material, speed=1.0, normalised_pressure=1.0, thickness=0.5)
    assert err.value.code == 2


def test_a_scene_text_with_a_variable_twice_is_refused_from_python():
    """The text path of the keyword API refuses what a namelist file would."""
    with refused("group &scene: period and period_x are both given"):
        lc.scene_namelist("&scene\n period = 1.0\n period_x = 2.0\n/\n&loading\n normalised_pressure = 1.0\n/\n")
    with refused("period_y applies to surfaces only"):
        lc.scene_namelist(period_y=2.0, normalised_pressure=1.0)


@pytest.mark.parametrize("heights, word", [
    (np.ones(64, dtype=complex), "complex"),
    (np.ones(64, dtype=bool), "boolean"),
    (np.full(64, np.inf), "NaN or infinite"),
    (np.ones((8, 8)), "solve_areal"),
])
def test_solve_line_refuses_what_is_not_a_real_profile(heights, word):
    with refused(word) as err:
        lc.solve_line(heights, mean_pressure=0.01)
    assert err.value.code == 2


@pytest.mark.parametrize("heights, period, word", [
    (np.ones((8, 8), dtype=complex), 1.0, "complex"),
    (np.ones((8, 8), dtype=bool), 1.0, "boolean"),
    (np.ones(64), 1.0, "shape"),
    (np.zeros((8, 8)), (1.0,), "period"),
    (np.zeros((8, 8)), (1.0, 0.0), "period"),
])
def test_solve_areal_refuses_what_is_not_a_real_surface_or_its_periods(heights, period, word):
    with refused(word) as err:
        lc.solve_areal(heights, period=period, mean_pressure=0.01)
    assert err.value.code == 2


def test_a_surface_larger_than_the_memory_allowed_is_an_error_not_a_crash():
    """Under an address-space limit of 1 GiB a 16384² surface (2 GiB of heights) cannot be
    made: the interpreter gets code 5 and goes on."""
    import subprocess
    import sys
    script = """
import resource
resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))
import layercontact as lc
try:
    lc.self_affine_surface(16384)
except lc.LayercontactError as error:
    print("code", error.code)
print("alive", lc.self_affine_surface(16).shape)
"""
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "code 5" in proc.stdout and "alive (16, 16)" in proc.stdout
