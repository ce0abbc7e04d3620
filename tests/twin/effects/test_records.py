"""Several records of one gearbox: reading them, the run-up's signatures, the held-out run, the verdict."""
from __future__ import annotations

import numpy as np
import pytest

from twin.effects.verdict import Candidate, Evidence, judge
from twin.errors import MeasurementError, ParameterError

FS = 10_000.0
Z1, Z2 = 19, 71


def _speed_record(name, speed, x, **kw):
    from twin.measurements import Record
    return Record(name, {"accel_pinion_casing": x, "tacho": speed}, {"accel_pinion_casing": "m/s2", "tacho": "Hz"},
                  FS, nominal_speed=20.0, load=20.0, **kw)


def _gearbox_signal(speed, *, line_hz=None, runout=0.0, seed=0):
    """Mesh harmonics (orders 19, 38, 57) with first pinion sidebands of relative size ``runout``,
    an optional line fixed at ``line_hz``, and white noise; ``speed`` (n,) [Hz]."""
    rng = np.random.default_rng(seed)
    angle = 2 * np.pi * np.cumsum(speed) / FS
    x = 0.2 * rng.standard_normal(speed.size)
    for k in (1, 2, 3):
        x += np.sin(k * Z1 * angle)
        for s in (-1, 1):
            x += runout * np.sin((k * Z1 + s) * angle)
    if line_hz:
        x += 0.5 * np.sin(2 * np.pi * line_hz * np.arange(speed.size) / FS)
    return x


def _write(path, *, runout=0.0, line_hz=None):
    from twin.measurements import write_measurements
    steady_speed = np.full(int(2 * FS), 20.0)
    ramp = np.linspace(8.0, 20.0, int(6 * FS))
    write_measurements([_speed_record("steady", steady_speed, _gearbox_signal(steady_speed, runout=runout,
                                                                              line_hz=line_hz)),
                        _speed_record("runup", ramp, _gearbox_signal(ramp, runout=runout, line_hz=line_hz, seed=1))],
                       path)
    return path


def test_records_are_read_by_name_and_a_runup_told_from_a_steady_record(tmp_path):
    from twin.effects.records import read_records
    path = _write(tmp_path / "m.h5")
    steady, runup = read_records(path, every=True)
    assert (steady.name, steady.runup, runup.name, runup.runup) == ("steady", False, "runup", True)
    assert np.median(runup.shaft_hz[:1000]) == pytest.approx(8.0, abs=0.1)
    assert [r.name for r in read_records(path, names=["runup", "steady"])] == ["runup", "steady"]
    assert [r.name for r in read_records(path)] == ["steady"]
    with pytest.raises(MeasurementError, match="run9.*steady, runup"):
        read_records(path, names=["steady", "run9"])
    with pytest.raises(MeasurementError, match="given twice"):
        read_records(path, names=["steady", "steady"])


def test_a_runup_alone_is_refused_before_anything_runs(tmp_path, gearbox_fmu):
    from twin.effects.diagnose import diagnose
    from twin.effects.records import read_records
    runup = read_records(_write(tmp_path / "m.h5"), names=["runup"])
    with pytest.raises(ParameterError, match="all run-ups"):
        diagnose(gearbox_fmu, runup)


def test_signatures_tell_shaft_sidebands_and_a_fixed_line_apart(tmp_path):
    """A run-out puts first pinion sidebands on every mesh harmonic, locked to the shaft through the
    run-up; a drive line stays at its frequency. Each test finds its own signature and not the other."""
    from twin.effects.records import read_records
    from twin.effects.signatures import signature, survey_records
    fitted = {"motor_torque_ripple.frequency": 113.0, "housing_mode.frequency": 2000.0}
    for runout, line in ((0.3, None), (0.0, 113.0)):
        steady, runup = read_records(_write(tmp_path / f"m{runout}.h5", runout=runout, line_hz=line), every=True)
        survey = survey_records([steady], runup, "accel_pinion_casing", Z1, Z2, {"steady": 20.0})
        assert signature("pinion_eccentricity", fitted, survey)[0] is (runout > 0)
        assert signature("gear_eccentricity", fitted, survey)[0] is False
        assert signature("motor_torque_ripple", fitted, survey)[0] is (line is not None)
        assert signature("housing_mode", fitted, survey)[0] is False
        assert signature("backlash", fitted, survey)[0] is None               # no test: held-out record only
    assert signature("pinion_eccentricity", fitted, None)[0] is None          # one record: not tested


def _cand(effect, score, held=(), sig=None, explains=("a",)):
    ev = tuple(Evidence(f, "resonance", "", 1.0, 0.1) for f in explains)
    return Candidate(effect, effect, score, 10.0 * (1 - score), {}, ev, (), 10, None, tuple(held), sig, "why")


def test_an_effect_must_hold_on_the_held_out_record_show_its_signature_and_not_tie():
    from twin.compare import Comparison, Finding
    before = Comparison(10.0, 0.5, 0.5, 1.0, 1.0, 20.0, (Finding("resonance", "a", 900, (850, 950), 9.0, 0.9),),
                        np.zeros(1), np.zeros(1), np.zeros(1))
    good = _cand("housing_mode", 0.5, [("runup", 8.0, 7.0)], True)
    assert judge(before, [good])[:2] == ("missing_effect", "housing_mode")
    # it cut the fit but not the run-up it was not fitted on: a flexible candidate absorbing base error
    overfit = _cand("housing_mode", 0.5, [("runup", 8.0, 8.02)], True)
    verdict, missing, _, msg, _ = judge(before, [overfit])
    assert (verdict, missing) == ("unexplained", None) and "did not earn its place" in msg and "runup" in msg
    # the held-out record agrees but the run-up shows no such band
    assert judge(before, [_cand("housing_mode", 0.5, [("runup", 8.0, 7.0)], False)])[0] == "unexplained"
    # the runner-up earned its place too: the next best that did is named, not the first
    assert judge(before, [overfit, _cand("backlash", 0.4, [("runup", 8.0, 7.5)], None)])[1] == "backlash"
    # two that explain the same findings with close scores are a tie, neither added
    verdict, missing, _, msg, tied = judge(before, [good, _cand("pinion_eccentricity", 0.45, [("runup", 8.0, 7.2)],
                                                                True)])
    assert (verdict, missing, tied) == ("tie", None, ("housing_mode", "pinion_eccentricity"))
    # a clearly weaker one, or one explaining something else, is no tie
    assert judge(before, [good, _cand("backlash", 0.3, [("runup", 8.0, 7.5)])])[0] == "missing_effect"
    assert judge(before, [good, _cand("backlash", 0.45, [("runup", 8.0, 7.5)], explains=("b",))])[0] == \
        "missing_effect"


def test_the_model_follows_a_measured_speed_profile(gearbox_fmu):
    """The held-out run-up: the drive follows the record's speed, so the mesh line sweeps with it."""
    from twin.effects.records import simulate_runup
    fs = 20_000.0
    speed = np.linspace(17.0, 20.0, int(0.4 * fs))
    y = simulate_runup(gearbox_fmu, {}, speed, 20.0, fs, "accel_pinion_casing")
    assert y.shape == speed.shape and np.all(np.isfinite(y))
    n = y.size // 4
    peaks = []
    for part, sp in ((y[:n], speed[:n]), (y[-n:], speed[-n:])):
        f = np.fft.rfftfreq(8 * n, 1 / fs)
        a = np.abs(np.fft.rfft(part * np.hanning(n), 8 * n))
        band = (f > 250) & (f < 450)
        peaks.append((f[band][np.argmax(a[band])], Z1 * sp.mean()))
    for got, expected in peaks:
        assert got == pytest.approx(expected, rel=0.03)
    assert peaks[1][0] > peaks[0][0] + 30


def test_improve_starts_from_a_diagnosis_of_the_same_scenario_and_refuses_another(tmp_path, gearbox_fmu, capsys):
    import json

    import yaml

    from twin.cli import main
    meas = _write(tmp_path / "m.h5")
    scen = tmp_path / "s.yaml"
    scen.write_text(yaml.safe_dump({"version": 1, "name": "s", "fmu": str(gearbox_fmu), "stop_time": 1.0}))
    diag = {"scenario": "s", "fmu": str(gearbox_fmu), "measurements": str(meas.resolve()), "records": ["steady"],
            "duration": 2.0, "record": "steady", "verdict": "nothing_missing", "missing": None, "candidates": [],
            "headline": {"log_spectral_distance_db": 0.4}}
    (tmp_path / "d.json").write_text(json.dumps(diag))
    # the diagnosis is taken as it is: nothing is simulated, the loop stops at its verdict
    assert main(["improve", str(scen), "--measurements", str(meas), "--out", str(tmp_path / "o"),
                 "--from-diagnosis", str(tmp_path / "d.json")]) == 0
    steps = json.loads((tmp_path / "o" / "history.json").read_text())["steps"]
    assert [(s["effect"], s["verdict"], s["lsd_before_db"]) for s in steps] == [(None, "nothing_missing", 0.4)]
    assert not (tmp_path / "o" / "diagnosis_1.json").exists()
    (tmp_path / "d2.json").write_text(json.dumps({**diag, "scenario": "other-gearbox"}))
    assert main(["improve", str(scen), "--measurements", str(meas), "--out", str(tmp_path / "o2"),
                 "--from-diagnosis", str(tmp_path / "d2.json")]) == 2
    assert "other-gearbox" in capsys.readouterr().err and not (tmp_path / "o2").exists()
    assert main(["improve", str(scen), "--measurements", str(meas), "--out", str(tmp_path / "o3"), "--record",
                 "runup", "--from-diagnosis", str(tmp_path / "d.json")]) == 2
    assert "runup" in capsys.readouterr().err


def test_a_hidden_mode_is_fitted_on_the_steady_record_and_held_out_on_the_runup(gearbox_fmu, candidates_fmu,
                                                                                  executor):
    """Records made by the candidate model with a casing mode switched on (plumbing, not evidence):
    the mode is fitted on the steady record, cuts the discrepancy on the run-up it was not fitted
    on, and its band is fixed across the run-up."""
    from twin.effects.catalogue import CATALOGUE
    from twin.effects.diagnose import diagnose
    from twin.effects.records import Record, simulate_runup
    from twin.operating import Operating, simulate_at
    fs = 20_000.0
    truth = {e.parameter(k): v for e in CATALOGUE.values() for k, v in e.neutral.items()}
    truth.update({"housing_mode.frequency": 1500.0, "housing_mode.participation": 0.8,
                  "housing_mode.damping_ratio": 0.02})
    rng = np.random.default_rng(3)
    n = int(0.5 * fs)
    op = Operating(20.0, 20.0, 20.0, fs)
    steady = simulate_at(candidates_fmu, truth, op, n, "accel_pinion_casing")
    ramp = np.linspace(14.0, 20.0, int(1.0 * fs))
    runup = simulate_runup(candidates_fmu, truth, ramp, 20.0, fs, "accel_pinion_casing")
    noise = 0.02 * np.std(steady)
    recs = [Record("steady", steady + noise * rng.standard_normal(n), fs, 20.0, 20.0, np.full(n, 20.0)),
            Record("runup", runup + noise * rng.standard_normal(ramp.size), fs, 20.0, 20.0, ramp)]
    d = diagnose(gearbox_fmu, recs, candidates_fmu=candidates_fmu, executor=executor, duration=0.5,
                 effects=["housing_mode"], max_evals=8, related_leaders=0, held_out_runup=0.5)
    c, = d.candidates
    assert d.held_out_records == ("runup",) and c.held_out and c.held_out[0][0] == "runup"
    assert c.held_out_cut() > 0.5
    assert (d.verdict, d.missing) == ("missing_effect", "housing_mode"), d.message
    assert c.signature_present is None         # Records without the loaded run-up: no survey


def _encoder_file(path, *, runout: float, seed: int):
    """One steady record with an angle encoder: a pinion angle with a once-per-turn line of
    ``runout`` rad over a small healthy one, a gear-speed line, and a casing signal without sidebands."""
    from twin.measurements import Record, write_measurements
    n = int(2 * FS)
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    angle = (2 * np.pi * 20.0 * t + (2e-5 + runout) * np.sin(2 * np.pi * 20.0 * t)
             + 1e-4 * np.sin(2 * np.pi * 20.0 * Z1 / Z2 * t + 0.3) + 1e-7 * rng.standard_normal(n))
    x = _gearbox_signal(np.full(n, 20.0), seed=seed)
    write_measurements([Record("steady", {"accel_pinion_casing": x, "encoder": angle},
                               {"accel_pinion_casing": "m/s2", "encoder": "rad"}, FS, nominal_speed=20.0, load=20.0,
                               tachometer="encoder", tachometer_kind="angle")], path)
    return path


def test_an_encoders_once_per_turn_line_is_a_runouts_signature_where_the_casing_shows_none(tmp_path):
    """Below the first torsional mode a run-out turns the shafts (bench/encoder_rigs.py): the
    encoder's line at the pinion speed that rose since the baseline is the pinion run-out's
    signature although the casing has no sidebands; not the gear's, nor a local fault's."""
    from twin.effects.records import read_records
    from twin.effects.signatures import ENCODER_RISE_DB, signature, survey_records
    base, = read_records(_encoder_file(tmp_path / "base.h5", runout=0.0, seed=1))
    later, = read_records(_encoder_file(tmp_path / "later.h5", runout=4e-4, seed=2))
    same, = read_records(_encoder_file(tmp_path / "same.h5", runout=0.0, seed=3))
    assert base.angle is not None and base.angle.shape == base.signal.shape
    assert read_records(_write(tmp_path / "m.h5"))[0].angle is None         # a speed channel is no encoder
    for rec, seen in ((later, True), (same, False)):
        s = survey_records([rec], None, "accel_pinion_casing", Z1, Z2, {"steady": 20.0}, encoder=True,
                           baseline={"steady": base})
        assert s.encoder_basis == "baseline"
        assert (s.encoder_lines["steady"]["pinion"] >= ENCODER_RISE_DB) is seen
        assert s.steady_sidebands["steady"]["pinion"] == 0                    # the casing shows nothing
        present, text = signature("pinion_eccentricity", {}, s)
        assert present is seen and "encoder" in text
        assert signature("gear_eccentricity", {}, s)[0] is False
        assert signature("local_tooth_damage", {}, s)[0] is False
    # without the encoder the casing's test alone: absent
    s = survey_records([later], None, "accel_pinion_casing", Z1, Z2, {"steady": 20.0})
    assert signature("pinion_eccentricity", {}, s)[0] is False


def test_the_encoder_is_compared_only_when_model_records_and_baseline_all_have_one(tmp_path):
    from twin.angular import ANGLE_OUTPUT
    from twin.effects.baseline import Discrepancy
    from twin.effects.diagnose import uses_encoder
    from twin.effects.records import read_records
    enc, = read_records(_encoder_file(tmp_path / "e.h5", runout=0.0, seed=1))
    plain, = read_records(_write(tmp_path / "m.h5"))
    outputs = frozenset({"accel_pinion_casing", ANGLE_OUTPUT})
    assert uses_encoder([enc], None, outputs) and uses_encoder([enc], [enc], outputs)
    assert not uses_encoder([enc], None, frozenset({"accel_pinion_casing"}))     # a model without the output
    assert not uses_encoder([enc, plain], None, outputs)
    assert not uses_encoder([enc], [plain], outputs)                               # the baseline has none
    d = Discrepancy("steady", np.zeros(2), np.zeros(2))
    assert not uses_encoder([enc], {"steady": d}, outputs)
    assert uses_encoder([enc], {"steady": Discrepancy("steady", np.zeros(2), np.zeros(2), d)}, outputs)


def test_a_runups_drive_follows_the_speeds_trend_not_the_shafts_wobble():
    """An encoder's speed carries the shaft's vibration (a run-out's once-per-turn wobble); the
    model's drive follows the trend, which keeps a ramp and leaves the wobble out."""
    from twin.effects.records import speed_trend
    fs = 50_000.0
    t = np.arange(int(2 * fs)) / fs
    ramp = 14.0 + 3.0 * t + 0.2 * np.sin(2 * np.pi * 0.3 * t)
    wobble = 0.5 * np.sin(2 * np.pi * 17.0 * t)
    trend = speed_trend(ramp + wobble, fs)
    assert np.sqrt(np.mean((trend - ramp) ** 2)) < 0.1 * np.sqrt(np.mean(wobble ** 2))      # 20 dB down
    assert speed_trend(np.linspace(2.0, 20.0, int(6 * fs)), fs) == pytest.approx(np.linspace(2.0, 20.0, int(6 * fs)))
