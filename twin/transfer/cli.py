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
    transfer = _lib("twin.transfer")
    from twin.errors import OutputPathError
    out = Path(args.out)
    if not out.parent.is_dir():    # before minutes of training, not after
        raise OutputPathError(f"output directory '{out.parent}' does not exist (for '{out}')")
    settings = {"remove_level": args.remove_level, "channel": args.channel, "target_channel": args.target_channel}
    pre = (transfer.Preprocessing(**settings) if args.shaft_speed is None
           else transfer.Preprocessing.for_shaft_speed(args.shaft_speed, **settings))
    a = transfer.Assessor(args.method, epochs=args.epochs, seed=args.seed, preprocessing=pre,
                          progress=not args.no_progress, class_prior=None if args.no_class_prior else args.class_prior,
                          pairs=args.pairs, contrastive_reduction=args.contrastive_reduction)
    from twin.transfer.errors import class_prior_notes
    with class_prior_notes() as notes:
        a.fit(Path(args.source), Path(args.target))
    a.save(out)
    from twin.transfer.report import plot_learning_curves
    curves = plot_learning_curves({args.method: a.history_}, out / "learning_curves.png",
                                  f"{args.method}, seed {args.seed}: {args.source} -> {args.target}")
    last = a.history_[-1]
    print(f"{args.method}: {a.n_classes_} stages, {a.n_source_windows_} source / {a.n_target_windows_} target "
          f"windows, {len(a.history_)} epochs in {a.fit_time_:.0f} s; last epoch: loss {last['loss']:.3f}, "
          f"source accuracy {100 * last['source_acc']:.1f} % -> {out} (learning curves: {curves})")
    _print_match(a, notes)
    return 0


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
    p = sub.add_parser("train-assessor", help="train the transfer-learning wear assessor (twin -> rig)")
    p.add_argument("--source", required=True, help="labelled source archive HDF5 (twin archive)")
    p.add_argument("--target", required=True, help="unlabelled rig measurements HDF5 (labels are ignored)")
    p.add_argument("--out", required=True, help="directory to save the assessor in")
    p.add_argument("--method", choices=("proposed", "mmd", "cnn", "coral"), default="proposed",
                   help="proposed (MMD + class contrastive, default), mmd, cnn (source only), coral")
    p.add_argument("--pairs", choices=("all", "diagonal"), default="all",
                   help="source/target pairs of the class-contrastive loss: every pair of the batch (default) or "
                        "the paper's i-th with i-th")
    p.add_argument("--contrastive-reduction", choices=("mean", "sum"), default="mean",
                   help="mean over the pairs (default) or the paper's sum over the batch (Eq. 18), 20 times the "
                        "weight at batch 20; measured in docs/experiments.md and not the default")
    p.add_argument("--seed", type=int, default=0, help="seed of initialisation, batches, augmentation")
    p.add_argument("--epochs", type=int, default=80, help="passes over the source windows (default: 80)")
    p.add_argument("--shaft-speed", type=float, metavar="HZ",
                   help="nominal pinion speed of the test [Hz]: records are resampled so a 2048-sample window "
                        "spans two pinion revolutions (default: 20 kHz, about two revolutions at 20 Hz)")
    p.add_argument("--remove-level", action="store_true",
                   help="remove each window's level and keep only the spectral shape: for pitting, whose early "
                        "stages differ in level by less than the rig's gain scatter (the default keeps the level, "
                        "which carries deep wear)")
    p.add_argument("--channel", default="accel_pinion_casing",
                   help="acceleration channel of the source archive (default: accel_pinion_casing)")
    p.add_argument("--target-channel", metavar="NAME",
                   help="the rig's name for that channel, if it differs; saved with the assessor, so `twin assess` "
                        "reads new rig files from it too")
    match = p.add_mutually_exclusive_group()
    match.add_argument("--class-prior", choices=("source", "ordinal"), default="source",
                   help="how the rig's stage proportions are matched to the archive's: per-stage logit offsets "
                        "(source, default) or boundaries along the expected stage, which keep only the order of "
                        "the windows (ordinal; the benchmark's pitting rule, docs/transfer.md)")
    match.add_argument("--no-class-prior", action="store_true",
                   help="do not match the rig's stage proportions to the archive's after training (use it when the "
                        "rig data are mostly one stage, e.g. a run-to-failure history; default: match them)")
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
