"""Damage states -> FMU k_pair / profile_deviation."""
from __future__ import annotations

import numpy as np
import pytest

from twin.degradation.archard import ArchardWear
from twin.degradation.base import PittingState, WearState
from twin.degradation.geometry import GearPair
from twin.degradation.load import MeshLoad
from twin.degradation.mapping import HEALTHY_K_PAIR, mesh_parameters, project_on_nodes, project_wear
from twin.errors import ParameterError

GEOMETRY = GearPair()
XI = np.linspace(0, 1, 101)
NODES = np.linspace(0, 1, 11)
K_KEYS = [f"k_pair[{i}]" for i in range(1, 12)]
E_KEYS = [f"profile_deviation[{i}]" for i in range(1, 12)]


def test_zero_damage_gives_the_healthy_parameters_exactly():
    for update in (mesh_parameters(GEOMETRY),
                   mesh_parameters(GEOMETRY, wear=WearState.pristine(GEOMETRY, 101),
                                   pitting=PittingState.pristine(GEOMETRY, 101))):
        assert list(update.parameters) == K_KEYS + E_KEYS
        assert [update.parameters[k] for k in K_KEYS] == list(HEALTHY_K_PAIR)
        assert [update.parameters[k] for k in E_KEYS] == [0.0] * 11
        assert update.truncation_error == {"k_pair": 0.0, "profile_deviation": 0.0}


def test_piecewise_linear_field_on_the_nodes_is_exact():
    node_depth = 1e-6 * np.array([40, 30, 22, 15, 8, 2, 6, 10, 14, 18, 20], dtype=float)
    nodes, err = project_on_nodes(XI, np.interp(XI, NODES, node_depth), 11)
    assert np.allclose(nodes, node_depth, rtol=0, atol=1e-15) and err < 1e-15


def test_wear_maps_to_the_separation_of_both_worn_flanks():
    """profile_deviation is the worn pair's least separation (conjugate action of both flanks),
    fitted on the nodes: a gentle wear field is seen as is, pinion and gear depths add."""
    from twin.degradation import wear_deviation
    pinion = 1e-6 * (20 + 10 * np.cos(np.pi * XI))
    gear = 1e-6 * (5 + 5 * XI)
    wear = WearState(1e5, XI, pinion, GEOMETRY, gear)
    xi, sep = wear_deviation(GEOMETRY, wear)
    assert np.allclose(sep, np.interp(xi, XI, pinion + gear), rtol=0, atol=0.3e-6)
    update = mesh_parameters(GEOMETRY, wear=wear)
    nodes = np.array([update.parameters[k] for k in E_KEYS])
    assert np.allclose(nodes, project_on_nodes(xi, sep, 11)[0], rtol=0, atol=1e-15)
    assert [update.parameters[k] for k in K_KEYS] == list(HEALTHY_K_PAIR)


def test_uniform_pitting_scales_the_stiffness():
    pitting = PittingState(1e6, XI, np.full(101, 0.1), GEOMETRY)
    update = mesh_parameters(GEOMETRY, pitting=pitting)
    assert np.allclose([update.parameters[k] for k in K_KEYS], 0.9 * np.array(HEALTHY_K_PAIR), rtol=1e-12)
    assert update.truncation_error["k_pair"] < 1e-12


def test_truncation_error_of_a_field_between_the_nodes():
    # A wear bump narrower than a node interval: the nodes cannot follow it.
    depth = 10e-6 * np.exp(-((XI - 0.23) / 0.02) ** 2)
    nodes, err = project_on_nodes(XI, depth, 11)
    assert nodes.min() >= 0
    assert err == pytest.approx(np.abs(np.interp(XI, NODES, nodes) - depth).max())
    assert 1e-6 < err < 10e-6
    # The same for the stiffness, relative to the local healthy value.
    density = 0.5 * (np.abs(XI - 0.45) < 0.05)
    update = mesh_parameters(GEOMETRY, pitting=PittingState(1.0, XI, density, GEOMETRY))
    k_nodes = np.array([update.parameters[k] for k in K_KEYS])
    k_field = np.interp(XI, NODES, HEALTHY_K_PAIR) * (1 - density)
    expected = np.abs(np.interp(XI, NODES, k_nodes) - k_field) / np.interp(XI, NODES, HEALTHY_K_PAIR)
    assert update.truncation_error["k_pair"] == pytest.approx(expected.max())
    assert 0 < update.truncation_error["k_pair"] < 0.5


def test_custom_healthy_stiffness_and_node_count():
    healthy = np.linspace(1e8, 2e8, 6)
    update = mesh_parameters(GEOMETRY, k_pair_healthy=healthy, n_nodes=6)
    expected = [f"k_pair[{i}]" for i in range(1, 7)] + [f"profile_deviation[{i}]" for i in range(1, 7)]
    assert list(update.parameters) == expected
    assert [update.parameters[f"k_pair[{i}]"] for i in range(1, 7)] == list(healthy)


def test_pitting_reduces_the_load_share_through_the_static_load():
    density = np.where(XI < 0.3, 0.5, 0.0)
    update = mesh_parameters(GEOMETRY, pitting=PittingState(1e6, XI, density, GEOMETRY))
    healthy = MeshLoad.static(GEOMETRY, 7.3)
    pitted = MeshLoad.static(GEOMETRY, 7.3, parameters=update.parameters)
    assert pitted.force_at(0.1) < 0.8 * healthy.force_at(0.1)
    assert pitted.force_at(0.5) == pytest.approx(healthy.force_at(0.5))   # single-pair zone: all of it anyway


def test_project_wear_is_the_node_fit_and_keeps_the_volume():
    model = ArchardWear()
    wear = model.advance(model.initial_state(GEOMETRY), MeshLoad.static(GEOMETRY, 1.83), 1e5, 62.8)
    projected = project_wear(wear)
    nodes, _ = project_on_nodes(wear.xi, wear.depth, 11)
    assert np.allclose(projected.depth, np.interp(XI, NODES, nodes), rtol=0, atol=1e-18)
    assert projected.cycles == wear.cycles and projected.geometry == wear.geometry
    assert projected.mean_depth == pytest.approx(wear.mean_depth, rel=0.02)


def test_invalid_inputs_raise_typed_errors_naming_the_value():
    with pytest.raises(ParameterError, match="got 10"):
        mesh_parameters(GEOMETRY, k_pair_healthy=HEALTHY_K_PAIR[:10])
    with pytest.raises(ParameterError, match="-1.0"):
        mesh_parameters(GEOMETRY, k_pair_healthy=(-1.0,) + HEALTHY_K_PAIR[1:])
    with pytest.raises(ParameterError, match="n_nodes"):
        mesh_parameters(GEOMETRY, n_nodes=1)
    other = GearPair(face_width=0.03)
    with pytest.raises(ParameterError, match="face_width=0.03"):
        mesh_parameters(GEOMETRY, wear=WearState.pristine(other, 11))
    with pytest.raises(ParameterError, match="PittingState"):
        mesh_parameters(GEOMETRY, pitting=WearState.pristine(GEOMETRY, 11))
    with pytest.raises(ParameterError, match="too coarse"):
        project_on_nodes(np.linspace(0, 1, 5), np.ones(5), 11)


def test_at_load_a_ridge_narrower_than_the_contact_is_bridged():
    """With the transmitted force the flanks are seen through the Hertz contact width: a pinion tip
    left proud over one grid step (narrower than the contact) no longer makes a step of the
    separation at the end of the path; a gentle field is seen as without the force."""
    from twin.degradation import wear_deviation
    xi = np.linspace(0, 1, 401)
    depth = np.full(xi.size, 30e-6)
    depth[-1] = 10e-6                                     # the last 13 um of the pinion tip stand proud
    wear = WearState(1e5, xi, depth, GEOMETRY, np.zeros(xi.size))
    force = 2000.0                                        # b about 80 um at the tip
    _, rigid = wear_deviation(GEOMETRY, wear)
    _, loaded = wear_deviation(GEOMETRY, wear, force=force)
    assert rigid[-2] - rigid[-1] > 15e-6
    assert loaded[-2] - loaded[-1] < 0.2 * (rigid[-2] - rigid[-1])
    gentle = WearState(1e5, XI, 1e-6 * (20 + 10 * np.cos(np.pi * XI)), GEOMETRY, 1e-6 * (5 + 5 * XI))
    np.testing.assert_allclose(wear_deviation(GEOMETRY, gentle, force=force)[1], wear_deviation(GEOMETRY, gentle)[1],
                               rtol=0, atol=0.2e-6)
    with pytest.raises(ParameterError, match="force"):
        mesh_parameters(GEOMETRY, wear=wear, force=-1.0)


def test_contact_pair_stiffness_is_the_ltca_secant_at_the_load():
    """At 20 N.m the LTCA's pair gives way more than the load-independent potential-energy
    stiffness says (the half-plane contact's compliance grows as the load falls), and less
    at a larger load; the pair law with it gives the LTCA's approach of a lone pair."""
    from twin.degradation.ltca import contact_for
    from twin.degradation.mapping import contact_k_pair
    from twin.degradation.stiffness import k_pair_nodes
    force = 20.0 / GEOMETRY.base_radius_gear
    k = contact_k_pair(GEOMETRY, force, 11)
    assert np.all(k < np.array(k_pair_nodes(GEOMETRY, 11)))
    assert np.all(contact_k_pair(GEOMETRY, 10 * force, 11) > k)
    # a lone pair at mid path carries the whole force in the healthy load sharing
    sol = contact_for(GEOMETRY).solve([0.5], force)
    assert force / k[5] == pytest.approx(sol.approach - sol.pairs[0].separation, rel=0.03)
    with pytest.raises(ParameterError, match="force"):
        contact_k_pair(GEOMETRY, -1.0, 11)
