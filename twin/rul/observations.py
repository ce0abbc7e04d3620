"""Assessed records in time order: the observations the RUL estimate is fitted to.

**Observations.**  Record i at ``N_i`` cycles has stage probabilities ``p_i``.  A classifier's
output is read as soft evidence about the true stage: tempered ``q ∝ p^(1/T)`` (``temperature``
T > 1 softens an over-confident classifier) and mixed with a uniform floor,
``q <- (1 - eps) q + eps / K`` (``floor`` eps bounds the weight of one confident mistake).  The
likelihood of a damage value D is then

    L_i(D) = sum_k q_ik m_k(D),   m_k(D) = Phi((D - b_k)/w) - Phi((D - b_{k+1})/w)

with the outer boundaries at -inf / +inf (damage above the last boundary is in the last stage)
and a boundary width ``w = boundary_width x`` the median stage width (the archive's records are
drawn uniformly in each stage, so a classifier is least sure right at a boundary).


Input formats
-------------
Input formats
-------------
JSON (``read_observations``)::

    {"stages": [0.0, 0.0333, ...],          # optional: stage boundaries (else the scenario's)
     "damage_kind": "pitting_density",      # optional: checked against the trajectory
     "speed_hz": 20.0,                      # optional: pinion speed to convert time_s to cycles
     "records": [
        {"record": "r001", "cycles": 1.2e6, "probabilities": [0.9, 0.1, 0, 0, 0, 0]},
        {"record": "r002", "time_s": 86400, "probabilities": [...]},
        {"record": "r003", "stage": 2, "confidence": 0.93, "cycles": 3.1e6}, ...]}

This accepts the ``twin assess`` JSON as is (extra keys are ignored); when a record has no
``probabilities`` its ``stage`` and ``confidence`` stand for them (confidence on the stage, the
rest spread evenly).  ``cycles`` may instead come from a separate file (``cycles_file``: CSV
with columns ``record`` and ``cycles`` or ``time_s``, or JSON ``{record: cycles}``).
CSV: a header with ``record``, ``cycles`` or ``time_s``, optional ``speed_hz``, and one column
per stage named ``p0`` .. ``p{K-1}`` (or ``prob_0`` ..).  Cycles are pinion revolutions;
``time_s`` is converted with the record's ``speed_hz``, else the file's, else the caller's
(the scenario's nominal speed on the command line).  Records must be in time order
(non-decreasing cycles; ``sort=True`` sorts them instead).
"""
from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from twin.rul.base import _PROB_TOL, DAMAGE_KINDS, RULError
from twin.rul.trajectory import Trajectory


@dataclass(frozen=True, eq=False)
class Observation:
    """One assessed record: pinion cycles and stage probabilities (K,)."""

    record: str
    cycles: float
    probabilities: np.ndarray


@dataclass(frozen=True, eq=False)
class ObservationSet:
    """Assessed records in time order, with what the file says about the stages."""

    observations: tuple[Observation, ...]
    stages: tuple[float, ...] | None = None
    damage_kind: str | None = None
    source: str = ""

    @property
    def cycles(self) -> np.ndarray:
        return np.array([o.cycles for o in self.observations])

    @property
    def probabilities(self) -> np.ndarray:
        return np.stack([o.probabilities for o in self.observations])

    def __len__(self) -> int:
        return len(self.observations)

    def head(self, n: int) -> "ObservationSet":
        return ObservationSet(self.observations[:n], self.stages, self.damage_kind, self.source)


def _number(value, what: str, source, record, *, positive: bool = False) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if ok:
        value = float(value)
        ok = math.isfinite(value) and (value > 0 if positive else value >= 0)
    if not ok:
        raise RULError(f"{what} must be a finite number {'> 0' if positive else '>= 0'}, got {value!r}",
                       source=source, record=record)
    return value


def check_stages(stages, source: str | None = None) -> tuple[float, ...]:
    """Stage boundaries: >= 3 finite numbers >= 0, strictly ascending (K = len - 1 >= 2 stages)."""
    try:
        vals = [float(b) for b in stages]
    except (TypeError, ValueError):
        raise RULError(f"stage boundaries must be a list of numbers, got {stages!r}", source=source) from None
    if len(vals) < 3:
        raise RULError(f"need at least 3 stage boundaries (2 stages), got {vals}", source=source)
    if not all(math.isfinite(b) and b >= 0 for b in vals) or any(b <= a for a, b in zip(vals, vals[1:])):
        raise RULError(f"stage boundaries must be finite, >= 0 and strictly ascending, got {vals}", source=source)
    return tuple(vals)


def _probabilities(entry: Mapping, n_stages: int | None, source, record) -> np.ndarray:
    if "probabilities" in entry and entry["probabilities"] is not None:
        try:
            p = np.array(entry["probabilities"], dtype=float)
        except (TypeError, ValueError):
            raise RULError(f"probabilities must be a list of numbers, got {entry['probabilities']!r}",
                           source=source, record=record) from None
        if p.ndim != 1 or p.size < 2:
            raise RULError(f"probabilities must be a list of >= 2 numbers, got {entry['probabilities']!r}",
                           source=source, record=record)
    elif "stage" in entry and n_stages is not None:
        stage, conf = entry["stage"], entry.get("confidence", 1.0)
        if not (isinstance(stage, (int, np.integer)) and not isinstance(stage, bool) and 0 <= stage < n_stages):
            raise RULError(f"stage must be an integer in [0, {n_stages - 1}], got {stage!r}",
                           source=source, record=record)
        conf = _number(conf, "confidence", source, record)
        if conf > 1:
            raise RULError(f"confidence must lie in [0, 1], got {conf!r}", source=source, record=record)
        p = np.full(n_stages, (1 - conf) / (n_stages - 1))
        p[stage] = conf
    else:
        raise RULError("no 'probabilities' (nor 'stage' with known stage boundaries)", source=source, record=record)
    if n_stages is not None and p.size != n_stages:
        raise RULError(f"{p.size} probabilities for {n_stages} stages: {p.tolist()}", source=source, record=record)
    if not np.all(np.isfinite(p)) or p.min() < 0:
        raise RULError(f"probabilities must be finite and >= 0, got {p.tolist()}", source=source, record=record)
    if abs(p.sum() - 1) > _PROB_TOL:
        raise RULError(f"probabilities sum to {p.sum():.6g}, not 1: {p.tolist()}", source=source, record=record)
    p = p / p.sum()
    p.setflags(write=False)
    return p


def _cycles(entry: Mapping, speed_hz: float | None, source, record) -> float | None:
    if entry.get("cycles") is not None:
        return _number(entry["cycles"], "cycles", source, record)
    if entry.get("time_s") is not None:
        t = _number(entry["time_s"], "time_s", source, record)
        speed = entry.get("speed_hz", speed_hz)
        if speed is None:
            raise RULError("time_s given without a speed_hz (record, file or caller) to convert it to cycles",
                           source=source, record=record)
        return t * _number(speed, "speed_hz", source, record, positive=True)
    return None


def _read_cycles_file(path: Path, speed_hz: float | None) -> dict[str, float]:
    src = str(path)
    if not path.is_file():
        raise RULError("cycles file does not exist", source=src)
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise RULError(f"not valid JSON: {exc}", source=src) from None
        if not isinstance(data, dict):
            raise RULError("expected a JSON object {record: cycles}", source=src)
        return {str(k): _number(v, "cycles", src, str(k)) for k, v in data.items()}
    out = {}
    for row in _csv_rows(path):
        rec = row.get("record")
        val = _cycles({k: _float_or_none(v) for k, v in row.items() if k != "record"}, speed_hz, src, rec)
        if val is None:
            raise RULError("needs a 'cycles' or 'time_s' column", source=src, record=rec)
        out[str(rec)] = val
    return out


def _float_or_none(text):
    if text is None or str(text).strip() == "":
        return None
    try:
        return float(text)
    except ValueError:
        return text


def _csv_rows(path: Path) -> list[dict]:
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            rows = list(reader)
            header = reader.fieldnames or []
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise RULError(f"cannot read as CSV: {exc}", source=str(path)) from None
    if "record" not in header:
        raise RULError(f"CSV needs a 'record' column (it has: {', '.join(header) or 'no header'})",
                       source=str(path))
    return rows


def _csv_records(path: Path) -> list[dict]:
    rows = _csv_rows(path)
    header = list(rows[0].keys()) if rows else []
    pcols = []
    for prefix in ("p", "prob_", "p_"):
        k = 0
        cols = []
        while f"{prefix}{k}" in header:
            cols.append(f"{prefix}{k}")
            k += 1
        if len(cols) > len(pcols):
            pcols = cols
    records = []
    for row in rows:
        entry: dict[str, Any] = {"record": row["record"]}
        for key in ("cycles", "time_s", "speed_hz", "confidence"):
            if key in row and row[key] not in (None, ""):
                entry[key] = _float_or_none(row[key])
        if "stage" in row and row["stage"] not in (None, ""):
            try:
                entry["stage"] = int(row["stage"])
            except ValueError:
                entry["stage"] = row["stage"]
        if pcols:
            entry["probabilities"] = [_float_or_none(row[c]) for c in pcols]
        records.append(entry)
    return records


def observations_from_dict(data: Any, *, source: str = "<observations>", stages: Sequence[float] | None = None,
                           speed_hz: float | None = None, cycles: Mapping[str, float] | None = None,
                           sort: bool = False, default_stages: Sequence[float] | None = None) -> ObservationSet:
    """Validate a parsed observation document (see the module docstring) into an :class:`ObservationSet`.

    ``stages`` (if given) wins over the document's, which wins over ``default_stages`` (e.g. the
    scenario's archive stages); ``cycles`` ({record: cycles}) fills records that have none and must
    agree with those that have.  Raises :class:`RULError` naming the record and value.
    """
    if isinstance(data, list):
        data = {"records": data}
    if not isinstance(data, dict) or not isinstance(data.get("records"), list) or not data["records"]:
        raise RULError("expected {'records': [...]} with at least one record", source=source)
    if stages is None:
        stages = data.get("stages") if data.get("stages") is not None else default_stages
    bounds = check_stages(stages, source) if stages is not None else None
    n_stages = None if bounds is None else len(bounds) - 1
    file_speed = data.get("speed_hz")
    if file_speed is not None:
        file_speed = _number(file_speed, "speed_hz", source, None, positive=True)
    speed = file_speed if file_speed is not None else speed_hz
    kind = data.get("damage_kind")
    if kind is not None and kind not in DAMAGE_KINDS.values():
        raise RULError(f"damage_kind must be one of {sorted(DAMAGE_KINDS.values())}, got {kind!r}", source=source)
    extra = dict(cycles or {})
    obs, seen = [], set()
    for i, entry in enumerate(data["records"]):
        if not isinstance(entry, dict):
            raise RULError(f"records[{i}] must be an object, got {entry!r}", source=source)
        rec = str(entry.get("record", f"#{i}"))
        if rec in seen:
            raise RULError("record given twice", source=source, record=rec)
        seen.add(rec)
        p = _probabilities(entry, n_stages, source, rec)
        if n_stages is None:
            n_stages = p.size
        n = _cycles(entry, speed, source, rec)
        if rec in extra:
            if n is not None and not math.isclose(n, extra[rec], rel_tol=1e-9, abs_tol=1e-9):
                raise RULError(f"cycles {n!r} in the records disagree with {extra[rec]!r} in the cycles file",
                               source=source, record=rec)
            n = extra[rec]
        if n is None:
            raise RULError("no cycles (nor time_s, nor an entry in the cycles file)", source=source, record=rec)
        obs.append(Observation(rec, n, p))
    if sort:
        obs.sort(key=lambda o: o.cycles)
    for a, b in zip(obs, obs[1:]):
        if b.cycles < a.cycles:
            raise RULError(f"cycles go backwards: {b.cycles!r} after {a.cycles!r} (record '{a.record}'); "
                           f"records must be in time order (or sort them)", source=source, record=b.record)
    return ObservationSet(tuple(obs), bounds, kind, source)


def read_observations(path: str | Path, *, stages: Sequence[float] | None = None, speed_hz: float | None = None,
                      cycles_file: str | Path | None = None, sort: bool = False,
                      default_stages: Sequence[float] | None = None) -> ObservationSet:
    """Read assessed records from JSON (incl. the ``twin assess`` output) or CSV; see the module docstring."""
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise RULError("observation file does not exist", source=src)
    cycles = _read_cycles_file(Path(cycles_file), speed_hz) if cycles_file is not None else None
    if path.suffix.lower() == ".csv":
        data: Any = {"records": _csv_records(path)}
    else:
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise RULError(f"not valid JSON: {exc}", source=src) from None
    return observations_from_dict(data, source=src, stages=stages, speed_hz=speed_hz, cycles=cycles, sort=sort,
                                  default_stages=default_stages)


def simulate_assessments(trajectory: Trajectory, stages: Sequence[float], cycles, *, rate: float = 1.0,
                         offset_cycles: float = 0.0, accuracy: tuple[float, float] = (0.90, 0.97),
                         sharpness: tuple[float, float] = (1.5, 4.0), seed: int = 0) -> ObservationSet:
    """Assessed records of a gearbox whose true damage is ``D_model(rate N + offset_cycles)``.

    An imperfect classifier, for validation: at each of ``cycles`` (n,) the true stage k is
    called correctly with probability a ~ U(accuracy) (drawn per record), otherwise as a
    neighbouring stage (k - 1 or k + 1, equally likely; the only neighbour at the ends).  Its
    output is a softmax peaked on the called stage, ``p_j ∝ exp(-beta |j - called|)`` with
    beta ~ U(sharpness) per record, so a wrong call still gives the true stage some weight.
    Deterministic for a given ``seed``.
    """
    bounds = np.asarray(check_stages(stages), dtype=float)
    k_max = bounds.size - 2
    n = np.asarray(cycles, dtype=float)
    rng = np.random.default_rng(seed)
    true_d = trajectory.damage_at(rate * n + offset_cycles)
    true_k = np.clip(np.searchsorted(bounds, true_d, side="right") - 1, 0, k_max)
    obs = []
    for i, (ni, k) in enumerate(zip(n, true_k)):
        a = rng.uniform(*accuracy)
        beta = rng.uniform(*sharpness)
        called = int(k)
        if rng.uniform() > a:
            options = [j for j in (k - 1, k + 1) if 0 <= j <= k_max]
            called = int(options[rng.integers(len(options))])
        logits = -beta * np.abs(np.arange(k_max + 1) - called)
        p = np.exp(logits - logits.max())
        p /= p.sum()
        p.setflags(write=False)
        obs.append(Observation(f"sim{i:04d}", float(ni), p))
    return ObservationSet(tuple(obs), tuple(bounds.tolist()), trajectory.kind, f"simulated (seed {seed})")
