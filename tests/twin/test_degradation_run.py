"""twin.degradation_run: the FMU and the degradation models coupled between co-simulation steps."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from twin.degradation_run import run_degradation
from twin.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]


def _lubricated(stop=0.04, **deg):
    sc = load_scenario(REPO / "scenarios" / "lubricated.yaml")
    d = dict(sc.degradation)
    d.update({"stop": {"pitting_density": stop}, "load_window": 0.05, "record_duration": 0.01, **deg})
    return sc.with_overrides(degradation=d)


def test_pitting_grows_and_lowers_mesh_stiffness(gearbox_fmu, tmp_path):
    run = run_degradation(_lubricated(), tmp_path / "lub.h5", fmu_path=gearbox_fmu, progress=False)
    assert run.complete
    assert np.all(np.diff(run.damage) > 0) and np.all(np.diff(run.cycles) > 0)
    assert run.damage[-1] >= 0.04
    first, last = run.stages[0], run.stages[-1]
    k0 = np.array([first.parameters[f"k_pair[{i}]"] for i in range(1, 12)])
    k1 = np.array([last.parameters[f"k_pair[{i}]"] for i in range(1, 12)])
    assert np.all(k1 <= k0 + 1e-6) and np.any(k1 < 0.99 * k0)    # pitting only removes stiffness
    assert "accel_pinion_casing" in last.vibration
    # the teeth pit unequally and at different places: the FMU has each tooth's own pit profile
    field = np.array([last.parameters[f"tooth_pit_field[{k}]"] for k in range(1, 19 * 11 + 1)]).reshape(19, 11)
    assert np.any(field != 0) and np.ptp(field.sum(axis=1)) > 0
    s = np.linalg.svd(field, compute_uv=False)
    assert s[1] > 0.1 * s[0]                 # not one shape times a scale per tooth
    assert set(last.truncation_error) >= {"k_pair", "tooth_pit_field"}
    assert 0 <= last.truncation_error["tooth_pit_field"] < 1
    assert not any(k.startswith("pinion_roughness")
                   for s in run.stages for k in s.parameters)
    with h5py.File(tmp_path / "lub.h5") as f:
        assert f.attrs["complete"] and f.attrs["model"] == "pitting"
        assert len(f["stages"]) == len(run.stages)


def test_the_pits_leave_the_pinion_roughness_alone(measured_fmu):
    # the per-tooth field carries the pits' differences: the broadband roughness keeps its value
    sc = _lubricated(stop=0.02)
    sc = sc.with_overrides(fmu="GearTwin.Gearbox21Measured", parameters={**sc.parameters, "pinion_roughness.rms": 4e-8})
    run = run_degradation(sc, None, fmu_path=measured_fmu, progress=False)
    assert len(run.stages) > 1
    last = run.stages[-1]
    assert any(last.parameters[f"tooth_pit_field[{k}]"] != 0 for k in range(1, 19 * 11 + 1))
    assert not any(k.startswith("pinion_roughness") for s in run.stages for k in s.parameters)


def test_wear_moves_the_profile(gearbox_fmu):
    sc = load_scenario(REPO / "scenarios" / "dry.yaml")
    d = dict(sc.degradation)
    d.update({"stop": {"wear_depth": 1e-5}, "load_window": 0.1, "record_duration": 0.0})
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=gearbox_fmu, progress=False)
    dev = np.array([run.stages[-1].parameters[f"profile_deviation[{i}]"] for i in range(1, 12)])
    assert run.damage[-1] >= 1e-5
    assert dev.max() > 5e-6 and dev.min() >= 0
    # wear is largest where sliding is largest (ends of the path), smallest near the pitch point
    assert dev[0] > dev[5] and dev[-1] > dev[5]


def test_wear_with_the_contact_pair_stiffness(gearbox_fmu):
    """pair_stiffness: contact gives the FMU the LTCA's secant pair stiffness at the load, from
    the first record on; the default keeps the model's k_pair."""
    from twin.degradation import GearPair, contact_k_pair
    sc = load_scenario(REPO / "scenarios" / "dry.yaml")
    d = dict(sc.degradation)
    d.update({"max_updates": 2, "load_window": 0.1, "record_duration": 0.0, "pair_stiffness": "contact"})
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=gearbox_fmu, progress=False)
    g = GearPair()
    first = np.array([run.stages[0].parameters[f"k_pair[{i}]"] for i in range(1, 12)])
    assert np.allclose(first, contact_k_pair(g, 5.0 / g.base_radius_gear, 11), rtol=1e-12)
    second = np.array([run.stages[1].parameters[f"k_pair[{i}]"] for i in range(1, 12)])
    assert np.allclose(second, first, rtol=0.05) and run.damage[1] > 0
    d.pop("pair_stiffness")
    d["max_updates"] = 1
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=gearbox_fmu, progress=False)
    assert run.stages[0].parameters["k_pair[6]"] == pytest.approx(3.0e8)


def test_a_run_off_the_default_operating_point_starts_in_contact(gearbox_fmu):
    """dry.yaml runs at 10 Hz / 5 N.m; the model's start parameters say 20 Hz / 20 N.m. Started
    from those, the gear flew ahead of the slowing pinion and, with the mesh damping acting only
    in contact, the flanks stayed apart: the first update saw no load and jumped 1e7 cycles."""
    sc = load_scenario(REPO / "scenarios" / "dry.yaml")
    d = dict(sc.degradation)
    d.update({"max_updates": 2, "load_window": 0.1, "record_duration": 0.0})
    run = run_degradation(sc.with_overrides(degradation=d), None, fmu_path=gearbox_fmu, progress=False)
    assert run.damage[1] > 0 and run.cycles[1] < 1e6


def test_resume_continues_from_last_stage(gearbox_fmu, tmp_path):
    out = tmp_path / "r.h5"
    part = run_degradation(_lubricated(stop=0.02), out, fmu_path=gearbox_fmu, progress=False)
    full = run_degradation(_lubricated(stop=0.04), out, fmu_path=gearbox_fmu, progress=False, resume=True)
    assert full.stages[0].cycles == part.stages[0].cycles
    assert len(full.stages) > len(part.stages)
    assert full.damage[-1] >= 0.04
    np.testing.assert_allclose(full.damage[:len(part.stages) - 1], part.damage[:-1])


def test_interrupt_keeps_completed_stages(gearbox_fmu, tmp_path, monkeypatch):
    import twin.degradation_run as dr
    calls = {"n": 0}
    real = dr.FMU.capture

    def flaky(self, *a, **k):
        calls["n"] += 1
        if calls["n"] == 8:
            raise KeyboardInterrupt
        return real(self, *a, **k)

    monkeypatch.setattr(dr.FMU, "capture", flaky)
    (tmp_path / "i.h5").write_bytes(b"an earlier result")
    run = run_degradation(_lubricated(), tmp_path / "i.h5", fmu_path=gearbox_fmu, progress=False)
    assert not run.complete and len(run.stages) >= 2
    assert (tmp_path / "i.h5").read_bytes() == b"an earlier result"     # only a complete run replaces it
    with h5py.File(tmp_path / "i.partial.h5") as f:
        assert not f.attrs["complete"] and len(f["stages"]) == len(run.stages)


def test_bad_coefficients_are_a_scenario_error(gearbox_fmu):
    from twin.errors import ScenarioError
    with pytest.raises(ScenarioError, match="coefficients"):
        run_degradation(_lubricated(coefficients={"wear_rate": 1.0}), None, fmu_path=gearbox_fmu, progress=False)


def test_clustered_pits_are_an_opt_in(gearbox_fmu):
    from twin.errors import ScenarioError
    fields = []
    for length in (0.0, 0.8e-3):
        run = run_degradation(_lubricated(stop=0.03, pit_cluster_length=length), None, fmu_path=gearbox_fmu,
                              progress=False)
        last = run.stages[-1]
        fields.append(np.array([last.parameters[f"tooth_pit_field[{k}]"] for k in range(1, 19 * 11 + 1)]))
    # the same law and cycles, the pits placed differently (clustered)
    assert np.any(fields[0] != fields[1])
    from twin.errors import ParameterError
    with pytest.raises((ScenarioError, ParameterError), match="cluster length"):
        run_degradation(_lubricated(pit_cluster_length=-1.0), None, fmu_path=gearbox_fmu, progress=False)
