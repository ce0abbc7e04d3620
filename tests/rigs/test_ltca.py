"""The LTCA simulator: load sharing by hand, stiffness, wear and pit physics, determinism, file layout, bad input."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twin.errors import ParameterError, ScenarioError
from rigs.ltca import (LtcaRig, lost_width, make_ltca_target, pair_stiffness, pit_fields, simulate_ltca,
                                static_approach, wear_profiles)
from rigs.lumped import mesh_geometry, LumpedRig

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
U = np.linspace(0.0, 1.0, 401)


def test_static_approach_by_hand():
    k, e = np.array([2e8, 1e8]), np.array([0.0, 1e-6])
    # 100 N deflect the first pair by 0.5 um: the second, 1 um away, stays free
    assert static_approach(k, e, 100.0) == pytest.approx(0.5e-6)
    # 400 N would deflect it 2 um: both carry, 2e8 d + 1e8 (d - 1e-6) = 400
    assert static_approach(k, e, 400.0) == pytest.approx(500 / 3e8)
    # a pair out of mesh (k = 0) carries nothing, whatever its deviation
    assert static_approach(np.array([0.0, 1e8]), np.array([-5e-6, 2e-6]), 100.0) == pytest.approx(3e-6)
    # broadcasting over positions, one force each
    d = static_approach(np.tile(k, (2, 1)), np.tile(e, (2, 1)), np.array([100.0, 400.0]))
    np.testing.assert_allclose(d, [0.5e-6, 500 / 3e8])


def test_pair_stiffness_peaks_at_the_iso_value_and_falls_towards_both_ends():
    k = pair_stiffness(LtcaRig())
    assert k.max() == pytest.approx(14e9 * 0.020)
    assert 0.2 < U[np.argmax(k)] < 0.8
    assert k[0] < 0.6 * k.max() and k[-1] < 0.6 * k.max()


def test_archard_wear_is_zero_at_the_pitch_point_deepest_in_the_pinion_dedendum_and_lighter_on_the_gear():
    rig = LtcaRig()
    pitch = mesh_geometry(LumpedRig()).roll_pitch
    depths = np.array([0.0, 6e-5, 1.2e-4, 2.4e-4])
    pinion, gear = wear_profiles(rig, depths, 5.0)
    np.testing.assert_allclose(pinion.mean(axis=1), depths, rtol=1e-9, atol=1e-15)
    at_pitch = np.argmin(np.abs(U - pitch))
    assert pinion[-1, at_pitch] < 0.02 * pinion[-1].max() and gear[-1, at_pitch] < 0.02 * gear[-1].max()
    assert pinion[-1, U < pitch].mean() > pinion[-1, U > pitch].mean()
    # each gear tooth meshes z1/z2 as often as a pinion tooth
    assert 0 < gear[-1].mean() < 0.6 * pinion[-1].mean()
    assert np.all(np.diff(pinion, axis=0) >= -1e-12)          # wear only removes material
    with pytest.raises(ParameterError, match="wear depths"):
        wear_profiles(rig, [-1e-6], 5.0)


def test_pits_cover_the_asked_share_below_the_pitch_line_and_grow_in_place():
    rig = LtcaRig()
    pitch = mesh_geometry(LumpedRig()).roll_pitch
    fields = pit_fields(rig, np.random.default_rng(0))[:3]
    small, large = lost_width(fields, np.full(3, 0.05)), lost_width(fields, np.full(3, 0.2))
    # pits come whole: the share reaches the density and passes it by at most about one large pit
    for lost, d in ((small, 0.05), (large, 0.2)):
        assert np.all(lost.mean(axis=1) > d - 0.002) and np.all(lost.mean(axis=1) < d + 0.01)
    assert np.all(large >= small - 1e-12)                      # the pits of stage 2 are still there at stage 6
    assert large[:, U < pitch].mean() > 3 * large[:, U > pitch].mean()
    assert np.all(lost_width(fields, np.zeros(3)) == 0)
    # beyond what the pit sequence covers, the share stops there instead of pitting everything
    assert np.all(lost_width(fields, np.ones(3)).mean(axis=1) < 0.7)


def _spectrum(acc, fs):
    p = np.abs(np.fft.rfft(acc * np.hanning(acc.size))) ** 2
    return np.fft.rfftfreq(acc.size, 1 / fs), p


def test_error_free_gears_vibrate_at_the_mesh_harmonics_only():
    rig = LtcaRig(pitch_error=(0.0, 0.0), runout=(0.0, 0.0), coupling_ripple=0.0)
    speed = 20.0
    acc = simulate_ltca(rig, [speed], [20.0], [0.0], "pitting_density", 0.1, gear_seed=0, nominal_load=20.0,
                        settle=0.02)[0]
    f, p = _spectrum(acc, rig.sample_rate)
    mesh = speed * rig.teeth[0]
    near = np.abs(f / mesh - np.round(f / mesh)) * mesh < 1.5 * f[1]
    assert p[near & (f > 100)].sum() / p[f > 100].sum() > 0.95
    rough = simulate_ltca(LtcaRig(), [speed], [20.0], [0.0], "pitting_density", 0.1, gear_seed=0, nominal_load=20.0,
                          settle=0.02)[0]
    f, p = _spectrum(rough, rig.sample_rate)
    assert p[near & (f > 100)].sum() / p[f > 100].sum() < 0.95


def test_the_vibration_grows_with_wear_depth_and_with_pitting():
    rig = LtcaRig()
    wear = simulate_ltca(rig, [10.0] * 3, [5.0] * 3, [0.0, 6e-5, 1.8e-4], "wear_depth", 0.1, gear_seed=1,
                         nominal_load=5.0, settle=0.02)
    assert np.all(np.diff(np.sqrt(np.mean(wear ** 2, axis=1))) > 0)
    pit = simulate_ltca(rig, [20.0] * 2, [20.0] * 2, [0.0, 0.2], "pitting_density", 0.1, gear_seed=1,
                        nominal_load=20.0, settle=0.02)
    assert np.sqrt(np.mean(pit[1] ** 2)) > 1.5 * np.sqrt(np.mean(pit[0] ** 2))


def test_same_gear_seed_same_records_another_seed_another_gearbox():
    args = ([10.0, 10.0], [5.0, 5.0], [6e-5, 6e-5], "wear_depth", 0.03)
    kw = dict(nominal_load=5.0, start_angles=[0.1, 2.0], settle=0.01)
    a = simulate_ltca(LtcaRig(), *args, gear_seed=4, **kw)
    b = simulate_ltca(LtcaRig(), *args, gear_seed=4, **kw)
    c = simulate_ltca(LtcaRig(), *args, gear_seed=5, **kw)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert a.shape == (2, int(round(0.03 * LtcaRig().sample_rate)))


@pytest.mark.parametrize("bad, name", [({"teeth": (19,)}, "teeth"), ({"module": -1.0}, "module"),
                                       ({"pitch_error": (1e-6,)}, "pitch_error"), ({"poisson_ratio": 0.6}, "poisson"),
                                       ({"modes_hz": (20000.0, 1.0, 2.0, 3.0, 4.0)}, "casing modes"),
                                       ({"oversampling": 0}, "oversampling"), ({"noise": float("nan")}, "noise")])
def test_bad_rig_settings_are_parameter_errors_naming_the_setting(bad, name):
    with pytest.raises(ParameterError, match=name):
        LtcaRig(**bad)


def test_bad_records_are_parameter_errors():
    with pytest.raises(ParameterError, match="cracks"):
        simulate_ltca(LtcaRig(), [10.0], [5.0], [0.0], "cracks", 0.01, gear_seed=0, nominal_load=5.0)
    with pytest.raises(ParameterError, match=r"loads \[-5.0\]"):
        simulate_ltca(LtcaRig(), [10.0], [-5.0], [0.0], "wear_depth", 0.01, gear_seed=0, nominal_load=5.0)
    with pytest.raises(ParameterError, match="nominal_load"):
        simulate_ltca(LtcaRig(), [10.0], [5.0], [0.0], "wear_depth", 0.01, gear_seed=0, nominal_load=0.0)
    with pytest.raises(ParameterError, match="start_angles"):
        simulate_ltca(LtcaRig(), [10.0], [5.0], [0.0], "wear_depth", 0.01, gear_seed=0, nominal_load=5.0,
                      start_angles=[0, 1])


def test_target_file_has_the_twins_layout_and_is_reproducible(tmp_path):
    from twin.measurements import load_measurements
    from twin.scenario import load_scenario

    sc = load_scenario(SCENARIOS / "dry.yaml")
    rig = replace(LtcaRig(), oversampling=2)
    a = make_ltca_target(sc, tmp_path / "a.h5", records_per_stage=1, record_duration=0.05, seed=4, rig=rig,
                         progress=False)
    b = make_ltca_target(sc, tmp_path / "b.h5", records_per_stage=1, record_duration=0.05, seed=4, rig=rig,
                         progress=False)
    ma, mb = (load_measurements(p, channels=["accel_pinion_casing"]) for p in (a, b))
    assert [r.label for r in ma.records] == [0, 1, 2, 3]
    bounds = sc.archive["stages"]
    for r, rb in zip(ma.records, mb.records):
        np.testing.assert_array_equal(r["accel_pinion_casing"], rb["accel_pinion_casing"])
        assert bounds[r.label] <= r.damage < bounds[r.label + 1]
        assert r.sample_rate == rig.sample_rate and r.nominal_speed > 0 and r.load > 0
    assert ma.metadata["damage_kind"] == "wear_depth" and "oversampling" in ma.metadata["ltca_rig"]


def test_a_scenario_without_pitting_or_wear_is_a_scenario_error_and_nothing_is_written(tmp_path):
    from twin.scenario import load_scenario

    sc = load_scenario(SCENARIOS / "dry.yaml")
    with pytest.raises(ScenarioError, match="degradation.model"):
        make_ltca_target(replace(sc, degradation=None), tmp_path / "x.h5", records_per_stage=1,
                         record_duration=0.01, progress=False)
    with pytest.raises(ParameterError, match="records_per_stage"):
        make_ltca_target(sc, tmp_path / "x.h5", records_per_stage=0, progress=False)
    assert not (tmp_path / "x.h5").exists()
