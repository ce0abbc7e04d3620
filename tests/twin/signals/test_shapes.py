"""A mode's level and phase at each channel, from a two-channel run-up with known shapes."""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.cli import main
from twin.measurements import Record, write_measurements
from twin.modes import survey_record
from twin.signals import SignalError
from twin.signals.shapes import channel_shapes

FS = 12800.0
MODES = ((87.0, 0.02), (218.0, 0.02), (430.0, 0.015), (767.0, 0.02), (1248.0, 0.02))
#: the second channel sees each mode at this multiple of the first (0: not at all)
SECOND = (0.5, -2.0, 0.7, -0.25, 0.0)


@pytest.fixture(scope="module")
def two_channel(runup_factory):
    x, angle, truth = runup_factory(fs=FS, seed=3, modes=MODES, weights=[np.ones(len(MODES)), SECOND],
                                    noise=0.05)
    rec = Record("runup", {"accel_pinion_casing": x[0], "accel_gear_casing": x[1], "encoder": angle},
                 {"accel_pinion_casing": "m/s2", "accel_gear_casing": "m/s2", "encoder": "rad"}, FS,
                 tachometer="encoder", tachometer_kind="angle", nominal_speed=20.0)
    return rec, survey_record(rec)


def _shape_of(survey, fn):
    m = min(survey.modes, key=lambda m: abs(m.frequency - fn))
    assert abs(m.frequency - fn) / fn < 0.02
    return m.evidence["shape"]


@pytest.mark.parametrize("k", [0, 1, 2, 3])
def test_level_and_phase_of_each_mode_at_the_other_channel(two_channel, k):
    _, survey = two_channel
    shape = _shape_of(survey, MODES[k][0])
    w = SECOND[k]
    ref, other = (("accel_pinion_casing", "accel_gear_casing") if abs(w) <= 1
                  else ("accel_gear_casing", "accel_pinion_casing"))
    assert shape["reference"] == ref
    v = shape["channels"][other]
    ratio = abs(w) if abs(w) <= 1 else 1 / abs(w)
    assert v["level_db"] == pytest.approx(20 * np.log10(ratio), abs=1.0)
    assert abs(((v["phase_deg"] - (0.0 if w > 0 else 180.0)) + 180) % 360 - 180) < 10
    assert v["coherence"] > 0.9 and shape["min_coherence"] > 0.9
    assert shape["channels"][ref] == {"level_db": 0.0, "phase_deg": 0.0, "coherence": 1.0}


def test_a_channel_with_only_independent_noise_has_a_low_coherence():
    from scipy import signal as sps
    rng = np.random.default_rng(5)
    b, a = sps.iirpeak(500.0, 25.0, fs=FS)
    drive = rng.standard_normal(int(4 * FS))
    x = sps.lfilter(b, a, drive) + 0.05 * rng.standard_normal(drive.size)
    y = 0.3 * sps.lfilter(b, a, drive) + 0.05 * rng.standard_normal(drive.size)
    noise = 0.3 * np.std(x) * rng.standard_normal(drive.size)
    seen, unseen = channel_shapes([x, y], ["a", "b"], FS, [500.0, 500.0], [10.0, 10.0], nperseg=2048)
    assert seen.min_coherence > 0.95 and seen.level_db[1] == pytest.approx(20 * np.log10(0.3), abs=0.5)
    (only,) = channel_shapes([x, noise], ["a", "b"], FS, [500.0], [10.0], nperseg=2048)
    assert only.reference == "a" and only.min_coherence < 0.1
    assert np.allclose(seen.vector(), [1.0, 0.3], atol=0.03)


def test_json_table_and_plot_carry_the_shapes(two_channel, tmp_path, capsys):
    rec, _ = two_channel
    h5 = tmp_path / "rig.h5"
    write_measurements([rec], h5)
    assert main(["modes", str(h5), "--record", "runup", "--json", str(tmp_path / "m.json"),
                 "--plot", str(tmp_path / "m.png")]) == 0
    assert "shape re accel_pinion_casing: accel_gear_casing -6." in capsys.readouterr().out
    data = json.loads((tmp_path / "m.json").read_text())
    assert all("shape" in m["evidence"] for m in data["modes"])
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_one_channel_record_has_no_shape(two_channel):
    rec, _ = two_channel
    one = survey_record(rec, channels=["accel_pinion_casing"])
    assert all("shape" not in m.evidence for m in one.modes)


def test_bad_input_is_named():
    x = np.random.default_rng(0).standard_normal(4096)
    with pytest.raises(SignalError, match="one name per channel"):
        channel_shapes([x, x], ["a"], FS, [100.0], [2.0], nperseg=1024)
    with pytest.raises(SignalError, match="same length"):
        channel_shapes([x, x[:2048]], ["a", "b"], FS, [100.0], [2.0], nperseg=1024)
