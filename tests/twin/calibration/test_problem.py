"""Calibration problem on the gearbox FMU: synthetic recovery, failures scored infeasible, outputs."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from twin.calibration.problem import (CalibrationTarget, EvalTask, ParameterSpace, calibrate, evaluate_candidate,
                                      write_parameter_set)
from twin.errors import ParameterError, ResumeError
from twin.executor import LocalExecutor
from twin.fmu import FMU
from twin.linearize import natural_frequencies

TRUTH = {"kt12": 1800.0, "c_mesh": 880.0}


@pytest.fixture(scope="module")
def target(gearbox_fmu):
    p = {**TRUTH, "speed_ref_start": 2 * math.pi * 20, "load_start": 20.0}
    with FMU(gearbox_fmu) as f:
        f.setup(0.0, parameters=p, inputs={"motor_speed_ref": 2 * math.pi * 20, "load_torque": 20.0})
        f.capture(0.1, 1e-5, ["accel_pinion_casing"])
        x = f.capture(0.3, 1e-5, ["accel_pinion_casing"])[:, 0]
    x = x + 0.05 * np.std(x) * np.random.default_rng(0).standard_normal(x.size)
    return CalibrationTarget(x, 1e5, 20.0, 20.0, natural_frequencies(gearbox_fmu, n=8, parameters=TRUTH))


def test_truth_scores_near_zero_and_defaults_do_not(gearbox_fmu, target):
    f_true, _ = evaluate_candidate(EvalTask(str(gearbox_fmu), TRUTH, target, 0.1, 0.2, target.measured_shaft_hz))
    f_def, _ = evaluate_candidate(EvalTask(str(gearbox_fmu), {}, target, 0.1, 0.2, target.measured_shaft_hz))
    assert f_true[0] < 0.02 and f_true[1] < 0.02 and f_true[2] < 1.0
    assert f_def[2] > 100 * max(f_true[2], 1e-3)


def test_calibration_moves_towards_truth(gearbox_fmu, target, tmp_path):
    # failing and crashing evaluations are scored infeasible: tests/robustness/test_isolation.py
    space = ParameterSpace.from_bounds({"kt12": [1000.0, 2500.0], "m5": [0.2, 1.0]})
    res = calibrate(gearbox_fmu, space, target, algorithm="nsga2", pop_size=6, n_gen=3, seed=1,
                    executor=LocalExecutor(2), settle=0.1, duration=0.2, fixed={"c_mesh": TRUTH["c_mesh"]},
                    checkpoint=tmp_path / "ckpt.json")
    assert res.n_evals == 18
    assert np.all(np.isfinite(res.F)) and res.F[:, 2].min() < 1e3
    assert set(res.chosen) == {"kt12", "m5"} and res.chosen["m5"] > 0
    ck = json.loads((tmp_path / "ckpt.json").read_text())
    assert ck["generation"] == 3 and len(ck["history"]) == 18


def test_parameter_sets_json_and_ssv(tmp_path):
    from twin.scenario import read_parameter_file
    write_parameter_set({"kt12": 1800.0, "k_pair[3]": 2.5e8}, tmp_path / "p.json")
    write_parameter_set({"kt12": 1800.0, "k_pair[3]": 2.5e8}, tmp_path / "p.ssv")
    assert read_parameter_file(tmp_path / "p.json") == read_parameter_file(tmp_path / "p.ssv") == \
        {"kt12": 1800.0, "k_pair[3]": 2.5e8}


def test_bad_bounds_are_refused():
    with pytest.raises(ParameterError, match="kt12"):
        ParameterSpace.from_bounds({"kt12": [2.0, 1.0]})


def test_resume_continues_from_the_checkpoint(gearbox_fmu, target, tmp_path):
    space = ParameterSpace.from_bounds({"kt12": [1000.0, 2500.0]})
    ck = tmp_path / "ck.json"
    common = dict(algorithm="nsga2", pop_size=4, seed=0, executor=LocalExecutor(1), settle=0.05, duration=0.1,
                  checkpoint=ck)
    calibrate(gearbox_fmu, space, target, n_gen=2, **common)
    assert json.loads(ck.read_text())["generation"] == 2
    res = calibrate(gearbox_fmu, space, target, n_gen=4, resume=True, **common)
    data = json.loads(ck.read_text())
    assert data["generation"] == 4 and res.n_evals == 16
    with pytest.raises(ResumeError, match="checkpoint"):
        calibrate(gearbox_fmu, ParameterSpace.from_bounds({"I1": [3e-3, 6e-3]}), target, n_gen=3, resume=True,
                  **common)
    with pytest.raises(ResumeError, match="another calibration"):     # same names, other bounds
        calibrate(gearbox_fmu, ParameterSpace.from_bounds({"kt12": [1200.0, 2500.0]}), target, n_gen=5,
                  resume=True, **common)


def test_refinement_recovers_the_modes(gearbox_fmu, target):
    from twin.calibration.problem import refine_modes
    from twin.calibration.objectives import frequency_mismatch
    space = ParameterSpace.from_bounds({"kt12": [1000.0, 2500.0], "c_mesh": [600.0, 1600.0]})
    x = refine_modes(gearbox_fmu, space, target, np.array([1300.0, 1100.0]), max_nfev=30)
    assert x[0] == pytest.approx(TRUTH["kt12"], rel=0.01)
    freqs = natural_frequencies(gearbox_fmu, n=12, parameters=space.to_dict(x))
    assert frequency_mismatch(freqs, target.natural_frequencies) < 0.5
