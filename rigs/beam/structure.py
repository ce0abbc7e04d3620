"""Finite-element model of the rig: Timoshenko shafts, rigid gear disks, ball bearings into
the casing modal model, torsional drivetrain; its modes and modal damping.

Degrees of freedom: per shaft node (v, w, v', w', phi): lateral displacements in y and z,
their slopes, and torsion (the gear shaft's torsion is counted in its running direction);
motor, torque-meter and brake rotations; casing modal coordinates. The mesh couples the
pinion and gear nodes along the line of action n = (sin a, cos a) through
delta = rb1 phi_p - rb2 phi_g + (u_p - u_g) . n.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .casing import casing_modes
from .tooth import mesh_geometry

GRAVITY = 9.81
NDOF_NODE = 5


@dataclass(frozen=True)
class LinearModel:
    M: np.ndarray
    K: np.ndarray                 # without the mesh
    parts: dict                   # component stiffness matrices and their loss factors
    mesh: np.ndarray              # (n,) delta = mesh @ x
    motor: int
    torque_meter: int
    brake: int
    encoder: int                  # pinion free-end torsion
    gear_encoder: int
    pinion_node: int              # first DOF of the pinion node
    gear_node: int
    pinion_coupling_node: int
    bearing_dofs: np.ndarray      # (4, 2) shaft DOFs (y, z) of bearings A, B, C, D
    bearing_housing: np.ndarray   # (4, 2, n) DOF vectors of housing motion (y, z)
    sensors: np.ndarray           # (2, n) DOF vectors of the sensor accelerations
    casing_dofs: np.ndarray
    casing_labels: tuple
    bearing_loads: np.ndarray     # (4, 2) static bearing loads on the shafts [N]
    bearing_stiffness: np.ndarray  # (4, 2) along / across the load line [N/m]
    normal: np.ndarray            # (2,) line of action (y, z)


def timoshenko(E, G, rho, d, L, factor=1.0):
    """Bending stiffness and mass (4x4, DOFs v1, v1', v2, v2') and torsion (2x2)."""
    A = np.pi * d * d / 4
    I = np.pi * d**4 / 64 * factor
    J = np.pi * d**4 / 32
    nu = E / (2 * G) - 1
    kappa = 6 * (1 + nu) / (7 + 6 * nu)
    ph = 12 * E * I / (kappa * G * A * L * L)
    kb = E * I / ((1 + ph) * L**3) * np.array([
        [12, 6 * L, -12, 6 * L],
        [6 * L, (4 + ph) * L * L, -6 * L, (2 - ph) * L * L],
        [-12, -6 * L, 12, -6 * L],
        [6 * L, (2 - ph) * L * L, -6 * L, (4 + ph) * L * L]])
    mt = rho * A * L / 420 * np.array([
        [156, 22 * L, 54, -13 * L], [22 * L, 4 * L * L, 13 * L, -3 * L * L],
        [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L * L, -22 * L, 4 * L * L]])
    mr = rho * I / factor / (30 * L) * np.array([
        [36, 3 * L, -36, 3 * L], [3 * L, 4 * L * L, -3 * L, -L * L],
        [-36, -3 * L, 36, -3 * L], [3 * L, -L * L, -3 * L, 4 * L * L]])
    kt = G * J / L * np.array([[1, -1], [-1, 1]])
    mtor = rho * J * L / 6 * np.array([[2, 1], [1, 2]])
    return kb, mt + mr, kt, mtor


def _bearing_stiffness(load, balls, hertz, p):
    """Radial stiffness of a deep-groove ball bearing (Stribeck load zone, Hertz balls)."""
    f = max(load, p.min_load)
    k = 1.5 * (balls * hertz / 5.0) ** (2 / 3) * f ** (1 / 3)
    k_par = 1 / (1 / k + 1 / p.housing)
    kt = p.transverse_ratio * k
    return k_par, 1 / (1 / kt + 1 / p.housing)


def build(params, load: float) -> LinearModel:
    """Assemble M and K at a brake torque `load` [N m] (bearing stiffness depends on it)."""
    g, sh, dt, bp = params.gears, params.shafts, params.drivetrain, params.bearings
    geo = mesh_geometry(g)
    alpha = g.pressure_angle
    normal = np.array([np.sin(alpha), np.cos(alpha)])
    nn = len(sh.stations)
    n_shaft = nn * NDOF_NODE
    p0, g0 = 0, n_shaft
    motor, tmeter, brake = 2 * n_shaft, 2 * n_shaft + 1, 2 * n_shaft + 2
    c0 = 2 * n_shaft + 3
    a = geo.centre_distance
    x_b = [sh.stations[i] for i in sh.bearing_nodes]
    housings = np.array([[x_b[0], 0, 0], [x_b[1], 0, 0], [x_b[0], a, 0], [x_b[1], a, 0]])
    cas = casing_modes(params.casing, housings)
    nc = cas.freq.size
    n = c0 + nc
    M = np.zeros((n, n))
    parts = {k: np.zeros((n, n)) for k in ("shaft", "coupling", "coupling_radial", "bearing")}
    E, G = sh.young, sh.young / (2 * (1 + sh.poisson))
    shaft_mass = [0.0, 0.0]
    for s, (base, dia) in enumerate(((p0, sh.pinion_diameters), (g0, sh.gear_diameters))):
        for e in range(nn - 1):
            L = sh.stations[e + 1] - sh.stations[e]
            kb, mb, kt, mt = timoshenko(E, G, sh.density, dia[e], L, sh.bending_factor)
            i, j = base + e * NDOF_NODE, base + (e + 1) * NDOF_NODE
            shaft_mass[s] += sh.density * np.pi * dia[e] ** 2 / 4 * L
            for plane in (0, 1):
                idx = [i + plane, i + 2 + plane, j + plane, j + 2 + plane]
                parts["shaft"][np.ix_(idx, idx)] += kb
                M[np.ix_(idx, idx)] += mb
            idx = [i + 4, j + 4]
            parts["shaft"][np.ix_(idx, idx)] += kt
            M[np.ix_(idx, idx)] += mt
    # gear bodies as rigid disks
    rho, b = g.density, g.face_width
    def disk(base_node, r_out, r_in, factor):
        m = factor * rho * np.pi * (r_out**2 - r_in**2) * b
        jp = m * (r_out**2 + r_in**2) / 2
        jd = jp / 2 + m * b * b / 12
        k = base_node
        M[k, k] += m
        M[k + 1, k + 1] += m
        M[k + 2, k + 2] += jd
        M[k + 3, k + 3] += jd
        M[k + 4, k + 4] += jp
        return m
    pin = p0 + sh.gear_node * NDOF_NODE
    gea = g0 + sh.gear_node * NDOF_NODE
    r_root1 = geo.r1 - g.dedendum * g.module
    m_p = disk(pin, (r_root1 + geo.r1) / 2, g.pinion_bore / 2, 1.0)
    m_g = disk(gea, (geo.r2 - g.dedendum * g.module + geo.r2) / 2, g.gear_bore / 2, g.gear_web_factor)
    for node, (m, j) in ((p0, sh.pinion_coupling_half), (p0 + (nn - 1) * NDOF_NODE, sh.pinion_encoder_end),
                         (g0, sh.gear_encoder_end), (g0 + (nn - 1) * NDOF_NODE, sh.gear_coupling_half)):
        M[node, node] += m
        M[node + 1, node + 1] += m
        M[node + 4, node + 4] += j
    M[motor, motor] = dt.motor_inertia
    M[tmeter, tmeter] = dt.torque_meter_inertia
    M[brake, brake] = dt.brake_inertia
    # couplings: motor - torque meter - pinion shaft end; gear shaft end - brake
    def spring(mat, i, j, k):
        mat[i, i] += k
        mat[j, j] += k
        mat[i, j] -= k
        mat[j, i] -= k
    spring(parts["coupling"], motor, tmeter, dt.coupling_motor)
    spring(parts["coupling"], tmeter, p0 + 4, dt.coupling_pinion)
    gear_end = g0 + (nn - 1) * NDOF_NODE
    spring(parts["coupling"], gear_end + 4, brake, dt.coupling_brake)
    for node in (p0, gear_end):
        parts["coupling_radial"][node, node] += sh.coupling_radial
        parts["coupling_radial"][node + 1, node + 1] += sh.coupling_radial
    # static bearing loads: mesh force and weights shared by the two bearings of a shaft
    f_mesh = load * g.z_pinion / g.z_gear / geo.rb1
    w_p = (shaft_mass[0] + m_p + sh.pinion_coupling_half[0] + sh.pinion_encoder_end[0]) * GRAVITY
    w_g = (shaft_mass[1] + m_g + sh.gear_coupling_half[0] + sh.gear_encoder_end[0]) * GRAVITY
    xb = np.array(x_b)
    x_gear = sh.stations[sh.gear_node]
    share = np.array([(xb[1] - x_gear), (x_gear - xb[0])]) / (xb[1] - xb[0])
    loads = np.zeros((4, 2))
    for h in range(2):
        loads[h] = share[h] * (-f_mesh * normal) + 0.5 * np.array([0, -w_p])
        loads[2 + h] = share[h] * (f_mesh * normal) + 0.5 * np.array([0, -w_g])
    bdofs = np.zeros((4, 2), int)
    hvec = np.zeros((4, 2, n))
    kstore = np.zeros((4, 2))
    for h in range(4):
        base = (p0 if h < 2 else g0) + sh.bearing_nodes[h % 2] * NDOF_NODE
        bdofs[h] = (base, base + 1)
        mag = np.linalg.norm(loads[h])
        d = loads[h] / mag
        if h < 2:
            kp, kq = _bearing_stiffness(mag, bp.pinion_balls, bp.pinion_hertz, bp)
        else:
            kp, kq = _bearing_stiffness(mag, bp.gear_balls, bp.gear_hertz, bp)
        kstore[h] = (kp, kq)
        kb = kp * np.outer(d, d) + kq * (np.eye(2) - np.outer(d, d))
        T = np.zeros((2, n))
        T[0, base], T[1, base + 1] = 1, 1
        T[:, c0:] -= cas.housing[h]
        hvec[h, :, c0:] = cas.housing[h]
        parts["bearing"] += T.T @ kb @ T
    Kc = np.zeros((n, n))
    idx = np.arange(c0, n)
    M[idx, idx] = 1.0
    Kc[idx, idx] = (2 * np.pi * cas.freq) ** 2
    parts["casing"] = Kc
    K = sum(parts.values())
    mesh = np.zeros(n)
    mesh[pin + 4] = geo.rb1
    mesh[gea + 4] = -geo.rb2
    mesh[pin:pin + 2] = normal
    mesh[gea:gea + 2] = -normal
    sensors = np.zeros((2, n))
    sensors[:, c0:] = cas.sensor
    return LinearModel(M, K, parts, mesh, motor, tmeter, brake, p0 + (nn - 1) * NDOF_NODE + 4, g0 + 4,
                       pin, gea, p0, bdofs, hvec, sensors, idx, cas.labels, loads, kstore, normal)


@dataclass(frozen=True)
class ModalModel:
    freq: np.ndarray      # (m,) Hz, ascending, first is the rigid-body rotation (0)
    zeta: np.ndarray
    shapes: np.ndarray    # (n, m) mass-normalised
    mesh_residual: float  # static mesh compliance of the modes left out [m/N]
    energy: dict          # component strain-energy fractions per mode


def modal(model: LinearModel, mesh_stiffness: float, params, lubricated: bool = True,
          cutoff: float | None = None) -> ModalModel:
    """Modes of the rig with the mesh at its mean stiffness; damping by strain energy."""
    dmp = params.damping
    K = model.K + mesh_stiffness * np.outer(model.mesh, model.mesh)
    L = np.linalg.cholesky(model.M)
    Li = np.linalg.inv(L)
    w2, Y = np.linalg.eigh(Li @ K @ Li.T)
    Phi = Li.T @ Y
    w2 = np.maximum(w2, 0.0)
    freq = np.sqrt(w2) / (2 * np.pi)
    # exact rigid-body rotation replaces the numerically computed first mode
    rigid = _rigid_mode(model, params)
    rigid /= np.sqrt(rigid @ model.M @ rigid)
    Phi[:, 0] = rigid
    freq[0] = 0.0
    cas = model.casing_dofs
    cas_zeta = np.concatenate([np.full(6, params.casing.mount_damping),
                               [p[3] for p in params.casing.panels]])
    loss = {"shaft": dmp.shaft, "coupling": dmp.coupling, "coupling_radial": dmp.coupling_radial,
            "bearing": dmp.bearing, "mesh": dmp.mesh_lubricated if lubricated else dmp.mesh_dry}
    energies = {k: np.einsum("im,ij,jm->m", Phi, model.parts[k], Phi) for k in
                ("shaft", "coupling", "coupling_radial", "bearing")}
    energies["mesh"] = mesh_stiffness * (model.mesh @ Phi) ** 2
    cas_e = Phi[cas] ** 2 * np.diag(model.parts["casing"])[cas][:, None]
    total = sum(energies.values()) + cas_e.sum(axis=0)
    total = np.where(total > 0, total, 1.0)
    zeta = sum(loss[k] * energies[k] for k in energies) + (cas_zeta[:, None] * cas_e).sum(axis=0)
    zeta = zeta / total
    frac = {k: v / total for k, v in energies.items()}
    frac["casing"] = cas_e.sum(axis=0) / total
    zeta[0] = 0.0
    keep = freq <= (cutoff if cutoff is not None else params.numerics.mode_cutoff)
    gphi = model.mesh @ Phi
    resid = float(np.sum(gphi[~keep] ** 2 / np.maximum(w2[~keep], 1e-30)))
    return ModalModel(freq[keep], zeta[keep], Phi[:, keep], resid,
                      {k: v[keep] for k, v in frac.items()})


def _rigid_mode(model, params):
    n = model.M.shape[0]
    v = np.zeros(n)
    ratio = params.gears.z_pinion / params.gears.z_gear
    nn = len(params.shafts.stations)
    for i in range(nn):
        v[i * NDOF_NODE + 4] = 1.0
        v[(nn + i) * NDOF_NODE + 4] = ratio
    v[model.motor] = v[model.torque_meter] = 1.0
    v[model.brake] = ratio
    return v
