"""The three CLI handlers, on tiny synthetic files (default 2048-sample windows, 1 epoch)."""
from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

from twin.measurements import Record, load_measurements, write_measurements
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


def _single(out, src, tgt, method="mmd", seed=0, class_prior="source", epochs=1):
    """One assessor trained through the API (train-assessor trains ensembles): what rematch and
    agreement take."""
    import warnings

    from twin.transfer import Assessor
    from twin.transfer.errors import ClassPriorWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClassPriorWarning)
        Assessor(method, epochs=epochs, seed=seed, progress=False, class_prior=class_prior).fit(src, tgt).save(out)
    return out


def _archive_and_rig(tmp_path, channel="accel_pinion_casing"):
    from .conftest import rig_records, write_tiny_archive
    recs = [Record(r.name, {channel: r["accel_pinion_casing"]}, {channel: "m/s2"}, r.sample_rate,
                   nominal_speed=r.nominal_speed, load=r.load, label=r.label) for r in rig_records(per_stage=2)]
    return write_tiny_archive(tmp_path / "arc.h5"), write_measurements(recs, tmp_path / "rig.h5")


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


def test_train_assessor_with_no_options_trains_an_ensemble_with_the_archives_settings(tmp_path, capsys):
    arc, rig = _archive_and_rig(tmp_path)
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(arc), "--target", str(rig), "--out", str(tmp_path / "ens"),
                         "--members", "2", "--epochs", "1", "--jobs", "1", "--no-progress"])
    assert (args.members, args.method, args.first_seed) == (2, "proposed", 0)
    assert args.handler(args) == 0
    out = capsys.readouterr().out
    assert "proposed ensemble of 2 (seeds 0-1)" in out
    assert "pitting_density in 3 stages at 20 Hz / 20 N.m" in out and "level removed, class prior ordinal" in out
    assert "resampled from 25000 Hz to 20480 Hz" in out
    assert ("reliable" in out or "NOT RELIABLE" in out) and "stage order" in out
    cfg = json.loads((tmp_path / "ens" / "ensemble.json").read_text())
    assert cfg["members"] == ["member_0", "member_1"]
    assert json.loads((tmp_path / "ens" / "member_0" / "config.json").read_text())["preprocessing"][
        "sample_rate"] == pytest.approx(20480.0)
    args = p.parse_args(["assess", str(tmp_path / "ens"), str(rig), "--json", str(tmp_path / "stages.json"),
                         "--report", str(tmp_path / "rep")])
    assert args.handler(args) == 0
    saved = json.loads((tmp_path / "stages.json").read_text())
    assert saved["n_members"] == 2 and len(saved["records"]) == 6 and "verdict" in saved and saved["scores"]
    out = capsys.readouterr().out
    assert "members" in out and "accuracy:" in out and "report ->" in out
    assert (tmp_path / "rep" / "stages.png").read_bytes()[:4] == b"\x89PNG"
    # records of another test are refused by name, and --exclude names only records that exist
    from twin.transfer.errors import AssessorError
    args = p.parse_args(["train-assessor", "--source", str(arc), "--target", str(rig), "--out", str(tmp_path / "x"),
                         "--exclude", "rec00,nothere", "--no-progress"])
    with pytest.raises(AssessorError, match="nothere"):
        args.handler(args)
    assert not (tmp_path / "x").exists()


def test_assess_writes_a_report_and_refuses_a_bad_report_path_before_any_work(tmp_path, capsys):
    from twin.errors import OutputPathError
    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, True)
    p = _parser()
    _single(tmp_path / "model", src, tgt, method="cnn", class_prior=None)
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


def test_target_channel_reaches_the_saved_ensemble_and_assess(tmp_path):
    arc, rig = _archive_and_rig(tmp_path, channel="acc_rig")
    p = _parser()
    args = p.parse_args(["train-assessor", "--source", str(arc), "--target", str(rig), "--out", str(tmp_path / "ens"),
                         "--members", "2", "--epochs", "1", "--target-channel", "acc_rig", "--jobs", "1",
                         "--no-progress"])
    assert args.handler(args) == 0
    cfg = json.loads((tmp_path / "ens" / "member_1" / "config.json").read_text())
    assert cfg["preprocessing"]["channel"] == "accel_pinion_casing"
    assert cfg["preprocessing"]["target_channel"] == "acc_rig"
    args = p.parse_args(["assess", str(tmp_path / "ens"), str(rig), "--json", str(tmp_path / "stages.json")])
    assert args.handler(args) == 0
    assert len(json.loads((tmp_path / "stages.json").read_text())["records"]) == 6
    # records whose test does not fit: refused by name in one line, nothing written
    from dataclasses import replace

    from twin.transfer.errors import AssessorError
    recs = list(load_measurements(rig).records)
    recs[0], recs[3] = replace(recs[0], nominal_speed=10.0), replace(recs[3], load=5.0)
    bad = write_measurements(recs, tmp_path / "misfit.h5")
    args = p.parse_args(["assess", str(tmp_path / "ens"), str(bad), "--json", str(tmp_path / "bad.json")])
    with pytest.raises(AssessorError, match=r"^assess: 2 record\(s\) do not fit .*'rec00' \(speed 10 Hz\), "
                                            r"'rec03' \(load 5 N.m\)[^\n]*$"):
        args.handler(args)
    assert not (tmp_path / "bad.json").exists()


def test_agreement_of_two_seeds_and_its_refusals(tmp_path, capsys):
    from twin.transfer.errors import AssessorError

    src = _file(tmp_path / "src.h5", False, True)
    tgt = _file(tmp_path / "tgt.h5", True, False)
    p = _parser()
    for seed in (0, 1):
        _single(tmp_path / f"seed{seed}", src, tgt, method="cnn", seed=seed, class_prior=None)
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
    for name in ("source", "ordinal"):
        _single(tmp_path / name, src, tgt, class_prior=name)
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
