"""modelDescription.xml (FMI 2.0 and FMI 3.0) and documentation/index.html of a built FMU.

Everything here is read off the :class:`~fmu_build.symbolic.OdeModel` and the build metadata:

- ``UnitDefinitions``: every unit once, in one spelling (:func:`twin.units.canonical_name`),
  with its ``BaseUnit`` exponents, factor and offset (:func:`twin.units.parse_unit`); a unit the
  parser does not know stops the build, naming the variable.
- ``min``/``max``/``nominal`` from the Modelica attributes of each variable.
- ``ModelStructure`` dependencies from the Jacobian structure of the generated functions
  (:mod:`fmu_build.structure`).
- ``DefaultExperiment`` from the model's ``experiment`` annotation; without one, start 0 s, stop
  1 s and a communication step of :data:`DEFAULT_COMMUNICATION_STEP`.  The internal solver step is
  the parameter ``solver.step_size``, not the communication step.
"""
from __future__ import annotations

import datetime
import html
import os
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

from twin.errors import BuildError, UnitError
from twin.units import canonical_name, derivative_unit, parse_unit

from .structure import ModelStructure
from .symbolic import Variable

#: Communication step [s] written when the model's experiment annotation gives no Interval.
DEFAULT_COMMUNICATION_STEP = 1e-3
GENERATION_TOOL = "gear-twin fmu_build (rumoca + CasADi + gcc)"


@dataclass(frozen=True)
class BuildInfo:
    """What the description needs beyond the ODE: names, layout and metadata."""

    model: str
    identifier: str
    guid: str          # FMI 2.0 guid; FMI 3.0 instantiationToken
    step_size: float   # default of solver.step_size [s]
    builder_version: str
    experiment: dict = field(default_factory=dict)   # startTime, stopTime, stepSize, tolerance
    metadata: dict = field(default_factory=dict)     # version, author, license, copyright
    generated: str = ""                              # generationDateAndTime (xs:dateTime, UTC)


def generation_time() -> str:
    """UTC build time, or ``SOURCE_DATE_EPOCH`` when set (reproducible builds)."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    if epoch:
        try:
            when = datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc)
        except (ValueError, OverflowError, OSError):
            raise BuildError(f"SOURCE_DATE_EPOCH must be an integer number of seconds, got {epoch!r}") from None
    else:
        when = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def layout(ode) -> dict:
    """First value reference of each block of Real (Float64) variables; see fmu_build/README.md."""
    p = 0
    q = p + len(ode.parameters)
    u = q + len(ode.calculated)
    y = u + len(ode.inputs)
    x = y + len(ode.outputs)
    dx = x + len(ode.states)
    step = dx + len(ode.states)
    return {"p": p, "q": q, "u": u, "y": y, "x": x, "dx": dx, "step": step, "out": step + 1, "end": step + 2}


@dataclass
class _Row:
    """One variable of the FMU with everything both FMI versions need."""

    var: Variable
    vr: int
    causality: str
    variability: str
    initial: str | None
    start: float | None
    unit: str = ""
    derivative_of: int | None = None     # value reference of the state (FMI 3) / row of it (FMI 2)
    type: str = "Real"


def _unit(v: Variable, what: str | None = None) -> str:
    if not v.unit:
        return ""
    try:
        parse_unit(v.unit)
        return canonical_name(v.unit)
    except UnitError as exc:
        raise BuildError(f"unit of {what or v.name}: {exc}") from None


def rows(ode, step_size: float) -> list[_Row]:
    """Every variable, in the documented order (value references contiguous per block)."""
    lay = layout(ode)
    out: list[_Row] = []
    for i, v in enumerate(ode.parameters):
        out.append(_Row(v, lay["p"] + i, "parameter", "tunable", "exact", float(v.start), _unit(v)))
    for i, v in enumerate(ode.calculated):
        out.append(_Row(v, lay["q"] + i, "calculatedParameter", "tunable", "calculated", None, _unit(v)))
    for i, v in enumerate(ode.inputs):
        out.append(_Row(v, lay["u"] + i, "input", "continuous", None, float(v.start), _unit(v)))
    for i, v in enumerate(ode.outputs):
        out.append(_Row(v, lay["y"] + i, "output", "continuous", "calculated", None, _unit(v)))
    for i, v in enumerate(ode.states):
        out.append(_Row(v, lay["x"] + i, "local", "continuous", "calculated", None, _unit(v)))
    for i, v in enumerate(ode.states):
        unit = derivative_unit(_unit(v)) if v.unit else "1/s"
        dv = Variable(f"der({v.name})", "derivative", unit, f"Time derivative of {v.name}")
        out.append(_Row(dv, lay["dx"] + i, "local", "continuous", "calculated", None, unit,
                        derivative_of=lay["x"] + i))
    out.append(_Row(Variable("solver.step_size", "", "s", "Largest internal Runge-Kutta 4 step of the co-simulation",
                             min=0.0),
                    lay["step"], "parameter", "tunable", "exact", float(step_size), "s"))
    out.append(_Row(Variable("solver.output_interval", "", "s",
                             "Interval of the outputs buffered inside each doStep (0 = off)", min=0.0),
                    lay["out"], "parameter", "tunable", "exact", 0.0, "s"))
    for i, v in enumerate(ode.constants):
        out.append(_Row(v, i, "local", "constant", "exact", float(v.start), type="Integer"))
    return out


def unit_definitions(all_rows: list[_Row]) -> str:
    units = sorted({r.unit for r in all_rows if r.unit} | {"s"})
    lines = []
    for name in units:
        base = parse_unit(name).base_unit_attributes()
        attrs = "".join(f" {k}={quoteattr(v)}" for k, v in base.items())
        lines.append(f"    <Unit name={quoteattr(name)}>\n      <BaseUnit{attrs}/>\n    </Unit>")
    return "  <UnitDefinitions>\n" + "\n".join(lines) + "\n  </UnitDefinitions>"


def _common_attrs(r: _Row, vr: int) -> list[str]:
    """name, valueReference, description, causality, variability, initial: the same in FMI 2.0 and 3.0."""
    attrs = [f"name={quoteattr(r.var.name)}", f'valueReference="{vr}"']
    if r.var.description:
        attrs.append(f"description={quoteattr(r.var.description)}")
    attrs += [f'causality="{r.causality}"', f'variability="{r.variability}"']
    if r.initial:
        attrs.append(f'initial="{r.initial}"')
    return attrs


def _real_attrs(r: _Row) -> list[str]:
    v = r.var
    attrs = []
    if r.unit:
        attrs.append(f"unit={quoteattr(r.unit)}")
    if r.start is not None:
        attrs.append(f'start="{float(r.start)!r}"')
    for key in ("min", "max", "nominal"):
        val = getattr(v, key)
        if val is not None:
            attrs.append(f'{key}="{float(val)!r}"')
    return attrs


def _experiment_xml(info: BuildInfo) -> str:
    exp = {"startTime": 0.0, "stopTime": 1.0, "stepSize": DEFAULT_COMMUNICATION_STEP, **info.experiment}
    attrs = " ".join(f'{k}="{float(exp[k])!r}"' for k in ("startTime", "stopTime", "tolerance", "stepSize")
                     if k in exp)
    return f"  <DefaultExperiment {attrs}/>"


def _meta_attrs(info: BuildInfo) -> str:
    parts = []
    for key in ("author", "version", "copyright", "license"):
        if info.metadata.get(key):
            parts.append(f"{key}={quoteattr(info.metadata[key])}")
    parts.append(f"generationTool={quoteattr(GENERATION_TOOL + ' ' + info.builder_version)}")
    if info.generated:
        parts.append(f'generationDateAndTime="{info.generated}"')
    return "\n  ".join(parts)


def fmi2(ode, info: BuildInfo, structure: ModelStructure) -> str:
    """The FMI 2.0 modelDescription.xml (Co-Simulation and Model Exchange)."""
    all_rows = rows(ode, info.step_size)
    index = {(r.type, r.vr): k + 1 for k, r in enumerate(all_rows)}
    lay = layout(ode)
    xml_rows = []
    for r in all_rows:
        attrs = _common_attrs(r, r.vr)
        if r.type == "Real":
            inner = _real_attrs(r)
            if r.derivative_of is not None:
                inner.append(f'derivative="{index[("Real", r.derivative_of)]}"')
        else:
            inner = [f'start="{int(r.start)}"']
        xml_rows.append(f'    <ScalarVariable {" ".join(attrs)}>\n      <{r.type} {" ".join(inner)}/>\n'
                        "    </ScalarVariable>")

    def known_index(block: str, i: int) -> int:
        return index[("Real", lay[block] + i)]

    def unknown(idx: int, deps, with_kind: bool) -> str:
        ids = [known_index(b, i) for b, i, _ in deps]
        order = sorted(range(len(ids)), key=ids.__getitem__)
        dep = " ".join(str(ids[k]) for k in order)
        out = f'      <Unknown index="{idx}" dependencies="{dep}"'
        if with_kind and deps:
            out += f' dependenciesKind="{" ".join(deps[k][2] for k in order)}"'
        return out + "/>"

    outputs_xml = "\n".join(unknown(index[("Real", lay["y"] + i)], d, True) for i, d in enumerate(structure.outputs))
    ders_xml = "\n".join(unknown(index[("Real", lay["dx"] + i)], d, True)
                         for i, d in enumerate(structure.derivatives))
    initial = []
    for block, deps in (("y", structure.initial_outputs), ("q", structure.initial_calculated),
                        ("x", structure.initial_states), ("dx", structure.initial_derivatives)):
        for i, d in enumerate(deps):
            initial.append((index[("Real", lay[block] + i)], d))
    init_xml = "\n".join(unknown(idx, d, False) for idx, d in sorted(initial))
    desc = ode.description or info.model
    source_files = ('    <SourceFiles>\n      <File name="fmi2_wrapper.c"/>\n      <File name="model_functions.c"/>\n'
                    "    </SourceFiles>")
    sections = [f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName={quoteattr(info.model)} guid="{info.guid}"
  description={quoteattr(desc)}
  {_meta_attrs(info)}
  variableNamingConvention="structured" numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="{info.identifier}" canGetAndSetFMUstate="true" canSerializeFMUstate="true"
    completedIntegratorStepNotNeeded="true" canNotUseMemoryManagementFunctions="true">
{source_files}
  </ModelExchange>
  <CoSimulation modelIdentifier="{info.identifier}" canHandleVariableCommunicationStepSize="true"
    canGetAndSetFMUstate="true" canSerializeFMUstate="true" canNotUseMemoryManagementFunctions="true">
{source_files}
  </CoSimulation>""", unit_definitions(all_rows), _experiment_xml(info),
                "  <ModelVariables>\n" + "\n".join(xml_rows) + "\n  </ModelVariables>",
                f"""  <ModelStructure>
    <Outputs>
{outputs_xml}
    </Outputs>
    <Derivatives>
{ders_xml}
    </Derivatives>
    <InitialUnknowns>
{init_xml}
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""]
    return "\n".join(s for s in sections if s)


# ---- documentation ------------------------------------------------------------------------------
_CSS = """body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em;line-height:1.45}
table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #ccc;padding:.2em .5em;text-align:left}
code,pre{background:#f4f4f4}pre{padding:.5em;overflow-x:auto}"""


def documentation_html(ode, info: BuildInfo, readme: Path | None) -> str:
    """documentation/index.html: the model's readme (Markdown) and its interface, as one page."""
    import markdown

    esc = html.escape
    parts = [f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
             f"<title>{esc(info.model)}</title>\n<style>{_CSS}</style>\n</head>\n<body>"]
    if readme is not None and readme.exists():
        parts.append(markdown.markdown(readme.read_text(encoding="utf-8"), extensions=["tables", "fenced_code"]))
    else:
        parts.append(f"<h1>{esc(info.model)}</h1>\n<p>{esc(ode.description or '')}</p>")
    exp = {"startTime": 0.0, "stopTime": 1.0, "stepSize": DEFAULT_COMMUNICATION_STEP, **info.experiment}
    parts.append("<h2>FMU</h2>\n<table>"
                 + "".join(f"<tr><th>{esc(k)}</th><td>{esc(str(v))}</td></tr>" for k, v in (
                     ("model", info.model), ("version", info.metadata.get("version", "")),
                     ("author", info.metadata.get("author", "")), ("license", info.metadata.get("license", "")),
                     ("generated", info.generated), ("generation tool", f"{GENERATION_TOOL} {info.builder_version}"),
                     ("default experiment", f"{exp['startTime']:g} s to {exp['stopTime']:g} s, "
                                            f"communication step {exp['stepSize']:g} s"),
                     ("solver", f"fixed-step Runge-Kutta 4, largest step solver.step_size = {info.step_size:g} s")))
                 + "</table>")
    for title, group in (("Inputs", ode.inputs), ("Outputs", ode.outputs), ("Parameters", ode.parameters),
                         ("States", ode.states)):
        if not group:
            continue
        body = "".join(
            f"<tr><td><code>{esc(v.name)}</code></td><td>{esc(v.unit)}</td>"
            f"<td>{'' if title in ('Outputs',) else f'{v.start:.6g}'}</td>"
            f"<td>{'' if v.min is None else f'{v.min:g}'}</td><td>{'' if v.max is None else f'{v.max:g}'}</td>"
            f"<td>{esc(v.description)}</td></tr>" for v in group)
        parts.append(f"<h2>{title} ({len(group)})</h2>\n<table><tr><th>name</th><th>unit</th><th>start</th>"
                     f"<th>min</th><th>max</th><th>description</th></tr>{body}</table>")
    parts.append("</body>\n</html>\n")
    return "\n".join(parts)



# ---- FMI 3.0 ------------------------------------------------------------------------------------------
def fmi3_value_references(ode) -> dict:
    """FMI 3.0 layout: the Float64 blocks as in FMI 2.0, then ``time``, then the Int32 constants."""
    lay = layout(ode)
    return {**lay, "time": lay["end"], "c0": lay["end"] + 1}


def fmi3(ode, info: BuildInfo, structure: ModelStructure) -> str:
    """The FMI 3.0 modelDescription.xml (Co-Simulation and Model Exchange)."""
    all_rows = rows(ode, info.step_size)
    lay = fmi3_value_references(ode)
    xml_rows = [f'    <Float64 name="time" valueReference="{lay["time"]}" causality="independent" '
                'variability="continuous" unit="s" description="Simulation time"/>']
    for r in all_rows:
        attrs = _common_attrs(r, r.vr if r.type == "Real" else lay["c0"] + r.vr)
        if r.type == "Real":
            attrs += _real_attrs(r)
            if r.derivative_of is not None:
                attrs.append(f'derivative="{r.derivative_of}"')
            xml_rows.append(f'    <Float64 {" ".join(attrs)}/>')
        else:
            attrs.append(f'start="{int(r.start)}"')
            xml_rows.append(f'    <Int32 {" ".join(attrs)}/>')

    def vr_of(block: str, i: int) -> int:
        return lay[block] + i

    def unknown(tag: str, vr: int, deps, with_kind: bool) -> str:
        refs = [vr_of(b, i) for b, i, _ in deps]
        order = sorted(range(len(refs)), key=refs.__getitem__)
        out = f'    <{tag} valueReference="{vr}" dependencies="{" ".join(str(refs[k]) for k in order)}"'
        if with_kind and deps:
            out += f' dependenciesKind="{" ".join(deps[k][2] for k in order)}"'
        return out + "/>"

    structure_xml = [unknown("Output", vr_of("y", i), d, True) for i, d in enumerate(structure.outputs)]
    structure_xml += [unknown("ContinuousStateDerivative", vr_of("dx", i), d, True)
                      for i, d in enumerate(structure.derivatives)]
    initial = []
    for block, deps in (("y", structure.initial_outputs), ("q", structure.initial_calculated),
                        ("x", structure.initial_states), ("dx", structure.initial_derivatives)):
        for i, d in enumerate(deps):
            initial.append((vr_of(block, i), d))
    structure_xml += [unknown("InitialUnknown", vr, d, False) for vr, d in sorted(initial)]
    desc = ode.description or info.model
    return "\n".join([f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName={quoteattr(info.model)} instantiationToken="{info.guid}"
  description={quoteattr(desc)}
  {_meta_attrs(info)}
  variableNamingConvention="structured">
  <ModelExchange modelIdentifier="{info.identifier}" canGetAndSetFMUState="true" canSerializeFMUState="true"/>
  <CoSimulation modelIdentifier="{info.identifier}" canHandleVariableCommunicationStepSize="true"
    canGetAndSetFMUState="true" canSerializeFMUState="true" hasEventMode="false"/>""",
                      unit_definitions(all_rows), _experiment_xml(info),
                      "  <ModelVariables>\n" + "\n".join(xml_rows) + "\n  </ModelVariables>",
                      "  <ModelStructure>\n" + "\n".join(structure_xml) + "\n  </ModelStructure>",
                      "</fmiModelDescription>\n"])


def build_description_fmi3(info: BuildInfo) -> str:
    """sources/buildDescription.xml of an FMI 3.0 FMU: how to compile its sources (fmpy compile)."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration modelIdentifier="{info.identifier}">
    <SourceFileSet language="C99">
      <SourceFile name="fmi3_wrapper.c"/>
      <SourceFile name="model_functions.c"/>
    </SourceFileSet>
    <Library name="m"/>
  </BuildConfiguration>
</fmiBuildDescription>
"""
