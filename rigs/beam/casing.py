"""Modal model of the gearbox casing.

Rigid-body modes of the cast box on its four bolted feet (6-DOF rigid body with the mount
stiffnesses, solved exactly) plus a handful of assumed flexible modes of its panels and end
walls: each with a frequency, a modal mass and a shape evaluated at the four bearing
housings (radial y, z) and at the two sensor points (along the sensor axes). Panel shapes are
plate functions sin(m pi xi) sin(n pi eta) over the panel; housings, which sit in the end
walls, take part through the wall edges with the coupling factors below.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CasingModes:
    freq: np.ndarray        # (n,) Hz
    zeta: np.ndarray        # (n,)
    housing: np.ndarray     # (4, 2, n) mass-normalised shapes at housings A, B, C, D (y, z)
    sensor: np.ndarray      # (2, n) mass-normalised shapes at the two sensors, along their axes
    labels: tuple


def _rigid(cs, points):
    o = np.array(cs.origin)
    L = np.array(cs.size)
    cg = o + L / 2
    m = cs.mass
    # thin-walled box: inertia of its six plates (uniform area density)
    area = 2 * (L[0] * L[1] + L[1] * L[2] + L[0] * L[2])
    rho_a = m / area
    inertia = np.zeros(3)
    for i in range(3):
        j, k = [x for x in range(3) if x != i]
        # plates normal to j and k contribute; plate normal to i too
        pi_ = rho_a * L[j] * L[k]
        inertia[i] += 2 * pi_ * (L[j] ** 2 + L[k] ** 2) / 12
        pj = rho_a * L[i] * L[k]
        inertia[i] += 2 * pj * (L[k] ** 2 / 12 + (L[j] / 2) ** 2)
        pk = rho_a * L[i] * L[j]
        inertia[i] += 2 * pk * (L[j] ** 2 / 12 + (L[k] / 2) ** 2)
    M = np.diag([m, m, m, *inertia])
    K = np.zeros((6, 6))
    for fx in (o[0], o[0] + L[0]):
        for fy in (o[1], o[1] + L[1]):
            T = _transfer(np.array([fx, fy, o[2]]) - cg)
            K += T.T @ np.diag(cs.mount_stiffness) @ T
    w2, V = _gen_eig(K, M)
    shapes = [np.stack([_transfer(p - cg) @ V for p in pts]) for pts in points]
    names = ("axial surge", "lateral sway", "bounce", "roll", "pitch", "yaw")
    share = (V * np.sqrt(np.diag(M))[:, None]) ** 2
    labels = tuple(f"casing {names[i]} on mounts" for i in np.argmax(share, axis=0))
    return np.sqrt(w2) / (2 * np.pi), shapes, labels


def _transfer(r):
    """Point displacement (3,) from rigid-body DOFs (tx, ty, tz, rx, ry, rz)."""
    return np.array([[1, 0, 0, 0, r[2], -r[1]],
                     [0, 1, 0, -r[2], 0, r[0]],
                     [0, 0, 1, r[1], -r[0], 0]], float)


def _gen_eig(K, M):
    Li = np.linalg.inv(np.linalg.cholesky(M))
    w2, Y = np.linalg.eigh(Li @ K @ Li.T)
    return w2, Li.T @ Y


def casing_modes(cs, housings: np.ndarray) -> CasingModes:
    """housings: (4, 3) coordinates of bearing housings A, B (pinion), C, D (gear)."""
    sens = [np.array(cs.pinion_sensor), np.array(cs.gear_sensor)]
    axes = [cs.pinion_sensor_axis, cs.gear_sensor_axis]
    f_rb, (sh_h, sh_s), rb_labels = _rigid(cs, [housings, np.stack(sens)])
    n_rb = f_rb.size
    n = n_rb + len(cs.panels)
    freq = np.zeros(n)
    zeta = np.zeros(n)
    hous = np.zeros((4, 2, n))
    sensor = np.zeros((2, n))
    freq[:n_rb] = f_rb
    zeta[:n_rb] = cs.mount_damping
    hous[:, :, :n_rb] = sh_h[:, 1:3, :]
    for s in range(2):
        sensor[s, :n_rb] = sh_s[s, axes[s], :]
    o, L = np.array(cs.origin), np.array(cs.size)
    labels = list(rb_labels)
    rel = lambda p: (np.asarray(p) - o) / L
    for i, (label, f, mass, z) in enumerate(cs.panels):
        r = n_rb + i
        freq[r], zeta[r] = f, z
        labels.append(f"casing {label}")
        shape_h = np.zeros((4, 2))
        shape_s = np.zeros(2)
        scale = 1 / np.sqrt(mass)
        if label.startswith("top cover"):
            mx = 2 if "(2,1)" in label else 1
            for s in range(2):
                q = rel(sens[s])
                if axes[s] == 2 and abs(sens[s][2] - (o[2] + L[2])) < 1e-6:
                    shape_s[s] = np.sin(mx * np.pi * q[0]) * np.sin(np.pi * q[1])
                else:
                    shape_s[s] = 0.08
            for h in range(4):
                q = rel(housings[h])
                side = 1.0 if (mx == 1 or h in (0, 2)) else -1.0
                shape_h[h, 1] = 0.15 * side * np.sin(np.pi * q[1])
        elif label.startswith("gear-side wall"):
            mx = 2 if "(2,1)" in label else 1
            wall_y = o[1] + L[1]
            for s in range(2):
                q = rel(sens[s])
                if axes[s] == 1 and abs(sens[s][1] - wall_y) < 1e-6:
                    shape_s[s] = np.sin(mx * np.pi * q[0]) * np.sin(np.pi * q[2])
                else:
                    shape_s[s] = 0.06
            for h in range(4):
                q = rel(housings[h])
                side = 1.0 if (mx == 1 or h in (0, 2)) else -1.0
                dist = wall_y - housings[h][1]
                shape_h[h, 0] = 0.25 * side * np.exp(-dist / 0.1) * np.sin(np.pi * q[2])
        elif "ovalising" in label:
            shape_h[:, 0] = [-0.6, -0.6, 0.6, 0.6]
            shape_h[:, 1] = [0.2, 0.2, -0.2, -0.2]
            shape_s[:] = [0.15, 0.3]
        else:  # end walls shear: front and back walls in anti-phase
            shape_h[:, 1] = [0.5, -0.5, 0.5, -0.5]
            shape_h[:, 0] = [0.2, -0.2, 0.2, -0.2]
            shape_s[:] = [0.1, 0.12]
        hous[:, :, r] = shape_h * scale
        sensor[:, r] = shape_s * scale
    return CasingModes(freq, zeta, hous, sensor, tuple(labels))
