"""The measured modes no gearbox mode can reach, put into the sensor's casing path.

At a casing accelerometer, a mode the gearbox model does not have is most likely the casing wall
between the bearings and the sensor: the rig's counterpart of the paper's foundation modes, which
the paper measured apart and removed. :func:`casing_path` gives the parameters that set such modes
as panel modes of the sensor path of ``GearTwin.Gearbox21Measured`` (and the models built on it).
"""
from __future__ import annotations

import numpy as np


#: Casing panel modes a sensor path of GearTwin.Gearbox21Measured can hold.
PANEL_SLOTS = 3


def casing_path(fmu, channel: str, unmatched_hz, freqs, damping, confidence, *, shared: int = 1
                ) -> dict[str, float]:
    """Parameters that put the measured modes no gearbox mode can reach into the sensor's casing path.

    A measured mode with no visible mode of the gearbox model within 15 % (with the shape
    pairing: none within reach whose shape is not refused) is something the gearbox model does
    not have; at a casing accelerometer the casing wall between the bearings
    and the sensor is what it most likely is (the rig's counterpart of the paper's foundation
    modes, which were measured apart and removed). The most confident of them, at most
    PANEL_SLOTS, become the path's panel modes: frequency and damping as measured, the sensor on
    the modal mass (participation 1; 1/``shared`` when the modes were read at several sensors,
    whose paths all get them, since a run-up does not say which sensor's casing they belong to).
    A mode outside the range the model declares for a panel (a 13 Hz hump is no casing panel) is
    left out rather than written as a parameter the FMU refuses. Empty when the model has no such
    path.
    """
    from twin.calibration.levels import SENSOR_OF_CHANNEL
    from twin.fmu import FMU

    sensor = SENSOR_OF_CHANNEL.get(channel)
    if sensor is None or len(unmatched_hz) == 0:
        return {}
    with FMU(fmu) as f:
        if f"{sensor}.panel_frequency[1]" not in f.variables:
            return {}
        sv = {v.name: v for v in f.model_description.modelVariables}[f"{sensor}.panel_frequency[1]"]
    lo = float(sv.min) if getattr(sv, "min", None) is not None else 0.0
    hi = float(sv.max) if getattr(sv, "max", None) is not None else np.inf
    picks = [i for i in np.argsort(-np.asarray(confidence))
             if np.any(np.isclose(freqs[i], unmatched_hz)) and lo <= freqs[i] <= hi]
    out = {}
    for slot, i in enumerate(sorted(picks[:PANEL_SLOTS], key=lambda i: freqs[i]), start=1):
        zeta = float(damping[i]) if np.isfinite(damping[i]) else 0.02
        out[f"{sensor}.panel_frequency[{slot}]"] = float(freqs[i])
        out[f"{sensor}.panel_damping[{slot}]"] = float(np.clip(zeta, 0.005, 0.1))
        out[f"{sensor}.panel_participation[{slot}]"] = 1.0 / shared
    return out
