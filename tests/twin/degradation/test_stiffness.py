"""Tooth form and potential-energy mesh stiffness against closed forms, symmetry and ISO 6336."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.geometry import GearPair, inverse_involute, involute
from twin.degradation.stiffness import (iso_single_stiffness, k_pair_nodes, mesh_stiffness_curve,
                                        pair_compliance, pair_stiffness, stiffness_report)
from twin.degradation.tooth import ToothForm
from twin.errors import ParameterError

ALPHA = math.radians(20.0)


@pytest.mark.parametrize("z, x", [(18, 0.0), (19, 0.3), (35, -0.2), (52, 0.0), (12, 0.5)])
def test_generated_tooth_has_the_standard_thicknesses(z, x):
    t = ToothForm(z, 3e-3, ALPHA, x)
    r = t.pitch_radius
    # tooth thickness on the reference circle: s = m (pi/2 + 2 x tan alpha)
    assert 2 * r * float(t.half_angle(r)) == pytest.approx(3e-3 * (math.pi / 2 + 2 * x * math.tan(ALPHA)), rel=1e-9)
    assert t.root_radius == pytest.approx(r - (1.25 - x) * 3e-3)
    # the fillet meets the involute at the form radius without a step, and the tooth narrows
    # towards its tip
    rf = t.form_radius
    assert abs(float(t.half_angle(rf * (1 - 1e-4))) - float(t.half_angle(rf * (1 + 1e-4)))) < 2e-3
    rr, y, h = t.section(300)
    assert np.all(np.diff(y) > 0) and h[-1] < h[0]
    with pytest.raises(ParameterError, match="outside the tooth"):
        t.half_angle(t.tip_radius * 1.01)


def test_inverse_involute_and_profile_shift_geometry():
    for a in (0.2, 0.35, 0.5):
        assert inverse_involute(float(involute(a))) == pytest.approx(a, rel=1e-13)
    g = GearPair(z1=18, z2=35, profile_shift_pinion=0.4, profile_shift_gear=0.1)
    aw = g.working_pressure_angle
    assert involute(aw) == pytest.approx(involute(ALPHA) + 2 * math.tan(ALPHA) * 0.5 / 53, rel=1e-12)
    assert g.centre_distance == pytest.approx(1.5e-3 * 53 * math.cos(ALPHA) / math.cos(aw))
    # the operating pitch point divides the centre distance in the ratio of the tooth numbers
    assert g.rho1(g.pitch_point_xi) / g.line_of_action_length == pytest.approx(18 / 53)
    assert GearPair().working_pressure_angle == ALPHA


def test_compliances_scale_with_face_width_and_modulus():
    xi = np.linspace(0, 1, 9)
    base = pair_compliance(GearPair(), xi)
    wide = pair_compliance(GearPair(face_width=0.04), xi)
    stiff = pair_compliance(GearPair(youngs_modulus=412e9), xi)
    np.testing.assert_allclose(wide.total, 0.5 * base.total, rtol=1e-12)
    np.testing.assert_allclose(stiff.total, 0.5 * base.total, rtol=1e-12)
    # Hertz: 4 (1 - nu^2) / (pi E L)
    assert base.hertz[0] == pytest.approx(4 * 0.91 / (math.pi * 206e9 * 0.02))


def test_equal_gears_give_a_symmetric_stiffness_along_the_path():
    g = GearPair(z1=25, z2=25)
    xi = np.linspace(0, 1, 21)
    k = pair_stiffness(g, xi)
    np.testing.assert_allclose(k, k[::-1], rtol=1e-6)
    assert np.argmax(k) == 10
    # the pinion's bending compliance grows as the contact moves to its tip
    c = pair_compliance(g, xi)
    assert np.all(np.diff(c.pinion["bending"]) > 0) and np.all(np.diff(c.gear["bending"]) < 0)


@pytest.mark.parametrize("z1, z2", [(19, 52), (18, 35), (25, 61), (30, 30)])
def test_potential_energy_against_iso_6336(z1, z2):
    """The potential-energy single-pair stiffness lies between ISO's measured single stiffness
    c' b (with C_M = 0.8) and its theoretical c'_th b (without): 10-30 % above c' b."""
    rep = stiffness_report(GearPair(z1=z1, z2=z2))
    iso = rep.iso
    assert 0.10 < rep.single_difference < 0.30, rep.single_difference
    assert rep.k_pair_max < iso.single / 0.8 * 1.02
    assert 0.08 < rep.mesh_difference < 0.30, rep.mesh_difference


def test_iso_single_stiffness_worked_value():
    # 19/52, x = 0, ISO 53 rack: q' = 0.04723 + 0.15551/19 + 0.25791/52 = 0.060374 mm um / N,
    # c' = 0.8 x 0.975 / q' = 12.918 N/(mm um), times 20 mm
    iso = iso_single_stiffness(GearPair())
    assert iso.single == pytest.approx(0.8 * 0.975 / (0.04723 + 0.15551 / 19 + 0.25791 / 52) * 20 * 1e6, rel=1e-9)
    assert iso.mesh == pytest.approx(iso.single * (0.75 * GearPair().contact_ratio + 0.25))


def test_mesh_stiffness_alternates_between_one_and_two_pairs():
    g = GearPair()
    f, k = mesh_stiffness_curve(g, n=1000)
    single = (f > g.contact_ratio - 1 + 0.01) & (f < 0.99)
    double = f < g.contact_ratio - 1 - 0.01
    assert k[double].min() > 1.3 * k[single].max()
    nodes = k_pair_nodes(g, 11)
    assert len(nodes) == 11 and nodes[5] == pytest.approx(float(pair_stiffness(g, 0.5)))
    with pytest.raises(ParameterError, match="n_profile"):
        k_pair_nodes(g, 1)
