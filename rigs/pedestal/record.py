"""Records produced by the rig, and the damage specification."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

DAMAGE_KINDS = ("pitting", "wear")


@dataclass(frozen=True)
class Damage:
    """Surface damage of the gearbox.

    ``pitting``: pitted fraction of the pinion's active flank area [0, 1).
    ``wear``: mean wear depth of the pinion's active flank [m].
    """

    kind: str
    size: float

    def __post_init__(self):
        if self.kind not in DAMAGE_KINDS:
            raise ValueError(f"unknown damage kind {self.kind!r}; known: {', '.join(DAMAGE_KINDS)}")
        size = float(self.size)
        if not np.isfinite(size) or size < 0 or (self.kind == "pitting" and size >= 1.0):
            raise ValueError(f"damage {self.kind!r}: bad size {self.size!r}")
        if self.kind == "wear" and size > 1e-3:
            raise ValueError(f"wear depth is in m; {self.size!r} m is beyond a module-3 tooth")


def as_damage(damage) -> Damage | None:
    """Accept None, a ``Damage``, a ``(kind, size)`` pair or a mapping."""
    if damage is None or isinstance(damage, Damage):
        return damage
    if isinstance(damage, (tuple, list)) and len(damage) == 2:
        return Damage(str(damage[0]), float(damage[1]))
    if isinstance(damage, dict):
        return Damage(**damage)
    raise TypeError(f"damage must be a Damage, a (kind, size) pair or a mapping, got {damage!r}")


@dataclass(frozen=True)
class RigRecord:
    """One simulated measurement and what only the rig knows about it.

    ``channels`` map names to float arrays at ``sample_rate`` [Hz]; ``units`` give their units in
    the measurement format's vocabulary. ``attributes`` are the record attributes written to
    the measurement file; ``truth`` goes only to the truth file.
    """

    name: str
    channels: dict
    units: dict
    sample_rate: float
    attributes: dict
    truth: dict = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return next(iter(self.channels.values())).size

    @property
    def duration(self) -> float:
        return self.n_samples / self.sample_rate

    def __getitem__(self, channel: str) -> np.ndarray:
        return self.channels[channel]

    def renamed(self, name: str) -> "RigRecord":
        return RigRecord(name, self.channels, self.units, self.sample_rate, self.attributes,
                         self.truth)
