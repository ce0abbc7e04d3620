"""The gears' as-manufactured profile fitted to the mesh harmonics (calibration.mesh_form)."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.mesh_form import BOUND, fit_mesh_form, profile

CH = "accel_pinion_casing"
FS = 25600.0


def test_the_profile_shapes_are_material_missing_along_the_path():
    assert np.array_equal(profile(0.0, 0.0, 11), np.zeros(11))
    slope = profile(4e-6, 0.0, 11)
    assert slope.min() == 0.0 and slope[-1] == pytest.approx(4e-6) and np.allclose(np.diff(slope), 4e-7)
    assert np.allclose(profile(-4e-6, 0.0, 11), slope[::-1])          # a negative slope: towards the root
    crowned, hollow = profile(0.0, 3e-6, 11), profile(0.0, -3e-6, 11)
    assert crowned[0] == crowned[-1] == pytest.approx(3e-6) and crowned[5] == 0.0     # both ends relieved
    assert hollow[5] == pytest.approx(3e-6) and hollow[0] == hollow[-1] == 0.0        # the middle hollow


def _simulate(fmu, slope, crowning, seconds=0.5, seed=0):
    from twin.operating import simulate_operating_point
    values = {"pinion_roughness.rms": 0.0, "gear_roughness.rms": 0.0, "process.rms": 0.0,
              **{f"profile_deviation[{i}]": float(v) for i, v in enumerate(profile(slope, crowning, 11), 1)}}
    y = simulate_operating_point(fmu, 20.0, 20.0, parameters=values, settle=0.1, duration=seconds, channels=[CH],
                                 output_interval=1.0 / FS)[:, 0]
    return y + np.random.default_rng(seed).normal(0.0, 1e-3 * y.std(), y.size)


def test_the_fit_finds_a_profile_that_gives_the_measured_mesh_lines(measured_fmu):
    measured = _simulate(measured_fmu, 8e-6, -6e-6)
    fit = fit_mesh_form(measured_fmu, {}, measured, FS, speed_hz=20.0, load_nm=20.0, channel=CH, fmax=5000.0)
    # perfect involutes give those lines only at a gain of 30 or more; the fitted profile at the sensor's own
    assert fit.lines_db_before > 20.0 and fit.gain_before > 20.0, fit.describe()
    assert fit.lines_db_after < 0.5 and fit.gain_after == pytest.approx(1.0, abs=0.1)
    assert fit.harmonics[:2] == (1, 2) and 81 <= fit.simulations <= 81 + 24
    # the smallest of the profiles that match is the one the record was made with
    assert fit.slope == pytest.approx(8e-6, abs=0.5e-6) and fit.crowning == pytest.approx(-6e-6, abs=0.5e-6)
    assert not fit.on_bound()
    nodes = np.array([fit.parameters[f"profile_deviation[{i}]"] for i in range(1, 12)])
    assert np.allclose(nodes, profile(fit.slope, fit.crowning, 11)) and nodes.max() <= 2 * BOUND


def test_a_record_without_mesh_lines_or_a_model_without_a_profile_is_refused(measured_fmu, gearbox_fmu, tmp_path):
    from twin.calibration.run import _mesh_form
    from twin.errors import MeasurementError, ScenarioError
    from twin.measurements import Record
    from twin.scenario import scenario_from_dict

    # sampled at 600 Hz: the first mesh harmonic (380 Hz) is above what the record holds
    slow = np.random.default_rng(1).normal(size=600)
    rec = Record("steady", {CH: slow}, {CH: "m/s2"}, 600.0, nominal_speed=20.0, load=20.0)

    class Target:
        drive_hz, load = 20.0, 20.0

    sc = scenario_from_dict({"version": 1, "name": "m", "fmu": str(measured_fmu), "stop_time": 0.1})
    with pytest.raises(MeasurementError, match="outside the spectrum|no gear-mesh harmonic stands out") as err:
        _mesh_form(sc, measured_fmu, {}, rec, CH, Target, 0.05, 0.45 * 600.0, "rig.h5")
    assert err.value.record == "steady" and "mesh_form" in str(err.value)
    with pytest.raises(ScenarioError, match="mesh_form: fit needs a model that reads its casing sensors"):
        _mesh_form(sc, gearbox_fmu, {}, rec, CH, Target, 0.05, 5000.0)


def test_a_wear_run_starts_its_pinion_flank_from_the_scenario_s_profile():
    from twin.degradation import GearPair, mesh_parameters
    from twin.degradation.base import WearState
    from twin.degradation_run import manufactured_form

    g = GearPair.from_parameters({})
    state = WearState.pristine(g, 201)
    assert manufactured_form(state, {}, 11) is state
    nodes = profile(3e-6, -2e-6, 11)
    formed = manufactured_form(state, {f"profile_deviation[{i}]": v for i, v in enumerate(nodes, 1)}, 11)
    assert np.all(formed.depth == 0) and formed.pinion_form.max() == pytest.approx(nodes.max())
    back = mesh_parameters(g, wear=formed, n_nodes=11).parameters
    # the rigid flanks' separation is the profile again, up to backlash and the mating curvature's bridging
    got = np.array([back[f"profile_deviation[{i}]"] for i in range(1, 12)])
    assert np.abs((got - got.min()) - nodes).max() < 0.1 * nodes.max()
