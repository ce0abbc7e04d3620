"""The user's loop on scenario files: diagnose, add an effect, improve until nothing helps.

* :func:`diagnose_scenario` runs :func:`twin.effects.diagnose.diagnose` on a measurement record
  with the scenario's model and parameters, and writes ``diagnosis.json``.
* :func:`add_effect` writes a variant ``.mo`` (the current effects plus the new one) into
  ``modelica/GearTwin/Variants/``, builds its FMU, recalibrates the new effect's parameters on
  that FMU, compares before and after (overall and per finding), and writes a scenario file for
  the variant so the next step starts from it.
* :func:`improve` repeats diagnose -> add -> recalibrate until the diagnosis finds no candidate
  that cuts the discrepancy, and keeps a history table (CSV, JSON) and a plot.
"""
from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from twin.compare import MeasuredRecord, read_record  # noqa: F401  (part of this module's API)
from twin.effects.catalogue import RELATED_SPAN, effect as get_effect
from twin.effects.diagnose import (TrialSpec, active_effects, diagnose, fit_effect, record_conditions,
                                   related_values, require_running, simulate, split_fitted)
from twin.effects.verdict import Diagnosis


def neutral_values(active) -> dict:
    """Every catalogue effect not in ``active`` switched off (FMU names of the candidate model)."""
    from twin.effects.catalogue import CATALOGUE
    return {e.parameter(k): v for e in CATALOGUE.values() if e.id not in active for k, v in e.neutral.items()}


def _write_json(path: Path, data: dict) -> None:
    from twin._atomic import atomic_path
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps(data, indent=2, default=float))


def _out_dir(out) -> Path:
    from twin.errors import OutputPathError
    out = Path(out)
    if not out.parent.exists():
        raise OutputPathError(f"parent directory {out.parent} does not exist")
    out.mkdir(exist_ok=True)
    return out


def _record_names(record) -> list[str] | None:
    if record is None:
        return None
    return [record] if isinstance(record, str) else list(record)


def diagnose_scenario(scenario, measurements, *, record: str | Sequence[str] | None = None, all_records: bool = False,
                      json_path=None, executor=None, duration: float = 2.0, progress: bool = True,
                      candidates_fmu=None, effects: Sequence[str] | None = None, baseline=None,
                      encoder: bool = True) -> Diagnosis:
    """``twin diagnose``: the scenario's model against one or several records; writes ``json_path`` if given.

    ``record``: a record name or several (``--record steady --record runup``); ``all_records``:
    every record of the file; default: the first. With several, the candidates are fitted on the
    first steady record and must hold on the others (:func:`twin.effects.diagnose.diagnose`).
    ``effects``: the candidate ids tried (default: every catalogue effect the model lacks).
    ``baseline``: records of the gearbox as the scenario's model was calibrated on it, or their
    learned discrepancies (:func:`twin.effects.diagnose.diagnose`). ``encoder``: compare the
    records' pinion encoder too, where they have one (:mod:`twin.angular`).
    """
    from twin.effects.records import read_records
    from twin.errors import OutputPathError
    if json_path is not None and not Path(json_path).parent.exists():
        raise OutputPathError(f"parent directory of {json_path} does not exist")
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    recs = read_records(measurements, channel, _record_names(record), every=all_records)
    diag = diagnose(scenario.fmu_path(), recs, parameters=dict(scenario.parameters), channel=channel,
                    executor=executor, duration=duration, progress=progress, candidates_fmu=candidates_fmu,
                    effects=effects, anchors=(scenario.raw or {}).get("diagnosis", {}).get("calibrated", {}),
                    baseline=baseline, encoder=encoder)
    if json_path is not None:
        _write_json(Path(json_path), {"scenario": scenario.name, "fmu": str(scenario.fmu),
                                      "measurements": str(Path(measurements).resolve()),
                                      "records": [r.name for r in recs], "duration": duration,
                                      "effects": list(effects) if effects else None, **diag.to_dict()})
    return diag


def read_baseline(path, scenario, names: Sequence[str] | None = None, record=None) -> list:
    """Baseline records (:class:`~twin.effects.records.Record`) from measurement file ``path``:
    those ``names`` gives, else the records of the same names as ``record`` (the records
    diagnosed) that the file holds. Raises :class:`~twin.errors.MeasurementError` when the file
    holds none of them (naming what it has)."""
    from twin.effects.records import read_records
    from twin.errors import MeasurementError
    from twin.measurements import load_measurements
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    if not names:
        held = load_measurements(path).names
        wanted = _record_names(record) or [held[0]]
        names = [n for n in wanted if n in held]
        if not names:
            raise MeasurementError(str(path), ", ".join(wanted), f"no baseline record of these names; the file has "
                                                                  f"{', '.join(held)} (name them with --baseline-record)")
    return read_records(path, channel, list(names))


def learn_discrepancy(scenario, measurements, baseline, *, record=None, all_records: bool = False,
                      duration: float = 2.0, executor=None, encoder: bool = True) -> dict:
    """The scenario's model's discrepancy on ``baseline`` (records of the gearbox as the model was
    calibrated on it), for each record of ``measurements`` that ``record``/``all_records`` name:
    {record name: :class:`~twin.effects.baseline.Discrepancy`}. A run-up's baseline is driven with
    the loaded motor's slip that the first steady record gives the model."""
    from twin.effects.baseline import learn_all
    from twin.effects.records import as_records, read_records
    from twin.operating import simulate_settled
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    recs = read_records(measurements, channel, _record_names(record), every=all_records)
    fmu, params = scenario.fmu_path(), dict(scenario.parameters)
    steady = [r for r in recs if not r.runup]
    slip = load = 0.0
    if steady and len(steady) < len(recs):
        c = record_conditions(fmu, steady[0].signal, steady[0].sample_rate, steady[0].nominal_speed, steady[0].load,
                              params, record=steady[0].name, duration=duration, shaft_speed=steady[0].shaft_hz)
        op, _ = simulate_settled(fmu, params, c.operating, c.measured.size, channel)
        slip, load = op.drive_hz - op.shaft_hz, op.load
    return learn_all(fmu, params, recs, as_records(baseline), channel, duration=duration, slip_hz=slip,
                     fit_load=load, executor=executor, encoder=encoder)


def load_diagnosis(path, scenario, measurements, *, duration: float = 2.0) -> dict:
    """A ``diagnosis.json`` written by :func:`diagnose_scenario`, checked to be of this scenario,
    measurement file and record length: ``twin improve --from-diagnosis`` starts from it
    instead of diagnosing again.

    Raises :class:`~twin.errors.ParameterError` naming what differs (or a file that is not a
    diagnosis).
    """
    from twin.errors import ParameterError
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise ParameterError(f"cannot read diagnosis {path}: {exc}") from None
    need = ("scenario", "fmu", "measurements", "verdict", "missing", "candidates", "record", "headline")
    if not isinstance(data, dict) or any(k not in data for k in need):
        raise ParameterError(f"{path} is not a diagnosis written by twin diagnose (it lacks "
                             f"{next((k for k in need if not isinstance(data, dict) or k not in data), '')!r})")
    mine = {"scenario": scenario.name, "fmu": str(scenario.fmu), "measurements": str(Path(measurements).resolve()),
            "duration": duration}
    for k, v in mine.items():
        if data.get(k, v) != v:
            raise ParameterError(f"diagnosis {path} is of {k} {data.get(k)!r}, not {v!r}: diagnose again")
    return data


@dataclass(frozen=True)
class Addition:
    effect: str
    model: str                          # Modelica name of the variant
    modelica_file: Path
    fmu: Path
    scenario_file: Path | None
    fitted: dict                        # effect parameters and related base parameters after recalibration
    lsd_before_db: float
    lsd_after_db: float
    per_finding: tuple                  # (description, squared-dB error before, after)

    @property
    def reduction(self) -> float:
        return (self.lsd_before_db - self.lsd_after_db) / self.lsd_before_db if self.lsd_before_db > 0 else 0.0


def related_anchors(scenario, eff, parameters: dict, current: dict) -> tuple[dict, dict]:
    """(calibrated anchors, current values) of the effect's related base parameters.

    The anchors are the values before any effect was added (the scenario's ``diagnosis.calibrated``
    block, else its current values): every refit keeps a related parameter within
    +-:data:`~twin.effects.catalogue.RELATED_SPAN` of its anchor, however many effects are added.
    """
    block = (scenario.raw or {}).get("diagnosis", {}).get("calibrated", {})
    now = related_values(eff, parameters, current)
    return {k: float(block.get(k, v)) for k, v in now.items()}, now


def portable_scenario(scenario, name: str, fmu: str, parameter_file: str, anchors: dict) -> dict:
    """A scenario dict for a variant that stays valid wherever it is read: the parameter set is
    ``parameter_file`` (relative to the new scenario), files outside it are absolute."""
    import copy

    from twin.calibration.output import _absolute
    raw = copy.deepcopy(dict(scenario.raw)) if scenario.raw else {"version": 1, "stop_time": 1.0}
    base = scenario.source.parent if scenario.source is not None else None
    raw["name"] = name
    raw["fmu"] = fmu
    raw.pop("parameters", None)
    raw["parameter_files"] = [parameter_file]
    op = raw.get("operating", {})
    for _, spec in list(op.items()) + list(op.get("inputs", {}).items()):
        if isinstance(spec, dict) and "table" in spec:
            spec["table"]["file"] = _absolute(spec["table"]["file"], base)
    if anchors:
        raw["diagnosis"] = {**raw.get("diagnosis", {}), "calibrated": {k: float(v) for k, v in anchors.items()}}
    return raw


def add_effect(scenario, measurements, effect_id: str, out_dir, *, record: str | None = None,
               start: dict | None = None, refit: bool = True, modelica_dir=None, build_dir=None,
               candidates_fmu=None, duration: float = 2.0, max_evals: int = 30, baseline=None,
               encoder: bool = True) -> Addition:
    """``twin add-effect``: fit -> variant .mo -> FMU -> before/after report -> scenario.

    ``baseline``: records of the gearbox as the scenario's (calibrated) model was fitted to it,
    or their learned discrepancies: the model's discrepancy on them is taken out of the record
    before the effect is fitted and the before/after distances are taken
    (:mod:`twin.effects.baseline`). ``encoder``: the record's pinion encoder is a second channel
    of the fit and the distances, as in the diagnosis (:func:`twin.effects.diagnose.uses_encoder`).

    The effect is fitted in the candidate model (the current model's effects at their values,
    the new one switched on), together with its related base parameters (within
    +-``RELATED_SPAN`` of their calibrated values). ``start`` holds values of the effect
    parameters (FMU names), e.g. from a diagnosis; with ``refit=False`` they are taken as they
    are (the diagnosis already fitted them) and only the variant is written, built and checked.
    The variant's name carries a hash of its values (:func:`twin.effects.variant.variant_name`),
    so runs on other gearboxes never overwrite it.
    """
    import yaml

    from twin._atomic import atomic_path
    from twin.calibration.problem import write_parameter_set
    from twin.effects.diagnose import compare_record, starting_values, uses_encoder
    from twin.effects.fit import channels
    from twin.effects.records import as_records, read_records
    from twin.effects.verdict import finding_error
    from twin.effects.variant import (_REPO_MODELICA, base_of, build_like, candidates_model, modelica_root,
                                      variant_source, write_variant)
    from twin.errors import ParameterError

    eff = get_effect(effect_id)
    modelica_dir = modelica_root(modelica_dir)       # a bad directory fails before anything is written
    out = _out_dir(out_dir)
    build_dir = Path(build_dir) if build_dir is not None else modelica_dir.parent / "build"
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    this = read_records(measurements, channel, [record] if record else None)
    rec = this[0]
    current_fmu = scenario.fmu_path()
    base_params = dict(scenario.parameters)
    cond = record_conditions(current_fmu, rec.signal, rec.sample_rate, rec.nominal_speed, rec.load, base_params,
                             record=rec.name, duration=duration, shaft_speed=rec.shaft_hz)
    measured, current, z1, z2, op = cond.measured, cond.current, cond.z1, cond.z2, cond.operating
    shaft = op.shaft_hz
    known = given = None
    if baseline is not None:
        from collections.abc import Mapping

        from twin.effects.baseline import learn_all
        given = baseline if isinstance(baseline, Mapping) else as_records(baseline)
        known = learn_all(current_fmu, base_params, this, given, channel, duration=duration,
                          encoder=encoder)[rec.name]
    angle = this[0].angle[-measured.size:] if encoder and uses_encoder(this, given, cond.outputs) else None
    active = active_effects(current)
    if effect_id in active:
        raise ParameterError(f"the model {scenario.fmu} already has {effect_id}")
    # carry the active effects' values into the new variant so it reproduces the current model
    values = {k: v for k, v in current.items() if any(k.startswith(a + ".") for a in active)}
    sim0 = require_running(simulate(current_fmu, base_params, op, measured.size, channels(channel, angle)), rec.name, op)
    before = compare_record(sim0, measured, angle, rec.sample_rate, shaft, z1, z2, known)
    if sim0.ndim == 2:
        sim0 = sim0[:, 0]
    anchors, now = related_anchors(scenario, eff, base_params, current)

    # 1) the effect's parameters (and its related base parameters) in the candidate model
    guesses = {} if start and not refit else \
        starting_values(before, measured, sim0, rec.sample_rate, shaft, z1, z2).get(effect_id, {})
    if start:
        guesses.update(split_fitted(effect_id, start)[0])
    if refit:
        if candidates_fmu is None:
            candidates_fmu = build_like(candidates_model(base_of(current)), _REPO_MODELICA,
                                        _REPO_MODELICA.parent / "build", cond.structural)
        probe = {**base_params, **values, **neutral_values(active)}
        spec = TrialSpec(effect_id, str(candidates_fmu), channel, measured, op, probe, guesses, max_evals,
                         related=now, related_anchor=anchors, discrepancy=known, angle=angle)
        fitted, _, _, _ = fit_effect(spec)
    else:
        fitted = {**{eff.parameter(k): float(v) for k, v in guesses.items()},
                  **{k: float(v) for k, v in (start or {}).items() if k in now}}
    fitted_effect, fitted_base = split_fitted(effect_id, fitted)
    base_params.update(fitted_base)
    # 2) the variant with the fitted values as its defaults, built (cached by source) and checked
    neutral = {eff.parameter(k): v for k, v in eff.neutral.items()}
    ids = [*active, effect_id]
    model, path = write_variant(variant_source(ids, {**values, **neutral,
                                                     **{eff.parameter(k): v for k, v in fitted_effect.items()}},
                                               base=base_of(current)),
                                modelica_dir)
    fmu_path = build_like(model, modelica_dir, build_dir, cond.structural)
    sim1 = simulate(fmu_path, base_params, op, measured.size, channels(channel, angle))
    after = compare_record(sim1, measured, angle, rec.sample_rate, shaft, z1, z2, known)
    per = tuple((f.description, finding_error(before, f), finding_error(after, f)) for f in before.findings)
    # 3) a scenario for the variant, so the next step (or twin run) starts from it; the model name
    # resolves through the repository's modelica/, a variant written elsewhere by its FMU file
    write_parameter_set(base_params, out / f"parameters_{effect_id}.json")
    fmu_ref = model if modelica_dir.resolve() == _REPO_MODELICA.resolve() else str(Path(fmu_path).resolve())
    raw = portable_scenario(scenario, f"{scenario.name}+{effect_id}", fmu_ref, f"parameters_{effect_id}.json",
                            {**(scenario.raw or {}).get("diagnosis", {}).get("calibrated", {}), **anchors})
    scen_file = out / f"scenario_{effect_id}.yaml"
    from twin.scenario import scenario_from_dict
    scenario_from_dict(raw, source=scen_file)            # what is written must load
    with atomic_path(scen_file) as tmp:
        Path(tmp).write_text(yaml.safe_dump(raw, sort_keys=False))
    add = Addition(effect_id, model, path, fmu_path, scen_file, fitted, before.lsd_db, after.lsd_db, per)
    _write_json(out / f"add_effect_{effect_id}.json",
                {"effect": effect_id, "model": model, "modelica_file": str(path), "fmu": str(fmu_path),
                 "scenario": str(scen_file), "fitted_parameters": fitted,
                 "related_bounds": {k: [a * (1 - RELATED_SPAN), a * (1 + RELATED_SPAN)] for k, a in anchors.items()},
                 "log_spectral_distance_db": {"before": before.lsd_db, "after": after.lsd_db},
                 "reduction": add.reduction,
                 "per_finding": [{"finding": d, "squared_db_error_before": b, "squared_db_error_after": a}
                                 for d, b, a in per]})
    return add


@dataclass(frozen=True)
class Step:
    step: int
    effect: str | None
    lsd_before_db: float
    lsd_after_db: float
    model: str
    verdict: str


def improve(scenario, measurements, out_dir, *, record: str | Sequence[str] | None = None, all_records: bool = False,
            max_steps: int = 4, executor=None, modelica_dir=None, build_dir=None, duration: float = 2.0,
            progress: bool = True, effects: Sequence[str] | None = None, diagnosis=None,
            baseline=None, encoder: bool = True) -> tuple[Step, ...]:
    """``twin improve``: diagnose -> add -> recalibrate until no candidate improves the fit.

    ``baseline``: records of the gearbox as the scenario's model was calibrated on it. Their
    discrepancy is learned once, on the scenario's model, and kept while effects are added: a
    variant with an effect must not learn it again on records that lack the effect.

    ``effects``: the candidate ids tried at each step (default: the whole catalogue).
    ``encoder``: compare the records' pinion encoder too, where they have one (:mod:`twin.angular`).
    ``diagnosis``: a diagnosis of this scenario already made (a ``diagnosis.json`` path, see
    :func:`load_diagnosis`, or a :class:`Diagnosis`): the first step takes its verdict and
    fitted values instead of diagnosing again.
    """
    from twin.scenario import load_scenario
    for e in effects or ():
        get_effect(e)                   # an unknown id is refused before anything is written
    if baseline is not None and not isinstance(baseline, dict):
        baseline = learn_discrepancy(scenario, measurements, baseline, record=record, all_records=all_records,
                                     duration=duration, executor=executor, encoder=encoder)
    first = None
    if isinstance(diagnosis, Diagnosis):
        first = {"verdict": diagnosis.verdict, "missing": diagnosis.missing, "record": diagnosis.record,
                 "lsd": diagnosis.lsd_db, "fitted": _fitted_of(diagnosis)}
    elif diagnosis is not None:
        data = load_diagnosis(diagnosis, scenario, measurements, duration=duration)
        names = _record_names(record)
        if names is not None and names != data.get("records", names):
            from twin.errors import ParameterError
            raise ParameterError(f"diagnosis {diagnosis} is of records {data.get('records')}, not {names}: "
                                 "diagnose again")
        top = next((c for c in data["candidates"] if c["effect"] == data["missing"]), None)
        first = {"verdict": data["verdict"], "missing": data["missing"], "record": data["record"],
                 "lsd": data["headline"]["log_spectral_distance_db"],
                 "fitted": top["fitted_parameters"] if top else {}}
    out = _out_dir(out_dir)
    history: list[Step] = []
    for k in range(1, max_steps + 1):
        if k == 1 and first is not None:
            verdict, missing, fit_record, lsd, fitted = (first["verdict"], first["missing"], first["record"],
                                                         first["lsd"], first["fitted"])
        else:
            diag = diagnose_scenario(scenario, measurements, record=record, all_records=all_records,
                                     executor=executor, duration=duration, progress=progress,
                                     json_path=out / f"diagnosis_{k}.json", effects=effects, baseline=baseline,
                                     encoder=encoder)
            verdict, missing, fit_record, lsd = diag.verdict, diag.missing, diag.record, diag.lsd_db
            fitted = _fitted_of(diag)
        if verdict != "missing_effect":
            history.append(Step(k, None, lsd, lsd, scenario.fmu, verdict))
            break
        # the diagnosis fitted the effect already: add it with those values, without a refit
        add = add_effect(scenario, measurements, missing, out, record=fit_record, start=fitted, refit=False,
                         modelica_dir=modelica_dir, build_dir=build_dir, duration=duration, baseline=baseline,
                         encoder=encoder)
        history.append(Step(k, add.effect, add.lsd_before_db, add.lsd_after_db, add.model, verdict))
        if add.lsd_after_db >= add.lsd_before_db:
            break
        scenario = load_scenario(add.scenario_file)
    _write_history(history, out)
    return tuple(history)


def _fitted_of(diag: Diagnosis) -> dict:
    """Fitted values of the effect the diagnosis names (the best-scoring candidate need not be it:
    one that scores higher may have failed its held-out test or signature)."""
    return next((c.fitted for c in diag.candidates if c.effect == diag.missing), {})


def history_table(history) -> str:
    rows = [f"{'step':>4}  {'effect added':<24} {'LSD before':>10}  {'LSD after':>9}  model"]
    for s in history:
        rows.append(f"{s.step:>4}  {(s.effect or '(none: ' + s.verdict + ')'):<24} {s.lsd_before_db:>8.2f} dB"
                    f"  {s.lsd_after_db:>6.2f} dB  {s.model}")
    return "\n".join(rows)


def _write_history(history, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from twin._atomic import atomic_path
    _write_json(out / "history.json", {"steps": [asdict(s) for s in history]})
    with atomic_path(out / "history.csv") as tmp:
        Path(tmp).write_text("step,effect,lsd_before_db,lsd_after_db,model,verdict\n" + "".join(
            f"{s.step},{s.effect or ''},{s.lsd_before_db:.4f},{s.lsd_after_db:.4f},{s.model},{s.verdict}\n"
            for s in history))
    fig, ax = plt.subplots(figsize=(7, 4))
    levels = [history[0].lsd_before_db] + [s.lsd_after_db for s in history]
    labels = ["start"] + [s.effect or "no change" for s in history]
    ax.plot(range(len(levels)), levels, "o-", color="tab:blue")
    ax.set_xticks(range(len(levels)), labels, rotation=20, ha="right")
    ax.set_ylabel("log-spectral distance [dB]")
    ax.set_title("twin improve: discrepancy after each added effect")
    ax.grid(alpha=0.3)
    ax.set_ylim(bottom=0)
    fig.tight_layout()
    with atomic_path(out / "history.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
