"""The benchmark's per-task settings, its statistics and its references (training only on tiny synthetic data;
the real runs are bench/transfer.py)."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from twin.errors import ParameterError
from twin.transfer.benchmark import (RIGS, TASK_SETTINGS, DataSettings, RunResult, markdown_table, rig_settings,
                                     run_benchmark, seed_range, summarise, task_preprocessing, train_one,
                                     training_jobs)


def test_task_preprocessing_windows_two_revolutions_at_each_tests_speed():
    pitting, wear = task_preprocessing("pitting"), task_preprocessing("wear")
    assert pitting.sample_rate == 20480.0 and wear.sample_rate == 10240.0     # 20 Hz and 10 Hz tests
    assert pitting.remove_level and not wear.remove_level
    # records hold the same number of revolutions, so the same number of windows, at either speed
    for task, pre in (("pitting", pitting), ("wear", wear)):
        n = int(round(TASK_SETTINGS[task].source_record_duration * pre.sample_rate))
        assert (n - pre.window) // pre.hop + 1 == 2
    with pytest.raises(ParameterError, match="'gearbox'"):
        task_preprocessing("gearbox")


def test_blind_rig_changes_only_the_target_rig_and_its_data_seed():
    for task in ("pitting", "wear"):
        blind = rig_settings(task, "blind")
        assert blind.rig == "blind" and blind.target_seed != TASK_SETTINGS[task].target_seed
        assert replace(blind, rig="rig", target_seed=TASK_SETTINGS[task].target_seed) == TASK_SETTINGS[task]
        assert rig_settings(task) == TASK_SETTINGS[task]
    rig, other = RIGS["rig"], RIGS["blind"]
    assert other.resonance_hz != rig.resonance_hz and other.pedestal_stiffness_factor != rig.pedestal_stiffness_factor


def test_a_rig_without_records_or_a_bad_rig_name_is_refused_before_any_data_are_built(tmp_path):
    for bad in ("", "../garage", "gar age"):
        with pytest.raises(ParameterError, match="rig name"):
            DataSettings(rig=bad)
        with pytest.raises(ParameterError, match="rig name"):
            rig_settings("wear", bad)
    # a rig that is not emulated here needs the file of its records, and only it
    with pytest.raises(ParameterError, match="'garage'"):
        run_benchmark(tmp_path / "out", rig="garage", progress=False)
    with pytest.raises(ParameterError, match="'blind'"):
        run_benchmark(tmp_path / "out", tasks=("wear",), rig="blind", targets={"wear": tmp_path / "t.h5"},
                      progress=False)
    with pytest.raises(ParameterError, match="t.h5"):
        run_benchmark(tmp_path / "out", tasks=("wear",), rig="garage", targets={"wear": tmp_path / "t.h5"},
                      progress=False)
    assert not (tmp_path / "out").exists()


def test_first_seed_adds_later_seeds_and_is_checked_before_any_data_are_built(tmp_path):
    paths = {"wear": (Path("s.h5"), Path("t.h5"))}
    jobs = training_jobs(("wear",), ("mmd", "proposed"), seed_range(3, 5), paths, 80)
    assert [(j[1], j[2], j[3]) for j in jobs] == [("wear", m, s) for s in (5, 6, 7) for m in ("mmd", "proposed")]
    # features and the monitored learning curve come from the first seed of the run, whatever it is
    assert [(j[3], j[7], j[8]) for j in jobs[::2]] == [(5, True, True), (6, False, False), (7, False, False)]
    assert all(j[0] is train_one and j[4:7] == ("s.h5", "t.h5", 80) for j in jobs)
    for bad in (-1, 1.5, True):
        with pytest.raises(ParameterError, match="first_seed"):
            run_benchmark(tmp_path / "out", first_seed=bad, progress=False)
    with pytest.raises(ParameterError, match="seeds"):
        run_benchmark(tmp_path / "out", seeds=0, progress=False)
    with pytest.raises(ParameterError, match="'dann'"):
        run_benchmark(tmp_path / "out", methods=("dann",), progress=False)
    assert not (tmp_path / "out").exists()


def _run(method, seed, acc, drop=None):
    return RunResult("wear", method, seed, acc, acc, 1.0, 10.0, [[1]], [], class_prior_drop=drop)


def test_summarise_pairs_methods_by_seed():
    runs = [_run("cnn", s, a) for s, a in enumerate([0.80, 0.82, 0.81])]
    runs += [_run("mmd", s, a, 0.0) for s, a in enumerate([0.90, 0.91, 0.93])]
    # fit warns above a 4-point drop of confidence: seeds 1 and 2
    runs += [_run("proposed", s, a, d) for s, a, d in zip(range(3), [0.91, 0.90, 0.95], [0.039, 0.041, 0.2])]
    s = summarise(runs)["wear"]
    assert s["methods"]["mmd"]["mean"] == pytest.approx(0.9133333, abs=1e-6)
    assert s["methods"]["cnn"]["std"] == pytest.approx(0.01, abs=1e-9)
    d = s["paired"]["proposed-mmd"]
    assert d["mean_diff"] == pytest.approx(0.0066667, abs=1e-6) and d["wins"] == 2 and d["n"] == 3
    assert s["paired"]["mmd-cnn"]["paired_t_p"] < 0.05
    assert [s["methods"][m]["class_prior_warnings"] for m in ("cnn", "mmd", "proposed")] == [None, 0, 2]
    table = markdown_table(summarise(runs))
    assert "| wear | mmd | 91.3 +- 1.5 |" in table and "| wear | proposed-mmd | +0.7 | 2/3 |" in table
    rows = {line.split(" | ")[1]: line for line in table.splitlines() if line.startswith("| wear | ")}
    assert rows["cnn"].endswith("| n/a | n/a |") and rows["mmd"].endswith("| 0/3 | n/a |")
    assert rows["proposed"].endswith("| 2/3 | n/a |")


def test_the_report_draws_its_figures_from_the_runs_first_seed(tmp_path, monkeypatch):
    """A run of seeds 3-4 (``first_seed=3``): the figures show seed 3, whose jobs alone carry
    features and learning curves, and say so in their titles."""
    import json

    from twin.transfer import benchmark, report

    rng = np.random.default_rng(0)
    history = [{"epoch": 1, "loss": 1.0, "cls": 1.0, "align": 0.0, "con": 0.0, "source_acc": 0.5, "gate": 0.0,
                "lr": 0.01, "monitor_acc": 0.4}]

    def run(method, seed):
        first = seed == 3
        emb = ({"source": rng.normal(size=(20, 6)), "source_stage": np.repeat([0, 1], 10),
                "target": rng.normal(size=(12, 6)), "target_stage": np.repeat([0, 1], 6)} if first else {})
        confusion = [[6, 0], [0, 6]] if first else [[0, 6], [6, 0]]
        return RunResult("wear", method, seed, 0.9, 0.9, 1.0, 10.0, confusion, history if first else [], emb)

    results = [run(m, s) for s in (3, 4) for m in ("mmd", "proposed")]
    drawn = {}
    for name in ("plot_confusion", "plot_learning_curves", "plot_tsne"):
        def spy(panels, path, title="", _name=name, _real=getattr(report, name)):
            drawn[_name] = (dict(panels), title)
            return _real(panels, path, title)
        monkeypatch.setattr(report, name, spy)
    benchmark._write_outputs(tmp_path, results, summarise(results), 1, 1.0, {"wear": TASK_SETTINGS["wear"]}, 3)
    confusion, title = drawn["plot_confusion"]
    assert set(confusion) == {"mmd", "proposed"} and "seed 3" in title
    assert all(np.array_equal(c, [[6, 0], [0, 6]]) for c in confusion.values())
    curves, title = drawn["plot_learning_curves"]
    assert all(h == history for h in curves.values()) and "seed 3" in title
    assert set(drawn["plot_tsne"][0]) == {"mmd", "proposed"} and "seed 3" in drawn["plot_tsne"][1]
    for name in ("confusion_wear.png", "curves_wear.png", "tsne_wear.png", "report.html", "summary.md"):
        assert (tmp_path / name).stat().st_size > 0
    saved = json.loads((tmp_path / "results.json").read_text())
    assert sorted((r["seed"], r["method"]) for r in saved["runs"]) == [(3, "mmd"), (3, "proposed"),
                                                                        (4, "mmd"), (4, "proposed")]


def test_stage_order_scores_tell_one_stage_late_from_random():
    from twin.transfer.benchmark import stage_order_scores

    late = [[0, 10, 0, 0], [0, 0, 10, 0], [0, 0, 0, 10], [0, 0, 0, 10]]     # every stage read one too late
    within, rho = stage_order_scores(late)
    assert within == 1.0
    # hand-computed: 40 windows, true ranks 0..3 in blocks of 10, assessed 1, 2, 3, 3
    t = np.repeat([0, 1, 2, 3], 10).astype(float)
    a = np.repeat([1, 2, 3, 3], 10).astype(float)
    from scipy.stats import rankdata
    assert rho == pytest.approx(np.corrcoef(rankdata(t), rankdata(a))[0, 1])
    swapped = [[0, 0, 0, 10], [0, 0, 10, 0], [0, 10, 0, 0], [10, 0, 0, 0]]   # the order reversed
    within, rho = stage_order_scores(swapped)
    assert within == 0.5 and rho == pytest.approx(-1.0)
    assert np.isnan(stage_order_scores([[5, 0], [5, 0]])[1])                 # one verdict for all: no order
    with pytest.raises(ParameterError, match="square"):
        stage_order_scores([[1, 2, 3]])
    runs = [RunResult("wear", "mmd", s, 0.25, 0.25, 1.0, 1.0, late, []) for s in range(2)]
    assert "| 100.0 | 0.95 |" in markdown_table(summarise(runs))


def test_summary_reads_the_seeds_agreement_on_the_rig_windows():
    stages = [(0, 1, 2, 2), (0, 1, 1, 2), (1, 1, 1, 2)]      # pairs agree on 3/4, 2/4, 3/4 of the windows
    runs = [RunResult("wear", "mmd", s, 0.5, 0.5, 1.0, 1.0, [[1]], [], window_stages=w) for s, w in enumerate(stages)]
    s = summarise(runs)["wear"]["methods"]["mmd"]
    assert s["seed_agreement"] == pytest.approx(2 / 3)
    assert markdown_table(summarise(runs)).splitlines()[2].endswith("| 66.7 (83.3) |")
    # one seed, or runs without stages (older results): no figure
    assert summarise(runs[:1])["wear"]["methods"]["mmd"]["seed_agreement"] is None
    assert summarise([_run("mmd", s, 0.5) for s in range(2)])["wear"]["methods"]["mmd"]["seed_agreement"] is None
    assert markdown_table(summarise(runs[:1])).splitlines()[2].endswith("| n/a |")


def test_the_archive_gets_each_tasks_tooth_errors(tmp_path, monkeypatch):
    """The data settings' gear bounds reach the archive block that build_archive reads."""
    import twin.archive
    import twin.degradation_run
    import twin.scenario
    import twin.transfer.domain
    from twin.transfer.benchmark import prepare_task

    seen = {}

    def build_archive(sc, path, **kw):
        keys = twin.archive.TOOTH_ERROR_KEYS + twin.archive.WHEEL_ERROR_KEYS
        seen[path.name] = ({k: sc.archive.get(k) for k in keys}, kw["fmu_path"].name)
        path.write_text("source")

    def make_target_domain(sc, path, **kw):
        seen[path.name] = kw["fmu_path"].name
        path.write_text("t")

    monkeypatch.setattr(twin.scenario.Scenario, "fmu_path", lambda self: tmp_path / f"{self.fmu}.fmu")
    monkeypatch.setattr(twin.archive, "build_archive", build_archive)
    monkeypatch.setattr(twin.degradation_run, "run_degradation", lambda *a, **kw: None)
    monkeypatch.setattr(twin.transfer.domain, "make_target_domain", make_target_domain)
    prepare_task("pitting", tmp_path, progress=False)
    prepare_task("wear", tmp_path, replace(TASK_SETTINGS["wear"], source_runout=0.0, source_wheel_runout=5e-6),
                 progress=False)
    assert seen["source_pitting.h5"] == ({"pitch_error": 0.0, "runout": 10e-6, "tooth_damage_scatter": 0.5,
                                          "wheel_pitch_error": 0.0, "wheel_runout": 0.0}, "GearTwin.Gearbox21.fmu")
    # gears of their own: the source comes from the variant that has them, the target does not
    assert seen["source_wear.h5"] == ({"pitch_error": 2e-6, "runout": 0.0, "tooth_damage_scatter": 0.1,
                                       "wheel_pitch_error": 0.0, "wheel_runout": 5e-6},
                                      "GearTwin.Variants.Gearbox21WheelErrors.fmu")
    assert seen["target_wear.h5"] == seen["target_pitting.h5"] == "GearTwin.Gearbox21.fmu"


def test_prepare_task_keeps_each_rigs_data_apart_and_reuses_it(tmp_path, monkeypatch):
    """The cache logic only: the simulations are replaced by recorders that write marker files."""
    import twin.archive
    import twin.degradation_run
    import twin.scenario
    import twin.transfer.benchmark_data
    import twin.transfer.domain
    from twin.transfer.benchmark import prepare_task

    calls = []

    def build_archive(sc, path, **kw):
        calls.append(("source", path.name))
        path.write_text(f"{sc.archive['records_per_stage']}")

    def make_target_domain(sc, path, *, shift, seed, **kw):
        calls.append(("target", path.name))
        path.write_text(f"{shift.resonance_hz} {seed}")

    monkeypatch.setattr(twin.scenario.Scenario, "fmu_path", lambda self: tmp_path / "model.fmu")
    monkeypatch.setattr(twin.archive, "build_archive", build_archive)
    monkeypatch.setattr(twin.degradation_run, "run_degradation", lambda *a, **kw: None)
    monkeypatch.setattr(twin.transfer.domain, "make_target_domain", make_target_domain)

    rig = prepare_task("wear", tmp_path, progress=False)
    blind = prepare_task("wear", tmp_path, rig_settings("wear", "blind"), progress=False)
    assert [p.name for p in rig] == ["source_wear.h5", "target_wear.h5"]
    assert [p.name for p in blind] == ["source_wear_blind.h5", "target_wear_blind.h5"]
    assert blind[1].read_text() == f"{RIGS['blind'].resonance_hz} 2" and rig[1].read_text() == f"{RIGS['rig'].resonance_hz} 1"
    n = len(calls)
    assert prepare_task("wear", tmp_path, progress=False) == rig and len(calls) == n      # reused, not rebuilt
    changed = replace(TASK_SETTINGS["wear"], source_records_per_stage=3)
    prepare_task("wear", tmp_path, changed, progress=False)                                  # new settings: rebuilt
    assert calls[n:] == [("source", "source_wear.h5"), ("target", "target_wear.h5")]
    assert rig[0].read_text() == "3" and blind[0].read_text() == "32"                       # the blind pair untouched
    # data built under other archive rules (the same settings, older code) are rebuilt too
    monkeypatch.setattr(twin.transfer.benchmark_data, "ARCHIVE_RULES", twin.transfer.benchmark_data.ARCHIVE_RULES + 1)
    n = len(calls)
    prepare_task("wear", tmp_path, rig_settings("wear", "blind"), progress=False)
    assert calls[n:] == [("source", "source_wear_blind.h5"), ("target", "target_wear_blind.h5")]


def test_another_rigs_records_are_the_file_given_never_simulated_by_the_twin(tmp_path, monkeypatch):
    import twin.archive
    import twin.degradation_run
    import twin.scenario
    import twin.transfer.domain
    from twin.transfer.benchmark import prepare_task

    def refuse(*a, **kw):
        raise AssertionError("another rig's records must not come from the twin's degradation or target domain")

    monkeypatch.setattr(twin.scenario.Scenario, "fmu_path", lambda self: tmp_path / "model.fmu")
    monkeypatch.setattr(twin.archive, "build_archive", lambda sc, path, **kw: path.write_text("source"))
    monkeypatch.setattr(twin.degradation_run, "run_degradation", refuse)
    monkeypatch.setattr(twin.transfer.domain, "make_target_domain", refuse)
    records = tmp_path / "lumped_records.h5"
    records.write_text("lumped")
    settings = rig_settings("pitting", "lumped", target_seed=3)
    assert settings.target_seed == 3 and settings.rig == "lumped"
    src, tgt = prepare_task("pitting", tmp_path, settings, progress=False, target=records)
    assert (src.name, tgt) == ("source_pitting_lumped.h5", records) and records.read_text() == "lumped"
    with pytest.raises(ParameterError, match="'lumped'"):          # no file for a rig simulated elsewhere
        prepare_task("pitting", tmp_path, settings, progress=False)
    with pytest.raises(ParameterError, match="'blind'"):           # an emulated rig is simulated here
        prepare_task("pitting", tmp_path, rig_settings("pitting", "blind"), progress=False, target=records)
    with pytest.raises(ParameterError, match="missing.h5"):
        prepare_task("pitting", tmp_path, settings, progress=False, target=tmp_path / "missing.h5")


def _rig_file(tmp_path, name, shuffle_labels=False):
    from twin.measurements import MeasurementSet, write_measurements

    from .conftest import make_records

    recs = make_records(8, shifted=True, seed=2, duration=0.768)
    if shuffle_labels:       # each record keeps one label for both halves, unrelated to its signal
        import numpy as np
        labels = np.random.default_rng(0).permutation([r.label for r in recs])
        recs = [replace(r, label=int(k)) for r, k in zip(recs, labels)]
    return write_measurements(MeasurementSet(tuple(recs), None, (), {}), tmp_path / name)


def test_target_ceiling_trains_on_the_rigs_first_halves_and_scores_the_second(tmp_path, monkeypatch, tiny_pre):
    from twin.transfer import benchmark
    from twin.transfer.assessor import Assessor

    monkeypatch.setattr(benchmark, "task_preprocessing", lambda task: tiny_pre)
    seen = {}
    fit, score = Assessor.fit, Assessor.score

    def spy_fit(self, source, target, **kw):
        seen["fit"] = [(r.time_start, r.n_samples, r.label) for r in source]
        seen["fit_target_labels"] = {r.label for r in target}
        return fit(self, source, target, **kw)

    def spy_score(self, data, labels=None):
        seen["score"] = [(r.time_start, r.n_samples) for r in data]
        return score(self, data, labels)

    monkeypatch.setattr(Assessor, "fit", spy_fit)
    monkeypatch.setattr(Assessor, "score", spy_score)
    acc = benchmark.target_ceiling("wear", str(_rig_file(tmp_path, "rig.h5")), seed=0, epochs=6)
    assert all(t0 == 0 and n == 384 and k is not None for t0, n, k in seen["fit"])
    assert seen["fit_target_labels"] == {None}
    assert all(t0 == pytest.approx(0.384) and n == 384 for t0, n in seen["score"])
    assert acc >= 0.9
    # the rig's labels are what it learns from: labels unrelated to the signals leave it near chance
    assert benchmark.target_ceiling("wear", str(_rig_file(tmp_path, "shuffled.h5", True)), seed=0, epochs=6) < 0.6


# two epochs leave the tiny rig's windows in one stage, so the match warns; the warning is not tested here
@pytest.mark.filterwarnings("ignore::twin.transfer.errors.ClassPriorWarning")
def test_train_one_uses_each_tasks_class_prior_rule(monkeypatch, tiny_pre, tiny_data):
    """Pitting is staged by the ordinal match, wear by the per-stage offsets."""
    from twin.transfer import benchmark
    from twin.transfer.assessor import Assessor

    monkeypatch.setattr(benchmark, "task_preprocessing", lambda task: tiny_pre)
    monkeypatch.setattr(benchmark, "load_task_data", lambda *args: tiny_data)
    seen = {}
    fit = Assessor.fit

    def spy_fit(self, source, target, **kw):
        out = fit(self, source, target, **kw)
        seen[self.class_prior] = (self.ordinal_anchors_, self.target_log_weights_)
        return out

    monkeypatch.setattr(Assessor, "fit", spy_fit)
    assert set(benchmark.TASK_CLASS_PRIOR) == set(benchmark.TASKS)
    for task in ("pitting", "wear"):
        benchmark.train_one(task, "mmd", 0, "s.h5", "t.h5", epochs=2, monitor=False)
    assert set(seen) == {"ordinal", "source"}
    assert seen["ordinal"][0].shape == (5,) and not np.any(seen["ordinal"][1])
    assert seen["source"][0] is None and np.any(seen["source"][1])
