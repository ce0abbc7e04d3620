"""twin modes: the shaft reference from any tachometer kind, several sensors, JSON, plot, CLI."""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.cli import main
from twin.errors import MeasurementError
from twin.measurements import Record, write_measurements
from twin.modes import merge_surveys, survey_file, survey_record

FS = 12800.0


@pytest.fixture(scope="module")
def runup(runup_factory):
    return runup_factory(fs=FS, seed=0)


def _record(x, angle, **channels_units):
    channels = {"accel_pinion_casing": x, **{k: v for k, (v, _) in channels_units.items()}}
    units = {"accel_pinion_casing": "m/s2", **{k: u for k, (_, u) in channels_units.items()}}
    return channels, units


def test_encoder_speed_channel_and_pulse_tachometer_give_the_same_modes(runup):
    x, angle, truth = runup
    speed = np.gradient(angle) * FS / (2 * np.pi)
    pulses = (np.sin(angle) > 0).astype(float)
    encoder = Record("r", *_record(x, angle, encoder=(angle, "rad")), FS, tachometer="encoder", tachometer_kind="angle")
    by_speed = Record("r", *_record(x, angle, speed=(speed, "Hz")), FS)
    by_pulse = Record("r", *_record(x, angle, tacho=(pulses, "V")), FS, tachometer="tacho", tachometer_kind="pulse",
                      pulses_per_rev=1)
    results = [survey_record(r) for r in (encoder, by_speed, by_pulse)]
    for s in results:
        assert any(abs(o.order - 19.0) < 0.05 for o in s.orders)
        assert not any(abs(m.frequency - 300.0) < 2 for m in s.modes)
        for fn, _ in truth["modes"][:6]:
            assert min(abs(s.frequencies() - fn)) / fn < 0.02


def test_two_sensors_merge_into_one_list(runup):
    x, angle, _ = runup
    y = 0.5 * x + 0.01 * np.std(x) * np.random.default_rng(1).standard_normal(x.size)
    rec = Record("r", {"accel_pinion_casing": x, "accel_gear_casing": y, "encoder": angle},
                 {"accel_pinion_casing": "m/s2", "accel_gear_casing": "m/s2", "encoder": "rad"}, FS,
                 tachometer="encoder", tachometer_kind="angle")
    both = survey_record(rec)
    one = survey_record(rec, channels=["accel_pinion_casing"])
    assert both.channels == ("accel_pinion_casing", "accel_gear_casing")
    assert len(both.modes) == len(one.modes)
    assert all(set(m.evidence["channels"]) <= set(both.channels) for m in both.modes)
    assert merge_surveys([one]) is one


def test_missing_channel_is_named(runup):
    x, angle, _ = runup
    rec = Record("r", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, FS)
    with pytest.raises(MeasurementError, match="no channel 'nope'"):
        survey_record(rec, channels=["nope"])


def test_cli_table_json_and_plot(runup, tmp_path, capsys):
    x, angle, _ = runup
    h5 = tmp_path / "rig.h5"
    write_measurements([Record("runup", {"accel_pinion_casing": x, "encoder": angle},
                               {"accel_pinion_casing": "m/s2", "encoder": "rad"}, FS, nominal_speed=20.0,
                               tachometer="encoder", tachometer_kind="angle")], h5)
    assert main(["modes", str(h5), "--record", "runup", "--json", str(tmp_path / "m.json"),
                 "--plot", str(tmp_path / "m.png")]) == 0
    out = capsys.readouterr().out
    assert "structural modes" in out and "fixed non-synchronous lines" in out and "orders" in out
    data = json.loads((tmp_path / "m.json").read_text())
    assert data["record"] == "runup" and data["method"] == "runup"
    assert len(data["modes"]) == 7 and data["lines"][0]["frequency_hz"] == pytest.approx(300.0, abs=0.5)
    assert (tmp_path / "m.png").stat().st_size > 10_000
    assert survey_file(h5).frequencies().size == 7


def test_cli_bad_record_and_bad_output_path(runup, tmp_path, capsys):
    x, angle, _ = runup
    h5 = tmp_path / "rig.h5"
    write_measurements([Record("runup", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, FS)], h5)
    assert main(["modes", str(h5), "--record", "steady"]) == 2
    assert "record 'steady': no such record" in capsys.readouterr().err
    assert main(["modes", str(h5), "--json", str(tmp_path / "no" / "m.json")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_cli_surveys_several_records_together(runup, tmp_path, capsys):
    """``--record`` repeated: one survey of the structure; the high modes seen only in the second
    record (in the first, loud noise above ``cut`` buries them) join the list, each mode naming the
    records that saw it."""
    import scipy.signal as sps
    x, angle, truth = runup
    fn = [f for f, _ in truth["modes"]]
    cut = 0.5 * (fn[2] + fn[3])
    noise = np.random.default_rng(3).standard_normal(x.size) * 30 * np.std(x)
    low = x + sps.sosfiltfilt(sps.butter(8, cut, btype="highpass", fs=FS, output="sos"), noise)
    h5 = tmp_path / "rig.h5"
    records = [Record(name, {"accel_pinion_casing": sig, "encoder": angle}, {"accel_pinion_casing": "m/s2", "encoder": "rad"},
                      FS, nominal_speed=20.0, tachometer="encoder", tachometer_kind="angle")
               for name, sig in (("low", low), ("full", x))]
    write_measurements(records, h5)
    assert main(["modes", str(h5), "--record", "low", "--record", "full", "--json", str(tmp_path / "m.json")]) == 0
    data = json.loads((tmp_path / "m.json").read_text())
    assert data["record"] == ["low", "full"]
    only_low = survey_file(h5, "low").frequencies(0.3)
    both = survey_file(h5, ["low", "full"]).frequencies(0.3)
    assert not np.any(only_low > fn[3] * 1.02) and np.any(np.abs(both - fn[4]) < 0.02 * fn[4])
    by_f = {m["frequency_hz"]: m["evidence"]["records"] for m in data["modes"]}
    assert any(r == ["full"] for f, r in by_f.items() if f > cut) and any(r == ["low", "full"] for r in by_f.values())
    assert "seen in full" in capsys.readouterr().out
    assert main(["modes", str(h5), "--record", "full", "--record", "steady"]) == 2
    assert "record 'steady': no such record" in capsys.readouterr().err


def test_a_quantised_encoder_gives_the_same_survey(runup):
    x, angle, truth = runup
    counts = np.floor(angle / (2 * np.pi / 512)) * (2 * np.pi / 512)       # a 512-line encoder
    from twin.modes import smooth_counts
    smooth = smooth_counts(counts)
    assert np.all(np.diff(smooth) > 0)
    assert np.max(np.abs(smooth - angle)) < 2 * np.pi / 512
    rec = Record("r", {"accel_pinion_casing": x, "encoder": counts}, {"accel_pinion_casing": "m/s2", "encoder": "rad"},
                 FS, tachometer="encoder", tachometer_kind="angle")
    s = survey_record(rec)
    assert any(abs(o.order - 19.0) < 0.05 for o in s.orders)
    for fn, _ in truth["modes"][:6]:
        assert min(abs(s.frequencies() - fn)) / fn < 0.02


def test_hammer_tests_fitted_together_split_the_hump_of_a_close_pair(hammer_factory, tmp_path, capsys):
    """Two struck points x two sensors: every FRF shows the shaft's close pair (584, 597 Hz, alike at
    the sensors, unlike at the struck points) as one hump, which the peak survey (the default) reads
    as one mode between them; the LSCF fit of the four FRFs (opt-in) splits it into the two, with
    its evidence."""
    modes = ((584.0, 0.02), (597.0, 0.02), (900.0, 0.02), (1200.0, 0.01))
    shapes = np.array([[1.0, 0.8], [0.8, 1.0], [0.5, 0.7], [-0.6, 0.4]])
    part = np.array([[1.0, 0.8], [0.8, -1.0], [0.8, 0.6], [0.5, -0.9]])
    fs = 10_000.0
    records = []
    for r, name in enumerate(("hammer_a", "hammer_b")):
        force, ys = hammer_factory(modes, [shapes[:, o] * part[:, r] for o in range(2)], fs, 4.0, seed=r)
        records.append(Record(name, {"hammer": force, "accel_pinion_casing": ys[0], "accel_gear_casing": ys[1]},
                              {"hammer": "N", "accel_pinion_casing": "m", "accel_gear_casing": "m"}, fs))
    h5 = tmp_path / "hammer.h5"
    write_measurements(records, h5)
    names = ["hammer_a", "hammer_b"]
    pair = lambda s: [m for m in s.modes if 575 < m.frequency < 606 and m.confidence >= 0.3]   # noqa: E731
    alone = pair(survey_file(h5, names))
    together = survey_file(h5, names, lscf=True)
    assert len(alone) == 1 and 586 < alone[0].frequency < 595
    found = pair(together)
    assert len(found) == 2 and all(abs(m.frequency - fn) < 0.003 * fn for m, fn in zip(found, (584.0, 597.0)))
    assert all(m.evidence["found_by"] == "lscf" and m.evidence["records"] == names
               and m.evidence["replaces_hz"] == round(alone[0].frequency, 2) for m in found)
    assert any("1 hump(s) split into close modes" in n for n in together.notes)
    # where each isolated mode is struck hardest: |participation| 0.8 / 0.6 at 900 Hz, 0.5 / 0.9 at 1200 Hz
    struck = {round(m.frequency, -2): m.evidence["struck_db"] for m in together.modes if m.frequency > 800}
    assert struck[900.0]["hammer_a"] == 0.0 and abs(struck[900.0]["hammer_b"] - 20 * np.log10(0.6 / 0.8)) < 1.0
    assert struck[1200.0]["hammer_b"] == 0.0 and abs(struck[1200.0]["hammer_a"] - 20 * np.log10(0.5 / 0.9)) < 1.0
    assert main(["modes", str(h5), "--record", "hammer_a", "--record", "hammer_b", "--lscf"]) == 0
    printed = capsys.readouterr().out
    assert "stable pole of a poly-reference LSCF fit" in printed and "struck: hammer_a +0.0 dB, hammer_b" in printed
    assert main(["modes", str(h5), "--record", "hammer_a", "--record", "hammer_b"]) == 0
    assert "LSCF" not in capsys.readouterr().out


def test_hammer_records_that_cannot_be_read_together_say_why(hammer_factory, tmp_path):
    """Two hammer records at different sample rates: each is surveyed, the struck-point levels and
    the LSCF fit are left out with a note naming why; nothing else changes."""
    modes = ((900.0, 0.02), (1200.0, 0.01))
    records = []
    for r, (name, fs) in enumerate((("hammer_a", 10_000.0), ("hammer_b", 8_000.0))):
        force, ys = hammer_factory(modes, [np.array([1.0, 0.5])], fs, 4.0, seed=r)
        records.append(Record(name, {"hammer": force, "accel_pinion_casing": ys[0]},
                              {"hammer": "N", "accel_pinion_casing": "m"}, fs))
    h5 = tmp_path / "hammer.h5"
    write_measurements(records, h5)
    survey = survey_file(h5, ["hammer_a", "hammer_b"], lscf=True)
    assert "struck-point levels not read: their sample rates differ" in survey.notes
    assert "hammer tests not fitted together by LSCF: their sample rates differ" in survey.notes
    assert all("struck_db" not in m.evidence for m in survey.modes)
    assert np.any(np.abs(survey.frequencies(0.3) - 900.0) < 9.0) and np.any(np.abs(survey.frequencies(0.3) - 1200.0) < 12.0)
