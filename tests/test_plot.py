"""Pictures of results without solving again: `lc.plot_result` of a line and of an areal
result (file or object), `lc.plot_sweep` of a sweep's summary, and `python -m layercontact
plot`. The data a figure plots is read back from its artists and compared with the file's,
and a sweep's error bars with means and standard errors computed here from the summary."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import h5py
import matplotlib
import numpy as np
import pytest

import layercontact as lc

matplotlib.use("Agg")

LINE = """\
&scene
   n = 256
/
&layer
   thickness = 0.2
/
&friction
   coefficient = 0.3
   companion = .true.
/
&profile
   short_wavelength = 0.0625
/
&loading
   normalised_pressure = 1.0
/
&output
   file = 'line.h5'
/
"""
AREAL = """\
&scene
   geometry = 'areal'
   nx = 32
   ny = 16
   period_y = 0.5
/
&profile
   kind = 'sinusoid'
   amplitude = 0.01
   mode = 1
   mode_y = 1
/
&loading
   normalised_pressure = 0.5
/
&output
   file = 'areal.h5'
/
"""


def run_scene(directory: Path, text: str, name: str) -> Path:
    nml = directory / f"{name}.nml"
    nml.write_text(text)
    lc.run(nml)
    return directory / f"{name}.h5"


def lines_of(ax) -> list[tuple[np.ndarray, np.ndarray]]:
    return [(np.asarray(line.get_xdata()), np.asarray(line.get_ydata())) for line in ax.get_lines()]


def test_a_line_result_is_drawn_from_its_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    h5 = run_scene(tmp_path, LINE, "line")
    fig = lc.plot_result(h5, tmp_path / "line.png")
    assert (tmp_path / "line.png").stat().st_size > 0
    top, bottom = fig.axes
    with h5py.File(h5) as f:
        x = f["profile/x"][()] / f["input"].attrs["period"]
        r = f["profile/height"][()]
        runs = [(f["results"].attrs, f["fields"]), (f["companion/results"].attrs, f["companion/fields"])]
        surfaces = [a["penetration"] - g["displacement_z"][()] for a, g in runs]
        pressures = [g["pressure"][()] for _, g in runs]
    (x0, indenter), *layers = lines_of(top)
    # the figure plots the file's numbers themselves: equal to the last bit
    np.testing.assert_array_equal(x0, x)
    np.testing.assert_array_equal(indenter, r.max() - r)
    for (xs, ys), expected in zip(layers, surfaces, strict=True):
        np.testing.assert_array_equal(xs, x)
        np.testing.assert_array_equal(ys, expected)
    for (xs, ys), expected in zip(lines_of(bottom), pressures, strict=True):
        np.testing.assert_array_equal(ys, expected)
    # the same from the result object
    again = lc.plot_result(lc.read_result(h5))
    np.testing.assert_array_equal(lines_of(again.axes[1])[0][1], pressures[0])


def test_an_areal_result_is_drawn_with_its_maps_and_a_profile(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    h5 = run_scene(tmp_path, AREAL, "areal")
    fig = lc.plot_result(h5)
    pressure_map, gap_map = [ax for ax in fig.axes if ax.get_images()]
    heights, pressure = [ax for ax in fig.axes if ax.get_lines()]
    with h5py.File(h5) as f:
        p = f["fields/pressure"][()]
        g = f["fields/gap"][()]
        w = f["fields/displacement_z"][()]
        r = f["profile/height"][()]
        delta = f["results"].attrs["penetration"]
    np.testing.assert_array_equal(pressure_map.get_images()[0].get_array(), p)
    shown = np.ma.filled(gap_map.get_images()[0].get_array(), np.nan)
    np.testing.assert_array_equal(shown, np.where(p > 0, np.nan, g))
    row = np.unravel_index(np.argmax(p), p.shape)[0]
    (x, indenter), (_, surface) = lines_of(heights)
    np.testing.assert_array_equal(x, np.arange(32) / 32)
    np.testing.assert_array_equal(indenter, r.max() - r[row])
    np.testing.assert_array_equal(surface, delta - w[row])
    np.testing.assert_array_equal(lines_of(pressure)[0][1], p[row])
    proc = subprocess.run([sys.executable, "-m", "layercontact", "plot", "areal.h5"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "areal.png").stat().st_size > 0


SWEEP = """\
&scene
   n = 128
/
&layer
   thickness = 0.3
/
&profile
   short_wavelength = 0.0625
/
&loading
   normalised_pressure = 1.0
/
&sweep
   directory = 'out/s'
   processes = 1
   friction = 0.0, 0.4
   normalised_pressure = 0.5, 1.0, 2.0
   realisations = 3
/
"""


def test_a_sweep_is_drawn_with_the_mean_and_standard_error_over_its_realisations(tmp_path, monkeypatch):
    """The error bars are the mean and std(ddof=1)/sqrt(3) over the three seeds of each
    (friction, load), computed here from the summary's rows one by one."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.nml").write_text(SWEEP)
    lc.sweep(tmp_path / "s.nml", processes=1, progress=False)
    summary = lc.read_summary(tmp_path / "out/s/s_summary.h5")
    proc = subprocess.run([sys.executable, "-m", "layercontact", "plot", "out/s", "-o", "sweep.png"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "sweep.png").stat().st_size > 0
    fig = lc.plot_sweep(tmp_path / "out/s")
    observables = [ax.get_ylabel() for ax in fig.axes]
    assert observables[:3] == ["contact_fraction", "delta_mu", "mean_gap"]
    for ax, observable in zip(fig.axes, observables):
        assert ax.get_xlabel() == "friction"
        bars = ax.containers
        assert len(bars) == 3   # one curve per load
        for container in bars:
            load = float(container.get_label().split("= ")[1])
            line, _, (bar,) = container.lines
            x, mean = line.get_xdata(), line.get_ydata()
            np.testing.assert_array_equal(x, [0.0, 0.4])
            for k, friction in enumerate(x):
                rows = (summary["friction"] == friction) & (summary["normalised_pressure"] == load)
                values = [float(v) for v in summary[observable][rows]]
                assert len(values) == 3
                expected_mean = sum(values) / 3
                expected_error = (sum((v - expected_mean) ** 2 for v in values) / 2) ** 0.5 / 3 ** 0.5
                # the same sums in another order: equal to rounding
                assert mean[k] == pytest.approx(expected_mean, rel=1e-12, abs=1e-300)
                low, high = bar.get_segments()[k][:, 1]
                assert (high - low) / 2 == pytest.approx(expected_error, rel=1e-9, abs=1e-300)


def test_plot_refuses_what_is_not_a_result_or_a_sweep(tmp_path):
    (tmp_path / "empty").mkdir()
    (tmp_path / "garbage.h5").write_bytes(b"not hdf5")
    for target in ("empty", "garbage.h5", "missing.h5"):
        proc = subprocess.run([sys.executable, "-m", "layercontact", "plot", target], cwd=tmp_path,
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2 and "layercontact: error:" in proc.stderr, (target, proc.stderr)
