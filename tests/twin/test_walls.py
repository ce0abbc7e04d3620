"""GearTwin.Gearbox21Walls: bearing housings on flexible casing walls, coupled both ways."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.model_modes import model_modes
from twin.calibration.sensitivity import candidate_parameters
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


def _stiffness(fmu_path) -> tuple[np.ndarray, list]:
    """K = -M A[v, x] over every mechanical coordinate (the wall modes in mass-normalised
    coordinates, mass 1) and those coordinates as (position, velocity, mass)."""
    start, inputs = operating_point(20.0, 20.0)
    quiet = {"pinion_roughness.rms": 0.0, "gear_roughness.rms": 0.0, "process.rms": 0.0}
    A, names = state_jacobian(fmu_path, parameters={**quiet, **start}, inputs=inputs, samples=1)
    masses = mass_values(fmu_path, {})
    dofs = [(f"theta{i}", f"omega{i}", masses[f"I{i}"]) for i in (1, 2, 3, 5, 7, 8, 10, 12, 13)]
    dofs += [(f"{a}{i}", f"v{a}{i}", masses[f"m{i}"]) for a in "xy" for i in (4, 5, 6, 9, 10, 11)]
    dofs += [("x_casing", "vx_casing", masses["m_casing"]), ("y_casing", "vy_casing", masses["m_casing"]),
             ("phi_casing", "w_casing", masses["I_casing"])]
    dofs += [(f"casing.q[{k}]", f"casing.qd[{k}]", 1.0) for k in range(1, 5)]
    pos = [names.index(p) for p, _, _ in dofs]
    vel = [names.index(v) for _, v, _ in dofs]
    M = np.array([m for _, _, m in dofs])
    return -M[:, None] * A[np.ix_(vel, pos)], dofs


def test_the_walls_couple_both_ways_and_conservatively(walls_fmu):
    # K (_stiffness) is symmetric only if the walls push the pedestals back as they are pushed
    K, dofs = _stiffness(walls_fmu)
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


# ---- GearTwin.Gearbox21TiltingWalls: a bottom wall under both housings and side walls that tilt them

CC1, CC2, CP1 = (4.730040745, 0.982502215), (7.853204624, 1.000777312), (3.926602312, 1.000777304)


def _beam(s, beta, sigma):
    """Beam function (mean square 1) and its slope per unit of the span, at s from the clamped end."""
    b = beta * s
    return (math.cosh(b) - math.cos(b) - sigma * (math.sinh(b) - math.sin(b)),
            beta * (math.sinh(b) + math.sin(b) - sigma * (math.cosh(b) - math.cos(b))))


def _warburton_hz(a, b, ga, ha, gb, hb, h=0.008, E=1.1e11, nu=0.26, rho=7200.0):
    D = E * h ** 3 / (12 * (1 - nu ** 2))
    return 0.5 * math.pi * math.sqrt(D / (rho * h)) * math.sqrt(ga ** 4 / a ** 4 + gb ** 4 / b ** 4 + 2 * ha * hb / (a * b) ** 2)


def test_the_beam_functions_are_mass_normalised_and_clamped():
    s = np.linspace(0.0, 1.0, 4001)
    for beta, sigma in (CC1, CC2, CP1):
        phi = np.array([_beam(x, beta, sigma)[0] for x in s])
        assert np.mean(phi ** 2) == pytest.approx(1.0, abs=2e-3)
        assert _beam(0.0, beta, sigma) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert _beam(1.0, *CC1)[0] == pytest.approx(0.0, abs=1e-4) and _beam(1.0, *CC1)[1] == pytest.approx(0.0, abs=1e-3)
    # clamped-pinned: zero deflection but a slope at the pinned end (the cover flange)
    assert _beam(1.0, *CP1)[0] == pytest.approx(0.0, abs=1e-4) and abs(_beam(1.0, *CP1)[1]) > 1.0


def test_the_tilting_walls_follow_the_stated_geometry(tilting_walls_fmu):
    p = {"wall_thickness": 0.009, "panel_depth": 0.2, "side_panel_height": 0.24, "bottom_wall_width": 0.28,
         "housing_height": 0.13}
    names = ([f"casing.frequency[{k}]" for k in range(1, 5)] + ["centre_distance"]
             + [f"casing.reach_{h}_{d}[{k}]" for h in ("input", "output") for d in "xy" for k in range(1, 5)])
    with FMU(tilting_walls_fmu) as fmu:
        fmu.setup(parameters=p)
        v = dict(zip(names, fmu.get(names)))
    W, H, depth, t, h = 0.28, 0.24, 0.2, 0.009, 0.13
    side = _warburton_hz(H, depth, 1.25, 1.165, 1.506, 1.248, h=t)          # clamped / simply supported at the flange
    bottom = _warburton_hz(W, depth, 1.506, 1.248, 1.506, 1.248, h=t)       # (1,1), clamped all round
    bottom2 = _warburton_hz(W, depth, 2.5, 4.658, 1.506, 1.248, h=t)        # (2,1)
    assert [v[f"casing.frequency[{k}]"] for k in range(1, 5)] == pytest.approx([side, side, bottom, bottom2], rel=1e-6)
    mid = _beam(0.5, *CC1)[0]                                               # the housings at mid-depth
    ms, mb = 7200 * t * H * depth, 7200 * t * W * depth
    s_b = 0.5 * (1 - v["centre_distance"] / W)                              # input housing across the bottom wall
    lever = 0.5 * (W - v["centre_distance"])                               # side wall to shaft centre
    phi_s, dphi_s = _beam(h / H, *CP1)
    assert v["casing.reach_input_x[1]"] == pytest.approx(mid * phi_s / math.sqrt(ms), rel=1e-5)
    assert v["casing.reach_input_y[1]"] == pytest.approx(-lever * mid * dphi_s / H / math.sqrt(ms), rel=1e-5)
    assert v["casing.reach_output_x[2]"] == pytest.approx(-v["casing.reach_input_x[1]"], rel=1e-9)
    assert v["casing.reach_output_y[2]"] == pytest.approx(v["casing.reach_input_y[1]"], rel=1e-9)
    for k, mode in ((3, CC1), (4, CC2)):
        for side_name, s in (("input", s_b), ("output", 1 - s_b)):
            phi, dphi = _beam(s, *mode)
            assert v[f"casing.reach_{side_name}_y[{k}]"] == pytest.approx(mid * phi / math.sqrt(mb), rel=1e-4)
            assert v[f"casing.reach_{side_name}_x[{k}]"] == pytest.approx(-h * mid * dphi / W / math.sqrt(mb), rel=1e-4)
    assert v["casing.reach_input_x[2]"] == v["casing.reach_output_x[1]"] == 0.0
    cands = {c.name: c for c in candidate_parameters(tilting_walls_fmu)}
    assert cands["housing_height"].lower == pytest.approx(0.7 * 0.15)
    assert cands["housing_height"].upper == pytest.approx(1.2 * 0.15)
    assert cands["housing_height"].reason.startswith("tilt lever arm")
    assert cands["bottom_wall_width"].reason.startswith("wall panel size")
    assert not {"side_lever", "bottom_position", "depth_shape", "side_wall_mass"} & set(cands)


def test_the_tilting_walls_couple_both_ways_and_conservatively(tilting_walls_fmu):
    K, dofs = _stiffness(tilting_walls_fmu)
    assert np.abs(K - K.T).max() < 1e-6 * np.abs(np.diag(K)).max()
    i = {p: k for k, (p, _, _) in enumerate(dofs)}
    with FMU(tilting_walls_fmu) as fmu:
        fmu.setup(parameters={})
        kx4, ky4, rx, ry = fmu.get(["kx4", "ky4", "casing.reach_input_x[3]", "casing.reach_input_y[3]"])
    # the bottom wall's first mode is driven by both the horizontal and the vertical pedestal
    # forces of the input housing: a horizontal bearing force now moves the housing vertically
    assert K[i["x4"], i["casing.q[3]"]] == pytest.approx(-kx4 * rx, rel=1e-5)
    assert K[i["y4"], i["casing.q[3]"]] == pytest.approx(-ky4 * ry, rel=1e-5)
    assert rx != 0.0 and ry != 0.0
    # one bottom wall carries both housings: the output pedestals drive it too
    assert K[i["y9"], i["casing.q[3]"]] != 0.0


def test_horizontal_shaft_modes_reach_the_sensors_through_tilting_walls(tilting_walls_fmu, walls_fmu):
    def horizontal(mm, cls):
        return [(float(f), float(g), bool(v)) for f, g, v, c in zip(mm.frequency, mm.gain_db, mm.visible, mm.classes)
                if c.name == cls]

    tilting = model_modes(tilting_walls_fmu, {}, **KW)
    walls = model_modes(walls_fmu, {}, **KW)
    # the gear's horizontal mode: through walls that carry one direction each 76 dB below the most
    # visible mode and no peak; through the tilting bottom wall a peak within 45 dB
    assert all(g < -60 and not v for _, g, v in horizontal(walls, "gear lateral x"))
    assert any(g > -45 and v for _, g, v in horizontal(tilting, "gear lateral x"))
    # the bare bottom wall's modes (1.19 and 1.72 kHz) rise with the housings on them
    wall = sorted(float(f) for f, c in zip(tilting.frequency, tilting.classes) if c.name == "casing" and f > 1000)
    assert len(wall) == 4 and min(wall) > 1200
