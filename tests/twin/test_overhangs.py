"""GearTwin.Gearbox21Overhangs: the parts carried outside the bearings on overhung shaft ends."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.calibration.mode_classes import mass_values
from twin.calibration.model_modes import model_modes
from twin.calibration.sensitivity import candidate_parameters
from twin.fmu import FMU

KW = dict(speed_hz=20.0, load_nm=20.0, channels=("accel_pinion_casing", "accel_gear_casing"))
ENDS = ("input shaft ends x", "input shaft ends y", "output shaft ends x", "output shaft ends y")


def _get(path, parameters, names):
    with FMU(path) as fmu:
        fmu.setup(parameters=parameters)
        return dict(zip(names, fmu.get(list(names))))


def _dominant(mm, cls):
    """Index of the mode with the largest kinetic-energy share of ``cls``."""
    return max(range(len(mm.classes)), key=lambda i: mm.classes[i].shares.get(cls, 0.0))


def _beam_flexibility(EI, points, supports):
    """Influence matrix [m/N] of a free beam on two rigid supports at ``points``: Euler-Bernoulli
    finite elements (cubic Hermite, exact for point loads at nodes), independent of the model's
    closed forms."""
    nodes = np.unique(np.concatenate([np.linspace(lo, hi, 9) for lo, hi in
                                      zip(sorted([*points, *supports])[:-1], sorted([*points, *supports])[1:])]))
    n = nodes.size
    K = np.zeros((2 * n, 2 * n))
    for e in range(n - 1):
        h = nodes[e + 1] - nodes[e]
        k = EI / h ** 3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                    [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
        K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += k
    fixed = [2 * int(np.argmin(abs(nodes - s))) for s in supports]
    free = [i for i in range(2 * n) if i not in fixed]
    at = [2 * int(np.argmin(abs(nodes - s))) for s in points]
    F = np.zeros((len(points), len(points)))
    for j, pj in enumerate(at):
        f = np.zeros(2 * n)
        f[pj] = 1.0
        u = np.zeros(2 * n)
        u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
        F[:, j] = u[at]
    return F


def test_each_shaft_is_a_beam_through_its_gear_and_ends_on_two_bearings(overhangs_fmu):
    E, rho, d, L, a, b, pos = 2.1e11, 7850.0, 0.024, 0.16, 0.05, 0.08, 0.4
    k4, k6 = 1.0e8, 3.0e8
    p = {"d_shaft_input": d, "span_input": L, "overhang4": a, "overhang6": b, "pinion_position": pos,
         "kx_bearing4": k4, "kx_bearing6": k6, "end_mass6": 0.5}
    names = [f"K_input_x_{ij}" for ij in ("e1e1", "gg", "e2e2", "e1g", "e1e2", "ge2")]
    v = _get(overhangs_fmu, p, (*names, "m_end6", "kx45", "kx56"))
    EI = E * math.pi * d ** 4 / 64
    s = np.array([-a, pos * L, L + b])
    F = _beam_flexibility(EI, list(s), [0.0, L])
    # the bearings: a point at s moves with the shaft centres at the bearings by (L - s)/L and s/L
    T = np.stack([(L - s) / L, s / L])
    F += np.outer(T[0], T[0]) / k4 + np.outer(T[1], T[1]) / k6
    K = np.linalg.inv(F)
    got = np.array([[v["K_input_x_e1e1"], v["K_input_x_e1g"], v["K_input_x_e1e2"]],
                    [v["K_input_x_e1g"], v["K_input_x_gg"], v["K_input_x_ge2"]],
                    [v["K_input_x_e1e2"], v["K_input_x_ge2"], v["K_input_x_e2e2"]]])
    np.testing.assert_allclose(got, K, rtol=1e-6)
    # a load on the span lifts the overhangs: the gear and an end pull each other the same way
    assert v["K_input_x_e1g"] > 0 and v["K_input_x_ge2"] > 0
    # Gearbox21Shafts' two springs per gear are replaced by the beam
    assert v["kx45"] == 0 and v["kx56"] == 0
    # the stub's own mass moves with the end by the cantilever's Rayleigh share 33/140
    assert v["m_end6"] == pytest.approx(0.5 + 33 / 140 * rho * math.pi * d * d / 4 * b, rel=1e-9)
    assert mass_values(overhangs_fmu, p)["m_end6"] == pytest.approx(v["m_end6"], rel=1e-9)


def test_the_ends_add_their_own_modes_below_a_few_khz(overhangs_fmu, shafts_fmu):
    base = model_modes(shafts_fmu, {}, **KW)
    mm = model_modes(overhangs_fmu, {}, **KW)
    assert np.all(mm.damping > 0)
    assert len(mm.frequency) >= len(base.frequency) + 8 - 2     # eight DOFs; a pair may pass fmax
    for cls in ENDS:
        k = _dominant(mm, cls)
        # a 0.35-0.6 kg part on a 25 mm stub of 60-90 mm: a few hundred Hz to about 1 kHz
        assert 250.0 < mm.frequency[k] < 1500.0 and mm.classes[k].shares[cls] > 0.3
    # the mesh reaches them through the shafts: an end-dominated mode within 30 dB of the most
    # visible mode at the casing sensors
    assert max(g for c, g in zip(mm.classes, mm.gain_db) if c.name in ENDS) > -30.0


def test_light_short_ends_leave_the_shafts_gear_modes(overhangs_fmu, shafts_fmu):
    # parts of a gram on 5 mm stubs: their modes move far above 5 kHz, and the gears' lateral modes
    # are Gearbox21Shafts' again (the same beam seen at the gear); a wrong sign of a reaction on the
    # pedestals would show here
    tiny = {f"end_mass{n}": 1e-3 for n in (4, 6, 9, 11)}
    tiny.update({f"overhang{n}": 5e-3 for n in (4, 6, 9, 11)})
    tiny.update(k_coupling_radial_input=1.0, k_coupling_radial_output=1.0)
    base = model_modes(shafts_fmu, {}, fmax=5000.0, **KW)
    mm = model_modes(overhangs_fmu, tiny, fmax=5000.0, **KW)
    assert not any(c.name in ENDS for c in mm.classes)
    for cls in ("pinion lateral x", "pinion lateral y", "gear lateral x", "gear lateral y"):
        assert mm.frequency[_dominant(mm, cls)] == pytest.approx(base.frequency[_dominant(base, cls)], rel=5e-3), cls
    # but a shaft may now turn about its gear as a rigid beam (no tilting inertia here): the two
    # pedestals of a shaft moving against each other feel only their own supports, where the two
    # springs of Gearbox21Shafts also stretched the shaft (827 Hz there)
    k = _dominant(mm, "input pedestals x")
    assert mm.classes[k].shares["input pedestals x"] > 0.9
    assert mm.frequency[k] == pytest.approx(math.sqrt(3.0e7 / 2.0) / (2 * math.pi), rel=1e-2)


def test_the_ends_are_calibratable_within_physical_bounds(overhangs_fmu):
    cands = {c.name: c for c in candidate_parameters(overhangs_fmu)}
    assert cands["overhang6"].lower == pytest.approx(0.8 * 0.09)
    assert cands["overhang6"].upper == pytest.approx(1.25 * 0.09)
    assert cands["end_mass4"].reason.startswith("mass")
    assert cands["k_coupling_radial_input"].reason.startswith("elastomer coupling")
    assert not {"K_input_x_gg", "F_output_y_e1e2", "m_end9", "c_end11_y"} & set(cands)      # computed, not free
