"""Remaining useful life (RUL) from a time series of assessed wear stages (``twin rul``).

The assessor (``twin assess``) turns each vibration record into stage probabilities
``p_k``, k = 0 .. K-1, for the stages ``[b_k, b_{k+1})`` of the damage measure (pitting
density, or mean wear depth in m) the archive was built on.  A stage says little by itself;
RUL needs the *trajectory* of the damage.  This module combines the two.

Method
------
**Trajectory.**  The calibrated degradation model of the scenario gives the damage against
pinion cycles, ``D_model(N)`` (:class:`Trajectory`): by default the co-simulated run of
:func:`twin.degradation_run.run_degradation` (``method="cosim"``: the FMU's dynamic load, 20 s
for the lubricated and 35 s for the dry scenario), or an HDF5 already written by ``twin run`` /
``twin archive`` (:func:`read_trajectory`).  ``method="static"`` drives the same cycle-jumping
loop with the quasi-static load sharing :meth:`MeshLoad.static` (damage fed back through
:func:`mesh_parameters`; no FMU, < 1 s for pitting, ~15 s for wear).  For pitting it agrees
with the co-simulated run within 3 % in cycles to 20 % density; for wear it does *not*: the
co-simulated wear rate drops about 4x between 90 and 120 um of mean depth (the worn profile
changes the dynamic load sharing) and the run reaches 240 um after 2.3e6 cycles instead of
1.5e6.  Use the static trajectory for pitting only, or to test.

**Unknowns.**  The real gearbox does not degrade at exactly the model's rate: the wear /
pitting coefficients scatter, the load is not the nominal one, the flank finish differs.  The
real damage is modelled as the model's curve on a stretched and shifted clock,

    D_real(N) = D_model(max(0, s N + tau)),       tau = f N_model(threshold)

with a *rate factor* ``s`` (> 1: faster than the model) and an *offset* ``f`` (a fraction of the
model's life to the threshold; > 0: damage already present when counting started, e.g. a
gearbox run before monitoring began; < 0: an incubation delay).  Under a constant load the
Archard depth is linear in N and the Lundberg-Palmgren density is ``1 - exp(-A N^m)``, so a
change of the wear coefficient, the pitting coefficient or the load is *exactly* a change of
``s`` (``s = (A'/A)^(1/m)`` for pitting); the shape of the curve is the model's.

**Observations.**  Record i at ``N_i`` cycles has stage probabilities ``p_i``.  A classifier's
output is read as soft evidence about the true stage: tempered ``q ∝ p^(1/T)`` (``temperature``
T > 1 softens an over-confident classifier) and mixed with a uniform floor,
``q <- (1 - eps) q + eps / K`` (``floor`` eps bounds the weight of one confident mistake).  The
likelihood of a damage value D is then

    L_i(D) = sum_k q_ik m_k(D),   m_k(D) = Phi((D - b_k)/w) - Phi((D - b_{k+1})/w)

with the outer boundaries at -inf / +inf (damage above the last boundary is in the last stage)
and a boundary width ``w = boundary_width x`` the median stage width (the archive's records are
drawn uniformly in each stage, so a classifier is least sure right at a boundary).

**Posterior.**  On a grid over ``(log s, f)`` with prior ``log s ~ N(0, rate_sigma)`` truncated
to ``rate_range`` (``rate_sigma=None``: log-uniform) and ``f`` uniform in ``offset_range``, the
posterior is ``prior x prod_i L_i(D_real(N_i))``.  The grid is evaluated twice: over the prior
range, then refined over where the posterior mass lies, so its step stays well under the band
width.  Nothing is sampled: the result is deterministic.

**Estimates** at ``now`` (by default the last record's cycles), as posterior quantiles
(default 5 %, 50 %, 95 %):

* current damage ``D_real(now)``;
* failure cycles ``N_fail = (N_model(threshold) - tau) / s``, the first crossing of the
  threshold, and ``RUL = max(0, N_fail - now)``;
* the rate factor and offset, and the probability that the threshold is already passed.

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
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import OutputPathError, ParameterError, ScenarioError, TwinError

RUL_FORMAT = "gear-twin-rul"
DAMAGE_KINDS = {"pitting": "pitting_density", "wear": "wear_depth"}
_PROB_TOL = 5e-3


class RULError(TwinError):
    """An RUL input is unusable: observations, stage boundaries, threshold or trajectory.

    Attributes
    ----------
    source : str or None
        The file (or object) the problem was found in.
    record : str or None
        The record it concerns, if any.
    """

    def __init__(self, message: str, *, source: str | None = None, record: str | None = None):
        self.source = None if source is None else str(source)
        self.record = record
        where = ""
        if self.source is not None:
            where += f"{self.source}: "
        if record is not None:
            where += f"record '{record}': "
        super().__init__(where + message)


def _unit(kind: str) -> tuple[float, str]:
    return (1e6, "um") if kind == "wear_depth" else (100.0, "%")


def format_damage(value: float, kind: str) -> str:
    scale, unit = _unit(kind)
    return f"{scale * value:.3g} {unit}"


# ----------------------------------------------------------------------------------------------
# Trajectory
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Trajectory:
    """The model's damage against pinion cycles, ``D_model(N)``, tabulated.

    Attributes
    ----------
    cycles : (n,) float array, strictly increasing, starting at 0
    damage : (n,) float array, non-decreasing, >= 0 (pitting density or mean wear depth [m])
    kind : "pitting_density" or "wear_depth"
    source : str
        Where it came from (for reports).

    Between points the damage is interpolated linearly; beyond the last point it is
    extrapolated with the mean slope over the last quarter of the table (capped at 1 for a
    density); before 0 it is 0.
    """

    cycles: np.ndarray
    damage: np.ndarray
    kind: str
    source: str = ""

    def __post_init__(self):
        c = np.array(self.cycles, dtype=float)
        d = np.array(self.damage, dtype=float)
        src = self.source or "trajectory"
        if self.kind not in DAMAGE_KINDS.values():
            raise RULError(f"damage kind must be one of {sorted(DAMAGE_KINDS.values())}, got {self.kind!r}",
                           source=src)
        if c.ndim != 1 or d.shape != c.shape or c.size < 2:
            raise RULError(f"cycles and damage must be 1-D of the same length >= 2, got shapes {c.shape} "
                           f"and {d.shape}", source=src)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(d))):
            raise RULError("cycles and damage must be finite", source=src)
        if c[0] != 0 or np.any(np.diff(c) <= 0):
            bad = 0 if c[0] != 0 else int(np.argmax(np.diff(c) <= 0)) + 1
            raise RULError(f"cycles must start at 0 and increase strictly; cycles[{bad}] = {c[bad]!r}", source=src)
        if d.min() < 0 or np.any(np.diff(d) < 0):
            bad = int(np.argmax(np.diff(d) < 0)) + 1 if np.any(np.diff(d) < 0) else int(np.argmin(d))
            raise RULError(f"damage must be >= 0 and non-decreasing; damage[{bad}] = {d[bad]!r}", source=src)
        if d[-1] <= d[0]:
            raise RULError(f"the damage never grows (stays at {d[0]!r})", source=src)
        c.setflags(write=False)
        d.setflags(write=False)
        object.__setattr__(self, "cycles", c)
        object.__setattr__(self, "damage", d)
        tail = max(1, c.size // 4)
        slope = (d[-1] - d[-1 - tail]) / (c[-1] - c[-1 - tail])
        object.__setattr__(self, "_slope", float(slope))
        keep = np.concatenate(([True], np.diff(d) > 0))      # first point of each plateau
        object.__setattr__(self, "_inv", (d[keep], c[keep]))

    @property
    def max_damage(self) -> float:
        return float(self.damage[-1])

    def damage_at(self, cycles) -> np.ndarray:
        """D_model at ``cycles`` (any shape); see the class docstring for the extrapolation."""
        n = np.asarray(cycles, dtype=float)
        out = np.interp(n, self.cycles, self.damage, left=0.0)
        beyond = n > self.cycles[-1]
        if np.any(beyond):
            ext = self.damage[-1] + self._slope * (n - self.cycles[-1])
            out = np.where(beyond, ext, out)
        out = np.where(n <= 0, 0.0, out)
        if self.kind == "pitting_density":
            out = np.minimum(out, 1.0)
        return out

    def cycles_at(self, damage: float) -> float:
        """First cycle count at which D_model reaches ``damage`` (within the table)."""
        if not (math.isfinite(damage) and self.damage[0] < damage <= self.damage[-1]):
            raise RULError(f"damage {damage!r} is outside the trajectory's range "
                           f"({self.damage[0]!r}, {self.damage[-1]!r}]", source=self.source or "trajectory")
        d, c = self._inv
        return float(np.interp(damage, d, c))


def _nominal(scenario, name: str, default: float) -> float:
    prof = scenario.inputs.get(name)
    return prof(scenario.start_time) if prof is not None else default


def scenario_speed_hz(scenario) -> float:
    """The scenario's pinion speed [Hz] at its start (20 Hz when it has no speed input)."""
    return _nominal(scenario, "motor_speed_ref", 2 * math.pi * 20.0) / (2 * math.pi)


def _degradation_model(scenario):
    from twin.degradation import ArchardWear, FatiguePitting
    spec = scenario.degradation
    coeffs = dict(spec.get("coefficients", {}))
    try:
        return FatiguePitting(**coeffs) if spec["model"] == "pitting" else ArchardWear(**coeffs)
    except TypeError as exc:
        raise ScenarioError([(str(scenario.source), "degradation.coefficients", str(exc))]) from None


def trajectory_from_scenario(scenario, *, method: str = "cosim", reach: float | None = None,
                             progress: bool = False, substeps: int = 4) -> Trajectory:
    """The calibrated model's damage trajectory under the scenario's operating point.

    Parameters
    ----------
    scenario : Scenario
        Must have a ``degradation:`` block (model, coefficients, ``max_increment``).
    method : "static" or "cosim"
        "static": the cycle-jumping loop of :func:`~twin.degradation_run.run_degradation` with the
        quasi-static load (:meth:`MeshLoad.static`, torque from the scenario's load input) and the
        damage fed back through :func:`mesh_parameters`; no FMU.  "cosim": run_degradation itself
        (the co-simulated load; needs the FMU, ~20 s for the lubricated scenario).
    reach : float, optional
        Damage the trajectory must reach.  Static: default 1.5 x the largest of the scenario's
        stop criterion and last archive stage boundary.  Co-simulated: the run stops on the
        scenario's criterion, raised to ``reach`` when that is higher.  It also stops after
        ``degradation.max_updates`` x 4 load updates, when the damage stops growing, or when a
        node of the mesh has lost all its stiffness (the quasi-static load has no solution).
    substeps : int
        Static method: points recorded per load update (the load is frozen over an update, so
        the sub-steps are exact for the model and only make the table finer).
    """
    spec = scenario.degradation
    if spec is None:
        raise ScenarioError([(str(scenario.source), "degradation", "the scenario has no degradation block")])
    kind = DAMAGE_KINDS[spec["model"]]
    if method == "cosim":
        from twin.degradation_run import run_degradation
        stop_key = "pitting_density" if kind == "pitting_density" else "wear_depth"
        if reach is not None and spec.get("stop", {}).get(stop_key, math.inf) < reach:
            # the run must get past the damage asked for: raise its stop criterion
            scenario = scenario.with_overrides(degradation={**spec, "stop": {stop_key: float(reach)}})
        run = run_degradation(scenario, None, progress=progress)
        return _dedupe(run.cycles, run.damage, kind, f"co-simulated degradation run of '{scenario.name}'")
    if method != "static":
        raise RULError(f"trajectory method must be 'static' or 'cosim', got {method!r}")

    from twin._progress import progress_bar
    from twin.degradation import GearPair, MeshLoad, WearState, mesh_parameters, project_wear
    model = _degradation_model(scenario)
    geometry = GearPair.from_parameters({k: v for k, v in scenario.parameters.items() if "[" not in k})
    torque_pinion = _nominal(scenario, "load_torque", 20.0) * geometry.z1 / geometry.z2
    omega1 = 2 * math.pi * scenario_speed_hz(scenario)
    params = {k: v for k, v in scenario.parameters.items() if "[" in k or k == "mesh_stiffness_scale"}
    k_healthy = tuple(params.get(f"k_pair[{i}]", h) for i, h in enumerate(_healthy_k(), start=1))
    stop = spec.get("stop", {})
    crit = stop.get("pitting_density" if kind == "pitting_density" else "wear_depth", 0.0)
    last_stage = float(scenario.archive["stages"][-1]) if scenario.archive else 0.0
    target = reach if reach is not None else 1.5 * max(crit, last_stage)
    if target <= 0:
        raise RULError("give reach= (or a stop criterion / archive stages in the scenario): "
                       "the trajectory needs a damage to run to", source=str(scenario.source))
    if kind == "pitting_density":
        target = min(target, 0.95)
    max_inc = float(spec.get("max_increment", 3e-6 if kind == "wear_depth" else 0.01))
    dn_cap = float(spec.get("cycles_per_update", 1e7))
    max_updates = 4 * int(spec.get("max_updates", 1000))
    state = model.initial_state(geometry)
    cycles, damage = [0.0], [0.0]
    measure = (lambda s: float(s.pitting_density)) if kind == "pitting_density" else (lambda s: float(s.mean_depth))
    bar = progress_bar(max_updates, progress, f"{scenario.name} trajectory", "update")
    try:
        for _ in range(max_updates):
            try:
                load = MeshLoad.static(geometry, torque_pinion, parameters=params)
            except ParameterError:
                break                                 # a node lost all stiffness: the tooth has failed
            if kind == "wear_depth":
                # Archard under a frozen load is linear in cycles: one evaluation of the rate gives
                # the jump and every sub-step exactly (cycles_for_increment would take three).
                rate = model.depth_per_cycle(geometry, state.xi, load)
                dn = dn_cap if rate.max() <= 0 else min(dn_cap, max_inc / float(rate.max()))
                start = state
                for j in range(1, substeps + 1):
                    state = WearState(start.cycles + dn * j / substeps, start.xi,
                                      start.depth + rate * (dn * j / substeps), geometry)
                    cycles.append(float(state.cycles))
                    damage.append(measure(state))
            else:
                dn = min(dn_cap, model.cycles_for_increment(state, load, omega1, max_inc, max_cycles=dn_cap))
                for _ in range(substeps):
                    state = model.advance(state, load, dn / substeps, omega1)
                    cycles.append(float(state.cycles))
                    damage.append(measure(state))
            update = mesh_parameters(geometry, wear=state if kind == "wear_depth" else None,
                                     pitting=state if kind == "pitting_density" else None,
                                     k_pair_healthy=k_healthy)
            params = {**params, **update.parameters}
            if kind == "wear_depth":
                state = project_wear(state)
            bar.update(1)
            if damage[-1] >= target or damage[-1] <= damage[-1 - substeps] * (1 + 1e-9):
                break
    finally:
        bar.close()
    return _dedupe(np.array(cycles), np.maximum.accumulate(np.array(damage)), kind,
                   f"quasi-static degradation model of '{scenario.name}'")


def _healthy_k():
    from twin.degradation import HEALTHY_K_PAIR
    return HEALTHY_K_PAIR


def _dedupe(cycles, damage, kind, source) -> Trajectory:
    cycles = np.asarray(cycles, dtype=float)
    damage = np.asarray(damage, dtype=float)
    keep = np.concatenate(([True], np.diff(cycles) > 0))
    return Trajectory(cycles[keep], damage[keep], kind, source)


def read_trajectory(path: str | Path) -> Trajectory:
    """Trajectory from an HDF5 written by ``twin run`` (degradation record) or ``twin archive``."""
    import h5py
    path = Path(path)
    if not path.is_file():
        raise RULError("trajectory file does not exist", source=str(path))
    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
            if fmt == "gear-twin-degradation":
                kind = DAMAGE_KINDS.get(str(f.attrs.get("model")), "")
                cycles, damage = f["cycles"][:], f["damage"][:]
            elif fmt == "gear-twin-archive" and "degradation" in f:
                kind = str(f.attrs.get("damage_kind"))
                cycles, damage = f["degradation"]["cycles"][:], f["degradation"]["damage"][:]
            else:
                raise RULError(f"not a degradation record or an archive with its degradation run (format {fmt!r})",
                               source=str(path))
    except OSError as exc:
        raise RULError(f"cannot read as HDF5: {exc}", source=str(path)) from None
    return _dedupe(cycles, damage, kind, str(path))


# ----------------------------------------------------------------------------------------------
# Observations
# ----------------------------------------------------------------------------------------------
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


# ----------------------------------------------------------------------------------------------
# Estimate
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RULEstimate:
    """Posterior summary at ``now_cycles`` (bands are the central ``band`` interval).

    Damage in the unit of ``damage_kind`` (density 0-1, or m); cycles are pinion revolutions.
    """

    now_cycles: float
    current_damage: float
    damage_band: tuple[float, float]
    rul_cycles: float
    rul_band: tuple[float, float]
    failure_cycles: float
    failure_band: tuple[float, float]
    threshold: float
    damage_kind: str
    rate_factor: float
    rate_band: tuple[float, float]
    offset_fraction: float
    probability_failed: float
    n_observations: int
    band: float = 0.90
    speed_hz: float | None = None
    warnings: tuple[str, ...] = ()

    def rul_hours(self) -> tuple[float, float, float] | None:
        """(lo, median, hi) RUL in hours at ``speed_hz``, or None without a speed."""
        if not self.speed_hz:
            return None
        h = 3600.0 * self.speed_hz
        return self.rul_band[0] / h, self.rul_cycles / h, self.rul_band[1] / h

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        for k, v in d.items():
            if isinstance(v, tuple):
                d[k] = list(v)
        return d

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> "RULEstimate":
        try:
            kw = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
            for k in ("damage_band", "rul_band", "failure_band", "rate_band", "warnings"):
                if k in kw:
                    kw[k] = tuple(kw[k])
            return cls(**kw)
        except (TypeError, KeyError) as exc:
            raise RULError(f"not an RUL estimate: {exc}") from None

    def table(self) -> str:
        lo, hi = 100 * (1 - self.band) / 2, 100 * (1 + self.band) / 2
        name = "pitting density" if self.damage_kind == "pitting_density" else "mean wear depth"
        rows = [("quantity", "median", f"{lo:g} %", f"{hi:g} %"),
                (f"current {name}", format_damage(self.current_damage, self.damage_kind),
                 format_damage(self.damage_band[0], self.damage_kind),
                 format_damage(self.damage_band[1], self.damage_kind)),
                ("RUL [cycles]", f"{self.rul_cycles:.4g}", f"{self.rul_band[0]:.4g}", f"{self.rul_band[1]:.4g}")]
        hours = self.rul_hours()
        if hours is not None:
            rows.append((f"RUL [h at {self.speed_hz:g} Hz]", f"{hours[1]:.4g}", f"{hours[0]:.4g}", f"{hours[2]:.4g}"))
        rows += [("failure at [cycles]", f"{self.failure_cycles:.4g}", f"{self.failure_band[0]:.4g}",
                  f"{self.failure_band[1]:.4g}"),
                 ("rate factor vs model", f"{self.rate_factor:.3g}", f"{self.rate_band[0]:.3g}",
                  f"{self.rate_band[1]:.3g}")]
        widths = [max(len(r[i]) for r in rows) for i in range(4)]
        lines = [f"threshold {format_damage(self.threshold, self.damage_kind)} {name}; "
                 f"{self.n_observations} records, now = {self.now_cycles:.4g} cycles; "
                 f"P(threshold already passed) = {self.probability_failed:.3f}"]
        for j, r in enumerate(rows):
            lines.append("  ".join(c.ljust(widths[i]) if i == 0 else c.rjust(widths[i]) for i, c in enumerate(r)))
            if j == 0:
                lines.append("  ".join("-" * w for w in widths))
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def weighted_quantile(values: np.ndarray, weights: np.ndarray, q) -> np.ndarray:
    """Quantiles ``q`` of a discrete distribution (values, weights), interpolated on the mid-point CDF."""
    values = np.asarray(values, dtype=float).ravel()
    weights = np.asarray(weights, dtype=float).ravel()
    order = np.argsort(values, kind="stable")
    v, w = values[order], weights[order]
    cdf = (np.cumsum(w) - 0.5 * w) / w.sum()
    return np.interp(q, cdf, v)


class RULEstimator:
    """Bayesian grid posterior over the rate factor and clock offset (module docstring).

    Parameters
    ----------
    trajectory : Trajectory
        The model's D(N).
    stages : sequence of K + 1 floats
        Stage boundaries, in the trajectory's damage unit.
    threshold : float
        Damage at end of life (e.g. 0.2 pitting density); must lie inside the trajectory.
    rate_range : (lo, hi)
        Support of the rate factor s (> 0).
    rate_sigma : float or None
        Prior standard deviation of ln s (centred on 1: the calibrated model); None: log-uniform.
    offset_range : (lo, hi)
        Support of f = tau / N_model(threshold) (uniform prior); (0, 0) fixes the clock origin.
    temperature, floor, boundary_width :
        Softening of the classifier output and of the stage boundaries (module docstring).
    n_rate, n_offset : int
        Grid size per pass.
    band : float
        Central probability of the reported bands (0.90: 5 % .. 95 %).
    """

    def __init__(self, trajectory: Trajectory, stages: Sequence[float], threshold: float, *,
                 rate_range: tuple[float, float] = (0.1, 10.0), rate_sigma: float | None = math.log(2.0),
                 offset_range: tuple[float, float] = (-0.2, 0.2), temperature: float = 1.0, floor: float = 0.05,
                 boundary_width: float = 0.1, n_rate: int = 301, n_offset: int = 41, band: float = 0.90,
                 speed_hz: float | None = None):
        if not isinstance(trajectory, Trajectory):
            raise RULError(f"trajectory must be a Trajectory, got {type(trajectory).__name__}")
        self.trajectory = trajectory
        self.stages = check_stages(stages, "stages")
        if not (isinstance(threshold, (int, float, np.floating)) and math.isfinite(threshold)
                and trajectory.damage[0] < threshold <= trajectory.max_damage):
            raise RULError(f"threshold {threshold!r} is outside the trajectory's damage range "
                           f"({trajectory.damage[0]:.4g}, {trajectory.max_damage:.4g}] ({trajectory.source}); "
                           f"extend the trajectory or lower the threshold")
        self.threshold = float(threshold)
        lo, hi = (float(v) for v in rate_range)
        if not (0 < lo < hi and math.isfinite(hi)):
            raise RULError(f"rate_range must be 0 < lo < hi, got {rate_range!r}")
        self.rate_range = (lo, hi)
        if rate_sigma is not None and not (math.isfinite(rate_sigma) and rate_sigma > 0):
            raise RULError(f"rate_sigma must be > 0 or None, got {rate_sigma!r}")
        self.rate_sigma = rate_sigma
        olo, ohi = (float(v) for v in offset_range)
        if not (olo <= ohi and olo > -1 and ohi < 1):
            raise RULError(f"offset_range must be lo <= hi inside (-1, 1), got {offset_range!r}")
        self.offset_range = (olo, ohi)
        for name, v, ok in (("temperature", temperature, temperature > 0), ("floor", floor, 0 <= floor < 1),
                            ("boundary_width", boundary_width, boundary_width >= 0), ("band", band, 0 < band < 1)):
            if not (math.isfinite(v) and ok):
                raise RULError(f"{name} out of range: {v!r}")
        self.temperature, self.floor, self.boundary_width, self.band = temperature, floor, boundary_width, band
        if not (int(n_rate) >= 11 and int(n_offset) >= 1):
            raise RULError(f"n_rate must be >= 11 and n_offset >= 1, got {n_rate!r}, {n_offset!r}")
        self.n_rate, self.n_offset = int(n_rate), int(n_offset)
        self.speed_hz = speed_hz
        self.life_model = trajectory.cycles_at(self.threshold)   # N_model(threshold)

    # -- likelihood ------------------------------------------------------------------------
    def _evidence(self, probabilities: np.ndarray) -> np.ndarray:
        p = np.clip(probabilities, 0.0, None) ** (1.0 / self.temperature)
        p = p / p.sum(axis=1, keepdims=True)
        k = p.shape[1]
        return (1 - self.floor) * p + self.floor / k

    def _membership(self, damage: np.ndarray) -> np.ndarray:
        """m_k(D) for damage of any shape -> shape + (K,)."""
        from scipy.special import ndtr
        b = np.asarray(self.stages)
        k = b.size - 1
        w = self.boundary_width * float(np.median(np.diff(b)))
        d = damage[..., None]
        inner = b[1:-1]
        if w > 0:
            above = ndtr((d - inner) / w)                         # P(D above boundary j)
        else:
            above = (d >= inner).astype(float)
        ones = np.ones(d.shape[:-1] + (1,))
        zeros = np.zeros(d.shape[:-1] + (1,))
        upper = np.concatenate([ones, above], axis=-1)            # above lower boundary of stage k
        lower = np.concatenate([above, zeros], axis=-1)           # above upper boundary of stage k
        m = upper - lower
        assert m.shape[-1] == k
        return m

    def _log_prior(self, log_s: np.ndarray) -> np.ndarray:
        if self.rate_sigma is None:
            return np.zeros_like(log_s)
        return -0.5 * (log_s / self.rate_sigma) ** 2

    def _log_like(self, log_s: np.ndarray, f: np.ndarray, cycles: np.ndarray, q: np.ndarray) -> np.ndarray:
        s = np.exp(log_s)[:, None, None]
        tau = (f * self.life_model)[None, :, None]
        ll = np.zeros((log_s.size, f.size))
        for start in range(0, cycles.size, 16):                   # bounded memory
            n = cycles[start:start + 16][None, None, :]
            dmg = self.trajectory.damage_at(s * n + tau)          # (R, F, M)
            like = np.einsum("rfmk,mk->rfm", self._membership(dmg), q[start:start + 16])
            ll += np.sum(np.log(np.maximum(like, 1e-300)), axis=-1)
        return ll

    def _grid(self, lo_s, hi_s, lo_f, hi_f):
        log_s = np.linspace(math.log(lo_s), math.log(hi_s), self.n_rate)
        f = np.linspace(lo_f, hi_f, self.n_offset) if hi_f > lo_f else np.array([lo_f])
        return log_s, f

    def fit(self, observations: ObservationSet | Sequence[Observation]) -> "RULEstimator":
        """Posterior over (s, f) given the observations; returns self.

        Learned: ``log_rates_`` (R,), ``offsets_`` (F,), ``posterior_`` (R, F) normalised weights,
        ``observations_``, ``now_`` (cycles of the last record), ``log_evidence_``.
        """
        obs = observations.observations if isinstance(observations, ObservationSet) else tuple(observations)
        if not obs:
            raise RULError("no observations to fit")
        k = len(self.stages) - 1
        for o in obs:
            if o.probabilities.shape != (k,):
                raise RULError(f"{o.probabilities.size} probabilities for {k} stages "
                               f"(boundaries {list(self.stages)})", record=o.record)
        cycles = np.array([o.cycles for o in obs])
        if np.any(np.diff(cycles) < 0):
            i = int(np.argmax(np.diff(cycles) < 0)) + 1
            raise RULError(f"cycles go backwards: {cycles[i]!r} after {cycles[i - 1]!r}", record=obs[i].record)
        q = self._evidence(np.stack([o.probabilities for o in obs]))
        lo_s, hi_s = self.rate_range
        lo_f, hi_f = self.offset_range
        for _ in range(2):
            log_s, f = self._grid(lo_s, hi_s, lo_f, hi_f)
            logp = self._log_like(log_s, f, cycles, q) + self._log_prior(log_s)[:, None]
            top = logp.max()
            w = np.exp(logp - top)
            mass = w.sum()
            w /= mass
            # refine over where the posterior is (1e-6 .. 1 - 1e-6 of each marginal, plus a step)
            ms, mf = w.sum(axis=1), w.sum(axis=0)
            cs, cf = np.cumsum(ms), np.cumsum(mf)
            i0 = max(0, int(np.searchsorted(cs, 1e-6)) - 1)
            i1 = min(log_s.size - 1, int(np.searchsorted(cs, 1 - 1e-6)) + 1)
            j0 = max(0, int(np.searchsorted(cf, 1e-6)) - 1)
            j1 = min(f.size - 1, int(np.searchsorted(cf, 1 - 1e-6)) + 1)
            lo_s, hi_s = math.exp(log_s[i0]), math.exp(log_s[i1])
            lo_f, hi_f = f[j0], f[j1]
        self.log_rates_, self.offsets_, self.posterior_ = log_s, f, w
        d_ls = log_s[1] - log_s[0]
        d_f = (f[1] - f[0]) if f.size > 1 else 1.0
        self.log_evidence_ = float(top + math.log(mass * d_ls * d_f))
        self.observations_ = obs
        self.now_ = float(cycles[-1])
        return self

    def _check_fitted(self):
        if not hasattr(self, "posterior_"):
            raise RULError("call fit(observations) before estimate()")

    def damage_quantiles(self, cycles, q=(0.05, 0.5, 0.95)) -> np.ndarray:
        """Posterior quantiles of D_real at ``cycles`` (n,) -> (len(q), n)."""
        self._check_fitted()
        n = np.atleast_1d(np.asarray(cycles, dtype=float))
        s = np.exp(self.log_rates_)[:, None]
        tau = self.offsets_[None, :] * self.life_model
        w = self.posterior_.ravel()
        out = np.empty((len(q), n.size))
        for j, nj in enumerate(n):
            out[:, j] = weighted_quantile(self.trajectory.damage_at(s * nj + tau), w, q)
        return out

    def failure_samples(self) -> tuple[np.ndarray, np.ndarray]:
        """(failure cycles per grid point (R*F,), weights)."""
        self._check_fitted()
        s = np.exp(self.log_rates_)[:, None]
        tau = self.offsets_[None, :] * self.life_model
        return ((self.life_model - tau) / s).ravel(), self.posterior_.ravel()

    def estimate(self, now: float | None = None) -> RULEstimate:
        """Current damage, RUL and failure cycles at ``now`` (default: the last record's cycles)."""
        self._check_fitted()
        now = self.now_ if now is None else float(now)
        if not (math.isfinite(now) and now >= 0):
            raise RULError(f"now must be finite cycles >= 0, got {now!r}")
        q = ((1 - self.band) / 2, 0.5, (1 + self.band) / 2)
        n_fail, w = self.failure_samples()
        rul = np.maximum(0.0, n_fail - now)
        s = np.exp(self.log_rates_)[:, None] * np.ones_like(self.posterior_)
        f = np.ones_like(self.posterior_) * self.offsets_[None, :]
        d_now = self.trajectory.damage_at(s * now + f * self.life_model).ravel()
        dq = weighted_quantile(d_now, w, q)
        rq = weighted_quantile(rul, w, q)
        fq = weighted_quantile(n_fail, w, q)
        sq = weighted_quantile(s.ravel(), w, q)
        warnings = []
        ms = self.posterior_.sum(axis=1)
        for edge, val, name in ((ms[0], self.rate_range[0], "lower"), (ms[-1], self.rate_range[1], "upper")):
            at_edge = (name == "lower" and math.isclose(self.log_rates_[0], math.log(val))) or \
                      (name == "upper" and math.isclose(self.log_rates_[-1], math.log(val)))
            if at_edge and edge > 1e-3:
                warnings.append(f"the posterior reaches the {name} end of rate_range ({val:g}): "
                                f"the records disagree with the model by more than that factor")
        if self.threshold > 1.1 * self.stages[-1]:
            warnings.append(f"threshold {self.threshold:.4g} lies well above the last stage boundary "
                            f"{self.stages[-1]:.4g}: the records cannot see it, the crossing is the model's "
                            f"shape extrapolated")
        return RULEstimate(
            now_cycles=now, current_damage=float(dq[1]), damage_band=(float(dq[0]), float(dq[2])),
            rul_cycles=float(rq[1]), rul_band=(float(rq[0]), float(rq[2])),
            failure_cycles=float(fq[1]), failure_band=(float(fq[0]), float(fq[2])),
            threshold=self.threshold, damage_kind=self.trajectory.kind,
            rate_factor=float(sq[1]), rate_band=(float(sq[0]), float(sq[2])),
            offset_fraction=float(weighted_quantile(f.ravel(), w, 0.5)),
            probability_failed=float(w[d_now >= self.threshold].sum()),
            n_observations=len(self.observations_), band=self.band, speed_hz=self.speed_hz,
            warnings=tuple(warnings))


# ----------------------------------------------------------------------------------------------
# Output: JSON and plot
# ----------------------------------------------------------------------------------------------
def rul_document(estimate: RULEstimate, estimator: RULEstimator | None = None) -> dict[str, Any]:
    doc: dict[str, Any] = {"format": RUL_FORMAT, "format_version": 1, "estimate": estimate.to_dict()}
    if estimator is not None:
        doc["stages"] = list(estimator.stages)
        doc["trajectory"] = estimator.trajectory.source
        doc["settings"] = {"rate_range": list(estimator.rate_range), "rate_sigma": estimator.rate_sigma,
                           "offset_range": list(estimator.offset_range), "temperature": estimator.temperature,
                           "floor": estimator.floor, "boundary_width": estimator.boundary_width}
        doc["records"] = [{"record": o.record, "cycles": o.cycles, "probabilities": o.probabilities.tolist()}
                          for o in getattr(estimator, "observations_", ())]
    return doc


def check_json_path(path: str | Path) -> Path:
    from twin._atomic import check_parent
    target = check_parent(path)
    if target.suffix.lower() != ".json":
        raise OutputPathError(f"JSON path '{target}' has suffix '{target.suffix}'; only .json is written")
    return target


def check_png_path(path: str | Path) -> Path:
    from twin._atomic import check_parent
    target = check_parent(path)
    if target.suffix.lower() != ".png":
        raise OutputPathError(f"plot path '{target}' has suffix '{target.suffix}'; only .png is written")
    return target


def write_json(path: str | Path, estimate: RULEstimate, estimator: RULEstimator | None = None) -> Path:
    """Write the estimate (and, with the estimator, its inputs and settings) atomically."""
    from twin._atomic import atomic_path
    target = check_json_path(path)
    text = json.dumps(rul_document(estimate, estimator), indent=2)
    with atomic_path(target) as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")
    return target


def read_json(path: str | Path) -> RULEstimate:
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RULError(f"cannot read: {exc}", source=str(path)) from None
    if not isinstance(doc, dict) or doc.get("format") != RUL_FORMAT:
        raise RULError(f"not a {RUL_FORMAT} file", source=str(path))
    return RULEstimate.from_dict(doc["estimate"])


def plot_rul(estimator: RULEstimator, estimate: RULEstimate, path: str | Path) -> Path:
    """Damage vs cycles: records (stage spans), posterior median and band, threshold crossing."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from twin._atomic import atomic_path
    target = check_png_path(path)
    scale, unit = _unit(estimate.damage_kind)
    n_end = max(estimate.failure_band[1], estimate.now_cycles) * 1.1
    grid = np.linspace(0.0, n_end, 200)
    lo, med, hi = estimator.damage_quantiles(grid, ((1 - estimate.band) / 2, 0.5, (1 + estimate.band) / 2))
    fig = Figure(figsize=(9.0, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.fill_between(grid, scale * lo, scale * hi, color="C0", alpha=0.25,
                    label=f"posterior {100 * estimate.band:g} % band")
    ax.plot(grid, scale * med, color="C0", label="posterior median")
    ax.plot(grid, scale * estimator.trajectory.damage_at(grid), color="0.5", ls="--", lw=1, label="model (s = 1)")
    b = np.asarray(estimator.stages)
    for o in estimator.observations_:
        k = int(np.argmax(o.probabilities))
        ax.plot([o.cycles, o.cycles], [scale * b[k], scale * b[k + 1]], color="C3",
                alpha=0.3 + 0.7 * float(o.probabilities[k]), lw=2)
    ax.plot([], [], color="C3", lw=2, label="records: most probable stage")
    for v in b:
        ax.axhline(scale * v, color="0.85", lw=0.8, zorder=0)
    ax.axhline(scale * estimate.threshold, color="k", lw=1.2, label="threshold")
    ax.axvspan(estimate.failure_band[0], estimate.failure_band[1], color="C1", alpha=0.15,
               label="predicted crossing band")
    ax.axvline(estimate.failure_cycles, color="C1", lw=1.2)
    ax.axvline(estimate.now_cycles, color="k", ls=":", lw=1, label="now")
    ax.set_xlim(0, n_end)
    ax.set_ylim(0, scale * max(estimate.threshold, b[-1]) * 1.15)
    ax.set_xlabel("pinion cycles")
    ax.set_ylabel(("pitting density" if estimate.damage_kind == "pitting_density" else "mean wear depth")
                  + f" [{unit}]")
    ax.set_title(f"RUL {estimate.rul_cycles:.3g} cycles ({estimate.rul_band[0]:.3g} .. "
                 f"{estimate.rul_band[1]:.3g}) after {estimate.n_observations} records")
    ax.legend(loc="upper left", fontsize=8)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return target


# ----------------------------------------------------------------------------------------------
# CLI
# ----------------------------------------------------------------------------------------------
def default_threshold(scenario) -> float | None:
    """The scenario's stop criterion in damage units (pitting_density or wear_depth), else None."""
    spec = scenario.degradation or {}
    stop = spec.get("stop", {})
    key = "pitting_density" if spec.get("model") == "pitting" else "wear_depth"
    return float(stop[key]) if key in stop else None


def run_rul(scenario, observations_path, *, threshold: float | None = None, stages=None, cycles_file=None,
            speed_hz: float | None = None, trajectory=None, method: str = "cosim", now: float | None = None,
            sort: bool = False, json_path=None, plot_path=None, progress: bool = False,
            **estimator_options) -> tuple[RULEstimate, RULEstimator]:
    """Everything ``twin rul`` does, as a function: read, fit, estimate, write.

    Output paths are checked before any work, so a bad path writes nothing.
    """
    if json_path is not None:
        check_json_path(json_path)
    if plot_path is not None:
        check_png_path(plot_path)
    if scenario.degradation is None:
        raise ScenarioError([(str(scenario.source), "degradation", "twin rul needs the scenario's degradation block")])
    speed = speed_hz if speed_hz is not None else scenario_speed_hz(scenario)
    scenario_stages = scenario.archive["stages"] if scenario.archive else None
    obs = read_observations(observations_path, stages=stages, speed_hz=speed, cycles_file=cycles_file, sort=sort,
                            default_stages=scenario_stages)
    bounds = obs.stages
    if bounds is None:
        raise RULError("no stage boundaries: give them in the observation file, with --stages or in the "
                       "scenario's archive block", source=str(observations_path))
    if threshold is None:
        threshold = default_threshold(scenario)
        if threshold is None:
            threshold = float(bounds[-1])
    if trajectory is None:
        top = max(threshold, float(bounds[-1]))
        traj = trajectory_from_scenario(scenario, method=method, progress=progress,
                                        reach=1.5 * top if method == "static" else top)
    elif isinstance(trajectory, Trajectory):
        traj = trajectory
    else:
        traj = read_trajectory(trajectory)
    if obs.damage_kind is not None and obs.damage_kind != traj.kind:
        raise RULError(f"the records are {obs.damage_kind} stages but the trajectory is {traj.kind}",
                       source=str(observations_path))
    est = RULEstimator(traj, bounds, threshold, speed_hz=speed, **estimator_options).fit(obs)
    result = est.estimate(now)
    if json_path is not None:
        write_json(json_path, result, est)
    if plot_path is not None:
        plot_rul(est, result, plot_path)
    return result, est
