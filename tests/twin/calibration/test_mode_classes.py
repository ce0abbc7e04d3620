"""Mode classes from the kinetic-energy shares of a linearised GearTwin model."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.mode_classes import classify, dof_table, side_levels
from twin.calibration.model_modes import model_modes

NAMES = ("theta5", "omega5", "y10", "vy10", "x10", "vx10", "casing.q[1]", "casing.qd[1]",
         "sensor_pinion.panel_deflection[1]", "sensor_pinion.panel_rate[1]")


def test_shares_are_weighted_by_the_masses():
    table = dof_table(NAMES, {"I5": 2.5e-4, "m10": 3.5})
    assert [(NAMES[i], c) for i, c, _ in table] == [("omega5", "torsion"), ("vy10", "gear lateral y"),
                                                    ("vx10", "gear lateral x"), ("casing.qd[1]", "casing"),
                                                    ("sensor_pinion.panel_rate[1]", "sensor path")]
    v = np.zeros((len(NAMES), 4), complex)
    v[1, 0], v[3, 0] = 1.0, 0.01            # the pinion turns at 1 rad/s, the gear moves at 1 cm/s:
    v[3, 1], v[5, 1] = 1.0, 0.5j            # torsion has 2.5e-4 J/2, the gear 3.5e-4 J/2
    v[7, 2], v[3, 2] = 1.0, 0.1
    v[9, 3], v[3, 3] = 1.0, 1e-9            # only the sensor path moves
    c = classify(v, table)
    assert c[0].name == "gear lateral y" and c[0].shares["torsion"] == pytest.approx(2.5 / 6.0)
    assert c[1].name == "gear lateral y" and c[1].shares["gear lateral x"] == pytest.approx(0.2)
    assert c[1].plane == "y" and c[1].lateral == pytest.approx(1.0)
    assert c[2].name == "casing" and c[2].shares["gear lateral y"] == pytest.approx(0.035 / 1.035)
    assert c[3].name == "sensor path" and c[3].plane == ""


def test_the_twins_modes_get_their_physical_class(measured_fmu):
    mm = model_modes(measured_fmu, {}, speed_hz=20.0, load_nm=20.0,
                     channels=("accel_pinion_casing", "accel_gear_casing"))
    by = {round(f): c.name for f, c in zip(mm.frequency, mm.classes)}
    lowest = mm.frequency.argmin()
    assert mm.classes[lowest].name == "torsion"                    # the brake on its coupling
    gear = [f for f, c in zip(mm.frequency, mm.classes) if c.name.startswith("gear lateral")]
    assert gear and min(gear) < 600                                  # the heavy gear on its shaft and supports
    panels = [f for f, c in zip(mm.frequency, mm.classes) if c.name == "sensor path"]
    assert any(abs(f - 1000.0) < 1 for f in panels), by              # a panel of the sensor path (default 1 kHz)
    assert mm.sensor_shapes.shape == (2, mm.frequency.size)
    assert np.all(mm.sensor_shape(int(lowest), ("accel_gear_casing", "nope"))[1:] == 0)
    # where each mode lives: a gear lateral mode on the output shaft, a pinion lateral mode on the input
    named = {"gear lateral": [], "pinion lateral": [], "sensor path": []}
    for c, side in zip(mm.classes, mm.side_db):
        for prefix in named:
            if c.name.startswith(prefix):
                named[prefix].append(side)
    assert named["gear lateral"] and max(named["gear lateral"]) < -6.0, named
    assert named["pinion lateral"] and min(named["pinion lateral"]) > 6.0, named
    assert named["sensor path"] and np.isnan(named["sensor path"]).all()      # the structure still: no side


def test_which_shaft_a_mode_lives_on_from_the_unweighted_amplitudes():
    names = ("vx5", "vy5", "vy4", "vx10", "vy10", "vy_end11", "omega5")
    table = dof_table(names, {"m5": 0.6, "m10": 3.5, "m4": 2.0, "m_end11": 0.4, "I5": 1e-4})
    v = np.zeros((len(names), 4), complex)
    v[0, 0], v[3, 0] = 1.0, 0.1              # input 10 x the output: +20 dB (the gear's mass does not count)
    v[5, 1], v[2, 1] = 2.0, 1.0j             # an overhung end on the output shaft: -6 dB
    v[6, 2] = 1.0                            # torsion only: no lateral motion on either shaft
    v[1, 3], v[4, 3] = 1.0, 1.0
    assert np.allclose(side_levels(v, table)[[0, 1, 3]], [20.0, -20 * np.log10(2), 0.0])
    assert np.isnan(side_levels(v, table)[2])
    # a model with no output-shaft states has no side levels
    assert np.isnan(side_levels(v[:3], dof_table(names[:3], {}))).all()
