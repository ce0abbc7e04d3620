"""A second FMI/SSP importer: OSP libcosim (libcosimpy) runs our FMUs and .ssp packages.

Its outputs are compared with twin.fmu sample by sample: the largest difference of each
output, relative to the largest magnitude of that output, must stay within 1e-8.
"""
from __future__ import annotations

import numpy as np
import pytest

from twin.fmu import FMU

pytestmark = pytest.mark.needs_gcc

STEP = 1e-4          # s, libcosim's fixed co-simulation step
STEPS = 300
TOLERANCE = 1e-8


def max_relative_difference(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per column: max |a - b| / max |b| (written apart from the code it judges)."""
    scale = np.abs(b).max(axis=0)
    scale[scale == 0] = 1.0
    return np.abs(a - b).max(axis=0) / scale


@pytest.fixture(autouse=True)
def _quiet():
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.ERROR)


def _run_libcosim(execution, names: list[str], steps: int = STEPS) -> tuple[np.ndarray, dict[str, float]]:
    """Step ``execution`` and return (steps, len(names)) outputs of slave 0 and its final Reals."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimObserver import CosimObserver

    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    reals = {v.name.decode(): v.reference for v in execution.slave_variables(0)
             if v.type == CosimVariableType.REAL.value}
    refs = [reals[n] for n in names]
    rows = []
    for _ in range(steps):
        assert execution.step(1)
        rows.append(observer.last_real_values(0, refs))
    everything = dict(zip(reals, observer.last_real_values(0, list(reals.values()))))
    return np.array(rows), everything


def _run_twin(fmu_path, parameters=None, steps: int = STEPS) -> tuple[np.ndarray, list[str]]:
    with FMU(fmu_path) as fmu:
        names = [v.name for v in fmu.outputs]
        fmu.setup(0.0, parameters=parameters)
        result = fmu.run(steps * STEP, STEP)
    return np.column_stack([result.signals[n] for n in names])[1:], names


def test_libcosim_runs_the_gearbox_fmu_like_twin(gearbox_fmu):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave

    ours, names = _run_twin(gearbox_fmu)
    execution = CosimExecution.from_step_size(step_size=int(round(STEP * 1e9)))
    assert execution.add_local_slave(CosimLocalSlave(fmu_path=str(gearbox_fmu), instance_name="gearbox")) == 0
    theirs, _ = _run_libcosim(execution, names)
    assert np.abs(ours).max() > 0
    diff = max_relative_difference(theirs, ours)
    assert diff.max() <= TOLERANCE, dict(zip(names, diff))


def test_libcosim_runs_an_exported_ssp_with_its_parameter_values(gearbox_fmu, tmp_path):
    from libcosimpy.CosimExecution import CosimExecution

    from twin.ssp import write_ssp

    values = {"kt12": 1800.0, "c_mesh": 900.0, "mesh_stiffness_scale": 0.9}
    ssp = write_ssp(gearbox_fmu, values, tmp_path / "gearbox.ssp")
    ours, names = _run_twin(gearbox_fmu, values)
    default, _ = _run_twin(gearbox_fmu)
    theirs, final = _run_libcosim(CosimExecution.from_ssp_file(str(ssp)), names)
    assert {k: final[k] for k in values} == values
    diff = max_relative_difference(theirs, ours)
    assert diff.max() <= TOLERANCE, dict(zip(names, diff))
    # and the values matter: the default parameters give other outputs
    assert max_relative_difference(default, ours).max() > 1e-3
