"""Python keywords and namelist files describe one scene type: a keyword not given takes
the namelist default, a bad keyword value gets the namelist file's message, a solve returns
its scalars under the names of the result file, and the Prony terms of a file are read by
the one reader of &material prony_file."""

import h5py
import numpy as np
import pytest

import layercontact as lc

N = 256


@pytest.fixture(scope="module")
def heights():
    return lc.self_affine_profile(N, 0.7, seed=5, short_wavelength=1 / 32)


def namelist_message(tmp_path, groups: str) -> str:
    """The message for a namelist file of `groups` on a grid of N points with a load."""
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&scene\n n = {N}\n/\n&loading\n mean_pressure = 0.01\n/\n" + groups)
    with pytest.raises(lc.LayercontactError) as err:
        lc.check_scene_file(nml)
    return str(err.value)


@pytest.mark.parametrize("keywords, groups", [
    (dict(thickness=-1.0), "&layer\n thickness = -1.0\n/\n"),
    (dict(poisson=0.7), "&layer\n poisson = 0.7\n/\n"),
    (dict(young=0.0), "&layer\n young = 0.0\n/\n"),
    (dict(friction=11.0), "&friction\n coefficient = 11.0\n/\n"),
    (dict(method="dense"), "&solver\n method = 'dense'\n/\n"),
    (dict(tol=0.5), "&solver\n tol = 0.5\n/\n"),
    (dict(max_iter=0), "&solver\n max_iter = 0\n/\n"),
    (dict(memory=101), "&solver\n memory = 101\n/\n"),
    (dict(speed=0.1), "&material\n speed = 0.1\n/\n"),
    (dict(material=lc.StandardLinearSolid(1.0, 0.5, 1.0), speed=1.0),
     "&material\n model = 'sls'\n e0 = 1.0\n e_inf = 0.5\n tau = 1.0\n speed = 1.0\n/\n"),
], ids=["thickness", "poisson", "young", "friction", "method", "tol", "max_iter", "memory", "elastic speed",
        "sls moduli"])
def test_a_bad_keyword_gets_the_message_of_the_namelist_file(keywords, groups, heights, tmp_path):
    expected = namelist_message(tmp_path, groups)
    assert expected.startswith("&")
    with pytest.raises(lc.InputError) as err:
        lc.solve_line(heights, mean_pressure=0.01, **keywords)
    assert str(err.value) == expected
    assert err.value.code == 2 and isinstance(err.value, ValueError)


def test_loading_rules_are_the_namelist_rules(heights, tmp_path):
    """Neither or both loads: the &loading messages (control follows from penetration)."""
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&scene\n n = {N}\n/\n")
    with pytest.raises(lc.LayercontactError) as err:
        lc.check_scene_file(nml)
    with pytest.raises(lc.InputError) as neither:
        lc.solve_line(heights)
    assert str(neither.value) == str(err.value)
    assert "exactly one of them with control = 'load'" in str(neither.value)
    with pytest.raises(lc.InputError, match="neither with control = 'displacement'"):
        lc.solve_line(heights, mean_pressure=0.01, penetration=0.001)


def test_keywords_not_given_take_the_namelist_defaults(heights, tmp_path, monkeypatch):
    """A namelist file that gives only the grid, the heights and the load solves the scene
    that solve_line solves with only the load: every other default is the same."""
    with h5py.File(tmp_path / "h.h5", "w") as f:
        f["/profile/height"] = heights
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&scene\n n = {N}\n/\n&profile\n kind = 'file'\n file = 'h.h5'\n/\n"
                   "&loading\n mean_pressure = 0.002\n/\n&output\n file = 'r.h5'\n/\n")
    monkeypatch.chdir(tmp_path)
    with h5py.File(lc.api.run_to_file(nml)) as f:
        attrs = dict(f["input"].attrs)
        results = dict(f["results"].attrs)
    assert np.isinf(attrs["thickness"]) and attrs["thickness"] > 0
    res = lc.solve_line(heights, mean_pressure=0.002)
    fromfile = lc.read_result(tmp_path / "r.h5")
    np.testing.assert_array_equal(res.pressure, fromfile.pressure)
    np.testing.assert_array_equal(res.stress_xx, fromfile.stress_xx)
    assert res.iterations == fromfile.iterations and res.solver == fromfile.solver == "cg"
    # the scalars come back under the names of /results, with the same values
    for name in ("mean_pressure", "penetration", "contact_fraction", "delta_mu", "fft_pairs", "n_spots",
                 "max_tension", "leak_rate", "normalised_pressure", "gap_resolution"):
        assert getattr(res, name) == results[name], name


def test_companion_runs_in_the_library_under_displacement_control_too(heights):
    """The frictionless companion of a displacement-controlled scene is solved at the load
    the scene's solve found, as a namelist run solves it."""
    res = lc.solve_line(heights, thickness=0.2, poisson=0.3, friction=0.5, penetration=0.5 * np.ptp(heights),
                        companion=True)
    alone = lc.solve_line(heights, thickness=0.2, poisson=0.3, mean_pressure=res.mean_pressure)
    np.testing.assert_array_equal(res.companion.pressure, alone.pressure)
    assert res.a_over_a0 == res.contact_fraction / alone.contact_fraction


def test_prony_terms_from_a_file_are_read_by_the_namelist_reader(tmp_path):
    path = tmp_path / "terms.txt"
    path.write_text("# tau_i  E_i\n0.1 2.0\n1.0 1.0   ! slow\n\n10.0 0.5\n")
    law = lc.Prony.from_file(path, equilibrium=1.0)
    assert law.times == (0.1, 1.0, 10.0) and law.values == (2.0, 1.0, 0.5)
    bad = tmp_path / "bad.txt"
    bad.write_text("0.1 2.0 3.0\n")
    with pytest.raises(lc.InputError, match=r"line 1: expected two numbers 'tau_i value_i', got more"):
        lc.Prony.from_file(bad, equilibrium=1.0)
    assert lc.materials.MAX_TERMS == 64


def test_the_sinusoid_is_the_namelist_sinusoid():
    h = lc.sinusoid_profile(64, 0.01, mode=3, period=2.0)
    x = np.arange(64) * (2.0 / 64)
    np.testing.assert_allclose(h, 0.01 * np.cos(2 * np.pi * 3 * x / 2.0), rtol=0, atol=1e-17)
    with pytest.raises(lc.InputError, match=r"&profile: mode = 32 is not allowed; allowed: 1 <= mode <= \(n-1\)/2"):
        lc.sinusoid_profile(64, 0.01, mode=32)
