"""bench/levels_rigs.py and bench/path_rigs.py: the parts that need no FMU."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from levels_rigs import main as levels_main, without_levels  # noqa: E402
from mode_losses import read_run  # noqa: E402
from path_rigs import BANDS, band_shape  # noqa: E402


def test_without_levels_takes_the_levels_out_and_puts_the_panels_back_where_the_path_started():
    calibrated = {"kx9": 1e8, "sensor_pinion.gain": 7.0, "pinion_roughness.rms": 1e-11, "gear_roughness.rms": 1e-11,
                  "process.rms": 3.0, "sensor_pinion.panel_participation[1]": 2.7,
                  "sensor_pinion.panel_participation[2]": 0.0, "sensor_gear.panel_participation[1]": 0.3,
                  "sensor_pinion.panel_frequency[1]": 2300.0}
    out = without_levels(calibrated)
    assert "sensor_pinion.gain" not in out and "process.rms" not in out and "pinion_roughness.rms" not in out
    # two sensors were given panels, so each started at 1/2; an empty slot stays empty
    assert out["sensor_pinion.panel_participation[1]"] == 0.5 == out["sensor_gear.panel_participation[1]"]
    assert out["sensor_pinion.panel_participation[2]"] == 0.0
    assert out["kx9"] == 1e8 and out["sensor_pinion.panel_frequency[1]"] == 2300.0


def test_band_shape_is_level_free_and_reads_a_slope():
    f = np.linspace(100.0, 6399.0, 4000)
    flat, rising = np.full(f.size, 3.0), f / 1000.0           # |h| ~ f: +6 dB per octave
    assert band_shape(f, flat) == pytest.approx(np.zeros(len(BANDS)), abs=1e-9)
    shape = band_shape(f, 10 * rising)
    assert shape[BANDS.index(800)] == 0.0
    assert np.diff(shape) == pytest.approx(np.full(len(BANDS) - 1, 6.02), abs=0.3)


def test_a_directory_that_is_not_a_finished_run_is_one_line_and_exit_2(tmp_path, capsys):
    assert read_run(tmp_path) is None
    assert levels_main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err and all("not a finished calibration_rigs run" in line for line in err)
