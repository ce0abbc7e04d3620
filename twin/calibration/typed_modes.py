"""Calibration to typed natural frequencies without a measurement file (``twin calibrate`` without
``--measurements``): what such a calibration block may ask for, and its operating point.

A published table of modes (a paper's, a hammer-test report's) has no time record, so only the
``modes`` objective can be scored; the modes' operating point (speed, load: the mesh stiffness
and the bearing loads depend on it) comes from the block or from the scenario's constant
operating profile.
"""
from __future__ import annotations

import math

from twin.errors import ScenarioError


def modes_only_objectives(spec: dict, source: str) -> tuple[str, ...]:
    """The objectives of a calibration without a measurement file: ``("modes",)``; anything that
    needs a record is refused by name."""
    if spec.get("modes_from"):
        raise ScenarioError([(source, "calibration.modes_from", f"reads the modes from record {spec['modes_from']!r}: "
                              "give --measurements FILE, or type the modes in natural_frequencies")])
    if isinstance(spec.get("foundation_modes"), str):
        raise ScenarioError([(source, "calibration.foundation_modes", f"reads hammer record "
                              f"{spec['foundation_modes']!r}: give --measurements FILE, or the foundation's modes in Hz")])
    if not spec.get("natural_frequencies"):
        raise ScenarioError([(source, "calibration.natural_frequencies", "without --measurements the measured natural "
                              "frequencies must be typed here [Hz]")])
    objectives = tuple(spec.get("objectives", ["modes"]))
    others = [o for o in objectives if o != "modes"]
    if others:
        raise ScenarioError([(source, "calibration.objectives", f"{', '.join(others)} need a measured record: give "
                              "--measurements FILE, or objectives: [modes] to calibrate to the natural frequencies "
                              "alone")])
    return objectives


def typed_operating_point(scenario, spec: dict) -> tuple[float, float]:
    """(speed [Hz], load [N.m]) of typed modes: the block's ``speed``/``load``, else the scenario's
    constant operating speed and load; a missing or varying one is refused by name."""
    op = scenario.raw.get("operating") or {}
    out, problems = [], []
    for key, scale, default_input in (("speed", 2 * math.pi, "motor_speed_ref"), ("load", 1.0, "load_torque")):
        if key in spec:
            out.append(float(spec[key]))
            continue
        prof = scenario.inputs.get(op.get(f"{key}_input", default_input)) if key in op else None
        if prof is not None and len(set(prof.values)) == 1:
            out.append(float(prof.values[0]) / scale)
        else:
            problems.append((str(scenario.source), f"calibration.{key}", f"the modes' operating {key} "
                             f"[{'Hz' if key == 'speed' else 'N.m'}] is needed without --measurements: give it here "
                             f"or as a constant operating.{key}"))
    if problems:
        raise ScenarioError(problems)
    return out[0], out[1]
