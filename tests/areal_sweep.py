"""A small areal sweep file for the tests of sweeps whose scenes run on several MPI ranks
(`--ranks-per-scene`): 16 x 16 points, so that each of 2 ranks holds 8 rows."""

from __future__ import annotations

from pathlib import Path

#: the scene: a self-affine surface on a thin incompressible layer under a light load
AREAL_BASE = """\
&scene
   geometry = 'areal'
   n = 16
/
&layer
   thickness = 0.2
   poisson = 0.5
/
&profile
   kind = 'self_affine'
   short_wavelength = 0.25
   rms_gradient = 0.1
/
&loading
   normalised_pressure = 0.2
/
"""


def write_areal_sweep(directory: Path, settings: str = "", name: str = "a") -> Path:
    """The sweep file NAME.nml in ``directory``: two seeds into out/NAME, with ``settings``
    added to its &sweep group."""
    path = directory / f"{name}.nml"
    path.write_text(AREAL_BASE + f"&sweep\n directory = 'out/{name}'\n seed = 1, 2\n{settings}/\n")
    return path
