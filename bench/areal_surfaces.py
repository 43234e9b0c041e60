"""Rough surfaces and common observables for the areal benchmarks (bench/areal_*.py and
``bench/memory.py --areal``); not a benchmark itself.

``surface`` is ``layercontact.self_affine_surface`` on the unit square: isotropic,
``C(q) ~ q^(-2-2H)`` from the period down to ``short_wavelength``, random phases that
depend on the mode, not the grid (a spectrum fixed in physical wavenumbers gives the same
surface, sampled more finely, at every grid size), scaled to an rms gradient.
"""

from __future__ import annotations

import numpy as np

import layercontact as lc


def generator_name() -> str:
    return "layercontact.self_affine_surface"


def surface(n: int, *, short_wavelength: float, hurst: float = 0.8, seed: int = 1,
            rms_gradient: float = 0.1) -> np.ndarray:
    """n x n heights on the unit period."""
    return lc.self_affine_surface(n=n, hurst=hurst, seed=seed, short_wavelength=short_wavelength,
                                  rms_gradient=rms_gradient)


def halfspace_observables(pressure: np.ndarray, heights: np.ndarray, contact_modulus: float,
                          period: float = 1.0) -> tuple[float, float]:
    """Contact fraction (p > 0) and mean gap of a frictionless half-space computed from a
    pressure field alone, the same way for every code: ``w = IFFT[2/(E* |q|) FFT p]``
    (mean zero), ``d = w - h``; the rigid surface sits where ``d`` is on average over the
    contact set, so the mean gap is ``mean(d) - mean(d over the contact)``."""
    ny, nx = pressure.shape
    qx = 2 * np.pi * np.fft.rfftfreq(nx, period / nx)
    qy = 2 * np.pi * np.fft.fftfreq(ny, period / ny)
    q = np.hypot(qx[None, :], qy[:, None])
    compliance = np.zeros_like(q)
    compliance[q > 0] = 2 / (contact_modulus * q[q > 0])
    w = np.fft.irfft2(compliance * np.fft.rfft2(pressure), s=(ny, nx))
    contact = pressure > 0
    d = w - heights
    return float(contact.mean()), float(d.mean() - d[contact].mean())
