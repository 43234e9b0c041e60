"""Layered stacks checked against a direct solve of the Navier equations in depth.

``lc.surface_tensor`` computes the surface compliance of a stack of layers with transfer and
stiffness matrices (``src/greens/stack.f90``, docs/theory.md "Layered stacks"), and
tests/fortran/test_greens_stack.f90 checks it against a dense mode solve. This file is a third,
independent method: it uses no potentials, no modes of a layer, no transfer or stiffness
matrices and none of the layer closed forms of docs/theory.md. It discretises the
displacement equations themselves,

    G laplacian(u) + (lambda + G) grad div u = 0,

for one wavevector ``q`` along ``x`` (``q_y = 0``; fields ``f(z) exp(i q x)``, ``z`` into the
stack), by Chebyshev collocation in ``z`` in every layer, and imposes the surface tractions,
the interface conditions and the base condition as rows of one linear system (solved by
static condensation of every element's interior nodes). With ``'`` the derivative in ``z``
the plane-strain part reads

    G u_x'' - (lambda + 2G) q^2 u_x + i q (lambda + G) u_z' = 0,
    (lambda + 2G) u_z'' - G q^2 u_z + i q (lambda + G) u_x' = 0,
    sigma_xz = G (u_x' + i q u_z),      sigma_zz = (lambda + 2G) u_z' + i q lambda u_x,

(the ``x`` and ``z`` components of the Navier equations with ``d/dx -> i q`` and
``div u = i q u_x + u_z'``), and the antiplane part is ``G u_y'' = G q^2 u_y``,
``sigma_yz = G u_y'``.

Convention P (docs/theory.md): the surface ``z = 0`` has the outward normal ``-z``, so the
traction on the body there is ``-(sigma_xz, sigma_yz, sigma_zz)``; a compressive pressure
``p`` and a shear traction ``tau_x`` along ``+x`` on the body are

    sigma_zz(0) = -p,     sigma_xz(0) = -tau_x,     sigma_yz(0) = -tau_y.

These signs are not taken on trust: ``test_one_bonded_layer_fixes_the_signs`` checks them on
one layer bonded to a rigid base, the case whose ``lc.surface_tensor`` is already validated
against the closed forms (seed Eqs. 7-9) and the mode solve.

Interfaces: bonded = ``u`` and ``(sigma_xz, sigma_yz, sigma_zz)`` continuous; slipping
(frictionless) = ``u_z`` and ``sigma_zz`` continuous, ``sigma_xz = sigma_yz = 0`` on both
sides. Rigid base: ``u = 0`` (bonded) or ``u_z = 0``, ``sigma_xz = sigma_yz = 0`` (slipping).
An elastic half-space below is its exact surface impedance, built here from the decaying
solutions of the same equations (``half_space_compliance``).

Every layer is split into Chebyshev elements of thickness at most ``QH_ELEMENT / |q|`` (joined
as bonded interfaces of the same material), so that the ``exp(+-|q| z)`` solutions stay
resolved to rounding at any ``|q| h``; the accuracy is then set by the points per element
and checked by comparing two resolutions.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import layercontact as lc

# Largest |q| times the thickness of one Chebyshev element (the solutions vary like
# exp(+-QH_ELEMENT/2 s) on the element's [-1, 1]).
QH_ELEMENT = 12.0
# Polynomial degree per element of the solve compared with the library, and of the coarser
# one it is compared with to show the discretisation is converged (see rtol).
N_FINE = 28
N_COARSE = 22


# --------------------------------------------------------------------------------------------
# the independent solve


def lame(young: float, poisson: float) -> tuple[float, float]:
    """Shear modulus G and Lamé's lambda of an isotropic material."""
    g = young / (2.0 * (1.0 + poisson))
    lam = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
    return g, lam


def cheb(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev-Gauss-Lobatto points ``s_j = cos(pi j/n)`` (from +1 down to -1) and the
    differentiation matrix on them (Trefethen, *Spectral Methods in MATLAB*, ch. 6), with
    the diagonal from the negative row sums."""
    j = np.arange(n + 1)
    s = np.cos(np.pi * j / n)
    c = np.where((j == 0) | (j == n), 2.0, 1.0) * (-1.0) ** j
    ds = s[:, None] - s[None, :]
    d = np.outer(c, 1.0 / c) / (ds + np.eye(n + 1))
    d -= np.diag(d.sum(axis=1))
    return s, d


def half_space_compliance(q: float, young: float, poisson: float) -> np.ndarray:
    """Surface compliance of an elastic half-space ``z > 0`` for the mode ``exp(i q x)``:
    ``(u_x, u_z)(0) = C (f_x, f_z)`` with ``f = -(sigma_xz, sigma_zz)(0)`` the force per area
    on its top face.

    Built from the two decaying solutions of the Navier equations: with ``k = |q|``,
    ``s = sgn q`` and ``u_x = i s a(z)``, every solution that decays is

        a = (alpha + beta z) exp(-k z),     u_z = (gamma - beta z) exp(-k z),
        beta = -k (alpha + gamma) (lambda + G)/(lambda + 3G)

    (substituting into the equations: the ``z exp(-k z)`` terms force the ``-beta`` in
    ``u_z``, the ``exp(-k z)`` terms the relation for ``beta``). The result is the standard

        C = (1 - nu)/(G k) [[1, i s c], [-i s c, 1]],     c = (1 - 2 nu)/(2 (1 - nu)),

    Dundurs' constant; ``test_half_space_impedance`` checks both this construction against
    that closed form and the closed form against ``lc.surface_tensor`` with no layer.
    """
    g, lam = lame(young, poisson)
    k, s = abs(q), math.copysign(1.0, q)
    r = (lam + g) / (lam + 3.0 * g)
    modes = []
    for alpha, gamma in ((1.0, 0.0), (0.0, 1.0)):
        beta = -k * (alpha + gamma) * r
        a0, da0 = alpha, beta - k * alpha          # a(0), a'(0)
        w0, dw0 = gamma, -beta - k * gamma         # u_z(0), u_z'(0)
        ux0, dux0 = 1j * s * a0, 1j * s * da0
        sxz = g * (dux0 + 1j * q * w0)
        szz = (lam + 2.0 * g) * dw0 + 1j * q * lam * ux0
        modes.append(((ux0, w0), (-sxz, -szz)))
    u = np.array([m[0] for m in modes]).T           # columns: modes
    f = np.array([m[1] for m in modes]).T
    return u @ np.linalg.inv(f)


def _condensed_basis(op: np.ndarray, k: int, n: int) -> np.ndarray:
    """The discrete solutions of one element: ``op`` is the collocated operator on the nodal
    values of ``k`` fields (field-major, ``n + 1`` nodes each, node 0 at the element's top).
    The equations are imposed at the ``n - 1`` interior nodes of every field; the end values
    of the fields are the free parameters. Returns ``Phi`` with ``nodal values = Phi @ ends``,
    ``ends = (f_1(top), f_1(bottom), ..., f_k(top), f_k(bottom))``: the element's ``2k``
    solutions (static condensation; the linear system is the same as solving all nodes at
    once, split into blocks small enough for a serial LAPACK call)."""
    m = n + 1
    ends = [f * m + j for f in range(k) for j in (0, n)]
    inner = [f * m + j for f in range(k) for j in range(1, n)]
    a = op[inner][:, inner]
    b = op[inner][:, ends]
    scale = 1.0 / np.abs(a).max(axis=1, keepdims=True)          # row equilibration
    phi = np.zeros((k * m, 2 * k), op.dtype)
    phi[ends] = np.eye(2 * k)
    phi[inner] = -np.linalg.solve(a * scale, b * scale)
    return phi


def _elements(q, layers, interfaces, n):
    """The Chebyshev elements of a stack and, per element, the plane-strain and antiplane
    functionals (displacements and tractions on the plane of normal +z) at its top and
    bottom, as rows acting on the element's end values."""
    _, d = cheb(n)
    m = n + 1
    eye = np.eye(m)
    out = []
    for (h, e, nu), below in zip(layers, interfaces):
        parts = max(1, math.ceil(abs(q) * h / QH_ELEMENT))
        g, lam = lame(e, nu)
        he = h / parts
        dz = -(2.0 / he) * d                       # z = z_top + (1 - s) h_e/2
        d2 = dz @ dz
        op = np.block([[g * d2 - (lam + 2 * g) * q * q * eye, 1j * q * (lam + g) * dz],
                       [1j * q * (lam + g) * dz, (lam + 2 * g) * d2 - g * q * q * eye]])
        phi = _condensed_basis(op, 2, n)
        phi_y = _condensed_basis(g * (d2 - q * q * eye), 1, n)
        for i in range(parts):
            fun = {}
            for end, j in (("top", 0), ("bottom", n)):
                ej = eye[j]
                rows = {
                    "ux": np.concatenate([ej, 0 * ej]),
                    "uz": np.concatenate([0 * ej, ej]),
                    "sxz": np.concatenate([g * dz[j], 1j * q * g * ej]),
                    "szz": np.concatenate([1j * q * lam * ej, (lam + 2 * g) * dz[j]]),
                }
                fun[end] = {key: r @ phi for key, r in rows.items()}
                fun[end]["uy"] = ej @ phi_y
                fun[end]["syz"] = (g * dz[j]) @ phi_y
            out.append(dict(fun=fun, below=below if i == parts - 1 else "bonded"))
    return out


class _Rows:
    """Rows of the global system on the elements' end values (``width`` per element)."""

    def __init__(self, els, width, nrhs):
        self.els, self.width = els, width
        self.size = width * len(els)
        self.a, self.b = [], []
        self.nrhs = nrhs

    def add(self, terms, rhs=None):
        """One condition: ``sum gain * functional(element, end) = rhs``."""
        row = np.zeros(self.size, complex)
        for e, end, key, gain in terms:
            row[self.width * e:self.width * (e + 1)] += gain * self.els[e]["fun"][end][key]
        self.a.append(row)
        self.b.append(np.zeros(self.nrhs) if rhs is None else np.asarray(rhs, float))

    def solve(self):
        a, b = np.array(self.a), np.array(self.b)
        assert a.shape == (self.size, self.size)
        scale = 1.0 / np.abs(a).max(axis=1, keepdims=True)
        return np.linalg.solve(a * scale, b * scale)


def navier_stack(q, layers, interfaces, substrate=None, n=N_FINE):
    """Surface compliance of a stack from the collocated Navier equations.

    ``layers``: ``[(h, E, nu), ...]`` from the top down; ``interfaces``: ``'bonded'`` or
    ``'slip'`` for the interface below each layer (the last one is the base); ``substrate``:
    ``None`` for a rigid base or ``(E_s, nu_s)`` for an elastic half-space; ``n``: the
    polynomial degree per element.

    Returns ``(T2, t_yy)``: the plane-strain block ``(u_x, w) = T2 (tau_x, p)`` and the
    antiplane compliance ``u_y = t_yy tau_y``, complex, in convention P.
    """
    els = _elements(q, layers, interfaces, n)
    last, below = len(els) - 1, els[-1]["below"]

    # plane strain, two right-hand sides: tau_x = 1 and p = 1
    rows = _Rows(els, 4, 2)
    rows.add([(0, "top", "sxz", 1.0)], [-1.0, 0.0])         # sigma_xz(0) = -tau_x
    rows.add([(0, "top", "szz", 1.0)], [0.0, -1.0])         # sigma_zz(0) = -p
    for e in range(last):
        if els[e]["below"] == "bonded":
            for key in ("ux", "uz", "sxz", "szz"):
                rows.add([(e, "bottom", key, 1.0), (e + 1, "top", key, -1.0)])
        else:
            for key in ("uz", "szz"):
                rows.add([(e, "bottom", key, 1.0), (e + 1, "top", key, -1.0)])
            rows.add([(e, "bottom", "sxz", 1.0)])
            rows.add([(e + 1, "top", "sxz", 1.0)])
    if substrate is None and below == "bonded":
        rows.add([(last, "bottom", "ux", 1.0)])
        rows.add([(last, "bottom", "uz", 1.0)])
    elif substrate is None:
        rows.add([(last, "bottom", "uz", 1.0)])
        rows.add([(last, "bottom", "sxz", 1.0)])
    else:
        cb = half_space_compliance(q, *substrate)
        if below == "bonded":
            # u(z_b) = C_b f, f = -(sigma_xz, sigma_zz)(z_b) the force on the half-space
            for i, key in enumerate(("ux", "uz")):
                rows.add([(last, "bottom", key, 1.0), (last, "bottom", "sxz", cb[i, 0]),
                         (last, "bottom", "szz", cb[i, 1])])
        else:
            # frictionless: f_x = 0, so u_z(z_b) = C_b,zz f_z, and sigma_xz(z_b) = 0
            rows.add([(last, "bottom", "uz", 1.0), (last, "bottom", "szz", cb[1, 1])])
            rows.add([(last, "bottom", "sxz", 1.0)])
    ends = rows.solve()
    t2 = ends[[0, 2]]                      # (u_x, u_z) at the top of element 0

    # antiplane
    rows = _Rows(els, 2, 1)
    rows.add([(0, "top", "syz", 1.0)], [-1.0])               # sigma_yz(0) = -tau_y
    for e in range(last):
        if els[e]["below"] == "bonded":
            for key in ("uy", "syz"):
                rows.add([(e, "bottom", key, 1.0), (e + 1, "top", key, -1.0)])
        else:
            rows.add([(e, "bottom", "syz", 1.0)])
            rows.add([(e + 1, "top", "syz", 1.0)])
    if below == "slip":
        rows.add([(last, "bottom", "syz", 1.0)])             # no shear, rigid or elastic
    elif substrate is None:
        rows.add([(last, "bottom", "uy", 1.0)])
    else:
        # half-space: u_y = A exp(-|q| (z - z_b)), so sigma_yz(z_b) = -|q| G_s u_y(z_b)
        gs, _ = lame(*substrate)
        rows.add([(last, "bottom", "syz", 1.0), (last, "bottom", "uy", abs(q) * gs)])
    t_yy = rows.solve()[0, 0]
    return t2, t_yy


# --------------------------------------------------------------------------------------------
# the library, in the same layout


def library_tensor(q, layers, interfaces, substrate=None):
    """``lc.surface_tensor`` at ``(q, 0)`` for the same stack (3x3, ``(x, y, z)``)."""
    (h1, e1, nu1), lower = layers[0], layers[1:]
    kw = dict(thickness=h1, young=e1, poisson=nu1, interface=interfaces[0])
    if lower:
        kw.update(lower_thickness=[lay[0] for lay in lower], lower_young=[lay[1] for lay in lower],
                  lower_poisson=[lay[2] for lay in lower],
                  lower_interfaces=" ".join(interfaces[1:]))
    if substrate is not None:
        kw.update(substrate_young=substrate[0], substrate_poisson=substrate[1])
    return lc.surface_tensor(q, 0.0, **kw)


XZ = np.ix_([0, 2], [0, 2])


def rtol(q: float, h1: float = 1.0) -> float:
    """Relative tolerance of the collocated compliance at ``|q| h_1``.

    Two error sources, both measured on the stacks below. Truncation: at the largest
    ``|q| h`` of an element (``QH_ELEMENT = 12``) the error against the library is 2.6e-4,
    7e-7, 7e-10, 1.5e-11, 2.6e-13 and 4e-14 at n = 12, 16, 20, 22, 24, 28 points per element
    (``test_collocation_converges_spectrally``), so from N_COARSE = 22 on it is below the
    tolerance and at N_FINE = 28 it is at rounding. Rounding: it grows where ``|q| h`` is
    small, because the stack then nearly has a uniform mode (over a slipping interface or
    base the compliance grows like ``1/(|q|^2 h)``). Fine against library, worst over the
    stacks: 1.2e-11 for ``|q| h_1 >= 0.5``, 1e-10 down to 0.03, 3.4e-9 at 0.01; fine
    against coarse: 1.9e-11, 2.2e-10, 4.4e-9 (and fine against n = 40: 8.6e-11, 1.6e-10,
    7e-9). ``5e-10 max(1, 1/(|q| h_1))`` covers all of these with a margin of 7 or more, and
    is still six orders of magnitude below an error of a sign or of a factor in a formula.
    """
    return 5e-10 * max(1.0, 1.0 / (abs(q) * h1))


# |q| h_1 from 0.01 to 30 (h_1 = 1, the top layer) and two negative q (T(-q) = conj T(q)).
QS = [0.01, 0.03, 0.1, 0.3, 0.5, 1.0, 2.0, 3.5, 5.0, 8.0, 12.0, 20.0, 30.0, -0.2, -1.7]

STACKS = {
    # 1. two bonded layers, E ratio 10, on a rigid base
    "two_bonded_on_rigid": ([(1.0, 1.0, 0.3), (0.7, 10.0, 0.25)], ["bonded", "bonded"], None),
    # 2. one layer on an elastic half-space, bonded and slipping, E_s/E_1 = 1/5 and 5
    "bonded_on_softer_half_space": ([(1.0, 1.0, 0.35)], ["bonded"], (0.2, 0.25)),
    "bonded_on_stiffer_half_space": ([(1.0, 1.0, 0.35)], ["bonded"], (5.0, 0.45)),
    "slip_on_softer_half_space": ([(1.0, 1.0, 0.35)], ["slip"], (0.2, 0.25)),
    "slip_on_stiffer_half_space": ([(1.0, 1.0, 0.35)], ["slip"], (5.0, 0.45)),
    # 3. three layers, the interface between the second and the third slipping, on a
    #    rigid frictionless base; and the slip one interface higher
    "three_slip_middle_on_slip_rigid": (
        [(1.0, 1.0, 0.3), (0.5, 4.0, 0.45), (1.5, 0.5, 0.25)], ["bonded", "slip", "slip"], None),
    "three_slip_top_on_slip_rigid": (
        [(1.0, 1.0, 0.3), (0.5, 4.0, 0.45), (1.5, 0.5, 0.25)], ["slip", "bonded", "slip"], None),
    # 4. a soft layer on a stiff layer on a soft half-space
    "soft_stiff_soft_half_space": (
        [(1.0, 1.0, 0.45), (0.5, 20.0, 0.3)], ["bonded", "bonded"], (1.0, 0.35)),
}


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.25, 0.3, 0.45])
@pytest.mark.parametrize("q", [1.3, -0.4])
def test_half_space_impedance(q, nu):
    """The half-space impedance used below a stack, built from the decaying solutions of
    the Navier equations, equals the closed form ``(1-nu)/(G|q|) [[1, i s c], [-i s c, 1]]``
    (``c`` Dundurs' constant, ``s = sgn q``), which equals ``lc.surface_tensor`` with no
    layer (the Boussinesq-Cerruti tensor): same signs of the coupling, same 1/|q|. Both
    are exact, so the tolerance is rounding."""
    young = 2.5
    g, _ = lame(young, nu)
    c = (1 - 2 * nu) / (2 * (1 - nu))
    s = np.sign(q)
    closed = (1 - nu) / (g * abs(q)) * np.array([[1, 1j * s * c], [-1j * s * c, 1]])
    built = half_space_compliance(q, young, nu)
    assert np.abs(built - closed).max() <= 1e-14 * np.abs(closed).max()
    t = lc.surface_tensor(q, 0.0, young=young, poisson=nu)
    assert np.abs(t[XZ] - closed).max() <= 1e-14 * np.abs(closed).max()
    assert t[1, 1] == pytest.approx(1 / (g * abs(q)), rel=1e-14)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_one_bonded_layer_fixes_the_signs(nu):
    """One layer bonded to a rigid base: the case of ``lc.surface_tensor`` validated against
    the closed forms (seed Eqs. 7-9, docs/theory.md) and the mode solve. Agreement here fixes
    the signs of the surface conditions ``sigma_zz(0) = -p``, ``sigma_xz(0) = -tau_x``,
    ``sigma_yz(0) = -tau_y`` (convention P): the opposite sign of one of them flips the sign
    of its column of the tensor (e.g. ``T_zz < 0``, the surface rising under compression).
    It also checks the solve's own physics: ``T_zz, T_xx, T_yy > 0`` (positive work),
    ``T_xz = -T_zx`` purely imaginary (Betti reciprocity), and ``T(-q) = conj T(q)``."""
    layers, interfaces = [(1.0, 3.0, nu)], ["bonded"]
    for q in (0.05, 0.7, 2.0, 9.0, 25.0):
        t2, tyy = navier_stack(q, layers, interfaces)
        ref = library_tensor(q, layers, interfaces)
        scale = np.abs(ref[XZ]).max()
        assert np.abs(t2 - ref[XZ]).max() <= rtol(q) * scale, q
        assert abs(tyy - ref[1, 1]) <= rtol(q) * abs(ref[1, 1]), q
        assert t2[1, 1].real > 0 and t2[0, 0].real > 0 and tyy.real > 0
        assert abs(t2[0, 1] + t2[1, 0]) <= rtol(q) * scale
        assert abs(t2[0, 1].real) <= rtol(q) * scale
        # convention P: for a thick compressible layer the surface moves toward a
        # compressive load (Dundurs' c > 0): Im T_xz > 0 for q > 0
        if q > 3:                          # |q| h = q here
            assert t2[0, 1].imag > 0
        t2m, _ = navier_stack(-q, layers, interfaces)
        assert np.abs(t2m - t2.conj()).max() <= rtol(q) * scale


def test_collocation_converges_spectrally():
    """At the largest |q| h per element (``QH_ELEMENT``, where the exponentials are
    steepest) the error against the library falls exponentially with the points per
    element until rounding: this is what sets N_FINE and shows N_COARSE is on the same
    converged branch for the tolerance of ``rtol``."""
    layers, interfaces, substrate = STACKS["soft_stiff_soft_half_space"]
    q = QH_ELEMENT                         # |q| h_1 = QH_ELEMENT: one element at the limit
    ref = library_tensor(q, layers, interfaces, substrate)[XZ]
    errors = []
    for n in (12, 16, 20, 24, N_FINE):
        t2, _ = navier_stack(q, layers, interfaces, substrate, n=n)
        errors.append(np.abs(t2 - ref).max() / np.abs(ref).max())
    assert errors[0] > 1e-5                # under-resolved: the test can see an error
    assert all(b < a / 10 for a, b in zip(errors[:3], errors[1:4])), errors
    assert errors[-1] <= 1e-12, errors


@pytest.mark.parametrize("name", list(STACKS))
def test_stack_matches_navier_solve(name):
    """The full plane-strain block ``(u_x, w)`` from ``(tau_x, p)`` and the antiplane
    compliance ``u_y`` from ``tau_y`` of ``lc.surface_tensor`` for a stack equal the
    collocated Navier solve at |q| h_1 from 0.01 to 30 (and at negative q), within
    ``rtol(q)`` of the largest entry of the block (the coupling ``c`` crosses zero, so it
    is compared on the scale of the block, as in test_kernels.py). The coarser solve must
    agree with the finer one within the same tolerance (the discretisation is converged);
    the solve itself must be reciprocal (``T_xz = -T_zx``); at ``q_y = 0`` the library's
    in-plane and antiplane parts must be decoupled (``T_xy = T_yz = 0``)."""
    layers, interfaces, substrate = STACKS[name]
    for q in QS:
        tol = rtol(q)
        fine, yy_fine = navier_stack(q, layers, interfaces, substrate, n=N_FINE)
        coarse, yy_coarse = navier_stack(q, layers, interfaces, substrate, n=N_COARSE)
        ref = library_tensor(q, layers, interfaces, substrate)
        scale = np.abs(ref[XZ]).max()
        err = {
            "block": np.abs(fine - ref[XZ]).max() / scale,
            "antiplane": abs(yy_fine - ref[1, 1]) / abs(ref[1, 1]),
            "resolution": max(np.abs(fine - coarse).max() / scale,
                              abs(yy_fine - yy_coarse) / abs(ref[1, 1])),
            "reciprocity": abs(fine[0, 1] + fine[1, 0]) / scale,
            "decoupled": max(abs(ref[0, 1]), abs(ref[1, 0]), abs(ref[1, 2]),
                             abs(ref[2, 1])) / scale,
        }
        bad = {k: v for k, v in err.items() if not v <= tol}
        assert not bad, (name, q, tol, bad, fine, ref[XZ], yy_fine, ref[1, 1])
