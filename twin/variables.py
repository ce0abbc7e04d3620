"""FMI variables as ``twin`` sees them: type, causality, unit, and what a user may give as a value.

Every scalar type of FMI 2.0 (Real, Integer, Boolean, String, Enumeration) and FMI 3.0
(Float32, Float64, Int8 ... UInt64, Boolean, String, Enumeration) is read, written, set and
recorded.  FMI 3.0 ``Binary`` and ``Clock`` variables and array variables are refused by name.

A value for a variable may come from the command line (text), a scenario or a parameter file
(YAML/JSON numbers, booleans, strings) or Python; :meth:`Variable.coerce` turns it into the
variable's type or raises :class:`~twin.errors.ParameterError` naming the variable and the
value.  Enumerations take an item name (``fast``) or its integer value.

This module does not import fmpy: :func:`variables_from_description` reads the model
description object that :mod:`twin.fmu` got from fmpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from twin.errors import ParameterError

FLOAT_TYPES = {"Real": np.float64, "Float64": np.float64, "Float32": np.float32}
#: integer type -> (numpy dtype, smallest, largest)
INTEGER_TYPES = {
    "Integer": (np.int32, -2**31, 2**31 - 1),
    "Int8": (np.int8, -2**7, 2**7 - 1), "UInt8": (np.uint8, 0, 2**8 - 1),
    "Int16": (np.int16, -2**15, 2**15 - 1), "UInt16": (np.uint16, 0, 2**16 - 1),
    "Int32": (np.int32, -2**31, 2**31 - 1), "UInt32": (np.uint32, 0, 2**32 - 1),
    "Int64": (np.int64, -2**63, 2**63 - 1), "UInt64": (np.uint64, 0, 2**64 - 1),
}
UNSUPPORTED_TYPES = ("Binary", "Clock")
_TRUE = {"true", "1", "yes", "on"}
_FALSE = {"false", "0", "no", "off"}


@dataclass(frozen=True)
class Variable:
    """One variable of an FMU, as declared in its modelDescription.xml.

    ``type`` is the FMI type name (``Real`` ... ``Enumeration`` for FMI 2.0, ``Float64``,
    ``Int8`` ... for FMI 3.0).  ``unit`` is the variable's own unit or, failing that, its
    declared type's (``''`` when neither has one).  ``start`` is typed (float, int, bool or
    str; the integer value for an enumeration) or None.  ``items`` lists an enumeration's
    (name, value) pairs; ``shape`` is empty for a scalar; ``fmi_version`` is 2 or 3.
    """

    name: str
    value_reference: int
    type: str
    causality: str          # parameter, calculatedParameter, structuralParameter, input, output, local, independent
    variability: str        # constant, fixed, tunable, discrete, continuous
    unit: str
    description: str
    start: Any
    initial: str = ""
    declared_type: str = ""
    display_unit: str = ""
    quantity: str = ""
    items: tuple[tuple[str, int], ...] = ()
    shape: tuple[int, ...] = ()
    fmi_version: int = 2

    # -- kind ----------------------------------------------------------------------------
    @property
    def kind(self) -> str:
        """``float``, ``integer``, ``boolean``, ``string``, ``enumeration`` or ``unsupported``."""
        if self.shape or self.type in UNSUPPORTED_TYPES:
            return "unsupported"
        if self.type in FLOAT_TYPES:
            return "float"
        if self.type in INTEGER_TYPES:
            return "integer"
        return {"Boolean": "boolean", "String": "string", "Enumeration": "enumeration"}.get(self.type, "unsupported")

    @property
    def dtype(self) -> np.dtype:
        """numpy dtype of recorded samples (strings are ``object`` arrays of ``str``)."""
        kind = self.kind
        if kind == "float":
            return np.dtype(FLOAT_TYPES[self.type])
        if kind == "integer":
            return np.dtype(INTEGER_TYPES[self.type][0])
        if kind == "enumeration":      # an Integer in FMI 2.0, an Int64 in FMI 3.0
            return np.dtype(np.int32 if self.fmi_version == 2 else np.int64)
        if kind == "boolean":
            return np.dtype(np.bool_)
        return np.dtype(object)

    @property
    def unsupported_reason(self) -> str | None:
        """Why twin cannot read, set or record this variable, or None."""
        if self.shape:
            return (f"'{self.name}' is an array variable {self.type}{list(self.shape)}; "
                    "only scalar variables are supported")
        if self.kind == "unsupported":
            return f"'{self.name}' is a {self.type} variable; {self.type} variables are not supported"
        return None

    @property
    def is_parameter(self) -> bool:
        return self.causality in ("parameter", "structuralParameter")

    def read_only_reason(self, model: str) -> str | None:
        """Why this variable cannot be given a value (by a parameter, an input or an event), or None.

        The message says what the variable is and what can be done with it instead, in the
        command line's and the scenario file's terms."""
        what = f"'{self.name}' of {model}"
        cannot = "it cannot be set by --param, --input or a scenario"
        record = "--outputs (output.variables in a scenario) records it"
        if self.variability == "constant":
            value = f"value {self.format(self.start)}, " if self.start is not None else ""
            return (f"{what} is a constant ({value}fixed when the FMU was built); it is read-only: {cannot}; "
                    f"`twin info` lists it and {record}")
        if self.causality == "structuralParameter":
            return (f"{what} is a structural parameter (it shapes the model when the FMU is configured); "
                    f"it is read-only here: {cannot}; `twin info` lists it")
        if self.causality == "calculatedParameter":
            return (f"{what} is a calculated parameter (the FMU computes it from other parameters); it is "
                    f"read-only: {cannot}; {record}")
        if self.causality == "independent":
            return f"{what} is the independent variable (time); it is read-only"
        if self.causality in ("parameter", "input"):
            return None
        if self.initial in ("exact", "approx"):
            return None      # a start value (e.g. of a state) may be set before initialisation ends
        return (f"{what} has causality '{self.causality}' and cannot be set (only parameters, inputs and "
                "start values can)")

    # -- values --------------------------------------------------------------------------
    def coerce(self, value: Any) -> Any:
        """``value`` as this variable's type: float, int, bool or str (an enumeration's integer value).

        Text (from a command line or a CSV file) is parsed; numbers must be finite and integers
        whole and within the type's range; an enumeration takes an item name or value.
        Raises :class:`ParameterError` naming the variable and the value.
        """
        reason = self.unsupported_reason
        if reason:
            raise ParameterError(reason)
        kind = self.kind
        if kind == "float":
            return self._coerce_float(value)
        if kind == "integer":
            return self._coerce_int(value)
        if kind == "boolean":
            return self._coerce_bool(value)
        if kind == "string":
            if not isinstance(value, str):
                raise ParameterError(f"value of '{self.name}' must be a string (it is a String variable), "
                                     f"got {value!r}")
            if "\x00" in value:
                raise ParameterError(f"value of '{self.name}' must not contain a NUL character")
            return value
        return self._coerce_enumeration(value)

    def _bad(self, value: Any, what: str) -> ParameterError:
        return ParameterError(f"value of '{self.name}' must be {what} (it is a {self.type} variable), got {value!r}")

    def _coerce_float(self, value: Any) -> float:
        if isinstance(value, (bool, np.bool_)):
            raise self._bad(value, "a number")
        try:
            f = float(value.strip() if isinstance(value, str) else value)
        except (TypeError, ValueError):
            raise self._bad(value, "a number") from None
        if not math.isfinite(f):
            raise ParameterError(f"value of '{self.name}' must be finite, got {value!r}")
        if self.type == "Float32" and abs(f) > float(np.finfo(np.float32).max):
            raise ParameterError(f"value of '{self.name}' is out of the Float32 range, got {value!r}")
        return f

    def _coerce_int(self, value: Any) -> int:
        storage = self.type if self.type in INTEGER_TYPES else ("Integer" if self.fmi_version == 2 else "Int64")
        _, lo, hi = INTEGER_TYPES[storage]
        if isinstance(value, (bool, np.bool_)):
            raise self._bad(value, "a whole number")
        if isinstance(value, str):
            text = value.strip()
            try:
                i = int(text)
            except ValueError:
                try:
                    f = float(text)
                except ValueError:
                    raise self._bad(value, "a whole number") from None
                if not (math.isfinite(f) and f == int(f)):
                    raise self._bad(value, "a whole number") from None
                i = int(f)
        elif isinstance(value, (int, np.integer)):
            i = int(value)
        else:
            try:
                f = float(value)
            except (TypeError, ValueError):
                raise self._bad(value, "a whole number") from None
            if not (math.isfinite(f) and f == int(f)):
                raise self._bad(value, "a whole number")
            i = int(f)
        if not lo <= i <= hi:
            raise ParameterError(f"value of '{self.name}' must be within [{lo}, {hi}] "
                                 f"(it is a {self.type} variable), got {value!r}")
        return i

    def _coerce_bool(self, value: Any) -> bool:
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        if isinstance(value, str) and value.strip().lower() in _TRUE | _FALSE:
            return value.strip().lower() in _TRUE
        if isinstance(value, (int, float, np.integer, np.floating)) and value in (0, 1):
            return bool(value)
        raise self._bad(value, "true or false")

    def _coerce_enumeration(self, value: Any) -> int:
        names = {n: v for n, v in self.items}
        if isinstance(value, str) and value.strip() in names:
            return names[value.strip()]
        try:
            i = self._coerce_int(value) if not isinstance(value, (bool, np.bool_)) else None
        except ParameterError:
            i = None
        if i is not None and (not self.items or i in names.values()):
            return i
        listed = ", ".join(f"{n} ({v})" for n, v in self.items)
        raise ParameterError(f"value of '{self.name}' must be an item of {self.declared_type or 'its enumeration'}: "
                             f"{listed}; got {value!r}")

    def item_name(self, value: int) -> str | None:
        """The enumeration item with this value, or None."""
        for n, v in self.items:
            if v == value:
                return n
        return None

    def format(self, value: Any) -> str:
        """``value`` for people: numbers short, an enumeration as ``name (value)``."""
        if value is None:
            return ""
        kind = self.kind
        if kind == "float":
            return f"{value:.6g}"
        if kind == "boolean":
            return "true" if value else "false"
        if kind == "enumeration":
            name = self.item_name(value)
            return f"{name} ({value})" if name is not None else str(value)
        if kind == "string":
            return repr(value)
        return str(value)


# -- reading fmpy's model description ----------------------------------------------------------

def _parse_start(type_name: str, start: Any) -> Any:
    if start is None:
        return None
    if isinstance(start, (list, tuple)):          # FMI 3.0 arrays: not supported, keep the text
        return None
    text = str(start).strip()
    try:
        if type_name in FLOAT_TYPES:
            return float(text)
        if type_name in INTEGER_TYPES or type_name == "Enumeration":
            try:
                return int(text)
            except ValueError:
                return int(float(text))
        if type_name == "Boolean":
            return text.lower() in ("true", "1")
        if type_name == "String":
            return str(start)
    except (TypeError, ValueError):
        return None
    return None


def _shape(v) -> tuple[int, ...]:
    dims = getattr(v, "dimensions", None) or []
    if not dims:
        return ()
    shape = []
    for d in dims:
        start = getattr(d, "start", None)
        try:
            shape.append(int(start))
        except (TypeError, ValueError):
            shape.append(-1)          # sized by a structural parameter
    return tuple(shape)


def variables_from_description(md) -> dict[str, Variable]:
    """name -> :class:`Variable` for every variable of an fmpy ``ModelDescription``.

    Units come from the variable or, when it has none, from its declared type (the type
    definitions of both FMI versions), so ``h`` declared as ``Height`` (unit ``m``) has ``m``.
    """
    out: dict[str, Variable] = {}
    version = 2 if md.fmiVersion == "2.0" else 3
    for v in md.modelVariables:
        declared = getattr(v, "declaredType", None)
        unit = v.unit or (getattr(declared, "unit", None) if declared is not None else None) or ""
        display = (getattr(v, "displayUnit", None)
                   or (getattr(declared, "displayUnit", None) if declared is not None else None) or "")
        quantity = (getattr(v, "quantity", None)
                    or (getattr(declared, "quantity", None) if declared is not None else None) or "")
        items: tuple[tuple[str, int], ...] = ()
        if declared is not None and getattr(declared, "items", None):
            items = tuple((str(i.name), int(i.value)) for i in declared.items)
        out[v.name] = Variable(
            name=v.name, value_reference=int(v.valueReference), type=v.type, causality=v.causality,
            variability=v.variability, unit=str(unit), description=v.description or "",
            start=_parse_start(v.type, v.start), initial=v.initial or "",
            declared_type=getattr(declared, "name", "") if declared is not None else "",
            display_unit=str(display), quantity=str(quantity), items=items, shape=_shape(v),
            fmi_version=version)
    return out
