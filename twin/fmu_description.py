"""What an FMU declares: identity, variables by causality, units, default experiment.

:class:`FMUDescription` is the part of :class:`twin.fmu.FMU` that only reads the model
description (no FMI call): the FMU class supplies ``model_description``, ``variables``,
``default_experiment`` and ``_auto_interval(span)``, fmpy's automatic output interval [s] for a
run of ``span`` s (only :mod:`twin.fmu` imports fmpy).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from twin.checks import whole_multiple
from twin.errors import ParameterError, SimulationError, TwinWarning
from twin.variables import Variable

__all__ = ["DefaultExperiment", "FMUDescription", "float_or_none", "STEP_SIZE", "OUTPUT_INTERVAL"]

# parameters of FMUs built by fmu_build: the internal solver step and the output buffer's interval [s]
STEP_SIZE = "solver.step_size"
OUTPUT_INTERVAL = "solver.output_interval"


@dataclass(frozen=True)
class DefaultExperiment:
    """The model's ``DefaultExperiment`` (None where it gives no value); times in s."""

    start_time: float | None = None
    stop_time: float | None = None
    step_size: float | None = None
    tolerance: float | None = None


def float_or_none(value) -> float | None:
    """``value`` as a finite float, else None (missing, text or not finite)."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


class FMUDescription:
    """Identity, variables and default experiment of an opened FMU (read from its model description)."""

    model_description: object
    variables: dict[str, Variable]
    default_experiment: DefaultExperiment

    @property
    def model_name(self) -> str:
        return self.model_description.modelName

    @property
    def guid(self) -> str:
        """The FMI 2.0 ``guid`` or FMI 3.0 ``instantiationToken``."""
        return self.model_description.guid

    @property
    def description(self) -> str:
        return self.model_description.description or ""

    @property
    def rebuildable(self) -> bool:
        """True for FMUs built by ``fmu_build``, whose structural constants ``twin build --set`` changes."""
        return str(self.model_description.generationTool or "").startswith("gear-twin fmu_build")

    def _by(self, *causalities: str) -> list[Variable]:
        return sorted((v for v in self.variables.values() if v.causality in causalities),
                      key=lambda v: v.value_reference)

    @property
    def parameters(self) -> list[Variable]:
        """Parameters (FMI 3.0 structural parameters included), by value reference."""
        return self._by("parameter", "structuralParameter")

    @property
    def inputs(self) -> list[Variable]:
        return self._by("input")

    @property
    def outputs(self) -> list[Variable]:
        """Every output, of any type, by value reference."""
        return self._by("output")

    @property
    def unit_definitions(self) -> dict:
        """The FMU's ``UnitDefinitions`` with a ``BaseUnit``, as :class:`twin.units.Unit` by name."""
        from twin.units import BASE, Unit
        out = {}
        for u in self.model_description.unitDefinitions or ():
            b = getattr(u, "baseUnit", None)
            if b is not None:
                out[u.name] = Unit(u.name, tuple(int(getattr(b, k, 0) or 0) for k in BASE),
                                   float(b.factor if b.factor is not None else 1.0),
                                   float(b.offset if b.offset is not None else 0.0))
        return out

    @property
    def recordable_outputs(self) -> list[Variable]:
        """The outputs twin can record (scalars of every type but Binary and Clock)."""
        return [v for v in self.outputs if v.unsupported_reason is None]

    def warn_unrecorded_outputs(self) -> None:
        """Warn (:class:`~twin.errors.TwinWarning`) about outputs that recording every output leaves out."""
        skipped = [v for v in self.outputs if v.unsupported_reason is not None]
        if skipped:
            listed = ", ".join(f"{v.name} ({v.type}{list(v.shape) if v.shape else ''})" for v in skipped)
            warnings.warn(TwinWarning(f"{self.model_name}: not recorded: {listed}; twin records scalar variables "
                                      "of every type but Binary and Clock"), stacklevel=2)

    def structural_values(self) -> dict[str, int]:
        """The model's Integer constants (``z1``, ``z2``, ``n_profile``, ...): fixed when the FMU
        was built, so read from its model description."""
        return {v.name: int(v.start) for v in self.variables.values()
                if v.kind == "integer" and v.variability == "constant" and v.start is not None}

    @property
    def supports_output_buffer(self) -> bool:
        return OUTPUT_INTERVAL in self.variables

    def variable(self, name: str) -> Variable:
        try:
            return self.variables[name]
        except KeyError:
            close = [n for n in self.variables if name.lower() in n.lower()][:5]
            hint = f"; similar: {', '.join(close)}" if close else ""
            raise ParameterError(f"{self.model_name} has no variable {name!r}{hint}") from None

    def experiment(self, start_time: float | None = None, stop_time: float | None = None,
                   output_interval: float | None = None, *, fmpy_grid: bool = True) -> tuple[float, float, float]:
        """(start, stop, output interval) [s]: the values given, else the model's default experiment.

        Start: ``startTime``, else 0.  Stop: ``stopTime``, else start + 1 s.  Output interval, as
        ``fmpy.simulate_fmu`` chooses it over the model's own experiment: the FMI 3.0
        ``fixedInternalStepSize``, else ``stepSize``, doubled until the run has at most 1000
        intervals (where that does not divide the run, the largest doubling that does: the twin's
        samples are whole intervals, fmpy would end on a shorter one); else fmpy's automatic
        interval (500 to 1000 samples).  With a stop time given, or ``fmpy_grid=False``
        (scenarios), the model's step is taken as it is, so a vibration model keeps its sample rate.
        """
        de = self.default_experiment
        start = float(start_time) if start_time is not None else (de.start_time if de.start_time is not None else 0.0)
        stop = float(stop_time) if stop_time is not None else (de.stop_time if de.stop_time is not None else start + 1.0)
        if not stop > start:
            raise SimulationError(f"stop_time ({stop} s) must be after start_time ({start} s)")
        fixed = float_or_none(getattr(self.model_description.coSimulation, "fixedInternalStepSize", None))
        step = de.step_size if de.step_size is not None and de.step_size > 0 else None
        if output_interval is not None:
            interval = float(output_interval)
        elif fmpy_grid and (fixed or step) and stop_time is None:
            interval = float(fixed or step)
            while (stop - start) / interval > 1000:     # fmpy's rule, so both give the same samples
                interval *= 2
            while not whole_multiple(stop - start, interval) and interval > float(fixed or step):
                interval /= 2                           # fmpy would end on a shorter interval
        elif step:
            interval = step
        elif fixed:
            interval = fixed
        else:
            interval = float(self._auto_interval(stop - start))
        if not interval > 0:
            raise SimulationError(f"output_interval must be > 0 s, got {interval!r}")
        return start, stop, interval
