"""Pythonic API over the Fortran library: validation and unit handling stay thin, the
Fortran messages become exceptions, results come back as plain dataclasses."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field

import numpy as np

from .leakage import CoreLeakage
from .native import core as _core

# The library's "not given" (lc_scene's not_set): a value nobody types.
NOT_SET = -sys.float_info.max
_CONTROLS = {"load": 0, "displacement": 1}
_METHODS = {"auto": 0, "cg": 1, "anderson": 2, "gcr": 3, "gfmd": 4}
# Order of the scalars returned by the wrapper py_solve (driver/wrappers.f90).
_SCALARS = (
    "mean_pressure", "penetration", "contact_fraction", "delta_mu", "delta_mu_spectral", "delta_mu_energy",
    "delta_mu_profile", "converged", "iterations", "outer_iterations", "fft_pairs", "residual", "wall_time",
    "history_length", "n_spots", "contact_length", "mean_gap", "leak_rate", "max_tension", "max_tension_x",
    "max_tension_offset", "dissipated_power", "monotone", "pressure_shift", "summit_shift",
    "max_tension_grid", "solver", "normalised_pressure", "normalised_thickness", "max_tension_y",
    "max_principal_stress", "max_principal_x", "max_principal_y", "gap_resolution",
)
# The solver that ran, by the code in the scalars (driver/wrappers.f90 `solvers`).
_SOLVERS = {1: "cg", 2: "gcr", 3: "anderson", 4: "gcr+anderson", 5: "gfmd"}
_INTEGERS = ("iterations", "outer_iterations", "fft_pairs", "n_spots")
# Residuals returned per solve (the last ones): a max_iter-long array would cost more than
# a small solve.
HISTORY_CAPACITY = 10000


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


def surface_tensor(qx, qy, *, thickness=np.inf, young=1.0, poisson=0.5):
    """The layer's 3x3 surface compliance for in-plane wavevectors ``(qx, qy)`` (1/L,
    broadcast together): ``(u_x^, u_y^, w^) = T (tau_x^, tau_y^, p^)`` in convention P,
    shape ``broadcast.shape + (3, 3)``, complex. In the frame ``(l, t, z)`` with
    ``l = q/|q|`` it is the plane-strain multiplier with ``|k| -> |q|`` in ``(l, z)`` and the
    antiplane compliance ``tanh(|q|h)/(G|q|)`` along ``t``; ``q = 0`` gives the uniform mode
    ``(h/G, h/G, h/M)`` of a layer (zero for a half-space)."""
    qx, qy = np.broadcast_arrays(np.asarray(qx, dtype=np.float64), np.asarray(qy, dtype=np.float64))
    if not -1.0 < poisson <= 0.5:
        raise ValueError(f"poisson = {poisson} is not allowed; allowed: -1 < poisson <= 0.5")
    t = _core.py_surface_tensor(np.ascontiguousarray(qx.ravel()), np.ascontiguousarray(qy.ravel()),
                                float(thickness), float(young), float(poisson))
    return t.reshape(qx.shape + (3, 3))


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

    Fields are on the grid ``x_j = j period/n``; ``gap = w - (r - Lambda + Delta)``;
    ``displacement_x``, ``shear`` and ``stress_xx`` (surface in-plane stress, tension
    positive) are ``None`` when not asked for. ``spots`` is an ``(n_spots, 2)`` array of
    trailing (-x) and leading (+x) edges; ``leak_rate = <g^3>/12`` is the flow across the
    sliding direction per unit length, per unit pressure gradient, times the viscosity.
    ``max_tension`` (and ``spot_max_tension`` per spot) resolve the square-root cusp of
    ``stress_xx`` at a trailing edge sub-grid when there is friction; ``max_tension_grid``
    (``spot_max_tension_grid``) is the largest grid value.
    ``a_over_a0`` and ``companion`` are set when a frictionless companion was solved.
    ``solver`` names the method that ran: ``'cg'`` (symmetric scenes), ``'gcr'`` (coupled
    scenes), ``'anderson'``, or ``'gcr+anderson'`` (GCR stalled and the Anderson outer
    iteration went on from its best iterate). ``iterations`` counts CG or GCR iterations
    (all inner CG iterations for Anderson). ``residual_history`` holds the residual per
    iteration (per outer iteration for Anderson); from :func:`solve_line`, the last
    ``HISTORY_CAPACITY`` (10000) of them.
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
    contact_length: float
    delta_mu: float
    delta_mu_spectral: float
    delta_mu_energy: float
    delta_mu_profile: float
    converged: bool
    iterations: int
    outer_iterations: int
    solver: str
    fft_pairs: int
    residual: float
    wall_time: float
    residual_history: np.ndarray = field(repr=False)
    #: the smallest gap, relative to the profile's height range, that double precision
    #: resolves at this load; above ``tol`` the run reports ``converged = False``
    gap_resolution: float = 0.0
    n_spots: int = 0
    spots: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    mean_gap: float = float("nan")
    leak_rate: float = float("nan")
    displacement_x: np.ndarray | None = field(default=None, repr=False)
    shear: np.ndarray | None = field(default=None, repr=False)
    stress_xx: np.ndarray | None = field(default=None, repr=False)
    spot_max_tension: np.ndarray | None = field(default=None, repr=False)
    spot_tension_offset: np.ndarray | None = field(default=None, repr=False)
    spot_max_tension_grid: np.ndarray | None = field(default=None, repr=False)
    max_tension: float = float("nan")
    max_tension_grid: float = float("nan")
    max_tension_x: float = float("nan")
    max_tension_offset: float = float("nan")
    dissipated_power: float = 0.0
    monotone: bool = True
    pressure_shift: float = 0.0
    summit_shift: float = 0.0
    normalised_pressure: float = float("nan")
    normalised_thickness: float = float("nan")
    a_over_a0: float | None = None
    companion: "LineResult | None" = field(default=None, repr=False)

    @property
    def total_friction(self) -> float:
        """mu_c + Delta mu: the macroscopic friction coefficient."""
        return self.friction + self.delta_mu

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
    material=None,
    speed: float = 0.0,
    companion: bool = False,
    stress: bool = True,
    method: str = "auto",
    precondition: bool = True,
    coarse_start: bool = True,
    progress: bool = False,
    tol: float = 1e-10,
    max_iter: int = 100000,
    memory: int = 12,
    threads: int = 1,
) -> LineResult:
    """Solve the sliding line contact of the rigid profile ``heights`` (L, on a uniform
    periodic grid of one ``period``) on a layer of ``thickness`` (``inf``: half-space)
    bonded to a rigid base, with Coulomb friction ``tau = friction * p``.

    Give ``mean_pressure`` (load control) or ``penetration`` (displacement control, finite
    compressible layers only). ``material`` (a :class:`StandardLinearSolid` or
    :class:`Prony`; ``young`` is then ignored) makes the layer viscoelastic, sliding at
    ``speed`` (L/T); ``dissipated_power`` and ``monotone`` (``Re G_eff >= 0`` on every mode,
    hence a unique solution) are reported. ``companion=True`` also solves the frictionless problem at
    the same load and sets ``a_over_a0`` and ``companion``. ``stress`` computes
    ``displacement_x``, ``shear`` and the surface stress ``stress_xx`` (one more FFT pair).
    ``method``: ``'auto'`` (constrained CG for symmetric scenes, constrained GCR for coupled
    ones, going on with Anderson if GCR stalls), ``'cg'``, ``'gcr'`` or ``'anderson'``.
    ``precondition`` applies the Fourier stiffness 1/M to the residual on the contact set
    (fewer CG iterations). ``coarse_start`` starts from the solution on the grid of every
    second point, recursively down to 512 points (fine-grid iterations nearly flat in
    the grid size; see bench/iterations.py). ``progress=True`` prints a line to standard
    error for each grid level solved and every 2 s within a level (iteration, residual,
    contact fraction, elapsed time): it comes from the compiled core, so it shows in a
    terminal, not in a notebook cell.
    Raises :class:`LayercontactError` with the library's message for bad input. A run that
    did not reach ``tol`` returns with ``converged = False``.
    """
    h = np.ascontiguousarray(np.asarray(heights, dtype=np.float64))
    if h.ndim != 1:
        raise ValueError("heights must be one-dimensional (line contact); use solve_areal for a surface")
    if (mean_pressure is None) == (penetration is None):
        raise ValueError("give exactly one of mean_pressure (load control) and penetration")
    settings = dict(period=period, thickness=thickness, young=young, poisson=poisson, mean_pressure=mean_pressure,
                    penetration=penetration, stress=stress, method=method, precondition=precondition,
                    coarse_start=coarse_start, progress=progress, tol=tol,
                    max_iter=max_iter, memory=memory, threads=threads, material=material, speed=speed)
    result = _solve_once(h, friction=friction, **settings)
    if companion:
        if mean_pressure is None:
            raise ValueError("companion=True compares at the same load: give mean_pressure")
        result.companion = _solve_once(h, friction=0.0, **settings)
        result.a_over_a0 = result.contact_fraction / result.companion.contact_fraction
    return result


def _solve_native(h, nx, areal, *, period, period_y, thickness, young, poisson, friction, mean_pressure,
                  penetration, stress, method, precondition, coarse_start, progress, tol, max_iter, memory, threads,
                  material, speed):
    """One call of the library's solve (py_solve): fields (n, 5), spots, scalars, history."""
    from .materials import material_codes

    if method not in _METHODS:
        raise ValueError(f"method = {method!r} is not allowed; allowed: {sorted(_METHODS)}")
    control = "load" if mean_pressure is not None else "displacement"
    model, form, young, e0, e_inf, tau, eq, times, values = material_codes(material, young)
    # what comes back: the three solution fields, plus the in-plane ones with stress; a
    # line's contact spots (5 columns), or a surface's patches (area, perimeter)
    n_fields = (8 if areal else 5) if stress else 3
    spot_capacity, n_columns = (h.size // 2 + 1, 2) if areal else (h.size // 2 + 1, 5)
    fields, spots, s, hist, stat, errmsg = _core.py_solve(
        h, int(nx), int(areal), float(period), float(period_y), float(thickness), young, float(poisson),
        float(friction), _CONTROLS[control],
        NOT_SET if mean_pressure is None else float(mean_pressure),
        NOT_SET if penetration is None else float(penetration),
        _METHODS[method], int(bool(precondition)), int(bool(coarse_start)), int(bool(progress)), float(tol),
        int(max_iter), int(memory), int(threads),
        int(bool(stress)), model, form, e0, e_inf, tau, eq, times, values, float(speed),
        min(int(max_iter), HISTORY_CAPACITY), n_fields, spot_capacity, n_columns,
    )
    _check(stat, errmsg)
    scalars = {name: (int(v) if name in _INTEGERS else float(v)) for name, v in zip(_SCALARS, s)}
    n_hist = int(scalars.pop("history_length"))
    scalars["converged"] = bool(scalars["converged"])
    scalars["monotone"] = bool(scalars["monotone"])
    scalars["solver"] = _SOLVERS.get(int(scalars["solver"]), "")
    return fields, spots, scalars, hist[:n_hist].copy()


def _solve_once(h, *, period, stress, friction, **settings) -> LineResult:
    fields, spots, scalars, history = _solve_native(h, h.size, 0, period=period, period_y=NOT_SET, stress=stress,
                                                    friction=friction, **settings)
    for name in _AREAL_ONLY:
        scalars.pop(name)
    if not stress:
        for name in ("max_tension", "max_tension_x", "max_tension_offset", "max_tension_grid"):
            scalars[name] = float("nan")
    return LineResult(
        pressure=fields[:, 0].copy(), gap=fields[:, 1].copy(), displacement_z=fields[:, 2].copy(),
        displacement_x=fields[:, 3].copy() if stress else None, shear=friction * fields[:, 0] if stress else None,
        stress_xx=fields[:, 4].copy() if stress else None, height=h.copy(), period=float(period),
        friction=float(friction), spots=spots[: scalars["n_spots"], :2].copy(), residual_history=history,
        spot_max_tension=spots[: scalars["n_spots"], 2].copy() if stress else None,
        spot_tension_offset=spots[: scalars["n_spots"], 3].copy() if stress else None,
        spot_max_tension_grid=spots[: scalars["n_spots"], 4].copy() if stress else None,
        **scalars,
    )


# What an areal result keeps of the library's scalars (the others describe line contacts),
# and the scalars that only areal results have.
_AREAL_SCALARS = (
    "mean_pressure", "penetration", "contact_fraction", "delta_mu", "delta_mu_spectral", "delta_mu_energy",
    "delta_mu_profile", "converged", "iterations", "outer_iterations", "fft_pairs", "residual", "wall_time",
    "mean_gap", "dissipated_power", "monotone", "solver", "normalised_pressure", "normalised_thickness",
    "max_tension", "max_tension_x", "max_tension_y", "max_tension_offset", "max_principal_stress",
    "max_principal_x", "max_principal_y", "gap_resolution",
)
_AREAL_ONLY = ("max_tension_y", "max_principal_stress", "max_principal_x", "max_principal_y")
_STRESS_SCALARS = ("max_tension", "max_tension_x", "max_tension_y", "max_tension_offset", "max_principal_stress",
                   "max_principal_x", "max_principal_y")


@dataclass
class ArealResult:
    """A solved areal contact. Units are those of the inputs: lengths L, pressures S.

    Fields are ``(ny, nx)`` arrays on the grid ``x = j period_x/nx`` (axis 1, the sliding
    direction), ``y = i period_y/ny`` (axis 0); ``gap = w - (r - Lambda + Delta)``.
    ``delta_mu`` is the interlocking (or, on a viscoelastic layer, hysteretic) friction
    ``-<p dw/dx>/p_m`` from the displacement, ``delta_mu_spectral`` the same from the Fourier
    multiplier, ``delta_mu_profile = -<p dr/dx>/p_m`` from the rigid surface (equal to the
    others to the discretisation error), ``delta_mu_energy = mu_c <p du_x/dx>/p_m``.
    ``normalised_pressure`` is ``p_m/(E* h/period_x)`` on a layer and ``p_m/(E* Lambda0/period_x)``
    on a half-space (``Lambda0`` the highest summit above the mean plane). ``patches`` is an
    ``(n_patches, 2)`` array of the contact patches' areas (L^2) and perimeters (L), largest
    first (4-connected, periodic). With ``stress``: the in-plane surface displacements
    ``displacement_x``, ``displacement_y`` (L) and the surface stresses ``stress_xx``,
    ``stress_yy``, ``stress_xy`` (S, tension positive); ``max_tension`` is the largest
    ``stress_xx``, at (``max_tension_x``, ``max_tension_y``), ``max_tension_offset`` its
    distance along x from the trailing edge of the nearest contact on its row (negative:
    behind it); ``max_principal_stress`` the largest principal surface stress and where it
    sits. The solver statistics are those of :class:`LineResult`. ``leakage``: with
    ``&output leakage = .true.``, the Reynolds leakage of the gap computed by the run
    (:class:`~layercontact.leakage.CoreLeakage`: ``k_eff_x``, ``k_eff_y`` (L^3),
    ``percolating_x``, ``percolating_y``, ...; the companion's in ``companion.leakage``),
    else None.
    """

    pressure: np.ndarray
    gap: np.ndarray
    displacement_z: np.ndarray
    height: np.ndarray
    period: tuple[float, float]
    friction: float
    mean_pressure: float
    penetration: float
    contact_fraction: float
    mean_gap: float
    delta_mu: float
    delta_mu_spectral: float
    delta_mu_energy: float
    delta_mu_profile: float
    converged: bool
    iterations: int
    outer_iterations: int
    solver: str
    fft_pairs: int
    residual: float
    wall_time: float
    residual_history: np.ndarray = field(repr=False)
    #: the smallest gap, relative to the profile's height range, that double precision
    #: resolves at this load; above ``tol`` the run reports ``converged = False``
    gap_resolution: float = 0.0
    dissipated_power: float = 0.0
    monotone: bool = True
    normalised_pressure: float = float("nan")
    normalised_thickness: float = float("nan")
    patches: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    displacement_x: np.ndarray | None = field(default=None, repr=False)
    displacement_y: np.ndarray | None = field(default=None, repr=False)
    stress_xx: np.ndarray | None = field(default=None, repr=False)
    stress_yy: np.ndarray | None = field(default=None, repr=False)
    stress_xy: np.ndarray | None = field(default=None, repr=False)
    max_tension: float = float("nan")
    max_tension_x: float = float("nan")
    max_tension_y: float = float("nan")
    max_tension_offset: float = float("nan")
    max_principal_stress: float = float("nan")
    max_principal_x: float = float("nan")
    max_principal_y: float = float("nan")
    a_over_a0: float | None = None
    companion: "ArealResult | None" = field(default=None, repr=False)
    #: the Reynolds leakage of the gap computed by the run (``&output leakage = .true.``):
    #: :class:`layercontact.leakage.CoreLeakage` with ``k_eff_x``, ``k_eff_y``, ...; None otherwise
    leakage: "CoreLeakage | None" = None

    @property
    def n_patches(self) -> int:
        """Number of contact patches."""
        return int(self.patches.shape[0])

    @property
    def total_friction(self) -> float:
        """mu_c + Delta mu: the macroscopic friction coefficient."""
        return self.friction + self.delta_mu

    @property
    def x(self) -> np.ndarray:
        """Grid positions along the sliding direction (L), axis 1 of the fields."""
        return np.arange(self.pressure.shape[1]) * (self.period[0] / self.pressure.shape[1])

    @property
    def y(self) -> np.ndarray:
        """Grid positions across it (L), axis 0 of the fields."""
        return np.arange(self.pressure.shape[0]) * (self.period[1] / self.pressure.shape[0])


def solve_areal(
    heights,
    *,
    period=1.0,
    thickness: float = np.inf,
    young: float = 1.0,
    poisson: float = 0.5,
    friction: float = 0.0,
    mean_pressure: float | None = None,
    penetration: float | None = None,
    material=None,
    speed: float = 0.0,
    companion: bool = False,
    method: str = "auto",
    precondition: bool = True,
    coarse_start: bool = True,
    progress: bool = False,
    tol: float = 1e-10,
    max_iter: int = 100000,
    memory: int = 12,
    threads: int = 1,
    stress: bool = False,
) -> ArealResult:
    """Solve the sliding contact of the rigid surface ``heights`` (L; a ``(ny, nx)`` array on
    a uniform periodic grid, axis 1 = x = the sliding direction) on a layer of
    ``thickness`` (``inf``: half-space) bonded to a rigid base, with Coulomb friction
    ``tau_x = friction * p``. ``period`` is one length or a pair ``(period_x, period_y)``.
    ``stress=True`` also computes the in-plane displacements and the surface stress tensor
    (five more transforms). Every other keyword means what it means for :func:`solve_line`.
    """
    h = np.asarray(heights, dtype=np.float64)
    if h.ndim != 2:
        raise ValueError(f"heights must be a (ny, nx) array for an areal contact; got shape {h.shape}")
    if (mean_pressure is None) == (penetration is None):
        raise ValueError("give exactly one of mean_pressure (load control) and penetration")
    lx, ly = (float(period), float(period)) if np.ndim(period) == 0 else (float(period[0]), float(period[1]))
    ny, nx = h.shape
    flat = np.ascontiguousarray(h).ravel()
    settings = dict(thickness=thickness, young=young, poisson=poisson, mean_pressure=mean_pressure,
                    penetration=penetration, method=method, precondition=precondition, coarse_start=coarse_start,
                    progress=progress, tol=tol, max_iter=max_iter, memory=memory, threads=threads, material=material,
                    speed=speed)
    stress = bool(stress)

    def once(mu):
        fields, patches, scalars, history = _solve_native(flat, nx, 1, period=lx, period_y=ly, stress=stress,
                                                          friction=mu, **settings)
        kept = {name: scalars[name] for name in _AREAL_SCALARS}
        if not stress:
            kept.update({name: float("nan") for name in _STRESS_SCALARS})

        def field_map(column):
            return fields[:, column].reshape(ny, nx).copy() if column < fields.shape[1] else None

        return ArealResult(
            pressure=field_map(0), gap=field_map(1), displacement_z=field_map(2), displacement_x=field_map(3),
            displacement_y=field_map(4), stress_xx=field_map(5), stress_yy=field_map(6), stress_xy=field_map(7),
            height=h.copy(), period=(lx, ly), friction=float(mu), residual_history=history,
            patches=patches[: int(scalars["n_spots"])].copy(), **kept)

    result = once(friction)
    if companion:
        if mean_pressure is None:
            raise ValueError("companion=True compares at the same load: give mean_pressure")
        result.companion = once(0.0)
        result.a_over_a0 = result.contact_fraction / result.companion.contact_fraction
    return result


def surface_fields(pressure, *, period=1.0, thickness=np.inf, young=1.0, poisson=0.5, friction=0.0):
    """Surface displacement ``u_x`` (L) and in-plane stress ``sigma_xx`` (S, tension
    positive) of the layer under a prescribed pressure (S) and shear ``friction * p``,
    without solving a contact problem."""
    p = np.ascontiguousarray(np.asarray(pressure, dtype=np.float64))
    ux, sxx, stat, errmsg = _core.py_surface_fields(p, float(period), float(thickness), float(young),
                                                    float(poisson), float(friction))
    _check(stat, errmsg)
    return ux, sxx


@dataclass
class SurfaceStress:
    """In-plane surface displacements (L) and stresses (S, tension positive) of a layer
    under a prescribed pressure: ``(ny, nx)`` arrays for a surface; for a line,
    ``displacement_y``, ``stress_yy`` and ``stress_xy`` are ``None``."""

    displacement_x: np.ndarray
    stress_xx: np.ndarray
    displacement_y: np.ndarray | None = None
    stress_yy: np.ndarray | None = None
    stress_xy: np.ndarray | None = None


def surface_stress(pressure, *, period=1.0, thickness=np.inf, young=1.0, poisson=0.5,
                   friction=0.0) -> SurfaceStress:
    """Surface displacements and stresses of an elastic layer (``thickness=np.inf``:
    half-space) under the prescribed pressure (S; 1D for a line, ``(ny, nx)`` for a surface,
    x = axis 1) and the shear ``friction * p`` along x, without solving a contact problem.
    ``period`` is one length or, for a surface, a pair ``(period_x, period_y)``."""
    p = np.asarray(pressure, dtype=np.float64)
    if p.ndim == 1:
        lx = float(period) if np.ndim(period) == 0 else float(period[0])
        ux, sxx = surface_fields(p, period=lx, thickness=thickness, young=young, poisson=poisson,
                                 friction=friction)
        return SurfaceStress(displacement_x=ux, stress_xx=sxx)
    if p.ndim != 2:
        raise ValueError(f"pressure must be 1D (line) or (ny, nx) (surface); got shape {p.shape}")
    lx, ly = (float(period), float(period)) if np.ndim(period) == 0 else (float(period[0]), float(period[1]))
    ny, nx = p.shape
    fields, stat, errmsg = _core.py_surface_stress(np.ascontiguousarray(p).ravel(), nx, lx, ly, float(thickness),
                                                   float(young), float(poisson), float(friction))
    _check(stat, errmsg)
    ux, uy, sxx, syy, sxy = (fields[:, k].reshape(ny, nx).copy() for k in range(5))
    return SurfaceStress(displacement_x=ux, stress_xx=sxx, displacement_y=uy, stress_yy=syy, stress_xy=sxy)


def _maps(base) -> dict:
    """The solution fields of a result group; {} if it was written without maps
    (``&output fields = .false.``: the fields are then None)."""
    return {k: base["fields"][k][()] for k in base["fields"]} if "fields" in base else {}


def _profile(f):
    return f["profile/height"][()] if "profile" in f else None


def read_result(filename: str | os.PathLike, companion: bool = True) -> LineResult | ArealResult:
    """Read a result file written by the executable or :func:`run` (a :class:`LineResult`,
    or an :class:`ArealResult` for an areal scene); the frictionless companion run stored
    in it (if any) becomes ``result.companion``. A file written with ``&output fields =
    .false.`` has no maps: the fields and ``height`` are then None."""
    import h5py

    def one(f, base) -> LineResult:
        r = dict(base["results"].attrs)
        fields = _maps(base)
        spots = (np.column_stack([base["spots/trailing_edge"][()], base["spots/leading_edge"][()]])
                 if "spots" in base else np.zeros((0, 2)))
        names = set(_SCALARS) - {"history_length", "solver"}
        values = {k: (int(r[k]) if k in _INTEGERS else float(r[k])) for k in names if k in r}
        solver = r.get("solver", "")
        values["solver"] = solver.decode() if isinstance(solver, bytes) else str(solver)
        values["converged"] = bool(r["converged"])
        values["monotone"] = bool(r.get("monotone", 1))
        return LineResult(
            pressure=fields.get("pressure"), gap=fields.get("gap"), displacement_z=fields.get("displacement_z"),
            displacement_x=fields.get("displacement_x"), shear=fields.get("shear"),
            stress_xx=fields.get("stress_xx"), height=_profile(f),
            spot_max_tension=base["spots/max_tension"][()] if "spots/max_tension" in base else None,
            spot_tension_offset=base["spots/max_tension_offset"][()] if "spots/max_tension_offset" in base else None,
            spot_max_tension_grid=(base["spots/max_tension_grid"][()] if "spots/max_tension_grid" in base
                                   else None),
            period=float(f["input"].attrs["period"]), friction=float(r["friction"]), spots=spots,
            residual_history=base["convergence/residual"][()],
            a_over_a0=float(r["a_over_a0"]) if "a_over_a0" in r else None, **values,
        )

    def one_areal(f, base) -> ArealResult:
        r = dict(base["results"].attrs)
        values = {k: (int(r[k]) if k in _INTEGERS else float(r[k])) for k in _AREAL_SCALARS
                  if k in r and k not in ("solver",)}
        solver = r.get("solver", "")
        values["solver"] = solver.decode() if isinstance(solver, bytes) else str(solver)
        values["converged"] = bool(r["converged"])
        values["monotone"] = bool(r.get("monotone", 1))
        attrs = f["input"].attrs
        lx = float(attrs["period"])
        ly = float(attrs["period_y"]) if float(attrs["period_y"]) > 0 else lx
        fields = _maps(base)
        patches = (np.column_stack([base["patches/area"][()], base["patches/perimeter"][()]])
                   if "patches" in base else np.zeros((0, 2)))
        return ArealResult(
            pressure=fields.get("pressure"), gap=fields.get("gap"), displacement_z=fields.get("displacement_z"),
            displacement_x=fields.get("displacement_x"), displacement_y=fields.get("displacement_y"),
            stress_xx=fields.get("stress_xx"), stress_yy=fields.get("stress_yy"), stress_xy=fields.get("stress_xy"),
            height=_profile(f), period=(lx, ly), friction=float(r["friction"]), patches=patches,
            residual_history=base["convergence/residual"][()],
            leakage=CoreLeakage.from_attributes(base["leakage"].attrs) if "leakage" in base else None,
            a_over_a0=float(r["a_over_a0"]) if "a_over_a0" in r else None, **values)

    with h5py.File(filename, "r") as f:
        geometry = f.attrs.get("geometry", b"line")
        geometry = geometry.decode() if isinstance(geometry, bytes) else str(geometry)
        reader = one_areal if geometry == "areal" else one
        result = reader(f, f)
        if companion and "companion" in f:
            result.companion = reader(f, f["companion"])
        return result


def check_scene_file(filename: str | os.PathLike) -> None:
    """Read and validate a namelist file without solving; raises :class:`LayercontactError`
    with the message the executable would print."""
    stat, errmsg = _core.py_check_scene_file(os.fspath(filename))
    _check(stat, errmsg)


def choose_resolution(filename: str | os.PathLike) -> tuple[int | tuple[int, int], float]:
    """The grid and tolerance ``tol`` that a scene file with ``&solver target_error`` will be
    solved with (the accuracy rule of docs/accuracy.md; runs the pilot solve, writes
    nothing): ``(n, tol)`` for a line, ``((nx, ny), tol)`` for an areal scene."""
    n, ny, tol, stat, errmsg = _core.py_choose_resolution(os.fspath(filename))
    _check(stat, errmsg)
    return (int(n) if ny == 1 else (int(n), int(ny))), float(tol)


def run(filename: str | os.PathLike, verbose: bool = False) -> LineResult | ArealResult:
    """Run a namelist file exactly as the ``layercontact`` executable does (same library
    routine): the HDF5 result is written where ``&output file`` says, and read back.
    Raises :class:`LayercontactError` on bad input (nothing is written)."""
    return read_result(run_to_file(filename, verbose))


def run_to_file(filename: str | os.PathLike, verbose: bool = False) -> str:
    """Run a namelist file like :func:`run`, without reading the result back; returns the
    result file's path (for sweeps, which read only the scalars they tabulate)."""
    out, converged, stat, errmsg = _core.py_run(os.fspath(filename), 1 if verbose else 0)
    _check(stat, errmsg)
    return out.decode().strip() if isinstance(out, bytes) else str(out).strip()
