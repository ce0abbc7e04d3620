"""twin.measurements.write: atomic HDF5 writer round trips, CSV import."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twin.errors import MeasurementError, OutputPathError
from twin.measurements import (MEASUREMENT_FORMAT, MeasurementSet, Record, import_csv, load_measurements,
                               write_measurements)

FS = 10_000.0
N = 2_000


def _noisy(seed=0, n=N):
    rng = np.random.default_rng(seed)
    return np.sin(2 * np.pi * 480.0 * np.arange(n) / FS) + 0.3 * rng.standard_normal(n)


def _same(a: Record, b: Record) -> None:
    assert a.name == b.name and a.channel_names == b.channel_names and dict(a.units) == dict(b.units)
    for c in a.channels:
        np.testing.assert_array_equal(a[c], b[c])
    for attr in ("sample_rate", "nominal_speed", "load", "tachometer", "tachometer_kind", "pulses_per_rev",
                 "label", "damage", "time_start", "resampled_from"):
        assert getattr(a, attr) == getattr(b, attr), attr
    assert dict(a.metadata) == dict(b.metadata)


def test_hdf5_round_trip(good_h5, tmp_path):
    first = load_measurements(good_h5)
    out = write_measurements(first, tmp_path / "copy.h5")
    assert out == tmp_path / "copy.h5"
    again = load_measurements(out)
    assert again.names == first.names and dict(again.metadata) == dict(first.metadata)
    for a, b in zip(first, again):
        _same(a, b)
    import h5py
    with h5py.File(out) as f:
        assert f.attrs["format"] == MEASUREMENT_FORMAT and f.attrs["format_version"] == 1
        assert f["records/run_a/accel"].attrs["unit"] == "m/s2"          # g was converted on load
        assert f["records/run_a"].attrs["operator"] == "rig-2"
        assert "time_start" not in f["records/run_a"].attrs and f["records/run_b"].attrs["time_start"] == 1.5


def test_records_from_memory_and_resampled_from_survive(tmp_path):
    recs = [Record("b", {"x": _noisy(1)}, {"x": "N"}, FS, label=1),
            Record("a", {"x": _noisy(2), "phi": np.linspace(0, 40.0, N)}, {"x": "N", "phi": "rad"}, FS,
                   tachometer="phi", tachometer_kind="angle", resampled_from=5000.0, metadata={"note": "hand"})]
    back = load_measurements(write_measurements(recs, tmp_path / "m.hdf5"))
    assert back.names == ("b", "a")
    for a, b in zip(recs, back):
        _same(a, b)


def test_resampled_set_round_trip(write_h5, tmp_path):
    t = np.arange(5_000) / 50_000.0
    p = write_h5(tmp_path / "s.h5", {"r": {"channels": {"x": (np.sin(2 * np.pi * 1000 * t), "m/s2")},
                                           "attrs": {"sample_rate": 50_000.0}}})
    up = load_measurements(p, resample_to=100_000.0)
    back = load_measurements(write_measurements(up, tmp_path / "up.h5"), resample_to=100_000.0)
    assert back[0].resampled_from == 50_000.0 and back.notes == ()      # nothing more to do
    _same(up[0], back[0])


def test_writer_refuses_bad_targets_and_sets(tmp_path):
    rec = Record("r", {"x": _noisy()}, {"x": "V"}, FS)
    with pytest.raises(OutputPathError, match=r"\.h5"):
        write_measurements([rec], tmp_path / "r.csv")
    with pytest.raises(OutputPathError, match="does not exist"):
        write_measurements([rec], tmp_path / "missing" / "r.h5")
    with pytest.raises(MeasurementError, match="no records"):
        write_measurements([], tmp_path / "r.h5")
    with pytest.raises(MeasurementError, match="duplicate record name") as e:
        write_measurements([rec, rec], tmp_path / "r.h5")
    assert e.value.file == str(tmp_path / "r.h5") and e.value.record == "r"
    with pytest.raises(MeasurementError, match="'label' is a format attribute"):
        write_measurements([Record("r", {"x": _noisy()}, {"x": "V"}, FS, metadata={"label": 3})],
                           tmp_path / "r.h5")


def test_failed_write_leaves_existing_file_untouched(tmp_path):
    target = tmp_path / "keep.h5"
    good = Record("r", {"x": _noisy()}, {"x": "V"}, FS)
    write_measurements([good], target)
    before = target.read_bytes()
    bad = Record("s", {"x": _noisy(1)}, {"x": "V"}, FS, metadata={"obj": object()})
    with pytest.raises(MeasurementError, match="cannot be stored as an HDF5 attribute"):
        write_measurements([good, bad], target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.h5"]          # no temporary left


@pytest.mark.parametrize("kind", ["yaml", "json"])
def test_import_csv(write_csv, tmp_path, kind):
    x = _noisy(5)
    src = write_csv(tmp_path / "run.csv", {"accel": x, "tacho": (np.arange(N) % 500 < 5) * 5.0},
                    {"sample_rate": FS, "nominal_speed": 20.0, "load": 5.0, "label": 2, "damage": 0.1,
                     "tachometer": "tacho", "tachometer_kind": "pulse", "pulses_per_rev": 1,
                     "units": {"accel": "g", "tacho": "V"}, "metadata": {"sensor": "PCB"}}, kind=kind)
    out = import_csv(src, tmp_path / "run.h5")
    assert out == tmp_path / "run.h5"
    direct, imported = load_measurements(src), load_measurements(out)
    _same(direct[0], imported[0])
    rec = imported[0]
    assert rec.name == "run" and rec.units["accel"] == "m/s2" and rec.label == 2
    np.testing.assert_allclose(rec["accel"], 9.80665 * x, rtol=1e-15)


def test_import_csv_with_explicit_sidecar(write_csv, tmp_path):
    src = write_csv(tmp_path / "a.csv", {"v": _noisy()}, None)
    side = tmp_path / "meta" / "a-info.yaml"
    side.parent.mkdir()
    side.write_text("record: custom\nunits: {v: m/s}\n")
    out = import_csv(src, tmp_path / "a.h5", sidecar=side)
    assert load_measurements(out).names == ("custom",)


def test_import_csv_rejects_invalid_input_and_writes_nothing(write_csv, tmp_path):
    x = _noisy()
    x[3] = np.nan
    src = write_csv(tmp_path / "bad.csv", {"v": x}, {"units": {"v": "m/s"}})
    with pytest.raises(MeasurementError, match="non-finite"):
        import_csv(src, tmp_path / "bad.h5")
    assert not (tmp_path / "bad.h5").exists()
    with pytest.raises(OutputPathError):
        import_csv(src, tmp_path / "bad.txt")                 # checked before the CSV is read
    h5 = write_measurements([Record("r", {"x": _noisy()}, {"x": "V"}, FS)], tmp_path / "r.h5")
    with pytest.raises(MeasurementError, match="not a CSV file"):
        import_csv(h5, tmp_path / "r2.h5")


def test_measurement_set_of_records_writes_its_metadata(tmp_path):
    mset = MeasurementSet((Record("r", {"x": _noisy()}, {"x": "V"}, FS),), None, (), {"campaign": "2024-03"})
    back = load_measurements(write_measurements(mset, tmp_path / "c.h5"))
    assert back.metadata["campaign"] == "2024-03" and Path(back.source).name == "c.h5"
