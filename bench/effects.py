"""Hidden-effect benchmark of `twin diagnose`: top-1 accuracy, error reduction and wall time per effect.

For every catalogue effect, a case with nothing missing and a case with an effect outside the
catalogue, and for each seed: simulate a truth record with the effect hidden
(:func:`twin.effects.synthetic.make_case`: base parameters off, speed off, gain error, noise),
calibrate the twin's base parameters to the truth's modes, then diagnose with the base model.

    python bench/effects.py --seeds 3 --out bench_out/effects_RESULTS.md
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--effects", nargs="*", default=None)
    ap.add_argument("--out", type=Path, default=REPO / "bench_out" / "effects_RESULTS.md")
    args = ap.parse_args()

    from fmu_build import build_fmu
    from twin.effects import CATALOGUE
    from twin.effects.diagnose import diagnose
    from twin.effects.synthetic import calibrate_base, make_case
    from twin.executor import LocalExecutor

    base = build_fmu("GearTwin.Gearbox21", REPO / "modelica", REPO / "build")
    cand = build_fmu("GearTwin.Variants.Gearbox21Candidates", REPO / "modelica", REPO / "build")
    # "none": nothing hidden
    cases = [None if e == "none" else e for e in args.effects] if args.effects else [*CATALOGUE, None, "out_of_catalogue"]
    rows = []
    with LocalExecutor(args.workers) as ex:
        for eff in cases:
            for seed in range(args.seeds):
                case = make_case(eff, seed, candidates_fmu=cand)
                params = calibrate_base(case, base)
                t0 = time.perf_counter()
                d = diagnose(base, case.signal, case.sample_rate, case.nominal_speed, case.load, parameters=params,
                             candidates_fmu=cand, executor=ex, duration=case.duration)
                wall = time.perf_counter() - t0
                top = d.candidates[0]
                rows.append({"effect": eff or "none", "seed": seed, "verdict": d.verdict, "missing": d.missing,
                             "top": top.effect, "lsd_before": d.lsd_db, "lsd_after_top": top.lsd_after_db,
                             "score_top": top.score, "unexplained": list(d.unexplained), "wall_s": wall,
                             "load_nm": case.load, "record_s": case.duration})
                print(json.dumps(rows[-1]), flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    (args.out.with_suffix(".json")).write_text(json.dumps(rows, indent=1))
    lines = [f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
             f"{args.workers} workers; {args.seeds} seeds per case; records at 20 kHz.", "",
             "| hidden effect | record | top-1 correct | verdict (per seed) | LSD before [dB] | LSD after adding the top candidate [dB] | reduction | diagnose wall time [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for eff in cases:
        name = eff or "none"
        rs = [r for r in rows if r["effect"] == name]
        if eff in CATALOGUE:
            ok = sum(r["missing"] == eff for r in rs)
        elif eff is None:
            ok = sum(r["verdict"] == "nothing_missing" for r in rs)
        else:
            ok = sum(r["verdict"] == "unexplained" for r in rs)
        red = [100 * (r["lsd_before"] - r["lsd_after_top"]) / r["lsd_before"] for r in rs]
        lines.append(f"| {name} | {rs[0]['record_s']:g} s, {rs[0]['load_nm']:g} N.m | {ok}/{len(rs)} | {', '.join(r['verdict'] if r['verdict'] != 'missing_effect' else r['missing'] for r in rs)} "
                     f"| {np.mean([r['lsd_before'] for r in rs]):.2f} | {np.mean([r['lsd_after_top'] for r in rs]):.2f} "
                     f"| {np.mean(red):.0f} % | {np.mean([r['wall_s'] for r in rs]):.0f} (max {max(r['wall_s'] for r in rs):.0f}) |")
    args.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
