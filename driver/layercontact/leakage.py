"""Reynolds thin-film leakage through the gap of an areal contact.

The fluid in the gap ``g(x, y) >= 0`` of a periodic cell obeys the Reynolds equation

    div(g^3 grad P) = 0,    flux q = -g^3/(12 eta) grad P,

with no flux through contact (``g = 0``). A mean pressure gradient ``-G`` is imposed along
the flow direction ``s`` (``x`` or ``y``): ``P = G (-s + phi)`` with ``phi`` periodic, which
is the same as a pressure drop ``G L_s`` across one period. The effective conductance is

    k_eff = 12 eta <q_s> / G,

the mean flux per unit width per unit mean pressure gradient times ``12 eta``, so that a
uniform gap ``g`` gives ``k_eff = g^3``. The discretisation and its checks are described in
``docs/leakage.md``.

Finite volumes on the grid cells: the unknown ``phi`` sits at the grid point (cell
centre), the flux across the face between two neighbours is ``c (P_a - P_b)/h`` with the
face conductance ``c`` the harmonic mean of their ``g^3``. That is the exact series
conductance of two half cells of constant gap, so

* a contact cell has zero conductance on all four faces: nothing flows through contact;
* on a gap that varies along the flow only, the scheme gives ``1/<1/g^3>`` of the grid
  values, the periodic trapezoidal rule of the exact 1D integral (spectrally accurate for a
  smooth gap, exact for stripes);
* a narrow neck conducts according to its own gap, where ``g_face^3`` of the arithmetic
  mean gap (``face="arithmetic"``, with the faces of contact cells closed) lets a one-cell
  neck of gap ``e`` between gaps ``G`` conduct about ``G^3/16`` whatever ``e``;
* on a smooth 2D gap both rules are second-order accurate, the arithmetic one with a smaller
  error constant; the harmonic rule is below it face by face, so the two bracket ``k_eff``.

Fluid cells connect through faces (4-connectivity), so two gap cells that touch only at a
corner do not exchange fluid. Cells that cannot carry net flux are removed before the
solve: contact cells and fluid clusters that do not wind around the periodic cell along the
flow (isolated pockets, clusters that wrap only across the flow). One cell of each remaining
cluster is pinned (``phi = 0``), so the system is symmetric positive definite and the answer
on the flow-carrying part is that of the full problem.

``k_eff`` is evaluated as the mean dissipation ``sum_faces c (Delta P)^2 / (h^2 G^2 N)``,
equal to the mean flux at the solution and above it by the squared energy norm of the
solver error: a sum of positive terms, accurate even when ``k_eff`` is 1e-12 of the mean
``g^3`` near percolation, where the mean flux is a small difference of large face fluxes.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.ndimage as ndi
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ._library import _CONSTANTS, InputError, _check, periods, real_array

__all__ = ["CoreLeakage", "LeakageResult", "core_leakage", "reynolds_leakage"]

# Largest number of unknowns solved with the sparse direct solver under method="auto": on
# gaps near percolation SuperLU and AMG + CG take the same time near 30 000 unknowns, and the
# factorisation's cost grows faster than N beyond (1.8 times the AMG time at 78 000).
_DIRECT_MAX_UNKNOWNS = 30_000
# Smoothed-aggregation settings and the delay of the CG error estimate, chosen on gaps near
# percolation (bench/leakage_speed.py): a strength threshold of 0.5 takes 20-40 % fewer CG
# iterations than 0.25 on elastic gaps, and its error estimate stays below tol.
_AMG_STRENGTH = 0.5
_AMG_MAX_COARSE = 500
_AMG_MAX_LEVELS = 20
_CG_DELAY = 5
# Default contact threshold relative to the largest gap: the contact cells of a converged
# areal solve carry residual gaps of about 1e-8 of the largest gap, and a cell at 1e-6 of
# it conducts 1e-18 of the largest cell, far below any solver tolerance.
_CONTACT_THRESHOLD_RELATIVE = 1e-6
# Gaps below this are closed whatever the threshold: above it g^3, 1/g^3 and the sum of two
# of them are normal floats, so a face between two open cells never conducts zero.
_SMALLEST_GAP = 1e-100


@dataclass
class LeakageResult:
    """Effective conductance of the gap along ``direction``, for ``12 eta = 1`` and a unit
    mean pressure gradient unless ``viscosity`` and ``pressure_gradient`` say otherwise.

    Attributes
    ----------
    k_eff : float
        ``12 eta <q_s>/G`` (L^3): the mean flux per unit width per unit mean pressure
        gradient, times ``12 eta``; ``g^3`` for a uniform gap ``g``; zero when the fluid does
        not percolate along the flow.
    k_transverse : float
        ``12 eta <q_t>/G`` for the mean flux across the flow (``t`` the other axis): the
        off-diagonal conductance, zero for a gap symmetric under ``x -> -x`` or ``y -> -y``.
    flux : float
        Mean flux per unit width along the flow, ``k_eff G/(12 eta)`` (L^2/T).
    pressure : numpy.ndarray
        ``(ny, nx)`` total pressure ``P = G (-s + phi)``: the imposed mean gradient plus the
        periodic fluctuation, with ``s = j dx`` (flow along x) or ``i dy`` (along y) the
        grid coordinate from the first grid point, ``phi = 0`` at one pinned cell of each
        flow-carrying cluster. ``NaN`` in contact and in fluid that carries no net flux
        (its pressure is not set by the flow).
    fluctuation : numpy.ndarray
        ``(ny, nx)`` periodic part ``G phi`` of the pressure, ``NaN`` where ``pressure`` is.
    direction : str
        ``"x"`` (axis 1) or ``"y"`` (axis 0).
    period : tuple of float
        ``(lx, ly)``.
    fluid_fraction : float
        Fraction of the cells with a gap (not in contact).
    connected_fraction : float
        Fraction of the cells in fluid clusters that wind around the cell along the flow
        (the flow-carrying clusters including their dead ends).
    percolating : bool
        Whether any fluid cluster winds around the cell along the flow.
    face : str
        Face conductance rule (``"harmonic"`` or ``"arithmetic"``).
    solver : str
        ``"direct"`` (SuperLU), ``"amg"`` (pyamg smoothed aggregation preconditioning CG)
        or ``"none"`` (nothing to solve).
    unknowns : int
        Size of the linear system.
    converged : bool
        False when CG stopped at ``max_iter`` before reaching ``tol``.
    iterations : int
        CG iterations (0 for the direct solver).
    residual : float
        Relative residual ``||b - A phi|| / ||b||`` of the solved system.
    conservation_error : float
        Largest deviation of the flux through one grid line across the flow from the mean,
        relative to the mean flux (zero for an exact solve).
    wall_time : float
        Seconds spent in the call.
    """

    k_eff: float
    k_transverse: float
    flux: float
    pressure: np.ndarray = field(repr=False)
    fluctuation: np.ndarray = field(repr=False)
    direction: str
    period: tuple[float, float]
    fluid_fraction: float
    connected_fraction: float
    percolating: bool
    face: str
    solver: str
    unknowns: int
    converged: bool
    iterations: int
    residual: float
    conservation_error: float
    wall_time: float


def _cell(gap, period, contact, *, smallest: int) -> tuple[np.ndarray, tuple[float, float], np.ndarray]:
    """The gap as a finite ``(ny, nx)`` array (each side >= ``smallest``), the periods
    ``(lx, ly)`` and the contact mask (False where not given), checked."""
    g = real_array(gap, "gap", ndim=(2,))
    if min(g.shape) < smallest:
        raise InputError(f"gap: an array of shape {g.shape} is not allowed; allowed: (ny, nx) with nx, ny >= "
                         f"{smallest}", 2)
    lx, ly = periods(period)
    closed = np.zeros(g.shape, dtype=bool) if contact is None else np.asarray(contact, dtype=bool)
    if closed.shape != g.shape:
        raise InputError(f"contact: shape {closed.shape} is not allowed; allowed: the gap's, {g.shape}", 2)
    return g, (lx, ly), closed


def _check_iteration(tol, max_iter) -> None:
    """The iteration's tolerance and budget: the ranges of ``&output leakage_tol`` and a
    positive number of iterations (InputError otherwise)."""
    low, high = (float(v) for v in _CONSTANTS["leakage/tol_range"].split())
    if not (isinstance(tol, (int, float, np.floating, np.integer)) and low <= float(tol) <= high):
        raise InputError(f"tol = {tol!r} is not allowed; allowed: {low:g} <= tol <= {high:g}", 2)
    if isinstance(max_iter, (bool, np.bool_)) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise InputError(f"max_iter = {max_iter!r} is not allowed; allowed: an integer >= 1", 2)


def reynolds_leakage(
    gap,
    period=1.0,
    direction: str = "x",
    *,
    contact=None,
    contact_threshold: float | None = None,
    viscosity: float = 1.0,
    pressure_gradient: float = 1.0,
    face: str = "harmonic",
    method: str = "auto",
    tol: float = 1e-6,
    max_iter: int = 500,
) -> LeakageResult:
    """Reynolds thin-film flow through the periodic gap ``gap`` under a mean pressure
    gradient along ``direction``.

    Parameters
    ----------
    gap : array_like
        ``(ny, nx)`` gap (L) on the grid ``x = j lx/nx`` (axis 1), ``y = i ly/ny`` (axis 0),
        for example ``solve_areal(...).gap``.
    period : float or (float, float)
        Period (L), or the pair ``(lx, ly)``.
    direction : {"x", "y"}
        Direction of the imposed mean pressure gradient.
    contact : array_like of bool, optional
        ``(ny, nx)`` contact mask (for example ``result.pressure > 0``); these cells are
        closed whatever their gap.
    contact_threshold : float, optional
        Cells with ``gap <= contact_threshold`` are in contact. Default ``1e-6 max(gap)``,
        which closes the residual gaps (about ``1e-8 max(gap)``) of a converged contact
        solve and changes the conductance by a relative ``1e-18`` per cell at most. A gap
        below ``-contact_threshold`` outside ``contact`` is an error.
    viscosity : float
        Dynamic viscosity ``eta``; only ``flux`` depends on it.
    pressure_gradient : float
        Magnitude ``G`` of the mean pressure gradient (pressure drop per length).
    face : {"harmonic", "arithmetic"}
        Face conductance: harmonic mean of the two ``g^3`` (default, see the module
        docstring), or the cube of the arithmetic mean gap (zero on faces of contact cells).
    method : {"auto", "direct", "amg"}
        Linear solver: SuperLU, pyamg smoothed-aggregation AMG as the preconditioner of CG,
        or the direct solver up to 30 000 unknowns and AMG beyond.
    tol : float
        Relative error of ``k_eff`` at which CG stops (``method="amg"``), estimated from
        the energy decrease of the last five iterations. The pressure is then accurate to
        about ``sqrt(tol)`` in the energy norm; near percolation the flux through single
        grid lines (``conservation_error``) converges more slowly: 15 %, 2 % and 0.6 % at
        ``tol`` 1e-6, 1e-8 and 1e-10 on a 2048^2 elastic gap at contact area 0.38. Lower
        ``tol`` (or use the direct solver) for flux maps.
    max_iter : int
        Largest number of CG iterations.

    Returns
    -------
    LeakageResult
    """
    start = time.perf_counter()
    g, (lx, ly), closed = _cell(gap, period, contact, smallest=1)
    if direction not in ("x", "y"):
        raise ValueError(f"direction must be 'x' or 'y'; got {direction!r}")
    if face not in ("harmonic", "arithmetic"):
        raise ValueError(f"face must be 'harmonic' or 'arithmetic'; got {face!r}")
    if method not in ("auto", "direct", "amg"):
        raise ValueError(f"method must be 'auto', 'direct' or 'amg'; got {method!r}")
    if not (viscosity > 0 and pressure_gradient >= 0):
        raise ValueError("viscosity must be > 0 and pressure_gradient >= 0")
    _check_iteration(tol, max_iter)

    if contact_threshold is None:
        contact_threshold = _CONTACT_THRESHOLD_RELATIVE * max(float(g.max()), 0.0)
    if np.any(g[~closed] < -contact_threshold):
        raise ValueError(
            f"gap must be >= 0 outside contact; smallest value {g[~closed].min():.3e} is below "
            f"-contact_threshold = {-contact_threshold:.3e}"
        )
    fluid = ~closed & (g > max(contact_threshold, _SMALLEST_GAP))
    g = np.where(fluid, g, 0.0)

    # The solve runs with the flow along axis 1; a flow along y is the transposed problem.
    if direction == "y":
        g, fluid, h_flow, h_across = g.T, fluid.T, ly / g.shape[0], lx / g.shape[1]
    else:
        h_flow, h_across = lx / g.shape[1], ly / g.shape[0]
    n_flow = g.shape[1]
    c_flow, c_across = _face_conductances(g, face)

    cluster, winds = _flow_clusters(fluid)
    active = winds[cluster]
    phi = np.full(g.shape, np.nan)
    solver, unknowns, iterations, converged, residual, k_eff = "none", 0, 0, True, 0.0, 0.0
    if active.any():
        system = _assemble(active, cluster, c_flow, c_across, h_flow, h_across)
        solution, solver, iterations, converged = _solve(system, method, tol, max_iter)
        unknowns = solution.size
        phi[active] = system.grid(solution)[active]
        k_eff = system.dissipation(solution) / g.size
        if np.any(system.rhs):
            misfit = system.rhs - system.matrix @ solution
            residual = float(np.sqrt(_dot(misfit, misfit) / _dot(system.rhs, system.rhs)))

    # Mean flux (times 12 eta / G) through the faces, for the transverse conductance and the
    # conservation check; clusters that do not wind along the flow carry no net flux.
    phi_open = np.where(active, phi, 0.0)
    q_flow = np.where(active, c_flow * (phi_open - np.roll(phi_open, -1, axis=1) + h_flow) / h_flow, 0.0)
    q_across = np.where(active, c_across * (phi_open - np.roll(phi_open, -1, axis=0)) / h_across, 0.0)
    k_transverse = float(q_across.mean())
    line_flux = q_flow.mean(axis=0)
    conservation_error = float(np.abs(line_flux - k_eff).max() / k_eff) if k_eff > 0 else 0.0

    s = np.arange(n_flow) * h_flow
    pressure = pressure_gradient * (phi - s[None, :])
    fluctuation = pressure_gradient * phi
    if direction == "y":
        pressure, fluctuation = pressure.T.copy(), fluctuation.T.copy()
    return LeakageResult(
        k_eff=k_eff,
        k_transverse=k_transverse,
        flux=k_eff * pressure_gradient / (12.0 * viscosity),
        pressure=pressure,
        fluctuation=fluctuation,
        direction=direction,
        period=(lx, ly),
        fluid_fraction=float(fluid.mean()),
        connected_fraction=float(active.mean()),
        percolating=bool(active.any()),
        face=face,
        solver=solver,
        unknowns=unknowns,
        converged=converged,
        iterations=iterations,
        residual=residual,
        conservation_error=conservation_error,
        wall_time=time.perf_counter() - start,
    )


def _face_conductances(g: np.ndarray, face: str) -> tuple[np.ndarray, np.ndarray]:
    """Conductances of the faces between cell ``[i, j]`` and ``[i, j+1]`` (axis 1, the flow)
    and ``[i+1, j]`` (axis 0), periodic, zero on every face of a cell with ``g = 0``."""
    if face == "harmonic":
        # In series: c = 2/(r + r_next) with the resistance r = 1/g^3, infinite in contact.
        with np.errstate(divide="ignore"):
            resistance = 1.0 / (g * g * g)
        return tuple(2.0 / (resistance + np.roll(resistance, -1, axis=axis)) for axis in (1, 0))
    faces = []
    for axis in (1, 0):
        g_next = np.roll(g, -1, axis=axis)
        mean = 0.5 * (g + g_next)
        faces.append(np.where((g > 0) & (g_next > 0), mean * mean * mean, 0.0))
    return faces[0], faces[1]


def _flow_clusters(fluid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fluid clusters (4-connected, periodic) and whether each winds around the cell along
    axis 1: only those carry net flux along it.

    Clusters of the non-periodic grid (``scipy.ndimage.label``) are joined across the two
    seams by a union-find with offsets: crossing the axis-1 seam advances the winding
    number by one, crossing the axis-0 seam by zero. A joined cluster winds along axis 1
    when two paths between the same pieces differ in winding number. The Python loop runs
    over the seam crossings only (at most ``nx + ny``).

    Returns
    -------
    cluster : (ny, nx) int array
        Cluster number of each cell (0 outside the fluid); equal numbers, one periodic cluster.
    winds : bool array
        ``winds[cluster]`` is True for the cells of flow-carrying clusters (``winds[0]`` False).
    """
    labels, n_labels = ndi.label(fluid)
    parent = np.arange(n_labels + 1)
    rank = np.zeros(n_labels + 1, dtype=np.int64)
    offset = np.zeros(n_labels + 1, dtype=np.int64)  # winding of a piece relative to its parent
    winds = np.zeros(n_labels + 1, dtype=bool)

    def find(a):
        # Union by rank keeps the trees log-deep, so no path compression is needed.
        shift = 0
        while parent[a] != a:
            shift += offset[a]
            a = parent[a]
        return a, shift

    seams = (
        (labels[:, -1], labels[:, 0], 1),  # leaving the last column enters the first, one period on
        (labels[-1, :], labels[0, :], 0),
    )
    for last, first, step in seams:
        both = (last > 0) & (first > 0)
        for a, b in np.unique(np.stack([last[both], first[both]], axis=1), axis=0):
            # The winding of piece b is that of piece a plus step.
            root_a, shift_a = find(a)
            root_b, shift_b = find(b)
            if root_a == root_b:
                winds[root_a] |= shift_b != shift_a + step
                continue
            relative = shift_a + step - shift_b  # winding of root_b minus that of root_a
            if rank[root_a] < rank[root_b]:
                root_a, root_b, relative = root_b, root_a, -relative
            parent[root_b] = root_a
            offset[root_b] = relative
            rank[root_a] += rank[root_a] == rank[root_b]
            winds[root_a] |= winds[root_b]
    roots = parent.copy()
    while not np.array_equal(roots[roots], roots):
        roots = roots[roots]
    return roots[labels], winds


@dataclass
class _FlowSystem:
    """The finite-volume system on the flow-carrying cells. ``weight_flow`` and
    ``weight_across`` (grid arrays) are ``c/h^2`` of the face from each cell to its next
    neighbour along the flow and across it; ``step`` is the grid step along the flow, the
    jump of ``s`` across a face. The unknowns are ``phi`` at the cells ``free`` (flat
    indices); pinned and inactive cells have ``phi = 0``."""

    weight_flow: np.ndarray
    weight_across: np.ndarray
    step: float
    matrix: sp.csr_matrix
    rhs: np.ndarray
    free: np.ndarray

    def grid(self, phi_free: np.ndarray) -> np.ndarray:
        """``phi`` on the grid, zero outside the unknowns."""
        phi = np.zeros(self.weight_flow.shape)
        phi.ravel()[self.free] = phi_free
        return phi

    def dissipation(self, phi_free: np.ndarray) -> float:
        """``sum_faces w (phi - phi_next + jump)^2``: ``n_cells k_eff`` at the solution, above
        it by the squared energy norm of the error elsewhere (faces outside the flow-carrying
        clusters have zero weight here)."""
        phi = self.grid(phi_free)
        drop_flow = phi - np.roll(phi, -1, axis=1) + self.step
        drop_across = phi - np.roll(phi, -1, axis=0)
        return _dot((self.weight_flow * drop_flow).ravel(), drop_flow.ravel()) + _dot(
            (self.weight_across * drop_across).ravel(), drop_across.ravel()
        )


def _assemble(active, cluster, c_flow, c_across, h_flow, h_across) -> _FlowSystem:
    """Build the 5-point system for ``phi`` on the ``active`` cells with one pinned cell
    (``phi = 0``) per periodic ``cluster``, row by row in CSR form."""
    n_cells = active.size
    flat_active = np.flatnonzero(active)
    # Pin one cell of each flow-carrying cluster: it keeps its faces (and their
    # dissipation) but leaves the unknowns.
    pinned = np.full(int(cluster.max()) + 1, n_cells)
    np.minimum.at(pinned, cluster.ravel()[flat_active], flat_active)
    free_mask = active.ravel().copy()
    free_mask[pinned[pinned < n_cells]] = False
    free = np.flatnonzero(free_mask)
    # int32 indices, as scipy stores them, below 2^31 unknowns.
    index = np.int32 if free.size < 2**31 - 1 else np.int64
    number = np.full(active.shape, -1, dtype=index)
    number.ravel()[free] = np.arange(free.size, dtype=index)

    # Open faces join cells of one cluster, so weights restricted to active cells keep
    # exactly the faces of the flow-carrying clusters.
    east = np.where(active, c_flow, 0.0) / h_flow**2
    north = np.where(active, c_across, 0.0) / h_across**2
    n_across, n_flow = active.shape
    row, col = np.divmod(free, n_flow)
    neighbours = (  # flat indices of the east, west, north and south neighbours
        row * n_flow + (col + 1) % n_flow,
        row * n_flow + (col - 1) % n_flow,
        (row + 1) % n_across * n_flow + col,
        (row - 1) % n_across * n_flow + col,
    )
    weights = (
        east.ravel()[free],
        east.ravel()[neighbours[1]],
        north.ravel()[free],
        north.ravel()[neighbours[3]],
    )
    # Rows of five entries: diagonal, east, west, north, south; a face to a pinned cell
    # (number -1) only adds to the diagonal.
    columns = np.empty((free.size, 5), dtype=index)
    values = np.empty((free.size, 5))
    columns[:, 0] = np.arange(free.size, dtype=index)
    values[:, 0] = sum(weights)
    for k, (neighbour, weight) in enumerate(zip(neighbours, weights), start=1):
        columns[:, k] = number.ravel()[neighbour]
        values[:, k] = -weight
    kept = (columns >= 0) & (values != 0.0)
    kept[:, 0] = True
    indptr = np.zeros(free.size + 1, dtype=np.int64)
    np.cumsum(kept.sum(axis=1), out=indptr[1:])
    if indptr[-1] < 2**31 - 1:
        indptr = indptr.astype(np.int32)
    matrix = sp.csr_matrix((values[kept], columns[kept], indptr), shape=(free.size, free.size))
    matrix.sum_duplicates()  # sorts the columns; a grid one cell long has a cell as its own neighbour
    # b = -D^T W j with the jump h_flow on the faces along the flow.
    rhs = h_flow * (weights[1] - weights[0])
    return _FlowSystem(east, north, h_flow, matrix, rhs, free)


def _solve(system: _FlowSystem, method: str, tol: float, max_iter: int):
    """Solve ``A phi = b``. Returns ``(phi, solver, iterations, converged)``."""
    matrix, rhs = system.matrix, system.rhs
    n = rhs.size
    if n == 0 or not np.any(rhs):
        return np.zeros(n), "none", 0, True
    if method == "direct" or (method == "auto" and n <= _DIRECT_MAX_UNKNOWNS):
        # Minimum-degree ordering of A + A^T: SuperLU's default column ordering fills about
        # twice as much on these grid Laplacians.
        factor = spla.splu(matrix.tocsc(), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
        return factor.solve(rhs), "direct", 0, True
    cycle = _smoothed_aggregation(matrix).aspreconditioner(cycle="V")
    phi, iterations, converged = _pcg(matrix, rhs, cycle.matvec, system.dissipation, tol, max_iter)
    return phi, "amg", iterations, converged


def _smoothed_aggregation(matrix: sp.csr_matrix):
    """Smoothed-aggregation AMG hierarchy (Vanek, Mandel and Brezina, *Algebraic multigrid
    by smoothed aggregation for second and fourth order elliptic problems*) from pyamg's
    components, for the constant near-null space.

    Three choices differ from ``pyamg.smoothed_aggregation_solver``'s defaults:

    * classical (Ruge-Stueben) strength of connection with threshold 0.5, so that
      aggregates do not straddle the faces of tiny conductance near contact and at narrow
      necks; the default symmetric strength takes two to twenty times more iterations on
      gaps near percolation;
    * the prolongation is smoothed with the row-wise Gershgorin weight ``omega/sum_j |a_ij|``
      (pyamg's ``weighting='local'``) computed here on CSR matrices: pyamg's Arnoldi
      estimate of the spectral radius, or its local weighting on the BSR matrices of its
      coarse levels, takes three quarters of its setup time at 2048^2;
    * one forward Gauss-Seidel sweep before and one backward sweep after the coarse
      correction (symmetric V-cycle) instead of a symmetric sweep on each side: fewer sweeps
      for about the same number of CG iterations; SuperLU on the coarsest level (pyamg's
      default ``pinv`` calls threaded LAPACK, slow on busy cores).
    """
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers
    from pyamg.strength import classical_strength_of_connection

    a = matrix.tocsr()
    level = MultilevelSolver.Level()
    level.A = a
    levels = [level]
    candidates = np.ones((a.shape[0], 1))
    while a.shape[0] > _AMG_MAX_COARSE and len(levels) < _AMG_MAX_LEVELS:
        aggregates, _ = standard_aggregation(classical_strength_of_connection(a, theta=_AMG_STRENGTH))
        tentative, candidates = fit_candidates(aggregates, candidates)
        tentative = sp.csr_matrix(tentative)
        row_sum = abs(a) @ np.ones(a.shape[0])
        weight = np.divide(4.0 / 3.0, row_sum, out=np.zeros_like(row_sum), where=row_sum > 0)
        prolongation = (tentative - sp.diags(weight) @ (a @ tentative)).tocsr()
        level.P, level.R = prolongation, prolongation.T.tocsr()
        a = (level.R @ a @ prolongation).tocsr()
        level = MultilevelSolver.Level()
        level.A = a
        levels.append(level)
    hierarchy = MultilevelSolver(levels, coarse_solver="splu")
    change_smoothers(
        hierarchy,
        presmoother=("gauss_seidel", {"sweep": "forward"}),
        postsmoother=("gauss_seidel", {"sweep": "backward"}),
    )
    return hierarchy


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """Inner product without BLAS: a threaded BLAS dot on a machine whose cores are busy can
    be a thousand times slower than this loop (measured at 25 000 entries)."""
    return float(np.einsum("i,i", a, b))


def _pcg(matrix, rhs, precondition, dissipation, tol, max_iter):
    """Preconditioned conjugate gradients stopped on the energy error of ``phi``.

    CG lowers ``J(phi) = phi^T A phi - 2 b^T phi`` by ``alpha rho`` per step, and
    ``J(phi_k) - J(phi*)`` is the squared energy norm of the error, which is also the excess
    of the dissipation over ``n_cells k_eff``. The decrease over the next ``_CG_DELAY``
    steps is a lower bound of that error (Strakoš and Tichý, *On error estimation in the
    conjugate gradient method and why it works in finite precision computations*), used as
    its estimate: stop when it is below ``tol`` times the dissipation.
    """
    phi = np.zeros_like(rhs)
    residual = rhs.copy()
    z = precondition(residual)
    direction = z.copy()
    rho = _dot(residual, z)
    decreases: list[float] = []
    # The dissipation only falls, so a stale value screens the test and a fresh one decides.
    bound = dissipation(phi)
    for iteration in range(1, max_iter + 1):
        if rho <= 0.0:  # the residual vanished (or the preconditioner broke down)
            return phi, iteration - 1, rho == 0.0
        q = matrix @ direction
        alpha = rho / _dot(direction, q)
        phi += alpha * direction
        residual -= alpha * q
        decreases.append(alpha * rho)
        if len(decreases) >= _CG_DELAY and sum(decreases[-_CG_DELAY:]) <= tol * bound:
            bound = dissipation(phi)
            if sum(decreases[-_CG_DELAY:]) <= tol * bound:
                return phi, iteration, True
        z = precondition(residual)
        rho_next = _dot(residual, z)
        direction *= rho_next / rho
        direction += z
        rho = rho_next
    return phi, max_iter, False


@dataclass
class CoreLeakage:
    """The Reynolds leakage along x and along y computed by the compiled core: the group
    ``/leakage`` of a result file written with ``&output leakage = .true.`` (``ArealResult.leakage``),
    or :func:`core_leakage`. Same discretisation, contact rule and ``k_eff`` as
    :func:`reynolds_leakage`; the linear solver is conjugate gradients preconditioned by
    hypre's BoomerAMG, stopped on the same energy-error estimate.

    Attributes
    ----------
    k_eff_x, k_eff_y : float
        ``12 eta <q>/G`` (L^3) for a mean pressure gradient along x and along y: ``g^3`` for
        a uniform gap ``g``, zero when the fluid does not percolate along that direction.
    percolating_x, percolating_y : bool
        Whether a fluid cluster winds around the cell along x (along y).
    fluid_fraction : float
        Fraction of the cells with a gap (not in contact).
    connected_fraction_x, connected_fraction_y : float
        Fraction of the cells in the flow-carrying clusters along x (along y).
    unknowns_x, unknowns_y : int
        Size of each linear system.
    iterations_x, iterations_y : int
        CG iterations.
    residual_x, residual_y : float
        Relative residual ``||b - A phi||/||b||`` of each solve.
    converged : bool
        Both solves reached ``tol`` (otherwise ``k_eff`` is an upper bound).
    tol : float
        Relative accuracy of ``k_eff`` asked for (``&output leakage_tol``).
    solver : str
        The linear solver.
    wall_time : float
        Seconds spent on both directions.
    """

    k_eff_x: float
    k_eff_y: float
    percolating_x: bool
    percolating_y: bool
    fluid_fraction: float
    connected_fraction_x: float
    connected_fraction_y: float
    unknowns_x: int
    unknowns_y: int
    iterations_x: int
    iterations_y: int
    residual_x: float
    residual_y: float
    converged: bool
    tol: float
    solver: str
    wall_time: float

    @classmethod
    def from_attributes(cls, attrs) -> "CoreLeakage":
        """From the attributes of a result file's ``/leakage`` group."""
        values = {}
        for name, kind in cls.__annotations__.items():
            value = attrs[name]
            if kind == "str":
                values[name] = value.decode() if isinstance(value, bytes) else str(value)
            elif kind == "bool":
                values[name] = bool(value)
            elif kind == "int":
                values[name] = int(value)
            else:
                values[name] = float(value)
        return cls(**values)


def core_leakage(
    gap,
    period=1.0,
    *,
    contact=None,
    tol: float | None = None,
    max_iter: int | None = None,
) -> CoreLeakage:
    """The Reynolds leakage along x and along y of ``gap`` by the compiled core, as a run
    with ``&output leakage = .true.`` computes it (:class:`CoreLeakage`).

    Parameters
    ----------
    gap : array_like
        ``(ny, nx)`` gap (L), x = axis 1, as for :func:`reynolds_leakage`.
    period : float or (float, float)
        Period (L), or the pair ``(lx, ly)``.
    contact : array_like of bool, optional
        ``(ny, nx)`` contact mask; cells with ``gap <= 1e-6 max(gap)`` are closed as well.
    tol : float, optional
        Relative accuracy of ``k_eff`` at which CG stops (energy-error estimate); default
        that of ``&output leakage_tol`` (1e-6), the same range.
    max_iter : int, optional
        Largest number of CG iterations per direction; default that of a run (500).
    """
    from .native import core

    tol = float(_CONSTANTS["output/leakage_tol"]) if tol is None else tol
    max_iter = int(_CONSTANTS["leakage/max_iter"]) if max_iter is None else max_iter
    _check_iteration(tol, max_iter)
    tol = float(tol)

    # (nx, ny >= 4: an areal grid, as the core's run has)
    g, (lx, ly), closed = _cell(gap, period, contact, smallest=4)
    values, counts, stat, errmsg = core.py_reynolds_leakage(
        np.ascontiguousarray(g.ravel()), np.ascontiguousarray(closed.ravel(), dtype=np.int32), g.shape[1], lx, ly,
        tol,
        max_iter,
    )
    _check(stat, errmsg)
    return CoreLeakage(
        k_eff_x=float(values[0]), k_eff_y=float(values[1]),
        percolating_x=bool(counts[0]), percolating_y=bool(counts[1]),
        fluid_fraction=float(values[4]),
        connected_fraction_x=float(values[2]), connected_fraction_y=float(values[3]),
        unknowns_x=int(counts[4]), unknowns_y=int(counts[5]),
        iterations_x=int(counts[2]), iterations_y=int(counts[3]),
        residual_x=float(values[5]), residual_y=float(values[6]),
        converged=bool(counts[6] and counts[7]), tol=tol,
        solver=_CONSTANTS["leakage/solver"],
        wall_time=float(values[7]),
    )
