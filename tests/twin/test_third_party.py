"""The orchestrator on an FMU that fmu_build/ did not produce.

``tests/thirdparty/vanderpol`` is a hand-written FMI 2.0 Co-Simulation FMU (Van der Pol
oscillator, plain C, classic RK4 with substeps of at most 1 ms inside each doStep).  It has no
``solver.output_interval`` buffer and no ``solver.*`` parameters, so the run exercises the
generic path of :mod:`twin.fmu`: one ``fmi2DoStep`` + ``fmi2GetReal`` per output sample.
"""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from twin.errors import FMUCompatibilityError
from twin.fmu import OUTPUT_INTERVAL
from twin.orchestrator import run_scenario
from twin.scenario import Event, load_scenario

pytestmark = pytest.mark.needs_gcc

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "scenarios" / "third_party.yaml"

# The FMU integrates with RK4 at 1 ms substeps (global error O(1e-12) here, measured 1.5e-11
# on x0 against DOP853 at rtol=atol=1e-13).  1e-8 leaves three orders of margin for other
# compilers/libm while still catching a lower-order method (forward Euler at 1 ms is off by
# ~1e-2) or an input/parameter change applied one sample early or late (~1e-3 or more).
TOL = 1e-8


def _reference(times: np.ndarray, t_u: float = 10.0, t_mu: float = 15.0) -> np.ndarray:
    """solve_ivp of the same ODE: u steps 0 -> 0.5 at t_u, mu 1.5 -> 0.5 at t_mu. Shape (2, n)."""
    def rhs(t, x, mu, u):
        return [x[1], mu * (1.0 - x[0] ** 2) * x[1] - x[0] + u]

    segments = [(0.0, t_u, 1.5, 0.0), (t_u, t_mu, 1.5, 0.5), (t_mu, 20.0, 0.5, 0.5)]
    x = np.array([2.0, 0.0])          # start values of x0, x1 in modelDescription.xml
    out = np.empty((2, times.size))
    for a, b, mu, u in segments:
        last = b == segments[-1][1]
        mask = (times >= a - 1e-9) & ((times <= b + 1e-9) if last else (times < b - 1e-9))
        sol = solve_ivp(rhs, (a, b), x, method="DOP853", rtol=1e-13, atol=1e-13,
                        t_eval=np.clip(times[mask], a, b), args=(mu, u), dense_output=True)
        assert sol.success, sol.message
        out[:, mask] = sol.y
        x = sol.sol(b)
    return out


def test_fmu_passes_fmpy_validation(vanderpol_fmu):
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(vanderpol_fmu)) == []


def test_third_party_scenario_matches_solve_ivp(vanderpol_fmu, tmp_path):
    scenario = load_scenario(SCENARIO).with_overrides(fmu=str(vanderpol_fmu))
    assert scenario.parameters == {"mu": 1.5} and scenario.outputs == ("x0", "x1")

    # Count the FMI calls: wrap the slave's doStep from the first between-step hook on.
    calls = {"doStep": 0, "buffered": None}

    def count_steps(ctx):
        if ctx.step == 0:
            calls["buffered"] = ctx.fmu.supports_output_buffer or ctx.fmu._buffer_fn is not None
            slave = ctx.fmu._slave
            original = slave.doStep

            def do_step(*args, **kwargs):
                calls["doStep"] += 1
                return original(*args, **kwargs)
            slave.doStep = do_step

    out = tmp_path / "vdp.h5"
    rec = run_scenario(scenario, out, hooks=[count_steps], progress=False)

    assert rec.complete
    res = rec.result
    assert res.time.shape == (2001,)
    np.testing.assert_allclose(res.time, 0.01 * np.arange(2001), rtol=0, atol=1e-12)
    assert [a for _, a in rec.events_applied] == ["override mu = 0.5"]

    ref = _reference(res.time)
    err0 = np.max(np.abs(res["x0"] - ref[0]))
    err1 = np.max(np.abs(res["x1"] - ref[1]))
    assert err0 < TOL, f"x0 differs from solve_ivp by {err0:.3g}"
    assert err1 < 10 * TOL, f"x1 differs from solve_ivp by {err1:.3g}"
    # The tolerance does discriminate: the input step or the mu change one sample late is far off.
    for late in (_reference(res.time, t_u=10.01), _reference(res.time, t_mu=15.01)):
        assert np.max(np.abs(res["x0"] - late[0])) > 1e3 * TOL

    # No output buffer: the orchestrator took the per-sample path (one doStep per 10 ms sample,
    # ten per 0.1 s communication step), not one doStep per communication step.
    assert calls["buffered"] is False
    assert calls["doStep"] == 2000

    with h5py.File(out) as f:
        assert f.attrs["complete"]
        assert f.attrs["model_name"] == "VanDerPol"
        assert f["signals/x0"].shape == (2001,)
        np.testing.assert_array_equal(f["signals/x0"][:], res["x0"])
        assert list(f["events/time"][:]) == [15.0]


def test_fmu_without_output_buffer_variable(vanderpol_fmu):
    from twin.fmu import FMU
    with FMU(vanderpol_fmu) as fmu:
        assert OUTPUT_INTERVAL not in fmu.variables
        assert not fmu.supports_output_buffer
        assert [v.name for v in fmu.outputs] == ["x0", "x1"]
        assert [v.name for v in fmu.inputs] == ["u"]
        assert [(v.name, v.variability) for v in fmu.parameters] == [("mu", "tunable")]


def test_missing_variables_are_listed(vanderpol_fmu, tmp_path):
    scenario = load_scenario(SCENARIO).with_overrides(
        fmu=str(vanderpol_fmu), outputs=("x0", "x2"),
        events=(Event(15.0, override={"damping": 0.1}),))
    out = tmp_path / "never.h5"
    with pytest.raises(FMUCompatibilityError) as info:
        run_scenario(scenario, out, progress=False)
    mismatches = info.value.mismatches
    assert any("'x2'" in m and "missing" in m for m in mismatches), mismatches
    assert any("'damping'" in m and "missing" in m for m in mismatches), mismatches
    assert len(mismatches) == 2
    assert "'x2'" in str(info.value)
    assert not out.exists()
