"""Which parameters the measured modes can identify, and within which physical bounds.

1. **Candidates.** Every tunable scalar parameter of the FMU whose unit says it is a mass, an
   inertia, a stiffness (or the mesh-stiffness scale), with bounds from physics
   (:data:`PHYSICS_BOUNDS`: masses and inertias come from the geometry to within about 30 %,
   shaft stiffnesses to within a factor 1.6, couplings, bearings and supports to within a factor
   3-4; where the model computes a shaft from its geometry, its diameter within -15/+20 % and its
   bearing span within -20/+25 %; where it computes casing walls from a plate geometry, the wall
   thickness within -20/+40 %, each panel size within -20/+20 % and the lever arm by which a wall
   tilts a housing within -30/+20 %), narrowed to the model's own
   ``min``/``max`` when it declares them.
2. **Modes.** The model is linearised about the operating point (:mod:`twin.linearize`) with
   the sensor outputs and the excitations of a run-up (:data:`RUNUP_EXCITATIONS`): the mesh (a
   transmission error), the drive and the brake torque, and a force at each gear in each lateral
   direction and across the line of action (shaft-order run-out and unbalance, the process force).
   A model mode counts as *visible* when it makes a peak of an excitation-to-sensor response, the
   way a measured mode shows in a run-up: with ``visibility="mesh"`` (default) of the mesh
   column's, with ``visibility="run-up"`` of any column's (:data:`VISIBILITY`). At the nominal set
   every column's visible modes are kept (``ModelModes.visible_by``, reported) whichever rule is
   used; with the default rule the fit's linearisations take the mesh column alone. A mode's level
   (``gain_db``) is always the mesh column's: the columns' units differ (m, N.m, N), and the mesh
   is what excites the modes most in a geared run-up, so levels stay comparable between rules.
3. **Pairing and sensitivities** ``S[i, j] = d ln f_i / d ln p_j`` by one-sided differences (2 %),
   modes followed by their shapes (MAC) so that two crossing modes are not confused
   (:mod:`twin.calibration.pairing`). With ``pairing="frequency"`` (default) the measured modes
   are paired with visible model modes by frequency alone (none further than 15 %) and the paired
   modes' sensitivities are computed. With ``pairing="shape"`` the sensitivities of every
   candidate model mode (visible, or weakly visible down to
   :data:`twin.calibration.pairing.MIN_LEVEL_DB`) give each its reach within the bounds, and the
   measured modes are paired by frequency, shape at the sensors and reach; a pairing whose shape
   is clearly wrong (well measured and unlike) is refused and listed (``refused_by_shape``).
   Under either rule, when hammer records name the shaft they strike, a measured and a model mode
   that live on different shafts are never paired; each measured mode left unpaired so is a note.
4. **Identifiable subset** by QR with column pivoting on the weighted matrix
   ``S[i, j] * h_j / s_i`` (``h_j`` half the log-range of the bounds, ``s_i`` the relative
   uncertainty of mode i): a column is kept while the information it adds beyond the columns
   already kept, ``|R_kk|^2``, is at least :data:`MIN_INFORMATION` times the prior's (its bounds').
   A parameter left out is reported with why: the modes hardly depend on it, or it moves them
   the way a kept parameter does (named).
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from twin.calibration.model_modes import ModelModes, check_visibility, model_modes
from twin.calibration.pairing import (MATCH_REACH, REFUSE_COHERENCE, REFUSE_MISMATCH, MeasuredShapes, Pairing,
                                      candidate_modes, check_pairing, mode_reach, pair_by_frequency, pair_modes,
                                      shape_mismatch, shape_refusals, side_refused)

#: (unit, words in the description, relative bounds [lower, upper] about the nominal, reason); the
#: first rule whose unit matches and whose words (if any) occur in the description applies
PHYSICS_BOUNDS: tuple[tuple[str, tuple[str, ...], tuple[float, float], str], ...] = (
    ("kg.m2", (), (0.7, 1.4), "inertia: from the geometry of steel parts, within about 30 %"),
    ("kg", (), (0.7, 1.4), "mass: from the geometry, within about 30 %"),
    ("N.m/rad", ("shaft",), (0.6, 1.6), "shaft torsional stiffness: from the diameter (d^4), within a factor 1.6"),
    ("N.m/rad", (), (1 / 3, 3.0), "coupling stiffness: catalogue values scatter by a factor 3"),
    ("N/m", ("pedestal", "ground"), (0.25, 4.0), "support stiffness: bolted joints and foundation, a factor 4"),
    ("N/m", ("radial stiffness of bearing",), (1 / 3, 3.0), "bearing radial stiffness: clearance and preload, a factor 3"),
    ("N/m", ("coupling",), (1 / 3, 3.0), "elastomer coupling radial stiffness: spider hardness and catalogue scatter, a factor 3"),
    ("N/m", (), (1 / 3, 3.0), "shaft-and-bearing stiffness: bearing clearance and preload, a factor 3"),
    ("m", ("shaft diameter",), (0.85, 1.2),
     "shaft diameter: the effective bending diameter (shoulders, keyways, the hub's stiffening), -15/+20 %"),
    ("m", ("overhang",), (0.8, 1.25),
     "overhang: where the carried parts' mass centre and the bearing's support act, -20/+25 %"),
    ("m", ("bearing span",), (0.8, 1.25),
     "bearing span: where a bearing's support acts within its width and housing, -20/+25 %"),
    ("m", ("wall thickness",), (0.8, 1.4),
     "cast wall thickness: casting tolerance (about 1 mm on 8 mm) and the ribs and bosses that stiffen a panel, -20/+40 %"),
    ("m", ("wall panel size",), (0.8, 1.2),
     "wall panel size: where the clamped edges act (fillets, flanges, ribs), -20/+20 %"),
    ("m", ("tilt lever arm",), (0.7, 1.2),
     "tilt lever arm of a housing on a wall: the housing's boss and its joint to the end wall raise the pivot "
     "above the wall's mid-plane (-30 %), the wall's thickness and fillets lower it (+20 %)"),
    ("", ("calibration multiplier", "pair stiffness"), (0.6, 1.5),
     "mesh stiffness: ISO 6336 single-pair stiffness is good to about -40/+50 %"),
)
#: A kept column must add at least this many times the prior's information (posterior sd at most
#: 1/sqrt(1 + 4) = 45 % of the prior's).
MIN_INFORMATION = 4.0
#: Relative model-form uncertainty of a model mode [-], added in quadrature to the measurement's.
MODEL_FORM = 0.01
@dataclass(frozen=True)
class Candidate:
    name: str
    nominal: float
    lower: float
    upper: float
    reason: str

    @property
    def half_log_range(self) -> float:
        return 0.5 * math.log(self.upper / self.lower)


def candidate_parameters(fmu_path: str | Path, values: Mapping[str, float] | None = None) -> list[Candidate]:
    """Physical, tunable scalar parameters of the FMU with bounds from physics (see the docstring)."""
    from twin.fmu import FMU

    values = dict(values or {})
    out = []
    with FMU(fmu_path) as fmu:
        svs = {sv.name: sv for sv in fmu.model_description.modelVariables}
        for v in fmu.parameters:
            if v.type != "Real" or v.causality != "parameter" or "[" in v.name or "." in v.name:
                continue
            rule = _bounds_rule(v.unit, v.description)
            if rule is None:
                continue
            nominal = float(values.get(v.name, v.start if v.start is not None else 0.0))
            if not nominal > 0:
                continue
            (lo, hi), reason = rule
            lower, upper = nominal * lo, nominal * hi
            sv = svs.get(v.name)
            declared_min = getattr(sv, "min", None) if sv is not None else None
            declared_max = getattr(sv, "max", None) if sv is not None else None
            if declared_min is not None and float(declared_min) > lower and float(declared_min) < nominal:
                lower, reason = float(declared_min), reason + "; model min"
            if declared_max is not None and float(declared_max) < upper and float(declared_max) > nominal:
                upper, reason = float(declared_max), reason + "; model max"
            out.append(Candidate(v.name, nominal, lower, upper, reason))
    return out


def _bounds_rule(unit: str, description: str):
    text = (description or "").lower()
    for rule_unit, words, bounds, reason in PHYSICS_BOUNDS:
        if unit != rule_unit:
            continue
        if words and not any(w in text for w in words):
            continue
        if rule_unit == "" and not words:
            continue
        return bounds, reason
    return None


def match_measured(model: ModelModes, measured: np.ndarray, rel_sd: np.ndarray | None = None, *,
                   pairing: str = "frequency", shapes: MeasuredShapes | None = None,
                   reach: np.ndarray | None = None) -> np.ndarray:
    """Index of the model mode paired with each measured mode, -1 where none is: with
    ``pairing="frequency"`` the nearest visible model modes within 15 %
    (:func:`twin.calibration.pairing.pair_by_frequency`; of ``shapes`` only the struck levels,
    ``reach`` unused), with ``"shape"`` by frequency, shape at the sensors and reach
    (:func:`twin.calibration.pairing.pair_modes`); with struck levels never across shafts."""
    if check_pairing(pairing) == "frequency":
        return pair_by_frequency(model, measured, rel_sd, shapes)
    return pair_modes(model, measured, rel_sd, shapes=shapes, reach=reach)


def side_notes(model: ModelModes, measured: np.ndarray, match: np.ndarray,
               shapes: MeasuredShapes | None) -> list[str]:
    """One note per measured mode left unpaired although a visible model mode was within 15 %, because
    every such mode lives on the other shaft (:func:`twin.calibration.pairing.side_refused`)."""
    if shapes is None or shapes.side_db is None or model.side_db is None:
        return []
    vis = np.flatnonzero(model.visible)
    no = side_refused(model, shapes, vis)
    out = []
    for i in np.flatnonzero((match < 0) & no.any(axis=1)):
        near = vis[no[i] & (np.abs(np.log(model.frequency[vis] / measured[i])) <= MATCH_REACH)]
        if near.size:
            j = near[np.argmin(np.abs(np.log(model.frequency[near] / measured[i])))]
            out.append(f"measured {measured[i]:.0f} Hz (struck {shapes.side_db[i]:+.1f} dB input over output shaft) "
                       f"not paired with the model's {model.frequency[j]:.0f} Hz mode ({model.side_db[j]:+.1f} dB): "
                       "they live on different shafts")
    return out


def _mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion between the columns of a (n, p) and b (n, q): (p, q) in [0, 1]."""
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    return num / np.maximum(den, 1e-300)


def follow_index(base: ModelModes, moved: ModelModes, which: np.ndarray) -> np.ndarray:
    """Index in ``moved`` of each base mode ``which`` (one-to-one, by shape (MAC) and frequency).

    Reliable for small changes of the parameters (a finite difference, one step of a fit): modes
    that veer apart under a large change can exchange shapes.
    """
    mac = _mac(base.shapes[:, which], moved.shapes)
    closeness = np.abs(np.log(moved.frequency[None, :] / base.frequency[which][:, None]))
    rows, cols = linear_sum_assignment(-(mac - closeness))
    out = np.empty(which.size, dtype=int)
    out[rows] = cols
    return out


def follow(base: ModelModes, moved: ModelModes, which: np.ndarray) -> np.ndarray:
    """Frequencies [Hz] in ``moved`` of the base modes ``which`` (see :func:`follow_index`)."""
    return moved.frequency[follow_index(base, moved, which)]


@dataclass(frozen=True)
class Sensitivity:
    """d ln f / d ln p of the matched modes, the chosen subset and why the others are left out."""

    modes_hz: np.ndarray                  # (k,) model frequencies of the matched modes at nominal
    measured_hz: np.ndarray               # (k,)
    rel_sd: np.ndarray                    # (k,) relative uncertainty of each mode
    candidates: tuple[Candidate, ...]
    S: np.ndarray                         # (k, p)
    chosen: tuple[str, ...]
    left_out: Mapping[str, str]           # name -> reason
    information: Mapping[str, float]      # name -> |R_kk|^2 in pivot order (kept and first left out)
    condition: float                      # of the weighted, chosen columns
    unmatched_hz: tuple[float, ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)
    reach: np.ndarray | None = None       # (k, 2) how far (down, up) in ln f each paired model mode can move
    shape_mismatch: np.ndarray | None = None   # (k,) coherence x (1 - MAC) of each pairing (0: no shape)
    gain_db: np.ndarray | None = None     # (k,) peak gain of each paired model mode, dB re the most visible
    pairing: Pairing | None = None        # of all the measured modes (unpaired: -1), at the nominal set
    pairing_rule: str = "frequency"       # how the modes were paired (twin.calibration.pairing.PAIRINGS)
    refused: tuple[dict, ...] = ()        # measured modes left unpaired for their shape (pairing.shape_refusals)
    visibility: str = "mesh"              # which excitations made a model mode visible (VISIBILITY)
    visible_by: Mapping[str, tuple[float, ...]] = field(default_factory=dict)   # excitation -> visible modes [Hz]

    def pairing_warning(self, sensor_path_hz: Sequence[float] = ()) -> str | None:
        """A one-line warning when fewer measured modes were paired with a twin mode than were left
        with none (not paired, not given to the sensor path as ``sensor_path_hz``), else None: the
        fit then follows a few modes, and the modes it was given say little about the rest."""
        path = [float(f) for f in sensor_path_hz]
        left = [float(f) for f in self.unmatched_hz if not np.any(np.isclose(f, path or [np.nan]))]
        paired = len(self.measured_hz)
        if len(left) <= paired:
            return None
        total = paired + len(self.unmatched_hz)
        rule = ("visible twin mode within 15 %" if self.pairing_rule == "frequency"
                else "twin mode that reaches them within the bounds")
        to_path = len(self.unmatched_hz) - len(left)
        where = f"; {to_path} went to the sensor path" if to_path else ""
        return (f"only {paired} of {total} measured modes paired with a twin mode{where}; {len(left)} have no "
                f"{rule} ({', '.join(f'{f:.0f}' for f in left)} Hz): the calibration fitted the twin to the "
                f"paired ones alone, so its structure (or `calibration.visibility`: {self.visibility}"
                + ("; `--visibility run-up` to try" if self.visibility.startswith("mesh") else "")
                + ") may not suit this gearbox")

    def bounds(self) -> dict[str, list[float]]:
        by = {c.name: c for c in self.candidates}
        return {n: [by[n].lower, by[n].upper] for n in self.chosen}

    def table(self) -> str:
        by = {c.name: c for c in self.candidates}
        head = "  parameter        " + "".join(f"{f:>9.0f}" for f in self.modes_hz) + "   bounds"
        rows = ["d ln f / d ln p of the matched model modes [Hz at nominal]:", head]
        order = list(self.chosen) + [c.name for c in self.candidates if c.name not in self.chosen]
        for n in order:
            j = [c.name for c in self.candidates].index(n)
            mark = "*" if n in self.chosen else " "
            rows.append(f"{mark} {n:<16s}" + "".join(f"{v:9.3f}" for v in self.S[:, j])
                        + f"   [{by[n].lower:.4g}, {by[n].upper:.4g}]")
        rows.append(f"chosen (*): {', '.join(self.chosen) or 'none'}; condition number {self.condition:.3g}")
        rows.append("pairing: by frequency, among the visible model modes" if self.pairing_rule == "frequency"
                    else "pairing: by frequency, shape at the sensors and reach")
        if self.reach is not None:
            rows.append("pairing (measured -> model mode: its level re the most visible, its reach within the "
                        "bounds, shape mismatch):")
            for i, (fm, f) in enumerate(zip(self.measured_hz, self.modes_hz)):
                level = f"{self.gain_db[i]:6.1f} dB" if self.gain_db is not None else "      -"
                mis = f"{self.shape_mismatch[i]:.2f}" if self.shape_mismatch is not None else "-"
                rows.append(f"  {fm:9.1f} -> {f:9.1f} Hz  {level}  {-100 * (1 - math.exp(-self.reach[i, 0])):+.0f}/"
                            f"{100 * (math.exp(self.reach[i, 1]) - 1):+.0f} %  {mis}")
        for n, why in self.left_out.items():
            rows.append(f"  not identifiable: {n}: {why}")
        if self.unmatched_hz and self.pairing_rule == "frequency":
            rows.append("  measured modes the model has no visible mode for (within 15 %): "
                        + ", ".join(f"{f:.1f} Hz" for f in self.unmatched_hz))
        elif self.unmatched_hz:
            rows.append("  measured modes no model mode can reach within the bounds: "
                        + ", ".join(f"{f:.1f} Hz" for f in self.unmatched_hz))
        if self.refused:
            rows.append(f"  refused for their shape (1 - MAC > {REFUSE_MISMATCH:g}, measured with coherence >= "
                        f"{REFUSE_COHERENCE:g}): " + ", ".join(
                            f"{r['measured_hz']:.1f} Hz (model {r['model_hz']:.1f} Hz, {r['shape_mismatch']:.2f})"
                            for r in self.refused))
        if self.visible_by:
            rows.append(f"visible model modes at nominal [Hz], by excitation (visibility: {self.visibility}; "
                        + ("any column counts" if self.visibility.startswith("run-up") else "the mesh column counts")
                        + (", a mode dominating a response at its frequency too" if self.visibility.endswith("+dominant")
                           else "") + "):")
            rows += [f"  {e:<13s} " + ", ".join(f"{f:.0f}" for f in fs) for e, fs in self.visible_by.items()]
        rows += [f"note: {n}" for n in self.notes]
        return "\n".join(rows)

    def to_dict(self, sensor_path_hz: Sequence[float] | None = None) -> dict:
        """JSON-ready; with ``sensor_path_hz`` (the measured modes made sensor-path panel modes) each
        refused mode also says where it went (``sensor_path`` or ``unpaired``)."""
        refused = [dict(r) for r in self.refused]
        if sensor_path_hz is not None:
            for r in refused:
                r["goes_to"] = ("sensor_path" if np.any(np.isclose(r["measured_hz"], list(sensor_path_hz) or [np.nan]))
                                else "unpaired")
        return {"modes_hz": self.modes_hz.tolist(), "measured_hz": self.measured_hz.tolist(),
                "relative_sd": self.rel_sd.tolist(),
                "parameters": [{"name": c.name, "nominal": c.nominal, "bounds": [c.lower, c.upper],
                                "bounds_reason": c.reason, "d_ln_f_d_ln_p": self.S[:, j].tolist(),
                                "chosen": c.name in self.chosen, "left_out": self.left_out.get(c.name)}
                               for j, c in enumerate(self.candidates)],
                "chosen": list(self.chosen), "condition": self.condition,
                "unmatched_measured_hz": list(self.unmatched_hz), "notes": list(self.notes),
                "pairing_rule": self.pairing_rule, "visibility": self.visibility,
                "visible_by_excitation": {e: list(fs) for e, fs in self.visible_by.items()},
                "pairing": [{"measured_hz": float(fm), "model_hz": float(f),
                             "model_gain_db": None if self.gain_db is None else float(self.gain_db[i]),
                             "reach_ln_f": None if self.reach is None else [float(v) for v in self.reach[i]],
                             "shape_mismatch": None if self.shape_mismatch is None else float(self.shape_mismatch[i])}
                            for i, (fm, f) in enumerate(zip(self.measured_hz, self.modes_hz))],
                "refused_by_shape": refused,
                **({"sensor_path_hz": [float(f) for f in sensor_path_hz]} if sensor_path_hz is not None else {})}


def mode_sensitivity(fmu_path, values: Mapping[str, float], measured_hz, *, speed_hz: float, load_nm: float,
                     rel_sd=None, channels: Sequence[str] = ("accel_pinion_casing",),
                     candidates: Sequence[Candidate] | None = None, step: float = 0.02,
                     executor=None, shapes: MeasuredShapes | None = None,
                     pairing: str = "frequency", visibility: str = "mesh") -> Sensitivity:
    """Sensitivities of the measured modes' model counterparts and the identifiable subset.

    ``pairing``: ``"frequency"`` (default) or ``"shape"`` (see the module docstring); ``shapes``:
    the measured modes' shapes at the channels (``twin modes``), used by the shape pairing;
    ``visibility``: which excitations make a model mode visible (:data:`VISIBILITY`)."""
    check_pairing(pairing)
    measured = np.asarray(measured_hz, float)
    rel = np.sqrt((np.full(measured.size, 0.0) if rel_sd is None else np.asarray(rel_sd, float)) ** 2
                  + MODEL_FORM ** 2)
    cands = list(candidates) if candidates is not None else candidate_parameters(fmu_path, values)
    kw = dict(speed_hz=speed_hz, load_nm=load_nm, channels=tuple(channels), visibility=check_visibility(visibility))
    base = model_modes(fmu_path, values, **kw, every_excitation=True)      # each column's visible modes reported
    notes = []
    if pairing == "frequency":      # paired before the runs: only the paired modes' sensitivities are needed
        match = match_measured(base, measured, rel, shapes=shapes)
        notes += side_notes(base, measured, match, shapes)
        if not (match >= 0).any():
            raise ValueError("no measured mode has a visible model mode within 15 %: the model and the record "
                             f"do not share a mode (measured {np.round(measured, 1).tolist()} Hz, visible model "
                             f"{np.round(base.frequency[base.visible], 1).tolist()} Hz)")
    tasks = [(str(fmu_path), {**values, c.name: c.nominal * (1 + step)}, kw) for c in cands]
    if executor is not None:
        moved = executor.map(_modes_task, tasks, desc="sensitivities")
    else:
        moved = [_modes_task(t) for t in tasks]
    failed = [(c.name, r) for c, r in zip(cands, moved) if isinstance(r, BaseException)]
    if failed:      # a crashed or failed linearisation: named, not an AttributeError further down
        from twin.errors import SimulationError
        name, err = failed[0]
        raise SimulationError(f"{len(failed)} of {len(cands)} sensitivity runs failed; first ({name} moved by "
                              f"{100 * step:g} %): {err}")
    if pairing == "frequency":
        ok = match >= 0
        which = match[ok]
        S = np.empty((which.size, len(cands)))
        for j, mv in enumerate(moved):
            S[:, j] = np.log(follow(base, mv, which) / base.frequency[which]) / math.log(1 + step)
        chosen, left_out, info, cond = select_identifiable(S, cands, rel[ok])
        return Sensitivity(base.frequency[which], measured[ok], rel[ok], tuple(cands), S, chosen, left_out, info,
                           cond, tuple(float(f) for f in measured[~ok]), tuple(notes), gain_db=base.gain_db[which],
                           visibility=visibility, visible_by=_visible_by(base))
    # every candidate model mode's sensitivities, so that each has its own reach for the pairing
    cols = candidate_modes(base)
    S_all = np.zeros((base.frequency.size, len(cands)))
    for j, mv in enumerate(moved):
        S_all[cols, j] = np.log(follow(base, mv, cols) / base.frequency[cols]) / math.log(1 + step)
    reach = mode_reach(S_all, cands)
    match = match_measured(base, measured, rel, pairing="shape", shapes=shapes, reach=reach)
    notes += side_notes(base, measured, match, shapes)
    ok = match >= 0
    which = match[ok]
    if not ok.any():
        raise ValueError("no measured mode is within the reach of a model mode: the model and the record "
                         f"do not share a mode (measured {np.round(measured, 1).tolist()} Hz, visible model "
                         f"{np.round(base.frequency[base.visible], 1).tolist()} Hz)")
    mismatch = (shape_mismatch(base, shapes, which)[np.flatnonzero(ok), np.arange(which.size)]
                if shapes is not None else np.zeros(which.size))
    S = S_all[which]
    chosen, left_out, info, cond = select_identifiable(S, cands, rel[ok])
    return Sensitivity(base.frequency[which], measured[ok], rel[ok], tuple(cands), S, chosen, left_out, info, cond,
                       tuple(float(f) for f in measured[~ok]), tuple(notes), reach[which], mismatch,
                       base.gain_db[which], Pairing(base, match), "shape",
                       tuple(shape_refusals(base, measured, match, rel, shapes=shapes, reach=reach)),
                       visibility, _visible_by(base))


def _visible_by(model: ModelModes) -> dict[str, tuple[float, ...]]:
    """Excitation -> the frequencies [Hz] of the model modes its column makes visible."""
    return {e: tuple(float(f) for f in model.frequency[v]) for e, v in model.visible_by.items()}


def _modes_task(task):
    path, values, kw = task
    return model_modes(path, values, **kw)


def select_identifiable(S: np.ndarray, candidates: Sequence[Candidate], rel_sd: np.ndarray, *,
                        min_information: float = MIN_INFORMATION, max_parameters: int | None = None):
    """(chosen names, {left-out name: reason}, {name: information}, condition) by pivoted QR."""
    from scipy.linalg import qr

    half = np.array([c.half_log_range for c in candidates])
    Sw = S * half[None, :] / rel_sd[:, None]
    k = Sw.shape[0]
    limit = min(k, max_parameters or k)
    _, R, piv = qr(Sw, pivoting=True, mode="economic")
    diag = np.abs(np.diag(R))
    chosen_idx: list[int] = []
    info: dict[str, float] = {}
    for pos, j in enumerate(piv[: diag.size]):
        info[candidates[j].name] = float(diag[pos] ** 2)
        if diag[pos] ** 2 < min_information or len(chosen_idx) >= limit:
            break
        chosen_idx.append(int(j))
    chosen = tuple(candidates[j].name for j in chosen_idx)
    left_out: dict[str, str] = {}
    norms = np.linalg.norm(Sw, axis=0)
    for j, c in enumerate(candidates):
        if j in chosen_idx:
            continue
        if norms[j] ** 2 < min_information:
            shift = float(np.max(np.abs(S[:, j])) * 2 * c.half_log_range * 100)
            left_out[c.name] = (f"the modes hardly depend on it (across its bounds they move by at most "
                                f"{shift:.2g} %)")
            continue
        if chosen_idx:
            # the kept parameter whose effect on the modes is most alike (cosine of the columns)
            A = Sw[:, chosen_idx]
            cos = (A.T @ Sw[:, j]) / (np.linalg.norm(A, axis=0) * norms[j])
            best = int(np.argmax(np.abs(cos)))
            if abs(cos[best]) >= 0.9:
                left_out[c.name] = (f"moves the modes as {chosen[best]} does (cosine {cos[best]:+.2f}): the modes "
                                    "cannot tell them apart")
            else:
                left_out[c.name] = (f"adds too little beyond the chosen parameters (most alike: {chosen[best]}, "
                                    f"cosine {cos[best]:+.2f}; information {float(norms[j] ** 2):.2g} before, less "
                                    "after them)")
        else:
            left_out[c.name] = "no parameter can be chosen"
    cond = float(np.linalg.cond(Sw[:, chosen_idx])) if chosen_idx else float("inf")
    return chosen, left_out, info, cond
