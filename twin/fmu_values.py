"""Values by name: checked and converted to each variable's FMI type before any FMI call.

:class:`FMUValues` is the part of :class:`twin.fmu.FMU` that names and types values; the FMU class
supplies the FMI calls ``instantiate()``, ``_write(typed)`` and ``_read(variables)``.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from twin.errors import ParameterError

__all__ = ["FMUValues"]


class FMUValues:
    """Set and get parameters, inputs and outputs by name (see :class:`twin.fmu.FMU`)."""

    def _typed(self, values: Mapping[str, Any], *, initialised: bool) -> dict[str, Any]:
        """``values`` converted to their variables' types; every problem in one ParameterError."""
        out, problems = {}, []
        for name, value in values.items():
            try:
                v = self.variable(name)
                if v.variability == "constant" and v.kind in ("integer", "boolean") and self.rebuildable:
                    from twin.variants import rebuild_hint
                    raise ParameterError(rebuild_hint(self.model_name, name, value))
                reason = v.read_only_reason(self.model_name)
                if reason:
                    raise ParameterError(reason)
                if initialised:
                    if v.causality not in ("parameter", "input"):
                        raise ParameterError(f"'{name}' is a start value of {self.model_name}; it can only be "
                                             "set before the run starts")
                    if v.causality == "parameter" and v.variability != "tunable":
                        raise ParameterError(f"'{name}' is a {v.variability} parameter and cannot change "
                                             "during a run")
                out[name] = v.coerce(value)
            except ParameterError as exc:
                problems.append(str(exc))
        if problems:
            raise ParameterError(problems[0] if len(problems) == 1 else
                                 f"{len(problems)} bad values:\n  " + "\n  ".join(problems))
        return out

    def set(self, values: Mapping[str, Any]) -> None:
        """Set parameters, inputs or (before the run) start values by name.

        Values are converted to each variable's type (see :meth:`twin.variables.Variable.coerce`).
        Constants, structural and calculated parameters, and fixed parameters during a run are
        refused by name, all problems in one :class:`ParameterError`.
        """
        typed = self._typed(values, initialised=self._initialized)
        self.instantiate()
        self._write(typed)

    def get(self, names: str | Sequence[str]):
        """Current values by name: one value for one name (float, int, bool or str), else a
        float array when every name is a float variable and a list otherwise.

        Variables of every type are read (value references are unique per type only, so each is
        read with its own type's call); Binary, Clock and array variables are refused by name.
        """
        self.instantiate()
        single = isinstance(names, str)
        names = [names] if single else list(names)
        variables = [self.variable(n) for n in names]
        vals = self._read(variables)
        if single:
            return vals[0]
        if all(v.kind == "float" for v in variables):
            return np.array(vals, dtype=float)
        return vals

    def get_values(self, names: Sequence[str]) -> list:
        """Current values of ``names`` as a list of Python values of their types (float, int,
        bool, str; an enumeration's integer value)."""
        self.instantiate()
        return self._read([self.variable(n) for n in names])

    def parameter_values(self) -> dict[str, Any]:
        """Current value of every parameter of a supported type, by name."""
        params = [v for v in self.parameters if v.unsupported_reason is None]
        if not params:
            return {}
        return dict(zip((v.name for v in params), self._read(params)))
