"""twin.transfer.ensemble: members by seed, settings from the archive, agreement, order and time order."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from twin.measurements import write_measurements
from twin.transfer.ensemble import RELIABLE_AGREEMENT, Ensemble, train_ensemble
from twin.transfer.errors import AssessorError

from .conftest import rig_records, write_tiny_archive


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    d = tmp_path_factory.mktemp("ens")
    arc = write_tiny_archive(d / "arc.h5")
    rig = write_measurements(rig_records(labelled=False), d / "rig.h5")
    lines = []
    ens = train_ensemble(arc, rig, d / "ensemble", members=2, epochs=2, jobs=1, progress=False, log=lines.append)
    return d, arc, rig, ens, lines


def test_members_differ_by_seed_and_take_the_archives_settings(trained):
    d, _, _, ens, lines = trained
    assert [m.seed for m in ens.members] == [0, 1] and ens.rule == "ordinal"
    pre = ens.preprocessing
    assert pre.sample_rate == pytest.approx(20480.0) and pre.remove_level
    assert any("resampled from 25000 Hz to 20480 Hz" in line for line in lines)
    cfg = json.loads((d / "ensemble" / "ensemble.json").read_text())
    assert cfg["facts"]["damage_kind"] == "pitting_density" and len(cfg["anchors"]) == 5
    assert set(cfg["twin_trends"]) == {"level", "mesh"} and cfg["twin_trends"]["level"] > 0.5


def test_assessment_gives_stage_agreement_order_and_a_verdict(trained):
    d, _, _, ens, _ = trained
    recs = rig_records(seed=5)
    res = ens.assess(recs)
    assert len(res.records) == len(recs) and res.n_members == 2
    assert 0.0 <= res.window_agreement <= 1.0 and res.accuracy_bound == pytest.approx((1 + res.window_agreement) / 2)
    assert all(len(r.member_stages) == 2 and 0 <= r.stage < 3 for r in res.records)
    assert res.reliable == (res.window_agreement >= RELIABLE_AGREEMENT and res.order.verdict == "consistent")
    assert res.verdict().startswith("reliable" if res.reliable else "NOT RELIABLE")
    assert res.order.verdict in ("consistent", "reversed", "unconfirmed")
    assert set(res.scores()) == {"record_exact", "record_within_one", "window_exact", "window_within_one"}
    assert res.records[0].ordered_stage is None and res.time_order == "no time stamps"
    # the saved ensemble assesses alike
    again = Ensemble.load(d / "ensemble").assess(recs)
    assert [r.probabilities for r in again.records] == [r.probabilities for r in res.records]
    json.dumps(res.to_dict())


def test_time_stamps_make_the_stages_a_history_that_does_not_heal(trained):
    _, _, _, ens, _ = trained
    recs = rig_records(seed=6, timed=True, order=[0, 0, 1, 0, 2, 1, 2, 2])
    res = ens.assess(list(reversed(recs)))         # file order is not time order: the stamps decide
    assert res.time_order == "time_start"
    by_time = sorted(res.records, key=lambda r: int(r.name[3:]))
    assert np.all(np.diff([r.ordered_stage for r in by_time]) >= 0)
    assert res.moved_by_time_order == sum(r.stage != r.ordered_stage for r in res.records)
    assert "record_exact_time_order" in res.scores()
    assert ens.assess(recs, time_ordered=False).records[0].ordered_stage is None
    given = ens.assess(rig_records(seed=6, order=[0, 1, 2]), time_ordered=True)
    assert given.time_order == "the order given" and given.records[0].ordered_stage is not None


def test_a_finished_ensemble_is_kept_and_a_new_member_trained_alone(trained):
    d, arc, rig, ens, _ = trained
    before = {p.parent.name: p.stat().st_mtime_ns for p in (d / "ensemble").glob("member_*/weights.pt")}
    lines = []
    train_ensemble(arc, rig, d / "ensemble", members=3, epochs=2, jobs=1, progress=False, log=lines.append)
    assert any("2 of 3 members already trained" in line for line in lines)
    after = {p.parent.name: p.stat().st_mtime_ns for p in (d / "ensemble").glob("member_*/weights.pt")}
    assert len(after) == 3 and all(after[k] == v for k, v in before.items())
    assert Ensemble.load(d / "ensemble").n_classes_ == 3


def test_records_that_do_not_fit_are_refused_before_training(trained, tmp_path):
    _, arc, _, ens, _ = trained
    wrong = rig_records(per_stage=1, speed=10.0, load=5.0)
    with pytest.raises(AssessorError, match="'rec00' .*speed 10 Hz, load 5 N.m"):
        train_ensemble(arc, wrong, tmp_path / "e", members=2, epochs=1, progress=False)
    assert not (tmp_path / "e").exists()
    with pytest.raises(AssessorError, match="does not fit|do not fit"):
        ens.assess([replace(r, nominal_speed=10.0) for r in rig_records(per_stage=1)])
    with pytest.raises(AssessorError, match="members must be an integer >= 2"):
        train_ensemble(arc, rig_records(), tmp_path / "f", members=1)


def test_a_file_with_misfits_is_refused_as_read_without_preparing_the_rest(trained, tmp_path, monkeypatch):
    _, _, _, ens, _ = trained
    from twin.transfer.assessor import Assessor
    recs = rig_records(per_stage=2, seed=8)
    recs[0] = replace(recs[0], nominal_speed=10.0)                 # the first record misfits
    recs[4] = replace(recs[4], load=5.0)
    path = write_measurements(recs, tmp_path / "mixed.h5")
    prepared = []
    real = Assessor._prepared

    def counted(self, data, *a, **kw):
        prepared.append([r.name for r in data])
        return real(self, data, *a, **kw)
    monkeypatch.setattr(Assessor, "_prepared", counted)
    with pytest.raises(AssessorError) as err:
        ens.assess(path)
    msg = str(err.value)
    assert "\n" not in msg and "2 record(s) do not fit" in msg
    assert "'rec00' (speed 10 Hz)" in msg and "'rec04' (load 5 N.m)" in msg
    assert prepared == []                                          # nothing prepared after the first misfit
    recs[0] = rig_records(per_stage=2, seed=8)[0]                  # a later misfit: the records before it only
    path = write_measurements(recs, tmp_path / "late.h5")
    with pytest.raises(AssessorError, match=r"1 record\(s\) do not fit.*'rec04' \(load 5 N.m\)"):
        ens.assess(path)
    assert {n for names in prepared for n in names} <= {f"rec{i:02d}" for i in range(4)}


def test_loading_refuses_what_is_not_an_ensemble(tmp_path):
    with pytest.raises(AssessorError, match="ensemble.json"):
        Ensemble.load(tmp_path)
    (tmp_path / "ensemble.json").write_text("{not json")
    with pytest.raises(AssessorError, match="not valid JSON"):
        Ensemble.load(tmp_path)
    (tmp_path / "ensemble.json").write_text(json.dumps({"format": "other"}))
    with pytest.raises(AssessorError, match="format"):
        Ensemble.load(tmp_path)


def test_the_batched_inference_gives_each_members_own_forward_pass(trained):
    _, _, _, ens, _ = trained
    from twin.transfer.preprocess import windows_of
    recs = rig_records(seed=7)
    prepared = ens.members[0]._prepared(recs, None, "assess", "target")
    raw, _, _ = windows_of(prepared, ens.preprocessing, "assess")
    reference = np.stack([m._forward(m.target_normaliser_(raw))[1] for m in ens.members])
    fast = ens._network_probabilities(raw)
    np.testing.assert_allclose(fast, reference, rtol=0, atol=2e-6)
    streamed, rec, _, _ = ens._raw(recs)             # records prepared one by one beside the networks
    assert np.array_equal(streamed, fast) and np.array_equal(rec, np.repeat(np.arange(len(recs)), rec.size // len(recs)))
    res = ens.assess(recs, time_ordered=False)
    p = ens._match(reference.mean(0))
    assert np.array_equal(res.window_stages, p.argmax(1))
    assert np.array_equal(ens._member_stages(fast), ens._member_stages(reference))
