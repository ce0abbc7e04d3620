"""twin.fmu on FMUs it did not build: every variable type, FMI 3.0, FMU-ended runs, units, the
default experiment, and what is read-only (the hand-written type-coverage FMUs)."""
from __future__ import annotations

import numpy as np
import pytest

from twin.errors import FMUError, ParameterError, SimulationError, TwinWarning
from twin.fmu import FMU, describe, is_gearbox_model, simulate_fmu

pytestmark = pytest.mark.needs_gcc


@pytest.mark.parametrize("version", [2, 3])
def test_set_and_get_every_type(typecov_fmus, version):
    with FMU(typecov_fmus[("AllTypes", version)]) as fmu:
        assert fmu.fmi_version == version
        fmu.setup(0.0)
        fmu.set({"Real_input": 1.25, "Integer_input": "5", "Boolean_input": "true", "String_input": "xy",
                 "Enumeration_input": "fast", "gain": 4, "step": 1, "invert": False, "mode": 1})
        assert fmu.get("Real_output") == 4 * 1.25 + 0.5
        assert fmu.get("Integer_output") == 5 and isinstance(fmu.get("Integer_output"), int)
        assert fmu.get("Boolean_output") is True
        assert fmu.get("String_output") == "gear:xy"
        assert fmu.get("Enumeration_output") == 3
        assert fmu.get_values(["teeth", "ratio", "resource_length"]) == [19, 1.0, 31]
        if version == 3:
            fmu.set({"Int8_input": -128, "UInt64_input": 2**64 - 1, "Float32_input": 0.5, "Int64_parameter": -1})
            assert fmu.get_values(["Int8_output", "UInt64_output", "Float32_output"]) == [-128 ^ 5, 2**64 - 2, 2.0]
            assert fmu.get("Int64_output") == -9000000000000000000 ^ -1


@pytest.mark.parametrize("version", [2, 3])
def test_read_only_variables_are_refused_with_the_reason(typecov_fmus, version):
    with FMU(typecov_fmus[("AllTypes", version)]) as fmu:
        with pytest.raises(ParameterError, match=r"'teeth' of AllTypes is a constant \(value 19"):
            fmu.setup(0.0, parameters={"teeth": 20})
        with pytest.raises(ParameterError, match="'ratio' of AllTypes is a calculated parameter"):
            fmu.set({"ratio": 2.0})
        if version == 3:
            with pytest.raises(ParameterError, match="'sections' of AllTypes is a structural parameter"):
                fmu.set({"sections": 2})
        with pytest.raises(ParameterError) as info:          # every problem at once
            fmu.set({"Integer_input": 2.5, "mode": "medium", "label": 3})
        assert "3 bad values" in str(info.value) and "'mode'" in str(info.value) and "'label'" in str(info.value)
        fmu.setup(0.0)
        with pytest.raises(ParameterError, match="'offset' is a fixed parameter and cannot change during a run"):
            fmu.set({"offset": 1.0})


def test_binary_outputs_are_left_out_with_a_warning_and_refused_by_name(typecov_fmus):
    path = typecov_fmus[("AllTypes", 3)]
    with pytest.warns(TwinWarning, match=r"not recorded: Binary_output \(Binary\)"):
        result = simulate_fmu(path)
    assert "Binary_output" not in result.channels and "UInt64_output" in result.channels
    with pytest.raises(ParameterError, match="'Binary_output' is a Binary variable; Binary variables are not "
                                             "supported; it cannot be recorded"):
        simulate_fmu(path, outputs=["Real_output", "Binary_output"])
    with pytest.raises(ParameterError, match="independent variable"):
        simulate_fmu(path, outputs=["time"])


@pytest.mark.parametrize("version", [2, 3])
def test_a_run_the_fmu_ends_stops_there_and_keeps_its_samples(typecov_fmus, version):
    with FMU(typecov_fmus[("Staircase", version)]) as fmu:
        fmu.setup(0.0, parameters={"period": 0.5, "last": 4})
        result = fmu.run(10.0, 0.2)
        # ticks at 0.5, 1.0, 1.5: counter 4 at t = 1.5, between the samples 1.4 and 1.6
        assert result.ended_by_fmu and fmu.ended is not None and fmu.ended.time == 1.5
        np.testing.assert_allclose(result.time[-2:], [1.4, 1.5])
        assert list(result["counter"][-3:]) == [3, 3, 4]
        assert "counter reached last = 4" in result.end_reason or version == 3
        with pytest.raises(SimulationError, match="ended the run at t=1.5 s; it cannot step further"):
            fmu.step(0.1)


def test_capture_of_floats_reports_an_fmu_ended_run(typecov_fmus):
    with FMU(typecov_fmus[("Staircase", 2)]) as fmu:
        fmu.setup(0.0)
        block = fmu.capture(5.0, 0.5, ["since_tick"])
        assert block.shape == (10, 1)
        with pytest.raises(SimulationError, match="ended the run itself before t=12"):
            fmu.capture(12.0, 0.5, ["since_tick"])
        with pytest.raises(ParameterError, match="counter is not a float variable"):
            fmu.capture(1.0, 0.5, ["counter"])


def test_parameters_are_recorded_right_after_initialisation(typecov_fmus):
    """A tunable parameter changed during the run is not what the result records: the result holds
    the values the run started with (the change is the caller's, like an event's)."""
    with FMU(typecov_fmus[("AllTypes", 2)]) as fmu:
        fmu.setup(0.0, parameters={"gain": 3.0, "label": "wheel"})

        def retune(f, t):
            if t >= 1.0:
                f.set({"gain": 5.0})
        result = fmu.run(2.0, 0.1, callback=retune, communication_step=0.5)
    assert result.parameters["gain"] == 3.0 and result.parameters["label"] == "wheel"
    assert result["Real_output"][-1] == 5.0 * 1.0 + 0.5


@pytest.mark.parametrize("version", [2, 3])
def test_state_save_restore_of_every_type(typecov_fmus, version):
    with FMU(typecov_fmus[("AllTypes", version)]) as fmu:
        fmu.setup(0.0)
        fmu.set({"String_input": "before", "Integer_input": 1})
        fmu.step(0.5)
        state = fmu.get_state()
        fmu.set({"String_input": "after", "Integer_input": 2})
        fmu.step(1.0)
        fmu.set_state(state)
        assert fmu.time == 0.5 and fmu.get_values(["String_output", "Integer_output"]) == ["gear:before", 1]
        fmu.free_state(state)


def test_units_come_from_declared_types_in_both_versions(typecov_fmus):
    for version in (2, 3):
        with FMU(typecov_fmus[("Ball", version)]) as fmu:
            units = {v.name: v.unit for v in fmu.variables.values()}
            assert units == {"time": "s", "h": "m", "v": "m/s", "g": "m/s2", "e": "", "v_min": "m/s",
                             "bounces": "", "energy": "J/kg", "resting": ""}
            assert fmu.variable("h").display_unit == "cm" and fmu.variable("h").quantity == "Length"
        text = describe(typecov_fmus[("Ball", version)])
        assert "h " in text and " m/s2 " in text and "J/kg" in text


def test_default_experiment_and_description(typecov_fmus):
    with FMU(typecov_fmus[("Staircase", 3)]) as fmu:
        de = fmu.default_experiment
        assert (de.start_time, de.stop_time, de.step_size) == (0.0, 10.0, 0.2)
        assert fmu.experiment() == (0.0, 10.0, 0.2)
        assert fmu.experiment(stop_time=3.0, output_interval=0.5) == (0.0, 3.0, 0.5)
        with pytest.raises(SimulationError, match="must be after start_time"):
            fmu.experiment(start_time=5.0, stop_time=2.0)
    text = describe(typecov_fmus[("AllTypes", 2)])
    assert "Default experiment  startTime 0 s, stopTime 3 s, stepSize 0.1 s" in text
    assert "Inputs, outputs and parameters of every FMI 2.0 type" in text          # the model's own description
    assert "Constants (1, read-only):" in text and "teeth" in text
    assert "{off=1, slow=2, fast=3}" in text and "slow (2)" in text
    assert not is_gearbox_model(typecov_fmus[("AllTypes", 2)])


def test_a_model_exchange_only_fmu_is_refused(tmp_path, typecov_fmus):
    import zipfile
    bad = tmp_path / "me.fmu"
    with zipfile.ZipFile(typecov_fmus[("Ball", 2)]) as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "modelDescription.xml":
                data = (data.decode().replace("<CoSimulation", "<ModelExchange").replace("</CoSimulation>", "</ModelExchange>")
                        .replace('canHandleVariableCommunicationStepSize="true"', "").encode())
            zout.writestr(item, data)
    with pytest.raises(FMUError, match="does not support Co-Simulation"):
        FMU(bad)


def test_values_can_be_read_before_setup(typecov_fmus):
    """Reading instantiates the FMU when needed (the parameters' start values, before initialisation)."""
    with FMU(typecov_fmus[("AllTypes", 3)]) as fmu:
        values = fmu.parameter_values()
        assert values["label"] == "gear" and values["mode"] == 2 and values["sections"] == 4


def test_our_fmi3_build_runs_like_the_fmi2_build(two_mass_fmu, two_mass_fmu3):
    """fmu_build's FMI 3.0 export through twin.fmu: the same samples as the FMI 2.0 build, read
    from its output buffer (one C call per communication step) like the FMI 2.0 one."""
    a = simulate_fmu(two_mass_fmu, stop_time=0.5, output_interval=1e-4, parameters={"k1": 150.0})
    with FMU(two_mass_fmu3) as fmu:
        assert fmu.fmi_version == 3 and fmu.supports_output_buffer
        fmu.setup(0.0, parameters={"k1": "150"})
        assert fmu._buffer_fn is not None
        b = fmu.run(0.5, 1e-4)
    assert a.channels == b.channels and len(a) == len(b) == 5001
    for name in a.channels:
        np.testing.assert_allclose(b[name], a[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(a[name])))
    assert b.parameters["k1"] == 150.0


def test_no_option_grid_follows_fmpy(two_mass_fmu):
    """With no output interval the twin samples where fmpy.simulate_fmu does: the model's stepSize
    (1 ms over 10 s) doubled until the run has at most 1000 intervals; scenarios keep stepSize."""
    import warnings

    import fmpy

    with FMU(two_mass_fmu) as fmu:
        assert fmu.experiment() == (0.0, 10.0, 0.016)
        assert fmu.experiment(fmpy_grid=False) == (0.0, 10.0, 1e-3)
        assert fmu.experiment(stop_time=0.5) == (0.0, 0.5, 1e-3)        # the user's run: the model's step
        assert fmu.experiment(stop_time=30.0) == (0.0, 30.0, 1e-3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = simulate_fmu(two_mass_fmu)
    assert any(isinstance(w.message, TwinWarning) and "--output-interval 0.001" in str(w.message) for w in caught)
    reference = fmpy.simulate_fmu(str(two_mass_fmu))
    assert np.array_equal(result.time, reference["time"])
