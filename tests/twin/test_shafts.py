"""GearTwin.Gearbox21Shafts: shaft-and-bearing springs from the shafts' geometry, shaft mass on the gears."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.model_modes import model_modes
from twin.calibration.sensitivity import candidate_parameters
from twin.fmu import FMU

SPRINGS = ("kx45", "ky45", "kx56", "ky56", "kx910", "ky910", "kx1011", "ky1011")


def _values(path, parameters):
    with FMU(path) as fmu:
        fmu.setup(parameters=parameters)
        names = [*SPRINGS, "m5", "m10"]
        return dict(zip(names, fmu.get(names)))


def test_the_springs_are_the_beam_in_series_with_the_bearings(shafts_fmu):
    # a 25 mm steel shaft over 0.15 m: 48 E I / L^3 = 5.7e7 N/m under a mid-span gear; each
    # bearing carries half the load, so the gear sees 1 / (1/k_bend + 1/(4 kb) + 1/(4 kb))
    E, rho = 2.1e11, 7850.0
    p = {"d_shaft_input": 0.024, "span_input": 0.16, "kx_bearing4": 1.0e8, "kx_bearing6": 3.0e8,
         "ky_bearing4": 2.0e8, "ky_bearing6": 2.0e8, "d_shaft_output": 0.03, "span_output": 0.14}
    v = _values(shafts_fmu, p)
    bend_in = 48 * E * math.pi * 0.024 ** 4 / 64 / 0.16 ** 3
    assert v["kx45"] == pytest.approx(1 / (2 / bend_in + 1 / 1.0e8), rel=1e-9)
    assert v["kx56"] == pytest.approx(1 / (2 / bend_in + 1 / 3.0e8), rel=1e-9)
    assert v["ky45"] + v["ky56"] == pytest.approx(1 / (1 / bend_in + 1 / 4.0e8), rel=1e-9)
    bend_out = 48 * E * math.pi * 0.03 ** 4 / 64 / 0.14 ** 3
    assert v["kx910"] + v["kx1011"] == pytest.approx(1 / (1 / bend_out + 1 / 3.0e8), rel=1e-9)
    # off-centre: the beam under a point load at a = 0.3 L, k = 3 E I L / (a^2 b^2), split by the
    # bearings' shares of the load (b/L to bearing 4, a/L to bearing 6)
    off = _values(shafts_fmu, {**p, "pinion_position": 0.3})
    L, a, b = 0.16, 0.3 * 0.16, 0.7 * 0.16
    bend = 3 * E * math.pi * 0.024 ** 4 / 64 * L / (a * a * b * b)
    assert off["kx45"] == pytest.approx(1 / (L / (b * bend) + 1 / 1.0e8), rel=1e-9)
    assert off["kx56"] == pytest.approx(1 / (L / (a * bend) + 1 / 3.0e8), rel=1e-9)
    # the shaft's mass moves with its gear (Rayleigh share 17/35 at mid-span)
    assert v["m5"] == pytest.approx(0.6 + 17 / 35 * rho * math.pi * 0.024 ** 2 / 4 * 0.16, rel=1e-9)
    assert v["m10"] == pytest.approx(3.5 + 17 / 35 * rho * math.pi * 0.03 ** 2 / 4 * 0.14, rel=1e-9)
    # the mode classes weigh the gears with these masses, not with a default
    assert mass_values(shafts_fmu, p)["m5"] == pytest.approx(v["m5"], rel=1e-9)


def test_the_geometry_is_calibratable_within_physical_bounds(shafts_fmu):
    cands = {c.name: c for c in candidate_parameters(shafts_fmu)}
    assert not set(SPRINGS) & set(cands)           # computed, not free
    assert cands["d_shaft_input"].lower == pytest.approx(0.85 * 0.025)
    assert cands["d_shaft_input"].upper == pytest.approx(1.2 * 0.025)
    assert cands["span_output"].lower == pytest.approx(0.8 * 0.15)
    assert cands["ky_bearing11"].reason.startswith("bearing radial stiffness")
    assert {"pinion_mass", "gear_mass", "kx_bearing4"} <= set(cands)
    assert "pinion_position" not in cands          # at mid-span it moves no mode to first order


def _lateral(mm, cls):
    """Frequency of the mode with the largest share of ``cls``."""
    k = max(range(len(mm.classes)), key=lambda i: mm.classes[i].shares.get(cls, 0.0))
    return float(mm.frequency[k]), mm.classes[k].shares.get(cls, 0.0)


def test_nominal_shaft_modes_are_where_a_25_mm_shaft_puts_them(shafts_fmu):
    kw = dict(speed_hz=20.0, load_nm=20.0, channels=("accel_pinion_casing", "accel_gear_casing"))
    mm = model_modes(shafts_fmu, {}, **kw)
    assert np.all(mm.damping > 0)
    # the pinion on its shaft, horizontally (across the mesh force's main direction): a 25 mm
    # shaft with 0.9 kg of pinion and shaft on it, between bearings on pedestals, puts it at
    # 1-1.5 kHz (with the stated stiff shaft-and-bearing springs of Gearbox21Casing: 3.1 kHz)
    f, share = _lateral(mm, "pinion lateral x")
    assert 1000.0 < f < 1500.0 and share > 0.5
    # the gear (3.8 kg) on its shaft: below the pinion's, above the casing's sway on its mounts
    f_gear, _ = _lateral(mm, "gear lateral x")
    assert 300.0 < f_gear < 800.0
    # a thinner shaft lowers the pinion's mode as sqrt(d^4 / ...): about d^2 while the shaft dominates
    thin = model_modes(shafts_fmu, {"d_shaft_input": 0.0225}, **kw)
    f_thin, _ = _lateral(thin, "pinion lateral x")
    assert 0.8 < f_thin / f < 0.95
