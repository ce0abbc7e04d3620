"""The three CLI handlers, on tiny synthetic files (default 2048-sample windows, 1 epoch)."""
from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

from twin.measurements import Record, load_measurements, write_measurements
from twin.transfer.assessor import CLASS_PRIOR_WARN_DROP
from twin.transfer.cli import add_subcommands


def _parser():
    p = argparse.ArgumentParser()
    add_subcommands(p.add_subparsers(dest="command", required=True))
    return p


def _file(path, shifted, labelled):
    rng = np.random.default_rng(int(shifted))
    recs = []
    for k in range(2):
        for i in range(3):
            t = np.arange(6000) / 20000.0
            x = (1 + k) * np.sin(2 * np.pi * (300 + 200 * k) * t) + rng.normal(0, 0.2, t.size)
            recs.append(Record(f"s{k}r{i}", {"accel_pinion_casing": (2.0 if shifted else 1.0) * x},
                               {"accel_pinion_casing": "m/s2"}, 20000.0, label=k if labelled else None))
    return write_measurements(recs, path)


def test_rig_choices_are_the_benchmarks_rigs():
    from twin.transfer.benchmark import RIGS

    p = _parser()
    for rig in RIGS:
        assert p.parse_args(["benchmark-transfer", "--out", "x", "--rig", rig]).rig == rig
    with pytest.raises(SystemExit):
        p.parse_args(["benchmark-transfer", "--out", "x", "--rig", "garage"])
    choices = next(a.choices for a in p._subparsers._group_actions[0].choices["benchmark-transfer"]._actions
                   if a.dest == "rig")
    assert tuple(choices) == tuple(RIGS)


def test_registers_three_commands():
    p = _parser()
    assert p.parse_args(["assess", "a", "m.h5"]).handler.__name__ == "_cmd_assess"
    args = p.parse_args(["benchmark-transfer", "--out", "x"])
    assert (args.seeds, args.first_seed, args.task, args.epochs) == (5, 0, "both", 80)
    assert p.parse_args(["benchmark-transfer", "--out", "x", "--first-seed", "5"]).first_seed == 5
    with pytest.raises(SystemExit):
        p.parse_args(["train-assessor", "--source", "s.h5", "--target", "t.h5", "--out", "o", "--method", "dann"])


def test_train_then_assess(tmp_path, capsys):
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, True)
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "model"), "--epochs", "1", "--method", "mmd", "--no-progress"])
    assert args.handler(args) == 0
    args = p.parse_args(["assess", str(tmp_path / "model"), str(tgt), "--json", str(tmp_path / "stages.json")])
    assert args.handler(args) == 0
    out = json.loads((tmp_path / "stages.json").read_text())
    assert out["n_stages"] == 2 and len(out["records"]) == 6
    r = out["records"][0]
    assert {"name", "stage", "confidence", "windows", "label"} <= set(r)
    assert len(r["windows"]) == (6000 - 2048) // 1024 + 1      # 0.3 s at 20 kHz, hop 1024
    out = capsys.readouterr().out
    assert "accuracy" in out and f"learning curves: {tmp_path / 'model' / 'learning_curves.png'}" in out
    assert (tmp_path / "model" / "learning_curves.png").read_bytes()[:4] == b"\x89PNG"


def test_assess_writes_a_report_and_refuses_a_bad_report_path_before_any_work(tmp_path, capsys):
    from twin.errors import OutputPathError
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, True)
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "model"), "--epochs", "1", "--method", "cnn", "--no-progress"])
    assert args.handler(args) == 0
    capsys.readouterr()
    args = p.parse_args(["assess", str(tmp_path / "model"), str(tgt), "--report", str(tmp_path / "rep")])
    assert args.handler(args) == 0
    assert f"report -> {tmp_path / 'rep' / 'report.html'}" in capsys.readouterr().out
    page = (tmp_path / "rep" / "report.html").read_text()
    assert "stages.png" in page and "confusion.png" in page and "s1r2" in page
    (tmp_path / "afile").write_text("keep")
    for bad, match in ((tmp_path / "no" / "rep", "does not exist"), (tmp_path / "afile", "is not a directory")):
        args = p.parse_args(["assess", str(tmp_path / "nomodel"), str(tgt), "--report", str(bad)])
        with pytest.raises(OutputPathError, match=match):
            args.handler(args)
    assert capsys.readouterr().out == "" and (tmp_path / "afile").read_text() == "keep"


def test_shaft_speed_and_remove_level_reach_the_saved_preprocessing(tmp_path):
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, True)
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "model"), "--epochs", "1", "--method", "cnn", "--shaft-speed", "10",
                         "--remove-level", "--no-progress"])
    assert args.handler(args) == 0
    cfg = json.loads((tmp_path / "model" / "config.json").read_text())
    assert cfg["preprocessing"]["sample_rate"] == 10240.0               # 2048 samples = 0.2 s = 2 revolutions
    assert cfg["preprocessing"]["remove_level"] is True
    args = p.parse_args(["assess", str(tmp_path / "model"), str(tgt), "--json", str(tmp_path / "stages.json")])
    assert args.handler(args) == 0
    out = json.loads((tmp_path / "stages.json").read_text())
    assert len(out["records"][0]["windows"]) == (3072 - 2048) // 1024 + 1   # 0.3 s at 10.24 kHz


def test_train_to_missing_directory_fails_early(tmp_path):
    from twin.errors import OutputPathError
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", "s.h5", "--target", "t.h5", "--out",
                         str(tmp_path / "no" / "model")])
    with pytest.raises(OutputPathError, match="no"):
        args.handler(args)


def test_assess_checks_its_json_path_before_it_loads_or_prints_anything(tmp_path, capsys):
    from twin.errors import OutputPathError
    p = _parser()
    # the assessor and measurements do not exist either: the output path is refused first
    for bad, match in ((tmp_path / "no" / "stages.json", "does not exist"), (tmp_path, "is a directory")):
        args = p.parse_args(["assess", str(tmp_path / "model"), str(tmp_path / "m.h5"), "--json", str(bad)])
        with pytest.raises(OutputPathError, match=match):
            args.handler(args)
    assert capsys.readouterr().out == ""
    assert not (tmp_path / "no").exists()


def test_class_prior_choice_reaches_the_saved_assessor(tmp_path, capsys):
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, True)
    p = _parser()
    saved = {}
    for name, flag in (("source", []), ("none", ["--no-class-prior"]), ("ordinal", ["--class-prior", "ordinal"])):
        out = tmp_path / name
        args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out", str(out),
                             "--epochs", "1", "--method", "mmd", "--no-progress", *flag])
        assert args.handler(args) == 0
        saved[name] = json.loads((out / "config.json").read_text())
    assert saved["source"]["params"]["class_prior"] == "source"
    assert any(w != 0 for w in saved["source"]["target_log_weights"]) and saved["source"]["ordinal_anchors"] is None
    assert saved["none"]["params"]["class_prior"] is None
    assert saved["none"]["target_log_weights"] == [0.0, 0.0]
    assert saved["ordinal"]["params"]["class_prior"] == "ordinal"
    assert saved["ordinal"]["target_log_weights"] == [0.0, 0.0] and len(saved["ordinal"]["ordinal_anchors"]) == 3
    assert "ordinal class-prior match: rig adaptation windows per stage" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out", "x",
                      "--class-prior", "median"])
    with pytest.raises(SystemExit):      # one or the other, not a silent winner
        p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out", "x",
                      "--class-prior", "ordinal", "--no-class-prior"])


def test_train_assessor_reports_the_class_prior_match_and_warns_on_one_stage_rig_data(tmp_path, capsys):
    """A rig file holding only stage 0 breaks the match's assumption; the CLI says so on stdout, as
    one 'warning:' line naming the switch, not as a Python traceback-style warning.  20 epochs, so the
    network reads the stage with confidence and the match has to take it away (after 2 epochs it is
    unsure, and moving its windows costs too little confidence to warn)."""
    src = _file(tmp_path / "src.h5", False, True)
    one_stage = [r for r in load_measurements(_file(tmp_path / "all.h5", True, False)).records if r.name.startswith("s0")]
    tgt = write_measurements(one_stage, tmp_path / "tgt.h5")
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "model"), "--epochs", "20", "--method", "mmd", "--no-progress"])
    assert args.handler(args) == 0
    out, err = capsys.readouterr()
    assert "class-prior match: rig adaptation windows per stage" in out
    assert "changed stage; mean confidence -" in out
    assert "warning: the class-prior match lowered the mean confidence" in out and "--no-class-prior" in out
    assert "ClassPriorWarning" not in err
    cfg = json.loads((tmp_path / "model" / "config.json").read_text())
    assert cfg["class_prior_confidence_drop"] > CLASS_PRIOR_WARN_DROP
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "plain"), "--epochs", "2", "--method", "mmd", "--no-progress",
                         "--no-class-prior"])
    assert args.handler(args) == 0
    out = capsys.readouterr().out
    assert "class-prior match" not in out and "warning" not in out


def test_the_papers_contrastive_pairing_and_weighting_reach_the_saved_assessor(tmp_path):
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, False)
    p = _parser()
    base = ["train-assessor", "--source", str(src), "--target", str(tgt), "--epochs", "1", "--no-progress"]
    args = p.parse_args(base + ["--out", str(tmp_path / "default")])
    assert (args.pairs, args.contrastive_reduction) == ("all", "mean")
    args = p.parse_args(base + ["--out", str(tmp_path / "paper"), "--pairs", "diagonal",
                                "--contrastive-reduction", "sum"])
    assert args.handler(args) == 0
    params = json.loads((tmp_path / "paper" / "config.json").read_text())["params"]
    assert (params["pairs"], params["contrastive_reduction"]) == ("diagonal", "sum")
    with pytest.raises(SystemExit):
        p.parse_args(base + ["--out", "x", "--contrastive-reduction", "median"])


def test_target_channel_reaches_the_saved_assessor_and_assess(tmp_path):
    src = _file(tmp_path / "src.h5", False, True)
    recs = [Record(r.name, {"acc_rig": r["accel_pinion_casing"]}, {"acc_rig": "m/s2"}, r.sample_rate, label=r.label)
            for r in load_measurements(_file(tmp_path / "tgt0.h5", True, True)).records]
    tgt = write_measurements(recs, tmp_path / "tgt.h5")
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                         str(tmp_path / "model"), "--epochs", "1", "--method", "cnn", "--target-channel", "acc_rig",
                         "--no-progress"])
    assert args.handler(args) == 0
    cfg = json.loads((tmp_path / "model" / "config.json").read_text())
    assert cfg["preprocessing"]["channel"] == "accel_pinion_casing"
    assert cfg["preprocessing"]["target_channel"] == "acc_rig"
    args = p.parse_args(["assess", str(tmp_path / "model"), str(tgt), "--json", str(tmp_path / "stages.json")])
    assert args.handler(args) == 0
    assert len(json.loads((tmp_path / "stages.json").read_text())["records"]) == 6


def test_agreement_of_two_seeds_and_its_refusals(tmp_path, capsys):
    from twin.transfer.errors import AssessorError

    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, False)
    p = _parser()
    for seed in (0, 1):
        args = p.parse_args(["train-assessor", "--source", str(src), "--target", str(tgt), "--out",
                             str(tmp_path / f"seed{seed}"), "--epochs", "1", "--method", "cnn", "--seed", str(seed),
                             "--no-progress"])
        assert args.handler(args) == 0
    capsys.readouterr()
    out = tmp_path / "agree.json"
    args = p.parse_args(["agreement", str(tmp_path / "seed0"), str(tmp_path / "seed1"), str(tgt), "--json", str(out),
                         "--worst", "2"])
    assert args.handler(args) == 0
    saved = json.loads(out.read_text())
    assert saved["assessors"] == [str(tmp_path / "seed0"), str(tmp_path / "seed1")]
    assert saved["n_assessors"] == 2 and saved["n_records"] == 6 and len(saved["records"]) == 6
    # the same figure the library gives from the two assessments
    from twin.transfer import Assessor
    from twin.transfer.reliability import agreement
    res = agreement([Assessor.load(tmp_path / f"seed{s}").assess(tgt) for s in (0, 1)])
    assert saved["window_agreement"] == pytest.approx(res.window_agreement)
    assert saved["accuracy_bound"] == pytest.approx((1 + res.window_agreement) / 2)
    printed = capsys.readouterr().out
    assert f"at most {100 * res.accuracy_bound:.1f} %" in printed
    assert sum(line.startswith("  s") for line in printed.splitlines()) == 2       # --worst 2
    # the same network twice says nothing; one assessor is not an agreement; nothing is written
    out.unlink()
    import re
    same = re.escape(f"'{tmp_path / 'seed0'}' and '{tmp_path / 'seed0'}' hold the same network")
    for bad, message in (([str(tmp_path / "seed0"), str(tmp_path / "seed0")], same),
                         ([str(tmp_path / "seed0")], "at least 2 assessors")):
        args = p.parse_args(["agreement", *bad, str(tgt), "--json", str(out)])
        with pytest.raises(AssessorError, match=message):
            args.handler(args)
        assert not out.exists()
    args = p.parse_args(["agreement", str(tmp_path / "seed0"), str(tmp_path / "seed1"), str(tgt), "--worst", "-1"])
    with pytest.raises(AssessorError, match="--worst must be >= 0, got -1"):
        args.handler(args)


def test_rematch_stages_the_rig_by_another_rule_without_retraining(tmp_path, capsys):
    from twin.errors import OutputPathError
    from twin.transfer import Assessor
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, False)
    p = _parser()
    base = ["--source", str(src), "--target", str(tgt), "--epochs", "1", "--method", "mmd", "--no-progress"]
    for name, flag in (("source", []), ("ordinal", ["--class-prior", "ordinal"])):
        args = p.parse_args(["train-assessor", *base, "--out", str(tmp_path / name), *flag])
        assert args.handler(args) == 0
    capsys.readouterr()
    args = p.parse_args(["rematch", str(tmp_path / "source"), str(tgt), "--class-prior", "ordinal",
                         "--out", str(tmp_path / "re")])
    assert args.handler(args) == 0
    out = capsys.readouterr().out
    assert "mmd: class prior source -> ordinal, the same network" in out
    assert "ordinal class-prior match: rig adaptation windows per stage" in out
    re, direct = (json.loads((tmp_path / d / "config.json").read_text()) for d in ("re", "ordinal"))
    assert re["params"]["class_prior"] == "ordinal" and re["ordinal_anchors"] == direct["ordinal_anchors"]
    import torch
    w_re, w_src = (torch.load(tmp_path / d / "weights.pt", weights_only=True) for d in ("re", "source"))
    assert w_re.keys() == w_src.keys() and all(torch.equal(w_re[k], w_src[k]) for k in w_re)
    args = p.parse_args(["rematch", str(tmp_path / "re"), str(tgt), "--class-prior", "none",
                         "--out", str(tmp_path / "none")])
    assert args.handler(args) == 0
    assert "class prior ordinal -> none" in capsys.readouterr().out
    assert Assessor.load(tmp_path / "none").class_prior is None
    # the assessor being re-matched is never overwritten, and a bad --out is refused before any work
    before = (tmp_path / "source" / "config.json").read_bytes()
    for out_dir, match in ((tmp_path / "source", "is the assessor being re-matched"),
                           (tmp_path / "no" / "re", "does not exist")):
        args = p.parse_args(["rematch", str(tmp_path / "source"), str(tgt), "--class-prior", "none",
                             "--out", str(out_dir)])
        with pytest.raises(OutputPathError, match=match):
            args.handler(args)
    assert (tmp_path / "source" / "config.json").read_bytes() == before
    with pytest.raises(SystemExit):
        p.parse_args(["rematch", str(tmp_path / "source"), str(tgt), "--class-prior", "median", "--out", "x"])
