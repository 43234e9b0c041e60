"""How the result file stores its maps (docs/output.md, 'Size and write time';
docs/decisions/020-result-writing.md): contiguous and unfiltered, shuffle + deflate for the
maps that are mostly zeros, float32 with &output precision = 'single' (scalars stay double),
and one progress line on stderr while a large file is written."""

from pathlib import Path

import h5py
import numpy as np
import pytest

from test_inputs import run_exe

SCENE = """&scene
   geometry = 'areal'
   n = {n}
/
&layer
   thickness = 0.1
/
&friction
   coefficient = 0.5
/
&profile
   kind = 'self_affine'
   short_wavelength = 0.0625
/
&loading
   normalised_pressure = 0.15
/
&output
   file = '{file}'
   {extra}
/
"""


def run(tmp_path: Path, name: str, n: int = 64, extra: str = ""):
    nml = tmp_path / f"{name}.nml"
    nml.write_text(SCENE.format(n=n, file=f"{name}.h5", extra=extra))
    return run_exe(nml, tmp_path)


def maps(f: h5py.File) -> dict[str, h5py.Dataset]:
    found = {"profile/height": f["profile/height"]}
    found.update({f"fields/{k}": f["fields"][k] for k in f["fields"]})
    return found


def test_maps_are_contiguous_except_those_mostly_zero(tmp_path):
    proc = run(tmp_path, "double")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "double.h5") as f:
        stored = maps(f)
        assert len(stored) == 10
        for name, dset in stored.items():
            values = dset[()]
            assert dset.dtype == np.float64
            if 2 * np.count_nonzero(values == 0) > values.size:
                # outside the contact (about 80 % of the cell here) pressure and shear are 0
                assert name in ("fields/pressure", "fields/shear")
                assert dset.compression == "gzip" and dset.shuffle and dset.chunks == (64, 64), name
            else:
                assert dset.compression is None and dset.chunks is None, name
        assert f["fields/pressure"].id.get_storage_size() < f["fields/gap"].id.get_storage_size() / 2


def test_single_precision_maps_are_the_double_ones_rounded(tmp_path):
    """The same scene twice: with precision = 'single' every map is float32 and equal to
    the double map rounded to float32 (numpy's cast, round to nearest: exactly), and every
    scalar of /results is the same double (the timings aside)."""
    double, single = run(tmp_path, "double"), run(tmp_path, "single", extra="precision = 'single'")
    assert double.returncode == 0 and single.returncode == 0, double.stderr + single.stderr
    with h5py.File(tmp_path / "double.h5") as d, h5py.File(tmp_path / "single.h5") as s:
        for name, dset in maps(s).items():
            assert dset.dtype == np.float32, name
            np.testing.assert_array_equal(dset[()], d[name][()].astype(np.float32), err_msg=name)
        for key, value in d["results"].attrs.items():
            if not key.endswith("_time"):   # (the timings)
                assert np.array_equal(s["results"].attrs[key], value), key
        assert s["results"].attrs["contact_fraction"].dtype == np.float64
        assert s["input"].attrs["precision"] == b"single"
        assert s["profile/x"].dtype == np.float64   # coordinates are not maps


@pytest.mark.parametrize("value", ["'half'", "'float'", "''"])
def test_a_bad_precision_is_refused(value, tmp_path):
    proc = run(tmp_path, "bad", extra=f"precision = {value}")
    assert proc.returncode == 2, proc.stderr
    assert "&output: precision = " in proc.stderr and "allowed: 'double' or 'single'" in proc.stderr
    assert not (tmp_path / "bad.h5").exists()


def test_a_large_result_says_it_is_being_written(tmp_path):
    """1024^2 cells, ten maps: 84 MB in double, above the 64 MiB from which the write
    announces itself; 64^2 stays silent."""
    small = run(tmp_path, "small")
    assert small.returncode == 0 and "writing result file" not in small.stderr
    large = run(tmp_path, "large", n=1024, extra="precision = 'double'")
    assert large.returncode == 0, large.stderr
    lines = [line for line in large.stderr.splitlines() if "writing result file" in line]
    assert lines == ["layercontact: writing result file 'large.h5' (83 MB of maps)"]
