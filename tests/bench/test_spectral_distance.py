"""The benchmark's own spectral distance: zero for the same shape, blind to gain and to what lies
under the measurement's noise floor, and growing with a missing resonance."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from scipy import signal as sps

_spec = importlib.util.spec_from_file_location(
    "spectral_distance", Path(__file__).resolve().parents[2] / "bench" / "spectral_distance.py")
sd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sd)

FS = 10000.0


def _signal(seed, resonance=True, n=40000):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n)
    t = np.arange(n) / FS
    x = x + 5 * np.sin(2 * np.pi * 380 * t)
    if resonance:
        b, a = sps.iirpeak(1500.0, 10.0, FS)
        x = x + 20 * sps.lfilter(b, a, rng.standard_normal(n))
    return x


def test_same_shape_any_gain_is_close_to_zero():
    clean = _signal(0)
    measured = clean + 0.01 * np.random.default_rng(7).standard_normal(clean.size)
    report = sd.spectral_distance_report(3.0 * clean, measured, FS)
    assert report["distance_db"] < 0.5 and abs(report["gain_db"] + 20 * np.log10(3.0)) < 0.5
    other = sd.spectral_distance_report(3.0 * _signal(1), measured, FS)      # another draw of the same process
    assert other["distance_db"] < 2.5


def test_a_missing_resonance_counts_and_silence_under_the_noise_does_not():
    measured = _signal(0) + 0.01 * np.random.default_rng(5).standard_normal(40000)
    without = sd.log_spectral_distance(_signal(1, resonance=False), measured, FS)
    with_it = sd.log_spectral_distance(_signal(1), measured, FS)
    assert without > with_it + 1.0
    quiet = np.zeros(40000)
    noise = 1e-3 * np.random.default_rng(2).standard_normal(40000)
    assert sd.log_spectral_distance(quiet, noise, FS) < 1e-9


def test_the_command_line_scores_each_model_against_the_end_of_the_record(tmp_path, capsys):
    from twin.measurements import Record, write_measurements
    measured = _signal(0, n=50000) + 0.01 * np.random.default_rng(5).standard_normal(50000)
    write_measurements([Record("steady", {"accel_pinion_casing": measured}, {"accel_pinion_casing": "m/s2"}, FS,
                               nominal_speed=20.0, load=20.0)], tmp_path / "rig.h5")
    models = [Record(name, {"accel_pinion_casing": 2.0 * _signal(1, resonance=r)}, {"accel_pinion_casing": "m/s2"},
                     FS, nominal_speed=20.0, load=20.0) for name, r in (("before", False), ("after", True))]
    write_measurements(models, tmp_path / "models.h5")
    assert sd.main([str(tmp_path / "rig.h5"), "--record", "steady", "--models", str(tmp_path / "models.h5")]) == 0
    out = capsys.readouterr().out.splitlines()
    rows = {line.split()[0]: float(line.split()[1]) for line in out if line.split()[0] in ("before", "after")}
    assert rows["after"] < rows["before"] - 3.0
    assert out[-1].startswith(f"change: {rows['after'] - rows['before']:+.2f} dB")
    with pytest.raises(SystemExit):
        sd.main([str(tmp_path / "rig.h5"), "--record", "runup", "--models", str(tmp_path / "models.h5")])


def _geared(seed, speed, sideband=0.0, n=40000):
    """Noise, a resonance at 1500 Hz and mesh lines (orders 19, 38) of a shaft at ``speed`` [Hz],
    with first sidebands of relative size ``sideband``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    b, a = sps.iirpeak(1500.0, 10.0, FS)
    x = 0.3 * rng.standard_normal(n) + 5 * sps.lfilter(b, a, rng.standard_normal(n))
    for k in (19, 38):
        x += 3 * np.sin(2 * np.pi * k * speed * t)
        for s in (-1, 1):
            x += 3 * sideband * np.sin(2 * np.pi * (k + s) * speed * t)
    return x


def test_the_change_distance_counts_what_changed_and_not_what_both_records_share():
    """A model-form error common to both records (the model has no resonance, its lines are 20 dB
    off) cancels; sidebands that appeared count until the model shows them too; records at speeds
    0.5 % apart are compared in shaft orders."""
    then, now = _geared(1, 20.0), _geared(2, 20.1, sideband=0.3)
    t = np.arange(40000) / FS

    def model(seed, speed, sideband=0.0):      # broadband excitation, no resonance, lines 20 dB down
        x = 0.03 * np.random.default_rng(seed).standard_normal(t.size)
        for k in (19, 38):
            x += 0.3 * np.sin(2 * np.pi * k * speed * t)
            for s in (-1, 1):
                x += 0.3 * sideband * np.sin(2 * np.pi * (k + s) * speed * t)
        return x

    model_then, model_now, showing = model(5, 20.0), model(6, 20.1), model(6, 20.1, sideband=0.3)
    speeds = (20.1, 20.0, 20.1, 20.0)
    quiet = sd.change_distance_report(model_then, model_then, _geared(4, 20.0), then, FS, (20.0,) * 4)
    blind = sd.change_distance_report(model_now, model_then, now, then, FS, speeds)
    shows = sd.change_distance_report(showing, model_then, now, then, FS, speeds)
    assert quiet["distance_db"] < 2.0                      # estimation scatter only
    assert blind["distance_db"] == pytest.approx(blind["measured_change_db"], rel=0.05)
    assert blind["distance_db"] > 2 * quiet["distance_db"]
    assert shows["distance_db"] < 0.5 * blind["distance_db"]
