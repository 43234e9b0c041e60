"""GFMD (&solver method = 'gfmd') against the default solvers: the same contact on
frictionless and coupled scenes, to the bound the two tolerances allow, among them the
paper's Fig. 3 family (thin incompressible layers, mu_c up to 1, from ~1 % to full contact);
scenes whose friction ratio is beyond what the update of the friction traction was measured
to relax are refused before any step (docs/decisions/001-gfmd-masses.md). Under `mpirun -n P`
GFMD runs on the slabs and gives the serial run's answer (with the functions of test_mpi.py)."""

import numpy as np
import pytest

import layercontact as lc
from test_mpi import assert_same, executable, needs_mpi, read, run_mpi, run_serial

TOL = 1e-9
P_M = 0.02


def surface(n=64, seed=2):
    return lc.self_affine_surface(n=n, hurst=0.8, seed=seed, short_wavelength=8 / n, rms_gradient=0.1)


def pressure_bound(heights, thickness, poisson, friction, tol, mean_pressure=P_M):
    """What a residual tol allows the pressure to differ by: a gap off by tol g_ref moves the
    pressure by at most the largest stiffness |1/G_eff| times it, a pressure off by tol p_m
    directly (two solutions, each within its tolerance)."""
    ny, nx = heights.shape
    qx = 2 * np.pi * np.fft.rfftfreq(nx, 1 / nx)
    qy = 2 * np.pi * np.fft.fftfreq(ny, 1 / ny)
    t = lc.surface_tensor(*np.meshgrid(qx, qy), thickness=thickness, poisson=poisson)
    g = t[..., 2, 2] + friction * t[..., 2, 0]
    stiffness = np.max(1 / np.abs(g[np.abs(g) > 0]))
    g_ref = np.ptp(heights)
    return 2 * tol * (stiffness * g_ref + mean_pressure)


@pytest.mark.parametrize(
    "thickness, poisson, friction",
    [(np.inf, 0.5, 0.0), (np.inf, 0.3, 0.0), (np.inf, 0.3, 0.5), (0.16, 0.5, 0.3), (0.5, 0.3, 0.3)],
    ids=["half-space", "compressible", "compressible-friction", "thin-layer-friction", "layer-friction"],
)
def test_gfmd_agrees_with_the_default_solver(thickness, poisson, friction):
    h = surface()
    ref = lc.solve_areal(h, thickness=thickness, poisson=poisson, friction=friction, mean_pressure=P_M, tol=1e-13)
    dyn = lc.solve_areal(h, thickness=thickness, poisson=poisson, friction=friction, mean_pressure=P_M, tol=TOL,
                         method="gfmd", max_iter=20000)
    assert dyn.solver == "gfmd" and dyn.converged and dyn.residual <= TOL
    bound = pressure_bound(h, thickness, poisson, friction, TOL + 1e-13)
    assert np.max(np.abs(dyn.pressure - ref.pressure)) <= bound
    assert dyn.mean_pressure == pytest.approx(P_M, rel=TOL)
    # the contact sets agree but for nodes whose pressure or gap is within the bound
    differ = (dyn.pressure > 0) != (ref.pressure > 0)
    assert np.all(ref.pressure[differ] <= bound)
    assert abs(dyn.delta_mu - ref.delta_mu) <= 1e-6 * max(abs(ref.delta_mu), friction, 1e-3)


def test_gfmd_under_displacement_control():
    """A compressible layer pressed to a given penetration: the uniform mode has a stiffness."""
    h = surface(seed=5)
    ref = lc.solve_areal(h, thickness=0.5, poisson=0.3, penetration=0.01, tol=1e-13)
    dyn = lc.solve_areal(h, thickness=0.5, poisson=0.3, penetration=0.01, tol=TOL, method="gfmd", max_iter=20000)
    assert dyn.converged
    assert dyn.mean_pressure == pytest.approx(ref.mean_pressure, rel=1e-6)
    assert dyn.penetration == pytest.approx(0.01, rel=1e-12)


def fig3_surface(n):
    """The Fig. 3 sweeps' topography (inputs/sweeps/fig3*.nml): shortest wavelength lambda/32."""
    return lc.self_affine_surface(n=n, hurst=0.8, seed=1, short_wavelength=1 / 32, rms_gradient=0.1)


FIG3_SCENES = {  # id: (h/lambda, mu_c, p_m/(E* h/lambda), grids)
    "h005-frictionless-2%": (0.05, 0.0, 0.02154, (64, 128)),
    "h005-frictionless-26%": (0.05, 0.0, 1.0, (64, 128)),
    "h016-frictionless-8%": (0.16, 0.0, 0.02154, (64, 128)),
    "h016-mu02-8%": (0.16, 0.2, 0.02154, (64, 128)),
    "h016-mu02-97%": (0.16, 0.2, 1.0, (64, 128)),
    # the sparse contacts with friction take a few hundred traction updates: 64² only
    "h005-mu05-2%": (0.05, 0.5, 0.02154, (64,)),
    "h005-mu05-28%": (0.05, 0.5, 1.0, (64, 128)),
    "h005-mu05-98%": (0.05, 0.5, 21.54, (64, 128)),
    "h005-mu1-2%": (0.05, 1.0, 0.02154, (64,)),
    "h005-mu1-32%": (0.05, 1.0, 1.0, (64, 128)),
    "h005-mu1-full": (0.05, 1.0, 21.54, (64, 128)),
    "h016-mu1-8%": (0.16, 1.0, 0.02154, (64,)),
    "h016-mu1-99%": (0.16, 1.0, 1.0, (64, 128)),
}


@pytest.mark.parametrize(
    "n, thickness, friction, load",
    [pytest.param(n, h, mu, load, id=f"{name}-{n}") for name, (h, mu, load, grids) in FIG3_SCENES.items()
     for n in grids],
)
def test_gfmd_on_fig3_scenes(n, thickness, friction, load):
    """Fig. 3 scenes (incompressible layer, p_m/(E* h/lambda) = load): the contact of the
    default solver, pressures to the bound of the two tolerances, the contact set but for
    nodes within that bound, Delta mu and the penetration to 1e-6 relative (a residual of
    1e-9 moves the penetration by at most 1e-9 of the profile's peak-to-valley, below 1e-6
    of the penetration here)."""
    assert_gfmd_agrees(n, thickness, friction, load)


def assert_gfmd_agrees(n, thickness, friction, load, mass="auto"):
    """GFMD (its masses `mass`, &solver gfmd_mass) against the default solver on the Fig. 3
    surface, as test_gfmd_on_fig3_scenes; returns GFMD's result."""
    h = fig3_surface(n)
    keys = dict(thickness=thickness, poisson=0.5, friction=friction, normalised_pressure=load, stress=False)
    ref = lc.solve_areal(h, tol=1e-13, **keys)
    dyn = lc.solve_areal(h, tol=TOL, method="gfmd", gfmd_mass=mass, max_iter=20000, **keys)
    assert dyn.solver == "gfmd" and dyn.converged and dyn.residual <= TOL
    bound = pressure_bound(h, thickness, 0.5, friction, TOL + 1e-13, ref.mean_pressure)
    assert np.max(np.abs(dyn.pressure - ref.pressure)) <= bound
    differ = (dyn.pressure > 0) != (ref.pressure > 0)
    assert np.count_nonzero(differ) <= 2 and np.all(ref.pressure[differ] <= bound)
    assert abs(dyn.delta_mu - ref.delta_mu) <= 1e-6 * max(abs(ref.delta_mu), 1e-3)
    assert dyn.penetration == pytest.approx(ref.penetration, rel=1e-6)
    return dyn


MODE_MASS_SCENES = {  # id: (mu_c, p_m/(E* h/lambda), grids), h/lambda = 0.05
    "frictionless-2%": (0.0, 0.02154, (64, 128)),
    "frictionless-26%": (0.0, 1.0, (64, 128)),
    "mu05-2%": (0.5, 0.02154, (64,)),
    "mu05-28%": (0.5, 1.0, (64, 128)),
    "mu1-2%": (1.0, 0.02154, (64,)),
    "mu1-32%": (1.0, 1.0, (64,)),
}


@pytest.mark.parametrize(
    "n, friction, load",
    [pytest.param(n, mu, load, id=f"{name}-{n}") for name, (mu, load, grids) in MODE_MASS_SCENES.items()
     for n in grids],
)
def test_gfmd_with_a_mass_per_mode_agrees(n, friction, load):
    """&solver gfmd_mass = 'mode' (a mass per mode on the free set) on Fig. 3 scenes of the
    thin layer (h/lambda = 0.05), frictionless and with the friction traction's Newton
    update: the contact of the default solver to the bounds of test_gfmd_on_fig3_scenes,
    and two transform pairs a step (the mass's multiplier applied)."""
    dyn = assert_gfmd_agrees(n, 0.05, friction, load, mass="mode")
    assert dyn.fft_pairs >= 2 * dyn.iterations


def test_gfmd_steps_with_a_mass_per_mode_do_not_grow_with_the_grid():
    """At 2 % contact (h/lambda = 0.05, the Fig. 3 surface) one mass for every node, the
    stiffest mode's stiffness (which doubles with the grid), leaves the modes between the
    contact spots ever slower: its steps grow from 64² to 256² (200 to 290, measured),
    while with a mass per mode every mode has one frequency and the steps stay flat (210,
    180, 200). The mass per mode's steps grow by at most 1.15 (measured 0.95, the one
    mass's 1.45: the bound fails if the mass per mode is not applied), and stay below the
    one mass's at 256²."""
    steps = {}
    for mass in ("one", "mode"):
        for n in (64, 256):
            h = fig3_surface(n)
            dyn = lc.solve_areal(h, thickness=0.05, poisson=0.5, normalised_pressure=0.02154, stress=False,
                                 tol=1e-8, method="gfmd", gfmd_mass=mass, max_iter=20000)
            assert dyn.converged
            assert {"one": "GFMD with unit masses, as the scene asks",
                    "mode": "GFMD with a mass per mode, as the scene asks"}[mass] in dyn.solver_reason
            steps[mass, n] = dyn.iterations
    assert steps["mode", 256] <= 1.15 * steps["mode", 64]
    assert steps["one", 256] > 1.3 * steps["one", 64]
    assert steps["mode", 256] < steps["one", 256]


@pytest.mark.parametrize("n, load, per_mode", [(256, 0.02154, False), (512, 0.02154, True), (512, 0.1, False)],
                         ids=["256-2%", "512-2%", "512-7%"])
def test_gfmd_auto_takes_the_mass_per_mode_at_sparse_contact_from_512(n, load, per_mode):
    """gfmd_mass = 'auto' takes the mass per mode (two transform pairs a step) where it was
    measured to take fewer pairs than one mass: from 512² where the coarse start's contact is
    at most 4 % (2 % here: 420 pairs against 421 at 512², 359 against 520 at 1024²), one
    mass (a pair a step and one per check) on 256² (494 against 367 pairs) and at 6.6 %
    contact (359 against 331 at 512²); h/lambda = 0.05, frictionless. The pairs per step
    tell which ran: 1.1-1.3 with one mass (a pair a step, one a check of ten steps, and the
    coarse start's), 2 or more with the mass per mode. The result's reason says which."""
    h = fig3_surface(n)
    dyn = lc.solve_areal(h, thickness=0.05, poisson=0.5, normalised_pressure=load, stress=False, tol=1e-8,
                         method="gfmd", max_iter=20000)
    assert dyn.converged
    assert (dyn.fft_pairs >= 2 * dyn.iterations) == per_mode
    said = "GFMD with a mass per mode (gfmd_mass 'auto'" if per_mode else "GFMD with unit masses (gfmd_mass 'auto'"
    assert said in dyn.solver_reason, dyn.solver_reason


def test_gfmd_refuses_an_unknown_mass():
    """A gfmd_mass that is not one of the three is refused with the group, the variable, the
    value and the allowed ones, before any solve."""
    with pytest.raises(lc.InputError, match="&solver: gfmd_mass = heavy is not allowed; allowed: 'auto', "
                                            "'one' or 'mode'") as refused:
        lc.solve_areal(fig3_surface(32), thickness=0.05, poisson=0.5, normalised_pressure=1.0, method="gfmd",
                       gfmd_mass="heavy")
    assert refused.value.code == 2


def friction_ratio(n, thickness, friction):
    """mu_c |G_x|/|G_n| over the grid's modes, from the layer's surface tensor: the ratio of
    the normal response to the friction traction to that to the pressure."""
    q = 2 * np.pi * np.fft.fftfreq(n, 1 / n)
    t = lc.surface_tensor(*np.meshgrid(q, q), thickness=thickness, poisson=0.5)
    normal, tangential = t[..., 2, 2], t[..., 2, 0]
    keep = np.abs(normal) > 0
    return friction * np.max(np.abs(tangential[keep]) / np.abs(normal[keep]))


@pytest.mark.parametrize("thickness, friction", [(0.01, 0.26), (0.01, 0.5), (0.01, 1.5)],
                         ids=["h001-mu026", "h001-mu05", "h001-mu15"])
def test_gfmd_refuses_what_its_traction_update_cannot_relax(thickness, friction):
    """The thinnest incompressible layer with friction: mu_c |G_x|/|G_n| reaches 6.2 (h/lambda
    = 0.01, mu_c = 0.26, just beyond the limit 6), 12 (mu_c = 0.5) and 36 (mu_c = 1.5); the
    dynamics was measured to diverge at half contact from 6.92 and at 22-40 % contact at 12
    (docs/decisions/001-gfmd-masses.md); the solve is refused before any step, and the
    message names the default method."""
    assert friction_ratio(32, thickness, friction) > 6
    h = fig3_surface(32)
    refusal = "'gfmd' cannot solve this scene.*friction ratio.*'auto' \\(the default method\\)"
    with pytest.raises(lc.InputError, match=refusal):
        lc.solve_areal(h, thickness=thickness, poisson=0.5, friction=friction, mean_pressure=P_M, tol=TOL,
                       method="gfmd", max_iter=3000)


def test_gfmd_admits_the_fig3_family():
    """The Fig. 3 family's strongest coupling, h/lambda = 0.05 and mu_c = 1, has the ratio 4.68
    (the refusal's measure is the surface tensor's), within the limit: admitted."""
    assert friction_ratio(64, 0.05, 1.0) == pytest.approx(4.68, abs=0.01)
    dyn = lc.solve_areal(fig3_surface(32), thickness=0.05, poisson=0.5, friction=1.0, normalised_pressure=1.0,
                         tol=1e-8, method="gfmd", max_iter=20000, stress=False)
    assert dyn.solver == "gfmd" and dyn.converged


def test_gfmd_converges_just_inside_its_limit():
    """h/lambda = 0.01, mu_c = 0.25: the friction ratio 5.96, just inside the limit 6, at half
    contact (p_m/(E* h/lambda) = 600), where a ratio of 6.92 makes the dynamics diverge:
    admitted, and the contact of the default solver (the bounds of test_gfmd_on_fig3_scenes)."""
    assert friction_ratio(64, 0.01, 0.25) == pytest.approx(5.96, abs=0.01)
    assert_gfmd_agrees(64, 0.01, 0.25, 600.0)


def test_gfmd_refuses_a_strongly_coupled_line():
    """A line is a grid of one row: the same measure of the operator refuses it."""
    r = lc.self_affine_profile(n=256, hurst=0.8, seed=1)
    with pytest.raises(lc.InputError, match="'gfmd' cannot solve this scene"):
        lc.solve_line(r, thickness=0.01, poisson=0.5, friction=1.5, mean_pressure=P_M, method="gfmd")


def test_gfmd_on_a_coupled_line():
    """A thin incompressible layer under a line contact with friction (ratio 2.3): the contact
    of the default solver, pressures to the bound of the two tolerances (as pressure_bound:
    twice the tolerance times the largest stiffness |1/G_eff| of the line's modes times the
    profile's peak-to-valley, plus the mean pressure)."""
    r = lc.self_affine_profile(n=256, hurst=0.8, seed=1)
    keys = dict(thickness=0.05, poisson=0.5, friction=0.5, mean_pressure=P_M)
    ref = lc.solve_line(r, tol=1e-13, **keys)
    dyn = lc.solve_line(r, tol=TOL, method="gfmd", max_iter=20000, **keys)
    assert dyn.solver == "gfmd" and dyn.converged and dyn.residual <= TOL
    qx = 2 * np.pi * np.fft.rfftfreq(r.size, 1 / r.size)[1:]
    t = lc.surface_tensor(qx, 0 * qx, thickness=0.05, poisson=0.5)
    stiffness = np.max(1 / np.abs(t[..., 2, 2] + 0.5 * t[..., 2, 0]))
    bound = 2 * (TOL + 1e-13) * (stiffness * np.ptp(r) + P_M)
    assert np.max(np.abs(dyn.pressure - ref.pressure)) <= bound


SLS = lc.StandardLinearSolid(e0=1.0, e_inf=10.0, tau=1.0)


def test_gfmd_on_a_sliding_viscoelastic_layer_with_friction():
    """A standard linear solid sliding slowly (k V tau ~ 1e-2: |Im G_n|/Re G_n small) with
    friction: the contact of the default solver, pressures to the bound of the two tolerances
    (pressure_bound with the glassy modulus E_inf = 10 E0, whose stiffness bounds the
    viscoelastic layer's: |J*| >= 1/E_inf)."""
    h = surface(n=32)
    keys = dict(thickness=0.5, poisson=0.3, friction=0.5, material=SLS, speed=1e-3, mean_pressure=P_M, stress=False)
    ref = lc.solve_areal(h, tol=1e-13, **keys)
    dyn = lc.solve_areal(h, tol=TOL, method="gfmd", max_iter=20000, **keys)
    assert dyn.solver == "gfmd" and dyn.converged and dyn.residual <= TOL
    bound = SLS.e_inf / SLS.e0 * pressure_bound(h, 0.5, 0.3, 0.5, TOL + 1e-13)
    assert np.max(np.abs(dyn.pressure - ref.pressure)) <= bound


def test_gfmd_refuses_a_lossy_sliding_layer():
    """At k V tau ~ 1 the loss gives the response to the pressure itself a phase
    (|Im G_n|/Re G_n = 1.1 here), which no update of the friction traction removes: refused
    before any step, naming the default method."""
    with pytest.raises(lc.InputError, match="'gfmd' cannot solve this scene.*Im G_n.*'auto' \\(the default method\\)"):
        lc.solve_areal(surface(n=32), thickness=0.5, poisson=0.3, friction=0.3, material=SLS, speed=1.0,
                       mean_pressure=P_M, method="gfmd")


#: the distributed scenes: a thin incompressible layer (h/lambda = 0.05) at ~6 % contact,
#: frictionless and with mu_c = 0.5 (friction ratio 2.3: the traction update runs), with one
#: mass and with a mass per mode (its multiplier on each rank's modes)
MPI_SCENES = {"frictionless": (0.0, "one"), "coupled": (0.5, "one"), "frictionless-mode": (0.0, "mode"),
              "coupled-mode": (0.5, "mode")}


def write_gfmd_scene(directory, name, friction, output, thickness=0.05, n=64, mass="auto"):
    nml = directory / f"{name}.nml"
    nml.write_text(
        f"&scene geometry = 'areal', n = {n}, ny = {n} /\n"
        f"&layer thickness = {thickness}, poisson = 0.5 /\n&friction coefficient = {friction} /\n"
        f"&profile kind = 'self_affine', hurst = 0.8, seed = 3, short_wavelength = {8 / n} /\n"
        "&loading control = 'load', normalised_pressure = 0.15 /\n"
        f"&solver method = 'gfmd', gfmd_mass = '{mass}', tol = 1e-13, max_iter = 20000 /\n"
        f"&output file = '{output}', overwrite = .true., stress = .false. /\n")
    return nml


@needs_mpi
@pytest.mark.parametrize("scene", sorted(MPI_SCENES))
def test_distributed_gfmd_gives_the_serial_answer(scene, tmp_path):
    """GFMD on P = 1..4 ranks (3 splits the 64 rows 22 + 22 + 20): every field and scalar of
    the serial GFMD run to 1e-10 relative (tests/test_mpi.py's SAME). Both runs reach the
    complementarity residual 1e-13, which bounds their pressures' distance from the unique
    solution by ~1e-12 of the largest pressure (measured: 4e-13 against the default solver's);
    the FIRE trajectories differ by the ranks' order of summation (their step counts may
    differ), not the answer. A misplaced slab, a sum or a maximum taken on one rank only, or
    the uniform mode looked for on the wrong rank moves the answer by percents. With the mass
    per mode (gfmd_mass = 'mode') each rank multiplies its own modes by the inverse masses."""
    friction, mass = MPI_SCENES[scene]
    serial = write_gfmd_scene(tmp_path, scene, friction, "serial.h5", mass=mass)
    done = run_serial(serial)
    assert done.returncode == 0, done.stderr
    for ranks in (1, 2, 3, 4):
        out = f"ranks{ranks}.h5"
        nml = write_gfmd_scene(tmp_path, f"{scene}{ranks}", friction, out, mass=mass)
        done = run_mpi(ranks, [executable(), str(nml)], tmp_path)
        assert done.returncode == 0, done.stderr
        assert_same(tmp_path / "serial.h5", tmp_path / out)
        _, scalars, written_ranks = read(tmp_path / out)
        assert written_ranks == ranks
        solver = scalars["solver"]
        assert (solver.decode() if isinstance(solver, bytes) else solver) == "gfmd" and scalars["converged"]
        assert scalars["residual"] <= 1e-13


@needs_mpi
def test_distributed_gfmd_refuses_what_it_cannot_relax(tmp_path):
    """h/lambda = 0.01, mu_c = 1.5 (friction ratio 36, beyond 6): refused on 2 ranks as on one,
    the largest ratio taken over every rank's modes (its longest waves may be on either), exit
    2, one message, no file."""
    nml = write_gfmd_scene(tmp_path, "refused", 1.5, "refused.h5", thickness=0.01, n=32)
    done = run_mpi(2, [executable(), str(nml)], tmp_path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("'gfmd' cannot solve this scene") == 1 and "friction ratio" in done.stderr
    assert not (tmp_path / "refused.h5").exists()
