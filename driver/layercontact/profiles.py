"""Rigid profiles and surfaces: seeded self-affine synthesis (the Fortran routines, so that
a namelist run and Python give the same heights for the same seed), sinusoids, a spherical
cap, and measured profiles read from files by the library's reader (the one a namelist run
uses, so that both take the same files by the same rules; docs/topographies.md).

Surfaces are (ny, nx) float64 arrays, ``height[iy, ix] = r(x = ix*lx/nx, y = iy*ly/ny)``:
the C order of the Fortran library's flat fields with x fastest."""

from __future__ import annotations

import os
import warnings

import numpy as np

from .native import core as _core
from ._library import _CONSTANTS, NOT_SET, LayercontactError, PeriodicityWarning, _check, _namelist, grid_points, \
    grid_size, periods, real_array

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
    n = grid_points(n, "n")
    grid_size(n, 1)
    text = _namelist({"scene": {"n": n, "period": period},
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
    n = grid_points(n, "n")
    grid_size(n, 1)
    text = _namelist({"scene": {"n": n, "period": period},
                      "profile": {"kind": "sinusoid", "amplitude": amplitude, "mode": mode}})
    height, stat, errmsg = _core.py_make_profile(text, int(n))
    _check(stat, errmsg)
    return height


def load_profile(path: str | os.PathLike, dataset: str = "/profile/height") -> np.ndarray:
    """Heights of a line profile file, as the library reads them for
    ``&profile kind='file'`` of a line scene: a file of one row or one column.

    ``.h5``/``.hdf5``: the floating-point ``dataset`` (1D, or 2D of one row or column);
    ``.npy``: dtype ``'<f8'``, C order; anything else: text, one number per line or one
    line of numbers (blank lines and ``#`` comments skipped). Every height must be finite.
    Raises ValueError for content that breaks these rules and OSError for unreadable files.
    """
    return _as_read(path, dataset, areal=False)


def _as_read(path: str | os.PathLike, dataset: str | None, *, areal: bool) -> np.ndarray:
    """The heights of a file as the library takes them for a line (1D) or a surface
    ((ny, nx)) at the file's own size, untreated (its shape rules and messages); its errors
    as ValueError (bad content) or OSError (unreadable file)."""
    path = os.fspath(path)
    dataset = _DEFAULT_DATASET if dataset is None else dataset
    if len(path) > _MAX_STRING or len(dataset) > _MAX_STRING:
        raise ValueError(f"file and dataset names are limited to {_MAX_STRING} characters")
    try:
        nx, ny, stat, errmsg = _core.py_height_file_shape(path, dataset)
        _check(stat, errmsg)
        if not areal:
            nx, ny = nx * ny, 1
        height = _measured(path, dataset, areal, "none", "periodic", "none", nx, ny)
    except LayercontactError as error:
        kind = OSError if error.code == 4 else ValueError
        raise kind(str(error)) from None
    return height.reshape(ny, nx) if areal else height


def _surface_grid(n, period, nx, ny) -> tuple[int, int, float, float]:
    """``(nx, ny, lx, ly)`` from ``n`` (both sizes unless ``nx``/``ny`` are given) and
    ``period`` (one length for both axes, or a pair ``(lx, ly)``)."""
    nx = grid_points(n if nx is None else nx, "n" if nx is None else "nx")
    ny = grid_points(n if ny is None else ny, "n" if ny is None else "ny")
    grid_size(nx, ny)
    lx, ly = periods(period)
    return nx, ny, lx, ly


def self_affine_surface(
    n: int = 512,
    hurst: float | None = None,
    *,
    seed: int | None = None,
    short_wavelength: float | None = None,
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
    short_wavelength : float, optional
        Shortest wavelength (L); default that of ``&profile``, ``min(lx, ly)/128``. Modes
        shorter than the grid allows are left out along with it (a round cut, keeping the
        surface isotropic).
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
    try:
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
    except MemoryError:
        # (the heights and their half spectrum: 16 bytes a point)
        raise LayercontactError(f"self_affine_surface: {nx} x {ny} points need about {16*nx*ny/2**30:.1f} GiB, "
                                "more than this process may allocate; allowed: a smaller grid", 5) from None
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


def read_surface(
    path: str | os.PathLike,
    nx: int,
    ny: int,
    dataset: str | None = None,
    *,
    detrend: str = "auto",
    boundary: str = "periodic",
    resample: str = "none",
) -> np.ndarray:
    """Heights of a surface file on an ``nx`` x ``ny`` grid, made by the library exactly as
    ``&profile kind='file'`` of an areal scene makes them.

    The file: ``.h5``/``.hdf5`` (a 2D dataset ``[ny, nx]``), ``.npy`` (``'<f8'``, C order,
    2D) or text (lines of numbers, one row of x per line). Then, as in the namelist
    (docs/topographies.md): ``detrend`` (``'auto'``, ``'none'``, ``'mean'``, ``'plane'``,
    ``'curvature'``), ``boundary`` (``'periodic'``: the file is one period; ``'mirror'``:
    the patch and its mirror images, twice as many points each way) and ``resample``
    (``'none'``: the file must have the grid's size; ``'fourier'``: Fourier
    interpolation or truncation onto the grid). Raises LayercontactError (code 2 bad
    content, 4 unreadable file) with the library's message.
    """
    return _measured(path, dataset, True, detrend, boundary, resample, nx, ny).reshape(ny, nx)


def read_profile(
    path: str | os.PathLike,
    n: int,
    dataset: str | None = None,
    *,
    detrend: str = "auto",
    boundary: str = "periodic",
    resample: str = "none",
) -> np.ndarray:
    """Heights of a line profile file on a grid of ``n`` points, made by the library
    exactly as ``&profile kind='file'`` of a line scene makes them: a file of one row or
    one column, then ``detrend``, ``boundary`` and ``resample`` as in
    :func:`read_surface`. Raises LayercontactError (code 2 bad content, 4 unreadable file).
    """
    return _measured(path, dataset, False, detrend, boundary, resample, n, 1)


#: Limits of :func:`periodicity_mismatch` above which heights taken as one period are
#: suspect (the library's edge_jump_limit and edge_kink_limit, lc_profiles_measured;
#: measured in docs/decisions/019).
EDGE_JUMP_LIMIT = 2.0
EDGE_KINK_LIMIT = 4.0


def periodicity_mismatch(height) -> tuple[float, float]:
    """How far heights taken as one period are from periodic: ``(jump, kink)``, the larger
    value along x and along y (an axis of fewer than 16 points is not measured).

    ``jump`` is the rms over the rows of the step across the cell's edge,
    ``h[0] - h[n-1]``, in rms heights (about the mean): a tilted plane gives
    ``sqrt(12) (n-1)/n``. ``kink`` is the rms over the rows of the mismatch of the slopes
    across the edge, the second difference ``h[m] - 2 h[0] + h[n-m]`` over
    ``m = max(2, n//16)`` points of the periodic continuation, in units of the rms of the
    same second difference at the points at least ``2m`` from the edges: about 1 for a
    periodic surface, large for a kink that the cell does not have elsewhere (``inf`` on a
    smooth cell). The library warns of a height file taken as periodic above
    :data:`EDGE_JUMP_LIMIT` or :data:`EDGE_KINK_LIMIT` (the same measure, in Fortran).
    """
    h = np.atleast_2d(np.asarray(height, dtype=np.float64))
    rms = float(np.sqrt(np.mean((h - h.mean()) ** 2)))
    jump = kink = 0.0
    if not rms > 0:
        return jump, kink
    for rows in (h, h.T):   # each row along the axis measured: x, then y
        n = rows.shape[1]
        if n < 16:
            continue
        m = max(2, n // 16)
        jump = max(jump, float(np.sqrt(np.mean((rows[:, 0] - rows[:, -1]) ** 2))) / rms)
        edge = float(np.mean((rows[:, m] - 2 * rows[:, 0] + rows[:, n - m]) ** 2))
        j = np.arange(2 * m, n - 2 * m)
        inside = float(np.mean((rows[:, j + m] - 2 * rows[:, j] + rows[:, j - m]) ** 2)) if j.size else 0.0
        kink = max(kink, np.sqrt(edge / inside) if inside > 0 else (np.inf if edge > 0 else 0.0))
    return jump, kink


def warn_if_not_periodic(height, file: str) -> None:
    """A :class:`PeriodicityWarning` when heights from ``file`` taken as one period exceed the
    limits of :func:`periodicity_mismatch`."""
    jump, kink = periodicity_mismatch(height)
    if jump > EDGE_JUMP_LIMIT or kink > EDGE_KINK_LIMIT:
        warnings.warn(f"&profile: file = '{file}' is taken as one period (boundary = 'periodic'), but its heights "
                      f"jump by {jump:.2f} rms heights across the edges of the cell and their slopes differ there "
                      f"by {kink:.2e} times their differences inside it: a tilted or non-periodic surface; set "
                      "&profile boundary = 'mirror' (a non-periodic patch, detrended by a plane) or detrend = "
                      "'plane' (a tilt)", PeriodicityWarning, stacklevel=4)


def _measured(path, dataset, areal, detrend, boundary, resample, nx, ny) -> np.ndarray:
    path = os.fspath(path)
    dataset = _DEFAULT_DATASET if dataset is None else dataset
    if len(path) > _MAX_STRING or len(dataset) > _MAX_STRING:
        raise ValueError(f"file and dataset names are limited to {_MAX_STRING} characters")
    height, stat, errmsg = _core.py_measured_heights(
        path, dataset, int(areal), str(detrend), str(boundary), str(resample), int(nx), int(ny)
    )
    _check(stat, errmsg)
    if boundary == "periodic":
        warn_if_not_periodic(height.reshape(ny, nx), path)
    return height


def prepare_heights(
    height,
    *,
    shape: int | tuple[int, int] | None = None,
    detrend: str = "auto",
    boundary: str = "periodic",
) -> np.ndarray:
    """Measured heights made ready for a periodic solve by the library's routines (those of
    ``&profile detrend``, ``boundary`` and ``resample``; docs/topographies.md).

    Parameters
    ----------
    height : array_like
        A line profile (1D) or a surface ``(ny, nx)`` (L).
    shape : int or (int, int), optional
        The grid to resample onto by Fourier interpolation or truncation: ``n`` for a line,
        ``(ny, nx)`` for a surface; None keeps the size (twice the size with ``'mirror'``).
    detrend : str
        ``'auto'`` (``'none'`` for ``'periodic'``, ``'plane'`` for ``'mirror'``), ``'none'``,
        ``'mean'``, ``'plane'`` or ``'curvature'``: the least-squares polynomial subtracted.
    boundary : str
        ``'periodic'`` (the heights are one period) or ``'mirror'`` (the patch and its mirror
        images: the period is twice the patch's length along each axis).

    Returns
    -------
    numpy.ndarray
        The heights, 1D for a line, ``(ny, nx)`` for a surface. Raises LayercontactError
        (code 2) for a bad value.
    """
    raw = real_array(height, "height", ndim=(1, 2))
    areal = raw.ndim == 2
    factor = 2 if boundary == "mirror" else 1
    if shape is None:
        ny, nx = (raw.shape[0] * factor, raw.shape[1] * factor) if areal else (1, raw.shape[0] * factor)
        resample = "none"
    else:
        ny, nx = (int(shape[0]), int(shape[1])) if areal else (1, int(shape))
        resample = "fourier"
    mx = raw.shape[-1]
    out, stat, errmsg = _core.py_prepare_heights(
        np.ascontiguousarray(raw).ravel(), mx, int(areal), str(detrend), str(boundary), resample, nx, ny
    )
    _check(stat, errmsg)
    return out.reshape(ny, nx) if areal else out


def load_surface(path: str | os.PathLike, dataset: str | None = None) -> np.ndarray:
    """Heights of a surface file as a ``(ny, nx)`` array, read by the library's reader (the
    one of ``&profile kind='file'``; :func:`read_surface` also fits them to a grid).

    ``.h5``/``.hdf5``: the 2D floating-point ``dataset`` (default ``/profile/height``);
    ``.npy``: dtype ``'<f8'``, C order, 2D; anything else: text, one row of x per line
    (blank lines and ``#`` comments skipped). Every height must be finite. Raises
    ValueError for content that breaks these rules and OSError for unreadable files.
    """
    return _as_read(path, dataset, areal=True)
