"""Broadband excitation and transfer path (GearTwin.Excitation, GearTwin.Sensors, Gearbox21Measured):
the blocks against their formulas, the switch that folds them away, and the level fit."""
from __future__ import annotations

import re
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from twin.calibration.levels import band_levels, fit_levels, has_levels
from twin.fmu import simulate_fmu
from twin.operating import simulate_operating_point

REPO = Path(__file__).resolve().parents[2]

CHECK = """package ExcitationCheck
  model Blocks
    Real a(start = 0.2);
    GearTwin.Excitation.RoughnessTransmissionError r(angle = a, speed = 7.3, seed = 4, rms = 1e-6, slope = 0.8, rolling_radius = 0.01, contact_half_width = 3e-5);
    GearTwin.Excitation.ProcessForce p(seed = 5, rms = 2, f_high = 8000);
    output Real te = r.displacement;
    output Real rate = r.displacement_rate;
    output Real force = p.force;
  equation
    der(a) = 7.3;
  end Blocks;
  model Folded
    extends GearTwin.Gearbox21Measured(broadband = false);
  end Folded;
end ExcitationCheck;
"""


@pytest.fixture(scope="module")
def check_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("modelica")
    shutil.copytree(REPO / "modelica" / "GearTwin", root / "GearTwin")
    (root / "ExcitationCheck.mo").write_text(CHECK)
    return root


def _roughness_reference(angle, rms, slope, seed, rho=0.01, b=0.0):
    """The block's sum written order by order (not as its product): order n = 63 j + m, |m| <= 31."""
    j, k, l = np.arange(1, 33), np.arange(1, 5), np.arange(1, 4)
    gauss = lambda n: np.exp(-(n * b / rho) ** 2 / 8)
    p0 = 32.0 ** (-slope) * gauss(16.0)
    p = (63.0 * j) ** (-slope) * gauss(63.0 * j)
    phi = 43758.5453 * np.sin(12.9898 * j + 78.233 * seed)
    psi = 43758.5453 * np.sin(39.3468 * k + 11.135 * seed)
    chi = 43758.5453 * np.sin(93.9898 * l + 67.345 * seed)
    norm = np.sqrt((31 * p0 ** 2 + 63 * np.sum(p ** 2)) / 32)
    P = p0 / 2 + np.sum(p[None, :] * np.cos(63 * j[None, :] * angle[:, None] + phi[None, :]), axis=1)
    Q = 0.5 + np.sum(np.cos(7 * k[None, :] * angle[:, None] + psi[None, :]), axis=1)
    R = 0.5 + np.sum(np.cos(l[None, :] * angle[:, None] + chi[None, :]), axis=1)
    return rms / norm * (P * Q * R - p0 / 8)


def test_blocks_follow_their_formulas(check_dir, tmp_path):
    from fmu_build import build_fmu
    fmu = build_fmu("ExcitationCheck.Blocks", check_dir, tmp_path)
    res = simulate_fmu(fmu, stop_time=2.0, output_interval=1 / 20000)
    angle = 0.2 + 7.3 * res.time
    np.testing.assert_allclose(res["te"], _roughness_reference(angle, 1e-6, 0.8, 4.0, 0.01, 3e-5), atol=1e-12)
    h = 1e-6                                           # rad: a central difference of the reference
    rate = 7.3 * (_roughness_reference(angle + h, 1e-6, 0.8, 4.0, 0.01, 3e-5)
                  - _roughness_reference(angle - h, 1e-6, 0.8, 4.0, 0.01, 3e-5)) / (2 * h)
    assert np.sqrt(np.mean((rate - res["rate"]) ** 2)) < 1e-4 * np.sqrt(np.mean(res["rate"] ** 2))
    force = res["force"]
    assert np.sqrt(np.mean(force ** 2)) == pytest.approx(2.0, rel=0.25)
    fc, level = band_levels(force, 20000, 100, 7000, resolution=2.0)
    db = 10 * np.log10(level)
    assert db.max() - db.min() < 6.0                     # flat from 100 Hz to 7 kHz, in 1/12 octaves


def test_roughness_rms_and_orders(check_dir, tmp_path):
    angle = np.linspace(0, 2 * np.pi, 8192, endpoint=False)
    rho, b = 0.01, 3e-5
    te = _roughness_reference(angle, 1e-6, 0.8, 4.0, rho, b)
    assert np.mean(te) == pytest.approx(0.0, abs=1e-12)                  # no static offset
    assert np.sqrt(np.mean(te ** 2)) == pytest.approx(1e-6, rel=0.35)    # a random sum: RMS as designed in mean
    amp = 2 * np.abs(np.fft.rfft(te)) / te.size
    # every order 1..2047 is there once, nothing above; the amplitudes fall as n^-0.8 times the
    # contact's Gaussian: compare block means (orders of one block share one amplitude)
    assert amp[1:2048].min() > 0 and amp[2048:].max() < 1e-15
    for j in (1, 5, 12, 20):
        block = amp[63 * j - 31:63 * j + 32]
        assert np.allclose(block, block[0], rtol=1e-9)
        expected = (63.0 * j) ** -0.8 * np.exp(-(63 * j * b / rho) ** 2 / 8) / 4
        assert block[0] / amp[33] == pytest.approx(expected / ((63.0) ** -0.8 * np.exp(-(63 * b / rho) ** 2 / 8) / 4))
    # the Hertzian width ends the band: at 3e-5 m on a 0.01 m rolling radius the orders near
    # n = rho / b * sqrt(8 ln 10) = 1430 are a tenth of what the power law alone would give
    assert amp[1449] / amp[63] == pytest.approx((1449 / 63) ** -0.8 * np.exp(-(1449 * b / rho) ** 2 / 8)
                                              / np.exp(-(63 * b / rho) ** 2 / 8), rel=1e-6)
    wide = _roughness_reference(angle, 1e-6, 0.8, 4.0, rho, 0.0)
    amp_wide = 2 * np.abs(np.fft.rfft(wide)) / wide.size
    assert amp[1449] / amp[63] < 0.12 * amp_wide[1449] / amp_wide[63]


def test_switch_off_folds_the_excitation_away(check_dir, tmp_path, gearbox_fmu, measured_fmu):
    from fmu_build import build_fmu
    folded = build_fmu("ExcitationCheck.Folded", check_dir, tmp_path)

    def rhs_trig_calls(fmu):
        """sin/cos calls in the generated right-hand side (the function every solver stage runs)."""
        with zipfile.ZipFile(fmu) as z:
            code = z.read("sources/model_functions.c").decode()
        name = re.search(r"_rhs\(const casadi_real\*\* arg.*?\{\s*return (casadi_f\d+)\(", code, re.S).group(1)
        body = code.split(f"static int {name}(", 1)[1].split("\n}\n", 1)[0]
        return body.count("sin(") + body.count("cos(")

    # switched on, the broadband blocks put tens of sines in every evaluation; switched off none
    # is left beyond the base model's own (the phases, computed once per parameter change, stay)
    assert rhs_trig_calls(folded) == rhs_trig_calls(gearbox_fmu)
    assert rhs_trig_calls(measured_fmu) >= rhs_trig_calls(gearbox_fmu) + 10


def test_broadband_lifts_the_floor_and_the_sensor_reads_with_its_gain(measured_fmu, gearbox_fmu):
    kw = dict(settle=0.1, duration=0.5, channels=["accel_pinion_casing"], output_interval=2e-5)
    base = simulate_operating_point(gearbox_fmu, 20.0, 20.0, **kw)[:, 0]
    meas = simulate_operating_point(measured_fmu, 20.0, 20.0, **kw)[:, 0]
    double = simulate_operating_point(measured_fmu, 20.0, 20.0, parameters={"sensor_pinion.gain": 2.0}, **kw)[:, 0]
    np.testing.assert_allclose(double, 2 * meas, rtol=1e-9, atol=1e-9)
    # mesh lines alone leave the model's floor 60-100 dB down; the broadband content fills it
    from twin.signals import welch_psd
    f, pb = welch_psd(base, 5e4, resolution=4.0)
    _, pm = welch_psd(meas, 5e4, resolution=4.0)
    band = (f > 100) & (f < 5000)
    assert np.median(10 * np.log10(pm[band] / pb[band])) > 30
    assert has_levels(measured_fmu, "accel_pinion_casing") and not has_levels(gearbox_fmu, "accel_pinion_casing")


def test_level_fit_recovers_gain_and_roughness(measured_fmu):
    truth = {"sensor_pinion.gain": 0.6, "pinion_roughness.rms": 1.5e-7, "gear_roughness.rms": 1.5e-7,
             "process.rms": 1.0}
    x = simulate_operating_point(measured_fmu, 20.0, 20.0, parameters=truth, settle=0.1, duration=1.0,
                                 channels=["accel_pinion_casing"], output_interval=4e-5)[:, 0]
    x = x + 0.01 * np.std(x) * np.random.default_rng(0).standard_normal(x.size)
    fit = fit_levels(measured_fmu, {}, x, 25000.0, speed_hz=20.0, load_nm=20.0, channel="accel_pinion_casing",
                     fmin=20.0, fmax=5000.0)
    assert fit.gain == pytest.approx(0.6, rel=0.25)      # the roughness in the mesh lines biases it
    assert fit.parameters["pinion_roughness.rms"] == pytest.approx(1.5e-7, rel=0.4)
    assert fit.distance_db < 1.5
    assert not fit.gain_on_bound and fit.warning() is None


def test_level_fit_holds_the_gain_to_the_sensor_range_and_the_noise_below_the_quietest_band(measured_fmu):
    # a record 30 times louder than a sensor gain of 0.6 gives: the mesh lines ask for 18, the
    # sensor declares at most 10, so the roughness carries the rest of the broadband level
    truth = {"sensor_pinion.gain": 0.6, "pinion_roughness.rms": 1.5e-7, "gear_roughness.rms": 1.5e-7,
             "process.rms": 1.0}
    x = 30 * simulate_operating_point(measured_fmu, 20.0, 20.0, parameters=truth, settle=0.1, duration=1.0,
                                      channels=["accel_pinion_casing"], output_interval=4e-5)[:, 0]
    # white noise at a tenth of the record's RMS: left free, the noise would take the broadband
    x = x + 0.1 * np.std(x) * np.random.default_rng(1).standard_normal(x.size)
    fit = fit_levels(measured_fmu, {}, x, 25000.0, speed_hz=20.0, load_nm=20.0, channel="accel_pinion_casing",
                     fmin=20.0, fmax=5000.0)
    assert fit.gain == 10.0 and fit.parameters["sensor_pinion.gain"] == 10.0
    assert fit.gain_wanted == pytest.approx(18.0, rel=0.25) and fit.gain_on_bound
    assert "sensor gain held at 10" in fit.warning()
    assert fit.parameters["pinion_roughness.rms"] == pytest.approx(1.8 * 1.5e-7, rel=0.4)
    assert fit.noise_psd <= 10 ** (np.min(fit.measured_db) / 10) * (1 + 1e-9)


def test_modes_no_gearbox_mode_reaches_go_to_the_casing_path(measured_fmu, gearbox_fmu):
    from twin.calibration.sensor_path import casing_path
    freqs = np.array([640.0, 1700.0, 3300.0, 4100.0, 4500.0])
    damping = np.array([0.02, 0.015, np.nan, 0.5, 0.03])
    confidence = np.array([0.9, 0.8, 0.7, 0.6, 0.3])
    path = casing_path(measured_fmu, "accel_pinion_casing", (1700.0, 3300.0, 4100.0, 4500.0), freqs, damping,
                       confidence)
    assert [path[f"sensor_pinion.panel_frequency[{i}]"] for i in (1, 2, 3)] == [1700.0, 3300.0, 4100.0]
    assert path["sensor_pinion.panel_damping[2]"] == 0.02            # unknown damping: a typical 2 %
    assert path["sensor_pinion.panel_damping[3]"] == 0.1             # clipped to what a panel has
    assert all(path[f"sensor_pinion.panel_participation[{i}]"] == 1.0 for i in (1, 2, 3))
    assert casing_path(gearbox_fmu, "accel_pinion_casing", (1700.0,), freqs, damping, confidence) == {}
    assert casing_path(measured_fmu, "accel_pinion_casing", (), freqs, damping, confidence) == {}
    # a mode below the panels' declared range (50 Hz) never becomes a panel the FMU would refuse
    low = casing_path(measured_fmu, "accel_pinion_casing", (13.2, 1700.0), np.array([13.2, 1700.0]),
                      np.array([0.02, 0.02]), np.array([0.9, 0.5]))
    assert low["sensor_pinion.panel_frequency[1]"] == 1700.0 and "sensor_pinion.panel_frequency[2]" not in low


def test_a_gear_steel_without_stiffness_is_refused_by_name(measured_fmu):
    # a zero modulus would make the Hertzian width, and so the roughness, non-finite: the FMU's
    # declared range (polymer gears and up) refuses it before the run, naming the parameter
    from twin.errors import SimulationError
    with pytest.raises(SimulationError, match=r"gear_youngs_modulus = 0 is outside its range"):
        simulate_operating_point(measured_fmu, 20.0, 20.0, parameters={"gear_youngs_modulus": 0.0}, settle=0.0,
                                 duration=0.01, channels=["accel_pinion_casing"], output_interval=1e-4)
