"""Benchmark: switching a trained assessor's class-prior rule, re-matched against retrained.

    python bench/rematch.py [--task pitting|wear] [--epochs 80] [--seeds 2] [--out bench_out/rematch]

For each seed, the proposed method is trained with the task's benchmark rule
(``TASK_CLASS_PRIOR``) on the benchmark's data (built or reused in OUT/data).  Then, for each of
the other rules, side by side in one run: ``Assessor.rematch`` on the trained assessor, and a new
``fit`` with that rule (what a user had to do before).  Prints the wall time of each and whether
the two give the same stage probabilities on the rig's test windows, bit for bit; then a
Markdown table for BENCHMARKS.md and the machine.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--task", choices=("pitting", "wear"), default="pitting")
    ap.add_argument("--epochs", type=int, default=80)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--out", default=str(REPO / "bench_out" / "rematch"))
    args = ap.parse_args()
    import numpy as np
    import torch

    from twin.transfer.assessor import Assessor
    from twin.transfer.benchmark import TASK_CLASS_PRIOR, load_task_data, prepare_task, task_preprocessing
    from twin.transfer.errors import class_prior_notes

    data = Path(args.out) / "data"
    data.mkdir(parents=True, exist_ok=True)
    src, tgt = prepare_task(args.task, data)
    pre = task_preprocessing(args.task)
    source, adapt, test = load_task_data(args.task, str(src), str(tgt), pre.sample_rate)
    rule = TASK_CLASS_PRIOR[args.task]
    rows = []
    for seed in range(args.seeds):
        a = Assessor("proposed", epochs=args.epochs, seed=seed, preprocessing=pre, progress=False, class_prior=rule)
        with class_prior_notes():
            a.fit(source, adapt)
        for other in [r for r in ("source", "ordinal", None) if r != rule]:
            with class_prior_notes():
                t0 = time.perf_counter()
                re = a.rematch(adapt, other)
                t_re = time.perf_counter() - t0
                t0 = time.perf_counter()
                direct = Assessor(**{**a.get_params(), "class_prior": other}).fit(source, adapt)
                t_fit = time.perf_counter() - t0
            p_re, p_fit = re.predict_proba(test), direct.predict_proba(test)
            same = bool(np.array_equal(p_re, p_fit))
            acc = re.score(test)
            rows.append((seed, other, t_re, t_fit, same, acc))
            print(f"seed {seed}, {rule} -> {other}: rematch {t_re:.2f} s, retrain {t_fit:.1f} s, "
                  f"identical probabilities: {same}, accuracy {100 * acc:.1f} %", flush=True)
    print(f"\nMachine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python "
          f"{platform.python_version()}, torch {torch.__version__}; task {args.task}, {args.epochs} epochs, "
          f"{len(test)} test records")
    print("\n| seed | rule | rematch [s] | retrain [s] | ratio | identical test probabilities | accuracy [%] |")
    print("|---|---|---|---|---|---|---|")
    for seed, other, t_re, t_fit, same, acc in rows:
        print(f"| {seed} | {rule} -> {other or 'none'} | {t_re:.2f} | {t_fit:.1f} | {t_fit / t_re:.0f}x | "
              f"{'yes' if same else 'NO'} | {100 * acc:.1f} |")


if __name__ == "__main__":
    main()
