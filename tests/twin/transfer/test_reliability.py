"""Seed agreement on unlabelled data and the accuracy bound it gives (twin.transfer.reliability)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.transfer.assessor import Assessment, RecordAssessment
from twin.transfer.errors import AssessorError
from twin.transfer.reliability import agreement, mean_agreement, pairwise_agreement


def _assessment(windows_by_record, labels=None, n_stages=3):
    """An Assessment whose records have the given window stages; a record's stage is its majority."""
    recs = []
    for i, w in enumerate(windows_by_record):
        stage = int(np.bincount(w, minlength=n_stages).argmax())
        p = tuple(float(v) for v in np.bincount(w, minlength=n_stages) / len(w))
        recs.append(RecordAssessment(f"r{i}", stage, max(p), p, tuple(int(v) for v in w),
                                     tuple(1.0 for _ in w), None if labels is None else labels[i]))
    return Assessment(tuple(recs), n_stages, None, None)


def test_pairwise_agreement_by_hand():
    stages = [[0, 1, 2, 2], [0, 1, 1, 2], [1, 1, 1, 2]]
    g = pairwise_agreement(stages)
    assert g.tolist() == [[1.0, 0.75, 0.5], [0.75, 1.0, 0.75], [0.5, 0.75, 1.0]]
    assert mean_agreement(stages) == pytest.approx((0.75 + 0.5 + 0.75) / 3)


def test_the_bound_holds_for_any_truth():
    """(1 + agreement) / 2 bounds the members' mean accuracy, whatever the labels."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        m, n, k = rng.integers(2, 6), rng.integers(1, 40), rng.integers(2, 7)
        truth = rng.integers(0, k, n)
        # members right with different probabilities, wrong at random otherwise
        stages = np.array([np.where(rng.random(n) < rng.random(), truth, rng.integers(0, k, n)) for _ in range(m)])
        accuracy = float(np.mean(stages == truth[None, :]))
        assert accuracy <= (1 + mean_agreement(stages)) / 2 + 1e-12
    # tight when every disagreement has exactly one member right
    truth = np.array([0, 1, 2, 0])
    stages = np.array([[0, 1, 2, 0], [0, 1, 0, 1]])
    assert np.mean(stages == truth) == (1 + mean_agreement(stages)) / 2 == 0.75


def test_agreement_of_assessments_by_hand():
    a = _assessment([[0, 0, 0], [2, 2]])
    b = _assessment([[0, 1, 1], [2, 2]])
    c = _assessment([[0, 0, 1], [2, 1]])
    res = agreement([a, b, c])
    assert (res.n_assessors, res.n_records, res.n_windows) == (3, 2, 5)
    # windows: a-b 3/5, a-c 3/5, b-c 3/5
    assert res.window_agreement == pytest.approx(0.6) and res.accuracy_bound == pytest.approx(0.8)
    assert np.allclose(res.pairwise, [[1, 0.6, 0.6], [0.6, 1, 0.6], [0.6, 0.6, 1]])
    # records (majority stage): a (0, 2), b (1, 2), c (0, 1): a-b 1/2, a-c 1/2, b-c 0
    assert res.record_agreement == pytest.approx(1 / 3)
    # record r0: a-b 1/3, a-c 2/3, b-c 2/3; r1: a-b 1, a-c 1/2, b-c 1/2
    assert res.per_record == pytest.approx((5 / 9, 2 / 3)) and res.record_names == ("r0", "r1")
    d = json.loads(json.dumps(res.to_dict()))
    assert d["records"][1] == {"name": "r1", "window_agreement": pytest.approx(2 / 3)}
    assert agreement([a, a]).window_agreement == 1.0


def test_assessments_that_do_not_line_up_are_refused_by_name():
    a = _assessment([[0, 0, 0], [2, 2]])
    with pytest.raises(AssessorError, match="at least 2 assessments"):
        agreement([a])
    with pytest.raises(AssessorError, match="assessment 1 has 4 stages"):
        agreement([a, _assessment([[0, 0, 0], [2, 2]], n_stages=4)])
    with pytest.raises(AssessorError, match=r"other records than assessment 0 \(3 against 2; record 2 is 'r2' against 'none'\)"):
        agreement([a, _assessment([[0, 0, 0], [2, 2], [1]])])
    with pytest.raises(AssessorError, match="record 'r1' has another number of windows in assessment 2"):
        agreement([a, a, _assessment([[0, 0, 0], [2, 2, 2]])])
    with pytest.raises(AssessorError, match=r"shape \(1, 3\)"):
        pairwise_agreement([[0, 1, 2]])
    with pytest.raises(AssessorError, match="integers"):
        pairwise_agreement([[0.5, 1.0], [0.0, 1.0]])
    with pytest.raises(AssessorError, match="no record"):
        agreement([Assessment((), 3, None, None)] * 2)


def test_assessor_agreement_assesses_and_refuses_the_same_network(tiny_pre, tiny_data):
    from twin.transfer.assessor import Assessor

    source, adapt, test = tiny_data
    fits = [Assessor("cnn", epochs=2, seed=s, preprocessing=tiny_pre, progress=False).fit(source, adapt)
            for s in (0, 1, 0)]
    from twin.transfer.reliability import assessor_agreement
    res = assessor_agreement(fits[:2], test)
    assert res == agreement([fits[0].assess(test), fits[1].assess(test)])
    with pytest.raises(AssessorError, match="assessor 0 and assessor 2 hold the same network"):
        assessor_agreement(fits, test)
    with pytest.raises(AssessorError, match="'a' and 'c' hold the same network"):
        assessor_agreement(fits, test, names=["a", "b", "c"])
    with pytest.raises(AssessorError, match="2 names for 3 assessors"):
        assessor_agreement(fits, test, names=["a", "b"])
    with pytest.raises(AssessorError, match="at least 2 assessors"):
        assessor_agreement(fits[:1], test)
    with pytest.raises(AssessorError, match="'b' is not a fitted assessor"):
        assessor_agreement([fits[0], Assessor("cnn")], test, names=["a", "b"])
