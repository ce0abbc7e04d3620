"""GearTwin.Gearbox21Rocking: the gear body rocking on its shaft, reacted as a couple at the bearings."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.model_modes import model_modes
from twin.calibration.sensitivity import candidate_parameters
from twin.fmu import FMU
from twin.linearize import linear_model
from twin.operating import operating_point

KW = dict(speed_hz=20.0, load_nm=20.0, channels=("accel_pinion_casing", "accel_gear_casing"))


def _get(path, parameters, names):
    with FMU(path) as fmu:
        fmu.setup(parameters=parameters)
        return dict(zip(names, fmu.get(list(names))))


def _slope_under_moment(EI, L, a, n=40):
    """Slope [rad/(N.m)] at s = a of a beam simply supported at 0 and L under a unit moment at a:
    Euler-Bernoulli finite elements (cubic Hermite, exact for nodal loads), apart from the model's
    closed form."""
    nodes = np.unique(np.concatenate([np.linspace(0.0, a, n), np.linspace(a, L, n)]))
    m = nodes.size
    K = np.zeros((2 * m, 2 * m))
    for e in range(m - 1):
        h = nodes[e + 1] - nodes[e]
        K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += EI / h ** 3 * np.array(
            [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
             [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    free = [i for i in range(2 * m) if i not in (0, 2 * (m - 1))]
    at = 2 * int(np.argmin(abs(nodes - a))) + 1
    f = np.zeros(2 * m)
    f[at] = 1.0
    u = np.zeros(2 * m)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
    return u[at]


def test_the_rocking_stiffness_is_the_shafts_slope_stiffness_and_its_bearings(rocking_fmu):
    d, L, pos, k9, k11 = 0.028, 0.17, 0.4, 2.0e8, 1.2e8
    p = {"d_shaft_output": d, "span_output": L, "gear_position": pos, "kx_bearing9": k9, "kx_bearing11": k11}
    v = _get(rocking_fmu, p, ("rocking_compliance_x", "k_rock_x"))
    EI = 2.1e11 * math.pi * d ** 4 / 64
    # the couple M / L at the bearings deflects them by M / (L k) each, turning the shaft by their sum over L
    expected = _slope_under_moment(EI, L, pos * L) + (1 / k9 + 1 / k11) / L ** 2
    assert v["rocking_compliance_x"] == pytest.approx(expected, rel=1e-6)
    assert v["k_rock_x"] == pytest.approx(1 / expected, rel=1e-6)
    # at mid-span on rigid bearings: 12 E I / L
    mid = _get(rocking_fmu, {"d_shaft_output": d, "span_output": L, "kx_bearing9": 1e15, "kx_bearing11": 1e15},
               ("k_rock_x",))
    assert mid["k_rock_x"] == pytest.approx(12 * EI / L, rel=1e-6)


def test_the_couple_at_the_bearings_is_the_reaction_of_the_gears_tilt(rocking_fmu):
    """The linearised stiffness between the tilt and each pedestal is symmetric (a wrong sign of a
    reaction would make it antisymmetric) and equal to -k / L and +k / L."""
    start, inputs = operating_point(20.0, 20.0)
    lm = linear_model(rocking_fmu, parameters=start, inputs=inputs, settle=0.02, window=2.5e-3, samples=2)
    names = list(lm.state_names)
    v = _get(rocking_fmu, {}, ("k_rock_x", "I_rock10", "span_output"))
    masses = mass_values(rocking_fmu, {})

    def stiffness(force_on, velocity, mass, displacement):
        return -mass * lm.A[names.index(velocity), names.index(displacement)]

    k, L = v["k_rock_x"], v["span_output"]
    for pedestal, sign in (("11", -1.0), ("9", +1.0)):
        tilt_by_pedestal = stiffness("phi", "w_rock_x", v["I_rock10"], f"x{pedestal}")
        pedestal_by_tilt = stiffness(pedestal, f"vx{pedestal}", masses[f"m{pedestal}"], "phi_rock_x")
        assert tilt_by_pedestal == pytest.approx(sign * k / L, rel=1e-3)
        assert pedestal_by_tilt == pytest.approx(tilt_by_pedestal, rel=1e-3)


def test_the_gear_rocks_at_its_slope_stiffness_over_its_diametral_inertia(rocking_fmu, overhangs_fmu):
    # pedestals and bearings so stiff that the rocking is the gear's alone
    stiff = {f"k{d}{n}": 1e11 for d in "xy" for n in (9, 11)}
    stiff.update({f"k{d}_bearing{n}": 1e12 for d in "xy" for n in (9, 11)})
    mm = model_modes(rocking_fmu, stiff, **KW)
    v = _get(rocking_fmu, stiff, ("k_rock_x", "k_rock_y", "I_rock10"))
    rocking = sorted(f for f, c in zip(mm.frequency, mm.classes) if c.name == "gear rocking")
    expected = sorted(math.sqrt(v[k] / v["I_rock10"]) / (2 * math.pi) for k in ("k_rock_x", "k_rock_y"))
    assert len(rocking) == 2 and np.allclose(rocking, expected, rtol=5e-3)
    # at the stated values the rocking modes lie near 1 kHz, on the output shaft, and the rest of
    # the overhangs model's modes stay (two more modes)
    nominal = model_modes(rocking_fmu, {}, **KW)
    base = model_modes(overhangs_fmu, {}, **KW)
    rock = [i for i, c in enumerate(nominal.classes) if c.name == "gear rocking"]
    assert len(rock) == 2 and all(800.0 < nominal.frequency[i] < 1200.0 for i in rock)
    assert all(nominal.side_db[i] < -6.0 for i in rock)
    assert nominal.frequency.size == base.frequency.size + 2
    # its inertia is a calibration candidate with an inertia's bounds
    cand = {c.name: c for c in candidate_parameters(rocking_fmu, {})}
    assert cand["I_rock10"].lower == pytest.approx(0.7 * 5.9e-3) and cand["I_rock10"].upper == pytest.approx(1.4 * 5.9e-3)
