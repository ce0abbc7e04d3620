"""Matching the assessor's stage proportions on the rig to the twin's (a label-proportion prior).

After adaptation the classifier still carries the twin's decision boundaries.  Where a rig moves
a stage's records towards its neighbour's (its resonances weight the level differently, say), the
boundary cuts into that stage, and the rig's adaptation windows are assessed as too many of one
stage and too few of the other.  If the rig's adaptation data cover the stages in the twin's
proportions -- the assumption the domain normalisation (:mod:`twin.transfer.preprocess`, step 5)
and MMD alignment already make -- that imbalance is a measurable symptom of the shifted boundary.

:func:`match_class_prior` finds per-stage weights ``w`` (K,) such that the re-weighted
probabilities ``q_ik = p_ik w_k / sum_j p_ij w_j`` of the unlabelled adaptation windows average to
the prior ``pi``.  It is the fixed point of the EM prior adjustment of Saerens, Latinne & Decaestecker
(Neural Computation 14, 2002), run with the target prior held fixed instead of estimated: each
iteration sets ``w_k <- w_k pi_k / mean_i q_ik``.  Multiplying probabilities by ``w`` is adding
``log w`` to the logits, i.e. moving the boundaries, not retraining anything.

It reads no target label.  It does rely on the proportions: on rig data dominated by one stage
(a run-to-failure history that is mostly healthy) switch it off (``Assessor(class_prior=None)``).

:func:`confidence_drop` tells the two cases apart after the fact.  A rig that shifts a boundary
leaves windows near it that the classifier is unsure of, and the match moves those: the mean
confidence barely changes.  Rig data whose stage mix differs from the prior (or that do not fall
into the twin's stages at all) hold stages the classifier reads confidently in the "wrong"
proportions, and the match can only meet the prior by pushing confident windows over a boundary:
the mean confidence falls.  On the benchmark's rigs (BENCHMARKS.md, stop 20; 54 runs) the first
case cost at most 1.9 points of mean confidence and the second at least 5.3.
"""
from __future__ import annotations

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["LOG_WEIGHT_LIMIT", "apply_log_weights", "confidence_drop", "match_class_prior", "stage_moves"]

# A stage the adaptation data hardly show would need an unbounded weight; e^8 ~ 3000 is far past any
# boundary shift seen on the benchmark rigs (|log w| <= 3.2) and keeps the correction finite.
LOG_WEIGHT_LIMIT = 8.0


def apply_log_weights(proba: np.ndarray, log_weights: np.ndarray) -> np.ndarray:
    """``proba`` (n, K) re-weighted by ``exp(log_weights)`` (K,) and renormalised, shape (n, K)."""
    q = proba * np.exp(log_weights - np.max(log_weights))
    return q / q.sum(axis=1, keepdims=True)


def match_class_prior(proba: np.ndarray, prior: np.ndarray, *, tol: float = 1e-6,
                      max_iter: int = 1000) -> np.ndarray:
    """Log weights (K,) that make the mean re-weighted probability of ``proba`` equal ``prior``.

    Parameters
    ----------
    proba : ndarray (n, K)
        Stage probabilities of the unlabelled adaptation windows (rows sum to 1).
    prior : ndarray (K,)
        Wanted stage proportions (> 0, summing to 1), e.g. the twin's window proportions.
    tol : float
        Stop when every mean proportion is within ``tol`` of ``prior``.
    max_iter : int
        Iteration cap; the log weights are also bounded by :data:`LOG_WEIGHT_LIMIT`.

    Returns
    -------
    ndarray (K,)
        ``log w``, centred on 0 (only differences between stages matter) and within
        +- :data:`LOG_WEIGHT_LIMIT`.

    Raises
    ------
    AssessorError
        Shapes that do not match, non-finite or negative probabilities, a prior that is not a
        distribution with every stage > 0.
    """
    p = np.asarray(proba, dtype=np.float64)
    pi = np.asarray(prior, dtype=np.float64)
    if p.ndim != 2 or p.shape[0] < 1 or pi.shape != (p.shape[1],):
        raise AssessorError(f"class prior: probabilities (n, K) and a prior (K,) needed, got {p.shape} and {pi.shape}")
    if not np.all(np.isfinite(p)) or np.any(p < 0):
        raise AssessorError("class prior: probabilities must be finite and >= 0")
    if not np.all(np.isfinite(pi)) or np.any(pi <= 0) or not np.isclose(pi.sum(), 1.0, atol=1e-9):
        raise AssessorError(f"class prior: the prior must be > 0 for every stage and sum to 1, got {pi.tolist()}")
    p = np.maximum(p, 1e-300)
    log_w = np.zeros(p.shape[1])
    for _ in range(max_iter):
        mean = apply_log_weights(p, log_w).mean(axis=0)
        if np.max(np.abs(mean - pi)) < tol:
            break
        log_w = log_w + np.log(pi / mean)
        log_w = np.clip(log_w - log_w.mean(), -LOG_WEIGHT_LIMIT, LOG_WEIGHT_LIMIT)
    return log_w


def _windows_and_offsets(what: str, proba, log_weights) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(proba, dtype=np.float64)
    w = np.asarray(log_weights, dtype=np.float64)
    if p.ndim != 2 or p.shape[0] < 1 or w.shape != (p.shape[1],):
        raise AssessorError(f"{what}: probabilities (n, K) and offsets (K,) needed, got {p.shape} and {w.shape}")
    return p, w


def stage_moves(proba: np.ndarray, log_weights: np.ndarray) -> tuple[np.ndarray, float]:
    """How the offsets re-assess windows: counts per stage without and with them, and the share moved.

    Parameters
    ----------
    proba : ndarray (n, K)
        Stage probabilities of the windows, without offsets.
    log_weights : ndarray (K,)
        The offsets (:func:`match_class_prior`).

    Returns
    -------
    counts : ndarray (2, K) of int
        Windows assessed as each stage without (row 0) and with (row 1) the offsets.
    moved : float
        Share of the windows whose stage the offsets change, in [0, 1].
    """
    p, w = _windows_and_offsets("stage moves", proba, log_weights)
    before, after = p.argmax(1), apply_log_weights(p, w).argmax(1)
    k = p.shape[1]
    return np.stack([np.bincount(before, minlength=k), np.bincount(after, minlength=k)]), float(np.mean(before != after))


def confidence_drop(proba: np.ndarray, log_weights: np.ndarray) -> float:
    """How much the offsets lower the windows' mean confidence (largest stage probability).

    ``proba`` (n, K) and ``log_weights`` (K,) as in :func:`stage_moves`.

    Returns
    -------
    float
        ``mean_i max_k p_ik - mean_i max_k q_ik`` with ``q`` the re-weighted probabilities, in
        (-1, 1); positive when the offsets make the windows less certain.
    """
    p, w = _windows_and_offsets("confidence drop", proba, log_weights)
    return float(p.max(axis=1).mean() - apply_log_weights(p, w).max(axis=1).mean())
