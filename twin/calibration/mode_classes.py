"""What moves in each model mode: its class, from the share of kinetic energy of each part.

A linearised GearTwin model's right eigenvector holds the velocity of every degree of freedom.
Weighted by the masses and inertias (read from the FMU's parameters), ``m |v|^2`` is each part's
share of the mode's kinetic energy. The class with the largest share names the mode, except that
``torsion`` names it only when rotation carries more of the energy than translation in the gear
plane (the ``lateral`` classes together: shafts and pedestals, both planes). The torsion class
pools nine degrees of freedom on both shafts while the lateral motion is split over eight classes
by body and direction, so a largest-share rule alone calls a mode ``torsion`` whose motion is mostly
lateral (at nominal in GearTwin.Gearbox21Shafts, the input shaft's vertical mode at 1.17 kHz: 57 %
lateral, 39 % torsional, named ``torsion`` before and ``input pedestals y`` now). A mesh-coupled mode
whose energy is mostly rotation stays ``torsion`` and carries the pinion's share (the 1.66 kHz mode:
57 % torsion, 32 % pinion lateral y).

| class | degrees of freedom (velocity states) | mass |
|---|---|---|
| ``torsion`` | ``omegaN`` | ``IN`` |
| ``pinion lateral x`` / ``y`` | ``vx5`` / ``vy5``: the pinion on its shaft | ``m5`` |
| ``gear lateral x`` / ``y`` | ``vx10`` / ``vy10``: the gear on its shaft | ``m10`` |
| ``input pedestals x`` / ``y`` | ``vx4``, ``vx6`` / ``vy4``, ``vy6`` | ``m4``, ``m6`` |
| ``output pedestals x`` / ``y`` | ``vx9``, ``vx11`` / ``vy9``, ``vy11`` | ``m9``, ``m11`` |
| ``input shaft ends x`` / ``y`` | ``vx_end4``, ``vx_end6`` / ``vy_end4``, ``vy_end6``: parts on the input shaft outside its bearings (GearTwin.Gearbox21Overhangs) | ``m_end4``, ``m_end6`` |
| ``output shaft ends x`` / ``y`` | ``vx_end9``, ``vx_end11`` / ``vy_end9``, ``vy_end11`` | ``m_end9``, ``m_end11`` |
| ``gear rocking`` | ``w_rock_x``, ``w_rock_y``: the gear's tilt rates (GearTwin.Gearbox21Rocking) | ``I_rock10`` |
| ``casing`` | ``vx_casing``, ``vy_casing`` / ``w_casing`` (GearTwin.Gearbox21Casing); ``casing.qd[k]`` (the wall modes of GearTwin.Gearbox21Walls and Gearbox21TiltingWalls, mass-normalised) | ``m_casing`` / ``I_casing``; 1 (modal states carry sqrt of the modal mass) |
| ``sensor path`` | a sensor's panel or mount modes (massless: only when nothing else moves) | |

In GearTwin.Gearbox21Shafts the shaft bends under its gear and its mass moves with it: the shaft
lateral modes are the ``pinion lateral`` and ``gear lateral`` classes, and ``m5``, ``m10`` (gear body
plus the shaft's share) are calculated parameters, read after initialisation (:func:`mass_values`).

A mode whose energy is split (a torsional mode that drags the pinion sideways through the mesh)
carries every share, so a calibration can ask "mostly lateral?" as well as "which class?".
"""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

#: (velocity-state pattern, class, mass parameter template); the first match applies.
DOF_RULES: tuple[tuple[str, str, str | None], ...] = (
    (r"^omega(\d+)$", "torsion", r"I\1"),
    (r"^vx5$", "pinion lateral x", "m5"),
    (r"^vy5$", "pinion lateral y", "m5"),
    (r"^vx10$", "gear lateral x", "m10"),
    (r"^vy10$", "gear lateral y", "m10"),
    (r"^vx(4|6)$", "input pedestals x", r"m\1"),
    (r"^vy(4|6)$", "input pedestals y", r"m\1"),
    (r"^vx(9|11)$", "output pedestals x", r"m\1"),
    (r"^vy(9|11)$", "output pedestals y", r"m\1"),
    (r"^vx_end(4|6)$", "input shaft ends x", r"m_end\1"),
    (r"^vy_end(4|6)$", "input shaft ends y", r"m_end\1"),
    (r"^vx_end(9|11)$", "output shaft ends x", r"m_end\1"),
    (r"^vy_end(9|11)$", "output shaft ends y", r"m_end\1"),
    (r"^w_rock_(x|y)$", "gear rocking", "I_rock10"),
    (r"^v(x|y)_casing$", "casing", "m_casing"),
    (r"^w_casing$", "casing", "I_casing"),
    (r"^casing\.qd\[(\d+)\]$", "casing", None),
    (r"^sensor_\w+\.(panel_rate\[\d+\]|deflection_rate)$", "sensor path", None),
)
#: The classes, in the order reports list them.
CLASSES = ("torsion", "pinion lateral x", "pinion lateral y", "gear lateral x", "gear lateral y",
           "input pedestals x", "input pedestals y", "output pedestals x", "output pedestals y",
           "input shaft ends x", "input shaft ends y", "output shaft ends x", "output shaft ends y", "gear rocking",
           "casing", "sensor path")
#: The lateral classes of each shaft (all of the shaft's bodies, both planes): a blow at one shaft's
#: end or bearing support answers in the modes whose lateral motion is on that shaft
#: (:func:`side_levels`).
SIDES = {"input": ("pinion lateral", "input pedestals", "input shaft ends"),
         "output": ("gear lateral", "output pedestals", "output shaft ends")}
#: A mode counts as the sensor path's own when the structure carries less than this share of the
#: velocity (unweighted) of the mode: the path's modes do not act back, so the structure is still.
SENSOR_PATH_SHARE = 1e-6


@dataclass(frozen=True)
class ModeClass:
    """The class of one mode and the kinetic-energy share of every class in it."""

    name: str                       # the class with the largest share
    shares: Mapping[str, float]     # class -> share of the kinetic energy, summing to 1

    @property
    def lateral(self) -> float:
        """Share of the lateral classes (shafts and pedestals, both planes)."""
        return float(sum(v for k, v in self.shares.items() if k.endswith((" x", " y"))))

    @property
    def plane(self) -> str:
        """'x' or 'y' when the lateral motion is mostly in one plane, else ''."""
        x = sum(v for k, v in self.shares.items() if k.endswith(" x"))
        y = sum(v for k, v in self.shares.items() if k.endswith(" y"))
        if x + y <= 0:
            return ""
        return "x" if x >= 0.7 * (x + y) else "y" if y >= 0.7 * (x + y) else ""


def dof_table(state_names: Sequence[str], values: Mapping[str, float]) -> list[tuple[int, str, float]]:
    """(state index, class, mass) of every velocity state the rules know; mass 0 for the sensor path.

    ``values`` maps parameter names to values (those missing default to 1, which only matters
    for a model outside the GearTwin naming).
    """
    out = []
    for i, name in enumerate(state_names):
        for pattern, cls, mass in DOF_RULES:
            m = re.match(pattern, name)
            if m is None:
                continue
            if cls == "sensor path":
                w = 0.0
            elif mass is None:
                w = 1.0
            else:
                w = float(values.get(m.expand(mass), 1.0))
            out.append((i, cls, w))
            break
    return out


def classify(shapes: np.ndarray, table: Sequence[tuple[int, str, float]]) -> list[ModeClass]:
    """The class of each mode (column) of ``shapes`` (n_states, m) from a :func:`dof_table`."""
    out = []
    idx = np.array([i for i, _, _ in table], dtype=int)
    cls = [c for _, c, _ in table]
    w = np.array([m for _, _, m in table], float)
    sensor = np.array([c == "sensor path" for c in cls])
    for k in range(shapes.shape[1]):
        v2 = np.abs(shapes[idx, k]) ** 2
        if v2[~sensor].sum() <= SENSOR_PATH_SHARE * max(v2.sum(), 1e-300):
            out.append(ModeClass("sensor path", {"sensor path": 1.0}))
            continue
        energy: dict[str, float] = {}
        for c, e in zip(cls, w * v2):
            if c != "sensor path":
                energy[c] = energy.get(c, 0.0) + float(e)
        total = sum(energy.values()) or 1.0
        shares = {c: e / total for c, e in energy.items() if e > 0}
        out.append(ModeClass(_name(shares), shares))
    return out


def side_levels(shapes: np.ndarray, table: Sequence[tuple[int, str, float]],
                classes: Sequence[ModeClass] = ()) -> np.ndarray:
    """(m,) where each mode (column of ``shapes``, (n_states, m)) moves: the largest lateral
    velocity on the input shaft's bodies over the largest on the output shaft's, in dB
    (:data:`SIDES`; NaN where a shaft has no such state or neither moves). A sensor path's own modes
    (``classes``, from :func:`classify`, when given) are NaN too: their structure is still but for
    rounding.

    Unweighted amplitudes, not energies: a hammer's response at a point is the mode's amplitude
    there (by reciprocity the ratio of two struck points' FRFs at a lone mode is the ratio of the
    mode's amplitudes at them, whatever the sensor), and the gear's larger mass would otherwise
    tilt every mode towards the output shaft."""
    def side(name):
        return np.array([i for i, c, _ in table if c.rsplit(" ", 1)[0] in SIDES[name]], dtype=int)

    a, b = side("input"), side("output")
    out = np.full(shapes.shape[1], np.nan)
    if a.size == 0 or b.size == 0:
        return out
    amp_a, amp_b = np.abs(shapes[a]).max(axis=0), np.abs(shapes[b]).max(axis=0)
    still = np.array([c.name == "sensor path" for c in classes], bool) if len(classes) else np.zeros(out.size, bool)
    ok = (amp_a > 0) & (amp_b > 0) & ~still
    out[ok] = 20 * np.log10(amp_a[ok] / amp_b[ok])
    return out


def _name(shares: Mapping[str, float]) -> str:
    """The largest class of ``shares``; torsion only if it outweighs the lateral classes together."""
    if not shares:
        return "sensor path"
    lateral = sum(v for c, v in shares.items() if c.endswith((" x", " y")))
    if shares.get("torsion", 0.0) <= lateral:
        shares = {c: v for c, v in shares.items() if c != "torsion"}
    return max(shares, key=shares.get)


def mass_values(fmu_path, parameters: Mapping[str, float]) -> dict[str, float]:
    """Masses and inertias of the model (``I*``, ``m*`` parameters) at ``parameters``.

    A mass bound to other parameters (a calculated parameter, e.g. a gear body plus its shaft's
    share in GearTwin.Gearbox21Shafts) is read from the FMU after its initialisation with
    ``parameters``, so it follows the geometry it is computed from.
    """
    from pathlib import Path

    from twin.fmu import FMU

    key = (str(fmu_path), Path(fmu_path).stat().st_mtime_ns)
    if key not in _STARTS:
        with FMU(fmu_path) as fmu:
            starts = {v.name: float(v.start if v.start is not None else 1.0) for v in fmu.parameters
                      if re.match(_MASS, v.name)}
            calculated = tuple(v.name for v in fmu.variables.values()
                               if v.causality == "calculatedParameter" and re.match(_MASS, v.name))
        _STARTS[key] = (starts, calculated)
    starts, calculated = _STARTS[key]
    out = {n: float(parameters.get(n, v)) for n, v in starts.items()}
    if calculated:
        with FMU(fmu_path) as fmu:
            fmu.setup(parameters={n: v for n, v in parameters.items()
                                  if n in fmu.variables and fmu.variables[n].causality == "parameter"})
            out.update(zip(calculated, (float(x) for x in fmu.get(list(calculated)))))
    return out


#: Names of mass and inertia parameters: ``I5``, ``m10``, ``m_casing``, ``I_casing``, ``m_end4``, ``I_rock10``.
_MASS = r"^(I|m)(\d+|_casing|_end\d+|_rock\d+)$"
_STARTS: dict = {}
