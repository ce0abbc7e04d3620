"""FatiguePitting (Feng et al. Eqs. 11-14)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.base import PittingState, WearState
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.degradation.pitting import DEFAULT_PITTING_COEFFICIENT, FatiguePitting
from twin.errors import ParameterError

GEOMETRY = GearPair()
OMEGA_WET = 2 * math.pi * 20.0                         # lubricated test: 20 Hz
WET_TORQUE = 20.0 * 19 / 52                            # 20 N.m brake -> pinion torque [N.m]


def test_eq_11_by_hand_for_one_point():
    model = FatiguePitting(pitting_coefficient=1e-91, c=31 / 3, m=9 / 8, h=7 / 3)
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    n0, dn, d0 = 2e6, 5e5, 0.01
    state = PittingState(n0, np.linspace(0, 1, 11), np.full(11, d0), GEOMETRY)
    after = model.advance(state, load, dn, OMEGA_WET)
    j = 5
    xi = state.xi[j]
    force = load.force_at(xi)
    w = force / GEOMETRY.face_width
    r = GEOMETRY.equivalent_radius(xi)
    b = math.sqrt(4 * w * r / (math.pi * GEOMETRY.contact_modulus))          # Hertz half-width [m]
    pmax = 2 * w / (math.pi * b)                                              # [Pa]
    tau0 = 0.3 * pmax                                                         # Eq. 12
    z0 = 0.786 * b                                                            # Eq. 13
    volume = 2 * b * z0 * 2 * math.pi * r                                     # Eq. 14
    a = 1e-91 * tau0 ** (31 / 3) * volume / z0 ** (7 / 3)
    expected = d0 + math.exp(-a * n0 ** (9 / 8)) - math.exp(-a * (n0 + dn) ** (9 / 8))   # Eq. 11
    assert after.density[j] == pytest.approx(expected, rel=1e-10)
    assert after.cycles == n0 + dn


def test_cycle_jumping_telescopes_exactly():
    model = FatiguePitting()
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    s0 = model.initial_state(GEOMETRY)
    once = model.advance(s0, load, 4e6, OMEGA_WET)
    twice = model.advance(model.advance(s0, load, 2e6, OMEGA_WET), load, 2e6, OMEGA_WET)
    assert np.allclose(once.density, twice.density, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("equivalent_age", [False, True])
def test_density_is_monotonic_and_bounded(equivalent_age):
    model = FatiguePitting(pitting_coefficient=1e3 * DEFAULT_PITTING_COEFFICIENT, equivalent_age=equivalent_age)
    state = model.initial_state(GEOMETRY)
    history = [state.density]
    for torque in [WET_TORQUE, 0.5 * WET_TORQUE, 2 * WET_TORQUE, WET_TORQUE] * 3:  # load changes between jumps
        state = model.advance(state, MeshLoad.static(GEOMETRY, torque), 3e6, OMEGA_WET)
        history.append(state.density)
    history = np.array(history)
    assert np.all(np.diff(history, axis=0) >= 0)
    assert history.max() <= 1.0 and history[-1].max() == pytest.approx(1.0, abs=1e-12)
    # No load, no pitting.
    idle = model.advance(model.initial_state(GEOMETRY), MeshLoad([0.0, 1.0], [0.0, 0.0]), 1e9, OMEGA_WET)
    assert np.all(idle.density == 0)


def test_equivalent_age_matches_eq_11_at_constant_load_and_keeps_pitting_after_a_load_increase():
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    heavy = MeshLoad.static(GEOMETRY, 1.5 * WET_TORQUE)
    published, aged = FatiguePitting(), FatiguePitting(equivalent_age=True)
    s_pub = s_age = published.initial_state(GEOMETRY)
    for _ in range(4):
        s_pub = published.advance(s_pub, load, 1e6, OMEGA_WET)
        s_age = aged.advance(s_age, load, 1e6, OMEGA_WET)
    assert np.allclose(s_pub.density, s_age.density, rtol=1e-9, atol=1e-12)
    # A heavier load late in life, at the most pitted point: Eq. 11 as published moves less than
    # under the old load (its survival at N under the new load is ~0 already); the
    # equivalent-age rule pits faster, as a heavier load should.
    j = int(np.argmax(s_pub.density))
    gain_pub = published.advance(s_pub, heavy, 1e6, OMEGA_WET).density[j] - s_pub.density[j]
    gain_age = aged.advance(s_age, heavy, 1e6, OMEGA_WET).density[j] - s_age.density[j]
    gain_same_load = aged.advance(s_age, load, 1e6, OMEGA_WET).density[j] - s_age.density[j]
    assert gain_pub < gain_same_load < gain_age


def test_default_calibration_20_percent_after_1e7_cycles_of_the_lubricated_test():
    model = FatiguePitting()
    assert model.pitting_coefficient == DEFAULT_PITTING_COEFFICIENT
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    state = model.advance(model.initial_state(GEOMETRY), load, 1e7, OMEGA_WET)
    assert state.pitting_density == pytest.approx(0.20, abs=0.01)
    early = model.advance(model.initial_state(GEOMETRY), load, 1.3e6, OMEGA_WET)
    assert early.pitting_density == pytest.approx(0.03, abs=0.005)        # the paper's 3 % stage


def test_pitting_concentrates_in_the_single_pair_zone():
    cr = GEOMETRY.contact_ratio
    model = FatiguePitting()
    load = MeshLoad.static(GEOMETRY, WET_TORQUE, n_grid=201)
    state = model.advance(model.initial_state(GEOMETRY, 201), load, 1e7, OMEGA_WET)
    xi, d = state.xi, state.density
    single = (xi > (cr - 1) / cr + 1e-9) & (xi < 1 / cr - 1e-9)
    addendum = xi > 1 / cr + 1e-9                                          # tip-side double-pair zone
    assert GEOMETRY.pitch_point_xi == pytest.approx(0.533, abs=1e-3)       # inside the single-pair zone
    assert d[single].min() > 5 * d[addendum].max()
    # The largest rise along the path is the entry into the single-pair zone (its lowest point).
    rise = np.argmax(np.diff(d))
    assert xi[rise] == pytest.approx((cr - 1) / cr, abs=0.01)


def test_pitting_density_is_the_flank_area_mean():
    state = PittingState(0.0, [0.0, 0.5, 1.0], [0.0, 0.2, 0.0], GEOMETRY)
    # A triangle of height 0.2 over the flank (piecewise linear in u between the 3 points): mean 0.1.
    assert state.pitting_density == pytest.approx(0.1)
    assert state.max_density == 0.2
    with pytest.raises(ParameterError, match="1.5"):
        PittingState(0.0, [0.0, 1.0], [0.0, 1.5], GEOMETRY)


@pytest.mark.parametrize("kwargs, pattern", [({"pitting_coefficient": 0.0}, "pitting_coefficient"),
                                             ({"c": -1.0}, "c must"), ({"m": float("inf")}, "m must"),
                                             ({"h": -0.5}, "h must"),
                                             ({"equivalent_age": 1}, "equivalent_age")])
def test_constructor_rejects_bad_coefficients(kwargs, pattern):
    with pytest.raises(ParameterError, match=pattern):
        FatiguePitting(**kwargs)


def test_advance_validation_and_state_type():
    model = FatiguePitting()
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    with pytest.raises(ParameterError, match="WearState"):
        model.advance(WearState.pristine(GEOMETRY, 11), load, 1e3, OMEGA_WET)
    with pytest.raises(ParameterError, match="cycles"):
        model.advance(model.initial_state(GEOMETRY), load, float("nan"), OMEGA_WET)


def test_cycles_for_increment_for_pitting():
    model = FatiguePitting()
    load = MeshLoad.static(GEOMETRY, WET_TORQUE)
    state = model.initial_state(GEOMETRY)
    n = model.cycles_for_increment(state, load, OMEGA_WET, 0.02)
    assert model.advance(state, load, n, OMEGA_WET).max_density == pytest.approx(0.02, rel=2e-3)
