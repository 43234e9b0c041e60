"""Pythonic API over the Fortran library. Keywords become the namelist text of a scene,
which the library reads, completes with its defaults and checks as it does a namelist
file; its messages become exceptions; results come back by name as plain dataclasses."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from dataclasses import fields as dataclass_fields

import numpy as np

from . import scene_schema
from ._library import (_CONSTANTS, HISTORY_CAPACITY, NOT_SET, InputError, LayercontactError,  # noqa: F401
                       PeriodicityWarning, _check, _input_error, _lines, _namelist, contact_map, grid_points,
                       periods, positive_real, real_array, regular_file, stack_keywords)
from .leakage import CoreLeakage
from .native import core as _core


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


def surface_tensor(qx, qy, *, thickness=None, young=None, poisson=None, **stack):
    """The layer's 3x3 surface compliance for in-plane wavevectors ``(qx, qy)`` (1/L,
    broadcast together): ``(u_x^, u_y^, w^) = T (tau_x^, tau_y^, p^)`` in convention P,
    shape ``broadcast.shape + (3, 3)``, complex. In the frame ``(l, t, z)`` with
    ``l = q/|q|`` it is the plane-strain multiplier with ``|k| -> |q|`` in ``(l, z)`` and the
    antiplane compliance ``tanh(|q|h)/(G|q|)`` along ``t`` (for one layer bonded to a rigid
    base); ``q = 0`` gives the uniform mode ``(h/G, h/G, h/M)`` of a layer (summed over a
    stack's layers; zero where a half-space lies below, and in-plane where an interface
    slips). The layer's keywords and their defaults are those of :func:`solve_line`
    (``&layer``), the stack keywords of :func:`solve_line` included (elastic: the tensor is
    at rest)."""
    qx, qy = np.broadcast_arrays(np.asarray(qx, dtype=np.float64), np.asarray(qy, dtype=np.float64))
    text = _namelist({"layer": {"thickness": thickness, "young": young, "poisson": poisson,
                                **stack_keywords("surface_tensor", stack)}})
    t, stat, errmsg = _core.py_surface_tensor(text, np.ascontiguousarray(qx.ravel()),
                                              np.ascontiguousarray(qy.ravel()))
    _check(stat, errmsg)
    return t.reshape(qx.shape + (3, 3))


def layer_multipliers_lapack(kh, nu: float):
    """The same factors from the 4x4 plane-strain problem of one Fourier mode solved with
    LAPACK (an independent check; valid for 1e-3 <= kh <= 20)."""
    kh = np.ascontiguousarray(np.atleast_1d(np.asarray(kh, dtype=np.float64)))
    a, b, c, stat, errmsg = _core.py_layer_coefficients_lapack(kh, float(nu))
    _check(stat, errmsg)
    return a, b, c


@dataclass(kw_only=True)
class _SolvedContact:
    """The fields a solved line and a solved surface share (:class:`LineResult`,
    :class:`ArealResult`): the maps, the load, the friction and the solver's statistics."""

    pressure: np.ndarray
    gap: np.ndarray
    displacement_z: np.ndarray
    height: np.ndarray
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
    solver: str
    fft_pairs: int
    residual: float
    wall_time: float
    residual_history: np.ndarray = field(repr=False)
    #: why the methods of ``solver`` were chosen (docs/numerics.md, "How 'auto' chooses")
    solver_reason: str = ""
    #: the smallest gap, relative to the profile's height range, that double precision
    #: resolves at this load; above ``tol`` the run reports ``converged = False``
    gap_resolution: float = 0.0
    #: the threads the solve ran on (``threads``, or what the job was given) and the
    #: processes sharing its grid (1: this build has no MPI)
    omp_threads: int = 1
    mpi_ranks: int = 1
    #: of ``wall_time`` (s): the finest grid's set-up (operator: FFT plans, multipliers) and
    #: the coarse start (the solves on the coarser grids); the rest is the finest grid's
    #: iterations
    setup_time: float = 0.0
    coarse_time: float = 0.0
    #: of ``wall_time`` (s): the time in the grids' transforms, every grid's
    transform_time: float = 0.0
    dissipated_power: float = 0.0
    monotone: bool = True
    normalised_pressure: float = float("nan")
    normalised_thickness: float = float("nan")
    displacement_x: np.ndarray | None = field(default=None, repr=False)
    stress_xx: np.ndarray | None = field(default=None, repr=False)
    max_tension: float = float("nan")
    max_tension_x: float = float("nan")
    max_tension_offset: float = float("nan")
    #: with ``&output conductance``: the conductance per unit nominal area (``conductivity``
    #: per L, S/m^2 with S/m and m) and the normal interfacial stiffness ``dp_m/dDelta`` (S/L)
    #: at the solved contact set (docs/theory.md), NaN otherwise
    conductance: float = float("nan")
    contact_stiffness: float = float("nan")
    conductance_converged: bool = True
    conductance_iterations: int = 0
    stiffness_iterations: int = 0
    a_over_a0: float | None = None

    @property
    def total_friction(self) -> float:
        """mu_c + Delta mu: the macroscopic friction coefficient."""
        return self.friction + self.delta_mu


@dataclass
class LineResult(_SolvedContact):
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
    ``solver`` names the methods that ran, joined by ``'+'`` where one went on from the
    last one's iterate: ``'cg'`` (symmetric scenes), ``'gcr'`` (coupled scenes),
    ``'multigrid'``, ``'anderson'``, ``'gfmd'``, ``'newton'``; after ``'multigrid'`` the
    constrained CG (``'+cg'``) or GCR (``'+gcr'``) may finish, after ``'gcr'`` the GCR keeping
    its history across clips (``'+kept'``) and the Anderson iteration (``'+anderson'``), and
    on a grid of at most 2048 points with a unique solution the dense Newton method
    (``'+newton'``). ``solver_reason`` says why method ``'auto'`` chose them (docs/numerics.md,
    "How 'auto' chooses"); which fallback finishes may vary with rounding from one processor
    to another, the solution does not. ``iterations`` counts the iterations of every method
    (all inner CG iterations for Anderson, plus the Newton steps). ``residual_history``
    holds the residual per iteration (per outer iteration for Anderson); from
    :func:`solve_line`, the last ``HISTORY_CAPACITY`` (10000) of them.
    """

    period: float
    contact_length: float
    n_spots: int = 0
    spots: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    mean_gap: float = float("nan")
    leak_rate: float = float("nan")
    shear: np.ndarray | None = field(default=None, repr=False)
    spot_max_tension: np.ndarray | None = field(default=None, repr=False)
    spot_tension_offset: np.ndarray | None = field(default=None, repr=False)
    spot_max_tension_grid: np.ndarray | None = field(default=None, repr=False)
    max_tension_grid: float = float("nan")
    pressure_shift: float = 0.0
    summit_shift: float = 0.0
    companion: "LineResult | None" = field(default=None, repr=False)

    @property
    def x(self) -> np.ndarray:
        """Grid positions (L)."""
        return np.arange(self.pressure.size) * (self.period / self.pressure.size)


def solve_line(
    heights,
    *,
    period: float | None = None,
    thickness: float | None = None,
    young: float | None = None,
    poisson: float | None = None,
    friction: float | None = None,
    mean_pressure: float | None = None,
    normalised_pressure: float | None = None,
    penetration: float | None = None,
    material=None,
    speed: float | None = None,
    companion: bool | None = None,
    stress: bool | None = None,
    method: str | None = None,
    precondition: bool | None = None,
    coarse_start: bool | None = None,
    gfmd_mass: str | None = None,
    progress: bool | None = None,
    tol: float | None = None,
    max_iter: int | None = None,
    memory: int | None = None,
    threads: int | None = None,
    conductance: bool | None = None,
    conductivity: float | None = None,
    conductance_base: str | None = None,
    **stack,
) -> LineResult:
    """Solve the sliding line contact of the rigid profile ``heights`` (L, on a uniform
    periodic grid of one ``period``) on a layer of ``thickness`` (``inf``: half-space)
    bonded to a rigid base (or resting on a stack: below), with Coulomb friction ``tau = friction * p``.

    Every keyword sets the namelist variable of the same meaning (docs/namelist.md); one
    that is not given (None) takes that variable's default: ``period`` 1, ``thickness``
    ``inf`` (a half-space), ``young`` 1, ``poisson`` 0.5, ``friction`` 0, ``stress``
    True, ``method`` ``'auto'``, ``tol`` 1e-10, ``max_iter`` 100000, ``memory`` 12,
    ``threads`` 0, ``precondition`` and ``coarse_start`` True. A bad value raises
    :class:`InputError` with the message the namelist file would get. ``threads``: the
    threads of the solve; 0 takes what the job was given (``OMP_NUM_THREADS``, else Slurm's
    ``SLURM_CPUS_PER_TASK``, else the CPUs this process may run on); the result's
    ``omp_threads`` says how many ran (1 in a build without OpenMP).

    Give ``mean_pressure`` (load control), ``normalised_pressure`` (the load in the seed's
    scale ``E* Lambda0/period``) or ``penetration`` (displacement control, finite
    compressible layers only). ``material`` (a :class:`StandardLinearSolid` or
    :class:`Prony`; not with ``young``) makes the layer viscoelastic, sliding at
    ``speed`` (L/T); ``dissipated_power`` and ``monotone`` (``Re G_eff >= 0`` on every mode,
    hence a unique solution) are reported. The layer may rest on more than a rigid base bonded to it:
    the stack keywords ``interface`` (``'bonded'`` or ``'slip'``, below the layer),
    ``lower_thickness``, ``lower_young``, ``lower_poisson`` (lower layers, from the top down;
    ``lower_tau`` and ``lower_e_inf`` make them standard linear solids), ``lower_interfaces``
    (a word or a list of words, one per lower layer),
    ``substrate_young`` and ``substrate_poisson`` (an elastic half-space below them; not
    given: rigid) are the ``&layer`` variables of those names (docs/theory.md, "Layered
    stacks"). ``companion=True`` also solves the frictionless
    problem at the load of this one (its computed mean pressure, whatever the control) and
    sets ``a_over_a0`` and ``companion``. ``stress`` computes ``displacement_x``, ``shear``
    and the surface stress ``stress_xx`` (one more FFT pair). ``conductance=True`` computes
    the contact's conductance per unit nominal area (``conductivity``, default 1, per L) and
    its normal interfacial stiffness ``dp_m/dDelta`` (S/L) at the solved contact set
    (``conductance``, ``contact_stiffness``; docs/theory.md); ``conductance_base``:
    ``'conducting'``, the base under a layer at the far potential.
    ``method``: ``'auto'`` (the multigrid method for the frictionless elastic lines it
    applies to from 4096 points on (a thin incompressible one from 262144 points when its
    coarse solve needed more than 20 CG iterations), and surfaces from 1024², constrained CG for other
    symmetric scenes, constrained GCR for coupled ones, going on with its history kept
    across clips and then with Anderson if GCR stalls; a coupled line of 8192 points or
    more whose coarse-start solve needed more than 20 GCR iterations (a thin incompressible
    one: 262144 points or more), and a coupled surface of 1024² or more (512² for a sliding
    viscoelastic one that the multigrid method smooths by rows for its loss at long waves
    or its large loss among the short waves) whose coarse solve needed more than 12, i.e.
    broadband roughness, and a sliding viscoelastic line of 1024 points or more with 16
    contact points in its coarse start (a surface of 128² or more with 256) whose loss
    ``|Im K|/Re K`` reaches 1 (3) among its short waves, go to
    ``'multigrid'`` below where that applies; grids of at most
    2048 points that stall are finished by the dense Newton method), ``'cg'``, ``'gcr'``,
    ``'anderson'``, ``'gfmd'``, ``'newton'`` (dense semismooth Newton, grids of at most 2048
    points) or ``'multigrid'`` (nonsmooth Newton multigrid: frictionless lines and surfaces
    on an elastic half-space or a layer with ``poisson <= 0.47``, or an incompressible one
    from ``thickness ~ 0.07 period``; ``iterations`` counts its fine-grid iterations;
    ``coarse_start`` and ``precondition`` do not apply; on such a line or surface with
    friction or on a sliding viscoelastic layer, and on a line on a thinner layer, with
    friction or without, whose coarse grids still smooth (``thickness ~ 0.01 period`` at
    ``poisson = 0.5``), the same iteration with the non-symmetric stiffness, from the coarse start, GCR
    going on where it stalls: transform pairs that do not grow with ``n`` on broadband
    roughness). ``precondition`` applies the Fourier stiffness 1/M to the residual on the
    contact set (fewer CG iterations). ``coarse_start`` starts from the solution on the grid
    of every second point, recursively down to 512 points (fine-grid iterations nearly flat
    in the grid size; see bench/iterations.py). ``gfmd_mass`` (default ``'auto'``): the
    masses of method ``'gfmd'``, ``'one'`` for every node or a mass per ``'mode'`` on the
    nodes off the wall (docs/namelist.md). ``progress=True`` prints a line to standard
    error for each grid level solved and every 2 s within a level (iteration, residual,
    contact fraction, elapsed time): it comes from the compiled core, so it shows in a
    terminal, not in a notebook cell.
    A run that did not reach ``tol`` returns with ``converged = False``.
    """
    if np.ndim(heights) == 2:
        raise InputError("heights: a 2D array is not allowed; allowed: a 1D profile (use solve_areal for a "
                         "surface)", 2)
    h = np.ascontiguousarray(real_array(heights, "heights", ndim=(1,)))
    groups = _keyword_groups(
        thickness=thickness, young=young, poisson=poisson, friction=friction, companion=companion,
        mean_pressure=mean_pressure, normalised_pressure=normalised_pressure, penetration=penetration,
        material=material, speed=speed, method=method, precondition=precondition, coarse_start=coarse_start,
        gfmd_mass=gfmd_mass, progress=progress, tol=tol, max_iter=max_iter, memory=memory, threads=threads,
        stress=stress, conductance=conductance, conductivity=conductivity, conductance_base=conductance_base,
        **stack_keywords("solve_line", stack))
    runs = _solve_scene(h, {"scene": {"n": h.size, "period": period}, **groups}, areal=False,
                        companion=bool(companion), stress=stress)
    results = [_line_result(**run, height=h.copy()) for run in runs]
    if len(results) > 1:
        results[0].companion = results[1]
    return results[0]


def _keyword_groups(*, material, method, progress, penetration, **keywords) -> dict[str, dict]:
    """The namelist groups and variables that the keywords of solve_line and solve_areal set
    (None: not given): the scene schema's variables of the same names, ``method`` and
    ``progress`` for ``solver_method`` and ``verbose``, a penetration with displacement
    control, and the variables of ``material``. ``young`` and ``material`` both give the
    layer's modulus: given together they are refused (:class:`InputError`), as a namelist
    variable given twice is."""
    if material is not None and keywords.get("young") is not None:
        raise InputError(f"young = {keywords['young']!r} and material = {material!r} both give the layer's "
                         "modulus; allowed: one of them: keep material (a viscoelastic layer) or young (an "
                         "elastic one)", 2)
    groups = scene_schema.keyword_groups(
        **keywords, solver_method=method, verbose=progress, penetration=penetration,
        control=None if penetration is None else "displacement")
    if material is not None:
        groups.setdefault("material", {}).update(material._namelist())
    return groups


def _solve_scene(h, groups: dict, *, areal: bool, companion: bool, stress) -> list[dict]:
    """Solve the scene of the namelist groups on the flat heights ``h`` (x fastest) in the
    library (py_solve_scene); per run (the scene, then its companion) what it returned, by
    the names of a result file: scalars, fields, spots (or patches), residual history and
    the cell's periods."""
    runs = 2 if companion else 1
    n_fields = 3 if stress is False else (9 if areal else 6)
    spot_columns = 2 if areal else 5
    fields, spots, history, table, stat, errmsg = _core.py_solve_scene(
        _namelist(groups), h, runs, n_fields, h.size // 2 + 1, spot_columns, HISTORY_CAPACITY)
    _check(stat, errmsg)
    described = _lines(table)
    period = (float(described["input/period"]), float(described["input/period_y"]))
    out = []
    for k, prefix in enumerate(("", "companion/")[:runs]):
        scalars = {name[len(prefix) + 8:]: value for name, value in described.items()
                   if name.startswith(prefix + "results/")}
        n_spots = int(scalars["n_spots"].split()[0])
        columns = described.get(prefix + ("patches" if areal else "spots"), "").split()
        out.append(dict(
            scalars=scalars,
            fields={name: fields[:, i, k].copy() for i, name in enumerate(described[prefix + "fields"].split())},
            spots={name: spots[:n_spots, i, k].copy() for i, name in enumerate(columns)},
            history=history[: int(described[prefix + "convergence/residual"]), k].copy(),
            period=period if areal else period[0]))
    return out


def _typed(cls, scalars: dict) -> dict:
    """The scalars of a result (text from the library, or /results attributes) that are
    fields of ``cls``, as the types its fields declare (flags 0/1 become bool)."""
    kinds = {f.name: f.type for f in dataclass_fields(cls)}
    out = {}
    for name, value in scalars.items():
        kind = kinds.get(name)
        if kind is None or name == "period":
            continue
        if isinstance(value, bytes):
            value = value.decode()
        if isinstance(value, str) and kind == "str":
            value = "" if value.strip() == "''" else value.strip()
        elif isinstance(value, str):
            words = value.split()
            value = "" if not words else words[0]
        out[name] = {"bool": lambda v: bool(int(v)), "int": int, "str": str}.get(kind, float)(value)
    return out


def _line_result(*, scalars: dict, fields: dict, spots: dict, history, height, period) -> LineResult:
    """A LineResult from what a line run returned, by name (a solve or a result file)."""
    edges = (np.column_stack([spots["trailing_edge"], spots["leading_edge"]]) if "trailing_edge" in spots
             else np.zeros((0, 2)))
    return LineResult(
        pressure=fields.get("pressure"), gap=fields.get("gap"), displacement_z=fields.get("displacement_z"),
        displacement_x=fields.get("displacement_x"), shear=fields.get("shear"), stress_xx=fields.get("stress_xx"),
        height=height, period=float(np.atleast_1d(period)[0]), spots=edges, residual_history=history,
        spot_max_tension=spots.get("max_tension"), spot_tension_offset=spots.get("max_tension_offset"),
        spot_max_tension_grid=spots.get("max_tension_grid"), **_typed(LineResult, scalars))


def _areal_result(*, scalars: dict, fields: dict, spots: dict, history, height, period) -> ArealResult:
    """An ArealResult from what an areal run returned, by name (``spots``: the patches)."""
    patches = (np.column_stack([spots["area"], spots["perimeter"]]) if "area" in spots else np.zeros((0, 2)))
    return ArealResult(
        pressure=fields.get("pressure"), gap=fields.get("gap"), displacement_z=fields.get("displacement_z"),
        displacement_x=fields.get("displacement_x"), displacement_y=fields.get("displacement_y"),
        stress_xx=fields.get("stress_xx"), stress_yy=fields.get("stress_yy"), stress_xy=fields.get("stress_xy"),
        height=height, period=(float(period[0]), float(period[1])), patches=patches, residual_history=history,
        **_typed(ArealResult, scalars))


@dataclass
class ArealResult(_SolvedContact):
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

    period: tuple[float, float]
    mean_gap: float
    patches: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    displacement_y: np.ndarray | None = field(default=None, repr=False)
    stress_yy: np.ndarray | None = field(default=None, repr=False)
    stress_xy: np.ndarray | None = field(default=None, repr=False)
    max_tension_y: float = float("nan")
    max_principal_stress: float = float("nan")
    max_principal_x: float = float("nan")
    max_principal_y: float = float("nan")
    companion: "ArealResult | None" = field(default=None, repr=False)
    #: the Reynolds leakage of the gap computed by the run (``&output leakage = .true.``):
    #: :class:`layercontact.leakage.CoreLeakage` with ``k_eff_x``, ``k_eff_y``, ...; None otherwise
    leakage: "CoreLeakage | None" = None

    @property
    def n_patches(self) -> int:
        """Number of contact patches."""
        return int(self.patches.shape[0])

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
    period=None,
    thickness: float | None = None,
    young: float | None = None,
    poisson: float | None = None,
    friction: float | None = None,
    mean_pressure: float | None = None,
    normalised_pressure: float | None = None,
    penetration: float | None = None,
    material=None,
    speed: float | None = None,
    companion: bool | None = None,
    method: str | None = None,
    precondition: bool | None = None,
    coarse_start: bool | None = None,
    gfmd_mass: str | None = None,
    progress: bool | None = None,
    tol: float | None = None,
    max_iter: int | None = None,
    memory: int | None = None,
    threads: int | None = None,
    stress: bool | None = None,
    conductance: bool | None = None,
    conductivity: float | None = None,
    conductance_base: str | None = None,
    **stack,
) -> ArealResult:
    """Solve the sliding contact of the rigid surface ``heights`` (L; a ``(ny, nx)`` array on
    a uniform periodic grid, axis 1 = x = the sliding direction) on a layer of
    ``thickness`` (``inf``: half-space) bonded to a rigid base or resting on a stack, with Coulomb friction
    ``tau_x = friction * p``. ``period`` is one length or a pair ``(period_x, period_y)``.
    ``stress`` (default True) also computes the in-plane displacements and the surface
    stress tensor (five more transforms). ``normalised_pressure`` is the load in the scale
    ``E* h/period_x`` on a layer (the top layer's on a stack), ``E* Lambda0/period_x`` on a
    half-space. Every other keyword, the stack keywords included, means what it means for
    :func:`solve_line`, with the same defaults.
    """
    h = real_array(heights, "heights", ndim=(2,))
    ny, nx = h.shape
    lx, ly = (period, None) if period is None or np.ndim(period) == 0 else periods(period)
    groups = _keyword_groups(
        thickness=thickness, young=young, poisson=poisson, friction=friction, companion=companion,
        mean_pressure=mean_pressure, normalised_pressure=normalised_pressure, penetration=penetration,
        material=material, speed=speed, method=method, precondition=precondition, coarse_start=coarse_start,
        gfmd_mass=gfmd_mass, progress=progress, tol=tol, max_iter=max_iter, memory=memory, threads=threads,
        stress=stress, conductance=conductance, conductivity=conductivity, conductance_base=conductance_base,
        **stack_keywords("solve_areal", stack))
    scene = {"geometry": "areal", "nx": nx, "ny": ny, "period": lx, "period_y": ly}
    runs = _solve_scene(np.ascontiguousarray(h).ravel(), {"scene": scene, **groups}, areal=True,
                        companion=bool(companion), stress=stress)
    results = [_areal_result(**dict(run, fields={k: v.reshape(ny, nx) for k, v in run["fields"].items()}),
                             height=h.copy()) for run in runs]
    if len(results) > 1:
        results[0].companion = results[1]
    return results[0]


def surface_fields(pressure, *, period=None, thickness=None, young=None, poisson=None, friction=None, **stack):
    """Surface displacement ``u_x`` (L) and in-plane stress ``sigma_xx`` (S, tension
    positive) of the layer under a prescribed pressure (S) and shear ``friction * p``,
    without solving a contact problem. The keywords (the stack keywords included) and their
    defaults are those of :func:`solve_line`."""
    p = np.ascontiguousarray(real_array(pressure, "pressure", ndim=(1,)))
    fields = _surface_stress(p, {"n": p.size, "period": period}, thickness, young, poisson, friction,
                             stack_keywords("surface_fields", stack))
    return fields[:, 0].copy(), fields[:, 2].copy()


def contact_conductance(contact_mask, period, conductivity, *, thickness=np.inf, tol: float = 1e-10,
                        max_iter: int = 100000) -> float:
    """The electrical (or thermal) conductance per unit nominal area of a prescribed contact
    map: the rigid counter-surface a perfect conductor touching the body where
    ``contact_mask`` is true (1D: a line of ``period``; 2D ``(ny, nx)``, x = axis 1, with
    ``period`` one length or a pair ``(period_x, period_y)``), the rest of the surface
    insulated, and the far field of a half-space (``thickness=np.inf``) or the perfectly
    conducting base under a layer of ``thickness`` at the other potential. Returns
    ``conductivity * mean(J)/DeltaV`` (``conductivity`` per length: S/m^2 with S/m and m; a
    half-space's is the constriction conductance, docs/theory.md). Solved by preconditioned
    conjugate gradients to a relative ``tol`` on the mean (docs/numerics.md); a solve that
    does not reach it within ``max_iter`` iterations raises :class:`LayercontactError` with
    code 3."""
    mask = contact_map(contact_mask, "contact_mask")
    if mask.ndim == 1:
        if np.ndim(period) != 0:
            raise _input_error("period", period, "one positive length for a line")
        lx = ly = periods(period)[0]
        ny, nx = 1, mask.size
    else:
        lx, ly = periods(period)
        ny, nx = mask.shape
    sigma = positive_real(conductivity, "conductivity")
    h = positive_real(thickness, "thickness", infinite=True)
    tol = positive_real(tol, "tol")
    if not 1e-14 <= tol <= 1e-2:
        raise _input_error("tol", tol, "1e-14 <= tol <= 1e-2")
    budget = grid_points(max_iter, "max_iter")
    if not 1 <= budget <= 10_000_000:
        raise _input_error("max_iter", max_iter, "1 <= max_iter <= 10000000")
    value, iterations, converged, stat, errmsg = _core.py_contact_conductance(
        nx, ny, lx, ly, np.ascontiguousarray(mask).ravel(), h, tol, budget)
    _check(stat, errmsg)
    if not converged:
        raise LayercontactError(f"contact_conductance: not converged to tol = {tol!r} in {iterations} iterations "
                                "(max_iter)", 3)
    return sigma * float(value)


def _surface_stress(p, scene: dict, thickness, young, poisson, friction, stack: dict) -> np.ndarray:
    """fields(n, 5) = u_x, u_y, sigma_xx, sigma_yy, sigma_xy of the layer under the flat
    pressure ``p`` (x fastest) on the grid of the &scene variables ``scene``."""
    text = _namelist({"scene": scene, "layer": {"thickness": thickness, "young": young, "poisson": poisson, **stack},
                      "friction": {"coefficient": friction}})
    fields, stat, errmsg = _core.py_surface_stress(text, p)
    _check(stat, errmsg)
    return fields


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


def surface_stress(pressure, *, period=None, thickness=None, young=None, poisson=None,
                   friction=None, **stack) -> SurfaceStress:
    """Surface displacements and stresses of an elastic layer (``thickness=np.inf``:
    half-space, the default) under the prescribed pressure (S; 1D for a line, ``(ny, nx)``
    for a surface, x = axis 1) and the shear ``friction * p`` along x, without solving a
    contact problem. ``period`` is one length or, for a surface, a pair ``(period_x,
    period_y)``; the keywords and their defaults are those of :func:`solve_areal`."""
    p = real_array(pressure, "pressure", ndim=(1, 2))
    if p.ndim == 1:
        lx = period if period is None or np.ndim(period) == 0 else periods(period)[0]
        ux, sxx = surface_fields(p, period=lx, thickness=thickness, young=young, poisson=poisson,
                                 friction=friction, **stack)
        return SurfaceStress(displacement_x=ux, stress_xx=sxx)
    lx, ly = (period, None) if period is None or np.ndim(period) == 0 else periods(period)
    ny, nx = p.shape
    scene = {"geometry": "areal", "nx": nx, "ny": ny, "period": lx, "period_y": ly}
    fields = _surface_stress(np.ascontiguousarray(p).ravel(), scene, thickness, young, poisson, friction,
                             stack_keywords("surface_stress", stack))
    ux, uy, sxx, syy, sxy = (fields[:, k].reshape(ny, nx).copy() for k in range(5))
    return SurfaceStress(displacement_x=ux, stress_xx=sxx, displacement_y=uy, stress_yy=syy, stress_xy=sxy)


def _maps(base) -> dict:
    """The solution fields of a result group; {} if it was written without maps
    (``&output fields = .false.``: the fields are then None)."""
    return {k: base["fields"][k][()] for k in base["fields"]} if "fields" in base else {}


def _profile(f):
    return f["profile/height"][()] if "profile" in f else None


def _periods(attrs) -> tuple[float, float]:
    """(period, period_y) of a result file's /input (period_y not set, absent: the period;
    files of earlier versions hold a negative number for it)."""
    lx = float(attrs["period"])
    ly = float(attrs["period_y"]) if "period_y" in attrs and float(attrs["period_y"]) > 0 else lx
    return lx, ly


def read_result(filename: str | os.PathLike, companion: bool = True) -> LineResult | ArealResult:
    """Read a result file written by the executable or :func:`run` (a :class:`LineResult`,
    or an :class:`ArealResult` for an areal scene); the frictionless companion run stored
    in it (if any) becomes ``result.companion``. A file written with ``&output fields =
    .false.`` has no maps: the fields and ``height`` are then None."""
    import h5py

    def one(f, base, builder):
        spots = next((base[name] for name in ("spots", "patches") if name in base), {})
        result = builder(scalars=dict(base["results"].attrs), fields=_maps(base),
                         spots={name: spots[name][()] for name in spots}, history=base["convergence/residual"][()],
                         height=_profile(f), period=_periods(f["input"].attrs))
        if "leakage" in base:
            result.leakage = CoreLeakage.from_attributes(base["leakage"].attrs)
        return result

    # as for the readers of input files: a file that is not there, or whose content is not
    # a result, is bad input (code 2); one that is there but cannot be read an I/O failure (4)
    path = regular_file(filename, "result file")
    if not os.path.exists(path):
        raise InputError(f"result file '{path}' is not found; allowed: an existing result file", 2)
    try:
        f = h5py.File(path, "r")
    except OSError as err:
        # (h5py's message does not name the file)
        if os.access(path, os.R_OK) and not h5py.is_hdf5(path):
            raise InputError(f"cannot read result file '{path}': not an HDF5 file (no HDF5 signature); allowed: "
                             "a result file written by layercontact", 2) from err
        raise LayercontactError(f"cannot read result file '{path}': {err}", 4) from err
    with f:
        if "results" not in f or "input" not in f:
            raise InputError(f"cannot read result file '{path}': it is an HDF5 file but not a layercontact "
                             "result (no /results or /input)", 2)
        geometry = f.attrs.get("geometry", b"line")
        geometry = geometry.decode() if isinstance(geometry, bytes) else str(geometry)
        builder = _areal_result if geometry == "areal" else _line_result
        result = one(f, f, builder)
        if companion and "companion" in f:
            result.companion = one(f, f["companion"], builder)
        return result


def scene_namelist(text: str = "", **keywords) -> str:
    """A scene as the library reads it, written back as a complete namelist: every variable
    of the scene schema (docs/namelist.md) with its value, a variable that is not set as a
    comment. The scene is the namelist ``text`` or the keywords of
    :func:`layercontact.scene_schema.keyword_groups` (the names of a result's ``/input``;
    :func:`layercontact.scene_schema.input_keywords` reads them from a result). It is
    checked as a namelist file is: a bad scene raises :class:`InputError`."""
    if keywords:
        if text:
            raise TypeError("give the scene as text or as keywords, not both")
        text = _namelist(scene_schema.keyword_groups(**keywords))
    if not text.strip():
        raise ValueError("no scene given (default_scene gives the default one)")
    return _scene_text(text, "line")


def default_scene(geometry: str = "line") -> str:
    """The default scene of ``geometry`` (``'line'`` or ``'areal'``) as a complete namelist,
    as ``layercontact --defaults [line|areal]`` prints it: every variable with its default,
    one without a default value as a comment. It is not a scene that runs as it is: a scene
    gives its load."""
    if geometry not in ("line", "areal"):
        raise ValueError(f"geometry = {geometry!r} is not allowed; allowed: 'line' or 'areal'")
    return _scene_text("", geometry)


def _scene_text(text: str, geometry: str) -> str:
    echo, stat, errmsg = _core.py_scene_namelist(text, geometry)
    _check(stat, errmsg)
    return (echo.decode() if isinstance(echo, bytes) else str(echo)).rstrip() + "\n"


def check_scene_file(filename: str | os.PathLike) -> None:
    """Read and validate a namelist file without solving; raises :class:`LayercontactError`
    with the message the executable would print."""
    code, errmsg = _core.py_check_scene_file(regular_file(filename, "namelist file"))
    _check(code, errmsg)


def choose_resolution(filename: str | os.PathLike) -> tuple[int | tuple[int, int], float]:
    """The grid and tolerance ``tol`` that a scene file with ``&solver target_error`` will be
    solved with (the accuracy rule of docs/accuracy.md; runs the pilot solve, writes
    nothing): ``(n, tol)`` for a line, ``((nx, ny), tol)`` for an areal scene."""
    n, ny, tol, code, errmsg = _core.py_choose_resolution(regular_file(filename, "namelist file"))
    _check(code, errmsg)
    return (int(n) if ny == 1 else (int(n), int(ny))), float(tol)


def run(filename: str | os.PathLike, verbose: bool = False, comm=None) -> LineResult | ArealResult:
    """Run a namelist file exactly as the ``layercontact`` executable does (same library
    routine): the HDF5 result is written where ``&output file`` says, and read back.
    Raises :class:`LayercontactError` on bad input (nothing is written). Heights from a
    file taken as one period that jump or kink across the cell's edges give a
    :class:`PeriodicityWarning` (the executable's warning on standard error).

    Under ``mpirun -n P`` an areal scene is shared among the job's P ranks, every rank
    calling ``run`` with the same file (as ``python -m layercontact run`` does).
    ``comm``: an mpi4py communicator whose ranks share the scene instead, e.g.
    ``MPI.COMM_SELF`` for a script whose ranks each run scenes of their own; every rank of
    ``comm`` must call ``run`` with the same file. Every rank gets the result."""
    result_file = run_to_file(filename, verbose, comm)
    result = read_result(result_file)
    _warn_if_not_periodic(result, result_file)
    return result


def _warn_if_not_periodic(result, result_file: str) -> None:
    """The executable's warning of a height file that is not periodic, as a warning."""
    import h5py

    from .profiles import warn_if_not_periodic

    def text(value) -> str:
        return value.decode() if isinstance(value, bytes) else str(value)

    with h5py.File(result_file, "r") as f:
        attrs = f["input"].attrs
        if text(attrs.get("profile_kind", "")) != "file" or text(attrs.get("profile_boundary", "")) != "periodic":
            return
        file = text(attrs.get("profile_file", ""))
    if result.height is not None and np.size(result.height) > 0:
        warn_if_not_periodic(np.reshape(result.height, (-1, np.shape(result.height)[-1])), file)


def run_to_file(filename: str | os.PathLike, verbose: bool = False, comm=None) -> str:
    """Run a namelist file like :func:`run`, without reading the result back; returns the
    result file's path (for sweeps, which read only the scalars they tabulate)."""
    out, converged, code, errmsg = _core.py_run(regular_file(filename, "namelist file"), 1 if verbose else 0,
                                                _communicator_handle(comm))
    _check(code, errmsg)
    return out.decode().strip() if isinstance(out, bytes) else str(out).strip()


def _communicator_handle(comm) -> int:
    """The Fortran handle of an mpi4py communicator (-1: none, the launcher's job)."""
    if comm is None:
        return -1
    if not (hasattr(comm, "py2f") and hasattr(comm, "Get_size")):
        raise InputError(f"comm = {comm!r}; allowed: an mpi4py communicator (mpi4py.MPI.Comm) or None", 2)
    if comm.Get_size() > 1 and not _core.py_mpi_available():
        raise InputError(f"comm has {comm.Get_size()} ranks, but this build of layercontact has no MPI "
                         "(meson option 'mpi': MPI for Fortran or FFTW-MPI not found); allowed: a "
                         "communicator of one rank (MPI.COMM_SELF), or a build with MPI (docs/clusters.md)", 2)
    return int(comm.py2f())
