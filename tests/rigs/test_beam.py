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


# ---- the impact (hammer) test record

@pytest.fixture(scope="module")
def impact(rig):
    """Slow roll (0.5 Hz) at 20 N m, hammer on the pinion-side bearing housing."""
    return rig.impact(0.5, 20.0, 2.0, impacts_per_second=4.0, location="pinion_housing", seed=1)


def _h1(r, ch, nperseg=8192):
    f, Pxy = signal.csd(r.channels["hammer"], r.channels[ch], FS, nperseg=nperseg)
    _, Pxx = signal.welch(r.channels["hammer"], FS, nperseg=nperseg)
    _, Pyy = signal.welch(r.channels[ch], FS, nperseg=nperseg)
    return f, Pxy / Pxx, np.abs(Pxy) ** 2 / (Pxx * Pyy)


def test_impact_force_channel_is_written_and_loads(impact, tmp_path):
    from twin.measurements import load_measurements
    assert set(impact.channels) == {"accel_pinion_casing", "accel_gear_casing", "encoder", "hammer"}
    assert impact.units["hammer"] == "N" and impact.attributes["record_kind"] == "impact"
    assert len({x.size for x in impact.channels.values()}) == 1
    path = write(tmp_path / "impact.h5", [impact])
    rec = load_measurements(path)[0]
    assert "hammer" in rec.channel_names and rec.units["hammer"] == "N"
    assert np.array_equal(rec["hammer"], impact.channels["hammer"])
    t = json.loads((tmp_path / "impact.h5.truth.json").read_text())["records"][rec.name]["hammer"]
    assert t["location"] == "pinion_housing" and t["hits"] == len(t["hit_times"])
    hits = np.array(t["hit_times"])
    assert np.all(np.diff(hits) > 0) and 0 <= hits[0] and hits[-1] < 2.0
    # each blow is in the channel at its time with its peak (load-cell gain, 50 kHz sampling)
    x = rec["hammer"]
    for t0, w, peak in zip(hits, t["contact_times"], t["peak_forces"]):
        i0, i1 = int(t0 * FS), int(np.ceil((t0 + w) * FS)) + 1
        assert x[i0:i1].max() == pytest.approx(peak * t["sensor_gain"], rel=0.1)
    assert np.abs(np.delete(x, np.concatenate([np.arange(int(a * FS) - 20, int(a * FS) + 40)
                                               for a in hits]))).max() < 1.0


def test_impact_hit_count_near_rate_times_duration(impact):
    from rigs.beam.hammer import draw_blows
    from rigs.beam.params import Hammer
    hits = impact.truth["hammer"]["hits"]
    assert abs(hits - 8) <= 3
    peaks, _ = signal.find_peaks(impact.channels["hammer"], height=50.0, distance=int(0.02 * FS))
    assert peaks.size == hits
    for rate in (1.0, 4.0, 10.0):
        n = [draw_blows("gear_housing", rate, 60.0, Hammer(), np.random.default_rng(s)).starts.size
             for s in range(5)]
        assert np.mean(n) == pytest.approx(60.0 * rate, rel=0.08), (rate, n)


def test_impact_refuses_bad_requests_by_name(rig):
    with pytest.raises(ValueError, match="nowhere"):
        rig.impact(location="nowhere")
    for bad in (0.0, -2.0, float("nan")):
        with pytest.raises(ValueError, match=f"impacts_per_second {bad}"):
            rig.impact(0.5, 20.0, 1.0, impacts_per_second=bad)
        with pytest.raises(ValueError, match=f"speed {bad}"):
            rig.impact(bad, 20.0, 1.0)


def test_impact_leaves_the_other_records_unchanged(rig):
    """The steady record of a seed is the one computed before the hammer test was added."""
    r = rig.steady(20.0, 20.0, 0.2, seed=4)
    assert set(r.channels) == {"accel_pinion_casing", "accel_gear_casing", "encoder"}
    rms = {k: float(np.sqrt(np.mean(v ** 2))) for k, v in r.channels.items()}
    assert rms["accel_pinion_casing"] == pytest.approx(9.916372364709064, rel=1e-6)
    assert rms["accel_gear_casing"] == pytest.approx(3.0570079308314297, rel=1e-6)
    assert rms["encoder"] == pytest.approx(14.724357219023611, rel=1e-9)
    assert r.channels["encoder"][-1] == pytest.approx(25.42309125772332, rel=1e-9)


def test_impact_frf_peaks_at_an_observable_mode(rig, impact):
    """At slow roll the hammer-to-casing FRF (H1) peaks at one of the rig's own modes that the
    sensors see, with good coherence."""
    f, H, coh = _h1(impact, "accel_pinion_casing")
    band = (f > 100.0) & (f < 5000.0)
    i = np.flatnonzero(band)[np.argmax(np.abs(H[band]))]
    modes = rig.modes(0.5, impact.truth["load"]["true"])
    near = [m for m in modes if abs(f[i] / m.frequency - 1) < 0.03 and m.observability >= 0.1]
    assert near, (f[i], [(m.frequency, m.observability) for m in modes])
    assert coh[i] > 0.5


def test_impact_frf_matches_the_modal_model(rig, impact):
    """Sign, size and timing of the blow: the measured H1 agrees with the accelerance of the
    linearised rig from the struck DOF to the sensor (times the gain ratio)."""
    from rigs.beam.hammer import Blows
    from rigs.beam.simulate import modal_for
    ch = "accel_pinion_casing"
    f, H, coh = _h1(impact, ch)
    model, mm, _ = modal_for(rig.params, impact.truth["load"]["true"], True)
    v = Blows("pinion_housing", np.zeros(0), np.zeros(0), np.zeros(0)).vector(model)
    band = (f > 300.0) & (f < 4000.0)
    w, wr = 2 * np.pi * f[band, None], 2 * np.pi * mm.freq[None, 1:]
    num = (model.sensors[0] @ mm.shapes[:, 1:]) * (v @ mm.shapes[:, 1:])
    Hm = (-w ** 2 * num / (wr ** 2 - w ** 2 + 2j * mm.zeta[1:] * wr * w)).sum(axis=1)
    Hm *= impact.truth["sensor_gain"][ch] / impact.truth["hammer"]["sensor_gain"]
    ratio = H[band] / Hm
    assert 0.85 < np.median(np.abs(ratio)) < 1.2
    assert abs(np.degrees(np.median(np.angle(ratio)))) < 10.0


def test_impact_from_the_side_pushes_the_y_dof_and_matches_the_modal_model(rig):
    """A horizontal blow at the pinion shaft's free end pushes that node's y DOF (-y), says so in
    its name, attributes and truth, and its H1 agrees with the linearised rig's accelerance from
    that DOF, as the vertical blow's does from z."""
    from rigs.beam.hammer import Blows
    from rigs.beam.simulate import modal_for
    side = rig.impact(0.5, 20.0, 2.0, impacts_per_second=4.0, location="pinion_shaft_end", seed=1,
                      direction="horizontal")
    assert "horizontal" in side.name and side.attributes["impact_direction"] == "horizontal"
    assert side.truth["hammer"]["direction"].startswith("-y")
    model, mm, _ = modal_for(rig.params, side.truth["load"]["true"], True)
    node = model.encoder - 4
    v = Blows("pinion_shaft_end", np.zeros(0), np.zeros(0), np.zeros(0), "horizontal").vector(model)
    assert v[node] == -1.0 and np.count_nonzero(v) == 1
    up = Blows("pinion_shaft_end", np.zeros(0), np.zeros(0), np.zeros(0)).vector(model)
    assert up[node + 1] == -1.0 and np.count_nonzero(up) == 1
    ch = "accel_gear_casing"          # the sensor along y
    f, H, coh = _h1(side, ch)
    band = (f > 300.0) & (f < 4000.0) & (coh > 0.8)
    w, wr = 2 * np.pi * f[band, None], 2 * np.pi * mm.freq[None, 1:]
    num = (model.sensors[1] @ mm.shapes[:, 1:]) * (v @ mm.shapes[:, 1:])
    Hm = (-w ** 2 * num / (wr ** 2 - w ** 2 + 2j * mm.zeta[1:] * wr * w)).sum(axis=1)
    Hm *= side.truth["sensor_gain"][ch] / side.truth["hammer"]["sensor_gain"]
    ratio = H[band] / Hm
    assert band.sum() > 50
    assert 0.85 < np.median(np.abs(ratio)) < 1.2
    assert abs(np.degrees(np.median(np.angle(ratio)))) < 10.0
    with pytest.raises(ValueError, match="diagonal"):
        rig.impact(0.5, 20.0, 1.0, location="pinion_shaft_end", direction="diagonal")


def test_impact_command_line(tmp_path):
    from rigs.beam.__main__ import main
    from twin.measurements import load_measurements
    out = tmp_path / "impact.h5"
    assert main(["impact", "--seed", "2", "--speed", "0.5", "--duration", "0.3",
                 "--location", "gear_shaft_end", "--out", str(out)]) == 0
    rec = load_measurements(out)[0]
    assert rec.units["hammer"] == "N" and rec.metadata["impact_location"] == "gear_shaft_end"
    assert main(["impact", "--rate", "0", "--out", str(tmp_path / "x.h5")]) == 2
    side = tmp_path / "side.h5"
    assert main(["impact", "--seed", "2", "--speed", "0.5", "--duration", "0.3", "--location",
                 "gear_shaft_end", "--direction", "horizontal", "--out", str(side)]) == 0
    assert load_measurements(side)[0].metadata["impact_direction"] == "horizontal"
