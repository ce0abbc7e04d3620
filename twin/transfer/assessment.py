"""The assessor's verdicts: one record's stage with its confidences, and a set of records with the
accuracies when every record is labelled (returned by :meth:`twin.transfer.Assessor.assess`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.transfer.errors import AssessorError


@dataclass(frozen=True)
class RecordAssessment:
    """The verdict on one record.

    Attributes
    ----------
    name : str
    stage : int
        Stage with the highest mean window probability.
    confidence : float
        That mean probability, in [0, 1].
    probabilities : tuple of float
        Mean window probability of every stage, shape (K,).
    window_stages : tuple of int
        Stage of each window, shape (n_windows,).
    window_confidences : tuple of float
        Probability of each window's stage, shape (n_windows,).
    label : int or None
        The record's label if it has one (for evaluation only).
    """

    name: str
    stage: int
    confidence: float
    probabilities: tuple
    window_stages: tuple
    window_confidences: tuple
    label: int | None = None

    def to_dict(self) -> dict:
        return {"name": self.name, "stage": self.stage, "confidence": self.confidence,
                "probabilities": list(self.probabilities), "label": self.label,
                "windows": [{"index": i, "stage": s, "confidence": c}
                            for i, (s, c) in enumerate(zip(self.window_stages, self.window_confidences))]}


@dataclass(frozen=True)
class Assessment:
    """Verdicts on a set of records plus, when every record is labelled, the accuracies."""

    records: tuple
    n_stages: int
    record_accuracy: float | None
    window_accuracy: float | None

    def window_verdicts(self) -> tuple[np.ndarray, np.ndarray]:
        """(true stage, assessed stage) of every window, record by record, shape (n_windows,) each.

        Raises
        ------
        AssessorError
            A record without a label.
        """
        unlabelled = [r.name for r in self.records if r.label is None]
        if unlabelled:
            raise AssessorError(f"window_verdicts: record(s) {unlabelled[:5]} have no label")
        true = np.concatenate([np.full(len(r.window_stages), r.label, dtype=np.int64) for r in self.records])
        assessed = np.concatenate([np.asarray(r.window_stages, dtype=np.int64) for r in self.records])
        return true, assessed

    def to_dict(self) -> dict:
        return {"n_stages": self.n_stages, "record_accuracy": self.record_accuracy,
                "window_accuracy": self.window_accuracy, "records": [r.to_dict() for r in self.records]}
