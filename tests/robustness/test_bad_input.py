"""Every bad input is one typed ``twin: error:`` line (exit 2) that names the bad value, and the
good inputs next to them work.  In-process through ``twin.cli.main`` (fast); the FMU faults and
the last line of defence through a real ``twin`` process."""
from __future__ import annotations

import pytest
from cli_runner import one_error_line, run_twin

from twin.cli import main

SCENARIO = """version: 1
name: s
fmu: {fmu}
stop_time: 0.05
communication_step: 0.01
output: {{sample_rate: 100000, variables: [accel_pinion_casing]}}
operating: {{speed: {{constant: 20}}, load: {{constant: 20}}}}
"""


@pytest.fixture
def cli(capsys):
    def run(*args) -> tuple[int, str, str]:
        code = main([str(a) for a in args])
        out, err = capsys.readouterr()
        return code, out, err
    return run


SIMULATE_TIMES = [
    (["--stop-time=nan"], "nan"), (["--stop-time=inf"], "inf"), (["--stop-time=-inf"], "inf"),
    (["--stop-time=1e5", "--output-interval=1e-5"], "TiB"), (["--stop-time=1e12"], "memory"), (["--stop-time=-1"], "-1"),
    (["--stop-time=0"], "after --start-time"), (["--stop-time=1e-7"], "no output sample"),
    (["--stop-time=0.1", "--start-time=nan"], "nan"), (["--stop-time=0.1", "--output-interval=0"], "> 0"),
    (["--stop-time=0.1", "--output-interval=-1e-5"], "> 0"), (["--stop-time=0.1", "--output-interval=nan"], "nan"),
    (["--stop-time=0.100005"], "whole number of output intervals"),
    (["--stop-time=0.1", "--timeout=0"], "positive"),
]


@pytest.mark.parametrize("extra, words", SIMULATE_TIMES, ids=[" ".join(e) for e, _ in SIMULATE_TIMES])
def test_simulate_refuses_bad_times(cli, gearbox_fmu, tmp_path, extra, words):
    code, _, err = cli("simulate", gearbox_fmu, "--output", tmp_path / "s.h5", "--no-progress", *extra)
    assert code == 2 and words in err and "Traceback" not in err
    assert not (tmp_path / "s.h5").exists()


SIMULATE_VALUES = [
    ("--param", "no_such=1", "no variable 'no_such'"), ("--param", "c_mesh=-1e9", "damping cannot be negative"),
    ("--param", "m5=0", "mass must be positive"), ("--param", "kx45=-1", "stiffness cannot be negative"),
    ("--param", "mesh_stiffness_scale=-1", "stiffness scale"), ("--param", "load_torque=5", "is an input"),
    ("--param", "accel_pinion_casing=1", "is an output"), ("--input", "c_mesh=3", "is a parameter"),
    ("--input", "no_such=1", "no variable"), ("--input", "load_torque=nan", "finite"),
]


@pytest.mark.parametrize("option, token, words", SIMULATE_VALUES, ids=[f"{o} {t}" for o, t, _ in SIMULATE_VALUES])
def test_simulate_refuses_bad_parameters_and_inputs(cli, gearbox_fmu, tmp_path, option, token, words):
    code, _, err = cli("simulate", gearbox_fmu, "--stop-time", "0.01", "--output", tmp_path / "s.h5", "--no-progress",
                       option, token)
    assert code == 2 and words in err, err
    assert not (tmp_path / "s.h5").exists()


@pytest.mark.parametrize("output, words", [("nodir/s.h5", "does not exist"), ("d.h5", "is a directory"),
                                           ("s.mat", "'.mat'"), ("/sys/s.h5", "/sys")])
def test_simulate_refuses_bad_output_paths(cli, gearbox_fmu, tmp_path, monkeypatch, output, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d.h5").mkdir()
    code, _, err = cli("simulate", gearbox_fmu, "--stop-time", "0.01", "--output", output, "--no-progress")
    assert code == 2 and words in err, err


def test_simulate_good_run_and_implausible_parameters(cli, gearbox_fmu, tmp_path):
    ok = cli("simulate", gearbox_fmu, "--stop-time", "0.02", "--output", tmp_path / "s.h5", "--no-progress")
    assert ok[0] == 0 and (tmp_path / "s.h5").exists()
    before = (tmp_path / "s.h5").read_bytes()
    code, _, err = cli("simulate", gearbox_fmu, "--stop-time", "0.2", "--output", tmp_path / "s.h5", "--no-progress",
                       "--param", "mesh_stiffness_scale=1e6", "--input", "load_torque=20")
    assert code == 2 and "implausible run" in err and "m/s2" in err
    assert (tmp_path / "s.h5").read_bytes() == before          # the earlier result is kept


SCENARIO_EDITS = {
    "duplicate key": ("stop_time: 0.05\n", "stop_time: 0.05\nstop_time: 0.06\n", "duplicate key 'stop_time'"),
    "stop_time .nan": ("stop_time: 0.05\n", "stop_time: .nan\n", "finite number, got nan"),
    "stop_time .inf": ("stop_time: 0.05\n", "stop_time: .inf\n", "finite number, got inf"),
    "stop_time 1e12": ("stop_time: 0.05\n", "stop_time: 1.0e12\n", "memory"),
    "step .nan": ("communication_step: 0.01\n", "communication_step: .nan\n", "communication_step"),
    "sample_rate .inf": ("sample_rate: 100000", "sample_rate: .inf", "sample_rate"),
    "step longer than the run": ("communication_step: 0.01\n", "communication_step: 0.5\n", "communication_step"),
    "step not dividing the run": ("communication_step: 0.01\n", "communication_step: 0.03\n", "whole number"),
    "negative damping": ("stop_time: 0.05\n", "stop_time: 0.05\nparameters: {c_mesh: -1.0e9}\n", "negative"),
    "zero inertia": ("stop_time: 0.05\n", "stop_time: 0.05\nparameters: {I1: 0}\n", "inertia must be positive"),
    "gears apart": ("stop_time: 0.05\n", "stop_time: 0.2\nparameters: {mesh_stiffness_scale: 1.0e6}\n",
                    "implausible run"),
}


@pytest.mark.parametrize("label", list(SCENARIO_EDITS))
def test_run_refuses_bad_scenarios_and_keeps_the_earlier_result(cli, gearbox_fmu, tmp_path, label):
    good = SCENARIO.format(fmu=gearbox_fmu)
    (tmp_path / "good.yaml").write_text(good)
    out = tmp_path / "r.h5"
    assert cli("run", tmp_path / "good.yaml", "--output", out, "--no-progress")[0] == 0
    before = out.read_bytes()
    old, new, words = SCENARIO_EDITS[label]
    (tmp_path / "bad.yaml").write_text(good.replace(old, new))
    code, _, err = cli("run", tmp_path / "bad.yaml", "--output", out, "--no-progress")
    assert code == 2 and words in err, err
    assert out.read_bytes() == before
    assert not list(tmp_path.glob(".r.h5.*.tmp"))


@pytest.mark.parametrize("args, words", [
    (["run", "nope.yaml"], "does not exist"), (["run", "."], "is a directory"),
    (["run", "good.yaml", "--stop-time", "nan"], "got nan"), (["run", "good.yaml", "--stop-time", "1e5"], "memory"),
    (["run", "good.yaml", "--resume"], "--resume continues degradation runs only"),
    (["run", "good.yaml", "--output", "/sys/r.h5"], "/sys"),
    (["calibrate", "good.yaml", "--measurements", "m.h5", "--workers", "0"], "at least 1"),
])
def test_run_refuses_bad_arguments(cli, gearbox_fmu, tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "good.yaml").write_text(SCENARIO.format(fmu=gearbox_fmu))
    code, _, err = cli(*args)
    assert code == 2 and words in err, err


def test_yaml_numbers_like_1e6_are_numbers(tmp_path, gearbox_fmu):
    from twin.scenario import load_scenario
    (tmp_path / "s.yaml").write_text(SCENARIO.format(fmu=gearbox_fmu) + "parameters: {c_mesh: 1.1e3, kt12: 15e2}\n")
    assert load_scenario(tmp_path / "s.yaml").parameters == {"c_mesh": 1100.0, "kt12": 1500.0}


@pytest.mark.parametrize("mode, words", [(1, "killed by signal SIGSEGV"), (2, "exited with status 3"),
                                         (4, "killed by signal SIGABRT"), (5, "the model failed on purpose")])
def test_a_crashing_fmu_is_one_error_line(faulty_fmus, tmp_path, mode, words):
    proc = run_twin(["simulate", faulty_fmus["faulty"], "--stop-time", "0.1", "--output-interval", "0.01",
                     "--output", "f.h5", "--param", f"fault={mode}"], tmp_path)
    assert words in one_error_line(proc)
    assert not (tmp_path / "f.h5").exists()


def test_a_hanging_fmu_stops_at_the_timeout(faulty_fmus, tmp_path):
    proc = run_twin(["simulate", faulty_fmus["faulty"], "--stop-time", "0.1", "--output-interval", "0.01",
                     "--output", "f.h5", "--param", "fault=3", "--timeout", "2"], tmp_path, timeout=60)
    assert "time limit of 2 s" in one_error_line(proc)


def test_any_other_exception_is_one_line_with_a_debug_hint(tmp_path, monkeypatch, cli):
    import twin.scenario

    def broken(path):
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr(twin.scenario, "load_scenario", broken)
    code, _, err = cli("run", "x.yaml")
    assert code == 1 and err.strip() == ("twin: error: internal error ZeroDivisionError: a bug "
                                         "(re-run with --debug for the traceback)")
    with pytest.raises(ZeroDivisionError):
        main(["run", "x.yaml", "--debug"])
