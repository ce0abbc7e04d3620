"""Loaded tooth contact analysis: Hertz limits, load sharing, conjugate action of worn flanks, pits."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.geometry import GearPair
from twin.degradation.ltca import FlankDamage, LoadedContact, contact_for
from twin.errors import ParameterError

G = GearPair()
F = 272.9          # N: 20 N.m on the gear of the 19/52 rig


@pytest.fixture(scope="module")
def contact() -> LoadedContact:
    return contact_for(G)


def test_single_pair_pressure_is_hertzian(contact):
    xi = 0.5
    sol = contact.solve([xi], F)
    pair = sol.pairs[0]
    assert pair.total == pytest.approx(F, rel=1e-10)
    assert np.all(pair.force >= 0)
    loaded = pair.x[pair.force > 0]
    b = float(G.hertz_half_width(F, xi))
    # the loaded cells span the Hertz contact width, to a cell
    assert abs((loaded.max() - loaded.min() + pair.width) - 2 * b) <= 2 * pair.width
    p_max = float(np.max(pair.force / (pair.width * G.face_width)))
    assert p_max == pytest.approx(float(G.hertz_max_pressure(F, xi)), rel=0.15)
    # the approach is the tooth bodies' plus a contact part of Weber's order (log of depth/half-width)
    bulk = F * float(contact.bulk_compliance(xi))
    contact_part = sol.approach - bulk
    weber = 2 * F / (math.pi * G.contact_modulus * G.face_width)
    assert 2 * weber < contact_part < 12 * weber


def test_complementarity_and_force_balance(contact):
    xi = [0.2, 0.2 + 1 / G.contact_ratio]
    sol = contact.solve(xi, F)
    assert sum(p.total for p in sol.pairs) == pytest.approx(F, rel=1e-10)
    assert all(np.all(p.force >= 0) for p in sol.pairs)
    # healthy flanks one base pitch apart share the load in proportion to their stiffness
    a, b = sol.pairs
    assert 0.2 * F < a.total < 0.8 * F and 0.2 * F < b.total < 0.8 * F


def test_uniform_thinning_is_backlash_not_excitation(contact):
    """Conjugate action: the same depth all along both flanks moves the approach by that depth
    and changes no pair force."""
    xi = np.linspace(0, 1, 51)
    worn = FlankDamage.of(xi, pinion_depth=np.full(51, 40e-6), gear_depth=np.full(51, 10e-6))
    pos = [0.3, 0.3 + 1 / G.contact_ratio]
    healthy, thinned = contact.solve(pos, F), contact.solve(pos, F, worn)
    assert thinned.approach - healthy.approach == pytest.approx(50e-6, rel=1e-6)
    for h, t in zip(healthy.pairs, thinned.pairs):
        assert t.total == pytest.approx(h.total, rel=1e-6)
    np.testing.assert_allclose(contact.separation([0.1, 0.5, 0.9], worn), 50e-6, rtol=0, atol=1e-11)


def test_a_pair_further_apart_than_the_approach_loses_contact(contact):
    xi = np.linspace(0, 1, 101)
    # the early part of the path (xi < 0.45) worn 30 um deep: the pair there is clear of the load
    depth = np.where(xi < 0.45, 30e-6, 0.0)
    worn = FlankDamage.of(xi, pinion_depth=depth)
    sol = contact.solve([0.2, 0.2 + 1 / G.contact_ratio], F, worn)
    totals = {round(p.xi, 6): p.total for p in sol.pairs}
    assert totals.get(0.2, 0.0) < 1e-9 * F
    cycle = contact.mesh_cycle(F, worn, n_positions=32)
    assert cycle.unloaded.any() and not contact.mesh_cycle(F, n_positions=32).unloaded.any()


def test_a_groove_narrower_than_the_mating_curvature_bridges(contact):
    xi = np.linspace(0, 1, 401)
    narrow = FlankDamage.of(xi, pinion_depth=np.where(np.abs(xi - 0.5) < 0.004, 50e-6, 0.0))
    wide = FlankDamage.of(xi, pinion_depth=np.where(np.abs(xi - 0.5) < 0.2, 50e-6, 0.0))
    # 0.004 of the path is 60 um of flank; x^2 / 2R reaches 50 um only at ~0.6 mm
    assert contact.separation([0.5], narrow)[0] < 1e-6
    assert contact.separation([0.5], wide)[0] == pytest.approx(50e-6, rel=1e-6)


def test_uniform_pits_act_as_a_softer_contact(contact):
    """A pitted fraction D of the face width leaves the load on L (1 - D): the contact behaves as
    one of modulus E* (1 - D), which is wider, so its compliance is
    (c_contact + ln(1 - D) / (pi E* L)) / (1 - D) (the law pitting_map uses per tooth); the tooth
    body is untouched."""
    from twin.degradation.pitting_map import pitted_contact_compliance
    xi = np.linspace(0, 1, 51)
    bulk = float(contact.bulk_compliance(0.5))
    c0 = contact.pair_compliance([0.5], F)[0]
    for d in (0.2, 0.5, 0.8):
        pitted = FlankDamage.of(xi, pinion_pitted=np.full(51, d))
        c1 = contact.pair_compliance([0.5], F, pitted)[0]
        assert c1 - bulk == pytest.approx(float(pitted_contact_compliance(G, c0 - bulk, d)), rel=1e-2)
        assert c1 - bulk < (c0 - bulk) / (1 - d)


def test_bad_input_is_named(contact):
    with pytest.raises(ParameterError, match="force"):
        contact.solve([0.5], -1.0)
    with pytest.raises(ParameterError, match="pinion_depth"):
        FlankDamage.of(np.linspace(0, 1, 5), pinion_depth=np.full(4, 1e-6))
    with pytest.raises(ParameterError, match="pinion_pitted"):
        FlankDamage.of(np.linspace(0, 1, 5), pinion_pitted=np.full(5, 1.0))
