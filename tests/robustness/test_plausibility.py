"""Physical plausibility: parameter values refused up front, and runs that leave physics."""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.errors import ParameterError, ResumeError, SimulationError
from twin.plausibility import Limits, check_block, physical_problems

UNITS = {"k": "N/m", "kt": "N.m/rad", "c": "N.s/m", "ct": "N.m.s/rad", "m": "kg", "I": "kg.m2", "x": "m"}


@pytest.mark.parametrize("name, value, refused", [
    ("k", -1.0, True), ("k", 0.0, False), ("k", 1e8, False), ("kt", -5.0, True), ("c", -1e9, True),
    ("c", 0.0, False), ("ct", -0.1, True), ("m", 0.0, True), ("m", -2.0, True), ("m", 0.6, False),
    ("I", 0.0, True), ("I", 4e-3, False), ("x", -1.0, False), ("mesh_stiffness_scale", -1.0, True),
    ("mesh_stiffness_scale", 1e6, False), ("tooth_stiffness_factor[3]", -0.5, True), ("k", float("nan"), True),
])
def test_physical_problems(name, value, refused):
    assert bool(physical_problems({name: value}, UNITS)) == refused


def _block(a, force=None):
    names = ["accel", "f1", "f2", "f3"]
    f = np.full((a.size, 3), 100.0) if force is None else np.column_stack([force] * 3)
    return names, np.column_stack([a, f])


def test_a_plausible_window_passes():
    t = np.arange(4000) * 1e-5
    names, block = _block(50 * np.sin(2 * np.pi * 380 * t))
    check_block(names, block, {"accel": "m/s2"}, t0=0.0, dt=1e-5, load=20.0, constant_inputs=True,
                contact=block[:, 1:].sum(axis=1))


@pytest.mark.parametrize("what, words", [("accel", "beyond the bound"), ("contact", "never touch"),
                                         ("growth", "grows")])
def test_implausible_windows(what, words):
    t = np.arange(4000) * 1e-5
    a = 50 * np.sin(2 * np.pi * 380 * t)
    force = None
    if what == "accel":
        a[1234] = 3e6
    if what == "contact":
        force = np.zeros_like(t)
    if what == "growth":
        a = a * np.exp(t / 0.004)
    names, block = _block(a, force)
    with pytest.raises(SimulationError, match=words):
        check_block(names, block, {"accel": "m/s2"}, t0=0.0, dt=1e-5, load=20.0, constant_inputs=True,
                    contact=block[:, 1:].sum(axis=1), limits=Limits(max_acceleration=1e5 if what == "accel" else 1e9))


def test_no_contact_at_no_load_is_not_a_fault():
    names, block = _block(np.zeros(100), np.zeros(100))
    check_block(names, block, {}, t0=0.0, dt=1e-5, load=0.0, contact=block[:, 1:].sum(axis=1))


@pytest.mark.parametrize("params, error, words", [
    ({"mesh_stiffness_scale": 1e6}, SimulationError, "implausible"),
    ({"c_mesh": -1e9}, ParameterError, "damping cannot be negative"),
    ({"m10": 0.0}, ParameterError, "mass must be positive"),
])
def test_operating_point_runs_are_judged(gearbox_fmu, params, error, words):
    from twin.operating import simulate_operating_point
    with pytest.raises(error, match=words):
        simulate_operating_point(gearbox_fmu, 20.0, 20.0, parameters=params, settle=0.05, duration=0.1,
                                 channels=["accel_pinion_casing"])


def test_calibration_refuses_unknown_and_unphysical_parameters_up_front(gearbox_fmu):
    from twin.calibration.problem import ParameterSpace, check_calibration_parameters
    with pytest.raises(ParameterError, match="no parameter 'no_such'.*lower bound of 'c_mesh'"):
        check_calibration_parameters(gearbox_fmu, ParameterSpace.from_bounds({"no_such": [1, 2],
                                                                               "c_mesh": [-5.0, 10.0]}), None)
    with pytest.raises(ParameterError, match="not a Real parameter"):
        check_calibration_parameters(gearbox_fmu, ParameterSpace.from_bounds({"load_torque": [1, 2]}), None)


@pytest.mark.parametrize("text", ['{"algorithm": "nsga2", "generation": 1, "hist', '[]', '{"generation": "x"}', ""])
def test_damaged_checkpoint_is_named(tmp_path, text):
    from twin.calibration.problem import _read_checkpoint
    (tmp_path / "checkpoint.json").write_text(text)
    with pytest.raises(ResumeError, match="checkpoint.json"):
        _read_checkpoint(tmp_path / "checkpoint.json")


def test_run_identity_changes_with_what_decides_the_stages(gearbox_fmu):
    from twin.degradation_run import run_identity
    from twin.scenario import scenario_from_dict
    base = {"version": 1, "name": "d", "fmu": str(gearbox_fmu), "stop_time": 0.1,
            "degradation": {"model": "pitting", "stop": {"pitting_density": 0.1}, "max_increment": 0.01}}

    def ident(**changes):
        raw = json.loads(json.dumps(base))
        for k, v in changes.items():
            raw["degradation"][k] = v
        return run_identity(scenario_from_dict(raw), "sha")
    assert ident() == ident(stop={"pitting_density": 0.3}) == ident(max_updates=7)   # where it stops: same run
    assert ident() != ident(max_increment=0.02)
    assert run_identity(scenario_from_dict(base), "sha") != run_identity(scenario_from_dict(base), "other fmu")
