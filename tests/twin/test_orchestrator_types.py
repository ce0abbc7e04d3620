"""Scenarios with variables of every type, FMU-ended runs and the model's default experiment
(the hand-written type-coverage FMUs, FMI 2.0 and 3.0)."""
from __future__ import annotations

import contextlib
import json

import h5py
import numpy as np
import pytest
import yaml

from twin.cli import main
from twin.errors import FMUCompatibilityError, TwinWarning
from twin.orchestrator import run_scenario
from twin.results import read_result
from twin.scenario import load_scenario

pytestmark = pytest.mark.needs_gcc


def _write(tmp_path, data: dict):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize("version", [2, 3])
def test_values_profiles_and_events_of_every_type(typecov_fmus, tmp_path, version):
    data = {"version": 1, "name": "types", "fmu": str(typecov_fmus[("AllTypes", version)]),
            "stop_time": 3.0, "communication_step": 0.5, "output": {"sample_rate": 10},
            "parameters": {"label": "wheel", "mode": "fast", "invert": True, "step": 2, "gain": 1},
            "operating": {"inputs": {
                "Boolean_input": {"steps": [[0, False], [1.0, True]]},
                "Enumeration_input": "slow",
                "String_input": {"steps": [[0, "a"], [2.0, "b"]]},
                "Real_input": {"ramp": {"from": 0, "to": 3, "duration": 3}},
                "Integer_input": {"constant": 7}}},
            "events": [{"time": 1.5, "override": {"mode": "off", "invert": False}},
                       {"time": 2.0, "bias": {"step": 1}},
                       {"time": 2.5, "reset": ["mode", "invert"]}]}
    if version == 3:
        data["parameters"]["Int8_parameter"] = -1
        data["operating"]["inputs"]["UInt64_input"] = {"steps": [[0, 1], [1.0, 2**64 - 1]]}
    # the FMI 3.0 build has a Binary output, which recording every output leaves out, saying so
    with pytest.warns(TwinWarning, match="Binary_output") if version == 3 else contextlib.nullcontext():
        rec = run_scenario(load_scenario(_write(tmp_path, data)), tmp_path / "r.h5", progress=False)
    r = rec.result
    t = r.time
    assert rec.complete and not r.ended_by_fmu and len(r) == 31
    # inputs are set at the start of each 0.5 s communication step and held over it
    held = np.floor(t * 2 - 1e-9).clip(0) / 2                       # start of the step a sample ends
    held[0] = 0.0
    boolean = held >= 1.0
    np.testing.assert_array_equal(r["Boolean_output"], boolean != np.where((t > 1.5) & (t <= 2.5), False, True))
    mode = np.where((t > 1.5) & (t <= 2.5), 1, 3)
    np.testing.assert_array_equal(r["Enumeration_output"], np.where(boolean, 2, mode))
    assert list(r["String_output"][[0, 20, 21, 30]]) == ["wheel:a", "wheel:a", "wheel:b", "wheel:b"]
    step = np.where(t > 2.0, 3, 2)
    np.testing.assert_array_equal(r["Integer_output"], 7 + step * np.floor(t + 1e-9).astype(int))
    np.testing.assert_allclose(r["Real_output"], held + 0.5, rtol=0, atol=1e-12)
    assert [a for _, a in rec.events_applied] == ["override mode = 'off'", "override invert = false",
                                                  "bias step += 1", "reset mode", "reset invert"]
    assert r.parameters["mode"] == 3 and r.parameters["label"] == "wheel"     # after initialisation
    if version == 3:
        assert r["UInt64_output"][0] == 1 ^ 1 and r["UInt64_output"][-1] == (2**64 - 1) ^ 1
    with h5py.File(tmp_path / "r.h5") as f:
        assert f["signals/String_output"].asstr()[0] == "wheel:a"
        assert f["signals/Integer_output"].dtype == np.int32


def test_every_type_problem_is_listed_before_running(typecov_fmus, tmp_path):
    data = {"version": 1, "name": "bad", "fmu": str(typecov_fmus[("AllTypes", 3)]), "stop_time": 1.0,
            "output": {"sample_rate": 10, "variables": ["Real_output", "Binary_output"]},
            "parameters": {"teeth": 20, "sections": 2, "mode": "medium", "step": 2.5, "label": 4},
            "operating": {"inputs": {"Integer_input": {"ramp": {"from": 0, "to": 3, "duration": 1}},
                                     "Boolean_input": "maybe"}},
            "events": [{"time": 0.5, "bias": {"invert": 1}}, {"time": 0.5, "override": {"ratio": 1.0}}]}
    out = tmp_path / "never.h5"
    with pytest.raises(FMUCompatibilityError) as info:
        run_scenario(load_scenario(_write(tmp_path, data)), out, progress=False)
    m = "\n".join(info.value.mismatches)
    for needle in ("'teeth' of AllTypes is a constant (value 19", "'sections' of AllTypes is a structural parameter",
                   "item of Mode", "'step' must be a whole number", "'label' must be a string",
                   "ramp or table profile needs a float input", "'Boolean_input' must be true or false",
                   "bias at t=0.5 s needs a number", "'ratio' of AllTypes is a calculated parameter",
                   "'Binary_output' is a Binary variable"):
        assert needle in m, needle
    assert len(info.value.mismatches) == 10
    assert not out.exists()


@pytest.mark.parametrize("version", [2, 3])
def test_a_run_the_fmu_ends_is_complete_kept_and_marked(typecov_fmus, tmp_path, capsys, version):
    """Staircase ends its experiment when the counter reaches 10: twin run exits 0, writes what
    there is (CSV, as asked) and applies no event after the end."""
    data = {"version": 1, "name": "stairs", "fmu": str(typecov_fmus[("Staircase", version)]),
            "events": [{"time": 3.0, "override": {"period": 0.5}}, {"time": 9.6, "override": {"period": 1.0}}]}
    path = _write(tmp_path, data)
    sc = load_scenario(path)
    # stop time and output rate come from the model's default experiment
    assert (sc.start_time, sc.stop_time, sc.sample_rate, sc.communication_step) == (0.0, 10.0, 5.0, 0.2)
    out = tmp_path / "stairs.csv"
    assert main(["run", str(path), "--output", str(out), "--no-progress"]) == 0
    assert "(ended by the FMU: " in capsys.readouterr().out
    r = read_result(out)
    # ticks at 1, 2, 3 s, then every 0.5 s: the counter reaches 10 at t = 6 s
    assert r.ended_by_fmu and r.time[-1] == 6.0 and r["counter"][-1] == 10 and len(r) == 31
    sidecar = json.loads((tmp_path / "stairs.csv.json").read_text())
    assert sidecar["complete"] is True and sidecar["ended_by_fmu"] is True
    assert [e["action"] for e in sidecar["events"]] == ["override period = 0.5"]
    # with the default period the FMU ends the run at t = 9 s
    data["events"] = []
    assert main(["run", str(_write(tmp_path, data)), "--output", str(tmp_path / "end.h5"), "--no-progress"]) == 0
    r = read_result(tmp_path / "end.h5")
    assert r.ended_by_fmu and r.time[-1] == 9.0 and r["counter"][-1] == 10 and len(r) == 46
    with h5py.File(tmp_path / "end.h5") as f:
        assert f.attrs["complete"] and f.attrs["ended_by_fmu"]


def test_run_output_format_follows_the_suffix(typecov_fmus, tmp_path, capsys):
    data = {"version": 1, "name": "ball", "fmu": str(typecov_fmus[("Ball", 2)])}
    path = _write(tmp_path, data)
    assert main(["run", str(path), "--output", str(tmp_path / "b.csv"), "--no-progress"]) == 0
    assert (tmp_path / "b.csv").read_text().startswith("time,h,v,bounces")
    units = json.loads((tmp_path / "b.csv.json").read_text())["units"]
    assert units["h"] == "m" and units["v"] == "m/s" and units["energy"] == "J/kg"
    assert main(["run", str(path), "--output", str(tmp_path / "b.mat"), "--no-progress"]) == 2
    assert "'.mat'" in capsys.readouterr().err and not (tmp_path / "b.mat").exists()
