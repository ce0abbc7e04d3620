"""Round trips and failure behaviour of twin.results (HDF5, CSV, atomic writes)."""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from twin import results as res
from twin._atomic import atomic_path
from twin.errors import OutputPathError
from twin.results import SimulationResult, read_csv, read_hdf5, read_result, write_result


@pytest.fixture
def result() -> SimulationResult:
    rng = np.random.default_rng(1234)
    fs = 1000.0
    t = np.arange(500) / fs
    return SimulationResult(
        time=t,
        signals={
            "housing.a": rng.standard_normal(t.size),
            "shaft/speed": rng.standard_normal(t.size) * 1e-7 + 3.0,  # '/' must survive HDF5
            "torque[1]": np.sin(2 * np.pi * 50 * t),
        },
        units={"housing.a": "m/s2", "shaft/speed": "rad/s", "torque[1]": ""},
        sample_rate=fs,
        parameters={"k_mesh": 2.5e8, "damping": 0.02},
        model_name="GearTwin.Gearbox21",
        guid="{1234-abcd}",
        fmu_sha256="ab" * 32,
    )


def _assert_same(a: SimulationResult, b: SimulationResult) -> None:
    np.testing.assert_array_equal(a.time, b.time)
    assert a.channels == b.channels
    for name in a.channels:
        np.testing.assert_array_equal(a[name], b[name])
    assert dict(a.units) == dict(b.units)
    assert dict(a.parameters) == dict(b.parameters)
    assert (a.sample_rate, a.model_name, a.guid, a.fmu_sha256) == (
        b.sample_rate, b.model_name, b.guid, b.fmu_sha256)


def _tmp_leftovers(directory):
    return [p.name for p in directory.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("suffix", [".h5", ".hdf5"])
def test_hdf5_round_trip_and_layout(tmp_path, result, suffix):
    path = write_result(result, tmp_path / f"run{suffix}")
    _assert_same(result, read_hdf5(path))
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "gear-twin-result" and f.attrs["format_version"] == 1
        assert f["time"].attrs["unit"] == "s"
        ds = f["signals/housing.a"]
        assert ds.compression == "gzip" and ds.compression_opts == 4 and ds.chunks is not None
        assert ds.attrs["unit"] == "m/s2" and ds.attrs["sample_rate"] == 1000.0
        assert f["parameters"].attrs["k_mesh"] == 2.5e8
    assert _tmp_leftovers(tmp_path) == []


def test_csv_round_trip_and_sidecar(tmp_path, result):
    path = write_result(result, tmp_path / "run.csv")
    header = path.read_text().splitlines()[0]
    assert header == "time,housing.a,shaft/speed,torque[1]"      # plain names; units in the sidecar
    meta = json.loads((tmp_path / "run.csv.json").read_text())
    assert meta["sample_rate"] == 1000.0 and meta["guid"] == "{1234-abcd}"
    assert meta["units"]["shaft/speed"] == "rad/s" and meta["parameters"]["damping"] == 0.02
    _assert_same(result, read_csv(path))


@pytest.mark.parametrize("name", ["e.h5", "e.csv"])
def test_empty_result_round_trips(tmp_path, name):
    empty = SimulationResult(time=np.empty(0), signals={"a": np.empty(0)}, units={},
                             sample_rate=10.0, parameters={})
    back = read_result(write_result(empty, tmp_path / name))
    assert len(back) == 0 and back.channels == ("a",) and back.units["a"] == ""


def test_getitem_lists_available_channels(result):
    with pytest.raises(KeyError, match="housing.a"):
        result["nope"]


def test_shape_mismatch_rejected():
    with pytest.raises(ValueError, match="'x'"):
        SimulationResult(time=np.zeros(3), signals={"x": np.zeros(4)}, units={},
                         sample_rate=1.0, parameters={})


def test_to_dataframe(result):
    df = result.to_dataframe()
    assert list(df.columns) == ["time", *result.channels]
    np.testing.assert_array_equal(df["torque[1]"].to_numpy(), result["torque[1]"])


def test_failed_hdf5_write_keeps_existing_file(tmp_path, result, monkeypatch):
    path = tmp_path / "run.h5"
    path.write_bytes(b"previous contents")
    original = h5py.Group.create_dataset

    def fail_on_signals(self, name, *args, **kwargs):
        if name != "time":  # '/time' reaches the temp file, then the write dies
            raise RuntimeError("disk on fire")
        return original(self, name, *args, **kwargs)

    monkeypatch.setattr(h5py.Group, "create_dataset", fail_on_signals)
    with pytest.raises(RuntimeError, match="disk on fire"):
        write_result(result, path)
    assert path.read_bytes() == b"previous contents"
    assert _tmp_leftovers(tmp_path) == []


def test_failed_csv_write_keeps_existing_file(tmp_path, result, monkeypatch):
    path = tmp_path / "run.csv"
    path.write_text("old,csv\n")

    def half_write(fh, *args, **kwargs):
        fh.write("time,partial\n0,")
        raise OSError("no space left")

    monkeypatch.setattr(res.np, "savetxt", half_write)
    with pytest.raises(OSError, match="no space left"):
        write_result(result, path)
    assert path.read_text() == "old,csv\n"
    assert not (tmp_path / "run.csv.json").exists()
    assert _tmp_leftovers(tmp_path) == []


def test_atomic_path_keeps_mode_of_replaced_file(tmp_path):
    path = tmp_path / "f.txt"
    path.write_text("a")
    path.chmod(0o640)
    with atomic_path(path) as tmp:
        tmp.write_text("b")
    assert path.read_text() == "b" and (path.stat().st_mode & 0o777) == 0o640


@pytest.mark.parametrize("name", ["run.txt", "run", "run.h5.bak"])
def test_bad_suffix_names_suffix_and_accepted(tmp_path, result, name):
    with pytest.raises(OutputPathError) as info:
        write_result(result, tmp_path / name)
    message = str(info.value)
    assert f"'{(tmp_path / name).suffix}'" in message and ".h5" in message and ".csv" in message
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["run.h5", "run.csv"])
def test_missing_directory_is_not_created(tmp_path, result, name):
    missing = tmp_path / "no" / "such"
    with pytest.raises(OutputPathError, match="no/such"):
        write_result(result, missing / name)
    assert not (tmp_path / "no").exists()


def test_read_rejects_foreign_hdf5(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as f:
        f["x"] = np.arange(3)
    with pytest.raises(OutputPathError, match="not a gear-twin-result"):
        read_hdf5(path)


@pytest.fixture
def typed() -> SimulationResult:
    t = np.arange(5) * 0.1
    text = np.empty(5, dtype=object)
    text[:] = ["a", "b,c", 'say "hi"', "", "ünïcode"]
    return SimulationResult(
        time=t,
        signals={"x": np.linspace(0, 1, 5), "f32": np.array([0.1, 0.2, 1e-30, 3.0, -1.5], dtype=np.float32),
                 "i8": np.array([-128, 0, 1, 2, 127], dtype=np.int8),
                 "u64": np.array([0, 1, 2**63, 2**64 - 2, 2**64 - 1], dtype=np.uint64),
                 "flag": np.array([True, False, True, True, False]), "mode": np.array([1, 2, 3, 1, 2], dtype=np.int32),
                 "label": text},
        units={"x": "m"}, sample_rate=10.0,
        parameters={"gain": 2.0, "step": 3, "invert": True, "label": "gear", "big": 2**64 - 1},
        types={"x": "Real", "f32": "Float32", "i8": "Int8", "u64": "UInt64", "flag": "Boolean",
               "mode": "Enumeration", "label": "String"},
        enumerations={"mode": {"off": 1, "slow": 2, "fast": 3}},
        ended_by_fmu=True, end_reason="fmi2DoStep returned fmi2Discard with fmi2Terminated at t=0.4 s")


@pytest.mark.parametrize("suffix", [".h5", ".csv"])
def test_every_type_round_trips_with_its_dtype(tmp_path, typed, suffix):
    back = read_result(write_result(typed, tmp_path / f"typed{suffix}"))
    _assert_same(typed, back)
    for name in typed.channels:
        assert back[name].dtype == typed[name].dtype, name
    assert list(back["label"]) == ["a", "b,c", 'say "hi"', "", "ünïcode"]
    assert back.types == typed.types and back.enumerations == typed.enumerations
    assert back.ended_by_fmu and back.end_reason == typed.end_reason
    assert back.parameters["invert"] is True and back.parameters["big"] == 2**64 - 1


def test_typed_hdf5_layout(tmp_path, typed):
    path = write_result(typed, tmp_path / "typed.h5")
    with h5py.File(path, "r") as f:
        assert f["signals/u64"].dtype == np.uint64 and f["signals/flag"].dtype == bool
        assert h5py.check_string_dtype(f["signals/label"].dtype).encoding == "utf-8"
        assert f["signals/mode"].attrs["fmi_type"] == "Enumeration"
        assert json.loads(f["signals/mode"].attrs["items"]) == {"off": 1, "slow": 2, "fast": 3}
        assert f.attrs["ended_by_fmu"] and "fmi2Terminated" in f.attrs["end_reason"]
    sidecar = json.loads((write_result(typed, tmp_path / "typed.csv").parent / "typed.csv.json").read_text())
    assert sidecar["types"]["label"] == "String" and sidecar["dtypes"]["u64"] == "uint64"
    assert sidecar["ended_by_fmu"] is True


def test_csv_with_a_bad_field_is_refused_by_name(tmp_path, typed):
    import csv
    path = write_result(typed, tmp_path / "typed.csv")
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][3] == "i8"
    rows[2][3] = "1.5"                              # an Int8 field that is not whole
    with open(path, "w", newline="", encoding="utf-8") as fh:
        csv.writer(fh, lineterminator="\n").writerows(rows)
    with pytest.raises(OutputPathError, match="channel 'i8'"):
        read_result(path)


def test_hdf5_only_paths(tmp_path):
    assert res.check_hdf5_path(tmp_path / "a.hdf5", "an archive") == tmp_path / "a.hdf5"
    with pytest.raises(OutputPathError, match=r"an archive writes HDF5: '.*a.csv' must end in .h5 or .hdf5 \(not '.csv'\)"):
        res.check_hdf5_path(tmp_path / "a.csv", "an archive")
