"""The accuracy option (&solver target_error): the grid and tolerance the rule picks meet
the target on the measured table bench/accuracy_table.csv (bench/accuracy.py: errors
against a converged reference at ppw = 8192, for every ppw x tol measured; the largest
tension of a sliding layer is resolved sub-grid at the trailing edge), and bad uses are
refused with a clear message.

The rule runs in the library (src/application/accuracy.f90: a pilot solve for the mean spot length,
then ppw and tol); here its choices are read with layercontact.choose_resolution and
looked up in the table. A target is "verifiable" where the table has that (ppw, tol) with
the default solver and the reference's own uncertainty (ppw 8192 vs 4096) is below a
third of the target."""

import csv
from pathlib import Path

import numpy as np
import pytest

import layercontact as lc

TABLE = Path(__file__).resolve().parents[1] / "bench" / "accuracy_table.csv"
TARGETS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3)
# The scenes of bench/accuracy.py (shortest wavelength period/64, nu = 0.5, E = 1).
SCENES = {
    "half-space": ("Inf", 0.0, 0.3, ""),
    "h0.16": ("0.16", 0.5, 3.0, ""),
    "h0.01": ("0.01", 0.5, 30.0, ""),
    "visco": ("0.16", 0.0, 3.0, "model = 'sls'\n e0 = 1.0\n e_inf = 10.0\n tau = 1.0\n speed = 0.2"),
}


def _table():
    rows = {}
    with TABLE.open() as f:
        for row in csv.DictReader(f):
            if row["role"] == "sweep" and row["precondition"] == "1" and row["method"] in ("cg", "auto"):
                rows[(row["scene"], int(row["ppw"]), float(row["tol"]))] = row
    return rows


def _scene_file(tmp_path, scene, eps, stress, short_wavelength=0.015625):
    thickness, friction, pressure, material = SCENES[scene]
    text = f"""&scene
 n = 4096
/
&layer
 thickness = {thickness}
 poisson = 0.5
/
&material
 {material}
/
&friction
 coefficient = {friction}
/
&profile
 kind = 'self_affine'
 hurst = 0.8
 seed = 1
 short_wavelength = {short_wavelength}
 rms_gradient = 0.1
/
&loading
 normalised_pressure = {pressure}
/
&solver
 target_error = {eps}
/
&output
 file = '{tmp_path / 'unused.h5'}'
 stress = {'.true.' if stress else '.false.'}
/
"""
    path = tmp_path / f"{scene}_{eps}_{stress}.nml"
    path.write_text(text)
    return path


def test_rule_meets_the_measured_table(tmp_path):
    table = _table()
    verified = 0
    for scene in SCENES:
        coupled = SCENES[scene][1] > 0
        for eps in TARGETS:
            for stress in ((True, False) if coupled else (True,)):
                n, tol = lc.choose_resolution(_scene_file(tmp_path, scene, eps, stress))
                assert n % 64 == 0 and tol in (1e-2, 1e-3, 1e-4, 1e-6, 1e-8)
                ppw = n // 64
                row = table.get((scene, ppw, tol))
                if row is None:
                    continue  # not measured (ppw > 1024, or a fine ppw at a loose tol)
                error = float(row["max_error" if stress else "max_error_no_tension"])
                uncertainty = max(float(row[k]) for k in row if k.startswith("unc_") and row[k] != "nan"
                                  and (stress or k != "unc_max_tension"))
                if 3 * uncertainty > eps:
                    continue  # the reference cannot tell
                assert error <= eps, (scene, eps, stress, ppw, tol, error)
                verified += 1
    # all 30 (scene, target, stress) cases: with the sub-grid trailing-edge peak the largest
    # tension of a sliding layer needs no grid beyond the table (ppw <= 1024)
    assert verified == 30


def test_rule_is_monotone_and_the_stress_costs_nothing_extra(tmp_path):
    """A tighter target never asks for a coarser grid or a looser tolerance; the largest
    tension, resolved sub-grid, is below the contact fraction's error at the rule's
    settings, so asking for the stress does not change the choice."""
    chosen = [lc.choose_resolution(_scene_file(tmp_path, "h0.16", eps, True)) for eps in TARGETS]
    assert all(a[0] <= b[0] and a[1] >= b[1] for a, b in zip(chosen, chosen[1:]))
    without = [lc.choose_resolution(_scene_file(tmp_path, "h0.16", eps, False)) for eps in TARGETS]
    assert without == chosen


def test_unreachable_target_is_refused(tmp_path):
    """eps = 1e-4 with spots of ~0.8 shortest wavelengths asks for ~10^4 points per shortest
    wavelength: with 4096 of them in the period that is beyond 2^24 points."""
    path = _scene_file(tmp_path, "half-space", 1e-4, True, short_wavelength=1 / 4096)
    path.write_text(path.read_text().replace("n = 4096", "n = 8192"))  # n is checked, then replaced
    with pytest.raises(lc.LayercontactError, match=r"target_error = .* needs more than") as err:
        lc.choose_resolution(path)
    assert err.value.code == 2


def test_target_error_range_and_profile_kind(tmp_path):
    path = _scene_file(tmp_path, "half-space", 0.5, True)
    with pytest.raises(lc.LayercontactError, match=r"&solver.*target_error.*1e-4 <= target_error <= 0.3"):
        lc.check_scene_file(path)
    h5 = tmp_path / "profile.h5"
    import h5py

    with h5py.File(h5, "w") as f:
        f["/profile/height"] = lc.self_affine_profile(256, 0.8, short_wavelength=1 / 32)
    text = _scene_file(tmp_path, "half-space", 0.01, True).read_text()
    text = text.replace("kind = 'self_affine'", f"kind = 'file'\n file = '{h5}'").replace("n = 4096", "n = 256")
    text = text.replace(" hurst = 0.8\n seed = 1\n short_wavelength = 0.015625\n rms_gradient = 0.1\n", "")
    path.write_text(text)
    with pytest.raises(lc.LayercontactError, match=r"target_error.*profile file fixes the grid") as err:
        lc.choose_resolution(path)
    assert err.value.code == 2


def test_run_uses_the_chosen_settings(tmp_path):
    """The executable's run solves on the chosen grid and records it."""
    path = _scene_file(tmp_path, "half-space", 0.03, True)
    n, tol = lc.choose_resolution(path)
    result = lc.run(path)
    assert result.pressure.size == n
    assert result.converged and result.residual <= tol
    assert np.isclose(result.mean_pressure, 0.3 * (4 / 3) * (result.height.max() - result.height.mean()))


# ---- areal scenes: bench/accuracy_areal.py, shortest wavelength period/16 ---------------

AREAL_TABLE = Path(__file__).resolve().parents[1] / "bench" / "accuracy_areal_table.csv"
AREAL_TARGETS = (1e-1, 3e-2, 1e-2)
AREAL_MODES = 16
# (thickness, friction, P): p_m = P E* h/lambda on a layer, P E* Lambda0/lambda on the
# half-space with Lambda0 = max r - mean r of the bench's finest surface (2048^2)
AREAL_SCENES = {"half-space": ("Inf", 0.0, 0.3), "h0.16": ("0.16", 0.5, 0.05), "h0.01": ("0.01", 0.5, 3.0)}


def _areal_scene_file(tmp_path, scene, eps, lambda0):
    thickness, friction, pressure = AREAL_SCENES[scene]
    scale = lambda0 if thickness == "Inf" else float(thickness)
    text = f"""&scene
 geometry = 'areal'
 n = 64
/
&layer
 thickness = {thickness}
 poisson = 0.5
/
&friction
 coefficient = {friction}
/
&profile
 kind = 'self_affine'
 hurst = 0.8
 seed = 1
 short_wavelength = {1 / AREAL_MODES}
 rms_gradient = 0.1
/
&loading
 mean_pressure = {pressure * 4 / 3 * scale!r}
/
&solver
 target_error = {eps}
/
&output
 file = '{tmp_path / 'unused.h5'}'
/
"""
    path = tmp_path / f"areal_{scene}_{eps}.nml"
    path.write_text(text)
    return path


def test_areal_rule_meets_the_measured_table(tmp_path):
    """The areal rule's (ppw, tol) for the bench's three scenes and targets 1e-1 .. 1e-2 meet
    the target on every counted observable but the max tension (contact fraction, a/a0,
    Delta mu, penetration, k_eff along and across x), wherever the reference (ppw 128
    against 64) can tell."""
    rows = {}
    with AREAL_TABLE.open() as f:
        for row in csv.DictReader(f):
            if row["role"] == "sweep" and row["seed"] == "1" and row["method"] == "auto":
                rows[(row["scene"], int(row["ppw"]), float(row["tol"]))] = row
    fine = lc.self_affine_surface(n=2048, hurst=0.8, seed=1, short_wavelength=1 / AREAL_MODES, rms_gradient=0.1)
    lambda0 = float(fine.max() - fine.mean())
    verified = 0
    for scene in AREAL_SCENES:
        chosen = []
        for eps in AREAL_TARGETS:
            (nx, ny), tol = lc.choose_resolution(_areal_scene_file(tmp_path, scene, eps, lambda0))
            assert nx == ny and nx % AREAL_MODES == 0 and tol in (1e-2, 1e-3, 1e-4, 1e-6, 1e-8)
            chosen.append((nx, tol))
            row = rows.get((scene, nx // AREAL_MODES, tol))
            assert row is not None, (scene, eps, nx, tol)  # the bench measures every choice
            uncertainty = max(float(row[k]) for k in row if k.startswith("unc_") and row[k] != "nan"
                              and k != "unc_max_tension")
            if 3 * uncertainty > eps:
                continue
            assert float(row["max_error_no_tension"]) <= eps, (scene, eps, nx, tol, row["max_error_no_tension"])
            verified += 1
        # a tighter target never asks for a coarser grid or a looser tolerance
        assert all(a[0] <= b[0] and a[1] >= b[1] for a, b in zip(chosen, chosen[1:]))
    assert verified == 9


def test_areal_run_uses_the_chosen_grid(tmp_path):
    """An areal scene with target_error runs on the (nx, ny) the rule picks; a sphere has no
    shortest wavelength and is refused."""
    path = _areal_scene_file(tmp_path, "h0.16", 0.1, 0.0)
    (nx, ny), tol = lc.choose_resolution(path)
    result = lc.run(path)
    assert result.pressure.shape == (ny, nx)
    assert result.converged and result.residual <= tol
    sphere = path.read_text().replace("kind = 'self_affine'", "kind = 'sphere'\n radius = 1.0")
    sphere = sphere.replace(" hurst = 0.8\n seed = 1\n", "").replace(f" short_wavelength = {1 / AREAL_MODES}\n", "")
    sphere = sphere.replace(" rms_gradient = 0.1\n", "")
    path.write_text(sphere)
    with pytest.raises(lc.LayercontactError, match=r"target_error.*a sphere has no shortest wavelength") as err:
        lc.choose_resolution(path)
    assert err.value.code == 2
