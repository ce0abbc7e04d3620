"""The assessor's contract: determinism, persistence, typed errors, and adaptation that helps."""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.errors import MeasurementError, OutputPathError
from twin.transfer import Assessor, AssessorError

from .conftest import FS, make_records, tiny_assessor

# The tiny rig's gain and hum move a third of its windows under the class-prior match, so every fit
# on it warns; test_class_prior_diagnostics_and_the_warning checks that warning itself.
pytestmark = pytest.mark.filterwarnings("ignore::twin.transfer.errors.ClassPriorWarning")


@pytest.fixture(scope="module")
def fitted(tiny_pre, tiny_data):
    src, adapt, _ = tiny_data
    return tiny_assessor("proposed", tiny_pre, seed=3).fit(src, adapt)


def test_fit_returns_self_and_sets_learned_attributes(fitted):
    assert isinstance(fitted, Assessor)
    assert fitted.n_classes_ == 3
    assert fitted.classes_.tolist() == [0, 1, 2]
    assert len(fitted.history_) == 6
    assert {"loss", "cls", "align", "con", "gate", "source_acc"} <= set(fitted.history_[-1])
    # the gate opens only after the warm-up (2 epochs)
    assert fitted.history_[0]["gate"] == 0.0 and fitted.history_[1]["gate"] == 0.0
    # log spectrum + "domain": each domain is centred on its own mean spectrum, the scale is shared
    src_n, tgt_n = fitted.source_normaliser_, fitted.target_normaliser_
    assert src_n.centre.shape == tgt_n.centre.shape == (64,) and tgt_n.scale == src_n.scale > 0
    # the rig's 170 Hz hum the twin lacks lifts the rig's mean spectrum there (bin 170 / (FS / 128))
    hum = round(170 / (FS / 128))
    assert tgt_n.centre[hum] - src_n.centre[hum] > 1.0


def test_waveform_domain_scales_follow_the_rig_gain(tiny_data):
    from twin.transfer import Preprocessing
    src, adapt, _ = tiny_data
    pre = Preprocessing(sample_rate=FS, window=64, hop=32, representation="waveform")
    a = tiny_assessor("cnn", pre, epochs=1).fit(src, adapt)
    assert a.source_normaliser_.scale > 0 and a.target_normaliser_.scale > 2 * a.source_normaliser_.scale  # gain 3x


def test_same_seed_same_output_other_seed_differs(tiny_pre, tiny_data, fitted):
    src, adapt, test = tiny_data
    again = tiny_assessor("proposed", tiny_pre, seed=3).fit(src, adapt)
    np.testing.assert_array_equal(again.predict_proba(test), fitted.predict_proba(test))
    other = tiny_assessor("proposed", tiny_pre, seed=4).fit(src, adapt)
    assert not np.array_equal(other.predict_proba(test), fitted.predict_proba(test))


def test_predict_shapes(fitted, tiny_data):
    _, _, test = tiny_data
    p = fitted.predict_proba(test)
    assert p.shape == (len(test), 3)
    np.testing.assert_allclose(p.sum(1), 1.0, rtol=1e-5)
    assert fitted.predict(test).shape == (len(test),)
    w = np.zeros((5, 64))
    assert fitted.predict_proba(w).shape == (5, 3)             # arrays: one row per window
    assert fitted.transform(test).shape[1] == 300
    a = fitted.assess(test)
    assert len(a.records) == len(test) and a.record_accuracy is not None
    assert len(a.records[0].window_stages) == (384 - 64) // 32 + 1


def test_window_verdicts_pair_each_window_with_its_records_label(fitted, tiny_data):
    from dataclasses import replace

    _, _, test = tiny_data
    a = fitted.assess(test)
    true, assessed = a.window_verdicts()
    n = [len(r.window_stages) for r in a.records]
    assert true.shape == assessed.shape == (sum(n),)
    np.testing.assert_array_equal(true[:n[0]], a.records[0].label)
    np.testing.assert_array_equal(assessed[:n[0]], a.records[0].window_stages)
    assert np.mean(true == assessed) == pytest.approx(a.window_accuracy)
    unlabelled = fitted.assess([replace(r, label=None) for r in test])
    with pytest.raises(AssessorError, match="no label"):
        unlabelled.window_verdicts()


def test_save_load_round_trip_gives_identical_predictions(fitted, tiny_data, tmp_path):
    _, _, test = tiny_data
    d = fitted.save(tmp_path / "assessor")
    cfg = json.loads((d / "config.json").read_text())
    assert cfg["preprocessing"] == {"channel": "accel_pinion_casing", "sample_rate": FS, "window": 64, "hop": 32,
                                    "normalise": "domain", "representation": "log_spectrum",
                                    "time_bandwidth": 4.0, "remove_level": False, "target_channel": None}
    back = Assessor.load(d)
    assert back._pre == fitted._pre
    np.testing.assert_array_equal(back.target_normaliser_.centre, fitted.target_normaliser_.centre)
    assert back.target_normaliser_.scale == fitted.target_normaliser_.scale
    np.testing.assert_array_equal(back.predict_proba(test), fitted.predict_proba(test))
    assert not list(d.glob(".*.tmp"))                          # atomic writes left no temporaries


def test_version_1_assessors_still_load_as_waveform_models(tiny_data, tmp_path):
    """An assessor saved before the log-spectrum representation keeps assessing as it was trained."""
    from twin.transfer import Preprocessing
    src, adapt, test = tiny_data
    pre = Preprocessing(sample_rate=FS, window=64, hop=32, representation="waveform")
    a = tiny_assessor("cnn", pre, epochs=2).fit(src, adapt)
    d = a.save(tmp_path / "v1")
    cfg = json.loads((d / "config.json").read_text())
    # rewrite it as version 1 wrote it: no representation, one scale per domain
    del cfg["preprocessing"]["representation"]
    cfg["source_scale"] = cfg.pop("source_normaliser")["scale"]
    cfg["target_scale"] = cfg.pop("target_normaliser")["scale"]
    cfg["format_version"] = 1
    (d / "config.json").write_text(json.dumps(cfg))
    back = Assessor.load(d)
    assert back._pre.representation == "waveform"
    np.testing.assert_array_equal(back.predict_proba(test), a.predict_proba(test))


def test_version_2_assessors_keep_their_single_taper_level_free_spectrum(fitted, tiny_data, tmp_path):
    """Version 2 had no multitaper or level setting: its networks were trained on Hann-taper log
    spectra with each window's level removed."""
    _, _, test = tiny_data
    d = fitted.save(tmp_path / "v2")
    cfg = json.loads((d / "config.json").read_text())
    del cfg["preprocessing"]["time_bandwidth"], cfg["preprocessing"]["remove_level"]
    cfg["format_version"] = 2
    (d / "config.json").write_text(json.dumps(cfg))
    back = Assessor.load(d)
    from dataclasses import replace
    assert back._pre == replace(fitted._pre, time_bandwidth=0.0, remove_level=True)
    assert not np.array_equal(back.predict_proba(test), fitted.predict_proba(test))   # the input differs


def test_a_damaged_normaliser_is_an_assessor_error(fitted, tmp_path):
    d = fitted.save(tmp_path / "bad")
    cfg = json.loads((d / "config.json").read_text())
    cfg["target_normaliser"]["centre"] = [0.0, 1.0]          # not one value per bin
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match=r"centre shape \(2,\)"):
        Assessor.load(d)
    del cfg["target_normaliser"]
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match="target_normaliser"):
        Assessor.load(d)


def test_save_to_missing_parent_is_an_output_path_error(fitted, tmp_path):
    with pytest.raises(OutputPathError, match="nope"):
        fitted.save(tmp_path / "nope" / "assessor")


def test_load_bad_directory(tmp_path):
    with pytest.raises(AssessorError, match="config.json"):
        Assessor.load(tmp_path)
    (tmp_path / "config.json").write_text(json.dumps({"format": "other"}))
    (tmp_path / "weights.pt").write_bytes(b"x")
    with pytest.raises(AssessorError, match="'other'"):
        Assessor.load(tmp_path)


def test_wrong_window_shape_names_the_shape(fitted):
    with pytest.raises(AssessorError, match=r"\(n, 64\).*\(4, 50\)"):
        fitted.predict(np.zeros((4, 50)))
    with pytest.raises(AssessorError, match=r"\(n, 64\).*\(64,\)"):
        fitted.predict(np.zeros(64))
    # an empty array has the right width but nothing to assess: named, not numpy's concatenate error
    for verb in (fitted.predict, fitted.predict_proba, lambda x: fitted.rematch(x, "source")):
        with pytest.raises(AssessorError, match=r"no windows \(shape \(0, 64\)\)"):
            verb(np.zeros((0, 64)))


def test_missing_channel_names_record_and_channel(fitted):
    recs = make_records(1, 1, channel="accel_gear_casing")
    with pytest.raises(MeasurementError, match="accel_pinion_casing") as exc:
        fitted.predict(recs)
    assert exc.value.record == "s0r0"


def test_bad_path_is_a_measurement_error_naming_it(fitted, tmp_path):
    with pytest.raises(MeasurementError, match="missing.h5"):
        fitted.predict(tmp_path / "missing.h5")


def test_record_shorter_than_a_window(fitted):
    with pytest.raises(AssessorError, match=r"'s0r0' has 40 samples"):
        fitted.predict(make_records(1, 1, duration=0.04))


def test_mismatched_stage_count(tiny_pre, tiny_data, fitted):
    src, adapt, _ = tiny_data
    with pytest.raises(AssessorError, match="n_stages=4"):
        tiny_assessor("cnn", tiny_pre, n_stages=4).fit(src, adapt)
    no_stage_1 = [r for r in src if r.label != 1]
    with pytest.raises(AssessorError, match=r"stage\(s\) \[1\] have no record"):
        tiny_assessor("cnn", tiny_pre).fit(no_stage_1, adapt)
    with pytest.raises(AssessorError, match=r"label\(s\) \[3, 4\]"):
        fitted.assess(make_records(1, 5, seed=9))
    with pytest.raises(AssessorError, match="no stage label"):
        tiny_assessor("cnn", tiny_pre).fit(adapt, adapt)


def test_bad_parameters_are_named(tiny_pre, tiny_data):
    src, adapt, _ = tiny_data
    with pytest.raises(AssessorError, match="method='dann'"):
        Assessor("dann", preprocessing=tiny_pre).fit(src, adapt)
    with pytest.raises(AssessorError, match="threshold=1.5"):
        Assessor(threshold=1.5, preprocessing=tiny_pre).fit(src, adapt)
    with pytest.raises(AssessorError, match="contrastive_reduction='max'"):
        Assessor(contrastive_reduction="max", preprocessing=tiny_pre).fit(src, adapt)
    with pytest.raises(AssessorError, match="not fitted"):
        Assessor().predict(np.zeros((1, 2048)))
    with pytest.raises(AssessorError, match="labels must have shape \\(3,\\)"):
        Assessor(preprocessing=tiny_pre).fit(np.zeros((3, 64)), adapt, source_labels=[0, 1])


def test_get_set_params(tiny_pre):
    a = Assessor("mmd", preprocessing=tiny_pre)
    assert a.get_params()["method"] == "mmd"
    assert a.set_params(alpha=0.5).alpha == 0.5
    with pytest.raises(AssessorError, match="'gamma'"):
        a.set_params(gamma=1)


def test_adaptation_beats_source_only_on_shifted_data(tiny_pre, tiny_data):
    """The rig has a strong hum and a 3x gain the twin lacks; aligning the features must help.

    On the waveform: the hum sits 10 Hz from the stage line, inside one bin of a 64-sample
    spectrum, so this case is about the adaptation losses, not about the representation."""
    from dataclasses import replace
    src, adapt, test = tiny_data
    pre = replace(tiny_pre, representation="waveform")
    acc = {m: np.mean([tiny_assessor(m, pre, seed=s, epochs=15).fit(src, adapt).score(test)
                       for s in (0, 1)]) for m in ("cnn", "proposed")}
    assert acc["proposed"] > acc["cnn"] + 0.1, acc


def test_class_prior_match_balances_the_rig_and_leaves_training_alone(tiny_pre, tiny_data, fitted):
    """After fit, the adaptation windows' mean stage probabilities equal the source's proportions
    (1/3 each); the offsets only re-weight the probabilities of the very same network."""
    from twin.transfer.preprocess import prepare, window_signal
    from twin.transfer.prior import apply_log_weights
    src, adapt, test = tiny_data

    def raw_windows(records):
        return np.concatenate([window_signal(p.signal, tiny_pre.window, tiny_pre.hop)
                               for p in prepare(records, tiny_pre)])
    x = raw_windows(adapt)
    assert fitted.class_prior == "source" and np.any(fitted.target_log_weights_ != 0)
    np.testing.assert_allclose(fitted.predict_proba(x).mean(0), 1 / 3, atol=1e-5)
    plain = tiny_assessor("proposed", tiny_pre, seed=3, class_prior=None).fit(src, adapt)
    assert np.array_equal(plain.target_log_weights_, np.zeros(3))
    xt = raw_windows(test)
    np.testing.assert_allclose(apply_log_weights(plain.predict_proba(xt), fitted.target_log_weights_),
                               fitted.predict_proba(xt), rtol=1e-5, atol=1e-7)
    # the twin's own data are never re-weighted
    np.testing.assert_allclose(fitted.predict_proba(src, domain="source"), plain.predict_proba(src, domain="source"))


def test_source_only_cnn_gets_no_class_prior_offsets(tiny_pre, tiny_data):
    src, adapt, _ = tiny_data
    a = tiny_assessor("cnn", tiny_pre, epochs=1).fit(src, adapt)
    assert np.array_equal(a.target_log_weights_, np.zeros(3))


def test_contrastive_reduction_is_saved_and_older_assessors_load_with_the_mean(fitted, tmp_path):
    import copy
    paper = copy.copy(fitted).set_params(contrastive_reduction="sum")   # the fixture stays as it is
    d = paper.save(tmp_path / "red")
    assert Assessor.load(d).contrastive_reduction == "sum"
    cfg = json.loads((d / "config.json").read_text())
    del cfg["params"]["contrastive_reduction"]              # as saved before the option existed
    (d / "config.json").write_text(json.dumps(cfg))
    assert Assessor.load(d).contrastive_reduction == "mean"


def test_class_prior_offsets_survive_save_and_load_and_version_3_loads_without(fitted, tiny_data, tmp_path):
    _, _, test = tiny_data
    d = fitted.save(tmp_path / "v4")
    back = Assessor.load(d)
    np.testing.assert_array_equal(back.target_log_weights_, fitted.target_log_weights_)
    assert back.class_prior == "source"
    cfg = json.loads((d / "config.json").read_text())
    del cfg["target_log_weights"], cfg["params"]["class_prior"]
    cfg["format_version"] = 3
    (d / "config.json").write_text(json.dumps(cfg))
    old = Assessor.load(d)
    assert old.class_prior is None and np.array_equal(old.target_log_weights_, np.zeros(3))
    cfg["format_version"] = 4
    cfg["target_log_weights"] = [0.0, "x"]
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match="target_log_weights must be 3 finite numbers"):
        Assessor.load(d)
    del cfg["target_log_weights"]                            # version 4 without offsets: damaged
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match="got None"):
        Assessor.load(d)


def test_ordinal_class_prior_splits_the_rig_by_the_expected_stage_and_survives_save_and_load(
        tiny_pre, tiny_data, tmp_path):
    """class_prior="ordinal" leaves the network as class_prior=None trains it; the rig's windows are
    staged by where their expected stage falls among the adaptation windows' quantiles."""
    from twin.transfer.prior import expected_stage
    src, adapt, test = tiny_data
    a = tiny_assessor("proposed", tiny_pre, seed=3, class_prior="ordinal").fit(src, adapt)
    plain = tiny_assessor("proposed", tiny_pre, seed=3, class_prior=None).fit(src, adapt)
    assert np.array_equal(a.target_log_weights_, np.zeros(3)) and a.ordinal_anchors_.shape == (5,)
    assert plain.ordinal_anchors_ is None
    x, *_ = a._windows(adapt, "adapt")
    s_adapt = expected_stage(plain._proba_windows(x))
    np.testing.assert_allclose(a.ordinal_anchors_, np.quantile(s_adapt, [1 / 6, 1 / 3, 1 / 2, 2 / 3, 5 / 6]))
    xt, *_ = a._windows(test, "test")
    s_test = expected_stage(plain._proba_windows(xt))
    stages = a._proba_windows(xt).argmax(1)
    assert stages.tolist() == (s_test[:, None] > a.ordinal_anchors_[None, 1::2]).sum(1).tolist()
    assert a.adaptation_stage_counts_.sum(1).tolist() == [len(x), len(x)]
    # the twin's own data are never matched
    np.testing.assert_allclose(a.predict_proba(src, domain="source"), plain.predict_proba(src, domain="source"))
    d = a.save(tmp_path / "ordinal")
    back = Assessor.load(d)
    assert back.class_prior == "ordinal"
    np.testing.assert_array_equal(back.ordinal_anchors_, a.ordinal_anchors_)
    np.testing.assert_array_equal(back.predict_proba(test), a.predict_proba(test))
    cfg = json.loads((d / "config.json").read_text())
    for bad in (None, [0.1, 0.2], [0.5, 0.4, 0.6, 0.7, 0.8], [0.1, 0.2, "x", 0.4, 0.5]):
        cfg["ordinal_anchors"] = bad
        (d / "config.json").write_text(json.dumps(cfg))
        with pytest.raises(AssessorError, match="class_prior 'ordinal' needs ordinal_anchors"):
            Assessor.load(d)
    cfg["ordinal_anchors"], cfg["params"]["class_prior"] = a.ordinal_anchors_.tolist(), "source"
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match="ordinal_anchors are only read with class_prior 'ordinal'"):
        Assessor.load(d)


def test_source_only_cnn_with_ordinal_class_prior_is_not_matched(tiny_pre, tiny_data, tmp_path):
    src, adapt, test = tiny_data
    a = tiny_assessor("cnn", tiny_pre, epochs=1, class_prior="ordinal").fit(src, adapt)
    assert a.ordinal_anchors_ is None
    back = Assessor.load(a.save(tmp_path / "cnn"))
    assert back.ordinal_anchors_ is None
    np.testing.assert_array_equal(back.predict_proba(test), a.predict_proba(test))


def test_class_prior_diagnostics_and_the_warning(tiny_pre, tiny_data, fitted):
    """fit records how the match re-assesses the adaptation windows and warns when it costs them
    much confidence: the tiny rig's gain and hum push stage 0 into stage 1, read with confidence,
    so the match moves about a third of the windows against the network's certainty."""
    import warnings

    from twin.transfer import ClassPriorWarning
    from twin.transfer.assessor import CLASS_PRIOR_WARN_DROP
    src, adapt, _ = tiny_data
    counts = fitted.adaptation_stage_counts_
    assert counts.shape == (2, 3) and counts.sum(1).tolist() == [fitted.n_target_windows_] * 2
    assert counts[0, 0] < counts[1, 0]               # stage 0 windows won back by the match
    assert fitted.class_prior_moved_ > 0.2
    assert fitted.class_prior_confidence_drop_ > CLASS_PRIOR_WARN_DROP
    with pytest.warns(ClassPriorWarning, match=r"lowered the mean confidence of the \d+ rig adaptation windows by "
                                               r"\d+\.\d points.*moved \d+\.\d %.*--class-prior none"):
        tiny_assessor("mmd", tiny_pre, seed=3).fit(src, adapt)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClassPriorWarning)
        plain = tiny_assessor("mmd", tiny_pre, seed=3, class_prior=None).fit(src, adapt)
        # a rig without the hum and gain: nothing to move, no warning
        same = tiny_assessor("mmd", tiny_pre, seed=3).fit(src, make_records(8, seed=2, labelled=False))
    assert plain.class_prior_moved_ == 0.0 and plain.class_prior_confidence_drop_ == pytest.approx(0.0, abs=1e-6)
    assert same.class_prior_moved_ == 0.0 and same.class_prior_confidence_drop_ < CLASS_PRIOR_WARN_DROP


def _checked(p: np.ndarray) -> Assessor:
    """An assessor whose class-prior match was fitted to the adaptation probabilities ``p`` (n, 2)
    with a balanced prior, as ``fit`` does after training."""
    from twin.transfer.prior import match_class_prior
    a = Assessor("mmd")
    prior = np.array([0.5, 0.5])
    a.target_log_weights_ = match_class_prior(p, prior)
    a._class_prior_check(p, prior)
    return a


def test_a_shifted_boundary_moves_unsure_windows_without_a_warning():
    """Balanced rig data (50 windows per stage) whose boundary the rig has shifted: 30 stage-1
    windows read as stage 0, unsure.  The match moves them back (30 %, far more than the old 8 %
    share-moved rule allowed) but costs little confidence, so fit stays quiet."""
    import warnings

    from twin.transfer import ClassPriorWarning
    from twin.transfer.assessor import CLASS_PRIOR_WARN_DROP
    p0 = np.concatenate([np.linspace(0.85, 0.95, 40), np.linspace(0.05, 0.15, 30), np.linspace(0.51, 0.6, 30)])
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClassPriorWarning)
        a = _checked(np.stack([p0, 1 - p0], axis=1))
    assert a.adaptation_stage_counts_.tolist() == [[70, 30], [40, 60]]
    assert a.class_prior_moved_ == pytest.approx(0.3)
    assert 0 < a.class_prior_confidence_drop_ < CLASS_PRIOR_WARN_DROP


def test_an_imbalanced_rig_set_costs_confidence_and_warns():
    """Run-to-failure-like rig data, 70 windows of stage 0 and 30 of stage 1, all read with
    confidence.  A balanced prior is met by making every stage-0 window less sure; no window changes
    stage, so the old share-moved rule saw nothing."""
    from twin.transfer import ClassPriorWarning
    from twin.transfer.assessor import CLASS_PRIOR_WARN_DROP
    p0 = np.concatenate([np.linspace(0.9, 0.99, 70), np.linspace(0.01, 0.1, 30)])
    with pytest.warns(ClassPriorWarning, match=r"proportions 0\.50, 0\.50"):
        a = _checked(np.stack([p0, 1 - p0], axis=1))
    assert a.adaptation_stage_counts_.tolist() == [[70, 30], [70, 30]] and a.class_prior_moved_ == 0.0
    assert a.class_prior_confidence_drop_ > CLASS_PRIOR_WARN_DROP


def test_class_prior_diagnostics_survive_save_and_load(fitted, tmp_path):
    d = fitted.save(tmp_path / "diag")
    back = Assessor.load(d)
    assert back.class_prior_moved_ == fitted.class_prior_moved_
    assert back.class_prior_confidence_drop_ == fitted.class_prior_confidence_drop_
    np.testing.assert_array_equal(back.adaptation_stage_counts_, fitted.adaptation_stage_counts_)
    cfg = json.loads((d / "config.json").read_text())
    del cfg["class_prior_confidence_drop"]                             # written before the confidence drop was saved
    (d / "config.json").write_text(json.dumps(cfg))
    back = Assessor.load(d)
    assert back.class_prior_moved_ == fitted.class_prior_moved_ and not hasattr(back, "class_prior_confidence_drop_")
    cfg["class_prior_confidence_drop"] = "high"
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match=r"class_prior_confidence_drop must be a number in \(-1, 1\), got 'high'"):
        Assessor.load(d)
    del cfg["class_prior_confidence_drop"], cfg["class_prior_moved"], cfg["adaptation_stage_counts"]  # older file
    (d / "config.json").write_text(json.dumps(cfg))
    assert not hasattr(Assessor.load(d), "class_prior_moved_")
    cfg["class_prior_moved"], cfg["adaptation_stage_counts"] = 1.5, [[1, 2, 3]]
    (d / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(AssessorError, match="adaptation_stage_counts must be 2 x 3"):
        Assessor.load(d)


def test_an_unknown_class_prior_is_named(tiny_pre, tiny_data):
    src, adapt, _ = tiny_data
    with pytest.raises(AssessorError, match="class_prior='uniform'"):
        Assessor(class_prior="uniform", preprocessing=tiny_pre).fit(src, adapt)


def test_a_rig_channel_of_another_name_is_read_as_the_twins(tiny_pre, tiny_data, fitted):
    """``target_channel``: the rig calls its accelerometer "accel_x"; the twin's data keep theirs."""
    from dataclasses import replace
    src, _, test = tiny_data
    rig_adapt = make_records(8, shifted=True, seed=2, labelled=False, channel="accel_x")
    rig_test = make_records(8, shifted=True, seed=3, channel="accel_x")
    pre = replace(tiny_pre, target_channel="accel_x")
    a = tiny_assessor("proposed", pre, seed=3).fit(src, rig_adapt)
    # the same samples under another name: the same assessor as the one fitted on the default name
    np.testing.assert_array_equal(a.predict_proba(rig_test), fitted.predict_proba(test))
    with pytest.raises(MeasurementError, match="no channel 'accel_x'"):
        a.predict(test)                                     # rig data must carry the rig's name
    assert a.predict_proba(src, domain="source").shape == (len(src), 3)   # twin data keep theirs


def test_rematch_gives_what_fit_gives_under_the_other_rule(tiny_pre, tiny_data, fitted):
    """fit trains the same network under every rule, so re-matching a fitted assessor on the data fit
    saw must equal fitting with the other rule, bit for bit; the original is left as it was."""
    src, adapt, test = tiny_data
    weights = fitted.target_log_weights_.copy()
    np.testing.assert_array_equal(fitted.source_prior_, np.full(3, 1 / 3))
    for rule in ("ordinal", None):
        direct = tiny_assessor("proposed", tiny_pre, seed=3, class_prior=rule).fit(src, adapt)
        re = fitted.rematch(adapt, rule)
        assert re.class_prior == rule and re is not fitted
        np.testing.assert_array_equal(re.target_log_weights_, direct.target_log_weights_)
        if rule == "ordinal":
            np.testing.assert_array_equal(re.ordinal_anchors_, direct.ordinal_anchors_)
        else:
            assert re.ordinal_anchors_ is None and not np.any(re.target_log_weights_)
        np.testing.assert_array_equal(re.adaptation_stage_counts_, direct.adaptation_stage_counts_)
        assert re.class_prior_moved_ == direct.class_prior_moved_
        np.testing.assert_array_equal(re.predict_proba(test), direct.predict_proba(test))
    assert fitted.class_prior == "source" and fitted.ordinal_anchors_ is None
    np.testing.assert_array_equal(fitted.target_log_weights_, weights)
    back = fitted.rematch(adapt, "ordinal").rematch(adapt, "source")      # and back again
    np.testing.assert_array_equal(back.target_log_weights_, weights)


def test_rematch_warns_as_fit_does(fitted, tiny_data):
    from twin.transfer.errors import ClassPriorWarning
    _, adapt, _ = tiny_data
    with pytest.warns(ClassPriorWarning, match="rematch\\(rig, class_prior=None\\)"):
        fitted.rematch(adapt, "source")


def test_rematch_after_save_and_load_and_its_typed_errors(tiny_pre, tiny_data, fitted, tmp_path):
    src, adapt, test = tiny_data
    d = fitted.save(tmp_path / "a")
    back = Assessor.load(d)
    np.testing.assert_array_equal(back.source_prior_, fitted.source_prior_)
    np.testing.assert_array_equal(back.rematch(adapt, "ordinal").predict_proba(test),
                                  fitted.rematch(adapt, "ordinal").predict_proba(test))
    with pytest.raises(AssessorError, match="not fitted"):
        Assessor(preprocessing=tiny_pre).rematch(adapt, None)
    with pytest.raises(AssessorError, match="class_prior='median'"):
        fitted.rematch(adapt, "median")
    cnn = tiny_assessor("cnn", tiny_pre, epochs=1).fit(src, adapt)
    with pytest.raises(AssessorError, match="source-only CNN"):
        cnn.rematch(adapt, "source")
    assert cnn.rematch(adapt, None).class_prior is None
    with pytest.raises(MeasurementError, match="no channel"):
        fitted.rematch(make_records(2, shifted=True, labelled=False, channel="accel_x"), None)
    cfg = json.loads((d / "config.json").read_text())
    for bad in ([0.5, 0.5], [0.5, 0.5, 0.5], [0.0, 0.5, 0.5], [0.2, "x", 0.8]):
        cfg["source_prior"] = bad
        (d / "config.json").write_text(json.dumps(cfg))
        with pytest.raises(AssessorError, match=r"source_prior must be 3 numbers > 0 that sum to 1, got \["):
            Assessor.load(d)
    del cfg["source_prior"]                                  # saved before rematch existed
    (d / "config.json").write_text(json.dumps(cfg))
    old = Assessor.load(d)
    assert old.source_prior_ is None
    np.testing.assert_array_equal(old.predict_proba(test), fitted.predict_proba(test))
    assert old.rematch(adapt, None).class_prior is None      # dropping the match needs no proportions
    with pytest.raises(AssessorError, match="retrain it with class_prior='ordinal'"):
        old.rematch(adapt, "ordinal")


def test_assess_and_predict_take_the_batched_network_with_the_forward_pass_numbers(fitted, tiny_data):
    _, _, test = tiny_data
    x, rec, _, prepared, _ = fitted._windows(test, "assess")
    reference = fitted._proba_windows(x)                     # the training code's forward pass
    batched = fitted._proba_windows(x, batched=True)
    np.testing.assert_allclose(batched, reference, rtol=0, atol=2e-6)
    per_record = np.stack([batched[rec == i].mean(0) for i in range(len(prepared))])
    assert np.array_equal(fitted.predict_proba(test), per_record)
    res = fitted.assess(test)
    assert [r.stage for r in res.records] == [int(reference[rec == i].mean(0).argmax()) for i in range(len(prepared))]
