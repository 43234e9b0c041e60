"""The README's Python example runs as written, from the repository's root, as a script
(so that its sweep, behind the __main__ guard, runs too)."""

import re
import shutil
import subprocess
import sys

from conftest import ROOT


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
