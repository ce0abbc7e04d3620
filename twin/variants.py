"""Built variants of a model: structural parameters and build-time defaults.

``z1``, ``z2`` and ``n_profile`` of ``GearTwin.Gearbox21`` are structural: they size arrays or
fix the geometry the mesh stiffness is computed for, so changing them means building another
FMU.  ``twin build MODEL --set z1=18 --set z2=35`` and a scenario's ``structural: {z1: 18}``
both come here.  A build option that changes the gear geometry or the number of profile nodes
also sets the default of ``k_pair`` to the single-pair stiffness computed from that geometry
(:mod:`twin.degradation.stiffness`, potential-energy method), unless ``k_pair`` is given.
The FMU is cached by a hash of everything that went into it (:func:`fmu_build.build_fmu`).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from twin.errors import ParameterError

#: Build options that define the gear pair (a change recomputes the default mesh stiffness).
GEOMETRY_OPTIONS = ("z1", "z2", "module", "alpha", "face_width", "addendum_coefficient", "n_profile",
                    "youngs_modulus", "poisson_ratio", "profile_shift_pinion", "profile_shift_gear",
                    "dedendum_coefficient", "root_radius_coefficient", "bore_radius_pinion", "bore_radius_gear")
#: Options that the stiffness computation reads under these names (not parameters of the Modelica model).
STIFFNESS_ONLY = ("youngs_modulus", "poisson_ratio", "dedendum_coefficient", "root_radius_coefficient",
                  "bore_radius_pinion", "bore_radius_gear")
#: The gears' material also sizes the model's Hertzian contact (``hertz_half_width``, which ends the
#: flank roughness's band): the same values go to these parameters, so one steel sets both.
MATERIAL_PARAMETERS = {"youngs_modulus": "gear_youngs_modulus", "poisson_ratio": "gear_poisson_ratio"}
_REPO = Path(__file__).resolve().parents[1]


def rebuild_hint(model: str, name: str, value) -> str:
    """The sentence that tells a user how to change structural parameter ``name``."""
    shown = int(value) if isinstance(value, (int, float)) and float(value).is_integer() else value
    return (f"{name!r} is structural (fixed when the FMU is built); rebuild with "
            f"`twin build {model} --set {name}={shown}` or put `structural: {{{name}: {shown}}}` in the scenario")


def build_options(sets: Mapping[str, float], *, n_profile_default: int = 11) -> dict:
    """Modifiers for :func:`fmu_build.build_fmu` from user build options.

    Integer-valued options stay ints (structural parameters need them).  When an option in
    :data:`GEOMETRY_OPTIONS` is set and ``k_pair`` is not, ``k_pair`` gets the potential-energy
    single-pair stiffness of the resulting geometry at ``n_profile`` nodes.  Options in
    :data:`STIFFNESS_ONLY` enter that computation under their own names; the material among them
    also sets the model's ``gear_youngs_modulus`` / ``gear_poisson_ratio`` (:data:`MATERIAL_PARAMETERS`).
    """
    mods = _normalised(sets)
    if any(k in GEOMETRY_OPTIONS for k in mods) and "k_pair" not in mods:
        from twin.degradation.geometry import GearPair
        from twin.degradation.stiffness import k_pair_nodes
        geometry = GearPair.from_parameters({k: v for k, v in mods.items() if not isinstance(v, list)})
        n = int(mods.get("n_profile", n_profile_default))
        mods["k_pair"] = k_pair_nodes(geometry, n)
    out = {k: v for k, v in mods.items() if k not in STIFFNESS_ONLY}
    out.update({MATERIAL_PARAMETERS[k]: float(v) for k, v in mods.items() if k in MATERIAL_PARAMETERS})
    return out


def _normalised(sets: Mapping[str, float]) -> dict:
    """Integral numbers as ints (what a structural Integer needs, and a stable file name)."""
    out: dict = {}
    for name, value in sets.items():
        if isinstance(value, (list, tuple)):
            out[name] = [float(v) for v in value]
        elif isinstance(value, float) and value.is_integer() and abs(value) < 2 ** 31:
            out[name] = int(value)
        else:
            out[name] = value
    return out


def build_variant(model: str, sets: Mapping[str, float], *, modelica_dir: Path | str | None = None,
                  out_dir: Path | str | None = None, step_size: float | None = None, force: bool = False,
                  fmi_version: int = 2) -> Path:
    """Build (or take from the cache) ``model`` with build options ``sets``; return the FMU path."""
    from fmu_build import build_fmu
    from fmu_build.build import DEFAULT_STEP_SIZE, variant_name
    for name, value in sets.items():
        if not isinstance(value, (list, tuple)) and not (isinstance(value, (int, float)) and math.isfinite(value)):
            raise ParameterError(f"build option {name!r} must be a finite number, got {value!r}")
    mods = build_options(sets)
    # the file name says what the user chose (the computed k_pair follows from it)
    name = variant_name(model, _normalised(sets))
    return build_fmu(model, modelica_dir or _REPO / "modelica", out_dir or _REPO / "build",
                     step_size=DEFAULT_STEP_SIZE if step_size is None else step_size, force=force,
                     modifiers=mods, name=name if sets else None, fmi_version=fmi_version)


def geometry_summary(fmu) -> list[str]:
    """Lines describing the gear pair of an open :class:`twin.fmu.FMU` (empty if it has none).

    Structural values, radii, contact ratio, and the mesh stiffness: the FMU's ``k_pair``
    defaults beside the potential-energy single-pair stiffness and ISO 6336-1's."""
    import numpy as np

    from twin.degradation.geometry import GearPair
    from twin.degradation.stiffness import stiffness_report
    structural = fmu.structural_values()
    if "z1" not in structural or "k_pair[1]" not in fmu.variables:
        return []
    values = {v.name: v.start for v in fmu.parameters if "[" not in v.name and v.start is not None}
    values.update(structural)
    try:
        g = GearPair.from_parameters(values)
    except ParameterError as exc:
        return [f"Gear pair     not a valid spur pair: {exc}"]
    n = structural.get("n_profile", 11)
    k = np.array([fmu.variable(f"k_pair[{i}]").start for i in range(1, n + 1)])
    rep = stiffness_report(g)
    mm = 1e3
    return [
        f"Gear pair     z1 = {g.z1}, z2 = {g.z2}, module {g.module * mm:g} mm, pressure angle "
        f"{math.degrees(g.pressure_angle):g} deg, face width {g.face_width * mm:g} mm, "
        f"profile shift {g.profile_shift_pinion:g} / {g.profile_shift_gear:g}",
        f"Radii [mm]    pitch {g.pitch_radius_pinion * mm:.3f} / {g.pitch_radius_gear * mm:.3f}, "
        f"base {g.base_radius_pinion * mm:.3f} / {g.base_radius_gear * mm:.3f}, "
        f"tip {g.tip_radius_pinion * mm:.3f} / {g.tip_radius_gear * mm:.3f}, "
        f"root {g.root_radius_pinion * mm:.3f} / {g.root_radius_gear * mm:.3f}; "
        f"centre distance {g.centre_distance * mm:.3f}",
        f"Contact ratio {g.contact_ratio:.4f} (path of contact {g.path_of_contact_length * mm:.3f} mm, "
        f"pitch point at roll {g.pitch_point_xi:.3f})",
        f"k_pair        this FMU: {k.min():.4g}..{k.max():.4g} N/m on {n} nodes "
        f"(mean mesh stiffness {k.mean() * g.contact_ratio:.4g} N/m)",
        f"              potential energy: {rep.k_pair_max:.4g} N/m single pair at most, mean mesh "
        f"{rep.k_mesh_mean:.4g} N/m",
        f"              ISO 6336-1 B: c' b = {rep.iso.single:.4g} N/m ({100 * rep.single_difference:+.1f} %), "
        f"c_gamma_alpha b = {rep.iso.mesh:.4g} N/m ({100 * rep.mesh_difference:+.1f} %)",
        *_contact_line(values, g),
    ]


def _contact_line(values: Mapping[str, float], g) -> list[str]:
    """The Hertzian half-width at the FMU's start load on one pair at the pitch point
    (:meth:`twin.degradation.geometry.GearPair.hertz_half_width` with the FMU's gear steel; the
    FMU's ``hertz_half_width`` takes the same formula at the standard pitch radii, equal for gears
    without profile shift), and the shaft orders where the contact halves a roughness's amplitude
    (``GearTwin.Excitation.RoughnessTransmissionError``: exp(-(n b / rho)^2 / 8) = 1/2)."""
    import dataclasses

    needed = ("load_start", "gear_youngs_modulus", "gear_poisson_ratio")
    if not all(values.get(k) is not None for k in needed):
        return []
    try:
        steel = dataclasses.replace(g, youngs_modulus=float(values["gear_youngs_modulus"]),
                                    poisson_ratio=float(values["gear_poisson_ratio"]))
    except ParameterError:       # a steel the stiffness formulas refuse (nu = 0.5): no line, not a failed info
        return []
    xi = g.pitch_point_xi
    force = max(float(values["load_start"]), 0.0) / g.base_radius_gear      # one pair carries it
    b = float(steel.hertz_half_width(force, xi))
    if b <= 0:
        return ["Contact       no static load (load_start 0): the roughness is not averaged by the contact"]
    half = math.sqrt(8 * math.log(2))
    rho1, rho2 = float(g.rho1(xi)), float(g.rho2(xi))
    return [f"Contact       Hertz half-width {b * 1e6:.1f} um at load_start {float(values['load_start']):g} N.m; "
            f"roughness amplitude halved at shaft order {half * rho1 / b:.0f} (pinion) / {half * rho2 / b:.0f} (gear)"]
