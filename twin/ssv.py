"""SSP 1.0 parameter values (``.ssv``): typed parameter sets with units, read and written.

A :class:`ParameterSet` holds ``Real`` (with an optional unit), ``Integer``, ``Boolean``,
``String`` and ``Enumeration`` entries and the unit definitions of its file.  Applying it to an
FMU (:func:`resolve`) converts every ``Real`` given in another unit into the unit of the FMU
variable, by the ``BaseUnit`` definitions of both files:

- a unit must be defined in the ``Units`` element of the file that uses it (SSP 1.0); one that
  is not is refused by name, unless it is exactly the unit of the FMU variable;
- units of different dimensions are refused, naming both;
- non-finite values (``INF``, ``NaN``, which ``xs:double`` allows) are refused on reading and on
  writing.

The SSP standard lets a tool ignore parameters that match no variable; here they are an error
naming them, so that a misspelt parameter of a calibrated set never goes unnoticed.

    >>> from twin.ssv import write_ssv, read_ssv
    >>> write_ssv({"kt12": 1500.0, "n": 3, "on": True}, "p.ssv", units={"kt12": "N.m/rad"})  # doctest: +SKIP
"""
from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

from twin.errors import ParameterError, SSPError, UnitError
from twin.units import Unit, convert, parse_unit

NS_SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
NS_SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
NS_SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
NS_SSM = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")
_INT32 = (-2**31, 2**31 - 1)
#: FMI 3.0 type names -> the SSP type a value of that variable has
_FMI_TYPE = {"Float64": "Real", "Float32": "Real", "Int8": "Integer", "UInt8": "Integer", "Int16": "Integer",
             "UInt16": "Integer", "Int32": "Integer", "UInt32": "Integer", "Int64": "Integer",
             "UInt64": "Integer"}


@dataclass(frozen=True)
class ParameterValue:
    """One entry of a parameter set: its name, SSP type, value and (Real only) unit."""

    name: str
    type: str
    value: Any
    unit: str = ""


@dataclass(frozen=True)
class ParameterSet:
    """A parsed ``ssv:ParameterSet``: entries in file order and the file's unit definitions."""

    name: str
    values: tuple[ParameterValue, ...]
    units: Mapping[str, Unit] = field(default_factory=dict)
    source: str = "<parameter set>"

    def as_dict(self) -> dict[str, Any]:
        """name -> value, as given in the file (no unit conversion)."""
        return {v.name: v.value for v in self.values}


def _q(ns: str, tag: str) -> str:
    return f"{{{ns}}}{tag}"


def read_units(parent: ET.Element | None, where: str) -> dict[str, Unit]:
    """The ``ssc:Unit`` definitions below a ``Units`` element (``{}`` when there is none)."""
    out: dict[str, Unit] = {}
    if parent is None:
        return out
    for u in parent.findall(_q(NS_SSC, "Unit")):
        name = u.get("name")
        base = u.find(_q(NS_SSC, "BaseUnit"))
        if not name or base is None:
            raise SSPError(f"{where}: a Unit needs a name and a BaseUnit")
        try:
            out[name] = Unit.from_base_unit(name, dict(base.attrib))
        except UnitError as exc:
            raise SSPError(f"{where}: {exc}") from None
    return out


def _parse_value(kind: str, text: str | None, name: str, where: str):
    if text is None:
        raise SSPError(f"{where}: parameter {name!r}: ssv:{kind} has no value")
    text = text.strip()
    try:
        if kind == "Real":
            v = float(text.replace("INF", "inf"))
            if not math.isfinite(v):
                raise SSPError(f"{where}: parameter {name!r}: value {text!r} is not finite")
            return v
        if kind == "Integer":
            v = int(text)
            if not _INT32[0] <= v <= _INT32[1]:
                raise ValueError("outside the 32-bit range of xs:int")
            return v
        if kind == "Boolean":
            if text in ("true", "1"):
                return True
            if text in ("false", "0"):
                return False
            raise ValueError("not an xs:boolean")
    except ValueError as exc:
        raise SSPError(f"{where}: parameter {name!r}: {text!r} is not a valid {kind} ({exc})") from None
    return text


def parse_parameter_set(root: ET.Element, where: str) -> ParameterSet:
    """A :class:`ParameterSet` from an ``ssv:ParameterSet`` element (a file's root or inline in an SSD)."""
    if root.tag != _q(NS_SSV, "ParameterSet"):
        raise SSPError(f"{where}: expected an ssv:ParameterSet element ({NS_SSV}), found {root.tag!r}")
    params = root.find(_q(NS_SSV, "Parameters"))
    if params is None:
        raise SSPError(f"{where}: ssv:ParameterSet has no ssv:Parameters element")
    values: list[ParameterValue] = []
    seen: set[str] = set()
    for p in params.findall(_q(NS_SSV, "Parameter")):
        name = p.get("name")
        if not name:
            raise SSPError(f"{where}: an ssv:Parameter has no name")
        if name in seen:
            raise SSPError(f"{where}: parameter {name!r} is given twice")
        seen.add(name)
        typed = [c for c in p if c.tag.startswith(f"{{{NS_SSV}}}") and c.tag != _q(NS_SSV, "Annotations")]
        if len(typed) != 1:
            raise SSPError(f"{where}: parameter {name!r} needs exactly one typed value, found {len(typed)}")
        kind = typed[0].tag.split("}", 1)[1]
        if kind not in TYPES:
            raise SSPError(f"{where}: parameter {name!r}: ssv:{kind} values are not supported "
                           f"(supported: {', '.join(TYPES)})")
        value = _parse_value(kind, typed[0].get("value"), name, where)
        values.append(ParameterValue(name, kind, value, typed[0].get("unit", "") if kind == "Real" else ""))
    units = read_units(root.find(_q(NS_SSV, "Units")), where)
    return ParameterSet(root.get("name", ""), tuple(values), units, where)


def read_ssv(source: str | os.PathLike[str] | bytes, *, where: str | None = None) -> ParameterSet:
    """Read an ``.ssv`` file (a path, or its bytes with ``where`` naming it in messages)."""
    if isinstance(source, bytes):
        where = where or "<ssv>"
        data = source
    else:
        path = Path(source)
        where = where or str(path)
        if not path.is_file():
            raise SSPError(f"{where}: parameter file does not exist")
        data = path.read_bytes()
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise SSPError(f"{where}: not valid XML: {exc}") from None
    return parse_parameter_set(root, where)


# ---- applying a parameter set to an FMU ------------------------------------------------------------
def _unit_of(name: str, defs: Mapping[str, Unit]) -> Unit | None:
    if name in defs:
        return defs[name]
    try:
        return parse_unit(name)
    except UnitError:
        return None


def resolve(pset: ParameterSet, variables: Mapping[str, Any], fmu_units: Mapping[str, Unit] | None = None, *,
            extra_units: Mapping[str, Unit] | None = None, names: Mapping[str, str] | None = None) -> dict[str, Any]:
    """Values to set on an FMU, converted to the units of its variables.

    Parameters
    ----------
    pset : the parameter set.
    variables : FMU variable name -> object with ``type``, ``unit``, ``causality``, ``variability``
        (:class:`twin.fmu.Variable`).
    fmu_units : the FMU's unit definitions (``BaseUnit``); a unit missing there is parsed from its name.
    extra_units : further unit definitions in scope (the SSD's ``Units``), after the file's own.
    names : entry name -> FMU variable name (prefixes and parameter mappings already applied);
        default: the entry names themselves.

    Raises :class:`~twin.errors.SSPError` naming every entry that matches no variable, a
    variable that cannot be set, a type mismatch, and a unit that is undefined or of another
    dimension.
    """
    fmu_units = fmu_units or {}
    scope = {**(extra_units or {}), **pset.units}
    out: dict[str, Any] = {}
    unknown = []
    for entry in pset.values:
        target = (names or {}).get(entry.name, entry.name)
        var = variables.get(target)
        if var is None:
            unknown.append(entry.name if target == entry.name else f"{entry.name} (as {target})")
            continue
        out[target] = _value_for(entry, target, var, fmu_units, scope, pset.source)
    if unknown:
        shown = ", ".join(repr(n) for n in unknown[:10]) + (f" and {len(unknown) - 10} more" if len(unknown) > 10 else "")
        raise SSPError(f"{pset.source}: {len(unknown)} parameter(s) match no variable of the FMU: {shown}")
    return out


def _a(word: str) -> str:
    return ("an " if word[:1] in "AEIOU" else "a ") + word


def _value_for(entry: ParameterValue, target: str, var, fmu_units, scope, where: str):
    if var.causality not in ("parameter", "input") or var.variability == "constant":
        raise SSPError(f"{where}: {target!r} has causality {var.causality!r} and variability "
                       f"{var.variability!r}; only parameters and inputs can be set")
    vtype = _FMI_TYPE.get(var.type, var.type)
    if entry.type == "Real" or (entry.type == "Integer" and vtype == "Real"):
        if vtype != "Real":
            raise SSPError(f"{where}: parameter {entry.name!r} is a Real but {target!r} is {_a(var.type)}")
        value = float(entry.value)
        if not entry.unit:
            return value
        target_unit = var.unit or ""
        if entry.unit == target_unit or (entry.unit == "1" and not target_unit):
            return value
        source = scope.get(entry.unit)
        if source is None:
            raise SSPError(f"{where}: parameter {entry.name!r}: unit {entry.unit!r} is not defined in the "
                           f"Units element of the file (SSP 1.0); define it with its BaseUnit, or give the "
                           f"value in {target_unit or 'the dimensionless unit'!r}")
        dest = _unit_of(target_unit, fmu_units) if target_unit else Unit("")
        if dest is None:
            raise SSPError(f"{where}: parameter {entry.name!r}: the FMU's unit {target_unit!r} of {target!r} "
                           f"has no definition, so {entry.unit!r} cannot be converted to it")
        try:
            converted = convert(value, source, dest)
        except UnitError as exc:
            raise SSPError(f"{where}: parameter {entry.name!r}: {exc}") from None
        if not math.isfinite(converted):
            raise SSPError(f"{where}: parameter {entry.name!r}: {value!r} {entry.unit} is not finite in {target_unit}")
        return converted
    if vtype == "Enumeration" and entry.type in ("Enumeration", "Integer"):
        pass          # an item by name (ssv:Enumeration) or by its value (ssv:Integer, as some tools write it)
    elif entry.type != vtype:
        raise SSPError(f"{where}: parameter {entry.name!r} is {_a(entry.type)} but {target!r} is {_a(var.type)}")
    coerce = getattr(var, "coerce", None)
    if coerce is None:
        return entry.value
    try:          # integer ranges (FMI 3.0 Int8 ... UInt64) and enumeration items, as the FMU takes them
        return coerce(entry.value)
    except ParameterError as exc:
        raise SSPError(f"{where}: parameter {entry.name!r}: {exc}") from None


# ---- writing --------------------------------------------------------------------------------------
def utc_now() -> str:
    """The current time as an ``xs:dateTime`` in UTC (``generationDateAndTime``)."""
    import datetime
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


class EnumerationItem(str):
    """An enumeration item by name, written as ``ssv:Enumeration`` (a plain str is an ``ssv:String``)."""


def _typed(name: str, value) -> tuple[str, str]:
    """(SSP type, xs value text) of a Python value; non-finite numbers and big integers refused."""
    if isinstance(value, EnumerationItem):
        return "Enumeration", str(value)
    if isinstance(value, bool):
        return "Boolean", "true" if value else "false"
    if isinstance(value, int):
        if not _INT32[0] <= value <= _INT32[1]:
            raise SSPError(f"parameter {name!r}: {value} is outside the 32-bit range of an SSP Integer")
        return "Integer", str(value)
    if isinstance(value, str):
        return "String", value
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise SSPError(f"parameter {name!r}: {value!r} is not a number, integer, boolean or string") from None
    if not math.isfinite(f):
        raise SSPError(f"parameter {name!r}: {value!r} is not finite; SSV values must be finite numbers")
    return "Real", repr(f)


def units_xml(names, fmu_units: Mapping[str, Unit] | None, prefix: str, indent: str) -> str:
    """``<{prefix}:Units>`` with one ``ssc:Unit`` (and its BaseUnit) per unit name."""
    names = sorted(set(n for n in names if n))
    if not names:
        return ""
    rows = []
    for n in names:
        unit = _unit_of(n, fmu_units or {})
        if unit is None:
            raise SSPError(f"unit {n!r} has no definition and cannot be parsed; it cannot be written to SSP")
        attrs = "".join(f" {k}={quoteattr(v)}" for k, v in unit.base_unit_attributes().items())
        rows.append(f'{indent}  <ssc:Unit name={quoteattr(n)}>\n{indent}    <ssc:BaseUnit{attrs}/>\n'
                    f'{indent}  </ssc:Unit>')
    return f"{indent}<{prefix}:Units>\n" + "\n".join(rows) + f"\n{indent}</{prefix}:Units>\n"


def parameter_set_xml(parameters: Mapping[str, Any], *, name: str, units: Mapping[str, str] | None = None,
                      fmu_units: Mapping[str, Unit] | None = None, description: str = "",
                      generated: str = "", indent: str = "") -> str:
    """The ``ssv:ParameterSet`` element (with namespace declarations) as text."""
    units = units or {}
    rows = []
    used = []
    for key, value in parameters.items():
        kind, text = _typed(key, value)
        unit = units.get(key, "") if kind == "Real" else ""
        attr = f" unit={quoteattr(unit)}" if unit else ""
        if unit:
            used.append(unit)
        rows.append(f"{indent}    <ssv:Parameter name={quoteattr(key)}><ssv:{kind} value={quoteattr(text)}{attr}/>"
                    "</ssv:Parameter>")
    meta = f" description={quoteattr(description)}" if description else ""
    meta += f' generationTool="gear-twin"' + (f' generationDateAndTime="{generated}"' if generated else "")
    body = "\n".join(rows)
    params = f"{indent}  <ssv:Parameters>\n{body}\n{indent}  </ssv:Parameters>\n" if rows else \
        f"{indent}  <ssv:Parameters/>\n"
    return (f'{indent}<ssv:ParameterSet xmlns:ssv="{NS_SSV}" xmlns:ssc="{NS_SSC}" version="1.0" '
            f"name={quoteattr(name)}{meta}>\n{params}"
            f"{units_xml(used, fmu_units, 'ssv', indent + '  ')}{indent}</ssv:ParameterSet>")


def write_ssv(parameters: Mapping[str, Any], path: str | os.PathLike[str], *, name: str = "parameters",
              units: Mapping[str, str] | None = None, fmu_units: Mapping[str, Unit] | None = None,
              description: str = "") -> Path:
    """Write an ``.ssv`` file atomically and return its path.

    ``parameters`` maps names to floats (``ssv:Real``), ints (``ssv:Integer``), bools
    (``ssv:Boolean``), strings (``ssv:String``) or :class:`EnumerationItem` names
    (``ssv:Enumeration``); ``units`` gives the unit of Real entries, each
    defined in the file's ``Units`` with its BaseUnit (from ``fmu_units`` or parsed from the
    name). A non-finite value is an :class:`~twin.errors.SSPError` and nothing is written.
    """
    from twin._atomic import atomic_path

    text = '<?xml version="1.0" encoding="UTF-8"?>\n' + parameter_set_xml(
        parameters, name=name, units=units, fmu_units=fmu_units, description=description,
        generated=utc_now()) + "\n"
    target = Path(path)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return target
