"""Benchmark: the whole pipeline (twin pipeline) on the independent rigs, with the calibration ablation.

    python bench/pipeline_rigs.py [--rigs pedestal,beam] [--tasks pitting,wear] [--members 5]
                                  [--epochs 80] [--retrainings 3] [--per-stage 8] [--jobs 2]
                                  [--out bench_out/pipeline_rigs] [--arms path,calibrated,default]
                                  (arms also: path_form, path_contact)
                                  [--no-ablation] [--no-reversal]

For each rig (``rigs/``, used as black boxes through their public interface, defaults fixed) and
each test (pitting: 6 stages at 20 Hz / 20 N.m; wear: 4 stages at 10 Hz / 5 N.m):

1. **data** (cached in OUT/data): one scattered gearbox of the rig (``Rig().scattered(seed=1)``);
   its healthy run-up and steady record at the test's load; its stage records in the order of the
   test (``per_stage`` per stage, 1 s each, seed 10) for the pipeline to adapt to; and a second,
   disjoint set of stage records (seed 11) for the test.  The stage labels stay in the rig's truth
   file and are read by the scoring below only.  For the ``path`` arm the same records plus two
   hammer tests of the healthy rig at slow roll (0.5 Hz, the test's load, 8 s, 4 blows/s, seeds 103
   and 104), struck from above at its bearing supports (pedestal: the two pedestals; beam: the two
   housings), in a file of their own;
2. **pipeline** with the calibrated twin: ``twin.pipeline.run_pipeline`` (calibrate on the healthy
   records, degradation run, archive, ensemble of ``members``, assess), timed as a whole; the test
   records are assessed by the trained ensemble (``extra``).  Arm ``path``: the hammer tests are
   healthy records too and measure the path to the sensor (``path_from``: the pinion's support for
   ``bearing_force_input_y``, the gear's for ``bearing_force_output_y``), so the archive is simulated
   through the rig's measured path; arm ``path_form``: the same with the pinion's profile fitted to
   the mesh lines (``calibration.mesh_form: fit``); arm ``path_contact``: the same as ``path`` with a
   healthy steady record at another load (``light``: 5 N.m for pitting, 20 N.m for wear, seed 105)
   and the flanks' lead mismatch fitted to the load pair (``calibration.face_contact_from``); arm
   ``calibrated``: the modelled path;
3. **retrainings**: the ensemble trained again ``retrainings - 1`` times with disjoint seeds on the
   same archive, for the spread of the ensemble's accuracy (the calibrated arms);
4. **ablation**: the same pipeline with the default (uncalibrated) twin, one ensemble; every
   calibrated run comes first, so a run cut short loses the ablation first;
5. **scores** on the test records (last epoch; no label steers anything): window accuracy exact and
   within one stage, record accuracy, the same with the time order (the test records in the order
   of the test, ``time_ordered``), the members' agreement, each member's record accuracy (their
   spread), the stage-order verdict, inference time (the whole assessment per window);
6. **reversal** (``--no-reversal`` skips it): a rig built to provoke a reversed reading -- the
   pedestal rig's pitting records seen through a path whose spectral tilt, level-free, inverts the
   twin's damage trend stage by stage -- assessed by the pedestal pitting ensemble; the order check
   must say so.

Writes OUT/results.json and prints a Markdown table for BENCHMARKS.md with the machine and its load.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

TESTS = {"pitting": ("scenarios/lubricated.yaml", 20.0, 20.0), "wear": ("scenarios/dry.yaml", 10.0, 5.0)}
GEARBOX_SEED = 1
ADAPT_SEED, TEST_SEED = 10, 11
HAMMER_SEEDS = (103, 104)
#: Where the path's blows strike each rig (its bearing supports) and the twin's bearing force each stands for.
PATH_BLOWS = {"pedestal": ("pinion_pedestal", "gear_pedestal"), "beam": ("pinion_housing", "gear_housing")}
PATH_FORCES = ("bearing_force_input_y", "bearing_force_output_y")
ARMS = {"path_contact": "calibrated, measured path, lead mismatch from a load pair",
        "path_form": "calibrated, measured path, fitted profile", "path": "calibrated, measured path",
        "calibrated": "calibrated", "default": "default"}
CHANNEL = "accel_pinion_casing"


# ---- rig data through each rig's public interface ---------------------------------------------------
def _rig(name: str):
    if name == "pedestal":
        from rigs.pedestal import Rig, write
    elif name == "beam":
        from rigs.beam import Rig, write
    else:
        raise SystemExit(f"unknown rig {name!r}: pedestal or beam")
    return Rig().scattered(seed=GEARBOX_SEED), write


def _stage_records(name: str, box, task: str, per_stage: int, seed: int) -> list:
    if name == "pedestal":
        return list(box.stage_records(task, per_stage=per_stage, duration=1.0, seed=seed))
    f = box.pitting_stages if task == "pitting" else box.wear_stages
    return list(f(per_stage=per_stage, duration=1.0, seed=seed))


def rig_data(name: str, task: str, per_stage: int, data: Path) -> tuple[Path, Path]:
    """(pipeline file: healthy run-up and steady + adaptation stage records, test file); cached."""
    rig_file, test_file = data / f"{name}_{task}.h5", data / f"{name}_{task}_test.h5"
    key = data / f"{name}_{task}.json"
    wanted = json.dumps({"per_stage": per_stage, "gearbox": GEARBOX_SEED, "seeds": [ADAPT_SEED, TEST_SEED]})
    if rig_file.exists() and test_file.exists() and key.exists() and key.read_text() == wanted:
        return rig_file, test_file
    box, write = _rig(name)
    healthy = [dataclasses.replace(r, name=n) for r, n in zip(_healthy(name, box, task), ("runup", "steady"))]
    write(str(rig_file), healthy + _stage_records(name, box, task, per_stage, ADAPT_SEED))
    write(str(test_file), _stage_records(name, box, task, per_stage, TEST_SEED))
    key.write_text(wanted)
    return rig_file, test_file


def path_data(name: str, task: str, per_stage: int, data: Path) -> tuple[Path, dict]:
    """(the rig file of :func:`rig_data` with two hammer tests of the healthy rig added, path_from); cached."""
    rig_file, _ = rig_data(name, task, per_stage, data)
    path_file, key = data / f"{name}_{task}_path.h5", data / f"{name}_{task}_path.json"
    path_from = {f"hammer_{loc}": force for loc, force in zip(PATH_BLOWS[name], PATH_FORCES)}
    # the records of rig_file (its own key) and the blows' design
    wanted = json.dumps({"rig_file": (data / f"{name}_{task}.json").read_text(), "blows": PATH_BLOWS[name],
                         "seeds": HAMMER_SEEDS})
    if path_file.exists() and key.exists() and key.read_text() == wanted:
        return path_file, path_from
    box, write = _rig(name)
    # the same records as rig_file (re-simulated with the same seeds), then the blows
    write(str(path_file), _rig_records(name, box, task, per_stage))
    # the stage records must be the ones the other arms adapt to
    _same_records(rig_file, path_file, [CHANNEL])
    key.write_text(wanted)
    return path_file, path_from


def _same_records(old: Path, new: Path, channels=None) -> None:
    """Every record of ``old`` is in ``new`` sample for sample (``channels``: None, all of them);
    else ``new`` is removed and the run stops: the rig is not repeatable."""
    from twin.measurements import load_measurements
    a, b = load_measurements(old, channels=channels), load_measurements(new, channels=channels)
    for r in a.records:
        if not all(np.array_equal(np.asarray(r[c]), np.asarray(b[r.name][c])) for c in r.channel_names):
            new.unlink()
            raise SystemExit(f"{new}: record {r.name} differs from {old}'s; the rig is not repeatable")


#: The other load of the load pair [N.m] (``path_contact``: a healthy steady record at the test's speed), its seed.
CONTACT_LOAD, CONTACT_SEED = {"pitting": 5.0, "wear": 20.0}, 105


def contact_data(name: str, task: str, per_stage: int, data: Path) -> tuple[Path, dict]:
    """(the file of :func:`path_data` with a healthy steady record at :data:`CONTACT_LOAD` added as
    ``light``, path_from); cached."""
    path_file, path_from = path_data(name, task, per_stage, data)
    file, key = data / f"{name}_{task}_contact.h5", data / f"{name}_{task}_contact.json"
    wanted = json.dumps({"path_file": (data / f"{name}_{task}_path.json").read_text(),
                         "load": CONTACT_LOAD[task], "seed": CONTACT_SEED})
    if file.exists() and key.exists() and key.read_text() == wanted:
        return file, path_from
    box, write = _rig(name)
    _, speed, _ = TESTS[task]
    light = box.steady(speed=speed, load=CONTACT_LOAD[task], duration=2.0, seed=CONTACT_SEED, name="light")
    write(str(file), [*_rig_records(name, box, task, per_stage), light])
    _same_records(path_file, file)
    key.write_text(wanted)
    return file, path_from


def _rig_records(name: str, box, task: str, per_stage: int) -> list:
    """The healthy records, the adaptation stage records and two blows at the bearing supports
    (the records of :func:`path_data`'s file), simulated with their fixed seeds."""
    _, _, load = TESTS[task]
    healthy = [dataclasses.replace(r, name=n) for r, n in zip(_healthy(name, box, task), ("runup", "steady"))]
    blows = [box.impact(speed=0.5, load=load, duration=8.0, impacts_per_second=4.0, location=loc, seed=seed,
                        name=f"hammer_{loc}") for loc, seed in zip(PATH_BLOWS[name], HAMMER_SEEDS)]
    return healthy + _stage_records(name, box, task, per_stage, ADAPT_SEED) + blows


def _healthy(name: str, box, task: str) -> list:
    _, speed, load = TESTS[task]
    if name == "pedestal":
        return [box.runup(speeds=(2.0, speed), load=load, duration=6.0, seed=101),
                box.steady(speed=speed, load=load, duration=2.0, seed=102)]
    return [box.runup((2.0, speed), load, 6.0, seed=101), box.steady(speed, load, 2.0, seed=102)]


def labelled(path: Path) -> list:
    """The records of a rig file with their stage labels from the truth file (scoring only)."""
    from twin.measurements import load_measurements
    truth = json.loads(Path(str(path) + ".truth.json").read_text())["records"]
    recs = load_measurements(path, channels=[CHANNEL]).records
    return [dataclasses.replace(r, label=int(truth[r.name]["label"])) for r in recs
            if truth.get(r.name, {}).get("label") is not None]


# ---- scoring ----------------------------------------------------------------------------------------
def score(ens, records) -> dict:
    t = time.perf_counter()
    res = ens.assess(records, time_ordered=False)
    dt = time.perf_counter() - t
    # a run-to-failure history: the test records in the order of their damage (a rig may write them
    # shuffled; the beam rig does), as time stamps would give them
    timed = ens.assess(sorted(records, key=lambda r: r.label), time_ordered=True)
    s, st = res.scores(), timed.scores()
    return {"window_exact": s["window_exact"], "window_within_one": s["window_within_one"],
            "record_exact": s["record_exact"], "record_within_one": s["record_within_one"],
            "record_exact_time_order": st["record_exact_time_order"],
            "record_within_one_time_order": st["record_within_one_time_order"],
            "agreement": res.window_agreement, "order": res.order.verdict, "order_feature": res.order.feature,
            "order_rho": res.order.rig_trend, "reliable": res.reliable, "moved_by_time_order": timed.moved_by_time_order,
            "ms_per_window": 1e3 * dt / res.n_windows, "stages": [r.stage for r in res.records],
            "member_record_exact": [float(np.mean([r.member_stages[m] == r.label for r in res.records]))
                                    for m in range(res.n_members)],
            "labels": [r.label for r in res.records]}


def run_arm(name: str, task: str, arm: str, args, out: Path) -> dict:
    """One pipeline run (``arm``: :data:`ARMS`) on one rig's test, scored on its test records."""
    from twin.pipeline import PipelinePlan, run_pipeline
    from twin.transfer.ensemble import Ensemble, train_ensemble

    rig_file, test_file = rig_data(name, task, args.per_stage, out / "data")
    test = labelled(test_file)
    d = out / f"{name}_{task}_{arm}"
    healthy, path_from, scenario = ("runup", "steady"), {}, REPO / TESTS[task][0]
    if arm in ("path", "path_form"):
        rig_file, path_from = path_data(name, task, args.per_stage, out / "data")
        healthy += tuple(path_from)
    if arm == "path_contact":
        rig_file, path_from = contact_data(name, task, args.per_stage, out / "data")
        healthy += (*path_from, "light")
    if arm == "path_form":
        scenario = _with_mesh_form(scenario, out / "scenarios")
    if arm == "path_contact":
        scenario = _with_calibration(scenario, out / "scenarios", "face_contact", face_contact_from="light")
    t = time.perf_counter()
    run_pipeline(PipelinePlan(rig_file, healthy, scenario, d, members=args.members,
                              epochs=args.epochs, jobs=args.jobs, calibrate=arm != "default", time_ordered=True,
                              path_from=path_from),
                 progress=False, log=lambda m: print(f"  [{name} {task} {arm}] {m}", flush=True))
    wall = time.perf_counter() - t
    runs = [score(Ensemble.load(d / "assessor"), test)]
    if arm != "default":
        adapt = _unlabelled(labelled(rig_file))
        for k in range(1, args.retrainings):
            ens = train_ensemble(d / "archive.h5", adapt, d / f"assessor_{k}", members=args.members,
                                 epochs=args.epochs, first_seed=k * args.members, jobs=args.jobs, progress=False,
                                 log=lambda m: None)
            runs.append(score(ens, test))
    stages = json.loads((d / "pipeline.json").read_text())["stages"]
    return {"runs": runs, "wall_time": wall, "stage_seconds": {k: v.get("seconds") for k, v in stages.items()}}


def _with_mesh_form(scenario: Path, where: Path) -> Path:
    """A copy of ``scenario`` whose calibration block is the pipeline's with ``mesh_form: fit``."""
    return _with_calibration(scenario, where, "mesh_form", mesh_form="fit")


def _with_calibration(scenario: Path, where: Path, tag: str, **keys) -> Path:
    """A copy of ``scenario`` whose calibration block is the pipeline's with ``keys`` added."""
    import yaml

    from twin.pipeline.run import CALIBRATION
    raw = yaml.safe_load(scenario.read_text())
    raw["calibration"] = {**CALIBRATION, **keys}
    where.mkdir(parents=True, exist_ok=True)
    path = where / f"{scenario.stem}_{tag}.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False))
    return path


def _unlabelled(records):
    return [dataclasses.replace(r, label=None) for r in records]


# ---- a rig built to provoke a reversed reading --------------------------------------------------------
def reversal(out: Path, per_stage: int) -> dict | None:
    """Pedestal pitting records behind a path that inverts the twin's spectral damage trend."""
    from twin.transfer.ensemble import Ensemble
    from twin.transfer.preprocess import log_spectrum, window_signal

    d = out / "pedestal_pitting_calibrated" / "assessor"
    if not (d / "ensemble.json").is_file():
        return None
    ens = Ensemble.load(d)
    _, test_file = rig_data("pedestal", "pitting", per_stage, out / "data")
    recs = labelled(test_file)
    # the archive's mean log-magnitude shape change per stage (level removed), on the record's own grid
    from twin.transfer.preprocess import prepare
    pre = ens.preprocessing
    arc = prepare(out / "pedestal_pitting_calibrated" / "archive.h5", pre, "source", "source")
    spectra = {}
    for p in arc:
        w = window_signal(p.signal, pre.window, pre.hop)
        s = log_spectrum(w, pre.time_bandwidth).mean(0)
        spectra.setdefault(p.label, []).append(s - s.mean())
    shape = {k: np.mean(v, 0) for k, v in spectra.items()}
    provoked = []
    for r in recs:
        x = np.asarray(r[CHANNEL], float)
        # filter: the twin's shape change of this record's stage, inverted twice over, level-free
        delta = -2.0 * (shape[r.label] - shape[0])
        f_path = np.linspace(0.0, pre.sample_rate / 2, delta.size)
        f = np.fft.rfftfreq(x.size, 1.0 / r.sample_rate)
        gain = np.exp(np.interp(f, f_path, delta, right=0.0))
        y = np.fft.irfft(np.fft.rfft(x) * gain, n=x.size)
        y *= np.sqrt(np.mean(x ** 2) / np.mean(y ** 2))          # the record keeps its level
        provoked.append(dataclasses.replace(r, channels={CHANNEL: y}, units={CHANNEL: "m/s2"}, tachometer=None,
                                            tachometer_kind=None))
    res = ens.assess(provoked, time_ordered=False)
    s = res.scores()
    from scipy.stats import spearmanr
    rho = float(spearmanr([r.label for r in res.records], [r.expected_stage for r in res.records]).statistic)
    return {"window_exact": s["window_exact"], "rank_correlation_true_assessed": rho,
            "order": res.order.verdict, "message": res.order.message(), "reliable": res.reliable}


def machine() -> str:
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    return (f"{cpu}, {len(os.sched_getaffinity(0))} cores, Python {platform.python_version()}, "
            f"load average at the start {os.getloadavg()[0]:.1f}")


def table(rows: list[dict]) -> str:
    lines = ["| rig | test | twin | exact (windows) [%] | within one [%] | records exact [%] | with time order [%] | "
             "agreement [%] | members' records exact [%] | order | reliable | wall time [s] | ms/window |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        for arm in ARMS:
            if arm not in row:
                continue
            runs = row[arm]["runs"]
            def ms(key):
                v = 100 * np.array([r[key] for r in runs])
                return f"{v.mean():.1f} +- {v.std(ddof=1):.1f}" if v.size > 1 else f"{v.mean():.1f}"
            m = 100 * np.array([a for r in runs for a in r["member_record_exact"]])
            mem = f"{m.mean():.1f} +- {m.std(ddof=1):.1f}"
            lines.append(f"| {row['rig']} | {row['task']} | {ARMS[arm]} | {ms('window_exact')} | {ms('window_within_one')} | "
                         f"{ms('record_exact')} | {ms('record_exact_time_order')} | {ms('agreement')} | {mem} | "
                         f"{'/'.join(sorted({r['order'] for r in runs}))} | "
                         f"{sum(r['reliable'] for r in runs)}/{len(runs)} | {row[arm]['wall_time']:.0f} | "
                         f"{np.mean([r['ms_per_window'] for r in runs]):.2f} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rigs", default="pedestal,beam")
    ap.add_argument("--tasks", default="pitting,wear")
    ap.add_argument("--members", type=int, default=5)
    ap.add_argument("--retrainings", type=int, default=3)
    ap.add_argument("--epochs", type=int, default=80)
    ap.add_argument("--per-stage", type=int, default=8)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=str(REPO / "bench_out" / "pipeline_rigs"))
    ap.add_argument("--arms", default="path,calibrated,default",
                    help="comma-separated, in this order: path_form (measured path and the profile fitted to the "
                         "mesh lines), path (calibrated, measured path), calibrated (modelled path), default "
                         "(uncalibrated)")
    ap.add_argument("--no-ablation", action="store_true", help="leave out the default arm")
    ap.add_argument("--no-reversal", action="store_true")
    args = ap.parse_args()
    out = Path(args.out)
    (out / "data").mkdir(parents=True, exist_ok=True)
    print(f"Machine: {machine()}", flush=True)
    rows, t0 = {}, time.perf_counter()
    arms = [a for a in args.arms.split(",") if a and not (args.no_ablation and a == "default")]
    unknown = [a for a in arms if a not in ARMS]
    if unknown:
        raise SystemExit(f"unknown arm(s) {', '.join(unknown)}: {', '.join(ARMS)}")
    for arm in arms:                # every calibrated run first: the ablation is what a short run drops
        for name in args.rigs.split(","):
            for task in args.tasks.split(","):
                row = rows.setdefault(f"{name}_{task}", {"rig": name, "task": task})
                row[arm] = run_arm(name, task, arm, args, out)
                (out / "results.json").write_text(json.dumps({"machine": machine(), "args": vars(args),
                                                              "rows": list(rows.values())}, indent=1))
                print(table(list(rows.values())), flush=True)
    rows = list(rows.values())
    rev = None if args.no_reversal else reversal(out, args.per_stage)
    (out / "results.json").write_text(json.dumps({"machine": machine(), "args": vars(args), "rows": rows, "reversal": rev,
                                                  "wall_time": time.perf_counter() - t0}, indent=1))
    print(table(rows))
    if rev:
        print(f"\nreversal rig: {json.dumps(rev)}")


if __name__ == "__main__":
    main()
