"""The two builds of the compiled core, the portable one (x86-64) and the x86-64-v3 one
(AVX2, FMA) that the package picks where the processor runs it (layercontact/native.py):
the right one is picked and recorded, and both solve the same problems to the bound the
tolerance allows (their passes vectorise 2 and 4 wide, with fused multiply-adds in the
second: the same iterates to rounding, not bit for bit)."""

import os

import h5py
import numpy as np
import pytest

import layercontact as lc
from conftest import ROOT, g_eff

HAS_V3 = lc.native.core is not lc.native.portable


def test_the_faster_build_is_picked_where_it_runs(tmp_path, monkeypatch):
    try:
        from layercontact import _core_v3  # noqa: F401
        built = True
    except ImportError:
        built = False
    runs = lc.native.portable.py_cpu_level()[0] >= 3
    wanted = os.environ.get("LAYERCONTACT_ISA", "auto") == "auto"
    assert lc.BUILD == ("x86-64-v3" if built and runs and wanted else "x86-64")
    # the result file records the build that computed it
    monkeypatch.chdir(tmp_path)
    res = lc.run(ROOT / "inputs" / "default.nml")
    with h5py.File(next(tmp_path.rglob("*.h5"))) as f:
        assert f.attrs["layercontact_build"].decode() == lc.BUILD
    assert res.converged


@pytest.mark.skipif(not HAS_V3, reason="no x86-64-v3 core on this machine")
@pytest.mark.parametrize("case", ["half-space CG", "coupled GCR", "viscoelastic with friction", "Anderson"])
def test_builds_agree_to_rounding(rough_profile, case, monkeypatch):
    """Same scene, both cores: the pressures differ by less than a gap residual
    tol * ptp(profile) times the largest stiffness max 1/|G_eff(k)| allows, the contact sets
    by at most a point per spot edge, and both converge."""
    h = rough_profile
    pm = h.max()
    sls = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)
    kw = {
        "half-space CG": dict(thickness=np.inf, mean_pressure=0.3 * pm),
        "coupled GCR": dict(thickness=0.16, friction=0.5, mean_pressure=3 * pm),
        "viscoelastic with friction": dict(thickness=0.16, friction=0.3, mean_pressure=pm, material=sls, speed=0.1),
        "Anderson": dict(thickness=0.01, friction=0.5, mean_pressure=30 * pm, method="anderson"),
    }[case]
    tol = 1e-10
    fast = lc.solve_line(h, tol=tol, stress=False, **kw)
    monkeypatch.setattr(lc.api, "_core", lc.native.portable)
    portable = lc.solve_line(h, tol=tol, stress=False, **kw)
    assert fast.converged and portable.converged
    g = g_eff(h.size, 1.0, kw["thickness"], 1.0, 0.5, kw.get("friction", 0.0), kw.get("material"),
              kw.get("speed", 0.0))
    bound = tol * np.ptp(h) * np.max(1 / np.abs(g[1:]))
    assert np.abs(fast.pressure - portable.pressure).max() <= bound
    assert fast.penetration == pytest.approx(portable.penetration, rel=1e-8)
    assert abs(np.count_nonzero(fast.pressure) - np.count_nonzero(portable.pressure)) <= 2 * fast.n_spots
