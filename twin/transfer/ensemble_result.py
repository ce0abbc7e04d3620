"""The ensemble's verdict: per record and on a set of records (:meth:`twin.transfer.ensemble.Ensemble.assess`).

::

    res = Ensemble.load("assessor/").assess("rig.h5")      # an EnsembleAssessment
    res.stages, res.verdict(), res.scores(), res.to_dict()

Small frozen records: what the ensemble read (stage, probabilities, each member's stage), how far
the members agree (the bound ``(1 + agreement) / 2`` on their mean accuracy,
:mod:`twin.transfer.reliability`), the stage-order check and the time order, and when the result
is called reliable (:data:`RELIABLE_AGREEMENT`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["EnsembleAssessment", "EnsembleRecord", "RELIABLE_AGREEMENT"]

# The agreement a reliable result needs.  Measured on the project's rigs (BENCHMARKS.md): where the
# members read 93-98 % of the windows right they agreed on 94-97 % of them; where they read 20-79 %
# right, on 65-84 %.  At 0.9 the members' mean accuracy is bounded by 95 % and no measured unreliable
# case passes.
RELIABLE_AGREEMENT = 0.9


@dataclass(frozen=True)
class EnsembleRecord:
    """The ensemble's verdict on one record.

    Attributes
    ----------
    name : str
    stage : int
        Stage of the highest mean probability (before the time order).
    confidence : float
        That probability.
    probabilities : tuple of float (K,)
    expected_stage : float
        ``sum_k k p_k``.
    member_stages : tuple of int (members,)
        Each member's stage for the record.
    agreement : float
        Mean pairwise share of the record's windows two members stage alike.
    ordered_stage : int or None
        Stage under the time order (non-decreasing over the history); None without one.
    label : int or None
        The record's label, for evaluation only.
    """

    name: str
    stage: int
    confidence: float
    probabilities: tuple
    expected_stage: float
    member_stages: tuple
    agreement: float
    ordered_stage: int | None = None
    label: int | None = None

    def to_dict(self) -> dict:
        return {"name": self.name, "stage": self.stage, "confidence": self.confidence,
                "probabilities": list(self.probabilities), "expected_stage": self.expected_stage,
                "member_stages": list(self.member_stages), "agreement": self.agreement,
                "ordered_stage": self.ordered_stage, "label": self.label}


@dataclass(frozen=True)
class EnsembleAssessment:
    """The ensemble's verdict on a set of records.

    Attributes
    ----------
    records : tuple of EnsembleRecord
    n_stages, n_members, n_windows : int
    window_agreement : float
        Mean pairwise share of windows two members stage alike.
    accuracy_bound : float
        ``(1 + window_agreement) / 2``: the members' mean window accuracy cannot exceed it.
    order : OrderCheck
        The stage order against the physically monotone feature.
    time_order : str
        Where the time order came from (``time_start``, ``cycles``), or why there is none.
    moved_by_time_order : int
        Records whose stage the time order changed.
    reliable : bool
        Agreement at least :data:`RELIABLE_AGREEMENT` and a consistent order.
    notes : tuple of str
        What was assumed or done to the records (resampling, missing speeds).
    window_stages : ndarray (n_windows,)
        The ensemble's stage of every window, record by record.
    window_labels : ndarray (n_windows,)
        The records' labels per window, -1 where unknown (evaluation only).
    """

    records: tuple
    n_stages: int
    n_members: int
    n_windows: int
    window_agreement: float
    accuracy_bound: float
    order: object
    time_order: str
    moved_by_time_order: int
    reliable: bool
    notes: tuple = ()
    window_stages: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)
    window_labels: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64), repr=False)

    @property
    def stages(self) -> np.ndarray:
        """The final stage of each record: under the time order where there is one."""
        return np.array([r.stage if r.ordered_stage is None else r.ordered_stage for r in self.records])

    def verdict(self) -> str:
        """A plain sentence on how far to trust the result."""
        why = []
        if self.window_agreement < RELIABLE_AGREEMENT:
            why.append(f"the {self.n_members} members agree on only {100 * self.window_agreement:.1f} % of the "
                       f"windows (at least {100 * RELIABLE_AGREEMENT:.0f} % needed; their mean accuracy is at most "
                       f"{100 * self.accuracy_bound:.1f} %)")
        if self.order.verdict != "consistent":
            why.append(f"the stage order is {self.order.verdict}")
        if not why:
            return (f"reliable: the {self.n_members} members agree on {100 * self.window_agreement:.1f} % of the "
                    "windows and the stages rise with the twin's damage feature (agreement is necessary for "
                    "accuracy, not sufficient)")
        return "NOT RELIABLE: " + "; ".join(why)

    def scores(self) -> dict | None:
        """Exact and within-one-stage accuracy of windows and records when every record has a label."""
        if any(r.label is None for r in self.records):
            return None
        y = np.array([r.label for r in self.records])
        out = {"record_exact": float(np.mean(y == np.array([r.stage for r in self.records]))),
               "record_within_one": float(np.mean(np.abs(y - np.array([r.stage for r in self.records])) <= 1)),
               "window_exact": float(np.mean(self.window_stages == self.window_labels)),
               "window_within_one": float(np.mean(np.abs(self.window_stages - self.window_labels) <= 1))}
        if self.records and self.records[0].ordered_stage is not None:
            s = self.stages
            out["record_exact_time_order"] = float(np.mean(y == s))
            out["record_within_one_time_order"] = float(np.mean(np.abs(y - s) <= 1))
        return out

    def to_dict(self) -> dict:
        return {"n_stages": self.n_stages, "n_members": self.n_members, "n_windows": self.n_windows,
                "window_agreement": self.window_agreement, "accuracy_bound": self.accuracy_bound,
                "order": self.order.to_dict(), "time_order": self.time_order,
                "moved_by_time_order": self.moved_by_time_order, "reliable": self.reliable,
                "verdict": self.verdict(), "notes": list(self.notes), "scores": self.scores(),
                "records": [dict(r.to_dict(), final_stage=int(s)) for r, s in zip(self.records, self.stages)]}
