"""Benchmark: `twin diagnose` on gearboxes the twin did not generate (rigs/pedestal, rigs/beam).

    python bench/diagnosis_rigs.py --calibrated bench_out/calibration_rigs [--rigs pedestal beam]
                                   [--seed 1] [--effects ...] [--no-baseline] [--repeats 1]
                                   [--out bench_out/diagnosis_rigs]

Per rig: the gearbox ``Rig().scattered(seed, 0.12)`` that ``bench/calibration_rigs.py`` calibrated
(its ``<rig>_<seed>_cal/calibrated.yaml`` under ``--calibrated``: the twin as well calibrated as
the current tools make it). For each case, the rig writes a 2 s steady record at 20 Hz / 20 N.m
of that gearbox with one effect hidden (the rig's own implementation and default size; ``none``:
nothing hidden) and a 6 s run-up from 2 to 20 Hz, in the measurement format, the truth apart.
Then, as a user would, ``twin.effects.diagnose`` on both records' pinion casing channel with the
calibrated scenario's model and parameters (``twin diagnose --record steady --record runup``):
candidates are fitted on the steady record, must hold on the end of the run-up they were not
fitted on, and must show their signature in the run-up.

Scored: the verdict against the hidden effect (the catalogue effect the rig's effect corresponds
to; ``none`` -> "nothing missing"; an effect outside the catalogue -> "unexplained"), and the
floor-aware, gain-free spectral distance of ``bench/spectral_distance.py`` (written apart from
``twin.compare``) between the record and (a) the calibrated twin, (b) the twin with the top
candidate at its fitted values, both simulated at the operating point the diagnosis measured.

The diagnosis is given the records the gearbox was calibrated on (the file
``bench/calibration_rigs.py`` wrote beside ``<rig>_<seed>_cal``) as its baseline (``twin
diagnose --baseline``; ``--no-baseline``: without, the control), and the change distance of
``bench/spectral_distance.py`` (the change since the calibration's steady record against the
change the model shows) is reported beside the distance to the record. ``--repeats N`` gives the
baseline N more healthy steady records of the gearbox at the same operating point (the rig's
record seeds 300, 301, ...): their record-to-record scatter raises the comparison's line
threshold (``twin.effects.baseline``).

Cases already in --out/results.json for other rigs or effects are kept. Run once per method change; every figure goes to BENCHMARKS.md as measured. Prints a Markdown
table; writes results.json under --out.
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

SPEED, LOAD = 20.0, 20.0
CHANNEL = "accel_pinion_casing"
#: rig effect -> the catalogue effect a correct diagnosis names (None: "unexplained" is right)
EXPECTED = {"none": "nothing_missing", "pinion_runout": "pinion_eccentricity", "gear_runout": "gear_eccentricity",
            "drive_ripple": "motor_torque_ripple", "casing_resonance": "housing_mode",
            "local_tooth_fault": "local_tooth_damage", "bearing_outer_race": "unexplained",
            "coupling_misalignment": "unexplained"}


def correct(expected: str, d) -> bool:
    if expected in ("nothing_missing", "unexplained"):
        return d.verdict == expected
    return d.verdict == "missing_effect" and d.missing == expected


def encoder_speed(h5: Path, record: str, n: int) -> float:
    """Mean pinion speed [Hz] over the last ``n`` samples of a record, from its encoder angle [rad]
    (read with h5py and numpy alone, for the independent distance)."""
    import h5py
    with h5py.File(h5, "r") as f:
        g = f["records"][record]
        angle = np.asarray(g["encoder"][...], float)[-n:]
        fs = float(g.attrs["sample_rate"])
    return float(np.polyfit(np.arange(angle.size) / fs, angle, 1)[0] / (2 * np.pi))


def calibration_records(calibrated_dir: Path, rig_name: str, seed: int) -> Path:
    """The measurement file the gearbox was calibrated on (bench/calibration_rigs.py wrote it
    beside its ``<rig>_<seed>_cal``): the diagnosis's baseline."""
    found = sorted(p for p in calibrated_dir.glob(f"{rig_name}_{seed}*.h5"))
    if len(found) != 1:
        raise SystemExit(f"expected one calibration record file {rig_name}_{seed}*.h5 in {calibrated_dir}, "
                         f"found {[p.name for p in found]}")
    return found[0]


def repeat_records(rig_name: str, seed: int, out: Path, count: int) -> list:
    """``count`` more healthy 2 s steady records of the gearbox at the calibration's operating
    point (the rig's record seeds 300, 301, ...; written once to ``<rig>_<seed>_repeats<count>.h5``),
    as :class:`twin.effects.records.Record`: repeats of the baseline for the diagnosis."""
    from twin.effects.records import read_records
    if count <= 0:
        return []
    h5 = out / f"{rig_name}_{seed}_repeats{count}.h5"
    names = [f"steady_repeat{k + 1}" for k in range(count)]
    if not h5.exists():
        rigmod = importlib.import_module(f"rigs.{rig_name}")
        box = rigmod.Rig().scattered(seed=seed, scatter=0.12)
        rigmod.write(h5, [box.steady(speed=SPEED, load=LOAD, duration=2.0, effect=None, seed=300 + k, name=nm)
                          for k, nm in enumerate(names)])
    return list(read_records(h5, CHANNEL, names))


def one_case(rig_name: str, seed: int, effect: str, calibrated, out: Path, ex, search: dict | None = None,
             baseline: Path | None = None, encoder: bool = True, repeats: int = 0) -> dict:
    from spectral_distance import change_distance_report, spectral_distance_report

    from twin.effects.catalogue import CATALOGUE
    from twin.effects.diagnose import diagnose
    from twin.effects.records import read_records
    from twin.measurements import load_measurements
    from twin.operating import simulate_at

    rigmod = importlib.import_module(f"rigs.{rig_name}")
    box = rigmod.Rig().scattered(seed=seed, scatter=0.12)
    h5 = out / f"{rig_name}_{seed}_{effect}.h5"
    eff = None if effect == "none" else effect
    t = time.perf_counter()
    if not h5.exists():
        case_seed = 100 + sorted(EXPECTED).index(effect)
        steady = box.steady(speed=SPEED, load=LOAD, duration=2.0, effect=eff, seed=case_seed, name="steady")
        runup = box.runup(speeds=(2.0, SPEED), load=LOAD, duration=6.0, effect=eff, seed=case_seed, name="runup")
        rigmod.write(h5, [steady, runup])
    rig_s = time.perf_counter() - t
    rec = load_measurements(h5)["steady"]
    fs = float(rec.sample_rate)
    x = np.asarray(rec[CHANNEL], float)
    fmu, params = calibrated.fmu_path(), dict(calibrated.parameters)
    t0 = time.perf_counter()
    base_recs = read_records(baseline, CHANNEL, ["steady", "runup"]) if baseline else None
    given = base_recs + repeat_records(rig_name, seed, out, repeats) if base_recs else None
    d = diagnose(fmu, read_records(h5, CHANNEL, ["steady", "runup"]), parameters=params, executor=ex,
                 duration=2.0, baseline=given, encoder=encoder, **(search or {}))
    wall = time.perf_counter() - t0
    n = int(round(2.0 * fs))
    xm = x[-n:]
    base = simulate_at(fmu, params, d.operating, n, [CHANNEL])[:, 0]
    dist0 = spectral_distance_report(base, xm, fs)["distance_db"]
    change0 = change1 = None
    if baseline:
        from twin.effects.diagnose import record_conditions
        b = base_recs[0]
        op_ref = record_conditions(fmu, b.signal, b.sample_rate, b.nominal_speed, b.load, params,
                                   duration=2.0, shaft_speed=b.shaft_hz).operating
        model_ref = simulate_at(fmu, params, op_ref, n, [CHANNEL])[:, 0]
        ref = b.signal[-n:]
        speeds_x = (encoder_speed(h5, "steady", n), encoder_speed(baseline, "steady", n))

        def change(y):
            return change_distance_report(y, model_ref, xm, ref, fs, (d.operating.shaft_hz, op_ref.shaft_hz,
                                                                      *speeds_x))
        change0 = change(base)
    # the effect named (or the first of a tie), else the best-fitting candidate
    top = next((c for c in d.candidates if c.effect == (d.missing or (d.tied[0] if d.tied else None))),
               d.candidates[0])
    dist1 = None
    if top.fitted and top.error is None:
        from twin.effects.variant import _REPO_MODELICA, base_of, build_like, candidates_model
        from twin.fmu import FMU
        with FMU(fmu) as f:
            base, structural = base_of(f.parameter_values()), f.structural_values()
        cand = build_like(candidates_model(base), _REPO_MODELICA, _REPO_MODELICA.parent / "build", structural)
        probe = {**params, **{e.parameter(k): v for e in CATALOGUE.values() for k, v in e.neutral.items()},
                 **top.fitted}
        try:
            y = simulate_at(cand, probe, d.operating, n, [CHANNEL])[:, 0]
            dist1 = spectral_distance_report(y, xm, fs)["distance_db"]
            if baseline:
                change1 = change(y)
        except Exception as exc:  # reported in the table, never ends the benchmark
            dist1 = f"{type(exc).__name__}: {exc}"
    truth = json.loads(Path(str(h5) + ".truth.json").read_text())
    row = {"rig": rig_name, "seed": seed, "hidden": effect, "expected": EXPECTED[effect], "verdict": d.verdict,
           "missing": d.missing, "tied": list(d.tied), "correct": correct(EXPECTED[effect], d), "top": top.effect,
           "top_score": top.score, "top_held_out": top.held_out, "top_signature": [top.signature_present, top.signature],
           "message": d.message, "top_fitted": top.fitted, "unexplained": list(d.unexplained),
           "twin_lsd_before": d.lsd_db, "twin_lsd_after_top": top.lsd_after_db,
           "distance_before_db": dist0, "distance_after_top_db": dist1, "baseline": str(baseline or ""),
           "change_before": change0, "change_after_top": change1, "diagnose_s": wall, "rig_s": rig_s,
           "search": search or "default", "encoder": encoder, "repeats": repeats, "load_average": os.getloadavg()[0],
           "truth_effect": next((r.get("effect") for r in truth.get("records", [truth]) if isinstance(r, dict)
                                 and r.get("effect")), None) if isinstance(truth, dict) else None}
    return row


def table(rows: list[dict]) -> str:
    lines = ["| rig | hidden in the rig | verdict | top candidate (score; held-out run-up cut [dB]; signature) | correct "
             "| independent distance: calibrated twin -> with the top candidate [dB] | diagnose [s] |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        verdict = r["verdict"] + (f": {r['missing']}" if r["missing"] else "") + \
            (f": {' = '.join(r['tied'])}" if r.get("tied") else "")
        held = r.get("top_held_out") or []
        cut = f"{min(b - a for _, b, a in held):+.2f}" if held else "not run"
        sig = {True: "present", False: "absent", None: "no test"}[(r.get("top_signature") or [None])[0]]
        after = r["distance_after_top_db"]
        after = f"{after:.1f}" if isinstance(after, float) else "not simulated"
        lines.append(f"| {r['rig']} | {r['hidden']} | {verdict} | {r['top']} ({r['top_score']:.2f}; {cut}; {sig}) | "
                     f"{'yes' if r['correct'] else 'no'} | {r['distance_before_db']:.1f} -> {after} | "
                     f"{r['diagnose_s']:.0f} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calibrated", type=Path, required=True,
                    help="output directory of bench/calibration_rigs.py (holds <rig>_<seed>_cal/calibrated.yaml)")
    ap.add_argument("--rigs", nargs="+", default=["pedestal", "beam"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--effects", nargs="+", default=["none", "pinion_runout", "gear_runout", "drive_ripple",
                                                      "casing_resonance", "local_tooth_fault", "bearing_outer_race"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--search", type=float, default=None,
                    help="s of the record the candidates are searched on (0: the whole record; default: "
                         "twin.effects.diagnose.SEARCH_S)")
    ap.add_argument("--search-step", type=float, default=None,
                    help="RK4 step [s] of the search (0: the operating point's; default: SEARCH_STEP)")
    ap.add_argument("--baseline", action=argparse.BooleanOptionalAction, default=True,
                    help="give the diagnosis the records the gearbox was calibrated on as its baseline "
                         "(twin diagnose --baseline), and score the change since them (default; "
                         "--no-baseline: the diagnosis against the calibrated model alone)")
    ap.add_argument("--encoder", action=argparse.BooleanOptionalAction, default=True,
                    help="compare the records' pinion encoder as a second channel (twin diagnose's default; "
                         "--no-encoder: the casing channel alone, the control)")
    ap.add_argument("--repeats", type=int, default=1,
                    help="more healthy steady records of the gearbox given with the baseline "
                         "(twin.effects.baseline: their record-to-record scatter raises the line threshold; "
                         "default 1, adopted 2026-11-29; 0: the baseline's own records alone)")
    ap.add_argument("--out", type=Path, default=REPO / "bench_out" / "diagnosis_rigs")
    args = ap.parse_args()

    from twin.executor import LocalExecutor
    from twin.scenario import load_scenario

    search = {}
    if args.search is not None:
        search["search"] = args.search or None
    if args.search_step is not None:
        search["search_step"] = args.search_step or None
    args.out.mkdir(parents=True, exist_ok=True)
    done = args.out / "results.json"
    rows = [r for r in (json.loads(done.read_text()) if done.exists() else [])
            if (r["rig"], r["hidden"]) not in {(g, e) for g in args.rigs for e in args.effects}]
    with LocalExecutor(args.workers) as ex:
        for rig in args.rigs:
            calibrated = load_scenario(args.calibrated / f"{rig}_{args.seed}_cal" / "calibrated.yaml")
            for effect in args.effects:
                rows.append(one_case(rig, args.seed, effect, calibrated, args.out, ex, search,
                                     calibration_records(args.calibrated, rig, args.seed) if args.baseline else None,
                                     args.encoder, args.repeats))
                print(json.dumps({k: v for k, v in rows[-1].items() if k != "top_fitted"}), flush=True)
                (args.out / "results.json").write_text(json.dumps(rows, indent=1, default=str))
    print(f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, {args.workers} workers, "
          f"load average {os.getloadavg()[0]:.1f}")
    print(table(rows))


if __name__ == "__main__":
    main()
