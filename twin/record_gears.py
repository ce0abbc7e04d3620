"""The gears an archive record is simulated with: each record's own pinion and wheel.

Manufacturing errors (ISO 1328 pitch errors, run-out) and an uneven spread of the damage over the
teeth are drawn per record from streams of their own (:func:`tooth_errors`, :func:`draw_wheel`),
turned into the FMU's per-tooth parameters, and kept as ``gear_*`` record attributes
(:func:`gear_attributes`) so that a record names the gear it was simulated with.
:mod:`twin.archive` calls these for every record."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.errors import ParameterError, ScenarioError
from twin.scenario import Scenario

TOOTH_ERROR_KEYS = ("pitch_error", "runout", "tooth_damage_scatter")
PITTING_LOSS_CAP = 0.95     # a tooth keeps at least 5 % of its pair stiffness, as a pitted flank does


def runout_deviation(runout: float, phase: float, teeth: int) -> np.ndarray:
    """(teeth,) extra material loss [m] of an eccentric pinion's teeth: a once-per-revolution
    sinusoid, ``runout`` peak to peak, >= 0, tooth 1 at angle ``phase`` [rad]."""
    return 0.5 * runout * (1.0 - np.cos(2 * np.pi * np.arange(teeth) / teeth + phase))


@dataclass(frozen=True)
class PinionDraw:
    """One record's drawn pinion (:func:`draw_pinion`), before it meets the record's damage.

    Attributes
    ----------
    pitch_error_sd : float
        Drawn sd of the per-tooth pitch deviations [m].
    runout : float
        Drawn peak-to-peak run-out [m].
    runout_phase : float
        Angle of tooth 1 on the run-out sinusoid [rad].
    tooth_damage_scatter : float
        Drawn relative sd of the per-tooth damage factors [-].
    pitch_deviation : ndarray (teeth,)
        Per-tooth pitch deviations [m] (unshifted).
    damage_factors : ndarray (teeth,)
        Per-tooth damage factors c_i [-], mean 1 in distribution.
    """

    pitch_error_sd: float
    runout: float
    runout_phase: float
    tooth_damage_scatter: float
    pitch_deviation: np.ndarray
    damage_factors: np.ndarray

    def attributes(self) -> dict:
        """The drawn magnitudes as record attributes (``gear_`` prefix, SI units)."""
        return {"gear_pitch_error_sd": self.pitch_error_sd, "gear_runout": self.runout,
                "gear_runout_phase": self.runout_phase, "gear_tooth_damage_scatter": self.tooth_damage_scatter}


def draw_pinion(draw: np.random.Generator, spec, teeth: int) -> PinionDraw:
    """Draw one record's pinion within the archive block's bounds (see :func:`tooth_errors`)."""
    pitch_bound, runout_bound, scatter_bound = (float(spec.get(k, 0.0)) for k in TOOTH_ERROR_KEYS)
    pitch_sd = draw.uniform(0.0, pitch_bound)
    pitch = pitch_sd * draw.standard_normal(teeth)
    runout = draw.uniform(0.0, runout_bound)
    phase = draw.uniform(0.0, 2 * np.pi)
    scatter = draw.uniform(0.0, scatter_bound)
    c = draw.gamma(1.0 / scatter ** 2, scatter ** 2, teeth) if scatter > 0 else np.ones(teeth)
    return PinionDraw(float(pitch_sd), float(runout), float(phase), float(scatter), np.asarray(pitch, float),
                      np.asarray(c, float))


WHEEL_ERROR_KEYS = ("wheel_pitch_error", "wheel_runout")


@dataclass(frozen=True)
class WheelDraw:
    """One record's drawn gear (the wheel, 52 teeth in the rig): its tooth positions.

    Attributes
    ----------
    pitch_error_sd : float
        Drawn sd of the single pitch deviations [m].
    runout : float
        Drawn peak-to-peak run-out [m].
    runout_phase : float
        Angle of tooth 1 on the run-out sinusoid [rad].
    deviation : ndarray (teeth,)
        ``wheel_tooth_deviation_offset`` [m]: cumulative pitch deviation plus run-out, shifted so
        that the least-cut tooth has zero.
    """

    pitch_error_sd: float
    runout: float
    runout_phase: float
    deviation: np.ndarray

    def attributes(self) -> dict:
        """The drawn gear as record attributes (``gear_wheel_`` prefix, SI units)."""
        return {"gear_wheel_pitch_error_sd": self.pitch_error_sd, "gear_wheel_runout": self.runout,
                "gear_wheel_runout_phase": self.runout_phase,
                "gear_wheel_tooth_deviation_offset": np.asarray(self.deviation, float)}

    def parameters(self) -> dict[str, float]:
        """The FMU parameters ``wheel_tooth_deviation_offset[1..teeth]`` [m]."""
        return {f"wheel_tooth_deviation_offset[{i + 1}]": float(v) for i, v in enumerate(self.deviation)}


def draw_wheel(draw: np.random.Generator, spec, teeth: int) -> WheelDraw:
    """Draw one record's gear within the archive block's bounds (``wheel_pitch_error``,
    ``wheel_runout`` [m], absent = 0), each magnitude uniform between zero and its bound.

    The pinion's tooth positions are drawn independent from tooth to tooth
    (:func:`draw_pinion`).  The gear's follow ISO 1328's definition instead: the single pitch
    deviations (tooth to tooth spacing) are independent normal, and a tooth's position deviation
    is their sum from tooth 1, the cumulative pitch deviation, which closes over the revolution
    (the spacings sum to the circumference).  Its energy sits at the gear's first few shaft
    orders, which is where a hobbed gear's errors are, with run-out on top at the first.
    """
    pitch_sd = draw.uniform(0.0, float(spec.get("wheel_pitch_error", 0.0)))
    single = pitch_sd * draw.standard_normal(teeth)
    runout = draw.uniform(0.0, float(spec.get("wheel_runout", 0.0)))
    phase = draw.uniform(0.0, 2 * np.pi)
    cumulative = np.cumsum(single - single.mean())      # closed: tooth z + 1 is tooth 1 again
    dev = cumulative + runout_deviation(runout, phase, teeth)
    return WheelDraw(float(pitch_sd), float(runout), float(phase), dev - dev.min())


def _profile(parameters: dict, name: str) -> np.ndarray:
    """The FMU array ``name[1..n]`` of ``parameters`` in index order (empty when absent).

    Unlike :func:`twin.degradation._nodes.node_array` it accepts a single node, as a flank
    that is the same all along the path is written in the tests."""
    keys = sorted((k for k in parameters if k.startswith(name + "[")), key=lambda k: int(k[len(name) + 1:-1]))
    return np.array([parameters[k] for k in keys], dtype=float)


def tooth_compliance_factors(k_healthy: np.ndarray, k_damaged: np.ndarray, damage_factors: np.ndarray,
                             samples_per_segment: int = 50) -> np.ndarray:
    """Per-tooth stiffness multipliers of a pinion whose teeth are pitted unevenly.

    The uniform damage lowers the pair stiffness along the path of contact from ``k_healthy`` to
    ``k_damaged`` (the FMU's ``k_pair`` nodes, equally spaced in roll, interpolated piecewise
    linearly as the FMU does), a local loss ``d(u) = 1 - k_damaged(u) / k_healthy(u)``.  Tooth i is
    pitted ``c_i`` times as much in the same zone: its pair stiffness would be
    ``k_healthy(u) (1 - min(c_i d(u), 0.95))``.  The FMU scales the common profile by one number per
    tooth, so the number chosen keeps the tooth's *mean compliance* along the path, 1/k averaged
    over u: that is the tooth's mean quasi-static deflection under a given mesh force, whose
    differences from tooth to tooth are what puts energy at the shaft-order sidebands.  (Keeping
    the mean stiffness instead, the rule before 2026-11-24, underestimates how far a badly pitted
    tooth gives way: where its local loss nears the cap, its compliance grows as 1 / (1 - loss).)
    For uniform damage (``c_i = 1``), or a loss that is the same all along the path, both rules
    agree: (1 - min(c_i L, 0.95)) / (1 - L).

    Parameters
    ----------
    k_healthy, k_damaged : ndarray, shape (n,)
        Pair stiffness nodes [N/m] of the healthy and of the uniformly damaged flank.
    damage_factors : ndarray, shape (teeth,)
        c_i [-], >= 0.
    samples_per_segment : int
        Points per node interval of the grid the compliance is averaged on.

    Returns
    -------
    ndarray, shape (teeth,)
        ``tooth_stiffness_factor`` [-]; all ones when the damaged flank is nowhere softer.
    """
    from twin.degradation._nodes import interp_nodes, node_xi

    c = np.asarray(damage_factors, dtype=float)
    kh, kd = np.asarray(k_healthy, dtype=float), np.asarray(k_damaged, dtype=float)
    if kh.size == 0 or not np.any(kd < kh):
        return np.ones(c.size)
    u = node_xi(max(1, (kh.size - 1) * samples_per_segment) + 1)
    kh_u = interp_nodes(kh, u)
    # A flank the uniform damage has stripped bare (k_damaged 0 at a node) would make every
    # tooth's compliance infinite; the cap keeps the comparison finite for it too.
    loss = np.minimum(1.0 - interp_nodes(kd, u) / kh_u, PITTING_LOSS_CAP)      # (U,)
    common_k = kh_u * (1.0 - loss)
    tooth_k = kh_u * (1.0 - np.minimum(c[:, None] * loss, PITTING_LOSS_CAP))       # (teeth, U)
    return np.mean(1.0 / common_k) / np.mean(1.0 / tooth_k, axis=1)


def pinion_parameters(pinion: PinionDraw, healthy: dict, damaged: dict, sharing=None) -> dict[str, float]:
    """Per-tooth FMU parameters of a drawn pinion at a record's damage (see :func:`tooth_errors`).

    ``sharing`` (:class:`~twin.degradation.tooth_wear.ToothLoadSharing`, the record's mesh) is
    needed when the record is worn: the teeth are worn under it from their drawn offsets."""
    teeth = pinion.pitch_deviation.size
    c = pinion.damage_factors
    offset = pinion.pitch_deviation + runout_deviation(pinion.runout, pinion.runout_phase, teeth)
    factor = tooth_compliance_factors(_profile(healthy, "k_pair"), _profile(damaged, "k_pair"), c)
    depth = _profile(damaged, "profile_deviation")
    as_made = _profile(healthy, "profile_deviation")
    if as_made.size == depth.size:
        depth = depth - as_made      # the wear alone, not the flanks' as-manufactured profile (mesh_form)
    mean_depth = float(depth.mean()) if depth.size else 0.0
    if mean_depth > 0:
        if sharing is None:
            raise ParameterError(f"a worn record ({1e6 * mean_depth:.3g} um mean depth) needs the mesh's load "
                                 "sharing (sharing=ToothLoadSharing) to wear its teeth")
        # a gamma draw can come out near zero: no tooth is wear-free, the floor keeps the rates finite
        field = sharing.wear(offset, np.clip(c, 0.05, None), mean_depth)
        out = tooth_field_parameters(field, _profile(damaged, "tooth_pit_field"))
    else:
        out = {f"tooth_deviation_offset[{i + 1}]": float(v) for i, v in enumerate(offset - offset.min())}
    out.update({f"tooth_stiffness_factor[{i + 1}]": float(v) for i, v in enumerate(factor)})
    return out


def tooth_field_parameters(field: np.ndarray, pits: np.ndarray | None = None) -> dict[str, float]:
    """The FMU parameters of worn teeth (``ToothLoadSharing.wear``'s (z, n) field [m]): each tooth's
    rigid part ``tooth_deviation_offset[1..z]`` (its mean over the nodes, least-cut tooth at zero) and
    the rest along the path ``tooth_pit_field[1..z n]`` (tooth-major), plus ``pits`` (z n,) [m], the
    pit field the record already has (none: empty or None)."""
    rigid = field.mean(axis=1)
    flat = (field - rigid[:, None]).ravel()
    if pits is not None and np.size(pits):
        if np.size(pits) != flat.size:
            raise ParameterError(f"tooth_pit_field has {np.size(pits)} values where the worn teeth need "
                                 f"{flat.size} ({field.shape[0]} teeth x {field.shape[1]} nodes)")
        flat = flat + np.asarray(pits, dtype=float)
    out = {f"tooth_deviation_offset[{i + 1}]": float(v) for i, v in enumerate(rigid - rigid.min())}
    out.update({f"tooth_pit_field[{m + 1}]": float(v) for m, v in enumerate(flat)})
    return out


def tooth_errors(draw: np.random.Generator, spec, teeth: int, healthy: dict, damaged: dict,
                 sharing=None) -> dict[str, float]:
    """Per-pinion-tooth FMU parameters of one record's gear: manufacturing errors and uneven damage.

    Every real pinion has pitch errors and some run-out, and its damage is not the same on every
    tooth (pits start on single teeth).  Both make the vibration differ from tooth to tooth, i.e.
    put energy at shaft-order sidebands of the mesh harmonics, which a twin with identical teeth
    does not have.  Each record draws a pinion of its own, with each magnitude uniform between
    zero and the archive's bound, so the archive covers gears from perfect to the bound:

    * ``pitch_error`` [m]: bound of the sd of the per-tooth pitch deviations (normal, independent);
    * ``runout`` [m]: bound of the peak-to-peak run-out, a once-per-revolution sinusoid of random
      phase over the teeth;
    * ``tooth_damage_scatter`` [-]: bound of the relative sd of per-tooth damage factors c_i
      (gamma distributed, mean 1, so the stage's mean damage is kept).  Pitting: where the uniform
      damage loses d(u) of the pair stiffness, tooth i loses min(c_i d(u), 0.95); the FMU takes
      one ``tooth_stiffness_factor[i]`` per tooth on top of the uniform ``k_pair``, chosen to keep
      the tooth's mean compliance along the path (:func:`tooth_compliance_factors`).  Wear: c_i
      is tooth i's wear coefficient over the mean's, and the teeth are worn from their drawn
      offsets by the mean depth of ``profile_deviation`` beyond the healthy flank's (its
      as-manufactured profile is not wear) under the mesh's load sharing
      (:mod:`twin.degradation.tooth_wear`), node by node along the path: where a tooth shares the
      force (the double-contact zones) a proud spot carries more and wears faster, so the pitch
      errors and run-out wear in there; in the single-contact zone every tooth carries the whole
      force, so what a tooth's c_i adds there stays and grows with the depth.  Each worn tooth's
      field is written as its rigid part (``tooth_deviation_offset``) and the rest along the path
      (``tooth_pit_field[(i - 1) n + k]``, added to any pit field the record has).  Pitting: one
      number per tooth stands in for the damage's shape along that tooth's flank, which is taken
      to be the uniform damage's.

    The offsets are ``tooth_deviation_offset[1..teeth]`` [m], shifted so that the least-cut tooth
    has zero (a common offset only moves the static deflection).

    Parameters
    ----------
    draw : the generator of the gear draws (one call per record).
    spec : the archive block (the three keys above, each >= 0; absent = 0).
    teeth : pinion tooth count (the FMU's ``tooth_deviation_offset`` array size).
    healthy, damaged : FMU mesh parameters (``k_pair[j]``, ``profile_deviation[j]``) of the healthy
        flank and at the record's damage.
    sharing : :class:`~twin.degradation.tooth_wear.ToothLoadSharing` of the record's mesh; needed
        when ``damaged`` is worn (ParameterError otherwise).

    Returns
    -------
    dict: ``tooth_deviation_offset[i]`` [m] and ``tooth_stiffness_factor[i]`` [-], i = 1..teeth;
    for a worn record also ``tooth_pit_field[m]`` [m], m = 1..teeth x n (n: the ``k_pair`` nodes).
    """
    return pinion_parameters(draw_pinion(draw, spec, teeth), healthy, damaged, sharing)


GEAR_ARRAYS = ("tooth_deviation_offset", "tooth_stiffness_factor")


def gear_attributes(pinion: PinionDraw, parameters: dict, teeth: int) -> dict:
    """A record's ``gear_*`` attributes: the drawn magnitudes and the (teeth,) arrays set in the FMU
    (``gear_tooth_deviation_offset`` [m], ``gear_tooth_stiffness_factor`` [-]); for a worn record
    also each tooth's own worn flank beyond its rigid part, ``gear_tooth_flank_field`` (teeth, n) [m]
    at the ``k_pair`` nodes (what :func:`pinion_parameters` wrote to ``tooth_pit_field``)."""
    out = pinion.attributes()
    for name in GEAR_ARRAYS:
        out[f"gear_{name}"] = np.array([parameters[f"{name}[{i}]"] for i in range(1, teeth + 1)])
    field = _profile(parameters, "tooth_pit_field")
    if field.size:
        out["gear_tooth_flank_field"] = field.reshape(teeth, -1)
    return out


def tooth_error_bounds(scenario: Scenario, keys: tuple = TOOTH_ERROR_KEYS) -> tuple[float, ...]:
    """The archive block's bounds of ``keys`` (default ``pitch_error``, ``runout``,
    ``tooth_damage_scatter``; or :data:`WHEEL_ERROR_KEYS`), absent = 0.

    The scenario schema checks them in a file; a block built in code (``with_overrides``) is
    checked here, so a negative or non-numeric bound is a :class:`ScenarioError` naming every bad
    key rather than a silently flipped gear.
    """
    spec = scenario.archive or {}
    bounds, problems = [], []
    for key in keys:
        value = spec.get(key, 0.0)
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0
        if not ok:
            problems.append((str(scenario.source), f"archive.{key}", f"must be a finite number >= 0, got {value!r}"))
        bounds.append(float(value) if ok else 0.0)
    if problems:
        raise ScenarioError(problems)
    return tuple(bounds)
