"""Shared helpers for the pytest suite: the contact conditions of a result checked with the
independent numpy operator of reference_operator.py (numpy FFT + the kernel factors), without
going through the Fortran operator.

The kernel factors themselves come from `lc.layer_multipliers`, so these checks test the
operator assembly and the solver, not the kernels: those are tested against mpmath and the
LAPACK mode solve in test_kernels.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import layercontact as lc
from reference_operator import apply, g_eff  # noqa: F401 (shared with the tests)

ROOT = Path(__file__).resolve().parents[1]


def contact_violation(res: lc.LineResult, thickness: float, young: float, poisson: float, material=None,
                      speed: float = 0.0) -> dict:
    """Contact conditions of a result, recomputed independently: returns the worst
    overlap and the worst gap in contact, both relative to the profile's peak-to-valley,
    and the relative error of the mean pressure."""
    r = res.height
    n = r.size
    w = apply(g_eff(n, res.period, thickness, young, poisson, res.friction, material, speed), res.pressure)
    gap = w - (r - r.max() + res.penetration)
    scale = np.ptp(r)
    contact = res.pressure > 0
    return {
        "overlap": max(0.0, -gap.min()) / scale,
        "gap_in_contact": np.abs(gap[contact]).max() / scale,
        "w_error": np.abs(w - res.displacement_z).max() / np.abs(w).max(),
    }


@pytest.fixture(scope="session")
def rough_profile():
    """A self-affine profile used by several tests (n = 4096, H = 0.8, seed 1)."""
    return lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
