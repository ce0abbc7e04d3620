"""Units of measurement as FMI and SSP define them: a name, SI base-unit exponents, factor, offset.

A value ``v`` given in a unit is ``factor * v + offset`` in the SI base units whose exponents
the unit lists (``kg m s A K mol cd rad``, the ``BaseUnit`` of FMI 2.0/3.0 and SSP 1.0).  Two
units convert into each other exactly when their exponents agree.

Unit strings follow the Modelica unit syntax (Modelica Language Specification 3.5, section
19.1): factors joined by ``.``, an integer exponent glued to each factor (``m2``, ``s-1``), one
``/`` with a factor or a parenthesised expression after it, and SI prefixes (``kN.m/rad``,
``mm/s2``).  A chain of divisions (``m/s/s``) is read left to right.  Besides the SI base and
derived units, ``g``, ``min``, ``h``, ``d``, ``l``/``L``, ``bar``, ``deg``, ``rev``, ``rpm`` and
``degC`` are known.

    >>> parse_unit("kN.m/rad").factor, parse_unit("kN.m/rad").exponents
    (1000.0, (1, 2, -2, 0, 0, 0, 0, -1))
    >>> convert(1.875, "kN.m/rad", "N.m/rad")
    1875.0
    >>> derivative_unit("m/s")
    'm/s2'
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from twin.errors import UnitError

#: SI base units (and the radian, which FMI and SSP count as a base unit), in BaseUnit order.
BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

_DIMENSIONLESS = (0,) * len(BASE)


def _exp(**kw) -> tuple[int, ...]:
    return tuple(kw.get(b, 0) for b in BASE)


# symbol -> (exponents, factor to SI as mantissa and power of ten, offset); powers of ten are kept
# apart so that prefixed units get exact factors (g.cm2 -> 1e-7, not 1.0000000000000001e-07)
_SYMBOLS: dict[str, tuple[tuple[int, ...], float, int, float]] = {
    "1": (_DIMENSIONLESS, 1.0, 0, 0.0),
    "kg": (_exp(kg=1), 1.0, 0, 0.0),
    "g": (_exp(kg=1), 1.0, -3, 0.0),
    "m": (_exp(m=1), 1.0, 0, 0.0),
    "s": (_exp(s=1), 1.0, 0, 0.0),
    "A": (_exp(A=1), 1.0, 0, 0.0),
    "K": (_exp(K=1), 1.0, 0, 0.0),
    "mol": (_exp(mol=1), 1.0, 0, 0.0),
    "cd": (_exp(cd=1), 1.0, 0, 0.0),
    "rad": (_exp(rad=1), 1.0, 0, 0.0),
    "sr": (_exp(rad=2), 1.0, 0, 0.0),
    "Hz": (_exp(s=-1), 1.0, 0, 0.0),
    "N": (_exp(kg=1, m=1, s=-2), 1.0, 0, 0.0),
    "Pa": (_exp(kg=1, m=-1, s=-2), 1.0, 0, 0.0),
    "J": (_exp(kg=1, m=2, s=-2), 1.0, 0, 0.0),
    "W": (_exp(kg=1, m=2, s=-3), 1.0, 0, 0.0),
    "C": (_exp(A=1, s=1), 1.0, 0, 0.0),
    "V": (_exp(kg=1, m=2, s=-3, A=-1), 1.0, 0, 0.0),
    "F": (_exp(kg=-1, m=-2, s=4, A=2), 1.0, 0, 0.0),
    "Ohm": (_exp(kg=1, m=2, s=-3, A=-2), 1.0, 0, 0.0),
    "S": (_exp(kg=-1, m=-2, s=3, A=2), 1.0, 0, 0.0),
    "Wb": (_exp(kg=1, m=2, s=-2, A=-1), 1.0, 0, 0.0),
    "T": (_exp(kg=1, s=-2, A=-1), 1.0, 0, 0.0),
    "H": (_exp(kg=1, m=2, s=-2, A=-2), 1.0, 0, 0.0),
    "lm": (_exp(cd=1, rad=2), 1.0, 0, 0.0),
    "lx": (_exp(cd=1, rad=2, m=-2), 1.0, 0, 0.0),
    "Bq": (_exp(s=-1), 1.0, 0, 0.0),
    "Gy": (_exp(m=2, s=-2), 1.0, 0, 0.0),
    "Sv": (_exp(m=2, s=-2), 1.0, 0, 0.0),
    "kat": (_exp(mol=1, s=-1), 1.0, 0, 0.0),
    "degC": (_exp(K=1), 1.0, 0, 273.15),
    "min": (_exp(s=1), 60.0, 0, 0.0),
    "h": (_exp(s=1), 3600.0, 0, 0.0),
    "d": (_exp(s=1), 86400.0, 0, 0.0),
    "l": (_exp(m=3), 1.0, -3, 0.0),
    "L": (_exp(m=3), 1.0, -3, 0.0),
    "bar": (_exp(kg=1, m=-1, s=-2), 1.0, 5, 0.0),
    "deg": (_exp(rad=1), math.pi / 180.0, 0, 0.0),
    "rev": (_exp(rad=1), 2.0 * math.pi, 0, 0.0),
    "rpm": (_exp(rad=1, s=-1), 2.0 * math.pi / 60.0, 0, 0.0),
}

_PREFIXES = {"Y": 24, "Z": 21, "E": 18, "P": 15, "T": 12, "G": 9, "M": 6, "k": 3, "h": 2, "da": 1,
             "d": -1, "c": -2, "m": -3, "u": -6, "\u00b5": -6, "n": -9, "p": -12, "f": -15, "a": -18,
             "z": -21, "y": -24}

_TOKEN = re.compile(r"\s*(?:(?P<op>[./()])|(?P<factor>(?P<sym>[A-Za-z\u00b5]+|1)(?P<exp>[+-]?\d+)?))")


@dataclass(frozen=True)
class Unit:
    """A unit: its name, SI base-unit exponents (order :data:`BASE`), factor and offset.

    A value ``v`` in this unit is ``factor * v + offset`` in SI base units.
    """

    name: str
    exponents: tuple[int, ...] = _DIMENSIONLESS
    factor: float = 1.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        if len(self.exponents) != len(BASE):
            raise UnitError(f"unit {self.name!r}: {len(self.exponents)} exponents, expected {len(BASE)}")
        if not (math.isfinite(self.factor) and self.factor != 0.0 and math.isfinite(self.offset)):
            raise UnitError(f"unit {self.name!r}: factor must be finite and non-zero and offset finite, "
                            f"got factor={self.factor!r}, offset={self.offset!r}")

    @property
    def dimension(self) -> str:
        """The exponents written out, e.g. ``kg.m2.s-2.rad-1`` (``1`` when dimensionless)."""
        parts = [b if e == 1 else f"{b}{e}" for b, e in zip(BASE, self.exponents) if e]
        return ".".join(parts) or "1"

    def base_unit_attributes(self) -> dict[str, str]:
        """XML attributes of the ``BaseUnit`` element (FMI 2.0/3.0, SSP 1.0): non-default ones only."""
        attrs = {b: str(e) for b, e in zip(BASE, self.exponents) if e}
        if self.factor != 1.0:
            attrs["factor"] = repr(float(self.factor))
        if self.offset != 0.0:
            attrs["offset"] = repr(float(self.offset))
        return attrs

    @classmethod
    def from_base_unit(cls, name: str, attrs: dict[str, str]) -> "Unit":
        """The unit a ``BaseUnit`` element defines (attributes as strings, defaults as in the schemas)."""
        try:
            exps = tuple(int(attrs.get(b, "0")) for b in BASE)
            factor = float(attrs.get("factor", "1"))
            offset = float(attrs.get("offset", "0"))
        except ValueError as exc:
            raise UnitError(f"unit {name!r}: bad BaseUnit attribute ({exc})") from None
        return cls(name, exps, factor, offset)

    def to_si(self, value: float) -> float:
        return self.factor * value + self.offset

    def from_si(self, value: float) -> float:
        return (value - self.offset) / self.factor


def _factors(text: str) -> list[tuple[str, int]]:
    """The unit string as an ordered list of (operand, exponent), divisions folded in."""
    tokens = []
    pos = 0
    s = text.strip()
    while pos < len(s):
        m = _TOKEN.match(s, pos)
        if not m or m.end() == pos:
            raise UnitError(f"unit {text!r}: cannot read {s[pos:]!r} (Modelica unit syntax, e.g. 'N.m/rad', 'm/s2')")
        tokens.append(("op", m.group("op")) if m.group("op") else
                      ("f", (m.group("sym"), int(m.group("exp") or 1))))
        pos = m.end()
    i = 0

    def expression() -> list[tuple[str, int]]:
        nonlocal i
        out = product()
        while i < len(tokens) and tokens[i] == ("op", "/"):
            i += 1
            out += [(o, -e) for o, e in operand()]
        return out

    def product() -> list[tuple[str, int]]:
        nonlocal i
        out = operand()
        while i < len(tokens) and tokens[i] == ("op", "."):
            i += 1
            out += operand()
        return out

    def operand() -> list[tuple[str, int]]:
        nonlocal i
        if i >= len(tokens):
            raise UnitError(f"unit {text!r} ends early")
        kind, val = tokens[i]
        if kind == "f":
            i += 1
            return [val]
        if val == "(":
            i += 1
            inner = expression()
            if i >= len(tokens) or tokens[i] != ("op", ")"):
                raise UnitError(f"unit {text!r}: missing ')'")
            i += 1
            return inner
        raise UnitError(f"unit {text!r}: unexpected {val!r}")

    if not tokens:
        return []
    out = expression()
    if i != len(tokens):
        raise UnitError(f"unit {text!r}: unexpected {tokens[i][1]!r}")
    return out


def _operand(op: str, text: str) -> tuple[tuple[int, ...], float, int, float]:
    if op in _SYMBOLS:
        return _SYMBOLS[op]
    for pre in sorted(_PREFIXES, key=len, reverse=True):
        if op.startswith(pre) and op[len(pre):] in _SYMBOLS and op[len(pre):] not in ("1", "kg"):
            exps, mantissa, p10, offset = _SYMBOLS[op[len(pre):]]
            if offset:
                break
            return exps, mantissa, p10 + _PREFIXES[pre], 0.0
    raise UnitError(f"unit {text!r}: unknown unit symbol {op!r}")


def parse_unit(text: str) -> Unit:
    """The :class:`Unit` a Modelica unit string denotes (``''`` and ``'1'`` are dimensionless).

    Raises :class:`~twin.errors.UnitError` naming the string when it cannot be read.
    """
    factors = _factors(text or "")
    exps = [0] * len(BASE)
    mantissa, p10 = 1.0, 0
    offset = 0.0
    for op, e in factors:
        oe, om, op10, oo = _operand(op, text)
        for k in range(len(BASE)):
            exps[k] += oe[k] * e
        mantissa *= om ** e
        p10 += op10 * e
        if oo:
            if len(factors) != 1 or e != 1:
                # a temperature inside a product or a power is a difference: no offset
                continue
            offset = oo
    factor = mantissa * 10.0 ** p10 if p10 >= 0 else mantissa / 10.0 ** -p10
    return Unit(text or "", tuple(exps), factor, offset)


def canonical_name(text: str) -> str:
    """One spelling per unit: equal operands merged, positive exponents before the ``/``.

    ``m/s/s`` and ``m.s-2`` become ``m/s2``; a well-formed name such as ``N.m.s/rad`` is returned
    unchanged.  The unit is not otherwise rewritten (``Hz`` stays ``Hz``).
    """
    merged: dict[str, int] = {}
    for op, e in _factors(text or ""):
        if op != "1":
            merged[op] = merged.get(op, 0) + e
    return _render(merged)


def _render(merged: dict[str, int]) -> str:
    num = [op if e == 1 else f"{op}{e}" for op, e in merged.items() if e > 0]
    den = [op if e == -1 else f"{op}{-e}" for op, e in merged.items() if e < 0]
    top = ".".join(num) or "1"
    if not den:
        return top if num else ""
    bottom = den[0] if len(den) == 1 else "(" + ".".join(den) + ")"
    return f"{top}/{bottom}"


def derivative_unit(text: str) -> str:
    """Unit of the time derivative of a quantity in unit ``text``: ``m`` -> ``m/s``, ``m/s`` -> ``m/s2``."""
    merged: dict[str, int] = {}
    for op, e in _factors(text or ""):
        if op != "1":
            merged[op] = merged.get(op, 0) + e
    merged["s"] = merged.get("s", 0) - 1
    return _render(merged)


def as_unit(unit: Unit | str) -> Unit:
    return unit if isinstance(unit, Unit) else parse_unit(unit)


def convert(value: float, source: Unit | str, target: Unit | str) -> float:
    """``value`` given in ``source`` expressed in ``target``.

    Raises :class:`~twin.errors.UnitError` naming both units when their dimensions differ.
    """
    src, dst = as_unit(source), as_unit(target)
    if src.exponents != dst.exponents:
        raise UnitError(f"cannot convert {src.name or '1'!r} ({src.dimension}) to {dst.name or '1'!r} "
                        f"({dst.dimension}): the dimensions differ")
    if src.factor == dst.factor and src.offset == dst.offset:
        return float(value)
    return float(dst.from_si(src.to_si(float(value))))
