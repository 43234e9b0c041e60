"""The scene schema (driver/layercontact/scene_schema.py) is the one list of namelist
variables: the library reads exactly its variables, the generated docs table is current,
and its columns are complete."""

import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

import layercontact as lc
from layercontact import scene_schema as schema

ROOT = Path(__file__).resolve().parent.parent
# the executable installed with the package that runs the tests
EXECUTABLE = shutil.which("layercontact", path=sysconfig.get_path("scripts")) or "layercontact"


def test_the_docs_table_is_current():
    """docs/namelist.md holds the table generated from the schema (rerun
    `python tools/scene_codegen.py docs` after changing the schema)."""
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "scene_codegen.py"), "docs", "--check"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("group", schema.GROUPS)
def test_the_library_reads_the_variables_of_the_schema(group, tmp_path):
    """An unknown variable's message lists the group's variables: those of the schema, in
    its order."""
    nml = tmp_path / "scene.nml"
    nml.write_text(f"&{group}\n no_such_variable = 1\n/\n")
    with pytest.raises(lc.InputError) as err:
        lc.check_scene_file(nml)
    listed = re.search(rf"allowed variables in &{group}: (.*)$", str(err.value)).group(1)
    assert listed.split(", ") == [v.name for v in schema.group_variables(group)]


def test_every_row_is_complete():
    """Every variable has a known group, type, use and unit, a meaning and an allowed range;
    the names of /input (and of the keywords) are unique; aliases name a variable of their
    group; the sweep's positions are 1, 2, ..."""
    # (siemens/L: the conductivity, S/m with lengths in m; S is the stress unit)
    units = {"", "1", "L", "S", "T", "L/T", "S or 1/S", "siemens/L"}
    for v in schema.VARIABLES:
        assert v.group in schema.GROUPS and v.type in schema.TYPES, v
        assert v.uses in ("both", "line", "areal") and v.unit in units, v
        assert v.meaning and v.allowed and v.default and v.fortran.startswith("scene%"), v
    keys = [v.result_name for v in schema.VARIABLES if v.alias_of is None]
    assert len(keys) == len(set(keys)) == len(schema.by_key())
    for v in schema.VARIABLES:
        if v.alias_of is not None:
            assert v.alias_of in [w.name for w in schema.group_variables(v.group)]
    assert [v.sweep for v in schema.sweep_parameters()] == list(range(1, len(schema.sweep_parameters()) + 1))
    names = {(v.group, v.name) for v in schema.VARIABLES}
    assert len(names) == len(schema.VARIABLES)


def test_keyword_groups_put_each_keyword_in_its_group():
    groups = schema.keyword_groups(friction=0.3, profile_file="h.h5", output_file="r.h5", n=64, verbose=None)
    assert groups == {"friction": {"coefficient": 0.3}, "profile": {"file": "h.h5"}, "output": {"file": "r.h5"},
                      "scene": {"n": 64}, "solver": {"verbose": None}}
    with pytest.raises(TypeError, match="not scene variables: coefficient"):
        schema.keyword_groups(coefficient=0.3)


# Scenes that together set every variable of the schema (most to a value other than its
# default) and that run in well under a second each; variables that exclude each other
# (the loads, the material laws, the profile kinds) are in different scenes.
SCENES = {
    "areal_sinusoid": """
&scene geometry = 'areal', title = 'it''s a round trip', period = 2.0, period_y = 1.5, nx = 16, ny = 8 /
&layer thickness = 0.5, young = 3.0, poisson = 0.3 /
&material model = 'sls', e0 = 1.0, e_inf = 4.0, tau = 0.2, speed = 0.1 /
&friction coefficient = 0.2, companion = .true. /
&profile kind = 'sinusoid', amplitude = 0.01, mode = 1, mode_y = -1 /
&loading control = 'displacement', penetration = 0.005 /
&solver method = 'gcr', tol = 1e-9, max_iter = 5000, memory = 7, precondition = .false.,
        coarse_start = .false., threads = 1, verbose = .true. /
&output file = 'areal_sinusoid.h5', overwrite = .true., stress = .false., gap_bins = 10, fields = .false.,
        leakage = .true., leakage_tol = 1e-5 /
""",
    "line_prony": """
&scene n = 64, period = 0.5 /
&layer thickness = 0.2, interface = 'slip', lower_thickness = 0.1, 0.3, lower_young = 2.0, 5.0,
       lower_poisson = 0.3, 0.25, lower_tau = 0.5, 0.0, lower_e_inf = 8.0, 5.0,
       lower_interfaces = 'slip bonded', substrate_young = 20.0,
       substrate_poisson = 0.28 /
&material model = 'prony', prony_form = 'creep', prony_equilibrium = 0.5, prony_times = 0.1, 1.0,
          prony_values = 0.2, 0.3, speed = 0.05 /
&profile kind = 'self_affine', hurst = 0.6, seed = 7, rolloff_wavelength = 0.25, short_wavelength = 0.05,
         rms_height = 0.001 /
&loading normalised_pressure = 0.3 /
&output file = 'line_prony.h5' /
""",
    "areal_sphere": """
&scene geometry = 'areal', n = 16 /
&profile kind = 'sphere', radius = 2.0, rms_gradient = 0.05 /
&loading mean_pressure = 0.01 /
&output file = 'areal_sphere.h5' /
""",
    # the accuracy rule chooses n and tol (below: the expected scene takes its choice)
    "line_target": """
&scene n = 64 /
&profile kind = 'self_affine', rms_gradient = 0.05 /
&loading normalised_pressure = 0.5 /
&solver target_error = 0.1, tol = 1e-9 /
&output file = 'line_target.h5' /
""",
    "line_file": """
&scene n = 32 /
&profile kind = 'file', file = 'heights.h5', dataset = '/h', detrend = 'plane', boundary = 'mirror',
         resample = 'fourier' /
&loading normalised_pressure = 0.5 /
&output file = 'line_file.h5' /
""",
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """The /input of each scene's result: attributes and datasets, and the scene text."""
    import h5py
    import numpy as np

    directory = tmp_path_factory.mktemp("round_trip")
    with h5py.File(directory / "heights.h5", "w") as f:
        f["/h"] = 1e-3 * np.sin(np.linspace(0.0, 3.0, 24)) ** 2
    out = {}
    for name, text in SCENES.items():
        (directory / f"{name}.nml").write_text(text)
        done = subprocess.run([EXECUTABLE, f"{name}.nml"], cwd=directory,
                              capture_output=True, text=True)
        assert done.returncode in (0, 3), done.stderr
        with h5py.File(directory / f"{name}.h5") as f:
            attrs = dict(f["input"].attrs)
            datasets = {key: f["input"][key][()] for key in f["input"] if key != "namelist"}
        if "target_error" in text:
            n, tol = lc.choose_resolution(directory / f"{name}.nml")
            text = text.replace("n = 64", f"n = {n}").replace("tol = 1e-9", f"tol = {tol!r}")
        out[name] = (text, attrs, datasets)
    return out


def test_input_holds_every_variable_with_its_unit(results):
    """Every variable of the schema is in the /input of some scene; no value is a sentinel
    number; @units names the unit of every dimensional variable present."""
    seen = set()
    for text, attrs, datasets in results.values():
        seen |= set(attrs) | set(datasets)
        for key, value in attrs.items():
            if isinstance(value, float):
                assert abs(value) < 1e300 or value == float("inf"), (key, value)
        units = dict(item.rsplit(" ", 1) if " or " not in item else item.split(" ", 1)
                     for item in attrs["units"].decode().split("; ")[:-2])
        for key, variable in schema.by_key().items():
            if variable.unit not in ("", "1") and (key in attrs or key in datasets):
                assert units[key] == variable.unit, key
    assert set(schema.by_key()) <= seen
    assert set(seen) - set(schema.by_key()) == {"units", "normalised_pressure_scale"}


def test_unset_variables_are_absent(results):
    _, attrs, _ = results["line_prony"]
    for key in ("period_y", "mean_pressure", "penetration", "rms_gradient", "amplitude", "radius", "target_error",
                "e0", "e_inf", "tau"):
        assert key not in attrs, key
    assert attrs["normalised_pressure"] == 0.3
    assert attrs["normalised_pressure_scale"].decode() == "E* Lambda0/period (Lambda0 = max r - mean r)"
    _, attrs, _ = results["areal_sinusoid"]
    assert attrs["normalised_pressure_scale"].decode() == "E* thickness/period (an areal scene on a layer)"


@pytest.mark.parametrize("name", SCENES)
def test_namelist_input_keywords_give_the_same_scene(results, name):
    """namelist -> /input -> Python keywords -> the same scene: the library's echo of the
    keywords' scene is the echo of the namelist's."""
    text, attrs, datasets = results[name]
    keywords = schema.input_keywords(attrs, datasets)
    assert lc.scene_namelist(**keywords) == lc.scene_namelist(text)
    line = attrs["geometry"].decode() == "line"
    assert set(keywords) == {key for key, v in schema.by_key().items()
                             if (key in attrs or key in datasets) and v.echo and not (line and v.uses == "areal")}


def test_the_defaults_are_the_schemas(tmp_path):
    """`layercontact --defaults` prints every variable of the schema (the aliases aside),
    with the schema's default; the areal scene differs in its geometry and grid only."""
    line = subprocess.run([EXECUTABLE, "--defaults"], capture_output=True,
                          text=True, check=True).stdout
    areal = subprocess.run([EXECUTABLE, "--defaults", "areal"],
                           capture_output=True, text=True, check=True).stdout
    assert line == lc.default_scene() and areal == lc.default_scene("areal")
    for geometry, text in (("line", line), ("areal", areal)):
        printed = subprocess.run([sys.executable, "-m", "layercontact", "defaults", geometry], capture_output=True,
                                 text=True, check=True).stdout
        assert printed == text
    def shown_values(text: str) -> dict[tuple[str, str], str]:
        values = {}
        group = None
        for row in text.splitlines():
            row = row.strip()
            if row.startswith("&"):
                group = row[1:]
            elif row.startswith("! ") and row.endswith((": not set", ": surfaces only")):
                name, state = row[2:].split(": ")
                values[(group, name)] = state
            elif " = " in row and not row.startswith("!"):
                name, value = row.split(" = ", 1)
                values[(group, name)] = value
        return values

    # the variables of surfaces are comments in the line scene (a line scene refuses them):
    # their defaults are shown by the areal scene
    values, areal_values = shown_values(line), shown_values(areal)
    for v in schema.VARIABLES:
        if v.alias_of is not None or not v.echo or v.type == "reals":
            continue
        shown = values.pop((v.group, v.name))
        if v.uses == "areal":
            assert shown == "surfaces only", v.name
            shown = areal_values[(v.group, v.name)]
            if v.name == "ny":
                continue   # the areal grid's, not the schema's line default
        if shown == "not set" or v.default.startswith("`"):
            # no value of its own, or a default that depends on other variables
            assert v.default.startswith(("not set", "`")), v.name
        elif v.type == "real":
            assert float(shown) == float(v.default), v.name
        else:
            assert shown == v.default, v.name
    assert set(values) == {("material", "prony_file")}   # written when empty, a comment when set
    assert "n = 4096" in line and "! ny: surfaces only" in line and "n = 256" in areal and "ny = 256" in areal
    surfaces = {v.name for v in schema.VARIABLES if v.uses == "areal"}

    def common(text: str) -> list[str]:
        return [row for row in text.splitlines() if "geometry" not in row and " n = " not in row
                and row.strip().lstrip("! ").split(" ")[0].rstrip(":") not in surfaces]

    assert common(line) == common(areal)
    # a default scene has no load: it is refused as it is, and runs with one
    nml = tmp_path / "defaults.nml"
    nml.write_text(line)
    with pytest.raises(lc.InputError, match="exactly one of them with control = 'load'"):
        lc.check_scene_file(nml)
    nml.write_text(line.replace("! normalised_pressure: not set", "normalised_pressure = 0.5"))
    lc.check_scene_file(nml)


def test_the_python_keywords_are_scene_variables():
    """The keywords of solve_line and solve_areal are the schema's variables by their /input
    names (method and progress stand for solver_method and verbose; material for the
    &material law); the sweep's parameters too."""
    import inspect

    for function in (lc.solve_line, lc.solve_areal):
        names = [p.name for p in inspect.signature(function).parameters.values() if p.kind == p.KEYWORD_ONLY]
        assert set(names) - {"material", "method", "progress"} <= set(schema.by_key()), function
    assert list(lc.sweep.__globals__["PARAMETERS"]) == [
        "friction", "normalised_pressure", "mean_pressure", "thickness", "poisson", "speed", "hurst", "n", "seed",
        "substrate_young"]


def _outside(variable) -> list[str]:
    """Values just outside a variable's interval (as namelist text), or a word not among
    its choices."""
    if variable.choices is not None:
        return ["'none_of_them'"]
    bounds = [part.strip() for part in variable.interval[1:-1].split(",")]
    closed = (variable.interval[0] == "[", variable.interval[-1] == "]")
    values = []
    for bound, is_closed, step in ((bounds[0], closed[0], -1), (bounds[1], closed[1], 1)):
        if bound == "inf":
            if not is_closed:
                values.append("Inf")
        elif not is_closed:
            values.append(bound)   # an open end is itself outside
        elif variable.type == "integer":
            values.append(str(int(float(bound)) + step))
        else:
            x = float(bound)
            values.append(repr(x + step * abs(x) * 1e-9) if x else repr(step * 1e-300))
    return values


@pytest.mark.parametrize("variable", [v for v in schema.VARIABLES if v.interval or v.choices],
                         ids=lambda v: v.name)
def test_values_outside_the_schemas_range_are_refused(variable, tmp_path):
    """Each variable with an interval or a list of words in the schema: a value just outside
    is refused with the schema's `allowed` text and the exit code of bad input."""
    nml = tmp_path / "scene.nml"
    load = "&loading normalised_pressure = 0.5 /\n" if variable.group != "loading" else ""
    values = _outside(variable)
    assert values
    # (a variable of surfaces is checked in an areal scene: a line scene refuses it whatever its value)
    areal = variable.uses == "areal"
    scene = "&scene geometry = 'areal' n = 16 /\n" if areal and variable.group != "scene" else ""
    given = "geometry = 'areal' " if areal and variable.group == "scene" else ""
    for value in values:
        nml.write_text(f"{load}{scene}&{variable.group} {given}{variable.name} = {value} /\n")
        with pytest.raises(lc.InputError) as err:
            lc.check_scene_file(nml)
        assert f"&{variable.group}: {variable.name} = " in str(err.value), (value, str(err.value))
        assert str(err.value).endswith(f"is not allowed; allowed: {variable.allowed}"), value
        assert err.value.code == 2


def test_defaults_of_an_unknown_geometry_are_a_usage_error():
    done = subprocess.run([EXECUTABLE, "--defaults", "sphere"], capture_output=True, text=True)
    assert done.returncode == 1 and "--defaults takes 'line' (the default) or 'areal', not 'sphere'" in done.stderr
    done = subprocess.run([EXECUTABLE, "scene.nml", "areal"], capture_output=True, text=True)
    assert done.returncode == 1 and done.stderr.startswith("usage: layercontact FILE.nml")
    with pytest.raises(ValueError, match="allowed: 'line' or 'areal'"):
        lc.default_scene("sphere")
