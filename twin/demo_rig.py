"""Demo step 6: a gearbox the twin did not generate, from its raw records to a calibrated scenario.

The records come from files (``make demo`` writes them with ``python -m rigs.pedestal runup``
and ``steady``; ``twin`` never imports ``rigs``). The step does what a user does with a rig:

    twin modes rig.h5 --record runup --plot modes.png
    twin calibrate scenario.yaml --measurements rig.h5 --modes-from runup --out calibration_rig/
    twin compare calibration_rig/calibrated.yaml --measurements rig.h5 --record steady
"""
from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path


def merge_records(steady_file: Path, runup_file: Path, out: Path) -> Path:
    """One measurement file holding the first record of each file, named ``steady`` and ``runup``."""
    from twin.measurements import load_measurements, write_measurements

    steady = replace(load_measurements(steady_file)[0], name="steady")
    runup = replace(load_measurements(runup_file)[0], name="runup")
    return write_measurements([steady, runup], out)


def rig_calibration_demo(out_dir: Path, steady_file: Path, runup_file: Path) -> dict:
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
    h5 = merge_records(Path(steady_file), Path(runup_file), d / "pedestal.h5")
    mset = load_measurements(h5)
    survey = survey_record(mset["runup"])
    png = plot_modal_survey(survey, d / "modes.png", title="Run-up of the pedestal rig: modes (red), fixed lines "
                                                         "(dotted), orders (dashed)")
    _heading(6, "A gearbox the twin did not generate (rigs/pedestal, scattered 12 %): twin modes on its raw "
                "6 s run-up", time.perf_counter() - t)
    table = survey_table(survey)
    _lines(table.split("\nspeed-locked")[0])
    _lines(f"{len(survey.orders)} speed-locked orders set aside")
    scenario_file = d / "scenario.yaml"
    scenario_file.write_text(json.dumps({
        "version": 1, "name": "pedestal-rig", "fmu": "GearTwin.Gearbox21Measured", "stop_time": 2.0,
        "output": {"sample_rate": mset["steady"].sample_rate, "variables": ["accel_pinion_casing"]},
        "operating": {"speed": mset["steady"].nominal_speed, "load": mset["steady"].load}, "seed": 0,
        "calibration": {"parameters": "auto", "modes_from": "runup", "record": "steady", "objectives": ["modes"],
                        "algorithm": "nsga2", "pop_size": 8, "n_gen": 2}}, indent=2))
    t = time.perf_counter()
    report = run_calibration(load_scenario(scenario_file), h5, out_dir / "calibration_rig", progress=False)
    _lines(f"twin calibrate --modes-from runup, parameters chosen from the modes' sensitivities "
           f"({', '.join(report.result.chosen)}; {time.perf_counter() - t:.0f} s):")
    _lines(report.table())
    _lines("\n".join((*report.notes, *(f"warning: {w}" for w in report.warnings))))
    calibrated = load_scenario(report.scenario_file)
    comp = compare(calibrated, h5, out_dir / "compare_rig", record="steady", duration=1.0)
    _lines(f"twin compare on the calibrated scenario against the steady record: {comp.lsd_db:.1f} dB, "
           f"{len(comp.findings)} findings (what the twin still lacks: docs/diagnosis.md)")
    _written(png, report.scenario_file, out_dir / "calibration_rig" / "report.html")
    return {"survey": survey, "report": report, "scenario": report.scenario_file, "compare_lsd_db": comp.lsd_db}
