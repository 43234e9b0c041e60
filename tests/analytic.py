"""Closed-form contact solutions used as test oracles.

Westergaard's periodic problem (Westergaard, J. Appl. Mech. 6 (1939) A49; Johnson,
Greenwood & Higginson, Int. J. Mech. Sci. 27 (1985) 383; Johnson, Contact Mechanics
§13.2): a rigid sinusoid r(x) = h0 cos(2 pi x/lam), crest at x = 0, frictionless on an
elastic half-plane of contact modulus Es = E/(1-nu^2), mean pressure p_m. Full contact
needs p* = pi Es h0/lam.

Conventions of layercontact: w = indentation, gap g = w - (r - h0 + Delta), and the
uniform (k = 0) mode of w of the periodic half-plane is zero, so mean(g) = h0 - Delta.
"""

from __future__ import annotations

import numpy as np


def westergaard_full_contact_pressure(Es, h0, lam):
    """p* = pi Es h0/lam."""
    return np.pi * Es * h0 / lam


def westergaard_half_width(p_m, Es, h0, lam):
    """Contact half-width a: sin^2(pi a/lam) = p_m/p* (lam/2 in full contact)."""
    ratio = np.minimum(np.asarray(p_m) / westergaard_full_contact_pressure(Es, h0, lam), 1.0)
    return lam / np.pi * np.arcsin(np.sqrt(ratio))


def westergaard_pressure(x, p_m, Es, h0, lam):
    """p(x) = (2 p_m/sin^2 psi) cos(pi x/lam) sqrt(sin^2 psi - sin^2(pi x/lam)) for
    |x| < a (periodic), zero elsewhere; psi = pi a/lam. In full contact (p_m >= p*)
    p = p_m + p* cos(2 pi x/lam)."""
    pstar = westergaard_full_contact_pressure(Es, h0, lam)
    if p_m >= pstar:
        return p_m + pstar * np.cos(2 * np.pi * np.asarray(x) / lam)
    s2 = p_m / pstar
    theta = np.pi * (np.mod(np.asarray(x) / lam + 0.5, 1.0) - 0.5)
    inside = np.sin(theta) ** 2 < s2
    root = np.sqrt(np.where(inside, s2 - np.sin(theta) ** 2, 0.0))
    return np.where(inside, 2 * p_m / s2 * np.cos(theta) * root, 0.0)


def westergaard_mean_gap(p_m, Es, h0, lam):
    """Mean gap g_bar = h0 (1 - P + P ln P), P = p_m/p* (0 in full contact).

    Derivation: Delta = w(0) = -(2/(pi Es)) int p(x) ln|2 sin(pi x/lam)| dx (the periodic
    half-plane kernel with its k = 0 mode removed); with s = sin(pi x/lam) and
    int_0^1 sqrt(1-u^2) ln u du = -(pi/8)(1 + 2 ln 2) this gives
    Delta = (lam p_m/(pi Es)) (1 - ln P) = h0 P (1 - ln P), and g_bar = h0 - Delta.
    """
    ratio = np.minimum(np.asarray(p_m, dtype=float) / westergaard_full_contact_pressure(Es, h0, lam), 1.0)
    ratio_log_ratio = ratio * np.log(np.where(ratio > 0, ratio, 1.0))  # P ln P -> 0 as P -> 0
    return h0 * (1 - ratio + ratio_log_ratio)


def westergaard_sliding_tension(p_m, mu, Es, h0, lam):
    """Largest surface tension of Westergaard's contact sliding with Coulomb friction
    tau = mu p on an incompressible half-plane: 4 mu p_m cot(psi), psi = pi a/lam, at the
    trailing edge.

    Derivation: on an incompressible half-plane sigma_xx = -p - 2 mu H[p] at the surface
    (H the periodic Hilbert transform; the normal problem is not changed by the shear). With
    theta = pi x/lam and s = sin(psi), p = (2 p_m/s^2) cos(theta) sqrt(s^2 - sin^2 theta) is
    the boundary value of (2 p_m/s^2) [cos z sqrt(sin^2 z - s^2) - sin z cos z] (bounded as
    Im z -> inf), so H[p] = (2 p_m/s^2) sin(theta) cos(theta) in the contact, and at the
    trailing edge theta = -psi the tension is 4 mu p_m cos(psi)/s. Equivalently mu Es r'(x_e)
    with the indenter's slope there. For a -> 0 it is Johnson's 2 mu p0 (Contact Mechanics
    §7.1) with p0 = 2 p_m/s the Hertz peak pressure."""
    ratio = np.asarray(p_m) / westergaard_full_contact_pressure(Es, h0, lam)
    psi = np.arcsin(np.sqrt(ratio))
    return 4 * mu * p_m / np.tan(psi)
