"""Degradation stages of the endurance tests, and records drawn within them.

Following the rig's two endurance tests: six pitting stages of about 3 % pitted area each up to
20 % (lubricated, 20 Hz / 20 N.m) and four wear stages of 60 um mean depth each (dry,
10 Hz / 5 N.m). A record of a stage has its damage drawn uniformly over the middle 70 % of the
stage's band (records are taken at different times within a stage), and per-record scatter of the
true speed (std 2 %), brake torque (std 10 %), sensor gain and noise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .record import Damage, RigRecord

PITTING_EDGES = (0.02, 0.05, 0.08, 0.11, 0.14, 0.17, 0.20)
WEAR_EDGES = (0.0, 60e-6, 120e-6, 180e-6, 240e-6)
SPEED_SCATTER = 0.02
LOAD_SCATTER = 0.10
BAND_USE = 0.7


@dataclass(frozen=True)
class Stage:
    """One degradation stage: label, damage band [lo, hi) and the test's operating point."""

    label: int
    kind: str
    low: float
    high: float
    speed: float          # [Hz] commanded pinion speed
    load: float           # [N m] nominal brake torque
    lubricated: bool

    @property
    def centre(self) -> float:
        return 0.5 * (self.low + self.high)

    def draw(self, rng: np.random.Generator) -> float:
        half = 0.5 * BAND_USE * (self.high - self.low)
        return float(rng.uniform(self.centre - half, self.centre + half))


def pitting_stages() -> tuple[Stage, ...]:
    e = PITTING_EDGES
    return tuple(Stage(i, "pitting", e[i], e[i + 1], 20.0, 20.0, True) for i in range(len(e) - 1))


def wear_stages() -> tuple[Stage, ...]:
    e = WEAR_EDGES
    return tuple(Stage(i, "wear", e[i], e[i + 1], 10.0, 5.0, False) for i in range(len(e) - 1))


def stage_records(rig, kind: str, per_stage: int, duration: float, seed: int) -> list[RigRecord]:
    """``per_stage`` steady records of every stage of ``kind`` (``pitting`` or ``wear``)."""
    if kind not in ("pitting", "wear"):
        raise ValueError(f"stage kind must be 'pitting' or 'wear', got {kind!r}")
    if int(per_stage) < 1:
        raise ValueError(f"per_stage must be >= 1, got {per_stage!r}")
    per_stage = int(per_stage)
    stages = pitting_stages() if kind == "pitting" else wear_stages()
    rng = np.random.default_rng([int(seed), 77])
    out = []
    for st in stages:
        # records within a stage in the order of the test (damage does not heal); names are a
        # running number, so nothing the twin reads carries the stage or the damage
        draws = sorted((st.draw(rng), int(rng.integers(0, 2 ** 31))) for _ in range(per_stage))
        for size, rec_seed in draws:
            rec = rig.steady(speed=st.speed, load=st.load, duration=duration,
                             damage=Damage(kind, size), seed=rec_seed,
                             name=f"{kind}_{len(out):03d}", lubricated=st.lubricated,
                             speed_scatter=SPEED_SCATTER, load_scatter=LOAD_SCATTER)
            rec.truth.update({"label": st.label, "stage_band": [st.low, st.high]})
            out.append(rec)
    return out
