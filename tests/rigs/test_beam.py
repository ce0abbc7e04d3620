"""The beam rig: modes, effect signatures, damage trends, determinism and its files."""
from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal

from rigs.beam import (PITTING_EDGES, WEAR_EDGES, EffectError, Rig, RigError, VERSION, WriteError,
                       write)

FS = 50000.0


@pytest.fixture(scope="module")
def rig():
    return Rig()


@pytest.fixture(scope="module")
def records(rig):
    names = [None, "pinion_runout", "gear_runout", "drive_ripple", "casing_resonance",
             "local_tooth_fault", "bearing_outer_race", "coupling_misalignment"]
    return {n: rig.steady(20.0, 20.0, 1.0, effect=n, seed=1) for n in names}


def _spec(x):
    w = np.hanning(x.size)
    return np.fft.rfftfreq(x.size, 1 / FS), np.abs(np.fft.rfft((x - x.mean()) * w)) * 2 / w.sum()


def _line(f, X, f0, tol=1.2):
    return X[(f > f0 - tol) & (f < f0 + tol)].max()


def _sidebands(r, ch, order, harmonics=range(1, 6), offsets=(1,)):
    sp = r.truth["speed"]["true_mean"]
    f, X = _spec(r.channels[ch])
    fo = sp * order
    return np.sqrt(np.mean([_line(f, X, k * 19 * sp + s * j * fo) ** 2
                            for k in harmonics for s in (-1, 1) for j in offsets]))


def test_modes_table_and_observability(rig):
    modes = rig.modes(20.0, 20.0)
    f = np.array([m.frequency for m in modes])
    assert np.all(np.diff(f) >= 0) and 20.0 < f[0] < 100.0 and f[-1] <= 5000.0
    obs = np.array([m.observability for m in modes])
    assert obs.max() == pytest.approx(1.0) and obs.min() >= 0.0
    assert all(0 < m.damping_ratio < 0.2 and m.label for m in modes)


def test_observable_modes_appear_in_the_response(rig, records):
    """Each mode the linearisation calls well observable is a resonance hump of the record."""
    r = records[None]
    sp = r.truth["speed"]["true_mean"]
    spectra = [signal.welch(r.channels[ch], FS, nperseg=8192)
               for ch in ("accel_pinion_casing", "accel_gear_casing")]
    f = spectra[0][0]
    ok = np.ones(f.size, bool)
    for k in range(1, 60):                            # mask mesh harmonics and their sidebands
        ok &= np.abs(f - 19 * k * sp) > 3.5 * sp
    for m in rig.modes(20.0, r.truth["load"]["true"]):
        if m.observability < 0.4:
            continue
        band = ok & (np.abs(f - m.frequency) < 0.03 * m.frequency)
        wide = ok & (np.abs(f - m.frequency) < 0.3 * m.frequency) & ~band
        assert any(P[band].mean() > 1.5 * np.median(P[wide]) for _, P in spectra), m


def test_truth_is_separate_and_complete(records, tmp_path):
    from twin.measurements import load_measurements
    path = write(tmp_path / "rig.h5", list(records.values())[:2])
    mset = load_measurements(path)
    assert len(mset) == 2
    rec = mset[0]
    assert rec.sample_rate == FS and rec.tachometer == "encoder" and rec.tachometer_kind == "angle"
    assert set(rec.channel_names) == {"accel_pinion_casing", "accel_gear_casing", "encoder"}
    assert "damage" not in rec.metadata and rec.label is None and rec.damage is None
    truth = json.loads((tmp_path / "rig.h5.truth.json").read_text())
    assert truth["rig"] == VERSION
    t = truth["records"][rec.name]
    assert {"speed", "load", "sensor_gain", "modes", "effect", "damage"} <= set(t)
    assert abs(t["speed"]["true_mean"] / 20.0 - 1) < 0.03


def test_runup_loads(rig, tmp_path):
    from twin.measurements import load_measurements
    r = rig.runup((2.0, 20.0), 20.0, 1.0, seed=2)
    path = write(tmp_path / "ru.h5", [r])
    rec = load_measurements(path)[0]
    enc = rec["encoder"]
    assert np.all(np.diff(enc) >= 0) and r.truth["speed"]["true_end"] > 5 * r.truth["speed"]["true_start"]


def test_deterministic_for_a_seed(rig):
    a = rig.steady(20.0, 20.0, 0.2, seed=4)
    b = rig.steady(20.0, 20.0, 0.2, seed=4)
    c = rig.steady(20.0, 20.0, 0.2, seed=5)
    for k in a.channels:
        assert np.array_equal(a.channels[k], b.channels[k])
    assert not np.array_equal(a.channels["accel_pinion_casing"], c.channels["accel_pinion_casing"])


def test_levels_are_realistic(records):
    r = records[None]
    for ch in ("accel_pinion_casing", "accel_gear_casing"):
        assert 1.0 < r.channels[ch].std() < 50.0


def test_pinion_runout_adds_pinion_sidebands(records):
    base = _sidebands(records[None], "accel_pinion_casing", 1.0)
    assert _sidebands(records["pinion_runout"], "accel_pinion_casing", 1.0) > 1.3 * base


def test_gear_runout_adds_gear_sidebands(records):
    ch = "accel_gear_casing"
    base = _sidebands(records[None], ch, 19 / 52)
    assert _sidebands(records["gear_runout"], ch, 19 / 52) > 1.1 * base


def test_drive_ripple_is_a_fixed_line(records):
    f, X0 = _spec(records[None].channels["accel_gear_casing"])
    f, X1 = _spec(records["drive_ripple"].channels["accel_gear_casing"])
    assert _line(f, X1, 347.0) > 3 * _line(f, X0, 347.0)


def test_casing_resonance_is_a_band_on_its_sensor(records):
    def band(r, ch):
        f, P = signal.welch(r.channels[ch], FS, nperseg=4096)
        s = (f > 3000) & (f < 3600)
        return P[s].sum()
    assert band(records["casing_resonance"], "accel_pinion_casing") > 3 * band(records[None], "accel_pinion_casing")
    assert band(records["casing_resonance"], "accel_gear_casing") == pytest.approx(
        band(records[None], "accel_gear_casing"), rel=0.1)


def _tsa_residual(r, ch="accel_pinion_casing", n=1024):
    th, x = r.channels["encoder"], r.channels[ch]
    revs = int((th[-1] - th[0]) // (2 * np.pi)) - 1
    grid = th[0] + 2 * np.pi * np.arange(revs * n) / n
    avg = np.interp(grid, th, x).reshape(revs, n).mean(axis=0)
    X = np.fft.rfft(avg)
    for k in (-1, 0, 1):
        X[(19 + k) % 19::19] = 0
    res = np.fft.irfft(X, n)
    return ((res - res.mean()) ** 4).mean() / res.var() ** 2


def test_local_tooth_fault_is_impulsive_once_per_revolution(records):
    assert _tsa_residual(records["local_tooth_fault"]) > 1.15 * _tsa_residual(records[None])


def test_outer_race_defect_shows_in_the_envelope(records):
    def env(r):
        sos = signal.butter(4, [2000, 8000], "bandpass", fs=FS, output="sos")
        e = np.abs(signal.hilbert(signal.sosfiltfilt(sos, r.channels["accel_pinion_casing"])))
        f, E = _spec(e)
        bpfo = 4.5 * (1 - 7.94 / 39.04) * r.truth["speed"]["true_mean"]
        return _line(f, E, bpfo, 1.5)
    assert env(records["bearing_outer_race"]) > 2 * env(records[None])
    assert records["bearing_outer_race"].truth["effect"]["outside_catalogue"]


def test_coupling_misalignment_twice_per_revolution(records):
    sp = records[None].truth["speed"]["true_mean"]
    f, X0 = _spec(records[None].channels["accel_pinion_casing"])
    f, X1 = _spec(records["coupling_misalignment"].channels["accel_pinion_casing"])
    assert _line(f, X1, 2 * sp, 0.8) > 5 * _line(f, X0, 2 * sp, 0.8)


def test_pitting_raises_sidebands_monotonically(rig):
    level = []
    for s in range(len(PITTING_EDGES) - 1):
        c = 0.5 * (PITTING_EDGES[s] + PITTING_EDGES[s + 1])
        r = rig.steady(20.0, 20.0, 0.5, damage={"pitting": c}, seed=3)
        level.append(_sidebands(r, "accel_pinion_casing", 1.0, offsets=range(1, 9)))
    assert np.all(np.diff(level) > 0), level


def test_wear_raises_mesh_content_monotonically(rig):
    level = []
    for s in range(len(WEAR_EDGES) - 1):
        c = 0.5 * (WEAR_EDGES[s] + WEAR_EDGES[s + 1])
        r = rig.steady(10.0, 5.0, 0.5, damage={"wear": c}, seed=3)
        level.append(_sidebands(r, "accel_pinion_casing", 1.0, offsets=range(0, 4)))
        assert r.truth["lubricated"] is False
    assert np.all(np.diff(level) > 0), level


def test_bad_input_is_refused_by_name(rig, tmp_path):
    with pytest.raises(EffectError, match="nonsense"):
        rig.steady(effect="nonsense")
    with pytest.raises(RigError, match="speed"):
        rig.steady(speed=-3.0)
    with pytest.raises(WriteError, match="txt"):
        write(tmp_path / "a.txt", [rig.steady(duration=0.1)])


def test_stage_records_hide_their_stage(rig, monkeypatch):
    seen = []
    monkeypatch.setattr(Rig, "steady", lambda self, *a, **k: seen.append(k) or k["name"])
    names = rig.wear_stages(per_stage=2, duration=0.1, seed=1)
    assert sorted(names) == [f"wear_record_{i:03d}" for i in range(8)]
    assert [k["label"] for k in seen] == [0, 0, 1, 1, 2, 2, 3, 3]


def test_scattered_gearboxes_differ(rig):
    a, b = rig.scattered(1), rig.scattered(2)
    fa = [m.frequency for m in a.modes()][:6]
    fb = [m.frequency for m in b.modes()][:6]
    assert a.params != b.params and not np.allclose(fa, fb)
    assert rig.scattered(1).params == a.params
