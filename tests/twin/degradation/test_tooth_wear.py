"""Tooth-to-tooth wear under load sharing (twin.degradation.tooth_wear)."""
import numpy as np
import pytest

from twin.degradation import GearPair
from twin.degradation._nodes import HEALTHY_K_PAIR
from twin.degradation.tooth_wear import ToothLoadSharing, _share
from twin.errors import ParameterError


def _sharing(torque=5.0, profile=None):
    g = GearPair()
    return ToothLoadSharing.for_gears(g, HEALTHY_K_PAIR, torque / g.base_radius_gear, profile)


def _rig_pinion(seed=0, scatter=0.1):
    rng = np.random.default_rng(seed)
    teeth = np.arange(19)
    offsets = 2e-6 * rng.standard_normal(19) + 4e-6 * (1 - np.cos(2 * np.pi * teeth / 19 + 1.0))
    factors = rng.gamma(1 / scatter ** 2, scatter ** 2, 19)
    return offsets, factors


def test_load_sharing_by_hand():
    inf = np.inf
    # one pair carries the whole force; two alike split it; a pair proud by more than the
    # approach carries it alone; one deviation inside the band: delta = (W + k e) / 2k
    k = np.array([[2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [2.0, 2.0, 0.0], [2.0, 2.0, 0.0]])
    dev = np.array([[0.0, inf, inf], [0.0, 0.0, inf], [0.0, 5.0, inf], [0.0, 1.0, inf]])
    f = _share(k, dev, 4.0)
    np.testing.assert_allclose(f, [[4, 0, 0], [2, 2, 0], [4, 0, 0], [3, 1, 0]])
    np.testing.assert_allclose(f.sum(axis=1), 4.0)


MID = 5          # xi = 0.5: its hat [0.4, 0.6] lies inside the single-contact zone [0.395, 0.605]


def test_a_proud_tooth_wears_faster_where_it_shares_and_alike_where_it_is_alone():
    sh = _sharing()
    ref = sh.node_rates(np.zeros(19), np.ones(19))        # identical teeth
    assert ref.mean() == pytest.approx(1.0)
    np.testing.assert_allclose(ref, ref[0][None, :].repeat(19, axis=0), rtol=1e-12)
    assert ref[0, 0] > 3 * ref[0, MID]                   # the pinion root slides most, the pitch point least
    e = np.zeros(19)
    e[4] = -1e-6          # proud by ~4 static deflections
    e[9] = 1e-6           # recessed as much
    r = sh.node_rates(e, np.ones(19))
    assert r[4, 0] > 1.3 * ref[0, 0] and r[9, 0] < 0.7 * ref[0, 0]            # at the root: shared
    assert r[4, MID] == pytest.approx(ref[0, MID]) and r[9, MID] == pytest.approx(ref[0, MID])   # alone
    # a tooth whose material wears twice as fast, at equal offsets, wears twice as deep everywhere
    c = np.ones(19)
    c[2] = 2.0
    np.testing.assert_allclose(sh.node_rates(np.zeros(19), c)[2], 2 * ref[0], rtol=1e-12)


def test_pitch_errors_wear_in_where_teeth_share_and_stay_where_one_carries_all():
    sh = _sharing()
    offsets, _ = _rig_pinion()
    worn = sh.wear(offsets, np.ones(19), 60e-6)
    # the single-contact zone keeps the teeth's differences: every tooth carries the whole force there
    mid = worn[:, MID] - worn[:, MID].mean()
    np.testing.assert_allclose(mid, offsets - offsets.mean(), atol=0.02 * np.ptp(offsets))
    # once worn in, every tooth wears like the identical teeth at every node: nothing more changes
    ref = sh.node_rates(np.zeros(19), np.ones(19))[0]
    np.testing.assert_allclose(sh.node_rates(worn, np.ones(19)), ref[None, :].repeat(19, axis=0),
                               atol=0.01 * ref.max())
    np.testing.assert_allclose(sh.wear(offsets, np.ones(19), 240e-6)[:, MID] - sh.wear(offsets, np.ones(19), 240e-6)[:, MID].mean(),
                               mid, atol=0.02 * np.ptp(offsets))
    assert worn.min() == 0.0
    # identical teeth of identical material stay alike at any depth
    assert np.ptp(sh.wear(np.zeros(19), np.ones(19), 240e-6)) < 1e-15


def test_a_wear_coefficient_above_the_mean_digs_the_single_contact_zone_by_hand():
    sh = _sharing()
    c = np.ones(19)
    c[3] = 1.2
    ref = sh.node_rates(np.zeros(19), np.ones(19))[0]    # depth per unit mean depth at each node
    for depth in (20e-6, 80e-6):
        worn = sh.wear(np.zeros(19), c, depth)
        # alone in its single zone, tooth 4 loses 0.2 x the local depth more than the others
        assert worn[3, MID] - worn[0, MID] == pytest.approx(0.2 * depth * ref[MID], rel=1e-9)
        # where it shares, its neighbours take the load off it: less than 0.2 x the local depth
        assert worn[3, 0] - worn[0, 0] < 0.2 * depth * ref[0]


def test_wear_converges_with_the_step(monkeypatch):
    import twin.degradation.tooth_wear as tw
    sh = _sharing(20.0)
    offsets, factors = _rig_pinion(1)
    coarse = sh.wear(offsets, factors, 30e-6)
    monkeypatch.setattr(tw, "STEP_FRACTION", tw.STEP_FRACTION / 4)
    fine = sh.wear(offsets, factors, 30e-6)
    assert np.max(np.abs(coarse - fine)) < 0.01 * np.ptp(fine)


def test_the_worn_profile_enters_the_sharing():
    # a profile relieved at both ends (tip and root relief) moves load off the double-contact
    # ends into the single-pair zone: less wear there against the middle
    relief = 2e-6 * np.abs(np.linspace(-1, 1, 11)) ** 2
    plain = _sharing().node_rates(np.zeros(19), np.ones(19))[0]
    relieved = _sharing(profile=relief).node_rates(np.zeros(19), np.ones(19))[0]
    assert relieved[1] / relieved[MID] < 0.5 * plain[1] / plain[MID]


@pytest.mark.parametrize("field, value, match", [
    ("contact_ratio", 0.9, "contact_ratio"), ("mesh_force", -1.0, "mesh_force"),
    ("k_pair", np.zeros(11), "k_pair"), ("profile", np.zeros(5), "profile"), ("sliding", -np.ones(11), "sliding")])
def test_bad_mesh_is_refused_by_name(field, value, match):
    sh = _sharing()
    kwargs = {"k_pair": sh.k_pair, "contact_ratio": sh.contact_ratio, "mesh_force": sh.mesh_force,
              "sliding": sh.sliding, "profile": sh.profile, field: value}
    with pytest.raises(ParameterError, match=match):
        ToothLoadSharing(**kwargs)


def test_bad_teeth_are_refused():
    sh = _sharing()
    with pytest.raises(ParameterError, match="mean_depth"):
        sh.wear(np.zeros(19), np.ones(19), -1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.wear(np.zeros(19), np.ones(18), 1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.wear(np.zeros(19), np.zeros(19), 1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.wear(np.zeros((19, 7)), np.ones(19), 1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.wear(0.0, np.ones(19), 1e-6)
    with pytest.raises(ParameterError, match="too deep for this load"):
        sh.wear(np.zeros(19), np.ones(19), 1.0)


def test_the_two_pair_share_is_the_general_one():
    from twin.degradation.tooth_wear import _share_two
    rng = np.random.default_rng(0)
    dev = rng.normal(0.0, 1e-6, (4000, 2))
    dev[rng.random(4000) < 0.3, 1] = np.inf                     # one pair in mesh
    alone = rng.random(4000) < 0.2
    dev[alone, 0] = np.inf
    dev[alone, 1] = rng.normal(0.0, 1e-6, alone.sum())
    k = np.where(np.isfinite(dev), rng.uniform(1e8, 3e8, (4000, 2)), 0.0)
    np.testing.assert_allclose(_share_two(k, dev, 300.0), _share(k, dev, 300.0), atol=1e-9)


def test_the_compiled_integration_is_the_numpy_one():
    import math

    import twin.degradation.tooth_wear as tw
    sh = _sharing()
    offsets, factors = _rig_pinion(2)
    got = sh.wear(offsets, factors, 20e-6)
    mesh = sh._mesh(19)
    ref = sh._reference(mesh)
    norm = ref.mean()
    e = np.repeat(offsets[:, None], 11, axis=1)
    steps = math.ceil(20e-6 * factors.max() * sh.mesh_force * sh.sliding.max() / norm
                      / (tw.STEP_FRACTION * sh.static_deflection))
    for _ in range(steps):
        grow = (sh._node_rates(e, factors, mesh) - ref) / norm
        e += (20e-6 / steps) * (grow - grow.mean(axis=0))
    np.testing.assert_allclose(got, e - e.min(), atol=1e-15)
