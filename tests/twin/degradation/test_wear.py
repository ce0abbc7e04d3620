"""FlankWear: both flanks wear under the LTCA pressure; conjugate action; running-in; smoothness."""
from __future__ import annotations

import numpy as np
import pytest

from twin.degradation import ArchardWear, GearPair, MeshLoad, TransmittedLoad, WearState, flank_mean
from twin.degradation.wear import FlankWear
from twin.errors import ParameterError

G = GearPair()
T1 = 5.0 * 19 / 52                       # N.m on the pinion of the dry test
F = T1 / G.base_radius_pinion


@pytest.fixture(scope="module")
def model() -> FlankWear:
    return FlankWear(n_positions=48)


def test_both_flanks_wear_where_they_slide(model):
    state = model.initial_state(G, 201)
    d1, d2 = model.depth_per_cycle(state, TransmittedLoad(F))
    xp = G.pitch_point_xi
    near = np.abs(state.xi - xp) < 0.01
    # no sliding at the pitch point; most at the ends of the path
    assert d1[near].max() < 0.15 * d1.max() and d2[near].max() < 0.15 * d2.max()
    assert d1[state.xi < 0.1].max() > 3 * d1[near].max()
    assert d2[state.xi > 0.9].max() > 3 * d2[near].max()
    # the gear flank meets the pinion z1/z2 times as often: it wears less on the whole
    assert flank_mean(G, state.xi, d2) < flank_mean(G, state.xi, d1)


def test_the_pinion_rate_matches_the_prescribed_load_archard(model):
    """With the running-in excess removed, the pinion's flank-mean rate under the LTCA load is the
    classic Archard rate under the quasi-static load sharing (same K, same sliding)."""
    steady = FlankWear(n_positions=48, running_in_factor=1.0)
    state = steady.initial_state(G, 201)
    d1, _ = steady.depth_per_cycle(state, TransmittedLoad(F))
    classic = ArchardWear(adjacent=False).depth_per_cycle(G, state.xi, MeshLoad.static(G, T1))
    assert flank_mean(G, state.xi, d1) == pytest.approx(flank_mean(G, state.xi, classic), rel=0.08)


def test_uniform_thinning_does_not_change_the_wear(model):
    state = model.initial_state(G, 201)
    n = state.xi.size
    thin = WearState(0.0, state.xi, np.full(n, 30e-6), G, np.full(n, 30e-6))
    # two fresh models sample the same mesh phases
    a1, a2 = FlankWear(n_positions=48, running_in_factor=1.0).rates(state, TransmittedLoad(F))
    b1, b2 = FlankWear(n_positions=48, running_in_factor=1.0).rates(thin, TransmittedLoad(F))
    np.testing.assert_allclose(b1, a1, rtol=1e-6, atol=1e-9 * a1.max())
    np.testing.assert_allclose(b2, a2, rtol=1e-6, atol=1e-9 * a2.max())


def test_running_in_excess_decays_with_the_depth_removed():
    m = FlankWear(n_positions=48, running_in_factor=4.0, running_in_depth=2e-6)
    fresh = m.initial_state(G, 201)
    n = fresh.xi.size
    run_in = WearState(1e5, fresh.xi, np.full(n, 20e-6), G, np.full(n, 20e-6))
    r_fresh = m.depth_per_cycle(fresh, TransmittedLoad(F))[0]
    m = FlankWear(n_positions=48, running_in_factor=4.0, running_in_depth=2e-6)     # same phases
    r_run = m.depth_per_cycle(run_in, TransmittedLoad(F))[0]
    ratio = r_fresh[r_run > 0.1 * r_run.max()] / r_run[r_run > 0.1 * r_run.max()]
    np.testing.assert_allclose(ratio, 4.0 / (1 + 3 * np.exp(-10)), rtol=1e-6)


def test_worn_profile_stays_smooth_under_feedback(model):
    """A static wear loop (each jump re-solves the LTCA on the worn flanks): the pair's separation,
    what the FMU sees, keeps no point-to-point saw-tooth (within 15 % of its range of its
    9-point running mean); the flank depths keep a ripple of a few percent of their range at the
    scale of the mesh-phase sampling (about 0.015 of the path), which the separation bridges."""
    from twin.degradation import wear_deviation
    state = model.initial_state(G, 201)
    load = TransmittedLoad(F)
    for _ in range(10):
        dn = model.cycles_for_increment(state, load, 60.0, 3e-6)
        state = model.advance(state, load, dn, 60.0)
    _, sep = wear_deviation(G, state)
    smooth = np.convolve(sep, np.ones(9) / 9, mode="same")[4:-4]
    assert np.max(np.abs(sep[4:-4] - smooth)) < 0.15 * np.ptp(sep)
    assert state.max_depth > 4e-6 and state.gear_mean_depth > 0


def test_a_long_jump_takes_a_new_contact_analysis_every_ltca_increment():
    """A jump of about 10 um at the 90th percentile is integrated in segments of at most
    ``ltca_increment``, each on a fresh LTCA of the worn flanks, and ends at the cycles asked;
    with an increment larger than the jump the LTCA of the jump's start serves throughout."""
    load = TransmittedLoad(F)
    calls = {}
    for increment in (1e-3, 2e-6):
        model = FlankWear(n_positions=16, ltca_increment=increment, running_in_factor=1.0)
        state = model.initial_state(G, 101)
        dn = model.cycles_for_increment(state, load, 60.0, 10e-6)
        before = model._calls
        worn = model.advance(state, load, dn, 60.0)
        calls[increment] = model._calls - before
        assert worn.cycles == pytest.approx(dn, rel=1e-12)
    assert calls[1e-3] == 0 and calls[2e-6] >= 2
    with pytest.raises(ParameterError, match="ltca_increment"):
        FlankWear(ltca_increment=0.0)


def test_bad_arguments_are_named(model):
    with pytest.raises(ParameterError, match="running_in_factor"):
        FlankWear(running_in_factor=0.5)
    with pytest.raises(ParameterError, match="n_positions"):
        FlankWear(n_positions=4)
    with pytest.raises(ParameterError, match="transmitted force"):
        TransmittedLoad(-3.0)
    with pytest.raises(ParameterError, match="MeshLoad"):
        from twin.degradation import FatiguePitting
        FatiguePitting().advance(FatiguePitting().initial_state(G), TransmittedLoad(F), 1e3, 60.0)
