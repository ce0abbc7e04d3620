from __future__ import annotations

import numpy as np
import pytest

from twin.compare import spectral_levels
from twin.effects.diagnose import active_effects, diagnose
from twin.effects.verdict import Candidate, judge
from twin.errors import MeasurementError, ParameterError


def test_spectral_levels_absorb_a_small_gain_error_but_not_a_large_one():
    rng = np.random.default_rng(0)
    pm = np.zeros(500)
    pm[::5] = 10 ** rng.uniform(-3, 0, 100)      # lines over a noise-free model floor
    pp = pm * 1.03 ** 2 + 1e-6                   # the measurement: 3 % gain and white noise
    lp, lm, g = spectral_levels(pm, pp)
    assert g == pytest.approx(20 * np.log10(1.03), abs=0.02)
    assert np.sqrt(np.mean((lp - lm) ** 2)) < 0.05
    _, _, g2 = spectral_levels(pm, pm * 10.0)        # +10 dB is not a sensor gain error
    assert g2 == pytest.approx(1.0)


def test_active_effects_are_read_from_parameter_names():
    assert active_effects(["k_pair[1]", "housing_mode.frequency", "backlash.gap", "solver.step_size"]) == \
        ["housing_mode", "backlash"]


def _comparison(*findings, lsd=10.0):
    from twin.compare import Comparison, Finding
    return Comparison(lsd, 0.5, 0.5, 1.0, 1.0, 20.0,
                      tuple(Finding(kind, f"{kind} near {f:.0f} Hz", f, (f - 50, f + 50), size, share)
                            for kind, f, size, share in findings),
                      np.zeros(1), np.zeros(1), np.zeros(1))


def test_judge_tells_a_missing_effect_a_base_model_off_and_the_rest_apart():
    """The verdict from a baseline and its best candidate: an effect when it cuts the discrepancy
    enough; the base model when the level is off in several bands and no effect helps; an
    unlocked line nobody explains is unexplained; no finding, nothing missing."""
    weak = Candidate("housing_mode", "housing mode", 0.05, 9.5, {}, (), (), 30)
    strong = Candidate("housing_mode", "housing mode", 0.6, 4.0, {}, (), (), 30)
    modes_off = _comparison(("resonance", 636, 12.0, 0.3), ("resonance", 1728, -9.0, 0.25),
                            ("mesh_harmonic", 385, 7.0, 0.1))
    verdict, missing, unexplained, msg, _ = judge(modes_off, [weak])
    assert (verdict, missing, len(unexplained)) == ("base_not_calibrated", None, 3)
    assert "636 Hz (+12 dB), 1728 Hz (-9 dB)" in msg and "--modes-from" in msg
    assert judge(modes_off, [strong])[:2] == ("missing_effect", "housing_mode")
    one_band = _comparison(("resonance", 636, 12.0, 0.6), ("unlocked_line", 113, 15.0, 0.3))
    assert judge(one_band, [weak])[0] == "unexplained"                # one band: a missing resonance, perhaps
    small = _comparison(("resonance", 636, 7.0, 0.2), ("resonance", 1728, 7.0, 0.2), ("unlocked_line", 113, 15, 0.5))
    assert judge(small, [weak])[0] == "unexplained"                   # the bands hold under half the error
    assert judge(_comparison(lsd=0.4), [weak])[:3] == ("nothing_missing", None, ())
    # a series in the envelope counts though its band holds none of the spectral error
    verdict, _, unexplained, _, _ = judge(_comparison(("envelope_line", 72, 30.0, 0.0), lsd=0.4), [weak])
    assert (verdict, unexplained) == ("unexplained", ("envelope_line near 72 Hz",))
    assert judge(_comparison(lsd=0.4), [])[0] == "nothing_missing"


def test_bad_records_and_models_are_refused(gearbox_fmu, two_mass_fmu):
    with pytest.raises(MeasurementError, match="NaN"):
        diagnose(gearbox_fmu, np.full(20000, np.nan), 20000.0, 20.0, 20.0)
    with pytest.raises(MeasurementError, match="at least 0.25 s"):
        diagnose(gearbox_fmu, np.zeros(100), 20000.0, 20.0, 20.0)
    with pytest.raises(ParameterError, match="duration.*-1"):
        diagnose(gearbox_fmu, np.zeros(20000), 20000.0, 20.0, 20.0, duration=-1)
    with pytest.raises(ParameterError, match="not a GearTwin.Gearbox21 model"):
        diagnose(two_mass_fmu, np.zeros(20000), 20000.0, 20.0, 20.0)


def test_a_model_that_diverges_at_the_operating_point_is_refused_by_record(gearbox_fmu, monkeypatch):
    import twin.effects.diagnose as diag
    t = np.arange(20000) / 20000.0
    measured = np.sin(2 * np.pi * 19 * 20.0 * t) + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    monkeypatch.setattr(diag, "simulate_settled", lambda fmu, params, op, n, ch: (op, np.full(n, np.nan)))
    with pytest.raises(ParameterError, match="does not run at the operating point of record shop_floor "
                                             r"\(20\.\d\d Hz, 20 N\.m\).*NaN"):
        diagnose(gearbox_fmu, measured, 20000.0, 20.0, 20.0, record="shop_floor")


def test_starting_value_of_a_ripple_is_the_unlocked_line(gearbox_fmu):
    from twin.compare import compare_signals
    from twin.effects.diagnose import starting_values
    fs, shaft = 20000.0, 19.6
    t = np.arange(int(fs)) / fs
    gmf = 19 * shaft
    model = np.sin(2 * np.pi * gmf * t) + 0.3 * np.sin(2 * np.pi * 2 * gmf * t)
    measured = model + 0.05 * np.sin(2 * np.pi * 151.3 * t) + 1e-3 * np.random.default_rng(1).normal(size=t.size)
    comp = compare_signals(model, measured, fs, shaft)
    guess = starting_values(comp, measured, model, fs, shaft, 19, 52)
    assert guess["motor_torque_ripple"]["frequency"] == pytest.approx(151.3, abs=0.2)


def test_joint_refit_moves_the_related_base_parameter_toward_the_truth(candidates_fmu):
    """A run-out record from a gearbox whose mesh is 6 % stiffer than calibrated: refitting the
    related ``mesh_stiffness_scale`` with the run-out must lower the discrepancy and move it up."""
    from twin.effects.diagnose import TrialSpec, fit_effect, record_conditions
    from twin.effects.synthetic import _neutral
    from twin.operating import simulate_operating_point
    truth = {**_neutral(), "pinion_eccentricity.eccentricity": 2e-5, "mesh_stiffness_scale": 1.06}
    x = simulate_operating_point(candidates_fmu, 20.0, 20.0, parameters=truth, settle=0.15, duration=0.5,
                                 channels=["accel_pinion_casing"], output_interval=5e-5)[:, 0]
    x = x + np.random.default_rng(0).normal(0, 0.05 * x.std(), x.size)
    op = record_conditions(candidates_fmu, x, 20000.0, 20.0, 20.0, {}, duration=0.5).operating
    spec = dict(effect="pinion_eccentricity", fmu_path=str(candidates_fmu), channel="accel_pinion_casing",
                measured=x, operating=op, parameters=_neutral(), guesses={"eccentricity": 2e-5}, polish_only=True)
    _, lsd_alone, _, _ = fit_effect(TrialSpec(**spec))
    fitted, lsd_joint, n, sim = fit_effect(TrialSpec(**spec, related={"mesh_stiffness_scale": 1.0},
                                                     related_evals=10))
    assert lsd_joint < lsd_alone
    assert 1.02 < fitted["mesh_stiffness_scale"] <= 1.1 + 1e-12      # within RELATED_SPAN of 1.0
    assert n <= 11 and sim.shape == x.shape


def test_a_search_on_a_shorter_coarser_run_is_scored_on_the_whole_record(candidates_fmu):
    """The candidates' search runs on the last part of the record at a coarser step; the values it
    finds are simulated once more on the whole record at the operating point's step, and that
    run is what is returned and scored."""
    from twin.effects.diagnose import TrialSpec, fit_effect, record_conditions
    from twin.effects.fit import _Objective
    from twin.effects.synthetic import _neutral
    from twin.operating import simulate_operating_point
    truth = {**_neutral(), "pinion_eccentricity.eccentricity": 2e-5}
    x = simulate_operating_point(candidates_fmu, 20.0, 20.0, parameters=truth, settle=0.15, duration=0.5,
                                 channels=["accel_pinion_casing"], output_interval=5e-5)[:, 0]
    x = x + np.random.default_rng(0).normal(0, 0.05 * x.std(), x.size)
    op = record_conditions(candidates_fmu, x, 20000.0, 20.0, 20.0, {}, duration=0.5).operating
    fitted, lsd, n, sim = fit_effect(TrialSpec("pinion_eccentricity", str(candidates_fmu), "accel_pinion_casing", x,
                                               op, _neutral(), {}, search_samples=5000, search_step=2e-5))
    assert sim.shape == x.shape and lsd == pytest.approx(_Objective(x, 20000.0)(sim))
    assert fitted["pinion_eccentricity.eccentricity"] == pytest.approx(2e-5, rel=0.3)
    # per amplitude (eccentricity, wobble) 7 grid points and at most 8 polishing runs, then at most
    # max_evals - those (at least 4) together, and one scoring run
    assert n <= 2 * (7 + 8) + 4 + 1


def test_a_runout_only_the_encoder_sees_is_fitted_through_the_encoder_channel(candidates_fmu):
    """A record whose casing channel is the gearbox without the run-out and whose encoder angle is
    the gearbox with it (as on the beam rig, where the casing hardly sees it): fitted with the
    encoder, the run-out comes out at half its size or more; on the casing alone far smaller."""
    from twin.angular import ANGLE_OUTPUT
    from twin.effects.diagnose import TrialSpec, fit_effect, record_conditions
    from twin.effects.fit import _Objective
    from twin.effects.synthetic import _neutral
    from twin.operating import simulate_operating_point
    rng = np.random.default_rng(0)
    chans = ["accel_pinion_casing", ANGLE_OUTPUT]
    run = dict(settle=0.15, duration=0.5, channels=chans, output_interval=5e-5)
    healthy = simulate_operating_point(candidates_fmu, 20.0, 20.0, parameters=_neutral(), **run)
    runout = simulate_operating_point(candidates_fmu, 20.0, 20.0,
                                      parameters={**_neutral(), "pinion_eccentricity.eccentricity": 5e-5}, **run)
    x = healthy[:, 0] + rng.normal(0, 0.05 * healthy[:, 0].std(), healthy.shape[0])
    angle = runout[:, 1] + rng.normal(0, 1e-7, runout.shape[0])
    op = record_conditions(candidates_fmu, x, 20000.0, 20.0, 20.0, {}, duration=0.5).operating
    spec = dict(effect="pinion_eccentricity", fmu_path=str(candidates_fmu), channel="accel_pinion_casing",
                measured=x, operating=op, parameters=_neutral(), guesses={}, max_evals=20)
    fitted, lsd, _, sim = fit_effect(TrialSpec(**spec, angle=angle))
    assert sim.shape == (x.size, 2) and lsd == pytest.approx(_Objective(x, 20000.0, angle=angle)(sim))
    # the twin's own casing does show a run-out, so the fit settles between the channels
    e = fitted["pinion_eccentricity.eccentricity"]
    assert 2e-5 < e <= 5e-5 * 1.1
    alone, _, _, _ = fit_effect(TrialSpec(**spec))
    assert alone["pinion_eccentricity.eccentricity"] < e / 3


def test_the_records_own_speed_beats_a_sideband_taken_for_the_mesh_line(gearbox_fmu):
    """A local fault's 20th pinion order can stand above the 19th (the mesh line): read off the
    spectrum the speed would be 20/19 too high; the record's encoder speed is taken instead."""
    from twin.effects.diagnose import record_conditions
    fs, shaft = 20000.0, 19.9
    t = np.arange(int(0.5 * fs)) / fs
    x = 0.2 * np.sin(2 * np.pi * 19 * shaft * t) + np.sin(2 * np.pi * 20 * shaft * t)
    by_line = record_conditions(gearbox_fmu, x, fs, 20.0, 20.0, {}, duration=0.5)
    assert by_line.operating.shaft_hz == pytest.approx(20 * shaft / 19, rel=1e-3)
    speed = np.r_[np.full(x.size, 5.0), np.full(x.size, shaft)]     # the stretch before the one kept does not count
    kept = record_conditions(gearbox_fmu, np.r_[x, x], fs, 20.0, 20.0, {}, duration=0.5, shaft_speed=speed)
    assert kept.operating.shaft_hz == pytest.approx(shaft, rel=1e-9)
    with pytest.raises(MeasurementError, match="pinion speed is 0 Hz"):
        record_conditions(gearbox_fmu, x, fs, 20.0, 20.0, {}, duration=0.5, shaft_speed=np.zeros(x.size))
