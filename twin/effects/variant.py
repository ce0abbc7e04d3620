"""Write Modelica variants of the base gearbox with effect components wired in.

A variant is a readable ``.mo`` file in ``modelica/GearTwin/Variants/``::

    within GearTwin.Variants;
    model Gearbox21_housing_mode "GearTwin.Gearbox21 with: housing_mode"
      extends GearTwin.Gearbox21(
        effect_sensor_acceleration_pinion = housing_mode.extra_acceleration);
      GearTwin.Effects.SensorMountMode housing_mode(
        base_acceleration = casing_acceleration_pinion,
        frequency = 2480.0, damping_ratio = 0.021, participation = 0.9) "Casing or sensor-mount mode";
    end Gearbox21_housing_mode;

Variants written by ``twin add-effect`` carry a short hash of their effects and values in their
name (``Gearbox21_housing_mode_3f9c1a2b``): two gearboxes given the same effect with different
fitted values get two models and two FMUs, so neither run overwrites the other, and a scenario
always points at the FMU of its own values.

The same text is what a user writes by hand for an effect of their own. Hooks that several
effects drive are summed. ``GearTwin.Variants.Gearbox21Candidates`` carries every catalogue
effect at its neutral values; :mod:`twin.effects.diagnose` turns the effects on one at a time in
that single FMU instead of building one FMU per candidate.
"""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path

from twin.effects.catalogue import CATALOGUE, effect

BASE_MODEL = "GearTwin.Gearbox21"
#: The base gearbox as its sensors measure it (broadband excitation, transfer paths).
MEASURED_MODEL = "GearTwin.Gearbox21Measured"
#: The models with the casing in the loop, each with a parameter only it (and what extends it)
#: has, most derived first: every one extends GearTwin.Gearbox21 without binding its effect
#: hooks, so the catalogue's effects wire into them as into the base.
CASING_MODELS = (("end_mass4", "GearTwin.Gearbox21Overhangs"),
                 ("housing_height", "GearTwin.Gearbox21TiltingWalls"),
                 ("wall_thickness", "GearTwin.Gearbox21Walls"),
                 ("d_shaft_input", "GearTwin.Gearbox21Shafts"),
                 ("m_casing", "GearTwin.Gearbox21Casing"))
BASE_MODELS = (BASE_MODEL, MEASURED_MODEL, *(m for _, m in reversed(CASING_MODELS)))
VARIANTS_PACKAGE = "GearTwin.Variants"
CANDIDATES_MODEL = f"{VARIANTS_PACKAGE}.Gearbox21Candidates"


def candidates_model(base: str = BASE_MODEL) -> str:
    """The candidate model of a base model: ``GearTwin.Variants.<Base>Candidates``."""
    _check_base(base)
    return f"{VARIANTS_PACKAGE}.{base.rsplit('.', 1)[-1]}Candidates"


def base_of(parameter_names) -> str:
    """The base model an FMU extends, read from its parameters: a model of :data:`CASING_MODELS`
    by its own parameter, else :data:`MEASURED_MODEL` when it has a sensor model, else
    :data:`BASE_MODEL`."""
    names = set(parameter_names)
    for marker, model in CASING_MODELS:
        if marker in names:
            return model
    return MEASURED_MODEL if any(n.startswith("sensor_pinion.") for n in names) else BASE_MODEL


def _check_base(base: str) -> None:
    if base not in BASE_MODELS:
        from twin.errors import ParameterError
        raise ParameterError(f"effects extend {', '.join(BASE_MODELS)}, not {base!r}")
_REPO_MODELICA = Path(__file__).resolve().parents[2] / "modelica"


def _number(v: float) -> str:
    return repr(float(v))


def variant_name(effect_ids: Sequence[str], values: Mapping[str, float] | None = None, *,
                 base: str = BASE_MODEL) -> str:
    """``GearTwin.Variants.<Base>_<id>_<id>..._<hash>`` in catalogue order.

    ``<hash>`` (8 hex digits) is taken over the effect ids and ``values``, so different fitted
    values give different models; without ``values`` the name has no hash.
    """
    import hashlib
    _check_base(base)
    ordered = [e for e in CATALOGUE if e in set(effect_ids)]
    name = f"{VARIANTS_PACKAGE}.{base.rsplit('.', 1)[-1]}_" + "_".join(ordered)
    if values is None:
        return name
    text = ";".join(ordered) + "|" + ";".join(f"{k}={_number(v)}" for k, v in sorted(values.items()))
    return name + "_" + hashlib.sha256(text.encode()).hexdigest()[:8]


def variant_source(effect_ids: Sequence[str], values: Mapping[str, float] | None = None, *,
                   name: str | None = None, description: str | None = None, base: str = BASE_MODEL) -> str:
    """Modelica text of the base model with the given effects.

    ``values`` maps FMU parameter names (``housing_mode.frequency``) to the values written as
    modifiers; they become the FMU defaults. The default ``name`` is :func:`variant_name` of the
    effects and these values.
    """
    ids = [e for e in CATALOGUE if e in set(effect_ids)]
    unknown = sorted(set(effect_ids) - set(CATALOGUE))
    if unknown:
        effect(unknown[0])          # raises with the catalogue listed
    if not ids:
        from twin.errors import ParameterError
        raise ParameterError("a variant needs at least one effect")
    values = dict(values or {})
    own = {k: v for k, v in values.items() if k.split('.', 1)[0] in ids}
    name = name or variant_name(ids, own or None, base=base)
    short = name.rsplit(".", 1)[-1]
    hooks: dict[str, list[str]] = {}
    bindings: dict[str, str] = {}
    for i in ids:
        e = CATALOGUE[i]
        for hook, out in e.hooks.items():
            hooks.setdefault(hook, []).append(f"{i}.{out}")
        for par, comp in e.base_bindings.items():
            bindings[par] = f"{i}.{comp}"
    mods = [f"{h} = {' + '.join(v)}" for h, v in hooks.items()] + [f"{p} = {c}" for p, c in bindings.items()]
    lines = ["within GearTwin.Variants;",
             f'model {short} "{description or base + " with: " + ", ".join(ids)}"',
             f"  extends {base}(", "    " + ",\n    ".join(mods) + ");"]
    for i in ids:
        e = CATALOGUE[i]
        comp_mods = [f"{k} = {v}" for k, v in e.inputs.items()]
        comp_mods += [f"{k.split('.', 1)[1]} = {_number(v)}" for k, v in values.items() if k.startswith(i + ".")]
        lines.append(f"  {e.component} {i}(\n    " + ",\n    ".join(comp_mods) + f') "{e.title}";')
    lines.append(f"end {short};")
    return "\n".join(lines) + "\n"


def candidates_source(base: str = BASE_MODEL) -> str:
    """Every catalogue effect, switched off, on ``base`` (see the module docstring)."""
    values = {e.parameter(k): v for e in CATALOGUE.values() for k, v in e.neutral.items()}
    return variant_source(list(CATALOGUE), values, name=candidates_model(base), base=base,
                          description=f"{base} with every catalogue effect, switched off; "
                                      "generated by twin.effects.variant.candidates_source")


def modelica_root(modelica_dir: str | Path | None = None) -> Path:
    """The Modelica root variants go to (default: the repository's ``modelica/``).

    Raises :class:`twin.errors.OutputPathError` when it does not hold the ``GearTwin`` package.
    """
    from twin.errors import OutputPathError
    root = Path(modelica_dir) if modelica_dir is not None else _REPO_MODELICA
    if not (root / "GearTwin" / "package.mo").exists():
        raise OutputPathError(f"{root} does not hold the GearTwin package (no GearTwin/package.mo)")
    return root


def write_variant(source: str, modelica_dir: str | Path | None = None) -> tuple[str, Path]:
    """Write a variant (atomically) into ``<modelica_dir>/GearTwin/Variants/``; returns (model, path).

    The package directory and its ``package.mo`` / ``package.order`` are created or updated.
    """
    from twin._atomic import atomic_path
    root = modelica_root(modelica_dir)
    m = re.search(r"^model (\w+)", source, re.M)
    if m is None:
        from twin.errors import ParameterError
        raise ParameterError("variant source has no 'model <name>' line")
    short = m.group(1)
    pkg = root / "GearTwin" / "Variants"
    pkg.mkdir(exist_ok=True)
    if not (pkg / "package.mo").exists():
        with atomic_path(pkg / "package.mo") as tmp:
            Path(tmp).write_text('within GearTwin;\npackage Variants "Base gearbox models extended with effect '
                                 'components (written by twin add-effect or by hand)"\nend Variants;\n')
    path = pkg / f"{short}.mo"
    with atomic_path(path) as tmp:
        Path(tmp).write_text(source)
    order = pkg / "package.order"
    names = order.read_text().split() if order.exists() else []
    if short not in names:
        with atomic_path(order) as tmp:
            Path(tmp).write_text("\n".join(sorted([*names, short])) + "\n")
    top = root / "GearTwin" / "package.order"
    if top.exists() and "Variants" not in top.read_text().split():
        with atomic_path(top) as tmp:
            Path(tmp).write_text(top.read_text().rstrip("\n") + "\nVariants\n")
    return f"{VARIANTS_PACKAGE}.{short}", path


#: Build options of a current model that a candidate or variant built from it keeps: a measured
#: transfer path's sections (the path's values are parameters, but their number is structural).
CARRIED_OPTIONS = ("n_path_sections",)


def build_like(model: str, modelica_dir, build_dir, structural: Mapping[str, int] | None = None) -> Path:
    """Build ``model`` (cached) with the options of :data:`CARRIED_OPTIONS` that ``structural`` (the
    current FMU's structural values) sets, so a candidate or variant of a model with a measured
    path has the same path blocks."""
    from fmu_build import build_fmu
    keep = {k: int(v) for k, v in (structural or {}).items() if k in CARRIED_OPTIONS and v}
    if not keep:
        return build_fmu(model, modelica_dir, build_dir)
    from twin.variants import build_variant
    return build_variant(model, keep, modelica_dir=modelica_dir, out_dir=build_dir)

