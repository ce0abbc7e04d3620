"""Effects a gearbox of this rig can carry, each with its own implementation and default size.

``pinion_runout`` (size: eccentricity [m])
    The pitch-circle centre off the rotation axis: TE along the line of action, the teeth's
    engagement shifted along it (phase modulation of the mesh), centre-distance (backlash)
    change, mass unbalance, and a lead wobble across the face of ``wobble_ratio`` times the
    run-out (a tilted gear), which modulates the face contact once per turn.
``gear_runout`` (eccentricity [m])
    The same on the gear.
``drive_ripple`` (torque amplitude [N m])
    The VFD's DC-link ripple on the motor air-gap torque: twice the mains (100 Hz, from the
    supply's phase unbalance) and half as much at 300 Hz (six-pulse rectifier). Locked to the
    mains, to no shaft.
``casing_resonance`` (modal participation at the pinion sensor [m/sqrt(kg)])
    A lightly damped inspection-cover panel under the pinion-side accelerometer: an extra
    panel mode (``frequency`` [Hz], ``damping``).
``local_tooth_fault`` (stiffness loss [-])
    One pinion tooth with a root crack (its pair stiffness times 1 - size) and a spall of
    ``depth`` [m] across the face in its dedendum, from the lowest point of single contact to
    the pitch point, where it carries the load alone.
``bearing_outer_race`` (defect length [m])
    A spall in the outer race of the pinion-shaft bearing (62xx, 9 balls) in the load zone:
    each ball unloads while it crosses the spall and strikes its far edge, at the ball-pass
    frequency with 1 % slip jitter. Not in the twin's catalogue.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from .flanks import ToothTables
from .structure import Panel

DEFAULTS = {
    "pinion_runout": {"size": 80e-6},
    "gear_runout": {"size": 100e-6},
    "drive_ripple": {"size": 0.3, "frequency": None},           # frequency: the drive's own
    "casing_resonance": {"size": 0.5, "frequency": 3700.0, "damping": 0.008},
    "local_tooth_fault": {"size": 0.35, "depth": 3e-6},
    "bearing_outer_race": {"size": 1.0e-3},
}
CATALOGUE = ("pinion_runout", "gear_runout", "drive_ripple", "casing_resonance",
             "local_tooth_fault")
OUTSIDE_CATALOGUE = ("bearing_outer_race",)
EFFECTS = CATALOGUE + OUTSIDE_CATALOGUE

#: Bearing of the pinion shaft (6205-type): balls, ball diameter, pitch diameter [m].
BEARING = {"balls": 9, "ball_diameter": 7.94e-3, "pitch_diameter": 39.04e-3}


@dataclass(frozen=True)
class Effect:
    """One effect with its parameters (``None`` fields take the default)."""

    name: str
    size: float | None = None
    frequency: float | None = None
    damping: float | None = None
    depth: float | None = None

    def resolved(self, ripple_frequency: float) -> "Effect":
        if self.name not in DEFAULTS:
            raise ValueError(f"unknown effect {self.name!r}; known: {', '.join(EFFECTS)}")
        d = dict(DEFAULTS[self.name])
        if self.name == "drive_ripple":
            d["frequency"] = ripple_frequency
        out = replace(self, **{k: (getattr(self, k) if getattr(self, k) is not None else v)
                               for k, v in d.items()})
        if out.size is None or not np.isfinite(out.size) or out.size < 0:
            raise ValueError(
                f"effect {self.name!r}: size must be finite and >= 0, got {out.size!r}")
        return out

    def as_dict(self) -> dict:
        return {k: v for k, v in asdict(self).items() if v is not None}


def as_effect(effect) -> Effect | None:
    """Accept None, a name, an ``Effect`` or a mapping with ``name``."""
    if effect is None or isinstance(effect, Effect):
        return effect
    if isinstance(effect, str):
        return Effect(effect)
    if isinstance(effect, dict):
        return Effect(**effect)
    raise TypeError(f"effect must be a name, an Effect or a mapping, got {effect!r}")


def ball_pass_outer(shaft_hz: float) -> float:
    """Outer-race ball-pass frequency [Hz] of the pinion bearing at a shaft speed [Hz]."""
    b = BEARING
    return 0.5 * b["balls"] * (1 - b["ball_diameter"] / b["pitch_diameter"]) * shaft_hz


def eccentricities(effect: Effect | None, base: float) -> tuple[float, float]:
    e1 = base + (effect.size if effect is not None and effect.name == "pinion_runout" else 0.0)
    e2 = base + (effect.size if effect is not None and effect.name == "gear_runout" else 0.0)
    return e1, e2


def extra_panel(effect: Effect | None) -> tuple[Panel, ...]:
    if effect is None or effect.name != "casing_resonance":
        return ()
    # small coupling to the pinion pedestal (the cover is bolted next to it), full at its sensor
    shape = (0.02, 0.06, 0.0, 0.01, effect.size, 0.04)
    return (Panel(effect.frequency, effect.damping, shape, "cover_panel"),)


def tooth_fault(tables: ToothTables, effect: Effect | None, tooth: int) -> ToothTables:
    if effect is None or effect.name != "local_tooth_fault":
        return tables
    s = tables.s / tables.s[-1]
    k = tables.pinion_k.copy()
    dev = tables.pinion_dev.copy()
    k[tooth] *= max(1.0 - effect.size, 0.02)
    # spall over s/L in [0.42, 0.58] with 0.1 mm edges
    edge = 1e-4 / tables.s[-1]
    spall = np.clip(np.minimum(s - 0.42, 0.58 - s) / edge, 0.0, 1.0)
    dev[tooth] += effect.depth * spall
    return tables.replace(pinion_k=k, pinion_dev=dev)


def ripple_torque(effect: Effect | None, t: np.ndarray, phase: float) -> np.ndarray:
    if effect is None or effect.name != "drive_ripple":
        return np.zeros_like(t)
    w = 2 * np.pi * effect.frequency
    return effect.size * (np.sin(w * t + phase) + 0.5 * np.sin(3 * w * t + 1.7 * phase))


def outer_race_force(effect: Effect | None, shaft_angle: np.ndarray, shaft_speed: np.ndarray,
                     dt: float, bearing_load: float, rng: np.random.Generator) -> np.ndarray:
    """Force [N] on the pinion shaft along the load-zone direction (reaction on the pedestal)."""
    out = np.zeros_like(shaft_angle)
    if effect is None or effect.name != "bearing_outer_race":
        return out
    b = BEARING
    ratio = b["ball_diameter"] / b["pitch_diameter"]
    cage = 0.5 * (1 - ratio) * shaft_angle                       # cage angle [rad]
    passes = b["balls"] * cage / (2 * np.pi)
    k = np.arange(np.ceil(passes[0] + 0.5), np.floor(passes[-1]))
    if k.size == 0:
        return out
    t_pass = np.interp(k, passes, np.arange(passes.size) * dt)
    period = np.gradient(t_pass) if k.size > 1 else np.full(1, 1.0)
    t_pass = t_pass + rng.normal(0.0, 0.01, k.size) * period     # cage slip
    ball_load = 5.0 * bearing_load / b["balls"]                  # Stribeck
    ball_speed = np.interp(t_pass / dt, np.arange(passes.size), shaft_speed)
    ball_speed = 2 * np.pi * np.abs(ball_speed) * 0.5 * (1 - ratio) * 0.5 * b["pitch_diameter"]
    n = out.size
    for tp, vb in zip(t_pass, ball_speed):
        width = effect.size / max(vb, 1e-3)                      # time in the spall [s]
        i0 = int(tp / dt)
        i1 = min(n, int((tp + width) / dt) + 1)
        if i0 >= n:
            continue
        out[i0:i1] -= ball_load                                  # the ball unloads
        m = max(2, int(4e-5 / dt))                               # edge strike, 40 us half-sine
        j1 = min(n, i1 + m)
        out[i1:j1] += 2.0 * ball_load * np.sin(np.pi * (np.arange(j1 - i1) + 0.5) / m)
    return out
