"""Benchmark: ``twin modes`` on the rigs' run-ups, per-channel search against the frequency-domain
decomposition (FDD) of the cross-spectral matrix, on the same records side by side.

    python bench/modes_rigs.py [--rigs pedestal beam] [--seeds 41 42 43 44 45]
                               [--out bench_out/modes_rigs] [--records-only]

For each rig and seed: one gearbox with its base parameters scattered +-12 %
(``Rig().scattered(seed, 0.12)``), a 6 s run-up from 2 to 20 Hz at 20 N.m written in the measurement
format (every casing channel, the encoder), and the rig's own modes (``box.modes()``, its
linearisation) as the truth. *Observable* rig modes: observability >= 0.02 between 10 Hz and 5 kHz
(as bench/calibration_rigs.py). ``twin modes`` (confidence >= 0.3) is run twice on the same record,
with ``fdd=False`` (each channel on its own, lists merged) and ``fdd=True`` (the channels' cross-spectral
matrix as well). Reported per rig and method: precision (extracted modes within 2 % of a rig mode /
extracted), recall (observable rig modes with an extracted mode within 2 %), recall by the class of
the rig mode (its label), and the wall time of ``twin modes``. Extraction only: no calibration.

Scored once per method change; prints Markdown tables; writes results.json under --out.
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

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from calibration_rigs import BAND, LOAD, OBSERVABLE, SPEED, rig_class  # noqa: E402

TOLERANCE = 0.02
METHODS = {"per channel": False, "FDD": True}


def records(rig_name: str, seed: int, out: Path):
    """(path of the run-up record, the rig's modes); the record is written once per rig and seed."""
    rigmod = importlib.import_module(f"rigs.{rig_name}")
    box = rigmod.Rig().scattered(seed=seed, scatter=0.12)
    h5 = out / f"{rig_name}_{seed}.h5"
    if not h5.exists():
        runup = box.runup(speeds=(2.0, SPEED), load=LOAD, duration=6.0, seed=seed, name="runup")
        rigmod.write(h5, [runup])
    return h5, box.modes(speed=SPEED, load=LOAD)


def score(extracted: np.ndarray, truth) -> dict:
    """Precision and recall of the extracted frequencies [Hz] against the rig's modes, by class."""
    every = np.array([m.frequency for m in truth])
    obs = [m for m in truth if m.observability >= OBSERVABLE and BAND[0] <= m.frequency <= BAND[1]]
    near = [float(np.min(np.abs(every - f)) / f) for f in extracted]
    found = [bool(extracted.size and np.min(np.abs(extracted - m.frequency)) / m.frequency <= TOLERANCE)
             for m in obs]
    by_class: dict[str, list[int]] = {}
    for m, ok in zip(obs, found):
        c = by_class.setdefault(rig_class(m.label), [0, 0])
        c[0] += 1
        c[1] += ok
    return {"extracted": int(extracted.size), "precise": int(sum(e <= TOLERANCE for e in near)),
            "observable": len(obs), "found": int(sum(found)), "by_class": by_class,
            "extracted_hz": extracted.tolist()}


def one_gearbox(rig_name: str, seed: int, out: Path) -> dict:
    from twin.modes import MIN_CONFIDENCE, survey_file

    h5, truth = records(rig_name, seed, out)
    row = {"rig": rig_name, "seed": seed}
    for label, fdd in METHODS.items():
        t0 = time.perf_counter()
        survey = survey_file(h5, "runup", fdd=fdd)
        row[label] = {**score(survey.frequencies(MIN_CONFIDENCE), truth), "seconds": time.perf_counter() - t0}
    return row


def tables(rows: list[dict]) -> str:
    out = ["| rig | method | precision: extracted within 2 % of a rig mode | recall: observable rig modes found "
           "within 2 % | `twin modes` [s] (range) |", "|---|---|---|---|---|"]
    for rig in dict.fromkeys(r["rig"] for r in rows):
        sel = [r for r in rows if r["rig"] == rig]
        for label in METHODS:
            s = [r[label] for r in sel]
            p, e = sum(x["precise"] for x in s), sum(x["extracted"] for x in s)
            f, o = sum(x["found"] for x in s), sum(x["observable"] for x in s)
            t = [x["seconds"] for x in s]
            out.append(f"| {rig} | {label} | {p}/{e} ({100 * p / max(e, 1):.0f} %) | {f}/{o} ({100 * f / max(o, 1):.0f} %) | "
                       f"{min(t):.1f}-{max(t):.1f} |")
    out += ["", "| rig | rig mode class | observable | found, per channel | found, FDD |", "|---|---|---|---|---|"]
    for rig in dict.fromkeys(r["rig"] for r in rows):
        sel = [r for r in rows if r["rig"] == rig]
        classes = sorted({c for r in sel for c in r["per channel"]["by_class"]})
        for c in classes:
            n = sum(r["per channel"]["by_class"].get(c, [0, 0])[0] for r in sel)
            a = sum(r["per channel"]["by_class"].get(c, [0, 0])[1] for r in sel)
            b = sum(r["FDD"]["by_class"].get(c, [0, 0])[1] for r in sel)
            out.append(f"| {rig} | {c} | {n} | {a} | {b} |")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", nargs="+", default=["pedestal", "beam"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[41, 42, 43, 44, 45])
    ap.add_argument("--out", type=Path, default=REPO / "bench_out" / "modes_rigs")
    ap.add_argument("--records-only", action="store_true", help="write the records and stop (no scoring)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for rig in args.rigs:
        for seed in args.seeds:
            if args.records_only:
                records(rig, seed, args.out)
                print(f"{rig} seed {seed}: record written", flush=True)
                continue
            rows.append(one_gearbox(rig, seed, args.out))
            r = rows[-1]
            print(f"{rig} seed {seed}: " + "; ".join(
                f"{k} {r[k]['precise']}/{r[k]['extracted']} precise, {r[k]['found']}/{r[k]['observable']} found, "
                f"{r[k]['seconds']:.1f} s" for k in METHODS), flush=True)
            (args.out / "results.json").write_text(json.dumps(rows, indent=2))
    if not rows:
        return
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    print(f"\nMachine: {cpu}, {len(os.sched_getaffinity(0))} cores, Python {platform.python_version()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; load average at the end "
          f"{os.getloadavg()[0]:.1f}\n")
    print(tables(rows))


if __name__ == "__main__":
    main()
