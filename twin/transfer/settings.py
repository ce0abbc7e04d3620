"""What an archive says about how an assessor is trained and what rig records it can read.

The assessor's settings are not options for a user to find: they follow from the physics of the
test the archive was simulated for, which the archive file records (``twin.archive.write_archive``):

* **window length** -- two pinion revolutions at the test's nominal shaft speed
  (:meth:`~twin.transfer.preprocess.Preprocessing.for_shaft_speed`): the records are resampled to
  ``1024 x speed`` (20.48 kHz for the lubricated test at 20 Hz, 10.24 kHz for the dry test at
  10 Hz), so every 2048-sample window holds every tooth twice and the same mesh harmonics;
* **level** -- removed for pitting, kept for wear (:data:`REMOVE_LEVEL`).  Pitting is tooth-local:
  it shows in the spectral shape, and its early stages differ in level by less than a rig's gain
  scatter.  Deep wear shows in the level: the transmission error follows the worn profile, so the
  vibration grows with the depth while its shape hardly changes;
* **class prior** -- the stages are ordered (a damage measure cut into stages), so the rig's stage
  boundaries are placed along the windows' expected stage (``"ordinal"``,
  :mod:`twin.transfer.prior`), which keeps only the order of the windows and so survives a rig
  that turns the same damage into a larger or smaller change of its vibration.

Rig records are checked against the test before any is assessed (:func:`check_records`): a
record whose commanded speed or load lies outside the archive's operating range, or that names
another damage kind, is refused by name; a record without a speed is accepted with a note.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["ArchiveFacts", "DAMAGE_KINDS", "REMOVE_LEVEL", "archive_facts", "check_records", "class_prior_for",
           "misfit_error", "preprocessing_for", "record_misfit"]

DAMAGE_KINDS = ("pitting_density", "wear_depth")
REMOVE_LEVEL = {"pitting_density": True, "wear_depth": False}
# How far a rig record's commanded operating point may lie from the test's before it is refused:
# three times the archive's own operating scatter (the range the network has seen), and at least
# these shares (a test rig holds its speed to a few per cent, its brake load to tens of per cent).
MIN_SPEED_TOLERANCE = 0.05
MIN_LOAD_TOLERANCE = 0.3


@dataclass(frozen=True)
class ArchiveFacts:
    """The test an archive was simulated for.

    Attributes
    ----------
    damage_kind : {"pitting_density", "wear_depth"}
    stages : tuple of float
        Stage boundaries of the damage measure (K + 1,).
    nominal_speed : float
        Pinion shaft speed of the test [Hz].
    nominal_load : float
        Brake load of the test [N.m].
    speed_scatter, load_scatter : float
        Relative operating scatter of the archive's records [-].
    scenario : str
        Name of the scenario the archive was built from.
    """

    damage_kind: str
    stages: tuple
    nominal_speed: float
    nominal_load: float
    speed_scatter: float = 0.0
    load_scatter: float = 0.0
    scenario: str = ""

    @property
    def n_stages(self) -> int:
        return len(self.stages) - 1

    @property
    def speed_tolerance(self) -> float:
        return max(3.0 * self.speed_scatter, MIN_SPEED_TOLERANCE)

    @property
    def load_tolerance(self) -> float:
        return max(3.0 * self.load_scatter, MIN_LOAD_TOLERANCE)

    def to_dict(self) -> dict:
        return {"damage_kind": self.damage_kind, "stages": [float(v) for v in self.stages],
                "nominal_speed": self.nominal_speed, "nominal_load": self.nominal_load,
                "speed_scatter": self.speed_scatter, "load_scatter": self.load_scatter, "scenario": self.scenario}

    @classmethod
    def from_dict(cls, d: dict) -> "ArchiveFacts":
        try:
            return cls(str(d["damage_kind"]), tuple(float(v) for v in d["stages"]), float(d["nominal_speed"]),
                       float(d["nominal_load"]), float(d.get("speed_scatter", 0.0)), float(d.get("load_scatter", 0.0)),
                       str(d.get("scenario", "")))
        except (KeyError, TypeError, ValueError) as exc:
            raise AssessorError(f"damaged archive facts {d!r}: {exc!r}") from None


def archive_facts(path: str | Path) -> ArchiveFacts:
    """Read the test's facts from an archive file (``twin archive``).

    Archives written before the file held the nominal operating point give the median of their
    records' speeds and loads instead.

    Raises
    ------
    AssessorError
        Not a gear-twin archive (a measurement file of a rig, say), or no damage kind or stages.
    """
    import h5py

    from twin.archive import ARCHIVE_FORMAT

    p = Path(path)
    if not p.is_file():
        raise AssessorError(f"source archive '{p}' does not exist")
    try:
        f = h5py.File(p, "r")
    except OSError as exc:
        raise AssessorError(f"source '{p}' is not an HDF5 file: {exc}") from None
    with f:
        if f.attrs.get("format") != ARCHIVE_FORMAT:
            raise AssessorError(f"source '{p}' is not a gear-twin archive (format {f.attrs.get('format')!r}); "
                                "build one with twin archive SCENARIO, or give the scenario itself")
        kind = str(f.attrs.get("damage_kind", ""))
        if kind not in DAMAGE_KINDS:
            raise AssessorError(f"source '{p}' has damage kind {kind!r}; expected one of {', '.join(DAMAGE_KINDS)}")
        stages = tuple(float(v) for v in np.atleast_1d(f.attrs["stages"]))
        recs = f["records"]
        speeds = np.array([float(recs[k].attrs["nominal_speed"]) for k in recs])
        loads = np.array([float(recs[k].attrs["load"]) for k in recs])
        speed = float(f.attrs["nominal_speed"]) if "nominal_speed" in f.attrs else float(np.median(speeds))
        load = float(f.attrs["nominal_load"]) if "nominal_load" in f.attrs else float(np.median(loads))
        try:
            raw = json.loads(f.attrs.get("scenario", "{}"))
        except (TypeError, ValueError):
            raw = {}
    spec = raw.get("archive", {}) if isinstance(raw, dict) else {}
    return ArchiveFacts(kind, stages, speed, load, float(spec.get("speed_scatter", np.std(speeds) / speed)),
                        float(spec.get("load_scatter", np.std(loads) / abs(load) if load else 0.0)),
                        str(raw.get("name", "")) if isinstance(raw, dict) else "")


def preprocessing_for(facts: ArchiveFacts, *, channel: str = "accel_pinion_casing",
                      target_channel: str | None = None):
    """The assessor's preprocessing for the test of ``facts`` (module docstring)."""
    from twin.transfer.preprocess import Preprocessing
    return Preprocessing.for_shaft_speed(facts.nominal_speed, remove_level=REMOVE_LEVEL[facts.damage_kind],
                                         channel=channel, target_channel=target_channel)


def class_prior_for(facts: ArchiveFacts) -> str:
    """The class-prior rule for the stages of ``facts``: ``"ordinal"`` (module docstring)."""
    if facts.n_stages < 2:
        raise AssessorError(f"the archive has {facts.n_stages} stage(s); an assessor needs at least 2")
    return "ordinal"


def record_misfit(record, facts: ArchiveFacts) -> str | None:
    """Why the assessor of ``facts`` cannot read ``record`` (``"'name' (speed 10 Hz, ...)"``), or None.

    Only the record's attributes are read: its ``nominal_speed`` more than
    :attr:`ArchiveFacts.speed_tolerance` from the test's, its ``load`` more than
    :attr:`ArchiveFacts.load_tolerance`, or a ``damage_kind`` attribute naming another damage.
    """
    reasons = []
    speed = record.nominal_speed
    if speed is not None and abs(speed / facts.nominal_speed - 1.0) > facts.speed_tolerance:
        reasons.append(f"speed {record.nominal_speed:g} Hz")
    if record.load is not None and facts.nominal_load and (
            abs(record.load / facts.nominal_load - 1.0) > facts.load_tolerance):
        reasons.append(f"load {record.load:g} N.m")
    kind = (record.metadata or {}).get("damage_kind")
    if kind is not None and str(kind) != facts.damage_kind:
        reasons.append(f"damage kind {kind}")
    return f"'{record.name}' ({', '.join(reasons)})" if reasons else None


def misfit_error(misfits, facts: ArchiveFacts, what: str = "rig") -> AssessorError:
    """The one-line error refusing the records of ``misfits`` (:func:`record_misfit`'s strings)."""
    bad = list(misfits)
    more = f" and {len(bad) - 5} more" if len(bad) > 5 else ""
    return AssessorError(
        f"{what}: {len(bad)} record(s) do not fit the assessor's test ({facts.damage_kind} at "
        f"{facts.nominal_speed:g} Hz +- {100 * facts.speed_tolerance:.0f} %, {facts.nominal_load:g} N.m +- "
        f"{100 * facts.load_tolerance:.0f} %): {', '.join(bad[:5])}{more}; assess them with an assessor trained "
        "on an archive of their test")


def check_records(records, facts: ArchiveFacts, what: str = "rig") -> list[str]:
    """Refuse records the assessor of ``facts`` cannot read; return notes on what was assumed.

    A record is refused (one :class:`AssessorError` naming every such record,
    :func:`misfit_error`) when :func:`record_misfit` finds a reason.  A record without
    ``nominal_speed`` or ``load`` is taken at the test's and noted.

    Parameters
    ----------
    records : iterable of :class:`twin.measurements.Record`
    facts : ArchiveFacts
    what : str
        What the records are, for the messages.
    """
    bad, unknown = [], []
    for r in records:
        if r.nominal_speed is None:
            unknown.append(r.name)
        reason = record_misfit(r, facts)
        if reason is not None:
            bad.append(reason)
    if bad:
        raise misfit_error(bad, facts, what)
    notes = []
    if unknown:
        notes.append(f"{what}: {len(unknown)} record(s) have no nominal_speed (first '{unknown[0]}'); taken at the "
                     f"test's {facts.nominal_speed:g} Hz")
    return notes


def resampling_note(sample_rates, target_rate: float, what: str = "rig") -> str | None:
    """One line saying how the records were resampled for the assessor, or None if they were not.

    Resampling to ``target_rate`` keeps what lies below 80 % of its Nyquist frequency and drops
    everything above (:func:`twin.measurements.resample_record`).
    """
    rates = sorted({float(r) for r in sample_rates if not math.isclose(float(r), target_rate, rel_tol=1e-9)})
    if not rates:
        return None
    listed = ", ".join(f"{r:g}" for r in rates)
    return (f"{what}: records resampled from {listed} Hz to {target_rate:g} Hz (two pinion revolutions per "
            f"2048-sample window); content above {0.4 * target_rate:g} Hz is not used")
