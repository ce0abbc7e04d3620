"""Modelica -> FMI 2.0 or FMI 3.0 FMU (Co-Simulation + Model Exchange, Linux x86-64), compiled here.

Pipeline: subset check -> rumoca flattening -> :mod:`fmu_build.flat` parser ->
:mod:`fmu_build.symbolic` (states-only ODE as CasADi functions) -> CasADi C code
generation with common-subexpression elimination -> generic FMI wrapper
(``templates/fmi2_wrapper.c`` or ``templates/fmi3_wrapper.c`` around ``model_core.h``) -> gcc -> zip.  Builds are cached by a hash of every input
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

from twin.errors import BuildError

BUILDER_VERSION = "5"
DEFAULT_STEP_SIZE = 5e-6
_HERE = Path(__file__).resolve().parent
#: per FMI version: wrapper template, FMI headers, binary directory
_FMI = {2: ("fmi2_wrapper.c", ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"), "linux64"),
        3: ("fmi3_wrapper.c", ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h"), "x86_64-linux")}
CFLAGS = ["-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-std=c99", "-Wall", "-Wno-unused-variable",
          "-Wno-unused-but-set-variable", "-ffp-contract=off"]


def _fmi_headers(fmi_version: int = 2) -> Path:
    import fmpy
    d = Path(fmpy.__file__).parent / "c-code"
    for name in _FMI[fmi_version][1]:
        if not (d / name).exists():
            raise BuildError(f"FMI {fmi_version}.0 header {name} not found in {d}; reinstall fmpy")
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


def _sources_hash(modelica_dir: Path, model: str, step_size: float, fmi_version: int = 2,
                  modifiers: dict | None = None) -> str:
    h = hashlib.sha256()
    h.update(f"{BUILDER_VERSION}|{model}|{step_size!r}|{' '.join(CFLAGS)}".encode())
    if fmi_version != 2:
        h.update(f"|fmi{fmi_version}".encode())
    if modifiers:
        h.update(json.dumps(modifiers, sort_keys=True).encode())
    for f in sorted(modelica_dir.rglob("*")):
        if f.is_file() and f.suffix in (".mo", ".order", ".md"):
            h.update(str(f.relative_to(modelica_dir)).encode())
            h.update(f.read_bytes())
    for f in sorted(_HERE.rglob("*")):
        if f.is_file() and f.suffix in (".py", ".c", ".h"):
            h.update(f.name.encode())
            h.update(f.read_bytes())
    import casadi
    import markdown
    import rumoca
    h.update(f"markdown {markdown.__version__}".encode())
    h.update(f"casadi {casadi.__version__} rumoca {rumoca.version() if callable(getattr(rumoca, 'version', None)) else getattr(rumoca, '__version__', '')}".encode())
    return h.hexdigest()


def flatten(modelica_dir: Path, model: str, modifiers: dict | None = None) -> str:
    """Flat Modelica text of ``model`` rendered by rumoca, after the subset check.

    ``modifiers`` (from :func:`check_modifiers`) are applied as the modification of an
    ``extends`` clause: the model is flattened as ``model <Name> extends <model>(...); end``.
    """
    import rumoca

    from .subset import check_subset

    modelica_dir = Path(modelica_dir).resolve()
    if not modelica_dir.is_dir():
        raise BuildError(f"Modelica directory {modelica_dir} does not exist")
    src = model_file(modelica_dir, model)
    check_subset(modelica_dir, model)
    try:
        session = rumoca.Session(roots=[str(modelica_dir)])
        if not modifiers:
            return session.load(str(src), model=model).render("flat-modelica")
        name = model.rsplit(".", 1)[-1]
        text = _variant_source(name, model, modifiers, _class_description(src, name))
        return session.loads(text, model=name, filename=f"{name}.variant.mo").render("flat-modelica")
    except Exception as exc:  # rumoca raises its own exception family
        what = f" with {_modifier_text(modifiers)}" if modifiers else ""
        raise BuildError(f"rumoca could not compile {model}{what} from {src}:\n{exc}") from exc


def _modifier_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    return "{" + ", ".join(_modifier_value(v) for v in value) + "}"


def _modifier_text(modifiers: dict) -> str:
    return ", ".join(f"{k} = {_modifier_value(v)}" for k, v in modifiers.items())


def _class_description(src: Path, name: str) -> str:
    import re
    m = re.search(r"\b(?:model|block|class)\s+" + re.escape(name) + r'\s+"((?:[^"\\]|\\.)*)"', src.read_text())
    return m.group(1) if m else ""


def _variant_source(name: str, model: str, modifiers: dict, description: str) -> str:
    """A class that only extends ``model`` with ``modifiers`` (no equations of its own)."""
    shown = ", ".join(f"{k} = {_modifier_value(v)}" for k, v in modifiers.items()
                      if not isinstance(v, (list, tuple)))
    desc = f"{description} (built with {shown})" if shown else description
    desc = desc.replace("\\", "\\\\").replace('"', '\\"')
    return f'model {name} "{desc}"\n  extends {model}({_modifier_text(modifiers)});\nend {name};\n'


def _plain_modifiers(modifiers) -> dict:
    """``modifiers`` as a dict of numbers, booleans and lists of numbers (nothing else)."""
    out = {}
    for name, value in dict(modifiers or {}).items():
        if not (isinstance(name, str) and name.isidentifier()):
            raise BuildError(f"bad build option: parameter name must be an identifier, got {name!r}")
        if isinstance(value, (bool, int, float)):
            out[name] = value
        elif isinstance(value, (list, tuple)) and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            out[name] = [float(v) for v in value]
        else:
            raise BuildError(f"bad build option {name!r}: needs a number, a boolean or a list of numbers, "
                             f"got {value!r}")
    return out


def check_modifiers(modelica_dir: Path | str, model: str, modifiers) -> dict:
    """Validate build-time modifications of ``model``'s parameters; return them normalised.

    ``modifiers`` maps parameter names to values: an ``int`` for a structural ``Integer``
    (``z1``, ``n_profile``), ``True``/``False`` for a ``Boolean``, a finite number for a
    ``Real`` scalar and a sequence of finite numbers for a ``Real`` array (its length is
    checked once the structural values are applied).  A Real value becomes the parameter's
    default (it stays tunable).  Raises :class:`BuildError` naming each bad entry.
    """
    import math

    if not modifiers:
        return {}
    decls = _declarations(flatten(modelica_dir, model))
    problems, out = [], {}
    for name, value in modifiers.items():
        d = decls.get(name)
        if d is None or d[0] != "parameter":
            what = "is not a parameter of" if d is not None else "is not declared in"
            problems.append(f"{name!r} {what} {model}")
            continue
        if d[1] == "Integer":
            ok = isinstance(value, int) and not isinstance(value, bool) or (
                isinstance(value, float) and value.is_integer())
            if not ok:
                problems.append(f"{name!r} is a structural Integer of {model}, got {value!r}")
                continue
            out[name] = int(value)
        elif d[1] == "Boolean":
            if not isinstance(value, bool):
                problems.append(f"{name!r} is a structural Boolean of {model}, got {value!r}")
                continue
            out[name] = value
        elif d[2]:
            try:
                vals = [float(v) for v in value]
            except (TypeError, ValueError):
                problems.append(f"{name!r} is a Real array of {model}, needs a list of numbers, got {value!r}")
                continue
            if not vals or not all(math.isfinite(v) for v in vals):
                problems.append(f"{name!r} needs finite numbers, got {value!r}")
                continue
            out[name] = vals
        else:
            try:
                v = float(value)
            except (TypeError, ValueError):
                problems.append(f"{name!r} is a Real parameter of {model}, needs a number, got {value!r}")
                continue
            if isinstance(value, bool) or not math.isfinite(v):
                problems.append(f"{name!r} needs a finite number, got {value!r}")
                continue
            out[name] = v
    if problems:
        raise BuildError("bad build option(s): " + "; ".join(problems))
    return out


_DECLARATION = None


def _declarations(flat_text: str) -> dict[str, tuple[str, str, str]]:
    """``{name: (prefix, type, dims)}`` of the declarations in rumoca's flat text (dims as
    written, e.g. ``"18"``; empty for scalars).  A light scan: the full parser is not needed
    to check build options."""
    import re
    global _DECLARATION
    if _DECLARATION is None:
        _DECLARATION = re.compile(r"^\s*(?:(parameter|constant|input|output)\s+)?(Real|Integer|Boolean)"
                                  r"(?:\[([^\]]*)\])?\s+([A-Za-z_][\w.]*)", re.M)
    return {m.group(4): (m.group(1) or "", m.group(2), m.group(3) or "") for m in _DECLARATION.finditer(flat_text)}


def _check_array_sizes(flat_text: str, modifiers: dict, model: str) -> None:
    """A list modifier must have the length its array gets with the structural values applied."""
    decls = _declarations(flat_text)
    problems = []
    for name, value in modifiers.items():
        if isinstance(value, list):
            dims = decls.get(name, ("", "", ""))[2]
            if dims.strip().isdigit() and int(dims) != len(value):
                problems.append(f"{name!r} has {int(dims)} elements in this build, got {len(value)}")
    if problems:
        raise BuildError(f"bad build option(s) for {model}: " + "; ".join(problems))


def variant_name(model: str, modifiers: dict | None) -> str:
    """File stem of the FMU built from ``model`` with ``modifiers``: ``model`` without any, else
    ``model`` followed by the scalar modifiers (``GearTwin.Gearbox21-z1_18-z2_35``) and, when
    arrays are modified too, a short hash of them."""
    if not modifiers:
        return model
    parts = [f"{k}_{_modifier_value(v)}" for k, v in sorted(modifiers.items()) if not isinstance(v, list)]
    arrays = {k: v for k, v in modifiers.items() if isinstance(v, list)}
    if arrays:
        parts.append(hashlib.sha256(json.dumps(arrays, sort_keys=True).encode()).hexdigest()[:8])
    stem = "-".join([model, *parts])
    safe = "".join(c if c.isalnum() or c in "._-" else "_" for c in stem)
    return safe if len(safe) <= 120 else model + "-" + hashlib.sha256(stem.encode()).hexdigest()[:12]


def build_fmu(model: str = "GearTwin.Gearbox21", modelica_dir: Path | str = "modelica",
              out_dir: Path | str = "build", *, step_size: float = DEFAULT_STEP_SIZE,
              force: bool = False, fmi_version: int = 2, modifiers=None, name: str | None = None) -> Path:
    """Build ``<out_dir>/<model>.fmu`` from ``<modelica_dir>`` and return its path.

    Parameters
    ----------
    model : full Modelica name, e.g. ``"GearTwin.Gearbox21"``.
    step_size : default internal RK4 step [s] (the FMU parameter ``solver.step_size``).
    force : rebuild even when the cache says the FMU is current.
    fmi_version : 2 (FMI 2.0) or 3 (FMI 3.0); both run the same generated code and solver.
    modifiers : build options, ``{parameter: value}``; structural Integers (``z1``,
        ``n_profile``) resize the model, Real values become defaults (:func:`check_modifiers`).
        The FMU is then ``<out_dir>/<name>.fmu`` with ``name`` defaulting to
        :func:`variant_name`, and the cache key covers the modifiers.
    """
    if not (step_size > 0):
        raise BuildError(f"step_size must be > 0 s, got {step_size!r}")
    if fmi_version not in _FMI:
        raise BuildError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    modelica_dir = Path(modelica_dir).resolve()
    out_dir = Path(out_dir)
    if not modelica_dir.is_dir():
        raise BuildError(f"Modelica directory {modelica_dir} does not exist")
    if not out_dir.parent.exists():
        raise BuildError(f"output directory's parent {out_dir.parent} does not exist")
    out_dir.mkdir(exist_ok=True)
    mods = _plain_modifiers(modifiers)
    stem = name or variant_name(model, mods)
    if not stem or any(not (c.isalnum() or c in "._-") for c in stem):
        raise BuildError(f"FMU name must use letters, digits, '.', '_' and '-' only, got {stem!r}")
    digest = _sources_hash(modelica_dir, model, step_size, fmi_version, mods)
    fmu_path = out_dir / f"{stem}.fmu"
    stamp = out_dir / f".{stem}.fmu.hash"
    if not force and fmu_path.exists() and stamp.exists() and stamp.read_text().strip() == digest:
        return fmu_path

    from . import description
    from .annotations import default_experiment, library_metadata
    from .flat import parse_flat
    from .structure import model_structure
    from .symbolic import build_ode

    src_file = model_file(modelica_dir, model)
    experiment = default_experiment(src_file, model.split(".")[-1])
    metadata = library_metadata(modelica_dir, model)
    mods = check_modifiers(modelica_dir, model, mods)
    if any(isinstance(v, list) for v in mods.values()):
        # array lengths follow the structural values: check them on the model resized first,
        # so that a wrong length is named (rumoca reports a bare shape mismatch)
        scalars = {k: v for k, v in mods.items() if not isinstance(v, list)}
        _check_array_sizes(flatten(modelica_dir, model, scalars), mods, model)
    flat_text = flatten(modelica_dir, model, mods)
    ode = build_ode(parse_flat(flat_text))
    identifier = "".join(c if c.isalnum() else "_" for c in stem)
    guid = "{" + digest[:8] + "-" + digest[8:12] + "-" + digest[12:16] + "-" + digest[16:20] + "-" + digest[20:32] + "}"
    info = description.BuildInfo(model=model, identifier=identifier, guid=guid, step_size=step_size,
                                 builder_version=BUILDER_VERSION, experiment=experiment, metadata=metadata,
                                 generated=description.generation_time())
    structure = model_structure(ode)
    readme = src_file.with_name(f"{model.split('.')[-1]}.readme.md")

    wrapper, headers, platform = _FMI[fmi_version]
    with tempfile.TemporaryDirectory(prefix="fmu_build_") as tmp:
        tmp = Path(tmp)
        root = tmp / "fmu"
        (root / "sources").mkdir(parents=True)
        (root / "binaries" / platform).mkdir(parents=True)
        (root / "documentation").mkdir()
        prefix = "m" + digest[:10]
        _generate_c(ode, root / "sources", prefix, guid, step_size)
        shutil.copy(_HERE / "templates" / wrapper, root / "sources" / wrapper)
        for header in ("twin_math.h", "model_core.h"):
            shutil.copy(_HERE / "templates" / header, root / "sources" / header)
        hdr = _fmi_headers(fmi_version)
        for name in headers:
            shutil.copy(hdr / name, root / "sources" / name)
        (root / "sources" / "model_flat.mo").write_text(flat_text)
        md = description.fmi2(ode, info, structure) if fmi_version == 2 else description.fmi3(ode, info, structure)
        (root / "modelDescription.xml").write_text(md, encoding="utf-8")
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(description.build_description_fmi3(info),
                                                                   encoding="utf-8")
        (root / "documentation" / "index.html").write_text(description.documentation_html(ode, info, readme),
                                                           encoding="utf-8")
        so = root / "binaries" / platform / f"{identifier}.so"
        cmd = ["gcc", *CFLAGS, "-I", str(root / "sources"), "-o", str(so),
               str(root / "sources" / wrapper), str(root / "sources" / "model_functions.c"), "-lm"]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True)
        except FileNotFoundError as exc:
            raise BuildError("gcc not found; a C compiler is needed to build FMUs") from exc
        if proc.returncode != 0:
            raise BuildError(f"gcc failed for {model}:\n{proc.stderr[-4000:]}")
        tmp_fmu = out_dir / f".{stem}.fmu.tmp"
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


def _c_double(v: float | None, missing: str) -> str:
    if v is None:
        return missing
    return repr(float(v))


def _c_array(values, missing: str = "0.0") -> str:
    vals = list(values)
    if not vals:
        return "{0}"
    return "{" + ", ".join(_c_double(v, missing) for v in vals) + "}"


def _c_names(variables) -> str:
    return "{" + (", ".join(json.dumps(v.name) for v in variables) or '""') + "}"


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
    from .description import layout

    lay = layout(ode)
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
static const double P_MIN[{max(np_, 1)}] = {_c_array((v.min for v in ode.parameters), "-INFINITY")};
static const double P_MAX[{max(np_, 1)}] = {_c_array((v.max for v in ode.parameters), "INFINITY")};
static const double U_MIN[{max(nu, 1)}] = {_c_array((v.min for v in ode.inputs), "-INFINITY")};
static const double U_MAX[{max(nu, 1)}] = {_c_array((v.max for v in ode.inputs), "INFINITY")};
static const double X_NOMINAL[{max(nx, 1)}] = {_c_array((v.nominal for v in ode.states), "1.0")};
static const char *const P_NAMES[{max(np_, 1)}] = {_c_names(ode.parameters)};
static const char *const U_NAMES[{max(nu, 1)}] = {_c_names(ode.inputs)};
static const char *STATE_NAMES[{max(nx, 1)}] = {_c_names(ode.states)};
#endif
"""
    (src / "model_info.h").write_text(info)


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m fmu_build", description="Build FMI 2.0 or 3.0 FMUs from Modelica models.")
    ap.add_argument("models", nargs="*", default=["GearTwin.Gearbox21"])
    ap.add_argument("--modelica-dir", default="modelica")
    ap.add_argument("--out", default="build")
    ap.add_argument("--step-size", type=float, default=DEFAULT_STEP_SIZE)
    ap.add_argument("--force", action="store_true")
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default: 2)")
    args = ap.parse_args(argv)
    from twin.errors import TwinError
    try:
        for m in args.models:
            print(build_fmu(m, args.modelica_dir, args.out, step_size=args.step_size, force=args.force,
                            fmi_version=args.fmi))
    except TwinError as exc:
        print(f"fmu_build: error: {exc}", file=sys.stderr)
        return 2
    return 0
