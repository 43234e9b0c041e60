"""A seeded fuzz of the input path: a few hundred namelists made by mutating the example
scenes (characters deleted or repeated, numbers replaced by extreme or malformed values,
lines duplicated or dropped, group ends removed) run through the executable. None may
crash (a runtime error or a signal), hang, or write a result when it fails; every refusal
is a one-line message with the exit code of bad input, I/O or memory."""

from __future__ import annotations

import random
import re
import resource
import subprocess
from pathlib import Path

import pytest

from conftest import ROOT
from test_inputs import executable

SEED = 20261123
MUTANTS = 300
#: what a scene of the fuzz may map (grids beyond it end with exit 5, not a long solve)
ADDRESS_SPACE = 2 * 2**30
EXTREME = ["0", "-1", "1e308", "-1e308", "1e-308", "nan", "inf", "2147483647", "-2147483648", "1.5", "0.0",
           "1d400", ".true.", "'x'", "", "3*1.0", "1,2,3", "huge"]
OUTPUT = "&output\n   file = 'r.h5'\n   overwrite = .false.\n/\n"


def scenes() -> list[str]:
    """The example scenes without their &output group (the fuzz writes to r.h5)."""
    texts = []
    for path in sorted((ROOT / "inputs").glob("*.nml")):
        text = re.sub(r"(?ims)^\s*&output\b.*?^\s*/\s*$", "", path.read_text())
        texts.append(text)
    return texts


def mutate(text: str, rng: random.Random) -> str:
    lines = text.splitlines()
    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(6)
        k = rng.randrange(len(lines))
        line = lines[k]
        if kind == 0 and line:                      # delete a character
            j = rng.randrange(len(line))
            lines[k] = line[:j] + line[j + 1:]
        elif kind == 1 and line:                    # repeat a character
            j = rng.randrange(len(line))
            lines[k] = line[:j] + line[j] + line[j:]
        elif kind == 2:                             # a value replaced by an extreme or malformed one
            numbers = list(re.finditer(r"(?<==)\s*[^,!/]+", line))
            if numbers:
                m = rng.choice(numbers)
                lines[k] = line[:m.start()] + " " + rng.choice(EXTREME) + line[m.end():]
        elif kind == 3:                             # a line duplicated
            lines.insert(k, line)
        elif kind == 4:                             # a line dropped
            del lines[k]
        else:                                       # a group's end removed
            ends = [j for j, text_line in enumerate(lines) if text_line.strip() == "/"]
            if ends:
                del lines[rng.choice(ends)]
        if not lines:
            lines = [""]
    return "\n".join(lines) + "\n"


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


@pytest.mark.parametrize("batch", range(3))
def test_mutated_namelists_never_crash_hang_or_write_on_failure(batch, tmp_path):
    rng = random.Random(SEED + batch)
    bases = scenes()
    outcomes: dict[int, int] = {}
    for k in range(MUTANTS // 3):
        text = mutate(rng.choice(bases), rng) + OUTPUT
        case = tmp_path / f"case{k}"
        case.mkdir()
        (case / "scene.nml").write_text(text)
        try:
            proc = subprocess.run([executable(), "scene.nml"], cwd=case, capture_output=True, text=True,
                                  timeout=60, preexec_fn=limit_memory)
        except subprocess.TimeoutExpired:
            pytest.fail(f"hangs (60 s):\n{text}")
        where = f"exit {proc.returncode}:\n{text}\n{proc.stderr[-2000:]}"
        outcomes[proc.returncode] = outcomes.get(proc.returncode, 0) + 1
        assert proc.returncode in (0, 2, 3, 4, 5), where          # no runtime error (1), no signal (< 0)
        assert "Backtrace" not in proc.stderr and "Error termination" not in proc.stderr, where
        if proc.returncode in (0, 3):
            assert (case / "r.h5").exists(), where
        else:
            assert not (case / "r.h5").exists(), where
            assert proc.stderr.startswith("layercontact: error: ") and proc.stderr.count("\n") == 1, where
        assert not list(case.rglob("*.tmp")), where
    # the fuzz reaches both sides: scenes that run and scenes that are refused
    assert outcomes.get(2, 0) > 0 and outcomes.get(0, 0) + outcomes.get(3, 0) > 0, outcomes
