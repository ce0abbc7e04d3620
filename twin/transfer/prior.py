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
the mean confidence falls.  On the benchmark's rigs (the runs that chose the warning threshold,
2026-11-23; 54 runs) the first case cost at most 1.9 points of mean confidence and the second at
least 5.3.

**The ordinal match** (:func:`ordinal_anchors`, :func:`ordinal_probabilities`; ``class_prior="ordinal"``)
uses the same assumption and one more fact: the stages are ordered.  Each window is reduced to its
expected stage ``s = sum_k k p_k`` under the network's probabilities, and the rig's stage
boundaries are the quantiles of ``s`` over the adaptation windows at the twin's cumulative stage
proportions.  Only the order of the windows along ``s`` matters, not where the twin's boundaries
lie, so a rig whose damage moves the vibration features the same way as the twin's but by a
different amount is read right.  The per-stage offsets above can move each boundary on its own
but keep the twin's scale.  Measured (2026-11-24; pitting, proposed method, seeds 0-4; docs/transfer.md):
the lumped rig, whose stages keep their order (rank correlation 0.8-0.9), goes from 23 % to 59 %; the
LTCA rig, which reads its last stage below its fifth, falls from 26 % to 20 %; the benchmark rigs
stay within their scatter.  The quantiles put exactly the prior's share into each stage, so they
need the adaptation windows balanced more strictly than the offsets do: with the stages off by the
sampling scatter of 180 windows (about +-17 % each) the emulated rigs read 87 % instead of 97 %,
where the offsets lose 2-4 points (docs/experiments.md).
"""
from __future__ import annotations

import numpy as np

from twin.transfer.errors import AssessorError

__all__ = ["LOG_WEIGHT_LIMIT", "apply_log_weights", "confidence_drop", "expected_stage", "match_class_prior",
           "ordinal_anchors", "ordinal_probabilities", "stage_moves"]

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
    p = _check_proba("class prior", proba)
    pi = _check_prior("class prior", p, prior)
    p = np.maximum(p, 1e-300)
    log_w = np.zeros(p.shape[1])
    for _ in range(max_iter):
        mean = apply_log_weights(p, log_w).mean(axis=0)
        if np.max(np.abs(mean - pi)) < tol:
            break
        log_w = log_w + np.log(pi / mean)
        log_w = np.clip(log_w - log_w.mean(), -LOG_WEIGHT_LIMIT, LOG_WEIGHT_LIMIT)
    return log_w


def _check_proba(what: str, proba) -> np.ndarray:
    p = np.asarray(proba, dtype=np.float64)
    if p.ndim != 2 or p.shape[0] < 1:
        raise AssessorError(f"{what}: probabilities (n, K) with n >= 1 needed, got shape {p.shape}")
    if not np.all(np.isfinite(p)) or np.any(p < 0):
        raise AssessorError(f"{what}: probabilities must be finite and >= 0")
    return p


def _check_prior(what: str, p: np.ndarray, prior) -> np.ndarray:
    """``prior`` as an array (K,) for probabilities ``p`` (n, K): finite, every stage > 0, sum 1."""
    pi = np.asarray(prior, dtype=np.float64)
    if pi.shape != (p.shape[1],):
        raise AssessorError(f"{what}: probabilities (n, K) and a prior of shape ({p.shape[1]},) needed, "
                            f"got {p.shape} and {pi.shape}")
    if not np.all(np.isfinite(pi)) or np.any(pi <= 0) or not np.isclose(pi.sum(), 1.0, atol=1e-9):
        raise AssessorError(f"{what}: the prior must be > 0 for every stage and sum to 1, got {pi.tolist()}")
    return pi


def expected_stage(proba: np.ndarray) -> np.ndarray:
    """The expected stage ``sum_k k p_k`` of each window, shape (n,), in [0, K - 1].

    ``proba`` (n, K): stage probabilities (rows sum to 1).
    """
    return _expected(_check_proba("expected stage", proba))


def _expected(p: np.ndarray) -> np.ndarray:
    return p @ np.arange(p.shape[1], dtype=np.float64)


def ordinal_anchors(proba: np.ndarray, prior: np.ndarray) -> np.ndarray:
    """Where the rig's stages lie along the expected stage, fitted on unlabelled adaptation windows.

    Parameters
    ----------
    proba : ndarray (n, K)
        Stage probabilities of the adaptation windows, as the network gives them (no offsets).
    prior : ndarray (K,)
        The stage proportions the windows are assumed to cover (> 0, summing to 1).

    Returns
    -------
    ndarray (2K - 1,)
        Quantiles of the expected stage at the cumulative proportions ``pi_0 / 2, pi_0,
        pi_0 + pi_1 / 2, ...``: entry ``2k`` is the middle of stage k and entry ``2k + 1`` the
        boundary between stages k and k + 1.  Non-decreasing.

    Raises
    ------
    AssessorError
        Shapes that do not match, non-finite or negative probabilities, a prior that is not a
        distribution with every stage > 0.
    """
    p = _check_proba("ordinal match", proba)
    pi = _check_prior("ordinal match", p, prior)
    upper = np.cumsum(pi)
    levels = np.empty(2 * pi.size - 1)
    levels[0::2] = upper - pi / 2
    levels[1::2] = upper[:-1]
    return np.maximum.accumulate(np.quantile(_expected(p), np.clip(levels, 0.0, 1.0)))


def ordinal_probabilities(proba: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """Stage probabilities of windows under the ordinal match, shape (n, K).

    A window's stage is the number of boundaries (``anchors[1::2]``) its expected stage exceeds.
    Its position between the anchors, mapped piecewise linearly onto the stage axis (middles to
    0, 1, ..., boundaries to 0.5, 1.5, ...), gives the matched stage coordinate ``c``; the
    probability is split between the two stages nearest to ``c`` in proportion to its distance
    from them.  So the arg-max is the window's stage, the confidence (in [0.5, 1]) says how far
    the window lies from the nearest boundary, and the mean stage of the probabilities is ``c``.

    Parameters
    ----------
    proba : ndarray (n, K)
        Stage probabilities as the network gives them.
    anchors : ndarray (2K - 1,)
        From :func:`ordinal_anchors`.
    """
    p = _check_proba("ordinal match", proba)
    k = p.shape[1]
    a = np.asarray(anchors, dtype=np.float64)
    if a.shape != (2 * k - 1,) or not np.all(np.isfinite(a)) or np.any(np.diff(a) < 0):
        raise AssessorError(f"ordinal match: {2 * k - 1} finite non-decreasing anchors needed, got {a.tolist()}")
    s = _expected(p)
    stage = (s[:, None] > a[None, 1::2]).sum(axis=1)
    # piecewise-linear map; a zero-width segment (tied quantiles) takes its upper end
    i = np.clip(np.searchsorted(a, s, side="right") - 1, 0, a.size - 2)
    width = a[i + 1] - a[i]
    frac = np.clip(np.divide(s - a[i], width, out=np.ones_like(s), where=width > 0), 0.0, 1.0)
    c = np.clip((i + frac) / 2.0, stage - 0.5, stage + 0.5)
    c = np.clip(c, 0.0, k - 1.0)
    dist = np.abs(c - stage)
    # a window exactly on its lower boundary would tie with the stage below; the stage it has wins
    dist = np.where((c < stage) & (dist >= 0.5), 0.5 - 1e-9, dist)
    out = np.zeros_like(p)
    rows = np.arange(p.shape[0])
    out[rows, stage] = 1.0 - dist
    other = np.clip(np.where(c >= stage, stage + 1, stage - 1), 0, k - 1)
    out[rows, other] += dist
    return out


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
