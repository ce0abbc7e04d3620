"""The pure-Python reference FMU (pythonfmu) against the compiled Gearbox21 FMU.

Relative error is ``max|ref - compiled| / max|compiled|`` over all samples; the tolerance
is 1e-3 on the casing accelerations and the mesh force (measured agreement ~1e-11: both
FMUs run RK4 with the same sub-steps on the same equations).
"""
from __future__ import annotations

import sys
import zipfile

import fmpy
import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from twin.reference.gearbox_numpy import OUTPUT_NAMES
from twin.reference.gearbox_pythonfmu import PARAMETERS, build_reference_fmu

COMPARED = ("accel_pinion_casing", "accel_gear_casing", "mesh_force")
STOP, INTERVAL = 5e-3, 1e-4


@pytest.fixture(scope="module")
def reference_fmu(tmp_path_factory):
    return build_reference_fmu(tmp_path_factory.mktemp("reference_fmu"))


def rel_err(a, b) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def simulate(fmu, start_values=None, input=None):
    return fmpy.simulate_fmu(str(fmu), stop_time=STOP, output_interval=INTERVAL, fmi_type="CoSimulation",
                             start_values=start_values or {}, input=input, output=list(OUTPUT_NAMES))


def test_reference_fmu_is_valid(reference_fmu):
    """fmpy's validation finds no problem and the archive carries the model module it imports."""
    assert validate_fmu(str(reference_fmu)) == []
    md = read_model_description(str(reference_fmu))
    variables = {v.name: v for v in md.modelVariables}
    assert {v.name for v in md.modelVariables if v.causality == "output"} == set(OUTPUT_NAMES)
    assert all(variables[n].initial == "exact" for n in OUTPUT_NAMES)
    assert {v.name for v in md.modelVariables if v.causality == "input"} == {
        "motor_speed_ref", "drive_torque", "load_torque"}
    assert {"c_mesh", "mesh_stiffness_scale", "I5", "m5", "solver_step_size"} <= {
        v.name for v in md.modelVariables if v.causality == "parameter"}
    with zipfile.ZipFile(reference_fmu) as z:
        names = set(z.namelist())
    assert {"resources/gearbox_pythonfmu.py", "resources/gearbox_numpy.py"} <= names


def test_build_leaves_interpreter_clean(tmp_path):
    """pythonfmu's builder imports the slave script by its flat name; building must leave
    sys.path and the flat module entries of sys.modules as they were."""
    path_before = list(sys.path)
    flat = ("gearbox_numpy", "gearbox_pythonfmu")
    modules_before = {n: sys.modules.get(n) for n in flat}
    fmu = build_reference_fmu(tmp_path)
    assert fmu.is_file() and fmu.suffix == ".fmu"
    assert sys.path == path_before
    assert {n: sys.modules.get(n) for n in flat} == modules_before


def test_default_run_matches_compiled(reference_fmu, gearbox_fmu):
    """Defaults, 5 ms at 1e-4 s communication step: relative error < 1e-3 on the casing
    accelerations and the mesh force (and the other outputs)."""
    ref = simulate(reference_fmu)
    cmp_ = simulate(gearbox_fmu)
    np.testing.assert_allclose(ref["time"], cmp_["time"], rtol=0, atol=1e-12)
    for name in OUTPUT_NAMES:
        assert rel_err(ref[name], cmp_[name]) < 1e-3, name


def test_parameters_and_input_step_match_compiled(reference_fmu, gearbox_fmu):
    """Changed parameters (mesh damping, stiffness scale, pinion inertia and mass, pre-load),
    a coarser internal step (1e-5 s in both), and a brake-torque step 20 -> 35 N.m at 2 ms
    delivered through fmpy's input signal: relative error < 1e-3 on the compared outputs."""
    params = {"c_mesh": 800.0, "mesh_stiffness_scale": 0.9, "I5": 2.8e-4, "m5": 0.7, "load_start": 25.0}
    assert set(params) <= set(PARAMETERS)
    speed, drive = 2 * np.pi * 20, 0.0   # the other two inputs at their start values
    signal = np.array([(0.0, speed, drive, 20.0), (2e-3, speed, drive, 20.0),
                       (2e-3, speed, drive, 35.0), (STOP, speed, drive, 35.0)],
                      dtype=[("time", np.float64), ("motor_speed_ref", np.float64),
                             ("drive_torque", np.float64), ("load_torque", np.float64)])
    ref = simulate(reference_fmu, {**params, "solver_step_size": 1e-5}, signal)
    cmp_ = simulate(gearbox_fmu, {**params, "solver.step_size": 1e-5}, signal)
    for name in COMPARED:
        assert rel_err(ref[name], cmp_[name]) < 1e-3, name
    # The load step reached both models: more mesh force after it than before.
    late, early = ref["time"] > 3e-3, ref["time"] < 2e-3
    assert ref["mesh_force"][late].mean() > ref["mesh_force"][early].mean()
