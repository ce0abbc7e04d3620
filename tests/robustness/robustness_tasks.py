"""Top-level task functions for worker processes in the robustness tests (importable by name:
the spawned workers unpickle them by module and name)."""
from __future__ import annotations

import ctypes
import time

import numpy as np


def simulate_faulty(task):
    """(fmu path, fault mode) -> last x of a 0.1 s run of the Faulty FMU."""
    from twin.fmu import simulate_fmu
    path, mode = task
    r = simulate_fmu(path, stop_time=0.1, output_interval=0.01, parameters={"fault": float(mode)})
    return float(r.signals["x"][-1])


def python_fault(kind):
    """A fault of the task's own process, outside any FMU."""
    if kind == "segfault":
        ctypes.string_at(0)
    if kind == "hang":
        while True:
            time.sleep(60)
    if kind == "raise":
        raise ValueError("an ordinary error")
    return kind


def _objectives(path, parameters, fault):
    from twin.fmu import simulate_fmu
    r = simulate_fmu(path, stop_time=0.2, output_interval=0.001,
                     parameters={**parameters, "fault": float(fault)})
    x = r.signals["x"]
    # distances of the oscillation's frequency, decay and level from a reference oscillator
    k, c = parameters["k"], parameters["c"]
    return np.array([abs(np.sqrt(k) - 100.0), abs(c - 2.0), float(np.sqrt(np.mean(x ** 2)))]), {}


def faulty_fmu_evaluate(task):
    """Calibration evaluation on the Faulty FMU in fault mode 7: the FMU itself segfaults for one
    stiffness in ten and loops for one in ten (by the last digit of round(1000 k))."""
    return _objectives(task.fmu_path, task.parameters, 7)


def reference_evaluate(task):
    """The same evaluation, with the same parameter sets failing by an ordinary exception."""
    from twin.errors import SimulationError
    digit = round(1000 * task.parameters["k"]) % 10
    if digit in (0, 1):
        raise SimulationError(f"reference failure (digit {digit})")
    return _objectives(task.fmu_path, task.parameters, 0)
