"""Shared helpers for the pytest suite: an independent numpy implementation of the
convention-P operator (numpy FFT + the kernel factors), used to check the Fortran solver's
output against the contact conditions without going through the Fortran operator.

The kernel factors themselves come from `lc.layer_multipliers`, so these checks test the
operator assembly and the solver, not the kernels: those are tested against mpmath and the
LAPACK mode solve in test_kernels.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import layercontact as lc

ROOT = Path(__file__).resolve().parents[1]


def g_eff(n: int, period: float, thickness: float, young: float, poisson: float, friction: float,
          material=None, speed: float = 0.0):
    """G_eff(k) for k = 0..n/2 (numpy rfft order), convention P, Nyquist made real. With a
    viscoelastic ``material`` 1/E -> J*(k V) (seed Eq. 14)."""
    m = np.arange(n // 2 + 1)
    k = 2 * np.pi * m / period
    compliance = np.full(m.size, 1 / young, dtype=complex)
    if material is not None:
        compliance = lc.creep_compliance(material, k * speed)
    g = np.zeros(m.size, dtype=complex)
    oma, _, c = lc.layer_multipliers(k[1:] * thickness, poisson)
    g[1:] = 2 * (1 - poisson**2) * compliance[1:] / k[1:] * (oma - 1j * friction * c)
    if n % 2 == 0:
        g[-1] = g[-1].real  # the Nyquist mode is its own mirror image: (G(k) + G(-k))/2
    if np.isfinite(thickness):
        g[0] = thickness * (1 + poisson) * (1 - 2 * poisson) * compliance[0].real / (1 - poisson)
    return g


def apply(g: np.ndarray, p: np.ndarray) -> np.ndarray:
    """w = G_eff * p by numpy FFT."""
    return np.fft.irfft(np.fft.rfft(p) * g, n=p.size)


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
