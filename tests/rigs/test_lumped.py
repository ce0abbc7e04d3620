"""The independent lumped simulator: geometry, physics checks, determinism, file layout, bad input."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twin.errors import ParameterError, ScenarioError
from rigs.lumped import LumpedRig, _profile_shapes, make_lumped_target, mesh_geometry, simulate_lumped

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def test_geometry_agrees_with_the_twins_independent_geometry_code():
    from twin.degradation.geometry import GearPair

    g, pair = mesh_geometry(LumpedRig()), GearPair()
    assert g.contact_ratio == pytest.approx(pair.contact_ratio, rel=1e-12)
    assert g.roll_pitch == pytest.approx(pair.pitch_point_xi, rel=1e-9)
    # two solid steel disks of 57 mm and 156 mm pitch diameter, 20 mm wide
    i1 = 0.5 * 7850 * math.pi * 0.02 * 0.0285 ** 4
    i2 = 0.5 * 7850 * math.pi * 0.02 * 0.078 ** 4
    rb1, rb2 = g.base_radii
    assert g.equivalent_mass == pytest.approx(1 / (rb1 ** 2 / i1 + rb2 ** 2 / i2))
    assert g.pair_stiffness == pytest.approx(14 * 1e3 / 1e-6 * 0.02)       # 14 N/(mm um) x 20 mm


def test_wear_shape_vanishes_at_the_pitch_point_and_pits_sit_below_it():
    g = mesh_geometry(LumpedRig())
    u, wear, band = _profile_shapes(g, 0.12)
    assert wear.mean() == pytest.approx(1.0) and band.mean() == pytest.approx(1.0)
    assert wear[np.argmin(np.abs(u - g.roll_pitch))] < 1e-2 * wear.max()
    single_start = (g.contact_ratio - 1) / g.contact_ratio
    assert single_start < u[np.argmax(band)] < g.roll_pitch


def _spectrum(acc, fs):
    p = np.abs(np.fft.rfft(acc * np.hanning(acc.size))) ** 2
    return np.fft.rfftfreq(acc.size, 1 / fs), p


def test_error_free_gears_vibrate_at_the_mesh_harmonics_only():
    rig = LumpedRig(pitch_error=0.0, runout=0.0, wear_tooth_scatter=0.0)
    speed = 20.0
    # 0.1 s: whole periods of the shaft (2) and of the mesh (38), so every line sits on a bin
    acc = simulate_lumped(rig, [speed], [20.0], [0.0], "wear_depth", 0.1, gear_seed=0, settle=0.01)[0]
    f, p = _spectrum(acc, rig.sample_rate)
    mesh = speed * rig.teeth[0]
    near = np.abs(f / mesh - np.round(f / mesh)) * mesh < 1.5 * f[1]      # the shaft's sidebands are 2 bins off
    assert p[near & (f > 100)].sum() / p[f > 100].sum() > 0.95
    # the shaft's tooth errors put energy between the mesh harmonics
    rough = simulate_lumped(LumpedRig(), [speed], [20.0], [0.0], "wear_depth", 0.1, gear_seed=0, settle=0.01)[0]
    f, p = _spectrum(rough, rig.sample_rate)
    assert p[near & (f > 100)].sum() / p[f > 100].sum() < 0.95


def test_the_vibration_grows_with_wear_depth_and_with_deep_pitting():
    rig = LumpedRig()
    wear = simulate_lumped(rig, [10.0] * 3, [5.0] * 3, [0.0, 6e-5, 1.8e-4], "wear_depth", 0.1, gear_seed=1,
                           settle=0.01)
    assert np.all(np.diff(wear.std(axis=1)) > 0)
    pit = simulate_lumped(rig, [20.0] * 2, [20.0] * 2, [0.0, 0.2], "pitting_density", 0.1, gear_seed=1, settle=0.01)
    assert pit[1].std() > 1.2 * pit[0].std()


def test_same_seed_same_records_and_the_seed_is_the_gearbox():
    args = ([10.0, 10.5], [5.0, 5.5], [3e-5, 9e-5], "wear_depth", 0.03)
    a = simulate_lumped(LumpedRig(), *args, gear_seed=4, start_angles=[0.1, 2.0], settle=0.01)
    b = simulate_lumped(LumpedRig(), *args, gear_seed=4, start_angles=[0.1, 2.0], settle=0.01)
    c = simulate_lumped(LumpedRig(), *args, gear_seed=5, start_angles=[0.1, 2.0], settle=0.01)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert a.shape == (2, int(round(0.03 * LumpedRig().sample_rate)))


@pytest.mark.parametrize("bad, match", [
    (dict(teeth=(5, 52)), "teeth"),
    (dict(module=-1.0), "module"),
    (dict(noise=float("nan")), "noise"),
    (dict(substeps=0), "substeps"),
    (dict(modes_hz=(1e3, 3e4), modes_damping=(0.03, 0.03), modes_gain=(1.0, 1.0)), "casing modes"),
    (dict(modes_gain=(1.0,)), "same, non-zero length"),
])
def test_bad_rig_settings_are_named(bad, match):
    with pytest.raises(ParameterError, match=match):
        LumpedRig(**bad)


def test_bad_simulation_input_is_refused():
    with pytest.raises(ParameterError, match="damage kind"):
        simulate_lumped(LumpedRig(), [10.0], [5.0], [0.0], "cracks", 0.01, gear_seed=0)
    with pytest.raises(ParameterError, match="speeds and loads"):
        simulate_lumped(LumpedRig(), [10.0], [-5.0], [0.0], "wear_depth", 0.01, gear_seed=0)
    with pytest.raises(ParameterError, match="start_angles"):
        simulate_lumped(LumpedRig(), [10.0], [5.0], [0.0], "wear_depth", 0.01, gear_seed=0, start_angles=[0, 1])


def test_target_file_has_the_twins_layout_and_is_reproducible(tmp_path):
    from twin.measurements import load_measurements
    from twin.scenario import load_scenario

    sc = load_scenario(SCENARIOS / "dry.yaml")
    rig = replace(LumpedRig(), substeps=2)          # a coarser step keeps the test short
    a = make_lumped_target(sc, tmp_path / "a.h5", records_per_stage=1, record_duration=0.05, seed=3, rig=rig,
                           progress=False)
    b = make_lumped_target(sc, tmp_path / "b.h5", records_per_stage=1, record_duration=0.05, seed=3, rig=rig,
                           progress=False)
    ma, mb = (load_measurements(p, channels=["accel_pinion_casing"]) for p in (a, b))
    assert [r.label for r in ma.records] == [0, 1, 2, 3]
    bounds = sc.archive["stages"]
    for r, rb in zip(ma.records, mb.records):
        np.testing.assert_array_equal(r["accel_pinion_casing"], rb["accel_pinion_casing"])
        assert bounds[r.label] <= r.damage < bounds[r.label + 1]
        assert r.sample_rate == rig.sample_rate and r.nominal_speed > 0 and r.load > 0
    assert ma.metadata["damage_kind"] == "wear_depth"


def test_a_scenario_without_pitting_or_wear_is_a_scenario_error(tmp_path):
    from twin.scenario import load_scenario

    sc = load_scenario(SCENARIOS / "dry.yaml")
    bad = replace(sc, degradation=None)
    with pytest.raises(ScenarioError, match="degradation.model"):
        make_lumped_target(bad, tmp_path / "x.h5", records_per_stage=1, record_duration=0.01, progress=False)
    assert not (tmp_path / "x.h5").exists()
    with pytest.raises(ParameterError, match="records_per_stage"):
        make_lumped_target(sc, tmp_path / "x.h5", records_per_stage=0, progress=False)


def test_the_command_line_writes_what_the_function_writes_and_names_bad_input(tmp_path, capsys):
    from rigs.lumped import main
    from twin.measurements import load_measurements
    from twin.scenario import load_scenario

    args = ["--records-per-stage", "1", "--record-duration", "0.05", "--seed", "5", "--no-progress"]
    assert main(["target", str(SCENARIOS / "dry.yaml"), "--out", str(tmp_path / "cli.h5"),
                 "--damage-sampling", "snapshot", "--damage-scatter", "0.2", *args]) == 0
    sc = load_scenario(SCENARIOS / "dry.yaml")
    sc = sc.with_overrides(archive={**sc.archive, "damage_sampling": "snapshot", "damage_scatter": 0.2})
    make_lumped_target(sc, tmp_path / "fn.h5", records_per_stage=1, record_duration=0.05, seed=5, progress=False)
    cli, fn = (load_measurements(tmp_path / f"{n}.h5").records for n in ("cli", "fn"))
    assert [(r.label, r.damage) for r in cli] == [(r.label, r.damage) for r in fn]
    for r, q in zip(cli, fn):
        np.testing.assert_array_equal(r["accel_pinion_casing"], q["accel_pinion_casing"])
    # a scenario without stages: a one-line error naming it, exit code 2, nothing written
    assert main(["target", str(SCENARIOS / "healthy.yaml"), "--out", str(tmp_path / "bad.h5"),
                 "--damage-sampling", "snapshot", *args]) == 2
    assert "healthy.yaml" in capsys.readouterr().err and not (tmp_path / "bad.h5").exists()
