"""The flanks' lead mismatch fitted to a load pair (calibration.face_contact_from)."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.face_contact import choose, fit_face_contact, ratio_distance, smoothed_db

CH = "accel_pinion_casing"
FS = 25600.0
GRID = (0.0, 5e-6, 15e-6, 30e-6)


def test_the_smallest_lead_mismatch_within_the_tolerance_is_taken():
    grid = (0.0, 5e-6, 10e-6, 20e-6)
    assert choose([6.0, 5.0, 3.9, 3.8], grid) == 10e-6          # 3.9 is within 0.25 dB of 3.8
    assert choose([6.0, 5.0, 4.2, 3.8], grid) == 20e-6
    assert choose([4.0, 4.1, 4.2, 3.9], grid) == 0.0            # a flat ratio keeps the aligned pair


def test_the_ratio_distance_is_gain_free_and_smoothing_removes_the_lines():
    rng = np.random.default_rng(0)
    a = rng.normal(size=4000)
    assert ratio_distance(a, a + 7.0) == pytest.approx(0.0, abs=1e-12)
    assert ratio_distance(a, -a) > 1.0
    # white noise with a strong line every 380 Hz: the smoothed PSD is flat within 1 dB over 1-8 kHz
    t = np.arange(int(2 * FS)) / FS
    x = rng.normal(size=t.size) + sum(3.0 * np.sin(2 * np.pi * 380.0 * h * t) for h in range(3, 20))
    f, db = smoothed_db(x, FS)
    band = (f > 1500) & (f < 7000)
    assert np.ptp(db[band]) < 1.5


def test_a_mode_that_moves_down_with_load_shows_as_a_rise_then_a_fall():
    """Noise through one resonance at 4 kHz (the heavier load) and at 2.6 kHz (the lighter): the
    ratio rises near 4 kHz and falls near 2.6 kHz, each within 10 %; the order of the records is
    the heavier first."""
    from scipy.signal import lfilter

    from twin.calibration.face_contact import load_lobes

    rng = np.random.default_rng(1)

    def through(f0, n=int(2 * FS)):
        r, w = np.exp(-2 * np.pi * 0.03 * f0 / FS), 2 * np.pi * f0 / FS
        return lfilter([1.0], [1.0, -2 * r * np.cos(w), r * r], rng.normal(size=n)) + 0.05 * rng.normal(size=n)

    lobes = load_lobes(through(4000.0), through(2600.0), FS)
    assert abs(lobes.rise_hz / 4000.0 - 1) < 0.1 and abs(lobes.fall_hz / 2600.0 - 1) < 0.1, lobes
    assert lobes.rise_db > 10 and lobes.fall_db < -10
    assert "dB at" in lobes.describe()


def _pair(fmu, lead_mismatch, seed=0):
    from twin.operating import simulate_operating_point
    rng = np.random.default_rng(seed)
    out = []
    for load in (20.0, 5.0):
        y = simulate_operating_point(fmu, 20.0, load, parameters={"lead_mismatch": lead_mismatch}, settle=0.3,
                                     duration=1.0, channels=[CH], output_interval=1.0 / FS)[:, 0]
        out.append((3.0 * y + rng.normal(0.0, 1e-3 * y.std(), y.size), load))     # a gain the fit must not see
    return out


@pytest.mark.parametrize("made_with", [15e-6, 0.0])
def test_the_fit_finds_the_lead_mismatch_the_records_were_made_with(measured_fmu, made_with):
    fit = fit_face_contact(measured_fmu, {}, _pair(measured_fmu, made_with), CH, FS, 20.0, duration=1.0, grid=GRID)
    assert fit.lead_mismatch == pytest.approx(made_with, abs=1e-12), fit.describe()
    # the model's lobes are those of its own run at the fitted value: the records' own, up to the noise
    assert fit.lobes_model.rise_hz == pytest.approx(fit.lobes_measured.rise_hz, rel=0.05), fit.describe()
    assert "the records' ratio" in fit.describe()
    d = dict(zip(fit.grid, fit.distances_db))
    if made_with:
        # an aligned pair's mesh mode does not move with load: its ratio is far from the records'
        assert d[0.0] > d[made_with] + 1.0, fit.describe()
        assert not fit.on_bound() and fit.parameters == {"lead_mismatch": made_with}


def test_the_lobes_read_the_heavier_load_first_whichever_record_is_the_steady_one(measured_fmu):
    from twin.calibration.face_contact import load_lobes

    (heavy, lh), (light, ll) = _pair(measured_fmu, 15e-6)
    fit = fit_face_contact(measured_fmu, {}, [(light, ll), (heavy, lh)], CH, FS, 20.0, duration=1.0, grid=(0.0,))
    assert fit.lobes_measured == load_lobes(heavy, light, FS)
    assert fit.lobes_measured.rise_hz > fit.lobes_measured.fall_hz      # the twin's mesh mode moves down


def test_a_load_pair_that_is_not_one_speed_and_two_loads_is_refused_by_name():
    from twin.calibration.run import _face_contact_record
    from twin.errors import ScenarioError
    from twin.measurements import MeasurementSet, Record
    from twin.scenario import scenario_from_dict

    x = np.zeros(int(FS))
    rec = lambda name, speed, load: Record(name, {CH: x}, {CH: "m/s2"}, FS, nominal_speed=speed, load=load)
    steady = rec("steady", 20.0, 20.0)
    mset = MeasurementSet((steady, rec("light", 20.0, 5.0), rec("fast", 25.0, 5.0), rec("same", 20.0, 18.0)))
    sc = scenario_from_dict({"version": 1, "name": "m", "fmu": "x.fmu", "stop_time": 0.1,
                             "output": {"sample_rate": FS, "variables": [CH]}})
    assert _face_contact_record(sc, mset, {"face_contact_from": "light"}, steady, CH, "s.yaml", "m.h5").name == "light"
    for name, msg in (("dark", "no record 'dark' in the measurements"),
                      ("fast", "runs at 25 Hz, the steady record 'steady' at 20 Hz"),
                      ("same", "is at 18 N.m, the steady record 'steady' at 20 N.m: the loads must differ")):
        with pytest.raises(ScenarioError, match=msg):
            _face_contact_record(sc, mset, {"face_contact_from": name}, steady, CH, "s.yaml", "m.h5")


def test_a_load_pair_without_a_measurement_file_is_refused_before_anything_is_written(tmp_path):
    from twin.calibration.run import run_calibration
    from twin.errors import ScenarioError
    from twin.scenario import scenario_from_dict

    sc = scenario_from_dict({"version": 1, "name": "m", "fmu": "x.fmu", "stop_time": 0.1,
                             "output": {"sample_rate": FS, "variables": [CH]},
                             "calibration": {"parameters": "auto", "natural_frequencies": [430.0, 512.0],
                                             "face_contact_from": "light"}})
    with pytest.raises(ScenarioError, match="calibration.face_contact_from.*needs the measurement file"):
        run_calibration(sc, None, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("signal, fs, message, record", [
    (np.full(int(FS), np.nan), FS, "1-D finite signal", "the load pair's record at 5 N.m"),
    (np.zeros(2000), FS, "lasts 0.0781 s", "the load pair's record at 5 N.m"),
    (np.zeros(4000), 2000.0, "sampled at 2000.0 Hz", "the load pair"),
])
def test_a_record_the_spectra_cannot_be_read_from_is_refused_by_name(gearbox_fmu, signal, fs, message, record):
    from twin.errors import MeasurementError
    good = np.random.default_rng(0).normal(size=int(fs))
    with pytest.raises(MeasurementError, match=message) as err:
        fit_face_contact(gearbox_fmu, {}, [(good, 20.0), (signal, 5.0)], CH, fs, 20.0, grid=GRID)
    assert err.value.record == record
