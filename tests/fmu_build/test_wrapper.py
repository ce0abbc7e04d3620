"""The generic FMI 2.0 wrapper (fmu_build/templates/fmi2_wrapper.c) at run time, through fmpy.

TwoMassOscillator is used because its exact solution is known (conftest.TwoMassODE).
"""
from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

pytestmark = pytest.mark.needs_gcc

H = 1e-3                                   # communication step [s]
STATES = ["x1", "v1", "x2", "v2"]
OUTPUTS = ["a2", "position2"]              # output value-reference order


def _run(slave, vr, names, t0: float, n: int, h: float = H) -> np.ndarray:
    """doStep n times from t0 and return (n, len(names)) values read after each step."""
    rows = []
    for k in range(n):
        slave.doStep(t0 + k * h, h)
        rows.append(slave.getReal([vr[v] for v in names]))
    return np.array(rows)


# ---- tunable parameters -------------------------------------------------------------------------
def test_parameter_change_between_steps_acts_from_that_step_on(two_mass_fmu, open_slave, two_mass):
    names = STATES + OUTPUTS
    ref, vr = open_slave(two_mass_fmu, step_size=1e-4)
    mod, _ = open_slave(two_mass_fmu, step_size=1e-4)
    before_ref = _run(ref, vr, names, 0.0, 10)
    before_mod = _run(mod, vr, names, 0.0, 10)
    assert np.array_equal(before_mod, before_ref)

    # k1 changes at t = 10 ms; the calculated parameter f1 = sqrt(k1/m1)/(2 pi) follows at once.
    mod.setReal([vr["k1"]], [400.0])
    assert mod.getReal([vr["k1"], vr["f1"]]) == pytest.approx([400.0, math.sqrt(400.0) / (2 * math.pi)],
                                                              rel=1e-15)
    after_ref = _run(ref, vr, names, 10 * H, 20)
    after_mod = _run(mod, vr, names, 10 * H, 20)
    assert np.all(np.abs(after_mod[:, :4] - after_ref[:, :4]).max(axis=1) > 0), "no effect from the first step on"

    # From the state at the switch, the modified run follows the ODE with the new k1 exactly.
    exact = two_mass.solution(H * np.arange(1, 21), [*before_mod[-1, :4], 0.0], k1=400.0)
    rel = np.abs(after_mod[:, :4] - exact[:, :4]).max(axis=0) / np.abs(exact[:, :4]).max(axis=0)
    assert rel.max() < 1e-6


def test_fmu_state_restore_reproduces_the_continuation_bit_for_bit(two_mass_fmu, open_slave):
    names = STATES + OUTPUTS + ["f1"]
    slave, vr = open_slave(two_mass_fmu, step_size=1e-4)
    _run(slave, vr, names, 0.0, 5)
    state = slave.getFMUstate()
    first = _run(slave, vr, names, 5 * H, 10)

    # Diverge (new parameter and input), then go back: the snapshot carries p, u, x and t.
    slave.setFMUstate(state)
    slave.setReal([vr["k1"], vr["force"]], [250.0, 1.0])
    diverged = _run(slave, vr, names, 5 * H, 10)
    assert not np.array_equal(diverged, first)
    slave.setFMUstate(state)
    assert slave.getReal([vr["k1"], vr["force"]]) == [100.0, 0.0]
    assert np.array_equal(_run(slave, vr, names, 5 * H, 10), first)

    # The same through serialisation, into another instance of the same FMU.
    blob = slave.serializeFMUstate(state)
    slave.freeFMUstate(state)
    other, _ = open_slave(two_mass_fmu)
    restored = other.deSerializeFMUstate(blob)
    other.setFMUstate(restored)
    other.freeFMUstate(restored)
    assert np.array_equal(_run(other, vr, names, 5 * H, 10), first)


def test_solver_step_size_must_be_positive(two_mass_fmu, open_slave, capsys):
    slave, vr = open_slave(two_mass_fmu, step_size=1e-4)
    for bad in (0.0, -1e-5):
        with pytest.raises(FMICallException) as info:
            slave.setReal([vr["solver.step_size"]], [bad])
        assert info.value.status == 3       # fmi2Error
    assert "solver.step_size must be > 0" in capsys.readouterr().out
    with pytest.raises(FMICallException):
        slave.setReal([vr["solver.output_interval"]], [-1e-3])
    # the refused values left the solver untouched and the FMU usable
    assert slave.getReal([vr["solver.step_size"], vr["solver.output_interval"]]) == [1e-4, 0.0]
    slave.doStep(0.0, H)


def test_solver_step_size_sets_the_rk4_step(two_mass_fmu, open_slave, two_mass):
    """Halving solver.step_size divides the error by ~16: the FMU runs a 4th-order RK4 at that step."""
    exact = two_mass.solution(0.01 * np.arange(1, 101), [*two_mass.x0, 0.0])[:, :4]
    errors = []
    for step in (2e-3, 1e-3):
        slave, vr = open_slave(two_mass_fmu, step_size=step)
        sim = _run(slave, vr, STATES, 0.0, 100, h=0.01)
        errors.append(np.abs(sim - exact).max() / np.abs(exact).max())
    assert 1e-10 < errors[1] < 1e-7
    assert 12 < errors[0] / errors[1] < 20, errors


# ---- output buffer extension ----------------------------------------------------------------------
def _buffer_api(slave):
    """(width, get) for the twin_fmi2 output-buffer functions of the slave's loaded library."""
    lib = slave.dll                       # fmpy loads the binary as a ctypes CDLL
    lib.twin_fmi2OutputBufferWidth.restype = ctypes.c_size_t
    lib.twin_fmi2OutputBufferWidth.argtypes = []
    lib.twin_fmi2GetOutputBuffer.restype = ctypes.c_size_t
    lib.twin_fmi2GetOutputBuffer.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
    width = lib.twin_fmi2OutputBufferWidth()

    def get(capacity: int) -> tuple[int, np.ndarray]:
        """(samples held, (capacity, width) array; rows past the copied ones stay NaN)."""
        dst = np.full((capacity, width), np.nan)
        n = lib.twin_fmi2GetOutputBuffer(slave.component, dst.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                                         capacity)
        return n, dst
    return width, get


def test_output_buffer_holds_the_samples_inside_each_do_step(two_mass_fmu, open_slave):
    buffered, vr = open_slave(two_mass_fmu, step_size=1e-4, force=0.3)
    width, get = _buffer_api(buffered)
    assert width == len(OUTPUTS)
    assert get(4)[0] == 0                       # nothing before the first doStep

    buffered.setReal([vr["solver.output_interval"]], [1e-3])
    samples = []
    for k in range(2):                          # two doSteps of 10 ms -> 2 x 10 samples
        buffered.doStep(k * 0.01, 0.01)
        n, rows = get(16)
        assert n == 10 and np.isnan(rows[10:]).all()
        samples.append(rows[:10])
        # the last sample of a step is the state at the end of the step
        assert np.array_equal(rows[9], buffered.getReal([vr[v] for v in OUTPUTS]))
    samples = np.vstack(samples)

    stepped, _ = open_slave(two_mass_fmu, step_size=1e-4, force=0.3)
    reference = _run(stepped, vr, OUTPUTS, 0.0, 20)
    # Same RK4 sub-steps; only the sample times' rounding (t0 + k*interval vs t + h) differs.
    scale = np.abs(reference).max(axis=0)
    assert (np.abs(samples - reference) <= 1e-13 * scale).all()

    # A small destination gets the first samples; the return value still says how many exist.
    n, rows = get(4)
    assert n == 10 and np.array_equal(rows, samples[10:14])

    # output_interval = 0 switches buffering off again
    buffered.setReal([vr["solver.output_interval"]], [0.0])
    buffered.doStep(0.02, 0.01)
    assert get(4)[0] == 0


# ---- Model Exchange (used for linearisation) -------------------------------------------------------
def test_model_exchange_derivatives_are_the_linear_ode(two_mass_fmu, unzip_fmu, two_mass):
    from fmpy.fmi2 import FMU2Model

    md, unzipped = unzip_fmu(two_mass_fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    model = FMU2Model(guid=md.guid, unzipDirectory=str(unzipped),
                      modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me")
    model.instantiate()
    try:
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
        model.setReal([vr["force"], vr["k12"]], [0.8, 60.0])
        model.exitInitializationMode()
        model.enterContinuousTimeMode()
        nx = md.numberOfContinuousStates
        assert nx == 4
        x = np.zeros(nx)
        model.getContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
        assert x.tolist() == list(two_mass.x0)

        a = two_mass.matrix(k12=60.0)
        dx = np.zeros(nx)
        for x in np.random.default_rng(0).normal(size=(5, nx)):
            x = np.ascontiguousarray(x)
            model.setContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
            model.getDerivatives(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)
            expected = (a @ [*x, 0.8])[:4]
            assert np.allclose(dx, expected, rtol=1e-14, atol=1e-12)
            # the der(...) variables report the same numbers
            assert model.getReal([vr[f"der({s})"] for s in STATES]) == dx.tolist()
        model.terminate()
    finally:
        model.freeInstance()
