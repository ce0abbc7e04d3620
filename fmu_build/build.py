"""Modelica -> FMI 2.0 FMU (Co-Simulation + Model Exchange, linux64), compiled here.

Pipeline: subset check -> rumoca flattening -> :mod:`fmu_build.flat` parser ->
:mod:`fmu_build.symbolic` (states-only ODE as CasADi functions) -> CasADi C code
generation with common-subexpression elimination -> generic FMI wrapper
(``templates/fmi2_wrapper.c``) -> gcc -> zip.  Builds are cached by a hash of every input
(sources, builder code, options), and the archive is byte-for-byte reproducible.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.sax.saxutils import escape

from twin.errors import BuildError

BUILDER_VERSION = "4"
DEFAULT_STEP_SIZE = 5e-6
_HERE = Path(__file__).resolve().parent
_TEMPLATE = _HERE / "templates" / "fmi2_wrapper.c"
CFLAGS = ["-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-std=c99", "-Wall", "-Wno-unused-variable",
          "-Wno-unused-but-set-variable", "-ffp-contract=off"]


def _fmi_headers() -> Path:
    import fmpy
    d = Path(fmpy.__file__).parent / "c-code"
    if not (d / "fmi2Functions.h").exists():
        raise BuildError(f"FMI 2.0 headers not found in {d}; reinstall fmpy")
    return d


def model_file(modelica_dir: Path, model: str) -> Path:
    """Source file of a model given by its full name (package directory layout)."""
    parts = model.split(".")
    for k in range(len(parts), 0, -1):
        cand = modelica_dir.joinpath(*parts[:k]).with_suffix(".mo")
        if cand.exists():
            return cand
        pkg = modelica_dir.joinpath(*parts[:k], "package.mo")
        if pkg.exists():
            return pkg
    raise BuildError(f"model {model!r} not found under {modelica_dir} "
                     f"(looked for {'/'.join(parts)}.mo and package.mo files)")


def _sources_hash(modelica_dir: Path, model: str, step_size: float) -> str:
    h = hashlib.sha256()
    h.update(f"{BUILDER_VERSION}|{model}|{step_size!r}|{' '.join(CFLAGS)}".encode())
    for f in sorted(modelica_dir.rglob("*")):
        if f.is_file() and f.suffix in (".mo", ".order"):
            h.update(str(f.relative_to(modelica_dir)).encode())
            h.update(f.read_bytes())
    for f in sorted(_HERE.rglob("*")):
        if f.is_file() and f.suffix in (".py", ".c", ".h"):
            h.update(f.name.encode())
            h.update(f.read_bytes())
    import casadi
    import rumoca
    h.update(f"casadi {casadi.__version__} rumoca {rumoca.version() if callable(getattr(rumoca, 'version', None)) else getattr(rumoca, '__version__', '')}".encode())
    return h.hexdigest()


def flatten(modelica_dir: Path, model: str) -> str:
    """Flat Modelica text of ``model`` rendered by rumoca, after the subset check."""
    import rumoca

    from .subset import check_subset

    modelica_dir = Path(modelica_dir).resolve()
    if not modelica_dir.is_dir():
        raise BuildError(f"Modelica directory {modelica_dir} does not exist")
    src = model_file(modelica_dir, model)
    check_subset(modelica_dir, model)
    try:
        session = rumoca.Session(roots=[str(modelica_dir)])
        compiled = session.load(str(src), model=model)
        return compiled.render("flat-modelica")
    except Exception as exc:  # rumoca raises its own exception family
        raise BuildError(f"rumoca could not compile {model} from {src}:\n{exc}") from exc


def build_fmu(model: str = "GearTwin.Gearbox21", modelica_dir: Path | str = "modelica",
              out_dir: Path | str = "build", *, step_size: float = DEFAULT_STEP_SIZE,
              force: bool = False) -> Path:
    """Build ``<out_dir>/<model>.fmu`` from ``<modelica_dir>`` and return its path.

    Parameters
    ----------
    model : full Modelica name, e.g. ``"GearTwin.Gearbox21"``.
    step_size : default internal RK4 step [s] (the FMU parameter ``solver.step_size``).
    force : rebuild even when the cache says the FMU is current.
    """
    if not (step_size > 0):
        raise BuildError(f"step_size must be > 0 s, got {step_size!r}")
    modelica_dir = Path(modelica_dir).resolve()
    out_dir = Path(out_dir)
    if not modelica_dir.is_dir():
        raise BuildError(f"Modelica directory {modelica_dir} does not exist")
    if not out_dir.parent.exists():
        raise BuildError(f"output directory's parent {out_dir.parent} does not exist")
    out_dir.mkdir(exist_ok=True)
    digest = _sources_hash(modelica_dir, model, step_size)
    fmu_path = out_dir / f"{model}.fmu"
    stamp = out_dir / f".{model}.fmu.hash"
    if not force and fmu_path.exists() and stamp.exists() and stamp.read_text().strip() == digest:
        return fmu_path

    from .flat import parse_flat
    from .symbolic import build_ode

    flat_text = flatten(modelica_dir, model)
    ode = build_ode(parse_flat(flat_text))
    identifier = model.replace(".", "_")
    guid = "{" + digest[:8] + "-" + digest[8:12] + "-" + digest[12:16] + "-" + digest[16:20] + "-" + digest[20:32] + "}"

    with tempfile.TemporaryDirectory(prefix="fmu_build_") as tmp:
        tmp = Path(tmp)
        root = tmp / "fmu"
        (root / "sources").mkdir(parents=True)
        (root / "binaries" / "linux64").mkdir(parents=True)
        prefix = "m" + digest[:10]
        _generate_c(ode, root / "sources", prefix, guid, step_size)
        shutil.copy(_TEMPLATE, root / "sources" / "fmi2_wrapper.c")
        shutil.copy(_HERE / "templates" / "twin_math.h", root / "sources" / "twin_math.h")
        hdr = _fmi_headers()
        for name in ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"):
            shutil.copy(hdr / name, root / "sources" / name)
        (root / "sources" / "model_flat.mo").write_text(flat_text)
        (root / "modelDescription.xml").write_text(_model_description(ode, identifier, guid, step_size, model),
                                                  encoding="utf-8")
        (root / "sources" / "buildDescription.xml").write_text(
            '<?xml version="1.0" encoding="UTF-8"?>\n<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{identifier}">\n'
            '    <SourceFileSet language="C99">\n'
            '      <SourceFile name="fmi2_wrapper.c"/>\n      <SourceFile name="model_functions.c"/>\n'
            '    </SourceFileSet>\n    <Library name="m"/>\n  </BuildConfiguration>\n</fmiBuildDescription>\n')
        so = root / "binaries" / "linux64" / f"{identifier}.so"
        cmd = ["gcc", *CFLAGS, "-I", str(root / "sources"), "-o", str(so),
               str(root / "sources" / "fmi2_wrapper.c"), str(root / "sources" / "model_functions.c"), "-lm"]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True)
        except FileNotFoundError as exc:
            raise BuildError("gcc not found; a C compiler is needed to build FMUs") from exc
        if proc.returncode != 0:
            raise BuildError(f"gcc failed for {model}:\n{proc.stderr[-4000:]}")
        tmp_fmu = out_dir / f".{model}.fmu.tmp"
        _zip_reproducible(root, tmp_fmu)
        os.replace(tmp_fmu, fmu_path)
    stamp.write_text(digest + "\n")
    return fmu_path


def _zip_reproducible(root: Path, target: Path) -> None:
    with zipfile.ZipFile(target, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for f in sorted(p for p in root.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(str(f.relative_to(root)), date_time=(2000, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, f.read_bytes())


def _c_array(values) -> str:
    vals = list(values)
    if not vals:
        return "{0}"
    return "{" + ", ".join(repr(float(v)) for v in vals) + "}"


def _generate_c(ode, src: Path, prefix: str, guid: str, step_size: float) -> None:
    import casadi as ca

    opts = {"cse": True}
    funcs = []
    for f, tag in ((ode.rhs, "rhs"), (ode.outputs_fn, "out"), (ode.init, "init"), (ode.derived, "derived")):
        ins = f.sx_in()
        funcs.append(ca.Function(f"{prefix}_{tag}", ins, f.call(ins), opts))
    # xdot and y together: at an output sample the wrapper needs both at the same (t, x), and
    # CSE shares the mesh computation between them (the next RK4 stage reuses xdot).
    ins = ode.rhs.sx_in()
    funcs.append(ca.Function(f"{prefix}_rhsout", ins, [*ode.rhs.call(ins), *ode.outputs_fn.call(ins)], opts))
    cg = ca.CodeGenerator("model_functions.c", {"with_header": False, "prefix": f"{prefix}_"})
    for f in funcs:
        cg.add(f)
    cg.generate(str(src) + os.sep)
    generated = src / "model_functions.c"
    generated.write_text('#include "twin_math.h"\n' + generated.read_text())
    nx, nu, ny, np_, nq = (len(ode.states), len(ode.inputs), len(ode.outputs), len(ode.parameters),
                           len(ode.calculated))
    lay = _layout(ode)
    names = ", ".join(json.dumps(v.name) for v in ode.states) or '""'
    info = f"""/* Generated by fmu_build {BUILDER_VERSION}: sizes and defaults of {ode.name}. */
#ifndef MODEL_INFO_H
#define MODEL_INFO_H
#define MODEL_GUID "{guid}"
#define N_X {nx}
#define N_U {nu}
#define N_Y {ny}
#define N_P {np_}
#define N_Q {nq}
#define N_QALL {nq + ode.n_hidden}
#define N_C_ {len(ode.constants)}
#define VR_P0 {lay['p']}
#define VR_Q0 {lay['q']}
#define VR_U0 {lay['u']}
#define VR_Y0 {lay['y']}
#define VR_X0 {lay['x']}
#define VR_DX0 {lay['dx']}
#define VR_STEP {lay['step']}
#define VR_OUTPUT_INTERVAL {lay['out']}
#define VR_END {lay['end']}
#define DEFAULT_STEP_SIZE {step_size!r}
#define FN_RHS {prefix}_rhs
#define FN_RHS_WORK {prefix}_rhs_work
#define FN_OUT {prefix}_out
#define FN_OUT_WORK {prefix}_out_work
#define FN_INIT {prefix}_init
#define FN_INIT_WORK {prefix}_init_work
#define FN_DERIVED {prefix}_derived
#define FN_DERIVED_WORK {prefix}_derived_work
#define FN_RHSOUT {prefix}_rhsout
#define FN_RHSOUT_WORK {prefix}_rhsout_work
static const double P_DEFAULT[{max(np_, 1)}] = {_c_array(v.start for v in ode.parameters)};
static const double U_DEFAULT[{max(nu, 1)}] = {_c_array(v.start for v in ode.inputs)};
static const int C_VALUES[{max(len(ode.constants), 1)}] = {{{', '.join(str(int(v.start)) for v in ode.constants) or '0'}}};
static const char *STATE_NAMES[{max(nx, 1)}] = {{{names}}};
#endif
"""
    (src / "model_info.h").write_text(info)


def _layout(ode) -> dict:
    p = 0
    q = p + len(ode.parameters)
    u = q + len(ode.calculated)
    y = u + len(ode.inputs)
    x = y + len(ode.outputs)
    dx = x + len(ode.states)
    step = dx + len(ode.states)
    return {"p": p, "q": q, "u": u, "y": y, "x": x, "dx": dx, "step": step, "out": step + 1, "end": step + 2}


def _model_description(ode, identifier: str, guid: str, step_size: float, model: str) -> str:
    lay = _layout(ode)
    units = sorted({v.unit for v in [*ode.parameters, *ode.calculated, *ode.inputs, *ode.outputs, *ode.states]
                    if v.unit} | {f"{v.unit}/s" for v in ode.states if v.unit} | {"s"})
    rows = []
    index = {}

    def add(vr, v, causality, variability, initial=None, start=None, extra="", type_="Real"):
        index[(type_, vr)] = len(rows) + 1
        attrs = [f'name="{escape(v.name, {chr(34): "&quot;"})}"', f'valueReference="{vr}"']
        if v.description:
            attrs.append(f'description="{escape(v.description, {chr(34): "&quot;"})}"')
        attrs += [f'causality="{causality}"', f'variability="{variability}"']
        if initial:
            attrs.append(f'initial="{initial}"')
        inner = []
        if v.unit and type_ == "Real":
            inner.append(f'unit="{escape(v.unit)}"')
        if start is not None:
            inner.append(f'start="{start!r}"' if type_ == "Real" else f'start="{int(start)}"')
        rows.append(f'    <ScalarVariable {" ".join(attrs)}>\n      <{type_} {" ".join(inner)}{extra}/>\n    </ScalarVariable>')

    for i, v in enumerate(ode.parameters):
        add(lay["p"] + i, v, "parameter", "tunable", "exact", float(v.start))
    for i, v in enumerate(ode.calculated):
        add(lay["q"] + i, v, "calculatedParameter", "tunable", "calculated")
    for i, v in enumerate(ode.inputs):
        add(lay["u"] + i, v, "input", "continuous", None, float(v.start))
    for i, v in enumerate(ode.outputs):
        add(lay["y"] + i, v, "output", "continuous", "calculated")
    for i, v in enumerate(ode.states):
        add(lay["x"] + i, v, "local", "continuous", "calculated")
    for i, v in enumerate(ode.states):
        from .symbolic import Variable
        dv = Variable(f"der({v.name})", "derivative", f"{v.unit}/s" if v.unit else "", f"Time derivative of {v.name}")
        add(lay["dx"] + i, dv, "local", "continuous", "calculated",
            extra=f' derivative="{index[("Real", lay["x"] + i)]}"')
    from .symbolic import Variable
    add(lay["step"], Variable("solver.step_size", "", "s", "Largest internal Runge-Kutta 4 step of the co-simulation"),
        "parameter", "tunable", "exact", float(step_size))
    add(lay["out"], Variable("solver.output_interval", "", "s",
                             "Interval of the outputs buffered inside each doStep (0 = off)"),
        "parameter", "tunable", "exact", 0.0)
    for i, v in enumerate(ode.constants):
        add(i, v, "local", "constant", "exact", v.start, type_="Integer")

    unit_defs = "\n".join(f'    <Unit name="{escape(u)}"/>' for u in units)
    outputs_xml = "\n".join(f'      <Unknown index="{index[("Real", lay["y"] + i)]}"/>' for i in range(len(ode.outputs)))
    ders_xml = "\n".join(f'      <Unknown index="{index[("Real", lay["dx"] + i)]}"/>' for i in range(len(ode.states)))
    init_idx = sorted([index[("Real", lay["y"] + i)] for i in range(len(ode.outputs))] +
                      [index[("Real", lay["q"] + i)] for i in range(len(ode.calculated))] +
                      [index[("Real", lay["x"] + i)] for i in range(len(ode.states))] +
                      [index[("Real", lay["dx"] + i)] for i in range(len(ode.states))])
    init_xml = "\n".join(f'      <Unknown index="{i}"/>' for i in init_idx)
    desc = escape(ode.description or model, {'"': "&quot;"})
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{escape(model)}" guid="{guid}" description="{desc}"
  generationTool="gear-twin fmu_build {BUILDER_VERSION} (rumoca + CasADi + gcc)" variableNamingConvention="structured"
  numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="{identifier}" canGetAndSetFMUstate="true" canSerializeFMUstate="true"
    completedIntegratorStepNotNeeded="true" canNotUseMemoryManagementFunctions="true">
    <SourceFiles>
      <File name="fmi2_wrapper.c"/>
      <File name="model_functions.c"/>
    </SourceFiles>
  </ModelExchange>
  <CoSimulation modelIdentifier="{identifier}" canHandleVariableCommunicationStepSize="true"
    canGetAndSetFMUstate="true" canSerializeFMUstate="true" canNotUseMemoryManagementFunctions="true">
    <SourceFiles>
      <File name="fmi2_wrapper.c"/>
      <File name="model_functions.c"/>
    </SourceFiles>
  </CoSimulation>
  <UnitDefinitions>
{unit_defs}
  </UnitDefinitions>
  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="{step_size!r}"/>
  <ModelVariables>
{chr(10).join(rows)}
  </ModelVariables>
  <ModelStructure>
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
"""


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m fmu_build", description="Build FMI 2.0 FMUs from Modelica models.")
    ap.add_argument("models", nargs="*", default=["GearTwin.Gearbox21"])
    ap.add_argument("--modelica-dir", default="modelica")
    ap.add_argument("--out", default="build")
    ap.add_argument("--step-size", type=float, default=DEFAULT_STEP_SIZE)
    ap.add_argument("--force", action="store_true")
    args = ap.parse_args(argv)
    from twin.errors import TwinError
    try:
        for m in args.models:
            print(build_fmu(m, args.modelica_dir, args.out, step_size=args.step_size, force=args.force))
    except TwinError as exc:
        print(f"fmu_build: error: {exc}", file=sys.stderr)
        return 2
    return 0
