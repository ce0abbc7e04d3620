"""The twin CLI shell, with the library modules replaced by fakes (no FMU needed)."""
from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import fmu_build
from twin.cli import main, parse_assignments
from twin.errors import ParameterError, SimulationError
from twin.results import SimulationResult, read_hdf5


@pytest.fixture
def fake_fmu(monkeypatch):
    """Install a fake ``twin.fmu`` module; returns the list of simulate_fmu calls."""
    calls: list[tuple[tuple, dict]] = []

    def simulate_fmu(path, **kwargs):
        calls.append(((path,), kwargs))
        interval = kwargs["output_interval"] or 0.1
        t = np.arange(11) * interval
        return SimulationResult(time=t, signals={"a": np.cos(t)}, units={"a": "m/s2"},
                                sample_rate=1.0 / interval, parameters=kwargs["parameters"])

    module = types.ModuleType("twin.fmu")
    module.simulate_fmu = simulate_fmu
    module.describe = lambda path: f"FMU {path.name}: fake"
    module.is_gearbox_model = lambda path: path.name.startswith("GearTwin")
    monkeypatch.setitem(sys.modules, "twin.fmu", module)
    # in process (the call list above must see the calls) and without opening a real FMU
    monkeypatch.setattr("twin.isolation.run_isolated", lambda fn, *a, what="", timeout=None, **k: fn(*a, **k))
    monkeypatch.setattr("twin.checks.check_assignments", lambda fmu, parameters, inputs, values=None: None)
    monkeypatch.setattr("twin.checks.check_times", lambda *args, **kwargs: None)   # it would read the FMU
    return calls


def test_help(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for command in ("build", "info", "simulate", "demo"):
        assert command in out


def test_help_subprocess_is_lazy():
    code = "import sys, twin.cli; sys.exit(twin.cli.main(['--help']) or ('numpy' in sys.modules))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "usage: twin" in done.stdout


def test_usage_error_exit_code(capsys):
    assert main(["simulate", "x.fmu", "--stop-time", "soon"]) == 2
    assert "--stop-time" in capsys.readouterr().err


@pytest.mark.parametrize("token", ["k_mesh", "=3", "k mesh=1", "k="])
def test_bad_param_token(tmp_path, capsys, fake_fmu, token):
    code = main(["simulate", "m.fmu", "--stop-time", "1", "--output", str(tmp_path / "r.h5"),
                 "--param", "ok=1", "--param", token])
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("twin: error: ") and f"'{token}'" in err
    assert fake_fmu == []  # rejected before simulating


def test_bad_input_token(tmp_path, capsys, fake_fmu):
    assert main(["simulate", "m.fmu", "--stop-time", "1", "--input", "torque:5"]) == 2
    assert "--input 'torque:5'" in capsys.readouterr().err


def test_parse_assignments_duplicate():
    """Values stay text: the FMU converts them to each variable's type (and refuses what does not fit)."""
    assert parse_assignments(["a=1", "b=-2.5e3", "c=fast", "d=x=y"], "--param") == \
        {"a": "1", "b": "-2.5e3", "c": "fast", "d": "x=y"}
    with pytest.raises(ParameterError, match="'a=2'"):
        parse_assignments(["a=1", "a=2"], "--param")


def test_simulate_writes_result(tmp_path, capsys, fake_fmu):
    out = tmp_path / "r.h5"
    code = main(["simulate", "m.fmu", "--stop-time", "0.5", "--output-interval", "0.01",
                 "--output", str(out), "--outputs", "a, b", "--param", "k=2e8",
                 "--input", "torque=10", "--no-progress"])
    assert code == 0
    (path,), kwargs = fake_fmu[0]
    assert path.name == "m.fmu"
    assert kwargs == {"stop_time": 0.5, "start_time": None, "output_interval": 0.01,
                      "outputs": ["a", "b"], "parameters": {"k": "2e8"},
                      "inputs": {"torque": "10"}, "progress": False}
    assert f"wrote {out}: 11 samples x 1 channels" in capsys.readouterr().out


def test_simulate_bad_output_fails_before_running(tmp_path, capsys, fake_fmu):
    assert main(["simulate", "m.fmu", "--stop-time", "1", "--output", str(tmp_path / "r.mat")]) == 2
    assert "'.mat'" in capsys.readouterr().err and fake_fmu == []


def test_twin_error_is_reported(monkeypatch, capsys, fake_fmu, tmp_path):
    def boom(path, **kwargs):
        raise SimulationError("doStep failed", time=0.25, status="fmi2Error")

    monkeypatch.setattr(sys.modules["twin.fmu"], "simulate_fmu", boom)
    assert main(["simulate", "m.fmu", "--stop-time", "1", "--output", str(tmp_path / "r.h5")]) == 2
    assert capsys.readouterr().err.strip() == \
        "twin: error: doStep failed at t=0.25 s (status fmi2Error)"


def test_info_prints_mode_table(monkeypatch, capsys, fake_fmu):
    module = types.ModuleType("twin.linearize")
    module.natural_frequencies = lambda path, n: np.array([22.0, 88.74])
    monkeypatch.setitem(sys.modules, "twin.linearize", module)
    assert main(["info", "GearTwin.Gearbox21.fmu", "--modes"]) == 0
    out = capsys.readouterr().out
    assert "FMU GearTwin.Gearbox21.fmu: fake" in out
    assert "+2.0" in out and "1927" in out  # 88.74 vs 87 Hz; mode 8 listed without model value


def test_info_of_another_model_has_no_paper_table(monkeypatch, capsys, fake_fmu):
    module = types.ModuleType("twin.linearize")
    module.natural_frequencies = lambda path, n: np.array([3.5, 12.25])
    monkeypatch.setitem(sys.modules, "twin.linearize", module)
    assert main(["info", "m.fmu", "--modes"]) == 0
    out = capsys.readouterr().out
    assert "natural frequencies (linearised model)" in out and "12.25" in out
    assert "paper" not in out and "1927" not in out


def test_info_no_modes_skips_linearize(monkeypatch, capsys, fake_fmu):
    monkeypatch.setitem(sys.modules, "twin.linearize", None)  # importing it would fail
    assert main(["info", "m.fmu", "--no-modes"]) == 0
    assert capsys.readouterr().out.strip() == "FMU m.fmu: fake"
    assert main(["info", "m.fmu"]) == 0                       # fast by default: no linearisation
    assert capsys.readouterr().out.strip() == "FMU m.fmu: fake"


def test_info_compares_with_a_records_modes(monkeypatch, capsys, fake_fmu):
    from twin.signals.survey import Mode

    module = types.ModuleType("twin.linearize")
    module.natural_frequencies = lambda path, n: np.array([21.0, 90.0, 300.0, 440.0])[:n]
    monkeypatch.setitem(sys.modules, "twin.linearize", module)
    survey = types.SimpleNamespace(method="runup", modes=[Mode(88.0, 0.02, 0.9, 10.0), Mode(430.0, 0.02, 0.6, 8.0),
                                                          Mode(600.0, 0.02, 0.1, 2.0)])
    survey.frequencies = lambda min_confidence=0.0: np.array(sorted(m.frequency for m in survey.modes
                                                                    if m.confidence >= min_confidence))
    modes = types.ModuleType("twin.modes")
    modes.survey_file = lambda path, record: survey
    monkeypatch.setitem(sys.modules, "twin.modes", modes)
    assert main(["info", "m.fmu", "--measurements", "rec.h5"]) == 0
    out = capsys.readouterr().out
    assert "rec.h5 (runup, 2 mode(s) with confidence >= 0.3)" in out
    assert "   1           88.0        0.90         90.0      +2.3" in out
    assert "   2          430.0        0.60        440.0      +2.3" in out
    assert "600" not in out and "mean |diff| over 2 matched mode(s): 2.3 %" in out


def test_build_defaults(monkeypatch, capsys, tmp_path):
    calls = []

    def build_fmu(model, modelica_dir, out_dir, *, step_size, force):
        calls.append((model, modelica_dir, out_dir, step_size, force))
        return out_dir / f"{model}.fmu"

    monkeypatch.setattr(fmu_build, "build_fmu", build_fmu, raising=False)
    assert main(["build", "--out", str(tmp_path)]) == 0
    assert calls == [("GearTwin.Gearbox21", Path("modelica"), tmp_path,
                      5e-6, False)]
    assert capsys.readouterr().out.strip() == str(tmp_path / "GearTwin.Gearbox21.fmu")


@pytest.mark.parametrize("command", [["run", "scenarios/lubricated.yaml", "--output"],
                                     ["archive", "scenarios/lubricated.yaml", "--out"]])
def test_hdf5_only_outputs_refuse_other_suffixes_before_running(tmp_path, capsys, command):
    """A degradation run and an archive only exist as HDF5: a .csv name is refused, not filled with HDF5."""
    repo = Path(__file__).resolve().parents[2]
    command = [str(repo / c) if c.startswith("scenarios/") else c for c in command]
    out = tmp_path / "stages.csv"
    assert main([*command, str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "writes HDF5" in err and "'.csv'" in err and not out.exists()
