"""GFMD's masses, a numpy prototype of the frictionless dynamics: one mass for every node
(the Fortran solver's) against a mass per mode K(q)^alpha, with the hard wall either as the
projection after each step or with the mass restricted to the free nodes; FIRE as in the
solver (Bitzek et al.) or FIRE 2.0 (Guenole et al.).

The scenes of bench/gfmd.py (the Fig. 3 surface: H = 0.8, shortest wavelength lambda/32, rms
gradient 0.1, incompressible layer h/lambda = 0.05, loads p_m/(E* h/lambda) 0.0215 and 1:
2 % and 26 % contact). A run counts FIRE's steps until the pressure the wall carries is within
`--error` p_m of the default solver's at tol 1e-13 (checked every 10 steps); a step costs one
transform pair with one mass, two with a mass per mode. docs/decisions/001-gfmd-masses.md.

    .venv/bin/python bench/gfmd_masses.py [--sizes 64 128] [--max-steps 3000] [--variants NAME ...]
"""

from __future__ import annotations

import argparse

import numpy as np

import layercontact as lc

THICKNESS = 0.05
LOADS = (0.02154, 1.0)
# FIRE (Bitzek et al.), as in src/contact/solver_gfmd.f90
FIRE_MIN_STEPS, FIRE_GROW, FIRE_SHRINK, FIRE_ALPHA0, FIRE_ALPHA_DECAY = 5, 1.1, 0.5, 0.1, 0.99


def scene(n: int, load: float):
    """The heights, the default solver's result and the compliance G_n(q) of the result's units."""
    r = lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=1 / 32, rms_gradient=0.1)
    ref = lc.solve_areal(r, tol=1e-13, thickness=THICKNESS, poisson=0.5, friction=0.0,
                         normalised_pressure=load, stress=False)
    qx = 2 * np.pi * np.fft.rfftfreq(n, 1 / n)
    qy = 2 * np.pi * np.fft.fftfreq(n, 1 / n)
    g = np.real(lc.surface_tensor(*np.meshgrid(qx, qy), thickness=THICKNESS, poisson=0.5)[..., 2, 2])
    # (the surface tensor's compliance up to the modulus: the factor that gives the result's w)
    w = np.fft.irfft2(g * np.fft.rfft2(ref.pressure), s=r.shape)
    w, w_ref = w - w.mean(), ref.displacement_z - ref.displacement_z.mean()
    return r, ref, g * np.sum(w_ref * w) / np.sum(w * w)


def steps(r, ref, g, alpha=None, wall="projection", dt_max=1.0, error=1e-8, max_steps=3000, fire2=False):
    """FIRE's steps to the default solver's pressure (None if not within max_steps) and the
    last error. alpha None: one mass (the largest stiffness); else a mass per mode K^alpha,
    scaled so that the stiffest mode has unit frequency. wall: 'projection' (the wall after
    the step) or 'free' (the mass restricted to the free nodes and those the wall releases).
    fire2: FIRE 2.0 (Guenole et al.): the mixing after the velocity's step, half a step back
    when the power turns negative, no shrink in the first 20 steps, 20 steps of positive
    power before the step grows, alpha_0 0.25."""
    pm = ref.mean_pressure
    k = np.zeros_like(g)
    k[g > 0] = 1 / g[g > 0]
    k[0, 0] = 0.0   # load control: the uniform mode carries the load, no stiffness
    k_max = k.max()
    if alpha is None:
        inverse_mass = None
    else:
        mass = np.maximum(k, k[k > 0].min()) ** alpha * k_max ** (1 - alpha)
        inverse_mass = 1 / mass
    u = np.full(r.shape, r.max())
    v = np.zeros_like(u)
    alpha0, min_steps, delay = (0.25, 20, 20) if fire2 else (FIRE_ALPHA0, FIRE_MIN_STEPS, 0)
    dt, mix, positive, err = 0.25, alpha0, 0, np.inf
    for step in range(1, max_steps + 1):
        p = np.fft.irfft2(k * np.fft.rfft2(u), s=r.shape) + pm
        contact = u <= r
        lam = np.where(contact, np.maximum(p, 0), 0.0)
        force = lam - p
        if inverse_mass is None:
            a = force / k_max
        else:
            a = np.fft.irfft2(inverse_mass * np.fft.rfft2(force), s=r.shape)
            if wall == "free":
                a = np.where(contact & (p >= 0), 0.0, a)
        power = np.sum(v * a)
        if power > 0:
            if not fire2:
                v = (1 - mix) * v + mix * np.sqrt(np.sum(v * v) / max(np.sum(a * a), 1e-300)) * a
            positive += 1
            if positive > min_steps:
                dt, mix = min(dt * FIRE_GROW, dt_max), mix * FIRE_ALPHA_DECAY
        else:
            if fire2:
                u = np.maximum(u - 0.5 * dt * v, r)
            v[:] = 0
            if step >= delay:
                dt, mix = dt * FIRE_SHRINK, alpha0
            positive = 0
        v = v + dt * a
        if fire2 and power > 0:
            v = (1 - mix) * v + mix * np.sqrt(np.sum(v * v) / max(np.sum(a * a), 1e-300)) * a
        u = u + dt * v
        below = u < r
        u[below] = r[below]
        v[below] = np.maximum(v[below], 0)
        if step % 10 == 0:
            err = np.max(np.abs(lam - ref.pressure)) / pm
            if err < error:
                return step, err
    return None, err


VARIANTS = {
    "one mass": dict(),
    "K^0.25, wall by projection": dict(alpha=0.25),
    "K^0.5, wall by projection": dict(alpha=0.5),
    "K^0.25, free nodes": dict(alpha=0.25, wall="free"),
    "K^0.5, free nodes": dict(alpha=0.5, wall="free"),
    "K^1, free nodes": dict(alpha=1.0, wall="free"),
    "K^1, free nodes, dt_max 1.8": dict(alpha=1.0, wall="free", dt_max=1.8),
    "one mass, FIRE 2.0": dict(fire2=True),
    "K^1, free nodes, FIRE 2.0": dict(alpha=1.0, wall="free", fire2=True),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128])
    parser.add_argument("--max-steps", type=int, default=3000)
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), help="names of VARIANTS to run")
    args = parser.parse_args()
    for n in args.sizes:
        for load in LOADS:
            r, ref, g = scene(n, load)
            print(f"{n}^2, p_m/(E* h/lambda) = {load:g}, contact {ref.contact_fraction:.3f}, "
                  f"default solver {ref.fft_pairs} pairs", flush=True)
            for name in args.variants:
                keys = VARIANTS[name]
                count, err = steps(r, ref, g, max_steps=args.max_steps, **keys)
                pairs = "-" if count is None else count * (1 if "alpha" not in keys else 2)
                print(f"  {name:30s} steps {str(count):>5s}  pairs {pairs!s:>5s}  error {err:.1e}", flush=True)


if __name__ == "__main__":
    main()
