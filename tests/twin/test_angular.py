"""The pinion encoder's angular vibration as a second channel of a record (twin.angular)."""
from __future__ import annotations

import numpy as np
import pytest

FS = 10_000.0
SHAFT = 20.0
Z1, Z2 = 19, 52


def _angle(n, *, runout=0.0, ripple=0.0, ripple_hz=113.0, seed=0):
    """A pinion angle [rad] accelerating slowly, with a once-per-turn line of ``runout`` rad, a
    line of ``ripple`` rad at ``ripple_hz``, a gear-speed line and encoder noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    a = 2 * np.pi * SHAFT * t + 0.3 * t ** 2 + 2e-5 * np.sin(2 * np.pi * SHAFT * Z1 / Z2 * t + 0.4)
    a += runout * np.sin(2 * np.pi * SHAFT * t + 1.0) + ripple * np.sin(2 * np.pi * ripple_hz * t)
    return a + 1e-7 * rng.standard_normal(n)


def test_angular_vibration_takes_out_the_rotation_and_keeps_the_vibration():
    from twin.angular import angular_vibration
    t = np.arange(20_000) / FS
    wiggle = 1e-4 * np.sin(2 * np.pi * 37.0 * t)
    x = angular_vibration(5.0 + 2 * np.pi * SHAFT * t + 0.7 * t ** 2 + wiggle, FS)
    # a whole number of periods in 2 s: the quadratic fit takes (almost) nothing of the wiggle
    assert np.max(np.abs(x - wiggle)) < 2e-6
    assert np.max(np.abs(angular_vibration(3.0 + 40.0 * t - 2.0 * t ** 2, FS))) < 1e-9


def test_the_encoder_comparison_names_a_shaft_line_and_a_line_locked_to_no_shaft():
    from twin.angular import KIND, compare_angles
    n = int(2 * FS)
    model = _angle(n, seed=1)
    same = compare_angles(model, _angle(n, seed=2), FS, SHAFT, z1=Z1, z2=Z2)
    assert same.lsd_db < 0.5 and same.findings == ()
    c = compare_angles(model, _angle(n, runout=3e-4, ripple=5e-6, seed=2), FS, SHAFT, z1=Z1, z2=Z2)
    assert c.lsd_db > 1.0 and all(f.kind == KIND for f in c.findings)
    runout = [f for f in c.findings if "1x pinion speed" in f.description]
    assert runout and runout[0].size_db > 20 and runout[0].order == 1.0
    ripple = [f for f in c.findings if "locked to no shaft" in f.description]
    assert len(ripple) == 1 and ripple[0].frequency_hz == pytest.approx(113.0, abs=0.2) and ripple[0].order is None
    # a line at a shaft's order is never called unlocked: the gear's 3rd order (21.9 Hz) lies
    # one 2 Hz bin from the pinion's 1st
    gear_line = compare_angles(model, _angle(n, ripple=5e-6, ripple_hz=3 * SHAFT * Z1 / Z2, seed=2), FS, SHAFT,
                               z1=Z1, z2=Z2)
    assert not [f for f in gear_line.findings if "locked to no shaft" in f.description]


def test_the_two_channels_are_judged_together():
    from twin.angular import AngularComparison, joint, joint_lsd
    from twin.compare import Comparison, Finding
    casing = Comparison(3.0, 0.1, 0.1, 1.0, 1.0, SHAFT, (Finding("resonance", "r", 900.0, (850.0, 950.0), 8.0, 0.6),),
                        np.zeros(1), np.zeros(1), np.zeros(1))
    enc = AngularComparison(4.0, (Finding("angular_line", "a", 20.0, (18.0, 22.0), 30.0, 0.9),))
    both = joint(casing, enc)
    assert both.lsd_db == pytest.approx(joint_lsd(3.0, 4.0)) == pytest.approx(np.sqrt(12.5))
    # each finding's share of the joint squared distance: 0.6 of 9/25 and 0.9 of 16/25
    assert [f.share for f in both.findings] == pytest.approx([0.9 * 16 / 25, 0.6 * 9 / 25])
    assert both.angular is enc and joint(casing, None) is casing and joint_lsd(3.0, None) == 3.0


def test_the_objective_with_an_encoder_scores_both_channels():
    from twin.angular import AngularObjective
    from twin.effects.fit import _Objective
    n = int(2 * FS)
    rng = np.random.default_rng(0)
    casing = rng.standard_normal(n)
    measured_angle = _angle(n, runout=3e-4, seed=2)
    obj = _Objective(casing, FS, angle=measured_angle)
    enc = AngularObjective(measured_angle, FS, obj.resolution)
    model_angle = _angle(n, seed=1)
    # (a model equal to the measurement stands a little off: its PSD gets the measured noise added)
    one = _Objective(casing, FS)(casing)
    both = obj(np.column_stack([casing, model_angle]))
    assert both == pytest.approx(np.sqrt(0.5 * (one ** 2 + enc(model_angle) ** 2)))
    assert enc(model_angle) > 5.0 > 1.0 > enc(measured_angle)
    assert obj(np.column_stack([casing, measured_angle])) < both


def test_the_encoder_distance_is_the_error_of_its_content_not_of_its_band():
    """A line the model lacks (or adds) weighs by the record's content bins, not by the 250 bins
    of the 2-500 Hz band: widening the band would otherwise dilute it."""
    from twin.angular import AngularObjective
    n = int(2 * FS)
    measured = _angle(n, ripple=5e-6, seed=2)              # a gear-speed line and a 113 Hz line
    enc = AngularObjective(measured, FS, 2.0)
    lp, lm = enc.levels(_angle(n, seed=1))                 # the model lacks the 113 Hz line
    d2 = (lp - lm) ** 2
    assert enc.content < 0.1 * lp.size
    held = (lp >= enc.threshold) | (lm >= enc.threshold)
    assert enc(_angle(n, seed=1)) == pytest.approx(np.sqrt(d2[held].sum() / enc.content))
    assert enc(_angle(n, seed=1)) > 3 * np.sqrt(d2.mean()) and enc(_angle(n, seed=1)) > 10.0
    # a model with a line the record lacks is as far off
    plain = AngularObjective(_angle(n, seed=2), FS, 2.0)
    assert plain(_angle(n, ripple=5e-6, seed=1)) > 10.0 > 1.0 > plain(_angle(n, seed=1))


def test_a_discrepancy_adds_what_the_model_lacks_and_scales_what_it_overstates():
    """Learned on a baseline, the read model equals the baseline; what an effect adds to the model
    is added on top of the gearbox's own content, not scaled by its ratio to the model."""
    from twin.angular import AngularDiscrepancy
    f = np.array([10.0, 20.0, 30.0])
    baseline = np.array([1e-8, 1e-10, 1e-9])
    model = np.array([1e-12, 1e-12, 4e-9])             # lacks the first two, overstates the third
    d = AngularDiscrepancy.learn("steady", f, baseline, model)
    assert d.apply(f, model) == pytest.approx(baseline)
    effect = np.array([0.0, 1e-8, 0.0])                 # an effect adds a line at 20 Hz
    assert d.apply(f, model + effect) == pytest.approx(baseline + effect)
    assert d.apply(f, 2 * model)[2] == pytest.approx(2 * baseline[2])


def test_a_diagnosis_says_when_its_distance_is_both_channels():
    from twin.effects.verdict import Diagnosis
    from twin.operating import Operating
    d = Diagnosis("steady", 2.5, (), (), "nothing_missing", None, (), "nothing missing", Operating(20, 20, 20, FS),
                  1.0, encoder=True)
    assert "2.50 dB on steady (casing and encoder, RMS of the two)" in d.table() and d.to_dict()["encoder"] is True
    assert "encoder" not in Diagnosis("steady", 2.5, (), (), "nothing_missing", None, (), "", Operating(20, 20, 20, FS),
                                      1.0).table()
