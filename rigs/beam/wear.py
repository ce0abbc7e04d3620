"""Abrasive wear of both flanks by Archard's law, integrated with the evolving load sharing.

At a flank point the depth worn in one passage through the contact is

    dh = k * integral p v_s dt = k * p_mean * 2a * |v_s| / v_r = k F |v_s| / (b v_r),

with p the Hertzian pressure (mean p_mean over the half-width a), v_s the sliding speed
(omega1 + omega2) |u - u_pitch| and v_r the rolling speed of that flank (omega1 rho1 on the
pinion, omega2 rho2 on the gear). Per pinion revolution a pinion tooth passes once and a
gear tooth z1/z2 times. The pair force F(u) comes from the quasi-static loaded mesh of the
worn pair, recomputed after each of N increments, so deep wear near the pinion root and the
gear tip unloads itself and the profile shape evolves. The depth per increment is scaled so
the mean depth over the pinion's active flank grows by target/N: the unknown wear coefficient
and running time collapse into the damage measure. Each increment is smoothed over the
Hertzian contact width widened by SPREAD (semi-elliptic kernel): the contact of neighbouring
points (the contact shifts on the changing profile, debris spreads) smooths the worn profile.
"""
from __future__ import annotations

import numpy as np

from .contact import cycle_positions, static_mesh

INCREMENTS = 12
SPREAD = 0.6e-3   # m: wear debris and the contact shifting on the changing profile spread each
#                   increment over neighbouring points (a smoother worn profile)


def _smooth(x, half_width_cells):
    n = max(int(np.ceil(half_width_cells)), 1)
    t = np.arange(-n, n + 1) / (half_width_cells + 1e-12)
    k = np.sqrt(np.clip(1 - t**2, 0, None))
    k /= k.sum()
    return np.convolve(x, k, mode="same")


def archard_profiles(mean_depth: float, geo, tables, force: float, z1: int, z2: int):
    """Worn depth of pinion and gear flanks on the path grid [m], mean pinion depth given."""
    u = tables.u
    h_p = np.zeros_like(u)
    h_g = np.zeros_like(u)
    if mean_depth <= 0:
        return h_p, h_g
    pos, valid = cycle_positions(geo, 256)
    c = np.interp(pos, u, tables.body_pinion + tables.body_gear)
    aw = np.interp(pos, u, tables.hertz_a)
    qw = np.full_like(pos, tables.hertz_q)
    ratio = z1 / z2
    rho1, rho2 = tables.rho1, tables.rho2
    slide = (1.0 + ratio) * np.abs(u - geo.pitch_u)
    du = u[1] - u[0]
    half = np.sqrt(8 * force * (rho1 * rho2 / (rho1 + rho2)).mean() * 0.91 / (np.pi * 2.06e11 * 0.02))
    for _ in range(INCREMENTS):
        e = np.interp(pos, u, h_p + h_g)
        _, forces, _ = static_mesh(force, e, c, qw, aw, valid)
        f_u = np.zeros_like(u)
        for n in range(2):
            ok = valid[:, n]
            order = np.argsort(pos[ok, n])
            f_u = np.maximum(f_u, np.interp(u, pos[ok, n][order], forces[ok, n][order], left=0, right=0))
        rate_p = _smooth(f_u * slide / rho1, (half + SPREAD) / du)
        rate_g = _smooth(f_u * slide / (ratio * rho2) * ratio, (half + SPREAD) / du)
        scale = (mean_depth / INCREMENTS) / rate_p.mean()
        h_p += scale * rate_p
        h_g += scale * rate_g
    return h_p, h_g
