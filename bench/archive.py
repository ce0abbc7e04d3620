"""Benchmark: wall time of the lubricated archive on 1 and 2 local worker processes.

    python bench/archive.py [--records-per-stage 50]

6 pitting stages x 50 records of 0.2 s at 100 kHz (plus 0.05 s settling each), preceded by the
coupled degradation run that produces the stages. Both runs use the same seed, and the script
checks that they give identical archives. Prints a Markdown table for BENCHMARKS.md.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--records-per-stage", type=int, default=50)
    args = ap.parse_args()
    from twin.archive import build_archive
    from twin.scenario import load_scenario

    sc = load_scenario(REPO / "scenarios" / "lubricated.yaml")
    arc = dict(sc.archive)
    arc["records_per_stage"] = args.records_per_stage
    fmu = sc.fmu_path()
    rows, archives = [], []
    for workers in (1, 2):
        s = sc.with_overrides(archive=arc, executor={"type": "local", "workers": workers})
        t = time.perf_counter()
        a = build_archive(s, None, fmu_path=fmu, progress=False)
        rows.append((workers, time.perf_counter() - t, a.labels.size))
        archives.append(a)
    same = np.array_equal(archives[0].signals["accel_pinion_casing"], archives[1].signals["accel_pinion_casing"])
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    print(f"Machine: {cpu}, {len(os.sched_getaffinity(0))} cores, Python {platform.python_version()}")
    print(f"Archive: {len(arc['stages']) - 1} stages x {args.records_per_stage} records x {arc['record_duration']:g} s "
          f"at 100 kHz; identical archives: {same}\n")
    print("| local workers | records | wall time [s] | speed-up |")
    print("|---|---|---|---|")
    for w, wall, n in rows:
        print(f"| {w} | {n} | {wall:.1f} | {rows[0][1] / wall:.2f}x |")


if __name__ == "__main__":
    main()
