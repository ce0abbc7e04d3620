"""twin.units: Modelica unit strings, their SI base units, conversion and one spelling per unit."""
from __future__ import annotations

import math

import pytest

from twin.errors import UnitError
from twin.units import Unit, canonical_name, convert, derivative_unit, parse_unit


@pytest.mark.parametrize("text, exponents, factor", [
    ("N.m/rad", dict(kg=1, m=2, s=-2, rad=-1), 1.0),
    ("kN.m/rad", dict(kg=1, m=2, s=-2, rad=-1), 1e3),
    ("N.m.s/rad", dict(kg=1, m=2, s=-1, rad=-1), 1.0),
    ("kg.m2", dict(kg=1, m=2), 1.0),
    ("g.cm2", dict(kg=1, m=2), 1e-7),
    ("m/s2", dict(m=1, s=-2), 1.0),
    ("m/s/s", dict(m=1, s=-2), 1.0),
    ("mm", dict(m=1), 1e-3),
    ("ms-1", dict(s=-1), 1e3),          # the prefix binds to the symbol: (ms)^-1
    ("Hz", dict(s=-1), 1.0),
    ("1/s", dict(s=-1), 1.0),
    ("rpm", dict(rad=1, s=-1), 2 * math.pi / 60),
    ("deg", dict(rad=1), math.pi / 180),
    ("(kg.m)/s2", dict(kg=1, m=1, s=-2), 1.0),
    ("", {}, 1.0),
    ("1", {}, 1.0),
])
def test_parse_unit(text, exponents, factor):
    u = parse_unit(text)
    assert u.exponents == tuple(exponents.get(b, 0) for b in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"))
    assert u.factor == pytest.approx(factor, rel=1e-15) and u.offset == 0.0


def test_conversion_by_base_units():
    assert convert(1.875, "kN.m/rad", "N.m/rad") == 1875.0
    assert convert(3000.0, "rpm", "rad/s") == pytest.approx(100 * math.pi, rel=1e-15)
    assert convert(20.0, "degC", "K") == pytest.approx(293.15)
    assert convert(1.0, Unit("my_torque", (1, 2, -2, 0, 0, 0, 0, 0), 4.448), "N.m") == 4.448
    with pytest.raises(UnitError, match=r"cannot convert 'N' \(kg\.m\.s-2\) to 'm' \(m\): the dimensions differ"):
        convert(1.0, "N", "m")


@pytest.mark.parametrize("bad, message", [
    ("furlong", "unknown unit symbol 'furlong'"),
    ("m/(s", r"missing '\)'"),
    ("N..m", "unexpected"),
    ("m^2", "cannot read"),
])
def test_unreadable_units_are_named(bad, message):
    with pytest.raises(UnitError, match=message):
        parse_unit(bad)


def test_one_spelling_per_unit():
    assert canonical_name("m/s/s") == canonical_name("m.s-2") == canonical_name("m/s2") == "m/s2"
    assert canonical_name("N.m.s/rad") == "N.m.s/rad"
    assert canonical_name("Hz") == "Hz"
    assert derivative_unit("m") == "m/s" and derivative_unit("m/s") == "m/s2"
    assert derivative_unit("rad/s") == "rad/s2" and derivative_unit("N.m.s/rad") == "N.m/rad"
    assert derivative_unit("") == "1/s"


def test_base_unit_attributes_round_trip():
    for text in ("kN.m/rad", "degC", "mm/s2", "rpm"):
        u = parse_unit(text)
        back = Unit.from_base_unit(text, u.base_unit_attributes())
        assert back == u
    with pytest.raises(UnitError, match="factor must be finite and non-zero"):
        Unit("zero", factor=0.0)
