"""layercontact: sliding contact of rough rigid surfaces on thin elastic layers with
Coulomb friction, by the Green's function (Fourier multiplier) method.

Sign convention P (see docs/theory.md): ``x`` is the sliding direction of the indenter, ``z``
points into the layer, ``p > 0`` is compressive, ``w = u_z > 0`` is indentation and the
friction traction on the layer is ``tau = +mu_c p``.
"""

from .api import (
    ArealResult,
    InputError,
    LayercontactError,
    LineResult,
    PeriodicityWarning,
    check_scene_file,
    choose_resolution,
    contact_conductance,
    default_scene,
    layer_multipliers,
    layer_multipliers_lapack,
    read_result,
    run,
    scene_namelist,
    solve_areal,
    solve_line,
    surface_fields,
    surface_stress,
    surface_tensor,
)
from .leakage import CoreLeakage, LeakageResult, core_leakage, reynolds_leakage
from .materials import Prony, StandardLinearSolid, creep_compliance
from .native import BUILD
from .plot import plot_result, plot_sweep
from . import scene_schema
from .profiles import (
    load_profile,
    load_surface,
    periodicity_mismatch,
    prepare_heights,
    read_profile,
    read_surface,
    self_affine_profile,
    self_affine_surface,
    sinusoid_profile,
    sinusoid_surface,
    spherical_cap,
)
from .sweeps.sweep import read_summary, sweep
from .topography import Topography, read_topography, write_height_file

__all__ = [
    "ArealResult",
    "BUILD",
    "CoreLeakage",
    "Prony",
    "StandardLinearSolid",
    "creep_compliance",
    "InputError",
    "LayercontactError",
    "LeakageResult",
    "LineResult",
    "PeriodicityWarning",
    "check_scene_file",
    "choose_resolution",
    "contact_conductance",
    "core_leakage",
    "default_scene",
    "layer_multipliers",
    "layer_multipliers_lapack",
    "load_profile",
    "load_surface",
    "periodicity_mismatch",
    "plot_result",
    "plot_sweep",
    "prepare_heights",
    "read_profile",
    "read_surface",
    "read_topography",
    "read_result",
    "read_summary",
    "reynolds_leakage",
    "run",
    "scene_namelist",
    "self_affine_profile",
    "self_affine_surface",
    "sinusoid_profile",
    "sinusoid_surface",
    "solve_areal",
    "solve_line",
    "spherical_cap",
    "sweep",
    "surface_fields",
    "surface_stress",
    "surface_tensor",
    "Topography",
    "write_height_file",
]
__version__ = "0.1.0"
