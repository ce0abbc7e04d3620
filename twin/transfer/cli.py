"""Command-line handlers of the transfer-learning assessor (wired into ``twin`` by twin/cli.py).

``add_subcommands(sub)`` registers ``train-assessor``, ``rematch``, ``assess``, ``agreement`` and
``benchmark-transfer`` on the ``twin`` sub-parser object.  Handlers only parse and print; the work lives in
:mod:`twin.transfer`, imported inside each handler so ``twin --help`` stays free of torch.
"""
from __future__ import annotations

import argparse
import importlib
import json
from pathlib import Path


def _lib(name: str):
    return importlib.import_module(name)


def _cmd_train_assessor(args: argparse.Namespace) -> int:
    from twin.errors import OutputPathError
    from twin.measurements import load_measurements
    from twin.transfer.ensemble import train_ensemble
    out = Path(args.out)
    if not out.parent.is_dir():    # before minutes of training, not after
        raise OutputPathError(f"output directory '{out.parent}' does not exist (for '{out}')")
    source = Path(args.source)
    rig = load_measurements(Path(args.target), channels=[args.target_channel or args.channel])
    skip = {n.strip() for n in (args.exclude or "").split(",") if n.strip()}
    unknown = sorted(skip - set(rig.names))
    if unknown:
        from twin.transfer.errors import AssessorError
        raise AssessorError(f"--exclude: no record(s) {', '.join(unknown)} in {args.target}")
    records = [r for r in rig.records if r.name not in skip]
    if source.suffix.lower() in (".yaml", ".yml", ".json"):
        # a scenario (a calibrated one, say): its archive first, at the rig's operating point
        from twin._atomic import check_output_dir
        from twin.pipeline.run import archive_for_records
        from twin.scenario import load_scenario
        check_output_dir(out, "assessor ensemble", create=True)
        arc = out / "archive.h5"
        print(f"archive of {source} at the rig's operating point -> {arc}")
        archive_for_records(load_scenario(source), records, arc, jobs=args.jobs, progress=not args.no_progress)
        source = arc
    ens = train_ensemble(source, records, out, members=args.members, method=args.method, epochs=args.epochs,
                         first_seed=args.first_seed, jobs=args.jobs, channel=args.channel,
                         target_channel=args.target_channel, progress=not args.no_progress)
    f, pre = ens.facts, ens.preprocessing
    print(f"{args.method} ensemble of {len(ens.members)} (seeds {args.first_seed}-{args.first_seed + args.members - 1}) "
          f"trained in {ens.train_time_:.0f} s on {source} -> {out}")
    print(f"settings from the archive: {f.damage_kind} in {f.n_stages} stages at {f.nominal_speed:g} Hz / "
          f"{f.nominal_load:g} N.m; windows of two pinion revolutions ({pre.sample_rate:g} Hz), level "
          f"{'removed' if pre.remove_level else 'kept'}, class prior {ens.rule}")
    res = ens.assess(records)
    print(f"on its {len(records)} rig records: {res.verdict()}")
    print(res.order.message())
    return 0


def _print_ensemble(res) -> None:
    """The ensemble's verdict per record, then how far to trust it."""
    for r in res.records:
        lab = "" if r.label is None else f"  (label {r.label})"
        ordered = "" if r.ordered_stage is None else f", {r.ordered_stage} in time order"
        print(f"{r.name}: stage {r.stage}{ordered}, confidence {r.confidence:.2f}, members "
              f"{'/'.join(map(str, r.member_stages))} ({100 * r.agreement:.0f} % of windows alike){lab}")
    for n in res.notes:
        print(f"note: {n}")
    if res.records[0].ordered_stage is not None:
        print(f"time order ({res.time_order}): {res.moved_by_time_order} of {len(res.records)} records moved")
    scores = res.scores()
    if scores:
        print("accuracy: " + ", ".join(f"{k.replace('_', ' ')} {100 * v:.1f} %" for k, v in scores.items()))
    print(res.order.message())
    print(res.verdict())


def _print_match(a, notes) -> None:
    """What the class-prior match of the fitted assessor ``a`` did to the rig's adaptation windows,
    and the warnings ``notes`` caught while it was fitted, one 'warning:' line each."""
    if a.class_prior is not None and a.method != "cnn":
        before, after = (" / ".join(map(str, row)) for row in a.adaptation_stage_counts_)
        changed = f"{100 * a.class_prior_moved_:.1f} % changed stage"
        if a.class_prior == "source":
            print(f"class-prior match: rig adaptation windows per stage {before} -> {after} "
                  f"({changed}; mean confidence {-100 * a.class_prior_confidence_drop_:+.1f} points)")
        else:
            print(f"ordinal class-prior match: rig adaptation windows per stage {before} -> {after} ({changed}); "
                  f"stage boundaries along the expected stage "
                  + " ".join(f"{v:.2f}" for v in a.ordinal_anchors_[1::2]))
    for note in notes:
        print(f"warning: {note}")


def _cmd_rematch(args: argparse.Namespace) -> int:
    transfer = _lib("twin.transfer")
    from twin.errors import OutputPathError
    from twin.transfer.errors import class_prior_notes
    src, out = Path(args.assessor), Path(args.out)
    if not out.parent.is_dir():
        raise OutputPathError(f"output directory '{out.parent}' does not exist (for '{out}')")
    if out.resolve() == src.resolve():      # the assessor with its old rule is not to be lost
        raise OutputPathError(f"--out '{out}' is the assessor being re-matched; give a new directory")
    rule = None if args.class_prior == "none" else args.class_prior
    a = transfer.Assessor.load(src)
    with class_prior_notes() as notes:
        b = a.rematch(Path(args.target), rule)
    b.save(out)
    print(f"{a.method}: class prior {a.class_prior or 'none'} -> {b.class_prior or 'none'}, the same network, "
          f"{b.adaptation_stage_counts_.sum(1)[0]} rig adaptation windows -> {out}")
    _print_match(b, notes)
    return 0


def _cmd_assess(args: argparse.Namespace) -> int:
    transfer = _lib("twin.transfer")
    if args.json:
        from twin._atomic import check_parent
        check_parent(args.json)     # before the assessment is printed, not after
    if args.report:
        from twin._atomic import check_output_dir
        check_output_dir(args.report, "report")     # before the assessment, not after
    if (Path(args.assessor) / "ensemble.json").is_file():
        return _assess_ensemble(args)
    a = transfer.Assessor.load(Path(args.assessor))
    res = a.assess(Path(args.measurements))
    for r in res.records:
        lab = "" if r.label is None else f"  (label {r.label})"
        print(f"{r.name}: stage {r.stage}, confidence {r.confidence:.2f}, {len(r.window_stages)} windows{lab}")
    if res.record_accuracy is not None:
        print(f"accuracy: records {100 * res.record_accuracy:.1f} %, windows {100 * res.window_accuracy:.1f} %")
    if args.json:
        from twin._atomic import atomic_path
        with atomic_path(Path(args.json)) as tmp:
            Path(tmp).write_text(json.dumps(res.to_dict(), indent=1))
        print(f"stages -> {args.json}")
    if args.report:
        from twin.transfer.report import write_assessment_report
        page = write_assessment_report(res, args.report, f"{args.assessor} on {args.measurements}")
        print(f"report -> {page}")
    return 0


def _assess_ensemble(args: argparse.Namespace) -> int:
    from twin.transfer.ensemble import Ensemble
    ens = Ensemble.load(Path(args.assessor))
    res = ens.assess(Path(args.measurements), time_ordered={"auto": None, "yes": True, "no": False}[args.time_order])
    _print_ensemble(res)
    if args.json:
        from twin._atomic import atomic_path
        with atomic_path(Path(args.json)) as tmp:
            Path(tmp).write_text(json.dumps(res.to_dict(), indent=1))
        print(f"stages -> {args.json}")
    if args.report:
        from twin.pipeline.run import _plot_stages
        from twin.transfer.report import write_html
        d = Path(args.report)
        d.mkdir(exist_ok=True)
        png = _plot_stages(res, d / "stages.png")
        page = write_html(d / "report.html", f"{args.assessor} on {args.measurements}",
                          [("Verdict", res.verdict() + "\n" + res.order.message()), ("Stages", png.name)])
        print(f"report -> {page}")
    return 0


def _cmd_agreement(args: argparse.Namespace) -> int:
    transfer = _lib("twin.transfer")
    import numpy as np

    from twin.transfer.errors import AssessorError
    from twin.transfer.reliability import assessor_agreement
    if args.json:
        from twin._atomic import check_parent
        check_parent(args.json)
    if args.worst < 0:
        raise AssessorError(f"agreement: --worst must be >= 0, got {args.worst}")
    if len(args.assessors) < 2:
        raise AssessorError(f"agreement: at least 2 assessors needed, got {len(args.assessors)}")
    loaded = [transfer.Assessor.load(Path(d)) for d in args.assessors]
    res = assessor_agreement(loaded, Path(args.measurements), names=args.assessors)
    g = np.array(res.pairwise)
    off = g[~np.eye(len(g), dtype=bool)]
    print(f"{res.n_assessors} assessors, {res.n_records} records, {res.n_windows} windows: the same stage on "
          f"{100 * res.window_agreement:.1f} % of windows (pairs {100 * off.min():.1f}-{100 * off.max():.1f} %) and "
          f"{100 * res.record_agreement:.1f} % of records")
    print(f"so their mean window accuracy on these data is at most {100 * res.accuracy_bound:.1f} %, whatever the true "
          "stages (agreement is necessary for accuracy, not sufficient: members can agree and all be wrong)")
    worst = sorted(zip(res.per_record, res.record_names))[:args.worst]
    for share, name in worst:
        print(f"  {name}: windows agree {100 * share:.1f} %")
    if args.json:
        from twin._atomic import atomic_path
        with atomic_path(Path(args.json)) as tmp:
            Path(tmp).write_text(json.dumps({"assessors": list(args.assessors), **res.to_dict()}, indent=1))
        print(f"agreement -> {args.json}")
    return 0


def _cmd_benchmark_transfer(args: argparse.Namespace) -> int:
    bench = _lib("twin.transfer.benchmark")
    tasks = ("pitting", "wear") if args.task == "both" else (args.task,)
    rig, targets = args.rig, None
    if args.target:
        from twin.errors import ParameterError
        if len(tasks) != 1:
            raise ParameterError("--target holds the records of one task: give --task pitting or --task wear")
        # the rig is named after its file (the name tags the cached source archive beside it)
        rig = "".join(c if c.isalnum() or c in "_-" else "_" for c in Path(args.target).stem) or "target"
        rig = rig + "_file" if rig in bench.RIGS else rig
        targets = {tasks[0]: Path(args.target)}
    summary = bench.run_benchmark(Path(args.out), tasks=tasks, seeds=args.seeds, epochs=args.epochs,
                                  jobs=args.jobs, data_dir=Path(args.data_dir) if args.data_dir else None,
                                  rig=rig, progress=not args.no_progress, first_seed=args.first_seed,
                                  targets=targets)
    print(bench.markdown_table(summary))
    print(f"report -> {Path(args.out) / 'report.html'}")
    return 0


def add_subcommands(sub) -> None:
    """Register ``train-assessor``, ``rematch``, ``assess``, ``agreement`` and ``benchmark-transfer`` on
    ``sub`` (the object returned by ``parser.add_subparsers``)."""
    p = sub.add_parser("train-assessor", help="train an ensemble of transfer-learning assessors (twin -> rig); "
                                               "every setting follows from the archive")
    p.add_argument("--source", required=True,
                   help="the twin's labelled archive (twin archive), or a scenario (the calibrated.yaml of twin "
                        "calibrate, say), whose archive is then simulated first at the rig's operating point")
    p.add_argument("--target", required=True, help="the rig's unlabelled records, HDF5 (labels are never read)")
    p.add_argument("--out", required=True, help="directory to save the ensemble in (rerun to resume)")
    p.add_argument("--members", type=int, default=5,
                   help="assessors in the ensemble, seeds FIRST_SEED.. (default: 5; the cost is that many trainings, "
                        "run --jobs at a time)")
    p.add_argument("--method", choices=("proposed", "mmd", "cnn", "coral"), default="proposed",
                   help="proposed (MMD + class contrastive, default), mmd, cnn (source only), coral")
    p.add_argument("--epochs", type=int, default=80, help="passes over the source windows (default: 80)")
    p.add_argument("--first-seed", type=int, default=0, help="seed of the first member (default: 0)")
    p.add_argument("--jobs", type=int, default=2, help="members trained in parallel (default: 2)")
    p.add_argument("--exclude", metavar="RECORDS", help="comma-separated records of the target file not to adapt to "
                                                      "(its healthy run-up, say)")
    p.add_argument("--channel", default="accel_pinion_casing",
                   help="acceleration channel of the source archive (default: accel_pinion_casing)")
    p.add_argument("--target-channel", metavar="NAME",
                   help="the rig's name for that channel, if it differs; saved with the assessor, so `twin assess` "
                        "reads new rig files from it too")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.set_defaults(handler=_cmd_train_assessor)

    p = sub.add_parser("rematch", help="stage the rig by another class-prior rule without retraining (a copy of "
                                       "the assessor with the same network)")
    p.add_argument("assessor", metavar="ASSESSOR", help="directory written by train-assessor")
    p.add_argument("target", metavar="TARGET", help="the rig's unlabelled adaptation data given to train-assessor "
                                                    "(HDF5, or CSV + sidecar)")
    p.add_argument("--class-prior", choices=("source", "ordinal", "none"), required=True,
                   help="per-stage logit offsets (source), boundaries along the expected stage (ordinal), or no "
                        "match (none: for rig data far from the archive's stage proportions)")
    p.add_argument("--out", required=True, help="new directory for the re-matched assessor (not ASSESSOR)")
    p.set_defaults(handler=_cmd_rematch)

    p = sub.add_parser("assess", help="assess the wear stage of measurements with a trained assessor")
    p.add_argument("assessor", metavar="ASSESSOR", help="directory written by train-assessor")
    p.add_argument("measurements", metavar="MEASUREMENTS", help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--json", help="write stage and confidence per record and per window to this JSON file")
    p.add_argument("--report", metavar="DIR",
                   help="write stages.png (stage probabilities per record), confusion.png (when every record has "
                        "a label) and report.html into DIR")
    p.add_argument("--time-order", choices=("auto", "yes", "no"), default="auto",
                   help="an ensemble's use of the records' time order (damage does not heal): auto (default) when "
                        "they carry time stamps (time_start, cycles), yes for records given in time order, no never")
    p.set_defaults(handler=_cmd_assess)

    p = sub.add_parser("agreement", help="how often assessors trained with other seeds agree on measurements "
                                         "(no labels needed): an upper bound on their accuracy")
    p.add_argument("assessors", metavar="ASSESSOR", nargs="+",
                   help="two or more directories written by train-assessor (same data, other --seed)")
    p.add_argument("measurements", metavar="MEASUREMENTS", help="measurement HDF5 (or CSV + sidecar)")
    p.add_argument("--worst", type=int, default=5, help="records with the least agreement to list (default: 5)")
    p.add_argument("--json", help="write the agreement (pairwise and per record) to this JSON file")
    p.set_defaults(handler=_cmd_agreement)

    p = sub.add_parser("benchmark-transfer", help="CNN vs MMD vs proposed on twin -> emulated rig, over seeds")
    p.add_argument("--out", required=True, help="output directory (results.json, summary.md, report.html)")
    p.add_argument("--seeds", type=int, default=5, help="seeds per method (default: 5)")
    p.add_argument("--first-seed", type=int, default=0,
                   help="first seed (default: 0); --first-seed 5 --seeds 5 adds seeds 5-9 to a 5-seed run")
    p.add_argument("--task", choices=("pitting", "wear", "both"), default="both")
    p.add_argument("--epochs", type=int, default=80, help="epochs per training run (default: 80)")
    p.add_argument("--jobs", type=int, default=2, help="training runs in parallel (default: 2)")
    p.add_argument("--data-dir", help="where the simulated source/target data are cached (default: OUT/data)")
    # The names of benchmark.RIGS, spelt out: importing it would pull numpy into ``twin --help``
    # (tests/twin/transfer/test_cli_transfer.py checks that the two agree).
    p.add_argument("--rig", choices=("rig", "blind"), default="rig",
                   help="emulated rig of the target data (a variant of the twin: plumbing only): the benchmark's "
                        "(default) or the blind one fixed after every setting was chosen")
    p.add_argument("--target", metavar="FILE",
                   help="instead of an emulated rig: the labelled records of another rig for the one --task (for "
                        "example written by 'python -m rigs.lumped target' or 'python -m rigs.ltca target')")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.set_defaults(handler=_cmd_benchmark_transfer)
