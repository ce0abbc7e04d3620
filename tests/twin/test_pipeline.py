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
