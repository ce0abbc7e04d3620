"""In-memory measurement records: :class:`Record` and :class:`MeasurementSet`.

Both are frozen and their sample arrays read-only, so a record handed to a feature extractor
or a transfer-learning stage cannot be altered behind the loader's back. Construction checks
the invariants of the format (one length for all channels, canonical units, finite samples,
consistent tachometer attributes) and raises :class:`twin.errors.MeasurementError` listing
every violation, so a record built in memory is as trustworthy as one loaded from a file.
"""
from __future__ import annotations

import math
import types
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from twin.errors import MeasurementError
from twin.measurements.format import CANONICAL_UNITS, RESERVED_CHANNELS, TACHOMETER_KINDS, TACHOMETER_UNITS

_MEMORY = "<memory>"


@dataclass(frozen=True, eq=False)
class Record:
    """One vibration record: equally sampled channels plus the operating point.

    Attributes
    ----------
    name : str
        Record name (the HDF5 group name under ``/records``); no ``/``.
    channels : mapping of str -> ndarray
        Channel name -> ``(n,)`` read-only float64 samples in the canonical unit.
    units : mapping of str -> str
        Channel name -> canonical unit (``m/s2``, ``m/s``, ``m``, ``rad``, ``N``, ``N.m``,
        ``V``, ``rad/s``, ``Hz`` or ``1`` for dimensionless).
    sample_rate : float
        Sampling rate of every channel [Hz].
    nominal_speed : float or None
        Input (pinion) shaft speed [Hz].
    load : float or None
        Brake torque [N.m].
    tachometer : str or None
        Channel holding the shaft reference.
    tachometer_kind : str or None
        ``'pulse'`` (pulse train) or ``'angle'`` (unwrapped encoder angle [rad]).
    pulses_per_rev : int or None
        Pulses per shaft revolution (pulse tachometer only).
    label : int or None
        Class label (e.g. damage stage).
    damage : float or None
        Damage measure (pitting density, or mean wear depth [m]).
    source : str or None
        File the record was loaded from.
    time_start : float
        Time of the first sample [s].
    resampled_from : float or None
        Original sampling rate [Hz] if the record was resampled, else ``None``.
    metadata : mapping
        Attributes outside the format, kept verbatim.
    """

    name: str
    channels: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    sample_rate: float
    nominal_speed: float | None = None
    load: float | None = None
    tachometer: str | None = None
    tachometer_kind: str | None = None
    pulses_per_rev: int | None = None
    label: int | None = None
    damage: float | None = None
    source: str | None = None
    time_start: float = 0.0
    resampled_from: float | None = None
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        problems: list[str] = []
        if not isinstance(self.name, str) or not self.name or "/" in self.name or self.name in (".", ".."):
            problems.append(f"record name must be a non-empty string without '/', got {self.name!r}")
        given = dict(self.channels)
        chans: dict[str, np.ndarray] = {}
        for c, x in given.items():
            if not isinstance(c, str) or not c or "/" in c or c in RESERVED_CHANNELS:
                problems.append(f"channel name {c!r} is not allowed (empty, contains '/', or reserved: "
                                f"{', '.join(RESERVED_CHANNELS)})")
                continue
            # A private copy: the caller's array must not be able to change a frozen record.
            a = np.array(x, dtype=np.float64)
            if a.ndim != 1:
                problems.append(f"channel '{c}' must be 1-D, got shape {a.shape}")
                continue
            if not np.all(np.isfinite(a)):
                problems.append(f"channel '{c}' has non-finite samples; first at index "
                                f"{int(np.argmax(~np.isfinite(a)))}")
            a.flags.writeable = False
            chans[c] = a
        if not chans and not problems:
            problems.append("empty record: no channels")
        lengths = {c: a.size for c, a in chans.items()}
        if len(set(lengths.values())) > 1:
            problems.append("channels differ in length: " + ", ".join(f"{c}={n}" for c, n in lengths.items()))
        elif chans and next(iter(lengths.values())) == 0:
            problems.append("empty record: channels have no samples")
        units = dict(self.units)
        for c in chans:
            u = units.get(c)
            if u is None:
                problems.append(f"channel '{c}' has no unit")
            elif u not in CANONICAL_UNITS:
                problems.append(f"channel '{c}' has unit {u!r}, not a canonical unit "
                                f"({', '.join(sorted(CANONICAL_UNITS))}); load through load_measurements "
                                "to convert")
        for c in units:
            if c not in given:
                problems.append(f"unit given for channel '{c}', which is not in the record")
        if not _positive(self.sample_rate):
            problems.append(f"sample_rate must be a finite number > 0 [Hz], got {self.sample_rate!r}")
        if self.nominal_speed is not None and not _positive(self.nominal_speed):
            problems.append(f"nominal_speed must be a finite number > 0 [Hz], got {self.nominal_speed!r}")
        if self.resampled_from is not None and not _positive(self.resampled_from):
            problems.append(f"resampled_from must be a finite number > 0 [Hz], got {self.resampled_from!r}")
        for attr in ("load", "damage", "time_start"):
            v = getattr(self, attr)
            if v is not None and not _finite(v):
                problems.append(f"{attr} must be a finite number, got {v!r}")
        if self.time_start is None:
            problems.append("time_start must be a finite number [s], got None")
        if self.label is not None and (isinstance(self.label, bool) or not isinstance(self.label, (int, np.integer))):
            problems.append(f"label must be an integer, got {self.label!r}")
        if self.tachometer is not None:
            if self.tachometer not in chans:
                problems.append(f"tachometer channel '{self.tachometer}' is not in the record")
            if self.tachometer_kind not in TACHOMETER_KINDS:
                problems.append(f"tachometer_kind must be one of {', '.join(TACHOMETER_KINDS)}, "
                                f"got {self.tachometer_kind!r}")
            elif self.tachometer in units and units[self.tachometer] not in TACHOMETER_UNITS[self.tachometer_kind]:
                problems.append(f"tachometer channel '{self.tachometer}' of kind '{self.tachometer_kind}' "
                                f"must have unit {' or '.join(TACHOMETER_UNITS[self.tachometer_kind])}")
        elif self.tachometer_kind is not None:
            problems.append("tachometer_kind is given but tachometer is not")
        if self.tachometer_kind == "pulse":
            if (self.pulses_per_rev is None or isinstance(self.pulses_per_rev, bool)
                    or not isinstance(self.pulses_per_rev, (int, np.integer)) or self.pulses_per_rev < 1):
                problems.append(f"pulses_per_rev must be a positive integer, got {self.pulses_per_rev!r}")
        elif self.pulses_per_rev is not None:
            problems.append("pulses_per_rev only applies to tachometer_kind 'pulse'")
        if problems:
            src = self.source or _MEMORY
            name = self.name if isinstance(self.name, str) else repr(self.name)
            raise MeasurementError(src, name, problems[0], problems=[(src, name, p) for p in problems])
        set_ = object.__setattr__   # frozen: normalise the stored values once, here
        set_(self, "channels", types.MappingProxyType(chans))
        set_(self, "units", types.MappingProxyType({c: units[c] for c in chans}))
        set_(self, "sample_rate", float(self.sample_rate))
        set_(self, "time_start", float(self.time_start))
        for attr in ("nominal_speed", "load", "damage", "resampled_from"):
            if getattr(self, attr) is not None:
                set_(self, attr, float(getattr(self, attr)))
        if self.label is not None:
            set_(self, "label", int(self.label))
        if self.pulses_per_rev is not None:
            set_(self, "pulses_per_rev", int(self.pulses_per_rev))
        set_(self, "metadata", types.MappingProxyType(dict(self.metadata)))

    @property
    def n_samples(self) -> int:
        """Number of samples per channel."""
        return next(iter(self.channels.values())).size

    @property
    def duration(self) -> float:
        """Record length ``n_samples / sample_rate`` [s] (n sample periods)."""
        return self.n_samples / self.sample_rate

    @property
    def time(self) -> np.ndarray:
        """Sample times ``time_start + i / sample_rate`` [s], shape ``(n_samples,)``."""
        return self.time_start + np.arange(self.n_samples) / self.sample_rate

    @property
    def channel_names(self) -> tuple[str, ...]:
        """Channel names in stored order."""
        return tuple(self.channels)

    def __getitem__(self, channel: str) -> np.ndarray:
        """Samples of ``channel``, shape ``(n_samples,)``, canonical unit."""
        try:
            return self.channels[channel]
        except KeyError:
            raise KeyError(f"record '{self.name}' has no channel '{channel}' "
                           f"(channels: {', '.join(self.channels)})") from None

    def __contains__(self, channel: object) -> bool:
        return channel in self.channels

    def __repr__(self) -> str:
        extra = f", resampled_from={self.resampled_from:g}" if self.resampled_from is not None else ""
        return (f"Record({self.name!r}, channels={list(self.channels)}, n={self.n_samples}, "
                f"sample_rate={self.sample_rate:g}, label={self.label}{extra})")


@dataclass(frozen=True, eq=False)
class MeasurementSet:
    """The records of one file (or built in memory), in stored order.

    Attributes
    ----------
    records : tuple of Record
        Unique names.
    source : str or None
        File the set was loaded from.
    notes : tuple of str
        Human-readable account of what the loader did to the data (resampling), one line each.
    metadata : mapping
        File-level attributes outside the format (e.g. the archive's ``damage_kind``, ``stages``).
    """

    records: tuple[Record, ...]
    source: str | None = None
    notes: tuple[str, ...] = ()
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        recs = tuple(self.records)
        src = self.source or _MEMORY
        problems = []
        for r in recs:
            if not isinstance(r, Record):
                problems.append((src, None, f"not a Record: {type(r).__name__}"))
        names = [r.name for r in recs if isinstance(r, Record)]
        for n in sorted({n for n in names if names.count(n) > 1}):
            problems.append((src, n, "duplicate record name"))
        if problems:
            raise MeasurementError(*problems[0], problems=problems)
        object.__setattr__(self, "records", recs)
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "metadata", types.MappingProxyType(dict(self.metadata)))

    def __iter__(self) -> Iterator[Record]:
        return iter(self.records)

    def __len__(self) -> int:
        return len(self.records)

    def __getitem__(self, key: int | str) -> Record:
        """Record by position or by name."""
        if isinstance(key, str):
            for r in self.records:
                if r.name == key:
                    return r
            raise KeyError(f"no record '{key}' in {self.source or 'the set'}")
        return self.records[key]

    def __repr__(self) -> str:
        return (f"MeasurementSet({self.source or '<memory>'!r}, {len(self.records)} records"
                + (f", {len(self.notes)} notes" if self.notes else "") + ")")

    @property
    def names(self) -> tuple[str, ...]:
        """Record names in stored order."""
        return tuple(r.name for r in self.records)

    def by_label(self) -> dict[int | None, tuple[Record, ...]]:
        """Records grouped by label, labels ascending; unlabelled records under ``None`` (last)."""
        groups: dict[int | None, list[Record]] = {}
        for r in self.records:
            groups.setdefault(r.label, []).append(r)
        keys = sorted(k for k in groups if k is not None) + ([None] if None in groups else [])
        return {k: tuple(groups[k]) for k in keys}


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and math.isfinite(v)


def _positive(v: Any) -> bool:
    return _finite(v) and v > 0
