"""Pitting mapped through the LTCA: the tooth body keeps its compliance, teeth pit unequally."""
from __future__ import annotations

import numpy as np
import pytest

from twin.degradation import HEALTHY_K_PAIR, FatiguePitting, GearPair, MeshLoad
from twin.degradation.pitting_map import ToothScatter, gear_density, pitting_parameters
from twin.errors import ParameterError

G = GearPair()
F = 20.0 * 19 / 52 / G.base_radius_pinion


@pytest.fixture(scope="module")
def pitted():
    model = FatiguePitting()
    state = model.initial_state(G)
    return model.advance(state, MeshLoad.static(G, 20.0 * 19 / 52), 6e6, 125.0)


def _k(params, n=11):
    return np.array([params[f"k_pair[{i}]"] for i in range(1, n + 1)])


def test_no_pits_leaves_the_mesh_healthy():
    state = FatiguePitting().initial_state(G)
    m = pitting_parameters(G, state, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.3, 1))
    np.testing.assert_allclose(_k(m.parameters), HEALTHY_K_PAIR, rtol=1e-12)
    factors = [m.parameters[f"tooth_stiffness_factor[{j}]"] for j in range(1, 20)]
    np.testing.assert_allclose(factors, 1.0, rtol=1e-9)


def test_pits_soften_only_the_contact(pitted):
    m = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR)
    k = _k(m.parameters)
    assert np.all(k <= np.array(HEALTHY_K_PAIR) + 1e-6) and np.any(k < 0.95 * np.array(HEALTHY_K_PAIR))
    # at low density the contact-only loss is smaller than the lumped k (1 - D)
    xi = np.linspace(0, 1, 11)
    d = np.interp(xi, pitted.xi, pitted.density)
    light = (d > 0.02) & (d < 0.3)
    assert light.any()
    assert np.all(k[light] / np.array(HEALTHY_K_PAIR)[light] > 1 - d[light])
    # teeth alike: every factor 1
    np.testing.assert_allclose([m.parameters[f"tooth_stiffness_factor[{j}]"] for j in range(1, 20)], 1.0,
                               atol=1e-9)


def test_weaker_teeth_get_softer(pitted):
    scatter = ToothScatter.draw(19, 0.3, 7)
    m = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=scatter)
    factors = np.array([m.parameters[f"tooth_stiffness_factor[{j}]"] for j in range(1, 20)])
    # lambda > 1 pits faster: a lower factor; the order of the factors is the reverse of lambda's
    assert np.all(np.diff(factors[np.argsort(scatter.factors)]) < 0)
    assert factors.min() < 1 < factors.max()
    # the same seed gives the same teeth
    np.testing.assert_array_equal(ToothScatter.draw(19, 0.3, 7).factors, scatter.factors)


def test_the_gear_flank_pits_less():
    d = np.array([0.0, 0.1, 0.5])
    dg = gear_density(G, d, 9 / 8)
    assert dg[0] == 0 and np.all(dg[1:] < d[1:]) and np.all(dg[1:] > 0)


def test_bad_input_is_named(pitted):
    with pytest.raises(ParameterError, match="force"):
        pitting_parameters(G, pitted, -1.0, HEALTHY_K_PAIR)
    with pytest.raises(ParameterError, match="tooth factors"):
        pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(18, 0.2, 0))
    with pytest.raises(ParameterError, match="scatter"):
        ToothScatter.draw(19, -0.1, 0)
