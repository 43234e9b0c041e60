"""A result file is complete or absent (docs/output.md), on a full disk too: the program
exits 4 with a message naming the result file and its full file system, the result that
was there stays byte for byte, no temporary file is left and nothing crashes at exit; the
same from ``lc.run`` (a LayercontactError with code 4, and a Python process that goes on
and ends cleanly).

The disk is a 2 MB tmpfs that the tests mount (root on Linux). Where mounting is not
permitted they are skipped, saying why; in CI (CI=true) that is a failure."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import pytest

from test_inputs import executable

#: An areal scene of n x n points whose result file (about 115 kB at n = 32, 4 MB at
#: n = 256 with its stress maps) is written to FILE.
SCENE = """\
&scene
   geometry = 'areal'
   n = {n}
/
&layer
   thickness = 0.1
   poisson = 0.5
/
&friction
   coefficient = 0.5
/
&profile
   kind = 'self_affine'
   hurst = 0.8
   seed = 1
   short_wavelength = 0.125
   rms_gradient = 0.1
/
&loading
   normalised_pressure = 0.15
/
&output
   file = '{file}'
   overwrite = .true.
/
"""


@pytest.fixture
def small_disk():
    """A 2 MB tmpfs mounted on a fresh directory; unmounted afterwards."""
    def unavailable(reason: str):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"the full-disk tests need a small tmpfs: {reason}", pytrace=False)
        pytest.skip(f"the full-disk tests need a small tmpfs: {reason}")

    if not sys.platform.startswith("linux"):
        unavailable("tmpfs is Linux's")
    mount_point = Path(tempfile.mkdtemp(prefix="lc-full-disk-"))
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount_point)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        mount_point.rmdir()
        unavailable(f"mounting one is not permitted here ({mounted.stderr.strip() or 'mount failed'})")
    try:
        yield mount_point
    finally:
        subprocess.run(["umount", str(mount_point)], capture_output=True)
        mount_point.rmdir()


def scene_file(directory: Path, name: str, n: int, result: Path) -> Path:
    path = directory / f"{name}.nml"
    path.write_text(SCENE.format(n=n, file=result))
    return path


def fill(disk: Path, leave: int) -> None:
    """Fill ``disk`` up to ``leave`` free bytes (a file ``filler``)."""
    (disk / "filler").unlink(missing_ok=True)
    info = os.statvfs(disk)
    (disk / "filler").write_bytes(b"\0" * max(0, info.f_bavail * info.f_frsize - leave))


def leftovers(disk: Path) -> list[str]:
    return sorted(p.name for p in disk.iterdir() if p.name.endswith(".tmp"))


def test_a_full_disk_keeps_the_previous_result_and_exits_4(small_disk, tmp_path):
    result = small_disk / "out.h5"
    first = subprocess.run([executable(), str(scene_file(tmp_path, "small", 32, result))],
                           capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    before = result.read_bytes()

    # the same scene on a finer grid: its result does not fit in what is left
    second = subprocess.run([executable(), str(scene_file(tmp_path, "large", 256, result))],
                            capture_output=True, text=True, timeout=300)
    assert second.returncode == 4, second.stderr
    assert f"cannot write result file '{result}'" in second.stderr
    assert "its file system is full" in second.stderr
    assert "the file that was there is kept" in second.stderr
    assert "Segmentation" not in second.stderr
    assert "result file" not in second.stdout   # no summary of a result that is not there
    assert result.read_bytes() == before
    assert leftovers(small_disk) == []


def test_the_disk_filling_up_at_any_point_of_the_write_leaves_a_complete_result_or_none(small_disk, tmp_path):
    """The free space ends at 13 points from before the file's creation to past its end
    (its data, then the metadata HDF5 writes when it closes): every run exits 0 with a
    complete result or 4 with none, and none crashes."""
    result = small_disk / "out.h5"
    nml = scene_file(tmp_path, "small", 32, result)
    probe = subprocess.run([executable(), str(nml)], capture_output=True, text=True, timeout=300)
    assert probe.returncode == 0, probe.stderr
    size = result.stat().st_size
    result.unlink()
    codes = {}
    for leave in [0, 4096] + [size * k // 10 for k in range(1, 11)] + [2 * size]:
        fill(small_disk, leave)
        run = subprocess.run([executable(), str(nml)], capture_output=True, text=True, timeout=300)
        codes[leave] = run.returncode
        assert run.returncode in (0, 4), f"free {leave} bytes: exit {run.returncode}\n{run.stderr}"
        assert leftovers(small_disk) == [], f"free {leave} bytes"
        if run.returncode == 0:
            with h5py.File(result, "r") as f:
                assert f["fields/pressure"].shape == (32, 32)
            result.unlink()
        else:
            assert not result.exists()
            assert f"cannot write result file '{result}'" in run.stderr
    assert codes[0] == 4 and codes[2 * size] == 0


def test_python_raises_on_a_full_disk_and_ends_cleanly(small_disk, tmp_path):
    """In one Python process: a result written, the same file refused on a full disk
    (LayercontactError, code 4, the old file kept), then another scene solved; the process
    ends with exit 0 (no crash at exit)."""
    result = small_disk / "out.h5"
    small = scene_file(tmp_path, "small", 32, result)
    large = scene_file(tmp_path, "large", 256, result)
    elsewhere = scene_file(tmp_path, "elsewhere", 32, tmp_path / "elsewhere.h5")
    script = f"""
import layercontact as lc
first = lc.run({str(small)!r})
before = open({str(result)!r}, "rb").read()
try:
    lc.run({str(large)!r})
except lc.LayercontactError as err:
    assert err.code == 4, err.code
    assert "its file system is full" in str(err), err
    print("refused:", err)
else:
    raise SystemExit("a result that does not fit was written")
assert open({str(result)!r}, "rb").read() == before
again = lc.run({str(elsewhere)!r})
assert again.contact_fraction == first.contact_fraction
print("done")
"""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "refused: cannot write result file" in run.stdout and run.stdout.rstrip().endswith("done")
    assert leftovers(small_disk) == []
