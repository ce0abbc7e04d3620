"""Effects a gearbox can carry, each with this rig's own implementation and default size.

| name | implementation |
|---|---|
| pinion_runout | eccentric pinion: its teeth reach the line of action early or late (separation and contact timing) and the path of contact shortens as the centre distance grows, once per pinion revolution |
| gear_runout | the same on the gear, once per gear revolution |
| drive_ripple | armature-torque ripple of the drive at a fixed frequency (a supply interharmonic), locked to no shaft |
| casing_resonance | the pinion-side accelerometer sits on a bracket with its own lightly damped resonance |
| local_tooth_fault | a spall on one pinion tooth across part of the face, through the slice-wise contact |
| bearing_outer_race | (outside the twin's catalogue) a localised outer-race defect of the pinion back-wall bearing: impacts at the ball-pass frequency with rolling-element slip |
| coupling_misalignment | (outside the twin's catalogue) parallel offset of the pinion jaw coupling: radial force and torque twice per revolution |
"""
from __future__ import annotations

from dataclasses import dataclass, field

DEFAULTS = {
    "pinion_runout": {"eccentricity": 80e-6, "phase": 0.7},
    "gear_runout": {"eccentricity": 200e-6, "phase": 2.1},
    "drive_ripple": {"frequency": 347.0, "amplitude": 0.8, "phase": 0.0},
    "casing_resonance": {"frequency": 3300.0, "damping": 0.03, "channel": "accel_pinion_casing"},
    "local_tooth_fault": {"tooth": 5, "from_pitch": -1.8e-3, "to_pitch": 1.6e-3,
                          "face_from": 0.0, "face_to": 0.9, "depth": 40e-6},
    "bearing_outer_race": {"bearing": 1, "severity": 0.35, "pulse": 0.12e-3, "jitter": 0.01},
    "coupling_misalignment": {"force": 45.0, "torque": 0.12, "phase": 0.3},
}
OUTSIDE_CATALOGUE = ("bearing_outer_race", "coupling_misalignment")
UNITS = {"eccentricity": "m", "frequency": "Hz", "amplitude": "N m", "damping": "1",
         "depth": "m", "from_pitch": "m of path", "to_pitch": "m of path", "force": "N",
         "torque": "N m", "severity": "1 (peak impulse force / static bearing load)",
         "pulse": "s", "face_from": "1 (of the face width)", "face_to": "1 (of the face width)"}


class EffectError(ValueError):
    """An unknown effect or a bad effect parameter."""


@dataclass(frozen=True)
class Effect:
    name: str
    params: dict = field(default_factory=dict)


def resolve(effect) -> Effect | None:
    """None, a name, a mapping {'name': ..., **params} or an Effect -> Effect with defaults."""
    if effect is None:
        return None
    if isinstance(effect, str):
        name, over = effect, {}
    elif isinstance(effect, Effect):
        name, over = effect.name, dict(effect.params)
    elif isinstance(effect, dict):
        over = dict(effect)
        name = over.pop("name", None)
    else:
        raise EffectError(f"effect must be a name, a mapping or an Effect, not {effect!r}")
    if name not in DEFAULTS:
        raise EffectError(f"unknown effect {name!r}; known: {', '.join(DEFAULTS)}")
    unknown = set(over) - set(DEFAULTS[name])
    if unknown:
        raise EffectError(f"effect {name!r} has no parameter {sorted(unknown)[0]!r}")
    return Effect(name, {**DEFAULTS[name], **over})
