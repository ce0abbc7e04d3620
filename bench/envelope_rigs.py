"""Benchmark: harmonic series in the envelope of the rigs' records, a steady record against its run-up.

    python bench/envelope_rigs.py [--rigs pedestal beam] [--seeds 1 3] [--out bench_out/envelope_rigs]

A rolling-element bearing's passage is a fixed non-integer order of its shaft, so its series in
the squared-envelope spectrum stays at that order through a run-up, where healthy records' series
locked to neither shaft (12-17 dB in one steady record) do not. Per rig and gearbox
``Rig().scattered(seed, 0.12)`` and each case of ``bench/diagnosis_rigs.py`` (the same case seeds:
a 2 s steady record at 20 Hz / 20 N.m and a 6 s run-up 2-20 Hz): the steady record's series locked
to neither shaft standing 12 dB or more (``twin.signals.envelope.envelope_series`` at the record's
mean speed from its encoder), the run-up's series in pinion orders
(``twin.signals.envelope.order_envelope_series``), and which of the former a run-up series
confirms (``EnvelopeSeries.confirms``: within both spectra's location tolerances). The signal
functions are the twin's (this checks what they see); no model is simulated. Prints a Markdown
table; writes results.json.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

CASES = ("none", "bearing_outer_race", "pinion_runout", "gear_runout", "drive_ripple", "casing_resonance",
         "local_tooth_fault")
SPEED, LOAD = 20.0, 20.0


def one(rig: str, seed: int, case: str, out: Path) -> dict:
    from diagnosis_rigs import EXPECTED
    from twin.effects.records import read_records
    from twin.signals.envelope import CONFIRMED_DB, envelope_series, order_envelope_series

    mod = importlib.import_module(f"rigs.{rig}")
    h5 = out / f"{rig}_{seed}_{case}.h5"
    if not h5.exists():
        box = mod.Rig().scattered(seed=seed, scatter=0.12)
        eff = None if case == "none" else case
        cs = 100 + sorted(EXPECTED).index(case)         # the diagnosis benchmark's case seeds
        mod.write(h5, [box.steady(speed=SPEED, load=LOAD, duration=2.0, effect=eff, seed=cs, name="steady"),
                       box.runup(speeds=(2.0, SPEED), load=LOAD, duration=6.0, effect=eff, seed=cs, name="runup")])
    steady, runup = read_records(h5, "accel_pinion_casing", ["steady", "runup"])
    ratio = 19 / 52
    found = [s for s in envelope_series(steady.signal, steady.sample_rate, float(np.mean(steady.shaft_hz)),
                                        gear_ratio=ratio, min_db=CONFIRMED_DB) if s.locked_to is None]
    orders = order_envelope_series(runup.signal, runup.sample_rate, runup.shaft_hz, gear_ratio=ratio)
    return {"rig": rig, "seed": seed, "case": case,
            "steady": [[s.order, s.prominence_db, list(s.band_hz)] for s in found],
            "runup": [[s.order, s.prominence_db, list(s.band_hz)] for s in orders],
            "confirmed": [[s.order, s.prominence_db, r.prominence_db] for s in found for r in orders
                          if s.confirms(r)]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rigs", nargs="+", default=["pedestal", "beam"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 3])
    ap.add_argument("--out", type=Path, default=Path("bench_out/envelope_rigs"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows = [one(r, s, c, args.out) for r in args.rigs for s in args.seeds for c in CASES]
    print("| rig | seed | hidden | steady: unlocked series >= 12 dB (order, dB) | confirmed by the run-up "
          "(order, steady dB, run-up dB) |")
    print("|---|---|---|---|---|")
    for r in rows:
        st = ", ".join(f"{o:.3f} ({p:.0f})" for o, p, _ in r["steady"]) or "none"
        cf = ", ".join(f"{o:.3f} ({a:.0f}, {b:.0f})" for o, a, b in r["confirmed"]) or "none"
        print(f"| {r['rig']} | {r['seed']} | {r['case']} | {st} | {cf} |")
    meta = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
            "date": time.strftime("%Y-%m-%d %H:%M"), "wall_s": time.perf_counter() - t0}
    print(f"\n{meta['machine']}, {meta['date']}, {meta['wall_s']:.0f} s")
    (args.out / "results.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
