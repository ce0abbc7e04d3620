"""GearPair: FMU parameter names, contact ratio, kinematics along the path, Hertz line contact."""
from __future__ import annotations

import math

import numpy as np
import pytest

from twin.degradation.geometry import GearPair
from twin.errors import ParameterError, TwinError

ALPHA = math.radians(20.0)


def test_contact_ratio_matches_modelica_formula():
    g = GearPair()
    m, z1, z2, ha = 3e-3, 19, 52, 1.0
    rb1, rb2 = 0.5 * m * z1 * math.cos(ALPHA), 0.5 * m * z2 * math.cos(ALPHA)
    modelica = (math.sqrt((0.5 * m * z1 + ha * m) ** 2 - rb1 ** 2) + math.sqrt((0.5 * m * z2 + ha * m) ** 2 - rb2 ** 2)
                - 0.5 * m * (z1 + z2) * math.sin(ALPHA)) / (math.pi * m * math.cos(ALPHA))
    assert g.contact_ratio == pytest.approx(modelica, rel=1e-12)
    assert round(g.contact_ratio, 4) == 1.6526
    assert g.base_radius_pinion == pytest.approx(0.02678, abs=1e-5)
    assert g.base_radius_gear == pytest.approx(0.07330, abs=1e-5)
    assert g.path_of_contact_length == pytest.approx(g.contact_ratio * g.base_pitch)


def test_from_parameters_reads_fmu_names_and_ignores_others():
    g = GearPair.from_parameters({"z1": 19, "z2": 52.0, "module": 3e-3, "alpha": ALPHA, "face_width": 0.02,
                                  "addendum_coefficient": 1.0, "c_mesh": 1100.0, "k_pair[1]": 1.65e8})
    assert g == GearPair()
    assert isinstance(g.z2, int)
    wide = GearPair.from_parameters({"face_width": 0.03})
    assert wide.face_width == 0.03 and wide.z1 == 19


@pytest.mark.parametrize("name, value", [("z1", 4), ("z1", 18.5), ("z2", 3), ("module", -3e-3),
                                         ("module", float("nan")), ("face_width", 0.0), ("alpha", 1.2),
                                         ("poisson_ratio", 0.5), ("youngs_modulus", -1.0)])
def test_invalid_values_raise_parameter_error_naming_the_value(name, value):
    with pytest.raises(ParameterError, match=repr(value).replace("(", r"\(").replace(")", r"\)")) as info:
        GearPair.from_parameters({name: value})
    assert isinstance(info.value, TwinError)


def test_interference_is_rejected():
    with pytest.raises(ParameterError, match="interference"):
        GearPair(z1=8, z2=52)


def test_curvature_radii_and_pitch_point():
    g = GearPair()
    r1, r2 = 0.5 * 3e-3 * 19, 0.5 * 3e-3 * 52
    assert g.rho1(g.pitch_point_xi) == pytest.approx(r1 * math.sin(ALPHA))
    assert g.rho2(g.pitch_point_xi) == pytest.approx(r2 * math.sin(ALPHA))
    xi = np.linspace(0, 1, 7)
    assert np.allclose(g.rho1(xi) + g.rho2(xi), (r1 + r2) * math.sin(ALPHA))
    assert g.rho1(xi).shape == (7,)
    # The pinion tip: rho1 = sqrt(ra1^2 - rb1^2).
    assert g.rho1(1.0) == pytest.approx(math.sqrt((r1 + 3e-3) ** 2 - g.base_radius_pinion ** 2))
    with pytest.raises(ParameterError, match="1.2"):
        g.rho1(1.2)


def test_sliding_speed_zero_at_pitch_point_and_hand_values_at_ends():
    g = GearPair()
    omega1 = 100.0
    assert g.sliding_speed(g.pitch_point_xi, omega1) == pytest.approx(0.0, abs=1e-12)
    # Start of contact by hand: rho2 = sqrt(ra2^2 - rb2^2) = 34.478 mm, rho1 = a sin(alpha) - rho2 = 1.947 mm.
    rho2 = math.sqrt(0.081 ** 2 - (0.078 * math.cos(ALPHA)) ** 2)
    rho1 = 0.1065 * math.sin(ALPHA) - rho2
    expected = omega1 * rho1 - omega1 * 19 / 52 * rho2                      # -1.0650 m/s
    assert expected == pytest.approx(-1.0650, abs=1e-4)
    assert g.sliding_velocity(0.0, omega1) == pytest.approx(expected, rel=1e-9)
    assert g.sliding_speed(0.0, omega1) == pytest.approx(-expected, rel=1e-9)
    # End of contact: the pinion tip slides faster than the gear flank (positive).
    rho1 = math.sqrt(0.0315 ** 2 - (0.0285 * math.cos(ALPHA)) ** 2)
    expected = omega1 * rho1 - omega1 * 19 / 52 * (0.1065 * math.sin(ALPHA) - rho1)
    assert expected == pytest.approx(0.9334, abs=1e-4)
    assert g.sliding_velocity(1.0, omega1) == pytest.approx(expected, rel=1e-9)
    v1, v2 = g.rolling_speeds(np.array([0.0, 1.0]), omega1)
    assert np.allclose(np.abs(v1 - v2), g.sliding_speed(np.array([0.0, 1.0]), omega1))
    assert np.allclose(g.slide_to_roll_ratio([0.0, 1.0]), np.abs(v1 - v2) / v1)


def test_hertz_line_contact_hand_computed_at_pitch_point():
    g = GearPair()
    # F = 1000 N over 20 mm: w = 5e4 N/m.  R = 9.7476 * 26.6776 / 36.4252 mm = 7.1391 mm.
    # E* = 206e9 / (2 * 0.91) = 113.19 GPa.  b = sqrt(4 w R / (pi E*)) = 63.37 um.
    # Pmax = 2 w / (pi b) = 502.3 MPa.
    xi = g.pitch_point_xi
    assert g.equivalent_radius(xi) == pytest.approx(7.1391e-3, rel=1e-4)
    assert g.contact_modulus == pytest.approx(113.187e9, rel=1e-5)
    assert g.hertz_half_width(1000.0, xi) == pytest.approx(63.37e-6, rel=1e-3)
    assert g.hertz_max_pressure(1000.0, xi) == pytest.approx(502.3e6, rel=1e-3)
    b = g.hertz_half_width(1000.0, xi)
    assert g.hertz_max_pressure(1000.0, xi) == pytest.approx(2 * 5e4 / (math.pi * b), rel=1e-12)
    assert g.hertz_max_pressure(0.0, xi) == 0.0 and g.hertz_half_width(0.0, xi) == 0.0
    with pytest.raises(ParameterError, match="-5.0"):
        g.hertz_half_width(-5.0, xi)


def test_flank_position_round_trip():
    g = GearPair()
    xi = np.linspace(0, 1, 11)
    u = g.flank_position(xi)
    assert np.all(np.diff(u) > 0)
    assert np.allclose(g.xi_at_flank_position(u), xi)
    assert u[0] == pytest.approx(g.contact_start ** 2 / (2 * g.base_radius_pinion))
