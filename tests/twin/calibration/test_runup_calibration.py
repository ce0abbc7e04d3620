"""twin calibrate from a raw run-up record: modes read from it, parameters chosen for the user, a
calibrated scenario valid wherever it is moved, a warning for a parameter on its bound.

The records are made here from the twin's own modes (a perturbed twin): they check the plumbing,
not the method (that is bench/calibration_rigs.py, on the independent rigs).
"""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from twin.calibration.run import run_calibration
from twin.calibration.model_modes import model_modes
from twin.cli import main
from twin.errors import ScenarioError
from twin.measurements import Record, write_measurements
from twin.operating import simulate_operating_point
from twin.scenario import load_scenario, read_parameter_file, scenario_from_dict

FS = 12800.0
TRUTH = {"kt57": 1.3e4, "ky4": 4.3e7, "ky6": 4.3e7, "kx9": 3.6e7, "kx11": 3.6e7}


@pytest.fixture(scope="module")
def rig_file(gearbox_fmu, runup_factory, tmp_path_factory):
    mm = model_modes(gearbox_fmu, TRUTH, speed_hz=20.0, load_nm=20.0)
    modes = tuple((f, z) for f, z, v in zip(mm.frequency, mm.damping, mm.visible) if v and 200 < f < 3000)
    x, angle, _ = runup_factory(fs=FS, modes=modes, lines=((300.0, 1.0),), seed=2)
    y = simulate_operating_point(gearbox_fmu, 20.0, 20.0, parameters=TRUTH, settle=0.05, duration=0.2,
                                 channels=["accel_pinion_casing"], output_interval=1 / FS)[:, 0]
    path = tmp_path_factory.mktemp("rig") / "rig.h5"
    write_measurements([
        Record("steady", {"accel_pinion_casing": y}, {"accel_pinion_casing": "m/s2"}, FS, nominal_speed=20.0, load=20.0),
        Record("runup", {"accel_pinion_casing": x, "encoder": angle}, {"accel_pinion_casing": "m/s2", "encoder": "rad"},
               FS, nominal_speed=20.0, load=20.0, tachometer="encoder", tachometer_kind="angle")], path)
    return path, np.array([f for f, _ in modes])


def _scenario(fmu, source=None, **block):
    data = {"version": 1, "name": "rigcal", "fmu": str(fmu), "stop_time": 0.2,
            "output": {"sample_rate": FS, "variables": ["accel_pinion_casing"]},
            "operating": {"speed": 20, "load": 20}, "executor": {"type": "local", "workers": 1}}
    if block:
        data["calibration"] = {"algorithm": "nsga2", "pop_size": 4, "n_gen": 2, "objectives": ["modes"],
                               "record_duration": 0.1, "settle_time": 0.05, **block}
    return scenario_from_dict(data, source=source)


@pytest.fixture(scope="module")
def calibrated(gearbox_fmu, rig_file, tmp_path_factory):
    path, _ = rig_file
    out = tmp_path_factory.mktemp("cal") / "out"
    return run_calibration(_scenario(gearbox_fmu, parameters="auto", modes_from="runup"), path, out,
                           progress=False), out


def test_modes_come_from_the_runup_and_the_calibrated_twin_reaches_them(calibrated, rig_file):
    report, out = calibrated
    _, true_modes = rig_file
    assert "read from record 'runup'" in report.modes_source
    assert report.measured_modes.size >= 4
    assert all(abs(m - 300.0) > 3 for m in report.measured_modes)            # the drive line is not a mode
    for m in report.measured_modes:                                          # every measured mode is a true one
        assert np.min(np.abs(true_modes - m) / true_modes) < 0.02
    ok = np.isfinite(report.after_modes)
    err_after = np.abs(report.after_modes[ok] - report.measured_modes[ok]) / report.measured_modes[ok]
    err_before = np.abs(report.before_modes[ok] - report.measured_modes[ok]) / report.measured_modes[ok]
    assert err_after.max() < 0.02 and err_after.max() < err_before.max()
    assert report.warnings == ()
    sens = json.loads((out / "sensitivity.json").read_text())
    assert sens["chosen"] and all(p["left_out"] for p in sens["parameters"] if not p["chosen"])
    modes = json.loads((out / "modes.json").read_text())
    assert modes["record"] == "runup" and any(abs(ln["frequency_hz"] - 300.0) < 0.5 for ln in modes["lines"])


def test_the_calibrated_scenario_holds_the_calibrated_set_and_survives_a_move(calibrated, tmp_path):
    report, out = calibrated
    moved = tmp_path / "elsewhere" / "calibration"
    shutil.copytree(out, moved)
    sc = load_scenario(moved / "calibrated.yaml")
    cal = read_parameter_file(out / "calibrated.json")
    assert dict(sc.parameters) == cal
    assert set(report.result.chosen) <= set(sc.parameters)
    assert sc.name == "rigcal-calibrated" and sc.fmu_path().exists()


def test_relative_paths_of_the_input_scenario_stay_valid(gearbox_fmu, rig_file, tmp_path):
    path, _ = rig_file
    home = tmp_path / "project"
    home.mkdir()
    shutil.copy(gearbox_fmu, home / "box.fmu")
    (home / "speed.csv").write_text("time,speed\n0,20\n1,20\n")
    extra = home / "extra.json"
    extra.write_text(json.dumps({"c_mesh": 1000.0}))
    data = {"version": 1, "name": "rel", "fmu": "box.fmu", "stop_time": 0.2, "parameter_files": ["extra.json"],
            "output": {"sample_rate": FS, "variables": ["accel_pinion_casing"]},
            "operating": {"speed": {"table": {"file": "speed.csv", "column": "speed"}}, "load": 20},
            "calibration": {"parameters": {"kt57": [9000.0, 24000.0]}, "natural_frequencies": [930.0],
                            "objectives": ["modes"], "algorithm": "nsga2", "pop_size": 4, "n_gen": 1,
                            "record_duration": 0.1, "settle_time": 0.05}}
    (home / "rel.yaml").write_text(json.dumps(data))
    run_calibration(load_scenario(home / "rel.yaml"), path, tmp_path / "out", progress=False)
    moved = tmp_path / "far" / "away"
    shutil.copytree(tmp_path / "out", moved)
    sc = load_scenario(moved / "calibrated.yaml")
    assert sc.fmu_path() == (home / "box.fmu").resolve()
    assert sc.parameters["c_mesh"] == 1000.0 and "kt57" in sc.parameters
    assert sc.inputs["motor_speed_ref"](0.5) == pytest.approx(2 * np.pi * 20)


def test_a_parameter_pulled_onto_its_bound_is_reported(gearbox_fmu, rig_file, tmp_path):
    path, _ = rig_file
    mm = model_modes(gearbox_fmu, {}, speed_hz=20.0, load_nm=20.0)
    kt57_mode = float(mm.frequency[mm.visible][np.argmin(np.abs(mm.frequency[mm.visible] - 980.0))])
    sc = _scenario(gearbox_fmu, parameters={"kt57": [1.2e4, 1.8e4]}, natural_frequencies=[0.8 * kt57_mode])
    report = run_calibration(sc, path, tmp_path / "out", progress=False)
    assert len(report.warnings) == 1 and report.warnings[0].startswith("kt57 = ")
    assert "ended on a bound" in report.warnings[0]
    assert "Warnings" in (tmp_path / "out" / "report.html").read_text()


def test_modes_from_a_record_that_does_not_exist_is_refused(gearbox_fmu, rig_file, tmp_path):
    path, _ = rig_file
    with pytest.raises(ScenarioError, match="no record 'ramp'"):
        run_calibration(_scenario(gearbox_fmu, parameters="auto", modes_from="ramp"), path, tmp_path / "o",
                        progress=False)
    with pytest.raises(ScenarioError, match="must be 'auto' or a mapping"):
        _scenario(gearbox_fmu, parameters="all")


def test_cli_calibrate_with_modes_from_and_no_calibration_block(gearbox_fmu, rig_file, tmp_path, capsys):
    path, _ = rig_file
    sc = tmp_path / "sc.yaml"
    sc.write_text(json.dumps({"version": 1, "name": "cli", "fmu": str(gearbox_fmu), "stop_time": 0.2,
                              "output": {"sample_rate": FS, "variables": ["accel_pinion_casing"]},
                              "executor": {"type": "local", "workers": 1}}))
    assert main(["calibrate", str(sc), "--measurements", str(path), "--modes-from", "nope", "--out",
                 str(tmp_path / "o"), "--no-progress"]) == 2
    assert "no record 'nope'" in capsys.readouterr().err
    assert main(["calibrate", str(sc), "--out", str(tmp_path / "o")]) == 2
    assert "no calibration block: without --measurements it must type the measured natural_frequencies" in \
        capsys.readouterr().err
    assert main(["calibrate", str(sc), "--measurements", str(path), "--pairing", "nearest"]) == 2
    assert "argument --pairing: invalid choice: 'nearest'" in capsys.readouterr().err


def test_cli_sensitivity_from_a_runup(gearbox_fmu, rig_file, tmp_path, capsys):
    path, _ = rig_file
    sc = tmp_path / "sc.yaml"
    sc.write_text(json.dumps({"version": 1, "name": "cli", "fmu": str(gearbox_fmu), "stop_time": 0.2,
                              "output": {"sample_rate": FS, "variables": ["accel_pinion_casing"]}}))
    assert main(["sensitivity", str(sc), "--measurements", str(path), "--modes-from", "runup",
                 "--json", str(tmp_path / "s.json")]) == 0
    out = capsys.readouterr().out
    assert "chosen (*)" in out and "not identifiable" in out
    data = json.loads((tmp_path / "s.json").read_text())
    assert data["chosen"] and len(data["measured_hz"]) >= 4
    assert data["visibility"] == "mesh" and "load torque" in data["visible_by_excitation"]
    assert set(data["modes_hz"]) <= set(data["visible_by_excitation"]["mesh"])
    assert "by excitation (visibility: mesh" in out
    assert main(["sensitivity", str(sc), "--json", str(tmp_path / "missing" / "s.json")]) == 2
    assert main(["sensitivity", str(sc), "--pairing", "by-shape"]) == 2
    assert "argument --pairing: invalid choice: 'by-shape'" in capsys.readouterr().err


def test_cli_visibility_overrides_the_calibration_block(gearbox_fmu, rig_file, tmp_path, capsys):
    path, _ = rig_file
    sc = tmp_path / "sc.yaml"
    sc.write_text(json.dumps({"version": 1, "name": "cli", "fmu": str(gearbox_fmu), "stop_time": 0.2,
                              "output": {"sample_rate": FS, "variables": ["accel_pinion_casing"]},
                              "calibration": {"parameters": "auto", "visibility": "mesh"}}))
    assert main(["sensitivity", str(sc), "--measurements", str(path), "--modes-from", "runup", "--visibility",
                 "run-up", "--json", str(tmp_path / "s.json")]) == 0
    assert "by excitation (visibility: run-up; any column counts" in capsys.readouterr().out
    assert json.loads((tmp_path / "s.json").read_text())["visibility"] == "run-up"
    assert main(["calibrate", str(sc), "--measurements", str(path), "--visibility", "all"]) == 2
    assert "argument --visibility: invalid choice: 'all'" in capsys.readouterr().err
