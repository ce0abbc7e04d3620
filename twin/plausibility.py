"""Physical plausibility: parameter values that make no sense, and runs that left physics.

A non-finite output is not the only sign of a failed simulation.  A gearbox run whose mesh
stiffness is scaled by 1e6, or whose mesh damping is negative, stays finite: the flanks fly
apart and the casing "vibrates" at millions of m/s2.  Such a result must not be written as a
complete run nor scored as a good calibration candidate.

* :func:`physical_problems`: values refused up front, by unit (a stiffness in N/m or N.m/rad
  or a damping in N.s/m or N.m.s/rad below 0; a mass in kg or an inertia in kg.m2 not above 0)
  and by name (a ``*stiffness*`` scale or factor below 0).
* :func:`check_block`: a sampled run judged against :class:`Limits`: accelerations beyond
  ``max_acceleration``; the mesh out of contact for the whole window at a load that should
  hold it; vibration growing without any change of input (``growth_factor``).  Each raises a
  :class:`~twin.errors.SimulationError` saying what left physics, where and by how much; in a
  calibration the candidate is scored infeasible.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from twin.errors import SimulationError

_NON_NEGATIVE_UNITS = {"N/m": "stiffness", "N.m/rad": "torsional stiffness", "N.s/m": "damping",
                       "N.m.s/rad": "torsional damping"}
_POSITIVE_UNITS = {"kg": "mass", "kg.m2": "inertia"}
ACCELERATION_UNITS = ("m/s2", "m/s^2")


def physical_problems(values: Mapping[str, float], units: Mapping[str, str], *, what: str = "") -> list[str]:
    """Why each value of ``values`` (name -> value) makes no physical sense, given the FMU's
    ``units`` (name -> unit); empty when all are acceptable.  ``what`` prefixes the name
    (e.g. ``"lower bound of"``)."""
    out = []
    for name, value in values.items():
        unit = units.get(name, "")
        label = f"{what} {name!r}".strip()
        try:
            v = float(value)
        except (TypeError, ValueError):
            continue
        if not math.isfinite(v):
            out.append(f"{label} = {value!r} is not finite")
        elif unit in _NON_NEGATIVE_UNITS and v < 0:
            out.append(f"{label} = {v:g} {unit}: a {_NON_NEGATIVE_UNITS[unit]} cannot be negative")
        elif unit in _POSITIVE_UNITS and v <= 0:
            out.append(f"{label} = {v:g} {unit}: a {_POSITIVE_UNITS[unit]} must be positive")
        elif not unit and "stiffness" in name.split("[")[0] and v < 0:
            out.append(f"{label} = {v:g}: a stiffness scale cannot be negative")
    return out


@dataclass(frozen=True)
class Limits:
    """Bounds of a plausible gearbox run.

    max_acceleration : m/s2; no gearbox casing or shaft reaches 1e5 m/s2 (about 10,000 g).
    growth_factor : largest ratio of the vibration RMS over the last quarter of a window to
        that over its second quarter, with constant inputs (a damped system does not grow).
    contact_load : N.m; above this load the gear flanks must touch at some time of a window.
    """

    max_acceleration: float = 1e5
    growth_factor: float = 20.0
    contact_load: float = 1.0

    def __post_init__(self):
        for k in ("max_acceleration", "growth_factor", "contact_load"):
            v = getattr(self, k)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise SimulationError(f"plausibility limit {k} must be a positive finite number, got {v!r}")


DEFAULT_LIMITS = Limits()


def check_block(names: Sequence[str], block: np.ndarray, units: Mapping[str, str], *, t0: float, dt: float,
                load: float | None = None, constant_inputs: bool = False, contact: np.ndarray | None = None,
                limits: Limits = DEFAULT_LIMITS) -> None:
    """Raise :class:`SimulationError` if the sampled window ``block`` (m, len(names)) left physics.

    ``units``: name -> unit (accelerations are the channels in m/s2 or named ``accel*``);
    ``t0`` [s]: time of the first row; ``dt`` [s]: sample interval; ``load`` [N.m]: the brake
    load held over the window (None: unknown, no contact check); ``contact``: (m,) force
    through the mesh [N] (``mesh_force`` or the sum of the pair forces), None if not sampled;
    ``constant_inputs``: no input changed in the window, so the vibration may not grow.
    """
    block = np.asarray(block, float)
    if block.ndim != 2 or block.shape[0] == 0:
        return
    accel = [j for j, n in enumerate(names)
             if units.get(n, "") in ACCELERATION_UNITS or n.startswith("accel")]
    for j in accel:
        peak = int(np.argmax(np.abs(block[:, j])))
        value = float(block[peak, j])
        if abs(value) > limits.max_acceleration:
            raise SimulationError(f"implausible run: {names[j]} reaches {value:.3g} m/s2, beyond the bound of "
                                  f"{limits.max_acceleration:.3g} m/s2 (check the parameters; the bound is "
                                  "checks.max_acceleration)", time=t0 + peak * dt)
    if contact is not None and load is not None and abs(load) >= limits.contact_load:
        force = np.asarray(contact, float)
        if force.size and float(np.max(np.abs(force))) <= 0.0:
            raise SimulationError(f"implausible run: the gear flanks never touch over {force.size * dt:.3g} s "
                                  f"at a load of {load:g} N.m (contact lost for the whole window; check the mesh "
                                  "stiffness and damping)", time=t0)
    m = block.shape[0]
    if constant_inputs and accel and m >= 64:
        q = m // 4
        for j in accel:
            early = float(np.sqrt(np.mean(block[q:2 * q, j] ** 2)))
            late = float(np.sqrt(np.mean(block[3 * q:, j] ** 2)))
            if late > limits.growth_factor * max(early, 1e-12) and late > 1e-6 * limits.max_acceleration:
                raise SimulationError(f"implausible run: the vibration of {names[j]} grows {late / early:.3g}-fold "
                                      f"within {m * dt:.3g} s at constant inputs (energy growing without input; "
                                      "check the damping)", time=t0 + 3 * q * dt)


_PAIR_FORCES = ("pair_force[1]", "pair_force[2]", "pair_force[3]")


def contact_channels(variables: Mapping[str, object]) -> list[str]:
    """The outputs that carry the elastic mesh force of a gearbox FMU (none for other FMUs):
    the tooth-pair forces, which are zero exactly when the flanks are apart."""
    return list(_PAIR_FORCES) if all(n in variables for n in _PAIR_FORCES) else []


def checked_capture(fmu, t_end: float, dt: float, channels: Sequence[str], *, load: float | None,
                    constant_inputs: bool, limits: Limits = DEFAULT_LIMITS) -> np.ndarray:
    """``fmu.capture(t_end, dt, channels)``, judged by :func:`check_block` (the pair forces are
    sampled too when the FMU has them).  Returns shape (m, len(channels))."""
    channels = list(channels)
    extra = [n for n in contact_channels(fmu.variables) if n not in channels]
    names = channels + extra
    t0 = fmu.time + dt
    block = fmu.capture(t_end, dt, names)
    idx = [names.index(n) for n in _PAIR_FORCES if n in names]
    contact = block[:, idx].sum(axis=1) if len(idx) == 3 else None
    units = {n: fmu.variables[n].unit for n in names}
    check_block(names, block, units, t0=t0, dt=dt, load=load, constant_inputs=constant_inputs, contact=contact,
                limits=limits)
    return block[:, :len(channels)]


def check_parameters(fmu, values: Mapping[str, float]) -> None:
    """Raise :class:`~twin.errors.ParameterError` listing the values of ``values`` that make no
    physical sense for ``fmu`` (see :func:`physical_problems`)."""
    from twin.errors import ParameterError
    problems = physical_problems(values, {n: v.unit for n, v in fmu.variables.items()})
    if problems:
        raise ParameterError("; ".join(problems))


def check_result(result, *, load: float | None = None, constant_inputs: bool = True,
                 limits: Limits = DEFAULT_LIMITS) -> None:
    """:func:`check_block` on a :class:`~twin.results.SimulationResult` (its float channels and units)."""
    names = [n for n, v in result.signals.items() if v.dtype.kind == "f"]
    if not names:
        return
    block = np.column_stack([result.signals[n] for n in names])
    idx = [names.index(n) for n in _PAIR_FORCES if n in names]
    dt = 1.0 / result.sample_rate
    check_block(names, block, result.units, t0=float(result.time[0]) if len(result.time) else 0.0, dt=dt,
                load=load, constant_inputs=constant_inputs,
                contact=block[:, idx].sum(axis=1) if len(idx) == 3 else None, limits=limits)
