"""Pythonic API over the Fortran library: validation and unit handling stay thin, the
Fortran messages become exceptions, results come back as plain dataclasses."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from . import _core

NOT_SET = -1.0
_CONTROLS = {"load": 0, "displacement": 1}
_METHODS = {"auto": 0, "cg": 1, "anderson": 2}


class LayercontactError(RuntimeError):
    """An error reported by the Fortran library. ``code`` is the executable's exit code
    for it (2 bad input, 4 I/O, 5 internal)."""

    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


def _check(stat: int, errmsg: bytes | str) -> None:
    if stat != 0:
        text = errmsg.decode() if isinstance(errmsg, bytes) else str(errmsg)
        raise LayercontactError(text.strip(), int(stat))


def layer_multipliers(kh, nu: float):
    """Convention-P layer factors ``(1-A, 1-B, c)`` for ``kh = |k| h`` (array, >= 0;
    ``inf`` gives the half-space) and Poisson ratio ``-1 < nu <= 0.5``.

    ``w^ = 2/(E*|k|) [(1-A) p^ - i sgn(k) c tau^]``,
    ``u_x^ = 2/(E*|k|) [i sgn(k) c p^ + (1-B) tau^]``.
    """
    kh = np.ascontiguousarray(np.atleast_1d(np.asarray(kh, dtype=np.float64)))
    if not -1.0 < nu <= 0.5:
        raise ValueError(f"nu = {nu} is not allowed; allowed: -1 < nu <= 0.5")
    if np.any(~(kh >= 0)):
        raise ValueError("kh must be >= 0 (inf allowed for the half-space)")
    return _core.py_layer_coefficients(kh, float(nu))


def layer_multipliers_lapack(kh, nu: float):
    """The same factors from the 4x4 plane-strain problem of one Fourier mode solved with
    LAPACK (an independent check; valid for 1e-3 <= kh <= 20)."""
    kh = np.ascontiguousarray(np.atleast_1d(np.asarray(kh, dtype=np.float64)))
    a, b, c, stat, errmsg = _core.py_layer_coefficients_lapack(kh, float(nu))
    _check(stat, errmsg)
    return a, b, c


@dataclass
class LineResult:
    """A solved line contact. Units are those of the inputs: lengths L, pressures S.

    Fields are on the grid ``x_j = j period/n``; ``gap = w - (r - Lambda + Delta)``.
    """

    pressure: np.ndarray
    gap: np.ndarray
    displacement_z: np.ndarray
    height: np.ndarray
    period: float
    friction: float
    mean_pressure: float
    penetration: float
    contact_fraction: float
    delta_mu: float
    delta_mu_spectral: float
    delta_mu_energy: float
    delta_mu_profile: float
    converged: bool
    iterations: int
    outer_iterations: int
    fft_pairs: int
    residual: float
    wall_time: float
    residual_history: np.ndarray = field(repr=False)

    @property
    def x(self) -> np.ndarray:
        """Grid positions (L)."""
        return np.arange(self.pressure.size) * (self.period / self.pressure.size)


def solve_line(
    heights,
    *,
    period: float = 1.0,
    thickness: float = np.inf,
    young: float = 1.0,
    poisson: float = 0.5,
    friction: float = 0.0,
    mean_pressure: float | None = None,
    penetration: float | None = None,
    method: str = "auto",
    precondition: bool = True,
    tol: float = 1e-10,
    max_iter: int = 20000,
    memory: int = 12,
    threads: int = 1,
) -> LineResult:
    """Solve the sliding line contact of the rigid profile ``heights`` (L, on a uniform
    periodic grid of one ``period``) on a layer of ``thickness`` (``inf``: half-space)
    bonded to a rigid base, with Coulomb friction ``tau = friction * p``.

    ``precondition`` applies the Fourier stiffness 1/M to the residual on the contact set
    (fewer iterations, nearly flat in the grid size; see bench/iterations.py). Give
    ``mean_pressure`` (load control) or ``penetration`` (displacement control, finite
    compressible layers only). Raises :class:`LayercontactError` with the library's
    message for bad input. A run that did not reach ``tol`` returns with
    ``converged = False``.
    """
    h = np.ascontiguousarray(np.asarray(heights, dtype=np.float64))
    if h.ndim != 1:
        raise ValueError("heights must be one-dimensional (line contact)")
    if (mean_pressure is None) == (penetration is None):
        raise ValueError("give exactly one of mean_pressure (load control) and penetration")
    if method not in _METHODS:
        raise ValueError(f"method = {method!r} is not allowed; allowed: {sorted(_METHODS)}")
    control = "load" if mean_pressure is not None else "displacement"
    pm = NOT_SET if mean_pressure is None else float(mean_pressure)
    pen = NOT_SET if penetration is None else float(penetration)
    p, g, w, s, hist, stat, errmsg = _core.py_solve_line(
        h, float(period), float(thickness), float(young), float(poisson), float(friction),
        _CONTROLS[control], pm, pen, _METHODS[method], int(bool(precondition)), float(tol), int(max_iter),
        int(memory), int(threads),
    )
    _check(stat, errmsg)
    return LineResult(
        pressure=p, gap=g, displacement_z=w, height=h.copy(), period=float(period), friction=float(friction),
        mean_pressure=s[0], penetration=s[1], contact_fraction=s[2], delta_mu=s[3], delta_mu_spectral=s[4],
        delta_mu_energy=s[5], delta_mu_profile=s[13], converged=bool(s[6]), iterations=int(s[7]), outer_iterations=int(s[8]),
        fft_pairs=int(s[9]), residual=s[10], wall_time=s[11], residual_history=hist[: int(s[12])].copy(),
    )


def read_result(filename: str | os.PathLike, companion: bool = False) -> LineResult:
    """Read a result file written by the executable or :func:`run` (``companion=True``:
    the frictionless companion run stored in it)."""
    import h5py

    with h5py.File(filename, "r") as f:
        base = f["companion"] if companion else f
        r = dict(base["results"].attrs)
        fields = base["fields"]
        return LineResult(
            pressure=fields["pressure"][()], gap=fields["gap"][()], displacement_z=fields["displacement_z"][()],
            height=f["profile/height"][()], period=float(f["input"].attrs["period"]),
            friction=float(r["friction"]), mean_pressure=float(r["mean_pressure"]),
            penetration=float(r["penetration"]), contact_fraction=float(r["contact_fraction"]),
            delta_mu=float(r["delta_mu"]), delta_mu_spectral=float(r["delta_mu_spectral"]),
            delta_mu_energy=float(r["delta_mu_energy"]), delta_mu_profile=float(r["delta_mu_profile"]),
            converged=bool(r["converged"]),
            iterations=int(r["iterations"]), outer_iterations=int(r.get("outer_iterations", 1)),
            fft_pairs=int(r["fft_pairs"]), residual=float(r["residual"]), wall_time=float(r["wall_time"]),
            residual_history=base["convergence/residual"][()],
        )


def check_scene_file(filename: str | os.PathLike) -> None:
    """Read and validate a namelist file without solving; raises :class:`LayercontactError`
    with the message the executable would print."""
    stat, errmsg = _core.py_check_scene_file(os.fspath(filename))
    _check(stat, errmsg)


def run(filename: str | os.PathLike, verbose: bool = False) -> LineResult:
    """Run a namelist file exactly as the ``layercontact`` executable does (same library
    routine): the HDF5 result is written where ``&output file`` says, and read back.
    Raises :class:`LayercontactError` on bad input (nothing is written)."""
    out, converged, stat, errmsg = _core.py_run(os.fspath(filename), 1 if verbose else 0)
    _check(stat, errmsg)
    return read_result(out.decode().strip() if isinstance(out, bytes) else str(out).strip())
