"""SSP 1.0 system files: ``.ssd`` system structure descriptions and ``.ssp`` packages.

:func:`write_ssp` packs an FMU and a parameter set into a standard ``.ssp`` that other SSP tools
(OSP libcosim, ...) run with those values::

    SystemStructure.ssd          one System with one FMU Component, its connectors with units,
                                 a ParameterBinding to the parameter set, Units, DefaultExperiment
    resources/<model>.fmu
    resources/<name>.ssv

:func:`read_ssp` reads an ``.ssp`` (or a directory holding an unpacked one) with exactly one FMU
component: it extracts the FMU and applies the parameter bindings of the component and of the
system, in the standard's order (later bindings win; system bindings win over component
bindings), with names resolved through ``prefix`` and ``ssm`` parameter mappings (inline or
from a file, with ``ssc:LinearTransformation``), and Real values converted into the FMU's units
(:mod:`twin.ssv`).
"""
from __future__ import annotations

import atexit
import hashlib
import math
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any
from xml.sax.saxutils import quoteattr

from twin.errors import FMUError, ParameterError, SSPError, TwinError
from twin.ssv import (_FMI_TYPE, NS_SSC, NS_SSD, NS_SSM, NS_SSV, EnumerationItem, ParameterSet, parameter_set_xml,
                      parse_parameter_set, read_units, resolve, units_xml, utc_now)

FMU_MIME = "application/x-fmu-sharedlibrary"
SSV_MIME = "application/x-ssp-parameter-set"
SSM_MIME = "application/x-ssp-parameter-mapping"
DEFAULT_SSD = "SystemStructure.ssd"
#: OSP's vendor annotation that gives libcosim its fixed co-simulation step.
NS_OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"


def _q(ns: str, tag: str) -> str:
    return f"{{{ns}}}{tag}"


@dataclass(frozen=True)
class SSPSystem:
    """What :func:`read_ssp` found: the FMU, its resolved parameter values, the default experiment."""

    source: Path
    name: str
    component: str
    fmu: Path                                   # extracted FMU file, valid for the life of the process
    parameters: Mapping[str, Any] = field(default_factory=dict)   # FMU variable -> value, in FMU units
    default_experiment: Mapping[str, float] = field(default_factory=dict)   # startTime, stopTime
    parameter_sets: tuple[str, ...] = ()        # where each applied set came from


# ---- reading -------------------------------------------------------------------------------------
class _Archive:
    """Files of an .ssp (zip) or of a directory holding an unpacked SSP, by relative POSIX path."""

    def __init__(self, path: Path):
        self.path = path
        self.zip = None
        if path.is_dir():
            return
        if not path.is_file():
            raise SSPError(f"{path}: file does not exist")
        if not zipfile.is_zipfile(path):
            raise SSPError(f"{path}: not an SSP package (not a zip archive)")
        self.zip = zipfile.ZipFile(path)

    def read(self, name: str, what: str) -> bytes:
        norm = str(PurePosixPath(name))
        if norm.startswith("/") or ".." in PurePosixPath(norm).parts or "://" in name:
            raise SSPError(f"{self.path}: {what} {name!r} is not a relative path inside the package")
        try:
            if self.zip is not None:
                return self.zip.read(norm)
            return (self.path / norm).read_bytes()
        except (KeyError, FileNotFoundError):
            raise SSPError(f"{self.path}: {what} {name!r} is not in the package") from None

    def names(self) -> list[str]:
        if self.zip is not None:
            return [n for n in self.zip.namelist() if not n.endswith("/")]
        return sorted(str(p.relative_to(self.path).as_posix()) for p in self.path.rglob("*") if p.is_file())

    def close(self) -> None:
        if self.zip is not None:
            self.zip.close()


_EXTRACTED: dict[str, Path] = {}


def _extraction_dir() -> Path:
    if "root" not in _EXTRACTED:
        root = Path(tempfile.mkdtemp(prefix="twin_ssp_"))
        atexit.register(shutil.rmtree, root, True)
        _EXTRACTED["root"] = root
    return _EXTRACTED["root"]


def _xml(data: bytes, where: str) -> ET.Element:
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        raise SSPError(f"{where}: not valid XML: {exc}") from None


def _fmu_interface(fmu: Path):
    from twin.fmu import FMU
    try:
        with FMU(fmu) as f:
            return dict(f.variables), f.unit_definitions
    except FMUError as exc:
        raise SSPError(f"the FMU of the SSP is unusable: {exc}") from None


def _mapping(binding: ET.Element, archive: _Archive, where: str, fmu_bytes: bytes | None) -> dict[str, tuple]:
    """source name -> (target name, factor, offset, suppress unit conversion) of a ParameterMapping."""
    node = binding.find(_q(NS_SSD, "ParameterMapping"))
    if node is None:
        return {}
    if node.get("type", SSM_MIME) != SSM_MIME:
        raise SSPError(f"{where}: parameter mapping of type {node.get('type')!r} is not supported ({SSM_MIME} is)")
    src = node.get("source")
    if src:
        data = _from_base(node, src, archive, fmu_bytes, "parameter mapping")
        root = _xml(data, f"{where} ({src})")
    else:
        root = node.find(_q(NS_SSM, "ParameterMapping"))
        if root is None:
            raise SSPError(f"{where}: ParameterMapping has neither a source nor an inline ssm:ParameterMapping")
    out = {}
    for e in root.findall(_q(NS_SSM, "MappingEntry")):
        factor, offset = 1.0, 0.0
        for child in e:
            tag = child.tag.split("}", 1)[1]
            if tag == "LinearTransformation":
                factor = float(child.get("factor", "1"))
                offset = float(child.get("offset", "0"))
            elif tag != "Annotations":
                raise SSPError(f"{where}: mapping entry {e.get('source')!r}: ssc:{tag} is not supported "
                               "(only ssc:LinearTransformation)")
        out[e.get("source")] = (e.get("target"), factor, offset, e.get("suppressUnitConversion") == "true")
    return out


def _from_base(node: ET.Element, src: str, archive: _Archive, fmu_bytes: bytes | None, what: str) -> bytes:
    if node.get("sourceBase", "SSD") == "component":
        if fmu_bytes is None:
            raise SSPError(f"{archive.path}: {what} {src!r} is relative to a component that is not an FMU")
        import io
        try:
            with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as fz:
                return fz.read(src)
        except KeyError:
            raise SSPError(f"{archive.path}: {what} {src!r} is not inside the FMU") from None
    return archive.read(src, what)


def _bindings(element: ET.Element, archive: _Archive, where: str, fmu_bytes: bytes | None):
    """(ParameterSet, prefix, mapping) of each ParameterBinding of an element, in document order."""
    node = element.find(_q(NS_SSD, "ParameterBindings"))
    if node is None:
        return []
    out = []
    for k, b in enumerate(node.findall(_q(NS_SSD, "ParameterBinding"))):
        label = f"{where}, ParameterBinding {k + 1}"
        if b.get("type", SSV_MIME) != SSV_MIME:
            raise SSPError(f"{label}: parameter source type {b.get('type')!r} is not supported ({SSV_MIME} is)")
        src = b.get("source")
        if src:
            if src.startswith(("http://", "https://")):
                raise SSPError(f"{label}: parameter sets from a repository ({src}) are not supported")
            data = _from_base(b, src, archive, fmu_bytes, "parameter set")
            pset = parse_parameter_set(_xml(data, f"{archive.path}:{src}"), f"{archive.path}:{src}")
        else:
            values = b.find(_q(NS_SSD, "ParameterValues"))
            inner = values.find(_q(NS_SSV, "ParameterSet")) if values is not None else None
            if inner is None:
                raise SSPError(f"{label}: neither a source nor inline ssv:ParameterSet values")
            pset = parse_parameter_set(inner, f"{label} (inline)")
        out.append((pset, b.get("prefix", ""), _mapping(b, archive, label, fmu_bytes)))
    return out


def read_ssp(path: str | os.PathLike[str], *, ssd: str = DEFAULT_SSD) -> SSPSystem:
    """Read an ``.ssp`` package (or an unpacked one) whose system holds exactly one FMU component.

    Raises :class:`~twin.errors.SSPError` naming the file and element at fault: a missing or
    invalid SSD, nested systems, other than one FMU component, a missing FMU or parameter file,
    and every parameter problem :func:`twin.ssv.resolve` reports.
    """
    path = Path(path)
    archive = _Archive(path)
    try:
        where = f"{path}:{ssd}"
        root = _xml(archive.read(ssd, "system structure description"), where)
        if root.tag != _q(NS_SSD, "SystemStructureDescription"):
            raise SSPError(f"{where}: expected ssd:SystemStructureDescription ({NS_SSD}), found {root.tag!r}")
        system = root.find(_q(NS_SSD, "System"))
        if system is None:
            raise SSPError(f"{where}: no ssd:System")
        elements = system.find(_q(NS_SSD, "Elements"))
        children = list(elements) if elements is not None else []
        nested = [e.get("name") for e in children if e.tag == _q(NS_SSD, "System")]
        if nested:
            raise SSPError(f"{where}: nested systems ({', '.join(map(str, nested))}) are not supported; "
                           "twin runs a system of one FMU component")
        comps = [e for e in children if e.tag == _q(NS_SSD, "Component")]
        fmus = [c for c in comps if c.get("type", FMU_MIME) == FMU_MIME]
        if len(comps) != 1 or len(fmus) != 1:
            names = ", ".join(f"{c.get('name')} ({c.get('type', FMU_MIME)})" for c in comps) or "none"
            raise SSPError(f"{where}: twin runs an SSP with exactly one FMU component; "
                           f"{system.get('name')!r} has {len(comps)}: {names}")
        comp = fmus[0]
        name = comp.get("name", "")
        if comp.get("implementation", "any") == "ModelExchange":
            raise SSPError(f"{where}: component {name!r} asks for the Model Exchange implementation; "
                           "twin runs FMUs as Co-Simulation")
        src = comp.get("source")
        if not src:
            raise SSPError(f"{where}: component {name!r} has no source")
        fmu_bytes = archive.read(src, f"FMU of component {name!r}")
        digest = hashlib.sha256(fmu_bytes).hexdigest()[:16]
        target = _extraction_dir() / digest / PurePosixPath(src).name
        if not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            tmp = target.with_suffix(".part")
            tmp.write_bytes(fmu_bytes)
            os.replace(tmp, target)
        ssd_units = read_units(root.find(_q(NS_SSD, "Units")), where)
        variables, fmu_units = _fmu_interface(target)
        values: dict[str, Any] = {}
        applied = []
        # component bindings first, then the system's: later and higher bindings take precedence
        for element, scope in ((comp, ""), (system, f"{name}.")):
            for pset, prefix, mapping in _bindings(element, archive, f"{where}, {element.get('name')!r}",
                                                   fmu_bytes):
                values.update(_apply(pset, prefix, mapping, scope, variables, fmu_units, ssd_units))
                applied.append(pset.source)
        exp = {}
        de = root.find(_q(NS_SSD, "DefaultExperiment"))
        if de is not None:
            for key in ("startTime", "stopTime"):
                if de.get(key) is not None:
                    v = float(de.get(key))
                    if not math.isfinite(v):
                        raise SSPError(f"{where}: DefaultExperiment {key} must be finite")
                    exp[key] = v
        return SSPSystem(path, root.get("name", ""), name, target, values, exp, tuple(applied))
    finally:
        archive.close()


def _apply(pset: ParameterSet, prefix: str, mapping: dict, scope: str, variables, fmu_units, ssd_units) -> dict:
    """Resolve one binding's parameter set onto the component's variables."""
    names: dict[str, str] = {}
    entries = []
    outside = []
    for entry in pset.values:
        full = prefix + entry.name
        target, factor, offset, suppress = mapping.get(full, (full, 1.0, 0.0, False))
        if scope:                                  # a system-level name: Component.variable
            if not target.startswith(scope):
                outside.append(full)
                continue
            target = target[len(scope):]
        if (factor, offset) != (1.0, 0.0):
            if entry.type != "Real":
                raise SSPError(f"{pset.source}: a linear transformation maps {entry.name!r}, which is an {entry.type}")
            entry = type(entry)(entry.name, entry.type, factor * entry.value + offset,
                                "" if suppress else entry.unit)
        elif suppress:
            entry = type(entry)(entry.name, entry.type, entry.value, "")
        names[entry.name] = target
        entries.append(entry)
    if outside:
        raise SSPError(f"{pset.source}: system-level parameter(s) {', '.join(map(repr, outside[:10]))} do not "
                       f"name the component ({scope[:-1]}.<variable>)")
    sub = ParameterSet(pset.name, tuple(entries), pset.units, pset.source)
    return resolve(sub, variables, fmu_units, extra_units=ssd_units, names=names)


_SCHEMAS = {".ssd": "SystemStructureDescription.xsd", ".ssv": "SystemStructureParameterValues.xsd",
            ".ssm": "SystemStructureParameterMapping.xsd"}


def validate_ssp(path: str | os.PathLike[str]) -> list[str]:
    """Problems of an ``.ssp`` package (or an unpacked one), ``[]`` when there are none.

    Every ``.ssd``, ``.ssv`` and ``.ssm`` file is checked against the SSP 1.0 XML schemas, then
    the package is read as :func:`read_ssp` reads it (one FMU component, parameters that apply),
    and its FMU is validated like ``fmpy validate``.
    """
    from lxml import etree

    from twin.fmu import validate, xml_schema

    path = Path(path)
    problems: list[str] = []
    archive = _Archive(path)
    try:
        schemas = {}
        for name in archive.names():
            suffix = PurePosixPath(name).suffix
            if suffix not in _SCHEMAS:
                continue
            if suffix not in schemas:
                schemas[suffix] = etree.XMLSchema(etree.parse(str(xml_schema("ssp", _SCHEMAS[suffix]))))
            try:
                doc = etree.fromstring(archive.read(name, "file"))
            except etree.XMLSyntaxError as exc:
                problems.append(f"{name}: not valid XML: {exc}")
                continue
            if not schemas[suffix].validate(doc):
                problems += [f"{name}:{e.line}: {e.message}" for e in schemas[suffix].error_log]
    finally:
        archive.close()
    try:
        system = read_ssp(path)
    except SSPError as exc:
        return problems + [str(exc)]
    return problems + [f"{system.fmu.name}: {p}" for p in validate(system.fmu)]


# ---- writing -------------------------------------------------------------------------------------
def _component_name(model: str) -> str:
    # '.' separates hierarchical names in SSP, so a component name must not contain one
    return model.replace(".", "_") or "model"


def ssd_xml(*, name: str, fmu_file: str, model: str, variables: Mapping[str, Any], bound: Mapping[str, Any],
            ssv_file: str, fmu_units, default_experiment: Mapping[str, float], description: str = "") -> str:
    """SystemStructure.ssd of a system with one FMU component bound to one parameter set."""
    comp = _component_name(model)
    connectors = []
    units_used = []
    for v in sorted(variables.values(), key=lambda v: ({"input": 0, "output": 1}.get(v.causality, 2),
                                                        v.value_reference)):
        kind = v.causality if v.causality in ("input", "output") else ("parameter" if v.name in bound else None)
        if kind is None:
            continue
        vtype = _FMI_TYPE.get(v.type, v.type)
        if vtype == "Real":
            unit = f" unit={quoteattr(v.unit)}" if v.unit else ""
            if v.unit:
                units_used.append(v.unit)
            typed = f"<ssc:Real{unit}/>"
        elif vtype in ("Integer", "Boolean", "String"):
            typed = f"<ssc:{vtype}/>"
        else:
            typed = ""
        connectors.append(f'          <ssd:Connector name={quoteattr(v.name)} kind="{kind}">{typed}</ssd:Connector>')
    conn_xml = ("        <ssd:Connectors>\n" + "\n".join(connectors) + "\n        </ssd:Connectors>\n") \
        if connectors else ""
    exp = default_experiment
    exp_attrs = " ".join(f'{k}="{float(exp[k])!r}"' for k in ("startTime", "stopTime") if k in exp)
    step = exp.get("stepSize")
    osp = ("\n    <ssd:Annotations>\n      <ssc:Annotation type=\"com.opensimulationplatform\">\n"
           f"        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize=\"{float(step)!r}\"/></osp:Algorithm>\n"
           "      </ssc:Annotation>\n    </ssd:Annotations>\n  ") if step else ""
    desc = f" description={quoteattr(description)}" if description else ""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="{NS_SSD}" xmlns:ssc="{NS_SSC}" xmlns:ssv="{NS_SSV}"
  xmlns:osp="{NS_OSP}" version="1.0" name={quoteattr(name)}{desc}
  generationTool="gear-twin" generationDateAndTime="{utc_now()}">
  <ssd:System name={quoteattr(name)}>
    <ssd:Elements>
      <ssd:Component name={quoteattr(comp)} type="{FMU_MIME}" source={quoteattr(fmu_file)} implementation="CoSimulation">
{conn_xml}        <ssd:ParameterBindings>
          <ssd:ParameterBinding type="{SSV_MIME}" source={quoteattr(ssv_file)}/>
        </ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
{units_xml(units_used, fmu_units, 'ssd', '  ')}  <ssd:DefaultExperiment {exp_attrs}>{osp}</ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def _from_text(variable, name: str, value):
    """A value given as text (the command line's ``--param k=60``) in its variable's type; other
    values, text for String variables and names the FMU does not have are left as they are."""
    if not isinstance(value, str) or variable is None or variable.kind == "string":
        return value
    try:
        return variable.coerce(value)
    except ParameterError as exc:
        raise SSPError(f"parameter {name!r}: {exc}") from None


def _enumeration_item(variable, name: str, value):
    """An enumeration variable's value (its item's name or value) as an :class:`EnumerationItem`."""
    if variable is None or variable.kind != "enumeration" or isinstance(value, bool):
        return value
    try:
        item = variable.item_name(variable.coerce(value))
    except ParameterError as exc:
        raise SSPError(f"parameter {name!r}: {exc}") from None
    if item is None:
        raise SSPError(f"parameter {name!r}: {value!r} is no item of {variable.declared_type or 'its enumeration'}")
    return EnumerationItem(item)


def write_ssp(fmu: str | os.PathLike[str], parameters: Mapping[str, Any], out: str | os.PathLike[str], *,
              name: str | None = None, description: str = "") -> Path:
    """Write ``out`` (``.ssp``): the FMU, ``parameters`` as an ``.ssv`` with the FMU's units, and the SSD.

    Every parameter must be a settable variable of the FMU (checked, with the value's type); Real
    values are written in the FMU variable's unit, which the ``.ssv`` and the ``.ssd`` define with
    its BaseUnit. The package is written atomically; on any error nothing is written.
    """
    from twin._atomic import atomic_path
    from twin.fmu import FMU
    from twin.ssv import ParameterValue

    fmu = Path(fmu)
    out = Path(out)
    if out.suffix != ".ssp":
        raise SSPError(f"an SSP package must end in .ssp, got {out.name!r}")
    try:
        with FMU(fmu) as f:
            variables, fmu_units, model = dict(f.variables), f.unit_definitions, f.model_name
            md = f.model_description
            bounds = {v.name: (v.min, v.max) for v in md.modelVariables if v.name in parameters}
            exp = {}
            if md.defaultExperiment is not None:
                for key in ("startTime", "stopTime", "stepSize"):
                    v = getattr(md.defaultExperiment, key, None)
                    if v is not None:
                        exp[key] = float(v)
    except TwinError as exc:
        raise SSPError(f"cannot write an SSP for {fmu}: {exc}") from None
    name = name or out.stem
    parameters = {k: _from_text(variables.get(k), k, v) for k, v in parameters.items()}
    # an enumeration's value is written as its item's name (ssv:Enumeration)
    parameters = {k: _enumeration_item(variables.get(k), k, v) for k, v in parameters.items()}
    # validate every entry against the FMU, exactly as a reader will apply it
    typed = []
    for key, value in parameters.items():
        kind = "Enumeration" if isinstance(value, EnumerationItem) else "Boolean" if isinstance(value, bool) else \
            "Integer" if isinstance(value, int) else "String" if isinstance(value, str) else "Real"
        typed.append(ParameterValue(key, kind, value, ""))
    resolve(ParameterSet(name, tuple(typed), {}, f"parameters for {out.name}"), variables, fmu_units)
    for key, (lo, hi) in bounds.items():
        value = parameters[key]
        if isinstance(value, (bool, str)) or variables[key].kind == "enumeration":
            continue
        if (lo is not None and float(value) < float(lo)) or (hi is not None and float(value) > float(hi)):
            raise SSPError(f"parameter {key!r} = {value!r} is outside its range "
                           f"[{lo if lo is not None else '-inf'}, {hi if hi is not None else 'inf'}] in {fmu.name}")
    units = {k: variables[k].unit for k in parameters if variables[k].unit}
    ssv_name = f"resources/{name}.ssv"
    fmu_name = f"resources/{fmu.name}"
    ssv_text = '<?xml version="1.0" encoding="UTF-8"?>\n' + parameter_set_xml(
        parameters, name=name, units=units, fmu_units=fmu_units, description=description, generated=utc_now()) + "\n"
    ssd_text = ssd_xml(name=name, fmu_file=fmu_name, model=model, variables=variables, bound=parameters,
                       ssv_file=ssv_name, fmu_units=fmu_units, default_experiment=exp, description=description)
    with atomic_path(out) as tmp:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            zf.writestr(DEFAULT_SSD, ssd_text)
            zf.writestr(ssv_name, ssv_text)
            zf.write(fmu, fmu_name)
    return out
