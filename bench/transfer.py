"""Benchmark: transfer from the twin's archive to an emulated rig, CNN vs MMD vs proposed.

    python bench/transfer.py [--seeds 5] [--first-seed 0] [--task both] [--epochs 80] [--jobs 2] [--out bench_out/transfer]
                             [--rig rig|blind|lumped|ltca] [--source-ceiling | --target-ceiling]

Builds (or reuses, in OUT/data) the source archives of scenarios/lubricated.yaml (6 pitting
stages) and scenarios/dry.yaml (4 wear stages) and their "measured" target domains
(twin.transfer.domain.make_target_domain for the emulated rigs 'rig' and 'blind', variants of the
twin that prove plumbing only; rigs.lumped / rigs.ltca for the independent simulators, whose records
are written here and handed to the twin as files), then trains every method with the paper's settings
(alpha = beta = 0.1, lr 0.01, batch 20, 80 epochs) for each seed and scores the last epoch on the
held-out second halves of the target records.  Prints the machine and a Markdown table for
BENCHMARKS.md; figures and report.html go to OUT.

``--source-ceiling`` and ``--target-ceiling`` print references instead of the comparison: the
source-only CNN on held-out twin records, and the same CNN trained on the rig's own labelled
first halves (target labels, so never a method; it bounds what the rig's records allow).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from dataclasses import asdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def main() -> None:
    from twin.transfer.benchmark import RIGS

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=0,
                    help="first seed; --first-seed 5 --seeds 5 adds seeds 5-9 to a 5-seed run")
    ap.add_argument("--task", choices=("pitting", "wear", "both"), default="both")
    ap.add_argument("--epochs", type=int, default=80)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=str(REPO / "bench_out" / "transfer"))
    ap.add_argument("--data-dir", default=None)
    ap.add_argument("--rig", choices=tuple(RIGS) + tuple(INDEPENDENT_RIGS), default="rig",
                    help="the rig of the target data: an emulated one (rig; blind: fixed after every choice, only "
                         "scored) or an independent simulator of rigs/ (lumped, ltca)")
    ref = ap.add_mutually_exclusive_group()
    ref.add_argument("--source-ceiling", action="store_true",
                    help="instead: the source-only CNN on held-out *source* records (no domain shift), per seed")
    ref.add_argument("--target-ceiling", action="store_true",
                    help="instead: a CNN trained on the rig's own labelled first halves, tested on the "
                         "second halves (no transfer), per seed")
    args = ap.parse_args()
    from twin.errors import ParameterError
    from twin.transfer.benchmark import seed_range
    try:        # checked here too: the ceiling references do not go through run_benchmark
        args.seed_range = seed_range(args.seeds, args.first_seed)
    except ParameterError as e:
        ap.error(str(e))
    import torch

    from twin.transfer.benchmark import markdown_table, run_benchmark

    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tasks = ("pitting", "wear") if args.task == "both" else (args.task,)
    if args.source_ceiling or args.target_ceiling:
        _ceiling(args, tasks)
        return
    t = time.perf_counter()
    settings = targets = None
    if args.rig in INDEPENDENT_RIGS:
        out.mkdir(exist_ok=True)
        data_dir = Path(args.data_dir) if args.data_dir else out / "data"
        data_dir.mkdir(exist_ok=True)
        settings, targets = independent_targets(args.rig, tasks, data_dir)
    summary = run_benchmark(out, tasks=tasks, seeds=args.seeds, epochs=args.epochs, jobs=args.jobs,
                            data_dir=args.data_dir, rig=args.rig, first_seed=args.first_seed,
                            settings=settings, targets=targets)
    wall = time.perf_counter() - t
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    print(f"Machine: {cpu}, {len(os.sched_getaffinity(0))} cores, Python {platform.python_version()}, "
          f"torch {torch.__version__} (CPU, 1 thread per training run, {args.jobs} runs in parallel)")
    print(f"{args.seeds} seeds ({args.seed_range[0]}-{args.seed_range[-1]}) x 3 methods x {len(tasks)} task(s), "
          f"{args.epochs} epochs, rig '{args.rig}'; total wall time {wall:.0f} s\n")
    print(markdown_table(summary))
    print(f"\nfigures and report.html -> {out}")


# The independent simulators of rigs/ and the data seeds of their benchmark records.
INDEPENDENT_RIGS = {"lumped": 3, "ltca": 4}


def independent_targets(rig: str, tasks, data_dir: Path, progress: bool = True) -> tuple[dict, dict]:
    """(settings, target files) per task for an independent simulator of ``rigs/``: its records of the
    task's stages, written into ``data_dir`` (``target_<task>_<rig>.h5``) unless the ones there were
    made with the same settings (the key ``<task>_<rig>.json`` that prepare_task writes beside them)."""
    from rigs import ltca, lumped
    from twin.transfer.benchmark import ARCHIVE_RULES, rig_settings, task_scenario

    make = {"lumped": lumped.make_lumped_target, "ltca": ltca.make_ltca_target}[rig]
    settings, targets = {}, {}
    for t in tasks:
        s = rig_settings(t, rig, target_seed=INDEPENDENT_RIGS[rig])
        tgt, key = data_dir / f"target_{t}_{rig}.h5", data_dir / f"{t}_{rig}.json"
        wanted = json.dumps({**asdict(s), "archive_rules": ARCHIVE_RULES}, sort_keys=True)
        if not (tgt.exists() and key.exists() and key.read_text() == wanted):
            make(task_scenario(t, s), tgt, records_per_stage=s.target_records_per_stage,
                 record_duration=s.target_record_duration, seed=s.target_seed, progress=progress)
        settings[t], targets[t] = s, tgt
    return settings, targets


def _ceiling(args, tasks) -> None:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    import numpy as np

    from twin.errors import OutputPathError
    from twin.transfer.benchmark import _star, prepare_task, rig_settings, source_ceiling, target_ceiling

    if args.data_dir:
        data_dir = Path(args.data_dir)
    else:       # OUT/data, as for the main run: main() made OUT's parent, run_benchmark makes OUT
        Path(args.out).mkdir(exist_ok=True)
        data_dir = Path(args.out) / "data"
    if not data_dir.parent.is_dir():
        raise OutputPathError(f"output directory '{data_dir.parent}' does not exist (for '{data_dir}')")
    data_dir.mkdir(exist_ok=True)
    if args.target_ceiling:
        what, fn, pick = f"CNN trained on rig '{args.rig}' labels, target test halves", target_ceiling, 1
    else:
        what, fn, pick = "source-only CNN on held-out source records", source_ceiling, 0
    settings, targets = ({t: rig_settings(t, args.rig) for t in tasks}, {}) if args.rig not in INDEPENDENT_RIGS \
        else independent_targets(args.rig, tasks, data_dir)
    jobs = [(fn, t, str(prepare_task(t, data_dir, settings[t], target=targets.get(t))[pick]), s, args.epochs)
            for t in tasks for s in args.seed_range]
    with ProcessPoolExecutor(max_workers=args.jobs, mp_context=mp.get_context("spawn")) as pool:
        acc = list(pool.map(_star, jobs))
    print(f"| task | {what} [%] | per seed |\n|---|---|---|")
    for t in tasks:
        a = np.array([x for (_, tk, *_), x in zip(jobs, acc) if tk == t]) * 100
        print(f"| {t} | {a.mean():.1f} +- {a.std(ddof=1) if a.size > 1 else 0:.1f} | {', '.join(f'{v:.1f}' for v in a)} |")


if __name__ == "__main__":
    main()
