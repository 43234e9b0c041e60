"""What every module of the package shares over the compiled core: its errors as
exceptions, its constants, and the namelist text a scene is given to it as. Private: the
public names are re-exported by the package."""

from __future__ import annotations

import numpy as np

from .native import core as _core


def _lines(text: bytes | str) -> dict[str, str]:
    """The ``name = value`` lines of a text from the library, as text values by name."""
    text = text.decode() if isinstance(text, bytes) else str(text)
    pairs = (line.split(" = ", 1) for line in text.splitlines() if " = " in line)
    return {name.strip(): value.strip() for name, value in pairs}


_CONSTANTS = _lines(_core.py_constants())
# The library's "not given" (lc_scene's not_set): a value nobody types.
NOT_SET = float(_CONSTANTS["not_set"])
# Residuals returned per solve (the last ones): a max_iter-long array would cost more than
# a small solve.
HISTORY_CAPACITY = 10000


class LayercontactError(RuntimeError):
    """An error reported by the Fortran library. ``code`` is the executable's exit code
    for it (2 bad input, 4 I/O, 5 internal)."""

    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


class InputError(LayercontactError, ValueError):
    """Bad input (code 2): a value the library does not allow. The message is the one a
    namelist file with that value gets: it names the group, the variable, the value and
    the allowed range."""


def _check(stat: int, errmsg: bytes | str) -> None:
    if stat != 0:
        text = errmsg.decode() if isinstance(errmsg, bytes) else str(errmsg)
        raise (InputError if int(stat) == 2 else LayercontactError)(text.strip(), int(stat))


def _namelist_value(value) -> str:
    """A Python value as a namelist value (reals with all the digits of a double)."""
    if isinstance(value, (bool, np.bool_)):
        return ".true." if value else ".false."
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return "NaN" if x != x else {float("inf"): "Inf", -float("inf"): "-Inf"}.get(x, repr(x))
    if isinstance(value, str):
        return "'" + value.replace("'", "''") + "'"
    # a few values a line: long arrays (Prony terms) stay readable
    items = [_namelist_value(v) for v in value]
    return ",\n   ".join(", ".join(items[i:i + 4]) for i in range(0, len(items), 4))


def _namelist(groups: dict[str, dict]) -> str:
    """Namelist text of the given variables, group by group; None means not given (the
    scene's default stays)."""
    text = []
    for group, variables in groups.items():
        given = [f" {name} = {_namelist_value(value)}" for name, value in variables.items() if value is not None]
        if given:
            text += [f"&{group}", *given, "/"]
    return "\n".join(text) + "\n"
