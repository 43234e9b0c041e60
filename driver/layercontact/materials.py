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

from ._library import _CONSTANTS, _check, _namelist
from .native import core as _core

#: Largest number of Prony terms (the library's max_prony_terms).
MAX_TERMS = int(_CONSTANTS["max_prony_terms"])


@dataclass(frozen=True)
class StandardLinearSolid:
    """Seed Eq. (15): ``J(t) = 1/E0 - (1/E0 - 1/E_inf) exp(-t/tau)``; ``e0`` the
    low-frequency (rubbery) and ``e_inf`` the high-frequency (glassy) modulus (S),
    ``tau`` the retardation (creep) time (T). The loss of the modulus peaks at
    ``omega tau = e_inf/e0``."""

    e0: float
    e_inf: float
    tau: float

    def _namelist(self) -> dict:
        """The &material variables of this law."""
        return {"model": "sls", "e0": float(self.e0), "e_inf": float(self.e_inf), "tau": float(self.tau)}


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
        object.__setattr__(self, "times", tuple(float(t) for t in np.atleast_1d(self.times)))
        object.__setattr__(self, "values", tuple(float(v) for v in np.atleast_1d(self.values)))
        # the library's checks of &material (form, number of terms, signs, order)
        # (room for one more entry than given: the library takes no empty arrays)
        room = max(len(self.times), len(self.values)) + 1
        times, values = np.zeros(room), np.zeros(room)
        times[: len(self.times)], values[: len(self.values)] = self.times, self.values
        _check(*_core.py_check_prony(str(self.form), float(self.equilibrium), len(self.times), len(self.values),
                                     times, values))

    @classmethod
    def from_file(cls, path: str | os.PathLike, equilibrium: float, form: str = "relaxation") -> "Prony":
        """Terms from a text file of two columns ``tau_i value_i`` (comments after '#' or
        '!'), read by the library's reader of ``&material prony_file``."""
        times, values, count, stat, errmsg = _core.py_read_prony_file(os.fspath(path), MAX_TERMS)
        _check(stat, errmsg)
        return cls(tuple(times[:count]), tuple(values[:count]), equilibrium, form, source=os.fspath(path))

    def _namelist(self) -> dict:
        """The &material variables of this law."""
        return {"model": "prony", "prony_form": self.form, "prony_equilibrium": float(self.equilibrium),
                "prony_times": self.times, "prony_values": self.values}


def creep_compliance(material, omega) -> np.ndarray:
    """``J*(k)`` of seed Eq. (14) at ``omega = k V`` (1/S), vectorised over ``omega``;
    ``material`` None: the elastic layer of the default ``young``."""
    w = np.ascontiguousarray(np.atleast_1d(np.asarray(omega, dtype=np.float64)))
    text = _namelist({"material": material._namelist() if material is not None else {}})
    j, stat, errmsg = _core.py_creep_compliance(text, w)
    _check(stat, errmsg)
    return j
