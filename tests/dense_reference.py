"""A third solver for the discretised line contact, independent of the library's: a dense
semismooth Newton method on the Fischer-Burmeister function (numpy, dense LU), for grids up
to ~1024 points. It solves the same point-collocation problem as the library under load
control,

    p >= 0, gap = G p - r - s >= 0, p gap = 0, mean(p) = p_m,

with G the circulant matrix of the multipliers G_eff(k) (reference_operator.py, uniform mode
left out: under load control it only shifts s). The Fischer-Burmeister function
phi(a, b) = sqrt(a^2 + b^2) - a - b vanishes iff a >= 0, b >= 0, a b = 0; with a = p/p_m and
b = gap/ptp(r) the residual is scaled as the library's. Newton steps on (p, s) with an
Armijo line search on |Phi|^2 converge for monotone problems (Re G_eff >= 0) from a uniform
start, and quadratically near the solution; a step at a degenerate point (a = b = 0) uses
the element (1/sqrt 2 - 1, 1/sqrt 2 - 1) of the generalised Jacobian.
"""

from __future__ import annotations

import numpy as np


def circulant(g: np.ndarray, n: int) -> np.ndarray:
    """The n x n matrix of p -> irfft(g rfft(p)) with the uniform mode dropped (g: the
    multipliers of modes 0..n/2, numpy rfft order)."""
    mult = np.array(g, dtype=complex)
    mult[0] = 0.0
    column = np.fft.irfft(mult, n=n)          # the response to a unit load at x_0
    index = (np.arange(n)[:, None] - np.arange(n)[None, :]) % n
    return column[index]


def solve_dense(heights: np.ndarray, g: np.ndarray, mean_pressure: float, tol: float = 1e-13,
                max_steps: int = 1000) -> tuple[np.ndarray, float, float]:
    """(p, s, residual): the pressure, the multiplier and the complementarity residual
    max_j |min(p_j/p_m, gap_j/ptp(r))| of the dense semismooth Newton solution."""
    r = np.asarray(heights, dtype=float)
    n = r.size
    G = circulant(g, n)
    p_scale, g_scale = mean_pressure, np.ptp(r)

    def residuals(p: np.ndarray, s: float):
        gap = G @ p - r - s
        a, b = p / p_scale, gap / g_scale
        root = np.hypot(a, b)
        return np.append(root - a - b, p.mean() / p_scale - 1.0), a, b, root, gap

    p = np.full(n, mean_pressure)
    s = float(np.mean(G @ p - r))
    for _ in range(max_steps):
        phi, a, b, root, gap = residuals(p, s)
        residual = float(np.max(np.abs(np.minimum(p / p_scale, gap / g_scale))))
        if residual <= tol:
            break
        degenerate = root == 0.0
        safe = np.where(degenerate, 1.0, root)
        da = np.where(degenerate, 2**-0.5 - 1.0, a / safe - 1.0)
        db = np.where(degenerate, 2**-0.5 - 1.0, b / safe - 1.0)
        jac = np.empty((n + 1, n + 1))
        jac[:n, :n] = (db / g_scale)[:, None] * G
        jac[np.arange(n), np.arange(n)] += da / p_scale
        jac[:n, n] = -db / g_scale
        jac[n, :n] = 1.0 / (n * p_scale)
        jac[n, n] = 0.0
        step = np.linalg.solve(jac, -phi)
        merit = phi @ phi
        t = 1.0
        while t > 1e-12:
            trial = residuals(p + t * step[:n], s + t * step[n])[0]
            if trial @ trial <= (1.0 - 1e-4 * t) * merit:
                break
            t *= 0.5
        p, s = p + t * step[:n], s + t * step[n]
    p = np.maximum(p, 0.0)   # the Newton iterate may be negative by rounding where p = 0
    gap = G @ p - r - s
    residual = float(np.max(np.abs(np.minimum(p / p_scale, gap / g_scale))))
    return p, s, residual
