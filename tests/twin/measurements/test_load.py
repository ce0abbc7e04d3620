"""twin.measurements.load_measurements: formats, unit conversion, every validation error, resampling."""
from __future__ import annotations

import logging
import math
import types

import numpy as np
import pytest

from twin.errors import MeasurementError, ParameterError, TwinError
from twin.measurements import (ACCEPTED_UNITS, ARCHIVE_FORMAT, STANDARD_GRAVITY, MeasurementSet, Record,
                               iter_measurements, load_measurements)

FS = 10_000.0
N = 2_000


def _noisy(seed=0, n=N):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    return np.sin(2 * np.pi * 480.0 * t) + 0.3 * rng.standard_normal(n)


def _one(write_h5, path, data, unit="m/s2", **attrs):
    attrs.setdefault("sample_rate", FS)
    return write_h5(path, {"r1": {"channels": {"accel": (data, unit)}, "attrs": attrs}})


def _problems(excinfo) -> list[str]:
    return [p for _, _, p in excinfo.value.problems]


# --------------------------------------------------------------------------- happy paths

def test_hdf5_loads_with_attributes_and_g_conversion(good_h5):
    import h5py
    with h5py.File(good_h5) as f:
        raw_a = f["records/run_a/accel"][()]
    mset = load_measurements(good_h5)
    assert isinstance(mset, MeasurementSet) and len(mset) == 2 and mset.names == ("run_a", "run_b")
    a, b = mset
    assert a.units["accel"] == "m/s2" and b.units["accel"] == "m/s2"
    np.testing.assert_array_equal(a["accel"], raw_a * STANDARD_GRAVITY)
    assert STANDARD_GRAVITY == 9.80665
    assert (a.sample_rate, a.nominal_speed, a.load, a.label, a.damage) == (FS, 20.0, 20.0, 0, 0.01)
    assert (a.tachometer, a.tachometer_kind, a.pulses_per_rev) == ("tacho", "pulse", 1)
    assert a.metadata["operator"] == "rig-2" and mset.metadata["rig"] == "FZG-like"
    assert a.duration == pytest.approx(0.2) and a.n_samples == N
    assert b.time[0] == 1.5 and b.time[-1] == pytest.approx(1.5 + (N - 1) / FS)
    assert a.source == str(good_h5) and mset.notes == ()
    assert "accel" in a and "nope" not in a
    with pytest.raises(KeyError, match="no channel 'nope'"):
        a["nope"]
    assert not a["accel"].flags.writeable                       # frozen all the way down
    with pytest.raises(Exception):
        a.sample_rate = 1.0


def test_by_label_and_lookup(good_h5, write_h5, tmp_path):
    mset = load_measurements(good_h5)
    groups = mset.by_label()
    assert list(groups) == [0, 1] and groups[1][0].name == "run_b"
    assert mset["run_b"] is mset[1]
    p = write_h5(tmp_path / "u.h5", {
        "z": {"channels": {"x": (_noisy(3), "1")}, "attrs": {"sample_rate": FS, "label": 2}},
        "y": {"channels": {"x": (_noisy(4), "")}, "attrs": {"sample_rate": FS}},
        "a": {"channels": {"x": (_noisy(5), "1")}, "attrs": {"sample_rate": FS, "label": 0}},
    })
    m2 = load_measurements(p)
    assert m2.names == ("z", "y", "a")                           # stored order, not alphabetical
    assert [k for k in m2.by_label()] == [0, 2, None]
    assert m2["y"].units["x"] == "1"


def test_channel_selection_keeps_tachometer(good_h5):
    mset = load_measurements(good_h5, channels=["accel"])
    assert mset[0].channel_names == ("accel", "tacho")


def test_channel_selection_without_the_tachometer(good_h5):
    mset = load_measurements(good_h5, channels=["accel"], tachometer=False)
    assert mset[0].channel_names == ("accel",)
    assert (mset[0].tachometer, mset[0].tachometer_kind, mset[0].pulses_per_rev) == (None, None, None)
    assert np.array_equal(mset[0]["accel"], load_measurements(good_h5, channels=["accel"])[0]["accel"])
    assert load_measurements(good_h5, channels=["accel", "tacho"], tachometer=False)[0].tachometer == "tacho"
    with pytest.raises(ParameterError, match="tachometer must be True or False"):
        load_measurements(good_h5, tachometer="no")


def test_csv_with_yaml_sidecar_derives_rate(write_csv, tmp_path):
    x = _noisy(7)
    p = write_csv(tmp_path / "run.csv", {"accel": x, "force": 100 + x},
                  {"nominal_speed": 20.0, "label": 3, "units": {"accel": "g", "force": "N", "time": "s"},
                   "record": "run_017", "metadata": {"sensor": "PCB"}}, time=0.25 + np.arange(N) / FS)
    rec = load_measurements(p)[0]
    assert rec.name == "run_017" and rec.sample_rate == FS and rec.time_start == 0.25
    np.testing.assert_allclose(rec["accel"], x * 9.80665, rtol=1e-15)
    np.testing.assert_array_equal(rec["force"], 100 + x)
    assert rec.units == {"accel": "m/s2", "force": "N"} and rec.label == 3
    assert rec.metadata == {"sensor": "PCB"}


def test_csv_with_json_sidecar_and_explicit_rate(write_csv, tmp_path):
    x = _noisy(8)
    p = write_csv(tmp_path / "run.csv", {"v": x}, {"sample_rate": "10e3", "units": {"v": "m/s"}}, kind="json")
    rec = load_measurements(p)[0]
    assert rec.name == "run" and rec.sample_rate == FS and rec.units["v"] == "m/s"
    np.testing.assert_array_equal(rec["v"], x)


def test_csv_sidecar_named_after_stem_and_explicit(write_csv, tmp_path):
    p = write_csv(tmp_path / "run.csv", {"v": _noisy(9)}, None)
    (tmp_path / "run.yaml").write_text("units: {v: m/s}\n")
    assert load_measurements(p)[0].units["v"] == "m/s"
    other = tmp_path / "elsewhere.json"
    other.write_text('{"units": {"v": "m"}}')
    assert load_measurements(p, sidecar=other)[0].units["v"] == "m"
    (tmp_path / "run.csv.json").write_text('{"units": {"v": "m"}}')
    with pytest.raises(MeasurementError, match="ambiguous sidecars"):
        load_measurements(p)


def test_archive_layout_from_write_archive_loads(tmp_path):
    from twin.archive import ARCHIVE_FORMAT as ARCHIVE, Archive, write_archive
    assert ARCHIVE == ARCHIVE_FORMAT
    rng = np.random.default_rng(11)
    signals = {"accel_pinion_casing": rng.standard_normal((3, 500)).astype(np.float32),
               "pinion_speed": (125.0 + rng.standard_normal((3, 500))).astype(np.float32)}
    arc = Archive(labels=np.array([0, 0, 1]), damage=np.array([0.01, 0.02, 0.04]), speed=np.array([20.0, 20.1, 19.9]),
                  load=np.array([20.0, 21.0, 19.0]), signals=signals, sample_rate=5000.0, stages=(0.0, 0.03, 0.06),
                  damage_kind="pitting_density")
    scenario = types.SimpleNamespace(raw={"name": "tiny"}, seed=4, start_time=0.0, inputs={})
    path = write_archive(arc, tmp_path / "arc.h5", scenario)
    mset = load_measurements(path, min_duration=0.1)
    assert mset.names == ("000000", "000001", "000002")
    assert [r.label for r in mset] == [0, 0, 1]
    r = mset[2]
    assert (r.sample_rate, r.nominal_speed, r.load, r.damage) == (5000.0, 19.9, 19.0, 0.04)
    assert r.units == {"accel_pinion_casing": "m/s2", "pinion_speed": "1"}
    np.testing.assert_array_equal(r["accel_pinion_casing"], signals["accel_pinion_casing"][2].astype(np.float64))
    assert mset.metadata["damage_kind"] == "pitting_density"
    assert list(mset.metadata["stages"]) == [0.0, 0.03, 0.06]
    assert (mset.metadata["nominal_speed"], mset.metadata["nominal_load"]) == (20.0, 20.0)   # no inputs: the defaults


# --------------------------------------------------------------------------- file-level errors

def test_missing_file(tmp_path):
    with pytest.raises(MeasurementError, match="does not exist") as e:
        load_measurements(tmp_path / "nope.h5")
    assert e.value.file == str(tmp_path / "nope.h5") and e.value.record is None
    assert isinstance(e.value, TwinError)


def test_neither_hdf5_nor_csv(tmp_path):
    p = tmp_path / "notes.txt"
    p.write_text("hello")
    with pytest.raises(MeasurementError, match="neither an HDF5 file"):
        load_measurements(p)
    q = tmp_path / "fake.h5"
    q.write_text("not hdf5 at all")
    with pytest.raises(MeasurementError, match="neither an HDF5 file"):
        load_measurements(q)


def test_unknown_format_attribute(write_h5, tmp_path):
    p = write_h5(tmp_path / "f.h5", {"r": {"channels": {"x": (_noisy(), "V")}, "attrs": {"sample_rate": FS}}},
                 fmt="gear-twin-result", version=7)
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    probs = _problems(e)
    assert len(probs) == 2
    assert "unknown format 'gear-twin-result'" in probs[0] and "gear-twin-measurements" in probs[0]
    assert "format_version 7 is not supported" in probs[1]
    p2 = write_h5(tmp_path / "g.h5", {}, fmt=None)
    with pytest.raises(MeasurementError, match="no root attribute 'format'"):
        load_measurements(p2)


def test_empty_file_and_empty_records(write_h5, tmp_path):
    with pytest.raises(MeasurementError, match="holds no records"):
        load_measurements(write_h5(tmp_path / "e.h5", {}))
    p = write_h5(tmp_path / "e2.h5", {
        "nochan": {"attrs": {"sample_rate": FS}},
        "nosamples": {"channels": {"x": (np.zeros(0), "V")}, "attrs": {"sample_rate": FS}}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert [(r, p) for _, r, p in e.value.problems] == [("nochan", "empty record: no channels"),
                                                        ("nosamples", "empty record: 0 samples")]


def test_csv_without_rows_is_empty(write_csv, tmp_path):
    p = tmp_path / "e.csv"
    p.write_text("time,x\n")
    (tmp_path / "e.csv.yaml").write_text("sample_rate: 100\nunits: {x: V}\n")
    with pytest.raises(MeasurementError, match="empty record: 0 samples"):
        load_measurements(p)


def test_records_one_at_a_time_are_the_loaded_ones(good_h5, write_h5, tmp_path):
    loaded = load_measurements(good_h5, channels=["accel"], tachometer=False)
    it = iter_measurements(good_h5, channels=["accel"], tachometer=False)
    first = next(it)                                   # yielded before the rest of the file is read
    streamed = [first, *it]
    assert [r.name for r in streamed] == [r.name for r in loaded.records]
    for a, b in zip(streamed, loaded.records):
        assert np.array_equal(a["accel"], b["accel"]) and (a.sample_rate, a.label) == (b.sample_rate, b.label)
    x = _noisy()
    x[5] = np.nan
    bad = write_h5(tmp_path / "b.h5", {"r1": {"channels": {"accel": (_noisy(), "m/s2")}, "attrs": {"sample_rate": FS}},
                                       "r2": {"channels": {"accel": (x, "m/s2")}, "attrs": {"sample_rate": FS}}})
    with pytest.raises(MeasurementError) as want:
        load_measurements(bad)
    seen = []
    with pytest.raises(MeasurementError) as got:
        for r in iter_measurements(bad):
            seen.append(r.name)
    assert seen == ["r1"] and got.value.problems == want.value.problems


# --------------------------------------------------------------------------- sample errors

def test_nan_reports_channel_index_and_time(write_h5, tmp_path):
    x = _noisy()
    x[[123, 500]] = np.nan
    with pytest.raises(MeasurementError) as e:
        load_measurements(_one(write_h5, tmp_path / "n.h5", x))
    assert e.value.record == "r1"
    assert e.value.problem == "channel 'accel' has 2 non-finite samples (NaN); first at index 123 (t = 0.0123 s)"
    assert "n.h5" in str(e.value) and "r1" in str(e.value) and "index 123" in str(e.value)


def test_inf_is_reported(write_h5, tmp_path):
    x = _noisy()
    x[7] = -np.inf
    with pytest.raises(MeasurementError, match=r"1 non-finite samples \(Inf\); first at index 7"):
        load_measurements(_one(write_h5, tmp_path / "i.h5", x))


def test_csv_non_monotonic_time(write_csv, tmp_path):
    t = np.arange(N) / FS
    t[10], t[11] = t[11], t[10]
    p = write_csv(tmp_path / "m.csv", {"x": _noisy()}, {"units": {"x": "V"}}, time=t)
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert _problems(e) == [f"time is not strictly increasing: sample 11 (t = {t[11]:.9g} s) follows "
                            f"t = {t[10]:.9g} s"]


def test_csv_non_uniform_time(write_csv, tmp_path):
    t = np.arange(N) / FS
    t[50:] += 0.2 / FS                                              # one step 20 % long
    p = write_csv(tmp_path / "u.csv", {"x": _noisy()}, {"units": {"x": "V"}}, time=t)
    with pytest.raises(MeasurementError, match="time is not uniform: step before sample 50 .* 1 such steps") as e:
        load_measurements(p)
    assert len(e.value.problems) == 1              # no extra "missing sample rate" for the same cause


def test_csv_printed_with_six_decimals_is_not_uniform_enough(write_csv, tmp_path):
    p = tmp_path / "short.csv"
    p.write_text("time,x\n" + "".join(f"{i / 3e4:.6f},{math.sin(i)}\n" for i in range(50)))
    (tmp_path / "short.csv.yaml").write_text("units: {x: V}\n")
    with pytest.raises(MeasurementError, match="write time with full precision"):
        load_measurements(p)


def test_csv_sidecar_rate_must_match_time(write_csv, tmp_path):
    p = write_csv(tmp_path / "r.csv", {"x": _noisy()}, {"sample_rate": 12000, "units": {"x": "V"}})
    with pytest.raises(MeasurementError, match="sample_rate 12000 Hz disagrees with the time column"):
        load_measurements(p)


def test_csv_non_numeric_cell(write_csv, tmp_path):
    x = [repr(float(v)) for v in _noisy(n=20)]
    x[4] = "oops"
    p = write_csv(tmp_path / "c.csv", {"x": x}, {"units": {"x": "V"}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert _problems(e) == ["column 'x' has 1 non-numeric cells; first at sample 4: 'oops'"]


def test_missing_sample_rate(write_h5, write_csv, tmp_path):
    p = write_h5(tmp_path / "s.h5", {"r1": {"channels": {"x": (_noisy(), "V")}, "attrs": {"label": 1}}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert _problems(e) == ["missing sample rate: attribute 'sample_rate' [Hz] is required"]
    q = write_csv(tmp_path / "one.csv", {"x": [0.5]}, {"units": {"x": "V"}})
    with pytest.raises(MeasurementError, match="missing sample rate"):
        load_measurements(q)


def test_unknown_unit_lists_accepted(write_h5, tmp_path):
    with pytest.raises(MeasurementError) as e:
        load_measurements(_one(write_h5, tmp_path / "u.h5", _noisy(), unit="mm/s"))
    msg = e.value.problem
    assert "channel 'accel' has unknown unit 'mm/s'" in msg
    assert all(repr(u) in msg for u in ACCEPTED_UNITS)


def test_missing_unit(write_h5, write_csv, tmp_path):
    with pytest.raises(MeasurementError, match="channel 'accel' has no unit \\(attribute 'unit'\\)"):
        load_measurements(_one(write_h5, tmp_path / "m.h5", _noisy(), unit=None))
    p = write_csv(tmp_path / "m.csv", {"x": _noisy(), "y": _noisy(1)}, {"units": {"x": "V", "z": "V"}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert _problems(e) == ["sidecar 'units' names 'z', which is not a column of the CSV",
                            "channel 'y' has no unit (entry in the sidecar's 'units')"]


def test_clipping_run_reports_level_and_count(write_h5, tmp_path):
    x = _noisy()
    top = 1.2
    x = np.minimum(x, top)                                      # saturate the positive peaks
    count = int((x == top).sum())
    assert count > 5
    with pytest.raises(MeasurementError) as e:
        load_measurements(_one(write_h5, tmp_path / "c.h5", x, unit="g"))
    (msg,) = _problems(e)
    assert msg.startswith(f"channel 'accel' is clipped at its maximum 1.2 g: {count} samples")


def test_clipping_by_fraction_without_runs(write_h5, tmp_path):
    x = _noisy(n=10_000)
    lo = x.min() - 0.5                                          # a level no sample had
    idx = np.arange(100, 10_000, 400)                           # 25 isolated samples = 0.25 %
    x[idx] = lo
    with pytest.raises(MeasurementError, match=r"clipped at its minimum .* 25 samples \(0.25 %\) .* longest run 1"):
        load_measurements(_one(write_h5, tmp_path / "f.h5", x))
    x[idx[:9]] = 0.0                                            # 16 = 0.16 %: still clipped
    with pytest.raises(MeasurementError, match="16 samples"):
        load_measurements(_one(write_h5, tmp_path / "f2.h5", x))
    x[idx[:-10]] = 0.0                                          # 10 = 0.1 %: not more than 0.1 %
    assert load_measurements(_one(write_h5, tmp_path / "f3.h5", x))[0].n_samples == 10_000


def test_clipping_can_be_switched_off_and_spares_constant_and_tachometer(write_h5, tmp_path):
    x = np.clip(_noisy(), -1.0, 1.0)
    p = write_h5(tmp_path / "k.h5", {"r": {"channels": {"x": (x, "V"), "dc": (np.full(N, 3.0), "V"),
                                                        "tach": ((np.arange(N) % 100 < 10) * 1.0, "1")},
                                           "attrs": {"sample_rate": FS, "tachometer": "tach",
                                                     "tachometer_kind": "pulse", "pulses_per_rev": 2}}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert [m.split(":")[0] for m in _problems(e)] == ["channel 'x' is clipped at its maximum 1 V",
                                                       "channel 'x' is clipped at its minimum -1 V"]
    rec = load_measurements(p, check_clipping=False)[0]
    assert rec.pulses_per_rev == 2


def test_min_duration(write_h5, tmp_path):
    p = _one(write_h5, tmp_path / "d.h5", _noisy())
    assert len(load_measurements(p, min_duration=0.2)) == 1
    with pytest.raises(MeasurementError) as e:
        load_measurements(p, min_duration=0.5)
    assert _problems(e) == ["record is 0.2 s long (2000 samples at 10000 Hz), shorter than min_duration 0.5 s"]


def test_requested_channels_missing(good_h5):
    with pytest.raises(MeasurementError) as e:
        load_measurements(good_h5, channels=["accel", "mic", "strain"])
    assert [(r, p) for _, r, p in e.value.problems] == [
        ("run_a", "requested channels missing: mic, strain (record has: accel, tacho)"),
        ("run_b", "requested channels missing: mic, strain (record has: accel, tacho)")]


def test_unselected_channels_are_not_checked(write_h5, tmp_path):
    bad = _noisy()
    bad[3] = np.nan
    p = write_h5(tmp_path / "s.h5", {"r": {"channels": {"good": (_noisy(1), "V"), "bad": (bad, "V")},
                                           "attrs": {"sample_rate": FS}}})
    assert load_measurements(p, channels="good")[0].channel_names == ("good",)


def test_attribute_problems(write_h5, tmp_path):
    p = write_h5(tmp_path / "a.h5", {"r": {"channels": {"x": (_noisy(), "V"), "ang": (np.arange(N) % 7.0, "V")},
                                           "attrs": {"sample_rate": -5.0, "nominal_sped": 20.0, "label": 1.5,
                                                     "tachometer": "ang", "tachometer_kind": "angle",
                                                     "pulses_per_rev": 3}}})
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    probs = _problems(e)
    assert "unknown record attribute 'nominal_sped' (did you mean 'nominal_speed'?)" in probs
    assert "attribute 'sample_rate' must be > 0, got -5" in probs
    assert "attribute 'label' must be an integer, got 1.5" in probs
    assert "attribute 'pulses_per_rev' only applies to tachometer_kind 'pulse'" in probs
    assert "tachometer channel 'ang' of kind 'angle' must have unit 'rad', got 'V'" in probs
    assert any("must be unwrapped" in m for m in probs)


def test_three_problems_in_one_file_are_reported_together(write_h5, tmp_path):
    x = _noisy()
    x[42] = np.nan
    p = write_h5(tmp_path / "three.h5", {
        "a": {"channels": {"accel": (x, "m/s2")}, "attrs": {"sample_rate": FS}},
        "b": {"channels": {"accel": (_noisy(1), "furlong/s2")}, "attrs": {"sample_rate": FS}},
        "c": {"channels": {"accel": (_noisy(2), "m/s2")}, "attrs": {}},
    })
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    err = e.value
    assert len(err.problems) == 3
    assert [r for _, r, _ in err.problems] == ["a", "b", "c"]
    assert "non-finite" in err.problems[0][2] and "unknown unit" in err.problems[1][2]
    assert "missing sample rate" in err.problems[2][2]
    text = str(err)
    assert text.startswith("3 problems in measurement file") and all(p in text for _, _, p in err.problems)
    assert (err.file, err.record, err.problem) == err.problems[0]


def test_csv_problems_are_collected(write_csv, tmp_path):
    t = np.arange(N) / FS
    t[5] = t[4]
    x = _noisy()
    x[9] = np.inf
    p = write_csv(tmp_path / "bad.csv", {"x": x, "y": _noisy(1)}, {"units": {"x": "V", "y": "parsec"}}, time=t)
    with pytest.raises(MeasurementError) as e:
        load_measurements(p, min_duration=1.0)
    probs = _problems(e)
    assert len(probs) == 3
    assert probs[0].startswith("time is not strictly increasing: sample 5")
    assert probs[1] == "channel 'x' has 1 non-finite samples (Inf); first at index 9"
    assert probs[2].startswith("channel 'y' has unknown unit 'parsec'")


def test_csv_header_and_sidecar_problems(tmp_path):
    p = tmp_path / "h.csv"
    p.write_text("t,x,x\n0,1,2\n")
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    probs = _problems(e)
    assert probs[0].startswith("no sidecar with units")
    assert "no 'time' column (columns: t, x, x)" in probs and "duplicate column names: x" in probs
    q = tmp_path / "s.csv"
    q.write_text("time,x\n0,1\n")
    (tmp_path / "s.yaml").write_text("- just\n- a list\n")
    with pytest.raises(MeasurementError, match="must hold a mapping"):
        load_measurements(q)


def test_argument_errors(good_h5):
    with pytest.raises(ParameterError):
        load_measurements(good_h5, resample_to=-1.0)
    with pytest.raises(ParameterError):
        load_measurements(good_h5, min_duration=float("nan"))
    with pytest.raises(ParameterError):
        load_measurements(good_h5, channels=[])
    with pytest.raises(ParameterError, match="sidecar only applies to CSV"):
        load_measurements(good_h5, sidecar="x.yaml")


# --------------------------------------------------------------------------- resampling

def test_resample_50k_to_100k_preserves_1khz_sine(write_h5, tmp_path, caplog):
    fs = 50_000.0
    t = np.arange(10_000) / fs
    p = write_h5(tmp_path / "s.h5", {
        "fast": {"channels": {"accel": (np.sin(2 * np.pi * 1000.0 * t), "m/s2")}, "attrs": {"sample_rate": fs}},
        "ready": {"channels": {"accel": (_noisy(), "m/s2")}, "attrs": {"sample_rate": 100_000.0}},
    })
    with caplog.at_level(logging.INFO, logger="twin.measurements"):
        mset = load_measurements(p, resample_to=100_000.0)
    rec = mset["fast"]
    assert rec.sample_rate == 100_000.0 and rec.resampled_from == fs and rec.n_samples == 20_000
    assert rec.duration == pytest.approx(0.2)
    inner = slice(200, -200)                                    # clear of the filter's edge transient
    y, tt = rec["accel"][inner], rec.time[inner]
    assert np.max(np.abs(y - np.sin(2 * np.pi * 1000.0 * tt))) < 1e-3
    basis = np.column_stack([np.sin(2 * np.pi * 1000.0 * tt), np.cos(2 * np.pi * 1000.0 * tt)])
    amp = np.hypot(*np.linalg.lstsq(basis, y, rcond=None)[0])
    assert abs(amp - 1.0) < 1e-3
    assert mset["ready"].resampled_from is None                # already at the target: untouched
    (note,) = mset.notes
    assert note.startswith("record 'fast': resampled 50000 Hz -> 100000 Hz (up 2, down 1;")
    assert "resample_poly" in note and "10000 -> 20000 samples" in note
    assert note in caplog.text


def test_downsampling_is_anti_aliased_and_tachometer_held(write_h5, tmp_path):
    fs = 48_000.0
    t = np.arange(9_600) / fs
    # 1 kHz stays, 20 kHz is above the new Nyquist (16 kHz) and must not alias to 12 kHz.
    x = np.sin(2 * np.pi * 1000.0 * t) + np.sin(2 * np.pi * 20_000.0 * t)
    tach = ((np.arange(t.size) % 2400) < 24) * 5.0
    p = write_h5(tmp_path / "d.h5", {"r": {"channels": {"x": (x, "V"), "tach": (tach, "V")},
                                           "attrs": {"sample_rate": fs, "tachometer": "tach",
                                                     "tachometer_kind": "pulse"}}})
    mset = load_measurements(p, resample_to=32_000.0)
    rec = mset[0]
    assert rec.resampled_from == fs and rec.sample_rate == 32_000.0
    y = rec["x"][400:-400]
    spec = np.abs(np.fft.rfft(y * np.hanning(y.size)))
    f = np.fft.rfftfreq(y.size, 1 / 32_000.0)
    assert spec[np.argmin(np.abs(f - 12_000.0))] < 1e-3 * spec[np.argmin(np.abs(f - 1000.0))]
    assert set(np.unique(rec["tach"])) == {0.0, 5.0}            # pulses stay pulses
    assert "content above 16000 Hz removed" in mset.notes[0]
    assert "tachometer 'tach' (pulse) by sample-and-hold" in mset.notes[0]


# --------------------------------------------------------------------------- records in memory

def test_record_in_memory_checks_invariants():
    with pytest.raises(MeasurementError) as e:
        Record("r/1", {"a": np.zeros(3), "b": np.zeros(4), "time": np.zeros(3)}, {"a": "g", "b": "V"}, 0.0)
    probs = _problems(e)
    assert e.value.file == "<memory>"
    assert any("record name" in m for m in probs) and any("reserved" in m for m in probs)
    assert any("differ in length" in m for m in probs) and any("not a canonical unit" in m for m in probs)
    assert any("sample_rate must be" in m for m in probs)
    src = np.arange(4.0)
    rec = Record("ok", {"a": src}, {"a": "m"}, 4.0)
    src[0] = 99.0                                               # the record keeps its own copy
    assert rec["a"][0] == 0.0 and rec.duration == 1.0
    with pytest.raises(MeasurementError, match="duplicate record name"):
        MeasurementSet((rec, rec))


@pytest.mark.parametrize("body", ["0,1,5\n1e-4,2,6\n", "0,1\n1e-4,2,6\n"])
def test_csv_rows_longer_than_header_are_malformed(tmp_path, body):
    p = tmp_path / "r.csv"
    p.write_text("time,x\n" + body)
    (tmp_path / "r.csv.yaml").write_text("units: {x: V}\n")
    with pytest.raises(MeasurementError, match="malformed CSV"):
        load_measurements(p)


def test_csv_short_row_and_nan_text(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text("time,x,y\n0,1,2\n1e-4,nan,3\n2e-4,4\n")
    (tmp_path / "s.csv.yaml").write_text("units: {x: V, y: V}\n")
    with pytest.raises(MeasurementError) as e:
        load_measurements(p)
    assert _problems(e) == ["column 'y' has 1 non-numeric cells; first at sample 2: ''",
                            "channel 'x' has 1 non-finite samples (NaN); first at index 1 (t = 0.0001 s)"]


@pytest.mark.parametrize("up, down, n", [(256, 625, 3000), (2, 1, 501), (3, 7, 1000), (7, 3, 64), (1, 5, 999),
                                         (5, 1, 3), (625, 256, 40)])
def test_polyphase_resampling_is_scipys_resample_poly(up, down, n):
    from scipy.signal import resample_poly

    from twin.measurements.resample import anti_aliasing_filter, polyphase
    x = np.cumsum(np.random.default_rng(n).standard_normal(n)) + 3.0       # a trend and an offset: the padding shows
    ref = resample_poly(x, up, down, window=anti_aliasing_filter(up, down), padtype="line")
    y = polyphase(x, up, down)
    assert y.shape == ref.shape
    np.testing.assert_allclose(y, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_a_hammer_force_at_rest_between_hits_is_not_clipping(write_h5, tmp_path):
    """An impact test's force is exactly zero between its hits; a clipped hit is still refused."""
    force = np.zeros(N)
    for i, k in enumerate(range(100, N - 20, N // 4)):
        force[k:k + 7] = (50.0 + 3.0 * i) * np.hanning(9)[1:8] * np.linspace(1.0, 0.9, 7)   # one peak sample
    assert load_measurements(_one(write_h5, tmp_path / "h.h5", force, unit="N"))[0].n_samples == N
    force[force > 40.0] = 40.0                                  # the hits cut at the amplifier's limit
    with pytest.raises(MeasurementError, match="clipped at its maximum 40 N"):
        load_measurements(_one(write_h5, tmp_path / "h2.h5", force, unit="N"))
