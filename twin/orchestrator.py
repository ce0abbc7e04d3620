"""The co-simulation orchestrator: runs a :class:`~twin.scenario.Scenario` on any FMU.

One explicit loop over communication steps::

    for each step [t, t + h):
        apply the timed events due at t      (override / bias / reset)
        set the inputs from the operating profile at t (held over the step)
        call the between-step hooks          (hook(context, t); degradation lives here)
        advance the FMU and record its outputs for (t, t + h]

Before running, the FMU's model description is checked against what the scenario needs
(variables by name, causality, variability, and every value against its variable's type);
every mismatch is listed in one :class:`~twin.errors.FMUCompatibilityError`.  Parameter values
that make no physical sense are refused before the run, and a run that leaves physics
(:mod:`twin.plausibility`) is a :class:`~twin.errors.SimulationError`, not a result.

Only a complete run replaces the output file (atomically).  Ctrl-C stops after the current
step; the samples recorded so far go to ``<stem>.partial<suffix>`` beside the output (marked
``complete = False``) and the output itself is left as it was.  An FMU that ends the run
itself (FMI 2.0 ``fmi2Discard``, FMI 3.0 ``terminateSimulation``) ends it cleanly: the samples
up to its last valid time are written, marked ``ended_by_fmu``, and the run is complete.

Parameter values are recorded once, right after the FMU's initialisation (before any event);
what events change is in the run's event log.  The result file's format follows its suffix
(``.h5``/``.hdf5`` or ``.csv`` with a JSON sidecar).
"""
from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twin._progress import progress_bar
from twin.errors import FMUCompatibilityError, ParameterError
from twin.fmu import FMU, Block
from twin.results import SimulationResult, write_result
from twin.scenario import Scenario


@dataclass
class StepContext:
    """What a between-step hook sees and may change."""

    fmu: FMU
    scenario: Scenario
    time: float
    step: int
    store: dict = field(default_factory=dict)   # hook-owned data that ends up in the run record


Hook = Callable[[StepContext], None]


@dataclass(frozen=True)
class RunRecord:
    """Outcome of :func:`run_scenario`."""

    scenario: Scenario
    result: SimulationResult
    complete: bool
    path: Path | None
    events_applied: tuple[tuple[float, str], ...]


def required_variables(scenario: Scenario) -> dict[str, list[tuple[set[str], str, bool]]]:
    """name -> every requirement on it: (accepted causalities, why, must be tunable)."""
    need: dict[str, list[tuple[set[str], str, bool]]] = {}

    def add(name, causalities, why, tunable=False):
        need.setdefault(name, []).append((causalities, why, tunable))

    for n in scenario.outputs or ():
        add(n, {"output", "local"}, "recorded output")
    for n in scenario.parameters:
        add(n, {"parameter"}, "parameter value")
    for n in scenario.inputs:
        add(n, {"input"}, "input driven by the operating profile")
    for e in scenario.events:
        for n in [*e.override, *e.bias, *e.reset]:
            add(n, {"parameter", "input"}, f"changed by the event at t={e.time:g} s", tunable=True)
    return need


def _value_problem(fmu: FMU, name: str, value, why: str) -> str | None:
    try:
        fmu.variables[name].coerce(value)
    except ParameterError as exc:
        return f"{exc} ({why})"
    return None


def check_compatibility(fmu: FMU, scenario: Scenario) -> None:
    """Raise :class:`FMUCompatibilityError` listing every way ``fmu`` does not fit ``scenario``."""
    problems = []
    built = fmu.structural_values()
    for name, value in scenario.structural.items():
        if name in built and built[name] != value:
            problems.append(f"the FMU was built with {name} = {built[name]}, the scenario's structural block "
                            f"says {value!r}; name the model in 'fmu' to build the variant")
    for name, reqs in required_variables(scenario).items():
        v = fmu.variables.get(name)
        if v is not None and v.variability == "constant" and name in built and fmu.rebuildable:
            from twin.variants import rebuild_hint
            problems.append(rebuild_hint(fmu.model_name, name, scenario.parameters.get(name, "<value>")))
            continue
        if v is None:
            problems.append(f"missing variable {name!r} ({'; '.join(why for _, why, _ in reqs)})")
            continue
        if v.unsupported_reason:
            problems.append(f"{v.unsupported_reason} ({'; '.join(why for _, why, _ in reqs)})")
            continue
        for causalities, why, tunable in reqs:
            if ("parameter" in causalities or "input" in causalities) and (
                    v.variability == "constant"
                    or v.causality in ("structuralParameter", "calculatedParameter", "independent")):
                reason = v.read_only_reason(fmu.model_name)
                if reason:
                    problems.append(f"{reason} ({why})")
                    continue
            # a scenario's parameters may also give start values (a state's initial value, say)
            start_value = causalities == {"parameter"} and v.initial in ("exact", "approx")
            if v.causality not in causalities and not start_value:
                problems.append(f"{name!r} has causality {v.causality!r}, needs "
                                f"{' or '.join(sorted(causalities))} ({why})")
            elif tunable and v.causality == "parameter" and v.variability != "tunable":
                problems.append(f"{name!r} is a {v.variability} parameter and cannot change during the run ({why})")
    problems += _value_problems(fmu, scenario)
    if scenario.outputs is None and not fmu.recordable_outputs:
        problems.append("the FMU has no outputs to record and the scenario names none")
    if scenario.degradation is not None:
        for n in ("roll[1]", "pair_force[1]", "k_pair[1]", "profile_deviation[1]"):
            if n not in fmu.variables:
                problems.append(f"missing variable {n!r} (needed by the degradation coupling)")
    if problems:
        raise FMUCompatibilityError(str(fmu.path), problems)


def _value_problems(fmu: FMU, scenario: Scenario) -> list[str]:
    """Every scenario value that does not fit its variable's type."""
    problems = []
    known = {n: v for n, v in fmu.variables.items() if v.unsupported_reason is None}
    for n, value in scenario.parameters.items():
        if n in known:
            problems.append(_value_problem(fmu, n, value, "parameter value"))
    for n, profile in scenario.inputs.items():
        if n not in known:
            continue
        if profile.interpolated and known[n].kind != "float":
            problems.append(f"{n!r} is a {known[n].type} input; a ramp or table profile needs a float input "
                            "(use a constant or steps)")
            continue
        for value in profile.values:
            problems.append(_value_problem(fmu, n, value, "input driven by the operating profile"))
    for e in scenario.events:
        for n, value in e.override.items():
            if n in known:
                problems.append(_value_problem(fmu, n, value, f"override at t={e.time:g} s"))
        for n, b in e.bias.items():
            if n in known and known[n].kind not in ("float", "integer"):
                problems.append(f"{n!r} is a {known[n].type} variable; bias at t={e.time:g} s needs a number")
            elif n in known and known[n].kind == "integer" and b != int(b):
                problems.append(f"{n!r} is a {known[n].type} variable; bias at t={e.time:g} s must be whole, got {b:g}")
    return [p for p in problems if p]


def run_scenario(scenario: Scenario, output: str | Path | None = None, *, fmu_path: Path | None = None,
                 hooks: Sequence[Hook] = (), progress: bool = True) -> RunRecord:
    """Run ``scenario``; write the result to ``output`` if given (HDF5 for ``.h5``/``.hdf5``, CSV
    with a JSON sidecar for ``.csv``; any other suffix is refused before the run).

    Returns a :class:`RunRecord`.  A complete run replaces ``output`` atomically and removes a
    partial file left by an earlier interrupted run.  On Ctrl-C the partial result is written
    to :func:`~twin._atomic.partial_path` of ``output`` (``output`` is left untouched) and
    returned with ``complete=False``.  If the FMU ends the run itself, the result stops at its
    last valid time (``result.ended_by_fmu``) and the run is complete.  Groups that hooks
    register in ``store["_writers"]`` are written to HDF5 files only.
    """
    from twin import _interrupt
    from twin._atomic import partial_path
    from twin.plausibility import DEFAULT_LIMITS, check_block, check_parameters, contact_channels

    path = Path(output) if output is not None else None
    if path is not None:
        from twin.results import check_output_path
        check_output_path(path)
    fmu_file = fmu_path or scenario.fmu_path()
    applied: list[tuple[float, str]] = []
    with FMU(fmu_file) as fmu:
        check_compatibility(fmu, scenario)
        variables = ([fmu.variables[n] for n in scenario.outputs] if scenario.outputs
                     else fmu.recordable_outputs)
        if not scenario.outputs:
            fmu.warn_unrecorded_outputs()
        names = [v.name for v in variables]
        # the pair forces are sampled too (not stored) so a run with the flanks apart is caught
        extra = [fmu.variables[n] for n in contact_channels(fmu.variables) if n not in names]
        captured = [*variables, *extra]
        t0 = scenario.start_time
        inputs_now = {n: p(t0) for n, p in scenario.inputs.items()}
        from twin.operating import consistent_start
        start = consistent_start(scenario.parameters, inputs_now, [v.name for v in fmu.parameters])
        check_parameters(fmu, start)
        fmu.setup(t0, parameters=start, inputs=inputs_now, stop_time=scenario.stop_time)
        initial = {n: fmu.get(n) for n in required_variables(scenario)
                   if fmu.variables[n].causality in ("parameter", "input")}
        h = scenario.communication_step
        dt = scenario.output_interval
        n_steps = int(round((scenario.stop_time - t0) / h))
        per_step = int(round(h / dt))
        blocks = [Block(np.array([fmu.time]), tuple(np.array([x], dtype=v.dtype) for v, x in
                                                    zip(captured, fmu.get_values([v.name for v in captured]))))]
        overrides: dict[str, Any] = {}
        biases: dict[str, float] = {}
        events = list(scenario.events)
        ctx = StepContext(fmu, scenario, t0, 0)
        bar = progress_bar(n_steps * per_step, progress, scenario.name, "samples")
        complete = True
        try:
            for k in range(n_steps):
                _interrupt.check()
                t = t0 + k * h
                while events and events[0].time <= t + 1e-9 * h:
                    e = events.pop(0)
                    applied += _apply_event(fmu, e, initial, overrides, biases)
                if scenario.inputs or overrides or biases:
                    values = {n: p(t) for n, p in scenario.inputs.items()}
                    for n, v in overrides.items():
                        if fmu.variables[n].causality == "input":
                            values[n] = v
                    for n, b in biases.items():
                        if fmu.variables[n].causality == "input":
                            values[n] = values.get(n, initial[n]) + b
                    if values:
                        fmu.set(values)
                ctx.time, ctx.step = t, k
                for hook in hooks:
                    hook(ctx)
                blocks.append(fmu.capture_block(t0 + (k + 1) * h, dt, [v.name for v in captured]))
                bar.update(per_step)
                if fmu.ended is not None:
                    break
            else:
                # events at exactly stop_time change nothing simulated but are applied and logged
                while events and events[0].time <= scenario.stop_time + 1e-9 * h:
                    applied += _apply_event(fmu, events.pop(0), initial, overrides, biases)
        except KeyboardInterrupt:
            complete = False
        finally:
            bar.close()
        columns = [np.concatenate([b.columns[j] for b in blocks]) for j in range(len(captured))]
        time = np.concatenate([b.time for b in blocks])
        if complete:
            floats = [(v.name, c) for v, c in zip(captured, columns) if v.kind == "float"]
            if floats:
                data = np.column_stack([c for _, c in floats]).astype(float)
                float_names = [n for n, _ in floats]
                check_block(float_names, data, {n: fmu.variables[n].unit for n in float_names}, t0=t0, dt=dt,
                            load=_held_load(scenario), contact=_contact(float_names, data), limits=DEFAULT_LIMITS)
        columns = columns[:len(names)]
        result = SimulationResult(time=time, signals=dict(zip(names, columns)),
                                  units={v.name: v.unit for v in variables}, sample_rate=scenario.sample_rate,
                                  parameters=fmu.initial_parameters, model_name=fmu.model_name, guid=fmu.guid,
                                  fmu_sha256=fmu.sha256, types={v.name: v.type for v in variables},
                                  enumerations={v.name: dict(v.items) for v in variables if v.items},
                                  ended_by_fmu=fmu.ended is not None,
                                  end_reason=fmu.ended.reason if fmu.ended is not None else "")
    written = None
    if path is not None:
        written = path if complete else partial_path(path)
        write_result(result, written,
                     hdf5_extra=lambda f: _write_run_groups(f, scenario, complete, applied, ctx.store),
                     csv_extra=_run_meta(scenario, complete, applied))
        if complete:
            partial_path(path).unlink(missing_ok=True)
    return RunRecord(scenario, result, complete, written, tuple(applied))


def _held_load(scenario: Scenario) -> float | None:
    """The smallest brake load [N.m] over the run when the scenario holds one (no event changes
    it), else None: only then must the flanks stay in contact at some time."""
    prof = scenario.inputs.get("load_torque")
    if prof is None or any("load_torque" in {*e.override, *e.bias, *e.reset} for e in scenario.events):
        return None
    t = np.linspace(scenario.start_time, scenario.stop_time, 64)
    return float(np.min(np.abs([prof(x) for x in t])))


def _contact(names: list[str], data: np.ndarray) -> np.ndarray | None:
    idx = [names.index(n) for n in ("pair_force[1]", "pair_force[2]", "pair_force[3]") if n in names]
    return data[:, idx].sum(axis=1) if len(idx) == 3 else None


def _show(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return repr(value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def _apply_event(fmu: FMU, e, initial, overrides, biases) -> list[tuple[float, str]]:
    log = []
    changes = {}
    for n, v in e.override.items():
        overrides[n] = v
        biases.pop(n, None)
        if fmu.variables[n].causality == "parameter":
            changes[n] = v
        log.append((e.time, f"override {n} = {_show(v)}"))
    for n, b in e.bias.items():
        if fmu.variables[n].causality == "parameter":
            changes[n] = fmu.get(n) + b
        else:
            biases[n] = biases.get(n, 0.0) + b
        log.append((e.time, f"bias {n} += {b:g}"))
    for n in e.reset:
        overrides.pop(n, None)
        biases.pop(n, None)
        if fmu.variables[n].causality == "parameter":
            changes[n] = initial[n]
        log.append((e.time, f"reset {n}"))
    if changes:
        fmu.set(changes)
    return log


def _run_meta(scenario: Scenario, complete: bool, applied) -> dict[str, Any]:
    """What a CSV result's sidecar records of the run (the HDF5 file has it in groups)."""
    return {"complete": complete, "scenario_name": scenario.name,
            "scenario": json.loads(json.dumps(scenario.raw, default=str)), "scenario_source": str(scenario.source or ""),
            "events": [{"time": t, "action": a} for t, a in applied]}


def _write_run_groups(f, scenario: Scenario, complete: bool, applied, store: dict) -> None:
    f.attrs["complete"] = complete
    f.attrs["scenario_name"] = scenario.name
    g = f.create_group("scenario")
    g.attrs["json"] = json.dumps(scenario.raw, default=str)
    g.attrs["source"] = str(scenario.source or "")
    ev = f.create_group("events")
    ev.create_dataset("time", data=np.array([t for t, _ in applied], dtype="f8"))
    ev.attrs["actions"] = json.dumps([a for _, a in applied])
    for key, writer in store.get("_writers", {}).items():
        writer(f)


def describe_scenario(scenario: Scenario) -> dict[str, Any]:
    """A JSON-friendly summary (used by the CLI)."""
    return {"name": scenario.name, "fmu": scenario.fmu, "start_time": scenario.start_time,
            "stop_time": scenario.stop_time, "communication_step": scenario.communication_step,
            "sample_rate": scenario.sample_rate, "events": len(scenario.events),
            "inputs": sorted(scenario.inputs), "degradation": bool(scenario.degradation)}
