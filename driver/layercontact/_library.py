"""What every module of the package shares over the compiled core: its errors as
exceptions, its constants, and the namelist text a scene is given to it as. Private: the
public names are re-exported by the package."""

from __future__ import annotations

import errno
import os
import stat as _stat

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


class PeriodicityWarning(UserWarning):
    """Heights taken as one period (``&profile boundary = 'periodic'``) that jump or kink
    across the cell's edges: most likely a tilted or non-periodic measurement, which the
    solve takes as a periodic surface with a step at each edge. Set ``boundary = 'mirror'``
    (a non-periodic patch) or ``detrend = 'plane'`` (a tilt); the measure and its limits are
    :func:`layercontact.periodicity_mismatch` (docs/decisions/019)."""


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
        for name, value in variables.items():
            if isinstance(value, str) and any(ord(c) < 32 or ord(c) == 127 for c in value):
                raise InputError(f"&{group}: {name} = {value!r} is not allowed; allowed: text without control "
                                 "characters (newline, tab, ...)", 2)
        given = [f" {name} = {_namelist_value(value)}" for name, value in variables.items() if value is not None]
        if given:
            text += [f"&{group}", *given, "/"]
    return "\n".join(text) + "\n"


# The largest grid a generator or reader of the package makes: 2^30 points (8 GiB of
# heights), far above what one node solves, and below what would overflow the library's
# default integers.
MAX_POINTS = 2**30


#: The &layer keywords that say what a layer rests on (docs/theory.md, "Layered stacks"),
#: taken by every function that takes a layer.
STACK_KEYWORDS = ("interface", "lower_thickness", "lower_young", "lower_poisson", "lower_tau", "lower_e_inf",
                  "lower_interfaces", "substrate_young", "substrate_poisson")


def stack_keywords(function: str, given: dict) -> dict:
    """The stack keywords ``given`` to ``function`` as &layer variables: lists of reals for
    the lower layers' values, one blank-separated word list for ``lower_interfaces``; None
    and empty lists are not given. Another name raises TypeError, as Python does."""
    unknown = sorted(set(given) - set(STACK_KEYWORDS))
    if unknown:
        raise TypeError(f"{function}() got unexpected keyword argument(s) {', '.join(map(repr, unknown))}; "
                        f"the stack keywords are {', '.join(STACK_KEYWORDS)}")
    out = {}
    for name, value in given.items():
        if value is None:
            continue
        if name == "lower_interfaces":
            if not isinstance(value, str):
                value = " ".join(str(word) for word in value)
        elif name.startswith("lower_"):
            if np.size(value) == 0:
                continue
            value = [float(x) for x in real_array(value, name, ndim=(0, 1)).ravel()]
        out[name] = value
    return out


def _input_error(name: str, value, allowed: str) -> InputError:
    return InputError(f"{name} = {value!r} is not allowed; allowed: {allowed}", 2)


def grid_points(value, name: str) -> int:
    """A number of grid points given in Python: an integer (not a bool, not 16.7; 16.0 is
    16), else :class:`InputError` naming it. Its range is the library's to check."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer, float, np.floating)) \
            or not float(value).is_integer():
        raise _input_error(name, value, "an integer number of points")
    return int(value)


def grid_size(nx: int, ny: int) -> None:
    """Refuse a grid of more than MAX_POINTS points before anything is allocated."""
    if nx * ny > MAX_POINTS:
        raise _input_error("nx x ny", f"{nx} x {ny}", f"at most {MAX_POINTS} points (2^30)")


def periods(value, name: str = "period") -> tuple[float, float]:
    """``(lx, ly)`` from one period (both axes) or a pair; positive and finite."""
    if np.ndim(value) == 0:
        lx = ly = value
    elif np.ndim(value) == 1 and len(value) == 2:
        lx, ly = value
    else:
        raise _input_error(name, value, "a positive length, or a pair (lx, ly) of them")
    try:
        lx, ly = float(lx), float(ly)
    except (TypeError, ValueError):
        raise _input_error(name, value, "a positive length, or a pair (lx, ly) of them") from None
    if not (lx > 0 and ly > 0 and np.isfinite(lx) and np.isfinite(ly)):
        raise _input_error(name, value, "positive, finite lengths")
    return lx, ly


def real_array(value, name: str, *, ndim: tuple[int, ...], finite: bool = True) -> np.ndarray:
    """A float64 array of real numbers given in Python: complex, boolean and non-numeric
    arrays are refused (rather than losing an imaginary part or taking True as 1), and so
    are NaN and infinite values where ``finite``; :class:`InputError` names it."""
    raw = np.asarray(value)
    if raw.dtype.kind not in "iuf":
        kind = {"c": "complex", "b": "boolean"}.get(raw.dtype.kind, f"of dtype {raw.dtype}")
        raise InputError(f"{name}: a {kind} array is not allowed; allowed: real numbers", 2)
    if raw.ndim not in ndim or raw.size == 0:
        shapes = " or ".join(f"{d}D" for d in ndim)
        raise InputError(f"{name}: an array of shape {raw.shape} is not allowed; allowed: a non-empty {shapes} array",
                         2)
    out = raw.astype(np.float64)
    if finite and not np.all(np.isfinite(out)):
        bad = int(np.count_nonzero(~np.isfinite(out)))
        raise InputError(f"{name}: {bad} NaN or infinite values are not allowed; allowed: finite values", 2)
    return out


def regular_file(filename: str | os.PathLike, what: str) -> str:
    """``filename`` as a string, refused (:class:`InputError`, code 2) when it names
    something other than a regular file: a FIFO would block the read until a writer comes,
    a directory or a device holds no input, a loop of symbolic links names nothing. A missing
    file passes (its reader says so)."""
    path = os.fspath(filename)
    try:
        mode = os.stat(path).st_mode
    except OSError as err:
        if err.errno == errno.ELOOP:
            raise InputError(f"{what} '{path}' is a loop of symbolic links; allowed: a regular file", 2) from None
        return path
    if not _stat.S_ISREG(mode):
        kind = ("a directory" if _stat.S_ISDIR(mode) else "a FIFO (named pipe)" if _stat.S_ISFIFO(mode)
                else "a device" if _stat.S_ISCHR(mode) or _stat.S_ISBLK(mode)
                else "a socket" if _stat.S_ISSOCK(mode) else "not a regular file")
        raise InputError(f"{what} '{path}' is {kind}; allowed: a regular file", 2)
    return path


def contact_map(value, name: str) -> np.ndarray:
    """A contact map given in Python: a non-empty 1D or 2D array of booleans, or of the
    numbers 0 and 1 (a NaN, a 0.5 or a -1 is not a contact map), as int8 (1 in contact);
    :class:`InputError` names it."""
    raw = np.asarray(value)
    if raw.ndim not in (1, 2) or raw.size == 0 or min(raw.shape) < 2:
        raise InputError(f"{name}: an array of shape {raw.shape} is not allowed; allowed: a 1D or 2D array of at "
                         "least 2 points along each axis", 2)
    if raw.dtype.kind == "b":
        return raw.astype(np.int8)
    if raw.dtype.kind not in "iuf":
        raise InputError(f"{name}: an array of dtype {raw.dtype} is not allowed; allowed: booleans, or 0 and 1", 2)
    bad = ~((raw == 0) | (raw == 1))
    if np.any(bad):
        raise InputError(f"{name}: {int(np.count_nonzero(bad))} values other than 0 and 1 (e.g. "
                         f"{raw[bad].flat[0]!r}) are not allowed; allowed: booleans, or 0 and 1", 2)
    return (raw == 1).astype(np.int8)


def positive_real(value, name: str, *, infinite: bool = False) -> float:
    """A real number > 0 (finite unless ``infinite``); :class:`InputError` names it."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = float("nan")
    if isinstance(value, (bool, np.bool_)) or not (x > 0 and (infinite or np.isfinite(x))):
        raise _input_error(name, value, "> 0, or Inf" if infinite else "> 0 and finite")
    return x
