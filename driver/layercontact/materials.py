"""Viscoelastic material laws for steady sliding (seed Eqs. 12-15).

A law gives the complex creep compliance ``J*(k)`` of seed Eq. (14) at the sliding
frequency ``omega = k V`` (``J*(k) = J(0+) + int_0^inf J'(t) exp(i k V t) dt``); the
library multiplies the elastic layer multipliers by it. Poisson's ratio stays constant.
Moduli in the stress unit S, times in the time unit T of the sliding speed (L/T).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from .native import core as _core

_FORMS = {"relaxation": 0, "creep": 1}
#: Largest number of Prony terms (the library's max_prony_terms).
MAX_TERMS = 64


@dataclass(frozen=True)
class StandardLinearSolid:
    """Seed Eq. (15): ``J(t) = 1/E0 - (1/E0 - 1/E_inf) exp(-t/tau)``; ``e0`` the
    low-frequency (rubbery) and ``e_inf`` the high-frequency (glassy) modulus (S),
    ``tau`` the retardation (creep) time (T). The loss of the modulus peaks at
    ``omega tau = e_inf/e0``."""

    e0: float
    e_inf: float
    tau: float

    def _codes(self):
        return 1, 0, float(self.e0), float(self.e_inf), float(self.tau), -1.0, np.ones(1), np.ones(1)


@dataclass(frozen=True)
class Prony:
    """A Prony series. ``form='relaxation'``: ``E(t) = equilibrium + sum values_i
    exp(-t/times_i)`` (moduli, S); ``form='creep'``: ``J(t) = equilibrium + sum values_i
    (1 - exp(-t/times_i))`` (compliances, 1/S). ``times`` (T) increasing, all positive."""

    times: tuple[float, ...]
    values: tuple[float, ...]
    equilibrium: float
    form: str = "relaxation"
    source: str = field(default="", compare=False)

    def __post_init__(self):
        if self.form not in _FORMS:
            raise ValueError(f"&material: prony_form = {self.form!r} is not allowed; allowed: {sorted(_FORMS)}")
        object.__setattr__(self, "times", tuple(float(t) for t in np.atleast_1d(self.times)))
        object.__setattr__(self, "values", tuple(float(v) for v in np.atleast_1d(self.values)))
        if not 1 <= len(self.times) <= MAX_TERMS or len(self.times) != len(self.values):
            raise ValueError(f"&material: prony_times/prony_values = {len(self.times)} times, {len(self.values)} "
                             f"values is not allowed; allowed: the same number, 1 to {MAX_TERMS}")

    @classmethod
    def from_file(cls, path: str | os.PathLike, equilibrium: float, form: str = "relaxation") -> "Prony":
        """Terms from a text file of two columns ``tau_i value_i`` ('#' comments)."""
        data = np.loadtxt(path, comments=("#", "!"), ndmin=2)
        if data.shape[1] != 2:
            raise ValueError(f"{path}: expected two columns 'tau_i value_i', got {data.shape[1]}")
        return cls(tuple(data[:, 0]), tuple(data[:, 1]), equilibrium, form, source=os.fspath(path))

    def _codes(self):
        times = np.asarray(self.times, dtype=np.float64)
        values = np.asarray(self.values, dtype=np.float64)
        return 2, _FORMS[self.form], -1.0, -1.0, -1.0, float(self.equilibrium), times, values


def material_codes(material, young: float):
    """(model, form, young, e0, e_inf, tau, equilibrium, times, values) for the wrappers."""
    if material is None:
        return 0, 0, float(young), -1.0, -1.0, -1.0, -1.0, np.ones(1), np.ones(1)
    model, form, e0, e_inf, tau, eq, times, values = material._codes()
    return model, form, float(young), e0, e_inf, tau, eq, times, values


def creep_compliance(material, omega) -> np.ndarray:
    """``J*(k)`` of seed Eq. (14) at ``omega = k V`` (1/S), vectorised over ``omega``."""
    from .api import _check

    w = np.ascontiguousarray(np.atleast_1d(np.asarray(omega, dtype=np.float64)))
    model, form, young, e0, e_inf, tau, eq, times, values = material_codes(material, 1.0)
    j, stat, errmsg = _core.py_creep_compliance(w, model, form, young, e0, e_inf, tau, eq, times, values)
    _check(stat, errmsg)
    return j
