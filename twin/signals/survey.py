"""Records of a modal survey: structural modes, fixed non-synchronous lines and speed-locked orders.

A run-up or a hammer test shows three kinds of spectral content, and only one of them is a mode
of the structure:

* :class:`Order` -- content locked to a shaft (shaft harmonics, gear-mesh orders); its frequency
  follows the speed;
* :class:`Line` -- a narrow line fixed in frequency through the run-up that is not locked to a
  shaft (a drive or supply frequency, an electrical pick-up); it does not broaden like a
  resonance and the orders that cross it are not amplified;
* :class:`Mode` -- a structural resonance: a hump fixed in frequency, as wide as its damping
  makes it, lit by broadband excitation and amplifying the orders that cross it.

Frequencies in Hz, levels in dB re the local spectral floor.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Mode:
    """A structural resonance.

    frequency : natural frequency [Hz]; damping : damping ratio [-] (NaN when not resolved);
    confidence : 0..1, how sure the survey is that this is a mode of the structure;
    prominence_db : height of the hump above the local floor [dB];
    evidence : what the classification rests on (width, persistence, crossing orders, ...).
    """

    frequency: float
    damping: float
    confidence: float
    prominence_db: float
    evidence: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Line:
    """A narrow line fixed in frequency and locked to no shaft [Hz]; level above the floor [dB]."""

    frequency: float
    level_db: float
    width_hz: float
    evidence: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Order:
    """Content locked to the reference shaft: order [cycles/rev], level above the floor [dB]."""

    order: float
    level_db: float
    persistence: float


@dataclass(frozen=True, eq=False)
class ModalSurvey:
    """The result of a run-up or hammer analysis.

    ``f`` (nf,), ``stationary_db`` (nf,): the spectrum the modes were read from [Hz, dB re floor];
    for a run-up also ``slice_speed`` (nt,) [Hz] and ``spectrogram_db`` (nf, nt) [dB re floor]
    for the Campbell plot; ``notes`` are warnings for the user.
    """

    method: str                              # "runup" or "hammer"
    modes: tuple[Mode, ...]
    lines: tuple[Line, ...]
    orders: tuple[Order, ...]
    band: tuple[float, float]
    resolution: float
    f: np.ndarray = field(repr=False)
    stationary_db: np.ndarray = field(repr=False)
    slice_speed: np.ndarray | None = field(default=None, repr=False)
    spectrogram_db: np.ndarray | None = field(default=None, repr=False)
    notes: tuple[str, ...] = ()
    channels: tuple[str, ...] = ()

    def frequencies(self, min_confidence: float = 0.0) -> np.ndarray:
        """Mode frequencies [Hz] with confidence >= ``min_confidence``, ascending."""
        return np.array(sorted(m.frequency for m in self.modes if m.confidence >= min_confidence))

    def to_dict(self) -> dict:
        def clean(v):
            if isinstance(v, (float, np.floating)):
                return None if not np.isfinite(v) else float(v)
            if isinstance(v, (np.integer,)):
                return int(v)
            if isinstance(v, Mapping):
                return {k: clean(x) for k, x in v.items()}
            if isinstance(v, (list, tuple, np.ndarray)):
                return [clean(x) for x in v]
            return v
        return clean({
            "method": self.method, "band_hz": list(self.band), "resolution_hz": self.resolution,
            "channels": list(self.channels),
            "modes": [{"frequency_hz": m.frequency, "damping_ratio": m.damping, "confidence": m.confidence,
                       "prominence_db": m.prominence_db, "evidence": dict(m.evidence)} for m in self.modes],
            "lines": [{"frequency_hz": ln.frequency, "level_db": ln.level_db, "width_hz": ln.width_hz,
                       "evidence": dict(ln.evidence)} for ln in self.lines],
            "orders": [{"order": o.order, "level_db": o.level_db, "persistence": o.persistence}
                       for o in self.orders],
            "notes": list(self.notes)})
