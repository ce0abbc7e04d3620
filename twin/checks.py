"""Checks of times, rates and sizes before a run starts, with errors that name the value.

A stop time of ``nan``, ``inf`` or ``1e12`` s must not reach numpy as an overflow or an
allocation of a terabyte: it is refused here with the memory the run would need.
"""
from __future__ import annotations

import math
from pathlib import Path

from twin.errors import ParameterError

#: Largest sampled result a run may hold in memory [bytes].
MEMORY_BUDGET = 4 * 1024 ** 3


def _bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"


def whole_multiple(span: float, step: float) -> bool:
    """True when ``span`` is a whole number (>= 1) of ``step`` (to 1e-6 of a step)."""
    k = span / step
    return k >= 1 - 1e-9 and abs(k - round(k)) <= 1e-6


def sample_budget_problem(span: float, interval: float, channels: int) -> str | None:
    """Why sampling ``channels`` channels every ``interval`` s over ``span`` s does not fit in
    :data:`MEMORY_BUDGET`, or None."""
    n = span / interval + 1
    need = n * (channels + 1) * 8.0
    if need > MEMORY_BUDGET:
        return (f"{span:g} s sampled every {interval:g} s is {n:.3g} samples x {channels + 1} channels, "
                f"which would need {_bytes(need)} of memory (the limit is {_bytes(MEMORY_BUDGET)}); "
                "shorten the run or lower the sample rate")
    return None


def check_times(start_time: float | None, stop_time: float | None, output_interval: float | None, *,
                n_channels: int | None = None, fmu: Path | None = None) -> None:
    """Refuse non-finite or absurd times before a simulation (``twin simulate``).

    A time left out (None) is the model's default experiment's (read from ``fmu``'s
    description); ``n_channels`` defaults to the number of outputs of ``fmu``.
    """
    # the run's own span and interval are checked for whole multiples; a model's default experiment
    # is taken as it is
    user_grid = stop_time is not None or output_interval is not None
    if None in (start_time, stop_time, output_interval):
        if fmu is None:
            return
        from twin.fmu import FMU
        for name, v in (("--start-time", start_time), ("--stop-time", stop_time), ("--output-interval", output_interval)):
            if v is not None and not math.isfinite(v):
                raise ParameterError(f"{name} must be a finite number of seconds, got {v!r}")
        with FMU(fmu) as f:
            de = f.default_experiment
            start_time = start_time if start_time is not None else (de.start_time or 0.0)
            stop_time = stop_time if stop_time is not None else (
                de.stop_time if de.stop_time is not None else start_time + 1.0)
            if output_interval is None:      # (a span that is no span is refused below, by name)
                output_interval = f.experiment(start_time, stop_time, None)[2] if stop_time > start_time else 1.0
    for name, v in (("--start-time", start_time), ("--stop-time", stop_time), ("--output-interval", output_interval)):
        if not math.isfinite(v):
            raise ParameterError(f"{name} must be a finite number of seconds, got {v!r}")
    if not output_interval > 0:
        raise ParameterError(f"--output-interval must be > 0 s, got {output_interval!r}")
    if not stop_time > start_time:
        raise ParameterError(f"--stop-time ({stop_time:g} s) must be after --start-time ({start_time:g} s)")
    span = stop_time - start_time
    if span < output_interval * (1 - 1e-9):
        raise ParameterError(f"--stop-time {stop_time:g} s leaves no output sample after {start_time:g} s at an "
                             f"interval of {output_interval:g} s")
    if user_grid and not whole_multiple(span, output_interval):
        raise ParameterError(f"the run of {span:.10g} s is not a whole number of output intervals "
                             f"({output_interval:g} s); use --stop-time "
                             f"{start_time + math.floor(span / output_interval) * output_interval:.10g} or "
                             f"{start_time + math.ceil(span / output_interval) * output_interval:.10g}")
    if n_channels is None:
        n_channels = _count_outputs(fmu) if fmu is not None else 1
    problem = sample_budget_problem(span, output_interval, max(n_channels, 1))
    if problem:
        raise ParameterError(f"--stop-time {stop_time:g}: {problem}")


def _count_outputs(fmu: Path) -> int:
    from twin.errors import TwinError
    try:
        from twin.fmu import FMU
        with FMU(fmu) as f:
            return len(f.outputs)
    except (TwinError, ImportError):  # the FMU's own errors are reported when it is run
        return 1


def check_assignments(fmu: Path, parameters: dict[str, object], inputs: dict[str, object], *,
                      values: dict[str, object] | None = None) -> None:
    """Refuse ``--param`` names that are not parameters (or start values), ``--input`` names that
    are not inputs, read-only variables (constants, structural and calculated parameters, with the
    reason), values that do not fit their variable's type, and values that make no physical sense
    (of ``values`` too: start values from other sources), before the FMU is loaded."""
    from twin.fmu import FMU
    from twin.plausibility import physical_problems
    with FMU(fmu) as f:
        problems = []
        for option, values, causality in (("--param", parameters, "parameter"), ("--input", inputs, "input")):
            for name, value in values.items():
                v = f.variables.get(name)
                if v is None:
                    close = [n for n in f.variables if name.lower() in n.lower()][:5]
                    problems.append(f"{option} {name}: {f.model_name} has no variable {name!r}"
                                    + (f" (similar: {', '.join(close)})" if close else ""))
                elif v.variability == "constant" and v.kind in ("integer", "boolean") and f.rebuildable:
                    from twin.variants import rebuild_hint
                    problems.append(f"{option} {name}: {rebuild_hint(f.model_name, name, value)}")
                elif v.read_only_reason(f.model_name) and (v.variability == "constant" or v.causality in (
                        "structuralParameter", "calculatedParameter", "independent")):
                    problems.append(f"{option} {name}: {v.read_only_reason(f.model_name)}")
                elif v.causality != causality and not (causality == "parameter" and v.causality != "input"
                                                       and v.initial in ("exact", "approx")):
                    problems.append(f"{option} {name}: {name!r} is a{'n' if v.causality[0] in 'aeiou' else ''} "
                                    f"{v.causality}, not a{'n' if causality == 'input' else ''} {causality}"
                                    + (" (use --input)" if v.causality == "input" else
                                       " (use --param)" if v.causality == "parameter" else ""))
                else:
                    try:
                        v.coerce(value)        # the variable's type: a number, true/false, text, an item
                    except ParameterError as exc:
                        problems.append(f"{option} {name}: {exc}")
        problems += physical_problems({**(values or {}), **parameters, **inputs},
                                      {n: v.unit for n, v in f.variables.items()})
    if problems:
        raise ParameterError("; ".join(problems))


def override_stop_time(scenario, stop_time: float):
    """The scenario with ``stop_time`` replaced, validated like the file itself."""
    from twin.scenario import scenario_from_dict
    raw = dict(scenario.raw)
    raw["stop_time"] = stop_time
    return scenario_from_dict(raw, source=scenario.source)
