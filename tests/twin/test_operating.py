"""The operating point in FMU terms."""
from __future__ import annotations

import math

from twin.operating import consistent_start, operating_point


def test_operating_point_maps_speed_and_load():
    start, inputs = operating_point(10.0, 5.0)
    assert start == {"speed_ref_start": 2 * math.pi * 10.0, "load_start": 5.0}
    assert inputs == {"motor_speed_ref": 2 * math.pi * 10.0, "load_torque": 5.0}


def test_consistent_start_fills_only_what_is_missing_and_exists():
    tunable = ["speed_ref_start", "load_start", "c_mesh"]
    inputs = {"motor_speed_ref": 62.8, "load_torque": 5.0}
    assert consistent_start({"c_mesh": 900.0}, inputs, tunable) == \
        {"c_mesh": 900.0, "speed_ref_start": 62.8, "load_start": 5.0}
    # a value the scenario sets is kept
    assert consistent_start({"load_start": 7.0}, inputs, tunable)["load_start"] == 7.0
    # another model (no start parameters) is left alone, and so is a run without those inputs
    assert consistent_start({}, inputs, ["c_mesh"]) == {}
    assert consistent_start({}, {}, tunable) == {}
