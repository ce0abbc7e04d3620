"""``twin simulate`` against ``fmpy.simulate_fmu`` on the project's own type-coverage FMUs.

tests/thirdparty/typecov holds three hand-written models, each built for FMI 2.0 and FMI 3.0,
that together have the behaviours importers are checked with: variables of every type, a
constant, a calculated and a structural parameter, a resource file (AllTypes); time events and
an experiment the FMU ends itself (Staircase, like the Reference FMUs' Stair); state events and
units through type definitions (Ball).  Each runs through ``twin simulate`` with no option but
the output path, and every output must equal fmpy's simulation of the same FMU bit for bit, on
the same sample times, in HDF5 and in CSV.  fmpy does not record String variables; those are
checked against the model's own definition.
"""
from __future__ import annotations

import math

import fmpy
import numpy as np
import pytest

from twin.cli import main
from twin.results import read_result

pytestmark = pytest.mark.needs_gcc

MODELS = [(m, v) for v in (2, 3) for m in ("AllTypes", "Staircase", "Ball")]


def _strings(model: str, version: int) -> dict[str, str]:
    """The String outputs of each model at its start values (fmpy does not record them)."""
    return {"AllTypes": {"String_output": "gear:abc", "resource_text": "hello from the resources folder"},
            "Staircase": {}, "Ball": {}}[model]


def _compare(twin_result, reference) -> None:
    np.testing.assert_array_equal(twin_result.time, reference["time"])
    for name in reference.dtype.names[1:]:
        expected = reference[name]
        got = twin_result[name]
        assert got.dtype == expected.dtype, (name, got.dtype, expected.dtype)
        np.testing.assert_array_equal(got, expected, err_msg=name)


@pytest.mark.parametrize("model,version", MODELS)
@pytest.mark.parametrize("suffix", [".h5", ".csv"])
def test_simulate_with_no_options_equals_fmpy(typecov_fmus, tmp_path, capsys, model, version, suffix):
    fmu = typecov_fmus[(model, version)]
    out = tmp_path / f"{model}{suffix}"
    assert main(["simulate", str(fmu), "--output", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr()
    result = read_result(out)
    reference = fmpy.simulate_fmu(str(fmu))
    _compare(result, reference)
    # twin records every output fmpy does, and the String outputs fmpy leaves out
    md = fmpy.read_model_description(str(fmu))
    outputs = {v.name for v in md.modelVariables if v.causality == "output" and v.type != "Binary"}
    assert set(result.channels) == outputs
    for name, value in _strings(model, version).items():
        assert set(result[name]) == {value}
    if model == "AllTypes" and version == 3:
        assert "not recorded: Binary_output (Binary)" in printed.err
    if model == "Staircase":
        # the FMU ends the experiment at t = 9 s, the tenth step of the stair
        assert result.ended_by_fmu and result.time[-1] == 9.0 and result["counter"][-1] == 10
        assert "ended the run itself" in printed.out
        assert ("fmi2Discard with fmi2Terminated" if version == 2 else "terminateSimulation") in result.end_reason
    else:
        assert not result.ended_by_fmu


def test_default_experiment_sets_the_span_and_interval(typecov_fmus, tmp_path):
    out = tmp_path / "ball.h5"
    assert main(["simulate", str(typecov_fmus[("Ball", 2)]), "--output", str(out), "--no-progress"]) == 0
    result = read_result(out)
    assert len(result) == 301 and result.time[-1] == 3.0 and result.sample_rate == pytest.approx(100.0)


@pytest.mark.parametrize("version", [2, 3])
def test_parameters_inputs_and_start_values_of_every_type_equal_fmpy(typecov_fmus, tmp_path, version):
    fmu = typecov_fmus[("AllTypes", version)]
    params = {"gain": "3", "step": "2", "invert": "true", "label": "wheel", "mode": "fast"}
    inputs = {"Real_input": "0.5", "Integer_input": "-4", "Boolean_input": "true", "String_input": "xyz",
              "Enumeration_input": "off"}
    start_values = {"gain": 3.0, "step": 2, "invert": True, "label": "wheel", "mode": 3, "Real_input": 0.5,
                    "Integer_input": -4, "Boolean_input": True, "String_input": "xyz", "Enumeration_input": 1}
    if version == 3:
        params |= {"Int8_parameter": "-7", "UInt64_parameter": "0"}
        inputs |= {"Float32_input": "1.5", "UInt64_input": str(2**64 - 1), "Int16_input": "-32768"}
        start_values |= {"Int8_parameter": -7, "UInt64_parameter": 0, "Float32_input": 1.5,
                         "UInt64_input": 2**64 - 1, "Int16_input": -32768}
    argv = ["simulate", str(fmu), "--output", str(tmp_path / "r.h5"), "--no-progress"]
    for k, v in params.items():
        argv += ["--param", f"{k}={v}"]
    for k, v in inputs.items():
        argv += ["--input", f"{k}={v}"]
    assert main(argv) == 0
    result = read_result(tmp_path / "r.h5")
    _compare(result, fmpy.simulate_fmu(str(fmu), start_values=start_values))
    assert set(result["String_output"]) == {"wheel:xyz"}
    assert result["Enumeration_output"][0] == 1          # Boolean_input: Enumeration_input (off)
    assert result.enumerations["Enumeration_output"] == {"off": 1, "slow": 2, "fast": 3}
    # parameters are recorded as they were after initialisation, typed
    assert result.parameters["label"] == "wheel" and result.parameters["invert"] is True
    assert result.parameters["mode"] == 3 and result.parameters["step"] == 2
    if version == 3:
        assert result["UInt64_output"][0] == 2**64 - 1 and result["UInt64_output"].dtype == np.uint64


def test_self_ended_run_with_a_parameter_equals_fmpy(typecov_fmus, tmp_path):
    for version in (2, 3):
        fmu = typecov_fmus[("Staircase", version)]
        out = tmp_path / f"stair{version}.csv"
        assert main(["simulate", str(fmu), "--output", str(out), "--param", "last=5", "--no-progress"]) == 0
        result = read_result(out)
        _compare(result, fmpy.simulate_fmu(str(fmu), start_values={"last": 5}))
        assert result.ended_by_fmu and result.time[-1] == 4.0 and list(result["label"][-2:]) == ["step 4", "step 5"]


def _impacts(h0: float, g: float, e: float, v_min: float, t_end: float) -> list[float]:
    """Impact times of the ball, in closed form."""
    t, v, times = math.sqrt(2 * h0 / g), math.sqrt(2 * g * h0), []
    while t <= t_end:
        times.append(t)
        v *= e
        if v < v_min:
            break
        t += 2 * v / g
    return times


def test_ball_bounces_on_the_samples_the_closed_form_gives(typecov_fmus, tmp_path):
    """Every impact lands in the output sample interval where the closed form puts it, in both
    FMI versions, with units from the declared types."""
    for version in (2, 3):
        out = tmp_path / f"ball{version}.h5"
        assert main(["simulate", str(typecov_fmus[("Ball", version)]), "--output", str(out),
                     "--param", "e=0.6", "--param", "h=1.5", "--no-progress"]) == 0
        result = read_result(out)
        impacts = _impacts(1.5, 9.81, 0.6, 0.1, 3.0)
        expected = np.searchsorted(np.array(impacts), result.time, side="right")
        np.testing.assert_array_equal(result["bounces"], expected)
        assert len(impacts) >= 8
        assert result.units == {"h": "m", "v": "m/s", "bounces": "", "energy": "J/kg", "resting": ""}


def test_read_only_and_bad_values_are_refused_in_cli_terms(typecov_fmus, tmp_path, capsys):
    fmu = str(typecov_fmus[("AllTypes", 3)])
    out = tmp_path / "never.h5"
    assert main(["simulate", fmu, "--output", str(out), "--param", "teeth=20", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "'teeth' of AllTypes is a constant (value 19" in err and "--param" in err and "twin info" in err
    assert "()" not in err                                    # no Python method in the advice
    assert main(["simulate", fmu, "--output", str(out), "--param", "sections=2", "--param", "gain=fast",
                 "--input", "Int8_input=300", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "--param sections: 'sections' of AllTypes is a structural parameter" in err
    assert "--param gain: value of 'gain' must be a number" in err
    assert "within [-128, 127]" in err and not out.exists()
