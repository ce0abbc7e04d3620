"""What a reader of a measurement file hands to the validation: one record as stored
(:class:`_RawRecord`), and the problems found so far, raised together (:class:`_Problems`)."""
from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from twin.errors import MeasurementError


@dataclass
class _RawRecord:
    """One record as read from a file, before validation (samples as stored, float64)."""

    name: str
    channels: dict[str, np.ndarray]            # kept channels only
    units: dict[str, Any]                      # kept channel -> stored unit (None: missing)
    all_channels: list[str]                    # every channel in the file, kept or not
    attrs: dict[str, Any] | None               # None: no attributes could be read (no sidecar)
    metadata: dict[str, Any] = field(default_factory=dict)
    unchecked: set[str] = field(default_factory=set)   # value problems already reported
    require_sample_rate: bool = True
    unit_hint: str = "attribute 'unit'"


class _Problems:
    """Collects (file, record, problem) triples; raises them together."""

    def __init__(self, file: str):
        self.file = file
        self.items: list[tuple[str, str | None, str]] = []

    def add(self, record: str | None, problem: str) -> None:
        self.items.append((self.file, record, problem))

    def extend(self, record: str | None, problems: Iterable[str]) -> None:
        for p in problems:
            self.add(record, p)

    def raise_if_any(self) -> None:
        if self.items:
            raise MeasurementError(*self.items[0], problems=self.items)


def _number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and math.isfinite(v)
