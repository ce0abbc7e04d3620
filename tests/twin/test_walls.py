"""GearTwin.Gearbox21Walls: bearing housings on flexible casing walls, coupled both ways."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.sensitivity import candidate_parameters, model_modes
from twin.fmu import FMU
from twin.linearize import state_jacobian
from twin.operating import operating_point

CHANNELS = ("accel_pinion_casing", "accel_gear_casing")
KW = dict(speed_hz=20.0, load_nm=20.0, channels=CHANNELS)
PEDESTALS = [f"k{a}{i}" for a in "xy" for i in (4, 6, 9, 11)]


def _clamped_plate_hz(a, b, h, E=1.1e11, nu=0.26, rho=7200.0):
    """Warburton's first natural frequency of a plate a x b x h clamped on all edges [Hz]."""
    D = E * h ** 3 / (12 * (1 - nu ** 2))
    G, H = 1.506, 1.248
    return 0.5 * math.pi * math.sqrt(D / (rho * h)) * math.sqrt(G ** 4 / a ** 4 + G ** 4 / b ** 4 + 2 * H ** 2 / (a * b) ** 2)


def test_the_plate_formula_is_warburtons_and_close_to_leissas_square_plate():
    # Leissa (NASA SP-160): a clamped square plate's first mode is lambda^2 = 35.99, with
    # omega = lambda^2 / a^2 sqrt(D / (rho h))
    a, h = 0.2, 0.008
    D = 1.1e11 * h ** 3 / (12 * (1 - 0.26 ** 2))
    exact = 35.99 / a ** 2 * math.sqrt(D / (7200 * h)) / (2 * math.pi)
    assert _clamped_plate_hz(a, a, h) == pytest.approx(exact, rel=0.01)


def test_the_wall_parameters_follow_the_stated_geometry(walls_fmu):
    p = {"wall_thickness": 0.01, "panel_depth": 0.2, "side_panel_height": 0.22, "bottom_panel_width": 0.16}
    names = ["side_wall_frequency", "bottom_wall_frequency", "side_wall_modal_mass", "bottom_wall_modal_mass",
             "casing.frequency[1]", "casing.modal_mass[4]"]
    with FMU(walls_fmu) as fmu:
        fmu.setup(parameters=p)
        v = dict(zip(names, fmu.get(names)))
    assert v["side_wall_frequency"] == pytest.approx(_clamped_plate_hz(0.22, 0.2, 0.01), rel=1e-9)
    assert v["bottom_wall_frequency"] == pytest.approx(_clamped_plate_hz(0.16, 0.2, 0.01), rel=1e-9)
    # modal mass at the centre: the product of two clamped-clamped beam functions, 0.3965^2 of the plate
    assert v["side_wall_modal_mass"] == pytest.approx(0.3965 ** 2 * 7200 * 0.01 * 0.22 * 0.2, rel=1e-9)
    assert v["casing.frequency[1]"] == v["side_wall_frequency"]
    assert v["casing.modal_mass[4]"] == v["bottom_wall_modal_mass"]
    cands = {c.name: c for c in candidate_parameters(walls_fmu)}
    assert cands["wall_thickness"].lower == pytest.approx(0.8 * 0.008)
    assert cands["wall_thickness"].upper == pytest.approx(1.4 * 0.008)
    assert cands["panel_depth"].reason.startswith("wall panel size")
    assert {"side_panel_height", "bottom_panel_width"} <= set(cands)
    assert not {"side_wall_frequency", "side_wall_modal_mass", "wall_damping"} & set(cands)


def test_the_walls_couple_both_ways_and_conservatively(walls_fmu):
    # K = -M A[v, x] over every mechanical coordinate, the wall modes in mass-normalised
    # coordinates (mass 1): symmetric only if the walls push the pedestals back as they are pushed
    start, inputs = operating_point(20.0, 20.0)
    quiet = {"pinion_roughness.rms": 0.0, "gear_roughness.rms": 0.0, "process.rms": 0.0}
    A, names = state_jacobian(walls_fmu, parameters={**quiet, **start}, inputs=inputs, samples=1)
    masses = mass_values(walls_fmu, {})
    dofs = [(f"theta{i}", f"omega{i}", masses[f"I{i}"]) for i in (1, 2, 3, 5, 7, 8, 10, 12, 13)]
    dofs += [(f"{a}{i}", f"v{a}{i}", masses[f"m{i}"]) for a in "xy" for i in (4, 5, 6, 9, 10, 11)]
    dofs += [("x_casing", "vx_casing", masses["m_casing"]), ("y_casing", "vy_casing", masses["m_casing"]),
             ("phi_casing", "w_casing", masses["I_casing"])]
    dofs += [(f"casing.q[{k}]", f"casing.qd[{k}]", 1.0) for k in range(1, 5)]
    pos = [names.index(p) for p, _, _ in dofs]
    vel = [names.index(v) for _, v, _ in dofs]
    M = np.array([m for _, _, m in dofs])
    K = -M[:, None] * A[np.ix_(vel, pos)]
    assert np.abs(K - K.T).max() < 1e-6 * np.abs(np.diag(K)).max()
    # a wall mode is driven by its housing's pedestals (input shaft, horizontal: pedestals 4 and 6)
    with FMU(walls_fmu) as fmu:
        fmu.setup(parameters={})
        kx4, m1 = fmu.get(["kx4", "casing.modal_mass[1]"])
    i = {p: k for k, (p, _, _) in enumerate(dofs)}
    assert K[i["x4"], i["casing.q[1]"]] == pytest.approx(-kx4 / math.sqrt(m1), rel=1e-5)
    assert K[i["y4"], i["casing.q[1]"]] == 0.0


def test_wall_modes_sit_where_the_plate_formula_puts_them(walls_fmu):
    # on pedestal springs a thousand times softer the walls carry almost nothing: their modes are
    # the bare clamped panels'
    soft = {k: 3e4 for k in PEDESTALS}
    mm = model_modes(walls_fmu, soft, **KW)
    walls = sorted(float(f) for f, c in zip(mm.frequency, mm.classes) if c.name == "casing" and f > 1000)
    side, bottom = _clamped_plate_hz(0.25, 0.18, 0.008), _clamped_plate_hz(0.15, 0.18, 0.008)
    assert 1200 < side < 1400 and 1950 < bottom < 2150
    assert walls == pytest.approx([side, side, bottom, bottom], rel=0.01)


def test_shaft_modes_reach_the_sensors_through_the_walls(walls_fmu, shafts_fmu):
    def vertical_shaft_modes(mm, cls):
        return [(float(f), float(g), bool(v)) for f, g, v, c in zip(mm.frequency, mm.gain_db, mm.visible, mm.classes)
                if c.shares.get(cls, 0.0) > 0.25]

    walls = model_modes(walls_fmu, {}, **KW)
    rigid = model_modes(shafts_fmu, {}, **KW)
    # the pinion's vertical mode on its shaft (1.6-1.7 kHz, shared with torsion through the mesh):
    # through the rigid casing 21 dB below the most visible mode and no peak of its own; through
    # the walls a peak within 30 dB
    pinion = vertical_shaft_modes(walls, "pinion lateral y")
    assert any(1400 < f < 1900 and g > -30 and v for f, g, v in pinion)
    assert not any(1400 < f < 1900 and v for f, g, v in vertical_shaft_modes(rigid, "pinion lateral y"))
    # the gear's vertical mode: visible, within 30 dB
    gear = vertical_shaft_modes(walls, "gear lateral y")
    assert any(g > -30 and v for f, g, v in gear)
    # the wall modes the housings load (above 1 kHz; below it the rigid casing moves on its mounts)
    # lie above the bare panels' frequencies, stiffened by the pedestals on them, and a
    # vertical one reaches a sensor
    wall = [(float(f), bool(v)) for f, v, c in zip(walls.frequency, walls.visible, walls.classes)
            if c.name == "casing" and c.shares["casing"] > 0.9 and f > 1000]
    assert len(wall) == 4 and min(f for f, _ in wall) > 1300 and any(v for _, v in wall)
