"""The measured transfer path: its fit to hammer records and its realisation in the FMU."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy import signal as sps

from twin.calibration.transfer_path import (FORCES, PathFit, fit_paths, hammer_accelerance, path_parameters,
                                            without_path)


def _sections_response(f, freq, zeta, c1, c0, d):
    s = 2j * np.pi * f
    w = 2 * np.pi * np.asarray(freq)
    den = s[None, :] ** 2 + (2 * np.asarray(zeta) * w)[:, None] * s[None, :] + (w ** 2)[:, None]
    return (np.asarray(c1)[:, None] * s[None, :] / den + np.asarray(c0)[:, None] / den).sum(axis=0) + d


def _random_path(seed: int, n: int = 8, responses: int = 2):
    rng = np.random.default_rng(seed)
    freq = np.sort(rng.uniform(150, 4500, n))
    zeta = rng.uniform(0.01, 0.05, n)
    # accelerances of a structure: residues of the mass-normalised modes (s^2 / den), written as
    # (c1 s + c0) / den + d with c1 = -2 zeta w r, c0 = -w^2 r, d = sum r
    r = rng.normal(size=(responses, n)) * 0.05
    w = 2 * np.pi * freq
    return freq, zeta, -2 * zeta * w * r, -(w ** 2) * r, r.sum(axis=1)


def test_the_fit_recovers_a_rational_accelerance_with_common_poles():
    f = np.arange(0.0, 6000.0, 2.0)
    freq, zeta, c1, c0, d = _random_path(1)
    h = np.array([_sections_response(f, freq, zeta, c1[k], c0[k], d[k]) for k in range(2)])
    fit = PathFit(10, fmin=20.0, fmax=5000.0)
    assert fit.fit(f, h) is fit
    band = (f >= 20) & (f <= 5000)
    err = 20 * np.log10(np.abs(fit.predict(f[band])) / np.abs(h[:, band]))
    assert np.max(np.abs(err)) < 0.05
    assert fit.error_db_.shape == (2,) and np.all(fit.error_db_ < 0.05)
    assert fit.residue_rate_.shape == fit.residue_.shape == (10, 2)
    # every true section is among the fitted ones
    assert all(np.min(np.abs(fit.section_frequency_ / fn - 1)) < 1e-3 for fn in freq)
    assert np.all(fit.section_damping_ > 0)


def test_the_fit_refuses_what_it_cannot_do():
    f = np.arange(0.0, 100.0, 10.0)
    with pytest.raises(ValueError, match="cannot fit"):
        PathFit(4, fmin=20.0, fmax=5000.0).fit(f, np.ones((1, f.size)))
    with pytest.raises(ValueError, match="n_sections"):
        PathFit(0).fit(np.arange(0.0, 6000.0, 2.0), np.ones((1, 3000)))


class _Record(SimpleNamespace):
    """A measured record's interface: channels by name, their units, the sample rate."""

    def __getitem__(self, key):
        return self.data[key]

    def __contains__(self, key):
        return key in self.data


def _record(name: str, fs: float, freq, zeta, r, seconds: float = 8.0, seed: int = 0) -> _Record:
    """A hammer record: half-sine blows every 0.25 s through a sum of accelerance modes (bilinear
    transform), with 1 % noise on the response."""
    n = int(seconds * fs)
    force = np.zeros(n)
    pulse = 100.0 * np.sin(np.pi * np.arange(8) / 8)
    for start in range(int(0.02 * fs), n - 8, int(0.25 * fs)):
        force[start:start + 8] += pulse
    y = np.zeros(n)
    for fn, z, rr in zip(freq, zeta, r):
        w = 2 * np.pi * fn
        b, a = sps.bilinear([rr, 0.0, 0.0], [1.0, 2 * z * w, w * w], fs=fs)
        y += sps.lfilter(b, a, force)
    y += 0.01 * np.std(y) * np.random.default_rng(seed).standard_normal(n)
    data = {"hammer": force, "accel_pinion_casing": y}
    return _Record(name=name, sample_rate=fs, channel_names=list(data),
                   units={"hammer": "N", "accel_pinion_casing": "m/s2"}, data=data)


def test_the_accelerance_of_a_hammer_record_is_the_structure_s():
    fs = 20000.0
    freq, zeta, r = [400.0, 1500.0], [0.02, 0.03], [0.02, -0.01]
    acc = hammer_accelerance(_record("hammer_pinion_pedestal", fs, freq, zeta, r), "accel_pinion_casing")
    # the generator's own (discrete) accelerance
    truth = sum(sps.freqz(*sps.bilinear([rr, 0.0, 0.0], [1.0, 2 * z * 2 * np.pi * fn, (2 * np.pi * fn) ** 2], fs=fs),
                          worN=acc.frequency, fs=fs)[1] for fn, z, rr in zip(freq, zeta, r))
    band = (acc.frequency > 100) & (acc.frequency < 3000)
    err = 20 * np.log10(np.abs(acc.value[band]) / np.abs(truth[band]))
    # within 0.5 dB over the band; at the peaks the Hann segments' leakage takes up to 2 dB
    assert np.median(np.abs(err)) < 0.5 and np.max(np.abs(err)) < 2.5
    assert np.median(acc.coherence[band]) > 0.99


def test_paths_fitted_from_records_map_onto_the_fmu_s_forces():
    fs = 20000.0
    mset = {"a": _record("a", fs, [400.0, 1500.0], [0.02, 0.03], [0.02, -0.01]),
            "b": _record("b", fs, [400.0, 1500.0], [0.02, 0.03], [-0.005, 0.02], seed=1)}
    fits = fit_paths(mset, {"a": "bearing_force_input_y", "b": "bearing_force_output_y"},
                     ["accel_pinion_casing", "accel_gear_casing"], n_sections=4, fmax=5000.0)
    assert list(fits) == ["accel_pinion_casing"]          # the gear channel is in neither record
    values = path_parameters(fits, ["bearing_force_input_y", "bearing_force_output_y"])
    k_in, k_out = FORCES.index("bearing_force_input_y"), FORCES.index("bearing_force_output_y")
    fit = fits["accel_pinion_casing"]
    for r in range(4):
        base = r * len(FORCES)
        assert values[f"path_pinion.residue[{base + k_in + 1}]"] == fit.residue_[r, 0]
        assert values[f"path_pinion.residue_rate[{base + k_out + 1}]"] == fit.residue_rate_[r, 1]
        # a horizontal force was not struck: no path
        assert values[f"path_pinion.residue[{base + FORCES.index('bearing_force_input_x') + 1}]"] == 0.0
    assert len(values) == 4 * (2 + 2 * len(FORCES)) + len(FORCES)
    assert without_path({**values, "kt12": 1.0}) == {"kt12": 1.0}


@pytest.fixture(scope="module")
def path_fmu(fmu_dir):
    """GearTwin.Gearbox21Shafts with two path sections per sensor, built as a carried option."""
    from tests.conftest import MODELICA
    from twin.effects.variant import build_like
    return build_like("GearTwin.Gearbox21Shafts", MODELICA, fmu_dir, {"n_path_sections": 2, "z1": 19})


def test_the_fmu_reads_the_bearing_forces_through_the_fitted_sections(path_fmu):
    """The sensor channel of the path build is, to the integration error, the sections' transfer
    function applied to the FMU's own bearing forces (scipy's lsim on the recorded forces)."""
    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    with FMU(path_fmu) as f:
        assert f.structural_values()["n_path_sections"] == 2
    freq, zeta = [700.0, 2300.0], [0.03, 0.02]
    rng = np.random.default_rng(3)
    c1, c0 = rng.normal(size=(2, 4)) * 1e-3, rng.normal(size=(2, 4)) * 20.0
    d = np.array([0.0, 2e-4, 0.0, -1e-4])
    params = {"sensor_pinion.gain": 2.0}
    for r in range(2):
        params[f"path_pinion.section_frequency[{r + 1}]"] = freq[r]
        params[f"path_pinion.section_damping[{r + 1}]"] = zeta[r]
        for k in range(4):
            params[f"path_pinion.residue_rate[{r * 4 + k + 1}]"] = c1[r, k]
            params[f"path_pinion.residue[{r * 4 + k + 1}]"] = c0[r, k]
    params.update({f"path_pinion.feedthrough[{k + 1}]": d[k] for k in range(4)})
    fs = 100000.0
    out = simulate_operating_point(path_fmu, 20.0, 20.0, parameters=params, settle=0.0, duration=0.1,
                                   channels=["accel_pinion_casing", *FORCES], output_interval=1 / fs)
    t = np.arange(out.shape[0]) / fs
    expected = np.zeros_like(t)
    for r in range(2):
        w = 2 * np.pi * freq[r]
        den = [1.0, 2 * zeta[r] * w, w * w]
        for k in range(4):
            expected += sps.lsim(([c1[r, k], c0[r, k]], den), out[:, 1 + k], t)[1]
    expected = 2.0 * (expected + out[:, 1:] @ d)
    late = t > 0.02
    rel = np.sqrt(np.mean((out[late, 0] - expected[late]) ** 2)) / np.sqrt(np.mean(expected[late] ** 2))
    assert rel < 0.02


def test_a_build_without_a_path_keeps_the_modelled_casing_and_its_states(shafts_fmu):
    from twin.fmu import FMU
    with FMU(shafts_fmu) as f:
        assert f.structural_values()["n_path_sections"] == 0
        assert all(name in {v.name for v in f.outputs} for name in FORCES)
        assert not any(n.startswith("path_pinion.x") for n in f.variables)


@pytest.fixture(scope="module")
def path_records(shafts_fmu, tmp_path_factory):
    """A steady record of the shafts model and two hammer records (blows at each housing) of a
    structure with two modes, in one measurement file."""
    from twin.measurements import Record, write_measurements
    from twin.operating import simulate_operating_point

    fs = 12800.0
    y = simulate_operating_point(shafts_fmu, 20.0, 20.0, settle=0.05, duration=0.3,
                                 channels=["accel_pinion_casing"], output_interval=1 / fs)[:, 0]
    records = [Record("steady", {"accel_pinion_casing": y}, {"accel_pinion_casing": "m/s2"}, fs,
                      nominal_speed=20.0, load=20.0)]
    for name, r, seed in (("hammer_a", [0.02, -0.01], 0), ("hammer_b", [-0.005, 0.02], 1)):
        rec = _record(name, fs, [400.0, 1500.0], [0.02, 0.03], r, seconds=4.0, seed=seed)
        records.append(Record(name, dict(rec.data), dict(rec.units), fs, nominal_speed=0.5, load=20.0))
    path = tmp_path_factory.mktemp("path") / "rig.h5"
    write_measurements(records, path)
    return path


def _path_scenario(fmu: str, **block):
    from twin.scenario import scenario_from_dict
    return scenario_from_dict({
        "version": 1, "name": "pathcal", "fmu": fmu, "stop_time": 0.3,
        "output": {"sample_rate": 12800.0, "variables": ["accel_pinion_casing"]},
        "operating": {"speed": 20, "load": 20}, "executor": {"type": "local", "workers": 1},
        "calibration": {"parameters": {"kt57": [9.0e3, 1.5e4]}, "natural_frequencies": [450.0],
                        "objectives": ["modes"], "algorithm": "nsga2", "pop_size": 4, "n_gen": 1, "refine": False,
                        "record": "steady", "record_duration": 0.1, "settle_time": 0.05,
                        "path_from": {"hammer_a": "bearing_force_input_y", "hammer_b": "bearing_force_output_y"},
                        "path_sections": 2, **block}})


@pytest.mark.parametrize("change, message", [
    ({"path_from": {"nope": "bearing_force_input_y"}}, "no record 'nope' in the measurements"),
    ({"path_from": {"steady": "bearing_force_input_y"}}, "'steady' is not a hammer test"),
])
def test_a_bad_path_from_is_refused_naming_the_record(path_records, tmp_path, change, message):
    from twin.calibration.run import run_calibration
    from twin.errors import ScenarioError
    with pytest.raises(ScenarioError, match=message):
        run_calibration(_path_scenario("GearTwin.Gearbox21Shafts", **change), path_records, tmp_path / "out",
                        progress=False)
    assert not (tmp_path / "out" / "calibrated.yaml").exists()


def test_a_path_needs_a_model_built_here_with_bearing_forces(path_records, shafts_fmu, tmp_path):
    from twin.calibration.run import run_calibration
    from twin.errors import ScenarioError
    with pytest.raises(ScenarioError, match="must name a Modelica model"):
        run_calibration(_path_scenario(str(shafts_fmu)), path_records, tmp_path / "a", progress=False)
    with pytest.raises(ScenarioError, match="no bearing force outputs"):
        run_calibration(_path_scenario("GearTwin.Gearbox21Measured"), path_records, tmp_path / "b", progress=False)
    with pytest.raises(ScenarioError, match="needs the measurement file"):
        run_calibration(_path_scenario("GearTwin.Gearbox21Shafts"), None, tmp_path / "c", progress=False)
    assert not (tmp_path / "c").exists()


def test_twin_calibrate_with_path_from_writes_a_scenario_that_reads_the_measured_path(path_records, tmp_path):
    import json

    from twin.calibration.run import run_calibration
    from twin.fmu import FMU
    from twin.operating import simulate_operating_point
    from twin.scenario import load_scenario

    report = run_calibration(_path_scenario("GearTwin.Gearbox21Shafts"), path_records, tmp_path / "out",
                             progress=False)
    assert any(n.startswith("measured transfer path (2 sections) from hammer_a (bearing_force_input_y)")
               for n in report.notes)
    calibrated = load_scenario(tmp_path / "out" / "calibrated.yaml")
    assert dict(calibrated.structural) == {"n_path_sections": 2}
    values = json.loads((tmp_path / "out" / "calibrated.json").read_text())["parameters"]
    fitted = sorted(values[f"path_pinion.section_frequency[{r}]"] for r in (1, 2))
    # the records' modes where their bilinear generator puts them (frequency warping at 12.8 kHz)
    warped = [12800.0 / np.pi * np.arctan(np.pi * f / 12800.0) for f in (400.0, 1500.0)]
    assert fitted == pytest.approx(warped, rel=0.01)
    with FMU(calibrated.fmu_path()) as f:
        assert f.structural_values()["n_path_sections"] == 2
    from twin.calibration.transfer_path import model_without_path
    with FMU(model_without_path(calibrated)) as f:        # what its modes are read on (sensitivity, a new fit)
        assert f.structural_values()["n_path_sections"] == 0
    y = simulate_operating_point(calibrated.fmu_path(), 20.0, 20.0, parameters=dict(calibrated.parameters),
                                 settle=0.05, duration=0.1, channels=["accel_pinion_casing"], output_interval=1e-4)
    assert np.all(np.isfinite(y)) and np.std(y) > 0
    # calibrating the calibrated scenario again needs the path's records
    from twin.errors import ScenarioError
    again = {k: v for k, v in calibrated.raw["calibration"].items() if k not in ("path_from", "path_sections")}
    from dataclasses import replace
    with pytest.raises(ScenarioError, match="reads a measured transfer path"):
        run_calibration(replace(calibrated, raw={**calibrated.raw, "calibration": again}), path_records,
                        tmp_path / "again", progress=False)


def test_path_from_on_the_command_line(capsys, shafts_fmu):
    from twin.calibration.run import _block
    from twin.cli import main
    from twin.commands.common import path_pair

    assert path_pair(" hammer_a = bearing_force_input_y") == ("hammer_a", "bearing_force_input_y")
    assert main(["calibrate", "s.yaml", "--path-from", "hammer_a"]) == 2
    assert "expected RECORD=FORCE" in capsys.readouterr().err
    scenario = _path_scenario(str(shafts_fmu))
    assert _block(scenario, {"path_from": {"h": "bearing_force_output_x"}})["path_from"] == {"h": "bearing_force_output_x"}
    from twin.errors import ScenarioError
    with pytest.raises(ScenarioError, match="bearing_force_sideways"):
        _block(scenario, {"path_from": {"h": "bearing_force_sideways"}})


def test_a_record_without_blows_or_coherence_is_named():
    fs = 20000.0
    silent = _record("silent", fs, [400.0], [0.02], [0.02])
    silent.data["hammer"] = np.zeros_like(silent.data["hammer"])
    with pytest.raises(ValueError, match="record 'silent' gives no accelerance"):
        fit_paths({"silent": silent}, {"silent": "bearing_force_input_y"}, ["accel_pinion_casing"], n_sections=2)
    noisy = _record("noisy", fs, [400.0], [0.02], [0.02])
    noisy.data["accel_pinion_casing"] = np.random.default_rng(0).standard_normal(noisy.data["hammer"].size)
    with pytest.raises(ValueError, match="record 'noisy': the response of accel_pinion_casing is not coherent"):
        fit_paths({"noisy": noisy}, {"noisy": "bearing_force_input_y"}, ["accel_pinion_casing"], n_sections=2)
