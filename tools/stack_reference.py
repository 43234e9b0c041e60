"""Check the closed forms of lc_greens_stack in 40-digit arithmetic (mpmath).

The layer's stiffness matrix K, its transfer matrix P and the frictionless-rigid-base
compliance (docs/theory.md, "Layered stacks") were derived symbolically from the plane-strain
Papkovich-Neuber solution. This script rebuilds the same mode problem numerically, with the
field rows written out again here, and prints the largest relative difference from each closed
form over a grid of x = |q|h and nu. Run: ``python tools/stack_reference.py``.
"""

import mpmath as mp

mp.mp.dps = 40


def field_rows(x_z, nu):
    """Rows (u_x/i, u_z, sigma_xz/i, sigma_zz) at depth z for 2G = 1, |q| = 1.

    Columns: phi = cosh z, sinh z; psi = cosh z, sinh z (2G u = 4(1-nu) psi e_z - grad(z psi + phi)).
    """
    z = mp.mpf(x_z)
    f = [mp.cosh(z), mp.sinh(z)]
    df = [mp.sinh(z), mp.cosh(z)]
    rows = mp.matrix(4, 4)
    for j in range(2):
        rows[0, j] = -f[j]
        rows[1, j] = -df[j]
        rows[2, j] = -df[j]
        rows[3, j] = -f[j]
        rows[0, j + 2] = -z * f[j]
        rows[1, j + 2] = (3 - 4 * nu) * f[j] - z * df[j]
        rows[2, j + 2] = (1 - 2 * nu) * f[j] - z * df[j]
        rows[3, j + 2] = 2 * (1 - nu) * df[j] - z * f[j]
    return rows


def closed_forms(x, nu):
    s, c = mp.sinh(x), mp.cosh(x)
    g, k, e = 1 - nu, 3 - 4 * nu, 1 - 2 * nu
    delta = k**2 * s**2 - x**2
    off = x**2 - e * k * s**2
    kk = mp.matrix(
        [
            [2 * g * (k * s * c - x), off, -2 * g * (k * s - x * c), -2 * g * x * s],
            [off, 2 * g * (k * s * c + x), 2 * g * x * s, -2 * g * (k * s + x * c)],
            [-2 * g * (k * s - x * c), 2 * g * x * s, 2 * g * (k * s * c - x), -off],
            [-2 * g * x * s, -2 * g * (k * s + x * c), -off, 2 * g * (k * s * c + x)],
        ]
    ) / delta
    d = x * c - s
    g2 = 2 * g
    pp = mp.matrix(
        [
            [c + x * s / g2, (e * s + x * c) / g2, -(k * s + x * c) / g2, -x * s / g2],
            [-(d + 2 * nu * s) / g2, c - x * s / g2, x * s / g2, (d - 2 * e * s) / g2],
            [-(x * c + s) / g2, -x * s / g2, c + x * s / g2, (d + 2 * nu * s) / g2],
            [x * s / g2, d / g2, -(e * s + x * c) / g2, c - x * s / g2],
        ]
    )
    slip = mp.matrix(
        [[c**2 / (s * c + x), (e * s * c - x) / (2 * g * (s * c + x))],
         [(e * s * c - x) / (2 * g * (s * c + x)), s**2 / (s * c + x)]]
    )
    return kk, pp, slip


def largest(a, b):
    scale = max(abs(v) for v in b)
    return max(abs(a[i, j] - b[i, j]) for i in range(a.rows) for j in range(a.cols)) / scale


def main():
    worst = {"stiffness": 0, "transfer": 0, "frictionless base": 0}
    for x in [mp.mpf("1e-3"), mp.mpf("0.1"), mp.mpf(1), mp.mpf(3), mp.mpf(12)]:
        for nu in [mp.mpf(-0.5), mp.mpf(0), mp.mpf("0.3"), mp.mpf("0.49"), mp.mpf("0.5")]:
            top, bottom = field_rows(0, nu), field_rows(x, nu)
            disp = mp.matrix(4, 4)
            force = mp.matrix(4, 4)
            for j in range(4):
                disp[0, j], disp[1, j] = top[0, j], top[1, j]
                disp[2, j], disp[3, j] = bottom[0, j], bottom[1, j]
                force[0, j], force[1, j] = -top[2, j], -top[3, j]
                force[2, j], force[3, j] = bottom[2, j], bottom[3, j]
            kk, pp, slip = closed_forms(x, nu)
            worst["stiffness"] = max(worst["stiffness"], largest(force * mp.inverse(disp), kk))
            worst["transfer"] = max(worst["transfer"], largest(top * mp.inverse(bottom), pp))
            # Frictionless rigid base: -sigma_xz = tau, -sigma_zz = p at z = 0; sigma_xz = u_z = 0 at z = h.
            a = mp.matrix(4, 4)
            for j in range(4):
                a[0, j], a[1, j] = -top[2, j], -top[3, j]
                a[2, j], a[3, j] = bottom[2, j], bottom[1, j]
            comp = mp.matrix(2, 2)
            for col in range(2):
                rhs = mp.matrix(4, 1)
                rhs[col] = 1
                coef = mp.lu_solve(a, rhs)
                for i in range(2):
                    comp[i, col] = sum(top[i, j] * coef[j] for j in range(4)) / (2 * (1 - nu))
            worst["frictionless base"] = max(worst["frictionless base"], largest(comp, slip))
    for name, value in worst.items():
        print(f"{name:18s} closed form vs 40-digit mode solve: {mp.nstr(value, 3)}")


if __name__ == "__main__":
    main()
