"""An independent numpy implementation of the convention-P operator G_eff (numpy FFT and
the kernel factors of `lc.layer_multipliers`), shared by the tests (through conftest) and by
the grids of tests/extremes_grid.py, which bench/extremes.py also imports."""

from __future__ import annotations

import numpy as np

import layercontact as lc


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
