"""Rigid profiles and surfaces: seeded self-affine synthesis (the Fortran routines, so that
a namelist run and Python give the same heights for the same seed), sinusoids, a spherical
cap, and measured profiles read from files.

Surfaces are (ny, nx) float64 arrays, ``height[iy, ix] = r(x = ix*lx/nx, y = iy*ly/ny)``:
the C order of the Fortran library's flat fields with x fastest."""

from __future__ import annotations

import os

import numpy as np

from .native import core as _core
from .api import _CONSTANTS, NOT_SET, _check, _namelist

# Length of the Fortran scene's file-name fields (lc_scene max_string).
_MAX_STRING = 512
# The dataset of &profile when none is given (lc_scene profile_spec).
_DEFAULT_DATASET = "/profile/height"


def self_affine_profile(
    n: int,
    hurst: float | None = None,
    *,
    period: float | None = None,
    seed: int | None = None,
    rolloff_wavelength: float | None = None,
    short_wavelength: float | None = None,
    rms_gradient: float | None = None,
    rms_height: float | None = None,
) -> np.ndarray:
    """Seeded self-affine line profile of ``n`` heights on one ``period``: the heights of
    ``&profile kind='self_affine'``, made by the same routine from the same variables (a
    keyword not given takes the namelist default: hurst 0.8, seed 1, period 1).

    Power spectrum flat below the roll-off wavenumber (default: the period), ``~ q^(-1-2H)``
    up to the short cutoff (default: ``period/128``), zero beyond; random phases from
    SplitMix64 seeded with ``seed``; scaled to exactly ``rms_gradient`` or ``rms_height``
    (give at most one; neither: rms_gradient 0.1). Raises LayercontactError with the
    namelist's message for a value it does not allow.
    """
    text = _namelist({"scene": {"n": int(n), "period": period},
                      "profile": {"kind": "self_affine", "hurst": hurst, "seed": seed,
                                  "rolloff_wavelength": rolloff_wavelength, "short_wavelength": short_wavelength,
                                  "rms_gradient": rms_gradient, "rms_height": rms_height}})
    height, stat, errmsg = _core.py_make_profile(text, int(n))
    _check(stat, errmsg)
    return height


def sinusoid_profile(n: int, amplitude: float, *, mode: int | None = None, period: float | None = None) -> np.ndarray:
    """``amplitude * cos(2 pi mode x/period)`` on ``n`` points of one period, the heights
    of ``&profile kind='sinusoid'`` (``mode`` default 1, ``1 <= mode <= (n-1)/2``;
    ``period`` default 1; raises LayercontactError otherwise)."""
    text = _namelist({"scene": {"n": int(n), "period": period},
                      "profile": {"kind": "sinusoid", "amplitude": amplitude, "mode": mode}})
    height, stat, errmsg = _core.py_make_profile(text, int(n))
    _check(stat, errmsg)
    return height


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


def _surface_grid(n, period, nx, ny) -> tuple[int, int, float, float]:
    """``(nx, ny, lx, ly)`` from ``n`` (both sizes unless ``nx``/``ny`` are given) and
    ``period`` (one length for both axes, or a pair ``(lx, ly)``)."""
    nx = int(n if nx is None else nx)
    ny = int(n if ny is None else ny)
    lx, ly = (float(period), float(period)) if np.ndim(period) == 0 else map(float, period)
    return nx, ny, lx, ly


def self_affine_surface(
    n: int = 512,
    hurst: float | None = None,
    *,
    seed: int | None = None,
    short_wavelength: float | None = 1 / 64,
    rms_gradient: float | None = None,
    rms_height: float | None = None,
    period: float | tuple[float, float] = 1.0,
    rolloff_wavelength: float | None = None,
    nx: int | None = None,
    ny: int | None = None,
) -> np.ndarray:
    """Seeded isotropic self-affine surface, the heights of ``&profile kind='self_affine'``
    on an areal scene.

    Parameters
    ----------
    n : int
        Grid points along x and y (unless ``nx``, ``ny`` are given; each >= 4).
    hurst : float, optional
        Hurst exponent H, 0 < H < 1: power spectrum ``C(q) ~ |q|^(-2-2H)``; default that of
        ``&profile`` (0.8).
    seed : int, optional
        SplitMix64 seed (>= 0; default that of ``&profile``, 1); the phase of mode (mx, my) depends on the seed and the mode
        only, so a finer grid at the same ``short_wavelength`` gives the same surface.
    short_wavelength : float or None
        Shortest wavelength (L); None: ``min(lx, ly)/128``. Modes shorter than the grid
        allows are left out along with it (a round cut, keeping the surface isotropic).
    rms_gradient, rms_height : float, optional
        Scale target, met exactly on the grid; give at most one (neither: the rms_gradient
        of ``&profile``, 0.1).
    period : float or (float, float)
        Period (L), or the pair ``(lx, ly)``.
    rolloff_wavelength : float, optional
        Roll-off wavelength (L): the spectrum is flat at longer wavelengths; default
        ``max(lx, ly)`` (no flat part). On a rectangular cell the longest waves are not
        isotropic (their modes lie on a lattice of spacings 1/lx, 1/ly): a roll-off well
        below ``min(lx, ly)`` makes the surface isotropic.
    nx, ny : int, optional
        Grid points along x and y.

    Returns
    -------
    numpy.ndarray
        ``(ny, nx)`` heights (L), zero mean.
    """
    nx, ny, lx, ly = _surface_grid(n, period, nx, ny)
    # the defaults of &profile (lc_scene's profile_spec)
    hurst = float(_CONSTANTS["profile/hurst"]) if hurst is None else hurst
    seed = int(_CONSTANTS["profile/seed"]) if seed is None else seed
    if rms_gradient is None and rms_height is None:
        rms_gradient = float(_CONSTANTS["profile/rms_gradient"])
    height, stat, errmsg = _core.py_self_affine_surface(
        nx,
        ny,
        lx,
        ly,
        float(hurst),
        int(seed),
        NOT_SET if rolloff_wavelength is None else float(rolloff_wavelength),
        NOT_SET if short_wavelength is None else float(short_wavelength),
        NOT_SET if rms_gradient is None else float(rms_gradient),
        NOT_SET if rms_height is None else float(rms_height),
    )
    _check(stat, errmsg)
    return height.reshape(ny, nx)


def _make_surface(
    kind: str,
    nx: int,
    ny: int,
    lx: float,
    ly: float,
    *,
    amplitude=NOT_SET,
    mode=1,
    mode_y=0,
    radius=NOT_SET,
    path="",
    dataset=_DEFAULT_DATASET,
) -> np.ndarray:
    """The surface of an areal scene's &profile, made by the library's make_profile."""
    if len(path) > _MAX_STRING or len(dataset) > _MAX_STRING:
        raise ValueError(f"file and dataset names are limited to {_MAX_STRING} characters")
    height, stat, errmsg = _core.py_make_surface(
        kind,
        int(nx),
        int(ny),
        float(lx),
        float(ly),
        float(amplitude),
        int(mode),
        int(mode_y),
        float(radius),
        path,
        dataset,
    )
    _check(stat, errmsg)
    return height.reshape(ny, nx)


def sinusoid_surface(
    n: int,
    amplitude: float,
    *,
    mode: int | None = None,
    mode_y: int | None = None,
    period: float | tuple[float, float] | None = None,
    nx: int | None = None,
    ny: int | None = None,
) -> np.ndarray:
    """``amplitude * cos(2 pi (mode x/lx + mode_y y/ly))`` on an ``(ny, nx)`` grid, the
    heights of ``&profile kind='sinusoid'`` on an areal scene (``mode`` default 1,
    ``mode_y`` default 0; ``0 <= mode <= (nx-1)/2``, ``|mode_y| <= (ny-1)/2``, not both
    zero; raises LayercontactError otherwise)."""
    return _areal_profile(n, period, nx, ny, {"kind": "sinusoid", "amplitude": amplitude, "mode": mode,
                                              "mode_y": mode_y})


def spherical_cap(
    n: int,
    radius: float,
    *,
    period: float | tuple[float, float] | None = None,
    nx: int | None = None,
    ny: int | None = None,
) -> np.ndarray:
    """Spherical cap of ``radius`` R with its apex (height 0, the maximum) at the grid
    point ``(ix, iy) = (nx//2, ny//2)``: ``sqrt(R^2 - rho^2) - R`` within the distance R of
    the apex, ``-R`` beyond; the heights of ``&profile kind='sphere'``."""
    return _areal_profile(n, period, nx, ny, {"kind": "sphere", "radius": radius})


def _areal_profile(n, period, nx, ny, profile: dict) -> np.ndarray:
    """The heights of an areal scene's &profile variables ``profile`` (the library's
    make_profile, from namelist text: its defaults and checks), ``(ny, nx)``."""
    nx, ny = int(n if nx is None else nx), int(n if ny is None else ny)
    lx, ly = (period, None) if np.ndim(period) == 0 else (float(period[0]), float(period[1]))
    text = _namelist({"scene": {"geometry": "areal", "nx": nx, "ny": ny, "period": lx, "period_y": ly},
                      "profile": profile})
    height, stat, errmsg = _core.py_make_profile(text, nx * ny)
    _check(stat, errmsg)
    return height.reshape(ny, nx)


def read_surface(path: str | os.PathLike, nx: int, ny: int, dataset: str | None = None) -> np.ndarray:
    """Heights of a surface file read by the library for an ``nx`` x ``ny`` areal scene
    (``&profile kind='file'``): ``.h5``/``.hdf5`` (a 2D dataset ``[ny, nx]``), ``.npy``
    (``'<f8'``, C order, shape ``(ny, nx)``) or text (ny lines of nx numbers). Raises
    LayercontactError (code 2 bad content, 4 unreadable file) with the library's message.
    """
    return _make_surface(
        "file",
        nx,
        ny,
        1.0,
        1.0,
        path=os.fspath(path),
        dataset=_DEFAULT_DATASET if dataset is None else dataset,
    )


def load_surface(path: str | os.PathLike, dataset: str | None = None) -> np.ndarray:
    """Heights of a surface file as a ``(ny, nx)`` array, by the rules of the library's
    reader (:func:`read_surface`, which also checks the grid size).

    ``.h5``/``.hdf5``: the 2D floating-point ``dataset`` (default ``/profile/height``);
    ``.npy``: dtype ``'<f8'``, C order, 2D; anything else: text, one row of x per line
    (blank lines and ``#`` comments skipped). Every height must be finite. Raises
    ValueError for content that breaks these rules and OSError for unreadable files.
    """
    path = os.fspath(path)
    lowered = path.lower()
    if lowered.endswith((".h5", ".hdf5")):
        import h5py

        dataset = _DEFAULT_DATASET if dataset is None else dataset
        with h5py.File(path, "r") as f:
            if dataset not in f:
                raise ValueError(f"{path}: no dataset {dataset!r}")
            data = f[dataset]
            if data.ndim != 2 or data.dtype.kind != "f":
                raise ValueError(
                    f"{path}, dataset {dataset!r}: shape {data.shape}, dtype {data.dtype}; "
                    "allowed: a 2D floating-point dataset of shape (ny, nx)"
                )
            h = np.asarray(data[()], dtype=np.float64)
    elif lowered.endswith(".npy"):
        h = np.load(path, allow_pickle=False)
        if h.dtype.str != "<f8":
            raise ValueError(f"{path}: dtype {h.dtype.str!r}; allowed: '<f8' (little-endian float64)")
        # numpy.save writes fortran_order = True exactly for these arrays
        if np.isfortran(h):
            raise ValueError(f"{path}: fortran_order = True; allowed: C order (numpy.ascontiguousarray)")
        if h.ndim != 2:
            raise ValueError(f"{path}: shape {h.shape}; allowed: a 2D array of shape (ny, nx)")
    else:
        h = np.loadtxt(path, ndmin=2)
    if not np.all(np.isfinite(h)):
        raise ValueError(f"{path}: non-finite heights; allowed: finite heights")
    return np.ascontiguousarray(h, dtype=np.float64)
