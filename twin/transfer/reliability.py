"""How far to trust an assessment of rig data without labels: the agreement of independent fits.

A rig's stages are unknown; that is why the assessor exists.  So on a rig whose physics the twin
does not share, nothing in one assessor's output says whether its stages are right: on the LTCA
simulator (BENCHMARKS.md) the assessors read pitting at chance with a mean confidence of
0.77, and the class-prior warning fired on one run in five.

What can be measured without labels is whether assessors that differ only in their seed (their
initialisation, batches and augmentation) give the rig's windows the same stage.  That has a bound
that needs no assumption.  Two assessors that are both right on a window agree on it, so with
window accuracies ``a1`` and ``a2`` on the same windows and agreement ``g``,

    a1 + a2 - 1  <=  P(both right)  <=  g,    i.e.  (a1 + a2) / 2  <=  (1 + g) / 2.

Averaged over every pair of ``m`` assessors (each one is in ``m - 1`` pairs), the members' mean
window accuracy is at most ``(1 + mean pairwise agreement) / 2``.  The bound is tight when every
disagreement has exactly one member right; it says nothing when the members agree and are all wrong
in the same way, which a rig can also do (on the LTCA rig five seeds agreed on 71 % of the
pitting windows and were right on 20 %).  Low agreement is therefore a proof of unreliability, high
agreement is not a proof of the opposite.

Measured on the benchmark's rigs (2026-11-24, docs/transfer.md; the proposed method with each task's
class-prior rule, 5 seeds for pitting and 3 for wear, target test windows): on the emulated rigs,
where the members read 93-98 % of the windows right, they agreed on 94-97 % of them; on the two
simulators that are not the twin, where they read 20-79 %, on 65-84 %.
"""
from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["Agreement", "agreement", "assessor_agreement", "mean_agreement", "pairwise_agreement"]


@dataclass(frozen=True)
class Agreement:
    """Stage agreement of ``n_assessors`` assessments of the same records.

    Attributes
    ----------
    n_assessors, n_records, n_windows : int
    window_agreement : float
        Mean over pairs of assessors of the share of windows given the same stage, in [0, 1].
    record_agreement : float
        The same for the records' stages (arg-max of the mean window probability).
    accuracy_bound : float
        ``(1 + window_agreement) / 2``: the members' mean window accuracy cannot exceed it, whatever
        the true stages are (module docstring).
    pairwise : tuple of tuple of float
        Window agreement of every pair, shape (n_assessors, n_assessors), ones on the diagonal.
    per_record : tuple of float
        Mean pairwise window agreement within each record, shape (n_records,): where the members
        part ways.
    record_names : tuple of str
        The records, in the order of ``per_record``.
    """

    n_assessors: int
    n_records: int
    n_windows: int
    window_agreement: float
    record_agreement: float
    accuracy_bound: float
    pairwise: tuple
    per_record: tuple
    record_names: tuple

    def to_dict(self) -> dict:
        return {"n_assessors": self.n_assessors, "n_records": self.n_records, "n_windows": self.n_windows,
                "window_agreement": self.window_agreement, "record_agreement": self.record_agreement,
                "accuracy_bound": self.accuracy_bound, "pairwise": [list(r) for r in self.pairwise],
                "records": [{"name": n, "window_agreement": g} for n, g in zip(self.record_names, self.per_record)]}


def pairwise_agreement(stages) -> np.ndarray:
    """Share of items given the same stage by each pair of members.

    Parameters
    ----------
    stages : array-like (m, n) of int
        Stage of each of ``n`` items (windows) by each of ``m >= 2`` members (assessors), the
        items in the same order for every member.

    Returns
    -------
    ndarray (m, m)
        Symmetric, ones on the diagonal.

    Raises
    ------
    AssessorError
        Fewer than two members, no item, or stages that are not integers.
    """
    s = np.asarray(stages)
    if s.ndim != 2 or s.shape[0] < 2 or s.shape[1] < 1:
        raise AssessorError(f"agreement: stages of at least 2 members on at least 1 window needed, "
                            f"as an array (m, n); got shape {s.shape}")
    if not np.issubdtype(s.dtype, np.integer):
        raise AssessorError(f"agreement: stages must be integers, got dtype {s.dtype}")
    g = np.ones((s.shape[0], s.shape[0]))
    for i, j in itertools.combinations(range(s.shape[0]), 2):
        g[i, j] = g[j, i] = float(np.mean(s[i] == s[j]))
    return g


def _mean_off_diagonal(g: np.ndarray) -> float:
    m = g.shape[0]
    return float((g.sum() - m) / (m * (m - 1)))


def mean_agreement(stages) -> float:
    """Mean over pairs of members of the share of items given the same stage, in [0, 1].

    ``stages`` (m, n) as in :func:`pairwise_agreement`.  ``(1 + mean_agreement) / 2`` bounds the
    members' mean accuracy on those items (module docstring).
    """
    return _mean_off_diagonal(pairwise_agreement(stages))


def agreement(assessments: Sequence) -> Agreement:
    """How often assessments of the same records agree, window by window and record by record.

    Parameters
    ----------
    assessments : sequence of :class:`twin.transfer.assessor.Assessment`
        At least two, from assessors trained independently (another ``seed``; the same seed on the
        same data is the same network) and applied to the same records with the same
        preprocessing, so the records and their windows line up.

    Raises
    ------
    AssessorError
        Fewer than two assessments, or assessments whose stage counts, records or window counts
        differ (the message names the first one that does not line up with the first).
    """
    items = list(assessments)
    if len(items) < 2:
        raise AssessorError(f"agreement: at least 2 assessments needed, got {len(items)}")
    first = items[0]
    names = tuple(r.name for r in first.records)
    counts = tuple(len(r.window_stages) for r in first.records)
    for i, a in enumerate(items[1:], start=1):
        if a.n_stages != first.n_stages:
            raise AssessorError(f"agreement: assessment {i} has {a.n_stages} stages, assessment 0 has "
                                f"{first.n_stages}")
        other = tuple(r.name for r in a.records)
        if other != names:
            k = next((k for k, (x, y) in enumerate(zip(names, other)) if x != y), min(len(names), len(other)))
            ours, theirs = (names[k] if k < len(names) else "none"), (other[k] if k < len(other) else "none")
            raise AssessorError(f"agreement: assessment {i} covers other records than assessment 0 "
                                f"({len(other)} against {len(names)}; record {k} is '{theirs}' against '{ours}')")
        bad = next((r.name for r, n in zip(a.records, counts) if len(r.window_stages) != n), None)
        if bad is not None:
            raise AssessorError(f"agreement: record '{bad}' has another number of windows in assessment {i} "
                                "than in assessment 0 (another preprocessing?)")
    if not names:
        raise AssessorError("agreement: the assessments hold no record")
    windows = np.array([np.concatenate([np.asarray(r.window_stages, dtype=np.int64) for r in a.records])
                        for a in items])
    g = pairwise_agreement(windows)
    edges = np.cumsum((0,) + counts)
    per_record = tuple(mean_agreement(windows[:, lo:hi]) if hi > lo else float("nan")
                       for lo, hi in zip(edges[:-1], edges[1:]))
    records = np.array([[r.stage for r in a.records] for a in items], dtype=np.int64)
    window_agreement = _mean_off_diagonal(g)
    return Agreement(len(items), len(names), int(windows.shape[1]), window_agreement,
                     mean_agreement(records), (1.0 + window_agreement) / 2.0,
                     tuple(tuple(float(v) for v in row) for row in g), per_record, names)


def assessor_agreement(assessors: Sequence, data, names: Sequence[str] | None = None) -> Agreement:
    """Assess ``data`` with each fitted assessor and return how often they agree.

    Parameters
    ----------
    assessors : sequence of fitted :class:`twin.transfer.assessor.Assessor`
        At least two, trained independently (another ``seed``).
    data : path, MeasurementSet or list of Record
        The rig records; no label needed.
    names : sequence of str, optional
        What to call the assessors in messages (their directories, say); default "assessor i".

    Raises
    ------
    AssessorError
        Fewer than two assessors, one that is not fitted, or two that hold the same network (identical weights: ``fit`` is
        deterministic, so the same settings, seed and data give the same network, and their
        agreement of 1 says nothing), named by their position; or assessments that do not line up
        (:func:`agreement`).
    """
    import torch

    items = list(assessors)
    if len(items) < 2:
        raise AssessorError(f"agreement: at least 2 assessors needed, got {len(items)}")
    names = [f"assessor {i}" for i in range(len(items))] if names is None else [f"'{n}'" for n in names]
    if len(names) != len(items):
        raise AssessorError(f"agreement: {len(names)} names for {len(items)} assessors")
    unfitted = [n for a, n in zip(items, names) if getattr(a, "network_", None) is None]
    if unfitted:
        raise AssessorError(f"agreement: {unfitted[0]} is not a fitted assessor (call fit, or Assessor.load)")
    weights = [a.network_.state_dict() for a in items]
    for i, j in itertools.combinations(range(len(items)), 2):
        if weights[i].keys() == weights[j].keys() and all(torch.equal(weights[i][k], weights[j][k])
                                                          for k in weights[i]):
            raise AssessorError(f"agreement: {names[i]} and {names[j]} hold the same network (the same settings, seed "
                                "and data), so their agreement says nothing; train another with a different seed")
    return agreement([a.assess(data) for a in items])
