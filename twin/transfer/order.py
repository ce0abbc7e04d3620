"""The stage order: a check against a physically monotone feature, and the time order of a history.

**Is the order right?**  An assessor can read a rig's stages in the right order or the reverse one
and be just as confident either way (two seeds once did exactly that on a rig the twin did not
generate).  Its labels cannot tell; a feature whose trend with damage is physical can.  Surface
damage makes a gearbox louder: pits and worn flanks raise the transmission error, so the mesh
harmonics and the overall vibration level grow over a run to failure.  :func:`record_features`
measures both per record, from the signal the assessor reads:

* ``level`` -- the log RMS of the record (the band the assessor sees);
* ``mesh`` -- the log energy at the first :data:`MESH_HARMONICS` harmonics of the tooth-mesh
  frequency, whose position is read from the record's own spectrum near the nominal one (a rig's
  speed is off its command by a per cent or so).

:func:`feature_trends` gives each feature's rank correlation with the stage in the twin's archive
(the twin's own trend, and its sign); :func:`check_order` then correlates the same feature with the
stages assessed on the rig.  The verdict is ``"consistent"`` when the assessed stages rise where the
twin's feature rises, ``"reversed"`` when they fall (significantly), and ``"unconfirmed"`` when the
feature does not order the rig's records either way.  A constant sensor gain leaves rank
correlations within one rig unchanged; a gain that scatters from record to record by a few per cent
is far below the two- to fivefold change of the level over a test.

**The time order.**  Damage does not heal: in a run-to-failure history, a later record is at the
same stage or a later one.  :func:`monotone_stages` finds the non-decreasing stage sequence with the
highest joint probability under the assessor's per-record stage probabilities (dynamic programming,
O(n K^2)).  It uses the order of the records only, no time scale, and no assumption on how many
records each stage has.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["FEATURES", "MESH_HARMONICS", "OrderCheck", "check_order", "feature_trends", "monotone_stages",
           "record_features", "time_order"]

FEATURES = ("level", "mesh")
MESH_HARMONICS = 8
PINION_TEETH = 19
# A verdict needs a rank correlation this far from zero and a two-sided p below ORDER_P.
ORDER_MIN_RHO = 0.3
ORDER_P = 0.01


def _mesh_energy(x: np.ndarray, fs: float, mesh_hz: float, harmonics: int) -> float:
    """Log energy at the first ``harmonics`` mesh harmonics of ``x`` (n,) sampled at ``fs`` [Hz].

    The mesh frequency is taken at the strongest line within +-5 % of ``mesh_hz`` (the record's
    true speed is off its command); each harmonic's energy is summed over +-1.5 % of its frequency.
    """
    n = x.size
    spec = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(n))) ** 2
    f = np.fft.rfftfreq(n, 1.0 / fs)
    near = (f > 0.95 * mesh_hz) & (f < 1.05 * mesh_hz)
    f1 = float(f[near][np.argmax(spec[near])]) if near.any() else mesh_hz
    total = 0.0
    for m in range(1, harmonics + 1):
        band = np.abs(f - m * f1) <= 0.015 * m * f1
        if m * f1 * 1.015 >= fs / 2 or not band.any():
            break
        total += float(spec[band].sum())
    return float(np.log(total + 1e-300))


def record_features(signals: Sequence[np.ndarray], sample_rate: float, shaft_speed: float,
                    teeth: int = PINION_TEETH, harmonics: int = MESH_HARMONICS) -> dict[str, np.ndarray]:
    """The monotone features of each record (module docstring).

    Parameters
    ----------
    signals : sequence of ndarray (n_i,)
        One acceleration signal per record, at ``sample_rate`` [Hz].
    shaft_speed : float
        Nominal pinion speed [Hz]; the mesh frequency is ``teeth x shaft_speed``.

    Returns
    -------
    dict: feature name -> ndarray (n_records,)
    """
    level, mesh = [], []
    for x in signals:
        x = np.asarray(x, dtype=np.float64)
        level.append(0.5 * float(np.log(np.mean((x - x.mean()) ** 2) + 1e-300)))
        mesh.append(_mesh_energy(x, sample_rate, teeth * shaft_speed, harmonics))
    return {"level": np.array(level), "mesh": np.array(mesh)}


def _spearman(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    from scipy.stats import spearmanr
    if np.ptp(a) == 0 or np.ptp(b) == 0 or a.size < 3:
        return 0.0, 1.0
    r = spearmanr(a, b)
    return float(r.statistic), float(r.pvalue)


def feature_trends(features: dict[str, np.ndarray], stages: np.ndarray) -> dict[str, float]:
    """Rank correlation of each feature with the stage over the twin's archive records."""
    s = np.asarray(stages, dtype=float)
    return {name: _spearman(np.asarray(v, float), s)[0] for name, v in features.items()}


@dataclass(frozen=True)
class OrderCheck:
    """How the assessed stages follow a physically monotone feature on the rig.

    Attributes
    ----------
    feature : str
        The feature used: the one with the strongest trend in the twin's archive.
    twin_trend : float
        Its rank correlation with the stage in the archive (the twin's own trend).
    rig_trend : float
        Its rank correlation with the assessed expected stage over the rig's records.
    p_value : float
        Two-sided p of ``rig_trend``.
    verdict : {"consistent", "reversed", "unconfirmed"}
    trends : dict
        ``rig_trend`` of every feature, for the report.
    """

    feature: str
    twin_trend: float
    rig_trend: float
    p_value: float
    verdict: str
    trends: dict

    def message(self) -> str:
        """One plain sentence for the user."""
        base = (f"{self.feature} feature: rank correlation {self.twin_trend:+.2f} with the stage in the twin's "
                f"archive, {self.rig_trend:+.2f} with the assessed stage on these records (p {self.p_value:.2g})")
        if self.verdict == "consistent":
            return f"stage order consistent with the {base}"
        if self.verdict == "reversed":
            return (f"STAGE ORDER REVERSED: the assessed stages fall where the twin's damage trend rises ({base}); "
                    "the assessment reads these records in the wrong order and must not be used")
        return (f"stage order unconfirmed: the {base}; nothing here confirms that the assessed stages increase "
                "with the damage")

    def to_dict(self) -> dict:
        return {"feature": self.feature, "twin_trend": self.twin_trend, "rig_trend": self.rig_trend,
                "p_value": self.p_value, "verdict": self.verdict, "trends": dict(self.trends),
                "message": self.message()}


def check_order(features: dict[str, np.ndarray], expected_stage: np.ndarray, twin_trends: dict[str, float]
                ) -> OrderCheck:
    """Compare the assessed stages with the twin's feature trends (module docstring).

    Parameters
    ----------
    features : dict name -> ndarray (n,)
        :func:`record_features` of the rig's records.
    expected_stage : ndarray (n,)
        The assessed expected stage of each record (``sum_k k p_k``).
    twin_trends : dict name -> float
        :func:`feature_trends` of the twin's archive.

    Raises
    ------
    AssessorError
        No feature in common, or arrays of other lengths.
    """
    names = [n for n in twin_trends if n in features]
    if not names:
        raise AssessorError(f"order check: no feature in common between the twin's trends {sorted(twin_trends)} "
                            f"and the records' {sorted(features)}")
    e = np.asarray(expected_stage, dtype=float)
    for n in names:
        if np.shape(features[n]) != e.shape:
            raise AssessorError(f"order check: feature '{n}' has shape {np.shape(features[n])}, the stages {e.shape}")
    best = max(names, key=lambda n: abs(twin_trends[n]))
    trends = {n: _spearman(np.asarray(features[n], float), e)[0] for n in names}
    rho, p = _spearman(np.asarray(features[best], float), e)
    sign = np.sign(twin_trends[best])
    if sign != 0 and p < ORDER_P and abs(rho) >= ORDER_MIN_RHO:
        verdict = "consistent" if np.sign(rho) == sign else "reversed"
    else:
        verdict = "unconfirmed"
    return OrderCheck(best, float(twin_trends[best]), rho, p, verdict, trends)


def monotone_stages(probabilities: np.ndarray, floor: float = 1e-3) -> np.ndarray:
    """The non-decreasing stage sequence of highest joint probability (module docstring).

    Parameters
    ----------
    probabilities : ndarray (n, K)
        Stage probabilities of ``n`` records in time order.
    floor : float
        Added to every probability before the log, so one confident mistake cannot veto a sequence.

    Returns
    -------
    ndarray (n,) of int, non-decreasing.
    """
    p = np.asarray(probabilities, dtype=float)
    if p.ndim != 2 or p.shape[0] == 0 or p.shape[1] < 1:
        raise AssessorError(f"monotone_stages: probabilities must be (n, K) with n >= 1, got shape {p.shape}")
    logp = np.log(p + floor)
    n, k = logp.shape
    score = np.empty((n, k))
    back = np.zeros((n, k), dtype=np.int64)
    score[0] = logp[0]
    for i in range(1, n):
        # best previous stage <= k: a running maximum over the previous scores
        best_prev = np.maximum.accumulate(score[i - 1])
        arg = np.zeros(k, dtype=np.int64)
        for j in range(1, k):
            arg[j] = arg[j - 1] if score[i - 1, arg[j - 1]] >= score[i - 1, j] else j
        score[i] = logp[i] + best_prev
        back[i] = arg
    out = np.empty(n, dtype=np.int64)
    out[-1] = int(np.argmax(score[-1]))
    for i in range(n - 1, 0, -1):
        out[i - 1] = back[i, out[i]]
    return out


def time_order(records) -> tuple[np.ndarray | None, str]:
    """The time order of records, from their ``time_start`` [s] or ``cycles`` attribute.

    Returns
    -------
    (order, how): ``order`` (n,) indices that sort the records in time, or ``None`` when the
    records carry no time (all ``time_start`` equal and no ``cycles``); ``how`` says which.
    """
    recs = list(records)
    cycles = [(r.metadata or {}).get("cycles") for r in recs]
    if recs and all(c is not None for c in cycles):
        return np.argsort(np.asarray(cycles, dtype=float), kind="stable"), "cycles"
    starts = np.array([float(r.time_start) for r in recs])
    if recs and np.unique(starts).size == len(recs):
        return np.argsort(starts, kind="stable"), "time_start"
    return None, "no time stamps"
