"""Instrument topographies (profilometers, AFM, optical interferometers) read through the
optional SurfaceTopography package (``pip install 'layercontact[topography]'``), and the
HDF5 height file that ``&profile kind='file'`` reads, so that the executable and batch
jobs without Python can use them (docs/topographies.md).

Heights and sizes come out in one length unit (the file's, or the one asked for): that unit
is the scene's length unit L, so ``&scene period`` and the layer's thickness must be given
in it too.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

#: What to install when SurfaceTopography is missing.
EXTRA_HINT = "pip install 'layercontact[topography]'"


@dataclass(frozen=True)
class Topography:
    """A measured topography on a uniform grid.

    Attributes
    ----------
    height : numpy.ndarray
        Heights (``unit``): 1D for a line scan, ``(ny, nx)`` for a map (x along the rows).
    size : tuple of float
        Physical size along x (and y) (``unit``): the measured length, n grid steps; NaN
        when the file states none.
    unit : str
        Length unit of ``height`` and ``size`` ('' when the file states none).
    periodic : bool
        True when the file says the data are periodic (simulated surfaces); measured
        patches are not, and need ``&profile boundary = 'mirror'`` (or a periodic cut).
    source : str
        The file read, with the channel.
    """

    height: np.ndarray
    size: tuple[float, ...]
    unit: str
    periodic: bool
    source: str


def _open_topography():
    """SurfaceTopography's file opener, or ImportError naming the extra to install."""
    try:
        from SurfaceTopography.IO import open_topography
    except ImportError as error:
        raise ImportError(
            "reading instrument topography files needs the SurfaceTopography package: " + EXTRA_HINT
        ) from error
    return open_topography


def read_topography(path: str | os.PathLike, *, unit: str | None = None, channel: int | None = None) -> Topography:
    """Read an instrument topography file with SurfaceTopography (the formats it reads:
    x3p, Zygo datx, Digital Instruments/Bruker, Gwyddion gwy, Keyence vk4, Sensofar plu,
    Alicona al3d, MountainsMap sur, OPD, ...).

    Parameters
    ----------
    path : str or path-like
        The file.
    unit : str, optional
        Length unit to convert heights and sizes to ('m', 'mm', 'um', 'nm', ...); default:
        the file's.
    channel : int, optional
        Data channel of a file holding several (default: the file's default channel).

    Returns
    -------
    Topography
        Heights, physical size, unit and periodicity. Raises ImportError (with the
        command to install the extra) when SurfaceTopography is missing, and ValueError
        for a file with undefined (missing) points, which a contact solve cannot take.
    """
    open_topography = _open_topography()
    path = os.fspath(path)
    reader = open_topography(path)
    index = reader.default_channel.index if channel is None else int(channel)
    topography = reader.topography(channel_index=index)
    if unit is not None:
        if topography.unit is None:
            raise ValueError(f"{path}: the file states no length unit, so it cannot be converted to {unit!r}")
        topography = topography.to_unit(unit)
    if getattr(topography, "has_undefined_data", False):
        raise ValueError(
            f"{path}: the topography has undefined (missing) points; fill them first, e.g. with "
            "SurfaceTopography's interpolate_undefined_data()"
        )
    # SurfaceTopography indexes heights [ix, iy]; the (ny, nx) layout has x along the rows
    height = np.asarray(topography.heights(), dtype=np.float64)
    if height.ndim == 2:
        height = height.T
    # some formats state no physical size: then the scene's period is the user's to give
    sizes = topography.physical_sizes
    sizes = sizes if sizes is not None else [None] * height.ndim
    size = tuple(float("nan") if s is None else float(s) for s in sizes)
    return Topography(
        height=np.ascontiguousarray(height),
        size=size,
        unit=topography.unit or "",
        periodic=bool(topography.is_periodic),
        source=f"{path} (channel {index})",
    )


def write_height_file(path: str | os.PathLike, topography: Topography, dataset: str = "/profile/height") -> None:
    """Write a topography as the HDF5 height file ``&profile kind='file'`` reads: the
    heights in ``dataset`` (1D, or ``[ny, nx]``), with the attributes ``unit``, ``size``
    (the physical size, x first), ``periodic`` and ``source`` for the record (the solver
    reads the heights only: the period is the scene's)."""
    import h5py

    with h5py.File(os.fspath(path), "w") as f:
        data = f.create_dataset(dataset, data=np.asarray(topography.height, dtype=np.float64))
        data.attrs["unit"] = topography.unit
        data.attrs["size"] = np.asarray(topography.size, dtype=np.float64)
        data.attrs["periodic"] = int(topography.periodic)
        data.attrs["source"] = topography.source


def scene_lines(topography: Topography, file: str) -> str:
    """The &scene and &profile lines that run a converted topography: a periodic file as
    one period, a measured patch mirrored (period and points doubled)."""
    h = np.asarray(topography.height)
    factor = 1 if topography.periodic else 2
    unit = f"({topography.unit})" if topography.unit else "(the file's length unit)"
    sized = bool(np.all(np.isfinite(topography.size)))

    def period(name: str, length: float, note: str = "") -> str:
        # a file that states no size gets no period line (a NaN would be bad input), only a note
        if not sized:
            return f"   ! {name} = ? (the file states no size: give it in the heights' unit)"
        return f"   {name} = {factor * length!r}" + (f"   ! {note}" if note else "")

    lines = ["&scene"]
    if h.ndim == 2:
        ny, nx = h.shape
        lines += ["   geometry = 'areal'", f"   nx = {factor * nx}", f"   ny = {factor * ny}",
                  period("period", topography.size[0], unit), period("period_y", topography.size[1])]
    else:
        lines += [f"   n = {factor * h.size}", period("period", topography.size[0], unit)]
    lines += ["/", "&profile", "   kind = 'file'", f"   file = '{file}'"]
    if not topography.periodic:
        lines += ["   boundary = 'mirror'   ! a measured patch: it and its mirror images make the period"]
    lines += ["/"]
    return "\n".join(lines)
