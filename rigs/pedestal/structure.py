"""Assembly of the rig's linear structure: diagonal mass, stiffness and damping by elements.

Generalised coordinates (``DOF``): five rotations of the torsional chain (the gear and brake
positive clockwise, so that ``rb1 theta_p = rb2 theta_g`` is the rigid kinematics), the pinion
and gear centres and the two bearing pedestals in the gear plane, the casing as a rigid body
(x, y, rotation about the casing centre of mass) on two isolators, and mass-normalised casing
panel modes. The casing point where a pedestal or a sensor sits moves with the rigid body plus
the panel modes, so the mass matrix stays diagonal and the coupling is in the stiffness.

The gear mesh is *not* in K: it acts through ``mesh_vector`` (the line-of-action deflection
``delta = g . x``) with its time-varying, unilateral law in the integrator, and with the mean
tangent stiffness in the linearisation (``rigs.pedestal.modes``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import GearPair
from .params import Drivetrain, Structure

BASE_DOF = ("theta_motor", "theta_meter", "theta_pinion", "theta_gear", "theta_brake",
            "x_pinion", "y_pinion", "x_gear", "y_gear",
            "x_pinion_pedestal", "y_pinion_pedestal", "x_gear_pedestal", "y_gear_pedestal",
            "x_casing", "y_casing", "phi_casing")
I_M, I_T, I_P, I_G, I_B = 0, 1, 2, 3, 4
I_XP, I_YP, I_XG, I_YG = 5, 6, 7, 8
I_XA, I_YA, I_XB, I_YB = 9, 10, 11, 12
I_X, I_Y, I_PHI = 13, 14, 15


@dataclass(frozen=True)
class Panel:
    """One casing panel mode: frequency [Hz], damping ratio, mass-normalised shape [m/sqrt(kg)]
    at (pinion pedestal x, y, gear pedestal x, y, pinion sensor, gear sensor), and a name."""

    frequency: float
    damping: float
    shape: tuple
    name: str


@dataclass(frozen=True)
class Element:
    name: str
    w: np.ndarray       # elongation = w . x
    k: float
    c: float


@dataclass(frozen=True)
class LinearStructure:
    dof: tuple
    mass: np.ndarray            # (n,) diagonal
    K: np.ndarray               # (n, n) without the mesh
    C: np.ndarray               # (n, n) without the mesh
    elements: tuple
    mesh_vector: np.ndarray     # (n,) g: delta = g . x along the line of action
    normal: np.ndarray          # (2,) line-of-action direction n (force on the gear)
    tangent: np.ndarray         # (2,) t = z x n, flank sliding direction
    sensor_rows: np.ndarray     # (2, n) casing acceleration along each sensor axis = row . a
    mesh_mass: float            # [kg] torsional equivalent mass of the pair on the line of action


def _unit(n: int, i: int) -> np.ndarray:
    e = np.zeros(n)
    e[i] = 1.0
    return e


def build_structure(gears: GearPair, dt: Drivetrain, st: Structure,
                    panels: tuple[Panel, ...]) -> LinearStructure:
    """Assemble mass, stiffness and damping of the rig (mesh excluded)."""
    n = len(BASE_DOF) + len(panels)
    dof = BASE_DOF + tuple(p.name for p in panels)
    e = [_unit(n, i) for i in range(n)]
    mass = np.zeros(n)
    mass[:5] = (dt.motor_inertia, dt.meter_inertia, dt.pinion_inertia, dt.gear_inertia,
                dt.brake_inertia)
    mass[I_XP] = mass[I_YP] = st.pinion_mass
    mass[I_XG] = mass[I_YG] = st.gear_mass
    mass[I_XA] = mass[I_YA] = st.pinion_pedestal_mass
    mass[I_XB] = mass[I_YB] = st.gear_pedestal_mass
    mass[I_X] = mass[I_Y] = st.casing_mass
    mass[I_PHI] = st.casing_inertia
    mass[16:] = 1.0

    def casing_point(p: tuple, direction: tuple, panel_slot: int | None) -> np.ndarray:
        """Displacement of casing point p=(x, y) along direction d, rigid body + panels."""
        d = np.asarray(direction, float)
        w = d[0] * (e[I_X] - p[1] * e[I_PHI]) + d[1] * (e[I_Y] + p[0] * e[I_PHI])
        if panel_slot is not None:
            for j, pan in enumerate(panels):
                w = w + pan.shape[panel_slot] * e[16 + j]
        return w

    def reduced(m1: float, m2: float) -> float:
        return m1 * m2 / (m1 + m2)

    def zc(zeta: float, k: float, m: float) -> float:
        return 2.0 * zeta * np.sqrt(k * m)

    elements: list[Element] = []

    def add(name, w, k, zeta, m):
        elements.append(Element(name, w, float(k), zc(zeta, k, m)))

    zt = dt.coupling_damping_ratio
    add("motor coupling", e[I_M] - e[I_T], dt.motor_meter_stiffness, zt,
        reduced(dt.motor_inertia, dt.meter_inertia))
    add("meter coupling", e[I_T] - e[I_P], dt.meter_pinion_stiffness, zt,
        reduced(dt.meter_inertia, dt.pinion_inertia + dt.gear_inertia / gears.ratio ** 2))
    add("brake coupling", e[I_G] - e[I_B], dt.gear_brake_stiffness, zt,
        reduced(dt.gear_inertia + dt.pinion_inertia * gears.ratio ** 2, dt.brake_inertia))
    zs = st.support_damping_ratio
    for axis, (ip, ig, ia, ib) in enumerate(((I_XP, I_XG, I_XA, I_XB), (I_YP, I_YG, I_YA, I_YB))):
        tag = "xy"[axis]
        add(f"pinion support {tag}", e[ip] - e[ia], st.pinion_support_stiffness, zs,
            reduced(st.pinion_mass, st.pinion_pedestal_mass))
        add(f"gear support {tag}", e[ig] - e[ib], st.gear_support_stiffness, zs,
            reduced(st.gear_mass, st.gear_pedestal_mass))
    half = 0.5 * gears.centre_distance
    pos_a = (-half, st.shaft_height)
    pos_b = (half, st.shaft_height)
    zp = st.pedestal_damping_ratio
    for axis, (ia, ib) in enumerate(((I_XA, I_XB), (I_YA, I_YB))):
        tag = "xy"[axis]
        direction = (1.0, 0.0) if axis == 0 else (0.0, 1.0)
        scale = 0.8 if axis == 0 else 1.0
        add(f"pinion pedestal {tag}", e[ia] - casing_point(pos_a, direction, axis),
            scale * st.pinion_pedestal_stiffness, zp, st.pinion_pedestal_mass)
        add(f"gear pedestal {tag}", e[ib] - casing_point(pos_b, direction, 2 + axis),
            scale * st.gear_pedestal_stiffness, zp, st.gear_pedestal_mass)
    zi = st.isolator_damping_ratio
    for side in (-1.0, 1.0):
        p = (side * st.isolator_half_span, -st.isolator_depth)
        add("isolators", casing_point(p, (1.0, 0.0), None), st.isolator_stiffness_x, zi,
            0.5 * st.casing_mass)
        add("isolators", casing_point(p, (0.0, 1.0), None), st.isolator_stiffness_y, zi,
            0.5 * st.casing_mass)
    for j, pan in enumerate(panels):
        om = 2.0 * np.pi * pan.frequency
        elements.append(Element(pan.name.replace("_", " "), e[16 + j], om ** 2,
                                2.0 * pan.damping * om))

    K = np.zeros((n, n))
    C = np.zeros((n, n))
    for el in elements:
        K += el.k * np.outer(el.w, el.w)
        C += el.c * np.outer(el.w, el.w)

    alpha = gears.pressure_angle
    normal = np.array([np.sin(alpha), np.cos(alpha)])
    tangent = np.array([-normal[1], normal[0]])
    g = gears.rb1 * e[I_P] - gears.rb2 * e[I_G]
    g = g + normal[0] * (e[I_XP] - e[I_XG]) + normal[1] * (e[I_YP] - e[I_YG])

    rows = np.zeros((2, n))
    for s in range(2):
        rows[s] = casing_point(st.sensor_positions[s], st.sensor_directions[s], None)
        for j, pan in enumerate(panels):
            rows[s, 16 + j] = pan.shape[4 + s]
    m_eq = 1.0 / (gears.rb1 ** 2 / dt.pinion_inertia + gears.rb2 ** 2 / dt.gear_inertia)
    return LinearStructure(dof=dof, mass=mass, K=K, C=C, elements=tuple(elements),
                           mesh_vector=g, normal=normal, tangent=tangent, sensor_rows=rows,
                           mesh_mass=m_eq)


def panels_of(st: Structure) -> tuple[Panel, ...]:
    return tuple(Panel(float(f), float(z), tuple(float(v) for v in sh), f"panel_{i + 1}")
                 for i, (f, z, sh) in enumerate(zip(st.panel_frequencies, st.panel_damping,
                                                     st.panel_shapes)))
