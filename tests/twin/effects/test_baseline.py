"""The model's discrepancy learned on baseline records and taken out of later ones."""
from __future__ import annotations

import numpy as np
import pytest

from twin.effects.baseline import Discrepancy, pair
from twin.effects.records import Record
from twin.errors import ParameterError


def _line(f0: float, fs: float = 20000.0, n: int = 40000, amp: float = 1.0) -> np.ndarray:
    return amp * np.sin(2 * np.pi * f0 * np.arange(n) / fs)


def test_the_discrepancy_is_taken_out_of_the_compared_levels_by_hand():
    """A record no different from its baseline stands at the model once the discrepancy learned
    there is taken out, whatever the model's form error (a 20 dB path resonance it lacks); a line
    that appeared since stays, at its size. The discrepancy is read at the comparison's own bins,
    also on a shorter stretch's coarser grid."""
    from twin.compare import spectral_levels
    from twin.effects.fit import _Objective
    from twin.signals import welch_psd

    fs, n = 20000.0, 40000
    rng = np.random.default_rng(1)
    model = rng.standard_normal(n) + _line(380.0, amp=3.0)

    def measured(seed, extra=0.0):        # the model's content through a path resonance, noise, a new line
        r = np.random.default_rng(seed)
        return (_resonance(model, fs) + 0.05 * r.standard_normal(n) + _line(1234.0, amp=extra))

    then, same, changed = measured(2), measured(3), measured(4, extra=2.0)
    objective = _Objective(then, fs)
    f, pp = welch_psd(then, fs, resolution=objective.resolution)
    _, pm = welch_psd(model, fs, resolution=objective.resolution)
    lp, lm, _ = spectral_levels(pm[objective.band], pp[objective.band])
    level = np.zeros(f.size)
    level[objective.band] = lp - lm
    d = Discrepancy("then", f, level)
    assert _Objective(same, fs)(model) > 2.0                          # the path resonance, 20 dB
    assert _Objective(same, fs, discrepancy=d)(model) < 0.2           # taken out: estimation scatter
    short = _Objective(same[-n // 2:], fs, discrepancy=d)
    assert short.resolution > objective.resolution and short(model) < 1.0
    with_line = _Objective(changed, fs, discrepancy=d)
    lp2, lm2, _ = spectral_levels(welch_psd(model, fs, resolution=with_line.resolution)[1][with_line.band],
                                  with_line.pp)
    k = np.argmin(np.abs(f[objective.band] - 1234.0))
    assert (lp2 - with_line.offset - lm2)[k] > 20.0                    # what changed is left


def test_a_baseline_read_at_another_speed_moves_its_lines_not_its_resonances():
    """Records of one gearbox 1.6 % apart in speed: seven mesh lines through a path resonance
    (Q = 8 at 1500 Hz, fixed in frequency) on broadband noise. The baseline read at the record's
    speed has its lines where the record has them, and its resonance where it was: closer to the
    record over the resonance than the baseline carried whole in orders, as close on the lines."""
    from twin.effects.baseline import at_speed
    from twin.signals import welch_psd

    fs, n = 20000.0, 200000

    def record(speed, seed):
        r = np.random.default_rng(seed)
        t = np.arange(n) / fs
        x = r.standard_normal(n) + sum(2.0 * np.sin(2 * np.pi * 19 * k * speed * t + k) for k in range(1, 8))
        return _resonance(x, fs) + 0.05 * r.standard_normal(n)

    f, then = welch_psd(record(20.0, 1), fs, resolution=2.0)
    _, now = welch_psd(record(20.32, 2), fs, resolution=2.0)
    ratio = 20.0 / 20.32
    assert np.array_equal(at_speed(f, then, 1.0), then)

    def rms_db(a, where):
        return float(np.sqrt(np.mean((10 * np.log10(a / now))[where] ** 2)))

    resonance = (f > 1300) & (f < 1700)
    lines = np.zeros(f.size, bool)
    for k in range(1, 8):
        lines |= np.abs(f - 19 * k * 20.32) < 3
    split, orders = at_speed(f, then, ratio), np.interp(f * ratio, f, then)
    assert rms_db(split, resonance) < rms_db(orders, resonance) - 0.5
    assert rms_db(split, lines) < rms_db(orders, lines) + 0.1 < 3.0        # the lines moved (30 dB if not)
    assert rms_db(then, lines) > 20.0


def test_records_are_paired_with_their_baseline_by_name_then_by_kind():
    speed = np.full(100, 20.0)
    sweep = np.linspace(5.0, 20.0, 100)

    rng = np.random.default_rng(0)

    def rec(name, shaft=speed):
        return Record(name, rng.standard_normal(100), 1000.0, 20.0, 20.0, shaft)

    steady, runup, other = rec("steady"), rec("runup", sweep), rec("steady_2")
    base = [rec("steady"), rec("healthy_runup", sweep)]
    got = pair([steady, runup, other], base)
    assert got["steady"] is base[0] and got["steady_2"] is base[0] and got["runup"] is base[1]
    with pytest.raises(ParameterError, match="no baseline for record runup.*hold no run-up"):
        pair([steady, runup], [rec("steady")])
    standstill = Record("steady", rng.standard_normal(100), 1000.0, 0.0, 20.0, speed)
    with pytest.raises(ParameterError, match="baseline steady was taken at 0 Hz"):
        pair([steady], [standstill])


def _resonance(x: np.ndarray, fs: float, f0: float = 1500.0, gain_db: float = 20.0, q: float = 8.0) -> np.ndarray:
    """x through a peaking filter (RBJ biquad): a mode of the real gearbox's path the model lacks."""
    from scipy.signal import lfilter
    a_ = 10 ** (gain_db / 40)
    w0 = 2 * np.pi * f0 / fs
    alpha = np.sin(w0) / (2 * q)
    b = [1 + alpha * a_, -2 * np.cos(w0), 1 - alpha * a_]
    a = [1 + alpha / a_, -2 * np.cos(w0), 1 - alpha / a_]
    return lfilter(b, a, x)


@pytest.mark.slow
def test_a_path_error_in_every_record_is_not_blamed_on_an_effect_with_a_baseline(gearbox_fmu, candidates_fmu,
                                                                                   executor, tmp_path):
    """The gearbox's path has a resonance the model lacks, in the baseline and in the record; a
    motor ripple appeared since. With the baseline the diagnosis names the ripple; the
    discrepancy learned from files once (as twin improve does) gives the same diagnosis."""
    from twin.effects.diagnose import diagnose
    from twin.effects.synthetic import calibrate_base, make_case

    then = make_case(None, 3, candidates_fmu=candidates_fmu)
    now = make_case("motor_torque_ripple", 3, candidates_fmu=candidates_fmu)
    params = calibrate_base(then, gearbox_fmu)

    def record(case, name):
        return Record(name, _resonance(case.signal, case.sample_rate), case.sample_rate, case.nominal_speed,
                      case.load)

    d = diagnose(gearbox_fmu, [record(now, "now")], parameters=params, candidates_fmu=candidates_fmu,
                 executor=executor, duration=now.duration, baseline=[record(then, "then")],
                 effects=["motor_torque_ripple", "housing_mode", "load_torque_fluctuation"])
    assert d.baseline == ("then",)
    assert (d.verdict, d.missing) == ("missing_effect", "motor_torque_ripple"), d.table()
    fitted = d.candidates[0].fitted["motor_torque_ripple.frequency"]
    assert fitted == pytest.approx(now.truth_parameters["motor_torque_ripple.frequency"], rel=0.01)

    from dataclasses import replace

    import yaml

    from twin.effects.loop import learn_discrepancy, read_baseline
    from twin.effects.records import read_records
    from twin.effects.synthetic import write_case
    from twin.scenario import load_scenario
    files = {name: write_case(replace(case, signal=_resonance(case.signal, case.sample_rate)), tmp_path / f"{name}.h5")
             for name, case in (("then", then), ("now", now))}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({"version": 1, "name": "s", "fmu": str(gearbox_fmu),
                                                      "stop_time": 1.0, "parameters": params}))
    scenario = load_scenario(tmp_path / "s.yaml")
    learned = learn_discrepancy(scenario, files["now"], read_baseline(files["then"], scenario))
    assert list(learned) == ["record"]
    again = diagnose(gearbox_fmu, read_records(files["now"]), parameters=params, candidates_fmu=candidates_fmu,
                     executor=executor, duration=now.duration, baseline=learned,
                     effects=["motor_torque_ripple", "housing_mode", "load_torque_fluctuation"])
    assert (again.verdict, again.missing) == (d.verdict, d.missing)
    assert again.lsd_db == pytest.approx(d.lsd_db, rel=1e-6)


def test_the_cli_refuses_a_baseline_it_cannot_use_by_name(tmp_path, gearbox_fmu, capsys):
    """No record of the diagnosed names, the record itself, another operating point: each a
    one-line error naming the values, before any simulation."""
    import yaml

    from twin.cli import main
    from twin.measurements import Record as MRecord, write_measurements
    from tests.twin.effects.test_records import _write

    meas = _write(tmp_path / "now.h5", runout=0.1)
    scen = tmp_path / "s.yaml"
    scen.write_text(yaml.safe_dump({"version": 1, "name": "s", "fmu": str(gearbox_fmu), "stop_time": 1.0}))
    other = tmp_path / "other.h5"
    write_measurements([MRecord("healthy", {"accel_pinion_casing": np.zeros(20000)}, {"accel_pinion_casing": "m/s2"},
                                10000.0, nominal_speed=10.0, load=20.0)], other)
    cmd = ["diagnose", str(scen), "--measurements", str(meas), "--record", "steady", "--record", "runup"]
    assert main([*cmd, "--baseline", str(other)]) == 2
    err = capsys.readouterr().err
    assert "healthy" in err and "--baseline-record" in err and len(err.strip().splitlines()) == 1
    assert main([*cmd, "--baseline", str(meas)]) == 2
    assert "record steady is its own baseline" in capsys.readouterr().err
    assert main([*cmd, "--baseline", str(other), "--baseline-record", "healthy"]) == 2
    err = capsys.readouterr().err
    assert "baseline healthy was taken at 10 Hz" in err and "record steady at 20 Hz" in err


def test_repeated_baseline_records_give_the_record_to_record_scatter_that_raises_the_line_threshold():
    """A line that reads 6 dB apart in two healthy records is scatter there, not elsewhere; a
    change of 8 dB at that line is then no finding, while the same change at a steady line is."""
    from twin.compare import compare_signals
    from twin.effects.baseline import DiscrepancySpec, _scatter, repeated
    from twin.effects.fit import _Objective

    fs, n = 20000.0, 40000
    rng = np.random.default_rng(4)

    def healthy(seed, wander=1.0):
        r = np.random.default_rng(seed)
        return r.standard_normal(n) + _line(380.0, amp=30.0) + _line(700.0, amp=10.0 * wander)

    b, again = healthy(1), healthy(2, wander=2.0)            # the 700 Hz line 6 dB apart
    spec = DiscrepancySpec("steady", "unused.fmu", {}, "accel", b, fs, 20.0, baseline_hz=20.0,
                           repeats=(("steady_again", again, None, 20.0),))
    objective = _Objective(b, fs)
    scatter, angle_scatter = _scatter(spec, objective, objective.psd[objective.band], None, 20.0)
    f = objective.frequencies
    assert angle_scatter is None
    assert scatter[np.argmin(np.abs(f - 700.0))] == pytest.approx(6.0, abs=1.0)
    assert np.median(scatter[objective.band]) < 1.0 and scatter[np.argmin(np.abs(f - 380.0))] < 1.5

    d = Discrepancy("steady", f, np.zeros(f.size), scatter_db=scatter)
    later = healthy(3, wander=2.5) + _line(380.0, amp=75.0)    # 700 Hz +8 dB, 380 Hz +8 dB
    model = healthy(1)
    without = compare_signals(model, later, fs, 20.0, z1=19, z2=52, discrepancy=Discrepancy("steady", f,
                                                                                            np.zeros(f.size)))
    found = compare_signals(model, later, fs, 20.0, z1=19, z2=52, discrepancy=d)
    near = lambda c, fc: [x for x in c.findings if x.band_hz[0] - 2 <= fc <= x.band_hz[1] + 2]  # noqa: E731
    assert near(without, 700.0) and near(without, 380.0)
    assert not near(found, 700.0) and near(found, 380.0)

    steady = Record("steady", b, fs, 20.0, 20.0)
    others = [Record("steady_2", again, fs, 20.0, 20.0), Record("light", again, fs, 20.0, 5.0),
              Record("runup", again, fs, 20.0, 20.0, np.linspace(5.0, 20.0, n)), steady]
    assert [o.name for o in repeated(steady, others)] == ["steady_2"]


def test_the_encoder_channel_learns_its_own_scatter_from_repeats_with_an_angle():
    """The angle's line at the gear's speed 6 dB apart in two healthy records: the encoder's
    scatter reads it there and little elsewhere; without an angle in a repeat there is none."""
    from twin.angular import AngularObjective
    from twin.effects.baseline import DiscrepancySpec, _scatter
    from twin.effects.fit import _Objective

    fs, n = 20000.0, 40000
    t = np.arange(n) / fs

    def angle(size, seed):
        r = np.random.default_rng(seed)
        return (2 * np.pi * 20.0 * t + size * np.sin(2 * np.pi * 7.31 * t) + 1e-4 * np.sin(2 * np.pi * 40.0 * t)
                + 1e-7 * r.standard_normal(n))

    x = np.random.default_rng(0).standard_normal(n)
    spec = DiscrepancySpec("steady", "unused.fmu", {}, "accel", x, fs, 20.0, baseline_hz=20.0,
                           angle=angle(1e-3, 1), repeats=(("steady_again", x, angle(2e-3, 2), 20.0),))
    objective = _Objective(x, fs)
    ao = AngularObjective(spec.angle, fs, objective.resolution)
    _, scatter = _scatter(spec, objective, objective.psd[objective.band], ao, 20.0)
    f = ao.frequencies[ao.band]
    assert scatter[np.argmin(np.abs(f - 7.31))] == pytest.approx(6.0, abs=1.5)
    assert scatter[np.argmin(np.abs(f - 40.0))] < 1.5
    no_angle = DiscrepancySpec("steady", "unused.fmu", {}, "accel", x, fs, 20.0, baseline_hz=20.0,
                               angle=spec.angle, repeats=(("steady_again", x, None, 20.0),))
    assert _scatter(no_angle, objective, objective.psd[objective.band], ao, 20.0)[1] is None


def test_learn_all_names_the_repeats_and_the_diagnosis_reports_them(gearbox_fmu):
    """A further steady baseline record at the same operating point is learned as a repeat (its
    name kept with the discrepancy); one at another load is not; the diagnosis's table says so."""
    from twin.effects.baseline import learn_all
    from twin.effects.verdict import Diagnosis
    from twin.operating import Operating

    fs, n = 50000.0, 25000
    rng = np.random.default_rng(7)

    def rec(name, load=20.0):
        return Record(name, rng.standard_normal(n), fs, 20.0, load, np.full(n, 19.6))

    out = learn_all(gearbox_fmu, {}, [rec("later")], [rec("steady"), rec("steady_again"), rec("light", 5.0)],
                    "accel_pinion_casing", duration=0.5)
    d = out["later"]
    assert d.record == "steady" and d.repeats == ("steady_again",)
    assert d.scatter_db is not None and np.all(d.scatter_db >= 0)
    diag = Diagnosis("later", 2.0, (), (), "nothing_missing", None, (), "", Operating(20, 20, 19.6, fs), 1.0,
                     baseline=("steady",), baseline_repeats=d.repeats)
    assert "the line threshold raised by how far steady_again differs" in diag.table()
    assert diag.to_dict()["baseline_repeats"] == ["steady_again"]
