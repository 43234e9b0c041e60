"""The compiled core in use (``core``): the x86-64-v3 build (AVX2, FMA; 6-37 % faster,
bench/builds.py) where the processor runs it and the package has it, else the portable
build (``portable``). The two agree to rounding, not bit for bit: set
``LAYERCONTACT_ISA=baseline`` in the environment for the portable build everywhere
(results identical across x86-64 machines). ``BUILD`` names the instruction set of the
core in use; result files record it (``layercontact_build``)."""

from __future__ import annotations

import os

from . import _core as portable

core = portable
_choice = os.environ.get("LAYERCONTACT_ISA", "auto")
if _choice not in ("auto", "baseline"):
    raise ValueError(f"LAYERCONTACT_ISA = {_choice!r} is not allowed; allowed: 'auto', 'baseline'")
if _choice == "auto" and portable.py_cpu_level()[0] >= 3:
    try:
        from . import _core_v3 as core  # noqa: F811 (the faster build replaces the portable one)
    except ImportError:  # built without it (meson option x86_64_v3, or not x86-64)
        pass

BUILD = core.py_cpu_level()[1].decode().strip()
