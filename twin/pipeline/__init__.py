"""``twin pipeline``: calibrate on a rig's healthy records, simulate, train, assess, RUL, one report.

The work is in :mod:`twin.pipeline.run`; this module registers the command line
(:func:`add_subcommands`) and forwards the public names lazily, so ``twin --help`` imports no numpy.
"""
from __future__ import annotations

import argparse
import importlib
from pathlib import Path

from twin.commands.common import path_pair

_PUBLIC = ("PipelinePlan", "STAGES", "run_pipeline", "healthy_roles", "archive_for_records")

__all__ = [*_PUBLIC, "add_subcommands"]


def __getattr__(name: str):
    if name in _PUBLIC:
        return getattr(importlib.import_module("twin.pipeline.run"), name)
    raise AttributeError(f"module 'twin.pipeline' has no attribute {name!r}")


def _cmd_pipeline(args: argparse.Namespace) -> int:
    run = importlib.import_module("twin.pipeline.run")
    healthy = tuple(n.strip() for n in args.healthy.split(",") if n.strip())
    plan = run.PipelinePlan(Path(args.measurements), healthy, Path(args.scenario), Path(args.out),
                            members=args.members, epochs=args.epochs, jobs=args.jobs,
                            calibrate=not args.no_calibration,
                            time_ordered=True if args.time_ordered else None,
                            extra=Path(args.assess) if args.assess else None,
                            path_from=tuple(args.path_from or ()))
    run.run_pipeline(plan, progress=not args.no_progress)
    return 0


def add_subcommands(sub) -> None:
    """Register ``twin pipeline`` on an argparse sub-parser collection (``parser.add_subparsers()``)."""
    p = sub.add_parser("pipeline", help="calibrate on healthy rig records -> degradation run -> archive -> train an "
                                        "ensemble -> assess -> RUL -> one HTML report (resumable)")
    p.add_argument("measurements", metavar="RIG.h5", help="the rig's records: healthy ones and the ones to assess")
    p.add_argument("--healthy", required=True, metavar="RECORDS",
                   help="comma-separated names of the healthy records: a run-up (or hammer test) and a steady record")
    p.add_argument("--scenario", required=True, help="the test's scenario, e.g. scenarios/lubricated.yaml (pitting) "
                                                     "or scenarios/dry.yaml (wear)")
    p.add_argument("--out", required=True, help="output directory; run again to resume")
    p.add_argument("--members", type=int, default=5, help="assessors in the ensemble (default: 5)")
    p.add_argument("--epochs", type=int, default=80, help="training epochs per assessor (default: 80)")
    p.add_argument("--jobs", type=int, default=2, help="parallel processes (default: 2)")
    p.add_argument("--time-ordered", action="store_true",
                   help="the records are in time order in the file (a run-to-failure history); without it, the "
                        "records' own time stamps (time_start, cycles) decide")
    p.add_argument("--assess", metavar="FILE", help="more records of the same rig to assess with the trained ensemble")
    p.add_argument("--path-from", metavar="RECORD=FORCE", type=path_pair, action="append",
                   help="a healthy hammer record struck at a bearing housing and the model's bearing force its blow "
                        "stands for (e.g. hammer_pinion=bearing_force_input_y; repeat per record): the twin's sensors "
                        "then read its bearing forces through the measured path, in the calibration and the archive")
    p.add_argument("--no-calibration", action="store_true",
                   help="use the scenario's twin as it is, uncalibrated (to see what calibration adds)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bars")
    p.set_defaults(handler=_cmd_pipeline)
