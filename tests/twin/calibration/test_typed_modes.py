"""twin calibrate from typed natural frequencies alone, without a measurement file.

The "measured" modes are the linearisation of a perturbed twin: the test checks the plumbing,
not the method (that is bench/paper_modes.py, on the paper's published modes).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from twin.calibration.run import run_calibration
from twin.calibration.model_modes import model_modes
from twin.cli import main
from twin.errors import ScenarioError
from twin.scenario import load_scenario, read_parameter_file, scenario_from_dict

TRUTH = {"kt57": 1.3e4, "ky4": 4.3e7, "ky6": 4.3e7, "kx9": 3.6e7, "kx11": 3.6e7}


def _scenario(fmu, operating=None, **block):
    data = {"version": 1, "name": "typed", "fmu": str(fmu), "stop_time": 0.2,
            "output": {"variables": ["accel_pinion_casing"]}, "executor": {"type": "local", "workers": 1},
            "calibration": {"algorithm": "nsga2", "pop_size": 4, "n_gen": 2, **block}}
    if operating is not None:
        data["operating"] = operating
    return scenario_from_dict(data)


@pytest.fixture(scope="module")
def truth_modes(gearbox_fmu):
    mm = model_modes(gearbox_fmu, TRUTH, speed_hz=20.0, load_nm=20.0)
    return np.array([f for f, v in zip(mm.frequency, mm.visible) if v and 200 < f < 3000])


@pytest.mark.parametrize("fit", [{}, {"fit": "search", "search_budget": 24}], ids=["follow", "search"])
def test_typed_modes_alone_calibrate_the_twin_to_a_perturbed_variant(gearbox_fmu, truth_modes, tmp_path, fit):
    sc = _scenario(gearbox_fmu, {"speed": 20, "load": 20}, parameters="auto", pop_size=2, n_gen=1,
                   natural_frequencies=[float(f) for f in truth_modes], **fit)
    out = tmp_path / "out"
    report = run_calibration(sc, None, out, progress=False)
    assert report.objectives == ("modes",)
    for name in ("calibrated.yaml", "calibrated.json", "calibrated.ssv", "calibrated.ssp", "sensitivity.json",
                 "report.html", "pareto.csv"):
        assert (out / name).exists(), name
    assert not (out / "report_psd.png").exists()
    ok = np.isfinite(report.after_modes)
    assert ok.sum() >= 4
    err_after = np.abs(report.after_modes[ok] / truth_modes[ok] - 1)
    err_before = np.abs(report.before_modes[ok] / truth_modes[ok] - 1)
    assert err_after.max() < 0.01 < err_before.max()
    assert json.loads((out / "sensitivity.json").read_text())["chosen"]
    cal = load_scenario(out / "calibrated.yaml")
    assert dict(cal.parameters) == read_parameter_file(out / "calibrated.json")
    html = (out / "report.html").read_text()
    assert "Table 2" in html and "none (typed modes only)" in html and "report_psd.png\"" not in html


def test_the_operating_point_comes_from_the_constant_profile(gearbox_fmu):
    from twin.calibration.typed_modes import typed_operating_point
    sc = _scenario(gearbox_fmu, {"speed": 12.5, "load": {"constant": 7}}, parameters="auto",
                   natural_frequencies=[400.0])
    assert typed_operating_point(sc, sc.raw["calibration"]) == (12.5, 7.0)
    assert typed_operating_point(sc, {"speed": 20, "load": 20}) == (20.0, 20.0)
    ramp = _scenario(gearbox_fmu, {"speed": {"ramp": {"from": 2, "to": 20, "duration": 0.2}}}, parameters="auto",
                     natural_frequencies=[400.0])
    with pytest.raises(ScenarioError, match="(?s)calibration.speed: .*calibration.load: "):
        typed_operating_point(ramp, ramp.raw["calibration"])


@pytest.mark.parametrize("block, words", [
    ({"objectives": ["correlation", "modes"]}, "calibration.objectives: correlation need a measured record"),
    ({"objectives": ["frequencies"]}, "calibration.objectives: frequencies need a measured record"),
    ({"modes_from": "runup"}, "calibration.modes_from: reads the modes from record 'runup'"),
    ({"natural_frequencies": None}, "calibration.natural_frequencies: without --measurements"),
])
def test_a_block_that_needs_a_record_is_refused_by_name(gearbox_fmu, tmp_path, block, words):
    spec = {"parameters": "auto", "natural_frequencies": [400.0, 900.0], **block}
    spec = {k: v for k, v in spec.items() if v is not None}
    with pytest.raises(ScenarioError, match=words):
        run_calibration(_scenario(gearbox_fmu, {"speed": 20, "load": 20}, **spec), None, tmp_path / "out",
                        progress=False)
    assert not (tmp_path / "out").exists()


def test_cli_without_measurements_refuses_a_signal_objective(gearbox_fmu, tmp_path, capsys):
    import yaml
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"version": 1, "name": "typed", "fmu": str(gearbox_fmu),
                                    "operating": {"speed": 20, "load": 20},
                                    "calibration": {"parameters": "auto", "natural_frequencies": [400.0],
                                                    "objectives": ["waveform"]}}))
    assert main(["calibrate", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "calibration.objectives: waveform need a measured record" in capsys.readouterr().err


def test_twin_sensitivity_studies_the_typed_modes_at_the_blocks_operating_point(gearbox_fmu, monkeypatch):
    import twin.calibration.sensitivity as sensitivity
    from twin.calibration.run import scenario_sensitivity
    seen = {}
    monkeypatch.setattr(sensitivity, "mode_sensitivity", lambda fmu, values, freqs, **kw: seen.update(kw, freqs=freqs))
    sc = _scenario(gearbox_fmu, {"speed": 20, "load": 20}, parameters="auto", natural_frequencies=[400.0, 900.0],
                   speed=12.5, load=7)
    scenario_sensitivity(sc)
    assert (seen["speed_hz"], seen["load_nm"]) == (12.5, 7.0) and list(seen["freqs"]) == [400.0, 900.0]
