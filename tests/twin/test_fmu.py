"""twin.fmu: names, set/get, stepping, state save/restore, buffered capture and errors."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest

from twin.errors import FMUError, ParameterError, SimulationError
from twin.fmu import FMU, describe, simulate_fmu


def test_variables_by_name(gearbox_fmu):
    with FMU(gearbox_fmu) as fmu:
        names = {v.name for v in fmu.outputs}
        assert {"accel_pinion_casing", "accel_gear_casing", "mesh_force", "transmission_error",
                "encoder_pinion_angle", "encoder_gear_angle"} <= names
        assert {v.name for v in fmu.inputs} == {"motor_speed_ref", "drive_torque", "load_torque"}
        assert fmu.variable("c_mesh").variability == "tunable"
        assert fmu.variable("c_mesh").unit == "N.s/m"
        assert fmu.supports_output_buffer


def test_structural_integers_are_read_with_their_own_type_and_are_read_only(gearbox_fmu):
    """z1 (an Integer) and module (the first Real) share value reference 0: each is read with its
    own type's call, so z1 is 19, not the module; the constants cannot be set, and the message
    gives the command that rebuilds the FMU with another value."""
    with FMU(gearbox_fmu) as fmu:
        fmu.setup(0.0)
        assert fmu.variable("z1").value_reference == fmu.variable("module").value_reference
        assert fmu.get("z1") == 19 and isinstance(fmu.get("z1"), int)
        assert isinstance(fmu.get("module"), float) and fmu.get("module") != 19
        assert fmu.get(["c_mesh", "n_profile", "z1", "z2"])[1:] == [11, 19, 52]
        values = fmu.structural_values()
        assert values["z1"] == 19 and values["n_profile"] == 11 and values["z2"] == 52
        with pytest.raises(ParameterError, match=r"rebuild with `twin build GearTwin.Gearbox21 --set z1=20`"):
            fmu.set({"z1": 20})


def test_buffered_capture_equals_per_sample_calls(two_mass_fmu):
    """The buffer inside the FMU gives exactly what a doStep+getReal per sample gives."""
    fast = simulate_fmu(two_mass_fmu, stop_time=0.05, output_interval=1e-3)
    with FMU(two_mass_fmu) as fmu:
        fmu.setup()
        ref = [fmu.get("a2")]
        for _ in range(50):
            fmu.step(1e-3)
            ref.append(fmu.get("a2"))
    assert fast.time.shape == (51,)
    np.testing.assert_allclose(fast["a2"], ref, rtol=0, atol=1e-12)
    assert fast.sample_rate == pytest.approx(1000.0)
    assert fast.units["a2"] == "m/s2"


def test_run_at_100khz_returns_every_sample(gearbox_fmu):
    r = simulate_fmu(gearbox_fmu, stop_time=0.02, output_interval=1e-5, outputs=["accel_pinion_casing"])
    assert r.time.size == 2001
    np.testing.assert_allclose(np.diff(r.time), 1e-5, rtol=1e-9)
    assert np.all(np.isfinite(r["accel_pinion_casing"]))
    assert r.parameters["c_mesh"] == pytest.approx(1.1e3)
    assert len(r.guid) > 10 and len(r.fmu_sha256) == 64


def test_parameter_change_between_steps_changes_response_from_then_on(two_mass_fmu):
    with FMU(two_mass_fmu) as a, FMU(two_mass_fmu) as b:
        a.setup()
        b.setup()
        first_a = a.run(0.5, 1e-3, outputs=["a2"])
        first_b = b.run(0.5, 1e-3, outputs=["a2"])
        np.testing.assert_array_equal(first_a["a2"], first_b["a2"])
        b.set({"k1": 300.0})
        rest_a = a.run(1.0, 1e-3, outputs=["a2"])
        rest_b = b.run(1.0, 1e-3, outputs=["a2"])
        assert rest_a["a2"][0] == rest_b["a2"][0]  # the sample at the switch time is unchanged
        assert np.max(np.abs(rest_a["a2"][5:] - rest_b["a2"][5:])) > 1e-3


def test_state_save_restore_reproduces_continuation(gearbox_fmu):
    with FMU(gearbox_fmu) as fmu:
        fmu.setup()
        fmu.step(0.01)
        state = fmu.get_state()
        one = fmu.run(0.02, 1e-5, outputs=["mesh_force"])
        fmu.set_state(state)
        two = fmu.run(0.02, 1e-5, outputs=["mesh_force"])
        fmu.free_state(state)
    np.testing.assert_array_equal(one["mesh_force"], two["mesh_force"])


def test_reset_restores_defaults(two_mass_fmu):
    with FMU(two_mass_fmu) as fmu:
        fmu.setup(parameters={"k1": 400.0})
        assert fmu.get("k1") == 400.0
        fmu.reset()
        assert fmu.get("k1") == 100.0


def test_bad_names_and_values_are_refused(two_mass_fmu):
    with FMU(two_mass_fmu) as fmu:
        with pytest.raises(ParameterError, match="no variable 'k_1'"):
            fmu.set({"k_1": 1.0})
        with pytest.raises(ParameterError, match="must be finite"):
            fmu.set({"k1": float("nan")})
        with pytest.raises(ParameterError, match="cannot be set"):
            fmu.set({"a2": 1.0})
        with pytest.raises(ParameterError, match="must be a number"):
            fmu.set({"k1": "stiff"})


def test_fmu_failure_becomes_simulation_error_with_time_and_status(gearbox_fmu):
    with FMU(gearbox_fmu) as fmu:
        fmu.setup()
        fmu.step(1e-3)
        with pytest.raises(SimulationError) as info:
            fmu.set({"solver.step_size": -1.0})
        assert info.value.status == "fmi2Error"
        assert info.value.time == pytest.approx(1e-3)
        assert "step_size must be > 0" in str(info.value)


def test_diverging_simulation_is_reported(two_mass_fmu):
    """RK4 steps far beyond its stability limit (omega*h ~ 12) diverge; the wrapper reports the
    non-finite state. A negative mass, the other way to an unstable ODE, is refused by its min."""
    with FMU(two_mass_fmu) as fmu:
        fmu.setup(parameters={"solver.step_size": 1.0})
        with pytest.raises(SimulationError, match="non-finite") as info:
            fmu.run(2000.0, 1.0)
        assert info.value.status == "fmi2Error"
        assert info.value.time is not None
    with FMU(two_mass_fmu) as fmu:
        with pytest.raises(SimulationError, match=r"parameter m1 = -1e-06 is outside its range \[0, inf\]"):
            fmu.setup(parameters={"m1": -1e-6})


def test_not_an_fmu(tmp_path):
    bad = tmp_path / "x.fmu"
    bad.write_text("hello")
    with pytest.raises(FMUError, match="not an FMU"):
        FMU(bad)
    with pytest.raises(FMUError, match="does not exist"):
        FMU(tmp_path / "missing.fmu")
    broken = tmp_path / "broken.fmu"
    with zipfile.ZipFile(broken, "w") as z:
        z.writestr("modelDescription.xml", "<fmiModelDescription")
    with pytest.raises(FMUError, match="modelDescription"):
        FMU(broken)


def test_describe_lists_variables(gearbox_fmu):
    text = describe(gearbox_fmu)
    assert "GearTwin.Gearbox21" in text and "accel_pinion_casing" in text and "N.s/m" in text


def test_fmu_messages_reach_their_instance_and_fmpy_after_an_instance_closed(gearbox_fmu, capsys):
    """fmpy keeps one logger proxy per process; closing an instance must not leave it dangling."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from twin.errors import TwinError
    with FMU(gearbox_fmu) as first:
        first.setup(0.0)
    with FMU(gearbox_fmu) as second:
        second.setup(0.0)
        with pytest.raises(TwinError, match="solver.step_size must be > 0"):
            second.set({"solver.step_size": -1.0})
    md = read_model_description(str(gearbox_fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(gearbox_fmu)),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="plain")
    slave.instantiate()
    vr = next(v.valueReference for v in md.modelVariables if v.name == "solver.step_size")
    with pytest.raises(Exception):
        slave.setReal([vr], [-1.0])
    slave.freeInstance()
    assert "solver.step_size must be > 0" in capsys.readouterr().out
