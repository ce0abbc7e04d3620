"""The gearbox's operating point in FMU terms, and a steady-state capture at it.

A drive speed [Hz] and a brake load [N.m] map onto two inputs (``motor_speed_ref`` in rad/s,
``load_torque``) and two parameters (``speed_ref_start``, ``load_start``) that start the run
already twisted by the load at its slip speed. Every caller (calibration, comparison, archive,
demo) goes through here so that the mapping exists once.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np


def operating_point(speed_hz: float, load_nm: float) -> tuple[dict[str, float], dict[str, float]]:
    """(parameters, inputs) for a drive speed [Hz] and a brake load [N.m]."""
    omega = 2 * math.pi * float(speed_hz)
    return ({"speed_ref_start": omega, "load_start": float(load_nm)},
            {"motor_speed_ref": omega, "load_torque": float(load_nm)})


def consistent_start(parameters: Mapping[str, float], inputs: Mapping[str, float],
                     tunable: Sequence[str]) -> dict[str, float]:
    """``parameters`` with the start parameters filled in from the inputs at the start time.

    A run whose inputs start at another speed or load than ``speed_ref_start``/``load_start``
    (defaults: 20 Hz, 20 N.m) would begin with a transient: the flanks fly apart, and with the
    mesh damping acting only in contact, they may stay apart for seconds. Values the caller set
    are kept; start parameters the model does not have (not in ``tunable``, its parameter
    names) are not added.
    """
    out = dict(parameters)
    for par, inp in (("speed_ref_start", "motor_speed_ref"), ("load_start", "load_torque")):
        if par not in out and par in tunable and inp in inputs:
            out[par] = float(inputs[inp])
    return out


def simulate_operating_point(fmu_path: str | Path, speed_hz: float, load_nm: float, *,
                             parameters: Mapping[str, float] | None = None, settle: float = 0.1,
                             duration: float, channels: Sequence[str],
                             output_interval: float = 1e-5) -> np.ndarray:
    """Run at a steady operating point; discard ``settle`` s, return the next ``duration`` s.

    Returns shape (round(duration / output_interval), len(channels)).
    """
    from twin.fmu import FMU

    start, inputs = operating_point(speed_hz, load_nm)
    with FMU(fmu_path) as fmu:
        fmu.setup(0.0, parameters={**(parameters or {}), **start}, inputs=inputs)
        if settle > 0:
            fmu.capture(settle, output_interval, list(channels))
        return fmu.capture(settle + duration, output_interval, list(channels))
