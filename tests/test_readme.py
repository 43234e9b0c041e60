"""The README's examples run as written: its Python example from the repository's root, as
a script (so that its sweep, behind the __main__ guard, runs too), and its scene file
through the executable."""

import re
import shutil
import subprocess
import sys

from conftest import ROOT
from test_inputs import executable


def test_readme_python_example_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "the README has no Python example"
    shutil.copytree(ROOT / "inputs", tmp_path / "inputs")
    for k, block in enumerate(blocks):
        script = tmp_path / f"readme_{k}.py"
        script.write_text(block)
        proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
                              timeout=300, env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"})
        assert proc.returncode == 0, f"README block {k} failed:\n{proc.stderr[-3000:]}"
    assert (tmp_path / "out/sweeps/example/example_summary.csv").exists()


def test_readme_scene_file_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    blocks, block = [], None   # fenced blocks, in order; block: the lines of the open one
    for line in text.splitlines():
        if line.startswith("```") and block is None:
            block = []
        elif line.startswith("```"):
            blocks.append("\n".join(block) + "\n")
            block = None
        elif block is not None:
            block.append(line)
    scenes = [b for b in blocks if b.lstrip().startswith("&scene")]
    assert len(scenes) == 1, "the README shows one scene file"
    (tmp_path / "scene.nml").write_text(scenes[0])
    proc = subprocess.run([executable(), "scene.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "contact fraction" in proc.stdout and (tmp_path / "out/scene.h5").exists()


def test_python_reference_is_current():
    """docs/python.md is generated from the package's docstrings: it matches them."""
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "python_reference.py"), "--check"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
