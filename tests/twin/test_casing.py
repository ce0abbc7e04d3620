"""GearTwin.Gearbox21Casing: the pedestals on a casing that moves on its mounts (two-way)."""
from __future__ import annotations

import numpy as np
import pytest

from twin.calibration.model_modes import model_modes
from twin.fmu import FMU
from twin.linearize import state_jacobian
from twin.operating import operating_point

CHANNELS = ("accel_pinion_casing", "accel_gear_casing")
TORSION = ("1", "2", "3", "5", "7", "8", "10", "12", "13")
LATERAL = ("4", "5", "6", "9", "10", "11")


def _mechanical(names):
    """(position state, velocity state, mass parameter) of every mechanical degree of freedom."""
    dofs = [(f"theta{i}", f"omega{i}", f"I{i}") for i in TORSION]
    dofs += [(f"{a}{i}", f"v{a}{i}", f"m{i}") for a in "xy" for i in LATERAL]
    dofs += [("x_casing", "vx_casing", "m_casing"), ("y_casing", "vy_casing", "m_casing"),
             ("phi_casing", "w_casing", "I_casing")]
    assert all(p in names and v in names for p, v, _ in dofs)
    return dofs


@pytest.fixture(scope="module")
def stiffness(casing_fmu):
    """K = -M A[v, x] over the mechanical degrees of freedom at the operating point, and the values."""
    start, inputs = operating_point(20.0, 20.0)
    quiet = {"pinion_roughness.rms": 0.0, "gear_roughness.rms": 0.0, "process.rms": 0.0}
    A, names = state_jacobian(casing_fmu, parameters={**quiet, **start}, inputs=inputs, samples=1)
    dofs = _mechanical(names)
    with FMU(casing_fmu) as fmu:
        values = {v.name: float(v.start) for v in fmu.parameters if v.start is not None and v.type == "Real"}
    pos = [names.index(p) for p, _, _ in dofs]
    vel = [names.index(v) for _, v, _ in dofs]
    M = np.array([values[m] for _, _, m in dofs])
    K = -M[:, None] * A[np.ix_(vel, pos)]
    return K, [p for p, _, _ in dofs], values


def test_the_casing_couples_both_ways_and_conservatively(stiffness):
    K, names, v = stiffness
    # a conservative structure has a symmetric stiffness matrix: the casing pushes the pedestals
    # back exactly as they push it (a one-way or sign-wrong coupling breaks the symmetry)
    scale = np.abs(np.diag(K)).max()
    assert np.abs(K - K.T).max() < 1e-6 * scale
    i = {n: k for k, n in enumerate(names)}
    kx = v["kx4"] + v["kx6"] + v["kx9"] + v["kx11"]
    ky = v["ky4"] + v["ky6"] + v["ky9"] + v["ky11"]
    a, h, s, hm = 0.25 * v["module"] * (19 + 52), v["shaft_height"], v["mount_spacing"], v["mount_height"]
    assert K[i["x_casing"], i["x_casing"]] == pytest.approx(kx + 2 * v["kx_mount"], rel=1e-5)
    assert K[i["y_casing"], i["y_casing"]] == pytest.approx(ky + 2 * v["ky_mount"], rel=1e-5)
    assert K[i["phi_casing"], i["phi_casing"]] == pytest.approx(
        h ** 2 * kx + a ** 2 * ky + 2 * v["ky_mount"] * (s / 2) ** 2 + 2 * v["kx_mount"] * hm ** 2, rel=1e-5)
    # a pedestal of the pinion shaft, left of the centre of mass: its vertical spring turns the casing
    assert K[i["y4"], i["phi_casing"]] == pytest.approx(v["ky4"] * a, rel=1e-5)
    assert K[i["x9"], i["phi_casing"]] == pytest.approx(v["kx9"] * h, rel=1e-5)
    assert K[i["x4"], i["x_casing"]] == pytest.approx(-v["kx4"], rel=1e-5)


def test_the_casing_modes_and_a_horizontal_mode_at_the_vertical_sensors(casing_fmu, measured_fmu):
    kw = dict(speed_hz=20.0, load_nm=20.0, channels=CHANNELS)
    on = model_modes(casing_fmu, {}, **kw)
    assert np.all(on.damping > 0)
    casing = [k for k, c in enumerate(on.classes) if c.name == "casing"]
    assert len(casing) >= 3                       # sway, bounce and rocking on the mounts
    # the casing's horizontal sway (x share above y share) shows at the vertical sensors: the
    # bearing forces act above the centre of mass and rock the casing
    sway = [k for k in casing if on.classes[k].shares.get("casing", 0) > 0.3
            and on.classes[k].shares.get("output pedestals x", 0) + on.classes[k].shares.get("gear lateral x", 0)
            > on.classes[k].shares.get("output pedestals y", 0) + on.classes[k].shares.get("gear lateral y", 0)]
    assert sway and any(on.visible[k] for k in sway)
    # on rigid ground (heavy, stiff casing) the gearbox modes are those of Gearbox21Measured
    rigid = model_modes(casing_fmu, {"m_casing": 1e5, "I_casing": 1e4, "kx_mount": 1e13, "ky_mount": 1e13}, **kw)
    ground = model_modes(measured_fmu, {}, **kw)
    for f, c in zip(ground.frequency, ground.classes):
        if c.name != "sensor path" and 30.0 < f < 5000.0:
            assert np.min(np.abs(rigid.frequency / f - 1)) < 0.005, f
