"""Demo steps 6 and 8: a gearbox the twin did not generate, from its raw records to a calibrated
scenario, then the diagnosis loop on it with one of the rig's own effects hidden.

The records come from files (``make demo`` writes them with ``python -m rigs.pedestal runup``
and ``steady``; ``twin`` never imports ``rigs``). The step does what a user does with a rig:

    twin modes rig.h5 --record runup --plot modes.png
    twin modes rig.h5 --record runup --record hammer        # with a hammer test: the two together
    twin modes rig.h5 --record runup --record hammer --record hammer_gear   # struck on each shaft
    twin calibrate scenario.yaml --measurements rig.h5 --modes-from runup --out calibration_rig/
    twin compare calibration_rig/calibrated.yaml --measurements rig.h5 --record steady

With a steady record at another load (``light``) the calibration also fits the flanks' lead
mismatch from how the spectrum changes with load (``face_contact_from: light``,
:mod:`twin.calibration.face_contact`), before the levels.

With both hammer records (blows at the pinion's and the gear's pedestal) the twin is
``GearTwin.Gearbox21Shafts`` and its casing sensors read the path those blows measured
(``calibration.path_from``, :mod:`twin.calibration.transfer_path`); without them,
``GearTwin.Gearbox21Measured`` with its modelled sensor path.
"""
from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np


#: The demo's hammer records and the shaft each strikes (calibration.struck_shafts): the pinion's
#: pedestal on the input shaft, the gear's on the output shaft.
STRUCK = {"hammer": "input", "hammer_gear": "output"}
#: The twin's bearing force each of those blows stands for (calibration.path_from).
PATH_FROM = {"hammer": "bearing_force_input_y", "hammer_gear": "bearing_force_output_y"}


#: The names of the optional records after the steady one and the run-up, in the order given
#: (``steady_again``: another healthy steady record, step 8's baseline repeat).
EXTRA = (*STRUCK, "light", "steady_again")


def merge_records(steady_file: Path, runup_file: Path, out: Path, *more_files: Path) -> Path:
    """One measurement file holding the first record of each file, named ``steady``, ``runup`` and
    (when given) ``hammer`` and ``hammer_gear`` (blows at the pinion's, then the gear's pedestal),
    ``light`` (a steady record at the same speed and another load) and ``steady_again`` (another
    healthy steady record at the steady one's operating point)."""
    from twin.measurements import load_measurements, write_measurements

    records = [replace(load_measurements(steady_file)[0], name="steady"),
               replace(load_measurements(runup_file)[0], name="runup")]
    records += [replace(load_measurements(f)[0], name=name) for f, name in zip(more_files, EXTRA)]
    return write_measurements(records, out)


def rig_calibration_demo(out_dir: Path, steady_file: Path, runup_file: Path, *more_files: Path) -> dict:
    """Step 6 (see the module docstring); returns the paths and headline numbers."""
    from twin.calibration.run import run_calibration
    from twin.compare import compare
    from twin.demo import _heading, _lines, _written
    from twin.modes import survey_record, survey_table
    from twin.measurements import load_measurements
    from twin.plotting import plot_modal_survey
    from twin.scenario import load_scenario

    t = time.perf_counter()
    d = out_dir / "rig"
    d.mkdir(exist_ok=True)
    h5 = merge_records(Path(steady_file), Path(runup_file), d / "pedestal.h5", *map(Path, more_files))
    mset = load_measurements(h5)
    survey = survey_record(mset["runup"])
    png = plot_modal_survey(survey, d / "modes.png", title="Run-up of the pedestal rig: modes (red), fixed lines "
                                                         "(dotted), orders (dashed)")
    _heading(6, "A gearbox the twin did not generate (rigs/pedestal, scattered 12 %): twin modes on its raw "
                "6 s run-up", time.perf_counter() - t)
    table = survey_table(survey)
    _lines(table.split("\nspeed-locked")[0])
    _lines(f"{len(survey.orders)} speed-locked orders set aside")
    if "hammer" in mset.names:
        # what `twin modes --record runup --record hammer` shows: the run-up's survey (above)
        # merged with the hammer test's, the run-up not surveyed again
        from twin.modes import MIN_CONFIDENCE, merge_surveys, with_lscf, with_struck_levels
        hammers = [mset[n] for n in STRUCK if n in mset.names]
        names = " ".join(f"--record {h.name}" for h in hammers)
        both = merge_surveys([survey, *(survey_record(h) for h in hammers)])
        alone, together = survey.frequencies(MIN_CONFIDENCE), both.frequencies(MIN_CONFIDENCE)
        added = [f for f in together if not alone.size or np.min(np.abs(alone - f)) > 0.01 * f]
        _lines(f"twin modes --record runup {names} (blows at the {' and the '.join(['pinion', 'gear'][:len(hammers)])} "
               f"pedestal, the gears rolling at {hammers[0].nominal_speed or 0:g} Hz): {together.size} modes, "
               f"{len(added)} the run-up alone did not show ({', '.join(f'{f:.0f}' for f in added) or 'none'} Hz); "
               f"{both.notes[-1] if both.notes else ''}")
        if len(hammers) == 2:
            _lines(_shaft_reading(with_struck_levels(both, hammers)))
        fitted = with_lscf(both, hammers)
        _lines(f"twin modes ... --lscf (the hammer FRFs also fitted by poly-reference LSCF, an opt-in): "
               f"{fitted.notes[-1]}")
    scenario_file = d / "scenario.yaml"
    path = all(n in mset.names for n in PATH_FROM)
    scenario_file.write_text(json.dumps({
        "version": 1, "name": "pedestal-rig", "fmu": "GearTwin.Gearbox21Shafts" if path else "GearTwin.Gearbox21Measured",
        "stop_time": 2.0,
        "output": {"sample_rate": mset["steady"].sample_rate, "variables": ["accel_pinion_casing"]},
        "operating": {"speed": mset["steady"].nominal_speed, "load": mset["steady"].load}, "seed": 0,
        "calibration": {"parameters": "auto", "modes_from": "runup", "record": "steady", "objectives": ["modes"],
                        "algorithm": "nsga2", "pop_size": 8, "n_gen": 2, **({"path_from": PATH_FROM} if path else {}),
                        **({"face_contact_from": "light"} if "light" in mset.names else {})}},
        indent=2))
    t = time.perf_counter()
    report = run_calibration(load_scenario(scenario_file), h5, out_dir / "calibration_rig", progress=False)
    pair = "light" in mset.names
    _lines(f"twin calibrate --modes-from runup{' (path_from: the two hammer records)' * path}"
           f"{' --face-contact-from light' * pair}, parameters chosen "
           f"from the modes' sensitivities ({', '.join(report.result.chosen)}; {time.perf_counter() - t:.0f} s):")
    _lines(report.table())
    _lines("\n".join((*report.notes, *(f"warning: {w}" for w in report.warnings))))
    calibrated = load_scenario(report.scenario_file)
    comp = compare(calibrated, h5, out_dir / "compare_rig", record="steady", duration=1.0)
    _lines(f"twin compare on the calibrated scenario against the steady record: {comp.lsd_db:.1f} dB, "
           f"{len(comp.findings)} findings (what the twin still lacks: docs/diagnosis.md)")
    _written(png, report.scenario_file, out_dir / "calibration_rig" / "report.html")
    return {"survey": survey, "report": report, "scenario": report.scenario_file, "compare_lsd_db": comp.lsd_db,
            "records": h5}


def _shaft_reading(survey) -> str:
    """Which shaft the surveyed modes live on, from their levels per struck pedestal (what
    ``calibration.struck_shafts`` lets the pairing read)."""
    from twin.calibration.pairing import SIDE_DB, struck_sides
    from twin.modes import MIN_CONFIDENCE

    modes = [m for m in survey.modes if m.confidence >= MIN_CONFIDENCE]
    sides = struck_sides([m.evidence for m in modes], STRUCK)
    if sides is None:
        return "struck-point levels: no mode in both hammer records' band"
    on = {k: [f"{m.frequency:.0f}" for m, s in zip(modes, sides) if test(s)] for k, test in
          (("input", lambda s: s >= SIDE_DB), ("output", lambda s: s <= -SIDE_DB),
           ("both", lambda s: abs(s) < SIDE_DB))}
    return (f"where each mode lives, from its level per struck pedestal ({SIDE_DB:g} dB or more louder from one "
            f"shaft; calibration.struck_shafts pairs no mode across shafts): input shaft {', '.join(on['input']) or '-'} "
            f"Hz; output shaft {', '.join(on['output']) or '-'} Hz; both {', '.join(on['both']) or '-'} Hz")


def loop_demo(out_dir: Path, records, calibrated, baseline=None) -> dict:
    """Step 8: ``twin diagnose`` and ``twin improve`` on a steady record and a run-up of step 6's
    gearbox of ``rigs/pedestal`` with one of the rig's own effects hidden (``records``: the two
    files, written by ``python -m rigs.pedestal ... --effect casing_resonance``), against step 6's
    calibrated scenario ``calibrated``, with step 6's records (``baseline``: the file holding its
    ``steady`` and ``runup``, and ``steady_again`` when given: a repeat whose record-to-record
    scatter raises the line threshold) as the baseline (``--baseline``): what changed since
    calibration.

    Writes ``loop/models.h5``: the model before (record ``before``) and after ``twin improve``
    (``after``; the same model when nothing was added), at the operating point the diagnosis
    measured, as long as the stretch it compared. ``make demo`` scores them against the steady
    record with ``bench/spectral_distance.py`` (floor-aware, gain-free, apart from ``twin.compare``).
    """
    import shutil

    from twin.demo import REPO, _heading, _lines, _written
    from twin.effects.loop import diagnose_scenario, history_table, improve, learn_discrepancy, read_baseline
    from twin.executor import LocalExecutor
    from twin.measurements import Record, load_measurements, write_measurements
    from twin.operating import simulate_at
    from twin.scenario import load_scenario

    t = time.perf_counter()
    loop = out_dir / "loop"
    loop.mkdir(exist_ok=True)
    (out_dir / "rig").mkdir(exist_ok=True)
    h5 = merge_records(Path(records[0]), Path(records[1]), out_dir / "rig" / "pedestal_hidden.h5")
    scenario = load_scenario(calibrated)
    base_names = ["steady", "runup"]
    if baseline is not None and "steady_again" in load_measurements(baseline).names:
        base_names.append("steady_again")
    with LocalExecutor() as ex:
        # the discrepancy learned once on the calibrated model, kept by the diagnosis and improve
        known = (learn_discrepancy(scenario, h5, read_baseline(baseline, scenario, base_names),
                                   record=["steady", "runup"], executor=ex) if baseline is not None else None)
        diag = diagnose_scenario(scenario, h5, record=["steady", "runup"], json_path=loop / "diagnosis.json",
                                 executor=ex, progress=False, baseline=known)
    took = time.perf_counter() - t
    # variants go into a copy of modelica/, so the demo leaves the repository untouched
    modelica = out_dir / "modelica"
    if modelica.exists():
        shutil.rmtree(modelica)
    shutil.copytree(REPO / "modelica", modelica, ignore=shutil.ignore_patterns("Variants"))
    history = improve(scenario, h5, loop, record=["steady", "runup"], max_steps=1, diagnosis=diag,
                      modelica_dir=modelica, build_dir=out_dir / "build", progress=False, baseline=known)
    after = load_scenario(loop / f"scenario_{history[-1].effect}.yaml") if history[-1].effect else scenario
    channel = (scenario.outputs or ("accel_pinion_casing",))[0]
    fs = diag.operating.sample_rate
    n = int(round(2.0 * fs))        # the stretch the diagnosis compared (its default duration)
    models = [Record(name, {channel: simulate_at(s.fmu_path(), dict(s.parameters), diag.operating, n, channel)},
                     {channel: "m/s2"}, fs, nominal_speed=diag.operating.drive_hz, load=diag.operating.load)
              for name, s in (("before", scenario), ("after", after))]
    write_measurements(models, loop / "models.h5")
    _heading(8, "The loop on a gearbox the twin did not generate: step 6's rigs/pedestal gearbox with a "
                "casing resonance hidden; twin diagnose --record steady --record runup --baseline (step 6's records, "
                f"{' '.join(base_names)}), "
                "then twin improve",
             time.perf_counter() - t)
    _lines(f"twin diagnose ({took:.0f} s; candidates searched on 1 s at a 20 us step, scored on 2 s at 10 us):")
    _lines(diag.table())
    _lines("twin improve --from-diagnosis:")
    _lines(history_table(history))
    _lines("the independent distance (bench/spectral_distance.py) before and after is printed by make demo next")
    _written(loop / "diagnosis.json", loop / "history.png", loop / "models.h5")
    return {"diagnosis": diag, "history": history, "records": h5, "models": loop / "models.h5"}
