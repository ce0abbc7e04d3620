"""The loop on files: twin improve (diagnose -> add-effect -> recalibrate) on a hidden local tooth damage."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture
def case_files(tmp_path, gearbox_fmu, candidates_fmu):
    import yaml

    from twin.effects.synthetic import calibrate_base, make_case, write_case
    case = make_case("local_tooth_damage", 3, candidates_fmu=candidates_fmu)
    params = calibrate_base(case, gearbox_fmu)
    meas = write_case(case, tmp_path / "measured.h5")
    scen = tmp_path / "twin.yaml"
    scen.write_text(yaml.safe_dump({"version": 1, "name": "rig", "fmu": str(gearbox_fmu), "stop_time": 1.0,
                                    "parameters": params}))
    modelica = tmp_path / "modelica"
    shutil.copytree(REPO / "modelica", modelica, ignore=shutil.ignore_patterns("Variants"))
    return scen, meas, modelica


@pytest.mark.slow
def test_improve_adds_the_missing_effect_and_stops(case_files, tmp_path, capsys):
    import json

    from twin.cli import main
    from twin.scenario import load_scenario
    scen, meas, modelica = case_files
    assert main(["improve", str(scen), "--measurements", str(meas), "--out", str(tmp_path / "loop"),
                 "--max-steps", "2", "--workers", "2", "--modelica-dir", str(modelica)]) == 0
    assert "local_tooth_damage" in capsys.readouterr().out
    history = json.loads((tmp_path / "loop" / "history.json").read_text())["steps"]
    first = history[0]
    assert first["effect"] == "local_tooth_damage"
    assert first["lsd_after_db"] <= 0.5 * first["lsd_before_db"]
    # the variant is a readable Modelica file that extends the base with the component
    src = (modelica / "GearTwin" / "Variants" / "Gearbox21_local_tooth_damage.mo").read_text()
    assert "extends GearTwin.Gearbox21(" in src and "GearTwin.Effects.LocalToothDamage local_tooth_damage(" in src
    # the loop stopped: the next diagnosis found nothing that helps
    assert len(history) <= 2 and (len(history) == 1 or history[1]["effect"] is None)
    for f in ("history.csv", "history.json", "history.png", "diagnosis_1.json", "add_effect_local_tooth_damage.json",
              "scenario_local_tooth_damage.yaml"):
        assert (tmp_path / "loop" / f).exists(), f
    # the variant's scenario runs through the CLI like any other
    assert main(["info", str(load_scenario(tmp_path / "loop" / "scenario_local_tooth_damage.yaml").fmu_path())]) == 0


def test_add_effect_refuses_an_effect_the_model_has_and_an_unknown_one(case_files, tmp_path):
    from twin.effects.loop import add_effect
    from twin.errors import ParameterError
    from twin.scenario import load_scenario
    scen, meas, modelica = case_files
    with pytest.raises(ParameterError, match="unknown effect 'gremlins'"):
        add_effect(load_scenario(scen), meas, "gremlins", tmp_path / "o", modelica_dir=modelica)
    assert not (modelica / "GearTwin" / "Variants").exists()     # nothing written


def test_diagnose_cli_reports_a_missing_measurement_attribute(tmp_path, gearbox_fmu, capsys):
    import numpy as np
    import yaml

    from twin.cli import main
    from twin.measurements import Record, write_measurements
    write_measurements([Record("r", {"accel_pinion_casing": np.zeros(20000)}, {"accel_pinion_casing": "m/s2"},
                               20000.0)], tmp_path / "m.h5")
    scen = tmp_path / "s.yaml"
    scen.write_text(yaml.safe_dump({"version": 1, "name": "s", "fmu": str(gearbox_fmu), "stop_time": 1.0}))
    assert main(["diagnose", str(scen), "--measurements", str(tmp_path / "m.h5")]) == 2
    assert "nominal_speed" in capsys.readouterr().err


def test_unknown_record_name_is_a_typed_error_naming_the_records(tmp_path, gearbox_fmu, capsys):
    import numpy as np
    import yaml

    from twin.cli import main
    from twin.measurements import Record, write_measurements
    write_measurements([Record("run1", {"accel_pinion_casing": np.zeros(20000)}, {"accel_pinion_casing": "m/s2"},
                               20000.0, nominal_speed=20.0, load=20.0)], tmp_path / "m.h5")
    scen = tmp_path / "s.yaml"
    scen.write_text(yaml.safe_dump({"version": 1, "name": "s", "fmu": str(gearbox_fmu), "stop_time": 1.0}))
    for command in (["diagnose"], ["compare", "--out", str(tmp_path / "c")]):
        assert main([*command, str(scen), "--measurements", str(tmp_path / "m.h5"), "--record", "run9"]) == 2
        err = capsys.readouterr().err
        assert "run9" in err and "run1" in err
