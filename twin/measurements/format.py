"""The measurement format: vibration records of the gearbox rig and of the twin's archive.

The full specification, with examples, is ``twin/measurements/README.md``; this module is its
executable half: the constants of the format and the checks every loader applies. Everything
here is pure numpy and works on plain arrays and mappings, so the HDF5 and CSV readers of
:mod:`twin.measurements.load` share one definition of what a valid record is.

Summary
-------
HDF5 (``.h5``/``.hdf5``; detected by the HDF5 signature, not the suffix)
    Root attributes ``format="gear-twin-measurements"`` (or ``"gear-twin-archive"`` for files
    written by :func:`twin.archive.write_archive`, same layout) and ``format_version=1``.
    One group per record, ``/records/<name>``; each channel a 1-D numeric dataset with a
    ``unit`` attribute (see :data:`UNITS`); record attributes in :data:`RECORD_ATTRIBUTES`.
CSV (``.csv``)
    A header row with a ``time`` column [s] plus one column per channel, one row per
    sample, and a sidecar ``<file>.yaml``/``.yml``/``.json`` (``data.csv.yaml`` or
    ``data.yaml``) holding the record attributes, ``units: {channel: unit}``, optional
    ``record`` (name, default: the file stem) and optional ``metadata`` (free mapping).
"""
from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

MEASUREMENT_FORMAT = "gear-twin-measurements"
ARCHIVE_FORMAT = "gear-twin-archive"   # == twin.archive.ARCHIVE_FORMAT; not imported to stay FMU-free
FORMAT_VERSION = 1
READABLE_FORMATS = (MEASUREMENT_FORMAT, ARCHIVE_FORMAT)
HDF5_SUFFIXES = (".h5", ".hdf5")
CSV_SUFFIXES = (".csv",)
SIDECAR_SUFFIXES = (".yaml", ".yml", ".json")

STANDARD_GRAVITY = 9.80665             # m/s2 per g (CGPM 1901, exact)

#: Accepted channel units -> (canonical unit stored on the loaded record, factor to it).
#: ``g`` is the only unit converted; ``''`` and ``'1'`` both mean dimensionless.
UNITS: Mapping[str, tuple[str, float]] = {
    "m/s2": ("m/s2", 1.0),
    "g": ("m/s2", STANDARD_GRAVITY),
    "m/s": ("m/s", 1.0),
    "m": ("m", 1.0),
    "rad": ("rad", 1.0),
    "N": ("N", 1.0),
    "N.m": ("N.m", 1.0),
    "V": ("V", 1.0),
    "rad/s": ("rad/s", 1.0),
    "Hz": ("Hz", 1.0),
    "1": ("1", 1.0),
    "": ("1", 1.0),
}
ACCEPTED_UNITS = tuple(UNITS)
CANONICAL_UNITS = frozenset(canon for canon, _ in UNITS.values())

TACHOMETER_KINDS = ("pulse", "angle")
#: Units a tachometer channel may carry, by kind: a pulse train is a voltage or a 0/1 logic
#: level; an encoder angle must be in radians so order analysis needs no guessing.
TACHOMETER_UNITS = {"pulse": ("V", "1"), "angle": ("rad",)}

RESERVED_CHANNELS = ("time",)          # the time axis is implicit: time_start + i / sample_rate

CLIP_MIN_RUN = 5                       # consecutive samples at the extreme that count as clipping
CLIP_MAX_FRACTION = 1e-3               # share of all samples at the extreme that counts as clipping
TIME_UNIFORMITY_RTOL = 1e-6            # CSV time steps may deviate this much from their median


@dataclass(frozen=True)
class AttributeSpec:
    """One record attribute of the format (HDF5 attribute or sidecar key)."""

    name: str
    kind: str            # "float", "int", "str"
    unit: str            # physical unit, '' for none
    required: bool
    description: str


RECORD_ATTRIBUTES: tuple[AttributeSpec, ...] = (
    AttributeSpec("sample_rate", "float", "Hz", True,
                  "sampling rate of every channel of the record; > 0 (CSV: may be derived from time)"),
    AttributeSpec("nominal_speed", "float", "Hz", False,
                  "input (pinion) shaft speed; > 0; needed for order analysis without a tachometer"),
    AttributeSpec("load", "float", "N.m", False, "brake (output) torque"),
    AttributeSpec("tachometer", "str", "", False, "name of the channel holding the shaft reference"),
    AttributeSpec("tachometer_kind", "str", "", False,
                  "'pulse' (pulse train) or 'angle' (unwrapped encoder angle, rad); required with tachometer"),
    AttributeSpec("pulses_per_rev", "int", "", False, "pulses per shaft revolution (pulse kind only; default 1)"),
    AttributeSpec("label", "int", "", False, "class label, e.g. the damage stage of the archive"),
    AttributeSpec("damage", "float", "", False, "damage measure (pitting density, or wear depth in m)"),
    AttributeSpec("time_start", "float", "s", False, "time of the first sample (default 0)"),
    AttributeSpec("resampled_from", "float", "Hz", False,
                  "original sampling rate when the record was resampled before it was written"),
)
RECORD_ATTRIBUTE_NAMES = tuple(a.name for a in RECORD_ATTRIBUTES)


def canonical_unit(unit: Any) -> tuple[str, float] | None:
    """``(canonical unit, factor)`` for an accepted unit string, ``None`` otherwise.

    Loaded samples are ``raw * factor`` in the canonical unit (``g`` -> ``m/s2``).
    """
    if isinstance(unit, bytes):
        unit = unit.decode("utf-8", "replace")
    if not isinstance(unit, str):
        return None
    return UNITS.get(unit.strip())


def unknown_unit_problem(channel: str, unit: Any) -> str:
    """Message for a unit that is not in :data:`UNITS` (lists the accepted ones)."""
    accepted = ", ".join(repr(u) for u in ACCEPTED_UNITS)
    return f"channel '{channel}' has unknown unit {unit!r}; accepted units: {accepted}"


def plain_value(value: Any) -> Any:
    """An HDF5 attribute / sidecar value as a plain Python value.

    Bytes become ``str``, numpy scalars and size-1 arrays become Python scalars; other arrays
    are returned as numpy arrays (for metadata only; no record attribute is an array).
    """
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        if value.size == 1:
            return plain_value(value.reshape(()).item())
        return value
    if isinstance(value, np.generic):
        return plain_value(value.item())
    return value


def _as_float(value: Any) -> float | None:
    """Float from a number (or a numeric string: PyYAML reads ``50e3`` as a string); else None."""
    value = plain_value(value)
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value.strip())
        except ValueError:
            return None
    return None


def _as_int(value: Any) -> int | None:
    """Integer from an int or an integral float (JSON writers may emit ``2.0``); else None."""
    value = plain_value(value)
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value
    if isinstance(value, float) and math.isfinite(value) and value == int(value):
        return int(value)
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            return None
    return None


def parse_record_attributes(raw: Mapping[str, Any], channel_names: list[str], *,
                            require_sample_rate: bool = True) -> tuple[dict, dict, list[str]]:
    """Check the record attributes of one record against :data:`RECORD_ATTRIBUTES`.

    Parameters
    ----------
    raw : mapping
        Attribute name -> value, as stored (HDF5 attributes or sidecar keys).
    channel_names : list of str
        Channels present in the record (the tachometer must be one of them).
    require_sample_rate : bool
        Report a missing ``sample_rate``. The CSV reader passes False when a broken time
        column already explains why no rate could be derived.

    Returns
    -------
    attributes : dict
        Parsed values of every known attribute (``None`` when absent; ``time_start`` 0.0,
        ``pulses_per_rev`` 1 for a pulse tachometer).
    metadata : dict
        Attributes outside the format, kept verbatim (plain values).
    problems : list of str
        Everything wrong; an attribute with a problem is ``None`` in ``attributes``.
    """
    problems: list[str] = []
    out: dict[str, Any] = {name: None for name in RECORD_ATTRIBUTE_NAMES}
    metadata: dict[str, Any] = {}
    for key, value in raw.items():
        if key in out:
            continue
        close = difflib.get_close_matches(key, RECORD_ATTRIBUTE_NAMES, n=1, cutoff=0.8)
        if close:
            # An unknown key this close to a known one is almost certainly a typo that would
            # otherwise silently drop e.g. the nominal speed.
            problems.append(f"unknown record attribute '{key}' (did you mean '{close[0]}'?)")
        else:
            metadata[key] = plain_value(value)

    def number(name: str, *, positive: bool = False) -> None:
        if name not in raw:
            return
        v = _as_float(raw[name])
        if v is None or not math.isfinite(v):
            problems.append(f"attribute '{name}' must be a finite number, got {plain_value(raw[name])!r}")
        elif positive and v <= 0:
            problems.append(f"attribute '{name}' must be > 0, got {v:g}")
        else:
            out[name] = v

    if "sample_rate" not in raw and require_sample_rate:
        problems.append("missing sample rate: attribute 'sample_rate' [Hz] is required")
    number("sample_rate", positive=True)
    number("nominal_speed", positive=True)
    number("load")
    number("damage")
    number("time_start")
    number("resampled_from", positive=True)
    if out["time_start"] is None and "time_start" not in raw:
        out["time_start"] = 0.0
    if "label" in raw:
        lab = _as_int(raw["label"])
        if lab is None:
            problems.append(f"attribute 'label' must be an integer, got {plain_value(raw['label'])!r}")
        out["label"] = lab

    tach = plain_value(raw.get("tachometer"))
    kind = plain_value(raw.get("tachometer_kind"))
    if tach is not None:
        if not isinstance(tach, str) or not tach:
            problems.append(f"attribute 'tachometer' must be a channel name, got {tach!r}")
        elif tach not in channel_names:
            problems.append(f"tachometer channel '{tach}' is not in the record "
                            f"(channels: {', '.join(channel_names) or 'none'})")
        else:
            out["tachometer"] = tach
        if kind is None:
            problems.append(f"attribute 'tachometer_kind' ({' or '.join(TACHOMETER_KINDS)}) "
                            "is required with 'tachometer'")
    elif kind is not None:
        problems.append("attribute 'tachometer_kind' is given but 'tachometer' is not")
    if kind is not None:
        if kind not in TACHOMETER_KINDS:
            problems.append(f"attribute 'tachometer_kind' must be one of {', '.join(TACHOMETER_KINDS)}, "
                            f"got {kind!r}")
        else:
            out["tachometer_kind"] = kind
    if "pulses_per_rev" in raw:
        ppr = _as_int(raw["pulses_per_rev"])
        if kind != "pulse":
            problems.append("attribute 'pulses_per_rev' only applies to tachometer_kind 'pulse'")
        elif ppr is None or ppr < 1:
            problems.append(f"attribute 'pulses_per_rev' must be a positive integer, "
                            f"got {plain_value(raw['pulses_per_rev'])!r}")
        else:
            out["pulses_per_rev"] = ppr
    elif kind == "pulse":
        out["pulses_per_rev"] = 1
    return out, metadata, problems


def nonfinite_problem(channel: str, x: np.ndarray, sample_rate: float | None, time_start: float) -> str | None:
    """Message for NaN/Inf samples in ``x`` (count, first index and its time), or ``None``."""
    bad = ~np.isfinite(x)
    if not bad.any():
        return None
    i = int(np.argmax(bad))
    when = f" (t = {time_start + i / sample_rate:.9g} s)" if sample_rate else ""
    kinds = []
    if np.isnan(x).any():
        kinds.append("NaN")
    if np.isinf(x).any():
        kinds.append("Inf")
    return (f"channel '{channel}' has {int(bad.sum())} non-finite samples ({'/'.join(kinds)}); "
            f"first at index {i}{when}")


def _longest_run(mask: np.ndarray) -> int:
    """Length of the longest run of True in a 1-D boolean array."""
    if not mask.any():
        return 0
    edges = np.diff(np.concatenate(([0], mask.view(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)
    return int((stops - starts).max())


def clipping_problems(channel: str, x: np.ndarray, unit: str) -> list[str]:
    """Messages for a clipped channel, one per clipped extreme (max and/or min).

    A channel counts as clipped at its maximum (minimum) value when at least
    :data:`CLIP_MIN_RUN` consecutive samples sit exactly at it, or when more than
    ``max(1, CLIP_MAX_FRACTION * n)`` samples do (a smooth signal reaches its extreme
    once; a saturated converter holds it). Constant channels are not checked: they have no
    excursion that could have been cut; nor is an extreme of exactly zero that holds most of
    the samples, the rest level of an impulsive channel (a hammer's force between its hits).
    ``x`` must be finite.
    """
    n = x.size
    if n == 0 or x.max() == x.min():
        return []
    out = []
    for side, level in (("maximum", x.max()), ("minimum", x.min())):
        at = x == level
        count = int(at.sum())
        if level == 0.0 and 2 * count > n:
            continue
        run = count if count <= 1 else _longest_run(at)       # a noisy signal's extreme: one sample
        if run >= CLIP_MIN_RUN or count > max(1.0, CLIP_MAX_FRACTION * n):
            out.append(f"channel '{channel}' is clipped at its {side} {float(level):.9g} {unit}".rstrip()
                       + f": {count} samples ({100.0 * count / n:.3g} %) at that level, "
                         f"longest run {run}")
    return out


def tachometer_problems(channel: str, x: np.ndarray, kind: str, unit: str) -> list[str]:
    """Messages for a tachometer channel unfit for its kind (``x`` finite, canonical unit)."""
    out = []
    if unit not in TACHOMETER_UNITS[kind]:
        out.append(f"tachometer channel '{channel}' of kind '{kind}' must have unit "
                   f"{' or '.join(repr(u) for u in TACHOMETER_UNITS[kind])}, got {unit!r}")
    if x.size < 2:
        return out
    if kind == "pulse" and x.max() == x.min():
        out.append(f"tachometer channel '{channel}' is constant: it holds no pulses")
    if kind == "angle":
        # An encoder angle must be unwrapped; a wrapped (sawtooth) angle jumps by ~2 pi once
        # per revolution, which order tracking would read as an instant reversal.
        jumps = np.abs(np.diff(x))
        if jumps.max() > math.pi:
            i = int(np.argmax(jumps > math.pi))
            out.append(f"tachometer channel '{channel}' (angle) jumps by {jumps[i]:.4g} rad at index {i + 1}; "
                       "the angle must be unwrapped (continuous)")
    return out


def time_axis(t: np.ndarray) -> tuple[float | None, list[str]]:
    """Check a CSV time column; return ``(step [s] or None, problems)``.

    The column must be strictly increasing and uniform: every step within
    :data:`TIME_UNIFORMITY_RTOL` (relative) of the median step, so the message points at the
    steps that are actually off (a mean would be shifted by them and blame every step). The
    returned step is the mean ``(t[-1] - t[0]) / (n - 1)``, which averages out the rounding
    of the printed times. Fewer than two samples give no step. ``t`` must be finite.
    """
    if t.size < 2:
        return None, []
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.argmax(d <= 0)) + 1
        return None, [f"time is not strictly increasing: sample {i} (t = {t[i]:.9g} s) "
                      f"follows t = {t[i - 1]:.9g} s"]
    ref = float(np.median(d))
    dev = np.abs(d - ref) / ref
    if dev.max() > TIME_UNIFORMITY_RTOL:
        i = int(np.argmax(dev > TIME_UNIFORMITY_RTOL)) + 1
        return None, [f"time is not uniform: step before sample {i} (t = {t[i]:.9g} s) is {d[i - 1]:.9g} s, "
                      f"median step {ref:.9g} s (relative deviation {dev[i - 1]:.3g} > {TIME_UNIFORMITY_RTOL:g}; "
                      f"{int((dev > TIME_UNIFORMITY_RTOL).sum())} such steps); "
                      "write time with full precision"]
    return float((t[-1] - t[0]) / (t.size - 1)), []


def rate_from_step(step: float) -> float:
    """Sampling rate [Hz] from a time step [s], snapped to an integer when within 1e-9.

    Times printed in decimal give ``1/step`` like 49999.9999999998 Hz; the snap only
    removes that print noise (far below the 1e-6 uniformity tolerance).
    """
    rate = 1.0 / step
    nearest = round(rate)
    return float(nearest) if nearest > 0 and abs(rate - nearest) <= 1e-9 * rate else rate


def sidecar_candidates(csv_path) -> list:
    """Sidecar paths looked for next to a CSV file, in order of preference.

    ``data.csv.yaml``, ``data.csv.yml``, ``data.csv.json`` (the sidecar named after the whole
    file name, as :mod:`twin.results` writes it), then ``data.yaml``, ``data.yml``, ``data.json``.
    """
    from pathlib import Path
    p = Path(csv_path)
    cands = [Path(str(p) + s) for s in SIDECAR_SUFFIXES] + [p.with_suffix(s) for s in SIDECAR_SUFFIXES]
    return list(dict.fromkeys(cands))
