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


def _pits(params, z1=19, n=11):
    """The written field as (z1, n) node values [m] (tooth-major in the parameters)."""
    return np.array([params[f"tooth_pit_field[{k}]"] for k in range(1, z1 * n + 1)]).reshape(z1, n)


def test_no_pits_leaves_the_mesh_healthy():
    state = FatiguePitting().initial_state(G)
    m = pitting_parameters(G, state, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.3, 1))
    np.testing.assert_allclose(_k(m.parameters), HEALTHY_K_PAIR, rtol=1e-12)
    assert np.all(_pits(m.parameters) == 0) and m.pit_truncation_error == 0.0
    assert not any(k.startswith("tooth_stiffness_factor") for k in m.parameters)


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


def test_teeth_pit_in_discrete_cells(pitted):
    m = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.0, 3))
    share = m.pitted_share
    assert share.shape == (19, m.xi.size) and np.all((share >= 0) & (share <= 1))
    # the cells' expected pitted share is the law's density: the teeth's mean follows it
    d = np.interp(m.xi, pitted.xi, pitted.density)
    assert abs(share.mean() - d.mean()) < 0.2 * d.mean()
    # the teeth differ, and the per-tooth deviations are the differences (mean zero over the teeth)
    assert np.ptp(share, axis=0).max() > 0.05
    np.testing.assert_allclose(m.tooth_deviation.mean(axis=0), 0.0, atol=1e-15)
    # a tooth never gives way more than a pit is deep over the healthy tooth
    assert np.all(m.tooth_deviation <= m.pit_depth[None, :] + 1e-12) and np.all(np.isfinite(m.tooth_deviation))
    # the FMU gets the whole field, fitted on the nodes tooth by tooth, to its stated error
    from twin.degradation._nodes import interp_nodes
    nodes = _pits(m.parameters)
    approx = np.array([interp_nodes(row, m.xi) for row in nodes])
    fit = np.linalg.norm(m.tooth_deviation - approx) / np.linalg.norm(m.tooth_deviation)
    assert fit == pytest.approx(m.pit_truncation_error, rel=1e-9)
    # the teeth's differences have no common shape on the nodes: a rank-1 (shape x scale) form of
    # the fitted field would lose a large part of it, the written field loses none of it
    s = np.linalg.svd(nodes, compute_uv=False)
    assert np.sqrt(np.sum(s[1:] ** 2)) / np.linalg.norm(s) > 0.3
    u, s, vt = np.linalg.svd(nodes, full_matrices=False)
    rank_one = np.array([interp_nodes(row, m.xi) for row in s[0] * np.outer(u[:, 0], vt[0])])
    assert fit < np.linalg.norm(m.tooth_deviation - rank_one) / np.linalg.norm(m.tooth_deviation) - 0.1


def test_the_node_fit_of_a_hand_made_field():
    from twin.degradation._nodes import hat_matrix
    from twin.degradation.pitting_map import _fit_teeth
    xi = np.linspace(0.0, 1.0, 41)
    rng = np.random.default_rng(4)
    # teeth with different shapes the 11 nodes hold exactly (rank > 1): the fit returns their nodes
    nodes = rng.normal(0.0, 1e-6, (19, 11))
    held, err = _fit_teeth(nodes @ hat_matrix(xi, 11).T, xi, 11)
    np.testing.assert_allclose(held, nodes, atol=1e-15)
    assert err < 1e-12
    # a shape finer than the nodes: the fit keeps what they hold and reports the rest
    fine = np.outer(np.ones(19), np.cos(2 * np.pi * 9 * xi)) * 1e-6
    _, err = _fit_teeth(fine, xi, 11)
    assert 0.3 < err < 1.0
    assert _fit_teeth(np.zeros((19, 41)), xi, 11)[1] == 0.0


def test_a_face_pitted_through_reaches_the_pit_bottom():
    # late pitting: some teeth have their whole face pitted at some roll positions
    late = FatiguePitting().advance(FatiguePitting().initial_state(G), MeshLoad.static(G, 20.0 * 19 / 52),
                                    3e7, 125.0)
    m = pitting_parameters(G, late, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.58, 0))
    assert np.any(m.pitted_share > 0.999)
    e = m.tooth_deviation
    assert np.all(np.isfinite(e)) and np.isfinite(m.pit_truncation_error)
    # over the healthy tooth each tooth gives way by 0 .. the pit depth; so the teeth differ by no more
    assert np.all(np.ptp(e, axis=0) <= m.pit_depth + 1e-12)


def test_pits_grow_where_they_started():
    model = FatiguePitting()
    load = MeshLoad.static(G, 20.0 * 19 / 52)
    early = model.advance(model.initial_state(G), load, 3e6, 125.0)
    late = model.advance(early, load, 4e6, 125.0)
    scatter = ToothScatter.draw(19, 0.58, 5)
    a = pitting_parameters(G, early, F, HEALTHY_K_PAIR, scatter=scatter).pitted_share
    b = pitting_parameters(G, late, F, HEALTHY_K_PAIR, scatter=scatter).pitted_share
    assert np.all(b >= a - 1e-12) and b.sum() > a.sum()


def test_weaker_teeth_pit_more(pitted):
    scatter = ToothScatter.draw(19, 0.58, 7)
    m = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=scatter)
    pitted_area = m.pitted_share.mean(axis=1)
    order = np.argsort(scatter.factors)
    # lambda > 1 pits faster: the strongest third of the teeth has less pitted area than the weakest
    assert pitted_area[order[:6]].mean() < pitted_area[order[-6:]].mean()
    # the same seed gives the same teeth and the same pits
    again = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.58, 7))
    np.testing.assert_array_equal(again.pitted_share, m.pitted_share)
    np.testing.assert_array_equal(ToothScatter.draw(19, 0.58, 7).factors, scatter.factors)


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


def test_clustered_cells_keep_the_law_and_fail_together():
    independent = ToothScatter.draw(19, 0.0, 11)
    clustered = ToothScatter.draw(19, 0.0, 11, 0.8e-3)
    # a length of 0 is the independent cells exactly: one uniform draw per cell from the seed
    np.testing.assert_array_equal(independent.cell_quantiles(9, 40),
                                  np.random.default_rng([11, 1]).random((19, 9, 40)))
    u = clustered.cell_quantiles(9, 40)
    assert u.shape == (19, 9, 40) and np.all((u > 0) & (u < 1))
    # uniform marginals: the expected pitted fraction at any density is the law's (many flanks:
    # clustered cells sample the law more coarsely than independent ones)
    many = ToothScatter(np.ones(400), 11, 0.8e-3).cell_quantiles(9, 40)
    for d in (0.05, 0.2, 0.5):
        assert abs(np.mean(many < d) - d) < 0.02
    # neighbours across the face are correlated, far cells are not
    z = u - 0.5
    near = np.mean(z[:, :, :-1] * z[:, :, 1:]) / np.var(z)
    far = np.mean(z[:, :, :-20] * z[:, :, 20:]) / np.var(z)
    assert near > 0.5 and abs(far) < 0.1
    np.testing.assert_array_equal(u, ToothScatter.draw(19, 0.0, 11, 0.8e-3).cell_quantiles(9, 40))


def test_clustered_pits_make_the_teeth_differ_more(pitted):
    spread = []
    for length in (0.0, 0.8e-3):
        m = pitting_parameters(G, pitted, F, HEALTHY_K_PAIR, scatter=ToothScatter.draw(19, 0.58, 2, length))
        spread.append(np.sqrt(np.mean(m.tooth_deviation ** 2)))
    assert spread[1] > 1.5 * spread[0]


def test_a_bad_cluster_length_is_named():
    for bad in (-1e-3, float("nan"), 1.0):
        with pytest.raises(ParameterError, match="cluster length"):
            ToothScatter.draw(19, 0.5, 0, bad)
