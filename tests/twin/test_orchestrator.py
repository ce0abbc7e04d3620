"""twin.orchestrator: events at the right step, hooks, compatibility check, Ctrl-C."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from twin.errors import FMUCompatibilityError
from twin.orchestrator import run_scenario
from twin.scenario import scenario_from_dict


def _scenario(fmu, **extra):
    data = {"version": 1, "name": "two-mass", "fmu": str(fmu), "stop_time": 1.0, "communication_step": 0.1,
            "output": {"sample_rate": 100.0, "variables": ["a2", "position2"]}}
    data.update(extra)
    return scenario_from_dict(data)


def test_event_takes_effect_at_its_step_and_not_before(two_mass_fmu, tmp_path):
    base = run_scenario(_scenario(two_mass_fmu), progress=False).result
    ev = run_scenario(_scenario(two_mass_fmu, events=[{"time": 0.5, "override": {"force": 2.0}},
                                                      {"time": 0.8, "reset": ["force"]}]),
                      tmp_path / "ev.h5", progress=False)
    i = int(round(0.5 * 100))
    np.testing.assert_array_equal(ev.result["a2"][:i + 1], base["a2"][:i + 1])
    assert abs(ev.result["a2"][i + 1] - base["a2"][i + 1]) > 0.5   # 2 N on 0.5 kg
    with h5py.File(tmp_path / "ev.h5") as f:
        assert f.attrs["complete"]
        assert list(f["events/time"][:]) == [0.5, 0.8]


def test_bias_on_parameter_and_reset(two_mass_fmu):
    seen = []
    rec = run_scenario(_scenario(two_mass_fmu, events=[{"time": 0.2, "bias": {"k1": 50.0}},
                                                       {"time": 0.4, "reset": ["k1"]}]),
                       hooks=[lambda ctx: seen.append((round(ctx.time, 6), ctx.fmu.get("k1")))], progress=False)
    assert dict(seen)[0.1] == 100.0 and dict(seen)[0.2] == 150.0 and dict(seen)[0.3] == 150.0
    assert dict(seen)[0.4] == 100.0
    assert [a for _, a in rec.events_applied] == ["bias k1 += 50", "reset k1"]


def test_parameter_change_in_hook_changes_response_from_that_step(two_mass_fmu):
    base = run_scenario(_scenario(two_mass_fmu), progress=False).result

    def stiffen(ctx):
        if ctx.step == 3:
            ctx.fmu.set({"k1": 400.0})

    changed = run_scenario(_scenario(two_mass_fmu), hooks=[stiffen], progress=False).result
    i = 30  # t = 0.3 s at 100 Hz
    np.testing.assert_array_equal(changed["a2"][:i + 1], base["a2"][:i + 1])
    assert np.max(np.abs(changed["a2"][i + 1:] - base["a2"][i + 1:])) > 1e-3


def test_missing_variables_are_listed(two_mass_fmu):
    sc = _scenario(two_mass_fmu, parameters={"k_mesh": 1.0, "a2": 3.0},
                   output={"sample_rate": 100.0, "variables": ["a2", "accel"]},
                   operating={"load": 20})
    with pytest.raises(FMUCompatibilityError) as info:
        run_scenario(sc, progress=False)
    m = info.value.mismatches
    assert any("'k_mesh'" in x for x in m)
    assert any("'accel'" in x for x in m)
    assert any("'load_torque'" in x for x in m)           # operating load drives this input
    assert any("'a2' has causality 'output'" in x for x in m)
    assert len(m) == 4


def test_ctrl_c_keeps_what_was_recorded_beside_the_output(two_mass_fmu, tmp_path):
    out = tmp_path / "run.h5"
    out.write_bytes(b"an earlier result")

    def interrupt(ctx):
        if ctx.step == 4:
            raise KeyboardInterrupt

    rec = run_scenario(_scenario(two_mass_fmu), out, hooks=[interrupt], progress=False)
    assert not rec.complete
    assert rec.result.time[-1] == pytest.approx(0.4)
    assert rec.path == tmp_path / "run.partial.h5"
    assert out.read_bytes() == b"an earlier result"      # only a complete run replaces it
    with h5py.File(rec.path) as f:
        assert not f.attrs["complete"]
        assert f["time"].shape == (41,)
    done = run_scenario(_scenario(two_mass_fmu), out, progress=False)
    assert done.complete and done.path == out and not rec.path.exists()


def test_event_on_a_recorded_output_is_refused(two_mass_fmu):
    sc = _scenario(two_mass_fmu, events=[{"time": 0.5, "override": {"a2": 0.0}}])
    with pytest.raises(FMUCompatibilityError, match="'a2' has causality 'output'.*event at t=0.5"):
        run_scenario(sc, progress=False)


def test_event_at_stop_time_is_logged_and_start_parameters_are_stored(two_mass_fmu):
    rec = run_scenario(_scenario(two_mass_fmu, parameters={"k1": 120.0},
                                 events=[{"time": 1.0, "override": {"k1": 300.0}}]), progress=False)
    assert [a for _, a in rec.events_applied] == ["override k1 = 300"]
    assert rec.result.parameters["k1"] == 120.0   # the values the run started with
