"""The model's modes at one parameter set, and which of them a sensor shows.

The FMU is linearised about the operating point (:mod:`twin.linearize`) with its sensor outputs
and the excitations of a run-up: the mesh (a transmission error), the drive and the brake torque,
and a force at each gear in each lateral direction and across the line of action (shaft-order
run-out and unbalance, the process force). A model mode is *visible* when it makes a peak of an
excitation-to-sensor response, the way a measured mode shows in a run-up: with
``visibility="mesh"`` (default) of the mesh column's, with ``visibility="run-up"`` of any
column's (:data:`VISIBILITY`). With ``"mesh+dominant"`` or ``"run-up+dominant"`` a mode that
dominates such a response at its own frequency counts as well (:func:`dominant_modes`: two close
modes can share one peak). :mod:`twin.calibration.sensitivity` pairs measured modes with them.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from twin.scenario_schema import VISIBILITY_RULES

#: Parameters moved together to form a transmission error (mesh excitation) in GearTwin models.
MESH_EXCITATION = "profile_deviation"
#: Levels of the broadband sources of GearTwin.Gearbox21Measured, set to zero to linearise.
BROADBAND_LEVELS = ("pinion_roughness.rms", "gear_roughness.rms", "process.rms")
#: Which excitation-to-sensor responses make a model mode visible: the mesh's alone (default), or
#: any of a run-up's excitations (:data:`RUNUP_EXCITATIONS`, :data:`LATERAL_FORCES`); with
#: ``+dominant`` a mode that dominates one of them at its own frequency counts too
#: (:func:`dominant_modes`), not only one that makes a peak.
VISIBILITY = VISIBILITY_RULES
#: Excitations of a run-up that are FMU inputs, by column name (a unit change of the input). The
#: speed reference acts through the motor's slip law as ``c_motor`` times the drive torque: the
#: same column scaled, so it is not repeated.
RUNUP_EXCITATIONS = {"drive torque": ("drive_torque",), "load torque": ("load_torque",)}
#: Forces on the gear bodies (no model input needed: a force F on a body of mass m is the column
#: F/m on its velocity state), by column name: ((velocity state, mass parameter, direction
#: factor), ...). Run-out and unbalance rotate at shaft order, so they push each gear both ways;
#: the process force acts across the line of action on the pinion, the gear taking the reaction,
#: along (cos alpha, -sin alpha) (GearTwin.Gearbox21Measured, ``excitation_off_line_force``).
LATERAL_FORCES = {"pinion x": (("vx5", "m5", "1"),), "pinion y": (("vy5", "m5", "1"),),
                  "gear x": (("vx10", "m10", "1"),), "gear y": (("vy10", "m10", "1"),),
                  "process force": (("vx5", "m5", "cos"), ("vy5", "m5", "-sin"),
                                    ("vx10", "m10", "-cos"), ("vy10", "m10", "sin"))}


def _starts(fmu_path) -> dict[str, float | None]:
    """Every variable of an FMU by name, with its numeric start value or None (read once per file
    and content)."""
    from twin.fmu import FMU
    key = (str(fmu_path), Path(fmu_path).stat().st_mtime_ns)
    if key not in _VARIABLES:
        with FMU(fmu_path) as fmu:
            _VARIABLES[key] = {n: (float(v.start) if isinstance(v.start, (int, float)) else None)
                               for n, v in fmu.variables.items()}
    return _VARIABLES[key]


def _variables(fmu_path) -> frozenset[str]:
    """Variable names of an FMU."""
    return frozenset(_starts(fmu_path))


_VARIABLES: dict = {}


@dataclass(frozen=True)
class ModelModes:
    """Model modes at one parameter set: all oscillatory ones and which of them a sensor shows."""

    frequency: np.ndarray         # (m,) Hz
    damping: np.ndarray           # (m,)
    visible: np.ndarray           # (m,) bool
    shapes: np.ndarray            # (n, m) complex
    gain_db: np.ndarray           # (m,) peak gain of the mode alone, dB re the most visible
    classes: tuple = ()           # (m,) ModeClass of each mode (twin.calibration.mode_classes)
    sensor_shapes: np.ndarray | None = None   # (k, m) complex residue of each mode at each channel (mesh)
    channels: tuple[str, ...] = ()
    visible_by: Mapping[str, np.ndarray] = field(default_factory=dict)   # excitation -> (m,) bool
    visibility: str = "mesh"      # the rule that made ``visible`` (VISIBILITY)
    side_db: np.ndarray | None = None   # (m,) input over output shaft's largest lateral amplitude [dB]

    def sensor_shape(self, i: int, channels: Sequence[str]) -> np.ndarray:
        """Mode i's residues at ``channels`` (those it was linearised with; 0 for others), (len,)."""
        out = np.zeros(len(channels), complex)
        for j, c in enumerate(channels):
            if self.sensor_shapes is not None and c in self.channels:
                out[j] = self.sensor_shapes[self.channels.index(c), i]
        return out


def check_visibility(visibility: str) -> str:
    """``visibility`` if it is a known rule (:data:`VISIBILITY`), else a ValueError naming it."""
    if visibility not in VISIBILITY:
        raise ValueError(f"unknown visibility {visibility!r}: use one of {', '.join(VISIBILITY)}")
    return visibility


def model_modes(fmu_path, parameters: Mapping[str, float], *, speed_hz: float, load_nm: float,
                channels: Sequence[str] = ("accel_pinion_casing",), fmax: float = 10_000.0,
                visibility: str = "mesh", every_excitation: bool = False) -> ModelModes:
    """Linearise at the operating point and find the visible modes (see the module docstring).

    The run-up's other excitation columns are linearised only when they decide visibility
    (``visibility="run-up"``, ``"run-up+dominant"``) or are asked for (``every_excitation``, for the report of
    ``visible_by``): with the default rule the fit's many linearisations need the mesh column alone."""
    from scipy.signal import find_peaks

    from twin.calibration.mode_classes import classify, dof_table, mass_values, side_levels
    from twin.linearize import frequency_response, linear_model, modal_model
    from twin.operating import operating_point

    check_visibility(visibility)
    start, inputs = operating_point(speed_hz, load_nm)
    names = _variables(fmu_path)
    excitations = {"mesh": [MESH_EXCITATION + "[*]"]}
    columns, _, rule = visibility.partition("+")
    every_excitation = every_excitation or columns == "run-up"
    if every_excitation:
        excitations.update({k: list(v) for k, v in RUNUP_EXCITATIONS.items() if all(n in names for n in v)})
    # the broadband sources are excitation, not structure: linearised without them (a rough
    # flank's transmission error would otherwise add its slope to the mesh stiffness)
    quiet = {n: 0.0 for n in BROADBAND_LEVELS if n in names}
    lm = linear_model(fmu_path, parameters={**parameters, **quiet, **start}, inputs=inputs, outputs=list(channels),
                      excitations=excitations, settle=0.02, window=2.5e-3, samples=4)
    masses = {**mass_values(fmu_path, parameters), **parameters}
    if every_excitation:
        lm = _with_forces(lm, masses, float(parameters.get("alpha", _start(fmu_path, "alpha", 20 * math.pi / 180))))
    mm = modal_model(lm)
    keep = mm.frequency <= fmax
    freq, damp, shapes = mm.frequency[keep], mm.damping[keep], mm.shapes[:, keep]
    gain = mm.gain[:, 0, keep].max(axis=0)      # the mesh column's (see the module docstring)
    by = {e: np.zeros(freq.size, dtype=bool) for e in lm.excitations}
    if freq.size:
        grid = np.geomspace(max(1.0, 0.5 * freq.min()), min(fmax, 1.5 * freq.max()), 6000)
        # every mode enters the response, those above fmax too: a stiff sensor mount far above the
        # band carries the whole response to the output, and leaving it out would leave nothing
        h = frequency_response(mm, grid)
        for e, name in enumerate(lm.excitations):
            # the mode nearest a peak is the one that makes it through this column (its own gain)
            g = mm.gain[:, e, keep].max(axis=0)
            for k in range(h.shape[0]):
                level = 20 * np.log10(np.maximum(np.abs(h[k, e]), 1e-300))
                peaks, _ = find_peaks(level, prominence=3.0)
                for p in peaks:
                    near = np.abs(np.log(freq / grid[p])) <= np.maximum(0.03, 2 * damp)
                    if near.any():
                        by[name][np.flatnonzero(near)[np.argmax(g[near])]] = True
            if rule == "dominant":
                by[name] |= dominant_modes(mm, e, keep)[keep]
    visible = by["mesh"].copy() if columns == "mesh" else np.any(list(by.values()), axis=0)
    top = gain[visible].max() if visible.any() else (gain.max() if gain.size else 1.0)
    table = dof_table(lm.state_names, masses)
    classes = tuple(classify(shapes, table))
    return ModelModes(freq, damp, visible, shapes, 20 * np.log10(np.maximum(gain, 1e-300) / top),
                      classes, mm.residues[:, 0, keep], tuple(channels), by, visibility,
                      side_levels(shapes, table, classes))


#: A mode that dominates the response at its own frequency is visible only if its own peak there is
#: at least this fraction of the strongest mode's peak in the same response (-40 dB): below it a
#: record's noise hides it, as the rigs' observability threshold (2 % of their best mode) does.
DOMINANT_FLOOR = 0.01


def dominant_modes(mm, column: int, within: np.ndarray | None = None) -> np.ndarray:
    """(m,) bool: the modes of ``mm`` (:class:`twin.linearize.ModalModel`) that dominate the response
    from excitation ``column`` at some output at their own frequency; ``within`` (m,) bool, the
    modes of the band (default all): the strongest of them sets the floor, so a stiff sensor mount
    far above the band does not.

    A mode is seen at a sensor when its own response there, at its frequency, is at least that of
    all the other modes together, and it is not buried below the strongest mode of that response
    (:data:`DOMINANT_FLOOR`). Two modes a few per cent apart can share one peak of the FRF, which a
    peak search gives to one of them; by its own contribution each is seen (the rigs' observability
    is a residue measure too, not a peak search)."""
    m = mm.frequency.size
    out = np.zeros(m, dtype=bool)
    if m == 0:
        return out
    s = 2j * np.pi * mm.frequency                                     # (m,) each mode's own frequency
    lam = mm.eigenvalues
    res = mm.residues[:, column, :]                                   # (k, m)
    # terms[k, i, j]: mode j's response at mode i's frequency (with its conjugate)
    terms = (res[:, None, :] / (s[None, :, None] - lam[None, None, :])
             + np.conj(res)[:, None, :] / (s[None, :, None] - np.conj(lam)[None, None, :]))
    own = np.abs(terms[:, np.arange(m), np.arange(m)])                # (k, m)
    rest = np.abs(terms.sum(axis=2) - terms[:, np.arange(m), np.arange(m)])
    band = np.ones(m, dtype=bool) if within is None else np.asarray(within, bool)
    if not band.any():
        return out
    strongest = own[:, band].max(axis=1, keepdims=True)
    return np.any((own >= rest) & (own >= DOMINANT_FLOOR * strongest), axis=0)


def _start(fmu_path, name: str, default: float) -> float:
    """Start value of a parameter of the FMU (``default`` when it has none)."""
    v = _starts(fmu_path).get(name)
    return default if v is None else v


def _with_forces(lm, masses: Mapping[str, float], alpha: float):
    """``lm`` with a B column per force of :data:`LATERAL_FORCES` whose velocity states it has
    (1 N on each body: 1/m on its velocity state, times the direction factor)."""
    from dataclasses import replace
    factor = {"1": 1.0, "cos": math.cos(alpha), "-cos": -math.cos(alpha), "sin": math.sin(alpha),
              "-sin": -math.sin(alpha)}
    cols, names = [], []
    for name, terms in LATERAL_FORCES.items():
        if not all(state in lm.state_names for state, _, _ in terms):
            continue
        col = np.zeros(len(lm.state_names))
        for state, mass, f in terms:
            col[lm.state_names.index(state)] += factor[f] / float(masses.get(mass, 1.0))
        cols.append(col)
        names.append(name)
    if not cols:
        return lm
    return replace(lm, B=np.column_stack([lm.B, *cols]), excitations=lm.excitations + tuple(names))
