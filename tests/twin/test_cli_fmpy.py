"""twin simulate and twin import speak fmpy's command line: its option spellings, its CSV files.

Each test runs the same invocation through fmpy (its Python API or its ``fmpy`` command) and
through ``twin`` and compares the results.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from twin.cli import main

pytestmark = pytest.mark.needs_gcc
FMPY = str(Path(sys.executable).parent / "fmpy")


def _fmpy_csv(path: Path) -> np.ndarray:
    from fmpy.util import read_csv
    return read_csv(str(path))


def test_fmpy_spellings_give_fmpys_result(two_mass_fmu, tmp_path, capsys):
    args = ["--start-time", "0", "--stop-time", "1", "--output-interval", "0.01",
            "--start-values", "k12", "60", "m2", "0.4", "--output-variables", "a2", "position2",
            "--output-file", str(tmp_path / "twin.csv")]
    assert main(["simulate", str(two_mass_fmu), *args, "--no-progress"]) == 0
    proc = subprocess.run([FMPY, "simulate", str(two_mass_fmu), *args[:-1], str(tmp_path / "fmpy.csv")],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    ours, theirs = _fmpy_csv(tmp_path / "twin.csv"), _fmpy_csv(tmp_path / "fmpy.csv")
    assert ours.dtype.names == theirs.dtype.names == ("time", "a2", "position2")   # plain names: fmpy reads them
    assert np.array_equal(ours["time"], theirs["time"])
    for name in ("a2", "position2"):
        assert np.allclose(ours[name], theirs[name], rtol=1e-9, atol=1e-12 * np.abs(theirs[name]).max())
    # a start value given twice, and an odd number of words, are refused by name
    assert main(["simulate", str(two_mass_fmu), "--stop-time", "1", "--param", "k12=60",
                 "--start-values", "k12", "61", "--output", str(tmp_path / "x.csv")]) == 2
    assert "'k12' given both by --param and --start-values" in capsys.readouterr().err
    assert main(["simulate", str(two_mass_fmu), "--stop-time", "1", "--start-values", "k12",
                 "--output", str(tmp_path / "x.csv")]) == 2
    assert "--start-values takes NAME VALUE pairs" in capsys.readouterr().err


def test_input_file_in_fmpys_format(two_mass_fmu, tmp_path):
    """A force ramp and a step, applied as fmpy applies an input file (linear, set at each sample)."""
    from fmpy import simulate_fmu
    from fmpy.util import read_csv

    csv = tmp_path / "input.csv"
    csv.write_text('"time","force"\n0,0\n0.5,2.0\n0.5,-1.0\n1.0,0.5\n')
    assert main(["simulate", str(two_mass_fmu), "--stop-time", "1", "--output-interval", "0.01",
                 "--input-file", str(csv), "--output-file", str(tmp_path / "twin.csv"), "--no-progress"]) == 0
    ours = _fmpy_csv(tmp_path / "twin.csv")
    theirs = simulate_fmu(str(two_mass_fmu), stop_time=1.0, output_interval=0.01, step_size=0.01,
                          input=read_csv(str(csv)), output=["a2", "position2"])
    for name in ("a2", "position2"):
        scale = np.abs(theirs[name]).max()
        assert np.abs(ours[name] - theirs[name]).max() <= 1e-9 * scale, name
    # the input mattered: without it the outputs differ
    free = simulate_fmu(str(two_mass_fmu), stop_time=1.0, output_interval=0.01, step_size=0.01, output=["a2"])
    assert np.abs(free["a2"] - theirs["a2"]).max() > 0.1


@pytest.mark.parametrize("content, message", [
    ('"time","nope"\n0,1\n', "column(s) 'nope' name no input or tunable parameter"),
    ('"time","force"\n1,0\n0,1\n', "must be ascending"),
    ('"time","force"\n0,x\n', "could not convert string to float"),
])
def test_bad_input_files_are_refused_by_name(two_mass_fmu, tmp_path, capsys, content, message):
    csv = tmp_path / "input.csv"
    csv.write_text(content)
    assert main(["simulate", str(two_mass_fmu), "--stop-time", "1", "--input-file", str(csv),
                 "--output", str(tmp_path / "r.csv")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "r.csv").exists()


def test_show_plot_and_validate(two_mass_fmu, tmp_path, capsys):
    assert main(["simulate", str(two_mass_fmu), "--stop-time", "0.5", "--output-interval", "0.01", "--validate",
                 "--show-plot", "--output", str(tmp_path / "r.h5"), "--no-progress"]) == 0
    assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"plot of 2 channel(s) -> {tmp_path / 'r.png'}" in capsys.readouterr().out


@pytest.mark.parametrize("which", ["Ball", "two_mass"])
def test_fmpy_readme_show_plot_runs_headless(which, typecov_fmus, two_mass_fmu, tmp_path):
    """fmpy's README: `fmpy simulate BouncingBall.fmu --show-plot`, no stop time, no output file,
    as `twin simulate`, on a machine with no display: the model's default experiment, out.h5 and
    its plot in the working directory."""
    import os

    from matplotlib.image import imread

    from twin.results import read_result

    # the oscillator's 1 ms step over 10 s is sampled as fmpy does, at 16 ms, and the twin says so
    fmu, samples = (typecov_fmus[("Ball", 2)], 301) if which == "Ball" else (two_mass_fmu, 626)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MPLBACKEND"] = "Agg"
    proc = subprocess.run([str(Path(sys.executable).parent / "twin"), "simulate", str(fmu), "--show-plot"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    warned = [line for line in proc.stderr.splitlines() if "warning" in line.lower()]
    assert warned == ([] if which == "Ball" else
                      ["twin: warning: output interval 0.016 s: the model's step 0.001 s doubled to at most 1000 "
                       "intervals, as fmpy does; give --output-interval 0.001 for every step"])
    result = read_result(tmp_path / "out.h5")
    assert len(result) == samples
    assert f"plot of {len(result.signals)} channel(s) -> out.png" in proc.stdout
    png = tmp_path / "out.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = imread(png)
    assert image.shape[0] > 200 and image.shape[1] > 200 and image[..., :3].std() > 0.05   # something drawn


def test_import_an_fmpy_result_with_units_from_the_fmu(two_mass_fmu, tmp_path, capsys):
    from twin.measurements import load_measurements

    result = tmp_path / "fmpy.csv"
    proc = subprocess.run([FMPY, "simulate", str(two_mass_fmu), "--stop-time", "1", "--output-interval", "0.001",
                           "--output-file", str(result)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    # without a sidecar or the FMU the units are unknown
    assert main(["import", str(result), "--out", str(tmp_path / "m.h5")]) == 2
    assert "no sidecar with units" in capsys.readouterr().err
    assert main(["import", str(result), "--fmu", str(two_mass_fmu), "--out", str(tmp_path / "m.h5")]) == 0
    record = load_measurements(tmp_path / "m.h5")[0]
    assert record.units == {"a2": "m/s2", "position2": "m"}
    assert record.sample_rate == pytest.approx(1000.0)
    assert np.allclose(record["position2"], _fmpy_csv(result)["position2"], rtol=0, atol=0)
    bad = tmp_path / "bad.csv"
    bad.write_text('"time","mystery"\n0,1\n0.001,2\n')
    assert main(["import", str(bad), "--fmu", str(two_mass_fmu), "--out", str(tmp_path / "b.h5")]) == 2
    assert "column(s) 'mystery' name no variable of" in capsys.readouterr().err
