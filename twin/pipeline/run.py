"""``twin pipeline``: a rig's records in, assessed damage stages and one report out.

::

    twin pipeline RIG.h5 --healthy runup,steady --scenario scenarios/lubricated.yaml --out DIR

The paper's chain, one stage after the other, each writing into ``DIR``:

1. **calibrate** (``DIR/calibration/``): the scenario's twin calibrated on the rig's healthy records
   (:func:`twin.calibration.run.run_calibration`): the modes read from the run-up (or hammer) record,
   the parameters they identify chosen automatically, the steady record for the spectrum.  The model
   is the gearbox as its accelerometers measure it (``GearTwin.Gearbox21Measured`` for
   ``GearTwin.Gearbox21``: flank roughness, process force, sensor path), whose sensor gain and
   broadband levels the calibration fits; ``calibrated.yaml`` is the calibrated twin.  With hammer
   records struck at the bearing housings (``path_from``) the path to the sensors is the measured
   one: the model is ``GearTwin.Gearbox21Shafts`` (the casing in the loop, bearing-force outputs) and
   its sensors read the bearing forces through the accelerances of those records
   (:mod:`twin.calibration.transfer_path`), so the archive is simulated through the rig's own path;
2. **archive** (``DIR/archive.h5``): the calibrated twin's degradation run and its labelled archive
   (:func:`twin.archive.build_archive`), at the operating point of the rig's records;
3. **train** (``DIR/assessor/``): an ensemble of assessors on the archive and the rig's other records,
   unlabelled (:func:`twin.transfer.ensemble.train_ensemble`); every setting follows from the archive;
4. **assess** (``DIR/assessment.json``): the ensemble's stage of every record, its agreement, the
   stage-order check and, when the records are in time order, the stages decoded as a history that
   never heals (:class:`twin.transfer.ensemble.Ensemble`);
5. **rul** (``DIR/rul.json``, ``rul.png``), when the records carry times (``time_start`` or
   ``cycles``): the remaining useful life from the assessed history and the calibrated twin's
   degradation trajectory (:func:`twin.rul.run_rul`);
6. **report** (``DIR/report.html``): every stage on one page.

Each stage shows a progress bar and records what it was computed from in ``DIR/pipeline.json``.
Run the same command again after an interruption: finished stages whose inputs have not changed
are kept, and the pipeline resumes at the first stage that is not (the ensemble also keeps the
members it had finished).  Nothing already written is replaced by a partial result: every output
is written atomically.
"""
from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from twin.errors import ParameterError, ScenarioError

__all__ = ["PipelinePlan", "STAGES", "run_pipeline"]

STAGES = ("calibrate", "archive", "train", "assess", "rul", "report")
# The gearbox as its casing accelerometers measure it: the same model with flank roughness and a process
# force (broadband) and a sensor path, whose levels and gain the calibration fits to the steady record.
MEASURED = {"GearTwin.Gearbox21": "GearTwin.Gearbox21Measured"}
# With a measured path: the casing in the loop and bending shafts, whose bearing forces the hammer
# records' accelerances carry to the sensors (the model bench/calibration_rigs.py --path scored).
MEASURED_PATH = {"GearTwin.Gearbox21": "GearTwin.Gearbox21Shafts"}
# The calibration block when the scenario has none: the parameters the run-up's modes identify, and a
# search sized for the pipeline's time budget (bench/calibration_rigs.py measured it on the rigs).
CALIBRATION = {"parameters": "auto", "pop_size": 12, "n_gen": 6}
MANIFEST = "pipeline.json"


@dataclass(frozen=True)
class PipelinePlan:
    """What ``twin pipeline`` is asked to do.

    Attributes
    ----------
    measurements : Path
        The rig's measurement file: healthy records plus the records to assess.
    healthy : tuple of str
        Names of the healthy records: a run-up (or hammer test) for the modes and a steady record.
    scenario : Path
        The test's scenario (its degradation and archive blocks), e.g. ``scenarios/lubricated.yaml``.
    out : Path
        Output directory (created; its parent must exist).
    members : int
        Ensemble size.
    epochs : int
        Training epochs per member.
    jobs : int
        Parallel processes (calibration, archive, members).
    calibrate : bool
        False: the scenario's twin as it is (the ablation's default twin).
    time_ordered : bool or None
        None: the records' own time stamps decide; True: the file order is the time order.
    extra : Path or None
        Another file of the same rig's records to assess with the trained ensemble.
    path_from : tuple of (str, str)
        (healthy hammer record, bearing force of the model its blows stand for) pairs, e.g.
        ``(("hammer_pinion", "bearing_force_input_y"),)``: the calibration fits the measured path
        from those records (``calibration.path_from``); empty: the modelled path.  A mapping is
        accepted.
    """

    measurements: Path
    healthy: tuple
    scenario: Path
    out: Path
    members: int = 5
    epochs: int = 80
    jobs: int = 2
    calibrate: bool = True
    time_ordered: bool | None = None
    extra: Path | None = None
    path_from: tuple = ()

    def __post_init__(self) -> None:
        for name, lo in (("members", 2), ("epochs", 1), ("jobs", 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < lo:
                raise ParameterError(f"pipeline: {name} must be an integer >= {lo}, got {v!r}")
        if not self.healthy:
            raise ParameterError("pipeline: --healthy needs at least one record name (a run-up and a steady record)")
        pairs = tuple(self.path_from.items()) if isinstance(self.path_from, dict) else tuple(map(tuple, self.path_from))
        object.__setattr__(self, "path_from", pairs)
        for record, _ in pairs:
            if record not in self.healthy:
                raise ParameterError(f"pipeline: --path-from record {record!r} is not among the healthy records "
                                     f"({', '.join(self.healthy)}); the path is measured on the healthy gearbox")
        if pairs and not self.calibrate:
            raise ParameterError("pipeline: --path-from needs the calibration (it fits the measured path); "
                                 "drop --no-calibration")


@dataclass
class _Manifest:
    path: Path
    stages: dict = field(default_factory=dict)

    @classmethod
    def read(cls, path: Path) -> "_Manifest":
        if path.is_file():
            try:
                return cls(path, json.loads(path.read_text()).get("stages", {}))
            except (json.JSONDecodeError, UnicodeDecodeError, AttributeError):
                pass        # a damaged manifest only costs a re-run
        return cls(path)

    def done(self, stage: str, key: str, outputs) -> bool:
        s = self.stages.get(stage)
        return bool(s) and s.get("key") == key and all(Path(o).exists() for o in outputs)

    def record(self, stage: str, key: str, seconds: float, **info) -> None:
        from twin._atomic import atomic_path
        self.stages[stage] = {"key": key, "seconds": seconds, **info}
        with atomic_path(self.path) as tmp:
            Path(tmp).write_text(json.dumps({"stages": self.stages}, indent=1, default=str))


def _key(*parts) -> str:
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, Path) and p.is_file():
            st = p.stat()
            h.update(f"{p.resolve()}:{st.st_size}:{st.st_mtime_ns}".encode())
        else:
            h.update(json.dumps(p, sort_keys=True, default=str).encode())
    return h.hexdigest()[:16]


def healthy_roles(records) -> tuple[tuple[str, ...], str]:
    """(modes records, steady record) among the healthy records: the modes come from every run-up
    (shaft speed varying by a factor 1.5 or more) and every hammer test (a force channel), read
    together (the run-up first), the spectrum from the record whose speed varies least.

    Raises
    ------
    ScenarioError
        No record with a speed that varies by at least a factor 1.5, and no hammer test.
    """
    from twin.modes import shaft_angle

    spread = {}
    for r in records:
        if any(r.units[c] == "N" for c in r.channel_names):
            spread[r.name] = np.inf
            continue
        angle = shaft_angle(r)
        if angle is None:
            spread[r.name] = 0.0
            continue
        speed = np.gradient(np.asarray(angle, float)) * r.sample_rate / (2 * np.pi)
        speed = speed[np.isfinite(speed)]
        # the speed averaged over each twentieth of the record: a run-up's ends, free of encoder jitter
        parts = np.array_split(speed, 20) if speed.size >= 20 else [speed]
        means = np.array([p.mean() for p in parts if p.size])
        lo, hi = float(means.min()), float(means.max())
        spread[r.name] = hi / lo if lo > 0 else np.inf
    # run-ups before hammer tests (a stable sort keeps the given order within each)
    names = tuple(sorted((n for n in spread if spread[n] >= 1.5), key=lambda n: spread[n] == np.inf))
    if not names:
        raise ScenarioError([("--healthy", "records", "no healthy record is a run-up (shaft speed varying by a "
                              f"factor 1.5 or more) or a hammer test: {', '.join(spread)}; the modes are read "
                              "from one")])
    steady = min((n for n in spread if n not in names), key=spread.get, default=None)
    if steady is None:
        raise ScenarioError([("--healthy", "records", f"only the run-up or hammer test {', '.join(map(repr, names))} "
                              "was given; add a steady record of the healthy rig for the spectrum")])
    return names, steady


def run_pipeline(plan: PipelinePlan, *, progress: bool = True, log=print) -> dict:
    """Run (or resume) the pipeline of ``plan``; return the summary written to ``DIR/pipeline.json``.

    Raises
    ------
    ScenarioError, MeasurementError, AssessorError, ParameterError
        Bad scenario, measurement file, record names or settings, before any long stage starts
        where they can be found then.
    """
    from twin._atomic import check_output_dir
    from twin.measurements import load_measurements
    from twin.scenario import load_scenario

    meas, scen = Path(plan.measurements), Path(plan.scenario)
    scenario = load_scenario(scen)
    if scenario.degradation is None or scenario.archive is None:
        raise ScenarioError([(str(scen), "degradation/archive", "the pipeline needs a scenario with a degradation "
                              "and an archive block (e.g. scenarios/lubricated.yaml or scenarios/dry.yaml)")])
    mset = load_measurements(meas)
    missing = [n for n in plan.healthy if n not in mset.names]
    if missing:
        raise ScenarioError([(str(meas), "--healthy", f"no record(s) {', '.join(repr(n) for n in missing)} in the "
                              f"file (it has {', '.join(mset.names[:8])}{' ...' if len(mset) > 8 else ''})")])
    rig = [r for r in mset.records if r.name not in plan.healthy]
    if not rig:
        raise ScenarioError([(str(meas), "records", "every record is named healthy; the pipeline needs records to "
                              "assess besides the healthy ones")])
    out = check_output_dir(plan.out, "pipeline output", create=True)
    man = _Manifest.read(out / MANIFEST)
    timings = {}

    # 1. calibrate ------------------------------------------------------------------------------
    cal_dir = out / "calibration"
    if plan.calibrate:
        healthy = [mset[n] for n in plan.healthy]
        # a steady record at another load for the flanks' lead mismatch is not the spectrum's
        contact = (scenario.raw.get("calibration") or {}).get("face_contact_from")
        modes_rec, steady_rec = healthy_roles([r for r in healthy if r.name != contact])
        key = _key("calibrate", scen, meas, list(plan.healthy), scenario.raw, list(plan.path_from))
        cal_file = cal_dir / "calibrated.yaml"
        if man.done("calibrate", key, [cal_file]):
            log(f"[1/6] calibrate: kept {cal_file}")
        else:
            from twin.calibration.run import run_calibration
            log(f"[1/6] calibrate: modes from {', '.join(map(repr, modes_rec))}, spectrum from '{steady_rec}'"
                + "".join(f", path from {r!r} ({f})" for r, f in plan.path_from))
            t = time.perf_counter()
            block = {**(scenario.raw.get("calibration") or CALIBRATION),
                     "modes_from": modes_rec[0] if len(modes_rec) == 1 else list(modes_rec),
                     "record": steady_rec, **({"path_from": dict(plan.path_from)} if plan.path_from else {})}
            model = (MEASURED_PATH if plan.path_from else MEASURED).get(scenario.fmu, scenario.fmu)
            cal_sc = scenario.with_overrides(fmu=model, raw={**scenario.raw, "fmu": model, "calibration": block},
                                             executor={"type": "local", "workers": plan.jobs})
            report = run_calibration(cal_sc, meas, cal_dir, progress=progress)
            for w in report.warnings:
                log(f"warning: {w}")
            man.record("calibrate", key, time.perf_counter() - t, modes=list(modes_rec), steady=steady_rec,
                       model=model, path_from=dict(plan.path_from), table=report.table(),
                       warnings=list(report.warnings))
        timings["calibrate"] = man.stages["calibrate"]["seconds"]
        twin_sc, twin_file, key_up = load_scenario(cal_file), cal_file, man.stages["calibrate"]["key"]
    else:
        log("[1/6] calibrate: skipped (the scenario's twin as it is)")
        twin_sc, twin_file, key_up = scenario, scen, _key("uncalibrated", scen, scenario.raw)

    # 2. archive at the rig's operating point ---------------------------------------------------
    speed, load = _operating_point(rig, twin_sc)
    arc_path = out / "archive.h5"
    key = _key("archive", key_up, speed, load)
    if man.done("archive", key, [arc_path]):
        log(f"[2/6] archive: kept {arc_path}")
    else:
        log(f"[2/6] archive: degradation run and labelled records of the twin at {speed:g} Hz / {load:g} N.m")
        t = time.perf_counter()
        a = archive_for_records(twin_sc, rig, arc_path, jobs=plan.jobs, progress=progress)
        man.record("archive", key, time.perf_counter() - t, records=int(a.labels.size), stages=len(a.stages) - 1,
                   damage_kind=a.damage_kind, speed=speed, load=load)
    timings["archive"] = man.stages["archive"]["seconds"]

    # 3. train the ensemble ---------------------------------------------------------------------
    from twin.transfer.ensemble import Ensemble, train_ensemble
    ens_dir = out / "assessor"
    key = _key("train", man.stages["archive"]["key"], meas, [r.name for r in rig], plan.members, plan.epochs)
    if man.done("train", key, [ens_dir / "ensemble.json"]):
        log(f"[3/6] train: kept {ens_dir}")
        ens = Ensemble.load(ens_dir)
    else:
        log(f"[3/6] train: {plan.members} assessors on the archive and {len(rig)} unlabelled rig records")
        t = time.perf_counter()
        ens = train_ensemble(arc_path, rig, ens_dir, members=plan.members, epochs=plan.epochs, jobs=plan.jobs,
                             progress=progress, log=log)
        man.record("train", key, time.perf_counter() - t, members=plan.members, epochs=plan.epochs)
    timings["train"] = man.stages["train"]["seconds"]

    # 4. assess ---------------------------------------------------------------------------------
    from twin._atomic import atomic_path
    t = time.perf_counter()
    res = ens.assess(rig, time_ordered=plan.time_ordered)
    assessed = {"records": res}
    if plan.extra is not None:
        assessed["extra"] = ens.assess(Path(plan.extra), time_ordered=plan.time_ordered)
    doc = {name: r.to_dict() for name, r in assessed.items()}
    with atomic_path(out / "assessment.json") as tmp:
        Path(tmp).write_text(json.dumps(doc, indent=1))
    timings["assess"] = time.perf_counter() - t
    per_window = 1e3 * timings["assess"] / max(sum(r.n_windows for r in assessed.values()), 1)
    log(f"[4/6] assess: {len(rig)} records, {res.n_windows} windows ({per_window:.2f} ms per window)")
    log(f"      {res.verdict()}")
    log(f"      {res.order.message()}")
    if res.records[0].ordered_stage is not None:
        log(f"      time order ({res.time_order}): {res.moved_by_time_order} of {len(res.records)} records moved")
    for note in res.notes:
        log(f"      note: {note}")

    # 5. remaining useful life ------------------------------------------------------------------
    rul = None
    cycles = _cycles(rig, speed) if res.records[0].ordered_stage is not None else None
    if cycles is not None:
        rul = _rul(twin_sc, twin_file, res, cycles, arc_path, out, log)
    else:
        log("[5/6] rul: skipped (the records carry no times: time_start or cycles)")

    # 6. report ---------------------------------------------------------------------------------
    summary = {"plan": {k: (str(v) if isinstance(v, Path) else v) for k, v in asdict(plan).items()},
               "timings": timings, "assessment": {n: r.to_dict() for n, r in assessed.items()},
               "rul": rul, "ms_per_window": per_window}
    page = _report(out, plan, man, assessed, rul, timings, per_window)
    log(f"[6/6] report -> {page}")
    man.record("report", _key("report", time.time()), 0.0, summary=summary["timings"])
    return summary


def archive_for_records(scenario, records, path, *, jobs: int = 2, progress: bool = True):
    """The scenario's archive (:func:`twin.archive.build_archive`) simulated at the operating point of
    the rig's ``records`` (their median commanded speed and load), written to ``path``.

    The twin learns the stages at the speed and load the rig ran at: a different speed moves every
    mesh line against the structure's resonances.
    """
    from twin.archive import build_archive
    from twin.scenario import scenario_from_dict

    speed, load = _operating_point(records, scenario)
    op = {**scenario.raw.get("operating", {}), "speed": {"constant": speed}, "load": {"constant": load}}
    sc = scenario_from_dict({**scenario.raw, "operating": op}, source=scenario.source)
    return build_archive(sc.with_overrides(executor={"type": "local", "workers": jobs}), path, progress=progress)


def _operating_point(records, scenario) -> tuple[float, float]:
    """Median commanded speed and load of the rig's records; the scenario's where they have none."""
    from twin.archive import nominal_operating_point
    s0, l0 = nominal_operating_point(scenario)
    speeds = [r.nominal_speed for r in records if r.nominal_speed is not None]
    loads = [r.load for r in records if r.load is not None]
    return (float(np.median(speeds)) if speeds else s0), (float(np.median(loads)) if loads else l0)


def _cycles(records, speed: float) -> np.ndarray | None:
    """Pinion cycles of each record from its ``cycles`` attribute or ``time_start`` x speed; None without."""
    c = [(r.metadata or {}).get("cycles") for r in records]
    if all(v is not None for v in c):
        return np.asarray(c, dtype=float)
    starts = np.array([float(r.time_start) for r in records])
    if np.unique(starts).size == len(records):
        return starts * speed
    return None


def _rul(scenario, scenario_file, res, cycles, archive, out: Path, log) -> dict | None:
    from twin._atomic import atomic_path
    from twin.errors import TwinError
    from twin.rul import run_rul

    obs = {"stages": list(res.records and _stages_of(archive)), "records": [
        {"record": r.name, "cycles": float(c), "probabilities": list(r.probabilities)}
        for r, c in sorted(zip(res.records, cycles), key=lambda rc: rc[1])]}
    path = out / "rul_observations.json"
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps(obs, indent=1))
    try:
        est, _ = run_rul(scenario, path, trajectory=archive, json_path=out / "rul.json", plot_path=out / "rul.png",
                         progress=False)
    except TwinError as exc:
        log(f"[5/6] rul: not estimated: {exc}")
        return {"error": str(exc)}
    log("[5/6] rul:")
    for line in est.table().splitlines():
        log(f"      {line}")
    return json.loads((out / "rul.json").read_text())


def _stages_of(archive) -> list:
    from twin.transfer.settings import archive_facts
    return list(archive_facts(archive).stages)


def _report(out: Path, plan, man, assessed, rul, timings, per_window) -> Path:
    from twin.transfer.report import write_html
    blocks = [("Inputs", f"rig records: {plan.measurements}\nhealthy: {', '.join(plan.healthy)}\n"
                         f"scenario: {plan.scenario}\ncalibrated: {plan.calibrate}\nensemble: {plan.members} members, "
                         f"{plan.epochs} epochs\npath to the sensors: "
                         + (", ".join(f"measured, {r} -> {f}" for r, f in plan.path_from) or "modelled"))]
    cal = man.stages.get("calibrate")
    if plan.calibrate and cal:
        text = cal.get("table", "") + "".join(f"\nwarning: {w}" for w in cal.get("warnings", []))
        blocks.append(("1. Calibration on the healthy records (details: calibration/report.html)", text))
    arc = man.stages["archive"]
    blocks.append(("2. The twin's archive", f"{arc['records']} records in {arc['stages']} stages of "
                   f"{arc['damage_kind']} at {arc['speed']:g} Hz / {arc['load']:g} N.m"))
    for name, res in assessed.items():
        table = "\n".join(f"{r.name:>16s}  stage {r.stage}  conf {r.confidence:.2f}  agree {100 * r.agreement:5.1f} %"
                          + ("" if r.ordered_stage is None else f"  time-ordered stage {r.ordered_stage}")
                          + ("" if r.label is None else f"  (label {r.label})") for r in res.records)
        head = [res.verdict(), res.order.message(), f"time order: {res.time_order}"
                + ("" if res.records[0].ordered_stage is None
                   else f" ({res.moved_by_time_order} of {len(res.records)} records moved)")]
        head += [f"note: {n}" for n in res.notes]
        scores = res.scores()
        if scores:
            head.append("against the records' labels (evaluation only): "
                        + ", ".join(f"{k} {100 * v:.1f} %" for k, v in scores.items()))
        png = _plot_stages(res, out / f"stages_{name}.png")
        blocks += [(f"4. Assessment ({name})", "\n".join(head) + "\n\n" + table), (f"stages ({name})", png.name)]
    if rul is not None:
        blocks.append(("5. Remaining useful life", json.dumps(rul.get("estimate", rul), indent=1)[:3000]))
        if (out / "rul.png").exists():
            blocks.append(("RUL", "rul.png"))
    blocks.append(("Timings [s]", "\n".join(f"{k}: {v:.0f}" for k, v in timings.items())
                   + f"\ninference: {per_window:.2f} ms per window"))
    return write_html(out / "report.html", "twin pipeline", blocks)


def _plot_stages(res, path: Path) -> Path:
    from twin.transfer.report import _plt, _save
    plt = _plt()
    fig, ax = plt.subplots(figsize=(10, 3.5))
    x = np.arange(len(res.records))
    p = np.array([r.probabilities for r in res.records])
    ax.imshow(p.T, aspect="auto", origin="lower", cmap="Greys", vmin=0, vmax=1, extent=(-0.5, x[-1] + 0.5, -0.5,
                                                                                         p.shape[1] - 0.5))
    ax.plot(x, [r.stage for r in res.records], "o", color="tab:blue", ms=4, label="ensemble stage")
    if res.records[0].ordered_stage is not None:
        ax.step(x, [r.ordered_stage for r in res.records], where="mid", color="tab:green", label="time-ordered")
    if all(r.label is not None for r in res.records):
        ax.plot(x, [r.label for r in res.records], "x", color="tab:red", ms=5, label="label")
    ax.set_xlabel("record")
    ax.set_ylabel("stage")
    ax.legend(loc="upper left", fontsize=8)
    return _save(fig, path)
