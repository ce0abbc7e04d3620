"""twin pipeline: healthy records' roles, the stages in order, resuming, and early refusals."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from twin.errors import ParameterError, ScenarioError
from twin.measurements import Record, write_measurements
from twin.pipeline import PipelinePlan, healthy_roles, run_pipeline

REPO = Path(__file__).resolve().parents[2]
CH = "accel_pinion_casing"
FS = 25000.0


def _record(name, speed_from, speed_to, duration, seed, *, stage=0, time_start=0.0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FS)) / FS
    speed = speed_from + (speed_to - speed_from) * t / duration
    angle = 2 * np.pi * np.cumsum(speed) / FS
    mesh = 19 * angle
    x = (1 + 0.6 * stage) * np.sin(mesh) + 0.3 * stage * np.sin(2 * mesh + 0.4) + rng.normal(0, 0.3, t.size)
    return Record(name, {CH: x, "encoder": angle}, {CH: "m/s2", "encoder": "rad"}, FS, nominal_speed=speed_to,
                  load=20.0, tachometer="encoder", tachometer_kind="angle", time_start=time_start)


def _rig(path, timed=True):
    recs = [_record("runup", 2.0, 20.0, 3.0, 0), _record("steady", 20.0, 20.0, 1.0, 1)]
    recs += [_record(f"r{i}", 20.0, 20.0, 0.5, 10 + i, stage=k, time_start=3600.0 * i if timed else 0.0)
             for i, k in enumerate([0, 0, 1, 1, 2, 2])]
    return write_measurements(recs, path)


def _scenario(path):
    raw = yaml.safe_load((REPO / "scenarios" / "lubricated.yaml").read_text())
    raw["degradation"].update({"stop": {"pitting_density": 0.07}, "load_window": 0.05, "record_duration": 0.0})
    raw["archive"] = {"stages": [0.0, 0.03, 0.06, 0.07], "records_per_stage": 2, "record_duration": 0.1,
                      "settle_time": 0.01, "speed_scatter": 0.01, "load_scatter": 0.05, "noise": 0.05}
    raw["fmu"] = str(path.parent / "gearbox.fmu")
    path.write_text(yaml.safe_dump(raw))
    return path


def test_healthy_roles_pick_the_run_up_and_the_steady_record():
    recs = [_record("steady", 20.0, 20.0, 1.0, 1), _record("up", 2.0, 20.0, 2.0, 0)]
    assert healthy_roles(recs) == (("up",), "steady")
    # a hammer test (a force channel) joins the run-up for the modes, after it
    hammer = Record("hammer", {CH: np.zeros(100), "hammer": np.zeros(100)}, {CH: "m/s2", "hammer": "N"}, FS)
    assert healthy_roles([hammer, *recs]) == (("up", "hammer"), "steady")
    with pytest.raises(ScenarioError, match="run-up"):
        healthy_roles([_record("a", 20.0, 20.0, 1.0, 1), _record("b", 19.0, 20.0, 1.0, 2)])
    with pytest.raises(ScenarioError, match="steady record"):
        healthy_roles([_record("up", 2.0, 20.0, 2.0, 0)])
    with pytest.raises(ScenarioError, match="'up', 'hammer' was given; add a steady record"):
        healthy_roles([_record("up", 2.0, 20.0, 2.0, 0), hammer])


def test_bad_names_and_settings_are_refused_before_anything_is_written(tmp_path):
    rig = _rig(tmp_path / "rig.h5")
    out = tmp_path / "out"
    with pytest.raises(ScenarioError, match="'runp'"):
        run_pipeline(PipelinePlan(rig, ("runp", "steady"), REPO / "scenarios" / "lubricated.yaml", out))
    with pytest.raises(ScenarioError, match="degradation"):
        run_pipeline(PipelinePlan(rig, ("runup", "steady"), REPO / "scenarios" / "healthy.yaml", out))
    assert not out.exists()
    with pytest.raises(ParameterError, match="members"):
        PipelinePlan(rig, ("runup",), REPO / "scenarios" / "lubricated.yaml", out, members=1)


def test_pipeline_runs_every_stage_and_resumes(tmp_path, gearbox_fmu):
    import shutil
    shutil.copy(gearbox_fmu, tmp_path / "gearbox.fmu")
    rig, scen = _rig(tmp_path / "rig.h5"), _scenario(tmp_path / "scenario.yaml")
    plan = PipelinePlan(rig, ("runup", "steady"), scen, tmp_path / "out", members=2, epochs=1, jobs=1,
                        calibrate=False)
    lines = []
    summary = run_pipeline(plan, progress=False, log=lines.append)
    out = tmp_path / "out"
    for f in ("archive.h5", "assessor/ensemble.json", "assessment.json", "report.html", "pipeline.json",
              "stages_records.png"):
        assert (out / f).exists(), f
    res = summary["assessment"]["records"]
    assert [r["name"] for r in res["records"]] == [f"r{i}" for i in range(6)]
    assert res["time_order"] == "time_start" and res["order"]["verdict"] in ("consistent", "reversed", "unconfirmed")
    assert np.all(np.diff([r["final_stage"] for r in res["records"]]) >= 0)
    assert summary["rul"] is not None and (out / "rul_observations.json").exists()
    assert "skipped" in lines[0] and summary["ms_per_window"] > 0
    page = (out / "report.html").read_text()
    assert "Assessment" in page and "stages_records.png" in page
    # a second run keeps what is done
    lines.clear()
    run_pipeline(plan, progress=False, log=lines.append)
    assert any("archive: kept" in line for line in lines) and any("train: kept" in line for line in lines)
    stages = json.loads((out / "pipeline.json").read_text())["stages"]
    assert {"archive", "train", "report"} <= set(stages)


def _hammer(name, seed):
    rng = np.random.default_rng(seed)
    f = np.zeros(int(2 * FS))
    f[rng.choice(f.size - 100, 8, replace=False)] = 200.0
    x = np.convolve(f, np.exp(-np.arange(400) / 40.0) * np.sin(np.arange(400) * 0.3), mode="same")
    return Record(name, {CH: x + rng.normal(0, 0.01, f.size), "hammer": f}, {CH: "m/s2", "hammer": "N"}, FS,
                  nominal_speed=0.5, load=20.0)


def test_path_from_hands_the_hammer_records_and_a_model_with_bearing_forces_to_the_calibration(tmp_path,
                                                                                              monkeypatch):
    import twin.calibration.run as cal

    recs = [_record("runup", 2.0, 20.0, 3.0, 0), _record("steady", 20.0, 20.0, 1.0, 1), _hammer("hammer_p", 2),
            _record("r0", 20.0, 20.0, 0.5, 10)]
    rig = write_measurements(recs, tmp_path / "rig.h5")
    seen = {}

    class Stop(Exception):
        pass

    def calibrate(scenario, measurements, out, **kw):
        seen.update(fmu=scenario.fmu, block=scenario.raw["calibration"])
        raise Stop

    monkeypatch.setattr(cal, "run_calibration", calibrate)
    plan = PipelinePlan(rig, ("runup", "steady", "hammer_p"), REPO / "scenarios" / "lubricated.yaml",
                        tmp_path / "out", path_from={"hammer_p": "bearing_force_input_y"})
    assert plan.path_from == (("hammer_p", "bearing_force_input_y"),)
    lines = []
    with pytest.raises(Stop):
        run_pipeline(plan, progress=False, log=lines.append)
    assert seen["fmu"] == "GearTwin.Gearbox21Shafts"
    assert seen["block"]["path_from"] == {"hammer_p": "bearing_force_input_y"}
    assert seen["block"]["modes_from"] == ["runup", "hammer_p"] and seen["block"]["record"] == "steady"
    assert "path from 'hammer_p' (bearing_force_input_y)" in lines[0]
    # without the path: the modelled one, on the measured-gearbox model
    with pytest.raises(Stop):
        run_pipeline(PipelinePlan(rig, ("runup", "steady"), REPO / "scenarios" / "lubricated.yaml", tmp_path / "o2"),
                     progress=False, log=lines.append)
    assert seen["fmu"] == "GearTwin.Gearbox21Measured" and "path_from" not in seen["block"]


def test_a_path_record_must_be_healthy_and_calibrated(tmp_path, capsys):
    from twin.cli import main
    scen = REPO / "scenarios" / "lubricated.yaml"
    with pytest.raises(ParameterError, match="'hammer_p' is not among the healthy records"):
        PipelinePlan(tmp_path / "rig.h5", ("runup", "steady"), scen, tmp_path / "out",
                     path_from={"hammer_p": "bearing_force_input_y"})
    with pytest.raises(ParameterError, match="--path-from needs the calibration"):
        PipelinePlan(tmp_path / "rig.h5", ("runup", "steady", "h"), scen, tmp_path / "out", calibrate=False,
                     path_from={"h": "bearing_force_input_y"})
    assert main(["pipeline", "rig.h5", "--healthy", "a,b", "--scenario", str(scen), "--out", "o",
                 "--path-from", "hammer_p"]) == 2
    assert "expected RECORD=FORCE" in capsys.readouterr().err
