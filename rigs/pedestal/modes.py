"""The rig's own linearisation: eigenvalues of the linear system at the mean mesh stiffness.

State ``[x, v, z, T_e]``: the structure (diagonal mass, element stiffness and damping), the gear
mesh replaced by its mean tangent stiffness at the operating load (from the quasi-static loaded
contact of this gearbox's own teeth over a hunting period, ``mesh.mean_tangent_stiffness``) and a
viscous mesh damper, plus the VFD's PI speed loop (integrator ``z``) and its torque lag ``T_e``.

Each mode carries:

* ``observability`` [0..1]: the peak of the mode's own contribution to the pinion-side casing
  acceleration per unit transmission error on the line of action (the excitation a run-up
  sweeps), divided by the largest such peak over all modes. A mode at 1e-2 sits 40 dB below the
  most visible one;
* ``label``: the body with most kinetic energy and the element with most strain energy.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .structure import LinearStructure

_GROUPS = {
    "theta_motor": "motor rotor", "theta_meter": "torque meter", "theta_pinion": "pinion torsion",
    "theta_gear": "gear torsion", "theta_brake": "brake rotor",
    "x_pinion": "pinion lateral", "y_pinion": "pinion lateral",
    "x_gear": "gear lateral", "y_gear": "gear lateral",
    "x_pinion_pedestal": "pinion pedestal", "y_pinion_pedestal": "pinion pedestal",
    "x_gear_pedestal": "gear pedestal", "y_gear_pedestal": "gear pedestal",
    "x_casing": "casing x", "y_casing": "casing y", "phi_casing": "casing rocking",
}


@dataclass(frozen=True)
class Mode:
    """One mode of the linearised rig."""

    frequency: float        # [Hz] undamped natural frequency |lambda| / 2 pi
    damping_ratio: float    # [-]
    observability: float    # [0..1] at the pinion-side casing sensor (see module docstring)
    label: str

    def as_dict(self) -> dict:
        return {"frequency": self.frequency, "damping_ratio": self.damping_ratio,
                "observability": self.observability, "label": self.label}


def state_matrix(struct: LinearStructure, k_mesh: float, c_mesh: float,
                 kp: float, ki: float, lag: float) -> tuple[np.ndarray, np.ndarray]:
    """First-order system matrix A (2n+2 square) and the TE input column b (unit TE)."""
    n = struct.mass.size
    g = struct.mesh_vector
    K = struct.K + k_mesh * np.outer(g, g)
    C = struct.C + c_mesh * np.outer(g, g)
    minv = 1.0 / struct.mass
    A = np.zeros((2 * n + 2, 2 * n + 2))
    A[:n, n:2 * n] = np.eye(n)
    A[n:2 * n, :n] = -minv[:, None] * K
    A[n:2 * n, n:2 * n] = -minv[:, None] * C
    A[n + 0, 2 * n + 1] = minv[0]            # motor torque on the motor rotor
    A[2 * n, n + 0] = -1.0                   # z' = w_ref - w_m (deviation form)
    A[2 * n + 1, n + 0] = -kp / lag
    A[2 * n + 1, 2 * n] = ki / lag
    A[2 * n + 1, 2 * n + 1] = -1.0 / lag
    b = np.zeros(2 * n + 2)
    b[n:2 * n] = minv * k_mesh * g           # a TE e adds -k e on delta: force k e along g
    return A, b


def linear_modes(struct: LinearStructure, k_mesh: float, c_mesh: float, kp: float, ki: float,
                 lag: float, fmin: float = 1.0) -> tuple[Mode, ...]:
    """Modes above ``fmin`` [Hz] with damping ratio below 0.5, ascending in frequency."""
    n = struct.mass.size
    A, b = state_matrix(struct, k_mesh, c_mesh, kp, ki, lag)
    lam, right = np.linalg.eig(A)
    left = np.linalg.inv(right)              # rows: left eigenvectors, normalised to right
    out_row = struct.sensor_rows[0] @ A[n:2 * n, :]   # acceleration = row . (dv/dt)
    keep = []
    for i, la in enumerate(lam):
        w = abs(la)
        if la.imag <= 0 or w < 2 * np.pi * fmin:
            continue
        zeta = -la.real / w
        if zeta >= 0.5:
            continue
        residue = (out_row @ right[:, i]) * (left[i] @ b)
        peak = abs(residue) / max(-la.real, 1e-9)
        keep.append((w / (2 * np.pi), zeta, peak, right[:n, i]))
    keep.sort(key=lambda r: r[0])
    top = max((r[2] for r in keep), default=1.0)
    g = struct.mesh_vector
    modes = []
    for f, zeta, peak, shape in keep:
        modes.append(Mode(float(f), float(zeta), float(peak / top),
                          _label(struct, np.real(shape * np.exp(-1j * np.angle(
                              shape[np.argmax(abs(shape))]))), k_mesh, g)))
    return tuple(modes)


def _label(struct: LinearStructure, shape: np.ndarray, k_mesh: float, g: np.ndarray) -> str:
    kinetic: dict[str, float] = {}
    for i, name in enumerate(struct.dof):
        grp = _GROUPS.get(name, name.replace("_", " "))
        kinetic[grp] = kinetic.get(grp, 0.0) + struct.mass[i] * shape[i] ** 2
    strain: dict[str, float] = {"mesh": k_mesh * (g @ shape) ** 2}
    for el in struct.elements:
        base = el.name[:-2] if el.name.endswith((" x", " y")) else el.name
        strain[base] = strain.get(base, 0.0) + el.k * (el.w @ shape) ** 2
    body = max(kinetic, key=kinetic.get)
    spring = max(strain, key=strain.get)
    if spring == body:
        return body
    return f"{body} on {spring}"


def mode_table(modes: tuple[Mode, ...], count: int = 10) -> str:
    """Markdown table of the first ``count`` modes."""
    lines = ["| # | frequency [Hz] | damping [%] | observability | label |",
             "|---|---|---|---|---|"]
    for i, m in enumerate(modes[:count]):
        lines.append(f"| {i + 1} | {m.frequency:.1f} | {100 * m.damping_ratio:.2f} | "
                     f"{m.observability:.3g} | {m.label} |")
    return "\n".join(lines)

