"""Print the validation table of docs/validation.md: each row is an independent check of the code,
computed here and now (the tests in tests/ assert the same quantities).

    .venv/bin/python tools/validation_table.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import layercontact as lc

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from analytic import westergaard_half_width, westergaard_mean_gap  # noqa: E402
from conftest import contact_violation  # noqa: E402
from test_solver import full_contact_sinusoid  # noqa: E402


def row(check: str, reference: str, value: str) -> None:
    print(f"| {check} | {reference} | {value} |")


def kernels() -> None:
    data = np.loadtxt(ROOT / "tests/data/kernel_reference.txt")
    worst = np.zeros(3)
    for nu in np.unique(data[:, 1]):
        sel = data[:, 1] == nu
        got = np.column_stack(lc.layer_multipliers(data[sel, 0], nu))
        ref = data[sel, 2:5]
        scale = np.maximum(np.abs(ref), 1e-300)
        scale[:, 2] = np.maximum(np.abs(ref[:, 2]), 1e-13 * ref[:, 0])
        worst = np.maximum(worst, (np.abs(got - ref) / scale).max(axis=0))
    row("kernels 1-A, 1-B, c for kh in [1e-8, 1e6], 10 values of nu (610 points)",
        "mpmath, 60 digits (tests/data)", f"max rel. error {worst[0]:.1e}, {worst[1]:.1e}, {worst[2]:.1e}")
    x = np.geomspace(1e-2, 20, 200)
    err = 0.0
    for nu in (-0.9, 0.0, 0.3, 0.49, 0.5):
        closed = np.column_stack(lc.layer_multipliers(x, nu))
        lapack = np.column_stack(lc.layer_multipliers_lapack(x, nu))
        scale = np.abs(closed)
        scale[:, 2] = np.maximum(scale[:, 2], 1e-4 * np.sqrt(closed[:, 0] * closed[:, 1]))
        err = max(err, (np.abs(lapack - closed) / scale).max())
    row("closed forms vs 4x4 plane-strain mode solve (kh in [1e-2, 20], 5 nu)", "LAPACK zgesv",
        f"max rel. difference {err:.1e}")


def westergaard() -> None:
    h0, estar = 0.01, 4 / 3
    pstar = np.pi * estar * h0
    for n in (1024, 8192):
        h = lc.sinusoid_profile(n, h0)
        for ratio in (0.1, 0.5):
            res = lc.solve_line(h, poisson=0.5, mean_pressure=ratio * pstar, tol=1e-12)
            a = 2 * westergaard_half_width(ratio * pstar, estar, h0, 1.0)
            gbar = westergaard_mean_gap(ratio * pstar, estar, h0, 1.0)
            row(f"Westergaard, half-space, p_m/p* = {ratio}, n = {n}", f"2a/lambda = {a:.6f}, mean gap/h0 = {gbar / h0:.6f}",
                f"2a/lambda error {res.contact_fraction - a:+.1e} (grid step {1 / n:.1e}); "
                f"mean gap error {(h0 - res.penetration - gbar) / h0:+.1e} h0")


def full_contact() -> None:
    for thickness, nu, mu in ((0.01, 0.5, 1.5), (0.05, 0.3, 0.8), (np.inf, 0.3, 0.5)):
        n, h0, mode = 512, 1e-3, 3
        *_, gabs = full_contact_sinusoid(h0, mode, 1.0, thickness, 1.0, nu, mu, n)
        pm = 2 * h0 / gabs
        p_ref, pen_ref, dmu_ref, _ = full_contact_sinusoid(h0, mode, pm, thickness, 1.0, nu, mu, n)
        res = lc.solve_line(lc.sinusoid_profile(n, h0, mode=mode), thickness=thickness, poisson=nu, friction=mu,
                            mean_pressure=pm, tol=1e-10)
        row(f"full-contact sinusoid, h/lambda = {thickness:g}, nu = {nu}, mu_c = {mu} (tol 1e-10)",
            "exact: p = p_m + h0 Re[e^ikx/G_eff(k)]",
            f"max p error {np.abs(res.pressure - p_ref).max() / pm:.1e} p_m; Delta {abs(res.penetration - pen_ref) / h0:.1e} h0; "
            f"Delta mu rel. {abs(res.delta_mu - dmu_ref) / abs(dmu_ref):.1e}")


def partial_contact() -> None:
    h = lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
    for thickness, mu in ((0.16, 0.5), (1e-3, 1.5)):
        pm = h.max() * (1.0 if thickness > 0.1 else 160.0)
        res = lc.solve_line(h, thickness=thickness, friction=mu, mean_pressure=pm, tol=1e-10)
        v = contact_violation(res, thickness, 1.0, 0.5)
        row(f"rough profile, h/lambda = {thickness:g}, mu_c = {mu}, contact {res.contact_fraction:.2f} (tol 1e-10)",
            "contact conditions recomputed with numpy FFT",
            f"overlap {v['overlap']:.1e}, gap in contact {v['gap_in_contact']:.1e} (of peak-to-valley)")
        row("  Delta mu routes, same run", "Eq. 11 vs spectral vs energy",
            f"{abs(res.delta_mu_spectral / res.delta_mu - 1):.1e}, {abs(res.delta_mu_energy / res.delta_mu - 1):.1e}")
    for n in (2048, 8192, 32768):
        h = lc.self_affine_profile(n, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
        res = lc.solve_line(h, thickness=0.16, friction=0.5, mean_pressure=0.4 * h.max(), tol=1e-11)
        row(f"  force balance -<p r'>/p_m vs Eq. 11, n = {n}", "converges with the grid",
            f"rel. difference {abs(res.delta_mu_profile / res.delta_mu - 1):.1e}")
    h = lc.self_affine_profile(4096, 0.8, seed=1, short_wavelength=1 / 64, rms_gradient=0.1)
    r0 = lc.solve_line(h, poisson=0.5, friction=0.0, mean_pressure=0.3 * h.max())
    r1 = lc.solve_line(h, poisson=0.5, friction=0.9, mean_pressure=0.3 * h.max())
    row("incompressible half-space, mu_c = 0.9 vs 0", "friction changes nothing (c = 0)",
        f"max pressure difference {np.abs(r1.pressure - r0.pressure).max():.1e}")


def surface_stress() -> None:
    mu, a, nu = 0.5, 0.02, 0.3
    for n in (2**14, 2**16, 2**18):
        x = (np.arange(n) / n + 0.5) % 1 - 0.5
        p = np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))
        _, sxx = lc.surface_fields(p, poisson=nu, friction=mu)
        inside = np.abs(x) < 0.9 * a
        interior = np.abs(sxx - (-p - 2 * mu * x / a))[inside].max()
        row(f"sliding Hertz tractions on a half-space, a = 0.02 lambda, mu = 0.5, n = 2^{int(np.log2(n))}",
            "Johnson §7.1: sigma_xx = -p - 2 mu p0 x/a; 2 mu p0 at the trailing edge",
            f"interior error {interior:.1e} p0 (periodic images); trailing-edge tension {sxx.max():.4f} "
            f"(exact 1) at x/a = {x[np.argmax(sxx)] / a:.4f}")
    _, sxx = lc.surface_fields(np.full(64, 0.7), thickness=0.1, poisson=0.3, friction=0.5)
    row("uniform pressure on a layer, nu = 0.3", "sigma_xx = -(nu/(1-nu)) p_m",
        f"max rel. error {np.abs(sxx / (-0.3 / 0.7 * 0.7) - 1).max():.1e}")


def main() -> None:
    print("| check | reference | result |")
    print("|---|---|---|")
    kernels()
    westergaard()
    full_contact()
    partial_contact()
    surface_stress()


if __name__ == "__main__":
    main()
