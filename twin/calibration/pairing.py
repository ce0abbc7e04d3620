"""Which model mode each measured mode is: two pairing rules (:data:`PAIRINGS`).

``frequency`` (the default, :func:`pair_by_frequency`): each measured mode is paired with a
*visible* model mode (one that makes a peak at a sensor) by least total
``|ln(f_model / f_measured)| / s_i`` (one-to-one, Hungarian algorithm); a measured mode with no
visible model mode within :data:`MATCH_REACH` stays unpaired.

``shape`` (opt-in, :func:`pair_modes`; scored worse on the rigs, see docs/experiments.md): a
measured mode is paired with a model mode when the model can *become* it: the model mode must
be able to reach the measured frequency within the physical bounds of the parameters, and its
shape at the casing sensors must look like the measured one.

* **Candidates.** Every model mode that makes a peak at a sensor (*visible*) and every mode whose
  own peak gain is at least :data:`MIN_LEVEL_DB` below the most visible mode's: a shaft's lateral
  mode seen through a stiff casing peaks 40-65 dB down, and it is still the mode a rig's shaft
  mode must be fitted with.
* **Reach.** Model mode j can move down by ``down_j`` and up by ``up_j`` (in ln f):
  ``up_j = sum_p max(0, S_jp ln(upper_p / p_p), S_jp ln(lower_p / p_p))`` (each parameter at the
  bound that raises it most; ``down_j`` likewise), from the first-order sensitivities
  ``S = d ln f / d ln p`` (:func:`twin.calibration.sensitivity.mode_sensitivity`). Without
  sensitivities every mode reaches :data:`MATCH_REACH` either way. A measured mode further from
  a model mode than its reach (plus twice its uncertainty) is never paired with it. The reach is
  what the bounds allow, not what is likely (every parameter at its most favourable bound): it
  decides which pairings are possible, not which is best.
* **Cost** of pairing measured mode i with model mode j:
  ``max(0, |ln(f_i / f_j)| - 2 s_i) / MATCH_REACH`` (0 within the measurement's uncertainty; a
  15 % gap costs 1) plus ``SHAPE_WEIGHT * coherence_i * (1 - MAC_ij)``,
  where MAC is the modal assurance criterion between the measured shape at the channels (level
  and phase re a reference, :mod:`twin.signals.shapes`) and the model's residues at the same
  channels (``ModelModes.sensor_shapes``), and ``coherence_i`` the measured shape's lowest
  coherence: a shape that is not trustworthy does not count.
* **Refusal.** A pairing whose shape is clearly wrong is not made at any cost: when the measured
  shape is well measured (lowest coherence at least :data:`REFUSE_COHERENCE`) and the model mode's
  shape differs from it by more than :data:`REFUSE_MISMATCH` (``1 - MAC``). At coherence 0.8 the
  random error of a measured level ratio is at most about 35 % even from one average (Bendat and
  Piersol: ``sqrt((1 - g) / (2 g n))``), which makes ``1 - MAC`` of two-channel shapes at most about
  0.06; a mismatch above 0.5 (the shapes less alike than unlike) is then the physics, not the
  estimate. Below that coherence a neighbouring mode or the noise may have bent the shape, and
  the mismatch only costs. A refused measured mode goes to another model mode of its shape
  within reach, or stays unpaired (and may become a sensor-path panel mode,
  :func:`twin.calibration.sensor_path.casing_path`); :func:`shape_refusals` lists them.
* **Assignment.** One-to-one with least total cost (Hungarian algorithm); a measured mode is left
  unpaired at cost :data:`UNPAIRED`, more than any feasible pairing.

**Which shaft** (both rules, when hammer records struck on each shaft name their shaft,
``calibration.struck_shafts``). A mode answers a blow where it moves: its response to the blows on
the input shaft over those on the output shaft (``evidence["struck_db"]`` of ``twin modes``) says on
which shaft it lives, and the model mode's largest lateral amplitude on the input shaft over the
output shaft's (``ModelModes.side_db``, :func:`twin.calibration.mode_classes.side_levels`) says the
same of the model's. A pairing is refused when both say, by :data:`SIDE_DB` or more, that the two
modes live on different shafts (:func:`side_refused`): the frequency order alone gave the rigs' gear
shaft modes the twin's input shaft mode, and the fit then drove that shaft's bearing to its bound.
A mode that lives on both shafts (within :data:`SIDE_DB` either side) or that the hammers did not
reach is paired as before. Scored on the rigs it lost matches (docs/calibration.md, seeds 101-105):
the modes it refused there are a gear rocking on its shaft, which the twin's models lack; an opt-in.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

#: The pairing rules: by frequency among the visible modes (default), or by frequency, shape and reach.
PAIRINGS = ("frequency", "shape")
#: Frequency-only pairing: no model mode further than this (relative, in ln f) is paired; shape
#: pairing without sensitivities: each model mode reaches this far either way.
MATCH_REACH = 0.15
#: Model modes whose peak gain is at least this far below the most visible mode's [dB] are candidates.
MIN_LEVEL_DB = -70.0
#: Weight of a full shape mismatch (1 - MAC = 1, coherence 1) against a 15 % frequency gap.
SHAPE_WEIGHT = 1.0
#: Cost of leaving a measured mode unpaired: a pairing that costs more (a gap of more than about
#: 45 % with the right shape) is not made even within reach.
UNPAIRED = 3.0
#: A measured shape counts as well measured from this lowest coherence with its reference [-].
REFUSE_COHERENCE = 0.8
#: A well-measured shape is never paired with a model mode whose shape differs more than this (1 - MAC).
REFUSE_MISMATCH = 0.5
#: A mode lives on one shaft when it answers blows there, or moves there, this much more than on the
#: other [dB]: twice the amplitude, well beyond the few dB a neighbouring mode's tail or a coherence
#: of 0.7 puts on a struck-point level.
SIDE_DB = 6.0
#: The shafts a hammer record may be struck on (``calibration.struck_shafts``).
SHAFTS = ("input", "output")


@dataclass(frozen=True)
class MeasuredShapes:
    """Shapes of the measured modes at the channels, and the shaft each lives on (from ``twin modes``).

    channels : (c,) names; vectors : (k, c) complex, level and phase re each mode's reference
    (NaN where a channel has no estimate); coherence : (k,) lowest coherence with the reference;
    side_db : (k,) the loudest blow on the input shaft over that on the output shaft [dB] (NaN where
    a mode has no level on both, None without ``struck_shafts``: :func:`struck_sides`).
    """

    channels: tuple[str, ...]
    vectors: np.ndarray
    coherence: np.ndarray
    side_db: np.ndarray | None = None     # (k,) input over output shaft's struck level [dB], NaN where unknown

    def subset(self, keep: np.ndarray) -> "MeasuredShapes":
        """The same for the measured modes ``keep`` ((k,) bool or indices) only."""
        return MeasuredShapes(self.channels, self.vectors[keep], self.coherence[keep],
                              None if self.side_db is None else self.side_db[keep])

    @classmethod
    def from_evidence(cls, evidence: Sequence[dict], struck_shafts: Mapping[str, str] | None = None,
                      ) -> "MeasuredShapes | None":
        """From the modes' ``evidence["shape"]`` and ``evidence["struck_db"]`` (``twin modes`` JSON);
        ``struck_shafts`` maps hammer record names to the shaft struck (:data:`SHAFTS`). None when no
        mode has a shape at two channels and no mode a struck level on each shaft."""
        sides = struck_sides(evidence, struck_shafts or {})
        shaped = [e.get("shape") for e in evidence]
        names: list[str] = []
        for s in shaped:
            for c in (s or {}).get("channels", {}):
                if c not in names:
                    names.append(c)
        if len(names) < 2:
            if sides is None:
                return None
            return cls((), np.full((len(evidence), 0), np.nan, complex), np.zeros(len(evidence)), sides)
        vec = np.full((len(shaped), len(names)), np.nan, complex)
        coh = np.zeros(len(shaped))
        for i, s in enumerate(shaped):
            if not s:
                continue
            for c, v in s["channels"].items():
                vec[i, names.index(c)] = 10 ** (v["level_db"] / 20) * np.exp(1j * np.radians(v["phase_deg"]))
            coh[i] = float(s.get("min_coherence", 0.0))
        return cls(tuple(names), vec, coh, sides)


def struck_sides(evidence: Sequence[dict], struck_shafts: Mapping[str, str]) -> np.ndarray | None:
    """(k,) each mode's loudest response to the blows on the input shaft over that on the output
    shaft [dB] (from ``evidence["struck_db"]``, records named in ``struck_shafts``), NaN where a mode
    has no level on both; None when no mode has."""
    out = np.full(len(evidence), np.nan)
    for i, e in enumerate(evidence):
        levels = e.get("struck_db") or {}
        by = {s: [v for r, v in levels.items() if struck_shafts.get(r) == s] for s in SHAFTS}
        if all(by.values()):
            out[i] = max(by["input"]) - max(by["output"])
    return out if np.isfinite(out).any() else None


def side_refused(model, shapes: MeasuredShapes | None, cols: np.ndarray) -> np.ndarray:
    """(k, len(cols)) True where measured mode i and model mode ``cols[j]`` live on different shafts,
    each by :data:`SIDE_DB` or more (see the module docstring); (1, len(cols)) all False, which
    broadcasts, without struck levels."""
    model_side = getattr(model, "side_db", None)
    if shapes is None or shapes.side_db is None or model_side is None:
        return np.zeros((1, cols.size), bool)
    meas = np.nan_to_num(shapes.side_db)[:, None]
    mod = np.nan_to_num(np.asarray(model_side, float)[cols])[None, :]
    return ((meas >= SIDE_DB) & (mod <= -SIDE_DB)) | ((meas <= -SIDE_DB) & (mod >= SIDE_DB))


@dataclass(frozen=True, eq=False)
class Pairing:
    """A pairing made at one parameter set: ``index`` (k,) of the model mode of ``model`` (a
    ``ModelModes``) paired with each measured mode, -1 where none."""

    model: object
    index: np.ndarray

    def at(self, other) -> np.ndarray:
        """The same pairing in ``other`` (the model at nearby parameters), each mode followed by its
        shape and frequency (:func:`twin.calibration.sensitivity.follow_index`)."""
        from twin.calibration.sensitivity import follow_index

        out = np.full(self.index.size, -1, dtype=int)
        ok = self.index >= 0
        if ok.any():
            out[ok] = follow_index(self.model, other, self.index[ok])
        return out


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """Modal assurance criterion |a^H b|^2 / (|a|^2 |b|^2) of two complex vectors, in [0, 1]."""
    den = float(np.sum(np.abs(a) ** 2) * np.sum(np.abs(b) ** 2))
    return float(np.abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def raw_mismatch(model, shapes: MeasuredShapes | None, cols: np.ndarray) -> np.ndarray:
    """(k, len(cols)) shape mismatch ``1 - MAC_ij`` at the channels both know; NaN where the measured
    mode has no shape at two such channels, or a coherence of 0 (all NaN without shapes)."""
    k = 0 if shapes is None else shapes.vectors.shape[0]
    out = np.full((k, cols.size), np.nan)
    if shapes is None or model.sensor_shapes is None:
        return out
    for i in range(k):
        known = [c for c, v in zip(shapes.channels, shapes.vectors[i]) if np.isfinite(v) and c in model.channels]
        if len(known) < 2 or shapes.coherence[i] <= 0:
            continue
        m = np.array([shapes.vectors[i, shapes.channels.index(c)] for c in known])
        for jj, j in enumerate(cols):
            out[i, jj] = 1.0 - mac(m, model.sensor_shape(int(j), known))
    return out


def shape_mismatch(model, shapes: MeasuredShapes | None, cols: np.ndarray) -> np.ndarray:
    """(k, len(cols)) coherence-weighted shape mismatch ``coherence_i (1 - MAC_ij)`` (0 without shapes)."""
    raw = raw_mismatch(model, shapes, cols)
    if shapes is None:
        return np.nan_to_num(raw)
    return np.nan_to_num(shapes.coherence[:, None] * raw)


def refused(model, shapes: MeasuredShapes | None, cols: np.ndarray) -> np.ndarray:
    """(k, len(cols)) True where a pairing is refused: the measured shape well measured (coherence
    >= :data:`REFUSE_COHERENCE`) and ``1 - MAC`` above :data:`REFUSE_MISMATCH`."""
    raw = raw_mismatch(model, shapes, cols)
    if shapes is None:
        return np.zeros(raw.shape, bool)
    return _refusal(raw, shapes.coherence)


def _refusal(raw: np.ndarray, coherence: np.ndarray) -> np.ndarray:
    """:func:`refused` from the (k, n) ``1 - MAC`` of :func:`raw_mismatch` and the (k,) coherences."""
    return (coherence[:, None] >= REFUSE_COHERENCE) & (np.nan_to_num(raw) > REFUSE_MISMATCH)


def mode_reach(S: np.ndarray, candidates) -> np.ndarray:
    """(m, 2) how far (down, up) in ln f each mode can move within the candidates' bounds, to first
    order; ``S`` (m, p) is d ln f / d ln p of the modes, ``candidates`` (p,) have nominal and bounds."""
    lo = np.array([np.log(c.lower / c.nominal) for c in candidates])
    hi = np.array([np.log(c.upper / c.nominal) for c in candidates])
    a, b = S * hi[None, :], S * lo[None, :]
    up = np.sum(np.maximum(0.0, np.maximum(a, b)), axis=1)
    down = np.sum(np.maximum(0.0, -np.minimum(a, b)), axis=1)
    return np.column_stack([down, up])


def candidate_modes(model, min_level_db: float = MIN_LEVEL_DB) -> np.ndarray:
    """Indices of the model modes a measured mode may be paired with (visible, or not far below)."""
    return np.flatnonzero(model.visible | (model.gain_db >= min_level_db))


def pairing_cost(model, measured: np.ndarray, rel_sd: np.ndarray, cols: np.ndarray, *,
                 shapes: MeasuredShapes | None = None, reach: np.ndarray | None = None) -> np.ndarray:
    """(k, len(cols)) cost of each pairing (see the module docstring); inf where out of reach or
    refused for its shape (:func:`refused`)."""
    excess, within = _gap(model, measured, rel_sd, cols, reach)
    if shapes is None:
        return np.where(within, excess / MATCH_REACH, np.inf)
    raw = raw_mismatch(model, shapes, cols)       # once: it weighs the cost and decides refusals
    cost = excess / MATCH_REACH + SHAPE_WEIGHT * np.nan_to_num(shapes.coherence[:, None] * raw)
    return np.where(within & ~_refusal(raw, shapes.coherence) & ~side_refused(model, shapes, cols), cost, np.inf)


def _gap(model, measured: np.ndarray, rel_sd: np.ndarray, cols: np.ndarray, reach: np.ndarray | None):
    """(k, len(cols)) frequency gap beyond twice the uncertainty [ln f], and whether it is within reach."""
    lr = np.log(measured[:, None] / model.frequency[cols][None, :])           # > 0: the model mode must rise
    r = np.full((cols.size, 2), MATCH_REACH) if reach is None else np.asarray(reach, float)[cols]
    side = np.where(lr > 0, r[None, :, 1], r[None, :, 0])
    excess = np.maximum(0.0, np.abs(lr) - 2 * rel_sd[:, None])
    return excess, excess <= side


def pair_modes(model, measured, rel_sd=None, *, shapes: MeasuredShapes | None = None,
               reach: np.ndarray | None = None, min_level_db: float = MIN_LEVEL_DB) -> np.ndarray:
    """Index of the model mode paired with each measured mode, -1 where none can be (see the module
    docstring); ``reach`` (m, 2) is :func:`mode_reach` of all the model's modes, or None."""
    from twin.calibration.sensitivity import MODEL_FORM

    measured = np.asarray(measured, float)
    rel_sd = np.full(measured.size, MODEL_FORM) if rel_sd is None else np.asarray(rel_sd, float)
    cols = candidate_modes(model, min_level_db)
    out = np.full(measured.size, -1, dtype=int)
    if cols.size == 0 or measured.size == 0:
        return out
    cost = pairing_cost(model, measured, rel_sd, cols, shapes=shapes, reach=reach)
    big = 1e6
    dummy = np.full((measured.size, measured.size), UNPAIRED)
    rows, picked = linear_sum_assignment(np.hstack([np.where(np.isfinite(cost), cost, big), dummy]))
    for r, c in zip(rows, picked):
        if c < cols.size and np.isfinite(cost[r, c]):
            out[r] = cols[c]
    return out


def shape_refusals(model, measured, index: np.ndarray, rel_sd=None, *, shapes: MeasuredShapes | None = None,
                   reach: np.ndarray | None = None, min_level_db: float = MIN_LEVEL_DB) -> list[dict]:
    """The measured modes left unpaired (``index`` -1, from :func:`pair_modes`) although a model mode
    was within reach, because every such mode's shape was refused: for each, the nearest refused
    model mode (``measured_hz``, ``model_hz``, ``model_gain_db``, ``shape_mismatch`` = 1 - MAC,
    ``coherence`` of the measured shape)."""
    from twin.calibration.sensitivity import MODEL_FORM

    measured = np.asarray(measured, float)
    rel_sd = np.full(measured.size, MODEL_FORM) if rel_sd is None else np.asarray(rel_sd, float)
    cols = candidate_modes(model, min_level_db)
    if shapes is None or cols.size == 0:
        return []
    _, within = _gap(model, measured, rel_sd, cols, reach)
    raw = raw_mismatch(model, shapes, cols)
    no = _refusal(raw, shapes.coherence) & within
    out = []
    for i in np.flatnonzero((np.asarray(index) < 0) & no.any(axis=1)):
        jj = np.flatnonzero(no[i])
        jj = jj[np.argmin(np.abs(np.log(measured[i] / model.frequency[cols[jj]])))]
        j = int(cols[jj])
        out.append({"measured_hz": float(measured[i]), "model_hz": float(model.frequency[j]),
                    "model_gain_db": float(model.gain_db[j]), "shape_mismatch": float(raw[i, jj]),
                    "coherence": float(shapes.coherence[i])})
    return out


def check_pairing(pairing: str) -> str:
    """``pairing`` if it is one of :data:`PAIRINGS`; ValueError naming it otherwise."""
    if pairing not in PAIRINGS:
        raise ValueError(f"unknown pairing {pairing!r} (expected one of: {', '.join(PAIRINGS)})")
    return pairing


def pair_by_frequency(model, measured, rel_sd=None, shapes: MeasuredShapes | None = None) -> np.ndarray:
    """Index of the visible model mode paired with each measured mode by frequency alone, -1 where
    none is within :data:`MATCH_REACH` (the default rule; see the module docstring); with the
    measured modes' struck levels (``shapes.side_db``) never across shafts (:func:`side_refused`)."""
    from twin.calibration.sensitivity import MODEL_FORM

    measured = np.asarray(measured, float)
    rel_sd = np.full(measured.size, MODEL_FORM) if rel_sd is None else np.asarray(rel_sd, float)
    idx = np.flatnonzero(model.visible)
    out = np.full(measured.size, -1, dtype=int)
    if idx.size == 0 or measured.size == 0:
        return out
    dist = np.abs(np.log(model.frequency[idx][None, :] / measured[:, None]))
    big = 1e6
    cost = np.where((dist <= MATCH_REACH) & ~side_refused(model, shapes, idx), dist / rel_sd[:, None], big)
    # dummy columns: leaving a measured mode unpaired costs as much as twice the reach
    dummy = np.full((measured.size, measured.size), MATCH_REACH / rel_sd.min() * 2)
    rows, cols = linear_sum_assignment(np.hstack([cost, dummy]))
    for r, c in zip(rows, cols):
        if c < idx.size and cost[r, c] < big:
            out[r] = idx[c]
    return out
