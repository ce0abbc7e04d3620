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


def test_a_proud_tooth_wears_faster_and_the_mean_rate_is_one():
    sh = _sharing()
    e = np.zeros(19)
    np.testing.assert_allclose(sh.wear_rates(e, np.ones(19)), 1.0, atol=1e-12)
    e[4] = -1e-6          # proud by ~4 static deflections
    e[9] = 1e-6           # recessed as much
    r = sh.wear_rates(e, np.ones(19))
    assert r.mean() == pytest.approx(1.0)
    assert r[4] > 1.3 and r[9] < 0.7
    # a tooth whose material wears twice as fast, at equal offsets, wears twice the others
    c = np.ones(19)
    c[2] = 2.0
    r = sh.wear_rates(np.zeros(19), c)
    assert r[2] / r[0] == pytest.approx(2.0)


def test_wear_levels_the_teeth_to_a_fraction_of_the_static_deflection():
    sh = _sharing()
    offsets, factors = _rig_pinion()
    band = sh.static_deflection
    assert 0.2e-6 < band < 0.4e-6                    # 5 N.m on the rig's pair
    sd = [np.std(sh.level(offsets, factors, d)) for d in (0.0, 5e-6, 20e-6, 60e-6, 240e-6)]
    assert sd[0] == pytest.approx(np.std(offsets))
    assert all(a > b for a, b in zip(sd[:3], sd[1:4]))  # the spread falls as the teeth wear in
    assert sd[3] < band and sd[4] == pytest.approx(sd[3], rel=1e-2)   # then stays: all wear alike
    level = sh.level(offsets, factors, 240e-6)
    np.testing.assert_allclose(sh.wear_rates(level, factors), 1.0, atol=1e-3)
    assert level.min() == 0.0
    # the tooth of largest wear coefficient stands recessed, the smallest proud
    assert level[np.argmax(factors)] > level[np.argmin(factors)]
    # identical material: the teeth end level
    assert np.ptp(sh.level(offsets, np.ones(19), 240e-6)) < 0.05 * band


def test_levelling_converges_with_the_step(monkeypatch):
    import twin.degradation.tooth_wear as tw
    sh = _sharing(20.0)
    offsets, factors = _rig_pinion(1)
    coarse = sh.level(offsets, factors, 30e-6)
    monkeypatch.setattr(tw, "STEP_FRACTION", tw.STEP_FRACTION / 4)
    fine = sh.level(offsets, factors, 30e-6)
    assert np.max(np.abs(coarse - fine)) < 0.02 * np.ptp(fine)


def test_the_worn_profile_enters_the_sharing():
    # a profile relieved at both ends (tip and root relief) moves load into the single-pair zone,
    # where the sliding is small: the proud tooth's extra wear is smaller
    relief = 2e-6 * np.abs(np.linspace(-1, 1, 11)) ** 2
    e = np.zeros(19)
    e[4] = -1e-6
    plain, relieved = _sharing().wear_rates(e, np.ones(19)), _sharing(profile=relief).wear_rates(e, np.ones(19))
    assert relieved[4] < plain[4]


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
        sh.level(np.zeros(19), np.ones(19), -1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.level(np.zeros(19), np.ones(18), 1e-6)
    with pytest.raises(ParameterError, match="one finite value per tooth"):
        sh.level(np.zeros(19), np.zeros(19), 1e-6)
