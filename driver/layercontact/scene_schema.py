"""The scene schema: one table of every namelist variable.

Each row names a variable's group and name, its type, default, unit, allowed values, which
contacts use it (lines, surfaces or both: a line scene refuses the variables of surfaces) and
its meaning, and where it lives:

- ``fortran``: the component of ``scene_type`` (``lc_scene``) that holds it;
- ``key``: its name as an attribute of the result file's ``/input`` and as a keyword of
  :func:`keyword_groups` (the name of the variable, made unique across groups:
  ``&profile file`` is ``profile_file``, ``&output file`` is ``output_file``);
- ``sweep``: its position in the product of a ``&sweep`` (None: not a sweep parameter);
- ``unset``: the Fortran value that marks "not given" (None: the variable always has a
  value); a variable that is not given is absent from ``/input``;
- ``alias_of``: another name of that variable (``period_x`` for ``period``; a scene that
  gives both is refused);
- ``read``: ``'copy'`` (the reader copies it between the scene and the namelist) or
  ``'hook'`` (the group's hand-written hooks in ``lc_io_namelist`` set it up and take it
  over: the grid's variables); lists always go through the hooks;
- ``interval`` (numbers) or ``choices`` (words): the values allowed whatever the other
  variables, checked by ``check_scene`` (``lc_scene``) with ``allowed`` as the message:
  ``'(0, inf)'`` is ``> 0 and finite``, ``'(0, inf]'`` admits ``Inf``, ``'[a, b]'``
  includes both ends; a variable that is not set is not checked. Ranges that depend on
  other variables stay code there;
- ``echo``: False for a variable whose values the scene holds under other names (a Prony
  file's terms): the scene written back as text gives those, and this one as a comment.

From this table come, at build time, the Fortran namelist group readers, the lists of
allowed variables in messages, the checks of ``interval`` and ``choices``, the writer of a
scene as namelist text and the ``/input`` writer of the result file
(``tools/scene_codegen.py``); in Python the keyword groups of
:func:`layercontact.solve_line` and :func:`layercontact.solve_areal`, the sweep's parameters
(:mod:`layercontact.sweeps.sweep`); and the tables of ``docs/namelist.md``. This module is plain
data and standard-library Python: the build runs it before the package exists.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The namelist groups, in the order of a scene file.
GROUPS = ("scene", "layer", "material", "friction", "profile", "loading", "solver", "output")

#: The types of the variables: reals, integers (integer8: 64 bits), flags, words and lists
#: of reals.
TYPES = ("real", "integer", "integer8", "logical", "string", "reals")


@dataclass(frozen=True)
class Variable:
    """One namelist variable (see the module's docstring for the columns)."""

    group: str
    name: str
    type: str
    default: str
    unit: str
    uses: str
    allowed: str
    meaning: str
    fortran: str
    key: str = ""
    sweep: int | None = None
    unset: str | None = None
    alias_of: str | None = None
    echo: bool = True
    read: str = "copy"
    interval: str | None = None
    choices: tuple[str, ...] | None = None

    @property
    def result_name(self) -> str:
        """The attribute (or dataset) name in ``/input`` and the keyword of
        :func:`keyword_groups`."""
        return self.key or self.name


_NOT_SET = "not_set"

VARIABLES: tuple[Variable, ...] = (
    # &scene
    Variable("scene", "geometry", "string", "'line'", "", "both", "'line' or 'areal'",
             "a line contact or an areal (surface) contact", "scene%geometry", choices=("line", "areal")),
    Variable("scene", "title", "string", "''", "", "both", "free text", "free text, echoed", "scene%title"),
    Variable("scene", "period", "real", "1.0", "L", "both", "> 0 and finite",
             "period `lambda` along `x`, the sliding direction (also `period_x`)", "scene%period",
             read="hook", interval="(0, inf)"),
    Variable("scene", "period_x", "real", "`period`", "L", "both", "> 0 and finite",
             "the same as `period`", "scene%period", alias_of="period", read="hook"),
    Variable("scene", "period_y", "real", "`period`", "L", "areal", "> 0 and finite", "period along `y`",
             "scene%period_y", unset=_NOT_SET, interval="(0, inf)"),
    Variable("scene", "n", "integer", "`4096` (line), `256` (areal); a profile file's size", "", "both",
             "line: 8 to 2^26; areal: 4 to 65536",
             "grid points per period (line: odd allowed; areal: `nx = ny = n`); with `&profile kind = 'file'` "
             "and none of `n`, `nx`, `ny` given, the file's size (twice it with `boundary = 'mirror'`)",
             "scene%n", sweep=8, read="hook"),
    Variable("scene", "nx", "integer", "`n`", "", "areal", "4 to 65536, `nx*ny` at most 2^28",
             "grid points along `x` (the same as `n`)", "scene%n", alias_of="n", read="hook"),
    Variable("scene", "ny", "integer", "`n` (areal), 1 (line)", "", "areal",
             "4 to 65536, `nx*ny` at most 2^28",
             "grid points along `y`", "scene%ny", read="hook"),
    # &layer
    Variable("layer", "thickness", "real", "Inf", "L", "both", "> 0, or Inf for a half-space",
             "`h`; `Inf` for a half-space (the default)", "scene%thickness", sweep=4, interval="(0, inf]"),
    Variable("layer", "young", "real", "1.0", "S", "both", "> 0 and finite", "Young's modulus `E`",
             "scene%young", interval="(0, inf)"),
    Variable("layer", "poisson", "real", "0.5", "1", "both", "-1 < poisson <= 0.5", "Poisson's ratio `nu`",
             "scene%poisson", sweep=5, interval="(-1, 0.5]"),
    Variable("layer", "interface", "string", "'bonded'", "", "both", "'bonded' or 'slip'",
             "the interface below the layer (with the next layer, the substrate or the rigid base): bonded, or "
             "slipping without friction (continuous normal displacement and traction, no shear traction); "
             "a finite `thickness` only ([theory.md](theory.md#layered-stacks))", "scene%interface",
             choices=("bonded", "slip")),
    Variable("layer", "lower_thickness", "reals", "none", "L", "both",
             "up to 64 layers, each > 0 and finite; a finite `thickness` only",
             "elastic layers below the layer, from the top down: their thicknesses", "scene%lower_thickness"),
    Variable("layer", "lower_young", "reals", "none", "S", "both", "one per lower layer, each > 0 and finite",
             "Young's moduli of the lower layers", "scene%lower_young"),
    Variable("layer", "lower_poisson", "reals", "0.5 each", "1", "both",
             "none or one per lower layer, each in (-1, 0.5]", "Poisson's ratios of the lower layers",
             "scene%lower_poisson"),
    Variable("layer", "lower_tau", "reals", "none (elastic)", "T", "both",
             "none or one per lower layer, each >= 0 and finite",
             "a lower layer with `lower_tau > 0` is a standard linear solid (seed Eq. 15) of retardation time "
             "`lower_tau`, low-frequency modulus `lower_young` and high-frequency modulus `lower_e_inf`, sliding "
             "at `&material speed`; 0: elastic", "scene%lower_tau"),
    Variable("layer", "lower_e_inf", "reals", "none", "S", "both",
             "one per lower layer with lower_tau; each >= lower_young and finite",
             "high-frequency (glassy) moduli of the viscoelastic lower layers", "scene%lower_e_inf"),
    Variable("layer", "lower_interfaces", "string", "''", "", "both",
             "'' or one word 'bonded' or 'slip' per lower layer, separated by blanks or commas",
             "the interface below each lower layer, from the top down (`''`: all bonded)", "scene%lower_interfaces"),
    Variable("layer", "substrate_young", "real", "not set (a rigid base)", "S", "both",
             "> 0 and finite; a finite `thickness` only",
             "Young's modulus of an elastic half-space substrate below the layers; not set: a rigid base",
             "scene%substrate_young", sweep=10, unset=_NOT_SET, interval="(0, inf)"),
    Variable("layer", "substrate_poisson", "real", "`poisson`", "1", "both",
             "-1 < substrate_poisson <= 0.5; with substrate_young only", "Poisson's ratio of the substrate",
             "scene%substrate_poisson", unset=_NOT_SET, interval="(-1, 0.5]"),
    # &material
    Variable("material", "model", "string", "'elastic'", "", "both", "'elastic', 'sls' or 'prony'",
             "the material law: `'elastic'` (uses `young`), `'sls'` or `'prony'`", "scene%material%model",
             key="material_model"),
    Variable("material", "e0", "real", "not set", "S", "both", "> 0 and finite, e0 <= e_inf",
             "`'sls'` (seed Eq. 15): low-frequency (rubbery) modulus", "scene%material%e0", unset="-1.0_wp"),
    Variable("material", "e_inf", "real", "not set", "S", "both", ">= e0 and finite",
             "`'sls'`: high-frequency (glassy) modulus", "scene%material%e_inf", unset="-1.0_wp"),
    Variable("material", "tau", "real", "not set", "T", "both", "> 0 and finite", "`'sls'`: retardation time",
             "scene%material%tau", unset="-1.0_wp"),
    Variable("material", "speed", "real", "0.0", "L/T", "both", ">= 0 and finite",
             "sliding speed `V` (0 with `model = 'elastic'`)", "scene%speed", sweep=6, interval="[0, inf)"),
    Variable("material", "prony_form", "string", "'relaxation'", "", "both", "'relaxation' or 'creep'",
             "`'relaxation'`: `E(t) = E_r + sum E_i exp(-t/tau_i)`; `'creep'`: "
             "`J(t) = J_g + sum J_i (1 - exp(-t/tau_i))`", "scene%material%form"),
    Variable("material", "prony_equilibrium", "real", "not set", "S or 1/S", "both", "> 0 and finite",
             "`'prony'`: `E_r` (S, relaxation) or `J_g` (1/S, creep)", "scene%material%equilibrium",
             unset="-1.0_wp"),
    Variable("material", "prony_times", "reals", "none", "T", "both", "up to 64 terms, positive, increasing",
             "`'prony'`: the times `tau_i`", "scene%material%times"),
    Variable("material", "prony_values", "reals", "none", "S or 1/S", "both",
             "as many as prony_times, positive",
             "`'prony'`: `E_i` (S, relaxation) or `J_i` (1/S, creep)", "scene%material%values"),
    Variable("material", "prony_file", "string", "''", "", "both",
             "an existing text file; not with prony_times/prony_values",
             "or: a text file of lines `tau_i value_i` (`#` comments), relative to the working directory; "
             "the result holds the terms it gave", "scene%prony_file", echo=False),
    # &friction
    Variable("friction", "coefficient", "real", "0.0", "1", "both", "0 <= coefficient <= 10",
             "Coulomb friction coefficient `mu_c`", "scene%friction", key="friction", sweep=1,
             interval="[0, 10]"),
    Variable("friction", "companion", "logical", ".false.", "", "both", ".true. or .false.",
             "also solve the frictionless companion at the same load (for `a/a0`): the scene's load, or under "
             "displacement control the load its solve found", "scene%companion"),
    # &profile
    Variable("profile", "kind", "string", "'self_affine'", "", "both",
             "'self_affine', 'sinusoid', 'file'; areal also 'sphere'", "how the rigid profile is made",
             "scene%profile%kind", key="profile_kind"),
    Variable("profile", "hurst", "real", "0.8", "1", "both", "0 < hurst < 1",
             "self-affine: Hurst exponent `H`",
             "scene%profile%hurst", sweep=7),
    Variable("profile", "seed", "integer8", "1", "", "both", ">= 0",
             "self-affine: SplitMix64 seed (same seed, same profile in Fortran and Python)",
             "scene%profile%seed",
             sweep=9),
    Variable("profile", "rolloff_wavelength", "real", "`period`", "L", "both",
             "0 < rolloff_wavelength <= period (areal: max(period, period_y))",
             "self-affine: flat spectrum above this wavelength", "scene%profile%rolloff_wavelength",
             unset=_NOT_SET),
    Variable("profile", "short_wavelength", "real", "`period`/128", "L", "both",
             "at least 2 grid spacings, at most the period",
             "self-affine: no roughness below this wavelength", "scene%profile%short_wavelength",
             unset=_NOT_SET),
    Variable("profile", "rms_gradient", "real", "not set (then 0.1 unless rms_height is given)", "1", "both",
             "> 0 and finite; at most one of rms_gradient and rms_height",
             "self-affine: the scale as the rms gradient of the heights", "scene%profile%rms_gradient",
             unset=_NOT_SET),
    Variable("profile", "rms_height", "real", "not set", "L", "both",
             "> 0 and finite; at most one of rms_gradient and rms_height",
             "self-affine: the scale as the rms height", "scene%profile%rms_height", unset=_NOT_SET),
    Variable("profile", "amplitude", "real", "not set", "L", "both", "> 0 and finite",
             "sinusoid: `amplitude cos(2 pi mode x/lambda)`", "scene%profile%amplitude", unset=_NOT_SET),
    Variable("profile", "mode", "integer", "1", "", "both",
             "line: 1 <= mode <= (n-1)/2; areal: 0 to (nx-1)/2",
             "sinusoid: wavenumber along `x` (periods per cell)", "scene%profile%mode"),
    Variable("profile", "mode_y", "integer", "0", "", "areal", "|mode_y| <= (ny-1)/2, not 0 with mode = 0",
             "sinusoid on a surface: `amplitude cos(2 pi (mode x/period_x + mode_y y/period_y))`",
             "scene%profile%mode_y"),
    Variable("profile", "radius", "real", "not set", "L", "areal", "> 0 and finite",
             "`'sphere'`: a spherical cap of this radius, apex at the cell's centre", "scene%profile%radius",
             unset=_NOT_SET),
    Variable("profile", "file", "string", "''", "", "both", "a .h5/.hdf5, .npy or text file",
             "heights (L) from a file: `.h5`/`.hdf5` (the dataset, 1D or 2D), `.npy` (`'<f8'`, C order) or text "
             "(lines of numbers); a line: one row or one column, areal: `(ny, nx)`; see "
             "[topographies.md](topographies.md)", "scene%profile%file", key="profile_file"),
    Variable("profile", "dataset", "string", "'/profile/height'", "", "both", "a dataset of the HDF5 file",
             "file: the dataset of an HDF5 height file", "scene%profile%dataset", key="profile_dataset"),
    Variable("profile", "detrend", "string", "'auto'", "", "both",
             "'auto', 'none', 'mean', 'plane', 'curvature'; not set unless kind = 'file'",
             "file: least-squares polynomial subtracted; `'auto'`: `'none'` if `boundary = 'periodic'`, "
             "`'plane'` if `'mirror'`", "scene%profile%detrend", key="profile_detrend"),
    Variable("profile", "boundary", "string", "'periodic'", "", "both",
             "'periodic' or 'mirror'; not set unless kind = 'file'",
             "file: `'periodic'` (the file is one period) or `'mirror'` (a non-periodic patch and its mirror "
             "images: `period`, `n` are twice the patch's)", "scene%profile%boundary",
             key="profile_boundary"),
    Variable("profile", "resample", "string", "'none'", "", "both",
             "'none' or 'fourier'; not set unless kind = 'file'",
             "file: `'none'` (the file has the grid's size) or `'fourier'` (Fourier interpolation/truncation "
             "onto the grid)", "scene%profile%resample", key="profile_resample"),
    # &loading
    Variable("loading", "control", "string", "'load'", "", "both", "'load' or 'displacement'",
             "load control (give `mean_pressure` or `normalised_pressure`) or displacement control "
             "(give `penetration`)", "scene%control", choices=("load", "displacement")),
    Variable("loading", "mean_pressure", "real", "not set", "S", "both",
             "> 0 and finite; exactly one of mean_pressure and normalised_pressure with control = 'load'",
             "the mean pressure `p_m`", "scene%mean_pressure", sweep=3, unset=_NOT_SET),
    Variable("loading", "normalised_pressure", "real", "not set", "1", "both",
             "> 0 and finite; exactly one of mean_pressure and normalised_pressure with control = 'load'",
             "`p_m/p_s`, the load in the seed's pressure scale `p_s`; one rule for lines and surfaces: "
             "`p_s = E* Lambda0/lambda` (`Lambda0 = max r - mean r`, the highest summit above the mean plane), "
             "except on an areal scene on a layer: `p_s = E* h/lambda` (of the top layer on a stack); `E*` with the "
             "static modulus; "
             "`/input@normalised_pressure_scale` names the one a result used",
             "scene%normalised_pressure", sweep=2, unset=_NOT_SET),
    Variable("loading", "penetration", "real", "not set", "L", "both",
             "> 0 and finite with control = 'displacement'",
             "`Delta`, displacement control (and only then)", "scene%penetration", unset=_NOT_SET),
    # &solver
    Variable("solver", "method", "string", "'auto'", "", "both",
             "'auto', 'cg', 'gcr', 'anderson', 'gfmd', 'newton' or 'multigrid'",
             "the solver: `'auto'` chooses the methods from the scene, or one method; each is described "
             "[below the table](#solver-method)", "scene%solver%method", key="solver_method", choices=("auto", "cg",
             "gcr", "anderson", "gfmd", "newton", "multigrid")),
    Variable("solver", "tol", "real", "1e-10", "1", "both", "1e-14 <= tol <= 1e-2",
             "tolerance on the complementarity residual", "scene%solver%tol", interval="[1e-14, 1e-2]"),
    Variable("solver", "max_iter", "integer", "100000", "", "both", "1 <= max_iter <= 10000000",
             "budget of CG or GCR iterations (Anderson: all inner CG iterations together; gfmd, newton, "
             "multigrid: their steps)", "scene%solver%max_iter", interval="[1, 10000000]"),
    Variable("solver", "memory", "integer", "12", "", "both", "1 <= memory <= 100",
             "history length of GCR (directions kept) and of the Anderson mixing", "scene%solver%memory",
             interval="[1, 100]"),
    Variable("solver", "precondition", "logical", ".true.", "", "both", ".true. or .false.",
             "Fourier-preconditioned CG", "scene%solver%precondition"),
    Variable("solver", "coarse_start", "logical", ".true.", "", "both", ".true. or .false.",
             "start from the solution on the grid of every second point (recursively, down to 512)",
             "scene%solver%coarse_start"),
    Variable("solver", "gfmd_mass", "string", "'auto'", "", "both", "'auto', 'one' or 'mode'",
             "the masses of method `'gfmd'`: `'one'` for every node (the stiffest mode's stiffness), `'mode'` "
             "a mass per mode, its stiffness, on the nodes off the wall (every mode at one frequency: steps "
             "nearly flat in the grid size, two transform pairs a step), `'auto'` [below the table](#solver-method)",
             "scene%solver%gfmd_mass", choices=("auto", "one", "mode")),
    Variable("solver", "threads", "integer", "0", "", "both", "0 <= threads <= 1024",
             "threads of one solve (OpenMP loops and FFTW's threads); 0: what the job was given "
             "(`OMP_NUM_THREADS`, else `SLURM_CPUS_PER_TASK`, else the CPUs the process may run on); "
             "a build without OpenMP runs 1", "scene%solver%threads", interval="[0, 1024]"),
    Variable("solver", "target_error", "real", "not set", "1", "both",
             "1e-4 <= target_error <= 0.3 (the rule was measured for 1e-3 .. 1e-1)",
             "instead of `n` (`nx`, `ny`) and `tol`: the accuracy rule picks them (see "
             "[accuracy.md](accuracy.md)); generated rough profiles only", "scene%solver%target_error",
             unset=_NOT_SET, interval="[1e-4, 0.3]"),
    Variable("solver", "verbose", "logical", ".false.", "", "both", ".true. or .false.",
             "progress on standard error: a line per grid level solved and every 2 s within one; Python: "
             "`progress=True`", "scene%solver%verbose"),
    # &output
    Variable("output", "file", "string", "'layercontact.h5'", "", "both", "a file name",
             "result file, relative to the working directory; parent directories are created",
             "scene%output_file", key="output_file"),
    Variable("output", "overwrite", "logical", ".false.", "", "both", ".true. or .false.",
             "replace an existing result file", "scene%overwrite"),
    Variable("output", "stress", "logical", ".true.", "", "both", ".true. or .false.",
             "compute the in-plane surface fields (displacements, shear, surface stresses)", "scene%stress"),
    Variable("output", "gap_bins", "integer", "64", "", "both", "0 <= gap_bins <= 100000",
             "bins of the gap histogram (0: none)", "scene%gap_bins", interval="[0, 100000]"),
    Variable("output", "fields", "logical", ".true.", "", "both", ".true. or .false.",
             "write the maps (`/profile` and `/fields`); `.false.`: scalars, histograms, spots and patches only",
             "scene%fields"),
    Variable("output", "precision", "string", "'double'", "", "both", "'double' or 'single'",
             "the maps' storage: `'double'` (float64) or `'single'` (float32: half the size, 7 significant "
             "digits); scalars, histograms, spots and patches stay double ([output.md](output.md#size-and-write-time))",
             "scene%precision", choices=("double", "single")),
    Variable("output", "leakage", "logical", ".false.", "", "areal", ".false. with geometry = 'line'",
             "compute the Reynolds leakage of the solved gap, `k_eff` along `x` and `y` "
             "([leakage.md](leakage.md#leakage-in-the-result))", "scene%leakage"),
    Variable("output", "leakage_tol", "real", "1e-6", "1", "areal", "1e-14 <= leakage_tol <= 1e-2",
             "relative accuracy of `k_eff` (the CG's energy-error stop)", "scene%leakage_tol"),
    Variable("output", "conductance", "logical", ".false.", "", "both", ".true. or .false.",
             "compute the contact's electrical (or thermal) conductance and its normal interfacial stiffness "
             "([theory.md](theory.md#contact-conductance-and-interfacial-stiffness))", "scene%conductance"),
    Variable("output", "conductivity", "real", "1.0", "siemens/L", "both", "> 0 and finite",
             "the layer's conductivity `sigma` (S/m with L in m; thermal: W/(m K))", "scene%conductivity",
             interval="(0, inf)"),
    Variable("output", "conductance_base", "string", "'conducting'", "", "both",
             "'conducting' ('insulating' is refused: no current reaches the base)",
             "what lies under a layer: `'conducting'`, a perfect conductor held at the far potential (a half-space "
             "has none)", "scene%conductance_base", choices=("conducting", "insulating")),
)


def group_variables(group: str) -> list[Variable]:
    """The variables of one group, in the table's order."""
    return [v for v in VARIABLES if v.group == group]


def by_key() -> dict[str, Variable]:
    """The variables that hold a value of their own (no aliases), by ``/input`` name."""
    return {v.result_name: v for v in VARIABLES if v.alias_of is None}


def sweep_parameters() -> list[Variable]:
    """The variables a ``&sweep`` may list, in the order of its product (the last fastest)."""
    return sorted((v for v in VARIABLES if v.sweep is not None), key=lambda v: v.sweep)


def keyword_groups(**values) -> dict[str, dict[str, object]]:
    """Namelist groups from keywords named as ``/input`` names them (:func:`by_key`); a
    value of None is not given. Raises TypeError for a name that is not a variable."""
    table = by_key()
    unknown = sorted(set(values) - set(table))
    if unknown:
        raise TypeError(f"not scene variables: {', '.join(unknown)}; allowed: {', '.join(table)}")
    groups: dict[str, dict[str, object]] = {}
    for key, value in values.items():
        variable = table[key]
        groups.setdefault(variable.group, {})[variable.name] = value
    return groups


def input_keywords(attrs, datasets=None) -> dict[str, object]:
    """The keywords of :func:`keyword_groups` that give the scene of a result file back:
    from the attributes of its ``/input`` (and the list datasets there, e.g. the Prony terms;
    ``datasets`` maps names to arrays). Flags (1/0) become bools, byte strings text; a
    variable that is not echoed (a Prony file whose terms are given) is left out, and so are
    the variables of surfaces in a line scene's (its ``ny = 1``: a line scene refuses them)."""
    table = by_key()
    out: dict[str, object] = {}
    geometry = attrs.get("geometry", "line")
    line = (geometry.decode() if isinstance(geometry, bytes) else str(geometry)) == "line"
    for key, variable in table.items():
        source = attrs if variable.type != "reals" else (datasets or {})
        if key not in source or not variable.echo or (line and variable.uses == "areal"):
            continue
        value = source[key]
        if variable.type == "logical":
            value = bool(int(value))
        elif variable.type == "string":
            value = value.decode() if isinstance(value, bytes) else str(value)
        elif variable.type in ("integer", "integer8"):
            value = int(value)
        elif variable.type == "real":
            value = float(value)
        else:
            value = [float(x) for x in value]
        out[key] = value
    return out
