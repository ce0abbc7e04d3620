"""twin.transfer.order: the stage-order check against a monotone feature, and the time order of a history."""
from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from twin.transfer.errors import AssessorError
from twin.transfer.order import check_order, feature_trends, monotone_stages, record_features, time_order

from .conftest import rig_records


def _best_monotone(p, floor=1e-3):
    n, k = p.shape
    best, arg = -np.inf, None
    for seq in itertools.combinations_with_replacement(range(k), n):     # every non-decreasing sequence
        score = np.sum(np.log(p[np.arange(n), seq] + floor))
        if score > best:
            best, arg = score, np.array(seq)
    return arg


def test_monotone_stages_is_the_best_non_decreasing_sequence():
    rng = np.random.default_rng(0)
    for _ in range(30):
        p = rng.dirichlet(np.ones(3), size=6)
        s = monotone_stages(p)
        assert np.all(np.diff(s) >= 0)
        np.testing.assert_array_equal(s, _best_monotone(p))
    # a history already in order is left alone; one healed record is put back
    p = np.eye(4)[[0, 0, 1, 2, 1, 3]] * 0.9 + 0.025
    s = monotone_stages(p)
    assert np.all(np.diff(s) >= 0) and s[0] == 0 and s[-1] == 3 and np.sum(s != p.argmax(1)) == 1
    with pytest.raises(AssessorError, match="shape"):
        monotone_stages(np.zeros((0, 3)))


def test_features_follow_level_and_mesh_energy_with_the_speed_off_its_command():
    recs = rig_records(per_stage=2)          # stages 0..2, the mesh 1 % above 20 Hz x 19
    f = record_features([r["accel_pinion_casing"] for r in recs], recs[0].sample_rate, 20.0)
    stage = np.array([r.label for r in recs])
    trends = feature_trends(f, stage)
    assert trends["level"] > 0.8 and trends["mesh"] > 0.8


def test_order_check_verdicts():
    rng = np.random.default_rng(1)
    stage = np.repeat(np.arange(4), 6)
    feat = {"level": stage + rng.normal(0, 0.3, stage.size), "mesh": rng.normal(0, 1, stage.size)}
    twin = {"level": 0.9, "mesh": 0.1}
    ok = check_order(feat, stage + rng.normal(0, 0.2, stage.size), twin)
    assert ok.verdict == "consistent" and ok.feature == "level" and "consistent" in ok.message()
    rev = check_order(feat, 3 - stage, twin)
    assert rev.verdict == "reversed" and "REVERSED" in rev.message()
    flat = check_order(feat, rng.normal(0, 1, stage.size), twin)
    assert flat.verdict == "unconfirmed"
    # a twin whose feature falls with damage: a rig whose assessed stages fall with it is consistent
    assert check_order(feat, 3 - stage, {"level": -0.9}).verdict == "consistent"
    with pytest.raises(AssessorError, match="no feature in common"):
        check_order(feat, stage, {"sidebands": 0.5})


def test_time_order_from_time_stamps_or_cycles():
    recs = rig_records(per_stage=1, timed=True)
    idx, how = time_order(list(reversed(recs)))
    assert how == "time_start" and list(idx) == [2, 1, 0]
    assert time_order(rig_records(per_stage=1))[0] is None
    cyc = [replace(r, metadata={"cycles": c}) for r, c in zip(rig_records(per_stage=1), (5e5, 1e5, 9e5))]
    idx, how = time_order(cyc)
    assert how == "cycles" and list(idx) == [1, 0, 2]
