"""Independent reference solutions (test oracles) for areal (2D periodic) contacts of a rigid
indenter on an elastic layer bonded to a rigid base, or on an elastic half-space.

Pure numpy; nothing here calls the layercontact library.

Convention P (the one the code uses): ``z`` points into the layer, the rigid base is at depth
``h``; ``p > 0`` is compressive; ``w = u_z > 0`` is indentation; ``tau_x``, ``tau_y`` are the
shear tractions exerted on the layer (the indenter slides along ``+x`` and Coulomb friction
gives ``tau_x = +mu_c p``). Fields are ``f(x, y) = sum_q f^(q) exp(i q.x)``. Young's modulus
``E``, Poisson ratio ``-1 < nu <= 0.5``, ``E* = E/(1-nu^2)``, ``G = E/(2(1+nu))``,
``kappa = 3 - 4 nu``, ``M = E(1-nu)/((1+nu)(1-2nu))`` (constrained modulus).

Surface compliance tensors are returned with shape ``(..., 3, 3)`` (complex):
``T[..., i, j]`` is the displacement ``(u_x, u_y, w)[i]`` produced by a unit traction
``(tau_x, tau_y, p)[j]`` of the same wavevector, i.e.

    (u_x^, u_y^, w^)(q) = T(q) @ (tau_x^, tau_y^, p^)(q).

Properties that hold for every tensor here (and are tested): ``T(-q) = conj(T(q))`` (real
fields), ``T`` Hermitian and positive definite (Betti reciprocity and positive strain energy),
so ``T_xz = -T_zx`` (purely imaginary) and ``T_xy = T_yx`` (real).

References
----------
- K. L. Johnson, *Contact Mechanics*, Cambridge University Press (1985), §3.2-3.3
  (Boussinesq and Cerruti point-load solutions), §3.4 (line loads).
- J. Dundurs, "Discussion of 'Edge-bonded dissimilar orthogonal elastic wedges under normal
  and shear loading'", J. Appl. Mech. 36 (1969) 650 (the coupling constant beta).
- C. Menga, G. Carbone, C. Müller, M. H. Müser, "How does friction affect sliding contact
  mechanics?", Eqs. (4)-(9) (the layer coefficients A, B, C).
- H. Hertz, "Über die Berührung fester elastischer Körper", J. reine angew. Math. 92 (1882)
  156; Johnson §4.2.
- M. L. Glasser, I. J. Zucker, "Lattice sums", in *Theoretical Chemistry: Advances and
  Perspectives* 5 (1980) 67 (the square-lattice Epstein zeta function
  ``Z(s) = sum' (m^2+n^2)^(-s) = 4 zeta(s) beta(s)``).
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

__all__ = [
    "boussinesq_cerruti_tensor",
    "layer_tensor_mode_solve",
    "layer_tensor_closed_form",
    "layer_factors",
    "seed_coefficients",
    "layer_uniform_compliance",
    "effective_normal_multiplier",
    "SinusoidFullContact",
    "oblique_sinusoid_full_contact",
    "hertz_sphere",
    "hertz_periodic_correction",
    "SQUARE_LATTICE_Z_HALF",
    "SQUARE_LATTICE_Z_MINUS_HALF",
]

# Square-lattice Epstein zeta Z(s) = sum_{(m,n) != 0} (m^2 + n^2)^(-s) = 4 zeta(s) beta(s)
# (analytic continuation; Glasser & Zucker 1980), zeta the Riemann and beta the Dirichlet
# beta function. Values from mpmath at 30 digits: 4*zeta(s)*dirichlet(s, [0, 1, 0, -1]).
SQUARE_LATTICE_Z_HALF = -3.9002649200019558828      # Z(1/2)
SQUARE_LATTICE_Z_MINUS_HALF = -0.22882431037721895335  # Z(-1/2)


def _moduli(young, poisson):
    if not -1.0 < poisson <= 0.5:
        raise ValueError(f"poisson = {poisson}: need -1 < nu <= 0.5")
    shear = young / (2.0 * (1.0 + poisson))
    estar = young / (1.0 - poisson**2)
    return shear, estar


def _unit_and_norm(qx, qy):
    qx = np.asarray(qx, dtype=float)
    qy = np.asarray(qy, dtype=float)
    qx, qy = np.broadcast_arrays(qx, qy)
    q = np.hypot(qx, qy)
    safe = np.where(q > 0, q, 1.0)
    return qx / safe, qy / safe, q


# ---------------------------------------------------------------------------------------------
# 1. Half-space: Boussinesq-Cerruti in Fourier space
# ---------------------------------------------------------------------------------------------

def boussinesq_cerruti_tensor(qx, qy, young, poisson):
    """Fourier-space surface compliance of an elastic half-space ``z >= 0`` (convention P).

    With ``q = |q|``, ``n = q/|q|``, ``G = E/(2(1+nu))``:

        T_xx = (1 - nu n_x^2)/(G q)        T_xy = T_yx = -nu n_x n_y/(G q)
        T_yy = (1 - nu n_y^2)/(G q)        T_zz = (1 - nu)/(G q) = 2/(E* q)
        T_zx = -i (1-2nu)/(2 G q) n_x      T_xz = +i (1-2nu)/(2 G q) n_x
        T_zy = -i (1-2nu)/(2 G q) n_y      T_yz = +i (1-2nu)/(2 G q) n_y

    Derivation (independent of the plane-strain line-load formulas). Johnson, *Contact
    Mechanics* §3.2 (Boussinesq, Eq. 3.21) and §3.3 (Cerruti, Eq. 3.23), surface values
    (``z = 0``, ``r = |x|``) of the displacements due to a point force ``P`` normal (into the
    solid) and ``Q_x`` tangential at the origin, ``z`` into the solid:

        w   = P (1-nu)/(2 pi G r),      u_x = -P (1-2nu)/(4 pi G) x/r^2      (Boussinesq)
        u_x = Q_x/(2 pi G) [(1-nu)/r + nu x^2/r^3],   u_y = Q_x nu/(2 pi G) x y/r^3,
        w   = +Q_x (1-2nu)/(4 pi G) x/r^2                                     (Cerruti)

    (surface points move toward a compressive load; Betti: the ``w`` of Cerruti at ``x`` equals
    the ``u_x`` at the origin of a Boussinesq load at ``x``). The kernel's multiplier is
    ``K^(q) = int K(x) exp(-i q.x) d^2x``; with the two-dimensional transforms
    ``1/r -> 2 pi/q``, ``x_i x_j/r^3 -> 2 pi (delta_ij/q - q_i q_j/q^3)`` and
    ``x_i/r^2 = d_i ln r -> i q_i (-2 pi/q^2)`` the table above follows.

    Check against convention P (plane-strain limit, ``q`` along ``x``, ``q_y = 0``):
    ``w^ = 2/(E*|q|) [p^ - i sgn(q) c tau_x^]``, ``u_x^ = 2/(E*|q|) [i sgn(q) c p^ + tau_x^]``
    with ``c = (1-2nu)/(2(1-nu))`` (Dundurs' beta for a rigid counter-body), and the antiplane
    ``u_y^ = tau_y^/(G|q|) = 2(1+nu)/(E|q|) tau_y^``.

    ``qx``, ``qy`` broadcast; the result has shape ``broadcast.shape + (3, 3)``. The uniform
    mode (``q = 0``) of a half-space has no finite compliance: its entries are set to 0 (the
    code removes that mode).
    """
    shear, _ = _moduli(young, poisson)
    nx, ny, q = _unit_and_norm(qx, qy)
    nu = poisson
    inv = np.where(q > 0, 1.0 / (shear * np.where(q > 0, q, 1.0)), 0.0)
    coup = 0.5j * (1.0 - 2.0 * nu)
    t = np.empty(q.shape + (3, 3), dtype=complex)
    t[..., 0, 0] = (1.0 - nu * nx * nx) * inv
    t[..., 1, 1] = (1.0 - nu * ny * ny) * inv
    t[..., 0, 1] = t[..., 1, 0] = -nu * nx * ny * inv
    t[..., 2, 2] = (1.0 - nu) * inv
    t[..., 0, 2] = coup * nx * inv
    t[..., 1, 2] = coup * ny * inv
    t[..., 2, 0] = -coup * nx * inv
    t[..., 2, 1] = -coup * ny * inv
    return t


# ---------------------------------------------------------------------------------------------
# 2. Layer: one Fourier mode of the 3D Navier equations, solved with LAPACK
# ---------------------------------------------------------------------------------------------

def layer_tensor_mode_solve(qx, qy, thickness, young, poisson):
    """Surface compliance ``T`` (3x3 complex, rows ``(u_x, u_y, w)``, columns
    ``(tau_x, tau_y, p)``, convention P) of a layer ``0 <= z <= h`` bonded to a rigid base at
    ``z = h``, for ONE wavevector ``(qx, qy)`` (``|q| > 0``), from the 3D Navier equations
    ``(1-2nu) lap u + grad div u = 0`` solved as a 6x6 linear system (``numpy.linalg.solve``,
    LAPACK gesv) for three load cases.

    General solution for ``u = U(z) exp(i q.x)`` (Papkovich-Neuber; e.g. Barber, *Elasticity*,
    Ch. 20): with ``phi_s = exp(i q.x + s q z)``, ``s = +-1`` (harmonic), ``k_s = grad phi_s/phi_s
    = (i q_x, i q_y, s q)``, the six independent solutions are
      - ``u = a phi_s`` with ``a . k_s = 0`` (harmonic and divergence-free): two per sign,
        ``a = (s, 0, -i n_x)`` and ``a = (0, s, -i n_y)``, ``n = q/|q|``;
      - ``u = kappa phi_s e_z - z grad phi_s`` (Boussinesq's potential), ``div u =
        (2-4nu) d_z phi_s``, one per sign.
    Stresses from Hooke's law ``sigma_ij = lambda delta_ij div u + G (u_i,j + u_j,i)``, with
    ``lambda div u = 4 G nu d_z phi_s`` written out so that ``nu = 1/2`` is regular.
    Conditions: at ``z = 0`` the traction on the layer (outward normal ``-e_z``) is
    ``-sigma_iz = (tau_x, tau_y, p)_i``; at ``z = h``, ``u = 0``. The growing solutions are
    scaled by ``exp(-q h)`` (``phi_+ -> exp(q (z-h))``) so that no entry exceeds 1.

    Lengths are scaled by ``1/|q|`` and tractions by ``G|q|``, so the result is
    ``T = X/(G |q|)`` with ``X`` the dimensionless surface displacements.

    Accuracy (measured against :func:`layer_tensor_closed_form`, error of ``T_ij`` relative to
    ``sqrt(|T_ii T_jj|)``): a few ulps for ``|q| h >= 1``; for ``nu < 1/2`` below 1e-12 down to
    ``|q| h = 1e-3`` (4e-12 at 1e-4). For ``nu = 1/2`` the normal compliance is
    ``~ (2/3) x^3`` against ``~ x`` for the shear (``x = |q| h``), a cancellation of the O(1)
    solution coefficients, so the error grows like ``x^-3.5``: 2e-13 at ``x = 0.1``, 1.4e-10 at
    0.01, 5e-7 at 1e-3. Use ``1e-2 <= |q| h <= 30`` (``1e-3`` for ``nu < 1/2``); beyond ~30
    the layer is a half-space to rounding (the scaled exponentials underflow only past ~700).
    Valid for every ``-1 < nu <= 1/2``.
    """
    shear, _ = _moduli(young, poisson)
    qx = float(qx)
    qy = float(qy)
    q = float(np.hypot(qx, qy))
    if not q > 0:
        raise ValueError("the mode solve needs |q| > 0")
    if not (thickness > 0 and np.isfinite(thickness)):
        raise ValueError("the mode solve needs a finite thickness > 0")
    nx, ny = qx / q, qy / q
    nu = poisson
    kappa = 3.0 - 4.0 * nu
    big_h = q * thickness

    def columns(zz):
        """Displacements U (3x6) and tractions sigma_iz/(G q) (3x6) at depth Z = q z of the six
        basis solutions, ordered (D1-, D2-, B-, D1+, D2+, B+)."""
        u = np.zeros((3, 6), dtype=complex)
        s_iz = np.zeros((3, 6), dtype=complex)
        for block, s in enumerate((-1.0, 1.0)):
            e = np.exp(-zz) if s < 0 else np.exp(zz - big_h)
            kn = np.array([1j * nx, 1j * ny, s])
            for j, a in enumerate((np.array([s, 0.0, -1j * nx]), np.array([0.0, s, -1j * ny]))):
                col = 3 * block + j
                u[:, col] = a * e
                # sigma_iz/(G q) = (kn_i a_z + s a_i) e   (div u = 0)
                s_iz[:, col] = (kn * a[2] + s * a) * e
            col = 3 * block + 2
            u[:, col] = np.array([-1j * nx * zz, -1j * ny * zz, kappa - s * zz]) * e
            fac = kappa - 1.0 - 2.0 * s * zz
            s_iz[:, col] = np.array([1j * nx * fac, 1j * ny * fac,
                                     2.0 * s * (2.0 * (1.0 - nu) - s * zz)]) * e
        return u, s_iz

    u0, s0 = columns(0.0)
    uh, _ = columns(big_h)
    mat = np.vstack([s0, uh])                      # 6x6
    rhs = np.zeros((6, 3), dtype=complex)
    rhs[:3, :3] = -np.eye(3)                       # sigma_iz(0) = -t_i (traction on the layer)
    coef = np.linalg.solve(mat, rhs)               # 6x3, LAPACK
    return (u0 @ coef) / (shear * q)


# ---------------------------------------------------------------------------------------------
# 3. Layer: closed form (plane strain in the wavevector's frame + antiplane shear)
# ---------------------------------------------------------------------------------------------

def seed_coefficients(kh, poisson):
    """The seed paper's coefficients ``A, B, C`` of Eqs. (7)-(9), transcribed literally
    (Menga, Carbone, Müller, Müser, "How does friction affect sliding contact mechanics?"):

        D = 5 + 2 x^2 - 4 nu (3 - 2 nu) + (3 - 4 nu) cosh 2x
        A = 1 + (2x - (3-4nu) sinh 2x)/D,   B = 1 - (2x + (3-4nu) sinh 2x)/D,
        C = 4 (1-nu) [2 + x^2 - 6 nu + 4 nu^2]/D,        x = |k| h.

    Naive evaluation (cancellation at small ``x``, overflow past ``x ~ 350``); for checks."""
    x = np.asarray(kh, dtype=float)
    nu = poisson
    k = 3.0 - 4.0 * nu
    d = 5.0 + 2.0 * x**2 - 4.0 * nu * (3.0 - 2.0 * nu) + k * np.cosh(2 * x)
    a = 1.0 + (2 * x - k * np.sinh(2 * x)) / d
    b = 1.0 - (2 * x + k * np.sinh(2 * x)) / d
    c = 4.0 * (1.0 - nu) * (2.0 + x**2 - 6.0 * nu + 4.0 * nu**2) / d
    return a, b, c


def _sinh_minus_arg(y):
    """sinh(y) - y without cancellation (series for |y| < 1)."""
    y = np.asarray(y, dtype=float)
    small = np.abs(y) < 1.0
    ys = np.where(small, y, 0.0)
    term = ys**3 / 6.0
    acc = term.copy()
    for n in range(2, 12):                         # y^(2n+1)/(2n+1)!, |y| < 1: 12 terms > eps
        term = term * ys * ys / ((2 * n) * (2 * n + 1))
        acc = acc + term
    with np.errstate(over="ignore", invalid="ignore"):
        big = np.sinh(np.where(small, 1.0, y)) - np.where(small, 1.0, y)
    return np.where(small, acc, big)


def layer_factors(kh, poisson):
    """Convention-P plane-strain layer factors ``(1-A, 1-B, c)`` for ``x = |k| h`` (array,
    ``x > 0``, ``inf`` allowed):

        1-A = (kappa sinh 2x - 2x)/D,   1-B = (kappa sinh 2x + 2x)/D,
        D = kappa cosh 2x + 2x^2 + (1+kappa^2)/2,
        c = ((1-2nu) - C)/(2(1-nu)) = [(1-2nu) kappa sinh^2 x - x^2]/((1-nu) D),

    with ``A, B, C`` the seed's Eqs. (7)-(9) (``(1+kappa^2)/2 = 5 - 4nu(3-2nu)`` is the seed's
    constant). Mapping to convention P: the seed's Eq. (5) has the Fourier coefficient
    ``-i (1+nu)[(1-2nu) - C]/(E k)`` for ``v_x`` due to ``p``; convention P has
    ``u_x^ = +i 2 c p^/(E* k)``, i.e. the opposite sign (the literal sign would make a
    half-space surface move away from a compressive load, against Johnson's Boussinesq
    solution and Betti reciprocity), hence ``c = +((1-2nu) - C)/(2(1-nu))``. The second form
    of ``c`` uses ``2 - 6nu + 4nu^2 = 2(1-nu)(1-2nu)`` and ``(1+kappa)^2/2 = 8(1-nu)^2``.

    Evaluation: ``kappa sinh 2x - 2x = 2(1-2nu) 2x + kappa (sinh 2x - 2x)`` and
    ``(1-2nu) kappa sinh^2 x - x^2 = 2(1-nu)(1-4nu) x^2 + (1-2nu) kappa (sinh x - x)(sinh x + x)``
    with a series for ``sinh y - y`` (no cancellation at small ``x``, also at ``nu = 1/4``); for ``x > 1`` numerator and denominator are
    divided by ``cosh 2x`` (``sech 2x = 2 exp(-2x)/(1 + exp(-4x))``, no overflow). Limits:
    ``x -> inf``: ``(1, 1, (1-2nu)/(2(1-nu)))``; ``x -> 0``:
    ``1-A ~ x (1-2nu)/(2(1-nu)^2)`` (``2(1-A)/(E* |k|) -> h/M``; ``(2/3) x^3`` for
    ``nu = 1/2``), ``1-B ~ x/(1-nu)`` (``-> h/G``), ``c ~ x^2 (1-4nu)/(4(1-nu)^2)``.
    """
    x = np.asarray(kh, dtype=float)
    nu = poisson
    kappa = 3.0 - 4.0 * nu
    big = x > 1.0
    xs = np.where(big, 1.0, x)        # small branch
    xb = np.where(big, x, 2.0)        # large branch (finite or inf)
    # small x: direct
    sh2 = np.sinh(2 * xs)
    d_s = kappa * np.cosh(2 * xs) + 2 * xs**2 + 0.5 * (1 + kappa**2)
    oma_s = (2 * (1 - 2 * nu) * 2 * xs + kappa * _sinh_minus_arg(2 * xs)) / d_s
    omb_s = (kappa * sh2 + 2 * xs) / d_s
    # (1-2nu) kappa sinh^2 x - x^2 = 2(1-nu)(1-4nu) x^2 + (1-2nu) kappa (sinh x - x)(sinh x + x)
    c_s = (2 * (1 - nu) * (1 - 4 * nu) * xs**2
           + (1 - 2 * nu) * kappa * _sinh_minus_arg(xs) * (np.sinh(xs) + xs)) / ((1 - nu) * d_s)
    # large x: divided by cosh 2x
    with np.errstate(over="ignore", invalid="ignore"):
        e2 = np.exp(-2 * xb)
        sech = 2 * e2 / (1 + e2 * e2)
        th = np.tanh(2 * xb)
        fin = np.isfinite(xb)
        xsech = np.where(fin, xb * sech, 0.0)
        x2sech = np.where(fin, xb * xsech, 0.0)
        d_b = kappa + 2 * x2sech + 0.5 * (1 + kappa**2) * sech
        oma_b = (kappa * th - 2 * xsech) / d_b
        omb_b = (kappa * th + 2 * xsech) / d_b
        # sinh^2 x / cosh 2x = (1 - sech 2x)/2
        c_b = ((1 - 2 * nu) * kappa * 0.5 * (1 - sech) - x2sech) / ((1 - nu) * d_b)
    oma = np.where(big, oma_b, oma_s)
    omb = np.where(big, omb_b, omb_s)
    c = np.where(big, c_b, c_s)
    return oma, omb, c


def layer_uniform_compliance(thickness, young, poisson):
    """``q = 0`` compliance of a bonded layer: ``diag(h/G, h/G, h/M)``,
    ``M = E(1-nu)/((1+nu)(1-2nu))`` (``h/M = 0`` for ``nu = 1/2``): uniform shear and uniaxial
    strain of the layer (the ``|q| -> 0`` limit of both tensors). Zero for ``h = inf``."""
    shear, _ = _moduli(young, poisson)
    t = np.zeros((3, 3), dtype=complex)
    if np.isfinite(thickness):
        t[0, 0] = t[1, 1] = thickness / shear
        t[2, 2] = thickness * (1 + poisson) * (1 - 2 * poisson) / (young * (1 - poisson))
    return t


def layer_tensor_closed_form(qx, qy, thickness, young, poisson):
    """Surface compliance of a bonded layer (convention P, shape ``broadcast.shape + (3, 3)``,
    rows ``(u_x, u_y, w)``, columns ``(tau_x, tau_y, p)``) from the rotated closed form.

    In the frame ``(l, t, z)``, ``l = q/|q| = (n_x, n_y)``, ``t = (-n_y, n_x)``, a single Fourier
    mode is uniform along ``t``, so the problem splits exactly into plane strain in ``(l, z)``
    and antiplane shear along ``t``:

        w^   = 2/(E*|q|) [(1-A) p^ - i c tau_l^]
        u_l^ = 2/(E*|q|) [i c p^ + (1-B) tau_l^]
        u_t^ = tanh(|q| h)/(G |q|) tau_t^

    with ``(1-A, 1-B, c)`` from :func:`layer_factors` (``x = |q| h``). The antiplane part solves
    ``lap u_t = 0``, ``u_t = 0`` at ``z = h``, ``G du_t/dz = -tau_t`` at ``z = 0``:
    ``u_t = tau_t sinh(q(h-z))/(G q cosh(q h))``. Then ``T = R T_ltz R^T`` with
    ``R = [[n_x, -n_y, 0], [n_y, n_x, 0], [0, 0, 1]]``.

    ``thickness = inf`` gives the half-space. At ``q = 0`` the uniform compliance of
    :func:`layer_uniform_compliance` is returned (0 for the half-space). Accurate to a few
    ulps for every ``|q| h > 0`` (no cancellation or overflow, see :func:`layer_factors`).
    """
    shear, estar = _moduli(young, poisson)
    nx, ny, q = _unit_and_norm(qx, qy)
    pos = q > 0
    qs = np.where(pos, q, 1.0)
    x = qs * thickness
    oma, omb, c = layer_factors(x, poisson)
    s = 2.0 / (estar * qs)
    with np.errstate(over="ignore"):
        tt = np.tanh(x) / (shear * qs)
    tll = s * omb
    tzz = s * oma
    tlz = 1j * s * c           # u_l due to p
    tzl = -1j * s * c          # w due to tau_l
    t = np.empty(q.shape + (3, 3), dtype=complex)
    t[..., 0, 0] = nx * nx * tll + ny * ny * tt
    t[..., 1, 1] = ny * ny * tll + nx * nx * tt
    t[..., 0, 1] = t[..., 1, 0] = nx * ny * (tll - tt)
    t[..., 0, 2] = nx * tlz
    t[..., 1, 2] = ny * tlz
    t[..., 2, 0] = nx * tzl
    t[..., 2, 1] = ny * tzl
    t[..., 2, 2] = tzz
    if np.any(~pos):
        t[~pos] = layer_uniform_compliance(thickness, young, poisson)
    return t


def effective_normal_multiplier(tensor, friction):
    """``G_eff(q) = w^/p^ = T_zz + mu_c T_zx`` for Coulomb sliding along ``+x``
    (``tau_x = mu_c p``, ``tau_y = 0``). For the layer:
    ``2/(E*|q|) [(1-A) - i (q_x/|q|) mu_c c]``."""
    return tensor[..., 2, 2] + friction * tensor[..., 2, 0]


# ---------------------------------------------------------------------------------------------
# 4. A sinusoid pressed into full contact on any linear multiplier
# ---------------------------------------------------------------------------------------------

class SinusoidFullContact(NamedTuple):
    """Full-contact solution of :func:`oblique_sinusoid_full_contact`.

    ``wavevector``: ``(q_x, q_y)``; ``pressure_coefficient``: ``p^(q)`` (``p^(-q)`` is its
    conjugate); ``pressure(x, y)``: callable; ``penetration``: ``Delta``;
    ``uniform_displacement``: ``g0 p_m`` (the rigid shift added back); ``delta_mu``:
    ``-<p dr/dx>/p_m``; ``min_mean_pressure``: smallest ``p_m`` with ``p >= 0`` everywhere;
    ``min_phase``: the phase ``q.x`` where ``p`` is smallest; ``compliance``: ``G(q)``."""

    wavevector: tuple
    pressure_coefficient: complex
    pressure: Callable
    penetration: float
    uniform_displacement: float
    delta_mu: float
    min_mean_pressure: float
    min_phase: float
    compliance: complex


def oblique_sinusoid_full_contact(mx, my, lx, ly, amplitude, mean_pressure, G_of_q,
                                  uniform_compliance=0.0):
    """Exact full-contact solution for the rigid profile ``r(x, y) = a cos(q.x)``,
    ``q = 2 pi (mx/lx, my/ly)`` (integers ``mx, my``, not both 0), pressed under load control
    (mean pressure ``p_m``) on a linear operator whose normal response is ``w^(q) = G(q) p^(q)``
    (``G_of_q(qx, qy) -> complex``, with ``G(-q) = conj G(q)``; with Coulomb friction
    ``tau_x = mu_c p`` the coupling is included, ``G = T_zz + mu_c T_zx``).

    Geometry (the code's): ``Lambda = max r = |a|``, gap ``g = w - (r - Lambda + Delta)``;
    full contact is ``g = 0`` everywhere. The uniform mode of ``w`` is ``g0 p_m`` with
    ``g0 = uniform_compliance`` (0 for a half-space, whose uniform mode is removed; ``h/M``
    for a compressible bonded layer, the rigid shift that the code adds back to ``w`` and to
    the penetration; 0 for an incompressible one).

    Solution: ``r^(+-q) = a/2``; ``g = 0`` mode by mode gives ``G(q) p^(q) = a/2`` and
    ``g0 p_m = -Lambda + Delta``:

        p(x)     = p_m + Re[(a/G(q)) exp(i q.x)]
        Delta    = |a| + g0 p_m
        Delta_mu = -<p dr/dx>/p_m = a^2 q_x Im G(q) / (2 |G(q)|^2 p_m)
                 = -a^2 q_x Im[1/G(q)]/(2 p_m)

    (``dr/dx = -a q_x sin(q.x)``; with ``1/G = alpha + i beta``,
    ``<(alpha cos t - beta sin t) sin t> = -beta/2``), which equals the spectral form
    ``(2/p_m) sum_{q_x>0} q_x Im G |p^|^2``. ``p >= 0`` everywhere iff
    ``p_m >= |a|/|G(q)|`` (the minimum ``p_m - |a/G|`` is reached at
    ``q.x = pi - arg(a/G)``). For the layer,
    ``G = 2/(E*|q|) [(1-A) - i n_x mu_c c]`` so ``Delta_mu`` has the sign of ``-c`` (for
    ``q_x > 0``): positive on thin incompressible layers (``c < 0``), negative on a
    compressible half-space (``c > 0``).
    """
    if mx == 0 and my == 0:
        raise ValueError("the sinusoid needs a non-zero wavevector")
    qx = 2.0 * np.pi * mx / lx
    qy = 2.0 * np.pi * my / ly
    g = complex(G_of_q(qx, qy))
    if g == 0:
        raise ValueError("G(q) = 0: no finite full-contact pressure")
    a = float(amplitude)
    pm = float(mean_pressure)
    coef = a / (2.0 * g)                          # p^(q)

    def pressure(x, y):
        phase = qx * np.asarray(x, dtype=float) + qy * np.asarray(y, dtype=float)
        return pm + np.real((a / g) * np.exp(1j * phase))

    shift = float(np.real(uniform_compliance)) * pm
    penetration = abs(a) + shift
    delta_mu = a * a * qx * g.imag / (2.0 * abs(g) ** 2 * pm) if pm != 0 else np.nan
    pmin = abs(a) / abs(g)
    min_phase = float(np.mod(np.pi - np.angle(a / g), 2 * np.pi))
    return SinusoidFullContact((qx, qy), coef, pressure, penetration, shift, delta_mu, pmin,
                               min_phase, g)


# ---------------------------------------------------------------------------------------------
# 5. Hertz, and a sphere in a periodic cell
# ---------------------------------------------------------------------------------------------

def hertz_sphere(radius, load, young, poisson):
    """Hertz contact of a rigid sphere (paraboloid ``z = rho^2/(2R)``) pressed with force ``F``
    on a half-space (Hertz 1882; Johnson §4.2, Eqs. 4.22-4.23 with a rigid counter-body):

        a = (3 F R/(4 E*))^(1/3),  p0 = 3F/(2 pi a^2),  delta = a^2/R,
        p(rho) = p0 sqrt(1 - rho^2/a^2),  <rho^2>_p = (2/5) a^2.

    Returns a dict with ``contact_radius``, ``max_pressure``, ``penetration`` (the approach of
    distant points, i.e. ``w`` at the centre with ``w -> 0`` at infinity), ``pressure``
    (callable of ``rho``) and ``second_moment`` (``int p rho^2 dA = (2/5) F a^2``)."""
    _, estar = _moduli(young, poisson)
    a = (3.0 * load * radius / (4.0 * estar)) ** (1.0 / 3.0)
    p0 = 3.0 * load / (2.0 * np.pi * a * a)

    def pressure(rho):
        u = 1.0 - (np.asarray(rho, dtype=float) / a) ** 2
        return p0 * np.sqrt(np.clip(u, 0.0, None))

    return {"contact_radius": a, "max_pressure": p0, "penetration": a * a / radius,
            "pressure": pressure, "second_moment": 0.4 * load * a * a}


def hertz_periodic_correction(radius, load, young, poisson, cell):
    """A Hertz sphere in a square periodic cell of side ``L`` on a half-space whose uniform
    mode is removed (``w^(0) = 0``, as the code does), under load control ``p_m = F/L^2``.

    The periodic zero-mean kernel is ``K_per(x) = (1/L^2) sum_{q != 0} 2/(E* |q|) exp(i q.x)``,
    ``q = 2 pi n/L``; near ``x = 0`` it differs from the isolated Boussinesq kernel
    ``1/(pi E* r)`` by a smooth function (images at distance ``>= L``, minus the mean)

        K_per(x) - 1/(pi E* r) = c0 + c2 r^2 + O(r^4/L^5),
        c0 = Z(1/2)/(pi E* L)         = -1.24148/(E* L),
        c2 = -pi Z(-1/2)/(E* L^3)     = +0.71887/(E* L^3),

    with ``Z(s) = sum' |n|^(-2s) = 4 zeta(s) beta(s)`` the square lattice's Epstein zeta
    function (Glasser & Zucker): ``c0`` is the regularised sum
    ``(2/E*)[(1/L^2) sum'_q 1/|q| - int d^2q/(2 pi)^2 1/|q|] = (1/(pi E* L)) lim_R
    [sum'_{|n|<R} 1/|n| - 2 pi R]``; ``c2 = lap/4`` of the same difference, whose multiplier is
    ``-2|q|/E*``, giving ``Z(-1/2)`` likewise (the quadratic term is isotropic by the square's
    symmetry, the linear one vanishes by inversion symmetry).

    Consequences (``p`` of total force ``F`` inside ``rho < a``):
    - The penetration shifts at FIRST order in ``a/L``: the apex displacement gets
      ``c0 F`` (relative to ``delta = a^2/R``: ``(4/3) Z(1/2)/pi (a/L) = -1.655 a/L``). This is
      the "mean displacement" offset of a cell with the uniform mode removed.
    - The contact radius and peak pressure change only at THIRD order: a uniform shift does
      not change the contact problem, the quadratic term ``c2 F r^2`` acts as a change of the
      indenter's curvature, ``1/R_eff = 1/R + 2 c2 F``, i.e. relative ``2 c2 F R =
      -(8 pi/3) Z(-1/2) (a/L)^3 = 1.917 (a/L)^3``, so ``a_per = a (R_eff/R)^(1/3)``
      (``a_per/a ~ 1 + (8 pi/9) Z(-1/2) (a/L)^3 = 1 - 0.639 (a/L)^3``) and
      ``p0_per = 3F/(2 pi a_per^2)`` (``~ 1 + 1.278 (a/L)^3``), with relative errors
      ``O((a/L)^5)`` from the ``r^4`` terms of the images.
    - Penetration to that order: ``Delta_per = a_per^2/R_eff + c0 F + c2 (2/5) F a_per^2``.

    Returns a dict: ``c0``, ``c2``, ``contact_radius``, ``max_pressure``, ``penetration``
    (periodic, to ``O(delta (a/L)^5)``), ``penetration_first_order`` (``delta + c0 F``), and the
    isolated Hertz values under ``hertz`` (the dict of :func:`hertz_sphere`)."""
    _, estar = _moduli(young, poisson)
    hz = hertz_sphere(radius, load, young, poisson)
    L = float(cell)
    c0 = SQUARE_LATTICE_Z_HALF / (np.pi * estar * L)
    c2 = -np.pi * SQUARE_LATTICE_Z_MINUS_HALF / (estar * L**3)
    r_eff = 1.0 / (1.0 / radius + 2.0 * c2 * load)
    a_per = (3.0 * load * r_eff / (4.0 * estar)) ** (1.0 / 3.0)
    p0_per = 3.0 * load / (2.0 * np.pi * a_per**2)
    pen = a_per**2 / r_eff + c0 * load + c2 * 0.4 * load * a_per**2
    return {"c0": c0, "c2": c2, "effective_radius": r_eff, "contact_radius": a_per,
            "max_pressure": p0_per, "penetration": pen,
            "penetration_first_order": hz["penetration"] + c0 * load, "hertz": hz}
