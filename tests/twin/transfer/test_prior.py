"""The class-prior match: hand-computable offsets, the constraint it solves, its bounds and errors,
and the two diagnostics of what it did (windows moved, confidence lost)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.transfer import AssessorError
from twin.transfer.prior import (LOG_WEIGHT_LIMIT, apply_log_weights, confidence_drop, expected_stage,
                                 match_class_prior, ordinal_anchors, ordinal_probabilities, stage_moves)


def test_identical_windows_give_the_hand_computed_offsets():
    # every window says (0.8, 0.2); a uniform prior needs w1 / w0 = 4, i.e. log w = (-ln 2, +ln 2)
    p = np.tile([0.8, 0.2], (5, 1))
    log_w = match_class_prior(p, np.array([0.5, 0.5]))
    np.testing.assert_allclose(log_w, [-math.log(2), math.log(2)], atol=1e-6)
    np.testing.assert_allclose(apply_log_weights(p, log_w), 0.5, atol=1e-6)


def test_probabilities_that_already_match_need_no_offsets():
    p = np.array([[0.9, 0.1, 0.0], [0.1, 0.8, 0.1], [0.0, 0.1, 0.9]])
    np.testing.assert_allclose(match_class_prior(p, np.full(3, 1 / 3)), 0.0, atol=1e-12)


def test_the_reweighted_mean_equals_a_non_uniform_prior():
    rng = np.random.default_rng(0)
    p = rng.dirichlet([0.5, 1.0, 2.0, 0.7], size=200)
    prior = np.array([0.4, 0.3, 0.2, 0.1])
    log_w = match_class_prior(p, prior, tol=1e-9)
    q = apply_log_weights(p, log_w)
    np.testing.assert_allclose(q.sum(1), 1.0)
    np.testing.assert_allclose(q.mean(0), prior, atol=1e-8)
    assert abs(log_w.mean()) < 1e-9
    # the ranking within a stage is kept: only the boundaries between stages move
    assert np.array_equal(np.argsort(q[:, 0]), np.argsort(p[:, 0] / (p * np.exp(log_w)).sum(1)))


def test_a_stage_the_data_never_show_gets_a_bounded_weight():
    p = np.array([[0.5, 0.5, 0.0], [0.4, 0.6, 0.0]])
    log_w = match_class_prior(p, np.full(3, 1 / 3), max_iter=200)
    assert np.all(np.isfinite(log_w)) and np.max(np.abs(log_w)) <= LOG_WEIGHT_LIMIT
    assert log_w[2] == LOG_WEIGHT_LIMIT


@pytest.mark.parametrize("p, prior, match", [
    (np.ones((3, 2)) / 2, np.array([0.5, 0.3, 0.2]), r"\(3, 2\) and \(3,\)"),
    (np.array([[0.5, np.nan]]), np.array([0.5, 0.5]), "finite"),
    (np.ones((3, 2)) / 2, np.array([1.0, 0.0]), r"\[1.0, 0.0\]"),
    (np.ones((3, 2)) / 2, np.array([0.5, 0.6]), r"sum to 1"),
])
def test_bad_inputs_are_named(p, prior, match):
    with pytest.raises(AssessorError, match=match):
        match_class_prior(p, prior)


def test_stage_moves_counts_by_hand():
    # offsets (ln 3, -ln 3) turn (0.4, 0.6) into (0.86, 0.14) but leave (0.05, 0.95) at stage 1
    p = np.array([[0.4, 0.6], [0.05, 0.95], [0.7, 0.3], [0.45, 0.55]])
    counts, moved = stage_moves(p, np.array([math.log(3), -math.log(3)]))
    assert counts.tolist() == [[1, 3], [3, 1]]
    assert moved == 0.5
    counts, moved = stage_moves(p, np.zeros(2))
    assert counts.tolist() == [[1, 3], [1, 3]] and moved == 0.0
    with pytest.raises(AssessorError, match=r"offsets \(K,\) needed"):
        stage_moves(p, np.zeros(3))


def test_confidence_drop_by_hand():
    # (0.8, 0.2) under offsets (-ln 2, +ln 2) becomes (0.5, 0.5): each window loses 0.3 of confidence;
    # (0.1, 0.9) becomes (0.1 / 3.7, 3.6 / 3.7) and gains 3.6 / 3.7 - 0.9
    p = np.array([[0.8, 0.2], [0.8, 0.2], [0.1, 0.9]])
    log_w = np.array([-math.log(2), math.log(2)])
    assert confidence_drop(p, log_w) == pytest.approx((0.3 + 0.3 - (3.6 / 3.7 - 0.9)) / 3, abs=1e-12)
    assert confidence_drop(p, np.zeros(2)) == 0.0
    with pytest.raises(AssessorError, match=r"confidence drop: .*offsets \(K,\) needed"):
        confidence_drop(p, np.zeros(3))


# ---- the ordinal match ------------------------------------------------------------------------
def _onehot_mix(s: np.ndarray, k: int) -> np.ndarray:
    """Probabilities (n, K) whose expected stage is ``s``: mass split between floor(s) and floor(s)+1."""
    lo = np.minimum(np.floor(s).astype(int), k - 2)
    f = s - lo
    p = np.zeros((s.size, k))
    p[np.arange(s.size), lo] = 1 - f
    p[np.arange(s.size), lo + 1] = f
    return p


def test_ordinal_anchors_are_the_hand_computed_quantiles():
    # expected stages 0, 0.25, ..., 2 (9 windows), uniform prior over 3 stages:
    # quantile levels 1/6, 1/3, 1/2, 2/3, 5/6 of 0..2 in steps of 0.25 (linear interpolation)
    s = np.linspace(0.0, 2.0, 9)
    a = ordinal_anchors(_onehot_mix(s, 3), np.full(3, 1 / 3))
    np.testing.assert_allclose(a, np.quantile(s, [1 / 6, 1 / 3, 1 / 2, 2 / 3, 5 / 6]))
    np.testing.assert_allclose(a, [1 / 3, 2 / 3, 1.0, 4 / 3, 5 / 3])
    np.testing.assert_allclose(expected_stage(_onehot_mix(s, 3)), s)


def test_ordinal_stages_split_the_windows_in_the_prior_and_ignore_the_gain():
    """A rig whose damage moves the expected stage by a different amount (any increasing map) is
    read the same: only the order of the windows along the expected stage counts."""
    rng = np.random.default_rng(1)
    true = np.repeat(np.arange(4), 50)
    s_twin = np.clip(true + rng.normal(0, 0.3, true.size), 0, 3)
    s_rig = 3 * (s_twin / 3) ** 2.5                     # the rig's stages 0-2 read low, all in order
    prior = np.full(4, 0.25)
    p_twin, p_rig = _onehot_mix(s_twin, 4), _onehot_mix(s_rig, 4)
    st_twin = ordinal_probabilities(p_twin, ordinal_anchors(p_twin, prior)).argmax(1)
    st_rig = ordinal_probabilities(p_rig, ordinal_anchors(p_rig, prior)).argmax(1)
    assert np.array_equal(st_twin, st_rig)
    assert np.bincount(st_rig, minlength=4).tolist() == [50, 50, 50, 50]
    assert np.mean(st_rig == true) > 0.8
    assert np.mean(p_rig.argmax(1) == true) < 0.6      # the twin's own boundaries fail on the rig


def test_ordinal_probabilities_by_hand():
    # anchors of 2 stages: middle of 0 at 0.2, boundary at 0.5, middle of 1 at 0.9
    a = np.array([0.2, 0.5, 0.9])
    p = _onehot_mix(np.array([0.1, 0.2, 0.35, 0.5, 0.7, 0.9, 1.0]), 2)
    q = ordinal_probabilities(p, a)
    # c = 0 below the first middle; 0.25 half way to the boundary; the boundary itself stays in
    # stage 0 (a window must exceed it) at 0.5 / 0.5; 0.75 half way to the next middle; 1 beyond
    np.testing.assert_allclose(q[:, 1], [0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0])
    np.testing.assert_allclose(q.sum(1), 1.0)
    assert q.argmax(1).tolist() == [0, 0, 0, 0, 1, 1, 1]
    assert np.all(q.max(1) >= 0.5)


def test_ordinal_match_with_tied_anchors_keeps_the_count_rule():
    # most windows saturate at the same expected stage, so quantiles tie
    s = np.array([0.0, 0.1, 2.0, 2.0, 2.0, 2.0])
    p = _onehot_mix(s, 3)
    a = ordinal_anchors(p, np.full(3, 1 / 3))
    assert np.all(np.diff(a) >= 0)
    q = ordinal_probabilities(p, a)
    assert np.all(np.isfinite(q)) and np.allclose(q.sum(1), 1.0)
    assert q.argmax(1).tolist() == (s[:, None] > a[None, 1::2]).sum(1).tolist()


@pytest.mark.parametrize("call, match", [
    (lambda: ordinal_anchors(np.ones((3, 2)) / 2, np.array([0.5, 0.3, 0.2])), r"shape \(2,\)"),
    (lambda: ordinal_anchors(np.array([[0.5, np.nan]]), np.array([0.5, 0.5])), "finite"),
    (lambda: ordinal_anchors(np.ones((3, 2)) / 2, np.array([1.0, 0.0])), r"\[1.0, 0.0\]"),
    (lambda: ordinal_probabilities(np.ones((3, 2)) / 2, np.array([0.2, 0.5])), "3 finite non-decreasing"),
    (lambda: ordinal_probabilities(np.ones((3, 2)) / 2, np.array([0.9, 0.5, 0.2])), r"\[0.9, 0.5, 0.2\]"),
    (lambda: expected_stage(np.ones(4)), r"got shape \(4,\)"),
])
def test_ordinal_bad_inputs_are_named(call, match):
    with pytest.raises(AssessorError, match=match):
        call()
