"""Scenario files: what to simulate, declaratively (``scenarios/*.yaml``).

A scenario names an FMU, a time span, the outputs to record, parameter values, an operating
profile (shaft speed and load: constant, ramp, steps or a CSV table), timed events that
override, bias or reset parameters and inputs (after the Open Simulation Platform's scenario
files), an optional ``degradation:`` block, an optional ``archive:`` block and an optional
``executor:``.  The format is versioned and published as a JSON Schema (``twin schema``).

Values may be of any FMI variable type: numbers, booleans, strings, and enumeration items by
name; they are checked against the FMU's variables when the scenario runs.  A start time, stop
time or output sample rate left out comes from the model's default experiment.

Reading a file validates it completely: every problem is collected and raised at once as a
:class:`~twin.errors.ScenarioError` with the file, the key path and the reason.  Unknown keys
are errors.
"""
from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twin.errors import ScenarioError

from twin.scenario_schema import FORMAT_VERSION, SCHEMA


@dataclass(frozen=True)
class Profile:
    """A piecewise-linear signal ``value(t)`` (times in s) holding its last value.

    Values are numbers, or (held, never interpolated) booleans and strings for inputs of
    those types."""

    times: tuple[float, ...]
    values: tuple[Any, ...]
    hold: bool = False          # True: steps (zero-order hold); False: linear interpolation

    def __call__(self, t: float) -> Any:
        if self.hold:
            i = int(np.searchsorted(self.times, t, side="right")) - 1
            v = self.values[max(i, 0)]
            return v if isinstance(v, (bool, str, int)) else float(v)
        return float(np.interp(t, self.times, self.values))

    @property
    def interpolated(self) -> bool:
        """True when values between the given points are interpolated (ramps and tables)."""
        return not self.hold and len(self.times) > 1


@dataclass(frozen=True)
class Event:
    time: float
    override: Mapping[str, Any] = field(default_factory=dict)
    bias: Mapping[str, float] = field(default_factory=dict)
    reset: tuple[str, ...] = ()


def scenario_value(value: Any) -> Any:
    """A value from YAML/JSON as given to an FMU variable: booleans and strings as they are,
    numbers as floats (integers beyond 2**53, which a float cannot hold, stay integers)."""
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, int) and abs(value) > 2**53:
        return value
    return float(value)


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (see :data:`SCHEMA` for the meaning of each field)."""

    name: str
    fmu: str
    stop_time: float
    source: Path | None = None
    description: str = ""
    start_time: float = 0.0
    communication_step: float = 0.01
    sample_rate: float = 100_000.0
    outputs: tuple[str, ...] | None = None
    parameters: Mapping[str, Any] = field(default_factory=dict)
    structural: Mapping[str, float] = field(default_factory=dict)
    inputs: Mapping[str, Profile] = field(default_factory=dict)
    events: tuple[Event, ...] = ()
    degradation: Mapping[str, Any] | None = None
    archive: Mapping[str, Any] | None = None
    executor: Mapping[str, Any] = field(default_factory=lambda: {"type": "local"})
    seed: int = 0
    raw: Mapping[str, Any] = field(default_factory=dict)

    @property
    def output_interval(self) -> float:
        return 1.0 / self.sample_rate

    def fmu_path(self, modelica_dir: Path | None = None, build_dir: Path | None = None) -> Path:
        """The FMU file: a path as given, the FMU inside an ``.ssp``, or the model built from
        ``modelica/`` on demand."""
        candidate = self._given_path()
        if self.fmu.endswith((".fmu", ".ssp")):
            if not candidate.exists():
                kind = "FMU" if self.fmu.endswith(".fmu") else "SSP"
                raise ScenarioError([(str(self.source), "fmu", f"{kind} file {candidate} does not exist")])
            if self.fmu.endswith(".ssp"):
                return _ssp_system(candidate, self.source).fmu
            return candidate
        repo = Path(__file__).resolve().parents[1]
        if self.structural:
            from twin.variants import build_variant
            return build_variant(self.fmu, dict(self.structural), modelica_dir=modelica_dir or repo / "modelica",
                                 out_dir=build_dir or repo / "build")
        from fmu_build import build_fmu
        return build_fmu(self.fmu, modelica_dir or repo / "modelica", build_dir or repo / "build")

    def _given_path(self) -> Path:
        candidate = Path(self.fmu)
        if not candidate.is_absolute() and self.source is not None:
            candidate = self.source.parent / candidate
        return candidate

    def with_overrides(self, **changes) -> "Scenario":
        from dataclasses import replace
        return replace(self, **changes)


_SSP_CACHE: dict = {}


def _ssp_system(path: Path, source: Path | None):
    """The SSP package at ``path``, read once per process (keyed by path and modification time)."""
    from twin.errors import SSPError
    from twin.ssp import read_ssp

    key = (str(path.resolve()), path.stat().st_mtime_ns)
    if key not in _SSP_CACHE:
        try:
            _SSP_CACHE[key] = read_ssp(path)
        except SSPError as exc:
            raise ScenarioError([(str(source), "fmu", str(exc))]) from None
    return _SSP_CACHE[key]


def scenario_from_ssp(path: str | Path, stop_time: float | None = None) -> Scenario:
    """A scenario that runs an ``.ssp`` as it is: its FMU with its parameter bindings, every output,
    over the SSD's DefaultExperiment (``stop_time`` [s] overrides its stop time)."""
    path = Path(path)
    if not path.exists():
        raise ScenarioError([(str(path), "", "SSP file does not exist")])
    exp = _ssp_system(path, path).default_experiment
    stop = stop_time if stop_time is not None else exp.get("stopTime")
    if stop is None:
        raise ScenarioError([(str(path), "DefaultExperiment", "the SSP gives no stopTime; pass a stop time")])
    return scenario_from_dict({"version": FORMAT_VERSION, "name": path.stem, "fmu": str(path.resolve()),
                               "start_time": exp.get("startTime", 0.0), "stop_time": stop}, source=path)


def schema_json() -> str:
    return json.dumps(SCHEMA, indent=2)


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a YAML (or JSON) scenario file."""
    import yaml

    path = Path(path)
    if not path.exists():
        raise ScenarioError([(str(path), "", "file does not exist")])
    if path.is_dir():
        raise ScenarioError([(str(path), "", "is a directory, not a scenario file")])
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError([(str(path), "", f"cannot read: {exc.strerror or exc}")]) from None
    except UnicodeDecodeError as exc:
        raise ScenarioError([(str(path), "", f"not a text file ({exc.reason} at byte {exc.start})")]) from None
    try:
        data = yaml.load(text, Loader=_unique_key_loader())
    except yaml.YAMLError as exc:
        raise ScenarioError([(str(path), "", f"not valid YAML: {exc}")]) from None
    return scenario_from_dict(data, source=path)


def _unique_key_loader():
    import yaml

    class UniqueKeyLoader(yaml.SafeLoader):
        """A SafeLoader that refuses a key given twice in one mapping (YAML would keep the last)."""

        def construct_mapping(self, node, deep=False):
            seen = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=deep)
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        "while constructing a mapping", node.start_mark,
                        f"duplicate key {key!r} (first at line {seen[key] + 1})", key_node.start_mark)
                seen[key] = key_node.start_mark.line
            return super().construct_mapping(node, deep=deep)

    # YAML 1.1 (PyYAML) reads 1.0e6 or 1e-5 as strings; YAML 1.2 and every user read numbers
    import re
    UniqueKeyLoader.yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
    UniqueKeyLoader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789"))
    return UniqueKeyLoader


def _value_at(data, path):
    for p in path:
        data = data[p]
    return data


def _nonfinite(data, path=()):
    """Key paths of the non-finite numbers (YAML ``.nan``, ``.inf``) anywhere in ``data``."""
    if isinstance(data, float) and not math.isfinite(data):
        yield path
    elif isinstance(data, dict):
        for k, v in data.items():
            yield from _nonfinite(v, (*path, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _nonfinite(v, (*path, i))


def _key_path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(top level)"


def scenario_from_dict(data: Any, source: Path | None = None) -> Scenario:
    """Validate a scenario given as a dict (e.g. parsed YAML) and build the :class:`Scenario`."""
    import jsonschema

    where = str(source) if source else "<scenario>"
    if not isinstance(data, dict):
        raise ScenarioError([(where, "", "a scenario must be a mapping of keys to values")])
    problems: list[tuple[str, str, str]] = []
    validator = jsonschema.Draft202012Validator(SCHEMA)
    for err in sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path))):
        msg = err.message
        if err.validator == "oneOf" and list(err.absolute_path)[:2] == ["calibration", "parameters"]:
            msg = "must be 'auto' or a mapping of parameter name to [lower, upper]"
        elif err.validator == "oneOf":
            msg = ("must be a value or one of {constant: v}, {ramp: {from, to, start, duration}}, "
                   "{steps: [[t, v], ...]}, {table: {file, column, time_column}}")
        elif err.validator == "additionalProperties":
            msg = msg.replace("Additional properties are not allowed", "unknown key(s)")
        problems.append((where, _key_path(err.absolute_path), msg))
    problems += [(where, _key_path(p), f"must be a finite number, got {_value_at(data, p)}") for p in _nonfinite(data)]
    if problems:
        raise ScenarioError(problems)

    out = data.get("output", {})
    defaults = None
    if "stop_time" not in data or "sample_rate" not in out:
        defaults = _model_experiment(data, source, where, problems)
        if defaults is None:
            raise ScenarioError(problems)
    start = float(data["start_time"]) if "start_time" in data else (defaults[0] if defaults else 0.0)
    stop = float(data["stop_time"]) if "stop_time" in data else defaults[1]
    if stop <= start:
        problems.append((where, "stop_time", f"must be after start_time ({start} s), got {stop} s"))
    rate = float(out["sample_rate"]) if "sample_rate" in out else 1.0 / defaults[2]
    comm = (float(data["communication_step"]) if "communication_step" in data
            else max(1, round(0.01 * rate)) / rate)
    if comm * rate < 1 - 1e-9:
        problems.append((where, "communication_step",
                         f"{comm} s is shorter than one output sample (1/{rate:g} Hz)"))
    elif abs(comm * rate - round(comm * rate)) > 1e-6 * comm * rate:
        problems.append((where, "communication_step",
                         f"{comm} s must be a whole number of output samples (1/{rate:g} Hz)"))
    from twin.checks import sample_budget_problem, whole_multiple
    if stop > start and not whole_multiple(stop - start, comm):
        n = (stop - start) / comm
        problems.append((where, "communication_step",
                         f"the run of {stop - start:g} s is not a whole number of communication steps of {comm:g} s "
                         f"({n:.6g} steps); make stop_time {start + max(1, math.floor(n)) * comm:.10g} or "
                         f"{start + math.ceil(n) * comm:.10g}, or change the step"))
    n_out = len(out.get("variables", ())) or 32
    if stop > start and (budget := sample_budget_problem(stop - start, 1.0 / rate, n_out)):
        problems.append((where, "stop_time", budget))

    params: dict[str, float] = {}
    locator = Scenario(name=str(data["name"]), fmu=str(data["fmu"]), stop_time=1.0, source=source)
    if str(data["fmu"]).endswith(".ssp"):
        try:
            locator.fmu_path()
            params.update(_ssp_system(locator._given_path(), source).parameters)
        except ScenarioError as exc:
            problems += [(where, "fmu", r) for _, _, r in exc.problems]
    for i, f in enumerate(data.get("parameter_files", [])):
        p = Path(f)
        if not p.is_absolute() and source is not None:
            p = source.parent / p
        try:
            params.update(read_parameter_file(p, fmu=locator.fmu_path))
        except ScenarioError as exc:
            problems += [(where, f"parameter_files[{i}]", r) for _, _, r in exc.problems]
    params.update({k: scenario_value(v) for k, v in data.get("parameters", {}).items()})
    structural = {k: int(v) if float(v).is_integer() else float(v) for k, v in data.get("structural", {}).items()}
    for k in sorted(set(structural) & set(params)):
        problems.append((where, f"parameters.{k}", f"{k!r} is also in 'structural'; give it in one place"))

    inputs: dict[str, Profile] = {}
    op = data.get("operating", {})
    for key, unit_scale, default_input in (("speed", 2 * math.pi, "motor_speed_ref"), ("load", 1.0, "load_torque")):
        if key in op:
            name = op.get(f"{key}_input", default_input)
            prof = _profile(op[key], f"operating.{key}", source, problems, where)
            if prof is not None:
                inputs[name] = Profile(prof.times, tuple(float(v) * unit_scale for v in prof.values), prof.hold)
    for name, spec in op.get("inputs", {}).items():
        prof = _profile(spec, f"operating.inputs.{name}", source, problems, where)
        if prof is not None:
            if name in inputs:
                problems.append((where, f"operating.inputs.{name}", "this input is already driven by speed/load"))
            inputs[name] = prof

    events = []
    for i, e in enumerate(data.get("events", [])):
        t = float(e["time"])
        if not start <= t <= stop:
            problems.append((where, f"events[{i}].time", f"{t} s is outside [{start}, {stop}] s"))
        k = round((t - start) / comm)
        if abs(start + k * comm - t) > 1e-9 * max(1.0, abs(t)):
            problems.append((where, f"events[{i}].time",
                             f"{t} s is not on a communication step boundary (step {comm} s)"))
        events.append(Event(t, {n: scenario_value(v) for n, v in e.get("override", {}).items()},
                            {n: float(v) for n, v in e.get("bias", {}).items()}, tuple(e.get("reset", ()))))
    if any(b.time < a.time for a, b in zip(events, events[1:])):
        problems.append((where, "events", "events must be in ascending time order"))

    deg = data.get("degradation")
    if deg is not None:
        stop_crit = deg.get("stop", {})
        if deg["model"] == "pitting" and "wear_depth" in stop_crit:
            problems.append((where, "degradation.stop.wear_depth", "a pitting model stops on pitting_density or cycles"))
        if deg["model"] == "wear" and "pitting_density" in stop_crit:
            problems.append((where, "degradation.stop.pitting_density", "a wear model stops on wear_depth or cycles"))
        if not stop_crit and "max_updates" not in deg:
            problems.append((where, "degradation.stop", "give a stop criterion or max_updates, or the run never ends"))
    arc = data.get("archive")
    if arc is not None:
        st = arc["stages"]
        if any(b <= a for a, b in zip(st, st[1:])):
            problems.append((where, "archive.stages", f"stage boundaries must be strictly ascending, got {st}"))
        if deg is None:
            problems.append((where, "archive", "an archive needs a degradation block to produce its stages"))
    ex = data.get("executor", {"type": "local"})
    if ex.get("type") == "dask" and "address" not in ex:
        pass  # no address: a LocalCluster is started
    if problems:
        raise ScenarioError(problems)

    outputs = tuple(out["variables"]) if "variables" in out else None
    return Scenario(name=data["name"], fmu=data["fmu"], stop_time=stop, source=source,
                    description=data.get("description", ""), start_time=start, communication_step=comm,
                    sample_rate=rate, outputs=outputs, parameters=params, structural=structural, inputs=inputs,
                    events=tuple(events), degradation=deg, archive=arc, executor=dict(ex),
                    seed=int(data.get("seed", 0)), raw=data)


def _model_experiment(data, source, where, problems) -> tuple[float, float, float] | None:
    """(start, stop, output interval) of the scenario's FMU for what the scenario leaves out, or
    None (with the problem recorded) when the model cannot give them."""
    from twin.errors import TwinError
    missing = [k for k, given in (("stop_time", "stop_time" in data),
                                  ("output.sample_rate", "sample_rate" in data.get("output", {}))) if not given]
    try:
        draft = Scenario(name=str(data.get("name", "")), fmu=str(data["fmu"]), stop_time=1.0, source=source,
                         structural=dict(data.get("structural", {})))
        from twin.fmu import FMU
        with FMU(draft.fmu_path()) as fmu:
            if "stop_time" not in data and fmu.default_experiment.stop_time is None:
                problems.append((where, "stop_time", f"not given, and {fmu.model_name} has no default "
                                                     "experiment stop time"))
                return None
            return fmu.experiment(data.get("start_time"), data.get("stop_time"), None, fmpy_grid=False)
    except ScenarioError as exc:
        problems.extend((where, k, f"{' and '.join(missing)} not given, and the model's default experiment "
                                   f"cannot be read: {r}") for _, k, r in exc.problems)
    except TwinError as exc:
        problems.append((where, "fmu", f"{' and '.join(missing)} not given, and the model's default experiment "
                                       f"cannot be read: {exc}"))
    return None


def _profile(spec, key, source, problems, where) -> Profile | None:
    if isinstance(spec, (bool, str)):
        return Profile((0.0,), (spec,), hold=True)
    if isinstance(spec, (int, float)):
        return Profile((0.0,), (scenario_value(spec),))
    if "constant" in spec:
        value = scenario_value(spec["constant"])
        return Profile((0.0,), (value,), hold=isinstance(value, (bool, str)))
    if "ramp" in spec:
        r = spec["ramp"]
        t0 = float(r.get("start", 0.0))
        return Profile((t0, t0 + float(r["duration"])), (float(r["from"]), float(r["to"])))
    if "steps" in spec:
        steps = sorted(((float(t), scenario_value(v)) for t, v in spec["steps"]), key=lambda tv: tv[0])
        return Profile(tuple(t for t, _ in steps), tuple(v for _, v in steps), hold=True)
    tab = spec["table"]
    p = Path(tab["file"])
    if not p.is_absolute() and source is not None:
        p = source.parent / p
    if not p.exists():
        problems.append((where, f"{key}.table.file", f"CSV file {p} does not exist"))
        return None
    tcol = tab.get("time_column", "time")
    with open(p, newline="") as f:
        reader = csv.DictReader(f)
        header = reader.fieldnames or []
        rows = list(reader)
    missing = [c for c in (tcol, tab["column"]) if c not in header]
    if missing:
        problems.append((where, f"{key}.table", f"column(s) {', '.join(repr(c) for c in missing)} not found in {p} "
                                                 f"(it has: {', '.join(header) or 'no header'})"))
        return None
    try:
        t = [float(r[tcol]) for r in rows]
        v = [float(r[tab["column"]]) for r in rows]
    except (TypeError, ValueError) as exc:
        problems.append((where, f"{key}.table", f"non-numeric value in {p}: {exc}"))
        return None
    if len(t) < 1 or any(b <= a for a, b in zip(t, t[1:])):
        problems.append((where, f"{key}.table", f"time column of {p} must be strictly increasing and non-empty"))
        return None
    if not all(math.isfinite(x) for x in v):
        problems.append((where, f"{key}.table", f"values in {p} must be finite"))
        return None
    return Profile(tuple(t), tuple(v))


def read_parameter_file(path: str | Path, *, fmu=None) -> dict[str, Any]:
    """Parameter set from JSON (``{name: value}`` or ``{"parameters": {...}}``; values are numbers,
    booleans or strings) or SSP ``.ssv``.

    An ``.ssv`` entry with a unit is converted into the unit of the FMU variable; ``fmu`` is the
    FMU's path, or a function returning it (called only when some entry has a unit). Without an
    FMU, only values in a coherent SI unit (factor 1, no offset: ``N.m/rad``, not ``kN.m/rad``) are
    accepted, as they are. Integer and Boolean entries keep their type.
    """
    path = Path(path)
    if not path.exists():
        raise ScenarioError([(str(path), "", "parameter file does not exist")])
    if path.suffix == ".ssv":
        from twin.errors import SSPError
        from twin.ssv import read_ssv, resolve
        try:
            pset = read_ssv(path)
            if not any(v.unit for v in pset.values):
                return pset.as_dict()
            if fmu is not None:
                from twin.ssp import _fmu_interface
                variables, units = _fmu_interface(Path(fmu() if callable(fmu) else fmu))
                return resolve(pset, variables, units)
            out = {}
            for v in pset.values:
                unit = pset.units.get(v.unit) if v.unit else None
                if v.unit and (unit is None or unit.factor != 1.0 or unit.offset != 0.0):
                    raise SSPError(f"{path}: parameter {v.name!r} is given in {v.unit!r}, which needs the FMU "
                                   "to be converted (or is not defined in the file's Units)")
                out[v.name] = v.value
            return out
        except SSPError as exc:
            raise ScenarioError([(str(path), "", str(exc))]) from None
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise ScenarioError([(str(path), "", f"not valid JSON: {exc}")]) from None
    if isinstance(data, dict) and "parameters" in data and isinstance(data["parameters"], dict):
        data = data["parameters"]
    if not isinstance(data, dict) or not all(isinstance(v, (int, float, bool, str)) for v in data.values()):
        raise ScenarioError([(str(path), "", "expected a JSON object of parameter name -> value "
                                             "(number, boolean or string)")])
    return {k: scenario_value(v) for k, v in data.items()}
