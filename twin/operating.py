"""The gearbox's operating point in FMU terms, and a steady-state capture at it.

A drive speed [Hz] and a brake load [N.m] map onto two inputs (``motor_speed_ref`` in rad/s,
``load_torque``) and two parameters (``speed_ref_start``, ``load_start``) that start the run
already twisted by the load at its slip speed. Every caller (calibration, comparison, archive,
demo) goes through here so that the mapping exists once. :func:`measured_operating` and
:func:`simulate_at` put the model where a measured record was taken (its measured shaft speed),
for ``twin compare`` and ``twin diagnose`` alike.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
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

    The run is judged physically (:mod:`twin.plausibility`): parameters that make no sense
    are a :class:`~twin.errors.ParameterError`; flanks apart for the whole window at load,
    accelerations beyond the bound or vibration growing at these constant inputs are a
    :class:`~twin.errors.SimulationError`.
    """
    from twin.fmu_pool import reused
    from twin.plausibility import check_parameters, checked_capture

    start, inputs = operating_point(speed_hz, load_nm)
    with reused(fmu_path) as fmu:       # trials run the same FMU many times: opened once per process
        params = {**(parameters or {}), **start}
        check_parameters(fmu, params)
        fmu.setup(0.0, parameters=params, inputs=inputs)
        if settle > 0:
            fmu.capture(settle, output_interval, list(channels))
        return checked_capture(fmu, settle + duration, output_interval, channels, load=load_nm,
                               constant_inputs=True)


@dataclass(frozen=True)
class Operating:
    """Where a measured record was taken, in model terms (what compare and diagnose simulate at)."""

    drive_hz: float          # motor speed command that gives the measured shaft speed [Hz]
    shaft_hz: float          # measured pinion speed [Hz]
    load: float              # brake torque [N.m]
    sample_rate: float       # Hz
    settle: float = 0.15     # s simulated and discarded before the compared stretch
    # RK4 step of the trials [s]: 1e-5 s keeps the response within 4e-4 of the 5e-6 s default
    # (Gearbox21.readme.md), far below measurement noise, at half the cost
    solver_step: float | None = 1e-5
    teeth: int = 19          # pinion teeth, to read the shaft speed off the gear-mesh line


def stretch_speed(shaft_speed, n: int) -> float | None:
    """The mean pinion speed [Hz] over the last ``n`` samples of a record's per-sample speed
    ``shaft_speed`` (its encoder, tachometer or speed channel), or None when there is none
    (``shaft_speed`` None, or no finite sample in the stretch)."""
    if shaft_speed is None:
        return None
    speed = np.asarray(shaft_speed, float)[-int(n):]
    return float(np.nanmean(speed)) if np.any(np.isfinite(speed)) else None


def measured_operating(measured: np.ndarray, sample_rate: float, nominal_speed: float, load: float, *,
                       teeth: int, gear_teeth: int, c_motor: float | None, solver_step: float | None = 1e-5,
                       shaft_hz: float | None = None) -> Operating:
    """The operating point of a record: the pinion speed measured on it, and the drive command that
    gives that speed in the model.

    ``shaft_hz`` [Hz] is the pinion speed when the record gives it (an encoder); otherwise it is
    read off the gear-mesh line of ``measured`` (an induction motor slips under load, so the
    nominal drive setting is not the shaft speed). With ``c_motor`` [N.m.s/rad], the slope of the
    model's motor torque-slip line, the drive command is the shaft speed plus the slip the load
    causes; without it (a model with another drive), the drive command is the shaft speed.
    """
    from twin.calibration.objectives import estimate_shaft_hz
    shaft = float(shaft_hz) if shaft_hz is not None else estimate_shaft_hz(measured, sample_rate, nominal_speed, teeth)
    slip = load * teeth / gear_teeth / c_motor / (2 * math.pi) if c_motor else 0.0
    return Operating(shaft + slip, shaft, float(load), float(sample_rate), solver_step=solver_step, teeth=teeth)


def simulate_at(fmu_path, parameters: Mapping[str, float], op: Operating, n: int,
                channels: str | Sequence[str], *, retune: bool = True) -> np.ndarray:
    """Model signal at the operating point, after ``op.settle`` s, with the pinion at ``op.shaft_hz``.

    Returns (n,) for one channel name, (n, len(channels)) for a list; the first channel must be a
    casing acceleration (its gear-mesh line checks the speed). The drive command comes from the
    slip of the loaded motor; an effect that adds losses (tooth friction) or torque slows the shaft
    a little more, and at the 13th mesh harmonic a few mHz of shaft speed already move a line by
    a bin. So the shaft speed of the result is read off its gear-mesh line and, if it is off by
    more than 1 mHz, the run is repeated with the drive corrected by that amount. ``retune=False``
    runs once at ``op.drive_hz`` (a short search run: 1 s of signal cannot resolve 1 mHz, the
    zero-padded gear-mesh bin is 2.5 mHz of shaft speed at 50 kHz).
    """
    return simulate_settled(fmu_path, parameters, op, n, channels, retune=retune)[1]


def simulate_settled(fmu_path, parameters: Mapping[str, float], op: Operating, n: int,
                     channels: str | Sequence[str], *, retune: bool = True) -> tuple[Operating, np.ndarray]:
    """:func:`simulate_at`, also returning the operating point with the drive command that gave
    the measured shaft speed: runs of the same model started from it need no second run."""
    from dataclasses import replace

    from twin.calibration.objectives import estimate_shaft_hz
    single = isinstance(channels, str)
    names = [channels] if single else list(channels)
    if op.solver_step is not None:
        parameters = {**parameters, "solver.step_size": op.solver_step}
    drive = op.drive_hz
    for attempt in range(2):
        block = simulate_operating_point(fmu_path, drive, op.load, parameters=parameters, settle=op.settle,
                                         duration=n / op.sample_rate, channels=names,
                                         output_interval=1.0 / op.sample_rate)[:n]
        if attempt or not retune or not np.all(np.isfinite(block)):
            break
        error = op.shaft_hz - estimate_shaft_hz(block[:, 0], op.sample_rate, op.shaft_hz, op.teeth)
        if abs(error) <= 1e-3:
            break
        drive += error
    return replace(op, drive_hz=drive), (block[:, 0] if single else block)
