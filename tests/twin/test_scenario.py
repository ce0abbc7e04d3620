"""twin.scenario: schema validation lists every problem; profiles and parameter files."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from twin.errors import ScenarioError
from twin.scenario import SCHEMA, load_scenario, read_parameter_file, scenario_from_dict

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", sorted(p.name for p in (REPO / "scenarios").glob("*.yaml")))
def test_shipped_scenarios_are_valid(name):
    sc = load_scenario(REPO / "scenarios" / name)
    assert sc.stop_time > sc.start_time


def test_every_problem_is_reported_at_once(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("""
version: 1
name: bad
fmu: x.fmu
stop_time: -1
communication_step: 0.01
colour: blue
operating:
  speed: {ramp: {from: 1}}
events:
  - {time: 0.5, override: {k1: [1, 2]}}
""")
    with pytest.raises(ScenarioError) as info:
        load_scenario(bad)
    msg = str(info.value)
    paths = {k for _, k, _ in info.value.problems}
    assert {"stop_time", "(top level)", "operating.speed", "events[0].override.k1"} <= paths, msg
    assert "unknown key(s)" in msg and "'colour'" in msg
    assert str(bad) in msg
    assert len(info.value.problems) >= 4


def test_semantic_problems_are_all_listed():
    data = {"version": 1, "name": "s", "fmu": "m.fmu", "start_time": 1.0, "stop_time": 0.5,
            "communication_step": 0.015, "output": {"sample_rate": 100.0},
            "events": [{"time": 0.7, "override": {"a": 1}}, {"time": 0.2, "reset": ["a"]}]}
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict(data)
    keys = [k for _, k, _ in info.value.problems]
    assert "stop_time" in keys
    assert "communication_step" in keys          # 1.5 samples per step
    assert "events" in keys                      # not ascending
    assert sum(k.startswith("events[") for k in keys) >= 2


def test_profiles_ramp_steps_table(tmp_path):
    (tmp_path / "prof.csv").write_text("time,load\n0,5\n1,15\n")
    data = {"version": 1, "name": "p", "fmu": "m.fmu", "stop_time": 2.0, "output": {"sample_rate": 1e5},
            "operating": {"speed": {"ramp": {"from": 2, "to": 22, "start": 1.0, "duration": 10}},
                          "load": {"table": {"file": "prof.csv", "column": "load"}},
                          "inputs": {"drive_torque": {"steps": [[0, 0.0], [0.5, 1.0]]}}}}
    sc = scenario_from_dict(data, source=tmp_path / "p.yaml")
    speed = sc.inputs["motor_speed_ref"]
    assert speed(0.0) == pytest.approx(2 * 3.141592653589793 * 2)
    assert speed(6.0) == pytest.approx(2 * 3.141592653589793 * 12)
    assert sc.inputs["load_torque"](0.5) == pytest.approx(10.0)
    assert sc.inputs["drive_torque"](0.49) == 0.0 and sc.inputs["drive_torque"](0.5) == 1.0


def test_missing_table_and_bad_columns(tmp_path):
    (tmp_path / "p.csv").write_text("t,x\n0,1\n")
    data = {"version": 1, "name": "p", "fmu": "m.fmu", "stop_time": 2.0, "output": {"sample_rate": 1e5},
            "operating": {"load": {"table": {"file": "missing.csv", "column": "load"}},
                          "speed": {"table": {"file": "p.csv", "column": "speed"}}}}
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict(data, source=tmp_path / "p.yaml")
    msg = str(info.value)
    assert "missing.csv" in msg and "'speed'" in msg


def test_parameter_files_json_and_ssv(tmp_path):
    (tmp_path / "a.json").write_text(json.dumps({"parameters": {"k1": 2.0, "m1": 3.0}}))
    (tmp_path / "b.ssv").write_text(
        '<?xml version="1.0"?><ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
        'version="1.0" name="b"><ssv:Parameters><ssv:Parameter name="k1"><ssv:Real value="5.0"/></ssv:Parameter>'
        '</ssv:Parameters></ssv:ParameterSet>')
    assert read_parameter_file(tmp_path / "b.ssv") == {"k1": 5.0}
    data = {"version": 1, "name": "p", "fmu": "m.fmu", "stop_time": 1.0, "output": {"sample_rate": 1e5},
            "parameter_files": ["a.json", "b.ssv"], "parameters": {"m1": 4.0}}
    sc = scenario_from_dict(data, source=tmp_path / "p.yaml")
    assert sc.parameters == {"k1": 5.0, "m1": 4.0}
    (tmp_path / "c.json").write_text("[1, 2]")
    with pytest.raises(ScenarioError, match="parameter name -> value"):
        read_parameter_file(tmp_path / "c.json")


def test_schema_is_valid_json_schema():
    import jsonschema
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
