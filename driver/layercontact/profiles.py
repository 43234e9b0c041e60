"""Rigid profiles: seeded self-affine synthesis (the Fortran routine, so that a namelist
run and Python give the same heights for the same seed), sinusoids, and measured profiles
read from files."""

from __future__ import annotations

import os

import numpy as np

from .native import core as _core
from .api import NOT_SET, _check


def self_affine_profile(
    n: int,
    hurst: float = 0.8,
    *,
    period: float = 1.0,
    seed: int = 1,
    rolloff_wavelength: float | None = None,
    short_wavelength: float | None = None,
    rms_gradient: float | None = None,
    rms_height: float | None = None,
) -> np.ndarray:
    """Seeded self-affine line profile of ``n`` heights on one ``period``.

    Power spectrum flat below the roll-off wavenumber, ``~ q^(-1-2H)`` up to the short
    cutoff (default: ``period/128``), zero beyond; random phases from SplitMix64 seeded
    with ``seed``; scaled to exactly ``rms_gradient`` or ``rms_height`` (give one; default
    rms_gradient = 0.1). Same arguments, same heights as ``&profile kind='self_affine'``.
    """
    if rms_gradient is None and rms_height is None:
        rms_gradient = 0.1
    height, stat, errmsg = _core.py_self_affine_profile(
        int(n), float(period), float(hurst), int(seed),
        NOT_SET if rolloff_wavelength is None else float(rolloff_wavelength),
        NOT_SET if short_wavelength is None else float(short_wavelength),
        NOT_SET if rms_gradient is None else float(rms_gradient),
        NOT_SET if rms_height is None else float(rms_height),
    )
    _check(stat, errmsg)
    return height


def sinusoid_profile(n: int, amplitude: float, *, mode: int = 1, period: float = 1.0) -> np.ndarray:
    """``amplitude * cos(2 pi mode x/period)`` on ``n`` points of one period."""
    x = np.arange(n) * (period / n)
    return amplitude * np.cos(2 * np.pi * mode * x / period)


def load_profile(path: str | os.PathLike, dataset: str = "/profile/height") -> np.ndarray:
    """Heights from a file: ``.npy``, an HDF5 file (``dataset``), or a text column."""
    path = os.fspath(path)
    if path.endswith(".npy"):
        h = np.load(path)
    elif path.endswith((".h5", ".hdf5")):
        import h5py

        with h5py.File(path, "r") as f:
            h = f[dataset][()]
    else:
        h = np.loadtxt(path)
    h = np.asarray(h, dtype=np.float64)
    if h.ndim != 1 or not np.all(np.isfinite(h)):
        raise ValueError(f"{path}: expected one column of finite heights, got shape {h.shape}")
    return h
