"""ArchardWear (Feng et al. Eq. 10) and the validating DegradationModel.advance."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.archard import DEFAULT_WEAR_COEFFICIENT, ArchardWear
from twin.degradation.base import PittingState, WearState, flank_mean
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.errors import ParameterError

GEOMETRY = GearPair()
OMEGA_DRY = 2 * math.pi * 10.0                        # dry test: 10 Hz
DRY_TORQUE = 5.0 * 19 / 52                            # 5 N.m brake -> pinion torque [N.m]


def _flat(force: float) -> MeshLoad:
    return MeshLoad([0.0, 1.0], [force, force])


def test_pointwise_archard_is_k_p_v_t_by_hand():
    """h = K p v t with p the mean Hertz pressure, v the sliding speed, t = 2b / v1 the passage time."""
    k, force, cycles = 1e-13, 150.0, 1000.0
    model = ArchardWear(k, adjacent=False)
    state = model.advance(model.initial_state(GEOMETRY, 11), _flat(force), cycles, OMEGA_DRY)
    for j in (1, 3, 8):
        xi = state.xi[j]
        w = force / GEOMETRY.face_width
        r = GEOMETRY.equivalent_radius(xi)
        b = math.sqrt(4 * w * r / (math.pi * GEOMETRY.contact_modulus))
        p = w / (2 * b)
        v = abs(OMEGA_DRY * GEOMETRY.rho1(xi) - OMEGA_DRY * 19 / 52 * GEOMETRY.rho2(xi))
        t = 2 * b / (OMEGA_DRY * GEOMETRY.rho1(xi))
        assert state.depth[j] == pytest.approx(k * p * v * t * cycles, rel=1e-12)
    assert state.cycles == cycles
    # Per-cycle wear does not depend on speed (only the sliding distance per pass counts).
    faster = model.advance(model.initial_state(GEOMETRY, 11), _flat(force), cycles, 3 * OMEGA_DRY)
    assert np.allclose(faster.depth, state.depth)


def test_adjacent_contacts_equal_pointwise_for_a_smooth_load():
    xi = np.linspace(0, 1, 201)
    load = _flat(200.0)
    pointwise = ArchardWear(1.0, adjacent=False).depth_per_cycle(GEOMETRY, xi, load)
    adjacent = ArchardWear(1.0, adjacent=True).depth_per_cycle(GEOMETRY, xi, load)
    # Away from the path ends (half the Hertz zone lies outside) and the pitch-point kink of |v_s|.
    interior = (xi > 0.02) & (xi < 0.98) & (np.abs(xi - GEOMETRY.pitch_point_xi) > 0.02)
    assert np.allclose(adjacent[interior], pointwise[interior], rtol=2e-3)
    assert adjacent[0] == pytest.approx(0.5 * pointwise[0], rel=0.05)


def test_adjacent_contacts_smooth_the_profile_and_keep_the_volume():
    load = MeshLoad.static(GEOMETRY, 20.0 * 19 / 52, n_grid=401)   # steps at the single-pair zone ends
    depth = {}
    for adjacent in (False, True):
        model = ArchardWear(adjacent=adjacent)
        depth[adjacent] = model.advance(model.initial_state(GEOMETRY, 401), load, 1e5, OMEGA_DRY)
    # Max second difference inside the path: the jumps of load at the single-pair zone ends are
    # spread over the contact width.  The outer 2 % are left out: there the Hertz zone reaches
    # past the active profile and the adjacent model rolls the depth off over +-b, as it should.
    inner = slice(8, -8)
    roughness = {a: np.abs(np.diff(s.depth[inner], 2)).max() for a, s in depth.items()}
    assert roughness[True] < 0.3 * roughness[False]
    assert depth[True].mean_depth == pytest.approx(depth[False].mean_depth, rel=0.03)


def test_cycle_jumping_is_linear_for_a_constant_load():
    model = ArchardWear()
    load = MeshLoad.static(GEOMETRY, DRY_TORQUE)
    s0 = model.initial_state(GEOMETRY)
    once = model.advance(s0, load, 2e4, OMEGA_DRY)
    twice = model.advance(model.advance(s0, load, 1e4, OMEGA_DRY), load, 1e4, OMEGA_DRY)
    assert once.cycles == twice.cycles == 2e4
    assert np.allclose(once.depth, twice.depth, rtol=1e-12, atol=0)


def test_default_coefficient_gives_60_um_per_dry_stage():
    """The calibration claim of DEFAULT_WEAR_COEFFICIENT: 60 um mean depth in 3.3e5 dry cycles."""
    model = ArchardWear()
    assert model.wear_coefficient == DEFAULT_WEAR_COEFFICIENT
    state = model.advance(model.initial_state(GEOMETRY), MeshLoad.static(GEOMETRY, DRY_TORQUE), 3.3e5, OMEGA_DRY)
    assert state.mean_depth == pytest.approx(60e-6, rel=0.02)
    # Wear concentrates where the slide-to-roll ratio is high: pinion root, none at the pitch point.
    assert state.depth[0] > state.depth[-1] > 0
    assert state.depth[np.argmin(np.abs(state.xi - GEOMETRY.pitch_point_xi))] < 0.1 * state.max_depth


def test_mean_depth_is_the_flank_area_mean():
    state = WearState(0.0, [0.0, 1.0], [0.0, 2e-6], GEOMETRY)
    u0, u1 = GEOMETRY.flank_position([0.0, 1.0])
    assert state.mean_depth == pytest.approx(1e-6)                 # linear in xi over 2 points
    assert flank_mean(GEOMETRY, state.xi, state.depth) == state.mean_depth
    assert state.max_depth == 2e-6 and u1 > u0


@pytest.mark.parametrize("cycles", [0, -5.0, float("nan"), float("inf"), True])
def test_advance_rejects_bad_cycles(cycles):
    model = ArchardWear()
    with pytest.raises(ParameterError, match="cycles"):
        model.advance(model.initial_state(GEOMETRY), _flat(10.0), cycles, OMEGA_DRY)


@pytest.mark.parametrize("omega1", [0.0, -1.0, float("nan")])
def test_advance_rejects_bad_speed(omega1):
    model = ArchardWear()
    with pytest.raises(ParameterError, match=f"omega1.*{omega1!r}"):
        model.advance(model.initial_state(GEOMETRY), _flat(10.0), 10.0, omega1)


def test_advance_rejects_partial_load_and_wrong_state():
    model = ArchardWear()
    with pytest.raises(ParameterError, match="cover the path of contact"):
        model.advance(model.initial_state(GEOMETRY), MeshLoad([0.0, 0.9], [1.0, 1.0]), 10.0, OMEGA_DRY)
    with pytest.raises(ParameterError, match="PittingState"):
        model.advance(PittingState.pristine(GEOMETRY, 11), _flat(10.0), 10.0, OMEGA_DRY)


def test_constructor_and_state_validation():
    with pytest.raises(ParameterError, match="-1e-13"):
        ArchardWear(-1e-13)
    with pytest.raises(ParameterError, match="adjacent"):
        ArchardWear(adjacent=1)
    with pytest.raises(ParameterError, match="n_grid"):
        ArchardWear().initial_state(GEOMETRY, 1)
    with pytest.raises(ParameterError, match="-1e-06"):
        WearState(0.0, [0.0, 1.0], [0.0, -1e-6], GEOMETRY)
    with pytest.raises(ParameterError, match="from 0 to 1"):
        WearState(0.0, [0.0, 0.5], [0.0, 0.0], GEOMETRY)


def test_cycles_for_increment_hits_the_target():
    model = ArchardWear()
    load = MeshLoad.static(GEOMETRY, DRY_TORQUE)
    state = model.initial_state(GEOMETRY)
    n = model.cycles_for_increment(state, load, OMEGA_DRY, 1e-6)
    assert model.advance(state, load, n, OMEGA_DRY).max_depth == pytest.approx(1e-6, rel=2e-3)
    assert model.cycles_for_increment(state, load, OMEGA_DRY, 1.0, max_cycles=1e6) == 1e6


def test_state_from_field_round_trip():
    model = ArchardWear()
    state = model.advance(model.initial_state(GEOMETRY, 21), _flat(50.0), 1e4, OMEGA_DRY)
    again = model.state_from_field(GEOMETRY, state.cycles, state.xi, state.depth)
    assert isinstance(again, WearState) and again.cycles == 1e4
    assert np.array_equal(again.depth, state.depth)
    with pytest.raises(ParameterError, match="-1.0"):
        model.state_from_field(GEOMETRY, -1.0, state.xi, state.depth)
